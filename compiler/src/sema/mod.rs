//! Semantic analysis: resolves the names of a parsed mission against the robot
//! catalog, reports every check of spec section 5, and builds the [`Mission`] IR.
//!
//! Phases, each in its own module:
//! 1. [`declare`]: teams, robots, plans, services, modes, mains and functions.
//! 2. [`body`]: statement bodies, walked with the set of robots that run them
//!    (narrowed by `group`/`leader`/`others`): calls, arguments, values, events,
//!    communication.
//! 3. [`behaviour`]: modes and main blocks: `set` targets, transitions,
//!    reachability, uncaught events, unused services and functions.
//! 4. [`comm`]: every receive/subscribe matched with a send/publish, and back.
//! 5. [`values`]: value flow: what each team variable can hold, and the
//!    comparisons with it that decide the same way at every run; when a
//!    received value can have been sent: read before any robot can have
//!    sent it, sent on once while it keeps coming, never fed.
//!
//! Sema never reads files and never panics. [`lookup`] answers "which
//! symbols are written here" by binary search in the IR's sorted occurrences,
//! for the editor and for refinement alike.

mod behaviour;
mod body;
mod comm;
mod declare;
pub mod ir;
pub(crate) mod lookup;
mod params;
mod results;
mod values;

pub use ir::*;

use crate::catalog::Catalog;
use crate::diag::{self, Diagnostic, FileId, Sink};
use crate::fasthash::{FastMap, FastSet};
use crate::span::Span;
use crate::syntax::{self, ast, ast::Name};

/// The most robots one `name[N]` declaration may declare (E036). The
/// checker keeps per-robot facts (names, which statements each robot runs),
/// so the number written is checked before any robot is made: a swarm of a
/// thousand robots is checked in well under a second, and a typo of a few
/// more digits is a positioned error instead of gigabytes.
pub const MAX_ROBOTS_PER_DECLARATION: u32 = 4096;

/// The most robots a mission may declare in all its teams (E036, on the
/// declaration that goes past it).
pub const MAX_ROBOTS_PER_MISSION: usize = 4096;

/// The most `set`s and catches the copies of modes entered with arguments
/// may hold in all (E048, where they go past it): each distinct list of
/// arguments copies its mode's `set`s and the catches of `case` for the
/// mode, so many lists of a mode with many of them would otherwise cost
/// their product.
pub const MAX_MODE_COPIES: usize = 65_536;

/// Everything known about one mission file after checking.
#[derive(Clone, Debug)]
pub struct CheckedMission {
    pub syntax: ast::SourceFile,
    pub mission: Mission,
    /// Syntax and semantic diagnostics, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
}

impl CheckedMission {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }

    /// The syntax (body, `repeat`) of a composite service of the IR.
    pub fn service_syntax(&self, service: &Service) -> Option<&ast::CompositeService> {
        match self.syntax.items.get(service.item) {
            Some(ast::Item::Service(s)) => Some(s),
            _ => None,
        }
    }

    /// The syntax (body) of a function of the IR.
    pub fn function_syntax(&self, function: &FunctionInfo) -> Option<&ast::Function> {
        match self.syntax.items.get(function.item) {
            Some(ast::Item::Function(f)) => Some(f),
            _ => None,
        }
    }
}

/// Parses and checks one mission script.
pub fn check_source(file: FileId, text: &str, catalog: &Catalog) -> CheckedMission {
    check_parsed(file, syntax::parse(file, text), catalog)
}

/// Checks a mission script already parsed (by [`syntax::parse`] or
/// [`syntax::parse_incremental`]): the same analysis as [`check_source`].
pub fn check_parsed(file: FileId, parse: syntax::Parse, catalog: &Catalog) -> CheckedMission {
    let (mission, mut diagnostics) = check(file, &parse, catalog);
    diagnostics.extend(parse.diagnostics);
    diag::sort_and_dedup(&mut diagnostics);
    CheckedMission {
        syntax: parse.file,
        mission,
        diagnostics,
    }
}

