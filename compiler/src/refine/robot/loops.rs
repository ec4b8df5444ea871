//! Services implemented by task graphs (`graph=` in the catalog): the
//! graph's looped schedule, SDF/L loop nodes opened, as [`GraphStep`]s the
//! service task runs per call (`codegen/loops.rs`, `sim/engine/loops.rs`),
//! with the graph's channels ([`GraphChannel`]: every level's, numbered in
//! level order, each bounded by the analysis's buffer bound) and the
//! channels each inner task's and loop node's ports join. A port joined by
//! more than one channel, a loop port without a channel on both sides, or a
//! loop output that cannot give its outer rate when the loop stops refuses
//! the graph like a missing schedule.
//!
//! The schedule is the analysis's own (`taskgraph::analysis::schedule`, per
//! hierarchy level: a loop node's body is the level at its path). A graph
//! without one (inconsistent, deadlocked, no single-appearance schedule)
//! or with sub-graph references keeps the reason: the dataflow warnings
//! (W070, W071) name it on the call, and code generation refuses it (E100),
//! never giving a stub instead.

use super::{Builder, implementing_task};
use crate::catalog::Implementation;
use crate::refine::program::{
    GraphChannel, GraphService, GraphStep, InnerTask, LoopPort, PortUse, StateKind,
};
use crate::span::Span;
use crate::taskgraph::TaskGraph;
use crate::taskgraph::analysis::{buffers, consistency, level::Level, schedule};
use crate::taskgraph::model::{Direction, LoopNode, LoopType, PortKind, Task};
use std::collections::HashMap;

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
                let opened = steps_of(&loaded.graph)
                    .map_err(|why| format!("the task graph of `{service}` ({path}), which {why},"));
                let (steps, channels, tasks) = match opened {
                    Ok(o) => (Ok(o.steps), o.channels, o.tasks),
                    Err(why) => (Err(why), Vec::new(), Vec::new()),
                };
                found.push(GraphService {
                    task: task.clone(),
                    graph: loaded.graph.name.clone(),
                    call: self.call_span(&task),
                    steps,
                    channels,
                    tasks,
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

/// A service graph opened: one iteration of its top level as steps, its
/// channels and its inner tasks.
#[derive(Debug)]
pub(crate) struct Opened {
    pub steps: Vec<GraphStep>,
    pub channels: Vec<GraphChannel>,
    pub tasks: Vec<InnerTask>,
}

/// Firings of one level's iteration, at most, that bounding its channels
/// expands (beyond, the graph is refused).
const MAX_LEVEL_FIRINGS: u64 = 1 << 20;

/// `graph` opened, or why it cannot run.
pub(crate) fn steps_of(graph: &TaskGraph) -> Result<Opened, String> {
    if graph
        .levels()
        .iter()
        .any(|l| l.graph.tasks.iter().any(|t| t.subgraph.is_some()))
    {
        return Err("references sub-graph files".into());
    }
    let levels = Level::all(graph);
    let mut opener = Opener {
        levels: &levels,
        channels: Vec::new(),
        ends: HashMap::new(),
        tasks: Vec::new(),
    };
    for index in 0..levels.len() {
        opener.channels_of(index)?;
    }
    let steps = opener.level_steps(0)?;
    Ok(Opened {
        steps,
        channels: opener.channels,
        tasks: opener.tasks,
    })
}

/// Which side of a task's port a channel joins: a loop node's port has a
/// channel outside (its level) and one inside (its body's boundary).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Side {
    Outer,
    Inner,
}

struct Opener<'l, 'g> {
    levels: &'l [Level<'g>],
    channels: Vec<GraphChannel>,
    /// (task path below the graph, port, side) → the channels joining it.
    ends: HashMap<(String, String, Side), Vec<usize>>,
    tasks: Vec<InnerTask>,
}

impl Opener<'_, '_> {
    /// A path below the graph: the top level's name left out.
    fn below(&self, path: &str) -> String {
        path.strip_prefix(&self.levels[0].path)
            .unwrap_or(path)
            .trim_start_matches('/')
            .to_string()
    }

    fn level_order(&self, index: usize) -> Result<Vec<schedule::Schedule>, String> {
        let level = &self.levels[index];
        let counts = consistency::repetition_vector(level)
            .map_err(|_| format!("has inconsistent rates in `{}`", level.path))?;
        schedule::single_appearance(level, &counts)
            .ok_or_else(|| format!("has no looped schedule for `{}`", level.path))
    }

    /// The channels of level `index`, each bounded by the analysis's buffer
    /// bound for the order the service task runs it in: the boundary's
    /// inputs first, the schedule's task firings, the boundary's outputs
    /// last (`codegen/loops.rs`, `sim/engine/loops.rs`).
    fn channels_of(&mut self, index: usize) -> Result<(), String> {
        let level = &self.levels[index];
        let looped = self.level_order(index)?;
        let firings = schedule::expand(&looped, MAX_LEVEL_FIRINGS).ok_or_else(|| {
            format!(
                "has more than {MAX_LEVEL_FIRINGS} firings in one iteration of `{}`",
                level.path
            )
        })?;
        let mut order: Vec<usize> = Vec::with_capacity(firings.len() + 2);
        order.extend(level.boundary.map(|(inputs, _)| inputs));
        order.extend(firings.iter().filter(|&&n| level.nodes[n].task.is_some()));
        order.extend(level.boundary.map(|(_, outputs)| outputs));
        let bounds = buffers::buffer_bounds(level, &order);
        let at = self.below(&level.path);
        for (edge, bound) in level.edges.iter().zip(bounds) {
            let channel = self.channels.len();
            self.channels.push(GraphChannel {
                label: if at.is_empty() {
                    edge.label.clone()
                } else {
                    format!("{at}: {}", edge.label)
                },
                // A channel no firing of the iteration reaches still needs
                // a place in C.
                capacity: bound.max(1),
                initial_tokens: edge.initial_tokens,
            });
            let c = &level.graph.channels[edge.channel];
            for (node, port) in [(edge.src, &c.src.port), (edge.dst, &c.dst.port)] {
                let key = match level.nodes[node].task {
                    Some(t) => (
                        self.below(&format!(
                            "{}/{}",
                            level.path, level.graph.tasks[t].name.name
                        )),
                        port.clone(),
                        Side::Outer,
                    ),
                    // The enclosing loop node's boundary.
                    None => (at.clone(), port.clone(), Side::Inner),
                };
                self.ends.entry(key).or_default().push(channel);
            }
        }
        Ok(())
    }

