//! Analyses of a task graph, level by level (the top graph and every loop
//! body): consistency and repetition vectors, deadlock, schedules and buffer
//! bounds; plus the structural SDF/L rules. Results are data; the problems
//! found are also diagnostics on the channel or task concerned.

pub mod buffers;
pub mod consistency;
pub mod deadlock;
pub mod level;
pub mod ratio;
pub mod rules;
pub mod schedule;
pub mod throughput;

use crate::diag::{Code, Diagnostic};
use crate::taskgraph::model::TaskGraph;
use consistency::{RateProblem, repetition_vector};
use deadlock::find_deadlock;
use level::Level;

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
    /// A looped single-appearance schedule (`3A 2B`), else a flat one, when
    /// the level is consistent and deadlock-free.
    pub schedule: Option<String>,
    /// Per edge of the level: the most samples it holds under that schedule.
    pub buffers: Vec<BufferBound>,
    /// The self-timed iteration period, when execution times are known.
    pub throughput: Option<ThroughputReport>,
}

/// The iteration period of the self-timed execution and the cycle bounding it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ThroughputReport {
    /// Time units per iteration, exact (`16`, `11/2`).
    pub period: ratio::Ratio,
    /// Node names around the critical cycle, in flow order (one name: that
    /// task alone, which cannot overlap with itself, bounds the period).
    pub critical_cycle: Vec<String>,
}

/// The most samples a channel holds while one iteration runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BufferBound {
    /// `A.o → B.i`
    pub channel: String,
    pub samples: u64,
}

#[derive(Clone, Debug, Default)]
pub struct GraphReport {
    pub levels: Vec<LevelReport>,
    /// The whole hierarchy as one looped schedule (`A 10(B C) D`), where every
    /// level has a single-appearance schedule.
    pub looped_schedule: Option<String>,
    pub diagnostics: Vec<Diagnostic>,
}

impl GraphReport {
    pub fn is_consistent(&self) -> bool {
        self.levels.iter().all(|l| l.repetition.is_some())
    }

    pub fn is_deadlock_free(&self) -> bool {
        self.levels.iter().all(|l| l.deadlock_free == Some(true))
    }
}

/// Runs the analyses on every level of `graph`.
pub fn analyze(graph: &TaskGraph) -> GraphReport {
    let mut report = GraphReport {
        diagnostics: rules::check(graph),
        ..GraphReport::default()
    };
    let levels = Level::all(graph);
    // Each level's single-appearance schedule, kept to write the whole
    // hierarchy's looped schedule at the end.
    let mut single_appearance = Vec::with_capacity(levels.len());
    for level in &levels {
        let nodes = level.nodes.iter().map(|n| n.name.clone()).collect();
        let mut level_report = LevelReport {
            path: level.path.clone(),
            nodes,
            repetition: None,
            deadlock_free: None,
            schedule: None,
            buffers: Vec::new(),
            throughput: None,
        };
        let mut sas = None;
        match repetition_vector(level) {
            Ok(counts) => {
                let blocked = find_deadlock(level, &counts);
                match &blocked {
                    Some(b) => report.diagnostics.push(deadlock_diagnostic(level, b)),
                    None => {
                        sas = schedule_level(
                            level,
                            &counts,
                            &mut level_report,
                            &mut report.diagnostics,
                        )
                    }
                }
                level_report.deadlock_free = Some(blocked.is_none());
                level_report.repetition = Some(counts);
            }
            Err(problem) => report.diagnostics.push(rate_diagnostic(level, &problem)),
        }
        single_appearance.push(sas);
        report.levels.push(level_report);
    }
    report.looped_schedule = schedule::render_hierarchy(&levels, &single_appearance);
    report
}

/// The schedule of a live level, its buffer bounds, capacity warnings, and
/// its throughput when some task has an execution time. Gives the level's
/// single-appearance schedule, if it has one.
fn schedule_level(
    level: &Level<'_>,
    counts: &[u64],
    report: &mut LevelReport,
    diagnostics: &mut Vec<Diagnostic>,
) -> Option<Vec<schedule::Schedule>> {
    let timed = level.nodes.iter().any(|n| {
        n.task
            .is_some_and(|t| level.graph.tasks[t].wcet.is_some_and(|w| w > 0))
    });
    if timed {
        report.throughput = throughput::throughput(level, counts).map(|t| ThroughputReport {
            period: t.period,
            critical_cycle: t
                .critical_cycle
                .iter()
                .map(|&n| level.nodes[n].name.clone())
                .collect(),
        });
    }
    let single_appearance = schedule::single_appearance(level, counts);
    // The flat (sample-frugal) schedule: the buffer bounds are measured under
    // it, and it is the level's schedule where no single-appearance one exists.
    let flat = schedule::flat_schedule(level, counts);
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
