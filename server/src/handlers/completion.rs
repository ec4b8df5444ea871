//! `textDocument/completion`: [`semo::ide::completion`] in protocol types.

use crate::world::Snapshot;
use semo::ide::completion::{self, CompletionConfig, CompletionKind};
use tower_lsp_server::ls_types::*;

pub fn completion(
    snapshot: &Snapshot,
    position: Position,
    config: CompletionConfig,
) -> Option<CompletionResponse> {
    let analysis = snapshot.analysis();
    if analysis.graph.is_some() {
        return super::taskgraph::completion(snapshot, &analysis, position);
    }
    let mission = analysis.mission.as_ref()?;
    let lines = snapshot.line_map(&analysis);
    let offset = lines.offset(position);
    let catalog = snapshot.catalog.catalog();
    let items = completion::completions(mission, catalog, &snapshot.text, offset, config);
    let items = items
        .into_iter()
        .enumerate()
        .map(|(i, item)| CompletionItem {
            kind: Some(kind(item.kind)),
            detail: item.detail,
            documentation: item.documentation.map(|value| {
                Documentation::MarkupContent(MarkupContent {
                    kind: MarkupKind::Markdown,
                    value,
                })
            }),
            // The library's order, most specific first.
            sort_text: Some(format!("{i:05}")),
            filter_text: Some(item.label.clone()),
            insert_text_format: Some(match item.snippet {
                true => InsertTextFormat::SNIPPET,
                false => InsertTextFormat::PLAIN_TEXT,
            }),
            text_edit: Some(CompletionTextEdit::Edit(TextEdit {
                range: lines.range(item.replace),
                new_text: item.insert,
            })),
            label: item.label,
            ..CompletionItem::default()
        })
        .collect();
    Some(CompletionResponse::List(CompletionList {
        is_incomplete: false,
        items,
    }))
}

fn kind(kind: CompletionKind) -> CompletionItemKind {
    match kind {
        CompletionKind::BuiltinService => CompletionItemKind::FUNCTION,
        CompletionKind::Function => CompletionItemKind::FUNCTION,
        CompletionKind::Value => CompletionItemKind::FIELD,
        CompletionKind::TeamVariable => CompletionItemKind::VARIABLE,
        CompletionKind::Team => CompletionItemKind::MODULE,
        CompletionKind::User => CompletionItemKind::MODULE,
        CompletionKind::RobotType => CompletionItemKind::CLASS,
        CompletionKind::Capability => CompletionItemKind::PROPERTY,
        CompletionKind::Plan => CompletionItemKind::STRUCT,
        CompletionKind::Service => CompletionItemKind::METHOD,
        CompletionKind::Mode => CompletionItemKind::ENUM_MEMBER,
        CompletionKind::Event => CompletionItemKind::EVENT,
        CompletionKind::Constant => CompletionItemKind::CONSTANT,
        CompletionKind::Unit => CompletionItemKind::UNIT,
        CompletionKind::Keyword => CompletionItemKind::KEYWORD,
        CompletionKind::Snippet => CompletionItemKind::SNIPPET,
    }
}

/// Whether the client can take snippets in completion items.
pub fn snippet_support(caps: &ClientCapabilities) -> bool {
    caps.text_document
        .as_ref()
        .and_then(|t| t.completion.as_ref())
        .and_then(|c| c.completion_item.as_ref())
        .and_then(|i| i.snippet_support)
        .unwrap_or(false)
}
