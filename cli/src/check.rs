//! `semo check`: the report on the files named (or the current folder), with
//! `--fix` applying the preferred quick fixes first and `--statistics`
//! counting the problems by code instead of listing them.

use crate::fix::{self, Applied};
use crate::output::{self, Format};
use crate::{input, render};
use semo::diag::{Code, Diagnostic, FileId, Severity};
use semo::host::CheckRun;
use semo::span::Span;
use semo::workspace::FileKind;
use std::collections::{BTreeMap, HashSet};
use std::io::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug)]
pub struct Options {
    pub format: Format,
    pub color: bool,
    pub deny_warnings: bool,
    pub fix: bool,
    pub statistics: bool,
}

pub fn run(paths: Vec<PathBuf>, options: Options, out: &mut impl Write) -> i32 {
    checked(paths, options, out).0
}

/// [`run`] when the process ends next: the check's data is not freed piece
/// by piece, which would only add to its time (a tenth of it on a 3 MB
/// mission). `--watch` checks again and again, and frees.
pub fn run_once(paths: Vec<PathBuf>, options: Options, out: &mut impl Write) -> i32 {
    let (code, run) = checked(paths, options, out);
    std::mem::forget(run);
    code
}

/// The exit code of a check, and the check (`None` when it was refused).
fn checked(paths: Vec<PathBuf>, options: Options, out: &mut impl Write) -> (i32, Option<CheckRun>) {
    let format = options.format;
    if options.statistics && format == Format::Sarif {
        eprintln!("error: --statistics has no SARIF form (use --format human, concise or json)");
        return (2, None);
    }
    let paths = if paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        paths
    };
    let (run, applied) = match load(&paths, options.fix, out) {
        Ok(loaded) => loaded,
        Err((path, message)) => {
            return (output::refused(format, "check", &path, &message, out), None);
        }
    };
    let fixable = if options.statistics || format.for_people() {
        fixable(&run)
    } else {
        HashSet::new()
    };
    let is_fixable = |d: &Diagnostic| fixable.contains(&(d.file, d.code, d.span));
    let written = match format {
        // The report for people, summary included, is diagnostics: stderr.
        Format::Human | Format::Concise => {
            let mut err = std::io::stderr().lock();
            people(&run, &applied, options, &is_fixable, &mut err)
        }
        _ => {
            let mut data = serde_json::json!({});
            if options.fix {
                data["fixes"] = serde_json::json!(applied);
            }
            if options.statistics {
                data["statistics"] = serde_json::json!(
                    statistics(&run.diagnostics, &is_fixable)
                        .into_iter()
                        .map(|s| serde_json::json!({
                            "code": s.code.as_str(),
                            "severity": s.severity.as_str(),
                            "count": s.count,
                            "fixable": s.fixable,
                        }))
                        .collect::<Vec<_>>()
                );
            }
            output::report(
                format,
                "check",
                &run.files,
                &run.diagnostics,
                options.color,
                data,
                out,
            )
        }
    };
    if let Err(code) = output::written(written) {
        return (code, Some(run));
    }
    let warnings = run
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .count();
    let code = if run.error_count() > 0 {
        1
    } else if options.deny_warnings && warnings > 0 {
        eprintln!("error: {warnings} warning(s), denied by --deny warnings");
        1
    } else {
        0
    };
    (code, Some(run))
}

/// The check of `paths`, after the fixes when `fix` (a mission on standard
/// input is then printed fixed on `out`), and the fixes applied.
fn load(
    paths: &[PathBuf],
    fix: bool,
    out: &mut impl Write,
) -> Result<(CheckRun, Vec<Applied>), (PathBuf, String)> {
    let stdin = paths.iter().any(|p| input::is_stdin(p));
    if !fix {
        return load_for_check(paths).map(|run| (run, Vec::new()));
    }
    let source = if stdin {
        // The refusals of `-` with other paths, before reading anything.
        if paths.len() > 1 {
            load_for_check(paths)?;
        }
        fix::Source::Stdin(input::read_stdin().map_err(|m| (PathBuf::from(input::STDIN_NAME), m))?)
    } else {
        fix::Source::Paths(&|| load_for_check(paths))
    };
    let fixed = fix::run(source)?;
    if let Some(text) = &fixed.stdin_text {
        let written = out.write_all(text.as_bytes()).and_then(|()| out.flush());
        output::written(written).map_err(|_| {
            let message = "cannot write the fixed mission".to_string();
            (PathBuf::from(input::STDIN_NAME), message)
        })?;
    }
    Ok((fixed.run, fixed.applied))
}

