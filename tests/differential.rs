//! The simulator as the reference for the code generator: each example
//! mission runs on the same scenario through `semo simulate` and as the
//! generated `linux-sim` programs (one process per robot, talking over UDP),
//! and per robot the two traces must show the same behaviour: the sequence
//! of modes, of services started per plan, of caught events, of leaders;
//! the same messages sent (to, key) and received (from robot, key); and
//! each mode entered at about the same mission time.
//!
//! The tolerance on times, [`TOLERANCE_MS`]: the processes run at
//! `time_scale` 0.2 (5 mission ms per wall ms; patrol_groups at 1), each on
//! its own clock from its own start, and the simulator orders same-time
//! events one fixed way where threads race. A process's first control
//! firing comes up to about 190 mission ms after its start (the runtime's
//! start-up, ~40 wall ms, scaled; measured 175-185 ms for scouting); a
//! sensor-driven change then waits for the next sensor sample (period
//! 100 ms) and, in a loop around a service call, for the call under way to
//! end (the scenario's 100 ms plus a control period of 10 ms). Together:
//! 400 ms of mission time. The scouting run measured up to 285 ms.
//! Differences beyond it, or in any sequence, are a bug in one of the two.

mod support;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use support::{examples, repo_root, semo_in};

const TOLERANCE_MS: i64 = 400;

/// How long after their start the processes of a random mission may still
/// miss each other's messages: their start-up spread (measured up to about
/// 190 mission ms at `time_scale` 0.2, see [`TOLERANCE_MS`]).
const START_MS: i64 = 250;

type Event = serde_json::Map<String, serde_json::Value>;

/// Held while a test's robot processes run (see [`run_processes`]), the
/// random missions' included.
static RUNNING: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("differential")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn field<'e>(event: &'e Event, key: &str) -> &'e str {
    event.get(key).and_then(|v| v.as_str()).unwrap_or("")
}

fn parse_trace(text: &str) -> Vec<Event> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("bad trace line {l}: {e}")))
        .collect()
}

/// What is compared of one robot's trace.
#[derive(Debug, PartialEq, Eq)]
struct Behaviour {
    modes: Vec<String>,
    services: BTreeMap<String, Vec<String>>,
    catches: Vec<(String, String)>,
    leaders: Vec<String>,
    sent: BTreeSet<(String, String)>,
    received: BTreeSet<(String, String)>,
}

fn behaviour(events: &[&Event]) -> Behaviour {
    fn of<'a>(events: &'a [&'a Event], kind: &'a str) -> impl Iterator<Item = &'a &'a Event> {
        events.iter().filter(move |e| field(e, "event") == kind)
    }
    let mut services: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for e in of(events, "service_start") {
        services
            .entry(field(e, "plan").to_string())
            .or_default()
            .push(field(e, "service").to_string());
    }
    Behaviour {
        modes: of(events, "mode")
            .map(|e| field(e, "mode").to_string())
            .collect(),
        services,
        catches: of(events, "catch")
            .map(|e| (field(e, "name").to_string(), field(e, "mode").to_string()))
            .collect(),
        leaders: of(events, "leader")
            .map(|e| field(e, "leader").to_string())
            .collect(),
        sent: of(events, "send")
            .map(|e| (field(e, "to").to_string(), field(e, "key").to_string()))
            .collect(),
        received: of(events, "receive")
            .map(|e| {
                (
                    field(e, "from_robot").to_string(),
                    field(e, "key").to_string(),
                )
            })
            .collect(),
    }
}

fn mode_times(events: &[&Event]) -> Vec<i64> {
    events
        .iter()
        .filter(|e| field(e, "event") == "mode")
        .map(|e| e["t"].as_i64().unwrap())
        .collect()
}

/// Every robot folder under an output folder, as (robot, folder).
fn robot_folders(out: &Path) -> Vec<(String, PathBuf)> {
    support::robots::robot_folders(out)
        .into_iter()
        .map(|folder| {
            let robot = folder.file_name().unwrap().to_string_lossy().into_owned();
            (robot, folder)
        })
        .collect()
}

