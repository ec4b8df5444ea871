//! Byte positions for XML read with quick-xml, shared by the catalog and the
//! task-graph loaders. The reader borrows the text (`Reader::from_str`), so every
//! name and attribute value it hands out is a slice of the text and its range is
//! found by pointer arithmetic ([`slice_span`]).

use crate::span::Span;
use crate::suggest::{did_you_mean, edit_distance};
use quick_xml::encoding::Decoder;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesRef, BytesStart};

/// One attribute as written.
#[derive(Clone, Debug)]
pub(crate) struct Attr {
    pub key: String,
    pub key_span: Span,
    /// The value with entities replaced.
    pub value: String,
    /// The byte range of the value (between the quotes).
    pub span: Span,
    /// Whether `value` is byte-for-byte the text at `span` (no entities), so that
    /// positions inside the value can be computed.
    pub exact: bool,
}

impl Attr {
    /// The whitespace- or comma-separated words of the value, each with its range.
    pub fn words(&self) -> Vec<(String, Span)> {
        let mut out = Vec::new();
        let mut start: Option<usize> = None;
        let is_sep = |c: char| c.is_whitespace() || c == ',';
        for (i, c) in self.value.char_indices().chain([(self.value.len(), ' ')]) {
            match (start, is_sep(c)) {
                (None, false) => start = Some(i),
                (Some(s), true) => {
                    out.push((self.value[s..i].to_string(), self.sub_span(s, i)));
                    start = None;
                }
                _ => {}
            }
        }
        out
    }

    /// The range of `value[start..end]`, or the whole value when entities make
    /// the positions inexact.
    pub fn sub_span(&self, start: usize, end: usize) -> Span {
        if self.exact && start <= end && end <= self.span.len() {
            Span::new(self.span.start + start, self.span.start + end)
        } else {
            self.span
        }
    }

    pub fn trimmed(&self) -> &str {
        self.value.trim()
    }

    /// The range of the trimmed value (the whole value when it is blank or inexact).
    pub fn trimmed_span(&self) -> Span {
        let lead = self.value.len() - self.value.trim_start().len();
        let end = lead + self.trimmed().len();
        if end == lead {
            return self.span;
        }
        self.sub_span(lead, end)
    }
}

pub(crate) fn get<'a>(attrs: &'a [Attr], key: &str) -> Option<&'a Attr> {
    attrs.iter().find(|a| a.key == key)
}

/// Namespace declarations and prefixed attributes (`xmlns`, `xsi:...`): allowed
/// on every element of every format.
pub(crate) fn is_namespace_attribute(key: &str) -> bool {
    key == "xmlns" || key.contains(':')
}

/// The byte range of `slice` if it borrows from `text`.
/// The range of an end tag `</name>`: `name` is the tag's name (a slice of
/// `text`) and `tag_end` where the tag ends.
pub(crate) fn end_tag_span(text: &str, name: &[u8], tag_end: usize) -> Span {
    let name_span = slice_span(text, name).unwrap_or(Span::new(tag_end, tag_end));
    Span::new(
        name_span.start.saturating_sub(2),
        tag_end.max(name_span.end),
    )
}

/// The message for `</name>` with no element open.
pub(crate) fn unopened_close(name: &str) -> String {
    format!("`</{name}>` closes an element that was never opened")
}

/// The message for `</name>` while `<open>` is the element open, and the
/// label for where `<open>` was opened.
pub(crate) fn mismatched_close(name: &str, open: &str) -> (String, String) {
    (
        format!("`</{name}>` does not match the open `<{open}>`: close it first with `</{open}>`"),
        format!("`<{open}>` opened here"),
    )
}

pub(crate) fn slice_span(text: &str, slice: &[u8]) -> Option<Span> {
    let base = text.as_ptr() as usize;
    let ptr = slice.as_ptr() as usize;
    if ptr >= base && ptr + slice.len() <= base + text.len() {
        Some(Span::new(ptr - base, ptr - base + slice.len()))
    } else {
        None
    }
}

/// A short range at `pos` for an error position: the word starting there.
pub(crate) fn word_at(text: &str, pos: usize) -> Span {
    let mut pos = pos.min(text.len());
    while !text.is_char_boundary(pos) {
        pos -= 1;
    }
    let mut end = pos;
    for (i, c) in text[pos..].char_indices() {
        if i > 0 && (c.is_whitespace() || c == '<' || i >= 40) {
            break;
        }
        end = pos + i + c.len_utf8();
        if c == '>' {
            break;
        }
    }
    Span::new(pos, end)
}

