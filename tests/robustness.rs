//! The parser, the checker and the editor features never panic, whatever the input: random bytes, random
//! token soups, and random line mutations (delete, duplicate, swap) of the
//! reference examples; nor does the strategy loader and cross checker on
//! damaged strategy XML. Thousands of cases run in the normal test run; the
//! `#[ignore]`d variant runs many more (`cargo test --test robustness -- --ignored`,
//! with `SEMO_FUZZ_CASES` to choose how many). A libFuzzer target lives in
//! `compiler/fuzz/`.

mod support;

use proptest::prelude::*;
use semo::catalog::{Catalog, builtin_catalog};
use semo::diag::FileId;
use semo::strategy::{cross_check, load_strategy};
use std::sync::OnceLock;

fn catalog() -> &'static Catalog {
    static CATALOG: OnceLock<Catalog> = OnceLock::new();
    CATALOG.get_or_init(builtin_catalog)
}

fn examples() -> &'static Vec<String> {
    static EXAMPLES: OnceLock<Vec<String>> = OnceLock::new();
    EXAMPLES.get_or_init(|| {
        let root = support::examples();
        [
            "scouting/scouting.mission",
            "follow/follow.mission",
            "swarm/march.mission",
            "swarm/patrol_groups.mission",
        ]
        .iter()
        .map(|p| std::fs::read_to_string(root.join(p)).expect("shared example"))
        .collect()
    })
}

/// Parses and checks `text`, and checks the invariants of the result: every
/// range lies inside the text on character boundaries.
fn check_never_panics(text: &str) {
    let analysis = semo::check_source(FileId(0), text, catalog());
    for d in &analysis.diagnostics {
        assert!(
            d.span.start <= d.span.end && d.span.end <= text.len(),
            "{d:?}"
        );
        assert!(
            text.is_char_boundary(d.span.start) && text.is_char_boundary(d.span.end),
            "{d:?}"
        );
        assert!(!d.message.is_empty());
    }
    for o in &analysis.mission.occurrences {
        assert!(o.span.end <= text.len(), "{o:?}");
    }
    ide_never_panics(text, &analysis);
}

/// The editor features on the analysis, at a spread of offsets (past the end
/// too): no panic, and their ranges lie inside the text, sorted or nested.
fn ide_never_panics(text: &str, analysis: &semo::Analysis) {
    use semo::ide::mission::*;
    let inside = |s: semo::span::Span| s.start <= s.end && s.end <= text.len();
    let tokens = semantic_tokens::semantic_tokens(analysis, None);
    assert!(tokens.iter().all(|t| inside(t.span)));
    assert!(tokens.windows(2).all(|w| w[0].span.end <= w[1].span.start));
    assert!(
        folding::folding_ranges(analysis, text)
            .iter()
            .all(|f| inside(f.span))
    );
    let outline = symbols::document_symbols(analysis, text);
    assert!(
        outline
            .iter()
            .all(|s| inside(s.span) && inside(s.name_span))
    );
    symbols::workspace_symbols(analysis, "a");
    let step = text.len() / 7 + 1;
    for offset in (0..text.len() + 2).step_by(step) {
        navigation::definition(analysis, catalog(), offset);
        assert!(
            navigation::references(analysis, offset)
                .iter()
                .all(|r| inside(r.span))
        );
        let _ = rename::prepare_rename(analysis, text, offset);
        if let Ok(spans) = rename::rename(analysis, catalog(), text, offset, "renamed") {
            assert!(spans.iter().all(|s| inside(*s)));
        }
        let chain = selection::selection_ranges(analysis, text, offset);
        assert!(
            chain
                .windows(2)
                .all(|w| w[1].start <= w[0].start && w[0].end <= w[1].end)
        );
    }
}

