//! Services implemented by task graphs (`graph=` in the catalog): the
//! graph's looped schedule, SDF/L loop nodes and sub-graph references
//! opened, as [`GraphStep`]s the service task runs per call
//! (`codegen/loops.rs`, `sim/engine/loops.rs`), with the graph's channels
//! ([`GraphChannel`]: every level's, numbered in level order, each bounded
//! by the analysis's buffer bound) and the channels each inner task's, loop
//! node's and sub-graph task's ports join. A port joined by more than one
//! channel, a loop port without a channel on both sides, or a loop output
//! that cannot give its outer rate when the loop stops refuses the graph
//! like a missing schedule.
//!
//! The levels are the analysis's own (`Level::all_with`: a loop node's body
//! is the level at its path, a sub-graph's top level the level at the path
//! of the task standing for it, its boundary edges joining the task's ports
//! by name), and so is each level's schedule
//! (`taskgraph::analysis::schedule`). A graph without one (inconsistent,
//! deadlocked, no single-appearance schedule) keeps the reason: the
//! dataflow warnings (W070, W071) name it on the call, and code generation
//! refuses it (E100), never giving a stub instead. A sub-graph reference
//! the workspace could not follow (E067, E068, E069, E078 in the graph
//! file) refuses it with E135 on the call, pointing at the reference.

use super::{Builder, implementing_task};
use crate::catalog::Implementation;
use crate::diag::{Code, Related};
use crate::refine::program::{
    GraphChannel, GraphChannelId, GraphRefused, GraphService, GraphStep, InnerTask, InnerTaskId,
    LoopPort, PortUse, StateKind, SubgraphPort,
};
use crate::span::Span;
use crate::taskgraph::TaskGraph;
use crate::taskgraph::analysis::{buffers, consistency, level::Level, schedule};
use crate::taskgraph::model::{Direction, LoopNode, LoopType, PortKind, Task, Trigger};
use crate::taskgraph::subgraph::{Hierarchy, PortLink};
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
                let opened = unusable_subgraphs(&service, path, &loaded.hierarchy).and_then(|()| {
                    steps_of(&loaded.graph, &loaded.hierarchy).map_err(|why| GraphRefused {
                        code: Code::CodegenUnsupported,
                        message: format!(
                            "code generation does not support the task graph of `{service}` ({path}), which {why}, yet"
                        ),
                        related: Vec::new(),
                    })
                });
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

/// E135 when the workspace could not follow one of the graph's sub-graph
/// references (its problems are the graph file's own diagnostics: each is
/// related here, where the graph is run).
fn unusable_subgraphs(
    service: &str,
    path: &str,
    hierarchy: &Hierarchy,
) -> Result<(), GraphRefused> {
    let problems: Vec<Related> = hierarchy
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| Related {
            file: d.file,
            span: d.span,
            message: format!("{} {}", d.code, d.message),
        })
        .collect();
    let Some(first) = problems.first() else {
        return Ok(());
    };
    Err(GraphRefused {
        code: Code::ServiceSubgraphUnusable,
        message: format!(
            "the task graph of `{service}` ({path}) cannot run: a sub-graph it references cannot be used ({}{})",
            first.message,
            match problems.len() {
                1 => String::new(),
                n => format!("; and {} more", n - 1),
            }
        ),
        related: problems,
    })
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

