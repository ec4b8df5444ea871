//! `semo build` as a user runs it: the reference missions become C programs
//! that compile cleanly with gcc and clang, and the scouting mission, built for
//! the simulated platform, runs as three processes whose traces show the
//! expected modes, also under AddressSanitizer/UBSan and ThreadSanitizer.

mod support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use support::robots::{make, robot_command, robot_folders};
use support::{examples, repo_root, semo_in};

const STRICT: &str = "-std=c11 -Wall -Wextra -Wpedantic -Werror -O1 -g";

/// A fresh folder under cargo's scratch space for tests.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("build")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn build(mission: &Path, target: &str, out: &Path) -> support::Output {
    let out_arg = out.display().to_string();
    let mission_arg = mission.display().to_string();
    semo_in(
        &repo_root(),
        &["build", &mission_arg, "--target", target, "-o", &out_arg],
    )
}

/// `semo build MISSION --target TARGET --scenario SCENARIO -o OUT`.
fn build_sim(mission: &Path, target: &str, scenario: &Path, out: &Path) -> support::Output {
    support::robots::build_sim(mission, target, scenario, out)
}

/// [`support::robots::build_for`].
fn build_for(mission: &Path, target: &str, out: &Path) -> support::Output {
    support::robots::build_for(mission, target, out)
}

fn example(path: &str) -> PathBuf {
    examples().join(path)
}

/// Every mission file under `dir`, sorted.
fn missions_under(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "mission") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn every_example_and_fixture_that_builds_compiles_pedantically_with_gcc_and_clang() {
    // Examples must build; fixtures that `semo build` refuses are there to
    // be refused (their codes are checked elsewhere).
    let root = repo_root();
    let examples = missions_under(&examples());
    let fixtures = missions_under(&root.join("tests/fixtures"));
    assert!(examples.len() >= 5, "the reference missions are there");
    let mut outputs = Vec::new();
    for (mission, must_build) in examples
        .iter()
        .map(|m| (m, true))
        .chain(fixtures.iter().map(|m| (m, false)))
    {
        let name = mission
            .strip_prefix(&root)
            .unwrap_or(mission)
            .display()
            .to_string();
        for target in ["linux", "linux-sim"] {
            let out = scratch(&format!("compile-{}-{target}", name.replace('/', "-")));
            let built = build_for(mission, target, &out);
            if built.code != 0 {
                assert!(
                    !must_build,
                    "{name} ({target}): {}{}",
                    built.stdout, built.stderr
                );
                continue;
            }
            outputs.push((name.clone(), target, out));
        }
    }
    assert!(
        outputs.len() > 2 * examples.len(),
        "fixture missions that build are compiled too"
    );
    support::cc::compile_all(&scratch("compile-pool"), &outputs, &["linux", "linux-sim"]);
}

/// One line of a trace.
type Event = serde_json::Map<String, serde_json::Value>;

/// Builds the scouting mission for the simulation with `cflags`, starts its
/// three robots as processes and returns each robot's trace and stderr.
fn run_scouting(
    name: &str,
    port_offset: u32,
    cc: &str,
    cflags: &str,
    env: &[(&str, &str)],
) -> BTreeMap<String, (Vec<Event>, String)> {
    let out = scratch(name);
    let scenario = repo_root().join("tests/fixtures/build/scouting.scenario.json");
    let built = build_sim(
        &example("scouting/scouting.mission"),
        "linux-sim",
        &scenario,
        &out,
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    // Each run gets its own ports, so runs in parallel do not hear each other.
    // Below the ephemeral range (32768 and up), where other sockets come and go.
    let port_base = 20000 + (std::process::id() % 250) * 40 + port_offset;
    let folders = robot_folders(&out);
    // Build every robot before starting any: they must start together.
    for folder in &folders {
        make(folder, cc, cflags).unwrap_or_else(|e| panic!("{e}"));
    }
    let mut children = Vec::new();
    for folder in folders {
        let robot = folder.file_name().unwrap().to_string_lossy().into_owned();
        let trace = out.join(format!("{robot}.jsonl"));
        let child = Command::new(folder.join(&robot))
            .args(["--trace", &trace.display().to_string()])
            .args(["--port-base", &port_base.to_string()])
            .envs(env.iter().copied())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("the robot program starts");
        children.push((robot, trace, child));
    }
    let mut result = BTreeMap::new();
    for (robot, trace, child) in children {
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        assert!(
            output.status.success(),
            "{robot} exited with {:?}: {stderr}",
            output.status
        );
        let text = std::fs::read_to_string(&trace).unwrap_or_default();
        let events = text
            .lines()
            .map(|l| {
                serde_json::from_str(l)
                    .unwrap_or_else(|e| panic!("{robot}: bad trace line {l}: {e}"))
            })
            .collect();
        result.insert(robot, (events, stderr));
    }
    result
}

fn field<'e>(event: &'e Event, key: &str) -> &'e str {
    event.get(key).and_then(|v| v.as_str()).unwrap_or("")
}

