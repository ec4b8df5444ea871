//! A private `mosquitto` for the monitor's tests and benchmark, on a free
//! loopback port, its configuration and log in a temporary folder (written
//! by the one broker set-up of every crate's tests, `tests/support/mosquitto.rs`).

#[path = "../../../tests/support/mosquitto.rs"]
mod mosquitto;

use std::path::{Path, PathBuf};
use std::process::Child;

pub use mosquitto::free_port;

/// The `mosquitto` binary, or None after saying so; a missing broker fails
/// under `SEMO_MQTT_TESTS=require` (CI).
pub fn mosquitto() -> Option<PathBuf> {
    let found = mosquitto::binary();
    if found.is_none() {
        assert!(
            std::env::var("SEMO_MQTT_TESTS").as_deref() != Ok("require"),
            "SEMO_MQTT_TESTS=require but `mosquitto` is not installed"
        );
        eprintln!("skipping: `mosquitto` is not installed");
    }
    found
}

/// A private broker on a free port, killed when dropped.
pub struct Broker {
    child: Child,
    pub port: u16,
    _dir: tempfile::TempDir,
}

impl Broker {
    pub fn start(binary: &Path) -> Broker {
        let dir = tempfile::tempdir().unwrap();
        let port = free_port();
        let config = mosquitto::write_config(
            dir.path(),
            port,
            mosquitto::Keeps {
                persistence: false,
                log: true,
            },
        );
        let broker = Broker {
            child: mosquitto::spawn(binary, &config),
            port,
            _dir: dir,
        };
        assert!(
            mosquitto::listening(port),
            "mosquitto did not listen on port {port}"
        );
        broker
    }

    pub fn url(&self) -> String {
        format!("mqtt://127.0.0.1:{}", self.port)
    }
}

impl Drop for Broker {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
