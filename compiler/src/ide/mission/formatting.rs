//! Formatting in the editor: [`crate::format::format_source`], the layout
//! `semo fmt` writes, as one edit covering only the lines that change (so
//! the editor keeps its cursor and folds elsewhere).

use crate::edit::TextEdit;
use crate::format::{FormatRefusal, format_source};
use crate::span::Span;

/// The edits formatting `text` (none when it is formatted already), or why
/// it is left as it is (syntax errors, a nesting too deep).
pub fn formatting(text: &str) -> Result<Vec<TextEdit>, FormatRefusal> {
    let formatted = format_source(text)?;
    if formatted == text {
        return Ok(Vec::new());
    }
    let (old, new) = changed_lines(text, &formatted);
    Ok(vec![TextEdit {
        span: old,
        new_text: formatted[new.range()].to_string(),
    }])
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
    use super::{changed_lines, formatting};

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

    #[test]
    fn a_formatted_mission_needs_no_edit_and_a_broken_one_is_refused() {
        let messy = "{ A :  Rover   r }\n";
        let edits = formatting(messy).expect("formats");
        assert_eq!(edits.len(), 1);
        let mut fixed = messy.to_string();
        fixed.replace_range(edits[0].span.range(), &edits[0].new_text);
        assert_eq!(formatting(&fixed), Ok(Vec::new()));
        assert!(formatting("{ A: Rover").is_err());
    }
}