/// Checks a parsed mission script: its tree, and whether the parse dropped
/// a line (a syntax error), which some checks must know.
pub fn check<'a>(
    file: FileId,
    parse: &'a syntax::Parse,
    catalog: &'a Catalog,
) -> (Mission, Vec<Diagnostic>) {
    let source = &parse.file;
    let mut checker = Checker::new(file, catalog);
    checker.declare(source);
    checker.check_bodies();
    checker.check_behaviour(source);
    // After the modes: a `set` and a mode entered give arguments too.
    checker.check_parameters();
    checker.check_communication();
    // Sorted now: the value flow looks names up.
    checker.sort_occurrences();
    checker.check_values(!parse.diagnostics.iter().any(Diagnostic::is_error));
    checker.finish()
}

/// The name written for the operator console.
pub(crate) fn is_user(name: &str) -> bool {
    name == "USER" || name == "user"
}

/// A function body checked for a (function, team, service, robots running it).
type InlinedBody = (FunctionId, Option<TeamId>, Option<ServiceId>, body::Robots);

pub(crate) struct Checker<'a> {
    /// The syntax of each team's services, parallel to `Team::services`, and of
    /// each function: bodies are walked from the tree, not from the IR copy.
    service_syntax: Vec<Vec<&'a ast::CompositeService>>,
    function_syntax: Vec<&'a ast::Function>,
    catalog: &'a Catalog,
    mission: Mission,
    diagnostics: Sink,
    teams_by_name: FastMap<Name, TeamId>,
    functions_by_name: FastMap<Name, FunctionId>,
    /// Team variables declared anywhere by `T.X = ...` or received, by name:
    /// the teams declaring them (`None` when written bare inside a function).
    variables: FastMap<Name, Vec<Option<TeamId>>>,
    /// The same, by (team, name): whether a team has a variable is one lookup,
    /// where a name that thousands of teams declare has a list as long.
    team_variables: FastSet<(Option<TeamId>, Name)>,
    /// Services named by the `set`s of a mode defined twice (already reported):
    /// they are not "never set".
    set_by_duplicate_modes: FastSet<(TeamId, ServiceId)>,
    /// Teams whose main block names an undefined mode (already reported): which
    /// modes it can reach is unknown.
    mains_with_unknown_modes: FastSet<TeamId>,
    /// The `set`s and catches the copies of modes entered with arguments
    /// hold so far, all teams (at most [`MAX_MODE_COPIES`]).
    mode_copies: usize,
    /// Teams with modes left without copies past [`MAX_MODE_COPIES`]
    /// (E048, already reported).
    past_mode_copies: FastSet<TeamId>,
    /// Communication statements naming an unknown team (already reported), as
    /// (kind, running team, value): they may be the counterpart of another.
    comms_with_unknown_team: Vec<(ast::CommKind, TeamId, AttrKey)>,
    /// A team's own values that its robots receive or subscribe to (team
    /// name, value): they may read them without having them (spec §3).
    received_values: std::collections::HashSet<(Name, Name)>,
    /// E033 findings held back until every body is checked: a value a robot
    /// lacks is fine wherever its team receives it.
    lacking_values: Vec<body::LackingValue>,
    /// Function bodies already checked for a (function, team, service, robots):
    /// checking again would find the same, and nested calls would be exponential.
    inlined: FastSet<InlinedBody>,
    /// Bodies of duplicate definitions and of services of undeclared teams:
    /// not part of the IR, but still checked so that their mistakes show now.
    rejected_bodies: Vec<(Option<TeamId>, &'a ast::Block)>,
    /// Each team's robot types (all its robots), for values read across teams.
    team_types: Vec<body::TypeList>,
    /// Where each scope of `mission.scopes` is, by its range: a function body
    /// walked for several callers is one scope with several runners.
    scope_index: FastMap<Span, usize>,
    /// Where each comparison of `mission.comparisons` is, by its range.
    comparison_index: FastMap<Span, usize>,
    /// Every write of a team variable and every comparison of one with a
    /// literal, for the value flow (`values.rs`).
    variable_writes: Vec<values::VariableWrite>,
    variable_tests: Vec<values::VariableTest>,
    /// Every comparison of a parameter with a literal, and what each
    /// parameter is given (once every body is walked, `params.rs`), for the
    /// value flow.
    parameter_tests: Vec<values::ParameterTest>,
    given: Option<values::Given>,
    /// The robots that run each of `mission.messages`, in the same order.
    message_robots: Vec<std::sync::Arc<[RobotId]>>,
    /// Every set of robots running a scope, once ([`Checker::shared_robots`]).
    robot_sets: FastSet<std::sync::Arc<[RobotId]>>,
    /// The events each service throws, as in its `throws` list: a service
    /// may throw thousands.
    thrown: FastSet<(TeamId, ServiceId, Name)>,
    /// Where each team's `Team::broadcasts` entry of a statement is, by the
    /// range of its event name: a function's statement walked for several
    /// callers is one entry with the robots of all.
    broadcast_index: FastMap<(TeamId, Span), usize>,
    /// What each function's body asks of its parameters, and the argument
    /// of every call walked, checked against each other once every body is
    /// walked (`params.rs`).
    param_uses: params::ParamUses,
    /// Each body's result names to their index in its `results`: a read
    /// or a binding finds its result in constant time, however many a
    /// body binds.
    result_index: FastMap<(ParamOwner, Name), u32>,
    /// The mission went past [`MAX_ROBOTS_PER_MISSION`] (reported once):
    /// no further robot is declared.
    robots_full: bool,
}

