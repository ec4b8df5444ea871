//! `semo.generateCode` from a careless or hostile editor (issue 21): output
//! folders outside the workspace are refused, requests at once never
//! interleave or lose an edit, edited files stop a target switch unless
//! forced; and the protocol's promises (every request answered).

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path)
}

/// `<scratch>/<name>/ws`, a workspace folder holding the follow example.
fn workspace(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("lsp_generate_safety")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let ws = dir.join("ws");
    std::fs::create_dir_all(&ws).unwrap();
    std::fs::copy(example("follow/follow.mission"), ws.join("follow.mission")).unwrap();
    ws
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

async fn started(ws: &Path) -> (semo_server::harness::TestClient, String) {
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(ws))).await;
    let mission = ws.join("follow.mission");
    let mission_uri = uri(&mission);
    client
        .open(&mission_uri, &std::fs::read_to_string(&mission).unwrap())
        .await;
    client.diagnostics(&mission_uri, Some(1)).await;
    (client, mission_uri)
}

fn generate(arguments: Value) -> (&'static str, Value) {
    (
        "workspace/executeCommand",
        json!({ "command": "semo.generateCode", "arguments": [arguments] }),
    )
}

fn message(error: &Value) -> String {
    error["message"].as_str().unwrap_or_default().to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn output_folders_outside_the_workspace_are_refused() {
    let ws = workspace("outside");
    let outside = ws.parent().unwrap().join("elsewhere");
    std::fs::create_dir_all(&outside).unwrap();
    std::os::unix::fs::symlink(&outside, ws.join("link")).unwrap();
    let (mut client, mission_uri) = started(&ws).await;
    let absolute = outside.join("abs").display().to_string();
    for folder in [
        "..",
        "../../..",
        "../elsewhere",
        &absolute,
        "link",
        "link/out",
        "gen/../../x",
        "new/../link/x",
    ] {
        let (method, params) = generate(json!({ "uri": mission_uri, "outputFolder": folder }));
        let refused = client.request(method, params).await.unwrap_err();
        let text = message(&refused);
        assert!(text.contains("outside the workspace"), "{folder}: {text}");
    }
    assert_eq!(
        std::fs::read_dir(&outside).unwrap().count(),
        0,
        "nothing written outside"
    );
    assert!(!ws.parent().unwrap().join("Team1").exists());
    // Inside the workspace, `..` that stays inside is fine.
    let (method, params) = generate(json!({ "uri": mission_uri, "outputFolder": "a/../gen" }));
    let done = client.request(method, params).await.unwrap();
    assert_eq!(done["refused"], false, "{done}");
    assert!(ws.join("gen/Team1/create1/main.c").exists());
    // A team folder turned into a link out of the workspace: refused too.
    std::fs::remove_dir_all(ws.join("gen/Team1")).unwrap();
    std::os::unix::fs::symlink(&outside, ws.join("gen/Team1")).unwrap();
    let (method, params) = generate(json!({ "uri": mission_uri, "outputFolder": "gen" }));
    let refused = client.request(method, params).await.unwrap_err();
    assert!(
        message(&refused).contains("is a symbolic link"),
        "{refused}"
    );
    assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 0);
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn generate_requests_at_once_lose_no_edits() {
    let ws = workspace("at-once");
    let (mut client, mission_uri) = started(&ws).await;
    let args = json!({ "uri": mission_uri });
    let first = client
        .request(generate(args.clone()).0, generate(args.clone()).1)
        .await;
    assert_eq!(first.unwrap()["refused"], false);
    let folder = ws.join("out/Team1/create1");
    let task = folder.join("tasks/follow.c");
    let mine = "/* my follow algorithm */\n#include \"../program.h\"\nTASK_INIT {}\nTASK_GO {}\nTASK_WRAPUP {}\n";
    std::fs::write(&task, mine).unwrap();
    for trial in 0..20 {
        let at_once = if trial % 2 == 0 { 2 } else { 8 };
        let requests = vec![generate(args.clone()); at_once];
        for answer in client.requests_at_once(&requests).await {
            let answer = answer.unwrap_or_else(|e| panic!("trial {trial}: {e}"));
            assert_eq!(answer["refused"], false, "trial {trial}");
            assert_eq!(answer["robots"][0]["taskFilesKept"], 5, "trial {trial}");
        }
        assert_eq!(
            std::fs::read_to_string(&task).unwrap(),
            mine,
            "trial {trial}"
        );
        let hidden: Vec<_> = std::fs::read_dir(ws.join("out/Team1"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(hidden.is_empty(), "trial {trial}: {hidden:?}");
    }
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_target_switch_over_an_edited_task_file_is_refused_unless_forced() {
    let ws = workspace("switch");
    let (mut client, mission_uri) = started(&ws).await;
    let (method, params) = generate(json!({ "uri": mission_uri }));
    client.request(method, params).await.unwrap();
    let task = ws.join("out/Team1/create1/tasks/follow.c");
    std::fs::write(&task, "/* mine */\n").unwrap();
    std::fs::write(ws.join("quiet.scenario.json"), r#"{"duration": 2000}"#).unwrap();
    let sim =
        json!({ "uri": mission_uri, "target": "linux-sim", "scenario": "quiet.scenario.json" });
    let (method, params) = generate(sim.clone());
    let refused = client.request(method, params).await.unwrap_err();
    let text = message(&refused);
    assert!(text.contains("tasks/follow.c"), "{text}");
    assert!(text.contains("force"), "{text}");
    // The files in the way as data, for the editor's "Back up and regenerate".
    let conflicts = refused["data"]["conflicts"].as_array().unwrap();
    assert_eq!(conflicts.len(), 1, "{refused}");
    assert!(
        conflicts[0]["path"]
            .as_str()
            .unwrap()
            .ends_with("tasks/follow.c"),
        "{refused}"
    );
    assert!(
        !conflicts[0]["why"].as_str().unwrap().is_empty(),
        "{refused}"
    );
    assert_eq!(std::fs::read_to_string(&task).unwrap(), "/* mine */\n");
    let mut forced = sim;
    forced["force"] = json!(true);
    let (method, params) = generate(forced);
    let done = client.request(method, params).await.unwrap();
    let saved = done["robots"][0]["backedUp"].as_array().unwrap();
    assert_eq!(saved.len(), 1, "{done}");
    let saved = PathBuf::from(saved[0].as_str().unwrap());
    assert!(saved.starts_with(ws.join("out/.semo-backup")), "{saved:?}");
    assert_eq!(std::fs::read_to_string(saved).unwrap(), "/* mine */\n");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unknown_dollar_requests_are_answered_method_not_found() {
    let ws = workspace("dollar");
    let (mut client, _) = started(&ws).await;
    for method in ["$/unknown", "$/cancelRequest", "$/semo/anything"] {
        let error = client.request(method, json!({})).await.unwrap_err();
        assert_eq!(error["code"], -32601, "{method}: {error}");
    }
    // The server goes on answering.
    assert!(client.request("shutdown", Value::Null).await.is_ok());
}

/// The stress runs of issue 33 (counts of what was written outside or left
/// partial).
#[path = "lsp_generate_safety/stress.rs"]
mod stress;
