//! `textDocument/rename`: [`semo::host::Analysis::rename`], or an error
//! naming what the new name is wrong for; the caller names the files.

use crate::to_proto::{self, FileEdits};
use crate::world::Snapshot;
use semo::host::Analysis;
use tower_lsp_server::jsonrpc::Result;
use tower_lsp_server::ls_types::RenameParams;

pub fn rename(
    snapshot: &Snapshot,
    workspace: &Analysis,
    params: &RenameParams,
) -> Result<Option<FileEdits>> {
    let position = params.text_document_position.position;
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let Some(change) = workspace.rename(snapshot.position(&lines, position), &params.new_name)
    else {
        return Ok(None);
    };
    let change = change.map_err(|e| super::request_failed(e.to_string()))?;
    Ok(Some(to_proto::source_change(
        snapshot, workspace, &lines, change,
    )))
}
