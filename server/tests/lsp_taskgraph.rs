//! Task-graph files in the editor: SDF warnings on the element concerned,
//! hover with repetition counts and rates, `task.port` completion in a
//! channel's `src`/`dst`, and repetition counts as inlay hints.

mod support;

use serde_json::{Value, json};
use support::{client_with, cursors, text_at};

fn example(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/taskgraphs")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_inconsistent_graph_gets_its_warning_on_the_channel() {
    let text = example("inconsistent.taskgraph.xml");
    let uri = "file:///g/inconsistent.taskgraph.xml";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let diags = client.diagnostics(uri, Some(1)).await;
    assert!(!diags.is_empty());
    let first = &diags[0];
    assert!(first["code"].as_str().unwrap().starts_with('E'), "{first}");
    assert!(
        text_at(&text, &first["range"]).contains('.'),
        "on a channel end: {first}"
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn hover_completion_and_inlay_hints_on_the_data_loop() {
    let marked = example("data_loop.taskgraph.xml")
        .replace("<Task name=\"B\">", "<Task name=\"$0B\">")
        .replace("<Channel src=\"B.o\"", "<Channel src=\"$0B.o\"");
    let (text, at) = cursors(&marked);
    let uri = "file:///g/data_loop.taskgraph.xml";
    let mut client = client_with(uri, &text).await;

    let hover = client
        .request(
            "textDocument/hover",
            json!({ "textDocument": { "uri": uri }, "position": at[0] }),
        )
        .await
        .unwrap();
    let md = hover["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("fires **1×** per iteration of `data_loop/L`"),
        "{md}"
    );
    assert_eq!(text_at(&text, &hover["range"]), "B");

    let completion = client
        .request(
            "textDocument/completion",
            json!({ "textDocument": { "uri": uri }, "position": at[1] }),
        )
        .await
        .unwrap();
    let labels: Vec<&str> = completion["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["B.o", "C.o", "L.in"]);
    let edit = &completion["items"][0]["textEdit"];
    assert_eq!(text_at(&text, &edit["range"]), "B.o");

    let end = support::position_of(&text, text.len());
    let hints = client
        .request(
            "textDocument/inlayHint",
            json!({ "textDocument": { "uri": uri }, "range": { "start": { "line": 0, "character": 0 }, "end": end } }),
        )
        .await
        .unwrap();
    let labels: Vec<Value> = hints
        .as_array()
        .unwrap()
        .iter()
        .map(|h| h["label"].clone())
        .collect();
    assert_eq!(labels, ["×1", "×1", "×1", "×1", "×1"]);
    client.shutdown().await;
}

const PARENT: &str = r#"<TaskGraph name="parent" xmlns="urn:semo:taskgraph:1">
  <Task name="A"><Port name="o" dir="out"/></Task>
  <Task name="$0B" subgraph="$0child.taskgraph.xml"><Port name="in" dir="in"/></Task>
  <Channel src="A.o" dst="B.in"/>
</TaskGraph>
"#;

/// `in` is the open input port that `B.in` stands for.
const CHILD: &str = r#"<TaskGraph name="child" xmlns="urn:semo:taskgraph:1">
  <Task name="C"><Port name="in" dir="in"/></Task>
</TaskGraph>
"#;

fn codes(diagnostics: &[Value]) -> Vec<&str> {
    diagnostics
        .iter()
        .map(|d| d["code"].as_str().unwrap_or_default())
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sub_graph_problems_follow_the_referenced_document() {
    let (parent, at) = cursors(PARENT);
    let parent_uri = "file:///g/parent.taskgraph.xml";
    let child_uri = "file:///g/child.taskgraph.xml";
    let mut client = semo_server::harness::TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(parent_uri, &parent).await;
    // Neither open nor on the disk.
    let diags = client.diagnostics(parent_uri, Some(1)).await;
    assert_eq!(codes(&diags), ["E067"]);
    assert_eq!(text_at(&parent, &diags[0]["range"]), "child.taskgraph.xml");

    // Opening the child re-checks the graph referencing it.
    client.open(child_uri, CHILD).await;
    let diags = client.diagnostics(parent_uri, Some(1)).await;
    assert_eq!(codes(&diags), Vec::<&str>::new(), "{diags:?}");
    let hover = client
        .request(
            "textDocument/hover",
            json!({ "textDocument": { "uri": parent_uri }, "position": at[0] }),
        )
        .await
        .unwrap();
    let md = hover["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("stands for the sub-graph `child.taskgraph.xml`: each firing runs one iteration of it (C×1)"),
        "{md}"
    );

    // Renaming the child's open port breaks the correspondence.
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": child_uri, "version": 2 },
                "contentChanges": [{ "text": CHILD.replace("name=\"in\"", "name=\"input\"") }],
            }),
        )
        .await;
    let diags = client.diagnostics(parent_uri, Some(1)).await;
    assert_eq!(codes(&diags), ["E078", "E078"], "{diags:?}");
    assert_eq!(text_at(&parent, &diags[0]["range"]), "child.taskgraph.xml");

    // Go to definition on the attribute value opens the file it names.
    let found = client
        .request(
            "textDocument/definition",
            json!({ "textDocument": { "uri": parent_uri }, "position": at[1] }),
        )
        .await
        .unwrap();
    assert_eq!(found["uri"], child_uri, "{found}");
    assert_eq!(
        found["range"]["start"],
        json!({ "line": 0, "character": 0 })
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sub_graph_cycle_is_reported_on_the_reference_closing_it() {
    let (parent, _) = cursors(PARENT);
    let parent_uri = "file:///g/parent.taskgraph.xml";
    let child = CHILD.replace(
        "<Task name=\"C\">",
        "<Task name=\"C\" subgraph=\"../g/parent.taskgraph.xml\">",
    );
    let mut client = client_with("file:///g/child.taskgraph.xml", &child).await;
    client.open(parent_uri, &parent).await;
    let diags = client.diagnostics(parent_uri, Some(1)).await;
    let cycle = diags
        .iter()
        .find(|d| d["code"] == "E069")
        .unwrap_or_else(|| panic!("{diags:?}"));
    assert_eq!(
        cycle["message"],
        "`child.taskgraph.xml` leads back to this file: parent.taskgraph.xml → child.taskgraph.xml → parent.taskgraph.xml"
    );
    client.shutdown().await;
}
