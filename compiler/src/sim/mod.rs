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
//! - `temporal.rs`: `always`, `eventually`, `leads_to` judged instant by
//!   instant (for a run, and for each step `semo verify` explores).
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
pub mod loss;
pub mod replay;
pub mod scenario;
pub mod svg;
pub mod temporal;
pub mod trace;

pub use engine::{
    Arrival, DEFAULT_UNTIL_MS, Differs, Memory, MessageRace, Options, Race, Run, Sim, Taken,
};
pub use expect::{Digest, Verdict};
pub use scenario::{Scenario, ScenarioError};
pub use trace::TraceEvent;

use crate::refine::RobotProgram;
use std::fmt::Write;

/// Runs every program on the scenario.
pub fn simulate(programs: &[RobotProgram], scenario: &Scenario, options: &Options) -> Run {
    engine::Sim::new(programs, scenario, options).run(options)
}

/// [`simulate`] giving each trace event to `sink` as it is made, keeping
/// none (the run's `trace` is empty): a long run's memory follows its
/// robots, not its trace. Feed a [`Digest`] for the summary and the
/// expectations.
pub fn simulate_into(
    programs: &[RobotProgram],
    scenario: &Scenario,
    options: &Options,
    sink: &mut dyn FnMut(TraceEvent),
) -> Run {
    engine::Sim::new(programs, scenario, options).run_into(options, sink)
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
    summary_of(run, &Digest::of(run, &[]), verdicts)
}

/// [`summary`] of a run whose trace went elsewhere as it was made
/// ([`simulate_into`]), from its [`Digest`].
pub fn summary_of(run: &Run, digest: &Digest, verdicts: &[Verdict]) -> String {
    let mut out = format!(
        "simulated {} robot(s) for {} ms of mission time ({} events)\n",
        run.robots.len(),
        run.end_ms,
        run.events
    );
    robots_and_verdicts(&mut out, run, digest, verdicts);
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
    robots_and_verdicts(&mut out, run, &Digest::of(run, &[]), verdicts);
    out
}

/// Each robot's modes in order with its last word, then every expectation.
fn robots_and_verdicts(out: &mut String, run: &Run, digest: &Digest, verdicts: &[Verdict]) {
    let ends = digest.last_words(run.end_ms);
    for (((team, robot), modes), end) in run.robots.iter().zip(digest.modes()).zip(&ends) {
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

#[cfg(test)]
mod tests;
