use super::*;
use crate::taskgraph::analysis::consistency::repetition_vector;
use crate::taskgraph::analysis::deadlock::find_deadlock;
use crate::taskgraph::analysis::testing::{channel, graph, task};
use crate::taskgraph::model::TaskGraph;
use proptest::prelude::*;

/// A task with execution time `wcet` and ports as `testing::port` reads
/// them (`o>2`: output o of rate 2).
fn timed(name: &str, wcet: u64, ports: &[&str]) -> crate::taskgraph::model::Task {
    let mut t = task(name, ports);
    t.wcet = Some(wcet);
    t
}

fn level(g: &TaskGraph) -> Level<'_> {
    Level::build(g, None, g.name.clone())
}

fn between(
    g: &TaskGraph,
    from: &str,
    to: &str,
    concurrency: Concurrency,
) -> Result<Latency, NoLatency> {
    let level = level(g);
    let counts = repetition_vector(&level).unwrap();
    let index = |name: &str| level.nodes.iter().position(|n| n.name == name).unwrap();
    latency(&level, &counts, index(from), index(to), concurrency)
}

/// S (2) → A (5) → K (1), and K back to S with 2 samples: at most two
/// samples in the pipeline.
fn pipeline() -> TaskGraph {
    graph(
        "pipeline",
        vec![
            timed("S", 2, &["o>1", "back<1"]),
            timed("A", 5, &["i<1", "o>1"]),
            timed("K", 1, &["i<1", "back>1"]),
        ],
        vec![
            channel("S.o", "A.i", 0, 1),
            channel("A.o", "K.i", 0, 2),
            channel("K.back", "S.back", 2, 3),
        ],
    )
}

/// Worked by hand. Every count is 1, and no firing of K comes before S
/// fires: d = 0, δ = 0. Minimal: S 0–2, A 2–7, K 7–8: 8.
///
/// Self-timed, one firing at a time (start–end of firing k):
///
/// | k | S     | A     | K     | L(k)    |
/// |---|-------|-------|-------|---------|
/// | 0 | 0–2   | 2–7   | 7–8   | 8 − 0   |
/// | 1 | 2–4   | 7–12  | 12–13 | 13 − 2  |
/// | 2 | 8–10  | 12–17 | 17–18 | 18 − 8  |
/// | 3 | 13–15 | 17–22 | 22–23 | 23 − 13 |
/// | 4 | 18–20 | 22–27 | 27–28 | 28 − 18 |
///
/// (S's firing 2 waits for K's firing 0 to give a sample back at 8; A,
/// busy until 7, starts its firing 1 then.) From iteration 2 on the
/// latency is 10 every iteration; iteration 1's 11 is the largest.
///
/// With auto-concurrency S and A fire twice at once: S 0–2 twice, A 2–7
/// twice, K 7–8 twice, the samples back at 8, and so on: 8 every time.
#[test]
fn hand_computed_pipeline() {
    let single = between(&pipeline(), "S", "K", Concurrency::Single).unwrap();
    assert_eq!(single.minimal, 8);
    assert_eq!((single.sink_firings_before, single.offset), (0, 0));
    let st = single.self_timed.unwrap();
    assert_eq!((st.latency, st.worst_iteration), (11, 1));
    let auto = between(&pipeline(), "S", "K", Concurrency::Auto).unwrap();
    assert_eq!(auto.minimal, 8);
    assert_eq!(auto.self_timed.unwrap().latency, 8);
    // From A: A 0–5, K 5–6 alone; self-timed (single), A's firing k starts
    // at 2, 7, 12, 17 and K's ends at 8, 13, 18, 23: 6 every time.
    let from_a = between(&pipeline(), "A", "K", Concurrency::Single).unwrap();
    assert_eq!(from_a.minimal, 6);
    assert_eq!(from_a.self_timed.unwrap().latency, 6);
}

