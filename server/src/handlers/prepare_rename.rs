//! `textDocument/prepareRename`: the range of the name to rename, or an error
//! saying why it cannot be renamed (a catalog name, a constant, a keyword):
//! [`semo::host::Analysis::prepare_rename`].

use crate::world::Snapshot;
use tower_lsp_server::jsonrpc::Result;
use tower_lsp_server::ls_types::{Position, PrepareRenameResponse};

pub fn prepare_rename(
    snapshot: &Snapshot,
    position: Position,
) -> Result<Option<PrepareRenameResponse>> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let Some(found) = snapshot
        .host()
        .prepare_rename(snapshot.position(&lines, position))
    else {
        return Ok(None);
    };
    let span = found.map_err(|e| super::request_failed(e.to_string()))?;
    Ok(Some(PrepareRenameResponse::Range(lines.range(span))))
}
