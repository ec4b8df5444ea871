//! The events of an XML text as quick-xml's reader gives them (configured
//! as [`crate::xmlpos::reader`]), each start tag with its attributes as
//! quick-xml's attribute reader reads them, for the clean SDF3 reader. Tags
//! and text are found here; everything that starts with `<!` or `<?`
//! (comments, CDATA, DOCTYPE, declarations, processing instructions) is read
//! by quick-xml itself, one event at a time from where it starts.
//!
//! Why not quick-xml for all of it: on a large SDF3 file almost every event
//! is a tag of a few attributes, and quick-xml finds a tag's end by one
//! `memchr3` search per quote, after which its attribute reader walks the
//! same bytes again. Here one walk through a start tag finds its name, its
//! attributes and its end.
//!
//! What holds: on any text, [`Tags`] gives quick-xml's events with quick-xml's
//! positions (as offsets in the text, [`crate::xmlpos::offset`]), and the
//! attributes of each start tag, or stops (`None`) where quick-xml gives an
//! error (its reader's, or its attribute reader's on a start tag) or at a
//! general reference (`&`). Like quick-xml, it skips a byte-order mark at
//! the start. The grammar followed
//! is quick-xml 0.38's. Text runs to the next `<` or `&`. After `<`, a `/`
//! starts an end tag, `!` and `?` what quick-xml reads, anything else a start
//! tag. A tag runs to the first `>` outside quotes (a `"` or `'` opens a
//! quote anywhere in it). A start tag ending in `/` is empty, and its name
//! runs to the first blank. An end tag's name is its content without
//! trailing blanks. Attributes are read as [`each_attribute`] says
//! (`tests::events_are_quick_xmls`, `tests::events_agree_with_quick_xml`).

use crate::xmlpos::reader;
use quick_xml::events::{BytesEnd, BytesStart, BytesText, Event};

/// The events of a text, each with the position just after it.
pub(super) struct Tags<'t> {
    text: &'t str,
    /// Where the next event starts.
    at: usize,
    /// The names and values of the attributes of the last start tag.
    attributes: Vec<(&'t [u8], &'t [u8])>,
}

/// A start tag quick-xml would give an error on: its attributes break the
/// attribute reader's grammar, or it never ends.
struct Malformed;

