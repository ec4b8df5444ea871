//! Text from files and from the network made safe to show on a terminal.
//!
//! A mission's line quoted in a diagnostic, a value a robot sends to the
//! operator, a mode named in a robot's status: none of it is ours, and a
//! terminal obeys the control characters in what it is given (an escape
//! sequence can set the window's title, rewrite the line above, or write
//! the clipboard; a carriage return can hide what came before it). Every
//! such character is shown instead, as the Unicode "control picture" of
//! its code (`␀`, `␛`, `␡`) or, for the C1 controls, as `�`. Tabs, line
//! feeds and the carriage return of a CRLF line end are kept.

use std::borrow::Cow;

/// `text` with its control characters shown ([`shown`]).
pub fn visible(text: &str) -> Cow<'_, str> {
    if !text.char_indices().any(|(i, c)| hidden(text, i, c)) {
        return Cow::Borrowed(text);
    }
    Cow::Owned(ShownSource::new(text).text)
}

/// A source text with its control characters shown, and the way from its
/// byte offsets to the shown text's (each control character shown takes
/// more bytes than it did).
pub struct ShownSource {
    pub text: String,
    /// (offset in the original, bytes added before the next character),
    /// ascending: one entry per character shown.
    added: Vec<(usize, usize)>,
}

impl ShownSource {
    pub fn new(text: &str) -> ShownSource {
        let mut added = Vec::new();
        let mut extra = 0;
        let shown_text = if text.char_indices().any(|(i, c)| hidden(text, i, c)) {
            let mut out = String::with_capacity(text.len() + 8);
            for (i, c) in text.char_indices() {
                if hidden(text, i, c) {
                    let s = shown(c);
                    out.push(s);
                    extra += s.len_utf8() - c.len_utf8();
                    added.push((i, extra));
                } else {
                    out.push(c);
                }
            }
            out
        } else {
            text.to_owned()
        };
        ShownSource {
            text: shown_text,
            added,
        }
    }

    /// Where the original's byte `offset` is in the shown text.
    pub fn offset(&self, offset: usize) -> usize {
        let before = self.added.partition_point(|&(at, _)| at < offset);
        offset + before.checked_sub(1).map_or(0, |i| self.added[i].1)
    }
}

/// Whether the character `c` at byte `i` of `text` would act on a terminal.
fn hidden(text: &str, i: usize, c: char) -> bool {
    match c {
        '\t' | '\n' => false,
        '\r' => text.as_bytes().get(i + 1) != Some(&b'\n'),
        _ => c.is_control(),
    }
}

/// How a control character is shown.
fn shown(c: char) -> char {
    match c as u32 {
        code @ 0..=0x1f => char::from_u32(0x2400 + code).unwrap_or('\u{fffd}'),
        0x7f => '\u{2421}',
        _ => '\u{fffd}',
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_sequences_and_lone_carriage_returns_are_shown_not_obeyed() {
        assert_eq!(
            visible("a \x1b]0;PWNED\x07 \x1b[31mred\rover\x7f\u{9b}"),
            "a ␛]0;PWNED␇ ␛[31mred␍over␡\u{fffd}"
        );
        assert_eq!(visible("tab\tand crlf\r\n"), "tab\tand crlf\r\n");
        assert!(matches!(visible("plain é"), Cow::Borrowed(_)));
    }

    #[test]
    fn offsets_follow_the_characters_shown() {
        let source = ShownSource::new("ab\0c\x1bd\n");
        assert_eq!(source.text, "ab␀c␛d\n");
        let byte = |original: usize| source.offset(original);
        // Each shown control takes 3 bytes where it took 1.
        assert_eq!([0, 2, 3, 4, 5, 6, 7].map(byte), [0, 2, 5, 6, 9, 10, 11]);
        assert_eq!(&source.text[byte(3)..byte(4)], "c");
        assert_eq!(&source.text[byte(5)..byte(6)], "d");
    }
}
