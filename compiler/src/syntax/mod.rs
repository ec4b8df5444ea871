//! Mission-script syntax: text to a positioned [`ast::SourceFile`] plus syntax
//! diagnostics. Never panics, whatever the input; always returns a tree holding
//! every item that could be parsed.

pub mod ast;
mod chunks;
mod delimiters;
mod incremental;
mod parser;
mod shift;
pub mod token;

pub use incremental::{ParseCache, parse_incremental};

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

/// Files at least this large are lexed and parsed on two threads.
const PARALLEL_MIN_BYTES: usize = 64 * 1024;

/// Whether `len` bytes of text are worth two threads (and there are two).
fn parallel(len: usize) -> bool {
    len >= PARALLEL_MIN_BYTES && std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2)
}

/// Runs `a` here and `b` on another thread; a panic in `b` is passed on.
fn join<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    std::thread::scope(|scope| {
        let other = scope.spawn(b);
        let a = a();
        match other.join() {
            Ok(b) => (a, b),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// Parses a mission script. Large files use two threads: no token spans a
/// newline, so the two halves of the text lex independently, and chunks parse
/// independently; the result is the same as on one thread.
pub fn parse(file: FileId, text: &str) -> Parse {
    parse_with(file, text, parallel(text.len())).0
}

/// [`parse`], also giving the tokens the tree was parsed from, for tools that
/// need both (the formatter). Where there are lexical errors, the tokens are
/// as repaired for the parser: unknown characters dropped, unterminated
/// strings taken as strings.
pub fn parse_with_tokens(file: FileId, text: &str) -> (Parse, Vec<token::Spanned<'_>>) {
    parse_with(file, text, parallel(text.len()))
}

fn parse_with(file: FileId, text: &str, two_threads: bool) -> (Parse, Vec<token::Spanned<'_>>) {
    let mut others = Vec::new();
    let mut tokens = lex(text, two_threads);
    let lexical = lexical_errors(&mut tokens);
    let ranges = chunks::split(&tokens);
    let mut items = Vec::new();
    for chunk in parse_ranges(file, text, &tokens, &ranges, two_threads) {
        items.extend(chunk.items);
        others.extend(chunk.diagnostics);
    }
    let diagnostics = assemble_diagnostics(file, &lexical, others);
    let parse = Parse {
        file: ast::SourceFile { items },
        diagnostics,
    };
    (parse, tokens)
}

/// Balances and parses the chunks `ranges` of `tokens`, on two threads if
/// asked (each taking about half of the tokens); the result is the same.
fn parse_ranges(
    file: FileId,
    text: &str,
    tokens: &[token::Spanned<'_>],
    ranges: &[std::ops::Range<usize>],
    two_threads: bool,
) -> Vec<ChunkParse> {
    let total: usize = ranges.iter().map(|r| r.len()).sum();
    let mut before = 0;
    let cut = ranges
        .iter()
        .position(|r| {
            before += r.len();
            before > total / 2
        })
        .map_or(ranges.len(), |i| i + 1);
    if two_threads && cut > 0 && cut < ranges.len() {
        let (first, second) = ranges.split_at(cut);
        let (mut chunks, more) = join(
            || parse_chunks(file, text, tokens, first),
            || parse_chunks(file, text, tokens, second),
        );
        chunks.extend(more);
        chunks
    } else {
        parse_chunks(file, text, tokens, ranges)
    }
}

/// Lexes `text`, in two halves cut at a newline when it is large.
fn lex(text: &str, two_threads: bool) -> Vec<token::Spanned<'_>> {
    let middle = text.len() / 2;
    let cut = match text.as_bytes()[middle..].iter().position(|&b| b == b'\n') {
        Some(i) if two_threads => middle + i + 1,
        _ => return token::lex(text),
    };
    let (mut tokens, rest) = join(|| token::lex(&text[..cut]), || token::lex(&text[cut..]));
    tokens.extend(
        rest.into_iter()
            .map(|(t, s)| (t, SimpleSpan::from(s.start + cut..s.end + cut))),
    );
    tokens
}

/// A lexical error, kept in this compact form (no message yet) so that a
/// file of junk costs little per error: the incremental cache holds every
/// one, but only the reported ones become [`Diagnostic`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct LexError {
    pub(crate) span: Span,
    kind: LexErrorKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LexErrorKind {
    /// Characters the language does not use: the first, and whether more follow.
    Unknown {
        first: char,
        more: bool,
    },
    Unterminated,
}

impl LexError {
    pub(crate) fn diagnostic(&self, file: FileId) -> Diagnostic {
        match self.kind {
            LexErrorKind::Unknown { first, more } => {
                let message = if more {
                    format!(
                        "these characters (from `{}` on) are not used in mission scripts",
                        first.escape_debug()
                    )
                } else {
                    format!(
                        "the character `{}` is not used in mission scripts",
                        first.escape_debug()
                    )
                };
                Diagnostic::new(Code::InvalidCharacter, file, self.span, message)
            }
            LexErrorKind::Unterminated => Diagnostic::new(
                Code::UnterminatedString,
                file,
                self.span,
                "this string has no closing quote `\"`",
            ),
        }
    }

    pub(crate) fn shifted(mut self, by: isize) -> LexError {
        self.span = Span::new(
            self.span.start.wrapping_add_signed(by),
            self.span.end.wrapping_add_signed(by),
        );
        self
    }
}

/// Finds characters the language does not use and unterminated strings, and
/// repairs the tokens so that the parser sees the rest of the statement. A run
/// of unknown characters (no space between them) is one error, so junk costs
/// one error per run, not per byte; runs never cross a newline, so a line's
/// errors depend only on the line (incremental lexing relies on it). In order.
fn lexical_errors(tokens: &mut Vec<token::Spanned<'_>>) -> Vec<LexError> {
    let mut errors: Vec<LexError> = Vec::new();
    tokens.retain_mut(|(tok, span)| match *tok {
        Token::Error(c) => {
            // A token is a run of unknown characters already (the lexer
            // joins them); runs that touch (`&` then `\0`) are joined here.
            let one_char = span.end - span.start == c.len_utf8();
            match errors.last_mut() {
                Some(LexError {
                    span: run,
                    kind: LexErrorKind::Unknown { more, .. },
                }) if run.end == span.start => {
                    run.end = span.end;
                    *more = true;
                }
                _ => errors.push(LexError {
                    span: Span::new(span.start, span.end),
                    kind: LexErrorKind::Unknown {
                        first: c,
                        more: !one_char,
                    },
                }),
            }
            false
        }
        Token::Unterminated(raw) => {
            errors.push(LexError {
                span: Span::new(span.start, span.end),
                kind: LexErrorKind::Unterminated,
            });
            *tok = Token::Str(raw);
            true
        }
        _ => true,
    });
    errors
}

/// The most syntax diagnostics reported for one file: past them, the file is
/// more likely junk than a script, and each costs memory and the editor's time.
pub const MAX_SYNTAX_DIAGNOSTICS: usize = 100;

/// A file's syntax diagnostics: the lexical errors and the others (brackets,
/// grammar) in the order of a stable sort by position of the lexical ones
/// followed by the others, the first [`MAX_SYNTAX_DIAGNOSTICS`] of them, and
/// then, if there were more, one E004 saying how many and where they start.
/// Only the kept lexical errors become diagnostics.
pub(crate) fn assemble_diagnostics(
    file: FileId,
    lexical: &[LexError],
    mut others: Vec<Diagnostic>,
) -> Vec<Diagnostic> {
    let key = |s: Span| (s.start, s.end);
    others.sort_by_key(|d| key(d.span));
    let total = lexical.len() + others.len();
    let mut out = Vec::with_capacity(total.min(MAX_SYNTAX_DIAGNOSTICS + 1));
    let (mut l, mut o) = (0, 0);
    let mut others = others.into_iter().peekable();
    while out.len() < MAX_SYNTAX_DIAGNOSTICS && l + o < total {
        // On equal positions the lexical error comes first, as in a stable sort.
        let take_lexical = match (lexical.get(l), others.peek()) {
            (Some(lex), Some(d)) => key(lex.span) <= key(d.span),
            (Some(_), None) => true,
            _ => false,
        };
        if take_lexical {
            out.push(lexical[l].diagnostic(file));
            l += 1;
        } else if let Some(d) = others.next() {
            out.push(d);
            o += 1;
        }
    }
    if l + o < total {
        let next = match (lexical.get(l), others.peek()) {
            (Some(lex), Some(d)) if key(lex.span) <= key(d.span) => lex.span,
            (_, Some(d)) => d.span,
            (Some(lex), None) => lex.span,
            (None, None) => unreachable!("fewer than the total"),
        };
        out.push(Diagnostic::new(
            Code::TooManyProblems,
            file,
            next,
            format!(
                "{} more syntax problem(s) from here on are not shown: fix the ones above first (is this a mission script?)",
                total - l - o
            ),
        ));
    }
    out
}

/// One chunk balanced and parsed. Everything in it depends only on the
/// chunk's own text: the same text elsewhere gives the same result, moved.
#[derive(Clone, Debug, Default)]
struct ChunkParse {
    items: Vec<ast::Item>,
    /// Bracket repairs first, then parse errors.
    diagnostics: Vec<Diagnostic>,
}

/// Balances and parses the chunks `ranges` of `tokens`, one result per range.
fn parse_chunks(
    file: FileId,
    text: &str,
    tokens: &[token::Spanned<'_>],
    ranges: &[std::ops::Range<usize>],
) -> Vec<ChunkParse> {
    let mut results: Vec<ChunkParse> = Vec::with_capacity(ranges.len());
    let chunks: Vec<_> = ranges
        .iter()
        .map(|range| {
            let mut result = ChunkParse::default();
            let chunk =
                delimiters::balance(text, &tokens[range.clone()], file, &mut result.diagnostics);
            results.push(result);
            chunk
        })
        .collect();
    let fast = parser::items::<_, chumsky::error::EmptyErr>();
    let rich = parser::items::<_, parser::RichError<'_, '_>>();
    for (chunk, result) in chunks.iter().zip(&mut results) {
        let (Some(first), Some(last)) = (chunk.first(), chunk.last()) else {
            continue;
        };
        let chunk_span = Span::new(first.1.start, last.1.end);
        let eoi = SimpleSpan::from(last.1.end..last.1.end);
        let input = || -> parser::TokenInput<'_, '_> { chunk.as_ref().map(eoi, |(t, s)| (t, s)) };
        if let (Some(parsed), errors) = fast.parse(input()).into_output_errors()
            && errors.is_empty()
        {
            result.items = parsed;
            continue;
        }
        let (output, errors) = rich.parse(input()).into_output_errors();
        for error in &errors {
            result.diagnostics.push(syntax_diagnostic(file, error));
        }
        match output {
            Some(parsed) => result.items = parsed,
            None => {
                if errors.is_empty() {
                    result.diagnostics.push(Diagnostic::new(
                        Code::SyntaxError,
                        file,
                        chunk_span,
                        "this text could not be understood",
                    ));
                }
                result.items.push(ast::Item::Error(chunk_span));
            }
        }
    }
    results
}

/// A standalone expression parsed with the mission grammar (spec section 2,
/// `Expr`): a condition written outside a mission, such as a strategy file's
/// `cond="distance > 20"`.
#[derive(Clone, Debug, Default)]
pub struct ExprParse {
    /// `None` when the text is blank or did not parse (the diagnostics say why).
    pub expr: Option<ast::Expr>,
    /// Syntax diagnostics (E001–E003), positioned in the file the text came from.
    pub diagnostics: Vec<Diagnostic>,
}

/// Parses `text` as one expression. Every position is `base` plus the offset
/// in `text`, so that ranges are right in the file `text` was taken from.
pub fn parse_expr(file: FileId, text: &str, base: usize) -> ExprParse {
    parse_expr_mapped(file, text, |offset| base + offset)
}

/// As [`parse_expr`], with each byte offset of `text` (and the offset of its
/// end) mapped to a file position by `position`, which must not decrease: for
/// text that was unescaped from the file (an XML attribute written with
/// `&lt;` is shorter once read).
pub fn parse_expr_mapped(file: FileId, text: &str, position: impl Fn(usize) -> usize) -> ExprParse {
    let mut tokens = token::lex(text);
    let mut diagnostics: Vec<Diagnostic> = lexical_errors(&mut tokens)
        .iter()
        .map(|e| e.diagnostic(file))
        .collect();
    // Brackets balanced and nesting bounded, as in a mission.
    let tokens = delimiters::balance(text, &tokens, file, &mut diagnostics);
    let map =
        |s: SimpleSpan| SimpleSpan::from(position(s.start)..position(s.end).max(position(s.start)));
    let tokens: Vec<token::Spanned<'_>> = tokens.iter().map(|&(t, s)| (t, map(s))).collect();
    for d in &mut diagnostics {
        let mapped = map(SimpleSpan::from(d.span.start..d.span.end));
        d.span = Span::new(mapped.start, mapped.end);
    }
    let text_end = position(text.len());
    let expr = if tokens.is_empty() {
        if diagnostics.is_empty() {
            diagnostics.push(Diagnostic::new(
                Code::SyntaxError,
                file,
                Span::new(text_end, text_end),
                "expected a condition, found nothing",
            ));
        }
        None
    } else {
        let eoi = SimpleSpan::from(text_end..text_end);
        let input: parser::TokenInput<'_, '_> = tokens.as_slice().map(eoi, |(t, s)| (t, s));
        let (output, errors) = parser::expr::<_, parser::RichError<'_, '_>>()
            .then_ignore(end())
            .parse(input)
            .into_output_errors();
        for error in &errors {
            diagnostics.push(syntax_diagnostic(file, error));
        }
        // A tree with recovered errors inside is kept: its names can still be checked.
        output
    };
    diagnostics.sort_by_key(|d| (d.span.start, d.span.end));
    ExprParse { expr, diagnostics }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_throw_keeps_where_broadcast_is_written() {
        let text = "T.A.S { throw go broadcast\n throw stay } repeat()";
        let p = parse(FileId(0), text);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let ast::Item::Service(service) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        let throws: Vec<(&str, Option<Span>)> = service
            .body
            .stmts
            .iter()
            .map(|s| match &s.kind {
                ast::StmtKind::Throw(t) => (t.event.name.as_str(), t.broadcast),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(throws, [("go", Some(Span::new(17, 26))), ("stay", None)]);
        // `broadcast` is a keyword: it is no event name.
        let p = parse(FileId(0), "T.A.S { throw broadcast } repeat()");
        assert_eq!(p.diagnostics[0].code, Code::SyntaxError);
        assert_eq!(p.diagnostics[0].span, Span::new(14, 23));
    }

    #[test]
    fn a_counted_group_keeps_its_name_and_min_positioned() {
        let text = "T.A.S { [[ group(Room1, min = 2) { x() } others { y() } ]] } repeat()";
        let p = parse(FileId(0), text);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let ast::Item::Service(service) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        let ast::StmtKind::Group(g) = &service.body.stmts[0].kind else {
            panic!("{:?}", service.body.stmts)
        };
        let cond = &g.arms[0].condition;
        assert_eq!(cond.kind, ast::CondKind::Counted);
        let name = cond.counted_name().unwrap();
        assert_eq!((name.as_str(), name.span), ("Room1", Span::new(17, 22)));
        let min = cond.min.as_ref().unwrap();
        assert_eq!(min.keyword_span, Span::new(24, 27));
        assert_eq!(min.count.value, Some(2));
        assert_eq!(min.count.span, Span::new(30, 31));
        assert!(g.others.is_some());
        // `min` is a word only there: elsewhere it is a plain name.
        let p = parse(FileId(0), "T.A.S { min(1) } repeat()");
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    }

    #[test]
    fn a_counted_group_without_min_is_a_positioned_syntax_error_and_the_next_line_parses() {
        let text = "T.A.S { [[ group(Room1, 2) { x() } ]]\n throw go } repeat()";
        let p = parse(FileId(0), text);
        assert_eq!(p.diagnostics.len(), 1, "{:?}", p.diagnostics);
        assert_eq!(p.diagnostics[0].code, Code::SyntaxError);
        assert_eq!(p.diagnostics[0].span, Span::new(24, 25));
        let ast::Item::Service(service) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        assert!(
            service.body.stmts.iter().any(
                |s| matches!(&s.kind, ast::StmtKind::Throw(t) if t.event.name.as_str() == "go")
            ),
            "{:?}",
            service.body.stmts
        );
    }

    #[test]
    fn a_function_keeps_its_parameters_positioned() {
        let text = "def go_to(PLACE, WAIT) { move(PLACE) }\ndef home { stop() }";
        let p = parse(FileId(0), text);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let ast::Item::Function(f) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        let params: Vec<(&str, Span)> = f.params.iter().map(|p| (p.as_str(), p.span)).collect();
        assert_eq!(
            params,
            [("PLACE", Span::new(10, 15)), ("WAIT", Span::new(17, 21))]
        );
        assert_eq!(f.params_span, Some(Span::new(9, 22)));
        let ast::Item::Function(home) = &p.file.items[1] else {
            panic!("{:?}", p.file.items)
        };
        assert!(home.params.is_empty() && home.params_span.is_none());
    }

    #[test]
    fn a_call_keeps_the_names_bound_to_its_results_positioned() {
        let text = "R.A.S { F, W = search(red), timeout = 2 SEC\n move(W) }";
        let p = parse(FileId(0), text);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let ast::Item::Service(s) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        let [first, second] = s.body.stmts.as_slice() else {
            panic!("{:?}", s.body.stmts)
        };
        let ast::StmtKind::Call(call) = &first.kind else {
            panic!("{first:?}")
        };
        let results: Vec<(&str, Span)> =
            call.results.iter().map(|r| (r.as_str(), r.span)).collect();
        assert_eq!(results, [("F", Span::new(8, 9)), ("W", Span::new(11, 12))]);
        assert_eq!(call.name.as_str(), "search");
        assert!(call.timeout.is_some());
        assert_eq!(first.span, Span::new(8, 43));
        assert!(matches!(&second.kind, ast::StmtKind::Call(c) if c.results.is_empty()));
    }

    #[test]
    fn names_bound_without_a_call_are_a_positioned_syntax_error_and_the_next_line_parses() {
        let text = "R.A.S {\n F, = search(red)\n X Y = search(red)\n stop()\n}";
        let p = parse(FileId(0), text);
        let spans: Vec<Span> = p.diagnostics.iter().map(|d| d.span).collect();
        assert!(p.diagnostics.iter().all(|d| d.code == Code::SyntaxError));
        assert_eq!(spans, [Span::new(12, 13), Span::new(29, 30)]);
        let ast::Item::Service(s) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        assert!(
            matches!(&s.body.stmts.last().map(|s| &s.kind), Some(ast::StmtKind::Call(c)) if c.name.as_str() == "stop"),
            "{:?}",
            s.body.stmts
        );
    }

    #[test]
    fn a_parameter_list_that_does_not_parse_is_positioned_and_the_body_parses() {
        let text = "def go_to(5 SEC) { move(x) }\ndef home(A) { stop() }";
        let p = parse(FileId(0), text);
        assert_eq!(p.diagnostics.len(), 1, "{:?}", p.diagnostics);
        assert_eq!(p.diagnostics[0].code, Code::SyntaxError);
        assert_eq!(p.diagnostics[0].span, Span::new(10, 11));
        let ast::Item::Function(f) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        assert!(f.params.is_empty());
        assert_eq!(f.body.stmts.len(), 1);
        assert!(matches!(&p.file.items[1], ast::Item::Function(h) if h.params.len() == 1));
    }

    #[test]
    fn modes_and_services_keep_their_parameters_and_arguments_positioned() {
        let text = "R.A.Go(PLACE) { move(PLACE) }\nR.MOVE(T) { set(A, Go(T)) }\n\
                    R.main { case (MOVE): catch (e): mode = MOVE(hall door) default: mode = MOVE(5) }";
        let p = parse(FileId(0), text);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let [
            ast::Item::Service(go),
            ast::Item::Mode(mode),
            ast::Item::Main(main),
        ] = p.file.items.as_slice()
        else {
            panic!("{:?}", p.file.items)
        };
        assert_eq!(go.params[0].span, Span::new(7, 12));
        assert_eq!(go.params_span, Some(Span::new(6, 13)));
        assert_eq!(
            (mode.params[0].as_str(), mode.params_span),
            ("T", Some(Span::new(36, 39)))
        );
        let args = mode.sets[0].args.as_ref().unwrap();
        assert_eq!((args.args.len(), args.span), (1, Span::new(51, 54)));
        let catch = &main.cases[0].catches[0];
        let target_args = catch.target_args.as_ref().unwrap();
        assert!(
            matches!(&target_args.args[0], ast::Arg::Words { text, .. } if text == "hall door")
        );
        let default = main.default_args.as_ref().unwrap();
        assert_eq!(default.args[0].written(), "5");
    }

    #[test]
    fn a_service_shared_by_teams_keeps_each_team_positioned() {
        let text = "A, B , C.Act.S { x() } repeat()\nsend(T, T.X)\nD.M { }";
        let p = parse(FileId(0), text);
        // The stray `send` between items is one error; the items around it parse.
        assert_eq!(p.diagnostics.len(), 1, "{:?}", p.diagnostics);
        let ast::Item::Service(s) = &p.file.items[0] else {
            panic!("{:?}", p.file.items)
        };
        assert_eq!((s.team.as_str(), s.team.span), ("A", Span::new(0, 1)));
        let more: Vec<(&str, Span)> = s.more_teams.iter().map(|t| (t.as_str(), t.span)).collect();
        assert_eq!(more, [("B", Span::new(3, 4)), ("C", Span::new(7, 8))]);
        assert_eq!((s.plan.as_str(), s.name.as_str()), ("Act", "S"));
        assert!(matches!(p.file.items.last(), Some(ast::Item::Mode(_))));
    }

    #[test]
    fn a_standalone_expression_is_positioned_from_its_base() {
        let p = parse_expr(FileId(2), "distance > 20 and not stop", 100);
        assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
        let expr = p.expr.unwrap();
        assert_eq!(expr.span, Span::new(100, 126));
        let ast::ExprKind::And(lhs, _) = &expr.kind else {
            panic!("{expr:?}")
        };
        let ast::ExprKind::Compare(name, ast::CmpOp::Gt, _) = &lhs.kind else {
            panic!("{lhs:?}")
        };
        assert_eq!(name.span, Span::new(100, 108));
    }

    #[test]
    fn standalone_expression_errors_are_positioned_and_never_empty() {
        let p = parse_expr(FileId(0), "a == ", 10);
        assert!(p.expr.is_none());
        assert_eq!(p.diagnostics.len(), 1, "{:?}", p.diagnostics);
        assert_eq!(p.diagnostics[0].code, Code::SyntaxError);
        assert_eq!(p.diagnostics[0].span, Span::new(15, 15));
        let p = parse_expr(FileId(0), "a @ b", 0);
        assert_eq!(p.diagnostics[0].code, Code::InvalidCharacter);
        assert_eq!(p.diagnostics[0].span, Span::new(2, 3));
        let p = parse_expr(FileId(0), "(a", 0);
        assert!(
            p.diagnostics.iter().any(|d| d.message.contains("`(`")),
            "{:?}",
            p.diagnostics
        );
        let p = parse_expr(FileId(0), "  ", 7);
        assert!(p.expr.is_none());
        assert_eq!(p.diagnostics[0].span, Span::new(9, 9));
        let deep = format!("{}a{}", "(".repeat(5000), ")".repeat(5000));
        assert!(!parse_expr(FileId(0), &deep, 0).diagnostics.is_empty());
        let long = format!("a{}", " and a".repeat(20_000));
        assert!(!parse_expr(FileId(0), &long, 0).diagnostics.is_empty());
    }

    #[test]
    fn mapped_positions_follow_the_map() {
        // `a<b` written as `a&lt;b` at offset 50: `<` is 4 bytes longer in the file.
        let map = |i: usize| 50 + if i <= 1 { i } else { i + 3 };
        let p = parse_expr_mapped(FileId(0), "a<b", map);
        let expr = p.expr.unwrap();
        assert_eq!(expr.span, Span::new(50, 56));
        let ast::ExprKind::Compare(_, ast::CmpOp::Lt, rhs) = &expr.kind else {
            panic!("{expr:?}")
        };
        assert_eq!(rhs.span, Span::new(55, 56));
    }

    #[test]
    fn two_threads_give_the_same_result_as_one() {
        let unit = "T.Action.Go { move(\"1,1\" \n stop() @ } repeat(2 SEC)\n# 한국어 😀\nT.M { set(Action Go) }\n";
        let text = unit.repeat(PARALLEL_MIN_BYTES / unit.len() + 10);
        let (one, one_tokens) = parse_with(FileId(0), &text, false);
        let (two, two_tokens) = parse_with(FileId(0), &text, true);
        assert_eq!(one_tokens, two_tokens);
        assert!(two.diagnostics.len() > 100);
        assert_eq!(one.file, two.file);
        assert_eq!(one.diagnostics, two.diagnostics);
    }

    #[test]
    fn a_header_being_typed_after_an_item_keeps_the_item() {
        let text = "T.Action.Go { stop() } repeat()\nT.\nT.main { default: mode = M }";
        let parse = parse(FileId(0), text);
        assert_eq!(parse.diagnostics.len(), 1, "{:#?}", parse.diagnostics);
        let kinds: Vec<&str> = parse
            .file
            .items
            .iter()
            .map(|i| match i {
                ast::Item::Service(_) => "service",
                ast::Item::Error(span) => &text[span.range()],
                ast::Item::Main(_) => "main",
                _ => "other",
            })
            .collect();
        assert_eq!(kinds, ["service", "T.", "main"]);
    }
}
