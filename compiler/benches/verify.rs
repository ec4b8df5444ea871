//! `semo verify`: states explored per second on the examples, whether the
//! search is exhaustive, and what merging states across instants (the
//! reduction) saves over the unreduced search (only states of one instant
//! merge) on the same budget. Goals (issue 31): scouting exhaustive in
//! under 1 s (not met: bounded). Run with `cargo bench --bench verify`.

use semo::refine::RobotProgram;
use std::path::Path;
use std::time::Instant;

fn programs(mission: &Path) -> (Vec<RobotProgram>, semo::diag::FileId, String) {
    let (run, id) = semo::host::load_build(mission, &[]).expect("the example loads");
    let text = run.files.get(id).text.clone();
    let build = run
        .analysis()
        .build_input(id)
        .expect("the mission was checked");
    let refined = semo::codegen::refine_checked(&build.input());
    assert!(!refined.programs.is_empty(), "{:#?}", refined.diagnostics);
    (refined.programs, id, text)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for example in [
        "examples/follow/follow.mission",
        "examples/patrol/patrol.mission",
        "examples/scouting/scouting.mission",
        "examples/swarm/patrol_groups.mission",
    ] {
        let (programs, id, text) = programs(&root.join(example));
        for merge_in_time in [true, false] {
            let options = semo::verify::Options {
                max_states: 20_000,
                merge_in_time,
                ..semo::verify::Options::default()
            };
            let start = Instant::now();
            let report =
                semo::verify::verify(&programs, id, &text, &options).expect("valid options");
            let took = start.elapsed().as_secs_f64();
            println!(
                "verify {example}{}: {} ({} states, {} transitions, {} ms of mission time) in {:.2} s: {:.0} transitions/s, {} finding(s)",
                if merge_in_time { "" } else { " (unreduced)" },
                if report.exhaustive {
                    "exhaustive"
                } else {
                    "bounded"
                },
                report.states,
                report.transitions,
                report.reached_ms,
                took,
                report.transitions as f64 / took.max(1e-9),
                report.findings.len()
            );
        }
    }
}
