//! The parser, the checker and the editor features never panic, whatever the input: random bytes, random
//! token soups, and random line mutations (delete, duplicate, swap) of the
//! reference examples; nor does the strategy loader and cross checker on
//! damaged strategy XML; nor do the deployment reader, `deploy::check` and
//! the broker's files on damaged deployment files (whose broker files stay
//! lines mosquitto reads as written), nor the scenario reader and the
//! simulator on damaged scenarios. Thousands of cases run in the normal test
//! run; the `#[ignore]`d variant runs many more (`cargo test --test robustness -- --ignored`,
//! with `SEMO_FUZZ_CASES` to choose how many). libFuzzer targets live in
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
fn ide_never_panics(text: &str, analysis: &semo::CheckedMission) {
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
    replace_with(text, at, len, c.encode_utf8(&mut [0; 4]))
}

/// [`replace_chars`] with a piece of text in place of one character.
fn replace_with(text: &str, at: usize, len: usize, piece: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let at = at % (chars.len() + 1);
    let end = (at + len).min(chars.len());
    let mut out: String = chars[..at].iter().collect();
    out.push_str(piece);
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
fn strategy_missions() -> &'static Vec<(String, semo::CheckedMission)> {
    static MISSIONS: OnceLock<Vec<(String, semo::CheckedMission)>> = OnceLock::new();
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

// --- refined missions ----------------------------------------------------------

/// A mission checked and refined as `semo build` and `semo simulate` do it.
struct Refined {
    analysis: std::sync::Arc<semo::CheckedMission>,
    programs: Vec<semo::refine::RobotProgram>,
}

fn refined(path: &str) -> Refined {
    let (run, id) =
        semo::host::load_build(&support::repo_root().join(path), &[]).expect("the mission loads");
    let build = run.analysis().build_input(id).expect("the mission checks");
    let refined = semo::refine::refine_checked(&build.input());
    assert!(
        !refined.programs.is_empty(),
        "{path}: {:#?}",
        refined.diagnostics
    );
    Refined {
        analysis: build.analysis.clone(),
        programs: refined.programs,
    }
}

/// The first fenced block in `lang` of a document of the repository.
fn doc_block(path: &str, lang: &str) -> String {
    let text = std::fs::read_to_string(support::repo_root().join(path)).expect("the document");
    let start = text.find(&format!("```{lang}\n")).expect("a block") + lang.len() + 4;
    let end = start + text[start..].find("```").expect("its end");
    text[start..end].to_string()
}

/// Character damage in one of `examples`: one of `pieces` (text that damages
/// the format more to the point than a random character) or a random
/// character in place of up to 3 characters, so that a good share of the
/// damaged files is still read and goes on to what comes after reading.
fn damaged(
    examples: fn() -> &'static Vec<String>,
    pieces: &'static [&'static str],
) -> impl Strategy<Value = String> {
    (
        0..examples().len(),
        any::<usize>(),
        any::<usize>(),
        prop::sample::select(pieces),
        any::<char>(),
        any::<bool>(),
    )
        .prop_map(move |(which, at, len, piece, c, special)| {
            let text = &examples()[which];
            if special {
                replace_with(text, at, len % 4, piece)
            } else {
                replace_chars(text, at, len % 4, c)
            }
        })
}

/// The byte ranges of the values written in a TOML or JSON text: its quoted
/// strings on one line but its keys, and its numbers.
fn value_tokens(text: &str) -> Vec<std::ops::Range<usize>> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && !matches!(bytes[i], b'"' | b'\n') {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if bytes.get(i) == Some(&b'"') {
                    i += 1;
                    // A key is not a value.
                    let after = text[i..].trim_start_matches([' ', '\t']);
                    if !after.starts_with([':', '=']) {
                        tokens.push(start..i);
                    }
                }
            }
            b'-' | b'0'..=b'9'
                if start == 0
                    || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_') =>
            {
                i += 1;
                while i < bytes.len()
                    && matches!(bytes[i], b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-')
                {
                    i += 1;
                }
                tokens.push(start..i);
            }
            _ => i += 1,
        }
    }
    tokens
}

