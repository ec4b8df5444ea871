//! Reading task-graph files: our `*.taskgraph.xml` format (`<TaskGraph>`) and
//! SDF3 graphs (`<sdf3 type="sdf">`), with positioned diagnostics (E060–E066,
//! W060). `docs/taskgraph.md` is the reference of both formats for users.
//!
//! Our format is read in two steps: the XML is read into a small positioned
//! element tree ([`crate::xmltree`]: every element, attribute and attribute
//! value keeps its byte range), then the tree is read as a graph. An SDF3
//! file (the root's start tag tells) is read in one step, its elements as
//! they come ([`sdf3`]), with the same positions and checks: its files are
//! large, and the tree was most of the time of analysing one. Before that, a
//! clean SDF3 file (nothing to report, no entity) is read straight from
//! quick-xml's events ([`tags`]) into the graph ([`sdf3_clean`]), with the
//! same result;
//! any other file goes to the full reader. Malformed XML
//! (E060) stops reading; what was read before the error is still read as a
//! graph, and channel ends are not checked in a graph level that was cut
//! short.
//!
//! What the returned graph holds:
//! - Entries that cannot be used are left out, so that analyses see no
//!   made-up values: a task, loop, port or library without a name, a second
//!   task or port of the same name, a port with a bad `dir` or rate, a loop with
//!   a bad `type` or `loopCount`, a channel with a malformed end or a bad
//!   `initialTokens`. Channels naming a left-out entry are dropped without a
//!   second report. Other bad values (kind, trigger, wcet, size, capacity) are
//!   reported and replaced by their default.
//! - Channels whose ends are well-formed are kept even when an end names no task
//!   or port (E064) or has the wrong direction (E066): analyses resolve the ends
//!   themselves.
//!
//! Format choices of our format beyond the spec:
//! - The functions a task calls through a library master port are written
//!   either as `<Call function="f"/>` children or as `calls="f g"` (words
//!   separated by spaces or commas), or both; slave ports have neither.
//! - `name` is required on the outer `<TaskGraph>`; a loop body's `<TaskGraph>`
//!   may omit it (it is then `<loop>_body`).
//! - Task, loop, port, library, function and parameter names must be
//!   identifiers (letters, digits, `_`), since channel ends are `task.port`.
//! - Tasks and loops share one namespace per graph level (which includes the
//!   enclosing loop's name inside a body); libraries have their own; all the
//!   ports of one task (data, library and multicast) share one.
//! - `kind` (distributing/broadcasting) is only for loop input ports; it is
//!   `None` when not written.
//! - A channel end naming a library or multicast port is E064: those ports are
//!   not joined by channels.
//!
//! SDF3 files are read leniently: elements and attributes the loader does not
//! use are ignored silently (no E061/W060), as are properties of unknown actors.
//!
//! An SDF3 actor may list execution times for several processor types; which
//! one is its time is an [`ExecutionTimes`] choice, by default the file's
//! (`default="true"`).

use super::model::*;
use crate::diag::{Code, Diagnostic, FileId, Sink, sort_and_dedup};
use crate::fasthash::{FastMap as HashMap, FastSet as HashSet};
use crate::span::Span;
use crate::suggest::did_you_mean;
use crate::syntax::ast::TimeUnit;
use crate::xmlpos::{Attr, get, is_ident, shown, suggest};
use crate::xmltree::{Elem, TreeCollector, TreeFormat, Visit, Vocabulary, walk};
use quick_xml::Reader;
use quick_xml::events::Event;
use smol_str::SmolStr;

/// The two file formats a task graph can be read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GraphFormat {
    /// Our format: a `<TaskGraph>` root element.
    SemoXml,
    /// An SDF3 graph: a `<sdf3 type="sdf">` root element.
    Sdf3,
}

/// Which of an SDF3 actor's `<processor>` entries gives its execution time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ExecutionTimes {
    /// What the file says: the first processor with `default="true"`, else
    /// the first one.
    #[default]
    FileDefault,
    /// What SDF3's loader (`TimedSDFactor::setProperties`, 2009 release)
    /// does: the last processor that has a `default` attribute, whatever its
    /// value (`default="false"` too), and none (time 0) when no processor has
    /// one.
    Sdf3Compat,
}

/// Reads one task-graph file, in our format or SDF3 (told apart by the root
/// element): the graph, as much of it as could be read, and the diagnostics.
/// `None` when no graph could be read at all (no root element, an unknown root
/// element, an SDF3 file of another graph type, an SDF3 file without `<sdf>`).
pub fn load_task_graph(file: FileId, text: &str) -> (Option<TaskGraph>, Vec<Diagnostic>) {
    load_task_graph_as(file, text, ExecutionTimes::FileDefault)
}

/// [`load_task_graph`], reading SDF3 execution times as `times` says.
pub fn load_task_graph_as(
    file: FileId,
    text: &str,
    times: ExecutionTimes,
) -> (Option<TaskGraph>, Vec<Diagnostic>) {
    // A clean SDF3 file needs none of the full reader's positions.
    if let Some(graph) = sdf3_clean::read(file, text, times) {
        return (Some(graph), Vec::new());
    }
    load_fully(file, text, times)
}

