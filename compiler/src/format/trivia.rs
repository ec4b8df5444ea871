//! Comments and line breaks between tokens. The lexer drops them, so they are
//! recovered here from the gaps between token spans: in a file without lexical
//! errors a gap holds only whitespace and `#` comments.

use crate::span::Span;
use crate::syntax::token::Spanned;

/// A `#` comment as written, trailing whitespace (a `\r`, say) removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Comment<'s> {
    pub text: &'s str,
    pub span: Span,
    /// Line breaks between the end of what precedes it (token, comment or the
    /// start of the file) and the comment.
    pub newlines_before: u32,
}

/// What lies between two tokens (or before the first, or after the last).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Gap {
    /// Index of the gap's first comment in [`Trivia::comments`].
    first: u32,
    /// Number of comments in the gap.
    count: u32,
    /// Line breaks between the last comment (or the previous token) and the token.
    pub newlines_after: u32,
    /// Whether the gap follows a token (it is not the start of the file).
    after_token: bool,
}

/// Every comment of a file, and for each token the gap before it.
#[derive(Clone, Debug, Default)]
pub struct Trivia<'s> {
    pub comments: Vec<Comment<'s>>,
    /// `gaps[i]` lies before token `i`; `gaps[tokens.len()]` after the last token.
    pub gaps: Vec<Gap>,
}

impl<'s> Trivia<'s> {
    /// All comments of gap `i`, trailing one included.
    pub fn all(&self, i: usize) -> &[Comment<'s>] {
        let gap = self.gaps[i];
        &self.comments[gap.first as usize..(gap.first + gap.count) as usize]
    }

    /// The comment that ends the line of the token before gap `i`, if any.
    pub fn trailing(&self, i: usize) -> Option<&Comment<'s>> {
        let gap = self.gaps.get(i)?;
        self.all(i)
            .first()
            .filter(|c| gap.after_token && c.newlines_before == 0)
    }

    /// The comments of gap `i` that stand on their own lines.
    pub fn own_line(&self, i: usize) -> &[Comment<'s>] {
        let all = self.all(i);
        match self.trailing(i) {
            Some(_) => &all[1..],
            None => all,
        }
    }

    /// Line breaks before the first own-line comment of gap `i`, or before the
    /// token when there is none.
    pub fn newlines_before_own_line(&self, i: usize) -> u32 {
        let skip = usize::from(self.trailing(i).is_some());
        match self.all(i).get(skip) {
            Some(c) => c.newlines_before,
            None => self.gaps[i].newlines_after,
        }
    }
}

/// The position of a character that is neither whitespace nor in a comment
/// between two tokens (possible only in text with lexical errors).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unexpected(pub usize);

/// Finds the comments and counts the line breaks between `tokens` of `text`.
pub fn scan<'s>(text: &'s str, tokens: &[Spanned<'s>]) -> Result<Trivia<'s>, Unexpected> {
    let mut trivia = Trivia {
        comments: Vec::new(),
        gaps: Vec::with_capacity(tokens.len() + 1),
    };
    let mut from = 0;
    for (i, (_, span)) in tokens.iter().enumerate() {
        let gap = scan_gap(text, from, span.start, i > 0, &mut trivia.comments)?;
        trivia.gaps.push(gap);
        from = span.end;
    }
    let last = scan_gap(
        text,
        from,
        text.len(),
        !tokens.is_empty(),
        &mut trivia.comments,
    )?;
    trivia.gaps.push(last);
    Ok(trivia)
}

fn scan_gap<'s>(
    text: &'s str,
    start: usize,
    end: usize,
    after_token: bool,
    comments: &mut Vec<Comment<'s>>,
) -> Result<Gap, Unexpected> {
    let first = comments.len() as u32;
    let gap = text.get(start..end).ok_or(Unexpected(start))?;
    let bytes = gap.as_bytes();
    let mut newlines = 0;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'#' => {
                let line_end = gap[i..].find('\n').map_or(gap.len(), |n| i + n);
                let comment = gap[i..line_end].trim_end();
                comments.push(Comment {
                    text: comment,
                    span: Span::new(start + i, start + i + comment.len()),
                    newlines_before: newlines,
                });
                newlines = 0;
                i = line_end;
            }
            b'\n' => {
                newlines += 1;
                i += 1;
            }
            b if b.is_ascii_whitespace() || b == 0x0b => i += 1,
            b if b.is_ascii() => return Err(Unexpected(start + i)),
            _ => {
                // Other whitespace the lexer skips: no-break spaces, em spaces...
                let c = gap[i..].chars().next().ok_or(Unexpected(start + i))?;
                if !c.is_whitespace() {
                    return Err(Unexpected(start + i));
                }
                i += c.len_utf8();
            }
        }
    }
    Ok(Gap {
        first,
        count: comments.len() as u32 - first,
        newlines_after: newlines,
        after_token,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::token::lex;

    #[test]
    fn trailing_and_own_line_comments_with_their_line_breaks() {
        let text = "# head\n\na # end of a\n  # own\n\n\n  b # last\n";
        let tokens = lex(text);
        let trivia = scan(text, &tokens).unwrap();
        assert_eq!(trivia.gaps.len(), 3);
        // Before `a`: a comment at the start of the file is not trailing.
        assert_eq!(trivia.trailing(0), None);
        assert_eq!(trivia.own_line(0)[0].text, "# head");
        assert_eq!(trivia.gaps[0].newlines_after, 2);
        // Between `a` and `b`.
        assert_eq!(trivia.trailing(1).map(|c| c.text), Some("# end of a"));
        let own: Vec<_> = trivia.own_line(1).iter().map(|c| c.text).collect();
        assert_eq!(own, ["# own"]);
        assert_eq!(trivia.newlines_before_own_line(1), 1);
        assert_eq!(trivia.gaps[1].newlines_after, 3);
        // After `b`.
        assert_eq!(trivia.trailing(2).map(|c| c.text), Some("# last"));
        assert!(trivia.own_line(2).is_empty());
    }

    #[test]
    fn comment_text_keeps_everything_but_trailing_whitespace() {
        let text = "a #  Korean 한국어 😀 \r\nb";
        let tokens = lex(text);
        let trivia = scan(text, &tokens).unwrap();
        let c = trivia.trailing(1).unwrap();
        assert_eq!(c.text, "#  Korean 한국어 😀");
        assert_eq!(&text[c.span.range()], c.text);
        assert_eq!(trivia.gaps[1].newlines_after, 1);
    }

    #[test]
    fn every_whitespace_the_lexer_skips_is_skipped_and_anything_else_reported() {
        let text = "a\t\u{b}\u{c}\r\u{85}\u{a0}\u{3000}\u{2028}b";
        let tokens = lex(text);
        assert_eq!(tokens.len(), 2);
        assert!(scan(text, &tokens).is_ok());
        // Between tokens that do not cover the text, something is left over.
        let partial = &tokens[..1];
        assert_eq!(scan("a @", partial).err(), Some(Unexpected(2)));
        assert_eq!(scan("a 한", partial).err(), Some(Unexpected(2)));
    }

    #[test]
    fn a_hash_inside_a_string_is_not_a_comment() {
        let text = "say(\"#1\")";
        let trivia = scan(text, &lex(text)).unwrap();
        assert!(trivia.comments.is_empty());
    }
}
