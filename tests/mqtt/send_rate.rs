//! One robot's send path at QoS 1 (issue 34, item 5), as a user reaches
//! it: a generated talker whose mode runs `PLANS` plans, each sending
//! numbered messages in one service body (`Talkers.N = <plan>·10⁶ + i`),
//! built with `semo build` and `make TRANSPORT=mqtt`, run against a private
//! mosquitto, and a `mosquitto_sub` that records every message the broker
//! forwards (its arrival time and payload). Several plans because one
//! region takes at most 64 steps per control firing (10 ms,
//! `codegen::control::STEPS_PER_FIRING`): one plan alone could not send
//! more than 6,400 messages a second whatever the transport.
//!
//! Asserted (deterministic): every send reaches the subscriber once, in the
//! order the robot's trace says it sent them, with no `comm_error`.
//! Measured (`stress_send_rate_and_memory`, ignored: real time on a shared
//! machine): the robot's rate next to `mosquitto_pub -q 1 -l`'s on the same
//! broker in the same run, each as the subscriber sees it, and the robot's
//! peak RSS (`VmHWM`) over plain MQTT, over TLS and with `--transport udp`
//! (the same program: what loading libmosquitto costs by itself).

use super::support;
use super::support::mqtt::{Fleet, Started};
use super::support::robots::{Event, field};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// The mission's file name (its topics' `<mission>` level).
const MISSION: &str = "send_rate";

/// A talker with `plans` plans of `per_plan` numbered sends each, all in
/// one mode, and a listener team (never started: the subscriber listens on
/// its topics).
pub fn rate_mission(plans: usize, per_plan: usize) -> String {
    let mut text = String::from(
        "# One talker sending numbered messages as fast as its plans let it\n# (tests/mqtt/send_rate.rs).\n{\n  Talkers: TIEvalbot talker\n  Listeners: TIEvalbot listener\n}\n\n",
    );
    for plan in 0..plans {
        text.push_str(&format!("Talkers.Send{plan}.Burst{plan} {{\n"));
        for i in 0..per_plan {
            text.push_str(&format!(
                "  send(Listeners, Talkers.N = {})\n",
                plan * 1_000_000 + i
            ));
        }
        text.push_str("}\n\n");
    }
    text.push_str(
        "Listeners.Hear.All {\n  receive(Talkers, Talkers.N)\n} repeat()\n\nTalkers.TALK {\n",
    );
    for plan in 0..plans {
        text.push_str(&format!("  set(Send{plan}, Burst{plan})\n"));
    }
    text.push_str(
        "}\n\nListeners.HEAR {\n  set(Hear, All)\n}\n\nTalkers.main {\n  default: mode = TALK\n}\n\nListeners.main {\n  default: mode = HEAR\n}\n",
    );
    text
}

/// Writes the mission and builds its robots with MQTT (`cflags`), the
/// talker's folder.
pub fn build_talker(fleet: &Fleet, plans: usize, per_plan: usize, cflags: &str) -> PathBuf {
    let mission = fleet.out.join(format!("{MISSION}.mission"));
    std::fs::write(&mission, rate_mission(plans, per_plan)).unwrap();
    let folders = support::mqtt::build_with(&mission, &fleet.out.join("built"), &[], "gcc", cflags);
    support::mqtt::folder_of(&folders, "talker")
}

