//! The chumsky grammar of mission scripts (spec section 2).
//!
//! Error recovery works at two levels. First, [`super::chunks`] cuts the token
//! stream into independent top-level chunks at every item header, so a syntax
//! error in one service never hides the next one. Second, inside blocks a
//! statement that fails to parse is skipped token by token until the parser can
//! resume, so several errors in one block are each reported.

use super::ast::*;
use super::token::{Kw, Token, unescape};
use crate::span::Span;
use chumsky::input::{MappedInput, ValueInput};
use chumsky::prelude::*;

pub type TokenInput<'t, 's> = MappedInput<
    't,
    Token<'s>,
    SimpleSpan,
    &'t [(Token<'s>, SimpleSpan)],
    fn(&'t (Token<'s>, SimpleSpan)) -> (&'t Token<'s>, &'t SimpleSpan),
>;

/// The detailed error, used to report a chunk that failed the fast parse.
pub type RichError<'t, 's> = Rich<'t, Token<'s>, SimpleSpan>;

/// What the grammar needs of its error type. The same grammar runs with
/// chumsky's zero-cost `EmptyErr` first (most chunks are valid), and again with
/// [`RichError`] only for the chunks that failed, to explain what went wrong.
pub trait ParseErr<'t, I: chumsky::input::Input<'t>>:
    chumsky::error::Error<'t, I> + chumsky::label::LabelError<'t, I, &'static str>
{
}

impl<'t, I: chumsky::input::Input<'t>, T> ParseErr<'t, I> for T where
    T: chumsky::error::Error<'t, I> + chumsky::label::LabelError<'t, I, &'static str>
{
}

fn sp(s: SimpleSpan) -> Span {
    Span::new(s.start, s.end)
}

fn kw<'t, 's: 't, I, E>(k: Kw) -> impl Parser<'t, I, SimpleSpan, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    just(Token::Kw(k)).map_with(|_, e| e.span())
}

fn tok<'t, 's: 't, I, E>(t: Token<'s>) -> impl Parser<'t, I, Token<'s>, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    just(t)
}

/// Wraps a parser of one line of a braced body (a statement, a `set`, a `case`)
/// so that a line that does not parse is reported and skipped: first by skipping
/// tokens until a later line parses, else by taking everything up to the closing
/// bracket as one bad line. Either way the enclosing item survives.
fn recovering<'t, 's: 't, I, E, O: 't>(
    line: impl Parser<'t, I, O, extra::Err<E>> + Clone + 't,
    bad_line: impl Fn(Span) -> O + Clone + 't,
) -> impl Parser<'t, I, O, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    let bracketed = nested_delimiters(
        Token::LBrace,
        Token::RBrace,
        [
            (Token::LParen, Token::RParen),
            (Token::GroupOpen, Token::GroupClose),
        ],
        |_| (),
    );
    let closing = one_of([Token::RBrace, Token::GroupClose]).ignored();
    let rest = bracketed
        .clone()
        .or(none_of([Token::RBrace, Token::GroupClose]).ignored())
        .repeated()
        .at_least(1)
        .map_with(move |_, e| bad_line(sp(e.span())));
    line.recover_with(skip_then_retry_until(
        bracketed.or(any().ignored()),
        closing,
    ))
    .recover_with(via_parser(rest))
}

/// A non-reserved identifier.
fn name<'t, 's: 't, I, E>() -> impl Parser<'t, I, Ident, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    select! { Token::Ident(s) = e => Ident::new(s, sp(e.span())) }.labelled("a name")
}

/// `2 SEC`, `500 msec`.
fn period<'t, 's: 't, I, E>() -> impl Parser<'t, I, Period, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    select! { Token::Number(n) => n }
        .then(
            select! { Token::Ident(w) if TimeUnit::parse(w).is_some() => TimeUnit::parse(w) }
                .map(|unit| unit.unwrap_or(TimeUnit::Sec))
                .labelled("a time unit"),
        )
        .map_with(|(amount, unit), e| Period {
            amount: amount.to_string(),
            unit,
            span: sp(e.span()),
        })
        .labelled("a period such as `2 SEC`")
}

fn timeout<'t, 's: 't, I, E>() -> impl Parser<'t, I, Period, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    kw(Kw::Timeout)
        .ignore_then(tok(Token::Assign))
        .ignore_then(period())
}

