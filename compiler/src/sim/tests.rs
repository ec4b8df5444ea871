//! The simulator on the examples: the behaviour `tests/build.rs` asserts of
//! the generated C programs, faults, determinism, and scenario mistakes.

use super::*;
use crate::refine::{RobotProgram, ServiceMachineId, StateId};
use std::path::Path;

#[path = "../../benches/common/mission.rs"]
mod mission;

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

/// The refined programs of an example mission, as `semo simulate` gets them.
pub(super) fn programs(mission: &str) -> Vec<RobotProgram> {
    let (run, id) = crate::host::load_build(&repo(mission), &[]).unwrap();
    refined(&run.analysis(), id)
}

/// The refined programs of a mission's text (the built-in catalog only).
fn programs_of_text(name: &str, text: String) -> Vec<RobotProgram> {
    let mut host = crate::host::AnalysisHost::default();
    let id = crate::diag::FileId(0);
    let kind = crate::workspace::FileKind::Mission;
    host.set_file(id, Some(name.into()), kind, text.into());
    refined(&host.analysis(), id)
}

fn refined(analysis: &crate::host::Analysis, id: crate::diag::FileId) -> Vec<RobotProgram> {
    let build = analysis.build_input(id).expect("the mission was checked");
    let refined = crate::refine::refine_checked(&build.input());
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
            ..options.clone()
        },
    );
    assert_eq!(run.trace_lines(), every_firing.trace_lines());
    assert_eq!(run.end_ms, every_firing.end_ms);
    // Without the messages' trace events, the robots do the same.
    let untraced = simulate(
        programs,
        &scenario,
        &Options {
            untraced_messages: true,
            ..options
        },
    );
    let without_messages = |run: &Run| {
        let lines = run.trace_lines();
        let kept = lines.lines().filter(|l| {
            !l.contains(r#","event":"send","#) && !l.contains(r#","event":"receive","#)
        });
        kept.map(str::to_string).collect::<Vec<_>>()
    };
    assert_eq!(
        without_messages(&run),
        untraced.trace_lines().lines().collect::<Vec<_>>()
    );
    assert_eq!((run.end_ms, run.events), (untraced.end_ms, untraced.events));
    let verdicts = expect::judge(&run, &scenario.expect);
    (run, verdicts)
}

fn modes(run: &Run, robot: &str) -> Vec<String> {
    let r = index_of(run, robot);
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

/// The index of robot `robot` in the run.
fn index_of(run: &Run, robot: &str) -> usize {
    run.robots.iter().position(|(_, n)| n == robot).unwrap()
}

fn leaders(run: &Run, robot: &str) -> Vec<String> {
    let r = index_of(run, robot);
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
    let tb_1 = index_of(&run_, "tb_1");
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
        // Past 5 s: the restarted tb_0 claims at its pass at 5 s (a run
        // ends before its last instant).
        r#"{"duration": 5100, "faults": [{"at": 1200, "kill": "tb_0"}, {"at": 3000, "restart": "tb_0"}]}"#,
        0,
    );
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_1", "tb_0"]);
    // The restarted robot listens before it claims, and the one that took
    // over gives way first, at its first heartbeat after hearing tb_0
    // again, before tb_0 has listened: never two leaders at once.
    // (tb_0's trace: before the kill, then after the restart.)
    assert_eq!(leaders(&run_, "tb_0"), ["tb_0", "tb_0"]);
    assert_eq!(two_leaders(&run_), None);
    let tb_0 = index_of(&run_, "tb_0");
    let claimed = run_
        .trace
        .iter()
        .find(|e| e.robot == tb_0 && e.t >= 3000 && e.field("leader") == Some("tb_0"))
        .unwrap()
        .t;
    let listen = crate::refine::protocol::listen_ms(crate::refine::HEARTBEAT_MS);
    assert!(claimed >= 3000 + listen, "claimed at {claimed}");
}

#[test]
fn a_leader_cut_off_from_the_majority_steps_down_before_the_others_elect() {
    let programs = programs("examples/swarm/patrol_groups.mission");
    let hb = crate::refine::HEARTBEAT_MS;
    // tb_0 leads; from 1200 to 3000 ms it reaches none of the others.
    let (run_, _) = run(
        &programs,
        r#"{"duration": 6000, "faults": [{"from": 1200, "until": 3000, "partition": [["tb_0"], ["tb_1", "tb_2", "ev_0", "ev_1"]]}]}"#,
        0,
    );
    let at = |robot: &str, event: &str, leader: Option<&str>| {
        let r = index_of(&run_, robot);
        run_.trace
            .iter()
            .find(|e| {
                e.robot == r
                    && e.event == event
                    && (leader.is_none() || e.field("leader") == leader)
            })
            .map(|e| e.t)
    };
    let fenced = at("tb_0", "fenced", None).expect("tb_0 steps down");
    let took_over = at("tb_1", "leader", Some("tb_1")).expect("tb_1 takes over");
    // tb_0's lease lapses two heartbeats after the last it heard; the
    // others count it lost after three.
    assert!(
        fenced > 1200 + crate::refine::protocol::lease_ms(hb) - hb,
        "fenced at {fenced}"
    );
    assert!(
        fenced <= took_over,
        "fenced at {fenced}, tb_1 led at {took_over}"
    );
    let lost = crate::refine::protocol::lost_after_ms(hb);
    assert!(took_over > 1200 + lost - hb, "took over at {took_over}");
    let tb_0 = index_of(&run_, "tb_0");
    let heard = run_
        .trace
        .iter()
        .find(|e| e.robot == tb_0 && e.event == "fenced");
    assert_eq!(heard.and_then(|e| e.field("heard")), Some("1 of 3"));
    // Healed, tb_0 follows tb_1 until tb_1 gives way, then leads again.
    assert_eq!(leaders(&run_, "tb_0"), ["tb_0", "tb_1", "tb_0"]);
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_1", "tb_0"]);
    assert_eq!(two_leaders(&run_), None);

    // Without fencing (the lease as long as the others' patience) tb_0
    // would have kept leading while tb_1 led: the check above can fail.
    let lights = |robot: &str, from: i64, until: i64| {
        let r = index_of(&run_, robot);
        run_.trace
            .iter()
            .filter(|e| e.robot == r && e.event == "call_start" && (from..until).contains(&e.t))
            .filter(|e| e.field("service") == Some("light_on"))
            .count()
    };
    assert_eq!(
        lights("tb_0", fenced, 3000),
        0,
        "a fenced robot runs no leader's block"
    );
    assert!(lights("tb_1", took_over, 3000) >= 1);
}

#[test]
fn a_robot_left_alone_of_three_candidates_never_leads() {
    // Two of patrol_groups' three TurtleBots are killed: the survivor hears
    // one of three and never leads (it cannot tell whether it is the one
    // cut off).
    let programs = programs("examples/swarm/patrol_groups.mission");
    let (run_, _) = run(
        &programs,
        r#"{"duration": 3000, "faults": [{"at": 1000, "kill": "tb_1"}, {"at": 1000, "kill": "tb_0"}]}"#,
        0,
    );
    let tb_2 = index_of(&run_, "tb_2");
    let fenced: Vec<_> = run_
        .trace
        .iter()
        .filter(|e| e.robot == tb_2 && e.event == "fenced")
        .map(|e| e.field("heard").unwrap().to_string())
        .collect();
    assert_eq!(fenced, ["1 of 3"]);
    assert_eq!(leaders(&run_, "tb_2"), ["tb_0"]);
}

/// The first instant two live robots both lead by their own traces (a
/// robot leads from its `leader` event naming itself until another one, a
/// `fenced`, or until it is killed), with the two robots. Judged at the end
/// of each instant: within one, the robots' events have no order.
fn two_leaders(run: &Run) -> Option<(i64, String, String)> {
    let mut leading: Vec<bool> = vec![false; run.robots.len()];
    for (i, e) in run.trace.iter().enumerate() {
        let me = &run.robots[e.robot].1;
        match e.event {
            "leader" => leading[e.robot] = e.field("leader") == Some(me.as_str()),
            "fault" | "start" | "fenced" => leading[e.robot] = false,
            _ => {}
        }
        if run.trace.get(i + 1).is_some_and(|next| next.t == e.t) {
            continue;
        }
        let both: Vec<&String> = (0..leading.len())
            .filter(|&r| leading[r])
            .map(|r| &run.robots[r].1)
            .collect();
        if let [a, b, ..] = both.as_slice() {
            return Some((e.t, a.to_string(), b.to_string()));
        }
    }
    None
}

/// `tests/fixtures/elections/<algorithm>`: three robots with battery levels
/// 40, 90 and 60; the one with 90 (tb_1) is killed at 1000 ms and restarted
/// at 2000 ms.
fn election(algorithm: &str) -> Run {
    let programs = programs(&format!(
        "tests/fixtures/elections/{algorithm}/election.mission"
    ));
    let scenario = r#"{"duration": 3000,
        "robots": {"tb_0": {"battery": [{"at": 0, "level": 40}]},
                   "tb_1": {"battery": [{"at": 0, "level": 90}]},
                   "tb_2": {"battery": [{"at": 0, "level": 60}]}},
        "faults": [{"at": 1000, "kill": "tb_1"}, {"at": 2000, "restart": "tb_1"}]}"#;
    let (run_, _) = run(&programs, scenario, 0);
    assert_eq!(two_leaders(&run_), None, "{algorithm}");
    run_
}

