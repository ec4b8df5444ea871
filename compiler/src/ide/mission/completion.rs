//! Completion: what may be written at the cursor, and only that.
//!
//! The place is found from the tokens before the cursor ([`super::context`]),
//! which works in half-typed text; who runs the statement there comes from the
//! scopes the checker recorded ([`crate::sema::Mission::scope_at`]), so that
//! inside `group(instance of X)` only the services X provides are offered.
//! Items are ranked most specific first (the services of the robots here, then
//! functions, then keyword snippets; the events a mode's services throw before
//! the team's other events...).

use super::context::{self, Head, Lt, Paren, Place, Scan};
use super::docs;
use super::robots::{self, RobotsHere};
use super::snippets::{self, Snippet};
use super::values;
use crate::catalog::{Catalog, RobotTypeId, ValueDef, ValueType};
use crate::ide::{CompletionConfig, CompletionItem, CompletionKind};
use crate::sema::{
    CheckedMission, Mission, ModeId, PlanId, ScopeKind, ServiceId, Symbol, Team, TeamId, is_user,
};
use crate::span::Span;
use crate::syntax::ast::{self, Name};
use crate::syntax::token::Token;

/// The completions at `offset` in `text`, most specific first.
pub fn completions(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    offset: usize,
    config: CompletionConfig,
) -> Vec<CompletionItem> {
    let offset = offset.min(text.len());
    if context::trivia_at(text, offset) != context::Trivia::Code {
        return Vec::new();
    }
    let replace = context::prefix_at(text, offset);
    let scan = context::scan(analysis, text, replace.start);
    let place = context::place(&scan);
    let mut c = Completions {
        analysis,
        mission: &analysis.mission,
        catalog,
        text,
        offset,
        scan: &scan,
        config,
        replace,
        items: Vec::new(),
    };
    c.fill(&place);
    let mut items = c.items;
    // Stable: equal ranks keep the order they were added in.
    items.sort_by_key(|(rank, _)| *rank);
    let mut seen = std::collections::HashSet::new();
    items
        .into_iter()
        .filter(|(_, item)| seen.insert((item.label.clone(), item.kind)))
        .map(|(_, item)| item)
        .collect()
}

struct Completions<'a> {
    analysis: &'a CheckedMission,
    mission: &'a Mission,
    catalog: &'a Catalog,
    text: &'a str,
    offset: usize,
    scan: &'a Scan<'a>,
    config: CompletionConfig,
    replace: Span,
    /// With their rank: lower first.
    items: Vec<(u8, CompletionItem)>,
}

/// Ranks, most specific first.
const SPECIFIC: u8 = 0;
const EXACT: u8 = 1;
const LIKELY: u8 = 2;
const OTHER: u8 = 3;
const KEYWORD: u8 = 4;
const SNIPPET: u8 = 5;

impl<'a> Completions<'a> {
    fn add(
        &mut self,
        rank: u8,
        kind: CompletionKind,
        label: impl Into<String>,
        detail: Option<String>,
        documentation: Option<String>,
    ) {
        let label = label.into();
        self.items.push((
            rank,
            CompletionItem {
                insert: label.clone(),
                label,
                kind,
                detail,
                documentation,
                snippet: false,
                replace: self.replace,
            },
        ));
    }

    /// An item whose text is a snippet (plain text without snippet support).
    fn add_snippet(
        &mut self,
        rank: u8,
        kind: CompletionKind,
        label: impl Into<String>,
        body: &str,
        detail: Option<String>,
        documentation: Option<String>,
    ) {
        let label = label.into();
        let (insert, snippet) = match self.config.snippets {
            true => (body.to_string(), true),
            false => (snippets::to_plain(body), false),
        };
        self.items.push((
            rank,
            CompletionItem {
                label,
                kind,
                detail,
                documentation,
                insert,
                snippet,
                replace: self.replace,
            },
        ));
    }

    fn add_construct(&mut self, rank: u8, s: Snippet) {
        self.add_snippet(
            rank,
            CompletionKind::Snippet,
            s.label,
            &s.body,
            Some(s.detail.to_string()),
            None,
        );
    }

    fn team(&self, name: &str) -> Option<(TeamId, &'a Team)> {
        let mission: &'a Mission = self.mission;
        let id = mission.team_by_name(name)?;
        Some((id, mission.team(id)))
    }

    fn head_team(&self) -> Option<(TeamId, &'a Team)> {
        self.scan.head.team().and_then(|t| self.team(t))
    }

    fn robots_here(&self) -> RobotsHere {
        RobotsHere::at(
            self.analysis,
            self.offset,
            self.scan.head.team().map(Name::as_str),
        )
    }

