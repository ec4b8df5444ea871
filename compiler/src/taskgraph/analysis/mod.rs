//! Analyses of a task graph, level by level (the top graph and every loop
//! body): consistency and repetition vectors, deadlock, schedules and buffer
//! bounds; plus the structural SDF/L rules. Results are data; the problems
//! found are also diagnostics on the channel or task concerned.

pub mod buffers;
pub mod consistency;
pub mod deadlock;
pub mod latency;
pub mod level;
pub mod ratio;
pub mod rules;
pub mod schedule;
pub mod throughput;
pub mod tradeoff;
pub mod triggers;

use crate::diag::{Code, Diagnostic};
use crate::taskgraph::model::TaskGraph;
use crate::taskgraph::subgraph::Hierarchy;
use consistency::{RateProblem, repetition_vector};
use deadlock::find_deadlock;
use level::Level;
use std::collections::HashMap;
pub use throughput::{Concurrency, NoPeriod};

/// What the analyses found about one hierarchy level.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LevelReport {
    /// `kmeans`, `kmeans/Converge`, ...
    pub path: String,
    /// Node names: the level's tasks, then its loop boundary nodes if any.
    pub nodes: Vec<String>,
    /// Firings per iteration of each node, when the rates are consistent.
    pub repetition: Option<Vec<u64>>,
    /// Whether one iteration completes (`None` when inconsistent).
    pub deadlock_free: Option<bool>,
    /// When it does not: the cycle that blocks it.
    pub blocked: Option<BlockedCycle>,
    /// A looped single-appearance schedule (`3A 2B`), else a flat one, when
    /// the level is consistent and deadlock-free.
    pub schedule: Option<String>,
    /// Per edge of the level: the most samples it holds under that schedule.
    pub buffers: Vec<BufferBound>,
    /// The self-timed iteration period, or why there is none (never
    /// missing without a reason).
    pub throughput: Result<ThroughputReport, NoPeriod>,
}

/// A cycle of a level whose tasks wait for each other, so that one iteration
/// cannot complete: what the deadlock diagnostic names, as data for pictures.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlockedCycle {
    /// The level's node names around the cycle, in flow order.
    pub nodes: Vec<String>,
    /// The cycle's channels: indices in the level's graph's `channels`.
    pub channels: Vec<usize>,
}

/// The iteration period of the self-timed execution and the cycle bounding it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ThroughputReport {
    /// Time units per iteration, exact (`16`, `11/2`).
    pub period: ratio::Ratio,
    /// Node names around the critical cycle, in flow order (one name: that
    /// task alone bounds the period, by not overlapping with itself or by its
    /// self-loop channel); empty when no cycle bounds it (period 0).
    pub critical_cycle: Vec<String>,
}

/// The most samples a channel holds while one iteration runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BufferBound {
    /// `A.o → B.i`
    pub channel: String,
    pub samples: u64,
}

#[derive(Clone, Debug)]
pub struct GraphReport {
    /// How the throughput was computed: whether a task fires concurrently
    /// with itself.
    pub concurrency: Concurrency,
    pub levels: Vec<LevelReport>,
    /// The whole hierarchy as one looped schedule (`A 10(B C) D`), where every
    /// level has a single-appearance schedule.
    pub looped_schedule: Option<String>,
    /// The least iteration period the time-triggered tasks allow, where the
    /// graph has any (`triggers`).
    pub time_bound: Option<triggers::TimeBound>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Default for GraphReport {
    fn default() -> GraphReport {
        GraphReport {
            concurrency: Concurrency::Single,
            levels: Vec::new(),
            looped_schedule: None,
            time_bound: None,
            diagnostics: Vec::new(),
        }
    }
}

impl GraphReport {
    pub fn is_consistent(&self) -> bool {
        self.levels.iter().all(|l| l.repetition.is_some())
    }

