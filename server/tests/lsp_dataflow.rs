//! Dataflow warnings while editing a mission (`semo::dataflow`), through the
//! protocol: one case per warning on the fixtures of `semo check`
//! (`tests/fixtures/diagnostics/W07x_*`: a mission, a catalog whose `scan`
//! service is a task graph, that graph), the keystroke's diagnostics never
//! waiting for them, stale results dropped, and the team hover's periods.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use support::text_at;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/diagnostics")
        .join(name)
}

fn uri(path: &Path) -> String {
    let path: PathBuf = path.components().collect();
    format!("file://{}", path.display())
}

fn codes(diagnostics: &Value) -> Vec<String> {
    diagnostics
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap_or("").to_string())
        .collect()
}

/// A client on the fixture folder with its mission open (version 1).
async fn open_fixture(name: &str) -> (TestClient, String, String) {
    let dir = fixture(name);
    let mission = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "mission"))
        .unwrap();
    let text = std::fs::read_to_string(&mission).unwrap();
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], Some(&uri(&dir))).await;
    client.open(&uri(&mission), &text).await;
    (client, uri(&mission), text)
}

/// Waits for the publication of `version` of `uri` that has `code`.
async fn published_with(client: &mut TestClient, uri: &str, version: i64, code: &str) -> Value {
    let found = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["uri"] == uri
                && p["version"] == json!(version)
                && codes(&p["diagnostics"]).contains(&code.to_string())
        })
        .await;
    found["diagnostics"].clone()
}