#[test]
fn lowest_id_elects_the_first_live_candidate() {
    let run_ = election("lowest_id");
    assert!(
        run_.robots
            .iter()
            .all(|(_, r)| programs_heartbeat(&run_, r) == 100)
    );
    assert_eq!(leaders(&run_, "tb_0"), ["tb_0"]);
    assert_eq!(leaders(&run_, "tb_2"), ["tb_0"]);
    // Restarted, tb_1 listens and then follows tb_0.
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_0"]);
}

#[test]
fn bully_elects_the_last_live_candidate() {
    let run_ = election("bully");
    assert_eq!(leaders(&run_, "tb_0"), ["tb_2"]);
    assert_eq!(leaders(&run_, "tb_1"), ["tb_2", "tb_2"]);
}

#[test]
fn highest_battery_elects_by_the_levels_heartbeats_carry() {
    let run_ = election("highest_battery");
    // Everyone listens one and a half heartbeats (150 ms) first; tb_1 (90)
    // leads, tb_2 (60) takes over when it dies, and gives way to the
    // restarted tb_1 at its first heartbeat after hearing it, before tb_1
    // has listened and claims.
    assert_eq!(leaders(&run_, "tb_0"), ["tb_1", "tb_2", "tb_1"]);
    assert_eq!(leaders(&run_, "tb_2"), ["tb_1", "tb_2", "tb_1"]);
    assert_eq!(leaders(&run_, "tb_1"), ["tb_1", "tb_1"]);
    let first = run_.trace.iter().find(|e| e.event == "leader").unwrap().t;
    assert_eq!(first, 150);
    let heartbeat = run_
        .trace
        .iter()
        .find(|e| e.event == "send" && e.field("key") == Some("Crew.__alive") && e.t > 200)
        .unwrap();
    // A heartbeat's value is text.
    assert!(
        matches!(
            heartbeat.value_json().as_str(),
            r#""leader 90 1""# | r#""member 40 1""# | r#""member 60 1""#
        ),
        "{:?}",
        heartbeat.value
    );
}

/// The terms robots claimed leadership under, each claim once, in the
/// order of its first heartbeat: (robot, term) from the `leader ...`
/// heartbeats they sent.
fn claims(run: &Run, alive_key: &str) -> Vec<(String, i64)> {
    let mut out: Vec<(String, i64)> = Vec::new();
    for e in run.trace.iter().filter(|e| e.event == "send") {
        if e.field("key") != Some(alive_key) {
            continue;
        }
        let value = e.value_json();
        let words: Vec<&str> = value.trim_matches('"').split(' ').collect();
        if let ["leader", _, term] = words.as_slice() {
            let claim = (run.robots[e.robot].1.clone(), term.parse().unwrap());
            if !out.contains(&claim) {
                out.push(claim);
            }
        }
    }
    out
}

/// Terms (docs/groups.md): each robot that begins to lead does so under a
/// term past every one it has heard, so the claims of a run, in order, have
/// rising terms; the restarted tb_0 starts from 0, hears tb_1's term 2, and
/// claims 3 once tb_1 gives way.
#[test]
fn every_new_leader_claims_a_higher_term() {
    let programs = programs("examples/swarm/patrol_groups.mission");
    let (run_, _) = run(
        &programs,
        r#"{"duration": 5500, "faults": [{"at": 1200, "kill": "tb_0"}, {"at": 3000, "restart": "tb_0"}]}"#,
        0,
    );
    assert_eq!(
        claims(&run_, "Guards.__alive"),
        [("tb_0".into(), 1), ("tb_1".into(), 2), ("tb_0".into(), 3)]
    );
    assert_eq!(two_leaders(&run_), None);
}

/// A term heard that is higher than the one a leader leads under deposes
/// it. tb_0's link to tb_1 is slowed by 1 s from 1 s on: tb_1 hears tb_0
/// silent and takes over at its pass at 2 s under term 2 (it hears tb_2 and
/// itself, a majority), while tb_0, which hears tb_2, leads on under term
/// 1 (two leaders: a slow link is outside what fencing bounds). tb_2 learns
/// term 2 from tb_1 and says it; at its pass at 3 s tb_0, deposed, finds no
/// live claimant of term 2 (tb_1's claims are still on the slow link) and
/// leads on only under a new term, 3, which tb_1 and tb_2 then say; tb_1
/// gives way at its pass at 3 s (tb_0, the lowest id, is heard again).
#[test]
fn a_leader_that_hears_a_higher_term_steps_down() {
    let programs = programs("examples/swarm/patrol_groups.mission");
    let (run_, _) = run(
        &programs,
        r#"{"duration": 5000, "faults": [{"from": 1000, "until": 3000, "delay": ["tb_0", "tb_1"], "by": 1000}]}"#,
        0,
    );
    assert_eq!(
        claims(&run_, "Guards.__alive"),
        [("tb_0".into(), 1), ("tb_1".into(), 2), ("tb_0".into(), 3)]
    );
    assert_eq!(leaders(&run_, "tb_1"), ["tb_0", "tb_1", "tb_0"]);
    assert_eq!(leaders(&run_, "tb_2"), ["tb_0"]);
    // Every robot's heartbeats say a term that never goes down, and all end
    // on the last leader's.
    for (r, (_, name)) in run_.robots.iter().enumerate() {
        let terms: Vec<i64> = run_
            .trace
            .iter()
            .filter(|e| e.robot == r && e.event == "send")
            .filter(|e| e.field("key") == Some("Guards.__alive"))
            .map(|e| {
                let value = e.value_json();
                value
                    .trim_matches('"')
                    .rsplit(' ')
                    .next()
                    .unwrap()
                    .parse()
                    .unwrap()
            })
            .collect();
        assert!(terms.windows(2).all(|w| w[0] <= w[1]), "{name}: {terms:?}");
        if name.starts_with("tb_") {
            assert_eq!(terms.last(), Some(&3), "{name}");
        }
    }
}

/// The heartbeat period of a robot's program in a run, from its sends.
fn programs_heartbeat(run: &Run, robot: &str) -> i64 {
    let r = index_of(run, robot);
    let sends: Vec<i64> = run
        .trace
        .iter()
        .filter(|e| e.robot == r && e.event == "send" && e.field("key") == Some("Crew.__alive"))
        .map(|e| e.t)
        .take(3)
        .collect();
    sends[1] - sends[0]
}

#[test]
fn link_faults_lose_and_delay_messages() {
    // (ti and nxt also talk to each other: heartbeats, shared values.)
    let run_robot = |run: &Run, r: usize| run.robots[r].1.clone();
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
        .filter(|e| run_robot(&slow, e.robot) == "irobot")
        .find(|e| e.event == "receive" && e.field("from_robot") == Some("ti"))
        .unwrap();
    assert_eq!(late.t - late.sent_at.unwrap(), 251);
}