/// The files `semo check PATHS` reports on, loaded; or the path that
/// stopped it and why.
fn load_for_check(paths: &[PathBuf]) -> Result<CheckRun, (PathBuf, String)> {
    for path in paths {
        if let Some(message) = input::named_file_misfit(path) {
            return Err((path.clone(), message));
        }
    }
    if paths.iter().any(|p| input::is_stdin(p)) {
        if paths.len() > 1 {
            let message =
                "`-` (a mission on standard input) cannot be checked with other paths".to_string();
            return Err((PathBuf::from(input::STDIN_NAME), message));
        }
        return input::read_stdin()
            .map(semo::host::load_check_stdin)
            .map_err(|message| (PathBuf::from(input::STDIN_NAME), message));
    }
    semo::host::load_check(paths).map_err(|e| (e.path.clone(), e.to_string()))
}

/// The diagnostics `--fix` would fix: those with a preferred quick fix.
fn fixable(run: &CheckRun) -> HashSet<(FileId, Code, Span)> {
    let analysis = run.analysis();
    let mut found = HashSet::new();
    for &id in &run.checked {
        let file = run.files.get(id);
        if !matches!(file.kind, FileKind::Mission | FileKind::Strategy) {
            continue;
        }
        let published = analysis.diagnostics(id);
        if published.is_empty() {
            continue; // nothing to fix: no quick fixes asked for
        }
        for action in analysis.code_actions(id, Span::new(0, file.text.len())) {
            if let Some(d) = published
                .get(action.diagnostic)
                .filter(|_| action.preferred)
            {
                found.insert((d.file, d.code, d.span));
            }
        }
    }
    found
}

struct CodeCount {
    code: Code,
    severity: Severity,
    count: usize,
    fixable: usize,
}

/// How many diagnostics of each code (and severity), most frequent first.
fn statistics(found: &[Diagnostic], is_fixable: &dyn Fn(&Diagnostic) -> bool) -> Vec<CodeCount> {
    let mut by_code: BTreeMap<(Code, Severity), (usize, usize)> = BTreeMap::new();
    for d in found {
        let entry = by_code.entry((d.code, d.severity)).or_default();
        entry.0 += 1;
        entry.1 += usize::from(is_fixable(d));
    }
    let mut counts: Vec<CodeCount> = by_code
        .into_iter()
        .map(|((code, severity), (count, fixable))| CodeCount {
            code,
            severity,
            count,
            fixable,
        })
        .collect();
    counts.sort_by_key(|c| std::cmp::Reverse(c.count));
    counts
}

/// The report for people: the fixes applied, the problems (or their
/// statistics), the summary, and how many `--fix` would fix.
fn people(
    run: &CheckRun,
    applied: &[Applied],
    options: Options,
    is_fixable: &dyn Fn(&Diagnostic) -> bool,
    err: &mut impl Write,
) -> std::io::Result<()> {
    for a in applied {
        writeln!(
            err,
            "fixed {}:{}:{}: [{}] {}",
            a.file, a.line, a.column, a.code, a.title
        )?;
    }
    if options.statistics {
        for s in statistics(&run.diagnostics, is_fixable) {
            let fixable = if s.fixable > 0 {
                format!(" ({} fixable)", s.fixable)
            } else {
                String::new()
            };
            writeln!(
                err,
                "{:>6}  {}  {:<7}  {}{fixable}",
                s.count,
                s.code,
                s.severity.as_str(),
                s.code.summary()
            )?;
        }
        render::summary(run, err)?;
    } else {
        render::human(run, options.format, options.color, err)?;
    }
    if !applied.is_empty() {
        let files: HashSet<&str> = applied.iter().map(|a| a.file.as_str()).collect();
        writeln!(
            err,
            "fixed {} problem{} in {} file{}",
            applied.len(),
            if applied.len() == 1 { "" } else { "s" },
            files.len(),
            if files.len() == 1 { "" } else { "s" },
        )?;
    }
    let fixable = run.diagnostics.iter().filter(|d| is_fixable(d)).count();
    if fixable > 0 {
        writeln!(
            err,
            "{fixable} of these can be fixed with `semo check --fix`"
        )?;
    }
    Ok(())
}
