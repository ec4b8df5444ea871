//! `textDocument/documentHighlight`: the names meaning the symbol at the
//! position; definitions, throws and received or assigned team variables are
//! writes, the other uses reads (`host::Analysis::highlights`).

use crate::world::Snapshot;
use semo::ide::mission::navigation::Access;
use tower_lsp_server::ls_types::{DocumentHighlight, DocumentHighlightKind, Position};

pub fn document_highlight(
    snapshot: &Snapshot,
    position: Position,
) -> Option<Vec<DocumentHighlight>> {
    super::with_mission(snapshot, |_, lines| {
        let at = snapshot.position(&lines, position);
        snapshot
            .host()
            .highlights(at)
            .into_iter()
            .map(|r| DocumentHighlight {
                range: lines.range(r.span),
                kind: Some(match r.access {
                    Access::Write => DocumentHighlightKind::WRITE,
                    Access::Read => DocumentHighlightKind::READ,
                }),
            })
            .collect::<Vec<_>>()
    })
    .filter(|found| !found.is_empty())
}
