//! Between strategy entries and the missions they refine: from a `<Service>`
//! to the mission calls it refines (and back, from a call to its entry), from
//! a `<Value>` to the mission lines reading it, and from team, plan and robot
//! type names to where they are declared.

use super::StrategyFile;
use crate::diag::FileId;
use crate::ide::NavigationTarget;
use crate::sema::Symbol;
use crate::span::Span;
use crate::strategy::cross::{ServiceEntryRef, StrategyLinks};
use crate::strategy::model::Strategy;

/// Where the name at `offset` leads: a `Service`'s name or plan to the
/// mission calls it refines, a `Value`'s name to the mission lines reading
/// the value, the strategy's team, a `TargetRobot` or a `plan_name` to its
/// declaration.
pub fn definition(
    file: &StrategyFile<'_>,
    links: &StrategyLinks,
    offset: usize,
) -> Vec<NavigationTarget> {
    let Some(strategy) = file.strategy else {
        return Vec::new();
    };
    let touches =
        |n: &Option<crate::strategy::Named>| n.as_ref().is_some_and(|n| n.span.touches(offset));
    if touches(&strategy.team) {
        return file
            .teams()
            .into_iter()
            .map(|(a, _, team)| NavigationTarget {
                file: a.mission.file,
                span: team.name_span,
            })
            .collect();
    }
    for (index, service) in strategy.services.iter().enumerate() {
        if touches(&service.name) {
            return calls_of(strategy, links, index);
        }
        if touches(&service.plan) {
            let plan = service
                .plan
                .as_ref()
                .map(|p| p.name.as_str())
                .unwrap_or_default();
            return plans(file, plan);
        }
    }
    if let Some(leader) = strategy
        .grouping
        .as_ref()
        .and_then(|g| g.leader_selection.as_ref())
        && let Some(plan) = leader.plan.as_ref().filter(|p| p.span.touches(offset))
    {
        return plans(file, &plan.name);
    }
    for value in &strategy.values {
        if let Some(name) = value.name.as_ref().filter(|n| n.span.touches(offset)) {
            return value_uses(file, &name.name);
        }
    }
    let targets = strategy
        .values
        .iter()
        .flat_map(|v| v.targets.iter())
        .chain(strategy.services.iter().flat_map(|s| s.targets.iter()));
    for target in targets {
        if let Some(name) = target.name.as_ref().filter(|n| n.span.touches(offset)) {
            return file
                .catalog
                .robot(&name.name)
                .map(|r| NavigationTarget {
                    file: r.origin.file,
                    span: r.origin.span,
                })
                .into_iter()
                .collect();
        }
    }
    Vec::new()
}

/// The mission calls that entry `index` refines.
fn calls_of(strategy: &Strategy, links: &StrategyLinks, index: usize) -> Vec<NavigationTarget> {
    let entry = ServiceEntryRef {
        file: strategy.file,
        index,
    };
    let mut out: Vec<NavigationTarget> = Vec::new();
    for link in links.of_entry(entry) {
        let target = NavigationTarget {
            file: link.mission,
            span: link.call,
        };
        // A call inside a function is linked once per service running it.
        if !out.contains(&target) {
            out.push(target);
        }
    }
    out
}

fn plans(file: &StrategyFile<'_>, plan: &str) -> Vec<NavigationTarget> {
    file.teams()
        .into_iter()
        .filter_map(|(a, _, team)| {
            let index = team.plan_by_name(plan)?;
            Some(NavigationTarget {
                file: a.mission.file,
                span: team.plans[index.index()].span,
            })
        })
        .collect()
}

/// Where the team's missions read the value `name`.
fn value_uses(file: &StrategyFile<'_>, name: &str) -> Vec<NavigationTarget> {
    let mut out = Vec::new();
    for (analysis, id, _) in file.teams() {
        for o in &analysis.mission.occurrences {
            if let Symbol::Value {
                owner: Some(owner),
                name: used,
            } = &o.symbol
                && *owner == id
                && used == name
            {
                out.push(NavigationTarget {
                    file: analysis.mission.file,
                    span: o.span,
                });
            }
        }
    }
    out
}

/// References of the entry whose name is at `offset`: the mission calls a
/// `Service` refines, the lines reading a `Value`; the entry's own name first
/// when `include_declaration`.
pub fn references(
    file: &StrategyFile<'_>,
    links: &StrategyLinks,
    offset: usize,
    include_declaration: bool,
) -> Vec<NavigationTarget> {
    let Some(strategy) = file.strategy else {
        return Vec::new();
    };
    let names = strategy
        .services
        .iter()
        .filter_map(|s| s.name.as_ref())
        .chain(strategy.values.iter().filter_map(|v| v.name.as_ref()));
    let Some(name) = names.into_iter().find(|n| n.span.touches(offset)) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    if include_declaration {
        out.push(NavigationTarget {
            file: strategy.file,
            span: name.span,
        });
    }
    out.extend(definition(file, links, offset));
    out
}

/// The strategy entries refining the mission call at `offset` of `mission`:
/// the ranges of their `name` in `strategy`'s file (for go-to-definition from
/// a mission). `links` are the strategy's own.
pub fn entries_of_call(
    strategy: &Strategy,
    links: &StrategyLinks,
    mission: FileId,
    offset: usize,
) -> Vec<Span> {
    let mut out: Vec<Span> = Vec::new();
    for link in links.at(mission, offset) {
        if link.entry.file != strategy.file {
            continue;
        }
        let Some(entry) = strategy.services.get(link.entry.index) else {
            continue;
        };
        let span = entry.name.as_ref().map_or(entry.tag, |n| n.span);
        if !out.contains(&span) {
            out.push(span);
        }
    }
    out
}
