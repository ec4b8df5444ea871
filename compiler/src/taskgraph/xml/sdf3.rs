//! Reading an SDF3 graph as its elements come ([`crate::xmltree::walk`]),
//! without the element tree: SDF3 files are large (a 20,000-actor graph is
//! 8.5 MB of XML), and building the tree was most of the time of analysing
//! one. What is kept is only what the graph needs: the actor, port and
//! channel being read, and per `<actorProperties>` its processors.
//!
//! The reading is SDF3's format as [`super`] describes it: the first
//! `<applicationGraph>` of the root, its first `<sdf>` (actors, ports,
//! channels) and its first `<sdfProperties>` (each actor's execution time,
//! chosen as [`ExecutionTimes`] says); every other element is ignored
//! silently. Properties may come before or after the graph: times are given
//! to the actors at the end.

use super::{ExecutionTimes, LevelBuild, Loader, Min, PortsBuild};
use crate::diag::Code;
use crate::fasthash::FastMap as HashMap;
use crate::span::Span;
use crate::taskgraph::model::*;
use crate::xmlpos::{Attr, get, shown};
use crate::xmltree::{Elem, Visit};

/// What an open element is to the graph (both readers of SDF3 files use it:
/// this one and [`super::sdf3_clean`]).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Role {
    Root,
    ApplicationGraph,
    Sdf,
    Actor,
    Port,
    Channel,
    Properties,
    ActorProperties,
    Processor,
    ExecutionTime,
    /// Not read, nor anything inside it.
    Ignored,
}

impl Role {
    /// The role of an element named `local` inside one of this role. The
    /// graph reads only the first `<applicationGraph>`, `<sdf>` and
    /// `<sdfProperties>`: `first(role)` says whether one of that role may
    /// still open (a later one is ignored).
    pub(super) fn child(self, local: &[u8], first: impl Fn(Role) -> bool) -> Role {
        let once = |role| if first(role) { role } else { Role::Ignored };
        match (self, local) {
            (Role::Root, b"applicationGraph") => once(Role::ApplicationGraph),
            (Role::ApplicationGraph, b"sdf") => once(Role::Sdf),
            (Role::ApplicationGraph, b"sdfProperties") => once(Role::Properties),
            (Role::Sdf, b"actor") => Role::Actor,
            (Role::Sdf, b"channel") => Role::Channel,
            (Role::Actor, b"port") => Role::Port,
            (Role::Properties, b"actorProperties") => Role::ActorProperties,
            (Role::ActorProperties, b"processor") => Role::Processor,
            (Role::Processor, b"executionTime") => Role::ExecutionTime,
            _ => Role::Ignored,
        }
    }
}

/// One `<processor>` of the `<actorProperties>` being read.
struct Processor {
    /// `type`, trimmed.
    kind: Option<String>,
    /// `default`, trimmed, and where it is written.
    default: Option<(String, Span)>,
    /// The `time` of its first `<executionTime>` (`None` inside when that
    /// one has no `time`).
    time: Option<Option<Attr>>,
}

/// The [`Visit`] that reads an SDF3 graph.
pub(super) struct Sdf3Reader<'s> {
    loader: Loader<'s>,
    /// The roles of the open elements, outermost first.
    open: Vec<Role>,
    /// The root's `type` is not `sdf`: nothing is read.
    other_type: bool,
    root_tag: Span,
    root_complete: bool,
    application_graph_seen: bool,
    application_graph_name: Option<String>,
    properties_seen: bool,
    /// The graph element `<sdf>`: its `name`, range and whether it was closed.
    sdf: Option<(Option<String>, Span, bool)>,
    level: LevelBuild,
    /// The ports of the actor being read.
    ports: PortsBuild,
    /// The processors of the `<actorProperties>` being read.
    processors: Vec<Processor>,
    times: HashMap<String, u64>,
}

impl<'s> Sdf3Reader<'s> {
    /// Whether an element of a read-once `role` is the first of its kind.
    fn first(&self, role: Role) -> bool {
        match role {
            Role::ApplicationGraph => !self.application_graph_seen,
            Role::Sdf => self.sdf.is_none(),
            Role::Properties => !self.properties_seen,
            _ => true,
        }
    }

    pub(super) fn new(loader: Loader<'s>) -> Self {
        Sdf3Reader {
            loader,
            open: Vec::new(),
            other_type: false,
            root_tag: Span::default(),
            root_complete: false,
            application_graph_seen: false,
            application_graph_name: None,
            properties_seen: false,
            sdf: None,
            level: LevelBuild::default(),
            ports: PortsBuild::default(),
            processors: Vec::new(),
            times: HashMap::default(),
        }
    }

