//! Phase 2: statement bodies. Each statement is checked against the robots that
//! run it: all robots of the team, narrowed inside `group`/`leader` to those
//! meeting the condition and inside `others` to the rest. Functions are inlined:
//! their body is checked at every call, with the caller's robots.

use super::ir::*;
use super::values::{Literal, ParameterTest, VariableTest, VariableWrite};
use super::{Checker, is_user, suggestion};
use crate::catalog::{RobotTypeId, ServiceDef, ValueType};
use crate::diag::Code;
use crate::fasthash::FastMap;
use crate::span::Span;
use crate::syntax::ast::{self, Arg, ArmKind, CondKind, Expr, ExprKind, Name, StmtKind};
use std::rc::Rc;
use std::sync::Arc;

/// Deeper chains of function calls are refused: they are surely a mistake, and
/// the checker's recursion must stay bounded.
const MAX_INLINING_DEPTH: usize = 64;

/// Robot types, each with the names of the robots of that type.
pub(super) type TypeList = Rc<[(RobotTypeId, Vec<Name>)]>;

/// The robots running a scope, shared ([`Checker::shared_robots`]): equal
/// sets are one list, so equality and hashing are by identity, not by the
/// thousands of robots a team may have.
#[derive(Clone, Debug)]
pub(super) struct Robots(Arc<[RobotId]>);

impl std::ops::Deref for Robots {
    type Target = [RobotId];

    fn deref(&self) -> &[RobotId] {
        &self.0
    }
}

impl PartialEq for Robots {
    fn eq(&self, other: &Robots) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Eq for Robots {}

impl std::hash::Hash for Robots {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        std::ptr::hash(Arc::as_ptr(&self.0), state);
    }
}

/// The most robot names a message lists; the others are counted.
const NAMES_LISTED: usize = 8;

/// `names` (`count` of them) for a message: the first few, then how many
/// more, so that a message stays short whatever the team's size.
fn some_names<'n>(names: impl Iterator<Item = &'n str>, count: usize) -> String {
    let listed: Vec<&str> = names.take(NAMES_LISTED).collect();
    match count.checked_sub(listed.len()) {
        Some(more @ 1..) => format!("{} and {more} more", listed.join(", ")),
        _ => listed.join(", "),
    }
}

/// Who runs the statements being checked.
#[derive(Clone, Debug)]
pub(super) struct Scope {
    /// `None` inside a function that no service calls: robots are unknown.
    team: Option<TeamId>,
    service: Option<ServiceId>,
    /// The team's robots that run the statement: one shared list per set
    /// of robots ([`Checker::shared_robots`]), however many statements and
    /// scopes it runs (a team of thousands of robots and a file of
    /// thousands of statements would otherwise hold their product).
    robots: Robots,
    /// The known robot types among `robots`, with those robots' names: computed
    /// once per scope, read by every call and value in it.
    types: TypeList,
    /// Functions being inlined, innermost last, to catch recursion.
    inlining: Vec<FunctionId>,
}

impl Scope {
    /// Whose parameters a bare name in the statement may be: the innermost
    /// function's being inlined, else the service's.
    fn param_owner(&self) -> Option<ParamOwner> {
        match (self.inlining.last(), self.team, self.service) {
            (Some(&function), ..) => Some(ParamOwner::Function(function)),
            (None, Some(team), Some(service)) => Some(ParamOwner::Service(team, service)),
            _ => None,
        }
    }
}

/// A parameter: whose, and its place in the list.
pub(super) type ParamRef = (ParamOwner, u32);

/// What an attribute (`X`, `T.X`, `USER.X`) refers to, before reporting.
#[derive(Clone, Debug)]
enum Resolution {
    Value {
        owner: Option<TeamId>,
        name: Name,
        ty: ValueType,
    },
    /// A catalog value that some of the robots running the statement lack, or
    /// all of them (`none`).
    PartialValue {
        name: Name,
        team: Name,
        lacking: String,
        advice: String,
        none: bool,
    },
    Variable {
        team: Option<TeamId>,
        name: Name,
    },
    /// `T.X` where `T` is a team (or `USER`) without such a value or variable.
    NotInTeam {
        team: Name,
        name: Name,
        known: Vec<String>,
    },
    NotATeam {
        team: Name,
    },
    TooLong,
    /// A single name that is neither: a symbolic constant where one is allowed.
    /// `known`: where to look for the value or variable it may be a typo of
    /// (gathered only if it is reported: most bare names are fine constants).
    Bare {
        name: Name,
        known: Candidates,
        /// The function or service whose body is walked: its parameters are
        /// candidates too.
        function: Option<ParamOwner>,
    },
    /// Nothing can be said (no robot runs the statement).
    Unchecked,
    /// A parameter of the function (else the service) whose body is being
    /// walked.
    Parameter {
        param: ParamRef,
        name: Name,
    },
    /// A result name the function's (else the service's) body binds.
    Result {
        owner: ParamOwner,
        index: u32,
    },
}

/// A value read or sent by robots of which some lack it: E033 unless their
/// team receives it somewhere.
#[derive(Clone, Debug)]
pub(super) struct LackingValue {
    team: Name,
    name: Name,
    span: Span,
    message: String,
}

/// Where did-you-mean candidates for a bare name come from.
#[derive(Clone, Debug)]
enum Candidates {
    /// Every value of the catalog and every team variable.
    Everywhere,
    /// The values of these robot types and the variables of the team.
    Team(TeamId, TypeList),
}

/// The type of an expression, as far as the checker can tell.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Type {
    Text,
    Int,
    Float,
    Bool,
    Period,
    Value(ValueType),
    Constant(Name),
    Unknown,
    /// A parameter of the function (or service) being walked: whatever
    /// each call (`set`) gives (checked against the body's uses once every
    /// body is walked, `params.rs`). Compared as a team variable is.
    Param {
        param: ParamRef,
        name: Name,
    },
}

/// Whether `t` is surely a number (not what the checker cannot type).
fn known_number(t: &Type) -> bool {
    t.is_numeric() && !matches!(t, Type::Unknown | Type::Param { .. })
}

/// How a comparison of these two sides compares (see [`Compared`]).
fn compared(lt: &Type, rt: &Type, ordering: bool) -> Compared {
    let numbers =
        lt.is_numeric() && rt.is_numeric() && (known_number(lt) || known_number(rt) || ordering);
    if numbers {
        Compared::Numbers
    } else {
        Compared::Words
    }
}

impl Type {
    pub(super) fn describe(&self) -> String {
        match self {
            Type::Text => "a string".into(),
            Type::Int => "a whole number".into(),
            Type::Float => "a number".into(),
            Type::Bool => "true or false".into(),
            Type::Period => "a period".into(),
            Type::Value(t) => format!("a value of type {t}"),
            Type::Constant(c) => format!("the constant `{c}`"),
            Type::Unknown => "a value".into(),
            Type::Param { name, .. } => format!("the parameter `{name}`"),
        }
    }

    /// Whether `<`, `<=`, `>`, `>=` may order it: a number, a numeric value,
    /// a period, or what the checker cannot type (a team variable, or a name
    /// already reported).
    pub(super) fn is_numeric(&self) -> bool {
        matches!(
            self,
            Type::Int
                | Type::Float
                | Type::Period
                | Type::Unknown
                | Type::Param { .. }
                | Type::Value(ValueType::Int | ValueType::Float)
        )
    }

