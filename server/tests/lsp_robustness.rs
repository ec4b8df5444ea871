//! The server survives anything a client sends: malformed frames and JSON,
//! unknown methods, requests about files it never saw, positions past the end,
//! and a 10 MB document. After each abuse a normal request still works.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};

async fn still_serves(client: &mut TestClient) {
    assert!(client.server_is_running());
    let catalog = client.request("semo/catalog", json!({})).await;
    assert!(catalog.is_ok(), "{catalog:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn malformed_json_rpc_is_answered_or_ignored() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    for body in [
        "{ not json",
        "[]",
        "42",
        r#"{"jsonrpc":"2.0","id":1}"#,
        r#"{"jsonrpc":"2.0","method":7}"#,
        r#"{"jsonrpc":"2.0","id":{"x":1},"method":"hover"}"#,
        "\u{0}\u{1}binary",
    ] {
        let frame = format!("Content-Length: {}\r\n\r\n{body}", body.len());
        client.send_raw(frame.as_bytes()).await;
    }
    // A frame whose header is not understood.
    client.send_raw(b"Content-Type: nonsense\r\n\r\n{}").await;
    still_serves(&mut client).await;
    // Each bad frame got its JSON-RPC error: parse errors for what is not
    // JSON (or not framed), invalid request for JSON that is no message, and
    // "method not found" from tower-lsp for the odd id it accepts.
    let mut codes: Vec<i64> = client
        .take_unclaimed()
        .into_iter()
        .filter_map(|m| m["error"]["code"].as_i64())
        .collect();
    codes.sort();
    assert_eq!(
        codes,
        [
            -32700, -32700, -32700, -32601, -32600, -32600, -32600, -32600
        ]
    );
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unknown_methods_and_bad_params_get_errors() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let err = client
        .request("semo/noSuchThing", json!({}))
        .await
        .unwrap_err();
    assert_eq!(err["code"], -32601, "{err}");
    client.notify("semo/noSuchNotification", json!({})).await;
    client
        .notify("textDocument/didChange", json!({ "nonsense": true }))
        .await;
    let err = client
        .request("semo/viewFileText", json!(["wrong"]))
        .await
        .unwrap_err();
    assert_eq!(err["code"], -32602, "{err}");
    still_serves(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn requests_and_changes_for_unopened_files_are_harmless() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let err = client
        .request(
            "semo/viewFileText",
            json!({ "uri": "file:///never/opened.mission" }),
        )
        .await
        .unwrap_err();
    assert!(
        err["message"]
            .as_str()
            .unwrap()
            .contains("unknown document"),
        "{err}"
    );
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": "file:///never/opened.mission", "version": 2 },
                "contentChanges": [{ "text": "x" }]
            }),
        )
        .await;
    client
        .notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": "file:///never/opened.mission" } }),
        )
        .await;
    still_serves(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn positions_past_the_end_clamp() {
    let uri = "file:///t/clamp.mission";
    let mut client = support::client_with(uri, "ab\ncd\n").await;
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": uri, "version": 2 },
                "contentChanges": [
                    { "range": { "start": { "line": 0, "character": 99 }, "end": { "line": 0, "character": 120 } }, "text": "X" },
                    { "range": { "start": { "line": 50, "character": 0 }, "end": { "line": 60, "character": 3 } }, "text": "Y" },
                    { "range": { "start": { "line": 1, "character": 1 }, "end": { "line": 0, "character": 0 } }, "text": "" }
                ]
            }),
        )
        .await;
    let text = client
        .request("semo/viewFileText", json!({ "uri": uri }))
        .await
        .unwrap();
    assert_eq!(text, json!("d\nY"));
    client.diagnostics(uri, Some(2)).await;
    still_serves(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_ten_megabyte_document_is_checked_and_its_diagnostics_capped() {
    // Ten megabytes of damaged mission: many thousands of problems.
    let unit = "T.Action.Go { move(\"1,1\" \n stop() @ } repeat(2 SEC)\n# 한국어 😀\nT.M { set(Action Go) }\n";
    let text = unit.repeat(10_000_000 / unit.len() + 1);
    let uri = "file:///t/huge.mission";
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, &text).await;
    let diags: Vec<Value> = client.diagnostics(uri, Some(1)).await;
    assert_eq!(diags.len(), semo::diag::MAX_PER_FILE + 1);
    let last = diags.last().unwrap();
    assert_eq!(last["code"], "E004", "{last}");
    assert!(
        last["message"]
            .as_str()
            .unwrap()
            .contains("more problem(s)"),
        "{last}"
    );
    // An edit at the end of the huge document is applied and re-checked.
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": uri, "version": 2 },
                "contentChanges": [{ "range": { "start": { "line": 999999, "character": 0 }, "end": { "line": 999999, "character": 0 } }, "text": "\n# end" }]
            }),
        )
        .await;
    client.diagnostics(uri, Some(2)).await;
    still_serves(&mut client).await;
    client.shutdown().await;
}

