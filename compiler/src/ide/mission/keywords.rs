//! Hover on a keyword: its entry of the language reference. The entries are
//! the `` ## `keyword` `` sections of `docs/language/keywords.md`, built into
//! the library: the reference is their one source. This module's tests fail
//! for a keyword of the lexer without an entry, an entry without an example
//! line that is a line of a checked example of `docs/language/`, and a link
//! that leads to no page or heading there.

use crate::ide::HoverResult;
use crate::span::Span;
use crate::syntax::ast::{self, Arg, StmtKind};
use crate::syntax::token::{self, Kw, Token};
use std::sync::OnceLock;

/// The reference's keyword page.
const KEYWORDS_PAGE: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../docs/language/keywords.md"
));

/// Where the reference's pages are, as the hover names them.
const REFERENCE_DIR: &str = "docs/language/";

/// The entry of `kw` as markdown for the editor.
pub fn entry(kw: Kw) -> Option<&'static str> {
    entries()
        .iter()
        .find(|(word, _)| word == kw.as_str())
        .map(|(_, markdown)| markdown.as_str())
}

/// The words the keyword page has entries for, in its order.
pub fn words_with_entries() -> impl Iterator<Item = &'static str> {
    entries().iter().map(|(word, _)| word.as_str())
}

fn entries() -> &'static [(String, String)] {
    static ENTRIES: OnceLock<Vec<(String, String)>> = OnceLock::new();
    ENTRIES.get_or_init(|| sections(KEYWORDS_PAGE))
}

/// The page's `` ## `word` `` sections: (word, the section as hover markdown).
fn sections(page: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, Vec<&str>)> = Vec::new();
    for line in page.lines() {
        if let Some(heading) = line.strip_prefix("## ") {
            let word = heading.trim().trim_matches('`');
            out.push((word.to_string(), Vec::new()));
        } else if let Some((_, body)) = out.last_mut() {
            body.push(line);
        }
    }
    out.into_iter()
        .map(|(word, body)| {
            let markdown = hover_markdown(&word, &body);
            (word, markdown)
        })
        .collect()
}

/// A section as the editor shows it: the keyword, its syntax as code of the
/// language, its text and example, with each link written as the page and
/// heading it leads to in the repository (the reference's relative links
/// lead nowhere from an editor).
fn hover_markdown(word: &str, body: &[&str]) -> String {
    let mut out = format!("**`{word}`** (keyword)\n\n");
    for line in body {
        let line = match *line {
            "```syntax" => "```semo".to_string(),
            other => plain_links(other),
        };
        out.push_str(&line);
        out.push('\n');
    }
    out.trim_end().to_string()
}

/// `[Control flow](control-flow.md#repeat)` → ``Control flow (`docs/language/control-flow.md#repeat`)``.
fn plain_links(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(open) = rest.find('[') {
        let Some((text, target, after)) = link_at(&rest[open..]) else {
            out.push_str(&rest[..=open]);
            rest = &rest[open + 1..];
            continue;
        };
        let page = target.strip_prefix("../").map_or_else(
            || format!("{REFERENCE_DIR}{target}"),
            |up| format!("docs/{up}"),
        );
        out.push_str(&rest[..open]);
        out.push_str(&format!("{text} (`{page}`)"));
        rest = after;
    }
    out.push_str(rest);
    out
}

/// `[text](target)rest` at the start of `s`: (text, target, rest).
fn link_at(s: &str) -> Option<(&str, &str, &str)> {
    let close = s.find("](")?;
    let text = &s[1..close];
    let after_paren = &s[close + 2..];
    let end = after_paren.find(')')?;
    (!text.contains('[')).then(|| (text, &after_paren[..end], &after_paren[end + 1..]))
}

