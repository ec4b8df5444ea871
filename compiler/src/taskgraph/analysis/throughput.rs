//! Throughput: the iteration period of the self-timed execution of a level
//! (every node fires as soon as its input samples are there), which is the
//! maximum cycle mean of the equivalent homogeneous SDF graph (HSDF), and the
//! cycle that attains it.
//!
//! A node cannot overlap with itself, which the HSDF models by chaining the
//! firings of each node with one sample on the edge from its last firing back
//! to its first: even an acyclic level has cycles, and its period is at least
//! every node's γ·wcet.
//!
//! Method: the level is expanded to its HSDF (when every repetition count is
//! 1 the level already is one, and only its edges are read, no firing is
//! copied), then Howard's policy iteration finds the maximum cycle ratio
//! (execution time over initial samples) in exact arithmetic.
//!
//! Complexity: the HSDF has N = Σγ nodes and M ≤ N + Σ γ(dst)·min(⌈c/p⌉+1,
//! γ(src)) edges (summed over the level's edges); building it is O(N + M).
//! Each policy iteration is O(N + M); their number has no known polynomial
//! bound but is small in practice (2 to 15 on the SDF3 benchmarks, whose
//! HSDFs have up to 10 601 nodes and 37 094 edges).

use super::level::Level;
use super::ratio::Ratio;

/// The throughput of one level.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Throughput {
    /// Time units per iteration of the level, exact.
    pub period: Ratio,
    /// Nodes of the level around the cycle that bounds the period, in flow
    /// order, the first-declared node first. A single node means that node
    /// alone bounds it (its firings of one iteration back to back).
    pub critical_cycle: Vec<usize>,
}

/// Most HSDF nodes plus edges built before giving up (about 150 MB).
const MAX_HSDF: u64 = 1 << 23;

/// The period of the self-timed execution of `level` with repetition vector
/// `counts`, taking each task's `wcet` (0 when unknown or for boundary nodes)
/// as its execution time. The level must be consistent and deadlock-free.
///
/// `None` for an empty level, and also (rather than a wrong or panicking
/// answer) when `counts` does not fit the level, when the HSDF would exceed
/// 2^23 nodes plus edges (`MAX_HSDF`), when a cycle without initial samples is met
/// (a deadlock), or when the exact arithmetic would overflow.
pub fn throughput(level: &Level<'_>, counts: &[u64]) -> Option<Throughput> {
    if level.nodes.is_empty() || counts.len() != level.nodes.len() {
        return None;
    }
    let wcet: Vec<u64> = level.nodes.iter().map(|n| n.wcet.unwrap_or(0)).collect();
    let hsdf =
        if counts.iter().all(|&c| c == 1) && level.edges.iter().all(|e| e.produce == e.consume) {
            Hsdf::direct(level, wcet)
        } else {
            Hsdf::expand(level, counts, &wcet)?
        };
    let (period, cycle) = max_cycle_ratio(&hsdf)?;
    let walk: Vec<usize> = cycle.iter().map(|&v| hsdf.actor(v)).collect();
    Some(Throughput {
        period,
        critical_cycle: level_cycle(walk),
    })
}

/// A graph in compressed adjacency form; edge `e` goes from the node whose
/// range `first[v]..first[v + 1]` holds it to `head[e]`, carrying `tokens[e]`
/// initial samples and the execution time of its source node.
struct Hsdf {
    weight: Vec<u64>,
    first: Vec<usize>,
    head: Vec<usize>,
    tokens: Vec<u64>,
    /// The level node of each HSDF node; empty when they are the same.
    actor: Vec<usize>,
}

impl Hsdf {
    fn len(&self) -> usize {
        self.weight.len()
    }

    fn out(&self, v: usize) -> std::ops::Range<usize> {
        self.first[v]..self.first[v + 1]
    }

    fn actor(&self, v: usize) -> usize {
        self.actor.get(v).copied().unwrap_or(v)
    }