/// `span` without the surrounding whitespace of `s` (the text at `span`), when
/// `s` is exactly that text.
pub(crate) fn trim_span(s: &str, span: Span) -> Span {
    if span.len() != s.len() {
        return span;
    }
    let lead = s.len() - s.trim_start().len();
    let trail = s.len() - s.trim_end().len();
    if lead + trail >= s.len() {
        return span;
    }
    Span::new(span.start + lead, span.end - trail)
}

/// A plain one-line message for a quick-xml error.
pub(crate) fn xml_error_message(err: &quick_xml::Error) -> String {
    use quick_xml::Error as E;
    use quick_xml::errors::{IllFormedError, SyntaxError};
    match err {
        E::Syntax(SyntaxError::UnclosedTag) => {
            "this tag is never closed: a `>` is missing".to_string()
        }
        E::Syntax(SyntaxError::UnclosedComment) => {
            "this comment is never closed: `-->` is missing".to_string()
        }
        E::Syntax(SyntaxError::UnclosedCData) => {
            "this CDATA section is never closed: `]]>` is missing".to_string()
        }
        E::Syntax(SyntaxError::UnclosedDoctype) => {
            "this DOCTYPE is never closed: a `>` is missing".to_string()
        }
        E::Syntax(SyntaxError::UnclosedPIOrXmlDecl) => {
            "this `<?...` declaration is never closed: `?>` is missing".to_string()
        }
        E::Syntax(SyntaxError::InvalidBangMarkup) => {
            "`<!` must start a comment `<!-- ... -->`".to_string()
        }
        E::IllFormed(IllFormedError::UnclosedReference) => {
            "a `&` must start an entity such as `&amp;`, ended by `;`".to_string()
        }
        E::IllFormed(IllFormedError::DoubleHyphenInComment) => {
            "a comment cannot contain `--`".to_string()
        }
        E::IllFormed(IllFormedError::MismatchedEndTag { expected, found }) => {
            format!("`</{found}>` does not close `<{expected}>`")
        }
        E::IllFormed(IllFormedError::UnmatchedEndTag(found)) => {
            format!("`</{found}>` closes an element that was never opened")
        }
        other => format!("the file is not well-formed XML: {other}"),
    }
}

/// The name range and the start-tag range (`<` to `>`) of a start tag whose
/// event ended at `tag_end`.
pub(crate) fn start_tag_spans(text: &str, e: &BytesStart<'_>, tag_end: usize) -> (Span, Span) {
    let qname = e.name();
    let name_span = slice_span(text, qname.as_ref()).unwrap_or(Span::new(tag_end, tag_end));
    let tag = Span::new(
        name_span.start.saturating_sub(1),
        tag_end.max(name_span.end),
    );
    (name_span, tag)
}

/// The attributes of a start tag (`tag` is its range), with their ranges. A
/// malformed attribute list gives the range and message of the first error.
pub(crate) fn read_attributes(
    text: &str,
    e: &BytesStart<'_>,
    tag: Span,
    decoder: Decoder,
) -> Result<Vec<Attr>, (Span, String)> {
    let mut out = Vec::new();
    // Attribute error positions count from the byte after `<`.
    let content_start = tag.start + 1;
    for attr in e.attributes() {
        let attr = match attr {
            Ok(a) => a,
            Err(err) => {
                let (pos, message) = match err {
                    AttrError::ExpectedEq(p) => (
                        p,
                        "an attribute name must be followed by `=` and a value in quotes"
                            .to_string(),
                    ),
                    AttrError::ExpectedValue(p) => {
                        (p, "`=` must be followed by a value in quotes".to_string())
                    }
                    AttrError::UnquotedValue(p) => (
                        p,
                        "an attribute value must be in quotes, like name=\"value\"".to_string(),
                    ),
                    AttrError::ExpectedQuote(p, q) => (
                        p,
                        format!(
                            "this attribute value is never closed: a `{}` is missing",
                            q as char
                        ),
                    ),
                    AttrError::Duplicated(p, _) => (
                        p,
                        "this attribute is given twice on the same element".to_string(),
                    ),
                };
                return Err((word_at(text, content_start + pos), message));
            }
        };
        let key = String::from_utf8_lossy(attr.key.as_ref()).into_owned();
        let key_span = slice_span(text, attr.key.as_ref()).unwrap_or(tag);
        let raw: &[u8] = &attr.value;
        let span = slice_span(text, raw).unwrap_or(tag);
        if let Some(p) = raw.iter().position(|&b| b == b'<') {
            let at = span.start + p;
            let span = if text.len() > at {
                Span::new(at, at + 1)
            } else {
                span
            };
            return Err((
                span,
                "a `<` inside an attribute value: is a closing quote missing? (write `&lt;` for a plain `<`)"
                    .to_string(),
            ));
        }
        let value = match attr.decode_and_unescape_value(decoder) {
            Ok(v) => v.into_owned(),
            Err(_) => {
                return Err((
                    span,
                    "this value has an unknown `&...;` entity: write `&amp;` for a plain `&`"
                        .to_string(),
                ));
            }
        };
        let exact = value.as_bytes() == raw;
        out.push(Attr {
            key,
            key_span,
            value,
            span,
            exact,
        });
    }
    Ok(out)
}