impl<'a> Checker<'a> {
    fn new(file: FileId, catalog: &'a Catalog) -> Self {
        Checker {
            service_syntax: Vec::new(),
            function_syntax: Vec::new(),
            catalog,
            mission: Mission {
                file,
                ..Mission::default()
            },
            diagnostics: Sink::new(file),
            teams_by_name: FastMap::default(),
            functions_by_name: FastMap::default(),
            variables: FastMap::default(),
            team_variables: FastSet::default(),
            set_by_duplicate_modes: FastSet::default(),
            mains_with_unknown_modes: FastSet::default(),
            mode_copies: 0,
            past_mode_copies: FastSet::default(),
            comms_with_unknown_team: Vec::new(),
            received_values: Default::default(),
            lacking_values: Vec::new(),
            inlined: FastSet::default(),
            team_types: Vec::new(),
            rejected_bodies: Vec::new(),
            scope_index: FastMap::default(),
            comparison_index: FastMap::default(),
            variable_writes: Vec::new(),
            variable_tests: Vec::new(),
            parameter_tests: Vec::new(),
            given: None,
            message_robots: Vec::new(),
            robot_sets: FastSet::default(),
            thrown: FastSet::default(),
            broadcast_index: FastMap::default(),
            param_uses: params::ParamUses::default(),
            result_index: FastMap::default(),
            robots_full: false,
        }
    }

    fn occurrence(&mut self, span: Span, symbol: Symbol, is_definition: bool) {
        self.mission.occurrences.push(Occurrence {
            span,
            symbol,
            is_definition,
        });
    }

    /// Records that `event`, written here, is an event of `team`.
    fn event_occurrence(&mut self, team: TeamId, event: &ast::Ident) {
        let symbol = Symbol::Event {
            team,
            name: event.name.clone(),
        };
        self.occurrence(event.span, symbol, false);
    }

    fn team_id(&self, name: &str) -> Option<TeamId> {
        self.teams_by_name.get(name).copied()
    }

    fn team(&self, id: TeamId) -> &Team {
        &self.mission.teams[id.0 as usize]
    }

