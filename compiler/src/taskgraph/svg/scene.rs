//! What to draw: the model turned into levels of nodes and edges, without
//! coordinates. A loop node is a cluster node holding the level of its body;
//! the loop's ports are port nodes of that inner level (on the cluster's
//! border), and outer channels attach to them.
//!
//! Library and multicast connections that leave a loop body pass through a
//! relay point on the cluster's border: a library is drawn in the level that
//! declares it (the innermost enclosing one), a multicast group at the top
//! level (groups are global), and a call from inside a loop is drawn as a
//! dashed line to the border and on from there to the library.

use crate::taskgraph::analysis::{BlockedCycle, GraphReport};
use crate::taskgraph::model::*;
use std::collections::{HashMap, HashSet};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shape {
    /// A computational task (or a task of unknown kind).
    Task,
    Control,
    LibraryTask,
    /// A declared library.
    Library,
    /// A multicast group.
    Group,
    /// Something a channel or port names that the graph does not have.
    Missing,
    /// A loop's data port, on its cluster's border.
    Port,
    /// A library or multicast connection crossing a cluster's border.
    Relay,
    /// A loop node: `Node::cluster` holds its body.
    Cluster,
}

/// The border of a cluster that a port or relay sits on: inputs on the left,
/// outputs on the right.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Side {
    Left,
    Right,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Style {
    /// A channel.
    Data,
    /// A library master port to its library.
    Call,
    /// A library to the task serving it (slave port).
    Serve,
    /// A multicast write (task → group) or read (group → task).
    Multicast,
}

pub(super) struct Node {
    /// Unique in the picture: `L/B` for task B in loop L, `L.in` for L's port.
    pub path: String,
    pub shape: Shape,
    /// The name, then an optional smaller detail line.
    pub lines: Vec<String>,
    /// Shown on hover.
    pub tooltip: String,
    /// Ports and relays: the border they sit on.
    pub side: Option<Side>,
    pub cluster: Option<Box<Level>>,
}

/// One end of an edge: a node, and for a cluster node the port or relay
/// (a node index in the cluster's level) it attaches to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct End {
    pub node: usize,
    pub port: Option<usize>,
}

pub(super) struct Edge {
    pub from: End,
    pub to: End,
    pub style: Style,
    /// Near the tail: the production rate.
    pub tail: String,
    /// Near the head: the consumption rate.
    pub head: String,
    /// In the middle: initial samples, or a library port's name.
    pub mid: String,
}

/// One graph level: the top level, or a loop body.
#[derive(Default)]
pub(super) struct Level {
    pub nodes: Vec<Node>,
    pub edges: Vec<Edge>,
    /// The nodes and edges of a cycle that blocks this level (the analysis's
    /// deadlock), drawn in red.
    pub deadlocked_nodes: HashSet<usize>,
    pub deadlocked_edges: HashSet<usize>,
}

/// A connection that must leave a loop body.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Ext {
    Library(String),
    Group(String),
}

/// The picture's top level; `report`, the graph's analysis, marks the cycles
/// that deadlock.
pub(super) fn build(graph: &TaskGraph, report: Option<&GraphReport>) -> Level {
    let mut b = Builder::new(String::new(), graph.name.clone(), report);
    b.fill(graph);
    b.level
}

/// The loop whose body a level is: its name, and its port nodes (with the
/// rate seen from inside) by port name.
type Enclosing = (String, HashMap<String, (usize, String)>);

struct Builder<'r> {
    prefix: String,
    /// The level's path in the analysis report (`graph`, `graph/Loop`).
    analysis_path: String,
    report: Option<&'r GraphReport>,
    level: Level,
    enclosing: Option<Enclosing>,
    /// Task name → (node index, index in the graph's tasks).
    tasks: HashMap<String, (usize, usize)>,
    /// For each cluster node: its ports' node indices (in the cluster's level) by name.
    cluster_ports: HashMap<usize, HashMap<String, (usize, String)>>,
    missing: HashMap<String, usize>,
    libraries: HashMap<String, usize>,
    /// Top level: groups and undeclared libraries; inside a body: relays.
    externals: HashMap<(Ext, Side), usize>,
    /// Inside a body: the connections its relays stand for, in order.
    requests: Vec<(Ext, Side, usize)>,
}

