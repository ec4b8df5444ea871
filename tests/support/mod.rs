//! Helpers shared by the end-to-end tests: running the real `semo` binary.
#![allow(dead_code)]

pub mod cc;
pub mod differential;
pub mod markdown;
pub mod missiongen;
pub mod mosquitto;
pub mod mqtt;
pub mod proxy;
pub mod python;
pub mod qemu;
pub mod robots;
pub mod swap;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root (the parent of `compiler/`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("compiler/ has a parent")
        .to_path_buf()
}

/// The bundled examples: the reference missions, strategies and task graphs (copied from the
/// project's shared reference material, see `examples/README.md`) and our own.
pub fn examples() -> PathBuf {
    repo_root().join("examples")
}

/// The SDF3 benchmark graphs (`tests/data/sdf3/README.md` says where they come from).
pub fn sdf3() -> PathBuf {
    repo_root().join("tests/data/sdf3")
}

pub struct Output {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

impl Output {
    /// A finished process's status and output, as text.
    fn of(out: std::process::Output) -> Output {
        Output {
            code: out.status.code().unwrap_or(-1),
            stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }
}

/// Runs `semo ARGS` in `dir`.
pub fn semo_in(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("the semo binary runs");
    Output::of(out)
}

/// `semo simulate MISSION --scenario SCENARIO --engine ENGINE --trace -`
/// (`sim`: the simulator; `c`: the generated programs in lock-step): the
/// run, its trace on standard output. The C is compiled at `-O1` (the
/// Makefile's `CFLAGS`), not the default `-O2`: what these tests compare is
/// the programs' meaning, which no optimization level may change, and `-O1`
/// halves gcc's time, most of theirs. `tests/build.rs` compiles every
/// example at the default level with warnings as errors, and the
/// sanitizer tests run optimized programs.
pub fn simulate_trace(mission: &Path, scenario: &Path, engine: &str) -> Output {
    simulate_trace_with(mission, scenario, engine, "-std=c11 -Wall -Wextra -O1")
}

/// [`simulate_trace`] with the C compiled with `cflags`.
pub fn simulate_trace_with(mission: &Path, scenario: &Path, engine: &str, cflags: &str) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(["simulate", &mission.display().to_string()])
        .args(["--scenario", &scenario.display().to_string()])
        .args(["--engine", engine, "--trace", "-"])
        .current_dir(repo_root())
        .env("NO_COLOR", "1")
        .env("CFLAGS", cflags)
        .output()
        .expect("the semo binary runs");
    Output::of(out)
}

/// Runs `semo ARGS` in `dir` with `input` on its standard input.
pub fn semo_with_stdin(dir: &Path, args: &[&str], input: &str) -> Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the semo binary runs");
    // A command may end without reading its input (a usage error): a
    // broken pipe here is its answer, not the test's failure.
    match child
        .stdin
        .take()
        .expect("stdin is piped")
        .write_all(input.as_bytes())
    {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {}
        written => written.expect("write stdin"),
    }
    let out = child.wait_with_output().expect("semo finishes");
    Output::of(out)
}

pub fn semo(args: &[&str]) -> Output {
    semo_in(&repo_root(), args)
}

/// One diagnostic of `semo check --format json`.
#[derive(Debug, Clone)]
pub struct Diag {
    pub code: String,
    pub severity: String,
    pub file: String,
    pub start: (u64, u64),
    pub end: (u64, u64),
    pub message: String,
    pub suggestion: Option<String>,
}

/// The diagnostics of a `--format json` document (docs/diagnostics-json.md).
pub fn parse_json_report(stdout: &str) -> Vec<Diag> {
    let document: serde_json::Value =
        serde_json::from_str(stdout).expect("the output is one JSON document");
    assert_eq!(document["version"], 1, "{document}");
    document["diagnostics"]
        .as_array()
        .expect("a diagnostics array")
        .iter()
        .map(|v| {
            let pos = |key: &str| {
                (
                    v[key]["line"].as_u64().expect("line"),
                    v[key]["column"].as_u64().expect("column"),
                )
            };
            Diag {
                code: v["code"].as_str().expect("code").to_string(),
                severity: v["severity"].as_str().expect("severity").to_string(),
                file: v["file"].as_str().expect("file").to_string(),
                start: pos("start"),
                end: pos("end"),
                message: v["message"].as_str().expect("message").to_string(),
                suggestion: v["suggestion"].as_str().map(str::to_string),
            }
        })
        .collect()
}

/// `semo check --format json ARGS` in `dir`, parsed.
pub fn check_json_in(dir: &Path, paths: &[&str]) -> (i32, Vec<Diag>) {
    let mut args = vec!["check", "--format", "json"];
    args.extend_from_slice(paths);
    let out = semo_in(dir, &args);
    assert!(
        out.code == 0 || out.code == 1,
        "exit {}: {}",
        out.code,
        out.stderr
    );
    (out.code, parse_json_report(&out.stdout))
}

/// A compact, readable listing for snapshots: `file:line:col-line:col CODE severity: message`.
pub fn listing(diags: &[Diag]) -> String {
    let mut s = String::new();
    for d in diags {
        s.push_str(&format!(
            "{}:{}:{}-{}:{} {} {}: {}\n",
            d.file, d.start.0, d.start.1, d.end.0, d.end.1, d.code, d.severity, d.message
        ));
    }
    s
}
