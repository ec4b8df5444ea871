//! "Simulate Mission" from the editor: `workspace/executeCommand`
//! `semo.simulate {uri, scenario}` runs the library's simulator on the
//! server's view of the mission (the open text, not the file on disk) and
//! answers with the summary, the timeline SVG and each expectation with its
//! place in the scenario file; a bad scenario is refused with its position.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

fn workspace(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("lsp_simulate")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for file in ["scouting.mission", "MasterTeam.strategy.xml"] {
        std::fs::copy(repo(&format!("examples/scouting/{file}")), dir.join(file)).unwrap();
    }
    std::fs::copy(
        repo("tests/fixtures/build/scouting.scenario.json"),
        dir.join("scouting.scenario.json"),
    )
    .unwrap();
    dir
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

async fn simulate(
    client: &mut semo_server::harness::TestClient,
    mission: &str,
    scenario: &str,
) -> Result<Value, String> {
    client
        .request(
            "workspace/executeCommand",
            json!({"command": "semo.simulate", "arguments": [{"uri": mission, "scenario": scenario}]}),
        )
        .await
        .map_err(|e| e["message"].as_str().unwrap_or_default().to_string())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_open_mission_is_simulated_with_its_scenario() {
    let dir = workspace("run");
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&dir))).await;
    let mission = dir.join("scouting.mission");
    let mission_uri = uri(&mission);
    let text = std::fs::read_to_string(&mission).unwrap();
    client.open(&mission_uri, &text).await;
    client.diagnostics(&mission_uri, Some(1)).await;

    let answer = simulate(&mut client, &mission_uri, "scouting.scenario.json")
        .await
        .unwrap();
    assert_eq!(answer["ok"], true, "{}", answer["summary"]);
    let scenario_uri = uri(&dir.join("scouting.scenario.json"));
    assert_eq!(
        client.diagnostics(&scenario_uri, None).await,
        Vec::<Value>::new()
    );
    assert!(
        answer["summary"]
            .as_str()
            .unwrap()
            .contains("MasterTeam/irobot: AUTO_MODE@0 -> WAIT_MODE@1050")
    );
    assert!(answer["svg"].as_str().unwrap().starts_with("<svg"));
    let scenario_text = std::fs::read_to_string(dir.join("scouting.scenario.json")).unwrap();
    let first = &answer["expectations"][0];
    let line = first["range"]["start"]["line"].as_u64().unwrap() as usize;
    assert!(
        scenario_text
            .lines()
            .nth(line)
            .unwrap()
            .contains("\"enters\": \"WAIT_MODE\""),
        "{first}"
    );

    // The open text counts: when AUTO_MODE's CHANGE_WAIT_MODE leads to
    // RETURN_MODE instead, the master never waits and the expectation fails.
    let edited = text.replacen(
        "catch (CHANGE_WAIT_MODE): mode = WAIT_MODE",
        "catch (CHANGE_WAIT_MODE): mode = RETURN_MODE",
        1,
    );
    assert_ne!(edited, text);
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": {"uri": mission_uri, "version": 2},
                "contentChanges": [{"text": edited}],
            }),
        )
        .await;
    let answer = simulate(
        &mut client,
        &mission_uri,
        &uri(&dir.join("scouting.scenario.json")),
    )
    .await
    .unwrap();
    assert_eq!(answer["ok"], false);
    assert_eq!(answer["expectations"][0]["met"], false);
    assert_eq!(answer["expectations"][0]["why"], "never entered");
    // The failure is a diagnostic on the scenario file, at the expectation.
    let diagnostics = client.diagnostics(&scenario_uri, None).await;
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(
        diagnostics[0]["range"], answer["expectations"][0]["range"],
        "{diagnostics:?}"
    );
    assert_eq!(
        diagnostics[0]["message"],
        "expectation failed: irobot enters WAIT_MODE before 5000 ms: never entered"
    );

    // A bad scenario: refused with its line and column.
    std::fs::write(
        dir.join("bad.scenario.json"),
        "{\n  \"duration\": \"soon\"\n}\n",
    )
    .unwrap();
    let refused = simulate(&mut client, &mission_uri, "bad.scenario.json")
        .await
        .unwrap_err();
    assert!(
        refused.contains(
            "bad.scenario.json:2:15: \"duration\" must be a whole number of milliseconds"
        ),
        "{refused}"
    );
    // ... and a diagnostic at the value.
    let diagnostics = client
        .diagnostics(&uri(&dir.join("bad.scenario.json")), None)
        .await;
    assert_eq!(
        diagnostics[0]["range"]["start"],
        json!({"line": 1, "character": 14}),
        "{diagnostics:?}"
    );

    // A sensor value no robot samples: simulated, and a warning at it.
    std::fs::write(
        dir.join("colour.scenario.json"),
        "{\"robots\": {\"ti\": {\"sensors\": [{\"at\": 0, \"value\": \"COLOUR\", \"is\": \"RED\"}]}}}\n",
    )
    .unwrap();
    simulate(&mut client, &mission_uri, "colour.scenario.json")
        .await
        .unwrap();
    let diagnostics = client
        .diagnostics(&uri(&dir.join("colour.scenario.json")), None)
        .await;
    let warning = diagnostics
        .iter()
        .find(|d| d["severity"] == 2)
        .unwrap_or_else(|| panic!("a warning: {diagnostics:?}"));
    assert_eq!(
        (&warning["range"]["start"], &warning["message"]),
        (
            &json!({"line": 0, "character": 50}),
            &json!(
                "robot ti samples no sensor value \"COLOUR\": nothing reads this entry (it samples: COLOR, LOCATION) (did you mean \"COLOR\"?)"
            )
        ),
        "{diagnostics:?}"
    );
    client.shutdown().await;
}

