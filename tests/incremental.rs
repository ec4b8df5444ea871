//! Incremental parsing gives exactly what parsing from scratch gives: random
//! sequences of edits (characters, brackets, quotes, comments, newlines, item
//! headers, Korean text and emoji; whole lines deleted, duplicated, moved;
//! undo) are applied to the reference examples, the repository's missions and
//! fixtures and a generated mission, and after every edit
//! `syntax::parse_incremental`, chained from an earlier version's cache, must
//! equal `syntax::parse`: items, positions, diagnostics and their order. So
//! must any text parsed with the cache of any other.

mod support;

#[path = "../compiler/benches/common/mission.rs"]
mod mission;

use proptest::prelude::*;
use proptest::sample::Index;
use semo::diag::FileId;
use semo::syntax::{Parse, ParseCache, parse, parse_incremental};
use std::path::Path;
use std::sync::OnceLock;

/// Every mission script the repository holds.
fn corpus() -> &'static Vec<String> {
    static CORPUS: OnceLock<Vec<String>> = OnceLock::new();
    CORPUS.get_or_init(|| {
        let mut paths = Vec::new();
        for root in [
            support::examples(),
            support::repo_root().join("tests/fixtures"),
        ] {
            missions_under(&root, &mut paths);
        }
        paths.sort();
        assert!(paths.len() > 70, "missions found: {paths:?}");
        paths
            .iter()
            .map(|p| std::fs::read_to_string(p).expect("a readable mission"))
            .collect()
    })
}

fn missions_under(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            missions_under(&path, out);
        } else if path.extension().is_some_and(|e| e == "mission") {
            out.push(path);
        }
    }
}

/// A generated mission large enough (over 64 KiB) to be lexed and parsed on
/// two threads.
fn generated() -> &'static String {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| mission::generate(50))
}

/// Text typed in: brackets, quotes, comments, newlines, item headers, Korean
/// and emoji, and pieces of statements.
const TYPED: &[&str] = &[
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    "[[",
    "]]",
    "\"",
    "\\",
    "#",
    "# 한국어 주석\n",
    "\n",
    "\n\n",
    " ",
    "\t",
    "x",
    "1",
    "-",
    ".",
    ",",
    ":",
    ";",
    "=",
    "==",
    "@",
    "😀",
    "한",
    "é",
    "Team0.Action.Patrol {",
    "T.P.S { move(\"1,1\") }",
    "def g {",
    "def g { stop() }\n",
    "Team0.HIDE {",
    "Team0.main {",
    "T.main { default: mode = M }",
    "{ T: Turtlebot3_Burger tb }",
    "T: Turtlebot3_Burger tb\n",
    "}\n",
    "} repeat(1 SEC)\n",
    "repeat(",
    "if (a and b) ",
    "else ",
    "else if (x) ",
    "throw e\n",
    "move(\"5,5)",
    "\"한국어 😀\"",
    "set(Action, OFF)",
    "case (PATROL):",
    "[[ leader(instance of Ev3_Robot) { stop() } ]]",
    "and not ",
];

#[derive(Clone, Debug)]
enum Edit {
    /// Insert a piece of [`TYPED`] at a character.
    Type(Index, Index),
    /// Delete up to this many characters from a character on.
    Delete(Index, usize),
    /// Replace up to this many characters from a character with a piece.
    Replace(Index, usize, Index),
    /// Delete a whole line.
    DeleteLine(Index),
    /// Copy a line before another.
    CopyLine(Index, Index),
    /// Move a block of lines elsewhere (cut and paste in one edit).
    MoveLines(Index, usize, Index),
    /// Go back to the version before the previous edit.
    Undo,
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<Index>(), any::<Index>()).prop_map(|(at, what)| Edit::Type(at, what)),
        2 => (any::<Index>(), 1..12usize).prop_map(|(at, n)| Edit::Delete(at, n)),
        2 => (any::<Index>(), 1..8usize, any::<Index>())
            .prop_map(|(at, n, what)| Edit::Replace(at, n, what)),
        1 => any::<Index>().prop_map(Edit::DeleteLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Edit::CopyLine(a, b)),
        1 => (any::<Index>(), 1..30usize, any::<Index>())
            .prop_map(|(a, n, b)| Edit::MoveLines(a, n, b)),
        1 => Just(Edit::Undo),
    ]
}

