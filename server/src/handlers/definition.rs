//! `textDocument/definition`: from a name to where its symbol is defined, in
//! the mission or in a workspace catalog file (see `semo::ide::navigation`),
//! and from a built-in call to the strategy entries refining it; in strategy
//! files, see [`super::strategy`].

use crate::encoding::LineMap;
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::text::LineIndex;
use semo::workspace::FileKind;
use std::collections::HashMap;
use std::sync::Arc;
use tower_lsp_server::ls_types::{GotoDefinitionResponse, Location, Position, Range, Uri};

/// The definitions of the name at `position`, as ranges of files by id
/// (the caller maps ids to URIs under the world lock). From a mission's
/// built-in call: the entries of the `strategies` refining it first, then
/// the service in the catalog.
pub fn definition(
    snapshot: &Snapshot,
    strategies: &[Arc<Snapshot>],
    position: Position,
) -> Vec<(FileId, Range)> {
    if snapshot.kind == FileKind::Strategy {
        return super::strategy::definition(snapshot, position);
    }
    super::with_mission(snapshot, |analysis, lines| {
        let offset = lines.offset(position);
        let catalog = &snapshot.catalog;
        let targets = semo::ide::navigation::definition(analysis, catalog.catalog(), offset);
        let mut indexes: HashMap<FileId, LineIndex> = HashMap::new();
        let entries = super::strategy::entries_of_call(snapshot, strategies, offset);
        entries
            .into_iter()
            .chain(targets.into_iter().filter_map(|target| {
                if target.file == snapshot.id {
                    return Some((target.file, lines.range(target.span)));
                }
                let text = catalog.text_of(target.file)?;
                let index = indexes
                    .entry(target.file)
                    .or_insert_with(|| LineIndex::new(text));
                let map = LineMap {
                    text,
                    index,
                    encoding: snapshot.encoding,
                };
                Some((target.file, map.range(target.span)))
            }))
            .collect()
    })
    .unwrap_or_default()
}

/// The protocol answer: one location, several, or none.
pub fn response(
    found: Vec<(FileId, Range)>,
    uri_of: impl Fn(FileId) -> Option<Uri>,
) -> Option<GotoDefinitionResponse> {
    let mut locations: Vec<Location> = found
        .into_iter()
        .filter_map(|(file, range)| Some(Location::new(uri_of(file)?, range)))
        .collect();
    match locations.len() {
        0 => None,
        1 => locations.pop().map(GotoDefinitionResponse::Scalar),
        _ => Some(GotoDefinitionResponse::Array(locations)),
    }
}
