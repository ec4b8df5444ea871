//! Structure through the protocol: document outline, workspace symbols,
//! semantic tokens, folding ranges and selection ranges.
//!
//! Each fixture in `tests/fixtures/<request>/` is a mission (with `$0`
//! cursors where the request takes positions); its snapshot
//! (`tests/snapshots/lsp_structure__*`) shows the answer, every range marked
//! `‹…›` in its line.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::fmt::Write;
use support::render::{self, list};
use support::{client_with, cursors};

fn doc(uri: &str) -> Value {
    json!({ "textDocument": { "uri": uri } })
}

fn symbol_kind(kind: &Value) -> &'static str {
    match kind.as_u64() {
        Some(3) => "namespace",
        Some(5) => "class",
        Some(8) => "field",
        Some(12) => "function",
        Some(13) => "variable",
        Some(22) => "enum-member",
        Some(24) => "event",
        other => panic!("unexpected symbol kind {other:?}"),
    }
}

#[test]
fn document_symbol() {
    let rt = render::runtime();
    insta::glob!("fixtures/document_symbol/*.mission", |path| {
        let text = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(outline(&text)));
    });
}

async fn outline(text: &str) -> String {
    let uri = "file:///t/outline.mission";
    let mut client = client_with(uri, text).await;
    let symbols = client
        .request("textDocument/documentSymbol", doc(uri))
        .await
        .unwrap();
    client.shutdown().await;
    let mut out = String::new();
    write_symbols(text, &list(symbols), None, 0, &mut out);
    out
}

/// Each symbol: kind, name, detail, its name in its line, and how many lines
/// it spans; children indented. Checks that every name is inside its range
/// and every range inside its parent's.
fn write_symbols(
    text: &str,
    symbols: &[Value],
    parent: Option<(usize, usize)>,
    depth: usize,
    out: &mut String,
) {
    for s in symbols {
        let span = |r: &Value| {
            (
                render::offset_at(text, &r["start"]),
                render::offset_at(text, &r["end"]),
            )
        };
        let (range, name) = (span(&s["range"]), span(&s["selectionRange"]));
        assert!(range.0 <= name.0 && name.1 <= range.1, "{s}");
        if let Some(p) = parent {
            assert!(p.0 <= range.0 && range.1 <= p.1, "{s}");
        }
        let lines = text[range.0..range.1].matches('\n').count() + 1;
        writeln!(
            out,
            "{:indent$}{} {}{} — {} ({lines} line{})",
            "",
            symbol_kind(&s["kind"]),
            s["name"].as_str().unwrap(),
            s["detail"]
                .as_str()
                .map(|d| format!(" [{d}]"))
                .unwrap_or_default(),
            render::range(text, &s["selectionRange"]),
            if lines == 1 { "" } else { "s" },
            indent = depth * 2
        )
        .unwrap();
        if let Some(children) = s["children"].as_array() {
            write_symbols(text, children, Some(range), depth + 1, out);
        }
    }
}

/// Searches over every mission the server knows: `alpha` is open, `beta`
/// only indexed from the workspace folder.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn workspace_symbol() {
    let root = render::fixtures().join("workspace");
    let (alpha, _) = cursors(&std::fs::read_to_string(root.join("alpha.mission")).unwrap());
    let alpha_uri = render::file_uri(&root.join("alpha.mission"));
    let mut client = TestClient::start();
    client
        .initialize(&["utf-16"], Some(&render::file_uri(&root)))
        .await;
    let beta_uri = render::file_uri(&root.join("beta.mission"));
    client.diagnostics(&beta_uri, None).await;
    client.open(&alpha_uri, &alpha).await;
    client.diagnostics(&alpha_uri, Some(1)).await;
    let beta = std::fs::read_to_string(root.join("beta.mission")).unwrap();

    let mut out = String::new();
    for query in ["survey", "SURV", "land", "fw", "nothing_like_this"] {
        let found = client
            .request("workspace/symbol", json!({ "query": query }))
            .await
            .unwrap();
        writeln!(out, "query {query:?}").unwrap();
        for s in list(found) {
            let uri = s["location"]["uri"].as_str().unwrap();
            let (file, text) = if uri == alpha_uri {
                ("alpha", &alpha)
            } else {
                assert_eq!(uri, beta_uri);
                ("beta", &beta)
            };
            writeln!(
                out,
                "  {} {}{} — {file} {}",
                symbol_kind(&s["kind"]),
                s["name"].as_str().unwrap(),
                s["containerName"]
                    .as_str()
                    .map(|c| format!(" in {c}"))
                    .unwrap_or_default(),
                render::range(text, &s["location"]["range"])
            )
            .unwrap();
        }
    }
    let everything = list(
        client
            .request("workspace/symbol", json!({ "query": "" }))
            .await
            .unwrap(),
    );
    // alpha: 2 teams, 2 services, 2 modes; beta: a team, 2 services, 2 modes, a function.
    assert_eq!(everything.len(), 12);
    client.shutdown().await;
    insta::assert_snapshot!(out);
}