/// The byte offset of a character boundary chosen by `at` (the end included).
fn boundary(text: &str, at: &Index) -> usize {
    let count = text.chars().count();
    let n = at.index(count + 1);
    text.char_indices().nth(n).map_or(text.len(), |(i, _)| i)
}

/// `text` with up to `n` characters from `start` on replaced by `with`.
fn splice(text: &str, start: usize, n: usize, with: &str) -> String {
    let end = text[start..]
        .char_indices()
        .nth(n)
        .map_or(text.len(), |(i, _)| start + i);
    format!("{}{with}{}", &text[..start], &text[end..])
}

fn apply(text: &str, edit: &Edit, history: &[String]) -> String {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    match edit {
        Edit::Type(at, what) => splice(text, boundary(text, at), 0, what.get::<&str>(TYPED)),
        Edit::Delete(at, n) => splice(text, boundary(text, at), *n, ""),
        Edit::Replace(at, n, what) => splice(text, boundary(text, at), *n, what.get::<&str>(TYPED)),
        Edit::DeleteLine(at) if !lines.is_empty() => {
            let i = at.index(lines.len());
            let mut lines = lines;
            lines.remove(i);
            lines.concat()
        }
        Edit::CopyLine(from, to) if !lines.is_empty() => {
            let line = lines[from.index(lines.len())].to_string();
            let line = if line.ends_with('\n') {
                line
            } else {
                format!("{line}\n")
            };
            let mut lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            lines.insert(to.index(lines.len() + 1), line);
            lines.concat()
        }
        Edit::MoveLines(from, n, to) if !lines.is_empty() => {
            let mut lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            if let Some(last) = lines.last_mut()
                && !last.ends_with('\n')
            {
                last.push('\n');
            }
            let start = from.index(lines.len());
            let end = (start + n).min(lines.len());
            let block: Vec<String> = lines.drain(start..end).collect();
            let at = to.index(lines.len() + 1);
            lines.splice(at..at, block);
            lines.concat()
        }
        Edit::Undo => history
            .len()
            .checked_sub(2)
            .map_or_else(|| text.to_string(), |i| history[i].clone()),
        _ => text.to_string(),
    }
}

/// The first difference between two parses, or `None` when they are equal.
fn difference(incremental: &Parse, scratch: &Parse) -> Option<String> {
    let (a, b) = (&incremental.file.items, &scratch.file.items);
    if let Some(i) = (0..a.len().max(b.len())).find(|&i| a.get(i) != b.get(i)) {
        return Some(format!(
            "item {i} differs:\nincremental {:#?}\nscratch {:#?}",
            a.get(i),
            b.get(i)
        ));
    }
    let (a, b) = (&incremental.diagnostics, &scratch.diagnostics);
    (0..a.len().max(b.len()))
        .find(|&i| a.get(i) != b.get(i))
        .map(|i| {
            format!(
                "diagnostic {i} differs:\nincremental {:#?}\nscratch {:#?}",
                a.get(i),
                b.get(i)
            )
        })
}