/// [`load_task_graph_as`] with the full reader only.
fn load_fully(
    file: FileId,
    text: &str,
    times: ExecutionTimes,
) -> (Option<TaskGraph>, Vec<Diagnostic>) {
    let mut sink = Sink::quoting_xml(file);
    let format = TreeFormat {
        file,
        xml_code: Code::GraphXml,
        empty_message: "this file is empty: a task graph needs a `<TaskGraph>` element",
        raw_lt: None,
    };
    let loader = Loader {
        file,
        sink: &mut sink,
        sdf3: false,
        times,
    };
    let mut reading = Reading::Undecided(Some(loader));
    let xml_diagnostics = walk(text, format, &mut reading);
    let graph = match reading {
        Reading::Undecided(_) => None,
        Reading::Sdf3(reader) => reader.finish(),
        Reading::Tree(tree, mut loader) => tree.into_root().and_then(|root| {
            match root.local.as_str() {
                "TaskGraph" => Some(loader.semo_root(&root)),
                _ => {
                    let message = format!(
                        "a task-graph file must start with `<TaskGraph>` (or SDF3 `<sdf3 type=\"sdf\">`), not `<{}>`",
                        root.qname
                    );
                    loader
                        .sink
                        .report(Code::GraphUnknownElement, root.name_span, message)
                        .suggest(suggest(&root.local, &["TaskGraph", "sdf3"]));
                    None
                }
            }
        }),
    };
    sink.extend(xml_diagnostics);
    let mut diags = sink.into_vec();
    sort_and_dedup(&mut diags);
    (graph, diags)
}

/// How a file is read, decided by its root element's start tag: an SDF3
/// graph as its elements come ([`sdf3`]), our format as an element tree.
enum Reading<'s> {
    /// No root element yet (the loader is waiting).
    Undecided(Option<Loader<'s>>),
    Sdf3(Box<sdf3::Sdf3Reader<'s>>),
    Tree(TreeCollector, Loader<'s>),
}

impl Visit for Reading<'_> {
    fn open(&mut self, e: &Elem) {
        if let Reading::Undecided(loader) = self {
            let Some(mut loader) = loader.take() else {
                return;
            };
            *self = if e.local == "sdf3" {
                loader.sdf3 = true;
                Reading::Sdf3(Box::new(sdf3::Sdf3Reader::new(loader)))
            } else {
                Reading::Tree(TreeCollector::default(), loader)
            };
        }
        match self {
            Reading::Undecided(_) => {}
            Reading::Sdf3(reader) => reader.open(e),
            Reading::Tree(tree, _) => tree.open(e),
        }
    }

    fn close(&mut self, e: &mut Elem) {
        match self {
            Reading::Undecided(_) => {}
            Reading::Sdf3(reader) => reader.close(e),
            Reading::Tree(tree, _) => tree.close(e),
        }
    }

    fn text(&mut self, span: Span) {
        match self {
            Reading::Undecided(_) => {}
            Reading::Sdf3(reader) => reader.text(span),
            Reading::Tree(tree, _) => tree.text(span),
        }
    }
}

/// The format of a task-graph text, from its root element; `None` when the
/// first element is neither `<TaskGraph>` nor `<sdf3>` (or there is none).
pub fn detect_format(text: &str) -> Option<GraphFormat> {
    let mut reader = Reader::from_str(text);
    loop {
        match reader.read_event() {
            Ok(Event::Start(e) | Event::Empty(e)) => {
                return match e.local_name().as_ref() {
                    b"TaskGraph" => Some(GraphFormat::SemoXml),
                    b"sdf3" => Some(GraphFormat::Sdf3),
                    _ => None,
                };
            }
            Ok(Event::Eof) | Err(_) => return None,
            Ok(_) => {}
        }
    }
}

// ---------------------------------------------------------------------------
// Reading the tree as a graph.

/// Elements of our format, with where each belongs (for "not allowed here").
const SEMO_ELEMENTS: &[(&str, &str)] = &[
    (
        "TaskGraph",
        "at the top of the file or once inside `<Loop>`",
    ),
    ("Task", "inside `<TaskGraph>`"),
    ("Loop", "inside `<TaskGraph>`"),
    ("Library", "inside `<TaskGraph>`"),
    ("Channel", "inside `<TaskGraph>`"),
    ("Port", "inside `<Task>` or `<Loop>`"),
    ("LibraryMasterPort", "inside `<Task>`"),
    ("LibrarySlavePort", "inside `<Task>`"),
    ("MulticastPort", "inside `<Task>`"),
    ("Call", "inside `<LibraryMasterPort>`"),
    ("Function", "inside `<Library>`"),
    ("Param", "inside `<Function>`"),
];

const GRAPH_ATTRS: &[&str] = &["name"];
const TASK_ATTRS: &[&str] = &[
    "name", "kind", "trigger", "period", "wcet", "source", "subgraph",
];
const PORT_ATTRS: &[&str] = &["name", "dir", "rate", "type", "size"];
const LOOP_PORT_ATTRS: &[&str] = &[
    "name",
    "dir",
    "kind",
    "outerRate",
    "innerRate",
    "type",
    "size",
];
const MASTER_ATTRS: &[&str] = &["name", "library", "calls"];
const SLAVE_ATTRS: &[&str] = &["name", "library"];
const CALL_ATTRS: &[&str] = &["function"];
const MULTICAST_ATTRS: &[&str] = &["name", "dir", "group"];
const LIBRARY_ATTRS: &[&str] = &["name"];
const FUNCTION_ATTRS: &[&str] = &["name", "returns"];
const PARAM_ATTRS: &[&str] = &["name", "type"];
const LOOP_ATTRS: &[&str] = &["name", "type", "loopCount", "exitTask"];
const CHANNEL_ATTRS: &[&str] = &["src", "dst", "initialTokens", "capacity"];

/// Every element of our format with the attributes the reader accepts on it,
/// the very lists it checks with (a loop node's `<Port>` has its own), for
/// those who list the format: `docs/taskgraph.md` names each of them
/// (`compiler/tests/format_docs.rs`).
pub const SEMO_VOCABULARY: &[(&str, &[&str])] = &[
    ("TaskGraph", GRAPH_ATTRS),
    ("Task", TASK_ATTRS),
    ("Port", PORT_ATTRS),
    ("Port", LOOP_PORT_ATTRS),
    ("LibraryMasterPort", MASTER_ATTRS),
    ("LibrarySlavePort", SLAVE_ATTRS),
    ("Call", CALL_ATTRS),
    ("MulticastPort", MULTICAST_ATTRS),
    ("Library", LIBRARY_ATTRS),
    ("Function", FUNCTION_ATTRS),
    ("Param", PARAM_ATTRS),
    ("Loop", LOOP_ATTRS),
    ("Channel", CHANNEL_ATTRS),
];

/// The elements and attributes of an SDF3 file that the SDF3 readers read
/// (everything else is ignored silently), as [`sdf3::Role`] and the readers
/// take them: the root, the first `<applicationGraph>`, its first `<sdf>`
/// and first `<sdfProperties>`.
pub const SDF3_VOCABULARY: &[(&str, &[&str])] = &[
    ("sdf3", &["type"]),
    ("applicationGraph", &["name"]),
    ("sdf", &["name"]),
    ("actor", &["name"]),
    ("port", &["name", "type", "rate"]),
    (
        "channel",
        &[
            "srcActor",
            "srcPort",
            "dstActor",
            "dstPort",
            "initialTokens",
        ],
    ),
    ("sdfProperties", &[]),
    ("actorProperties", &["actor"]),
    ("processor", &["type", "default"]),
    ("executionTime", &["time"]),
];

/// Whether a whole number must be at least one.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Min {
    Zero,
    One,
}

