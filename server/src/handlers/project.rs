//! Completion in `semo.toml`: [`semo::project::completions`] in protocol
//! types (its diagnostics come from the workspace analysis as every file's).

use crate::world::Snapshot;
use semo::project::{self, CompletionKind};
use tower_lsp_server::ls_types::*;

pub fn completion(snapshot: &Snapshot, position: Position) -> CompletionResponse {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let offset = lines.offset(position);
    let items = project::completions(&snapshot.text, offset)
        .into_iter()
        .enumerate()
        .map(|(i, item)| CompletionItem {
            kind: Some(match item.kind {
                CompletionKind::Table => CompletionItemKind::MODULE,
                CompletionKind::Key => CompletionItemKind::PROPERTY,
                CompletionKind::Code => CompletionItemKind::CONSTANT,
                CompletionKind::Value => CompletionItemKind::VALUE,
            }),
            detail: Some(item.detail),
            insert_text_format: Some(InsertTextFormat::PLAIN_TEXT),
            ..super::completion::in_order(i, item.label, lines.range(item.replace), item.insert)
        })
        .collect();
    super::completion::list(items)
}
