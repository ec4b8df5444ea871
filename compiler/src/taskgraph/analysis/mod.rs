//! Analyses of a task graph, level by level (the top graph and every loop
//! body): consistency and repetition vectors, deadlock. Results are data; the
//! problems found are also diagnostics on the channel concerned.

pub mod consistency;
pub mod deadlock;
pub mod level;
pub mod ratio;
pub mod rules;

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
}

#[derive(Clone, Debug, Default)]
pub struct GraphReport {
    pub levels: Vec<LevelReport>,
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
    for level in Level::all(graph) {
        let nodes = level.nodes.iter().map(|n| n.name.clone()).collect();
        let (repetition, deadlock_free) = match repetition_vector(&level) {
            Ok(counts) => {
                let blocked = find_deadlock(&level, &counts);
                if let Some(b) = &blocked {
                    report.diagnostics.push(deadlock_diagnostic(&level, b));
                }
                (Some(counts), Some(blocked.is_none()))
            }
            Err(problem) => {
                report.diagnostics.push(rate_diagnostic(&level, &problem));
                (None, None)
            }
        };
        report.levels.push(LevelReport {
            path: level.path.clone(),
            nodes,
            repetition,
            deadlock_free,
        });
    }
    report
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
mod tests;
