//! `semo verify` as a user reaches it: the findings of the fixtures at
//! their lines and nothing else, each counterexample replayed by `semo
//! simulate` to the state the finding names, and the examples free of
//! findings (the false-positive count of the closing notes).

mod support;

use support::semo;

/// (code, line, message) of each finding of `semo verify MISSION --format
/// json ARGS`, and the document's data.
fn verify(mission: &str, args: &[&str]) -> (i32, Vec<(String, u64, String)>, serde_json::Value) {
    let mut all = vec!["verify", mission, "--format", "json"];
    all.extend(args);
    let out = semo(&all);
    assert!(out.code <= 1, "{all:?}: {}{}", out.stdout, out.stderr);
    let document: serde_json::Value =
        serde_json::from_str(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", out.stdout));
    assert_eq!(document["command"], "verify", "{document}");
    let findings = document["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            (
                d["code"].as_str().unwrap().to_string(),
                d["start"]["line"].as_u64().unwrap(),
                d["message"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    (out.code, findings, document)
}

#[test]
fn a_mode_behind_an_endless_loop_is_never_entered() {
    let (code, findings, data) = verify("tests/fixtures/verify/never_entered/main.mission", &[]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    assert_eq!(findings.len(), 1, "{findings:?}");
    let (code, line, message) = &findings[0];
    assert_eq!((code.as_str(), *line), ("V001", 17), "{message}");
    assert!(message.contains("REST"), "{message}");
}

#[test]
fn a_mode_with_no_way_out_is_found_and_its_counterexample_replays() {
    let dir = support::robots::scratch("verify-never-finishes");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/never_finishes/main.mission";
    let (code, findings, data) = verify(mission, &["--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(findings.len(), 1, "{findings:?}");
    let (code, line, message) = &findings[0];
    // On the mode the robot is stuck in.
    assert_eq!((code.as_str(), *line), ("V002", 18), "{message}");
    assert!(message.contains("WANDER"), "{message}");
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    // The replay ends with the robot in WANDER, not finished.
    let out = semo(&[
        "simulate",
        mission,
        "--scenario",
        &scenario,
        "--format",
        "json",
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let run: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let text = run.to_string();
    assert!(text.contains("WANDER"), "{text}");
    assert!(!text.contains("FINISH"), "{text}");
}

#[test]
fn the_repaired_missions_and_the_small_examples_have_no_finding() {
    for (mission, exhaustive) in [
        ("tests/fixtures/verify/clean/main.mission", true),
        ("examples/follow/follow.mission", true),
        ("examples/swarm/march.mission", true),
        ("examples/scouting/scouting.mission", false),
        ("examples/swarm/patrol_groups.mission", false),
    ] {
        let (code, findings, data) = verify(mission, &["--max-states", "3000"]);
        assert_eq!((code, &findings), (0, &Vec::new()), "{mission}");
        assert_eq!(data["exhaustive"], exhaustive, "{mission}: {data}");
        assert!(data["states"].as_u64().unwrap() > 0, "{mission}");
    }
}

#[test]
fn a_step_off_the_sensors_period_is_bad_input() {
    let out = semo(&[
        "verify",
        "examples/follow/follow.mission",
        "--step",
        "250ms",
    ]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("multiple of 100ms"), "{}", out.stderr);
}