impl<'t> Tags<'t> {
    pub(super) fn new(text: &'t str) -> Tags<'t> {
        let mark = '\u{feff}';
        Tags {
            text,
            at: if text.starts_with(mark) {
                mark.len_utf8()
            } else {
                0
            },
            attributes: Vec::new(),
        }
    }

    /// The next event and the position after it; `None` where the reading
    /// stops (see the module's documentation).
    pub(super) fn next(&mut self) -> Option<(Event<'t>, usize)> {
        let text = self.text;
        let bytes = text.as_bytes();
        let start = self.at;
        match bytes.get(start) {
            None => Some((Event::Eof, start)),
            Some(b'<') => self.markup(start),
            Some(_) => {
                let end =
                    memchr::memchr2(b'<', b'&', &bytes[start..]).map_or(text.len(), |i| start + i);
                if bytes.get(end) == Some(&b'&') {
                    return None;
                }
                self.at = end;
                // Both ends are at ASCII bytes or the text's ends.
                let content = text.get(start..end)?;
                Some((Event::Text(BytesText::from_escaped(content)), end))
            }
        }
    }

    /// The names and values (between the quotes) of the attributes of the
    /// start tag [`Tags::next`] gave last, in their order.
    pub(super) fn attributes(&self) -> &[(&'t [u8], &'t [u8])] {
        &self.attributes
    }

    /// The markup at `lt` (a `<`).
    fn markup(&mut self, lt: usize) -> Option<(Event<'t>, usize)> {
        let text = self.text;
        let bytes = text.as_bytes();
        let from = lt + 1;
        match bytes.get(from)? {
            b'!' | b'?' => {
                // From `<` on: no byte-order mark to skip.
                let mut quick = reader(text.get(lt..)?);
                let event = quick.read_event().ok()?;
                let end = lt + usize::try_from(quick.buffer_position()).ok()?;
                self.at = end;
                Some((event, end))
            }
            b'/' => {
                let gt = tag_end(bytes, from)?;
                self.at = gt + 1;
                let content = text.get(from + 1..gt)?;
                // All blank: quick-xml keeps the content as it is.
                let name = match content.trim_end_matches(|c: char| c.is_ascii() && blank(c as u8))
                {
                    "" => content,
                    name => name,
                };
                Some((Event::End(BytesEnd::new(name)), gt + 1))
            }
            _ => {
                self.attributes.clear();
                let (gt, empty) = match walk_start_tag(bytes, from, &mut self.attributes) {
                    Ok(Some(end)) => end,
                    Ok(None) => self.read_start_tag(from)?,
                    Err(Malformed) => return None,
                };
                self.at = gt + 1;
                let content = text.get(from..gt - usize::from(empty))?;
                let start = BytesStart::from_content(content, name_len(content.as_bytes()));
                let event = if empty {
                    Event::Empty(start)
                } else {
                    Event::Start(start)
                };
                Some((event, gt + 1))
            }
        }
    }

    /// A start tag at `from` read in two steps, its end and then its
    /// attributes: where [`walk_start_tag`] cannot read it in one.
    fn read_start_tag(&mut self, from: usize) -> Option<(usize, bool)> {
        let bytes = self.text.as_bytes();
        let gt = tag_end(bytes, from)?;
        let content = &bytes[from..gt];
        let empty = content.last() == Some(&b'/');
        let content = &content[..content.len() - usize::from(empty)];
        let raw = &content[name_len(content)..];
        self.attributes.clear();
        let attributes = &mut self.attributes;
        each_attribute(raw, |key, value| {
            attributes.push((key, value));
            Ok(())
        })
        .ok()?;
        Some((gt, empty))
    }
}

/// XML's blanks, as quick-xml's `is_whitespace`.
fn blank(b: u8) -> bool {
    matches!(b, b' ' | b'\r' | b'\n' | b'\t')
}

/// The length of a tag's name: up to its first blank.
fn name_len(content: &[u8]) -> usize {
    content
        .iter()
        .position(|&b| blank(b))
        .unwrap_or(content.len())
}

/// The first position from `from` whose byte `is` accepts.
fn find(raw: &[u8], from: usize, is: impl Fn(u8) -> bool) -> Option<usize> {
    let skipped = raw.get(from..)?.iter().position(|&b| is(b))?;
    Some(from + skipped)
}

/// Calls `f` with the name and the value (between its quotes) of each
/// attribute of a start tag, `raw` its content after the element's name (as
/// quick-xml's `attributes_raw` gives it), and fails where quick-xml's
/// attribute reader would give an error. It follows that reader's grammar
/// step by step (blanks; a name: its first byte whatever it is, then up to
/// `=` or a blank; blanks, `=`, blanks; a value in double or single quotes),
/// so it reads the same names and values from the same tags, but without
/// the reader's state machine and the list of names it allocates per
/// element for its duplicate check.
fn each_attribute<'a>(
    raw: &'a [u8],
    mut f: impl FnMut(&'a [u8], &'a [u8]) -> Result<(), Malformed>,
) -> Result<(), Malformed> {
    let mut at = 0;
    while let Some(key_start) = find(raw, at, |b| !blank(b)) {
        let key_end = find(raw, key_start + 1, |b| b == b'=' || blank(b)).ok_or(Malformed)?;
        let equals = find(raw, key_end, |b| !blank(b)).ok_or(Malformed)?;
        if raw[equals] != b'=' {
            return Err(Malformed);
        }
        let open = find(raw, equals + 1, |b| !blank(b)).ok_or(Malformed)?;
        let quote = raw[open];
        if quote != b'"' && quote != b'\'' {
            return Err(Malformed);
        }
        let close = find(raw, open + 1, |b| b == quote).ok_or(Malformed)?;
        f(&raw[key_start..key_end], &raw[open + 1..close])?;
        at = close + 1;
    }
    Ok(())
}