/// The legend of the `initialize` answer, as (token types, modifiers).
async fn legend(client: &mut TestClient, encodings: &[&str]) -> (Vec<String>, Vec<String>) {
    let init = client.initialize(encodings, None).await;
    let legend = &init["capabilities"]["semanticTokensProvider"]["legend"];
    let names = |key: &str| -> Vec<String> {
        legend[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect()
    };
    (names("tokenTypes"), names("tokenModifiers"))
}

/// A decoded token: line, column (in the encoding's units), length, type
/// and modifiers.
#[derive(Debug, PartialEq)]
struct Token {
    line: usize,
    col: usize,
    len: usize,
    kind: String,
    modifiers: Vec<String>,
}

fn decode(data: &Value, legend: &(Vec<String>, Vec<String>)) -> Vec<Token> {
    let data: Vec<usize> = data
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(data.len() % 5, 0);
    let (mut line, mut col) = (0, 0);
    let mut tokens: Vec<Token> = Vec::new();
    for t in data.chunks(5) {
        if t[0] > 0 {
            line += t[0];
            col = t[1];
        } else {
            col += t[1];
        }
        if let Some(prev) = tokens.last() {
            assert!(prev.line < line || prev.col + prev.len <= col, "overlap");
        }
        tokens.push(Token {
            line,
            col,
            len: t[2],
            kind: legend.0[t[3]].clone(),
            modifiers: (0..legend.1.len())
                .filter(|i| t[4] & (1 << i) != 0)
                .map(|i| legend.1[i].clone())
                .collect(),
        });
    }
    tokens
}

/// The text of a token: `units` counts a character's columns.
fn token_text(text: &str, t: &Token, units: fn(char) -> usize) -> String {
    let line = text.lines().nth(t.line).expect("the token's line");
    let mut col = 0;
    let mut out = String::new();
    for ch in line.chars() {
        if col >= t.col && col < t.col + t.len {
            out.push(ch);
        }
        col += units(ch);
    }
    assert!(t.col + t.len <= col, "a token stays on its line");
    out
}

async fn tokens_of(text: &str, encodings: &[&str], range: Option<Value>) -> Vec<(Token, String)> {
    let uri = "file:///t/tokens.mission";
    let mut client = TestClient::start();
    let legend = legend(&mut client, encodings).await;
    client.open(uri, text).await;
    client.diagnostics(uri, Some(1)).await;
    let result = match range {
        None => client
            .request("textDocument/semanticTokens/full", doc(uri))
            .await
            .unwrap(),
        Some(range) => {
            let mut params = doc(uri);
            params["range"] = range;
            client
                .request("textDocument/semanticTokens/range", params)
                .await
                .unwrap()
        }
    };
    client.shutdown().await;
    let units: fn(char) -> usize = if encodings.contains(&"utf-8") {
        char::len_utf8
    } else {
        char::len_utf16
    };
    decode(&result["data"], &legend)
        .into_iter()
        .map(|t| {
            let s = token_text(text, &t, units);
            (t, s)
        })
        .collect()
}

#[test]
fn semantic_tokens() {
    let rt = render::runtime();
    insta::glob!("fixtures/semantic_tokens/*.mission", |path| {
        let text = std::fs::read_to_string(path).unwrap();
        let utf16 = rt.block_on(tokens_of(&text, &["utf-16"], None));
        let utf8 = rt.block_on(tokens_of(&text, &["utf-8", "utf-16"], None));
        // The same names in both encodings, at different columns after
        // Korean text and emoji.
        let names = |tokens: &[(Token, String)]| -> Vec<(usize, String, String)> {
            tokens
                .iter()
                .map(|(t, s)| (t.line, s.clone(), t.kind.clone()))
                .collect()
        };
        assert_eq!(names(&utf16), names(&utf8));
        assert!(utf16.iter().zip(&utf8).any(|(a, b)| a.0.col != b.0.col));
        let mut out = String::new();
        for (t, s) in &utf16 {
            writeln!(
                out,
                "{}:{} {s} {}{}",
                t.line + 1,
                t.col + 1,
                t.kind,
                t.modifiers
                    .iter()
                    .map(|m| format!(" +{m}"))
                    .collect::<String>()
            )
            .unwrap();
        }
        insta::assert_snapshot!(out);
    });
}

/// A range request answers the tokens of the full request that overlap it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn semantic_tokens_of_a_range() {
    let path = render::fixtures().join("semantic_tokens/korean_emoji.mission");
    let text = std::fs::read_to_string(path).unwrap();
    let range = json!({
        "start": { "line": 6, "character": 30 },
        "end": { "line": 8, "character": 0 },
    });
    let part = tokens_of(&text, &["utf-16"], Some(range)).await;
    let full = tokens_of(&text, &["utf-16"], None).await;
    let expected: Vec<&(Token, String)> = full
        .iter()
        .filter(|(t, _)| (t.line == 6 && t.col + t.len > 30) || t.line == 7)
        .collect();
    assert!(expected.len() > 5);
    assert_eq!(part.iter().collect::<Vec<_>>(), expected);
}

