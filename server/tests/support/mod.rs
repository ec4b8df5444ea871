//! Shared by the protocol tests: cursor markers in fixtures, and a client with
//! one document open.
#![allow(dead_code)] // each test file uses its own part

pub mod broker;
pub mod render;

use semo_server::harness::TestClient;
use serde_json::{Value, json};

/// The cursor marker in fixture texts.
pub const CURSOR: &str = "$0";

/// Removes every `$0` from `text`, giving the text and the (UTF-16) LSP
/// positions of the markers in order.
pub fn cursors(text: &str) -> (String, Vec<Value>) {
    let mut clean = String::with_capacity(text.len());
    let mut positions = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find(CURSOR) {
        clean.push_str(&rest[..i]);
        positions.push(position_of(&clean, clean.len()));
        rest = &rest[i + CURSOR.len()..];
    }
    clean.push_str(rest);
    (clean, positions)
}

/// The UTF-16 position of byte `offset` in `text`.
pub fn position_of(text: &str, offset: usize) -> Value {
    let before = &text[..offset];
    let line = before.matches('\n').count();
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    json!({ "line": line, "character": before[line_start..].encode_utf16().count() })
}

/// The text a range covers (UTF-16 positions), to print results readably.
pub fn text_at(text: &str, range: &Value) -> String {
    let offset = |p: &Value| {
        let line = p["line"].as_u64().unwrap() as usize;
        let col = p["character"].as_u64().unwrap() as usize;
        let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
        let line_text = text[start..].split('\n').next().unwrap_or("");
        let mut units = 0;
        for (i, ch) in line_text.char_indices() {
            if units >= col {
                return start + i;
            }
            units += ch.len_utf16();
        }
        start + line_text.len()
    };
    text[offset(&range["start"])..offset(&range["end"])].to_string()
}

/// A client, initialized (UTF-16), with `text` open as `uri`; its first
/// diagnostics have been published, so analysis results are ready.
pub async fn client_with(uri: &str, text: &str) -> TestClient {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    client.open(uri, text).await;
    client.diagnostics(uri, Some(1)).await;
    client
}

pub mod ide;