    /// The graph read; `None` for another type of SDF3 graph or a file
    /// without `<sdf>`.
    pub(super) fn finish(mut self) -> Option<TaskGraph> {
        if self.other_type {
            return None;
        }
        let Some((name, span, complete)) = self.sdf.take() else {
            if self.root_complete {
                self.loader.sink.report(
                    Code::GraphMissingAttribute,
                    self.root_tag,
                    "this SDF3 file has no graph: it needs `<applicationGraph>` with an `<sdf>` element",
                );
            }
            return None;
        };
        if complete {
            self.loader.check_channels(&self.level, None);
        }
        let mut tasks = self.level.tasks;
        for task in &mut tasks {
            task.wcet = self.times.get(task.name.name.as_str()).copied();
        }
        Some(TaskGraph {
            name: name.or(self.application_graph_name).unwrap_or_default(),
            file: self.loader.file,
            span,
            tasks,
            channels: self.level.channels,
            libraries: Vec::new(),
        })
    }

    /// The root `<sdf3>`: only `type="sdf"` graphs are read.
    fn root(&mut self, e: &Elem) {
        self.root_tag = e.tag;
        match get(&e.attrs, "type") {
            None => {
                self.loader.sink.report(
                    Code::GraphMissingAttribute,
                    e.tag,
                    "`<sdf3>` needs a `type` attribute: only type=\"sdf\" graphs are read",
                );
            }
            Some(a) if a.trimmed() != "sdf" => {
                let message = format!(
                    "only SDF3 graphs of type=\"sdf\" can be read, not `{}`",
                    shown(a.trimmed())
                );
                self.loader
                    .sink
                    .report(Code::GraphBadAttribute, a.span, message);
                self.other_type = true;
            }
            Some(_) => {}
        }
    }

    fn actor(&mut self, e: &Elem) {
        let name = self.loader.required(e, "name").map(named);
        let ports = std::mem::take(&mut self.ports);
        let Some(name) = name else {
            return;
        };
        let message = || format!("actor `{}` is already defined", name.name);
        let mut names = std::mem::take(&mut self.level.task_names);
        if self.loader.register(&mut names, &name, message) {
            self.level.tasks.push(Task {
                wcet: None,
                name,
                span: e.span,
                kind: TaskKind::Computational,
                trigger: Trigger::Data,
                source: None,
                subgraph: None,
                ports: ports.ports,
                library_ports: Vec::new(),
                multicast_ports: Vec::new(),
                loop_node: None,
            });
            self.level.broken_ports.push(ports.broken);
        }
        self.level.task_names = names;
    }

    fn port(&mut self, p: &Elem) {
        let loader = &mut self.loader;
        let name = loader.required(p, "name").map(named);
        let dir = loader.required(p, "type").and_then(|a| {
            loader.choice(a, &["in", "out"]).map(|d| match d {
                "in" => Direction::In,
                _ => Direction::Out,
            })
        });
        let rate_attr = get(&p.attrs, "rate");
        let rate = loader.opt_number(p, "rate", Min::One);
        let Some(name) = name else {
            return;
        };
        if !loader.register_port(&mut self.ports, &name) {
            return;
        }
        let (Some(dir), Ok(rate)) = (dir, rate) else {
            self.ports.broken.insert(name.name);
            return;
        };
        self.ports.ports.push(Port {
            name,
            span: p.span,
            dir,
            rate: rate.unwrap_or(1),
            rate_span: rate_attr.map(Attr::trimmed_span),
            sample_type: None,
            size: None,
            kind: None,
            inner_rate: None,
        });
    }

    fn channel(&mut self, e: &Elem) {
        let loader = &mut self.loader;
        let mut end = |actor: &str, port: &str| -> Option<(Endpoint, (Span, Span))> {
            let a = loader.required(e, actor);
            let p = loader.required(e, port);
            let (a, p) = (a?, p?);
            let (a_span, p_span) = (a.trimmed_span(), p.trimmed_span());
            Some((
                Endpoint {
                    task: a.trimmed().into(),
                    port: p.trimmed().into(),
                    span: a_span.cover(p_span),
                },
                (a_span, p_span),
            ))
        };
        let src = end("srcActor", "srcPort");
        let dst = end("dstActor", "dstPort");
        let initial_tokens = self.loader.opt_number(e, "initialTokens", Min::Zero);
        let (Some((src, src_parts)), Some((dst, dst_parts)), Ok(initial_tokens)) =
            (src, dst, initial_tokens)
        else {
            return;
        };
        self.level.channels.push(Channel {
            src,
            dst,
            initial_tokens: initial_tokens.unwrap_or(0),
            capacity: None,
            span: e.span,
        });
        self.level.channel_parts.push([src_parts, dst_parts]);
    }