/// A start tag whose content starts at `from`, read in one walk: its name,
/// then [`each_attribute`]'s grammar with the tag's end looked for where a
/// name could start (`>`, or `/>` for an empty tag). Gives the position of
/// the `>` and whether the tag is empty, and pushes the attributes to `out`.
/// `Ok(None)` where a `"` or `'` is part of a name (which may move the tag's
/// end: [`Tags::read_start_tag`] then reads it). Otherwise every quote the
/// walk meets opens or closes a value, so the `>` it stops at is the first
/// outside quotes, as quick-xml finds it; and where it fails, the tag's end
/// is further on, or here, and the attribute reader fails on it too.
fn walk_start_tag<'a>(
    bytes: &'a [u8],
    from: usize,
    out: &mut Vec<(&'a [u8], &'a [u8])>,
) -> Result<Option<(usize, bool)>, Malformed> {
    let quoted = |b: u8| b == b'"' || b == b'\'';
    // The name: up to a blank, or to the end of the tag.
    let mut at = from;
    loop {
        match bytes.get(at) {
            None => return Err(Malformed),
            Some(&b) if blank(b) => break,
            Some(b'>') => return Ok(Some((at, false))),
            Some(b'/') if bytes.get(at + 1) == Some(&b'>') => return Ok(Some((at + 1, true))),
            Some(&b) if quoted(b) => return Ok(None),
            Some(_) => at += 1,
        }
    }
    loop {
        let key_start = find(bytes, at, |b| !blank(b)).ok_or(Malformed)?;
        match bytes[key_start] {
            b'>' => return Ok(Some((key_start, false))),
            b'/' if bytes.get(key_start + 1) == Some(&b'>') => {
                return Ok(Some((key_start + 1, true)));
            }
            b if quoted(b) => return Ok(None),
            _ => {}
        }
        let key_end = find(bytes, key_start + 1, |b| {
            b == b'=' || blank(b) || b == b'>' || quoted(b)
        })
        .ok_or(Malformed)?;
        if quoted(bytes[key_end]) {
            return Ok(None);
        }
        let equals = find(bytes, key_end, |b| !blank(b)).ok_or(Malformed)?;
        if bytes[equals] != b'=' {
            return Err(Malformed);
        }
        let open = find(bytes, equals + 1, |b| !blank(b)).ok_or(Malformed)?;
        let quote = bytes[open];
        if !quoted(quote) {
            return Err(Malformed);
        }
        let close = find(bytes, open + 1, |b| b == quote).ok_or(Malformed)?;
        out.push((&bytes[key_start..key_end], &bytes[open + 1..close]));
        at = close + 1;
    }
}