impl<'r> Builder<'r> {
    fn new(prefix: String, analysis_path: String, report: Option<&'r GraphReport>) -> Builder<'r> {
        Builder {
            prefix,
            analysis_path,
            report,
            level: Level::default(),
            enclosing: None,
            tasks: HashMap::new(),
            cluster_ports: HashMap::new(),
            missing: HashMap::new(),
            libraries: HashMap::new(),
            externals: HashMap::new(),
            requests: Vec::new(),
        }
    }

    fn add(&mut self, node: Node) -> usize {
        self.level.nodes.push(node);
        self.level.nodes.len() - 1
    }

    fn edge(&mut self, from: End, to: End, style: Style, mid: String) {
        self.edge_with_rates(from, to, style, String::new(), String::new(), mid);
    }

    fn edge_with_rates(
        &mut self,
        from: End,
        to: End,
        style: Style,
        tail: String,
        head: String,
        mid: String,
    ) {
        self.level.edges.push(Edge {
            from,
            to,
            style,
            tail,
            head,
            mid,
        });
    }

    /// Adds the nodes and edges of `graph`: tasks and loops, libraries,
    /// channels, then library and multicast connections (those of inner
    /// loops last, once every library of this level is known).
    fn fill(&mut self, graph: &TaskGraph) {
        let blocked = self.blocked_cycle();
        let mut pending = Vec::new();
        // The ports that this level's channels name, per task: a loop's
        // cluster needs a place for each.
        let mut named: HashMap<&str, Vec<(&str, Side)>> = HashMap::new();
        for c in &graph.channels {
            for (end, side) in [(&c.src, Side::Right), (&c.dst, Side::Left)] {
                named
                    .entry(end.task.as_str())
                    .or_default()
                    .push((end.port.as_str(), side));
            }
        }
        for (t, task) in graph.tasks.iter().enumerate() {
            let path = format!("{}{}", self.prefix, task.name.name);
            let index = match &task.loop_node {
                Some(l) => {
                    let outside = named
                        .get(task.name.name.as_str())
                        .map_or(&[][..], Vec::as_slice);
                    let (index, requests) = self.cluster(task, l, outside, path);
                    pending.extend(requests.into_iter().map(|r| (index, r)));
                    index
                }
                None => {
                    let node = task_node(task, path);
                    self.add(node)
                }
            };
            self.tasks
                .entry(task.name.name.to_string())
                .or_insert((index, t));
            if blocked.is_some_and(|b| {
                b.nodes
                    .iter()
                    .any(|n| n.as_str() == task.name.name.as_str())
            }) {
                self.level.deadlocked_nodes.insert(index);
            }
        }
        for library in &graph.libraries {
            let node = Node {
                path: format!("{}library {}", self.prefix, library.name.name),
                shape: Shape::Library,
                lines: vec![library.name.name.to_string()],
                tooltip: library_tooltip(library),
                side: None,
                cluster: None,
            };
            let index = self.add(node);
            self.libraries
                .entry(library.name.name.to_string())
                .or_insert(index);
        }
        for (c, channel) in graph.channels.iter().enumerate() {
            if blocked.is_some_and(|b| b.channels.contains(&c)) {
                self.level.deadlocked_edges.insert(self.level.edges.len());
            }
            let (from, tail) = self.channel_end(graph, &channel.src);
            let (to, head) = self.channel_end(graph, &channel.dst);
            let mid = match channel.initial_tokens {
                0 => String::new(),
                1 => "●".to_string(),
                n => format!("●×{n}"),
            };
            self.edge_with_rates(from, to, Style::Data, tail, head, mid);
        }
        for task in &graph.tasks {
            let Some(&(index, _)) = self.tasks.get(task.name.name.as_str()) else {
                continue;
            };
            let here = End {
                node: index,
                port: None,
            };
            for port in &task.library_ports {
                let library = Ext::Library(port.library.name.to_string());
                let name = port.name.name.clone();
                if port.master {
                    let to = self.external(library, Side::Right);
                    self.edge(here, to, Style::Call, name.to_string());
                } else {
                    let from = self.external(library, Side::Left);
                    self.edge(from, here, Style::Serve, name.to_string());
                }
            }
            for port in &task.multicast_ports {
                let group = Ext::Group(port.group.name.to_string());
                match port.dir {
                    Direction::Out => {
                        let to = self.external(group, Side::Right);
                        self.edge(here, to, Style::Multicast, String::new());
                    }
                    Direction::In => {
                        let from = self.external(group, Side::Left);
                        self.edge(from, here, Style::Multicast, String::new());
                    }
                }
            }
        }
        for (cluster, (ext, side, relay)) in pending {
            let here = End {
                node: cluster,
                port: Some(relay),
            };
            let style = match (&ext, side) {
                (Ext::Group(_), _) => Style::Multicast,
                (Ext::Library(_), Side::Right) => Style::Call,
                (Ext::Library(_), Side::Left) => Style::Serve,
            };
            let there = self.external(ext, side);
            match side {
                Side::Right => self.edge(here, there, style, String::new()),
                Side::Left => self.edge(there, here, style, String::new()),
            }
        }
    }

    /// A loop node: its body as a level of its own inside a cluster node.
    /// Gives the node's index and the connections its relays need outside.
    /// `outside`: the ports of the loop that channels around it name, with
    /// the side their use implies.
    fn cluster(
        &mut self,
        task: &Task,
        l: &LoopNode,
        outside: &[(&str, Side)],
        path: String,
    ) -> (usize, Vec<(Ext, Side, usize)>) {
        let name = &task.name.name;
        // The loop's ports: declared ones, then any the channels name (on the
        // side their use implies), so that every channel end has a place.
        let mut ports: Vec<(String, Side, Option<&Port>)> = task
            .ports
            .iter()
            .map(|p| {
                let side = match p.dir {
                    Direction::In => Side::Left,
                    Direction::Out => Side::Right,
                };
                (p.name.name.to_string(), side, Some(p))
            })
            .collect();
        let inside = l.body.channels.iter().flat_map(|c| {
            [(&c.src, Side::Left), (&c.dst, Side::Right)]
                .into_iter()
                .filter(|(end, _)| end.task == *name)
                .map(|(end, side)| (end.port.as_str(), side))
        });
        let mut known: HashSet<String> = ports.iter().map(|(p, _, _)| p.clone()).collect();
        for (port, side) in outside.iter().copied().chain(inside) {
            if known.insert(port.to_string()) {
                ports.push((port.to_string(), side, None));
            }
        }
        let mut inner = Builder::new(
            format!("{path}/"),
            format!("{}/{name}", self.analysis_path),
            self.report,
        );
        let mut by_name = HashMap::new();
        let mut from_inside = HashMap::new();
        for (port, side, declared) in ports {
            let node = Node {
                path: format!("{path}.{port}"),
                shape: Shape::Port,
                lines: vec![port.clone()],
                tooltip: port_tooltip(name, &port, declared),
                side: Some(side),
                cluster: None,
            };
            let index = inner.add(node);
            let rate = |r: Option<u64>| r.map_or("?".to_string(), |r| r.to_string());
            let outer = rate(declared.map(|p| p.rate));
            let inner_rate = rate(declared.map(|p| p.inner_rate.unwrap_or(p.rate)));
            by_name.entry(port.clone()).or_insert((index, outer));
            from_inside.entry(port).or_insert((index, inner_rate));
        }
        inner.enclosing = Some((name.to_string(), from_inside));
        inner.fill(&l.body);
        let kind = match l.loop_type {
            LoopType::D => "D",
            LoopType::C => "C",
        };
        let mut tooltip = match l.loop_type {
            LoopType::D => format!("loop {name}: D-type, {} iterations", l.loop_count),
            LoopType::C => format!("loop {name}: C-type, at most {} iterations", l.loop_count),
        };
        if let Some(exit) = &l.exit_task {
            tooltip.push_str(&format!(", exit task {}", exit.name));
        }
        let node = Node {
            path,
            shape: Shape::Cluster,
            lines: vec![format!("{name} ({kind}-loop × {})", l.loop_count)],
            tooltip,
            side: None,
            cluster: Some(Box::new(inner.level)),
        };
        let index = self.add(node);
        self.cluster_ports.insert(index, by_name);
        (index, inner.requests)
    }

    /// The cycle that blocks this level, if the analysis found one.
    fn blocked_cycle(&self) -> Option<&'r BlockedCycle> {
        let report = self.report?;
        let level = report
            .levels
            .iter()
            .find(|l| l.path == self.analysis_path)?;
        level.blocked.as_ref()
    }

