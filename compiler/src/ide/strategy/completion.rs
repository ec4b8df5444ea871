//! CompletionItem in strategy files, from the raw text around the cursor: element
//! names allowed in the parent element, the attributes the tag does not have
//! yet, and attribute values taken from the missions (teams, robot types,
//! plans, the built-in services a team calls) and the catalog (values, tasks).

use super::raw::{Position, RawAttr, RawTag, position_at};
use super::{StrategyFile, distinct};
use crate::ide::{CompletionItem, CompletionKind};
use crate::span::Span;
use crate::strategy::model::{DataCharacteristic, LeaderAlgorithm};
use crate::strategy::schema::{attribute_doc, children, element_info};
use crate::strategy::{CONTROL_TASK, team_calls};

/// The completions at `offset`, most specific first.
pub fn completions(file: &StrategyFile<'_>, offset: usize, snippets: bool) -> Vec<CompletionItem> {
    let text = file.text;
    let offset = offset.min(text.len());
    if !text.is_char_boundary(offset) {
        return Vec::new();
    }
    let position = position_at(text, offset);
    if position.in_markup {
        return Vec::new();
    }
    let Some(tag) = &position.tag else {
        // Between tags: a new element (with its `<`).
        let typed = Span::new(offset, offset);
        return elements(&position, typed, "<", snippets);
    };
    if tag.closing {
        return close_tag(&position, tag, offset);
    }
    if tag.name_span.touches(offset) {
        // A bare name being typed gets its required attributes as well.
        let bare = snippets && tag.attrs.is_empty() && !tag.terminated;
        return elements(&position, tag.name_span, "", bare);
    }
    if let Some(attr) = tag.attrs.iter().find(|a| in_value(text, a, offset)) {
        return values(file, tag, attr, offset);
    }
    let editing = tag.attrs.iter().find(|a| a.name_span.touches(offset));
    if editing.is_none() && !text[..offset].ends_with(|c: char| c.is_ascii_whitespace()) {
        return Vec::new(); // right after a value's quote or inside a word
    }
    attributes(tag, editing, offset, snippets)
}

/// Whether `offset` is inside `attr`'s quoted value.
fn in_value(text: &str, attr: &RawAttr<'_>, offset: usize) -> bool {
    let Some(span) = attr.value_span else {
        return false;
    };
    let quoted = span.start > 0 && matches!(text.as_bytes()[span.start - 1], b'"' | b'\'');
    quoted && span.touches(offset)
}

/// The elements allowed in the parent; with `required`, each inserted with
/// its required attributes as snippet fields (`<Service plan_name="$1" name="$2"`).
fn elements(
    position: &Position<'_>,
    replace: Span,
    prefix: &str,
    required: bool,
) -> Vec<CompletionItem> {
    children(position.parent(), position.grandparent())
        .iter()
        .map(|name| {
            let mut item = CompletionItem::new(*name, CompletionKind::Element, replace);
            item.insert = format!("{prefix}{name}");
            let info = element_info(name);
            if let Some(info) = info {
                if required && !info.required.is_empty() {
                    for (i, attr) in info.required.iter().enumerate() {
                        item.insert.push_str(&format!(" {attr}=\"${}\"", i + 1));
                    }
                    item.snippet = true;
                }
                item = item.documentation(info.doc);
                if !info.required.is_empty() {
                    item = item.detail(format!("needs {}", info.required.join(", ")));
                }
            }
            item
        })
        .collect()
}

/// `</` closes the innermost open element.
fn close_tag(position: &Position<'_>, tag: &RawTag<'_>, offset: usize) -> Vec<CompletionItem> {
    let Some(parent) = position.parent() else {
        return Vec::new();
    };
    if offset < tag.name_span.start {
        return Vec::new();
    }
    let mut item = CompletionItem::new(parent, CompletionKind::Element, tag.name_span);
    if !tag.terminated {
        item.insert.push('>');
    }
    vec![item.detail(format!("closes <{parent}>"))]
}

fn attributes(
    tag: &RawTag<'_>,
    editing: Option<&RawAttr<'_>>,
    offset: usize,
    snippets: bool,
) -> Vec<CompletionItem> {
    let Some(info) = element_info(tag.name) else {
        return Vec::new();
    };
    let replace = editing.map_or(Span::new(offset, offset), |a| a.name_span);
    let has_value = editing.is_some_and(|a| a.value_span.is_some());
    info.attributes
        .iter()
        .filter(|name| {
            !tag.attrs
                .iter()
                .any(|a| a.name == **name && Some(a) != editing)
        })
        .map(|name| {
            let mut item = CompletionItem::new(*name, CompletionKind::Attribute, replace);
            if !has_value {
                item.insert = if snippets {
                    format!("{name}=\"$1\"")
                } else {
                    format!("{name}=\"\"")
                };
                item.snippet = snippets;
            }
            if info.required.contains(name) {
                item = item.detail("required");
            }
            item.documentation(attribute_doc(tag.name, name).unwrap_or_default())
        })
        .collect()
}

