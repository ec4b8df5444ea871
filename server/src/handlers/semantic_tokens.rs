//! `textDocument/semanticTokens/full` and `/range`: every resolved name of a
//! mission ([`semo::host::Analysis::semantic_tokens`]) in the protocol's
//! relative encoding (`to_proto::semantic_tokens`, with the legend announced
//! at `initialize`).

use crate::to_proto;
use crate::world::Snapshot;
use tower_lsp_server::ls_types::{Range, SemanticTokens};

/// The tokens of the whole file (`range` `None`) or of a range of it.
pub fn semantic_tokens(snapshot: &Snapshot, range: Option<Range>) -> Option<SemanticTokens> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let span = range.map(|r| lines.span(r));
    let tokens = snapshot.host().semantic_tokens(snapshot.id, span)?;
    Some(to_proto::semantic_tokens(&tokens, &lines))
}