const SOUP: &[&str] = &[
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    "[[",
    "]]",
    ":",
    ";",
    ",",
    ".",
    "=",
    "==",
    "!=",
    "<",
    "<=",
    ">",
    ">=",
    "&&",
    "||",
    "!",
    "if",
    "else",
    "loop",
    "repeat",
    "throw",
    "send",
    "receive",
    "publish",
    "subscribe",
    "set",
    "OFF",
    "def",
    "main",
    "case",
    "catch",
    "default",
    "mode",
    "group",
    "leader",
    "others",
    "instance",
    "of",
    "capable",
    "timeout",
    "true",
    "false",
    "and",
    "or",
    "not",
    "SEC",
    "MSEC",
    "2",
    "-4",
    "3.5",
    "0",
    "\"5,5\"",
    "\"😀 한국\"",
    "\"open",
    "T",
    "Team",
    "USER",
    "iRobotCreate",
    "TIEvalbot",
    "Turtlebot3_Burger",
    "move",
    "light_on",
    "LOCATION",
    "COLOR",
    "Action",
    "Listen",
    "M",
    "E",
    "# comment\n",
    "\n",
    " ",
    "@",
    "한",
];

fn token_soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(SOUP), 0..200).prop_map(|toks| toks.join(" "))
}

#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
}

/// Line mutations (delete, duplicate, swap) of one of `examples`.
fn line_mutations(examples: fn() -> &'static Vec<String>) -> impl Strategy<Value = String> {
    let mutation = prop_oneof![
        any::<usize>().prop_map(Mutation::Delete),
        any::<usize>().prop_map(Mutation::Duplicate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::Swap(a, b)),
    ];
    (0..examples().len(), prop::collection::vec(mutation, 1..8)).prop_map(
        move |(which, mutations)| {
            let mut lines: Vec<String> = examples()[which].lines().map(str::to_string).collect();
            for m in mutations {
                let n = lines.len();
                if n == 0 {
                    break;
                }
                match m {
                    Mutation::Delete(i) => {
                        lines.remove(i % n);
                    }
                    Mutation::Duplicate(i) => {
                        let line = lines[i % n].clone();
                        lines.insert(i % n, line);
                    }
                    Mutation::Swap(a, b) => lines.swap(a % n, b % n),
                }
            }
            lines.join("\n")
        },
    )
}

fn mutated_example() -> impl Strategy<Value = String> {
    line_mutations(examples)
}

/// `text` with the characters from `at` (up to `len`) replaced by `c`; `at`
/// is taken modulo the text's length (plus one).
fn replace_chars(text: &str, at: usize, len: usize, c: char) -> String {
    let chars: Vec<char> = text.chars().collect();
    let at = at % (chars.len() + 1);
    let end = (at + len).min(chars.len());
    let mut out: String = chars[..at].iter().collect();
    out.push(c);
    out.extend(&chars[end..]);
    out
}

/// Byte-level damage inside an example: truncation or a character cut in half
/// is impossible for `&str`, so damage is done on characters.
fn damaged_example() -> impl Strategy<Value = String> {
    (
        0..examples().len(),
        any::<usize>(),
        any::<usize>(),
        any::<char>(),
    )
        .prop_map(|(which, at, len, c)| replace_chars(&examples()[which], at, len % 16, c))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        check_never_panics(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn token_soups(text in token_soup()) {
        check_never_panics(&text);
    }

    #[test]
    fn line_mutations_of_the_examples(text in mutated_example()) {
        check_never_panics(&text);
    }

    #[test]
    fn character_damage_in_the_examples(text in damaged_example()) {
        check_never_panics(&text);
    }
}

// --- strategy files ----------------------------------------------------------

const STRATEGY_FILE: FileId = FileId(2);

fn strategy_examples() -> &'static Vec<String> {
    static EXAMPLES: OnceLock<Vec<String>> = OnceLock::new();
    EXAMPLES.get_or_init(|| {
        let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
        [
            support::examples().join("scouting/MasterTeam.strategy.xml"),
            // Every element of the format, and conditions with a plain `<`.
            fixtures.join("E081_strategy_plain_lt/Scouts.strategy.xml"),
        ]
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("strategy example"))
        .collect()
    })
}

/// The missions the strategies are cross-checked against (their teams are
/// MasterTeam and Scouts).
fn strategy_missions() -> &'static Vec<(String, semo::Analysis)> {
    static MISSIONS: OnceLock<Vec<(String, semo::Analysis)>> = OnceLock::new();
    MISSIONS.get_or_init(|| {
        let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
        [
            support::examples().join("scouting/scouting.mission"),
            fixtures.join("E081_strategy_plain_lt/scouts.mission"),
        ]
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let text = std::fs::read_to_string(p).expect("mission");
            let analysis = semo::check_source(FileId(10 + i as u32), &text, catalog());
            (text, analysis)
        })
        .collect()
    })
}

