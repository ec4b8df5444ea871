//! Inlay hints through the protocol. Each fixture in `fixtures/inlay_hints/`
//! is a mission; the snapshot is its text with the hints of the whole
//! document written in at their places, as `⟨hint⟩`.

mod support;

use serde_json::{Value, json};
use support::ide::{Session, offset_of, positions_past_the_end};

fn hints(session: &mut Session, uri: &str, range: Value) -> Vec<Value> {
    let params = json!({ "textDocument": { "uri": uri }, "range": range });
    session
        .request("textDocument/inlayHint", params)
        .expect("inlay hints")
        .as_array()
        .cloned()
        .unwrap_or_default()
}

/// The text with each hint's label inserted at its position.
fn render(text: &str, hints: &[Value]) -> String {
    let mut at: Vec<(usize, String)> = hints
        .iter()
        .map(|h| {
            (
                offset_of(text, &h["position"]),
                h["label"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    at.sort_by_key(|(offset, _)| std::cmp::Reverse(*offset));
    let mut out = text.to_string();
    for (offset, label) in at {
        out.insert_str(offset, &format!("⟨{label}⟩"));
    }
    out
}

#[test]
fn inlay_hint_fixtures() {
    let mut session = Session::new();
    insta::glob!("fixtures/inlay_hints/*.mission", |path| {
        let doc = session.open_fixture(path);
        let [end, _] = positions_past_the_end(&doc.text);
        let all = hints(
            &mut session,
            &doc.uri,
            json!({ "start": { "line": 0, "character": 0 }, "end": end }),
        );
        for h in &all {
            assert!(h["tooltip"]["value"].is_string(), "{h}");
        }
        insta::assert_snapshot!(render(&doc.text, &all));
    });
    session.shutdown();
}

/// Only the hints inside the requested range are given.
#[test]
fn hints_of_a_range_only() {
    let mut session = Session::new();
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/inlay_hints/groups_and_modes.mission"),
    )
    .unwrap();
    let doc = session.open("range.mission", &text);
    let [end, _] = positions_past_the_end(&doc.text);
    let all = hints(
        &mut session,
        &doc.uri,
        json!({ "start": { "line": 0, "character": 0 }, "end": end }),
    );
    assert!(all.len() >= 4, "{all:#?}");
    let line = all[1]["position"]["line"].clone();
    let one_line = hints(
        &mut session,
        &doc.uri,
        json!({ "start": { "line": line, "character": 0 }, "end": { "line": line, "character": 999 } }),
    );
    assert_eq!(one_line, vec![all[1].clone()]);
    let nothing = hints(
        &mut session,
        &doc.uri,
        json!({ "start": { "line": 9999, "character": 0 }, "end": { "line": 9999, "character": 1 } }),
    );
    assert!(nothing.is_empty());
    session.shutdown();
}
