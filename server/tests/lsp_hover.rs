//! Hover through the protocol. Each fixture in `fixtures/hover/` holds a
//! mission with `$0` cursors; the snapshot shows, for each, the hovered range
//! and the markdown, or that there is nothing to show.

mod support;

use serde_json::json;
use support::ide::{Session, positions_past_the_end, render_cursors};
use support::text_at;

fn render(session: &mut Session, doc: &support::ide::Doc) -> String {
    render_cursors(session, doc, "textDocument/hover", |result| {
        if result.is_null() {
            return None;
        }
        let range = text_at(&doc.text, &result["range"]);
        assert_eq!(result["contents"]["kind"], "markdown");
        let markdown = result["contents"]["value"].as_str().unwrap();
        Some(format!(
            "hovering `{range}`:\n    {}\n\n",
            markdown.replace('\n', "\n    ")
        ))
    })
}

#[test]
fn hover_fixtures() {
    snapshot_fixtures!(
        "fixtures/hover/*.mission",
        cursors,
        "a fixture needs a $0 cursor",
        render
    );
}

/// Past the end of the text, in an empty file and on blank space: no hover,
/// and no error.
#[test]
fn nothing_to_hover() {
    let mut session = Session::new();
    for text in ["", "{ T: iRobotCreate r }\n\n", "T.Action.Go{ mvoe( }"] {
        let doc = session.open("empty.mission", text);
        let mut positions = positions_past_the_end(&doc.text).to_vec();
        positions.push(json!({ "line": 1, "character": 0 }));
        for position in positions {
            let result = session.at("textDocument/hover", &doc, &position);
            assert!(result.is_null(), "{text:?} at {position}: {result}");
        }
    }
    session.shutdown();
}
