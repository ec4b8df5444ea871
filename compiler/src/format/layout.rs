//! The canonical layout, construct by construct: where the syntax tree's parts
//! start their lines and how deep they are indented. Tokens come from the
//! cursor ([`Emitter`]) in order, so the tree decides only where lines break;
//! bodies of `main` are laid out from their tokens, which keep every arm (the
//! tree keeps only the first `default`).

use super::doc::Item;
use super::emit::{Emitter, Sep};
use crate::span::Span;
use crate::syntax::ast::{self, Arg, Block, Else, StmtKind};
use crate::syntax::token::{Kw, Token};

/// Statements nested deeper than this are refused (the parser bounds bracket
/// nesting, but not `if (a) if (b) ...` without braces).
pub const MAX_NESTING: usize = 200;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutError {
    TooDeep(Span),
    /// A part of the tree that did not parse.
    Unparsed(Span),
}

type Result = std::result::Result<(), LayoutError>;

/// Lays out a whole file: items separated by one empty line, except that
/// consecutive bare team declarations (`T: A a`) stay together.
pub fn file(e: &mut Emitter<'_, '_>, file: &ast::SourceFile) -> Result {
    let mut prev_bare = false;
    for (i, item) in file.items.iter().enumerate() {
        let bare = matches!(item, ast::Item::Formation(f) if !f.braced);
        let sep = if i == 0 || (bare && prev_bare) {
            Sep::BlankIfWritten
        } else {
            Sep::Blank
        };
        e.boundary(sep, false);
        match item {
            ast::Item::Formation(f) => formation(e, f)?,
            ast::Item::Service(s) => {
                e.plain(s.body.span.start);
                body(e, &s.body, 0)?;
                if let Some(r) = &s.repeat {
                    join(e);
                    inline(e, r.span.end, &[]);
                }
            }
            ast::Item::Function(f) => {
                e.plain(f.body.span.start);
                body(e, &f.body, 0)?;
            }
            ast::Item::Mode(m) => mode(e, m)?,
            ast::Item::Main(m) => {
                e.plain(m.main_span.end);
                let empty = m.cases.is_empty() && m.default.is_none();
                braced(e, empty, |e| {
                    main_arms(e, m.span.end);
                    Ok(())
                })?;
            }
            ast::Item::Error(span) => return Err(LayoutError::Unparsed(*span)),
        }
        e.semis();
        prev_bare = bare;
    }
    Ok(())
}

/// `{` then the body indented, then `}` on its own line; `{}` when there is
/// nothing inside, not even a comment.
fn braced(
    e: &mut Emitter<'_, '_>,
    empty: bool,
    inside: impl FnOnce(&mut Emitter<'_, '_>) -> Result,
) -> Result {
    // After a comment, `{` starts a line at the level of its header.
    if e.has_comments_before_next() {
        e.boundary(Sep::Line, false);
    }
    e.token();
    if empty && e.at(Token::RBrace) && !e.has_comments_before_next() {
        e.token();
        return Ok(());
    }
    e.push(Item::IndentStart);
    inside(e)?;
    close(e, empty);
    Ok(())
}

/// The comments before a closing `}` or `]]` (indented as the body), then the
/// closer on its own line.
fn close(e: &mut Emitter<'_, '_>, empty: bool) {
    if e.has_own_line_comments() {
        let sep = if empty {
            Sep::Line
        } else {
            Sep::BlankIfWritten
        };
        e.boundary(sep, true);
    }
    e.push(Item::IndentEnd);
    e.push(Item::Hard);
    e.token();
}

/// Keeps the next token on the current line (`} else`, `} repeat()`), unless
/// comments stand on their own lines before it.
fn join(e: &mut Emitter<'_, '_>) {
    if e.has_own_line_comments() {
        e.boundary(Sep::Line, false);
    }
}

fn separator(first: bool) -> Sep {
    if first {
        Sep::Line
    } else {
        Sep::BlankIfWritten
    }
}

fn formation(e: &mut Emitter<'_, '_>, f: &ast::Formation) -> Result {
    if !f.braced {
        for t in &f.teams {
            team(e, t);
        }
        return Ok(());
    }
    braced(e, f.teams.is_empty(), |e| {
        for (j, t) in f.teams.iter().enumerate() {
            e.boundary(separator(j == 0), false);
            team(e, t);
            e.semis();
        }
        Ok(())
    })
}