/// One initial sample on S → K lets K fire once before S (d = 1): S's
/// iteration k is closed by K's firing k + 1 (δ = 1). Minimal: S 0–1, K
/// 1–2. Self-timed, both one at a time: S's firing k at k–k+1, K's firing
/// k at k–k+1 (firing 0 on the initial sample): L(k) = (k + 2) − k = 2.
#[test]
fn initial_samples_shift_the_sink_firing() {
    let g = graph(
        "g",
        vec![timed("S", 1, &["o>1"]), timed("K", 1, &["i<1"])],
        vec![channel("S.o", "K.i", 1, 1)],
    );
    let l = between(&g, "S", "K", Concurrency::Single).unwrap();
    assert_eq!((l.sink_firings_before, l.offset), (1, 1));
    assert_eq!(l.minimal, 2);
    assert_eq!(l.self_timed.unwrap().latency, 2);
}

/// S fires three times per iteration, K twice (S makes 2 samples, K takes
/// 3). δ = 1: K's second firing closes the iteration. Minimal: S 0–1 three
/// times at once (auto-concurrency)... one at a time: S 0–1, 1–2, 2–3; K's
/// first firing needs 3 samples (at 2), 2–6; its second needs 6 (at 3),
/// 6–10: 10.
#[test]
fn multirate_minimal_latency() {
    let g = graph(
        "g",
        vec![timed("S", 1, &["o>2"]), timed("K", 4, &["i<3"])],
        vec![channel("S.o", "K.i", 0, 1)],
    );
    let l = between(&g, "S", "K", Concurrency::Single).unwrap();
    assert_eq!((l.source_firings, l.sink_firings, l.offset), (3, 2, 1));
    assert_eq!(l.minimal, 10);
    // Auto: S 0–1 three times, K 1–5 twice (6 samples at 1): 5.
    let l = between(&g, "S", "K", Concurrency::Auto).unwrap();
    assert_eq!(l.minimal, 5);
}

#[test]
fn a_slower_task_after_the_source_makes_it_unbounded() {
    // S every 1, K every 3: samples pile up before K.
    let g = graph(
        "g",
        vec![timed("S", 1, &["o>1"]), timed("K", 3, &["i<1"])],
        vec![channel("S.o", "K.i", 0, 1)],
    );
    let l = between(&g, "S", "K", Concurrency::Single).unwrap();
    assert_eq!(l.minimal, 4);
    let ratio = |n| Ratio { num: n, den: 1 };
    assert_eq!(
        l.self_timed,
        Err(NoSelfTimed::Unbounded {
            slowest: 1,
            slowest_period: ratio(3),
            source_period: ratio(1),
        })
    );
}

#[test]
fn a_faster_task_beside_the_source_runs_ahead() {
    // Z every 1 and S every 3 both feed K: Z's samples pile up.
    let g = graph(
        "g",
        vec![
            timed("Z", 1, &["o>1"]),
            timed("S", 3, &["o>1"]),
            timed("K", 1, &["z<1", "s<1"]),
        ],
        vec![channel("Z.o", "K.z", 0, 1), channel("S.o", "K.s", 0, 2)],
    );
    let l = between(&g, "S", "K", Concurrency::Single).unwrap();
    // Z's samples are there when S's come: S 0–3, K 3–4.
    assert_eq!(l.minimal, 4);
    let why = l.self_timed.unwrap_err();
    assert!(
        matches!(why, NoSelfTimed::RunsAhead { edge: 0, .. }),
        "{why:?}"
    );
    let g2 = g.clone();
    assert!(
        why.describe(&level(&g2)).contains("Z.o → K.z"),
        "{}",
        why.describe(&level(&g2))
    );
}

