//! `semo/graphSvg`: the pictures behind the editor's "Show Task Graph" and
//! "Show Mode Machine" — the same SVG as `semo graph svg` and `semo graph
//! modes`, drawn from the document as it is in the editor.

use serde_json::{Value, json};

fn shared(path: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

async fn graph_svg(
    client: &mut semo_server::harness::TestClient,
    uri: &str,
    team: Option<&str>,
) -> Result<Value, Value> {
    let mut params = json!({ "textDocument": { "uri": uri } });
    if let Some(team) = team {
        params["team"] = json!(team);
    }
    client.request("semo/graphSvg", params).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_task_graph_is_drawn_as_the_cli_draws_it() {
    let text = shared("taskgraphs/data_loop.taskgraph.xml");
    let uri = "file:///g/data_loop.taskgraph.xml";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let answer = graph_svg(&mut client, uri, None).await.unwrap();
    let svg = answer["svg"].as_str().unwrap();
    let (graph, _) = semo::taskgraph::load_task_graph(semo::diag::FileId(0), &text);
    assert_eq!(svg, semo::taskgraph::to_svg(&graph.unwrap()));
    assert!(svg.contains(">L (D-loop × 10)</text>"), "{svg}");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_deadlocked_cycle_is_marked_in_the_editor_picture() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/diagnostics/E071_deadlock/graph.taskgraph.xml");
    let text = std::fs::read_to_string(&path).unwrap();
    let uri = "file:///g/deadlock.taskgraph.xml";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let answer = graph_svg(&mut client, uri, None).await.unwrap();
    let svg = answer["svg"].as_str().unwrap();
    assert!(
        svg.contains("<g class=\"node task deadlock\" data-path=\"X\">"),
        "{svg}"
    );
    assert_eq!(
        svg.matches("<g class=\"edge data deadlock\"").count(),
        2,
        "{svg}"
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mission_gives_its_mode_machines_as_edited() {
    let text = shared("scouting/scouting.mission");
    let uri = "file:///m/scouting.mission";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let all = graph_svg(&mut client, uri, None).await.unwrap();
    let svg = all["svg"].as_str().unwrap();
    assert!(svg.contains("data-team=\"MasterTeam\"") && svg.contains("data-team=\"SlaveTeam\""));
    let slave = graph_svg(&mut client, uri, Some("SlaveTeam"))
        .await
        .unwrap();
    let svg = slave["svg"].as_str().unwrap();
    assert!(!svg.contains("data-team=\"MasterTeam\""));
    assert!(svg.contains("<g class=\"mode default\" data-mode=\"AUTO_MODE\">"));
    // The unsaved text is what is drawn: a new default mode.
    let edited = text.replacen(
        "default: mode = AUTO_MODE\n}",
        "default: mode = RC_MODE\n}",
        2,
    );
    assert_ne!(edited, text);
    client
        .notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": edited }] }),
        )
        .await;
    let slave = graph_svg(&mut client, uri, Some("SlaveTeam"))
        .await
        .unwrap();
    assert!(
        slave["svg"]
            .as_str()
            .unwrap()
            .contains("<g class=\"mode default\" data-mode=\"RC_MODE\">")
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn refusals_say_why() {
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let mission = "file:///m/a.mission";
    client
        .open(mission, "{\n  T: iRobotCreate a\n}\nT.A{\n}\n")
        .await;
    let unknown_team = graph_svg(&mut client, mission, Some("Nobody"))
        .await
        .unwrap_err();
    assert!(
        unknown_team["message"].as_str().unwrap().contains("Nobody"),
        "{unknown_team}"
    );
    let catalog = "file:///m/r.robot.xml";
    client.open(catalog, "<Robots/>").await;
    let not_a_graph = graph_svg(&mut client, catalog, None).await.unwrap_err();
    assert!(
        not_a_graph["message"]
            .as_str()
            .unwrap()
            .contains("only task graphs"),
        "{not_a_graph}"
    );
    let broken = "file:///g/broken.taskgraph.xml";
    client.open(broken, "<taskgraph name=\"x\"><task").await;
    let unreadable = graph_svg(&mut client, broken, None).await.unwrap_err();
    assert!(
        unreadable["message"]
            .as_str()
            .unwrap()
            .contains("could not be read"),
        "{unreadable}"
    );
    let never_opened = graph_svg(&mut client, "file:///nowhere.mission", None).await;
    assert!(never_opened.is_err());
    // The server is still answering.
    assert!(graph_svg(&mut client, mission, None).await.is_ok());
    client.shutdown().await;
}

/// What `semo/graphSvg` answers for a mission with `kind` and `robot`.
async fn robot_svg(
    client: &mut semo_server::harness::TestClient,
    uri: &str,
    robot: Option<&str>,
) -> Result<Value, Value> {
    let mut params = json!({ "textDocument": { "uri": uri }, "kind": "taskgraph" });
    if let Some(robot) = robot {
        params["robot"] = json!(robot);
    }
    client.request("semo/graphSvg", params).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_missions_robot_is_drawn_as_its_generated_task_graph() {
    let text = shared("swarm/march.mission");
    let uri = "file:///m/march.mission";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let first = robot_svg(&mut client, uri, None).await.unwrap();
    let robots: Vec<&str> = first["robots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_str().unwrap())
        .collect();
    assert!(robots.len() > 1, "{first}");
    assert_eq!(first["robot"], robots[0]);
    let last = robots[robots.len() - 1].to_string();
    let chosen = robot_svg(&mut client, uri, Some(&last)).await.unwrap();
    assert_eq!(chosen["robot"], last.as_str());
    // The picture is the written taskgraph.xml's, as `semo graph svg` draws it.
    for answer in [&first, &chosen] {
        let svg = answer["svg"].as_str().unwrap();
        assert!(svg.starts_with("<svg"), "{svg}");
        assert!(svg.contains("class=\"node task"), "{svg}");
    }
    let unknown = robot_svg(&mut client, uri, Some("nobody"))
        .await
        .unwrap_err();
    let message = unknown["message"].as_str().unwrap();
    assert!(message.contains("no robot `nobody`"), "{message}");
    assert!(message.contains(&last), "{message}");
    // The same robot's taskgraph.xml, opened from a generated folder: drawn too.
    let graph = format!(
        "file:///out/{}/{last}/taskgraph.xml",
        chosen["team"].as_str().unwrap()
    );
    let written = generated_taskgraph(&text, &last);
    client.open(&graph, &written).await;
    let opened = graph_svg(&mut client, &graph, None).await.unwrap();
    assert_eq!(opened["svg"], chosen["svg"]);
    client.shutdown().await;
}

/// The `taskgraph.xml` `semo build --emit taskgraph` writes for `robot` of
/// `mission` (built-in catalog), through the library as the CLI calls it.
fn generated_taskgraph(mission: &str, robot: &str) -> String {
    let mut host = semo::host::AnalysisHost::default();
    let id = semo::diag::FileId(0);
    let path = Some(std::path::PathBuf::from("/m/march.mission"));
    host.set_file(id, path, semo::workspace::FileKind::Mission, mission.into());
    let build = host.analysis().build_input(id).expect("a mission");
    let refined = semo::refine::refine_checked(&build.input());
    let program = refined
        .programs
        .iter()
        .find(|p| p.robot == robot)
        .expect("the robot");
    semo::taskgraph::write::to_xml(&program.graph, "test")
}