/// The diagnostic codes of `diagnostics`.
fn codes(diagnostics: &[Value]) -> Vec<&str> {
    diagnostics
        .iter()
        .filter_map(|d| d["code"].as_str())
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_robot_count_past_the_limit_is_an_error_and_the_folder_still_checks() {
    let swarm = "file:///t/swarm/swarm.mission";
    let other = "file:///t/swarm/other.mission";
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    // What took 51 GB before the limit.
    let text = "{ S: Ev3_Robot ev[2147483648] }\nS.Action.Go { move(\"5,5\") } repeat()\nS.GO { set(Action, Go) }\nS.main { default: mode = GO }\n";
    client.open(swarm, text).await;
    let diagnostics = client.diagnostics(swarm, Some(1)).await;
    assert_eq!(codes(&diagnostics), ["E036"], "{diagnostics:?}");
    let range = &diagnostics[0]["range"];
    assert_eq!(support::text_at(text, range), "2147483648");
    // A mission beside it is checked as ever.
    let clean = "{ T: Ev3_Robot ev[1000] }\nT.Action.Go { move(\"5,5\") } repeat()\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n";
    client.open(other, clean).await;
    let diagnostics = client.diagnostics(other, Some(1)).await;
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    still_serves(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn xml_nested_a_million_deep_is_an_error_on_the_servers_threads() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    for (uri, open, close) in [
        (
            "file:///t/deep/deep.robot.xml",
            "<Catalog xmlns=\"urn:semo:catalog:1\">",
            "</Catalog>",
        ),
        (
            "file:///t/deep/deep.strategy.xml",
            "<Strategy name=\"T\">",
            "</Strategy>",
        ),
        (
            "file:///t/deep/deep.taskgraph.xml",
            "<TaskGraph name=\"g\">",
            "</TaskGraph>",
        ),
        (
            "file:///t/deep/sdf3.taskgraph.xml",
            "<sdf3 type=\"sdf\" version=\"1.0\">",
            "</sdf3>",
        ),
    ] {
        // 1,000,000 levels: the server's threads overflowed at about 50,000.
        let levels = 1_000_000;
        let text = [open, &"<x>".repeat(levels), &"</x>".repeat(levels), close].concat();
        client.open(uri, &text).await;
        let diagnostics = client.diagnostics(uri, Some(1)).await;
        assert!(
            codes(&diagnostics).contains(&"E097"),
            "{uri}: {diagnostics:?}"
        );
        // The element past the limit: the 256th `<x>` below the root.
        let e097 = diagnostics.iter().find(|d| d["code"] == "E097").unwrap();
        let column = open.len() + 255 * "<x>".len() + 1;
        assert_eq!(
            e097["range"]["start"],
            json!({ "line": 0, "character": column })
        );
        // Editor features on the file answer too.
        let hover = client
            .request(
                "textDocument/hover",
                json!({ "textDocument": { "uri": uri }, "position": { "line": 0, "character": column } }),
            )
            .await;
        assert!(hover.is_ok(), "{uri}: {hover:?}");
    }
    still_serves(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn loops_nested_to_the_xml_limit_are_analysed_and_drawn_on_the_servers_threads() {
    // 126 loops, the innermost `<Port>` 255 deep: the loader, the analyses
    // and the picture walk the nesting on the server's 2 MiB threads.
    let text = include_str!("../../tests/fixtures/limits/nested_loops.taskgraph.xml");
    let uri = "file:///t/nest/nested_loops.taskgraph.xml";
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, text).await;
    let diagnostics = client.diagnostics(uri, Some(1)).await;
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    let picture = client
        .request("semo/graphSvg", json!({ "textDocument": { "uri": uri } }))
        .await
        .unwrap();
    assert!(
        picture["svg"].as_str().unwrap().contains("L126"),
        "{picture}"
    );
    still_serves(&mut client).await;
    client.shutdown().await;
}
