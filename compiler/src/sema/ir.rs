//! The Mission IR: a mission with every name resolved. This is the one contract
//! that the language server, the strategy checker and the code generator read.
//! Statement bodies stay as syntax trees; what each name in them refers to is in
//! [`Mission::occurrences`], keyed by the name's byte range.

use crate::catalog::RobotTypeId;
use crate::diag::FileId;
use crate::fasthash::FastMap;
use crate::index::newtype_index;
use crate::span::Span;
use crate::syntax::ast::{self, Name};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TeamId(pub u32);

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FunctionId(pub u32);

newtype_index! {
    /// A plan of its team: an index into [`Team::plans`].
    pub struct PlanId;
}

newtype_index! {
    /// A service of its team: an index into [`Team::services`].
    pub struct ServiceId;
}

newtype_index! {
    /// A mode of its team: an index into [`Team::modes`].
    pub struct ModeId;
}

newtype_index! {
    /// A mode with parameters of its team: an index into [`Team::templates`].
    pub struct TemplateId;
}

/// Whose parameter a name is: a function's (`def f(P)`), a composite
/// service's (`T.Plan.S(P)`) or a mode's (`T.M(P)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ParamOwner {
    Function(FunctionId),
    Service(TeamId, ServiceId),
    Mode(TeamId, TemplateId),
}

newtype_index! {
    /// A robot of its team: an index into [`Team::robots`] (`name[N]`
    /// declares N of them). Not the robot's number in the generated
    /// programs, which counts across teams.
    pub struct RobotId;
}

#[derive(Clone, Debug, Default)]
pub struct Mission {
    pub file: FileId,
    pub teams: Vec<Team>,
    pub functions: Vec<FunctionInfo>,
    /// Every communication statement, with the service that runs it.
    pub messages: Vec<Message>,
    /// Every name written in the file and what it refers to, sorted by position.
    pub occurrences: Vec<Occurrence>,
    /// The parts of the file whose statements robots run (service and function
    /// bodies, group arms), outer before inner: see [`Mission::scope_at`].
    pub scopes: Vec<RobotScope>,
    /// How each comparison (`a < b`, `a == b`) compares, as the checker typed
    /// its sides, by the comparison's range, sorted: see [`Mission::compared_at`].
    pub comparisons: Vec<(Span, Compared)>,
}

/// How a comparison compares, decided by the checker from its sides' types
/// (the catalog's value types, the literals): generated code and the
/// simulator compare exactly so, never by looking at the values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compared {
    /// Both sides are numbers (whole or real numbers, numeric values,
    /// periods; a team variable counts as one when the other side is, and
    /// two variables are ordered as numbers): by value. A side that is not
    /// a number at run time makes the comparison false.
    Numbers,
    /// Anything else (words, strings, locations, symbolic constants, truth
    /// values, two variables with `==`/`!=`): equal when the texts are.
    Words,
}

#[derive(Clone, Debug)]
pub struct Team {
    pub name: Name,
    pub name_span: Span,
    pub robots: Vec<Robot>,
    pub plans: Vec<Plan>,
    pub services: Vec<Service>,
    /// The modes of its mode machine: each mode without parameters, and
    /// each mode with parameters once per distinct list of arguments it is
    /// entered with (`MOVE(kitchen)`, `MOVE(hall)`: [`Mode::instance`]).
    pub modes: Vec<Mode>,
    /// Its modes with parameters, as declared: each is a mode of the
    /// machine only through the arguments it is entered with.
    pub templates: Vec<ModeTemplate>,
    pub main: Option<Main>,
    /// Events its services throw or its main catches.
    pub events: Vec<Event>,
    /// Its `throw E broadcast` statements, sorted by position: see
    /// [`Team::broadcast_at`].
    pub broadcasts: Vec<Broadcast>,
    /// Team variables (`T.X` assigned in send/publish, or received).
    pub variables: Vec<Name>,
    /// Its plans, services, modes and events by name: a mission may have
    /// hundreds of thousands, and a lookup must not scan them.
    names: Names,
}

