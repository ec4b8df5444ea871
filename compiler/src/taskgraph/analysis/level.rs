//! One hierarchy level of a task graph seen as plain SDF: nodes and edges with
//! their rates. Inside a loop body, the enclosing loop node's boundary becomes
//! two virtual nodes, one that feeds the loop's input ports and one that drains
//! its output ports, each firing once per iteration.

use crate::span::Span;
use crate::taskgraph::model::{Direction, Endpoint, Task, TaskGraph};
use crate::taskgraph::subgraph::{Hierarchy, PortLink};
use smol_str::SmolStr;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    /// The task's name (a copy of a small string kept inline, as
    /// [`crate::taskgraph::model::Named`] keeps it), or a boundary node's.
    pub name: SmolStr,
    /// The task of the graph, or `None` for a loop boundary node.
    pub task: Option<usize>,
    pub span: Span,
    /// The execution time of one firing: the task's `wcet`, or for a task
    /// standing for a sub-graph without one, the time of one iteration of
    /// the sub-graph (set by the analysis); `None` for boundary nodes.
    pub wcet: Option<u64>,
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
    /// Index of the channel in the graph; `None` for a sub-graph's boundary
    /// edge, which is one of the standing-for task's port links
    /// ([`HierarchyLevel::entered_through`]), not a channel of the file.
    pub channel: Option<usize>,
    pub span: Span,
    /// `A.o → B.i`, for messages.
    pub label: String,
}

/// A list of indices per node (its input or output edges, its successors),
/// all in one vector: a level of 1,000 nodes built a thousand small vectors
/// per list otherwise, each grown by pushes, and the allocations were a
/// tenth of an analysis. `lists[v]` is node `v`'s slice.
#[derive(Clone, Debug, Default)]
pub struct Lists {
    /// Node `v`'s items are `items[first[v]..first[v + 1]]`.
    first: Vec<usize>,
    items: Vec<usize>,
}

impl Lists {
    /// The lists of nodes `0..n` holding each `(node, item)` pair, in the
    /// order given (as pushing each item onto its node's vector would).
    /// `pairs` is iterated twice: once to count, once to place.
    pub fn new<I>(n: usize, pairs: impl Fn() -> I) -> Lists
    where
        I: Iterator<Item = (usize, usize)>,
    {
        let mut first = vec![0; n + 1];
        for (v, _) in pairs() {
            first[v + 1] += 1;
        }
        for v in 0..n {
            first[v + 1] += first[v];
        }
        let mut next = first.clone();
        let mut items = vec![0; first[n]];
        for (v, item) in pairs() {
            items[next[v]] = item;
            next[v] += 1;
        }
        Lists { first, items }
    }

    /// How many nodes have a list.
    pub fn len(&self) -> usize {
        self.first.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn get(&self, v: usize) -> Option<&[usize]> {
        let range = *self.first.get(v)?..*self.first.get(v + 1)?;
        self.items.get(range)
    }

    /// Each node's list, in node order.
    pub fn iter(&self) -> impl Iterator<Item = &[usize]> {
        (0..self.len()).map(|v| &self[v])
    }

    /// Each node's list as a slice, for loops that read them once per
    /// firing (`mp3playback` fires 10,601 times per iteration): indexing
    /// these costs what indexing a vector of vectors did, where indexing
    /// `Lists` looks up two offsets each time.
    pub fn slices(&self) -> Vec<&[usize]> {
        self.iter().collect()
    }

    /// Every list's items, one list after the other.
    pub fn items(&self) -> &[usize] {
        &self.items
    }

    pub fn get_mut(&mut self, v: usize) -> Option<&mut [usize]> {
        let range = *self.first.get(v)?..*self.first.get(v + 1)?;
        self.items.get_mut(range)
    }
}

impl std::ops::Index<usize> for Lists {
    type Output = [usize];

    fn index(&self, v: usize) -> &[usize] {
        &self.items[self.first[v]..self.first[v + 1]]
    }
}

#[derive(Clone, Debug)]
pub struct Level<'g> {
    /// `kmeans`, `kmeans/Converge`, ...
    pub path: String,
    pub graph: &'g TaskGraph,
    pub nodes: Vec<Node>,
    pub edges: Vec<Edge>,
    /// The boundary nodes (inputs side, outputs side) inside a loop body or
    /// a task's sub-graph.
    pub boundary: Option<(usize, usize)>,
    /// In a sub-graph's top level: the name of the task it stands for.
    pub stands_for: Option<String>,
}

