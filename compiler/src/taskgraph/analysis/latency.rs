//! Latency from a source task to a sink task of a level: how long after the
//! source starts an iteration the sink completes the iteration that it
//! causes, by SDF3's two definitions (Stuijk, Ghamarian et al.: SDF3's
//! `sdf/analysis/latency`, minimal and self-timed).
//!
//! Firings of each node are numbered from 0 in the order they start; γ is
//! the repetition vector. The level is executed as the throughput analysis
//! executes it: unbounded channels, every node firing as soon as its input
//! samples are there, concurrently with itself or not as [`Concurrency`]
//! says.
//!
//! - **Offset δ.** With the source held back (it never fires), the rest runs
//!   until nothing more can fire: the sink completes `d` firings that need no
//!   source firing (fed by initial samples). The sink's firing that closes
//!   the source's iteration `k` is `k·γ(sink) + δ`, where δ = ⌊d/γ(sink)⌋·
//!   γ(sink) + γ(sink) − 1: the last firing of the sink's iteration that
//!   firing `d` opens (SDF3's `distance`).
//! - **Minimal latency.** From that held-back state (everything idle), the
//!   source is let go for one iteration (γ(source) firings) at time 0 and
//!   the level runs as early as possible: the minimal latency is the time at
//!   which the sink's firing δ ends. It is the latency of one iteration
//!   alone in an idle graph, with as many processors as it can use. (SDF3
//!   fires only the firings that the sink's firing needs; running the others
//!   too delays none of those, since no firing waits for a later one.)
//! - **Self-timed latency.** In the self-timed execution from the initial
//!   samples, `L(k)` = the end of the sink's firing `k·γ(sink) + δ` − the
//!   start of the source's firing `k·γ(source)`; the self-timed latency is
//!   the largest `L(k)` over every iteration `k ≥ 0`, the transient
//!   included. The execution is run until its state (samples per channel,
//!   the remaining times of the firings under way, the source's firings
//!   modulo γ) repeats at a start of the source, found by Brent's cycle
//!   detection (one saved state, not every state seen): from the first of
//!   the two states on, `L` repeats, so the largest of the iterations up to
//!   one cycle past it is the largest of all.
//!
//! SDF3 asks for a strongly connected graph. Here only the tasks that the
//! sink depends on matter to it (the others are left out, as they change
//! none of its firings), and of those, for the minimal latency, only the
//! ones that depend on the source: a task the source does not feed has
//! run ahead by as much as it can while the source was held back, so its
//! samples are always there. On a strongly connected graph this is SDF3's
//! definition exactly.
//!
//! The self-timed execution of the tasks before the sink has a repeating
//! state only where all of them run at one pace: per strongly connected
//! part, its iteration period ([`super::throughput`]) taken over every part
//! before it is the pace of its tasks. Where a part before the sink is
//! slower than the source, samples pile up before it and `L(k)` grows
//! without bound ([`NoSelfTimed::Unbounded`]: an answer). Where a task runs
//! ahead of the pace (a faster part that the source does not feed), its
//! samples pile up and the state never repeats ([`NoSelfTimed::RunsAhead`]),
//! and where the pace is 0 (auto-concurrency, no cycle bounding the
//! source) firings never end at one instant ([`NoSelfTimed::NoPace`]):
//! then there is no self-timed latency here, and the minimal one stands.
//!
//! Cost: each firing simulated is one unit of work, each state compared or
//! saved one unit per number it holds; the work of one latency is bounded by
//! [`MAX_WORK`], past which it says so rather than run on. Memory is linear
//! in the level plus the firings under way and the source iterations whose
//! sink firing has not ended yet.

use super::level::{Level, Lists};
use super::ratio::Ratio;
use super::throughput::{Concurrency, NoPeriod, throughput};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// Work units one latency may take: firings simulated plus the numbers of
/// the states compared (a few seconds at most).
pub const MAX_WORK: u64 = 30_000_000;

/// The latency from `source` to `sink`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Latency {
    /// γ(source) and γ(sink).
    pub source_firings: u64,
    pub sink_firings: u64,
    /// Firings of the sink that need no firing of the source (`d`).
    pub sink_firings_before: u64,
    /// The sink's firing closing the source's iteration 0 (δ).
    pub offset: u64,
    /// The minimal latency, in the level's time unit.
    pub minimal: u64,
    pub self_timed: Result<SelfTimed, NoSelfTimed>,
}

