//! `semo.toml` in the editor: its diagnostics (positioned), completion of
//! its tables, keys, lint codes and values, and its `[lints]` applied to the
//! open missions, which are re-checked when it changes.

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::Path;

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

/// `CODE line:col message` per diagnostic, lines and columns from 0.
fn listing(diags: &[Value]) -> Vec<String> {
    diags
        .iter()
        .map(|d| {
            format!(
                "{} {}:{} {}",
                d["code"].as_str().unwrap(),
                d["range"]["start"]["line"],
                d["range"]["start"]["character"],
                d["message"].as_str().unwrap()
            )
        })
        .collect()
}

fn change(text: &str, uri: &str, version: i64) -> Value {
    json!({
        "textDocument": { "uri": uri, "version": version },
        "contentChanges": [{ "text": text }]
    })
}

/// The labels of the completion at `line:character`.
async fn labels(client: &mut TestClient, uri: &str, line: u32, character: u32) -> Vec<String> {
    let answer = client
        .request(
            "textDocument/completion",
            json!({
                "textDocument": { "uri": uri },
                "position": { "line": line, "character": character }
            }),
        )
        .await
        .unwrap();
    answer["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["label"].as_str().unwrap().to_string())
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_project_file_gets_positioned_diagnostics_and_completion() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("robots")).unwrap();
    let file = uri(&dir.path().join("semo.toml"));
    let text = "[project]\ncatalogs = [\"robots\", \"gone\"]\n\n[biuld]\n\n[lints]\nE019 = \"allow\"\nW007 = \"\"\n";
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(&file, text).await;
    let found = client.diagnostics(&file, Some(1)).await;
    assert_eq!(
        listing(&found),
        [
            "W111 1:22 there is no folder `gone` in the project",
            "W110 3:1 unknown table `biuld` (known: project, build, lints) (did you mean `build`?)",
            "E112 6:7 E019 is an error: it cannot be allowed or made a warning (only \"deny\")",
            "E111 7:7 the level of W007 must be \"allow\", \"warn\" or \"deny\"",
        ]
    );
    // Typing a lint code: the file does not parse meanwhile, and says so.
    let typing = format!("{text}W00");
    client
        .notify("textDocument/didChange", change(&typing, &file, 2))
        .await;
    let found = client.diagnostics(&file, Some(2)).await;
    assert_eq!(
        found.iter().map(|d| d["code"].clone()).collect::<Vec<_>>(),
        [json!("E110")]
    );
    assert_eq!(found[0]["range"]["start"]["line"], 8);
    let codes = labels(&mut client, &file, 8, 3).await;
    // Warnings first, by code: `semo verify`'s V… before the checker's W….
    assert_eq!(codes[..3], ["V001", "V002", "V003"]);
    assert!(codes.contains(&"W001".to_string()));
    assert!(codes.contains(&"E010".to_string()));
    // Not those the table has already.
    assert!(!codes.contains(&"E019".to_string()) && !codes.contains(&"W007".to_string()));
    // The level of a warning, then of an error (only `deny`).
    let typing = format!("{text}W001 = ");
    client
        .notify("textDocument/didChange", change(&typing, &file, 3))
        .await;
    assert_eq!(
        labels(&mut client, &file, 8, 7).await,
        ["allow", "warn", "deny"]
    );
    assert_eq!(labels(&mut client, &file, 6, 7).await, ["deny"]);
    // Tables on a header line, keys of the table the cursor is in.
    assert_eq!(
        labels(&mut client, &file, 3, 1).await,
        ["project", "build", "build.targets", "lints"]
    );
    let keys = labels(&mut client, &file, 2, 0).await;
    assert_eq!(keys, ["version", "name", "strategies", "task-graphs"]);
    client.shutdown().await;
}

/// A mission with one W010 (a function never called) and one W002 (a mode
/// never reached).
const TWO_WARNINGS: &str = "{ A: iRobotCreate scout }\n\
def zigzag{\n  go_forward()\n}\n\
A.Action.Explore{\n  move(\"5,5\")\n} repeat(1 SEC)\n\
A.EXPLORE{ set(Action, Explore) }\n\
A.REST{ set(Action, OFF) }\n\
A.main{\n  default: mode = EXPLORE\n}\n";

fn code_and_severity(diags: &[Value]) -> Vec<(String, i64)> {
    diags
        .iter()
        .map(|d| {
            (
                d["code"].as_str().unwrap().to_string(),
                d["severity"].as_i64().unwrap(),
            )
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_change_to_the_project_file_rechecks_the_open_missions_at_its_levels() {
    let dir = tempfile::tempdir().unwrap();
    let mission = uri(&dir.path().join("m.mission"));
    let project = uri(&dir.path().join("semo.toml"));
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(&mission, TWO_WARNINGS).await;
    let before = client.diagnostics(&mission, Some(1)).await;
    assert_eq!(
        code_and_severity(&before),
        [("W010".to_string(), 2), ("W002".to_string(), 2)]
    );
    // Allow one, deny the other: the mission is published again.
    let lints = "[lints]\nW010 = \"allow\"\nW002 = \"deny\"\n";
    client.open(&project, lints).await;
    let after = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == mission.as_str() && p["diagnostics"].as_array().unwrap().len() == 1
        })
        .await;
    let after = after["diagnostics"].as_array().unwrap();
    assert_eq!(code_and_severity(after), [("W002".to_string(), 1)]);
    // Emptied: both warnings are back.
    client
        .notify("textDocument/didChange", change("", &project, 2))
        .await;
    let again = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == mission.as_str() && p["diagnostics"].as_array().unwrap().len() == 2
        })
        .await;
    assert_eq!(
        code_and_severity(again["diagnostics"].as_array().unwrap()),
        [("W010".to_string(), 2), ("W002".to_string(), 2)]
    );
    client.shutdown().await;
}