/// A receive task held up by a full channel takes, once free, every
/// message that waited behind, in order, until one is held up again (as
/// the generated CommReceive's loop does). It took one: the rest waited
/// behind for ever, unheard (heartbeats among them), and a swarm's backlog
/// grew with the run (290 of the 1,002-robot benchmark's 362 MB).
#[test]
fn messages_behind_a_held_receive_task_are_all_taken() {
    // One team of the benchmark swarm: every robot tells the team its
    // status each second while `Hear` reads one every half second, and the
    // team's heartbeats (it has a leader and groups) come in between.
    let programs = programs_of_text("swarm.mission", mission::generate(1));
    let (run, _) = run(&programs, r#"{"duration": 60000}"#, 0);
    let count = |event: &str, key: &str| {
        (run.trace.iter())
            .filter(|e| e.event == event && e.field("key") == Some(key))
            .count()
    };
    // The team's own messages: each reaches the five others.
    for key in ["Team0.__alive", "Team0.Status"] {
        let (sent, received) = (count("send", key), count("receive", key));
        assert!(sent >= 300, "{key}: {sent} sent");
        assert_eq!(
            received,
            5 * sent,
            "{key}: each of the five others takes each one"
        );
    }
}

#[test]
fn a_sensor_value_no_task_samples_is_a_positioned_warning_with_a_did_you_mean() {
    let programs = programs("examples/scouting/scouting.mission");
    let text =
        "{\"robots\": {\"nxt\": {\"sensors\": [{\"at\": 0, \"value\": \"LOCATOIN\", \"is\": 1}]}}}";
    let scenario = scenario::parse(text, &programs).unwrap();
    let warnings: Vec<_> = scenario
        .warnings
        .iter()
        .map(|w| {
            (
                w.line_col(text),
                w.message.as_str(),
                w.suggestion.as_deref(),
            )
        })
        .collect();
    assert_eq!(
        warnings,
        [(
            (1, 52),
            "robot nxt samples no sensor value \"LOCATOIN\": nothing reads this entry (it samples: COLOR, LOCATION) (did you mean \"LOCATION\"?)",
            Some("LOCATION")
        )]
    );
}

/// A service's `results` are checked against what the service gives back
/// as the robot's type's catalog says (`search`: FOUND, a bool, and WHERE,
/// a location): a value of another type, more values than it gives, and
/// results for a service that gives none are refused where they are
/// written, not taken as none at run time.
#[test]
fn scenario_results_are_checked_against_the_catalog() {
    let programs = programs("tests/fixtures/action_results/survey.mission");
    let with =
        |services: &str| format!("{{\"robots\": {{\"ti\": {{\"services\": {{{services}}}}}}}}}");
    for (services, line_col, message) in [
        (
            r#""search": {"results": [[true, "3,4"], ["yes", "3,4"]]}"#,
            (1, 72),
            "result FOUND of search must be a value of its type (bool), not \"yes\"",
        ),
        (
            r#""search": {"results": [[1, null]]}"#,
            (1, 57),
            "result FOUND of search must be a value of its type (bool), not \"1\"",
        ),
        (
            r#""search": {"results": [[false, null, 3]]}"#,
            (1, 70),
            "service search gives back 2 results (FOUND, WHERE): this call has more values",
        ),
        (
            r#""move": {"ms": 10, "results": [["3,4"]]}"#,
            (1, 63),
            "service move gives nothing back: \"results\" are for a service with results",
        ),
    ] {
        let text = with(services);
        let e = scenario::parse(&text, &programs).unwrap_err();
        assert_eq!(
            (e.line_col(&text), e.message.as_str()),
            (line_col, message),
            "{text}"
        );
    }
    // What the service gives back, fewer values (the rest none) and
    // nulls are read; a service the robot never calls is not checked:
    // nothing reads its entry.
    let good = with(
        r#""search": {"results": [[true, 7], [false], ["true", null]]}, "scatter": {"results": [[1]]}"#,
    );
    let read = scenario::parse(&good, &programs).unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(read.robots[0].results.len(), 2);
}

#[test]
fn scenario_mistakes_point_at_the_value() {
    let programs = programs("examples/scouting/scouting.mission");
    for (text, line_col, message) in [
        (
            "{\n  \"robots\": {\"robot9\": {}}\n}",
            (2, 24),
            "robot \"robot9\" is not in the mission (robots: irobot, ti, nxt) (did you mean \"irobot\"?)",
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
            // The runtime's reader refuses it too (tests/runtime_c.rs): its
            // rounding would not fit an integer.
            "{\"robots\": {\"ti\": {\"battery\": [{\"at\": 0, \"level\": 1e300}]}}}",
            (1, 51),
            "\"level\" must be between -1e15 and 1e15",
        ),
        (
            "{\"colour\": 2}",
            (1, 12),
            "unknown key \"colour\" in a scenario object {\"robots\": ..., \"operator\": ...} (expected one of: version, time_scale, duration, robots, operator, network, faults, expect)",
        ),
        ("{\"robots\": {}", (1, 14), "expected ',' or '}'"),
        (
            "{\"expect\": [{\"eventually\": {\"robot\": \"ti\", \"in\": \"WAIT\"}}]}",
            (1, 50),
            "no mode \"WAIT\" for robot ti (modes: AUTO_MODE, FINISH, RC_MODE, RETURN_MODE, SEARCH_MODE)",
        ),
        (
            "{\"expect\": [{\"always\": {\"not\": {\"robot\": \"ti\", \"in\": \"FINISH\"}, \"robot\": \"ti\"}}]}",
            (1, 74),
            "\"not\" combines conditions: no \"robot\" or \"from\" beside it",
        ),
        (
            "{\"expect\": [{\"leads_to\": [{\"robot\": \"ti\", \"enters\": \"FINISH\"}]}]}",
            (1, 26),
            "\"leads_to\" takes two conditions: [CONDITION, CONDITION]",
        ),
        (
            "{\"expect\": [{\"always\": {\"any\": []}}]}",
            (1, 32),
            "\"any\" needs at least one condition",
        ),
        (
            "{\"expect\": [{\"eventually\": {\"robot\": \"ti\", \"in\": \"FINISH\"}, \"always\": {\"robot\": \"ti\", \"in\": \"FINISH\"}}]}",
            (1, 13),
            "a property is exactly one of \"always\", \"eventually\", \"leads_to\"",
        ),
    ] {
        let e = scenario::parse(text, &programs).unwrap_err();
        assert_eq!(
            (e.line_col(text), e.message.as_str()),
            (line_col, message),
            "{text}"
        );
    }
}

/// `tests/fixtures/group_sync`: the robots drive for `moves` ms (tb_0,
/// tb_1, tb_2), then meet at the group statement (GroupSync, 2 s timeout).
fn group_sync(moves: [i64; 3], faults: &str) -> Run {
    let programs = programs("tests/fixtures/group_sync/sync.mission");
    let robots: Vec<String> = moves
        .iter()
        .enumerate()
        .map(|(i, ms)| format!(r#""tb_{i}": {{"services": {{"move": {ms}}}}}"#))
        .collect();
    let scenario = format!(
        r#"{{"duration": 8000, "robots": {{{}}}, "faults": [{faults}]}}"#,
        robots.join(", ")
    );
    run(&programs, &scenario, 0).0
}

/// When `robot` passed the group statement's start, and how.
fn synced(run: &Run, robot: &str) -> Option<(i64, &'static str)> {
    let r = index_of(run, robot);
    run.trace
        .iter()
        .find(|e| {
            e.robot == r
                && (e.event == "group_sync"
                    || (e.event == "timeout" && e.field("statement") == Some("GroupSync")))
        })
        .map(|e| (e.t, e.event))
}

#[test]
fn group_sync_waits_for_every_member() {
    let run_ = group_sync([100, 700, 1200], "");
    for robot in ["tb_0", "tb_1", "tb_2"] {
        let (t, how) = synced(&run_, robot).unwrap();
        assert_eq!(how, "group_sync", "{robot}");
        // Not before the slowest one arrived (1200 ms), and at once then.
        assert!((1200..=1220).contains(&t), "{robot} met at {t}");
    }
}

#[test]
fn group_sync_does_not_wait_for_a_dead_member() {
    // tb_1 dies on the way: the others meet when tb_2 arrives, without
    // waiting for the timeout.
    let run_ = group_sync([100, 700, 1200], r#"{"at": 300, "kill": "tb_1"}"#);
    assert_eq!(synced(&run_, "tb_1"), None);
    for robot in ["tb_0", "tb_2"] {
        let (t, how) = synced(&run_, robot).unwrap();
        assert_eq!(how, "group_sync", "{robot}");
        assert!((1200..=1220).contains(&t), "{robot} met at {t}");
    }
}

#[test]
fn group_sync_gives_up_after_the_strategys_timeout() {
    // tb_2 is alive but takes 5 s: tb_0 and tb_1 wait 2 s from their own
    // arrival, then go on; tb_2, last, finds them finished (no heartbeat:
    // dead) and goes on at once.
    let run_ = group_sync([100, 700, 5000], "");
    assert_eq!(synced(&run_, "tb_0"), Some((2110, "timeout")));
    assert_eq!(synced(&run_, "tb_1"), Some((2710, "timeout")));
    assert_eq!(synced(&run_, "tb_2"), Some((5000, "group_sync")));
}

/// The (t, rank, size) of every `group` event of `robot` (group services).
fn groups(run: &Run, robot: &str) -> Vec<(i64, String, String)> {
    events(run, robot, "group", &["rank", "size"])
        .into_iter()
        .map(|(t, mut f)| {
            let size = f.pop().unwrap();
            (t, f.pop().unwrap(), size)
        })
        .collect()
}

/// The events of one kind of a robot, as `(t, field values)`.
fn events(run: &Run, robot: &str, event: &str, fields: &[&str]) -> Vec<(i64, Vec<String>)> {
    let r = index_of(run, robot);
    run.trace
        .iter()
        .filter(|e| e.robot == r && e.event == event)
        .map(|e| {
            let values = fields
                .iter()
                .map(|f| e.field(f).unwrap_or_default().to_string())
                .collect();
            (e.t, values)
        })
        .collect()
}

fn ranks(run: &Run, robot: &str) -> Vec<(String, String)> {
    groups(run, robot)
        .into_iter()
        .map(|(_, rank, size)| (rank, size))
        .collect()
}

fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|(r, s)| (r.to_string(), s.to_string()))
        .collect()
}

#[test]
fn group_service_members_learn_rank_and_size() {
    let programs = programs("tests/fixtures/group_service/sweep.mission");
    let peers = crate::refine::PeerId::all(3);
    assert!(
        programs
            .iter()
            .all(|p| p.control.group.iter().copied().eq(peers.clone()))
    );
    let (run_, _) = run(&programs, r#"{"duration": 1000}"#, 0);
    for (i, robot) in ["tb_0", "tb_1", "tb_2"].into_iter().enumerate() {
        let rank = i.to_string();
        assert_eq!(ranks(&run_, robot), pairs(&[(&rank, "3")]), "{robot}");
    }
}

#[test]
fn group_service_redivides_when_a_member_fails_and_returns() {
    let programs = programs("tests/fixtures/group_service/sweep.mission");
    let (run_, _) = run(
        &programs,
        r#"{"duration": 3000, "faults": [{"at": 500, "kill": "tb_1"}, {"at": 1500, "restart": "tb_1"}]}"#,
        0,
    );
    // tb_1 fails: tb_2 moves up to rank 1 of 2; it returns: back to 2 of 3.
    assert_eq!(
        ranks(&run_, "tb_0"),
        pairs(&[("0", "3"), ("0", "2"), ("0", "3")])
    );
    assert_eq!(
        ranks(&run_, "tb_2"),
        pairs(&[("2", "3"), ("1", "2"), ("2", "3")])
    );
    // tb_1's two lives: each starts with the whole group.
    assert_eq!(ranks(&run_, "tb_1"), pairs(&[("1", "3"), ("1", "3")]));
    // The failure is noticed after three silent heartbeats (200 ms each;
    // the last one heard at 400), at the next heartbeat; the return at the
    // first heartbeat after the restarted robot's first.
    let (failed, _, _) = groups(&run_, "tb_2")[1].clone();
    assert!((1000..=1400).contains(&failed), "{failed}");
    let (returned, _, _) = groups(&run_, "tb_2")[2].clone();
    assert!((1500..=1800).contains(&returned), "{returned}");
}

#[test]
fn a_robot_in_no_group_traces_no_group() {
    let programs = programs("tests/fixtures/group_sync/sync.mission");
    assert!(programs.iter().all(|p| p.control.group.is_empty()));
    let (run_, _) = run(&programs, r#"{"duration": 1000}"#, 0);
    assert!(run_.trace.iter().all(|e| e.event != "group"));
}

/// `tests/fixtures/shared`: a value one scout writes is read by the others
/// through its owner; when the owner is killed the next scout owns it and a
/// write of the third reaches it (`docs/shared-information.md`).
#[test]
fn globally_shared_values_live_on_the_owner_and_move_when_it_is_lost() {
    let programs = programs("tests/fixtures/shared/shared.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/shared/shared.scenario.json")).unwrap();
    let (run_, _) = run(&programs, &scenario, 0);
    // `a` owns and writes; `b` and `c` get its value and change mode by it.
    let a_sets = events(&run_, "a", "shared_set", &["key", "owner"]);
    assert!(!a_sets.is_empty());
    assert!(
        a_sets
            .iter()
            .all(|(t, f)| *t < 1500 && f == &["Scouts.NEAR", "a"])
    );
    for reader in ["b", "c"] {
        let got = events(&run_, reader, "shared_value", &["from"]);
        assert!(
            got.iter().any(|(t, f)| *t < 1500 && f == &["a"]),
            "{reader}: {got:?}"
        );
        assert_eq!(modes(&run_, reader)[..2], ["FAR", "NEAR_MODE"], "{reader}");
    }
    // Killed at 1500: `b` takes over three heartbeats after it last heard `a`.
    let hb = crate::refine::HEARTBEAT_MS;
    for robot in ["b", "c"] {
        let owners = events(&run_, robot, "shared_owner", &["owner", "lost"]);
        assert_eq!(owners.len(), 1, "{robot}: {owners:?}");
        assert_eq!(owners[0].1, ["b", "a"], "{robot}");
        assert!(
            (1500..=1500 + 4 * hb + 10).contains(&owners[0].0),
            "{owners:?}"
        );
    }
    // `c` writes 3 at 3000 to the new owner, which takes it and tells `c`.
    let c_sets = events(&run_, "c", "shared_set", &["owner"]);
    assert!(
        c_sets.iter().any(|(t, f)| *t >= 3000 && f == &["b"]),
        "{c_sets:?}"
    );
    let b_takes = events(&run_, "b", "shared_set", &["owner", "from"]);
    assert!(b_takes.iter().any(|(_, f)| f == &["b", "c"]), "{b_takes:?}");
    assert_eq!(modes(&run_, "b"), ["FAR", "NEAR_MODE", "CLOSER"]);
}

/// `tests/fixtures/shared_named`: the strategy names `b` the owner
/// (`<SharedOwner>`): `a`'s write goes to `b`, which tells the team; when `b`
/// is killed the first live robot of the formation order, `a`, owns, and
/// `c`'s write reaches it.
#[test]
fn the_owner_the_strategy_names_holds_the_values_until_it_is_lost() {
    let programs = programs("tests/fixtures/shared_named/shared.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/shared_named/shared.scenario.json")).unwrap();
    let (run_, _) = run(&programs, &scenario, 0);
    let a_sets = events(&run_, "a", "shared_set", &["owner"]);
    assert!(
        a_sets.iter().any(|(t, f)| *t < 1500 && f == &["b"]),
        "{a_sets:?}"
    );
    let b_takes = events(&run_, "b", "shared_set", &["owner", "from"]);
    assert!(b_takes.iter().any(|(_, f)| f == &["b", "a"]), "{b_takes:?}");
    for reader in ["a", "c"] {
        let got = events(&run_, reader, "shared_value", &["from"]);
        assert!(
            got.iter().any(|(t, f)| *t < 1500 && f == &["b"]),
            "{reader}: {got:?}"
        );
        let owners = events(&run_, reader, "shared_owner", &["owner", "lost"]);
        assert_eq!(owners.len(), 1, "{reader}: {owners:?}");
        assert_eq!(owners[0].1, ["a", "b"], "{reader}");
    }
    let c_sets = events(&run_, "c", "shared_set", &["owner"]);
    assert!(
        c_sets.iter().any(|(t, f)| *t >= 3000 && f == &["a"]),
        "{c_sets:?}"
    );
    let a_takes = events(&run_, "a", "shared_set", &["owner", "from"]);
    assert!(a_takes.iter().any(|(_, f)| f == &["a", "c"]), "{a_takes:?}");
    assert_eq!(modes(&run_, "a"), ["FAR", "NEAR_MODE", "CLOSER"]);
    assert_eq!(modes(&run_, "c"), ["FAR", "NEAR_MODE", "CLOSER"]);
}

/// `tests/fixtures/shared_bully`: no `<SharedOwner>`, the team elects by
/// `bully`: its leader, the last robot `c`, owns; killed, the next leader
/// `b` owns and its own write is read by `a`.
#[test]
fn without_a_named_owner_the_teams_leader_owns_and_failover_follows_the_leader() {
    let programs = programs("tests/fixtures/shared_bully/shared.mission");
    let ownership = programs[0]
        .library
        .as_ref()
        .and_then(|l| l.ownership.as_ref())
        .unwrap();
    assert_eq!(
        ownership.rule,
        crate::refine::OwnerRule::Leader(crate::refine::LeaderAlgorithm::Bully)
    );
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/shared_bully/shared.scenario.json")).unwrap();
    let (run_, _) = run(&programs, &scenario, 0);
    let a_sets = events(&run_, "a", "shared_set", &["owner"]);
    assert!(
        a_sets.iter().any(|(t, f)| *t < 1500 && f == &["c"]),
        "{a_sets:?}"
    );
    for robot in ["a", "b"] {
        let owners = events(&run_, robot, "shared_owner", &["owner", "lost"]);
        assert_eq!(owners.len(), 1, "{robot}: {owners:?}");
        assert_eq!(owners[0].1, ["b", "c"], "{robot}");
    }
    let b_sets = events(&run_, "b", "shared_set", &["owner"]);
    assert!(
        b_sets.iter().any(|(t, f)| *t >= 3000 && f == &["b"]),
        "{b_sets:?}"
    );
    let got = events(&run_, "a", "shared_value", &["from"]);
    assert!(
        got.iter().any(|(t, f)| *t >= 3000 && f == &["b"]),
        "{got:?}"
    );
    assert_eq!(modes(&run_, "a"), ["FAR", "NEAR_MODE", "CLOSER"]);
}

/// `tests/fixtures/shared_battery`: the team elects by `highest_battery`:
/// `a` owns at start (no level heard yet); killed, `c` (70 %) follows it,
/// not `b` (40 %, the next in formation order), and `b`'s write reaches it.
#[test]
fn a_lost_owner_is_followed_by_the_fullest_robot_when_the_team_elects_by_battery() {
    let programs = programs("tests/fixtures/shared_battery/shared.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/shared_battery/shared.scenario.json"))
            .unwrap();
    let (run_, _) = run(&programs, &scenario, 0);
    let a_sets = events(&run_, "a", "shared_set", &["owner"]);
    assert!(
        a_sets.iter().any(|(t, f)| *t < 1500 && f == &["a"]),
        "{a_sets:?}"
    );
    for robot in ["b", "c"] {
        let owners = events(&run_, robot, "shared_owner", &["owner", "lost"]);
        assert_eq!(owners.len(), 1, "{robot}: {owners:?}");
        assert_eq!(owners[0].1, ["c", "a"], "{robot}");
        assert_eq!(
            modes(&run_, robot),
            ["FAR", "NEAR_MODE", "CLOSER"],
            "{robot}"
        );
    }
    let c_takes = events(&run_, "c", "shared_set", &["owner", "from"]);
    assert!(c_takes.iter().any(|(_, f)| f == &["c", "b"]), "{c_takes:?}");
}

/// A time-triggered inner task of a service graph fires at most once per
/// period, counted across calls (tests/fixtures/loops/periodic.mission:
/// `sampler`'s Sample every 200 ms, twice per call, `2(Sample) Average`):
/// its first firing in the robot's life at the first call's start, each
/// later one exactly 200 ms after the previous one's start (`release`, the
/// line's time), so the second call waits for its first Sample; the call's
/// service time (50 ms) counts from the iteration's end, and the trace
/// stays in time order. All read from the trace: no wall clock.
#[test]
fn a_time_triggered_inner_task_fires_once_per_period_across_calls() {
    let programs = programs("tests/fixtures/loops/periodic.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/loops/periodic.scenario.json")).unwrap();
    let (run, _) = run(&programs, &scenario, 0);
    let at = |event: &str, task: Option<&str>| -> Vec<i64> {
        run.trace
            .iter()
            .filter(|e| e.event == event && task.is_none_or(|t| e.field("task") == Some(t)))
            .map(|e| e.t)
            .collect()
    };
    let samples = at("graph_fire", Some("Sample"));
    let releases: Vec<i64> = run
        .trace
        .iter()
        .filter(|e| e.event == "graph_fire" && e.field("task") == Some("Sample"))
        .map(|e| e.field("release").unwrap().parse().unwrap())
        .collect();
    assert_eq!(samples, releases, "a firing is traced at its release");
    let starts = at("call_start", None);
    let ends = at("call_end", None);
    let averages = at("graph_fire", Some("Average"));
    assert!(samples.len() >= 6, "{samples:?}");
    let first = starts[0];
    let expected: Vec<i64> = (0..samples.len() as i64).map(|k| first + 200 * k).collect();
    assert_eq!(samples, expected);
    // Each call: its Samples, then Average with the second; its end 50 ms on
    // (but the last one's, which the end of the run cuts short).
    let (cut, ends) = ends.split_last().expect("calls");
    assert_eq!(*cut, run.end_ms, "the call under way ends with the run");
    for (call, end) in ends.iter().enumerate() {
        assert_eq!(averages[call], samples[2 * call + 1]);
        assert_eq!(*end, averages[call] + 50);
    }
    // The second call starts before Sample is due again, and waits.
    assert!(starts[1] < samples[2], "{starts:?} {samples:?}");
    // Average reads the two samples of its call (1 each: nothing read).
    let read: Vec<&str> = run
        .trace
        .iter()
        .filter(|e| e.event == "graph_fire" && e.field("task") == Some("Average"))
        .filter_map(|e| e.field("read"))
        .collect();
    assert!(read.iter().all(|r| *r == "1,1"), "{read:?}");
    assert!(run.trace.windows(2).all(|w| w[0].t <= w[1].t));
}