    /// Where a channel end attaches, and the rate written next to it.
    fn channel_end(&mut self, graph: &TaskGraph, end: &Endpoint) -> (End, String) {
        if let Some(&(node, t)) = self.tasks.get(end.task.as_str()) {
            if let Some(ports) = self.cluster_ports.get(&node) {
                let (port, rate) = match ports.get(end.port.as_str()) {
                    Some((p, rate)) => (Some(*p), rate.clone()),
                    None => (None, "?".to_string()),
                };
                return (End { node, port }, rate);
            }
            let rate = graph.tasks[t]
                .port(&end.port)
                .map_or("?".to_string(), |p| p.rate.to_string());
            return (End { node, port: None }, rate);
        }
        if let Some((name, ports)) = &self.enclosing
            && *name == end.task
            && let Some((node, rate)) = ports.get(end.port.as_str())
        {
            return (
                End {
                    node: *node,
                    port: None,
                },
                rate.clone(),
            );
        }
        let node = match self.missing.get(end.task.as_str()) {
            Some(&n) => n,
            None => {
                let node = Node {
                    path: format!("{}{}", self.prefix, end.task),
                    shape: Shape::Missing,
                    lines: vec![end.task.to_string()],
                    tooltip: format!("{}: no such task in this graph", end.task),
                    side: None,
                    cluster: None,
                };
                let n = self.add(node);
                self.missing.insert(end.task.to_string(), n);
                n
            }
        };
        (End { node, port: None }, "?".to_string())
    }

