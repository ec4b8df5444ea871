//! Byte positions for XML read with quick-xml, under the positioned element
//! tree of [`crate::xmltree`] that the catalog, strategy and task-graph loaders
//! read, and the readers' shared attribute helpers. The reader borrows the text (`Reader::from_str`), so every
//! name and attribute value it hands out is a slice of the text and its range is
//! found by pointer arithmetic ([`slice_span`]).

use crate::fasthash::FastSet;
use crate::span::Span;
use crate::suggest::{did_you_mean, edit_distance};
use quick_xml::Reader;
use quick_xml::encoding::Decoder;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesEnd, BytesRef, BytesStart};
use smol_str::SmolStr;

/// One attribute as written. Names and values are small strings (inline up
/// to 23 bytes): a large graph file has hundreds of thousands of them, and a
/// heap allocation each was most of its reading time.
#[derive(Clone, Debug)]
pub(crate) struct Attr {
    pub key: SmolStr,
    pub key_span: Span,
    /// The value with entities replaced.
    pub value: SmolStr,
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

/// Where `position`, a position of [`reader`]`(text)`, lies in `text`: the
/// reader skips a byte-order mark at the start without counting its three
/// bytes, so every position it gives after one is three bytes short.
pub(crate) fn offset(text: &str, position: u64) -> usize {
    let mark = if text.starts_with('\u{feff}') { 3 } else { 0 };
    usize::try_from(position)
        .map_or(text.len(), |p| p.saturating_add(mark))
        .min(text.len())
}

/// A quick-xml reader over `text` that leaves end tags to be matched by the
/// caller (to report them with both positions) and keeps text untrimmed. Its
/// positions are offsets in `text` through [`offset`].
pub(crate) fn reader(text: &str) -> Reader<&[u8]> {
    let mut reader = Reader::from_str(text);
    let config = reader.config_mut();
    config.check_end_names = false;
    config.allow_unmatched_ends = true;
    config.trim_text(false);
    reader
}

/// An end tag's range (`</` to `>`) and its name.
pub(crate) fn end_tag(text: &str, e: &BytesEnd<'_>, tag_end: usize) -> (Span, String) {
    let name = e.name();
    let span = end_tag_span(text, name.as_ref(), tag_end);
    (span, String::from_utf8_lossy(name.as_ref()).into_owned())
}

/// The message for an element open when the file ends.
pub(crate) fn never_closed(qname: &str) -> String {
    format!("`<{qname}>` is never closed: add `</{qname}>`")
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

/// A start tag's names and ranges.
pub(crate) struct StartTag {
    pub qname: SmolStr,
    /// The name without a namespace prefix.
    pub local: SmolStr,
    pub name_span: Span,
    /// `<` to `>`.
    pub tag: Span,
}

/// The names and ranges of a start tag; `Err` (range, message) for a `<`
/// followed by no name, which is malformed XML.
pub(crate) fn start_tag(
    text: &str,
    e: &BytesStart<'_>,
    tag_end: usize,
) -> Result<StartTag, (Span, &'static str)> {
    let (name_span, tag) = start_tag_spans(text, e, tag_end);
    // The text itself where it can be (it is already UTF-8).
    let name = |bytes: &[u8]| match slice_span(text, bytes).and_then(|s| text.get(s.range())) {
        Some(name) => SmolStr::new(name),
        None => SmolStr::new(String::from_utf8_lossy(bytes)),
    };
    let qname = name(e.name().as_ref());
    let local = name(e.local_name().as_ref());
    if local.is_empty() {
        return Err((
            word_at(text, tag.start),
            "a `<` must be followed by an element name: write `&lt;` for a plain `<`",
        ));
    }
    Ok(StartTag {
        qname,
        local,
        name_span,
        tag,
    })
}

/// What is said of a `<` inside an attribute value when reading stops there:
/// most often a closing quote is missing and the value ran into the next tag.
pub(crate) const LT_IN_VALUE: &str =
    "a `<` inside an attribute value: is a closing quote missing? (write `&lt;` for a plain `<`)";

/// For a tag that quick-xml found never closed (it starts at `tag_start`): the
/// range of the first `<` inside one of its quoted values, if any. That is
/// where a value whose closing quote is missing ran into the next tag.
pub(crate) fn lt_in_unclosed_tag(text: &str, tag_start: usize) -> Option<Span> {
    let bytes = text.as_bytes().get(tag_start..)?;
    let mut quote: Option<u8> = None;
    for (i, &b) in bytes.iter().enumerate().skip(1) {
        match (quote, b) {
            (None, b'"' | b'\'') => quote = Some(b),
            (Some(q), _) if b == q => quote = None,
            (Some(_), b'<') => return Some(Span::new(tag_start + i, tag_start + i + 1)),
            _ => {}
        }
    }
    None
}

/// The range of the `<` at byte `at` (or `fallback` past the end).
fn lt_span(text: &str, at: usize, fallback: Span) -> Span {
    if text.len() > at {
        Span::new(at, at + 1)
    } else {
        fallback
    }
}

/// The attributes of a start tag (`tag` is its range), with their ranges,
/// into `out` (emptied first: a reader of many elements reuses one list). A
/// malformed attribute list gives the range and message of the first error; a
/// `<` inside a value is such an error.
pub(crate) fn read_attributes_into(
    text: &str,
    e: &BytesStart<'_>,
    tag: Span,
    decoder: Decoder,
    out: &mut Vec<Attr>,
) -> Result<(), (Span, String)> {
    let raw_lt = read_attributes_keeping_lt_into(text, e, tag, decoder, out)?;
    match raw_lt.first() {
        Some(&at) => Err((lt_span(text, at, tag), LT_IN_VALUE.to_string())),
        None => Ok(()),
    }
}

/// As [`read_attributes_into`], except that a `<` inside a value (which quick-xml
/// reads as part of the value, and XML forbids) is kept: the byte position of
/// every such `<` is returned, for formats that report it
/// and read on. When the attribute list is malformed after such a `<`, the
/// error is the `<` (a closing quote is likely missing there).
pub(crate) fn read_attributes_keeping_lt_into(
    text: &str,
    e: &BytesStart<'_>,
    tag: Span,
    decoder: Decoder,
    out: &mut Vec<Attr>,
) -> Result<Vec<usize>, (Span, String)> {
    out.clear();
    let mut raw_lt: Vec<usize> = Vec::new();
    let fail = |raw_lt: &[usize], span: Span, message: String| match raw_lt.first() {
        Some(&at) => (lt_span(text, at, tag), LT_IN_VALUE.to_string()),
        None => (span, message),
    };
    // Attribute error positions count from the byte after `<`.
    let content_start = tag.start + 1;
    // quick-xml's own check for a repeated name compares each name with every
    // one before it: quadratic in a tag's attributes. [`first_repeated`] is
    // linear, and runs where quick-xml's would have stopped: at the end, or
    // before the first malformed attribute.
    let repeated = |out: &[Attr], raw_lt: &[usize]| {
        let i = first_repeated(out, |a| a.key.as_bytes())?;
        let key = out[i].key_span;
        let lt_before: Vec<usize> = raw_lt
            .iter()
            .copied()
            .filter(|&at| at < key.start)
            .collect();
        let message = "this attribute is given twice on the same element".to_string();
        Some(fail(&lt_before, word_at(text, key.start), message))
    };
    for attr in e.attributes().with_checks(false) {
        let attr = match attr {
            Ok(a) => a,
            Err(err) => {
                if let Some(error) = repeated(out, &raw_lt) {
                    return Err(error);
                }
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
                    // Not checked by quick-xml (see above).
                    AttrError::Duplicated(p, _) => (
                        p,
                        "this attribute is given twice on the same element".to_string(),
                    ),
                };
                return Err(fail(&raw_lt, word_at(text, content_start + pos), message));
            }
        };
        let key_in_text = slice_span(text, attr.key.as_ref());
        // The text itself where it can be (it is already UTF-8): most of a
        // large file's reading time otherwise.
        let key = match key_in_text.and_then(|span| text.get(span.range())) {
            Some(key) => SmolStr::new(key),
            None => SmolStr::new(String::from_utf8_lossy(attr.key.as_ref())),
        };
        let key_span = key_in_text.unwrap_or(tag);
        let raw: &[u8] = &attr.value;
        let value_in_text = slice_span(text, raw);
        let span = value_in_text.unwrap_or(tag);
        raw_lt.extend(
            raw.iter()
                .enumerate()
                .filter(|&(_, &b)| b == b'<')
                .map(|(i, _)| span.start + i),
        );
        let plain = value_in_text
            .filter(|_| !raw.contains(&b'&'))
            .and_then(|span| text.get(span.range()));
        let value = match plain {
            Some(value) => SmolStr::new(value),
            None => match attr.decode_and_unescape_value(decoder) {
                Ok(v) => SmolStr::new(v),
                Err(_) => {
                    let message =
                        "this value has an unknown `&...;` entity: write `&amp;` for a plain `&`";
                    return Err(fail(&raw_lt, span, message.to_string()));
                }
            },
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
    match repeated(out, &raw_lt) {
        Some(error) => Err(error),
        None => Ok(raw_lt),
    }
}

/// The index of the first of `items` whose key is that of an item before it,
/// in linear time: a scan while there are few (most elements have a handful
/// of attributes), a hash set past that.
///
/// The scan compares two keys' lengths and first bytes before their bytes,
/// which tells apart the names an element carries (SDF3's `srcActor` and
/// `dstActor`, `name` and `type`) without calling `memcmp`. Every element of
/// a document is checked, so this is on the reader's hot path.
pub(crate) fn first_repeated<T>(items: &[T], key: impl Fn(&T) -> &[u8]) -> Option<usize> {
    const SCAN: usize = 16;
    if items.len() <= SCAN {
        let same = |a: &[u8], b: &[u8]| a.len() == b.len() && a.first() == b.first() && a == b;
        return (1..items.len()).find(|&i| {
            let k = key(&items[i]);
            items[..i].iter().any(|seen| same(key(seen), k))
        });
    }
    let mut seen = FastSet::default();
    seen.reserve(items.len());
    items.iter().position(|item| !seen.insert(key(item)))
}

/// For each byte offset of `attr.value` (and one past its end), the byte
/// offset in `text` where it was written: entities (`&lt;`) make the value
/// shorter than its text, and every byte of what an entity stands for maps to
/// the entity's `&`. Offsets stay inside the value's range whatever happens.
pub(crate) fn value_offsets(text: &str, attr: &Attr) -> Vec<usize> {
    let span = attr.span;
    if attr.exact
        || span.end > text.len()
        || !text.is_char_boundary(span.start)
        || !text.is_char_boundary(span.end)
    {
        return (0..=attr.value.len())
            .map(|i| (span.start + i).min(span.end))
            .collect();
    }
    let raw = &text[span.range()];
    let mut out = Vec::with_capacity(attr.value.len() + 1);
    let mut i = 0;
    while i < raw.len() {
        let rest = &raw[i..];
        if rest.starts_with('&') {
            if let Some(semi) = rest.find(';') {
                let name = &rest[1..semi];
                let decoded = if let Some(num) = name.strip_prefix('#') {
                    let n = match num.strip_prefix('x') {
                        Some(hex) => u32::from_str_radix(hex, 16).ok(),
                        None => num.parse::<u32>().ok(),
                    };
                    n.and_then(char::from_u32).map(|c| c.len_utf8())
                } else {
                    quick_xml::escape::resolve_predefined_entity(name).map(str::len)
                };
                if let Some(len) = decoded {
                    out.extend(std::iter::repeat_n(span.start + i, len));
                    i += semi + 1;
                    continue;
                }
            }
        }
        let c_len = rest.chars().next().map_or(1, char::len_utf8);
        out.extend((0..c_len).map(|k| span.start + i + k));
        i += c_len;
    }
    out.push(span.end);
    // Should the decoding differ from quick-xml's, keep every offset in range
    // and the table as long as the value.
    out.resize(attr.value.len() + 1, span.end);
    out
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

/// Text for XML content or a quoted attribute: special characters escaped,
/// characters XML 1.0 does not allow replaced by U+FFFD.
#[derive(Clone, Copy)]
pub(crate) struct Escaped<'s>(&'s str);

/// Text safe inside an XML comment (`<!-- … -->`): no `--` however the
/// pieces meet, no `-` at the end (it would meet the closing `-->`), and no
/// control characters (they are not XML characters), in one pass.
pub(crate) fn comment(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '-' if out.ends_with('-') => out.push_str(" -"),
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    if out.ends_with('-') {
        out.push(' ');
    }
    out
}

pub(crate) fn escape(s: &str) -> Escaped<'_> {
    Escaped(s)
}

impl std::fmt::Display for Escaped<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut plain = 0;
        for (i, c) in self.0.char_indices() {
            let replacement = match c {
                '&' => "&amp;",
                '<' => "&lt;",
                '>' => "&gt;",
                '"' => "&quot;",
                '\'' => "&apos;",
                '\t' | '\n' | '\r' => continue,
                c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => "\u{FFFD}",
                _ => continue,
            };
            f.write_str(&self.0[plain..i])?;
            f.write_str(replacement)?;
            plain = i + c.len_utf8();
        }
        f.write_str(&self.0[plain..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `first_repeated` reads each key a bounded number of times, however
    /// many there are: counted, not timed.
    #[test]
    fn a_repeated_key_is_found_in_linear_work() {
        for n in [2, 16, 17, 1_000, 100_000] {
            let mut keys: Vec<String> = (0..n).map(|i| format!("a{i}")).collect();
            let reads = std::cell::Cell::new(0);
            let counted = first_repeated(&keys, |k| {
                reads.set(reads.get() + 1);
                k.as_bytes()
            });
            assert_eq!(counted, None);
            assert!(reads.get() <= 16 * n, "{n} keys read {} times", reads.get());
            keys.push(format!("a{}", n / 2));
            assert_eq!(first_repeated(&keys, |k| k.as_bytes()), Some(n));
        }
    }

    /// Keys alike in length and first byte are told apart in full, an
    /// empty key is one like any other, and the first repeat is the one given.
    #[test]
    fn keys_with_the_same_digest_are_compared_in_full() {
        let first = |keys: &[&str]| first_repeated(keys, |k| k.as_bytes());
        assert_eq!(first(&["srcActor", "dstActor", "name", "type"]), None);
        assert_eq!(first(&["abxd", "acxd", "abyd", "adxd"]), None);
        assert_eq!(first(&["abxd", "acxd", "abyd", "acxd", "abxd"]), Some(3));
        assert_eq!(first(&["", "a", ""]), Some(2));
        assert_eq!(first(&["", "a"]), None);
        assert_eq!(first(&[]), None);
        let long = "x".repeat(70_000);
        let other = format!("x{}x", "y".repeat(70_000 - 2));
        assert_eq!(first(&[&long, &other, "x"]), None);
        assert_eq!(first(&[&other, &long, &long]), Some(2));
    }

    #[test]
    fn a_repeated_attribute_is_malformed_xml_at_its_second_name() {
        use quick_xml::events::Event;
        for (text, second) in [
            (r#"<a x="1" y="2" x="3"/>"#, 15),
            // Before a malformed attribute after it, as quick-xml found it.
            (r#"<a x="1" x="2" y=3/>"#, 9),
        ] {
            let mut reader = reader(text);
            let Ok(Event::Empty(e)) = reader.read_event() else {
                panic!("{text}");
            };
            let tag = Span::new(0, text.len());
            let mut out = Vec::new();
            let (span, message) =
                read_attributes_into(text, &e, tag, reader.decoder(), &mut out).unwrap_err();
            assert_eq!(span.start, second, "{text}: {message}");
        }
        // Many attributes: found all the same, past the short scan.
        let many: String = (0..100).map(|i| format!(" a{i}=\"v\"")).collect();
        let text = format!("<a{many} a50=\"again\"/>");
        let mut reader = reader(&text);
        let Ok(quick_xml::events::Event::Empty(e)) = reader.read_event() else {
            panic!("{text}");
        };
        let mut out = Vec::new();
        let tag = Span::new(0, text.len());
        let (span, message) =
            read_attributes_into(&text, &e, tag, reader.decoder(), &mut out).unwrap_err();
        assert_eq!(span.start, text.rfind("a50").unwrap(), "{message}");
    }

    #[test]
    fn xml_comments_cannot_end_early() {
        assert_eq!(comment("a-->b"), "a- ->b");
        assert_eq!(comment("---"), "- - - ");
        assert_eq!(comment("x-"), "x- ");
        assert_eq!(comment("l1\nl2"), "l1 l2");
    }

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
    fn value_offsets_map_entities_to_their_ampersand() {
        let text = r#"<C cond="a&lt;=b&#x3E;é"/>"#;
        let start = text.find('a').unwrap();
        let end = text.rfind('"').unwrap();
        let a = Attr {
            key: "cond".into(),
            key_span: Span::new(3, 7),
            value: "a<=b>é".into(),
            span: Span::new(start, end),
            exact: false,
        };
        let offsets = value_offsets(text, &a);
        assert_eq!(offsets.len(), a.value.len() + 1);
        let at = |i: usize| &text[offsets[i]..];
        assert!(at(0).starts_with("a&lt;"));
        assert!(at(1).starts_with("&lt;"));
        assert!(at(2).starts_with("=b"));
        assert!(at(4).starts_with("&#x3E;"));
        assert!(at(5).starts_with('é'));
        assert_eq!(offsets[a.value.len()], end);
        // Exact values map one to one.
        let exact = attr("xy", 4);
        assert_eq!(value_offsets("0123xy\"", &exact), vec![4, 5, 6]);
    }

    #[test]
    fn lt_in_unclosed_tag_finds_the_lt_inside_quotes() {
        let text = "<B a='1' cond=\"x<2/>\n<C k=\"1\"/>";
        let lt = lt_in_unclosed_tag(text, 0).unwrap();
        assert_eq!(lt.start, text.find("x<").unwrap() + 1);
        assert_eq!(lt_in_unclosed_tag("<B a=\"1\"", 0), None);
        assert_eq!(lt_in_unclosed_tag("<B", 9), None);
    }

    #[test]
    fn trim_span_keeps_blank_and_inexact() {
        assert_eq!(trim_span("  x ", Span::new(5, 9)), Span::new(7, 8));
        assert_eq!(trim_span("   ", Span::new(5, 8)), Span::new(5, 8));
        assert_eq!(trim_span("x", Span::new(5, 9)), Span::new(5, 9));
    }
}
