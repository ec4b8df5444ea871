//! Inlay hints: after a `group`/`leader` condition and after `others`, the
//! robots that the arm will select; after the service of a `set`, how that
//! service runs (its `repeat`, or once).

use super::docs;
use crate::catalog::Catalog;
pub use crate::ide::{InlayHint, InlayKind};
use crate::sema::{CheckedMission, Runners, ScopeKind};
use crate::span::Span;
use crate::syntax::ast::{self, ArmKind, SetTarget};

/// The hints whose position lies in `range`.
pub fn inlay_hints(
    analysis: &CheckedMission,
    _catalog: &Catalog,
    text: &str,
    range: Span,
) -> Vec<InlayHint> {
    let mut hints = Vec::new();
    group_hints(analysis, text, range, &mut hints);
    set_hints(analysis, text, range, &mut hints);
    hints.sort_by_key(|h| h.offset);
    hints
}

fn group_hints(analysis: &CheckedMission, text: &str, range: Span, hints: &mut Vec<InlayHint>) {
    let mission = &analysis.mission;
    // A hint sits just before its scope's body, so only scopes that start
    // (at most a line or so) after the range's start can have one inside it.
    let first = mission
        .scopes
        .partition_point(|s| s.span.start < range.start);
    for scope in &mission.scopes[first..] {
        let (at, what) = match scope.kind {
            ScopeKind::Arm { kind, condition } => (after_paren(text, condition.end), Some(kind)),
            ScopeKind::Others { keyword } => (keyword.end, None),
            _ => continue,
        };
        if at > range.end {
            break;
        }
        if at < range.start {
            continue;
        }
        let names = robot_names(analysis, &scope.runs);
        let label = match (what, names.is_empty()) {
            (_, true) => "no robot".to_string(),
            (Some(ArmKind::Leader), false) => format!("one of {names}"),
            (_, false) => names,
        };
        let tooltip = match what {
            Some(ArmKind::Leader) => {
                "The robots among which a leader is elected to run this block."
            }
            Some(ArmKind::Group) => "The robots that run this block.",
            None => "The robots of no group above, which run this block.",
        };
        hints.push(InlayHint {
            offset: at,
            label: format!(": {label}"),
            kind: InlayKind::Robots,
            tooltip: Some(tooltip.to_string()),
        });
    }
}

/// The robots of runners: `a, b`, or `A: a, b; B: c` when several teams run
/// them (a function); empty when there are none.
fn robot_names(analysis: &CheckedMission, runs: &[Runners]) -> String {
    let mission = &analysis.mission;
    let teams: Vec<_> = runs.iter().filter(|r| r.team.is_some()).collect();
    let mut parts: Vec<String> = Vec::new();
    for r in &teams {
        let Some(team) = r.team else { continue };
        let t = mission.team(team);
        let robots: Vec<&str> = r
            .robots
            .iter()
            .filter_map(|&i| t.robots.get(i.index()))
            .map(|robot| robot.name.as_str())
            .collect();
        let part = match (teams.len(), robots.is_empty()) {
            (_, true) => continue,
            (1, false) => robots.join(", "),
            (_, false) => format!("{}: {}", t.name, robots.join(", ")),
        };
        if !parts.contains(&part) {
            parts.push(part);
        }
    }
    parts.join("; ")
}

/// The offset after the `)` that closes a group condition ending at `end`.
fn after_paren(text: &str, end: usize) -> usize {
    let rest = text.get(end..).unwrap_or("");
    let skipped = rest.len() - rest.trim_start().len();
    match rest[skipped..].starts_with(')') {
        true => end + skipped + 1,
        false => end,
    }
}

fn set_hints(analysis: &CheckedMission, text: &str, range: Span, hints: &mut Vec<InlayHint>) {
    let mission = &analysis.mission;
    let items = &analysis.syntax.items;
    let first = items.partition_point(|i| i.span().end < range.start);
    for item in &items[first..] {
        if item.span().start > range.end {
            break;
        }
        let ast::Item::Mode(m) = item else { continue };
        let Some(team) = mission.team_by_name(&m.team.name) else {
            continue;
        };
        let t = mission.team(team);
        for set in &m.sets {
            let SetTarget::Service(name) = &set.service else {
                continue;
            };
            if name.span.end < range.start || name.span.end > range.end {
                continue;
            }
            let Some(plan) = t.plan_by_name(&set.plan.name) else {
                continue;
            };
            let Some(service) = t.service_in_plan(plan, &name.name) else {
                continue;
            };
            let syntax = analysis.service_syntax(&t.services[service.index()]);
            hints.push(InlayHint {
                offset: name.span.end,
                label: format!(": {}", docs::schedule(text, syntax)),
                kind: InlayKind::Schedule,
                tooltip: Some(docs::composite_service(analysis, text, team, service)),
            });
        }
    }
}