/// The self-timed latency and where it is reached.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SelfTimed {
    pub latency: u64,
    /// The first iteration `k` whose `L(k)` is the latency.
    pub worst_iteration: u64,
    /// From this iteration on, `L` repeats ...
    pub periodic_from: u64,
    /// ... every this many iterations.
    pub cycle: u64,
}

/// Why there is no latency at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoLatency {
    /// No path of channels leads from the source to the sink.
    NoPath,
    /// `counts` is not a repetition vector of the level.
    Inconsistent,
    /// The sink's firing δ never comes (the level deadlocks on the way).
    Stuck,
    /// More than [`MAX_WORK`] work units.
    Budget,
    /// A time or a sample count past 64 bits.
    Overflow,
}

impl NoLatency {
    /// Why, in words (after "no latency: ").
    pub fn why(self) -> String {
        match self {
            NoLatency::NoPath => "no path of channels leads from the source to the sink".into(),
            NoLatency::Inconsistent => "the rates are inconsistent".into(),
            NoLatency::Stuck => {
                "the sink's firing never comes: the graph stops on the way (a deadlock)".into()
            }
            NoLatency::Budget => format!(
                "the execution needs more than the analysis's work budget ({MAX_WORK} firings)"
            ),
            NoLatency::Overflow => "a time or a sample count overflows 64 bits".into(),
        }
    }

    /// A name for machines (JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            NoLatency::NoPath => "no_path",
            NoLatency::Inconsistent => "inconsistent",
            NoLatency::Stuck => "stuck",
            NoLatency::Budget => "budget",
            NoLatency::Overflow => "overflow",
        }
    }
}

/// Why there is no self-timed latency (the minimal one still is).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NoSelfTimed {
    /// The part of `slowest` takes longer per iteration than the source's
    /// pace: the sink falls further behind every iteration.
    Unbounded {
        slowest: usize,
        slowest_period: Ratio,
        source_period: Ratio,
    },
    /// The source of `edge` runs ahead of the pace of the sink's tasks
    /// (`ahead` per iteration against `pace`): its samples pile up and the
    /// execution's state never repeats.
    RunsAhead {
        edge: usize,
        ahead: Ratio,
        pace: Ratio,
    },
    /// `node` fires without end at one instant (period 0: auto-concurrency
    /// without a cycle bounding it, or a cycle taking no time).
    NoPace {
        node: usize,
    },
    /// The period of a part could not be computed.
    Period(NoPeriod),
    /// More than [`MAX_WORK`] work units before the state repeated.
    Budget,
    Overflow,
}

impl NoSelfTimed {
    /// A name for machines (JSON).
    pub fn as_str(&self) -> &'static str {
        match self {
            NoSelfTimed::Unbounded { .. } => "unbounded",
            NoSelfTimed::RunsAhead { .. } => "runs_ahead",
            NoSelfTimed::NoPace { .. } => "no_pace",
            NoSelfTimed::Period(_) => "no_period",
            NoSelfTimed::Budget => "budget",
            NoSelfTimed::Overflow => "overflow",
        }
    }

    /// Why, in words, with the level's names.
    pub fn describe(&self, level: &Level<'_>) -> String {
        let name = |v: usize| level.nodes[v].name.as_str();
        match self {
            NoSelfTimed::Unbounded {
                slowest,
                slowest_period,
                source_period,
            } => format!(
                "`{}` takes {slowest_period} per iteration, but the source starts one every {source_period}: samples pile up before it and the latency grows every iteration",
                name(*slowest)
            ),
            NoSelfTimed::RunsAhead { edge, ahead, pace } => format!(
                "samples pile up on channel {}: `{}` runs ahead (an iteration every {ahead}, where the sink's pace is {pace}), so the self-timed execution never repeats",
                level.edges[*edge].label,
                name(level.edges[*edge].src)
            ),
            NoSelfTimed::NoPace { node } => format!(
                "`{}` fires without end at one instant (no cycle bounds it, or its cycle takes no time), so the self-timed execution never advances",
                name(*node)
            ),
            NoSelfTimed::Period(why) => format!("no period for a part of the graph: {}", why.why()),
            NoSelfTimed::Budget => format!(
                "the execution did not repeat within the analysis's work budget ({MAX_WORK} firings)"
            ),
            NoSelfTimed::Overflow => "a time or a sample count overflows 64 bits".to_string(),
        }
    }
}