/// The keyword at `offset` of `text` (touching it at either end), with its range.
/// Tokens never span lines (strings and comments end with theirs), so the
/// line around `offset` is all that is lexed.
fn keyword_at(text: &str, offset: usize) -> Option<(Kw, Span)> {
    let offset = offset.min(text.len());
    let bytes = text.as_bytes();
    let start = bytes[..offset]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let end = bytes[offset..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(text.len(), |i| offset + i);
    token::lex(&text[start..end])
        .into_iter()
        .find_map(|(tok, span)| match tok {
            Token::Kw(kw) if start + span.start <= offset && offset <= start + span.end => {
                Some((kw, Span::new(start + span.start, start + span.end)))
            }
            _ => None,
        })
}

/// Whether `offset` is in an argument of several bare words
/// (`move(Paris palace of congress)`), where a keyword is only a word.
fn in_words_argument(syntax: &ast::SourceFile, offset: usize) -> bool {
    let mut found = false;
    for item in &syntax.items {
        let span = item.span();
        if !(span.start <= offset && offset <= span.end) {
            continue;
        }
        let body = match item {
            ast::Item::Service(s) => &s.body,
            ast::Item::Function(f) => &f.body,
            _ => continue,
        };
        body.walk(&mut |stmt| {
            if let StmtKind::Call(call) = &stmt.kind {
                found |= call.args.iter().any(|arg| match arg {
                    Arg::Words { span, .. } => span.start <= offset && offset <= span.end,
                    Arg::Expr(_) => false,
                });
            }
        });
    }
    found
}

/// The hover on the keyword at `offset`: its entry of the reference.
pub(crate) fn hover(syntax: &ast::SourceFile, text: &str, offset: usize) -> Option<HoverResult> {
    let (kw, range) = keyword_at(text, offset)?;
    if in_words_argument(syntax, offset) {
        return None;
    }
    Some(HoverResult {
        range,
        markdown: entry(kw)?.to_string(),
    })
}

/// A heading's anchor as GitHub makes it: lower case, punctuation dropped,
/// spaces as dashes (the reference's links and the hovers' lead there;
/// `tests/language_reference.rs` checks them with it).
pub fn heading_anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_keyword_of_the_lexer_has_an_entry_and_every_entry_is_a_keyword() {
        for kw in Kw::ALL {
            let entry = entry(*kw).unwrap_or_else(|| {
                panic!(
                    "`{}` has no `## `{0}`` section in docs/language/keywords.md",
                    kw.as_str()
                )
            });
            assert!(entry.contains("```semo\n"), "{entry}");
        }
        for word in words_with_entries() {
            assert!(
                Kw::from_word(word).is_some(),
                "docs/language/keywords.md has an entry for `{word}`, which is no keyword"
            );
        }
    }

    #[test]
    fn links_become_the_pages_they_lead_to() {
        assert_eq!(
            plain_links("See [Control flow](control-flow.md#repeat) and [groups](../groups.md)."),
            "See Control flow (`docs/language/control-flow.md#repeat`) and groups (`docs/groups.md`)."
        );
        assert_eq!(plain_links("`[[ a ]]` [x"), "`[[ a ]]` [x");
    }

    fn hover_at(text: &str, needle: &str, within: usize) -> Option<HoverResult> {
        let offset = text.find(needle).expect("the needle is in the text") + within;
        let syntax = crate::syntax::parse(crate::diag::FileId(0), text).file;
        hover(&syntax, text, offset)
    }

    #[test]
    fn a_keyword_shows_its_entry_and_nothing_else_does() {
        let text = "{ R: iRobotCreate r }\n\
                    R.Action.Go {\n  move(back of the room) # repeat here\n  send(USER, R.X = \"loop\")\n} repeat(1 SEC)\n";
        let found = hover_at(text, "repeat(1", 3).expect("a hover on repeat");
        assert_eq!(&text[found.range.start..found.range.end], "repeat");
        assert!(found.markdown.starts_with("**`repeat`** (keyword)"));
        assert!(
            found
                .markdown
                .contains("(`docs/language/control-flow.md#repeat`)")
        );
        assert!(found.markdown.contains("\nExample: `} repeat("));
        // Touching its end still hovers it.
        assert!(hover_at(text, "send(", 4).is_some());
        // A word of a bare-word argument, a comment, a string: no keyword.
        assert!(hover_at(text, "of the", 0).is_none());
        assert!(hover_at(text, "repeat here", 1).is_none());
        assert!(hover_at(text, "loop\"", 1).is_none());
        // Past the end and on a lone line: nothing, and no panic.
        assert!(hover(&ast::SourceFile::default(), text, text.len() + 5).is_none());
    }

    /// The repository's `docs/` folder, read by the tests only (the entries
    /// themselves are built in).
    fn docs_dir() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs")
    }

    /// The lines of the examples of `docs/language/` that the reference's
    /// test checks clean (` ```semo ` without `expect=`), comments cut.
    fn checked_example_lines() -> Vec<String> {
        let mut lines = Vec::new();
        let dir = docs_dir().join("language");
        for entry in std::fs::read_dir(&dir).expect("docs/language") {
            let path = entry.expect("a page").path();
            if path.extension().is_none_or(|e| e != "md") {
                continue;
            }
            let page = std::fs::read_to_string(&path).expect("a page's text");
            let mut inside = false;
            for line in page.lines() {
                if let Some(fence) = line.strip_prefix("```") {
                    inside = !inside && fence.trim() == "semo";
                    continue;
                }
                if inside {
                    let code = line.split('#').next().unwrap_or(line).trim();
                    lines.push(code.to_string());
                }
            }
        }
        lines
    }

    #[test]
    fn every_entry_has_an_example_line_of_a_checked_example() {
        let examples = checked_example_lines();
        for kw in Kw::ALL {
            let word = kw.as_str();
            let entry = entry(*kw).expect("an entry");
            let example = entry
                .lines()
                .find_map(|l| l.strip_prefix("Example: `")?.strip_suffix('`'))
                .unwrap_or_else(|| panic!("the entry of `{word}` has no `Example: `...`` line"));
            let uses = token::lex(example)
                .iter()
                .any(|(tok, _)| *tok == Token::Kw(*kw));
            assert!(uses, "the example of `{word}` does not use it: {example}");
            assert!(
                examples.iter().any(|l| l == example),
                "the example of `{word}` is no line of a checked example of docs/language: {example}"
            );
        }
    }

    use super::heading_anchor as slug;

    #[test]
    fn every_link_of_an_entry_leads_to_a_page_and_heading() {
        let mut links = 0;
        for kw in Kw::ALL {
            let entry = entry(*kw).expect("an entry");
            assert!(
                entry.contains("(`docs/"),
                "the entry of `{}` links to no page",
                kw.as_str()
            );
            for (at, _) in entry.match_indices("(`docs/") {
                let rest = &entry[at + 2..];
                let target = &rest[..rest.find('`').unwrap_or(rest.len())];
                let (page, anchor) = target.split_once('#').unwrap_or((target, ""));
                let path = docs_dir().join(page.strip_prefix("docs/").expect("under docs/"));
                let text = std::fs::read_to_string(&path).unwrap_or_else(|_| {
                    panic!("`{}` links to {page}, which is no file", kw.as_str())
                });
                let mut in_code = false;
                let headings: Vec<String> = text
                    .lines()
                    .filter(|l| {
                        in_code ^= l.starts_with("```");
                        !in_code && l.starts_with('#')
                    })
                    .map(|l| slug(l.trim_start_matches('#')))
                    .collect();
                assert!(
                    anchor.is_empty() || headings.iter().any(|h| h == anchor),
                    "`{}` links to {page}#{anchor}, which has no such heading",
                    kw.as_str()
                );
                links += 1;
            }
        }
        assert!(links >= Kw::ALL.len());
    }
}