fn modes(events: &[Event]) -> Vec<&str> {
    events
        .iter()
        .filter(|e| field(e, "event") == "mode")
        .map(|e| field(e, "mode"))
        .collect()
}

fn assert_scouting_behaviour(runs: &BTreeMap<String, (Vec<Event>, String)>) {
    let master = ["AUTO_MODE", "WAIT_MODE", "RETURN_MODE", "FINISH"];
    let slave = ["AUTO_MODE", "SEARCH_MODE", "RETURN_MODE", "FINISH"];
    assert_eq!(runs.len(), 3, "three robots");
    for (robot, (events, _)) in runs {
        let expected: &[&str] = if robot == "irobot" { &master } else { &slave };
        assert_eq!(modes(events), expected, "{robot}'s modes");
        assert!(
            events.iter().any(|e| field(e, "event") == "finish"),
            "{robot} reaches its end"
        );
    }
    // The master hears the colors of both slaves.
    let (master_events, _) = &runs["irobot"];
    for slave in ["ti", "nxt"] {
        let heard = master_events.iter().any(|e| {
            field(e, "event") == "receive"
                && field(e, "key") == "SlaveTeam.COLOR"
                && field(e, "from_robot") == slave
        });
        assert!(heard, "the master receives SlaveTeam.COLOR from {slave}");
    }
    // The slaves report the colors they found, up to the complete set.
    let (ti, _) = &runs["ti"];
    assert!(ti.iter().any(|e| field(e, "event") == "send"
        && field(e, "key") == "SlaveTeam.COLOR"
        && field(e, "value") == "RGB"));
    // The master leaves WAIT_MODE because of the operator's command.
    assert!(
        master_events
            .iter()
            .any(|e| field(e, "event") == "receive" && field(e, "value") == "RETURN_MODE")
    );
}

#[test]
fn scouting_runs_in_simulation_with_the_expected_modes() {
    let runs = run_scouting("sim", 0, "gcc", STRICT, &[]);
    assert_scouting_behaviour(&runs);
}

#[test]
fn scouting_runs_clean_under_address_and_undefined_behaviour_sanitizers() {
    let flags = format!(
        "{STRICT} -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all"
    );
    let runs = run_scouting(
        "asan",
        20,
        "gcc",
        &flags,
        &[
            ("ASAN_OPTIONS", "detect_leaks=1:abort_on_error=1"),
            ("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1"),
        ],
    );
    for (robot, (_, stderr)) in &runs {
        assert!(
            stderr.trim().is_empty(),
            "{robot}: sanitizer report:\n{stderr}"
        );
    }
    assert_scouting_behaviour(&runs);
}

#[test]
fn scouting_runs_clean_under_thread_sanitizer() {
    let flags = format!("{STRICT} -fsanitize=thread");
    let runs = run_scouting(
        "tsan",
        10,
        "gcc",
        &flags,
        &[("TSAN_OPTIONS", "halt_on_error=1")],
    );
    for (robot, (_, stderr)) in &runs {
        assert!(
            stderr.trim().is_empty(),
            "{robot}: ThreadSanitizer report:\n{stderr}"
        );
    }
    assert_scouting_behaviour(&runs);
}