    /// Whether an argument of this type fits a parameter of type `param`.
    pub(super) fn fits(&self, param: &ValueType) -> bool {
        use ValueType as V;
        match (self, param) {
            // A parameter's argument is checked at each call (`params.rs`).
            (Type::Unknown | Type::Param { .. }, _) => true,
            (Type::Value(v), p) => match (v, p) {
                (a, b) if a.name() == b.name() => true,
                (V::Int, V::Float) => true,
                (V::String | V::Enum(_), V::String | V::Location | V::Enum(_)) => true,
                _ => false,
            },
            (Type::Int, V::Int | V::Float) | (Type::Float, V::Float) => true,
            (Type::Bool, V::Bool) => true,
            (Type::Text, V::String | V::Location) => true,
            (Type::Text | Type::Constant(_), V::Enum(domain)) => match self {
                Type::Constant(c) => domain.iter().any(|d| d == c),
                _ => true,
            },
            (Type::Constant(_), V::String | V::Location) => true,
            _ => false,
        }
    }
}

impl<'a> Checker<'a> {
    pub(super) fn check_bodies(&mut self) {
        self.team_types = (0..self.mission.teams.len())
            .map(|t| {
                let team = TeamId(t as u32);
                let all: Vec<RobotId> = self.team(team).robot_ids().collect();
                self.types_of(team, &all)
            })
            .collect();
        for t in 0..self.mission.teams.len() {
            let team = TeamId(t as u32);
            let all = self.shared_robots(self.team(team).robot_ids().collect());
            for s in 0..self.service_syntax[t].len() {
                let syntax = self.service_syntax[t][s];
                let scope = Scope {
                    team: Some(team),
                    service: Some(ServiceId::new(s)),
                    robots: all.clone(),
                    types: self.team_types[t].clone(),
                    inlining: Vec::new(),
                };
                let kind = ScopeKind::Service {
                    team,
                    service: ServiceId::new(s),
                };
                self.record_scope(syntax.span, kind, &scope);
                self.block(&syntax.body, &scope);
                if let Some(repeat) = &syntax.repeat {
                    if let Some(p) = &repeat.period {
                        self.period(p);
                    }
                    if let Some(c) = &repeat.condition {
                        self.condition(c, &scope);
                    }
                }
            }
        }
        // Rejected definitions: checked with their team's robots, but belonging
        // to no service (they send, receive and run nothing).
        for (team, body) in std::mem::take(&mut self.rejected_bodies) {
            let robots = match team {
                Some(t) => self.team(t).robot_ids().collect(),
                None => Vec::new(),
            };
            let robots = self.shared_robots(robots);
            let scope = Scope {
                team,
                service: None,
                types: team.map_or_else(|| Rc::from([]), |t| self.team_types[t.0 as usize].clone()),
                robots,
                inlining: Vec::new(),
            };
            self.record_scope(body.span, ScopeKind::Rejected, &scope);
            self.block(body, &scope);
        }
        self.report_lacking_values();
        self.finish_broadcasts();
        // Functions nobody calls are still checked, as far as possible without robots.
        for f in 0..self.function_syntax.len() {
            if !self.mission.functions[f].called {
                let scope = Scope {
                    team: None,
                    service: None,
                    robots: self.shared_robots(Vec::new()),
                    types: Rc::new([]),
                    inlining: vec![FunctionId(f as u32)],
                };
                let span = self.function_syntax[f].span;
                self.record_scope(span, ScopeKind::Function(FunctionId(f as u32)), &scope);
                self.block(&self.function_syntax[f].body, &scope);
            }
        }
    }

    /// E033 for the values some robots lack and their team does not receive.
    fn report_lacking_values(&mut self) {
        for lacking in std::mem::take(&mut self.lacking_values) {
            let key = (lacking.team.clone(), lacking.name.clone());
            if !self.received_values.contains(&key) {
                self.diagnostics
                    .report(Code::ValueNotProvided, lacking.span, lacking.message);
            }
        }
    }

    /// Records who runs the statements of `span` (for the IDE).
    fn record_scope(&mut self, span: Span, kind: ScopeKind, scope: &Scope) {
        let runners = Runners {
            team: scope.team,
            robots: scope.robots.0.clone(),
        };
        self.scope(span, kind, runners);
    }

    fn block(&mut self, block: &'a ast::Block, scope: &Scope) {
        for stmt in &block.stmts {
            self.stmt(stmt, scope);
        }
    }

    fn stmt(&mut self, stmt: &'a ast::Stmt, scope: &Scope) {
        match &stmt.kind {
            StmtKind::If(i) => {
                self.condition(&i.condition, scope);
                self.block(&i.then_block, scope);
                match i.else_branch.as_deref() {
                    Some(ast::Else::If(s)) => self.stmt(s, scope),
                    Some(ast::Else::Block(b)) => self.block(b, scope),
                    None => {}
                }
            }
            StmtKind::Loop(l) => {
                if let Some(p) = &l.period {
                    self.period(p);
                }
                if let Some(c) = &l.condition {
                    self.condition(c, scope);
                }
                self.block(&l.body, scope);
            }
            StmtKind::Group(g) => self.group(g, scope),
            StmtKind::Comm(c) => self.comm(c, scope),
            StmtKind::Throw(throw) => self.throw(throw, scope),
            StmtKind::Call(c) => self.call(c, scope),
            StmtKind::Error => {}
        }
    }

    pub(super) fn period(&mut self, period: &ast::Period) {
        if !period.millis().is_some_and(|ms| ms > 0.0) {
            self.diagnostics.report(
                Code::InvalidPeriod,
                period.span,
                "a period or timeout must be more than zero",
            );
        }
    }

    fn throw(&mut self, throw: &ast::Throw, scope: &Scope) {
        let Some(team) = scope.team else { return };
        let event = &throw.event;
        self.event_occurrence(team, event);
        if let Some(keyword) = throw.broadcast {
            self.broadcast(team, event, keyword, &scope.robots);
        }
        let t = self.team_mut(team);
        t.event_mut(&event.name).thrown_at.push(event.span);
        if let Some(service) = scope.service
            && self.thrown.insert((team, service, event.name.clone()))
        {
            self.team_mut(team).services[service.index()]
                .throws
                .push(event.name.clone());
        }
    }

    /// Records who a `throw E broadcast` goes to: the robots running it
    /// here, added to those of its other callers' walks.
    fn broadcast(&mut self, team: TeamId, event: &ast::Ident, keyword: Span, robots: &Robots) {
        if robots.is_empty() {
            return; // no robot runs it: it tells no one
        }
        match self.broadcast_index.get(&(team, event.span)) {
            Some(&i) => {
                let known = &self.team(team).broadcasts[i].receivers;
                if Arc::ptr_eq(known, &robots.0) {
                    return;
                }
                let mut all: Vec<RobotId> = known.iter().chain(robots.iter()).copied().collect();
                all.sort_unstable();
                all.dedup();
                let all = self.shared_robots(all).0;
                self.team_mut(team).broadcasts[i].receivers = all;
            }
            None => {
                let t = self.team_mut(team);
                t.broadcasts.push(Broadcast {
                    event: event.name.clone(),
                    span: event.span,
                    keyword,
                    receivers: robots.0.clone(),
                });
                let i = t.broadcasts.len() - 1;
                self.broadcast_index.insert((team, event.span), i);
            }
        }
    }

    /// Sorts each team's broadcasts by position (for `Team::broadcast_at`)
    /// and gives W013 on each that only one robot runs.
    fn finish_broadcasts(&mut self) {
        for t in 0..self.mission.teams.len() {
            let team = TeamId(t as u32);
            let mut broadcasts = std::mem::take(&mut self.team_mut(team).broadcasts);
            broadcasts.sort_by_key(|b| (b.span.start, b.span.end));
            for b in broadcasts.iter().filter(|b| b.receivers.len() == 1) {
                let t = self.team(team);
                let robot = &t.robots[b.receivers[0].index()].name;
                let message = if t.robots.len() == 1 {
                    format!(
                        "{robot} is the only robot of team {}: `broadcast` tells no one else",
                        t.name
                    )
                } else {
                    format!(
                        "only {robot} runs this `throw`: its group has no one else to tell, so `broadcast` changes nothing"
                    )
                };
                self.diagnostics
                    .report(Code::BroadcastToNoOne, b.keyword, message)
                    .severity = crate::diag::Severity::Hint;
            }
            self.team_mut(team).broadcasts = broadcasts;
        }
    }

