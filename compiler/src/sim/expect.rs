//! Expectations of a scenario, judged on a run's trace.

use super::engine::Run;
use super::scenario::{ExpectKind, Expectation};

/// One expectation and whether the run met it, with the evidence.
#[derive(Clone, Debug)]
pub struct Verdict {
    pub expectation: Expectation,
    pub met: bool,
    /// What the run showed: when the mode was entered, the robot's last
    /// mode, the messages received, ...
    pub why: String,
}

fn robot_index(run: &Run, robot: &str) -> Option<usize> {
    run.robots.iter().position(|(_, r)| r == robot)
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

pub fn judge(run: &Run, expectations: &[Expectation]) -> Vec<Verdict> {
    expectations
        .iter()
        .map(|x| {
            let (met, why) = judge_one(run, &x.kind);
            Verdict {
                expectation: x.clone(),
                met,
                why,
            }
        })
        .collect()
}

fn judge_one(run: &Run, kind: &ExpectKind) -> (bool, String) {
    match kind {
        ExpectKind::Enters {
            robot,
            mode,
            before,
        } => {
            let Some(r) = robot_index(run, robot) else {
                return (false, format!("no robot {robot}"));
            };
            match modes(run, r).into_iter().find(|(_, m)| m == mode) {
                Some((t, _)) if before.is_none_or(|b| t <= b) => {
                    (true, format!("entered at {t} ms"))
                }
                Some((t, _)) => (false, format!("entered only at {t} ms")),
                None => (false, "never entered".into()),
            }
        }
        ExpectKind::NeverEnters { robot, mode } => {
            let Some(r) = robot_index(run, robot) else {
                return (false, format!("no robot {robot}"));
            };
            match modes(run, r).into_iter().find(|(_, m)| m == mode) {
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
            let Some(r) = robot_index(run, robot) else {
                return (false, format!("no robot {robot}"));
            };
            let received = run.trace.iter().find(|e| {
                e.robot == r
                    && e.event == "receive"
                    && e.field("key") == Some(key)
                    && from
                        .as_deref()
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
            let every = modes_of_every_robot(run);
            for ((_, robot), modes) in run.robots.iter().zip(&every) {
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
