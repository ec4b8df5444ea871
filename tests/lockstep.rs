//! `semo simulate --engine c`: the generated `linux-sim` programs, built and
//! run as processes in lock-step virtual time (`cli/src/lockstep.rs`, the
//! runtime's `semo_lockstep.c`). A run reads no clock: the same mission and
//! scenario give the same trace, byte for byte, however loaded the machine.

mod support;

use std::collections::BTreeMap;
use std::path::Path;
use support::{examples, repo_root, semo_in};

/// The trace of `semo simulate MISSION --scenario SCENARIO --engine ENGINE`.
fn trace(mission: &Path, scenario: &str, engine: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let scenario_path = dir.path().join("scenario.json");
    std::fs::write(&scenario_path, scenario).unwrap();
    let out = support::simulate_trace(mission, &scenario_path, engine);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    out.stdout
}

/// Per robot, how many events of each kind the trace has.
fn kinds(trace: &str) -> BTreeMap<(String, String), usize> {
    let mut counts = BTreeMap::new();
    for line in trace.lines() {
        let event: serde_json::Value = serde_json::from_str(line).unwrap();
        let key = (
            event["robot"].as_str().unwrap().to_string(),
            event["event"].as_str().unwrap().to_string(),
        );
        *counts.entry(key).or_default() += 1;
    }
    counts
}

fn scouting_scenario() -> String {
    std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
        .unwrap()
}

/// Twice the same trace, every robot from `start` to `stop`, and the same
/// events as the simulator's, kind for kind (their times are the next step:
/// issue "One exact meaning").
#[test]
fn scouting_runs_the_same_way_twice_in_lock_step() {
    let mission = examples().join("scouting/scouting.mission");
    let scenario = scouting_scenario();
    let first = trace(&mission, &scenario, "c");
    let second = trace(&mission, &scenario, "c");
    assert!(first == second, "two lock-step runs differ");
    let counts = kinds(&first);
    for robot in ["irobot", "ti", "nxt"] {
        for edge in ["start", "stop"] {
            assert_eq!(
                counts.get(&(robot.into(), edge.into())),
                Some(&1),
                "{robot} {edge}"
            );
        }
    }
    let simulated = kinds(&trace(&mission, &scenario, "sim"));
    let differing: Vec<String> = counts
        .keys()
        .chain(simulated.keys())
        .filter(|k| counts.get(*k) != simulated.get(*k))
        // The C runtime's own end-of-run record of dropped samples.
        .filter(|(_, kind)| kind != "dropped")
        .map(|k| format!("{k:?}: C {:?}, sim {:?}", counts.get(k), simulated.get(k)))
        .collect();
    assert!(differing.is_empty(), "{}", differing.join("\n"));
}

/// A robot killed and restarted (the leader of a swarm's group): the
/// coordinator does it at the fault's mission time, so that too is the same
/// in every run.
#[test]
fn a_killed_and_restarted_leader_runs_the_same_way_twice_in_lock_step() {
    let mission = examples().join("swarm/patrol_groups.mission");
    let scenario = r#"{"duration": 5000,
        "faults": [{"at": 1200, "kill": "tb_0"}, {"at": 2200, "restart": "tb_0"}]}"#;
    let first = trace(&mission, scenario, "c");
    assert_eq!(first, trace(&mission, scenario, "c"));
    let starts: Vec<i64> = first
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|e| e["robot"] == "tb_0" && e["event"] == "start")
        .map(|e| e["t"].as_i64().unwrap())
        .collect();
    assert_eq!(
        starts,
        [0, 2200],
        "tb_0 starts at 0 and again when restarted"
    );
    let events: Vec<serde_json::Value> = first
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .filter(|e: &serde_json::Value| e["robot"] == "tb_0")
        .collect();
    // The coordinator traces the faults it does, as the simulator does.
    let faults: Vec<(i64, &str)> = events
        .iter()
        .filter(|e| e["event"] == "fault")
        .map(|e| (e["t"].as_i64().unwrap(), e["fault"].as_str().unwrap()))
        .collect();
    assert_eq!(faults, [(1200, "kill"), (2200, "restart")]);
    let after_kill = events
        .iter()
        .any(|e| e["event"] != "fault" && (1200..2200).contains(&e["t"].as_i64().unwrap()));
    assert!(!after_kill, "tb_0 traced something while killed");
}

/// What `--engine c` cannot do is said, not done some other way.
#[test]
fn lock_step_refuses_what_it_does_not_model() {
    let mission = examples().join("scouting/scouting.mission");
    let dir = tempfile::tempdir().unwrap();
    let lossy = dir.path().join("lossy.json");
    std::fs::write(&lossy, r#"{"duration": 1000, "network": {"loss": 0.5}}"#).unwrap();
    let args = |extra: &[&str]| {
        let mut args = vec![
            "simulate".to_string(),
            mission.display().to_string(),
            "--scenario".to_string(),
            lossy.display().to_string(),
            "--engine".to_string(),
            "c".to_string(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let run = |args: Vec<String>| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        semo_in(&repo_root(), &args)
    };
    let out = run(args(&["--format", "json"]));
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("--engine sim"), "{}", out.stderr);
}
