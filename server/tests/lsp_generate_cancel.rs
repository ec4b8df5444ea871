//! Cancelling `semo.generateCode`: the generation stops before its next
//! robot and leaves the output folder as it was; a cancel that comes once
//! files are being replaced is too late, and the user is told. A test binary of
//! its own: it pauses the server's generations through the hidden
//! `SEMO_PAUSE_AFTER_FS_OPS` / `SEMO_PAUSE_SOCKET`, which hold for the whole
//! process.

use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::sync::mpsc;

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path)
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

/// Every entry under `dir` with its bytes (links and folders as such).
fn contents(dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    walk(dir, dir)
}

fn walk(root: &Path, dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut found = BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let meta = std::fs::symlink_metadata(&path).unwrap();
        let rel = path.strip_prefix(root).unwrap().to_path_buf();
        if meta.is_dir() {
            found.extend(walk(root, &path));
            found.insert(rel, None);
        } else {
            found.insert(rel, Some(std::fs::read(&path).unwrap()));
        }
    }
    found
}

/// Where the test holds a generation: given each paused step's line
/// (`paused N KIND`), whether to hand it to the test.
type HoldAt = std::sync::Arc<std::sync::Mutex<Box<dyn FnMut(&str) -> bool + Send>>>;

fn hold_at(when: impl FnMut(&str) -> bool + Send + 'static) -> Box<dyn FnMut(&str) -> bool + Send> {
    Box::new(when)
}

/// Answers the generations' pauses (one after every step): a step that
/// `hold` picks goes to the test, which lets it go on by sending `()`; the
/// others go on at once.
fn pause_answerer(socket: PathBuf, hold: HoldAt) -> (mpsc::Receiver<String>, mpsc::Sender<()>) {
    let (paused_tx, paused_rx) = mpsc::channel();
    let (go_tx, go_rx) = mpsc::channel::<()>();
    let listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    std::thread::spawn(move || {
        // One connection per pause; closing it lets the generation go on.
        for paused in listener.incoming() {
            let Ok(paused) = paused else { return };
            let mut line = String::new();
            if std::io::BufReader::new(&paused)
                .read_line(&mut line)
                .is_err()
            {
                return;
            }
            let held = (hold.lock().unwrap())(&line);
            if held && (paused_tx.send(line).is_err() || go_rx.recv().is_err()) {
                return;
            }
        }
    });
    (paused_rx, go_tx)
}

