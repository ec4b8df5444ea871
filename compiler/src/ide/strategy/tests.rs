//! The editor features over the scouting example (its mission, its
//! MasterTeam strategy and the built-in catalog), with half-typed variants.

use super::code_actions::{code_actions, create_entry};
use super::completion::completions;
use super::hover::hover;
use super::navigation::{definition, entries_of_call};
use super::symbols::document_symbols;
use super::*;
use crate::catalog::builtin_catalog;
use crate::diag::FileId;
use crate::strategy::{StrategyLinks, cross_check, load_strategy};

const MISSION: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/scouting/scouting.mission"
));
const STRATEGY: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/scouting/MasterTeam.strategy.xml"
));

struct Loaded {
    mission: CheckedMission,
    strategy: Option<Strategy>,
    links: StrategyLinks,
    diagnostics: Vec<crate::diag::Diagnostic>,
    catalog: Catalog,
}

fn load(text: &str) -> Loaded {
    let catalog = builtin_catalog();
    let mission = crate::check_source(FileId(0), MISSION, &catalog);
    let (strategy, mut diagnostics) = load_strategy(FileId(1), text);
    let mut links = StrategyLinks::default();
    if let Some(s) = &strategy {
        let (l, d) = cross_check(&[s], &[&mission], &catalog);
        links = l;
        diagnostics.extend(d);
    }
    Loaded {
        mission,
        strategy,
        links,
        diagnostics,
        catalog,
    }
}

