//! A service's actions as a state machine (a petgraph graph: one node per
//! action, one edge per transition), checked as a graph:
//!
//! - every `actionId` is unique in its service (E085);
//! - exactly one action is `initial="Yes"` (E087);
//! - a transition leaves its enclosing action (`srcId`) and goes to an action
//!   that exists (`dstId`) (E086);
//! - every action can be reached from the initial action (W081);
//! - a final action can be reached from it (W082): otherwise the service never
//!   ends, and the statement calling it never returns (unless a timeout
//!   bounds the call).
//!
//! - a final action has no outgoing transitions (E096);
//! - each action's transition conditions, where they compare one variable
//!   with numbers, cover every value, each can hold, and no two hold at once
//!   (`guards.rs`: W083–W085).
//!
//! A transition with a wrong `srcId` still counts as leaving its enclosing
//! action (where it is written), so that one mistake is reported once.
//! Actions without a usable `actionId` of their own (missing, malformed or
//! already taken: reported) are not reported as unreachable. An entry cut short by malformed XML is checked for its ids and
//! transitions only.

use super::model::*;
use crate::diag::{Code, Sink};
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::Dfs;
use std::collections::HashMap;

/// Checks the action machine of `service`, adding to `diagnostics`.
pub(super) fn check_machine(service: &ServiceEntry, sink: &mut Sink) {
    let actions = &service.actions;
    let name = service
        .name
        .as_ref()
        .map_or("this service".to_string(), |n| format!("`{}`", n.name));

    // Ids: the first action with an id owns it.
    let mut by_id: HashMap<u64, usize> = HashMap::new();
    for (i, action) in actions.iter().enumerate() {
        let Some(id) = action.id else { continue };
        match by_id.get(&id.value) {
            Some(&first) => {
                let message = format!(
                    "actionId {} is already the id of {} in {name}",
                    id.value,
                    actions[first].describe()
                );
                let first_span = actions[first].id.map_or(actions[first].tag, |f| f.span);
                sink.report(Code::StrategyDuplicate, id.span, message)
                    .relate(first_span, "first used here");
            }
            None => {
                by_id.insert(id.value, i);
            }
        }
    }

    let mut graph: DiGraph<usize, ()> = DiGraph::with_capacity(actions.len(), actions.len());
    let nodes: Vec<NodeIndex> = (0..actions.len()).map(|i| graph.add_node(i)).collect();
    let mut ids: Vec<u64> = by_id.keys().copied().collect();
    ids.sort_unstable();
    for (i, action) in actions.iter().enumerate() {
        for t in &action.transitions {
            if let (Some(src), Some(own)) = (t.src, action.id) {
                if src.value != own.value {
                    let message = format!(
                        "this transition is written inside {}, so its srcId must be {}, not {}",
                        action.describe(),
                        own.value,
                        src.value
                    );
                    sink.report(Code::StrategyBadTransition, src.span, message);
                }
            }
            let Some(dst) = t.dst else { continue };
            match by_id.get(&dst.value) {
                Some(&j) => {
                    graph.add_edge(nodes[i], nodes[j], ());
                }
                // Cut short: the action it names may be in the part not read.
                None if !service.complete => {}
                None => {
                    let known = if ids.is_empty() {
                        "none has a usable actionId".to_string()
                    } else {
                        let shown: Vec<String> =
                            ids.iter().take(12).map(|id| id.to_string()).collect();
                        format!(
                            "the actionIds are {}{}",
                            shown.join(", "),
                            if ids.len() > 12 { ", …" } else { "" }
                        )
                    };
                    let message =
                        format!("no action of {name} has actionId {} ({known})", dst.value);
                    sink.report(Code::StrategyBadTransition, dst.span, message);
                }
            }
        }
    }

    for action in actions {
        if action.is_final.is_yes()
            && let Some(first) = action.transitions.first()
        {
            let message = format!(
                "{} is final: {name} ends when it is done, so its transitions are never taken (remove them, or its `final` mark)",
                action.describe()
            );
            sink.report(Code::FinalWithTransitions, first.span, message);
        }
        super::guards::check_guards(action, sink);
    }

    if !service.complete {
        return;
    }
    if actions.iter().any(|a| a.initial.is_malformed()) {
        return; // which action starts is not known (already reported)
    }
    let initial: Vec<usize> = (0..actions.len())
        .filter(|&i| actions[i].initial.is_yes())
        .collect();
    let Some(&start) = initial.first() else {
        let message = if actions.is_empty() {
            format!(
                "{name} has no actions: add an `<Action ... initial=\"Yes\">` to `<ActionInfo>`"
            )
        } else {
            format!("no action of {name} is initial: mark the one it starts with `initial=\"Yes\"`")
        };
        sink.report(Code::StrategyInitialAction, service.tag, message);
        return;
    };
    for &again in &initial[1..] {
        let message = format!(
            "{} is initial too, but {name} starts with one action: {} is already initial",
            actions[again].describe(),
            actions[start].describe()
        );
        let span = actions[again].initial.span().unwrap_or(actions[again].tag);
        let first = actions[start].initial.span().unwrap_or(actions[start].tag);
        sink.report(Code::StrategyInitialAction, span, message)
            .relate(first, "the first initial action");
    }

    // Reachable from the initial action(s).
    let mut reached = vec![false; actions.len()];
    let mut dfs = Dfs::new(&graph, nodes[start]);
    for &s in &initial {
        dfs.move_to(nodes[s]);
        while let Some(n) = dfs.next(&graph) {
            reached[graph[n]] = true;
        }
    }
    for (i, action) in actions.iter().enumerate() {
        // Without an id of its own (missing, malformed or taken), no
        // transition could name it: that is already reported.
        let own_id = action.id.is_some_and(|id| by_id.get(&id.value) == Some(&i));
        if reached[i] || !own_id {
            continue;
        }
        let message = format!(
            "{} cannot be reached from the initial action {}: no transition leads to it",
            action.describe(),
            actions[start].describe()
        );
        let span = action.name.as_ref().map_or(action.tag, |n| n.span);
        sink.report(Code::UnreachableAction, span, message);
    }
    let ends = actions
        .iter()
        .enumerate()
        .any(|(i, a)| reached[i] && (a.is_final.is_yes() || a.is_final.is_malformed()));
    if !ends {
        let message = if actions.iter().any(|a| a.is_final.is_yes()) {
            format!(
                "no final action can be reached from {}: {name} never ends",
                actions[start].describe()
            )
        } else {
            format!(
                "no action of {name} is final, so it never ends: mark the action that ends it `final=\"Yes\"`"
            )
        };
        let span = actions[start]
            .name
            .as_ref()
            .map_or(actions[start].tag, |n| n.span);
        sink.report(Code::NoFinalAction, span, message);
    }
}