#[test]
fn no_cycle_under_auto_concurrency_has_no_pace() {
    let g = graph(
        "g",
        vec![timed("S", 1, &["o>1"]), timed("K", 1, &["i<1"])],
        vec![channel("S.o", "K.i", 0, 1)],
    );
    let l = between(&g, "S", "K", Concurrency::Auto).unwrap();
    assert_eq!(l.minimal, 2);
    assert_eq!(l.self_timed, Err(NoSelfTimed::NoPace { node: 0 }));
}

#[test]
fn no_path_and_bad_counts_are_refused() {
    let g = pipeline();
    let level = level(&g);
    let g2 = graph(
        "g",
        vec![timed("S", 1, &["o>1"]), timed("K", 1, &["i<1"])],
        vec![channel("S.o", "K.i", 0, 1)],
    );
    let l2 = Level::build(&g2, None, "g".into());
    assert_eq!(
        latency(&l2, &[1, 1], 1, 0, Concurrency::Single),
        Err(NoLatency::NoPath)
    );
    assert_eq!(
        latency(&level, &[1, 1], 0, 2, Concurrency::Single),
        Err(NoLatency::Inconsistent)
    );
    assert_eq!(
        latency(&level, &[1, 1, 1], 0, 7, Concurrency::Single),
        Err(NoLatency::Inconsistent)
    );
}

#[test]
fn a_task_to_itself_is_its_iteration() {
    // S's iteration is one firing: minimal 2; self-timed, S's firing k at
    // 2k–2k+2 … but it waits for K's samples back: 2 every time.
    let l = between(&pipeline(), "S", "S", Concurrency::Single).unwrap();
    assert_eq!((l.minimal, l.offset), (2, 0));
    assert_eq!(l.self_timed.unwrap().latency, 2);
}

#[test]
fn huge_executions_stop_at_the_budget() {
    // 10^9 firings of K per iteration: the minimal latency runs past the
    // budget and says so.
    let g = graph(
        "g",
        vec![timed("S", 1, &["o>1000000000"]), timed("K", 1, &["i<1"])],
        vec![channel("S.o", "K.i", 0, 1)],
    );
    let level = level(&g);
    let counts = repetition_vector(&level).unwrap();
    for concurrency in [Concurrency::Single, Concurrency::Auto] {
        assert_eq!(
            latency_within(&level, &counts, 0, 1, concurrency, 100_000),
            Err(NoLatency::Budget)
        );
    }
}

/// An independent reference: the self-timed execution of the whole level
/// advanced one time unit at a time (every firing in one list, every node
/// scanned each step). At each time the firings due end, then firings start
/// until none can; a node fires at most `burst` times in one time unit
/// (only a node the analysis leaves out could fire more).
#[derive(Clone)]
struct Stepper<'l> {
    level: &'l Level<'l>,
    single: bool,
    time: u64,
    tokens: Vec<u64>,
    /// (node, end time) of the firings under way.
    running: Vec<(usize, u64)>,
    started: Vec<u64>,
    completed: Vec<u64>,
    /// Per node, the most firings it may start (`u64::MAX`: any).
    most: Vec<u64>,
    starts: Vec<Vec<u64>>,
    ends: Vec<Vec<u64>>,
}

impl<'l> Stepper<'l> {
    fn new(level: &'l Level<'l>, concurrency: Concurrency) -> Self {
        let n = level.nodes.len();
        Stepper {
            level,
            single: concurrency == Concurrency::Single,
            time: 0,
            tokens: level.edges.iter().map(|e| e.initial_tokens).collect(),
            running: Vec::new(),
            started: vec![0; n],
            completed: vec![0; n],
            most: vec![u64::MAX; n],
            starts: vec![Vec::new(); n],
            ends: vec![Vec::new(); n],
        }
    }

    fn end(&mut self, v: usize) {
        self.completed[v] += 1;
        self.ends[v].push(self.time);
        for (i, e) in self.level.edges.iter().enumerate() {
            if e.src == v {
                self.tokens[i] += e.produce;
            }
        }
    }

