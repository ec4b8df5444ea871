//! `workspace/executeCommand` `semo.simulate`: the mission's robots run on a
//! scenario by the library's simulator (`semo::sim`, the same call as
//! `semo simulate`), over the server's view of the workspace (open documents
//! as typed, other files from disk: the workspace analysis `semo.generateCode` reads).
//!
//! Arguments: one object `{ "uri": mission, "scenario": path or file URI
//! (relative paths from the mission's folder), "untilMs"?: mission ms,
//! "seed"?: number }`. Answer: `{ "ok", "summary" (the text `semo simulate`
//! prints), "svg" (the timeline), "expectations": [{ "expectation", "met",
//! "why", "range" (the expectation in the scenario file) }] }`. A mission with
//! errors or a bad scenario is refused with the reason (the scenario's line
//! and column).

use super::generate_code::{self, GenerateParams};
use crate::world::World;
use semo::sim;
use semo::text::{ColumnUnit, LineIndex};
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::PathBuf;
use tower_lsp_server::ls_types::Uri;

pub const COMMAND: &str = "semo.simulate";

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SimulateParams {
    pub uri: Uri,
    pub scenario: String,
    pub until_ms: Option<i64>,
    pub seed: Option<u64>,
}

pub fn params(arguments: &[Value]) -> Result<SimulateParams, String> {
    let first = arguments
        .first()
        .ok_or("semo.simulate needs {uri, scenario}")?;
    serde_json::from_value(first.clone()).map_err(|e| e.to_string())
}

/// What one simulation works on, taken from the world at once.
pub struct Job {
    /// The workspace as it was when the command came (open documents as typed).
    analysis: semo::host::Analysis,
    mission: semo::diag::FileId,
    scenario: PathBuf,
    until_ms: Option<i64>,
    seed: u64,
}

pub fn job(world: &World, params: SimulateParams) -> Result<Job, String> {
    let generate = generate_code::job(
        world,
        GenerateParams {
            uri: params.uri,
            output_folder: None,
            target: None,
            team: None,
            force: false,
        },
    )?;
    let folder = generate
        .mission_path
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default();
    let scenario = match params.scenario.parse::<Uri>() {
        Ok(uri) if params.scenario.starts_with("file:") => uri
            .to_file_path()
            .map(|p| p.into_owned())
            .ok_or_else(|| format!("{} is not a file", params.scenario))?,
        _ => folder.join(&params.scenario),
    };
    Ok(Job {
        analysis: generate.analysis,
        mission: generate.mission,
        scenario,
        until_ms: params.until_ms,
        seed: params.seed.unwrap_or(0),
    })
}

/// Refines, reads the scenario, simulates; the answer or the reason for refusing.
pub fn simulate(job: &Job) -> Result<Value, String> {
    let text = semo::workspace::read_text(&job.scenario)
        .map_err(|e| format!("{}: {e}", job.scenario.display()))?;
    let build = job
        .analysis
        .build_input(job.mission)
        .ok_or("internal error: the mission is not in the workspace analysis")?;
    let refined = semo::codegen::refine_checked(&build.input());
    let errors = refined.diagnostics.iter().filter(|d| d.is_error()).count();
    if errors > 0 {
        return Err(format!(
            "cannot simulate: {errors} error(s) in the mission, its catalog or strategies"
        ));
    }
    let programs = refined.programs;
    let scenario = sim::scenario::parse(&text, &programs).map_err(|e| {
        let (line, col) = e.line_col(&text);
        format!(
            "scenario {}:{line}:{col}: {}",
            job.scenario.display(),
            e.message
        )
    })?;
    let result = sim::simulate(
        &programs,
        &scenario,
        &sim::Options {
            until_ms: job.until_ms,
            seed: job.seed,
        },
    );
    let verdicts = sim::expect::judge(&result, &scenario.expect);
    let index = LineIndex::new(&text);
    let expectations: Vec<Value> = verdicts
        .iter()
        .map(|v| {
            // JSON text is ASCII around an expectation's opening brace, and
            // the brace is one character: UTF-16 columns are exact here.
            let at = index.line_col(&text, v.expectation.at_offset, ColumnUnit::Utf16);
            json!({
                "expectation": v.expectation.kind.to_string(),
                "met": v.met,
                "why": v.why,
                "range": {
                    "start": {"line": at.line, "character": at.col},
                    "end": {"line": at.line, "character": at.col + 1},
                },
            })
        })
        .collect();
    Ok(json!({
        "ok": verdicts.iter().all(|v| v.met),
        "summary": sim::summary(&result, &verdicts),
        "svg": sim::svg::to_svg(&result, &programs, &scenario),
        "expectations": expectations,
    }))
}
