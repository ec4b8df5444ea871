//! Cutting the token stream into independent top-level chunks, so that a syntax
//! error in one item (even an unbalanced brace) cannot swallow the items after it.
//!
//! A chunk starts at every item header. `T.P.S {`, `A, B.P.S {`, `T.M {`,
//! `T.main {`, `def f {`, and with a parameter list `def f(A, B) {`,
//! `T.P.S(A) {`, `A, B.P.S(A) {` and `T.M(A) {` can never occur inside a
//! statement, so they start a chunk wherever
//! they appear; `{` and `T:` start one only at brace depth zero (they also occur
//! inside a braced team formation). A `}` with no matching `{` is a chunk of its own.

use super::token::{Kw, Token};
use chumsky::span::SimpleSpan;

type Tok<'s> = (Token<'s>, SimpleSpan);

/// The most tokens a header's list (the parameters of a function, a service
/// or a mode, the teams of a shared service) may hold: a header is then at
/// most [`MAX_HEADER_TOKENS`]
/// long, which incremental parsing relies on (it cuts again from a chunk
/// start at least that far before an edit, so that no header it keeps
/// reaches into the edit). 64 tokens: 32 names.
pub const MAX_LIST_TOKENS: usize = 64;

/// The longest header: `A, B.P.S(A) {`, a list of teams and a list of
/// parameters, each at most the longest list.
pub const MAX_HEADER_TOKENS: usize = 2 * MAX_LIST_TOKENS + 8;

