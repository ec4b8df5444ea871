//! Quick fixes through the protocol. Each fixture in `fixtures/code_actions/`
//! is a mission with diagnostics. For every diagnostic, the code actions at
//! its range are requested with it as context; every action is applied to the
//! text, and the result checked again from scratch: the diagnostic it fixes
//! must be gone, and no error may appear. The snapshot lists each diagnostic,
//! its fixes with the lines they change, and what the check says after.

mod support;

use serde_json::{Value, json};
use std::collections::HashMap;
use support::ide::{Session, apply_edits, diff, listing};

fn count_by_code(diagnostics: &[Value]) -> HashMap<String, usize> {
    let mut counts = HashMap::new();
    for d in diagnostics {
        *counts
            .entry(d["code"].as_str().unwrap().to_string())
            .or_default() += 1;
    }
    counts
}

fn code_actions(session: &mut Session, uri: &str, diagnostic: &Value) -> Vec<Value> {
    let params = json!({
        "textDocument": { "uri": uri },
        "range": diagnostic["range"],
        "context": { "diagnostics": [diagnostic] },
    });
    session
        .request("textDocument/codeAction", params)
        .expect("code actions")
        .as_array()
        .cloned()
        .unwrap_or_default()
}

fn render(session: &mut Session, doc: &support::ide::Doc) -> String {
    let mut out = String::new();
    let before = count_by_code(&doc.diagnostics);
    for d in &doc.diagnostics {
        out.push_str(&listing(std::slice::from_ref(d)));
        out.push('\n');
        let code = d["code"].as_str().unwrap();
        let actions = code_actions(session, &doc.uri, d);
        if actions.is_empty() {
            out.push_str("  (no fix)\n");
        }
        for action in &actions {
            assert_eq!(action["kind"], "quickfix");
            // Attached to the diagnostic it fixes, as the client sent it.
            assert_eq!(action["diagnostics"], json!([d]));
            let edits = action["edit"]["changes"][&doc.uri]
                .as_array()
                .expect("edits of this document");
            let fixed = apply_edits(&doc.text, edits);
            let preferred = if action["isPreferred"] == true {
                " (preferred)"
            } else {
                ""
            };
            out.push_str(&format!(
                "  → {}{preferred}\n",
                action["title"].as_str().unwrap()
            ));
            out.push_str(&diff(&doc.text, &fixed));
            let after = session.check(&fixed);
            let counts = count_by_code(&after);
            assert!(
                counts.get(code).copied().unwrap_or(0) < before[code],
                "`{}` leaves {code}:\n{fixed}\n{}",
                action["title"],
                listing(&after)
            );
            for (c, n) in &counts {
                if c.starts_with('E') {
                    assert!(
                        *n <= before.get(c).copied().unwrap_or(0),
                        "`{}` adds {c}:\n{}",
                        action["title"],
                        listing(&after)
                    );
                }
            }
            let left = if after.is_empty() {
                "nothing".to_string()
            } else {
                listing(&after).replace('\n', "\n          ")
            };
            out.push_str(&format!("    then: {left}\n"));
        }
        out.push('\n');
    }
    out
}

#[test]
fn code_action_fixtures() {
    snapshot_fixtures!(
        "fixtures/code_actions/*.mission",
        diagnostics,
        "a fixture needs diagnostics",
        render
    );
}

/// A client that asks for other kinds of actions gets no quick fixes; one
/// that sends no diagnostics still gets them (from the server's own), and a
/// range without diagnostics gets nothing.
#[test]
fn kinds_and_ranges() {
    let mut session = Session::new();
    let doc = session.open(
        "kinds.mission",
        "{ T: iRobotCreate r }\nT.Action.Go{ mvoe() } repeat()\nT.M{ set(Action, Go) }\nT.main{ default: mode = M }\n",
    );
    let d = doc.diagnostics[0].clone();
    let ask = |session: &mut Session, range: Value, only: Option<&str>, diags: Value| {
        let mut context = json!({ "diagnostics": diags });
        if let Some(kind) = only {
            context["only"] = json!([kind]);
        }
        let params =
            json!({ "textDocument": { "uri": doc.uri }, "range": range, "context": context });
        session
            .request("textDocument/codeAction", params)
            .unwrap()
            .as_array()
            .cloned()
            .unwrap_or_default()
    };
    assert!(
        ask(
            &mut session,
            d["range"].clone(),
            Some("refactor"),
            json!([d])
        )
        .is_empty()
    );
    assert_eq!(
        ask(
            &mut session,
            d["range"].clone(),
            Some("quickfix"),
            json!([d])
        )
        .len(),
        1
    );
    let without_context = ask(&mut session, d["range"].clone(), None, json!([]));
    assert_eq!(without_context.len(), 1);
    assert_eq!(without_context[0]["diagnostics"], json!([d]));
    let elsewhere =
        json!({ "start": { "line": 3, "character": 0 }, "end": { "line": 3, "character": 1 } });
    assert!(ask(&mut session, elsewhere, None, json!([])).is_empty());
    session.shutdown();
}
