//! Navigation through the protocol: go to definition, find references,
//! document highlights, prepare rename and rename.
//!
//! Each fixture in `tests/fixtures/<request>/` is a mission whose `$0`
//! markers are cursors; its snapshot (`tests/snapshots/lsp_navigation__*`)
//! shows, for each cursor, what the server answers, every range marked `‹…›`
//! in its line.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::fmt::Write;
use support::render::{self, at, list};
use support::{client_with, cursors};

#[test]
fn definition() {
    let rt = render::runtime();
    insta::glob!("fixtures/definition/*.mission", |path| {
        let raw = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(definitions(&raw)));
    });
}

async fn definitions(raw: &str) -> String {
    let (text, positions) = cursors(raw);
    let uri = "file:///t/definition.mission";
    let mut client = client_with(uri, &text).await;
    let mut out = String::new();
    for pos in &positions {
        let result = client
            .request("textDocument/definition", at(uri, pos))
            .await
            .expect("definition answers");
        writeln!(out, "{}", render::cursor(&text, pos)).unwrap();
        let found = list(result);
        if found.is_empty() {
            writeln!(out, "  (no definition)").unwrap();
        }
        for location in found {
            assert_eq!(location["uri"], uri);
            writeln!(out, "  → {}", render::range(&text, &location["range"])).unwrap();
        }
    }
    client.shutdown().await;
    out
}

/// Names of the workspace catalog go to their element in the `*.robot.xml`
/// file; built-in ones go nowhere.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn definition_in_a_workspace_catalog_file() {
    let root = render::fixtures().join("workspace");
    let xml = std::fs::read_to_string(root.join("robots.robot.xml")).unwrap();
    let (text, positions) = cursors(&std::fs::read_to_string(root.join("alpha.mission")).unwrap());
    let uri = render::file_uri(&root.join("alpha.mission"));
    let mut client = workspace_client(&root).await;
    client.open(&uri, &text).await;
    assert_eq!(client.diagnostics(&uri, Some(1)).await, Vec::<Value>::new());

    let mut out = String::new();
    for pos in &positions {
        let result = client
            .request("textDocument/definition", at(&uri, pos))
            .await
            .unwrap();
        writeln!(out, "{}", render::cursor(&text, pos)).unwrap();
        let found = list(result);
        if found.is_empty() {
            writeln!(out, "  (no definition)").unwrap();
        }
        for location in found {
            let target = location["uri"].as_str().unwrap();
            assert!(target.ends_with("/workspace/robots.robot.xml"), "{target}");
            writeln!(
                out,
                "  → robots.robot.xml {}",
                render::range(&xml, &location["range"])
            )
            .unwrap();
        }
    }
    client.shutdown().await;
    insta::assert_snapshot!(out);
}

/// A client whose workspace folder is `root`, once its catalog file is indexed.
async fn workspace_client(root: &std::path::Path) -> TestClient {
    let mut client = TestClient::start();
    client
        .initialize(&["utf-16"], Some(&render::file_uri(root)))
        .await;
    let catalog = render::file_uri(&root.join("robots.robot.xml"));
    assert_eq!(
        client.diagnostics(&catalog, None).await,
        Vec::<Value>::new()
    );
    client
}

#[test]
fn references_and_highlights() {
    let rt = render::runtime();
    insta::glob!("fixtures/references/*.mission", |path| {
        let raw = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(references(&raw)));
    });
}

/// For each cursor, every reference with: `def` if it is left out without
/// declarations, and its highlight kind (`write` or `read`).
async fn references(raw: &str) -> String {
    let (text, positions) = cursors(raw);
    let uri = "file:///t/references.mission";
    let mut client = client_with(uri, &text).await;
    let mut out = String::new();
    for pos in &positions {
        let refs = |include: bool| {
            let mut params = at(uri, pos);
            params["context"] = json!({ "includeDeclaration": include });
            params
        };
        let (with, without) = (refs(true), refs(false));
        let with = list(
            client
                .request("textDocument/references", with)
                .await
                .unwrap(),
        );
        let without = list(
            client
                .request("textDocument/references", without)
                .await
                .unwrap(),
        );
        let highlights = list(
            client
                .request("textDocument/documentHighlight", at(uri, pos))
                .await
                .unwrap(),
        );
        assert_eq!(
            with.iter().map(|l| &l["range"]).collect::<Vec<_>>(),
            highlights.iter().map(|h| &h["range"]).collect::<Vec<_>>(),
            "highlights are the references in the file"
        );
        writeln!(out, "{}", render::cursor(&text, pos)).unwrap();
        for (location, highlight) in with.iter().zip(&highlights) {
            assert_eq!(location["uri"], uri);
            let declaration = !without.contains(location);
            let kind = match highlight["kind"].as_u64() {
                Some(3) => "write",
                Some(2) => "read",
                other => panic!("highlight kind {other:?}"),
            };
            writeln!(
                out,
                "  {:<4} {:<5} {}",
                if declaration { "def" } else { "" },
                kind,
                render::range(&text, &location["range"])
            )
            .unwrap();
        }
        assert!(without.iter().all(|l| with.contains(l)));
    }
    client.shutdown().await;
    out
}

#[test]
fn rename() {
    let rt = render::runtime();
    insta::glob!("fixtures/rename/*.mission", |path| {
        let raw = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(renames(&raw)));
    });
}

