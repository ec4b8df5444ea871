//! `semo build`: a mission, its strategy files and the catalog → one folder of
//! C code (and the refined task graph) per robot.

use super::input::{self, Content};
use super::output::{self, Format, Record};
use semo::codegen::output::{OutputError, Transaction};
use semo::codegen::{Emit, Target};
use semo::host;
use semo::targets::{Chosen, Reason};
use std::io::Write;
use std::path::PathBuf;

pub struct Options {
    /// Else the project's one mission (`defaults::mission`).
    pub mission: Option<PathBuf>,
    pub strategy: Vec<PathBuf>,
    /// Else the project file's `[build] output`, else `out` beside the mission.
    pub out: Option<PathBuf>,
    /// Every robot's target; else each robot's own (the build plan:
    /// the project file, the robot type's platform, `linux`).
    pub target: Option<Target>,
    /// Each robot built for its platform's simulation.
    pub sim: bool,
    /// Compiled into each robot whose target needs it (`cortex-m-sim`).
    pub scenario: Option<PathBuf>,
    pub emit: Emit,
    pub format: Format,
    pub color: bool,
    /// Replace files in the way (saved to the backup folder first).
    pub force: bool,
    /// A deployment file baked into every robot folder.
    pub deploy: Option<PathBuf>,
}

