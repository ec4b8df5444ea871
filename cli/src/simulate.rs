//! `semo simulate`: a mission's robots run together in virtual time on a
//! scenario (`semo::sim`); a summary, the trace, the timeline picture, and
//! the scenario's expectations judged. Exit status: 0 every expectation
//! holds, 1 one fails, 2 bad input (mission errors, a bad scenario, options).

use super::input::{self, Content};
use super::output::{self, Format, Record};
use semo::diag::Severity;
use semo::sim::{self, scenario};
use std::io::Write;
use std::path::{Path, PathBuf};

pub struct Options {
    /// Else the project's one mission (`defaults::mission`).
    pub mission: Option<PathBuf>,
    /// Else the mission's own scenario (`defaults::scenario`).
    pub scenario: Option<PathBuf>,
    pub strategy: Vec<PathBuf>,
    pub until_ms: Option<i64>,
    pub seed: u64,
    pub json: bool,
    pub svg: Option<PathBuf>,
    pub trace: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    pub color: bool,
    pub engine: Engine,
    /// With `--engine c`: each robot on its own platform's simulation, a
    /// board robot's firmware in its emulator.
    pub boards: bool,
}

/// What runs the robots.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Engine {
    /// The simulator (`semo::sim`): the reference meaning.
    Sim,
    /// The generated `linux-sim` C programs, built with `make` and run as
    /// processes in lock-step virtual time (`lockstep.rs`).
    C,
}

/// `--until`: mission time as `10min`, `90s`, `500ms`, `1h` or plain milliseconds.
pub fn parse_duration(text: &str) -> Result<i64, String> {
    let split = text
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let scale = match unit {
        "" | "ms" => 1,
        "s" | "sec" => 1000,
        "min" => 60_000,
        "h" => 3_600_000,
        _ => return Err(format!("unknown unit `{unit}` (ms, s, min, h)")),
    };
    number
        .parse::<i64>()
        .ok()
        .and_then(|n| n.checked_mul(scale))
        .filter(|n| *n > 0 && *n <= 1_000_000_000_000_000)
        .ok_or_else(|| format!("`{text}` is not a positive mission time such as 10min or 500ms"))
}

const SIMULATE: &str = "semo simulate";

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let format = if options.json {
        Format::Json
    } else {
        Format::Human
    };
    if options.boards && options.engine != Engine::C {
        eprintln!(
            "error: --boards runs the generated programs, each on its platform's simulation: it needs --engine c"
        );
        return 2;
    }
    let mission_file = match super::defaults::mission_file(
        options.mission.clone(),
        &options.strategy,
        "simulate",
        ("", " (the scenario may be `-`)"),
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
    let scenario_file = match options.scenario.clone() {
        Some(named) => named,
        None => match super::defaults::scenario(&mission_file) {
            Ok(found) => found,
            Err(e) => return output::refused(format, "simulate", &e.folder, &e.message, out),
        },
    };
    let Some((scenario_name, scenario_text)) = input::read(&scenario_file) else {
        return 2;
    };
    if !input::is_kind(&scenario_name, &scenario_text, Content::Scenario, SIMULATE) {
        return 2;
    }
    let (build, refined) = match super::refine_or_report(
        &mut check,
        mission,
        format,
        options.color,
        "simulate",
        out,
    ) {
        Ok(refined) => refined,
        Err(code) => return code,
    };
    let Some((scenario, warnings)) = read_scenario(
        &scenario_name,
        &scenario_text,
        &refined.programs,
        format,
        "simulate",
        out,
    ) else {
        return 2;
    };
    if options.engine == Engine::C {
        // Every robot on linux-sim, or with --boards each on its own
        // platform's simulation (the build plan `semo build --sim` follows).
        let targets = if options.boards {
            check
                .analysis()
                .build_plan(
                    mission,
                    &mission_file,
                    semo::host::PlanRequest {
                        sim: true,
                        ..Default::default()
                    },
                )
                .targets()
        } else {
            semo::targets::Targets::all(semo::platform::Target::LinuxSim)
        };
        return run_generated(&options, &build.input(), &refined, &targets, &scenario, out);
    }
    let programs = &refined.programs;
    let robots = sim::Run::robots_of(programs);
    let mut digest = sim::Digest::new(&robots, &scenario.expect);
    let mut trace = match TraceOut::open(options.trace.as_deref()) {
        Ok(trace) => trace,
        Err(code) => return code,
    };
    // The picture and the MCAP file read the whole trace; the summary, the
    // expectations and the trace file take each event as it is made.
    let keep = options.svg.is_some() || options.mcap.is_some();
    // A summary without expectations reads no message: without a trace
    // file or a kept trace, the run makes no `send` and `receive` events
    // (a swarm's heartbeats are most of its trace).
    let untraced_messages =
        !keep && matches!(trace, TraceOut::Nowhere) && scenario.expect.is_empty();
    let mut kept = Vec::new();
    let mut run = sim::simulate_into(
        programs,
        &scenario,
        &sim::Options {
            until_ms: options.until_ms,
            seed: options.seed,
            untraced_messages,
            ..sim::Options::default()
        },
        &mut |e| {
            digest.see(&e);
            trace.write(&e, &robots[e.robot].1, out);
            if keep {
                kept.push(e);
            }
        },
    );
    run.trace = kept;
    if trace.finish() != 0 {
        return 2;
    }
    let verdicts = digest.verdicts();
    if let Some(path) = &options.svg {
        let picture = sim::svg::to_svg(&run, programs, &scenario);
        if write_to(path, &picture, out) != 0 {
            return 2;
        }
    }
    if let Some(path) = &options.mcap
        && super::mcap::write(path, &run, programs, out) != 0
    {
        return 2;
    }
    let writes_stdout = |p: &Option<PathBuf>| p.as_deref() == Some(Path::new("-"));
    if [&options.trace, &options.svg, &options.mcap]
        .iter()
        .all(|p| !writes_stdout(p))
    {
        let report = if options.json {
            json_summary("simulate", &run, &digest, &verdicts, &warnings)
        } else {
            // Values of the scenario's in it: shown, not obeyed (`terminal.rs`).
            let summary = sim::summary_of(&run, &digest, &verdicts);
            crate::terminal::visible(&summary).into_owned()
        };
        let _ = out.write_all(report.as_bytes());
    }
    if verdicts.iter().all(|v| v.met) { 0 } else { 1 }
}

