//! The simulator (`semo simulate`): every robot of a mission run at once as
//! a deterministic discrete-event simulation in virtual time, from the same
//! refined [`RobotProgram`]s the C generator walks — the reference meaning
//! of a mission, against which the generated `linux-sim` programs are tested.
//!
//! - `json.rs`: a strict JSON reader keeping each value's position.
//! - `scenario.rs`: the scenario file (sensors, services, operator, network,
//!   faults, expectations), names checked against the programs.
//! - `engine.rs`: the event loop mirroring the generated control task and
//!   the runtime.
//! - `trace.rs`: trace events, written as `linux-sim` writes them.
//! - `expect.rs`: expectations judged on the trace.
//! - `replay.rs`: a recorded trace read back into a [`Run`] (`semo replay`),
//!   so that the summary, the picture and the expectations are these
//!   same functions on a field run.
//! - `svg.rs`: the timeline picture.
//! - `complete.rs`: completion in scenario files, and which mission a
//!   scenario belongs to.
//!
//! Nothing reads the wall clock; a run is a function of the programs, the
//! scenario and the seed.

pub mod complete;
mod engine;
pub mod expect;
mod json;
pub mod replay;
pub mod scenario;
pub mod svg;
pub mod trace;

pub use engine::{DEFAULT_UNTIL_MS, Memory, Options, Run, Sim};
pub use expect::Verdict;
pub use scenario::{Scenario, ScenarioError};
pub use trace::TraceEvent;

use crate::refine::RobotProgram;
use std::fmt::Write;

/// Runs every program on the scenario.
pub fn simulate(programs: &[RobotProgram], scenario: &Scenario, options: &Options) -> Run {
    engine::Sim::new(programs, scenario, options).run(options)
}

impl Run {
    /// The trace as JSON lines, each ending in a newline.
    pub fn trace_lines(&self) -> String {
        let mut out = String::new();
        for e in &self.trace {
            out.push_str(&e.to_json(&self.robots[e.robot].1));
            out.push('\n');
        }
        out
    }
}

/// The text summary: each robot's modes in order, then every expectation.
pub fn summary(run: &Run, verdicts: &[Verdict]) -> String {
    let mut out = format!(
        "simulated {} robot(s) for {} ms of mission time ({} events)\n",
        run.robots.len(),
        run.end_ms,
        run.events
    );
    robots_and_verdicts(&mut out, run, verdicts);
    out
}

/// [`summary`] of a recorded run ([`replay`]): the same lines under a
/// heading that says where they come from.
pub fn replay_summary(run: &Run, verdicts: &[Verdict], files: usize) -> String {
    let mut out = format!(
        "replayed {} robot(s) from {files} trace file(s): {} lines to {} ms of mission time\n",
        run.robots.len(),
        run.events,
        run.end_ms
    );
    robots_and_verdicts(&mut out, run, verdicts);
    out
}

/// Each robot's modes in order with its last word, then every expectation.
fn robots_and_verdicts(out: &mut String, run: &Run, verdicts: &[Verdict]) {
    let modes = expect::modes_of_every_robot(run);
    let ends = last_words(run);
    for (((team, robot), modes), end) in run.robots.iter().zip(&modes).zip(&ends) {
        let modes: Vec<String> = modes.iter().map(|(t, m)| format!("{m}@{t}")).collect();
        let _ = writeln!(
            out,
            "  {team}/{robot}: {} ({end})",
            if modes.is_empty() {
                "no mode".to_string()
            } else {
                modes.join(" -> ")
            }
        );
    }
    if !verdicts.is_empty() {
        let met = verdicts.iter().filter(|v| v.met).count();
        let _ = writeln!(out, "expectations: {met} of {} met", verdicts.len());
        for v in verdicts {
            let _ = writeln!(
                out,
                "  {} {}: {}",
                if v.met { "ok  " } else { "FAIL" },
                v.expectation.kind,
                v.why
            );
        }
    }
}

/// Each robot's last word, indexed by robot: finished, killed, still
/// running, or (a recorded run) no trace line at all; found in one pass
/// over the trace, from its end.
fn last_words(run: &Run) -> Vec<String> {
    let mut words: Vec<Option<String>> = vec![None; run.robots.len()];
    // The time of each robot's last line, for one whose start is not in
    // a recorded trace.
    let mut last: Vec<Option<i64>> = vec![None; run.robots.len()];
    let mut missing = words.len();
    for e in run.trace.iter().rev() {
        if missing == 0 {
            break;
        }
        if let Some(t @ None) = last.get_mut(e.robot) {
            *t = Some(e.t);
        }
        let Some(word @ None) = words.get_mut(e.robot) else {
            continue;
        };
        *word = match (e.event, e.field("fault")) {
            ("finish", _) => Some(format!("finished at {} ms", e.t)),
            ("fault", Some("kill")) => Some(format!("killed at {} ms", e.t)),
            ("start", _) => Some(format!("running at {} ms", run.end_ms)),
            _ => None,
        };
        if word.is_some() {
            missing -= 1;
        }
    }
    words
        .into_iter()
        .zip(last)
        .map(|(word, last)| match (word, last) {
            (Some(word), _) => word,
            (None, Some(t)) => format!("last line at {t} ms"),
            (None, None) => "no trace line".to_string(),
        })
        .collect()
}

#[cfg(test)]
mod tests;
