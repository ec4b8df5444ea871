//! `semo replay`: a recorded run (the trace lines of each robot's
//! `--trace` file, or one merged file) read back against the mission,
//! merged by time, and shown and judged as `semo simulate` shows and judges
//! a simulated run: the same summary, timeline picture and expectations
//! (`semo::sim::replay` makes the recorded run a `sim::Run`). Exit status:
//! 0 every expectation holds, 1 one fails, 2 bad input (mission errors, a
//! bad scenario, a malformed trace line, options).

use super::input::{self, Content};
use super::output::{self, Format, Record};
use super::simulate;
use semo::sim::{self, replay::Replay, scenario::Scenario};
use std::io::{BufRead, Read, Write};
use std::path::{Path, PathBuf};

pub struct Options {
    /// The trace files (`-`: standard input), at least one.
    pub traces: Vec<PathBuf>,
    /// Else the project's one mission (`defaults::mission`).
    pub mission: Option<PathBuf>,
    /// Else the mission's own scenario, when it has one.
    pub scenario: Option<PathBuf>,
    pub strategy: Vec<PathBuf>,
    pub json: bool,
    pub svg: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    pub color: bool,
}

const REPLAY: &str = "semo replay";

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let format = if options.json {
        Format::Json
    } else {
        Format::Human
    };
    if options.traces.iter().filter(|p| input::is_stdin(p)).count() > 1 {
        eprintln!("error: standard input (`-`) can be only one of the trace files");
        return 2;
    }
    let mission_file = match super::defaults::mission_file(
        options.mission.clone(),
        &options.strategy,
        "replay",
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
    let (_build, refined) =
        match super::refine_or_report(&mut check, mission, format, options.color, "replay", out) {
            Ok(refined) => refined,
            Err(code) => return code,
        };
    let programs = &refined.programs;
    // The scenario: named, else the mission's own; without one there is
    // nothing to expect, and the run is still shown.
    let scenario_file = match options.scenario.clone() {
        Some(named) => Some(named),
        None => match super::defaults::scenario(&mission_file) {
            Ok(found) => Some(found),
            Err(e) => {
                if format == Format::Human {
                    eprintln!("note: no expectations to check: {}", e.message);
                }
                None
            }
        },
    };
    let (scenario, warnings) = match scenario_file {
        Some(file) => {
            let Some((name, text)) = input::read(&file) else {
                return 2;
            };
            if !input::is_kind(&name, &text, Content::Scenario, REPLAY) {
                return 2;
            }
            match simulate::read_scenario(&name, &text, programs, format, "replay", out) {
                Some(read) => read,
                None => return 2,
            }
        }
        None => (Scenario::default(), Vec::new()),
    };
    let mut replay = Replay::new(programs);
    for path in &options.traces {
        if let Err(record) = read_trace(&mut replay, path) {
            if format == Format::Human {
                eprintln!(
                    "trace {}:{}:{}: {}",
                    record.file, record.start.line, record.start.column, record.message
                );
            } else {
                let document = output::json_document(
                    "replay",
                    std::slice::from_ref(&*record),
                    serde_json::json!({}),
                );
                let _ = output::written(output::write_json(out, &document));
            }
            return 2;
        }
    }
    let run = replay.finish();
    let digest = sim::Digest::of(&run, &scenario.expect);
    let verdicts = digest.verdicts();
    if let Some(path) = &options.svg {
        let picture = sim::svg::to_svg(&run, programs, &scenario);
        if simulate::write_to(path, &picture, out) != 0 {
            return 2;
        }
    }
    if let Some(path) = &options.mcap
        && super::mcap::write(path, &run, programs, out) != 0
    {
        return 2;
    }
    let writes_stdout = |p: &Option<PathBuf>| p.as_deref() == Some(Path::new("-"));
    if !writes_stdout(&options.svg) && !writes_stdout(&options.mcap) {
        let report = if options.json {
            simulate::json_summary("replay", &run, &digest, &verdicts, &warnings)
        } else {
            // The traces are the robots': what they name is shown, never
            // obeyed by the terminal (`terminal.rs`).
            let summary = sim::replay_summary(&run, &verdicts, options.traces.len());
            crate::terminal::visible(&summary).into_owned()
        };
        let _ = out.write_all(report.as_bytes());
    }
    if verdicts.iter().all(|v| v.met) { 0 } else { 1 }
}

/// Reads one trace file (`-`: standard input) line by line into `replay`;
/// a line that cannot be read or is not a trace line of the mission is the
/// error record at its line and column.
fn read_trace(replay: &mut Replay, path: &Path) -> Result<(), Box<Record>> {
    let name = if input::is_stdin(path) {
        PathBuf::from(input::STDIN_NAME)
    } else {
        path.to_path_buf()
    };
    let at = |line: u64, column: u64, message: String| {
        let clamp = |n: u64| u32::try_from(n).unwrap_or(u32::MAX);
        Box::new(Record::uncoded_error(
            &name,
            clamp(line),
            clamp(column),
            message,
        ))
    };
    let reader: Box<dyn BufRead> = if input::is_stdin(path) {
        Box::new(std::io::stdin().lock())
    } else {
        match std::fs::File::open(path) {
            Ok(file) if file.metadata().is_ok_and(|m| m.is_file()) => {
                Box::new(std::io::BufReader::new(file))
            }
            Ok(_) => return Err(at(1, 1, "not a regular file".into())),
            Err(e) => return Err(at(1, 1, format!("cannot read it: {e}"))),
        }
    };
    replay.start_file();
    let limit = semo::sim::replay::MAX_LINE_BYTES as u64 + 1;
    let mut reader = reader;
    let mut bytes = Vec::new();
    let mut number = 0u64;
    loop {
        bytes.clear();
        number += 1;
        // At most one byte past the limit is read of a line, so that a
        // file without line breaks costs no more than the limit.
        let read = (&mut reader)
            .take(limit)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| at(number, 1, format!("cannot read it: {e}")))?;
        if read == 0 {
            return Ok(());
        }
        if bytes.last() == Some(&b'\n') {
            bytes.pop();
        }
        replay.line(number, &bytes).map_err(|e| {
            let mut record = at(e.line, e.column, e.message);
            record.suggestion = e.suggestion;
            record
        })?;
    }
}
