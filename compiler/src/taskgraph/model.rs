//! The task-graph model (extended SDF: control, library and loop tasks,
//! multicast ports). The file formats: `docs/taskgraph.md`. Every element keeps the
//! byte range it was read from, so analyses can point at the channel or task
//! concerned. Rates and counts are exact integers.

use crate::diag::FileId;
use crate::span::Span;
use smol_str::SmolStr;

/// A name with the range it was written at. Names are short: a
/// [`SmolStr`] keeps them inline, without an allocation each (a large SDF3
/// graph has tens of thousands).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Named {
    pub name: SmolStr,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TaskGraph {
    pub name: String,
    pub file: FileId,
    /// The `<TaskGraph>` (or SDF3 `<sdf>`) element.
    pub span: Span,
    pub tasks: Vec<Task>,
    pub channels: Vec<Channel>,
    pub libraries: Vec<Library>,
}

impl TaskGraph {
    /// The task named `name` (a linear search: index the tasks for many lookups).
    pub fn task_index(&self, name: &str) -> Option<usize> {
        self.tasks.iter().position(|t| t.name.name == name)
    }

    /// This graph and every loop body nested in it, outermost first (the
    /// order of the analyses' levels), each with its path (`kmeans/Converge`).
    pub fn levels(&self) -> Vec<LevelRef<'_>> {
        fn collect<'g>(
            graph: &'g TaskGraph,
            enclosing: Option<&'g Task>,
            path: String,
            out: &mut Vec<LevelRef<'g>>,
        ) {
            out.push(LevelRef {
                path: path.clone(),
                graph,
                enclosing,
            });
            for task in &graph.tasks {
                if let Some(l) = &task.loop_node {
                    collect(
                        &l.body,
                        Some(task),
                        format!("{path}/{}", task.name.name),
                        out,
                    );
                }
            }
        }
        let mut out = Vec::new();
        collect(self, None, self.name.clone(), &mut out);
        out
    }
}

/// One level of a graph's hierarchy: its tasks and channels, its path, and
/// the loop node whose body it is.
#[derive(Clone, Debug)]
pub struct LevelRef<'g> {
    pub path: String,
    pub graph: &'g TaskGraph,
    pub enclosing: Option<&'g Task>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TaskKind {
    Computational,
    Control,
    Library,
    Loop,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Trigger {
    /// Runs every period (milliseconds).
    Time { period_ms: f64 },
    /// Runs when every input holds enough samples (the SDF default).
    Data,
    /// Run, stopped, suspended and resumed by the control task.
    Control,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    pub name: Named,
    /// The whole element.
    pub span: Span,
    pub kind: TaskKind,
    pub trigger: Trigger,
    /// Worst-case execution time, in the graph's time unit (SDF3: the default
    /// processor's execution time).
    pub wcet: Option<u64>,
    pub source: Option<String>,
    /// A sub-graph file this task stands for (hierarchy by reference).
    pub subgraph: Option<Named>,
    pub ports: Vec<Port>,
    pub library_ports: Vec<LibraryPort>,
    pub multicast_ports: Vec<MulticastPort>,
    /// For `kind == Loop`: the loop's type, count and inner graph.
    pub loop_node: Option<Box<LoopNode>>,
}

impl Task {
    pub fn port(&self, name: &str) -> Option<&Port> {
        self.ports.iter().find(|p| p.name.name == name)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    In,
    Out,
}

/// How a loop node's input port hands samples to the iterations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortKind {
    /// One share per iteration.
    Distributing,
    /// The same samples for every iteration.
    Broadcasting,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Port {
    pub name: Named,
    pub span: Span,
    pub dir: Direction,
    /// Samples per firing (for a loop node: the outer rate). At least 1.
    pub rate: u64,
    /// The range of the `rate` (or `outerRate`) attribute, if written.
    pub rate_span: Option<Span>,
    pub sample_type: Option<String>,
    pub size: Option<u64>,
    /// Loop-node ports only: distributing or broadcasting (inputs).
    pub kind: Option<PortKind>,
    /// Loop-node ports only: the rate seen by the inner graph per iteration.
    pub inner_rate: Option<u64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopType {
    /// Data loop: fresh inputs every iteration, exactly `loop_count` iterations.
    D,
    /// Convergent loop: iterates until the exit task says so (at most `loop_count`).
    C,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LoopNode {
    pub loop_type: LoopType,
    pub loop_count: u64,
    pub exit_task: Option<Named>,
    pub body: TaskGraph,
}

/// `task.port` at one end of a channel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Endpoint {
    pub task: SmolStr,
    pub port: SmolStr,
    /// The attribute value (`camera.out`).
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Channel {
    pub src: Endpoint,
    pub dst: Endpoint,
    pub initial_tokens: u64,
    pub capacity: Option<u64>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Library {
    pub name: Named,
    pub span: Span,
    pub functions: Vec<LibraryFunction>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LibraryFunction {
    pub name: Named,
    pub returns: Option<String>,
    pub params: Vec<(String, String)>,
}

/// A library master port (a caller) or slave port (the library side).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LibraryPort {
    pub name: Named,
    pub span: Span,
    pub library: Named,
    pub master: bool,
    /// Functions this task calls through the port (master ports).
    pub calls: Vec<Named>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MulticastPort {
    pub name: Named,
    pub span: Span,
    pub dir: Direction,
    pub group: Named,
}
