//! Files that depend on each other: strategies are cross-checked against the
//! open missions, missions against the workspace catalog; workspace folders
//! are indexed at start and kept current through watched-file events.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn scouting(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/scouting")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn codes(diags: &[Value]) -> Vec<String> {
    diags
        .iter()
        .map(|d| d["code"].as_str().unwrap_or("").to_string())
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_strategy_is_rechecked_when_its_mission_changes() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let mission_uri = "file:///w/scouting.mission";
    let strategy_uri = "file:///w/MasterTeam.strategy.xml";
    let mission = scouting("scouting.mission");
    client.open(mission_uri, &mission).await;
    client
        .open(strategy_uri, &scouting("MasterTeam.strategy.xml"))
        .await;
    let clean = client.diagnostics(strategy_uri, Some(1)).await;
    assert_eq!(clean, Vec::<Value>::new());

    // Renaming the team in the mission leaves the strategy naming no team.
    let renamed = mission.replace("MasterTeam", "ChiefTeam");
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": mission_uri, "version": 2 },
                "contentChanges": [{ "text": renamed }]
            }),
        )
        .await;
    let after = client.diagnostics(strategy_uri, Some(1)).await;
    assert!(codes(&after).contains(&"E089".to_string()), "{after:#?}");
    client.shutdown().await;
}

fn temp_workspace(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("semo-lsp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

const CATALOG: &str = r#"<?xml version="1.0"?>
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Service name="dig" task="dig_task"/>
  </Robot>
</Catalog>
"#;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn workspace_files_are_indexed_and_catalog_changes_recheck_missions() {
    let dir = temp_workspace("index");
    let mission_path = dir.join("dig.mission");
    let catalog_path = dir.join("rover.robot.xml");
    std::fs::write(
        &mission_path,
        "{\n  T: Rover r\n}\nT.P.S{\n  dig()\n} repeat()\nT.M{ set(P, S) }\nT.main{ default: mode = M }\n",
    )
    .unwrap();
    std::fs::write(&catalog_path, CATALOG).unwrap();

    let mut client = TestClient::start();
    client.initialize(&["utf-16"], Some(&uri(&dir))).await;
    // Indexed from disk, unopened: published without a version, and clean
    // because the workspace catalog defines Rover and dig.
    let first = client.diagnostics(&uri(&mission_path), None).await;
    assert_eq!(first, Vec::<Value>::new());

    // The catalog loses `dig` on disk; the watcher event re-checks the mission.
    std::fs::write(&catalog_path, CATALOG.replace("dig", "drill")).unwrap();
    client
        .notify(
            "workspace/didChangeWatchedFiles",
            json!({ "changes": [{ "uri": uri(&catalog_path), "type": 2 }] }),
        )
        .await;
    let after = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == uri(&mission_path) && !p["diagnostics"].as_array().unwrap().is_empty()
        })
        .await;
    let message = after["diagnostics"][0]["message"].as_str().unwrap();
    assert!(message.contains("dig"), "{after:#}");

    // Deleting the mission clears its diagnostics.
    std::fs::remove_file(&mission_path).unwrap();
    client
        .notify(
            "workspace/didChangeWatchedFiles",
            json!({ "changes": [{ "uri": uri(&mission_path), "type": 3 }] }),
        )
        .await;
    client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == uri(&mission_path) && p["diagnostics"] == json!([])
        })
        .await;
    client.shutdown().await;
    let _ = std::fs::remove_dir_all(&dir);
}

/// A request sent at once after `initialized` sees the workspace as a later
/// one does: it waits for the folders to be read. (Many files make the read
/// long enough that a request which did not wait would answer before it.)
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_request_sent_at_once_after_start_sees_the_workspace() {
    let dir = temp_workspace("at-once");
    std::fs::write(dir.join("rover.robot.xml"), CATALOG).unwrap();
    let filler = dir.join("filler");
    std::fs::create_dir(&filler).unwrap();
    for i in 0..600 {
        std::fs::write(filler.join(format!("m{i}.mission")), "{\n  T: Rover r\n}\n").unwrap();
    }
    let mission = dir.join("dig.mission");
    let text = "{\n  T: Rover r\n}\nT.P.S{\n  dig()\n} repeat()\nT.M{ set(P, S) }\nT.main{ default: mode = M }\n";
    std::fs::write(&mission, text).unwrap();

    let mut client = TestClient::start();
    client.initialize(&["utf-16"], Some(&uri(&dir))).await;
    let catalog = client
        .request("semo/catalog", json!({ "uri": uri(&mission) }))
        .await
        .unwrap();
    let types: Vec<&str> = catalog["robots"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|r| r["name"].as_str())
        .collect();
    assert!(types.contains(&"Rover"), "{types:?}");
    // The first diagnostics of the mission come with the catalog read too.
    client.open(&uri(&mission), text).await;
    assert_eq!(
        client.diagnostics(&uri(&mission), Some(1)).await,
        Vec::<Value>::new()
    );
    client.shutdown().await;
    let _ = std::fs::remove_dir_all(&dir);
}

