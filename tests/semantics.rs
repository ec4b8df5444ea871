//! Generated robots do what the checker accepted: regression tests for the
//! places where refinement or code generation used to mean something else
//! than the checker, each through the user's path (`semo check`, `semo build`,
//! compiling the robots, and for behaviour running the `linux-sim` programs
//! and reading their traces). Missions in `tests/fixtures/semantics/`.

mod support;

use std::path::PathBuf;
use support::robots::{
    Event, PEDANTIC, build, calls, compilers, events, field, make, modes, robot_folders,
    run_in_simulation, scratch,
};
use support::{examples, repo_root, semo, semo_in};

fn fixture(name: &str) -> PathBuf {
    repo_root().join("tests/fixtures/semantics").join(name)
}

const SHORT_RUN: &str = r#"{"time_scale": 0.2, "duration": 3000}"#;

#[test]
fn capable_of_several_capabilities_means_all_of_them() {
    let out = scratch("semantics/capable-of");
    let traces = run_in_simulation(&fixture("capable_of_all.mission"), &out, SHORT_RUN);
    let ev = events(&traces["ev"]);
    let nxt = events(&traces["nxt"]);
    assert_eq!(calls(&ev), ["scatter"], "the Ev3 has both capabilities");
    assert_eq!(
        calls(&nxt),
        ["spin"],
        "the NXT lacks a distance sensor: `others`"
    );
}

#[test]
fn a_task_providing_a_value_and_a_service_becomes_two_tasks() {
    let out = scratch("semantics/value-and-service");
    let built = build(&fixture("value_and_service_task.mission"), "linux", &out);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let folder = out.join("Finders/ev");
    let graph = std::fs::read_to_string(folder.join("taskgraph.xml")).unwrap();
    assert!(graph.contains("name=\"search\""), "{graph}");
    assert!(graph.contains("name=\"search_values\""), "{graph}");
    let analyzed = semo(&[
        "graph",
        "analyze",
        &folder.join("taskgraph.xml").display().to_string(),
    ]);
    assert_eq!(analyzed.code, 0, "{}{}", analyzed.stdout, analyzed.stderr);
    for cc in compilers() {
        make(&folder, cc, PEDANTIC).unwrap_or_else(|e| panic!("{e}"));
        let _ = std::process::Command::new("make")
            .args(["-s", "clean"])
            .current_dir(&folder)
            .status();
    }
}

#[test]
fn a_subscription_sees_the_robots_own_publication() {
    let out = scratch("semantics/own-publication");
    let traces = run_in_simulation(&fixture("own_publication.mission"), &out, SHORT_RUN);
    assert_eq!(modes(&events(&traces["a"])), ["SHARE", "MINE"]);
}

#[test]
fn a_received_value_needs_no_sensor_on_the_receiver() {
    let checked = semo(&[
        "check",
        &fixture("received_value.mission").display().to_string(),
    ]);
    assert_eq!(checked.code, 0, "{}{}", checked.stderr, checked.stderr);
    assert!(!checked.stderr.contains("E033"), "{}", checked.stderr);
    let out = scratch("semantics/received-value");
    let traces = run_in_simulation(
        &fixture("received_value.mission"),
        &out,
        r#"{"time_scale": 0.2, "duration": 3000,
            "robots": {"ev": {"sensors": [{"at": 0, "value": "COLOR", "is": "R"}]}}}"#,
    );
    let tb = events(&traces["tb"]);
    assert!(
        tb.iter()
            .any(|e| field(e, "event") == "receive" && field(e, "key") == "Mixed.COLOR"),
        "tb receives COLOR"
    );
    assert!(calls(&tb).iter().any(|c| c == "light_on"), "and acts on it");
}

#[test]
fn a_value_sent_without_having_or_receiving_it_is_still_reported() {
    let checked = semo(&[
        "check",
        &fixture("sends_value_it_lacks.mission")
            .display()
            .to_string(),
    ]);
    assert_eq!(checked.code, 1, "{}", checked.stderr);
    assert!(checked.stderr.contains("E033"), "{}", checked.stderr);
}

#[test]
fn strategies_inside_the_mission_folder_are_read_once() {
    let dir = scratch("semantics/strategy-twice");
    std::fs::create_dir_all(dir.join("strategies")).unwrap();
    std::fs::copy(
        examples().join("scouting/scouting.mission"),
        dir.join("scouting.mission"),
    )
    .unwrap();
    std::fs::copy(
        examples().join("scouting/MasterTeam.strategy.xml"),
        dir.join("strategies/MasterTeam.strategy.xml"),
    )
    .unwrap();
    let built = semo_in(
        &dir,
        &[
            "build",
            "scouting.mission",
            "--strategy",
            "strategies",
            "-o",
            "out",
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert!(!built.stdout.contains("E085"), "{}", built.stdout);
    let control =
        std::fs::read_to_string(dir.join("out/MasterTeam/irobot/control_task.c")).unwrap();
    assert!(control.contains("Strategy actions of `move` (MasterTeam.strategy.xml)"));
}

#[test]
fn trace_lines_name_each_key_once() {
    let out = scratch("semantics/trace-keys");
    let scenario =
        std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
            .unwrap();
    let traces = run_in_simulation(
        &examples().join("scouting/scouting.mission"),
        &out,
        &scenario,
    );
    let mut throws = 0;
    for (robot, lines) in &traces {
        for line in lines {
            let keys: Vec<&str> = line
                .split('"')
                .collect::<Vec<_>>()
                .windows(2)
                .filter(|w| w[1].starts_with(':'))
                .map(|w| w[0])
                .collect();
            let mut unique = keys.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), keys.len(), "{robot}: a key repeats in {line}");
            if line.contains("\"event\":\"throw\"") {
                throws += 1;
                assert!(line.contains("\"name\":\"CHANGE_"), "{line}");
            }
        }
    }
    assert!(throws > 0, "the scouting robots throw events");
}

