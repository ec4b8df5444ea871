//! `workspace/executeCommand` `semo.generateCode`, and the code lens that runs
//! it on each team: the same library calls as `semo build` (the host's
//! `build_input`, so the same files by the same rule; refine, generate, write
//! each robot's folder atomically), over the server's view of the workspace
//! (open documents as typed, other files from disk), with `$/progress` per
//! robot.
//!
//! Arguments: one object `{ "uri": mission, "outputFolder"?: path (relative
//! to the mission's folder), "target"?: every robot's target ("linux",
//! "linux-sim", "cortex-m", "cortex-m-sim", "stm32f4", "stm32f4-sim"), "sim"?: each robot's platform
//! simulated (`semo build --sim`), "scenario"?: the scenario file compiled
//! into a simulation (relative to the mission's folder; needed by, and only
//! by, a simulation target, as `semo build --scenario`), "team"?: only this
//! team's robots, "force"?: replace files in the way, saved first (as `semo
//! build --force`) }`, or just the URI. What the arguments do not say the
//! mission's project file and catalog do, as for `semo build`: both ask the
//! host's one [`semo::host::Analysis::build_plan`] (each robot's target,
//! the output folder, and the deployment whose broker and credentials are
//! baked into the robots). The result names each robot's target.
//! Refused over files in the way, the error's `data` is `{ "conflicts":
//! [{ "path", "why" }] }`, so that an editor can offer to force.
//!
//! The output folder, with `..` and symbolic links resolved, must lie inside
//! a workspace folder (the mission's folder when there is none), and is
//! opened from that folder down without following links: the editor's
//! request, or a link swapped in meanwhile, cannot make the server write
//! anywhere else.
//!
//! Cancelling the request (`$/cancelRequest`) stops the generation before
//! its next robot, or before it replaces the first file: the folder stays
//! as it was. A cancel that comes later is too late: the generation
//! finishes, and a warning (`window/showMessage`) says the code was written. Files changed while it ran are kept and listed in the
//! result's `kept` (`[{ "path", "why" }]`).

use crate::encoding::LineMap;
use crate::world::{Snapshot, World};
use semo::build::NotBuilt;
use semo::codegen::{self, BuildResult, Emit, Target, output};
use semo::diag::{Diagnostic, FileId};
use semo::host::BuildPlan;
use semo::text::LineIndex;
use semo::workspace::FileKind;
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use tower_lsp_server::ls_types::*;

pub const COMMAND: &str = "semo.generateCode";

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct GenerateParams {
    pub uri: Uri,
    pub output_folder: Option<String>,
    pub target: Option<String>,
    #[serde(default)]
    pub sim: bool,
    pub scenario: Option<String>,
    pub team: Option<String>,
    #[serde(default)]
    pub force: bool,
}

/// Reads the command's arguments.
pub fn params(arguments: &[Value]) -> Result<GenerateParams, String> {
    let first = arguments
        .first()
        .ok_or("semo.generateCode needs the mission's URI")?;
    let params = match first {
        Value::String(uri) => GenerateParams {
            uri: uri.parse().map_err(|_| format!("`{uri}` is not a URI"))?,
            output_folder: None,
            target: None,
            sim: false,
            scenario: None,
            team: None,
            force: false,
        },
        other => serde_json::from_value(other.clone()).map_err(|e| e.to_string())?,
    };
    Ok(params)
}

/// What one generation works on, taken from the world at once.
pub struct Job {
    pub mission_uri: Uri,
    pub mission_path: PathBuf,
    /// The workspace as it was when the command came.
    pub analysis: semo::host::Analysis,
    pub mission: FileId,
    pub out: output::Confined,
    /// Each robot's target (and the output folder and deployment, as
    /// resolved).
    pub plan: BuildPlan,
    /// The deployment file to bake into the robots (`semo build --deploy`'s).
    pub deployment: Option<PathBuf>,
    /// The scenario compiled into a simulation (`semo build --scenario`'s).
    pub scenario: Option<PathBuf>,
    pub team: Option<String>,
    pub force: bool,
}

