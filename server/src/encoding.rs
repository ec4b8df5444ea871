//! Positions at the protocol door. Inside the library every position is a byte
//! range; the client counts columns in the encoding negotiated at `initialize`
//! (UTF-8 when the client offers it, else UTF-16, the protocol's default).
//! Lines end at `\n` only, as in `semo::text::LineIndex` and our ropes.

use ropey::Rope;
use semo::span::Span;
use semo::text::{ColumnUnit, LineCol, LineIndex};
use tower_lsp_server::ls_types::{ClientCapabilities, Position, PositionEncodingKind, Range};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Encoding {
    Utf8,
    #[default]
    Utf16,
}

impl Encoding {
    /// UTF-8 when the client lists it (no conversion needed), else UTF-16.
    pub fn negotiate(caps: &ClientCapabilities) -> Encoding {
        let offered = caps
            .general
            .as_ref()
            .and_then(|g| g.position_encodings.as_ref());
        match offered {
            Some(kinds) if kinds.contains(&PositionEncodingKind::UTF8) => Encoding::Utf8,
            _ => Encoding::Utf16,
        }
    }

    pub fn kind(self) -> PositionEncodingKind {
        match self {
            Encoding::Utf8 => PositionEncodingKind::UTF8,
            Encoding::Utf16 => PositionEncodingKind::UTF16,
        }
    }

    fn unit(self) -> ColumnUnit {
        match self {
            Encoding::Utf8 => ColumnUnit::Utf8,
            Encoding::Utf16 => ColumnUnit::Utf16,
        }
    }
}

/// Converts between byte offsets of one text and protocol positions.
#[derive(Clone, Copy)]
pub struct LineMap<'a> {
    pub text: &'a str,
    pub index: &'a LineIndex,
    pub encoding: Encoding,
}

impl LineMap<'_> {
    pub fn position(&self, offset: usize) -> Position {
        let LineCol { line, col } = self.index.line_col(self.text, offset, self.encoding.unit());
        Position::new(line, col)
    }

    pub fn range(&self, span: Span) -> Range {
        Range::new(self.position(span.start), self.position(span.end))
    }

    /// The byte offset of a position; past the end of a line or the text, the
    /// position clamps to it (clients do send such positions).
    pub fn offset(&self, pos: Position) -> usize {
        let lc = LineCol {
            line: pos.line,
            col: pos.character,
        };
        self.index.offset(self.text, lc, self.encoding.unit())
    }

    pub fn span(&self, range: Range) -> Span {
        let (a, b) = (self.offset(range.start), self.offset(range.end));
        Span::new(a.min(b), a.max(b))
    }
}

/// The char index in `rope` of a protocol position, clamped as [`LineMap::offset`].
pub fn rope_char(rope: &Rope, pos: Position, encoding: Encoding) -> usize {
    let line = pos.line as usize;
    if line >= rope.len_lines() {
        return rope.len_chars();
    }
    let start = rope.line_to_char(line);
    let slice = rope.line(line);
    // The line's content without its `\n`.
    let mut len = slice.len_chars();
    if len > 0 && slice.char(len - 1) == '\n' {
        len -= 1;
    }
    let content = slice.slice(..len);
    let col = pos.character as usize;
    let chars = match encoding {
        Encoding::Utf8 => {
            let byte = col.min(content.len_bytes());
            // A column inside a character moves back to its start.
            content.byte_to_char(byte)
        }
        Encoding::Utf16 => {
            let unit = col.min(content.len_utf16_cu());
            content.utf16_cu_to_char(unit)
        }
    };
    start + chars
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# 한국어 주석\nmove(\"😀\") x\n";

    #[test]
    fn rope_and_line_index_agree_in_both_encodings() {
        let rope = Rope::from_str(TEXT);
        let index = LineIndex::new(TEXT);
        for encoding in [Encoding::Utf8, Encoding::Utf16] {
            let map = LineMap {
                text: TEXT,
                index: &index,
                encoding,
            };
            for (offset, _) in TEXT.char_indices() {
                let pos = map.position(offset);
                assert_eq!(map.offset(pos), offset, "{encoding:?} {pos:?}");
                let ch = rope_char(&rope, pos, encoding);
                assert_eq!(rope.char_to_byte(ch), offset, "{encoding:?} {pos:?}");
            }
        }
    }

    #[test]
    fn positions_past_the_end_clamp() {
        let rope = Rope::from_str(TEXT);
        let x_line_end = TEXT.len() - 1;
        for encoding in [Encoding::Utf8, Encoding::Utf16] {
            assert_eq!(
                rope.char_to_byte(rope_char(&rope, Position::new(1, 999), encoding)),
                x_line_end
            );
            assert_eq!(
                rope_char(&rope, Position::new(99, 0), encoding),
                rope.len_chars()
            );
        }
    }

    #[test]
    fn utf16_columns_count_surrogate_pairs() {
        let index = LineIndex::new(TEXT);
        let x = TEXT.find(" x").unwrap() + 1;
        let utf16 = LineMap {
            text: TEXT,
            index: &index,
            encoding: Encoding::Utf16,
        };
        let utf8 = LineMap {
            encoding: Encoding::Utf8,
            ..utf16
        };
        assert_eq!(utf16.position(x), Position::new(1, 11));
        assert_eq!(utf8.position(x), Position::new(1, 13));
    }
}
