//! Reading one `*.robot.xml` catalog file into robot types, with positioned
//! diagnostics (E050–E056, W050). The reader borrows the text, so every element,
//! attribute and attribute value gets its exact byte range.
//!
//! Malformed XML (E050) stops the file: robots completely read before the error
//! are kept. Every other problem is reported and reading goes on; a broken entry
//! (a value without a name, a duplicate robot type) is left out of the result.

use super::{
    Implementation, Origin, ParamDef, Platform, RobotType, ServiceDef, ValueDef, ValueType,
};
use crate::diag::{Code, Diagnostic, FileId, Sink};
use crate::span::Span;
use crate::xmlpos::{
    self, Attr, StartTag, get, is_ident, is_namespace_attribute, read_attributes,
    resolve_reference, suggest, trim_span, xml_error_message,
};
use quick_xml::encoding::Decoder;
use quick_xml::events::{BytesEnd, BytesStart, Event};
use std::collections::HashMap;
use std::path::Path;

/// Reads one catalog file: the robot types it defines and its diagnostics.
/// An `<Operator>` element (the `USER` pseudo-robot) is not a robot type and is
/// left out here; see [`parse_catalog`]. `graph=` files are looked up relative to
/// `base_dir`; with `None` they are not checked.
pub fn parse_catalog_file(
    file: FileId,
    text: &str,
    base_dir: Option<&Path>,
) -> (Vec<RobotType>, Vec<Diagnostic>) {
    let parsed = parse_catalog(file, text, base_dir);
    (
        parsed.robots.into_iter().map(|r| r.robot).collect(),
        parsed.diagnostics,
    )
}

/// Everything read from one catalog file.
#[derive(Clone, Debug, Default)]
pub struct ParsedCatalog {
    /// The `<Robot>` elements, in file order.
    pub robots: Vec<ParsedRobot>,
    /// The `<Operator>` element (the operator console, `USER`), if the file has one.
    pub operator: Option<ParsedRobot>,
    pub diagnostics: Vec<Diagnostic>,
}

/// One robot type with where its names are written.
#[derive(Clone, Debug)]
pub struct ParsedRobot {
    pub robot: RobotType,
    /// The type name, then each alias, with the byte range of each in the file.
    pub names: Vec<(String, Span)>,
}

/// Reads one catalog file, keeping the operator console and name positions.
pub fn parse_catalog(file: FileId, text: &str, base_dir: Option<&Path>) -> ParsedCatalog {
    let mut parser = Parser {
        text,
        base_dir,
        sink: Sink::new(file),
        out_robots: Vec::new(),
        operator: None,
        stack: Vec::new(),
        robot_names: HashMap::new(),
        seen_root: false,
        robot: None,
        value: None,
        service: None,
        doc: None,
    };
    parser.run();
    ParsedCatalog {
        robots: parser.out_robots,
        operator: parser.operator,
        diagnostics: parser.sink.into_vec(),
    }
}

/// The value types, for messages and did-you-mean.
const TYPE_NAMES: &[&str] = &[
    "int", "float", "bool", "string", "location", "image", "enum",
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Catalog,
    Robot,
    Operator,
    Doc,
    Platform,
    Capability,
    Value,
    Service,
    Param,
    /// An element that was reported (or sits inside one): its content is skipped.
    Skip,
}

