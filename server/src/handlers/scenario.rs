//! `textDocument/completion` in a scenario file (`*.scenario.json`):
//! [`semo::sim::complete::editor_completions`] in protocol types, over the
//! refined programs of the mission the scenario belongs to
//! ([`semo::sim::complete::mission_for`]), as the workspace analysis has it
//! (open documents as typed).

use crate::encoding::{Encoding, LineMap};
use crate::to_proto;
use crate::world::World;
use semo::diag::FileId;
use semo::sim::complete;
use semo::text::LineIndex;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::{CompletionResponse, Position, Uri};

/// What one completion works on, taken from the world at once.
pub struct Job {
    text: String,
    workspace: semo::host::Analysis,
    /// The scenario's mission, when the workspace has it.
    mission: Option<FileId>,
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
        .map(|s| s.id);
    Some(Job {
        text,
        workspace: world.analysis(),
        mission,
        encoding: world.encoding,
    })
}

/// The completions at `position`.
pub fn completion(job: &Job, position: Position) -> CompletionResponse {
    let index = LineIndex::new(&job.text);
    let lines = LineMap {
        text: &job.text,
        index: &index,
        encoding: job.encoding,
    };
    let items = complete::editor_completions(
        &job.workspace,
        job.mission,
        &job.text,
        lines.offset(position),
    );
    to_proto::completion_list(items, &lines)
}
