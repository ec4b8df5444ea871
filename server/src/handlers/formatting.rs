//! `textDocument/formatting`: [`semo::host::Analysis::formatting`], the
//! layout `semo fmt` writes, as one edit covering only the lines that change
//! (so the editor keeps its cursor and folds elsewhere). A mission with
//! syntax errors is not formatted: the request fails with the reason.

use crate::world::Snapshot;
use tower_lsp_server::jsonrpc::Result;
use tower_lsp_server::ls_types::TextEdit;

pub fn formatting(snapshot: &Snapshot) -> Result<Option<Vec<TextEdit>>> {
    let Some(found) = snapshot.host().formatting(snapshot.id) else {
        return Ok(None);
    };
    let edits =
        found.map_err(|refusal| super::request_failed(format!("not formatted: {refusal}")))?;
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    Ok(Some(
        edits
            .into_iter()
            .map(|e| TextEdit::new(lines.range(e.span), e.new_text))
            .collect(),
    ))
}
