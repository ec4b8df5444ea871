//! A positioned XML element tree, read with quick-xml: every element, attribute
//! and attribute value keeps its byte range. The catalog, task-graph and
//! strategy loaders read a file into this tree first, then read the tree as
//! their model. The
//! walk under the tree ([`walk`], [`Visit`]) is for a loader that reads the
//! elements as they come instead (SDF3 graphs, large ones): the same
//! well-formedness checks and positions without holding the tree.
//!
//! Malformed XML is reported with the format's own code and stops reading; what
//! was read before the error is kept, the elements left open marked incomplete.

use crate::diag::{Code, Diagnostic, FileId, Sink};
use crate::span::Span;
use crate::xmlpos::{
    self, Attr, StartTag, read_attributes_into, read_attributes_keeping_lt_into, resolve_reference,
    trim_span, xml_error_message,
};
use quick_xml::encoding::Decoder;
use quick_xml::errors::SyntaxError;
use quick_xml::events::{BytesEnd, BytesStart, Event};

/// The deepest an element may be nested, the root being at depth 1 (E097):
/// libxml2's default. SeMo's formats need a few levels (a loop body's
/// `<TaskGraph>` inside its `<Loop>` adds two per loop), and what the
/// loaders build from the tree, its own drop included, recurses on its
/// depth: bounded here, it stays far from any thread's stack.
pub const MAX_DEPTH: usize = 256;

/// One element as written.
#[derive(Debug)]
pub(crate) struct Elem {
    pub qname: smol_str::SmolStr,
    /// The name without a namespace prefix.
    pub local: smol_str::SmolStr,
    pub name_span: Span,
    /// The start tag, `<` to `>`.
    pub tag: Span,
    /// The whole element, to the end of its end tag (or to where reading stopped).
    pub span: Span,
    pub attrs: Vec<Attr>,
    pub children: Vec<Elem>,
    /// Non-blank text directly inside, trimmed.
    pub texts: Vec<Span>,
    /// Closed by its end tag or `/>`; false when malformed XML stopped reading
    /// inside it.
    pub complete: bool,
}

/// How one format reports what the tree reader finds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TreeFormat<'a> {
    pub file: FileId,
    /// The code of "not well-formed XML".
    pub xml_code: Code,
    /// The message for a file with no element at all.
    pub empty_message: &'a str,
    /// `Some(code)`: a `<` written inside an attribute value (quick-xml reads
    /// it; XML forbids it) is reported with this code, pointing at the `<`,
    /// and reading goes on. `None`: it is malformed XML and reading stops.
    pub raw_lt: Option<Code>,
}

/// Reads `text` into its root element (with everything read before any XML
/// error) and the diagnostics of malformed XML.
pub(crate) fn read_tree(text: &str, format: TreeFormat<'_>) -> (Option<Elem>, Vec<Diagnostic>) {
    let mut tree = TreeCollector::default();
    let diagnostics = walk(text, format, &mut tree);
    (tree.root, diagnostics)
}

/// What a reader does with the elements as they are read, in document order,
/// instead of holding the whole tree: a loader that needs only some elements
/// keeps only what it needs (the SDF3 reader).
pub(crate) trait Visit {
    /// A start tag: `elem` has its names, ranges and attributes, no children
    /// or texts, and `span` is its tag. Its [`Visit::close`] follows after
    /// its content (at once for `<a/>`).
    fn open(&mut self, elem: &Elem);
    /// The end of the element opened last: `span` is now the whole element,
    /// `complete` false when malformed XML stopped reading inside it. The
    /// visitor may take what it keeps (its attributes) out of `elem`.
    fn close(&mut self, elem: &mut Elem);
    /// Non-blank text directly inside the element opened last, trimmed.
    fn text(&mut self, span: Span);
}

/// Walks `text` with quick-xml, checking that it is well-formed, and tells
/// `visitor` the elements; returns the diagnostics of malformed XML. Elements
/// left open by an error are closed as incomplete, innermost first.
pub(crate) fn walk(
    text: &str,
    format: TreeFormat<'_>,
    visitor: &mut impl Visit,
) -> Vec<Diagnostic> {
    let mut walker = Walker {
        text,
        diagnostics: Sink::quoting_xml(format.file),
        format,
        stack: Vec::new(),
        root: None,
        spare: Vec::new(),
        visitor,
    };
    let stopped_at = walker.run();
    while let Some(mut open) = walker.stack.pop() {
        open.span = Span::new(open.tag.start, stopped_at.max(open.tag.end));
        open.complete = false;
        walker.close(open);
    }
    walker.diagnostics.into_vec()
}

