//! Checks of one strategy file on its own (no mission, no catalog): entries and
//! parameters given twice (E085), and the names that conditions read (E088).
//! The action machines are checked in [`super::machine`].
//!
//! The names a transition's condition may read are the parameters that the
//! service declares, in any of its actions. As in missions, a bare name on the
//! right of a comparison that is not one of them is a symbolic constant
//! (`cmd == Forward`), unless it is a near miss of a parameter's name, which
//! is reported with a did-you-mean. A battery requirement's condition reads
//! `Battery` only.

use super::model::*;
use crate::diag::{Code, Sink};
use crate::span::Span;
use crate::suggest::did_you_mean;
use crate::syntax::ast::{Expr, ExprKind};
use std::collections::HashMap;

/// Runs the per-file checks, adding to `diagnostics`.
pub(super) fn check_strategy(strategy: &Strategy, diagnostics: &mut Sink) {
    let mut checker = Checker { diagnostics };
    checker.duplicate_entries(strategy);
    for value in &strategy.values {
        checker.targets_once(&value.targets);
        let params = value.tasks.iter().flat_map(|t| t.parameters.iter());
        checker.parameters_once(params, "this value");
    }
    for service in &strategy.services {
        checker.targets_once(&service.targets);
        for action in &service.actions {
            checker.parameters_once(action.parameters(), "this action");
        }
        checker.service_conditions(service);
    }
    for rule in &strategy.battery_rules {
        if let Some(expr) = rule.condition.as_ref().and_then(|c| c.expr.as_ref()) {
            checker.battery_condition(expr);
        }
    }
}

/// Names already used in one scope, for "given twice".
#[derive(Default)]
struct Seen {
    first: HashMap<String, Span>,
}

impl Seen {
    /// `None` the first time `key` is seen; the first range afterwards.
    fn first(&mut self, key: String, span: Span) -> Option<Span> {
        match self.first.get(&key) {
            Some(first) => Some(*first),
            None => {
                self.first.insert(key, span);
                None
            }
        }
    }
}

struct Checker<'d> {
    diagnostics: &'d mut Sink,
}

