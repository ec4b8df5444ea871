//! For the protocol tests of the editor features: one server for a whole
//! test, fixtures with `$0` cursors opened as documents, edits applied as an
//! editor would, and results rendered as readable text for snapshots.

use super::{cursors, position_of, text_at};
use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::Path;

/// A client and the runtime it runs on, for tests driven by `insta::glob!`
/// (whose closure is not async).
pub struct Session {
    runtime: tokio::runtime::Runtime,
    pub client: TestClient,
    opened: usize,
    /// The file names opened so far.
    names: std::collections::HashSet<String>,
}

/// A document opened from a fixture.
pub struct Doc {
    pub uri: String,
    /// The text without its `$0` markers.
    pub text: String,
    /// The positions of the markers, in order.
    pub cursors: Vec<Value>,
    /// The diagnostics published when it was opened.
    pub diagnostics: Vec<Value>,
}

/// The workspace root of a session (no folder on disk: nothing is indexed).
const ROOT: &str = "file:///fixtures";

impl Session {
    /// A server initialized with UTF-16 positions and snippet support.
    pub fn new() -> Session {
        Session::with_capabilities(None)
    }

    /// A server initialized with these client capabilities (the harness's
    /// default ones when `None`).
    pub fn with_capabilities(capabilities: Option<Value>) -> Session {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .expect("a runtime");
        let client = runtime.block_on(async {
            let mut client = TestClient::start();
            match capabilities {
                Some(caps) => client.initialize_with(caps, Some(ROOT)).await,
                None => client.initialize(&["utf-16"], Some(ROOT)).await,
            };
            client
        });
        Session {
            runtime,
            client,
            opened: 0,
            names: std::collections::HashSet::new(),
        }
    }

    /// Opens `text` (with `$0` markers) as a new document and waits for its
    /// diagnostics, so that its analysis is ready.
    pub fn open(&mut self, name: &str, text: &str) -> Doc {
        self.opened += 1;
        // The documents of a session are one workspace: one folder, where
        // every file sees the others (a name opened again goes into a folder
        // below, which still sees the files above it: the root is /fixtures).
        let uri = if self.names.insert(name.to_string()) {
            format!("file:///fixtures/{name}")
        } else {
            format!("file:///fixtures/{}/{name}", self.opened)
        };
        self.open_uri(&uri, text)
    }

    /// Opens `text` (with `$0` markers) at `uri` and waits for its diagnostics.
    pub fn open_uri(&mut self, uri: &str, text: &str) -> Doc {
        let (clean, cursors) = cursors(text);
        let diagnostics = self.runtime.block_on(async {
            self.client.open(uri, &clean).await;
            self.client.diagnostics(uri, Some(1)).await
        });
        Doc {
            uri: uri.to_string(),
            text: clean,
            cursors,
            diagnostics,
        }
    }

    /// Replaces the text of an open document (as version `version`) and
    /// waits for its diagnostics.
    pub fn replace(&mut self, doc: &Doc, version: i64, text: &str) -> Vec<Value> {
        let params = serde_json::json!({
            "textDocument": { "uri": doc.uri, "version": version },
            "contentChanges": [{ "text": text }]
        });
        self.runtime.block_on(async {
            self.client.notify("textDocument/didChange", params).await;
            self.client.diagnostics(&doc.uri, Some(version)).await
        })
    }

    /// Opens a fixture file.
    pub fn open_fixture(&mut self, path: &Path) -> Doc {
        let text = std::fs::read_to_string(path).expect("fixture");
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        self.open(&name, &text)
    }

    pub fn notify(&mut self, method: &str, params: Value) {
        self.runtime.block_on(self.client.notify(method, params));
    }

    pub fn request(&mut self, method: &str, params: Value) -> Result<Value, Value> {
        self.runtime.block_on(self.client.request(method, params))
    }

    /// The diagnostics published for `version` of `uri`.
    pub fn diagnostics(&mut self, uri: &str, version: i64) -> Vec<Value> {
        self.runtime
            .block_on(self.client.diagnostics(uri, Some(version)))
    }

    /// A request at a position of a document, which must succeed.
    pub fn at(&mut self, method: &str, doc: &Doc, position: &Value) -> Value {
        let params = json!({ "textDocument": { "uri": doc.uri }, "position": position });
        self.request(method, params)
            .unwrap_or_else(|e| panic!("{method} failed: {e}"))
    }

