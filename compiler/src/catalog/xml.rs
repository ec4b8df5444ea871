//! Reading one `*.robot.xml` catalog file into robot types, with positioned
//! diagnostics (E050–E056, W050). The file is first read into the positioned
//! element tree of [`crate::xmltree`], then the tree is walked against the
//! format's table ([`super::schema`]).
//!
//! Malformed XML (E050) stops the first step: robots completely read before the
//! error are kept, the robot cut short is not. Every other problem is reported
//! and reading goes on; a broken entry (a value without a name, a duplicate
//! robot type) is left out of the result. Diagnostics come in document order,
//! the malformed XML (where reading stopped) last.

use super::latency::{self, LatencyBound};
use super::schema::{self, TYPE_NAMES};
use super::{
    Implementation, Origin, ParamDef, Platform, ResultDef, RobotType, ServiceDef, ValueDef,
    ValueType,
};
use crate::diag::{Code, Diagnostic, FileId, Sink};
use crate::fasthash::FastMap;
use crate::span::Span;
use crate::xmlpos::{Attr, get, is_ident, suggest};
use crate::xmltree::{Elem, TreeFormat, Vocabulary, read_tree};
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
    let (root, malformed) = read_tree(
        text,
        TreeFormat {
            file,
            xml_code: Code::CatalogXml,
            empty_message: "this catalog file is empty: it needs a `<Catalog>` element",
            raw_lt: None,
        },
    );
    let mut reader = Reader {
        text,
        base_dir,
        sink: Sink::new(file),
        robot_names: FastMap::default(),
        out: ParsedCatalog::default(),
    };
    if let Some(root) = &root {
        reader.root(root);
    }
    let mut out = reader.out;
    out.diagnostics = reader.sink.into_vec();
    out.diagnostics.extend(malformed);
    out
}

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
    let mut line = String::with_capacity(s.len());
    let mut push = |word: &str| {
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    };
    // The same words either way on ASCII text without a vertical tab (which
    // only `split_whitespace` splits on); the ASCII split decodes nothing.
    if s.is_ascii() && !s.as_bytes().contains(&0x0b) {
        s.split_ascii_whitespace().for_each(&mut push);
    } else {
        s.split_whitespace().for_each(&mut push);
    }
    line
}

/// Whether the markup between two pieces of a `<Doc>`'s text separates words:
/// whitespace, or a character reference that the tree left out as blank
/// (`&#32;`); comments and processing instructions do not.
fn separates_words(mut gap: &str) -> bool {
    loop {
        let (open, close) = match (gap.find("<!--"), gap.find("<?")) {
            (Some(c), Some(p)) if p < c => (p, "?>"),
            (Some(c), _) => (c, "-->"),
            (None, Some(p)) => (p, "?>"),
            (None, None) => break,
        };
        if gap[..open].contains(|c: char| c.is_whitespace() || c == '&') {
            return true;
        }
        match gap[open..].find(close) {
            Some(end) => gap = &gap[open + end + close.len()..],
            None => return false,
        }
    }
    gap.contains(|c: char| c.is_whitespace() || c == '&')
}

/// A robot type being read, with the names used in it so far.
struct RobotBuild {
    /// False when the robot is left out (no type, duplicate type): its content is
    /// still checked.
    valid: bool,
    robot: RobotType,
    names: Vec<(String, Span)>,
    doc_at: Option<Span>,
    platform_at: Option<Span>,
    capabilities: FastMap<String, Span>,
    value_names: FastMap<String, Span>,
    service_names: FastMap<String, Span>,
}

/// A value or service being read.
struct ItemBuild<T> {
    /// `None` when the entry is left out (missing name, duplicate).
    def: Option<T>,
    /// Where the item was documented (`doc=` or an earlier `<Doc>`).
    doc_at: Option<Span>,
    param_names: FastMap<String, Span>,
    /// A service's results by name, to where each is first written.
    result_names: FastMap<String, Span>,
    /// The first optional parameter seen, for "required after optional".
    optional_seen: bool,
}

impl<T> ItemBuild<T> {
    fn new(def: Option<T>, doc_at: Option<Span>) -> Self {
        ItemBuild {
            def,
            doc_at,
            param_names: FastMap::default(),
            result_names: FastMap::default(),
            optional_seen: false,
        }
    }
}