    fn can_start(&self, v: usize) -> bool {
        let busy = self.running.iter().any(|&(u, _)| u == v);
        let inputs_ok = self
            .level
            .edges
            .iter()
            .enumerate()
            .all(|(i, e)| e.dst != v || self.tokens[i] >= e.consume);
        !(self.single && busy) && inputs_ok && self.started[v] < self.most[v]
    }

    fn start(&mut self, v: usize) {
        for (i, e) in self.level.edges.iter().enumerate() {
            if e.dst == v {
                self.tokens[i] -= e.consume;
            }
        }
        self.started[v] += 1;
        self.starts[v].push(self.time);
        let wcet = self.level.nodes[v].wcet.unwrap_or(0);
        if wcet == 0 {
            self.end(v);
        } else {
            self.running.push((v, self.time + wcet));
        }
    }

    fn step(&mut self) {
        let now = self.time;
        let due: Vec<usize> = self
            .running
            .iter()
            .filter(|&&(_, t)| t == now)
            .map(|&(v, _)| v)
            .collect();
        self.running.retain(|&(_, t)| t != now);
        for v in due {
            self.end(v);
        }
        let burst = 64;
        let mut fired = vec![0; self.level.nodes.len()];
        loop {
            let mut any = false;
            for (v, count) in fired.iter_mut().enumerate() {
                if *count < burst && self.can_start(v) {
                    self.start(v);
                    *count += 1;
                    any = true;
                }
            }
            if !any {
                break;
            }
        }
        self.time += 1;
    }
}

/// The reference's state after the source was held back for a long time.
fn held_back<'l>(level: &'l Level<'l>, source: usize, concurrency: Concurrency) -> Stepper<'l> {
    let mut s = Stepper::new(level, concurrency);
    s.most[source] = 0;
    for _ in 0..500 {
        s.step();
    }
    s
}

/// `d` and the minimal latency by the reference: from `held` (the source
/// held back), the source let go for one iteration from time 0.
fn stepped_minimal(mut s: Stepper<'_>, counts: &[u64], source: usize, sink: usize) -> (u64, u64) {
    assert!(
        s.running.iter().all(|&(v, _)| v != sink),
        "the sink still runs"
    );
    let before = s.completed[sink];
    let offset = before / counts[sink] * counts[sink] + counts[sink] - 1;
    s.most[source] = counts[source];
    let release = s.time;
    while s.completed[sink] <= offset {
        s.step();
        assert!(s.time < release + 1000, "the sink's firing never came");
    }
    // Ended during the last step, at its time.
    (before, s.time - 1 - release)
}

/// `L(k)` by the reference for every iteration it saw.
fn stepped_latencies(
    run: &Stepper<'_>,
    counts: &[u64],
    source: usize,
    sink: usize,
    offset: u64,
) -> Vec<i128> {
    let starts = &run.starts[source];
    let ends = &run.ends[sink];
    (0u64..)
        .map_while(|k| {
            let start = starts.get(usize::try_from(k * counts[source]).ok()?)?;
            let end = ends.get(usize::try_from(k * counts[sink] + offset).ok()?)?;
            Some(i128::from(*end) - i128::from(*start))
        })
        .collect()
}

/// A random small consistent level: nodes `T0..Tn` in a chain (each with
/// a repetition count from `gamma`), extra edges between random nodes
/// (backwards ones with initial samples), execution times 1..=4.
#[derive(Clone, Debug)]
struct Random {
    gamma: Vec<u64>,
    wcet: Vec<u64>,
    /// (from, to, multiple of the least rates, initial samples)
    edges: Vec<(usize, usize, u64, u64)>,
}