#[test]
fn a_failed_leader_is_replaced_by_the_next_robot() {
    // patrol_groups: `leader(instance of Turtlebot3_Burger)` among tb_0..tb_2.
    let out = scratch("leader");
    let scenario = out.join("scenario.json");
    std::fs::write(&scenario, r#"{"time_scale": 1, "duration": 3500}"#).unwrap();
    let built = build_sim(
        &example("swarm/patrol_groups.mission"),
        "linux-sim",
        &scenario,
        &out.join("out"),
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let folders = robot_folders(&out.join("out"));
    for folder in &folders {
        make(folder, "gcc", STRICT).unwrap_or_else(|e| panic!("{e}"));
    }
    let port_base = 20000 + (std::process::id() % 250) * 40 + 30;
    let mut children = BTreeMap::new();
    for folder in &folders {
        let robot = folder.file_name().unwrap().to_string_lossy().into_owned();
        let trace = out.join(format!("{robot}.jsonl"));
        let child = robot_command(folder, &trace, port_base)
            .spawn()
            .expect("the robot program starts");
        children.insert(robot, child);
    }
    // The first leader fails (killed, without a word) after a while.
    std::thread::sleep(std::time::Duration::from_millis(1200));
    children.get_mut("tb_0").unwrap().kill().unwrap();
    for (robot, mut child) in children {
        let status = child.wait().unwrap();
        assert!(robot == "tb_0" || status.success(), "{robot}: {status:?}");
    }
    let trace = |robot: &str| -> Vec<Event> {
        std::fs::read_to_string(out.join(format!("{robot}.jsonl")))
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let leaders = |events: &[Event]| -> Vec<String> {
        events
            .iter()
            .filter(|e| field(e, "event") == "leader")
            .map(|e| field(e, "leader").to_string())
            .collect()
    };
    let tb_1 = trace("tb_1");
    assert_eq!(
        leaders(&tb_1),
        ["tb_0", "tb_1"],
        "tb_1 sees tb_0 fail and takes over"
    );
    assert_eq!(leaders(&trace("tb_2")), ["tb_0", "tb_1"]);
    let took_over = tb_1
        .iter()
        .find(|e| field(e, "event") == "leader" && field(e, "leader") == "tb_1")
        .and_then(|e| e["t"].as_i64())
        .unwrap();
    let lights_after = tb_1
        .iter()
        .filter(|e| field(e, "event") == "call_start" && field(e, "service") == "light_on")
        .filter(|e| e["t"].as_i64().unwrap() >= took_over)
        .count();
    assert!(lights_after >= 1, "the new leader runs the leader's block");
    let tb_2_lights = trace("tb_2")
        .iter()
        .filter(|e| field(e, "event") == "call_start" && field(e, "service") == "light_on")
        .count();
    assert_eq!(tb_2_lights, 0, "only the leader runs it");
    // Robots of another type never take part.
    assert!(leaders(&trace("ev_0")).is_empty());
}

/// Every file under a folder with its bytes.
fn contents(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[test]
fn output_is_byte_identical_for_identical_inputs() {
    let a = scratch("same-a");
    let b = scratch("same-b");
    for target in ["linux", "linux-sim"] {
        assert_eq!(
            build_for(&example("scouting/scouting.mission"), target, &a).code,
            0
        );
        assert_eq!(
            build_for(&example("scouting/scouting.mission"), target, &b).code,
            0
        );
        let (left, right) = (contents(&a), contents(&b));
        assert!(left.len() > 40, "{target}: {} files", left.len());
        assert_eq!(left, right, "{target}");
    }
}

#[test]
fn task_files_the_user_filled_are_never_overwritten() {
    let out = scratch("user-files");
    let mission = example("follow/follow.mission");
    assert_eq!(build(&mission, "linux", &out).code, 0);
    let folder = out.join("Team1/create1");
    let task = folder.join("tasks/follow.c");
    assert!(task.exists(), "the follow task template is created");
    let mine = "/* my follow algorithm */\n#include \"../program.h\"\nTASK_INIT {}\nTASK_GO {}\nTASK_WRAPUP {}\n";
    std::fs::write(&task, mine).unwrap();
    std::fs::write(folder.join("NOTES.txt"), "my notes").unwrap();
    let again = build(&mission, "linux", &out);
    assert_eq!(again.code, 0, "{}", again.stderr);
    assert!(again.stdout.contains("kept"), "{}", again.stdout);
    assert_eq!(std::fs::read_to_string(&task).unwrap(), mine);
    assert_eq!(
        std::fs::read_to_string(folder.join("NOTES.txt")).unwrap(),
        "my notes"
    );
    // The user's own task code still builds with the rest. (A generated
    // file edited by hand stops generation: tests/generation.rs.)
    make(&folder, "gcc", STRICT).unwrap();
}

/// Line 3 of the header of each C file semo writes for the robot (not the
/// runtime's), with the manifest's owner of the file (`generated` or
/// `template`).
fn header_promises(folder: &Path) -> BTreeMap<String, (String, String)> {
    let manifest = std::fs::read_to_string(folder.join(".semo-manifest")).unwrap();
    manifest
        .lines()
        .skip(1)
        .filter_map(|line| {
            let mut fields = line.split(' ');
            let (owner, _hash, path) = (fields.next()?, fields.next()?, fields.next()?);
            let text = std::fs::read_to_string(folder.join(path)).unwrap();
            let mut lines = text.lines();
            let (first, third) = (lines.next()?, lines.nth(1)?);
            first.contains(" by semo for robot ").then(|| {
                let promise = (owner.to_string(), third.to_string());
                (path.to_string(), promise)
            })
        })
        .collect()
}

#[test]
fn each_file_header_says_what_the_next_build_does_to_it() {
    let mission = example("follow/follow.mission");
    for target in ["linux", "linux-sim"] {
        let out = scratch(&format!("headers-{target}"));
        let built = build_for(&mission, target, &out);
        assert_eq!(built.code, 0, "{}", built.stderr);
        let promises = header_promises(&out.join("Team1/create1"));
        assert!(promises.contains_key("tasks/follow.c"), "{promises:?}");
        for (path, (owner, promise)) in &promises {
            let regenerated = promise.contains("Regenerated by `semo build`");
            let kept = promise.contains("Yours to fill: later builds for this target keep it");
            match owner.as_str() {
                "generated" => assert!(regenerated && !kept, "{target} {path}: {promise}"),
                "template" => assert!(kept && !regenerated, "{target} {path}: {promise}"),
                other => panic!("{target} {path}: owner {other}"),
            }
        }
        // The user's task files are templates only where the user fills them.
        let follow = &promises["tasks/follow.c"].0;
        let expected = if target == "linux" {
            "template"
        } else {
            "generated"
        };
        assert_eq!(follow, expected, "{target}");
    }
}

#[test]
fn generation_is_refused_while_the_mission_has_errors() {
    let dir = scratch("refused");
    let mission = dir.join("broken.mission");
    std::fs::write(
        &mission,
        "{ T: iRobotCreate r }\nT.A.S{ fly() }\nT.M{ set(A, S) }\nT.main{ default: mode = M }\n",
    )
    .unwrap();
    let out = dir.join("out");
    let built = build(&mission, "linux", &out);
    assert_eq!(built.code, 1, "{}", built.stderr);
    assert!(built.stderr.contains("refused"), "{}", built.stderr);
    assert!(!out.exists(), "nothing is written");
}

#[test]
fn every_build_fixture_gives_its_code() {
    let root = repo_root().join("tests/fixtures/build");
    let mut seen = 0;
    for entry in std::fs::read_dir(&root).unwrap() {
        let dir = entry.unwrap().path();
        if !dir.is_dir() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let code = &name[..4];
        let mission = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "mission"))
            .expect("a fixture holds a mission");
        // A fixture for another target names it in a file `target`.
        let target = std::fs::read_to_string(dir.join("target"))
            .map(|t| t.trim().to_string())
            .unwrap_or_else(|_| "linux".to_string());
        let out = scratch(&format!("fixture-{name}"));
        // A deployment fixture (E120–E123) holds the `*.deploy.toml` it is about.
        let deploy = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.to_string_lossy().ends_with(".deploy.toml"));
        let built = match &deploy {
            None => build(&mission, &target, &out),
            Some(deploy) => semo_in(
                &repo_root(),
                &[
                    "build",
                    &mission.display().to_string(),
                    "--target",
                    &target,
                    "-o",
                    &out.display().to_string(),
                    "--deploy",
                    &deploy.display().to_string(),
                ],
            ),
        };
        assert_eq!(built.code, 1, "{name}: {}", built.stderr);
        assert!(
            built.stderr.contains(&format!("[{code}]")),
            "{name}: {}",
            built.stderr
        );
        assert!(robot_folders(&out).is_empty(), "{name}: nothing is written");
        seen += 1;
    }
    assert!(seen >= 2);
}

#[test]
fn refined_task_graphs_are_written_and_analyse_clean() {
    let out = scratch("taskgraphs");
    let built = semo_in(
        &repo_root(),
        &[
            "build",
            &example("scouting/scouting.mission").display().to_string(),
            "--emit",
            "taskgraph",
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(built.code, 0, "{}", built.stderr);
    for folder in robot_folders(&out) {
        let names: Vec<_> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n != ".semo-manifest")
            .collect();
        assert_eq!(names, ["taskgraph.xml"], "only the task graph");
        let graph = folder.join("taskgraph.xml").display().to_string();
        let analyzed = semo_in(
            &repo_root(),
            &["graph", "analyze", &graph, "--format", "json"],
        );
        assert_eq!(analyzed.code, 0, "{graph}: {}", analyzed.stdout);
        let report: serde_json::Value = serde_json::from_str(&analyzed.stdout).unwrap();
        assert_eq!(
            report["diagnostics"].as_array().map(Vec::len),
            Some(0),
            "{graph}: {report}"
        );
        let svg = semo_in(&repo_root(), &["graph", "svg", &graph]);
        assert!(svg.stdout.contains("ControlTask"), "{graph}");
    }
}

#[test]
fn strategy_files_elsewhere_are_read_with_strategy() {
    // The mission alone in one folder, its strategy in another.
    let dir = scratch("strategy-option");
    std::fs::create_dir_all(dir.join("mission")).unwrap();
    std::fs::create_dir_all(dir.join("strategies")).unwrap();
    std::fs::copy(
        example("scouting/scouting.mission"),
        dir.join("mission/scouting.mission"),
    )
    .unwrap();
    std::fs::copy(
        example("scouting/MasterTeam.strategy.xml"),
        dir.join("strategies/MasterTeam.strategy.xml"),
    )
    .unwrap();
    let mission = dir.join("mission/scouting.mission");
    let control =
        |out: &Path| std::fs::read_to_string(out.join("MasterTeam/irobot/control_task.c")).unwrap();
    let without = dir.join("without");
    assert_eq!(build(&mission, "linux", &without).code, 0);
    assert!(
        !control(&without).contains("Strategy actions"),
        "no strategy found beside the mission"
    );
    let with = dir.join("with");
    let built = semo_in(
        &repo_root(),
        &[
            "build",
            &mission.display().to_string(),
            "--strategy",
            &dir.join("strategies").display().to_string(),
            "-o",
            &with.display().to_string(),
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert!(control(&with).contains("Strategy actions of `move` (MasterTeam.strategy.xml)"));
}

#[test]
fn a_mission_that_cannot_be_read_is_an_io_error() {
    let out = scratch("missing-mission");
    let built = build(&out.join("nowhere.mission"), "linux", &out.join("out"));
    assert_eq!(built.code, 2);
    assert!(built.stderr.contains("nowhere.mission"), "{}", built.stderr);
}

#[test]
fn unknown_targets_are_a_usage_error() {
    let out = semo_in(&repo_root(), &["build", "x.mission", "--target", "amiga"]);
    assert_eq!(out.code, 2);
    assert!(out.stderr.contains("linux-sim"), "{}", out.stderr);
}

/// CommReceive reads a received value as its key's declared type: a word
/// of the key's enumeration is taken, and a word of another enumeration of
/// the same program, an unknown word or a number are refused with a
/// `reject` line (as the simulator refuses them).
#[test]
fn a_received_word_of_another_enumeration_is_refused() {
    let out = scratch("enum-receive");
    let fixture = repo_root().join("tests/fixtures/receive");
    let mut scenario: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(fixture.join("relay.scenario.json")).unwrap(),
    )
    .unwrap();
    // Real time, long enough to hear the datagrams sent once it runs.
    scenario["time_scale"] = 1.into();
    scenario["duration"] = 4000.into();
    let scenario_path = out.join("relay.scenario.json");
    std::fs::write(&scenario_path, scenario.to_string()).unwrap();
    let built = build_sim(
        &fixture.join("relay.mission"),
        "linux-sim",
        &scenario_path,
        &out.join("out"),
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let placer = robot_folders(&out.join("out"))
        .into_iter()
        .find(|f| f.ends_with("q"))
        .expect("the placer is built");
    make(&placer, "cc", STRICT).unwrap_or_else(|e| panic!("{e}"));
    let port_base = 21000 + (std::process::id() % 250) * 40;
    let trace = out.join("q.jsonl");
    let mut child = robot_command(&placer, &trace, port_base as u32)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the placer starts");
    // Its port is open once it traces its first mode.
    while !std::fs::read_to_string(&trace).is_ok_and(|t| t.contains("\"mode\"")) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the placer ended early"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let values = [
        semo::refine::Value::text("ON"),     // LAMP's, not BRICK's
        semo::refine::Value::text("PURPLE"), // no enumeration's
        semo::refine::Value::Int(3),         // not a word
        semo::refine::Value::text("RED"),    // BRICK's: taken
    ];
    for value in values {
        let datagram = semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: false,
            team: "Pickers".into(),
            robot: "p".into(),
            key: "Pickers.BRICK".into(),
            value: Some(value),
        });
        // The placer owns one of the two robots' ports; the other is closed.
        for port in [port_base, port_base + 1] {
            socket
                .send_to(&datagram, ("127.0.0.1", port as u16))
                .unwrap();
        }
    }
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success(), "{output:?}");
    let events: Vec<Event> = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let rejected = events
        .iter()
        .filter(|e| field(e, "event") == "reject" && field(e, "key") == "Pickers.BRICK")
        .count();
    assert_eq!(rejected, 3, "{events:#?}");
    // RED was taken: with the lamp on, the placer moves.
    assert!(
        events
            .iter()
            .any(|e| field(e, "event") == "call_start" && field(e, "service") == "move"),
        "{events:#?}"
    );
}