#[test]
fn robots_without_values_and_shared_getters_compile_pedantically() {
    for target in ["linux", "linux-sim"] {
        let out = scratch(&format!("semantics/pedantic-{target}"));
        let built =
            support::robots::build_for(&fixture("no_values_shared_getter.mission"), target, &out);
        assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
        let control = std::fs::read_to_string(out.join("Counter/nxt/control_task.c")).unwrap();
        assert!(control.contains("LIBCALL(shared, CounterShared_get_Counter_TICKS, )"));
        for folder in robot_folders(&out) {
            for cc in compilers() {
                make(&folder, cc, PEDANTIC).unwrap_or_else(|e| panic!("{target}, {cc}: {e}"));
                let _ = std::process::Command::new("make")
                    .args(["-s", "clean"])
                    .current_dir(&folder)
                    .status();
            }
        }
    }
}

#[test]
fn a_request_stopped_before_its_task_fired_does_not_survive_a_mode_change() {
    // The stale request appears only when the mode changes before the task's
    // thread takes the request: a race, so several runs.
    for run in 0..3 {
        let out = scratch(&format!("semantics/stale-request-{run}"));
        let traces = run_in_simulation(&fixture("stale_request.mission"), &out, SHORT_RUN);
        let ev = events(&traces["ev"]);
        let in_m1 = ev
            .iter()
            .position(|e| field(e, "event") == "mode" && field(e, "mode") == "M1")
            .expect("the robot reaches M1");
        let goals: Vec<&str> = ev[in_m1..]
            .iter()
            .filter(|e| field(e, "event") == "call_start")
            .map(|e| field(e, "arg"))
            .collect();
        // A "1,1" already taken by the task may still be traced after the
        // change; what must not happen is the old goal taking the new call's
        // place (the robot never moves to "9,9").
        assert_eq!(
            goals.last(),
            Some(&"9,9"),
            "run {run}: moves started in M1: {goals:?}"
        );
        assert!(goals.len() <= 2, "run {run}: {goals:?}");
    }
}

/// The arguments each `call_start` of `task` gave it, in a trace.
fn arguments_given(trace: &[String], task: &str) -> Vec<String> {
    events(trace)
        .iter()
        .filter(|e| field(e, "event") == "call_start" && field(e, "task") == task)
        .map(|e| field(e, "arg").to_string())
        .collect()
}

/// A strategy's algorithm is given the argument of the call it refines
/// (`search(ROOM2)`), through the action's variable named in `value` and
/// through the catalog's name of the service's parameter: once `"room"` and
/// `""` were passed instead, and `semo check` said nothing.
#[test]
fn a_strategy_algorithm_is_given_the_calls_argument_in_the_simulator_and_in_c() {
    let mission = fixture("strategy_argument/finders.mission");
    let out = scratch("semantics/strategy-argument");
    let scenario = out.join("short.scenario.json");
    std::fs::write(&scenario, SHORT_RUN).unwrap();
    let simulated = support::simulate_trace(&mission, &scenario, "sim");
    assert_eq!(
        simulated.code, 0,
        "{}{}",
        simulated.stdout, simulated.stderr
    );
    let simulated: Vec<String> = simulated.stdout.lines().map(str::to_string).collect();
    assert_eq!(arguments_given(&simulated, "search"), ["ROOM2", "ROOM2"]);
    let traces = run_in_simulation(&mission, &out.join("linux-sim"), SHORT_RUN);
    assert_eq!(arguments_given(&traces["ti"], "search"), ["ROOM2", "ROOM2"]);
}

/// The values a robot sent (`send` events), in order.
fn values_sent(trace: &[String]) -> Vec<String> {
    events(trace)
        .iter()
        .filter(|e| field(e, "event") == "send")
        .map(|e| field(e, "value").to_string())
        .collect()
}