    fn from_edges(
        weight: Vec<u64>,
        mut edges: Vec<(usize, usize, u64)>,
        actor: Vec<usize>,
    ) -> Hsdf {
        let n = weight.len();
        edges.sort_by_key(|&(src, _, _)| src);
        let mut first = vec![0; n + 1];
        for &(src, _, _) in &edges {
            first[src + 1] += 1;
        }
        for v in 0..n {
            first[v + 1] += first[v];
        }
        Hsdf {
            weight,
            first,
            head: edges.iter().map(|&(_, dst, _)| dst).collect(),
            tokens: edges.iter().map(|&(_, _, t)| t).collect(),
            actor,
        }
    }

    /// Every node fires once per iteration (and so every edge has equal
    /// rates): the level is its own HSDF. An edge with `d` samples and rate
    /// `p` lets a firing depend on the firing `⌊d/p⌋` iterations earlier.
    fn direct(level: &Level<'_>, weight: Vec<u64>) -> Hsdf {
        let n = level.nodes.len();
        let edges = level
            .edges
            .iter()
            .map(|e| (e.src, e.dst, e.initial_tokens / e.produce))
            .chain((0..n).map(|v| (v, v, 1)))
            .collect();
        Hsdf::from_edges(weight, edges, Vec::new())
    }

    /// The classic SDF→HSDF expansion: node (v, k) for each firing k < γ(v).
    /// On an edge with rates p, c and d initial samples, firing k of the
    /// destination consumes the samples numbered k·c .. k·c + c - 1 of the
    /// iteration, the d initial ones counted first; sample n comes from firing
    /// j = ⌊(n - d)/p⌋ of the source, which is firing j mod γ(src) of the
    /// iteration ⌈-j/γ(src)⌉ earlier when j < 0: the HSDF edge carries that
    /// many samples. Of several dependencies on the same source firing only
    /// the nearest iteration matters, so j runs over at most γ(src) values.
    fn expand(level: &Level<'_>, counts: &[u64], wcet: &[u64]) -> Option<Hsdf> {
        let n = level.nodes.len();
        let mut offset = Vec::with_capacity(n + 1);
        let mut total = 0u64;
        offset.push(0usize);
        for &c in counts {
            if c == 0 {
                return None;
            }
            total = total.checked_add(c)?;
            offset.push(usize::try_from(total).ok()?);
        }
        let mut size = total.checked_mul(2)?;
        for e in &level.edges {
            let per = (e.consume.div_ceil(e.produce).saturating_add(1)).min(counts[e.src]);
            size = size.checked_add(counts[e.dst].checked_mul(per)?)?;
        }
        if size > MAX_HSDF {
            return None;
        }
        let mut weight = Vec::with_capacity(offset[n]);
        let mut actor = Vec::with_capacity(offset[n]);
        for v in 0..n {
            for _ in 0..counts[v] {
                weight.push(wcet[v]);
                actor.push(v);
            }
        }
        let mut edges = Vec::new();
        for v in 0..n {
            // Firing k waits for firing k - 1 of the same node.
            let g = offset[v + 1] - offset[v];
            for k in 0..g {
                let next = offset[v] + (k + 1) % g;
                edges.push((offset[v] + k, next, u64::from(k + 1 == g)));
            }
        }
        for e in &level.edges {
            let (p, c, d) = (
                i128::from(e.produce),
                i128::from(e.consume),
                i128::from(e.initial_tokens),
            );
            let gs = i128::from(counts[e.src]);
            for k in 0..counts[e.dst] {
                let k = i128::from(k);
                let low = (k * c - d).div_euclid(p);
                let high = (k * c + c - 1 - d).div_euclid(p);
                for j in low.max(high - gs + 1)..=high {
                    let copy = usize::try_from(j.rem_euclid(gs)).ok()?;
                    let distance = u64::try_from(-j.div_euclid(gs)).ok()?;
                    let dst = offset[e.dst] + usize::try_from(k).ok()?;
                    edges.push((offset[e.src] + copy, dst, distance));
                }
            }
        }
        Some(Hsdf::from_edges(weight, edges, actor))
    }
}

