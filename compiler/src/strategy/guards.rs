//! The guards of one action's transitions, checked as an expert reads them
//! when they compare one variable with numbers (`distance > 20`,
//! `distance <= 20`):
//!
//! - a guard that can never hold (W084);
//! - two guards that can hold at once: the machine is not deterministic (W085);
//! - a value for which no guard holds: the action waits there for ever (W083),
//!   named (`distance == 20`).
//!
//! Such guards are exact on a few test points: the numbers the guards name,
//! a point between each two neighbours, and one beyond each end. Between two
//! neighbouring numbers every comparison keeps its truth, so a finding on a
//! test point holds for the whole stretch it stands for, and no finding is
//! missed. Guards reading several variables, or anything but numbers, are
//! left alone (nothing is claimed about them). A transition without a
//! condition always holds.

use super::model::Action;
use crate::diag::{Code, Sink};
use crate::syntax::ast::{CmpOp, Expr, ExprKind};

/// A guard over one variable, as a predicate on its value.
enum Guard {
    Always,
    Compare(CmpOp, f64, bool),
    Not(Box<Guard>),
    And(Box<Guard>, Box<Guard>),
    Or(Box<Guard>, Box<Guard>),
}

impl Guard {
    fn holds(&self, x: f64) -> bool {
        match self {
            Guard::Always => true,
            // `flipped`: the number is on the left (`20 < x`).
            Guard::Compare(op, c, flipped) => {
                let (a, b) = if *flipped { (*c, x) } else { (x, *c) };
                match op {
                    CmpOp::Eq => a == b,
                    CmpOp::Ne => a != b,
                    CmpOp::Lt => a < b,
                    CmpOp::Le => a <= b,
                    CmpOp::Gt => a > b,
                    CmpOp::Ge => a >= b,
                }
            }
            Guard::Not(g) => !g.holds(x),
            Guard::And(a, b) => a.holds(x) && b.holds(x),
            Guard::Or(a, b) => a.holds(x) || b.holds(x),
        }
    }
}

/// Reads a condition as a guard over one variable: its name, the guard and
/// the numbers it names. `None` when it is anything else.
fn read(expr: &Expr, variable: &mut Option<String>, numbers: &mut Vec<f64>) -> Option<Guard> {
    let number = |e: &Expr| match &e.kind {
        ExprKind::Number(n) => n.parse::<f64>().ok().filter(|v| v.is_finite()),
        _ => None,
    };
    let name = |e: &Expr, variable: &mut Option<String>| match &e.kind {
        ExprKind::Attr(a) => {
            let dotted = a.dotted();
            match variable {
                Some(v) if *v != dotted => false,
                _ => {
                    *variable = Some(dotted);
                    true
                }
            }
        }
        _ => false,
    };
    Some(match &expr.kind {
        ExprKind::Compare(a, op, b) => {
            let (c, flipped) = match (number(a), number(b)) {
                (None, Some(c)) if name(a, variable) => (c, false),
                (Some(c), None) if name(b, variable) => (c, true),
                _ => return None,
            };
            numbers.push(c);
            Guard::Compare(*op, c, flipped)
        }
        ExprKind::Not(a) => Guard::Not(Box::new(read(a, variable, numbers)?)),
        ExprKind::And(a, b) => Guard::And(
            Box::new(read(a, variable, numbers)?),
            Box::new(read(b, variable, numbers)?),
        ),
        ExprKind::Or(a, b) => Guard::Or(
            Box::new(read(a, variable, numbers)?),
            Box::new(read(b, variable, numbers)?),
        ),
        _ => return None,
    })
}

/// A test point and the stretch of values it stands for, in words.
struct Point {
    value: f64,
    stretch: String,
}

fn points(numbers: &mut Vec<f64>, variable: &str) -> Vec<Point> {
    numbers.sort_by(f64::total_cmp);
    numbers.dedup();
    let mut points = Vec::new();
    let (Some(&first), Some(&last)) = (numbers.first(), numbers.last()) else {
        return points;
    };
    points.push(Point {
        value: first - 1.0,
        stretch: format!("`{variable}` < {first}"),
    });
    for (i, &c) in numbers.iter().enumerate() {
        points.push(Point {
            value: c,
            stretch: format!("`{variable}` == {c}"),
        });
        if let Some(&next) = numbers.get(i + 1) {
            points.push(Point {
                value: c + (next - c) / 2.0,
                stretch: format!("{c} < `{variable}` < {next}"),
            });
        }
    }
    points.push(Point {
        value: last + 1.0,
        stretch: format!("`{variable}` > {last}"),
    });
    points
}

/// Checks the guards of `action`'s transitions, adding to `diagnostics`.
pub(super) fn check_guards(action: &Action, sink: &mut Sink) {
    if action.transitions.is_empty() {
        return;
    }
    let mut variable = None;
    let mut numbers = Vec::new();
    let mut guards = Vec::new();
    for t in &action.transitions {
        let guard = match &t.condition {
            None => Guard::Always,
            Some(c) => match c
                .expr
                .as_ref()
                .and_then(|e| read(e, &mut variable, &mut numbers))
            {
                Some(g) => g,
                None => return, // not one variable against numbers: nothing to claim
            },
        };
        let span = t.condition.as_ref().map_or(t.span, |c| c.span);
        guards.push((guard, span));
    }
    let variable = variable.unwrap_or_default();
    let points = points(&mut numbers, &variable);
    let what = action.describe();
    if points.is_empty() {
        // Only transitions without conditions.
        if guards.len() > 1 {
            let message = format!(
                "{what} has {} transitions without a condition: which one it takes is not determined",
                guards.len()
            );
            sink.report(Code::OverlappingGuards, guards[1].1, message);
        }
        return;
    }
    for (guard, span) in &guards {
        if !points.iter().any(|p| guard.holds(p.value)) {
            let message = format!("this condition never holds, for any value of `{variable}`");
            sink.report(Code::GuardNeverHolds, *span, message);
        }
    }
    for (i, (a, span_a)) in guards.iter().enumerate() {
        for (b, span_b) in &guards[i + 1..] {
            if let Some(p) = points.iter().find(|p| a.holds(p.value) && b.holds(p.value)) {
                let message = format!(
                    "this condition and an earlier one of {what} both hold when {}: which transition is taken is not determined",
                    p.stretch
                );
                sink.report(Code::OverlappingGuards, *span_b, message)
                    .relate(*span_a, "the earlier condition");
            }
        }
    }
    let uncovered: Vec<&str> = points
        .iter()
        .filter(|p| !guards.iter().any(|(g, _)| g.holds(p.value)))
        .map(|p| p.stretch.as_str())
        .collect();
    if !uncovered.is_empty() {
        let message = format!(
            "no transition of {what} is taken when {}: the action waits there for ever",
            uncovered.join(", or ")
        );
        let span = action.name.as_ref().map_or(action.tag, |n| n.span);
        sink.report(Code::UncoveredGuards, span, message);
    }
}
