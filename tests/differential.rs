//! The simulator as the reference for the code generator: each example
//! mission runs on the same scenario through `semo simulate` and as the
//! generated `linux-sim` programs (`semo simulate --engine c`: one process
//! per robot, in lock-step virtual time, the coordinator their clock and
//! network), and per robot the two traces must show the same behaviour: the
//! sequence of modes, of services started per plan, of caught events, of
//! leaders; the same messages sent (to, key) and received (from robot, key);
//! and each mode entered at about the same mission time.
//!
//! The scenarios include faults: kill and restart (done by the coordinator
//! at their mission time), link faults (drop, delay, partition: the
//! runtime's send path) and battery levels (the runtime's `BATTERY` value);
//! the random missions get random ones (`missiongen::scenario`).
//!
//! In lock-step no clock is read: a run is the same on a loaded machine,
//! and what is left of the differences in time is the two's different step
//! rules, the same in every run (the simulator's control task fires on a
//! 10 ms grid, the C one when woken: a call started after another ends comes
//! 10 ms later in C, and such steps add up along a chain). Until the two
//! agree event for event (issue "One exact meaning"), the times are compared
//! one-sided, within bounds measured when they ran on the wall clock:
//!
//! - never earlier than the simulator's by more than [`EARLY_MS`] (210 ms:
//!   a race at one instant resolved the other way costs one period of the
//!   service polling for it, 200 ms for march's `Watch`, and one control
//!   period, 10 ms);
//! - never later by more than [`LATE_MS`] (500 ms): a sensor-driven change
//!   waits for the next sample (100 ms) and the call under way (100 ms + 10
//!   ms), and every step of a chain adds up.
//!
//! Differences beyond them, or in any sequence, are a bug in one of the two.

mod support;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use support::{examples, repo_root, semo_in};

const EARLY_MS: i64 = 210;
const LATE_MS: i64 = 500;

/// The start-up window of a random mission's run, whose receptions are not
/// compared. This and the other windows ([`HEAL_MS`], [`finishing`]) were
/// measured when the robots ran on the wall clock; they stay until the exact
/// comparison replaces these checks (in lock-step the same instants are
/// ordered one fixed way by each engine, not always the same way by both).
/// On the wall clock: behind the barrier every port is open from mission time 0, but
/// each process's first control firing still comes when its threads get the
/// cores (measured up to 38 mission ms after 0 at `time_scale` 0.2), so a
/// robot that finishes at its first firing (random seed 6) may hear the
/// others' first messages in C and not in the simulator, where every robot
/// fires at 0 and a message takes 1 ms. Before the barrier: 250 ms.
const START_MS: i64 = 100;

type Event = serde_json::Map<String, serde_json::Value>;

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

/// What is compared of one robot's trace. The sequences are compared as
/// runs of equal items (the item, and whether it repeats): a mode that
/// catches its own event is entered again at every control firing it keeps
/// up with, a rate that a loaded machine lowers in C (random seed 11 at
/// `time_scale` 0.2 fired 115 times in C, 200 in the simulator), while a
/// different event, mode, service or leader, another order, or a repetition
/// on one side only is still a difference.
#[derive(Debug, PartialEq, Eq)]
struct Behaviour {
    modes: Runs<String>,
    services: BTreeMap<String, Runs<String>>,
    catches: Runs<(String, String)>,
    leaders: Runs<String>,
    /// The owners of the team's globally shared values it changed to.
    owners: Runs<String>,
    /// Group services: (rank, size) as each change was traced.
    groups: Runs<(String, String)>,
    sent: BTreeSet<(String, String)>,
    received: BTreeSet<(String, String)>,
    /// Adaptive resource management: the battery policies that start and
    /// stop holding and the levels they give (`resources`).
    resources: Vec<(String, String, String)>,
}

/// A sequence as runs of equal consecutive items: (item, repeated).
type Runs<T> = Vec<(T, bool)>;

