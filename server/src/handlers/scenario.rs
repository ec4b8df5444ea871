//! `textDocument/completion` in a scenario file (`*.scenario.json`):
//! [`semo::sim::complete`] in protocol types, over the refined programs of
//! the mission the scenario belongs to ([`semo::sim::complete::mission_for`]),
//! as the workspace analysis has it (open documents as typed).

use crate::encoding::{Encoding, LineMap};
use crate::to_proto;
use crate::world::World;
use semo::diag::FileId;
use semo::ide::{CompletionItem, CompletionKind};
use semo::sim::complete::{self, ScenarioCompletionKind};
use semo::text::LineIndex;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::{CompletionResponse, Position, Uri};

/// What one completion works on, taken from the world at once.
pub struct Job {
    text: String,
    /// The scenario's mission, when the workspace has it.
    mission: Option<(semo::host::Analysis, FileId)>,
    encoding: Encoding,
}

/// `None` when `uri` is not an open scenario file.
pub fn job(world: &World, uri: &Uri) -> Option<Job> {
    let text = world.scenario_text(uri)?;
    let mission = crate::world::file_path(uri)
        .and_then(|path| complete::mission_for(&path))
        .and_then(Uri::from_file_path)
        .and_then(|mission| world.snapshot(&mission))
        .filter(|s| s.kind == FileKind::Mission)
        .map(|s| (world.analysis(), s.id));
    Some(Job {
        text,
        mission,
        encoding: world.encoding,
    })
}

/// The completions at `position`; none when the scenario has no mission
/// or the mission does not refine (it has errors: they are shown on it).
pub fn completion(job: &Job, position: Position) -> CompletionResponse {
    let programs = job
        .mission
        .as_ref()
        .and_then(|(analysis, id)| analysis.build_input(*id))
        .map(|build| semo::codegen::refine_checked(&build.input()))
        .filter(|refined| !refined.diagnostics.iter().any(|d| d.is_error()))
        .map(|refined| refined.programs)
        .unwrap_or_default();
    let index = LineIndex::new(&job.text);
    let lines = LineMap {
        text: &job.text,
        index: &index,
        encoding: job.encoding,
    };
    let items = complete::completions(&job.text, lines.offset(position), &programs)
        .into_iter()
        .map(|item| {
            let mut out =
                CompletionItem::new(item.label, kind(item.kind), item.replace).detail(item.detail);
            out.insert = item.insert;
            out
        })
        .collect();
    to_proto::completion_list(items, &lines)
}

/// The editor vocabulary's kind of each scenario completion.
fn kind(kind: ScenarioCompletionKind) -> CompletionKind {
    match kind {
        ScenarioCompletionKind::Robot => CompletionKind::Robot,
        ScenarioCompletionKind::Team => CompletionKind::Team,
        ScenarioCompletionKind::Value => CompletionKind::Value,
        ScenarioCompletionKind::Service => CompletionKind::Service,
        ScenarioCompletionKind::Mode => CompletionKind::Mode,
        ScenarioCompletionKind::Command => CompletionKind::Event,
        ScenarioCompletionKind::Constant => CompletionKind::Constant,
    }
}
