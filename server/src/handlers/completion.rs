//! `textDocument/completion`: the workspace analysis'
//! [`semo::host::Analysis::completions`].

use crate::to_proto;
use crate::world::Snapshot;
use semo::host::Analysis;
use semo::ide::CompletionConfig;
use tower_lsp_server::ls_types::*;

pub fn completion(
    snapshot: &Snapshot,
    workspace: &Analysis,
    position: Position,
    config: CompletionConfig,
) -> Option<CompletionResponse> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let items = workspace.completions(snapshot.position(&lines, position), config)?;
    Some(to_proto::completion_list(items, &lines))
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
