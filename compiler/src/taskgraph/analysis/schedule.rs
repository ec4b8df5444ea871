//! Static schedules of one hierarchy level: a looped single-appearance
//! schedule (each node written once, e.g. `A 10(B C) D`), a flat sequence of
//! firings for one iteration, and a list schedule of one iteration's firings
//! onto several cores.
//!
//! # Notation
//!
//! [`render`] writes a firing of a node by its name, `n` consecutive firings
//! as `nA` (`3A`), and a loop as `n(…)` (`10(B C)`), terms separated by
//! spaces: `3A 2(B C) D`. A node whose name starts with a digit or holds a
//! space is parenthesized when repeated (`3(2x)`), so the count stays readable.
//! Loop boundary nodes (inside a loop body) are part of the schedule terms but
//! not written: the body of `data_loop/L` renders `B C`.
//!
//! # Single-appearance method
//!
//! The method of Bhattacharyya, Murthy and Lee (loose interdependence with
//! dynamic-programming loop factoring):
//!
//! 1. The node set is split into strongly connected components, ordered
//!    topologically (ties: the component with the node written first).
//! 2. A component of several nodes is scheduled recursively in its own frame
//!    (its counts divided by their gcd): the edges whose initial samples cover
//!    a whole frame iteration of their consumer (`initial ≥ q(dst)·consume`)
//!    are removed, which can never starve the consumer, and the rest is split
//!    into components again. If nothing can be removed, the component is
//!    tightly interdependent and has no single-appearance schedule: `None`.
//! 3. The ordered components (each firing `c` times, `c` the gcd of its
//!    nodes' counts) are nested into loops by DPPO (dynamic programming post
//!    optimization): among all ways of bracketing the sequence, the one that
//!    minimises the sum of the samples crossing each split per loop iteration,
//!    a loop over a range repeating it gcd(counts in the range) times.
//!
//! For an acyclic graph this gives the topological order with loop factoring
//! (`3A 2B`, `2(A B) C`). Every result is checked: the firings per node must
//! equal the counts, and replaying it must never read a channel short of
//! samples, which is decided edge by edge on the loops, without expanding
//! them (`valid_looped`), whatever the number of firings.

use super::level::{Level, Lists};
use super::ratio::gcd;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The most firings an expanded iteration may have: [`flat_schedule`] and
/// [`multicore`] give `None` beyond.
pub const MAX_FIRINGS: u64 = 1 << 20;

/// Above this many components in one frame, loops are factored by the gcd of
/// the whole frame only (DPPO is cubic).
const DPPO_LIMIT: usize = 64;

/// A term of a looped schedule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Schedule {
    /// `count` consecutive firings of `node`.
    Fire { node: usize, count: u64 },
    /// `body` repeated `count` times.
    Loop { count: u64, body: Vec<Schedule> },
}

/// The schedule in the notation of the module documentation.
pub fn render(level: &Level<'_>, schedule: &[Schedule]) -> String {
    render_with(level, schedule, &|_| None)
}

/// As [`render`], writing one firing of a node as `expand(node)` when it gives
/// a text (used to write a loop node as its body's schedule).
fn render_with(
    level: &Level<'_>,
    schedule: &[Schedule],
    expand: &dyn Fn(usize) -> Option<String>,
) -> String {
    let mut terms = Vec::new();
    for term in schedule {
        match term {
            Schedule::Fire { node, count } => {
                let Some(n) = level.nodes.get(*node) else {
                    continue;
                };
                if n.task.is_none() {
                    continue;
                }
                let (text, plain) = match expand(*node) {
                    Some(text) => (text, false),
                    None => {
                        let plain = !n.name.starts_with(|c: char| c.is_ascii_digit())
                            && !n.name.contains(char::is_whitespace);
                        (n.name.to_string(), plain)
                    }
                };
                terms.push(match (*count, plain) {
                    (1, _) => text,
                    (c, true) => format!("{c}{text}"),
                    (c, false) => format!("{c}({text})"),
                });
            }
            Schedule::Loop { count, body } => {
                let inner = render_with(level, body, expand);
                if inner.is_empty() {
                    continue;
                }
                terms.push(if *count == 1 {
                    inner
                } else {
                    format!("{count}({inner})")
                });
            }
        }
    }
    terms.join(" ")
}

