//! Markdown descriptions of what names mean, shared by hover and completion.

use crate::catalog::{Catalog, RobotType, RobotTypeId, ServiceDef, ValueDef};
use crate::sema::{CheckedMission, Mission, ModeId, ModeSet, PlanId, ServiceId, Team, TeamId};
use crate::syntax::ast;
use std::fmt::Write;

/// A fenced code block in the language.
pub(crate) fn code(text: &str) -> String {
    format!("```semo\n{text}\n```")
}

/// `a, b and c`.
pub(crate) fn list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

fn ticked(names: impl IntoIterator<Item = impl AsRef<str>>) -> Vec<String> {
    names
        .into_iter()
        .map(|n| format!("`{}`", n.as_ref()))
        .collect()
}

/// `iRobotCreate (irobot), TIEvalbot (ti)`: the types, each with its robots.
pub(crate) fn types_with_robots(
    catalog: &Catalog,
    mission: &Mission,
    team: TeamId,
    types: &[RobotTypeId],
) -> String {
    let t = mission.team(team);
    let parts: Vec<String> = types
        .iter()
        .map(|ty| {
            let robots: Vec<&str> = t
                .robots
                .iter()
                .filter(|r| r.robot_type == Some(*ty))
                .map(|r| r.name.as_str())
                .collect();
            format!("`{}` ({})", catalog.get(*ty).name, robots.join(", "))
        })
        .collect();
    list(&parts)
}

/// A built-in service: signature, doc, aliases.
pub(crate) fn service(def: &ServiceDef) -> String {
    let mut out = code(&def.signature());
    if !def.doc.is_empty() {
        write!(out, "\n\n{}", def.doc).ok();
    }
    if !def.results.is_empty() {
        let results: Vec<String> = def
            .results
            .iter()
            .map(|r| match r.doc.is_empty() {
                true => format!("`{}: {}`", r.name, r.ty),
                false => format!("`{}: {}` ({})", r.name, r.ty, r.doc.trim_end_matches('.')),
            })
            .collect();
        let names: Vec<&str> = def.results.iter().map(|r| r.name.as_str()).collect();
        write!(
            out,
            "\n\nGives back {} when done: `{} = {}(...)`.",
            list(&results),
            names.join(", "),
            def.name
        )
        .ok();
    }
    if !def.aliases.is_empty() {
        write!(out, "\n\nAlso written {}.", list(&ticked(&def.aliases))).ok();
    }
    out
}

fn value_type(def: &ValueDef) -> String {
    match &def.unit {
        Some(unit) => format!("{} (in {unit})", def.ty),
        None => def.ty.to_string(),
    }
}

/// One line: `int (in cm)`.
pub(crate) fn value_detail(def: &ValueDef) -> String {
    value_type(def)
}

/// A robot value: name, type, unit, doc.
pub(crate) fn value(owner: Option<&str>, def: &ValueDef) -> String {
    let name = match owner {
        Some(o) => format!("{o}.{}", def.name),
        None => def.name.clone(),
    };
    let mut out = code(&format!("{name}: {}", def.ty));
    if let Some(unit) = &def.unit {
        write!(out, "\n\nUnit: {unit}.").ok();
    }
    if !def.doc.is_empty() {
        write!(out, "\n\n{}", def.doc).ok();
    }
    if !def.aliases.is_empty() {
        write!(out, "\n\nAlso written {}.", list(&ticked(&def.aliases))).ok();
    }
    out
}