/// The mission and the workspace as they are now.
pub fn job(world: &World, params: GenerateParams) -> Result<Job, String> {
    let target = match params.target.as_deref() {
        None => None,
        Some(name) => {
            Some(Target::from_name(name).ok_or_else(|| format!("unknown target `{name}`"))?)
        }
    };
    let mission = world
        .snapshot(&params.uri)
        .filter(|s| s.kind == FileKind::Mission)
        .ok_or_else(|| format!("{} is not a mission the server knows", params.uri.as_str()))?;
    let mission_path =
        path_of(&mission).ok_or("code can only be generated for a mission saved as a file")?;
    let folder = mission_path
        .parent()
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let analysis = world.analysis();
    let plan = analysis.build_plan(
        mission.id,
        &mission_path,
        semo::host::PlanRequest {
            target,
            sim: params.sim,
            output: params.output_folder.map(|f| folder.join(f)),
            deployment: None,
        },
    );
    let requested = plan.output.clone();
    let allowed = if world.roots().is_empty() {
        std::slice::from_ref(&folder)
    } else {
        world.roots()
    };
    let out = output::confine(&requested, allowed)?;
    let scenario = match params.scenario {
        Some(named) => Some(folder.join(named)),
        None => default_scenario(&plan, &mission_path)?,
    };
    Ok(Job {
        mission_uri: params.uri,
        mission_path,
        analysis,
        mission: mission.id,
        out,
        deployment: plan.deployment.clone(),
        scenario,
        plan,
        team: params.team,
        force: params.force,
    })
}

/// A simulation's scenario when the request names none: the mission's
/// own beside it, as `semo build` and `semo simulate` choose
/// (`sim::complete::scenarios_of`); none needed when no robot is simulated.
fn default_scenario(
    plan: &semo::host::BuildPlan,
    mission: &std::path::Path,
) -> Result<Option<PathBuf>, String> {
    if !plan.robots.iter().any(|r| r.chosen.target.needs_scenario()) {
        return Ok(None);
    }
    let found = semo::sim::complete::scenarios_of(mission)
        .map_err(|e| format!("cannot look for the mission's scenario: {e}"))?;
    match found.as_slice() {
        [one] => Ok(Some(one.clone())),
        [] => Err(format!(
            "a simulation compiles a scenario into each robot: add {} beside the mission, or name one",
            semo::sim::complete::own_scenario(mission).display()
        )),
        many => Err(format!(
            "a simulation compiles a scenario into each robot: {} scenarios beside the mission, name one",
            many.len()
        )),
    }
}

fn path_of(snapshot: &Snapshot) -> Option<PathBuf> {
    crate::world::file_path(&snapshot.uri)
}

/// Checks, refines and generates (no writing yet); the mission's text too,
/// for positions.
pub fn generate(job: &Job) -> Result<(BuildResult, String), String> {
    const NO_MISSION: &str = "internal error: the mission is not in the workspace analysis";
    let text = job
        .analysis
        .file(job.mission)
        .ok_or(NO_MISSION)?
        .text
        .to_string();
    // The scenario compiled into each simulated robot (`semo build
    // --scenario`), read with the library's bounded reader, as every other
    // file the doors read.
    let scenario = match &job.scenario {
        None => None,
        Some(path) => Some(
            semo::fsread::read_text(path)
                .map_err(|e| format!("scenario {}: cannot read: {e}", path.display()))?,
        ),
    };
    // The one build every door asks (`semo build` too): a scenario's
    // mistake is the request's error, positioned.
    let built = semo::build::generate(
        &job.analysis,
        job.mission,
        &job.plan.targets(),
        Emit::All,
        scenario.as_deref(),
    );
    let mut result = match (built, &job.scenario, &scenario) {
        (Ok(built), ..) => built.result,
        (Err(NotBuilt::Scenario(e)), Some(path), Some(text)) => {
            let (line, col) = e.line_col(text);
            return Err(format!(
                "scenario {}:{line}:{col}: {}",
                path.display(),
                e.message
            ));
        }
        (Err(NotBuilt::Scenario(e)), ..) => {
            return Err(format!(
                "internal error: a scenario's mistake in a build without one: {}",
                e.message
            ));
        }
        (Err(NotBuilt::NoMission), ..) => return Err(NO_MISSION.into()),
    };
    // The plan's findings in the project file, with generation's.
    result
        .diagnostics
        .extend(job.plan.diagnostics.iter().cloned());
    // The project's deployment, baked in as `semo build` does.
    if let (Some(path), false) = (&job.deployment, result.refused()) {
        let deployment = semo::deploy::load(path, FileId(u32::MAX)).map_err(|found| {
            let first = found
                .first()
                .map_or(String::new(), |d| format!(": {}", d.message));
            format!(
                "the project's deployment file {} has {} problem(s){first} (see `semo build`)",
                path.display(),
                found.len()
            )
        })?;
        if !semo::deploy::bake(&deployment, &mut result) {
            return Err(format!(
                "target {} has no network transport to deploy",
                target_names(&result.targets())
            ));
        }
    }
    if let Some(team) = &job.team {
        result.robots.retain(|r| &r.team == team);
        // The runtime the team's robots compile, not the others'.
        if !result.runtime.is_empty() {
            result.runtime = codegen::runtime_files(&result.targets());
        }
    }
    Ok((result, text))
}

