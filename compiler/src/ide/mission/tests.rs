//! Unit tests of the `ide` functions on small missions: the scopes the checker
//! records, places found in half-typed text, catalog-dependent completions,
//! robustness on arbitrary text and offsets, and completion latency on a large
//! mission. The protocol tests of `semo-server` cover each feature end to end.

use super::code_actions::code_actions;
use super::completion::completions;
use super::context::{self, Place};
use super::hover::hover;
use super::inlay_hints::inlay_hints;
use super::signature_help::signature_help;
use crate::catalog::{Catalog, CatalogSource, builtin_catalog, load_catalog};
use crate::diag::FileId;
use crate::ide::{CompletionConfig, CompletionItem, CompletionKind};
use crate::sema::{CheckedMission, ScopeKind};
use crate::span::Span;
use crate::syntax::ast::ArmKind;
use proptest::prelude::*;
use std::sync::OnceLock;

fn builtin() -> &'static Catalog {
    static CATALOG: OnceLock<Catalog> = OnceLock::new();
    CATALOG.get_or_init(builtin_catalog)
}

fn analyse(text: &str) -> CheckedMission {
    crate::check_source(FileId(0), text, builtin())
}

/// The text without its `$0`, and the marker's offset.
fn cursor(text: &str) -> (String, usize) {
    let at = text.find("$0").expect("a $0 marker");
    (text.replacen("$0", "", 1), at)
}

fn complete_with(text: &str, catalog: &Catalog) -> Vec<CompletionItem> {
    let (text, at) = cursor(text);
    let analysis = crate::check_source(FileId(0), &text, catalog);
    completions(
        &analysis,
        catalog,
        &text,
        at,
        CompletionConfig { snippets: true },
    )
}

fn labels_of(items: &[CompletionItem], kind: CompletionKind) -> Vec<String> {
    items
        .iter()
        .filter(|i| i.kind == kind)
        .map(|i| i.label.clone())
        .collect()
}

fn place_at(text: &str) -> Place {
    let (text, at) = cursor(text);
    let analysis = analyse(&text);
    let start = context::prefix_at(&text, at).start;
    context::place(&context::scan(&analysis, &text, start))
}

const GUARDS: &str = "{
  Guards: Turtlebot3_Burger tb[2], Ev3_Robot ev
}
Guards.Action.Patrol{
  stop()
  [[
    group(instance of Turtlebot3_Burger){
      light_on()
    }
    others{
      scatter()
    }
  ]]
} repeat()
def helper{
  [[ leader(instance of Turtlebot3_Burger){ light_off() } ]]
}
Guards.Report.Tell{ helper() } repeat(1 SEC)
Guards.PATROL{ set(Action, Patrol); set(Report, Tell) }
Guards.main{ default: mode = PATROL }
";

#[test]
fn scopes_nest_and_give_the_robots_of_each_place() {
    let analysis = analyse(GUARDS);
    let mission = &analysis.mission;
    let at = |needle: &str| GUARDS.find(needle).unwrap() + 1;
    let robots = |offset: usize| {
        let scope = mission.scope_at(offset).expect("a scope");
        let mut names: Vec<String> = scope
            .runs
            .iter()
            .flat_map(|r| {
                let t = mission.team(r.team.unwrap());
                r.robots
                    .iter()
                    .map(|&i| t.robots[i.index()].name.to_string())
            })
            .collect();
        names.sort();
        (scope.kind, names)
    };
    let (kind, names) = robots(at("stop()"));
    assert!(matches!(kind, ScopeKind::Service { .. }));
    assert_eq!(names, ["ev", "tb_0", "tb_1"]);
    let (kind, names) = robots(at("light_on"));
    assert!(matches!(
        kind,
        ScopeKind::Arm {
            kind: ArmKind::Group,
            ..
        }
    ));
    assert_eq!(names, ["tb_0", "tb_1"]);
    let (kind, names) = robots(at("scatter"));
    assert!(matches!(kind, ScopeKind::Others { .. }));
    assert_eq!(names, ["ev"]);
    // The arm inside the function is run by the caller's robots.
    let (_, names) = robots(at("light_off"));
    assert_eq!(names, ["tb_0", "tb_1"]);
    let function = mission.scope_at(at("[[ leader")).unwrap();
    assert!(matches!(function.kind, ScopeKind::Function(_)));
    // Between items, and at the very ends of a body: no scope.
    assert!(mission.scope_at(at("Guards.PATROL")).is_none());
    assert!(mission.scope_at(0).is_none());
    assert!(mission.scope_at(GUARDS.len() + 10).is_none());
    // Outer before inner, each linked to the smallest one around it.
    for (i, s) in mission.scopes.iter().enumerate() {
        if let Some(p) = s.parent {
            let parent = &mission.scopes[p as usize];
            assert!((p as usize) < i);
            assert!(parent.span.start <= s.span.start && s.span.end <= parent.span.end);
        }
    }
}