/// A robot type of the catalog: doc, platform, capabilities, what it knows and
/// can do.
pub(crate) fn robot_type(robot: &RobotType) -> String {
    let mut out = format!("**robot type** `{}`", robot.name);
    if !robot.aliases.is_empty() {
        write!(out, " (also {})", list(&ticked(&robot.aliases))).ok();
    }
    if !robot.doc.is_empty() {
        write!(out, "\n\n{}", robot.doc).ok();
    }
    let p = &robot.platform;
    let mut platform = Vec::new();
    if !p.os.is_empty() {
        platform.push(p.os.clone());
    }
    if !p.cpu.is_empty() {
        let mut cpu = p.cpu.clone();
        if let (Some(cores), Some(mhz)) = (p.cores, p.clock_mhz) {
            write!(cpu, " {cores}×{mhz} MHz").ok();
        } else if let Some(mhz) = p.clock_mhz {
            write!(cpu, " {mhz} MHz").ok();
        }
        platform.push(cpu);
    }
    if let Some(kb) = p.memory_kb {
        platform.push(if kb >= 1024 {
            format!("{} MB", kb / 1024)
        } else {
            format!("{kb} KB")
        });
    }
    if !platform.is_empty() {
        write!(out, "\n\nPlatform: {}.", platform.join(", ")).ok();
    }
    if let Some((target, _)) = p.target {
        write!(out, "\n\n`semo build` builds it for `{target}`.").ok();
    }
    if !robot.capabilities.is_empty() {
        write!(
            out,
            "\n\nCapabilities: {}.",
            ticked(&robot.capabilities).join(", ")
        )
        .ok();
    }
    if !robot.services.is_empty() {
        let services: Vec<String> = robot
            .services
            .iter()
            .map(|s| format!("`{}`", s.signature()))
            .collect();
        write!(out, "\n\nServices: {}.", services.join(", ")).ok();
    }
    if !robot.values.is_empty() {
        let values: Vec<String> = robot
            .values
            .iter()
            .map(|v| format!("`{}` ({})", v.name, v.ty))
            .collect();
        write!(out, "\n\nValues: {}.", values.join(", ")).ok();
    }
    out
}

/// A team: its robots, plans and modes.
pub(crate) fn team(catalog: &Catalog, t: &Team) -> String {
    let mut out = format!("**team** `{}`", t.name);
    let robots: Vec<String> = t
        .robots
        .iter()
        .map(|r| {
            let doc = r
                .robot_type
                .map(|ty| catalog.get(ty).doc.as_str())
                .and_then(|d| d.split(':').next())
                .unwrap_or("");
            if doc.is_empty() || doc == r.type_name {
                format!("- `{}`: {}", r.name, r.type_name)
            } else {
                format!("- `{}`: {} ({doc})", r.name, r.type_name)
            }
        })
        .collect();
    match robots.len() {
        0 => out.push_str("\n\nNo robots."),
        n => write!(
            out,
            "\n\n{n} robot{}:\n{}",
            if n == 1 { "" } else { "s" },
            robots.join("\n")
        )
        .unwrap_or(()),
    }
    if !t.plans.is_empty() {
        let plans: Vec<String> = t.plans.iter().map(|p| format!("`{}`", p.name)).collect();
        write!(out, "\n\nPlans: {}.", plans.join(", ")).ok();
    }
    if !t.modes.is_empty() {
        let modes: Vec<String> = t.modes.iter().map(|m| format!("`{}`", m.name)).collect();
        write!(out, "\n\nModes: {}.", modes.join(", ")).ok();
    }
    out
}

/// A team in one line, for completion lists (which may hold hundreds):
/// `3 robots: tb_0, tb_1 (Turtlebot3_Burger), ev (Ev3_Robot)`.
pub(crate) fn team_brief(t: &Team) -> String {
    let mut out = format!(
        "**team** `{}` — {} robot{}",
        t.name,
        t.robots.len(),
        plural(t.robots.len())
    );
    for (i, r) in t.robots.iter().enumerate() {
        out.push_str(if i == 0 { ": " } else { ", " });
        out.push_str(&r.name);
        let next = t.robots.get(i + 1).map(|n| n.type_name.as_str());
        if next != Some(r.type_name.as_str()) {
            out.push_str(" (");
            out.push_str(&r.type_name);
            out.push(')');
        }
    }
    out
}

/// A composite service's schedule, as written: `repeat(2 SEC)`, or "runs once".
pub(crate) fn schedule(text: &str, syntax: Option<&ast::CompositeService>) -> String {
    match syntax.and_then(|s| s.repeat.as_ref()) {
        Some(r) => text
            .get(r.span.range())
            .unwrap_or("repeat(...)")
            .to_string(),
        None => "runs once".to_string(),
    }
}

