//! Reading the repository's Markdown pages in tests: fenced blocks and
//! relative links. Shared by `tests/language_reference.rs` (the language
//! reference) and `compiler/tests/format_docs.rs` (the format pages), which
//! includes this file by path.

use semo::ide::mission::keywords::heading_anchor;
use std::path::Path;

/// A fenced block: its info string, its text, and the line of its opening fence.
pub struct Block {
    pub info: String,
    pub body: String,
    pub line: usize,
}

pub fn blocks(text: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut lines = text.lines().enumerate();
    while let Some((number, line)) = lines.next() {
        let Some(info) = line.strip_prefix("```") else {
            continue;
        };
        let body: Vec<&str> = lines
            .by_ref()
            .map(|(_, l)| l)
            .take_while(|l| *l != "```")
            .collect();
        blocks.push(Block {
            info: info.trim().to_string(),
            body: body.join("\n") + "\n",
            line: number + 1,
        });
    }
    blocks
}

/// The relative links of a page: (target file, anchor), without web links.
pub fn links(text: &str) -> Vec<(String, Option<String>)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        let Some(end) = rest.find(')') else { break };
        let target = &rest[..end];
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (file, anchor) = match target.split_once('#') {
            Some((file, anchor)) => (file.to_string(), Some(anchor.to_string())),
            None => (target.to_string(), None),
        };
        out.push((file, anchor));
    }
    out
}

/// The anchors of a page's headings, as GitHub makes them.
pub fn anchors(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| heading_anchor(l.trim_start_matches('#')))
        .collect()
}

/// The links of the page `name` (text `text`, in the folder `dir`) that lead
/// to no file, or to no heading of it when they name one.
pub fn broken_links(dir: &Path, name: &str, text: &str) -> Vec<String> {
    let mut broken = Vec::new();
    for (file, anchor) in links(text) {
        let linked = if file.is_empty() {
            Some(text.to_string())
        } else {
            std::fs::read_to_string(dir.join(&file)).ok()
        };
        match (linked, anchor) {
            (None, _) => broken.push(format!("{name}: {file} does not exist")),
            (Some(linked), Some(anchor)) if !anchors(&linked).contains(&anchor) => {
                broken.push(format!("{name}: {file} has no heading #{anchor}"))
            }
            _ => {}
        }
    }
    broken
}
