//! `textDocument/hover`: the workspace analysis' [`semo::host::Analysis::hover`].

use crate::to_proto;
use crate::world::Snapshot;
use semo::host::Analysis;
use tower_lsp_server::ls_types::*;

pub fn hover(snapshot: &Snapshot, workspace: &Analysis, position: Position) -> Option<Hover> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let found = workspace.hover(snapshot.position(&lines, position))?;
    Some(to_proto::hover(found, &lines))
}
