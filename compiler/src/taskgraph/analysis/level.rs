//! One hierarchy level of a task graph seen as plain SDF: nodes and edges with
//! their rates. Inside a loop body, the enclosing loop node's boundary becomes
//! two virtual nodes, one that feeds the loop's input ports and one that drains
//! its output ports, each firing once per iteration.

use crate::span::Span;
use crate::taskgraph::model::{Direction, Task, TaskGraph};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    pub name: String,
    /// The task of the graph, or `None` for a loop boundary node.
    pub task: Option<usize>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Edge {
    pub src: usize,
    pub dst: usize,
    /// Samples produced per firing of `src`.
    pub produce: u64,
    /// Samples consumed per firing of `dst`.
    pub consume: u64,
    pub initial_tokens: u64,
    /// Index of the channel in the graph.
    pub channel: usize,
    pub span: Span,
    /// `A.o → B.i`, for messages.
    pub label: String,
}

#[derive(Clone, Debug)]
pub struct Level<'g> {
    /// `kmeans`, `kmeans/Converge`, ...
    pub path: String,
    pub graph: &'g TaskGraph,
    pub nodes: Vec<Node>,
    pub edges: Vec<Edge>,
    /// The boundary nodes (inputs side, outputs side) inside a loop body.
    pub boundary: Option<(usize, usize)>,
}

impl<'g> Level<'g> {
    /// The level of `graph`, enclosed by the loop task `enclosing` if any.
    /// Channels whose ends do not resolve (already reported by the loader) are
    /// left out.
    pub fn build(graph: &'g TaskGraph, enclosing: Option<&Task>, path: String) -> Level<'g> {
        let mut nodes: Vec<Node> = graph
            .tasks
            .iter()
            .enumerate()
            .map(|(i, t)| Node {
                name: t.name.name.clone(),
                task: Some(i),
                span: t.name.span,
            })
            .collect();
        let boundary = enclosing.map(|l| {
            let inputs = nodes.len();
            for side in ["inputs", "outputs"] {
                nodes.push(Node {
                    name: format!("{} ({side})", l.name.name),
                    task: None,
                    span: l.name.span,
                });
            }
            (inputs, inputs + 1)
        });
        let index: std::collections::HashMap<&str, usize> = graph
            .tasks
            .iter()
            .enumerate()
            .map(|(i, t)| (t.name.name.as_str(), i))
            .collect();
        let task_index = |name: &str| index.get(name).copied();
        let mut edges = Vec::new();
        for (channel, c) in graph.channels.iter().enumerate() {
            let src = match (task_index(&c.src.task), enclosing, boundary) {
                (Some(t), _, _) => graph.tasks[t]
                    .port(&c.src.port)
                    .filter(|p| p.dir == Direction::Out)
                    .map(|p| (t, p.rate)),
                (None, Some(l), Some((inputs, _))) if l.name.name == c.src.task => l
                    .port(&c.src.port)
                    .filter(|p| p.dir == Direction::In)
                    .map(|p| (inputs, p.inner_rate.unwrap_or(p.rate))),
                _ => None,
            };
            let dst = match (task_index(&c.dst.task), enclosing, boundary) {
                (Some(t), _, _) => graph.tasks[t]
                    .port(&c.dst.port)
                    .filter(|p| p.dir == Direction::In)
                    .map(|p| (t, p.rate)),
                (None, Some(l), Some((_, outputs))) if l.name.name == c.dst.task => l
                    .port(&c.dst.port)
                    .filter(|p| p.dir == Direction::Out)
                    .map(|p| (outputs, p.inner_rate.unwrap_or(p.rate))),
                _ => None,
            };
            let (Some((src, produce)), Some((dst, consume))) = (src, dst) else {
                continue;
            };
            if produce == 0 || consume == 0 {
                continue;
            }
            edges.push(Edge {
                src,
                dst,
                produce,
                consume,
                initial_tokens: c.initial_tokens,
                channel,
                span: c.span,
                label: format!(
                    "{}.{} → {}.{}",
                    c.src.task, c.src.port, c.dst.task, c.dst.port
                ),
            });
        }
        Level {
            path,
            graph,
            nodes,
            edges,
            boundary,
        }
    }

    /// This level and every level nested in its loop nodes, outermost first.
    pub fn all(graph: &'g TaskGraph) -> Vec<Level<'g>> {
        graph
            .levels()
            .into_iter()
            .map(|l| Level::build(l.graph, l.enclosing, l.path))
            .collect()
    }
}
