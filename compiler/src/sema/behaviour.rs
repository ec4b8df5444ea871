//! Phase 3: modes and main blocks. `set` must name a service of that plan;
//! `case`/`catch`/`mode =` must name modes; every mode should be reachable from
//! the default, every thrown event caught, every service set somewhere.

use super::ir::*;
use super::{Checker, suggestion};
use crate::diag::{Code, Severity};
use crate::fasthash::{FastMap, FastSet};
use crate::span::Span;
use crate::syntax::ast::Name;
use crate::syntax::ast::{self, Item, SetTarget};
use std::collections::hash_map::Entry;

impl<'a> Checker<'a> {
    pub(super) fn check_behaviour(&mut self, source: &'a ast::SourceFile) {
        for item in &source.items {
            match item {
                Item::Mode(m) => self.mode_sets(m),
                Item::Main(m) => self.main(m),
                _ => {}
            }
        }
        for t in 0..self.mission.teams.len() {
            let team = TeamId(t as u32);
            self.uncaught_events(team);
            self.catches_never_thrown(team);
            self.unreachable_modes(team);
            self.services_never_set(team);
        }
        for f in 0..self.mission.functions.len() {
            let function = &self.mission.functions[f];
            if !function.called {
                let (span, name) = (function.name_span, function.name.clone());
                self.diagnostics.report(
                    Code::FunctionNeverCalled,
                    span,
                    format!("the function `{name}` is never called"),
                );
            }
        }
    }

    /// The team and mode index of a mode definition, unless it was rejected.
    fn declared_mode(&self, m: &ast::ModeDef) -> Option<(TeamId, ModeId)> {
        let team = self.team_id(&m.team.name)?;
        let mode = self.team(team).mode_by_name(&m.name.name)?;
        (self.team(team).modes[mode.index()].span == m.span).then_some((team, mode))
    }

    fn mode_sets(&mut self, m: &ast::ModeDef) {
        let Some(team) = self.team_id(&m.team.name) else {
            return;
        };
        // `None` for a second definition of the mode (already reported): its sets
        // are still checked.
        let mode = self.declared_mode(m).map(|(_, mode)| mode);
        let mut sets: Vec<ModeSet> = Vec::new();
        // Where each plan is first set, without scanning `sets`.
        let mut first_sets: FastMap<PlanId, Span> = FastMap::default();
        for set in &m.sets {
            if let Some(p) = &set.timeout {
                self.period(p);
            }
            let plan = self.team(team).plan_by_name(&set.plan.name);
            match plan {
                Some(plan) => self.occurrence(set.plan.span, Symbol::Plan { team, plan }, false),
                None => {
                    let t = self.team(team);
                    let plans: Vec<&str> = t.plans.iter().map(|p| p.name.as_str()).collect();
                    let guess = suggestion(&set.plan.name, plans.iter().copied());
                    let message = format!(
                        "team {} has no plan `{}` (its plans: {})",
                        t.name,
                        set.plan.name,
                        if plans.is_empty() {
                            "none".to_string()
                        } else {
                            plans.join(", ")
                        }
                    );
                    self.diagnostics
                        .report(Code::ServiceNotInPlan, set.plan.span, message)
                        .suggest(guess);
                }
            }
            let first = plan.and_then(|plan| match first_sets.entry(plan) {
                Entry::Occupied(first) => Some(*first.get()),
                Entry::Vacant(at) => {
                    at.insert(set.span);
                    None
                }
            });
            if let Some(first) = first {
                self.diagnostics
                    .report(
                        Code::PlanSetTwice,
                        set.plan.span,
                        format!("this mode already sets the plan `{}`", set.plan.name),
                    )
                    .relate(first, "first set here");
            }
            let service = match (&set.service, plan) {
                (SetTarget::Off(_), _) => None,
                (SetTarget::Service(name), Some(plan)) => self.set_target(team, plan, name),
                (SetTarget::Service(_), None) => None,
            };
            sets.push(ModeSet {
                plan,
                service,
                timeout_ms: set.timeout.as_ref().and_then(|p| p.millis()),
                span: set.span,
            });
        }
        match mode {
            Some(mode) => self.team_mut(team).modes[mode.index()].sets = sets,
            None => self
                .set_by_duplicate_modes
                .extend(sets.iter().filter_map(|s| s.service).map(|s| (team, s))),
        }
    }

