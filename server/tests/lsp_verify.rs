//! `semo verify` through the protocol: a saved mission's findings join its
//! diagnostics once the background search ends, on the saved text only,
//! each with an action that writes the scenario showing it; an edit drops
//! them and typing never waits for a search.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::Path;
use support::render::file_uri;

fn codes(diagnostics: &Value) -> Vec<String> {
    diagnostics
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap_or("").to_string())
        .collect()
}

/// A client on the folder of `tests/fixtures/verify/<fixture>` with its
/// `main.mission` open: the client, the mission's URI, the folder and the
/// mission's text.
async fn opened_fixture(fixture: &str) -> (TestClient, String, std::path::PathBuf, String) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/verify")
        .join(fixture);
    let mission = dir.join("main.mission");
    let text = std::fs::read_to_string(&mission).unwrap();
    let mission = file_uri(&mission);
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], Some(&file_uri(&dir))).await;
    client.open(&mission, &text).await;
    (client, mission, dir, text)
}

/// Saves `mission` and waits for the publication with the search's
/// findings among its diagnostics: those diagnostics.
async fn saved_and_verified(client: &mut TestClient, mission: &str) -> Value {
    client
        .notify(
            "textDocument/didSave",
            json!({ "textDocument": { "uri": mission } }),
        )
        .await;
    let found = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == mission && codes(&p["diagnostics"]).contains(&"V002".to_string())
        })
        .await;
    found["diagnostics"].clone()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_saved_mission_gets_its_verify_findings_and_an_edit_drops_them() {
    let (mut client, mission, dir, text) = opened_fixture("never_finishes").await;
    // Opened: the check's diagnostics, no search yet.
    let opened = client.diagnostics(&mission, Some(1)).await;
    assert!(!codes(&json!(opened)).contains(&"V002".to_string()));
    let found = saved_and_verified(&mut client, &mission).await;
    let v002: Vec<&Value> = found
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "V002")
        .collect();
    assert_eq!(v002.len(), 1, "{found:#}");
    // On the line of the mode the robot is stuck in (0-based 17).
    assert_eq!(v002[0]["range"]["start"]["line"], 17, "{found:#}");
    assert!(v002[0]["message"].as_str().unwrap().contains("WANDER"));
    // The finding's action writes the scenario that shows it beside the
    // mission, named as `semo verify --counterexamples` names it, created
    // and never overwritten.
    let actions = client
        .request(
            "textDocument/codeAction",
            json!({
                "textDocument": { "uri": mission },
                "range": v002[0]["range"],
                "context": { "diagnostics": [v002[0]] }
            }),
        )
        .await
        .unwrap();
    let write: Vec<&Value> = actions
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| {
            a["title"]
                .as_str()
                .unwrap()
                .starts_with("Write the scenario")
        })
        .collect();
    assert_eq!(write.len(), 1, "{actions:#}");
    let changes = write[0]["edit"]["documentChanges"].as_array().unwrap();
    let scenario_uri = format!("{}/main.V002-1.scenario.json", file_uri(&dir));
    assert_eq!(changes[0]["kind"], "create", "{changes:#?}");
    assert_eq!(changes[0]["uri"], scenario_uri.as_str());
    assert_eq!(changes[0]["options"]["overwrite"], false);
    assert_eq!(changes[1]["textDocument"]["uri"], scenario_uri.as_str());
    let scenario: Value =
        serde_json::from_str(changes[1]["edits"][0]["newText"].as_str().unwrap()).unwrap();
    assert!(scenario["duration"].as_i64().unwrap() > 0, "{scenario:#}");
    assert!(
        scenario["robots"]["ti"]["sensors"].is_array(),
        "{scenario:#}"
    );
    // An edit: the findings were of the saved text, and go.
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": mission, "version": 2 },
                "contentChanges": [{ "text": format!("{text}\n") }]
            }),
        )
        .await;
    let edited = client.diagnostics(&mission, Some(2)).await;
    assert!(
        !codes(&json!(edited)).contains(&"V002".to_string()),
        "{edited:#?}"
    );
    client.shutdown().await;
}

