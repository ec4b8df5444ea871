//! Building missions as a user does and running the robot programs: `semo build`
//! into a scratch folder, `make` in each robot folder, the `linux-sim` programs
//! started together and their JSON traces read back.

use super::{Output, repo_root, semo_in};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The flags every generated program must compile with, warnings as errors.
pub const PEDANTIC: &str = "-std=c11 -Wall -Wextra -Wpedantic -Werror -O0";

/// One line of a trace.
pub type Event = serde_json::Map<String, serde_json::Value>;

/// A fresh folder under cargo's scratch space for tests.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `semo build MISSION --target TARGET -o OUT`, run from the repository
/// root; a simulation target (`linux-sim`, `cortex-m-sim`) needs
/// [`build_sim`].
pub fn build(mission: &Path, target: &str, out: &Path) -> Output {
    let out_arg = out.display().to_string();
    let mission_arg = mission.display().to_string();
    semo_in(
        &repo_root(),
        &["build", &mission_arg, "--target", target, "-o", &out_arg],
    )
}

/// `semo build MISSION --target TARGET --scenario SCENARIO -o OUT`: a
/// simulation with the scenario compiled in.
pub fn build_sim(mission: &Path, target: &str, scenario: &Path, out: &Path) -> Output {
    let out_arg = out.display().to_string();
    let mission_arg = mission.display().to_string();
    let scenario_arg = scenario.display().to_string();
    semo_in(
        &repo_root(),
        &[
            "build",
            &mission_arg,
            "--target",
            target,
            "--scenario",
            &scenario_arg,
            "-o",
            &out_arg,
        ],
    )
}

/// Every robot folder under an output folder (one generation wrote: it
/// has its `.semo-manifest`; a broker's folder beside them is not), sorted.
pub fn robot_folders(out: &Path) -> Vec<PathBuf> {
    let mut folders = Vec::new();
    let Ok(teams) = std::fs::read_dir(out) else {
        return folders;
    };
    for team in teams {
        let team = team.unwrap().path();
        if !team.is_dir() {
            continue;
        }
        for robot in std::fs::read_dir(&team).unwrap() {
            let robot = robot.unwrap().path();
            let hidden = robot
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with('.');
            if robot.is_dir() && !hidden && robot.join(".semo-manifest").is_file() {
                folders.push(robot);
            }
        }
    }
    folders.sort();
    folders
}

/// Runs `make` in a robot folder; the compiler's complaints on failure (a
/// warning is a failure).
pub fn make(folder: &Path, cc: &str, cflags: &str) -> Result<(), String> {
    let out = Command::new("make")
        .args([
            "-s",
            "-j2",
            &format!("CC={cc}"),
            &format!("CFLAGS={cflags}"),
        ])
        .current_dir(folder)
        .output()
        .expect("make runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if out.status.success() && !stderr.contains("warning") {
        Ok(())
    } else {
        Err(format!("{}: {stderr}", folder.display()))
    }
}

/// A build for `target`; a simulation with a scenario in which nothing
/// happens for two seconds (any mission runs on it), written beside `out`.
pub fn build_for(mission: &Path, target: &str, out: &Path) -> Output {
    if !target.ends_with("-sim") {
        return build(mission, target, out);
    }
    std::fs::create_dir_all(out).unwrap();
    let scenario = out.with_extension("quiet.scenario.json");
    std::fs::write(&scenario, r#"{"duration": 2000}"#).unwrap();
    build_sim(mission, target, &scenario, out)
}

/// The `linux-sim` program of a robot folder (its scenario compiled in),
/// set to write its trace to `trace`, on the ports from `port_base`.
pub fn robot_command(folder: &Path, trace: &Path, port_base: u32) -> Command {
    let robot = folder.file_name().expect("a robot folder").to_owned();
    let mut command = Command::new(folder.join(robot));
    command
        .args(["--trace", &trace.display().to_string()])
        .args(["--port-base", &port_base.to_string()]);
    command
}

/// The start barrier of a run of `robots` programs: mission time 0 is a
/// moment far enough ahead for every one of them to have started and opened
/// its port (`--start-at`, Unix ms), so that they start together and no
/// first message is lost; also the same moment on this process's clock.
pub fn start_barrier(robots: usize) -> (std::time::Instant, u64) {
    let lead = std::time::Duration::from_millis(600 + 100 * robots as u64);
    let unix = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("the clock is after 1970");
    (
        std::time::Instant::now() + lead,
        (unix + lead).as_millis() as u64,
    )
}

pub fn has(program: &str) -> bool {
    Command::new(program).arg("--version").output().is_ok()
}

/// Whether the board tools are here (the ARM compiler, its `size`, QEMU);
/// without them a board test is skipped (with a message) unless
/// `SEMO_CORTEX_M_TESTS=require` (CI), where a missing tool fails it.
pub fn board_tools_present(test: &str) -> bool {
    let missing: Vec<&str> = ["arm-none-eabi-gcc", "arm-none-eabi-size", "qemu-system-arm"]
        .into_iter()
        .filter(|tool| !has(tool))
        .collect();
    if missing.is_empty() {
        return true;
    }
    let required = std::env::var("SEMO_CORTEX_M_TESTS").is_ok_and(|v| v == "require");
    assert!(
        !required,
        "{test}: SEMO_CORTEX_M_TESTS=require but {} missing (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm)",
        missing.join(", ")
    );
    eprintln!(
        "skipped {test}: {} not installed (CI installs them and sets SEMO_CORTEX_M_TESTS=require)",
        missing.join(", ")
    );
    false
}

/// `make` in a board robot's folder with warnings as errors (`-Wpedantic
/// -Werror -Os`); fails the test on an error or a warning.
pub fn make_board(folder: &Path) {
    let made = Command::new("make")
        .args([
            "-s",
            "-j2",
            "CFLAGS=-std=c11 -Wall -Wextra -Wpedantic -Werror -Os",
        ])
        .current_dir(folder)
        .output()
        .expect("make runs");
    let stderr = String::from_utf8_lossy(&made.stderr);
    assert!(
        made.status.success() && !stderr.contains("warning"),
        "{}: {stderr}",
        folder.display()
    );
}

/// Flash (text + data) and RAM (data + bss, the stack included) of an ELF file.
pub fn board_size(elf: &Path) -> (u64, u64) {
    let out = Command::new("arm-none-eabi-size")
        .arg(elf)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let numbers: Vec<u64> = text
        .lines()
        .nth(1)
        .expect("a line of sizes")
        .split_whitespace()
        .take(3)
        .map(|n| n.parse().unwrap())
        .collect();
    let (text, data, bss) = (numbers[0], numbers[1], numbers[2]);
    (text + data, data + bss)
}

/// gcc, and clang where it is installed (CI installs it).
pub fn compilers() -> Vec<&'static str> {
    let found: Vec<&str> = ["gcc", "clang"].into_iter().filter(|c| has(c)).collect();
    assert!(found.contains(&"gcc"), "gcc is required");
    if !found.contains(&"clang") {
        eprintln!("note: clang is not installed here; only gcc was tried (CI installs clang)");
    }
    found
}

