//! Completion through the protocol. Each fixture in `fixtures/completion/`
//! holds a mission with `$0` cursors; the snapshot lists, for each cursor,
//! the items offered there in the server's order (most specific first):
//! label, kind, detail, and the text inserted when it differs from the label,
//! then the documentation of the first item. No label is offered twice at a
//! place.

mod support;

use serde_json::{Value, json};
use support::ide::{Session, render_cursors};
use support::text_at;

fn kind_name(kind: &Value) -> &'static str {
    match kind.as_u64().unwrap_or(0) {
        2 => "method",
        3 => "function",
        5 => "field",
        6 => "variable",
        7 => "class",
        9 => "module",
        10 => "property",
        11 => "unit",
        14 => "keyword",
        15 => "snippet",
        20 => "enum-member",
        21 => "constant",
        22 => "struct",
        23 => "event",
        _ => "?",
    }
}

fn visible(text: &str) -> String {
    text.replace('\n', "⏎").replace('\t', "⇥")
}

/// The completion list at each cursor of a document, rendered for a reader.
fn render(session: &mut Session, doc: &support::ide::Doc) -> String {
    render_cursors(session, doc, "textDocument/completion", |result| {
        let items = result["items"].as_array().cloned().unwrap_or_default();
        if items.is_empty() {
            return None;
        }
        let mut out = String::new();
        let replaced = text_at(&doc.text, &items[0]["textEdit"]["range"]);
        if !replaced.is_empty() {
            out.push_str(&format!("replacing `{replaced}`:\n"));
        }
        let mut sort_texts = Vec::new();
        let mut labels = std::collections::HashSet::new();
        for item in &items {
            let label = item["label"].as_str().unwrap();
            // A name means one thing at a place: it is offered once.
            assert!(
                labels.insert(label),
                "`{label}` is offered twice: {items:#?}"
            );
            let insert = item["textEdit"]["newText"].as_str().unwrap();
            let mut line = format!(
                "{label:<22} {:<11} {}",
                kind_name(&item["kind"]),
                item["detail"].as_str().unwrap_or("")
            );
            if insert != label {
                line.push_str(&format!("  ⇒ {}", visible(insert)));
            }
            out.push_str(line.trim_end());
            out.push('\n');
            sort_texts.push(item["sortText"].as_str().unwrap().to_string());
            // Every item edits the same identifier prefix, on one line.
            assert_eq!(item["textEdit"]["range"], items[0]["textEdit"]["range"]);
        }
        let mut sorted = sort_texts.clone();
        sorted.sort();
        assert_eq!(sort_texts, sorted, "items come in their sort order");
        if let Some(doc) = items[0]["documentation"]["value"].as_str() {
            out.push_str("\n    ");
            out.push_str(&doc.replace('\n', "\n    "));
            out.push('\n');
        }
        out.push('\n');
        Some(out)
    })
}

#[test]
fn completion_fixtures() {
    snapshot_fixtures!(
        "fixtures/completion/*.mission",
        cursors,
        "a fixture needs a $0 cursor",
        render
    );
}

/// A client without snippet support gets plain text: names, and constructs
/// with their placeholders' default text.
#[test]
fn plain_text_for_clients_without_snippets() {
    let caps = json!({ "general": { "positionEncodings": ["utf-16"] } });
    let mut session = Session::with_capabilities(Some(caps));
    let doc = session.open(
        "plain.mission",
        "{ T: iRobotCreate r }\nT.Action.Go{\n  $0\n} repeat()\nT.M{ set(Action, Go) }\nT.main{ default: mode = M }\n",
    );
    let result = session.at("textDocument/completion", &doc, &doc.cursors[0]);
    let items = result["items"].as_array().unwrap();
    let insert = |label: &str| {
        let item = items.iter().find(|i| i["label"] == label).unwrap();
        assert_eq!(item["insertTextFormat"], 1, "plain text: {item}");
        item["textEdit"]["newText"].as_str().unwrap().to_string()
    };
    assert_eq!(insert("move"), "move");
    assert_eq!(insert("stop"), "stop()");
    assert_eq!(insert("if"), "if (condition) {\n  \n}");
    assert_eq!(insert("send"), "send(T, VALUE)");
    assert!(items.iter().all(|i| i["insertTextFormat"] == 1));
    session.shutdown();
}