/// The [`Visit`] that keeps every element: the tree of [`read_tree`].
#[derive(Default)]
pub(crate) struct TreeCollector {
    /// Per open element, the children and texts read so far.
    open: Vec<(Vec<Elem>, Vec<Span>)>,
    root: Option<Elem>,
}

impl TreeCollector {
    /// The root element read, if any.
    pub fn into_root(self) -> Option<Elem> {
        self.root
    }
}

impl Visit for TreeCollector {
    fn open(&mut self, _: &Elem) {
        self.open.push((Vec::new(), Vec::new()));
    }

    fn close(&mut self, elem: &mut Elem) {
        let (children, texts) = self.open.pop().unwrap_or_default();
        let elem = Elem {
            qname: elem.qname.clone(),
            local: elem.local.clone(),
            name_span: elem.name_span,
            tag: elem.tag,
            span: elem.span,
            attrs: std::mem::take(&mut elem.attrs),
            children,
            texts,
            complete: elem.complete,
        };
        match self.open.last_mut() {
            Some((siblings, _)) => siblings.push(elem),
            None => {
                if self.root.is_none() {
                    self.root = Some(elem);
                }
            }
        }
    }

    fn text(&mut self, span: Span) {
        if let Some((_, texts)) = self.open.last_mut() {
            texts.push(span);
        }
    }
}

/// A diagnostic whose message is one line, whatever text it quotes.
pub(crate) fn one_line_diagnostic(
    code: Code,
    file: FileId,
    span: Span,
    message: impl Into<String>,
) -> Diagnostic {
    let message: String = message
        .into()
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    Diagnostic::new(code, file, span, message)
}

/// What a format reports of the elements and attributes it does not know,
/// once the tree is read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vocabulary<'a> {
    pub file: FileId,
    /// The code of an attribute an element does not have.
    pub unknown_attribute: Code,
    /// The code of an element not allowed where it is written, and of text.
    pub unknown_element: Code,
    /// Every element of the format, with where it belongs.
    pub elements: &'a [(&'a str, &'a str)],
}

impl Vocabulary<'_> {
    /// Reports the attributes of `e` not among `allowed` (nor namespace
    /// declarations); `hint` may name the attribute meant before the nearest
    /// of `allowed` is guessed.
    pub fn check_attributes(
        &self,
        out: &mut Vec<Diagnostic>,
        e: &Elem,
        allowed: &[&str],
        hint: impl Fn(&str) -> Option<String>,
    ) {
        for a in &e.attrs {
            if xmlpos::is_namespace_attribute(&a.key) || allowed.contains(&a.key.as_str()) {
                continue;
            }
            let message = format!(
                "`<{}>` has no attribute `{}`; it is ignored",
                e.local, a.key
            );
            let suggestion = hint(&a.key).or_else(|| xmlpos::suggest(&a.key, allowed));
            let mut d = one_line_diagnostic(self.unknown_attribute, self.file, a.key_span, message);
            d.suggest(suggestion);
            out.push(d);
        }
    }

    /// The children of `e` among `allowed`; the others, and text, reported.
    pub fn children<'e>(
        &self,
        out: &mut Vec<Diagnostic>,
        e: &'e Elem,
        allowed: &[&str],
    ) -> Vec<&'e Elem> {
        let code = self.unknown_element;
        if let Some(&text) = e.texts.first() {
            let message = format!("text is not allowed inside `<{}>`", e.local);
            out.push(one_line_diagnostic(code, self.file, text, message));
        }
        let mut children = Vec::new();
        for c in &e.children {
            if allowed.contains(&c.local.as_str()) {
                children.push(c);
            } else {
                self.misplaced(out, e, c, allowed);
            }
        }
        children
    }

    /// Reports `child`, an element of `parent` not among `allowed`: a known
    /// element written in the wrong place, or an unknown one.
    pub fn misplaced(
        &self,
        out: &mut Vec<Diagnostic>,
        parent: &Elem,
        child: &Elem,
        allowed: &[&str],
    ) {
        let code = self.unknown_element;
        match self.elements.iter().find(|(name, _)| *name == child.local) {
            Some((name, belongs)) => {
                let message = format!(
                    "`<{name}>` is not allowed inside `<{}>`: it goes {belongs}",
                    parent.local
                );
                out.push(one_line_diagnostic(
                    code,
                    self.file,
                    child.name_span,
                    message,
                ));
            }
            None => {
                let message = if allowed.is_empty() {
                    format!(
                        "unknown element `<{}>`: `<{}>` cannot contain elements",
                        child.qname, parent.local
                    )
                } else {
                    format!(
                        "unknown element `<{}>` inside `<{}>`",
                        child.qname, parent.local
                    )
                };
                let mut d = one_line_diagnostic(code, self.file, child.name_span, message);
                d.suggest(xmlpos::suggest(&child.local, allowed));
                out.push(d);
            }
        }
    }
}