    fn fill(&mut self, place: &Place) {
        match place {
            Place::Nothing => {}
            Place::Item => self.item_start(),
            Place::ItemAfterTeam { team } => self.after_team(team),
            Place::ItemAfterPlan { team, plan } => self.after_plan(team, plan),
            Place::TeamDecl => self.team_decl(),
            Place::RobotType => self.robot_types(),
            Place::Statement => self.statement(),
            Place::GroupArm { first, leader } => {
                let types = self.type_names_here();
                let types: Vec<&str> = types.iter().map(String::as_str).collect();
                for s in snippets::arm_snippets(&types, *first, *leader) {
                    self.add_construct(EXACT, s);
                }
            }
            Place::ArmCondition => {
                for (word, detail) in [
                    ("instance of", "the robots of these types"),
                    ("capable of", "the robots with all these capabilities"),
                ] {
                    self.add(
                        EXACT,
                        CompletionKind::Keyword,
                        word,
                        Some(detail.to_string()),
                        None,
                    );
                    if let Some((_, item)) = self.items.last_mut() {
                        item.insert.push(' ');
                    }
                }
            }
            Place::ArmTypes => self.arm_types(),
            Place::ArmCapabilities => self.arm_capabilities(),
            Place::Throw => self.throw_events(),
            Place::CommTeam => self.comm_teams(),
            Place::Expr { qualifier } => self.expression(qualifier.as_ref()),
            Place::Compared { attr, words } => self.compared(attr.as_deref(), *words),
            Place::AfterOperand => {
                for word in ["and", "or"] {
                    self.add(KEYWORD, CompletionKind::Keyword, word, None, None);
                }
            }
            Place::Unit { in_condition } => {
                if *in_condition {
                    for word in ["and", "or"] {
                        self.add(KEYWORD, CompletionKind::Keyword, word, None, None);
                    }
                }
                for (unit, detail) in [
                    ("MSEC", "milliseconds"),
                    ("SEC", "seconds"),
                    ("MIN", "minutes"),
                    ("HOUR", "hours"),
                ] {
                    self.add(
                        EXACT,
                        CompletionKind::Unit,
                        unit,
                        Some(detail.to_string()),
                        None,
                    );
                }
            }
            Place::SetStart => {
                let plans = self
                    .head_team()
                    .map(|(_, t)| plan_names(t))
                    .unwrap_or_default();
                let plans: Vec<&str> = plans.iter().map(Name::as_str).collect();
                self.add_construct(EXACT, snippets::set_snippet(&plans));
            }
            Place::SetPlan => self.set_plans(),
            Place::SetService { plan } => self.set_services(plan),
            Place::SetTimeout => {
                self.add_snippet(
                    EXACT,
                    CompletionKind::Keyword,
                    "timeout",
                    "timeout = ${1:10} ${2|SEC,MSEC,MIN,HOUR|}",
                    Some("timeout = period: the most time the service may take".to_string()),
                    None,
                );
            }
            Place::MainArm { in_case } => {
                let has_default = self.main_has_default();
                for s in snippets::main_snippets(*in_case, has_default) {
                    self.add_construct(EXACT, s);
                }
            }
            Place::CaseMode => self.case_modes(),
            Place::CatchEvent { mode } => self.catch_events(mode.as_ref()),
            Place::ModeKeyword => {
                let detail = "mode = MODE: the mode to switch to".to_string();
                self.add(EXACT, CompletionKind::Keyword, "mode", Some(detail), None);
                if let Some((_, item)) = self.items.last_mut() {
                    item.insert = "mode = ".to_string();
                }
            }
            Place::ModeName => self.mode_names(),
        }
    }

    // ----- items -----

    fn item_start(&mut self) {
        let teams: Vec<Name> = self.mission.teams.iter().map(|t| t.name.clone()).collect();
        for t in &self.mission.teams {
            self.add_team(EXACT, t);
        }
        let has_formation = self
            .analysis
            .syntax
            .items
            .iter()
            .any(|i| matches!(i, ast::Item::Formation(_)));
        if self.analysis.syntax.items.is_empty() {
            self.add_construct(EXACT, snippets::mission_template());
        }
        // Right after a service's body: its `repeat`.
        if matches!(self.scan.head, Head::Service { .. })
            && self.scan.frames.is_empty()
            && matches!(self.scan.top.as_slice(), [body] if body.is_closed_brace())
        {
            self.add_snippet(
                SPECIFIC,
                CompletionKind::Keyword,
                "repeat",
                "repeat($1)",
                Some(
                    "repeat(period, condition): run the service again; repeat() forever"
                        .to_string(),
                ),
                None,
            );
        }
        let types: Vec<&str> = self.catalog.types().map(|(_, r)| r.name.as_str()).collect();
        let team_names: Vec<&str> = teams.iter().map(Name::as_str).collect();
        for s in snippets::item_snippets(&team_names, &types) {
            if s.label == "formation" && has_formation {
                continue;
            }
            self.add_construct(SNIPPET, s);
        }
    }

