//! Inlay hints in `*.taskgraph.xml` files: [`semo::ide::taskgraph`] in
//! protocol types.

use crate::world::{FileAnalysis, Snapshot};
use semo::ide::taskgraph as ide;
use tower_lsp_server::ls_types::*;

/// The graph and its report, when the file is a task graph that loaded.
fn loaded(
    analysis: &FileAnalysis,
) -> Option<(
    &semo::taskgraph::TaskGraph,
    &semo::taskgraph::analysis::GraphReport,
)> {
    let run = analysis.graph.as_ref()?;
    Some((run.graph.as_ref()?, &run.report))
}

pub fn inlay_hints(snapshot: &Snapshot, analysis: &FileAnalysis, range: Range) -> Vec<InlayHint> {
    let Some((graph, report)) = loaded(analysis) else {
        return Vec::new();
    };
    let lines = snapshot.line_map(analysis);
    let wanted = lines.span(range);
    ide::inlay_hints(graph, report)
        .into_iter()
        .filter(|h| wanted.touches(h.offset))
        .map(|h| InlayHint {
            // After the closing quote of the name.
            position: lines.position(h.offset + 1),
            label: InlayHintLabel::String(h.label),
            kind: Some(InlayHintKind::TYPE),
            text_edits: None,
            tooltip: Some(InlayHintTooltip::String(
                "firings per iteration of this level (repetition vector)".to_string(),
            )),
            padding_left: Some(true),
            padding_right: Some(false),
            data: None,
        })
        .collect()
}
