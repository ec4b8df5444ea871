//! The static schedule of a robot's task graph: one iteration of its looped
//! single-appearance schedule (`taskgraph::analysis::schedule`), expanded
//! into firings and run-length coded as `(task, count)` for `main.c`'s
//! `schedule` table, which `Core_1_go` walks on static-schedule targets.
//!
//! Refined robot graphs are flat (one level); their rates are consistent
//! and they have initial samples where they loop, which the refined graph's
//! own check guarantees before code generation (E102 otherwise). A graph
//! without a schedule is therefore an internal error, never a silently
//! different order.

use crate::taskgraph::analysis::{consistency, level::Level, schedule};
use crate::taskgraph::model::TaskGraph;

/// `(task index, consecutive firings)` for one iteration, or why there is none.
pub fn firings(graph: &TaskGraph) -> Result<Vec<(usize, u64)>, String> {
    let levels = Level::all(graph);
    let Some(level) = levels.first() else {
        return Err("the task graph has no top level".into());
    };
    if levels.len() > 1 {
        return Err("the refined task graph has sub-graphs or loops".into());
    }
    let counts = consistency::repetition_vector(level)
        .map_err(|_| "the task graph's rates are inconsistent".to_string())?;
    let looped = schedule::single_appearance(level, &counts)
        .ok_or("the task graph has no single-appearance schedule")?;
    let order = schedule::expand(&looped, schedule::MAX_FIRINGS)
        .ok_or("one iteration of the schedule has too many firings")?;
    let mut out: Vec<(usize, u64)> = Vec::new();
    for node in order {
        let Some(task) = level.nodes.get(node).and_then(|n| n.task) else {
            continue;
        };
        match out.last_mut() {
            Some((last, count)) if *last == task && *count < u64::from(u16::MAX) => *count += 1,
            _ => out.push((task, 1)),
        }
    }
    if out.len() > usize::from(u16::MAX) || graph.tasks.len() > usize::from(u16::MAX) {
        return Err("the schedule does not fit the runtime's table".into());
    }
    Ok(out)
}