    /// `Team.` between items: its plans (for a new service), `main`, and the
    /// modes its main names but nobody defined yet.
    fn after_team(&mut self, team: &Name) {
        let Some((_, t)) = self.team(team) else {
            return;
        };
        for (i, p) in t.plans.iter().enumerate() {
            let doc = docs::plan(self.text, t, PlanId::new(i));
            self.add(
                EXACT,
                CompletionKind::Plan,
                p.name.as_str(),
                Some(format!("plan of {}", t.name)),
                Some(doc),
            );
        }
        if t.main.is_none() {
            self.add_snippet(
                LIKELY,
                CompletionKind::Keyword,
                "main",
                "main{\n\tcase (${1:MODE}):\n\t\tcatch (${2:event}): mode = ${3:OTHER_MODE}\n\tdefault: mode = ${1:MODE}\n}",
                Some(format!("the main block of {}", t.name)),
                None,
            );
        }
        for name in self.undefined_modes(team) {
            self.add_snippet(
                LIKELY,
                CompletionKind::Mode,
                name.as_str(),
                &format!(
                    "{}{{\n\tset(${{1:Plan}}, ${{2:Service}})\n}}",
                    snippets::escape(&name)
                ),
                Some("a mode the main block names, not yet defined".to_string()),
                None,
            );
        }
        let plans = plan_names(t);
        let plans: Vec<&str> = plans.iter().map(Name::as_str).collect();
        self.add_snippet(
            SNIPPET,
            CompletionKind::Snippet,
            "mode",
            &format!(
                "${{1:MODE}}{{\n\tset({}, ${{3:Service}})\n}}",
                snippets::choice(2, &plans, "Plan")
            ),
            Some(format!("a mode of {}", t.name)),
            None,
        );
    }

    /// `Team.Plan.` between items: the services that a `set` of the team
    /// names for that plan but no definition has.
    fn after_plan(&mut self, team: &Name, plan: &Name) {
        let Some((_, t)) = self.team(team) else {
            return;
        };
        let defined = |name: &str| {
            t.plan_by_name(plan)
                .is_some_and(|p| t.service_in_plan(p, name).is_some())
        };
        let mut missing: Vec<(&Name, &Name)> = Vec::new();
        for item in &self.analysis.syntax.items {
            let ast::Item::Mode(m) = item else { continue };
            if m.team.name != *team {
                continue;
            }
            for set in &m.sets {
                if let ast::SetTarget::Service(s) = &set.service
                    && set.plan.name == *plan
                    && !defined(&s.name)
                    && !missing.iter().any(|(n, _)| **n == s.name)
                {
                    missing.push((&s.name, &m.name.name));
                }
            }
        }
        for (name, mode) in missing {
            self.add_snippet(
                EXACT,
                CompletionKind::Service,
                name.as_str(),
                &format!("{}{{\n\t$0\n}} repeat($1)", snippets::escape(name)),
                Some(format!("set in mode {mode}, not yet defined")),
                None,
            );
        }
    }

    /// Modes named in the team's main block that no definition has.
    fn undefined_modes(&self, team: &str) -> Vec<Name> {
        let Some((_, t)) = self.team(team) else {
            return Vec::new();
        };
        let mut out: Vec<Name> = Vec::new();
        for item in &self.analysis.syntax.items {
            let ast::Item::Main(m) = item else { continue };
            if m.team.name != team {
                continue;
            }
            let names = m
                .cases
                .iter()
                .flat_map(|c| std::iter::once(&c.mode).chain(c.catches.iter().map(|k| &k.target)))
                .chain(m.default.iter());
            for n in names {
                if t.mode_by_name(&n.name).is_none() && !out.contains(&n.name) {
                    out.push(n.name.clone());
                }
            }
        }
        out
    }

    fn team_decl(&mut self) {
        let types: Vec<&str> = self.catalog.types().map(|(_, r)| r.name.as_str()).collect();
        let body = format!(
            "${{1:Team}}: {} ${{3:robot}}",
            snippets::choice(2, &types, "RobotType")
        );
        self.add_snippet(
            EXACT,
            CompletionKind::Snippet,
            "team declaration",
            &body,
            Some("Team: RobotType robot, RobotType robot[2]".to_string()),
            None,
        );
    }

    /// Every robot type of the catalog (built-in and workspace files).
    fn robot_types(&mut self) {
        for (_, r) in self.catalog.types() {
            let detail = platform_line(r);
            let doc = docs::robot_type(r);
            self.add(
                EXACT,
                CompletionKind::RobotType,
                r.name.as_str(),
                Some(detail),
                Some(doc.clone()),
            );
            for alias in &r.aliases {
                self.add(
                    LIKELY,
                    CompletionKind::RobotType,
                    alias.as_str(),
                    Some(format!("alias of {}", r.name)),
                    Some(doc.clone()),
                );
            }
        }
    }

