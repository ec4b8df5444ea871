//! `semo graph analyze|schedule|buffers|latency|dot|svg`: a task graph's
//! repetition vectors and deadlock freedom level by level with its
//! diagnostics, its schedules, buffer sizes and latencies, and pictures of
//! it; `semo graph modes`: a mission's mode machines.

use super::input::{self, Content};
use super::output::{self, Format};
use super::render;
use semo::diag::Diagnostic;
use semo::taskgraph::analysis::NoPeriod;
use semo::taskgraph::analysis::ratio::Ratio;
use semo::workspace::{
    FileKind, FileResolver, Files, GraphReading, GraphRun, analyze_graph, analyze_graph_as,
};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The graph file at `path` (`-`: standard input) when it holds a task
/// graph, with the name reports give it; otherwise a message is printed.
fn read(path: &Path, command: &str) -> Option<(PathBuf, String)> {
    let (name, text) = input::read(path)?;
    input::is_kind(&name, &text, Content::TaskGraph, command).then_some((name, text))
}

/// The graph file at `path` read (a message on failure) and analysed with
/// `reading`; its sub-graph references are read from the disk (beside the
/// file, or from the current folder for standard input).
fn read_and_analyze(
    path: &Path,
    reading: GraphReading,
    command: &str,
) -> Option<(Files, GraphRun)> {
    let (name, text) = read(path, command)?;
    let mut files = Files::default();
    let id = files.add(name, FileKind::TaskGraph, text);
    let file = files.get(id);
    let run = analyze_graph_as(
        id,
        &file.text,
        Some(&file.path),
        &mut FileResolver::new(&files),
        reading,
    );
    Some((files, run))
}

/// The graph in `path` when it loads without errors; otherwise the errors
/// are printed and the exit code given.
fn load_clean(path: &Path, command: &str) -> Result<semo::taskgraph::TaskGraph, i32> {
    let Some((name, text)) = read(path, command) else {
        return Err(2);
    };
    let mut files = Files::default();
    let id = files.add(name, FileKind::TaskGraph, text);
    let (graph, diagnostics) = semo::taskgraph::load_task_graph(id, &files.get(id).text);
    let errors: Vec<Diagnostic> = diagnostics
        .into_iter()
        .filter(Diagnostic::is_error)
        .collect();
    match graph {
        Some(g) if errors.is_empty() => Ok(g),
        _ => {
            let _ = render::diagnostics(&files, &errors, false, &mut std::io::stderr());
            Err(1)
        }
    }
}

/// `semo graph dot`: the DOT text, or the loading errors (exit 1).
pub fn dot(path: &Path, out: &mut impl Write) -> i32 {
    match load_clean(path, "semo graph dot") {
        Ok(g) => {
            let _ = out.write_all(semo::taskgraph::dot::to_dot(&g).as_bytes());
            0
        }
        Err(code) => code,
    }
}

/// `semo graph svg`: the SVG picture on `out` or in `output`, with the cycles
/// that deadlock marked, or the loading errors (exit 1).
pub fn svg(path: &Path, output: Option<&Path>, out: &mut impl Write) -> i32 {
    let graph = match load_clean(path, "semo graph svg") {
        Ok(g) => g,
        Err(code) => return code,
    };
    let report = semo::taskgraph::analysis::analyze(&graph);
    write_picture(
        &semo::taskgraph::to_svg_analyzed(&graph, &report),
        output,
        out,
    )
}

const MODES: &str = "semo graph modes";

/// The mission `semo graph modes` draws, checked; `None` when it cannot be
/// read or is not a mission (the reason printed).
fn load_mission(path: &Path) -> Option<semo::host::CheckRun> {
    if input::is_stdin(path) {
        let (name, text) = input::read(path)?;
        return input::is_kind(&name, &text, Content::Mission, MODES)
            .then(|| semo::host::load_check_stdin(text));
    }
    if !input::file_is_kind(path, Content::Mission, MODES) {
        return None;
    }
    semo::host::load_check(&[path.to_path_buf()])
        .map_err(|e| eprintln!("error: {e}"))
        .ok()
}