/// The values of `attr` (of `tag`) the model knows.
fn values(
    file: &StrategyFile<'_>,
    tag: &RawTag<'_>,
    attr: &RawAttr<'_>,
    offset: usize,
) -> Vec<CompletionItem> {
    let text = file.text;
    let Some(span) = attr.value_span else {
        return Vec::new();
    };
    // A value whose quote is not closed yet ends at the word being typed.
    let end = if attr.closed {
        span.end
    } else {
        text[offset..span.end]
            .find(|c: char| c.is_whitespace() || matches!(c, '/' | '>' | '<'))
            .map_or(span.end, |i| offset + i)
    };
    let replace = Span::new(span.start, end);
    let item = |label: &str, kind| CompletionItem::new(label, kind, replace);
    use CompletionKind as K;
    match (tag.name, attr.name) {
        ("Strategy", "name") => {
            let mut out: Vec<CompletionItem> = Vec::new();
            for analysis in file.missions {
                for team in &analysis.mission.teams {
                    if out.iter().any(|c| c.label == team.name.as_str()) {
                        continue;
                    }
                    let robots: Vec<String> = team
                        .robots
                        .iter()
                        .map(|r| format!("{} {}", r.type_name, r.name))
                        .collect();
                    out.push(item(&team.name, K::Team).detail(distinct(robots).join(", ")));
                }
            }
            out
        }
        ("TargetRobot", "name") => file
            .team_or_catalog_types()
            .into_iter()
            .map(|robot| {
                item(&robot.name, K::RobotType)
                    .detail("robot type")
                    .documentation(robot.doc.clone())
            })
            .collect(),
        ("TargetRobot", "nickName") => {
            let of_type = tag.value("name");
            let mut out = Vec::new();
            for (_, _, team) in file.teams() {
                for robot in &team.robots {
                    if of_type.is_some_and(|t| t != robot.type_name) {
                        continue;
                    }
                    out.push(item(&robot.name, K::Robot).detail(robot.type_name.clone()));
                }
            }
            dedup_labels(out)
        }
        ("Service" | "LeaderSelectionInfo", "plan_name") => {
            let mut out = Vec::new();
            for (_, _, team) in file.teams() {
                for (index, plan) in team.plans.iter().enumerate() {
                    let services: Vec<&str> = team
                        .services
                        .iter()
                        .filter(|s| s.plan.index() == index)
                        .map(|s| s.name.as_str())
                        .collect();
                    out.push(item(&plan.name, K::Plan).detail(format!(
                        "plan of {}: {}",
                        team.name,
                        services.join(", ")
                    )));
                }
            }
            dedup_labels(out)
        }
        ("Service", "name" | "service_name") => services(file, tag, replace),
        ("LeaderSelectionInfo", "cs_name") => {
            let plan = tag.value("plan_name");
            let mut out = Vec::new();
            for (_, _, team) in file.teams() {
                for (index, service) in team.services.iter().enumerate() {
                    let plan_name = &team.plans[service.plan.index()].name;
                    if plan.is_some_and(|p| p != plan_name.as_str()) {
                        continue;
                    }
                    out.push(
                        item(&service.name, K::BuiltinService)
                            .detail(team.service_path(crate::sema::ServiceId::new(index))),
                    );
                }
            }
            dedup_labels(out)
        }
        ("Value", "name") => {
            let mut out = Vec::new();
            for robot in file.types_at(offset) {
                for value in &robot.values {
                    let unit = value.unit.as_ref().map(|u| format!(" ({u})"));
                    out.push(
                        item(&value.name, K::Value)
                            .detail(format!(
                                "{}{} of {}",
                                value.ty,
                                unit.unwrap_or_default(),
                                robot.name
                            ))
                            .documentation(value.doc.clone()),
                    );
                }
            }
            dedup_labels(out)
        }
        (
            "CheckSensor" | "ExecuteActuator" | "ExecuteAlgorithm" | "Sensor" | "Actuator",
            "name",
        ) => task_use_names(file, tag.name, offset, replace),
        ("Parameter", "srcTask" | "dstTask") => {
            let mut out = vec![
                item(CONTROL_TASK, K::Task).detail("the control task the refinement synthesizes"),
            ];
            for robot in file.types_at(offset) {
                for (task, what) in super::hover::tasks_of(robot) {
                    out.push(item(task, K::Task).detail(format!("{what} of {}", robot.name)));
                }
            }
            dedup_labels(out)
        }
        ("Transition", "srcId" | "dstId") => {
            let Some((_, service)) = file.service_at(offset) else {
                return Vec::new();
            };
            let mut actions: Vec<_> = service.actions.iter().collect();
            // `srcId` is the enclosing action's: offered first.
            if attr.name == "srcId"
                && let Some(i) = actions.iter().position(|a| a.span.contains(offset))
            {
                let own = actions.remove(i);
                actions.insert(0, own);
            }
            actions
                .into_iter()
                .filter_map(|a| {
                    let id = a.id?;
                    let name = a.name.as_ref().map_or("", |n| n.name.as_str());
                    Some(item(&id.value.to_string(), K::Action).detail(format!("action {name}")))
                })
                .collect()
        }
        ("Action", "initial" | "final") => {
            ["Yes", "No"].iter().map(|w| item(w, K::Choice)).collect()
        }
        ("Parameter", "dataCharacteristic") => DataCharacteristic::ALL
            .iter()
            .map(|(w, _)| item(w, K::Choice))
            .collect(),
        ("LeaderSelectionInfo", "algorithm") => LeaderAlgorithm::ALL
            .iter()
            .map(|(w, _)| item(w, K::Choice))
            .collect(),
        _ => Vec::new(),
    }
}