    // ----- statements -----

    fn type_names_here(&self) -> Vec<String> {
        let here = self.robots_here();
        here.types(self.mission)
            .into_iter()
            .map(|ty| self.catalog.get(ty).name.clone())
            .collect()
    }

    fn statement(&mut self) {
        let here = self.robots_here();
        let types = here.types(self.mission);
        let teams = here.teams();
        // Inside a group arm, the services its robots have and the others
        // around do not come first: they are why the group is there.
        let around: Option<Vec<String>> = RobotsHere::around(self.analysis, self.offset)
            .filter(|_| {
                matches!(
                    here.kind,
                    Some(ScopeKind::Arm { .. } | ScopeKind::Others { .. })
                )
            })
            .map(|outer| {
                robots::shared_services(self.catalog, &outer.types(self.mission))
                    .into_iter()
                    .map(|s| s.name.clone())
                    .collect()
            });
        for def in robots::shared_services(self.catalog, &types) {
            let rank = match &around {
                Some(common) if !common.contains(&def.name) => SPECIFIC,
                _ => EXACT,
            };
            let body = service_call_snippet(def);
            let mut doc = docs::service(def);
            let providers: Vec<String> = teams
                .iter()
                .filter_map(|t| {
                    let team_types: Vec<_> = types
                        .iter()
                        .copied()
                        .filter(|ty| {
                            !here.robots_of_type(self.mission, *ty).is_empty()
                                && robots::team_types(self.mission, *t).contains(ty)
                        })
                        .collect();
                    (!team_types.is_empty()).then(|| {
                        format!(
                            "team `{}`: {}",
                            self.mission.team(*t).name,
                            docs::types_with_robots(self.catalog, self.mission, *t, &team_types)
                        )
                    })
                })
                .collect();
            if !providers.is_empty() {
                doc.push_str(&format!("\n\nRun here by {}.", providers.join("; ")));
            }
            if self.config.snippets || def.params.is_empty() {
                self.add_snippet(
                    rank,
                    CompletionKind::BuiltinService,
                    def.name.as_str(),
                    &body,
                    Some(def.signature()),
                    Some(doc),
                );
            } else {
                // Without snippets the cursor could not stop inside `()`.
                self.add(
                    rank,
                    CompletionKind::BuiltinService,
                    def.name.as_str(),
                    Some(def.signature()),
                    Some(doc),
                );
            }
        }
        let current = match here.kind {
            Some(ScopeKind::Function(f)) => Some(f),
            _ => None,
        };
        for (i, f) in self.mission.functions.iter().enumerate() {
            if current.is_some_and(|c| c.0 as usize == i) {
                continue;
            }
            // `go_to(${1:PLACE})`: a stop at each parameter, named.
            let call = snippets::call(&f.name, f.params.iter().map(|p| p.name.as_str()));
            self.add_snippet(
                LIKELY,
                CompletionKind::Function,
                f.name.as_str(),
                &call,
                Some(super::hover::function_signature(f)),
                Some("A function: its statements run here, by these robots.".to_string()),
            );
        }
        let team_names: Vec<&str> = self
            .mission
            .teams
            .iter()
            .map(|t| t.name.as_str())
            .chain(["USER"])
            .collect();
        let type_names: Vec<String> = types
            .iter()
            .map(|ty| self.catalog.get(*ty).name.clone())
            .collect();
        let type_names: Vec<&str> = type_names.iter().map(String::as_str).collect();
        // After `if (...) { ... }`: its `else`.
        let level = self
            .scan
            .frames
            .last()
            .map_or(&[][..], |f| f.level.as_slice());
        if let [.., cond, block] = level
            && cond.closed_paren() == Some(&Paren::If)
            && block.is_closed_brace()
        {
            self.add_snippet(
                LIKELY,
                CompletionKind::Keyword,
                "else",
                "else {\n\t$0\n}",
                Some("else { ... }: when the condition does not hold".to_string()),
                None,
            );
        }
        for s in snippets::statement_snippets(&team_names, &type_names) {
            self.add_construct(KEYWORD, s);
        }
    }

    fn arm_types(&mut self) {
        let here = self.robots_here();
        let types = here.types(self.mission);
        if types.is_empty() {
            return self.robot_types();
        }
        for ty in types {
            let r = self.catalog.get(ty);
            let robots = here.robots_of_type(self.mission, ty);
            self.add(
                EXACT,
                CompletionKind::RobotType,
                r.name.as_str(),
                Some(robots.join(", ")),
                Some(docs::robot_type(r)),
            );
        }
    }