struct Reader<'t, 'p> {
    text: &'t str,
    base_dir: Option<&'p Path>,
    sink: Sink,
    /// Robot type names and aliases of this file, to where they are first written.
    robot_names: FastMap<String, Span>,
    out: ParsedCatalog,
}

impl Reader<'_, '_> {
    // --- the walk ------------------------------------------------------------

    fn vocabulary(&self) -> Vocabulary<'static> {
        Vocabulary {
            file: self.sink.file(),
            unknown_attribute: Code::CatalogUnknownAttribute,
            unknown_element: Code::CatalogUnknownElement,
            elements: &schema::PLACES,
        }
    }

    fn root(&mut self, e: &Elem) {
        if e.local != "Catalog" {
            let message = format!(
                "a catalog file must start with `<Catalog>`, not `<{}>`",
                e.qname
            );
            self.sink
                .report(Code::CatalogUnknownElement, e.name_span, message);
            return;
        }
        self.check_attributes(e);
        self.content(e, |r, robot| r.robot(robot));
    }

    /// Reads the content of `e` in document order: each child the schema
    /// allows there is read by `read`; text and the other children are
    /// reported (E051) and their content skipped.
    fn content<'e>(&mut self, e: &'e Elem, mut read: impl FnMut(&mut Self, &'e Elem)) {
        let allowed = schema::element(&e.local).map_or(&[][..], |info| info.children);
        let vocabulary = self.vocabulary();
        let mut texts = e.texts.iter().peekable();
        for child in &e.children {
            while let Some(&text) = texts.next_if(|t| t.start < child.tag.start) {
                self.stray_text(e, text);
            }
            if allowed.contains(&child.local.as_str()) {
                read(self, child);
            } else {
                vocabulary.misplaced(&mut self.sink, e, child, allowed);
            }
        }
        for &text in texts {
            self.stray_text(e, text);
        }
    }

    fn stray_text(&mut self, e: &Elem, text: Span) {
        if e.local == "Doc" {
            return;
        }
        let message = format!(
            "text is not allowed inside `<{}>`: put descriptions in a `<Doc>` element",
            e.local
        );
        self.sink.report(Code::CatalogUnknownElement, text, message);
    }

    /// W050 for attributes that the element does not have.
    fn check_attributes(&mut self, e: &Elem) {
        let allowed = schema::element(&e.local).map_or(&[][..], |info| info.attributes);
        let vocabulary = self.vocabulary();
        vocabulary.check_attributes(&mut self.sink, e, allowed, |_| None);
    }

    /// An element without content of its own: its attributes are checked by
    /// the caller, text and children are reported.
    fn leaf(&mut self, e: &Elem) {
        self.content(e, |_, _| {});
    }

    fn origin(&self, e: &Elem) -> Origin {
        Origin {
            file: self.sink.file(),
            span: e.tag,
        }
    }

    fn robot(&mut self, e: &Elem) {
        self.check_attributes(e);
        let operator = e.local == "Operator";
        let mut build = RobotBuild {
            valid: false,
            robot: RobotType {
                name: String::new(),
                aliases: Vec::new(),
                doc: String::new(),
                platform: Platform::default(),
                capabilities: Vec::new(),
                values: Vec::new(),
                services: Vec::new(),
                origin: self.origin(e),
            },
            names: Vec::new(),
            doc_at: None,
            platform_at: None,
            capabilities: FastMap::default(),
            value_names: FastMap::default(),
            service_names: FastMap::default(),
        };
        if let Some((name, span)) = self.name_attr(e, "type") {
            if operator && name != "USER" {
                self.sink.report(
                    Code::CatalogBadAttribute,
                    span,
                    format!("the operator console is always called `USER`, not `{name}`"),
                );
            } else if let Some(&first) = self.robot_names.get(&name) {
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
        let aliases = self.aliases(e);
        if build.valid {
            for (alias, span) in aliases {
                if let Some(&first) = self.robot_names.get(&alias) {
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
        let target = if operator { "Operator" } else { "Robot" };
        self.content(e, |r, c| match c.local.as_str() {
            "Doc" => r.doc(c, target, &mut build.doc_at, &mut build.robot.doc),
            "Platform" => r.platform(c, &mut build),
            "Capability" => r.capability(c, &mut build),
            "Value" => r.value(c, &mut build),
            "Service" => r.service(c, &mut build),
            // The schema allows nothing else inside a robot.
            _ => {}
        });
        // A robot cut short by malformed XML is left out.
        if !build.valid || !e.complete {
            return;
        }
        let parsed = ParsedRobot {
            robot: build.robot,
            names: build.names,
        };
        if operator {
            self.out.operator = Some(parsed);
        } else {
            self.out.robots.push(parsed);
        }
    }

    /// A `<Doc>` of `target`: its text, unless the target is already documented.
    fn doc(&mut self, e: &Elem, target: &str, doc_at: &mut Option<Span>, doc: &mut String) {
        self.check_attributes(e);
        match *doc_at {
            Some(first) => duplicate(
                &mut self.sink,
                e.tag,
                first,
                format!("this `<{target}>` is already documented"),
            ),
            None => {
                *doc_at = Some(e.tag);
                *doc = self.doc_text(e);
            }
        }
        self.leaf(e);
    }

    /// The text of a `<Doc>` on one line, with its references and CDATA
    /// sections read (the tree keeps the positions of the non-blank pieces).
    fn doc_text(&self, e: &Elem) -> String {
        let mut text = String::new();
        let mut previous_end = None;
        for &piece in &e.texts {
            if let Some(end) = previous_end {
                // The markup between the pieces, without the (reported) elements in it.
                let mut from = end;
                let mut gap = String::new();
                for child in e
                    .children
                    .iter()
                    .filter(|c| end <= c.span.start && c.span.end <= piece.start)
                {
                    gap.push_str(&self.text[from..child.span.start]);
                    from = child.span.end;
                }
                gap.push_str(&self.text[from..piece.start]);
                if separates_words(&gap) {
                    text.push(' ');
                }
            }
            let raw = &self.text[piece.range()];
            let in_cdata = self.text[..piece.start].trim_end().ends_with("<![CDATA[");
            match quick_xml::escape::unescape(raw) {
                Ok(resolved) if !in_cdata => text.push_str(&resolved),
                _ => text.push_str(raw),
            }
            previous_end = Some(piece.end);
        }
        one_line(&text)
    }

    fn platform(&mut self, e: &Elem, robot: &mut RobotBuild) {
        self.check_attributes(e);
        if let Some(first) = robot.platform_at {
            duplicate(
                &mut self.sink,
                e.tag,
                first,
                "this robot already has a `<Platform>`",
            );
        } else {
            robot.platform_at = Some(e.tag);
            let text = |key: &str| {
                get(&e.attrs, key)
                    .map(|a| one_line(&a.value))
                    .unwrap_or_default()
            };
            let mut number = |key: &str, example: &str| -> Option<u64> {
                let a = get(&e.attrs, key)?;
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
            let (cores, clock_mhz, memory_kb) = (
                number("cores", "4").map(|n| n as u32),
                number("clockMHz", "900").map(|n| n as u32),
                number("memoryKB", "1048576"),
            );
            robot.robot.platform = Platform {
                target: self.build_target(e),
                cores,
                clock_mhz,
                memory_kb,
                os: text("os"),
                cpu: text("cpu"),
                note: text("note"),
            };
        }
        self.leaf(e);
    }

    /// `target="..."` of a `<Platform>`: a platform `semo build` knows
    /// (its simulation is the build's choice, `--sim`, not the robot's).
    fn build_target(&mut self, e: &Elem) -> Option<(crate::platform::Target, Span)> {
        let a = get(&e.attrs, "target")?;
        let name = a.trimmed();
        if let Some(target) = crate::platform::platform_target(name) {
            return Some((target, a.trimmed_span()));
        }
        let platforms: Vec<&str> = crate::platform::platform_names().collect();
        let message = match crate::platform::Target::from_name(name) {
            Some(sim) => format!(
                "`{name}` is the simulation of {}: a robot type names the platform it runs on ({}); `semo build --sim` builds its simulation",
                sim.platform().name,
                platforms.join(", ")
            ),
            None => format!(
                "unknown platform `{name}` (platforms: {})",
                platforms.join(", ")
            ),
        };
        self.sink
            .report(Code::CatalogBadAttribute, a.trimmed_span(), message)
            .suggest(suggest(name, &platforms));
        None
    }

    fn capability(&mut self, e: &Elem, robot: &mut RobotBuild) {
        self.check_attributes(e);
        if let Some((name, span)) = self.name_attr(e, "name") {
            if let Some(&first) = robot.capabilities.get(&name) {
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
        self.leaf(e);
    }

    fn value(&mut self, e: &Elem, robot: &mut RobotBuild) {
        self.check_attributes(e);
        let name = self.name_attr(e, "name");
        let ty = self.required(e, "type").map(|t| self.value_type(t, e));
        let implementation = self.implementation(e);
        let aliases = self.aliases(e);
        let (doc, doc_at) = doc_attr(e);
        let unit = get(&e.attrs, "unit")
            .map(|u| u.trimmed().to_string())
            .filter(|u| !u.is_empty());
        let def = match (name, ty) {
            (Some(name), Some(ty)) => self
                .register_item(&mut robot.value_names, "value", &name, aliases)
                .map(|aliases| ValueDef {
                    name: name.0,
                    aliases,
                    ty,
                    unit,
                    doc,
                    implementation,
                    origin: self.origin(e),
                }),
            _ => None,
        };
        let mut item = ItemBuild::new(def, doc_at);
        self.content(e, |r, c| r.item_doc(c, "Value", &mut item));
        if let Some(def) = item.def {
            robot.robot.values.push(def);
        }
    }

    fn service(&mut self, e: &Elem, robot: &mut RobotBuild) {
        self.check_attributes(e);
        let name = self.name_attr(e, "name");
        let implementation = self.implementation(e);
        let aliases = self.aliases(e);
        let (doc, doc_at) = doc_attr(e);
        let def = name.and_then(|name| {
            self.register_item(&mut robot.service_names, "service", &name, aliases)
                .map(|aliases| ServiceDef {
                    name: name.0,
                    aliases,
                    params: Vec::new(),
                    results: Vec::new(),
                    doc,
                    implementation,
                    latency: Vec::new(),
                    origin: self.origin(e),
                })
        });
        let mut item = ItemBuild::new(def, doc_at);
        self.content(e, |r, c| match c.local.as_str() {
            "Param" => r.param(c, &mut item),
            "Result" => r.result(c, &mut item),
            "Latency" => r.latency(c, &mut item),
            _ => r.item_doc(c, "Service", &mut item),
        });
        if let Some(def) = item.def {
            robot.robot.services.push(def);
        }
    }

    /// The `<Doc>` of a value or service (kept only when the entry is).
    fn item_doc<T: Documented>(&mut self, e: &Elem, target: &str, item: &mut ItemBuild<T>) {
        let mut left_out = String::new();
        let doc = item.def.as_mut().map_or(&mut left_out, T::doc_mut);
        self.doc(e, target, &mut item.doc_at, doc);
    }

    /// A `<Latency>` bound of a service: its tasks are names of the
    /// service's graph (checked against the graph where it is analysed,
    /// `crate::dataflow`); its time is read here.
    fn latency(&mut self, e: &Elem, service: &mut ItemBuild<ServiceDef>) {
        self.check_attributes(e);
        let from = self.required(e, "from");
        let to = self.required(e, "to");
        let max = self.required(e, "max").and_then(|a| {
            latency::parse_time(a.trimmed())
                .map_err(|why| self.sink.report(Code::CatalogBadAttribute, a.span, why))
                .ok()
        });
        self.leaf(e);
        let Some(def) = service.def.as_mut() else {
            return;
        };
        if !matches!(def.implementation, Implementation::Graph(_)) {
            self.sink.report(
                Code::CatalogBadAttribute,
                e.tag,
                format!(
                    "a latency bound is stated on a task graph: `{}` is not implemented by one (give it `graph=\"…\"`)",
                    def.name
                ),
            );
            return;
        }
        if let (Some(from), Some(to), Some(max)) = (from, to, max) {
            def.latency.push(LatencyBound {
                from: (from.trimmed().to_string(), from.trimmed_span()),
                to: (to.trimmed().to_string(), to.trimmed_span()),
                max,
                span: e.tag,
            });
        }
    }

    fn param(&mut self, e: &Elem, service: &mut ItemBuild<ServiceDef>) {
        self.check_attributes(e);
        let name = self.name_attr(e, "name");
        let ty = self.required(e, "type").map(|t| self.value_type(t, e));
        let optional = match get(&e.attrs, "optional") {
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
        if let (Some((name, span)), Some(ty)) = (name, ty) {
            self.add_param(service, name, span, ty, optional);
        }
        self.leaf(e);
    }

    /// A `<Result>` of a service: a name missions bind (an identifier, E056
    /// otherwise; twice in one service E053) and a value type, read as a
    /// `<Value>`'s.
    fn result(&mut self, e: &Elem, service: &mut ItemBuild<ServiceDef>) {
        self.check_attributes(e);
        let name = self.name_attr(e, "name");
        let ty = self.required(e, "type").map(|t| self.value_type(t, e));
        let (doc, _) = doc_attr(e);
        self.leaf(e);
        let (Some((name, span)), Some(ty)) = (name, ty) else {
            return;
        };
        if let Some(&first) = service.result_names.get(&name) {
            duplicate(
                &mut self.sink,
                span,
                first,
                format!("this service already has a result `{name}`"),
            );
            return;
        }
        service.result_names.insert(name.clone(), span);
        if let Some(def) = service.def.as_mut() {
            def.results.push(ResultDef { name, ty, doc });
        }
    }

    fn add_param(
        &mut self,
        service: &mut ItemBuild<ServiceDef>,
        name: String,
        span: Span,
        ty: ValueType,
        optional: bool,
    ) {
        if let Some(&first) = service.param_names.get(&name) {
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

    // --- attributes ----------------------------------------------------------

    /// Required attribute: E052 when missing, E056 when empty.
    fn required<'e>(&mut self, e: &'e Elem, key: &str) -> Option<&'e Attr> {
        match get(&e.attrs, key) {
            None => {
                self.sink.report(
                    Code::CatalogMissingAttribute,
                    e.tag,
                    format!("this `<{}>` needs a `{key}` attribute", e.local),
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

    /// The name from a required attribute, checked.
    fn name_attr(&mut self, e: &Elem, key: &str) -> Option<(String, Span)> {
        let a = self.required(e, key)?;
        let name = a.trimmed().to_string();
        self.check_name(&name, a.span).then_some((name, a.span))
    }

    /// The aliases of a robot, value or service, checked as names.
    fn aliases(&mut self, e: &Elem) -> Vec<(String, Span)> {
        let Some(a) = get(&e.attrs, "aliases") else {
            return Vec::new();
        };
        a.words()
            .into_iter()
            .filter(|(w, span)| self.check_name(w, *span))
            .collect()
    }

    /// E053 for a value or service name (or alias) already used in this robot.
    /// Returns the aliases that are free.
    fn register_item(
        &mut self,
        names: &mut FastMap<String, Span>,
        what: &str,
        name: &(String, Span),
        aliases: Vec<(String, Span)>,
    ) -> Option<Vec<String>> {
        if let Some(&first) = names.get(&name.0) {
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
            if let Some(&first) = names.get(&alias) {
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

    /// The type of a value or parameter (`type=` and `domain=`). Falls back to
    /// `string` after an error so that missions using it are not flooded.
    fn value_type(&mut self, ty: &Attr, e: &Elem) -> ValueType {
        let name = ty.trimmed();
        let domain = get(&e.attrs, "domain");
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
            let mut seen: FastMap<&str, Span> = FastMap::default();
            let mut values = Vec::new();
            for (w, span) in &words {
                if !self.check_name(w, *span) {
                    continue;
                }
                if let Some(&first) = seen.get(w.as_str()) {
                    duplicate(
                        &mut self.sink,
                        *span,
                        first,
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
    fn implementation(&mut self, e: &Elem) -> Implementation {
        let task = get(&e.attrs, "task");
        let graph = get(&e.attrs, "graph");
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
}

/// `doc=` of a value or service, and where it is written.
fn doc_attr(e: &Elem) -> (String, Option<Span>) {
    match get(&e.attrs, "doc") {
        Some(a) => (one_line(&a.value), Some(a.span)),
        None => (String::new(), None),
    }
}

/// A catalog entry with a doc text.
trait Documented {
    fn doc_mut(&mut self) -> &mut String;
}

impl Documented for ValueDef {
    fn doc_mut(&mut self) -> &mut String {
        &mut self.doc
    }
}

impl Documented for ServiceDef {
    fn doc_mut(&mut self) -> &mut String {
        &mut self.doc
    }
}

#[cfg(test)]
mod tests;
