//! "Generate code" from the editor: a code lens on each team, and
//! `workspace/executeCommand` `semo.generateCode` writing every robot's folder
//! (the same library call as `semo build`) with `$/progress` per robot; a
//! mission with errors is refused with its reasons as diagnostics.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn shared(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path)
}

/// A workspace folder holding a copy of the scouting example.
fn scouting_workspace(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("lsp_generate")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for file in ["scouting.mission", "MasterTeam.strategy.xml"] {
        std::fs::copy(shared(&format!("scouting/{file}")), dir.join(file)).unwrap();
    }
    dir
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

async fn started(
    dir: &Path,
    capabilities: Value,
) -> (semo_server::harness::TestClient, String, String) {
    started_with(dir, capabilities, Value::Null).await
}

/// [`started`] with `initializationOptions`.
async fn started_with(
    dir: &Path,
    capabilities: Value,
    options: Value,
) -> (semo_server::harness::TestClient, String, String) {
    let mut client = semo_server::harness::TestClient::start();
    client
        .initialize_with_options(capabilities, options, Some(&uri(dir)))
        .await;
    let mission = dir.join("scouting.mission");
    let text = std::fs::read_to_string(&mission).unwrap();
    let mission_uri = uri(&mission);
    client.open(&mission_uri, &text).await;
    client.diagnostics(&mission_uri, Some(1)).await;
    (client, mission_uri, text)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_team_has_a_generate_code_lens() {
    let dir = scouting_workspace("lens");
    let (mut client, mission_uri, text) = started(&dir, json!({})).await;
    let lenses = client
        .request(
            "textDocument/codeLens",
            json!({ "textDocument": { "uri": mission_uri } }),
        )
        .await
        .unwrap();
    let lenses = lenses.as_array().unwrap();
    let titles: Vec<&str> = lenses
        .iter()
        .map(|l| l["command"]["title"].as_str().unwrap())
        .collect();
    assert_eq!(
        titles,
        [
            "▶ Generate code for MasterTeam",
            "▶ Generate code for SlaveTeam"
        ]
    );
    for lens in lenses {
        assert_eq!(lens["command"]["command"], "semo.generateCode");
        let line = lens["range"]["start"]["line"].as_u64().unwrap() as usize;
        assert!(
            text.lines().nth(line).unwrap().contains(':'),
            "on the formation line"
        );
    }
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn generate_code_writes_every_robot_with_progress() {
    let dir = scouting_workspace("generate");
    let capabilities = json!({ "window": { "workDoneProgress": true } });
    let (mut client, mission_uri, _) = started(&dir, capabilities).await;
    // A simulation compiles its scenario in: the request's, else the
    // mission's own beside it (as `semo build`); without either the request
    // fails saying where to put one; a scenario's mistake is the request's
    // error, positioned.
    let generate = |scenario: Option<&str>| {
        let mut arguments =
            json!({ "uri": mission_uri, "outputFolder": "gen", "target": "linux-sim" });
        if let Some(scenario) = scenario {
            arguments["scenario"] = scenario.into();
        }
        json!({ "command": "semo.generateCode", "arguments": [arguments] })
    };
    let refused = client
        .request("workspace/executeCommand", generate(None))
        .await
        .unwrap_err();
    assert!(
        refused["message"]
            .as_str()
            .unwrap()
            .contains("scouting.scenario.json beside the mission"),
        "{refused}"
    );
    assert!(!dir.join("gen").exists());
    std::fs::write(
        dir.join("bad.scenario.json"),
        "{\n  \"robots\": {\"robot9\": {}}\n}",
    )
    .unwrap();
    let bad = client
        .request(
            "workspace/executeCommand",
            generate(Some("bad.scenario.json")),
        )
        .await
        .unwrap_err();
    assert!(
        bad["message"]
            .as_str()
            .unwrap()
            .ends_with("bad.scenario.json:2:24: robot \"robot9\" is not in the mission (robots: irobot, ti, nxt) (did you mean \"irobot\"?)"),
        "{bad}"
    );
    std::fs::write(dir.join("s.scenario.json"), r#"{"duration": 2000}"#).unwrap();
    let result = client
        .request(
            "workspace/executeCommand",
            generate(Some("s.scenario.json")),
        )
        .await
        .unwrap();
    assert_eq!(result["refused"], false, "{result}");
    assert!(dir.join("gen/MasterTeam/irobot/scenario.c").is_file());
    // The mission's own scenario, when the request names none.
    std::fs::write(dir.join("scouting.scenario.json"), r#"{"duration": 3000}"#).unwrap();
    let own = client
        .request("workspace/executeCommand", generate(None))
        .await
        .unwrap();
    assert_eq!(own["refused"], false, "{own}");
    let compiled = std::fs::read_to_string(dir.join("gen/MasterTeam/irobot/scenario.c")).unwrap();
    assert!(compiled.contains("3000"), "{compiled}");
    let robots: Vec<String> = result["robots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            format!(
                "{}/{}",
                r["team"].as_str().unwrap(),
                r["robot"].as_str().unwrap()
            )
        })
        .collect();
    assert_eq!(
        robots,
        ["MasterTeam/irobot", "SlaveTeam/ti", "SlaveTeam/nxt"]
    );
    for robot in &robots {
        let folder = dir.join("gen").join(robot);
        assert!(folder.join("control_task.c").exists(), "{robot}");
        assert!(folder.join("Makefile").exists(), "{robot}");
    }
    // The master's action machine comes from the strategy file the server
    // found in the workspace.
    let control =
        std::fs::read_to_string(dir.join("gen/MasterTeam/irobot/control_task.c")).unwrap();
    assert!(control.contains("MasterTeam.strategy.xml"), "{control}");
    // Progress: begin, one report per robot, end.
    let mut kinds = Vec::new();
    while kinds.last() != Some(&"end".to_string()) {
        let p = client.notification("$/progress", |_| true).await;
        kinds.push(p["value"]["kind"].as_str().unwrap().to_string());
    }
    assert_eq!(kinds, ["begin", "report", "report", "report", "end"]);
    let message = client.notification("window/showMessage", |_| true).await;
    assert!(
        message["message"].as_str().unwrap().contains("3 robot(s)"),
        "{message}"
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_lens_of_a_team_generates_only_its_robots() {
    let dir = scouting_workspace("one-team");
    let (mut client, mission_uri, _) = started(&dir, json!({})).await;
    let lenses = client
        .request(
            "textDocument/codeLens",
            json!({ "textDocument": { "uri": mission_uri } }),
        )
        .await
        .unwrap();
    let slave = lenses[1]["command"].clone();
    let result = client
        .request(
            "workspace/executeCommand",
            json!({ "command": slave["command"], "arguments": slave["arguments"] }),
        )
        .await
        .unwrap();
    let robots = result["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 2, "{result}");
    assert!(dir.join("out/SlaveTeam/ti/main.c").exists());
    assert!(!dir.join("out/MasterTeam").exists());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mission_with_errors_is_refused_with_its_reasons() {
    let dir = scouting_workspace("refused");
    let (mut client, mission_uri, text) = started(&dir, json!({})).await;
    // An unsaved edit that breaks the mission: the server generates from what
    // the user sees, so it refuses.
    let broken = text.replace("standby()", "standbye()");
    client.change(&mission_uri, 2, &broken).await;
    let result = client
        .request(
            "workspace/executeCommand",
            json!({ "command": "semo.generateCode", "arguments": [mission_uri] }),
        )
        .await
        .unwrap();
    assert_eq!(result["refused"], true, "{result}");
    let reasons = result["errors"].as_array().unwrap();
    assert!(
        reasons
            .iter()
            .any(|r| r.as_str().unwrap().contains("standbye")),
        "{result}"
    );
    let published = client
        .notification("textDocument/publishDiagnostics", |p| {
            p["diagnostics"]
                .as_array()
                .is_some_and(|d| d.iter().any(|d| d["source"] == "semo build"))
        })
        .await;
    assert_eq!(published["uri"], mission_uri.as_str());
    let message = client.notification("window/showMessage", |_| true).await;
    assert!(
        message["message"].as_str().unwrap().contains("refused"),
        "{message}"
    );
    assert!(!dir.join("out").exists(), "nothing written");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_arguments_are_errors_not_crashes() {
    let dir = scouting_workspace("bad-args");
    let (mut client, mission_uri, _) = started(&dir, json!({})).await;
    for arguments in [
        json!([]),
        json!([42]),
        json!([{ "uri": "file:///nowhere/x.mission" }]),
        json!([{ "uri": mission_uri, "target": "amiga" }]),
    ] {
        let answer = client
            .request(
                "workspace/executeCommand",
                json!({ "command": "semo.generateCode", "arguments": arguments }),
            )
            .await;
        assert!(answer.is_err(), "{arguments}: {answer:?}");
    }
    let unknown = client
        .request(
            "workspace/executeCommand",
            json!({ "command": "semo.nope", "arguments": [] }),
        )
        .await;
    assert!(unknown.is_err());
    assert!(client.server_is_running());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refined_graph_that_fails_its_own_check_is_refused_naming_robot_and_cause() {
    // tests/fixtures/build/E102_refined_graph_fails: a catalog value named
    // like a generated port; the mission checks clean, its refined graph
    // does not.
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/build/E102_refined_graph_fails");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("lsp_generate")
        .join("refined-graph-fails");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for file in ["clash.mission", "robots.robot.xml"] {
        std::fs::copy(fixture.join(file), dir.join(file)).unwrap();
    }
    let mut client = semo_server::harness::TestClient::start();
    client.initialize_with(json!({}), Some(&uri(&dir))).await;
    let mission = dir.join("clash.mission");
    let mission_uri = uri(&mission);
    client
        .open(&mission_uri, &std::fs::read_to_string(&mission).unwrap())
        .await;
    client.diagnostics(&mission_uri, Some(1)).await;
    let result = client
        .request(
            "workspace/executeCommand",
            json!({ "command": "semo.generateCode", "arguments": [mission_uri] }),
        )
        .await
        .unwrap();
    assert_eq!(result["refused"], true, "{result}");
    let reasons: Vec<&str> = result["errors"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|r| r.as_str())
        .collect();
    assert!(
        reasons
            .iter()
            .any(|r| r.contains("robot `bot`") && r.contains("E063")),
        "{result}"
    );
    assert!(!dir.join("out").exists(), "nothing written");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unsaved_mission_is_refused_and_nothing_is_written() {
    let dir = scouting_workspace("unsaved");
    let (mut client, _, text) = started(&dir, json!({})).await;
    // The same mission in a new buffer, never saved: `untitled:` names no file,
    // not even one relative to the server's working folder.
    let unsaved = "untitled:Untitled-1";
    client.open(unsaved, &text).await;
    client.diagnostics(unsaved, Some(1)).await;
    let answer = client
        .request(
            "workspace/executeCommand",
            json!({ "command": "semo.generateCode", "arguments": [unsaved] }),
        )
        .await;
    let error = answer.expect_err("an unsaved mission has no folder to generate beside");
    assert!(error.to_string().contains("saved as a file"), "{error}");
    let cwd = std::env::current_dir().unwrap();
    assert!(!cwd.join("Untitled-1").exists() && !cwd.join("out").exists());
    assert!(!dir.join("out").exists(), "nothing written");
    client.shutdown().await;
}

/// A client that tells the user itself how a generation ended (VS Code:
/// `generateCodeOutcome`) gets no message from the server for it, so that
/// one generation is one notification: neither for code written nor for a
/// refusal. Others (Neovim) get the server's message, as above.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_that_tells_the_outcome_itself_gets_no_message() {
    let dir = scouting_workspace("tells-itself");
    let options = json!({ "generateCodeOutcome": true });
    let (mut client, mission_uri, text) = started_with(&dir, json!({}), options).await;
    let generate = json!({
        "command": "semo.generateCode",
        "arguments": [{ "uri": mission_uri, "outputFolder": "gen" }],
    });
    let messages = |client: &mut semo_server::harness::TestClient| -> Vec<Value> {
        client
            .take_unclaimed()
            .into_iter()
            .filter(|m| m["method"] == "window/showMessage")
            .collect()
    };
    let result = client
        .request("workspace/executeCommand", generate.clone())
        .await
        .unwrap();
    assert_eq!(result["refused"], false, "{result}");
    assert_eq!(messages(&mut client), Vec::<Value>::new());
    // A mission with an error: refused, said in the answer only.
    let broken = text.replacen("repeat()", "repeat(", 1);
    client.change(&mission_uri, 2, &broken).await;
    client.diagnostics(&mission_uri, Some(2)).await;
    let refused = client
        .request("workspace/executeCommand", generate)
        .await
        .unwrap();
    assert_eq!(refused["refused"], true, "{refused}");
    assert_eq!(messages(&mut client), Vec::<Value>::new());
    client.shutdown().await;
}
