//! The positioned syntax tree of a mission script. Every node carries the byte
//! range it was written at; names carry their own range for precise diagnostics.
//! Nodes that failed to parse are kept as `Error` variants so the rest of the
//! file can still be checked.

use crate::span::Span;

/// A name as stored everywhere in the tree and the IR: short names (nearly all
/// of them) live inline, so parsing allocates nothing per identifier.
pub type Name = smol_str::SmolStr;

/// A name as written, with its range.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Ident {
    pub name: Name,
    pub span: Span,
}

impl Ident {
    pub fn new(name: &str, span: Span) -> Self {
        Ident {
            name: Name::new(name),
            span,
        }
    }

    pub fn as_str(&self) -> &str {
        &self.name
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceFile {
    pub items: Vec<Item>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `{ T: A a, B b[2] }` or a bare `T: A a` (then `braced` is false).
    Formation(Formation),
    Service(CompositeService),
    Function(Function),
    Mode(ModeDef),
    Main(MainDef),
    /// Text that could not be parsed; its syntax error is already reported.
    Error(Span),
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Formation(f) => f.span,
            Item::Service(s) => s.span,
            Item::Function(f) => f.span,
            Item::Mode(m) => m.span,
            Item::Main(m) => m.span,
            Item::Error(span) => *span,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Formation {
    pub teams: Vec<TeamDecl>,
    pub braced: bool,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TeamDecl {
    pub name: Ident,
    pub robots: Vec<RobotDecl>,
    pub span: Span,
}

/// `Type name` or `Type name[N]` (N robots `name_0` .. `name_{N-1}`).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotDecl {
    pub robot_type: Ident,
    pub name: Ident,
    pub count: Option<Count>,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Count {
    /// `None` when the number is not a whole number; `u32::MAX` when it is
    /// one too large for `u32`.
    pub value: Option<u32>,
    pub span: Span,
}

/// `Team.Plan.Service { ... } repeat(...)`, or `A, B.Plan.Service { ... }`:
/// one service that the robots of each team named run, each team its own
/// copy (`docs/language/services.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct CompositeService {
    /// The first team of the header.
    pub team: Ident,
    /// The teams after the first (`A, B.Plan.S`: `B`); empty for one team.
    pub more_teams: Vec<Ident>,
    pub plan: Ident,
    pub name: Ident,
    /// The parameters, in order (`T.P.S(PLACE) { ... }`): each a name that
    /// stands in the body for the argument a mode's `set` gives
    /// (`docs/language/modes.md`).
    pub params: Vec<Ident>,
    /// The range of `( ... )` after the name; `None` without a list.
    pub params_span: Option<Span>,
    pub body: Block,
    pub repeat: Option<Repeat>,
    pub span: Span,
}

/// `repeat()`, `repeat(P)`, `repeat(expr)` or `repeat(P, expr)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Repeat {
    pub period: Option<Period>,
    pub condition: Option<Expr>,
    pub span: Span,
}

/// `def name { ... }` or `def name(PARAM, ...) { ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    pub name: Ident,
    /// The parameters, in order: each a name that stands for its argument
    /// in the body (`docs/language/services.md`).
    pub params: Vec<Ident>,
    /// The range of `( ... )` after the name; `None` for `def name { ... }`.
    pub params_span: Option<Span>,
    pub body: Block,
    pub span: Span,
}

/// `Team.MODE { set(...) ... }` or `Team.MODE(TARGET) { ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeDef {
    pub team: Ident,
    pub name: Ident,
    /// The parameters, in order: each a name that stands in the mode's
    /// `set`s for the argument the mode is entered with
    /// (`mode = MOVE(kitchen)`, `docs/language/modes.md`).
    pub params: Vec<Ident>,
    /// The range of `( ... )` after the name; `None` without a list.
    pub params_span: Option<Span>,
    pub sets: Vec<SetStmt>,
    pub span: Span,
}