/// Howard's policy iteration for the maximum cycle ratio (Cochet-Terrasson et
/// al. 1998, Dasdan 2004): each node keeps one outgoing edge (the policy); the
/// policy graph's cycles give each node a ratio λ and a potential x with
/// x(v) = w(v) - λ·t(e) + x(head e) along its policy edge e, x = 0 at the
/// smallest node of each cycle. The policy then moves to edges that reach a
/// larger λ, or else a larger potential, until none does; then the largest λ
/// is the maximum cycle ratio. A new cycle made by the second kind of move has
/// a strictly larger ratio, so the (λ, x) pairs only grow and it terminates.
///
/// Potentials are exact: with λ = num/den, x·den is an integer (kept in i128,
/// and equal λs have equal denominators since ratios are reduced).
/// Returns the ratio and the HSDF nodes of a cycle attaining it, in flow order.
fn max_cycle_ratio(g: &Hsdf) -> Option<(Ratio, Vec<usize>)> {
    let n = g.len();
    if n == 0 {
        return None;
    }
    let mut policy = Vec::with_capacity(n);
    for v in 0..n {
        // The edge with the fewest samples: a good first guess.
        policy.push(g.out(v).min_by_key(|&e| g.tokens[e])?);
    }
    let zero = Ratio { num: 0, den: 1 };
    let mut lambda = vec![zero; n];
    let mut x = vec![0i128; n];
    loop {
        let cycles = evaluate(g, &policy, &mut lambda, &mut x)?;
        let mut changed = false;
        for v in 0..n {
            let mut best = (lambda[v], policy[v]);
            for e in g.out(v) {
                if lambda[g.head[e]] > best.0 {
                    best = (lambda[g.head[e]], e);
                }
            }
            if best.1 != policy[v] {
                policy[v] = best.1;
                changed = true;
            }
        }
        if !changed {
            for v in 0..n {
                let l = lambda[v];
                let mut best = (x[v], policy[v]);
                for e in g.out(v) {
                    let u = g.head[e];
                    if lambda[u] != l {
                        continue;
                    }
                    let value = step(g.weight[v], g.tokens[e], l)?.checked_add(x[u])?;
                    if value > best.0 {
                        best = (value, e);
                    }
                }
                if best.1 != policy[v] {
                    policy[v] = best.1;
                    changed = true;
                }
            }
        }
        if !changed {
            // The first cycle found with the largest ratio.
            let mut best: Option<(Ratio, Vec<usize>)> = None;
            for (r, cycle) in cycles {
                if best.as_ref().is_none_or(|b| r > b.0) {
                    best = Some((r, cycle));
                }
            }
            return best;
        }
    }
}

/// `(w - λ·t)·den` for λ = num/den.
fn step(w: u64, t: u64, l: Ratio) -> Option<i128> {
    let a = i128::from(w).checked_mul(i128::from(l.den))?;
    let b = i128::from(l.num).checked_mul(i128::from(t))?;
    a.checked_sub(b)
}

