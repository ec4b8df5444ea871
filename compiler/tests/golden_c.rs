//! The files code generation writes, as golden output (insta snapshots under
//! `tests/snapshots/`): every example mission (`examples/`) for every target
//! (`Target::ALL`, a second board's targets on the follow robot only), one
//! snapshot per pair holding every robot's files, each
//! under a header naming it, then the runtime folder's files (a file written
//! as it is in `src/codegen/runtime/` is only named; one filled in for a
//! board is written out). A target that refuses a mission's robots (E103)
//! is snapshotted with
//! its diagnostics, so that a change of what is refused shows too. A change
//! to the emitted C, Makefile or task graph shows in review as a change to
//! a snapshot, and a change nobody meant fails here. A deliberate change:
//! run the test with `INSTA_UPDATE=always` (or `cargo insta review`) and
//! read the diff of the snapshots before committing it.
//!
//! Every fixed piece of every template of the generator
//! (`src/codegen/templates/`) is in some snapshot
//! (`every_template_s_text_is_in_some_snapshot`): moving text between the
//! Rust and the templates, or changing a template, shows here.
//!
//! `cortex-m-sim` compiles a scenario into each robot: the example's own
//! scenario where the repository has one (`tests/fixtures/`), else a run of
//! two seconds with nothing happening.

use semo::codegen::{self, Emit, Target};
use semo::host::load_build;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Every example mission: (snapshot name, path under `examples/`, scenario
/// for `cortex-m-sim` under the repository's `tests/fixtures/`, if any).
const EXAMPLES: &[(&str, &str, Option<&str>)] = &[
    (
        "follow",
        "follow/follow.mission",
        Some("cortex_m/follow.scenario.json"),
    ),
    ("patrol", "patrol/patrol.mission", None),
    (
        "scouting",
        "scouting/scouting.mission",
        Some("build/scouting.scenario.json"),
    ),
    ("swarm-march", "swarm/march.mission", None),
    ("swarm-patrol_groups", "swarm/patrol_groups.mission", None),
];

/// Test fixtures (under the repository's `tests/fixtures/`) for what the
/// examples do not generate: graph services with loops and sub-graphs,
/// counted groups (nested, and a broadcast in a counted arm), group synchronisation, group services, globally shared
/// values with battery policies, broadcast events, a relay receiving from
/// another team, a team on the static schedule, action results. As
/// [`EXAMPLES`].
const FIXTURES: &[(&str, &str, Option<&str>)] = &[
    (
        "fixture-loops",
        "loops/loops.mission",
        Some("loops/loops.scenario.json"),
    ),
    (
        "fixture-loops-tracking",
        "loops/tracking.mission",
        Some("loops/tracking.scenario.json"),
    ),
    (
        "fixture-counted_groups",
        "counted_groups/nested.mission",
        Some("counted_groups/nested.scenario.json"),
    ),
    (
        "fixture-counted_alarm",
        "counted_groups/alarm.mission",
        Some("counted_groups/alarm.scenario.json"),
    ),
    ("fixture-group_sync", "group_sync/sync.mission", None),
    ("fixture-group_service", "group_service/sweep.mission", None),
    (
        "fixture-shared_battery",
        "shared_battery/shared.mission",
        Some("shared_battery/shared.scenario.json"),
    ),
    (
        "fixture-broadcast",
        "broadcast/crew.mission",
        Some("broadcast/crew.scenario.json"),
    ),
    (
        "fixture-receive",
        "receive/relay.mission",
        Some("receive/relay.scenario.json"),
    ),
    (
        "fixture-cortex_m-swarm",
        "cortex_m/swarm.mission",
        Some("cortex_m/swarm.scenario.json"),
    ),
    (
        "fixture-action_results",
        "action_results/survey.mission",
        Some("action_results/survey.scenario.json"),
    ),
];

/// This test's own missions (`compiler/tests/fixtures/golden/`), for what no
/// other mission generates: timeouts on receives, calls and a strategy's
/// actions, a leader's block that receives, a plain throw beside a
/// broadcast one. (snapshot name, mission, `--strategy` folder under the
/// repository, if any).
const OWN: &[(&str, &str, Option<&str>)] = &[
    ("golden-constructs", "constructs.mission", None),
    (
        "golden-strategy_timeout",
        "strategy_timeout.mission",
        Some("examples/scouting"),
    ),
];

/// The scenario of an example the repository has none for.
const QUIET_SCENARIO: &str = r#"{"duration": 2000}"#;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// What `semo build MISSION [--strategy PATH] --target TARGET [--scenario
/// FILE]` generates.
fn build(
    mission: &Path,
    strategy: &[PathBuf],
    target: Target,
    scenario: Option<&str>,
) -> codegen::BuildResult {
    let (run, id) = load_build(mission, strategy).expect("the mission loads");
    let analysis = run.analysis();
    let build = analysis.build_input(id).expect("the mission is checked");
    let input = build.input();
    if !target.needs_scenario() {
        return codegen::build(&input, target, Emit::All);
    }
    let refined = semo::refine::refine_checked(&input);
    assert!(
        !refined.programs.is_empty(),
        "{}: {:#?}",
        mission.display(),
        refined.diagnostics
    );
    let text = match scenario {
        Some(file) => std::fs::read_to_string(repository().join("tests/fixtures").join(file))
            .expect("the scenario is read"),
        None => QUIET_SCENARIO.to_string(),
    };
    let scenario = semo::sim::scenario::parse(&text, &refined.programs).expect("the scenario");
    let worlds = scenario.compiled_for_each(&refined.programs);
    codegen::build_refined(&input, &refined, target, Emit::All, &worlds)
}

/// One build as text: its diagnostics, each robot's files, the runtime's.
fn written(result: &codegen::BuildResult) -> String {
    let mut out = String::new();
    for d in &result.diagnostics {
        let _ = writeln!(
            out,
            "diagnostic {:?} {:?}: {}",
            d.severity, d.code, d.message
        );
    }
    for robot in &result.robots {
        for file in &robot.files {
            let _ = writeln!(
                out,
                "==== {}/{}/{} ({}, {:?}) ====",
                robot.team, robot.robot, file.path, robot.target, file.owner
            );
            out.push_str(&file.text);
        }
    }
    let sources = repository().join("compiler/src/codegen/runtime");
    for file in &result.runtime {
        let _ = write!(out, "==== {}/{} ", codegen::RUNTIME_FOLDER, file.path);
        match std::fs::read_to_string(sources.join(&file.path)) {
            Ok(source) if source == file.text => out.push_str("(as in src/codegen/runtime) ====\n"),
            _ => {
                out.push_str("====\n");
                out.push_str(&file.text);
            }
        }
    }
    out
}

/// The targets every mission is snapshotted for: every target but those of
/// a second board of a layer, whose files differ from the first board's
/// only in the board's facts (its Makefile's head, its start-up file and
/// link script): those are snapshotted on one mission
/// (`the_files_of_a_second_board_for_the_follow_robot`).
fn targets_for_every_mission() -> impl Iterator<Item = Target> {
    // The first platform of each layer, as the table lists them.
    let first_of_layer = |t: Target| {
        semo::platform::PLATFORMS
            .iter()
            .find(|p| p.layer == t.layer())
            .is_some_and(|p| p == t.platform())
    };
    Target::ALL.into_iter().filter(move |&t| first_of_layer(t))
}

/// Every target's files of each mission of `missions`, under `folder`.
fn snapshot_every_target(folder: &str, missions: &[(&str, &str, Option<&str>)]) {
    for (name, mission, scenario) in missions {
        let mission = repository().join(folder).join(mission);
        for target in targets_for_every_mission() {
            let result = build(&mission, &[], target, *scenario);
            insta::assert_snapshot!(format!("{name}@{}", target.name()), written(&result));
        }
    }
}

#[test]
fn the_files_of_every_example_for_every_target() {
    snapshot_every_target("examples", EXAMPLES);
}

#[test]
fn the_files_of_the_fixtures_the_examples_miss_for_every_target() {
    snapshot_every_target("tests/fixtures", FIXTURES);
}

#[test]
fn the_files_of_a_second_board_for_the_follow_robot() {
    let (_, mission, scenario) = EXAMPLES
        .iter()
        .find(|(name, ..)| *name == "follow")
        .expect("the follow example");
    let mission = repository().join("examples").join(mission);
    for target in Target::ALL
        .into_iter()
        .filter(|t| targets_for_every_mission().all(|every| every != *t))
    {
        let result = build(&mission, &[], target, *scenario);
        insta::assert_snapshot!(format!("follow@{}", target.name()), written(&result));
    }
}

#[test]
fn the_files_of_the_constructs_only_this_test_writes_for_linux() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/golden");
    for (name, mission, strategy) in OWN {
        let strategy: Vec<PathBuf> = strategy.iter().map(|s| repository().join(s)).collect();
        let result = build(&folder.join(mission), &strategy, Target::Linux, None);
        insta::assert_snapshot!(format!("{name}@linux"), written(&result));
    }
}

