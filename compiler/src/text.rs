//! Line/column conversion for a source text, used only at the edges (CLI output,
//! LSP positions). Columns can be counted in UTF-8 bytes, UTF-16 code units or
//! Unicode scalar values (characters), because LSP clients and humans differ.

/// How a column is counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnUnit {
    Utf8,
    Utf16,
    Char,
}

/// A zero-based line and column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct LineCol {
    pub line: u32,
    pub col: u32,
}

/// Start offsets of every line of a text.
#[derive(Clone, Debug)]
pub struct LineIndex {
    line_starts: Vec<usize>,
    len: usize,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        let mut line_starts = vec![0];
        line_starts.extend(newlines(text.as_bytes()).map(|i| i + 1));
        LineIndex {
            line_starts,
            len: text.len(),
        }
    }

    pub fn line_count(&self) -> usize {
        self.line_starts.len()
    }

    /// Byte offset where zero-based `line` starts (clamped to the text).
    pub fn line_start(&self, line: usize) -> usize {
        self.line_starts.get(line).copied().unwrap_or(self.len)
    }

    /// The position of byte `offset` (clamped, and moved back to a char boundary).
    pub fn line_col(&self, text: &str, offset: usize, unit: ColumnUnit) -> LineCol {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.line_starts.partition_point(|&s| s <= offset) - 1;
        let prefix = &text[self.line_starts[line]..offset];
        let col = match unit {
            ColumnUnit::Utf8 => prefix.len(),
            ColumnUnit::Utf16 => prefix.encode_utf16().count(),
            ColumnUnit::Char => prefix.chars().count(),
        };
        LineCol {
            line: line as u32,
            col: col as u32,
        }
    }

    /// The byte offset of a position; columns past the end of the line clamp to it.
    pub fn offset(&self, text: &str, pos: LineCol, unit: ColumnUnit) -> usize {
        let line = pos.line as usize;
        if line >= self.line_starts.len() {
            return text.len();
        }
        let start = self.line_starts[line];
        let end = self
            .line_starts
            .get(line + 1)
            .map_or(text.len(), |&next| next - 1);
        let line_text = &text[start..end];
        let want = pos.col as usize;
        let mut counted = 0;
        for (i, ch) in line_text.char_indices() {
            if counted >= want {
                return start + i;
            }
            counted += match unit {
                ColumnUnit::Utf8 => ch.len_utf8(),
                ColumnUnit::Utf16 => ch.len_utf16(),
                ColumnUnit::Char => 1,
            };
        }
        end
    }
}

/// The offsets of the `\n` bytes of `bytes`, by `memchr` (vectorized: the
/// language server indexes every version of a file, and searching character
/// by character took a millisecond on a 10k-line file).
fn newlines(bytes: &[u8]) -> impl Iterator<Item = usize> + '_ {
    memchr::memchr_iter(b'\n', bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newlines_are_found_exactly() {
        for text in [
            "",
            "\n",
            "a\nb",
            "\n\x0b\n\x0b\x0b\n",
            "12345678\n1234567\n123456789\n",
            "# 한국어\n😀\n\n\n\n\n\n\n\n\nx\u{a0a}\u{10a0a}\n",
            "\x0a\x0b\x09\u{8a}\x0a\x0a\x01\x0a\x0b\x0b\x0a",
        ] {
            let expected: Vec<usize> = text.match_indices('\n').map(|(i, _)| i).collect();
            assert_eq!(
                newlines(text.as_bytes()).collect::<Vec<_>>(),
                expected,
                "{text:?}"
            );
        }
        // Every mix of newlines and their neighbours in value, up to 24 bytes.
        let alphabet = ['\n', '\x0b', '\x09', '\x01', 'a', 'é', '\u{a0a}'];
        let mut seed = 7u64;
        for _ in 0..2000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let text: String = (0..(seed >> 59) as usize)
                .map(|k| alphabet[((seed >> (k * 2 % 48)) % 7) as usize])
                .collect();
            let expected: Vec<usize> = text.match_indices('\n').map(|(i, _)| i).collect();
            assert_eq!(
                newlines(text.as_bytes()).collect::<Vec<_>>(),
                expected,
                "{text:?}"
            );
        }
    }

    #[test]
    fn columns_with_korean_and_emoji() {
        let text = "# 한국어 주석\nmove(\"😀\") x\n";
        let idx = LineIndex::new(text);
        let x = text.find(" x").unwrap() + 1;
        assert_eq!(
            idx.line_col(text, x, ColumnUnit::Char),
            LineCol { line: 1, col: 10 }
        );
        assert_eq!(
            idx.line_col(text, x, ColumnUnit::Utf16),
            LineCol { line: 1, col: 11 }
        );
        assert_eq!(
            idx.line_col(text, x, ColumnUnit::Utf8),
            LineCol { line: 1, col: 13 }
        );
        for unit in [ColumnUnit::Char, ColumnUnit::Utf16, ColumnUnit::Utf8] {
            let lc = idx.line_col(text, x, unit);
            assert_eq!(idx.offset(text, lc, unit), x);
        }
    }

    #[test]
    fn offsets_clamp() {
        let text = "ab\ncd";
        let idx = LineIndex::new(text);
        assert_eq!(
            idx.offset(text, LineCol { line: 0, col: 99 }, ColumnUnit::Char),
            2
        );
        assert_eq!(
            idx.offset(text, LineCol { line: 9, col: 0 }, ColumnUnit::Char),
            5
        );
        assert_eq!(
            idx.line_col(text, 99, ColumnUnit::Char),
            LineCol { line: 1, col: 2 }
        );
    }
}
