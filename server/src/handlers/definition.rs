//! `textDocument/definition`: from a name to where its symbol is defined, in
//! the mission or in a workspace catalog file (see `semo::ide::navigation`),
//! and from a built-in call to the strategy entries refining it; in a task
//! graph, from a `subgraph` attribute to the file it names; in strategy files,
//! see [`super::strategy`].

use crate::encoding::LineMap;
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::text::LineIndex;
use semo::workspace::FileKind;
use std::collections::HashMap;
use std::sync::Arc;
use tower_lsp_server::ls_types::{GotoDefinitionResponse, Location, Position, Range, Uri};

/// Where a definition is: a file the world knows by id (the caller maps ids
/// to URIs under the world lock), or a file by its URI.
pub enum Place {
    File(FileId),
    Uri(Uri),
}

/// The definitions of the name at `position`. From a mission's built-in
/// call: the entries of the `strategies` refining it first, then the service
/// in the catalog.
pub fn definition(
    snapshot: &Snapshot,
    strategies: &[Arc<Snapshot>],
    position: Position,
) -> Vec<(Place, Range)> {
    if let Some(found) = sub_graph_file(snapshot, position) {
        return vec![(Place::Uri(found), Range::default())];
    }
    let found = if snapshot.kind == FileKind::Strategy {
        super::strategy::definition(snapshot, position)
    } else {
        mission_definition(snapshot, strategies, position)
    };
    found
        .into_iter()
        .map(|(file, range)| (Place::File(file), range))
        .collect()
}

/// On the value of a task's `subgraph` attribute: the file it names, when
/// it could be read (the start of the file is its definition).
fn sub_graph_file(snapshot: &Snapshot, position: Position) -> Option<Uri> {
    let analysis = snapshot.analysis();
    let run = analysis.graph.as_ref()?;
    let offset = snapshot.line_map(&analysis).offset(position);
    let reference = run
        .hierarchy
        .references
        .iter()
        .find(|r| r.readable && r.span.touches(offset))?;
    Uri::from_file_path(&reference.location)
}

fn mission_definition(
    snapshot: &Snapshot,
    strategies: &[Arc<Snapshot>],
    position: Position,
) -> Vec<(FileId, Range)> {
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
    found: Vec<(Place, Range)>,
    uri_of: impl Fn(FileId) -> Option<Uri>,
) -> Option<GotoDefinitionResponse> {
    let mut locations: Vec<Location> = found
        .into_iter()
        .filter_map(|(place, range)| {
            let uri = match place {
                Place::File(file) => uri_of(file)?,
                Place::Uri(uri) => uri,
            };
            Some(Location::new(uri, range))
        })
        .collect();
    match locations.len() {
        0 => None,
        1 => locations.pop().map(GotoDefinitionResponse::Scalar),
        _ => Some(GotoDefinitionResponse::Array(locations)),
    }
}
