//! Throughput: the iteration period of the self-timed execution of a level
//! (every node fires as soon as its input samples are there), which is the
//! maximum cycle mean of the equivalent homogeneous SDF graph (HSDF), and the
//! cycle that attains it.
//!
//! Two meanings of a node firing ([`Concurrency`]): with `Single` (our task
//! graphs, as the generated code runs them: one thread per task) a node cannot
//! overlap with itself, which the HSDF models by chaining the firings of each
//! node with one sample on the edge from its last firing back to its first:
//! even an acyclic level has cycles, and its period is at least every node's
//! γ·wcet. With `Auto` (SDF3's meaning of its own files) a node fires
//! concurrently with itself as often as its input samples allow: only the
//! level's channels (a self-loop channel among them) bound it, and a level
//! without a cycle has period 0 (no bound on its throughput).
//!
//! Method: the level's strongly connected parts are analysed side by side,
//! without the channels between them (every cycle lies within one part, and
//! those channels are unbounded), each part at its own repetition vector
//! (the level's counts divided by their gcd over the part) with its
//! execution times multiplied by that gcd, so that its period counts per
//! iteration of the level; the largest bounds the level. They are expanded
//! to their HSDF (when every repetition count is 1 they already are one,
//! and only their edges are read, no firing is copied), or executed
//! symbolically for one iteration where that costs less ([`symbolic`]), then
//! Howard's policy iteration finds the maximum cycle ratio (execution time
//! over initial samples) in exact arithmetic.
//!
//! Complexity: the HSDF has N = Σγ nodes and M ≤ N + Σ γ(dst)·min(⌈c/p⌉+1,
//! γ(src)) edges (summed over the level's edges); building it is O(N + M).
//! Each policy iteration is O(N + M); their number has no known polynomial
//! bound but is small in practice (2 to 15 on the SDF3 benchmarks, whose
//! HSDFs have up to 10 601 nodes and 37 094 edges).

use super::level::Level;
use super::ratio::Ratio;

/// Whether a node may fire concurrently with itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Concurrency {
    /// Auto-concurrency (SDF3): as many firings of a node at once as its
    /// input samples allow; a self-loop channel with `n` samples limits it to
    /// `n` at a time.
    Auto,
    /// One firing at a time per node (our task graphs and generated code).
    Single,
}

impl Concurrency {
    /// The meaning of a file of `format`: SDF3's own for SDF3 files, ours for
    /// ours.
    pub fn of(format: crate::taskgraph::GraphFormat) -> Concurrency {
        match format {
            crate::taskgraph::GraphFormat::Sdf3 => Concurrency::Auto,
            crate::taskgraph::GraphFormat::SemoXml => Concurrency::Single,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Concurrency::Auto => "auto",
            Concurrency::Single => "single",
        }
    }
}

/// The throughput of one level.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Throughput {
    /// Time units per iteration of the level, exact.
    pub period: Ratio,
    /// Nodes of the level around the cycle that bounds the period, in flow
    /// order, the first-declared node first. A single node means that node
    /// alone bounds it (its firings of one iteration back to back, or its
    /// self-loop channel). Empty when no cycle bounds the period (period 0,
    /// only with [`Concurrency::Auto`]).
    pub critical_cycle: Vec<usize>,
    /// The level nodes of the critical cycle's firings in flow order, as
    /// the engine found it, before [`Throughput::critical_cycle`] merges
    /// consecutive firings of one node and repeated rounds: each entry and
    /// the next (the last and the first) are joined by a channel between
    /// those nodes (a self-loop, or a node's chain of firings, when they are
    /// the same node). Empty when `critical_cycle` is.
    pub walk: Vec<usize>,
}

/// Most HSDF nodes plus edges built before giving up (about 150 MB).
const MAX_HSDF: u64 = 1 << 23;

/// Why a level has no period: every report without one says which, so that
/// a period is never silently missing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoPeriod {
    /// The rates are inconsistent (no repetition vector).
    Inconsistent,
    /// One iteration deadlocks.
    Deadlock,
    /// No task of the level has an execution time (or the level is empty).
    Untimed,
    /// One iteration expanded would exceed 2^23 nodes plus edges.
    TooLarge,
    /// The exact arithmetic of the period would overflow 64 (or 128) bits.
    Overflow,
}