/// Value determination: fills `lambda` and `x` for the policy and returns its
/// cycles (ratio, nodes in flow order starting at the smallest). `None` on a
/// cycle without samples (a deadlock) or on overflow.
fn evaluate(
    g: &Hsdf,
    policy: &[usize],
    lambda: &mut [Ratio],
    x: &mut [i128],
) -> Option<Vec<(Ratio, Vec<usize>)>> {
    const NEW: usize = usize::MAX;
    const DONE: usize = usize::MAX - 1;
    let n = g.len();
    let next = |v: usize| g.head[policy[v]];
    // NEW, DONE, or the position on the current path.
    let mut mark = vec![NEW; n];
    let mut path = Vec::new();
    let mut cycles = Vec::new();
    for start in 0..n {
        if mark[start] != NEW {
            continue;
        }
        path.clear();
        let mut v = start;
        while mark[v] == NEW {
            mark[v] = path.len();
            path.push(v);
            v = next(v);
        }
        let mut tail = path.len();
        if mark[v] != DONE {
            // A new cycle: path[mark[v]..].
            let at = mark[v];
            let mut cycle = path[at..].to_vec();
            tail = at;
            let (mut w, mut t) = (0u64, 0u64);
            for &c in &cycle {
                w = w.checked_add(g.weight[c])?;
                t = t.checked_add(g.tokens[policy[c]])?;
            }
            if t == 0 {
                return None;
            }
            let r = Ratio::new(w, t)?;
            let smallest = (0..cycle.len()).min_by_key(|&i| cycle[i])?;
            cycle.rotate_left(smallest);
            x[cycle[0]] = 0;
            lambda[cycle[0]] = r;
            for &c in cycle[1..].iter().rev() {
                x[c] = step(g.weight[c], g.tokens[policy[c]], r)?.checked_add(x[next(c)])?;
                lambda[c] = r;
            }
            for &c in &cycle {
                mark[c] = DONE;
            }
            cycles.push((r, cycle));
        }
        for &c in path[..tail].iter().rev() {
            let r = lambda[next(c)];
            x[c] = step(g.weight[c], g.tokens[policy[c]], r)?.checked_add(x[next(c)])?;
            lambda[c] = r;
            mark[c] = DONE;
        }
    }
    Some(cycles)
}