/// Builds `mission` for `linux-sim` into `out` and compiles every robot
/// with gcc (pedantic, warnings as errors), then runs the generated robots
/// together on `scenario` (JSON text) in lock-step virtual time (`semo
/// simulate --engine c`, compiled with the same flags): no clock, so the
/// machine's load changes nothing. Each robot's trace lines, in its order.
pub fn run_in_simulation(
    mission: &Path,
    out: &Path,
    scenario: &str,
) -> BTreeMap<String, Vec<String>> {
    std::fs::create_dir_all(out).unwrap();
    let scenario_path = out.join("scenario.json");
    std::fs::write(&scenario_path, scenario).unwrap();
    let built = build_sim(mission, "linux-sim", &scenario_path, out);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    for folder in &robot_folders(out) {
        make(folder, "gcc", PEDANTIC).unwrap_or_else(|e| panic!("{e}"));
    }
    let run = super::simulate_trace_with(mission, &scenario_path, "c", PEDANTIC);
    assert!(run.code <= 1, "{}{}", run.stdout, run.stderr);
    let mut traces: BTreeMap<String, Vec<String>> = robot_folders(out)
        .iter()
        .map(|f| {
            (
                f.file_name().unwrap().to_string_lossy().into_owned(),
                Vec::new(),
            )
        })
        .collect();
    for line in run.stdout.lines() {
        let event: Event = serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"));
        let robot = event["robot"].as_str().expect("a robot").to_string();
        traces.entry(robot).or_default().push(line.to_string());
    }
    traces
}

/// A trace's lines as JSON objects.
pub fn events(lines: &[String]) -> Vec<Event> {
    lines
        .iter()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("bad trace line {l}: {e}")))
        .collect()
}

pub fn field<'e>(event: &'e Event, key: &str) -> &'e str {
    event.get(key).and_then(|v| v.as_str()).unwrap_or("")
}

/// The modes a robot entered, in order.
pub fn modes(events: &[Event]) -> Vec<String> {
    events
        .iter()
        .filter(|e| field(e, "event") == "mode")
        .map(|e| field(e, "mode").to_string())
        .collect()
}

/// Each robot's modes in `semo simulate` of `mission` on `scenario` (the
/// reference a run of real processes is compared with), by robot.
pub fn simulated_modes(
    mission: &std::path::Path,
    scenario: &std::path::Path,
) -> std::collections::BTreeMap<String, Vec<String>> {
    let simulated = super::simulate_trace(mission, scenario, "sim");
    assert_eq!(simulated.code, 0, "{}", simulated.stderr);
    let lines: Vec<String> = simulated.stdout.lines().map(str::to_string).collect();
    let mut by_robot: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for e in events(&lines) {
        if field(&e, "event") == "mode" {
            by_robot
                .entry(field(&e, "robot").to_string())
                .or_default()
                .push(field(&e, "mode").to_string());
        }
    }
    by_robot
}

/// The services a robot's tasks started, in order.
pub fn calls(events: &[Event]) -> Vec<String> {
    events
        .iter()
        .filter(|e| field(e, "event") == "call_start")
        .map(|e| field(e, "service").to_string())
        .collect()
}
