//! A mixed fleet elects a leader and fails over (issue 35): one crew with
//! one robot per board kind (`tests/fixtures/board_election/`): `lm` on the
//! TI Stellaris LM3S6965 and `st` on the ST STM32F405, each in QEMU with its
//! link (the second serial port) served on a TCP port, both bridged to a
//! private mosquitto by one `semo gateway` (a `--link` each), and `lx`, a
//! `linux-sim` process on the same broker. One `semo build --sim` builds
//! each robot for the platform the project file names. The election is
//! `lowest_id`: lm, the first in formation order, leads; its QEMU is killed
//! once all three follow it and st and lx have heard its claim, and st, the
//! next, takes over (under a higher term).
//!
//! What must hold, from the robots' traces: every robot's leaders in order
//! (its `leader` events) are the ones `semo simulate` gives it on the same
//! mission and scenario with lm killed; every live robot follows lm before
//! the kill and st after it; st claims only after the last heartbeat it
//! heard from lm; and at no instant do two robots each believe they lead.
//! Instants are the traces' mission times, each robot's put on one clock
//! by its mission time 0: a board's is the gateway's welcome (the instant
//! its `start` line was read, at or after it was written), the Linux
//! robot's its `--start-at`; lm leads until the instant its kill returned
//! (after it died). st's last status, kept by the broker, says its counted
//! group as its trace's last `allocated` does, and the gateway's welcome as
//! its `started`. What is compared is orders, never durations:
//! the deadline only ends a test that would otherwise hang.
//!
//! Skipped with a message without arm-none-eabi-gcc, qemu-system-arm or
//! mosquitto, unless `SEMO_CORTEX_M_TESTS=require` / `SEMO_MQTT_TESTS=require`
//! (CI), where a missing tool fails.

mod support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};
use support::mqtt::{Fleet, Started};
use support::qemu::{self, Board, LM3S6965, Line, STM32F405};
use support::robots::{self, Event, field};

/// A hang guard, not a timing tolerance.
const LIMIT: Duration = Duration::from_secs(90);

fn fixture() -> PathBuf {
    support::repo_root().join("tests/fixtures/board_election")
}

fn mission() -> PathBuf {
    fixture().join("election.mission")
}

fn scenario() -> PathBuf {
    fixture().join("election.scenario.json")
}

/// The board robots, each on its board kind; `lx` is the Linux one.
const BOARDS: [(&str, Board); 2] = [("lm", LM3S6965), ("st", STM32F405)];
const LINUX: &str = "lx";