#[test]
fn places_in_half_typed_text() {
    let cases: &[(&str, Place)] = &[
        ("{ T: $0", Place::RobotType),
        ("{ T: A a, $0", Place::RobotType),
        ("{ T: A $0", Place::Nothing),
        ("T: A a\n$0", Place::Item),
        ("T.P.S{ st$0", Place::Statement),
        ("T.P.S{ move($0", Place::Expr { qualifier: None }),
        ("T.P.S{ move(\n  $0", Place::Statement),
        (
            "T.P.S{ if(T.$0",
            Place::Expr {
                qualifier: Some("T".into()),
            },
        ),
        (
            "T.P.S{ if(T.COLOR == $0",
            Place::Compared {
                attr: Some(vec!["T".into(), "COLOR".into()]),
                words: true,
            },
        ),
        ("T.P.S{ throw $0", Place::Throw),
        ("T.P.S{ send($0", Place::CommTeam),
        (
            "T.P.S{ [[ $0",
            Place::GroupArm {
                first: true,
                leader: false,
            },
        ),
        ("T.P.S{ [[ group($0", Place::ArmCondition),
        ("T.P.S{ [[ group(instance of A, $0", Place::ArmTypes),
        ("T.P.S{ [[ group(capable of $0", Place::ArmCapabilities),
        ("T.P.S{ x() } repeat($0", Place::Expr { qualifier: None }),
        (
            "T.P.S{ x() } repeat(2 $0",
            Place::Unit {
                in_condition: false,
            },
        ),
        ("T.M{ $0", Place::SetStart),
        ("T.M{ set($0", Place::SetPlan),
        ("T.M{ set(P, $0", Place::SetService { plan: "P".into() }),
        ("T.M{ set(P, S, $0", Place::SetTimeout),
        ("T.main{ case($0", Place::CaseMode),
        (
            "T.main{ case(A): catch($0",
            Place::CatchEvent {
                mode: Some("A".into()),
            },
        ),
        ("T.main{ case(A): catch(e): $0", Place::ModeKeyword),
        ("T.main{ case(A): catch(e): mode = $0", Place::ModeName),
        ("T.main{ default: $0", Place::ModeKeyword),
        ("T.main{ case(A): $0", Place::MainArm { in_case: true }),
        ("$0", Place::Item),
        ("T.$0", Place::ItemAfterTeam { team: "T".into() }),
        (
            "T.P.$0",
            Place::ItemAfterPlan {
                team: "T".into(),
                plan: "P".into(),
            },
        ),
        ("T.P.S.$0", Place::Nothing),
        (
            "T.P.S{ x() } repeat()\nT.$0",
            Place::ItemAfterTeam { team: "T".into() },
        ),
        ("T.P.S{ x() }\n$0", Place::Item),
    ];
    for (text, expected) in cases {
        assert_eq!(&place_at(text), expected, "in {text:?}");
    }
}

#[test]
fn trivia_and_prefixes() {
    use context::{Trivia, prefix_at, trivia_at};
    assert_eq!(trivia_at("a # b", 5), Trivia::Comment);
    assert_eq!(trivia_at("move(\"a # b", 10), Trivia::String);
    assert_eq!(trivia_at("move(\"a\\\" b", 10), Trivia::String);
    assert_eq!(trivia_at("move(\"a\") b", 10), Trivia::Code);
    assert_eq!(trivia_at("# x\nmove(", 9), Trivia::Code);
    assert_eq!(prefix_at("move(ab", 7), Span::new(5, 7));
    assert_eq!(prefix_at("2SE", 3), Span::new(1, 3));
    assert_eq!(prefix_at("한국ab", 8), Span::new(6, 8));
    assert_eq!(prefix_at("", 4), Span::new(0, 0));
}

/// A workspace catalog with an enumerated value and a service of its own.
fn enum_catalog() -> Catalog {
    let xml = r#"<Catalog>
  <Robot type="Lamp">
    <Value name="MODE" type="enum" domain="RED GREEN BLUE" doc="The lamp's color."/>
    <Value name="ON" type="bool" doc="Whether it is lit."/>
    <Service name="blink" doc="Blink."><Param name="times" type="int"/></Service>
  </Robot>
</Catalog>"#;
    catalog_of(xml)
}