/// A team's name indexes, kept by the `add_*` methods.
#[derive(Clone, Debug, Default)]
struct Names {
    plans: FastMap<Name, PlanId>,
    services: FastMap<(PlanId, Name), ServiceId>,
    modes: FastMap<Name, ModeId>,
    templates: FastMap<Name, TemplateId>,
    events: FastMap<Name, usize>,
}

/// One robot. `name[N]` declares N robots `name_0` .. `name_{N-1}`.
#[derive(Clone, Debug)]
pub struct Robot {
    pub name: Name,
    /// The range of the declaration's name (shared by the N robots of `name[N]`).
    pub name_span: Span,
    pub type_name: String,
    /// `None` when the type is not in the catalog (already reported).
    pub robot_type: Option<RobotTypeId>,
}

#[derive(Clone, Debug)]
pub struct Plan {
    pub name: Name,
    /// Where the plan is first named in a service header.
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct Service {
    pub name: Name,
    pub name_span: Span,
    pub plan: PlanId,
    pub span: Span,
    /// Index of the service's item in the file's syntax tree: its body and
    /// `repeat` are read from there ([`crate::CheckedMission::service_syntax`]).
    pub item: usize,
    /// Events this service can throw, directly or through functions it calls.
    pub throws: Vec<Name>,
    /// The parameters, in order (`T.Plan.S(PLACE)`): each stands in the
    /// body for the argument of the mode's `set` that runs it.
    pub params: Vec<ParamInfo>,
    /// The names its body binds to action results (`F, W = search(red)`),
    /// in the order first bound.
    pub results: Vec<ResultInfo>,
}

#[derive(Clone, Debug)]
pub struct Mode {
    /// As written, or for a mode with parameters entered with arguments,
    /// the mode's name and the arguments as written: `MOVE(kitchen)`.
    pub name: Name,
    pub name_span: Span,
    pub span: Span,
    pub sets: Vec<ModeSet>,
    /// For a mode with parameters: which, and the arguments it is entered
    /// with here.
    pub instance: Option<ModeInstance>,
}

/// A mode with parameters entered with one list of arguments: the mode
/// its `set`s are with each parameter standing for its argument.
#[derive(Clone, Debug)]
pub struct ModeInstance {
    pub template: TemplateId,
    /// As first written where the mode is entered (`mode = MOVE(kitchen)`):
    /// words, strings or numbers, fixed when the mission is written.
    pub args: Vec<ast::Arg>,
}

/// A mode with parameters (`T.MOVE(TARGET) { set(Action, Go(TARGET)) }`).
#[derive(Clone, Debug)]
pub struct ModeTemplate {
    pub name: Name,
    pub name_span: Span,
    pub span: Span,
    pub params: Vec<ParamInfo>,
    /// Its `set`s, each argument as written (a parameter of the mode or a
    /// fixed word, string or number).
    pub sets: Vec<ModeSet>,
    /// The modes of the machine it is entered as, one per distinct list
    /// of arguments, in the order first entered.
    pub instances: Vec<ModeId>,
}

#[derive(Clone, Debug)]
pub struct ModeSet {
    pub plan: Option<PlanId>,
    /// `None` for `OFF` (or a service that does not exist, already reported).
    pub service: Option<ServiceId>,
    /// The arguments of a service with parameters, fixed: the service runs
    /// with each parameter standing for its argument
    /// (`set(Action, Go(kitchen))`, or in an instance of a mode with
    /// parameters the mode's argument). In a [`ModeTemplate`], as written.
    pub args: Vec<ast::Arg>,
    pub timeout_ms: Option<f64>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct Main {
    pub span: Span,
    pub default: Option<ModeId>,
    pub transitions: Vec<Transition>,
    /// The modes no catch leads to from the default mode (W002), in order;
    /// empty when that was not decided (no default, or a catch naming an
    /// unknown mode).
    pub unreachable: Vec<ModeId>,
}

/// `case (from): catch (event): mode = to`.
#[derive(Clone, Debug)]
pub struct Transition {
    pub from: ModeId,
    pub event: Name,
    pub event_span: Span,
    pub to: ModeId,
    pub span: Span,
    /// No service that the `from` mode runs throws the event, so the catch
    /// never fires there (W009).
    pub never_thrown: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Event {
    pub name: Name,
    pub thrown_at: Vec<Span>,
    pub caught_at: Vec<Span>,
}

/// `throw E broadcast` in a service of the team (or a function its
/// services call): who the event goes to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Broadcast {
    pub event: Name,
    /// The range of the event's name in the statement (one per statement).
    pub span: Span,
    /// The range of the word `broadcast`.
    pub keyword: Span,
    /// The thrower's group: the team's robots that run the statement, as
    /// the checker walked it (inside a `group`/`leader` arm or `others`,
    /// the robots that run that arm; outside any, the whole team; in a
    /// function called from several places, the robots of every one of
    /// them), in formation order. Any of them may throw it; each of them
    /// receives it, the thrower included.
    pub receivers: std::sync::Arc<[RobotId]>,
}

#[derive(Clone, Debug)]
pub struct FunctionInfo {
    pub name: Name,
    pub name_span: Span,
    /// Index of the function's item in the file's syntax tree.
    pub item: usize,
    pub called: bool,
    /// The parameters, in order (`def name(PLACE, ...)`).
    pub params: Vec<ParamInfo>,
    /// The names its body binds to action results, in the order first bound.
    pub results: Vec<ResultInfo>,
}

/// A name a body binds to a result of a built-in service
/// (`FOUND, WHERE = search(red)`): a value of the robot running the body,
/// none until a call binding it is done, readable by name after it
/// (`docs/language/services.md`).
#[derive(Clone, Debug)]
pub struct ResultInfo {
    pub name: Name,
    /// Where it is first bound (its definition).
    pub span: Span,
    /// The service whose call first binds it, and that result's name in the
    /// catalog (`search`, `FOUND`).
    pub service: Name,
    pub catalog_name: Option<Name>,
    /// Its type, the catalog's for that result; `None` until a call binding
    /// it is walked with robots that have the service.
    pub ty: Option<crate::catalog::ValueType>,
}

/// A parameter of a function: a name that stands, in the body, for the
/// argument of the call being run (`docs/language/services.md`).
#[derive(Clone, Debug)]
pub struct ParamInfo {
    pub name: Name,
    pub span: Span,
    /// What the body asks of it, its own uses and those of the functions it
    /// is passed on to: every call's argument is checked against each (E023).
    pub needs: Vec<ParamNeed>,
}

/// One use that asks something of a parameter's argument.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamNeed {
    pub kind: NeedKind,
    /// Where the parameter is used so (in this function or one it calls).
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum NeedKind {
    /// Passed to a built-in service's parameter of this type.
    Argument {
        service: Name,
        param: Name,
        ty: crate::catalog::ValueType,
    },
    /// Compared with a number, or ordered (`<`, `<=`, `>`, `>=`): compared
    /// as numbers, so the argument must be one.
    Number,
}

/// Who is at the other end of a communication statement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Peer {
    Team(TeamId),
    /// The operator console.
    User,
}

/// A communicated value, normalised: `COLOR` in SlaveTeam is `SlaveTeam.COLOR`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct AttrKey {
    /// The team the value belongs to, or `USER`.
    pub owner: Name,
    pub name: Name,
}

