//! `semo/graphSvg` `{ textDocument, team? }` → `{ svg }`: the picture the CLI
//! draws, for an editor's graph view ([`semo::host::Analysis::picture`]). A
//! task graph gives `semo graph svg`'s picture, a mission its mode machines
//! (`semo graph modes`; one team's with `team`). Other files, a task graph
//! that did not load, or an unknown team are refused with the reason.

use crate::world::Snapshot;
use serde::Deserialize;
use serde_json::{Value, json};
use tower_lsp_server::jsonrpc;
use tower_lsp_server::ls_types::TextDocumentIdentifier;

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct GraphSvgParams {
    pub text_document: TextDocumentIdentifier,
    /// For a mission: draw only this team's machine.
    #[serde(default)]
    pub team: Option<String>,
}

pub fn graph_svg(snapshot: &Snapshot, team: Option<&str>) -> jsonrpc::Result<Value> {
    match snapshot.host().picture(snapshot.id, team) {
        Ok(svg) => Ok(json!({ "svg": svg })),
        Err(refused) => Err(super::request_failed(refused.to_string())),
    }
}
