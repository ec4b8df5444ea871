//! XML read from the raw text around the cursor, for editor features on
//! files being typed (`<Serv`, `name="` with no closing quote), where the
//! loader's tree stops at the first error. Tolerant by design: any text gives
//! an answer, an unterminated tag ends at the next `<` outside quotes, and an
//! unterminated quoted value at the end of its line.

use crate::span::Span;

/// One attribute of a tag as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawAttr<'t> {
    pub name: &'t str,
    pub name_span: Span,
    /// The value between the quotes (not unescaped); `None` when no `=`
    /// followed the name.
    pub value: Option<&'t str>,
    pub value_span: Option<Span>,
    /// Whether the value's closing quote is written.
    pub closed: bool,
}

/// One tag as written: `<Name a="1" ...>`, `</Name>` or a tag being typed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawTag<'t> {
    /// From `<` to after `>` (or where the unterminated tag stops).
    pub span: Span,
    /// The element name without namespace prefix.
    pub name: &'t str,
    pub name_span: Span,
    pub closing: bool,
    pub self_closing: bool,
    /// Whether the tag's `>` is written.
    pub terminated: bool,
    pub attrs: Vec<RawAttr<'t>>,
}

impl<'t> RawTag<'t> {
    pub fn attr(&self, name: &str) -> Option<&RawAttr<'t>> {
        self.attrs.iter().find(|a| a.name == name)
    }

    /// The value of attribute `name`, if written.
    pub fn value(&self, name: &str) -> Option<&'t str> {
        self.attr(name).and_then(|a| a.value)
    }
}

fn is_name_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.' | b':') || c >= 0x80
}

/// The end of the name starting at `from`.
fn name_end(bytes: &[u8], from: usize) -> usize {
    let mut i = from;
    while i < bytes.len() && is_name_char(bytes[i]) {
        i += 1;
    }
    i
}

/// The name without its namespace prefix (`s:Service` → `Service`).
fn local(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or(name)
}

/// Reads the tag whose `<` is at `start` (an element's start or end tag).
pub fn read_tag(text: &str, start: usize) -> RawTag<'_> {
    let bytes = text.as_bytes();
    let mut pos = start + 1;
    let closing = bytes.get(pos) == Some(&b'/');
    if closing {
        pos += 1;
    }
    let name_stop = name_end(bytes, pos);
    let name_span = Span::new(pos, name_stop);
    let mut tag = RawTag {
        span: Span::new(start, text.len()),
        name: local(&text[pos..name_stop]),
        name_span,
        closing,
        self_closing: false,
        terminated: false,
        attrs: Vec::new(),
    };
    pos = name_stop;
    while pos < bytes.len() {
        match bytes[pos] {
            b'>' => {
                tag.terminated = true;
                tag.span.end = pos + 1;
                return tag;
            }
            b'/' if bytes.get(pos + 1) == Some(&b'>') => {
                tag.terminated = true;
                tag.self_closing = true;
                tag.span.end = pos + 2;
                return tag;
            }
            b'<' => {
                tag.span.end = pos;
                return tag;
            }
            c if is_name_char(c) => pos = read_attr(text, pos, &mut tag.attrs),
            _ => pos += 1,
        }
    }
    tag
}

/// Reads `name="value"` at `start`; returns where reading goes on.
fn read_attr<'t>(text: &'t str, start: usize, attrs: &mut Vec<RawAttr<'t>>) -> usize {
    let bytes = text.as_bytes();
    let stop = name_end(bytes, start);
    let mut attr = RawAttr {
        name: &text[start..stop],
        name_span: Span::new(start, stop),
        value: None,
        value_span: None,
        closed: false,
    };
    let mut pos = stop;
    while pos < bytes.len() && bytes[pos].is_ascii_whitespace() && bytes[pos] != b'\n' {
        pos += 1;
    }
    if bytes.get(pos) != Some(&b'=') {
        attrs.push(attr);
        return stop;
    }
    pos += 1;
    while pos < bytes.len() && bytes[pos].is_ascii_whitespace() && bytes[pos] != b'\n' {
        pos += 1;
    }
    let value_start;
    let value_end;
    match bytes.get(pos) {
        Some(&q) if q == b'"' || q == b'\'' => {
            value_start = pos + 1;
            let rest = &bytes[value_start..];
            match rest.iter().position(|&c| c == q || c == b'\n') {
                Some(i) if rest[i] == q => {
                    value_end = value_start + i;
                    attr.closed = true;
                    pos = value_end + 1;
                }
                Some(i) => {
                    value_end = value_start + i;
                    pos = value_end;
                }
                None => {
                    value_end = bytes.len();
                    pos = value_end;
                }
            }
        }
        _ => {
            // An unquoted value (malformed, but read for the editor).
            value_start = pos;
            let mut i = pos;
            while i < bytes.len()
                && !bytes[i].is_ascii_whitespace()
                && !matches!(bytes[i], b'>' | b'<')
            {
                i += 1;
            }
            value_end = i;
            pos = i;
        }
    }
    // Byte positions found by ASCII bytes are char boundaries.
    attr.value = text.get(value_start..value_end);
    attr.value_span = Some(Span::new(value_start, value_end));
    attrs.push(attr);
    pos
}

/// Comments, CDATA, processing instructions and declarations: skipped.
const MARKUP: [(&str, &str); 4] = [
    ("<!--", "-->"),
    ("<![CDATA[", "]]>"),
    ("<?", "?>"),
    ("<!", ">"),
];

/// Where an offset is, read from the text before it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Position<'t> {
    /// The elements open around the offset, outermost first (their local names).
    pub open: Vec<&'t str>,
    /// The tag the offset is in (after its `<`, up to its `>`), if any.
    pub tag: Option<RawTag<'t>>,
    /// Whether the offset is inside a comment, a processing instruction or CDATA.
    pub in_markup: bool,
}