fn attr<'t, 's: 't, I, E>() -> impl Parser<'t, I, Attr, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    name()
        .separated_by(tok(Token::Dot))
        .at_least(1)
        .collect::<Vec<_>>()
        .map_with(|segments, e| Attr {
            segments,
            span: sp(e.span()),
        })
        .labelled("a value name")
}

pub fn expr<'t, 's: 't, I, E>() -> impl Parser<'t, I, Expr, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    recursive(|expr| {
        let literal = select! {
            Token::Str(s) => ExprKind::Str(unescape(s)),
            Token::Kw(Kw::True) => ExprKind::Bool(true),
            Token::Kw(Kw::False) => ExprKind::Bool(false),
        };
        let number = select! { Token::Number(n) => ExprKind::Number(n.to_string()) };
        let atom = choice((
            literal,
            period().map(ExprKind::Period),
            number,
            attr().map(ExprKind::Attr),
        ))
        .map_with(|kind, e| Expr {
            kind,
            span: sp(e.span()),
        })
        .or(expr
            .clone()
            .delimited_by(tok(Token::LParen), tok(Token::RParen))
            .map_with(|inner: Expr, e| Expr {
                kind: inner.kind,
                span: sp(e.span()),
            }))
        .recover_with(via_parser(nested_delimiters(
            Token::LParen,
            Token::RParen,
            [(Token::LBrace, Token::RBrace)],
            |span| Expr {
                kind: ExprKind::Error,
                span: sp(span),
            },
        )))
        .labelled("a value")
        .boxed();

        let cmp_op = select! {
            Token::EqEq => CmpOp::Eq,
            Token::NotEq => CmpOp::Ne,
            Token::Lt => CmpOp::Lt,
            Token::Le => CmpOp::Le,
            Token::Gt => CmpOp::Gt,
            Token::Ge => CmpOp::Ge,
        };
        let compare = atom
            .clone()
            .then(cmp_op.then(atom).or_not())
            .map_with(|(lhs, rhs), e| match rhs {
                None => lhs,
                Some((op, rhs)) => Expr {
                    kind: ExprKind::Compare(Box::new(lhs), op, Box::new(rhs)),
                    span: sp(e.span()),
                },
            });

        let not_op = kw(Kw::Not).or(tok(Token::Bang).map_with(|_, e| e.span()));
        let not = not_op
            .repeated()
            .foldr_with(compare, |op, inner: Expr, _| Expr {
                span: sp(op).cover(inner.span),
                kind: ExprKind::Not(Box::new(inner)),
            });

        let and_op = kw(Kw::And).ignored().or(tok(Token::AndAnd).ignored());
        let and = not.clone().foldl(
            and_op.ignore_then(not).repeated(),
            |lhs: Expr, rhs: Expr| Expr {
                span: lhs.span.cover(rhs.span),
                kind: ExprKind::And(Box::new(lhs), Box::new(rhs)),
            },
        );

        let or_op = kw(Kw::Or).ignored().or(tok(Token::OrOr).ignored());
        and.clone()
            .foldl(or_op.ignore_then(and).repeated(), |lhs: Expr, rhs: Expr| {
                Expr {
                    span: lhs.span.cover(rhs.span),
                    kind: ExprKind::Or(Box::new(lhs), Box::new(rhs)),
                }
            })
            .labelled("a condition")
    })
}

/// `(P)`, `(expr)`, `(P, expr)`, and for `repeat` also `()`.
fn period_and_condition<'t, 's: 't, I, E>()
-> impl Parser<'t, I, (Option<Period>, Option<Expr>), extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    period()
        .then(tok(Token::Comma).ignore_then(expr()).or_not())
        .map(|(p, c)| (Some(p), c))
        .or(expr().map(|c| (None, Some(c))))
}