const BUILD: &str = "semo build";

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let started = std::time::Instant::now();
    let mission_file = match super::defaults::mission_file(
        options.mission.clone(),
        &options.strategy,
        "build",
        (", `out/` beside it", ""),
        options.format,
        out,
    ) {
        Ok(found) => found,
        Err(code) => return code,
    };
    let (mut run, mission) = match super::defaults::load(&mission_file, &options.strategy) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    // What the command line does not say, the project file does (the plan
    // the editor's Generate Code asks for too).
    let plan = run.analysis().build_plan(
        mission,
        &mission_file,
        host::PlanRequest {
            target: options.target,
            sim: options.sim,
            output: options.out.clone(),
            deployment: options.deploy.clone(),
        },
    );
    let targets = plan.distinct_targets();
    let out_dir = plan.output.clone();
    // The plan's findings in the project file (a `[build.targets]` name the
    // mission does not have) are printed with the mission's.
    run.diagnostics.extend(plan.diagnostics.iter().cloned());
    let compiled_in: Vec<&host::PlannedRobot> = plan
        .robots
        .iter()
        .filter(|r| r.chosen.target.needs_scenario())
        .collect();
    if options.scenario.is_some() && compiled_in.is_empty() {
        eprintln!(
            "error: --scenario is compiled into simulations only (targets linux-sim, cortex-m-sim, stm32f4-sim, or --sim), and no robot of this build is built for one (target {})",
            names(&targets)
        );
        return 2;
    }
    // A simulation's scenario: the command line's, else the mission's own
    // (`<mission>.scenario.json`, as `semo simulate` and the editor choose).
    let scenario_path = match (&options.scenario, compiled_in.is_empty()) {
        (_, true) => None,
        (Some(path), false) => Some(path.clone()),
        (None, false) => match super::defaults::scenario(&mission_file) {
            Ok(path) => Some(path),
            Err(no) => {
                let robots: Vec<&str> = compiled_in.iter().map(|r| r.robot.as_str()).collect();
                let mut sims: Vec<&str> =
                    compiled_in.iter().map(|r| r.chosen.target.name()).collect();
                sims.sort_unstable();
                sims.dedup();
                let (targets, compile) = match sims.len() {
                    1 => ("target", "compiles"),
                    _ => ("targets", "compile"),
                };
                eprintln!(
                    "error: {targets} {} {compile} a scenario into each robot ({}): {}",
                    sims.join(", "),
                    robots.join(", "),
                    no.message
                );
                return 2;
            }
        },
    };
    // Read before anything is written, so that a wrong file stops the
    // build before the output folder is touched (`-`: standard input).
    let scenario = match &scenario_path {
        None => None,
        Some(path) => match input::read(path) {
            Some((name, text)) if input::is_kind(&name, &text, Content::Scenario, BUILD) => {
                Some((name, text))
            }
            _ => return 2,
        },
    };
    // The deployment file: the command line's, else the project file's.
    let deploy_path = plan.deployment.clone();
    let deployment = match &deploy_path {
        None => None,
        Some(path) => {
            match super::deploy::load(&mut run, path, options.format, options.color, out) {
                Ok(deployment) => Some(deployment),
                Err(code) => return code,
            }
        }
    };
    if let Some(deployment) = &deployment {
        // The checked mission the deployment is checked against (the
        // build below asks the host for its own input).
        let files = match super::build_files(&run.analysis(), mission) {
            Ok(files) => files,
            Err(code) => return code,
        };
        let found = semo::deploy::check(deployment, &files.input().analysis.mission);
        if found.iter().any(|d| d.is_error()) {
            drop(files);
            return super::deploy::refuse(&mut run, found, options.format, options.color, out);
        }
    }
    // The one build every door asks: the host's refined mission, the
    // scenario compiled into each simulated robot.
    let scenario_text = scenario.as_ref().map(|(_, text)| text.as_str());
    let built = semo::build::generate(
        &run.analysis(),
        mission,
        &plan.targets(),
        options.emit,
        scenario_text,
    );
    let mut result = match (built, &scenario) {
        (Ok(built), _) => {
            if let Some((name, text)) = &scenario {
                // For people, whatever the format: the build's document
                // has no place for a scenario's warnings.
                for warning in built.scenario_warnings {
                    let record =
                        Record::scenario(name, text, warning, semo::diag::Severity::Warning);
                    eprintln!("{}", record.scenario_line());
                }
            }
            built.result
        }
        (Err(semo::build::NotBuilt::Scenario(e)), Some((name, text))) => {
            let record = Record::scenario(name, text, e, semo::diag::Severity::Error);
            report_scenario(&record, options.format, out);
            return 2;
        }
        (Err(semo::build::NotBuilt::NoMission), _) => {
            eprintln!("internal error: the mission was loaded but not checked");
            return 2;
        }
        (Err(semo::build::NotBuilt::Scenario(e)), None) => {
            eprintln!(
                "internal error: a scenario's mistake in a build without one: {}",
                e.message
            );
            return 2;
        }
    };
    // A plan finding the project denies (`[lints] W110 = "deny"`) refuses
    // the build as generation's errors do.
    result
        .diagnostics
        .extend(plan.diagnostics.iter().filter(|d| d.is_error()).cloned());
    if result.refused() {
        // What `semo check` gives for the mission and what generation adds,
        // each once.
        run.diagnostics.extend(result.diagnostics);
        semo::diag::sort_and_dedup(&mut run.diagnostics);
        let reported = match options.format {
            Format::Human | Format::Concise => {
                super::render::human(&run, options.format, options.color, &mut std::io::stderr())
            }
            format => output::report(
                format,
                "build",
                &run.files,
                &run.diagnostics,
                options.color,
                serde_json::json!({
                    "target": single(&targets),
                    "targets": names_json(&targets),
                    "robots": [],
                }),
                out,
            ),
        };
        if let Err(code) = output::written(reported) {
            return code;
        }
        eprintln!("error: code generation refused: fix the errors above first");
        return 1;
    }
    let baking = options.emit == Emit::All;
    if let (Some(deployment), true) = (&deployment, baking) {
        if !semo::deploy::bake(deployment, &mut result) {
            eprintln!(
                "error: --deploy: target {} has no network transport to deploy",
                names(&targets)
            );
            return 2;
        }
    }
    let human = options.format.for_people();
    // The mission builds: its warnings are what `semo check` gives for it
    // (the host's diagnostics and dataflow, refinement's W130 among them),
    // printed before anything is written.
    if human {
        let shown = super::render::people(
            options.format,
            &run.files,
            &run.diagnostics,
            options.color,
            &mut std::io::stderr(),
        );
        if let Err(code) = output::written(shown) {
            return code;
        }
    }
    let mut robots_json = Vec::new();
    let generated = started.elapsed();
    let mut transaction = match Transaction::begin(&out_dir, || {
        eprintln!(
            "waiting for another generation writing to {}...",
            out_dir.display()
        )
    }) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    for line in &transaction.recovered {
        if human {
            let _ = writeln!(out, "recovered: {line}");
        } else {
            eprintln!("recovered: {line}");
        }
    }
    let runtime = match transaction.stage_runtime(&result.runtime, &targets, options.force) {
        Ok(written) => written,
        Err(e) => {
            let folder = semo::codegen::RUNTIME_FOLDER;
            return refuse(&transaction, e, folder, &result.robots);
        }
    };
    let mut staged = Vec::new();
    for (i, robot) in result.robots.iter().enumerate() {
        match transaction.stage_robot(robot, options.force) {
            Ok(written) => staged.push((robot, written)),
            Err(e) => {
                let folder = format!("{}/{}", robot.team, robot.robot);
                return refuse(&transaction, e, &folder, &result.robots[i + 1..]);
            }
        }
    }
    let kept = match transaction.commit() {
        Ok(kept) => kept,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    for (robot, written) in &staged {
        let (generated, user) = robot.line_counts();
        let share = if generated + user == 0 {
            100.0
        } else {
            100.0 * generated as f64 / (generated + user) as f64
        };
        let chosen = plan.target_of(&robot.robot);
        robots_json.push(serde_json::json!({
            "team": robot.team,
            "robot": robot.robot,
            "target": robot.target.name(),
            "chosen_by": chosen.map(chosen_by),
            "simulated": chosen.is_some_and(|c| c.simulated),
            "folder": written.folder.display().to_string(),
            "generated_files": written.generated,
            "task_files_created": written.created,
            "task_files_kept": written.kept,
        }));
        if !human {
            continue;
        }
        let _ = writeln!(
            out,
            "{}/{}: {} ({}; {} generated files; {} task files created, {} kept; {generated} lines generated, {user} in task files: {share:.0}% generated)",
            robot.team,
            robot.robot,
            written.folder.display(),
            chosen.map_or_else(|| format!("target {}", robot.target), target_line),
            written.generated,
            written.created,
            written.kept,
        );
        for saved in &written.backed_up {
            let _ = writeln!(out, "  saved the file in the way as {}", saved.display());
        }
        for special in &written.left_alone {
            let _ = writeln!(
                out,
                "  left alone (not a regular file, not opened): {}",
                special.display()
            );
        }
    }
    if !kept.is_empty() {
        eprintln!("error: {}", semo::codegen::output::kept_message(&kept));
    }
    let failed = if kept.is_empty() { 0 } else { 1 };
    if !human {
        let reported = output::report(
            options.format,
            "build",
            &run.files,
            &run.diagnostics,
            options.color,
            serde_json::json!({
                "target": single(&targets),
                "targets": names_json(&targets),
                "robots": robots_json,
                "runtime": (!result.runtime.is_empty()).then(|| serde_json::json!({
                    "folder": runtime.folder.display().to_string(),
                    "generated_files": runtime.generated,
                })),
                "kept": kept
                    .iter()
                    .map(|c| serde_json::json!({ "path": c.path.display().to_string(), "why": c.why }))
                    .collect::<Vec<_>>(),
            }),
            out,
        );
        return output::written(reported).err().unwrap_or(failed);
    }
    if !result.runtime.is_empty() {
        let _ = writeln!(
            out,
            "the runtime the robots share: {} ({} generated files)",
            runtime.folder.display(),
            runtime.generated
        );
        for saved in &runtime.backed_up {
            let _ = writeln!(out, "  saved the file in the way as {}", saved.display());
        }
    }
    let _ = writeln!(
        out,
        "built {} robot(s) for {} in {:.1} ms ({:.1} ms generating)",
        result.robots.len(),
        count_by_target(&result.robots),
        started.elapsed().as_secs_f64() * 1000.0,
        generated.as_secs_f64() * 1000.0
    );
    failed
}

