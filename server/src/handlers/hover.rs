//! `textDocument/hover`: [`semo::ide::hover`] in protocol types.

use crate::world::Snapshot;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::*;

pub fn hover(snapshot: &Snapshot, position: Position) -> Option<Hover> {
    if snapshot.kind == FileKind::Strategy {
        return super::strategy::hover(snapshot, position);
    }
    let analysis = snapshot.analysis();
    if analysis.graph.is_some() {
        return super::taskgraph::hover(snapshot, &analysis, position);
    }
    let mission = analysis.mission.as_ref()?;
    let lines = snapshot.line_map(&analysis);
    let offset = lines.offset(position);
    let catalog = snapshot.catalog.catalog();
    let found = semo::ide::hover::hover(mission, catalog, &snapshot.text, offset)?;
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: found.markdown,
        }),
        range: Some(lines.range(found.range)),
    })
}