fn runs<T: PartialEq>(items: impl IntoIterator<Item = T>) -> Runs<T> {
    let mut out: Runs<T> = Vec::new();
    for item in items {
        match out.last_mut() {
            Some((last, repeated)) if *last == item => *repeated = true,
            _ => out.push((item, false)),
        }
    }
    out
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
        modes: runs(of(events, "mode").map(|e| field(e, "mode").to_string())),
        services: services
            .into_iter()
            .map(|(plan, list)| (plan, runs(list)))
            .collect(),
        catches: runs(
            of(events, "catch")
                .map(|e| (field(e, "name").to_string(), field(e, "mode").to_string())),
        ),
        leaders: runs(of(events, "leader").map(|e| field(e, "leader").to_string())),
        owners: runs(of(events, "shared_owner").map(|e| field(e, "owner").to_string())),
        groups: runs(
            of(events, "group")
                .map(|e| (field(e, "rank").to_string(), field(e, "size").to_string())),
        ),
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
        resources: resources(events).into_iter().map(|(_, r)| r).collect(),
    }
}

/// The resource manager's events: (time, (event, the policy's condition or
/// the task, whether it holds or the level)).
fn resources(events: &[&Event]) -> Vec<(i64, (String, String, String))> {
    events
        .iter()
        .filter_map(|e| {
            let (what, value) = match field(e, "event") {
                "battery_policy" => (field(e, "condition"), field(e, "holds")),
                "period" | "speed" => (field(e, "task"), field(e, "level")),
                _ => return None,
            };
            let kind = field(e, "event").to_string();
            Some((
                e["t"].as_i64().unwrap(),
                (kind, what.to_string(), value.to_string()),
            ))
        })
        .collect()
}

/// When each run of modes began (see [`Behaviour`]).
fn mode_times(events: &[&Event]) -> Vec<i64> {
    let mut times = Vec::new();
    let mut last = None;
    for e in events.iter().filter(|e| field(e, "event") == "mode") {
        if last != Some(field(e, "mode")) {
            times.push(e["t"].as_i64().unwrap());
            last = Some(field(e, "mode"));
        }
    }
    times
}