impl NoPeriod {
    /// Why, in words (after "no period: ").
    pub fn why(self) -> &'static str {
        match self {
            NoPeriod::Inconsistent => "the rates are inconsistent",
            NoPeriod::Deadlock => "an iteration deadlocks",
            NoPeriod::Untimed => "no task has an execution time above 0",
            NoPeriod::TooLarge => {
                "one iteration has too many firings to expand (over 2^23 firings plus dependencies)"
            }
            NoPeriod::Overflow => {
                "its exact arithmetic overflows (rates, samples or times too large)"
            }
        }
    }

    /// A name for machines (JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            NoPeriod::Inconsistent => "inconsistent",
            NoPeriod::Deadlock => "deadlock",
            NoPeriod::Untimed => "untimed",
            NoPeriod::TooLarge => "too_large",
            NoPeriod::Overflow => "overflow",
        }
    }
}

/// The period of the self-timed execution of `level` with repetition vector
/// `counts`, taking each task's `wcet` (0 when unknown or for boundary nodes)
/// as its execution time, a node firing as `concurrency` says. The level must
/// be consistent and deadlock-free.
///
/// No period (rather than a wrong or panicking answer) for an empty level
/// ([`NoPeriod::Untimed`]), when `counts` does not fit the level
/// ([`NoPeriod::Inconsistent`]), when the HSDF would exceed 2^23 nodes plus
/// edges (`MAX_HSDF`), or when the exact arithmetic would overflow (also
/// said when a cycle without initial samples is met: the callers find
/// deadlocks first).
pub fn throughput(
    level: &Level<'_>,
    counts: &[u64],
    concurrency: Concurrency,
) -> Result<Throughput, NoPeriod> {
    let n = level.nodes.len();
    if n == 0 {
        return Err(NoPeriod::Untimed);
    }
    if counts.len() != n || counts.contains(&0) {
        return Err(NoPeriod::Inconsistent); // not a repetition vector of it
    }
    let wcet: Vec<u64> = level
        .nodes
        .iter()
        .map(|node| node.wcet.unwrap_or(0))
        .collect();
    let sdf = Sdf::of(level);
    let chained = chained(&sdf, concurrency);
    // The strongly connected parts at their own rates: every cycle lies
    // within one part, and the channels between parts are unbounded, so they
    // bound nothing and are left out. Each part then runs its own iteration
    // (the level's counts divided by their gcd g over the part:
    // `mp3playback`'s 10,601 firings per iteration become parts of 1, 1 and
    // 2), which the level's iteration runs g times; a period is linear in
    // the execution times, so taking each node's time g times over gives
    // the part's period per iteration of the level. One run of an engine on
    // the parts side by side gives the largest. Of parts that tie, the
    // policy iteration names the cycle it meets first: on the HSDF, the
    // part's with the first-declared node; on the symbolic iteration's
    // matrix, the part's with the first initial samples.
    let (part, parts) = crate::digraph::components(n, sdf.edges.iter().map(|e| (e.src, e.dst)));
    let mut gcd = vec![0; parts];
    for (v, &count) in counts.iter().enumerate() {
        gcd[part[v]] = super::ratio::gcd(gcd[part[v]], count);
    }
    let own_counts: Vec<u64> = (0..n).map(|v| counts[v] / gcd[part[v]]).collect();
    let times = (0..n)
        .map(|v| wcet[v].checked_mul(gcd[part[v]]))
        .collect::<Option<Vec<u64>>>()
        .ok_or(NoPeriod::Overflow)?;
    let parts = Sdf {
        nodes: n,
        edges: sdf
            .edges
            .into_iter()
            .filter(|e| part[e.src] == part[e.dst])
            .collect(),
    };
    period(&parts, &own_counts, &times, &chained)
}

/// What the engines read of a level: its rates and samples, no names.
struct Sdf {
    nodes: usize,
    edges: Vec<Rates>,
}

#[derive(Clone, Copy, Debug)]
struct Rates {
    src: usize,
    dst: usize,
    produce: u64,
    consume: u64,
    initial_tokens: u64,
}

impl Sdf {
    fn of(level: &Level<'_>) -> Sdf {
        let edges = level.edges.iter().map(|e| Rates {
            src: e.src,
            dst: e.dst,
            produce: e.produce,
            consume: e.consume,
            initial_tokens: e.initial_tokens,
        });
        Sdf {
            nodes: level.nodes.len(),
            edges: edges.collect(),
        }
    }
}