impl std::fmt::Display for AttrKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.owner, self.name)
    }
}

#[derive(Clone, Debug)]
pub struct Message {
    pub kind: ast::CommKind,
    /// The team whose service runs the statement.
    pub team: TeamId,
    pub service: ServiceId,
    pub peer: Peer,
    pub value: AttrKey,
    pub span: Span,
}

/// What a name refers to.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Symbol {
    Team(TeamId),
    User,
    Robot {
        team: TeamId,
        robot: RobotId,
    },
    RobotType(Name),
    Capability(Name),
    Plan {
        team: TeamId,
        plan: PlanId,
    },
    Service {
        team: TeamId,
        service: ServiceId,
    },
    Mode {
        team: TeamId,
        mode: ModeId,
    },
    Event {
        team: TeamId,
        name: Name,
    },
    Function(FunctionId),
    /// A catalog service such as `move`.
    BuiltinService(Name),
    /// A catalog value of a team's robots (or of `USER`).
    Value {
        owner: Option<TeamId>,
        name: Name,
    },
    TeamVariable {
        team: Option<TeamId>,
        name: Name,
    },
    /// A symbolic constant such as `colored_paper`.
    Constant(Name),
    /// The `index`th parameter of a function, a service or a mode, where
    /// it is declared and where its body (a mode's `set`s) uses it.
    Parameter {
        owner: ParamOwner,
        index: u32,
    },
    /// The `index`th result name of a function's or a service's body
    /// (`FOUND` of `FOUND, WHERE = search(red)`), where bound and where read.
    Result {
        owner: ParamOwner,
        index: u32,
    },
    /// A mode with parameters, where declared and where named (in `case`,
    /// and entered with arguments).
    ModeTemplate {
        team: TeamId,
        template: TemplateId,
    },
    /// The name of a counted group, `group(Name, min = N)`, where it is
    /// written (its only occurrence: a group is named in its statement
    /// alone): `min` its minimum, `robots` how many robots run the
    /// statement (any may be given the group at run time).
    CountedGroup {
        team: TeamId,
        name: Name,
        min: u32,
        robots: u32,
    },
}

