//! Hover on a keyword: its entry of the language reference. The entries are
//! the `` ## `keyword` `` sections of `docs/language/keywords.md`, built into
//! the library: the reference is their one source, and a keyword of the lexer
//! without an entry fails this module's tests.

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
/// language, and its text with each link written as the page it leads to
/// (the reference's relative links lead nowhere from an editor).
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

/// `[Control flow](control-flow.md#repeat)` → ``Control flow (`docs/language/control-flow.md`)``.
fn plain_links(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(open) = rest.find('[') {
        let Some((text, target, after)) = link_at(&rest[open..]) else {
            out.push_str(&rest[..=open]);
            rest = &rest[open + 1..];
            continue;
        };
        let page = target.split('#').next().unwrap_or(target);
        let page = page.strip_prefix("../").map_or_else(
            || format!("{REFERENCE_DIR}{page}"),
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
            "See Control flow (`docs/language/control-flow.md`) and groups (`docs/groups.md`)."
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
        assert!(found.markdown.contains("(`docs/language/control-flow.md`)"));
        // Touching its end still hovers it.
        assert!(hover_at(text, "send(", 4).is_some());
        // A word of a bare-word argument, a comment, a string: no keyword.
        assert!(hover_at(text, "of the", 0).is_none());
        assert!(hover_at(text, "repeat here", 1).is_none());
        assert!(hover_at(text, "loop\"", 1).is_none());
        // Past the end and on a lone line: nothing, and no panic.
        assert!(hover(&ast::SourceFile::default(), text, text.len() + 5).is_none());
    }
}
