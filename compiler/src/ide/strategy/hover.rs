//! Hover in strategy files: what an element or attribute means (from the
//! format's description), and for names, what they refer to (a team, robot
//! type, plan, built-in service with its signature, value, task or action).

use super::StrategyFile;
use super::raw::{RawAttr, RawTag, position_at};
use crate::catalog::{Implementation, RobotType};
use crate::ide::HoverResult;
use crate::strategy::schema::{attribute_doc, children, element_info};
use crate::strategy::{CONTROL_TASK, team_calls};
use std::fmt::Write;

pub fn hover(file: &StrategyFile<'_>, offset: usize) -> Option<HoverResult> {
    let text = file.text;
    let offset = offset.min(text.len());
    if !text.is_char_boundary(offset) {
        return None;
    }
    let tag = position_at(text, offset).tag?;
    if tag.name_span.touches(offset) && !tag.name.is_empty() {
        return Some(HoverResult {
            range: tag.name_span,
            markdown: element_doc(tag.name)?,
        });
    }
    let attr = tag
        .attrs
        .iter()
        .find(|a| a.name_span.touches(offset) || a.value_span.is_some_and(|v| v.touches(offset)))?;
    let in_value = attr.value_span.filter(|v| v.touches(offset));
    if let Some(span) = in_value
        && let Some(markdown) = refers_to(file, &tag, attr, offset)
    {
        return Some(HoverResult {
            range: span,
            markdown,
        });
    }
    let doc = attribute_doc(tag.name, attr.name)?;
    Some(HoverResult {
        range: in_value.unwrap_or(attr.name_span),
        markdown: format!("**`{}`** of `<{}>`\n\n{doc}", attr.name, tag.name),
    })
}

fn element_doc(name: &str) -> Option<String> {
    let info = element_info(name)?;
    let mut md = format!("**`<{name}>`**\n\n{}", info.doc);
    if !info.attributes.is_empty() {
        let attrs: Vec<String> = info
            .attributes
            .iter()
            .map(|a| match info.required.contains(a) {
                true => format!("`{a}` (required)"),
                false => format!("`{a}`"),
            })
            .collect();
        let _ = write!(md, "\n\nattributes: {}", attrs.join(", "));
    }
    let inside = children(Some(name), None);
    if !inside.is_empty() {
        let _ = write!(md, "\n\ncontains: {}", inside.join(", "));
    }
    Some(md)
}

/// The tasks of a robot type's library that the catalog names, with what
/// each implements.
pub(super) fn tasks_of(robot: &RobotType) -> Vec<(&str, String)> {
    let values = robot
        .values
        .iter()
        .map(|v| (&v.implementation, format!("value {}", v.name)));
    let services = robot
        .services
        .iter()
        .map(|s| (&s.implementation, format!("service {}", s.name)));
    let mut out: Vec<(&str, String)> = Vec::new();
    for (implementation, what) in values.chain(services) {
        let Implementation::Task(task) = implementation else {
            continue;
        };
        match out.iter_mut().find(|(t, _)| t == task) {
            Some((_, all)) => {
                let _ = write!(all, ", {what}");
            }
            None => out.push((task.as_str(), format!("implements {what}"))),
        }
    }
    out
}