/// One value of one of `examples` replaced by another of the same text, or
/// by one of `values`: the text stays well-formed more often than not, and
/// its meaning goes where damage to its syntax does not reach.
fn swapped_values(
    examples: fn() -> &'static Vec<String>,
    values: &'static [&'static str],
) -> impl Strategy<Value = String> {
    (
        0..examples().len(),
        any::<usize>(),
        any::<usize>(),
        prop::sample::select(values),
        any::<bool>(),
    )
        .prop_map(move |(which, at, other, value, own)| {
            let text = &examples()[which];
            let tokens = value_tokens(text);
            if tokens.is_empty() {
                return text.clone();
            }
            let at = tokens[at % tokens.len()].clone();
            let value = if own {
                &text[tokens[other % tokens.len()].clone()]
            } else {
                value
            };
            format!("{}{value}{}", &text[..at.start], &text[at.end..])
        })
}

// --- deployment files -------------------------------------------------------------

const DEPLOY_FILE: FileId = FileId(3);

/// The repository's deployment files: the build fixtures (each with its own
/// mistake, some of them only the mission's to find) and the example of
/// `docs/deployment.md` (every key).
fn deploy_examples() -> &'static Vec<String> {
    static EXAMPLES: OnceLock<Vec<String>> = OnceLock::new();
    EXAMPLES.get_or_init(|| {
        let fixtures = support::repo_root().join("tests/fixtures/build");
        let mut examples: Vec<String> = [
            "E120_deploy_unknown_key",
            "E121_deploy_unknown_robot",
            "E122_deploy_bad_broker",
            "E123_deploy_missing_file",
            "E126_deploy_not_a_certificate",
            "E127_deploy_unwritable_user",
        ]
        .iter()
        .map(|dir| {
            std::fs::read_to_string(fixtures.join(dir).join("pair.deploy.toml"))
                .expect("deployment fixture")
        })
        .collect();
        examples.push(doc_block("docs/deployment.md", "toml"));
        examples
    })
}

/// The folder the deployments' relative paths are read against: every file
/// the examples name is there and holds what it should (a PEM certificate,
/// a PEM key, a password), so that the undamaged files get past their own
/// reading and the damage reaches `check` and the broker's files.
fn deploy_folder() -> &'static std::path::Path {
    static FOLDER: OnceLock<std::path::PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("robustness-deploy");
        for name in [
            "ca.crt",
            "rover.crt",
            "rover.key",
            "rovers.pw",
            "certs/ca.crt",
            "certs/operator.crt",
            "certs/operator.key",
            "certs/irobot.crt",
            "certs/irobot.key",
            "secrets/operator.pw",
            "secrets/slaves.pw",
            "secrets/irobot.pw",
        ] {
            let path = dir.join(name);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            let text = if name.ends_with(".crt") {
                "-----BEGIN CERTIFICATE-----\nMIIBAA==\n-----END CERTIFICATE-----\n"
            } else if name.ends_with(".key") {
                "-----BEGIN PRIVATE KEY-----\nMIIBAA==\n-----END PRIVATE KEY-----\n"
            } else {
                "secret\n"
            };
            std::fs::write(&path, text).unwrap();
        }
        dir
    })
}

/// The missions the deployments are checked against: the fixtures' pair
/// (teams Base and Rover) and scouting (the documentation's example).
fn deploy_missions() -> &'static Vec<Refined> {
    static MISSIONS: OnceLock<Vec<Refined>> = OnceLock::new();
    MISSIONS.get_or_init(|| {
        [
            "tests/fixtures/build/E121_deploy_unknown_robot/pair.mission",
            "examples/scouting/scouting.mission",
        ]
        .iter()
        .map(|p| refined(p))
        .collect()
    })
}

/// A diagnostic of the deployment file: in it, inside it, on one line.
fn assert_deploy_diagnostic(text: &str, d: &semo::diag::Diagnostic) {
    assert_eq!(d.file, DEPLOY_FILE, "{d:?}");
    assert_in(text, d.span, d);
    assert!(!d.message.is_empty() && !d.message.contains('\n'), "{d:?}");
    assert!(d.related.is_empty(), "{d:?}");
}

/// The directives `semo deploy broker-config` writes into mosquitto.conf.
const CONFIG_DIRECTIVES: &[&str] = &[
    "per_listener_settings",
    "allow_anonymous",
    "password_file",
    "acl_file",
    "set_tcp_nodelay",
    "persistence",
    "persistence_location",
    "user",
    "listener",
    "cafile",
    "certfile",
    "keyfile",
    "require_certificate",
];

