//! `textDocument/formatting`: [`semo::format::format_source`], the layout
//! `semo fmt` writes, as one edit covering only the lines that change (so
//! the editor keeps its cursor and folds elsewhere). A mission with syntax
//! errors is not formatted: the request fails with the reason.

use crate::world::Snapshot;
use semo::span::Span;
use semo::workspace::FileKind;
use tower_lsp_server::jsonrpc::{Error, ErrorCode, Result};
use tower_lsp_server::ls_types::*;

pub fn formatting(snapshot: &Snapshot) -> Result<Option<Vec<TextEdit>>> {
    if snapshot.kind != FileKind::Mission {
        return Ok(None);
    }
    let text: &str = &snapshot.text;
    let formatted = semo::format::format_source(text).map_err(|refusal| Error {
        // -32803, the protocol's RequestFailed.
        code: ErrorCode::ServerError(-32803),
        message: format!("not formatted: {refusal}").into(),
        data: None,
    })?;
    if formatted == text {
        return Ok(Some(Vec::new()));
    }
    let (old, new) = changed_lines(text, &formatted);
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    Ok(Some(vec![TextEdit {
        range: lines.range(old),
        new_text: formatted[new.range()].to_string(),
    }]))
}

/// The smallest run of whole lines that differs: its range in `old` and in `new`.
fn changed_lines(old: &str, new: &str) -> (Span, Span) {
    let prefix = old
        .bytes()
        .zip(new.bytes())
        .take_while(|(a, b)| a == b)
        .count();
    // Back to the start of the line, so the edit replaces whole lines.
    let start = old[..prefix].rfind('\n').map_or(0, |i| i + 1);
    let max_suffix = (old.len() - start).min(new.len() - start);
    let suffix = old
        .bytes()
        .rev()
        .zip(new.bytes().rev())
        .take(max_suffix)
        .take_while(|(a, b)| a == b)
        .count();
    // Forward to just after a line break, for the same reason.
    let old_end = old.len() - suffix;
    let new_end = new.len() - suffix;
    let extend = old[old_end..]
        .find('\n')
        .map_or(old.len() - old_end, |i| i + 1);
    let (old_end, new_end) = (old_end + extend, new_end + extend);
    (Span::new(start, old_end), Span::new(start, new_end))
}

#[cfg(test)]
mod tests {
    use super::changed_lines;

    #[test]
    fn only_the_changed_lines_are_replaced() {
        let old = "a\nb c\nd\n";
        let new = "a\nb  c\nd\n";
        let (o, n) = changed_lines(old, new);
        assert_eq!((&old[o.range()], &new[n.range()]), ("b c\n", "b  c\n"));
        let mut rebuilt = old.to_string();
        rebuilt.replace_range(o.range(), &new[n.range()]);
        assert_eq!(rebuilt, new);
    }

    #[test]
    fn edits_at_the_ends_and_length_changes_rebuild_the_new_text() {
        for (old, new) in [
            ("x\n", "y\n"),
            ("{T:a}", "{\n  T: a\n}\n"),
            ("a\n\n\nb\n", "a\n\nb\n"),
            ("a\nb\n", "a\nb\nc\n"),
            ("", "x\n"),
        ] {
            let (o, n) = changed_lines(old, new);
            let mut rebuilt = old.to_string();
            rebuilt.replace_range(o.range(), &new[n.range()]);
            assert_eq!(rebuilt, new, "{old:?} → {new:?}");
        }
    }
}