/// A part of the file whose statements some robots run, as the checker saw it:
/// a composite service (header to `repeat`), a function, or the body of a
/// `group`/`leader` arm or of `others` (run by fewer robots than around it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotScope {
    pub span: Span,
    pub kind: ScopeKind,
    /// Who runs it: one entry per team and set of robots (a function called
    /// from several places has several; a function nobody calls has one,
    /// with no team).
    pub runs: Vec<Runners>,
    /// The smallest scope around this one (an index into [`Mission::scopes`]).
    pub parent: Option<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScopeKind {
    Service {
        team: TeamId,
        service: ServiceId,
    },
    Function(FunctionId),
    /// The body of `group(cond)` or `leader(cond)`; `condition` is `cond`'s range.
    Arm {
        kind: ast::ArmKind,
        condition: Span,
    },
    /// The body of `others`; `keyword` is the range of the word.
    Others {
        keyword: Span,
    },
    /// The body of a definition that was rejected (a duplicate, or of an
    /// undeclared team): checked, but part of nothing.
    Rejected,
}

/// Robots that run a scope: `team` is `None` where they are unknown (a
/// function that no service calls).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Runners {
    pub team: Option<TeamId>,
    /// Indices into the team's robots (shared by every scope the same
    /// robots run).
    pub robots: std::sync::Arc<[RobotId]>,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Occurrence {
    pub span: Span,
    pub symbol: Symbol,
    pub is_definition: bool,
}

impl Mission {
    pub fn team(&self, id: TeamId) -> &Team {
        &self.teams[id.0 as usize]
    }

    pub fn team_by_name(&self, name: &str) -> Option<TeamId> {
        self.teams
            .iter()
            .position(|t| t.name == name)
            .map(|i| TeamId(i as u32))
    }

    /// The parameters of a function, a service or a mode with parameters.
    pub fn params(&self, owner: ParamOwner) -> &[ParamInfo] {
        match owner {
            ParamOwner::Function(f) => &self.functions[f.0 as usize].params,
            ParamOwner::Service(team, service) => &self.team(team).service(service).params,
            ParamOwner::Mode(team, template) => &self.team(team).template(template).params,
        }
    }

    /// The result names a function's or a service's body binds (a mode
    /// binds none).
    pub fn results(&self, owner: ParamOwner) -> &[ResultInfo] {
        match owner {
            ParamOwner::Function(f) => &self.functions[f.0 as usize].results,
            ParamOwner::Service(team, service) => &self.team(team).service(service).results,
            ParamOwner::Mode(..) => &[],
        }
    }

