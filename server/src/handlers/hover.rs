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
    let mut markdown = found.markdown;
    // On a team: its robots' iteration periods (refines the mission once
    // per version; the diagnostics task usually has already).
    if let Some(periods) = semo::dataflow::team_periods_at(&mission.mission, offset, || {
        snapshot.host().dataflow(snapshot.id)
    }) {
        markdown.push_str("\n\n---\n\n");
        markdown.push_str(&periods);
    }
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: markdown,
        }),
        range: Some(lines.range(found.range)),
    })
}