/// `semo build` prints every warning `semo check` gives for the mission (one
/// source: the host's diagnostics with the mission's dataflow and
/// refinement's warnings), in a JSON document and for people, and still
/// builds: W130 (a battery policy naming no task, found by refinement) and a
/// dataflow warning (W072).
#[test]
fn build_prints_every_warning_check_gives() {
    let fixtures = repo_root().join("tests/fixtures/diagnostics");
    for (fixture, mission, code) in [
        (
            "W130_battery_policy_names_no_task",
            "scouts.mission",
            "W130",
        ),
        ("W072_dataflow_buffer_too_small", "scan.mission", "W072"),
    ] {
        let dir = fixtures.join(fixture);
        let mission = dir.join(mission).display().to_string();
        let (checked, from_check) = support::check_json_in(&dir, &[&mission]);
        assert_eq!(checked, 0, "{fixture}: it has warnings only");
        assert!(
            from_check.iter().any(|d| d.code == code),
            "{fixture}: {}",
            support::listing(&from_check)
        );
        let out = scratch(&format!("warnings-{code}"));
        let out_arg = out.display().to_string();
        let json = semo_in(
            &dir,
            &["build", &mission, "--format", "json", "-o", &out_arg],
        );
        assert_eq!(json.code, 0, "{fixture}: {}", json.stderr);
        assert_eq!(
            support::listing(&support::parse_json_report(&json.stdout)),
            support::listing(&from_check),
            "{fixture}: build and check"
        );
        let human = semo_in(
            &dir,
            &["build", &mission, "-o", &out_arg, "--color", "never"],
        );
        assert_eq!(human.code, 0, "{fixture}: {}", human.stderr);
        for d in &from_check {
            assert!(
                human.stderr.contains(&format!("[{}]", d.code))
                    && human.stderr.contains(&d.message),
                "{fixture}: {} missing from\n{}",
                d.code,
                human.stderr
            );
        }
        assert!(!robot_folders(&out).is_empty(), "{fixture}: it is built");
    }
}

