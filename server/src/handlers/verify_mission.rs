//! `workspace/executeCommand` `semo.verify`: everything the mission's team
//! can do, explored by the library's `semo::verify` (the call `semo verify`
//! makes, with its budget), over the server's view of the workspace (open
//! documents as typed, other files from disk), on the editor's demand: the
//! commands "SeMo: Verify Mission" (VS Code) and `:SemoVerify` (Neovim).
//! The search after each save (`crate::verify`) keeps a smaller budget.
//!
//! Arguments: one object `{ "uri": mission, "expect"?: a scenario's path or
//! file URI (relative paths from the mission's folder) whose `expect` list
//! is checked over every behaviour, "faults"?, "network"?, "maxStates"?,
//! "horizonMs"? }`. Answer: `{ "exhaustive", "states", "transitions",
//! "exploredMs", "summary" (the lines `semo verify` prints), "findings":
//! [{ "code", "message", "range", "scenario" (the counterexample's scenario
//! text, or null) }], "properties": [{ "expectation", "verdict", "proof",
//! "why", "scenario" }] }`. A mission with errors, or a bad expectations
//! file (its line and column), is refused with the reason.

use crate::world::World;
use semo::workspace::FileKind;
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use tower_lsp_server::ls_types::Uri;

pub const COMMAND: &str = "semo.verify";

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct VerifyParams {
    pub uri: Uri,
    pub expect: Option<String>,
    pub faults: Option<u32>,
    pub network: Option<u32>,
    pub max_states: Option<usize>,
    pub horizon_ms: Option<i64>,
}

pub fn params(arguments: &[Value]) -> Result<VerifyParams, String> {
    let first = arguments.first().ok_or("semo.verify needs {uri}")?;
    serde_json::from_value(first.clone()).map_err(|e| e.to_string())
}

/// What one search works on, taken from the world at once.
pub struct Job {
    snapshot: Arc<crate::world::Snapshot>,
    expect: Option<PathBuf>,
    options: semo::verify::Options,
}

pub fn job(world: &World, params: VerifyParams, cancel: Arc<AtomicBool>) -> Result<Job, String> {
    let snapshot = world
        .snapshot(&params.uri)
        .filter(|s| s.kind == FileKind::Mission)
        .ok_or_else(|| format!("{} is not a mission the server knows", params.uri.as_str()))?;
    let folder = crate::world::file_path(&snapshot.uri).and_then(|p| p.parent().map(PathBuf::from));
    let expect = match params.expect {
        None => None,
        Some(given) => Some(match given.parse::<Uri>() {
            Ok(uri) if given.starts_with("file:") => {
                crate::world::file_path(&uri).ok_or_else(|| format!("{given} is not a file"))?
            }
            _ => folder
                .ok_or("an expectations path relative to an unsaved mission: give its file URI")?
                .join(&given),
        }),
    };
    let defaults = semo::verify::Options::default();
    let options = semo::verify::Options {
        faults: params.faults.unwrap_or(defaults.faults),
        network: params.network.unwrap_or(defaults.network),
        max_states: params.max_states.unwrap_or(defaults.max_states),
        horizon_ms: params.horizon_ms.unwrap_or(defaults.horizon_ms),
        cancel: Some(cancel),
        ..defaults
    };
    Ok(Job {
        snapshot,
        expect,
        options,
    })
}

/// Refines, reads the expectations, searches (`crate::verify::explore`).
pub fn verify(job: &Job) -> Result<Value, String> {
    let snapshot = &job.snapshot;
    let expectations = |programs: &[semo::refine::RobotProgram]| match &job.expect {
        None => Ok(Vec::new()),
        Some(file) => {
            let text =
                semo::workspace::read_text(file).map_err(|e| format!("{}: {e}", file.display()))?;
            let positioned = |e: semo::sim::ScenarioError| {
                let (line, column) = e.line_col(&text);
                format!("{}:{line}:{column}: {}", file.display(), e.message)
            };
            let scenario = semo::sim::scenario::parse(&text, programs).map_err(positioned)?;
            semo::verify::properties_of(&scenario.expect).map_err(positioned)
        }
    };
    let (report, refined) =
        crate::verify::explore(snapshot, &job.options, expectations).map_err(|why| match why {
            crate::verify::NoReport::Errors => {
                "the mission has errors: fix them to verify it".to_string()
            }
            crate::verify::NoReport::Refused(problem) => problem,
            crate::verify::NoReport::Cancelled => "cancelled".to_string(),
        })?;
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let programs = &refined.programs;
    let scenario_of = |way: Option<&semo::verify::Counterexample>,
                       expect: Option<&semo::sim::scenario::ExpectKind>| {
        way.map(|w| w.scenario_json_expecting(&report.inputs, programs, expect))
    };
    let findings: Vec<Value> = report
        .findings
        .iter()
        .zip(&report.counterexamples)
        .map(|(d, way)| {
            json!({
                "code": d.code.as_str(),
                "message": d.message,
                "range": lines.range(d.span),
                "scenario": scenario_of(way.as_ref(), None),
            })
        })
        .collect();
    let mut summary = vec![report.headline()];
    let properties: Vec<Value> = report
        .properties
        .iter()
        .map(|(property, outcome)| {
            let kind = &property.expectation.kind;
            summary.push(format!("property `{kind}`: {}", outcome.said()));
            let (way, proof, why) = match outcome {
                semo::verify::Outcome::Broken { way, why } => (Some(way), true, Some(why)),
                semo::verify::Outcome::Holds { proof } => (None, *proof, None),
                semo::verify::Outcome::NotJudged => (None, false, None),
            };
            json!({
                "expectation": kind.to_string(),
                "verdict": outcome.verdict(),
                "proof": proof,
                "why": why,
                "scenario": scenario_of(way, Some(kind)),
            })
        })
        .collect();
    for d in &report.findings {
        let line = lines.range(d.span).start.line + 1;
        summary.push(format!("{} line {line}: {}", d.code, d.message));
    }
    Ok(json!({
        "exhaustive": report.exhaustive,
        "states": report.states,
        "transitions": report.transitions,
        "exploredMs": report.reached_ms,
        "summary": summary.join("\n"),
        "findings": findings,
        "properties": properties,
    }))
}