/// `semo graph modes`: the mode machines of a mission, checked as `semo check
/// FILE` checks it (against the catalog files it sees; standard input
/// against the built-in catalog alone), all teams or `team`.
/// Errors in the mission or what it reads do not stop the drawing: what was
/// understood is drawn, the errors are on stderr and the exit code is 1. An
/// unknown team is a usage error (2).
pub fn modes(path: &Path, team: Option<&str>, output: Option<&Path>, out: &mut impl Write) -> i32 {
    let Some(run) = load_mission(path) else {
        return 2;
    };
    let analysis = run
        .checked
        .first()
        .and_then(|&id| run.analysis().mission(id));
    let Some(analysis) = analysis else {
        eprintln!("error: {}: not a mission", path.display());
        return 2;
    };
    let mut machines = semo::modemachine::machines(&analysis.mission);
    if let Some(team) = team {
        machines.retain(|m| m.team == team);
        if machines.is_empty() {
            let known: Vec<&str> = analysis
                .mission
                .teams
                .iter()
                .map(|t| t.name.as_str())
                .collect();
            eprintln!(
                "error: {}: no team `{team}` with modes (teams: {})",
                path.display(),
                known.join(", ")
            );
            return 2;
        }
    }
    let errors: Vec<Diagnostic> = run
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .cloned()
        .collect();
    let _ = render::diagnostics(&run.files, &errors, false, &mut std::io::stderr());
    match write_picture(&semo::modemachine::to_svg(&machines), output, out) {
        0 if !errors.is_empty() => 1,
        code => code,
    }
}

/// Writes a picture to `output`, or standard output (no `-o`, or `-o -`).
fn write_picture(picture: &str, output: Option<&Path>, out: &mut impl Write) -> i32 {
    match output.filter(|file| !input::is_stdin(file)) {
        Some(file) => match std::fs::write(file, picture) {
            Ok(()) => 0,
            Err(e) => {
                eprintln!("error: {}: {e}", file.display());
                2
            }
        },
        None => {
            let _ = out.write_all(picture.as_bytes());
            0
        }
    }
}

pub fn analyze(
    path: &Path,
    reading: GraphReading,
    format: Format,
    color: bool,
    out: &mut impl Write,
) -> i32 {
    let Some((files, run)) = read_and_analyze(path, reading, "semo graph analyze") else {
        return 2;
    };
    let written = match format {
        Format::Human | Format::Concise => render::people(
            format,
            &files,
            &run.diagnostics,
            color,
            &mut std::io::stderr().lock(),
        )
        .and_then(|()| write_human(&run, reading, out)),
        Format::Json => output::report(
            format,
            "graph analyze",
            &files,
            &run.diagnostics,
            color,
            analysis_json(&run, reading),
            out,
        ),
        Format::Sarif => output::report(
            format,
            "graph analyze",
            &files,
            &run.diagnostics,
            color,
            serde_json::Value::Null,
            out,
        ),
    };
    let code = match output::written(written) {
        Err(code) => code,
        Ok(()) if run.diagnostics.iter().any(Diagnostic::is_error) => 1,
        Ok(()) => 0,
    };
    // The process ends next: freeing a large graph and its report piece by
    // piece would only add to its time (a twentieth on a 1,000-actor graph).
    std::mem::forget((files, run));
    code
}

/// Why a level has no period, in words: the analysis's reason, and under
/// `--sdf3-compat` where the times come from.
fn no_period_words(why: NoPeriod, reading: GraphReading) -> String {
    let compat = reading.times == semo::taskgraph::ExecutionTimes::Sdf3Compat;
    match why {
        NoPeriod::Untimed if compat => format!(
            "{} (with --sdf3-compat an actor's time comes only from a processor marked `default`)",
            why.why()
        ),
        _ => why.why().to_string(),
    }
}

