//! `textDocument/formatting` gives the layout `semo fmt` writes, as an edit of
//! the changed lines only, and refuses a mission with syntax errors.

mod support;

use serde_json::json;

fn apply(text: &str, edit: &serde_json::Value) -> String {
    let range = &edit["range"];
    let covered = support::text_at(text, range);
    // The edit covers whole lines, so locating it by its start line is exact.
    let start_line = range["start"]["line"].as_u64().unwrap() as usize;
    let start: usize = text
        .split_inclusive('\n')
        .take(start_line)
        .map(str::len)
        .sum();
    let mut out = text.to_string();
    out.replace_range(
        start..start + covered.len(),
        edit["newText"].as_str().unwrap(),
    );
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn formatting_gives_the_canonical_layout_and_refuses_broken_text() {
    let messy = "{\n  T: iRobotCreate a\n}\n\nT.Action.Go {\n  move(\"1,1\")   # go\n      stop()\n} repeat()\n\nT.GO {\n  set(Action,Go)\n}\n\nT.main {\n  default: mode = GO\n}\n";
    let uri = "file:///f/messy.mission";
    let mut client = support::client_with(uri, messy).await;
    let params = json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 2, "insertSpaces": true } });
    let edits = client
        .request("textDocument/formatting", params.clone())
        .await
        .unwrap();
    let edits = edits.as_array().unwrap();
    assert_eq!(edits.len(), 1);
    let formatted = apply(messy, &edits[0]);
    assert_eq!(formatted, semo::format::format_source(messy).unwrap());
    // Only the body of Go and the set line changed: the edit starts at `move`.
    assert_eq!(edits[0]["range"]["start"]["line"], 5);

    // Broken text is refused with the reason; nothing is rewritten.
    client
        .notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": "T.Action.Go { move(" }] }),
        )
        .await;
    let err = client
        .request("textDocument/formatting", params)
        .await
        .unwrap_err();
    assert!(
        err["message"]
            .as_str()
            .unwrap()
            .starts_with("not formatted"),
        "{err}"
    );
    client.shutdown().await;
}
