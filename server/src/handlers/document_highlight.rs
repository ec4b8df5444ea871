//! `textDocument/documentHighlight`: the names meaning the symbol at the
//! position; definitions, throws and received or assigned team variables are
//! writes, the other uses reads (`host::Analysis::highlights`).

use crate::to_proto;
use crate::world::Snapshot;
use tower_lsp_server::ls_types::{DocumentHighlight, Position};

pub fn document_highlight(
    snapshot: &Snapshot,
    position: Position,
) -> Option<Vec<DocumentHighlight>> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let found = snapshot
        .host()
        .highlights(snapshot.position(&lines, position));
    (!found.is_empty()).then(|| to_proto::highlights(found, &lines))
}
