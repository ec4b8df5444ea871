//! `semo gateway` end to end: a private mosquitto, the gateway, a robot on a
//! link (the test, speaking the link with `semo::link`, as `semo_link.c`
//! does: `tests/link.rs` holds the two to each other) and an MQTT client
//! watching the run's topics. What the link robot sends is published on its
//! own topics with its datagram unchanged; a frame claiming another sender
//! is refused, never published; what the broker delivers to the robot comes
//! down the link, and a message whose datagram names another sender than
//! its topic comes down as `R`; its status is retained, and `lost` when the
//! link closes; a gateway killed and started again loses no message either
//! way and passes none twice. Waits are bounded by events (a message
//! heard), never by time: the deadlines only end a test that would
//! otherwise hang.

mod support;

use semo::deploy::datagram::{self, Datagram};
use semo::link::{Endpoint, Frame, Kind};
use semo::refine::Value;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use support::mqtt::Fleet;

const LIMIT: Duration = Duration::from_secs(20);

fn scouting() -> std::path::PathBuf {
    support::examples().join("scouting/scouting.mission")
}

fn gram(publish: bool, team: &str, robot: &str, key: &str, value: i64) -> Vec<u8> {
    datagram::encode(&Datagram {
        publish,
        team: team.into(),
        robot: robot.into(),
        key: key.into(),
        value: Some(Value::Int(value)),
    })
}

/// The robot's end of the link: the test's side of a TCP connection the
/// gateway made, with the link's session over it.
struct LinkRobot {
    stream: TcpStream,
    endpoint: Endpoint,
    started: Instant,
    taken: Vec<Frame>,
}

impl LinkRobot {
    /// The robot at the end of the link the gateway connects to on
    /// `listener`, once its session stands.
    fn connected(listener: &TcpListener) -> LinkRobot {
        LinkRobot::taking(listener, semo::link::PAYLOAD_MAX as u16)
    }

    /// As [`LinkRobot::connected`], a robot that takes payloads of at most
    /// `payload_max` bytes (a board's `SEMO_LINK_PAYLOAD_MAX`).
    fn taking(listener: &TcpListener, payload_max: u16) -> LinkRobot {
        let (stream, _) = listener.accept().expect("the gateway connects to the link");
        stream
            .set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        let mut robot = LinkRobot {
            stream,
            endpoint: Endpoint::taking(8, payload_max),
            started: Instant::now(),
            taken: Vec::new(),
        };
        robot.until("the session", |_, e| e.outgoing.welcomed());
        robot
    }

    fn now(&self) -> u64 {
        self.started.elapsed().as_millis() as u64
    }

    /// Reads and answers until `done` holds of what was taken.
    fn until(&mut self, what: &str, done: impl Fn(&[Frame], &Endpoint) -> bool) {
        let end = Instant::now() + LIMIT;
        let mut buf = [0u8; 4096];
        loop {
            let mut wire = Vec::new();
            let now = self.now();
            self.endpoint.tick(now, &mut wire);
            self.stream.write_all(&wire).unwrap();
            if done(&self.taken, &self.endpoint) {
                return;
            }
            assert!(Instant::now() < end, "the link robot waited for {what}");
            match self.stream.read(&mut buf) {
                Ok(0) => panic!("the gateway closed the link while waiting for {what}"),
                Ok(n) => {
                    let mut wire = Vec::new();
                    let now = self.now();
                    let frames = self.endpoint.feed(&buf[..n], now, &mut wire);
                    self.taken.extend(frames);
                    self.stream.write_all(&wire).unwrap();
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) => {}
                Err(e) => panic!("link: {e}"),
            }
        }
    }

    /// A new gateway connects to the link (the last one stopped): the
    /// robot goes on with its session state as a board does, which does not
    /// see the gateway go; the new gateway's `Hello` starts the session.
    fn reconnected(&mut self, listener: &TcpListener) {
        let (stream, _) = listener.accept().expect("the new gateway connects");
        stream
            .set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        self.stream = stream;
    }

    /// Waits until the gateway has written bytes down the link, without
    /// reading them (the robot takes nothing, so acknowledges nothing).
    fn until_written_to(&self, what: &str) {
        let end = Instant::now() + LIMIT;
        let mut buf = [0u8; 64];
        while !matches!(self.stream.peek(&mut buf), Ok(n) if n > 0) {
            assert!(Instant::now() < end, "the link robot waited for {what}");
        }
    }

    fn send(&mut self, kind: Kind, to: &str, datagram: &[u8]) {
        let frame = Frame::addressed(kind, 0, to, datagram).unwrap();
        if kind.reliable() {
            self.endpoint.queue(kind, frame.payload).unwrap();
            self.until("the gateway's ack", |_, e| e.outgoing.pending() == 0);
        } else {
            let mut wire = Vec::new();
            self.endpoint.emit(&frame, &mut wire);
            self.stream.write_all(&wire).unwrap();
        }
    }
}