/// What the name in `attr`'s value refers to, if the model knows it.
fn refers_to(
    file: &StrategyFile<'_>,
    tag: &RawTag<'_>,
    attr: &RawAttr<'_>,
    offset: usize,
) -> Option<String> {
    let value = attr.value?.trim();
    let catalog = file.catalog;
    match (tag.name, attr.name) {
        ("Strategy", "name") => {
            let mut md = String::new();
            for analysis in file.missions {
                let Some(id) = analysis.mission.team_by_name(value) else {
                    continue;
                };
                let team = analysis.mission.team(id);
                let robots: Vec<String> = team
                    .robots
                    .iter()
                    .map(|r| format!("`{}` ({})", r.name, r.type_name))
                    .collect();
                let plans: Vec<&str> = team.plans.iter().map(|p| p.name.as_str()).collect();
                let _ = write!(
                    md,
                    "**team** `{value}`\n\nrobots: {}\n\nplans: {}",
                    robots.join(", "),
                    plans.join(", ")
                );
                break;
            }
            (!md.is_empty()).then_some(md)
        }
        ("TargetRobot", "name") => {
            let robot = catalog.robot(value)?;
            let services: Vec<String> = robot.services.iter().map(|s| s.signature()).collect();
            let values: Vec<&str> = robot.values.iter().map(|v| v.name.as_str()).collect();
            Some(format!(
                "**robot type** `{}`\n\n{}\n\nservices: {}\n\nvalues: {}",
                robot.name,
                robot.doc,
                services.join(", "),
                values.join(", ")
            ))
        }
        ("Service", "name" | "service_name") => {
            let service = file
                .types_at(offset)
                .into_iter()
                .find_map(|r| r.service(value))
                .or_else(|| catalog.types().find_map(|(_, r)| r.service(value)))?;
            let mut md = format!(
                "**built-in service** `{}`\n\n{}",
                service.signature(),
                service.doc
            );
            let plan = tag.value("plan_name");
            let mut callers: Vec<String> = Vec::new();
            for (analysis, id, team) in file.teams() {
                for call in team_calls(analysis, id) {
                    let in_plan = plan.is_none_or(|p| team.plans[call.plan.index()].name == p);
                    let path = team.service_path(call.service);
                    if in_plan && call.name == service.name && !callers.contains(&path) {
                        callers.push(path);
                    }
                }
            }
            if !callers.is_empty() {
                let shown: Vec<String> = callers.iter().map(|c| format!("`{c}`")).collect();
                let _ = write!(md, "\n\ncalled by {}", shown.join(", "));
            }
            Some(md)
        }
        ("Value", "name") => {
            let (robot, def) = file
                .types_at(offset)
                .into_iter()
                .find_map(|r| r.value(value).map(|v| (r, v)))?;
            let unit = def
                .unit
                .as_ref()
                .map(|u| format!(" ({u})"))
                .unwrap_or_default();
            Some(format!(
                "**value** `{}`: {}{unit} of {}\n\n{}",
                def.name, def.ty, robot.name, def.doc
            ))
        }
        ("Service" | "LeaderSelectionInfo", "plan_name") => {
            for (_, _, team) in file.teams() {
                let Some(plan) = team.plan_by_name(value) else {
                    continue;
                };
                let services: Vec<String> = team
                    .services
                    .iter()
                    .filter(|s| s.plan == plan)
                    .map(|s| format!("`{}`", s.name))
                    .collect();
                return Some(format!(
                    "**plan** `{value}` of team {}\n\ncomposite services: {}",
                    team.name,
                    services.join(", ")
                ));
            }
            None
        }
        ("Parameter", "srcTask" | "dstTask") => {
            if value == CONTROL_TASK {
                return Some(format!(
                    "**task** `{CONTROL_TASK}`: the control task the refinement synthesizes for every robot"
                ));
            }
            file.types_at(offset).into_iter().find_map(|robot| {
                let (task, what) = tasks_of(robot).into_iter().find(|(t, _)| *t == value)?;
                Some(format!("**task** `{task}` of {}: {what}", robot.name))
            })
        }
        ("Transition", "srcId" | "dstId") => {
            let id: u64 = value.parse().ok()?;
            let (_, service) = file.service_at(offset)?;
            let action = service.action_by_id(id)?;
            let mut md = format!("**action** {}", action.describe());
            if action.initial.is_yes() {
                md.push_str(", initial");
            }
            if action.is_final.is_yes() {
                md.push_str(", final");
            }
            Some(md)
        }
        _ => None,
    }
}