/// Whatever a deployment says, the broker's files are lines mosquitto reads
/// as written: comments, the directives above, `user U` and `topic read|write T`;
/// no control character but the line breaks, no value with a blank at an end;
/// anonymous clients refused once and for all.
fn assert_broker_files(files: &semo::deploy::broker::BrokerFiles) {
    for text in [&files.config, &files.acl] {
        assert!(!text.chars().any(|c| c.is_control() && c != '\n'), "{text}");
    }
    let value = |v: &str| !v.is_empty() && v.trim() == v;
    for line in files.config.lines() {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (directive, rest) = line.split_once(' ').expect("a directive and its value");
        assert!(CONFIG_DIRECTIVES.contains(&directive), "{line:?}");
        assert!(value(rest), "{line:?}");
    }
    let anonymous: Vec<&str> = files
        .config
        .lines()
        .filter(|l| l.starts_with("allow_anonymous"))
        .collect();
    assert_eq!(anonymous, ["allow_anonymous false"], "{}", files.config);
    for line in files.acl.lines() {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let rest = line
            .strip_prefix("user ")
            .or_else(|| line.strip_prefix("topic read "))
            .or_else(|| line.strip_prefix("topic write "));
        assert!(rest.is_some_and(value), "{line:?}");
    }
}

/// Reads `text` as a deployment file, then checks it against each mission
/// and writes the broker's files for it: no panic, every diagnostic inside
/// the text on character boundaries, and broker files that say only what
/// they mean to.
fn check_deploy_never_panics(text: &str) {
    let deployment = match semo::deploy::parse(text, DEPLOY_FILE, deploy_folder()) {
        Ok(deployment) => deployment,
        Err(diagnostics) => {
            assert!(!diagnostics.is_empty());
            for d in &diagnostics {
                assert_deploy_diagnostic(text, d);
            }
            return;
        }
    };
    assert_in(text, deployment.broker.span, &deployment.broker);
    for named in deployment
        .teams
        .iter()
        .map(|t| t.span)
        .chain(deployment.robots.iter().map(|r| r.span))
    {
        assert_in(text, named, &named);
    }
    for mission in deploy_missions() {
        for d in &semo::deploy::check(&deployment, &mission.analysis.mission) {
            assert_deploy_diagnostic(text, d);
        }
        for p in &mission.programs {
            deployment.robot(&p.team, &p.robot);
        }
        deployment.operator_credentials();
        let out = std::path::Path::new("/srv/semo/broker");
        match semo::deploy::broker::files(&deployment, &mission.programs, out, "x.deploy.toml") {
            Ok(files) => assert_broker_files(&files),
            Err(semo::deploy::broker::Refusal::Deployment(diagnostics)) => {
                assert!(!diagnostics.is_empty());
                for d in &diagnostics {
                    assert_deploy_diagnostic(text, d);
                }
            }
            Err(semo::deploy::broker::Refusal::Unwritable(why)) => assert!(!why.is_empty()),
        }
    }
}

const TOML_PIECES: &[&str] = &[
    "=",
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    ",",
    ".",
    "\"",
    "'",
    "'''",
    "\"\"\"",
    "#",
    "\n",
    "\r\n",
    " ",
    "\\",
    "\\n",
    "\\u0000",
    "\\U0010FFFF",
    "mqtt://",
    "mqtts://",
    ":0",
    ":65536",
    ":8883",
    "/",
    "..",
    "x",
    "0",
    "1e400",
    "inf",
    "nan",
    "true",
    "1979-05-27T07:32:00Z",
    "[robots.irobot]",
    "[teams.SlaveTeam]",
    "[robots.base]\nid = \"x\"",
    "[operator]",
    "[broker_config]",
    "user = \"u\"",
    "user = \"a:b\"",
    "ca = \"certs/ca.crt\"",
    "password_file = \"rovers.pw\"",
    "id = \"semo\"",
    "한",
    "😀",
    "\u{feff}",
];

fn damaged_deployment() -> impl Strategy<Value = String> {
    damaged(deploy_examples, TOML_PIECES)
}

fn mutated_deployment() -> impl Strategy<Value = String> {
    line_mutations(deploy_examples)
}

const TOML_VALUES: &[&str] = &[
    "\"mqtt://localhost\"",
    "\"mqtts://[::1]:8883\"",
    "\"mqtt://127.0.0.1:0\"",
    "\"mqtt://h:65535/\"",
    "\"mqtt://a b\"",
    "\"mqtt://\"",
    "\"\"",
    "\" x\"",
    "\"a:b\"",
    "\"a\\nb\"",
    "\"a\\u0000b\"",
    "\"/\"",
    "\".\"",
    "\"../..\"",
    "\"certs\"",
    "\"rovers.pw\"",
    "\"certs/irobot.key\"",
    "\"ca.crt\"",
    "\"/dev/null\"",
    "\"😀\"",
    "'literal'",
    "'''two\nlines'''",
    "1",
    "true",
    "[]",
    "{}",
    "{ user = \"u\" }",
];