impl Loaded {
    fn file<'a>(&'a self, text: &'a str, missions: &'a [&'a CheckedMission]) -> StrategyFile<'a> {
        StrategyFile {
            text,
            strategy: self.strategy.as_ref(),
            missions,
            catalog: &self.catalog,
        }
    }
}

/// The text with its `$0` removed, and the cursor's offset.
fn cursor(marked: &str) -> (String, usize) {
    let at = marked.find("$0").expect("a cursor");
    (marked.replacen("$0", "", 1), at)
}

fn labels_at(marked: &str) -> Vec<String> {
    let (text, at) = cursor(marked);
    let loaded = load(&text);
    let missions = [&loaded.mission];
    completions(&loaded.file(&text, &missions), at, false)
        .into_iter()
        .map(|c| c.label)
        .collect()
}

#[test]
fn element_names_follow_the_parent_even_half_typed() {
    let marked = STRATEGY.replacen("<ServiceInfo>\n", "<ServiceInfo>\n    <Se$0\n", 1);
    assert_eq!(labels_at(&marked), ["Service"]);
    let marked = STRATEGY.replacen(
        "<ActionInfo>\n",
        "<ActionInfo>\n<Action name=\"A\" actionId=\"9\">\n  $0\n</Action>\n",
        1,
    );
    assert_eq!(
        labels_at(&marked),
        [
            "CheckSensor",
            "ExecuteActuator",
            "ExecuteAlgorithm",
            "Parameter",
            "TransitionInfo"
        ]
    );
}

#[test]
fn attribute_names_leave_out_those_written() {
    let marked = STRATEGY.replacen(
        "<Action name=\"CheckGoal\"",
        "<Action $0 name=\"CheckGoal\"",
        1,
    );
    assert_eq!(labels_at(&marked), ["final"]);
    let marked = STRATEGY.replacen("<Service plan_name=", "<Service na$0 plan_name=", 1);
    assert_eq!(labels_at(&marked), ["service_name"]);
}

#[test]
fn a_service_leads_to_its_mission_calls_and_back() {
    let loaded = load(STRATEGY);
    let missions = [&loaded.mission];
    let file = loaded.file(STRATEGY, &missions);
    let at = STRATEGY.find("name=\"move\"").unwrap() + 7;
    let calls = definition(&file, &loaded.links, at);
    let shown: Vec<&str> = calls.iter().map(|t| &MISSION[t.span.range()]).collect();
    assert_eq!(shown, ["move", "move"]);
    let strategy = loaded.strategy.as_ref().unwrap();
    for call in &calls {
        let back = entries_of_call(strategy, &loaded.links, call.file, call.span.start);
        assert_eq!(
            back.iter()
                .map(|s| &STRATEGY[s.range()])
                .collect::<Vec<_>>(),
            ["move"]
        );
    }
    let h = hover(&file, at).expect("a hover on the service");
    assert!(
        h.markdown.contains("`move(goal?: location)`"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.contains("`MasterTeam.Action.AutonomousMove`"),
        "{}",
        h.markdown
    );
}

#[test]
fn a_raw_lt_is_escaped_and_the_file_then_loads_clean() {
    let text = STRATEGY.replacen("distance&lt;=20", "distance<=20", 1);
    let loaded = load(&text);
    let (index, d) = loaded
        .diagnostics
        .iter()
        .enumerate()
        .find(|(_, d)| d.code == crate::diag::Code::StrategyRawLt)
        .expect("E081");
    let actions = code_actions(&text, &loaded.diagnostics, d.span);
    assert_eq!(actions.len(), 1);
    assert_eq!(actions[0].diagnostic, index);
    let mut fixed = text.clone();
    let edit = &actions[0].edits[0];
    fixed.replace_range(edit.span.range(), &edit.new_text);
    assert_eq!(fixed, STRATEGY);
    assert_eq!(load(&fixed).diagnostics, []);
}

#[test]
fn a_created_entry_checks_clean_and_refines_the_call() {
    let loaded = load(STRATEGY);
    let at = MISSION.find("process(USER").unwrap() + 2;
    let strategy = loaded.strategy.as_ref().unwrap();
    let edit = create_entry(
        &loaded.mission,
        &loaded.catalog,
        at,
        strategy,
        STRATEGY,
        &loaded.links,
    )
    .expect("process has no entry");
    let mut fixed = STRATEGY.to_string();
    fixed.insert_str(edit.edit.span.start, &edit.edit.new_text);
    let after = load(&fixed);
    assert_eq!(after.diagnostics, []);
    assert_eq!(after.links.at(FileId(0), at).count(), 1);
    // `move` is refined already: nothing to create.
    let moved = MISSION.find("move(\"5,5\")").unwrap();
    assert_eq!(
        create_entry(
            &loaded.mission,
            &loaded.catalog,
            moved,
            strategy,
            STRATEGY,
            &loaded.links
        ),
        None
    );
    // Without `<ServiceInfo>`, the entry comes with one.
    let bare = "<Strategy name=\"MasterTeam\">\n</Strategy>\n";
    let loaded = load(bare);
    let strategy = loaded.strategy.as_ref().unwrap();
    let edit = create_entry(
        &loaded.mission,
        &loaded.catalog,
        at,
        strategy,
        bare,
        &loaded.links,
    )
    .unwrap();
    let mut fixed = bare.to_string();
    fixed.insert_str(edit.edit.span.start, &edit.edit.new_text);
    assert_eq!(load(&fixed).diagnostics, []);
}

#[test]
fn the_outline_has_values_then_services_with_their_actions() {
    let loaded = load(STRATEGY);
    let symbols = document_symbols(loaded.strategy.as_ref().unwrap());
    let names: Vec<(&str, usize)> = symbols
        .iter()
        .map(|s| (s.name.as_str(), s.children.len()))
        .collect();
    assert_eq!(
        names,
        [("DISTANCE", 0), ("LOCATION", 0), ("Action.move", 5)]
    );
    for s in symbols
        .iter()
        .chain(symbols.iter().flat_map(|s| s.children.iter()))
    {
        assert!(
            s.span.start <= s.name_span.start && s.name_span.end <= s.span.end,
            "{}",
            s.name
        );
    }
}

#[test]
fn the_team_is_read_from_the_text_when_the_file_does_not_load() {
    // No `>` after the root tag: no model, but the team's services are known.
    let marked =
        "<Strategy name=\"MasterTeam\"\n<ServiceInfo><Service plan_name=\"Action\" name=\"$0";
    let (text, at) = cursor(marked);
    let loaded = load(&text);
    assert!(loaded.strategy.is_none());
    let missions = [&loaded.mission];
    let labels: Vec<String> = completions(&loaded.file(&text, &missions), at, false)
        .into_iter()
        .map(|c| c.label)
        .collect();
    assert_eq!(labels, ["move", "process", "standby"]);
}

/// A strategy of 10,000 lines: completion, hover and navigation at its end
/// scan the text before the cursor once, and stay well under a keystroke.
#[test]
fn features_stay_fast_on_a_large_strategy() {
    let start = STRATEGY.find("<ServiceInfo>").unwrap() + "<ServiceInfo>\n".len();
    let service_start = STRATEGY.find("    <Service plan_name").unwrap();
    let service_end = STRATEGY.find("</Service>").unwrap() + "</Service>\n".len();
    let service = &STRATEGY[service_start..service_end];
    let mut text = STRATEGY[..start].to_string();
    while text.lines().count() < 10_000 {
        text.push_str(service);
    }
    text.push_str("    <Service plan_name=\"Action\" name=\"");
    let at = text.len();
    text.push_str("\">\n");
    text.push_str(&STRATEGY[service_end..]);
    let loaded = load(&text);
    let missions = [&loaded.mission];
    let file = loaded.file(&text, &missions);
    let items = completions(&file, at, false);
    let _ = hover(&file, at);
    let _ = definition(&file, &loaded.links, at);
    assert_eq!(items.len(), 3);
}
