//! Completion in `semo.toml` (as taplo completes from a schema): on a
//! header line the tables, at a key's place the keys of the table the
//! cursor is in that it does not have yet (in `[lints]` every warning and
//! hint code, and `E` codes, which may only be denied; in `[build.targets]`
//! the teams and robots of the project's missions), after `=` the values
//! a key takes (lint levels, target names). Read from the text around the
//! cursor, so it works while the file does not parse.

use super::{BUILD_KEYS, Level, PROJECT_KEYS, TABLES};
use crate::diag::{Code, Severity};
use crate::platform::Target;
use crate::span::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompletionKind {
    Table,
    Key,
    /// A diagnostic code in `[lints]`.
    Code,
    Value,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Completion {
    pub label: String,
    pub kind: CompletionKind,
    pub detail: String,
    /// What replaces [`Completion::replace`].
    pub insert: String,
    /// The word being typed (empty at a fresh place).
    pub replace: Span,
}

fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

/// A team or robot a `[build.targets]` key may name, with what it is
/// (`robot of team Scouts (TIEvalbot), scouting.mission`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Named {
    pub name: String,
    pub detail: String,
}

/// The completions at `offset` in the project file `text`; `named`: the
/// teams and robots of the missions of the project.
pub fn completions(text: &str, offset: usize, named: &[Named]) -> Vec<Completion> {
    let Some(before_cursor) = text.get(..offset) else {
        return Vec::new();
    };
    let line_start = before_cursor.rfind('\n').map_or(0, |i| i + 1);
    let line = &before_cursor[line_start..];
    let word_len = line.len() - line.trim_end_matches(is_word).len();
    let replace = Span::new(offset - word_len, offset);
    let item = |kind, label: &str, detail: &str, insert: String| Completion {
        label: label.to_string(),
        kind,
        detail: detail.to_string(),
        insert,
        replace,
    };
    let trimmed = line.trim_start();
    if trimmed.starts_with('#') {
        return Vec::new();
    }
    if let Some(header) = trimmed.strip_prefix('[') {
        if header.contains(']') {
            return Vec::new();
        }
        return TABLES
            .iter()
            .map(|(name, detail)| item(CompletionKind::Table, name, detail, name.to_string()))
            .collect();
    }
    let table = current_table(&text[..line_start]);
    if let Some((key, value)) = line.split_once('=') {
        let key = key.trim().trim_matches('"');
        // Inside quotes the quotes are there already.
        let quoted = value.trim_start().starts_with('"');
        let value_item = |name: &str, detail: &str| {
            let insert = if quoted {
                name.to_string()
            } else {
                format!("\"{name}\"")
            };
            item(CompletionKind::Value, name, detail, insert)
        };
        return match (table.as_deref(), key) {
            (Some("lints"), code) => {
                let error =
                    Code::from_code(code).is_some_and(|c| c.default_severity() == Severity::Error);
                Level::NAMES
                    .iter()
                    .filter(|l| !error || **l == "deny")
                    .map(|l| value_item(l, level_detail(l)))
                    .collect()
            }
            (Some("build"), "target") => Target::ALL
                .iter()
                .map(|t| value_item(t.name(), &target_detail(*t, "every robot")))
                .collect(),
            (Some("build.targets"), _) => Target::ALL
                .iter()
                .map(|t| value_item(t.name(), &target_detail(*t, "its robots")))
                .collect(),
            _ => Vec::new(),
        };
    }
    let written = written_keys(text, line_start, offset);
    let keys = |keys: &[(&str, &str)]| -> Vec<Completion> {
        keys.iter()
            .filter(|(k, _)| !written.iter().any(|w| w == k))
            .map(|(k, d)| item(CompletionKind::Key, k, d, format!("{k} = ")))
            .collect()
    };
    match table.as_deref() {
        None => TABLES
            .iter()
            .map(|(name, d)| item(CompletionKind::Table, name, d, format!("[{name}]")))
            .collect(),
        Some("project") => keys(PROJECT_KEYS),
        Some("build") => keys(BUILD_KEYS),
        Some("build.targets") => named
            .iter()
            .filter(|n| !written.contains(&n.name))
            .map(|n| {
                let insert = format!("{} = ", key_text(&n.name));
                item(CompletionKind::Key, &n.name, &n.detail, insert)
            })
            .collect(),
        Some("lints") => {
            // Warnings and hints first: those are the ones a project tunes.
            let mut codes: Vec<&Code> = Code::ALL.iter().collect();
            codes.sort_by_key(|c| (c.default_severity() == Severity::Error, c.as_str()));
            codes
                .into_iter()
                .filter(|c| !written.iter().any(|w| w == c.as_str()))
                .map(|c| {
                    let detail = format!("{} ({}): {}", c, c.default_severity(), c.summary());
                    item(CompletionKind::Code, c.as_str(), &detail, format!("{c} = "))
                })
                .collect()
        }
        Some(_) => Vec::new(),
    }
}

/// What building `who` for `target` means, for a value's detail.
fn target_detail(target: Target, who: &str) -> String {
    let platform = target.platform();
    if target.simulated() {
        format!(
            "{who} on {}, simulated from a scenario ({})",
            platform.name, platform.doc
        )
    } else {
        format!("{who} on {}", platform.doc)
    }
}

/// `name` as a TOML key: bare when it can be (team and robot names are
/// identifiers), else quoted.
fn key_text(name: &str) -> String {
    let bare = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        name.to_string()
    } else {
        format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""))
    }
}

fn level_detail(level: &str) -> &'static str {
    match level {
        "allow" => "not reported",
        "warn" => "reported as a warning",
        _ => "reported as an error",
    }
}

/// The keys written in the table the cursor's line (from `line_start`,
/// the cursor at `offset`) is in, on its other lines.
fn written_keys(text: &str, line_start: usize, offset: usize) -> Vec<String> {
    let key = |line: &str| -> Option<String> {
        let (key, _) = line.split_once('=')?;
        Some(key.trim().trim_matches('"').to_string())
    };
    let is_header = |line: &str| line.trim_start().starts_with('[');
    let before = text[..line_start]
        .lines()
        .rev()
        .take_while(|l| !is_header(l))
        .filter_map(key);
    let after_cursor = text[offset..].split_once('\n').map_or("", |(_, rest)| rest);
    let after = after_cursor
        .lines()
        .take_while(|l| !is_header(l))
        .filter_map(key);
    before.chain(after).collect()
}

/// The table whose header is the last one in `before` (the text above the
/// cursor's line); `None` before any header.
fn current_table(before: &str) -> Option<String> {
    before.lines().rev().find_map(|line| {
        let header = line.trim_start().strip_prefix('[')?;
        let name = header.split(']').next()?.trim().trim_matches('[');
        Some(name.trim().to_string())
    })
}
