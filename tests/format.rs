//! The formatter as a specification.
//!
//! - Fixture pairs: `tests/fixtures/format/NAME.mission` formats to
//!   `NAME.expected.mission` (`SEMO_UPDATE_FORMAT=1 cargo test --test format`
//!   rewrites the expected files; review the diff).
//! - Every mission of the examples and fixtures keeps its tokens and comments,
//!   and formats to itself once formatted; a mission with syntax errors is
//!   refused.
//! - Property tests: any text gives a result or a refusal, never a panic;
//!   generated valid missions, laid out at random with comments everywhere,
//!   are never refused, keep their tokens and comments, and are formatted in
//!   one pass.

mod support;

use proptest::prelude::*;
use semo::diag::FileId;
use semo::format::{FormatRefusal, format_source};
use semo::syntax::token::{Token, lex};
use std::path::{Path, PathBuf};

/// Every `*.mission` under `dir`, sorted.
fn missions(dir: &Path, found: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            missions(&path, found);
        } else if path.extension().is_some_and(|e| e == "mission") {
            found.push(path);
        }
    }
}

fn format_dir() -> PathBuf {
    support::repo_root().join("tests/fixtures/format")
}

#[test]
fn fixtures_format_to_their_expected_text() {
    let update = std::env::var_os("SEMO_UPDATE_FORMAT").is_some();
    let mut inputs = Vec::new();
    missions(&format_dir(), &mut inputs);
    inputs.retain(|p| !p.to_string_lossy().ends_with(".expected.mission"));
    assert!(inputs.len() >= 10, "the fixtures are there");
    let mut failures = Vec::new();
    for input in &inputs {
        let text = std::fs::read_to_string(input).unwrap();
        let expected_path = input.with_extension("expected.mission");
        let formatted =
            format_source(&text).unwrap_or_else(|e| panic!("{}: refused: {e}", input.display()));
        if update {
            std::fs::write(&expected_path, &formatted).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|e| panic!("{}: {e}", expected_path.display()));
        if formatted != expected {
            failures.push(format!(
                "{} formats to:\n{formatted}\ninstead of:\n{expected}",
                input.display()
            ));
        }
        // The expected text is itself formatted.
        assert_eq!(
            format_source(&expected).as_ref(),
            Ok(&expected),
            "{} is not formatted",
            expected_path.display()
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// The tokens of `text` as written.
fn tokens(text: &str) -> Vec<String> {
    lex(text)
        .into_iter()
        .map(|(t, _)| match t {
            Token::Str(s) => s.to_string(),
            other => other.to_string(),
        })
        .collect()
}

/// Every comment of `text` (trailing whitespace removed) with the number of
/// tokens before it and whether code precedes it on its line. Written apart
/// from the formatter's own scanning, so that the two check each other.
fn comments(text: &str) -> Vec<(usize, String, bool)> {
    let spans: Vec<(usize, usize)> = lex(text)
        .into_iter()
        .map(|(_, s)| (s.start, s.end))
        .collect();
    let mut found = Vec::new();
    let mut gap_start = 0;
    for i in 0..=spans.len() {
        let gap_end = spans.get(i).map_or(text.len(), |s| s.0);
        let gap = &text[gap_start..gap_end];
        let mut at = 0;
        while let Some(hash) = gap[at..].find('#') {
            let start = at + hash;
            let end = gap[start..].find('\n').map_or(gap.len(), |e| start + e);
            let after_code = i > 0 && !gap[..start].contains('\n');
            found.push((i, gap[start..end].trim_end().to_string(), after_code));
            at = end;
        }
        gap_start = spans.get(i).map_or(text.len(), |s| s.1);
    }
    found
}

/// Formats `text`; when it is not refused, checks that the output keeps the
/// tokens and comments, parses without errors, and formats to itself.
fn check_faithful_and_stable(text: &str) -> Result<String, FormatRefusal> {
    let out = format_source(text)?;
    assert_eq!(
        tokens(&out),
        tokens(text),
        "tokens changed:\n{text}\n---\n{out}"
    );
    assert_eq!(
        comments(&out),
        comments(text),
        "comments changed:\n{text}\n---\n{out}"
    );
    let parsed = semo::syntax::parse(FileId(0), &out);
    assert!(
        parsed.diagnostics.is_empty(),
        "{:?}\n{out}",
        parsed.diagnostics
    );
    assert_eq!(
        format_source(&out).as_ref(),
        Ok(&out),
        "not idempotent:\n{text}\n---\n{out}"
    );
    Ok(out)
}

#[test]
fn every_example_and_fixture_keeps_its_tokens_and_comments_and_is_stable() {
    let root = support::repo_root();
    let mut paths = Vec::new();
    for dir in [root.join("examples"), root.join("tests/fixtures")] {
        missions(&dir, &mut paths);
    }
    assert!(paths.len() > 60, "only {} missions found", paths.len());
    let (mut formatted, mut refused) = (0, 0);
    for path in &paths {
        let text = std::fs::read_to_string(path).unwrap();
        let syntax_errors = !semo::syntax::parse(FileId(0), &text).diagnostics.is_empty();
        match check_faithful_and_stable(&text) {
            Ok(_) => {
                assert!(!syntax_errors, "{}", path.display());
                formatted += 1;
            }
            Err(FormatRefusal::SyntaxErrors(diags)) => {
                assert!(syntax_errors && !diags.is_empty(), "{}", path.display());
                refused += 1;
            }
            Err(other) => panic!("{}: {other}", path.display()),
        }
    }
    // The examples and nearly all fixtures are valid syntax; a few are not on purpose.
    assert!(
        formatted > 50 && refused >= 3,
        "{formatted} formatted, {refused} refused"
    );
}

#[test]
fn the_reference_examples_are_close_to_the_canonical_layout() {
    // The style follows the examples: formatting them changes few lines.
    for name in ["scouting/scouting.mission", "swarm/march.mission"] {
        let text = std::fs::read_to_string(support::examples().join(name)).unwrap();
        let out = format_source(&text).unwrap();
        let kept = text
            .lines()
            .filter(|l| out.lines().any(|o| o == *l))
            .count();
        assert!(
            kept * 10 >= text.lines().count() * 7,
            "{name}: only {kept} of {} lines unchanged",
            text.lines().count()
        );
    }
}

// ---- property tests ----

/// A small deterministic generator (xorshift), seeded by proptest.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }
    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[self.below(from.len())]
    }
}

const NAMES: &[&str] = &[
    "T",
    "Team",
    "A_VERY_LONG_NAME_FOR_A_VALUE_OF_THE_TEAM",
    "x",
    "LOCATION",
    "Status",
];
const WORDS: &[&str] = &["Paris", "palace", "of", "and", "congress", "or", "group"];
const PERIODS: &[&str] = &["2 SEC", "500 msec", "1 MIN", "3 hour", "1.5 sec"];

/// A valid mission as a list of tokens, covering the whole grammar.
struct Mission {
    rng: Rng,
    tokens: Vec<String>,
}

impl Mission {
    fn t(&mut self, token: &str) {
        for part in token.split(' ') {
            self.tokens.push(part.to_string());
        }
    }
    /// One token that may hold spaces (a string).
    fn raw(&mut self, token: &str) {
        self.tokens.push(token.to_string());
    }
    fn name(&mut self) {
        let n = self.rng.pick(NAMES);
        self.t(n);
    }
    fn semis(&mut self) {
        while self.rng.chance(15) {
            self.t(";");
        }
    }
    fn period(&mut self) {
        let p = self.rng.pick(PERIODS);
        self.t(p);
    }
    fn attr(&mut self) {
        self.name();
        for _ in 0..self.rng.below(3) {
            self.t(".");
            self.name();
        }
    }
    fn primary(&mut self, depth: usize) {
        match self.rng.below(if depth > 2 { 6 } else { 7 }) {
            0 => {
                let s = self.rng.pick(&[
                    "\"5,5\"",
                    "\"한국어 😀\"",
                    "\"esc \\\" \\\\ \\n\"",
                    "\"# not a comment\"",
                ]);
                self.raw(s);
            }
            1 => {
                let n = self.rng.pick(&["12", "3.5", "-4", "0"]);
                self.t(n);
            }
            2 => self.period(),
            3 => {
                let b = self.rng.pick(&["true", "false"]);
                self.t(b);
            }
            4 | 5 => self.attr(),
            _ => {
                self.t("(");
                self.expr(depth + 1);
                self.t(")");
            }
        }
    }
    fn expr(&mut self, depth: usize) {
        let terms = 1 + self.rng.below(if depth > 1 { 1 } else { 3 });
        for k in 0..terms {
            if k > 0 {
                let op = self.rng.pick(&["and", "or", "&&", "||"]);
                self.t(op);
            }
            for _ in 0..self.rng.below(2) {
                let not = self.rng.pick(&["not", "!"]);
                self.t(not);
            }
            self.primary(depth);
            if self.rng.chance(50) {
                let op = self.rng.pick(&["==", "!=", "<", "<=", ">", ">="]);
                self.t(op);
                self.primary(depth);
            }
        }
    }
    /// A condition alone in `loop(...)` or `repeat(...)`: it must not start
    /// with a period, which would be read as `loop(2 SEC)`.
    fn condition(&mut self) {
        self.attr();
        if self.rng.chance(50) {
            let op = self.rng.pick(&["==", "<", ">="]);
            self.t(op);
            self.primary(0);
        }
        if self.rng.chance(40) {
            let op = self.rng.pick(&["and", "or", "&&", "||"]);
            self.t(op);
            self.expr(1);
        }
    }
    fn timeout(&mut self) {
        self.t("timeout =");
        self.period();
    }
    fn block(&mut self, depth: usize) {
        if depth < 4 && self.rng.chance(30) {
            self.stmt(depth + 1);
        } else {
            self.t("{");
            for _ in 0..self.rng.below(if depth < 4 { 4 } else { 2 }) {
                self.stmt(depth + 1);
            }
            self.t("}");
        }
    }
    fn stmt(&mut self, depth: usize) {
        match self.rng.below(if depth < 4 { 9 } else { 5 }) {
            0 | 1 => {
                // A call.
                self.name();
                self.t("(");
                for k in 0..self.rng.below(4) {
                    if k > 0 {
                        self.t(",");
                    }
                    if self.rng.chance(20) {
                        for _ in 0..2 + self.rng.below(3) {
                            let w = self.rng.pick(WORDS);
                            self.t(w);
                        }
                    } else {
                        self.expr(0);
                    }
                }
                self.t(")");
                if self.rng.chance(20) {
                    self.t(",");
                    self.timeout();
                }
            }
            2 => {
                let kind = self.rng.pick(&["send", "receive", "publish", "subscribe"]);
                self.t(kind);
                self.t("(");
                self.name();
                let items = if matches!(kind, "send" | "receive") {
                    1 + self.rng.below(3)
                } else {
                    1
                };
                for _ in 0..items {
                    self.t(",");
                    self.attr();
                    if (kind == "send" || kind == "publish") && self.rng.chance(30) {
                        self.t("=");
                        self.expr(0);
                    }
                }
                self.t(")");
                if self.rng.chance(15) {
                    self.t(",");
                    self.timeout();
                }
            }
            3 => {
                self.t("throw");
                self.name();
            }
            4 => {
                self.t("stop ( )");
            }
            5 | 6 => {
                self.t("if (");
                self.expr(0);
                self.t(")");
                self.block(depth);
                if self.rng.chance(50) {
                    self.t("else");
                    if self.rng.chance(40) {
                        self.t("if (");
                        self.expr(0);
                        self.t(")");
                    }
                    self.block(depth);
                }
            }
            7 => {
                self.t("loop (");
                match self.rng.below(3) {
                    0 => self.period(),
                    1 => self.condition(),
                    _ => {
                        self.period();
                        self.t(",");
                        self.expr(0);
                    }
                }
                self.t(")");
                self.block(depth);
            }
            _ => {
                self.t("[[");
                let leader = self.rng.chance(30);
                for _ in 0..if leader { 1 } else { 1 + self.rng.below(2) } {
                    self.t(if leader { "leader (" } else { "group (" });
                    let condition = self.rng.pick(&["instance of", "capable of"]);
                    self.t(condition);
                    self.name();
                    for _ in 0..self.rng.below(3) {
                        self.t(",");
                        self.name();
                    }
                    self.t(")");
                    self.block(depth);
                }
                if self.rng.chance(50) {
                    self.t("others");
                    self.block(depth);
                }
                self.t("]]");
            }
        }
        self.semis();
    }
    fn team(&mut self) {
        self.name();
        self.t(":");
        for k in 0..1 + self.rng.below(3) {
            if k > 0 {
                self.t(",");
            }
            self.name();
            self.name();
            if self.rng.chance(30) {
                self.t("[ 3 ]");
            }
        }
        self.semis();
    }
    fn item(&mut self) {
        match self.rng.below(7) {
            0 => {
                self.t("{");
                for _ in 0..self.rng.below(4) {
                    self.team();
                }
                self.t("}");
            }
            1 => self.team(),
            2 | 3 => {
                self.name();
                self.t(".");
                self.name();
                self.t(".");
                self.name();
                self.t("{");
                for _ in 0..self.rng.below(5) {
                    self.stmt(0);
                }
                self.t("}");
                if self.rng.chance(70) {
                    self.t("repeat (");
                    match self.rng.below(4) {
                        0 => {}
                        1 => self.period(),
                        2 => self.condition(),
                        _ => {
                            self.period();
                            self.t(",");
                            self.expr(0);
                        }
                    }
                    self.t(")");
                }
            }
            4 => {
                self.t("def");
                self.name();
                self.t("{");
                for _ in 0..self.rng.below(4) {
                    self.stmt(0);
                }
                self.t("}");
            }
            5 => {
                self.name();
                self.t(".");
                self.name();
                self.t("{");
                for _ in 0..self.rng.below(4) {
                    self.t("set (");
                    self.name();
                    self.t(",");
                    if self.rng.chance(30) {
                        self.t("OFF");
                    } else {
                        self.name();
                    }
                    if self.rng.chance(20) {
                        self.t(",");
                        self.timeout();
                    }
                    self.t(")");
                    self.semis();
                }
                self.t("}");
            }
            _ => {
                self.name();
                self.t(". main {");
                for _ in 0..self.rng.below(3) {
                    self.t("case (");
                    self.name();
                    self.t(") :");
                    for _ in 0..self.rng.below(3) {
                        self.t("catch (");
                        self.name();
                        self.t(") : mode =");
                        self.name();
                        self.semis();
                    }
                }
                if self.rng.chance(80) {
                    self.t("default : mode =");
                    self.name();
                    self.semis();
                }
                self.t("}");
            }
        }
        self.semis();
    }
}

/// Whether two tokens may touch without whitespace and still lex the same.
fn may_touch(a: &str, b: &str) -> bool {
    let glue = ["(", ")", "{", "}", ",", ";", ":"];
    let risky = |t: &str| t.starts_with(['[', ']', '=', '!', '<', '>', '&', '|', '-', '.']);
    (glue.contains(&a) || glue.contains(&b)) && !risky(a) && !risky(b)
}

/// A generated mission, laid out at random: any whitespace, end-of-line and
/// own-line comments, banners, blank lines, tabs, or no space at all.
fn random_layout(seed: u64) -> String {
    let mut m = Mission {
        rng: Rng(seed | 1),
        tokens: Vec::new(),
    };
    for _ in 0..1 + m.rng.below(5) {
        m.item();
    }
    let mut rng = Rng(seed.rotate_left(17) | 1);
    let mut out = String::new();
    if rng.chance(30) {
        out.push_str("# header\n\n");
    }
    for (i, token) in m.tokens.iter().enumerate() {
        if i > 0 {
            let sep = match rng.below(14) {
                0 if may_touch(&m.tokens[i - 1], token) => "",
                0..=5 => " ",
                6 => "\n",
                7 => "\n\n\n",
                8 => "\t ",
                9 => " # end of line\n",
                10 => "\n  # own line\n",
                11 => "\n\n##### banner #####\n\n",
                12 => " #한국어 주석 😀   \n\n",
                _ => "\n    ",
            };
            out.push_str(sep);
        }
        out.push_str(token);
    }
    if rng.chance(30) {
        out.push_str("\n# footer\n\n");
    }
    out
}

fn mutated_example(which: usize, mutations: &[(u8, usize, usize)]) -> String {
    let root = support::examples();
    let names = [
        "scouting/scouting.mission",
        "follow/follow.mission",
        "swarm/march.mission",
        "swarm/patrol_groups.mission",
    ];
    let text = std::fs::read_to_string(root.join(names[which % names.len()])).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for &(kind, a, b) in mutations {
        let n = lines.len();
        if n == 0 {
            break;
        }
        match kind % 4 {
            0 => {
                lines.remove(a % n);
            }
            1 => {
                let line = lines[a % n].clone();
                lines.insert(b % n, line);
            }
            2 => lines.swap(a % n, b % n),
            _ => {
                let line = &mut lines[a % n];
                line.push_str(" # added");
            }
        }
    }
    lines.join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn any_text_is_formatted_or_refused_never_a_panic(text in any::<String>()) {
        let _ = check_faithful_and_stable(&text);
    }

    #[test]
    fn any_bytes_are_formatted_or_refused(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let _ = check_faithful_and_stable(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn generated_missions_in_any_layout_are_formatted_faithfully_in_one_pass(seed in any::<u64>()) {
        let text = random_layout(seed);
        let parsed = semo::syntax::parse(FileId(0), &text);
        prop_assert!(parsed.diagnostics.is_empty(), "the generator wrote invalid text: {:?}\n{}", parsed.diagnostics, text);
        let out = check_faithful_and_stable(&text);
        prop_assert!(out.is_ok(), "refused: {:?}\n{}", out, text);
    }

    #[test]
    fn mutated_examples_that_parse_are_formatted_faithfully(
        which in 0..4usize,
        mutations in prop::collection::vec((any::<u8>(), any::<usize>(), any::<usize>()), 1..6),
    ) {
        let text = mutated_example(which, &mutations);
        let valid = semo::syntax::parse(FileId(0), &text).diagnostics.is_empty();
        match check_faithful_and_stable(&text) {
            Ok(_) => prop_assert!(valid),
            Err(FormatRefusal::SyntaxErrors(_)) => prop_assert!(!valid),
            Err(other) => prop_assert!(false, "{other}\n{text}"),
        }
    }
}
