//! `semo/graphSvg` `{ textDocument, team?, kind?, robot? }` → `{ svg }`: the
//! picture the CLI draws, for an editor's graph view
//! ([`semo::host::Analysis::picture`]). A task graph gives `semo graph svg`'s
//! picture, a mission its mode machines (`semo graph modes`; one team's with
//! `team`). A mission with `kind: "taskgraph"` gives a robot's refined task
//! graph, the `taskgraph.xml` `semo build` writes
//! ([`semo::host::Analysis::robot_picture`]): `robot`'s, else the first
//! robot's, and the answer names it and every robot (`{ svg, team, robot,
//! robots }`) so that the editor can offer the others. Other files, a task
//! graph that did not load, a mission that does not refine, an unknown team
//! or robot are refused with the reason.

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
    /// For a mission: `modes` (the default) or `taskgraph` (a robot's).
    #[serde(default)]
    pub kind: Option<PictureKind>,
    /// With `kind: "taskgraph"`: the robot to draw.
    #[serde(default)]
    pub robot: Option<String>,
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum PictureKind {
    Modes,
    Taskgraph,
}

pub fn graph_svg(snapshot: &Snapshot, params: &GraphSvgParams) -> jsonrpc::Result<Value> {
    let host = snapshot.host();
    let is_mission = snapshot.kind == semo::workspace::FileKind::Mission;
    if is_mission && params.kind == Some(PictureKind::Taskgraph) {
        return match host.robot_picture(snapshot.id, params.robot.as_deref()) {
            Ok(p) => Ok(json!({
                "svg": p.svg,
                "team": p.team,
                "robot": p.robot,
                "robots": p.robots,
            })),
            Err(refused) => Err(super::request_failed(refused.to_string())),
        };
    }
    match host.picture(snapshot.id, params.team.as_deref()) {
        Ok(svg) => Ok(json!({ "svg": svg })),
        Err(refused) => Err(super::request_failed(refused.to_string())),
    }
}
