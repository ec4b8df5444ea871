//! The token cursor: puts the file's tokens into the document one by one, in
//! order, each with its comments and the space the spacing rule asks for. The
//! layout only says where lines break; it cannot drop or reorder a token.

use super::doc::Item;
use super::spacing::space_between;
use super::trivia::Trivia;
use crate::syntax::token::{Spanned, Token};

/// How a boundary between two lines of content is separated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sep {
    /// A line break (right after an opening bracket, say).
    Line,
    /// A line break, and an empty line if the user left one or more there.
    BlankIfWritten,
    /// A line break and an empty line (between top-level items).
    Blank,
}

pub struct Emitter<'s, 't> {
    text: &'s str,
    tokens: &'t [Spanned<'s>],
    trivia: &'t Trivia<'s>,
    /// Index of the next token to place.
    next: usize,
    items: Vec<Item<'s>>,
    prev: Option<Token<'s>>,
    /// The last item placed breaks the line (or nothing is placed yet): the
    /// next token needs no space.
    at_break: bool,
    /// The own-line comments before the next token are placed already.
    comments_placed: bool,
    /// The comment ending the line of the last token, placed after the groups
    /// and indentation that close right after that token: a comment after
    /// `move(a)` does not break the parentheses.
    trailing: Option<&'s str>,
}

impl<'s, 't> Emitter<'s, 't> {
    pub fn new(text: &'s str, tokens: &'t [Spanned<'s>], trivia: &'t Trivia<'s>) -> Self {
        Emitter {
            text,
            tokens,
            trivia,
            next: 0,
            items: Vec::with_capacity(tokens.len() * 3),
            prev: None,
            at_break: true,
            comments_placed: false,
            trailing: None,
        }
    }

    pub fn text(&self) -> &'s str {
        self.text
    }

    pub fn peek(&self) -> Option<Token<'s>> {
        self.tokens.get(self.next).map(|t| t.0)
    }

    /// The token `k` places after the next one, and where it starts.
    pub fn peek_nth(&self, k: usize) -> Option<(Token<'s>, usize)> {
        self.tokens.get(self.next + k).map(|t| (t.0, t.1.start))
    }

    /// Where the next token starts (the end of the text when there is none).
    pub fn peek_start(&self) -> usize {
        self.tokens
            .get(self.next)
            .map_or(self.text.len(), |t| t.1.start)
    }

    /// Where the next token ends (the end of the text when there is none).
    pub fn peek_end(&self) -> usize {
        self.tokens
            .get(self.next)
            .map_or(self.text.len(), |t| t.1.end)
    }

    pub fn at(&self, token: Token<'_>) -> bool {
        self.peek() == Some(token)
    }

    pub fn push(&mut self, item: Item<'s>) {
        if !matches!(item, Item::GroupEnd | Item::IndentEnd)
            && let Some(comment) = self.trailing.take()
        {
            self.items.push(Item::TrailingComment(comment));
            self.at_break = true;
        }
        match item {
            Item::Text(_) | Item::SpacedText(_) => self.at_break = false,
            Item::Line(_)
            | Item::Hard
            | Item::Blank
            | Item::TrailingComment(_)
            | Item::OwnLineComment(_) => self.at_break = true,
            Item::GroupStart | Item::GroupEnd | Item::IndentStart | Item::IndentEnd => {}
        }
        self.items.push(item);
    }

    /// Whether own-line comments precede the next token and are not placed yet.
    pub fn has_own_line_comments(&self) -> bool {
        !self.comments_placed && !self.trivia.own_line(self.next).is_empty()
    }

    /// Whether any comment lies between the last token placed and the next.
    pub fn has_comments_before_next(&self) -> bool {
        !self.trivia.all(self.next).is_empty()
    }

    /// Places the next token, after its own-line comments if the layout has not
    /// placed them at a boundary, and followed by its end-of-line comment.
    pub fn token(&mut self) {
        let Some(&(token, span)) = self.tokens.get(self.next) else {
            return;
        };
        if !self.comments_placed {
            for c in self.trivia.own_line(self.next) {
                self.push(Item::OwnLineComment(c.text));
            }
        }
        // The lexer's spans lie on character boundaries; were one not to, the
        // token would be missing and the output refused by the final check.
        let text = self.text.get(span.start..span.end).unwrap_or_default();
        if !self.at_break && self.prev.is_some_and(|p| space_between(p, token)) {
            self.push(Item::SpacedText(text));
        } else {
            self.push(Item::Text(text));
        }
        self.prev = Some(token);
        self.next += 1;
        self.comments_placed = false;
        self.trailing = self.trivia.trailing(self.next).map(|c| c.text);
    }

    /// Places every token that starts before `end`, on the current line.
    pub fn plain(&mut self, end: usize) {
        while self.next < self.tokens.len() && self.peek_start() < end {
            self.token();
        }
    }

    /// Places the `;` tokens that follow.
    pub fn semis(&mut self) {
        while self.at(Token::Semi) {
            self.token();
        }
    }

    /// A line break before the next token, with the own-line comments before
    /// it each on their line. Empty lines the user wrote between them are kept
    /// (one at most), except before a closing bracket (`before_closer`).
    pub fn boundary(&mut self, sep: Sep, before_closer: bool) {
        let i = self.next;
        let first = match sep {
            Sep::Line => Item::Hard,
            Sep::Blank => Item::Blank,
            Sep::BlankIfWritten if self.trivia.newlines_before_own_line(i) >= 2 => Item::Blank,
            Sep::BlankIfWritten => Item::Hard,
        };
        self.push(first);
        if self.comments_placed {
            return;
        }
        let comments = self.trivia.own_line(i);
        for (k, c) in comments.iter().enumerate() {
            if k > 0 {
                self.push(if c.newlines_before >= 2 {
                    Item::Blank
                } else {
                    Item::Hard
                });
            }
            self.push(Item::OwnLineComment(c.text));
        }
        if !comments.is_empty() {
            let blank = !before_closer && self.trivia.gaps[i].newlines_after >= 2;
            self.push(if blank { Item::Blank } else { Item::Hard });
        }
        self.comments_placed = true;
    }

    /// The document, with the comments after the last token. Fails with the
    /// position of the first token the layout did not place (a formatter bug).
    pub fn finish(mut self) -> Result<Vec<Item<'s>>, usize> {
        if let Some(&(_, span)) = self.tokens.get(self.next) {
            return Err(span.start);
        }
        if !self.trivia.own_line(self.next).is_empty() {
            self.boundary(Sep::BlankIfWritten, true);
        }
        if let Some(comment) = self.trailing.take() {
            self.items.push(Item::TrailingComment(comment));
        }
        Ok(self.items)
    }
}