/// The refusal's diagnostics in the mission, for publishing.
pub fn mission_diagnostics(
    job: &Job,
    text: &str,
    diagnostics: &[Diagnostic],
    encoding: crate::encoding::Encoding,
) -> Vec<tower_lsp_server::ls_types::Diagnostic> {
    let index = LineIndex::new(text);
    let map = LineMap {
        text,
        index: &index,
        encoding,
    };
    diagnostics
        .iter()
        .filter(|d| d.file == job.mission)
        .map(|d| tower_lsp_server::ls_types::Diagnostic {
            source: Some("semo build".into()),
            ..crate::to_proto::diagnostic(d, map.range(d.span))
        })
        .collect()
}

/// A robot's line in the result.
pub fn robot_summary(robot: &codegen::RobotOutput, written: &output::Written) -> Value {
    let (generated, user) = robot.line_counts();
    let paths = |list: &[PathBuf]| -> Vec<String> {
        list.iter().map(|p| p.display().to_string()).collect()
    };
    json!({
        "backedUp": paths(&written.backed_up),
        "leftAlone": paths(&written.left_alone),
        "team": robot.team,
        "robot": robot.robot,
        "target": robot.target.name(),
        "folder": written.folder.display().to_string(),
        "generatedFiles": written.generated,
        "taskFilesCreated": written.created,
        "taskFilesKept": written.kept,
        "linesGenerated": generated,
        "linesInTaskFiles": user,
    })
}

/// A code lens on each team's name in the formation: generate its robots' code.
pub fn code_lenses(snapshot: &Snapshot) -> Vec<CodeLens> {
    super::with_mission(snapshot, |analysis, map| {
        analysis
            .mission
            .teams
            .iter()
            .filter(|t| !t.robots.is_empty())
            .map(|team| CodeLens {
                range: map.range(team.name_span),
                command: Some(Command {
                    title: format!("▶ Generate code for {}", team.name),
                    command: COMMAND.to_string(),
                    arguments: Some(vec![json!({
                        "uri": snapshot.uri.as_str(),
                        "team": team.name.as_str(),
                    })]),
                }),
                data: None,
            })
            .collect()
    })
    .unwrap_or_default()
}

/// Why a generation did not begin: the message, and for files in the way
/// their list `{ "conflicts": [{ "path", "why" }] }` (the JSON-RPC error's
/// `data`, so that an editor can offer to back them up and force).
pub struct NotBegun {
    pub message: String,
    pub data: Option<Value>,
}

/// Takes the output folder's lock (waiting for another generation) and
/// recovers what an interrupted one left; then checks, unless forced, that no
/// robot folder (nor the runtime's) holds files in the way, and stages the
/// runtime's folder the robots share. Blocking: run off the async threads.
pub fn begin(job: &Job, build: &codegen::BuildResult) -> Result<output::Transaction, NotBegun> {
    let failed = |e: output::OutputError| NotBegun {
        message: e.to_string(),
        data: None,
    };
    let mut transaction =
        output::Transaction::begin_inside(&job.out.root, &job.out.rel, || {}).map_err(failed)?;
    if !job.force {
        let conflicts = transaction
            .conflicts(&build.robots, &build.runtime)
            .map_err(failed)?;
        if !conflicts.is_empty() {
            let data = json!({
                "conflicts": conflicts
                    .iter()
                    .map(|c| json!({ "path": c.path.display().to_string(), "why": c.why }))
                    .collect::<Vec<_>>(),
            });
            return Err(NotBegun {
                message: output::OutputError::Conflicts(conflicts).to_string(),
                data: Some(data),
            });
        }
    }
    transaction
        .stage_runtime(&build.runtime, &build.targets(), job.force)
        .map_err(failed)?;
    Ok(transaction)
}

/// `linux`, or `cortex-m and linux-sim`.
pub fn target_names(targets: &[Target]) -> String {
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    names.join(" and ")
}