    /// The node a library or multicast connection attaches to at this level:
    /// the library declared here, the group (top level), or a relay on the
    /// border of the enclosing cluster.
    fn external(&mut self, ext: Ext, side: Side) -> End {
        if let Ext::Library(name) = &ext
            && let Some(&node) = self.libraries.get(name)
        {
            return End { node, port: None };
        }
        let top = self.enclosing.is_none();
        // At the top level one node serves both directions.
        let key = (ext.clone(), if top { Side::Left } else { side });
        if let Some(&node) = self.externals.get(&key) {
            return End { node, port: None };
        }
        let node = if top {
            match &ext {
                Ext::Group(name) => Node {
                    path: format!("multicast {name}"),
                    shape: Shape::Group,
                    lines: vec![name.clone(), "multicast".to_string()],
                    tooltip: format!("multicast group {name}"),
                    side: None,
                    cluster: None,
                },
                Ext::Library(name) => Node {
                    path: format!("library {name}"),
                    shape: Shape::Missing,
                    lines: vec![name.clone(), "library?".to_string()],
                    tooltip: format!("library {name}: not declared"),
                    side: None,
                    cluster: None,
                },
            }
        } else {
            let (what, name) = match &ext {
                Ext::Group(name) => ("multicast", name),
                Ext::Library(name) => ("library", name),
            };
            let dir = match side {
                Side::Left => "in",
                Side::Right => "out",
            };
            let cluster = self.prefix.trim_end_matches('/');
            Node {
                path: format!("{cluster}.{what} {name} {dir}"),
                shape: Shape::Relay,
                lines: Vec::new(),
                tooltip: format!("{what} {name}"),
                side: Some(side),
                cluster: None,
            }
        };
        let index = self.add(node);
        self.externals.insert(key, index);
        if !top {
            self.requests.push((ext, side, index));
        }
        End {
            node: index,
            port: None,
        }
    }
}