    // ----- calls -----

    fn call(&mut self, call: &'a ast::Call, scope: &Scope) {
        if let Some(p) = &call.timeout {
            self.period(p);
        }
        if let Some(&function) = self.functions_by_name.get(&call.name.name) {
            self.occurrence(call.name.span, Symbol::Function(function), false);
            self.function_results(call);
            self.function_arguments(function, call, scope);
            if scope.inlining.contains(&function) {
                self.diagnostics.report(
                    Code::RecursiveFunction,
                    call.name.span,
                    format!(
                        "`{}` calls itself: functions are copied where they are called, so this would never end",
                        call.name.name
                    ),
                );
                return;
            }
            if scope.inlining.len() >= MAX_INLINING_DEPTH {
                self.diagnostics.report(
                    Code::RecursiveFunction,
                    call.name.span,
                    format!(
                        "functions call each other more than {MAX_INLINING_DEPTH} levels deep here"
                    ),
                );
                return;
            }
            if scope.team.is_some() {
                self.mission.functions[function.0 as usize].called = true;
            }
            let key = (function, scope.team, scope.service, scope.robots.clone());
            if !self.inlined.insert(key) {
                return;
            }
            let mut inner = scope.clone();
            inner.inlining.push(function);
            let syntax = self.function_syntax[function.0 as usize];
            self.record_scope(syntax.span, ScopeKind::Function(function), &inner);
            self.block(&syntax.body, &inner);
            return;
        }
        self.builtin_call(call, scope);
    }

    /// The arguments of a call of `function`, typed in the caller's scope
    /// and recorded for the check against the body's uses (`params.rs`);
    /// E022 when there are more or fewer than its parameters.
    fn function_arguments(&mut self, function: FunctionId, call: &ast::Call, scope: &Scope) {
        let params = &self.mission.functions[function.0 as usize].params;
        let (given, takes) = (call.args.len(), params.len());
        if given != takes {
            let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
            let expected = match takes {
                0 => "no arguments".to_string(),
                1 => format!("1 argument ({})", names.join(", ")),
                n => format!("{n} arguments ({})", names.join(", ")),
            };
            self.diagnostics.report(
                Code::WrongArgumentCount,
                call.args_span,
                format!(
                    "the function `{}` takes {expected}, but {given} {} given",
                    call.name.name,
                    if given == 1 { "is" } else { "are" },
                ),
            );
            // What this call gives them is not known (value flow).
            for index in 0..takes {
                let param = (ParamOwner::Function(function), index as u32);
                self.param_uses.unfixed(param, call.args_span);
            }
        }
        for (index, arg) in call.args.iter().enumerate() {
            let ty = match arg {
                Arg::Words { .. } => Type::Text,
                Arg::Expr(e) => self.expr(e, scope, true),
            };
            if index < takes {
                let callee = (ParamOwner::Function(function), index as u32);
                let literal = argument_literal(arg, &ty);
                self.param_uses.argument(callee, ty, arg.span(), literal);
            }
        }
    }

    /// The same scope, run by fewer robots (inside a group).
    fn narrowed(&mut self, scope: &Scope, robots: Vec<RobotId>) -> Scope {
        let types = match scope.team {
            Some(team) => self.types_of(team, &robots),
            None => Rc::new([]),
        };
        Scope {
            robots: self.shared_robots(robots),
            types,
            ..scope.clone()
        }
    }

    /// `robots` as the one shared list of that set: equal sets are one
    /// list, so that a scope's robots are compared and hashed by identity.
    fn shared_robots(&mut self, robots: Vec<RobotId>) -> Robots {
        let robots: Arc<[RobotId]> = robots.into();
        match self.robot_sets.get(&robots) {
            Some(shared) => Robots(shared.clone()),
            None => {
                self.robot_sets.insert(robots.clone());
                Robots(robots)
            }
        }
    }

    /// The known robot types among `robots` of `team`, each with its robots' names.
    fn types_of(&self, team: TeamId, robots: &[RobotId]) -> TypeList {
        let mut types: Vec<(RobotTypeId, Vec<Name>)> = Vec::new();
        let t = self.team(team);
        for &r in robots {
            let robot = &t.robots[r.index()];
            let Some(ty) = robot.robot_type else { continue };
            match types.iter_mut().find(|(id, _)| *id == ty) {
                Some((_, names)) => names.push(robot.name.clone()),
                None => types.push((ty, vec![robot.name.clone()])),
            }
        }
        types.into()
    }