/// `semo build --sim` of the mission with its scenario into `out`: each
/// robot for its own platform (the project file's `[build.targets]`); the
/// boards made with arm-none-eabi-gcc and the Linux robot with gcc and
/// MQTT, warnings as errors. Each robot's folder.
fn build(out: &Path) -> BTreeMap<String, PathBuf> {
    let (mission, scenario, out_arg) = (
        mission().display().to_string(),
        scenario().display().to_string(),
        out.display().to_string(),
    );
    let built = support::semo_in(
        &support::repo_root(),
        &[
            "build",
            &mission,
            "--sim",
            "--scenario",
            &scenario,
            "-o",
            &out_arg,
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let folders: BTreeMap<String, PathBuf> = robots::robot_folders(out)
        .into_iter()
        .map(|f| (support::mqtt::robot_name(&f), f))
        .collect();
    assert_eq!(
        folders.keys().collect::<Vec<_>>(),
        ["lm", "lx", "st"],
        "{}",
        built.stdout
    );
    let targets = BOARDS
        .iter()
        .map(|(robot, board)| (*robot, board.target))
        .chain([(LINUX, "linux-sim")]);
    for (robot, target) in targets {
        let said = format!("target {target} from semo.toml's `[build.targets] {robot}` (--sim)");
        assert!(
            built
                .stdout
                .lines()
                .any(|l| l.starts_with(&format!("Crew/{robot}: ")) && l.contains(&said)),
            "{robot}: {said}\n{}",
            built.stdout
        );
    }
    for (robot, _) in BOARDS {
        let folder = &folders[robot];
        let makefile = std::fs::read_to_string(folder.join("Makefile")).unwrap();
        assert!(
            makefile.contains("-DSEMO_LINK "),
            "{robot} messages its crew: built with the link\n{makefile}"
        );
        robots::make_board(folder);
    }
    let made = Command::new("make")
        .args([
            "-s",
            "-j2",
            "CC=gcc",
            &format!("CFLAGS={}", robots::PEDANTIC),
            "TRANSPORT=mqtt",
        ])
        .current_dir(&folders[LINUX])
        .output()
        .expect("make runs");
    let stderr = String::from_utf8_lossy(&made.stderr);
    assert!(
        made.status.success() && !stderr.contains("warning"),
        "{LINUX}: {stderr}"
    );
    folders
}

/// A trace's lines that are whole events: a line cut short (by a kill, or
/// a file read while it is written) is left out.
fn whole_events<'a>(lines: impl IntoIterator<Item = &'a str>) -> Vec<Event> {
    lines
        .into_iter()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect()
}

/// The leaders a robot followed or was, in order (its `leader` events), a
/// leader named again after a `fenced` once: a lease lapsed for a moment
/// and held again on a loaded machine is timing, not another leader.
fn leaders(trace: &[Event]) -> Vec<String> {
    let mut named: Vec<String> = trace
        .iter()
        .filter(|e| field(e, "event") == "leader")
        .map(|e| field(e, "leader").to_string())
        .collect();
    named.dedup();
    named
}

fn t(event: &Event) -> u64 {
    event["t"].as_u64().expect("a mission time")
}

/// When `robot` believed it led, on the common clock: from each `leader`
/// event naming itself to its next `leader` or `fenced` event, or else to
/// `end` (its `stop`, or its kill). `origin` is its mission time 0 on that
/// clock.
fn leading_spans(robot: &str, trace: &[Event], origin: u64, end: u64) -> Vec<(u64, u64)> {
    let mut spans = Vec::new();
    let mut since = None;
    for e in trace {
        let at = origin + t(e);
        match field(e, "event") {
            "leader" | "fenced" => {
                if let Some(from) = since.take() {
                    spans.push((from, at));
                }
                if field(e, "event") == "leader" && field(e, "leader") == robot {
                    since = Some(at);
                }
            }
            _ => {}
        }
    }
    if let Some(from) = since {
        spans.push((from, end.max(from)));
    }
    spans
}

/// `semo gateway` for both boards' links, its standard error in `log`.
fn gateway(fleet: &Fleet, ports: &BTreeMap<&str, u16>, log: &Path) -> std::process::Child {
    let mut command = Command::new(env!("CARGO_BIN_EXE_semo"));
    command.arg("gateway").arg(mission());
    for (robot, port) in ports {
        command.args(["--link", &format!("{robot}=tcp:127.0.0.1:{port}")]);
    }
    command
        .args(["--broker", &fleet.url()])
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(log).expect("a log file"))
        .spawn()
        .expect("semo gateway starts")
}

