//! What is being typed at a cursor, read from the tokens before it.
//!
//! The syntax tree of half-typed text (`set(`, `Team.`, `move(` at the end of a
//! line) has lost exactly what matters here, so the place is found from tokens:
//! the text from the start of the item around the cursor (found in the tree,
//! whose items always start at an item header) up to the cursor is lexed, and
//! a small bracket-aware scan keeps, for every bracket still open, what opened
//! it and the tokens written directly inside it. The last few tokens at the
//! innermost level then say what may come next. This costs one item's worth of
//! lexing, whatever the size of the file.

use crate::sema::CheckedMission;
use crate::span::Span;
use crate::syntax::ast::{self, ArmKind, CommKind, Name};
use crate::syntax::token::{self, Kw, Token};

/// The item the cursor is in, from its header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Head {
    /// Not inside any item's brackets.
    None,
    /// `{ Team: Type robot ... }`
    Formation,
    Service {
        team: Name,
    },
    Function,
    Mode {
        team: Name,
    },
    Main {
        team: Name,
    },
}

impl Head {
    pub(crate) fn team(&self) -> Option<&Name> {
        match self {
            Head::Service { team } | Head::Mode { team } | Head::Main { team } => Some(team),
            _ => None,
        }
    }
}

/// What an open `(` belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Paren {
    Set,
    Case,
    Catch,
    Comm(CommKind),
    Arm(ArmKind),
    If,
    Loop,
    Repeat,
    /// The arguments of a built-in service or function call.
    Call {
        name: Name,
    },
    /// Anything else: a parenthesised expression.
    Expr,
}

/// One token directly at a bracket level, or a whole closed bracket group.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Lt<'s> {
    Tok(Token<'s>, Span),
    Closed {
        opener: Token<'s>,
        /// What a closed `(` belonged to.
        paren: Option<Paren>,
        /// The first token inside, when it is a name: `P` of `set(P, S)`.
        first_name: Option<Name>,
        span: Span,
    },
}

impl<'s> Lt<'s> {
    fn token(&self) -> Option<Token<'s>> {
        match self {
            Lt::Tok(t, _) => Some(*t),
            Lt::Closed { .. } => None,
        }
    }

    fn name(&self) -> Option<&'s str> {
        match self {
            Lt::Tok(Token::Ident(n), _) => Some(n),
            _ => None,
        }
    }

    pub(crate) fn closed_paren(&self) -> Option<&Paren> {
        match self {
            Lt::Closed {
                opener: Token::LParen,
                paren,
                ..
            } => paren.as_ref(),
            _ => None,
        }
    }

    pub(crate) fn is_closed_brace(&self) -> bool {
        matches!(
            self,
            Lt::Closed {
                opener: Token::LBrace,
                ..
            }
        )
    }
}

/// A bracket still open at the cursor.
#[derive(Clone, Debug)]
pub(crate) struct Frame<'s> {
    pub opener: Token<'s>,
    pub paren: Option<Paren>,
    pub open_span: Span,
    /// The tokens directly inside, up to the cursor.
    pub level: Vec<Lt<'s>>,
}

impl Frame<'_> {
    /// How many commas directly inside: the index of the argument at the cursor.
    pub(crate) fn argument_index(&self) -> usize {
        self.level
            .iter()
            .filter(|t| t.token() == Some(Token::Comma))
            .count()
    }

    /// The tokens of the argument at the cursor (after the last comma).
    fn current_argument(&self) -> &[Lt<'_>] {
        let start = self
            .level
            .iter()
            .rposition(|t| t.token() == Some(Token::Comma))
            .map_or(0, |i| i + 1);
        &self.level[start..]
    }

    fn first_name(&self) -> Option<&str> {
        self.level.first().and_then(Lt::name)
    }
}

/// The state of the text up to a cursor.
#[derive(Clone, Debug)]
pub(crate) struct Scan<'s> {
    pub head: Head,
    /// Open brackets, outermost first.
    pub frames: Vec<Frame<'s>>,
    /// Tokens at the top level since the last item header.
    pub top: Vec<Lt<'s>>,
}

