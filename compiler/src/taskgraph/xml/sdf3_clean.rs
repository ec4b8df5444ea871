//! The direct reading of a clean SDF3 file: quick-xml's events (found by
//! [`super::tags`]) straight into the graph, with no element, attribute list
//! or owned string on the way (the attribute values are slices of the text,
//! their ranges found by pointer arithmetic, and only the model's own names
//! are copied). On a 1,000-actor
//! graph this reading takes a fraction of the time of the full reader
//! ([`super::sdf3`] over [`crate::xmltree::walk`]), which was most of the time
//! of analysing one.
//!
//! It reads only files it can read completely and silently: at the first
//! thing that would need a diagnostic (malformed XML, an entity, text outside
//! the root, a missing or bad attribute, a second actor or port of one name,
//! a channel end that does not resolve, a port joined by two channels, an
//! actor with two processors marked `default="true"`, a root that is not
//! `<sdf3 type="sdf">`) it declines, and the caller reads the file with the full
//! reader, which reports it. It keeps the full reader's meaning element for
//! element (the same roles, first-of-a-kind rules and execution-time choice),
//! so the two give the same graph on every file this one accepts and this one
//! declines only files the full reader reports or that hold an entity
//! (`taskgraph::xml::tests::the_clean_sdf3_reader_*`).

use super::ExecutionTimes;
use super::sdf3::Role;
use super::tags::Tags;
use crate::diag::FileId;
use crate::fasthash::FastMap as HashMap;
use crate::span::Span;
use crate::taskgraph::model::*;
use crate::xmlpos::{end_tag_span, first_repeated, slice_span, start_tag_spans};
use crate::xmltree::MAX_DEPTH;
use quick_xml::events::{BytesStart, Event};

/// The file needs the full reader (it has something to report, or an entity).
struct Decline;

type Read<T> = Result<T, Decline>;

/// The attributes an element of each role is read for, in the order of
/// [`Open::attrs`].
fn keys(role: Role) -> &'static [&'static [u8]] {
    match role {
        Role::Root => &[b"type"],
        Role::ApplicationGraph | Role::Sdf | Role::Actor => &[b"name"],
        Role::Port => &[b"name", b"type", b"rate"],
        Role::Channel => &[
            b"srcActor",
            b"srcPort",
            b"dstActor",
            b"dstPort",
            b"initialTokens",
        ],
        Role::ActorProperties => &[b"actor"],
        Role::Processor => &[b"type", b"default"],
        Role::ExecutionTime => &[b"time"],
        Role::Properties | Role::Ignored => &[],
    }
}

/// An attribute value (without entities), trimmed once when read: every
/// use wants it trimmed.
#[derive(Clone, Copy)]
struct Value<'t> {
    /// The value without its leading and trailing blanks.
    text: &'t str,
    /// The range of `text`, or of the whole value when it is blank, as
    /// [`crate::xmlpos::Attr::trimmed_span`] gives it.
    span: Span,
}

impl<'t> Value<'t> {
    /// The value `raw`, written at `span`.
    fn new(raw: &'t str, span: Span) -> Value<'t> {
        // Nothing to trim when it starts and ends with a visible ASCII
        // character (an ASCII byte is a whole character, and none of those
        // is white space): the common case, without `trim`'s decoding.
        let text = match (raw.as_bytes().first(), raw.as_bytes().last()) {
            (Some(first), Some(last)) if first.is_ascii_graphic() && last.is_ascii_graphic() => raw,
            _ => raw.trim(),
        };
        if text.is_empty() {
            return Value { text, span };
        }
        let lead = text.as_ptr() as usize - raw.as_ptr() as usize;
        let start = span.start + lead;
        Value {
            text,
            span: Span::new(start, start + text.len()),
        }
    }

    fn trimmed(self) -> &'t str {
        self.text
    }

    fn trimmed_span(self) -> Span {
        self.span
    }

    /// A required attribute must not be blank.
    fn required(value: Option<Value<'t>>) -> Read<Value<'t>> {
        value.filter(|v| !v.trimmed().is_empty()).ok_or(Decline)
    }

    fn named(self) -> Named {
        Named {
            name: self.trimmed().into(),
            span: self.trimmed_span(),
        }
    }

    /// A whole number, as the full reader accepts it.
    fn number(self, at_least_one: bool) -> Read<u64> {
        let s = self.trimmed();
        if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
            return Err(Decline);
        }
        match s.parse::<u64>() {
            Ok(n) if n >= 1 || !at_least_one => Ok(n),
            _ => Err(Decline),
        }
    }
}

