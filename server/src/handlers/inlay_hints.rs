//! `textDocument/inlayHint`: [`semo::ide::mission::inlay_hints`] in protocol types.

use crate::world::Snapshot;
use semo::ide::mission::inlay_hints::InlayKind;
use tower_lsp_server::ls_types::*;

pub fn inlay_hints(snapshot: &Snapshot, range: Range) -> Option<Vec<InlayHint>> {
    let analysis = snapshot.analysis();
    if analysis.graph.is_some() {
        return Some(super::taskgraph::inlay_hints(snapshot, &analysis, range));
    }
    let mission = analysis.mission.as_ref()?;
    let lines = snapshot.line_map(&analysis);
    let span = lines.span(range);
    let catalog = snapshot.catalog.catalog();
    let hints =
        semo::ide::mission::inlay_hints::inlay_hints(mission, catalog, &snapshot.text, span);
    Some(
        hints
            .into_iter()
            .map(|h| InlayHint {
                position: lines.position(h.offset),
                label: InlayHintLabel::String(h.label),
                kind: Some(match h.kind {
                    InlayKind::Robots => InlayHintKind::PARAMETER,
                    InlayKind::Schedule => InlayHintKind::TYPE,
                }),
                text_edits: None,
                tooltip: h.tooltip.map(|value| {
                    InlayHintTooltip::MarkupContent(MarkupContent {
                        kind: MarkupKind::Markdown,
                        value,
                    })
                }),
                padding_left: Some(false),
                padding_right: Some(false),
                data: None,
            })
            .collect(),
    )
}