/// The latency from node `source` to node `sink` of `level` (consistent,
/// with repetition vector `counts`, and deadlock-free), nodes firing as
/// `concurrency` says, each taking its `wcet` (none: 0).
pub fn latency(
    level: &Level<'_>,
    counts: &[u64],
    source: usize,
    sink: usize,
    concurrency: Concurrency,
) -> Result<Latency, NoLatency> {
    latency_within(level, counts, source, sink, concurrency, MAX_WORK)
}

/// [`latency`] within `budget` work units for each of the two executions.
fn latency_within(
    level: &Level<'_>,
    counts: &[u64],
    source: usize,
    sink: usize,
    concurrency: Concurrency,
    budget: u64,
) -> Result<Latency, NoLatency> {
    let n = level.nodes.len();
    if counts.len() != n || counts.contains(&0) || source >= n || sink >= n {
        return Err(NoLatency::Inconsistent);
    }
    let after_source = reach(level, source, Direction::Forward);
    if !after_source[sink] {
        return Err(NoLatency::NoPath);
    }
    let before_sink = reach(level, sink, Direction::Backward);
    let between: Vec<bool> = (0..n).map(|v| after_source[v] && before_sink[v]).collect();
    let net = Net::of(level, &between, concurrency);
    let (sink_firings_before, minimal) = minimal_latency(&net, counts, source, sink, budget)?;
    let offset = last_of_iteration(sink_firings_before, counts[sink]);
    let ends = Ends {
        source,
        sink,
        offset,
    };
    let self_timed = self_timed_latency(level, counts, &before_sink, ends, concurrency, budget);
    Ok(Latency {
        source_firings: counts[source],
        sink_firings: counts[sink],
        sink_firings_before,
        offset,
        minimal,
        self_timed,
    })
}