/// An MQTT client on the run's topics: what it hears comes through `rx`.
/// Each with its own client id: a second one would take the first one's
/// session over at the broker.
fn watcher(url_port: u16, run: &str) -> (rumqttc::Client, mpsc::Receiver<(String, Vec<u8>, bool)>) {
    static WATCHERS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let id = WATCHERS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut options = rumqttc::MqttOptions::new(format!("watcher-{id}"), "127.0.0.1", url_port);
    options.set_keep_alive(Duration::from_secs(10));
    let (client, mut connection) = rumqttc::Client::new(options, 64);
    client
        .subscribe(format!("semo/scouting/{run}/#"), rumqttc::QoS::AtLeastOnce)
        .unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for event in connection.iter() {
            match event {
                Ok(rumqttc::Event::Incoming(rumqttc::Packet::SubAck(_))) => {
                    let _ = tx.send((String::new(), Vec::new(), false));
                }
                Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) => {
                    if tx.send((p.topic, p.payload.to_vec(), p.retain)).is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(_) => std::thread::sleep(Duration::from_millis(100)),
            }
        }
    });
    // Subscribed before anything is sent.
    let (topic, _, _) = rx.recv_timeout(LIMIT).expect("the watcher's SUBACK");
    assert!(topic.is_empty());
    (client, rx)
}

fn unix_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_millis() as i64
}

fn heard(rx: &mpsc::Receiver<(String, Vec<u8>, bool)>, what: &str) -> (String, Vec<u8>, bool) {
    rx.recv_timeout(LIMIT)
        .unwrap_or_else(|_| panic!("the watcher waited for {what}"))
}

fn gateway(broker: &str, link_port: u16, run: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("gateway")
        .arg(scouting())
        .args(["--link", &format!("ti=tcp:127.0.0.1:{link_port}")])
        .args(["--broker", broker, "--run", run])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("semo gateway starts")
}

/// Stops the gateway `gw` of `fleet`; what it said on standard error.
fn stopped_saying(fleet: &mut Fleet, gw: usize) -> String {
    fleet.processes.kill(gw);
    let mut said = String::new();
    fleet.processes.0[gw]
        .stderr
        .take()
        .expect("the gateway's standard error is piped")
        .read_to_string(&mut said)
        .unwrap();
    said
}

