//! Code generation: the time of `semo build` on the scouting mission (target:
//! under 50 ms), and the footprint of a generated program, the remote-control
//! robot of `follow`: on target `linux` its peak RSS and VSZ (the thesis
//! measured 0.44 MB RSS / 25.55 MB VSZ for its generated remote-control
//! program) and its wake-ups per second while idle (voluntary context
//! switches of all its threads over one second), in the default build and
//! in `make STATIC=1` (musl, when `musl-gcc` is installed); the same for a
//! robot with no periods that waits for the operator (`fixtures/idle.mission`:
//! it should not wake at all); on target `cortex-m` the follow robot's flash
//! and RAM (`arm-none-eabi-size`; budget 32 KB / 8 KB).
//! Run with `cargo bench --bench codegen`; the second part needs `make` and
//! `cc`, the last `arm-none-eabi-gcc`.

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
    transaction
        .stage_runtime(&result.runtime, &[target], false)
        .expect("staged");
    for robot in &result.robots {
        transaction.stage_robot(robot, false).expect("staged");
    }
    let kept = transaction.commit().expect("written");
    assert!(kept.is_empty(), "{kept:?}");
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

/// Builds the follow robot for `linux` (default and `STATIC=1`) and
/// samples its memory and wake-ups while it runs; then for `cortex-m`.
fn follow_memory() {
    let out = scratch("follow");
    build(&shared("follow/follow.mission"), Target::Linux, &out);
    let folder = out.join("Team1/create1");
    for (label, args) in [
        ("default build", vec!["-s", "CFLAGS=-std=c11 -O2"]),
        (
            "make STATIC=1 TRANSPORT=udp (musl)",
            // musl has no libmosquitto: the static build keeps to loopback UDP.
            vec!["-s", "STATIC=1", "TRANSPORT=udp", "CFLAGS=-std=c11 -O2"],
        ),
    ] {
        let _ = Command::new("make")
            .args(["-s", "clean"])
            .current_dir(&folder)
            .status();
        let made = Command::new("make")
            .args(&args)
            .current_dir(&folder)
            .status();
        if !made.is_ok_and(|s| s.success()) {
            println!("follow robot (linux, {label}): skipped (make, cc or musl-gcc missing)");
            continue;
        }
        follow_run(&folder, "create1", label);
    }
    let _ = std::fs::remove_dir_all(&out);
    idle_robot();
    follow_cortex_m();
}

/// A robot with no sensor and no period, waiting for an operator command
/// that never comes: what wakes it is what polls.
fn idle_robot() {
    let out = scratch("idle");
    let mission = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/fixtures/idle.mission");
    build(&mission, Target::Linux, &out);
    let folder = out.join("Team1/waiter");
    let made = Command::new("make")
        .args(["-s", "TRANSPORT=udp", "CFLAGS=-std=c11 -O2"])
        .current_dir(&folder)
        .status();
    if made.is_ok_and(|s| s.success()) {
        follow_run(&folder, "waiter", "idle robot, no periods");
    } else {
        println!("idle robot (linux): skipped (make or cc missing)");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// Voluntary context switches of every thread of process `pid`.
fn wakeups(pid: u32) -> u64 {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return 0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("status")).ok())
        .filter_map(|status| {
            status
                .lines()
                .find(|l| l.starts_with("voluntary_ctxt_switches:"))?
                .split_whitespace()
                .nth(1)?
                .parse::<u64>()
                .ok()
        })
        .sum()
}

fn follow_run(folder: &Path, robot: &str, label: &str) {
    let port_base = (21000 + std::process::id() % 1000).to_string();
    let mut child = Command::new(folder.join(robot))
        .args(["--duration", "3000", "--port-base", &port_base])
        .spawn()
        .expect("the program starts");
    let (mut rss, mut vsz) = (0u64, 0u64);
    let status = format!("/proc/{}/status", child.id());
    let started = std::time::Instant::now();
    let (mut first, mut per_second) = (None, None);
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
        // Wake-ups over the second from 1 s to 2 s (after start-up).
        let elapsed = started.elapsed();
        if first.is_none() && elapsed >= Duration::from_secs(1) {
            first = Some(wakeups(child.id()));
        }
        if per_second.is_none() && elapsed >= Duration::from_secs(2) {
            per_second = first.map(|f| wakeups(child.id()).saturating_sub(f));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    println!(
        "{robot} robot (linux, -O2, {label}) while running: peak RSS {:.2} MB, VSZ {:.2} MB (thesis: 0.44 MB / 25.55 MB); {} wake-ups per second while idle",
        rss as f64 / 1024.0,
        vsz as f64 / 1024.0,
        per_second.map_or("?".to_string(), |n| n.to_string())
    );
}

/// Builds the follow robot for `cortex-m` and prints its flash and RAM.
fn follow_cortex_m() {
    let out = scratch("follow-cortex-m");
    build(&shared("follow/follow.mission"), Target::CortexM, &out);
    let folder = out.join("Team1/create1");
    let made = Command::new("make")
        .args(["-s"])
        .current_dir(&folder)
        .status();
    let sized = Command::new("arm-none-eabi-size")
        .arg(folder.join("create1.elf"))
        .output();
    match (made, sized) {
        (Ok(m), Ok(size)) if m.success() && size.status.success() => {
            let text = String::from_utf8_lossy(&size.stdout);
            let n: Vec<u64> = text
                .lines()
                .nth(1)
                .unwrap_or("")
                .split_whitespace()
                .take(3)
                .filter_map(|v| v.parse().ok())
                .collect();
            if let [text, data, bss] = n[..] {
                println!(
                    "follow robot (cortex-m, -Os): flash {} B, RAM {} B with a 2 KB stack (budget 32 KB / 8 KB)",
                    text + data,
                    data + bss
                );
            }
        }
        _ => println!("follow robot (cortex-m): skipped (arm-none-eabi-gcc missing)"),
    }
    let _ = std::fs::remove_dir_all(&out);
}
