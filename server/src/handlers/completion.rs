//! `textDocument/completion`: [`semo::ide::completion`] in protocol types.

use crate::world::Snapshot;
use semo::ide::completion::{self, CompletionConfig, CompletionKind};
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::*;

pub fn completion(
    snapshot: &Snapshot,
    position: Position,
    config: CompletionConfig,
) -> Option<CompletionResponse> {
    if snapshot.kind == FileKind::Project {
        return Some(super::project::completion(snapshot, position));
    }
    if snapshot.kind == FileKind::Strategy {
        return Some(super::strategy::completion(
            snapshot,
            position,
            config.snippets,
        ));
    }
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
            insert_text_format: Some(match item.snippet {
                true => InsertTextFormat::SNIPPET,
                false => InsertTextFormat::PLAIN_TEXT,
            }),
            ..in_order(i, item.label, lines.range(item.replace), item.insert)
        })
        .collect();
    Some(list(items))
}

/// An item that replaces `range` by `new_text`, kept in the library's order
/// (most specific first) rather than the editor's alphabetical one.
pub(super) fn in_order(
    index: usize,
    label: String,
    range: Range,
    new_text: String,
) -> CompletionItem {
    CompletionItem {
        sort_text: Some(format!("{index:05}")),
        filter_text: Some(label.clone()),
        text_edit: Some(CompletionTextEdit::Edit(TextEdit { range, new_text })),
        label,
        ..CompletionItem::default()
    }
}

/// A complete list: the server sends every candidate, the editor filters.
pub(super) fn list(items: Vec<CompletionItem>) -> CompletionResponse {
    CompletionResponse::List(CompletionList {
        is_incomplete: false,
        items,
    })
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