    /// The diagnostics of `text` checked from scratch in a new document.
    pub fn check(&mut self, text: &str) -> Vec<Value> {
        self.open("check.mission", text).diagnostics
    }

    pub fn shutdown(self) {
        let Session {
            runtime, client, ..
        } = self;
        runtime.block_on(client.shutdown());
    }
}

/// Snapshots `render(&mut session, &doc)` for each fixture matching `glob`
/// (relative to the calling test file), opened as a document in one session;
/// `needs` is what a fixture must have (`cursors`, `diagnostics`), with the
/// message when it has none. A macro, so that `insta` names the snapshots
/// after the calling test.
#[macro_export]
macro_rules! snapshot_fixtures {
    ($glob:literal, $needs:ident, $message:literal, $render:expr) => {{
        let mut session = $crate::support::ide::Session::new();
        insta::glob!($glob, |path| {
            let doc = session.open_fixture(path);
            assert!(!doc.$needs.is_empty(), $message);
            insta::assert_snapshot!($render(&mut session, &doc));
        });
        session.shutdown();
    }};
}

/// For each cursor of `doc`: the line with the cursor, then what `render`
/// makes of the result of `method` there, or `(nothing)` when it gives `None`.
pub fn render_cursors(
    session: &mut Session,
    doc: &Doc,
    method: &str,
    mut render: impl FnMut(&Value) -> Option<String>,
) -> String {
    let mut out = String::new();
    for position in &doc.cursors {
        let result = session.at(method, doc, position);
        out.push_str(&show_position(&doc.text, position));
        out.push('\n');
        match render(&result) {
            Some(shown) => out.push_str(&shown),
            None => out.push_str("(nothing)\n\n"),
        }
    }
    out
}

/// Where a position is, for a reader: the line with `$0` at the position.
pub fn show_position(text: &str, position: &Value) -> String {
    let line = position["line"].as_u64().unwrap() as usize;
    let line_text = text.split('\n').nth(line).unwrap_or("");
    let start = json!({ "line": line, "character": 0 });
    let before = text_at(text, &json!({ "start": start, "end": position }));
    format!(
        "{:>3} | {before}$0{}",
        line + 1,
        &line_text[before.len().min(line_text.len())..]
    )
}

/// Byte offset of an LSP (UTF-16) position.
pub fn offset_of(text: &str, position: &Value) -> usize {
    let start = json!({ "line": 0, "character": 0 });
    let before = text_at(text, &json!({ "start": start, "end": position }));
    // `text_at` gives the text between the two positions: its length is the offset.
    before.len()
}

/// The text after applying LSP text edits (non-overlapping, any order).
pub fn apply_edits(text: &str, edits: &[Value]) -> String {
    let mut spans: Vec<(usize, usize, String)> = edits
        .iter()
        .map(|e| {
            (
                offset_of(text, &e["range"]["start"]),
                offset_of(text, &e["range"]["end"]),
                e["newText"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    spans.sort_by_key(|(start, _, _)| std::cmp::Reverse(*start));
    let mut out = text.to_string();
    for (start, end, new_text) in spans {
        out.replace_range(start..end, &new_text);
    }
    out
}

/// The position right after the end of `text`, and one far beyond it.
pub fn positions_past_the_end(text: &str) -> [Value; 2] {
    [
        position_of(text, text.len()),
        json!({ "line": 9999, "character": 9999 }),
    ]
}

/// `code message` lines for diagnostics.
pub fn listing(diagnostics: &[Value]) -> String {
    diagnostics
        .iter()
        .map(|d| {
            format!(
                "{}:{} {} {}",
                d["range"]["start"]["line"].as_u64().unwrap() + 1,
                d["range"]["start"]["character"].as_u64().unwrap() + 1,
                d["code"].as_str().unwrap_or("?"),
                d["message"].as_str().unwrap_or("")
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The lines that differ between two texts: the old ones with `-`, the new
/// ones with `+` (between the common first and last lines).
pub fn diff(old: &str, new: &str) -> String {
    let a: Vec<&str> = old.lines().collect();
    let b: Vec<&str> = new.lines().collect();
    let prefix = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let suffix = a[prefix..]
        .iter()
        .rev()
        .zip(b[prefix..].iter().rev())
        .take_while(|(x, y)| x == y)
        .count();
    let mut out = String::new();
    for line in &a[prefix..a.len() - suffix] {
        out.push_str(&format!("      - {line}\n"));
    }
    for line in &b[prefix..b.len() - suffix] {
        out.push_str(&format!("      + {line}\n"));
    }
    out
}