fn statement<'t, 's: 't, I, E>() -> impl Parser<'t, I, Stmt, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    recursive(|stmt| {
        let recovering_stmt = recovering(stmt.clone(), |span| Stmt {
            kind: StmtKind::Error,
            span,
        });

        let braced = recovering_stmt
            .repeated()
            .collect::<Vec<_>>()
            .delimited_by(tok(Token::LBrace), tok(Token::RBrace))
            .map_with(|stmts, e| Block {
                stmts,
                span: sp(e.span()),
            })
            .boxed();
        let block = braced.clone().or(stmt.clone().map(|s: Stmt| Block {
            span: s.span,
            stmts: vec![s],
        }));

        let paren_expr = expr().delimited_by(tok(Token::LParen), tok(Token::RParen));

        let if_stmt = kw(Kw::If)
            .ignore_then(paren_expr.clone())
            .then(block.clone())
            .then(kw(Kw::Else).ignore_then(block.clone()).or_not())
            .map(|((condition, then_block), else_block)| {
                StmtKind::If(If {
                    condition,
                    then_block,
                    else_branch: else_block.map(|b| Box::new(else_of(b))),
                })
            });

        let loop_stmt = kw(Kw::Loop)
            .ignore_then(
                period_and_condition().delimited_by(tok(Token::LParen), tok(Token::RParen)),
            )
            .then(block.clone())
            .map(|((period, condition), body)| {
                StmtKind::Loop(Loop {
                    period,
                    condition,
                    body,
                })
            });

        let throw = kw(Kw::Throw)
            .ignore_then(name().labelled("an event name"))
            .then(kw(Kw::Broadcast).map(sp).or_not())
            .map(|(event, broadcast)| StmtKind::Throw(Throw { event, broadcast }));

        let comm_kind = select! {
            Token::Kw(Kw::Send) => CommKind::Send,
            Token::Kw(Kw::Receive) => CommKind::Receive,
            Token::Kw(Kw::Publish) => CommKind::Publish,
            Token::Kw(Kw::Subscribe) => CommKind::Subscribe,
        }
        .map_with(|k, e| (k, sp(e.span())));
        let comm_item = attr()
            .then(tok(Token::Assign).ignore_then(expr()).or_not())
            .map(|(attr, value)| CommItem { attr, value });
        let comm = comm_kind
            .then(
                name()
                    .labelled("a team name")
                    .then_ignore(tok(Token::Comma))
                    .then(
                        comm_item
                            .separated_by(tok(Token::Comma))
                            .at_least(1)
                            .collect::<Vec<_>>(),
                    )
                    .delimited_by(tok(Token::LParen), tok(Token::RParen)),
            )
            .then(tok(Token::Comma).ignore_then(timeout()).or_not())
            .map(|(((kind, keyword_span), (team, items)), timeout)| {
                StmtKind::Comm(Comm {
                    kind,
                    keyword_span,
                    team,
                    items,
                    timeout,
                })
            });

        let arg = arg();
        // `FOUND, WHERE = search(red)`: the names bound to the results. A
        // statement starting with a name is a call, so trying the list
        // first costs at most the names before a `(`.
        let results = name()
            .separated_by(tok(Token::Comma))
            .at_least(1)
            .collect::<Vec<_>>()
            .then_ignore(tok(Token::Assign))
            .or_not()
            .map(Option::unwrap_or_default);
        let call = results
            .then(name())
            .then(
                arg.separated_by(tok(Token::Comma))
                    .collect::<Vec<_>>()
                    .delimited_by(tok(Token::LParen), tok(Token::RParen))
                    .map_with(|args, e| (args, sp(e.span()))),
            )
            .then(tok(Token::Comma).ignore_then(timeout()).or_not())
            .map(|(((results, name), (args, args_span)), timeout)| {
                StmtKind::Call(Call {
                    results,
                    name,
                    args,
                    timeout,
                    args_span,
                })
            });

        let names = name()
            .separated_by(tok(Token::Comma))
            .at_least(1)
            .collect::<Vec<_>>();
        let cond_kind = kw(Kw::Instance)
            .then(kw(Kw::Of))
            .to(CondKind::InstanceOf)
            .or(kw(Kw::Capable).then(kw(Kw::Of)).to(CondKind::CapableOf));
        let typed_cond = cond_kind
            .then(names)
            .map_with(|(kind, names), e| GroupCond {
                kind,
                names,
                min: None,
                span: sp(e.span()),
            });
        // `Room1, min = 2`: `min` is a word only here, not a keyword.
        let min_word = select! { Token::Ident("min") = e => sp(e.span()) }.labelled("`min`");
        let min_count =
            select! { Token::Number(n) = e => Count { value: count_value(n), span: sp(e.span()) } }
                .labelled("a whole number");
        let counted_cond = name()
            .then_ignore(tok(Token::Comma))
            .then(min_word)
            .then_ignore(tok(Token::Assign))
            .then(min_count)
            .map_with(|((name, keyword_span), count), e| GroupCond {
                kind: CondKind::Counted,
                names: vec![name],
                min: Some(GroupMin {
                    keyword_span,
                    count,
                }),
                span: sp(e.span()),
            });
        let group_cond = typed_cond
            .or(counted_cond)
            .delimited_by(tok(Token::LParen), tok(Token::RParen))
            .labelled("`instance of ...`, `capable of ...` or `Name, min = N`")
            // A condition that does not parse is reported where it goes
            // wrong, and the arm's block is still parsed: an empty counted
            // condition (no name, no min) checks nothing more.
            .recover_with(via_parser(nested_delimiters(
                Token::LParen,
                Token::RParen,
                [(Token::GroupOpen, Token::GroupClose)],
                |span| GroupCond {
                    kind: CondKind::Counted,
                    names: Vec::new(),
                    min: None,
                    span: sp(span),
                },
            )));
        let arm_kind = kw(Kw::Leader)
            .map(|s| (ArmKind::Leader, sp(s)))
            .or(kw(Kw::Group).map(|s| (ArmKind::Group, sp(s))));
        let arm = arm_kind.then(group_cond).then(block.clone()).map_with(
            |(((kind, keyword_span), condition), body), e| GroupArm {
                kind,
                keyword_span,
                condition,
                body,
                span: sp(e.span()),
            },
        );
        let others = kw(Kw::Others).then(block.clone()).map(|(k, body)| Others {
            keyword_span: sp(k),
            body,
        });
        let group = arm
            .repeated()
            .at_least(1)
            .collect::<Vec<_>>()
            .then(others.or_not())
            .delimited_by(tok(Token::GroupOpen), tok(Token::GroupClose))
            .map(|(arms, others)| StmtKind::Group(GroupStmt { arms, others }));

        choice((if_stmt, loop_stmt, group, comm, throw, call))
            .map_with(|kind, e| Stmt {
                kind,
                span: sp(e.span()),
            })
            .then_ignore(tok(Token::Semi).repeated())
            .labelled("a statement")
            .boxed()
    })
}