/// The most attributes a role reads.
const MAX_KEYS: usize = 5;

/// One open element.
struct Open<'t> {
    role: Role,
    qname: &'t [u8],
    tag: Span,
    /// The values of [`Role::keys`], the first of each key.
    attrs: [Option<Value<'t>>; MAX_KEYS],
}

/// One `<processor>` of the `<actorProperties>` being read.
struct Processor<'t> {
    kind: Option<&'t str>,
    default: Option<&'t str>,
    /// The `time` of its first `<executionTime>`.
    time: Option<Option<Value<'t>>>,
}

/// The graph of `text` when it is an SDF3 graph this reader takes (see the
/// module's documentation); `None` when the full reader must read it.
pub(super) fn read(file: FileId, text: &str, times: ExecutionTimes) -> Option<TaskGraph> {
    let mut state = State {
        text,
        times,
        open: Vec::new(),
        root_seen: false,
        application_graph_seen: false,
        application_graph_name: None,
        properties_seen: false,
        sdf: None,
        tasks: Vec::new(),
        task_index: HashMap::default(),
        ports: Vec::new(),
        channels: Vec::new(),
        processors: Vec::new(),
        actor_times: HashMap::default(),
    };
    state.run().ok()?;
    state.finish(file).ok()
}

/// Whether two attribute names are the same. SDF3's names of one length
/// mostly differ in their first byte (`name`, `type`, `rate`; `srcActor`,
/// `dstActor`): compared first, it spares most of the calls to `memcmp`
/// that comparing the slices makes (a few percent of reading a large graph).
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.first() == b.first() && a == b
}

struct State<'t> {
    text: &'t str,
    times: ExecutionTimes,
    open: Vec<Open<'t>>,
    root_seen: bool,
    application_graph_seen: bool,
    application_graph_name: Option<&'t str>,
    properties_seen: bool,
    /// `<sdf>`: its `name` and its range once closed.
    sdf: Option<(Option<&'t str>, Option<Span>)>,
    tasks: Vec<Task>,
    task_index: HashMap<&'t str, usize>,
    /// The ports of the actor being read.
    ports: Vec<Port>,
    channels: Vec<Channel>,
    processors: Vec<Processor<'t>>,
    actor_times: HashMap<&'t str, u64>,
}