    pub(super) fn results_mut(&mut self, owner: ParamOwner) -> Option<&mut Vec<ResultInfo>> {
        match owner {
            ParamOwner::Function(f) => Some(&mut self.functions[f.0 as usize].results),
            ParamOwner::Service(team, service) => {
                Some(&mut self.teams[team.0 as usize].services[service.index()].results)
            }
            ParamOwner::Mode(..) => None,
        }
    }

    pub(super) fn params_mut(&mut self, owner: ParamOwner) -> &mut Vec<ParamInfo> {
        match owner {
            ParamOwner::Function(f) => &mut self.functions[f.0 as usize].params,
            ParamOwner::Service(team, service) => {
                &mut self.teams[team.0 as usize].services[service.index()].params
            }
            ParamOwner::Mode(team, template) => {
                &mut self.teams[team.0 as usize].templates[template.index()].params
            }
        }
    }

    /// `def f`, `T.Plan.S` or `T.M`: what a parameter belongs to, for messages.
    pub fn owner_name(&self, owner: ParamOwner) -> String {
        match owner {
            ParamOwner::Function(f) => self.functions[f.0 as usize].name.to_string(),
            ParamOwner::Service(team, service) => self.team(team).service_path(service),
            ParamOwner::Mode(team, template) => {
                let t = self.team(team);
                format!("{}.{}", t.name, t.template(template).name)
            }
        }
    }

    /// The innermost occurrence at a byte offset (for hover, go-to-definition).
    pub fn occurrence_at(&self, offset: usize) -> Option<&Occurrence> {
        self.occurrences
            .iter()
            .filter(|o| o.span.touches(offset))
            .min_by_key(|o| o.span.len())
    }

    /// The innermost scope strictly inside which `offset` lies (after its
    /// first byte, before its end): O(log n + nesting depth).
    pub fn scope_at(&self, offset: usize) -> Option<&RobotScope> {
        let after = self.scopes.partition_point(|s| s.span.start < offset);
        let mut candidate = after.checked_sub(1)?;
        loop {
            let scope = &self.scopes[candidate];
            if offset < scope.span.end {
                return Some(scope);
            }
            candidate = scope.parent? as usize;
        }
    }

    /// How the comparison written at `span` compares (None: not a comparison
    /// the checker saw).
    pub fn compared_at(&self, span: Span) -> Option<Compared> {
        self.comparisons
            .binary_search_by(|(s, _)| (s.start, s.end).cmp(&(span.start, span.end)))
            .ok()
            .map(|i| self.comparisons[i].1)
    }

    /// Every occurrence of a symbol (definitions and uses).
    pub fn occurrences_of<'a>(
        &'a self,
        symbol: &'a Symbol,
    ) -> impl Iterator<Item = &'a Occurrence> {
        self.occurrences.iter().filter(move |o| &o.symbol == symbol)
    }
}

impl Team {
    /// A team of `robots`, with no plan, service, mode, main or event yet.
    pub fn new(name: Name, name_span: Span, robots: Vec<Robot>) -> Team {
        Team {
            name,
            name_span,
            robots,
            plans: Vec::new(),
            services: Vec::new(),
            modes: Vec::new(),
            templates: Vec::new(),
            main: None,
            events: Vec::new(),
            broadcasts: Vec::new(),
            variables: Vec::new(),
            names: Names::default(),
        }
    }

    /// Adds `plan` (whose name the team does not have yet).
    pub fn add_plan(&mut self, plan: Plan) -> PlanId {
        let id = PlanId::new(self.plans.len());
        self.names.plans.insert(plan.name.clone(), id);
        self.plans.push(plan);
        id
    }

    /// Adds `service` (whose name its plan does not have yet).
    pub fn add_service(&mut self, service: Service) -> ServiceId {
        let id = ServiceId::new(self.services.len());
        let key = (service.plan, service.name.clone());
        self.names.services.insert(key, id);
        self.services.push(service);
        id
    }

    /// Adds `mode` (whose name the team does not have yet).
    pub fn add_mode(&mut self, mode: Mode) -> ModeId {
        let id = ModeId::new(self.modes.len());
        self.names.modes.insert(mode.name.clone(), id);
        self.modes.push(mode);
        id
    }