    fn arm_capabilities(&mut self) {
        let here = self.robots_here();
        let mut types = here.types(self.mission);
        if types.is_empty() {
            types = self.catalog.types().map(|(id, _)| id).collect();
        }
        let mut capabilities: Vec<(&str, Vec<&str>)> = Vec::new();
        for ty in &types {
            let r = self.catalog.get(*ty);
            for c in &r.capabilities {
                match capabilities.iter_mut().find(|(n, _)| n == c) {
                    Some((_, having)) => having.push(&r.name),
                    None => capabilities.push((c, vec![&r.name])),
                }
            }
        }
        capabilities.sort();
        for (c, having) in capabilities {
            self.add(
                EXACT,
                CompletionKind::Capability,
                c,
                Some(having.join(", ")),
                None,
            );
        }
    }

    fn throw_events(&mut self) {
        let mut teams = self.robots_here().teams();
        if teams.is_empty() {
            teams = self.head_team().map(|(id, _)| id).into_iter().collect();
        }
        for team in teams {
            let t = self.mission.team(team);
            for e in &t.events {
                let rank = if e.caught_at.is_empty() {
                    LIKELY
                } else {
                    EXACT
                };
                let detail = match e.caught_at.len() {
                    0 => "event: no mode catches it yet".to_string(),
                    _ => format!("event of {}", t.name),
                };
                self.add_event(rank, t, &e.name, detail);
            }
        }
    }

    fn comm_teams(&mut self) {
        let own = self.robots_here().teams();
        for (i, t) in self.mission.teams.iter().enumerate() {
            let rank = if own.contains(&TeamId(i as u32)) {
                LIKELY
            } else {
                EXACT
            };
            self.add_team(rank, t);
        }
        self.add_user(LIKELY);
    }

    fn add_team(&mut self, rank: u8, t: &Team) {
        let detail = format!("team of {} robot{}", t.robots.len(), plural(t.robots.len()));
        let doc = docs::team_brief(t);
        self.add(
            rank,
            CompletionKind::Team,
            t.name.as_str(),
            Some(detail),
            Some(doc),
        );
    }

    /// A catalog value, documented as `owner.NAME` when written after `owner.`.
    fn add_value(&mut self, rank: u8, v: &ValueDef, owner: Option<&str>) {
        self.add(
            rank,
            CompletionKind::Value,
            v.name.as_str(),
            Some(docs::value_detail(v)),
            Some(docs::value(owner, v)),
        );
    }

    /// The team's variables, but for those named as a value of `types` (the
    /// robots the checker reads the name on): `COLOR` received is then the
    /// robots' value, as the checker reads it, and is offered once, as that.
    fn add_team_variables(&mut self, rank: u8, team: TeamId, types: &[RobotTypeId]) {
        let t = self.mission.team(team);
        for var in &t.variables {
            if types
                .iter()
                .any(|ty| self.catalog.get(*ty).value(var).is_some())
            {
                continue;
            }
            self.add(
                rank,
                CompletionKind::TeamVariable,
                var.as_str(),
                Some(format!("team variable of {}", t.name)),
                None,
            );
        }
    }

    fn add_event(&mut self, rank: u8, t: &Team, name: &Name, detail: String) {
        let doc = docs::event(t, name);
        self.add(
            rank,
            CompletionKind::Event,
            name.as_str(),
            Some(detail),
            Some(doc),
        );
    }

    fn add_user(&mut self, rank: u8) {
        let doc = self
            .catalog
            .user()
            .map(|u| u.doc.clone())
            .filter(|d| !d.is_empty());
        self.add(
            rank,
            CompletionKind::User,
            "USER",
            Some("the operator's console".to_string()),
            doc,
        );
    }

    // ----- values -----