/// A composite service of a team: path, schedule, events, modes that run it.
pub(crate) fn composite_service(
    analysis: &CheckedMission,
    text: &str,
    team: TeamId,
    service: ServiceId,
) -> String {
    let t = analysis.mission.team(team);
    let Some(s) = t.services.get(service.index()) else {
        return String::new();
    };
    let syntax = analysis.service_syntax(s);
    let repeat = match syntax.and_then(|x| x.repeat.as_ref()) {
        Some(_) => format!(" {}", schedule(text, syntax)),
        None => String::new(),
    };
    let mut out = code(&format!("{} {{ ... }}{repeat}", t.service_path(service)));
    let how = match syntax.and_then(|x| x.repeat.as_ref()) {
        None => "Runs once when its mode starts.".to_string(),
        Some(r) => match (&r.period, &r.condition) {
            (None, None) => "Runs again and again, forever.".to_string(),
            (Some(p), None) => format!("Runs again every {}.", period_text(text, p)),
            (None, Some(c)) => format!(
                "Runs again while `{}` holds.",
                text.get(c.span.range()).unwrap_or("...")
            ),
            (Some(p), Some(c)) => format!(
                "Runs again every {} while `{}` holds.",
                period_text(text, p),
                text.get(c.span.range()).unwrap_or("...")
            ),
        },
    };
    write!(out, "\n\n{how}").ok();
    if let Some(shared) = syntax.filter(|x| !x.more_teams.is_empty()) {
        let teams: Vec<String> = std::iter::once(&shared.team)
            .chain(&shared.more_teams)
            .map(|team| format!("`{}`", team.name))
            .collect();
        write!(
            out,
            "\n\nShared by teams {}: each runs its own copy, checked with its own robots.",
            list(&teams)
        )
        .ok();
    }
    if !s.throws.is_empty() {
        write!(out, "\n\nThrows {}.", list(&ticked(&s.throws))).ok();
    }
    let modes: Vec<String> = t
        .modes
        .iter()
        .filter(|m| m.sets.iter().any(|set| set.service == Some(service)))
        .map(|m| format!("`{}`", m.name))
        .collect();
    if modes.is_empty() {
        out.push_str("\n\nNo mode sets it, so it never runs.");
    } else {
        write!(
            out,
            "\n\nRun in mode{} {}.",
            plural(modes.len()),
            list(&modes)
        )
        .ok();
    }
    out
}

