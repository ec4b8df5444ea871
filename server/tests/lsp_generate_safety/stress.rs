//! Stress runs of issue 33's editor findings, measured as counts: Generate
//! Code (`semo.generateCode` through the language server) while a thread
//! swaps the output folder (or a robot folder) for a link out of the
//! workspace, and Generate Code requests cancelled at varied moments. Each
//! run prints its counts as one line (`stress: ...`) and asserts the zero,
//! which holds whatever the interleaving: a small run of each is a plain
//! test, the sizes the issue quotes are the `#[ignore]`d runs.
//!
//! The cancellations are here rather than in `lsp_generate_cancel.rs`: that
//! binary pauses every generation of its process (the pause variables are
//! read once per process), and these must run free.

use super::{generate, uri};

#[path = "../../../tests/support/swap.rs"]
mod swap;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use swap::{clear_set_aside, swapper};

/// A stress run's size: `var` if set, else `default`.
fn sized(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// `<scratch>/<name>/ws` holding the scouting example and a scenario for
/// `linux-sim`; a server started on it, the mission open.
async fn scouting(name: &str) -> (semo_server::harness::TestClient, String, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("lsp_generate_safety")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let ws = dir.join("ws");
    std::fs::create_dir_all(&ws).unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scouting");
    for file in ["scouting.mission", "MasterTeam.strategy.xml"] {
        std::fs::copy(example.join(file), ws.join(file)).unwrap();
    }
    std::fs::write(ws.join("quiet.scenario.json"), r#"{"duration": 2000}"#).unwrap();
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&ws))).await;
    let mission = ws.join("scouting.mission");
    let mission_uri = uri(&mission);
    client
        .open(&mission_uri, &std::fs::read_to_string(&mission).unwrap())
        .await;
    client.diagnostics(&mission_uri, Some(1)).await;
    (client, mission_uri, ws)
}

/// Generate Code's arguments for `target` (every file differs between
/// `linux` and `linux-sim`).
fn for_target(mission_uri: &str, target: &str) -> Value {
    if target == "linux-sim" {
        json!({ "uri": mission_uri, "target": target, "scenario": "quiet.scenario.json" })
    } else {
        json!({ "uri": mission_uri, "target": target })
    }
}

const TARGETS: [&str; 2] = ["linux", "linux-sim"];

/// Every entry under `dir` with its bytes (links and folders as such),
/// but generation's own bookkeeping (`.semo*`: lock, manifests, work and
/// backup folders), which says when, not what.
fn generated(dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut found = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(".semo")
            {
                continue;
            }
            let meta = std::fs::symlink_metadata(&path).unwrap();
            let rel = path.strip_prefix(dir).unwrap().to_path_buf();
            if meta.is_dir() {
                stack.push(path);
                found.insert(rel, None);
            } else if meta.is_symlink() {
                found.insert(rel, Some(b"-> link".to_vec()));
            } else {
                found.insert(rel, Some(std::fs::read(&path).unwrap()));
            }
        }
    }
    found
}

/// Waits until no generation holds `out` (its lock, through util-linux's
/// `flock`): a cancelled request is answered at once, its work stops at
/// its next check.
fn released(out: &Path) {
    let status = tokio::task::block_in_place(|| {
        std::process::Command::new("flock")
            .arg(out.join(".semo.lock"))
            .arg("true")
            .status()
            .unwrap()
    });
    assert!(status.success());
}

/// What the cancellation runs counted.
#[derive(Default, Debug)]
struct CancelCounts {
    requests: usize,
    cancelled: usize,
    /// Cancelled, and the folder as it was.
    as_it_was: usize,
    /// Answered `Canceled` once the generation had begun replacing files
    /// (its last step, which is not stopped half-way): the new folder whole.
    cancelled_too_late: usize,
    /// Of those, told by a warning that the code was written.
    told_too_late: usize,
    /// Done before the cancellation came: the new folder whole.
    completed: usize,
    /// Neither the old folder nor the new one whole.
    partial: usize,
}