/// Runs the generated programs of `mission` on `scenario` (killing robots
/// at the scenario's `kill` faults) and returns each robot's trace.
fn run_processes(
    name: &str,
    mission: &Path,
    scenario: &Path,
    kills: &[(&str, i64)],
    time_scale: f64,
    port_offset: u32,
) -> BTreeMap<String, Vec<Event>> {
    let out = scratch(name);
    let built = semo_in(
        &repo_root(),
        &[
            "build",
            &mission.display().to_string(),
            "--target",
            "linux-sim",
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let folders = robot_folders(&out);
    for (_, folder) in &folders {
        let made = Command::new("make")
            .args(["-s", "-j2", "CFLAGS=-std=c11 -O1"])
            .current_dir(folder)
            .status()
            .expect("make runs");
        assert!(made.success(), "{}", folder.display());
    }
    let port_base = 20000 + (std::process::id() % 250) * 40 + port_offset;
    // The processes keep mission time on their own clocks, so robots of two
    // tests running at once would delay each other past the tolerance on a
    // loaded machine: one test's robots run at a time (building overlaps).
    let _one_run_at_a_time = RUNNING.lock().unwrap_or_else(|e| e.into_inner());
    let mut children = BTreeMap::new();
    for (robot, folder) in &folders {
        let trace = out.join(format!("{robot}.jsonl"));
        let child = support::robots::robot_command(folder, scenario, &trace, port_base)
            .spawn()
            .expect("the robot program starts");
        children.insert(robot.clone(), child);
    }
    let started = std::time::Instant::now();
    let mut kills: Vec<_> = kills.to_vec();
    kills.sort_by_key(|(_, at)| *at);
    for (robot, at) in kills {
        let wall = std::time::Duration::from_micros((at as f64 * time_scale * 1000.0) as u64);
        if let Some(left) = wall.checked_sub(started.elapsed()) {
            std::thread::sleep(left);
        }
        children.get_mut(robot).unwrap().kill().unwrap();
    }
    for (robot, mut child) in children {
        let status = child.wait().unwrap();
        assert!(
            status.success() || status.code().is_none(),
            "{robot}: {status:?}"
        );
    }
    folders
        .iter()
        .map(|(robot, _)| {
            let text =
                std::fs::read_to_string(out.join(format!("{robot}.jsonl"))).unwrap_or_default();
            (robot.clone(), parse_trace(&text))
        })
        .collect()
}

fn simulate(mission: &Path, scenario: &Path) -> Vec<Event> {
    let out = semo_in(
        &repo_root(),
        &[
            "simulate",
            &mission.display().to_string(),
            "--scenario",
            &scenario.display().to_string(),
            "--trace",
            "-",
        ],
    );
    assert!(out.code <= 1, "{}{}", out.stdout, out.stderr);
    parse_trace(&out.stdout)
}

fn compare(name: &str, mission: &Path, scenario_text: &str, kills: &[(&str, i64)], port: u32) {
    let dir = scratch(&format!("{name}-scenario"));
    let scenario = dir.join("scenario.json");
    std::fs::write(&scenario, scenario_text).unwrap();
    let reference: Vec<Event> = simulate(mission, &scenario);
    let time_scale =
        serde_json::from_str::<serde_json::Value>(scenario_text).unwrap()["time_scale"]
            .as_f64()
            .unwrap();
    let processes = run_processes(name, mission, &scenario, kills, time_scale, port);
    let mut problems = Vec::new();
    for (robot, events) in &processes {
        let c: Vec<&Event> = events.iter().collect();
        let s: Vec<&Event> = reference
            .iter()
            .filter(|e| field(e, "robot") == robot)
            .collect();
        let (bc, bs) = (behaviour(&c), behaviour(&s));
        if bc != bs {
            problems.push(format!("{robot}:\n  C:   {bc:?}\n  sim: {bs:?}"));
            continue;
        }
        let worst = mode_times(&c)
            .into_iter()
            .zip(mode_times(&s))
            .map(|(tc, ts)| (tc - ts).abs())
            .max()
            .unwrap_or(0);
        eprintln!(
            "{name}/{robot}: {} modes, {} catches, {} leaders, {} kinds of message sent, {} received; mode times differ by up to {worst} ms",
            bs.modes.len(),
            bs.catches.len(),
            bs.leaders.len(),
            bs.sent.len(),
            bs.received.len()
        );
        for (tc, ts) in mode_times(&c).into_iter().zip(mode_times(&s)) {
            if (tc - ts).abs() > TOLERANCE_MS {
                problems.push(format!(
                    "{robot}: modes entered at {:?} (C) and {:?} (sim)",
                    mode_times(&c),
                    mode_times(&s)
                ));
                break;
            }
        }
    }
    assert!(problems.is_empty(), "{name}:\n{}", problems.join("\n"));
}

#[test]
fn scouting_behaves_the_same_in_c_and_in_the_simulator() {
    let scenario =
        std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
            .unwrap()
            .replacen("\"time_scale\": 0.1", "\"time_scale\": 0.2", 1);
    compare(
        "scouting",
        &examples().join("scouting/scouting.mission"),
        &scenario,
        &[],
        0,
    );
}

#[test]
fn a_killed_leader_is_replaced_the_same_way_in_c_and_in_the_simulator() {
    compare(
        "patrol_groups",
        &examples().join("swarm/patrol_groups.mission"),
        r#"{"time_scale": 1, "duration": 3500, "faults": [{"at": 1200, "kill": "tb_0"}]}"#,
        &[("tb_0", 1200)],
        10,
    );
}

#[test]
fn the_other_examples_behave_the_same_in_c_and_in_the_simulator() {
    compare(
        "march",
        &examples().join("swarm/march.mission"),
        r#"{"time_scale": 0.2, "duration": 3000, "robots": {"quad_2": {"sensors": [{"at": 1000, "value": "obstacle", "is": "true"}]}}}"#,
        &[],
        20,
    );
    compare(
        "follow",
        &examples().join("follow/follow.mission"),
        r#"{"time_scale": 0.2, "duration": 4000,
            "robots": {"create1": {"sensors": [{"at": 0, "value": "DISTANCE", "is": "80"}, {"at": 2000, "value": "DISTANCE", "is": "20"}]}},
            "operator": [{"every": 500, "to": "create1", "value": "RC_CMD", "is": "LEFT"}]}"#,
        &[],
        30,
    );
}

/// The events without the receptions of the start-up window ([`START_MS`]).
fn settled<'e>(events: &[&'e Event]) -> Vec<&'e Event> {
    events
        .iter()
        .copied()
        .filter(|e| field(e, "event") != "receive" || e["t"].as_i64().unwrap() >= START_MS)
        .collect()
}

