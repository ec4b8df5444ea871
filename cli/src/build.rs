//! `semo build`: a mission, its strategy files and the catalog → one folder of
//! C code (and the refined task graph) per robot.

use super::input::{self, Content};
use super::output::{self, Format, Record};
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
    pub format: Format,
    pub color: bool,
    /// Replace files in the way (saved to the backup folder first).
    pub force: bool,
}

const BUILD: &str = "semo build";

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let started = std::time::Instant::now();
    if input::is_stdin(&options.mission) {
        eprintln!(
            "error: `semo build` reads the mission's folder (its catalog and strategy files, `out/` beside it): give the mission's file, not `-`"
        );
        return 2;
    }
    if !input::file_is_kind(&options.mission, Content::Mission, BUILD)
        || options
            .scenario
            .as_deref()
            .is_some_and(|s| !input::file_is_kind(s, Content::Scenario, BUILD))
    {
        return 2;
    }
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
    let Some(input) = run.analysis().build_input(mission) else {
        eprintln!("internal error: the mission was loaded but not checked");
        return 2;
    };
    let input = input.input();
    let result = match &options.scenario {
        None => codegen::build(&input, options.target, options.emit),
        Some(path) => match build_with_scenario(&input, path, &options) {
            Ok(result) => result,
            Err(ScenarioError::Unreadable(message)) => {
                eprintln!("{message}");
                return 2;
            }
            Err(ScenarioError::Bad(record)) => {
                report_scenario(&record, options.format, out);
                return 2;
            }
        },
    };
    if result.refused() {
        run.diagnostics = result.diagnostics;
        let reported = match options.format {
            Format::Human => super::render::human(&run, options.color, &mut std::io::stderr()),
            format => output::report(
                format,
                "build",
                &run.files,
                &run.diagnostics,
                options.color,
                serde_json::json!({ "target": options.target.name(), "robots": [] }),
                out,
            ),
        };
        if let Err(code) = output::written(reported) {
            return code;
        }
        eprintln!("error: code generation refused: fix the errors above first");
        return 1;
    }
    let human = options.format == Format::Human;
    let mut robots_json = Vec::new();
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
        if human {
            let _ = writeln!(out, "recovered: {line}");
        } else {
            eprintln!("recovered: {line}");
        }
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
                robots_json.push(serde_json::json!({
                    "team": robot.team,
                    "robot": robot.robot,
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
    if !human {
        let reported = output::report(
            options.format,
            "build",
            &run.files,
            &[],
            options.color,
            serde_json::json!({ "target": options.target.name(), "robots": robots_json }),
            out,
        );
        return output::written(reported).err().unwrap_or(0);
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

enum ScenarioError {
    /// The file cannot be read (the message says why).
    Unreadable(String),
    /// The scenario has an error, at a position.
    Bad(Box<Record>),
}

/// A scenario's error for people (`scenario FILE:LINE:COL: message`, on
/// standard error) or in a JSON document or SARIF log.
fn report_scenario(record: &Record, format: Format, out: &mut impl Write) {
    let written = match format {
        Format::Human => {
            eprintln!(
                "scenario {}:{}:{}: {}",
                record.file, record.start.line, record.start.column, record.message
            );
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

/// Builds for a target that compiles the scenario in: the mission is refined
/// first, since the scenario's names are checked against its programs.
fn build_with_scenario(
    input: &codegen::BuildInput<'_>,
    path: &Path,
    options: &Options,
) -> Result<codegen::BuildResult, ScenarioError> {
    let text = semo::workspace::read_text(path)
        .map_err(|e| ScenarioError::Unreadable(format!("error: {}: {e}", path.display())))?;
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
        ScenarioError::Bad(Box::new(Record::uncoded_error(path, line, col, e.message)))
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