impl Random {
    fn graph(&self) -> TaskGraph {
        let n = self.gamma.len();
        let mut ports: Vec<Vec<String>> = vec![Vec::new(); n];
        let mut channels = Vec::new();
        for (i, &(a, b, m, tokens)) in self.edges.iter().enumerate() {
            let g = super::super::ratio::gcd(self.gamma[a], self.gamma[b]);
            let (p, c) = (self.gamma[b] / g * m, self.gamma[a] / g * m);
            ports[a].push(format!("o{i}>{p}"));
            ports[b].push(format!("i{i}<{c}"));
            channels.push(channel(
                &format!("T{a}.o{i}"),
                &format!("T{b}.i{i}"),
                tokens,
                i + 1,
            ));
        }
        let tasks = (0..n)
            .map(|v| {
                let p: Vec<&str> = ports[v].iter().map(String::as_str).collect();
                timed(&format!("T{v}"), self.wcet[v], &p)
            })
            .collect();
        graph("random", tasks, channels)
    }
}

fn random_level() -> impl Strategy<Value = Random> {
    (2usize..=4).prop_flat_map(|n| {
        let extra = prop::collection::vec((0..n, 0..n, 1u64..=2, 0u64..=6), 0..=3);
        (
            prop::collection::vec(1u64..=3, n),
            prop::collection::vec(1u64..=4, n),
            extra,
            prop::collection::vec(0u64..=2, n - 1),
        )
            .prop_map(move |(gamma, wcet, extra, chain_tokens)| {
                let mut edges: Vec<(usize, usize, u64, u64)> =
                    (1..n).map(|v| (v - 1, v, 1, chain_tokens[v - 1])).collect();
                edges.extend(extra);
                Random { gamma, wcet, edges }
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// On random small levels, both readings of concurrency, every pair of
    /// tasks joined by a path: the minimal latency and `d` are the
    /// reference's, and the self-timed latency, where there is one, is the
    /// largest `L(k)` the reference sees over more iterations than the
    /// analysis needed (its transient and one cycle); where it is
    /// unbounded, the reference's `L(k)` grows.
    #[test]
    fn latencies_agree_with_a_step_by_step_execution(random in random_level()) {
        let g = random.graph();
        let level = level(&g);
        let counts = repetition_vector(&level).unwrap();
        prop_assume!(find_deadlock(&level, &counts).is_none());
        let n = level.nodes.len();
        for concurrency in [Concurrency::Single, Concurrency::Auto] {
            let mut free = Stepper::new(&level, concurrency);
            for _ in 0..1000 {
                free.step();
            }
            for source in 0..n {
                let held = held_back(&level, source, concurrency);
                for sink in 0..n {
                    let what = format!("{concurrency:?} T{source}→T{sink}");
                    let found = match latency(&level, &counts, source, sink, concurrency) {
                        Err(NoLatency::NoPath) => {
                            prop_assert!(!reach(&level, source, Direction::Forward)[sink]);
                            continue;
                        }
                        other => other.unwrap(),
                    };
                    let (before, minimal) = stepped_minimal(held.clone(), &counts, source, sink);
                    prop_assert_eq!(found.sink_firings_before, before, "{}", what);
                    prop_assert_eq!(found.minimal, minimal, "{}", what);
                    let seen = stepped_latencies(&free, &counts, source, sink, found.offset);
                    match found.self_timed {
                        Ok(st) => {
                            let needed = usize::try_from(st.periodic_from + st.cycle).unwrap();
                            prop_assert!(seen.len() >= needed, "{}: {} < {}", what, seen.len(), needed);
                            let worst = seen.iter().copied().max().unwrap();
                            prop_assert_eq!(i128::from(st.latency), worst, "{}", what);
                            let at = seen.iter().position(|&l| l == worst).unwrap();
                            prop_assert_eq!(st.worst_iteration, at as u64, "{}", what);
                        }
                        Err(NoSelfTimed::Unbounded { .. }) => {
                            prop_assert!(seen.len() > 40, "{}", what);
                            let last = seen[seen.len() - 1];
                            prop_assert!(last > seen[seen.len() / 4], "{}: {:?}", what, seen);
                        }
                        Err(_) => {}
                    }
                }
            }
        }
    }
}
