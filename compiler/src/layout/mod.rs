//! Drawing graphs without Graphviz, shared by the task-graph picture
//! (`taskgraph::svg`) and the mode-machine picture (`modemachine`): the rank
//! and order phases of a layered layout ([`layered`]) and text widths
//! estimated from the characters ([`text_width`]). Knows nothing of what the
//! nodes stand for.

pub(crate) mod layered;

/// An estimate of the width of `text` in Helvetica at `size` px: a width per
/// character class, erring on the wide side so that boxes hold their labels.
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    let ems: f64 = text
        .chars()
        .map(|c| match c {
            'i' | 'j' | 'l' | 'I' | '.' | ',' | ':' | ';' | '!' | '|' | '\'' => 0.3,
            ' ' | 'f' | 't' | 'r' | '(' | ')' | '[' | ']' | '/' | '-' => 0.4,
            'm' | 'w' | 'M' | 'W' | '@' => 0.88,
            'A'..='Z' => 0.7,
            c if c.is_ascii() => 0.58,
            c if is_wide(c) => 1.0,
            _ => 0.7,
        })
        .sum();
    ems * size
}

/// East Asian wide characters and emoji, drawn about one em wide.
fn is_wide(c: char) -> bool {
    matches!(c as u32,
        0x1100..=0x115F
        | 0x2E80..=0xA4CF
        | 0xAC00..=0xD7A3
        | 0xF900..=0xFAFF
        | 0xFE30..=0xFE4F
        | 0xFF00..=0xFF60
        | 0xFFE0..=0xFFE6
        | 0x1F300..=0x1FAFF
        | 0x20000..=0x3FFFD)
}