    /// Records how the comparison at `span` compares. A body walked for
    /// several callers is typed each time: it compares numbers only when
    /// every walk found numbers.
    fn comparison(&mut self, span: Span, compared: Compared) {
        let comparisons = &mut self.mission.comparisons;
        let index = *self.comparison_index.entry(span).or_insert_with(|| {
            comparisons.push((span, compared));
            comparisons.len() - 1
        });
        if compared == Compared::Words {
            comparisons[index].1 = Compared::Words;
        }
    }

    fn team_mut(&mut self, id: TeamId) -> &mut Team {
        &mut self.mission.teams[id.0 as usize]
    }

    /// Whether `name` is a team variable of `team` (or written bare in a function).
    fn is_variable(&self, team: TeamId, name: &str) -> bool {
        let name = Name::new(name);
        self.team_variables.contains(&(Some(team), name.clone()))
            || self.team_variables.contains(&(None, name))
    }

    fn team_names(&self) -> Vec<String> {
        self.mission
            .teams
            .iter()
            .map(|t| t.name.to_string())
            .collect()
    }

    /// Records that `runners` run the statements of `span`.
    fn scope(&mut self, span: Span, kind: ScopeKind, runners: Runners) {
        let scopes = &mut self.mission.scopes;
        let index = *self.scope_index.entry(span).or_insert_with(|| {
            scopes.push(RobotScope {
                span,
                kind,
                runs: Vec::new(),
                parent: None,
            });
            scopes.len() - 1
        });
        let runs = &mut scopes[index].runs;
        if !runs.contains(&runners) {
            runs.push(runners);
        }
    }

    /// Sorts the occurrences by position, once every name is recorded.
    fn sort_occurrences(&mut self) {
        self.mission.occurrences =
            sorted_occurrences(std::mem::take(&mut self.mission.occurrences));
    }

    fn finish(mut self) -> (Mission, Vec<Diagnostic>) {
        nest_scopes(&mut self.mission.scopes);
        self.mission
            .comparisons
            .sort_by_key(|(span, _)| (span.start, span.end));
        (self.mission, self.diagnostics.into_vec())
    }
}

/// Sorts scopes outer before inner (by start, then longest first) and links
/// each to the smallest scope containing it.
fn nest_scopes(scopes: &mut [RobotScope]) {
    scopes.sort_by_key(|s| (s.span.start, std::cmp::Reverse(s.span.end)));
    let mut open: Vec<usize> = Vec::new();
    for i in 0..scopes.len() {
        let span = scopes[i].span;
        while let Some(&top) = open.last() {
            let outer = scopes[top].span;
            if outer.start <= span.start && span.end <= outer.end {
                break;
            }
            open.pop();
        }
        scopes[i].parent = open.last().map(|&p| p as u32);
        open.push(i);
    }
}

/// Occurrences sorted by position, without the repeats that checking a
/// function body at several call sites leaves. Occurrences are large, so
/// compact keys are sorted and the occurrences moved once.
fn sorted_occurrences(occurrences: Vec<Occurrence>) -> Vec<Occurrence> {
    let key = |o: &Occurrence| {
        ((o.span.start as u64) << 33) | ((o.span.end as u64) << 1) | u64::from(o.is_definition)
    };
    // The key, then the index: one integer compares faster than a pair.
    let mut order: Vec<u128> = occurrences
        .iter()
        .enumerate()
        .map(|(i, o)| (u128::from(key(o)) << 32) | i as u128)
        .collect();
    order.sort_unstable();
    let mut slots: Vec<Option<Occurrence>> = occurrences.into_iter().map(Some).collect();
    let mut sorted: Vec<Occurrence> = Vec::with_capacity(slots.len());
    for entry in order {
        if let Some(o) = slots[entry as u32 as usize].take() {
            if sorted.last() != Some(&o) {
                sorted.push(o);
            }
        }
    }
    sorted
}

/// Resolves `name` in `candidates`, or reports `code` with a did-you-mean.
pub(crate) fn suggestion<'s>(
    name: &str,
    candidates: impl IntoIterator<Item = &'s str>,
) -> Option<String> {
    crate::suggest::did_you_mean(name, candidates)
}