/// Every fixed piece of every template (`src/codegen/templates/`, the text
/// between its slots) is in some snapshot, so that a change to any of them
/// shows here: a template no mission above fills would change unseen.
#[test]
fn every_template_s_text_is_in_some_snapshot() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut snapshots = String::new();
    for entry in std::fs::read_dir(manifest.join("tests/snapshots")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with("golden_c__") && name.ends_with(".snap") {
            snapshots.push_str(&std::fs::read_to_string(&path).unwrap());
        }
    }
    let mut unseen = Vec::new();
    for entry in walkdir::WalkDir::new(manifest.join("src/codegen/templates")) {
        let entry = entry.unwrap();
        if !entry.file_type().is_file() {
            continue;
        }
        let path = entry.path();
        let text = std::fs::read_to_string(path).unwrap();
        for piece in fixed_pieces(&text) {
            if !snapshots.contains(piece) {
                unseen.push(format!("{}: {piece:?}", path.display()));
            }
        }
    }
    assert!(unseen.is_empty(), "in no snapshot:\n{}", unseen.join("\n"));
}

/// The text between a template's `{{slot}}`s (those of more than a few
/// characters: a short piece proves nothing). A slot is `{{name}}`, `name`
/// a lower-case identifier, as `codegen::template` reads it; any other `{{`
/// is text.
fn fixed_pieces(text: &str) -> Vec<&str> {
    let mut pieces = Vec::new();
    let (mut piece_start, mut at) = (0, 0);
    while let Some(found) = text[at..].find("{{") {
        let start = at + found;
        let name = &text[start + 2..];
        let len = name
            .bytes()
            .enumerate()
            .take_while(|&(i, b)| {
                b.is_ascii_lowercase() || b == b'_' || (i > 0 && b.is_ascii_digit())
            })
            .count();
        if len > 0 && name[len..].starts_with("}}") {
            pieces.push(&text[piece_start..start]);
            piece_start = start + 2 + len + 2;
            at = piece_start;
        } else {
            at = start + 1;
        }
    }
    pieces.push(&text[piece_start..]);
    pieces.retain(|p| p.trim().len() > 3);
    pieces
}