/// For each cursor: what prepareRename says, then the rename to the name of
/// the fixture's `# rename:` line: the lines it changes, or its error.
async fn renames(raw: &str) -> String {
    let (text, positions) = cursors(raw);
    let new_name = render::header(&text, "rename").expect("a `# rename:` line");
    let uri = "file:///t/rename.mission";
    let mut client = client_with(uri, &text).await;
    let mut out = String::new();
    for pos in &positions {
        writeln!(out, "{}", render::cursor(&text, pos)).unwrap();
        match client
            .request("textDocument/prepareRename", at(uri, pos))
            .await
        {
            Ok(range) => writeln!(out, "  prepare: {}", render::range(&text, &range)).unwrap(),
            Err(e) => {
                assert_eq!(e["code"], -32803, "{e}");
                writeln!(out, "  prepare: error: {}", e["message"].as_str().unwrap()).unwrap();
            }
        }
        let mut params = at(uri, pos);
        params["newName"] = json!(new_name);
        match client.request("textDocument/rename", params).await {
            Ok(edit) => {
                let edits = edit["changes"][uri].as_array().expect("edits of this file");
                assert_eq!(edit["changes"].as_object().unwrap().len(), 1);
                let renamed = apply(&text, edits);
                let n = edits.len();
                let plural = if n == 1 { "" } else { "s" };
                writeln!(out, "  rename to {new_name}: {n} edit{plural}").unwrap();
                for (before, after) in text.lines().zip(renamed.lines()) {
                    if before != after {
                        writeln!(out, "    - {}\n    + {}", before.trim(), after.trim()).unwrap();
                    }
                }
                // The renamed mission means the same: it has the same diagnostics.
                assert_eq!(
                    diagnostic_codes(&mut client, &renamed).await,
                    diagnostic_codes(&mut client, &text).await,
                    "{renamed}"
                );
            }
            Err(e) => {
                assert_eq!(e["code"], -32803, "{e}");
                writeln!(
                    out,
                    "  rename to {new_name}: error: {}",
                    e["message"].as_str().unwrap()
                )
                .unwrap();
            }
        }
    }
    client.shutdown().await;
    out
}

/// `text` with the edits applied (UTF-16 ranges, not overlapping).
fn apply(text: &str, edits: &[Value]) -> String {
    let mut spans: Vec<(usize, usize, &str)> = edits
        .iter()
        .map(|e| {
            (
                render::offset_at(text, &e["range"]["start"]),
                render::offset_at(text, &e["range"]["end"]),
                e["newText"].as_str().unwrap(),
            )
        })
        .collect();
    spans.sort();
    let mut out = text.to_string();
    for (start, end, new) in spans.into_iter().rev() {
        out.replace_range(start..end, new);
    }
    out
}

/// The diagnostic codes of `text`, opened as a new document.
async fn diagnostic_codes(client: &mut TestClient, text: &str) -> Vec<Value> {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let uri = format!("file:///t/check{n}.mission");
    client.open(&uri, text).await;
    let diags = client.diagnostics(&uri, Some(1)).await;
    diags.iter().map(|d| d["code"].clone()).collect()
}

/// Every navigation request at every position of a broken file, and past
/// its end, answers (with an empty result at worst) and the server lives on.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_position_of_a_broken_file_answers() {
    let text = "# 한국어 😀\n{ T: iRobotCreate r\n  U iRobotCreate }\nT.P.S {\n  move(\"1,1\"\n  if (LOCATION == ) throw x\n  [[ group(instance of ) { stop( } \n}\nT.M { set(P, S) set( }\nT.main { case (M): catch (x): mode = \n\"unterminated";
    let uri = "file:///t/broken.mission";
    let mut client = client_with(uri, text).await;
    let lines = text.lines().count() as u32;
    let mut positions = Vec::new();
    for (line, content) in text.lines().enumerate() {
        for col in 0..=content.encode_utf16().count() as u32 + 1 {
            positions.push(json!({ "line": line, "character": col }));
        }
    }
    positions.push(json!({ "line": lines + 5, "character": 0 }));
    positions.push(json!({ "line": 0, "character": 9999 }));
    for pos in &positions {
        let mut refs = at(uri, pos);
        refs["context"] = json!({ "includeDeclaration": true });
        let mut rename = at(uri, pos);
        rename["newName"] = json!("fresh");
        for (method, params) in [
            ("textDocument/definition", at(uri, pos)),
            ("textDocument/references", refs),
            ("textDocument/documentHighlight", at(uri, pos)),
        ] {
            client
                .request(method, params)
                .await
                .unwrap_or_else(|e| panic!("{method} at {pos}: {e}"));
        }
        for (method, params) in [
            ("textDocument/prepareRename", at(uri, pos)),
            ("textDocument/rename", rename),
        ] {
            if let Err(e) = client.request(method, params).await {
                assert_eq!(e["code"], -32803, "{method} at {pos}: {e}");
            }
        }
    }
    assert!(client.server_is_running());
    client.shutdown().await;
}

/// A mission is self-contained: renaming a team renames it in its file only,
/// even when another mission of the workspace has a team of that name.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn rename_stays_in_the_mission() {
    let root = render::fixtures().join("workspace");
    let (text, _) = cursors(&std::fs::read_to_string(root.join("alpha.mission")).unwrap());
    let uri = render::file_uri(&root.join("alpha.mission"));
    let mut client = workspace_client(&root).await;
    client.open(&uri, &text).await;
    client.diagnostics(&uri, Some(1)).await;
    let air = text.find("Air:").unwrap();
    let mut params = at(&uri, &support::position_of(&text, air));
    params["newName"] = json!("Sky");
    let edit = client.request("textDocument/rename", params).await.unwrap();
    let changes = edit["changes"].as_object().unwrap();
    assert_eq!(changes.keys().collect::<Vec<_>>(), [&uri]);
    // `Air:`, `Air.Action.Survey`, `Air.SURVEY`, `Air.main`; not beta's `Air`.
    assert_eq!(changes[&uri].as_array().unwrap().len(), 4);
    client.shutdown().await;
}