impl<'t> Position<'t> {
    /// The innermost open element.
    pub fn parent(&self) -> Option<&'t str> {
        self.open.last().copied()
    }

    pub fn grandparent(&self) -> Option<&'t str> {
        self.open.len().checked_sub(2).map(|i| self.open[i])
    }
}

/// Scans the tags before `offset`: which elements are open there and which
/// tag holds it. Linear in the text before the offset.
pub fn position_at(text: &str, offset: usize) -> Position<'_> {
    let offset = offset.min(text.len());
    let bytes = text.as_bytes();
    let mut out = Position {
        open: Vec::new(),
        tag: None,
        in_markup: false,
    };
    let mut pos = 0;
    while pos < offset {
        let Some(found) = bytes[pos..offset].iter().position(|&c| c == b'<') else {
            break;
        };
        let at = pos + found;
        let rest = &text[at..];
        if let Some((open, close)) = MARKUP.iter().find(|(open, _)| rest.starts_with(open)) {
            let end = rest[open.len()..]
                .find(close)
                .map(|i| at + open.len() + i + close.len());
            match end {
                Some(end) if offset >= end => {
                    pos = end;
                    continue;
                }
                // Unterminated, or the offset is inside.
                _ => {
                    out.in_markup = true;
                    return out;
                }
            }
        }
        let tag = read_tag(text, at);
        // Inside the tag: after its `<` and before its `>` is passed.
        let inside = if tag.terminated {
            offset < tag.span.end
        } else {
            offset <= tag.span.end
        };
        if inside {
            out.tag = Some(tag);
            return out;
        }
        if tag.closing {
            if let Some(i) = out.open.iter().rposition(|&n| n == tag.name) {
                out.open.truncate(i);
            }
        } else if !tag.self_closing
            && !tag.name.is_empty()
            && (tag.terminated || !tag.attrs.is_empty())
        {
            // An unterminated tag with attributes lacks only its `>`; one
            // without is a name that was being typed.
            out.open.push(tag.name);
        }
        pos = tag.span.end.max(at + 1);
    }
    out
}

/// The tag that closes the element whose start tag begins at `start`, if
/// written (for renaming both).
pub fn matching_close(text: &str, start: usize) -> Option<RawTag<'_>> {
    let first = read_tag(text, start);
    if first.self_closing || first.closing || !first.terminated {
        return None;
    }
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut pos = first.span.end;
    while let Some(found) = bytes[pos..].iter().position(|&c| c == b'<') {
        let at = pos + found;
        let rest = &text[at..];
        if let Some((open, close)) = MARKUP.iter().find(|(open, _)| rest.starts_with(open)) {
            pos = at + open.len() + rest[open.len()..].find(close)? + close.len();
            continue;
        }
        let tag = read_tag(text, at);
        if tag.closing {
            if depth == 0 {
                return Some(tag);
            }
            depth -= 1;
        } else if !tag.self_closing {
            depth += 1;
        }
        pos = tag.span.end.max(at + 1);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str) -> (String, usize) {
        let offset = text.find("$0").expect("a cursor");
        (text.replacen("$0", "", 1), offset)
    }

    #[test]
    fn open_elements_and_the_tag_under_the_cursor() {
        let (text, offset) = at(concat!(
            "<?xml version=\"1.0\"?>\n<!-- <Fake> -->\n<Strategy name=\"T\">\n",
            "  <ServiceInfo>\n    <Service plan_name=\"P\" name=\"mo$0\n",
            "      <TargetRobot name=\"X\"/>\n",
        ));
        let p = position_at(&text, offset);
        assert_eq!(p.open, ["Strategy", "ServiceInfo"]);
        let tag = p.tag.expect("in a tag");
        assert_eq!(tag.name, "Service");
        assert!(!tag.terminated);
        assert_eq!(tag.value("plan_name"), Some("P"));
        let name = tag.attr("name").unwrap();
        assert_eq!((name.value, name.closed), (Some("mo"), false));
    }

    #[test]
    fn closed_and_self_closing_elements_leave_the_stack() {
        let (text, offset) = at("<A><B x='1>2'/><C></C><D><E cond=\"a<2\"></E>$0</D>");
        let p = position_at(&text, offset);
        assert_eq!(p.open, ["A", "D"]);
        assert_eq!(p.tag, None);
        let (text, offset) = at("<A><!-- <B> $0 -->");
        let p = position_at(&text, offset);
        assert!(p.in_markup);
        let (text, offset) = at("<A><Se$0");
        let tag = position_at(&text, offset).tag.unwrap();
        assert_eq!((tag.name, tag.attrs.len()), ("Se", 0));
    }

    #[test]
    fn any_text_gives_an_answer() {
        for text in [
            "",
            "<",
            "</",
            "<a b=",
            "<a b='",
            "<<<>>>",
            "<!--",
            "<?",
            "é<ü x=\"ö",
            "<a/><",
        ] {
            for offset in 0..=text.len() + 1 {
                if text.is_char_boundary(offset.min(text.len())) {
                    let _ = position_at(text, offset);
                }
            }
            for start in text.match_indices('<').map(|(i, _)| i) {
                let _ = read_tag(text, start);
                let _ = matching_close(text, start);
            }
        }
    }

    #[test]
    fn the_close_tag_of_an_element_is_found_past_nested_ones() {
        let text = "<A><B><B/></B><!-- </A> --></A>";
        let close = matching_close(text, 0).unwrap();
        assert_eq!(close.span.start, text.rfind("</A>").unwrap());
        assert_eq!(matching_close(text, 3).unwrap().span.start, 10);
    }
}