/// Where the scan of the text before `offset` starts: the start of the item
/// around it, or of the last item before it. Inside a braced formation (which
/// may declare hundreds of teams), the start of the team declaration there,
/// with the formation's brace already open.
fn window_start(analysis: &CheckedMission, offset: usize) -> (usize, Option<Span>) {
    let items = &analysis.syntax.items;
    let after = items.partition_point(|item| item.span().start <= offset);
    let Some(i) = after.checked_sub(1) else {
        return (0, None);
    };
    if let ast::Item::Formation(f) = &items[i]
        && f.braced
        && f.span.start < offset
        && offset < f.span.end
    {
        let teams = f.teams.partition_point(|t| t.span.start <= offset);
        if let Some(t) = teams.checked_sub(1) {
            let brace = Span::new(f.span.start, f.span.start + 1);
            return (f.teams[t].span.start, Some(brace));
        }
    }
    (items[i].span().start.min(offset), None)
}

/// If the tokens end with an item header (`T.P.S`, `T.main`, `T.M`, `def f`,
/// each with a parameter list or not), the item it starts.
fn header(level: &[Lt<'_>]) -> Option<Head> {
    // `T.M(A)`, `T.P.S(A)`, `def f(A)`: the parameter list is part of it.
    let level = match level.last() {
        Some(Lt::Closed {
            opener: Token::LParen,
            ..
        }) => &level[..level.len() - 1],
        _ => level,
    };
    let n = level.len();
    let tok = |back: usize| -> Option<Token<'_>> {
        n.checked_sub(back)
            .and_then(|i| level.get(i))
            .and_then(Lt::token)
    };
    let ident = |back: usize| -> Option<Name> {
        match tok(back) {
            Some(Token::Ident(s)) => Some(Name::new(s)),
            _ => None,
        }
    };
    let dot = |back: usize| tok(back) == Some(Token::Dot);
    if let (Some(team), true, Some(_), true, Some(_)) =
        (ident(5), dot(4), ident(3), dot(2), ident(1))
    {
        return Some(Head::Service { team });
    }
    if let (Some(team), true, Some(Token::Kw(Kw::Main))) = (ident(3), dot(2), tok(1)) {
        return Some(Head::Main { team });
    }
    if let (Some(team), true, Some(_)) = (ident(3), dot(2), ident(1)) {
        return Some(Head::Mode { team });
    }
    if let (Some(Token::Kw(Kw::Def)), Some(_)) = (tok(2), ident(1)) {
        return Some(Head::Function);
    }
    None
}

/// What the `(` after these tokens belongs to.
fn paren_of(level: &[Lt<'_>]) -> Paren {
    match level.last() {
        Some(Lt::Tok(Token::Kw(k), _)) => match k {
            Kw::Set => Paren::Set,
            Kw::Case => Paren::Case,
            Kw::Catch => Paren::Catch,
            Kw::Send => Paren::Comm(CommKind::Send),
            Kw::Receive => Paren::Comm(CommKind::Receive),
            Kw::Publish => Paren::Comm(CommKind::Publish),
            Kw::Subscribe => Paren::Comm(CommKind::Subscribe),
            Kw::Group => Paren::Arm(ArmKind::Group),
            Kw::Leader => Paren::Arm(ArmKind::Leader),
            Kw::If => Paren::If,
            Kw::Loop => Paren::Loop,
            Kw::Repeat => Paren::Repeat,
            _ => Paren::Expr,
        },
        // `T.x(` is not a call: only a plain name is.
        Some(Lt::Tok(Token::Ident(name), _))
            if !matches!(
                level.len().checked_sub(2).and_then(|i| level[i].token()),
                Some(Token::Dot)
            ) =>
        {
            Paren::Call {
                name: Name::new(name),
            }
        }
        _ => Paren::Expr,
    }
}

fn closer_of(open: Token<'_>) -> Option<Token<'static>> {
    Some(match open {
        Token::LBrace => Token::RBrace,
        Token::LParen => Token::RParen,
        Token::GroupOpen => Token::GroupClose,
        Token::LBracket => Token::RBracket,
        _ => return None,
    })
}

/// Scans `text[..end]` from the start of the item around `end`.
pub(crate) fn scan<'s>(analysis: &CheckedMission, text: &'s str, end: usize) -> Scan<'s> {
    let end = floor_char_boundary(text, end.min(text.len()));
    let (start, formation) = window_start(analysis, end);
    let start = floor_char_boundary(text, start.min(end));
    let mut state = Scan {
        head: Head::None,
        frames: Vec::new(),
        top: Vec::new(),
    };
    if let Some(brace) = formation {
        state.head = Head::Formation;
        state.frames.push(Frame {
            opener: Token::LBrace,
            paren: None,
            open_span: brace,
            level: Vec::new(),
        });
    }
    let mut previous_end = start;
    for (tok, span) in token::lex(&text[start..end]) {
        let span = Span::new(span.start + start, span.end + start);
        if text[previous_end..span.start].contains('\n') {
            state.line_break(previous_end);
        }
        previous_end = span.end;
        state.push(tok, span);
    }
    if text[previous_end..end].contains('\n') {
        state.line_break(previous_end);
    }
    state
}

