//! `textDocument/documentSymbol`: the outline, one entry per team (robots,
//! plans with their services, modes, main), functions at the top level.

use crate::encoding::LineMap;
use crate::world::Snapshot;
use semo::ide::mission::symbols::{self, SymbolKind as Kind};
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::{DocumentSymbol, DocumentSymbolResponse, SymbolKind};

pub fn document_symbol(snapshot: &Snapshot) -> Option<DocumentSymbolResponse> {
    if snapshot.kind == FileKind::Strategy {
        return super::strategy::document_symbol(snapshot);
    }
    super::with_mission(snapshot, |analysis, lines| {
        let outline = symbols::document_symbols(analysis, &snapshot.text);
        DocumentSymbolResponse::Nested(outline.iter().map(|s| convert(s, &lines)).collect())
    })
}

pub fn kind(kind: Kind) -> SymbolKind {
    match kind {
        Kind::Team => SymbolKind::CLASS,
        Kind::Robot => SymbolKind::FIELD,
        Kind::Plan => SymbolKind::NAMESPACE,
        Kind::Service | Kind::Function => SymbolKind::FUNCTION,
        Kind::Mode => SymbolKind::ENUM_MEMBER,
        Kind::Main => SymbolKind::EVENT,
    }
}

fn convert(symbol: &symbols::DocumentSymbol, lines: &LineMap<'_>) -> DocumentSymbol {
    #[allow(deprecated)] // `deprecated` must be written, even as None
    DocumentSymbol {
        name: symbol.name.clone(),
        detail: symbol.detail.clone(),
        kind: kind(symbol.kind),
        tags: None,
        deprecated: None,
        range: lines.range(symbol.span),
        selection_range: lines.range(symbol.name_span),
        children: (!symbol.children.is_empty())
            .then(|| symbol.children.iter().map(|c| convert(c, lines)).collect()),
    }
}
