//! Strategy files in the editor, next to the scouting mission they refine:
//! completion (element names by parent, missing attributes, values from the
//! mission and the catalog, on half-typed text), hover, navigation between
//! strategy entries and mission calls, the outline, and fixes, each applied
//! and checked again. And the catalog: a changed `*.robot.xml` is seen by
//! completion in an open mission at once.

mod support;

use serde_json::{Value, json};
use std::path::Path;
use support::ide::{Doc, Session, apply_edits, diff, listing, render_cursors};
use support::render;
use support::text_at;

fn scouting(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/scouting")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A session with the scouting mission open (marked with `$0` cursors when
/// `mission` says so): strategy files opened next are checked against it.
fn session_with_mission(mission: &str) -> (Session, Doc) {
    let mut session = Session::new();
    let doc = session.open("scouting.mission", mission);
    (session, doc)
}

/// `file:line  the line with ‹range›` for each location of a result.
fn locations(result: Value, texts: &[(&str, &str)]) -> String {
    let mut out = String::new();
    for location in render::list(result) {
        let uri = location["uri"].as_str().unwrap();
        let (name, text) = texts
            .iter()
            .find(|(u, _)| *u == uri)
            .unwrap_or_else(|| panic!("a location in an unknown file: {uri}"));
        let name = name.rsplit('/').next().unwrap();
        out.push_str(&format!(
            "  {name} {}\n",
            render::range(text, &location["range"])
        ));
    }
    if out.is_empty() {
        out.push_str("  (nothing)\n");
    }
    out
}

fn completion_render(session: &mut Session, doc: &Doc) -> String {
    render_cursors(session, doc, "textDocument/completion", |result| {
        let items = result["items"].as_array().cloned().unwrap_or_default();
        if items.is_empty() {
            return None;
        }
        let replaced = text_at(&doc.text, &items[0]["textEdit"]["range"]);
        let mut out = format!("replacing `{replaced}`:\n");
        for item in &items {
            let label = item["label"].as_str().unwrap();
            let insert = item["textEdit"]["newText"].as_str().unwrap();
            let mut line = format!("  {label:<20} {}", item["detail"].as_str().unwrap_or(""));
            if insert != label {
                line.push_str(&format!("  ⇒ {}", insert.replace('\n', "⏎")));
            }
            out.push_str(line.trim_end());
            out.push('\n');
            assert_eq!(item["textEdit"]["range"], items[0]["textEdit"]["range"]);
        }
        out.push('\n');
        Some(out)
    })
}

#[test]
fn completion_in_strategy_files() {
    let (mut session, _) = session_with_mission(&scouting("scouting.mission"));
    insta::glob!("fixtures/strategy/completion/*.strategy.xml", |path| {
        let doc = session.open_fixture(path);
        assert!(
            !doc.cursors.is_empty(),
            "a completion fixture needs `$0` cursors"
        );
        insta::assert_snapshot!(completion_render(&mut session, &doc));
    });
    session.shutdown();
}

#[test]
fn hover_in_strategy_files() {
    let (mut session, _) = session_with_mission(&scouting("scouting.mission"));
    insta::glob!("fixtures/strategy/hover/*.strategy.xml", |path| {
        let doc = session.open_fixture(path);
        assert!(
            !doc.cursors.is_empty(),
            "a hover fixture needs `$0` cursors"
        );
        let shown = render_cursors(&mut session, &doc, "textDocument/hover", |result| {
            let md = result["contents"]["value"].as_str()?;
            let on = text_at(&doc.text, &result["range"]);
            Some(format!(
                "on `{on}`:\n    {}\n\n",
                md.replace('\n', "\n    ")
            ))
        });
        insta::assert_snapshot!(shown);
    });
    session.shutdown();
}

/// From strategy entries to the mission lines they refine and read, from a
/// mission call to its entry (then the catalog), and references.
#[test]
fn navigation_between_strategy_entries_and_mission_calls() {
    let mission = scouting("scouting.mission")
        .replacen("  move(\"5,5\")", "  mo$0ve(\"5,5\")", 1)
        .replacen("  standby()", "  stand$0by()", 1);
    let (mut session, mission) = session_with_mission(&mission);
    let strategy = scouting("MasterTeam.strategy.xml")
        .replacen(
            "<Strategy name=\"MasterTeam\"",
            "<Strategy name=\"Master$0Team\"",
            1,
        )
        .replacen(
            "<Value name=\"LOCATION\">",
            "<Value name=\"LOC$0ATION\">",
            1,
        )
        .replacen(
            "<Service plan_name=\"Action\" name=\"move\">",
            "<Service plan_name=\"Act$0ion\" name=\"mo$0ve\">",
            1,
        );
    let strategy = session.open("MasterTeam.strategy.xml", &strategy);
    let texts = [
        (mission.uri.as_str(), mission.text.as_str()),
        (strategy.uri.as_str(), strategy.text.as_str()),
    ];
    let mut out = String::new();
    for (doc, cursor) in [&mission, &strategy]
        .into_iter()
        .flat_map(|d| d.cursors.iter().map(move |c| (d, c)))
    {
        out.push_str(&format!(
            "definition at {}\n",
            render::cursor(&doc.text, cursor)
        ));
        let result = session.at("textDocument/definition", doc, cursor);
        // Built-in catalog targets have no file: only the workspace's are shown.
        let in_workspace: Vec<Value> = render::list(result)
            .into_iter()
            .filter(|l| texts.iter().any(|(u, _)| l["uri"] == *u))
            .collect();
        out.push_str(&locations(Value::Array(in_workspace), &texts));
    }
    let service = &strategy.cursors[3];
    let params = json!({
        "textDocument": { "uri": strategy.uri },
        "position": service,
        "context": { "includeDeclaration": true },
    });
    let result = session.request("textDocument/references", params).unwrap();
    out.push_str(&format!(
        "references at {}\n",
        render::cursor(&strategy.text, service)
    ));
    out.push_str(&locations(result, &texts));
    insta::assert_snapshot!(out);
    session.shutdown();
}

#[test]
fn the_outline_lists_values_services_and_actions() {
    let (mut session, _) = session_with_mission(&scouting("scouting.mission"));
    let doc = session.open(
        "MasterTeam.strategy.xml",
        &scouting("MasterTeam.strategy.xml"),
    );
    let params = json!({ "textDocument": { "uri": doc.uri } });
    let result = session
        .request("textDocument/documentSymbol", params)
        .unwrap();
    fn show(symbols: &Value, depth: usize, text: &str, out: &mut String) {
        for s in symbols.as_array().into_iter().flatten() {
            out.push_str(&format!(
                "{}{} ({}) {}  @ {}\n",
                "  ".repeat(depth),
                s["name"].as_str().unwrap(),
                s["kind"],
                s["detail"].as_str().unwrap_or(""),
                text_at(text, &s["selectionRange"]),
            ));
            show(&s["children"], depth + 1, text, out);
        }
    }
    let mut out = String::new();
    show(&result, 0, &doc.text, &mut out);
    insta::assert_snapshot!(out);
    session.shutdown();
}

fn codes(diagnostics: &[Value]) -> Vec<String> {
    let mut out: Vec<String> = diagnostics
        .iter()
        .map(|d| d["code"].as_str().unwrap_or("?").to_string())
        .collect();
    out.sort();
    out
}

/// Every fix of every diagnostic, applied; the file is checked again: the
/// diagnostic fixed is gone and nothing new appears.
#[test]
fn fixes_in_strategy_files_remove_their_diagnostic() {
    let (mut session, _) = session_with_mission(&scouting("scouting.mission"));
    insta::glob!("fixtures/strategy/code_actions/*.strategy.xml", |path| {
        let doc = session.open_fixture(path);
        let mut version = 0;
        assert!(
            !doc.diagnostics.is_empty(),
            "a fix fixture needs diagnostics"
        );
        let mut out = String::new();
        for d in &doc.diagnostics {
            out.push_str(&listing(std::slice::from_ref(d)));
            out.push('\n');
            let params = json!({
                "textDocument": { "uri": doc.uri },
                "range": d["range"],
                "context": { "diagnostics": [d] },
            });
            let actions = session.request("textDocument/codeAction", params).unwrap();
            let actions = actions.as_array().cloned().unwrap_or_default();
            if actions.is_empty() {
                out.push_str("  (no fix)\n");
            }
            for action in &actions {
                assert_eq!(action["kind"], "quickfix");
                assert_eq!(action["diagnostics"], json!([d]));
                let edits = action["edit"]["changes"][&doc.uri]
                    .as_array()
                    .expect("edits");
                let fixed = apply_edits(&doc.text, edits);
                out.push_str(&format!("  fix: {}\n", action["title"].as_str().unwrap()));
                out.push_str(&diff(&doc.text, &fixed));
                // Checked again as the same file (another file with the
                // same entries would refine them twice), then put back.
                version += 2;
                let after = session.replace(&doc, version, &fixed);
                session.replace(&doc, version + 1, &doc.text);
                let mut expected = codes(&doc.diagnostics);
                let code = d["code"].as_str().unwrap().to_string();
                let i = expected.iter().position(|c| *c == code).unwrap();
                expected.remove(i);
                // Other problems may remain; the fixed one is gone, nothing is new.
                assert!(
                    codes(&after).iter().all(|c| expected.contains(c)),
                    "{}: after the fix: {}",
                    action["title"],
                    listing(&after)
                );
                out.push_str(&format!("    then: {}\n", codes(&after).join(" ")));
            }
        }
        insta::assert_snapshot!(out);
    });
    session.shutdown();
}

/// A mission call that the team's strategy does not refine: an action
/// creates the entry; the new strategy checks clean and the call then leads
/// to it.
#[test]
fn a_missing_entry_is_created_from_the_mission_call() {
    let marked = scouting("scouting.mission").replacen(
        "  process(USER.RC_CMD)",
        "  proc$0ess(USER.RC_CMD)",
        1,
    );
    let (mut session, mission) = session_with_mission(&marked);
    let strategy = session.open(
        "MasterTeam.strategy.xml",
        &scouting("MasterTeam.strategy.xml"),
    );
    assert_eq!(strategy.diagnostics, Vec::<Value>::new());
    let at = &mission.cursors[0];
    let params = json!({
        "textDocument": { "uri": mission.uri },
        "range": { "start": at, "end": at },
        "context": { "diagnostics": [] },
    });
    let actions = session.request("textDocument/codeAction", params).unwrap();
    let create: Vec<&Value> = actions
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["kind"] == "refactor")
        .collect();
    assert_eq!(create.len(), 1, "{actions:#}");
    let edits = create[0]["edit"]["changes"][&strategy.uri]
        .as_array()
        .expect("an edit of the strategy");
    let fixed = apply_edits(&strategy.text, edits);
    let mut out = format!("{}\n", create[0]["title"].as_str().unwrap());
    out.push_str(&diff(&strategy.text, &fixed));

    // The edited strategy is the one the server has: no diagnostic, and
    // the call leads to the new entry.
    session.notify(
        "textDocument/didChange",
        json!({
            "textDocument": { "uri": strategy.uri, "version": 2 },
            "contentChanges": [{ "text": fixed }]
        }),
    );
    let after = session.diagnostics(&strategy.uri, 2);
    assert_eq!(after, Vec::<Value>::new(), "{}", listing(&after));
    let result = session.at("textDocument/definition", &mission, at);
    let first = &render::list(result)[0];
    assert_eq!(first["uri"], json!(strategy.uri));
    out.push_str(&format!(
        "definition: {}\n",
        render::range(&fixed, &first["range"])
    ));
    // Refined now: no second entry is offered.
    let params = json!({
        "textDocument": { "uri": mission.uri },
        "range": { "start": at, "end": at },
        "context": { "diagnostics": [], "only": ["refactor"] },
    });
    assert_eq!(
        session.request("textDocument/codeAction", params).unwrap(),
        json!([])
    );
    insta::assert_snapshot!(out);
    session.shutdown();
}

