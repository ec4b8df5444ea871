//! Hover: what the name under the cursor means, in markdown.
//!
//! Services: signature, doc, and which robot types provide them (of this team,
//! where the name is used in a statement); values: type, unit, doc, providers;
//! teams: their robots; modes: what each plan runs; events: who throws them
//! and who catches them; keywords: their entry of the language reference
//! ([`keywords`]).

use super::docs::{self, list};
use super::keywords;
use super::robots::{self, RobotsHere};
use crate::catalog::{Catalog, RobotTypeId};
use crate::ide::HoverResult;
use crate::sema::{CheckedMission, Mission, Symbol, TeamId};
use std::fmt::Write;

/// The hover at `offset`, if a known name is there.
pub fn hover(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    offset: usize,
) -> Option<HoverResult> {
    let mission = &analysis.mission;
    let Some(occurrence) = robots::occurrence_at(mission, offset.min(text.len())) else {
        return keywords::hover(&analysis.syntax, text, offset);
    };
    let range = occurrence.span;
    let markdown = match &occurrence.symbol {
        Symbol::Team(t) => docs::team(catalog, mission.team(*t)),
        Symbol::User => {
            let mut out = "**USER**: the operator's console".to_string();
            if let Some(u) = catalog.user() {
                if !u.doc.is_empty() {
                    write!(out, "\n\n{}", u.doc).ok();
                }
                let values: Vec<String> = u
                    .values
                    .iter()
                    .map(|v| format!("`USER.{}` ({})", v.name, v.ty))
                    .collect();
                if !values.is_empty() {
                    write!(out, "\n\nValues: {}.", values.join(", ")).ok();
                }
            }
            out
        }
        Symbol::Robot { team, robot } => {
            let t = mission.team(*team);
            let r = t.robots.get(robot.index())?;
            let mut out = docs::code(&format!("{} {}", r.type_name, r.name));
            write!(out, "\n\nA robot of team `{}`.", t.name).ok();
            if let Some(ty) = r.robot_type {
                let doc = &catalog.get(ty).doc;
                if !doc.is_empty() {
                    write!(out, "\n\n{doc}").ok();
                }
            }
            out
        }
        Symbol::RobotType(name) => docs::robot_type(catalog.robot(name)?),
        Symbol::Capability(name) => capability(analysis, catalog, name, offset),
        Symbol::CountedGroup {
            team,
            name,
            min,
            robots,
        } => format!(
            "**group** `{name}`: a counted group of at least {min} robot{}, chosen at run time among the {robots} robot{} of team `{}` that run this statement. Each robot, at each pass, gives the live robots in formation order to the groups up to their minimums in declaration order; a spare runs `others`, else joins the groups round-robin; with too few alive, the later groups are short.",
            if *min == 1 { "" } else { "s" },
            if *robots == 1 { "" } else { "s" },
            mission.team(*team).name
        ),
        Symbol::Plan { team, plan } => docs::plan(text, mission.team(*team), *plan),
        Symbol::Service { team, service } => {
            docs::composite_service(analysis, text, *team, *service)
        }
        Symbol::Mode { team, mode } => docs::mode(text, mission.team(*team), *mode),
        Symbol::Event { team, name } => docs::event(mission.team(*team), name),
        Symbol::Function(f) => {
            let info = mission.functions.get(f.0 as usize)?;
            let mut out = docs::code(&function_signature(info));
            out.push_str("\n\nA function: its statements are copied where it is called");
            out.push_str(if info.params.is_empty() {
                "."
            } else {
                ", each parameter standing for the call's argument."
            });
            let teams: Vec<String> = mission
                .scopes
                .iter()
                .filter(|s| s.kind == crate::sema::ScopeKind::Function(*f))
                .flat_map(|s| &s.runs)
                .filter_map(|r| r.team)
                .map(|t| format!("`{}`", mission.team(t).name))
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            if teams.is_empty() {
                out.push_str("\n\nNo service calls it.");
            } else {
                write!(out, "\n\nCalled by services of {}.", list(&teams)).ok();
            }
            out
        }
        Symbol::BuiltinService(name) => builtin_service(analysis, catalog, name, offset)?,
        Symbol::Value { owner, name } => value(analysis, catalog, *owner, name, offset)?,
        Symbol::TeamVariable { team, name } => {
            let mut out = docs::code(&match team {
                Some(t) => format!("{}.{name}", mission.team(*t).name),
                None => name.to_string(),
            });
            out.push_str("\n\nA team variable: set where it is sent or published with `=`.");
            let owner = team.map(|t| mission.team(t).name.clone());
            let senders: Vec<String> = mission
                .messages
                .iter()
                .filter(|m| m.kind.is_outgoing())
                .filter(|m| m.value.name == *name)
                .filter(|m| owner.as_ref().is_none_or(|o| m.value.owner == *o))
                .map(|m| {
                    format!(
                        "`{}` ({})",
                        mission.team(m.team).service_path(m.service),
                        m.kind.as_str()
                    )
                })
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            if !senders.is_empty() {
                write!(out, "\n\nDelivered by {}.", list(&senders)).ok();
            }
            out
        }
        Symbol::Constant(name) => format!(
            "{}\n\nA symbolic constant: a word passed or compared as it is written.",
            docs::code(name)
        ),
        Symbol::Parameter { owner, index } => parameter(mission, *owner, *index as usize)?,
        Symbol::Result { owner, index } => result(mission, *owner, *index as usize)?,
        Symbol::ModeTemplate { team, template } => {
            docs::mode_template(mission.team(*team), *template)
        }
    };
    Some(HoverResult { range, markdown })
}

