//! Phase 1: the declarations of a mission: teams and robots (formation), plans
//! and composite services, modes, functions, and the team variables that
//! communication statements introduce.

use super::ir::*;
use super::{Checker, MAX_ROBOTS_PER_DECLARATION, MAX_ROBOTS_PER_MISSION, is_user, suggestion};
use crate::diag::Code;
use crate::fasthash::FastMap;
use crate::span::Span;
use crate::syntax::ast::{self, Item, Name};

impl<'a> Checker<'a> {
    pub(super) fn declare(&mut self, source: &'a ast::SourceFile) {
        let mut robot_names = FastMap::default();
        for item in &source.items {
            if let Item::Formation(formation) = item {
                for decl in &formation.teams {
                    self.declare_team(decl, &mut robot_names);
                }
            }
        }
        for (index, item) in source.items.iter().enumerate() {
            match item {
                Item::Function(f) => self.declare_function(f, index),
                Item::Service(s) => self.declare_service(s, index),
                _ => {}
            }
        }
        for item in &source.items {
            if let Item::Mode(m) = item {
                self.declare_mode(m);
            }
        }
        self.collect_variables();
        self.check_parameter_names();
        self.check_result_names();
    }

    fn declare_team(&mut self, decl: &ast::TeamDecl, robot_names: &mut FastMap<Name, Span>) {
        let name = &decl.name;
        if is_user(&name.name) {
            self.diagnostics.report(
                Code::ReservedName,
                name.span,
                format!(
                    "`{}` is the operator's console; choose another team name",
                    name.name
                ),
            );
            return;
        }
        if let Some(existing) = self.team_id(&name.name) {
            let first = self.team(existing).name_span;
            self.diagnostics
                .report(
                    Code::DuplicateTeam,
                    name.span,
                    format!("the team `{}` is already declared", name.name),
                )
                .relate(first, "first declared here");
            return;
        }
        let id = TeamId(self.mission.teams.len() as u32);
        self.teams_by_name.insert(name.name.clone(), id);
        self.occurrence(name.span, Symbol::Team(id), true);
        let mut robots = Vec::new();
        for robot in &decl.robots {
            let robot_type = self.resolve_robot_type(&robot.robot_type);
            let Some(count) = self.robot_count(robot, robot_names.len()) else {
                continue;
            };
            let names: Vec<Name> = match robot.count {
                None => vec![robot.name.name.clone()],
                Some(_) => (0..count)
                    .map(|i| Name::new(format!("{}_{i}", robot.name.name)))
                    .collect(),
            };
            for robot_name in names {
                if let Some(&first) = robot_names.get(&robot_name) {
                    self.diagnostics
                        .report(
                            Code::DuplicateRobot,
                            robot.name.span,
                            format!("a robot named `{robot_name}` is already declared"),
                        )
                        .relate(first, "first declared here");
                    continue;
                }
                robot_names.insert(robot_name.clone(), robot.name.span);
                self.occurrence(
                    robot.name.span,
                    Symbol::Robot {
                        team: id,
                        robot: RobotId::new(robots.len()),
                    },
                    true,
                );
                robots.push(Robot {
                    name: robot_name,
                    name_span: robot.name.span,
                    type_name: robot_type
                        .map(|t| self.catalog.get(t).name.clone())
                        .unwrap_or_else(|| robot.robot_type.name.to_string()),
                    robot_type,
                });
            }
        }
        self.service_syntax.push(Vec::new());
        self.mission
            .teams
            .push(Team::new(name.name.clone(), name.span, robots));
    }

    /// How many robots `robot` declares, checked against the limits before
    /// any of them is made: `None` (reported) for a count below one, above
    /// [`MAX_ROBOTS_PER_DECLARATION`], or taking the mission, which has
    /// `declared` robots so far, past [`MAX_ROBOTS_PER_MISSION`] (reported
    /// once: every later declaration is left out too).
    fn robot_count(&mut self, robot: &ast::RobotDecl, declared: usize) -> Option<usize> {
        if self.robots_full {
            return None;
        }
        let (count, span) = match robot.count {
            None => (1, robot.name.span),
            Some(ast::Count {
                value: Some(n @ 1..),
                span,
            }) => (n, span),
            Some(count) => {
                self.diagnostics.report(
                    Code::EmptyRobotGroup,
                    count.span,
                    "the number of robots must be a whole number of at least 1",
                );
                return None;
            }
        };
        if count > MAX_ROBOTS_PER_DECLARATION {
            self.diagnostics.report(
                Code::TooManyRobots,
                span,
                format!(
                    "a declaration may have at most {MAX_ROBOTS_PER_DECLARATION} robots: declare fewer, or split them among declarations"
                ),
            );
            return None;
        }
        let count = count as usize;
        if declared + count > MAX_ROBOTS_PER_MISSION {
            self.robots_full = true;
            self.diagnostics.report(
                Code::TooManyRobots,
                span,
                format!(
                    "this declaration takes the mission past {MAX_ROBOTS_PER_MISSION} robots, the most a mission may have (it has {declared} before it); it and the declarations after it are left out"
                ),
            );
            return None;
        }
        Some(count)
    }