fn swapped_deployment_values() -> impl Strategy<Value = String> {
    swapped_values(deploy_examples, TOML_VALUES)
}

// --- scenarios ---------------------------------------------------------------------

/// The missions the scenarios are for.
const SCENARIO_MISSIONS: &[&str] = &[
    "examples/scouting/scouting.mission",
    "tests/fixtures/semantics/leader_commands.mission",
    "tests/fixtures/shared_battery/shared.mission",
    "tests/fixtures/loops/loops.mission",
    "examples/follow/follow.mission",
];

/// The repository's scenario files, with the mission (of `SCENARIO_MISSIONS`)
/// each is for: between them every key of the format.
const SCENARIOS: &[(&str, usize)] = &[
    ("tests/fixtures/build/scouting.scenario.json", 0),
    // docs/scenario-and-trace.md's example (below): every section.
    ("", 0),
    ("tests/fixtures/semantics/leader_commands.scenario.json", 1),
    ("tests/fixtures/shared_battery/shared.scenario.json", 2),
    ("tests/fixtures/loops/loops.scenario.json", 3),
    ("tests/fixtures/cortex_m/follow.scenario.json", 4),
];

fn scenario_examples() -> &'static Vec<String> {
    static EXAMPLES: OnceLock<Vec<String>> = OnceLock::new();
    EXAMPLES.get_or_init(|| {
        SCENARIOS
            .iter()
            .map(|(path, _)| match *path {
                // Its faults kill and restart patrol_groups' tb_0: made
                // scouting's nxt, the example is all scouting's.
                "" => doc_block("docs/scenario-and-trace.md", "json").replace("tb_0", "nxt"),
                path => std::fs::read_to_string(support::repo_root().join(path))
                    .expect("scenario fixture"),
            })
            .collect()
    })
}

fn scenario_missions() -> &'static Vec<Refined> {
    static MISSIONS: OnceLock<Vec<Refined>> = OnceLock::new();
    MISSIONS.get_or_init(|| SCENARIO_MISSIONS.iter().map(|p| refined(p)).collect())
}

/// How long an accepted scenario is simulated (mission ms): a few of the
/// scenarios' instants, not their whole duration.
const SIMULATED_MS: i64 = 6000;

/// A scenario mistake or warning: inside the text, on a character boundary,
/// with a message; its line and column found.
fn assert_scenario_error(text: &str, e: &semo::sim::ScenarioError) {
    assert!(e.at <= text.len() && text.is_char_boundary(e.at), "{e:?}");
    assert!(!e.message.is_empty(), "{e:?}");
    let (line, col) = e.line_col(text);
    assert!(line >= 1 && col >= 1, "{e:?}");
    assert!(line as usize <= text.matches('\n').count() + 1, "{e:?}");
}

/// Reads `text` as a scenario of each mission: no panic, every mistake and
/// warning positioned inside the text; an accepted one is simulated for
/// `SIMULATED_MS` and its run judged, pictured and compiled per robot.
fn check_scenario_never_panics(text: &str) {
    use semo::sim;
    for mission in scenario_missions() {
        let programs = &mission.programs;
        let scenario = match sim::scenario::parse(text, programs) {
            Ok(scenario) => scenario,
            Err(e) => {
                assert_scenario_error(text, &e);
                continue;
            }
        };
        for w in &scenario.warnings {
            assert_scenario_error(text, w);
        }
        let options = sim::Options {
            until_ms: Some(SIMULATED_MS),
            ..sim::Options::default()
        };
        let run = sim::simulate(programs, &scenario, &options);
        assert!(run.end_ms <= SIMULATED_MS, "{}", run.end_ms);
        assert!(
            run.trace.windows(2).all(|w| w[0].t <= w[1].t),
            "the trace is in time order"
        );
        assert!(run.trace.iter().all(|e| e.t <= run.end_ms));
        let verdicts = sim::expect::judge(&run, &scenario.expect);
        assert_eq!(verdicts.len(), scenario.expect.len());
        sim::summary(&run, &verdicts);
        run.trace_lines();
        sim::svg::to_svg(&run, programs, &scenario);
        for p in programs {
            scenario.compiled_for(p);
        }
    }
}