/// The analysis for people (its diagnostics went to standard error).
fn write_human(
    run: &semo::workspace::GraphRun,
    reading: GraphReading,
    out: &mut impl Write,
) -> std::io::Result<()> {
    use std::fmt::Write as _;
    if !run.report.levels.is_empty() {
        writeln!(
            out,
            "concurrency: {}",
            concurrency_words(run.report.concurrency)
        )?;
    }
    for level in &run.report.levels {
        let state = match (&level.repetition, level.deadlock_free) {
            (None, _) => "inconsistent".to_string(),
            (Some(_), Some(false)) => "consistent, deadlocks".to_string(),
            (Some(_), _) => "consistent, deadlock-free".to_string(),
        };
        let per = if level.path.contains('/') {
            " (per iteration)"
        } else {
            ""
        };
        writeln!(out, "{}{per}: {state}", level.path)?;
        // Each of these lines is built in one string, not from a string per
        // item joined (a 1,000-actor graph has 3,000 items).
        if let Some(counts) = &level.repetition {
            let pairs = level
                .nodes
                .iter()
                .zip(counts)
                .filter(|(name, _)| !name.ends_with(')'));
            let mut line = String::from("  repetition vector:");
            for (name, n) in pairs {
                let _ = write!(line, " {name}={n}");
            }
            if line.ends_with(':') {
                line.push(' ');
            }
            writeln!(out, "{line}")?;
        }
        if let Some(schedule) = &level.schedule {
            writeln!(out, "  schedule: {schedule}")?;
        }
        match &level.throughput {
            Ok(t) => {
                let cycle = match t.critical_cycle.as_slice() {
                    [] => "no cycle: unbounded throughput".to_string(),
                    [one] => format!("bounded by {one} alone"),
                    many => format!("bounded by {} → {}", many.join(" → "), many[0]),
                };
                writeln!(out, "  iteration period: {} ({cycle})", t.period)?;
            }
            // The state line above already says these.
            Err(NoPeriod::Inconsistent | NoPeriod::Deadlock) => {}
            Err(why) => writeln!(
                out,
                "  iteration period: none: {}",
                no_period_words(*why, reading)
            )?,
        }
        if !level.buffers.is_empty() {
            let mut line = String::from("  buffers: ");
            for (i, b) in level.buffers.iter().enumerate() {
                let sep = if i == 0 { "" } else { ", " };
                let _ = write!(line, "{sep}{}: {}", b.channel, b.samples);
            }
            writeln!(out, "{line}")?;
        }
    }
    if let Some(looped) = &run.report.looped_schedule {
        writeln!(out, "looped schedule: {looped}")?;
    }
    if run.report.levels.is_empty() {
        writeln!(out, "not analysed: the file has errors")?;
    }
    Ok(())
}

/// The analysis's own fields of the JSON document.
fn analysis_json(run: &semo::workspace::GraphRun, reading: GraphReading) -> serde_json::Value {
    let levels: Vec<serde_json::Value> = run
        .report
        .levels
        .iter()
        .map(|level| {
            let repetition = level.repetition.as_ref().map(|counts| {
                level
                    .nodes
                    .iter()
                    .zip(counts)
                    .map(|(name, n)| (name.clone(), serde_json::json!(n)))
                    .collect::<serde_json::Map<_, _>>()
            });
            let buffers: serde_json::Map<String, serde_json::Value> = level
                .buffers
                .iter()
                .map(|b| (b.channel.clone(), serde_json::json!(b.samples)))
                .collect();
            serde_json::json!({
                "path": level.path,
                "consistent": level.repetition.is_some(),
                "deadlock_free": level.deadlock_free,
                "repetition": repetition,
                "schedule": level.schedule,
                "buffers": buffers,
                "throughput": level.throughput.as_ref().ok().map(|t| serde_json::json!({
                    "period": t.period.to_string(),
                    "critical_cycle": t.critical_cycle,
                })),
                "no_period": level.throughput.as_ref().err().map(|&why| serde_json::json!({
                    "reason": why.as_str(),
                    "message": no_period_words(why, reading),
                })),
            })
        })
        .collect();
    serde_json::json!({
        "graph": run.graph.as_ref().map(|g| g.name.clone()),
        "concurrency": run.report.concurrency.as_str(),
        "looped_schedule": run.report.looped_schedule,
        "levels": levels,
    })
}

