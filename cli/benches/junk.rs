//! Junk input (issue 21): 10 MB of random bytes, and long runs of NUL bytes,
//! through `semo check` (the real binary, reading, checking and rendering)
//! and through the language server (opened as a mission, then edited: the
//! time from each edit to its diagnostics). Targets: under 1 s for the check,
//! under 100 ms per edit. Run with `cargo bench -p semo-cli --bench junk`.
//!
//! Besides wall-clock times it reports CPU times (user + system, from
//! `/proc/self/stat`: the `semo check` child's, and this process's over the
//! edits, where the server runs in-process), which stay meaningful when other
//! work shares the machine's cores.

use semo_server::harness::TestClient;
use serde_json::json;
use std::time::{Duration, Instant};

/// `len` pseudo-random bytes (xorshift, fixed seed: every run sees the same).
fn random_bytes(len: usize) -> Vec<u8> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    (0..len)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 24) as u8
        })
        .collect()
}

fn fastest(runs: usize, mut f: impl FnMut() -> Duration) -> Duration {
    (0..runs).map(|_| f()).min().unwrap_or_default()
}

/// CPU time (user + system) used so far by this process (`self_`) and by its
/// waited-for children, from `/proc/self/stat` (in clock ticks of 10 ms).
fn cpu_times() -> (Duration, Duration) {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<u64> = rest
        .split_whitespace()
        .map(|f| f.parse().unwrap_or(0))
        .collect();
    // utime, stime, cutime, cstime are fields 14..=17, i.e. 11..=14 here.
    let ticks = |i: usize| fields.get(i).copied().unwrap_or(0);
    let tick = Duration::from_millis(10);
    (
        tick * (ticks(11) + ticks(12)) as u32,
        tick * (ticks(13) + ticks(14)) as u32,
    )
}

fn main() {
    let dir = std::env::temp_dir().join(format!("semo-bench-junk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let inputs = [
        ("10 MB random bytes", random_bytes(10 * 1024 * 1024)),
        ("200k NUL bytes", vec![0u8; 200_000]),
        ("4 MB NUL bytes", vec![0u8; 4 * 1024 * 1024]),
    ];
    for (name, bytes) in &inputs {
        let path = dir.join("junk.mission");
        std::fs::write(&path, bytes).unwrap();
        let mut diagnostics = 0;
        let mut cpu = Duration::MAX;
        let check = fastest(3, || {
            let children_before = cpu_times().1;
            let start = Instant::now();
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_semo"))
                .args(["check", "--format", "json"])
                .arg(&path)
                .output()
                .unwrap();
            let elapsed = start.elapsed();
            cpu = cpu.min(cpu_times().1 - children_before);
            // One JSON object per diagnostic, one per line.
            diagnostics = out
                .stdout
                .split(|&b| b == b'\n')
                .filter(|l| !l.is_empty())
                .count();
            elapsed
        });
        println!(
            "semo check, {name}: {:.0} ms, CPU {:.0} ms ({diagnostics} diagnostics)",
            check.as_secs_f64() * 1e3,
            cpu.as_secs_f64() * 1e3
        );
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    for (name, bytes) in &inputs {
        let text = String::from_utf8_lossy(bytes).into_owned();
        let per_edit = runtime.block_on(server_edits(&text, 20));
        println!(
            "server re-check per edit, {name}: median {:.1} ms, max {:.1} ms, CPU {:.1} ms per edit",
            per_edit.0.as_secs_f64() * 1e3,
            per_edit.1.as_secs_f64() * 1e3,
            per_edit.2.as_secs_f64() * 1e3
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Opens `text` as a mission and types `edits` characters at its start; the
/// median and the longest time from an edit to its diagnostics, and the CPU
/// time per edit (all threads).
async fn server_edits(text: &str, edits: i64) -> (Duration, Duration, Duration) {
    const URI: &str = "file:///bench/junk.mission";
    let mut client = TestClient::start();
    client.initialize(&["utf-8"], None).await;
    client.open(URI, text).await;
    client.diagnostics(URI, Some(1)).await;
    let mut times = Vec::new();
    let cpu_before = cpu_times().0;
    for version in 2..2 + edits {
        let start = Instant::now();
        client
            .notify(
                "textDocument/didChange",
                json!({
                    "textDocument": { "uri": URI, "version": version },
                    "contentChanges": [{
                        "range": { "start": { "line": 0, "character": 0 },
                                   "end": { "line": 0, "character": 0 } },
                        "text": "x"
                    }]
                }),
            )
            .await;
        client.diagnostics(URI, Some(version)).await;
        times.push(start.elapsed());
    }
    let cpu = (cpu_times().0 - cpu_before) / edits as u32;
    client.shutdown().await;
    times.sort();
    (times[times.len() / 2], times[times.len() - 1], cpu)
}