/// `requests` Generate Code requests, each for the other target (so that
/// every file changes), each cancelled after a delay stepping through the
/// length of one uncancelled generation (plus a fifth), and after each the
/// output folder compared with the folder before and with a whole
/// generation for the target.
async fn cancellations(name: &str, requests: usize) -> CancelCounts {
    let (mut client, mission_uri, ws) = scouting(name).await;
    let out = ws.join("out");
    let mut whole = BTreeMap::new();
    let mut took = Duration::ZERO;
    // Twice round: a switch leaves the files only the other target writes
    // (`linux-sim`'s scenario), so the folder is whole for a target once it
    // has been generated for both.
    for target in TARGETS.iter().chain(&TARGETS).copied() {
        let (method, params) = generate(for_target(&mission_uri, target));
        let began = Instant::now();
        let done = client.request(method, params).await.unwrap();
        took = took.max(began.elapsed());
        assert_eq!(done["refused"], false, "{done}");
        whole.insert(target, generated(&out));
    }
    assert_ne!(whole["linux"], whole["linux-sim"]);
    let mut counts = CancelCounts::default();
    let mut current = "linux-sim";
    for i in 0..requests {
        let target = if current == "linux" {
            "linux-sim"
        } else {
            "linux"
        };
        let before = generated(&out);
        let delay = took.mul_f64(1.2 * i as f64 / requests.max(1) as f64);
        let (method, params) = generate(for_target(&mission_uri, target));
        let id = client.send_request(method, params).await;
        tokio::time::sleep(delay).await;
        client.notify("$/cancelRequest", json!({ "id": id })).await;
        let answer = client.response(id).await;
        released(&out);
        let after = generated(&out);
        counts.requests += 1;
        let new_whole = after == whole[target];
        match answer {
            Ok(done) => {
                assert_eq!(done["refused"], false, "{done}");
                counts.completed += 1;
                if !new_whole {
                    eprintln!("request {i}: completed, folder not whole");
                    counts.partial += 1;
                }
            }
            Err(e) => {
                assert_eq!(e["code"], -32800, "request {i}: {e}");
                counts.cancelled += 1;
                if after == before {
                    counts.as_it_was += 1;
                } else if new_whole {
                    counts.cancelled_too_late += 1;
                    // The client got `Canceled`: the server says the code
                    // was written all the same.
                    client
                        .notification("window/showMessage", |m| {
                            (m["message"].as_str())
                                .is_some_and(|t| t.contains("cancelled too late"))
                        })
                        .await;
                    counts.told_too_late += 1;
                } else {
                    let changed: Vec<_> = after
                        .iter()
                        .filter(|(p, c)| before.get(*p) != Some(c))
                        .map(|(p, _)| p)
                        .collect();
                    eprintln!("request {i}: cancelled after {delay:?}, partial: {changed:?}");
                    counts.partial += 1;
                }
            }
        }
        if new_whole {
            current = target;
        }
    }
    client.shutdown().await;
    counts
}

