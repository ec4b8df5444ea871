//! Mission-script syntax: text to a positioned [`ast::SourceFile`] plus syntax
//! diagnostics. Never panics, whatever the input; always returns a tree holding
//! every item that could be parsed.

pub mod ast;
mod chunks;
mod delimiters;
mod parser;
pub mod token;

use crate::diag::{Code, Diagnostic, FileId};
use crate::span::Span;
use chumsky::error::{RichPattern, RichReason};
use chumsky::prelude::*;
use token::Token;

/// The result of parsing one file.
#[derive(Clone, Debug, Default)]
pub struct Parse {
    pub file: ast::SourceFile,
    pub diagnostics: Vec<Diagnostic>,
}

/// Parses a mission script.
pub fn parse(file: FileId, text: &str) -> Parse {
    let mut diagnostics = Vec::new();
    let mut tokens = token::lex(text);

    // Lexical problems are reported here, and the tokens repaired so the parser
    // sees the rest of the statement.
    tokens.retain_mut(|(tok, span)| match *tok {
        Token::Error(c) => {
            diagnostics.push(Diagnostic::new(
                Code::InvalidCharacter,
                file,
                Span::new(span.start, span.end),
                format!(
                    "the character `{}` is not used in mission scripts",
                    c.escape_debug()
                ),
            ));
            false
        }
        Token::Unterminated(raw) => {
            diagnostics.push(Diagnostic::new(
                Code::UnterminatedString,
                file,
                Span::new(span.start, span.end),
                "this string has no closing quote `\"`",
            ));
            *tok = Token::Str(raw);
            true
        }
        _ => true,
    });

    let chunks: Vec<_> = chunks::split(&tokens)
        .into_iter()
        .map(|range| delimiters::balance(text, &tokens[range], file, &mut diagnostics))
        .collect();
    let fast = parser::items::<_, chumsky::error::EmptyErr>();
    let rich = parser::items::<_, parser::RichError<'_, '_>>();
    let mut items = Vec::new();
    for chunk in &chunks {
        let (Some(first), Some(last)) = (chunk.first(), chunk.last()) else {
            continue;
        };
        let chunk_span = Span::new(first.1.start, last.1.end);
        let eoi = SimpleSpan::from(last.1.end..last.1.end);
        let input = || -> parser::TokenInput<'_, '_> { chunk.as_slice().map(eoi, |(t, s)| (t, s)) };
        if let (Some(parsed), errors) = fast.parse(input()).into_output_errors()
            && errors.is_empty()
        {
            items.extend(parsed);
            continue;
        }
        let (output, errors) = rich.parse(input()).into_output_errors();
        for error in &errors {
            diagnostics.push(syntax_diagnostic(file, error));
        }
        match output {
            Some(parsed) => items.extend(parsed),
            None => {
                if errors.is_empty() {
                    diagnostics.push(Diagnostic::new(
                        Code::SyntaxError,
                        file,
                        chunk_span,
                        "this text could not be understood",
                    ));
                }
                items.push(ast::Item::Error(chunk_span));
            }
        }
    }
    Parse {
        file: ast::SourceFile { items },
        diagnostics,
    }
}

fn describe_found(found: Option<&Token<'_>>) -> String {
    match found {
        None => "the end of this part".to_string(),
        Some(Token::Str(_)) => "a string".to_string(),
        Some(Token::Number(n)) => format!("the number `{n}`"),
        Some(t) => format!("`{t}`"),
    }
}

fn describe_pattern(pattern: &RichPattern<'_, Token<'_>>) -> String {
    match pattern {
        RichPattern::Token(t) => format!("`{}`", &**t),
        RichPattern::Label(label) => label.to_string(),
        RichPattern::Identifier(id) => format!("`{id}`"),
        RichPattern::Any => "something".to_string(),
        RichPattern::SomethingElse => "something else".to_string(),
        RichPattern::EndOfInput => "the end".to_string(),
        _ => "something else".to_string(),
    }
}

/// An operator (or "anything else") that would merely continue what was parsed.
fn is_continuation(pattern: &RichPattern<'_, Token<'_>>) -> bool {
    use token::Kw;
    match pattern {
        RichPattern::Token(t) => matches!(
            **t,
            Token::AndAnd
                | Token::OrOr
                | Token::Kw(Kw::And | Kw::Or)
                | Token::EqEq
                | Token::NotEq
                | Token::Lt
                | Token::Le
                | Token::Gt
                | Token::Ge
        ),
        RichPattern::SomethingElse => true,
        _ => false,
    }
}

fn syntax_diagnostic(file: FileId, error: &Rich<'_, Token<'_>>) -> Diagnostic {
    let span = Span::new(error.span().start, error.span().end);
    let message = match error.reason() {
        RichReason::ExpectedFound { expected, found } => {
            // An operator that could continue the expression is rarely what is
            // missing: `move("1,1"` lacks its `)`, not an `and`.
            let likely: Vec<_> = expected.iter().filter(|p| !is_continuation(p)).collect();
            let shown = if likely.is_empty() {
                expected.iter().collect()
            } else {
                likely
            };
            let mut wanted: Vec<String> = shown.into_iter().map(describe_pattern).collect();
            wanted.sort();
            wanted.dedup();
            let found = describe_found(found.as_deref());
            match wanted.len() {
                0 => format!("unexpected {found}"),
                1 => format!("expected {}, found {found}", wanted[0]),
                n if n <= 6 => format!(
                    "expected {} or {}, found {found}",
                    wanted[..n - 1].join(", "),
                    wanted[n - 1]
                ),
                _ => format!("unexpected {found}"),
            }
        }
        RichReason::Custom(msg) => msg.to_string(),
    };
    Diagnostic::new(Code::SyntaxError, file, span, message)
}
