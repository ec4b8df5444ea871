//! An open document: its text as a rope and the version the client gave it.
//! Edits arrive as incremental changes in the negotiated position encoding.

use crate::encoding::{Encoding, rope_char};
use ropey::Rope;
use tower_lsp_server::ls_types::TextDocumentContentChangeEvent;

#[derive(Clone, Debug)]
pub struct Document {
    pub rope: Rope,
    pub version: i32,
}

impl Document {
    pub fn new(text: &str, version: i32) -> Document {
        Document {
            rope: Rope::from_str(text),
            version,
        }
    }

    /// Applies the changes of one `didChange`, in order. A change without a
    /// range replaces the whole text. Ranges past the end clamp to it, and a
    /// reversed range is read as its two ends, so no change can fail.
    pub fn apply(
        &mut self,
        changes: Vec<TextDocumentContentChangeEvent>,
        version: i32,
        encoding: Encoding,
    ) {
        for change in changes {
            match change.range {
                None => self.rope = Rope::from_str(&change.text),
                Some(range) => {
                    let a = rope_char(&self.rope, range.start, encoding);
                    let b = rope_char(&self.rope, range.end, encoding);
                    let (start, end) = (a.min(b), a.max(b));
                    self.rope.remove(start..end);
                    self.rope.insert(start, &change.text);
                }
            }
        }
        self.version = version;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tower_lsp_server::ls_types::{Position, Range};

    fn change(range: ((u32, u32), (u32, u32)), text: &str) -> TextDocumentContentChangeEvent {
        TextDocumentContentChangeEvent {
            range: Some(Range::new(
                Position::new(range.0.0, range.0.1),
                Position::new(range.1.0, range.1.1),
            )),
            range_length: None,
            text: text.to_string(),
        }
    }

    #[test]
    fn edits_after_korean_and_emoji_land_in_both_encodings() {
        let text = "# 한국어\nsay(\"😀\") x\n";
        // `x` is at UTF-16 column 10 and UTF-8 column 12 of line 1.
        for (encoding, col) in [(Encoding::Utf16, 10), (Encoding::Utf8, 12)] {
            let mut doc = Document::new(text, 1);
            doc.apply(vec![change(((1, col), (1, col + 1)), "y")], 2, encoding);
            assert_eq!(doc.rope.to_string(), "# 한국어\nsay(\"😀\") y\n");
            assert_eq!(doc.version, 2);
        }
    }

    #[test]
    fn changes_apply_in_order_and_full_replacements_reset() {
        let mut doc = Document::new("abc", 1);
        doc.apply(
            vec![
                change(((0, 3), (0, 3)), "\nd"),
                change(((1, 1), (1, 1)), "e"),
                change(((0, 0), (0, 1)), ""),
            ],
            2,
            Encoding::Utf16,
        );
        assert_eq!(doc.rope.to_string(), "bc\nde");
        doc.apply(
            vec![TextDocumentContentChangeEvent {
                range: None,
                range_length: None,
                text: "new".into(),
            }],
            3,
            Encoding::Utf16,
        );
        assert_eq!(doc.rope.to_string(), "new");
    }

    #[test]
    fn out_of_range_and_reversed_ranges_do_not_panic() {
        let mut doc = Document::new("ab\ncd", 1);
        doc.apply(vec![change(((9, 9), (0, 1)), "X")], 2, Encoding::Utf16);
        assert_eq!(doc.rope.to_string(), "aX");
    }
}