fn task_node(task: &Task, path: String) -> Node {
    let name = &task.name.name;
    let shape = match task.kind {
        TaskKind::Control => Shape::Control,
        TaskKind::Library => Shape::LibraryTask,
        TaskKind::Computational | TaskKind::Loop => Shape::Task,
    };
    let mut detail = Vec::new();
    if let Trigger::Time { period_ms } = task.trigger {
        detail.push(format!("every {}", period(period_ms)));
    }
    if let Some(w) = task.wcet {
        detail.push(format!("wcet {w}"));
    }
    // A sub-graph file is named, not drawn inside (it is a picture of its own).
    if let Some(sub) = &task.subgraph {
        detail.push(format!("⤷ {}", sub.name));
    }
    let kind = match task.kind {
        TaskKind::Computational => "computational task",
        TaskKind::Control => "control task",
        TaskKind::Library => "library task",
        TaskKind::Loop => "loop task",
    };
    let trigger = match task.trigger {
        Trigger::Time { .. } => "time-triggered",
        Trigger::Data => "data-triggered",
        Trigger::Control => "run by the control task",
    };
    let mut tooltip = format!("{name}: {kind}, {trigger}");
    for d in &detail {
        tooltip.push_str(&format!(", {d}"));
    }
    if let Some(source) = &task.source {
        tooltip.push_str(&format!(", source {source}"));
    }
    if let Some(sub) = &task.subgraph {
        tooltip.push_str(&format!(", subgraph {}", sub.name));
    }
    let mut lines = vec![name.to_string()];
    if !detail.is_empty() {
        lines.push(detail.join(" · "));
    }
    Node {
        path,
        shape,
        lines,
        tooltip,
        side: None,
        cluster: None,
    }
}

/// `1 s`, `33 ms`, `0.5 ms`.
fn period(ms: f64) -> String {
    if ms >= 1000.0 && (ms / 1000.0).fract() == 0.0 {
        format!("{} s", ms / 1000.0)
    } else {
        format!("{} ms", (ms * 1000.0).round() / 1000.0)
    }
}

fn library_tooltip(library: &Library) -> String {
    let functions: Vec<String> = library
        .functions
        .iter()
        .map(|f| {
            let params: Vec<String> = f.params.iter().map(|(n, t)| format!("{n}: {t}")).collect();
            match &f.returns {
                Some(r) => format!("{}({}) → {r}", f.name.name, params.join(", ")),
                None => format!("{}({})", f.name.name, params.join(", ")),
            }
        })
        .collect();
    format!("library {}: {}", library.name.name, functions.join(", "))
}

fn port_tooltip(loop_name: &str, port: &str, declared: Option<&Port>) -> String {
    let Some(p) = declared else {
        return format!("{loop_name}.{port}: no such port");
    };
    let dir = match p.dir {
        Direction::In => "input",
        Direction::Out => "output",
    };
    let kind = match p.kind {
        Some(PortKind::Distributing) => ", distributing",
        Some(PortKind::Broadcasting) => ", broadcasting",
        None => "",
    };
    let inner = p
        .inner_rate
        .map_or(String::new(), |r| format!(", inner rate {r}"));
    format!(
        "{loop_name}.{port}: {dir}{kind}, outer rate {}{inner}",
        p.rate
    )
}