#[test]
fn a_link_robot_is_a_member_of_the_fleet_on_its_own_topics_only() {
    let Some(mut fleet) = Fleet::start("gateway-bridge") else {
        return;
    };
    let run = "g1";
    let (client, rx) = watcher(fleet.port, run);
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let link_port = listener.local_addr().unwrap().port();
    let gw = fleet.processes.push(gateway(&fleet.url(), link_port, run));
    let before_welcome = unix_ms();
    let mut robot = LinkRobot::connected(&listener);
    let after_welcome = unix_ms();

    // Noise on the line (a frame with a flipped bit, a flood without a
    // zero) is dropped and said; the link goes on.
    let mut noise = Frame::addressed(Kind::Publish, 0, "MasterTeam", b"SEMO")
        .unwrap()
        .encode()
        .unwrap();
    noise[8] ^= 0x40; // a letter of "MasterTeam"
    noise.extend(vec![0x5A; 3 * semo::link::WIRE_MAX]);
    noise.push(0);
    robot.stream.write_all(&noise).unwrap();
    // A send claiming another robot is refused; the good one after it is
    // the first thing published.
    robot.send(
        Kind::Send,
        "MasterTeam",
        &gram(false, "MasterTeam", "irobot", "SlaveTeam.COLOR", 1),
    );
    let good = gram(false, "SlaveTeam", "ti", "SlaveTeam.COLOR", 7);
    robot.send(Kind::Send, "MasterTeam", &good);
    let (topic, payload, retained) = heard(&rx, "ti's send");
    assert_eq!(
        topic,
        format!("semo/scouting/{run}/MasterTeam/SlaveTeam.COLOR/SlaveTeam/ti")
    );
    assert_eq!(payload, good, "the datagram unchanged");
    assert!(!retained);
    // A publish to one robot goes on that robot's topic.
    let heartbeat = gram(true, "SlaveTeam", "ti", "SlaveTeam.LOCATION", 3);
    robot.send(Kind::Publish, "irobot", &heartbeat);
    let (topic, payload, _) = heard(&rx, "ti's publish");
    assert_eq!(
        topic,
        format!("semo/scouting/{run}/MasterTeam/irobot/SlaveTeam.LOCATION/SlaveTeam/ti")
    );
    assert_eq!(payload, heartbeat);

    // From the broker: a message to SlaveTeam on its sender's topic comes
    // down as M; one whose datagram names another sender than its topic as R.
    let forward = gram(false, "MasterTeam", "irobot", "USER.RC_CMD", 2);
    client
        .publish(
            format!("semo/scouting/{run}/SlaveTeam/USER.RC_CMD/MasterTeam/irobot"),
            rumqttc::QoS::AtLeastOnce,
            false,
            forward.clone(),
        )
        .unwrap();
    client
        .publish(
            format!("semo/scouting/{run}/SlaveTeam/USER.RC_CMD/MasterTeam/irobot"),
            rumqttc::QoS::AtLeastOnce,
            false,
            gram(false, "SlaveTeam", "nxt", "USER.RC_CMD", 9),
        )
        .unwrap();
    robot.until("two frames from the gateway", |taken, _| taken.len() >= 2);
    assert_eq!(robot.taken[0].kind, Kind::Message);
    assert_eq!(robot.taken[0].payload, forward);
    assert_eq!(robot.taken[1].kind, Kind::Refused);
    // The watcher hears those two as well (they are on the run's topics).
    heard(&rx, "the forward");
    heard(&rx, "the forged one");

    // A board has no clock: its status says `started` 0, and the gateway
    // says the time it welcomed the board's session (its mission time 0).
    let board =
        br#"{"t":5,"robot":"ti","event":"status","state":"running","started":"0","mode":"Move"}"#;
    robot.endpoint.queue(Kind::Status, board.to_vec()).unwrap();
    robot.until("the board status's ack", |_, e| e.outgoing.pending() == 0);
    let (_, payload, _) = heard(&rx, "ti's board status");
    let said: serde_json::Value = serde_json::from_slice(&payload).unwrap();
    let started: i64 = said["started"].as_str().unwrap().parse().unwrap();
    assert!(
        (before_welcome..=after_welcome).contains(&started),
        "started {started} is the welcome, between {before_welcome} and {after_welcome}"
    );
    assert_eq!(said["mode"], "Move", "the rest as the board said it");

    // The status is published on the robot's status topic; when the link
    // closes the gateway says the robot is lost (retained), with the
    // `started` of its last status, as a Linux robot's last will does.
    let status = br#"{"t":5,"robot":"ti","event":"status","state":"running","started":"1234","mode":"Move"}"#;
    robot.endpoint.queue(Kind::Status, status.to_vec()).unwrap();
    robot.until("the status's ack", |_, e| e.outgoing.pending() == 0);
    let (topic, payload, _) = heard(&rx, "ti's status");
    assert_eq!(topic, format!("semo/scouting/{run}/status/ti"));
    assert_eq!(payload, status);
    drop(robot);
    let (topic, payload, _) = heard(&rx, "ti lost");
    assert_eq!(topic, format!("semo/scouting/{run}/status/ti"));
    let lost: serde_json::Value = serde_json::from_slice(&payload).unwrap();
    assert_eq!(
        lost,
        serde_json::json!({"robot": "ti", "event": "status", "state": "lost", "started": "1234"})
    );
    // A console that comes later reads it retained.
    let (_late, late_rx) = watcher(fleet.port, run);
    let (topic, _, retained) = heard(&late_rx, "the retained status");
    assert_eq!(topic, format!("semo/scouting/{run}/status/ti"));
    assert!(retained);
    // The gateway is still running: it waits for the link to come back.
    assert!(fleet.processes.is_running(gw));
    // A robot whose last status says it stopped ended cleanly (a board's
    // QEMU exits after its `stop`): its link closing leaves the status
    // `stopped`, as a Linux robot that disconnects leaves no last will. The
    // gateway's next publish, the status of the robot on its next link,
    // comes right after: no `lost` between.
    let mut again = LinkRobot::connected(&listener);
    let stopped = br#"{"t":9,"robot":"ti","event":"status","state":"stopped","started":"1234","mode":"Move"}"#;
    again
        .endpoint
        .queue(Kind::Status, stopped.to_vec())
        .unwrap();
    again.until("the stopped status's ack", |_, e| e.outgoing.pending() == 0);
    assert_eq!(heard(&rx, "ti stopped").1, stopped);
    drop(again);
    let mut restarted = LinkRobot::connected(&listener);
    let running =
        br#"{"t":0,"robot":"ti","event":"status","state":"running","started":"5678","mode":""}"#;
    restarted
        .endpoint
        .queue(Kind::Status, running.to_vec())
        .unwrap();
    restarted.until("the new status's ack", |_, e| e.outgoing.pending() == 0);
    assert_eq!(
        String::from_utf8_lossy(&heard(&rx, "ti running again").1),
        String::from_utf8_lossy(running),
        "no `lost` after a robot that stopped"
    );
    // Every refusal was counted and said.
    let said = stopped_saying(&mut fleet, gw);
    assert!(
        said.contains("ti: refused a send to MasterTeam: its datagram names MasterTeam/irobot as the sender, not this link's robot (1 refused)"),
        "{said}"
    );
    assert!(
        said.contains("names another sender or key (1 refused)"),
        "{said}"
    );
    assert!(said.contains("ti: link closed"), "{said}");
    assert!(
        said.contains("ti: a bad frame (CRC mismatch), dropped"),
        "{said}"
    );
    assert!(said.contains("ti: a bad frame (longer than"), "{said}");
}