/// Robot types come from the workspace's catalog files too.
#[test]
fn robot_types_of_workspace_catalog_files() {
    let dir = std::env::temp_dir().join(format!("semo-completion-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("bots.robot.xml"),
        r#"<Catalog><Robot type="MyBot"><Doc>A robot of ours.</Doc>
  <Service name="dance" doc="Dance."/></Robot></Catalog>"#,
    )
    .unwrap();
    let mission = "{\n  T: MyBot m\n}\nT.Action.Go{\n  stop()\n} repeat()\n";
    std::fs::write(dir.join("a.mission"), mission).unwrap();
    let root = format!("file://{}", dir.display());
    let uri = format!("{root}/a.mission");

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let mut client = semo_server::harness::TestClient::start();
        client.initialize(&["utf-16"], Some(&root)).await;
        // Published once the workspace is indexed, catalog included.
        client.diagnostics(&uri, None).await;
        let at = |line: u32, character: u32| {
            json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": character } })
        };
        let types = client
            .request("textDocument/completion", at(1, 5))
            .await
            .unwrap();
        let labels: Vec<&str> = types["items"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i["label"].as_str().unwrap())
            .collect();
        assert!(labels.contains(&"MyBot"), "{labels:?}");
        assert!(labels.contains(&"iRobotCreate"), "{labels:?}");
        // In the body: MyBot's services only.
        let services = client
            .request("textDocument/completion", at(4, 2))
            .await
            .unwrap();
        let labels: Vec<&str> = services["items"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|i| i["kind"] == 3)
            .map(|i| i["label"].as_str().unwrap())
            .collect();
        assert_eq!(labels, ["dance"]);
        client.shutdown().await;
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// Typing a line character by character, as an editor sends it: the
/// completions follow what is typed, in text that does not parse yet.
#[test]
fn completions_while_typing() {
    let mut session = Session::new();
    let text = "{ T: TIEvalbot t }\nT.Action.Go{\n  \n} repeat()\nT.M{ set(Action, Go) }\nT.main{ default: mode = M }\n";
    let doc = session.open("typing.mission", text);
    let typed = "if(T.COLOR == \"RED\") sea";
    let mut expectations = vec![
        (2, "if"),
        (3, "BATTERY"),
        (4, "T"),
        (5, "COLOR"),
        (typed.len(), "search"),
    ];
    expectations.reverse();
    let mut version = 1;
    for (i, ch) in typed.char_indices() {
        version += 1;
        let change = json!({
            "textDocument": { "uri": doc.uri, "version": version },
            "contentChanges": [{
                "range": { "start": { "line": 2, "character": 2 + i }, "end": { "line": 2, "character": 2 + i } },
                "text": ch.to_string()
            }]
        });
        session.notify("textDocument/didChange", change);
        let typed_so_far = i + ch.len_utf8();
        if expectations.last().is_some_and(|(n, _)| *n == typed_so_far) {
            let (_, wanted) = expectations.pop().unwrap();
            let position = json!({ "line": 2, "character": 2 + typed_so_far });
            let result = session.at("textDocument/completion", &doc, &position);
            let labels: Vec<&str> = result["items"]
                .as_array()
                .unwrap()
                .iter()
                .map(|i| i["label"].as_str().unwrap())
                .collect();
            assert!(
                labels.contains(&wanted),
                "after `{}`: {labels:?}",
                &typed[..typed_so_far]
            );
        }
    }
    assert!(expectations.is_empty());
    session.shutdown();
}

/// The replaced range counts columns as negotiated: after a Korean string,
/// UTF-8 columns are bytes, UTF-16 ones code units.
#[test]
fn replaced_ranges_in_both_encodings() {
    let text = "{ T: iRobotCreate r }\nT.Action.Go{\n  send(USER, \"한국어\") sto\n} repeat()\nT.M{ set(Action, Go) }\nT.main{ default: mode = M }\n";
    let line = text.lines().nth(2).unwrap();
    let end_bytes = line.len();
    let end_units = line.encode_utf16().count();
    for (encoding, end) in [("utf-8", end_bytes), ("utf-16", end_units)] {
        let caps = json!({
            "general": { "positionEncodings": [encoding] },
            "textDocument": { "completion": { "completionItem": { "snippetSupport": true } } }
        });
        let mut session = Session::with_capabilities(Some(caps));
        let doc = session.open("enc.mission", text);
        let position = json!({ "line": 2, "character": end });
        let result = session.at("textDocument/completion", &doc, &position);
        let stop = result["items"]
            .as_array()
            .unwrap()
            .iter()
            .find(|i| i["label"] == "stop")
            .expect("stop is offered");
        assert_eq!(
            stop["textEdit"]["range"],
            json!({
                "start": { "line": 2, "character": end - 3 },
                "end": { "line": 2, "character": end }
            }),
            "{encoding}"
        );
        session.shutdown();
    }
}