/// A level of a graph's whole hierarchy, and which of the graph's own
/// sub-graph references (an index in its `Hierarchy::subgraphs`) it lies
/// under, if any.
pub struct HierarchyLevel<'g> {
    pub level: Level<'g>,
    pub under: Option<usize>,
    /// In a sub-graph's top level: the task it stands for and how the task's
    /// ports link to the sub-graph's open ports (the level's boundary edges
    /// are these links, in order).
    pub entered_through: Option<(&'g Task, &'g [PortLink])>,
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
                wcet: t.wcet,
            })
            .collect();
        let boundary = enclosing.map(|l| {
            let inputs = nodes.len();
            for side in ["inputs", "outputs"] {
                nodes.push(Node {
                    name: format!("{} ({side})", l.name.name).into(),
                    task: None,
                    span: l.name.span,
                    wcet: None,
                });
            }
            (inputs, inputs + 1)
        });
        let index: crate::fasthash::FastMap<&str, usize> = graph
            .tasks
            .iter()
            .enumerate()
            .map(|(i, t)| (t.name.name.as_str(), i))
            .collect();
        let task_index = |name: &str| index.get(name).copied();
        let mut edges = Vec::with_capacity(graph.channels.len());
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
                channel: Some(channel),
                span: c.span,
                label: label(&c.src, &c.dst),
            });
        }
        Level {
            path,
            graph,
            nodes,
            edges,
            boundary,
            stands_for: None,
        }
    }

    /// Each node's input edges and output edges, in edge order (edges whose
    /// ends are not nodes of the level left out).
    pub fn adjacency(&self) -> (Lists, Lists) {
        let n = self.nodes.len();
        let edges = || {
            self.edges
                .iter()
                .enumerate()
                .filter(move |(_, e)| e.src < n && e.dst < n)
        };
        (
            Lists::new(n, || edges().map(|(i, e)| (e.dst, i))),
            Lists::new(n, || edges().map(|(i, e)| (e.src, i))),
        )
    }

    /// This level and every level nested in its loop nodes, outermost first.
    pub fn all(graph: &'g TaskGraph) -> Vec<Level<'g>> {
        graph
            .levels()
            .into_iter()
            .map(|l| Level::build(l.graph, l.enclosing, l.path))
            .collect()
    }

    /// The top level of the sub-graph `graph` that `task` stands for: its
    /// tasks and channels, and the two boundary nodes joined to the open
    /// ports `links` pairs with the task's ports, carrying the task's rates
    /// (one boundary firing is one firing of the task).
    pub fn subgraph(
        graph: &'g TaskGraph,
        task: &Task,
        links: &[PortLink],
        path: String,
    ) -> Level<'g> {
        let mut level = Level::build(graph, None, path);
        let inputs = level.nodes.len();
        for side in ["inputs", "outputs"] {
            level.nodes.push(Node {
                name: format!("{} ({side})", task.name.name).into(),
                task: None,
                span: graph.span,
                wcet: None,
            });
        }
        let outputs = inputs + 1;
        for link in links {
            let (Some(outer), Some(inner_task)) =
                (task.ports.get(link.outer), graph.tasks.get(link.inner_task))
            else {
                continue;
            };
            let Some(inner) = inner_task.ports.get(link.inner_port) else {
                continue;
            };
            let (outer_end, inner_end) = (
                format!("{}.{}", task.name.name, outer.name.name),
                format!("{}.{}", inner_task.name.name, inner.name.name),
            );
            let (src, dst, produce, consume, label) = match outer.dir {
                Direction::In => (
                    inputs,
                    link.inner_task,
                    outer.rate,
                    inner.rate,
                    format!("{outer_end} → {inner_end}"),
                ),
                Direction::Out => (
                    link.inner_task,
                    outputs,
                    inner.rate,
                    outer.rate,
                    format!("{inner_end} → {outer_end}"),
                ),
            };
            if produce == 0 || consume == 0 {
                continue;
            }
            level.edges.push(Edge {
                src,
                dst,
                produce,
                consume,
                initial_tokens: 0,
                channel: None,
                span: inner.name.span,
                label,
            });
        }
        level.boundary = Some((inputs, outputs));
        level.stands_for = Some(task.name.name.to_string());
        level
    }

    /// Every level of `graph` and of the sub-graphs it references
    /// (`hierarchy`), outermost first: the graph's own levels as
    /// [`Level::all`] gives them, then each sub-graph's levels (its top level
    /// at `<level>/<task>`), and theirs in turn. A level comes before the
    /// levels nested in it.
    pub fn all_with(graph: &'g TaskGraph, hierarchy: &'g Hierarchy) -> Vec<HierarchyLevel<'g>> {
        let mut out = Vec::new();
        collect(graph, &graph.name, None, hierarchy, None, &mut out);
        out
    }
}

/// `A.o → B.i`, copied once into a string of its size (`format!` grew it
/// piece by piece: two thousand labels on a 1,000-actor graph).
fn label(src: &Endpoint, dst: &Endpoint) -> String {
    let (a, b, c, d) = (&*src.task, &*src.port, &*dst.task, &*dst.port);
    [a, ".", b, " → ", c, ".", d].concat()
}

/// The levels of `graph` (its paths starting with `prefix` instead of its
/// name), entered through `boundary` when it is a sub-graph, then those of
/// its sub-graphs.
fn collect<'g>(
    graph: &'g TaskGraph,
    prefix: &str,
    boundary: Option<(&'g Task, &'g [PortLink])>,
    hierarchy: &'g Hierarchy,
    under: Option<usize>,
    out: &mut Vec<HierarchyLevel<'g>>,
) {
    let levels = graph.levels();
    let repath = |path: &str| format!("{prefix}{}", &path[graph.name.len().min(path.len())..]);
    for l in &levels {
        let path = repath(&l.path);
        let entered_through = boundary.filter(|_| l.enclosing.is_none());
        let level = match entered_through {
            Some((task, links)) => Level::subgraph(l.graph, task, links, path),
            None => Level::build(l.graph, l.enclosing, path),
        };
        out.push(HierarchyLevel {
            level,
            under,
            entered_through,
        });
    }
    for (i, s) in hierarchy.subgraphs.iter().enumerate() {
        let Some(task) = levels
            .iter()
            .find(|l| l.path == s.level)
            .and_then(|l| l.graph.tasks.get(s.task))
        else {
            continue;
        };
        let path = format!("{}/{}", repath(&s.level), task.name.name);
        collect(
            &s.graph,
            &path,
            Some((task, &s.links)),
            &s.nested,
            under.or(Some(i)),
            out,
        );
    }
}