/// `( a, b )` after a mode or service name: the arguments it is entered or
/// set with.
#[derive(Clone, Debug, PartialEq)]
pub struct ArgList {
    pub args: Vec<Arg>,
    /// The range of `( ... )`.
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SetStmt {
    pub plan: Ident,
    pub service: SetTarget,
    /// `set(Plan, S(a, b))`: the arguments of a service with parameters.
    pub args: Option<ArgList>,
    pub timeout: Option<Period>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum SetTarget {
    Service(Ident),
    /// `OFF`: the plan does not run in this mode.
    Off(Span),
}

/// `Team.main { case ... default: mode = M }`
#[derive(Clone, Debug, PartialEq)]
pub struct MainDef {
    pub team: Ident,
    /// The range of the `main` keyword.
    pub main_span: Span,
    pub cases: Vec<Case>,
    pub default: Option<Ident>,
    /// `default: mode = MOVE(kitchen)`: the default mode's arguments.
    pub default_args: Option<ArgList>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub mode: Ident,
    pub catches: Vec<Catch>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Catch {
    pub event: Ident,
    pub target: Ident,
    /// `mode = MOVE(kitchen)`: the arguments the mode is entered with.
    pub target_args: Option<ArgList>,
    pub span: Span,
}

/// `{ stmts }` or a single statement; `span` covers the braces when present.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub stmts: Vec<Stmt>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Stmt {
    pub kind: StmtKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum StmtKind {
    If(If),
    Loop(Loop),
    Group(GroupStmt),
    Comm(Comm),
    Throw(Throw),
    Call(Call),
    /// A statement that could not be parsed; its syntax error is already reported.
    Error,
}

/// `throw E` or `throw E broadcast`.
#[derive(Clone, Debug, PartialEq)]
pub struct Throw {
    pub event: Ident,
    /// The range of `broadcast`: the event goes to every robot of the
    /// thrower's group (its team outside any group), the thrower included.
    pub broadcast: Option<Span>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct If {
    pub condition: Expr,
    pub then_block: Block,
    pub else_branch: Option<Box<Else>>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Else {
    If(Stmt),
    Block(Block),
}

/// `loop(P)`, `loop(expr)` or `loop(P, expr)` followed by a block.
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    pub period: Option<Period>,
    pub condition: Option<Expr>,
    pub body: Block,
}

/// A built-in service or function call: `move("5,5"), timeout = 10 SEC`,
/// or with its results bound: `FOUND, WHERE = search(red)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    /// The names bound to the service's results, in order (`FOUND, WHERE =`);
    /// empty when none are (`docs/language/services.md`).
    pub results: Vec<Ident>,
    pub name: Ident,
    pub args: Vec<Arg>,
    pub timeout: Option<Period>,
    /// The range of `( ... )`.
    pub args_span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Arg {
    Expr(Expr),
    /// Several bare words taken as one string: `move(Paris palace of congress)`.
    Words {
        text: String,
        span: Span,
    },
}

impl Arg {
    pub fn span(&self) -> Span {
        match self {
            Arg::Expr(e) => e.span,
            Arg::Words { span, .. } => *span,
        }
    }

    /// A fixed argument as written, for the name of the mode or service it
    /// is given to (`MOVE(kitchen)`, `MOVE("hall door")`): distinct
    /// arguments have distinct texts (a string keeps its quotes, escaped).
    pub fn written(&self) -> String {
        match self {
            Arg::Words { text, .. } => text.clone(),
            Arg::Expr(e) => match &e.kind {
                ExprKind::Str(s) => format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"")),
                ExprKind::Number(n) => n.clone(),
                ExprKind::Period(p) => format!("{} {}", p.amount, p.unit.as_str()),
                ExprKind::Bool(b) => b.to_string(),
                ExprKind::Attr(a) => a.dotted(),
                _ => "?".to_string(),
            },
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CommKind {
    Send,
    Receive,
    Publish,
    Subscribe,
}

impl CommKind {
    pub fn as_str(self) -> &'static str {
        match self {
            CommKind::Send => "send",
            CommKind::Receive => "receive",
            CommKind::Publish => "publish",
            CommKind::Subscribe => "subscribe",
        }
    }

    /// Whether this statement delivers values (send, publish) or takes them in.
    pub fn is_outgoing(self) -> bool {
        matches!(self, CommKind::Send | CommKind::Publish)
    }
}

/// `send(T, a, T.X = e)`, `receive(T, a)`, `publish(T, a)`, `subscribe(T, a)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Comm {
    pub kind: CommKind,
    pub keyword_span: Span,
    pub team: Ident,
    pub items: Vec<CommItem>,
    pub timeout: Option<Period>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CommItem {
    pub attr: Attr,
    /// `T.X = expr`: sets the team variable, then delivers it.
    pub value: Option<Expr>,
}

/// `[[ leader(...) {...} ]]` or `[[ group(...) {...} ... others {...} ]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupStmt {
    pub arms: Vec<GroupArm>,
    pub others: Option<Others>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArmKind {
    Leader,
    Group,
}

#[derive(Clone, Debug, PartialEq)]
pub struct GroupArm {
    pub kind: ArmKind,
    pub keyword_span: Span,
    pub condition: GroupCond,
    pub body: Block,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Others {
    pub keyword_span: Span,
    pub body: Block,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CondKind {
    /// `instance of RobotType, ...`
    InstanceOf,
    /// `capable of capability, ...`
    CapableOf,
    /// `Name, min = N`: a counted group, its robots chosen at run time
    /// (`names` holds the group's name alone; `min` its minimum).
    Counted,
}

#[derive(Clone, Debug, PartialEq)]
pub struct GroupCond {
    pub kind: CondKind,
    pub names: Vec<Ident>,
    /// `min = N` of a [`CondKind::Counted`] condition; `None` otherwise.
    pub min: Option<GroupMin>,
    pub span: Span,
}

/// `min = N` in `group(Name, min = N)`: the fewest robots the group is given
/// when enough are alive.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupMin {
    /// The word `min` (a contextual word: elsewhere it is a plain name).
    pub keyword_span: Span,
    pub count: Count,
}

impl GroupCond {
    /// The counted group's name (`group(Name, min = N)`).
    pub fn counted_name(&self) -> Option<&Ident> {
        match self.kind {
            CondKind::Counted => self.names.first(),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TimeUnit {
    Msec,
    Sec,
    Min,
    Hour,
}

impl TimeUnit {
    pub fn parse(word: &str) -> Option<TimeUnit> {
        Some(match word.to_ascii_uppercase().as_str() {
            "MSEC" => TimeUnit::Msec,
            "SEC" => TimeUnit::Sec,
            "MIN" => TimeUnit::Min,
            "HOUR" => TimeUnit::Hour,
            _ => return None,
        })
    }

    /// [`TimeUnit::whole_millis`] for arithmetic on reals.
    pub fn millis(self) -> f64 {
        self.whole_millis() as f64
    }

    /// The milliseconds of one unit: every unit is a whole number of them,
    /// for exact arithmetic.
    pub fn whole_millis(self) -> u64 {
        match self {
            TimeUnit::Msec => 1,
            TimeUnit::Sec => 1_000,
            TimeUnit::Min => 60_000,
            TimeUnit::Hour => 3_600_000,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            TimeUnit::Msec => "MSEC",
            TimeUnit::Sec => "SEC",
            TimeUnit::Min => "MIN",
            TimeUnit::Hour => "HOUR",
        }
    }
}

/// `2 SEC`, `500 MSEC`.
#[derive(Clone, Debug, PartialEq)]
pub struct Period {
    /// The number as written.
    pub amount: String,
    pub unit: TimeUnit,
    pub span: Span,
}

impl Period {
    /// The period in milliseconds, if the amount is a valid number.
    pub fn millis(&self) -> Option<f64> {
        self.amount
            .parse::<f64>()
            .ok()
            .map(|a| a * self.unit.millis())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CmpOp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl CmpOp {
    pub fn as_str(self) -> &'static str {
        match self {
            CmpOp::Eq => "==",
            CmpOp::Ne => "!=",
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Or(Box<Expr>, Box<Expr>),
    And(Box<Expr>, Box<Expr>),
    Not(Box<Expr>),
    Compare(Box<Expr>, CmpOp, Box<Expr>),
    /// The unescaped text of a string literal.
    Str(String),
    /// A number as written.
    Number(String),
    Period(Period),
    Bool(bool),
    /// `LOCATION`, `SlaveTeam.COLOR`, `USER.RC_CMD`, or a symbolic constant.
    Attr(Attr),
    /// A sub-expression that failed to parse.
    Error,
}

/// A dotted name: `Name ('.' Name)*`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Attr {
    pub segments: Vec<Ident>,
    pub span: Span,
}

impl Attr {
    /// The text as written, `SlaveTeam.COLOR`.
    pub fn dotted(&self) -> String {
        let names: Vec<&str> = self.segments.iter().map(|s| s.as_str()).collect();
        names.join(".")
    }

    pub fn last(&self) -> &Ident {
        self.segments
            .last()
            .expect("an attribute has at least one segment")
    }
}

impl Block {
    /// Calls `f` on every statement of the block, nested ones included, in
    /// order (with the block's lifetime: `f` may keep what it is given).
    pub fn walk<'s>(&'s self, f: &mut impl FnMut(&'s Stmt)) {
        for stmt in &self.stmts {
            stmt.walk(f);
        }
    }
}

impl Stmt {
    /// Calls `f` on this statement and every statement nested in it.
    pub fn walk<'s>(&'s self, f: &mut impl FnMut(&'s Stmt)) {
        f(self);
        match &self.kind {
            StmtKind::If(i) => {
                i.then_block.walk(f);
                match i.else_branch.as_deref() {
                    Some(Else::If(stmt)) => stmt.walk(f),
                    Some(Else::Block(block)) => block.walk(f),
                    None => {}
                }
            }
            StmtKind::Loop(l) => l.body.walk(f),
            StmtKind::Group(g) => {
                for arm in &g.arms {
                    arm.body.walk(f);
                }
                if let Some(o) = &g.others {
                    o.body.walk(f);
                }
            }
            StmtKind::Comm(_) | StmtKind::Throw(_) | StmtKind::Call(_) | StmtKind::Error => {}
        }
    }
}
