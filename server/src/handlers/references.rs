//! `textDocument/references`: [`semo::host::Analysis::references`]; the
//! caller names the files (their URIs are the world's).

use crate::to_proto;
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::host::Analysis;
use tower_lsp_server::ls_types::{Range, ReferenceParams};

pub fn references(
    snapshot: &Snapshot,
    workspace: &Analysis,
    params: &ReferenceParams,
) -> Vec<(FileId, Range)> {
    let include_declaration = params.context.include_declaration;
    let position = params.text_document_position.position;
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let found = workspace.references(snapshot.position(&lines, position), include_declaration);
    to_proto::target_ranges(snapshot, workspace, &lines, found)
}