/// Simulating writes nothing: a mission outside every workspace root (a
/// file opened on its own) is simulated all the same.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mission_outside_the_workspace_roots_is_simulated() {
    let dir = workspace("outside");
    let root = dir.join("elsewhere");
    std::fs::create_dir_all(&root).unwrap();
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&root))).await;
    let mission = dir.join("scouting.mission");
    let mission_uri = uri(&mission);
    client
        .open(&mission_uri, &std::fs::read_to_string(&mission).unwrap())
        .await;
    client.diagnostics(&mission_uri, Some(1)).await;
    let answer = simulate(&mut client, &mission_uri, "scouting.scenario.json")
        .await
        .unwrap();
    assert_eq!(answer["ok"], true, "{}", answer["summary"]);
    client.shutdown().await;
}

/// Completion in a scenario file offers the names of the mission beside it
/// (`scouting.scenario.json` belongs to `scouting.mission`), as the editor has
/// it: a mode renamed in the open mission is offered at an expectation's mode.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_scenario_completes_the_names_of_its_mission() {
    let dir = workspace("complete");
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&dir))).await;
    let mission_uri = uri(&dir.join("scouting.mission"));
    let text = std::fs::read_to_string(dir.join("scouting.mission")).unwrap();
    client
        .open(&mission_uri, &text.replace("WAIT_MODE", "PAUSE_MODE"))
        .await;
    let diagnostics = client.diagnostics(&mission_uri, Some(1)).await;
    assert!(
        diagnostics.iter().all(|d| d["severity"] != 1),
        "{diagnostics:?}"
    );

    let scenario = "{\n  \"expect\": [\n    {\"robot\": \"irobot\", \"enters\": \"PA\"}\n  ]\n}\n";
    let complete = async |client: &mut semo_server::harness::TestClient, name: &str| {
        let scenario_uri = uri(&dir.join(name));
        client
            .notify(
                "textDocument/didOpen",
                json!({ "textDocument": {
                    "uri": scenario_uri, "languageId": "json", "version": 1, "text": scenario
                }}),
            )
            .await;
        // The cursor after `"PA`.
        let position = json!({"line": 2, "character": 37});
        client
            .request(
                "textDocument/completion",
                json!({"textDocument": {"uri": scenario_uri}, "position": position}),
            )
            .await
            .unwrap()
    };
    let answer = complete(&mut client, "scouting.scenario.json").await;
    let labels: Vec<&str> = answer["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["label"].as_str().unwrap())
        .collect();
    assert_eq!(
        labels,
        [
            "RC_MODE",
            "AUTO_MODE",
            "PAUSE_MODE",
            "RETURN_MODE",
            "FINISH"
        ]
    );
    // The edit replaces the string's contents, quotes kept.
    assert_eq!(
        answer["items"][2]["textEdit"],
        json!({"range": {"start": {"line": 2, "character": 35}, "end": {"line": 2, "character": 37}},
               "newText": "PAUSE_MODE"})
    );
    assert_eq!(answer["items"][2]["kind"], 20); // EnumMember

    // No mission is named `other.mission`: nothing to offer.
    let answer = complete(&mut client, "other.scenario.json").await;
    assert_eq!(answer["items"], json!([]));
}