/// If an item header starts at token `i`, the index of its opening brace.
#[inline(always)]
fn header_brace(tokens: &[Tok<'_>], i: usize) -> Option<usize> {
    let at = |k: usize| tokens.get(i + k).map(|t| t.0);
    let ident = |k: usize| matches!(at(k), Some(Token::Ident(_)));
    let brace = |k: usize| (at(k) == Some(Token::LBrace)).then_some(i + k);
    // `(A, B) {` from `from`, the token after `(`: the list ends at the
    // first bracket or `def` (so that each token is looked at by one header
    // at most: the cut stays linear), and the header is an item only if
    // that is `)` then `{` (a list that does not parse is still a header).
    let params = |from: usize| {
        let close = (from..=from + MAX_LIST_TOKENS).find(|&k| {
            !matches!(
                at(k),
                Some(t) if !matches!(
                    t,
                    Token::LParen | Token::RParen | Token::LBrace | Token::RBrace | Token::Kw(Kw::Def)
                )
            )
        })?;
        (at(close) == Some(Token::RParen)).then_some(())?;
        brace(close + 1)
    };
    match at(0)? {
        Token::Kw(Kw::Def) if ident(1) && at(2) == Some(Token::LParen) => params(3),
        Token::Kw(Kw::Def) if ident(1) => brace(2),
        // `A, B.P.S {`: a service shared by teams. The list is scanned
        // from its first name only (a name after a comma is inside the
        // list), so each token is looked at by one header at most.
        Token::Ident(_)
            if at(1) == Some(Token::Comma)
                && i.checked_sub(1).is_none_or(|p| tokens[p].0 != Token::Comma) =>
        {
            let mut k = 1;
            while at(k) == Some(Token::Comma) && ident(k + 1) && k < MAX_LIST_TOKENS {
                k += 2;
            }
            let service = at(k) == Some(Token::Dot)
                && ident(k + 1)
                && at(k + 2) == Some(Token::Dot)
                && ident(k + 3);
            service.then_some(())?;
            match at(k + 4) {
                Some(Token::LParen) => params(k + 5),
                _ => brace(k + 4),
            }
        }
        Token::Ident(_) if at(1) == Some(Token::Dot) => match at(2)? {
            Token::Kw(Kw::Main) => brace(3),
            Token::Ident(_) if at(3) == Some(Token::Dot) && ident(4) => match at(5) {
                Some(Token::LParen) => params(6),
                _ => brace(5),
            },
            Token::Ident(_) if at(3) == Some(Token::LParen) => params(4),
            Token::Ident(_) => brace(3),
            _ => None,
        },
        _ => None,
    }
}

/// Token index ranges of the chunks, in order, covering every token.
pub fn split(tokens: &[Tok<'_>]) -> Vec<std::ops::Range<usize>> {
    split_from(tokens, 0, |_| false).0
}

/// The chunks from token `from` on, where a chunk starts; stops early where
/// `stop` says so when a chunk starts at a token after `from`.
///
/// Returns the chunks before the stop, and where it stopped (`tokens.len()`
/// when it did not). Resuming at a chunk start is exact: after a cut the state
/// is always the same (depth zero, and no header whose brace is still to come,
/// as no chunk starts inside a header), so the chunks after a chunk start
/// depend only on the tokens from there on. Incremental parsing relies on
/// this, to cut again only around an edit.
pub fn split_from(
    tokens: &[Tok<'_>],
    from: usize,
    mut stop: impl FnMut(usize) -> bool,
) -> (Vec<std::ops::Range<usize>>, usize) {
    let mut chunks = Vec::new();
    let mut start = from;
    let mut depth: usize = 0;
    // The brace that opens the body of the header seen last: not a new chunk.
    let mut body_brace = None;
    for i in from..tokens.len() {
        let token = tokens[i].0;
        let at_top = depth == 0;
        // Inside `A.P.S {`, `P.S {` looks like a mode header: not a new item.
        let in_header = body_brace.is_some_and(|b| i <= b);
        let header = header_brace(tokens, i).filter(|_| !in_header);
        if header.is_some()
            || (at_top && token == Token::LBrace && body_brace != Some(i))
            || (at_top
                && matches!(token, Token::Ident(_))
                && tokens.get(i + 1).map(|t| t.0) == Some(Token::Colon))
        {
            if cut(&mut chunks, &mut start, i) && stop(i) {
                return (chunks, i);
            }
            depth = 0;
        }
        if header.is_some() {
            body_brace = header;
        }
        match token {
            Token::LBrace => depth += 1,
            Token::RBrace if depth == 0 => {
                if cut(&mut chunks, &mut start, i) && stop(i) {
                    return (chunks, i);
                }
                if cut(&mut chunks, &mut start, i + 1) && i + 1 < tokens.len() && stop(i + 1) {
                    return (chunks, i + 1);
                }
            }
            Token::RBrace => depth -= 1,
            _ => {}
        }
    }
    cut(&mut chunks, &mut start, tokens.len());
    (chunks, tokens.len())
}

/// Ends the chunk that began at `start` before token `at`, if it is not
/// empty; whether it did (a new chunk starts at `at`).
fn cut(chunks: &mut Vec<std::ops::Range<usize>>, start: &mut usize, at: usize) -> bool {
    if at > *start {
        chunks.push(*start..at);
        *start = at;
        true
    } else {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::token::lex;

    fn chunk_texts(text: &str) -> Vec<String> {
        let tokens = lex(text);
        split(&tokens)
            .into_iter()
            .map(|r| text[tokens[r.start].1.start..tokens[r.end - 1].1.end].to_string())
            .collect()
    }

    #[test]
    fn cuts_at_headers_even_when_a_brace_is_missing() {
        let text =
            "{ A: x a\n B: y b }\nA.P.S { move() \nA.M { set(P, S) }\nA.main { default: mode = M }";
        assert_eq!(
            chunk_texts(text),
            vec![
                "{ A: x a\n B: y b }",
                "A.P.S { move()",
                "A.M { set(P, S) }",
                "A.main { default: mode = M }"
            ]
        );
    }

    #[test]
    fn bare_team_declarations_and_stray_braces() {
        let text = "A: x a\nB: y b[2]\n} def f { stop() }";
        assert_eq!(
            chunk_texts(text),
            vec!["A: x a", "B: y b[2]", "}", "def f { stop() }"]
        );
    }

    #[test]
    fn a_function_with_parameters_is_a_header_even_when_its_list_is_wrong() {
        let text = "def f(A, B) { move(A) \ndef g(5 SEC) { x }\ndef h( { y } A.M { }";
        assert_eq!(
            chunk_texts(text),
            // `def h(` without `)` is no header: its `{` at the top starts one.
            vec![
                "def f(A, B) { move(A)",
                "def g(5 SEC) { x }\ndef h(",
                "{ y }",
                "A.M { }"
            ]
        );
    }

    #[test]
    fn services_and_modes_with_parameters_are_headers() {
        let text = "A.P.S(X) { move(X) \nA, B.P.T(X, Y) { x }\nA.M(X) { set(P, S(X)) }\nA.N( { y }";
        assert_eq!(
            chunk_texts(text),
            // `A.N(` without `)` is no header: its `{` at the top starts one.
            vec![
                "A.P.S(X) { move(X)",
                "A, B.P.T(X, Y) { x }",
                "A.M(X) { set(P, S(X)) }\nA.N(",
                "{ y }"
            ]
        );
    }

    #[test]
    fn a_service_shared_by_teams_is_one_header() {
        let text = "A, B.P.S { send(T, T.X) move() \nA, B, C.Q.R { x }\nf(a, b) A.M { }";
        assert_eq!(
            chunk_texts(text),
            vec![
                "A, B.P.S { send(T, T.X) move()",
                "A, B, C.Q.R { x }\nf(a, b)",
                "A.M { }"
            ]
        );
    }

    #[test]
    fn resuming_at_any_chunk_start_cuts_the_same_chunks() {
        let text = "{ A: x a\n B: y b }\n} } A.P.S { { move() } A.M { set(P, S) }\n\
                    T: a b { def f { x } T.main { } ) } A.P.S { B.C.D { def g(X) { y } def h( { A, B.C.D { x, y";
        let tokens = lex(text);
        let all = split(&tokens);
        assert!(all.len() > 8, "{all:?}");
        for (k, chunk) in all.iter().enumerate() {
            let (rest, end) = split_from(&tokens, chunk.start, |_| false);
            assert_eq!(rest, all[k..], "resumed at chunk {k}");
            assert_eq!(end, tokens.len());
            // Stopping where a later chunk starts gives the chunks before it.
            if let Some(later) = all.get(k + 2) {
                let (some, at) = split_from(&tokens, chunk.start, |at| at == later.start);
                assert_eq!((some.as_slice(), at), (&all[k..k + 2], later.start));
            }
        }
    }
}