    fn expression(&mut self, qualifier: Option<&Name>) {
        if let Some(q) = qualifier {
            return self.member(q);
        }
        let here = self.robots_here();
        let types = here.types(self.mission);
        // In a function's body, its parameters first: what a call gives.
        let analysis = self.analysis;
        let function = self.mission.functions.iter().find(|f| {
            analysis
                .function_syntax(f)
                .is_some_and(|syntax| syntax.body.span.contains(self.offset))
        });
        let body_owner = if let Some(f) = function {
            let signature = super::hover::function_signature(f);
            for p in &f.params {
                let detail = format!("parameter of {signature}");
                self.add(
                    LIKELY,
                    CompletionKind::Parameter,
                    p.name.as_str(),
                    Some(detail),
                    None,
                );
            }
            self.mission
                .functions
                .iter()
                .position(|g| std::ptr::eq(g, f))
                .map(|i| crate::sema::ParamOwner::Function(crate::sema::FunctionId(i as u32)))
        } else {
            // In a service's body with parameters or results, its
            // parameters first.
            let service = self.mission.teams.iter().enumerate().find_map(|(t, team)| {
                team.service_ids().find_map(|s| {
                    let info = team.service(s);
                    let inside = !(info.params.is_empty() && info.results.is_empty())
                        && analysis
                            .service_syntax(info)
                            .is_some_and(|syntax| syntax.body.span.contains(self.offset));
                    inside.then_some(crate::sema::ParamOwner::Service(
                        crate::sema::TeamId(t as u32),
                        s,
                    ))
                })
            });
            if let Some(owner) = service {
                let whose = self.mission.owner_name(owner);
                for p in self.mission.params(owner) {
                    let detail = format!("parameter of {whose}");
                    self.add(
                        LIKELY,
                        CompletionKind::Parameter,
                        p.name.as_str(),
                        Some(detail),
                        None,
                    );
                }
            }
            service
        };
        // The results bound before the cursor: what the calls gave back.
        if let Some(owner) = body_owner {
            for r in self.mission.results(owner) {
                if r.span.end > self.offset {
                    continue;
                }
                let ty = r.ty.as_ref().map_or(String::new(), |ty| format!(", {ty}"));
                let detail = format!("result of {}{ty}", r.service);
                self.add(
                    LIKELY,
                    CompletionKind::Result,
                    r.name.as_str(),
                    Some(detail),
                    None,
                );
            }
        }
        for v in robots::shared_values(self.catalog, &types) {
            self.add_value(LIKELY, v, None);
        }
        for team in here.teams() {
            self.add_team_variables(LIKELY, team, &types);
        }
        for t in &self.mission.teams {
            self.add_team(OTHER, t);
        }
        self.add_user(OTHER);
        for word in ["true", "false", "not"] {
            self.add(KEYWORD, CompletionKind::Keyword, word, None, None);
        }
    }

    /// The right side of a comparison: after `==` or `!=`, first the
    /// constants the value on the left can hold (its enumeration, `true`
    /// and `false`, the words and literals the mission compares it with or
    /// sets it to); then the teams and `USER`, whose values are written
    /// qualified here (a bare value on the right is E041).
    fn compared(&mut self, attr: Option<&[Name]>, words: bool) {
        if words && let Some(attr) = attr {
            let here = self.robots_here();
            let what = attr.iter().map(Name::as_str).collect::<Vec<_>>().join(".");
            let (symbol, ty) = self.compared_value(attr, &here);
            match ty {
                Some(ValueType::Enum(domain)) => {
                    for d in &domain {
                        let detail = format!("a value of {what}");
                        self.add(
                            EXACT,
                            CompletionKind::Constant,
                            d.as_str(),
                            Some(detail),
                            None,
                        );
                    }
                }
                Some(ValueType::Bool) => {
                    for b in ["true", "false"] {
                        self.add(
                            EXACT,
                            CompletionKind::Constant,
                            b,
                            Some(format!("a value of {what}")),
                            None,
                        );
                    }
                }
                _ => {
                    let written = symbol
                        .map(|s| values::constants_of(self.analysis, self.text, &s))
                        .unwrap_or_default();
                    for c in written {
                        let detail = format!("{what} is {} with it in this mission", c.how);
                        self.add(EXACT, CompletionKind::Constant, c.text, Some(detail), None);
                    }
                }
            }
        }
        for t in &self.mission.teams {
            self.add_team(OTHER, t);
        }
        self.add_user(OTHER);
    }

    /// After `Team.` or `USER.`: the team's values and variables.
    fn member(&mut self, qualifier: &Name) {
        if is_user(qualifier) {
            let values = self
                .catalog
                .user()
                .map(|u| u.values.clone())
                .unwrap_or_default();
            for v in &values {
                self.add_value(EXACT, v, Some("USER"));
            }
            return;
        }
        let Some((team, t)) = self.team(qualifier) else {
            return;
        };
        let here = self.robots_here();
        // A team's own values must be had by every robot running the
        // statement; another team's by some of its robots.
        let (values, types) = if here.teams() == [team] {
            let types = here.types(self.mission);
            (robots::shared_values(self.catalog, &types), types)
        } else {
            let types = robots::team_types(self.mission, team);
            (robots::any_values(self.catalog, &types), types)
        };
        for v in values {
            self.add_value(EXACT, v, Some(&t.name));
        }
        self.add_team_variables(EXACT, team, &types);
    }