/// A stop does not cut a service graph's iteration (its channels must hold
/// the next call's tokens): a call timed out at 100 ms while its Sample
/// waits for its period ends when the iteration does (the second Sample and
/// Average at 200 ms), without its service time, and the next call waits
/// for it (tests/fixtures/loops/periodic_timeout.mission).
#[test]
fn a_stop_ends_a_graph_call_when_its_iteration_ends() {
    let programs = programs("tests/fixtures/loops/periodic_timeout.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/loops/periodic.scenario.json")).unwrap();
    let (run, _) = run(&programs, &scenario, 0);
    let lines: Vec<(i64, &str, &str)> = run
        .trace
        .iter()
        .filter(|e| e.event != "start")
        .take(9)
        .map(|e| {
            (
                e.t,
                e.event,
                e.field("task").or(e.field("service")).unwrap_or(""),
            )
        })
        .collect();
    assert_eq!(
        lines,
        [
            (0, "mode", ""),
            (0, "service_start", "S"),
            (0, "call_start", "sampler"),
            (0, "graph_fire", "Sample"),
            (110, "timeout", "sample"),
            (200, "graph_fire", "Sample"),
            (200, "graph_fire", "Average"),
            (200, "call_end", "sampler"),
            (200, "call_start", "sampler"),
        ]
    );
    let samples: Vec<i64> = run
        .trace
        .iter()
        .filter(|e| e.event == "graph_fire" && e.field("task") == Some("Sample"))
        .map(|e| e.t)
        .collect();
    assert_eq!(samples[..4], [0, 200, 400, 600]);
}

