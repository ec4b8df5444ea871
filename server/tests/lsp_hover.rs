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

/// A mission that writes every keyword of the language.
const EVERY_KEYWORD: &str = r#"{ G: Turtlebot3_Burger tb[2], Ev3_Robot ev }
def report { send(USER, G.SEEN = true) }
G.Work.Patrol {
  if (not G.SEEN and DISTANCE < 30 or false) report()
  else throw tired
  loop(1 SEC, G.SEEN == true) {
    receive(USER, USER.RC_CMD), timeout = 2 SEC
    publish(G, G.LEVEL = 1)
    subscribe(G, G.LEVEL)
  }
  [[ group(instance of Ev3_Robot) { move("1,1") } others { scatter() } ]]
  [[ leader(capable of led) { light_on() } others { standby() } ]]
  throw tired broadcast
} repeat(1 SEC)
G.PATROL { set(Work, Patrol) }
G.REST { set(Work, OFF) }
G.main {
  case (PATROL):
    catch (tired): mode = REST
  default: mode = PATROL
}
"#;

/// Hovering each keyword of the lexer shows its entry of the language
/// reference (`docs/language/keywords.md`): a keyword added to the lexer
/// fails here until the reference has its entry (and this mission uses it).
#[test]
fn every_keyword_shows_its_entry_of_the_language_reference() {
    use semo::ide::mission::keywords;
    use semo::syntax::token::{Kw, Token, lex};
    let mut session = Session::new();
    let doc = session.open("keywords.mission", EVERY_KEYWORD);
    let tokens = lex(&doc.text);
    for &kw in Kw::ALL {
        let word = kw.as_str();
        let entry = keywords::entry(kw)
            .unwrap_or_else(|| panic!("`{word}` has no entry in docs/language/keywords.md"));
        let (_, span) = tokens
            .iter()
            .find(|(token, _)| *token == Token::Kw(kw))
            .unwrap_or_else(|| panic!("the test mission does not use the keyword `{word}`"));
        let position = support::position_of(&doc.text, span.start + 1);
        let result = session.at("textDocument/hover", &doc, &position);
        assert_eq!(text_at(&doc.text, &result["range"]), word, "{result}");
        assert_eq!(result["contents"]["kind"], "markdown");
        assert_eq!(result["contents"]["value"], entry, "hovering `{word}`");
    }
    session.shutdown();
}