    /// What the dotted name on the left of a comparison reads, as the
    /// checker records it (`Symbol::Value` or `Symbol::TeamVariable`), and
    /// its catalog type when it is a catalog value.
    fn compared_value(
        &self,
        attr: &[Name],
        here: &RobotsHere,
    ) -> (Option<Symbol>, Option<ValueType>) {
        let catalog_value = |owner: TeamId, types: &[RobotTypeId], name: &Name| {
            let def = types
                .iter()
                .find_map(|ty| self.catalog.get(*ty).value(name))?;
            let symbol = Symbol::Value {
                owner: Some(owner),
                name: name.clone(),
            };
            Some((Some(symbol), Some(def.ty.clone())))
        };
        match attr {
            // A bare name: a value of the robots running the statement.
            [name] => {
                let team = match here.teams().as_slice() {
                    [team] => Some(*team),
                    [] => self.head_team().map(|(id, _)| id),
                    _ => None,
                };
                let Some(team) = team else {
                    return (None, None);
                };
                let mut types = here.types(self.mission);
                if types.is_empty() {
                    types = robots::team_types(self.mission, team);
                }
                catalog_value(team, &types, name).unwrap_or((None, None))
            }
            [user, name] if is_user(user) => {
                let ty = self
                    .catalog
                    .user()
                    .and_then(|u| u.value(name))
                    .map(|v| v.ty.clone());
                let symbol = Symbol::Value {
                    owner: None,
                    name: name.clone(),
                };
                (Some(symbol), ty)
            }
            // `Team.NAME`: a value of its robots, else a team variable.
            [team, name] => {
                let Some((id, _)) = self.team(team) else {
                    return (None, None);
                };
                let types = robots::team_types(self.mission, id);
                catalog_value(id, &types, name).unwrap_or_else(|| {
                    let symbol = Symbol::TeamVariable {
                        team: Some(id),
                        name: name.clone(),
                    };
                    (Some(symbol), None)
                })
            }
            _ => (None, None),
        }
    }

    // ----- modes and main blocks -----