/// The robots of `mission`, in peer order (`semo build --target linux-sim`,
/// without compiling them).
fn robots_of(name: &str, mission: &Path) -> Vec<String> {
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
    support::robots::robot_folders(&out)
        .into_iter()
        .map(|folder| folder.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// Each robot's trace (its incarnations' in order) when the generated
/// programs run `scenario` in lock-step (`semo simulate --engine c`: built,
/// run as processes, killed and restarted at the scenario's faults).
fn lock_step(mission: &Path, scenario: &Path) -> BTreeMap<String, Vec<Event>> {
    let mut traces: BTreeMap<String, Vec<Event>> = BTreeMap::new();
    for event in run_engine(mission, scenario, "c") {
        traces
            .entry(field(&event, "robot").to_string())
            .or_default()
            .push(event);
    }
    traces
}

fn simulate(mission: &Path, scenario: &Path) -> Vec<Event> {
    run_engine(mission, scenario, "sim")
}

/// The trace of `semo simulate` with `engine`.
fn run_engine(mission: &Path, scenario: &Path, engine: &str) -> Vec<Event> {
    let out = support::simulate_trace(mission, scenario, engine);
    assert!(out.code <= 1, "{engine}: {}{}", out.stdout, out.stderr);
    parse_trace(&out.stdout)
}

/// Compares the two runs and returns them: the C traces by robot, and the
/// simulator's trace.
fn compare(
    name: &str,
    mission: &Path,
    scenario_text: &str,
) -> (BTreeMap<String, Vec<Event>>, Vec<Event>) {
    let dir = scratch(&format!("{name}-scenario"));
    let scenario = dir.join("scenario.json");
    std::fs::write(&scenario, scenario_text).unwrap();
    let reference: Vec<Event> = simulate(mission, &scenario);
    let processes = lock_step(mission, &scenario);
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
            .map(|(tc, ts)| tc - ts)
            .max_by_key(|d| d.abs())
            .unwrap_or(0);
        eprintln!(
            "{name}/{robot}: {} modes, {} catches, {} leaders, {} kinds of message sent, {} received; C mode times differ by up to {worst:+} ms",
            bs.modes.len(),
            bs.catches.len(),
            bs.leaders.len(),
            bs.sent.len(),
            bs.received.len()
        );
        let policy_times = |events: &[&Event]| -> Vec<i64> {
            resources(events)
                .into_iter()
                .filter(|(_, (kind, _, _))| kind == "battery_policy")
                .map(|(t, _)| t)
                .collect()
        };
        for (tc, ts) in policy_times(&c).into_iter().zip(policy_times(&s)) {
            if tc - ts < -EARLY_MS || tc - ts > LATE_MS {
                problems.push(format!(
                    "{robot}: battery policies changed at {:?} (C) and {:?} (sim)",
                    policy_times(&c),
                    policy_times(&s)
                ));
                break;
            }
        }
        for (tc, ts) in mode_times(&c).into_iter().zip(mode_times(&s)) {
            if tc - ts < -EARLY_MS || tc - ts > LATE_MS {
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
    (processes, reference)
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
    );
}

#[test]
fn a_killed_leader_is_replaced_the_same_way_in_c_and_in_the_simulator() {
    compare(
        "patrol_groups",
        &examples().join("swarm/patrol_groups.mission"),
        r#"{"time_scale": 1, "duration": 3500, "faults": [{"at": 1200, "kill": "tb_0"}]}"#,
    );
}

/// The leader killed and restarted: the new process starts from the default
/// mode, on the mission's clock, listens, follows tb_1 until it gives way
/// and takes the lead back (docs/groups.md): at 3.2 s or 4.2 s, as tb_1's
/// heartbeat saying it gave way arrives before tb_0's pass at 3.2 s or just
/// after it (a real-time race), so the run goes on to 5 s.
#[test]
fn a_restarted_leader_comes_back_the_same_way_in_c_and_in_the_simulator() {
    compare(
        "patrol_groups_restart",
        &examples().join("swarm/patrol_groups.mission"),
        r#"{"time_scale": 1, "duration": 5000,
            "faults": [{"at": 1200, "kill": "tb_0"}, {"at": 2200, "restart": "tb_0"}]}"#,
    );
}

/// Globally shared information (`docs/shared-information.md`): the owner
/// `a` killed, `b` takes over and a write of `c` reaches it, in both; what
/// each reads shows in its modes (`tests/fixtures/shared`).
#[test]
fn a_killed_owner_of_shared_values_is_replaced_the_same_way_in_c_and_in_the_simulator() {
    let fixture = repo_root().join("tests/fixtures/shared");
    let scenario = std::fs::read_to_string(fixture.join("shared.scenario.json")).unwrap();
    let (processes, _) = compare("shared", &fixture.join("shared.mission"), &scenario);
    for robot in ["b", "c"] {
        let owners: Vec<&str> = processes[robot]
            .iter()
            .filter(|e| field(e, "event") == "shared_owner")
            .map(|e| field(e, "owner"))
            .collect();
        assert_eq!(owners, ["b"], "{robot}");
    }
}

/// The owner the strategy names (`<SharedOwner>`, `tests/fixtures/shared_named`:
/// `b`) and the team's leader as owner (`bully`, `tests/fixtures/shared_bully`:
/// `c`; `highest_battery`, `tests/fixtures/shared_battery`: `a` at start),
/// each killed: ownership moves to `a` (the first live robot of the
/// formation order), to `b` (the next leader) and to `c` (the fullest live
/// robot) the same way in both.
#[test]
fn the_named_owner_and_the_leader_owner_are_replaced_the_same_way_in_c_and_in_the_simulator() {
    for (fixture, readers, next) in [
        ("shared_named", ["a", "c"], "a"),
        ("shared_bully", ["a", "b"], "b"),
        ("shared_battery", ["b", "c"], "c"),
    ] {
        let dir = repo_root().join("tests/fixtures").join(fixture);
        let scenario = std::fs::read_to_string(dir.join("shared.scenario.json")).unwrap();
        let (processes, _) = compare(fixture, &dir.join("shared.mission"), &scenario);
        for robot in readers {
            let owners: Vec<&str> = processes[robot]
                .iter()
                .filter(|e| field(e, "event") == "shared_owner")
                .map(|e| field(e, "owner"))
                .collect();
            assert_eq!(owners, [next], "{fixture}: {robot}");
        }
    }
}

/// A group service (tests/fixtures/group_service: `move`, heartbeats every
/// 200 ms) with tb_1 killed and restarted: the others' ranks and sizes
/// change the same way in both (2 of 3 → 1 of 2 → 2 of 3 for tb_2), and
/// tb_1 starts each life as 1 of 3.
#[test]
fn a_group_service_redivides_the_same_way_in_c_and_in_the_simulator() {
    let (c, _) = compare(
        "group_service",
        &repo_root().join("tests/fixtures/group_service/sweep.mission"),
        r#"{"time_scale": 1, "duration": 4000,
            "faults": [{"at": 1000, "kill": "tb_1"}, {"at": 2500, "restart": "tb_1"}]}"#,
    );
    let sizes: Vec<String> = c["tb_2"]
        .iter()
        .filter(|e| field(e, "event") == "group")
        .map(|e| format!("{} of {}", field(e, "rank"), field(e, "size")))
        .collect();
    assert_eq!(sizes, ["2 of 3", "1 of 2", "2 of 3"]);
}

/// Link faults in both: the master hears nothing from ti for two seconds,
/// nxt's messages arrive 300 ms late for three, and a partition cuts nxt off
/// at the end; ti's battery runs down (linux-sim's BATTERY value).
#[test]
fn link_faults_and_battery_act_the_same_in_c_and_in_the_simulator() {
    let mut scenario: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
            .unwrap(),
    )
    .unwrap();
    scenario["time_scale"] = 0.2.into();
    scenario["faults"] = serde_json::json!([
        {"from": 1500, "until": 3500, "drop": ["irobot", "ti"]},
        {"from": 1000, "until": 4000, "delay": ["irobot", "nxt"], "by": 300},
        {"from": 7000, "until": 9000, "partition": [["irobot", "ti"]]}
    ]);
    scenario["robots"]["ti"]["battery"] =
        serde_json::json!([{"at": 0, "level": 90}, {"at": 4000, "level": 10}]);
    compare(
        "scouting_faults",
        &examples().join("scouting/scouting.mission"),
        &scenario.to_string(),
    );
}

