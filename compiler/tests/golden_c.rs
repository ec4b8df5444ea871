//! The files code generation writes for a robot, as golden output (insta
//! snapshots under `tests/snapshots/`, one per file): a change to the emitted
//! C, Makefile or task graph shows in review as a change to a snapshot, and a
//! change nobody meant fails here. The follow mission's robot for `linux`,
//! `linux-sim` and `cortex-m` (the runtime's own files are in the repository
//! as they are written, `src/codegen/runtime/`). A deliberate change: run the
//! test with `INSTA_UPDATE=always` (or `cargo insta review`) and read the
//! diff of the snapshots before committing it.

use semo::codegen::{self, Emit, Target};
use semo::host::load_build;
use std::path::Path;

fn follow(target: Target) -> codegen::BuildResult {
    let mission = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/follow/follow.mission");
    let (run, id) = load_build(&mission, &[]).expect("the example loads");
    let build = run
        .analysis()
        .build_input(id)
        .expect("the mission is checked");
    let result = codegen::build(&build.input(), target, Emit::All);
    assert!(!result.refused(), "{:#?}", result.diagnostics);
    result
}

#[test]
fn the_files_of_the_follow_robot_for_each_target() {
    for target in [Target::Linux, Target::LinuxSim, Target::CortexM] {
        let result = follow(target);
        assert_eq!(result.robots.len(), 1);
        let robot = &result.robots[0];
        for file in &robot.files {
            let name = format!("{}-{}", target.name(), file.path.replace('/', "-"));
            insta::assert_snapshot!(name, file.text);
        }
    }
}