    fn set_target(&mut self, team: TeamId, plan: PlanId, name: &ast::Ident) -> Option<ServiceId> {
        let t = self.team(team);
        if let Some(service) = t.service_in_plan(plan, &name.name) {
            self.occurrence(name.span, Symbol::Service { team, service }, false);
            return Some(service);
        }
        let plan_name = &t.plans[plan.index()].name;
        let elsewhere = t
            .services
            .iter()
            .find(|s| s.name == name.name)
            .map(|s| t.plans[s.plan.index()].name.clone());
        let in_plan: Vec<&str> = t
            .services
            .iter()
            .filter(|s| s.plan == plan)
            .map(|s| s.name.as_str())
            .collect();
        let guess = suggestion(&name.name, in_plan);
        let message = match elsewhere {
            Some(other) => format!(
                "plan {plan_name} of team {} has no service `{}`; `{}` belongs to plan {other}",
                t.name, name.name, name.name
            ),
            None => format!(
                "plan {plan_name} of team {} has no service `{}`",
                t.name, name.name
            ),
        };
        self.diagnostics
            .report(Code::ServiceNotInPlan, name.span, message)
            .suggest(guess);
        None
    }

    /// Resolves a mode name in a main block, reporting it if undefined.
    fn mode_ref(&mut self, team: TeamId, name: &ast::Ident) -> Option<ModeId> {
        let mode = self.lookup_mode_ref(team, name);
        if mode.is_none() {
            self.mains_with_unknown_modes.insert(team);
        }
        mode
    }

    fn lookup_mode_ref(&mut self, team: TeamId, name: &ast::Ident) -> Option<ModeId> {
        match self.team(team).mode_by_name(&name.name) {
            Some(mode) => {
                self.occurrence(name.span, Symbol::Mode { team, mode }, false);
                Some(mode)
            }
            None => {
                let t = self.team(team);
                let guess = suggestion(&name.name, t.modes.iter().map(|m| m.name.as_str()));
                let message = format!("team {} has no mode `{}`", t.name, name.name);
                self.diagnostics
                    .report(Code::UnknownMode, name.span, message)
                    .suggest(guess);
                None
            }
        }
    }

    fn main(&mut self, m: &ast::MainDef) {
        let Some(team) = self.header_team(&m.team, "a main block") else {
            return;
        };
        if let Some(first) = &self.team(team).main {
            let first = first.span;
            self.diagnostics
                .report(
                    Code::DuplicateMain,
                    m.main_span,
                    format!("team {} already has a main block", m.team.name),
                )
                .relate(first, "first main block here");
            return;
        }
        let default = match &m.default {
            Some(name) => self.mode_ref(team, name),
            None => {
                self.diagnostics.report(
                    Code::MissingDefault,
                    m.team.span.cover(m.main_span),
                    format!(
                        "the main block of {} has no `default: mode = ...`, so its robots would not know which mode to start in",
                        m.team.name
                    ),
                );
                None
            }
        };
        let mut transitions = Vec::new();
        // The first case of each mode, and below the first catch of each
        // event, by hash: a main may have thousands.
        let mut cased: FastMap<ModeId, Span> = FastMap::default();
        for case in &m.cases {
            let from = self.mode_ref(team, &case.mode);
            if let Some(from) = from {
                if let Some(&first) = cased.get(&from) {
                    self.diagnostics
                        .report(
                            Code::DuplicateCase,
                            case.mode.span,
                            format!("there is already a case for the mode `{}`", case.mode.name),
                        )
                        .relate(first, "first case here");
                } else {
                    cased.insert(from, case.mode.span);
                }
            }
            let mut caught: FastMap<&Name, Span> = FastMap::default();
            for catch in &case.catches {
                self.caught(team, &catch.event);
                if let Some(&first) = caught.get(&catch.event.name) {
                    self.diagnostics
                        .report(
                            Code::DuplicateCatch,
                            catch.event.span,
                            format!("this case already catches `{}`", catch.event.name),
                        )
                        .relate(first, "first caught here");
                } else {
                    caught.insert(&catch.event.name, catch.event.span);
                }
                let to = self.mode_ref(team, &catch.target);
                if let (Some(from), Some(to)) = (from, to) {
                    transitions.push(Transition {
                        from,
                        event: catch.event.name.clone(),
                        event_span: catch.event.span,
                        to,
                        span: catch.span,
                        never_thrown: false,
                    });
                }
            }
        }
        self.team_mut(team).main = Some(Main {
            span: m.span,
            default,
            transitions,
            unreachable: Vec::new(),
        });
    }

    fn caught(&mut self, team: TeamId, event: &ast::Ident) {
        self.event_occurrence(team, event);
        self.team_mut(team)
            .event_mut(&event.name)
            .caught_at
            .push(event.span);
    }

