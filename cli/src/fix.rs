//! `semo check --fix`: applies the quick fixes the editor offers, the one
//! each diagnostic prefers (a did-you-mean, a missing `default`, …), to the
//! mission and strategy files checked, then checks again. A fix may uncover
//! another (a created mode whose name was misspelt), so this runs in rounds
//! until nothing more is fixed, at most [`MAX_ROUNDS`].
//!
//! Files are replaced whole (a temporary file renamed over them, as `semo fmt`
//! does); a mission on standard input is fixed in memory and printed.

use semo::edit::{CodeAction, TextEdit};
use semo::host::CheckRun;
use semo::span::Span;
use semo::text::ColumnUnit;
use semo::workspace::FileKind;
use std::path::PathBuf;

/// Rounds of fixing and checking again; each round fixes at least one
/// problem or ends the fixing.
pub const MAX_ROUNDS: usize = 10;

/// One fix applied: where its diagnostic was (before the fix) and what it did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Applied {
    pub file: String,
    pub line: u32,
    pub column: u32,
    pub code: &'static str,
    pub title: String,
}

/// Where the checked text lives, to check it again after each round.
pub enum Source<'a> {
    /// Files and folders on disk (`semo check PATHS`).
    Paths(&'a dyn Fn() -> Result<CheckRun, (PathBuf, String)>),
    /// A mission on standard input, its text fixed in memory.
    Stdin(String),
}

/// What fixing gives: the final check, the fixes applied in order, and the
/// fixed text of a mission read from standard input.
pub struct Fixed {
    pub run: CheckRun,
    pub applied: Vec<Applied>,
    pub stdin_text: Option<String>,
}

pub fn run(source: Source<'_>) -> Result<Fixed, (PathBuf, String)> {
    let mut stdin_text = match &source {
        Source::Stdin(text) => Some(text.clone()),
        Source::Paths(_) => None,
    };
    let load = |stdin_text: &Option<String>| match (&source, stdin_text) {
        (Source::Paths(load), _) => load(),
        (Source::Stdin(_), text) => Ok(semo::host::load_check_stdin(
            text.clone().unwrap_or_default(),
        )),
    };
    let mut applied = Vec::new();
    let mut run = load(&stdin_text)?;
    for _ in 0..MAX_ROUNDS {
        let before = applied.len();
        let analysis = run.analysis();
        for &id in &run.checked {
            let file = run.files.get(id);
            if !matches!(file.kind, FileKind::Mission | FileKind::Strategy) {
                continue;
            }
            let published = analysis.diagnostics(id);
            let actions = analysis.code_actions(id, Span::new(0, file.text.len()));
            let chosen = preferred_without_overlap(actions);
            if chosen.is_empty() {
                continue;
            }
            let mut edits: Vec<&TextEdit> = chosen.iter().flat_map(|a| &a.edits).collect();
            let fixed = apply(&file.text, &mut edits);
            match &mut stdin_text {
                Some(text) => *text = fixed,
                None => crate::fmt::write_replacing(&file.path, &fixed).map_err(|e| {
                    (
                        file.path.clone(),
                        format!("{}: cannot write the fixes: {e}", file.path.display()),
                    )
                })?,
            }
            for action in chosen {
                let Some(diagnostic) = published.get(action.diagnostic) else {
                    continue;
                };
                let at = file
                    .lines
                    .line_col(&file.text, diagnostic.span.start, ColumnUnit::Char);
                applied.push(Applied {
                    file: file.path.display().to_string(),
                    line: at.line + 1,
                    column: at.col + 1,
                    code: diagnostic.code.as_str(),
                    title: action.title,
                });
            }
        }
        if applied.len() == before {
            break;
        }
        run = load(&stdin_text)?;
    }
    Ok(Fixed {
        run,
        applied,
        stdin_text,
    })
}

/// Each diagnostic's preferred fix, in order of position, leaving out any
/// whose edits overlap or touch those of a fix taken before it (the next
/// round, on the new text, reconsiders them).
fn preferred_without_overlap(actions: Vec<CodeAction>) -> Vec<CodeAction> {
    let mut preferred: Vec<CodeAction> = actions.into_iter().filter(|a| a.preferred).collect();
    preferred.sort_by_key(|a| a.edits.first().map(|e| e.span));
    let mut taken: Vec<CodeAction> = Vec::new();
    let mut diagnostics_fixed = std::collections::HashSet::new();
    for action in preferred {
        let clashes = taken.iter().flat_map(|t| &t.edits).any(|old| {
            action
                .edits
                .iter()
                .any(|new| new.span.start <= old.span.end && old.span.start <= new.span.end)
        });
        if !clashes && !action.edits.is_empty() && diagnostics_fixed.insert(action.diagnostic) {
            taken.push(action);
        }
    }
    taken
}

/// `text` with `edits` (not overlapping) applied.
fn apply(text: &str, edits: &mut [&TextEdit]) -> String {
    edits.sort_by_key(|e| e.span);
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for edit in edits.iter() {
        let span = edit.span;
        if span.start < at || span.end > text.len() {
            continue;
        }
        out.push_str(&text[at..span.start]);
        out.push_str(&edit.new_text);
        at = span.end;
    }
    out.push_str(&text[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edit(start: usize, end: usize, new_text: &str) -> TextEdit {
        TextEdit {
            span: Span::new(start, end),
            new_text: new_text.to_string(),
        }
    }

    fn action(diagnostic: usize, edits: Vec<TextEdit>, preferred: bool) -> CodeAction {
        CodeAction {
            title: format!("fix {diagnostic}"),
            diagnostic,
            edits,
            preferred,
        }
    }

    #[test]
    fn takes_one_preferred_fix_per_diagnostic_and_none_that_overlap() {
        let taken = preferred_without_overlap(vec![
            action(0, vec![edit(10, 14, "B")], true),
            action(0, vec![edit(10, 14, "C")], false),
            action(1, vec![edit(2, 4, "A")], true),
            action(2, vec![edit(12, 20, "D")], true),
            action(3, vec![edit(30, 30, "E")], true),
            action(3, vec![edit(40, 40, "F")], true),
        ]);
        let titles: Vec<&str> = taken.iter().map(|a| a.title.as_str()).collect();
        assert_eq!(titles, ["fix 1", "fix 0", "fix 3"]);
    }

    #[test]
    fn applies_edits_from_the_end_without_moving_the_others() {
        let (a, b, c) = (edit(0, 1, "xy"), edit(4, 4, "!"), edit(6, 7, ""));
        assert_eq!(apply("abcdefg", &mut [&c, &a, &b]), "xybcd!ef");
    }
}