/// The built-in services the team calls in the tag's plan (all plans when
/// none is written), else those the target robot types provide.
fn services(file: &StrategyFile<'_>, tag: &RawTag<'_>, replace: Span) -> Vec<CompletionItem> {
    let plan = tag.value("plan_name");
    let signature = |name: &str| {
        file.catalog
            .types()
            .find_map(|(_, r)| r.service(name))
            .map(|s| (s.signature(), s.doc.clone()))
    };
    let mut out: Vec<CompletionItem> = Vec::new();
    for (analysis, id, team) in file.teams() {
        for call in team_calls(analysis, id) {
            let plan_name = &team.plans[call.plan.index()].name;
            if plan.is_some_and(|p| p != plan_name.as_str()) {
                continue;
            }
            let caller = team.service_path(call.service);
            if let Some(known) = out.iter_mut().find(|c| c.label == call.name.as_str()) {
                let doc = known.documentation.get_or_insert_with(String::new);
                if !doc.contains(&caller) {
                    doc.push_str(&format!(", `{caller}`"));
                }
                continue;
            }
            let (detail, doc) = signature(&call.name).unwrap_or_default();
            let mut item =
                CompletionItem::new(call.name.as_str(), CompletionKind::BuiltinService, replace)
                    .detail(detail);
            item.documentation = Some(format!("{doc}\n\ncalled by `{caller}`"));
            out.push(item);
        }
    }
    if !out.is_empty() {
        return out;
    }
    let mut out = Vec::new();
    for robot in file.types_for(&[]) {
        for service in &robot.services {
            out.push(
                CompletionItem::new(
                    service.name.as_str(),
                    CompletionKind::BuiltinService,
                    replace,
                )
                .detail(service.signature())
                .documentation(service.doc.clone()),
            );
        }
    }
    dedup_labels(out)
}

/// Sensor, actuator and algorithm names: those this file already uses for
/// the same element, then the capabilities of the robot types concerned.
fn task_use_names(
    file: &StrategyFile<'_>,
    element: &str,
    offset: usize,
    replace: Span,
) -> Vec<CompletionItem> {
    let mut out = Vec::new();
    if let Some(strategy) = file.strategy {
        let uses = strategy
            .values
            .iter()
            .flat_map(|v| v.tasks.iter())
            .chain(
                strategy
                    .services
                    .iter()
                    .flat_map(|s| s.actions.iter())
                    .flat_map(|a| a.tasks.iter()),
            )
            .filter(|t| t.kind.tag() == element)
            .filter_map(|t| t.name.as_ref());
        let rules = strategy.battery_rules.iter();
        let levels = match element {
            "Sensor" => rules.flat_map(|r| r.sensors.iter()).collect::<Vec<_>>(),
            "Actuator" => rules.flat_map(|r| r.actuators.iter()).collect(),
            _ => Vec::new(),
        };
        let named = uses.chain(levels.into_iter().filter_map(|l| l.name.as_ref()));
        for name in named.filter(|n| !n.span.touches(offset)) {
            out.push(
                CompletionItem::new(name.name.as_str(), CompletionKind::Task, replace)
                    .detail("used in this file"),
            );
        }
    }
    for robot in file.types_at(offset) {
        for capability in &robot.capabilities {
            out.push(
                CompletionItem::new(capability.as_str(), CompletionKind::Task, replace)
                    .detail(format!("capability of {}", robot.name)),
            );
        }
    }
    dedup_labels(out)
}

/// The first item of each label.
fn dedup_labels(items: Vec<CompletionItem>) -> Vec<CompletionItem> {
    let mut out: Vec<CompletionItem> = Vec::new();
    for item in items {
        if !out.iter().any(|c| c.label == item.label) {
            out.push(item);
        }
    }
    out
}
