//! Task-graph files in the editor: SDF warnings on the element concerned,
//! hover with repetition counts and rates, `task.port` completion in a
//! channel's `src`/`dst`, and repetition counts as inlay hints.

mod support;

use serde_json::{Value, json};
use support::{client_with, cursors, text_at};

fn example(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/examples/taskgraphs")
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