#[test]
fn one_robot_per_board_kind_elects_one_leader_and_fails_over_when_its_qemu_is_killed() {
    let test = "one_robot_per_board_kind_elects_one_leader_and_fails_over_when_its_qemu_is_killed";
    if !robots::board_tools_present(test) {
        return;
    }
    let Some(mut fleet) = Fleet::start("board-election") else {
        return;
    };
    let folders = build(&fleet.out.join("robots"));
    let scenario = scenario();

    // Both boards, then the gateway for both: it opens their links once the
    // broker has its subscriptions, and each board's mission time starts at
    // its welcome.
    let (tx, rx) = mpsc::channel::<Line>();
    let mut ports = BTreeMap::new();
    let mut qemus = BTreeMap::new();
    for (robot, board) in BOARDS {
        let port = support::mosquitto::free_port();
        let elf = folders[robot].join(format!("{robot}.elf"));
        let child = qemu::spawn(&elf, board, port, robot, tx.clone());
        ports.insert(robot, port);
        qemus.insert(robot, fleet.processes.push(child));
    }
    drop(tx);
    let gateway_log = fleet.out.join("gateway.stderr");
    let before_gateway = qemu::unix_ms();
    let gateway = fleet.processes.push(gateway(&fleet, &ports, &gateway_log));

    // The boards' lines as they come; lx started at the first board's
    // start, its mission time 0 that board's; lm's QEMU killed once every
    // robot follows it. The Linux robot's trace file is read between lines.
    let mut lines: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut origins: BTreeMap<String, u64> = BTreeMap::new();
    let mut linux: Option<Started> = None;
    let mut killed_at = None;
    let end = Instant::now() + LIMIT;
    loop {
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(line) => {
                let robot = line.robot.clone();
                if !origins.contains_key(&robot)
                    && let Some(start) = whole_events([line.text.as_str()]).first()
                {
                    assert_eq!(field(start, "event"), "start", "{robot}: {start:?}");
                    let origin = line.read_at_unix_ms - t(start);
                    origins.insert(robot.clone(), origin);
                    if linux.is_none() {
                        let start_at = origin.to_string();
                        let args = ["--time-scale", "1", "--start-at", start_at.as_str()];
                        let started = spawn_linux(&mut fleet, &folders[LINUX], &args);
                        origins.insert(LINUX.into(), origin);
                        linux = Some(started);
                    }
                }
                lines.entry(robot).or_default().push(line.text);
            }
            Err(RecvTimeoutError::Timeout) => {}
            // Both boards' traces ended: st stopped, lm killed (or stopped).
            Err(RecvTimeoutError::Disconnected) => break,
        }
        assert!(
            Instant::now() < end,
            "the boards' traces waited past {LIMIT:?}: {lines:#?}\nthe gateway said:\n{}",
            std::fs::read_to_string(&gateway_log).unwrap_or_default()
        );
        if killed_at.is_none()
            && let Some(started) = &linux
        {
            let lx_trace = std::fs::read_to_string(&started.trace).unwrap_or_default();
            // Every robot counts its peers alive at its start, so following
            // lm at first says nothing of the link: each follows lm and has
            // heard its claim (a heartbeat saying `leader`) through the
            // gateway and the broker, and lm has heard both.
            let heard = |trace: &[Event], from: &str, leads: bool| {
                trace.iter().any(|e| {
                    field(e, "event") == "receive"
                        && field(e, "from_robot") == from
                        && field(e, "key") == "Crew.__alive"
                        && (!leads || field(e, "value").starts_with("leader "))
                })
            };
            let board = |robot: &str| {
                whole_events(lines.get(robot).into_iter().flatten().map(String::as_str))
            };
            let (lm, st, lx) = (board("lm"), board("st"), whole_events(lx_trace.lines()));
            let follows_lm =
                |trace: &[Event]| leaders(trace).last().map(String::as_str) == Some("lm");
            let all_follow = [&lm, &st, &lx].into_iter().all(|t| follows_lm(t))
                && heard(&st, "lm", true)
                && heard(&lx, "lm", true)
                && heard(&lm, "st", false)
                && heard(&lm, "lx", false);
            if all_follow {
                fleet.processes.kill(qemus["lm"]);
                killed_at = Some(qemu::unix_ms());
            }
        }
    }
    let killed_at = killed_at.unwrap_or_else(|| {
        panic!(
            "the three robots never all followed lm: {lines:#?}\nthe gateway said:\n{}",
            std::fs::read_to_string(&gateway_log).unwrap_or_default()
        )
    });
    let linux = linux.expect("the Linux robot started");
    let mut traces: BTreeMap<String, Vec<Event>> = BTreeMap::new();
    traces.insert(LINUX.into(), fleet.finish(&linux, "board"));
    fleet.processes.wait_success(qemus["st"], "QEMU (st)");
    fleet.processes.kill(gateway);
    for (robot, text) in &lines {
        std::fs::write(
            fleet.out.join(format!("{robot}.board.jsonl")),
            text.join("\n"),
        )
        .unwrap();
        traces.insert(robot.clone(), whole_events(text.iter().map(String::as_str)));
    }
    // Only lm's last line may be cut short (by its kill).
    assert!(
        lines["lm"].len() - traces["lm"].len() <= 1 && lines["st"].len() == traces["st"].len(),
        "{lines:#?}"
    );
    for robot in ["st", LINUX] {
        assert_eq!(
            traces[robot].last().map(|e| field(e, "event")),
            Some("stop"),
            "{robot} runs to its end: {:#?}",
            traces[robot]
        );
    }
    let gateway_said = std::fs::read_to_string(&gateway_log).unwrap();
    assert!(
        gateway_said.contains("lm: link closed"),
        "the gateway sees lm's board go: {gateway_said}"
    );

    // The leaders each robot followed, as in the simulator with lm killed
    // once the crew follows it.
    let mut faulted: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&scenario).unwrap()).unwrap();
    faulted["faults"] = serde_json::json!([{"at": 1500, "kill": "lm"}]);
    let faulted_path = fleet.out.join("kill.scenario.json");
    std::fs::write(&faulted_path, faulted.to_string()).unwrap();
    let simulated = support::simulate_trace(&mission(), &faulted_path, "sim");
    assert_eq!(simulated.code, 0, "{}", simulated.stderr);
    let simulated = whole_events(simulated.stdout.lines());
    for (robot, trace) in &traces {
        let of_robot: Vec<Event> = simulated
            .iter()
            .filter(|e| field(e, "robot") == robot)
            .cloned()
            .collect();
        assert_eq!(
            leaders(trace),
            leaders(&of_robot),
            "{robot}'s leaders on its board (or Linux) and in `semo simulate`"
        );
    }
    assert_eq!(leaders(&traces["lm"]), ["lm"]);
    for robot in ["st", LINUX] {
        assert_eq!(leaders(&traces[robot]), ["lm", "st"], "{robot}");
    }

    // st claims only once lm has gone silent: after the last heartbeat it
    // heard from lm (one trace, its own order).
    let st = &traces["st"];
    let claim = st
        .iter()
        .position(|e| field(e, "event") == "leader" && field(e, "leader") == "st")
        .expect("st leads");
    let heard_from = |e: &Event, robot: &str| {
        field(e, "event") == "receive"
            && field(e, "from_robot") == robot
            && field(e, "key") == "Crew.__alive"
    };
    let heard_lm = |e: &Event| heard_from(e, "lm");
    let last_heard = st
        .iter()
        .rposition(heard_lm)
        .expect("st hears lm's heartbeats");
    assert!(
        last_heard < claim,
        "st claims after lm's last heartbeat: {st:#?}"
    );
    assert!(
        traces[LINUX].iter().any(heard_lm) && traces[LINUX].iter().any(|e| heard_from(e, "st")),
        "lx hears both boards' heartbeats, through the gateway and the broker"
    );

    // st leads under a new term, above the one lm led under (docs/groups.md,
    // "Terms"), as lx heard their heartbeats.
    let terms_led = |from: &str| -> Vec<u64> {
        traces[LINUX]
            .iter()
            .filter(|e| heard_from(e, from) && field(e, "value").starts_with("leader "))
            .map(|e| {
                let value = field(e, "value");
                value
                    .rsplit(' ')
                    .next()
                    .unwrap()
                    .parse()
                    .unwrap_or_else(|_| panic!("{e:?}"))
            })
            .collect()
    };
    let (lm_terms, st_terms) = (terms_led("lm"), terms_led("st"));
    assert!(
        !lm_terms.is_empty()
            && !st_terms.is_empty()
            && lm_terms.iter().max() < st_terms.iter().min(),
        "lm led under {lm_terms:?}, st under {st_terms:?}"
    );

    // At no instant do two robots each believe they lead.
    let mut spans = Vec::new();
    for (robot, trace) in &traces {
        let origin = origins[robot];
        let end = if robot == "lm" {
            killed_at
        } else {
            origin + t(trace.last().unwrap())
        };
        for span in leading_spans(robot, trace, origin, end) {
            spans.push((span, robot.as_str()));
        }
    }
    spans.sort();
    for (i, ((from_a, until_a), a)) in spans.iter().enumerate() {
        for ((from_b, until_b), b) in &spans[i + 1..] {
            assert!(
                a == b || until_a <= from_b || until_b <= from_a,
                "{a} and {b} both lead: {spans:?}"
            );
        }
    }
    let mut leaders_in_order: Vec<&str> = spans.iter().map(|(_, robot)| *robot).collect();
    leaders_in_order.dedup();
    assert_eq!(leaders_in_order, ["lm", "st"], "{spans:?}");
    let st_claim = spans
        .iter()
        .find(|(_, robot)| *robot == "st")
        .map(|((from, _), _)| *from)
        .unwrap();
    eprintln!(
        "lm led from {} ms (on lm's clock); killed; st led {} ms after the kill",
        spans[0].0.0 - origins["lm"],
        st_claim.saturating_sub(killed_at)
    );
    for (robot, trace) in &traces {
        let refused: Vec<&Event> = trace
            .iter()
            .filter(|e| matches!(field(e, "event"), "reject" | "comm_error"))
            .collect();
        assert!(refused.is_empty(), "{robot}: {refused:?}");
    }

    // st's last status, retained at the broker, says its counted group as
    // a Linux robot's does (the group of its last `allocated`, with the
    // robots it counted alive then), and the wall-clock time the gateway
    // welcomed it as its `started` (a board has no clock).
    let status = retained_status(&fleet, "st");
    let allocated = traces["st"]
        .iter()
        .rfind(|e| field(e, "event") == "allocated")
        .expect("st takes a counted group");
    assert_eq!(status["state"], "stopped", "{status}");
    assert_eq!(
        status["groups"],
        format!("{}={}", field(allocated, "name"), field(allocated, "alive")),
        "{status}"
    );
    let started: u64 = status["started"].as_str().unwrap().parse().unwrap();
    assert!(
        (before_gateway..=killed_at).contains(&started),
        "st was welcomed after the gateway started and before lm's kill (which waited for st's heartbeats): {status}"
    );
}

