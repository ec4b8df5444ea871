//! Builders of small task-graph models for the analyses' unit tests, and an
//! independent self-timed simulation to check periods against.

use super::level::{Edge, Level};
use super::ratio::Ratio;
use super::throughput::Concurrency;
use crate::diag::FileId;
use crate::span::Span;
use crate::taskgraph::model::*;
use std::collections::HashMap;

pub(crate) fn named(name: &str) -> Named {
    Named {
        name: name.into(),
        span: Span::default(),
    }
}

pub(crate) fn port(spec: &str) -> Port {
    // "o>2": output o, rate 2; "i<3": input i, rate 3.
    let (name, dir, rate) = match spec.split_once('>') {
        Some((n, r)) => (n, Direction::Out, r),
        None => {
            let (n, r) = spec.split_once('<').unwrap();
            (n, Direction::In, r)
        }
    };
    Port {
        name: named(name),
        span: Span::default(),
        dir,
        rate: rate.parse().unwrap(),
        rate_span: None,
        sample_type: None,
        size: None,
        kind: None,
        inner_rate: None,
    }
}

pub(crate) fn task(name: &str, ports: &[&str]) -> Task {
    Task {
        name: named(name),
        span: Span::default(),
        kind: TaskKind::Computational,
        trigger: Trigger::Data,
        wcet: None,
        source: None,
        subgraph: None,
        ports: ports.iter().map(|p| port(p)).collect(),
        library_ports: Vec::new(),
        multicast_ports: Vec::new(),
        loop_node: None,
    }
}

pub(crate) fn channel(src: &str, dst: &str, tokens: u64, at: usize) -> Channel {
    let end = |s: &str| {
        let (task, port) = s.split_once('.').unwrap();
        Endpoint {
            task: task.into(),
            port: port.into(),
            span: Span::default(),
        }
    };
    Channel {
        src: end(src),
        dst: end(dst),
        initial_tokens: tokens,
        capacity: None,
        span: Span::new(at, at + 1),
    }
}

pub(crate) fn graph(name: &str, tasks: Vec<Task>, channels: Vec<Channel>) -> TaskGraph {
    TaskGraph {
        name: name.into(),
        file: FileId(0),
        span: Span::default(),
        tasks,
        channels,
        libraries: Vec::new(),
    }
}

/// The graph of `examples/taskgraphs/data_loop.taskgraph.xml`, built in code:
/// A 10→ L (D-loop × 10 over B, C) 10→ D.
pub(crate) fn data_loop() -> TaskGraph {
    let mut l = task("L", &["in<10", "out>10"]);
    l.kind = TaskKind::Loop;
    for p in &mut l.ports {
        p.inner_rate = Some(1);
    }
    l.loop_node = Some(Box::new(LoopNode {
        loop_type: LoopType::D,
        loop_count: 10,
        exit_task: None,
        body: graph(
            "L_body",
            vec![task("B", &["i<1", "o>1"]), task("C", &["i<1", "o>1"])],
            vec![
                channel("L.in", "B.i", 0, 1),
                channel("B.o", "C.i", 0, 2),
                channel("C.o", "L.out", 0, 3),
            ],
        ),
    }));
    graph(
        "data_loop",
        vec![task("A", &["o>10"]), l, task("D", &["i<10"])],
        vec![channel("A.o", "L.in", 0, 4), channel("L.out", "D.i", 0, 5)],
    )
}

/// The period of the self-timed execution found by running it: each node
/// fires as soon as its inputs allow (and, with `Single`, it is idle),
/// taking its wcet. Each strongly connected part is run alone until its
/// state (samples on its edges, remaining times of the firings under
/// way) repeats at a start of its first node; the level's period is the
/// largest (with unbounded channels, a faster part upstream or downstream
/// does not change a part's period). With `Auto`, a part of one node
/// without a self-loop channel fires without bound: period 0.
pub(crate) fn simulated_period(
    level: &Level<'_>,
    counts: &[u64],
    concurrency: Concurrency,
) -> Ratio {
    let wcet: Vec<u64> = level.nodes.iter().map(|n| n.wcet.unwrap_or(0)).collect();
    components(level)
        .iter()
        .map(|part| simulate_part(level, counts, &wcet, part, concurrency))
        .max()
        .unwrap()
}