    /// The tokens directly inside the item's braces (the mode or main body).
    fn body_level(&self) -> &'a [Lt<'a>] {
        let scan: &'a Scan<'a> = self.scan;
        scan.frames
            .iter()
            .find(|f| f.opener == Token::LBrace)
            .map_or(&[], |f| f.level.as_slice())
    }

    /// The first names of the closed `(...)` of `paren` in the body so far.
    fn closed_names(&self, paren: &Paren) -> Vec<Name> {
        self.body_level()
            .iter()
            .filter_map(|t| match t {
                Lt::Closed {
                    paren: Some(p),
                    first_name: Some(n),
                    ..
                } if p == paren => Some(n.clone()),
                _ => None,
            })
            .collect()
    }

    /// Whether the main block at the cursor has its `default` (before the
    /// cursor, or anywhere in it as parsed).
    fn main_has_default(&self) -> bool {
        let typed = self
            .body_level()
            .iter()
            .any(|t| matches!(t, Lt::Tok(Token::Kw(crate::syntax::token::Kw::Default), _)));
        let parsed = self.analysis.syntax.items.iter().any(|item| {
            matches!(item, ast::Item::Main(m)
                if m.span.start < self.offset && self.offset < m.span.end && m.default.is_some())
        });
        typed || parsed
    }

    fn set_plans(&mut self) {
        let Some((_, t)) = self.head_team() else {
            return;
        };
        let set = self.closed_names(&Paren::Set);
        for (i, p) in t.plans.iter().enumerate() {
            let rank = if set.contains(&p.name) { OTHER } else { EXACT };
            self.add(
                rank,
                CompletionKind::Plan,
                p.name.as_str(),
                Some(format!("plan of {}", t.name)),
                Some(docs::plan(self.text, t, PlanId::new(i))),
            );
        }
    }

    fn set_services(&mut self, plan: &Name) {
        let Some((team, t)) = self.head_team() else {
            return;
        };
        let Some(p) = t.plan_by_name(plan) else {
            return;
        };
        for (i, s) in t.services.iter().enumerate() {
            if s.plan != p {
                continue;
            }
            let syntax = self.analysis.service_syntax(s);
            let detail = Some(format!(
                "{} {}",
                t.service_path(ServiceId::new(i)),
                docs::schedule(self.text, syntax)
            ));
            let documentation = Some(docs::composite_service(
                self.analysis,
                self.text,
                team,
                ServiceId::new(i),
            ));
            if s.params.is_empty() {
                self.add(
                    EXACT,
                    CompletionKind::Service,
                    s.name.as_str(),
                    detail,
                    documentation,
                );
            } else {
                // `Go(${1:PLACE})` for a service with parameters.
                let body = snippets::call(&s.name, s.params.iter().map(|p| p.name.as_str()));
                let name = s.name.as_str();
                self.add_snippet(
                    EXACT,
                    CompletionKind::Service,
                    name,
                    &body,
                    detail,
                    documentation,
                );
            }
        }
        self.add(
            LIKELY,
            CompletionKind::Constant,
            "OFF",
            Some(format!("the plan {plan} does not run in this mode")),
            None,
        );
    }

    fn case_modes(&mut self) {
        let Some((_, t)) = self.head_team() else {
            return;
        };
        let cased = self.closed_names(&Paren::Case);
        // A mode with parameters is named without arguments in `case`.
        for (i, m) in t.templates.iter().enumerate() {
            let rank = if cased.contains(&m.name) {
                OTHER
            } else {
                EXACT
            };
            self.add(
                rank,
                CompletionKind::Mode,
                m.name.as_str(),
                Some(format!("mode with parameters of {}", t.name)),
                Some(docs::mode_template(t, crate::sema::TemplateId::new(i))),
            );
        }
        for (i, m) in t.modes.iter().enumerate() {
            if m.instance.is_some() {
                continue;
            }
            let rank = if cased.contains(&m.name) {
                OTHER
            } else {
                EXACT
            };
            self.add(
                rank,
                CompletionKind::Mode,
                m.name.as_str(),
                Some(format!("mode of {}", t.name)),
                Some(docs::mode(self.text, t, ModeId::new(i))),
            );
        }
    }

    fn mode_names(&mut self) {
        let Some((_, t)) = self.head_team() else {
            return;
        };
        for (i, m) in t.modes.iter().enumerate() {
            if m.instance.is_some() {
                continue;
            }
            self.add(
                EXACT,
                CompletionKind::Mode,
                m.name.as_str(),
                Some(format!("mode of {}", t.name)),
                Some(docs::mode(self.text, t, ModeId::new(i))),
            );
        }
        // `MOVE(${1:TARGET})`: a stop at each parameter, named.
        for (i, m) in t.templates.iter().enumerate() {
            let call = snippets::call(&m.name, m.params.iter().map(|p| p.name.as_str()));
            self.add_snippet(
                EXACT,
                CompletionKind::Mode,
                m.name.as_str(),
                &call,
                Some(format!("mode with parameters of {}", t.name)),
                Some(docs::mode_template(t, crate::sema::TemplateId::new(i))),
            );
        }
    }

    /// Events of the team: first those that the services of the case's mode
    /// throw and the case does not catch yet.
    fn catch_events(&mut self, mode: Option<&Name>) {
        let Some((_, t)) = self.head_team() else {
            return;
        };
        let thrown_here: Vec<&Name> = mode
            .and_then(|m| t.mode_by_name(m))
            .map(|m| {
                t.modes[m.index()]
                    .sets
                    .iter()
                    .filter_map(|s| s.service)
                    .flat_map(|s| &t.services[s.index()].throws)
                    .collect()
            })
            .unwrap_or_default();
        // Catches of the current case: after its `case (M):`.
        let level = self.body_level();
        let case_start = level
            .iter()
            .rposition(|l| {
                matches!(
                    l,
                    Lt::Closed {
                        paren: Some(Paren::Case),
                        ..
                    }
                )
            })
            .map_or(level.len(), |i| i + 1);
        let caught: Vec<Name> = level[case_start..]
            .iter()
            .filter_map(|l| match l {
                Lt::Closed {
                    paren: Some(Paren::Catch),
                    first_name: Some(n),
                    ..
                } => Some(n.clone()),
                _ => None,
            })
            .collect();
        for e in &t.events {
            let rank = match (thrown_here.contains(&&e.name), caught.contains(&e.name)) {
                (_, true) => OTHER,
                (true, false) => EXACT,
                (false, false) => LIKELY,
            };
            let detail = match thrown_here.contains(&&e.name) {
                true => format!(
                    "thrown by a service of {}",
                    mode.map(Name::as_str).unwrap_or("this mode")
                ),
                false => format!("event of {}", t.name),
            };
            self.add_event(rank, t, &e.name, detail);
        }
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

fn plan_names(t: &Team) -> Vec<Name> {
    t.plans.iter().map(|p| p.name.clone()).collect()
}

/// `iRobotCreate`'s one line: `linux, ARM Cortex-A7`.
fn platform_line(r: &crate::catalog::RobotType) -> String {
    let p = &r.platform;
    let parts: Vec<&str> = [p.os.as_str(), p.cpu.as_str()]
        .into_iter()
        .filter(|s| !s.is_empty())
        .collect();
    match parts.is_empty() {
        true => "robot type".to_string(),
        false => format!("robot type: {}", parts.join(", ")),
    }
}

/// `move(${1:goal})`: the required parameters as placeholders; optional ones
/// are left out (the cursor stops inside the parentheses).
fn service_call_snippet(def: &crate::catalog::ServiceDef) -> String {
    let name = snippets::escape(&def.name);
    let required: Vec<String> = def
        .params
        .iter()
        .filter(|p| !p.optional)
        .enumerate()
        .map(|(i, p)| format!("${{{}:{}}}", i + 1, snippets::escape(&p.name)))
        .collect();
    match (def.params.is_empty(), required.is_empty()) {
        (true, _) => format!("{name}()"),
        (false, true) => format!("{name}($1)$0"),
        (false, false) => format!("{name}({})$0", required.join(", ")),
    }
}
