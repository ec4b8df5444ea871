//! Strategy files (`*.strategy.xml`): how a team's robots perform the services
//! of a mission (the format's reference: `docs/strategy.md`).
//!
//! - [`model`]: the typed model, every entry with its byte ranges.
//! - `xml`: the quick-xml loader (well-formedness, elements, attributes, value
//!   forms; conditions parsed with the mission expression grammar).
//! - `check`: per-file checks (duplicates, names read by conditions).
//! - `machine`: each service's actions checked as a graph (petgraph).
//! - `guards`: each action's transition conditions over one variable
//!   (uncovered values, conditions that never hold, overlaps).
//! - [`schema`]: the vocabulary (attributes, children, descriptions).
//! - Its editor features are `crate::ide::strategy`.
//! - [`cross`]: checks against the catalog and the missions of the same check,
//!   and the link from mission calls to strategy entries ([`StrategyLinks`]).
//!
//! Like sema, this module never reads files: [`crate::workspace`] does.

mod check;
pub mod cross;
mod guards;
mod machine;
pub mod model;
pub mod schema;
mod xml;

pub use cross::{
    BuiltinCall, CONTROL_TASK, CallLink, ServiceEntryRef, StrategyLinks, cross_check, task_library,
    team_calls,
};
pub use model::*;

use crate::diag::{self, Diagnostic, FileId};

/// Reads one strategy file and checks it on its own (everything that needs
/// neither the catalog nor a mission): the strategy (`None` when the file has
/// no `<Strategy>` element) and its diagnostics, sorted.
pub fn load_strategy(file: FileId, text: &str) -> (Option<Strategy>, Vec<Diagnostic>) {
    let (strategy, read) = xml::read_strategy(file, text);
    let mut sink = diag::Sink::new(file);
    sink.extend(read);
    if let Some(strategy) = &strategy {
        check::check_strategy(strategy, &mut sink);
        for service in &strategy.services {
            machine::check_machine(service, &mut sink);
        }
    }
    let mut diagnostics = sink.into_vec();
    diag::sort_and_dedup(&mut diagnostics);
    (strategy, diagnostics)
}

#[cfg(test)]
mod tests;