/// A client that cannot create files (no `create` resource operation) is
/// offered no action that would need one.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_that_cannot_create_files_gets_no_scenario_action() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/verify/never_finishes");
    let mission = dir.join("main.mission");
    let text = std::fs::read_to_string(&mission).unwrap();
    let mission = file_uri(&mission);
    let mut client = TestClient::start();
    // The harness's usual client, less the file operations of its edits.
    let plain = json!({
        "general": { "positionEncodings": ["utf-16"] },
        "workspace": { "didChangeWatchedFiles": { "dynamicRegistration": true } },
    });
    client.initialize_with(plain, Some(&file_uri(&dir))).await;
    client.open(&mission, &text).await;
    client.diagnostics(&mission, Some(1)).await;
    let found = saved_and_verified(&mut client, &mission).await;
    let v002 = found
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "V002")
        .unwrap()
        .clone();
    let actions = client
        .request(
            "textDocument/codeAction",
            json!({
                "textDocument": { "uri": mission },
                "range": v002["range"],
                "context": { "diagnostics": [v002] }
            }),
        )
        .await
        .unwrap();
    let titles: Vec<&str> = (actions.as_array().unwrap().iter())
        .map(|a| a["title"].as_str().unwrap())
        .collect();
    assert!(
        !titles.iter().any(|t| t.starts_with("Write the scenario")),
        "{titles:?}"
    );
    client.shutdown().await;
}

/// `semo.verify` on demand (VS Code's "Verify Mission", Neovim's
/// `:SemoVerify`): the findings with their ranges and counterexample
/// scenarios, the properties of an expectations file judged over every
/// behaviour, the summary `semo verify` prints; a bad expectations file is
/// refused with its line and column.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_verify_command_answers_findings_and_the_users_properties() {
    let (mut client, mission, ..) = opened_fixture("plans_race").await;
    let answer = client
        .request(
            "workspace/executeCommand",
            json!({"command": "semo.verify",
                   "arguments": [{"uri": mission, "expect": "properties.json"}]}),
        )
        .await
        .unwrap();
    assert_eq!(answer["exhaustive"], true, "{answer:#}");
    let found: Vec<(String, u64)> = answer["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["code"].as_str().unwrap().to_string(),
                f["range"]["start"]["line"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        found,
        [("V003".to_string(), 29), ("V005".to_string(), 16)],
        "{answer:#}"
    );
    let race = &answer["findings"][1]["scenario"];
    assert!(race.as_str().unwrap().contains("\"duration\""), "{race}");
    let verdicts: Vec<&str> = answer["properties"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["verdict"].as_str().unwrap())
        .collect();
    assert_eq!(verdicts, ["broken", "broken", "broken", "holds", "broken"]);
    let broken = answer["properties"][0]["scenario"].as_str().unwrap();
    assert!(broken.contains("\"eventually\""), "{broken}");
    let summary = answer["summary"].as_str().unwrap();
    assert!(
        summary.starts_with("explored every behaviour:")
            && summary.contains("V005 line 17: at 10 ms base's plan Listen"),
        "{summary}"
    );
    // A deadline is one run's: refused where it is written.
    let bad = std::env::temp_dir().join(format!("semo-verify-bad-{}.json", std::process::id()));
    std::fs::write(
        &bad,
        "{\"expect\": [{\"robot\": \"base\", \"enters\": \"DONE\", \"before\": 5}]}",
    )
    .unwrap();
    let refused = client
        .request(
            "workspace/executeCommand",
            json!({"command": "semo.verify",
                   "arguments": [{"uri": mission, "expect": file_uri(&bad)}]}),
        )
        .await
        .unwrap_err();
    std::fs::remove_file(&bad).unwrap();
    assert!(
        refused.to_string().contains(":1:13: a deadline"),
        "{refused}"
    );
}