const JSON_PIECES: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "\\",
    "\\u0000",
    "\\ud800",
    "\\udc00",
    "\\ud83d\\ude00",
    "-",
    "0",
    "9",
    "-1",
    "0.5",
    "-0",
    "1.5",
    "1e15",
    "1e16",
    "1e400",
    "9007199254740993",
    "null",
    "true",
    "false",
    " ",
    "\n",
    "\"irobot\"",
    "\"ti\"",
    "\"tb_0\"",
    "\"FINISH\"",
    "\"USER\"",
    "{\"at\": 0, \"kill\": \"ti\"}",
    "{\"at\": 0, \"restart\": \"irobot\"}",
    "{\"from\": 0, \"until\": 1000000000000000, \"partition\": [[\"ti\"], []]}",
    "{\"every\": 1, \"to\": \"irobot\", \"value\": \"RC_CMD\", \"is\": \"NONE\"}",
    "\"latency\": 0,",
    "\"loss\": 1,",
    "\"battery\": [{\"at\": 0, \"level\": -1e300}],",
    "한",
    "😀",
];

fn damaged_scenario() -> impl Strategy<Value = String> {
    damaged(scenario_examples, JSON_PIECES)
}

fn mutated_scenario() -> impl Strategy<Value = String> {
    line_mutations(scenario_examples)
}

const JSON_VALUES: &[&str] = &[
    "0",
    "1",
    "-1",
    "-0",
    "0.5",
    "1e-9",
    "2",
    "999",
    "3000",
    "1e15",
    "999999999999999",
    "1000000000000001",
    "1e308",
    "-1e308",
    "null",
    "true",
    "[]",
    "{}",
    "\"\"",
    "\"0,0\"",
    "\"irobot\"",
    "\"ti\"",
    "\"nxt\"",
    "\"tb_0\"",
    "\"MasterTeam\"",
    "\"SlaveTeam\"",
    "\"USER\"",
    "\"FINISH\"",
    "\"RC_MODE\"",
    "\"LOCATION\"",
    "\"BATTERY\"",
    "[\"ti\", \"ti\"]",
    "[[\"irobot\"], [\"irobot\"]]",
    "\"😀\"",
];

fn swapped_scenario_values() -> impl Strategy<Value = String> {
    swapped_values(scenario_examples, JSON_VALUES)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_as_a_deployment_file(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        check_deploy_never_panics(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn line_mutations_of_deployment_files(text in mutated_deployment()) {
        check_deploy_never_panics(&text);
    }

    #[test]
    fn damaged_deployment_files(text in damaged_deployment()) {
        check_deploy_never_panics(&text);
    }

    #[test]
    fn swapped_values_in_deployment_files(text in swapped_deployment_values()) {
        check_deploy_never_panics(&text);
    }

    #[test]
    fn random_bytes_as_a_scenario(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        check_scenario_never_panics(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn line_mutations_of_scenarios(text in mutated_scenario()) {
        check_scenario_never_panics(&text);
    }

    #[test]
    fn damaged_scenarios(text in damaged_scenario()) {
        check_scenario_never_panics(&text);
    }

    #[test]
    fn swapped_values_in_scenarios(text in swapped_scenario_values()) {
        check_scenario_never_panics(&text);
    }
}

#[test]
fn the_deployment_and_scenario_examples_read_as_expected() {
    // The accepted deployments reach `check` and the broker's files.
    let accepted: Vec<bool> = deploy_examples()
        .iter()
        .map(|text| semo::deploy::parse(text, DEPLOY_FILE, deploy_folder()).is_ok())
        .collect();
    assert_eq!(
        accepted,
        [false, true, false, true, true, false, true],
        "E120, E122 and E127 are mistakes of the file itself"
    );
    for text in deploy_examples() {
        check_deploy_never_panics(text);
    }
    // Every scenario is accepted by its mission, and simulated.
    for ((path, mission), text) in SCENARIOS.iter().zip(scenario_examples()) {
        let programs = &scenario_missions()[*mission].programs;
        let scenario =
            semo::sim::scenario::parse(text, programs).unwrap_or_else(|e| panic!("{path}: {e:?}"));
        assert!(
            scenario.warnings.is_empty(),
            "{path}: {:?}",
            scenario.warnings
        );
        check_scenario_never_panics(text);
    }
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
    let deployments = prop_oneof![
        random_text(),
        mutated_deployment(),
        damaged_deployment(),
        swapped_deployment_values(),
    ];
    runner
        .run(&deployments, |text| {
            check_deploy_never_panics(&text);
            Ok(())
        })
        .unwrap();
    let scenarios = prop_oneof![
        random_text(),
        mutated_scenario(),
        damaged_scenario(),
        swapped_scenario_values(),
    ];
    runner
        .run(&scenarios, |text| {
            check_scenario_never_panics(&text);
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