/// `semo verify`'s choices made while running (`Sim::set_sensor`,
/// `Sim::give_command`) are exactly the scenario entries its counterexamples
/// write: the same trace, event for event, as the scenario run.
#[test]
fn choices_made_while_running_are_the_scenario_entries_they_replay_as() {
    let programs = programs("examples/scouting/scouting.mission");
    let with_entries = r#"{"duration": 6000,
        "robots": {"ti": {"sensors": [{"at": 0, "value": "LOCATION", "is": "OTHER"},
                                      {"at": 1500, "value": "LOCATION", "is": "5,5"}]},
                   "irobot": {"sensors": [{"at": 500, "value": "LOCATION", "is": "5,5"}]}},
        "operator": [{"at": 3000, "to": "MasterTeam", "value": "RC_CMD", "is": "RC_MODE"}]}"#;
    let (reference, _) = run(&programs, with_entries, 0);
    let empty = Scenario::default();
    let mut sim = Sim::new(&programs, &empty, &Options::default());
    let ti = programs.iter().position(|p| p.robot == "ti").unwrap();
    let irobot = programs.iter().position(|p| p.robot == "irobot").unwrap();
    let mut trace = Vec::new();
    sim.set_sensor(ti, "LOCATION", "OTHER");
    for (at, choice) in [(500, 0), (1500, 1), (3000, 2), (6000, 3)] {
        sim.run_to(at);
        trace.extend(sim.take_trace());
        match choice {
            0 => sim.set_sensor(irobot, "LOCATION", "5,5"),
            1 => sim.set_sensor(ti, "LOCATION", "5,5"),
            2 => sim.give_command("MasterTeam", "USER.RC_CMD", "RC_MODE"),
            _ => {}
        }
    }
    // The reference run stops the robots at its end; compare before that.
    let lines = |events: &[TraceEvent]| -> Vec<String> {
        events
            .iter()
            .filter(|e| e.t < 6000)
            .map(|e| e.to_json(&reference.robots[e.robot].1))
            .collect()
    };
    assert!(trace.iter().any(|e| e.event == "receive"));
    assert_eq!(lines(&trace), lines(&reference.trace));
    // A clone is the same state.
    let copy = sim.clone();
    let memory = Memory::of(&programs);
    assert_eq!(copy.fingerprint(&memory), sim.fingerprint(&memory));
}

/// Robot crashes, a restart after every robot is down, and link faults.
const FAULTS: &str = r#"{
  "network": {"latency": 5, "loss": 0.1},
  "faults": [
    {"from": 300, "until": 1500, "drop": ["irobot", "ti"]},
    {"from": 400, "until": 1100, "delay": ["irobot", "nxt"], "by": 120},
    {"from": 600, "until": 900, "partition": [["ti"], ["nxt"]]},
    {"at": 700, "kill": "nxt"},
    {"at": 1000, "kill": "irobot"},
    {"at": 1000, "kill": "ti"},
    {"at": 1300, "restart": "nxt"},
    {"at": 1600, "kill": "nxt"},
    {"at": 3000, "restart": "ti"}
  ]
}"#;

#[test]
fn a_run_cut_by_until_is_the_start_of_the_whole_run_with_faults() {
    let programs = programs("examples/scouting/scouting.mission");
    let scenario = scenario::parse(FAULTS, &programs).unwrap();
    let options = |until_ms: i64, every_firing: bool| Options {
        until_ms: Some(until_ms),
        seed: 3,
        every_firing,
        ..Options::default()
    };
    let whole = simulate(&programs, &scenario, &options(6000, false));
    for until in [
        300, 700, 701, 1000, 1001, 1300, 1600, 1601, 2000, 2999, 3000, 3001, 4500,
    ] {
        let cut = simulate(&programs, &scenario, &options(until, false));
        let before = |run: &Run| -> Vec<String> {
            run.trace
                .iter()
                .filter(|e| e.t < until)
                .map(|e| e.to_json(&run.robots[e.robot].1))
                .collect()
        };
        assert_eq!(before(&cut), before(&whole), "until {until}");
        // At its end the robots still running stop, and nothing else happens.
        assert!(
            cut.trace
                .iter()
                .filter(|e| e.t >= until)
                .all(|e| e.t == until && ["call_end", "dropped", "stop"].contains(&e.event)),
            "until {until}"
        );
        // Every robot down with a restart to come still lasts the run to
        // its end (it ended at whatever stale event came last).
        assert_eq!(cut.end_ms, until, "until {until}");
        let every = simulate(&programs, &scenario, &options(until, true));
        assert_eq!(every.trace_lines(), cut.trace_lines(), "until {until}");
        assert_eq!(every.end_ms, cut.end_ms, "until {until}");
    }
    // With no restart to come, a run ends when its last robot is down.
    let no_restart = FAULTS.replace(
        r#"{"at": 3000, "restart": "ti"}"#,
        r#"{"at": 3000, "kill": "ti"}"#,
    );
    let scenario = scenario::parse(&no_restart, &programs).unwrap();
    let run = simulate(&programs, &scenario, &options(6000, false));
    assert_eq!(run.end_ms, 1600);
}

