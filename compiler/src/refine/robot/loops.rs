//! Services implemented by task graphs (`graph=` in the catalog): the
//! graph's looped schedule, SDF/L loop nodes opened, as [`GraphStep`]s the
//! service task runs per call (`codegen/loops.rs`, `sim/engine/loops.rs`).
//!
//! The schedule is the analysis's own (`taskgraph::analysis::schedule`, per
//! hierarchy level: a loop node's body is the level at its path). A graph
//! without one (inconsistent, deadlocked, no single-appearance schedule)
//! or with sub-graph references keeps the reason: the dataflow warnings
//! (W070, W071) name it on the call, and code generation refuses it (E100),
//! never giving a stub instead.

use super::{Builder, implementing_task};
use crate::catalog::Implementation;
use crate::refine::program::{GraphService, GraphStep, StateKind};
use crate::span::Span;
use crate::taskgraph::TaskGraph;
use crate::taskgraph::analysis::{consistency, level::Level, schedule};

impl Builder<'_, '_> {
    /// The robot's service tasks that run a task graph the workspace holds.
    pub(super) fn graph_services(&mut self) -> Vec<GraphService> {
        let mut found = Vec::new();
        let tasks: Vec<(String, Vec<String>)> = self
            .services
            .iter()
            .map(|(t, s)| (t.clone(), s.iter().cloned().collect()))
            .collect();
        for (task, services) in tasks {
            for service in services {
                let Some(def) = self.robot_type.service(&service) else {
                    continue; // an actuator command of a strategy
                };
                let Implementation::Graph(path) = &def.implementation else {
                    continue;
                };
                if implementing_task(&def.implementation, &service) != task {
                    continue;
                }
                let Some(loaded) = self
                    .input
                    .service_graphs
                    .iter()
                    .find(|g| g.catalog == def.origin.file && g.path == *path)
                else {
                    continue; // not in the workspace: reported on the catalog (E055)
                };
                if found.iter().any(|g: &GraphService| g.task == task) {
                    continue;
                }
                found.push(GraphService {
                    task: task.clone(),
                    graph: loaded.graph.name.clone(),
                    call: self.call_span(&task),
                    steps: steps_of(&loaded.graph).map_err(|why| {
                        format!("the task graph of `{service}` ({path}), which {why},")
                    }),
                });
            }
        }
        found
    }

    /// The first call of `task` in the machine (where problems are reported).
    fn call_span(&self, task: &str) -> Span {
        self.machine
            .services
            .iter()
            .flat_map(|s| &s.states)
            .find(|s| matches!(&s.kind, StateKind::Call { task: t, .. } if t == task))
            .map_or(self.team.name_span, |s| s.span)
    }
}

/// One iteration of `graph`'s top level as steps, or why there is none.
pub(crate) fn steps_of(graph: &TaskGraph) -> Result<Vec<GraphStep>, String> {
    if graph
        .levels()
        .iter()
        .any(|l| l.graph.tasks.iter().any(|t| t.subgraph.is_some()))
    {
        return Err("references sub-graph files".into());
    }
    let levels = Level::all(graph);
    level_steps(&levels, 0)
}

fn level_steps(levels: &[Level<'_>], index: usize) -> Result<Vec<GraphStep>, String> {
    let level = &levels[index];
    let counts = consistency::repetition_vector(level)
        .map_err(|_| format!("has inconsistent rates in `{}`", level.path))?;
    let looped = schedule::single_appearance(level, &counts)
        .ok_or_else(|| format!("has no looped schedule for `{}`", level.path))?;
    terms(levels, index, &looped)
}

fn terms(
    levels: &[Level<'_>],
    index: usize,
    terms_of: &[schedule::Schedule],
) -> Result<Vec<GraphStep>, String> {
    let level = &levels[index];
    // Paths below the graph: the top level's name is left out.
    let top = &levels[0].path;
    let below = |path: &str| {
        path.strip_prefix(top)
            .unwrap_or(path)
            .trim_start_matches('/')
            .to_string()
    };
    let mut out = Vec::new();
    for term in terms_of {
        match term {
            schedule::Schedule::Loop { count, body } => out.push(GraphStep::Repeat {
                count: *count,
                body: terms(levels, index, body)?,
            }),
            schedule::Schedule::Fire { node, count } => {
                // Boundary nodes (a loop body's ports) are not tasks.
                let Some(task) = level.nodes.get(*node).and_then(|n| n.task) else {
                    continue;
                };
                let task = &level.graph.tasks[task];
                let path = format!("{}/{}", level.path, task.name.name);
                let step = match &task.loop_node {
                    None => GraphStep::Fire {
                        task: below(&path),
                        count: *count,
                    },
                    Some(node) => {
                        let inner = levels
                            .iter()
                            .position(|l| l.path == path)
                            .ok_or_else(|| format!("has no level for `{path}`"))?;
                        let body = level_steps(levels, inner)?;
                        let looped = GraphStep::Loop {
                            path: below(&path),
                            convergent: node.loop_type == crate::taskgraph::model::LoopType::C,
                            loop_count: node.loop_count,
                            exit_task: node
                                .exit_task
                                .as_ref()
                                .map(|e| below(&format!("{path}/{}", e.name))),
                            body,
                        };
                        if *count == 1 {
                            looped
                        } else {
                            GraphStep::Repeat {
                                count: *count,
                                body: vec![looped],
                            }
                        }
                    }
                };
                out.push(step);
            }
        }
    }
    Ok(out)
}