/// Adaptive resource management (the strategy's `BatteryRequirement`:
/// below 30 % the camera and ultrasonic sample every 200 ms and the wheels
/// run at half speed): irobot's battery drains from 100 % to 20 % by 3 s
/// (it reads 28 % at its 2.7 s sample) and is charged from 20 % at 6 s to
/// 50 % at 8 s (31 % at 6.7 s). Both runs show the policy start and stop
/// holding at those samples and the levels change with it, and the calls of
/// the wheel task take twice the scenario's 100 ms while it holds.
#[test]
fn battery_policies_change_periods_and_speeds_the_same_in_c_and_in_the_simulator() {
    let mut scenario: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_root().join("tests/fixtures/build/scouting.scenario.json"))
            .unwrap(),
    )
    .unwrap();
    scenario["time_scale"] = 0.2.into();
    scenario["robots"]["irobot"]["battery"] = serde_json::json!([
        {"at": 0, "level": 100}, {"at": 3000, "level": 20},
        {"at": 6000, "level": 20}, {"at": 8000, "level": 50}
    ]);
    let (c, sim) = compare(
        "scouting_battery",
        &examples().join("scouting/scouting.mission"),
        &scenario.to_string(),
    );
    let expected: Vec<(String, String, String)> = [
        ("battery_policy", "Battery<30", "true"),
        ("period", "camera", "2"),
        ("period", "ultrasonic", "2"),
        ("speed", "wheel", "2"),
        ("battery_policy", "Battery<30", "false"),
        ("period", "camera", "1"),
        ("period", "ultrasonic", "1"),
        ("speed", "wheel", "1"),
    ]
    .iter()
    .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()))
    .collect();
    let sim: Vec<&Event> = sim
        .iter()
        .filter(|e| field(e, "robot") == "irobot")
        .collect();
    let c: Vec<&Event> = c["irobot"].iter().collect();
    for (side, events) in [("sim", &sim), ("C", &c)] {
        let changes = resources(events);
        let seen: Vec<_> = changes.iter().map(|(_, r)| r.clone()).collect();
        assert_eq!(seen, expected, "{side}");
        // The wheel's `Move` commands (the strategy's actuator; no mode
        // change stops one while the policy holds): twice as long then.
        let (on, off) = (changes[0].0, changes[4].0);
        let mut started = None;
        let mut slow_calls = 0;
        let moves = events
            .iter()
            .filter(|e| field(e, "task") == "wheel" && field(e, "service") == "Move");
        for e in moves {
            let t = e["t"].as_i64().unwrap();
            match field(e, "event") {
                "call_start" => started = Some(t),
                "call_end" => {
                    let Some(start) = started.take() else {
                        continue;
                    };
                    if start > on && t < off {
                        assert!(
                            t - start >= 200,
                            "{side}: a call at speed level 2 took {} ms",
                            t - start
                        );
                        slow_calls += 1;
                    } else if side == "sim" && t < on {
                        assert_eq!(t - start, 100, "sim: a call at speed level 1");
                    }
                }
                _ => {}
            }
        }
        assert!(
            slow_calls > 0,
            "{side}: no wheel call while the policy held"
        );
    }
    // The simulator samples the battery on the 100 ms grid.
    let sim_times: Vec<i64> = resources(&sim)
        .iter()
        .filter(|(_, (kind, _, _))| kind == "battery_policy")
        .map(|(t, _)| *t)
        .collect();
    assert_eq!(sim_times, [2700, 6700]);
}

