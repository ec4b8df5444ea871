//! Reads arbitrary text as a `*.scenario.json` of the scouting example: must
//! never panic, every mistake and warning must lie inside the text on a
//! character boundary, and an accepted scenario is simulated briefly.
#![no_main]

use libfuzzer_sys::fuzz_target;
use semo::refine::RobotProgram;
use semo::sim::{self, ScenarioError};
use std::path::Path;
use std::sync::OnceLock;

/// Mission ms an accepted scenario is simulated.
const SIMULATED_MS: i64 = 1500;

fn programs() -> &'static [RobotProgram] {
    static PROGRAMS: OnceLock<Vec<RobotProgram>> = OnceLock::new();
    PROGRAMS.get_or_init(|| {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scouting/scouting.mission");
        let (run, id) = semo::host::load_build(&path, &[]).expect("the mission loads");
        let build = run.analysis().build_input(id).expect("the mission checks");
        let programs = semo::refine::refine_checked(&build.input()).programs;
        assert!(!programs.is_empty());
        programs
    })
}

fn inside(text: &str, e: &ScenarioError) {
    assert!(e.at <= text.len() && text.is_char_boundary(e.at));
    assert!(!e.message.is_empty());
    e.line_col(text);
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let programs = programs();
    let scenario = match sim::scenario::parse(&text, programs) {
        Ok(scenario) => scenario,
        Err(e) => {
            inside(&text, &e);
            return;
        }
    };
    for w in &scenario.warnings {
        inside(&text, w);
    }
    let options = sim::Options {
        until_ms: Some(SIMULATED_MS),
        ..sim::Options::default()
    };
    let run = sim::simulate(programs, &scenario, &options);
    assert!(run.end_ms <= SIMULATED_MS);
    let verdicts = sim::expect::judge(&run, &scenario.expect);
    sim::summary(&run, &verdicts);
    run.trace_lines();
});