/// Applies `edits` to `text` one by one; after each, parses incrementally
/// with the cache of the version `back` edits earlier (1: the previous one;
/// past the first version: none) and compares with a parse from scratch.
fn check_edits(text: &str, edits: &[(Edit, usize)]) -> Result<(), TestCaseError> {
    let file = FileId(7);
    let mut history = vec![text.to_string()];
    let (first, cache) = parse_incremental(file, text, None);
    if let Some(diff) = difference(&first, &parse(file, text)) {
        return Err(TestCaseError::fail(format!("first parse: {diff}")));
    }
    let mut caches: Vec<ParseCache> = vec![cache];
    for (step, (edit, back)) in edits.iter().enumerate() {
        let current = history.last().expect("one version at least").clone();
        let next = apply(&current, edit, &history);
        let previous = caches.len().checked_sub(*back).map(|i| &caches[i]);
        let (incremental, cache) = parse_incremental(file, &next, previous);
        if let Some(diff) = difference(&incremental, &parse(file, &next)) {
            return Err(TestCaseError::fail(format!(
                "after edit {step} ({edit:?}, cache {back} back) of {current:?}\ngiving {next:?}:\n{diff}"
            )));
        }
        history.push(next);
        caches.push(cache);
    }
    Ok(())
}

/// Mostly the previous version's cache; sometimes an older one, or none.
fn edits(max: usize) -> impl Strategy<Value = Vec<(Edit, usize)>> {
    prop::collection::vec(
        (
            edit(),
            prop_oneof![8 => Just(1usize), 1 => 2..5usize, 1 => Just(usize::MAX)],
        ),
        1..max,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn edits_to_the_examples_and_fixtures_parse_as_from_scratch(
        which in any::<Index>(),
        edits in edits(24),
    ) {
        check_edits(which.get::<String>(corpus()), &edits)?;
    }
}

/// Text made of the characters that matter to lexing and cutting chunks.
const SOUP: &str = "[{}()\\[\\]\"\\\\#\n .:,;=<>!@a-fTMPS0-9한😀]{0,160}";

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    /// Any text parsed with the cache of any other gives what parsing it
    /// from scratch gives; so does one sharing a beginning and an end with it.
    #[test]
    fn any_text_after_any_other_parses_as_from_scratch(
        a in SOUP,
        b in SOUP,
        middle in SOUP,
    ) {
        let file = FileId(1);
        let (_, cache) = parse_incremental(file, &a, None);
        let (incremental, _) = parse_incremental(file, &b, Some(&cache));
        if let Some(diff) = difference(&incremental, &parse(file, &b)) {
            return Err(TestCaseError::fail(format!("{a:?} then {b:?}: {diff}")));
        }
        let joined = format!("{a}{middle}{b}");
        let (_, cache) = parse_incremental(file, &format!("{a}\n{b}"), None);
        let (incremental, _) = parse_incremental(file, &joined, Some(&cache));
        if let Some(diff) = difference(&incremental, &parse(file, &joined)) {
            return Err(TestCaseError::fail(format!("{joined:?}: {diff}")));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn edits_to_a_large_generated_mission_parse_as_from_scratch(edits in edits(10)) {
        check_edits(generated(), &edits)?;
    }
}

/// Typing a whole line of a statement character by character into the
/// generated mission, then deleting it again: every chunk but the edited
/// one is reused.
#[test]
fn typing_into_the_generated_mission_reparses_one_chunk() {
    let text = generated();
    let at = text.find("  stop()\n}").expect("a stop() in the mission") + "  stop()\n".len();
    let typed = "  if (DISTANCE > 30) move(\"1,1\") else turn_left()\n";
    let (_, mut cache) = parse_incremental(FileId(0), text, None);
    let chunks = cache.chunks();
    let mut versions = Vec::new();
    for n in (0..=typed.len()).chain((0..typed.len()).rev()) {
        versions.push(format!("{}{}{}", &text[..at], &typed[..n], &text[at..]));
    }
    for version in &versions {
        let (incremental, next) = parse_incremental(FileId(0), version, Some(&cache));
        assert!(next.reparsed() <= 1, "{next:?}");
        assert!(next.relexed().len() <= 2 * typed.len(), "{next:?}");
        assert_eq!(next.chunks(), chunks);
        let scratch = parse(FileId(0), version);
        assert_eq!(difference(&incremental, &scratch), None);
        cache = next;
    }
}