/// How many events of `kind` a trace holds, and how many `drop` or
/// `dropped` lines (a message lost in the robot).
fn count_events(lines: &[String], kind: &str) -> (usize, usize) {
    let events = support::robots::events(lines);
    let of = |k: &str| {
        events
            .iter()
            .filter(|e| support::robots::field(e, "event") == k)
            .count()
    };
    (of(kind), of("drop") + of("dropped"))
}

/// A service body that sends twenty messages at once (more than a message
/// channel holds, 16) loses none of them, on the way out (the control
/// task's sends wait for room in the channel to its send task) nor on the
/// way in (the listener's receive task waits for room in the channel to
/// its control task), as `semo simulate` delivers them all: every send is
/// received, pass after pass. Counted on the traces, whatever the timing.
#[test]
fn twenty_sends_in_one_firing_all_reach_the_listener() {
    let fixture = repo_root().join("tests/fixtures/messages");
    let mission = fixture.join("burst.mission");
    let scenario = std::fs::read_to_string(fixture.join("burst.scenario.json")).unwrap();

    let sim_trace = scratch("burst-simulated").join("trace.jsonl");
    let simulated = semo_in(
        &repo_root(),
        &[
            "simulate",
            &mission.display().to_string(),
            "--scenario",
            &fixture.join("burst.scenario.json").display().to_string(),
            "--trace",
            &sim_trace.display().to_string(),
        ],
    );
    assert_eq!(
        simulated.code, 0,
        "{}{}",
        simulated.stdout, simulated.stderr
    );
    let sim_lines: Vec<String> = std::fs::read_to_string(&sim_trace)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    let robot = |robot: &str| -> Vec<String> {
        sim_lines
            .iter()
            .filter(|l| l.contains(&format!("\"robot\":\"{robot}\"")))
            .cloned()
            .collect()
    };
    let (sim_sent, sim_lost) = count_events(&robot("talker"), "send");
    let (sim_received, sim_dropped) = count_events(&robot("listener"), "receive");
    assert!(
        sim_sent >= 40,
        "the simulator's talker makes passes: {sim_sent}"
    );
    assert_eq!(
        (sim_received, sim_lost + sim_dropped),
        (sim_sent, 0),
        "the simulator delivers every send"
    );

    let traces =
        support::robots::run_in_simulation(&mission, &scratch("burst-linux-sim"), &scenario);
    let talker = support::robots::events(&traces["talker"]);
    let passes = support::robots::calls(&talker).len();
    let (sent, lost) = count_events(&traces["talker"], "send");
    let (received, dropped) = count_events(&traces["listener"], "receive");
    assert!(passes >= 2, "the talker makes passes: {passes}");
    assert_eq!(
        (sent, lost),
        (20 * passes, 0),
        "every pass's twenty sends leave the talker"
    );
    assert_eq!(
        (received, dropped),
        (sent, 0),
        "the listener receives every send and drops none"
    );
}

