//! What the MQTT benches share: build a C bench program against the
//! runtime's own MQTT transport (`semo_mqtt.c`), start a private mosquitto on
//! a free loopback port, run the program against it and read the numbers it
//! prints. `None` (with the reason on stderr) when mosquitto,
//! libmosquitto-dev or a C compiler is missing: a bench measures nothing
//! rather than failing on a machine without them.

#[path = "../../../tests/support/mosquitto.rs"]
mod mosquitto;

use std::path::Path;
use std::process::Command;

/// What the program `benches/NAME.c` printed on stdout, as numbers, when it
/// succeeded with `args` after the broker's port; on failure, what it said.
pub fn run(name: &str, args: &[String]) -> Option<Result<Vec<f64>, String>> {
    let Some(broker) = mosquitto::binary() else {
        eprintln!("{name}: `mosquitto` is not installed; nothing measured");
        return None;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR")).join("../compiler/src/codegen/runtime");
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("benches/{name}.c"));
    let program = dir.path().join(name);
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
            "{name}: cannot build the benchmark (libmosquitto-dev?): {}",
            String::from_utf8_lossy(&built.stderr)
        );
        return None;
    }
    let port = mosquitto::free_port();
    let config = mosquitto::write_config(dir.path(), port, mosquitto::Keeps::default());
    let mut broker = mosquitto::spawn(&broker, &config);
    if !mosquitto::listening(port) {
        let _ = broker.kill();
        let _ = broker.wait();
        return Some(Err(format!("mosquitto did not listen on port {port}")));
    }
    let run = Command::new(&program)
        .arg(port.to_string())
        .args(args)
        .output()
        .expect("the benchmark runs");
    let _ = broker.kill();
    let _ = broker.wait();
    let text = String::from_utf8_lossy(&run.stdout);
    if !run.status.success() {
        return Some(Err(format!(
            "{text}{}",
            String::from_utf8_lossy(&run.stderr)
        )));
    }
    Some(Ok(text
        .split_whitespace()
        .filter_map(|n| n.parse().ok())
        .collect()))
}