/// The status the broker keeps for `robot` (retained), as JSON.
fn retained_status(fleet: &Fleet, robot: &str) -> serde_json::Value {
    let mut options = rumqttc::MqttOptions::new("status-reader", "127.0.0.1", fleet.port);
    options.set_keep_alive(Duration::from_secs(10));
    let (client, mut connection) = rumqttc::Client::new(options, 16);
    client
        .subscribe(
            format!("semo/+/+/status/{robot}"),
            rumqttc::QoS::AtLeastOnce,
        )
        .unwrap();
    let end = Instant::now() + LIMIT;
    for event in connection.iter() {
        assert!(Instant::now() < end, "no retained status of {robot}");
        if let Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) = event {
            return serde_json::from_slice(&p.payload).expect("a status is JSON");
        }
    }
    panic!("the broker closed before {robot}'s status")
}

/// The Linux robot on the fleet's broker (`--transport mqtt`), its trace
/// `lx.board.jsonl` in the scratch folder.
fn spawn_linux(fleet: &mut Fleet, folder: &Path, extra: &[&str]) -> Started {
    let trace = fleet.out.join(format!("{LINUX}.board.jsonl"));
    let child = robots::robot_command(folder, &trace, 1)
        .args(fleet.transport_args())
        .args(extra)
        .stderr(Stdio::piped())
        .spawn()
        .expect("the Linux robot starts");
    Started {
        robot: LINUX.into(),
        trace,
        index: fleet.processes.push(child),
    }
}
