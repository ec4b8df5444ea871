//! A private `mosquitto` for the tests and benchmarks of every crate, once:
//! finding the binary, a free loopback port, the broker's configuration,
//! starting it and waiting until it listens. Only `std`, so that each user
//! includes this file as it is: `tests/support/mqtt.rs` (the end-to-end
//! tests: `pub mod mosquitto` in `tests/support/mod.rs`), the monitor's
//! tests and benchmark (`server/tests/support/broker.rs`) and the MQTT
//! benchmarks (`cli/benches/support/c_broker_bench.rs`), both with
//! `#[path]`.
//!
//! What a broker configuration holds for our tests: a listener on
//! 127.0.0.1 only, anonymous clients, `set_tcp_nodelay true` (without it a
//! QoS 1 round trip waits for Nagle's algorithm, about 90 ms on loopback),
//! and `user <us>` (started as root, mosquitto drops to the `mosquitto`
//! user, which cannot read or write our folders; no effect otherwise).
//! Persistence and a log file when asked. Brokers with an ACL or TLS are
//! configured by `semo deploy broker-config` (`tests/mqtt.rs`).
#![allow(dead_code)] // each user takes its part

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// The `mosquitto` binary: on `PATH`, or where Debian puts it (`/usr/sbin`,
/// often not on a user's `PATH`).
pub fn binary() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>());
    on_path
        .chain([PathBuf::from("/usr/sbin"), PathBuf::from("/usr/local/sbin")])
        .map(|dir| dir.join("mosquitto"))
        .find(|path| path.is_file())
}

/// A free port of 127.0.0.1 (free when asked).
pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// The user we are.
pub fn current_user() -> String {
    let whoami = Command::new("id").arg("-un").output().expect("id runs");
    String::from_utf8_lossy(&whoami.stdout).trim().to_string()
}

/// What a private broker keeps besides the defaults above.
#[derive(Clone, Copy, Debug, Default)]
pub struct Keeps {
    /// Its state in `dir` (a restarted broker keeps sessions and QoS 1
    /// messages).
    pub persistence: bool,
    /// Its log in `dir/mosquitto.log`.
    pub log: bool,
}

/// Writes `dir/mosquitto.conf` for a private broker on `port` and returns
/// its path.
pub fn write_config(dir: &Path, port: u16, keeps: Keeps) -> PathBuf {
    let mut text = format!(
        "user {}\nlistener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\n",
        current_user()
    );
    if keeps.persistence {
        text.push_str(&format!(
            "persistence true\npersistence_location {}/\n",
            dir.display()
        ));
    }
    if keeps.log {
        // The default kinds, and each subscription (`CLIENT QOS TOPIC`):
        // a test can see that a client's subscriptions were taken.
        text.push_str(&format!(
            "log_dest file {}\nlog_type error\nlog_type warning\nlog_type notice\nlog_type information\nlog_type subscribe\n",
            dir.join("mosquitto.log").display()
        ));
    }
    let config = dir.join("mosquitto.conf");
    std::fs::write(&config, text).unwrap();
    config
}

/// Starts `binary -c config` (its output dropped: it logs where its
/// configuration says).
pub fn spawn(binary: &Path, config: &Path) -> Child {
    Command::new(binary)
        .arg("-c")
        .arg(config)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("mosquitto starts")
}

/// Whether something accepts connections on `port` of 127.0.0.1 within
/// about five seconds (a broker that never does, its port taken
/// meanwhile, is reported by the caller rather than waited for forever).
pub fn listening(port: u16) -> bool {
    for _ in 0..500 {
        if TcpStream::connect(("127.0.0.1", port)).is_ok() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    false
}