/// `graph` opened, with the sub-graphs its tasks reference (`hierarchy`,
/// resolved without errors), or why it cannot run.
pub(crate) fn steps_of(graph: &TaskGraph, hierarchy: &Hierarchy) -> Result<Opened, String> {
    let (levels, stands_for): (Vec<Level<'_>>, Vec<_>) = Level::all_with(graph, hierarchy)
        .into_iter()
        .map(|h| (h.level, h.entered_through))
        .unzip();
    let mut opener = Opener {
        levels: &levels,
        stands_for,
        channels: Vec::new(),
        ends: HashMap::new(),
        tasks: Vec::new(),
    };
    for index in 0..levels.len() {
        opener.channels_of(index)?;
    }
    let steps = opener.level_steps(0)?;
    let tokens: u64 = opener.channels.iter().map(|c| c.capacity).sum();
    if tokens > MAX_GRAPH_TOKENS {
        return Err(format!(
            "needs {tokens} tokens in its channels, more than {MAX_GRAPH_TOKENS}"
        ));
    }
    Ok(Opened {
        steps,
        channels: opener.channels,
        tasks: opener.tasks,
    })
}

/// The longest period of a time-triggered inner task (about 31 years):
/// release times stay far inside the generated program's `int64_t`
/// milliseconds.
pub const MAX_INNER_PERIOD_MS: u64 = 1_000_000_000_000;

/// Inner task `path`'s period as the service task's clock counts it: whole
/// milliseconds (the checked model's period is positive and finite), else
/// why the graph cannot run.
fn whole_period(path: &str, period_ms: f64) -> Result<u64, String> {
    if period_ms.fract() != 0.0 || !(1.0..=MAX_INNER_PERIOD_MS as f64).contains(&period_ms) {
        return Err(format!(
            "has time-triggered task `{path}` with a period of {period_ms} ms, not a whole number of milliseconds from 1 to {MAX_INNER_PERIOD_MS} (the service task's clock counts whole milliseconds)"
        ));
    }
    Ok(period_ms as u64)
}

/// Tokens a graph's channels hold, at most: the generated program keeps
/// them, and each firing's port arrays (no larger than a channel), in
/// static storage.
pub const MAX_GRAPH_TOKENS: u64 = 1 << 16;

/// The (task's, sub-graph's) port names of boundary edge `edge` of a
/// sub-graph level, the next of `links` that joins ports: checked against
/// the edge's ends.
fn boundary_ports<'g>(
    level: &Level<'g>,
    edge: &crate::taskgraph::analysis::level::Edge,
    task: &Task,
    links: &mut std::slice::Iter<'_, PortLink>,
) -> Option<(String, String)> {
    let (inputs, outputs) = level.boundary?;
    let link = links.find(|l| {
        let outer = task.ports.get(l.outer);
        let inner = level
            .graph
            .tasks
            .get(l.inner_task)
            .and_then(|t| t.ports.get(l.inner_port));
        outer
            .zip(inner)
            .is_some_and(|(o, i)| o.rate > 0 && i.rate > 0)
    })?;
    let outer = &task.ports[link.outer];
    let inner = &level.graph.tasks[link.inner_task].ports[link.inner_port];
    let ends = match outer.dir {
        Direction::In => (inputs, link.inner_task),
        Direction::Out => (link.inner_task, outputs),
    };
    (ends == (edge.src, edge.dst))
        .then(|| (outer.name.name.to_string(), inner.name.name.to_string()))
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
    /// Per level: in a sub-graph's top level, the task it stands for and
    /// how the task's ports link to the sub-graph's open ports
    /// (`HierarchyLevel::entered_through`).
    stands_for: Vec<Option<(&'g Task, &'g [PortLink])>>,
    channels: Vec<GraphChannel>,
    /// (task path below the graph, port, side) → the channels joining it.
    ends: HashMap<(String, String, Side), Vec<GraphChannelId>>,
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
        // A sub-graph's boundary edges join no channel of its file: they
        // are the links of the task's ports, in order (`Level::subgraph`).
        let mut links = self.stands_for[index].map(|(task, links)| (task, links.iter()));
        for (edge, bound) in level.edges.iter().zip(bounds) {
            let (src_port, dst_port) = if let Some(channel) = edge.channel {
                let c = &level.graph.channels[channel];
                (c.src.port.to_string(), c.dst.port.to_string())
            } else {
                let Some((task, links)) = links.as_mut() else {
                    return Err(format!("has an edge `{}` outside its channels", edge.label));
                };
                let Some((outer, inner)) = boundary_ports(level, edge, task, links) else {
                    return Err(format!(
                        "has sub-graph edge `{}` that no port of `{}` links",
                        edge.label, task.name.name
                    ));
                };
                // An open port of the task (the graph's interface) leaves
                // the sub-graph's port open too.
                if self.end(&at, &outer, Side::Outer)?.is_none() {
                    continue;
                }
                match level.boundary.is_some_and(|(inputs, _)| edge.src == inputs) {
                    true => (outer, inner),
                    false => (inner, outer),
                }
            };
            let channel = GraphChannelId::new(self.channels.len());
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
            for (node, port) in [(edge.src, src_port), (edge.dst, dst_port)] {
                let key = match level.nodes[node].task {
                    Some(t) => (
                        self.below(&format!(
                            "{}/{}",
                            level.path, level.graph.tasks[t].name.name
                        )),
                        port,
                        Side::Outer,
                    ),
                    // The enclosing loop node's or sub-graph task's boundary.
                    None => (at.clone(), port, Side::Inner),
                };
                self.ends.entry(key).or_default().push(channel);
            }
        }
        Ok(())
    }

    /// The one channel joining `path`'s `port` on `side`, if any.
    fn end(&self, path: &str, port: &str, side: Side) -> Result<Option<GraphChannelId>, String> {
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

    /// The index of inner task `path` in [`Opened::tasks`], listed at its
    /// first firing.
    fn inner_task(&mut self, path: &str, task: &Task) -> Result<InnerTaskId, String> {
        if let Some(index) = self.tasks.iter().position(|t| t.path == path) {
            return Ok(InnerTaskId::new(index));
        }
        let mut inputs = Vec::new();
        let mut outputs = Vec::new();
        for port in &task.ports {
            let Some(channel) = self.end(path, &port.name.name, Side::Outer)? else {
                continue; // an open port: the graph's interface
            };
            let used = PortUse {
                port: port.name.name.to_string(),
                channel,
                rate: port.rate,
            };
            match port.dir {
                Direction::In => inputs.push(used),
                Direction::Out => outputs.push(used),
            }
        }
        let period_ms = match task.trigger {
            Trigger::Time { period_ms } => Some(whole_period(path, period_ms)?),
            Trigger::Data => None,
            // The service task runs every inner task as its schedule
            // reaches it; no control task runs inside a service graph, so
            // firing it as a data task would quietly mean something else.
            Trigger::Control => {
                return Err(format!(
                    "has control-triggered task `{path}` (inside a service graph only the schedule runs tasks)"
                ));
            }
        };
        self.tasks.push(InnerTask {
            path: path.to_string(),
            inputs,
            outputs,
            period_ms,
        });
        Ok(InnerTaskId::new(self.tasks.len() - 1))
    }

    /// The ports of task `path` standing for a sub-graph that a channel
    /// joins outside, each with the channel joining the sub-graph's open
    /// port of its name.
    fn subgraph_ports(&self, path: &str, task: &Task) -> Result<Vec<SubgraphPort>, String> {
        let mut out = Vec::new();
        for port in &task.ports {
            let name = &port.name.name;
            let Some(outer) = self.end(path, name, Side::Outer)? else {
                continue; // an open port: the graph's interface
            };
            let Some(inner) = self.end(path, name, Side::Inner)? else {
                return Err(format!(
                    "has sub-graph port `{path}.{name}` that no open port of its sub-graph takes"
                ));
            };
            out.push(SubgraphPort {
                port: name.to_string(),
                input: port.dir == Direction::In,
                rate: port.rate,
                outer,
                inner,
            });
        }
        Ok(out)
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
                port: name.to_string(),
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
                        None if task.subgraph.is_some() => {
                            // Its firing is a whole iteration of another
                            // graph: no inner task to hold its period.
                            if let Trigger::Time { period_ms } = task.trigger {
                                return Err(format!(
                                    "has time-triggered task `{path}` (every {period_ms} ms) standing for a sub-graph"
                                ));
                            }
                            // The sub-graph's top level, at the task's path.
                            let inner = levels
                                .iter()
                                .position(|l| l.path == full)
                                .ok_or_else(|| format!("has no sub-graph level for `{full}`"))?;
                            let ports = self.subgraph_ports(&path, task)?;
                            let body = self.level_steps(inner)?;
                            let once = GraphStep::Subgraph { path, ports, body };
                            if *count == 1 {
                                once
                            } else {
                                GraphStep::Repeat {
                                    count: *count,
                                    body: vec![once],
                                }
                            }
                        }
                        None => GraphStep::Fire {
                            task: self.inner_task(&path, task)?,
                            count: *count,
                        },
                        Some(node) => {
                            let inner = levels
                                .iter()
                                .position(|l| l.path == full)
                                .ok_or_else(|| format!("has no level for `{full}`"))?;
                            let ports = self.loop_ports(&path, task, node)?;
                            let body = self.level_steps(inner)?;
                            let exit_task = match &node.exit_task {
                                None => None,
                                Some(e) => {
                                    let exit = format!("{path}/{}", e.name);
                                    let index = self
                                        .tasks
                                        .iter()
                                        .position(|t| t.path == exit)
                                        .ok_or_else(|| {
                                            format!(
                                                "has exit task `{exit}` that its loop never fires"
                                            )
                                        })?;
                                    Some(InnerTaskId::new(index))
                                }
                            };
                            let looped = GraphStep::Loop {
                                convergent: node.loop_type == LoopType::C,
                                loop_count: node.loop_count,
                                exit_task,
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