/// A scenario's error for people (`scenario FILE:LINE:COL: message`, on
/// standard error) or in a JSON document or SARIF log.
fn report_scenario(record: &Record, format: Format, out: &mut impl Write) {
    let written = match format {
        Format::Human | Format::Concise => {
            eprintln!("{}", record.scenario_line());
            Ok(())
        }
        Format::Json => output::write_json(
            out,
            &output::json_document("build", std::slice::from_ref(record), serde_json::json!({})),
        ),
        Format::Sarif => output::write_json(out, &output::sarif(std::slice::from_ref(record))),
    };
    let _ = output::written(written);
}

/// A folder that could not be staged: files in the way are listed with those
/// of the folders not yet staged (`rest`), all at once; nothing is written
/// (the transaction drops what it staged). The exit status.
fn refuse(
    transaction: &Transaction,
    error: OutputError,
    folder: &str,
    rest: &[semo::codegen::RobotOutput],
) -> i32 {
    match error {
        OutputError::Conflicts(mut conflicts) => {
            match transaction.conflicts(rest, &[]) {
                Ok(more) => conflicts.extend(more),
                Err(e) => {
                    eprintln!("error: {e}");
                    return 2;
                }
            }
            eprintln!("error: {}", OutputError::Conflicts(conflicts));
            1
        }
        e => {
            eprintln!("error: cannot write {folder}: {e}");
            2
        }
    }
}