/// One graph level while it is read.
#[derive(Default)]
struct LevelBuild {
    tasks: Vec<Task>,
    /// Per task: the names of its ports that were left out after an error.
    broken_ports: Vec<HashSet<SmolStr>>,
    /// Tasks and loops left out after an error (channels to them are dropped).
    broken_tasks: HashSet<SmolStr>,
    /// Inside a loop body: the enclosing loop's ports that were left out.
    enclosing_broken: HashSet<SmolStr>,
    task_names: HashMap<SmolStr, Span>,
    library_names: HashMap<SmolStr, Span>,
    libraries: Vec<Library>,
    channels: Vec<Channel>,
    /// For each kept channel, the ranges of the task and port parts of its ends.
    channel_parts: Vec<[(Span, Span); 2]>,
}

/// All the ports of one task (or loop node) while they are read.
#[derive(Default)]
struct PortsBuild {
    ports: Vec<Port>,
    library_ports: Vec<LibraryPort>,
    multicast_ports: Vec<MulticastPort>,
    names: HashMap<SmolStr, Span>,
    broken: HashSet<SmolStr>,
}

struct Loader<'s> {
    file: FileId,
    sink: &'s mut Sink,
    /// Reading SDF3: messages say "actor".
    sdf3: bool,
    times: ExecutionTimes,
}

