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
    "/../../shared/examples/scouting/scouting.mission"
));
const STRATEGY: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/examples/scouting/MasterTeam.strategy.xml"
));

struct Loaded {
    mission: Analysis,
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
    fn file<'a>(&'a self, text: &'a str, missions: &'a [&'a Analysis]) -> StrategyFile<'a> {
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
    let marked = STRATEGY.replacen("<ActionInfo>\n", "<ActionInfo>\n<Action name=\"A\" actionId=\"9\">\n  $0\n</Action>\n", 1);
    assert_eq!(
        labels_at(&marked),
        ["CheckSensor", "ExecuteActuator", "ExecuteAlgorithm", "Parameter", "TransitionInfo"]
    );
}

#[test]
fn attribute_names_leave_out_those_written() {
    let marked = STRATEGY.replacen("<Action name=\"CheckGoal\"", "<Action $0 name=\"CheckGoal\"", 1);
    assert_eq!(labels_at(&marked), ["final"]);
    let marked = STRATEGY.replacen("<Service plan_name=", "<Service na$0 plan_name=", 1);
    assert_eq!(labels_at(&marked), ["service_name"]);
}
