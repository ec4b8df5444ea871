//! Rendering diagnostics for people: ariadne snippets or one line each, and `semo check`'s
//! summary line (machine shapes are in `output`).

use crate::output::Format;
use crate::terminal::{ShownSource, visible};
use ariadne::{Color, Config, IndexType, Label, Report, ReportKind};
use semo::diag::{Diagnostic, Severity};
use semo::host::CheckRun;
use semo::text::{ColumnUnit, LineIndex};
use semo::workspace::Files;
use std::collections::HashMap;
use std::io::{self, Write};

pub fn kind(severity: Severity) -> ReportKind<'static> {
    match severity {
        Severity::Error => ReportKind::Error,
        Severity::Warning => ReportKind::Warning,
        // ariadne calls them "Advice"; the toolchain calls them hints.
        Severity::Hint => ReportKind::Custom("Hint", Color::Cyan),
    }
}

pub fn color(severity: Severity) -> Color {
    match severity {
        Severity::Error => Color::Red,
        Severity::Warning => Color::Yellow,
        Severity::Hint => Color::Cyan,
    }
}

/// Clamps a span to the text and to character boundaries, so that a bad span
/// can never make the renderer fail.
pub fn safe_range(text: &str, span: semo::span::Span) -> std::ops::Range<usize> {
    let fix = |mut i: usize| {
        i = i.min(text.len());
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let (start, end) = (fix(span.start), fix(span.end));
    start..end.max(start)
}

/// The longest line a snippet shows, in bytes: a longer one (a file of
/// one 400,000-byte line once printed 2.8 MB for one diagnostic, its line
/// and its underline) gets the one-line form, and a note.
const LONGEST_SHOWN_LINE: usize = 500;

/// A file as the snippets show it: control characters shown, not obeyed
/// (`terminal.rs`), and where its lines start.
struct Shown {
    path: String,
    source: ShownSource,
    lines: LineIndex,
}

impl Shown {
    /// `span` of the original text, in the shown one.
    fn range(&self, original: &str, span: semo::span::Span) -> std::ops::Range<usize> {
        let range = safe_range(original, span);
        self.source.offset(range.start)..self.source.offset(range.end)
    }

    /// The line (from 1) and length of the line `span` starts on, when it
    /// is too long to show.
    fn long_line(&self, original: &str, span: semo::span::Span) -> Option<(usize, usize)> {
        let start = safe_range(original, span).start;
        let line = self.lines.line_col(original, start, ColumnUnit::Utf8).line as usize;
        let length = self.lines.line_start(line + 1) - self.lines.line_start(line);
        (length > LONGEST_SHOWN_LINE).then_some((line + 1, length))
    }
}

/// Source snippets for people: one ariadne report per diagnostic. Text of
/// the files and of the messages is shown with its control characters made
/// visible, so that a mission cannot drive the terminal.
pub fn diagnostics(
    files: &Files,
    diagnostics: &[Diagnostic],
    colored: bool,
    out: &mut impl Write,
) -> io::Result<()> {
    if diagnostics.is_empty() {
        // Nothing to show: no copy of every file's text for the renderer.
        return Ok(());
    }
    let config = Config::default()
        .with_color(colored)
        .with_index_type(IndexType::Byte);
    // Only the files the diagnostics point into are shown: a workspace of
    // hundreds of files with one problem copies and indexes one.
    let mut shown = HashMap::new();
    let pointed = diagnostics
        .iter()
        .flat_map(|d| std::iter::once(d.file).chain(d.related.iter().map(|r| r.file)));
    for id in pointed {
        shown.entry(id).or_insert_with(|| {
            let f = files.get(id);
            Shown {
                path: f.path.display().to_string(),
                source: ShownSource::new(&f.text),
                lines: LineIndex::new(&f.text),
            }
        });
    }
    let mut cache = ariadne::sources(
        shown
            .values()
            .map(|s| (s.path.clone(), s.source.text.clone())),
    );
    for d in diagnostics {
        let text = &files.get(d.file).text;
        let file = &shown[&d.file];
        let mut long = file.long_line(text, d.span);
        for related in &d.related {
            let related_text = &files.get(related.file).text;
            long = long.or(shown[&related.file].long_line(related_text, related.span));
        }
        if let Some((line, length)) = long {
            // Written at once, as a report is (below).
            let mut one = Vec::new();
            concise(files, std::slice::from_ref(d), &mut one)?;
            writeln!(one, "  (line {line} is {length} bytes long: no snippet)")?;
            out.write_all(&one)?;
            continue;
        }
        let range = file.range(text, d.span);
        let mut report = Report::build(kind(d.severity), (file.path.clone(), range.clone()))
            .with_config(config)
            .with_code(d.code.as_str())
            .with_message(visible(&d.message))
            .with_label(
                Label::new((file.path.clone(), range))
                    .with_message(d.code.summary())
                    .with_color(color(d.severity)),
            );
        for related in &d.related {
            let other = &shown[&related.file];
            let range = other.range(&files.get(related.file).text, related.span);
            report = report.with_label(
                Label::new((other.path.clone(), range))
                    .with_message(visible(&related.message))
                    .with_color(Color::Blue),
            );
        }
        if let Some(s) = &d.suggestion {
            report = report.with_help(format!("did you mean `{}`?", visible(s)));
        }
        // Each report is rendered aside and written at once: ariadne writes
        // a snippet in small pieces, and standard error is unbuffered (a line
        // of 400,000 NULs once took 650,000 writes). Nothing is left in a
        // buffer when the command ends.
        let mut text = Vec::new();
        report.finish().write(&mut cache, &mut text)?;
        if !colored && d.severity == Severity::Hint {
            // ariadne colours a custom kind's header ("Hint") even with
            // colour off: its escape sequences are dropped.
            text = without_escapes(&text);
        }
        out.write_all(&text)?;
    }
    out.flush()
}

/// `bytes` without ANSI escape sequences (`ESC [ … letter`).
fn without_escapes(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == 0x1b && bytes.get(i + 1) == Some(&b'[') {
            i += 2;
            while i < bytes.len() && !bytes[i].is_ascii_alphabetic() {
                i += 1;
            }
            i += 1;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}

/// Diagnostics for people in `format` (which is `Human` or `Concise`):
/// source snippets, or one line each.
pub fn people(
    format: Format,
    files: &Files,
    found: &[Diagnostic],
    colored: bool,
    out: &mut impl Write,
) -> io::Result<()> {
    match format {
        Format::Concise => concise(files, found, out),
        _ => diagnostics(files, found, colored, out),
    }
}

/// One line per diagnostic, `FILE:LINE:COL: severity[CODE]: message`, the
/// position of its start counted from 1 in characters; a did-you-mean the
/// message does not name and the related places follow on the line.
pub fn concise(files: &Files, found: &[Diagnostic], out: &mut impl Write) -> io::Result<()> {
    let mut text = String::new();
    for record in crate::output::records(files, found) {
        let code = record.code.map_or("", |c| c.as_str());
        text.push_str(&format!(
            "{}:{}:{}: {}[{code}]: {}",
            visible(&record.file),
            record.start.line,
            record.start.column,
            record.severity,
            visible(&record.message)
        ));
        // Most messages name their did-you-mean already.
        if let Some(s) = record
            .suggestion
            .as_ref()
            .filter(|s| !record.message.contains(*s))
        {
            text.push_str(&format!(" (did you mean `{}`?)", visible(s)));
        }
        for related in &record.related {
            text.push_str(&format!(
                " [{}:{}:{}: {}]",
                visible(&related.file),
                related.line,
                related.column,
                visible(&related.message)
            ));
        }
        text.push('\n');
    }
    out.write_all(text.as_bytes())?;
    out.flush()
}

/// `semo check`'s report for people: the diagnostics in `format`, then a
/// one-line summary.
pub fn human(
    run: &CheckRun,
    format: Format,
    colored: bool,
    out: &mut impl Write,
) -> io::Result<()> {
    people(format, &run.files, &run.diagnostics, colored, out)?;
    summary(run, out)
}

/// `checked 2 missions and 1 catalog file: 1 error, 0 warnings, 0 hints`.
pub fn summary(run: &CheckRun, out: &mut impl Write) -> io::Result<()> {
    let count = |s: Severity| run.diagnostics.iter().filter(|d| d.severity == s).count();
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    let of_kind = |kind| {
        run.checked
            .iter()
            .filter(|&&id| run.files.get(id).kind == kind)
            .count()
    };
    let graphs = of_kind(semo::workspace::FileKind::TaskGraph);
    let graphs = if graphs > 0 {
        format!(", {}", plural(graphs, "task graph"))
    } else {
        String::new()
    };
    let strategies = of_kind(semo::workspace::FileKind::Strategy);
    let strategies = if strategies > 0 {
        format!(", {}", plural(strategies, "strategy file"))
    } else {
        String::new()
    };
    // One write: standard error is unbuffered, and `writeln!` writes each
    // piece of its format on its own.
    let line = format!(
        "checked {} and {}{graphs}{strategies}: {}, {}, {}\n",
        plural(of_kind(semo::workspace::FileKind::Mission), "mission"),
        plural(of_kind(semo::workspace::FileKind::Catalog), "catalog file"),
        plural(count(Severity::Error), "error"),
        plural(count(Severity::Warning), "warning"),
        plural(count(Severity::Hint), "hint"),
    );
    out.write_all(line.as_bytes())
}
