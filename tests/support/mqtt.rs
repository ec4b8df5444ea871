//! The MQTT tests' set-up, once: a private `mosquitto` broker on a free
//! loopback port (its configuration, persistence and log in a temp folder),
//! robots built for `linux-sim` with the MQTT transport compiled in, and
//! their processes (killed when the test ends, whatever happens). A robot
//! run on a scenario has it compiled in first, as a user does (`semo build
//! --scenario FILE`, then `make`): [`robot_on`].
//!
//! Needs `mosquitto` and `libmosquitto-dev` (Debian). [`Fleet::start`] and
//! [`broker_or_skip`] skip a test with a message when the broker is missing,
//! unless `SEMO_MQTT_TESTS=require` (CI).

use super::robots::{Event, PEDANTIC, events, robot_command, robot_folders, scratch};
use super::{repo_root, semo_in};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;

/// How an output folder's robots were built ([`build_with`]) and the
/// scenario compiled into them, so that [`robot_on`] builds them again with
/// another one.
struct Built {
    mission: PathBuf,
    extra: Vec<String>,
    cc: String,
    cflags: String,
    /// The text of the scenario compiled in.
    scenario: String,
}

static BUILT: Mutex<Option<HashMap<PathBuf, Built>>> = Mutex::new(None);

/// The scenario a fleet is first built with: nothing happens for two
/// seconds (any mission runs on it).
const QUIET_SCENARIO: &str = r#"{"duration": 2000}"#;

/// The `mosquitto` binary (Debian puts it in /usr/sbin, often not on PATH).
pub fn mosquitto() -> Option<PathBuf> {
    super::mosquitto::binary()
}

/// The broker, or None (after saying why) when the test must be skipped.
pub fn broker_or_skip(test: &str) -> Option<PathBuf> {
    let found = mosquitto();
    if found.is_none() {
        let required = std::env::var("SEMO_MQTT_TESTS").as_deref() == Ok("require");
        assert!(
            !required,
            "SEMO_MQTT_TESTS=require but `mosquitto` is not installed (apt-get install mosquitto libmosquitto-dev)"
        );
        eprintln!(
            "skipping {test}: `mosquitto` is not installed (set SEMO_MQTT_TESTS=require to fail instead)"
        );
    }
    found
}

/// Processes a test started; each is killed when the guard goes, so a
/// failing assertion leaves no broker or robot behind.
#[derive(Default)]
pub struct Processes(pub Vec<Child>);

impl Processes {
    pub fn push(&mut self, child: Child) -> usize {
        self.0.push(child);
        self.0.len() - 1
    }

    /// SIGTERM and wait: a broker then saves its state (SIGKILL would not).
    pub fn terminate(&mut self, index: usize) {
        let child = &mut self.0[index];
        let sent = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(sent.success(), "kill -TERM {}", child.id());
        child.wait().expect("wait for the terminated process");
    }

    /// Whether the process is still running (not yet ended by itself).
    pub fn is_running(&mut self, index: usize) -> bool {
        matches!(self.0[index].try_wait(), Ok(None))
    }

    /// SIGKILL and wait: a robot that vanishes without a word.
    pub fn kill(&mut self, index: usize) {
        let child = &mut self.0[index];
        child.kill().expect("kill the process");
        child.wait().expect("wait for the killed process");
    }

    /// Waits for a robot to end by itself and returns its stderr; a failure
    /// status fails the test.
    pub fn wait_success(&mut self, index: usize, what: &str) -> String {
        let child = &mut self.0[index];
        let status = child.wait().expect("wait for the robot");
        let mut stderr = String::new();
        if let Some(mut pipe) = child.stderr.take() {
            use std::io::Read;
            let _ = pipe.read_to_string(&mut stderr);
        }
        assert!(status.success(), "{what} exited with {status:?}: {stderr}");
        stderr
    }
}