fn labels(result: &Value) -> Vec<String> {
    result["items"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|i| i["label"].as_str().unwrap().to_string())
        .collect()
}

/// A catalog change reaches completion and hover in an open mission without
/// a restart: through `didChange` of an open catalog file, then through a
/// watched-file event for one on disk.
#[test]
fn catalog_changes_reach_completion_and_hover_in_open_missions() {
    let catalog = |services: &str| {
        format!(
            "<Catalog xmlns=\"urn:semo:catalog:1\">\n  <Robot type=\"Rover\">\n    {services}\n  </Robot>\n</Catalog>\n"
        )
    };
    let mut session = Session::new();
    let robots = session.open(
        "rovers.robot.xml",
        &catalog("<Service name=\"drive\" task=\"wheels\" doc=\"Drive.\"/>"),
    );
    let mission = session.open(
        "rover.mission",
        "{ R: Rover r }\nR.Go.Run{\n  $0\n  sc$0an()\n} repeat()\n",
    );
    let at = |session: &mut Session, i: usize, method: &str| {
        session.at(method, &mission, &mission.cursors[i])
    };
    let before = labels(&at(&mut session, 0, "textDocument/completion"));
    assert!(before.contains(&"drive".to_string()), "{before:?}");
    assert!(!before.contains(&"scan".to_string()), "{before:?}");
    assert_eq!(at(&mut session, 1, "textDocument/hover"), Value::Null);

    session.notify(
        "textDocument/didChange",
        json!({
            "textDocument": { "uri": robots.uri, "version": 2 },
            "contentChanges": [{ "text": catalog("<Service name=\"drive\" task=\"wheels\" doc=\"Drive.\"/>\n    <Service name=\"scan\" task=\"lidar\" doc=\"Sweep the lidar once.\"/>") }]
        }),
    );
    let after = labels(&at(&mut session, 0, "textDocument/completion"));
    assert!(after.contains(&"scan".to_string()), "{after:?}");
    let hover = at(&mut session, 1, "textDocument/hover");
    let md = hover["contents"]["value"].as_str().unwrap_or_default();
    assert!(md.contains("Sweep the lidar once."), "{hover:#}");

    // A catalog file on disk, changed behind the editor's back: a mission
    // using its robot type sees the type's new service.
    // (The mission is in the catalog's folder, so it sees the file.)
    let dir = std::env::temp_dir().join(format!("semo-strategy-lsp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let digger = session.open_uri(
        &format!("file://{}", dir.join("digger.mission").display()),
        "{ D: Digger d }\nD.Go.Run{\n  $0\n} repeat()\n",
    );
    let file = dir.join("diggers.robot.xml");
    let uri = format!("file://{}", file.display());
    let write = |services: &str| {
        let text = format!(
            "<Catalog xmlns=\"urn:semo:catalog:1\"><Robot type=\"Digger\">{services}</Robot></Catalog>"
        );
        std::fs::write(&file, text).unwrap();
    };
    write("");
    session.notify(
        "workspace/didChangeWatchedFiles",
        json!({ "changes": [{ "uri": uri, "type": 1 }] }),
    );
    let before = labels(&session.at("textDocument/completion", &digger, &digger.cursors[0]));
    assert!(!before.contains(&"dig".to_string()), "{before:?}");
    write("<Service name=\"dig\" task=\"arm\" doc=\"Dig.\"/>");
    session.notify(
        "workspace/didChangeWatchedFiles",
        json!({ "changes": [{ "uri": uri, "type": 2 }] }),
    );
    let after = labels(&session.at("textDocument/completion", &digger, &digger.cursors[0]));
    let _ = std::fs::remove_dir_all(&dir);
    assert!(after.contains(&"dig".to_string()), "{after:?}");
    session.shutdown();
}