/// `def name(A, B)`, or `def name` without parameters.
pub(super) fn function_signature(info: &crate::sema::FunctionInfo) -> String {
    if info.params.is_empty() {
        return format!("def {}", info.name);
    }
    let names: Vec<&str> = info.params.iter().map(|p| p.name.as_str()).collect();
    format!("def {}({})", info.name, names.join(", "))
}

/// An action result: the service whose call binds it, its type, and what
/// it holds when.
fn result(
    mission: &crate::sema::Mission,
    owner: crate::sema::ParamOwner,
    index: usize,
) -> Option<String> {
    let result = mission.results(owner).get(index)?;
    let mut out = docs::code(&match &result.ty {
        Some(ty) => format!("{}: {ty}", result.name),
        None => result.name.to_string(),
    });
    let which = match &result.catalog_name {
        Some(name) => format!("the result `{name}` of `{}`", result.service),
        None => format!("a result of `{}`", result.service),
    };
    write!(
        out,
        "\n\nAction result, {which}, bound in `{}`: what the call gave back when it was done (the robot's own). None until then, and after a call stopped by its timeout.",
        mission.owner_name(owner)
    )
    .ok();
    Some(out)
}

/// A parameter: whose it is, what it means, and what its uses ask of each
/// call's argument (the checker's needs, its own and those of the
/// functions it is passed on to).
fn parameter(
    mission: &crate::sema::Mission,
    owner: crate::sema::ParamOwner,
    index: usize,
) -> Option<String> {
    use crate::sema::ParamOwner;
    let params = mission.params(owner);
    let param = params.get(index)?;
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    let (signature, meaning) = match owner {
        ParamOwner::Function(f) => (
            function_signature(mission.functions.get(f.0 as usize)?),
            "in its body it stands for the argument of the call being run, read where it is used",
        ),
        ParamOwner::Service(..) => (
            format!("{}({})", mission.owner_name(owner), names.join(", ")),
            "in its body it stands for the argument the mode's `set` gives, fixed when the mission is written",
        ),
        ParamOwner::Mode(..) => (
            format!("{}({})", mission.owner_name(owner), names.join(", ")),
            "in the mode's `set`s it stands for the argument the mode is entered with (`mode = M(...)`): each list of arguments is a mode of its own",
        ),
    };
    let mut out = docs::code(&param.name);
    write!(
        out,
        "\n\nParameter {} of `{signature}`: {meaning}.",
        index + 1,
    )
    .ok();
    let asks: Vec<String> = param.needs.iter().map(docs::param_need).collect();
    if asks.is_empty() {
        out.push_str("\n\nAny argument fits.");
    } else {
        write!(out, "\n\nIts argument is {}.", list(&asks)).ok();
    }
    Some(out)
}

