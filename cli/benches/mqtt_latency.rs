//! `send` → `receive` latency through a private mosquitto on loopback, as
//! generated robots see it (issue 17's goal: median ≤ 1 ms, p99 ≤ 5 ms):
//! `mqtt_latency.c` opens the runtime's own MQTT transport (`semo_mqtt.c`,
//! QoS 1, persistent session, TCP_NODELAY) in two processes and times 2000
//! sends one millisecond apart. Needs `mosquitto`, `libmosquitto-dev` and a
//! C compiler; says so and does nothing without them.
//!
//! `cargo bench -p semo-cli --bench mqtt_latency`

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const SENDS: usize = 2000;

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
        eprintln!("mqtt_latency: `mosquitto` is not installed; nothing measured");
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR")).join("../compiler/src/codegen/runtime");
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/mqtt_latency.c");
    let program = dir.path().join("mqtt_latency");
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
            "mqtt_latency: cannot build the benchmark (libmosquitto-dev?): {}",
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
        .args([port.to_string(), SENDS.to_string()])
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
        (true, [median, p99, max]) => println!(
            "mqtt send→receive latency over {SENDS} sends on loopback: median {median:.1} µs, p99 {p99:.1} µs, max {max:.1} µs (goal: median ≤ 1000 µs, p99 ≤ 5000 µs)"
        ),
        _ => eprintln!(
            "mqtt_latency failed: {}{}",
            text,
            String::from_utf8_lossy(&run.stderr)
        ),
    }
}