    fn describe_types<'t>(
        &self,
        types: impl IntoIterator<Item = &'t (RobotTypeId, Vec<Name>)>,
    ) -> String {
        let parts: Vec<String> = types
            .into_iter()
            .map(|(ty, names)| {
                let names = some_names(names.iter().map(Name::as_str), names.len());
                format!("{} ({names})", self.catalog.get(*ty).name)
            })
            .collect();
        parts.join(", ")
    }

    fn builtin_call(&mut self, call: &ast::Call, scope: &Scope) {
        let name = &call.name.name;
        let catalog = self.catalog;
        let anywhere = catalog.types().find_map(|(_, r)| r.service(name));
        let types = scope.types.clone();
        let mut providing = types
            .iter()
            .filter_map(|(ty, _)| catalog.get(*ty).service(name));
        let first_provider = providing.next();
        let providers = first_provider.map_or(0, |_| 1 + providing.count());
        let Some(any_def) = anywhere else {
            let mut candidates: Vec<&str> =
                self.functions_by_name.keys().map(Name::as_str).collect();
            if types.is_empty() {
                candidates.extend(
                    catalog
                        .types()
                        .flat_map(|(_, r)| r.services.iter().map(|s| s.name.as_str())),
                );
            } else {
                candidates.extend(
                    types.iter().flat_map(|(ty, _)| {
                        catalog.get(*ty).services.iter().map(|s| s.name.as_str())
                    }),
                );
            }
            let guess = suggestion(name, candidates);
            self.diagnostics
                .report(
                    Code::UnknownService,
                    call.name.span,
                    format!("`{name}` is neither a robot service nor a function"),
                )
                .suggest(guess);
            return;
        };
        let def = first_provider.unwrap_or(any_def);
        self.occurrence(
            call.name.span,
            Symbol::BuiltinService(Name::new(&def.name)),
            false,
        );
        if providers < types.len() {
            let lacking: Vec<&(RobotTypeId, Vec<Name>)> = types
                .iter()
                .filter(|(ty, _)| catalog.get(*ty).service(name).is_none())
                .collect();
            let having: Vec<&str> = catalog
                .types()
                .filter(|(_, r)| r.service(name).is_some())
                .map(|(_, r)| r.name.as_str())
                .collect();
            let team = scope
                .team
                .map(|t| self.team(t).name.clone())
                .unwrap_or_default();
            let advice = if providers == 0 {
                format!(
                    "only {} {} it",
                    having.join(", "),
                    if having.len() == 1 {
                        "provides"
                    } else {
                        "provide"
                    }
                )
            } else {
                let types: Vec<&str> = types
                    .iter()
                    .filter(|(ty, _)| catalog.get(*ty).service(name).is_some())
                    .map(|(ty, _)| catalog.get(*ty).name.as_str())
                    .collect();
                format!(
                    "put the call inside `group(instance of {})`",
                    types.join(", ")
                )
            };
            let message = format!(
                "`{name}` is not a service of {} in team {team}; {advice}",
                self.describe_types(lacking)
            );
            self.diagnostics
                .report(Code::ServiceNotProvided, call.name.span, message);
        }
        self.arguments(call, def, scope);
        let providers: Vec<(Name, &ServiceDef)> = types
            .iter()
            .filter_map(|(ty, _)| {
                let robot_type = catalog.get(*ty);
                robot_type
                    .service(name)
                    .map(|d| (Name::new(&robot_type.name), d))
            })
            .collect();
        self.service_results(call, def, &providers, scope.param_owner());
    }

    fn arguments(&mut self, call: &ast::Call, def: &ServiceDef, scope: &Scope) {
        let given = call.args.len();
        let (min, max) = (def.required_params(), def.params.len());
        if given < min || given > max {
            let expected = match (min, max) {
                (0, 0) => "no arguments".to_string(),
                (a, b) if a == b => format!("{a} argument{}", if a == 1 { "" } else { "s" }),
                (0, b) => format!("at most {b} argument{}", if b == 1 { "" } else { "s" }),
                (a, b) => format!("{a} to {b} arguments"),
            };
            self.diagnostics.report(
                Code::WrongArgumentCount,
                call.args_span,
                format!(
                    "`{}` takes {expected}, but {given} {} given: {}",
                    call.name.name,
                    if given == 1 { "is" } else { "are" },
                    def.signature()
                ),
            );
        }
        for (arg, param) in call.args.iter().zip(&def.params) {
            let ty = match arg {
                Arg::Words { .. } => Type::Text,
                Arg::Expr(e) => self.expr(e, scope, true),
            };
            if let Type::Param { param: used, .. } = &ty {
                let kind = NeedKind::Argument {
                    service: Name::new(&def.name),
                    param: Name::new(&param.name),
                    ty: param.ty.clone(),
                };
                let need = ParamNeed {
                    kind,
                    span: arg.span(),
                };
                self.param_uses.need(*used, need);
            }
            if !ty.fits(&param.ty) {
                self.diagnostics.report(
                    Code::WrongArgumentType,
                    arg.span(),
                    format!(
                        "`{}` expects {} for `{}`, but this is {}",
                        call.name.name,
                        describe_param(&param.ty),
                        param.name,
                        ty.describe()
                    ),
                );
            }
        }
        // Extra arguments are still resolved, so their names are checked.
        for arg in call.args.iter().skip(def.params.len()) {
            if let Arg::Expr(e) = arg {
                self.expr(e, scope, true);
            }
        }
    }

    // ----- expressions and attributes -----

    fn condition(&mut self, e: &Expr, scope: &Scope) {
        self.expr(e, scope, false);
    }

    /// Checks an expression and gives its type. `bare_is_constant`: a single
    /// unknown name is a symbolic constant here (arguments, right of `==`).
    fn expr(&mut self, e: &Expr, scope: &Scope, bare_is_constant: bool) -> Type {
        match &e.kind {
            ExprKind::Or(a, b) | ExprKind::And(a, b) => {
                self.condition(a, scope);
                self.condition(b, scope);
                Type::Bool
            }
            ExprKind::Not(a) => {
                self.condition(a, scope);
                Type::Bool
            }
            ExprKind::Compare(lhs, op, rhs) => {
                self.compare(e.span, lhs, *op, rhs, scope);
                Type::Bool
            }
            ExprKind::Str(_) => Type::Text,
            ExprKind::Number(n) if n.contains('.') => Type::Float,
            ExprKind::Number(_) => Type::Int,
            ExprKind::Period(p) => {
                self.period(p);
                Type::Period
            }
            ExprKind::Bool(_) => Type::Bool,
            ExprKind::Attr(attr) => {
                let resolution = self.resolve_attr(attr, scope);
                if bare_is_constant {
                    self.word_or_value(attr, &resolution);
                }
                self.record_attr(attr, resolution, bare_is_constant)
            }
            ExprKind::Error => Type::Unknown,
        }
    }

    /// E041: a bare name where a word may stand (an argument, a value sent,
    /// the other side of `==`) that is also a value the robots running the
    /// statement read. The reading would win without a word said, and the
    /// user may well have meant the word (`publish(T, T.Alarm = FIRE)` with a
    /// `FIRE` sensor): each meaning has its own spelling, `"FIRE"` and
    /// `T.FIRE`, and the checker asks for one.
    fn word_or_value(&mut self, attr: &ast::Attr, resolution: &Resolution) {
        let [word] = attr.segments.as_slice() else {
            return;
        };
        let team = match resolution {
            Resolution::Value {
                owner: Some(team), ..
            } => self.team(*team).name.clone(),
            Resolution::PartialValue {
                team, none: false, ..
            } => team.clone(),
            _ => return,
        };
        let word = &word.name;
        self.diagnostics.report(
            Code::WordIsAValue,
            attr.span,
            format!(
                "`{word}` is both a word and the value `{word}` of team {team}'s robots: write `\"{word}\"` for the word or `{team}.{word}` for the value"
            ),
        );
    }

    fn compare(&mut self, span: Span, lhs: &Expr, op: ast::CmpOp, rhs: &Expr, scope: &Scope) {
        // A bare unknown name is a constant on the right, and on the left when the
        // right is a known value (`DARK == Guards.Alarm`); against a literal it is
        // a misspelt value (`LIGHTNES < 200`).
        let rhs_known = match &rhs.kind {
            ExprKind::Attr(a) => !matches!(
                self.resolve_attr(a, scope),
                Resolution::Bare { .. } | Resolution::PartialValue { none: true, .. }
            ),
            _ => false,
        };
        let lt = self.expr(lhs, scope, rhs_known);
        let rt = self.expr(rhs, scope, true);
        let ordering = matches!(
            op,
            ast::CmpOp::Lt | ast::CmpOp::Le | ast::CmpOp::Gt | ast::CmpOp::Ge
        );
        let how = compared(&lt, &rt, ordering);
        self.comparison(span, how);
        // A parameter compared with a number, or ordered, compares as a
        // number: each call's argument must be one, so that the comparison
        // means what it would with the argument written in its place.
        for (side, other, side_span) in [(&lt, &rt, lhs.span), (&rt, &lt, rhs.span)] {
            if let Type::Param { param, .. } = side {
                if ordering || known_number(other) {
                    let need = ParamNeed {
                        kind: NeedKind::Number,
                        span: side_span,
                    };
                    self.param_uses.need(*param, need);
                }
            }
        }
        if matches!(op, ast::CmpOp::Eq | ast::CmpOp::Ne) {
            let sides = [(lhs, (rhs, &rt)), (rhs, (lhs, &lt))];
            for (variable, (other, other_type)) in sides {
                let constant = literal(other, other_type).map(|c| (c, other.span));
                self.record_variable_test(variable, constant, op, how, scope);
            }
            // `PARAM == C`: what its arguments give decides it (`values`).
            for (side, other, other_type) in [(&lt, rhs, &rt), (&rt, lhs, &lt)] {
                if let Type::Param { param, name } = side
                    && let Some(constant) = literal(other, other_type)
                {
                    self.parameter_tests.push(ParameterTest {
                        param: *param,
                        name: name.clone(),
                        equal: op == ast::CmpOp::Eq,
                        constant,
                        compared: how,
                        span: other.span,
                    });
                }
            }
        }
        if ordering {
            for (ty, side) in [(&lt, lhs), (&rt, rhs)] {
                if !ty.is_numeric() {
                    self.diagnostics.report(
                        Code::OrderingNotNumeric,
                        side.span,
                        format!(
                            "`{}` orders numbers, but this is {}: compare it with `==` or `!=`, or compare a numeric value",
                            op.as_str(),
                            ty.describe()
                        ),
                    );
                }
            }
        }
        for (value, value_expr, other, other_span) in
            [(&lt, lhs, &rt, rhs.span), (&rt, rhs, &lt, lhs.span)]
        {
            let Type::Value(ValueType::Enum(domain)) = value else {
                continue;
            };
            let what = match &value_expr.kind {
                ExprKind::Attr(a) => format!("`{}`", a.dotted()),
                _ => "this value".to_string(),
            };
            let written = match (other, other_side_text(other_span, lhs, rhs)) {
                (Type::Constant(c), _) => Some(c.to_string()),
                (Type::Text, Some(s)) => Some(s),
                _ => None,
            };
            if let Some(c) = written.filter(|c| !domain.contains(c)) {
                let guess = suggestion(&c, domain.iter().map(String::as_str));
                self.diagnostics
                    .report(
                        Code::ConstantOutsideDomain,
                        other_span,
                        format!(
                            "`{c}` is not a possible value of {what}, which is one of {}",
                            domain.join(", ")
                        ),
                    )
                    .suggest(guess);
            }
        }
    }

    /// Records `T.X == C` or `T.X != C` for the value flow (`values.rs`):
    /// `variable` a team variable, `constant` the literal on the other side
    /// and its range.
    fn record_variable_test(
        &mut self,
        variable: &Expr,
        constant: Option<(Literal, Span)>,
        op: ast::CmpOp,
        compared: Compared,
        scope: &Scope,
    ) {
        let (ExprKind::Attr(attr), Some((constant, span))) = (&variable.kind, constant) else {
            return;
        };
        let Resolution::Variable {
            team: Some(team),
            name,
        } = self.resolve_attr(attr, scope)
        else {
            return;
        };
        let key = AttrKey {
            owner: self.team(team).name.clone(),
            name,
        };
        self.variable_tests.push(VariableTest {
            key,
            equal: op == ast::CmpOp::Eq,
            constant,
            compared,
            span,
        });
    }

    /// The robot types whose values `T.X` (or bare `X`) reads: those running
    /// the statement for its own team, all of the team's otherwise.
    fn types_for(&self, team: TeamId, scope: &Scope) -> TypeList {
        if scope.team == Some(team) {
            scope.types.clone()
        } else {
            self.team_types[team.0 as usize].clone()
        }
    }

    fn resolve_attr(&self, attr: &ast::Attr, scope: &Scope) -> Resolution {
        if let ([name], Some(owner)) = (attr.segments.as_slice(), scope.param_owner()) {
            let params = self.mission.params(owner);
            if let Some(index) = params.iter().position(|p| p.name == name.name) {
                return Resolution::Parameter {
                    param: (owner, index as u32),
                    name: name.name.clone(),
                };
            }
            if let Some(index) = self.result_of(owner, &name.name) {
                return Resolution::Result { owner, index };
            }
        }
        match attr.segments.as_slice() {
            [name] => match scope.team {
                Some(team) => self.resolve_in_team(team, &name.name, scope, true),
                None => {
                    let is_value = self
                        .catalog
                        .types()
                        .any(|(_, r)| r.value(&name.name).is_some());
                    let is_variable = self.variables.contains_key(&name.name);
                    if is_value || is_variable {
                        Resolution::Unchecked
                    } else {
                        Resolution::Bare {
                            name: name.name.clone(),
                            known: Candidates::Everywhere,
                            function: scope.param_owner(),
                        }
                    }
                }
            },
            [team, name] if is_user(&team.name) => {
                match self.catalog.user().and_then(|u| u.value(&name.name)) {
                    Some(v) => Resolution::Value {
                        owner: None,
                        name: Name::new(&v.name),
                        ty: v.ty.clone(),
                    },
                    None => Resolution::NotInTeam {
                        team: "USER".into(),
                        name: name.name.clone(),
                        known: self
                            .catalog
                            .user()
                            .map(|u| u.values.iter().map(|v| v.name.clone()).collect())
                            .unwrap_or_default(),
                    },
                }
            }
            [team, name] => match self.team_id(&team.name) {
                Some(t) => self.resolve_in_team(t, &name.name, scope, false),
                None => Resolution::NotATeam {
                    team: team.name.clone(),
                },
            },
            _ => Resolution::TooLong,
        }
    }

    fn resolve_in_team(&self, team: TeamId, name: &str, scope: &Scope, bare: bool) -> Resolution {
        let types = self.types_for(team, scope);
        let catalog = self.catalog;
        let mut defs = types
            .iter()
            .filter_map(|(ty, _)| catalog.get(*ty).value(name));
        let first = defs.next();
        // Robots read their own values; another team's value is what its robots
        // that have it send or publish, so only its own team must all have it.
        let own = scope.team == Some(team);
        if let Some(def) = first {
            if own && 1 + defs.count() < types.len() {
                let having: Vec<&str> = types
                    .iter()
                    .filter(|(ty, _)| catalog.get(*ty).value(name).is_some())
                    .map(|(ty, _)| catalog.get(*ty).name.as_str())
                    .collect();
                return self.partial_value(
                    team,
                    &def.name,
                    &types,
                    format!("read it inside `group(instance of {})`", having.join(", ")),
                    false,
                );
            }
            return Resolution::Value {
                owner: Some(team),
                name: Name::new(&def.name),
                ty: def.ty.clone(),
            };
        }
        if self.is_variable(team, name) {
            return Resolution::Variable {
                team: Some(team),
                name: Name::new(name),
            };
        }
        if types.is_empty() {
            return Resolution::Unchecked;
        }
        let having: Vec<(&str, &str)> = catalog
            .types()
            .filter_map(|(_, r)| r.value(name).map(|v| (r.name.as_str(), v.name.as_str())))
            .collect();
        if own {
            if let Some(&(_, value)) = having.first() {
                let types_having: Vec<&str> = having.iter().map(|(t, _)| *t).collect();
                let advice = format!(
                    "only {} {} it",
                    types_having.join(", "),
                    if types_having.len() == 1 {
                        "has"
                    } else {
                        "have"
                    }
                );
                return self.partial_value(team, value, &types, advice, true);
            }
        }
        if bare {
            return Resolution::Bare {
                name: Name::new(name),
                known: Candidates::Team(team, types),
                function: scope.param_owner(),
            };
        }
        Resolution::NotInTeam {
            team: self.team(team).name.clone(),
            name: Name::new(name),
            known: self.candidate_names(&Candidates::Team(team, types)),
        }
    }

    fn candidate_names(&self, candidates: &Candidates) -> Vec<String> {
        let catalog = self.catalog;
        match candidates {
            Candidates::Everywhere => catalog
                .types()
                .flat_map(|(_, r)| r.values.iter().map(|v| v.name.clone()))
                .chain(self.variables.keys().map(Name::to_string))
                .collect(),
            Candidates::Team(team, types) => types
                .iter()
                .flat_map(|(ty, _)| catalog.get(*ty).values.iter().map(|v| v.name.clone()))
                .chain(self.team(*team).variables.iter().map(Name::to_string))
                .collect(),
        }
    }

    /// A value that the robots `lacking` (among those running the statement) do
    /// not have.
    fn partial_value(
        &self,
        team: TeamId,
        name: &str,
        types: &[(RobotTypeId, Vec<Name>)],
        advice: String,
        none: bool,
    ) -> Resolution {
        let lacking = types
            .iter()
            .filter(|(ty, _)| self.catalog.get(*ty).value(name).is_none());
        Resolution::PartialValue {
            name: Name::new(name),
            team: self.team(team).name.clone(),
            lacking: self.describe_types(lacking),
            advice,
            none,
        }
    }

    /// Reports what a resolution says is wrong, records the occurrence, and gives
    /// the attribute's type.
    fn record_attr(
        &mut self,
        attr: &ast::Attr,
        resolution: Resolution,
        bare_is_constant: bool,
    ) -> Type {
        let last = attr.last().span;
        if let [team, _] = attr.segments.as_slice() {
            if is_user(&team.name) {
                self.occurrence(team.span, Symbol::User, false);
            } else if let Some(t) = self.team_id(&team.name) {
                self.occurrence(team.span, Symbol::Team(t), false);
            }
        }
        match resolution {
            Resolution::Value { owner, name, ty } => {
                self.occurrence(last, Symbol::Value { owner, name }, false);
                Type::Value(ty)
            }
            Resolution::Variable { team, name } => {
                self.occurrence(last, Symbol::TeamVariable { team, name }, false);
                Type::Unknown
            }
            // A name that no robot running the statement has, where a constant
            // may stand: the constant (`follow(obstacle)` for a camera robot).
            Resolution::PartialValue { none: true, .. }
                if bare_is_constant && attr.segments.len() == 1 =>
            {
                let name = attr.last().name.clone();
                self.occurrence(last, Symbol::Constant(name.clone()), false);
                Type::Constant(name)
            }
            Resolution::PartialValue {
                name,
                team,
                lacking,
                advice,
                ..
            } => {
                // Robots read (or send) a value they lack only if their team
                // receives it: decided once every body is checked.
                let owner = self.team_id(&team);
                let ty = self.catalog_value_type(&name);
                self.occurrence(
                    last,
                    Symbol::Value {
                        owner,
                        name: name.clone(),
                    },
                    false,
                );
                let message = format!(
                    "`{name}` is not a value of {lacking} in team {team}; {advice}, or receive it"
                );
                self.lacking_values.push(LackingValue {
                    team,
                    name,
                    span: attr.span,
                    message,
                });
                ty.map_or(Type::Unknown, Type::Value)
            }
            Resolution::NotInTeam { team, name, known } => {
                let guess = suggestion(&name, known.iter().map(String::as_str));
                let message = if is_user(&team) {
                    let has = match known.is_empty() {
                        true => "no values".to_string(),
                        false => known.join(", "),
                    };
                    format!(
                        "`{team}.{name}` is not a value of the operator's console, which has {has}"
                    )
                } else {
                    format!(
                        "`{team}.{name}` is neither a value of the robots of team {team} nor a team variable that is sent, published or received"
                    )
                };
                self.diagnostics
                    .report(Code::UnknownAttribute, attr.span, message)
                    .suggest(guess.map(|g| format!("{team}.{g}")));
                // What it means all the same (a warning lets the mission
                // build): a team variable nobody sets, which stays empty.
                let owner = self.team_id(&team);
                self.occurrence(last, Symbol::TeamVariable { team: owner, name }, false);
                Type::Unknown
            }
            Resolution::NotATeam { team } => {
                let guess = suggestion(&team, self.team_names().iter().map(String::as_str));
                self.diagnostics
                    .report(
                        Code::UnknownAttribute,
                        attr.span,
                        format!("`{}`: `{team}` is not a team", attr.dotted()),
                    )
                    .suggest(guess);
                // What it means all the same: the words as written.
                self.occurrence(last, Symbol::Constant(Name::new(attr.dotted())), false);
                Type::Unknown
            }
            Resolution::TooLong => {
                self.diagnostics.report(
                    Code::UnknownAttribute,
                    attr.span,
                    format!(
                        "`{}` is not a value: write `Team.VALUE` or `VALUE`",
                        attr.dotted()
                    ),
                );
                self.occurrence(last, Symbol::Constant(Name::new(attr.dotted())), false);
                Type::Unknown
            }
            Resolution::Bare { name, .. } if bare_is_constant => {
                self.occurrence(last, Symbol::Constant(name.clone()), false);
                Type::Constant(name)
            }
            Resolution::Bare {
                name,
                known,
                function,
            } => {
                let mut known = self.candidate_names(&known);
                if let Some(owner) = function {
                    let params = self.mission.params(owner);
                    known.extend(params.iter().map(|p| p.name.to_string()));
                    let results = self.mission.results(owner);
                    known.extend(results.iter().map(|r| r.name.to_string()));
                }
                let guess = suggestion(&name, known.iter().map(String::as_str));
                self.diagnostics.report(
                    Code::UnknownAttribute,
                    attr.span,
                    format!(
                        "`{name}` is neither a value of the robots running this statement nor a team variable"
                    ),
                )
                .suggest(guess);
                // What it means all the same: a symbolic constant.
                self.occurrence(last, Symbol::Constant(name), false);
                Type::Unknown
            }
            Resolution::Unchecked => Type::Unknown,
            Resolution::Result { owner, index } => {
                let result = &self.mission.results(owner)[index as usize];
                let (bound, ty) = (result.span, result.ty.clone());
                if attr.span.start < bound.start {
                    self.diagnostics
                        .report(
                            Code::ResultReadBeforeBound,
                            attr.span,
                            format!(
                                "`{}` is read before any call binds it: it is none until the call below is done",
                                result.name
                            ),
                        )
                        .relate(bound, "bound here");
                }
                self.occurrence(last, Symbol::Result { owner, index }, false);
                ty.map_or(Type::Unknown, Type::Value)
            }
            Resolution::Parameter { param, name } => {
                self.param_uses.used(param);
                let (owner, index) = param;
                self.occurrence(last, Symbol::Parameter { owner, index }, false);
                Type::Param { param, name }
            }
        }
    }

    /// The type of a catalog value, from the first robot type that has it.
    fn catalog_value_type(&self, name: &str) -> Option<ValueType> {
        self.catalog
            .types()
            .find_map(|(_, r)| r.value(name).map(|v| v.ty.clone()))
    }

    // ----- groups -----

    /// The robots of `scope` that meet a group condition, and whether every name
    /// in the condition is known (an unknown one is reported here).
    fn group_members(&mut self, cond: &ast::GroupCond, scope: &Scope) -> (Vec<RobotId>, bool) {
        let catalog = self.catalog;
        let mut types = Vec::new();
        let mut all_known = true;
        for name in &cond.names {
            match cond.kind {
                CondKind::InstanceOf => match self.resolve_robot_type(name) {
                    Some(ty) => types.push(ty),
                    None => all_known = false,
                },
                // Every robot may be given a counted group (its name is no
                // type or capability to look up).
                CondKind::Counted => {}
                CondKind::CapableOf => {
                    let known = catalog.types().any(|(_, r)| r.has_capability(&name.name));
                    if known {
                        self.occurrence(name.span, Symbol::Capability(name.name.clone()), false);
                    } else {
                        all_known = false;
                        let all: Vec<&str> = catalog
                            .types()
                            .flat_map(|(_, r)| r.capabilities.iter().map(String::as_str))
                            .collect();
                        let guess = suggestion(&name.name, all);
                        self.diagnostics
                            .report(
                                Code::UnsatisfiableGroup,
                                name.span,
                                format!("no robot type has the capability `{}`", name.name),
                            )
                            .suggest(guess);
                    }
                }
            }
        }
        let Some(team) = scope.team else {
            return (Vec::new(), all_known);
        };
        let t = self.team(team);
        let members = scope
            .robots
            .iter()
            .copied()
            .filter(|&r| {
                let Some(ty) = t.robots[r.index()].robot_type else {
                    return false;
                };
                match cond.kind {
                    CondKind::InstanceOf => types.contains(&ty),
                    CondKind::CapableOf => cond
                        .names
                        .iter()
                        .all(|c| catalog.get(ty).has_capability(&c.name)),
                    CondKind::Counted => true,
                }
            })
            .collect();
        (members, all_known)
    }

    fn group(&mut self, g: &'a ast::GroupStmt, scope: &Scope) {
        // A condition that did not parse (reported by the parser) is empty.
        let broken = |arm: &ast::GroupArm| {
            arm.condition.kind == CondKind::Counted && arm.condition.names.is_empty()
        };
        let counted = |arm: &ast::GroupArm| arm.condition.counted_name().is_some();
        if g.arms.iter().any(counted) {
            let pure = g
                .arms
                .iter()
                .all(|a| (counted(a) || broken(a)) && a.kind == ArmKind::Group);
            if pure {
                return self.counted_group(g, scope);
            }
            // Mixed: checked as the arms are written (a counted condition
            // meets every robot), after saying what is wrong.
            for arm in g.arms.iter().filter(|a| !broken(a)) {
                let message = match (arm.kind, counted(arm)) {
                    (ArmKind::Leader, true) => {
                        "a `leader` arm takes `instance of` or `capable of`, not a count"
                    }
                    (ArmKind::Leader, false) => {
                        "a `leader` arm cannot share a statement with counted groups: write the election in its own `[[ ... ]]`"
                    }
                    (ArmKind::Group, false) => {
                        "a group by type or capability cannot share a statement with counted groups: split the robots first, then count them inside an arm"
                    }
                    (ArmKind::Group, true) => continue,
                };
                self.diagnostics
                    .report(Code::CountedGroupMixed, arm.condition.span, message);
            }
        }
        // Per robot of the team, whether an earlier arm took it.
        let robot_count = scope.team.map_or(0, |t| self.team(t).robots.len());
        let mut taken = vec![false; robot_count];
        let is_taken = |taken: &[bool], r: &RobotId| taken.get(r.index()).copied().unwrap_or(false);
        let checkable = scope.team.is_some() && !scope.robots.is_empty();
        for arm in &g.arms {
            let (members, all_known) = self.group_members(&arm.condition, scope);
            // An unknown type or capability is reported on its own name.
            if checkable && all_known && members.is_empty() {
                let team = scope
                    .team
                    .map(|t| self.team(t).name.clone())
                    .unwrap_or_default();
                let what = match arm.condition.kind {
                    CondKind::InstanceOf => "is an instance of",
                    CondKind::CapableOf => "is capable of",
                    CondKind::Counted => "may join",
                };
                let names: Vec<&str> = arm.condition.names.iter().map(|n| n.as_str()).collect();
                self.diagnostics.report(
                    Code::UnsatisfiableGroup,
                    arm.condition.span,
                    format!(
                        "no robot of team {team} that runs this statement {what} {}",
                        names.join(", ")
                    ),
                );
            }
            let overlap: Vec<RobotId> = members
                .iter()
                .copied()
                .filter(|r| is_taken(&taken, r))
                .collect();
            // A counted arm here is already an error (E043).
            if arm.kind == ArmKind::Group && !overlap.is_empty() && !counted(arm) && !broken(arm) {
                let names = self.robot_names(scope, &overlap);
                self.diagnostics.report(
                    Code::AmbiguousGroup,
                    arm.condition.span,
                    format!(
                        "{names} also meet{} an earlier group's condition and will join that group only",
                        if overlap.len() == 1 { "s" } else { "" }
                    ),
                );
            }
            let runners: Vec<RobotId> = match arm.kind {
                ArmKind::Group => members
                    .iter()
                    .copied()
                    .filter(|r| !is_taken(&taken, r))
                    .collect(),
                ArmKind::Leader => members.clone(),
            };
            let runners = if runners.is_empty() {
                members.clone()
            } else {
                runners
            };
            let inner = self.narrowed(scope, runners);
            let kind = ScopeKind::Arm {
                kind: arm.kind,
                condition: arm.condition.span,
            };
            self.record_scope(arm.body.span, kind, &inner);
            self.block(&arm.body, &inner);
            // A leader is one robot among the members: the others may still run
            // `others`, unless the leader is the only candidate.
            if arm.kind == ArmKind::Group || members.len() == 1 {
                for r in members {
                    taken[r.index()] = true;
                }
            }
        }
        if let Some(others) = &g.others {
            let rest: Vec<RobotId> = scope
                .robots
                .iter()
                .copied()
                .filter(|r| !is_taken(&taken, r))
                .collect();
            if checkable && rest.is_empty() {
                self.diagnostics.report(
                    Code::EmptyOthers,
                    others.keyword_span,
                    "every robot already belongs to a group above: no robot runs `others`",
                );
            }
            let inner = self.narrowed(scope, rest);
            let kind = ScopeKind::Others {
                keyword: others.keyword_span,
            };
            self.record_scope(others.body.span, kind, &inner);
            self.block(&others.body, &inner);
        }
    }

    /// A statement of counted groups (`group(Name, min = N)` arms only): every
    /// robot that runs the statement may be given any group at run time, so
    /// each arm, and `others` (the spares beyond the minimums), is checked
    /// against all of them. Names are unique in the statement; the minimums
    /// are positive whole numbers whose sum the robots can meet.
    fn counted_group(&mut self, g: &'a ast::GroupStmt, scope: &Scope) {
        let checkable = scope.team.is_some() && !scope.robots.is_empty();
        // By name: a statement of thousands of arms stays linear.
        let mut first_named: FastMap<&str, Span> = FastMap::default();
        let mut sum: u64 = 0;
        let mut all_valid = true;
        let mut over_at = None;
        let robots = scope.robots.len() as u64;
        for arm in &g.arms {
            let cond = &arm.condition;
            if let Some(name) = cond.counted_name() {
                match first_named.get(name.as_str()) {
                    Some(&first) => {
                        self.diagnostics
                            .report(
                                Code::DuplicateCountedGroup,
                                name.span,
                                format!("a second group named `{}` in this statement", name.name),
                            )
                            .relate(first, "first named here");
                    }
                    None => {
                        first_named.insert(name.as_str(), name.span);
                    }
                }
            }
            if let (Some(team), Some(name), Some(min)) =
                (scope.team, cond.counted_name(), &cond.min)
            {
                let symbol = Symbol::CountedGroup {
                    team,
                    name: name.name.clone(),
                    min: min.count.value.unwrap_or(0),
                    robots: robots as u32,
                };
                self.occurrence(name.span, symbol, true);
            }
            if let Some(min) = &cond.min {
                match min.count.value {
                    Some(n) if n > 0 => {
                        sum += u64::from(n);
                        if sum > robots && over_at.is_none() {
                            over_at = Some(min.count.span);
                        }
                    }
                    _ => {
                        all_valid = false;
                        self.diagnostics.report(
                            Code::CountedGroupMin,
                            min.count.span,
                            "a group's `min` is a positive whole number of robots",
                        );
                    }
                }
            }
            let inner = scope.clone();
            let kind = ScopeKind::Arm {
                kind: arm.kind,
                condition: cond.span,
            };
            self.record_scope(arm.body.span, kind, &inner);
            self.block(&arm.body, &inner);
        }
        let team = scope
            .team
            .map(|t| self.team(t).name.to_string())
            .unwrap_or_default();
        let mins: Vec<Span> = g
            .arms
            .iter()
            .filter_map(|a| a.condition.min.as_ref().map(|m| m.count.span))
            .collect();
        if checkable && all_valid {
            if let Some(at) = over_at {
                let names = self.robot_names(scope, &scope.robots);
                let diagnostic = self.diagnostics.report(
                    Code::CountedGroupsTooLarge,
                    at,
                    format!(
                        "the groups' minimums add up to {sum}, but only {robots} robot{} of team {team} run{} this statement ({names}): they can never all be met",
                        if robots == 1 { "" } else { "s" },
                        if robots == 1 { "s" } else { "" },
                    ),
                );
                for &span in mins.iter().filter(|&&s| s != at) {
                    diagnostic.relate(span, "a minimum counted in the sum");
                }
            } else if sum == robots
                && g.others.is_none()
                && let Some(&last) = mins.last()
            {
                self.diagnostics.report(
                    Code::CountedGroupsNoSpare,
                    last,
                    format!(
                        "the groups' minimums take all {robots} robots of team {team} that run this statement: a robot lost leaves a group short"
                    ),
                );
            }
        }
        if let Some(others) = &g.others {
            if checkable && all_valid && sum >= robots {
                self.diagnostics.report(
                    Code::EmptyOthers,
                    others.keyword_span,
                    "the groups' minimums take every robot: no robot is left to run `others`",
                );
            }
            let inner = scope.clone();
            let kind = ScopeKind::Others {
                keyword: others.keyword_span,
            };
            self.record_scope(others.body.span, kind, &inner);
            self.block(&others.body, &inner);
        }
    }

    fn robot_names(&self, scope: &Scope, robots: &[RobotId]) -> String {
        let Some(team) = scope.team else {
            return String::new();
        };
        let t = self.team(team);
        let names = robots.iter().map(|&r| t.robots[r.index()].name.as_str());
        some_names(names, robots.len())
    }

    // ----- communication -----

    fn comm(&mut self, comm: &ast::Comm, scope: &Scope) {
        if let Some(p) = &comm.timeout {
            self.period(p);
        }
        let peer = if is_user(&comm.team.name) {
            self.occurrence(comm.team.span, Symbol::User, false);
            Some(Peer::User)
        } else if let Some(t) = self.team_id(&comm.team.name) {
            self.occurrence(comm.team.span, Symbol::Team(t), false);
            Some(Peer::Team(t))
        } else {
            let mut names = self.team_names();
            names.push("USER".into());
            let guess = suggestion(&comm.team.name, names.iter().map(String::as_str));
            self.diagnostics
                .report(
                    Code::UnknownCommTeam,
                    comm.team.span,
                    format!(
                        "`{}` is not a team: `{}` needs a declared team or USER",
                        comm.team.name,
                        comm.kind.as_str()
                    ),
                )
                .suggest(guess);
            None
        };
        for item in &comm.items {
            let written = item
                .value
                .as_ref()
                .map(|value| literal(value, &self.expr(value, scope, true)));
            let resolution = self.resolve_attr(&item.attr, scope);
            let key = self.attr_key(&item.attr, &resolution, scope);
            if let Some(key) = &key {
                // What the team variable can hold: a literal set here, or
                // anything the operator sends.
                let from_operator =
                    !comm.kind.is_outgoing() && peer == Some(Peer::User) && !is_user(&key.owner);
                if comm.kind.is_outgoing() && written.is_some() || from_operator {
                    self.variable_writes.push(VariableWrite {
                        key: key.clone(),
                        value: written.clone().flatten(),
                        span: item.attr.span,
                        team: scope.team,
                    });
                }
            }
            if comm.kind.is_outgoing() && item.value.is_some() {
                // `T.X = e` declares the team variable here.
                let team = match item.attr.segments.as_slice() {
                    [t, _] => self.team_id(&t.name),
                    _ => scope.team,
                };
                if let [t, _] = item.attr.segments.as_slice() {
                    if let Some(id) = team {
                        self.occurrence(t.span, Symbol::Team(id), false);
                    }
                }
                let name = item.attr.last().name.clone();
                self.occurrence(
                    item.attr.last().span,
                    Symbol::TeamVariable { team, name },
                    true,
                );
            } else if !comm.kind.is_outgoing()
                && matches!(
                    resolution,
                    Resolution::TooLong | Resolution::NotATeam { .. }
                )
            {
                // No message: the name is no key a robot could send.
                self.unreceivable(comm.kind, &item.attr, &resolution);
                continue;
            } else {
                // The team's own value, received from its other robots.
                let receiver = scope.team.map(|t| self.team(t).name.clone());
                if !comm.kind.is_outgoing()
                    && let Some(key) = &key
                    && receiver.as_ref() == Some(&key.owner)
                {
                    self.received_values
                        .insert((key.owner.clone(), key.name.clone()));
                }
                self.record_attr(&item.attr, resolution, false);
            }
            match (scope.team, scope.service, peer, key) {
                (Some(team), Some(service), Some(peer), Some(value)) => {
                    self.mission.messages.push(Message {
                        kind: comm.kind,
                        team,
                        service,
                        peer,
                        value,
                        span: item.attr.span,
                    });
                    self.message_robots.push(scope.robots.0.clone());
                }
                (Some(team), _, None, Some(value)) => {
                    self.comms_with_unknown_team.push((comm.kind, team, value));
                }
                _ => {}
            }
        }
    }

    /// E040: a received name that is not a value (`USER.RC.CMD`, `Nope.X`).
    /// A warning would let the mission build, but a message carries a value
    /// of a team, `USER` or the robot's own, which the name is none of: the
    /// robot could not be refined.
    fn unreceivable(&mut self, kind: ast::CommKind, attr: &ast::Attr, resolution: &Resolution) {
        let written = attr.dotted();
        let verb = kind.as_str();
        let (message, guess) = match resolution {
            Resolution::NotATeam { team } => (
                format!(
                    "`{verb}` takes a value, but `{written}` is none: `{team}` is not a team (write `Team.VALUE`, `USER.VALUE` or `VALUE`)"
                ),
                suggestion(team, self.team_names().iter().map(String::as_str)),
            ),
            _ => (
                format!(
                    "`{verb}` takes a value, but `{written}` is none: a value's name has one or two parts (`Team.VALUE`, `USER.VALUE` or `VALUE`)"
                ),
                None,
            ),
        };
        self.diagnostics
            .report(Code::ReceivedNotAValue, attr.span, message)
            .suggest(guess);
        self.occurrence(
            attr.last().span,
            Symbol::Constant(Name::new(&written)),
            false,
        );
    }

    /// `COLOR` written in SlaveTeam and `SlaveTeam.COLOR` are the same value.
    fn attr_key(
        &self,
        attr: &ast::Attr,
        resolution: &Resolution,
        scope: &Scope,
    ) -> Option<AttrKey> {
        let name = match resolution {
            Resolution::Value { name, .. } | Resolution::PartialValue { name, .. } => name.clone(),
            _ => attr.last().name.clone(),
        };
        let owner = match attr.segments.as_slice() {
            [_] => self.team(scope.team?).name.clone(),
            [team, _] if is_user(&team.name) => Name::new_static("USER"),
            [team, _] => team.name.clone(),
            _ => return None,
        };
        Some(AttrKey { owner, name })
    }
}