impl Drop for Processes {
    fn drop(&mut self) {
        for child in &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

use super::mosquitto::free_port;

/// A private broker's configuration in `dir` for `port`: anonymous clients,
/// TCP_NODELAY, persistence (a restarted broker keeps sessions), a log.
pub fn plain_config(dir: &Path, port: u16) -> PathBuf {
    super::mosquitto::write_config(
        dir,
        port,
        super::mosquitto::Keeps {
            persistence: true,
            log: true,
        },
    )
}

/// Starts mosquitto with `config` (which listens on `port` of 127.0.0.1)
/// and waits until it accepts connections; its log goes to `dir`.
pub fn start_broker_with(
    binary: &Path,
    config: &Path,
    dir: &Path,
    port: u16,
    processes: &mut Processes,
) -> usize {
    let index = processes.push(super::mosquitto::spawn(binary, config));
    if !super::mosquitto::listening(port) {
        let log = std::fs::read_to_string(dir.join("mosquitto.log")).unwrap_or_default();
        panic!("mosquitto did not listen on port {port}: {log}");
    }
    index
}

/// `semo build MISSION --target linux-sim --scenario S -o OUT EXTRA...`,
/// each robot made with the MQTT transport built in (`make TRANSPORT=mqtt`)
/// with `cc` and `cflags` (warnings are errors: any warning fails); `S` is
/// a scenario in which nothing happens for two seconds, until a robot is
/// run on another ([`robot_on`]). The robot folders.
pub fn build_with(
    mission: &Path,
    out: &Path,
    extra: &[&str],
    cc: &str,
    cflags: &str,
) -> Vec<PathBuf> {
    let built = Built {
        mission: mission.to_path_buf(),
        extra: extra.iter().map(|s| s.to_string()).collect(),
        cc: cc.to_string(),
        cflags: cflags.to_string(),
        scenario: QUIET_SCENARIO.to_string(),
    };
    let folders = compile(out, &built);
    BUILT
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get_or_insert_with(HashMap::new)
        .insert(out.to_path_buf(), built);
    folders
}

/// Builds and makes `out` as `built` says (its scenario written beside
/// `out`); the robot folders.
fn compile(out: &Path, built: &Built) -> Vec<PathBuf> {
    std::fs::create_dir_all(out).unwrap();
    let scenario = out.with_extension("compiled.scenario.json");
    std::fs::write(&scenario, &built.scenario).unwrap();
    let (mission, out_arg) = (
        built.mission.display().to_string(),
        out.display().to_string(),
    );
    let scenario_arg = scenario.display().to_string();
    let mut args = vec![
        "build",
        mission.as_str(),
        "--target",
        "linux-sim",
        "--scenario",
        scenario_arg.as_str(),
        "-o",
        out_arg.as_str(),
    ];
    args.extend(built.extra.iter().map(String::as_str));
    let result = semo_in(&repo_root(), &args);
    assert_eq!(result.code, 0, "{}{}", result.stdout, result.stderr);
    let folders = robot_folders(out);
    for folder in &folders {
        let made = Command::new("make")
            .args([
                "-s",
                "-j2",
                &format!("CC={}", built.cc),
                &format!("CFLAGS={}", built.cflags),
                "TRANSPORT=mqtt",
            ])
            .current_dir(folder)
            .output()
            .expect("make runs");
        let stderr = String::from_utf8_lossy(&made.stderr);
        assert!(
            made.status.success() && !stderr.contains("warning"),
            "{} ({} {}): {stderr}",
            folder.display(),
            built.cc,
            built.cflags
        );
    }
    folders
}

/// Compiles `scenario` into the robots of `folders` (one output folder
/// [`build_with`] wrote): built and made again unless it is the one in them
/// already. Before a start barrier, so that the robots start on time.
pub fn compile_in(folders: &[PathBuf], scenario: &Path) {
    let Some(folder) = folders.first() else {
        return;
    };
    let out = folder
        .parent()
        .and_then(Path::parent)
        .expect("a robot folder is <out>/<team>/<robot>");
    let text =
        std::fs::read_to_string(scenario).unwrap_or_else(|e| panic!("{}: {e}", scenario.display()));
    let mut all = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    let built = all
        .get_or_insert_with(HashMap::new)
        .get_mut(out)
        .unwrap_or_else(|| panic!("{} was not built by build_with", out.display()));
    if built.scenario != text {
        built.scenario = text;
        compile(out, built);
    }
}

/// The program of a robot folder [`build_with`] wrote, with `scenario`
/// compiled in ([`compile_in`]), set to write its trace to `trace` on the
/// ports from `port_base`.
pub fn robot_on(folder: &Path, scenario: &Path, trace: &Path, port_base: u32) -> Command {
    compile_in(std::slice::from_ref(&folder.to_path_buf()), scenario);
    robot_command(folder, trace, port_base)
}

/// [`build_with`] gcc at `-Wpedantic -Werror`.
pub fn build(mission: &Path, out: &Path, extra: &[&str]) -> Vec<PathBuf> {
    build_with(mission, out, extra, "gcc", PEDANTIC)
}

pub fn robot_name(folder: &Path) -> String {
    folder.file_name().unwrap().to_string_lossy().into_owned()
}

/// The folder of `robot` among `folders`.
pub fn folder_of(folders: &[PathBuf], robot: &str) -> PathBuf {
    folders
        .iter()
        .find(|f| robot_name(f) == robot)
        .unwrap_or_else(|| panic!("no robot {robot}"))
        .clone()
}

pub fn read_trace(path: &Path) -> Vec<Event> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    events(&text.lines().map(str::to_string).collect::<Vec<_>>())
}

/// A robot process of a [`Fleet`]: its trace file and its process.
pub struct Started {
    pub robot: String,
    pub trace: PathBuf,
    pub index: usize,
}

/// One test's private broker and the robot processes it runs against it.
pub struct Fleet {
    /// The test's scratch folder (the broker's files in `broker/`).
    pub out: PathBuf,
    pub port: u16,
    pub processes: Processes,
    binary: PathBuf,
    config: PathBuf,
    broker: Option<usize>,
}

impl Fleet {
    /// A fresh scratch folder `name` and a broker with [`plain_config`];
    /// None when the test must be skipped (no mosquitto).
    pub fn start(name: &str) -> Option<Fleet> {
        Fleet::start_configured(name, plain_config)
    }