fn assert_in(text: &str, span: semo::span::Span, what: &dyn std::fmt::Debug) {
    assert!(span.start <= span.end && span.end <= text.len(), "{what:?}");
    assert!(
        text.is_char_boundary(span.start) && text.is_char_boundary(span.end),
        "{what:?}"
    );
}

/// Loads and cross-checks `text` as a strategy file: no panic, and every range
/// lies inside the file it points into, on character boundaries.
fn check_strategy_never_panics(text: &str) {
    let missions = strategy_missions();
    let (strategy, mut diags) = load_strategy(STRATEGY_FILE, text);
    let strategies: Vec<_> = strategy.iter().collect();
    let analyses: Vec<_> = missions.iter().map(|(_, a)| a).collect();
    let (links, more) = cross_check(&strategies, &analyses, catalog());
    diags.extend(more);
    let text_of = |file: FileId| -> &str {
        if file == STRATEGY_FILE {
            return text;
        }
        &missions[(file.0 - 10) as usize].0
    };
    for d in &diags {
        assert_eq!(d.file, STRATEGY_FILE, "{d:?}");
        assert_in(text, d.span, d);
        assert!(!d.message.is_empty() && !d.message.contains('\n'), "{d:?}");
        for r in &d.related {
            assert_in(text_of(r.file), r.span, d);
        }
    }
    for link in links.calls() {
        assert_in(text_of(link.mission), link.call, link);
        assert!(link.entry.index < strategies[0].services.len());
    }
}

fn damaged_strategy() -> impl Strategy<Value = String> {
    (
        0..strategy_examples().len(),
        any::<usize>(),
        any::<usize>(),
        prop::sample::select(vec![
            '<', '>', '"', '\'', '&', ';', '/', '=', '!', '?', ' ', '\n', 'x', '0', '한', '😀',
        ]),
        any::<char>(),
        any::<bool>(),
    )
        .prop_map(|(which, at, len, xml_char, any_char, xml)| {
            let c = if xml { xml_char } else { any_char };
            replace_chars(&strategy_examples()[which], at, len % 24, c)
        })
}

fn mutated_strategy() -> impl Strategy<Value = String> {
    line_mutations(strategy_examples)
}

const XML_SOUP: &[&str] = &[
    "<Strategy name=\"MasterTeam\">",
    "</Strategy>",
    "<ServiceInfo>",
    "</ServiceInfo>",
    "<Service plan_name=\"Action\" name=\"move\">",
    "</Service>",
    "<TargetRobot name=\"iRobotCreate\"/>",
    "<ActionInfo>",
    "</ActionInfo>",
    "<Action name=\"A\" actionId=\"0\" initial=\"Yes\">",
    "<Action name=\"B\" actionId=\"1\" final=\"Yes\"/>",
    "</Action>",
    "<TransitionInfo>",
    "<Transition srcId=\"0\" dstId=\"1\">",
    "</Transition>",
    "<Condition cond=\"d<2 and (e\"/>",
    "<Condition cond=\"d &gt;= 2\">",
    "</Condition>",
    "<Parameter name=\"d\" type=\"int\" dataCharacteristic=\"channel\" srcTask=\"vicon\"/>",
    "<ValueInfo><Value name=\"DISTANCE\">",
    "</Value></ValueInfo>",
    "<GroupingInfo><LeaderSelectionInfo algorithm=\"bully\" plan_name=\"Action\" cs_name=\"Wait\"/>",
    "<GroupSync timeout=\"5 SEC\"/></GroupingInfo>",
    "<NonFunctionalInfo><BatteryRequirement>",
    "<Sensor name=\"Camera\" periodLevel=\"2\"/>",
    "<",
    ">",
    "\"",
    "&lt;",
    "&bogus;",
    "<!--",
    "-->",
    "<![CDATA[x",
    "text",
    "\n",
    "😀",
];