/// The last firing of the iteration that firing `first` of a node with
/// `count` firings per iteration lies in (δ).
fn last_of_iteration(first: u64, count: u64) -> u64 {
    first / count * count + count - 1
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Direction {
    Forward,
    Backward,
}

/// The nodes reached from `from` along the level's edges (`from` included).
fn reach(level: &Level<'_>, from: usize, direction: Direction) -> Vec<bool> {
    let n = level.nodes.len();
    let next = Lists::new(n, || {
        level.edges.iter().map(|e| match direction {
            Direction::Forward => (e.src, e.dst),
            Direction::Backward => (e.dst, e.src),
        })
    });
    let mut seen = vec![false; n];
    seen[from] = true;
    let mut stack = vec![from];
    while let Some(v) = stack.pop() {
        for &w in &next[v] {
            if !seen[w] {
                seen[w] = true;
                stack.push(w);
            }
        }
    }
    seen
}

/// `d` and the minimal latency: the level's tasks between the source and
/// the sink run with the source held back until nothing fires, then with
/// the source let go for one iteration from time 0.
fn minimal_latency(
    net: &Net,
    counts: &[u64],
    source: usize,
    sink: usize,
    budget: u64,
) -> Result<(u64, u64), NoLatency> {
    let mut run = Run::new(net, budget);
    run.hold(source, 0);
    run.until_idle()?;
    let before = run.completed[sink];
    let offset = last_of_iteration(before, counts[sink]);
    run.now = 0;
    run.hold(source, counts[source]);
    loop {
        run.instant()?;
        if run.completed[sink] > offset {
            return Ok((before, run.now));
        }
        if !run.advance() {
            return Err(NoLatency::Stuck);
        }
    }
}

/// The source, the sink and δ.
#[derive(Clone, Copy)]
struct Ends {
    source: usize,
    sink: usize,
    offset: u64,
}

/// The self-timed latency on the tasks the sink depends on (`before_sink`),
/// or why there is none.
fn self_timed_latency(
    level: &Level<'_>,
    counts: &[u64],
    before_sink: &[bool],
    ends: Ends,
    concurrency: Concurrency,
    budget: u64,
) -> Result<SelfTimed, NoSelfTimed> {
    one_pace(level, counts, before_sink, ends, concurrency)?;
    let net = Net::of(level, before_sink, concurrency);
    Watch::new(&net, counts, ends, budget).run()
}

/// Checks that every task before the sink runs at the source's pace (see
/// the module's documentation).
fn one_pace(
    level: &Level<'_>,
    counts: &[u64],
    inside: &[bool],
    ends: Ends,
    concurrency: Concurrency,
) -> Result<(), NoSelfTimed> {
    let Ends { source, sink, .. } = ends;
    let pace = paces(level, counts, inside, concurrency)?;
    let (up, own) = (&pace.upstream, &pace.own);
    if up[sink] > up[source] {
        let slowest = (0..level.nodes.len())
            .find(|&v| inside[v] && own[v] == up[sink])
            .unwrap_or(sink);
        return Err(NoSelfTimed::Unbounded {
            slowest,
            slowest_period: up[sink],
            source_period: up[source],
        });
    }
    if up[source].num == 0 {
        // Every part before the sink has period 0: one whose tasks have no
        // input from another part fires without end at time 0.
        let node = (0..level.nodes.len())
            .find(|&v| inside[v] && pace.first_of_part[v])
            .unwrap_or(source);
        return Err(NoSelfTimed::NoPace { node });
    }
    // Along a path to the sink the pace only grows; where it grows, the
    // channel's source runs ahead.
    let ahead = level
        .edges
        .iter()
        .position(|e| inside[e.src] && inside[e.dst] && up[e.src] < up[e.dst]);
    match ahead {
        Some(edge) => Err(NoSelfTimed::RunsAhead {
            edge,
            ahead: up[level.edges[edge].src],
            pace: up[sink],
        }),
        None => Ok(()),
    }
}

/// Per node: the period per iteration of its strongly connected part
/// (`own`), the largest over its part and every part before it
/// (`upstream`), and whether it is the first node of a part no other part
/// feeds (`first_of_part`). Nodes outside `inside` are 0 and ignored.
struct Paces {
    own: Vec<Ratio>,
    upstream: Vec<Ratio>,
    first_of_part: Vec<bool>,
}

fn paces(
    level: &Level<'_>,
    counts: &[u64],
    inside: &[bool],
    concurrency: Concurrency,
) -> Result<Paces, NoSelfTimed> {
    let n = level.nodes.len();
    let edges: Vec<usize> = (0..level.edges.len())
        .filter(|&i| inside[level.edges[i].src] && inside[level.edges[i].dst])
        .collect();
    let (part, parts) = crate::digraph::components(
        n,
        edges
            .iter()
            .map(|&i| (level.edges[i].src, level.edges[i].dst)),
    );
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); parts];
    for v in (0..n).filter(|&v| inside[v]) {
        members[part[v]].push(v);
    }
    let zero = Ratio { num: 0, den: 1 };
    let mut period = vec![zero; parts];
    for (p, nodes) in members.iter().enumerate().filter(|(_, m)| !m.is_empty()) {
        let (sub, sub_counts) = part_level(level, counts, nodes, &part, p);
        period[p] = throughput(&sub, &sub_counts, concurrency)
            .map_err(NoSelfTimed::Period)?
            .period;
    }
    // Parts are numbered so that an edge between two goes from a higher
    // number to a lower one: taking the edges by decreasing source part,
    // every part's pace is final before it is passed on.
    let mut upstream = period.clone();
    let mut fed = vec![false; parts];
    let mut between: Vec<(usize, usize)> = edges
        .iter()
        .map(|&i| (part[level.edges[i].src], part[level.edges[i].dst]))
        .filter(|(a, b)| a != b)
        .collect();
    between.sort_unstable_by_key(|&(a, _)| Reverse(a));
    for (a, b) in between {
        upstream[b] = upstream[b].max(upstream[a]);
        fed[b] = true;
    }
    let mut first_of_part = vec![false; n];
    for nodes in &members {
        if let Some(&v) = nodes.first() {
            first_of_part[v] = !fed[part[v]];
        }
    }
    Ok(Paces {
        own: (0..n).map(|v| period[part[v]]).collect(),
        upstream: (0..n).map(|v| upstream[part[v]]).collect(),
        first_of_part,
    })
}