    /// The same with the configuration `configure(broker folder, port)`
    /// writes (an ACL, TLS); the broker folder is `out/broker`.
    pub fn start_configured(
        name: &str,
        configure: impl FnOnce(&Path, u16) -> PathBuf,
    ) -> Option<Fleet> {
        let binary = broker_or_skip(name)?;
        let out = scratch(name);
        let dir = out.join("broker");
        std::fs::create_dir_all(&dir).unwrap();
        let port = free_port();
        let config = configure(&dir, port);
        let mut fleet = Fleet {
            out,
            port,
            processes: Processes::default(),
            binary,
            config,
            broker: None,
        };
        fleet.start_broker();
        Some(fleet)
    }

    pub fn broker_dir(&self) -> PathBuf {
        self.out.join("broker")
    }

    /// `mqtt://127.0.0.1:PORT`.
    pub fn url(&self) -> String {
        format!("mqtt://127.0.0.1:{}", self.port)
    }

    /// `--transport mqtt --broker URL`.
    pub fn transport_args(&self) -> Vec<String> {
        vec![
            "--transport".into(),
            "mqtt".into(),
            "--broker".into(),
            self.url(),
        ]
    }

    /// Starts the broker again on the same port, with the same state.
    pub fn start_broker(&mut self) {
        let dir = self.broker_dir();
        let index = start_broker_with(
            &self.binary,
            &self.config,
            &dir,
            self.port,
            &mut self.processes,
        );
        self.broker = Some(index);
    }

    /// The broker's process, while it runs.
    pub fn broker_process(&self) -> Option<&Child> {
        self.broker.map(|index| &self.processes.0[index])
    }

    /// Stops the broker as a service stop does (it saves its state).
    pub fn stop_broker(&mut self) {
        if let Some(index) = self.broker.take() {
            self.processes.terminate(index);
        }
    }

    /// Starts the `linux-sim` program of `folder` on `scenario` over this
    /// broker, its trace `<robot>.<tag>.jsonl` in the scratch folder, with
    /// `extra` arguments.
    pub fn spawn(&mut self, folder: &Path, scenario: &Path, tag: &str, extra: &[&str]) -> Started {
        self.spawn_with(folder, scenario, tag, extra, &[])
    }

    /// [`Fleet::spawn`] with environment variables (sanitizer options).
    pub fn spawn_with(
        &mut self,
        folder: &Path,
        scenario: &Path,
        tag: &str,
        extra: &[&str],
        env: &[(&str, &str)],
    ) -> Started {
        let robot = robot_name(folder);
        let trace = self.out.join(format!("{robot}.{tag}.jsonl"));
        let child = robot_on(folder, scenario, &trace, 1)
            .args(self.transport_args())
            .args(extra)
            .envs(env.iter().copied())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the robot program starts");
        let index = self.processes.push(child);
        Started {
            robot,
            trace,
            index,
        }
    }

    /// Waits for a robot to end by itself (a failure fails the test) and
    /// reads its trace.
    pub fn finish(&mut self, started: &Started, tag: &str) -> Vec<Event> {
        self.processes
            .wait_success(started.index, &format!("{} ({tag})", started.robot));
        read_trace(&started.trace)
    }

    /// Runs one robot to its end (a failure fails the test) and returns its
    /// trace.
    pub fn run(&mut self, folder: &Path, scenario: &Path, tag: &str, extra: &[&str]) -> Vec<Event> {
        let started = self.spawn(folder, scenario, tag, extra);
        self.finish(&started, tag)
    }

    /// Runs every robot of `folders` together on `scenario` and returns the
    /// traces by robot.
    pub fn run_all(
        &mut self,
        folders: &[PathBuf],
        scenario: &Path,
        tag: &str,
        extra: &[&str],
    ) -> std::collections::BTreeMap<String, Vec<Event>> {
        let started: Vec<Started> = folders
            .iter()
            .map(|f| self.spawn(f, scenario, tag, extra))
            .collect();
        started
            .iter()
            .map(|s| (s.robot.clone(), self.finish(s, tag)))
            .collect()
    }
}