/// An argument: an expression, or several bare words taken as one string.
fn arg<'t, 's: 't, I, E>() -> impl Parser<'t, I, Arg, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    let word = select! {
        Token::Ident(w) => w,
        Token::Kw(k) => k.as_str(),
    };
    let words = word
        .repeated()
        .at_least(2)
        .collect::<Vec<_>>()
        .map_with(|ws, e| Arg::Words {
            text: ws.join(" "),
            span: sp(e.span()),
        })
        .then_ignore(one_of([Token::Comma, Token::RParen]).rewind());
    words.or(expr().map(Arg::Expr))
}

/// `(a, b)` after a mode or service name.
fn arg_list<'t, 's: 't, I, E>() -> impl Parser<'t, I, ArgList, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    arg()
        .separated_by(tok(Token::Comma))
        .collect::<Vec<_>>()
        .delimited_by(tok(Token::LParen), tok(Token::RParen))
        .map_with(|args, e| ArgList {
            args,
            span: sp(e.span()),
        })
}

/// `else if (...)` is an unbraced block holding one `if`: keep it as an else-if.
fn else_of(block: Block) -> Else {
    match block.stmts.as_slice() {
        [only] if only.span == block.span && matches!(only.kind, StmtKind::If(_)) => Else::If(
            block
                .stmts
                .into_iter()
                .next()
                .unwrap_or_else(|| unreachable!()),
        ),
        _ => Else::Block(block),
    }
}

fn braced_block<'t, 's: 't, I, E>() -> impl Parser<'t, I, Block, extra::Err<E>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    recovering(statement(), |span| Stmt {
        kind: StmtKind::Error,
        span,
    })
    .repeated()
    .collect::<Vec<_>>()
    .delimited_by(tok(Token::LBrace), tok(Token::RBrace))
    .map_with(|stmts, e| Block {
        stmts,
        span: sp(e.span()),
    })
}

/// The number of `name[N]`: a whole number too large for `u32` is
/// `u32::MAX`, which is too many robots all the same (the checker says so,
/// instead of calling it not a number).
fn count_value(written: &str) -> Option<u32> {
    match written.parse() {
        Ok(n) => Some(n),
        Err(_) if written.bytes().all(|b| b.is_ascii_digit()) => Some(u32::MAX),
        Err(_) => None,
    }
}