impl<'s> Scan<'s> {
    fn level_mut(&mut self) -> &mut Vec<Lt<'s>> {
        match self.frames.last_mut() {
            Some(f) => &mut f.level,
            None => &mut self.top,
        }
    }

    fn level(&self) -> &[Lt<'s>] {
        match self.frames.last() {
            Some(f) => &f.level,
            None => &self.top,
        }
    }

    /// As the parser does, a `(` or `[` still open at the end of its line is
    /// closed there: argument lists and conditions are written on one line.
    fn line_break(&mut self, line_end: usize) {
        while let Some(frame) = self.frames.last()
            && matches!(frame.opener, Token::LParen | Token::LBracket)
        {
            let span = Span::new(line_end, line_end);
            self.close(self.frames.len() - 1, span);
        }
    }

    /// Closes the frame at `at` and those inside it, with a closer at `span`.
    fn close(&mut self, at: usize, span: Span) {
        let mut closed = self.frames.drain(at..);
        let Some(frame) = closed.next() else { return };
        drop(closed);
        let first_name = frame.first_name().map(Name::new);
        let item = Lt::Closed {
            opener: frame.opener,
            paren: frame.paren,
            first_name,
            span: frame.open_span.cover(span),
        };
        if self.frames.is_empty() && item.is_closed_brace() {
            // An item's body closed: what follows is the next item, or
            // the `repeat(...)` of a service.
            self.top.clear();
        }
        self.level_mut().push(item);
    }

    fn push(&mut self, tok: Token<'s>, span: Span) {
        if closer_of(tok).is_some() {
            let mut paren = None;
            if tok == Token::LBrace {
                // An item header starts a new item wherever it is (as the
                // parser's chunks do); a `{` at the top level is a formation.
                if let Some(head) = header(self.level()) {
                    self.frames.clear();
                    self.top.clear();
                    self.head = head;
                } else if self.frames.is_empty() {
                    self.top.clear();
                    self.head = Head::Formation;
                }
            } else if tok == Token::LParen {
                paren = Some(paren_of(self.level()));
            }
            self.frames.push(Frame {
                opener: tok,
                paren,
                open_span: span,
                level: Vec::new(),
            });
            return;
        }
        let closes = |f: &Frame<'_>| closer_of(f.opener) == Some(tok);
        if matches!(
            tok,
            Token::RBrace | Token::RParen | Token::GroupClose | Token::RBracket
        ) {
            // A closer without its opener is ignored; one that closes an outer
            // bracket closes the ones left open inside it too.
            if let Some(at) = self.frames.iter().rposition(closes) {
                self.close(at, span);
            }
            return;
        }
        self.level_mut().push(Lt::Tok(tok, span));
    }
}

fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The identifier being typed at `offset`: from its first character to the
/// cursor. Digits at its start belong to a number (`2SE` → `SE`).
pub(crate) fn prefix_at(text: &str, offset: usize) -> Span {
    let offset = floor_char_boundary(text, offset.min(text.len()));
    let bytes = text.as_bytes();
    let mut start = offset;
    while start > 0 && (bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_') {
        start -= 1;
    }
    while start < offset && bytes[start].is_ascii_digit() {
        start += 1;
    }
    Span::new(start, offset)
}

