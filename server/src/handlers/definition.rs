//! `textDocument/definition`: [`semo::host::Analysis::definition`]; in a task
//! graph, from a `subgraph` attribute to the file it names.

use crate::to_proto;
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::host::Analysis;
use tower_lsp_server::ls_types::{GotoDefinitionResponse, Location, Position, Range, Uri};

/// Where a definition is: a file the world knows by id (the caller maps ids
/// to URIs under the world lock), or a file by its URI.
pub enum Place {
    File(FileId),
    Uri(Uri),
}

/// The definitions of the name at `position` (see
/// [`semo::host::Analysis::definition`]); on a task's `subgraph`, the file it
/// names.
pub fn definition(
    snapshot: &Snapshot,
    workspace: &Analysis,
    position: Position,
) -> Vec<(Place, Range)> {
    if let Some(found) = sub_graph_file(snapshot, position) {
        return vec![(Place::Uri(found), Range::default())];
    }
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let targets = workspace.definition(snapshot.position(&lines, position));
    to_proto::target_ranges(snapshot, workspace, &lines, targets)
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
