//! Messages per second through `semo gateway` (issue 35), per link and for
//! 32 links at once, and the gateway's peak memory.
//!
//! A private mosquitto on a free loopback port, one `semo gateway` process
//! with one `--link` per robot of a 32-robot team, and the robots' ends of
//! the links played by threads speaking the link with `semo::link` (as
//! `tests/gateway.rs` does, the same session as `semo_link.c`): each sends
//! `MESSAGES` (to the team: `MESSAGES_TO_TEAM`) reliable `send`s as fast
//! as the link lets it (one frame in flight, the gateway acknowledging it
//! once the broker has it at QoS 1).
//! An MQTT client counts what the broker publishes. Three cases:
//!
//! - one link, each `send` to the operator (`USER`): one link's up rate;
//! - 32 links, each `send` to `USER`: the gateway's up rate;
//! - 32 links, each `send` to the robots' own team: every message also goes
//!   down the 31 other links (as `M`, each acknowledged by its robot).
//!
//! Prints messages per second for each case and the gateway's `VmHWM`.
//! Needs `mosquitto`; says so and measures nothing without it.
//!
//! `cargo bench -p semo-cli --bench gateway_throughput`

#[path = "../../tests/support/mosquitto.rs"]
mod mosquitto;

use semo::deploy::datagram::{self, Datagram};
use semo::link::{Endpoint, Frame, Kind};
use semo::refine::Value;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Barrier, mpsc};
use std::time::{Duration, Instant};

const ROBOTS: usize = 32;
/// Sends per robot: fewer when each goes down 31 links too (31 times as
/// many frames, each waiting for its robot's acknowledgement).
const MESSAGES: usize = 1_000;
const MESSAGES_TO_TEAM: usize = 100;
/// Ends a case that would otherwise hang (a bench, not a test: it says so).
const LIMIT: Duration = Duration::from_secs(120);

const MISSION: &str = "{ Crew: Turtlebot3_Burger tb[32] }
Crew.Work.Report { send(USER, Crew.N = 1) } repeat(1 SEC)
Crew.REPORT { set(Work, Report) }
Crew.main { default: mode = REPORT }
";