/// The object files under the runtime's `obj/` folder, by key folder, with
/// the moment each was last written.
fn runtime_objects(out: &Path) -> BTreeMap<String, BTreeMap<String, std::time::SystemTime>> {
    let mut keys = BTreeMap::new();
    for key in std::fs::read_dir(out.join("semo-runtime/obj")).unwrap() {
        let key = key.unwrap().path();
        let objects = std::fs::read_dir(&key)
            .unwrap()
            .map(|o| o.unwrap())
            .map(|o| {
                let written = o.metadata().unwrap().modified().unwrap();
                (o.file_name().to_string_lossy().into_owned(), written)
            })
            .collect();
        keys.insert(
            key.file_name().unwrap().to_string_lossy().into_owned(),
            objects,
        );
    }
    keys
}

/// The runtime is written once per build, beside the team folders, not
/// copied into each robot's; the robots built with the same compiler and
/// flags compile it once, others get their own objects; a robot folder
/// copied elsewhere builds with `make RUNTIME=...`.
#[test]
fn the_runtime_is_written_once_and_compiled_once_per_compiler_and_flags() {
    let out = scratch("shared-runtime");
    let built = build_for(&example("scouting/scouting.mission"), "linux-sim", &out);
    assert_eq!(built.code, 0, "{}", built.stderr);
    assert!(built.stdout.contains("semo-runtime"), "{}", built.stdout);
    let runtime = out.join("semo-runtime");
    let sources: Vec<String> = std::fs::read_dir(&runtime)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".c"))
        .collect();
    // The core, the threads platform, UDP, MQTT, the serial link and its
    // transport, the simulation and lock-step.
    assert_eq!(sources.len(), 8, "{sources:?}");
    let folders = robot_folders(&out);
    assert_eq!(folders.len(), 3, "{folders:?}");
    for folder in &folders {
        let copies: Vec<_> = std::fs::read_dir(folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|name| name.starts_with("semo_") && name != "semo_deploy.h")
            .collect();
        assert!(copies.is_empty(), "{}: {copies:?}", folder.display());
    }
    make(&folders[0], "gcc", STRICT).unwrap();
    let first = runtime_objects(&out);
    assert_eq!(first.len(), 1, "{first:?}");
    assert_eq!(
        first.values().next().unwrap().len(),
        sources.len(),
        "{first:?}"
    );
    for folder in &folders[1..] {
        make(folder, "gcc", STRICT).unwrap();
        assert!(folder.join(folder.file_name().unwrap()).is_file());
    }
    assert_eq!(
        runtime_objects(&out),
        first,
        "compiled again for the same flags"
    );
    // Other flags: objects of their own, the first ones untouched.
    make(&folders[1], "gcc", "-std=c11 -Wall -Wextra -Werror -O0").unwrap();
    let both = runtime_objects(&out);
    assert_eq!(both.len(), 2, "{both:?}");
    assert!(
        both.iter()
            .any(|(key, objects)| first.get(key) == Some(objects))
    );
    // A robot folder copied elsewhere names the runtime's folder.
    let copy = scratch("shared-runtime-copy").join("irobot");
    let status = Command::new("cp")
        .args([
            "-r",
            &folders[0].display().to_string(),
            &copy.display().to_string(),
        ])
        .status()
        .unwrap();
    assert!(status.success());
    let made = Command::new("make")
        .args(["-s", "clean", "all"])
        .arg(format!("RUNTIME={}", runtime.display()))
        .current_dir(&copy)
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    assert!(copy.join("irobot").is_file());
}

