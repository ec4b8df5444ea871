//! Strategy files checked against the catalog and the missions of the same
//! check, and the link from mission calls to the strategy entries refining them.
//!
//! Against the catalog (always):
//! - a `TargetRobot` is a known robot type (E010);
//! - a `Value` is a value of each target robot type (E093);
//! - a `Service` is provided by each target robot type (E095);
//! - `srcTask`/`dstTask` name tasks of each target robot type's task library
//!   (E094): `ControlTask` (the control task the refinement synthesizes) and
//!   the tasks that implement the type's values and services (`task=`). A type
//!   with a value or service implemented by a task graph (`graph=`) or with no
//!   implementation given has a library that is not fully known here, and is
//!   not checked.
//!
//! Against the missions (when the check has any):
//! - `Strategy name` is a team of a mission (E089);
//! - a `TargetRobot` is a robot type of that team (E090);
//! - each `Service` is called, by that team, in a composite service of that
//!   plan, directly or through functions (E091); every such call is linked to
//!   the entry ([`StrategyLinks`]);
//! - a leader selection's `plan_name`/`cs_name` name a composite service of
//!   the team that elects a leader (E092);
//! - a `GroupService` names a built-in service the team calls (in that plan,
//!   when it names one) (E124).
//!
//! In the file alone: a service declared a group service twice (E125).
//!
//! A team declared by several missions of the check is checked against each.
//! An entry refined in two strategy files of the same team is E085.

use super::model::*;
use crate::catalog::{Catalog, Implementation, RobotType, RobotTypeId};
use crate::diag::{self, Code, Diagnostic, FileId, Related};
use crate::sema::{CheckedMission, FunctionId, Mission, PlanId, ServiceId, Symbol, Team, TeamId};
use crate::span::Span;
use crate::suggest::did_you_mean;
use crate::syntax::ast::{self, ArmKind, StmtKind};
use std::collections::{HashMap, HashSet};

/// The name of the control task that the refinement synthesizes for every
/// robot: always part of a robot's task library.
pub const CONTROL_TASK: &str = "ControlTask";

/// Identifies one `<Service>` entry: its strategy file and its index in
/// [`Strategy::services`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ServiceEntryRef {
    pub file: FileId,
    pub index: usize,
}

/// A built-in service call of a mission that a strategy entry refines.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CallLink {
    /// The mission file.
    pub mission: FileId,
    /// The called name's range in the mission (`move` of `move("5,5")`).
    pub call: Span,
    pub team: TeamId,
    /// The composite service (of `team`) that runs the call, directly or
    /// through the functions it calls.
    pub service: ServiceId,
    pub entry: ServiceEntryRef,
}

/// Every mission call linked to the strategy entry that refines it, sorted by
/// mission and position. A call inside a function appears once per composite
/// service that runs it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StrategyLinks {
    calls: Vec<CallLink>,
}

impl StrategyLinks {
    pub fn calls(&self) -> &[CallLink] {
        &self.calls
    }

    /// The links of the call whose name is at (or ends at) `offset` in
    /// `mission`: for go-to-definition from a mission.
    pub fn at(&self, mission: FileId, offset: usize) -> impl Iterator<Item = &CallLink> {
        let start = self
            .calls
            .partition_point(|l| (l.mission, l.call.end) < (mission, offset));
        self.calls[start..]
            .iter()
            .take_while(move |l| l.mission == mission && l.call.start <= offset)
            .filter(move |l| l.call.touches(offset))
    }

    /// The links of several checks in one (a strategy file seen by the
    /// missions of several folders).
    pub fn merged<'a>(all: impl IntoIterator<Item = &'a StrategyLinks>) -> StrategyLinks {
        let mut calls: Vec<CallLink> = all.into_iter().flat_map(|l| l.calls.clone()).collect();
        calls.sort_by_key(|l| {
            (
                l.mission,
                l.call.start,
                l.call.end,
                l.entry,
                l.team,
                l.service,
            )
        });
        calls.dedup();
        StrategyLinks { calls }
    }

    /// The calls that an entry refines: for references from a strategy file.
    pub fn of_entry(&self, entry: ServiceEntryRef) -> impl Iterator<Item = &CallLink> {
        self.calls.iter().filter(move |l| l.entry == entry)
    }
}