/// The catalog of `xml`, which must load without a diagnostic.
fn catalog_of(xml: &str) -> Catalog {
    let (catalog, diags) = load_catalog(&[CatalogSource {
        file: FileId(1),
        text: xml,
        base_dir: None,
    }]);
    assert!(diags.is_empty(), "{diags:#?}");
    catalog
}

const LAMPS: &str = "{ L: Lamp l }\nL.Action.Go{\n  if(MODE == $0)\n} repeat()\nL.M{ set(Action, Go) }\nL.main{ default: mode = M }\n";

#[test]
fn constants_of_an_enumeration_after_a_comparison() {
    let catalog = enum_catalog();
    let items = complete_with(LAMPS, &catalog);
    assert_eq!(
        labels_of(&items, CompletionKind::Constant),
        ["RED", "GREEN", "BLUE"]
    );
    assert_eq!(items[0].label, "RED", "the domain comes first");
    let items = complete_with(&LAMPS.replace("MODE == $0", "L.ON == $0"), &catalog);
    assert_eq!(items[0].label, "true");
    let items = complete_with(&LAMPS.replace("if(MODE == $0)", "$0"), &catalog);
    assert_eq!(labels_of(&items, CompletionKind::BuiltinService), ["blink"]);
    let blink = items.iter().find(|i| i.label == "blink").unwrap();
    assert_eq!(blink.insert, "blink(${1:times})$0");
    assert_eq!(blink.detail.as_deref(), Some("blink(times: int)"));
}