    /// Adds `template` (whose name the team has for no mode yet).
    pub fn add_template(&mut self, template: ModeTemplate) -> TemplateId {
        let id = TemplateId::new(self.templates.len());
        self.names.templates.insert(template.name.clone(), id);
        self.templates.push(template);
        id
    }

    pub fn template_by_name(&self, name: &str) -> Option<TemplateId> {
        self.names.templates.get(name).copied()
    }

    pub fn template(&self, template: TemplateId) -> &ModeTemplate {
        &self.templates[template.index()]
    }

    /// The broadcast whose event is named at `span` (the event's range in
    /// its `throw ... broadcast` statement).
    pub fn broadcast_at(&self, span: Span) -> Option<&Broadcast> {
        let i = self
            .broadcasts
            .binary_search_by(|b| (b.span.start, b.span.end).cmp(&(span.start, span.end)))
            .ok()?;
        Some(&self.broadcasts[i])
    }

    /// The events that some robot of the team may receive from another one
    /// (`throw E broadcast` run by at least two of its robots): a robot in
    /// any mode may then catch them.
    pub fn events_told(&self) -> impl Iterator<Item = &Name> {
        self.broadcasts
            .iter()
            .filter(|b| b.receivers.len() > 1)
            .map(|b| &b.event)
    }

    /// The event named `name`, added (neither thrown nor caught yet) if new.
    pub fn event_mut(&mut self, name: &str) -> &mut Event {
        let index = match self.names.events.get(name) {
            Some(&i) => i,
            None => {
                let name = Name::new(name);
                self.names.events.insert(name.clone(), self.events.len());
                self.events.push(Event {
                    name,
                    ..Event::default()
                });
                self.events.len() - 1
            }
        };
        &mut self.events[index]
    }

    pub fn plan(&self, plan: PlanId) -> &Plan {
        &self.plans[plan.index()]
    }

    pub fn service(&self, service: ServiceId) -> &Service {
        &self.services[service.index()]
    }

    pub fn mode(&self, mode: ModeId) -> &Mode {
        &self.modes[mode.index()]
    }

    pub fn robot(&self, robot: RobotId) -> &Robot {
        &self.robots[robot.index()]
    }

    /// The team's robots by declaration, in order: `name[N]` declares N
    /// robots (sharing one `name_span`) that the checker treats alike: of
    /// one type, they run the same scopes and join the same groups.
    pub fn declarations(&self) -> Vec<Vec<RobotId>> {
        let mut declarations: Vec<Vec<RobotId>> = Vec::new();
        for (id, robot) in self.robot_ids().zip(&self.robots) {
            match declarations.last_mut() {
                Some(last) if self.robot(last[0]).name_span == robot.name_span => last.push(id),
                _ => declarations.push(vec![id]),
            }
        }
        declarations
    }

    pub fn plan_ids(&self) -> impl DoubleEndedIterator<Item = PlanId> + Clone + use<> {
        PlanId::all(self.plans.len())
    }

    pub fn service_ids(&self) -> impl DoubleEndedIterator<Item = ServiceId> + Clone + use<> {
        ServiceId::all(self.services.len())
    }

    pub fn mode_ids(&self) -> impl DoubleEndedIterator<Item = ModeId> + Clone + use<> {
        ModeId::all(self.modes.len())
    }

    pub fn robot_ids(&self) -> impl DoubleEndedIterator<Item = RobotId> + Clone + use<> {
        RobotId::all(self.robots.len())
    }

    pub fn plan_by_name(&self, name: &str) -> Option<PlanId> {
        self.names.plans.get(name).copied()
    }

    pub fn mode_by_name(&self, name: &str) -> Option<ModeId> {
        self.names.modes.get(name).copied()
    }

    pub fn service_in_plan(&self, plan: PlanId, name: &str) -> Option<ServiceId> {
        self.names.services.get(&(plan, Name::new(name))).copied()
    }

    /// `Team.Plan.Service`, for messages.
    pub fn service_path(&self, service: ServiceId) -> String {
        let s = self.service(service);
        format!("{}.{}.{}", self.name, self.plan(s.plan).name, s.name)
    }
}