impl Kind {
    const KNOWN: &'static [Kind] = &[
        Kind::Catalog,
        Kind::Robot,
        Kind::Operator,
        Kind::Doc,
        Kind::Platform,
        Kind::Capability,
        Kind::Value,
        Kind::Service,
        Kind::Param,
    ];

    fn tag(self) -> &'static str {
        match self {
            Kind::Catalog => "Catalog",
            Kind::Robot => "Robot",
            Kind::Operator => "Operator",
            Kind::Doc => "Doc",
            Kind::Platform => "Platform",
            Kind::Capability => "Capability",
            Kind::Value => "Value",
            Kind::Service => "Service",
            Kind::Param => "Param",
            Kind::Skip => "?",
        }
    }

    fn from_tag(name: &str) -> Option<Kind> {
        Kind::KNOWN.iter().copied().find(|k| k.tag() == name)
    }

    /// The elements allowed directly inside this one.
    fn children(self) -> &'static [Kind] {
        match self {
            Kind::Catalog => &[Kind::Robot, Kind::Operator],
            Kind::Robot | Kind::Operator => &[
                Kind::Doc,
                Kind::Platform,
                Kind::Capability,
                Kind::Value,
                Kind::Service,
            ],
            Kind::Value => &[Kind::Doc],
            Kind::Service => &[Kind::Doc, Kind::Param],
            _ => &[],
        }
    }

    /// Where this element belongs, for "not allowed here" messages.
    fn belongs(self) -> &'static str {
        match self {
            Kind::Catalog => "once, around the whole file",
            Kind::Robot | Kind::Operator => "directly inside `<Catalog>`",
            Kind::Doc => "inside `<Robot>`, `<Value>` or `<Service>`",
            Kind::Param => "inside `<Service>`",
            _ => "inside `<Robot>`",
        }
    }

    fn attributes(self) -> &'static [&'static str] {
        match self {
            Kind::Robot | Kind::Operator => &["type", "aliases"],
            Kind::Platform => &["os", "cpu", "cores", "clockMHz", "memoryKB", "note"],
            Kind::Capability => &["name"],
            Kind::Value => &[
                "name", "type", "domain", "unit", "task", "graph", "doc", "aliases",
            ],
            Kind::Service => &["name", "task", "graph", "doc", "aliases"],
            Kind::Param => &["name", "type", "optional", "domain"],
            Kind::Catalog | Kind::Doc | Kind::Skip => &[],
        }
    }
}

/// Malformed XML: stop reading the file.
struct Stop;

type Flow = Result<(), Stop>;

/// E053 with a pointer at the first definition.
fn duplicate(sink: &mut Sink, span: Span, first: Span, message: impl Into<String>) {
    sink.report(Code::CatalogDuplicateType, span, message)
        .relate(first, "first defined here");
}

/// Did-you-mean for a value type, knowing the usual names from other languages.
fn suggest_type(name: &str) -> Option<String> {
    let usual = match name.to_lowercase().as_str() {
        "integer" | "long" | "short" | "number" => "int",
        "double" | "real" | "decimal" => "float",
        "boolean" => "bool",
        "str" | "text" => "string",
        "position" | "point" | "coordinates" | "pose" => "location",
        "picture" | "img" | "photo" => "image",
        "enumeration" => "enum",
        _ => return suggest(name, TYPE_NAMES),
    };
    Some(usual.to_string())
}

/// Collapses runs of whitespace (a `<Doc>` may span lines) into single spaces.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

struct Open {
    qname: String,
    kind: Kind,
    tag: Span,
}

struct RobotBuild {
    operator: bool,
    /// False when the robot is left out (no type, duplicate type): its content is
    /// still checked.
    valid: bool,
    robot: RobotType,
    names: Vec<(String, Span)>,
    doc_at: Option<Span>,
    platform_at: Option<Span>,
    capabilities: HashMap<String, Span>,
    value_names: HashMap<String, Span>,
    service_names: HashMap<String, Span>,
}

struct ItemBuild<T> {
    /// `None` when the entry is left out (missing name, duplicate).
    def: Option<T>,
    /// Where the item was documented (`doc=` or an earlier `<Doc>`).
    doc_at: Option<Span>,
    param_names: HashMap<String, Span>,
    /// The first optional parameter seen, for "required after optional".
    optional_seen: bool,
}

impl<T> ItemBuild<T> {
    fn new(def: Option<T>, doc_at: Option<Span>) -> Self {
        ItemBuild {
            def,
            doc_at,
            param_names: HashMap::new(),
            optional_seen: false,
        }
    }
}

struct DocBuild {
    target: Kind,
    text: String,
}