/// The position of the `>` ending the tag whose content starts at `from`:
/// the first outside quotes.
fn tag_end(bytes: &[u8], from: usize) -> Option<usize> {
    let mut quote = None;
    for (i, &b) in bytes.get(from..)?.iter().enumerate() {
        match (quote, b) {
            (None, b'>') => return Some(from + i),
            (None, b'"' | b'\'') => quote = Some(b),
            (Some(q), _) if q == b => quote = None,
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// An event as both readers are compared on: its kind, its bytes, the
    /// position after it and, for a start tag, its name and attributes.
    fn shown(event: &Event<'_>, end: usize, attributes: &[(&[u8], &[u8])]) -> String {
        let kind = match event {
            Event::Start(_) => "start",
            Event::Empty(_) => "empty",
            Event::End(_) => "end",
            Event::Text(_) => "text",
            Event::CData(_) => "cdata",
            Event::Comment(_) => "comment",
            Event::Decl(_) => "decl",
            Event::PI(_) => "pi",
            Event::DocType(_) => "doctype",
            Event::GeneralRef(_) => "ref",
            Event::Eof => "eof",
        };
        let lossy = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        let name = match event {
            Event::Start(e) | Event::Empty(e) => format!(
                "{:?} {:?}",
                lossy(e.name().as_ref()),
                attributes
                    .iter()
                    .map(|(k, v)| (lossy(k), lossy(v)))
                    .collect::<Vec<_>>()
            ),
            _ => String::new(),
        };
        format!("{kind} {name} {:?} @{end}", lossy(event))
    }

    /// The events of `text` up to the end or the first stop, and whether it
    /// stopped.
    fn ours(text: &str) -> (Vec<String>, bool) {
        let mut out = Vec::new();
        let mut tags = Tags::new(text);
        loop {
            match tags.next() {
                None => return (out, true),
                Some((Event::Eof, end)) => {
                    out.push(shown(&Event::Eof, end, &[]));
                    return (out, false);
                }
                Some((event, end)) => out.push(shown(&event, end, tags.attributes())),
            }
        }
    }

    /// The attributes of a start tag as quick-xml's attribute reader reads
    /// them (with no check for duplicates, which the clean reader makes),
    /// `None` on an error.
    fn quick_attributes(e: &BytesStart<'_>) -> Option<Vec<(Vec<u8>, Vec<u8>)>> {
        e.attributes()
            .with_checks(false)
            .map(|a| a.ok().map(|a| (a.key.as_ref().to_vec(), a.value.to_vec())))
            .collect()
    }

    /// quick-xml's events of `text` up to the end or the first error (of
    /// the reader, or of the attribute reader on a start tag) or general
    /// reference, and whether it stopped.
    fn quick(text: &str) -> (Vec<String>, bool) {
        let mut out = Vec::new();
        let mut r = reader(text);
        loop {
            let event = r.read_event();
            let end = crate::xmlpos::offset(text, r.buffer_position());
            match event {
                Err(_) | Ok(Event::GeneralRef(_)) => return (out, true),
                Ok(Event::Eof) => {
                    out.push(shown(&Event::Eof, end, &[]));
                    return (out, false);
                }
                Ok(event) => {
                    let attributes = match &event {
                        Event::Start(e) | Event::Empty(e) => match quick_attributes(e) {
                            Some(attributes) => attributes,
                            None => return (out, true),
                        },
                        _ => Vec::new(),
                    };
                    let borrowed: Vec<(&[u8], &[u8])> = attributes
                        .iter()
                        .map(|(k, v)| (k.as_slice(), v.as_slice()))
                        .collect();
                    out.push(shown(&event, end, &borrowed));
                }
            }
        }
    }

    /// The events up to a stop agree, and both stop or neither: quick-xml's
    /// text before a `&` is dropped from the comparison (we stop at once).
    fn agree(text: &str) {
        let (a, a_stopped) = ours(text);
        let (mut b, b_stopped) = quick(text);
        assert_eq!(a_stopped, b_stopped, "{text:?}\nours: {a:?}\nquick: {b:?}");
        if b_stopped && b.last().is_some_and(|e| e.starts_with("text")) && a.len() < b.len() {
            b.pop();
        }
        assert_eq!(a, b, "{text:?}");
    }

    #[test]
    fn events_are_quick_xmls() {
        for text in [
            "",
            "x",
            "<a/>",
            "<?xml version=\"1.0\"?>\n<a b=\"1\" c='2'>t<b/>u</a >\n",
            r#"<a x=">" y='">'>"#,
            "<a/ b>",
            "<a//>",
            "<a\n/>",
            "<a b=\"1\" />",
            "<a b=\"1\"/ >",
            "<a b=\"1\"c='2'/>",
            "<a ==\"3\"/>",
            "<a b/=\"1\"/>",
            "<a b/>",
            "<a b >",
            "<a b \"x\">",
            "<a b=>",
            "<a b=x>",
            "<a b=\"1>",
            "<a b\"c=\">",
            "<a\"b\">",
            "<a 'b'=\"1\">",
            "<a b='1\">'>",
            "</a \n>",
            "</ >",
            "</a x=\">\">",
            "< a>",
            "<>",
            "<",
            "<a",
            "<a x=\">",
            "t&amp;u",
            "&",
            "<!-- c --><![CDATA[x<y]]><!DOCTYPE d><?pi x?>",
            "<!-x>",
            "<?x",
            "\u{feff}<a/>",
            "\u{feff} <a b='1'>t</a>",
            "<é/><a é='é'/>é",
            // quick-xml's attribute grammar: no blank needed between
            // attributes, and a name's first byte may be anything but a
            // blank.
            "<e xmlns:xsi=\"u\" é=\"1\" a = 'x y'\n\tb=\"\" />",
            "<e a=\"1\"b='2' ==\"3\">",
        ] {
            agree(text);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        #[test]
        fn events_agree_with_quick_xml(
            text in "([<>/=\"'&;!?\\-\\[\\] \n\tax:é]|<a|</a>|<a b=\"1\"/>| b='2'|<!--|-->|<!\\[CDATA\\[|\\]\\]>|<\\?xml |\\?>){0,24}"
        ) {
            agree(&text);
        }

        /// Tags of attributes in every shape quick-xml's grammar allows and
        /// some it does not.
        #[test]
        fn start_tags_agree_with_quick_xml(
            raw in "([ \t\n]{0,2}[a-z:é/\"'=>]{0,3}[ ]?=?[ ]?[\"']?[a-z <&\"'=>]{0,3}[\"']?){0,3}[ /]?"
        ) {
            agree(&format!("<e{raw}>t</e>"));
        }
    }
}