/// Checks `strategies` against the catalog and `missions`, and links the
/// missions' calls to the strategy entries. Diagnostics point into the
/// strategy files (with related positions in the missions).
pub fn cross_check(
    strategies: &[&Strategy],
    missions: &[&CheckedMission],
    catalog: &Catalog,
) -> (StrategyLinks, Vec<Diagnostic>) {
    let mut cx = Cross {
        catalog,
        diagnostics: Vec::new(),
        links: Vec::new(),
    };
    for strategy in strategies {
        cx.against_catalog(strategy);
    }
    cx.duplicates_across_files(strategies);
    if !missions.is_empty() {
        let summaries: Vec<MissionSummary<'_>> =
            missions.iter().map(|a| MissionSummary::new(a)).collect();
        for strategy in strategies {
            cx.against_missions(strategy, &summaries);
        }
    }
    let mut calls = cx.links;
    calls.sort_by_key(|l| {
        (
            l.mission,
            l.call.start,
            l.call.end,
            l.entry,
            l.team,
            l.service,
        )
    });
    calls.dedup();
    (StrategyLinks { calls }, cx.diagnostics)
}

/// A robot type's task library, when it is fully known (see the module docs).
pub fn task_library(robot: &RobotType) -> Option<Vec<&str>> {
    let mut tasks = vec![CONTROL_TASK];
    let implementations = robot
        .values
        .iter()
        .map(|v| &v.implementation)
        .chain(robot.services.iter().map(|s| &s.implementation));
    for implementation in implementations {
        match implementation {
            Implementation::Task(t) => tasks.push(t),
            Implementation::Graph(_) | Implementation::Unspecified => return None,
        }
    }
    tasks.sort_unstable();
    tasks.dedup();
    Some(tasks)
}

/// `a, b, c` with at most `max` items.
fn list(names: &[&str], max: usize) -> String {
    let mut out = names
        .iter()
        .take(max)
        .copied()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > max {
        out.push_str(", …");
    }
    out
}

/// `names` without repetitions, in their first order.
fn distinct<'a>(names: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for name in names {
        if !out.contains(&name) {
            out.push(name);
        }
    }
    out
}

/// One built-in service call run by a team's composite service.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuiltinCall {
    /// The catalog's name of the service.
    pub name: ast::Name,
    /// The called name's range in the mission.
    pub span: Span,
    pub plan: PlanId,
    /// The composite service that runs it (directly or through functions).
    pub service: ServiceId,
}

/// The built-in calls that `team`'s composite services run, service by
/// service (a call inside a function once per service running it): what a
/// strategy of the team may refine.
pub fn team_calls(analysis: &CheckedMission, team: TeamId) -> Vec<BuiltinCall> {
    let Some(team) = analysis.mission.teams.get(team.0 as usize) else {
        return Vec::new();
    };
    let mut calls = Vec::new();
    for (index, service) in team.services.iter().enumerate() {
        let walked = walk_service(analysis, service);
        calls.extend(walked.calls.into_iter().map(|(name, span)| BuiltinCall {
            name,
            span,
            plan: service.plan,
            service: ServiceId::new(index),
        }));
    }
    calls
}

/// What the cross checks need of one mission, computed once.
struct MissionSummary<'a> {
    analysis: &'a CheckedMission,
    /// Per team: the built-in calls its composite services run.
    calls: Vec<Vec<BuiltinCall>>,
    /// Per team: its composite services that elect a leader.
    electing: Vec<HashSet<ServiceId>>,
}

