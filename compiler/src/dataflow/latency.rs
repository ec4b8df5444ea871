//! The latency bounds of service graphs (`<Latency>` in the catalog,
//! `catalog::latency`), checked where a mission calls the service: W074
//! when the graph's latency from one task to the other is over the bound,
//! W075 when it cannot be checked, with the reason (never a silent skip).
//!
//! The latency is the task graphs' own analysis
//! (`taskgraph::analysis::latency`, SDF3's minimal and self-timed latency)
//! on the graph's top level, its tasks standing for sub-graphs timed by
//! them, as `semo graph latency` computes it, with the concurrency the
//! graph's report was computed with. Execution times of catalog service
//! graphs count milliseconds and the bound is kept as an exact fraction of
//! milliseconds, so the comparison is exact.
//!
//! Each distinct (graph, source, sink) is analysed once per mission
//! ([`Latencies`]), however many robots and calls run it.

use crate::catalog::latency::LatencyBound;
use crate::diag::{Code, Diagnostic, FileId, Related};
use crate::span::Span;
use crate::taskgraph::TaskGraph;
use crate::taskgraph::analysis::hierarchy_levels;
use crate::taskgraph::analysis::latency::{self, NoSelfTimed};
use crate::workspace::GraphRun;
use std::collections::HashMap;

/// The latencies measured for one mission, each once.
#[derive(Default)]
pub struct Latencies {
    found: HashMap<(FileId, String, String), Measured>,
    /// How many latency analyses ran (the cache's misses).
    pub analyses: usize,
}

/// What the analysis says of one path.
#[derive(Clone, Debug)]
enum Measured {
    Latency {
        minimal: u64,
        self_timed: Result<u64, SelfTimedMissing>,
        /// The two tasks in the graph's file.
        ends: (Span, Span),
    },
    /// Why there is no latency to compare.
    None(String),
    /// The bound names a task the graph's top level does not have: why, and
    /// whether it is the source (`from`) or the sink.
    UnknownTask { why: String, source: bool },
}

#[derive(Clone, Debug)]
enum SelfTimedMissing {
    /// It grows every iteration: over any bound.
    Unbounded(String),
    /// It is not known (the minimal one stands).
    Unknown(String),
}

/// A call of a service whose graph states bounds, for the messages.
pub struct BoundedCall<'a> {
    /// The mission file and the call's span in it.
    pub file: FileId,
    pub span: Span,
    pub service: &'a str,
    pub path: &'a str,
    /// The catalog file stating the bounds.
    pub catalog: FileId,
    pub run: &'a GraphRun,
}

impl Latencies {
    /// W074/W075 for each bound of `bounds` the call's graph breaks or that
    /// cannot be checked.
    pub fn check(&mut self, call: &BoundedCall<'_>, bounds: &[LatencyBound]) -> Vec<Diagnostic> {
        bounds
            .iter()
            .filter_map(|bound| {
                let measured = self.measure(call.run, bound);
                judge(call, bound, &measured)
            })
            .collect()
    }

    /// The path's latency, analysed the first time it is asked for.
    fn measure(&mut self, run: &GraphRun, bound: &LatencyBound) -> Measured {
        let Some(graph) = run.graph.as_ref() else {
            return Measured::None("the task graph could not be read".into());
        };
        let key = (graph.file, bound.from.0.clone(), bound.to.0.clone());
        let analyses = &mut self.analyses;
        self.found
            .entry(key)
            .or_insert_with(|| {
                *analyses += 1;
                measure(run, graph, &bound.from.0, &bound.to.0)
            })
            .clone()
    }
}