impl Checker<'_> {
    /// A value, or a service of a plan, refined twice for the same robot type.
    fn duplicate_entries(&mut self, strategy: &Strategy) {
        let mut values = Seen::default();
        for v in &strategy.values {
            let Some(name) = &v.name else { continue };
            let mut here: Vec<&str> = Vec::new();
            for robot in v.targets.iter().filter_map(|t| t.name.as_ref()) {
                if here.contains(&robot.name.as_str()) {
                    continue;
                }
                here.push(&robot.name);
                let key = format!("{}\u{0}{}", name.name, robot.name);
                if let Some(first) = values.first(key, robot.span) {
                    let message = format!(
                        "the value `{}` of {} is already described in this file",
                        name.name, robot.name
                    );
                    self.diagnostics
                        .report(Code::StrategyDuplicate, robot.span, message)
                        .relate(first, "first described here");
                }
            }
        }
        let mut services = Seen::default();
        for s in &strategy.services {
            let (Some(plan), Some(name)) = (&s.plan, &s.name) else {
                continue;
            };
            let mut here: Vec<&str> = Vec::new();
            for robot in s.targets.iter().filter_map(|t| t.name.as_ref()) {
                // Twice in the same entry: see `targets_once`.
                if here.contains(&robot.name.as_str()) {
                    continue;
                }
                here.push(&robot.name);
                let key = format!("{}\u{0}{}\u{0}{}", plan.name, name.name, robot.name);
                if let Some(first) = services.first(key, robot.span) {
                    let message = format!(
                        "the service `{}` of plan {} is already refined for {} in this file",
                        name.name, plan.name, robot.name
                    );
                    self.diagnostics
                        .report(Code::StrategyDuplicate, robot.span, message)
                        .relate(first, "first refined here");
                }
            }
        }
    }

    fn targets_once(&mut self, targets: &[TargetRobot]) {
        let mut seen = Seen::default();
        for name in targets.iter().filter_map(|t| t.name.as_ref()) {
            if let Some(first) = seen.first(name.name.clone(), name.span) {
                let message = format!("`{}` is listed twice as a target robot here", name.name);
                self.diagnostics
                    .report(Code::StrategyDuplicate, name.span, message)
                    .relate(first, "first listed here");
            }
        }
    }

    fn parameters_once<'p>(&mut self, params: impl Iterator<Item = &'p Parameter>, scope: &str) {
        let mut seen = Seen::default();
        for name in params.filter_map(|p| p.name.as_ref()) {
            if let Some(first) = seen.first(name.name.clone(), name.span) {
                let message = format!("{scope} already has a parameter `{}`", name.name);
                self.diagnostics
                    .report(Code::StrategyDuplicate, name.span, message)
                    .relate(first, "first declared here");
            }
        }
    }

    /// E088 for names in transition conditions that are not parameters.
    fn service_conditions(&mut self, service: &ServiceEntry) {
        let mut params: Vec<&str> = Vec::new();
        for p in service.parameters().filter_map(|p| p.name.as_ref()) {
            if !params.contains(&p.name.as_str()) {
                params.push(&p.name);
            }
        }
        let service_name = service
            .name
            .as_ref()
            .map_or("this service".to_string(), |n| {
                format!("service `{}`", n.name)
            });
        let conditions = service
            .actions
            .iter()
            .flat_map(|a| a.transitions.iter())
            .filter_map(|t| t.condition.as_ref()?.expr.as_ref());
        for expr in conditions {
            for (name, span, rhs, dotted) in names_in(expr) {
                if params.contains(&name.as_str()) {
                    continue;
                }
                let guess = did_you_mean(&name, params.iter().copied());
                if rhs && !dotted && guess.is_none() {
                    continue; // a symbolic constant
                }
                let listed = if params.is_empty() {
                    "it declares none".to_string()
                } else {
                    let mut list = params
                        .iter()
                        .take(8)
                        .copied()
                        .collect::<Vec<_>>()
                        .join(", ");
                    if params.len() > 8 {
                        list.push_str(", …");
                    }
                    format!("its parameters are {list}")
                };
                let message = if dotted {
                    format!(
                        "`{name}` is not a parameter of {service_name}: a condition reads the service's parameters, which are plain names ({listed})"
                    )
                } else {
                    format!("`{name}` is not a parameter of {service_name} ({listed})")
                };
                self.diagnostics
                    .report(Code::StrategyUnknownParameter, span, message)
                    .suggest(guess);
            }
        }
    }

    /// E088 for names other than `Battery` in a battery requirement.
    fn battery_condition(&mut self, expr: &Expr) {
        for (name, span, rhs, dotted) in names_in(expr) {
            if name.eq_ignore_ascii_case("battery") {
                continue;
            }
            if rhs && !dotted && did_you_mean(&name, ["Battery"]).is_none() {
                continue; // a symbolic constant such as `LOW`
            }
            let message = format!(
                "a battery requirement's condition reads `Battery` (the charge left, in percent), not `{name}`"
            );
            self.diagnostics
                .report(Code::StrategyUnknownParameter, span, message)
                .suggest(Some("Battery".to_string()));
        }
    }
}

/// Every name an expression reads: (the dotted name, its range, whether it is
/// the right operand of a comparison, whether it is dotted). Walks with an
/// explicit stack, whatever the depth.
fn names_in(expr: &Expr) -> Vec<(String, Span, bool, bool)> {
    let mut out = Vec::new();
    let mut stack: Vec<(&Expr, bool)> = vec![(expr, false)];
    while let Some((e, rhs)) = stack.pop() {
        match &e.kind {
            ExprKind::Or(a, b) | ExprKind::And(a, b) => {
                stack.push((b, false));
                stack.push((a, false));
            }
            ExprKind::Not(a) => stack.push((a, false)),
            ExprKind::Compare(a, _, b) => {
                stack.push((b, true));
                stack.push((a, false));
            }
            ExprKind::Attr(attr) => {
                out.push((attr.dotted(), attr.span, rhs, attr.segments.len() > 1));
            }
            ExprKind::Str(_)
            | ExprKind::Number(_)
            | ExprKind::Period(_)
            | ExprKind::Bool(_)
            | ExprKind::Error => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::FileId;
    use crate::syntax::parse_expr;

    #[test]
    fn names_are_found_with_their_side() {
        let p = parse_expr(FileId(0), "a == b and not (c.d < 3 or e)", 0);
        let names: Vec<(String, bool, bool)> = names_in(&p.expr.unwrap())
            .into_iter()
            .map(|(n, _, rhs, dotted)| (n, rhs, dotted))
            .collect();
        assert_eq!(
            names,
            vec![
                ("a".to_string(), false, false),
                ("b".to_string(), true, false),
                ("c.d".to_string(), false, true),
                ("e".to_string(), false, false),
            ]
        );
    }
}