#[test]
fn the_other_examples_behave_the_same_in_c_and_in_the_simulator() {
    compare(
        "march",
        &examples().join("swarm/march.mission"),
        r#"{"time_scale": 0.2, "duration": 3000, "robots": {"quad_2": {"sensors": [{"at": 1000, "value": "obstacle", "is": "true"}]}}}"#,
    );
    compare(
        "follow",
        &examples().join("follow/follow.mission"),
        r#"{"time_scale": 0.2, "duration": 4000,
            "robots": {"create1": {"sensors": [{"at": 0, "value": "DISTANCE", "is": "80"}, {"at": 2000, "value": "DISTANCE", "is": "20"}]}},
            "operator": [{"every": 500, "to": "create1", "value": "RC_CMD", "is": "LEFT"}]}"#,
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

/// One heartbeat period of the generated missions (200 ms): after a link
/// fault ends, which of two robots leads is decided by whether one's
/// heartbeat or the other's message (each every 200 ms, a few ms apart)
/// arrives first; within the simulator's link latency that is a race in real
/// time (random seed 14: a leader's publish 2 ms after the heartbeat that
/// ends its leadership).
const HEAL_MS: i64 = 200;

/// The events without the receptions of the heartbeat period after each
/// link fault of `scenario` ends ([`HEAL_MS`]).
fn healed<'e>(events: &[&'e Event], scenario: &str) -> Vec<&'e Event> {
    let scenario: serde_json::Value = serde_json::from_str(scenario).unwrap();
    let ends: Vec<i64> = scenario["faults"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|f| {
            ["drop", "delay", "partition"]
                .iter()
                .any(|k| f.get(k).is_some())
        })
        .filter_map(|f| f["until"].as_i64())
        .collect();
    events
        .iter()
        .copied()
        .filter(|e| {
            let t = e["t"].as_i64().unwrap();
            field(e, "event") != "receive"
                || !ends.iter().any(|&end| (end..end + HEAL_MS).contains(&t))
        })
        .collect()
}