/// A `&name;` or `&#N;` reference in text: the character(s) it stands for, or
/// the message for an unknown one. `event_end` is where the event ended.
pub(crate) fn resolve_reference(
    text: &str,
    r: &BytesRef<'_>,
    event_end: usize,
) -> (Span, Result<String, String>) {
    let inner = slice_span(text, r).unwrap_or(Span::new(event_end, event_end));
    let span = Span::new(inner.start.saturating_sub(1), event_end.max(inner.end));
    let name = String::from_utf8_lossy(r).into_owned();
    let resolved = if r.is_char_ref() {
        r.resolve_char_ref().ok().flatten().map(String::from)
    } else {
        quick_xml::escape::resolve_predefined_entity(&name).map(str::to_string)
    };
    let result = resolved.ok_or_else(|| {
        format!(
            "`&{};` is not a known character: write `&amp;` for a plain `&`",
            shown(&name)
        )
    });
    (span, result)
}

/// User text quoted in a one-line message: control characters (line breaks)
/// become spaces, and long text is cut to its first 40 characters.
pub(crate) fn shown(s: &str) -> String {
    let mut out: String = s
        .chars()
        .take(40)
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

/// Did-you-mean over a format's few element, attribute and value names: the
/// shared rule, plus swapped letters (`Valeu`, `dco`) and two edits on longer names.
pub(crate) fn suggest(name: &str, candidates: &[&str]) -> Option<String> {
    did_you_mean(name, candidates.iter().copied()).or_else(|| {
        let sorted = |s: &str| {
            let mut v: Vec<char> = s.to_lowercase().chars().collect();
            v.sort_unstable();
            v
        };
        let key = sorted(name);
        let lower = name.to_lowercase();
        candidates
            .iter()
            .find(|c| {
                sorted(c) == key
                    || (name.chars().count() >= 5 && edit_distance(&lower, &c.to_lowercase()) <= 2)
            })
            .map(|c| c.to_string())
    })
}

/// Letters, digits and `_`, not starting with a digit.
pub(crate) fn is_ident(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attr(value: &str, start: usize) -> Attr {
        Attr {
            key: "k".into(),
            key_span: Span::new(0, 1),
            value: value.into(),
            span: Span::new(start, start + value.len()),
            exact: true,
        }
    }

    #[test]
    fn words_and_trimmed_spans() {
        let a = attr(" ab, c ", 10);
        let words = a.words();
        assert_eq!(words[0], ("ab".to_string(), Span::new(11, 13)));
        assert_eq!(words[1], ("c".to_string(), Span::new(15, 16)));
        assert_eq!(a.trimmed_span(), Span::new(11, 16));
        assert_eq!(attr("  ", 3).trimmed_span(), Span::new(3, 5));
    }

    #[test]
    fn word_at_stops_at_space_and_bracket() {
        let text = "<ab>é y <c";
        assert_eq!(word_at(text, 0), Span::new(0, 4));
        assert_eq!(word_at(text, 4), Span::new(4, 6));
        // Inside a multi-byte character: moves back to its start.
        assert_eq!(word_at(text, 5).start, 4);
        assert_eq!(word_at(text, 7), Span::new(7, 8));
        assert_eq!(word_at(text, 100), Span::new(text.len(), text.len()));
    }

    #[test]
    fn trim_span_keeps_blank_and_inexact() {
        assert_eq!(trim_span("  x ", Span::new(5, 9)), Span::new(7, 8));
        assert_eq!(trim_span("   ", Span::new(5, 8)), Span::new(5, 8));
        assert_eq!(trim_span("x", Span::new(5, 9)), Span::new(5, 9));
    }
}
