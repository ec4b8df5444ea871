//! `textDocument/documentSymbol`: the outline (`host::Analysis::document_symbols`):
//! a mission's teams (robots, plans with their services, modes, main) and
//! functions, a strategy file's values and services with their actions.

use crate::to_proto;
use crate::world::Snapshot;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::DocumentSymbolResponse;

pub fn document_symbol(snapshot: &Snapshot) -> Option<DocumentSymbolResponse> {
    if !matches!(snapshot.kind, FileKind::Mission | FileKind::Strategy) {
        return None;
    }
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let outline = snapshot.host().document_symbols(snapshot.id);
    Some(to_proto::document_symbols(outline, &lines))
}
