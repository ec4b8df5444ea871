//! Expectations of a scenario, judged on a run's trace.

use super::engine::Run;
use super::scenario::{ExpectKind, Expectation};
use super::trace::TraceEvent;
use crate::fasthash::FastMap;

/// One expectation and whether the run met it, with the evidence.
#[derive(Clone, Debug)]
pub struct Verdict {
    pub expectation: Expectation,
    pub met: bool,
    /// What the run showed: when the mode was entered, the robot's last
    /// mode, the messages received, ...
    pub why: String,
}

/// The modes a robot entered, with their times.
pub fn modes(run: &Run, robot: usize) -> Vec<(i64, &str)> {
    run.trace
        .iter()
        .filter(|e| e.robot == robot && e.event == "mode")
        .filter_map(|e| Some((e.t, e.field("mode")?)))
        .collect()
}

/// [`modes`] of every robot, indexed by robot, in one pass over the trace
/// (asking [`modes`] robot by robot reads the trace once per robot: a
/// thousand robots' summary took ten times as long as their simulation).
pub fn modes_of_every_robot(run: &Run) -> Vec<Vec<(i64, &str)>> {
    let mut modes = vec![Vec::new(); run.robots.len()];
    for e in run.trace.iter().filter(|e| e.event == "mode") {
        if let (Some(of), Some(mode)) = (modes.get_mut(e.robot), e.field("mode")) {
            of.push((e.t, mode));
        }
    }
    modes
}

/// Every expectation judged on the run, in order: the one judgement of a
/// simulated run (`semo simulate`) and a recorded one (`semo replay`,
/// [`super::replay`]). The trace is read once for every robot's modes and
/// once for the messages received, whatever the number of expectations.
pub fn judge(run: &Run, expectations: &[Expectation]) -> Vec<Verdict> {
    let facts = Facts::of(run);
    expectations
        .iter()
        .map(|x| {
            let (met, why) = judge_one(run, &facts, &x.kind);
            Verdict {
                expectation: x.clone(),
                met,
                why,
            }
        })
        .collect()
}

/// What the expectations read, gathered in one pass each.
struct Facts<'r> {
    robot_of: FastMap<&'r str, usize>,
    /// Per robot, the modes it entered with their times.
    modes: Vec<Vec<(i64, &'r str)>>,
    /// Per (robot, key), its `receive` lines in order.
    received: FastMap<(usize, &'r str), Vec<&'r TraceEvent>>,
}

impl<'r> Facts<'r> {
    fn of(run: &'r Run) -> Self {
        let mut received: FastMap<(usize, &str), Vec<&TraceEvent>> = FastMap::default();
        for e in run.trace.iter().filter(|e| e.event == "receive") {
            if let Some(key) = e.field("key") {
                received.entry((e.robot, key)).or_default().push(e);
            }
        }
        Facts {
            robot_of: run
                .robots
                .iter()
                .enumerate()
                .map(|(i, (_, r))| (r.as_str(), i))
                .collect(),
            modes: modes_of_every_robot(run),
            received,
        }
    }
}

fn judge_one(run: &Run, facts: &Facts, kind: &ExpectKind) -> (bool, String) {
    let robot_index = |robot: &str| facts.robot_of.get(robot).copied();
    let modes = |r: usize| facts.modes[r].iter().copied();
    match kind {
        ExpectKind::Enters {
            robot,
            mode,
            before,
        } => {
            let Some(r) = robot_index(robot) else {
                return (false, format!("no robot {robot}"));
            };
            match modes(r).find(|(_, m)| m == mode) {
                Some((t, _)) if before.is_none_or(|b| t <= b) => {
                    (true, format!("entered at {t} ms"))
                }
                Some((t, _)) => (false, format!("entered only at {t} ms")),
                None => (false, "never entered".into()),
            }
        }
        ExpectKind::NeverEnters { robot, mode } => {
            let Some(r) = robot_index(robot) else {
                return (false, format!("no robot {robot}"));
            };
            match modes(r).find(|(_, m)| m == mode) {
                Some((t, _)) => (false, format!("entered at {t} ms")),
                None => (true, "never entered".into()),
            }
        }
        ExpectKind::Receives {
            robot,
            key,
            from,
            before,
        } => {
            let Some(r) = robot_index(robot) else {
                return (false, format!("no robot {robot}"));
            };
            let received = facts
                .received
                .get(&(r, key.as_str()))
                .into_iter()
                .flatten()
                .find(|e| {
                    from.as_deref()
                        .is_none_or(|f| e.field("from_robot") == Some(f))
                });
            match received {
                Some(e) if before.is_none_or(|b| e.t <= b) => {
                    (true, format!("received at {} ms: {}", e.t, e.value_json()))
                }
                Some(e) => (false, format!("received only at {} ms", e.t)),
                None => (false, "never received".into()),
            }
        }
        ExpectKind::AllEndIn { mode } => {
            let mut wrong = Vec::new();
            for ((_, robot), modes) in run.robots.iter().zip(&facts.modes) {
                let last = modes.last().map(|(_, m)| *m);
                if last != Some(mode.as_str()) {
                    wrong.push(format!("{robot} ends in {}", last.unwrap_or("no mode")));
                }
            }
            if wrong.is_empty() {
                (true, format!("every robot ends in {mode}"))
            } else {
                (false, wrong.join(", "))
            }
        }
    }
}
