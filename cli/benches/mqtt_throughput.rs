//! Messages per second through a private mosquitto on loopback with 50
//! robots publishing at 10 Hz (issue 17): `mqtt_throughput.c` forks 50
//! processes, each opening the runtime's own MQTT transport (`semo_mqtt.c`)
//! as one robot of a team of 50; each publishes to its team 10 times a
//! second for 10 s (a `publish`: QoS 0, retained, fanned out by the broker
//! to the 49 others) and counts what reaches it. Prints the messages
//! published and delivered per second, and the share delivered. Needs
//! `mosquitto`, `libmosquitto-dev` and a C compiler; says so and does
//! nothing without them.
//!
//! `cargo bench -p semo-cli --bench mqtt_throughput`

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const ROBOTS: usize = 50;
const RATE_HZ: usize = 10;
const SECONDS: usize = 10;
fn mosquitto() -> Option<PathBuf> {
    [
        "/usr/sbin/mosquitto",
        "/usr/local/sbin/mosquitto",
        "/usr/bin/mosquitto",
    ]
    .into_iter()
    .map(PathBuf::from)
    .find(|p| p.is_file())
}

fn main() {
    let Some(broker) = mosquitto() else {
        eprintln!("mqtt_throughput: `mosquitto` is not installed; nothing measured");
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR")).join("../compiler/src/codegen/runtime");
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/mqtt_throughput.c");
    let program = dir.path().join("mqtt_throughput");
    let built = Command::new("cc")
        .args(["-O2", "-std=c11", "-Wall", "-Wextra", "-DSEMO_MQTT", "-I"])
        .arg(&runtime)
        .arg(&bench)
        .arg(runtime.join("semo_mqtt.c"))
        .args(["-lmosquitto", "-lpthread", "-o"])
        .arg(&program)
        .output()
        .expect("cc runs");
    if !built.status.success() {
        eprintln!(
            "mqtt_throughput: cannot build the benchmark (libmosquitto-dev?): {}",
            String::from_utf8_lossy(&built.stderr)
        );
        return;
    }
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let user = Command::new("id").arg("-un").output().expect("id runs");
    let config = dir.path().join("mosquitto.conf");
    std::fs::write(
        &config,
        format!(
            "user {}\nlistener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\n",
            String::from_utf8_lossy(&user.stdout).trim()
        ),
    )
    .unwrap();
    let mut broker = Command::new(broker)
        .arg("-c")
        .arg(&config)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("mosquitto starts");
    for _ in 0..500 {
        if TcpStream::connect(("127.0.0.1", port)).is_ok() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let run = Command::new(&program)
        .args([
            port.to_string(),
            ROBOTS.to_string(),
            RATE_HZ.to_string(),
            SECONDS.to_string(),
        ])
        .output()
        .expect("the benchmark runs");
    let _ = broker.kill();
    let _ = broker.wait();
    let text = String::from_utf8_lossy(&run.stdout);
    let numbers: Vec<f64> = text
        .split_whitespace()
        .filter_map(|n| n.parse().ok())
        .collect();
    match (run.status.success(), numbers.as_slice()) {
        (true, [published, delivered, expected, wall]) => println!(
            "mqtt throughput, {ROBOTS} robot processes publishing at {RATE_HZ} Hz for {SECONDS} s on loopback: {:.0} messages/s published, {:.0} messages/s delivered ({:.2}% of the {expected:.0} fan-out deliveries)",
            published / wall,
            delivered / wall,
            100.0 * delivered / expected.max(1.0)
        ),
        _ => eprintln!(
            "mqtt_throughput failed: {}{}",
            text,
            String::from_utf8_lossy(&run.stderr)
        ),
    }
}