impl<'t> State<'t> {
    fn run(&mut self) -> Read<()> {
        let text = self.text;
        let mut tags = Tags::new(text);
        loop {
            let (event, end) = tags.next().ok_or(Decline)?;
            match event {
                Event::Start(e) => self.start(&e, tags.attributes(), end, false)?,
                Event::Empty(e) => self.start(&e, tags.attributes(), end, true)?,
                Event::End(e) => {
                    let name = e.name();
                    let open = self.open.pop().ok_or(Decline)?;
                    if open.qname != name.as_ref() {
                        return Err(Decline);
                    }
                    let span =
                        Span::new(open.tag.start, end_tag_span(text, name.as_ref(), end).end);
                    self.close(&open, span)?;
                }
                Event::Text(t) => self.content(&t)?,
                Event::CData(t) => self.content(&t)?,
                // An entity: resolved (or reported) by the full reader.
                Event::GeneralRef(_) => return Err(Decline),
                Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_) => {}
                Event::Eof => {
                    return if self.open.is_empty() && self.root_seen {
                        Ok(())
                    } else {
                        Err(Decline)
                    };
                }
            }
        }
    }

    /// Text is ignored inside the root; outside, only blanks (and a
    /// byte-order mark) may go.
    fn content(&self, t: &[u8]) -> Read<()> {
        if !self.open.is_empty() {
            return Ok(());
        }
        let s = std::str::from_utf8(t).map_err(|_| Decline)?;
        let blank = s
            .trim_matches(|c: char| c.is_whitespace() || c == '\u{feff}')
            .is_empty();
        if blank { Ok(()) } else { Err(Decline) }
    }

    /// A start tag and its attributes (names and values), as [`Tags`] reads
    /// them.
    fn start(
        &mut self,
        e: &BytesStart<'t>,
        attributes: &[(&'t [u8], &'t [u8])],
        tag_end: usize,
        empty: bool,
    ) -> Read<()> {
        let text = self.text;
        let (name_span, tag) = start_tag_spans(text, e, tag_end);
        let qname = text
            .as_bytes()
            .get(slice_span(text, e.name().as_ref()).ok_or(Decline)?.range())
            .ok_or(Decline)?;
        let local = e.local_name();
        let local = local.as_ref();
        if local.is_empty() || name_span.is_empty() {
            return Err(Decline);
        }
        // Past the depth the full reader reads, it reports E097.
        if self.open.len() == MAX_DEPTH {
            return Err(Decline);
        }
        let parent = match self.open.last() {
            Some(open) => Some(open.role),
            None if self.root_seen => return Err(Decline),
            None => None,
        };
        let role = match parent {
            None if local == b"sdf3" => Role::Root,
            // Not an SDF3 graph.
            None => return Err(Decline),
            Some(parent) => parent.child(local, |role| match role {
                Role::ApplicationGraph => !self.application_graph_seen,
                Role::Sdf => self.sdf.is_none(),
                Role::Properties => !self.properties_seen,
                _ => true,
            }),
        };
        let attrs = self.attributes(attributes, keys(role))?;
        match role {
            Role::Root => {
                self.root_seen = true;
                if Value::required(attrs[0])?.trimmed() != "sdf" {
                    return Err(Decline);
                }
            }
            Role::ApplicationGraph => {
                self.application_graph_seen = true;
                self.application_graph_name = attrs[0].map(Value::trimmed);
            }
            Role::Sdf => self.sdf = Some((attrs[0].map(Value::trimmed), None)),
            Role::Properties => self.properties_seen = true,
            Role::Processor => self.processors.push(Processor {
                kind: attrs[0].map(Value::trimmed),
                default: attrs[1].map(Value::trimmed),
                time: None,
            }),
            _ => {}
        }
        let open = Open {
            role,
            qname,
            tag,
            attrs,
        };
        if empty {
            self.close(&open, tag)
        } else {
            self.open.push(open);
            Ok(())
        }
    }

    /// Every attribute checked as the full reader checks it (no duplicate
    /// name, no `<` and, here, no entity in a value; [`Tags`] has checked
    /// their syntax), and the first value of each of `keys`.
    fn attributes(
        &self,
        attributes: &[(&'t [u8], &'t [u8])],
        keys: &[&[u8]],
    ) -> Read<[Option<Value<'t>>; MAX_KEYS]> {
        let text = self.text;
        let mut found = [None; MAX_KEYS];
        if first_repeated(attributes, |&(key, _)| key).is_some() {
            return Err(Decline);
        }
        for &(key, raw) in attributes {
            if raw.iter().any(|&b| b == b'<' || b == b'&') {
                return Err(Decline);
            }
            let Some(i) = keys.iter().position(|k| same(k, key)) else {
                continue;
            };
            if found[i].is_some() {
                continue;
            }
            let span = slice_span(text, raw).ok_or(Decline)?;
            let value = text.get(span.range()).ok_or(Decline)?;
            found[i] = Some(Value::new(value, span));
        }
        Ok(found)
    }

    /// The end of an element whose whole range is `span`.
    fn close(&mut self, open: &Open<'t>, span: Span) -> Read<()> {
        let attrs = &open.attrs;
        match open.role {
            Role::Sdf => {
                if let Some(sdf) = &mut self.sdf {
                    sdf.1 = Some(span);
                }
            }
            Role::Actor => self.actor(attrs[0], span)?,
            Role::Port => self.port(attrs, span)?,
            Role::Channel => self.channel(attrs, span)?,
            Role::ActorProperties => self.actor_properties(attrs[0])?,
            Role::ExecutionTime => {
                if let Some(p) = self.processors.last_mut() {
                    p.time.get_or_insert(attrs[0]);
                }
            }
            Role::Root
            | Role::ApplicationGraph
            | Role::Properties
            | Role::Processor
            | Role::Ignored => {}
        }
        Ok(())
    }

    fn actor(&mut self, name: Option<Value<'t>>, span: Span) -> Read<()> {
        let ports = std::mem::take(&mut self.ports);
        let name = Value::required(name)?;
        let index = self.tasks.len();
        if self.task_index.insert(name.trimmed(), index).is_some() {
            return Err(Decline);
        }
        self.tasks.push(Task {
            wcet: None,
            name: name.named(),
            span,
            kind: TaskKind::Computational,
            trigger: Trigger::Data,
            source: None,
            subgraph: None,
            ports,
            library_ports: Vec::new(),
            multicast_ports: Vec::new(),
            loop_node: None,
        });
        Ok(())
    }

    fn port(&mut self, attrs: &[Option<Value<'t>>; MAX_KEYS], span: Span) -> Read<()> {
        let name = Value::required(attrs[0])?;
        let dir = match Value::required(attrs[1])?.trimmed() {
            "in" => Direction::In,
            "out" => Direction::Out,
            _ => return Err(Decline),
        };
        let rate = match attrs[2] {
            None => 1,
            Some(r) => r.number(true)?,
        };
        if self.ports.iter().any(|p| p.name.name == name.trimmed()) {
            return Err(Decline);
        }
        self.ports.push(Port {
            name: name.named(),
            span,
            dir,
            rate,
            rate_span: attrs[2].map(Value::trimmed_span),
            sample_type: None,
            size: None,
            kind: None,
            inner_rate: None,
        });
        Ok(())
    }

    fn channel(&mut self, attrs: &[Option<Value<'t>>; MAX_KEYS], span: Span) -> Read<()> {
        let end = |actor: Option<Value<'t>>, port: Option<Value<'t>>| -> Read<Endpoint> {
            let (actor, port) = (Value::required(actor)?, Value::required(port)?);
            Ok(Endpoint {
                task: actor.trimmed().into(),
                port: port.trimmed().into(),
                span: actor.trimmed_span().cover(port.trimmed_span()),
            })
        };
        let src = end(attrs[0], attrs[1])?;
        let dst = end(attrs[2], attrs[3])?;
        let initial_tokens = match attrs[4] {
            None => 0,
            Some(t) => t.number(false)?,
        };
        self.channels.push(Channel {
            src,
            dst,
            initial_tokens,
            capacity: None,
            span,
        });
        Ok(())
    }

    /// An actor's time, from the processor [`ExecutionTimes`] chooses (as
    /// `Sdf3Reader::actor_properties` does).
    fn actor_properties(&mut self, actor: Option<Value<'t>>) -> Read<()> {
        let processors = std::mem::take(&mut self.processors);
        let Some(actor) = actor else {
            return Ok(());
        };
        let defaults = processors.iter().filter(|p| p.default == Some("true"));
        if defaults.count() > 1 {
            return Err(Decline); // W086
        }
        let chosen = match self.times {
            ExecutionTimes::FileDefault => processors
                .iter()
                .find(|p| p.default == Some("true"))
                .or(processors.first()),
            ExecutionTimes::Sdf3Compat => {
                let last = processors.iter().rev().find(|p| p.default.is_some());
                last.and_then(|l| l.kind)
                    .and_then(|kind| processors.iter().find(|p| p.kind == Some(kind)))
            }
        };
        if let Some(time) = chosen.and_then(|p| p.time).flatten() {
            let n = time.number(false)?;
            self.actor_times.entry(actor.trimmed()).or_insert(n);
        }
        Ok(())
    }

    /// The graph, once every channel end is known to resolve to a port of
    /// the right direction.
    fn finish(self, file: FileId) -> Read<TaskGraph> {
        let Some((name, Some(span))) = self.sdf else {
            return Err(Decline);
        };
        let port = |end: &Endpoint| {
            let task = &self.tasks[*self.task_index.get(end.task.as_str())?];
            task.port(&end.port).map(|p| p.dir)
        };
        // Each port the end of one channel (E098 otherwise).
        let mut joined = crate::fasthash::FastSet::default();
        for c in &self.channels {
            if port(&c.src) != Some(Direction::Out) || port(&c.dst) != Some(Direction::In) {
                return Err(Decline);
            }
            for end in [&c.src, &c.dst] {
                if !joined.insert((end.task.as_str(), end.port.as_str())) {
                    return Err(Decline);
                }
            }
        }
        let mut tasks = self.tasks;
        for task in &mut tasks {
            task.wcet = self.actor_times.get(task.name.name.as_str()).copied();
        }
        Ok(TaskGraph {
            name: name
                .or(self.application_graph_name)
                .unwrap_or_default()
                .to_string(),
            file,
            span,
            tasks,
            channels: self.channels,
            libraries: Vec::new(),
        })
    }
}
