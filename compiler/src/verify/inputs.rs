//! The world's choices `semo verify` explores, derived from the refined
//! programs alone: for each sensor value a robot compares, one value of
//! each class its comparisons tell apart (below, at and above each number;
//! each word and one that is none of them); for each operator command a
//! robot reads, each value it is compared with and one that is none; for
//! each service whose results a robot binds, what its calls give back, by
//! the same classes (a bool: true or false).

use crate::refine::value::{self, Value, ValueKind};
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

/// What one robot's calls of one service give back (`FOUND, WHERE =
/// search(red)`), which the world chooses as it chooses a sensor's class.
#[derive(Clone, Debug, PartialEq)]
pub struct ResultInput {
    /// Index of the robot's program.
    pub robot: usize,
    pub robot_name: String,
    pub service: String,
    /// One tuple per class, each value in the order of the service's
    /// results as scenario text (`None`: none): a bool result is `true` or
    /// `false`, a result the mission compares takes one value per class of
    /// its comparisons, one it only passes on is none. At most
    /// [`MAX_RESULT_CLASSES`] tuples.
    pub values: Vec<Vec<Option<String>>>,
}

/// The most classes of a service's results explored: beyond, the later
/// combinations are left out (several compared results multiply).
pub const MAX_RESULT_CLASSES: usize = 16;

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
    pub results: Vec<ResultInput>,
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
        inputs.results.extend(results_of(r, program, &tests));
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

/// The results robot `r`'s calls bind, per service it calls so, in the
/// order first called: the classes of each result over every call that
/// binds it, combined.
fn results_of(r: usize, program: &RobotProgram, tests: &[Vec<Test>]) -> Vec<ResultInput> {
    let m = &program.control;
    // Per service: per result position, its classes.
    let mut by_service: Vec<(String, Vec<Vec<Option<String>>>)> = Vec::new();
    for state in m.services.iter().flat_map(|s| &s.states) {
        let StateKind::Call {
            service, results, ..
        } = &state.kind
        else {
            continue;
        };
        if results.is_empty() {
            continue;
        }
        let entry = match by_service.iter().position(|(s, _)| s == service) {
            Some(i) => &mut by_service[i].1,
            None => {
                by_service.push((service.clone(), Vec::new()));
                &mut by_service.last_mut().expect("just pushed").1
            }
        };
        for (k, slot) in results.iter().enumerate() {
            let kind = &m.slots[slot.index()].kind;
            let mut values: Vec<Option<String>> = if *kind == ValueKind::Bool {
                vec![Some("true".into()), Some("false".into())]
            } else if tests[slot.index()].is_empty() {
                vec![None]
            } else {
                classes(&tests[slot.index()], |t| kind.parse(t))
                    .into_iter()
                    .map(Some)
                    .collect()
            };
            if values.is_empty() {
                values.push(None);
            }
            if entry.len() <= k {
                entry.resize(k + 1, Vec::new());
            }
            for v in values {
                if !entry[k].contains(&v) {
                    entry[k].push(v);
                }
            }
        }
    }
    by_service
        .into_iter()
        .map(|(service, positions)| {
            // Every combination, the first position turning slowest.
            let mut tuples: Vec<Vec<Option<String>>> = vec![Vec::new()];
            for choices in &positions {
                let choices = if choices.is_empty() {
                    &vec![None]
                } else {
                    choices
                };
                tuples = (tuples.iter())
                    .flat_map(|t| {
                        choices.iter().map(move |c| {
                            let mut t = t.clone();
                            t.push(c.clone());
                            t
                        })
                    })
                    .take(MAX_RESULT_CLASSES)
                    .collect();
            }
            ResultInput {
                robot: r,
                robot_name: program.robot.clone(),
                service,
                values: tuples,
            }
        })
        .collect()
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