/// `linux`, or `cortex-m and linux-sim`.
fn names(targets: &[Target]) -> String {
    if targets.is_empty() {
        return "none".into();
    }
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    names.join(" and ")
}

/// The JSON document's `target`: the build's one target, else null.
fn single(targets: &[Target]) -> serde_json::Value {
    match targets {
        [one] => serde_json::json!(one.name()),
        _ => serde_json::Value::Null,
    }
}

fn names_json(targets: &[Target]) -> Vec<&'static str> {
    targets.iter().map(|t| t.name()).collect()
}

/// Who chose a robot's target, for the JSON document.
fn chosen_by(chosen: &Chosen) -> &'static str {
    match chosen.reason {
        Reason::Asked => "command line",
        Reason::Project { .. } => "project file",
        Reason::Catalog { .. } => "catalog",
        Reason::Default => "default",
    }
}

/// A robot's target for people: `target cortex-m, its type `Evalbot`'s
/// platform`.
fn target_line(chosen: &Chosen) -> String {
    let why = match &chosen.reason {
        Reason::Asked | Reason::Default => String::new(),
        Reason::Project { key, .. } => format!(" from semo.toml's `{key}`"),
        Reason::Catalog { robot_type, .. } => format!(", its type `{robot_type}`'s platform"),
    };
    let sim = if chosen.simulated { " (--sim)" } else { "" };
    format!("target {}{why}{sim}", chosen.target)
}

/// `target linux-sim`, or `targets cortex-m (1), linux-sim (2)`.
fn count_by_target(robots: &[semo::codegen::RobotOutput]) -> String {
    let targets = semo::targets::distinct(robots.iter().map(|r| r.target));
    match targets.as_slice() {
        [one] => format!("target {one}"),
        _ => {
            let counted: Vec<String> = targets
                .iter()
                .map(|t| {
                    let n = robots.iter().filter(|r| r.target == *t).count();
                    format!("{t} ({n})")
                })
                .collect();
            format!("targets {}", counted.join(", "))
        }
    }
}
