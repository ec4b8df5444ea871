//! The `semo` command as a user runs it: the reference examples, output formats,
//! exit codes, help, and positions with non-ASCII text.

mod support;

use support::{check_json_in, semo, semo_in, shared};

#[test]
fn every_shared_example_checks_without_errors() {
    let examples = shared().join("examples");
    for folder in ["scouting", "follow", "swarm"] {
        let (code, diags) = check_json_in(&examples, &[folder]);
        let errors: Vec<_> = diags.iter().filter(|d| d.severity == "error").collect();
        assert!(errors.is_empty(), "{folder}: {errors:#?}");
        assert_eq!(code, 0, "{folder} should exit 0");
    }
}

#[test]
fn scouting_gives_exactly_the_unmatched_receive_warning() {
    let (_, diags) = check_json_in(&shared().join("examples/scouting"), &["scouting.mission"]);
    let warnings: Vec<_> = diags.iter().filter(|d| d.severity != "hint").collect();
    assert_eq!(warnings.len(), 1, "{warnings:#?}");
    let w = warnings[0];
    assert_eq!(w.code, "W004");
    assert_eq!(w.severity, "warning");
    assert!(
        w.message.contains("`SlaveTeam.Listen.CheckStatus`"),
        "{}",
        w.message
    );
    assert!(
        w.message.contains("`SlaveTeam.COLOR` from SlaveTeam"),
        "{}",
        w.message
    );
    // `receive(SlaveTeam, SlaveTeam.COLOR)`: the range is the value received.
    assert_eq!((w.start, w.end), ((122, 22), (122, 37)));
}

