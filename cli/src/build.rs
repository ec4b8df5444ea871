//! `semo build`: a mission, its strategy files and the catalog → one folder of
//! C code (and the refined task graph) per robot.

use super::render;
use semo::codegen::output::{OutputError, Transaction};
use semo::codegen::{self, Emit, Target};
use semo::host;
use std::io::Write;
use std::path::{Path, PathBuf};

pub struct Options {
    pub mission: PathBuf,
    pub strategy: Vec<PathBuf>,
    pub out: Option<PathBuf>,
    pub target: Target,
    /// Compiled into each robot (targets that need it: `cortex-m-sim`).
    pub scenario: Option<PathBuf>,
    pub emit: Emit,
    pub color: bool,
    /// Replace files in the way (saved to the backup folder first).
    pub force: bool,
    /// A deployment file baked into every robot folder.
    pub deploy: Option<PathBuf>,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let started = std::time::Instant::now();
    if options.scenario.is_some() != options.target.needs_scenario() {
        eprintln!(
            "error: {}",
            if options.scenario.is_some() {
                format!(
                    "--scenario is compiled in only for target cortex-m-sim (target {} reads it at run time, if at all)",
                    options.target.name()
                )
            } else {
                format!(
                    "target {} compiles a scenario into each robot: give --scenario FILE",
                    options.target.name()
                )
            }
        );
        return 2;
    }
    let (mut run, mission) = match host::load_build(&options.mission, &options.strategy) {
        Ok(loaded) => loaded,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let deployment = match &options.deploy {
        None => None,
        Some(path) => match super::deploy::load(path, options.color, out) {
            Ok(loaded) => Some(loaded),
            Err(code) => return code,
        },
    };
    let Some(input) = run.analysis().build_input(mission) else {
        eprintln!("internal error: the mission was loaded but not checked");
        return 2;
    };
    let input = input.input();
    if let Some((deployment, file)) = &deployment {
        let found = semo::deploy::check(deployment, &input.analysis.mission);
        if found.iter().any(|d| d.is_error()) {
            return super::deploy::refuse(file, &found, options.color, out);
        }
    }
    let mut result = match &options.scenario {
        None => codegen::build(&input, options.target, options.emit),
        Some(path) => match build_with_scenario(&input, path, &options) {
            Ok(result) => result,
            Err(message) => {
                eprintln!("{message}");
                return 2;
            }
        },
    };
    if result.refused() {
        run.diagnostics = result.diagnostics;
        let _ = render::human(&run, options.color, out);
        let _ = writeln!(
            out,
            "error: code generation refused: fix the errors above first"
        );
        return 1;
    }
    let baking = options.emit == Emit::All;
    if let (Some((deployment, _)), true) = (&deployment, baking) {
        if !semo::deploy::bake(deployment, &mut result) {
            eprintln!(
                "error: --deploy: target {} has no network transport to deploy",
                options.target.name()
            );
            return 2;
        }
    }
    let out_dir = options.out.clone().unwrap_or_else(|| {
        options
            .mission
            .parent()
            .unwrap_or(Path::new("."))
            .join("out")
    });
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
        let _ = writeln!(out, "recovered: {line}");
    }
    if !options.force {
        match transaction.conflicts(&result.robots, options.target) {
            Ok(conflicts) if conflicts.is_empty() => {}
            Ok(conflicts) => {
                eprintln!("error: {}", OutputError::Conflicts(conflicts));
                return 1;
            }
            Err(e) => {
                eprintln!("error: {e}");
                return 2;
            }
        }
    }
    for robot in &result.robots {
        match transaction.write_robot(robot, options.target, options.force) {
            Ok(written) => {
                let (generated, user) = robot.line_counts();
                let share = if generated + user == 0 {
                    100.0
                } else {
                    100.0 * generated as f64 / (generated + user) as f64
                };
                let _ = writeln!(
                    out,
                    "{}/{}: {} ({} generated files; {} task files created, {} kept; {generated} lines generated, {user} in task files: {share:.0}% generated)",
                    robot.team,
                    robot.robot,
                    written.folder.display(),
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
            Err(e) => {
                eprintln!("error: cannot write {}/{}: {e}", robot.team, robot.robot);
                return 2;
            }
        }
    }
    let _ = writeln!(
        out,
        "built {} robot(s) for target {} in {:.1} ms ({:.1} ms generating)",
        result.robots.len(),
        options.target.name(),
        started.elapsed().as_secs_f64() * 1000.0,
        generated.as_secs_f64() * 1000.0
    );
    0
}

/// Builds for a target that compiles the scenario in: the mission is refined
/// first, since the scenario's names are checked against its programs.
fn build_with_scenario(
    input: &codegen::BuildInput<'_>,
    path: &Path,
    options: &Options,
) -> Result<codegen::BuildResult, String> {
    let text =
        semo::workspace::read_text(path).map_err(|e| format!("error: {}: {e}", path.display()))?;
    let refined = codegen::refine_checked(input);
    if refined.programs.is_empty() {
        // Refused: the mission's own errors come first.
        return Ok(codegen::build_refined(
            input,
            refined,
            options.target,
            options.emit,
            &[],
        ));
    }
    let scenario = semo::sim::scenario::parse(&text, &refined.programs).map_err(|e| {
        let (line, col) = e.line_col(&text);
        format!("scenario {}:{line}:{col}: {}", path.display(), e.message)
    })?;
    let worlds: Vec<_> = refined
        .programs
        .iter()
        .map(|p| scenario.compiled_for(p))
        .collect();
    Ok(codegen::build_refined(
        input,
        refined,
        options.target,
        options.emit,
        &worlds,
    ))
}