/// `semo graph schedule`: the looped schedule of the whole graph, and with
/// `cores` a list schedule of each level's iteration onto that many cores.
pub fn schedule(path: &Path, cores: Option<usize>, out: &mut impl Write) -> i32 {
    use semo::taskgraph::analysis::{hierarchy_levels, schedule};
    let Some((name, text)) = read(path, "semo graph schedule") else {
        return 2;
    };
    let mut files = Files::default();
    let id = files.add(name, FileKind::TaskGraph, text);
    let run = analyze_graph(files.get(id), &mut FileResolver::new(&files));
    let Some(graph) = run
        .graph
        .as_ref()
        .filter(|_| !run.diagnostics.iter().any(Diagnostic::is_error))
    else {
        let _ = render::diagnostics(&files, &run.diagnostics, false, &mut std::io::stderr());
        return 1;
    };
    let mut text = String::new();
    match &run.report.looped_schedule {
        Some(looped) => text.push_str(&format!("{looped}\n")),
        None => {
            for level in &run.report.levels {
                let s = level.schedule.as_deref().unwrap_or("(none)");
                text.push_str(&format!("{}: {s}\n", level.path));
            }
        }
    }
    if let Some(cores) = cores {
        // The report's levels are these, in the same order.
        let levels = hierarchy_levels(graph, &run.hierarchy);
        for (level, report) in levels.iter().zip(&run.report.levels) {
            let (Some(counts), Some(true)) = (&report.repetition, report.deadlock_free) else {
                continue;
            };
            let Some(plan) = schedule::multicore(level, counts, cores) else {
                text.push_str(&format!("{}: no schedule on {cores} cores\n", level.path));
                continue;
            };
            text.push_str(&format!(
                "{} on {cores} core{}:\n",
                level.path,
                if cores == 1 { "" } else { "s" }
            ));
            for (core, firings) in plan.iter().enumerate() {
                // Loop boundary nodes take no time and run no code: not shown.
                let items: Vec<String> = firings
                    .iter()
                    .filter(|&&(node, _)| level.nodes[node].task.is_some())
                    .map(|&(node, start)| format!("{}@{start}", level.nodes[node].name))
                    .collect();
                text.push_str(&format!("  core {core}: {}\n", items.join(" ")));
            }
        }
    }
    let _ = out.write_all(text.as_bytes());
    0
}

/// A throughput `max`, `A/B` or a decimal, as the period bound it means:
/// `Ok(None)` for `max`.
fn period_bound(text: &str) -> Result<Option<Ratio>, String> {
    let text = text.trim();
    if text == "max" {
        return Ok(None);
    }
    let bad =
        || format!("`{text}` is not a throughput: give `max`, `A/B` or a decimal such as 0.0096");
    let (num, den) = match text.split_once('/') {
        Some((a, b)) => (
            a.trim().parse::<u64>().map_err(|_| bad())?,
            b.trim().parse::<u64>().map_err(|_| bad())?,
        ),
        None => {
            let (whole, frac) = text.split_once('.').unwrap_or((text, ""));
            if frac.len() > 18 || !(whole.chars().chain(frac.chars())).all(|c| c.is_ascii_digit()) {
                return Err(bad());
            }
            let den = 10u64.pow(frac.len() as u32);
            let digits = format!("{whole}{frac}");
            (digits.parse::<u64>().map_err(|_| bad())?, den)
        }
    };
    if num == 0 || den == 0 {
        return Err(bad());
    }
    // The period bound is the inverse of the throughput.
    Ratio::new(den, num).map(Some).ok_or_else(bad)
}