/// What the line holds at a cursor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Trivia {
    Code,
    Comment,
    String,
}

/// Whether `offset` is inside a comment or a string literal of its line.
pub(crate) fn trivia_at(text: &str, offset: usize) -> Trivia {
    let offset = floor_char_boundary(text, offset.min(text.len()));
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let mut in_string = false;
    let mut escaped = false;
    for c in text[line_start..offset].chars() {
        if in_string {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '"' => in_string = false,
                _ => {}
            }
        } else {
            match c {
                '"' => in_string = true,
                '#' => return Trivia::Comment,
                _ => {}
            }
        }
    }
    match in_string {
        true => Trivia::String,
        false => Trivia::Code,
    }
}

/// What may be written at the cursor.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Place {
    /// Nothing can be offered (a new name, a number, a comment...).
    Nothing,
    /// The start of an item.
    Item,
    /// `Team.` at the start of an item: its plans, `main`, its modes.
    ItemAfterTeam { team: Name },
    /// `Team.Plan.` at the start of an item: the services that modes set for
    /// that plan but nobody defined yet.
    ItemAfterPlan { team: Name, plan: Name },
    /// The start of a team declaration in the formation block.
    TeamDecl,
    /// `Team: |` or `Type a, |`: a robot type.
    RobotType,
    /// The start of a statement in a service or function body.
    Statement,
    /// Directly inside `[[ ... ]]`: an arm keyword.
    GroupArm { first: bool, leader: bool },
    /// `group(|`: `instance of` or `capable of`.
    ArmCondition,
    /// `group(instance of |`: robot types of the robots here.
    ArmTypes,
    /// `group(capable of |`: capabilities of the robots here.
    ArmCapabilities,
    /// `throw |`: an event of the team.
    Throw,
    /// `send(|`: a team or USER.
    CommTeam,
    /// A value: in a condition, argument or communicated item. `qualifier`:
    /// after `Team.`.
    Expr { qualifier: Option<Name> },
    /// The right side of a comparison (`COLOR == |`): `attr` is the dotted
    /// name on its left, if it is one; `words`: the operator is `==` or
    /// `!=`, which compare words and strings too. A bare value may not
    /// stand here (E041: a bare name on the right is a word).
    Compared {
        attr: Option<Vec<Name>>,
        words: bool,
    },
    /// After a complete operand in a condition: `and`, `or`.
    AfterOperand,
    /// After a number: a time unit (`and`, `or` too in a condition).
    Unit { in_condition: bool },
    /// The start of a line in a mode: `set`.
    SetStart,
    /// `set(|`: a plan of the team.
    SetPlan,
    /// `set(Plan, |`: a service of that plan, or `OFF`.
    SetService { plan: Name },
    /// `set(Plan, Service, |`: `timeout =`.
    SetTimeout,
    /// The start of a line in a main block.
    MainArm { in_case: bool },
    /// `case(|`: a mode of the team.
    CaseMode,
    /// `catch(|`: an event, preferably one that a service of `mode` throws.
    CatchEvent { mode: Option<Name> },
    /// `catch (e): |` or `default: |`: `mode =`.
    ModeKeyword,
    /// `mode = |`: a mode of the team.
    ModeName,
}

fn is_operator(t: Token<'_>) -> bool {
    matches!(
        t,
        Token::EqEq
            | Token::NotEq
            | Token::Lt
            | Token::Le
            | Token::Gt
            | Token::Ge
            | Token::AndAnd
            | Token::OrOr
            | Token::Bang
            | Token::Kw(Kw::And | Kw::Or | Kw::Not)
    )
}

fn is_comparison(t: Token<'_>) -> bool {
    matches!(
        t,
        Token::EqEq | Token::NotEq | Token::Lt | Token::Le | Token::Gt | Token::Ge
    )
}