/// A send is acknowledged to the robot only once the broker has it: with
/// the gateway cut off from the broker (a TCP proxy the test holds, which
/// drops what it reads), the send the gateway handed on is not acknowledged,
/// so a gateway that stopped then would lose nothing (the robot keeps it and
/// sends it again); healed, the gateway's connection publishes it again and
/// the robot hears its `Ack`. (The gateway acknowledged a send as it took
/// it, before the broker had it.)
#[test]
fn a_send_is_acknowledged_to_the_robot_only_once_the_broker_has_it() {
    let Some(mut fleet) = Fleet::start("gateway-puback") else {
        return;
    };
    let run = "g3";
    let (_client, rx) = watcher(fleet.port, run);
    let proxy = support::proxy::Proxy::start(fleet.port);
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let link_port = listener.local_addr().unwrap().port();
    let through_proxy = format!("mqtt://127.0.0.1:{}", proxy.port);
    fleet
        .processes
        .push(gateway(&through_proxy, link_port, run));
    let mut robot = LinkRobot::connected(&listener);

    proxy.cut();
    let good = gram(false, "SlaveTeam", "ti", "SlaveTeam.COLOR", 7);
    let frame = Frame::addressed(Kind::Send, 0, "MasterTeam", &good).unwrap();
    robot.endpoint.queue(Kind::Send, frame.payload).unwrap();
    // The gateway handed the publish on: the proxy dropped its bytes. An
    // `Ack` written before that would be on the link by now.
    robot.until("the publish to reach the cut proxy", |_, _| {
        proxy.dropped() > 0
    });
    let mut buf = [0u8; 4096];
    for _ in 0..4 {
        if let Ok(n) = robot.stream.read(&mut buf) {
            let mut wire = Vec::new();
            let now = robot.now();
            robot.endpoint.feed(&buf[..n], now, &mut wire);
        }
    }
    assert_eq!(
        robot.endpoint.outgoing.pending(),
        1,
        "the send was acknowledged before the broker had it"
    );

    proxy.heal();
    robot.until("the ack once the broker has the send", |_, e| {
        e.outgoing.pending() == 0
    });
    let (topic, payload, _) = heard(&rx, "ti's send, published again after the heal");
    assert_eq!(
        topic,
        format!("semo/scouting/{run}/MasterTeam/SlaveTeam.COLOR/SlaveTeam/ti")
    );
    assert_eq!(payload, good);
}

/// A board takes shorter payloads than the gateway (the scouting `ti`: 164
/// bytes); its session says how long. A message from the broker longer than
/// that comes down as `R` (`L`: too long), counted and said, and the next
/// message comes down after it. (The gateway sent it as `M`: a bad frame on
/// the board, never acknowledged, sent again for ever ahead of every later
/// message.)
#[test]
fn a_message_longer_than_the_board_takes_is_refused_and_the_next_one_arrives() {
    let Some(mut fleet) = Fleet::start("gateway-bound") else {
        return;
    };
    let run = "g4";
    let (client, rx) = watcher(fleet.port, run);
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let link_port = listener.local_addr().unwrap().port();
    let gw = fleet.processes.push(gateway(&fleet.url(), link_port, run));
    let mut robot = LinkRobot::taking(&listener, 64);

    let topic = format!("semo/scouting/{run}/SlaveTeam/USER.RC_CMD/MasterTeam/irobot");
    let long = datagram::encode(&Datagram {
        publish: false,
        team: "MasterTeam".into(),
        robot: "irobot".into(),
        key: "USER.RC_CMD".into(),
        value: Some(Value::Text("x".repeat(60).into())),
    });
    assert!(long.len() > 64);
    let short = gram(false, "MasterTeam", "irobot", "USER.RC_CMD", 2);
    for payload in [&long, &short] {
        client
            .publish(&topic, rumqttc::QoS::AtLeastOnce, false, payload.clone())
            .unwrap();
    }
    robot.until("two frames from the gateway", |taken, _| taken.len() >= 2);
    assert_eq!(
        robot.taken[0],
        Frame::new(Kind::Refused, robot.taken[0].seq, b"L".to_vec())
    );
    assert_eq!(robot.taken[1].kind, Kind::Message);
    assert_eq!(robot.taken[1].payload, short);
    assert!(
        robot.endpoint.bad_frames.is_empty(),
        "nothing too long came"
    );
    heard(&rx, "the long message");
    heard(&rx, "the short one");

    let said = stopped_saying(&mut fleet, gw);
    assert!(
        said.contains(&format!(
            "ti: a message of {} bytes on {topic} is longer than the robot takes (64 bytes) (1 refused)",
            long.len()
        )),
        "{said}"
    );
}