struct Parser<'t, 'p> {
    text: &'t str,
    base_dir: Option<&'p Path>,
    sink: Sink,
    out_robots: Vec<ParsedRobot>,
    operator: Option<ParsedRobot>,
    stack: Vec<Open>,
    /// Robot type names and aliases of this file, to where they are first written.
    robot_names: HashMap<String, Span>,
    seen_root: bool,
    robot: Option<RobotBuild>,
    value: Option<ItemBuild<ValueDef>>,
    service: Option<ItemBuild<ServiceDef>>,
    doc: Option<DocBuild>,
}

impl Parser<'_, '_> {
    fn run(&mut self) {
        let mut reader = xmlpos::reader(self.text);
        let decoder = reader.decoder();
        loop {
            let event = reader.read_event();
            let end = (reader.buffer_position() as usize).min(self.text.len());
            let flow = match event {
                Err(err) => {
                    let pos = (reader.error_position() as usize).min(self.text.len());
                    self.xml_error(&err, pos);
                    Err(Stop)
                }
                Ok(Event::Eof) => {
                    self.eof();
                    break;
                }
                Ok(Event::Start(e)) => self.start(&e, end, false, decoder),
                Ok(Event::Empty(e)) => self.start(&e, end, true, decoder),
                Ok(Event::End(e)) => self.end(&e, end),
                Ok(Event::Text(t)) => {
                    let span = self.slice_span(&t).unwrap_or(Span::new(end, end));
                    match t.decode() {
                        Ok(s) => self.text_content(&s, span),
                        Err(_) => self.malformed(span, "this text is not valid UTF-8"),
                    }
                }
                Ok(Event::CData(t)) => {
                    let span = self.slice_span(&t).unwrap_or(Span::new(end, end));
                    match t.decode() {
                        Ok(s) => self.text_content(&s, span),
                        Err(_) => self.malformed(span, "this text is not valid UTF-8"),
                    }
                }
                Ok(Event::GeneralRef(r)) => {
                    let (span, resolved) = resolve_reference(self.text, &r, end);
                    match resolved {
                        Ok(s) => self.text_content(&s, span),
                        Err(message) => self.malformed(span, message),
                    }
                }
                Ok(Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_)) => Ok(()),
            };
            if flow.is_err() {
                break;
            }
        }
    }

    /// The byte range of `slice` if it borrows from the text.
    fn slice_span(&self, slice: &[u8]) -> Option<Span> {
        xmlpos::slice_span(self.text, slice)
    }

    /// A short range at `pos` for an error position: the word starting there.
    fn word_at(&self, pos: usize) -> Span {
        xmlpos::word_at(self.text, pos)
    }

    /// E050: reports malformed XML; reading stops.
    fn malformed(&mut self, span: Span, message: impl Into<String>) -> Flow {
        Err(self.fail(span, message))
    }

    fn fail(&mut self, span: Span, message: impl Into<String>) -> Stop {
        self.sink.report(Code::CatalogXml, span, message);
        Stop
    }

    fn xml_error(&mut self, err: &quick_xml::Error, pos: usize) {
        let span = self.word_at(pos);
        self.sink
            .report(Code::CatalogXml, span, xml_error_message(err));
    }

    fn eof(&mut self) {
        if let Some(open) = self.stack.last() {
            let (tag, message) = (open.tag, xmlpos::never_closed(&open.qname));
            self.sink.report(Code::CatalogXml, tag, message);
        } else if !self.seen_root {
            let end = self.text.len();
            self.sink.report(
                Code::CatalogXml,
                Span::new(end, end),
                "this catalog file is empty: it needs a `<Catalog>` element",
            );
        }
    }

    fn text_content(&mut self, s: &str, span: Span) -> Flow {
        let top = self.stack.last().map(|o| o.kind);
        if top == Some(Kind::Doc) {
            if let Some(doc) = self.doc.as_mut() {
                doc.text.push_str(s);
            }
            return Ok(());
        }
        if s.trim().is_empty() {
            return Ok(());
        }
        let span = trim_span(s, span);
        match top {
            None => self.malformed(
                span,
                "text outside the `<Catalog>` element: only comments may go there",
            ),
            Some(Kind::Skip) => Ok(()),
            Some(kind) => {
                self.sink.report(
                    Code::CatalogUnknownElement,
                    span,
                    format!(
                        "text is not allowed inside `<{}>`: put descriptions in a `<Doc>` element",
                        kind.tag()
                    ),
                );
                Ok(())
            }
        }
    }

    fn attributes(
        &mut self,
        e: &BytesStart<'_>,
        tag: Span,
        decoder: Decoder,
    ) -> Result<Vec<Attr>, Stop> {
        read_attributes(self.text, e, tag, decoder)
            .map_err(|(span, message)| self.fail(span, message))
    }

    /// W050 for attributes that `kind` does not have.
    fn check_attributes(&mut self, kind: Kind, attrs: &[Attr]) {
        let allowed = kind.attributes();
        for a in attrs {
            // Namespace declarations and prefixed attributes (xsi:...) are allowed.
            if is_namespace_attribute(&a.key) || allowed.contains(&a.key.as_str()) {
                continue;
            }
            self.sink
                .report(
                    Code::CatalogUnknownAttribute,
                    a.key_span,
                    format!(
                        "`<{}>` has no attribute `{}`; it is ignored",
                        kind.tag(),
                        a.key
                    ),
                )
                .suggest(suggest(&a.key, allowed));
        }
    }

    fn start(&mut self, e: &BytesStart<'_>, tag_end: usize, empty: bool, decoder: Decoder) -> Flow {
        let StartTag {
            qname,
            local,
            name_span,
            tag,
        } = match xmlpos::start_tag(self.text, e, tag_end) {
            Ok(start) => start,
            Err((span, message)) => return self.malformed(span, message),
        };
        let attrs = self.attributes(e, tag, decoder)?;
        let parent = self.stack.last().map(|o| o.kind);
        let kind = match parent {
            None => {
                if self.seen_root {
                    return self.malformed(
                        name_span,
                        format!(
                            "`<{qname}>` comes after the end of `<Catalog>`: a catalog file has a single `<Catalog>` element"
                        ),
                    );
                }
                self.seen_root = true;
                if local == "Catalog" {
                    Kind::Catalog
                } else {
                    self.sink.report(
                        Code::CatalogUnknownElement,
                        name_span,
                        format!("a catalog file must start with `<Catalog>`, not `<{qname}>`"),
                    );
                    Kind::Skip
                }
            }
            Some(Kind::Skip) => Kind::Skip,
            Some(parent) => match Kind::from_tag(&local) {
                Some(k) if parent.children().contains(&k) => k,
                Some(k) => {
                    self.sink.report(
                        Code::CatalogUnknownElement,
                        name_span,
                        format!(
                            "`<{}>` is not allowed inside `<{}>`: it goes {}",
                            k.tag(),
                            parent.tag(),
                            k.belongs()
                        ),
                    );
                    Kind::Skip
                }
                None => {
                    let candidates: Vec<&str> = parent.children().iter().map(|k| k.tag()).collect();
                    let message = if parent.children().is_empty() {
                        format!(
                            "unknown element `<{qname}>`: `<{}>` cannot contain elements",
                            parent.tag()
                        )
                    } else {
                        format!("unknown element `<{qname}>` inside `<{}>`", parent.tag())
                    };
                    self.sink
                        .report(Code::CatalogUnknownElement, name_span, message)
                        .suggest(suggest(&local, &candidates));
                    Kind::Skip
                }
            },
        };
        if kind != Kind::Skip {
            self.check_attributes(kind, &attrs);
        }
        self.open(kind, parent, tag, &attrs);
        if empty {
            self.finish(kind);
        } else {
            self.stack.push(Open {
                qname: qname.into(),
                kind,
                tag,
            });
        }
        Ok(())
    }

    fn end(&mut self, e: &BytesEnd<'_>, tag_end: usize) -> Flow {
        let (span, name) = xmlpos::end_tag(self.text, e, tag_end);
        match self.stack.pop() {
            None => self.malformed(span, xmlpos::unopened_close(&name)),
            Some(open) if open.qname != name => {
                let (message, opened) = xmlpos::mismatched_close(&name, &open.qname);
                self.sink
                    .report(Code::CatalogXml, span, message)
                    .relate(open.tag, opened);
                Err(Stop)
            }
            Some(open) => {
                self.finish(open.kind);
                Ok(())
            }
        }
    }

    /// Required attribute: E052 when missing, E056 when empty.
    fn required<'a>(
        &mut self,
        attrs: &'a [Attr],
        key: &str,
        kind: Kind,
        tag: Span,
    ) -> Option<&'a Attr> {
        match get(attrs, key) {
            None => {
                self.sink.report(
                    Code::CatalogMissingAttribute,
                    tag,
                    format!("this `<{}>` needs a `{key}` attribute", kind.tag()),
                );
                None
            }
            Some(a) if a.trimmed().is_empty() => {
                self.sink.report(
                    Code::CatalogBadAttribute,
                    a.span,
                    format!("`{key}` is empty"),
                );
                None
            }
            Some(a) => Some(a),
        }
    }

    /// A name that missions write: E056 unless it is an identifier.
    fn check_name(&mut self, name: &str, span: Span) -> bool {
        if is_ident(name) {
            return true;
        }
        self.sink.report(
            Code::CatalogBadAttribute,
            span,
            format!(
                "`{name}` cannot be used as a name: use letters, digits and `_`, not starting with a digit"
            ),
        );
        false
    }

    /// The value's name from a required attribute, checked.
    fn name_attr(
        &mut self,
        attrs: &[Attr],
        key: &str,
        kind: Kind,
        tag: Span,
    ) -> Option<(String, Span)> {
        let a = self.required(attrs, key, kind, tag)?;
        let name = a.trimmed().to_string();
        let span = a.span;
        self.check_name(&name, span).then_some((name, span))
    }

    /// The aliases of a robot, value or service, checked as names.
    fn aliases(&mut self, attrs: &[Attr]) -> Vec<(String, Span)> {
        let Some(a) = get(attrs, "aliases") else {
            return Vec::new();
        };
        a.words()
            .into_iter()
            .filter(|(w, span)| self.check_name(w, *span))
            .collect()
    }

    /// The type of a value or parameter (`type=` and `domain=`). Falls back to
    /// `string` after an error so that missions using it are not flooded.
    fn value_type(&mut self, ty: &Attr, attrs: &[Attr]) -> ValueType {
        let name = ty.trimmed();
        let domain = get(attrs, "domain");
        if name == "enum" {
            let words = domain.map(Attr::words).unwrap_or_default();
            if words.is_empty() {
                let span = domain.map_or(ty.span, |d| d.span);
                self.sink.report(
                    Code::CatalogBadAttribute,
                    span,
                    "an `enum` needs a `domain` listing its values, like domain=\"RED GREEN BLUE\"",
                );
                return ValueType::String;
            }
            let mut seen: HashMap<&str, Span> = HashMap::new();
            let mut values = Vec::new();
            for (w, span) in &words {
                if !self.check_name(w, *span) {
                    continue;
                }
                if let Some(first) = seen.get(w.as_str()) {
                    duplicate(
                        &mut self.sink,
                        *span,
                        *first,
                        format!("`{w}` is listed twice in the domain"),
                    );
                    continue;
                }
                seen.insert(w, *span);
                values.push(w.clone());
            }
            return ValueType::Enum(values);
        }
        let Some(parsed) = ValueType::parse(name, None) else {
            self.sink.report(Code::CatalogUnknownValueType, ty.span, format!(
                    "unknown type `{name}`: the types are int, float, bool, string, location, image and enum"
                )).suggest(suggest_type(name));
            return ValueType::String;
        };
        if let Some(d) = domain {
            self.sink.report(
                Code::CatalogBadAttribute,
                d.span,
                format!("`domain` is only for type=\"enum\", and this type is `{name}`"),
            );
        }
        parsed
    }

    /// `task=` or `graph=`.
    fn implementation(&mut self, attrs: &[Attr]) -> Implementation {
        let task = get(attrs, "task");
        let graph = get(attrs, "graph");
        if let (Some(_), Some(g)) = (task, graph) {
            self.sink.report(
                Code::CatalogBadAttribute,
                g.span,
                "give either `task` or `graph`, not both",
            );
        }
        if let Some(t) = task {
            if t.trimmed().is_empty() {
                self.sink
                    .report(Code::CatalogBadAttribute, t.span, "`task` is empty");
                return Implementation::Unspecified;
            }
            return Implementation::Task(t.trimmed().to_string());
        }
        if let Some(g) = graph {
            let path = g.trimmed();
            if path.is_empty() {
                self.sink
                    .report(Code::CatalogBadAttribute, g.span, "`graph` is empty");
                return Implementation::Unspecified;
            }
            if let Some(dir) = self.base_dir {
                if !dir.join(path).is_file() {
                    self.sink.report(
                        Code::CatalogMissingGraph,
                        g.span,
                        format!("the task graph file `{path}` does not exist (it is looked up next to this catalog file)"),
                    );
                }
            }
            return Implementation::Graph(path.to_string());
        }
        Implementation::Unspecified
    }

    fn doc_attr(attrs: &[Attr]) -> (String, Option<Span>) {
        match get(attrs, "doc") {
            Some(a) => (one_line(&a.value), Some(a.span)),
            None => (String::new(), None),
        }
    }

    fn open(&mut self, kind: Kind, parent: Option<Kind>, tag: Span, attrs: &[Attr]) {
        let origin = Origin {
            file: self.sink.file(),
            span: tag,
        };
        match kind {
            Kind::Catalog | Kind::Skip => {}
            Kind::Robot | Kind::Operator => self.open_robot(kind, tag, origin, attrs),
            Kind::Doc => self.open_doc(parent.unwrap_or(Kind::Skip), tag),
            Kind::Platform => self.open_platform(tag, attrs),
            Kind::Capability => {
                let Some((name, span)) = self.name_attr(attrs, "name", kind, tag) else {
                    return;
                };
                let Some(robot) = self.robot.as_mut() else {
                    return;
                };
                if let Some(first) = robot.capabilities.get(&name) {
                    let first = *first;
                    duplicate(
                        &mut self.sink,
                        span,
                        first,
                        format!("capability `{name}` is listed twice for this robot"),
                    );
                } else {
                    robot.capabilities.insert(name.clone(), span);
                    robot.robot.capabilities.push(name);
                }
            }
            Kind::Value => self.open_value(tag, origin, attrs),
            Kind::Service => self.open_service(tag, origin, attrs),
            Kind::Param => self.open_param(tag, attrs),
        }
    }

    fn open_robot(&mut self, kind: Kind, tag: Span, origin: Origin, attrs: &[Attr]) {
        let mut build = RobotBuild {
            operator: kind == Kind::Operator,
            valid: false,
            robot: RobotType {
                name: String::new(),
                aliases: Vec::new(),
                doc: String::new(),
                platform: Platform::default(),
                capabilities: Vec::new(),
                values: Vec::new(),
                services: Vec::new(),
                origin,
            },
            names: Vec::new(),
            doc_at: None,
            platform_at: None,
            capabilities: HashMap::new(),
            value_names: HashMap::new(),
            service_names: HashMap::new(),
        };
        if let Some((name, span)) = self.name_attr(attrs, "type", kind, tag) {
            if kind == Kind::Operator && name != "USER" {
                self.sink.report(
                    Code::CatalogBadAttribute,
                    span,
                    format!("the operator console is always called `USER`, not `{name}`"),
                );
            } else if let Some(first) = self.robot_names.get(&name) {
                let first = *first;
                duplicate(
                    &mut self.sink,
                    span,
                    first,
                    format!("robot type `{name}` is defined twice in this file"),
                );
            } else {
                self.robot_names.insert(name.clone(), span);
                build.names.push((name.clone(), span));
                build.robot.name = name;
                build.valid = true;
            }
        }
        let aliases = self.aliases(attrs);
        if build.valid {
            for (alias, span) in aliases {
                if let Some(first) = self.robot_names.get(&alias) {
                    let first = *first;
                    duplicate(
                        &mut self.sink,
                        span,
                        first,
                        format!("`{alias}` is already the name of a robot type in this file"),
                    );
                    continue;
                }
                self.robot_names.insert(alias.clone(), span);
                build.names.push((alias.clone(), span));
                build.robot.aliases.push(alias);
            }
        }
        self.robot = Some(build);
    }

    fn open_doc(&mut self, target: Kind, tag: Span) {
        let first = match target {
            Kind::Robot | Kind::Operator => self.robot.as_mut().map(|r| &mut r.doc_at),
            Kind::Value => self.value.as_mut().map(|v| &mut v.doc_at),
            Kind::Service => self.service.as_mut().map(|s| &mut s.doc_at),
            _ => None,
        };
        let Some(slot) = first else {
            return;
        };
        match *slot {
            Some(first) => {
                duplicate(
                    &mut self.sink,
                    tag,
                    first,
                    format!("this `<{}>` is already documented", target.tag()),
                );
                self.doc = None;
            }
            None => {
                *slot = Some(tag);
                self.doc = Some(DocBuild {
                    target,
                    text: String::new(),
                });
            }
        }
    }

    fn open_platform(&mut self, tag: Span, attrs: &[Attr]) {
        let Some(robot) = self.robot.as_mut() else {
            return;
        };
        if let Some(first) = robot.platform_at {
            duplicate(
                &mut self.sink,
                tag,
                first,
                "this robot already has a `<Platform>`",
            );
            return;
        }
        robot.platform_at = Some(tag);
        let mut platform = Platform::default();
        let text = |key: &str| {
            get(attrs, key)
                .map(|a| one_line(&a.value))
                .unwrap_or_default()
        };
        platform.os = text("os");
        platform.cpu = text("cpu");
        platform.note = text("note");
        let mut number = |key: &str, example: &str| -> Option<u64> {
            let a = get(attrs, key)?;
            match a.trimmed().parse::<u64>() {
                Ok(n) if n <= u64::from(u32::MAX) || key == "memoryKB" => Some(n),
                _ => {
                    self.sink.report(
                        Code::CatalogBadAttribute,
                        a.span,
                        format!("`{key}` must be a whole number, like {key}=\"{example}\""),
                    );
                    None
                }
            }
        };
        platform.cores = number("cores", "4").map(|n| n as u32);
        platform.clock_mhz = number("clockMHz", "900").map(|n| n as u32);
        platform.memory_kb = number("memoryKB", "1048576");
        if let Some(robot) = self.robot.as_mut() {
            robot.robot.platform = platform;
        }
    }

    /// E053 for a value or service name (or alias) already used in this robot.
    /// Returns the aliases that are free.
    fn register_item(
        &mut self,
        service: bool,
        name: &(String, Span),
        aliases: Vec<(String, Span)>,
    ) -> Option<Vec<String>> {
        let what = if service { "service" } else { "value" };
        let robot = self.robot.as_mut()?;
        let names = if service {
            &mut robot.service_names
        } else {
            &mut robot.value_names
        };
        if let Some(first) = names.get(&name.0) {
            let first = *first;
            duplicate(
                &mut self.sink,
                name.1,
                first,
                format!("this robot already has a {what} `{}`", name.0),
            );
            return None;
        }
        names.insert(name.0.clone(), name.1);
        let mut kept = Vec::new();
        for (alias, span) in aliases {
            if let Some(first) = names.get(&alias) {
                let first = *first;
                duplicate(
                    &mut self.sink,
                    span,
                    first,
                    format!("this robot already has a {what} `{alias}`"),
                );
                continue;
            }
            names.insert(alias.clone(), span);
            kept.push(alias);
        }
        Some(kept)
    }

    fn open_value(&mut self, tag: Span, origin: Origin, attrs: &[Attr]) {
        let name = self.name_attr(attrs, "name", Kind::Value, tag);
        let ty = self
            .required(attrs, "type", Kind::Value, tag)
            .map(|t| self.value_type(t, attrs));
        let implementation = self.implementation(attrs);
        let aliases = self.aliases(attrs);
        let (doc, doc_at) = Self::doc_attr(attrs);
        let unit = get(attrs, "unit")
            .map(|u| u.trimmed().to_string())
            .filter(|u| !u.is_empty());
        let def = match (name, ty) {
            (Some(name), Some(ty)) => {
                self.register_item(false, &name, aliases)
                    .map(|aliases| ValueDef {
                        name: name.0,
                        aliases,
                        ty,
                        unit,
                        doc,
                        implementation,
                        origin,
                    })
            }
            _ => None,
        };
        self.value = Some(ItemBuild::new(def, doc_at));
    }

    fn open_service(&mut self, tag: Span, origin: Origin, attrs: &[Attr]) {
        let name = self.name_attr(attrs, "name", Kind::Service, tag);
        let implementation = self.implementation(attrs);
        let aliases = self.aliases(attrs);
        let (doc, doc_at) = Self::doc_attr(attrs);
        let def = name.and_then(|name| {
            self.register_item(true, &name, aliases)
                .map(|aliases| ServiceDef {
                    name: name.0,
                    aliases,
                    params: Vec::new(),
                    doc,
                    implementation,
                    origin,
                })
        });
        self.service = Some(ItemBuild::new(def, doc_at));
    }

    fn open_param(&mut self, tag: Span, attrs: &[Attr]) {
        let name = self.name_attr(attrs, "name", Kind::Param, tag);
        let ty = self
            .required(attrs, "type", Kind::Param, tag)
            .map(|t| self.value_type(t, attrs));
        let optional = match get(attrs, "optional") {
            None => false,
            Some(a) => match a.trimmed() {
                "true" => true,
                "false" => false,
                other => {
                    self.sink.report(
                        Code::CatalogBadAttribute,
                        a.span,
                        format!("`optional` must be true or false, not `{other}`"),
                    );
                    false
                }
            },
        };
        let (Some((name, span)), Some(ty)) = (name, ty) else {
            return;
        };
        let Some(service) = self.service.as_mut() else {
            return;
        };
        if let Some(first) = service.param_names.get(&name) {
            let first = *first;
            duplicate(
                &mut self.sink,
                span,
                first,
                format!("this service already has a parameter `{name}`"),
            );
            return;
        }
        service.param_names.insert(name.clone(), span);
        if optional {
            service.optional_seen = true;
        } else if service.optional_seen {
            self.sink.report(
                Code::CatalogBadAttribute,
                span,
                format!(
                    "parameter `{name}` is required but comes after an optional one: put required parameters first"
                ),
            );
        }
        if let Some(def) = service.def.as_mut() {
            def.params.push(ParamDef { name, ty, optional });
        }
    }

    fn finish(&mut self, kind: Kind) {
        match kind {
            Kind::Doc => {
                let Some(doc) = self.doc.take() else {
                    return;
                };
                let text = one_line(&doc.text);
                match doc.target {
                    Kind::Robot | Kind::Operator => {
                        if let Some(r) = self.robot.as_mut() {
                            r.robot.doc = text;
                        }
                    }
                    Kind::Value => {
                        if let Some(def) = self.value.as_mut().and_then(|v| v.def.as_mut()) {
                            def.doc = text;
                        }
                    }
                    Kind::Service => {
                        if let Some(def) = self.service.as_mut().and_then(|s| s.def.as_mut()) {
                            def.doc = text;
                        }
                    }
                    _ => {}
                }
            }
            Kind::Value => {
                if let (Some(def), Some(robot)) =
                    (self.value.take().and_then(|v| v.def), self.robot.as_mut())
                {
                    robot.robot.values.push(def);
                }
            }
            Kind::Service => {
                if let (Some(def), Some(robot)) =
                    (self.service.take().and_then(|s| s.def), self.robot.as_mut())
                {
                    robot.robot.services.push(def);
                }
            }
            Kind::Robot | Kind::Operator => {
                let Some(build) = self.robot.take() else {
                    return;
                };
                if !build.valid {
                    return;
                }
                let parsed = ParsedRobot {
                    robot: build.robot,
                    names: build.names,
                };
                if build.operator {
                    self.operator = Some(parsed);
                } else {
                    self.out_robots.push(parsed);
                }
            }
            Kind::Catalog | Kind::Platform | Kind::Capability | Kind::Param | Kind::Skip => {}
        }
    }
}

#[cfg(test)]
mod tests;