/// The looped single-appearance schedule of a whole graph, with every loop
/// node written as its body's schedule repeated `loopCount` times (for a C-type
/// loop: at most that many): `A 10(B C) D`. `levels` are as [`Level::all`]
/// gives them (outermost first) and `schedules` their single-appearance
/// schedules; `None` when some level has none.
pub fn render_hierarchy(
    levels: &[Level<'_>],
    schedules: &[Option<Vec<Schedule>>],
) -> Option<String> {
    render_at(levels, schedules, 0)
}

/// [`render_hierarchy`] computing every level's schedule itself.
pub fn looped_schedule(graph: &crate::taskgraph::model::TaskGraph) -> Option<String> {
    let levels = Level::all(graph);
    let schedules: Vec<Option<Vec<Schedule>>> = levels
        .iter()
        .map(|level| {
            let counts = super::consistency::repetition_vector(level).ok()?;
            single_appearance(level, &counts)
        })
        .collect();
    render_hierarchy(&levels, &schedules)
}

fn render_at(
    levels: &[Level<'_>],
    schedules: &[Option<Vec<Schedule>>],
    at: usize,
) -> Option<String> {
    let level = levels.get(at)?;
    let schedule = schedules.get(at)?.as_ref()?;
    let mut bodies: Vec<Option<String>> = vec![None; level.nodes.len()];
    for (v, node) in level.nodes.iter().enumerate() {
        let Some(task) = node.task.and_then(|t| level.graph.tasks.get(t)) else {
            continue;
        };
        if let Some(l) = &task.loop_node {
            let path = format!("{}/{}", level.path, task.name.name);
            let inner = levels.iter().position(|other| other.path == path)?;
            let body = render_at(levels, schedules, inner)?;
            bodies[v] = Some(if l.loop_count == 1 {
                body
            } else {
                format!("{}({body})", l.loop_count)
            });
        } else if task.subgraph.is_some() {
            // A task standing for a sub-graph runs one iteration of it; a
            // reference that did not resolve has no level: the task's name.
            let path = format!("{}/{}", level.path, task.name.name);
            if let Some(inner) = levels.iter().position(|other| other.path == path) {
                bodies[v] = Some(render_at(levels, schedules, inner)?);
            }
        }
    }
    Some(render_with(level, schedule, &|v| {
        bodies.get(v).cloned().flatten()
    }))
}

/// A looped single-appearance schedule of one iteration (`counts` is the
/// repetition vector of `level`), or `None` when the method finds none (a
/// tightly interdependent cycle, a deadlock, or counts that are not a
/// repetition vector).
pub fn single_appearance(level: &Level<'_>, counts: &[u64]) -> Option<Vec<Schedule>> {
    if !balanced(level, counts) {
        return None;
    }
    let n = level.nodes.len();
    let all: Vec<usize> = (0..n).collect();
    let mut frames = Frames::new(level);
    let schedule = frames.schedule_set(&all, &mut counts.to_vec(), false)?;
    if fired(&schedule, n)? != counts {
        return None;
    }
    let valid = match valid_looped(level, &schedule) {
        Some(valid) => valid,
        // A node written twice (the method writes each once): only a
        // replay can tell.
        None => expand(&schedule, MAX_FIRINGS).is_some_and(|f| valid(level, &f)),
    };
    valid.then_some(schedule)
}

/// Whether replaying `schedule`, a looped single-appearance schedule firing
/// a repetition vector of `level`, never reads a channel short of samples,
/// decided on the loops without expanding them (`mp3playback`'s 10,601
/// firings were 13% of its analysis). `None` when a node is written more
/// than once or not at all.
///
/// Why it holds: the two ends of an edge `s → t` are two leaves, which lie
/// in two different terms S and T of the innermost body holding both. Each
/// execution of that body fires `s` some `a` times (all in S) and `t` some
/// `b` times (all in T), with `a·produce = b·consume`, since the body runs
/// as often for both and the repetition vector balances the edge. So each
/// execution leaves the edge with its initial samples. With S first, the
/// samples rise, then fall back; with T first, its `b` firings take
/// `b·consume` samples before any arrives, which the initial samples must
/// cover. A self-loop edge gives back what each firing takes, so its
/// initial samples must cover one firing.
fn valid_looped(level: &Level<'_>, schedule: &[Schedule]) -> Option<bool> {
    /// Per step from the top: the term's index in its body and its count.
    type Step = (usize, u64);
    fn walk(
        body: &[Schedule],
        path: &mut Vec<Step>,
        steps: &mut Vec<Step>,
        leaves: &mut [Option<(usize, usize)>],
    ) -> Option<()> {
        for (i, term) in body.iter().enumerate() {
            match term {
                Schedule::Fire { node, count } => {
                    let leaf = leaves.get_mut(*node)?;
                    if leaf.is_some() {
                        return None;
                    }
                    path.push((i, *count));
                    *leaf = Some((steps.len(), steps.len() + path.len()));
                    steps.extend_from_slice(path);
                    path.pop();
                }
                Schedule::Loop { count, body } => {
                    path.push((i, *count));
                    walk(body, path, steps, leaves)?;
                    path.pop();
                }
            }
        }
        Some(())
    }
    let mut steps = Vec::new();
    let mut leaves = vec![None; level.nodes.len()];
    walk(schedule, &mut Vec::new(), &mut steps, &mut leaves)?;
    let path = |v: usize| leaves.get(v).copied().flatten().map(|(a, b)| &steps[a..b]);
    for e in &level.edges {
        let (src, dst) = (path(e.src)?, path(e.dst)?);
        let need = if e.src == e.dst {
            u128::from(e.consume)
        } else {
            // Where the two paths part: the terms S and T.
            let split = src.iter().zip(dst).position(|(s, t)| s.0 != t.0)?;
            if src[split].0 < dst[split].0 {
                continue;
            }
            let firings = dst[split..]
                .iter()
                .try_fold(1u128, |b, &(_, count)| b.checked_mul(u128::from(count)));
            firings.and_then(|b| b.checked_mul(u128::from(e.consume)))?
        };
        if u128::from(e.initial_tokens) < need {
            return Some(false);
        }
    }
    Some(true)
}

/// Whether `counts` is a repetition vector of `level`: one positive count per
/// node, balancing every edge.
pub fn balanced(level: &Level<'_>, counts: &[u64]) -> bool {
    let n = level.nodes.len();
    counts.len() == n
        && !counts.contains(&0)
        && level.edges.iter().all(|e| {
            e.src < n
                && e.dst < n
                && u128::from(counts[e.src]) * u128::from(e.produce)
                    == u128::from(counts[e.dst]) * u128::from(e.consume)
        })
}

/// What the frames of the single-appearance recursion share: each node's
/// outgoing edges, so that a frame reads only its members' edges and the
/// recursion costs the level's size once per nesting depth, not once per
/// frame (a 20,000-node level has about as many frames); and a node-indexed
/// scratch array, all `usize::MAX` between uses.
struct Frames<'l, 'g> {
    level: &'l Level<'g>,
    outputs: Lists,
    scratch: Vec<usize>,
}

impl<'l, 'g> Frames<'l, 'g> {
    fn new(level: &'l Level<'g>) -> Frames<'l, 'g> {
        Frames {
            level,
            outputs: level.adjacency().1,
            scratch: vec![usize::MAX; level.nodes.len()],
        }
    }

    /// Schedules the nodes `members` (sorted) of one frame, where node `v`
    /// fires `q[v]` times. `split` says whether edges with enough initial
    /// samples may be removed (the members are one strongly connected
    /// component). `q` is the same on return.
    fn schedule_set(
        &mut self,
        members: &[usize],
        q: &mut [u64],
        split: bool,
    ) -> Option<Vec<Schedule>> {
        let level = self.level;
        if members.is_empty() {
            return Some(Vec::new());
        }
        if let [v] = members {
            // A self-loop keeps its sample count across a firing (consistent
            // rates): enough for one firing is enough for all.
            let starved = self.outputs[*v].iter().any(|&i| {
                let e = &level.edges[i];
                e.dst == *v && e.initial_tokens < e.consume
            });
            return if starved {
                None
            } else {
                Some(vec![Schedule::Fire {
                    node: *v,
                    count: q[*v],
                }])
            };
        }
        let components = {
            let q = &*q;
            let keep = |e: &super::level::Edge| {
                !split
                    || q[e.dst]
                        .checked_mul(e.consume)
                        .is_none_or(|need| e.initial_tokens < need)
            };
            ordered_components(level, &self.outputs, &mut self.scratch, members, &keep)
        };
        if components.len() == 1 {
            if split {
                return None; // tightly interdependent
            }
            // One strongly connected component: schedule it in its own frame.
            return self
                .schedule_component(&components[0], q)
                .map(|(c, body)| wrap(c, body));
        }
        let mut clusters = Vec::with_capacity(components.len());
        for component in components.iter() {
            clusters.push(self.schedule_component(component, q)?);
        }
        Some(factor(self, &components, &clusters, q))
    }

    /// A component as a cluster: its count (gcd of its nodes' counts) and the
    /// schedule of one cluster firing (its nodes' counts divided by it while
    /// it is scheduled, then restored).
    fn schedule_component(
        &mut self,
        component: &[usize],
        q: &mut [u64],
    ) -> Option<(u64, Vec<Schedule>)> {
        let c = component.iter().fold(0, |g, &v| gcd(g, q[v])).max(1);
        let saved: Vec<u64> = component.iter().map(|&v| q[v]).collect();
        for &v in component {
            q[v] /= c;
        }
        let body = self.schedule_set(component, q, true);
        for (&v, count) in component.iter().zip(saved) {
            q[v] = count;
        }
        Some((c, body?))
    }
}

/// `body` repeated `count` times, merging a single term into the count.
fn wrap(count: u64, body: Vec<Schedule>) -> Vec<Schedule> {
    if count == 1 {
        return body;
    }
    if let [single] = body.as_slice() {
        match single {
            Schedule::Fire { node, count: c } => {
                if let Some(total) = count.checked_mul(*c) {
                    return vec![Schedule::Fire {
                        node: *node,
                        count: total,
                    }];
                }
            }
            Schedule::Loop { count: c, body: b } => {
                if let Some(total) = count.checked_mul(*c) {
                    return vec![Schedule::Loop {
                        count: total,
                        body: b.clone(),
                    }];
                }
            }
        }
    }
    vec![Schedule::Loop { count, body }]
}

/// Nests the ordered clusters into loops (DPPO, see the module
/// documentation).
fn factor(
    frames: &mut Frames<'_, '_>,
    components: &Lists,
    clusters: &[(u64, Vec<Schedule>)],
    q: &[u64],
) -> Vec<Schedule> {
    let level = frames.level;
    let m = clusters.len();
    let counts: Vec<u64> = clusters.iter().map(|(c, _)| *c).collect();
    if m > DPPO_LIMIT {
        let g = counts.iter().fold(0, |g, &c| gcd(g, c)).max(1);
        let body = clusters
            .iter()
            .flat_map(|(c, b)| wrap(c / g, b.clone()))
            .collect();
        return wrap(g, body);
    }
    // Samples per frame iteration between each pair of clusters.
    let cluster_of = &mut frames.scratch;
    for (i, component) in components.iter().enumerate() {
        for &v in component {
            cluster_of[v] = i;
        }
    }
    let mut weight = vec![vec![0u128; m]; m];
    for &v in components.iter().flatten() {
        for &i in &frames.outputs[v] {
            let e = &level.edges[i];
            let (a, b) = (cluster_of[e.src], cluster_of[e.dst]);
            if b == usize::MAX || a == b {
                continue;
            }
            let t = u128::from(q[e.src]) * u128::from(e.produce);
            weight[a][b] = weight[a][b].saturating_add(t);
            weight[b][a] = weight[b][a].saturating_add(t);
        }
    }
    for &v in components.iter().flatten() {
        cluster_of[v] = usize::MAX;
    }
    // prefix[a][b]: sum of weight[..a][..b].
    let mut prefix = vec![vec![0u128; m + 1]; m + 1];
    for a in 0..m {
        for b in 0..m {
            prefix[a + 1][b + 1] = weight[a][b]
                .saturating_add(prefix[a][b + 1])
                .saturating_add(prefix[a + 1][b])
                .saturating_sub(prefix[a][b]);
        }
    }
    // Rows i..=k, columns k+1..=j.
    let crossing = |i: usize, k: usize, j: usize| {
        prefix[k + 1][j + 1]
            .saturating_sub(prefix[i][j + 1])
            .saturating_sub(prefix[k + 1][k + 1])
            .saturating_add(prefix[i][k + 1])
    };
    let mut g = vec![vec![0u64; m]; m];
    for (i, row) in g.iter_mut().enumerate() {
        let mut acc = 0;
        for (j, &c) in counts.iter().enumerate().skip(i) {
            acc = gcd(acc, c);
            row[j] = acc.max(1);
        }
    }
    let mut cost = vec![vec![0u128; m]; m];
    let mut split = vec![vec![0usize; m]; m];
    for len in 2..=m {
        for i in 0..=m - len {
            let j = i + len - 1;
            let mut best = (u128::MAX, i);
            for k in i..j {
                let c = cost[i][k]
                    .saturating_add(cost[k + 1][j])
                    .saturating_add(crossing(i, k, j) / u128::from(g[i][j]));
                if c < best.0 {
                    best = (c, k);
                }
            }
            cost[i][j] = best.0;
            split[i][j] = best.1;
        }
    }
    if m == 0 {
        return Vec::new();
    }
    build(clusters, &g, &split, 0, m - 1, 1)
}

fn build(
    clusters: &[(u64, Vec<Schedule>)],
    g: &[Vec<u64>],
    split: &[Vec<usize>],
    i: usize,
    j: usize,
    outer: u64,
) -> Vec<Schedule> {
    let here = g[i][j];
    if i == j {
        return wrap(clusters[i].0 / outer, clusters[i].1.clone());
    }
    let k = split[i][j];
    let mut body = build(clusters, g, split, i, k, here);
    body.extend(build(clusters, g, split, k + 1, j, here));
    wrap(here / outer, body)
}

/// The strongly connected components of the sub-graph of `members` through
/// the edges that `keep` accepts, in topological order (ties: the component
/// with the smallest node first), each sorted. `outputs` are each node's
/// outgoing edges ([`Level::adjacency`]); `local` is node-indexed scratch, all
/// `usize::MAX` before and after: the cost is the members' edges, not the
/// level's.
fn ordered_components(
    level: &Level<'_>,
    outputs: &Lists,
    local: &mut [usize],
    members: &[usize],
    keep: &dyn Fn(&super::level::Edge) -> bool,
) -> Lists {
    for (i, &v) in members.iter().enumerate() {
        local[v] = i;
    }
    let m = members.len();
    let succ = {
        let local = &*local;
        Lists::new(m, || {
            members.iter().enumerate().flat_map(move |(a, &v)| {
                outputs[v].iter().filter_map(move |&i| {
                    let e = &level.edges[i];
                    let b = local[e.dst];
                    (b != usize::MAX && a != b && keep(e)).then_some((a, b))
                })
            })
        })
    };
    for &v in members {
        local[v] = usize::MAX;
    }
    let (comp, ncomp) =
        crate::digraph::components(m, (0..m).flat_map(|a| succ[a].iter().map(move |&b| (a, b))));
    let mut components = Lists::new(ncomp, || {
        comp.iter().enumerate().map(|(i, &c)| (c, members[i]))
    });
    for c in 0..ncomp {
        if let Some(members) = components.get_mut(c) {
            members.sort_unstable();
        }
    }
    // Kahn over the condensation, smallest first node first.
    let mut indegree = vec![0usize; ncomp];
    let (succ, comp) = (&succ, &comp);
    let crossing = || {
        (0..m).flat_map(|a| {
            succ[a]
                .iter()
                .filter(move |&&b| comp[a] != comp[b])
                .map(move |&b| (comp[a], comp[b]))
        })
    };
    for (_, d) in crossing() {
        indegree[d] += 1;
    }
    let csucc = Lists::new(ncomp, crossing);
    let mut ready: BinaryHeap<Reverse<(usize, usize)>> = (0..ncomp)
        .filter(|&c| indegree[c] == 0)
        .map(|c| Reverse((components[c][0], c)))
        .collect();
    let mut order = Vec::with_capacity(ncomp);
    while let Some(Reverse((_, c))) = ready.pop() {
        order.push(c);
        for &d in &csucc[c] {
            indegree[d] -= 1;
            if indegree[d] == 0 {
                ready.push(Reverse((components[d][0], d)));
            }
        }
    }
    let components = &components;
    Lists::new(order.len(), || {
        order
            .iter()
            .enumerate()
            .flat_map(|(k, &c)| components[c].iter().map(move |&v| (k, v)))
    })
}

/// Firings per node of a looped schedule, `None` on overflow or a bad node.
fn fired(schedule: &[Schedule], n: usize) -> Option<Vec<u64>> {
    fn add(schedule: &[Schedule], times: u64, out: &mut [u64]) -> Option<()> {
        for term in schedule {
            match term {
                Schedule::Fire { node, count } => {
                    let slot = out.get_mut(*node)?;
                    *slot = slot.checked_add(count.checked_mul(times)?)?;
                }
                Schedule::Loop { count, body } => add(body, times.checked_mul(*count)?, out)?,
            }
        }
        Some(())
    }
    let mut out = vec![0; n];
    add(schedule, 1, &mut out)?;
    Some(out)
}

/// The firings of a looped schedule in order, `None` beyond `limit` firings.
pub fn expand(schedule: &[Schedule], limit: u64) -> Option<Vec<usize>> {
    fn go(schedule: &[Schedule], limit: u64, out: &mut Vec<usize>) -> Option<()> {
        for term in schedule {
            match term {
                Schedule::Fire { node, count } => {
                    if (out.len() as u64).checked_add(*count)? > limit {
                        return None;
                    }
                    out.extend(std::iter::repeat_n(*node, usize::try_from(*count).ok()?));
                }
                Schedule::Loop { count, body } => {
                    for _ in 0..*count {
                        let before = out.len();
                        go(body, limit, out)?;
                        if out.len() == before {
                            break; // a body without firings
                        }
                    }
                }
            }
        }
        Some(())
    }
    let mut out = Vec::new();
    go(schedule, limit, &mut out)?;
    Some(out)
}

/// Whether `firings` never reads a channel short of samples.
pub fn valid(level: &Level<'_>, firings: &[usize]) -> bool {
    let mut tokens: Vec<u64> = level.edges.iter().map(|e| e.initial_tokens).collect();
    let (inputs, outputs) = level.adjacency();
    let (inputs, outputs) = (inputs.slices(), outputs.slices());
    for &v in firings {
        let (Some(&ins), Some(&outs)) = (inputs.get(v), outputs.get(v)) else {
            return false;
        };
        for &i in ins {
            match tokens[i].checked_sub(level.edges[i].consume) {
                Some(t) => tokens[i] = t,
                None => return false,
            }
        }
        for &i in outs {
            tokens[i] = tokens[i].saturating_add(level.edges[i].produce);
        }
    }
    true
}

/// A valid sequence of one iteration's firings, found by executing it
/// symbolically: among the nodes that can fire and have firings left, the one
/// latest in topological order (ties: file order) fires first, which drains
/// samples as soon as they can be used and keeps buffers small. `None` when
/// the iteration deadlocks, has more than [`MAX_FIRINGS`] firings, or `counts`
/// is not a repetition vector of `level`.
pub fn flat_schedule(level: &Level<'_>, counts: &[u64]) -> Option<Vec<usize>> {
    if !balanced(level, counts) {
        return None;
    }
    let n = level.nodes.len();
    let total = counts.iter().try_fold(0u64, |a, &c| a.checked_add(c))?;
    if total > MAX_FIRINGS {
        return None;
    }
    let all: Vec<usize> = (0..n).collect();
    let (inputs, outputs) = level.adjacency();
    let order: Vec<usize> =
        ordered_components(level, &outputs, &mut vec![usize::MAX; n], &all, &|_| true)
            .items()
            .to_vec();
    let mut rank = vec![0usize; n];
    for (r, &v) in order.iter().enumerate() {
        rank[v] = r;
    }
    let (inputs, outputs) = (inputs.slices(), outputs.slices());
    let mut tokens: Vec<u64> = level.edges.iter().map(|e| e.initial_tokens).collect();
    let mut remaining = counts.to_vec();
    let can_fire = |v: usize, tokens: &[u64], remaining: &[u64]| {
        remaining[v] > 0
            && inputs[v]
                .iter()
                .all(|&i| tokens[i] >= level.edges[i].consume)
    };
    // The ranks of the nodes that can fire, each once (`waiting`): a heap,
    // not an ordered set, since only the largest is ever taken (a tree's
    // insert and removal per firing was most of this on `mp3playback`'s
    // 10,601 firings). Only `v` consumes from its inputs, so a node waiting
    // can still fire when its turn comes.
    let mut waiting = vec![false; n];
    let mut ready: BinaryHeap<usize> = BinaryHeap::with_capacity(n);
    let make_ready = |v: usize, ready: &mut BinaryHeap<usize>, waiting: &mut [bool]| {
        if !waiting[v] {
            waiting[v] = true;
            ready.push(rank[v]);
        }
    };
    for v in (0..n).filter(|&v| can_fire(v, &tokens, &remaining)) {
        make_ready(v, &mut ready, &mut waiting);
    }
    let mut firings = Vec::with_capacity(usize::try_from(total).unwrap_or(0));
    while let Some(r) = ready.pop() {
        let v = order[r];
        waiting[v] = false;
        for &i in inputs[v] {
            tokens[i] -= level.edges[i].consume;
        }
        for &i in outputs[v] {
            tokens[i] = tokens[i].saturating_add(level.edges[i].produce);
        }
        remaining[v] -= 1;
        firings.push(v);
        if can_fire(v, &tokens, &remaining) {
            make_ready(v, &mut ready, &mut waiting);
        }
        for &i in outputs[v] {
            let d = level.edges[i].dst;
            if can_fire(d, &tokens, &remaining) {
                make_ready(d, &mut ready, &mut waiting);
            }
        }
    }
    remaining.iter().all(|&r| r == 0).then_some(firings)
}

/// The execution time of a node's firing: the task's WCET (1 when not given),
/// 0 for a loop boundary node.
pub fn execution_time(level: &Level<'_>, node: usize) -> u64 {
    level
        .nodes
        .get(node)
        .filter(|n| n.task.is_some())
        .map_or(0, |n| n.wcet.unwrap_or(1))
}

/// One iteration's firings list-scheduled onto `cores` cores: per core, the
/// `(node, start time)` of its firings in time order.
///
/// The firings form a precedence graph (as in the equivalent homogeneous
/// graph, within one iteration): firing `k` of a node follows firing `k - 1`
/// of the same node, and the last firing that produced a sample it consumes
/// (samples initially on a channel come first and need no producer). Firings
/// are taken highest bottom level first (the longest path of execution times
/// from the firing to the end of the iteration; ties: node, then firing
/// number) once their predecessors are placed, each on the core where it can
/// start earliest (ties: the lowest core). `None` when `cores` is 0, the
/// iteration deadlocks, it has more than [`MAX_FIRINGS`] firings, or `counts`
/// is not a repetition vector of `level`.
pub fn multicore(
    level: &Level<'_>,
    counts: &[u64],
    cores: usize,
) -> Option<Vec<Vec<(usize, u64)>>> {
    if cores == 0 || !balanced(level, counts) {
        return None;
    }
    let n = level.nodes.len();
    let total = counts.iter().try_fold(0u64, |a, &c| a.checked_add(c))?;
    if total > MAX_FIRINGS {
        return None;
    }
    let total = usize::try_from(total).ok()?;
    // Firing k of node v is offset[v] + k.
    let mut offset = vec![0usize; n + 1];
    let mut owner = Vec::with_capacity(total);
    for v in 0..n {
        offset[v + 1] = offset[v] + usize::try_from(counts[v]).ok()?;
        owner.extend(std::iter::repeat_n(v, usize::try_from(counts[v]).ok()?));
    }
    let (inputs, _) = level.adjacency();
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); total];
    let mut succs: Vec<Vec<usize>> = vec![Vec::new(); total];
    for v in 0..n {
        for k in 0..counts[v] {
            let f = offset[v] + k as usize;
            if k > 0 {
                preds[f].push(f - 1);
            }
            for &i in &inputs[v] {
                let e = &level.edges[i];
                // Samples k·c .. (k+1)·c - 1 of the channel; the first
                // `initial` were there before the iteration.
                let last = (u128::from(k) + 1) * u128::from(e.consume) - 1;
                let initial = u128::from(e.initial_tokens);
                if last < initial {
                    continue;
                }
                let producer = (last - initial) / u128::from(e.produce);
                if producer >= u128::from(counts[e.src]) {
                    return None; // more than one iteration produces
                }
                let p = offset[e.src] + producer as usize;
                if p != f && !preds[f].contains(&p) {
                    preds[f].push(p);
                }
            }
        }
    }
    for (f, ps) in preds.iter().enumerate() {
        for &p in ps {
            succs[p].push(f);
        }
    }
    // Topological order of the firings (a cycle means deadlock).
    let mut missing: Vec<usize> = preds.iter().map(Vec::len).collect();
    let mut topo: Vec<usize> = (0..total).filter(|&f| missing[f] == 0).collect();
    let mut at = 0;
    while let Some(&f) = topo.get(at) {
        at += 1;
        for &s in &succs[f] {
            missing[s] -= 1;
            if missing[s] == 0 {
                topo.push(s);
            }
        }
    }
    if topo.len() != total {
        return None;
    }
    let time: Vec<u64> = (0..n).map(|v| execution_time(level, v)).collect();
    let mut bottom = vec![0u64; total];
    for &f in topo.iter().rev() {
        let after = succs[f].iter().map(|&s| bottom[s]).max().unwrap_or(0);
        bottom[f] = after.saturating_add(time[owner[f]]);
    }
    let mut missing: Vec<usize> = preds.iter().map(Vec::len).collect();
    let mut ready: BinaryHeap<(u64, Reverse<usize>)> = (0..total)
        .filter(|&f| missing[f] == 0)
        .map(|f| (bottom[f], Reverse(f)))
        .collect();
    let mut finish = vec![0u64; total];
    let mut free = vec![0u64; cores];
    let mut placed: Vec<Vec<(usize, u64)>> = vec![Vec::new(); cores];
    while let Some((_, Reverse(f))) = ready.pop() {
        let earliest = preds[f].iter().map(|&p| finish[p]).max().unwrap_or(0);
        let core = (0..cores)
            .min_by_key(|&c| (free[c].max(earliest), c))
            .unwrap_or(0);
        let start = free[core].max(earliest);
        finish[f] = start.saturating_add(time[owner[f]]);
        free[core] = finish[f];
        placed[core].push((owner[f], start));
        for &s in &succs[f] {
            missing[s] -= 1;
            if missing[s] == 0 {
                ready.push((bottom[s], Reverse(s)));
            }
        }
    }
    Some(placed)
}

