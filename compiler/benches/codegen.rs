//! Code generation: the time of `semo build` on the scouting mission (target:
//! under 50 ms), and the memory of a generated program, the remote-control
//! robot of `follow` on target `linux` (the thesis measured 0.44 MB RSS /
//! 25.55 MB VSZ for its generated remote-control program). Run with
//! `cargo bench --bench codegen`; the second part needs `make` and `cc`.

mod common;
use common::fastest;

use semo::codegen::{self, Emit, Target, output};
use semo::host::{AnalysisHost, load_build as load};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

fn shared(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("semo-bench-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn build(mission: &Path, target: Target, out: &Path) {
    let (run, id) = load(mission, &[]).expect("the example loads");
    let build = run
        .analysis()
        .build_input(id)
        .expect("the mission is checked");
    let result = codegen::build(&build.input(), target, Emit::All);
    assert!(!result.refused(), "{:#?}", result.diagnostics);
    let mut transaction = output::Transaction::begin(out, || {}).expect("the output folder");
    for robot in &result.robots {
        transaction
            .write_robot(robot, target, false)
            .expect("written");
    }
}

fn main() {
    let mission = shared("scouting/scouting.mission");
    for target in [Target::Linux, Target::LinuxSim] {
        let (run, id) = load(&mission, &[]).unwrap();
        let in_memory = fastest(Duration::from_secs(2), || {
            // A fresh host each time: nothing memoised from the last run.
            let mut host = AnalysisHost::new(run.host.roots().clone());
            for f in run.files.iter() {
                host.set_file(f.id, Some(f.path.clone()), f.kind, f.text.as_str().into());
            }
            let build = host
                .analysis()
                .build_input(id)
                .expect("the mission is checked");
            let result = codegen::build(&build.input(), target, Emit::All);
            std::hint::black_box(result.robots.len());
        });
        let out = scratch("scouting");
        let whole = fastest(Duration::from_secs(2), || build(&mission, target, &out));
        println!(
            "semo build scouting ({}): {:.2} ms in memory (read, check, refine, generate); {:.2} ms with writing 3 robot folders",
            target.name(),
            in_memory.as_secs_f64() * 1e3,
            whole.as_secs_f64() * 1e3
        );
        let _ = std::fs::remove_dir_all(&out);
    }
    follow_memory();
}

/// Builds the follow robot for `linux` and samples its memory while it runs.
fn follow_memory() {
    let out = scratch("follow");
    build(&shared("follow/follow.mission"), Target::Linux, &out);
    let folder = out.join("Team1/create1");
    let made = Command::new("make")
        .args(["-s", "CFLAGS=-std=c11 -O2"])
        .current_dir(&folder)
        .status();
    if !made.is_ok_and(|s| s.success()) {
        println!("follow memory: skipped (make or cc missing)");
        return;
    }
    let port_base = (21000 + std::process::id() % 1000).to_string();
    let mut child = Command::new(folder.join("create1"))
        .args(["--duration", "2000", "--port-base", &port_base])
        .spawn()
        .expect("the program starts");
    let (mut rss, mut vsz) = (0u64, 0u64);
    let status = format!("/proc/{}/status", child.id());
    while child.try_wait().ok().flatten().is_none() {
        if let Ok(text) = std::fs::read_to_string(&status) {
            for line in text.lines() {
                let kb = |l: &str| {
                    l.split_whitespace()
                        .nth(1)
                        .and_then(|v| v.parse::<u64>().ok())
                };
                if line.starts_with("VmRSS:") {
                    rss = rss.max(kb(line).unwrap_or(0));
                } else if line.starts_with("VmSize:") {
                    vsz = vsz.max(kb(line).unwrap_or(0));
                }
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    println!(
        "follow robot (linux, -O2) while running: peak RSS {:.2} MB, VSZ {:.2} MB (thesis: 0.44 MB / 25.55 MB)",
        rss as f64 / 1024.0,
        vsz as f64 / 1024.0
    );
    let _ = std::fs::remove_dir_all(&out);
}
