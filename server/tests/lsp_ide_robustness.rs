//! Completion, hover, signature help, inlay hints and code actions never fail
//! on any text at any position: syntax errors, half-typed lines, Unicode,
//! empty files, positions past the end of a line or of the text. Every
//! request at every position of these texts gets an answer, not an error.

mod support;

use serde_json::{Value, json};
use support::ide::{Session, positions_past_the_end};
use support::position_of;

const TEXTS: &[&str] = &[
    "",
    "\n\n",
    "{",
    "}",
    "[[",
    "T.",
    "T.P.",
    "set(",
    "Team.main{ case (",
    "{ T: iRobotCreate r, ",
    "{ T: iRobotCreate r }\nT.Action.Go{\n  move(\n  [[ group(instance of \n} repeat(",
    "{ T: iRobotCreate r }\nT.Action.Go{ if(T. } \nT.M{ set(Action, \nT.main{ case (M): catch (",
    "# 한국어 😀\n{ 팀: iRobotCreate 로봇 }\nT.Action.Go{ move(\"😀\", ) throw \"x }\n",
    "def f { f() }\ndef g { [[ leader(capable of ) { others } ]] }\n",
    "T.Action.Go{ send(, ) receive(USER, USER.) publish(T, T.X = ) subscribe( }\n",
    "{ A: Turtlebot3_Burger a[0], Ev3_Robot e[99999999999] }\nA.main{ default: mode = }\n",
];

fn positions(text: &str) -> Vec<Value> {
    let mut out: Vec<Value> = text
        .char_indices()
        .map(|(i, _)| position_of(text, i))
        .collect();
    out.extend(positions_past_the_end(text));
    out.push(json!({ "line": 0, "character": 9999 }));
    out
}

#[test]
fn every_request_at_every_position_answers() {
    let mut session = Session::new();
    for text in TEXTS {
        let doc = session.open("robust.mission", text);
        for position in positions(text) {
            for method in [
                "textDocument/completion",
                "textDocument/hover",
                "textDocument/signatureHelp",
            ] {
                let params = json!({ "textDocument": { "uri": doc.uri }, "position": position });
                if let Err(e) = session.request(method, params) {
                    panic!("{method} at {position} of {text:?}: {e}");
                }
            }
            let range = json!({ "start": { "line": 0, "character": 0 }, "end": position });
            let params = json!({ "textDocument": { "uri": doc.uri }, "range": range });
            if let Err(e) = session.request("textDocument/inlayHint", params) {
                panic!("inlayHint to {position} of {text:?}: {e}");
            }
            let range = json!({ "start": position, "end": position });
            let params = json!({
                "textDocument": { "uri": doc.uri },
                "range": range,
                "context": { "diagnostics": doc.diagnostics },
            });
            if let Err(e) = session.request("textDocument/codeAction", params) {
                panic!("codeAction at {position} of {text:?}: {e}");
            }
        }
    }
    assert!(session.client.server_is_running());
    session.shutdown();
}

/// Strategy files being typed: unterminated tags, quotes and comments, raw
/// `<` and `&`, Unicode, unknown elements.
const STRATEGY_TEXTS: &[&str] = &[
    "",
    "<",
    "</",
    "<Strategy",
    "<Strategy name=\"",
    "<Strategy name='T'><ServiceInfo><Service name=\"mo",
    "<?xml version=\"1.0\"?>\n<!-- <Strategy> \n",
    "<Strategy name=\"MasterTeam\">\n<ServiceInfo>\n<Service plan_name=\"Action\" name=\"move\">\n<ActionInfo>\n<Action name=\"A\" actionId=\"x\" initial=\"Yes\">\n<TransitionInfo><Transition srcId=\"0\" dstId=\"\"><Condition cond=\"a<2 & b>\"/></Transition>\n</Action></ActionInfo></Service>\n",
    "<Strategy name=\"팀😀\"><ValueInfo><Value name=\"😀\"><TargetRobot name=\"로봇\"/></Value></ValueInfo></Strategy>",
    "<Strategy name=\"MasterTeam\"><Bogus><Service/></Bogus></Strategy></Strategy></",
    "<<<>>>\"\"''<![CDATA[ <x> ]]><x y=z/>",
];

#[test]
fn every_strategy_request_at_every_position_answers() {
    let mut session = Session::new();
    let scouting = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/scouting/scouting.mission");
    let mission = std::fs::read_to_string(scouting).expect("the scouting mission");
    session.open("scouting.mission", &mission);
    for text in STRATEGY_TEXTS {
        let doc = session.open("robust.strategy.xml", text);
        let params = json!({ "textDocument": { "uri": doc.uri } });
        if let Err(e) = session.request("textDocument/documentSymbol", params) {
            panic!("documentSymbol of {text:?}: {e}");
        }
        for position in positions(text) {
            for method in [
                "textDocument/completion",
                "textDocument/hover",
                "textDocument/definition",
            ] {
                let params = json!({ "textDocument": { "uri": doc.uri }, "position": position });
                if let Err(e) = session.request(method, params) {
                    panic!("{method} at {position} of {text:?}: {e}");
                }
            }
            let params = json!({
                "textDocument": { "uri": doc.uri },
                "position": position,
                "context": { "includeDeclaration": true },
            });
            if let Err(e) = session.request("textDocument/references", params) {
                panic!("references at {position} of {text:?}: {e}");
            }
            let range = json!({ "start": position, "end": position });
            let params = json!({
                "textDocument": { "uri": doc.uri },
                "range": range,
                "context": { "diagnostics": doc.diagnostics },
            });
            if let Err(e) = session.request("textDocument/codeAction", params) {
                panic!("codeAction at {position} of {text:?}: {e}");
            }
        }
    }
    assert!(session.client.server_is_running());
    session.shutdown();
}

/// Requests about a document the server does not know are errors, not crashes.
#[test]
fn unknown_documents_are_an_error() {
    let mut session = Session::new();
    let params = json!({
        "textDocument": { "uri": "file:///nowhere.mission" },
        "position": { "line": 0, "character": 0 }
    });
    assert!(
        session
            .request("textDocument/completion", params.clone())
            .is_err()
    );
    assert!(session.request("textDocument/hover", params).is_err());
    assert!(session.client.server_is_running());
    session.shutdown();
}

/// Catalog files are not missions: nothing to complete or hover there.
#[test]
fn catalog_files_have_no_mission_features() {
    let mut session = Session::new();
    let doc = session.open(
        "bots.robot.xml",
        "<Catalog><Robot type=\"MyBot\"/></Catalog>\n",
    );
    let position = json!({ "line": 0, "character": 12 });
    for method in [
        "textDocument/completion",
        "textDocument/hover",
        "textDocument/signatureHelp",
    ] {
        assert_eq!(session.at(method, &doc, &position), Value::Null, "{method}");
    }
    session.shutdown();
}