impl<'a> MissionSummary<'a> {
    fn new(analysis: &'a CheckedMission) -> Self {
        let mission = &analysis.mission;
        let mut calls = Vec::new();
        let mut electing = Vec::new();
        for team in &mission.teams {
            let mut team_calls = Vec::new();
            let mut team_electing = HashSet::new();
            for (index, service) in team.services.iter().enumerate() {
                let index = ServiceId::new(index);
                let walked = walk_service(analysis, service);
                if walked.elects_leader {
                    team_electing.insert(index);
                }
                team_calls.extend(walked.calls.into_iter().map(|(name, span)| BuiltinCall {
                    name,
                    span,
                    plan: service.plan,
                    service: index,
                }));
            }
            calls.push(team_calls);
            electing.push(team_electing);
        }
        MissionSummary {
            analysis,
            calls,
            electing,
        }
    }

    fn mission(&self) -> &'a Mission {
        &self.analysis.mission
    }
}

/// What running one composite service involves.
#[derive(Default)]
struct Walked {
    /// Built-in calls (catalog name, range of the called name).
    calls: Vec<(ast::Name, Span)>,
    /// Whether it has a `[[ leader(...) ... ]]` statement.
    elects_leader: bool,
}

/// The built-in calls and leader elections of a composite service, through
/// the functions it calls (each function walked once; a worklist, not
/// recursion, so that long call chains cannot overflow the stack).
fn walk_service(analysis: &CheckedMission, service: &crate::sema::Service) -> Walked {
    let mission = &analysis.mission;
    let mut out = Walked::default();
    let Some(syntax) = analysis.service_syntax(service) else {
        return out;
    };
    let mut seen: HashSet<FunctionId> = HashSet::new();
    let mut pending: Vec<&ast::Block> = vec![&syntax.body];
    while let Some(block) = pending.pop() {
        block.walk(&mut |stmt| match &stmt.kind {
            StmtKind::Call(call) => match symbol_at(mission, call.name.span) {
                Some(Symbol::BuiltinService(name)) => {
                    out.calls.push((name.clone(), call.name.span))
                }
                Some(Symbol::Function(f)) if seen.insert(*f) => {
                    let body = mission
                        .functions
                        .get(f.0 as usize)
                        .and_then(|info| analysis.function_syntax(info))
                        .map(|function| &function.body);
                    pending.extend(body);
                }
                _ => {}
            },
            StmtKind::Group(g) if g.arms.iter().any(|arm| arm.kind == ArmKind::Leader) => {
                out.elects_leader = true;
            }
            _ => {}
        });
    }
    out
}

/// What the name written at exactly `span` refers to.
fn symbol_at(mission: &Mission, span: Span) -> Option<&Symbol> {
    let occurrences = &mission.occurrences;
    let start = occurrences.partition_point(|o| o.span.start < span.start);
    occurrences[start..]
        .iter()
        .take_while(|o| o.span.start == span.start)
        .find(|o| o.span == span)
        .map(|o| &o.symbol)
}

struct Cross<'c> {
    catalog: &'c Catalog,
    diagnostics: Vec<Diagnostic>,
    links: Vec<CallLink>,
}

/// Every `TargetRobot` of a strategy's entries with a name.
fn all_targets(strategy: &Strategy) -> impl Iterator<Item = &Named> {
    let values = strategy.values.iter().flat_map(|v| v.targets.iter());
    let services = strategy.services.iter().flat_map(|s| s.targets.iter());
    values.chain(services).filter_map(|t| t.name.as_ref())
}