/// What the watcher hears, kept in order: `until` reads until `done`
/// holds of everything heard so far.
struct Heard {
    rx: mpsc::Receiver<(String, Vec<u8>, bool)>,
    all: Vec<(String, Vec<u8>)>,
}

impl Heard {
    fn until(&mut self, what: &str, done: impl Fn(&[(String, Vec<u8>)]) -> bool) {
        while !done(&self.all) {
            let (topic, payload, _) = heard(&self.rx, what);
            self.all.push((topic, payload));
        }
    }

    /// The payloads heard on `topic`, in order.
    fn on(&self, topic: &str) -> Vec<Vec<u8>> {
        self.all
            .iter()
            .filter(|(t, _)| t == topic)
            .map(|(_, p)| p.clone())
            .collect()
    }
}

/// A gateway killed (SIGKILL) in the middle of a run and a new one started
/// on the same link: no message is lost and none passes twice. Up the link,
/// a send the robot made while no gateway was there goes once the new
/// gateway's session stands, and what the first gateway published is not
/// published again. Down the link, the messages the first gateway held (the
/// robot had not acknowledged them) and the one published while no gateway
/// ran come down from the new gateway, each once and in order: a message is
/// acknowledged to the broker only once the robot has it, so the broker
/// delivers it again to the next gateway (the gateway acknowledged each as
/// it arrived, so those it held died with it, uncounted; and the messages a
/// kept session brings before the subscriptions' SUBACK were dropped).
#[test]
fn a_gateway_restarted_in_the_middle_loses_no_message_and_passes_none_twice() {
    let Some(mut fleet) = Fleet::start("gateway-restart") else {
        return;
    };
    let run = "g5";
    let (client, rx) = watcher(fleet.port, run);
    let mut heard = Heard {
        rx,
        all: Vec::new(),
    };
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let link_port = listener.local_addr().unwrap().port();
    let first = fleet.processes.push(gateway(&fleet.url(), link_port, run));
    let mut robot = LinkRobot::connected(&listener);

    let up = format!("semo/scouting/{run}/MasterTeam/SlaveTeam.COLOR/SlaveTeam/ti");
    let send = |v| gram(false, "SlaveTeam", "ti", "SlaveTeam.COLOR", v);
    let down = format!("semo/scouting/{run}/SlaveTeam/USER.RC_CMD/MasterTeam/irobot");
    let message = |v| gram(false, "MasterTeam", "irobot", "USER.RC_CMD", v);
    let publish = |v| {
        client
            .publish(&down, rumqttc::QoS::AtLeastOnce, false, message(v))
            .unwrap()
    };

    // Up: a send, acknowledged (the broker has it).
    robot.send(Kind::Send, "MasterTeam", &send(1));
    // Down: three messages; the first gateway passes the first down the
    // link, and the robot takes none of them.
    for v in 1..=3 {
        publish(v);
    }
    heard.until("the three messages", |all| {
        all.iter().filter(|(t, _)| *t == down).count() == 3
    });
    robot.until_written_to("the first message down the link");
    let said = stopped_saying(&mut fleet, first);
    assert!(said.contains("ti: link open"), "{said}");

    // No gateway: a message for the robot waits at the broker, and the
    // robot's next send waits with the robot.
    publish(4);
    heard.until("the message sent while no gateway ran", |all| {
        all.iter().filter(|(t, _)| *t == down).count() == 4
    });
    let frame = Frame::addressed(Kind::Send, 0, "MasterTeam", &send(2)).unwrap();
    robot.endpoint.queue(Kind::Send, frame.payload).unwrap();

    let second = fleet.processes.push(gateway(&fleet.url(), link_port, run));
    robot.reconnected(&listener);
    robot.until("the send made while no gateway ran", |_, e| {
        e.outgoing.pending() == 0
    });
    // One more each way, after everything before: a copy of anything
    // earlier would come before it (one topic, one sender: in order).
    robot.send(Kind::Send, "MasterTeam", &send(3));
    publish(5);
    robot.until("the five messages", |taken, _| {
        taken.iter().any(|f| f.payload == message(5))
    });
    let taken: Vec<(Kind, Vec<u8>)> = robot
        .taken
        .iter()
        .map(|f| (f.kind, f.payload.clone()))
        .collect();
    let expected: Vec<(Kind, Vec<u8>)> = (1..=5).map(|v| (Kind::Message, message(v))).collect();
    assert_eq!(
        taken, expected,
        "every message down the link once, in order, across the restart"
    );
    heard.until("the send after the restart", |all| {
        all.iter().any(|(t, p)| *t == up && *p == send(3))
    });
    assert_eq!(
        heard.on(&up),
        vec![send(1), send(2), send(3)],
        "every send published once, in order, across the restart"
    );
    let said = stopped_saying(&mut fleet, second);
    assert!(said.contains("ti: link open"), "{said}");
    assert!(!said.contains("bad frame"), "{said}");
}

