//! Hover, completion and inlay hints in `*.taskgraph.xml` files:
//! [`semo::taskgraph::ide`] in protocol types. The request handlers for
//! missions hand task-graph files over to these.

use crate::world::{FileAnalysis, Snapshot};
use semo::taskgraph::ide;
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

pub fn hover(snapshot: &Snapshot, analysis: &FileAnalysis, position: Position) -> Option<Hover> {
    let (graph, report) = loaded(analysis)?;
    let lines = snapshot.line_map(analysis);
    let found = ide::hover(graph, report, lines.offset(position))?;
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: found.markdown,
        }),
        range: Some(lines.range(found.span)),
    })
}

pub fn completion(
    snapshot: &Snapshot,
    analysis: &FileAnalysis,
    position: Position,
) -> Option<CompletionResponse> {
    let (graph, _) = loaded(analysis)?;
    let lines = snapshot.line_map(analysis);
    let (replace, items) = ide::complete_endpoint(&snapshot.text, graph, lines.offset(position))?;
    let range = lines.range(replace);
    let items = items
        .into_iter()
        .enumerate()
        .map(|(i, item)| CompletionItem {
            kind: Some(CompletionItemKind::FIELD),
            detail: Some(item.detail),
            ..super::completion::in_order(i, item.label.clone(), range, item.label)
        })
        .collect();
    Some(super::completion::list(items))
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
