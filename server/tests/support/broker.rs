//! A private `mosquitto` for the monitor's tests and benchmark: its
//! configuration and log in a temporary folder, on a free loopback port.

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// The `mosquitto` binary (Debian puts it in /usr/sbin), or None after
/// saying so; a missing broker fails under `SEMO_MQTT_TESTS=require` (CI).
pub fn mosquitto() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>());
    let found = on_path
        .chain([PathBuf::from("/usr/sbin"), PathBuf::from("/usr/local/sbin")])
        .map(|dir| dir.join("mosquitto"))
        .find(|path| path.is_file());
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
        let whoami = Command::new("id").arg("-un").output().expect("id runs");
        let config = dir.path().join("mosquitto.conf");
        std::fs::write(
            &config,
            format!(
                "user {}\nlistener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\nlog_dest file {}\n",
                String::from_utf8_lossy(&whoami.stdout).trim(),
                dir.path().join("mosquitto.log").display()
            ),
        )
        .unwrap();
        let child = Command::new(binary)
            .arg("-c")
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("mosquitto starts");
        let broker = Broker {
            child,
            port,
            _dir: dir,
        };
        for _ in 0..500 {
            if TcpStream::connect(("127.0.0.1", port)).is_ok() {
                return broker;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        panic!("mosquitto did not listen on port {port}");
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

pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}
