//! Board robots in lock-step (issue 35 with "One exact meaning"): `semo
//! simulate --engine c --boards` builds each robot for its own platform's
//! simulation (the build plan of `semo build --sim`), runs a board robot's
//! firmware (`make LOCKSTEP=1`) in QEMU with its link's serial port
//! connected to the coordinator (`semo_static_lockstep.c`) and the others as
//! `linux-sim` processes, all in one virtual time; the trace must be the
//! simulator's event for event, as `tests/differential.rs` asks of
//! `linux-sim` (per robot and instant, no tolerance), faults included: a
//! board killed and restarted is its QEMU stopped and started again.
//!
//! Nothing here reads a clock: the coordinator grants every robot its time,
//! so a loaded machine changes only how long a test takes.
//!
//! Skipped with a message without arm-none-eabi-gcc or qemu-system-arm,
//! unless `SEMO_CORTEX_M_TESTS=require` (CI), where a missing tool fails.

mod support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use support::differential::{Event, by_robot, field, parse_trace, robots_of, run_differences};
use support::{examples, repo_root, robots};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("board_lockstep")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What a run of `semo simulate` gave: its summary (standard output) and
/// its trace.
struct Run {
    summary: String,
    events: Vec<Event>,
}

/// `semo simulate MISSION --scenario SCENARIO ARGS --trace FILE`, the run
/// of the simulator (no `ARGS`) or of the generated programs.
fn simulate(mission: &Path, scenario: &Path, args: &[&str], work: &Path) -> Run {
    let trace = work.join(format!("{}.jsonl", args.len()));
    let (mission, scenario, trace_arg) = (
        mission.display().to_string(),
        scenario.display().to_string(),
        trace.display().to_string(),
    );
    let mut all = vec![
        "simulate",
        &mission,
        "--scenario",
        &scenario,
        "--trace",
        &trace_arg,
    ];
    all.extend(args);
    let out = support::semo_in(&repo_root(), &all);
    assert!(out.code <= 1, "{args:?}: {}{}", out.stdout, out.stderr);
    Run {
        summary: out.stdout,
        events: parse_trace(&std::fs::read_to_string(&trace).unwrap()),
    }
}

/// Runs `mission` on `scenario` in the simulator and with its board robots
/// in QEMU, asserts the traces are the same event for event, and returns
/// the lock-step run.
fn compare(name: &str, mission: &Path, scenario: &Path) -> Run {
    let work = scratch(name);
    let reference = simulate(mission, scenario, &[], &work);
    let boards = simulate(mission, scenario, &["--engine", "c", "--boards"], &work);
    let problems = run_differences(&by_robot(boards.events.clone()), &reference.events);
    assert!(problems.is_empty(), "{name}:\n{}", problems.join("\n"));
    eprintln!(
        "{name}: {} events the same with the boards in QEMU and in the simulator",
        reference.events.len()
    );
    boards
}

/// The summary says `robot` ran on `board` in QEMU (not as a Linux process).
fn ran_on(run: &Run, robot: &str, target: &str, machine: &str) {
    let said = format!("qemu-system-arm {machine})");
    assert!(
        run.summary.lines().any(|l| {
            l.trim_start().starts_with(&format!("{robot}: "))
                && l.contains(&format!("({target}, "))
                && l.ends_with(&said)
        }),
        "{robot} did not run on {target} in QEMU:\n{}",
        run.summary
    );
}

fn scenario_file(work: &Path, text: &str) -> PathBuf {
    let path = work.join("scenario.json");
    std::fs::write(&path, text).unwrap();
    path
}

/// The scouting fixture's scenario with `faults`.
fn scouting_scenario(work: &Path, faults: &str) -> PathBuf {
    let text =
        std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
            .unwrap();
    let mut scenario: serde_json::Value = serde_json::from_str(&text).unwrap();
    scenario["faults"] = serde_json::from_str(faults).unwrap();
    scenario_file(work, &scenario.to_string())
}

/// The scouting mission as the methodology describes it: the TI Evalbot
/// (`ti`, its catalog platform `cortex-m`) on the LM3S6965 in QEMU, the
/// iRobot and the NXT as `linux-sim` processes.
#[test]
fn scouting_with_the_evalbot_in_qemu_behaves_as_in_the_simulator() {
    if !robots::board_tools_present("scouting_with_the_evalbot_in_qemu_behaves_as_in_the_simulator")
    {
        return;
    }
    let work = scratch("scouting-scenario");
    let run = compare(
        "scouting",
        &examples().join("scouting/scouting.mission"),
        &scouting_scenario(&work, "[]"),
    );
    ran_on(&run, "ti", "cortex-m-sim", "lm3s6965evb");
    for linux in ["irobot", "nxt"] {
        let line = run
            .summary
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{linux}: ")));
        assert!(
            line.is_some_and(|l| !l.contains("qemu")),
            "{linux} is a Linux robot:
{}",
            run.summary
        );
    }
    let modes: Vec<&str> = run
        .events
        .iter()
        .filter(|e| field(e, "robot") == "ti" && field(e, "event") == "mode")
        .map(|e| field(e, "mode"))
        .collect();
    assert_eq!(modes, ["AUTO_MODE", "SEARCH_MODE", "RETURN_MODE", "FINISH"]);
}