/// A robot that comes back on its link (a board reset, its QEMU started
/// again) is welcomed as a robot restarted in its run: its broker session,
/// the gateway's, was kept, and the `Welcome` says so (its
/// `semo_session_resumed`, as a restarted Linux robot's CONNACK says), so
/// that its elections listen before they claim; the first session of a
/// run says not. (Every `Welcome` said what the broker said when the
/// gateway started: a board restarted in a swarm claimed leadership at
/// once.)
#[test]
fn a_robot_back_on_its_link_is_told_its_session_was_kept() {
    let Some(mut fleet) = Fleet::start("gateway-welcome-again") else {
        return;
    };
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let link_port = listener.local_addr().unwrap().port();
    let gw = fleet.processes.push(gateway(&fleet.url(), link_port, "g7"));
    let robot = LinkRobot::connected(&listener);
    assert_eq!(robot.endpoint.peer_flags, 0, "a new run: no session kept");
    drop(robot);
    let robot = LinkRobot::connected(&listener);
    assert_eq!(robot.endpoint.peer_flags, 1, "back on its link");
    drop(robot);
    let said = stopped_saying(&mut fleet, gw);
    assert!(said.matches("ti: link open").count() >= 2, "{said}");
}

#[test]
fn bad_arguments_are_refused_with_exit_status_2() {
    let mission = scouting();
    let mission = mission.to_str().unwrap();
    for (args, says) in [
        (vec!["gateway", mission], "no link"),
        (vec!["gateway", mission, "--link", "ti"], "ROBOT=LINK"),
        (
            vec!["gateway", mission, "--link", "ti=tcp:nowhere"],
            "HOST:PORT",
        ),
        (
            vec!["gateway", mission, "--link", "tee=tcp:127.0.0.1:1"],
            "no robot `tee`",
        ),
        (
            vec![
                "gateway",
                mission,
                "--link",
                "ti=tcp:127.0.0.1:1",
                "--link",
                "ti=tcp:127.0.0.1:2",
            ],
            "two links",
        ),
        (
            vec![
                "gateway",
                mission,
                "--link",
                "ti=tcp:127.0.0.1:1",
                "--run",
                "a/b",
            ],
            "--run",
        ),
    ] {
        let out = support::semo(&args);
        assert_eq!(out.code, 2, "{args:?}: {}", out.stderr);
        assert!(out.stderr.contains(says), "{args:?}: {}", out.stderr);
    }
    // A mission with errors is refused with its diagnostics, as `semo build`
    // reports them.
    let dir = support::robots::scratch("gateway-bad-mission");
    let bad = dir.join("bad.mission");
    std::fs::write(&bad, "{\n  T: NoSuchRobot r\n}\n").unwrap();
    let out = support::semo(&[
        "gateway",
        bad.to_str().unwrap(),
        "--link",
        "r=tcp:127.0.0.1:1",
    ]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("[E010]") && out.stderr.contains("bad.mission:2:6"),
        "{}",
        out.stderr
    );
    let help = support::semo(&["gateway", "--help"]);
    assert_eq!(help.code, 0);
    assert!(help.stdout.contains("--link"));
}

