//! `semo graph analyze|schedule|dot|svg`: a task graph's repetition vectors
//! and deadlock freedom level by level with its diagnostics, its schedules,
//! and pictures of it; `semo graph modes`: a mission's mode machines.

use super::render;
use semo::diag::Diagnostic;
use semo::workspace::{DiskResolver, FileKind, Files, analyze_graph};
use std::io::Write;
use std::path::Path;

fn read(path: &Path) -> Option<String> {
    match semo::workspace::read_text(path) {
        Ok(text) => Some(text),
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            None
        }
    }
}

/// The graph in `path` when it loads without errors; otherwise the errors
/// are printed and the exit code given.
fn load_clean(path: &Path) -> Result<semo::taskgraph::TaskGraph, i32> {
    let Some(text) = read(path) else {
        return Err(2);
    };
    let mut files = Files::default();
    let id = files.add(path.to_path_buf(), FileKind::TaskGraph, text);
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
    match load_clean(path) {
        Ok(g) => {
            let _ = out.write_all(semo::taskgraph::dot::to_dot(&g).as_bytes());
            0
        }
        Err(code) => code,
    }
}

/// `semo graph svg`: the SVG picture on `out` or in `output`, or the loading
/// errors (exit 1).
pub fn svg(path: &Path, output: Option<&Path>, out: &mut impl Write) -> i32 {
    let graph = match load_clean(path) {
        Ok(g) => g,
        Err(code) => return code,
    };
    write_picture(&semo::taskgraph::to_svg(&graph), output, out)
}

/// `semo graph modes`: the mode machines of a mission (checked against the
/// built-in catalog and the `*.robot.xml` files beside it, as `semo check`
/// of its folder would), all teams or `team`. Errors in the mission do not
/// stop the drawing: what was understood is drawn, the errors are on stderr
/// and the exit code is 1. An unknown team is a usage error (2).
pub fn modes(path: &Path, team: Option<&str>, output: Option<&Path>, out: &mut impl Write) -> i32 {
    let Some(text) = read(path) else { return 2 };
    let mut files = Files::default();
    // The catalog files beside the mission (and below), as `semo check DIR`.
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let beside = semo::workspace::collect(&[folder.to_path_buf()]).unwrap_or_default();
    for (catalog, _) in beside.iter().filter(|(_, k)| *k == FileKind::Catalog) {
        if let Some(text) = read(catalog) {
            files.add(catalog.clone(), FileKind::Catalog, text);
        }
    }
    let id = files.add(path.to_path_buf(), FileKind::Mission, text);
    let run = semo::workspace::check_files(files);
    let Some((_, analysis)) = run.analyses.iter().find(|(f, _)| *f == id) else {
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

fn write_picture(picture: &str, output: Option<&Path>, out: &mut impl Write) -> i32 {
    match output {
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

pub fn analyze(path: &Path, json: bool, color: bool, out: &mut impl Write) -> i32 {
    let Some(text) = read(path) else { return 2 };
    let mut files = Files::default();
    let id = files.add(path.to_path_buf(), FileKind::TaskGraph, text);
    let run = analyze_graph(files.get(id), &mut DiskResolver::new(&files));
    let written = if json {
        write_json(&files, &run, out)
    } else {
        write_human(&files, &run, color, out)
    };
    if let Err(e) = written
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        eprintln!("error: cannot write the report: {e}");
        return 2;
    }
    if run.diagnostics.iter().any(Diagnostic::is_error) {
        1
    } else {
        0
    }
}

fn write_human(
    files: &Files,
    run: &semo::workspace::GraphRun,
    color: bool,
    out: &mut impl Write,
) -> std::io::Result<()> {
    render::diagnostics(files, &run.diagnostics, color, out)?;
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
        if let Some(counts) = &level.repetition {
            let pairs: Vec<String> = level
                .nodes
                .iter()
                .zip(counts)
                .filter(|(name, _)| !name.ends_with(')'))
                .map(|(name, n)| format!("{name}={n}"))
                .collect();
            writeln!(out, "  repetition vector: {}", pairs.join(" "))?;
        }
        if let Some(schedule) = &level.schedule {
            writeln!(out, "  schedule: {schedule}")?;
        }
        if let Some(t) = &level.throughput {
            let cycle = match t.critical_cycle.as_slice() {
                [one] => format!("{one} alone"),
                many => format!("{} → {}", many.join(" → "), many[0]),
            };
            writeln!(out, "  iteration period: {} (bounded by {cycle})", t.period)?;
        }
        if !level.buffers.is_empty() {
            let bounds: Vec<String> = level
                .buffers
                .iter()
                .map(|b| format!("{}: {}", b.channel, b.samples))
                .collect();
            writeln!(out, "  buffers: {}", bounds.join(", "))?;
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

fn write_json(
    files: &Files,
    run: &semo::workspace::GraphRun,
    out: &mut impl Write,
) -> std::io::Result<()> {
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
                "throughput": level.throughput.as_ref().map(|t| serde_json::json!({
                    "period": t.period.to_string(),
                    "critical_cycle": t.critical_cycle,
                })),
            })
        })
        .collect();
    let diagnostics: Vec<serde_json::Value> = run
        .diagnostics
        .iter()
        .map(|d| render::json_value(files, d))
        .collect();
    let value = serde_json::json!({
        "graph": run.graph.as_ref().map(|g| g.name.clone()),
        "looped_schedule": run.report.looped_schedule,
        "levels": levels,
        "diagnostics": diagnostics,
    });
    writeln!(out, "{value}")
}

/// `semo graph schedule`: the looped schedule of the whole graph, and with
/// `cores` a list schedule of each level's iteration onto that many cores.
pub fn schedule(path: &Path, cores: Option<usize>, out: &mut impl Write) -> i32 {
    use semo::taskgraph::analysis::{hierarchy_levels, schedule};
    let Some(text) = read(path) else { return 2 };
    let mut files = Files::default();
    let id = files.add(path.to_path_buf(), FileKind::TaskGraph, text);
    let run = analyze_graph(files.get(id), &mut DiskResolver::new(&files));
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
