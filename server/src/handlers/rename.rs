//! `textDocument/rename`: one edit per name meaning the renamed symbol, all in
//! the mission (a mission is self-contained), or an error naming what the new
//! name is wrong for.

use crate::world::Snapshot;
use std::collections::HashMap;
use tower_lsp_server::jsonrpc::Result;
use tower_lsp_server::ls_types::{RenameParams, TextEdit, WorkspaceEdit};

pub fn rename(snapshot: &Snapshot, params: &RenameParams) -> Result<Option<WorkspaceEdit>> {
    let position = params.text_document_position.position;
    super::with_mission(snapshot, |analysis, lines| {
        let offset = lines.offset(position);
        let catalog = snapshot.catalog.catalog();
        let spans = semo::ide::mission::rename::rename(
            analysis,
            catalog,
            &snapshot.text,
            offset,
            &params.new_name,
        )
        .map_err(|e| super::request_failed(e.to_string()))?;
        let edits = spans
            .into_iter()
            .map(|span| TextEdit::new(lines.range(span), params.new_name.clone()))
            .collect();
        Ok(WorkspaceEdit {
            changes: Some(HashMap::from([(snapshot.uri.clone(), edits)])),
            ..WorkspaceEdit::default()
        })
    })
    .transpose()
}
