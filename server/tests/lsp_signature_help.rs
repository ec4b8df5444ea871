//! Signature help through the protocol. Each fixture in
//! `fixtures/signature_help/` holds a mission with `$0` cursors; the snapshot
//! shows, for each, the signature with the active parameter in `«»`, and its
//! documentation.

mod support;

use serde_json::Value;
use support::ide::{Session, render_cursors};

/// The label with the active parameter marked, from UTF-16 label offsets.
fn marked(signature: &Value, active: Option<u64>) -> String {
    let label = signature["label"].as_str().unwrap();
    let Some(active) = active else {
        return label.to_string();
    };
    let param = &signature["parameters"][active as usize]["label"];
    let units: Vec<u16> = label.encode_utf16().collect();
    let (start, end) = (
        param[0].as_u64().unwrap() as usize,
        param[1].as_u64().unwrap() as usize,
    );
    format!(
        "{}«{}»{}",
        String::from_utf16_lossy(&units[..start]),
        String::from_utf16_lossy(&units[start..end]),
        String::from_utf16_lossy(&units[end..])
    )
}

fn render(session: &mut Session, doc: &support::ide::Doc) -> String {
    render_cursors(session, doc, "textDocument/signatureHelp", |result| {
        if result.is_null() {
            return None;
        }
        let signature = &result["signatures"][0];
        assert_eq!(result["activeSignature"], 0);
        let active = result["activeParameter"].as_u64();
        let mut out = format!("    {}\n", marked(signature, active));
        if let Some(doc) = signature["documentation"]["value"].as_str() {
            out.push_str(&format!("    {doc}\n"));
        }
        out.push('\n');
        Some(out)
    })
}

#[test]
fn signature_help_fixtures() {
    snapshot_fixtures!(
        "fixtures/signature_help/*.mission",
        cursors,
        "a fixture needs a $0 cursor",
        render
    );
}
