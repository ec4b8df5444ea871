//! Protocol results as readable text, for snapshots: every range is shown in
//! its line, marked `‹…›`, every cursor as `│`. Positions are UTF-16 (the
//! clients of these tests offer only UTF-16) and shown one-based.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// A runtime for the fixture tests, whose `insta::glob!` bodies are not async.
pub fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a runtime")
}

/// The byte offset of a UTF-16 position (clamped to its line).
pub fn offset_at(text: &str, pos: &Value) -> usize {
    let line = pos["line"].as_u64().expect("a line") as usize;
    let col = pos["character"].as_u64().expect("a character") as usize;
    let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
    let line_text = text[start.min(text.len())..]
        .split('\n')
        .next()
        .unwrap_or("");
    let mut units = 0;
    for (i, ch) in line_text.char_indices() {
        if units >= col {
            return start + i;
        }
        units += ch.len_utf16();
    }
    start + line_text.len()
}

/// The line holding byte `offset`: its one-based number, start and text.
fn line_of(text: &str, offset: usize) -> (usize, usize, &str) {
    let start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    (
        text[..offset].matches('\n').count() + 1,
        start,
        &text[start..end],
    )
}

/// `L:C  the line with ‹the range›`; a range over several lines shows its
/// first line and how many lines it spans.
pub fn range(text: &str, range: &Value) -> String {
    let (a, b) = (
        offset_at(text, &range["start"]),
        offset_at(text, &range["end"]),
    );
    let (line, start, content) = line_of(text, a);
    let col = text[start..a].encode_utf16().count() + 1;
    let line_end = start + content.len();
    if b <= line_end {
        let marked = format!(
            "{}‹{}›{}",
            &content[..a - start],
            &text[a..b],
            &content[b - start..]
        );
        format!("{line}:{col}  {}", marked.trim())
    } else {
        let last = text[..b].matches('\n').count() + 1;
        let marked = format!("{}‹{}…", &content[..a - start], &content[a - start..]);
        format!(
            "{line}:{col}  {} ({} lines)",
            marked.trim(),
            last - line + 1
        )
    }
}

/// `L:C  the line with │ at the cursor`.
pub fn cursor(text: &str, pos: &Value) -> String {
    let a = offset_at(text, pos);
    let (line, start, content) = line_of(text, a);
    let col = text[start..a].encode_utf16().count() + 1;
    let marked = format!("{}│{}", &content[..a - start], &content[a - start..]);
    format!("{line}:{col}  {}", marked.trim())
}

/// A result that is `null`, one object or a list, as a list.
pub fn list(result: Value) -> Vec<Value> {
    match result {
        Value::Null => Vec::new(),
        Value::Array(items) => items,
        one => vec![one],
    }
}

/// `{ textDocument, position }`.
pub fn at(uri: &str, pos: &Value) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": pos })
}

/// The fixture folder of this package's tests.
pub fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// A fixture's `# key: value` header line, if any.
pub fn header<'a>(text: &'a str, key: &str) -> Option<&'a str> {
    let prefix = format!("# {key}:");
    text.lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .map(str::trim)
}

/// The `file:` URI of a path.
pub fn file_uri(path: &Path) -> String {
    let path = path.canonicalize().expect("an existing path");
    format!("file://{}", path.display())
}