/// `robot`'s events without the receptions of what the simulator
/// (`reference`) shows sent to it (to it or to its team) at the mission
/// instant it finished. A robot that finishes takes no more messages, in C
/// (`semo_core.c`) as in the simulator; but when others send at the very
/// instant it finishes, the simulator orders the finish first (a message
/// takes 1 ms), while in C each process's firing of that instant runs when
/// it gets a core: random seed 29, where three robots of a team finish at
/// mission time 100 in the simulator, two of them telling the third (the
/// owner of their globally shared value) their last write; in C their
/// firings ran at 107–109 and the owner's at 120, so it heard both writes
/// before it finished. That race is real, and only that one is left out.
fn finishing<'e>(events: &[&'e Event], reference: &[Event], robot: &str) -> Vec<&'e Event> {
    let of_robot = |e: &&Event| field(e, "robot") == robot;
    let Some(finish) = reference
        .iter()
        .filter(of_robot)
        .find(|e| field(e, "event") == "finish")
        .map(|e| e["t"].as_i64().unwrap())
    else {
        return events.to_vec();
    };
    let team = reference
        .iter()
        .filter(of_robot)
        .find(|e| field(e, "event") == "start")
        .map_or("", |e| field(e, "team"));
    let contested: BTreeSet<(&str, &str)> = reference
        .iter()
        .filter(|e| field(e, "event") == "send" && e["t"].as_i64().unwrap() == finish)
        .filter(|e| field(e, "robot") != robot && [robot, team].contains(&field(e, "to")))
        .map(|e| (field(e, "robot"), field(e, "key")))
        .collect();
    events
        .iter()
        .copied()
        .filter(|e| {
            field(e, "event") != "receive"
                || !contested.contains(&(field(e, "from_robot"), field(e, "key")))
        })
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
/// where `all` (the other run's whole sequence) begins; its last run may
/// have been cut before it repeated.
fn starts<T: PartialEq>(early: &[(T, bool)], all: &[(T, bool)]) -> bool {
    let Some(((last, repeated), before)) = early.split_last() else {
        return true;
    };
    all.len() >= early.len()
        && all[..before.len()] == *before
        && all[before.len()].0 == *last
        && (!repeated || all[before.len()].1)
}

/// Random valid missions (the generator of `support/missiongen.rs`) on
/// random scenarios (battery levels, link faults): the same checks as for the examples, except that a run
/// ends at a cut-off one of the two may reach a little earlier, so each
/// run's behaviour up to [`LATE_MS`] before the end must begin the
/// other's; receptions of the start-up window ([`START_MS`]) and of the
/// heartbeat period after a link fault ends ([`HEAL_MS`]) are left out, and
/// of what others send at the instant a robot finishes ([`finishing`]): a
/// robot that finishes takes no more messages, in C as in the simulator.
fn random_missions(seeds: std::ops::Range<u64>) {
    let catalog = semo::catalog::builtin_catalog();
    let duration = 2000;
    let mut problems = Vec::new();
    for seed in seeds {
        let dir = scratch(&format!("random-{seed}"));
        let mission = dir.join(format!("random{seed}.mission"));
        std::fs::write(&mission, support::missiongen::mission(seed, &catalog)).unwrap();
        let robots = robots_of(&format!("random-{seed}-out"), &mission);
        let scenario = support::missiongen::scenario(seed, &robots, duration, 0.2);
        let scenario_path = dir.join("scenario.json");
        std::fs::write(&scenario_path, &scenario).unwrap();
        let reference = simulate(&mission, &scenario_path);
        let processes = lock_step(&mission, &scenario_path);
        for (robot, c_events) in &processes {
            let c: Vec<&Event> = c_events.iter().collect();
            let s: Vec<&Event> = reference
                .iter()
                .filter(|e| field(e, "robot") == robot)
                .collect();
            let (c, s) = (settled(&c), settled(&s));
            let (c, s) = (healed(&c, &scenario), healed(&s, &scenario));
            let (c, s) = (
                finishing(&c, &reference, robot),
                finishing(&s, &reference, robot),
            );
            let cut = duration - LATE_MS;
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