#[test]
fn folding_range() {
    let rt = render::runtime();
    insta::glob!("fixtures/folding_range/*.mission", |path| {
        let text = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(folds(&text)));
    });
}

async fn folds(text: &str) -> String {
    let uri = "file:///t/folds.mission";
    let mut client = client_with(uri, text).await;
    let ranges = client
        .request("textDocument/foldingRange", doc(uri))
        .await
        .unwrap();
    client.shutdown().await;
    let lines: Vec<&str> = text.lines().collect();
    let mut out = String::new();
    for r in list(ranges) {
        let (start, end) = (
            r["startLine"].as_u64().unwrap() as usize,
            r["endLine"].as_u64().unwrap() as usize,
        );
        assert!(start < end, "{r}");
        writeln!(
            out,
            "{:>2}-{:<2} {:<8} {}  …  {}",
            start + 1,
            end + 1,
            r["kind"].as_str().unwrap_or("block"),
            lines[start].trim(),
            lines[end].trim()
        )
        .unwrap();
    }
    out
}

#[test]
fn selection_range() {
    let rt = render::runtime();
    insta::glob!("fixtures/selection_range/*.mission", |path| {
        let raw = std::fs::read_to_string(path).unwrap();
        insta::assert_snapshot!(rt.block_on(selections(&raw)));
    });
}

async fn selections(raw: &str) -> String {
    let (text, positions) = cursors(raw);
    let uri = "file:///t/selection.mission";
    let mut client = client_with(uri, &text).await;
    let mut params = doc(uri);
    params["positions"] = json!(positions);
    let result = client
        .request("textDocument/selectionRange", params)
        .await
        .unwrap();
    client.shutdown().await;
    let mut out = String::new();
    for (pos, selection) in positions.iter().zip(list(result)) {
        writeln!(out, "{}", render::cursor(&text, pos)).unwrap();
        let mut next = Some(&selection);
        while let Some(s) = next {
            writeln!(out, "  {}", render::range(&text, &s["range"])).unwrap();
            next = s.get("parent");
        }
    }
    out
}

/// Every structure request on a broken file, and selection ranges at every
/// position and past the end, answer; the server lives on.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn broken_files_and_any_position_answer() {
    let text = "# 한국어 😀\n{ T: iRobotCreate r\n  U iRobotCreate }\nT.P.S {\n  move(\"1,1\"\n  if (LOCATION == ) throw x\n  [[ group(instance of ) { stop( } \n}\nT.M { set(P, S) set( }\nT.main { case (M): catch (x): mode = \n\"unterminated";
    let uri = "file:///t/broken.mission";
    let mut client = client_with(uri, text).await;
    for method in [
        "textDocument/documentSymbol",
        "textDocument/semanticTokens/full",
        "textDocument/foldingRange",
    ] {
        client
            .request(method, doc(uri))
            .await
            .unwrap_or_else(|e| panic!("{method}: {e}"));
    }
    let mut positions = Vec::new();
    for (line, content) in text.lines().enumerate() {
        for col in 0..=content.encode_utf16().count() + 1 {
            positions.push(json!({ "line": line, "character": col }));
        }
    }
    positions.push(json!({ "line": 99, "character": 0 }));
    let mut params = doc(uri);
    params["positions"] = json!(positions);
    let selections = client
        .request("textDocument/selectionRange", params)
        .await
        .unwrap();
    assert_eq!(list(selections).len(), positions.len());
    let mut params = doc(uri);
    params["range"] =
        json!({ "start": { "line": 50, "character": 0 }, "end": { "line": 0, "character": 0 } });
    client
        .request("textDocument/semanticTokens/range", params)
        .await
        .unwrap();
    assert!(client.server_is_running());
    client.shutdown().await;
}

/// The server announces every feature of this file and of `lsp_navigation`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn capabilities_are_announced() {
    let mut client = TestClient::start();
    let init = client.initialize(&["utf-16"], None).await;
    let caps = &init["capabilities"];
    for key in [
        "definitionProvider",
        "referencesProvider",
        "documentHighlightProvider",
        "documentSymbolProvider",
        "workspaceSymbolProvider",
        "foldingRangeProvider",
        "selectionRangeProvider",
    ] {
        assert_eq!(caps[key], true, "{key}");
    }
    assert_eq!(caps["renameProvider"]["prepareProvider"], true);
    let tokens = &caps["semanticTokensProvider"];
    assert_eq!(tokens["full"], true);
    assert_eq!(tokens["range"], true);
    assert_eq!(
        tokens["legend"]["tokenTypes"],
        json!([
            "team",
            "robot",
            "robotType",
            "capability",
            "plan",
            "service",
            "mode",
            "event",
            "function",
            "variable",
            "value",
            "constant",
            "group",
            "parameter"
        ])
    );
    assert_eq!(
        tokens["legend"]["tokenModifiers"],
        json!(["declaration", "defaultLibrary"])
    );
    client.shutdown().await;
}
