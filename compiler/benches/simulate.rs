//! The simulator (`semo simulate`): the scouting scenario (about 9 s of
//! mission time until every robot finished, 3 robots; goal under 20 ms of
//! wall time) and 102 robots of the generated benchmark mission for 10
//! minutes of mission time (goal under 1 s), each with the cost per
//! simulated event. Each is measured also with every control firing
//! simulated (`Options::every_firing`), which skipping idle firings
//! replaces. Run with `cargo bench --bench simulate`.

mod common;
use common::fastest;

use semo::refine::RobotProgram;
use semo::sim::{self, scenario};
use std::path::Path;
use std::time::Duration;

fn programs(files: semo::workspace::Files, id: semo::diag::FileId) -> Vec<RobotProgram> {
    let mut host = semo::host::AnalysisHost::default();
    for f in files.iter() {
        host.set_file(f.id, Some(f.path.clone()), f.kind, f.text.as_str().into());
    }
    let build = host
        .analysis()
        .build_input(id)
        .expect("the mission was checked");
    let refined = semo::codegen::refine_checked(&build.input());
    assert!(!refined.programs.is_empty(), "{:#?}", refined.diagnostics);
    refined.programs
}

fn measure(name: &str, programs: &[RobotProgram], scenario_text: &str, until_ms: Option<i64>) {
    for every_firing in [false, true] {
        let name = if every_firing {
            format!("{name} (every firing, the reference)")
        } else {
            name.to_string()
        };
        measure_once(&name, programs, scenario_text, until_ms, every_firing);
    }
}

fn measure_once(
    name: &str,
    programs: &[RobotProgram],
    scenario_text: &str,
    until_ms: Option<i64>,
    every_firing: bool,
) {
    let scenario = scenario::parse(scenario_text, programs).expect("the scenario reads");
    let options = sim::Options {
        until_ms,
        seed: 1,
        every_firing,
    };
    let run = sim::simulate(programs, &scenario, &options);
    let best = fastest(Duration::from_secs(3), || {
        std::hint::black_box(sim::simulate(programs, &scenario, &options).events);
    });
    println!(
        "simulate {name}: {} robots, {} ms of mission time, {} events, {} trace lines: {:.2} ms ({:.0} ns per event)",
        programs.len(),
        run.end_ms,
        run.events,
        run.trace.len(),
        best.as_secs_f64() * 1e3,
        best.as_secs_f64() * 1e9 / run.events.max(1) as f64
    );
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let (run, id) = semo::host::load_build(&root.join("examples/scouting/scouting.mission"), &[])
        .expect("the example loads");
    let scouting = programs(run.files, id);
    let scenario =
        std::fs::read_to_string(root.join("tests/fixtures/build/scouting.scenario.json"))
            .expect("the scenario fixture");
    measure("scouting", &scouting, &scenario, None);

    // 17 teams of 6: 102 robots talking to their neighbouring teams.
    let mut files = semo::workspace::Files::default();
    let id = files.add(
        "swarm.mission".into(),
        semo::workspace::FileKind::Mission,
        common::mission::generate(17),
    );
    let swarm = programs(files, id);
    measure("swarm", &swarm, "{}", Some(10 * 60 * 1000));
}
