//! `textDocument/prepareRename`: the range of the name to rename, or an error
//! saying why it cannot be renamed (a catalog name, a constant, a keyword).

use crate::world::Snapshot;
use tower_lsp_server::jsonrpc::Result;
use tower_lsp_server::ls_types::{Position, PrepareRenameResponse};

pub fn prepare_rename(
    snapshot: &Snapshot,
    position: Position,
) -> Result<Option<PrepareRenameResponse>> {
    super::with_mission(snapshot, |analysis, lines| {
        let offset = lines.offset(position);
        semo::ide::mission::rename::prepare_rename(analysis, &snapshot.text, offset)
            .map(|span| PrepareRenameResponse::Range(lines.range(span)))
            .map_err(|e| super::request_failed(e.to_string()))
    })
    .transpose()
}