/// The level made of one strongly connected part (`nodes`, part `p`) and
/// the edges within it, with its nodes' repetition counts.
fn part_level<'g>(
    level: &Level<'g>,
    counts: &[u64],
    nodes: &[usize],
    part: &[usize],
    p: usize,
) -> (Level<'g>, Vec<u64>) {
    let mut index = vec![usize::MAX; level.nodes.len()];
    for (i, &v) in nodes.iter().enumerate() {
        index[v] = i;
    }
    let edges = level
        .edges
        .iter()
        .filter(|e| part[e.src] == p && part[e.dst] == p)
        .map(|e| super::level::Edge {
            src: index[e.src],
            dst: index[e.dst],
            ..e.clone()
        })
        .collect();
    let sub = Level {
        path: level.path.clone(),
        graph: level.graph,
        nodes: nodes.iter().map(|&v| level.nodes[v].clone()).collect(),
        edges,
        boundary: None,
        stands_for: None,
    };
    (sub, nodes.iter().map(|&v| counts[v]).collect())
}

/// What the execution reads of a level: the nodes' times and the edges
/// between the nodes taken part (the others are left out: a channel from a
/// node left out always holds enough samples).
struct Net {
    wcet: Vec<u64>,
    edges: Vec<Flow>,
    /// Per node, the indices of its input and output edges.
    inputs: Lists,
    outputs: Lists,
    /// Whether a node fires one firing at a time.
    single: bool,
    taken: Vec<bool>,
}

struct Flow {
    dst: usize,
    produce: u64,
    consume: u64,
    initial_tokens: u64,
}

impl Net {
    fn of(level: &Level<'_>, taken: &[bool], concurrency: Concurrency) -> Net {
        let kept: Vec<&super::level::Edge> = level
            .edges
            .iter()
            .filter(|e| taken[e.src] && taken[e.dst])
            .collect();
        let n = level.nodes.len();
        Net {
            wcet: level.nodes.iter().map(|v| v.wcet.unwrap_or(0)).collect(),
            inputs: Lists::new(n, || kept.iter().enumerate().map(|(i, e)| (e.dst, i))),
            outputs: Lists::new(n, || kept.iter().enumerate().map(|(i, e)| (e.src, i))),
            edges: kept
                .iter()
                .map(|e| Flow {
                    dst: e.dst,
                    produce: e.produce,
                    consume: e.consume,
                    initial_tokens: e.initial_tokens,
                })
                .collect(),
            single: concurrency == Concurrency::Single,
            taken: taken.to_vec(),
        }
    }
}

/// Why an execution stopped early.
enum Halt {
    Budget,
    Overflow,
}

impl From<Halt> for NoLatency {
    fn from(h: Halt) -> NoLatency {
        match h {
            Halt::Budget => NoLatency::Budget,
            Halt::Overflow => NoLatency::Overflow,
        }
    }
}

impl From<Halt> for NoSelfTimed {
    fn from(h: Halt) -> NoSelfTimed {
        match h {
            Halt::Budget => NoSelfTimed::Budget,
            Halt::Overflow => NoSelfTimed::Overflow,
        }
    }
}

/// The self-timed execution of a [`Net`], one instant at a time: at an
/// instant the firings due end (their samples produced), then every firing
/// that can start starts (a firing taking no time ends at once).
struct Run<'n> {
    net: &'n Net,
    now: u64,
    tokens: Vec<u64>,
    /// Per node, the end times of its firings under way, earliest first (a
    /// node's firings all take its time, so they end in the order they
    /// started).
    running: Vec<VecDeque<u64>>,
    /// The earliest end of each node with firings under way.
    ends: BinaryHeap<Reverse<(u64, usize)>>,
    started: Vec<u64>,
    completed: Vec<u64>,
    /// A node that may start no more than this many firings in all.
    held: Option<(usize, u64)>,
    /// Nodes to try to start, and whether each is listed.
    ready: Vec<usize>,
    listed: Vec<bool>,
    work: u64,
    budget: u64,
}