/// Scouts that receive their own COLOR (so COLOR is also a team variable
/// of theirs) and compare it with words and strings; Phase is a team
/// variable set to words.
const SCOUTS: &str = "{ S: TIEvalbot ti, NXTLego nxt }
S.Look.Share{
  receive(S, S.COLOR)
  if(COLOR == \"RGB\") send(S, S.Phase = DONE)
  if(S.Phase != WAITING) stop()
  CURSOR
} repeat(COLOR != RED)
S.M{ set(Look, Share) }
S.main{ default: mode = M }
";

fn complete_scouts(line: &str) -> Vec<CompletionItem> {
    complete_with(&SCOUTS.replace("CURSOR", line), builtin())
}

#[test]
fn constants_after_a_comparison_are_those_the_mission_writes_with_the_value() {
    for (line, constants) in [
        ("if(COLOR == $0)", vec!["RED", "\"RGB\""]),
        ("if(S.COLOR != $0)", vec!["RED", "\"RGB\""]),
        ("if(S.Phase == $0)", vec!["DONE", "WAITING"]),
    ] {
        let items = complete_scouts(line);
        let first: Vec<&str> = items
            .iter()
            .take_while(|i| i.kind == CompletionKind::Constant)
            .map(|i| i.label.as_str())
            .collect();
        assert_eq!(first, constants, "{line}: the constants first");
        // A bare value on the right of `==` is E041: none is offered.
        assert_eq!(
            labels_of(&items, CompletionKind::Value),
            Vec::<String>::new(),
            "{line}"
        );
        assert_eq!(
            labels_of(&items, CompletionKind::TeamVariable),
            Vec::<String>::new(),
            "{line}"
        );
        assert!(labels_of(&items, CompletionKind::Team).contains(&"S".to_string()));
    }
    // `<` compares numbers: no words, no bare values.
    let items = complete_scouts("if(DISTANCE < $0)");
    assert_eq!(
        labels_of(&items, CompletionKind::Constant),
        Vec::<String>::new()
    );
    assert_eq!(
        labels_of(&items, CompletionKind::Value),
        Vec::<String>::new()
    );
}

#[test]
fn a_received_value_is_offered_once() {
    for line in ["send(S, $0)", "if(S.$0)", "if($0)"] {
        let items = complete_scouts(line);
        let colors = items.iter().filter(|i| i.label == "COLOR").count();
        assert_eq!(colors, 1, "{line}: {items:#?}");
        let mut labels: Vec<&str> = items.iter().map(|i| i.label.as_str()).collect();
        let count = labels.len();
        labels.sort_unstable();
        labels.dedup();
        assert_eq!(labels.len(), count, "{line}: a label twice");
    }
}

#[test]
fn did_you_mean_of_a_string_keeps_the_quotes() {
    let catalog = enum_catalog();
    let text = LAMPS.replace("MODE == $0)", "MODE == \"GREN\") blink(2)");
    let analysis = crate::check_source(FileId(0), &text, &catalog);
    let at = text.find("GREN").unwrap();
    let actions = code_actions(&analysis, &catalog, &text, Span::new(at, at));
    assert_eq!(actions.len(), 1, "{actions:#?}");
    assert_eq!(actions[0].edits[0].new_text, "\"GREEN\"");
    assert_eq!(&text[actions[0].edits[0].span.range()], "\"GREN\"");
}

#[test]
fn a_word_that_is_also_a_value_is_fixed_either_way() {
    let catalog = builtin();
    let text = "{ Scouts: TIEvalbot ti }\nScouts.Report.Alarm{\n  send(USER, Scouts.Found = COLOR)\n} repeat(1 SEC)\nScouts.REPORT{ set(Report, Alarm) }\nScouts.main{ default: mode = REPORT }\n";
    let analysis = crate::check_source(FileId(0), text, catalog);
    let at = text.find("= COLOR").unwrap() + 2;
    let actions = code_actions(&analysis, catalog, text, Span::new(at, at));
    let fixes: Vec<(&str, &str, bool)> = actions
        .iter()
        .map(|a| (a.title.as_str(), a.edits[0].new_text.as_str(), a.preferred))
        .collect();
    assert_eq!(
        fixes,
        [
            ("Write `\"COLOR\"`: the word", "\"COLOR\"", false),
            (
                "Write `Scouts.COLOR`: the robots' value",
                "Scouts.COLOR",
                false
            ),
        ]
    );
    for action in &actions {
        let edit = &action.edits[0];
        assert_eq!(&text[edit.span.range()], "COLOR");
        let fixed = format!(
            "{}{}{}",
            &text[..edit.span.start],
            edit.new_text,
            &text[edit.span.end..]
        );
        let checked = crate::check_source(FileId(0), &fixed, catalog);
        assert!(!checked.has_errors(), "{fixed}: {:#?}", checked.diagnostics);
    }
}

/// A function with parameters, in the editor: completion offers the
/// parameters in its body (and a snippet with a stop per parameter at a
/// call), hover says what a parameter's uses ask, go to definition and
/// rename reach the parameter list and every use (nothing outside the
/// body), semantic tokens mark them as parameters, and signature help
/// names them.
#[test]
fn parameters_in_the_editor() {
    let catalog = builtin();
    let text = "{ R: TIEvalbot ti }\ndef go_to(PLACE, WAIT) {\n  move(PLACE)\n  if (WAIT > 2) standby()\n}\nR.Action.Go {\n  go_to(kitchen, 3)\n} repeat(1 SEC)\nR.GO { set(Action, Go) }\nR.main { default: mode = GO }\n";
    let analysis = crate::check_source(FileId(0), text, catalog);
    assert!(
        analysis.diagnostics.is_empty(),
        "{:#?}",
        analysis.diagnostics
    );

    // Completion in the body, not outside it.
    let body = text.find("if (WAIT").unwrap() + 4;
    let items = completions(
        &analysis,
        catalog,
        text,
        body,
        CompletionConfig { snippets: true },
    );
    assert_eq!(
        labels_of(&items, CompletionKind::Parameter),
        ["PLACE", "WAIT"]
    );
    let outside = text.find("go_to(kitchen").unwrap();
    let items = completions(
        &analysis,
        catalog,
        text,
        outside,
        CompletionConfig { snippets: true },
    );
    assert!(labels_of(&items, CompletionKind::Parameter).is_empty());
    let call = items
        .iter()
        .find(|i| i.label == "go_to")
        .expect("the function");
    assert_eq!(call.insert, "go_to(${1:PLACE}, ${2:WAIT})");

    // Hover on a use: its function and what its argument must be.
    let use_at = text.find("move(PLACE)").unwrap() + 6;
    let h = hover(&analysis, catalog, text, use_at).expect("a hover");
    assert!(
        h.markdown
            .contains("Parameter 1 of `def go_to(PLACE, WAIT)`"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.contains("passed to `move` as `goal` (location)"),
        "{}",
        h.markdown
    );
    let wait = text.find("WAIT >").unwrap();
    let h = hover(&analysis, catalog, text, wait).expect("a hover");
    assert!(
        h.markdown.contains("compared as a number"),
        "{}",
        h.markdown
    );

    // Definition and rename.
    let declared = text.find("PLACE,").unwrap();
    let targets = super::navigation::definition(&analysis, catalog, use_at);
    let spans: Vec<Span> = targets.iter().map(|t| t.span).collect();
    assert_eq!(spans, [Span::new(declared, declared + 5)]);
    let edits = super::rename::rename(&analysis, catalog, text, use_at, "GOAL").unwrap();
    assert_eq!(
        edits,
        [
            Span::new(declared, declared + 5),
            Span::new(use_at - 1, use_at + 4)
        ]
    );
    let clash = super::rename::rename(&analysis, catalog, text, use_at, "WAIT").unwrap_err();
    assert!(
        clash.to_string().contains("already has a parameter `WAIT`"),
        "{clash}"
    );
    let clash = super::rename::rename(&analysis, catalog, text, use_at, "LOCATION").unwrap_err();
    assert!(clash.to_string().contains("value of robot type"), "{clash}");

    // Semantic tokens: the declarations and the uses.
    let tokens = super::semantic_tokens::semantic_tokens(&analysis, None);
    let params: Vec<&str> = tokens
        .iter()
        .filter(|t| t.kind == super::semantic_tokens::TokenKind::Parameter)
        .map(|t| &text[t.span.range()])
        .collect();
    assert_eq!(params, ["PLACE", "WAIT", "PLACE", "WAIT"]);

    // Signature help at the call's second argument.
    let second = text.find(", 3)").unwrap() + 2;
    let help = signature_help(&analysis, catalog, text, second).expect("signature help");
    assert_eq!(help.label, "go_to(PLACE, WAIT)");
    assert_eq!(help.active_parameter, Some(1));
}

/// Modes and services with parameters, in the editor: completion offers a
/// service's parameters in its body and snippets for the mode after
/// `mode =` and the service in `set`; hover on the mode names the modes it
/// is entered as, on a parameter what it stands for; definition and rename
/// reach the mode's declaration and every place it is named, and a
/// parameter's list and uses; semantic tokens; signature help at the
/// arguments; the outline lists the mode once with its parameters.
#[test]
fn modes_with_parameters_in_the_editor() {
    let catalog = builtin();
    let text = "{ R: TIEvalbot ti }\nR.Action.Go(PLACE) {\n  move(PLACE)\n  throw arrived\n}\nR.Action.Wait { standby() } repeat()\nR.MOVE(TARGET) { set(Action, Go(TARGET)) }\nR.WAIT { set(Action, Wait) }\nR.main {\n  case (MOVE):\n    catch (arrived): mode = WAIT\n  case (WAIT):\n    catch (go): mode = MOVE(hall)\n  default: mode = MOVE(kitchen)\n}\n";
    let analysis = crate::check_source(FileId(0), text, catalog);
    let errors: Vec<_> = analysis
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");

    // Completion: the service's parameter in its body; the mode's snippet.
    let body = text.find("move(PLACE)").unwrap() + 5;
    let items = completions(
        &analysis,
        catalog,
        text,
        body,
        CompletionConfig { snippets: true },
    );
    assert_eq!(labels_of(&items, CompletionKind::Parameter), ["PLACE"]);
    let entered = text.find("MOVE(hall)").unwrap();
    let items = completions(
        &analysis,
        catalog,
        text,
        entered,
        CompletionConfig { snippets: true },
    );
    let mode = items.iter().find(|i| i.label == "MOVE").expect("the mode");
    assert_eq!(mode.insert, "MOVE(${1:TARGET})");
    assert!(
        !items.iter().any(|i| i.label.contains('(')),
        "a mode entered with arguments is offered by its name alone"
    );

    // Hover on the mode where it is entered, and on its parameter.
    let h = hover(&analysis, catalog, text, entered + 1).expect("a hover");
    assert!(h.markdown.contains("`MOVE(TARGET)`"), "{}", h.markdown);
    assert!(
        h.markdown
            .contains("Entered as `MOVE(kitchen)`, `MOVE(hall)`."),
        "{}",
        h.markdown
    );
    let target = text.find("Go(TARGET)").unwrap() + 3;
    let h = hover(&analysis, catalog, text, target).expect("a hover");
    assert!(
        h.markdown.contains("Parameter 1 of `R.MOVE(TARGET)`"),
        "{}",
        h.markdown
    );
    assert!(h.markdown.contains("passed to `move`"), "{}", h.markdown);

    // Definition of the mode and rename everywhere it is named.
    let declared = text.find("MOVE(TARGET)").unwrap();
    let targets = super::navigation::definition(&analysis, catalog, entered + 1);
    let spans: Vec<Span> = targets.iter().map(|t| t.span).collect();
    assert_eq!(spans, [Span::new(declared, declared + 4)]);
    let edits = super::rename::rename(&analysis, catalog, text, entered + 1, "GO_TO").unwrap();
    let renamed: Vec<usize> = edits.iter().map(|s| s.start).collect();
    let named: Vec<usize> = text.match_indices("MOVE").map(|(i, _)| i).collect();
    assert_eq!(renamed, named);
    let clash = super::rename::rename(&analysis, catalog, text, entered + 1, "WAIT").unwrap_err();
    assert!(
        clash.to_string().contains("already has a mode `WAIT`"),
        "{clash}"
    );
    // A mode's parameter: its list and its use in the `set`s.
    let edits = super::rename::rename(&analysis, catalog, text, target, "GOAL").unwrap();
    let param = text.find("TARGET").unwrap();
    assert_eq!(
        edits,
        [Span::new(param, param + 6), Span::new(target, target + 6)]
    );

    // Semantic tokens: the parameters, and the mode as a mode everywhere.
    let tokens = super::semantic_tokens::semantic_tokens(&analysis, None);
    let of = |kind| -> Vec<&str> {
        tokens
            .iter()
            .filter(|t| t.kind == kind)
            .map(|t| &text[t.span.range()])
            .collect()
    };
    use super::semantic_tokens::TokenKind;
    assert_eq!(
        of(TokenKind::Parameter),
        ["PLACE", "PLACE", "TARGET", "TARGET"]
    );
    assert_eq!(
        of(TokenKind::Mode).iter().filter(|m| **m == "MOVE").count(),
        4
    );

    // Signature help at the mode's argument and the service's.
    let help = signature_help(&analysis, catalog, text, entered + 5).expect("signature help");
    assert_eq!(
        (help.label.as_str(), help.active_parameter),
        ("MOVE(TARGET)", Some(0))
    );
    let help = signature_help(&analysis, catalog, text, target).expect("signature help");
    assert_eq!(help.label, "Go(PLACE)");

    // The outline: the mode once, with its parameters.
    let outline = super::symbols::document_symbols(&analysis, text);
    let team = &outline[0];
    let modes: Vec<(&str, Option<&str>)> = team
        .children
        .iter()
        .filter(|c| c.kind == crate::ide::SymbolKind::Mode)
        .map(|c| (c.name.as_str(), c.detail.as_deref()))
        .collect();
    assert_eq!(
        modes,
        [
            ("MOVE", Some("(TARGET) Action: Go(TARGET)")),
            ("WAIT", Some("Action: Wait"))
        ]
    );
}

/// Every `ide` function at `offset` of `text`: nothing panics, and every
/// range returned lies in the text, on character boundaries.
fn every_feature_at(text: &str, analysis: &CheckedMission, offset: usize) {
    let catalog = builtin();
    let valid = |span: Span| {
        assert!(span.start <= span.end && span.end <= text.len(), "{span:?}");
        assert!(text.is_char_boundary(span.start) && text.is_char_boundary(span.end));
    };
    for snippets in [true, false] {
        for item in completions(
            analysis,
            catalog,
            text,
            offset,
            CompletionConfig { snippets },
        ) {
            valid(item.replace);
            assert!(item.replace.end == offset.min(text.len()) || item.replace.is_empty());
        }
    }
    if let Some(h) = hover(analysis, catalog, text, offset) {
        valid(h.range);
    }
    if let Some(s) = signature_help(analysis, catalog, text, offset) {
        for (range, _) in &s.parameters {
            assert!(s.label.get(range.clone()).is_some());
        }
    }
    let range = Span::new(offset.saturating_sub(40), offset + 40);
    for h in inlay_hints(analysis, catalog, text, range) {
        valid(Span::new(h.offset, h.offset));
    }
    for action in code_actions(analysis, catalog, text, range) {
        for e in action.edits {
            valid(e.span);
        }
    }
}

fn examples() -> &'static [String] {
    static EXAMPLES: OnceLock<Vec<String>> = OnceLock::new();
    EXAMPLES.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
        [
            "scouting/scouting.mission",
            "follow/follow.mission",
            "swarm/march.mission",
            "swarm/patrol_groups.mission",
        ]
        .iter()
        .filter_map(|p| std::fs::read_to_string(root.join(p)).ok())
        .chain([GUARDS.to_string(), LAMPS.replace("$0", "")])
        .collect()
    })
}