#[cfg(test)]
mod tests {
    use super::super::consistency::repetition_vector;
    use super::super::testing::*;
    use super::*;
    use crate::diag::FileId;
    use crate::taskgraph::model::*;

    fn top(g: &TaskGraph) -> (Level<'_>, Vec<u64>) {
        let level = Level::build(g, None, g.name.clone());
        let counts = repetition_vector(&level).unwrap();
        (level, counts)
    }

    /// The single-appearance schedule, checked: each node once, valid.
    fn sas(level: &Level<'_>, counts: &[u64]) -> Option<String> {
        let s = single_appearance(level, counts)?;
        let firings = expand(&s, MAX_FIRINGS).unwrap();
        assert!(valid(level, &firings), "{s:?}");
        assert_eq!(fired(&s, counts.len()).unwrap(), counts);
        let mut appearances = vec![0; counts.len()];
        fn count(s: &[Schedule], out: &mut [usize]) {
            for t in s {
                match t {
                    Schedule::Fire { node, .. } => out[*node] += 1,
                    Schedule::Loop { body, .. } => count(body, out),
                }
            }
        }
        count(&s, &mut appearances);
        assert!(appearances.iter().all(|&a| a == 1), "{s:?}");
        Some(render(level, &s))
    }

    /// Replays a flat schedule: never short of samples, each node γ times.
    fn check_flat(level: &Level<'_>, counts: &[u64]) -> Vec<usize> {
        let firings = flat_schedule(level, counts).expect("deadlock-free");
        assert!(valid(level, &firings));
        let mut fired = vec![0u64; counts.len()];
        for &v in &firings {
            fired[v] += 1;
        }
        assert_eq!(fired, counts);
        firings
    }