/// The line of the next held pause.
fn next_pause(paused: &mpsc::Receiver<String>) -> String {
    tokio::task::block_in_place(|| paused.recv().unwrap())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cancelled_generation_leaves_the_output_folder_as_it_was() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lsp_generate_cancel");
    let _ = std::fs::remove_dir_all(&dir);
    let ws = dir.join("ws");
    std::fs::create_dir_all(&ws).unwrap();
    for file in ["scouting.mission", "MasterTeam.strategy.xml"] {
        std::fs::copy(example(&format!("scouting/{file}")), ws.join(file)).unwrap();
    }
    // What a simulation compiles in (`linux-sim` needs a scenario).
    std::fs::write(ws.join("quiet.scenario.json"), r#"{"duration": 2000}"#).unwrap();
    let socket = dir.join("pause");
    // Every generation pauses after its first file operation (the first
    // file staged for its first robot).
    // SAFETY: set before the server starts; no other thread reads the
    // environment yet.
    let every_step: Vec<String> = (1..=5000).map(|n| n.to_string()).collect();
    unsafe {
        std::env::set_var("SEMO_PAUSE_AFTER_FS_OPS", every_step.join(","));
        std::env::set_var("SEMO_PAUSE_SOCKET", &socket);
    }
    let first_step = || hold_at(|line| line.starts_with("paused 1 "));
    let hold: HoldAt = std::sync::Arc::new(std::sync::Mutex::new(first_step()));
    let (paused, go) = pause_answerer(socket, hold.clone());
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&ws))).await;
    let mission = ws.join("scouting.mission");
    let mission_uri = uri(&mission);
    client
        .open(&mission_uri, &std::fs::read_to_string(&mission).unwrap())
        .await;
    client.diagnostics(&mission_uri, Some(1)).await;
    let generate = |target: &str| {
        json!({
            "command": "semo.generateCode",
            "arguments": [if target.ends_with("-sim") {
                json!({ "uri": mission_uri, "target": target, "scenario": "quiet.scenario.json" })
            } else {
                json!({ "uri": mission_uri, "target": target })
            }],
        })
    };
    // A first generation, let through.
    let id = client
        .send_request("workspace/executeCommand", generate("linux"))
        .await;
    let line = next_pause(&paused);
    assert!(line.starts_with("paused 1 "), "{line}");
    go.send(()).unwrap();
    let first = client.response(id).await.unwrap();
    assert_eq!(first["refused"], false, "{first}");
    assert_eq!(first["robots"].as_array().unwrap().len(), 3, "{first}");
    let out = ws.join("out");
    let before = contents(&out);
    // A second one, for another target (every file changes), cancelled
    // while it stages its first robot.
    let id = client
        .send_request("workspace/executeCommand", generate("linux-sim"))
        .await;
    let line = next_pause(&paused);
    assert!(line.starts_with("paused 1 "), "{line}");
    client.notify("$/cancelRequest", json!({ "id": id })).await;
    let cancelled = client.response(id).await.unwrap_err();
    assert_eq!(cancelled["code"], -32800, "{cancelled}");
    go.send(()).unwrap();
    // Once the generation has let the folder go (its lock, waited for by
    // util-linux's `flock`), it is as it was.
    let released = tokio::task::block_in_place(|| {
        std::process::Command::new("flock")
            .arg(out.join(".semo.lock"))
            .arg("true")
            .status()
            .unwrap()
    });
    assert!(released.success());
    assert_eq!(
        contents(&out).keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>()
    );
    assert!(contents(&out) == before, "a robot folder changed");
    // The server goes on generating.
    let id = client
        .send_request("workspace/executeCommand", generate("linux-sim"))
        .await;
    let line = next_pause(&paused);
    assert!(line.starts_with("paused 1 "), "{line}");
    go.send(()).unwrap();
    let done: Value = client.response(id).await.unwrap();
    assert_eq!(done["target"], "linux-sim", "{done}");
    assert!(contents(&out) != before);

    // A cancel that comes once the files are replaced (after the
    // generation's second sync, which makes the replacement durable) is too
    // late: the generation finishes, and the user is told so, since the
    // client got `Canceled` and shows no outcome.
    let before = contents(&out);
    let mut syncs = 0;
    *hold.lock().unwrap() = hold_at(move |line| {
        syncs += usize::from(line.trim_end().ends_with(" sync"));
        syncs == 2 && line.trim_end().ends_with(" sync")
    });
    let id = client
        .send_request("workspace/executeCommand", generate("linux"))
        .await;
    let line = next_pause(&paused);
    assert!(line.trim_end().ends_with(" sync"), "{line}");
    client.notify("$/cancelRequest", json!({ "id": id })).await;
    let cancelled = client.response(id).await.unwrap_err();
    assert_eq!(cancelled["code"], -32800, "{cancelled}");
    go.send(()).unwrap();
    let told = client
        .notification("window/showMessage", |m| {
            m["message"]
                .as_str()
                .is_some_and(|t| t.contains("cancelled too late"))
        })
        .await;
    assert_eq!(told["type"], 2, "a warning: {told}");
    assert!(
        told["message"].as_str().unwrap().contains("3 robot(s)"),
        "{told}"
    );
    let after = contents(&out);
    assert!(after != before, "the generation finished");
    assert!(
        after.keys().all(|p| !p.starts_with(".semo-work")),
        "no work left: {:?}",
        after.keys().collect::<Vec<_>>()
    );
    client.shutdown().await;
}