fn main() {
    let Some(broker) = mosquitto::binary() else {
        eprintln!("gateway_throughput: `mosquitto` is not installed; nothing measured");
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mission = dir.path().join("crew.mission");
    std::fs::write(&mission, MISSION).expect("the mission is written");
    for (links, to) in [(1, "USER"), (ROBOTS, "USER"), (ROBOTS, "Crew")] {
        match case(&broker, dir.path(), &mission, links, to) {
            Ok(said) => println!("{said}"),
            Err(why) => eprintln!("gateway_throughput: {links} links to {to}: {why}"),
        }
    }
}

/// One case on a broker of its own; what it measured, as a line.
fn case(
    broker: &Path,
    dir: &Path,
    mission: &Path,
    links: usize,
    to: &str,
) -> Result<String, String> {
    let port = mosquitto::free_port();
    let config_dir = dir.join(format!("broker-{links}-{to}"));
    std::fs::create_dir_all(&config_dir).map_err(|e| e.to_string())?;
    let config = mosquitto::write_config(&config_dir, port, mosquitto::Keeps::default());
    let mut broker = Stopped(mosquitto::spawn(broker, &config));
    if !mosquitto::listening(port) {
        return Err(format!("mosquitto did not listen on port {port}"));
    }
    let run = format!("b{links}{}", to.to_lowercase());
    let messages = if to == "USER" {
        MESSAGES
    } else {
        MESSAGES_TO_TEAM
    };
    let published = watcher(port, &run)?;

    let listeners: Vec<TcpListener> = (0..links)
        .map(|_| TcpListener::bind("127.0.0.1:0").expect("a loopback port"))
        .collect();
    let mut gateway = Command::new(env!("CARGO_BIN_EXE_semo"));
    gateway.arg("gateway").arg(mission);
    for (i, listener) in listeners.iter().enumerate() {
        let port = listener.local_addr().expect("its address").port();
        gateway.args(["--link", &format!("tb_{i}=tcp:127.0.0.1:{port}")]);
    }
    gateway
        .args([
            "--broker",
            &format!("mqtt://127.0.0.1:{port}"),
            "--run",
            &run,
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    let gateway = Stopped(gateway.spawn().map_err(|e| e.to_string())?);

    // Every robot's session stands before the clock starts.
    let start = Arc::new(Barrier::new(links + 1));
    let (done_tx, done_rx) = mpsc::channel();
    for (i, listener) in listeners.into_iter().enumerate() {
        let (start, done) = (start.clone(), done_tx.clone());
        let to = to.to_string();
        let down = if to == "Crew" { links - 1 } else { 0 };
        std::thread::spawn(move || {
            let result = robot(&listener, i, &to, messages, down * messages, &start);
            let _ = done.send(result);
        });
    }
    start.wait();
    let began = Instant::now();
    for _ in 0..links {
        done_rx
            .recv_timeout(LIMIT)
            .map_err(|_| "a link robot did not finish".to_string())??;
    }
    let expected = links * messages;
    let mut heard = 0;
    while heard < expected {
        match published.recv_timeout(LIMIT) {
            Ok(()) => heard += 1,
            Err(_) => return Err(format!("the broker published {heard} of {expected}")),
        }
    }
    let seconds = began.elapsed().as_secs_f64();
    let peak = peak_kb(gateway.0.id());
    drop(gateway);
    broker.0.kill().ok();
    let down = if to == "Crew" {
        format!(", each also down {} links", links - 1)
    } else {
        String::new()
    };
    Ok(format!(
        "gateway, {links} link(s), {messages} sends each to {to}{down}: {:.0} messages/s published ({:.0} per link), {:.2} s; gateway peak RSS {} kB",
        expected as f64 / seconds,
        messages as f64 / seconds,
        seconds,
        peak.map_or("?".to_string(), |kb| kb.to_string())
    ))
}

/// The robot `tb_<i>` at its end of the link: sends `messages` to `to` and
/// takes `down` messages from the others.
fn robot(
    listener: &TcpListener,
    i: usize,
    to: &str,
    messages: usize,
    down: usize,
    start: &Barrier,
) -> Result<(), String> {
    let (mut stream, _) = listener.accept().map_err(|e| e.to_string())?;
    stream.set_nodelay(true).ok();
    stream
        .set_read_timeout(Some(Duration::from_millis(20)))
        .ok();
    let clock = Instant::now();
    let now = || clock.elapsed().as_millis() as u64;
    let mut endpoint = Endpoint::new(8);
    let mut taken = 0;
    pump(&mut stream, &mut endpoint, now(), &mut taken)?;
    while !endpoint.outgoing.welcomed() {
        pump(&mut stream, &mut endpoint, now(), &mut taken)?;
    }
    start.wait();
    let robot = format!("tb_{i}");
    let mut sent = 0;
    let end = Instant::now() + LIMIT;
    while sent < messages || endpoint.outgoing.pending() > 0 || taken < down {
        while sent < messages {
            let gram = datagram::encode(&Datagram {
                publish: false,
                team: "Crew".into(),
                robot: robot.clone(),
                key: "Crew.N".into(),
                value: Some(Value::Int(sent as i64)),
            });
            let frame = Frame::addressed(Kind::Send, 0, to, &gram).ok_or("a frame too long")?;
            if endpoint.queue(Kind::Send, frame.payload).is_err() {
                break;
            }
            sent += 1;
        }
        pump(&mut stream, &mut endpoint, now(), &mut taken)?;
        if Instant::now() > end {
            return Err(format!("{robot}: sent {sent}, took {taken} of {down}"));
        }
    }
    // The gateway takes the robot's last acknowledgements before the link closes.
    std::thread::sleep(Duration::from_millis(200));
    Ok(())
}

/// Writes what is due, then reads what comes (or waits a little).
fn pump(
    stream: &mut TcpStream,
    endpoint: &mut Endpoint,
    now: u64,
    taken: &mut usize,
) -> Result<(), String> {
    let mut wire = Vec::new();
    endpoint.tick(now, &mut wire);
    stream.write_all(&wire).map_err(|e| e.to_string())?;
    let mut buf = [0u8; 8192];
    match stream.read(&mut buf) {
        Ok(0) => Err("the gateway closed the link".to_string()),
        Ok(n) => {
            let mut wire = Vec::new();
            let frames = endpoint.feed(&buf[..n], now, &mut wire);
            *taken += frames.iter().filter(|f| f.kind == Kind::Message).count();
            stream.write_all(&wire).map_err(|e| e.to_string())
        }
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) =>
        {
            Ok(())
        }
        Err(e) => Err(e.to_string()),
    }
}

/// An MQTT client on the run's topics: one `()` per message published
/// (statuses left out), once it is subscribed.
fn watcher(port: u16, run: &str) -> Result<mpsc::Receiver<()>, String> {
    let mut options = rumqttc::MqttOptions::new(format!("bench-{run}"), "127.0.0.1", port);
    options.set_keep_alive(Duration::from_secs(30));
    let (client, mut connection) = rumqttc::Client::new(options, 1024);
    client
        .subscribe(format!("semo/crew/{run}/#"), rumqttc::QoS::AtMostOnce)
        .map_err(|e| e.to_string())?;
    let (tx, rx) = mpsc::channel();
    let (ready_tx, ready_rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _client = client;
        for event in connection.iter() {
            match event {
                Ok(rumqttc::Event::Incoming(rumqttc::Packet::SubAck(_))) => {
                    let _ = ready_tx.send(());
                }
                Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p)))
                    if !p.retain && !p.topic.contains("/status/") =>
                {
                    if tx.send(()).is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        }
    });
    ready_rx
        .recv_timeout(LIMIT)
        .map_err(|_| "the watcher was not subscribed".to_string())?;
    Ok(rx)
}

/// The process's peak resident memory (`VmHWM`), in kB.
fn peak_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// A child process killed when dropped.
struct Stopped(Child);

impl Drop for Stopped {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}