/// A parameter list as written, or none.
fn split_params(list: Option<(Vec<Ident>, Span)>) -> (Vec<Ident>, Option<Span>) {
    match list {
        Some((params, span)) => (params, Some(span)),
        None => (Vec::new(), None),
    }
}

/// Parses the items of one chunk.
pub fn items<'t, 's: 't, I, E>() -> impl Parser<'t, I, Vec<Item>, extra::Err<E>>
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    E: ParseErr<'t, I> + 't,
{
    let semis = tok(Token::Semi).repeated();

    let count =
        select! { Token::Number(n) = e => Count { value: count_value(n), span: sp(e.span()) } }
            .delimited_by(tok(Token::LBracket), tok(Token::RBracket));
    let robot = name()
        .labelled("a robot type")
        .then(name().labelled("a robot name"))
        .then(count.or_not())
        .map_with(|((robot_type, name), count), e| RobotDecl {
            robot_type,
            name,
            count,
            span: sp(e.span()),
        });
    let team_decl = name()
        .then_ignore(tok(Token::Colon))
        .then(
            robot
                .separated_by(tok(Token::Comma))
                .at_least(1)
                .collect::<Vec<_>>(),
        )
        .map_with(|(name, robots), e| TeamDecl {
            name,
            robots,
            span: sp(e.span()),
        })
        .then_ignore(semis.clone());
    let formation_block = team_decl
        .clone()
        .repeated()
        .collect::<Vec<_>>()
        .delimited_by(tok(Token::LBrace), tok(Token::RBrace))
        .map_with(|teams, e| {
            Item::Formation(Formation {
                teams,
                braced: true,
                span: sp(e.span()),
            })
        });
    let bare_team = team_decl.map(|decl| {
        Item::Formation(Formation {
            span: decl.span,
            teams: vec![decl],
            braced: false,
        })
    });

    let repeat = kw(Kw::Repeat)
        .ignore_then(
            period_and_condition()
                .or_not()
                .delimited_by(tok(Token::LParen), tok(Token::RParen)),
        )
        .map_with(|pc, e| {
            let (period, condition) = pc.unwrap_or((None, None));
            Repeat {
                period,
                condition,
                span: sp(e.span()),
            }
        });
    // `(A, B)`: a list that does not parse is reported where it goes wrong
    // and the body is still parsed, as one without parameters.
    let params = name()
        .labelled("a parameter name")
        .separated_by(tok(Token::Comma))
        .collect::<Vec<_>>()
        .delimited_by(tok(Token::LParen), tok(Token::RParen))
        .map_with(|params, e| (params, sp(e.span())))
        .recover_with(via_parser(nested_delimiters(
            Token::LParen,
            Token::RParen,
            [(Token::LBrace, Token::RBrace)],
            |span| (Vec::new(), sp(span)),
        )));
    // `A, B.Plan.S`: the teams that share the service, each running it.
    let teams = name().then(
        tok(Token::Comma)
            .ignore_then(name().labelled("a team name"))
            .repeated()
            .collect::<Vec<_>>(),
    );
    let service = teams
        .then_ignore(tok(Token::Dot))
        .then(name())
        .then_ignore(tok(Token::Dot))
        .then(name())
        .then(params.clone().or_not())
        .then(braced_block())
        .then(repeat.or_not())
        .map_with(
            |((((((team, more_teams), plan), name), params), body), repeat), e| {
                let (params, params_span) = split_params(params);
                Item::Service(CompositeService {
                    team,
                    more_teams,
                    plan,
                    name,
                    params,
                    params_span,
                    body,
                    repeat,
                    span: sp(e.span()),
                })
            },
        );

    let function = kw(Kw::Def)
        .ignore_then(name().labelled("a function name"))
        .then(params.clone().or_not())
        .then(braced_block())
        .map_with(|((name, params), body), e| {
            let (params, params_span) = split_params(params);
            Item::Function(Function {
                name,
                params,
                params_span,
                body,
                span: sp(e.span()),
            })
        });

    let set_target = kw(Kw::Off)
        .map(|s| SetTarget::Off(sp(s)))
        .or(name().map(SetTarget::Service));
    let set_stmt = kw(Kw::Set)
        .ignore_then(
            name()
                .labelled("a plan name")
                .then_ignore(tok(Token::Comma))
                .then(set_target)
                .then(arg_list().or_not())
                .then(tok(Token::Comma).ignore_then(timeout()).or_not())
                .delimited_by(tok(Token::LParen), tok(Token::RParen)),
        )
        .map_with(|(((plan, service), args), timeout), e| SetStmt {
            plan,
            service,
            args,
            timeout,
            span: sp(e.span()),
        })
        .then_ignore(semis.clone());
    let mode = name()
        .then_ignore(tok(Token::Dot))
        .then(name())
        .then(params.or_not())
        .then(
            recovering(set_stmt.map(Some), |_| None)
                .repeated()
                .collect::<Vec<_>>()
                .delimited_by(tok(Token::LBrace), tok(Token::RBrace)),
        )
        .map_with(|(((team, name), params), sets), e| {
            let (params, params_span) = split_params(params);
            Item::Mode(ModeDef {
                team,
                name,
                params,
                params_span,
                sets: sets.into_iter().flatten().collect(),
                span: sp(e.span()),
            })
        });

    let mode_assign = kw(Kw::Mode)
        .ignore_then(tok(Token::Assign))
        .ignore_then(name().labelled("a mode name"))
        .then(arg_list().or_not())
        .then_ignore(semis.clone());
    let catch = kw(Kw::Catch)
        .ignore_then(
            name()
                .labelled("an event name")
                .delimited_by(tok(Token::LParen), tok(Token::RParen)),
        )
        .then_ignore(tok(Token::Colon))
        .then(mode_assign.clone())
        .map_with(|(event, (target, target_args)), e| Catch {
            event,
            target,
            target_args,
            span: sp(e.span()),
        });
    let case = kw(Kw::Case)
        .ignore_then(
            name()
                .labelled("a mode name")
                .delimited_by(tok(Token::LParen), tok(Token::RParen)),
        )
        .then_ignore(tok(Token::Colon))
        .then(catch.repeated().collect::<Vec<_>>())
        .map_with(|(mode, catches), e| {
            MainArm::Case(Case {
                mode,
                catches,
                span: sp(e.span()),
            })
        });
    let default = kw(Kw::Default)
        .ignore_then(tok(Token::Colon))
        .ignore_then(mode_assign)
        .map(MainArm::Default);
    let main = name()
        .then_ignore(tok(Token::Dot))
        .then(kw(Kw::Main))
        .then(
            recovering(case.or(default), |_| MainArm::Bad)
                .repeated()
                .collect::<Vec<_>>()
                .delimited_by(tok(Token::LBrace), tok(Token::RBrace)),
        )
        .map_with(|((team, main_span), arms), e| {
            let mut cases = Vec::new();
            let mut default = None;
            for arm in arms {
                match arm {
                    MainArm::Case(c) => cases.push(c),
                    MainArm::Default(d) => default = default.or(Some(d)),
                    MainArm::Bad => {}
                }
            }
            let (default, default_args) = match default {
                Some((name, args)) => (Some(name), args),
                None => (None, None),
            };
            Item::Main(MainDef {
                team,
                main_span: sp(main_span),
                cases,
                default,
                default_args,
                span: sp(e.span()),
            })
        });

    // Text that starts no item, after the items of a chunk (a header being
    // typed: `Team.`), is one bad item: the items before it are kept.
    let rest = any()
        .repeated()
        .at_least(1)
        .map_with(|_, e| Item::Error(sp(e.span())));
    // Each item's parser boxed: the choice's type (and the drop glue's
    // symbol, whose name spells it) stays small, instead of nesting every
    // item's combinators into one name hundreds of kilobytes long.
    choice((
        formation_block.boxed(),
        service.boxed(),
        main.boxed(),
        mode.boxed(),
        function.boxed(),
        bare_team.boxed(),
    ))
    .then_ignore(semis)
    .labelled("a team, service, mode, main or function")
    .recover_with(via_parser(rest))
    .repeated()
    .collect::<Vec<_>>()
}

#[derive(Clone)]
enum MainArm {
    Case(Case),
    Default((Ident, Option<ArgList>)),
    /// A line that did not parse (already reported).
    Bad,
}