    pub fn is_deadlock_free(&self) -> bool {
        self.levels.iter().all(|l| l.deadlock_free == Some(true))
    }
}

/// Runs the analyses on every level of `graph`, one firing of a task at a
/// time (as the generated code runs it).
pub fn analyze(graph: &TaskGraph) -> GraphReport {
    analyze_with(graph, &Hierarchy::default())
}

/// [`analyze_with`], one firing of a task at a time.
pub fn analyze_with(graph: &TaskGraph, hierarchy: &Hierarchy) -> GraphReport {
    analyze_as(graph, hierarchy, Concurrency::Single)
}

/// Runs the analyses on every level of `graph` and of the sub-graphs its
/// tasks reference (`hierarchy`, from [`crate::taskgraph::resolve`]),
/// each at `<level>/<task>` after the graph's own levels.
///
/// A task standing for a sub-graph fires once per iteration of it: its ports
/// carry one iteration's samples (E079 otherwise, on its `subgraph`
/// attribute), and without a `wcet` of its own its execution time is the
/// time one iteration of the sub-graph takes on one processor, in schedule
/// order: Σ γ(v)·t(v) over the sub-graph's top level, where a loop node takes
/// `loopCount` times its body's time (a C-type loop at most that many) and a
/// task standing for a sub-graph that sub-graph's time, recursively. (A loop
/// node's own firing still takes no time in its level's throughput, as
/// before.) The throughput lets a task fire as `concurrency` says.
pub fn analyze_as(
    graph: &TaskGraph,
    hierarchy: &Hierarchy,
    concurrency: Concurrency,
) -> GraphReport {
    let mut report = GraphReport {
        concurrency,
        diagnostics: rules::check(graph),
        ..GraphReport::default()
    };
    let (mut levels, under): (Vec<Level<'_>>, Vec<Option<usize>>) =
        Level::all_with(graph, hierarchy)
            .into_iter()
            .map(|h| (h.level, h.under))
            .unzip();
    let n = levels.len();
    let mut reports = Vec::with_capacity(n);
    let mut found = Vec::with_capacity(n);
    // Each level's single-appearance schedule, kept to write the whole
    // hierarchy's looped schedule at the end.
    let mut single_appearance = Vec::with_capacity(n);
    // The time of one iteration of each level analysed so far, by path.
    let mut work: HashMap<String, u64> = HashMap::new();
    // Innermost first: a level's sub-graph tasks take their sub-graph's time.
    for level in levels.iter_mut().rev() {
        sub_graph_times(level, &work);
        let mut diagnostics = Vec::new();
        let (level_report, sas) = analyze_level(level, concurrency, &mut diagnostics);
        if let Some(w) = level_report
            .repetition
            .as_ref()
            .and_then(|counts| iteration_time(level, counts, &work))
        {
            work.insert(level.path.clone(), w);
        }
        reports.push(level_report);
        found.push(diagnostics);
        single_appearance.push(sas);
    }
    reports.reverse();
    found.reverse();
    single_appearance.reverse();
    for ((level_report, diagnostics), under) in reports.into_iter().zip(found).zip(&under) {
        match under {
            None => report.diagnostics.extend(diagnostics),
            Some(i) => report
                .diagnostics
                .extend(at_reference(graph, hierarchy, *i, diagnostics)),
        }
        report.levels.push(level_report);
    }
    report.looped_schedule = schedule::render_hierarchy(&levels, &single_appearance);
    report.time_bound = triggers::time_bound(&levels, &report.levels);
    report
}

/// The levels of the whole hierarchy as [`analyze_with`] analyses them (in
/// the order of its report's levels), the tasks standing for sub-graphs
/// timed by their sub-graph: for schedules made outside the analysis.
pub fn hierarchy_levels<'g>(graph: &'g TaskGraph, hierarchy: &'g Hierarchy) -> Vec<Level<'g>> {
    let mut levels: Vec<Level<'g>> = Level::all_with(graph, hierarchy)
        .into_iter()
        .map(|h| h.level)
        .collect();
    let mut work: HashMap<String, u64> = HashMap::new();
    for level in levels.iter_mut().rev() {
        sub_graph_times(level, &work);
        if let Some(w) = repetition_vector(level)
            .ok()
            .and_then(|counts| iteration_time(level, &counts, &work))
        {
            work.insert(level.path.clone(), w);
        }
    }
    levels
}

/// Consistency, deadlock, schedule and throughput of one level.
fn analyze_level(
    level: &Level<'_>,
    concurrency: Concurrency,
    diagnostics: &mut Vec<Diagnostic>,
) -> (LevelReport, Option<Vec<schedule::Schedule>>) {
    let nodes = level.nodes.iter().map(|n| n.name.to_string()).collect();
    let mut level_report = LevelReport {
        path: level.path.clone(),
        nodes,
        repetition: None,
        deadlock_free: None,
        blocked: None,
        schedule: None,
        buffers: Vec::new(),
        throughput: Err(NoPeriod::Inconsistent),
    };
    let mut sas = None;
    match repetition_vector(level) {
        Ok(counts) => {
            // The flat schedule is one whole iteration executed: where there
            // is one the level cannot deadlock, and only without one (a
            // deadlock, or more than `MAX_FIRINGS` firings) is the iteration
            // executed again to find the blocked cycle.
            let flat = schedule::flat_schedule(level, &counts);
            let blocked = match flat {
                Some(_) => None,
                None => find_deadlock(level, &counts),
            };
            match &blocked {
                Some(b) => diagnostics.push(deadlock_diagnostic(level, b)),
                None => {
                    sas = schedule_level(
                        level,
                        &counts,
                        flat,
                        concurrency,
                        &mut level_report,
                        diagnostics,
                    )
                }
            }
            if blocked.is_some() {
                level_report.throughput = Err(NoPeriod::Deadlock);
            }
            level_report.deadlock_free = Some(blocked.is_none());
            level_report.blocked = blocked.map(|b| BlockedCycle {
                nodes: b
                    .nodes
                    .iter()
                    .map(|&n| level.nodes[n].name.to_string())
                    .collect(),
                channels: b
                    .edges
                    .iter()
                    .filter_map(|&e| level.edges[e].channel)
                    .collect(),
            });
            level_report.repetition = Some(counts);
        }
        Err(problem) => diagnostics.push(rate_diagnostic(level, &problem)),
    }
    (level_report, sas)
}

/// Gives the tasks of `level` that stand for a sub-graph and have no `wcet`
/// of their own the time of one iteration of their sub-graph (already in
/// `work` when the sub-graph's level is consistent).
fn sub_graph_times(level: &mut Level<'_>, work: &HashMap<String, u64>) {
    let graph = level.graph;
    for node in &mut level.nodes {
        let Some(task) = node.task.and_then(|t| graph.tasks.get(t)) else {
            continue;
        };
        if task.wcet.is_none() && task.subgraph.is_some() {
            let inner = format!("{}/{}", level.path, task.name.name);
            node.wcet = work.get(&inner).copied().filter(|&w| w > 0);
        }
    }
}

/// Σ γ(v)·t(v) over the level: the time one iteration takes on one
/// processor. A loop node takes `loopCount` times its body's time; boundary
/// nodes and tasks without a known time take none. `None` on overflow.
fn iteration_time(level: &Level<'_>, counts: &[u64], work: &HashMap<String, u64>) -> Option<u64> {
    let mut total = 0u64;
    for (node, &count) in level.nodes.iter().zip(counts) {
        let task = node.task.and_then(|t| level.graph.tasks.get(t));
        let time = match task.and_then(|t| t.loop_node.as_ref().map(|l| (t, l))) {
            Some((t, l)) => {
                let body = work
                    .get(&format!("{}/{}", level.path, t.name.name))
                    .copied()
                    .unwrap_or(0);
                body.checked_mul(l.loop_count)?
            }
            None => node.wcet.unwrap_or(0),
        };
        total = total.checked_add(time.checked_mul(count)?)?;
    }
    Some(total)
}

/// The errors found in a sub-graph's levels, moved to the `subgraph`
/// attribute of the reference they lie under: the sub-graph has no errors of
/// its own (else it is not analysed here), so these come from the task's
/// rates. Warnings are the sub-graph's own and stay there.
fn at_reference(
    graph: &TaskGraph,
    hierarchy: &Hierarchy,
    index: usize,
    diagnostics: Vec<Diagnostic>,
) -> Vec<Diagnostic> {
    let Some(sub) = hierarchy.subgraphs.get(index) else {
        return Vec::new();
    };
    let Some(task) = graph
        .levels()
        .into_iter()
        .find(|l| l.path == sub.level)
        .and_then(|l| l.graph.tasks.get(sub.task))
    else {
        return Vec::new();
    };
    let Some(attr) = &task.subgraph else {
        return Vec::new();
    };
    diagnostics
        .into_iter()
        .filter(Diagnostic::is_error)
        .map(|d| {
            let code = match d.code {
                Code::InconsistentRates | Code::RateOverflow => Code::SubgraphBoundaryRate,
                other => other,
            };
            let mut moved = Diagnostic::new(
                code,
                graph.file,
                attr.span,
                format!(
                    "the port rates of `{}` do not fit one iteration of its sub-graph `{}`: {}",
                    task.name.name, attr.name, d.message
                ),
            );
            for port in &task.ports {
                if let Some(span) = port.rate_span {
                    moved.relate(span, format!("the rate of `{}`", port.name.name));
                }
            }
            moved
        })
        .collect()
}

/// The schedule of a live level, its buffer bounds, capacity warnings, and
/// its throughput when some task has an execution time. Gives the level's
/// single-appearance schedule, if it has one.
fn schedule_level(
    level: &Level<'_>,
    counts: &[u64],
    flat: Option<Vec<usize>>,
    concurrency: Concurrency,
    report: &mut LevelReport,
    diagnostics: &mut Vec<Diagnostic>,
) -> Option<Vec<schedule::Schedule>> {
    let timed = level.nodes.iter().any(|n| n.wcet.is_some_and(|w| w > 0));
    report.throughput = if timed {
        throughput::throughput(level, counts, concurrency).map(|t| ThroughputReport {
            period: t.period,
            critical_cycle: t
                .critical_cycle
                .iter()
                .map(|&n| level.nodes[n].name.to_string())
                .collect(),
        })
    } else {
        Err(NoPeriod::Untimed)
    };
    let single_appearance = schedule::single_appearance(level, counts);
    // `flat`, the flat (sample-frugal) schedule: the buffer bounds are
    // measured under it, and it is the level's schedule where no
    // single-appearance one exists.
    report.schedule = match (&single_appearance, &flat) {
        (Some(s), _) => Some(schedule::render(level, s)),
        (None, Some(firings)) => {
            let names: Vec<&str> = firings
                .iter()
                .map(|&n| level.nodes[n].name.as_str())
                .collect();
            Some(names.join(" "))
        }
        (None, None) => None,
    };
    if let Some(firings) = &flat {
        let bounds = buffers::buffer_bounds(level, firings);
        diagnostics.extend(buffers::capacity_warnings(level, &bounds));
        report.buffers = level
            .edges
            .iter()
            .zip(bounds)
            .map(|(e, samples)| BufferBound {
                channel: e.label.clone(),
                samples,
            })
            .collect();
    }
    single_appearance
}

fn times(r: impl std::fmt::Display) -> String {
    let s = r.to_string();
    if s == "1" {
        "once".to_string()
    } else {
        format!("{s} times")
    }
}

fn rate_diagnostic(level: &Level<'_>, problem: &RateProblem) -> Diagnostic {
    let file = level.graph.file;
    match problem {
        RateProblem::Inconsistent {
            edge,
            established,
            required,
        } => {
            let e = &level.edges[*edge];
            let (src, dst) = (&level.nodes[e.src].name, &level.nodes[e.dst].name);
            Diagnostic::new(
                Code::InconsistentRates,
                file,
                e.span,
                format!(
                    "sample rates contradict on channel {}: it makes {dst} fire {} per firing of {src}, but the other paths make it fire {}; samples would pile up or run out",
                    e.label,
                    times(required),
                    times(established)
                ),
            )
        }
        RateProblem::Overflow { edge } => {
            let span = edge.map_or(level.graph.span, |e| level.edges[e].span);
            Diagnostic::new(
                Code::RateOverflow,
                file,
                span,
                "the repetition counts of these rates are too large to compute (over 64 bits)",
            )
        }
        RateProblem::Boundary { node, count } if level.stands_for.is_some() => {
            let task = level.stands_for.as_deref().unwrap_or_default();
            let side = if level.boundary.is_some_and(|(inputs, _)| inputs == *node) {
                "input"
            } else {
                "output"
            };
            Diagnostic::new(
                Code::InconsistentRates,
                file,
                level.nodes[*node].span,
                format!(
                    "one iteration needs the samples of {count} firings of `{task}` at its {side}s, not one: the {side} rates of `{task}` would have to be {count} times larger"
                ),
            )
        }
        RateProblem::Boundary { node, count } => {
            let n = &level.nodes[*node];
            Diagnostic::new(
                Code::InconsistentRates,
                file,
                n.span,
                format!(
                    "inside {}, the inner rates need {} of the loop's samples per iteration instead of one: the loop's inner rates do not fit its body",
                    level.path,
                    times(count)
                ),
            )
        }
    }
}

fn deadlock_diagnostic(level: &Level<'_>, blocked: &deadlock::Blocked) -> Diagnostic {
    let file = level.graph.file;
    let mut names: Vec<&str> = blocked
        .nodes
        .iter()
        .map(|&n| level.nodes[n].name.as_str())
        .collect();
    if let Some(first) = names.first().copied() {
        names.push(first);
    }
    let cycle = names.join(" → ");
    let (span, advice) = match blocked.fix {
        Some((edge, n)) => {
            let e = &level.edges[edge];
            (
                e.span,
                format!(
                    "; {n} more initial sample{} on channel {} would let one iteration complete",
                    if n == 1 { "" } else { "s" },
                    e.label
                ),
            )
        }
        None => (
            blocked
                .edges
                .first()
                .map_or(level.nodes[blocked.nodes[0]].span, |&e| level.edges[e].span),
            String::new(),
        ),
    };
    let mut d = Diagnostic::new(
        Code::Deadlock,
        file,
        span,
        format!("deadlock: the cycle {cycle} has too few initial samples to start{advice}"),
    );
    for &e in &blocked.edges {
        if level.edges[e].span != span {
            d.relate(level.edges[e].span, "a channel of the cycle");
        }
    }
    d
}

#[cfg(test)]
mod testing;
#[cfg(test)]
mod tests;
