//! Bracket balancing inside one chunk, before parsing.
//!
//! Chumsky's recovery can only skip a bracketed group when the group is closed;
//! with unclosed brackets it retries at every nesting level, which is exponential.
//! So brackets are balanced first, in one linear pass: an unclosed `{`, `(`,
//! `[[` or `[` is reported and closed where its parent closes (or at the end of
//! the chunk); a closer without an opener is reported and dropped. Nesting deeper
//! than [`MAX_DEPTH`] (counting `else if` chains and `and`/`or`/`not` chains,
//! which nest too: each link is one level of the tree) is reported and the rest
//! of the chunk dropped, so that parser and checker recursion (and dropping the
//! tree) stays bounded whatever the input.

use super::token::{Kw, Token};
use crate::diag::{Code, Diagnostic, FileId};
use crate::span::Span;
use chumsky::span::SimpleSpan;
use std::borrow::Cow;

type Tok<'s> = (Token<'s>, SimpleSpan);

/// Deeper than any sensible mission, and shallow enough for a 2 MB thread stack.
pub const MAX_DEPTH: usize = 64;

fn closer_of(open: Token<'_>) -> Option<Token<'static>> {
    Some(match open {
        Token::LBrace => Token::RBrace,
        Token::LParen => Token::RParen,
        Token::GroupOpen => Token::GroupClose,
        Token::LBracket => Token::RBracket,
        _ => return None,
    })
}

fn is_closer(t: Token<'_>) -> bool {
    matches!(
        t,
        Token::RBrace | Token::RParen | Token::GroupClose | Token::RBracket
    )
}

fn too_deep() -> String {
    format!(
        "blocks, brackets, `else if` chains and `and`/`or`/`not` chains are nested too deeply here (more than {MAX_DEPTH} levels)"
    )
}

/// A token that nests the rest of its bracket one level deeper: an `else if`
/// link, or a logical operator (`a and b and c` is a tree as deep as its
/// chain).
fn nests(chunk: &[Tok<'_>], i: usize) -> bool {
    match chunk[i].0 {
        Token::Kw(Kw::Else) => chunk.get(i + 1).map(|t| t.0) == Some(Token::Kw(Kw::If)),
        Token::Kw(Kw::And | Kw::Or | Kw::Not) | Token::AndAnd | Token::OrOr | Token::Bang => true,
        _ => false,
    }
}

struct Open<'s> {
    token: Token<'s>,
    /// Index of the opener in the chunk.
    index: usize,
    /// `else if` links and logical operators seen directly in this bracket:
    /// each nests one level.
    else_ifs: usize,
}

/// Whether the chunk needs no repair: brackets balanced, nesting within bounds.
/// Most chunks are like this; checking needs no allocation.
fn already_balanced(chunk: &[Tok<'_>]) -> bool {
    let mut closers = [Token::RBrace; MAX_DEPTH];
    let mut else_ifs = [0usize; MAX_DEPTH];
    let (mut open, mut depth) = (0, 0);
    for (i, &(token, _)) in chunk.iter().enumerate() {
        if let Some(closer) = closer_of(token) {
            if depth >= MAX_DEPTH {
                return false;
            }
            closers[open] = closer;
            else_ifs[open] = 0;
            open += 1;
            depth += 1;
        } else if is_closer(token) {
            if open == 0 || closers[open - 1] != token {
                return false;
            }
            open -= 1;
            depth -= 1 + else_ifs[open];
        } else if nests(chunk, i) {
            if depth >= MAX_DEPTH {
                return false;
            }
            depth += 1;
            if open > 0 {
                else_ifs[open - 1] += 1;
            }
        }
    }
    open == 0
}

/// Returns the chunk with balanced brackets, reporting every repair.
///
/// An unclosed `(` or `[` is closed at the end of its own line (conditions and
/// argument lists are written on one line: `move("1,1"` then `stop()` below is
/// one mistake, not two); an unclosed `{` or `[[` where its parent closes.
pub fn balance<'c, 's>(
    text: &str,
    chunk: &'c [Tok<'s>],
    file: FileId,
    diagnostics: &mut Vec<Diagnostic>,
) -> Cow<'c, [Tok<'s>]> {
    if already_balanced(chunk) {
        return Cow::Borrowed(chunk);
    }
    let n = chunk.len();
    let mut report = |span: SimpleSpan, message: String| {
        diagnostics.push(Diagnostic::new(
            Code::SyntaxError,
            file,
            Span::new(span.start, span.end),
            message,
        ));
    };
    let starts_line = |j: usize| {
        j > 0
            && text
                .get(chunk[j - 1].1.end..chunk[j].1.start)
                .is_some_and(|gap| gap.contains('\n'))
    };

    // Pass 1: match brackets; decide where each missing closer goes.
    let mut stack: Vec<Open<'s>> = Vec::new();
    let mut matched: Vec<Option<usize>> = vec![None; n];
    let mut stray = vec![false; n];
    // (insert before this index, opener index)
    let mut missing: Vec<(usize, usize)> = Vec::new();
    let mut depth = 0;
    let mut end = n;
    let close_unclosed = |stack: &mut Vec<Open<'s>>,
                          keep: usize,
                          limit: usize,
                          matched: &[Option<usize>],
                          missing: &mut Vec<(usize, usize)>,
                          report: &mut dyn FnMut(SimpleSpan, String)| {
        // Innermost first; an outer closer never goes before an inner one.
        let mut floor = 0;
        let mut closed_levels = 0;
        while stack.len() > keep {
            let open = stack.pop().unwrap_or_else(|| unreachable!());
            report(
                chunk[open.index].1,
                format!("this `{}` is never closed", open.token),
            );
            let mut at = limit;
            if matches!(open.token, Token::LParen | Token::LBracket) {
                let mut j = open.index + 1;
                while j < limit {
                    if starts_line(j) {
                        at = j;
                        break;
                    }
                    j = matched[j].map_or(j + 1, |close| close + 1);
                }
            }
            at = at.max(floor);
            floor = at;
            missing.push((at, open.index));
            closed_levels += 1 + open.else_ifs;
        }
        closed_levels
    };
    for i in 0..n {
        let token = chunk[i].0;
        if closer_of(token).is_some() {
            depth += 1;
            if depth > MAX_DEPTH {
                report(chunk[i].1, too_deep());
                end = i;
                break;
            }
            stack.push(Open {
                token,
                index: i,
                else_ifs: 0,
            });
        } else if is_closer(token) {
            let Some(pos) = stack
                .iter()
                .rposition(|o| closer_of(o.token) == Some(token))
            else {
                report(
                    chunk[i].1,
                    format!("this `{token}` has no matching opening bracket"),
                );
                stray[i] = true;
                continue;
            };
            depth -= close_unclosed(&mut stack, pos + 1, i, &matched, &mut missing, &mut report);
            let open = stack.pop().unwrap_or_else(|| unreachable!());
            matched[open.index] = Some(i);
            depth -= 1 + open.else_ifs;
        } else if nests(chunk, i) {
            depth += 1;
            if let Some(open) = stack.last_mut() {
                open.else_ifs += 1;
            }
            if depth > MAX_DEPTH {
                report(chunk[i].1, too_deep());
                end = i;
                break;
            }
        }
    }
    close_unclosed(&mut stack, 0, end, &matched, &mut missing, &mut report);

    // Pass 2: copy, dropping stray closers and inserting the missing ones.
    missing.sort_by_key(|&(at, opener)| (at, std::cmp::Reverse(opener)));
    let mut out: Vec<Tok<'s>> = Vec::with_capacity(end + missing.len());
    let mut next = missing.iter().peekable();
    for i in 0..=end {
        while let Some(&&(at, opener)) = next.peek() {
            if at != i {
                break;
            }
            let after = if i > 0 { chunk[i - 1].1.end } else { 0 };
            let closer = closer_of(chunk[opener].0).unwrap_or(Token::RBrace);
            out.push((closer, SimpleSpan::from(after..after)));
            next.next();
        }
        if i < end && !stray[i] {
            out.push(chunk[i]);
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::token::lex;

    fn balanced(text: &str) -> (String, Vec<String>) {
        let mut diags = Vec::new();
        let tokens = lex(text);
        let toks = balance(text, &tokens, FileId(0), &mut diags);
        let s: Vec<String> = toks.iter().map(|t| t.0.to_string()).collect();
        (s.join(" "), diags.into_iter().map(|d| d.message).collect())
    }

    #[test]
    fn closes_an_unclosed_paren_before_its_block_ends() {
        let (toks, diags) = balanced("T.A.S { move(\"1,1\" }");
        assert_eq!(toks, "T . A . S { move ( \"1,1\" ) }");
        assert_eq!(diags, vec!["this `(` is never closed"]);
    }

    #[test]
    fn closes_an_unclosed_paren_at_the_end_of_its_line() {
        let (toks, diags) = balanced("T.A.S {\n  move(\"1,1\"\n  stop()\n}");
        assert_eq!(toks, "T . A . S { move ( \"1,1\" ) stop ( ) }");
        assert_eq!(diags, vec!["this `(` is never closed"]);
    }

    #[test]
    fn multi_line_groups_inside_an_unclosed_paren_stay_whole() {
        let (toks, _) = balanced("f( g(a\n b) c\n d }");
        assert_eq!(toks, "f ( g ( a b ) c ) d");
    }

    #[test]
    fn drops_stray_closers_and_closes_at_the_end() {
        let (toks, diags) = balanced("a ) { b");
        assert_eq!(toks, "a { b }");
        assert_eq!(
            diags,
            vec![
                "this `)` has no matching opening bracket",
                "this `{` is never closed"
            ]
        );
    }

    #[test]
    fn balanced_chunks_are_borrowed_unchanged() {
        let tokens = lex("T.A.S { if (a) { b() } else if (c) d() } repeat(1 SEC)");
        let mut diags = Vec::new();
        assert!(matches!(
            balance("", &tokens, FileId(0), &mut diags),
            Cow::Borrowed(_)
        ));
        assert!(diags.is_empty());
    }

    #[test]
    fn limits_depth_including_else_if_chains() {
        let deep = "(".repeat(MAX_DEPTH + 5);
        let (_, diags) = balanced(&deep);
        assert!(diags[0].contains("nested too deeply"));
        let chain = format!(
            "T.A.S {{ if (x) a() {} }}",
            "else if (x) a() ".repeat(MAX_DEPTH + 1)
        );
        let (_, diags) = balanced(&chain);
        assert!(diags[0].contains("nested too deeply"), "{diags:?}");
    }

    #[test]
    fn limits_and_or_not_chains_per_bracket() {
        let long =
            |op: &str, n: usize| format!("T.A.S {{ if (x{}) a() }}", format!(" {op} x").repeat(n));
        for op in ["and", "or", "&&", "||"] {
            let (_, diags) = balanced(&long(op, MAX_DEPTH + 1));
            assert!(diags[0].contains("nested too deeply"), "{op}: {diags:?}");
            // Each condition's chain ends with its bracket.
            let (_, diags) = balanced(&long(op, MAX_DEPTH - 4).repeat(3));
            assert!(diags.is_empty(), "{op}: {diags:?}");
        }
        let nots = format!("T.A.S {{ if ({}x) a() }}", "not ! ".repeat(MAX_DEPTH));
        let (_, diags) = balanced(&nots);
        assert!(diags[0].contains("nested too deeply"), "{diags:?}");
    }
}