/// The dotted name that `tokens` end with (`SlaveTeam.COLOR`), if any.
fn trailing_attr(tokens: &[Lt<'_>]) -> Option<Vec<Name>> {
    let mut names = Vec::new();
    let mut i = tokens.len();
    loop {
        let name = i.checked_sub(1).and_then(|j| tokens[j].name())?;
        names.push(Name::new(name));
        i -= 1;
        if i >= 2 && tokens[i - 1].token() == Some(Token::Dot) {
            i -= 1;
            continue;
        }
        break;
    }
    names.reverse();
    Some(names)
}

/// The place of an expression whose tokens so far (in this argument) are `ts`;
/// `words`: several bare words may follow each other (a call's argument).
fn expression(ts: &[Lt<'_>], words: bool) -> Place {
    let last = |back: usize| ts.len().checked_sub(back).and_then(|i| ts[i].token());
    match last(1) {
        // A number alone may be a period (`loop(2 SEC)`); after `>` it is not.
        Some(Token::Number(_)) => Place::Unit {
            in_condition: !words && ts.len() > 1,
        },
        Some(Token::Dot) => match (last(2), last(3)) {
            (Some(Token::Ident(q)), third) if third != Some(Token::Dot) => Place::Expr {
                qualifier: Some(Name::new(q)),
            },
            _ => Place::Nothing,
        },
        Some(t) if is_comparison(t) => Place::Compared {
            attr: trailing_attr(&ts[..ts.len() - 1]),
            words: matches!(t, Token::EqEq | Token::NotEq),
        },
        None if ts.is_empty() => Place::Expr { qualifier: None },
        Some(Token::Assign | Token::Comma) => Place::Expr { qualifier: None },
        Some(t) if is_operator(t) => Place::Expr { qualifier: None },
        // After a complete operand: `move(Paris |` may go on with words.
        Some(Token::Ident(_) | Token::Kw(_)) if words => Place::Expr { qualifier: None },
        Some(Token::Ident(_) | Token::Kw(Kw::True | Kw::False) | Token::Str(_)) => {
            Place::AfterOperand
        }
        None if matches!(ts.last(), Some(Lt::Closed { .. })) => Place::AfterOperand,
        _ => Place::Nothing,
    }
}

/// The place of the cursor, given the scan of the text before the identifier
/// being typed.
pub(crate) fn place(scan: &Scan<'_>) -> Place {
    let Some(frame) = scan.frames.last() else {
        return top_level(&scan.top);
    };
    match frame.opener {
        Token::LBrace => match scan.head {
            Head::Formation => formation(&frame.level, true),
            Head::Mode { .. } => mode_body(&frame.level),
            Head::Main { .. } => main_body(&frame.level),
            Head::Service { .. } | Head::Function => statement(&frame.level),
            // `{` without a recognised header at depth > 0 cannot happen (a top
            // level `{` is a formation); be quiet.
            Head::None => Place::Nothing,
        },
        Token::GroupOpen => {
            let leader = frame
                .level
                .iter()
                .any(|t| t.token() == Some(Token::Kw(Kw::Leader)));
            match frame.level.last() {
                None => Place::GroupArm {
                    first: true,
                    leader,
                },
                Some(t) if t.is_closed_brace() => Place::GroupArm {
                    first: false,
                    leader,
                },
                _ => Place::Nothing,
            }
        }
        Token::LParen => parenthesised(scan, frame),
        _ => Place::Nothing,
    }
}

fn top_level(top: &[Lt<'_>]) -> Place {
    // After a service body: `} repeat(...)` still belongs to it.
    let mut seg = top;
    if let [first, rest @ ..] = seg
        && first.is_closed_brace()
    {
        seg = rest;
    }
    if let [Lt::Tok(Token::Kw(Kw::Repeat), _), rest @ ..] = seg {
        seg = match rest {
            [closed, rest @ ..] if closed.closed_paren().is_some() => rest,
            _ => return Place::Nothing,
        };
    }
    // Bare team declarations: `Team: Type robot, Type robot`.
    if let Some(colon) = seg.iter().rposition(|t| t.token() == Some(Token::Colon))
        && colon > 0
        && seg[colon - 1].name().is_some()
    {
        return formation(&seg[colon - 1..], false);
    }
    let last = |back: usize| {
        seg.len()
            .checked_sub(back)
            .and_then(|i| seg.get(i))
            .and_then(Lt::token)
    };
    match (last(1), last(2), last(3)) {
        (None, _, _) | (Some(Token::Semi), _, _) => Place::Item,
        (Some(Token::Dot), Some(Token::Ident(team)), third) if third != Some(Token::Dot) => {
            Place::ItemAfterTeam {
                team: Name::new(team),
            }
        }
        (Some(Token::Dot), Some(Token::Ident(plan)), Some(Token::Dot)) => {
            match (last(4), last(5)) {
                (Some(Token::Ident(team)), fifth) if fifth != Some(Token::Dot) => {
                    Place::ItemAfterPlan {
                        team: Name::new(team),
                        plan: Name::new(plan),
                    }
                }
                _ => Place::Nothing,
            }
        }
        // After a complete bare team declaration, a new item may start.
        _ => Place::Nothing,
    }
}

/// Inside a formation (`braced`) or a bare team declaration; `level` starts at
/// the team name for a bare one.
fn formation(level: &[Lt<'_>], braced: bool) -> Place {
    let n = level.len();
    let at = |back: usize| n.checked_sub(back).and_then(|i| level.get(i));
    let tok = |back: usize| at(back).and_then(Lt::token);
    // Where a team declaration may start: a new one in the braces, a new item
    // after a bare one.
    let next = if braced { Place::TeamDecl } else { Place::Item };
    match (at(1), tok(2)) {
        (Some(Lt::Tok(Token::Colon, _)), Some(Token::Ident(_))) => Place::RobotType,
        (Some(Lt::Tok(Token::Comma, _)), _) => Place::RobotType,
        // `Type |`: the robot's name is new.
        (Some(Lt::Tok(Token::Ident(_), _)), Some(Token::Colon | Token::Comma)) => Place::Nothing,
        // `Type name |` or `name[2] |`.
        (Some(Lt::Tok(Token::Ident(_), _)), Some(Token::Ident(_))) => next,
        (Some(Lt::Closed { .. } | Lt::Tok(Token::Semi, _)), _) => next,
        (None, _) => next,
        _ => Place::Nothing,
    }
}

fn statement(level: &[Lt<'_>]) -> Place {
    let last = |back: usize| {
        level
            .len()
            .checked_sub(back)
            .and_then(|i| level.get(i))
            .and_then(Lt::token)
    };
    match (last(1), last(2)) {
        (Some(Token::Kw(Kw::Throw)), _) => Place::Throw,
        (Some(Token::Number(_)), Some(Token::Assign)) => Place::Unit {
            in_condition: false,
        },
        (Some(Token::Assign | Token::Kw(Kw::Timeout)), _) => Place::Nothing,
        (
            Some(Token::Kw(
                Kw::If
                | Kw::Loop
                | Kw::Group
                | Kw::Leader
                | Kw::Others
                | Kw::Send
                | Kw::Receive
                | Kw::Publish
                | Kw::Subscribe
                | Kw::Def,
            )),
            _,
        ) => Place::Nothing,
        (Some(Token::Dot | Token::Number(_) | Token::Str(_)), _) => Place::Nothing,
        (Some(t), _) if is_operator(t) => Place::Nothing,
        // `move() ,|` before `timeout`.
        (Some(Token::Comma), _) => Place::Nothing,
        _ => Place::Statement,
    }
}

fn mode_body(level: &[Lt<'_>]) -> Place {
    match level.last() {
        None => Place::SetStart,
        Some(t) if t.closed_paren().is_some() => Place::SetStart,
        Some(Lt::Tok(Token::Semi, _)) => Place::SetStart,
        _ => Place::Nothing,
    }
}

fn main_body(level: &[Lt<'_>]) -> Place {
    let n = level.len();
    let at = |back: usize| n.checked_sub(back).and_then(|i| level.get(i));
    let tok = |back: usize| at(back).and_then(Lt::token);
    let in_case = level.iter().any(|t| t.token() == Some(Token::Kw(Kw::Case)));
    match tok(1) {
        Some(Token::Assign) if tok(2) == Some(Token::Kw(Kw::Mode)) => return Place::ModeName,
        Some(Token::Kw(Kw::Mode)) => return Place::Nothing,
        Some(Token::Colon) => {
            if tok(2) == Some(Token::Kw(Kw::Default)) {
                return Place::ModeKeyword;
            }
            return match at(2).and_then(Lt::closed_paren) {
                Some(Paren::Catch) => Place::ModeKeyword,
                Some(Paren::Case) => Place::MainArm { in_case: true },
                _ => Place::Nothing,
            };
        }
        Some(Token::Kw(Kw::Case | Kw::Catch | Kw::Default)) => return Place::Nothing,
        _ => {}
    }
    match at(1) {
        None => Place::MainArm { in_case },
        // After `mode = X`.
        Some(Lt::Tok(Token::Ident(_) | Token::Semi, _)) => Place::MainArm { in_case },
        _ => Place::Nothing,
    }
}

/// The mode of the last `case (M):` among `level`'s tokens.
fn last_case_mode(level: &[Lt<'_>]) -> Option<Name> {
    level.iter().rev().find_map(|t| match t {
        Lt::Closed {
            paren: Some(Paren::Case),
            first_name,
            ..
        } => first_name.clone(),
        _ => None,
    })
}

fn parenthesised(scan: &Scan<'_>, frame: &Frame<'_>) -> Place {
    let Some(paren) = &frame.paren else {
        return Place::Nothing;
    };
    // Between items, only a service's `repeat(...)` has parentheses.
    if scan.frames.len() == 1 && *paren != Paren::Repeat {
        return Place::Nothing;
    }
    let index = frame.argument_index();
    let arg = frame.current_argument();
    match paren {
        Paren::Set => match (index, arg) {
            (0, []) => Place::SetPlan,
            (1, []) => match frame.first_name() {
                Some(plan) => Place::SetService {
                    plan: Name::new(plan),
                },
                None => Place::Nothing,
            },
            (2, []) => Place::SetTimeout,
            (
                2,
                [
                    Lt::Tok(Token::Kw(Kw::Timeout), _),
                    Lt::Tok(Token::Assign, _),
                    ..,
                ],
            ) => match arg.last().and_then(Lt::token) {
                Some(Token::Number(_)) => Place::Unit {
                    in_condition: false,
                },
                _ => Place::Nothing,
            },
            _ => Place::Nothing,
        },
        Paren::Case if frame.level.is_empty() => Place::CaseMode,
        Paren::Catch if frame.level.is_empty() => {
            let outer = scan.frames.len().checked_sub(2).map(|i| &scan.frames[i]);
            Place::CatchEvent {
                mode: outer.and_then(|f| last_case_mode(&f.level)),
            }
        }
        Paren::Case | Paren::Catch => Place::Nothing,
        Paren::Comm(_) if index == 0 => match arg {
            [] => Place::CommTeam,
            _ => Place::Nothing,
        },
        Paren::Arm(_) => arm_condition(&frame.level),
        Paren::Call { .. } => expression(arg, true),
        Paren::Comm(_) | Paren::If | Paren::Loop | Paren::Repeat | Paren::Expr => {
            expression(arg, false)
        }
    }
}

fn arm_condition(level: &[Lt<'_>]) -> Place {
    let kind = level.first().and_then(Lt::token);
    let last = level.last().and_then(Lt::token);
    match (kind, level.get(1).and_then(Lt::token), last) {
        (None, _, _) => Place::ArmCondition,
        (Some(Token::Kw(Kw::Instance)), Some(Token::Kw(Kw::Of)), Some(Token::Kw(Kw::Of)))
        | (Some(Token::Kw(Kw::Instance)), Some(Token::Kw(Kw::Of)), Some(Token::Comma)) => {
            Place::ArmTypes
        }
        (Some(Token::Kw(Kw::Capable)), Some(Token::Kw(Kw::Of)), Some(Token::Kw(Kw::Of)))
        | (Some(Token::Kw(Kw::Capable)), Some(Token::Kw(Kw::Of)), Some(Token::Comma)) => {
            Place::ArmCapabilities
        }
        _ => Place::Nothing,
    }
}
