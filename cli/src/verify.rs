//! `semo verify`: everything a mission's team can do, explored on the
//! simulator's step semantics (`semo::verify`); findings as diagnostics on
//! the mission's lines, each with the scenario that replays it. Exit
//! status: 0 nothing found, 1 a finding, 2 bad input (mission errors,
//! options).

use super::output::{self, Format};
use std::io::Write;
use std::path::{Path, PathBuf};

pub struct Options {
    /// Else the project's one mission (`defaults::mission`).
    pub mission: Option<PathBuf>,
    pub strategy: Vec<PathBuf>,
    pub format: Format,
    pub color: bool,
    pub search: semo::verify::Options,
    /// Write each finding's counterexample here as a scenario file.
    pub counterexamples: Option<PathBuf>,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let format = options.format;
    if let Some(problem) = options.search.problem() {
        eprintln!("error: --step: {problem}");
        return 2;
    }
    let mission_file = match super::defaults::mission_file(
        options.mission.clone(),
        &options.strategy,
        "verify",
        ("", ""),
        format,
        out,
    ) {
        Ok(found) => found,
        Err(code) => return code,
    };
    let (mut check, mission) = match super::defaults::load(&mission_file, &options.strategy) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let refined =
        match super::refine_or_report(&mut check, mission, format, options.color, "verify", out) {
            Ok((_, refined)) => refined,
            Err(code) => return code,
        };
    let text = check.files.get(mission).text.clone();
    let mut report = match semo::verify::verify(&refined.programs, mission, &text, &options.search)
    {
        Ok(report) => report,
        Err(problem) => {
            eprintln!("internal error: options checked above were refused: {problem}");
            return 2;
        }
    };
    if let Some(project) = check.analysis().project(mission) {
        report.apply_lints(&project.project);
    }
    let mut written_files = Vec::new();
    if let Some(dir) = &options.counterexamples {
        match write_counterexamples(dir, &mission_file, &report, &refined.programs) {
            Ok(files) => written_files = files,
            Err(e) => {
                eprintln!("error: {}: {e}", dir.display());
                return 2;
            }
        }
    }
    let data = serde_json::json!({
        "exhaustive": report.exhaustive,
        "states": report.states,
        "transitions": report.transitions,
        "explored_ms": report.reached_ms,
        "counterexamples": written_files
            .iter()
            .map(|f| f.as_ref().map(|p: &PathBuf| p.display().to_string()))
            .collect::<Vec<_>>(),
    });
    let reported = match format {
        Format::Human | Format::Concise => {
            let mut err = std::io::stderr().lock();
            let written = super::render::people(
                format,
                &check.files,
                &report.findings,
                options.color,
                &mut err,
            );
            let _ = writeln!(
                out,
                "{} {} state(s), {} transition(s): {}",
                if report.exhaustive {
                    "explored every behaviour:"
                } else {
                    "explored (bounded):"
                },
                report.states,
                report.transitions,
                if report.exhaustive {
                    "a proof for the choices explored".to_string()
                } else {
                    format!("the first {} ms", report.reached_ms)
                }
            );
            // The world's choices: each input with its values.
            let sensors = report
                .inputs
                .sensors
                .iter()
                .map(|s| (format!("sensor {}.{}", s.robot_name, s.port), &s.values));
            let commands = (report.inputs.commands.iter())
                .map(|c| (format!("command {} USER.{}", c.to, c.value), &c.values));
            for (input, values) in sensors.chain(commands) {
                let _ = writeln!(out, "  {input}: {}", values.join(" | "));
            }
            for (finding, file) in report.findings.iter().zip(&written_files) {
                if let Some(file) = file {
                    let _ = writeln!(
                        out,
                        "  {}: replay with `semo simulate {} --scenario {}`",
                        finding.code,
                        mission_file.display(),
                        file.display()
                    );
                }
            }
            written
        }
        _ => output::report(
            format,
            "verify",
            &check.files,
            &report.findings,
            options.color,
            data,
            out,
        ),
    };
    if let Err(code) = output::written(reported) {
        return code;
    }
    i32::from(!report.findings.is_empty())
}

/// Writes each finding's counterexample as `<mission>.<code>-<n>.scenario.json`
/// in `dir`, with the timeline of its replay beside it (`….svg`); per
/// finding, the scenario written, if it has one.
fn write_counterexamples(
    dir: &Path,
    mission: &Path,
    report: &semo::verify::Report,
    programs: &[semo::refine::RobotProgram],
) -> std::io::Result<Vec<Option<PathBuf>>> {
    std::fs::create_dir_all(dir)?;
    let stem = mission
        .file_stem()
        .map_or("mission".into(), |s| s.to_string_lossy().into_owned());
    let mut written = Vec::new();
    for (n, (finding, way)) in report
        .findings
        .iter()
        .zip(&report.counterexamples)
        .enumerate()
    {
        let Some(way) = way else {
            written.push(None);
            continue;
        };
        let name = semo::verify::counterexample_name(&stem, finding.code, n + 1);
        let path = dir.join(format!("{name}.scenario.json"));
        let text = way.scenario_json(&report.inputs, programs);
        std::fs::write(&path, &text)?;
        // Its timeline, as `semo simulate --svg` draws the replay.
        let scenario = semo::sim::scenario::parse(&text, programs).map_err(|e| {
            std::io::Error::other(format!(
                "internal error: a counterexample does not read back: {e:?}"
            ))
        })?;
        let run = semo::sim::simulate(programs, &scenario, &semo::sim::Options::default());
        let picture = semo::sim::svg::to_svg(&run, programs, &scenario);
        std::fs::write(dir.join(format!("{name}.svg")), picture)?;
        written.push(Some(path));
    }
    Ok(written)
}