/// The scenario read against the mission's programs, its warnings printed
/// for people (and returned as records for `--format json`); a mistake is
/// reported in `format` for `command`, and `None` returned (exit status 2).
pub fn read_scenario(
    name: &Path,
    text: &str,
    programs: &[semo::refine::RobotProgram],
    format: Format,
    command: &str,
    out: &mut impl Write,
) -> Option<(scenario::Scenario, Vec<Record>)> {
    let scenario = match scenario::parse(text, programs) {
        Ok(s) => s,
        Err(e) => {
            let record = Record::scenario(name, text, e, Severity::Error);
            if format == Format::Human {
                eprintln!("{}", crate::terminal::visible(&record.scenario_line()));
            } else {
                let document = output::json_document(
                    command,
                    std::slice::from_ref(&record),
                    serde_json::json!({}),
                );
                let _ = output::written(output::write_json(out, &document));
            }
            return None;
        }
    };
    let warnings: Vec<Record> = scenario
        .warnings
        .iter()
        .map(|w| Record::scenario(name, text, w.clone(), Severity::Warning))
        .collect();
    if format == Format::Human {
        for warning in &warnings {
            eprintln!("{}", crate::terminal::visible(&warning.scenario_line()));
        }
    }
    Some((scenario, warnings))
}

/// Where `--trace` writes the trace as the run makes it: a file (opened
/// before the run, so that a bad path costs no simulation), standard
/// output (`-`), or nowhere.
enum TraceOut {
    Nowhere,
    Stdout,
    File {
        path: PathBuf,
        file: std::io::BufWriter<std::fs::File>,
        /// The first failed write, reported at the end.
        failed: Option<std::io::Error>,
    },
}

impl TraceOut {
    fn open(path: Option<&Path>) -> Result<TraceOut, i32> {
        match path {
            None => Ok(TraceOut::Nowhere),
            Some(path) if path == Path::new("-") => Ok(TraceOut::Stdout),
            Some(path) => match std::fs::File::create(path) {
                Ok(file) => Ok(TraceOut::File {
                    path: path.to_path_buf(),
                    file: std::io::BufWriter::new(file),
                    failed: None,
                }),
                Err(e) => {
                    eprintln!("error: {}: {e}", path.display());
                    Err(2)
                }
            },
        }
    }