#[test]
fn human_output_shows_the_source_line_and_a_summary() {
    let out = semo_in(
        &shared().join("examples/scouting"),
        &["check", "scouting.mission"],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.contains("[W004] Warning"), "{}", out.stdout);
    assert!(
        out.stdout.contains("receive(SlaveTeam, SlaveTeam.COLOR)"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("scouting.mission:122:22"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("checked 1 mission and 0 catalog files: 0 errors, 1 warning, 2 hints"),
        "{}",
        out.stdout
    );
    assert!(
        !out.stdout.contains("\u{1b}["),
        "NO_COLOR output has no escape codes"
    );
}

#[test]
fn colours_can_be_forced() {
    let out = semo_in(
        &shared().join("examples/scouting"),
        &["check", "--color", "always", "scouting.mission"],
    );
    assert!(out.stdout.contains("\u{1b}["), "{}", out.stdout);
}

#[test]
fn errors_exit_with_1_and_json_has_every_field() {
    let dir = tempdir();
    std::fs::write(
        dir.join("typo.mission"),
        "{ T: iRobotCreat a }\nT.Action.Go { move(\"1,1\") } repeat()\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n",
    )
    .unwrap();
    let out = semo_in(&dir, &["check", "--format", "json", "typo.mission"]);
    assert_eq!(out.code, 1);
    let line = out.stdout.lines().next().expect("one diagnostic");
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    assert_eq!(v["code"], "E010");
    assert_eq!(v["severity"], "error");
    assert_eq!(v["file"], "typo.mission");
    assert_eq!(v["start"], serde_json::json!({"line": 1, "column": 6}));
    assert_eq!(v["end"], serde_json::json!({"line": 1, "column": 17}));
    assert_eq!(v["suggestion"], "iRobotCreate");
    assert!(
        v["message"]
            .as_str()
            .unwrap()
            .contains("did you mean `iRobotCreate`?")
    );
}

#[test]
fn io_and_usage_problems_exit_with_2() {
    let missing = semo(&["check", "no/such/file.mission"]);
    assert_eq!(missing.code, 2);
    assert!(
        missing.stderr.contains("no/such/file.mission"),
        "{}",
        missing.stderr
    );
    let usage = semo(&["check", "--format", "yaml"]);
    assert_eq!(usage.code, 2);
    let unknown = semo(&["frobnicate"]);
    assert_eq!(unknown.code, 2);
}

#[test]
fn help_explains_the_commands() {
    let top = semo(&["--help"]);
    assert_eq!(top.code, 0);
    assert!(top.stdout.contains("check"), "{}", top.stdout);
    assert!(top.stdout.contains("Exit status"), "{}", top.stdout);
    let check = semo(&["check", "--help"]);
    assert_eq!(check.code, 0);
    assert!(check.stdout.contains("--format"), "{}", check.stdout);
    assert!(check.stdout.contains("*.robot.xml"), "{}", check.stdout);
}

#[test]
fn explain_describes_a_code() {
    let out = semo(&["explain", "E019"]);
    assert_eq!(out.code, 0);
    assert!(out.stdout.starts_with("E019 (error): "), "{}", out.stdout);
    assert_eq!(semo(&["explain", "X999"]).code, 2);
}

#[test]
fn folders_are_checked_recursively_with_their_catalog_files() {
    let dir = tempdir();
    std::fs::create_dir_all(dir.join("robots")).unwrap();
    std::fs::write(
        dir.join("robots/scout.robot.xml"),
        r#"<Catalog><Robot type="Scout"><Doc>A small scout.</Doc>
             <Value name="HEAT" type="int" doc="Heat level." task="heat"/>
             <Service name="sniff" task="nose" doc="Sniff around."/></Robot></Catalog>"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "{ T: Scout s }\nT.Action.Go { sniff() if (HEAT > 3) throw hot } repeat()\nT.Action.Rest { stop() }\n\
         T.GO { set(Action, Go) }\nT.REST { set(Action, Rest) }\nT.main { case (GO): catch (hot): mode = REST default: mode = GO }\n",
    )
    .unwrap();
    let (code, diags) = check_json_in(&dir, &["."]);
    assert_eq!(code, 1, "Scout has no `stop`: {diags:#?}");
    assert_eq!(diags.len(), 1, "{diags:#?}");
    // `stop` exists in the catalog, but not for the Scout type of this folder.
    assert_eq!(diags[0].code, "E019");
    assert!(
        diags[0]
            .message
            .contains("`stop` is not a service of Scout (s)"),
        "{}",
        diags[0].message
    );
}

#[test]
fn positions_count_characters_after_korean_and_emoji() {
    let dir = tempdir();
    let line = "T.Report.Say { if (COLOR == \"😀 안녕\") send(USER, COLOUR) } repeat(1 SEC)";
    std::fs::write(
        dir.join("u.mission"),
        format!(
            "# 한국어 주석: 팀 구성 🤖\n{{ T: TIEvalbot a }}\n{line}\nT.ON {{ set(Report, Say) }}\nT.main {{ default: mode = ON }}\n"
        ),
    )
    .unwrap();
    let (_, diags) = check_json_in(&dir, &["u.mission"]);
    let d = diags
        .iter()
        .find(|d| d.code == "W007")
        .expect("unknown attribute");
    // Columns are 1-based and count characters, not bytes or UTF-16 units.
    let column = line[..line.find("COLOUR").unwrap()].chars().count() as u64 + 1;
    let byte_column = line.find("COLOUR").unwrap() as u64 + 1;
    assert_ne!(
        column, byte_column,
        "the line must hold multi-byte characters"
    );
    assert_eq!((d.start, d.end), ((3, column), (3, column + 6)), "{d:#?}");
    assert_eq!(d.suggestion.as_deref(), Some("COLOR"));
}

/// A fresh empty folder under the target directory.
fn tempdir() -> std::path::PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "semo-cli-test-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn three_unrelated_syntax_errors_are_each_reported_and_the_rest_is_checked() {
    let dir = support::repo_root().join("tests/fixtures/recovery");
    let (code, diags) = check_json_in(&dir, &["three_syntax_errors.mission"]);
    assert_eq!(code, 1);
    let syntax: Vec<_> = diags
        .iter()
        .filter(|d| ["E001", "E002", "E003"].contains(&d.code.as_str()))
        .map(|d| (d.start.0, d.message.as_str()))
        .collect();
    assert_eq!(
        syntax,
        vec![
            (5, "this `(` is never closed"),
            (13, "expected `,`, found `Go`"),
            (18, "expected `:`, found `mode`"),
        ]
    );
    // The valid parts around them are still checked.
    let codes: Vec<&str> = diags.iter().map(|d| d.code.as_str()).collect();
    assert!(
        codes.contains(&"E021"),
        "unknown team in receive: {codes:?}"
    );
    assert!(
        codes.contains(&"E019"),
        "spin on an iRobotCreate: {codes:?}"
    );
}

#[test]
fn rejected_definitions_are_still_checked() {
    let dir = tempdir();
    std::fs::write(
        dir.join("dup.mission"),
        "{ T: iRobotCreate a }\nT.Action.Go { move(\"1,1\") } repeat()\nT.Action.Go { mvoe(\"1,1\") }\n\
         U.Action.X { stopp() }\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n",
    )
    .unwrap();
    let (_, diags) = check_json_in(&dir, &["dup.mission"]);
    let found: Vec<(&str, u64, Option<&str>)> = diags
        .iter()
        .map(|d| (d.code.as_str(), d.start.0, d.suggestion.as_deref()))
        .collect();
    assert_eq!(
        found,
        vec![
            ("E013", 3, None),
            ("E024", 3, Some("move")),
            ("E015", 4, None),
            ("E024", 4, Some("stop")),
        ]
    );
}

#[test]
fn strategy_files_are_checked_against_their_missions() {
    let out = semo_in(&shared().join("examples"), &["check", "scouting"]);
    assert_eq!(out.code, 0, "{}", out.stdout);
    assert!(
        out.stdout
            .contains("checked 1 mission and 0 catalog files, 1 strategy file: 0 errors"),
        "{}",
        out.stdout
    );
    assert!(
        semo(&["check", "--help"]).stdout.contains("*.strategy.xml"),
        "check --help names strategy files"
    );

    // A target robot outside the team: shown in the strategy file, with the
    // team's declaration in the mission beside it.
    let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
    let out = semo_in(&fixtures, &["check", "E090_strategy_robot_not_in_team"]);
    assert_eq!(out.code, 1, "{}", out.stdout);
    assert!(out.stdout.contains("[E090] Error"), "{}", out.stdout);
    assert!(
        out.stdout.contains("Scouts.strategy.xml:5:26"),
        "{}",
        out.stdout
    );
    assert!(out.stdout.contains("scouts.mission:3:3"), "{}", out.stdout);
    assert!(
        out.stdout.contains("team Scouts is declared here"),
        "{}",
        out.stdout
    );
    let json = semo_in(
        &fixtures,
        &[
            "check",
            "--format",
            "json",
            "E090_strategy_robot_not_in_team",
        ],
    );
    let v: serde_json::Value = serde_json::from_str(json.stdout.lines().next().unwrap()).unwrap();
    let related = &v["related"][0];
    assert!(
        related["file"]
            .as_str()
            .unwrap()
            .ends_with("scouts.mission"),
        "{v}"
    );
    assert_eq!(
        (related["line"].as_u64(), related["column"].as_u64()),
        (Some(3), Some(3))
    );

    // Named alone, a strategy file is checked against the catalog only.
    let (code, diags) = check_json_in(
        &fixtures,
        &["E090_strategy_robot_not_in_team/Scouts.strategy.xml"],
    );
    assert_eq!((code, diags.len()), (0, 0), "{diags:#?}");
}

#[test]
fn a_plain_lt_in_a_condition_points_at_the_lt_with_the_fix() {
    let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
    let out = semo_in(&fixtures, &["check", "E081_strategy_plain_lt"]);
    assert_eq!(out.code, 1, "{}", out.stdout);
    assert!(
        out.stdout.contains("Scouts.strategy.xml:25:40"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("did you mean `&lt;`?"),
        "{}",
        out.stdout
    );
    let (_, diags) = check_json_in(&fixtures, &["E081_strategy_plain_lt"]);
    assert!(diags.iter().all(|d| d.code == "E081"), "{diags:#?}");
    assert_eq!(diags[0].suggestion.as_deref(), Some("&lt;"));
    assert_eq!((diags[0].start, diags[0].end), ((25, 40), (25, 41)));
}