    /// The one channel joining `path`'s `port` on `side`, if any.
    fn end(&self, path: &str, port: &str, side: Side) -> Result<Option<usize>, String> {
        match self
            .ends
            .get(&(path.to_string(), port.to_string(), side))
            .map(Vec::as_slice)
        {
            None | Some([]) => Ok(None),
            Some([one]) => Ok(Some(*one)),
            Some(_) => Err(format!(
                "joins port `{path}.{port}` by more than one channel"
            )),
        }
    }

    fn inner_task(&mut self, path: &str, task: &Task) -> Result<(), String> {
        if self.tasks.iter().any(|t| t.path == path) {
            return Ok(());
        }
        let mut inputs = Vec::new();
        let mut outputs = Vec::new();
        for port in &task.ports {
            let Some(channel) = self.end(path, &port.name.name, Side::Outer)? else {
                continue; // an open port: the graph's interface
            };
            let used = PortUse {
                port: port.name.name.clone(),
                channel,
                rate: port.rate,
            };
            match port.dir {
                Direction::In => inputs.push(used),
                Direction::Out => outputs.push(used),
            }
        }
        self.tasks.push(InnerTask {
            path: path.to_string(),
            inputs,
            outputs,
        });
        Ok(())
    }

    fn loop_ports(
        &self,
        path: &str,
        task: &Task,
        node: &LoopNode,
    ) -> Result<Vec<LoopPort>, String> {
        let mut out = Vec::new();
        for port in &task.ports {
            let name = &port.name.name;
            let (Some(outer), Some(inner)) = (
                self.end(path, name, Side::Outer)?,
                self.end(path, name, Side::Inner)?,
            ) else {
                return Err(format!(
                    "has loop port `{path}.{name}` without a channel both outside and inside"
                ));
            };
            let inner_rate = port.inner_rate.unwrap_or(port.rate);
            let input = port.dir == Direction::In;
            // An output puts the last `outer_rate` tokens its iterations
            // gave: there must be that many, whenever the loop stops.
            let iterations_needed = port.rate.div_ceil(inner_rate.max(1));
            let enough = if node.loop_type == LoopType::C {
                inner_rate >= port.rate
            } else {
                node.loop_count >= iterations_needed
            };
            if !input && (!enough || node.loop_count == 0) {
                return Err(format!(
                    "gives fewer than {} tokens on loop port `{path}.{name}` when its loop stops",
                    port.rate
                ));
            }
            out.push(LoopPort {
                port: name.clone(),
                input,
                distributing: port.kind == Some(PortKind::Distributing),
                outer_rate: port.rate,
                inner_rate,
                outer,
                inner,
            });
        }
        Ok(out)
    }

    fn level_steps(&mut self, index: usize) -> Result<Vec<GraphStep>, String> {
        let looped = self.level_order(index)?;
        self.terms(index, &looped)
    }

    fn terms(
        &mut self,
        index: usize,
        terms_of: &[schedule::Schedule],
    ) -> Result<Vec<GraphStep>, String> {
        let levels = self.levels;
        let level = &levels[index];
        let mut out = Vec::new();
        for term in terms_of {
            match term {
                schedule::Schedule::Loop { count, body } => out.push(GraphStep::Repeat {
                    count: *count,
                    body: self.terms(index, body)?,
                }),
                schedule::Schedule::Fire { node, count } => {
                    // Boundary nodes (a loop body's ports) are not tasks:
                    // the loop step feeds and drains them.
                    let Some(task) = level.nodes.get(*node).and_then(|n| n.task) else {
                        continue;
                    };
                    let task = &level.graph.tasks[task];
                    let full = format!("{}/{}", level.path, task.name.name);
                    let path = self.below(&full);
                    let step = match &task.loop_node {
                        None => {
                            self.inner_task(&path, task)?;
                            GraphStep::Fire {
                                task: path,
                                count: *count,
                            }
                        }
                        Some(node) => {
                            let inner = levels
                                .iter()
                                .position(|l| l.path == full)
                                .ok_or_else(|| format!("has no level for `{full}`"))?;
                            let ports = self.loop_ports(&path, task, node)?;
                            let body = self.level_steps(inner)?;
                            let looped = GraphStep::Loop {
                                convergent: node.loop_type == LoopType::C,
                                loop_count: node.loop_count,
                                exit_task: node
                                    .exit_task
                                    .as_ref()
                                    .map(|e| format!("{path}/{}", e.name)),
                                ports,
                                body,
                                path,
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
}