/// `semo graph buffers`: the storage/throughput trade-off of the top level.
pub fn buffers(
    path: &Path,
    reading: GraphReading,
    throughput: &str,
    json: bool,
    out: &mut impl Write,
) -> i32 {
    use semo::taskgraph::analysis::{level::Level, tradeoff};
    let bound = match period_bound(throughput) {
        Ok(b) => b,
        Err(message) => {
            eprintln!("error: {message}");
            return 2;
        }
    };
    let Some((files, run)) = read_and_analyze(path, reading, "semo graph buffers") else {
        return 2;
    };
    let live = run
        .report
        .levels
        .first()
        .is_some_and(|l| l.deadlock_free == Some(true));
    let Some(graph) = run
        .graph
        .as_ref()
        .filter(|_| live && !run.diagnostics.iter().any(Diagnostic::is_error))
    else {
        let format = if json { Format::Json } else { Format::Human };
        let reported = output::report(
            format,
            "graph buffers",
            &files,
            &run.diagnostics,
            false,
            serde_json::json!({}),
            out,
        );
        if let Err(code) = output::written(reported) {
            return code;
        }
        eprintln!(
            "error: {}: the buffers of a graph with errors cannot be sized",
            path.display()
        );
        return 1;
    };
    let concurrency = run.report.concurrency;
    let level = Level::build(graph, None, graph.name.clone());
    let Some(found) = tradeoff::trade_off_towards(&level, concurrency, bound) else {
        eprintln!(
            "error: {}: the period of this graph cannot be computed (too large an expansion or overflow)",
            path.display()
        );
        return 1;
    };
    let chosen = match bound {
        None => found.for_max_throughput(),
        Some(period) => found.for_period(period),
    };
    let written = if json {
        buffers_json(&level, &found, concurrency, chosen, out)
    } else {
        buffers_human(&level, &found, concurrency, bound, chosen, out)
    };
    if let Err(e) = written
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        eprintln!("error: cannot write the report: {e}");
        return 2;
    }
    if found.unbounded_throughput() && bound.is_none() {
        eprintln!(
            "error: {}: {UNBOUNDED}: ask for a period with --throughput",
            path.display()
        );
        return 1;
    }
    if chosen.is_none() {
        let why = if found.budget_exhausted {
            " (the search stopped at its work budget)"
        } else {
            ""
        };
        eprintln!("error: no buffer distribution found reaches that throughput{why}");
        return 1;
    }
    0
}

/// What `graph buffers` says of a level whose throughput nothing but the
/// buffers bounds.
const UNBOUNDED: &str = "the throughput is unbounded (no cycle bounds the period; every larger buffer raises it): no finite buffer distribution reaches it";

/// The sentence saying that the work budget stopped the search.
fn budget_words(found: &semo::taskgraph::analysis::tradeoff::TradeOff) -> String {
    let limit = found.work_limit;
    if found.evaluations == 1 {
        return format!(
            "no distribution evaluated: one evaluation takes {} work units (firings plus dependencies of one iteration), more than the search's budget of {limit}",
            found.evaluation_cost
        );
    }
    format!(
        "the search stopped at its work budget ({} work units of {limit}, {} evaluations of {} each): the points are distributions found, the bounds hold",
        found.work, found.evaluations, found.evaluation_cost
    )
}