#[path = "../compiler/benches/common/mission.rs"]
mod benchmark_mission;

/// Bytes of every file under `dir`, and the largest number of robots a
/// robot's `main.c` there names (the rows of its `peers[]` table).
fn bytes_and_widest_peer_table(dir: &Path) -> (u64, usize) {
    let (mut bytes, mut widest) = (0, 0);
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            bytes += std::fs::metadata(&path).unwrap().len();
            if path.file_name().is_some_and(|n| n == "main.c") {
                let text = std::fs::read_to_string(&path).unwrap();
                let table = text
                    .split("static const semo_peer peers[] = {\n")
                    .nth(1)
                    .and_then(|rest| rest.split("};").next())
                    .expect("main.c has a peer table");
                widest = widest.max(table.lines().count());
            }
        }
    }
    (bytes, widest)
}

/// A build's output is linear in the robots: twice the teams of the
/// generated benchmark mission (each of six robots, talking to the next
/// team) write at most twice the bytes, because a robot's program names only
/// its peers (its team and the team it sends to: 12 robots), never the whole
/// fleet, and the runtime is written once. Before, every `main.c` listed
/// every robot of the mission: 1,002 robots wrote some 227 MB.
#[test]
fn twice_the_robots_write_at_most_twice_the_bytes() {
    let measure = |teams: usize| {
        let dir = scratch(&format!("fleet-{teams}"));
        let mission = dir.join("fleet.mission");
        std::fs::write(&mission, benchmark_mission::generate(teams)).unwrap();
        let out = dir.join("out");
        let built = build_for(&mission, "linux-sim", &out);
        assert_eq!(built.code, 0, "{}", built.stderr);
        bytes_and_widest_peer_table(&out)
    };
    let (small, small_widest) = measure(20);
    let (large, large_widest) = measure(40);
    assert_eq!((small_widest, large_widest), (12, 12));
    assert!(
        large <= 2 * small,
        "120 robots wrote {small} bytes, 240 robots {large} (x{:.2})",
        large as f64 / small as f64
    );
}