    /// Looks a robot type (or alias) up in the catalog, reporting it if unknown.
    pub(super) fn resolve_robot_type(
        &mut self,
        name: &ast::Ident,
    ) -> Option<crate::catalog::RobotTypeId> {
        match self.catalog.lookup(&name.name) {
            Some(id) => {
                let canonical = self.catalog.get(id).name.clone();
                self.occurrence(name.span, Symbol::RobotType(Name::new(canonical)), false);
                Some(id)
            }
            None => {
                let guess = suggestion(&name.name, self.catalog.names());
                let message = match guess {
                    Some(_) => format!("unknown robot type `{}`", name.name),
                    None => {
                        let known: Vec<&str> =
                            self.catalog.types().map(|(_, r)| r.name.as_str()).collect();
                        format!(
                            "unknown robot type `{}`; the catalog has {}",
                            name.name,
                            known.join(", ")
                        )
                    }
                };
                self.diagnostics
                    .report(Code::UnknownRobotType, name.span, message)
                    .suggest(guess);
                None
            }
        }
    }

    /// The team a header names, or an "undeclared team" error.
    pub(super) fn header_team(&mut self, team: &ast::Ident, what: &str) -> Option<TeamId> {
        if let Some(id) = self.team_id(&team.name) {
            self.occurrence(team.span, Symbol::Team(id), false);
            return Some(id);
        }
        let guess = suggestion(&team.name, self.team_names().iter().map(String::as_str));
        self.diagnostics
            .report(
                Code::UnknownTeam,
                team.span,
                format!("{what} of `{}`, which is not a declared team", team.name),
            )
            .suggest(guess);
        None
    }

    fn declare_function(&mut self, f: &'a ast::Function, item: usize) {
        if let Some(&existing) = self.functions_by_name.get(&f.name.name) {
            let first = self.mission.functions[existing.0 as usize].name_span;
            self.diagnostics
                .report(
                    Code::DuplicateFunction,
                    f.name.span,
                    format!("the function `{}` is already defined", f.name.name),
                )
                .relate(first, "first defined here");
            self.rejected_bodies.push((None, &f.body));
            return;
        }
        let id = FunctionId(self.mission.functions.len() as u32);
        self.functions_by_name.insert(f.name.name.clone(), id);
        self.function_syntax.push(f);
        self.occurrence(f.name.span, Symbol::Function(id), true);
        let params = self.declare_params(ParamOwner::Function(id), &f.name.name, &f.params);
        self.mission.functions.push(FunctionInfo {
            name: f.name.name.clone(),
            name_span: f.name.span,
            item,
            called: false,
            params,
            results: Vec::new(),
        });
        let results = self.declare_results(ParamOwner::Function(id), &f.body);
        self.mission.functions[id.0 as usize].results = results;
    }

    /// A composite service, in each team its header names: a service shared
    /// by teams (`A, B.Plan.S`) is each team's own, its body walked with
    /// each team's robots (and so checked against every robot of every
    /// team), refined into each team's programs from the one syntax item.
    fn declare_service(&mut self, s: &'a ast::CompositeService, item: usize) {
        let mut seen: Vec<&Name> = Vec::new();
        // A body no team takes is still checked, as a rejected definition.
        let (mut declared, mut rejected) = (false, None);
        for team in std::iter::once(&s.team).chain(&s.more_teams) {
            if seen.contains(&&team.name) {
                self.diagnostics.report(
                    Code::DuplicateService,
                    team.span,
                    format!(
                        "the team `{}` is named twice in the header of `{}.{}`",
                        team.name, s.plan.name, s.name.name
                    ),
                );
                continue;
            }
            seen.push(&team.name);
            match self.declare_service_of(team, s, item) {
                Ok(()) => declared = true,
                Err(team) => rejected = rejected.or(Some(team)),
            }
        }
        if let (false, Some(team)) = (declared, rejected) {
            self.rejected_bodies.push((team, &s.body));
        }
    }