/// The Evalbot killed in the middle of its search and restarted (its QEMU
/// stopped and started again): the same trace as the simulator's, the
/// restarted robot starting over.
#[test]
fn the_evalbot_killed_and_restarted_in_qemu_behaves_as_in_the_simulator() {
    if !robots::board_tools_present(
        "the_evalbot_killed_and_restarted_in_qemu_behaves_as_in_the_simulator",
    ) {
        return;
    }
    let work = scratch("scouting-restart-scenario");
    let run = compare(
        "scouting-restart",
        &examples().join("scouting/scouting.mission"),
        &scouting_scenario(
            &work,
            r#"[{"at": 1700, "kill": "ti"}, {"at": 2600, "restart": "ti"}]"#,
        ),
    );
    ran_on(&run, "ti", "cortex-m-sim", "lm3s6965evb");
    let ti: Vec<(i64, &str)> = run
        .events
        .iter()
        .filter(|e| field(e, "robot") == "ti" && matches!(field(e, "event"), "start" | "fault"))
        .map(|e| (e["t"].as_i64().unwrap(), field(e, "event")))
        .collect();
    assert_eq!(
        ti,
        [
            (0, "start"),
            (1700, "fault"),
            (2600, "fault"),
            (2600, "start")
        ]
    );
}

/// Each live robot's leader at every instant of the trace (its latest
/// `leader` event since it last started).
fn leaders(events: &[Event]) -> BTreeMap<i64, BTreeMap<String, String>> {
    let mut now: BTreeMap<String, String> = BTreeMap::new();
    let mut at: BTreeMap<i64, BTreeMap<String, String>> = BTreeMap::new();
    for e in events {
        let robot = field(e, "robot").to_string();
        match field(e, "event") {
            "leader" => {
                now.insert(robot, field(e, "leader").to_string());
            }
            "start" | "fault" | "stop" => {
                now.remove(&robot);
            }
            _ => continue,
        }
        at.insert(e["t"].as_i64().unwrap(), now.clone());
    }
    at
}

/// One crew with one robot per board kind (`tests/fixtures/board_election`:
/// `lm` on the LM3S6965, `st` on the STM32F405, `lx` on Linux) elects `lm`
/// (`lowest_id`); `lm`'s QEMU is killed and `st` takes over; then `lm`
/// comes back. The same trace as the simulator's, and never two robots that
/// each believe they lead.
#[test]
fn a_leader_on_a_board_fails_over_the_same_way_in_qemu_and_in_the_simulator() {
    if !robots::board_tools_present(
        "a_leader_on_a_board_fails_over_the_same_way_in_qemu_and_in_the_simulator",
    ) {
        return;
    }
    let fixture = repo_root().join("tests/fixtures/board_election");
    let work = scratch("election-scenario");
    let text = std::fs::read_to_string(fixture.join("election.scenario.json")).unwrap();
    let mut scenario: serde_json::Value = serde_json::from_str(&text).unwrap();
    scenario["faults"] =
        serde_json::json!([{"at": 2000, "kill": "lm"}, {"at": 3500, "restart": "lm"}]);
    let run = compare(
        "election",
        &fixture.join("election.mission"),
        &scenario_file(&work, &scenario.to_string()),
    );
    ran_on(&run, "lm", "cortex-m-sim", "lm3s6965evb");
    ran_on(&run, "st", "stm32f4-sim", "netduinoplus2");
    let followed = |robot: &str| -> Vec<String> {
        let mut seen: Vec<String> = run
            .events
            .iter()
            .filter(|e| field(e, "robot") == robot && field(e, "event") == "leader")
            .map(|e| field(e, "leader").to_string())
            .collect();
        seen.dedup();
        seen
    };
    assert_eq!(followed("st"), ["lm", "st", "lm"]);
    assert_eq!(followed("lx"), ["lm", "st", "lm"]);
    for (t, believed) in leaders(&run.events) {
        let leading: Vec<&String> = believed
            .iter()
            .filter(|(r, l)| r == l)
            .map(|(r, _)| r)
            .collect();
        assert!(leading.len() <= 1, "at {t} ms {leading:?} each lead");
    }
}