fn xml_soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(XML_SOUP), 0..60).prop_map(|parts| parts.concat())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn damaged_strategy_files(text in damaged_strategy()) {
        check_strategy_never_panics(&text);
    }

    #[test]
    fn line_mutations_of_strategy_files(text in mutated_strategy()) {
        check_strategy_never_panics(&text);
    }

    #[test]
    fn strategy_xml_soups(text in xml_soup()) {
        check_strategy_never_panics(&text);
    }

    #[test]
    fn random_bytes_as_a_strategy_file(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        check_strategy_never_panics(&String::from_utf8_lossy(&bytes));
    }
}

#[test]
fn the_strategy_examples_load_cleanly() {
    // The damage above starts from valid files.
    for text in strategy_examples() {
        let (strategy, diags) = load_strategy(STRATEGY_FILE, text);
        assert!(strategy.is_some());
        assert!(
            diags.iter().all(|d| d.code.as_str() == "E081"),
            "{diags:#?}"
        );
    }
    let long = format!(
        "<Strategy name=\"T\"><NonFunctionalInfo><BatteryRequirement><Condition cond=\"Battery{}\"/></BatteryRequirement></NonFunctionalInfo></Strategy>",
        " and Battery".repeat(20_000)
    );
    check_strategy_never_panics(&long);
}

/// Up to 2000 random bytes, read as UTF-8 where they are not.
fn random_text() -> impl Strategy<Value = String> {
    prop::collection::vec(any::<u8>(), 0..2000)
        .prop_map(|b| String::from_utf8_lossy(&b).into_owned())
}

#[test]
#[ignore = "long-running: many more random cases"]
fn long_running_fuzz() {
    let cases: u32 = std::env::var("SEMO_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000);
    let mut runner = proptest::test_runner::TestRunner::new(ProptestConfig {
        cases,
        ..ProptestConfig::default()
    });
    let strategy = prop_oneof![
        random_text(),
        token_soup(),
        mutated_example(),
        damaged_example(),
    ];
    runner
        .run(&strategy, |text| {
            check_never_panics(&text);
            Ok(())
        })
        .unwrap();
    let strategy_files = prop_oneof![
        random_text(),
        xml_soup(),
        mutated_strategy(),
        damaged_strategy(),
    ];
    runner
        .run(&strategy_files, |text| {
            check_strategy_never_panics(&text);
            Ok(())
        })
        .unwrap();
}

#[test]
fn deeply_nested_input_does_not_overflow_the_stack() {
    let mut text = String::from("{ T: iRobotCreate a }\nT.Action.Go {\n");
    for _ in 0..2000 {
        text.push_str("if (LOCATION == \"0,0\") {\n");
    }
    check_never_panics(&text);
    let parens = format!(
        "T.Action.Go {{ if ({}x{}) stop() }}",
        "(".repeat(5000),
        ")".repeat(5000)
    );
    check_never_panics(&parens);
    // `a and a and ...` is a tree as deep as the chain, and so is `not not ...`.
    let ands = format!(
        "{{ T: iRobotCreate a }}\nT.Action.Go {{ if (a{}) stop() }}",
        " and a".repeat(20_000)
    );
    check_never_panics(&ands);
    let nots = format!(
        "{{ T: iRobotCreate a }}\nT.Action.Go {{ if ({}a) stop() }}",
        "not !".repeat(10_000)
    );
    check_never_panics(&nots);
}

#[test]
fn function_call_chains_are_neither_exponential_nor_unbounded() {
    // f0 calls f1 twice, f1 calls f2 twice, ...: 2^200 inlinings if done naively.
    let mut text = String::from(
        "{ T: iRobotCreate a }\nT.Action.Go { f0() } repeat()\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n",
    );
    for i in 0..200 {
        text.push_str(&format!(
            "def f{i} {{ f{}() f{}() stop() }}\n",
            i + 1,
            i + 1
        ));
    }
    text.push_str("def f200 { stop() }\n");
    let analysis = semo::check_source(FileId(0), &text, catalog());
    assert!(
        analysis
            .diagnostics
            .iter()
            .any(|d| d.code == semo::diag::Code::RecursiveFunction),
        "a 200-deep chain is reported"
    );
}