pub(super) fn describe_param(ty: &ValueType) -> String {
    match ty {
        ValueType::Enum(domain) => format!("one of {}", domain.join(", ")),
        ValueType::Location => "a location such as \"5,5\"".into(),
        other => format!("a {}", other.name()),
    }
}

/// The literal an argument is, as a comparison with the parameter it is
/// given reads it (`ty`: its checked type): several bare words are a
/// string.
pub(super) fn argument_literal(arg: &ast::Arg, ty: &Type) -> Option<Literal> {
    match arg {
        ast::Arg::Words { text, .. } => Some(Literal::Word(text.clone())),
        ast::Arg::Expr(e) => literal(e, ty),
    }
}

/// The literal `e` is, as a comparison reads it (`ty`: its checked type):
/// a string, a number, or a symbolic constant.
fn literal(e: &Expr, ty: &Type) -> Option<Literal> {
    match (&e.kind, ty) {
        (ExprKind::Str(s), _) => Some(Literal::Word(s.clone())),
        (ExprKind::Number(n), _) => n.parse().ok().map(Literal::Number),
        (ExprKind::Attr(_), Type::Constant(c)) => Some(Literal::Word(c.to_string())),
        _ => None,
    }
}

/// The text of a string literal on the other side of a comparison.
fn other_side_text(span: Span, lhs: &Expr, rhs: &Expr) -> Option<String> {
    [lhs, rhs]
        .into_iter()
        .find(|e| e.span == span)
        .and_then(|e| match &e.kind {
            ExprKind::Str(s) => Some(s.clone()),
            _ => None,
        })
}
