//! Phase 3: modes and main blocks. `set` must name a service of that plan;
//! `case`/`catch`/`mode =` must name modes; every mode should be reachable from
//! the default, every thrown event caught, every service set somewhere.

use super::body::{ParamRef, Type, argument_literal};
use super::ir::*;
use super::{Checker, MAX_MODE_COPIES, suggestion};
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
            self.instantiate(TeamId(t as u32));
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

    /// The template of a mode with parameters, unless it was rejected.
    fn declared_template(&self, team: TeamId, m: &ast::ModeDef) -> Option<TemplateId> {
        let template = self.team(team).template_by_name(&m.name.name)?;
        (self.team(team).template(template).span == m.span).then_some(template)
    }

    fn mode_sets(&mut self, m: &ast::ModeDef) {
        let Some(team) = self.team_id(&m.team.name) else {
            return;
        };
        // `None` for a second definition of the mode (already reported): its sets
        // are still checked.
        let mode = self.declared_mode(m).map(|(_, mode)| mode);
        let template = match m.params_span {
            Some(_) => self.declared_template(team, m),
            None => None,
        };
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
            if let Some(service) = service {
                self.service_arguments(team, service, set, template);
            }
            sets.push(ModeSet {
                plan,
                service,
                args: set
                    .args
                    .as_ref()
                    .map(|a| a.args.clone())
                    .unwrap_or_default(),
                timeout_ms: set.timeout.as_ref().and_then(|p| p.millis()),
                span: set.span,
            });
        }
        match (mode, template) {
            (Some(mode), _) => self.team_mut(team).modes[mode.index()].sets = sets,
            (None, Some(template)) => self.team_mut(team).templates[template.index()].sets = sets,
            (None, None) => self
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

    /// Resolves a mode entered in a main block (`mode = M`, `mode =
    /// MOVE(kitchen)`, the default), reporting it if undefined: a mode with
    /// parameters entered with arguments is the mode of the machine for
    /// those arguments, made the first time they are given.
    fn mode_ref(
        &mut self,
        team: TeamId,
        name: &ast::Ident,
        args: Option<&ast::ArgList>,
    ) -> Option<ModeId> {
        let mode = match self.team(team).template_by_name(&name.name) {
            Some(template) => {
                let symbol = Symbol::ModeTemplate { team, template };
                self.occurrence(name.span, symbol, false);
                self.entered_template(team, template, name, args)
            }
            None => {
                let mode = self.lookup_mode_ref(team, name);
                if let (Some(_), Some(args)) = (mode, args) {
                    let message = format!(
                        "the mode `{}` takes no arguments (it has no parameters)",
                        name.name
                    );
                    self.diagnostics
                        .report(Code::ModeArgumentCount, args.span, message);
                }
                mode
            }
        };
        if mode.is_none() {
            self.mains_with_unknown_modes.insert(team);
        }
        mode
    }

    /// A mode named in `case (M):`: a mode of the machine, or a mode with
    /// parameters, whose catches then hold in each mode it is entered as.
    fn case_ref(&mut self, team: TeamId, name: &ast::Ident) -> Option<CaseFrom> {
        if let Some(template) = self.team(team).template_by_name(&name.name) {
            let symbol = Symbol::ModeTemplate { team, template };
            self.occurrence(name.span, symbol, false);
            return Some(CaseFrom::Template(template));
        }
        let mode = self.lookup_mode_ref(team, name).map(CaseFrom::Mode);
        if mode.is_none() {
            self.mains_with_unknown_modes.insert(team);
        }
        mode
    }

    /// `MOVE(kitchen)`: its arguments checked (E046 the count, E047 one
    /// not fixed, each recorded for its parameter's needs), then the mode
    /// of the machine for them.
    fn entered_template(
        &mut self,
        team: TeamId,
        template: TemplateId,
        name: &ast::Ident,
        args: Option<&ast::ArgList>,
    ) -> Option<ModeId> {
        let owner = ParamOwner::Mode(team, template);
        let given = args.map_or(&[][..], |a| a.args.as_slice());
        if !self.argument_count(owner, given.len(), args.map_or(name.span, |a| a.span)) {
            return None;
        }
        let mut fixed = true;
        for (index, arg) in given.iter().enumerate() {
            let callee = (owner, index as u32);
            match self.fixed_argument(team, arg) {
                Some(ty) => {
                    let literal = argument_literal(arg, &ty);
                    self.param_uses.argument(callee, ty, arg.span(), literal);
                }
                None => {
                    self.param_uses.unfixed(callee, arg.span());
                    fixed = false;
                }
            }
        }
        if !fixed {
            return None;
        }
        let t = self.team(team);
        let written: Vec<String> = given.iter().map(ast::Arg::written).collect();
        let instance_name = Name::new(format!("{}({})", name.name, written.join(", ")));
        if let Some(mode) = t.mode_by_name(&instance_name) {
            return Some(mode);
        }
        let declared = t.template(template);
        let mode = Mode {
            name: instance_name,
            name_span: declared.name_span,
            span: declared.span,
            // Filled once every mode's `set`s are checked (`instantiate`).
            sets: Vec::new(),
            instance: Some(ModeInstance {
                template,
                args: given.to_vec(),
            }),
        };
        let mode = self.team_mut(team).add_mode(mode);
        self.team_mut(team).templates[template.index()]
            .instances
            .push(mode);
        Some(mode)
    }

    /// Whether `given` arguments (written at `span`) are as many as
    /// `owner`'s parameters; E046 when not.
    fn argument_count(&mut self, owner: ParamOwner, given: usize, span: Span) -> bool {
        let params = self.mission.params(owner);
        let takes = params.len();
        if given == takes {
            return true;
        }
        let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
        let expected = match takes {
            0 => "no arguments".to_string(),
            1 => format!("1 argument ({})", names.join(", ")),
            n => format!("{n} arguments ({})", names.join(", ")),
        };
        // What this entry or `set` gives them is not known (value flow).
        for index in 0..takes {
            self.param_uses.unfixed((owner, index as u32), span);
        }
        let what = match owner {
            ParamOwner::Mode(..) => "mode",
            _ => "service",
        };
        let message = format!(
            "the {what} `{}` takes {expected}, but {given} {} given",
            self.mission.owner_name(owner),
            if given == 1 { "is" } else { "are" },
        );
        self.diagnostics
            .report(Code::ModeArgumentCount, span, message);
        false
    }

    /// The type of an argument fixed when the mission is written (a word,
    /// a string, a number, a period, `true`/`false`); E047 otherwise. A
    /// bare word is a word unless the team's robots read a value or the
    /// team has a variable of that name.
    fn fixed_argument(&mut self, team: TeamId, arg: &ast::Arg) -> Option<Type> {
        let expr = match arg {
            ast::Arg::Words { .. } => return Some(Type::Text),
            ast::Arg::Expr(e) => e,
        };
        let not_fixed = match &expr.kind {
            ast::ExprKind::Str(_) => return Some(Type::Text),
            ast::ExprKind::Number(n) if n.contains('.') => return Some(Type::Float),
            ast::ExprKind::Number(_) => return Some(Type::Int),
            ast::ExprKind::Period(p) => {
                self.period(p);
                return Some(Type::Period);
            }
            ast::ExprKind::Bool(_) => return Some(Type::Bool),
            ast::ExprKind::Error => return None,
            ast::ExprKind::Attr(attr) => match attr.segments.as_slice() {
                [name] => {
                    let catalog = self.catalog;
                    let read = self.team_types[team.0 as usize]
                        .iter()
                        .any(|(ty, _)| catalog.get(*ty).value(&name.name).is_some());
                    let variable = self.is_variable(team, &name.name);
                    if !read && !variable {
                        let word = Symbol::Constant(name.name.clone());
                        self.occurrence(name.span, word, false);
                        return Some(Type::Constant(name.name.clone()));
                    }
                    let what = if read { "a value" } else { "a team variable" };
                    format!(
                        "`{}` is {what} of team {}, read at run time (write `\"{}\"` for the word)",
                        name.name,
                        self.team(team).name,
                        name.name
                    )
                }
                _ => format!("`{}` is a value read at run time", attr.dotted()),
            },
            _ => "an expression is worked out at run time".to_string(),
        };
        let message = format!(
            "{not_fixed}, but the arguments of a mode or a service in `set` must be known when the mission is written (a word, a string, a number)"
        );
        self.diagnostics
            .report(Code::ArgumentNotFixed, arg.span(), message);
        None
    }

    /// The arguments of `set(Plan, S(...))`: as many as `service`'s
    /// parameters (E046), each fixed (E047) or, in a mode with parameters,
    /// one of them (passed on to the service's parameter).
    fn service_arguments(
        &mut self,
        team: TeamId,
        service: ServiceId,
        set: &ast::SetStmt,
        template: Option<TemplateId>,
    ) {
        let owner = ParamOwner::Service(team, service);
        let given = set.args.as_ref().map_or(&[][..], |a| a.args.as_slice());
        let span = set.args.as_ref().map_or(set.span, |a| a.span);
        if !self.argument_count(owner, given.len(), span) {
            return;
        }
        for (index, arg) in given.iter().enumerate() {
            let callee = (owner, index as u32);
            if let Some((param, name)) = template.and_then(|t| self.mode_parameter(team, t, arg)) {
                self.param_uses.used(param);
                let (owner, index) = param;
                self.occurrence(arg.span(), Symbol::Parameter { owner, index }, false);
                self.param_uses
                    .argument(callee, Type::Param { param, name }, arg.span(), None);
            } else if let Some(ty) = self.fixed_argument(team, arg) {
                if let (Some(t), Type::Constant(word)) = (template, &ty) {
                    self.misspelt_mode_parameter(team, t, word, arg.span());
                }
                let literal = argument_literal(arg, &ty);
                self.param_uses.argument(callee, ty, arg.span(), literal);
            } else {
                self.param_uses.unfixed(callee, arg.span());
            }
        }
    }

    /// W007 for a word given in a mode's `set` that looks like one of the
    /// mode's parameters misspelt: it would be passed as the word.
    fn misspelt_mode_parameter(
        &mut self,
        team: TeamId,
        template: TemplateId,
        word: &Name,
        span: Span,
    ) {
        let params = &self.team(team).template(template).params;
        let Some(guess) = suggestion(word, params.iter().map(|p| p.name.as_str())) else {
            return;
        };
        let message = format!(
            "`{word}` is no parameter of the mode `{}`: it is given as the word `{word}`",
            self.team(team).template(template).name
        );
        self.diagnostics
            .report(Code::UnknownAttribute, span, message)
            .suggest(Some(guess));
    }

    /// The parameter of mode `template` that `arg` names, if it is one.
    fn mode_parameter(
        &self,
        team: TeamId,
        template: TemplateId,
        arg: &ast::Arg,
    ) -> Option<(ParamRef, Name)> {
        let ast::Arg::Expr(ast::Expr {
            kind: ast::ExprKind::Attr(attr),
            ..
        }) = arg
        else {
            return None;
        };
        let [name] = attr.segments.as_slice() else {
            return None;
        };
        let params = &self.team(team).template(template).params;
        let index = params.iter().position(|p| p.name == name.name)?;
        Some((
            (ParamOwner::Mode(team, template), index as u32),
            name.name.clone(),
        ))
    }

    /// Each mode entered with arguments gets its template's `set`s, each
    /// argument that is a parameter of the mode replaced by the argument
    /// the mode is entered with: the mode the hand-written copy is.
    ///
    /// Past [`MAX_MODE_COPIES`] in all, the first list of arguments that goes
    /// past it is E048 and its mode gets no `set`s (an error: nothing is
    /// built from the mission).
    fn instantiate(&mut self, team: TeamId) {
        let t = self.team(team);
        let mut filled = Vec::new();
        let mut past_limit = Vec::new();
        let mut copied = self.mode_copies;
        for mode in t.mode_ids() {
            let Some(instance) = &t.mode(mode).instance else {
                continue;
            };
            let template = t.template(instance.template);
            if copied + template.sets.len() > MAX_MODE_COPIES {
                let spans = instance.args.iter().map(ast::Arg::span);
                let span = spans.reduce(Span::cover).unwrap_or(template.name_span);
                past_limit.push((span, t.mode(mode).name.clone()));
                continue;
            }
            copied += template.sets.len();
            let sets: Vec<ModeSet> = template
                .sets
                .iter()
                .map(|set| ModeSet {
                    args: set
                        .args
                        .iter()
                        .map(
                            |arg| match self.mode_parameter(team, instance.template, arg) {
                                Some(((_, index), _)) => instance.args[index as usize].clone(),
                                None => arg.clone(),
                            },
                        )
                        .collect(),
                    ..set.clone()
                })
                .collect();
            filled.push((mode, sets));
        }
        self.mode_copies = copied;
        for (mode, sets) in filled {
            self.team_mut(team).modes[mode.index()].sets = sets;
        }
        // The first list past the bound (the others would say the same).
        if let Some((span, name)) = past_limit.first() {
            self.past_mode_copies.insert(team);
            let message = format!(
                "entering `{name}` would make the copies of the modes entered with arguments hold more than {MAX_MODE_COPIES} `set`s and catches in all: enter fewer distinct lists of arguments, or give the mode fewer `set`s"
            );
            self.diagnostics
                .report(Code::ModeCopiesPastLimit, *span, message);
        }
    }

    fn lookup_mode_ref(&mut self, team: TeamId, name: &ast::Ident) -> Option<ModeId> {
        match self.team(team).mode_by_name(&name.name) {
            Some(mode) => {
                self.occurrence(name.span, Symbol::Mode { team, mode }, false);
                Some(mode)
            }
            None => {
                let t = self.team(team);
                let names = t
                    .modes
                    .iter()
                    .filter(|m| m.instance.is_none())
                    .map(|m| &m.name);
                let templates = t.templates.iter().map(|m| &m.name);
                let guess = suggestion(&name.name, names.chain(templates).map(Name::as_str));
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
            Some(name) => self.mode_ref(team, name, m.default_args.as_ref()),
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
        let mut cased: FastMap<CaseFrom, Span> = FastMap::default();
        // The catches of a case for a mode with parameters, added for each
        // mode it is entered as once the whole main is read.
        let mut template_catches: Vec<(TemplateId, Transition)> = Vec::new();
        for case in &m.cases {
            let from = self.case_ref(team, &case.mode);
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
                let to = self.mode_ref(team, &catch.target, catch.target_args.as_ref());
                if let (Some(from), Some(to)) = (from, to) {
                    let transition = |from| Transition {
                        from,
                        event: catch.event.name.clone(),
                        event_span: catch.event.span,
                        to,
                        span: catch.span,
                        never_thrown: false,
                    };
                    match from {
                        CaseFrom::Mode(from) => transitions.push(transition(from)),
                        CaseFrom::Template(template) => {
                            template_catches.push((template, transition(ModeId::new(0))))
                        }
                    }
                }
            }
        }
        let mut past_limit = None;
        for (template, transition) in template_catches {
            let count = self.team(team).template(template).instances.len();
            if self.mode_copies + count > MAX_MODE_COPIES {
                past_limit.get_or_insert((transition.span, count));
                continue;
            }
            self.mode_copies += count;
            for &from in &self.team(team).template(template).instances {
                transitions.push(Transition {
                    from,
                    ..transition.clone()
                });
            }
        }
        if let Some((span, modes)) = past_limit {
            // Which modes the machine reaches is unknown without them.
            self.mains_with_unknown_modes.insert(team);
            self.past_mode_copies.insert(team);
            let message = format!(
                "this catch holds in each of the {modes} modes its mode is entered as: the copies of the modes entered with arguments would hold more than {MAX_MODE_COPIES} `set`s and catches in all; enter fewer distinct lists of arguments"
            );
            self.diagnostics
                .report(Code::ModeCopiesPastLimit, span, message);
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
        // Modes past E048 lack their `set`s or catches: they would all seem
        // to throw nothing.
        if self.past_mode_copies.contains(&team) {
            return;
        }
        let t = self.team(team);
        let mut findings: Vec<(Span, &Name, &Name, Vec<&Name>)> = Vec::new();
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
                // A catch of `case (MOVE)` is one transition per mode MOVE is
                // entered as, side by side: said once, naming the modes.
                match findings.last_mut() {
                    Some((span, _, _, more)) if *span == tr.event_span => more.push(&mode.name),
                    _ => findings.push((tr.event_span, &tr.event, &mode.name, Vec::new())),
                }
            }
        }
        let findings: Vec<(Span, String)> = findings
            .into_iter()
            .map(|(span, event, first, more)| {
                let message = match more.as_slice() {
                    [] => format!(
                        "no service that mode {first} runs throws `{event}`, so this catch never fires there"
                    ),
                    [second] => format!(
                        "no service that modes {first} and {second} run throws `{event}`, so this catch never fires there"
                    ),
                    [second, third] => format!(
                        "no service that modes {first}, {second} and {third} run throws `{event}`, so this catch never fires there"
                    ),
                    [second, rest @ ..] => format!(
                        "no service that modes {first}, {second} and {} more run throws `{event}`, so this catch never fires there",
                        rest.len()
                    ),
                };
                (span, message)
            })
            .collect();
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
        // A mode with parameters that no catch nor the default enters.
        let never_entered: Vec<(Span, Name)> = t
            .templates
            .iter()
            .filter(|m| m.instances.is_empty())
            .map(|m| (m.name_span, m.name.clone()))
            .collect();
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
        for (span, name) in never_entered {
            self.diagnostics.report(
                Code::UnreachableMode,
                span,
                format!("the mode `{name}` is never entered: no catch nor the default names it with arguments"),
            );
        }
    }

    fn services_never_set(&mut self, team: TeamId) {
        let t = self.team(team);
        // A service set only by a mode with parameters never entered is
        // reported there (W002), not here.
        let set: FastSet<ServiceId> = t
            .modes
            .iter()
            .flat_map(|m| m.sets.iter().filter_map(|s| s.service))
            .chain(
                t.templates
                    .iter()
                    .flat_map(|m| m.sets.iter().filter_map(|s| s.service)),
            )
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

/// What a `case` names: a mode of the machine, or a mode with parameters
/// (its catches hold in each mode it is entered as).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum CaseFrom {
    Mode(ModeId),
    Template(TemplateId),
}