fn minimum_words(found: &semo::taskgraph::analysis::tradeoff::TradeOff) -> String {
    match found.for_max_throughput() {
        Some(p) if found.exact() => format!("{} (exact: the lower bound is reached)", p.size),
        Some(p) => format!(
            "between {} and {} (a distribution of {} was found; no smaller one than {} can reach it)",
            found.lower_bound, p.size, p.size, found.lower_bound
        ),
        None => format!(
            "at least {} (no distribution found reaches it)",
            found.lower_bound
        ),
    }
}

fn buffers_human(
    level: &semo::taskgraph::analysis::level::Level<'_>,
    found: &semo::taskgraph::analysis::tradeoff::TradeOff,
    concurrency: semo::taskgraph::analysis::Concurrency,
    bound: Option<Ratio>,
    chosen: Option<&semo::taskgraph::analysis::tradeoff::Point>,
    out: &mut impl Write,
) -> std::io::Result<()> {
    writeln!(out, "concurrency: {}", concurrency.as_str())?;
    if found.unbounded_throughput() {
        writeln!(out, "maximal throughput: {UNBOUNDED}")?;
        if bound.is_none() {
            return Ok(());
        }
    } else {
        writeln!(
            out,
            "maximal throughput: period {} (unbounded buffers)",
            found.max_period
        )?;
    }
    if found.exact_front {
        writeln!(
            out,
            "trade-off (total buffer size → period; the exact Pareto front: every point the smallest size for its period, none missing):"
        )?;
    } else {
        writeln!(
            out,
            "trade-off (total buffer size → period; each point a distribution found that reaches its period, where a smaller one may too: the exact front was too large to explore within the budget):"
        )?;
    }
    for p in &found.points {
        writeln!(out, "  {} → {}", p.size, p.period)?;
    }
    if !found.unbounded_throughput() {
        writeln!(
            out,
            "smallest total size for the maximal throughput: {}",
            minimum_words(found)
        )?;
    }
    if found.budget_exhausted {
        writeln!(out, "{}", budget_words(found))?;
    }
    match chosen {
        Some(p) => {
            let what = match bound {
                None => "the maximal throughput".to_string(),
                Some(b) => format!("period at most {b}"),
            };
            writeln!(out, "channel sizes for {what} ({} → {}):", p.size, p.period)?;
            for (e, cap) in level.edges.iter().zip(&p.capacities) {
                writeln!(out, "  {}: {cap}", e.label)?;
            }
        }
        None => writeln!(out, "no distribution found reaches that throughput")?,
    }
    Ok(())
}

fn buffers_json(
    level: &semo::taskgraph::analysis::level::Level<'_>,
    found: &semo::taskgraph::analysis::tradeoff::TradeOff,
    concurrency: semo::taskgraph::analysis::Concurrency,
    chosen: Option<&semo::taskgraph::analysis::tradeoff::Point>,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let points: Vec<serde_json::Value> = found
        .points
        .iter()
        .map(|p| {
            serde_json::json!({
                "size": p.size,
                "period": p.period.to_string(),
                "proof": if found.exact_front { "exact" } else { "bounded" },
            })
        })
        .collect();
    let channels = chosen.map(|p| {
        level
            .edges
            .iter()
            .zip(&p.capacities)
            .map(|(e, cap)| (e.label.clone(), serde_json::json!(cap)))
            .collect::<serde_json::Map<_, _>>()
    });
    let data = serde_json::json!({
        "concurrency": concurrency.as_str(),
        "max_period": found.max_period.to_string(),
        "points": points,
        "exact_front": found.exact_front,
        "unbounded_throughput": found.unbounded_throughput(),
        "minimal_size": {
            "lower_bound": found.lower_bound,
            "found": found.for_max_throughput().map(|p| p.size),
            "exact": found.exact(),
        },
        "budget": {
            "work": found.work,
            "limit": found.work_limit,
            "per_evaluation": found.evaluation_cost,
            "exhausted": found.budget_exhausted,
        },
        "message": if found.unbounded_throughput() {
            Some(UNBOUNDED.to_string())
        } else if found.budget_exhausted {
            Some(budget_words(found))
        } else {
            None
        },
        "chosen": chosen.map(|p| serde_json::json!({
            "size": p.size,
            "period": p.period.to_string(),
            "channels": channels,
        })),
    });
    output::write_json(out, &output::json_document("graph buffers", &[], data))
}