/// A built-in service where it is called: which types of the robots running
/// the statement provide it, and which other catalog types do.
fn builtin_service(
    analysis: &CheckedMission,
    catalog: &Catalog,
    name: &str,
    offset: usize,
) -> Option<String> {
    let mission = &analysis.mission;
    let providers = robots::service_providers(catalog, name);
    let here = RobotsHere::at(analysis, offset, None);
    let types_here = here.types(mission);
    let def = types_here
        .iter()
        .chain(&providers)
        .find_map(|ty| catalog.get(*ty).service(name))?;
    let mut out = docs::service(def);
    let mut shown: Vec<RobotTypeId> = Vec::new();
    for (team, providing) in types_per_team(mission, &here, |ty| providers.contains(&ty)) {
        write!(
            out,
            "\n\nIn team `{}`, provided by {}.",
            mission.team(team).name,
            docs::types_with_robots(catalog, mission, team, &providing)
        )
        .ok();
        shown.extend(providing);
    }
    let others: Vec<String> = providers
        .iter()
        .filter(|ty| !shown.contains(ty))
        .map(|ty| format!("`{}`", catalog.get(*ty).name))
        .collect();
    if !others.is_empty() {
        let lead = if shown.is_empty() {
            "Provided by"
        } else {
            "Also provided by"
        };
        write!(out, "\n\n{lead} {}.", list(&others)).ok();
    }
    Some(out)
}

/// A robot value: its definition, and which types of the team have it.
fn value(
    analysis: &CheckedMission,
    catalog: &Catalog,
    owner: Option<TeamId>,
    name: &str,
    offset: usize,
) -> Option<String> {
    let mission = &analysis.mission;
    let Some(team) = owner else {
        let def = catalog.user()?.value(name)?;
        return Some(docs::value(Some("USER"), def));
    };
    // The robots reading it: those running the statement for the team's own
    // values, all of the team's robots for another team's.
    let here = RobotsHere::at(analysis, offset, None);
    let types = if here.teams() == [team] {
        here.types(mission)
    } else {
        robots::team_types(mission, team)
    };
    let having: Vec<RobotTypeId> = types
        .iter()
        .copied()
        .filter(|ty| catalog.get(*ty).value(name).is_some())
        .collect();
    let def = having
        .iter()
        .find_map(|ty| catalog.get(*ty).value(name))
        .or_else(|| catalog.types().find_map(|(_, r)| r.value(name)))?;
    let t = mission.team(team);
    let mut out = docs::value(Some(&t.name), def);
    if !having.is_empty() {
        write!(
            out,
            "\n\nIn team `{}`, read from {}.",
            t.name,
            docs::types_with_robots(catalog, mission, team, &having)
        )
        .ok();
    }
    // Where the types differ, say what each means by it.
    let docs_differ = having
        .iter()
        .filter_map(|ty| catalog.get(*ty).value(name))
        .any(|v| v.doc != def.doc);
    if docs_differ {
        for ty in &having {
            if let Some(v) = catalog.get(*ty).value(name) {
                write!(out, "\n- `{}`: {}", catalog.get(*ty).name, v.doc).ok();
            }
        }
    }
    Some(out)
}

/// A capability in a group condition: which robot types have it, and which
/// robots of the team.
fn capability(analysis: &CheckedMission, catalog: &Catalog, name: &str, offset: usize) -> String {
    let mission = &analysis.mission;
    let mut out = format!("**capability** `{name}`");
    let types: Vec<String> = catalog
        .types()
        .filter(|(_, r)| r.has_capability(name))
        .map(|(_, r)| format!("`{}`", r.name))
        .collect();
    write!(out, "\n\nRobot types that have it: {}.", list(&types)).ok();
    let here = RobotsHere::at(analysis, offset, None);
    let has = |ty: RobotTypeId| catalog.get(ty).has_capability(name);
    for (team, having) in types_per_team(mission, &here, has) {
        write!(
            out,
            "\n\nIn team `{}`: {}.",
            mission.team(team).name,
            docs::types_with_robots(catalog, mission, team, &having)
        )
        .ok();
    }
    out
}

/// Per team running the place, the robot types there (of that team) that
/// `keep` accepts; teams with none are left out.
fn types_per_team(
    mission: &Mission,
    here: &RobotsHere,
    keep: impl Fn(RobotTypeId) -> bool,
) -> Vec<(TeamId, Vec<RobotTypeId>)> {
    let types_here = here.types(mission);
    here.teams()
        .into_iter()
        .filter_map(|team| {
            let team_types = robots::team_types(mission, team);
            let types: Vec<RobotTypeId> = types_here
                .iter()
                .copied()
                .filter(|ty| keep(*ty) && team_types.contains(ty))
                .collect();
            (!types.is_empty()).then_some((team, types))
        })
        .collect()
}
