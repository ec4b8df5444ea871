//! Time-triggered tasks bound a graph's iteration period from below: a task
//! with `trigger="time"` fires at most once per period (as a service task
//! runs it: `codegen/loops.rs`), so an iteration of the top level, in which
//! it fires `n` times, takes at least `n × period` on average, whatever the
//! execution times. `n` is the task's repetition count in its level times
//! the iterations of its level per top-level iteration: the enclosing
//! node's count in the level above, times a loop node's `loopCount` (a
//! C-type loop's at most that many, counted as [`super::analyze_as`] counts
//! its time), up to the top.

use super::LevelReport;
use super::level::Level;
use super::ratio::Ratio;
use crate::diag::FileId;
use crate::span::Span;
use crate::taskgraph::model::Trigger;

/// The time-triggered task that bounds a graph's iteration the most.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeBound {
    /// Milliseconds per top-level iteration, at least: `firings × period`
    /// (the period counted in whole microseconds).
    pub period: Ratio,
    /// The task's path below the graph (`Converge/Sample`).
    pub task: String,
    /// Its firings per top-level iteration.
    pub firings: u64,
    /// Its period, ms.
    pub period_ms: f64,
    /// Its name in the graph file holding it.
    pub file: FileId,
    pub span: Span,
}

/// The largest `firings × period` of the time-triggered tasks of `levels`
/// (a graph's levels, its sub-graphs' included, top first, as
/// [`super::analyze_as`] analyses them; `reports` their reports, in the same
/// order); `None` when there are none, or when a level holding one, or one
/// above it, has no repetition vector.
pub(super) fn time_bound(levels: &[Level<'_>], reports: &[LevelReport]) -> Option<TimeBound> {
    let top = levels.first()?.path.clone();
    // Parents before children: a level's path extends its parent's.
    let mut order: Vec<usize> = (0..levels.len()).collect();
    order.sort_by_key(|&i| levels[i].path.len());
    // Per level: its iterations per top-level iteration, when known.
    let mut runs: Vec<Option<u64>> = vec![None; levels.len()];
    let mut found: Option<TimeBound> = None;
    for i in order {
        let level = &levels[i];
        runs[i] = if i == 0 {
            Some(1)
        } else {
            enclosing_runs(levels, &runs, reports, i)
        };
        let (Some(repetition), Some(level_runs)) =
            (reports.get(i).and_then(|r| r.repetition.as_ref()), runs[i])
        else {
            continue;
        };
        for (node, count) in level.nodes.iter().zip(repetition) {
            let Some(task) = node.task.and_then(|t| level.graph.tasks.get(t)) else {
                continue;
            };
            let Trigger::Time { period_ms } = task.trigger else {
                continue;
            };
            let firings = level_runs.saturating_mul(*count);
            // Whole microseconds: the model's periods are decimals of a unit.
            let micros = (period_ms * 1000.0).round().min(u64::MAX as f64) as u64;
            let Some(period) = Ratio::new(micros, 1000).and_then(|p| p.scale(firings, 1)) else {
                continue;
            };
            if found.as_ref().is_none_or(|f| period > f.period) {
                let path = format!("{}/{}", level.path, task.name.name);
                found = Some(TimeBound {
                    period,
                    task: path
                        .strip_prefix(&top)
                        .unwrap_or(&path)
                        .trim_start_matches('/')
                        .to_string(),
                    firings,
                    period_ms,
                    file: level.graph.file,
                    span: task.name.span,
                });
            }
        }
    }
    found
}

/// The iterations per top-level iteration of level `i` (not the top): its
/// parent's, times the count of the node standing for it there, times its
/// `loopCount` when that node is a loop node.
fn enclosing_runs(
    levels: &[Level<'_>],
    runs: &[Option<u64>],
    reports: &[LevelReport],
    i: usize,
) -> Option<u64> {
    let path = &levels[i].path;
    levels.iter().enumerate().find_map(|(j, parent)| {
        let name = path.strip_prefix(&parent.path)?.strip_prefix('/')?;
        let k = parent.nodes.iter().position(|n| n.name == name)?;
        let task = parent.graph.tasks.get(parent.nodes[k].task?)?;
        let count = *reports.get(j)?.repetition.as_ref()?.get(k)?;
        let iterations = task.loop_node.as_ref().map_or(1, |l| l.loop_count);
        Some(runs[j]?.saturating_mul(count).saturating_mul(iterations))
    })
}