    /// The service in one team of its header; else the team whose robots
    /// check its body as a rejected definition (`None`: an unknown team).
    fn declare_service_of(
        &mut self,
        team: &ast::Ident,
        s: &'a ast::CompositeService,
        item: usize,
    ) -> Result<(), Option<TeamId>> {
        let Some(team) = self.header_team(team, "a composite service") else {
            return Err(None);
        };
        let plan = match self.team(team).plan_by_name(&s.plan.name) {
            Some(plan) => {
                self.occurrence(s.plan.span, Symbol::Plan { team, plan }, false);
                plan
            }
            None => {
                let plan = self.team_mut(team).add_plan(Plan {
                    name: s.plan.name.clone(),
                    span: s.plan.span,
                });
                self.occurrence(s.plan.span, Symbol::Plan { team, plan }, true);
                plan
            }
        };
        if let Some(existing) = self.team(team).service_in_plan(plan, &s.name.name) {
            let first = self.team(team).services[existing.index()].name_span;
            self.diagnostics
                .report(
                    Code::DuplicateService,
                    s.name.span,
                    format!(
                        "`{}.{}.{}` is already defined",
                        self.team(team).name,
                        s.plan.name,
                        s.name.name
                    ),
                )
                .relate(first, "first defined here");
            return Err(Some(team));
        }
        self.service_syntax[team.0 as usize].push(s);
        let service = self.team_mut(team).add_service(Service {
            name: s.name.name.clone(),
            name_span: s.name.span,
            plan,
            span: s.span,
            item,
            throws: Vec::new(),
            params: Vec::new(),
            results: Vec::new(),
        });
        self.occurrence(s.name.span, Symbol::Service { team, service }, true);
        let owner = ParamOwner::Service(team, service);
        let what = self.team(team).service_path(service);
        let params = self.declare_params(owner, &what, &s.params);
        self.team_mut(team).services[service.index()].params = params;
        let results = self.declare_results(owner, &s.body);
        self.team_mut(team).services[service.index()].results = results;
        Ok(())
    }

    fn declare_mode(&mut self, m: &ast::ModeDef) {
        let Some(team) = self.header_team(&m.team, "a mode") else {
            return;
        };
        let t = self.team(team);
        let existing = match t.mode_by_name(&m.name.name) {
            Some(mode) => Some(t.mode(mode).name_span),
            None => t
                .template_by_name(&m.name.name)
                .map(|template| t.template(template).name_span),
        };
        if let Some(first) = existing {
            self.diagnostics
                .report(
                    Code::DuplicateMode,
                    m.name.span,
                    format!(
                        "the mode `{}.{}` is already defined",
                        m.team.name, m.name.name
                    ),
                )
                .relate(first, "first defined here");
            return;
        }
        if m.params_span.is_some() {
            // A mode with parameters: a mode of the machine only as entered
            // with arguments (`behaviour.rs` makes one per list of them).
            let template = self.team_mut(team).add_template(ModeTemplate {
                name: m.name.name.clone(),
                name_span: m.name.span,
                span: m.span,
                params: Vec::new(),
                sets: Vec::new(),
                instances: Vec::new(),
            });
            let symbol = Symbol::ModeTemplate { team, template };
            self.occurrence(m.name.span, symbol, true);
            let owner = ParamOwner::Mode(team, template);
            let what = format!("{}.{}", m.team.name, m.name.name);
            let params = self.declare_params(owner, &what, &m.params);
            self.team_mut(team).templates[template.index()].params = params;
            return;
        }
        let mode = self.team_mut(team).add_mode(Mode {
            name: m.name.name.clone(),
            name_span: m.name.span,
            span: m.span,
            sets: Vec::new(),
            instance: None,
        });
        self.occurrence(m.name.span, Symbol::Mode { team, mode }, true);
    }

    /// Team variables are declared by `send/publish(T, T.X = e)` and by receiving
    /// `T.X`, anywhere in the file: collect them all before checking bodies.
    fn collect_variables(&mut self) {
        let mut found = Vec::new();
        let mut visit =
            |owner: Option<TeamId>, block: &ast::Block, teams: &FastMap<Name, TeamId>| {
                block.walk(&mut |stmt| {
                    let ast::StmtKind::Comm(comm) = &stmt.kind else {
                        return;
                    };
                    for item in &comm.items {
                        if comm.kind.is_outgoing() && item.value.is_none() {
                            continue;
                        }
                        match item.attr.segments.as_slice() {
                            [name] => found.push((owner, name.name.clone())),
                            [team, name] => {
                                if let Some(&t) = teams.get(&team.name) {
                                    found.push((Some(t), name.name.clone()));
                                }
                            }
                            _ => {}
                        }
                    }
                });
            };
        for (i, services) in self.service_syntax.iter().enumerate() {
            for service in services {
                visit(Some(TeamId(i as u32)), &service.body, &self.teams_by_name);
            }
        }
        for function in &self.function_syntax {
            visit(None, &function.body, &self.teams_by_name);
        }
        // Each (team, name) once, in the order found, without scanning the
        // lists (a mission may name thousands of variables).
        for (team, name) in found {
            if !self.team_variables.insert((team, name.clone())) {
                continue;
            }
            if let Some(t) = team {
                self.mission.teams[t.0 as usize]
                    .variables
                    .push(name.clone());
            }
            self.variables.entry(name).or_default().push(team);
        }
    }
}