/// `semo graph latency`: the minimal and self-timed latency from one task of
/// the graph's top level to another.
pub fn latency(
    path: &Path,
    reading: GraphReading,
    from: &str,
    to: &str,
    json: bool,
    out: &mut impl Write,
) -> i32 {
    use semo::taskgraph::analysis::{hierarchy_levels, latency};
    const COMMAND: &str = "graph latency";
    let format = if json { Format::Json } else { Format::Human };
    let Some((files, run)) = read_and_analyze(path, reading, "semo graph latency") else {
        return 2;
    };
    let top = run.report.levels.first();
    let counts = top
        .filter(|l| l.deadlock_free == Some(true))
        .and_then(|l| l.repetition.as_ref());
    let (Some(graph), Some(counts), false) = (
        run.graph.as_ref(),
        counts,
        run.diagnostics.iter().any(Diagnostic::is_error),
    ) else {
        let reported = output::report(
            format,
            COMMAND,
            &files,
            &run.diagnostics,
            false,
            serde_json::json!({ "error": { "reason": "errors", "message": "the graph has errors" } }),
            out,
        );
        if let Err(code) = output::written(reported) {
            return code;
        }
        let why = match top {
            Some(l) if l.repetition.is_none() => "its rates are inconsistent",
            Some(l) if l.deadlock_free == Some(false) => "an iteration deadlocks",
            _ => "the file has errors",
        };
        eprintln!("error: {}: no latency: {why} (see above)", path.display());
        return 1;
    };
    // The report's levels are these, in the same order; the top level's
    // tasks standing for sub-graphs take their sub-graph's time.
    let levels = hierarchy_levels(graph, &run.hierarchy);
    let level = &levels[0];
    let (source, sink) = match (task_node(level, from), task_node(level, to)) {
        (Ok(s), Ok(k)) => (s, k),
        (Err(message), _) | (_, Err(message)) => {
            return output::refused(format, COMMAND, path, &message, out);
        }
    };
    let concurrency = run.report.concurrency;
    let found = latency::latency(level, counts, source, sink, concurrency);
    let written = if json {
        let data = latency_json(level, from, to, concurrency, &found);
        let records = output::records(&files, &run.diagnostics);
        output::write_json(out, &output::json_document(COMMAND, &records, data))
    } else {
        render::people(
            Format::Human,
            &files,
            &run.diagnostics,
            false,
            &mut std::io::stderr().lock(),
        )
        .and_then(|()| latency_human(level, from, to, concurrency, &found, out))
    };
    if let Err(code) = output::written(written) {
        return code;
    }
    match found {
        Ok(_) => 0,
        Err(why) => {
            eprintln!(
                "error: {}: no latency from `{from}` to `{to}`: {}",
                path.display(),
                why.why()
            );
            1
        }
    }
}

/// The node of the task named `name` in the top level, else why not.
fn task_node(
    level: &semo::taskgraph::analysis::level::Level<'_>,
    name: &str,
) -> Result<usize, String> {
    if let Some(v) = level.nodes.iter().position(|n| n.name == name) {
        return Ok(v);
    }
    let names = level.nodes.iter().map(|n| n.name.as_str());
    let mut message = format!("no task `{name}` in the graph's top level");
    if let Some(close) = semo::suggest::did_you_mean(name, names.clone()) {
        message.push_str(&format!(" (did you mean `{close}`?)"));
    } else if level.nodes.len() <= 12 {
        let all: Vec<&str> = names.collect();
        message.push_str(&format!(" (tasks: {})", all.join(", ")));
    }
    Err(message)
}