/// `FIRE` is a word and a guard's smoke detector: `semo check` refuses the
/// bare name (E041; once the reading was sent without a word said), and
/// each quick fix the editor offers means what it says, in the simulator
/// and in the generated robot alike: `"FIRE"` sends the word, `Guards.FIRE`
/// the reading.
#[test]
fn each_fix_of_a_word_that_is_also_a_value_builds_and_simulates_as_it_says() {
    use semo::diag::FileId;
    use semo::host::{AnalysisHost, Roots};
    use semo::span::Span;
    use semo::workspace::FileKind;
    let folder = fixture("word_or_value");
    let (code, diags) = support::check_json_in(&folder, &["alarm.mission"]);
    assert_eq!(code, 1);
    let codes: Vec<_> = diags.iter().map(|d| (d.code.as_str(), d.start)).collect();
    assert_eq!(codes, [("E041", (7, 29))]);
    let mission = std::fs::read_to_string(folder.join("alarm.mission")).unwrap();
    let catalog = std::fs::read_to_string(folder.join("firebot.robot.xml")).unwrap();
    // The fixes as the editor gets them: through the workspace analysis.
    let mut host = AnalysisHost::new(Roots {
        roots: vec![folder.clone()],
        seen_by_all: Vec::new(),
    });
    for (id, name, text) in [
        (0, "alarm.mission", &mission),
        (1, "firebot.robot.xml", &catalog),
    ] {
        let path = folder.join(name);
        let kind = FileKind::of(&path).unwrap();
        host.set_file(FileId(id), Some(path), kind, text.as_str().into());
    }
    let at = mission.find("= FIRE").unwrap() + 2;
    let actions = host.analysis().code_actions(FileId(0), Span::new(at, at));
    let offered: Vec<&str> = actions
        .iter()
        .map(|a| a.edits[0].new_text.as_str())
        .collect();
    assert_eq!(offered, ["\"FIRE\"", "Guards.FIRE"]);
    let scenario = r#"{"time_scale": 0.2, "duration": 1400,
        "robots": {"g": {"sensors": [{"at": 0, "value": "FIRE", "is": "smoke"}]}}}"#;
    for (action, meant) in actions.iter().zip(["FIRE", "smoke"]) {
        let edit = &action.edits[0];
        let fixed = format!(
            "{}{}{}",
            &mission[..edit.span.start],
            edit.new_text,
            &mission[edit.span.end..]
        );
        let out = scratch(&format!("semantics/word-or-value-{meant}"));
        std::fs::write(out.join("alarm.mission"), &fixed).unwrap();
        std::fs::write(out.join("firebot.robot.xml"), &catalog).unwrap();
        std::fs::write(out.join("alarm.scenario.json"), scenario).unwrap();
        let simulated = semo_in(
            &out,
            &[
                "simulate",
                "alarm.mission",
                "--scenario",
                "alarm.scenario.json",
                "--trace",
                "simulated.jsonl",
            ],
        );
        assert_eq!(
            simulated.code, 0,
            "{}{}",
            simulated.stdout, simulated.stderr
        );
        let simulated: Vec<String> = std::fs::read_to_string(out.join("simulated.jsonl"))
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect();
        assert_eq!(values_sent(&simulated), [meant; 3], "{}", edit.new_text);
        let traces = run_in_simulation(&out.join("alarm.mission"), &out.join("robots"), scenario);
        assert_eq!(values_sent(&traces["g"]), [meant; 3], "{}", edit.new_text);
    }
}

/// A robot that becomes the leader acts only on the operator's commands
/// sent while it leads (`docs/groups.md`): tb_0 leads and is switched to
/// remote control and back (0.5 s, 1.5 s); killed at 2 s, tb_1 takes over
/// and drops both commands (traced), where it once switched to remote
/// control and back on its own. The same run in C: `tests/differential.rs`.
#[test]
fn a_new_leader_does_not_act_on_commands_sent_before_it_led() {
    let mission = fixture("leader_commands.mission");
    let scenario = fixture("leader_commands.scenario.json");
    let simulated = support::simulate_trace(&mission, &scenario, "sim");
    assert_eq!(
        simulated.code, 0,
        "{}{}",
        simulated.stdout, simulated.stderr
    );
    let lines: Vec<String> = simulated.stdout.lines().map(str::to_string).collect();
    let all = events(&lines);
    let of = |robot: &str| -> Vec<Event> {
        all.iter()
            .filter(|e| field(e, "robot") == robot)
            .cloned()
            .collect()
    };
    let (tb_0, tb_1) = (of("tb_0"), of("tb_1"));
    assert_eq!(modes(&tb_0), ["AUTO_MODE", "RC_MODE", "AUTO_MODE"]);
    let leaders: Vec<&str> = tb_1
        .iter()
        .filter(|e| field(e, "event") == "leader")
        .map(|e| field(e, "leader"))
        .collect();
    assert_eq!(leaders, ["tb_0", "tb_1"], "tb_1 takes over");
    assert_eq!(modes(&tb_1), ["AUTO_MODE"], "no stale command acted on");
    let dropped: Vec<(&str, &str)> = tb_1
        .iter()
        .filter(|e| field(e, "event") == "drop")
        .map(|e| (field(e, "key"), field(e, "reason")))
        .collect();
    let before = ("USER.RC_CMD", semo::refine::protocol::UNLED_REASON);
    assert_eq!(dropped, [before, before]);
}