    /// W086 on each processor of `actor` marked `default="true"` after the
    /// first: which one's time is the actor's is then a matter of reading
    /// (SDF3's own benchmarks `h263encoder` and the mp3 decoders have such
    /// actors, and their periods differ by the reading).
    fn check_one_default(&mut self, actor: &str, processors: &[Processor]) {
        let mut defaults = processors.iter().filter(|p| p.is_default());
        let Some(first) = defaults.next() else {
            return;
        };
        let kind = |p: &Processor| p.kind.clone().unwrap_or_default();
        for other in defaults {
            let Some((_, span)) = &other.default else {
                continue;
            };
            let message = format!(
                "actor `{actor}` has a second processor marked default=\"true\" (`{}`, after `{}`): semo takes the first one's time, --sdf3-compat the time SDF3 takes (of the last one marked default)",
                shown(&kind(other)),
                shown(&kind(first)),
            );
            let diagnostic =
                self.loader
                    .sink
                    .report(Code::Sdf3TwoDefaultProcessors, *span, message);
            if let Some((_, first_span)) = &first.default {
                diagnostic.relate(*first_span, "the first processor marked default");
            }
        }
    }

    /// The end of an `<actorProperties>`: its actor's time, from the
    /// processor [`ExecutionTimes`] chooses (the first entry for an actor
    /// counts).
    fn actor_properties(&mut self, e: &Elem) {
        let processors = std::mem::take(&mut self.processors);
        let Some(actor) = get(&e.attrs, "actor") else {
            return;
        };
        self.check_one_default(actor.trimmed(), &processors);
        let chosen = match self.loader.times {
            ExecutionTimes::FileDefault => processors
                .iter()
                .find(|p| p.is_default())
                .or(processors.first()),
            ExecutionTimes::Sdf3Compat => {
                // SDF3 keeps the type of the last processor marked `default`
                // and then takes the first entry of that type.
                let last = processors.iter().rev().find(|p| p.default.is_some());
                last.and_then(|l| l.kind.as_ref())
                    .and_then(|kind| processors.iter().find(|p| p.kind.as_ref() == Some(kind)))
            }
        };
        let time = chosen
            .and_then(|p| p.time.as_ref())
            .and_then(Option::as_ref);
        if let Some(time) = time {
            if let Ok(n) = self.loader.number(time, Min::Zero) {
                self.times.entry(actor.trimmed().to_string()).or_insert(n);
            }
        }
    }
}

impl Processor {
    fn is_default(&self) -> bool {
        self.default
            .as_ref()
            .is_some_and(|(value, _)| value == "true")
    }
}

fn named(a: &Attr) -> Named {
    Named {
        name: a.trimmed().into(),
        span: a.trimmed_span(),
    }
}

impl Visit for Sdf3Reader<'_> {
    fn open(&mut self, e: &Elem) {
        let parent = self.open.last().copied();
        let role = match parent {
            None => {
                self.root(e);
                Role::Root
            }
            Some(_) if self.other_type => Role::Ignored,
            Some(parent) => parent.child(e.local.as_bytes(), |role| self.first(role)),
        };
        match role {
            Role::ApplicationGraph => {
                self.application_graph_seen = true;
                self.application_graph_name =
                    get(&e.attrs, "name").map(|a| a.trimmed().to_string());
            }
            Role::Sdf => {
                let name = get(&e.attrs, "name").map(|a| a.trimmed().to_string());
                self.sdf = Some((name, e.tag, false));
            }
            Role::Properties => self.properties_seen = true,
            Role::Processor => {
                let trimmed = |key| get(&e.attrs, key).map(|a| a.trimmed().to_string());
                self.processors.push(Processor {
                    kind: trimmed("type"),
                    default: get(&e.attrs, "default")
                        .map(|a| (a.trimmed().to_string(), a.trimmed_span())),
                    time: None,
                });
            }
            _ => {}
        }
        self.open.push(role);
    }

    fn close(&mut self, e: &mut Elem) {
        let Some(role) = self.open.pop() else {
            return;
        };
        match role {
            Role::Root => self.root_complete = e.complete,
            Role::Sdf => {
                if let Some(sdf) = &mut self.sdf {
                    (sdf.1, sdf.2) = (e.span, e.complete);
                }
            }
            Role::Actor => self.actor(e),
            Role::Port => self.port(e),
            Role::Channel => self.channel(e),
            Role::ActorProperties => self.actor_properties(e),
            Role::ExecutionTime => {
                if let Some(p) = self.processors.last_mut() {
                    p.time.get_or_insert_with(|| get(&e.attrs, "time").cloned());
                }
            }
            Role::ApplicationGraph | Role::Properties | Role::Processor | Role::Ignored => {}
        }
    }

    fn text(&mut self, _: Span) {}
}