#[test]
fn a_streamed_run_is_the_kept_run_and_its_digest_judges_it_alike() {
    let programs = programs("examples/scouting/scouting.mission");
    let expectations = r#""expect": [
        {"robot": "ti", "enters": "RETURN_MODE", "before": 1000},
        {"robot": "nxt", "never_enters": "FINISH"},
        {"robot": "ti", "receives": "USER.RC_CMD", "before": 5},
        {"robot": "ti", "receives": "USER.RC_CMD", "from": "irobot"},"#;
    let scouting = scouting_scenario().replacen(r#""expect": ["#, expectations, 1);
    let faults = FAULTS.replacen(
        '{',
        &format!("{{{expectations} {{\"all_end_in\": \"FINISH\"}}],"),
        1,
    );
    for text in [scouting, faults] {
        let scenario = scenario::parse(&text, &programs).unwrap_or_else(|e| panic!("{e:?}"));
        let options = Options::default();
        let kept = simulate(&programs, &scenario, &options);
        let robots = Run::robots_of(&programs);
        let mut digest = Digest::new(&robots, &scenario.expect);
        let mut lines = String::new();
        let streamed = simulate_into(&programs, &scenario, &options, &mut |e| {
            digest.see(&e);
            lines.push_str(&e.to_json(&robots[e.robot].1));
            lines.push('\n');
        });
        assert!(streamed.trace.is_empty(), "nothing kept");
        assert_eq!(lines, kept.trace_lines());
        assert_eq!(
            (streamed.end_ms, streamed.events),
            (kept.end_ms, kept.events)
        );
        let verdicts = expect::judge(&kept, &scenario.expect);
        let why = |v: &[Verdict]| v.iter().map(|v| (v.met, v.why.clone())).collect::<Vec<_>>();
        assert_eq!(why(&digest.verdicts()), why(&verdicts));
        assert!(verdicts.iter().any(|v| v.met) && verdicts.iter().any(|v| !v.met));
        assert_eq!(
            summary_of(&streamed, &digest, &verdicts),
            summary(&kept, &verdicts)
        );
    }
}

/// Races between plans (`semo verify`'s V005): the base's `Listen` throws
/// in the instant its `Forward` would send the colour on; watching for
/// races notes exactly that one and changes nothing of the run. With one
/// plan relaying and then throwing, there is none.
#[test]
fn a_throw_that_ends_the_mode_before_a_later_plan_sends_is_noted_as_a_race() {
    let races_of = |mission: &str| {
        let programs = programs(mission);
        let scenario = Scenario::default();
        let mut watched = watched_alike(&programs, &scenario, mission, Sim::watch_races);
        let said: Vec<String> = watched
            .take_races()
            .iter()
            .map(|race| {
                let m = &programs[race.robot].control;
                let state = |(s, pc): (ServiceMachineId, StateId)| {
                    m.service(s).states[pc.index()].text.clone()
                };
                format!(
                    "{} at {} in {}: {} before {}",
                    programs[race.robot].robot,
                    race.at,
                    m.mode(race.mode).name,
                    state(race.thrower),
                    state(race.lost)
                )
            })
            .collect();
        said
    };
    assert_eq!(
        races_of("tests/fixtures/verify/plans_race/main.mission"),
        ["base at 10 in RELAY: throw located before send(Carriers, Scouts.COLOR)"]
    );
    assert_eq!(
        races_of("tests/fixtures/verify/clean_relay/main.mission"),
        Vec::<String>::new()
    );
}

/// `mission` run to 2 s with `watch` set up, after checking that watching
/// changes nothing of its trace (the same run without it).
fn watched_alike<'p>(
    programs: &'p [RobotProgram],
    scenario: &'p Scenario,
    mission: &str,
    watch: impl FnOnce(&mut Sim<'p>),
) -> Sim<'p> {
    let mut watched = Sim::new(programs, scenario, &Options::default());
    watch(&mut watched);
    watched.run_to(2_000);
    let mut plain = Sim::new(programs, scenario, &Options::default());
    plain.run_to(2_000);
    let lines = |sim: &mut Sim| -> Vec<String> {
        sim.take_trace().iter().map(|e| format!("{e:?}")).collect()
    };
    assert_eq!(lines(&mut watched), lines(&mut plain), "{mission}");
    watched
}

/// Races between robots (`semo verify`'s V006): both scouts' answers reach
/// the base at 1 ms, north's first; taken the other way round the base
/// would go to LOST, not FOUND. Watching notes exactly that and changes
/// nothing of the run. The same answer from both, answers under keys of
/// their own that the base takes both of, or an answer the base only
/// reports to the operator, are no race.
#[test]
fn two_robots_whose_messages_the_receiver_takes_in_either_order_race() {
    let races_of = |mission: &str, north: &str, south: &str| {
        let programs = programs(mission);
        let text = format!(
            r#"{{"robots": {{"north": {{"sensors": [{{"at": 0, "value": "LOCATION", "is": "{north}"}}]}},
                "south": {{"sensors": [{{"at": 0, "value": "LOCATION", "is": "{south}"}}]}}}}}}"#
        );
        let scenario = scenario::parse(&text, &programs).unwrap_or_else(|e| panic!("{e:?}"));
        // The world's step the race is looked for within (any step holding
        // both arrivals' instant will do).
        let step_ms = 500;
        let mut watched = watched_alike(&programs, &scenario, mission, |sim| {
            sim.watch_message_races(step_ms)
        });
        let said: Vec<String> = watched
            .take_message_races()
            .iter()
            .map(|race| {
                let m = &programs[race.robot].control;
                let arrival = |a: &Arrival| {
                    let value = a.value.as_ref().map(|v| v.as_text()).unwrap_or_default();
                    format!("{}={value} from {}", a.key, programs[a.from].robot)
                };
                let differs = match race.differs {
                    Differs::Mode(ran, other) => format!(
                        "{} not {}",
                        other.map_or("-", |id| m.mode(id).name.as_str()),
                        ran.map_or("-", |id| m.mode(id).name.as_str())
                    ),
                    other => format!("{other:?}"),
                };
                format!(
                    "{} at {}: {} then {}; else {differs}",
                    programs[race.robot].robot,
                    race.at,
                    arrival(&race.first),
                    arrival(&race.second)
                )
            })
            .collect();
        said
    };
    let race = "tests/fixtures/verify/robots_race/main.mission";
    assert_eq!(
        races_of(race, "5,5", "0,0"),
        [
            "base at 1: Scouts.SEEN=YES from north then Scouts.SEEN=NO from south; else LOST not FOUND"
        ]
    );
    assert_eq!(
        races_of(race, "0,0", "5,5"),
        [
            "base at 1: Scouts.SEEN=NO from north then Scouts.SEEN=YES from south; else FOUND not LOST"
        ]
    );
    assert_eq!(races_of(race, "0,0", "1,1"), Vec::<String>::new());
    let commute = "tests/fixtures/verify/robots_commute/main.mission";
    assert_eq!(races_of(commute, "5,5", "0,0"), Vec::<String>::new());
    // The answer taken only reported to the operator: the orders differ in
    // the report alone.
    let report = "tests/fixtures/verify/robots_report/main.mission";
    assert_eq!(races_of(report, "5,5", "0,0"), Vec::<String>::new());
}

/// `always`, `eventually` and `leads_to` on one run of scouting, judged
/// instant by instant (beside the scenario's own expectations), each
/// verdict with its instant; and each written back as JSON reads back the
/// same.
#[test]
fn temporal_expectations_are_judged_instant_by_instant() {
    let programs = programs("examples/scouting/scouting.mission");
    let text = scouting_scenario();
    let expect = r#"
        {"eventually": {"robot": "irobot", "in": "WAIT_MODE"}},
        {"always": {"not": {"all": [{"robot": "ti", "in": "RETURN_MODE"}, {"robot": "irobot", "in": "AUTO_MODE"}]}}},
        {"always": {"robot": "irobot", "in": "AUTO_MODE"}},
        {"leads_to": [{"robot": "irobot", "enters": "WAIT_MODE"}, {"robot": "ti", "enters": "SEARCH_MODE"}]},
        {"leads_to": [{"robot": "ti", "enters": "SEARCH_MODE"}, {"robot": "ti", "enters": "RC_MODE"}]},
        {"eventually": {"any": [{"robot": "nxt", "receives": "USER.RC_CMD", "from": "irobot"}, {"robot": "ti", "in": "RC_MODE"}]}},"#;
    let with = text.replacen("\"expect\": [", &format!("\"expect\": [{expect}"), 1);
    let (run, verdicts) = run(&programs, &with, 1);
    let said: Vec<(bool, String)> = verdicts
        .iter()
        .map(|v| (v.met, format!("{}: {}", v.expectation.kind, v.why)))
        .collect();
    insta::assert_debug_snapshot!(said);
    assert!(run.end_ms > 0);
    // Written back, each reads back the same.
    let scenario = scenario::parse(&with, &programs).unwrap();
    for e in &scenario.expect {
        let again = format!("{{\"expect\": [{}]}}", e.kind.to_json());
        let read = scenario::parse(&again, &programs).unwrap();
        assert_eq!(read.expect[0].kind, e.kind, "{again}");
    }
}

/// The lines of a run that say what a broadcast did: the throws, catches,
/// drops, modes and faults, and the messages that carry the events.
fn broadcast_lines(run: &Run) -> Vec<String> {
    run.trace_lines()
        .lines()
        .filter(|l| {
            [
                "\"throw\"",
                "\"catch\"",
                "\"drop\"",
                "\"mode\"",
                "\"fault\"",
                "__event",
            ]
            .iter()
            .any(|k| l.contains(k))
        })
        .map(str::to_string)
        .collect()
}

/// `throw E broadcast` in a group arm (`tests/fixtures/broadcast/crew`):
/// one `throw` at the thrower, one message to each other robot of its
/// group, each receiver's `catch` (naming the thrower) or `drop` at its next
/// firing; the Ev3 robot, in no group, and the killed tb_2 hear nothing.
#[test]
fn a_broadcast_tells_the_throwers_group_as_the_trace_fixture_says() {
    let programs = programs("tests/fixtures/broadcast/crew.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/broadcast/crew.scenario.json")).unwrap();
    let (run, _) = run(&programs, &scenario, 0);
    let expected =
        std::fs::read_to_string(repo("tests/fixtures/broadcast/crew.trace.jsonl")).unwrap();
    let expected: Vec<&str> = expected.lines().collect();
    assert_eq!(broadcast_lines(&run), expected);
}

