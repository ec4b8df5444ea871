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
//! and column). The failed expectations and the scenario's warnings (a
//! sensor value no robot samples), or the scenario's mistake, are published
//! as the scenario file's diagnostics.

use crate::world::World;
use semo::sim;
use semo::text::{ColumnUnit, LineIndex};
use semo::workspace::FileKind;
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::PathBuf;
use tower_lsp_server::ls_types::{Diagnostic, DiagnosticSeverity, Position, Range, Uri};

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

/// The mission as the editor has it, wherever it is: simulating writes
/// nothing, so unlike generating code it needs no workspace root.
pub fn job(world: &World, params: SimulateParams) -> Result<Job, String> {
    let mission = world
        .snapshot(&params.uri)
        .filter(|s| s.kind == FileKind::Mission)
        .ok_or_else(|| format!("{} is not a mission the server knows", params.uri.as_str()))?;
    let folder = crate::world::file_path(&mission.uri).and_then(|p| p.parent().map(PathBuf::from));
    let scenario = match params.scenario.parse::<Uri>() {
        Ok(uri) if params.scenario.starts_with("file:") => crate::world::file_path(&uri)
            .ok_or_else(|| format!("{} is not a file", params.scenario))?,
        _ => folder
            .ok_or("a scenario path relative to an unsaved mission: give the scenario's file URI")?
            .join(&params.scenario),
    };
    Ok(Job {
        analysis: world.analysis(),
        mission: mission.id,
        scenario,
        until_ms: params.until_ms,
        seed: params.seed.unwrap_or(0),
    })
}

/// A simulation's answer, and what the editor shows on the scenario file.
pub struct Outcome {
    pub answer: Result<Value, String>,
    /// The scenario file and its diagnostics: each failed expectation, or
    /// the scenario's mistake; none when every expectation holds (which
    /// clears the last run's).
    pub scenario: Option<(Uri, Vec<Diagnostic>)>,
}

/// Refines, reads the scenario, simulates.
pub fn simulate(job: &Job) -> Outcome {
    let uri = Uri::from_file_path(&job.scenario);
    let text = match semo::workspace::read_text(&job.scenario) {
        Ok(text) => text,
        Err(e) => {
            return Outcome {
                answer: Err(format!("{}: {e}", job.scenario.display())),
                scenario: None,
            };
        }
    };
    let index = LineIndex::new(&text);
    // JSON text is ASCII around the places named (an expectation's opening
    // brace, a value's first character): UTF-16 columns are exact there.
    let at = |offset: usize| {
        let lc = index.line_col(&text, offset, ColumnUnit::Utf16);
        Range::new(
            Position::new(lc.line, lc.col),
            Position::new(lc.line, lc.col + 1),
        )
    };
    let (answer, diagnostics) = match run(job, &text) {
        Ok(Ran {
            answer,
            failed,
            warnings,
        }) => {
            let failed = failed.iter().map(|v| {
                diagnostic(
                    at(v.expectation.at_offset),
                    format!("expectation failed: {}: {}", v.expectation.kind, v.why),
                )
            });
            let warnings = warnings.into_iter().map(|w| Diagnostic {
                severity: Some(DiagnosticSeverity::WARNING),
                ..diagnostic(at(w.at), w.message)
            });
            (Ok(answer), failed.chain(warnings).collect())
        }
        Err(Refusal::Scenario(e)) => {
            let (line, col) = e.line_col(&text);
            let message = format!(
                "scenario {}:{line}:{col}: {}",
                job.scenario.display(),
                e.message
            );
            (Err(message), vec![diagnostic(at(e.at), e.message)])
        }
        Err(Refusal::Mission(message)) => (Err(message), Vec::new()),
    };
    Outcome {
        answer,
        scenario: uri.map(|uri| (uri, diagnostics)),
    }
}

fn diagnostic(range: Range, message: String) -> Diagnostic {
    Diagnostic {
        range,
        severity: Some(DiagnosticSeverity::ERROR),
        source: Some("semo simulate".into()),
        message,
        ..Diagnostic::default()
    }
}

enum Refusal {
    Mission(String),
    Scenario(sim::ScenarioError),
}

/// A simulation's answer, its failed expectations and the scenario's
/// warnings.
struct Ran {
    answer: Value,
    failed: Vec<sim::Verdict>,
    warnings: Vec<sim::ScenarioError>,
}

fn run(job: &Job, text: &str) -> Result<Ran, Refusal> {
    let refined = job.analysis.refined(job.mission).ok_or_else(|| {
        Refusal::Mission("internal error: the mission is not in the workspace analysis".into())
    })?;
    let errors = refined.diagnostics.iter().filter(|d| d.is_error()).count();
    if errors > 0 {
        return Err(Refusal::Mission(format!(
            "cannot simulate: {errors} error(s) in the mission, its catalog or strategies"
        )));
    }
    let programs = &refined.programs;
    let scenario = sim::scenario::parse(text, programs).map_err(Refusal::Scenario)?;
    let result = sim::simulate(
        programs,
        &scenario,
        &sim::Options {
            until_ms: job.until_ms,
            seed: job.seed,
            ..sim::Options::default()
        },
    );
    let verdicts = sim::expect::judge(&result, &scenario.expect);
    let index = LineIndex::new(text);
    let expectations: Vec<Value> = verdicts
        .iter()
        .map(|v| {
            let at = index.line_col(text, v.expectation.at_offset, ColumnUnit::Utf16);
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
    let answer = json!({
        "ok": verdicts.iter().all(|v| v.met),
        "summary": sim::summary(&result, &verdicts),
        "svg": sim::svg::to_svg(&result, programs, &scenario),
        "expectations": expectations,
    });
    Ok(Ran {
        answer,
        failed: verdicts.into_iter().filter(|v| !v.met).collect(),
        warnings: scenario.warnings,
    })
}