    fn uncaught_events(&mut self, team: TeamId) {
        let t = self.team(team);
        if t.main.is_none() {
            let span = t.name_span;
            let message = format!(
                "team {} has no main block, so its robots do nothing",
                t.name
            );
            self.diagnostics
                .report(Code::TeamWithoutMain, span, message);
            return;
        }
        let caught: Vec<Name> = t
            .events
            .iter()
            .filter(|e| !e.caught_at.is_empty())
            .map(|e| e.name.clone())
            .collect();
        let uncaught: Vec<(Name, Vec<crate::span::Span>)> = t
            .events
            .iter()
            .filter(|e| e.caught_at.is_empty())
            .map(|e| (e.name.clone(), e.thrown_at.clone()))
            .collect();
        let team_name = t.name.clone();
        for (name, spans) in uncaught {
            let guess = suggestion(&name, caught.iter().map(Name::as_str));
            for span in spans {
                self.diagnostics.report(
                    Code::EventNeverCaught,
                    span,
                    format!(
                        "the event `{name}` is thrown, but no mode of team {team_name} catches it"
                    ),
                )
                .suggest(guess.clone());
            }
        }
    }

    fn catches_never_thrown(&mut self, team: TeamId) {
        let Some(main) = &self.team(team).main else {
            return;
        };
        let t = self.team(team);
        let mut findings = Vec::new();
        let mut never_thrown = Vec::new();
        // The events each mode's services throw, gathered once per mode: a
        // mode may have many catches.
        let mut thrown_in: FastMap<ModeId, FastSet<&Name>> = FastMap::default();
        // An event another robot broadcasts may come in any mode.
        let told: FastSet<&Name> = t.events_told().collect();
        for (i, tr) in main.transitions.iter().enumerate() {
            let mode = &t.modes[tr.from.index()];
            let thrown = thrown_in.entry(tr.from).or_insert_with(|| {
                let services = mode.sets.iter().filter_map(|s| s.service);
                services
                    .flat_map(|s| &t.services[s.index()].throws)
                    .collect()
            });
            if !thrown.contains(&tr.event) && !told.contains(&tr.event) {
                never_thrown.push(i);
                findings.push((
                    tr.event_span,
                    format!(
                        "no service that mode {} runs throws `{}`, so this catch never fires there",
                        mode.name, tr.event
                    ),
                ));
            }
        }
        if let Some(main) = &mut self.team_mut(team).main {
            for i in never_thrown {
                main.transitions[i].never_thrown = true;
            }
        }
        for (span, message) in findings {
            self.diagnostics
                .report(Code::CatchNeverThrown, span, message)
                .severity = Severity::Hint;
        }
    }

    fn unreachable_modes(&mut self, team: TeamId) {
        // A catch or case naming an undefined mode is likely a typo of a mode
        // that would otherwise look unreachable.
        if self.mains_with_unknown_modes.contains(&team) {
            return;
        }
        let t = self.team(team);
        let Some(Main {
            default: Some(start),
            transitions,
            ..
        }) = &t.main
        else {
            return;
        };
        let mut leaving: FastMap<ModeId, Vec<ModeId>> = FastMap::default();
        for tr in transitions {
            leaving.entry(tr.from).or_default().push(tr.to);
        }
        let mut reached = FastSet::from_iter([*start]);
        let mut queue = vec![*start];
        while let Some(mode) = queue.pop() {
            for &to in leaving.get(&mode).into_iter().flatten() {
                if reached.insert(to) {
                    queue.push(to);
                }
            }
        }
        let default_name = t.modes[start.index()].name.clone();
        let unreachable: Vec<ModeId> = t.mode_ids().filter(|i| !reached.contains(i)).collect();
        let findings: Vec<(crate::span::Span, Name)> = unreachable
            .iter()
            .map(|&i| {
                (
                    t.modes[i.index()].name_span,
                    t.modes[i.index()].name.clone(),
                )
            })
            .collect();
        if let Some(main) = &mut self.team_mut(team).main {
            main.unreachable = unreachable;
        }
        for (span, name) in findings {
            self.diagnostics.report(
                Code::UnreachableMode,
                span,
                format!("the mode `{name}` can never be entered: no catch leads to it from the default mode {default_name}"),
            );
        }
    }

    fn services_never_set(&mut self, team: TeamId) {
        let t = self.team(team);
        let set: FastSet<ServiceId> = t
            .modes
            .iter()
            .flat_map(|m| m.sets.iter().filter_map(|s| s.service))
            .collect();
        let unused: Vec<(crate::span::Span, String)> = t
            .service_ids()
            .filter(|s| !set.contains(s) && !self.set_by_duplicate_modes.contains(&(team, *s)))
            .map(|s| (t.services[s.index()].name_span, t.service_path(s)))
            .collect();
        for (span, path) in unused {
            self.diagnostics.report(
                Code::ServiceNeverSet,
                span,
                format!("`{path}` is never set in any mode, so it never runs"),
            );
        }
    }
}