/// `Team: Type name, Type name[2]`; when too long, one robot per line below
/// the team name.
fn team(e: &mut Emitter<'_, '_>, t: &ast::TeamDecl) {
    let Some(first) = t.robots.first() else {
        e.plain(t.span.end);
        return;
    };
    e.plain(first.span.start);
    e.push(Item::GroupStart);
    e.push(Item::IndentStart);
    for (k, r) in t.robots.iter().enumerate() {
        if k > 0 && e.at(Token::Comma) {
            e.token();
        }
        e.push(Item::Line(" "));
        e.plain(r.span.end);
    }
    e.push(Item::IndentEnd);
    e.push(Item::GroupEnd);
}

fn mode(e: &mut Emitter<'_, '_>, m: &ast::ModeDef) -> Result {
    e.plain(m.params_span.map_or(m.name.span.end, |list| list.end));
    braced(e, m.sets.is_empty(), |e| {
        for (j, set) in m.sets.iter().enumerate() {
            e.boundary(separator(j == 0), false);
            inline(e, set.span.end, &[]);
            e.semis();
        }
        Ok(())
    })
}

/// The body of `main`, from its tokens: `case` and `default` one level in,
/// each `catch` one level deeper.
fn main_arms(e: &mut Emitter<'_, '_>, end: usize) {
    let mut in_catches = false;
    let mut first = true;
    while e.peek().is_some() && e.peek_end() < end {
        match e.peek() {
            Some(Token::Kw(Kw::Case | Kw::Default)) => {
                if in_catches {
                    e.push(Item::IndentEnd);
                    in_catches = false;
                }
                e.boundary(separator(first), false);
                first = false;
            }
            Some(Token::Kw(Kw::Catch)) => {
                if !in_catches {
                    e.push(Item::IndentStart);
                    in_catches = true;
                }
                e.boundary(separator(first), false);
                first = false;
            }
            _ => {}
        }
        e.token();
    }
    if in_catches {
        e.push(Item::IndentEnd);
    }
}

fn is_braced(e: &Emitter<'_, '_>, b: &Block) -> bool {
    e.text().as_bytes().get(b.span.start) == Some(&b'{')
}

/// A braced block of statements, one per line.
fn body(e: &mut Emitter<'_, '_>, b: &Block, depth: usize) -> Result {
    braced(e, b.stmts.is_empty(), |e| {
        for (j, s) in b.stmts.iter().enumerate() {
            e.boundary(separator(j == 0), false);
            stmt(e, s, depth)?;
        }
        Ok(())
    })
}

/// The block of an `if`, `else`, `loop` or group arm: braced, or a single
/// statement on the next line, one level in.
fn block(e: &mut Emitter<'_, '_>, b: &Block, depth: usize) -> Result {
    if is_braced(e, b) && e.peek_start() == b.span.start {
        return body(e, b, depth);
    }
    e.push(Item::IndentStart);
    for s in &b.stmts {
        e.boundary(Sep::Line, false);
        stmt(e, s, depth)?;
    }
    e.push(Item::IndentEnd);
    Ok(())
}