fn period_text(text: &str, p: &ast::Period) -> String {
    text.get(p.span.range()).unwrap_or(&p.amount).to_string()
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// A plan: the services it can run, and which one each mode runs.
pub(crate) fn plan(text: &str, t: &Team, plan: PlanId) -> String {
    let Some(p) = t.plans.get(plan.index()) else {
        return String::new();
    };
    let mut out = format!("**plan** `{}` of team `{}`", p.name, t.name);
    let services: Vec<String> = t
        .services
        .iter()
        .filter(|s| s.plan == plan)
        .map(|s| format!("`{}`", s.name))
        .collect();
    write!(out, "\n\nServices: {}.", services.join(", ")).ok();
    let mut runs = Vec::new();
    for m in &t.modes {
        let set = m.sets.iter().find(|s| s.plan == Some(plan));
        let what = match set {
            Some(ModeSet {
                service: Some(s), ..
            }) => format!("`{}`", t.services[s.index()].name),
            Some(set) => unset(text, set),
            None => "nothing".to_string(),
        };
        runs.push(format!("- `{}`: {what}", m.name));
    }
    if !runs.is_empty() {
        write!(out, "\n\nIn each mode:\n{}", runs.join("\n")).ok();
    }
    out
}

/// A mode: what each plan runs, and where its events lead.
/// A mode with parameters: its signature, what each `set` runs, and the
/// modes of the machine it is entered as.
pub(crate) fn mode_template(t: &Team, template: crate::sema::TemplateId) -> String {
    let Some(m) = t.templates.get(template.index()) else {
        return String::new();
    };
    let params: Vec<&str> = m.params.iter().map(|p| p.name.as_str()).collect();
    let mut out = format!(
        "**mode** `{}({})` of team `{}`\n\nA mode with parameters: each list of arguments it is entered with is a mode of its own, with each parameter standing in its `set`s for its argument.",
        m.name,
        params.join(", "),
        t.name
    );
    let mut lines = Vec::new();
    for s in &m.sets {
        let (Some(plan), Some(svc)) = (s.plan, s.service) else {
            continue;
        };
        let args: Vec<String> = s
            .args
            .iter()
            .map(crate::syntax::ast::Arg::written)
            .collect();
        let mut line = format!(
            "- `{}` runs `{}",
            t.plans[plan.index()].name,
            t.services[svc.index()].name
        );
        if !args.is_empty() {
            write!(line, "({})", args.join(", ")).ok();
        }
        line.push('`');
        lines.push(line);
    }
    if !lines.is_empty() {
        write!(out, "\n\n{}", lines.join("\n")).ok();
    }
    let entered: Vec<String> = m
        .instances
        .iter()
        .map(|i| format!("`{}`", t.modes[i.index()].name))
        .collect();
    if entered.is_empty() {
        out.push_str("\n\nNever entered.");
    } else {
        write!(out, "\n\nEntered as {}.", entered.join(", ")).ok();
    }
    out
}

pub(crate) fn mode(text: &str, t: &Team, mode: ModeId) -> String {
    let Some(m) = t.modes.get(mode.index()) else {
        return String::new();
    };
    let mut out = format!("**mode** `{}` of team `{}`", m.name, t.name);
    let mut lines = Vec::new();
    for (i, p) in t.plans.iter().enumerate() {
        let set = m.sets.iter().find(|s| s.plan == Some(PlanId::new(i)));
        let line = match set {
            Some(s) => match s.service {
                Some(svc) => {
                    let args: Vec<String> = s
                        .args
                        .iter()
                        .map(crate::syntax::ast::Arg::written)
                        .collect();
                    let service = match args.is_empty() {
                        true => t.services[svc.index()].name.to_string(),
                        false => format!("{}({})", t.services[svc.index()].name, args.join(", ")),
                    };
                    let mut l = format!("- `{}` runs `{service}`", p.name);
                    if let Some(ms) = s.timeout_ms {
                        write!(l, " (at most {})", millis_text(ms)).ok();
                    }
                    l
                }
                None => match unset(text, s).as_str() {
                    "`OFF`" => format!("- `{}` is `OFF`", p.name),
                    other => format!("- `{}` runs {other}", p.name),
                },
            },
            None => format!("- `{}` does not run", p.name),
        };
        lines.push(line);
    }
    if lines.is_empty() {
        out.push_str("\n\nIt runs no service.");
    } else {
        write!(out, "\n\n{}", lines.join("\n")).ok();
    }
    if let Some(main) = &t.main {
        if main.default == Some(mode) {
            out.push_str("\n\nThe team starts in this mode.");
        }
        let leaves: Vec<String> = main
            .transitions
            .iter()
            .filter(|tr| tr.from == mode)
            .map(|tr| format!("`{}` → `{}`", tr.event, t.modes[tr.to.index()].name))
            .collect();
        if !leaves.is_empty() {
            write!(out, "\n\nOn {}.", leaves.join(", ")).ok();
        }
    }
    out
}

/// What a `set` without a service names: `OFF`, or a service that does not
/// exist (already reported).
fn unset(text: &str, set: &ModeSet) -> String {
    let written = text
        .get(set.span.range())
        .and_then(|s| s.split(',').nth(1))
        .map(|s| s.trim().trim_end_matches(')').trim())
        .unwrap_or("");
    match written {
        "OFF" | "" => "`OFF`".to_string(),
        name => format!("`{name}`, which is not defined"),
    }
}

fn millis_text(ms: f64) -> String {
    if ms >= 1000.0 && (ms / 1000.0).fract() == 0.0 {
        format!("{} SEC", ms / 1000.0)
    } else {
        format!("{ms} MSEC")
    }
}

/// An event: who throws it, and where catching it leads.
pub(crate) fn event(t: &Team, name: &str) -> String {
    let mut out = format!("**event** `{name}` of team `{}`", t.name);
    let throwers: Vec<String> = t
        .services
        .iter()
        .enumerate()
        .filter(|(_, s)| s.throws.iter().any(|e| e == name))
        .map(|(i, _)| format!("`{}`", t.service_path(ServiceId::new(i))))
        .collect();
    if throwers.is_empty() {
        out.push_str("\n\nNo service throws it.");
    } else {
        write!(out, "\n\nThrown by {}.", list(&throwers)).ok();
    }
    let catches: Vec<String> = t
        .main
        .iter()
        .flat_map(|m| &m.transitions)
        .filter(|tr| tr.event == name)
        .map(|tr| {
            format!(
                "`{}` → `{}`",
                t.modes[tr.from.index()].name,
                t.modes[tr.to.index()].name
            )
        })
        .collect();
    if catches.is_empty() {
        out.push_str("\n\nNo mode catches it.");
    } else {
        write!(out, "\n\nCaught in {}.", catches.join(", ")).ok();
    }
    out
}

/// What one use of a parameter asks of its argument, in words.
pub(super) fn param_need(need: &crate::sema::ParamNeed) -> String {
    match &need.kind {
        crate::sema::NeedKind::Argument { service, param, ty } => {
            format!("passed to `{service}` as `{param}` ({ty})")
        }
        crate::sema::NeedKind::Number => "compared as a number".to_string(),
    }
}