    #[test]
    fn data_loop_is_a_l_d_with_body_b_c() {
        let g = data_loop();
        let levels = Level::all(&g);
        let counts = repetition_vector(&levels[0]).unwrap();
        assert_eq!(sas(&levels[0], &counts).unwrap(), "A L D");
        let body = repetition_vector(&levels[1]).unwrap();
        assert_eq!(sas(&levels[1], &body).unwrap(), "B C");
        // The boundary nodes are scheduled around the body, not written.
        assert_eq!(
            single_appearance(&levels[1], &body).unwrap(),
            [2, 0, 1, 3].map(|node| Schedule::Fire { node, count: 1 })
        );
        assert_eq!(looped_schedule(&g).unwrap(), "A 10(B C) D");
        assert_eq!(check_flat(&levels[0], &counts), [0, 1, 2]);
    }

    #[test]
    fn example_files_render_their_looped_schedules() {
        let load = |text: &str| {
            crate::taskgraph::load_task_graph(FileId(0), text)
                .0
                .unwrap()
        };
        let data_loop = load(include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/taskgraphs/data_loop.taskgraph.xml"
        )));
        assert_eq!(looped_schedule(&data_loop).unwrap(), "A 10(B C) D");
        let kmeans = load(include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/taskgraphs/kmeans.taskgraph.xml"
        )));
        assert_eq!(
            looped_schedule(&kmeans).unwrap(),
            "ReadPoints InitCenters 500(Select 16(Nearest) ReplaceCenter) Output"
        );
    }

    #[test]
    fn multirate_chain_factors_firing_counts() {
        let g = graph(
            "chain",
            vec![task("A", &["o>2"]), task("B", &["i<3"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let (level, counts) = top(&g);
        assert_eq!(counts, [3, 2]);
        assert_eq!(sas(&level, &counts).unwrap(), "3A 2B");
        check_flat(&level, &counts);
    }

    #[test]
    fn loops_nest_where_they_shrink_buffers() {
        // γ = (2, 2, 1): A and B alternate, C once at the end.
        let g = graph(
            "nest",
            vec![
                task("A", &["o>1"]),
                task("B", &["i<1", "o>1"]),
                task("C", &["i<2"]),
            ],
            vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
        );
        let (level, counts) = top(&g);
        assert_eq!(sas(&level, &counts).unwrap(), "2(A B) C");
        let s = single_appearance(&level, &counts).unwrap();
        assert_eq!(
            s,
            [
                Schedule::Loop {
                    count: 2,
                    body: vec![
                        Schedule::Fire { node: 0, count: 1 },
                        Schedule::Fire { node: 1, count: 1 }
                    ]
                },
                Schedule::Fire { node: 2, count: 1 }
            ]
        );
        // And the other way round: A once, then B and C alternate.
        let g = graph(
            "nest2",
            vec![
                task("A", &["o>2"]),
                task("B", &["i<1", "o>1"]),
                task("C", &["i<1"]),
            ],
            vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
        );
        let (level, counts) = top(&g);
        assert_eq!(sas(&level, &counts).unwrap(), "A 2(B C)");
    }

    #[test]
    fn feedback_with_enough_samples_has_a_single_appearance_schedule() {
        // A makes 2 for B (taking 1); B returns 1 each, A takes 2: γ = (1, 2).
        let fed = |tokens| {
            graph(
                "feedback",
                vec![
                    task("S", &["o>1"]),
                    task("A", &["in<1", "i<2", "o>2"]),
                    task("B", &["i<1", "o>1"]),
                ],
                vec![
                    channel("S.o", "A.in", 0, 1),
                    channel("A.o", "B.i", 0, 2),
                    channel("B.o", "A.i", tokens, 3),
                ],
            )
        };
        let g = fed(2);
        let (level, counts) = top(&g);
        assert_eq!(counts, [1, 1, 2]);
        assert_eq!(sas(&level, &counts).unwrap(), "S A 2B");
        check_flat(&level, &counts);
        // One sample short: deadlock, so no schedule at all.
        let g = fed(1);
        let (level, counts) = top(&g);
        assert_eq!(single_appearance(&level, &counts), None);
        assert_eq!(flat_schedule(&level, &counts), None);
        assert_eq!(multicore(&level, &counts, 2), None);
        // Self-loops with a sample.
        let g = graph(
            "self",
            vec![task("A", &["i<1", "o>1", "x>1"]), task("B", &["i<1"])],
            vec![channel("A.o", "A.i", 1, 1), channel("A.x", "B.i", 0, 2)],
        );
        let (level, counts) = top(&g);
        assert_eq!(sas(&level, &counts).unwrap(), "A B");
    }

    #[test]
    fn tightly_interdependent_cycle_has_only_a_flat_schedule() {
        // γ = (2, 1); neither channel holds a whole frame's worth: A B A.
        let g = graph(
            "tight",
            vec![task("A", &["i<1", "o>1"]), task("B", &["i<2", "o>2"])],
            vec![channel("A.o", "B.i", 1, 1), channel("B.o", "A.i", 1, 2)],
        );
        let (level, counts) = top(&g);
        assert_eq!(counts, [2, 1]);
        assert_eq!(single_appearance(&level, &counts), None);
        assert_eq!(check_flat(&level, &counts), [0, 1, 0]);
    }

    #[test]
    fn nested_cycles_are_split_recursively() {
        // S → (A ⇄ B ⇄ C) → T where the inner cycles carry enough samples
        // once the outer one is cut.
        let g = graph(
            "nested",
            vec![
                task("S", &["o>2"]),
                task("A", &["in<1", "fb<1", "o>1"]),
                task("B", &["i<1", "back>1", "o>2", "fb<2"]),
                task("C", &["i<2", "back>2", "o>1"]),
                task("T", &["i<1"]),
            ],
            vec![
                channel("S.o", "A.in", 0, 1),
                channel("A.o", "B.i", 0, 2),
                channel("B.back", "A.fb", 2, 3),
                channel("B.o", "C.i", 0, 4),
                channel("C.back", "B.fb", 2, 5),
                channel("C.o", "T.i", 0, 6),
            ],
        );
        let (level, counts) = top(&g);
        assert_eq!(counts, [1, 2, 2, 2, 2]);
        let s = sas(&level, &counts).unwrap();
        assert_eq!(s, "S 2(A B C T)");
        check_flat(&level, &counts);
    }

    #[test]
    fn flat_schedules_are_valid_and_drain_early() {
        let g = graph(
            "chain",
            vec![
                task("A", &["o>2"]),
                task("B", &["i<3", "o>1"]),
                task("C", &["i<2"]),
            ],
            vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
        );
        let (level, counts) = top(&g);
        assert_eq!(check_flat(&level, &counts), [0, 0, 1, 0, 1, 2]);
    }

    fn fork_join() -> TaskGraph {
        let mut tasks = vec![
            task("S", &["o1>1", "o2>1"]),
            task("X", &["i<1", "o>1"]),
            task("Y", &["i<1", "o>1"]),
            task("J", &["i1<1", "i2<1"]),
        ];
        for (t, w) in tasks.iter_mut().zip([1, 5, 5, 1]) {
            t.wcet = Some(w);
        }
        graph(
            "fork_join",
            tasks,
            vec![
                channel("S.o1", "X.i", 0, 1),
                channel("S.o2", "Y.i", 0, 2),
                channel("X.o", "J.i1", 0, 3),
                channel("Y.o", "J.i2", 0, 4),
            ],
        )
    }

    #[test]
    fn two_cores_run_the_branches_of_a_fork_join_in_parallel() {
        let g = fork_join();
        let (level, counts) = top(&g);
        let cores = multicore(&level, &counts, 2).unwrap();
        assert_eq!(cores, [vec![(0, 0), (1, 1), (3, 6)], vec![(2, 1)]]);
        let one = multicore(&level, &counts, 1).unwrap();
        assert_eq!(one, [vec![(0, 0), (1, 1), (2, 6), (3, 11)]]);
        assert_eq!(multicore(&level, &counts, 0), None);
    }

    #[test]
    fn multicore_follows_the_samples_of_multirate_channels() {
        // A makes 2, B takes 3 (γ = 3, 2): B's first firing needs A's second,
        // its second firing A's third; firings of a node are in order.
        let g = graph(
            "chain",
            vec![task("A", &["o>2"]), task("B", &["i<3"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let (level, counts) = top(&g);
        let cores = multicore(&level, &counts, 3).unwrap();
        let mut all: Vec<(u64, usize)> = cores
            .iter()
            .flatten()
            .map(|&(node, start)| (start, node))
            .collect();
        all.sort_unstable();
        assert_eq!(all, [(0, 0), (1, 0), (2, 0), (2, 1), (3, 1)]);
    }

    #[test]
    fn names_that_would_blur_with_counts_are_parenthesized() {
        let g = graph(
            "digits",
            vec![task("2x", &["o>1"]), task("y", &["i<3"])],
            vec![channel("2x.o", "y.i", 0, 1)],
        );
        let (level, counts) = top(&g);
        assert_eq!(sas(&level, &counts).unwrap(), "3(2x) y");
    }

    #[test]
    fn odd_input_gives_none_not_a_panic() {
        let g = fork_join();
        let level = Level::build(&g, None, g.name.clone());
        assert_eq!(single_appearance(&level, &[1, 1]), None);
        assert_eq!(flat_schedule(&level, &[1]), None);
        assert_eq!(multicore(&level, &[1], 2), None);
        assert_eq!(single_appearance(&level, &[0, 1, 1, 1]), None);
        // Counts that do not balance the rates.
        assert_eq!(single_appearance(&level, &[1, 2, 1, 1]), None);
        assert_eq!(flat_schedule(&level, &[1, 2, 1, 1]), None);
        assert_eq!(multicore(&level, &[1, 2, 1, 1], 2), None);
        // Too many firings to expand; the looped form still exists.
        let big = u64::MAX / 2;
        let g = graph(
            "big",
            vec![task("A", &[&format!("o>{big}")]), task("B", &["i<1"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let (level, counts) = top(&g);
        assert_eq!(flat_schedule(&level, &counts), None);
        assert_eq!(multicore(&level, &counts, 4), None);
        assert_eq!(single_appearance(&level, &[1, 1]), None);
        let s = single_appearance(&level, &counts).unwrap();
        assert_eq!(render(&level, &s), format!("A {big}B"));
        assert_eq!(expand(&s, 10), None);
        let idle = Schedule::Loop {
            count: u64::MAX,
            body: vec![Schedule::Fire { node: 0, count: 0 }],
        };
        assert_eq!(expand(&[idle], 10), Some(vec![]));
        // An empty graph.
        let g = graph("empty", vec![], vec![]);
        let (level, counts) = top(&g);
        assert_eq!(single_appearance(&level, &counts), Some(vec![]));
        assert_eq!(flat_schedule(&level, &counts), Some(vec![]));
        assert_eq!(multicore(&level, &counts, 2), Some(vec![vec![], vec![]]));
    }

    /// `schedule` with the terms of every body reordered by `turns` (each
    /// body rotated by the next turn, then its first two terms swapped when
    /// the turn is odd): single-appearance and firing the same counts, but
    /// often starving an edge.
    fn reordered(schedule: &[Schedule], turns: &mut impl Iterator<Item = usize>) -> Vec<Schedule> {
        let mut body: Vec<Schedule> = schedule
            .iter()
            .map(|term| match term {
                Schedule::Loop { count, body } => Schedule::Loop {
                    count: *count,
                    body: reordered(body, turns),
                },
                fire => fire.clone(),
            })
            .collect();
        let turn = turns.next().unwrap_or(0);
        if !body.is_empty() {
            let len = body.len();
            body.rotate_left(turn % len);
            if turn % 2 == 1 && len > 1 {
                body.swap(0, 1);
            }
        }
        body
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        /// The check on the loops says what replaying the expansion says,
        /// on the method's schedules and on reorderings of them.
        #[test]
        fn looped_validity_is_the_replays(
            random in random_level(),
            turns in proptest::collection::vec(0usize..7, 1..12),
        ) {
            let g = random.graph();
            let (level, counts) = top(&g);
            let Some(s) = single_appearance(&level, &counts) else {
                return Ok(());
            };
            let replay = |s: &[Schedule]| valid(&level, &expand(s, MAX_FIRINGS).unwrap());
            proptest::prop_assert_eq!(valid_looped(&level, &s), Some(true));
            proptest::prop_assert!(replay(&s));
            let other = reordered(&s, &mut turns.iter().copied().cycle());
            proptest::prop_assert_eq!(fired(&other, counts.len()).unwrap(), counts.clone());
            proptest::prop_assert_eq!(valid_looped(&level, &other), Some(replay(&other)), "{:?}", other);
        }
    }

    #[test]
    fn looped_validity_needs_each_node_written_once() {
        let g = graph(
            "twice",
            vec![task("A", &["o>1"]), task("B", &["i<1"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let (level, _) = top(&g);
        let a = Schedule::Fire { node: 0, count: 1 };
        let b = Schedule::Fire { node: 1, count: 1 };
        assert_eq!(valid_looped(&level, &[b.clone(), a.clone()]), Some(false));
        assert_eq!(valid_looped(&level, &[a.clone(), b.clone()]), Some(true));
        assert_eq!(valid_looped(&level, &[a.clone(), a.clone(), b]), None);
        assert_eq!(valid_looped(&level, &[a]), None);
    }

    #[test]
    fn published_sdf3_graphs_get_valid_schedules() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sdf3");
        let mut seen = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "xml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let Some(g) = crate::taskgraph::load_task_graph(FileId(0), &text).0 else {
                continue;
            };
            for level in Level::all(&g) {
                let Ok(counts) = repetition_vector(&level) else {
                    continue;
                };
                if super::super::deadlock::find_deadlock(&level, &counts).is_some() {
                    assert_eq!(flat_schedule(&level, &counts), None);
                    continue;
                }
                let total: u64 = counts.iter().sum();
                if total > MAX_FIRINGS {
                    continue;
                }
                seen += 1;
                check_flat(&level, &counts);
                if let Some(s) = single_appearance(&level, &counts) {
                    assert!(valid(&level, &expand(&s, MAX_FIRINGS).unwrap()));
                }
                let cores = multicore(&level, &counts, 3).unwrap();
                let placed: usize = cores.iter().map(Vec::len).sum();
                assert_eq!(placed as u64, total, "{}", path.display());
            }
        }
        assert!(seen > 0);
    }
}