/// A client with no workspace folder that never sends `initialized` (out of
/// protocol, but some do) still gets answers: with nothing to read, the
/// server does not wait for the read.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_folders_requests_are_answered_before_initialized() {
    let mut client = TestClient::start();
    client
        .request(
            "initialize",
            json!({ "processId": null, "rootUri": null, "capabilities": {} }),
        )
        .await
        .unwrap();
    let catalog = client
        .request(
            "semo/catalog",
            json!({ "uri": "file:///nowhere/a.mission" }),
        )
        .await
        .unwrap();
    assert!(catalog["robots"].as_array().is_some_and(|r| !r.is_empty()));
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_catalog_request_lists_builtin_and_workspace_robot_types_and_follows_changes() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let names = |catalog: &Value| -> Vec<String> {
        catalog["robots"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["name"].as_str().unwrap().to_string())
            .collect()
    };
    let builtin = client.request("semo/catalog", json!({})).await.unwrap();
    assert!(names(&builtin).contains(&"iRobotCreate".to_string()));
    assert!(!names(&builtin).contains(&"Rover".to_string()));
    let create = builtin["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "iRobotCreate")
        .unwrap();
    let mv = create["services"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "move")
        .unwrap();
    assert!(
        mv["signature"].as_str().unwrap().starts_with("move("),
        "{mv}"
    );
    assert!(!create["values"].as_array().unwrap().is_empty());
    assert_eq!(builtin["user"]["name"], "USER");

    // A catalog file opened in the editor adds its type at once.
    client
        .notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": "file:///w/rover.robot.xml", "languageId": "xml", "version": 1, "text": CATALOG } }),
        )
        .await;
    let with_rover = client.request("semo/catalog", json!({})).await.unwrap();
    let rover = with_rover["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "Rover");
    let rover = rover.unwrap_or_else(|| panic!("{:?}", names(&with_rover)));
    assert_eq!(rover["services"][0]["name"], "dig");
    client.shutdown().await;
}

/// The editor cross-checks a strategy file with every strategy file its
/// missions see (the host's rule, as `semo check`): a service refined in two
/// files is reported, and the report goes away with the second file.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_service_refined_in_two_strategy_files_is_reported_in_the_editor() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let mission_uri = "file:///w/scouting.mission";
    let first = "file:///w/MasterTeam.strategy.xml";
    let second = "file:///w/Zweite.strategy.xml";
    client
        .open(mission_uri, &scouting("scouting.mission"))
        .await;
    let strategy = scouting("MasterTeam.strategy.xml");
    client.open(first, &strategy).await;
    assert_eq!(
        client.diagnostics(first, Some(1)).await,
        Vec::<Value>::new()
    );
    // The same entries again in a second file: the second one refines them
    // twice (files are taken in path order).
    client.open(second, &strategy).await;
    let twice = client.diagnostics(second, Some(1)).await;
    assert!(codes(&twice).contains(&"E085".to_string()), "{twice:#?}");
    let related = &twice[0]["relatedInformation"][0]["location"]["uri"];
    assert_eq!(related, first, "{twice:#?}");
    client
        .notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": second } }),
        )
        .await;
    // The first file is re-checked without it (and stays clean).
    let alone = client.diagnostics(first, Some(1)).await;
    assert_eq!(alone, Vec::<Value>::new());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unsaved_document_sees_the_workspace_catalog() {
    let dir = temp_workspace("unsaved");
    let catalog = dir.join("rover.robot.xml");
    std::fs::write(&catalog, CATALOG).unwrap();
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], Some(&uri(&dir))).await;
    // Indexed (its diagnostics are published) before the buffer opens.
    client.diagnostics(&uri(&catalog), None).await;
    // A new buffer, never saved: its URI names no file.
    let unsaved = "untitled:Untitled-1";
    let mission = "{ T: Rover r }\nT.P.S { dig() } repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n";
    client.open(unsaved, mission).await;
    let diagnostics = client.diagnostics(unsaved, Some(1)).await;
    assert_eq!(diagnostics, Vec::<Value>::new());
    client.shutdown().await;
    let _ = std::fs::remove_dir_all(&dir);
}