/// [`throughput`] of the level's parts at their own rates, by whichever
/// engine costs less.
fn period(
    sdf: &Sdf,
    counts: &[u64],
    wcet: &[u64],
    chained: &[bool],
) -> Result<Throughput, NoPeriod> {
    let direct = counts.iter().all(|&c| c == 1) && sdf.edges.iter().all(|e| e.produce == e.consume);
    if !direct && symbolic_is_cheaper(sdf, counts, chained) {
        if let Some((period, walk)) = symbolic::period(sdf, counts, wcet, chained) {
            return Ok(Throughput {
                period,
                critical_cycle: level_cycle(walk.clone()),
                walk,
            });
        }
    }
    let hsdf = if direct {
        Hsdf::direct(sdf, wcet.to_vec(), chained)
    } else {
        Hsdf::expand(sdf, counts, wcet, chained)?
    };
    let Some(hsdf) = hsdf.on_cycles() else {
        return Ok(Throughput {
            period: Ratio { num: 0, den: 1 },
            critical_cycle: Vec::new(),
            walk: Vec::new(),
        });
    };
    let (period, cycle) = max_cycle_ratio(&hsdf).ok_or(NoPeriod::Overflow)?;
    let walk: Vec<usize> = cycle.iter().map(|&v| hsdf.actor(v)).collect();
    Ok(Throughput {
        period,
        critical_cycle: level_cycle(walk.clone()),
        walk,
    })
}

/// Per node, whether its firings are chained, one after the other: with
/// [`Concurrency::Single`] every node's, except a node whose self-loop
/// channel already lets only one of its firings run at a time (rates `p`
/// and `p ≤ samples < 2p`: firing k + 1 needs the samples firing k gives
/// back), where a chain would be a second copy of the same constraint. That
/// keeps the work of `Single` at `Auto`'s on graphs that limit every node so
/// (`mp3playback`: the symbolic iteration follows the file's 6 samples, not
/// 10).
fn chained(sdf: &Sdf, concurrency: Concurrency) -> Vec<bool> {
    let mut chained = vec![concurrency == Concurrency::Single; sdf.nodes];
    for e in &sdf.edges {
        let one_at_a_time = e.src == e.dst
            && e.produce == e.consume
            && e.produce <= e.initial_tokens
            && e.initial_tokens / 2 < e.produce;
        if one_at_a_time {
            chained[e.src] = false;
        }
    }
    chained
}

/// Whether the symbolic iteration ([`symbolic`]) costs less than the HSDF
/// expansion. Its steps (a max over D integers) are several times cheaper
/// than the expansion's (edges sorted, then policy iterations in exact
/// ratios), hence the factor.
fn symbolic_is_cheaper(sdf: &Sdf, counts: &[u64], chained: &[bool]) -> bool {
    const STEP_RATIO: u64 = 8;
    match (
        symbolic::cost(sdf, counts, chained),
        Hsdf::expanded_size(sdf, counts),
    ) {
        (Some(symbolic), Some(hsdf)) => symbolic <= hsdf.saturating_mul(STEP_RATIO),
        _ => false,
    }
}

mod symbolic;

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

    /// Edges grouped by source in one counting pass (each source's edges
    /// in the order given, as a stable sort would leave them): a sort of the
    /// expansion's edges was a tenth of a small graph's whole analysis.
    fn from_edges(weight: Vec<u64>, edges: Vec<(usize, usize, u64)>, actor: Vec<usize>) -> Hsdf {
        let n = weight.len();
        let mut first = vec![0; n + 1];
        for &(src, _, _) in &edges {
            first[src + 1] += 1;
        }
        for v in 0..n {
            first[v + 1] += first[v];
        }
        let mut next = first.clone();
        let mut head = vec![0; edges.len()];
        let mut tokens = vec![0; edges.len()];
        for (src, dst, t) in edges {
            head[next[src]] = dst;
            tokens[next[src]] = t;
            next[src] += 1;
        }
        Hsdf {
            weight,
            first,
            head,
            tokens,
            actor,
        }
    }

    /// Every node fires once per iteration (and so every edge has equal
    /// rates): the level is its own HSDF. An edge with `d` samples and rate
    /// `p` lets a firing depend on the firing `⌊d/p⌋` iterations earlier.
    /// `chained`: each of those nodes also waits for its own previous firing.
    fn direct(sdf: &Sdf, weight: Vec<u64>, chained: &[bool]) -> Hsdf {
        let n = sdf.nodes;
        let edges = sdf
            .edges
            .iter()
            .map(|e| (e.src, e.dst, e.initial_tokens / e.produce))
            .chain((0..n).filter(|&v| chained[v]).map(|v| (v, v, 1)))
            .collect();
        Hsdf::from_edges(weight, edges, Vec::new())
    }

    /// At most how many nodes plus edges [`Hsdf::expand`] makes.
    fn expanded_size(sdf: &Sdf, counts: &[u64]) -> Option<u64> {
        let total = counts.iter().try_fold(0u64, |s, &c| s.checked_add(c))?;
        let mut size = total.checked_mul(2)?;
        for e in &sdf.edges {
            let per = (e.consume.div_ceil(e.produce).saturating_add(1)).min(counts[e.src]);
            size = size.checked_add(counts[e.dst].checked_mul(per)?)?;
        }
        Some(size)
    }

    /// The classic SDF→HSDF expansion: node (v, k) for each firing k < γ(v).
    /// On an edge with rates p, c and d initial samples, firing k of the
    /// destination consumes the samples numbered k·c .. k·c + c - 1 of the
    /// iteration, the d initial ones counted first; sample n comes from firing
    /// j = ⌊(n - d)/p⌋ of the source, which is firing j mod γ(src) of the
    /// iteration ⌈-j/γ(src)⌉ earlier when j < 0: the HSDF edge carries that
    /// many samples. Of several dependencies on the same source firing only
    /// the nearest iteration matters, so j runs over at most γ(src) values.
    /// `chained`: firing k of such a node also waits for its firing k - 1.
    fn expand(sdf: &Sdf, counts: &[u64], wcet: &[u64], chained: &[bool]) -> Result<Hsdf, NoPeriod> {
        // Every count and sum below is at most the size, checked first.
        if Hsdf::expanded_size(sdf, counts).is_none_or(|size| size > MAX_HSDF) {
            return Err(NoPeriod::TooLarge);
        }
        let n = sdf.nodes;
        let mut offset = Vec::with_capacity(n + 1);
        let mut total = 0usize;
        offset.push(0usize);
        for &c in counts {
            total += c as usize;
            offset.push(total);
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
        for v in (0..n).filter(|&v| chained[v]) {
            // Firing k waits for firing k - 1 of the same node.
            let g = offset[v + 1] - offset[v];
            for k in 0..g {
                let next = offset[v] + (k + 1) % g;
                edges.push((offset[v] + k, next, u64::from(k + 1 == g)));
            }
        }
        for e in &sdf.edges {
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
                    let overflow = |_| NoPeriod::Overflow;
                    let copy = usize::try_from(j.rem_euclid(gs)).map_err(overflow)?;
                    let distance = u64::try_from(-j.div_euclid(gs)).map_err(overflow)?;
                    let dst = offset[e.dst] + usize::try_from(k).map_err(overflow)?;
                    edges.push((offset[e.src] + copy, dst, distance));
                }
            }
        }
        Ok(Hsdf::from_edges(weight, edges, actor))
    }
}

