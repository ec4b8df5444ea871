//! The world's choices `semo verify` explores, derived from the refined
//! programs alone: for each sensor value a robot compares, one value of
//! each class its comparisons tell apart (below, at and above each number;
//! each word and one that is none of them); for each operator command a
//! robot reads, each value it is compared with and one that is none.

use crate::refine::value::{self, Value};
use crate::refine::{ControlMachine, Expr, Operand, RobotProgram, SlotId, SlotSource, StateKind};
use crate::sema::Compared;
use crate::syntax::ast::CmpOp;

/// A sensor value of one robot the world sets.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorInput {
    /// Index of the robot's program.
    pub robot: usize,
    pub robot_name: String,
    /// The catalog value (`LIGHTNESS`), as a scenario names it.
    pub port: String,
    /// One value per class, as scenario text.
    pub values: Vec<String>,
}

/// An operator command the robots of a team read.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandInput {
    pub to: String,
    /// As a scenario names it: `RC_CMD` (it arrives as `USER.RC_CMD`).
    pub value: String,
    pub values: Vec<String>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Inputs {
    pub sensors: Vec<SensorInput>,
    pub commands: Vec<CommandInput>,
    /// The pairs of robots (indices, the lower first) that may exchange a
    /// message: one sends or publishes to the other's team or name, or
    /// they share a team whose robots send heartbeats. Only their links
    /// are lost or delayed (`--network`).
    pub links: Vec<(usize, usize)>,
}

/// A comparison of a slot with a constant: (operator with the slot on the
/// left, the constant, how it compares).
type Test = (CmpOp, Value, Compared);

impl Inputs {
    /// The world's choices for `programs` (what `semo verify` explores).
    pub fn derive(programs: &[RobotProgram]) -> Inputs {
        derive(programs)
    }
}

pub fn derive(programs: &[RobotProgram]) -> Inputs {
    let mut inputs = Inputs::default();
    for (r, program) in programs.iter().enumerate() {
        let m = &program.control;
        let tests = tests_by_slot(m);
        // This robot's inputs start here (a value two slots read is one).
        let first = inputs.sensors.len();
        for (i, slot) in m.slots.iter().enumerate() {
            let SlotSource::Sensor { port, .. } = &slot.source else {
                continue;
            };
            if tests[i].is_empty()
                || port == crate::refine::BATTERY_VALUE
                || inputs.sensors[first..].iter().any(|s| &s.port == port)
            {
                continue;
            }
            let values = classes(&tests[i], |text| slot.kind.parse(text));
            if values.is_empty() {
                // No value reads as the slot's type: nothing to choose.
                continue;
            }
            inputs.sensors.push(SensorInput {
                robot: r,
                robot_name: program.robot.clone(),
                port: port.clone(),
                values,
            });
        }
        for incoming in m.incoming.iter().filter(|i| i.from_team == "USER") {
            let Some(name) = incoming.key.strip_prefix("USER.") else {
                continue;
            };
            let values = classes(&tests[incoming.slot.index()], |t| Some(Value::text(t)));
            match inputs
                .commands
                .iter_mut()
                .find(|c| c.to == program.team && c.value == name)
            {
                Some(known) => {
                    for v in values {
                        if !known.values.contains(&v) {
                            known.values.push(v);
                        }
                    }
                }
                None => inputs.commands.push(CommandInput {
                    to: program.team.clone(),
                    value: name.to_string(),
                    values,
                }),
            }
        }
    }
    inputs.links = links(programs);
    inputs
}

/// [`Inputs::links`].
fn links(programs: &[RobotProgram]) -> Vec<(usize, usize)> {
    let tells = |a: &RobotProgram, b: &RobotProgram| {
        a.control
            .outgoing
            .iter()
            .any(|o| o.to_team == b.team || o.to_team == b.robot)
            || (a.team == b.team && (a.control.heartbeat || b.control.heartbeat))
    };
    let mut links = Vec::new();
    for (a, pa) in programs.iter().enumerate() {
        for (b, pb) in programs.iter().enumerate().skip(a + 1) {
            if tells(pa, pb) || tells(pb, pa) {
                links.push((a, b));
            }
        }
    }
    links
}