/// The events up to `until` mission ms.
fn until<'e>(events: &[&'e Event], until: i64) -> Vec<&'e Event> {
    events
        .iter()
        .copied()
        .filter(|e| e["t"].as_i64().unwrap() <= until)
        .collect()
}

/// `early` (one run's sequence up to a time both runs certainly reached) is
/// where `all` (the other run's whole sequence) begins.
fn starts<T: PartialEq + std::fmt::Debug>(early: &[T], all: &[T]) -> bool {
    all.len() >= early.len() && all[..early.len()] == *early
}

/// Random valid missions (the generator of `support/missiongen.rs`) on an
/// empty scenario: the same checks as for the examples, except that a run
/// ends at a cut-off one of the two may reach a little earlier, so each
/// run's behaviour up to [`TOLERANCE_MS`] before the end must begin the
/// other's.
fn random_missions(seeds: std::ops::Range<u64>) {
    let catalog = semo::catalog::builtin_catalog();
    let duration = 2000;
    let scenario = format!(r#"{{"time_scale": 0.2, "duration": {duration}}}"#);
    let mut problems = Vec::new();
    for seed in seeds {
        let dir = scratch(&format!("random-{seed}"));
        let mission = dir.join(format!("random{seed}.mission"));
        std::fs::write(&mission, support::missiongen::mission(seed, &catalog)).unwrap();
        let scenario_path = dir.join("scenario.json");
        std::fs::write(&scenario_path, &scenario).unwrap();
        let reference = simulate(&mission, &scenario_path);
        let processes = {
            let _one_run_at_a_time = RUNNING.lock().unwrap_or_else(|e| e.into_inner());
            support::robots::run_in_simulation(&mission, &dir.join("out"), &scenario)
        };
        for (robot, lines) in &processes {
            let c_events = support::robots::events(lines);
            let c: Vec<&Event> = c_events.iter().collect();
            let s: Vec<&Event> = reference
                .iter()
                .filter(|e| field(e, "robot") == robot)
                .collect();
            // The processes start a little apart and do not wait for each
            // other: a message sent before its receiver listens is lost (UDP),
            // where the simulator starts every robot at once. Receptions in
            // the start-up window are left out on both sides.
            let (c, s) = (settled(&c), settled(&s));
            let cut = duration - TOLERANCE_MS;
            let (c_early, s_early) = (behaviour(&until(&c, cut)), behaviour(&until(&s, cut)));
            let (c_all, s_all) = (behaviour(&c), behaviour(&s));
            let agree = |a: &Behaviour, b: &Behaviour| {
                starts(&a.modes, &b.modes)
                    && starts(&a.catches, &b.catches)
                    && starts(&a.leaders, &b.leaders)
                    && a.services.iter().all(|(plan, list)| {
                        starts(list, b.services.get(plan).map_or(&[][..], |l| l))
                    })
                    && a.sent.is_subset(&b.sent)
                    && a.received.is_subset(&b.received)
            };
            if !agree(&c_early, &s_all) || !agree(&s_early, &c_all) {
                problems.push(format!(
                    "seed {seed}, {robot}:\n  C:   {c_all:?}\n  sim: {s_all:?}"
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn random_missions_behave_the_same_in_c_and_in_the_simulator() {
    random_missions(0..30);
}

#[test]
#[ignore = "long: many more random missions (cargo test --test differential -- --ignored)"]
fn many_random_missions_behave_the_same_in_c_and_in_the_simulator() {
    random_missions(30..300);
}
