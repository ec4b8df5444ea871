//! The simulator on the examples: the behaviour `tests/build.rs` asserts of
//! the generated C programs, faults, determinism, and scenario mistakes.

use super::*;
use crate::refine::RobotProgram;
use std::path::Path;

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

/// The refined programs of an example mission, as `semo simulate` gets them.
pub(super) fn programs(mission: &str) -> Vec<RobotProgram> {
    let (run, id) = crate::host::load_build(&repo(mission), &[]).unwrap();
    let build = run
        .analysis()
        .build_input(id)
        .expect("the mission was checked");
    let refined = crate::codegen::refine_checked(&build.input());
    assert!(!refined.programs.is_empty(), "{:#?}", refined.diagnostics);
    refined.programs
}

fn run(programs: &[RobotProgram], scenario: &str, seed: u64) -> (Run, Vec<Verdict>) {
    let scenario = scenario::parse(scenario, programs).unwrap_or_else(|e| panic!("{e:?}"));
    let options = Options {
        seed,
        ..Options::default()
    };
    let run = simulate(programs, &scenario, &options);
    // Skipping idle firings changes nothing of the trace.
    let every_firing = simulate(
        programs,
        &scenario,
        &Options {
            every_firing: true,
            ..options
        },
    );
    assert_eq!(run.trace_lines(), every_firing.trace_lines());
    assert_eq!(run.end_ms, every_firing.end_ms);
    let verdicts = expect::judge(&run, &scenario.expect);
    (run, verdicts)
}

fn modes(run: &Run, robot: &str) -> Vec<String> {
    let r = run.robots.iter().position(|(_, n)| n == robot).unwrap();
    expect::modes(run, r)
        .into_iter()
        .map(|(_, m)| m.to_string())
        .collect()
}

fn scouting_scenario() -> String {
    std::fs::read_to_string(repo("tests/fixtures/build/scouting.scenario.json")).unwrap()
}

#[test]
fn scouting_runs_through_its_modes() {
    let programs = programs("examples/scouting/scouting.mission");
    let (run, _) = run(&programs, &scouting_scenario(), 0);
    eprintln!("{}", summary(&run, &[]));
    assert_eq!(
        modes(&run, "irobot"),
        ["AUTO_MODE", "WAIT_MODE", "RETURN_MODE", "FINISH"]
    );
    for slave in ["ti", "nxt"] {
        assert_eq!(
            modes(&run, slave),
            ["AUTO_MODE", "SEARCH_MODE", "RETURN_MODE", "FINISH"],
            "{slave}"
        );
    }
}

#[test]
fn scouting_meets_its_expectations_and_a_wrong_one_fails() {
    // The fixture's expectations are what `tests/build.rs` asserts of the C programs.
    let programs = programs("examples/scouting/scouting.mission");
    let (_, verdicts) = run(&programs, &scouting_scenario(), 0);
    assert_eq!(verdicts.len(), 8);
    assert!(verdicts.iter().all(|v| v.met), "{verdicts:#?}");
    let wrong = scouting_scenario().replacen(
        "\"expect\": [",
        r#""expect": [{"robot": "ti", "enters": "RETURN_MODE", "before": 1000},"#,
        1,
    );
    let (_, verdicts) = run(&programs, &wrong, 0);
    let failed: Vec<_> = verdicts.iter().filter(|v| !v.met).collect();
    assert_eq!(failed.len(), 1, "{verdicts:#?}");
    assert_eq!(failed[0].why, "entered only at 3500 ms");
}