/// The latency from task `from` to task `to` of the top level of `graph`,
/// the graph `run` read.
fn measure(run: &GraphRun, graph: &TaskGraph, from: &str, to: &str) -> Measured {
    let none = |why: &str| Measured::None(why.to_string());
    // The analyses' own errors first (W070 and W071 on the call say them
    // too), then any other (a format error: the graph is not analysed).
    let top = run.report.levels.first();
    let counts = match top {
        Some(t) if t.repetition.is_none() => {
            return none("its sample rates are inconsistent (no iteration exists)");
        }
        Some(t) if t.deadlock_free != Some(true) => return none("an iteration deadlocks"),
        _ if run.diagnostics.iter().any(Diagnostic::is_error) => {
            return none("the task graph has errors (reported in its file)");
        }
        Some(t) => t.repetition.as_ref(),
        None => None,
    };
    let Some(counts) = counts else {
        return none("the task graph was not analysed");
    };
    let levels = hierarchy_levels(graph, &run.hierarchy);
    let Some(level) = levels.first() else {
        return none("the task graph was not analysed");
    };
    let node = |name: &str, source: bool| {
        level
            .nodes
            .iter()
            .position(|n| n.task.is_some() && n.name == name)
            .ok_or_else(|| {
                let names = level.nodes.iter().filter(|n| n.task.is_some());
                let mut why = format!("the graph's top level has no task `{name}`");
                if let Some(close) =
                    crate::suggest::did_you_mean(name, names.map(|n| n.name.as_str()))
                {
                    why.push_str(&format!(" (did you mean `{close}`?)"));
                }
                Measured::UnknownTask { why, source }
            })
    };
    let (source, sink) = match (node(from, true), node(to, false)) {
        (Ok(s), Ok(k)) => (s, k),
        (Err(unknown), _) | (_, Err(unknown)) => return unknown,
    };
    if level.nodes.iter().all(|n| n.wcet.is_none_or(|w| w == 0)) {
        return none(
            "the task graph states no execution times (`wcet`), so it takes no time: give its tasks their `wcet` in milliseconds",
        );
    }
    match latency::latency(level, counts, source, sink, run.report.concurrency) {
        Err(why) => Measured::None(format!("no latency: {}", why.why())),
        Ok(found) => Measured::Latency {
            minimal: found.minimal,
            self_timed: match found.self_timed {
                Ok(st) => Ok(st.latency),
                Err(why @ NoSelfTimed::Unbounded { .. }) => {
                    Err(SelfTimedMissing::Unbounded(why.describe(level)))
                }
                Err(why) => Err(SelfTimedMissing::Unknown(why.describe(level))),
            },
            ends: (level.nodes[source].span, level.nodes[sink].span),
        },
    }
}

/// `latency` ms is over `bound`'s `num/den` ms.
fn over(latency: u64, bound: &LatencyBound) -> bool {
    u128::from(latency) * u128::from(bound.max.den) > u128::from(bound.max.num)
}

/// The bound in milliseconds, exactly (`50`, `1/2`).
fn bound_ms(bound: &LatencyBound) -> String {
    if bound.max.den == 1 {
        bound.max.num.to_string()
    } else {
        format!("{}/{}", bound.max.num, bound.max.den)
    }
}

fn judge(call: &BoundedCall<'_>, bound: &LatencyBound, measured: &Measured) -> Option<Diagnostic> {
    let (from, to) = (&bound.from.0, &bound.to.0);
    let allowed = format!("{} ({} ms)", bound.max.written, bound_ms(bound));
    let (code, message) = match measured {
        Measured::None(why) | Measured::UnknownTask { why, .. } => (
            Code::DataflowLatencyUnchecked,
            format!(
                "the latency bound from `{from}` to `{to}` on `{}` (the task graph `{}`) cannot be checked: {why}",
                call.service, call.path
            ),
        ),
        Measured::Latency {
            minimal,
            self_timed,
            ..
        } => {
            let self_timed_words = match self_timed {
                Ok(l) => format!("{l} ms"),
                Err(SelfTimedMissing::Unbounded(why)) => format!("unbounded ({why})"),
                Err(SelfTimedMissing::Unknown(why)) => format!("not known ({why})"),
            };
            let exceeded = over(*minimal, bound)
                || match self_timed {
                    Ok(l) => over(*l, bound),
                    Err(SelfTimedMissing::Unbounded(_)) => true,
                    Err(SelfTimedMissing::Unknown(_)) => false,
                };
            if exceeded {
                (
                    Code::DataflowLatencyExceeded,
                    format!(
                        "`{}` runs the task graph `{}`, whose latency from `{from}` to `{to}` is over the {allowed} its catalog allows: minimal latency {minimal} ms, self-timed latency {self_timed_words}",
                        call.service, call.path
                    ),
                )
            } else if let Err(SelfTimedMissing::Unknown(_)) = self_timed {
                (
                    Code::DataflowLatencyUnchecked,
                    format!(
                        "the latency bound from `{from}` to `{to}` on `{}` (the task graph `{}`) is checked only in part: the minimal latency, {minimal} ms, is within {allowed}, but the self-timed latency is {self_timed_words}",
                        call.service, call.path
                    ),
                )
            } else {
                return None;
            }
        }
    };
    let mut d = Diagnostic::new(code, call.file, call.span, message);
    d.related.push(Related {
        file: call.catalog,
        span: bound.span,
        message: format!("the bound, {allowed}, is stated here"),
    });
    if let Measured::UnknownTask { source, .. } = measured {
        let (name, span) = if *source { &bound.from } else { &bound.to };
        d.related.push(Related {
            file: call.catalog,
            span: *span,
            message: format!("`{name}`: no such task in the graph's top level"),
        });
    }
    if let (Measured::Latency { ends, .. }, Some(graph)) = (measured, call.run.graph.as_ref()) {
        for (span, name, role) in [(ends.0, from, "source"), (ends.1, to, "sink")] {
            d.related.push(Related {
                file: graph.file,
                span,
                message: format!("`{name}`, the path's {role}"),
            });
        }
    }
    Some(d)
}
