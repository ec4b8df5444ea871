//! `workspace/symbol`: the teams, composite services, modes and functions of
//! every mission the server knows (open, or indexed from the workspace
//! folders) whose name matches the query, best matches first.

use crate::world::Snapshot;
use semo::workspace::FileKind;
use std::sync::Arc;
use tower_lsp_server::ls_types::{Location, SymbolInformation};

/// At most this many symbols are returned (the client asks again as the
/// query grows).
pub const LIMIT: usize = 128;

pub fn workspace_symbol(snapshots: &[Arc<Snapshot>], query: &str) -> Vec<SymbolInformation> {
    let mut found: Vec<(u32, SymbolInformation)> = Vec::new();
    for snapshot in snapshots.iter().filter(|s| s.kind == FileKind::Mission) {
        super::with_mission(snapshot, |analysis, lines| {
            for symbol in semo::ide::mission::symbols::workspace_symbols(analysis, query) {
                #[allow(deprecated)] // `deprecated` must be written, even as None
                let info = SymbolInformation {
                    name: symbol.name,
                    kind: super::document_symbol::kind(symbol.kind),
                    tags: None,
                    deprecated: None,
                    location: Location::new(snapshot.uri.clone(), lines.range(symbol.name_span)),
                    container_name: symbol.container,
                };
                found.push((symbol.score, info));
            }
        });
    }
    found.sort_by(|(a, x), (b, y)| {
        (a, &x.name, x.location.uri.as_str(), x.location.range.start).cmp(&(
            b,
            &y.name,
            y.location.uri.as_str(),
            y.location.range.start,
        ))
    });
    found.truncate(LIMIT);
    found.into_iter().map(|(_, info)| info).collect()
}