/// Malformed XML: stop reading the file.
struct Stop;

type Flow = Result<(), Stop>;

struct Walker<'t, 'f, 'v, V> {
    text: &'t str,
    format: TreeFormat<'f>,
    diagnostics: Sink,
    /// The elements open, outermost first (without children).
    stack: Vec<Elem>,
    /// The root element's name, once it is read.
    root: Option<smol_str::SmolStr>,
    /// Attribute lists of closed elements, reused for the next ones.
    spare: Vec<Vec<Attr>>,
    visitor: &'v mut V,
}

impl<V: Visit> Walker<'_, '_, '_, V> {
    /// Reads events until the end or an error; returns where reading stopped.
    fn run(&mut self) -> usize {
        let text = self.text;
        let mut reader = xmlpos::reader(text);
        let decoder = reader.decoder();
        loop {
            let before = xmlpos::offset(text, reader.buffer_position());
            let event = reader.read_event();
            let end = xmlpos::offset(text, reader.buffer_position());
            let flow = match event {
                Err(err) => {
                    let pos = xmlpos::offset(text, reader.error_position());
                    let unclosed =
                        matches!(err, quick_xml::Error::Syntax(SyntaxError::UnclosedTag));
                    let (span, message) = match xmlpos::lt_in_unclosed_tag(text, pos) {
                        Some(lt) if unclosed => (lt, xmlpos::LT_IN_VALUE.to_string()),
                        _ => (xmlpos::word_at(text, pos), xml_error_message(&err)),
                    };
                    self.diagnostics.report(self.format.xml_code, span, message);
                    return pos.max(before);
                }
                Ok(Event::Eof) => {
                    self.eof();
                    return text.len();
                }
                Ok(Event::Start(e)) => self.start(&e, end, false, decoder),
                Ok(Event::Empty(e)) => self.start(&e, end, true, decoder),
                Ok(Event::End(e)) => self.end(&e, end),
                Ok(Event::Text(t)) => {
                    let span = xmlpos::slice_span(text, &t).unwrap_or(Span::new(end, end));
                    match t.decode() {
                        Ok(s) => self.text_content(&s, span),
                        Err(_) => self.malformed(span, "this text is not valid UTF-8"),
                    }
                }
                Ok(Event::CData(t)) => {
                    let span = xmlpos::slice_span(text, &t).unwrap_or(Span::new(end, end));
                    match t.decode() {
                        Ok(s) => self.text_content(&s, span),
                        Err(_) => self.malformed(span, "this text is not valid UTF-8"),
                    }
                }
                Ok(Event::GeneralRef(r)) => {
                    let (span, resolved) = resolve_reference(text, &r, end);
                    match resolved {
                        Ok(s) => self.text_content(&s, span),
                        Err(message) => self.malformed(span, message),
                    }
                }
                Ok(Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_)) => Ok(()),
            };
            if flow.is_err() {
                return end.max(before);
            }
        }
    }

    fn malformed(&mut self, span: Span, message: impl Into<String>) -> Flow {
        self.diagnostics.report(self.format.xml_code, span, message);
        Err(Stop)
    }

    /// Tells the visitor that `elem` ends, keeping its attribute list for
    /// reuse when the visitor left it.
    fn close(&mut self, mut elem: Elem) {
        self.visitor.close(&mut elem);
        if elem.attrs.capacity() > 0 {
            elem.attrs.clear();
            self.spare.push(elem.attrs);
        }
    }

    fn eof(&mut self) {
        if let Some(open) = self.stack.last() {
            let message = xmlpos::never_closed(&open.qname);
            let tag = open.tag;
            self.diagnostics.report(self.format.xml_code, tag, message);
        } else if self.root.is_none() {
            let end = self.text.len();
            self.diagnostics.report(
                self.format.xml_code,
                Span::new(end, end),
                self.format.empty_message,
            );
        }
    }

    fn text_content(&mut self, s: &str, span: Span) -> Flow {
        // A byte-order mark counts as blank.
        if s.trim_matches(|c: char| c.is_whitespace() || c == '\u{feff}')
            .is_empty()
        {
            return Ok(());
        }
        let span = trim_span(s, span);
        match self.stack.last() {
            Some(_) => {
                self.visitor.text(span);
                Ok(())
            }
            None => self.malformed(
                span,
                "text outside the root element: only comments may go there",
            ),
        }
    }

    fn attributes(
        &mut self,
        e: &BytesStart<'_>,
        tag: Span,
        decoder: Decoder,
    ) -> Result<Vec<Attr>, Stop> {
        let mut attrs = self.spare.pop().unwrap_or_default();
        let Some(code) = self.format.raw_lt else {
            return read_attributes_into(self.text, e, tag, decoder, &mut attrs)
                .map(|()| attrs)
                .map_err(|(span, message)| self.report_stop(span, message));
        };
        let raw_lt = read_attributes_keeping_lt_into(self.text, e, tag, decoder, &mut attrs)
            .map_err(|(span, message)| self.report_stop(span, message))?;
        for at in raw_lt {
            let value = attrs
                .iter()
                .find(|a| a.span.start <= at && at < a.span.end)
                .map(|a| {
                    let mut fixed = String::from(&self.text[a.span.start..at]);
                    fixed.push_str("&lt;");
                    fixed.push_str(&self.text[at + 1..a.span.end]);
                    format!(" ({}=\"{}\")", a.key, xmlpos::shown(&fixed))
                })
                .unwrap_or_default();
            self.diagnostics.report(
                code,
                Span::new(at, at + 1),
                format!("XML does not allow a plain `<` inside an attribute value: write `&lt;` instead{value}"),
            )
            .suggestion = Some("&lt;".to_string());
        }
        Ok(attrs)
    }

    fn report_stop(&mut self, span: Span, message: String) -> Stop {
        self.diagnostics.report(self.format.xml_code, span, message);
        Stop
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
        if self.stack.len() == MAX_DEPTH {
            return self.too_deep(name_span, &qname);
        }
        let attrs = self.attributes(e, tag, decoder)?;
        if self.stack.is_empty() {
            if let Some(root) = &self.root {
                let message = format!(
                    "`<{qname}>` comes after the end of `<{root}>`: a file has a single root element"
                );
                return self.malformed(name_span, message);
            }
            self.root = Some(qname.clone());
        }
        let elem = Elem {
            qname,
            local,
            name_span,
            tag,
            span: tag,
            attrs,
            children: Vec::new(),
            texts: Vec::new(),
            complete: empty,
        };
        self.visitor.open(&elem);
        if empty {
            self.close(elem);
        } else {
            self.stack.push(elem);
        }
        Ok(())
    }

    /// An element nested deeper than [`MAX_DEPTH`]: reading stops there, the
    /// elements around it closed as incomplete.
    fn too_deep(&mut self, name_span: Span, qname: &str) -> Flow {
        let message = format!(
            "`<{qname}>` is nested {} elements deep; SeMo reads XML nested at most {MAX_DEPTH} deep, and stops reading here",
            MAX_DEPTH + 1
        );
        self.diagnostics
            .report(Code::XmlTooDeep, name_span, message);
        Err(Stop)
    }

    fn end(&mut self, e: &BytesEnd<'_>, tag_end: usize) -> Flow {
        let (span, name) = xmlpos::end_tag(self.text, e, tag_end);
        match self.stack.pop() {
            None => self.malformed(span, xmlpos::unopened_close(&name)),
            Some(open) if open.qname != name => {
                let (message, opened) = xmlpos::mismatched_close(&name, &open.qname);
                let code = self.format.xml_code;
                self.diagnostics
                    .report(code, span, message)
                    .relate(open.tag, opened);
                // Left open: the caller closes it as incomplete.
                self.stack.push(open);
                Err(Stop)
            }
            Some(mut open) => {
                open.span = Span::new(open.tag.start, span.end);
                open.complete = true;
                self.close(open);
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(raw_lt: Option<Code>) -> TreeFormat<'static> {
        TreeFormat {
            file: FileId(1),
            xml_code: Code::GraphXml,
            empty_message: "empty",
            raw_lt,
        }
    }

    #[test]
    fn a_raw_lt_in_a_value_stops_reading_or_is_reported_and_kept() {
        let text = r#"<A><B cond="x<2" k="y &lt; 3"/><C/></A>"#;
        let (root, diags) = read_tree(text, format(None));
        assert_eq!(diags.len(), 1);
        assert_eq!(diags[0].code, Code::GraphXml);
        assert_eq!(&text[diags[0].span.range()], "<");
        assert_eq!(diags[0].span.start, text.find("x<").unwrap() + 1);
        assert!(root.unwrap().children.is_empty());

        let (root, diags) = read_tree(text, format(Some(Code::GraphBadAttribute)));
        assert_eq!(diags.len(), 1, "{diags:#?}");
        assert_eq!(diags[0].code, Code::GraphBadAttribute);
        assert_eq!(diags[0].span.start, text.find("x<").unwrap() + 1);
        assert_eq!(diags[0].suggestion.as_deref(), Some("&lt;"));
        assert!(
            diags[0].message.contains("cond=\"x&lt;2\""),
            "{}",
            diags[0].message
        );
        let root = root.unwrap();
        assert_eq!(root.children.len(), 2);
        assert_eq!(root.children[0].attrs[0].value, "x<2");
        assert_eq!(root.children[0].attrs[1].value, "y < 3");
    }

    #[test]
    fn a_raw_lt_before_a_broken_tag_is_a_missing_quote() {
        // The value runs into the next tag, and the tag never closes.
        let unclosed = "<A><B cond=\"x<2/>\n<C k=\"1\"/></A>";
        // The value runs into the next tag, and its attributes are malformed.
        let malformed = "<A><B cond=\"x<2/>\n<C k=\"1\" j=\"2\"/></A>";
        for text in [unclosed, malformed] {
            for raw_lt in [None, Some(Code::GraphBadAttribute)] {
                let (_, diags) = read_tree(text, format(raw_lt));
                assert_eq!(diags.len(), 1, "{diags:#?}");
                assert_eq!(diags[0].code, Code::GraphXml);
                assert!(diags[0].message.contains("closing quote"), "{diags:#?}");
                assert_eq!(diags[0].span.start, text.find("x<").unwrap() + 1);
            }
        }
    }

    /// `<r>` and `levels` nested `<x>`, closed.
    fn nested(levels: usize) -> String {
        ["<r>", &"<x>".repeat(levels), &"</x>".repeat(levels), "</r>"].concat()
    }

    #[test]
    fn nesting_past_the_limit_stops_reading_at_the_element_past_it() {
        let (root, diags) = read_tree(&nested(MAX_DEPTH - 1), format(None));
        assert!(diags.is_empty(), "{diags:#?}");
        assert!(root.unwrap().complete);
        // A million levels: one diagnostic, on the name of the element past
        // the limit, and a tree as deep as the limit, dropped without
        // recursing past it.
        let text = nested(1_000_000);
        let (root, diags) = read_tree(&text, format(None));
        assert_eq!(diags.len(), 1, "{diags:#?}");
        assert_eq!(diags[0].code, Code::XmlTooDeep);
        let name = "<r>".len() + (MAX_DEPTH - 1) * "<x>".len() + 1;
        assert_eq!(diags[0].span, Span::new(name, name + 1));
        let mut depth = 0;
        let mut elem = root.as_ref();
        while let Some(e) = elem {
            assert!(!e.complete);
            depth += 1;
            elem = e.children.first();
        }
        assert_eq!(depth, MAX_DEPTH);
    }

    #[test]
    fn unclosed_elements_are_kept_incomplete() {
        let text = "<A><B/><C>";
        let (root, diags) = read_tree(text, format(None));
        assert_eq!(diags.len(), 1);
        assert!(diags[0].message.contains("`<C>` is never closed"));
        let root = root.unwrap();
        assert!(!root.complete);
        assert!(root.children[0].complete);
        assert!(!root.children[1].complete);
        let (root, diags) = read_tree("  ", format(None));
        assert!(root.is_none());
        assert_eq!(diags[0].message, "empty");
    }
}