/// Eighteen robots broadcast at one instant: each hears seventeen events
/// before its next firing; its queue holds `EVENT_QUEUE` (16), so the last
/// is dropped at once, and the sixteen taken find the robot already in the
/// mode its own throw chose, so they are dropped as not caught.
#[test]
fn broadcast_events_past_the_queue_are_dropped() {
    let programs = programs("tests/fixtures/broadcast/crowd.mission");
    let scenario =
        std::fs::read_to_string(repo("tests/fixtures/broadcast/crowd.scenario.json")).unwrap();
    let (run, _) = run(&programs, &scenario, 0);
    let lines = run.trace_lines();
    for robot in 0..18 {
        let of = |reason: &str| {
            let needle = format!("\"robot\":\"tb_{robot}\",\"event\":\"drop\"");
            lines
                .lines()
                .filter(|l| l.contains(&needle) && l.contains(reason))
                .count()
        };
        assert_eq!(of("too many events"), 1, "tb_{robot}");
        assert_eq!(of("not caught"), crate::refine::EVENT_QUEUE, "tb_{robot}");
        assert_eq!(modes(&run, &format!("tb_{robot}")), ["GO", "HOLD"]);
    }
}

/// A robot cut off by a partition when the event is thrown misses it: a
/// broadcast is not sent again.
#[test]
fn a_partitioned_robot_misses_a_broadcast() {
    let programs = programs("tests/fixtures/broadcast/march.mission");
    let scenario = r#"{"duration": 1500,
        "robots": {"quad_2": {"sensors": [{"at": 600, "value": "obstacle", "is": "true"}]}},
        "faults": [{"from": 500, "until": 700, "partition": [["quad_4"]]}]}"#;
    let (run, _) = run(&programs, scenario, 0);
    for robot in ["quad_0", "quad_1", "quad_2", "quad_3"] {
        assert_eq!(modes(&run, robot), ["MARCH", "AVOID"], "{robot}");
    }
    assert_eq!(modes(&run, "quad_4"), ["MARCH"]);
}

/// The takeover after a kill of the leader tb_0 at `kill` ms, in heartbeat
/// periods: from the last heartbeat tb_0 sent to the first instant another
/// robot traces `leader` naming itself; `None` when tb_0 did not lead when
/// it was killed. Panics when two robots ever lead at once.
fn takeover_after_kill(programs: &[RobotProgram], kill: i64) -> Option<f64> {
    let hb = crate::refine::HEARTBEAT_MS;
    let text = format!(
        r#"{{"duration": {}, "faults": [{{"at": {kill}, "kill": "tb_0"}}]}}"#,
        kill + 10 * hb
    );
    let scenario = scenario::parse(&text, programs).unwrap_or_else(|e| panic!("{e:?}"));
    let run_ = simulate(programs, &scenario, &Options::default());
    assert_eq!(two_leaders(&run_), None, "killed at {kill}");
    let tb_0 = index_of(&run_, "tb_0");
    let before: Vec<_> = run_.trace.iter().filter(|e| e.t < kill).collect();
    let leads = before
        .iter()
        .rfind(|e| e.robot == tb_0 && e.event == "leader")
        .is_some_and(|e| e.field("leader") == Some("tb_0"));
    if !leads {
        return None;
    }
    let last_heartbeat = before
        .iter()
        .rfind(|e| e.robot == tb_0 && e.event == "send" && e.field("key") == Some("Guards.__alive"))
        .expect("a leader heart-beats")
        .t;
    let took_over = run_
        .trace
        .iter()
        .find(|e| {
            e.t >= kill
                && e.event == "leader"
                && e.field("leader") == Some(run_.robots[e.robot].1.as_str())
        })
        .unwrap_or_else(|| panic!("no robot took over after the kill at {kill}"))
        .t;
    Some((took_over - last_heartbeat) as f64 / hb as f64)
}

/// The leader killed at every 10 ms from 1 s to 3 s on the examples: the
/// others elect a new one within three heartbeat periods of its last
/// heartbeat (a peer silent for more than `lost_after_ms`, two periods, is
/// lost, and elections are decided at each heartbeat), and never do two
/// robots lead at once (`docs/groups.md`, "Takeover").
#[test]
fn a_killed_leader_is_replaced_within_three_heartbeats_at_every_kill_instant() {
    let mut slowest = Vec::new();
    for mission in [
        "examples/swarm/patrol_groups.mission",
        "examples/patrol/patrol.mission",
    ] {
        let programs = programs(mission);
        let mut took: Vec<f64> = (1000..=3000)
            .step_by(10)
            .filter_map(|kill| takeover_after_kill(&programs, kill))
            .collect();
        took.sort_by(f64::total_cmp);
        let (min, median, max) = (took[0], took[took.len() / 2], took[took.len() - 1]);
        eprintln!(
            "{mission}: {} kills of the leader, takeover min {min}, median {median}, max {max} heartbeats",
            took.len()
        );
        assert!(
            took.len() >= 150,
            "{mission}: tb_0 led at {} kills",
            took.len()
        );
        slowest.push(max);
    }
    assert!(
        slowest.iter().all(|&max| max <= 3.0),
        "takeover up to {slowest:?} heartbeats"
    );
}

/// The leader tb_0 cut off from the other robots of its team for 1.2 s, at
/// every 10 ms from 1 s to 3 s on the examples: it steps down (`fenced`)
/// no later than another robot begins to lead, so that never do two robots
/// lead at once, and the others' new leader comes within three heartbeat
/// periods of the last heartbeat of tb_0 they heard (`docs/groups.md`,
/// "Fencing" and "Takeover").
#[test]
fn a_leader_cut_off_steps_down_before_another_leads_at_every_partition_instant() {
    let hb = crate::refine::HEARTBEAT_MS;
    for mission in [
        "examples/swarm/patrol_groups.mission",
        "examples/patrol/patrol.mission",
    ] {
        let programs = programs(mission);
        let mut cut = 0;
        for from in (1000..=3000).step_by(10) {
            let text = format!(
                r#"{{"duration": {}, "faults": [{{"from": {from}, "until": {}, "partition": [["tb_0"], ["tb_1", "tb_2", "ev_0", "ev_1"]]}}]}}"#,
                from + 3000,
                from + 1200
            );
            let scenario = scenario::parse(&text, &programs).unwrap_or_else(|e| panic!("{e:?}"));
            let run_ = simulate(&programs, &scenario, &Options::default());
            assert_eq!(two_leaders(&run_), None, "{mission}: cut off at {from}");
            let (tb_0, tb_1) = (index_of(&run_, "tb_0"), index_of(&run_, "tb_1"));
            let leads = run_
                .trace
                .iter()
                .rfind(|e| e.t < from && e.robot == tb_0 && e.event == "leader")
                .is_some_and(|e| e.field("leader") == Some("tb_0"));
            if !leads {
                continue;
            }
            cut += 1;
            // When tb_0 sent the last of its heartbeats that reached tb_1.
            let heard = run_
                .trace
                .iter()
                .rfind(|e| {
                    e.robot == tb_1
                        && e.t <= from + 1200
                        && e.event == "receive"
                        && e.field("key") == Some("Guards.__alive")
                        && e.field("from_robot") == Some("tb_0")
                })
                .and_then(|e| e.sent_at)
                .expect("tb_1 heard tb_0");
            let took_over = run_
                .trace
                .iter()
                .find(|e| e.t >= from && e.robot == tb_1 && e.field("leader") == Some("tb_1"))
                .unwrap_or_else(|| panic!("{mission}: no takeover when cut off at {from}"))
                .t;
            assert!(
                took_over - heard <= 3 * hb,
                "{mission}: cut off at {from}, tb_1 heard tb_0's heartbeat of {heard} and led at {took_over}"
            );
        }
        assert!(cut >= 150, "{mission}: tb_0 led at {cut} partitions");
    }
}

/// The schema's property names at `path` (object keys to follow; `*`: each
/// item of a `oneOf` there, their names together).
fn schema_keys(schema: &json::Value, path: &[&str]) -> Vec<String> {
    let mut at = vec![schema];
    for step in path {
        at = at
            .into_iter()
            .flat_map(|v| match (*step, &v.kind) {
                ("*", json::Kind::Array(items)) => items.iter().collect::<Vec<_>>(),
                (key, _) => v.member(key).into_iter().collect(),
            })
            .collect();
    }
    let mut keys: Vec<String> = at
        .iter()
        .filter_map(|v| v.member("properties"))
        .flat_map(|p| match &p.kind {
            json::Kind::Object(members) => members.iter().map(|(k, _)| k.clone()).collect(),
            _ => Vec::new(),
        })
        .collect();
    keys.sort();
    keys.dedup();
    keys
}

/// Every object of the schema that names properties, by its path.
fn schema_objects(v: &json::Value, path: &mut Vec<String>, found: &mut Vec<String>) {
    match &v.kind {
        json::Kind::Object(members) => {
            if v.member("properties").is_some() {
                found.push(path.join("/"));
            }
            for (key, member) in members {
                path.push(key.clone());
                schema_objects(member, path, found);
                path.pop();
            }
        }
        json::Kind::Array(items) => {
            for item in items {
                path.push("*".into());
                schema_objects(item, path, found);
                path.pop();
            }
        }
        _ => {}
    }
}