impl<'n> Run<'n> {
    fn new(net: &'n Net, budget: u64) -> Run<'n> {
        let n = net.wcet.len();
        let ready: Vec<usize> = (0..n).rev().filter(|&v| net.taken[v]).collect();
        let mut listed = vec![false; n];
        for &v in &ready {
            listed[v] = true;
        }
        Run {
            net,
            now: 0,
            tokens: net.edges.iter().map(|e| e.initial_tokens).collect(),
            running: vec![VecDeque::new(); n],
            ends: BinaryHeap::new(),
            started: vec![0; n],
            completed: vec![0; n],
            held: None,
            ready,
            listed,
            work: 0,
            budget,
        }
    }

    /// Lets `node` start no more than `firings` more firings.
    fn hold(&mut self, node: usize, firings: u64) {
        self.held = Some((node, self.started[node] + firings));
        self.list(node);
    }

    fn list(&mut self, v: usize) {
        if !self.listed[v] {
            self.listed[v] = true;
            self.ready.push(v);
        }
    }

    fn charge(&mut self, units: u64) -> Result<(), Halt> {
        self.work = self.work.saturating_add(units);
        if self.work > self.budget {
            return Err(Halt::Budget);
        }
        Ok(())
    }

    /// Ends the firings due now, then starts every firing that can start.
    fn instant(&mut self) -> Result<(), Halt> {
        while let Some(&Reverse((t, v))) = self.ends.peek() {
            if t != self.now {
                break;
            }
            self.ends.pop();
            while self.running[v].front() == Some(&t) {
                self.running[v].pop_front();
                self.end_firing(v)?;
            }
            if let Some(&next) = self.running[v].front() {
                self.ends.push(Reverse((next, v)));
            }
        }
        while let Some(v) = self.ready.pop() {
            self.listed[v] = false;
            while self.can_start(v) {
                self.start_firing(v)?;
            }
        }
        Ok(())
    }

    /// Moves to the next instant a firing ends; `false` when none is under
    /// way (nothing will ever fire again).
    fn advance(&mut self) -> bool {
        match self.ends.peek() {
            Some(&Reverse((t, _))) => {
                self.now = t;
                true
            }
            None => false,
        }
    }

    /// Runs until nothing can fire.
    fn until_idle(&mut self) -> Result<(), Halt> {
        loop {
            self.instant()?;
            if !self.advance() {
                return Ok(());
            }
        }
    }

    fn can_start(&self, v: usize) -> bool {
        let net = self.net;
        if net.single && !self.running[v].is_empty() {
            return false;
        }
        if self
            .held
            .is_some_and(|(h, most)| h == v && self.started[v] >= most)
        {
            return false;
        }
        net.inputs[v]
            .iter()
            .all(|&e| self.tokens[e] >= net.edges[e].consume)
    }

    fn start_firing(&mut self, v: usize) -> Result<(), Halt> {
        self.charge(1)?;
        let net = self.net;
        for &e in &net.inputs[v] {
            self.tokens[e] -= net.edges[e].consume;
        }
        self.started[v] += 1;
        if net.wcet[v] == 0 {
            return self.end_firing(v);
        }
        let end = self.now.checked_add(net.wcet[v]).ok_or(Halt::Overflow)?;
        if self.running[v].is_empty() {
            self.ends.push(Reverse((end, v)));
        }
        self.running[v].push_back(end);
        Ok(())
    }

    fn end_firing(&mut self, v: usize) -> Result<(), Halt> {
        let net = self.net;
        self.completed[v] += 1;
        for &e in &net.outputs[v] {
            let edge = &net.edges[e];
            self.tokens[e] = self.tokens[e]
                .checked_add(edge.produce)
                .ok_or(Halt::Overflow)?;
            self.list(edge.dst);
        }
        // Idle again (`Single`), or one more firing allowed (`held`).
        self.list(v);
        Ok(())
    }

    /// The state the rest of the execution depends on, times relative to
    /// now: the samples per edge, then per node its firings under way and
    /// their remaining times, then `extra`.
    fn state(&self, extra: u64) -> Vec<u64> {
        let mut state = self.tokens.clone();
        for running in &self.running {
            state.push(running.len() as u64);
            state.extend(running.iter().map(|&end| end - self.now));
        }
        state.push(extra);
        state
    }
}

/// The self-timed execution watched for `L(k)` and a repeating state.
struct Watch<'n> {
    run: Run<'n>,
    source: usize,
    sink: usize,
    offset: u64,
    source_count: u64,
    sink_count: u64,
    /// Start times of the source's firings `k·γ(source)` whose `L(k)` is
    /// not known yet, and end times of the sink's firings `k·γ(sink) + δ`
    /// whose source firing has not started yet (never, in a level where δ
    /// is right).
    starts: VecDeque<u64>,
    ends: VecDeque<u64>,
    /// `L(k)` known for `k < known`; the largest and its first `k`.
    known: u64,
    worst: Option<(u64, u64)>,
}