/// Random valid missions (`support/missiongen.rs`) with every robot on a
/// board (the project file's `[build] target`, the LM3S6965 and the
/// STM32F405 in turn), on random scenarios without link faults (the
/// linux-sim runtime applies those; a board refuses them) and without a
/// network of no latency: the same exact comparison.
#[test]
fn random_missions_on_boards_behave_as_in_the_simulator() {
    if !robots::board_tools_present("random_missions_on_boards_behave_as_in_the_simulator") {
        return;
    }
    let catalog = semo::catalog::builtin_catalog();
    let mut problems = Vec::new();
    for seed in 0..24u64 {
        let dir = scratch(&format!("random-{seed}"));
        let target = if seed % 2 == 0 { "cortex-m" } else { "stm32f4" };
        std::fs::write(
            dir.join("semo.toml"),
            format!("[project]\nversion = 1\nname = \"random{seed}\"\n\n[build]\ntarget = \"{target}\"\n"),
        )
        .unwrap();
        let mission = dir.join(format!("random{seed}.mission"));
        std::fs::write(&mission, support::missiongen::mission(seed, &catalog)).unwrap();
        let robots = robots_of(&dir.join("robots"), &mission);
        let text = support::missiongen::scenario(seed, &robots, 2000, 0.2);
        let mut scenario: serde_json::Value = serde_json::from_str(&text).unwrap();
        if let Some(faults) = scenario["faults"].as_array_mut() {
            faults.retain(|f| f.get("from").is_none());
        }
        // Nor a network of no latency, which boards refuse in lock-step
        // (`a_board_with_a_link_of_no_latency_is_refused`).
        if let Some(network) = scenario.get_mut("network").and_then(|n| n.as_object_mut()) {
            network.remove("latency");
            if network.is_empty() {
                scenario.as_object_mut().unwrap().remove("network");
            }
        }
        let scenario = scenario_file(&dir, &scenario.to_string());
        let reference = simulate(&mission, &scenario, &[], &dir);
        let boards = simulate(&mission, &scenario, &["--engine", "c", "--boards"], &dir);
        for robot in &robots {
            assert!(
                boards
                    .summary
                    .lines()
                    .any(|l| l.trim_start().starts_with(&format!("{robot}: "))
                        && l.contains("qemu-system-arm")),
                "seed {seed}: {robot} did not run in QEMU:\n{}",
                boards.summary
            );
        }
        for problem in run_differences(&by_robot(boards.events), &reference.events) {
            problems.push(format!("seed {seed}: {problem}"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// `--boards` is a way of running the generated programs: with the
/// simulator it is refused, clearly.
/// A board takes messages only between its steps, so a message of no
/// latency that reaches it before its first step would be taken after it,
/// where the simulator's robot (and a linux-sim one) takes it within the
/// step: `--boards` refuses such a network before it builds anything, so
/// the board tools are not needed to see it.
#[test]
fn a_board_with_a_link_of_no_latency_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("no_latency.json");
    for (network, peer) in [
        (r#"{"latency": 0}"#, "irobot"),
        (
            r#"{"latency": 0, "links": [{"between": ["ti", "irobot"], "latency": 5}]}"#,
            "nxt",
        ),
        (
            r#"{"links": [{"between": ["nxt", "ti"], "latency": 0}]}"#,
            "nxt",
        ),
    ] {
        std::fs::write(
            &scenario,
            format!(r#"{{"duration": 1000, "network": {network}}}"#),
        )
        .unwrap();
        let out = support::semo_in(
            &repo_root(),
            &[
                "simulate",
                "examples/scouting/scouting.mission",
                "--scenario",
                scenario.to_str().unwrap(),
                "--engine",
                "c",
                "--boards",
            ],
        );
        assert_eq!(out.code, 2, "{network}: {}{}", out.stdout, out.stderr);
        assert!(
            out.stderr
                .contains("robot ti runs on the TI Stellaris LM3S6965")
                && out.stderr.contains(&format!("here to {peer}:")),
            "{network}: {}",
            out.stderr
        );
    }
}

#[test]
fn boards_without_the_generated_programs_is_refused() {
    let out = support::semo_in(
        &repo_root(),
        &[
            "simulate",
            "examples/scouting/scouting.mission",
            "--scenario",
            "tests/fixtures/build/scouting.scenario.json",
            "--boards",
        ],
    );
    assert_eq!(out.code, 2, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("--boards") && out.stderr.contains("--engine c"),
        "{}",
        out.stderr
    );
}