impl Loader<'_> {
    // --- shared helpers ----------------------------------------------------

    fn vocabulary(&self) -> Vocabulary<'static> {
        Vocabulary {
            file: self.file,
            unknown_attribute: Code::GraphUnknownAttribute,
            unknown_element: Code::GraphUnknownElement,
            elements: SEMO_ELEMENTS,
        }
    }

    /// W060 for attributes that the element does not have.
    fn check_attributes(&mut self, e: &Elem, allowed: &[&str]) {
        // A loop node's port has an outer and an inner rate.
        let hint = |key: &str| {
            (key == "rate" && allowed.contains(&"outerRate")).then(|| "outerRate".to_string())
        };
        self.vocabulary()
            .check_attributes(self.sink, e, allowed, hint);
    }

    /// The child elements among `allowed`; E061 for the others and for text.
    fn children<'e>(&mut self, e: &'e Elem, allowed: &[&str]) -> Vec<&'e Elem> {
        self.vocabulary().children(self.sink, e, allowed)
    }

    /// A required attribute: E062 when missing, E065 when blank.
    fn required<'e>(&mut self, e: &'e Elem, key: &str) -> Option<&'e Attr> {
        match get(&e.attrs, key) {
            None => {
                let message = format!("`<{}>` needs a `{key}` attribute", e.local);
                self.sink
                    .report(Code::GraphMissingAttribute, e.tag, message);
                None
            }
            Some(a) if a.trimmed().is_empty() => {
                self.sink
                    .report(Code::GraphBadAttribute, a.span, format!("`{key}` is empty"));
                None
            }
            Some(a) => Some(a),
        }
    }

    /// A required name; E065 (but still returned) unless it is an identifier.
    fn name(&mut self, e: &Elem, key: &str) -> Option<Named> {
        let a = self.required(e, key)?;
        let named = Named {
            name: a.trimmed().into(),
            span: a.trimmed_span(),
        };
        self.check_ident(&named, key);
        Some(named)
    }

    fn check_ident(&mut self, named: &Named, key: &str) {
        if !is_ident(&named.name) {
            let message = format!(
                "`{key}` must be a name of letters, digits and `_`, not starting with a digit, not `{}`",
                shown(&named.name)
            );
            self.sink
                .report(Code::GraphBadAttribute, named.span, message);
        }
    }

    /// A whole number; E065 when it is not one (or is zero where at least one
    /// is needed). `Err(())` after a report.
    fn number(&mut self, a: &Attr, min: Min) -> Result<u64, ()> {
        let s = a.trimmed();
        let quoted = || shown(s);
        let parsed = if !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) {
            s.parse::<u64>().ok()
        } else {
            None
        };
        let what = match min {
            Min::Zero => "a whole number (0 or more)",
            Min::One => "a positive whole number",
        };
        match parsed {
            Some(n) if n >= 1 || min == Min::Zero => Ok(n),
            Some(_) => {
                let message = format!("`{}` must be {what}, not `{}`", a.key, quoted());
                self.sink
                    .report(Code::GraphBadAttribute, a.trimmed_span(), message);
                Err(())
            }
            None if !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) => {
                let message = format!("`{}` is too large: `{}`", a.key, quoted());
                self.sink
                    .report(Code::GraphBadAttribute, a.trimmed_span(), message);
                Err(())
            }
            None => {
                let message = format!("`{}` must be {what}, not `{}`", a.key, quoted());
                self.sink.report(Code::GraphBadAttribute, a.span, message);
                Err(())
            }
        }
    }

    /// An optional whole number: `Ok(None)` when absent.
    fn opt_number(&mut self, e: &Elem, key: &str, min: Min) -> Result<Option<u64>, ()> {
        match get(&e.attrs, key) {
            None => Ok(None),
            Some(a) => self.number(a, min).map(Some),
        }
    }

    /// One of a few words; E065 with a did-you-mean otherwise.
    fn choice<'o>(&mut self, a: &Attr, options: &[&'o str]) -> Option<&'o str> {
        let s = a.trimmed();
        if let Some(o) = options.iter().find(|o| **o == s) {
            return Some(o);
        }
        let list = match options {
            [] => String::new(),
            [one] => format!("`{one}`"),
            [init @ .., last] => format!(
                "{} or `{last}`",
                init.iter()
                    .map(|o| format!("`{o}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        let message = format!("`{}` must be {list}, not `{}`", a.key, shown(s));
        self.sink
            .report(Code::GraphBadAttribute, a.span, message)
            .suggest(suggest(s, options));
        None
    }

    /// `dir`: required, `in` or `out`.
    fn direction(&mut self, e: &Elem) -> Option<Direction> {
        let a = self.required(e, "dir")?;
        match self.choice(a, &["in", "out"])? {
            "in" => Some(Direction::In),
            _ => Some(Direction::Out),
        }
    }

    /// E063 unless `named` is new in `names` (the message is made only then).
    fn register(
        &mut self,
        names: &mut HashMap<SmolStr, Span>,
        named: &Named,
        message: impl FnOnce() -> String,
    ) -> bool {
        if let Some(first) = names.get(named.name.as_str()) {
            let first = *first;
            self.sink
                .report(Code::GraphDuplicateName, named.span, message())
                .relate(first, "first defined here");
            return false;
        }
        names.insert(named.name.clone(), named.span);
        true
    }

    // --- our format ----------------------------------------------------------

    fn semo_root(&mut self, root: &Elem) -> TaskGraph {
        self.graph(root, None, HashSet::default())
    }

    /// One `<TaskGraph>`: the outer one, or a loop body (`enclosing` is then the
    /// loop node, with its ports, and `enclosing_broken` the names of its ports
    /// that were left out).
    fn graph(
        &mut self,
        e: &Elem,
        enclosing: Option<&Task>,
        enclosing_broken: HashSet<SmolStr>,
    ) -> TaskGraph {
        self.check_attributes(e, GRAPH_ATTRS);
        let name = match enclosing {
            None => self
                .required(e, "name")
                .map(|a| a.trimmed().to_string())
                .unwrap_or_default(),
            Some(l) => get(&e.attrs, "name")
                .map(|a| a.trimmed().to_string())
                .filter(|n| !n.is_empty())
                .unwrap_or_else(|| format!("{}_body", l.name.name)),
        };
        let mut level = LevelBuild {
            enclosing_broken,
            ..LevelBuild::default()
        };
        if let Some(l) = enclosing {
            level.task_names.insert(l.name.name.clone(), l.name.span);
        }
        let children = self.children(e, &["Task", "Loop", "Library", "Channel"]);
        for c in children {
            match c.local.as_str() {
                "Task" => {
                    if let Some((task, broken)) = self.task(c) {
                        self.add_task(&mut level, task, broken, enclosing);
                    }
                }
                "Loop" => match self.loop_node(c) {
                    LoopRead::Kept(task, broken) => {
                        self.add_task(&mut level, *task, broken, enclosing)
                    }
                    LoopRead::Broken(Some(name)) => {
                        level.broken_tasks.insert(name);
                    }
                    LoopRead::Broken(None) => {}
                },
                "Library" => {
                    if let Some(lib) = self.library(c) {
                        let message = format!(
                            "library `{}` is already defined in this graph",
                            lib.name.name
                        );
                        let mut names = std::mem::take(&mut level.library_names);
                        if self.register(&mut names, &lib.name, || message) {
                            level.libraries.push(lib);
                        }
                        level.library_names = names;
                    }
                }
                _ => {
                    if let Some((channel, parts)) = self.channel(c) {
                        level.channels.push(channel);
                        level.channel_parts.push(parts);
                    }
                }
            }
        }
        if e.complete {
            self.check_channels(&level, enclosing);
        }
        TaskGraph {
            name,
            file: self.file,
            span: e.span,
            tasks: level.tasks,
            channels: level.channels,
            libraries: level.libraries,
        }
    }

    fn add_task(
        &mut self,
        level: &mut LevelBuild,
        task: Task,
        broken: HashSet<SmolStr>,
        enclosing: Option<&Task>,
    ) {
        let what = if task.kind == TaskKind::Loop {
            "loop"
        } else {
            "task"
        };
        let message = match enclosing {
            Some(l) if l.name.name == task.name.name => format!(
                "`{}` is the name of the enclosing loop: give this {what} another name",
                task.name.name
            ),
            _ => format!(
                "a task or loop named `{}` is already defined in this graph",
                task.name.name
            ),
        };
        let mut names = std::mem::take(&mut level.task_names);
        if self.register(&mut names, &task.name, || message) {
            level.tasks.push(task);
            level.broken_ports.push(broken);
        }
        level.task_names = names;
    }

    /// A `<Task>`: `None` without a usable name. Also returns the names of the
    /// ports that were left out.
    fn task(&mut self, e: &Elem) -> Option<(Task, HashSet<SmolStr>)> {
        self.check_attributes(e, TASK_ATTRS);
        let name = self.name(e, "name");
        let kind = match get(&e.attrs, "kind") {
            None => TaskKind::Computational,
            Some(a) if a.trimmed() == "loop" => {
                self.sink.report(
                    Code::GraphBadAttribute,
                    a.span,
                    "a loop node is written as a `<Loop>` element, not kind=\"loop\"",
                );
                TaskKind::Computational
            }
            Some(a) => match self.choice(a, &["computational", "control", "library"]) {
                Some("control") => TaskKind::Control,
                Some("library") => TaskKind::Library,
                _ => TaskKind::Computational,
            },
        };
        let trigger = self.trigger(e);
        let wcet = self.opt_number(e, "wcet", Min::Zero).unwrap_or(None);
        let source = get(&e.attrs, "source").map(|a| a.trimmed().to_string());
        let subgraph = get(&e.attrs, "subgraph").map(|a| Named {
            name: a.trimmed().into(),
            span: a.trimmed_span(),
        });
        let children = self.children(
            e,
            &[
                "Port",
                "LibraryMasterPort",
                "LibrarySlavePort",
                "MulticastPort",
            ],
        );
        let ports = self.ports(&children, false);
        let name = name?;
        Some((
            Task {
                name,
                span: e.span,
                kind,
                trigger,
                wcet,
                source,
                subgraph,
                ports: ports.ports,
                library_ports: ports.library_ports,
                multicast_ports: ports.multicast_ports,
                loop_node: None,
            },
            ports.broken,
        ))
    }

    /// `trigger` and `period`.
    fn trigger(&mut self, e: &Elem) -> Trigger {
        let trigger = match get(&e.attrs, "trigger") {
            None => Some("data"),
            Some(a) => self.choice(a, &["time", "data", "control"]),
        };
        let period = get(&e.attrs, "period");
        match (trigger, period) {
            (Some("time"), None) => {
                self.sink.report(
                    Code::GraphMissingAttribute,
                    e.tag,
                    "a time-triggered `<Task>` needs a `period`, like period=\"100 MSEC\"",
                );
                Trigger::Data
            }
            (Some("time"), Some(p)) => match self.period(p) {
                Some(period_ms) => Trigger::Time { period_ms },
                None => Trigger::Data,
            },
            (other, period) => {
                if let (Some(p), Some(t)) = (period, other) {
                    let message = format!(
                        "`period` is only for trigger=\"time\", and this task's trigger is `{t}`"
                    );
                    self.sink.report(Code::GraphBadAttribute, p.span, message);
                }
                match other {
                    Some("control") => Trigger::Control,
                    _ => Trigger::Data,
                }
            }
        }
    }

    /// `N UNIT` (`33 MSEC`, `1 SEC`) in milliseconds.
    fn period(&mut self, a: &Attr) -> Option<f64> {
        let words: Vec<&str> = a.value.split_whitespace().collect();
        let parsed = match words.as_slice() {
            [amount, unit] => {
                let number = amount.bytes().all(|b| b.is_ascii_digit() || b == b'.')
                    && amount.bytes().any(|b| b.is_ascii_digit());
                match (
                    number.then(|| amount.parse::<f64>().ok()).flatten(),
                    TimeUnit::parse(unit),
                ) {
                    (Some(n), Some(u)) if n > 0.0 && n.is_finite() => Some(n * u.millis()),
                    _ => None,
                }
            }
            _ => None,
        };
        if parsed.is_none() {
            let message = format!(
                "`period` must be a positive number and a unit (MSEC, SEC, MIN or HOUR), like \"100 MSEC\", not `{}`",
                shown(a.trimmed())
            );
            self.sink.report(Code::GraphBadAttribute, a.span, message);
        }
        parsed
    }

    /// The ports of a task (`in_loop` false) or loop node (`in_loop` true).
    fn ports(&mut self, children: &[&Elem], in_loop: bool) -> PortsBuild {
        let mut build = PortsBuild::default();
        for c in children {
            match c.local.as_str() {
                "Port" => self.data_port(c, in_loop, &mut build),
                "LibraryMasterPort" | "LibrarySlavePort" => self.library_port(c, &mut build),
                "MulticastPort" => self.multicast_port(c, &mut build),
                _ => {}
            }
        }
        build
    }

    /// Registers a port name in its task; `false` (after E063) for a second one.
    fn register_port(&mut self, build: &mut PortsBuild, name: &Named) -> bool {
        let what = if self.sdf3 { "actor" } else { "task" };
        let message = || format!("this {what} already has a port named `{}`", name.name);
        let mut names = std::mem::take(&mut build.names);
        let fresh = self.register(&mut names, name, message);
        build.names = names;
        fresh
    }

    fn data_port(&mut self, e: &Elem, in_loop: bool, build: &mut PortsBuild) {
        self.check_attributes(e, if in_loop { LOOP_PORT_ATTRS } else { PORT_ATTRS });
        let name = self.name(e, "name");
        let dir = self.direction(e);
        let rate_key = if in_loop { "outerRate" } else { "rate" };
        let rate_attr = get(&e.attrs, rate_key);
        let rate = self.opt_number(e, rate_key, Min::One);
        let inner_rate = if in_loop {
            self.opt_number(e, "innerRate", Min::One)
                .map(|r| Some(r.unwrap_or(1)))
        } else {
            Ok(None)
        };
        let kind = match (in_loop, get(&e.attrs, "kind")) {
            (true, Some(a)) => match self.choice(a, &["distributing", "broadcasting"]) {
                Some(_) if dir == Some(Direction::Out) => {
                    self.sink.report(
                        Code::GraphBadAttribute,
                        a.span,
                        "`kind` is only for input ports: an output port of a loop has no kind",
                    );
                    None
                }
                Some("distributing") => Some(PortKind::Distributing),
                Some(_) => Some(PortKind::Broadcasting),
                None => None,
            },
            _ => None,
        };
        let sample_type = get(&e.attrs, "type")
            .map(|a| a.trimmed().to_string())
            .filter(|t| !t.is_empty());
        let size = self.opt_number(e, "size", Min::Zero).unwrap_or(None);
        let Some(name) = name else {
            return;
        };
        if !self.register_port(build, &name) {
            return;
        }
        let (Some(dir), Ok(rate), Ok(inner_rate)) = (dir, rate, inner_rate) else {
            build.broken.insert(name.name);
            return;
        };
        build.ports.push(Port {
            name,
            span: e.span,
            dir,
            rate: rate.unwrap_or(1),
            rate_span: rate_attr.map(Attr::trimmed_span),
            sample_type,
            size,
            kind,
            inner_rate,
        });
    }

    fn library_port(&mut self, e: &Elem, build: &mut PortsBuild) {
        let master = e.local == "LibraryMasterPort";
        self.check_attributes(e, if master { MASTER_ATTRS } else { SLAVE_ATTRS });
        let name = self.name(e, "name");
        let library = self.name(e, "library");
        let mut calls = Vec::new();
        if master {
            if let Some(a) = get(&e.attrs, "calls") {
                for (word, span) in a.words() {
                    let named = Named {
                        name: word.into(),
                        span,
                    };
                    self.check_ident(&named, "calls");
                    calls.push(named);
                }
            }
        }
        let children = self.children(e, if master { &["Call"] } else { &[] });
        for c in children {
            self.check_attributes(c, CALL_ATTRS);
            self.children(c, &[]);
            if let Some(f) = self.name(c, "function") {
                calls.push(f);
            }
        }
        let (Some(name), Some(library)) = (name, library) else {
            if let Some(name) = self.name_silently(e) {
                if self.register_port(build, &name) {
                    build.broken.insert(name.name);
                }
            }
            return;
        };
        if !self.register_port(build, &name) {
            return;
        }
        build.library_ports.push(LibraryPort {
            name,
            span: e.span,
            library,
            master,
            calls,
        });
    }

    /// The `name` attribute without any report (already made).
    fn name_silently(&self, e: &Elem) -> Option<Named> {
        get(&e.attrs, "name")
            .filter(|a| !a.trimmed().is_empty())
            .map(|a| Named {
                name: a.trimmed().into(),
                span: a.trimmed_span(),
            })
    }

    fn multicast_port(&mut self, e: &Elem, build: &mut PortsBuild) {
        self.check_attributes(e, MULTICAST_ATTRS);
        self.children(e, &[]);
        let name = self.name(e, "name");
        let dir = self.direction(e);
        let group = self.required(e, "group").map(|a| Named {
            name: a.trimmed().into(),
            span: a.trimmed_span(),
        });
        let Some(name) = name else {
            return;
        };
        if !self.register_port(build, &name) {
            return;
        }
        let (Some(dir), Some(group)) = (dir, group) else {
            build.broken.insert(name.name);
            return;
        };
        build.multicast_ports.push(MulticastPort {
            name,
            span: e.span,
            dir,
            group,
        });
    }

    fn library(&mut self, e: &Elem) -> Option<Library> {
        self.check_attributes(e, LIBRARY_ATTRS);
        let name = self.name(e, "name");
        let mut functions = Vec::new();
        let mut names = HashMap::default();
        for f in self.children(e, &["Function"]) {
            self.check_attributes(f, FUNCTION_ATTRS);
            let fname = self.name(f, "name");
            let returns = get(&f.attrs, "returns")
                .map(|a| a.trimmed().to_string())
                .filter(|r| !r.is_empty());
            let mut params = Vec::new();
            let mut param_names = HashMap::default();
            for p in self.children(f, &["Param"]) {
                self.check_attributes(p, PARAM_ATTRS);
                self.children(p, &[]);
                let pname = self.name(p, "name");
                let ty = self.required(p, "type").map(|a| a.trimmed().to_string());
                let (Some(pname), Some(ty)) = (pname, ty) else {
                    continue;
                };
                let message = format!("this function already has a parameter `{}`", pname.name);
                if self.register(&mut param_names, &pname, || message) {
                    params.push((pname.name.to_string(), ty));
                }
            }
            let Some(fname) = fname else {
                continue;
            };
            let message = format!("this library already has a function `{}`", fname.name);
            if self.register(&mut names, &fname, || message) {
                functions.push(LibraryFunction {
                    name: fname,
                    returns,
                    params,
                });
            }
        }
        Some(Library {
            name: name?,
            span: e.span,
            functions,
        })
    }

    fn loop_node(&mut self, e: &Elem) -> LoopRead {
        self.check_attributes(e, LOOP_ATTRS);
        let name = self.name(e, "name");
        let loop_type = self.required(e, "type").and_then(|a| {
            self.choice(a, &["D", "C"]).map(|t| match t {
                "D" => LoopType::D,
                _ => LoopType::C,
            })
        });
        let loop_count = self
            .required(e, "loopCount")
            .and_then(|a| self.number(a, Min::One).ok());
        let exit_task = get(&e.attrs, "exitTask").map(|a| Named {
            name: a.trimmed().into(),
            span: a.trimmed_span(),
        });
        let children = self.children(e, &["Port", "TaskGraph"]);
        let port_children: Vec<&Elem> = children
            .iter()
            .copied()
            .filter(|c| c.local == "Port")
            .collect();
        let ports = self.ports(&port_children, true);
        let mut bodies = children.iter().filter(|c| c.local == "TaskGraph");
        let body = bodies.next();
        for extra in bodies {
            self.sink.report(
                Code::GraphUnknownElement,
                extra.name_span,
                "a `<Loop>` has a single inner `<TaskGraph>`: this second one is ignored",
            );
        }
        let mut task = Task {
            name: name.clone().unwrap_or(Named {
                name: Default::default(),
                span: e.tag,
            }),
            span: e.span,
            kind: TaskKind::Loop,
            trigger: Trigger::Data,
            wcet: None,
            source: None,
            subgraph: None,
            ports: ports.ports,
            library_ports: Vec::new(),
            multicast_ports: Vec::new(),
            loop_node: None,
        };
        let body = match body {
            Some(b) => self.graph(b, Some(&task), ports.broken.clone()),
            None => {
                if e.complete {
                    self.sink.report(
                        Code::GraphMissingAttribute,
                        e.tag,
                        "this `<Loop>` needs an inner `<TaskGraph>` with its body",
                    );
                }
                TaskGraph {
                    name: format!("{}_body", task.name.name),
                    file: self.file,
                    span: e.span,
                    tasks: Vec::new(),
                    channels: Vec::new(),
                    libraries: Vec::new(),
                }
            }
        };
        let (Some(name), Some(loop_type), Some(loop_count)) = (name, loop_type, loop_count) else {
            return LoopRead::Broken(self.name_silently(e).map(|n| n.name));
        };
        task.name = name;
        task.loop_node = Some(Box::new(LoopNode {
            loop_type,
            loop_count,
            exit_task,
            body,
        }));
        LoopRead::Kept(Box::new(task), ports.broken)
    }

    /// A `<Channel>` with well-formed ends, and the ranges of the parts of
    /// each end (task, port).
    fn channel(&mut self, e: &Elem) -> Option<(Channel, [(Span, Span); 2])> {
        self.check_attributes(e, CHANNEL_ATTRS);
        self.children(e, &[]);
        let src = self.endpoint(e, "src");
        let dst = self.endpoint(e, "dst");
        let initial_tokens = self.opt_number(e, "initialTokens", Min::Zero);
        let capacity = self.opt_number(e, "capacity", Min::One).unwrap_or(None);
        let ((src, src_parts), (dst, dst_parts), Ok(initial_tokens)) = (src?, dst?, initial_tokens)
        else {
            return None;
        };
        Some((
            Channel {
                src,
                dst,
                initial_tokens: initial_tokens.unwrap_or(0),
                capacity,
                span: e.span,
            },
            [src_parts, dst_parts],
        ))
    }

    /// `task.port`.
    fn endpoint(&mut self, e: &Elem, key: &str) -> Option<(Endpoint, (Span, Span))> {
        let a = self.required(e, key)?;
        let value = a.trimmed();
        let lead = a.value.len() - a.value.trim_start().len();
        let well_formed = value.split_once('.').filter(|(t, p)| {
            let ok =
                |s: &str| !s.is_empty() && !s.contains(|c: char| c.is_whitespace() || c == '.');
            ok(t) && ok(p)
        });
        let Some((task, port)) = well_formed else {
            let message = format!(
                "`{key}` must be written task.port, like \"camera.out\", not `{}`",
                shown(value)
            );
            self.sink.report(Code::GraphBadAttribute, a.span, message);
            return None;
        };
        let task_span = a.sub_span(lead, lead + task.len());
        let port_start = lead + task.len() + 1;
        let port_span = a.sub_span(port_start, port_start + port.len());
        Some((
            Endpoint {
                task: task.into(),
                port: port.into(),
                span: a.trimmed_span(),
            },
            (task_span, port_span),
        ))
    }

    /// E064 and E066 for the channels of one level.
    fn check_channels(&mut self, level: &LevelBuild, enclosing: Option<&Task>) {
        // Looked up twice per channel: an index keeps large graphs linear.
        let index: HashMap<&str, usize> = level
            .tasks
            .iter()
            .enumerate()
            .map(|(i, t)| (t.name.name.as_str(), i))
            .collect();
        // Per port joined so far: the channel end that joined it first.
        let mut joined: HashMap<(&str, &str), Span> = HashMap::default();
        for (c, parts) in level.channels.iter().zip(&level.channel_parts) {
            for (end, part, want) in [
                (&c.src, parts[0], Direction::Out),
                (&c.dst, parts[1], Direction::In),
            ] {
                if self.check_end(level, &index, enclosing, end, part, want) {
                    self.check_joined_once(&mut joined, end);
                }
            }
        }
    }

    /// E098 on a channel end at a port that an earlier channel of the level
    /// already joins: a port is the end of one channel (a sample goes to one
    /// consumer; the analyses and the build read one channel per port).
    fn check_joined_once<'e>(
        &mut self,
        joined: &mut HashMap<(&'e str, &'e str), Span>,
        end: &'e Endpoint,
    ) {
        use std::collections::hash_map::Entry;
        let first = match joined.entry((end.task.as_str(), end.port.as_str())) {
            Entry::Vacant(slot) => {
                slot.insert(end.span);
                return;
            }
            Entry::Occupied(slot) => *slot.get(),
        };
        let what = if self.sdf3 { "actor port" } else { "port" };
        let message = format!(
            "{what} `{}.{}` is already joined by another channel: a port is the end of one channel (give each channel its own port)",
            end.task, end.port
        );
        self.sink
            .report(Code::GraphPortTwoChannels, end.span, message)
            .relate(first, "the channel that joins it first");
    }

    /// One end of a channel; `want` is the direction of the port at a task
    /// (the enclosing loop's ports are seen from the inside: reversed).
    /// Whether the end is a port of the right direction.
    fn check_end(
        &mut self,
        level: &LevelBuild,
        index: &HashMap<&str, usize>,
        enclosing: Option<&Task>,
        end: &Endpoint,
        (task_span, port_span): (Span, Span),
        want: Direction,
    ) -> bool {
        if level.broken_tasks.contains(end.task.as_str()) {
            return false;
        }
        let (task, broken, inside) = match (index.get(end.task.as_str()).copied(), enclosing) {
            (Some(i), _) => (&level.tasks[i], Some(&level.broken_ports[i]), false),
            (None, Some(l)) if l.name.name == end.task => (l, Some(&level.enclosing_broken), true),
            _ => {
                let candidates = level
                    .tasks
                    .iter()
                    .map(|t| t.name.name.as_str())
                    .chain(enclosing.map(|l| l.name.name.as_str()));
                let what = if self.sdf3 { "actor" } else { "task or loop" };
                let message = format!("no {what} named `{}` in this graph", end.task);
                self.sink
                    .report(Code::GraphUnknownEndpoint, task_span, message)
                    .suggest(did_you_mean(&end.task, candidates));
                return false;
            }
        };
        if broken.is_some_and(|b| b.contains(end.port.as_str())) {
            return false;
        }
        let Some(port) = task.port(&end.port) else {
            let what = match (inside, self.sdf3) {
                (true, _) => "the enclosing loop",
                (false, true) => "actor",
                (false, false) => "task",
            };
            let other = task
                .library_ports
                .iter()
                .find(|p| p.name.name == end.port)
                .map(|_| "a library port")
                .or_else(|| {
                    task.multicast_ports
                        .iter()
                        .any(|p| p.name.name == end.port)
                        .then_some("a multicast port")
                });
            let message = match other {
                Some(kind) => format!(
                    "`{}.{}` is {kind}: channels join data ports only",
                    end.task, end.port
                ),
                None => format!("{what} `{}` has no port `{}`", end.task, end.port),
            };
            let candidates = task.ports.iter().map(|p| p.name.name.as_str());
            let suggestion = match other {
                Some(_) => None,
                None => did_you_mean(&end.port, candidates),
            };
            self.sink
                .report(Code::GraphUnknownEndpoint, port_span, message)
                .suggest(suggestion);
            return false;
        };
        let needed = if inside { flip(want) } else { want };
        if port.dir == needed {
            return true;
        }
        let message = match (inside, want) {
            (false, Direction::Out) => format!(
                "`{}.{}` is an input port: a channel must start at an output port",
                end.task, end.port
            ),
            (false, Direction::In) => format!(
                "`{}.{}` is an output port: a channel must end at an input port",
                end.task, end.port
            ),
            (true, Direction::Out) => format!(
                "`{}.{}` is an output of the enclosing loop: inside its body a channel can only end there",
                end.task, end.port
            ),
            (true, Direction::In) => format!(
                "`{}.{}` is an input of the enclosing loop: inside its body a channel can only start there",
                end.task, end.port
            ),
        };
        let span = Span::new(
            task_span.start.min(port_span.start),
            port_span.end.max(task_span.end),
        );
        self.sink
            .report(Code::GraphPortDirection, span, message)
            .relate(port.name.span, "the port is declared here");
        false
    }
}

enum LoopRead {
    /// The loop node (a task of kind `Loop`) and its left-out port names.
    Kept(Box<Task>, HashSet<SmolStr>),
    /// Left out after an error; its name, if it has one.
    Broken(Option<SmolStr>),
}

fn flip(d: Direction) -> Direction {
    match d {
        Direction::In => Direction::Out,
        Direction::Out => Direction::In,
    }
}

mod sdf3;
mod sdf3_clean;
mod tags;
#[cfg(test)]
mod tests;