/// The one diagnostic with `code`: its code, the text it covers and the
/// start of its message.
async fn case(name: &str, code: &str) -> (String, String) {
    let (mut client, mission, text) = open_fixture(name).await;
    let diagnostics = published_with(&mut client, &mission, 1, code).await;
    let found: Vec<&Value> = diagnostics
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == code)
        .collect();
    assert_eq!(found.len(), 1, "{diagnostics:#}");
    assert_eq!(found[0]["severity"], 2, "a warning");
    let covered = text_at(&text, &found[0]["range"]);
    let message = found[0]["message"].as_str().unwrap().to_string();
    client.shutdown().await;
    (covered, message)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_inconsistent_service_graph_is_warned_about_on_the_call() {
    let (covered, message) = case("W070_dataflow_inconsistent", "W070").await;
    assert_eq!(covered, "scan()");
    assert!(message.contains("inconsistent sample rates"), "{message}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_deadlocking_service_graph_is_warned_about_on_the_call() {
    let (covered, message) = case("W071_dataflow_deadlock", "W071").await;
    assert_eq!(covered, "scan()");
    assert!(message.contains("deadlocks"), "{message}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_buffer_too_small_in_a_service_graph_is_warned_about_on_the_call() {
    let (covered, message) = case("W072_dataflow_buffer_too_small", "W072").await;
    assert_eq!(covered, "scan()");
    assert!(message.contains("capacity is 3"), "{message}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_period_the_graph_cannot_keep_up_with_is_warned_about_on_the_period() {
    let (covered, message) = case("W073_dataflow_too_slow", "W073").await;
    assert_eq!(covered, "20 MSEC");
    assert!(message.contains("50 ms"), "{message}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_latency_over_the_catalogs_bound_is_warned_about_on_the_call() {
    // Hand-computed in the fixture's mission: 30 + 20 + 15 ms from `camera`
    // to `wheels`, against 50 MSEC (`track`'s 0.065 SEC holds).
    let (mut client, mission, text) = open_fixture("W074_dataflow_latency_exceeded").await;
    let diagnostics = published_with(&mut client, &mission, 1, "W074").await;
    let found: Vec<&Value> = diagnostics
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "W074")
        .collect();
    assert_eq!(found.len(), 1, "{diagnostics:#}");
    assert_eq!(found[0]["severity"], 2, "a warning");
    assert_eq!(text_at(&text, &found[0]["range"]), "follow()");
    assert_eq!(
        found[0]["message"],
        "`follow` runs the task graph `graphs/follow.taskgraph.xml`, whose latency from `camera` to `wheels` is over the 50 MSEC (50 ms) its catalog allows: minimal latency 65 ms, self-timed latency 65 ms"
    );
    // The bound's declaration, in the catalog, is the related information.
    let related = &found[0]["relatedInformation"][0];
    assert!(
        related["location"]["uri"]
            .as_str()
            .unwrap()
            .ends_with("rover.robot.xml"),
        "{related:#}"
    );
    assert_eq!(
        related["message"],
        "the bound, 50 MSEC (50 ms), is stated here"
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_latency_bound_that_cannot_be_checked_is_warned_about_with_why() {
    let (mut client, mission, _) = open_fixture("W075_dataflow_latency_unchecked").await;
    let diagnostics = published_with(&mut client, &mission, 1, "W075").await;
    let mut found: Vec<&str> = diagnostics
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "W075")
        .map(|d| d["message"].as_str().unwrap())
        .collect();
    found.sort_unstable();
    assert_eq!(found.len(), 3, "{diagnostics:#}");
    // In the order of their messages: `steer`'s (to `wheels`), `whels`,
    // then from `wheels`.
    for (message, why) in found.iter().zip([
        "states no execution times",
        "no task `whels` (did you mean `wheels`?)",
        "no path of channels leads from the source to the sink",
    ]) {
        assert!(message.contains(why), "{message}");
    }
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn keystrokes_do_not_wait_for_the_dataflow_and_stale_results_are_dropped() {
    let (mut client, mission, text) = open_fixture("W073_dataflow_too_slow").await;
    // The first publication of the version is the check's, without waiting
    // for the refinement.
    let first = client.diagnostics(&mission, Some(1)).await;
    assert!(
        !codes(&json!(first)).contains(&"W073".to_string()),
        "{first:#?}"
    );
    // Then the same version again, with the warning.
    published_with(&mut client, &mission, 1, "W073").await;
    // Edits at once: each version replaces the last before its dataflow is
    // known; only the last one's warning is published, on its period.
    let mut seen = Vec::new();
    for (version, period) in [(2, "30 MSEC"), (3, "40 MSEC"), (4, "45 MSEC")] {
        client
            .notify(
                "textDocument/didChange",
                json!({
                    "textDocument": { "uri": mission, "version": version },
                    "contentChanges": [{ "text": text.replace("20 MSEC", period) }]
                }),
            )
            .await;
    }
    let last = client
        .notification("textDocument/publishDiagnostics", |p| {
            if p["uri"] == mission.as_str()
                && codes(&p["diagnostics"]).contains(&"W073".to_string())
            {
                // Only the newest version may be told about the dataflow.
                assert_eq!(p["version"], 4, "{p:#}");
                true
            } else {
                false
            }
        })
        .await;
    seen.push(last);
    let message = seen[0]["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "W073")
        .unwrap()["message"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(message.contains("the 45 ms period"), "{message}");
    // A period the graph keeps up with: no warning (the check's publication
    // already has none, and nothing is added).
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": mission, "version": 5 },
                "contentChanges": [{ "text": text.replace("20 MSEC", "50 MSEC") }]
            }),
        )
        .await;
    let fine = client.diagnostics(&mission, Some(5)).await;
    assert_eq!(fine, Vec::<Value>::new());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn hover_on_a_team_shows_each_robots_iteration_period() {
    let (mut client, mission, text) = open_fixture("W073_dataflow_too_slow").await;
    // Once the workspace is indexed (the catalog defines `Rover`).
    published_with(&mut client, &mission, 1, "W073").await;
    let team = text.find("{ T:").unwrap() + 2;
    let hover = client
        .request(
            "textDocument/hover",
            json!({
                "textDocument": { "uri": mission },
                "position": support::position_of(&text, team)
            }),
        )
        .await
        .unwrap();
    let markdown = hover["contents"]["value"].as_str().unwrap();
    assert!(
        markdown.contains(
            "**Iteration period** (dataflow):\n- `r`: 50 ms (`scan`: `graphs/scan.taskgraph.xml`)"
        ),
        "{markdown}"
    );
    // Not on other names.
    let service = text.find("scan()").unwrap();
    let hover = client
        .request(
            "textDocument/hover",
            json!({
                "textDocument": { "uri": mission },
                "position": support::position_of(&text, service)
            }),
        )
        .await
        .unwrap();
    assert!(
        !hover["contents"]["value"]
            .as_str()
            .unwrap()
            .contains("Iteration period")
    );
    client.shutdown().await;
}