/// One description of the format's keys: the editor's JSON Schema (its
/// validation, completion and hover of scenario files) names exactly the
/// keys the reader takes, object by object, and no object the reader does
/// not read.
#[test]
fn the_schema_names_exactly_the_keys_the_reader_takes() {
    use scenario::keys;
    let text = std::fs::read_to_string(repo("vscode-extension/schemas/scenario.schema.json"))
        .expect("the schema is in the repository");
    let schema = json::parse(&text).expect("the schema is JSON");
    let expect: Vec<&str> = keys::PROPERTY
        .iter()
        .chain(keys::EXPECTATION)
        .copied()
        .collect();
    let places: [(&[&str], &[&str]); 11] = [
        (&[], keys::SCENARIO),
        (
            &["properties", "robots", "additionalProperties"],
            keys::ROBOT,
        ),
        (
            &[
                "properties",
                "robots",
                "additionalProperties",
                "properties",
                "sensors",
                "items",
            ],
            keys::SENSOR,
        ),
        (
            &[
                "properties",
                "robots",
                "additionalProperties",
                "properties",
                "battery",
                "items",
            ],
            keys::BATTERY,
        ),
        (
            &[
                "properties",
                "robots",
                "additionalProperties",
                "properties",
                "services",
                "additionalProperties",
                "anyOf",
                "*",
            ],
            keys::SERVICE,
        ),
        (&["properties", "operator", "items"], keys::COMMAND),
        (&["properties", "network"], keys::NETWORK),
        (
            &["properties", "network", "properties", "links", "items"],
            keys::LINK,
        ),
        (
            &["properties", "faults", "items", "oneOf", "*"],
            keys::FAULT,
        ),
        (&["properties", "expect", "items", "oneOf", "*"], &expect),
        (&["definitions", "condition", "oneOf", "*"], keys::CONDITION),
    ];
    for (path, reader) in &places {
        let mut reader: Vec<String> = reader.iter().map(|k| k.to_string()).collect();
        reader.sort();
        assert_eq!(schema_keys(&schema, path), reader, "at {}", path.join("/"));
    }
    let mut found = Vec::new();
    schema_objects(&schema, &mut Vec::new(), &mut found);
    let checked: Vec<String> = places.iter().map(|(path, _)| path.join("/")).collect();
    let unchecked: Vec<&String> = found.iter().filter(|f| !checked.contains(f)).collect();
    assert!(
        unchecked.is_empty(),
        "objects the reader does not read: {unchecked:?}"
    );
}

/// The mistakes the runtime's own JSON reader refused when programs read
/// the scenario at run time (its tests moved here with it gone) are
/// refused by the one reader, at the value, before anything is built
/// (`semo build --scenario`, `semo simulate`).
#[test]
fn the_mistakes_the_runtime_refused_are_refused_at_the_value() {
    let programs = programs("examples/scouting/scouting.mission");
    let nested = format!("{}{}", "[".repeat(40), "]".repeat(40));
    let cases: [(&str, (u32, u32), &str); 18] = [
        (
            "{\n  \"robots\": {\n    \"irobot\": [1,]\n  }\n}",
            (3, 18),
            "expected a JSON value",
        ),
        (
            "{\"robots\": {}} x",
            (1, 16),
            "unexpected text after the scenario object",
        ),
        (
            "{\"time_scale\": 0}",
            (1, 16),
            "\"time_scale\" must be a positive number from 0.000001 (a million times faster) to 1000000",
        ),
        (
            "{\"time_scale\": 1e7}",
            (1, 16),
            "\"time_scale\" must be a positive number from 0.000001 (a million times faster) to 1000000",
        ),
        (
            "{\"duration\": 1.5}",
            (1, 14),
            "\"duration\" must be a whole number of milliseconds",
        ),
        (
            "{\"robots\": {\"ti\": 1, \"ti\": 2}}",
            (1, 22),
            "duplicate key \"ti\"",
        ),
        (
            "{\"operator\": [{\"at\": 1, \"every\": 2, \"to\": \"ti\", \"value\": \"V\", \"is\": \"x\"}]}",
            (1, 15),
            "an operator command needs either \"at\" or \"every\"",
        ),
        (
            "{\"operator\": [{\"every\": 0, \"to\": \"ti\", \"value\": \"V\", \"is\": \"x\"}]}",
            (1, 25),
            "\"every\" must be a whole number of milliseconds above 0",
        ),
        (
            "{\"a\": \"\\ud800\"}",
            (1, 14),
            "unpaired surrogate in \\u escape",
        ),
        (
            "{\"a\": \"tab\there\"}",
            (1, 11),
            "control character in string",
        ),
        (&nested, (1, 34), "nesting deeper than 32 levels"),
        ("", (1, 1), "unexpected end of the file"),
        ("{\"n\": 01}", (1, 7), "malformed number"),
        (
            "{\"robots\": {\"ti\": {\"battery\": [{\"at\": 5, \"level\": 1}, {\"at\": 5, \"level\": 2}]}}}",
            (1, 62),
            "battery levels must be in time order",
        ),
        (
            "{\"robots\": {\"ti\": {\"battery\": [{\"at\": 0, \"level\": \"full\"}]}}}",
            (1, 51),
            "\"level\" must be a number",
        ),
        (
            "{\"faults\": [{\"from\": 5, \"until\": 5, \"drop\": [\"ti\", \"nxt\"]}]}",
            (1, 34),
            "\"until\" must be after \"from\"",
        ),
        (
            "{\"faults\": [{\"from\": 1, \"until\": 5, \"delay\": [\"ti\"], \"by\": 3}]}",
            (1, 46),
            "\"delay\" must name two robots",
        ),
        (
            "{\"faults\": [{\"from\": 1, \"until\": 5, \"partition\": [[\"ti\", 7]]}]}",
            (1, 58),
            "\"partition\" must be a non-empty string shorter than 48 bytes",
        ),
    ];
    for (text, line_col, message) in cases {
        let e = scenario::parse(text, &programs).unwrap_err();
        assert_eq!(
            (e.line_col(text), e.message.as_str()),
            (line_col, message),
            "{text}"
        );
    }
}

/// A robot's compiled world ([`scenario::Scenario::compiled_for`]) holds
/// what its program applies itself: its sensors, battery and loop exits,
/// the run's time scale, and the link faults on its own messages (to the
/// other robot of a drop or delay it is at an end of; to every robot
/// outside its group of a partition); never a process fault, which the
/// coordinator applies from outside, nor another robot's link fault.
#[test]
fn a_robot_s_compiled_world_holds_what_its_program_applies() {
    use crate::refine::{CompiledLink, LinkEffect};
    let programs = programs("examples/scouting/scouting.mission");
    let text = r#"{"time_scale": 0.5, "duration": 900,
        "robots": {"irobot": {"battery": [{"at": 0, "level": 90}, {"at": 100, "level": 80.5}]}},
        "faults": [{"at": 5, "kill": "irobot"},
                   {"from": 1, "until": 5, "drop": ["ti", "irobot"]},
                   {"from": 2, "until": 6, "delay": ["ti", "nxt"], "by": 7},
                   {"from": 3, "until": 9, "partition": [["irobot"], ["ti"]]}]}"#;
    let scenario = scenario::parse(text, &programs).unwrap();
    let irobot = programs.iter().find(|p| p.robot == "irobot").unwrap();
    let world = scenario.compiled_for(irobot);
    assert_eq!(
        (world.time_scale, world.duration_ms, &world.battery[..]),
        (Some(0.5), Some(900), &[(0, 90.0), (100, 80.5)][..])
    );
    let link = |effect, from, until, robots: &[&str]| CompiledLink {
        effect,
        from,
        until,
        robots: robots.iter().map(|r| r.to_string()).collect(),
    };
    assert_eq!(
        world.links,
        [
            link(LinkEffect::Lost, 1, 5, &["ti"]),
            link(LinkEffect::Lost, 3, 9, &["ti", "nxt"]),
        ]
    );
    let nxt = programs.iter().find(|p| p.robot == "nxt").unwrap();
    assert_eq!(
        scenario.compiled_for(nxt).links,
        [
            link(LinkEffect::Delayed(7), 2, 6, &["ti"]),
            // No group is one more: nxt is cut from both.
            link(LinkEffect::Lost, 3, 9, &["irobot", "ti"]),
        ]
    );
}

/// A robot's compiled commands are those to it and to its team, in the
/// file's order, and every robot's world is the same built for the fleet
/// at once (`compiled_for_each`, one lookup) as for it alone.
#[test]
fn a_robot_s_compiled_commands_keep_the_file_s_order_across_robot_and_team() {
    let programs = programs("examples/scouting/scouting.mission");
    let text = r#"{"operator": [
        {"at": 3, "to": "irobot", "value": "RC_CMD", "is": "A"},
        {"at": 1, "to": "MasterTeam", "value": "RC_CMD", "is": "B"},
        {"at": 2, "to": "ti", "value": "RC_CMD", "is": "C"},
        {"at": 0, "to": "irobot", "value": "RC_CMD", "is": "D"}],
        "faults": [{"from": 3, "until": 9, "partition": [["irobot", "ti"], ["ti"]]}]}"#;
    let scenario = scenario::parse(text, &programs).unwrap();
    let irobot = programs.iter().find(|p| p.robot == "irobot").unwrap();
    let values: Vec<String> = (scenario.compiled_for(irobot).operator.iter())
        .map(|c| c.value.clone())
        .collect();
    assert_eq!(values, ["A", "B", "D"]);
    let each = scenario.compiled_for_each(&programs);
    for (p, world) in programs.iter().zip(&each) {
        assert_eq!(world, &scenario.compiled_for(p), "{}", p.robot);
    }
    // A robot named in two groups is in the first: ti is with irobot.
    let ti = programs.iter().position(|p| p.robot == "ti").unwrap();
    assert_eq!(each[ti].links[0].robots, ["nxt"]);
}
