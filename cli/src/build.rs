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
    pub emit: Emit,
    pub color: bool,
    /// Replace files in the way (saved to the backup folder first).
    pub force: bool,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let started = std::time::Instant::now();
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
    let result = codegen::build(&input.input(), options.target, options.emit);
    if result.refused() {
        run.diagnostics = result.diagnostics;
        let _ = render::human(&run, options.color, out);
        let _ = writeln!(
            out,
            "error: code generation refused: fix the errors above first"
        );
        return 1;
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
