//! The tree-sitter grammar against the compiler, the reference: every mission that the
//! compiler's parser accepts parses without an ERROR or MISSING node, every mission it
//! rejects has one, and the highlight queries give each kind of name its capture.

use semo::diag::FileId;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tree_sitter::{Language, Node, Parser, Point, Query, QueryCursor, StreamingIterator, Tree};

fn language() -> Language {
    tree_sitter_semo::LANGUAGE.into()
}

fn parse(text: &str) -> Tree {
    let mut parser = Parser::new();
    parser
        .set_language(&language())
        .expect("the tree-sitter crate reads the parser's ABI");
    parser
        .parse(text, None)
        .expect("no timeout or cancellation is set")
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn missions_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            missions_under(&path, out);
        } else if path.extension().is_some_and(|e| e == "mission") {
            out.push(path);
        }
    }
}

/// The reference examples, the repository's examples and every mission fixture of the
/// compiler's tests (valid ones and ones with syntax or semantic errors).
fn corpus() -> Vec<PathBuf> {
    let root = repo_root();
    let mut files = Vec::new();
    for dir in ["examples", "tests/fixtures"] {
        missions_under(&root.join(dir), &mut files);
    }
    files.sort();
    files
}

/// The first ERROR or MISSING node, as `line:column: kind`.
fn first_error(node: Node) -> Option<String> {
    if node.is_error() || node.is_missing() {
        let at = node.start_position();
        let what = if node.is_missing() {
            format!("missing {}", node.kind())
        } else {
            "ERROR".to_string()
        };
        return Some(format!("{}:{}: {what}", at.row + 1, at.column + 1));
    }
    if !node.has_error() {
        return None;
    }
    let mut cursor = node.walk();
    node.children(&mut cursor).find_map(first_error)
}

#[test]
fn the_parser_accepts_exactly_what_the_compiler_accepts() {
    let files = corpus();
    let examples = repo_root().join("examples");
    let reference = files
        .iter()
        .filter(|f| {
            ["scouting", "follow", "swarm"]
                .iter()
                .any(|d| f.starts_with(examples.join(d)))
        })
        .count();
    assert!(
        reference >= 4,
        "the reference examples (examples/) are missing"
    );

    let mut disagreements = Vec::new();
    let (mut valid, mut invalid) = (0, 0);
    for file in &files {
        let text = std::fs::read_to_string(file).expect("fixture is readable");
        let compiler_ok = semo::syntax::parse(FileId(0), &text).diagnostics.is_empty();
        let error = first_error(parse(&text).root_node());
        if compiler_ok {
            valid += 1;
        } else {
            invalid += 1;
        }
        match (compiler_ok, error) {
            (true, Some(error)) => disagreements.push(format!(
                "{}:{error} (the compiler accepts this file)",
                file.display()
            )),
            (false, None) => disagreements.push(format!(
                "{}: parses without error, but the compiler reports syntax errors",
                file.display()
            )),
            _ => {}
        }
    }
    assert!(
        valid > 20 && invalid > 3,
        "expected a corpus of valid and invalid missions, found {valid} and {invalid}"
    );
    assert!(disagreements.is_empty(), "{}", disagreements.join("\n"));
}

#[test]
fn every_query_compiles_against_the_grammar() {
    for (name, source) in [
        ("highlights", tree_sitter_semo::HIGHLIGHTS_QUERY),
        ("locals", tree_sitter_semo::LOCALS_QUERY),
        ("folds", tree_sitter_semo::FOLDS_QUERY),
        ("indents", tree_sitter_semo::INDENTS_QUERY),
    ] {
        if let Err(error) = Query::new(&language(), source) {
            panic!("queries/{name}.scm: {error}");
        }
    }
}