#[test]
fn the_trace_is_the_runtime_schema_and_the_same_for_a_seed() {
    let programs = programs("examples/scouting/scouting.mission");
    let lossy = scouting_scenario().replacen('{', r#"{"network": {"loss": 0.3},"#, 1);
    let (a, _) = run(&programs, &lossy, 7);
    let (b, _) = run(&programs, &lossy, 7);
    let (c, _) = run(&programs, &lossy, 8);
    assert_eq!(a.trace_lines(), b.trace_lines());
    assert_ne!(
        a.trace_lines(),
        c.trace_lines(),
        "the seed draws the losses"
    );
    let first = a.trace_lines().lines().next().unwrap().to_string();
    assert_eq!(
        first,
        r#"{"t":0,"robot":"irobot","event":"start","team":"MasterTeam","type":"iRobotCreate","mission":"scouting.mission"}"#
    );
    // One key per field: no field repeats the line's own keys.
    assert!(
        a.trace.iter().all(|e| e
            .fields
            .iter()
            .all(|(k, _)| !["t", "robot", "event"].contains(k))),
        "a field named like the line's own keys"
    );
    assert!(
        a.trace
            .iter()
            .any(|e| e.event == "catch" && e.field("name").is_some())
    );
    // Time never goes back.
    assert!(a.trace.windows(2).all(|w| w[0].t <= w[1].t));
}

fn leaders(run: &Run, robot: &str) -> Vec<String> {
    let r = run.robots.iter().position(|(_, n)| n == robot).unwrap();
    run.trace
        .iter()
        .filter(|e| e.robot == r && e.event == "leader")
        .map(|e| e.field("leader").unwrap().to_string())
        .collect()
}

#[test]
fn a_killed_leader_is_replaced_and_a_restarted_one_leads_again() {
    let programs = programs("examples/swarm/patrol_groups.mission");
    let (run_, _) = run(
        &programs,
        r#"{"duration": 3500, "faults": [{"at": 1200, "kill": "tb_0"}]}"#,
        0,
    );
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_1"]);
    assert_eq!(leaders(&run_, "tb_2"), ["tb_0", "tb_1"]);
    assert!(leaders(&run_, "ev_0").is_empty());
    let tb_1 = run_.robots.iter().position(|(_, n)| n == "tb_1").unwrap();
    let took_over = run_
        .trace
        .iter()
        .find(|e| e.robot == tb_1 && e.event == "leader" && e.field("leader") == Some("tb_1"))
        .unwrap()
        .t;
    // Three heartbeats after the last one heard.
    assert!((1200..=1200 + 4 * crate::refine::HEARTBEAT_MS).contains(&took_over));
    let lights = run_
        .trace
        .iter()
        .filter(|e| e.robot == tb_1 && e.event == "call_start")
        .filter(|e| e.field("service") == Some("light_on") && e.t >= took_over)
        .count();
    assert!(lights >= 1, "the new leader runs the leader's block");

    let (run_, _) = run(
        &programs,
        r#"{"duration": 5000, "faults": [{"at": 1200, "kill": "tb_0"}, {"at": 3000, "restart": "tb_0"}]}"#,
        0,
    );
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_1", "tb_0"]);
}

#[test]
fn link_faults_lose_and_delay_messages() {
    let programs = programs("examples/scouting/scouting.mission");
    let count = |run: &Run, from: &str| {
        run.trace
            .iter()
            .filter(|e| e.event == "receive" && e.field("from_robot") == Some(from))
            .filter(|e| run.robots[e.robot].1 == "irobot")
            .count()
    };
    let (plain, _) = run(&programs, &scouting_scenario(), 0);
    assert!(count(&plain, "ti") > 0);
    let cut = scouting_scenario().replacen(
        '{',
        r#"{"faults": [{"from": 0, "until": 20000, "partition": [["irobot"], ["ti", "nxt"]]}],"#,
        1,
    );
    let (cut, _) = run(&programs, &cut, 0);
    assert_eq!(count(&cut, "ti"), 0);
    assert_eq!(count(&cut, "nxt"), 0);
    let dropped = scouting_scenario().replacen(
        '{',
        r#"{"faults": [{"from": 0, "until": 20000, "drop": ["irobot", "ti"]}],"#,
        1,
    );
    let (dropped, _) = run(&programs, &dropped, 0);
    assert_eq!(count(&dropped, "ti"), 0);
    assert!(count(&dropped, "nxt") > 0);
    let slow = scouting_scenario().replacen(
        '{',
        r#"{"faults": [{"from": 0, "until": 20000, "delay": ["irobot", "ti"], "by": 250}],"#,
        1,
    );
    let (slow, _) = run(&programs, &slow, 0);
    let late = slow
        .trace
        .iter()
        .find(|e| e.event == "receive" && e.field("from_robot") == Some("ti"))
        .unwrap();
    assert_eq!(late.t - late.sent_at.unwrap(), 251);
}

#[test]
fn scenario_mistakes_point_at_the_value() {
    let programs = programs("examples/scouting/scouting.mission");
    for (text, line_col, message) in [
        (
            "{\n  \"robots\": {\"robot9\": {}}\n}",
            (2, 24),
            "robot \"robot9\" is not in the mission (robots: irobot, ti, nxt)",
        ),
        (
            "{\"expect\": [{\"robot\": \"ti\", \"enters\": \"WAIT_MODE\"}]}",
            (1, 39),
            "no mode \"WAIT_MODE\" for robot ti (modes: AUTO_MODE, FINISH, RC_MODE, RETURN_MODE, SEARCH_MODE)",
        ),
        (
            "{\"faults\": [{\"at\": 5, \"kill\": \"ti\", \"restart\": \"ti\"}]}",
            (1, 13),
            "a fault is exactly one of \"kill\", \"restart\", \"drop\", \"delay\", \"partition\"",
        ),
        (
            "{\"duration\": -1}",
            (1, 14),
            "\"duration\" must be a whole number of milliseconds",
        ),
        (
            "{\"operator\": [{\"at\": 1, \"to\": \"nobody\", \"value\": \"X\", \"is\": 1}]}",
            (1, 31),
            "\"nobody\" is neither a robot nor a team of the mission",
        ),
        (
            "{\"robots\": {\n  \"ti\": {\"sensors\": [{\"at\": 0, \"value\": \"COLOR\"}]}}}",
            (2, 22),
            "missing \"is\"",
        ),
        ("{\"version\": 2}", (1, 13), "\"version\" must be 1"),
        (
            "{\"colour\": 2}",
            (1, 12),
            "unknown key \"colour\" in a scenario object {\"robots\": ..., \"operator\": ...} (expected one of: version, time_scale, duration, robots, operator, network, faults, expect)",
        ),
        ("{\"robots\": {}", (1, 14), "expected ',' or '}'"),
    ] {
        let e = scenario::parse(text, &programs).unwrap_err();
        assert_eq!(
            (e.line_col(text), e.message.as_str()),
            (line_col, message),
            "{text}"
        );
    }
}