fn stmt(e: &mut Emitter<'_, '_>, s: &ast::Stmt, depth: usize) -> Result {
    if depth >= MAX_NESTING {
        return Err(LayoutError::TooDeep(s.span));
    }
    match &s.kind {
        StmtKind::If(i) => {
            inline(e, i.then_block.span.start, &[]);
            block(e, &i.then_block, depth + 1)?;
            if let Some(else_branch) = &i.else_branch {
                if is_braced(e, &i.then_block) {
                    join(e);
                } else {
                    e.boundary(Sep::Line, false);
                }
                e.token();
                match else_branch.as_ref() {
                    Else::If(inner) => {
                        join(e);
                        stmt(e, inner, depth + 1)?;
                    }
                    Else::Block(b) => block(e, b, depth + 1)?,
                }
            }
        }
        StmtKind::Loop(l) => {
            inline(e, l.body.span.start, &[]);
            block(e, &l.body, depth + 1)?;
        }
        StmtKind::Group(g) => {
            e.token();
            e.push(Item::IndentStart);
            for (j, arm) in g.arms.iter().enumerate() {
                e.boundary(separator(j == 0), false);
                inline(e, arm.body.span.start, &[]);
                block(e, &arm.body, depth + 1)?;
            }
            if let Some(others) = &g.others {
                e.boundary(separator(g.arms.is_empty()), false);
                e.plain(others.body.span.start);
                block(e, &others.body, depth + 1)?;
            }
            close(e, false);
        }
        StmtKind::Call(c) => {
            let words: Vec<Span> = c
                .args
                .iter()
                .filter_map(|a| match a {
                    Arg::Words { span, .. } => Some(*span),
                    Arg::Expr(_) => None,
                })
                .collect();
            inline(e, s.span.end, &words);
        }
        StmtKind::Comm(_) | StmtKind::Throw(_) => inline(e, s.span.end, &[]),
        StmtKind::Error => return Err(LayoutError::Unparsed(s.span)),
    }
    e.semis();
    Ok(())
}

/// Whether a break is allowed before this token inside the outermost
/// parentheses: `and`, `or`, `&&`, `||`, except inside bare words (`move(salt
/// and pepper)`).
fn breaks_before(token: Token<'_>, at: usize, words: &[Span]) -> bool {
    matches!(
        token,
        Token::Kw(Kw::And | Kw::Or) | Token::AndAnd | Token::OrOr
    ) && !words.iter().any(|w| w.contains(at))
}

/// Whether the parentheses opening at the next token hold more than one part
/// or a part with `and`/`or`: else breaking them would gain nothing.
fn breakable_parens(e: &Emitter<'_, '_>, words: &[Span]) -> bool {
    let mut depth = 0usize;
    let mut k = 0;
    while let Some((token, at)) = e.peek_nth(k) {
        match token {
            Token::LParen => depth += 1,
            Token::RParen if depth <= 1 => return false,
            Token::RParen => depth -= 1,
            Token::Comma if depth == 1 => return true,
            _ if depth == 1 && breaks_before(token, at, words) => return true,
            _ => {}
        }
        k += 1;
    }
    false
}

/// Places the tokens before `end` on one line, the outermost parentheses
/// forming a group: when the line is too long, each comma-separated part goes
/// on its own line, and a part still too long breaks before each `and`/`or`
/// outside nested parentheses.
fn inline(e: &mut Emitter<'_, '_>, end: usize, words: &[Span]) {
    let mut depth = 0usize;
    // Whether the outermost parentheses open now form a group.
    let mut grouped = false;
    while e.peek().is_some() && e.peek_start() < end {
        let Some(token) = e.peek() else { break };
        match token {
            Token::LParen if depth == 0 && !breakable_parens(e, words) => {
                // `()`, `(x)`: nothing worth breaking.
                depth = 1;
                grouped = false;
                e.token();
            }
            Token::LParen if depth == 0 => {
                e.push(Item::GroupStart);
                e.token();
                depth = 1;
                grouped = true;
                e.push(Item::IndentStart);
                e.push(Item::Line(""));
                e.push(Item::GroupStart);
            }
            Token::RParen if depth == 1 && grouped => {
                e.push(Item::GroupEnd);
                e.push(Item::IndentEnd);
                e.push(Item::Line(""));
                e.token();
                e.push(Item::GroupEnd);
                depth = 0;
                grouped = false;
            }
            Token::Comma if depth == 1 && grouped => {
                e.token();
                e.push(Item::GroupEnd);
                e.push(Item::Line(" "));
                e.push(Item::GroupStart);
            }
            _ if depth == 1 && grouped && breaks_before(token, e.peek_start(), words) => {
                e.push(Item::Line(" "));
                e.token();
            }
            Token::LParen => {
                depth += 1;
                e.token();
            }
            Token::RParen => {
                depth = depth.saturating_sub(1);
                e.token();
            }
            _ => e.token(),
        }
    }
    if depth > 0 && grouped {
        e.push(Item::GroupEnd);
        e.push(Item::IndentEnd);
        e.push(Item::GroupEnd);
    }
}