#[test]
fn every_offset_of_the_examples() {
    for text in examples() {
        let analysis = analyse(text);
        for offset in (0..=text.len() + 2).filter(|&o| o > text.len() || text.is_char_boundary(o)) {
            every_feature_at(text, &analysis, offset);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Cuts of the examples (a prefix, as while typing, plus random text)
    /// at random offsets.
    #[test]
    fn never_panics_on_half_typed_text(
        which in 0usize..6,
        cut in 0.0f64..1.0,
        tail in "[a-zA-Z_.,:;=<>!()\\[\\]{}\"# \n0-9한😀]{0,12}",
        at in 0.0f64..1.2,
    ) {
        let examples = examples();
        let base = &examples[which % examples.len()];
        let mut end = ((base.len() as f64) * cut) as usize;
        while !base.is_char_boundary(end) {
            end -= 1;
        }
        let text = format!("{}{tail}", &base[..end]);
        let analysis = analyse(&text);
        let mut offset = ((text.len() as f64) * at) as usize;
        while offset <= text.len() && !text.is_char_boundary(offset) {
            offset -= 1;
        }
        every_feature_at(&text, &analysis, offset);
    }
}

/// A mission of about 10,000 lines: teams with groups, functions, modes.
fn large_mission(teams: usize) -> String {
    use std::fmt::Write;
    let mut m = String::from("{\n");
    for t in 0..teams {
        writeln!(
            m,
            "  Team{t}: Turtlebot3_Burger tb{t}[3], Ev3_Robot ev{t}[2]"
        )
        .unwrap();
    }
    m.push_str("}\ndef home {\n  move(\"0,0\")\n}\n");
    for t in 0..teams {
        let next = (t + 1) % teams;
        write!(
            m,
            "Team{t}.Listen.Hear{{\n  subscribe(Team{t}, Team{t}.Alarm)\n  receive(Team{next}, Team{next}.Status)\n  if(Team{t}.Alarm == DARK) throw hide\n  else throw resume\n}} repeat(500 MSEC)\n\
             Team{t}.Action.Patrol{{\n  [[\n    group(instance of Turtlebot3_Burger){{\n      loop(2 SEC){{\n        if(LIGHTNESS < 200 and BATTERY > 20)\n          publish(Team{t}, Team{t}.Alarm = DARK)\n      }}\n    }}\n    others{{\n      search(colored_paper)\n      home()\n    }}\n  ]]\n}} repeat()\n\
             Team{t}.Action.Hide{{\n  if(DISTANCE > 30){{\n    go_forward()\n  }} else {{\n    turn_left()\n  }}\n  send(Team{next}, Team{t}.Status = \"hiding\")\n}} repeat(LOCATION != \"0,0\")\n\
             Team{t}.PATROL{{ set(Listen, Hear); set(Action, Patrol) }}\nTeam{t}.HIDE{{ set(Listen, Hear); set(Action, Hide, timeout = 30 SEC) }}\n\
             Team{t}.main{{\n  case (PATROL):\n    catch (hide): mode = HIDE\n  case (HIDE):\n    catch (resume): mode = PATROL\n  default: mode = PATROL\n}}\n"
        )
        .unwrap();
    }
    m
}

/// Completion answers all over a 10,000-line mission (its latency is measured
/// by `cargo bench --bench ide_latency`, not asserted here).
#[test]
fn completion_answers_all_over_a_large_mission() {
    let text = large_mission(265);
    assert!(text.lines().count() >= 10_000, "{}", text.lines().count());
    let analysis = analyse(&text);
    let catalog = builtin();
    // Places all over the file: statements, conditions, `Team.`, `set(`...
    let mut offsets: Vec<usize> = Vec::new();
    for needle in [
        "      home()",
        "LIGHTNESS <",
        "Team",
        "set(Action, ",
        "catch (",
        "  [[",
    ] {
        offsets.extend(
            text.match_indices(needle)
                .step_by(7)
                .map(|(i, _)| i + needle.len()),
        );
    }
    assert!(offsets.len() > 300, "{}", offsets.len());
    for &offset in &offsets {
        let items = completions(
            &analysis,
            catalog,
            &text,
            offset,
            CompletionConfig { snippets: true },
        );
        assert!(!items.is_empty(), "no completion at {offset}");
    }
}

#[test]
fn hover_on_a_robot_type_says_the_platform_semo_build_builds_it_for() {
    let xml = r#"<Catalog>
  <Robot type="Board">
    <Platform target="cortex-m" cpu="LM3S6965"/>
    <Service name="blink" doc="Blink."/>
  </Robot>
</Catalog>"#;
    let catalog = catalog_of(xml);
    let text =
        "{ B: Board b }\nB.A.Go{ blink() }\nB.M{ set(A, Go) }\nB.main{ default: mode = M }\n";
    let analysis = crate::check_source(FileId(0), text, &catalog);
    let hover = hover(&analysis, &catalog, text, text.find("Board").unwrap() + 1).unwrap();
    assert!(
        hover.markdown.contains("Platform: LM3S6965.")
            && hover
                .markdown
                .contains("`semo build` builds it for `cortex-m`."),
        "{}",
        hover.markdown
    );
}

#[test]
fn a_counted_group_name_is_highlighted_and_its_hover_says_its_minimum_and_its_robots() {
    let f = crate::ide::mission::testing::Fixture::new(
        "{ C: Turtlebot3_Burger tb[5] }\nC.A.Go{ [[ group(Room1, min = 2) { scatter() }\n  group(Room2, min = 1) { standby() } ]] } repeat(1 SEC)\nC.M{ set(A, Go) }\nC.main{ default: mode = M }\n",
    );
    let at = f.text.find("Room2").unwrap();
    let hover = hover(&f.analysis, &f.catalog, &f.text, at + 1).unwrap();
    assert_eq!(&f.text[hover.range.range()], "Room2");
    assert!(
        hover.markdown.starts_with(
            "**group** `Room2`: a counted group of at least 1 robot, chosen at run time among the 5 robots of team `C`"
        ),
        "{}",
        hover.markdown
    );
    let tokens = crate::ide::mission::semantic_tokens::semantic_tokens(&f.analysis, None);
    let groups: Vec<(&str, &str)> = tokens
        .iter()
        .filter(|t| t.kind.name() == "group")
        .map(|t| (&f.text[t.span.range()], t.kind.name()))
        .collect();
    assert_eq!(groups, [("Room1", "group"), ("Room2", "group")]);
}

/// Action results in the editor, in a function's body: completion offers
/// those bound before the cursor, rename refuses a name the body already
/// has or a robot value, semantic tokens mark them as variables, and the
/// service's hover lists what it gives back.
#[test]
fn action_results_in_the_editor() {
    let catalog = builtin();
    let text = "{ R: TIEvalbot ti }\ndef look(TARGET) {\n  FOUND, WHERE = search(TARGET)\n  if (FOUND) move(WHERE)\n}\nR.Action.Go {\n  look(red)\n} repeat(1 SEC)\nR.GO { set(Action, Go) }\nR.main { default: mode = GO }\n";
    let analysis = crate::check_source(FileId(0), text, catalog);
    assert!(
        analysis.diagnostics.is_empty(),
        "{:#?}",
        analysis.diagnostics
    );
    let config = CompletionConfig { snippets: true };
    let after = text.find("if (FOUND").unwrap() + 4;
    let items = completions(&analysis, catalog, text, after, config);
    assert_eq!(
        labels_of(&items, CompletionKind::Result),
        ["FOUND", "WHERE"]
    );
    assert_eq!(labels_of(&items, CompletionKind::Parameter), ["TARGET"]);
    let before = text.find("FOUND, WHERE").unwrap();
    let items = completions(&analysis, catalog, text, before, config);
    assert!(labels_of(&items, CompletionKind::Result).is_empty());

    let read = text.find("move(WHERE)").unwrap() + 6;
    let clash = super::rename::rename(&analysis, catalog, text, read, "FOUND").unwrap_err();
    assert!(
        clash.to_string().contains("already binds a result `FOUND`"),
        "{clash}"
    );
    let clash = super::rename::rename(&analysis, catalog, text, read, "TARGET").unwrap_err();
    assert!(
        clash.to_string().contains("already has a parameter"),
        "{clash}"
    );
    let clash = super::rename::rename(&analysis, catalog, text, read, "LOCATION").unwrap_err();
    assert!(
        clash.to_string().contains("has a value `LOCATION`"),
        "{clash}"
    );

    let tokens = super::semantic_tokens::semantic_tokens(&analysis, None);
    let variables: Vec<&str> = tokens
        .iter()
        .filter(|t| t.kind == super::semantic_tokens::TokenKind::Variable)
        .map(|t| &text[t.span.range()])
        .collect();
    assert_eq!(variables, ["FOUND", "WHERE", "FOUND", "WHERE"]);

    let h = hover(&analysis, catalog, text, read).expect("a hover");
    assert!(h.markdown.contains("WHERE: location"), "{}", h.markdown);
    assert!(h.markdown.contains("bound in `look`"), "{}", h.markdown);
}