    /// One event as its JSON line.
    fn write(&mut self, e: &sim::TraceEvent, robot: &str, out: &mut impl Write) {
        let line = |e: &sim::TraceEvent| {
            let mut line = e.to_json(robot);
            line.push('\n');
            line
        };
        match self {
            TraceOut::Nowhere => {}
            TraceOut::Stdout => {
                let _ = out.write_all(line(e).as_bytes());
            }
            TraceOut::File { file, failed, .. } => {
                if failed.is_none()
                    && let Err(error) = file.write_all(line(e).as_bytes())
                {
                    *failed = Some(error);
                }
            }
        }
    }

    /// 0 when every line was written, else 2 with the error said.
    fn finish(self) -> i32 {
        let TraceOut::File {
            path,
            mut file,
            failed,
        } = self
        else {
            return 0;
        };
        match failed.map_or_else(|| file.flush(), Err) {
            Ok(()) => 0,
            Err(e) => {
                eprintln!("error: {}: {e}", path.display());
                2
            }
        }
    }
}

/// Writes `text` to a file, or to standard output for `-`.
pub fn write_to(path: &Path, text: &str, out: &mut impl Write) -> i32 {
    if path == Path::new("-") {
        let _ = out.write_all(text.as_bytes());
        return 0;
    }
    match std::fs::write(path, text) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            2
        }
    }
}

/// `--format json`: one object with each robot's modes and every
/// expectation (`semo simulate`'s and `semo replay`'s, as `command`).
pub fn json_summary(
    command: &str,
    run: &sim::Run,
    digest: &sim::Digest,
    verdicts: &[sim::Verdict],
    warnings: &[Record],
) -> String {
    let robots: Vec<serde_json::Value> = run
        .robots
        .iter()
        .zip(digest.modes())
        .map(|((team, robot), modes)| {
            let modes: Vec<serde_json::Value> = modes
                .iter()
                .map(|(t, mode)| serde_json::json!({"t": t, "mode": &**mode}))
                .collect();
            serde_json::json!({"team": team, "robot": robot, "modes": modes})
        })
        .collect();
    let expectations: Vec<serde_json::Value> = verdicts
        .iter()
        .map(|v| {
            serde_json::json!({
                "expectation": v.expectation.kind.to_string(),
                "met": v.met,
                "why": v.why,
            })
        })
        .collect();
    let data = serde_json::json!({
        "end_ms": run.end_ms,
        "events": run.events,
        "robots": robots,
        "expectations": expectations,
        "ok": verdicts.iter().all(|v| v.met),
    });
    let mut text = output::json_document(command, warnings, data).to_string();
    text.push('\n');
    text
}

/// `--engine c`: the generated programs run the scenario in lock-step; the
/// trace is theirs, merged in time order (robots in peer order at one instant).
fn run_generated(
    options: &Options,
    input: &semo::refine::BuildInput<'_>,
    refined: &semo::refine::Refined,
    targets: &semo::targets::Targets,
    scenario: &scenario::Scenario,
    out: &mut impl Write,
) -> i32 {
    if options.json || options.svg.is_some() || options.mcap.is_some() {
        eprintln!(
            "error: --engine c writes the trace (--trace) and a text summary; --format json, --svg and --mcap need --engine sim (or `semo replay` of its trace)"
        );
        return 2;
    }
    if !scenario.expect.is_empty() {
        eprintln!("note: --engine c does not judge the scenario's expectations; --engine sim does");
    }
    let until_ms = options
        .until_ms
        .or(scenario.duration_ms)
        .unwrap_or(sim::DEFAULT_UNTIL_MS);
    let robots = match super::lockstep::simulate(
        input,
        refined,
        targets,
        scenario,
        until_ms,
        options.seed,
    ) {
        Ok(robots) => robots,
        Err(e) => {
            // It may quote what a robot or a compiler wrote.
            eprintln!("error: {}", super::terminal::visible(&e));
            return 2;
        }
    };
    let trace = super::lockstep::merged(&robots);
    if let Some(path) = &options.trace
        && write_to(path, &trace, out) != 0
    {
        return 2;
    }
    if options.trace.as_deref() != Some(Path::new("-")) {
        let lines = trace.lines().count();
        let mut summary = format!(
            "{} robots ran their generated programs in lock-step: {lines} trace events\n",
            robots.len()
        );
        for robot in &robots {
            summary.push_str(&format!(
                "  {}: {} events",
                robot.name,
                robot.trace.lines().count()
            ));
            if let Some(board) = robot.board {
                summary.push_str(&format!(
                    " ({}, {} in {} {})",
                    robot.target, board.name, board.emulator, board.machine
                ));
            }
            summary.push('\n');
        }
        let _ = out.write_all(summary.as_bytes());
    }
    0
}
