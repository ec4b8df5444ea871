//! `semo verify`: states and transitions explored per second, whether the
//! search is exhaustive, and what merging states across instants (the
//! reduction) saves over the unreduced search (only states of one instant
//! merge) on the same budget, on the examples, a five-robot three-team
//! mission (`tests/fixtures/verify/three_teams`) and the `tb[N]` swarm of
//! `examples/swarm/patrol_groups.mission` at N = 3 and N = 20. Goals (issue 31):
//! scouting exhaustive in under 1 s, five robots in three teams in under
//! 10 s, `name[20]` no costlier than `name[3]` (docs/verify.md has the
//! figures and which are met). Run with `cargo bench --bench verify`.

use semo::refine::RobotProgram;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "common/allocator.rs"]
mod allocator;

fn programs(mission: &Path) -> (Vec<RobotProgram>, semo::diag::FileId, String) {
    let (run, id) = semo::host::load_build(mission, &[]).expect("the example loads");
    let text = run.files.get(id).text.clone();
    let build = run
        .analysis()
        .build_input(id)
        .expect("the mission was checked");
    let refined = semo::refine::refine_checked(&build.input());
    assert!(!refined.programs.is_empty(), "{:#?}", refined.diagnostics);
    (refined.programs, id, text)
}

/// `examples/swarm/patrol_groups.mission` with `tb[count]` (each
/// TurtleBot compares its light level: three classes each), written to a
/// folder of its own.
fn swarm(root: &Path, count: usize) -> PathBuf {
    let text = std::fs::read_to_string(root.join("examples/swarm/patrol_groups.mission"))
        .expect("the example reads");
    assert!(text.contains("tb[3]"), "the example's swarm changed");
    let dir = std::env::temp_dir().join(format!("semo-bench-verify-swarm-{count}"));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let mission = dir.join("patrol_groups.mission");
    std::fs::write(&mission, text.replace("tb[3]", &format!("tb[{count}]")))
        .expect("the mission writes");
    mission
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut missions: Vec<(String, PathBuf)> = [
        "examples/follow/follow.mission",
        "examples/patrol/patrol.mission",
        "examples/scouting/scouting.mission",
        "examples/swarm/patrol_groups.mission",
        "tests/fixtures/verify/three_teams/main.mission",
    ]
    .into_iter()
    .map(|m| (m.to_string(), root.join(m)))
    .collect();
    for count in [3, 20] {
        missions.push((format!("patrol_groups tb[{count}]"), swarm(&root, count)));
    }
    for (name, mission) in missions {
        let (programs, id, text) = programs(&mission);
        for merge_in_time in [true, false] {
            let options = semo::verify::Options {
                max_states: 20_000,
                merge_in_time,
                ..semo::verify::Options::default()
            };
            let start = Instant::now();
            let report =
                semo::verify::verify(&programs, id, &text, &options).expect("valid options");
            let took = start.elapsed().as_secs_f64().max(1e-9);
            println!(
                "verify {name}{}: {} ({} states, {} transitions, {} ms of mission time) in {:.2} s: {:.0} states/s, {:.0} transitions/s, {} finding(s)",
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
                report.states as f64 / took,
                report.transitions as f64 / took,
                report.findings.len()
            );
        }
    }
}