/// Starts the scouting robots built in `folders` at one instant (ti's link
/// open by then): `ti` with `--transport link` to the gateway listening on
/// `link_port`, the others over MQTT; `extra`: more arguments for each.
fn start_with_ti_on_link(
    fleet: &mut Fleet,
    folders: &[std::path::PathBuf],
    scenario: &std::path::Path,
    link_port: u16,
    extra: &[&str],
    tag: &str,
) -> Vec<support::mqtt::Started> {
    let link = format!("tcp:127.0.0.1:{link_port}");
    let (_, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let mut started = Vec::new();
    for folder in folders {
        let robot = support::mqtt::robot_name(folder);
        let (args, env): (Vec<String>, Vec<(&str, &str)>) = if robot == "ti" {
            (
                vec!["--transport".into(), "link".into()],
                vec![("SEMO_LINK", link.as_str())],
            )
        } else {
            (fleet.transport_args(), vec![])
        };
        let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
        args.extend(["--start-at", start_at.as_str()]);
        args.extend(extra);
        started.push(fleet.spawn_with(folder, scenario, tag, &args, &env));
    }
    started
}

/// The scouting mission with `ti` on the link: its `linux-sim` program with
/// `--transport link` through `semo gateway`, `irobot` and `nxt` over MQTT,
/// one private broker. Every robot enters the modes `semo simulate` gives
/// it on the same scenario, in the same order, to FINISH; the master hears
/// ti's colors (they went up the link and through the broker), and the
/// broker's messages reached ti (its own modes depend on the master's
/// forwarded commands).
#[test]
fn a_linux_robot_over_the_link_behaves_as_in_the_simulator() {
    use support::robots::{field, modes};
    let Some(mut fleet) = Fleet::start("gateway-scouting") else {
        return;
    };
    let scenario = support::repo_root().join("tests/fixtures/build/scouting.scenario.json");
    let folders = support::mqtt::build(&scouting(), &fleet.out, &[]);
    // Built with the scenario before anything starts (compiling takes time).
    support::mqtt::compile_in(&folders, &scenario);
    let link_port = support::mosquitto::free_port();
    let gw = fleet.processes.push(
        Command::new(env!("CARGO_BIN_EXE_semo"))
            .arg("gateway")
            .arg(scouting())
            .args(["--link", &format!("ti=listen:127.0.0.1:{link_port}")])
            .args(["--broker", &fleet.url()])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("semo gateway starts"),
    );
    let started = start_with_ti_on_link(&mut fleet, &folders, &scenario, link_port, &[], "link");
    let traces: std::collections::BTreeMap<String, Vec<support::robots::Event>> = started
        .iter()
        .map(|s| (s.robot.clone(), fleet.finish(s, "link")))
        .collect();
    let simulated = support::robots::simulated_modes(&scouting(), &scenario);
    assert_eq!(traces.len(), 3);
    for (robot, trace) in &traces {
        assert_eq!(
            modes(trace),
            simulated[robot],
            "{robot}'s modes with ti on the link and in `semo simulate`"
        );
        assert_eq!(modes(trace).last().map(String::as_str), Some("FINISH"));
    }
    let heard_ti = traces["irobot"].iter().any(|e| {
        field(e, "event") == "receive"
            && field(e, "from_robot") == "ti"
            && field(e, "key") == "SlaveTeam.COLOR"
    });
    assert!(heard_ti, "the master hears ti's colors through the gateway");
    let ti_heard = traces["ti"]
        .iter()
        .filter(|e| field(e, "event") == "receive")
        .count();
    assert!(ti_heard > 0, "ti hears the fleet through the gateway");
    assert!(
        !traces["ti"].iter().any(|e| field(e, "event") == "reject"),
        "nothing refused"
    );
    fleet.processes.kill(gw);
}

/// The scouting mission as in the test above, at its real pace (so that a
/// gateway restart is a moment of it), with the gateway killed (SIGKILL)
/// once ti has heard its fleet and sent to it, and a new one started on the
/// same link. ti does not crash: it connects again (its trace's `link`
/// event counts one reconnection, and the publishes lost while no session
/// stood), hears its fleet after the restart, and ends as every robot
/// does, in the modes `semo simulate` gives. Every send ti traced is
/// published, in order, and none twice but the one in flight when the
/// gateway was killed: the broker may have had it (its PUBACK read) while
/// its `Ack` had not reached ti, which then sends it again to the new
/// gateway, as an MQTT robot sends a QoS 1 message again around a
/// reconnection. (A gateway knows nothing of what the last one published.)
#[test]
fn a_linux_robot_on_the_link_survives_a_gateway_restart_in_the_middle() {
    use support::robots::{field, modes};
    let Some(mut fleet) = Fleet::start("gateway-restart-scouting") else {
        return;
    };
    let run = "g6";
    let scenario = support::repo_root().join("tests/fixtures/build/scouting.scenario.json");
    let folders = support::mqtt::build(&scouting(), &fleet.out, &[]);
    support::mqtt::compile_in(&folders, &scenario);
    let (_client, rx) = watcher(fleet.port, run);
    let mut heard = Heard {
        rx,
        all: Vec::new(),
    };
    let link_port = support::mosquitto::free_port();
    let listening = |fleet: &Fleet| {
        Command::new(env!("CARGO_BIN_EXE_semo"))
            .arg("gateway")
            .arg(scouting())
            .args(["--link", &format!("ti=listen:127.0.0.1:{link_port}")])
            .args(["--broker", &fleet.url(), "--run", run])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("semo gateway starts")
    };
    let first = fleet.processes.push(listening(&fleet));
    let started = start_with_ti_on_link(
        &mut fleet,
        &folders,
        &scenario,
        link_port,
        &["--time-scale", "1", "--run", run],
        "restart",
    );
    let ti = started.iter().find(|s| s.robot == "ti").unwrap();

    // Messages flow both ways (ti reports its colors to the master as fast
    // as the link takes them, and hears nxt's heartbeats): the gateway is
    // killed then.
    let end = Instant::now() + LIMIT;
    let before = loop {
        let trace = support::mqtt::read_trace(&ti.trace);
        let heard = trace.iter().any(|e| field(e, "event") == "receive");
        let reported = trace
            .iter()
            .any(|e| field(e, "event") == "send" && field(e, "to") == "MasterTeam");
        if heard && reported {
            break trace.len();
        }
        assert!(Instant::now() < end, "ti neither heard nor sent: {trace:?}");
        std::thread::sleep(Duration::from_millis(10));
    };
    let said = stopped_saying(&mut fleet, first);
    assert!(said.contains("ti: link open"), "{said}");
    let second = fleet.processes.push(listening(&fleet));

    let traces: std::collections::BTreeMap<String, Vec<support::robots::Event>> = started
        .iter()
        .map(|s| (s.robot.clone(), fleet.finish(s, "restart")))
        .collect();
    let said = stopped_saying(&mut fleet, second);
    assert!(said.contains("ti: link open"), "the new gateway: {said}");

    // ti connected again and heard its fleet after the restart.
    let ti_trace = &traces["ti"];
    assert_eq!(field(ti_trace.last().unwrap(), "event"), "stop");
    let links: Vec<_> = ti_trace
        .iter()
        .filter(|e| field(e, "event") == "link")
        .collect();
    assert_eq!(links.len(), 1, "{links:?}");
    assert_eq!(field(links[0], "reconnections"), "1", "{links:?}");
    assert!(links[0].get("lost").is_some(), "{links:?}");
    assert!(
        ti_trace[before..]
            .iter()
            .any(|e| field(e, "event") == "receive"),
        "ti hears its fleet after the restart"
    );

    // The same modes as in the simulator, for every robot.
    let simulated = support::robots::simulated_modes(&scouting(), &scenario);
    for (robot, trace) in &traces {
        assert_eq!(
            modes(trace),
            simulated[robot],
            "{robot}'s modes with a gateway restart and in `semo simulate`"
        );
    }

    // Every send ti traced was published, in order; at most the one in
    // flight at the kill twice, right after its first copy.
    let sent: Vec<(String, String)> = ti_trace
        .iter()
        .filter(|e| field(e, "event") == "send" && field(e, "to") == "MasterTeam")
        .map(|e| (field(e, "key").to_string(), e["value"].to_string()))
        .collect();
    assert!(!sent.is_empty());
    let prefix = format!("semo/scouting/{run}/MasterTeam/");
    let from_ti = |all: &[(String, Vec<u8>)]| -> Vec<(String, String)> {
        all.iter()
            .filter(|(t, _)| t.starts_with(&prefix) && t.ends_with("/SlaveTeam/ti"))
            .filter_map(|(_, p)| datagram::decode(p))
            .filter(|d| !d.publish)
            .map(|d| {
                let value = match d.value {
                    Some(Value::Text(t) | Value::Word(t)) => {
                        serde_json::Value::String(t.to_string())
                    }
                    other => panic!("ti sends texts: {other:?}"),
                };
                (d.key.to_string(), value.to_string())
            })
            .collect()
    };
    // Until every send has come: counting copies of the last one was not
    // enough, as the send in flight at the kill (published twice) may be
    // one like it, and the last sends were still on their way.
    heard.until("ti's last send", |all| {
        without_redelivery(&from_ti(all), &sent).0.len() >= sent.len()
    });
    let (once, again) = without_redelivery(&from_ti(&heard.all), &sent);
    if let Some(again) = again {
        eprintln!("published again after the restart: {again:?}");
    }
    assert_eq!(
        once, sent,
        "every send ti traced published in order, none lost, none twice but the one in flight"
    );
}

/// `published` without the one message that may come twice in a row (the
/// send in flight at a gateway's kill): the first copy that is not the next
/// of `sent` when it repeats the one before it. And that copy, if any.
fn without_redelivery<T: Clone + PartialEq>(published: &[T], sent: &[T]) -> (Vec<T>, Option<T>) {
    let mut once = published.to_vec();
    let differs = (0..published.len().min(sent.len())).find(|&i| published[i] != sent[i]);
    let again = differs
        .or((published.len() > sent.len()).then_some(sent.len()))
        .filter(|&i| i > 0 && published[i] == published[i - 1]);
    match again {
        Some(i) => {
            let copy = once.remove(i);
            (once, Some(copy))
        }
        None => (once, None),
    }
}

/// The shapes a gateway restart gives: the send in flight published twice
/// in a row (in the middle or last), and the last sends still on their way
/// while a copy like the last one already came (which once ended the wait
/// for them early).
#[test]
fn a_redelivery_is_one_copy_in_a_row_and_the_sends_still_on_their_way_are_missing() {
    let sent = ["c", "l", "c", "l", "c", "l"];
    let twice_in_the_middle = ["c", "l", "l", "c", "l", "c", "l"];
    assert_eq!(
        without_redelivery(&twice_in_the_middle, &sent),
        (sent.to_vec(), Some("l"))
    );
    let twice_last = ["c", "l", "c", "l", "c", "l", "l"];
    assert_eq!(
        without_redelivery(&twice_last, &sent),
        (sent.to_vec(), Some("l"))
    );
    // As many copies of the last send as were sent, but two sends to come.
    let on_their_way = ["c", "l", "l", "c", "l"];
    assert_eq!(without_redelivery(&on_their_way, &sent).0.len(), 4);
    // A loss is not hidden: no copy in a row to take out.
    let lost = ["c", "l", "l", "l", "c", "l"];
    assert_ne!(without_redelivery(&lost, &sent).0, sent.to_vec());
}