fn print_cancellations(c: &CancelCounts) {
    eprintln!(
        "stress: {} Generate Code requests cancelled at varied moments: {} answered Canceled ({} left the folder as it was, \
         {} came once the files were being replaced and the new folder is whole, {} of them told so), {} completed first; \
         {} left the folder partial",
        c.requests,
        c.cancelled,
        c.as_it_was,
        c.cancelled_too_late,
        c.told_too_late,
        c.completed,
        c.partial
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn generate_code_cancelled_at_varied_moments_never_leaves_a_partial_folder() {
    let counts = cancellations("stress-cancel-small", 6).await;
    print_cancellations(&counts);
    assert_eq!(counts.partial, 0, "{counts:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "stress run (a few minutes): cargo test -p semo-server --test lsp_generate_safety -- --ignored stress_"]
async fn stress_generate_code_cancelled_at_varied_moments() {
    let counts = cancellations("stress-cancel", sized("SEMO_STRESS_REQUESTS", 100)).await;
    print_cancellations(&counts);
    assert_eq!(counts.partial, 0, "{counts:?}");
}

/// The first robot folder (`<team>/<robot>`) generation wrote in `out`.
fn first_robot_folder(out: &Path) -> PathBuf {
    let mut folders: Vec<PathBuf> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            p.is_dir() && !name.starts_with('.') && name != "semo-runtime"
        })
        .flat_map(|team| std::fs::read_dir(team).unwrap().map(|e| e.unwrap().path()))
        .filter(|p| p.is_dir() && !p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    folders.sort();
    folders.into_iter().next().expect("a robot folder")
}

/// What the link-swap runs counted.
#[derive(Default, Debug)]
struct SwapCounts {
    generations: usize,
    swaps: usize,
    refused: usize,
    outside: usize,
}

/// `generations` Generate Code requests (alternating the targets) while a
/// swapper turns the output folder (`robot`: a robot folder) into a link to
/// a folder outside the workspace and back: the entries that appear there.
async fn links_swapped(name: &str, robot: bool, generations: usize) -> SwapCounts {
    let (mut client, mission_uri, ws) = scouting(name).await;
    let out = ws.join("out");
    let (method, params) = generate(for_target(&mission_uri, "linux"));
    client.request(method, params).await.unwrap();
    let outside = ws.parent().unwrap().join("elsewhere");
    let real = if robot {
        first_robot_folder(&out)
    } else {
        out.clone()
    };
    assert!(real.is_dir(), "{}", real.display());
    let mut counts = SwapCounts::default();
    for i in 0..generations {
        let _ = std::fs::remove_dir_all(&outside);
        std::fs::create_dir_all(&outside).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let handle = swapper(real.clone(), outside.clone(), stop.clone());
        let (method, params) = generate(for_target(&mission_uri, TARGETS[(i + 1) % 2]));
        let answer = client.request(method, params).await;
        stop.store(true, Ordering::SeqCst);
        counts.swaps += tokio::task::block_in_place(|| handle.join().unwrap());
        counts.generations += 1;
        match answer {
            Ok(done) => counts.refused += usize::from(done["refused"] != false),
            Err(e) => {
                assert!(e["code"].is_i64(), "{e}");
                counts.refused += 1;
            }
        }
        let written = generated(&outside);
        if !written.is_empty() {
            eprintln!("generation {i}: written outside: {:?}", written.keys());
        }
        counts.outside += written.len();
        clear_set_aside(&real);
    }
    client.shutdown().await;
    counts
}

fn print_swaps(what: &str, c: &SwapCounts) {
    eprintln!(
        "stress: {what} swapped for a link out of the workspace {} times during {} editor generations \
         ({} refused or stopped), {} entries written outside",
        c.swaps, c.generations, c.refused, c.outside
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn no_link_swapped_in_a_loop_during_editor_generations_is_followed_out() {
    for (what, robot) in [("the output folder", false), ("a robot folder", true)] {
        let counts = links_swapped(&format!("stress-links-small-{robot}"), robot, 3).await;
        print_swaps(what, &counts);
        assert_eq!(counts.outside, 0, "{what}: {counts:?}");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "stress run (a few minutes): cargo test -p semo-server --test lsp_generate_safety -- --ignored stress_"]
async fn stress_links_swapped_during_editor_generations() {
    let generations = sized("SEMO_STRESS_REQUESTS", 100);
    let mut outside = 0;
    for (what, robot) in [("the output folder", false), ("a robot folder", true)] {
        let counts = links_swapped(&format!("stress-links-{robot}"), robot, generations).await;
        print_swaps(what, &counts);
        outside += counts.outside;
    }
    assert_eq!(outside, 0);
}
