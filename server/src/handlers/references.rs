//! `textDocument/references`: every name of the mission meaning the symbol at
//! the position; its definitions only if the client asks for declarations.

use crate::world::Snapshot;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::{Location, ReferenceParams};

pub fn references(snapshot: &Snapshot, params: &ReferenceParams) -> Option<Vec<Location>> {
    let include_declaration = params.context.include_declaration;
    let position = params.text_document_position.position;
    if snapshot.kind == FileKind::Strategy {
        let found = super::strategy::references(snapshot, position, include_declaration);
        return (!found.is_empty()).then_some(found);
    }
    super::with_mission(snapshot, |analysis, lines| {
        let offset = lines.offset(position);
        semo::ide::mission::navigation::references(analysis, offset)
            .into_iter()
            .filter(|r| include_declaration || !r.is_definition)
            .map(|r| Location::new(snapshot.uri.clone(), lines.range(r.span)))
            .collect::<Vec<_>>()
    })
    .filter(|found| !found.is_empty())
}