/// Each leaf token of `text` with the capture an editor shows it with: of the captures on
/// the token or its nearest captured ancestor, the one from the last pattern (Neovim's rule).
fn highlighted_tokens(text: &str) -> Vec<(String, Point, String)> {
    let tree = parse(text);
    let query = Query::new(&language(), tree_sitter_semo::HIGHLIGHTS_QUERY).expect("compiles");
    let mut winner: std::collections::HashMap<usize, (usize, String)> = Default::default();
    let mut cursor = QueryCursor::new();
    let mut matches = cursor.matches(&query, tree.root_node(), text.as_bytes());
    while let Some(m) = matches.next() {
        for capture in m.captures {
            let name = query.capture_names()[capture.index as usize].to_string();
            let entry = winner
                .entry(capture.node.id())
                .or_insert((0, String::new()));
            if entry.1.is_empty() || m.pattern_index >= entry.0 {
                *entry = (m.pattern_index, name);
            }
        }
    }
    let mut out = Vec::new();
    let mut stack = vec![tree.root_node()];
    while let Some(node) = stack.pop() {
        if node.child_count() == 0 {
            let mut capture = None;
            let mut at = Some(node);
            while let (None, Some(n)) = (&capture, at) {
                capture = winner.get(&n.id()).map(|(_, name)| name.clone());
                at = n.parent();
            }
            let token = node.utf8_text(text.as_bytes()).unwrap_or("").to_string();
            out.push((token, node.start_position(), capture.unwrap_or_default()));
        }
        let mut cursor = node.walk();
        let children: Vec<_> = node.children(&mut cursor).collect();
        stack.extend(children.into_iter().rev());
    }
    out
}

fn capture_of(text: &str, token: &str, nth: usize) -> String {
    highlighted_tokens(text)
        .into_iter()
        .filter(|(t, _, _)| t == token)
        .nth(nth)
        .map(|(_, _, capture)| capture)
        .unwrap_or_else(|| panic!("no token {token:?} (#{nth})"))
}

#[test]
fn names_are_highlighted_by_what_they_name() {
    let text = "\
{ Scouts: TIEvalbot ti[2] }
Scouts.Action.Search {
  if (USER.RC_CMD == \"STOP\") throw stop_now
  search(colored_paper), timeout = 2 SEC
}
Scouts.SEARCH { set(Action, Search) set(Report, OFF) }
Scouts.main { case (SEARCH): catch (stop_now): mode = SEARCH default: mode = SEARCH }
";
    assert_eq!(capture_of(text, "Scouts", 0), "module");
    assert_eq!(capture_of(text, "TIEvalbot", 0), "type");
    assert_eq!(capture_of(text, "Action", 0), "type");
    assert_eq!(capture_of(text, "Search", 0), "function");
    assert_eq!(capture_of(text, "USER", 0), "constant.builtin");
    assert_eq!(capture_of(text, "RC_CMD", 0), "variable.member");
    assert_eq!(capture_of(text, "throw", 0), "keyword.exception");
    assert_eq!(capture_of(text, "stop_now", 0), "label");
    assert_eq!(capture_of(text, "stop_now", 1), "label");
    assert_eq!(capture_of(text, "search", 0), "function.call");
    assert_eq!(capture_of(text, "SEC", 0), "type.builtin");
    assert_eq!(capture_of(text, "OFF", 0), "constant.builtin");
    assert_eq!(capture_of(text, "SEARCH", 0), "constant");
    assert_eq!(capture_of(text, "SEARCH", 2), "constant");
    assert_eq!(capture_of(text, "main", 0), "keyword");
}

/// The whole highlighting of a mission using every construct, one token per line.
#[test]
fn highlighting_of_every_construct() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/every_construct.mission");
    let text = std::fs::read_to_string(&path).expect("fixture is readable");
    assert!(first_error(parse(&text).root_node()).is_none());
    let mut rendered = String::new();
    let mut row = usize::MAX;
    for (token, at, capture) in highlighted_tokens(&text) {
        if at.row != row {
            row = at.row;
            let _ = write!(rendered, "\n{:>3}│", at.row + 1);
        }
        let capture = if capture.is_empty() { "-" } else { &capture };
        let token = if token.len() > 24 {
            format!("{}…", token.chars().take(20).collect::<String>())
        } else {
            token
        };
        let _ = write!(rendered, " {token}@{capture}");
    }
    insta::assert_snapshot!(rendered.trim_start());
}
