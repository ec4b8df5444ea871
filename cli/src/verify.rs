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
    /// A scenario file whose `expect` list is checked over every behaviour.
    pub expect: Option<PathBuf>,
}

/// A memory size: a whole number of bytes, or with a unit (`kB`, `MB`, `GB`
/// in powers of 1000; `KiB`, `MiB`, `GiB` in powers of 1024).
pub fn parse_bytes(text: &str) -> Result<usize, String> {
    let split = text
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let scale: usize = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "kb" => 1000,
        "mb" => 1000 * 1000,
        "gb" => 1000 * 1000 * 1000,
        "kib" => 1 << 10,
        "mib" => 1 << 20,
        "gib" => 1 << 30,
        _ => return Err(format!("unknown unit `{unit}` (kB, MB, GB, KiB, MiB, GiB)")),
    };
    number
        .parse::<usize>()
        .ok()
        .and_then(|n| n.checked_mul(scale))
        .filter(|n| *n > 0)
        .ok_or_else(|| format!("`{text}` is not a positive size such as 512MB or 2GiB"))
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
    let properties = match &options.expect {
        Some(file) => match read_properties(file, &refined.programs, format, out) {
            Some(properties) => properties,
            None => return 2,
        },
        None => Vec::new(),
    };
    let mut report = match semo::verify::verify_expecting(
        &refined.programs,
        mission,
        &text,
        &options.search,
        properties,
    ) {
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
    let mut property_files = vec![None; report.properties.len()];
    if let Some(dir) = &options.counterexamples {
        let written = write_counterexamples(dir, &mission_file, &report, &refined.programs)
            .and_then(|files| {
                written_files = files;
                write_property_counterexamples(dir, &mission_file, &report, &refined.programs)
            });
        match written {
            Ok(files) => property_files = files,
            Err(e) => {
                eprintln!("error: {}: {e}", dir.display());
                return 2;
            }
        }
    }
    let broken = report
        .properties
        .iter()
        .any(|(_, outcome)| matches!(outcome, semo::verify::Outcome::Broken { .. }));
    let data = serde_json::json!({
        "exhaustive": report.exhaustive,
        "states": report.states,
        "transitions": report.transitions,
        "explored_ms": report.reached_ms,
        "bounded_by": report.bound.map(|b| b.name()),
        "reductions": if options.search.merge_in_time {
            vec!["merge_in_time"]
        } else {
            Vec::new()
        },
        "counterexamples": written_files
            .iter()
            .map(|f| f.as_ref().map(|p: &PathBuf| p.display().to_string()))
            .collect::<Vec<_>>(),
        "properties": report
            .properties
            .iter()
            .zip(&property_files)
            .map(|((property, outcome), file)| property_json(property, outcome, file.as_deref()))
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
            let _ = writeln!(out, "{}", report.headline());
            // The world's choices: each input with its values.
            let sensors = report
                .inputs
                .sensors
                .iter()
                .map(|s| (format!("sensor {}.{}", s.robot_name, s.port), &s.values));
            let commands = (report.inputs.commands.iter())
                .map(|c| (format!("command {} USER.{}", c.to, c.value), &c.values));
            for (input, values) in sensors.chain(commands) {
                let line = format!("  {input}: {}", values.join(" | "));
                let _ = writeln!(out, "{}", crate::terminal::visible(&line));
            }
            for ((property, outcome), file) in report.properties.iter().zip(&property_files) {
                let _ = writeln!(
                    out,
                    "{}",
                    property_said(property, outcome, &mission_file, file.as_deref())
                );
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
    i32::from(!report.findings.is_empty() || broken)
}

/// The properties of the scenario `file`'s `expect` list; a mistake is
/// reported (exit status 2) and `None` returned.
fn read_properties(
    file: &Path,
    programs: &[semo::refine::RobotProgram],
    format: Format,
    out: &mut impl Write,
) -> Option<Vec<semo::verify::Property>> {
    let text = match std::fs::read_to_string(file) {
        Ok(text) => text,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return None;
        }
    };
    let (scenario, _) =
        super::simulate::read_scenario(file, &text, programs, format, "verify", out)?;
    if !(scenario.robots.is_empty() && scenario.operator.is_empty() && scenario.faults.is_empty()) {
        eprintln!(
            "note: {}: `semo verify` makes the world's choices itself; of this scenario only `expect` is read",
            file.display()
        );
    }
    match semo::verify::properties_of(&scenario.expect) {
        Ok(properties) => Some(properties),
        Err(mistake) => {
            let record =
                output::Record::scenario(file, &text, mistake, semo::diag::Severity::Error);
            if format == Format::Human {
                eprintln!("{}", crate::terminal::visible(&record.scenario_line()));
            } else {
                let document = output::json_document(
                    "verify",
                    std::slice::from_ref(&record),
                    serde_json::json!({}),
                );
                let _ = output::written(output::write_json(out, &document));
            }
            None
        }
    }
}

/// A property and what became of it, for people.
fn property_said(
    property: &semo::verify::Property,
    outcome: &semo::verify::Outcome,
    mission: &Path,
    file: Option<&Path>,
) -> String {
    let said = format!(
        "  property `{}`: {}",
        property.expectation.kind,
        outcome.said()
    );
    match (outcome, file) {
        (semo::verify::Outcome::Broken { .. }, Some(file)) => format!(
            "{said}; replay with `semo simulate {} --scenario {}`",
            mission.display(),
            file.display()
        ),
        (semo::verify::Outcome::Broken { .. }, None) => {
            format!("{said} (--counterexamples DIR writes the scenario that replays it)")
        }
        _ => said,
    }
}

/// A property and what became of it, for `--format json`.
fn property_json(
    property: &semo::verify::Property,
    outcome: &semo::verify::Outcome,
    file: Option<&Path>,
) -> serde_json::Value {
    use semo::verify::Outcome;
    let (proof, why) = match outcome {
        Outcome::Holds { proof } => (*proof, None),
        Outcome::NotJudged => (false, None),
        Outcome::Broken { why, .. } => (true, Some(why.as_str())),
    };
    serde_json::json!({
        "expectation": property.expectation.kind.to_string(),
        "verdict": outcome.verdict(),
        "proof": proof,
        "why": why,
        "counterexample": file.map(|f| f.display().to_string()),
    })
}

/// Writes each broken property's counterexample as
/// `<mission>.property-<n>.scenario.json` in `dir` (its `expect` the
/// property, so the replay says it breaks), with its timeline beside it.
fn write_property_counterexamples(
    dir: &Path,
    mission: &Path,
    report: &semo::verify::Report,
    programs: &[semo::refine::RobotProgram],
) -> std::io::Result<Vec<Option<PathBuf>>> {
    let stem = stem_of(mission);
    let mut written = Vec::new();
    for (n, (property, outcome)) in report.properties.iter().enumerate() {
        let semo::verify::Outcome::Broken { way, .. } = outcome else {
            written.push(None);
            continue;
        };
        let name = format!("{stem}.property-{}", n + 1);
        let text =
            way.scenario_json_expecting(&report.inputs, programs, Some(&property.expectation.kind));
        written.push(Some(write_replay(dir, &name, &text, programs)?));
    }
    Ok(written)
}

fn stem_of(mission: &Path) -> String {
    mission
        .file_stem()
        .map_or("mission".into(), |s| s.to_string_lossy().into_owned())
}

/// Writes the scenario `text` as `<name>.scenario.json` in `dir`, and the
/// timeline of its replay as `<name>.svg`; the scenario's path.
fn write_replay(
    dir: &Path,
    name: &str,
    text: &str,
    programs: &[semo::refine::RobotProgram],
) -> std::io::Result<PathBuf> {
    let path = dir.join(format!("{name}.scenario.json"));
    std::fs::write(&path, text)?;
    // Its timeline, as `semo simulate --svg` draws the replay.
    let scenario = semo::sim::scenario::parse(text, programs).map_err(|e| {
        std::io::Error::other(format!(
            "internal error: a counterexample does not read back: {e:?}"
        ))
    })?;
    let run = semo::sim::simulate(programs, &scenario, &semo::sim::Options::default());
    let picture = semo::sim::svg::to_svg(&run, programs, &scenario);
    std::fs::write(dir.join(format!("{name}.svg")), picture)?;
    Ok(path)
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
    let stem = stem_of(mission);
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
        let text = way.scenario_json(&report.inputs, programs);
        written.push(Some(write_replay(dir, &name, &text, programs)?));
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::parse_bytes;

    #[test]
    fn sizes_read_in_bytes_with_decimal_and_binary_units() {
        assert_eq!(parse_bytes("4096"), Ok(4096));
        assert_eq!(parse_bytes("512MB"), Ok(512_000_000));
        assert_eq!(parse_bytes("2GiB"), Ok(2 << 30));
        assert_eq!(parse_bytes("64kb"), Ok(64_000));
        assert!(parse_bytes("0MB").is_err());
        assert!(
            parse_bytes("1TB")
                .unwrap_err()
                .contains("unknown unit `TB`")
        );
        assert!(parse_bytes("MB").is_err());
        assert!(parse_bytes("99999999999999999999GB").is_err());
    }
}