/// Per slot of `m`: the constants its conditions compare it with.
fn tests_by_slot(m: &ControlMachine) -> Vec<Vec<Test>> {
    let mut tests = vec![Vec::new(); m.slots.len()];
    let mut add = |e: &Expr| collect(e, &mut tests);
    for service in &m.services {
        for state in &service.states {
            match &state.kind {
                StateKind::Branch { condition, .. } => add(condition),
                StateKind::LoopHead {
                    condition: Some(c), ..
                }
                | StateKind::Repeat {
                    condition: Some(c), ..
                } => add(c),
                _ => {}
            }
        }
    }
    for machine in &m.actions {
        for action in &machine.actions {
            for (condition, _) in &action.transitions {
                if let Some(c) = condition {
                    add(c);
                }
            }
        }
    }
    tests
}

fn collect(e: &Expr, tests: &mut [Vec<Test>]) {
    match e {
        Expr::Or(a, b) | Expr::And(a, b) => {
            collect(a, tests);
            collect(b, tests);
        }
        Expr::Not(a) => collect(a, tests),
        Expr::Compare(Operand::Slot(s), op, Operand::Literal(v), how) => {
            push(tests, *s, (*op, v.clone(), *how))
        }
        Expr::Compare(Operand::Literal(v), op, Operand::Slot(s), how) => {
            push(tests, *s, (flip(*op), v.clone(), *how))
        }
        Expr::Truthy(Operand::Slot(s)) => {
            push(tests, *s, (CmpOp::Eq, Value::Bool(true), Compared::Words));
            push(tests, *s, (CmpOp::Eq, Value::Int(0), Compared::Numbers));
        }
        _ => {}
    }
}

fn push(tests: &mut [Vec<Test>], slot: SlotId, test: Test) {
    if let Some(list) = tests.get_mut(slot.index()) {
        list.push(test);
    }
}

/// `c op x` written as `x op' c`.
fn flip(op: CmpOp) -> CmpOp {
    match op {
        CmpOp::Lt => CmpOp::Gt,
        CmpOp::Le => CmpOp::Ge,
        CmpOp::Gt => CmpOp::Lt,
        CmpOp::Ge => CmpOp::Le,
        same => same,
    }
}

/// One value (scenario text) for each combination of outcomes of `tests`
/// that some candidate reaches, in the order found: each constant, the
/// numbers just beside each, and a word none of them is.
fn classes(tests: &[Test], parse: impl Fn(&str) -> Option<Value>) -> Vec<String> {
    let mut candidates: Vec<String> = Vec::new();
    for (_, constant, _) in tests {
        let text = constant.as_text();
        candidates.push(text.clone());
        match constant {
            Value::Int(i) => {
                candidates.push((i - 1).to_string());
                candidates.push((i + 1).to_string());
            }
            Value::Real(r) => {
                candidates.push(value::format_real(r - 0.5));
                candidates.push(value::format_real(r + 0.5));
            }
            _ => {}
        }
    }
    let mut other = String::from("OTHER");
    while candidates.contains(&other) {
        other.push('_');
    }
    candidates.push(other);
    let mut seen: Vec<Vec<bool>> = Vec::new();
    let mut values = Vec::new();
    for text in candidates {
        let Some(v) = parse(&text) else {
            continue;
        };
        let outcome: Vec<bool> = tests
            .iter()
            .map(|(op, c, how)| value::holds(Some(&v), *op, Some(c), *how))
            .collect();
        if !seen.contains(&outcome) {
            seen.push(outcome);
            values.push(text);
        }
    }
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_get_one_value_per_class_and_words_one_that_is_none() {
        let below_200 = (CmpOp::Lt, Value::Int(200), Compared::Numbers);
        let above_500 = (CmpOp::Gt, Value::Int(500), Compared::Numbers);
        let number = |t: &str| value::parse_int(t).map(Value::Int);
        assert_eq!(
            classes(&[below_200, above_500], number),
            ["200", "199", "501"]
        );
        let word = (CmpOp::Eq, Value::text("5,5"), Compared::Words);
        let text = |t: &str| Some(Value::text(t));
        assert_eq!(classes(&[word], text), ["5,5", "OTHER"]);
    }
}
