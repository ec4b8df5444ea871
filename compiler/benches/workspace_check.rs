//! `semo check DIR` throughput on a big workspace: what the command does
//! before rendering (`host::load_check`: walk the folder, read every file,
//! check every mission against the catalogs and strategy files it sees,
//! cross-check the strategies, analyse the task graphs). The workspace is the
//! repository's `examples/` copied `SEMO_BENCH_COPIES` times (default 20)
//! into folders of a temporary directory, plus generated 1k-line missions
//! (one folder each, `SEMO_BENCH_BIG`, default 10). Prints files/s and MB/s
//! of the fastest run. Run with `cargo bench -p semo --bench workspace_check`.
//! `SEMO_BENCH_WORKSPACE=DIR` writes the workspace into `DIR` and keeps it
//! (to time `semo check DIR` as a whole process, old binary against new).

mod common;
use common::fastest;
use common::mission::generate;

use std::path::{Path, PathBuf};
use std::time::Duration;

fn env_or(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Copies the files of `from` (recursively) into `to`; gives their count and bytes.
fn copy_tree(from: &Path, to: &Path) -> (usize, usize) {
    std::fs::create_dir_all(to).expect("create a folder");
    let (mut files, mut bytes) = (0, 0);
    for entry in std::fs::read_dir(from).expect("read examples") {
        let entry = entry.expect("an entry");
        let target = to.join(entry.file_name());
        if entry.file_type().expect("a type").is_dir() {
            let (f, b) = copy_tree(&entry.path(), &target);
            files += f;
            bytes += b;
        } else {
            bytes += std::fs::copy(entry.path(), &target).expect("copy") as usize;
            files += 1;
        }
    }
    (files, bytes)
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument is accepted and ignored.
    let copies = env_or("SEMO_BENCH_COPIES", 20);
    let big = env_or("SEMO_BENCH_BIG", 10);
    let kept = std::env::var_os("SEMO_BENCH_WORKSPACE").map(PathBuf::from);
    let root: PathBuf = kept.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("semo-bench-ws-{}", std::process::id()))
    });
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let (mut files, mut bytes) = (0, 0);
    for i in 0..copies {
        let (f, b) = copy_tree(&examples, &root.join(format!("copy{i}")));
        files += f;
        bytes += b;
    }
    let mission = generate(20);
    for i in 0..big {
        let folder = root.join(format!("big{i}"));
        std::fs::create_dir_all(&folder).expect("create a folder");
        std::fs::write(folder.join("big.mission"), &mission).expect("write a mission");
        files += 1;
        bytes += mission.len();
    }
    let run = semo::host::load_check(std::slice::from_ref(&root)).expect("load the workspace");
    println!(
        "workspace: {files} files, {:.2} MB ({copies} copies of examples/, {big} missions of {} lines); {} diagnostics",
        bytes as f64 / 1e6,
        mission.lines().count(),
        run.diagnostics.len()
    );
    drop(run);
    let best = fastest(Duration::from_secs(5), || {
        let run = semo::host::load_check(std::slice::from_ref(&root)).expect("load");
        std::hint::black_box(run.diagnostics.len());
    });
    let secs = best.as_secs_f64();
    println!(
        "semo check DIR: {:.1} ms, {:.0} files/s, {:.1} MB/s",
        secs * 1e3,
        files as f64 / secs,
        bytes as f64 / 1e6 / secs
    );
    if kept.is_none() {
        std::fs::remove_dir_all(&root).expect("remove the workspace");
    }
}