/// A scenario long enough for every send: the talker stops by itself once
/// its plans are done (its control task finishes).
pub fn long_scenario(fleet: &Fleet) -> PathBuf {
    let path = fleet.out.join("send_rate.scenario.json");
    std::fs::write(&path, r#"{"version": 1, "duration": 120000}"#).unwrap();
    path
}

/// A message as the subscriber saw it.
pub struct Arrival {
    /// Unix seconds (mosquitto_sub's `%U`).
    pub at: f64,
    pub topic: String,
    pub payload: Vec<u8>,
}

/// `mosquitto_sub` on every topic of the mission (QoS 1), its lines read
/// by a thread.
pub struct Subscriber {
    child: Child,
    lines: mpsc::Receiver<Arrival>,
}

const PROBE: &str = "semo/send_rate/probe";
/// The talker's messages to its listeners' team (`<scope>/<team>/<key>/<from
/// team>/<from robot>`), not its status.
const TO_LISTENERS: &str = "/Listeners/Talkers.N/Talkers/talker";

impl Subscriber {
    /// Starts it and waits until it hears a probe (so that it is
    /// subscribed before anything it must count is sent).
    pub fn start(port: u16) -> Subscriber {
        let mut child = Command::new("mosquitto_sub")
            .args(["-h", "127.0.0.1", "-p", &port.to_string(), "-q", "1"])
            .args(["-t", &format!("semo/{MISSION}/#"), "-F", "%U %t %x"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("mosquitto_sub runs (Debian mosquitto-clients)");
        let stdout = child.stdout.take().unwrap();
        let (sender, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                let mut parts = line.splitn(3, ' ');
                let (Some(at), Some(topic), Some(hex)) = (parts.next(), parts.next(), parts.next())
                else {
                    continue;
                };
                let payload = (0..hex.len() / 2)
                    .filter_map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok())
                    .collect();
                let arrival = Arrival {
                    at: at.parse().unwrap_or(0.0),
                    topic: topic.to_string(),
                    payload,
                };
                if sender.send(arrival).is_err() {
                    break;
                }
            }
        });
        let subscriber = Subscriber { child, lines };
        for _ in 0..100 {
            publish_probe(port);
            // A status an earlier run left retained may come first.
            while let Ok(arrival) = subscriber.lines.recv_timeout(Duration::from_millis(100)) {
                if arrival.topic == PROBE {
                    return subscriber;
                }
            }
        }
        panic!("mosquitto_sub never heard a probe on port {port}");
    }

    /// The next `count` messages on a topic that contains `on` (not the
    /// probes, nor the robot's status), waiting at most `patience` for
    /// each; fewer when they stop coming.
    pub fn take(mut self, on: &str, count: usize, patience: Duration) -> Vec<Arrival> {
        let mut got = Vec::with_capacity(count);
        while got.len() < count {
            match self.lines.recv_timeout(patience) {
                Ok(arrival) if arrival.topic.contains(on) => got.push(arrival),
                Ok(_) => {}
                Err(_) => break,
            }
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        got
    }
}

fn publish_probe(port: u16) {
    let _ = Command::new("mosquitto_pub")
        .args([
            "-h",
            "127.0.0.1",
            "-p",
            &port.to_string(),
            "-t",
            PROBE,
            "-m",
            "p",
        ])
        .status();
}

/// The integer a datagram carries (its last 8 bytes, big-endian, after
/// the type byte; `semo__encode_message`).
pub fn datagram_int(payload: &[u8]) -> Option<i64> {
    let bytes: [u8; 8] = payload
        .get(payload.len().checked_sub(8)?..)?
        .try_into()
        .ok()?;
    Some(i64::from_be_bytes(bytes))
}

/// The values of the talker's `send` lines, in order.
pub fn sent_values(events: &[Event]) -> Vec<i64> {
    events
        .iter()
        .filter(|e| field(e, "event") == "send")
        .filter_map(|e| e.get("value").and_then(|v| v.as_i64()))
        .collect()
}

/// Messages per second between the first and the last arrival.
pub fn rate(arrivals: &[Arrival]) -> f64 {
    match (arrivals.first(), arrivals.last()) {
        (Some(first), Some(last)) if last.at > first.at => {
            (arrivals.len() - 1) as f64 / (last.at - first.at)
        }
        _ => 0.0,
    }
}

/// What a process used, read from `/proc` until it ended.
#[derive(Clone, Copy, Debug, Default)]
pub struct Usage {
    /// Peak RSS (`VmHWM`), kB.
    pub peak_kb: u64,
    /// User and system CPU time of all its threads, in clock ticks (the
    /// last reading before it exited: close to the total).
    pub cpu_ticks: u64,
}

/// Reads process `pid`'s [`Usage`] until it ends (a zombie has no `Vm`
/// lines).
pub fn usage_of(pid: u32) -> Usage {
    let mut usage = Usage::default();
    loop {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
        let Some(kb) = status
            .lines()
            .find(|l| l.starts_with("VmHWM:"))
            .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        else {
            return usage;
        };
        usage.peak_kb = usage.peak_kb.max(kb);
        // utime and stime: fields 14 and 15, after the `(comm)` that may
        // hold spaces.
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        let ticks: u64 = stat
            .rsplit_once(')')
            .map(|(_, rest)| {
                rest.split_whitespace()
                    .skip(11)
                    .take(2)
                    .filter_map(|n| n.parse::<u64>().ok())
                    .sum()
            })
            .unwrap_or(0);
        usage.cpu_ticks = usage.cpu_ticks.max(ticks);
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// One run of the talker: what it sent, what the subscriber got, its peak
/// RSS.
pub struct TalkerRun {
    pub events: Vec<Event>,
    pub arrivals: Vec<Arrival>,
    pub usage: Usage,
}

/// Runs the talker (with `extra` arguments and `env`) while a subscriber
/// counts `expected` messages.
pub fn run_talker(
    fleet: &mut Fleet,
    talker: &Path,
    tag: &str,
    extra: &[&str],
    env: &[(&str, &str)],
    expected: usize,
) -> TalkerRun {
    let scenario = long_scenario(fleet);
    // Compiled in before the subscriber starts (a rebuild takes a while).
    support::mqtt::compile_in(&[talker.to_path_buf()], &scenario);
    let subscriber = Subscriber::start(fleet.port);
    let started: Started = fleet.spawn_with(talker, &scenario, tag, extra, env);
    let pid = fleet.processes.0[started.index].id();
    let usage = usage_of(pid);
    let arrivals = subscriber.take(TO_LISTENERS, expected, Duration::from_secs(5));
    let events = fleet.finish(&started, tag);
    TalkerRun {
        events,
        arrivals,
        usage,
    }
}

/// Every value the talker traced as sent reached the subscriber once, in
/// that order, on the listeners' topic.
pub fn assert_all_in_order(run: &TalkerRun, expected: usize) {
    let sent = sent_values(&run.events);
    assert_eq!(sent.len(), expected, "the talker sends every message");
    let got: Vec<i64> = run
        .arrivals
        .iter()
        .map(|a| datagram_int(&a.payload).expect("a datagram with an integer"))
        .collect();
    let first_difference = sent.iter().zip(&got).position(|(s, g)| s != g);
    assert!(
        got.len() == sent.len() && first_difference.is_none(),
        "{} sent, {} received; first difference at {first_difference:?}: sent {:?}…, received {:?}…",
        sent.len(),
        got.len(),
        &sent[..sent.len().min(4)],
        &got[..got.len().min(4)]
    );
    assert!(
        run.arrivals
            .iter()
            .all(|a| a.topic.starts_with(&format!("semo/{MISSION}/"))),
        "in the mission's scope"
    );
    assert!(
        !run.events.iter().any(|e| field(e, "event") == "comm_error"),
        "no send fails"
    );
}

/// `mosquitto_pub -q 1 -l` fed `count` lines on the same broker: the
/// subscriber's rate.
pub fn mosquitto_pub_rate(port: u16, count: usize) -> f64 {
    let subscriber = Subscriber::start(port);
    let mut child = Command::new("mosquitto_pub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string(), "-q", "1", "-l"])
        .args(["-t", &format!("semo/{MISSION}/reference")])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("mosquitto_pub runs");
    let lines: String = (0..count).map(|i| format!("{i}\n")).collect();
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(lines.as_bytes()).unwrap();
    drop(stdin);
    let arrivals = subscriber.take("/reference", count, Duration::from_secs(5));
    assert!(child.wait().unwrap().success(), "mosquitto_pub succeeds");
    assert_eq!(arrivals.len(), count, "mosquitto_pub's messages all arrive");
    rate(&arrivals)
}

/// The tests' plain broker, which queues every message for a subscriber
/// that lags (mosquitto drops what exceeds `max_queued_messages`, 1000 by
/// default, for a QoS 1 subscriber: `mosquitto_sub` writing to a pipe lags
/// behind a robot sending thousands at once).
fn unbounded_queues(dir: &Path, port: u16) -> PathBuf {
    let config = support::mqtt::plain_config(dir, port);
    let mut text = std::fs::read_to_string(&config).unwrap();
    text.push_str("max_queued_messages 0\n");
    std::fs::write(&config, text).unwrap();
    config
}

#[test]
fn a_robot_sends_every_message_at_qos1_once_and_in_order() {
    let Some(mut fleet) = Fleet::start_configured("mqtt-send-order", unbounded_queues) else {
        return;
    };
    // Four plans of 250: more than one control firing's steps, more than
    // libmosquitto's in-flight window and the message channel's 16.
    let (plans, per_plan) = (4, 250);
    let talker = build_talker(&fleet, plans, per_plan, support::robots::PEDANTIC);
    let run = run_talker(&mut fleet, &talker, "order", &[], &[], plans * per_plan);
    assert_all_in_order(&run, plans * per_plan);
}

/// A run's size: `var` if set, else `default`.
fn sized(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The values of the `send` lines a live trace holds so far (a line still
/// being written is not counted).
fn sends_so_far(trace: &Path) -> usize {
    let text = std::fs::read_to_string(trace).unwrap_or_default();
    let whole = &text[..text.rfind('\n').map_or(0, |end| end + 1)];
    whole.matches("\"event\":\"send\"").count()
}

#[test]
fn a_robot_whose_broker_stops_acknowledging_holds_a_bounded_number_of_sends_then_delivers_them_all()
{
    let Some(mut fleet) = Fleet::start_configured("mqtt-send-bound", unbounded_queues) else {
        return;
    };
    // 8 plans of 500: far more than the 256 unacknowledged sends the
    // transport lets libmosquitto hold.
    let (plans, per_plan) = (8, 500);
    let count = plans * per_plan;
    let talker = build_talker(&fleet, plans, per_plan, support::robots::PEDANTIC);
    let scenario = long_scenario(&fleet);
    support::mqtt::compile_in(&[talker.to_path_buf()], &scenario);
    let subscriber = Subscriber::start(fleet.port);
    // The talker connects, then waits for its start instant; meanwhile the
    // broker stops answering (SIGSTOP: its socket stays open, so the robot
    // sees no disconnection).
    let (_, start_at) = support::robots::start_barrier(30);
    let started = fleet.spawn_with(
        &talker,
        &scenario,
        "bound",
        &["--start-at", &start_at.to_string()],
        &[],
    );
    let log = fleet.broker_dir().join("mosquitto.log");
    // Until the broker has taken its subscription (its log's `CLIENT QOS
    // TOPIC` line), which the talker waits to be acknowledged before it
    // sends anything: stopped before, the broker would fail its start.
    let subscribed = "semo-send_rate-default-talker 1 ";
    while !std::fs::read_to_string(&log)
        .unwrap_or_default()
        .lines()
        .any(|line| {
            line.split_once(": ")
                .is_some_and(|(_, rest)| rest.starts_with(subscribed))
        })
    {
        assert!(
            fleet.processes.is_running(started.index),
            "the talker ended before it subscribed"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // Room for the acknowledgement to leave, which mosquitto writes after
    // it logs the subscription.
    std::thread::sleep(Duration::from_millis(1000));
    super::signal(fleet.broker_process().unwrap(), "STOP");
    // Sends traced before the broker stopped may have been acknowledged.
    let before = sends_so_far(&started.trace);
    // The talker sends until it waits for acknowledgements: its count of
    // sends stops growing (a slow machine only takes longer to get there).
    let (mut seen, mut stable_since) = (usize::MAX, std::time::Instant::now());
    loop {
        let now = sends_so_far(&started.trace);
        if now != seen {
            (seen, stable_since) = (now, std::time::Instant::now());
        } else if now > 0 && stable_since.elapsed() > Duration::from_millis(500) {
            break;
        }
        assert!(
            fleet.processes.is_running(started.index),
            "the talker ended while its broker was stopped"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // At most 256 handed to libmosquitto unacknowledged, and the one
    // waiting (traced before the transport); the message channel's 16 are
    // not traced yet.
    assert!(
        seen - before <= 256 + 1 && seen < count,
        "with no acknowledgement the talker stops after 256 unacknowledged sends, not {} more ({seen} of {count})",
        seen - before
    );
    super::signal(fleet.broker_process().unwrap(), "CONT");
    let arrivals = subscriber.take(TO_LISTENERS, count, Duration::from_secs(10));
    let events = fleet.finish(&started, "bound");
    assert_all_in_order(
        &TalkerRun {
            events,
            arrivals,
            usage: Usage::default(),
        },
        count,
    );
}

/// A broker with a second listener on TLS (the tests' CA and server
/// certificate, no client certificate asked): the TLS port.
fn with_tls_listener(fleet_dir: &Path, config: &Path) -> u16 {
    super::tls_files(fleet_dir);
    let tls_port = support::mosquitto::free_port();
    let mut text = std::fs::read_to_string(config).unwrap();
    text.push_str(&format!(
        "listener {tls_port} 127.0.0.1\ncafile {0}/ca.crt\ncertfile {0}/server.crt\nkeyfile {0}/server.key\n",
        fleet_dir.display()
    ));
    std::fs::write(config, text).unwrap();
    tls_port
}

#[test]
#[ignore = "stress run (real time): cargo test --test mqtt -- --ignored stress_send_rate"]
fn stress_send_rate_and_memory() {
    let plans = sized("SEMO_STRESS_PLANS", 8);
    let per_plan = sized("SEMO_STRESS_SENDS", 1000);
    let count = plans * per_plan;
    let mut tls_port = 0;
    let Some(mut fleet) = Fleet::start_configured("mqtt-send-rate", |dir, port| {
        let config = unbounded_queues(dir, port);
        tls_port = with_tls_listener(dir.parent().unwrap(), &config);
        config
    }) else {
        return;
    };
    let talker = build_talker(
        &fleet,
        plans,
        per_plan,
        "-std=c11 -Wall -Wextra -Werror -O2",
    );
    let ca = fleet.out.join("ca.crt").display().to_string();
    let tls_url = format!("mqtts://127.0.0.1:{tls_port}");
    for round in 0..3 {
        let plain = run_talker(
            &mut fleet,
            &talker,
            &format!("plain{round}"),
            &[],
            &[],
            count,
        );
        assert_all_in_order(&plain, count);
        let reference = mosquitto_pub_rate(fleet.port, count);
        println!(
            "stress: send rate, round {round}: robot {:.0} msg/s, mosquitto_pub -q 1 -l {reference:.0} msg/s ({count} messages at QoS 1 each, same broker; ratio {:.2}); robot CPU {} ticks ({:.1} µs a message, start-up included), peak RSS {} kB",
            rate(&plain.arrivals),
            rate(&plain.arrivals) / reference,
            plain.usage.cpu_ticks,
            plain.usage.cpu_ticks as f64 * 10_000.0 / count as f64,
            plain.usage.peak_kb
        );
    }
    let tls = run_talker(
        &mut fleet,
        &talker,
        "tls",
        &["--broker", &tls_url],
        &[("SEMO_MQTT_CA", &ca)],
        count,
    );
    assert_all_in_order(&tls, count);
    println!(
        "stress: over TLS: robot {:.0} msg/s, CPU {} ticks, peak RSS {} kB",
        rate(&tls.arrivals),
        tls.usage.cpu_ticks,
        tls.usage.peak_kb
    );
    let scenario = long_scenario(&fleet);
    let trace = fleet.out.join("udp.jsonl");
    let udp = support::mqtt::robot_on(&talker, &scenario, &trace, 30000)
        .args(["--transport", "udp"])
        .spawn()
        .expect("the talker starts");
    let index = fleet.processes.push(udp);
    let usage = usage_of(fleet.processes.0[index].id());
    fleet.processes.wait_success(index, "talker over udp");
    println!(
        "stress: the same program with --transport udp (libmosquitto loaded, not used; the datagrams go to a port nobody reads): peak RSS {} kB",
        usage.peak_kb
    );
}