impl Cross<'_> {
    fn report(
        &mut self,
        code: Code,
        file: FileId,
        span: Span,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        diag::push(
            &mut self.diagnostics,
            Diagnostic::new(code, file, span, message),
        )
    }

    /// A report of `written`, which is none of `candidates`, with the nearest
    /// candidate suggested.
    fn report_unknown(
        &mut self,
        code: Code,
        file: FileId,
        span: Span,
        written: &str,
        candidates: &[&str],
        message: String,
    ) -> &mut Diagnostic {
        let guess = did_you_mean(written, candidates.iter().copied());
        self.report(code, file, span, message).suggest(guess)
    }

    /// `code` for an entry `name` that some of `targets` lack: `missing` gives,
    /// for a robot type without it, what the type has instead.
    fn not_of_targets(
        &mut self,
        code: Code,
        file: FileId,
        name: &Named,
        targets: &[(&Named, RobotTypeId)],
        missing: impl Fn(&RobotType) -> Option<Vec<&str>>,
        message: impl Fn(&RobotType, &str) -> String,
    ) {
        let catalog = self.catalog;
        for (_, id) in targets {
            let robot = catalog.get(*id);
            if let Some(names) = missing(robot) {
                let message = message(robot, &list(&names, 12));
                self.report_unknown(code, file, name.span, &name.name, &names, message);
            }
        }
    }

    /// `code` (E091, E092) for a plan the team does not have.
    fn no_plan(&mut self, code: Code, file: FileId, mission: &Mission, team: &Team, plan: &Named) {
        let plans: Vec<&str> = team.plans.iter().map(|p| p.name.as_str()).collect();
        let message = format!(
            "team {} has no plan `{}` (its plans are {})",
            team.name,
            plan.name,
            list(&plans, 12)
        );
        let related = Self::team_related(mission, team);
        self.report_unknown(code, file, plan.span, &plan.name, &plans, message)
            .related
            .push(related);
    }

    /// The known robot types among `targets`.
    fn known<'t>(&self, targets: &'t [TargetRobot]) -> Vec<(&'t Named, RobotTypeId)> {
        targets
            .iter()
            .filter_map(|t| t.name.as_ref())
            .filter_map(|n| self.catalog.lookup(&n.name).map(|id| (n, id)))
            .collect()
    }

    /// E125: the same service (and plan) declared a group service twice.
    fn duplicate_group_services(&mut self, strategy: &Strategy) {
        let declared: Vec<&GroupService> = strategy
            .grouping
            .iter()
            .flat_map(|g| &g.group_services)
            .collect();
        for (i, later) in declared.iter().enumerate() {
            let Some(name) = &later.name else {
                continue;
            };
            let plan_of = |g: &GroupService| g.plan.as_ref().map(|p| p.name.clone());
            let Some(first) = declared[..i].iter().find(|earlier| {
                earlier.name.as_ref().is_some_and(|n| n.name == name.name)
                    && plan_of(earlier) == plan_of(later)
            }) else {
                continue;
            };
            let message = format!("`{}` is already declared a group service", name.name);
            self.report(
                Code::GroupServiceDuplicate,
                strategy.file,
                later.span,
                message,
            )
            .related
            .push(Related {
                file: strategy.file,
                span: first.span,
                message: "first declared here".to_string(),
            });
        }
    }

    // --- against the catalog ---------------------------------------------------

    fn against_catalog(&mut self, strategy: &Strategy) {
        let file = strategy.file;
        let catalog = self.catalog;
        self.duplicate_group_services(strategy);
        for name in all_targets(strategy) {
            if catalog.lookup(&name.name).is_none() {
                let guess = did_you_mean(&name.name, catalog.names());
                self.report(
                    Code::UnknownRobotType,
                    file,
                    name.span,
                    format!("unknown robot type `{}`", name.name),
                )
                .suggest(guess);
            }
        }
        for value in &strategy.values {
            let targets = self.known(&value.targets);
            if let Some(name) = &value.name {
                self.not_of_targets(
                    Code::StrategyUnknownValue,
                    file,
                    name,
                    &targets,
                    |robot| {
                        let values = robot.values.iter().map(|v| v.name.as_str());
                        robot.value(&name.name).is_none().then(|| values.collect())
                    },
                    |robot, names| {
                        format!(
                            "`{}` is not a value of {} (its values are {names})",
                            name.name, robot.name
                        )
                    },
                );
            }
            let params = value.tasks.iter().flat_map(|t| t.parameters.iter());
            self.tasks(file, params, &targets);
        }
        for service in &strategy.services {
            let targets = self.known(&service.targets);
            if let Some(name) = &service.name {
                self.not_of_targets(
                    Code::StrategyServiceNotProvided,
                    file,
                    name,
                    &targets,
                    |robot| {
                        let services = robot.services.iter().map(|s| s.name.as_str());
                        robot
                            .service(&name.name)
                            .is_none()
                            .then(|| services.collect())
                    },
                    |robot, names| {
                        format!(
                            "{} does not provide a service `{}` (its services are {names})",
                            robot.name, name.name
                        )
                    },
                );
            }
            self.tasks(file, service.parameters(), &targets);
            self.passed(file, service, &targets);
        }
    }

    /// E042: a parameter of an actuator or algorithm that passes its task
    /// nothing (`ServiceEntry::passed`, the rule refinement applies) for a
    /// target's service, or any type's that provides it when none is named.
    fn passed(&mut self, file: FileId, entry: &ServiceEntry, targets: &[(&Named, RobotTypeId)]) {
        let Some(service) = &entry.name else { return };
        let catalog = self.catalog;
        let types: Vec<&RobotType> = match targets.is_empty() {
            true => catalog.types().map(|(_, r)| r).collect(),
            false => targets.iter().map(|(_, id)| catalog.get(*id)).collect(),
        };
        let params: Vec<Vec<&str>> = types
            .iter()
            .filter_map(|r| r.service(&service.name))
            .map(|def| def.params.iter().map(|p| p.name.as_str()).collect())
            .collect();
        let commands = entry
            .actions
            .iter()
            .flat_map(|a| &a.tasks)
            .filter(|t| t.kind != TaskUseKind::CheckSensor)
            .flat_map(|t| t.parameters.iter().map(move |p| (t, p)));
        for (task_use, p) in commands {
            if !params
                .iter()
                .any(|ps| entry.passed(p, ps) == Passed::Nothing)
            {
                continue;
            }
            let what = task_use
                .name
                .as_ref()
                .map_or(String::new(), |n| format!(" `{}`", n.name));
            let message = match &p.name {
                Some(name) => format!(
                    "`{}` gives {}{what} nothing: it has no `value`, and no parameter of the service `{}` or of its actions is named `{}` (write `value=\"...\"`, or name the variable or the service's parameter it passes)",
                    name.name,
                    task_use.kind.tag(),
                    service.name,
                    name.name
                ),
                None => format!(
                    "this parameter gives {}{what} nothing: it has neither a `name` nor a `value`",
                    task_use.kind.tag()
                ),
            };
            let span = p.name.as_ref().map_or(p.span, |n| n.span);
            self.report(Code::StrategyPassesNothing, file, span, message);
        }
    }

    /// E094 for `srcTask`/`dstTask` outside a target's task library.
    fn tasks<'p>(
        &mut self,
        file: FileId,
        params: impl Iterator<Item = &'p Parameter>,
        targets: &[(&Named, RobotTypeId)],
    ) {
        let catalog = self.catalog;
        let libraries: Vec<(&RobotType, Vec<&str>)> = targets
            .iter()
            .map(|(_, id)| catalog.get(*id))
            .filter_map(|r| task_library(r).map(|l| (r, l)))
            .collect();
        if libraries.is_empty() {
            return;
        }
        for p in params {
            for (key, task) in [("srcTask", &p.src_task), ("dstTask", &p.dst_task)] {
                let Some(task) = task else { continue };
                for (robot, library) in &libraries {
                    if library.contains(&task.name.as_str()) {
                        continue;
                    }
                    let message = format!(
                        "`{}` ({key}) is not a task of {} (its tasks are {})",
                        task.name,
                        robot.name,
                        list(library, 16)
                    );
                    self.report_unknown(
                        Code::StrategyUnknownTask,
                        file,
                        task.span,
                        &task.name,
                        library,
                        message,
                    );
                }
            }
        }
    }

    /// E085 for a service of a plan refined for the same robot type in two
    /// strategy files of the same team.
    fn duplicates_across_files(&mut self, strategies: &[&Strategy]) {
        // (team, plan, service, robot) → where first refined.
        let mut first: HashMap<(String, String, String, String), (FileId, Span)> = HashMap::new();
        for strategy in strategies {
            let Some(team) = &strategy.team else { continue };
            let mut here: Vec<((String, String, String, String), Span)> = Vec::new();
            for service in &strategy.services {
                let (Some(plan), Some(name)) = (&service.plan, &service.name) else {
                    continue;
                };
                for robot in service.targets.iter().filter_map(|t| t.name.as_ref()) {
                    let key = (
                        team.name.clone(),
                        plan.name.clone(),
                        name.name.clone(),
                        robot.name.clone(),
                    );
                    match first.get(&key) {
                        Some(&(file, span)) if file != strategy.file => {
                            let message = format!(
                                "the service `{}` of plan {} is already refined for {} in another strategy file of {}",
                                name.name, plan.name, robot.name, team.name
                            );
                            self.report(
                                Code::StrategyDuplicate,
                                strategy.file,
                                robot.span,
                                message,
                            )
                            .related
                            .push(Related {
                                file,
                                span,
                                message: "first refined here".to_string(),
                            });
                        }
                        Some(_) => {}
                        None => here.push((key, robot.span)),
                    }
                }
            }
            for (key, span) in here {
                first.entry(key).or_insert((strategy.file, span));
            }
        }
    }

    // --- against the missions --------------------------------------------------

    fn against_missions(&mut self, strategy: &Strategy, missions: &[MissionSummary<'_>]) {
        let Some(team_name) = &strategy.team else {
            return;
        };
        let teams: Vec<(&MissionSummary<'_>, TeamId)> = missions
            .iter()
            .filter_map(|m| m.mission().team_by_name(&team_name.name).map(|t| (m, t)))
            .collect();
        if teams.is_empty() {
            let names = distinct(
                missions
                    .iter()
                    .flat_map(|m| m.mission().teams.iter())
                    .map(|team| team.name.as_str()),
            );
            let message = format!(
                "no mission of this check declares a team `{}` (the teams are {})",
                team_name.name,
                list(&names, 12)
            );
            self.report_unknown(
                Code::StrategyUnknownTeam,
                strategy.file,
                team_name.span,
                &team_name.name,
                &names,
                message,
            );
            return;
        }
        for (summary, team) in teams {
            self.against_team(strategy, summary, team);
        }
    }

    /// A related position: the team's declaration in its mission.
    fn team_related(mission: &Mission, team: &Team) -> Related {
        Related {
            file: mission.file,
            span: team.name_span,
            message: format!("team {} is declared here", team.name),
        }
    }

    fn against_team(&mut self, strategy: &Strategy, summary: &MissionSummary<'_>, team_id: TeamId) {
        let mission = summary.mission();
        let team = mission.team(team_id);
        let file = strategy.file;
        let catalog = self.catalog;

        // Target robots: robot types of the team.
        let team_types: Vec<RobotTypeId> =
            team.robots.iter().filter_map(|r| r.robot_type).collect();
        // A robot of an unknown type (reported in the mission) may be the one meant.
        let all_known = team.robots.iter().all(|r| r.robot_type.is_some());
        for target in all_targets(strategy).filter(|_| all_known) {
            let Some(id) = catalog.lookup(&target.name) else {
                continue; // E010, reported against the catalog
            };
            if team_types.contains(&id) {
                continue;
            }
            let type_names = distinct(team.robots.iter().map(|r| r.type_name.as_str()));
            let message = format!(
                "{} is not a robot type of team {} (its robot types are {})",
                target.name,
                team.name,
                list(&type_names, 12)
            );
            let related = Self::team_related(mission, team);
            self.report_unknown(
                Code::StrategyRobotNotInTeam,
                file,
                target.span,
                &target.name,
                &type_names,
                message,
            )
            .related
            .push(related);
        }

        // Services: called by the team in that plan.
        for (index, entry) in strategy.services.iter().enumerate() {
            let (Some(plan), Some(name)) = (&entry.plan, &entry.name) else {
                continue;
            };
            let Some(plan_index) = team.plan_by_name(&plan.name) else {
                self.no_plan(Code::StrategyServiceNotCalled, file, mission, team, plan);
                continue;
            };
            // The catalog's name of the service (`stand_by` is `standby`).
            let Some(service_name) = catalog
                .types()
                .find_map(|(_, r)| r.service(&name.name))
                .map(|s| s.name.as_str())
            else {
                continue; // no robot type provides it: E095
            };
            let calls = &summary.calls[team_id.0 as usize];
            let entry_ref = ServiceEntryRef { file, index };
            let mut linked = false;
            for call in calls
                .iter()
                .filter(|c| c.plan == plan_index && c.name == service_name)
            {
                linked = true;
                self.links.push(CallLink {
                    mission: mission.file,
                    call: call.span,
                    team: team_id,
                    service: call.service,
                    entry: entry_ref,
                });
            }
            if linked {
                continue;
            }
            let mut elsewhere: Vec<&str> = calls
                .iter()
                .filter(|c| c.name == service_name)
                .map(|c| team.plans[c.plan.index()].name.as_str())
                .collect();
            elsewhere.sort_unstable();
            elsewhere.dedup();
            let mut message = format!(
                "no composite service of {} calls `{}` in plan {}",
                team.name, name.name, plan.name
            );
            match elsewhere.as_slice() {
                [] => message.push_str(&format!(": team {} never calls it", team.name)),
                [one] => message.push_str(&format!(" (it is called in plan {one})")),
                more => message.push_str(&format!(" (it is called in plans {})", more.join(", "))),
            }
            let related = Self::team_related(mission, team);
            self.report(Code::StrategyServiceNotCalled, file, name.span, message)
                .related
                .push(related);
        }

        // Leader selection: a composite service of the team that elects a leader.
        let leader = strategy
            .grouping
            .as_ref()
            .and_then(|g| g.leader_selection.as_ref());
        if let Some(LeaderSelection {
            plan: Some(plan),
            service: Some(service),
            ..
        }) = leader
        {
            self.leader_service(file, summary, team_id, plan, service);
        }

        // Group services: built-in services the team calls.
        let group_services = strategy.grouping.iter().flat_map(|g| &g.group_services);
        for declared in group_services {
            self.group_service(file, summary, team_id, declared);
        }

        // The owner of the shared values: the team's library, one of its robots.
        let owner = strategy
            .grouping
            .as_ref()
            .and_then(|g| g.shared_owner.as_ref());
        if let Some(owner) = owner {
            self.shared_owner(file, mission, team, owner);
        }
    }

    /// E130 unless `owner` names the team's library task (`<Team>Shared`),
    /// E131 unless it names a robot of the team.
    fn shared_owner(&mut self, file: FileId, mission: &Mission, team: &Team, owner: &SharedOwner) {
        let library = format!("{}Shared", team.name);
        if let Some(named) = owner.library.as_ref().filter(|l| l.name != library) {
            let message = format!(
                "`{}` is not the library task of team {}: its shared information is in `{library}`",
                named.name, team.name
            );
            let related = Self::team_related(mission, team);
            self.report_unknown(
                Code::SharedOwnerUnknownLibrary,
                file,
                named.span,
                &named.name,
                &[library.as_str()],
                message,
            )
            .related
            .push(related);
        }
        let Some(robot) = &owner.robot else {
            return;
        };
        let robots: Vec<&str> = team.robots.iter().map(|r| r.name.as_str()).collect();
        if robots.contains(&robot.name.as_str()) {
            return;
        }
        let message = format!(
            "team {} has no robot `{}` (its robots: {})",
            team.name,
            robot.name,
            list(&robots, 12)
        );
        let related = Self::team_related(mission, team);
        self.report_unknown(
            Code::SharedOwnerUnknownRobot,
            file,
            robot.span,
            &robot.name,
            &robots,
            message,
        )
        .related
        .push(related);
    }

    /// E124 unless the team calls `declared`'s service (in its plan, if it
    /// names one): the robots that run those calls are the group.
    fn group_service(
        &mut self,
        file: FileId,
        summary: &MissionSummary<'_>,
        team_id: TeamId,
        declared: &GroupService,
    ) {
        let mission = summary.mission();
        let team = mission.team(team_id);
        let Some(name) = &declared.name else {
            return;
        };
        let plan = match &declared.plan {
            None => None,
            Some(plan) => match team.plan_by_name(&plan.name) {
                Some(index) => Some(index),
                None => {
                    self.no_plan(Code::GroupServiceNotCalled, file, mission, team, plan);
                    return;
                }
            },
        };
        let calls = &summary.calls[team_id.0 as usize];
        let in_plan = |c: &&BuiltinCall| plan.is_none_or(|p| c.plan == p);
        // The catalog's name of the service (`stand_by` is `standby`).
        let catalog_name = self
            .catalog
            .types()
            .find_map(|(_, r)| r.service(&name.name))
            .map(|s| s.name.as_str());
        if calls
            .iter()
            .filter(in_plan)
            .any(|c| Some(c.name.as_str()) == catalog_name)
        {
            return;
        }
        let mut called: Vec<&str> = calls
            .iter()
            .filter(in_plan)
            .map(|c| c.name.as_str())
            .collect();
        called.sort_unstable();
        called.dedup();
        let place = match &declared.plan {
            Some(plan) => format!(" in plan {}", plan.name),
            None => String::new(),
        };
        let calls_instead = if called.is_empty() {
            "it calls no built-in service there".to_string()
        } else {
            format!("it calls {}", list(&called, 12))
        };
        let message = format!(
            "team {} never calls `{}`{place}, so no robot would be in its group ({calls_instead})",
            team.name, name.name,
        );
        let related = Self::team_related(mission, team);
        self.report_unknown(
            Code::GroupServiceNotCalled,
            file,
            name.span,
            &name.name,
            &called,
            message,
        )
        .related
        .push(related);
    }

    fn leader_service(
        &mut self,
        file: FileId,
        summary: &MissionSummary<'_>,
        team_id: TeamId,
        plan: &Named,
        service: &Named,
    ) {
        let mission = summary.mission();
        let team = mission.team(team_id);
        let Some(plan_index) = team.plan_by_name(&plan.name) else {
            self.no_plan(
                Code::StrategyUnknownCompositeService,
                file,
                mission,
                team,
                plan,
            );
            return;
        };
        let Some(index) = team.service_in_plan(plan_index, &service.name) else {
            let names: Vec<&str> = team
                .services
                .iter()
                .filter(|s| s.plan == plan_index)
                .map(|s| s.name.as_str())
                .collect();
            let message = format!(
                "team {} has no composite service `{}` in plan {} (its services there are {})",
                team.name,
                service.name,
                plan.name,
                list(&names, 12)
            );
            let related = Self::team_related(mission, team);
            self.report_unknown(
                Code::StrategyUnknownCompositeService,
                file,
                service.span,
                &service.name,
                &names,
                message,
            )
            .related
            .push(related);
            return;
        };
        if !summary.electing[team_id.0 as usize].contains(&index) {
            let s = &team.services[index.index()];
            let message = format!(
                "`{}` elects no leader: it has no `[[ leader(...) ... ]]` statement, so this leader selection is never used",
                team.service_path(index)
            );
            let d = self.report(
                Code::StrategyUnknownCompositeService,
                file,
                service.span,
                message,
            );
            d.related.push(Related {
                file: mission.file,
                span: s.name_span,
                message: "the composite service is defined here".to_string(),
            });
        }
    }
}