fn simulate_part(
    level: &Level<'_>,
    counts: &[u64],
    wcet: &[u64],
    part: &[usize],
    concurrency: Concurrency,
) -> Ratio {
    let zero = Ratio::new(0, 1).unwrap();
    if part.iter().all(|&v| wcet[v] == 0) {
        return zero;
    }
    let n = level.nodes.len();
    let mut inside = vec![false; n];
    for &v in part {
        inside[v] = true;
    }
    let edges: Vec<&Edge> = level
        .edges
        .iter()
        .filter(|e| inside[e.src] && inside[e.dst])
        .collect();
    if concurrency == Concurrency::Auto && edges.is_empty() {
        return zero;
    }
    let mut tokens: Vec<u64> = edges.iter().map(|e| e.initial_tokens).collect();
    // The remaining times of the firings under way, per node (sorted).
    let mut running: Vec<Vec<u64>> = vec![Vec::new(); n];
    let reference = part[0];
    let (mut time, mut fired) = (0u64, 0u64);
    type State = (Vec<u64>, Vec<Vec<u64>>);
    let mut seen: HashMap<State, (u64, u64)> = HashMap::new();
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
                let idle = concurrency == Concurrency::Auto || running[v].is_empty();
                if !idle || inputs[v].iter().any(|&i| tokens[i] < edges[i].consume) {
                    continue;
                }
                for &i in &inputs[v] {
                    tokens[i] -= edges[i].consume;
                }
                if wcet[v] == 0 {
                    produce(v, &mut tokens);
                } else {
                    running[v].push(wcet[v]);
                    running[v].sort_unstable();
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
            let state = (
                tokens.clone(),
                part.iter().map(|&v| running[v].clone()).collect(),
            );
            if let Some((t0, f0)) = seen.insert(state, (time, fired)) {
                return Ratio::new((time - t0) * counts[reference], fired - f0).unwrap();
            }
        }
        let dt = part
            .iter()
            .filter_map(|&v| running[v].first().copied())
            .min()
            .expect("deadlock in simulation");
        time += dt;
        for &v in part {
            for left in &mut running[v] {
                *left -= dt;
            }
            while running[v].first() == Some(&0) {
                running[v].remove(0);
                produce(v, &mut tokens);
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

/// A random consistent level: a ring through all nodes plus `extra`
/// channels, repetition counts `gamma`, rates a multiple of what the
/// counts need, initial samples from `fill`, and a self-loop channel with
/// 1 or 2 samples on the nodes `looped` says.
#[derive(Debug, Clone)]
pub(crate) struct RandomLevel {
    pub(crate) gamma: Vec<u64>,
    pub(crate) wcet: Vec<u64>,
    pub(crate) extra: Vec<(usize, usize, u64, u64)>,
    pub(crate) ring: Vec<(u64, u64)>,
    pub(crate) looped: Vec<u64>,
}

impl RandomLevel {
    pub(crate) fn graph(&self) -> TaskGraph {
        let n = self.gamma.len();
        let mut tasks: Vec<Task> = (0..n)
            .map(|v| Task {
                wcet: Some(self.wcet[v]),
                ..task(&format!("T{v}"), &[])
            })
            .collect();
        let mut channels = Vec::new();
        let ring = (0..n).map(|i| (i, (i + 1) % n, self.ring[i].0, self.ring[i].1));
        let extra = self.extra.iter().map(|&(s, d, m, f)| (s % n, d % n, m, f));
        for (i, (s, d, m, fill)) in ring.chain(extra).enumerate() {
            let (gs, gd) = (self.gamma[s], self.gamma[d]);
            let l = super::ratio::lcm(gs, gd).unwrap() * m;
            let (p, c) = (l / gs, l / gd);
            tasks[s].ports.push(port(&format!("o{i}>{p}")));
            tasks[d].ports.push(port(&format!("i{i}<{c}")));
            let tokens = fill % (2 * l + 1);
            channels.push(channel(
                &format!("T{s}.o{i}"),
                &format!("T{d}.i{i}"),
                tokens,
                0,
            ));
        }
        for (v, &samples) in self.looped.iter().enumerate().take(n) {
            if samples > 0 {
                tasks[v].ports.push(port("so>1"));
                tasks[v].ports.push(port("si<1"));
                channels.push(channel(
                    &format!("T{v}.so"),
                    &format!("T{v}.si"),
                    samples,
                    0,
                ));
            }
        }
        graph("g", tasks, channels)
    }
}

pub(crate) fn random_level() -> impl proptest::strategy::Strategy<Value = RandomLevel> {
    use proptest::prelude::*;
    (2usize..6).prop_flat_map(|n| {
        (
            proptest::collection::vec(1u64..4, n),
            proptest::collection::vec(1u64..7, n),
            proptest::collection::vec((0usize..6, 0usize..6, 1u64..3, 0u64..40), 0..4),
            proptest::collection::vec((1u64..3, 0u64..40), n),
            proptest::collection::vec(0u64..3, n),
        )
            .prop_map(|(gamma, wcet, extra, ring, looped)| RandomLevel {
                gamma,
                wcet,
                extra,
                ring,
                looped,
            })
    })
}