/// The level nodes of an HSDF cycle: consecutive firings of one node merged,
/// a walk going around the same level cycle several times reduced to once,
/// the first-declared node first.
fn level_cycle(mut walk: Vec<usize>) -> Vec<usize> {
    walk.dedup();
    while walk.len() > 1 && walk.first() == walk.last() {
        walk.pop();
    }
    let len = walk.len();
    if let Some(period) =
        (1..len).find(|&p| len % p == 0 && (p..len).all(|i| walk[i] == walk[i - p]))
    {
        walk.truncate(period);
    }
    if let Some(first) = (0..walk.len()).min_by_key(|&i| (walk[i], i)) {
        walk.rotate_left(first);
    }
    walk
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::FileId;
    use crate::taskgraph::analysis::consistency::repetition_vector;
    use crate::taskgraph::analysis::deadlock::find_deadlock;
    use crate::taskgraph::model::*;
    use std::collections::HashMap;

    use crate::taskgraph::analysis::testing::{self, port};

    fn task(name: &str, wcet: u64, ports: &[&str]) -> Task {
        Task {
            wcet: Some(wcet),
            ..testing::task(name, ports)
        }
    }

    fn channel(src: &str, dst: &str, tokens: u64) -> Channel {
        testing::channel(src, dst, tokens, 0)
    }

    fn graph(tasks: Vec<Task>, channels: Vec<Channel>) -> TaskGraph {
        testing::graph("g", tasks, channels)
    }

    fn ratio(num: u64, den: u64) -> Ratio {
        Ratio::new(num, den).unwrap()
    }

    /// Analyzes the top level, checking the result against the simulation.
    fn analyze(g: &TaskGraph) -> Throughput {
        let level = Level::build(g, None, g.name.clone());
        let counts = repetition_vector(&level).unwrap();
        assert_eq!(find_deadlock(&level, &counts), None);
        let t = throughput(&level, &counts).unwrap();
        assert_eq!(t.period, simulated_period(&level, &counts));
        t
    }

    fn two_node_cycle(tokens: u64) -> TaskGraph {
        graph(
            vec![task("A", 3, &["i<1", "o>1"]), task("B", 5, &["i<1", "o>1"])],
            vec![channel("A.o", "B.i", 0), channel("B.o", "A.i", tokens)],
        )
    }

    #[test]
    fn a_cycle_with_one_sample_runs_its_nodes_in_turn() {
        let t = analyze(&two_node_cycle(1));
        assert_eq!(t.period, ratio(8, 1));
        assert_eq!(t.critical_cycle, [0, 1]);
    }

    #[test]
    fn two_samples_let_both_nodes_work_at_once() {
        // The cycle's mean is (3 + 5) / 2 = 4, but B cannot overlap with
        // itself: its self-loop (5 per sample) bounds the period.
        let t = analyze(&two_node_cycle(2));
        assert_eq!(t.period, ratio(5, 1));
        assert_eq!(t.critical_cycle, [1]);
        // With B taking 4, the cycle and B alone tie at 4; with 3 and 3, the
        // cycle's (3 + 3) / 2 ties with both nodes.
        let mut g = two_node_cycle(2);
        g.tasks[1].wcet = Some(4);
        assert_eq!(analyze(&g).period, ratio(4, 1));
        g.tasks[1].wcet = Some(2);
        let t = analyze(&g);
        assert_eq!(t.period, ratio(3, 1), "A alone: 3 > (3 + 2) / 2");
        assert_eq!(t.critical_cycle, [0]);
        // Samples beyond one per node do not help further.
        g.channels[1].initial_tokens = 7;
        assert_eq!(analyze(&g).period, ratio(3, 1));
    }

    #[test]
    fn an_exact_fraction_period() {
        // The cycle A → B → C → A with 3 samples and times 3, 4, 4 has mean
        // 11/3, above each node alone (4).
        let g = graph(
            vec![
                task("A", 3, &["i<1", "o>1"]),
                task("B", 4, &["i<1", "o>1"]),
                task("C", 4, &["i<1", "o>1"]),
            ],
            vec![
                channel("A.o", "B.i", 0),
                channel("B.o", "C.i", 0),
                channel("C.o", "A.i", 2),
            ],
        );
        // With 2 samples: 11/2.
        let t = analyze(&g);
        assert_eq!(t.period, ratio(11, 2));
        assert_eq!(t.critical_cycle, [0, 1, 2]);
    }

    #[test]
    fn an_acyclic_chain_is_bounded_by_its_slowest_node() {
        let g = graph(
            vec![task("A", 2, &["o>1"]), task("B", 7, &["i<1"])],
            vec![channel("A.o", "B.i", 0)],
        );
        let t = analyze(&g);
        assert_eq!(t.period, ratio(7, 1));
        assert_eq!(t.critical_cycle, [1]);
    }

    /// A(2) produces 2 samples per firing for B(3), which consumes 1, so
    /// γ = (1, 2); B sends 1 back per firing, A takes 2, with `tokens`
    /// initial samples on the way back.
    fn multirate(tokens: u64, b_time: u64) -> TaskGraph {
        graph(
            vec![
                task("A", 2, &["i<2", "o>2"]),
                task("B", b_time, &["i<1", "o>1"]),
            ],
            vec![channel("A.o", "B.i", 0), channel("B.o", "A.i", tokens)],
        )
    }

    #[test]
    fn multirate_cycle_worked_out_by_hand() {
        // HSDF nodes A0, B0, B1. A → B (p 2, c 1, d 0): B_k takes sample k,
        // made by A firing ⌊k/2⌋ = 0 of the same iteration: A0→B0, A0→B1, no
        // samples. B → A (p 1, c 2, d 2): A0 takes samples 0 and 1, i.e. the
        // initial ones, j = -2 and -1: B0 and B1 one iteration earlier:
        // B0→A0 and B1→A0 with 1 sample each. Self-loops: A0→A0 (1),
        // B0→B1 (0), B1→B0 (1). Cycle means: A0→B0→B1→A0 is (2+3+3)/1 = 8,
        // A0→B0→A0 and A0→B1→A0 5, B0→B1→B0 6, A0 2. Period 8: A, then B
        // twice in a row, then A can fire again.
        let t = analyze(&multirate(2, 3));
        assert_eq!(t.period, ratio(8, 1));
        assert_eq!(t.critical_cycle, [0, 1]);

        // With 4 samples back, B0→A0 and B1→A0 carry 2 (j = -4, -3): the
        // cycle through A and both B firings has mean 8/2 = 4, and B's
        // own chain B0→B1→B0 (6/1) bounds the period.
        let t = analyze(&multirate(4, 3));
        assert_eq!(t.period, ratio(6, 1));
        assert_eq!(t.critical_cycle, [1]);

        // 3 samples, B taking 1: A0 takes j = -3 (B1, 2 samples) and j = -2
        // (B0, 1 sample). A0→B0→A0 is (2+1)/1 = 3; A0→B0→B1→A0 (2+1+1)/2,
        // A0→B1→B0→A0 4/2, B's chain 2, A's 2. Period 3, on A and B.
        let t = analyze(&multirate(3, 1));
        assert_eq!(t.period, ratio(3, 1));
        assert_eq!(t.critical_cycle, [0, 1]);
    }

    #[test]
    fn an_empty_level_has_no_period() {
        let g = graph(Vec::new(), Vec::new());
        let level = Level::build(&g, None, "g".into());
        assert_eq!(throughput(&level, &[]), None);
    }

    #[test]
    fn cycle_walks_are_reduced_to_level_cycles() {
        assert_eq!(level_cycle(vec![3, 3, 3]), [3]);
        assert_eq!(level_cycle(vec![2, 0, 2, 0]), [0, 2]);
        assert_eq!(level_cycle(vec![1, 1, 2, 0, 0, 1]), [0, 1, 2]);
        assert_eq!(level_cycle(vec![2, 1, 2, 0]), [0, 2, 1, 2]);
    }

    /// Small random consistent levels (a fixed pseudo-random sequence): the
    /// policy iteration agrees with the simulation on all that do not
    /// deadlock.
    #[test]
    fn random_levels_agree_with_simulation() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % m
        };
        let mut checked = 0;
        for _ in 0..300 {
            let n = 2 + next(4) as usize;
            let gamma: Vec<u64> = (0..n).map(|_| 1 + next(3)).collect();
            let mut tasks: Vec<Task> = (0..n)
                .map(|v| task(&format!("T{v}"), next(6), &[]))
                .collect();
            let mut channels = Vec::new();
            for i in 0..n + next(4) as usize {
                let (s, d) = if i < n {
                    (i, (i + 1) % n)
                } else {
                    (next(n as u64) as usize, next(n as u64) as usize)
                };
                // γ(s)·p = γ(d)·c.
                let l = super::super::ratio::lcm(gamma[s], gamma[d]).unwrap() * (1 + next(2));
                let (p, c) = (l / gamma[s], l / gamma[d]);
                tasks[s].ports.push(port(&format!("o{i}>{p}")));
                tasks[d].ports.push(port(&format!("i{i}<{c}")));
                let tokens = next(2 * l + 1);
                channels.push(channel(
                    &format!("T{s}.o{i}"),
                    &format!("T{d}.i{i}"),
                    tokens,
                ));
            }
            let g = graph(tasks, channels);
            let level = Level::build(&g, None, "g".into());
            let counts = repetition_vector(&level).unwrap();
            if find_deadlock(&level, &counts).is_some() {
                continue;
            }
            let t = throughput(&level, &counts).unwrap();
            assert_eq!(t.period, simulated_period(&level, &counts), "{g:#?}");
            checked += 1;
        }
        assert!(checked > 100, "{checked}");
    }

    const SDF3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sdf3");

    #[test]
    fn every_sdf3_graph_agrees_with_simulation() {
        let mut files: Vec<_> = std::fs::read_dir(SDF3)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "xml"))
            .collect();
        files.sort();
        assert_eq!(files.len(), 11);
        let mut periods = Vec::new();
        for path in files {
            let text = std::fs::read_to_string(&path).unwrap();
            let (g, _) = crate::taskgraph::load_task_graph(FileId(0), &text);
            let g = g.unwrap();
            let level = Level::build(&g, None, g.name.clone());
            let counts = repetition_vector(&level).unwrap();
            let started = std::time::Instant::now();
            let t = throughput(&level, &counts).unwrap();
            let elapsed = started.elapsed();
            assert!(t.period.num > 0, "{}", path.display());
            assert!(elapsed.as_secs() < 2, "{}: {elapsed:?}", path.display());
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            let cycle: Vec<&str> = t
                .critical_cycle
                .iter()
                .map(|&v| level.nodes[v].name.as_str())
                .collect();
            eprintln!("{name}: period {} on {cycle:?} ({elapsed:?})", t.period);
            assert_eq!(
                t.period,
                simulated_period(&level, &counts),
                "{}",
                path.display()
            );
            periods.push((name, t.period));
        }
        // Each checked against the simulation above.
        let expected = [
            ("h263decoder", 332046),
            ("h263encoder", 1232530),
            ("modem", 16),
            ("mp3decoder_block_parallelism", 3732276),
            ("mp3decoder_granule_parallelism", 3732276),
            ("mp3playback", 120000),
            ("random_1000", 7378),
            ("random_200", 1422),
            ("random_50", 280),
            ("samplerate", 960),
            ("satellite", 1056),
        ];
        let expected: Vec<(String, Ratio)> = expected
            .iter()
            .map(|&(name, period)| (name.to_string(), ratio(period, 1)))
            .collect();
        assert_eq!(periods, expected);
    }

    #[test]
    fn overflow_and_huge_expansions_give_none_without_panicking() {
        let mut g = two_node_cycle(1);
        g.tasks[0].wcet = Some(u64::MAX);
        g.tasks[1].wcet = Some(u64::MAX);
        let level = Level::build(&g, None, "g".into());
        assert_eq!(throughput(&level, &[1, 1]), None);
        // Times that fit: the exact period, far beyond what f64 holds exactly.
        g.tasks[0].wcet = Some(u64::MAX / 2 - 1);
        g.tasks[1].wcet = Some(1);
        let level = Level::build(&g, None, "g".into());
        assert_eq!(
            throughput(&level, &[1, 1]).map(|t| t.period),
            Some(ratio(u64::MAX / 2, 1))
        );
        let g = graph(
            vec![task("A", 1, &["o>1000000000"]), task("B", 1, &["i<1"])],
            vec![channel("A.o", "B.i", 0)],
        );
        let level = Level::build(&g, None, "g".into());
        let counts = repetition_vector(&level).unwrap();
        assert_eq!(counts, [1, 1_000_000_000]);
        assert_eq!(throughput(&level, &counts), None);
        assert_eq!(throughput(&level, &[1]), None, "counts of another level");
    }

    /// The period of the self-timed execution found by running it: each node
    /// fires as soon as its inputs allow and it is idle, taking its wcet. Each
    /// strongly connected part is run alone until its state (samples on its
    /// edges, remaining time of each node) repeats at a start of its first
    /// node; the level's period is the largest (with unbounded channels, a
    /// faster part upstream or downstream does not change a part's period).
    fn simulated_period(level: &Level<'_>, counts: &[u64]) -> Ratio {
        let wcet: Vec<u64> = level.nodes.iter().map(|n| n.wcet.unwrap_or(0)).collect();
        components(level)
            .iter()
            .map(|part| simulate_part(level, counts, &wcet, part))
            .max()
            .unwrap()
    }

    fn simulate_part(level: &Level<'_>, counts: &[u64], wcet: &[u64], part: &[usize]) -> Ratio {
        if part.iter().all(|&v| wcet[v] == 0) {
            return Ratio::new(0, 1).unwrap();
        }
        let n = level.nodes.len();
        let mut inside = vec![false; n];
        for &v in part {
            inside[v] = true;
        }
        let edges: Vec<&super::super::level::Edge> = level
            .edges
            .iter()
            .filter(|e| inside[e.src] && inside[e.dst])
            .collect();
        let mut tokens: Vec<u64> = edges.iter().map(|e| e.initial_tokens).collect();
        let mut busy = vec![0u64; n]; // remaining time; 0 when idle
        let reference = part[0];
        let (mut time, mut fired) = (0u64, 0u64);
        let mut seen: HashMap<(Vec<u64>, Vec<u64>), (u64, u64)> = HashMap::new();
        let mut inputs = vec![Vec::new(); n];
        let mut outputs = vec![Vec::new(); n];
        for (i, e) in edges.iter().enumerate() {
            inputs[e.dst].push(i);
            outputs[e.src].push(i);
        }
        let produce = |v: usize, tokens: &mut Vec<u64>| {
            for &i in &outputs[v] {
                tokens[i] += edges[i].produce;
            }
        };
        for _ in 0..10_000_000 {
            let mut started = false;
            loop {
                let mut progress = false;
                for &v in part {
                    if busy[v] > 0 || inputs[v].iter().any(|&i| tokens[i] < edges[i].consume) {
                        continue;
                    }
                    for &i in &inputs[v] {
                        tokens[i] -= edges[i].consume;
                    }
                    if wcet[v] == 0 {
                        produce(v, &mut tokens);
                    } else {
                        busy[v] = wcet[v];
                    }
                    if v == reference {
                        fired += 1;
                        started = true;
                    }
                    progress = true;
                }
                if !progress {
                    break;
                }
            }
            if started {
                let state = (tokens.clone(), part.iter().map(|&v| busy[v]).collect());
                if let Some((t0, f0)) = seen.insert(state, (time, fired)) {
                    return Ratio::new((time - t0) * counts[reference], fired - f0).unwrap();
                }
            }
            let dt = part
                .iter()
                .map(|&v| busy[v])
                .filter(|&b| b > 0)
                .min()
                .expect("deadlock in simulation");
            time += dt;
            for &v in part {
                if busy[v] > 0 {
                    busy[v] -= dt;
                    if busy[v] == 0 {
                        produce(v, &mut tokens);
                    }
                }
            }
        }
        panic!("no periodic state within the step budget");
    }

    /// Strongly connected components (Kosaraju), each listed by node index.
    fn components(level: &Level<'_>) -> Vec<Vec<usize>> {
        let n = level.nodes.len();
        let mut out = vec![Vec::new(); n];
        let mut inn = vec![Vec::new(); n];
        for e in &level.edges {
            out[e.src].push(e.dst);
            inn[e.dst].push(e.src);
        }
        let mut order = Vec::new();
        let mut seen = vec![false; n];
        for root in 0..n {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            let mut stack = vec![(root, 0)];
            while let Some((v, i)) = stack.pop() {
                if i < out[v].len() {
                    stack.push((v, i + 1));
                    let u = out[v][i];
                    if !seen[u] {
                        seen[u] = true;
                        stack.push((u, 0));
                    }
                } else {
                    order.push(v);
                }
            }
        }
        let mut part = vec![usize::MAX; n];
        let mut parts: Vec<Vec<usize>> = Vec::new();
        for &root in order.iter().rev() {
            if part[root] != usize::MAX {
                continue;
            }
            let id = parts.len();
            part[root] = id;
            let mut members = vec![root];
            let mut stack = vec![root];
            while let Some(v) = stack.pop() {
                for &u in &inn[v] {
                    if part[u] == usize::MAX {
                        part[u] = id;
                        members.push(u);
                        stack.push(u);
                    }
                }
            }
            members.sort();
            parts.push(members);
        }
        parts
    }
}