/// A state saved by Brent's cycle detection, with the counts at it.
struct Saved {
    state: Vec<u64>,
    source_started: u64,
    sink_completed: u64,
}

impl<'n> Watch<'n> {
    fn new(net: &'n Net, counts: &[u64], ends: Ends, budget: u64) -> Watch<'n> {
        Watch {
            run: Run::new(net, budget),
            source: ends.source,
            sink: ends.sink,
            offset: ends.offset,
            source_count: counts[ends.source],
            sink_count: counts[ends.sink],
            starts: VecDeque::new(),
            ends: VecDeque::new(),
            known: 0,
            worst: None,
        }
    }

    fn run(mut self) -> Result<SelfTimed, NoSelfTimed> {
        let mut saved: Option<Saved> = None;
        // Brent: states since `saved`, and how many before saving anew.
        let (mut since, mut power) = (0u64, 1u64);
        let mut repeat: Option<(u64, u64)> = None; // (periodic_from, cycle)
        loop {
            let (source_before, sink_before) =
                (self.run.started[self.source], self.run.completed[self.sink]);
            self.run.instant()?;
            self.record(source_before, sink_before);
            if repeat.is_none() && self.run.started[self.source] > source_before {
                let state = self
                    .run
                    .state(self.run.started[self.source] % self.source_count);
                self.run.charge(2 * state.len() as u64)?;
                if let Some(s) = saved.as_ref().filter(|s| s.state == state) {
                    repeat = Some(self.periodic(s));
                } else if saved.is_none() || since == power {
                    saved = Some(Saved {
                        state,
                        source_started: self.run.started[self.source],
                        sink_completed: self.run.completed[self.sink],
                    });
                    (since, power) = (0, power * 2);
                }
                since += 1;
            }
            if let Some((from, cycle)) = repeat
                && self.known >= from + cycle
            {
                let (latency, worst_iteration) = self.worst.unwrap_or((0, 0));
                return Ok(SelfTimed {
                    latency,
                    worst_iteration,
                    periodic_from: from,
                    cycle,
                });
            }
            if !self.run.advance() {
                // A live level never stops; the caller checked it is one.
                return Err(NoSelfTimed::Budget);
            }
        }
    }

    /// From which iteration `L` repeats, and every how many: the source's
    /// and sink's firings after the saved state's instant happen again,
    /// shifted, after the current one.
    fn periodic(&self, saved: &Saved) -> (u64, u64) {
        let cycle = (self.run.started[self.source] - saved.source_started) / self.source_count;
        let after_source = saved.source_started.div_ceil(self.source_count);
        let after_sink = saved
            .sink_completed
            .saturating_sub(self.offset)
            .div_ceil(self.sink_count);
        (after_source.max(after_sink), cycle)
    }

    /// Notes the source's firings `k·γ(source)` that started and the sink's
    /// firings `k·γ(sink) + δ` that ended at this instant, and each `L(k)`
    /// now known.
    fn record(&mut self, source_before: u64, sink_before: u64) {
        let now = self.run.now;
        let started = self.run.started[self.source];
        let mut k = source_before.div_ceil(self.source_count) * self.source_count;
        while k < started {
            self.starts.push_back(now);
            k += self.source_count;
        }
        let completed = self.run.completed[self.sink];
        let mut j = first_at_or_after(sink_before, self.offset, self.sink_count);
        while j < completed {
            self.ends.push_back(now);
            j += self.sink_count;
        }
        while let (Some(&start), Some(&end)) = (self.starts.front(), self.ends.front()) {
            self.starts.pop_front();
            self.ends.pop_front();
            // A sink firing closing iteration `k` needs the source's firing
            // `k·γ(source)` to have ended (δ counts every sink firing that
            // does not), so it never ends before that starts.
            let l = end.saturating_sub(start);
            if self.worst.is_none_or(|(w, _)| l > w) {
                self.worst = Some((l, self.known));
            }
            self.known += 1;
        }
    }
}

/// The least `j ≥ from` with `j = offset + k·step` for some `k ≥ 0`.
fn first_at_or_after(from: u64, offset: u64, step: u64) -> u64 {
    if from <= offset {
        offset
    } else {
        offset + (from - offset).div_ceil(step) * step
    }
}

#[cfg(test)]
mod tests;