impl Hsdf {
    /// The part of the graph whose nodes reach a cycle (every node keeps an
    /// outgoing edge, as the policy iteration needs); the others lie on no
    /// cycle and do not bound the period. `None` when no node is on a cycle.
    fn on_cycles(self) -> Option<Hsdf> {
        let n = self.len();
        let mut outs: Vec<usize> = (0..n).map(|v| self.out(v).len()).collect();
        if outs.iter().all(|&d| d > 0) {
            return Some(self);
        }
        let mut into = vec![Vec::new(); n];
        for v in 0..n {
            for e in self.out(v) {
                into[self.head[e]].push(v);
            }
        }
        let mut dead: Vec<usize> = (0..n).filter(|&v| outs[v] == 0).collect();
        let mut alive = vec![true; n];
        while let Some(v) = dead.pop() {
            alive[v] = false;
            for &u in &into[v] {
                outs[u] -= 1;
                if outs[u] == 0 {
                    dead.push(u);
                }
            }
        }
        let mut index = vec![usize::MAX; n];
        let mut kept = Vec::new();
        for v in (0..n).filter(|&v| alive[v]) {
            index[v] = kept.len();
            kept.push(v);
        }
        if kept.is_empty() {
            return None;
        }
        let mut edges = Vec::new();
        for &v in &kept {
            for e in self.out(v) {
                let u = self.head[e];
                if alive[u] {
                    edges.push((index[v], index[u], self.tokens[e]));
                }
            }
        }
        let weight = kept.iter().map(|&v| self.weight[v]).collect();
        let actor = kept.iter().map(|&v| self.actor(v)).collect();
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
/// Potentials are exact: with λ = num/den, x·den is an integer (equal λs
/// have equal denominators since ratios are reduced), kept in an `i64`; where
/// the `i64` run gives no answer, an `i128` run from the start again (the
/// same steps, so the same answer where both give one). Only an overflow of
/// the `i64`s needs that second run: the analyses find deadlocks (a cycle
/// without samples, the other `None`) before they ask for a period.
/// Returns the ratio and the HSDF nodes of a cycle attaining it, in flow order.
fn max_cycle_ratio(g: &Hsdf) -> Option<(Ratio, Vec<usize>)> {
    policy_iteration::<i64>(g).or_else(|| policy_iteration::<i128>(g))
}

/// An integer type for the potentials of [`max_cycle_ratio`]: every
/// operation `None` on overflow.
trait Potential: Copy + Ord + Default {
    /// `a·b`.
    fn product(a: u64, b: u64) -> Option<Self>;
    fn checked_add(self, other: Self) -> Option<Self>;
    fn checked_sub(self, other: Self) -> Option<Self>;
}

macro_rules! potential {
    ($t:ty) => {
        impl Potential for $t {
            /// The product of two `u64`s always fits a `u128`, and checking
            /// that it fits is a comparison, where checked multiplication of
            /// `i128`s is a call into the runtime.
            fn product(a: u64, b: u64) -> Option<$t> {
                <$t>::try_from(u128::from(a) * u128::from(b)).ok()
            }
            fn checked_add(self, other: $t) -> Option<$t> {
                <$t>::checked_add(self, other)
            }
            fn checked_sub(self, other: $t) -> Option<$t> {
                <$t>::checked_sub(self, other)
            }
        }
    };
}
potential!(i64);
potential!(i128);

/// [`max_cycle_ratio`] with potentials of type `P`; `None` also when one
/// overflows `P`.
fn policy_iteration<P: Potential>(g: &Hsdf) -> Option<(Ratio, Vec<usize>)> {
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
    let mut x = vec![P::default(); n];
    loop {
        let cycles = evaluate(g, &policy, &mut lambda, &mut x)?;
        // Every node's λ is the ratio of the cycle its policy leads to: when
        // all the cycles have one ratio, no edge leads to a larger λ, and the
        // pass looking for one is skipped (most of the passes, on a strongly
        // connected graph).
        let one_ratio = cycles.windows(2).all(|pair| pair[0].0 == pair[1].0);
        let mut changed = false;
        if !one_ratio {
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
        }
        if !changed {
            for v in 0..n {
                let l = lambda[v];
                // `step`'s first term, the same for every edge of `v` (and
                // computed by it at least once: `v`'s policy edge leads to
                // its own λ).
                let w = P::product(g.weight[v], l.den)?;
                let mut best = (x[v], policy[v]);
                // The edges as slices: no bounds check per edge.
                let out = g.out(v);
                let edges = g.head[out.clone()].iter().zip(&g.tokens[out.clone()]);
                for (e, (&u, &tokens)) in out.zip(edges) {
                    if !one_ratio && lambda[u] != l {
                        continue;
                    }
                    // Most HSDF edges carry no sample: no product.
                    let t = match tokens {
                        0 => P::default(),
                        tokens => P::product(l.num, tokens)?,
                    };
                    let value = w.checked_sub(t)?.checked_add(x[u])?;
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
fn step<P: Potential>(w: u64, t: u64, l: Ratio) -> Option<P> {
    let a = P::product(w, l.den)?;
    let b = P::product(l.num, t)?;
    a.checked_sub(b)
}

/// Value determination: fills `lambda` and `x` for the policy and returns its
/// cycles (ratio, nodes in flow order starting at the smallest). `None` on a
/// cycle without samples (a deadlock) or on overflow.
fn evaluate<P: Potential>(
    g: &Hsdf,
    policy: &[usize],
    lambda: &mut [Ratio],
    x: &mut [P],
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
            x[cycle[0]] = P::default();
            lambda[cycle[0]] = r;
            for &c in cycle[1..].iter().rev() {
                x[c] = step::<P>(g.weight[c], g.tokens[policy[c]], r)?.checked_add(x[next(c)])?;
                lambda[c] = r;
            }
            for &c in &cycle {
                mark[c] = DONE;
            }
            cycles.push((r, cycle));
        }
        for &c in path[..tail].iter().rev() {
            let r = lambda[next(c)];
            x[c] = step::<P>(g.weight[c], g.tokens[policy[c]], r)?.checked_add(x[next(c)])?;
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
    use proptest::prelude::*;

    use crate::taskgraph::analysis::testing::{self, port, random_level, simulated_period};

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
        let t = throughput(&level, &counts, Concurrency::Single).unwrap();
        assert_eq!(
            t.period,
            simulated_period(&level, &counts, Concurrency::Single)
        );
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

    /// A → B, A taking `a` and B `b`, B consuming `rate` samples a firing.
    fn chain(a: u64, b: u64, rate: u64) -> TaskGraph {
        graph(
            vec![
                task("A", a, &["o>1"]),
                task("B", b, &[&format!("i<{rate}")]),
            ],
            vec![channel("A.o", "B.i", 0)],
        )
    }

    #[test]
    fn an_acyclic_chain_is_bounded_by_its_slowest_node() {
        let t = analyze(&chain(2, 7, 1));
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
        assert_eq!(
            throughput(&level, &[], Concurrency::Single),
            Err(NoPeriod::Untimed)
        );
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
            let t = throughput(&level, &counts, Concurrency::Single).unwrap();
            assert_eq!(
                t.period,
                simulated_period(&level, &counts, Concurrency::Single),
                "{g:#?}"
            );
            checked += 1;
        }
        assert!(checked > 100, "{checked}");
    }

    /// The throughput of `level`, its period checked against the self-timed
    /// simulation.
    fn simulated(
        level: &Level<'_>,
        counts: &[u64],
        concurrency: Concurrency,
    ) -> Result<Throughput, TestCaseError> {
        let t = throughput(level, counts, concurrency).unwrap();
        prop_assert_eq!(
            t.period,
            simulated_period(level, counts, concurrency),
            "{:?}",
            concurrency
        );
        Ok(t)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Both readings of concurrency, both engines (the direct HSDF and
        /// the expansion), with and without self-loop channels: the period
        /// is the one the self-timed simulation reaches, and with `Single`
        /// a self-loop of one sample on every node changes nothing.
        #[test]
        fn random_levels_have_the_simulated_period(random in random_level()) {
            let g = random.graph();
            let level = Level::build(&g, None, "g".into());
            let counts = repetition_vector(&level).unwrap();
            prop_assume!(find_deadlock(&level, &counts).is_none());
            for concurrency in [Concurrency::Auto, Concurrency::Single] {
                let t = simulated(&level, &counts, concurrency)?;
                prop_assert_eq!(t.critical_cycle.is_empty(), t.period.num == 0);
                // The symbolic iteration, whichever engine `throughput` chose.
                let wcet: Vec<u64> = level.nodes.iter().map(|n| n.wcet.unwrap_or(0)).collect();
                let sdf = Sdf::of(&level);
                let chained = chained(&sdf, concurrency);
                let (period, cycle) = symbolic::period(&sdf, &counts, &wcet, &chained).unwrap();
                prop_assert_eq!(period, t.period, "symbolic, {:?}", concurrency);
                prop_assert_eq!(cycle.is_empty(), period.num == 0);
                prop_assert!(cycle.iter().all(|&v| v < level.nodes.len()));
            }
            let mut once = random.clone();
            once.looped = vec![1; random.gamma.len()];
            let g = once.graph();
            let level = Level::build(&g, None, "g".into());
            let counts = repetition_vector(&level).unwrap();
            prop_assert_eq!(
                throughput(&level, &counts, Concurrency::Auto).map(|t| t.period),
                throughput(&level, &counts, Concurrency::Single).map(|t| t.period)
            );
        }
    }

    /// Two random levels joined by one channel from `a`'s first node to
    /// `b`'s (`b`'s nodes renamed `U…`): a level of at least two strongly
    /// connected parts, where `b`'s repetition counts have a gcd of 3 or
    /// more.
    fn joined(a: &TaskGraph, b: &TaskGraph) -> TaskGraph {
        let first_count = |g: &TaskGraph| {
            let level = Level::build(g, None, "g".into());
            repetition_vector(&level).unwrap()[0]
        };
        let (qa, qb) = (first_count(a), first_count(b));
        let rename = |name: &str| name.replacen('T', "U", 1);
        let mut tasks = a.tasks.clone();
        let mut channels = a.channels.clone();
        for t in &b.tasks {
            let mut t = t.clone();
            t.name.name = rename(&t.name.name).into();
            tasks.push(t);
        }
        for c in &b.channels {
            let mut c = c.clone();
            c.src.task = rename(&c.src.task).into();
            c.dst.task = rename(&c.dst.task).into();
            channels.push(c);
        }
        let b0 = a.tasks.len();
        // `b` runs its own iteration three times per iteration of the whole.
        tasks[0].ports.push(port(&format!("jo>{}", 3 * qb)));
        tasks[b0].ports.push(port(&format!("ji<{qa}")));
        channels.push(channel("T0.jo", "U0.ji", 0));
        graph(tasks, channels)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// A level of several strongly connected parts, each analysed on
        /// its own: the period is still the simulated one.
        #[test]
        fn joined_levels_have_the_simulated_period(a in random_level(), b in random_level()) {
            let g = joined(&a.graph(), &b.graph());
            let level = Level::build(&g, None, "g".into());
            let counts = repetition_vector(&level).unwrap();
            prop_assume!(find_deadlock(&level, &counts).is_none());
            for concurrency in [Concurrency::Auto, Concurrency::Single] {
                let t = simulated(&level, &counts, concurrency)?;
                prop_assert!(t.critical_cycle.iter().all(|&v| v < level.nodes.len()));
            }
        }
    }

    #[test]
    fn parts_that_tie_name_the_first_declared() {
        // A fires twice for each firing of B: 2 × 2 = 1 × 4.
        let t = analyze(&chain(2, 4, 2));
        assert_eq!(t.period, ratio(4, 1));
        assert_eq!(t.critical_cycle, [0]);
        // B slower: B.
        assert_eq!(analyze(&chain(2, 5, 2)).critical_cycle, [1]);
    }

    const SDF3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sdf3");

    /// Per graph of `tests/data/sdf3/` (its README has the table and how the
    /// SDF3 numbers were measured): the period SDF3 gives (auto-concurrency,
    /// SDF3's reading of execution times), the period with auto-concurrency
    /// and the file's `default="true"` times, and with one firing at a time.
    const PERIODS: &[(&str, &str, &str, &str)] = &[
        ("h263decoder", "332046", "332046", "332046"),
        ("h263encoder", "211425", "408448", "1232530"),
        ("modem", "16", "16", "16"),
        (
            "mp3decoder_block_parallelism",
            "278650",
            "278650",
            "3732276",
        ),
        (
            "mp3decoder_granule_parallelism",
            "278650",
            "278650",
            "3732276",
        ),
        ("mp3playback", "120000", "120000", "120000"),
        ("random_1000", "463", "463", "7378"),
        ("random_200", "170", "170", "1422"),
        ("random_50", "104", "104", "280"),
        ("samplerate", "960", "960", "960"),
        ("satellite", "1056", "1056", "1056"),
        ("generated/r12_1", "67", "67", "184"),
        ("generated/r12_1_falsedefault", "66", "67", "184"),
        ("generated/r12_1_selfloops", "123", "123", "184"),
        ("generated/r12_1_somelooped", "123", "123", "184"),
        ("generated/r12_2", "57", "57", "70"),
        ("generated/r12_2_falsedefault", "43", "57", "70"),
        ("generated/r12_2_selfloops", "70", "70", "70"),
        ("generated/r12_2_somelooped", "70", "70", "70"),
        ("generated/r12_3", "54", "54", "210"),
        ("generated/r12_3_falsedefault", "63", "54", "210"),
        ("generated/r12_3_selfloops", "138", "138", "210"),
        ("generated/r12_3_somelooped", "62", "62", "210"),
        ("generated/r12_4", "45", "45", "238"),
        ("generated/r12_4_falsedefault", "46", "45", "238"),
        ("generated/r12_4_selfloops", "119", "119", "238"),
        ("generated/r12_4_somelooped", "119", "119", "238"),
        ("generated/r12_5", "62", "62", "62"),
        ("generated/r12_5_falsedefault", "71", "62", "62"),
        ("generated/r12_5_selfloops", "62", "62", "62"),
        ("generated/r12_5_somelooped", "62", "62", "62"),
        ("generated/r12_6", "83", "83", "159"),
        ("generated/r12_6_falsedefault", "124", "83", "159"),
        ("generated/r12_6_selfloops", "144", "144", "159"),
        ("generated/r12_6_somelooped", "104", "104", "159"),
        ("generated/r30_1", "137/2", "137/2", "121"),
        ("generated/r30_1_falsedefault", "111/2", "137/2", "121"),
        ("generated/r30_1_selfloops", "121", "121", "121"),
        ("generated/r30_1_somelooped", "81", "81", "121"),
        ("generated/r30_2", "110", "110", "308"),
        ("generated/r30_2_falsedefault", "138", "110", "308"),
        ("generated/r30_2_selfloops", "308", "308", "308"),
        ("generated/r30_2_somelooped", "130", "130", "308"),
    ];

    fn load(name: &str, times: crate::taskgraph::ExecutionTimes) -> TaskGraph {
        let text = std::fs::read_to_string(format!("{SDF3}/{name}.xml")).unwrap();
        let (g, diagnostics) = crate::taskgraph::load_task_graph_as(FileId(0), &text, times);
        // W086: processors marked default twice in some of SDF3's files.
        let two_defaults = crate::diag::Code::Sdf3TwoDefaultProcessors;
        assert!(
            diagnostics.iter().all(|d| d.code == two_defaults),
            "{name}: {diagnostics:?}"
        );
        g.unwrap()
    }

    /// Every SDF3 benchmark graph and the generated ones (with and without
    /// self-loops, several execution times per actor): SDF3's own period
    /// exactly, under each reading, each also checked against the simulation.
    #[test]
    fn sdf3_graphs_have_sdf3_periods_and_agree_with_simulation() {
        use crate::taskgraph::ExecutionTimes::{FileDefault, Sdf3Compat};
        let mut listed: Vec<String> = Vec::new();
        for dir in ["", "generated/"] {
            for e in std::fs::read_dir(format!("{SDF3}/{dir}")).unwrap() {
                let path = e.unwrap().path();
                if path.extension().is_some_and(|x| x == "xml") {
                    let stem = path.file_stem().unwrap().to_string_lossy();
                    listed.push(format!("{dir}{stem}"));
                }
            }
        }
        listed.sort();
        let mut names: Vec<String> = PERIODS.iter().map(|r| r.0.to_string()).collect();
        names.sort();
        assert_eq!(listed, names, "every graph in the table");
        for &(name, sdf3, auto, single) in PERIODS {
            let readings = [
                (Sdf3Compat, Concurrency::Auto, sdf3),
                (FileDefault, Concurrency::Auto, auto),
                (FileDefault, Concurrency::Single, single),
            ];
            for (times, concurrency, expected) in readings {
                let g = load(name, times);
                let level = Level::build(&g, None, g.name.clone());
                let counts = repetition_vector(&level).unwrap();
                assert_eq!(find_deadlock(&level, &counts), None, "{name}");
                let t = throughput(&level, &counts, concurrency).unwrap();
                let what = format!("{name}, {times:?}, {concurrency:?}");
                assert_eq!(t.period.to_string(), expected, "{what}");
                assert_eq!(
                    t.period,
                    simulated_period(&level, &counts, concurrency),
                    "{what}"
                );
            }
        }
    }

    #[test]
    fn overflow_and_huge_expansions_say_so_without_panicking() {
        let mut g = two_node_cycle(1);
        g.tasks[0].wcet = Some(u64::MAX);
        g.tasks[1].wcet = Some(u64::MAX);
        let level = Level::build(&g, None, "g".into());
        assert_eq!(
            throughput(&level, &[1, 1], Concurrency::Single),
            Err(NoPeriod::Overflow)
        );
        // Times that fit: the exact period, far beyond what f64 holds exactly.
        g.tasks[0].wcet = Some(u64::MAX / 2 - 1);
        g.tasks[1].wcet = Some(1);
        let level = Level::build(&g, None, "g".into());
        assert_eq!(
            throughput(&level, &[1, 1], Concurrency::Single).map(|t| t.period),
            Ok(ratio(u64::MAX / 2, 1))
        );
        // Potentials beyond an `i64` (B's edge back: (2^62 + 1)·(1 - 3)),
        // within an `i128`: the exact period all the same.
        let mut g = two_node_cycle(3);
        let w = (1 << 62) + 1;
        g.tasks[0].wcet = Some(w);
        g.tasks[1].wcet = Some(w);
        let level = Level::build(&g, None, "g".into());
        let sdf = Sdf::of(&level);
        let hsdf = Hsdf::direct(&sdf, vec![w, w], &chained(&sdf, Concurrency::Single));
        assert_eq!(policy_iteration::<i64>(&hsdf), None);
        assert_eq!(
            policy_iteration::<i128>(&hsdf).map(|(period, _)| period),
            Some(ratio(w, 1))
        );
        assert_eq!(
            throughput(&level, &[1, 1], Concurrency::Single).map(|t| t.period),
            Ok(ratio(w, 1))
        );
        let g = graph(
            vec![task("A", 1, &["o>1000000000"]), task("B", 1, &["i<1"])],
            vec![channel("A.o", "B.i", 0)],
        );
        let level = Level::build(&g, None, "g".into());
        let counts = repetition_vector(&level).unwrap();
        assert_eq!(counts, [1, 1_000_000_000]);
        // Two parts, each of one node firing once per iteration of its own:
        // no expansion, B's 10^9 firings back to back bound it.
        assert_eq!(
            throughput(&level, &counts, Concurrency::Single).map(|t| (t.period, t.critical_cycle)),
            Ok((ratio(1_000_000_000, 1), vec![1]))
        );
        // One part of 10^9 + 1 firings with 10^9 initial samples: too big
        // for both engines.
        let g = graph(
            vec![
                task("A", 1, &["o>1000000000", "i<1000000000"]),
                task("B", 1, &["i<1", "o>1"]),
            ],
            vec![
                channel("A.o", "B.i", 0),
                channel("B.o", "A.i", 1_000_000_000),
            ],
        );
        let level = Level::build(&g, None, "g".into());
        let counts = repetition_vector(&level).unwrap();
        assert_eq!(counts, [1, 1_000_000_000]);
        assert_eq!(
            throughput(&level, &counts, Concurrency::Single),
            Err(NoPeriod::TooLarge)
        );
        assert_eq!(
            throughput(&level, &[1], Concurrency::Single),
            Err(NoPeriod::Inconsistent),
            "counts of another level"
        );
        let g = chain(1, 1, 1);
        let level = Level::build(&g, None, "g".into());
        for concurrency in [Concurrency::Auto, Concurrency::Single] {
            assert_eq!(
                throughput(&level, &[0, 0], concurrency),
                Err(NoPeriod::Inconsistent),
                "zero counts"
            );
        }
    }
}
