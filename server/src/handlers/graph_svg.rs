//! `semo/graphSvg` `{ textDocument, team? }` → `{ svg }`: the picture the CLI
//! draws, for an editor's graph view. A task graph gives `semo graph svg`'s
//! picture, a mission its mode machines (`semo graph modes`; one team's
//! with `team`). Other files, a task graph that did not load, or an unknown
//! team are refused with the reason.

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
    let analysis = snapshot.analysis();
    if let Some(run) = &analysis.graph {
        return match &run.graph {
            Some(graph) => {
                Ok(json!({ "svg": semo::taskgraph::to_svg_analyzed(graph, &run.report) }))
            }
            None => Err(super::request_failed(
                "the task graph could not be read; see its diagnostics".to_string(),
            )),
        };
    }
    if let Some(mission) = &analysis.mission {
        let mut machines = semo::modemachine::machines(&mission.mission);
        if let Some(team) = team {
            machines.retain(|m| m.team == team);
            if machines.is_empty() {
                return Err(super::request_failed(format!(
                    "no team `{team}` with modes in this mission"
                )));
            }
        }
        return Ok(json!({ "svg": semo::modemachine::to_svg(&machines) }));
    }
    Err(super::request_failed(
        "only task graphs (*.taskgraph.xml) and missions (*.mission) have a picture".to_string(),
    ))
}