/// `S`'s firing `2k + 1`: which firing of a task with `count` firings per
/// iteration starts or ends iteration `k`, `offset` after its first.
fn firing_of_iteration(count: u64, offset: u64) -> String {
    let k = if count == 1 {
        "k".to_string()
    } else {
        format!("{count}k")
    };
    if offset == 0 {
        k
    } else {
        format!("{k} + {offset}")
    }
}

fn concurrency_words(concurrency: semo::taskgraph::analysis::Concurrency) -> &'static str {
    match concurrency {
        semo::taskgraph::analysis::Concurrency::Auto => {
            "auto (a task fires concurrently with itself unless a self-loop channel limits it)"
        }
        semo::taskgraph::analysis::Concurrency::Single => "single (one firing of a task at a time)",
    }
}

/// What `graph latency` found between its two tasks.
type LatencyFound = Result<
    semo::taskgraph::analysis::latency::Latency,
    semo::taskgraph::analysis::latency::NoLatency,
>;

fn latency_human(
    level: &semo::taskgraph::analysis::level::Level<'_>,
    from: &str,
    to: &str,
    concurrency: semo::taskgraph::analysis::Concurrency,
    found: &LatencyFound,
    out: &mut impl Write,
) -> std::io::Result<()> {
    use semo::taskgraph::analysis::latency::NoSelfTimed;
    writeln!(out, "concurrency: {}", concurrency_words(concurrency))?;
    let Ok(l) = found else {
        return Ok(());
    };
    writeln!(
        out,
        "iteration k: from the start of {from}'s firing {} to the end of {to}'s firing {} ({to} fires {} time{} before {from} first does)",
        firing_of_iteration(l.source_firings, 0),
        firing_of_iteration(l.sink_firings, l.offset),
        l.sink_firings_before,
        if l.sink_firings_before == 1 { "" } else { "s" },
    )?;
    writeln!(out, "minimal latency: {}", l.minimal)?;
    match &l.self_timed {
        Ok(st) => writeln!(
            out,
            "self-timed latency: {} (the largest, first at iteration {}; the latencies repeat every {} iteration{} from iteration {} on at the latest)",
            st.latency,
            st.worst_iteration,
            st.cycle,
            if st.cycle == 1 { "" } else { "s" },
            st.periodic_from,
        ),
        Err(why @ NoSelfTimed::Unbounded { .. }) => writeln!(
            out,
            "self-timed latency: unbounded: {}",
            why.describe(level)
        ),
        Err(why) => writeln!(out, "self-timed latency: none: {}", why.describe(level)),
    }
}

fn latency_json(
    level: &semo::taskgraph::analysis::level::Level<'_>,
    from: &str,
    to: &str,
    concurrency: semo::taskgraph::analysis::Concurrency,
    found: &LatencyFound,
) -> serde_json::Value {
    let mut data = serde_json::json!({
        "from": from,
        "to": to,
        "concurrency": concurrency.as_str(),
    });
    let fields = match found {
        Ok(l) => serde_json::json!({
            "firings": { "from": l.source_firings, "to": l.sink_firings },
            "sink_firings_before": l.sink_firings_before,
            "offset": l.offset,
            "minimal": l.minimal,
            "self_timed": l.self_timed.as_ref().ok().map(|st| serde_json::json!({
                "latency": st.latency,
                "worst_iteration": st.worst_iteration,
                "periodic_from": st.periodic_from,
                "cycle": st.cycle,
            })),
            "no_self_timed": l.self_timed.as_ref().err().map(|why| serde_json::json!({
                "reason": why.as_str(),
                "message": why.describe(level),
            })),
        }),
        Err(why) => serde_json::json!({
            "error": { "reason": why.as_str(), "message": why.why() },
        }),
    };
    if let (Some(all), serde_json::Value::Object(more)) = (data.as_object_mut(), fields) {
        all.extend(more);
    }
    data
}
