//! `semo/monitor/start` and `semo/monitor/stop`: the live robot monitor of a
//! mission (`docs/live-monitor.md`). Start answers with the mission's
//! robots and the broker; the session (`crate::monitor`) then sends
//! `semo/monitor` notifications.
//!
//! The robots are the refined programs of the mission as the workspace
//! analysis checked it (`semo::refine::refine_checked` on the host's build
//! input, as `semo operator` and `semo.simulate` read it): a mission with
//! errors is refused. The broker: the request's `broker` (the editor's
//! setting), else the deployment file of the mission's project (`semo.toml`
//! `[build] deployment`), else `mqtt://127.0.0.1:1883`; the deployment
//! file's operator credentials are used in every case.

use crate::live;
use crate::monitor::Plan;
use crate::monitor::roster::{Member, MissionLines};
use crate::world::World;
use semo::deploy::topics::RunId;
use semo::workspace::FileKind;
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::PathBuf;
use tower_lsp_server::ls_types::Uri;

pub const START: &str = "semo/monitor/start";
pub const STOP: &str = "semo/monitor/stop";

/// The notification a session sends.
pub enum MonitorNotification {}

impl tower_lsp_server::ls_types::notification::Notification for MonitorNotification {
    type Params = Value;
    const METHOD: &'static str = "semo/monitor";
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct StartParams {
    pub uri: Uri,
    /// `mqtt://HOST[:PORT]`; empty or absent: the deployment's, else the default.
    pub broker: Option<String>,
    /// The run to show (`semo::deploy::topics::RunId`); empty or absent:
    /// the newest.
    pub run: Option<String>,
}

#[derive(Debug, Deserialize)]
pub struct StopParams {
    pub uri: Uri,
}

/// What a start works on, taken from the world at once.
pub struct Job {
    uri: Uri,
    analysis: semo::host::Analysis,
    mission: semo::diag::FileId,
    broker: Option<String>,
    run: Option<RunId>,
    deployment: Option<PathBuf>,
}

pub fn job(world: &World, params: StartParams) -> Result<Job, String> {
    let mission = world
        .snapshot(&params.uri)
        .filter(|s| s.kind == FileKind::Mission)
        .ok_or_else(|| format!("{} is not a mission the server knows", params.uri.as_str()))?;
    let run = match params.run.as_deref().map(str::trim) {
        None | Some("") => None,
        Some(run) => Some(RunId::parse(run).map_err(|why| format!("cannot monitor: {why}"))?),
    };
    let analysis = world.analysis();
    let deployment = analysis
        .project(mission.id)
        .and_then(|p| p.project.deployment.as_ref().map(|d| d.path.clone()));
    Ok(Job {
        uri: params.uri,
        analysis,
        mission: mission.id,
        broker: params.broker.filter(|b| !b.trim().is_empty()),
        run,
        deployment,
    })
}

/// The session's plan: the robots, the broker, the credentials (reads the
/// deployment file and the operator's password file: off the async threads).
pub fn plan(job: &Job) -> Result<Plan, String> {
    let refined = job
        .analysis
        .refined(job.mission)
        .ok_or("internal error: the mission is not in the workspace analysis")?;
    let errors = refined.diagnostics.iter().filter(|d| d.is_error()).count();
    if errors > 0 || refined.programs.is_empty() {
        return Err(format!(
            "cannot monitor: {errors} error(s) in the mission, its catalog or strategies"
        ));
    }
    let deployment = match &job.deployment {
        None => None,
        Some(path) => Some(
            semo::deploy::load(path, semo::diag::FileId(u32::MAX)).map_err(|found| {
                let first = found.iter().find(|d| d.is_error()).or(found.first());
                let at = first.map_or(String::new(), |d| position(path, d.span.start));
                format!(
                    "cannot monitor: the deployment file {}{at} is wrong: {}",
                    path.display(),
                    first.map_or(String::new(), |d| format!(
                        "[{}] {}",
                        d.code.as_str(),
                        d.message
                    ))
                )
            })?,
        ),
    };
    let broker = match (&job.broker, &deployment) {
        (Some(url), _) => url.trim().to_string(),
        (None, Some(d)) => d.broker.url.clone(),
        (None, None) => live::DEFAULT_BROKER.to_string(),
    };
    let access = live::BrokerAccess::new(&broker, deployment.as_ref())
        .map_err(|why| format!("cannot monitor: {why}"))?;
    let members = refined
        .programs
        .iter()
        .map(|p| Member {
            robot: p.robot.clone(),
            team: p.team.clone(),
            heartbeat_key: p
                .control
                .heartbeat
                .then(|| semo::deploy::topics::heartbeat_key(p)),
            lines: std::sync::Arc::new(MissionLines {
                modes: p
                    .control
                    .modes
                    .iter()
                    .map(|m| (m.name.clone(), m.line))
                    .collect(),
                services: (p.control.services.iter())
                    .map(|s| ((s.plan.clone(), s.name.clone()), s.line))
                    .collect(),
            }),
        })
        .collect();
    Ok(Plan {
        uri: job.uri.as_str().to_string(),
        mission: semo::deploy::topics::mission(&refined.programs[0].mission),
        run: job.run.clone(),
        broker,
        access,
        members,
        heartbeat_ms: semo::refine::HEARTBEAT_MS,
    })
}

/// `:LINE:COLUMN` (from 1) of byte `offset` in the file at `path`, as a
/// refusal names a deployment file's mistake; empty when it cannot be read.
fn position(path: &std::path::Path, offset: usize) -> String {
    let Ok(text) = semo::workspace::read_text(path) else {
        return String::new();
    };
    let at = semo::text::LineIndex::new(&text).line_col(
        &text,
        offset.min(text.len()),
        semo::text::ColumnUnit::Utf8,
    );
    format!(":{}:{}", at.line + 1, at.col + 1)
}

/// The answer to `semo/monitor/start`.
pub fn started(plan: &Plan) -> Value {
    json!({
        "mission": plan.mission,
        "run": plan.run.as_ref().map(|r| r.as_str()),
        "broker": plan.broker,
        "robots": plan.members.iter().map(|m| json!({ "robot": m.robot, "team": m.team })).collect::<Vec<_>>(),
    })
}
