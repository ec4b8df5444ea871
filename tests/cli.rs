//! The `semo` command as a user runs it: the reference examples, output formats,
//! exit codes, help, and positions with non-ASCII text.

mod support;

use support::{check_json_in, examples, semo, semo_in, semo_with_stdin};

#[test]
fn every_reference_example_checks_without_errors() {
    let examples = examples();
    for folder in ["scouting", "follow", "swarm"] {
        let (code, diags) = check_json_in(&examples, &[folder]);
        let errors: Vec<_> = diags.iter().filter(|d| d.severity == "error").collect();
        assert!(errors.is_empty(), "{folder}: {errors:#?}");
        assert_eq!(code, 0, "{folder} should exit 0");
    }
}

#[test]
fn scouting_gives_exactly_its_two_warnings() {
    let (_, diags) = check_json_in(&examples().join("scouting"), &["scouting.mission"]);
    let warnings: Vec<_> = diags.iter().filter(|d| d.severity != "hint").collect();
    assert_eq!(warnings.len(), 2, "{warnings:#?}");
    let w = warnings[1];
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
    assert_eq!((w.start, w.end), ((126, 22), (126, 37)));
    // The master forwards the operator's command to the slaves once, when
    // RC_MODE starts, while its plan Listen takes the next ones (issue 31's
    // first defect): `send(SlaveTeam, USER.RC_CMD)`, the value sent.
    let w = warnings[0];
    assert_eq!(w.code, "W023");
    assert!(
        w.message
            .contains("`MasterTeam.Listen.ReceiveCmd` keeps receiving it"),
        "{}",
        w.message
    );
    assert_eq!((w.start, w.end), ((36, 19), (36, 30)));
}

#[test]
fn human_output_shows_the_source_line_and_a_summary() {
    let out = semo_in(&examples().join("scouting"), &["check", "scouting.mission"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stderr.contains("[W004] Warning"), "{}", out.stderr);
    assert!(
        out.stderr.contains("receive(SlaveTeam, SlaveTeam.COLOR)"),
        "{}",
        out.stderr
    );
    assert!(
        out.stderr.contains("scouting.mission:126:22"),
        "{}",
        out.stderr
    );
    assert!(
        out.stderr.contains(
            "checked 1 mission and 0 catalog files, 1 strategy file: 0 errors, 2 warnings, 2 hints"
        ),
        "{}",
        out.stderr
    );
    assert!(
        !out.stderr.contains("\u{1b}["),
        "NO_COLOR output has no escape codes"
    );
}

#[test]
fn colours_can_be_forced() {
    let out = semo_in(
        &examples().join("scouting"),
        &["check", "--color", "always", "scouting.mission"],
    );
    assert!(out.stderr.contains("\u{1b}["), "{}", out.stderr);
}

#[test]
fn errors_exit_with_1_and_json_has_every_field() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("typo.mission"),
        "{ T: iRobotCreat a }\nT.Action.Go { move(\"1,1\") } repeat()\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n",
    )
    .unwrap();
    let out = semo_in(dir, &["check", "--format", "json", "typo.mission"]);
    assert_eq!(out.code, 1);
    let document: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let v = &document["diagnostics"][0];
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
    let fmt = semo(&["fmt", "--help"]);
    assert_eq!(fmt.code, 0);
    assert!(fmt.stdout.contains("--check"), "{}", fmt.stdout);
    assert!(fmt.stdout.contains("standard input"), "{}", fmt.stdout);
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
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
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
    let (code, diags) = check_json_in(dir, &["."]);
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
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let line = "T.Report.Say { if (COLOR == \"😀 안녕\") send(USER, COLOUR) } repeat(1 SEC)";
    std::fs::write(
        dir.join("u.mission"),
        format!(
            "# 한국어 주석: 팀 구성 🤖\n{{ T: TIEvalbot a }}\n{line}\nT.ON {{ set(Report, Say) }}\nT.main {{ default: mode = ON }}\n"
        ),
    )
    .unwrap();
    let (_, diags) = check_json_in(dir, &["u.mission"]);
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
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("dup.mission"),
        "{ T: iRobotCreate a }\nT.Action.Go { move(\"1,1\") } repeat()\nT.Action.Go { mvoe(\"1,1\") }\n\
         U.Action.X { stopp() }\nT.GO { set(Action, Go) }\nT.main { default: mode = GO }\n",
    )
    .unwrap();
    let (_, diags) = check_json_in(dir, &["dup.mission"]);
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

// ---- semo fmt ----

const UNFORMATTED: &str = "{ T: iRobotCreate a }\nT.Action.Go{move(\"1,1\") # go\n}repeat()\n\
                           T.GO{set(Action,Go)}\nT.main{default:mode=GO}\n";
const FORMATTED: &str = "{\n  T: iRobotCreate a\n}\n\nT.Action.Go {\n  move(\"1,1\") # go\n} repeat()\n\n\
                         T.GO {\n  set(Action, Go)\n}\n\nT.main {\n  default: mode = GO\n}\n";

fn read(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

/// The names in `dir`, sorted.
fn names(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn fmt_rewrites_only_the_missions_that_change_and_lists_them() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::write(dir.join("a.mission"), UNFORMATTED).unwrap();
    std::fs::write(dir.join("sub/b.mission"), UNFORMATTED).unwrap();
    std::fs::write(dir.join("c.mission"), FORMATTED).unwrap();
    std::fs::write(dir.join("robots.robot.xml"), "<robots>  </robots>").unwrap();
    std::fs::write(dir.join("notes.txt"), "T.A.S{x()}").unwrap();
    let out = semo_in(dir, &["fmt", "."]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(
        out.stdout,
        "formatted ./a.mission\nformatted ./sub/b.mission\n"
    );
    for file in ["a.mission", "sub/b.mission", "c.mission"] {
        assert_eq!(read(&dir.join(file)), FORMATTED, "{file}");
    }
    assert_eq!(read(&dir.join("robots.robot.xml")), "<robots>  </robots>");
    assert_eq!(read(&dir.join("notes.txt")), "T.A.S{x()}");
    // No temporary file is left behind.
    assert_eq!(
        names(dir),
        [
            "a.mission",
            "c.mission",
            "notes.txt",
            "robots.robot.xml",
            "sub"
        ]
    );
    assert_eq!(names(&dir.join("sub")), ["b.mission"]);
    // Without a path, the current folder; nothing is left to change.
    let again = semo_in(dir, &["fmt"]);
    assert_eq!((again.code, again.stdout.as_str()), (0, ""));
}

#[test]
fn fmt_check_lists_the_files_that_would_change_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("a.mission"), UNFORMATTED).unwrap();
    std::fs::write(dir.join("c.mission"), FORMATTED).unwrap();
    let out = semo_in(dir, &["fmt", "--check", "a.mission", "c.mission"]);
    assert_eq!((out.code, out.stdout.as_str()), (1, "a.mission\n"));
    assert_eq!(read(&dir.join("a.mission")), UNFORMATTED);
    assert_eq!(names(dir), ["a.mission", "c.mission"]);
    let out = semo_in(dir, &["fmt", "--check", "c.mission"]);
    assert_eq!((out.code, out.stdout.as_str()), (0, ""));
}

#[test]
fn fmt_diff_prints_a_patch_that_formats_the_file_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("a.mission"), UNFORMATTED).unwrap();
    std::fs::write(dir.join("c.mission"), FORMATTED).unwrap();
    let out = semo_in(dir, &["fmt", "--diff", "a.mission", "c.mission"]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(
        out.stdout
            .starts_with("--- a/a.mission\n+++ b/a.mission\n@@ "),
        "{}",
        out.stdout
    );
    assert!(!out.stdout.contains("c.mission"), "{}", out.stdout);
    assert_eq!(read(&dir.join("a.mission")), UNFORMATTED);
    assert_eq!(names(dir), ["a.mission", "c.mission"]);
    // The patch is the formatting: applied, the file is the formatted text.
    std::fs::write(dir.join("fmt.patch"), &out.stdout).unwrap();
    let applied = std::process::Command::new("git")
        .args(["apply", "fmt.patch"])
        .current_dir(dir)
        .output()
        .expect("git runs");
    assert!(applied.status.success(), "{applied:?}");
    assert_eq!(read(&dir.join("a.mission")), FORMATTED);
    let out = semo_in(dir, &["fmt", "--diff", "a.mission", "c.mission"]);
    assert_eq!((out.code, out.stdout.as_str()), (0, ""));
}

#[test]
fn fmt_leaves_a_file_with_syntax_errors_as_it_is_and_says_where() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let broken = "T.Action.Go {\n  move(\"1,1\"\n  stop()\n}\n  # keep   this\n";
    std::fs::write(dir.join("broken.mission"), broken).unwrap();
    std::fs::write(dir.join("fine.mission"), UNFORMATTED).unwrap();
    let out = semo_in(dir, &["fmt", "broken.mission", "fine.mission"]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(
        out.stderr.contains(
            "error: broken.mission:2:7: syntax error: this `(` is never closed; not formatted"
        ),
        "{}",
        out.stderr
    );
    assert_eq!(read(&dir.join("broken.mission")), broken);
    // The other files are formatted all the same.
    assert_eq!(out.stdout, "formatted fine.mission\n");
    assert_eq!(read(&dir.join("fine.mission")), FORMATTED);
}

#[test]
fn fmt_leaves_a_file_that_is_not_utf8_as_it_is() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let bytes = b"# caf\xe9\n{ T: iRobotCreate a }\n";
    std::fs::write(dir.join("latin1.mission"), bytes).unwrap();
    let out = semo_in(dir, &["fmt", "latin1.mission"]);
    assert_eq!(out.code, 1);
    assert!(
        out.stderr.contains("latin1.mission: not UTF-8 text"),
        "{}",
        out.stderr
    );
    assert_eq!(std::fs::read(dir.join("latin1.mission")).unwrap(), bytes);
}

#[test]
fn fmt_reads_standard_input_and_can_print_instead_of_writing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let out = semo_with_stdin(dir, &["fmt", "-"], UNFORMATTED);
    assert_eq!(
        (out.code, out.stdout.as_str()),
        (0, FORMATTED),
        "{}",
        out.stderr
    );
    let out = semo_with_stdin(dir, &["fmt", "--check", "-"], UNFORMATTED);
    assert_eq!((out.code, out.stdout.as_str()), (1, "<stdin>\n"));
    let out = semo_with_stdin(dir, &["fmt", "-"], "T.A.S { move( }");
    assert_eq!((out.code, out.stdout.as_str()), (1, ""));
    assert!(out.stderr.contains("<stdin>:1:13:"), "{}", out.stderr);

    std::fs::write(dir.join("a.mission"), UNFORMATTED).unwrap();
    let out = semo_in(dir, &["fmt", "--stdout", "a.mission"]);
    assert_eq!((out.code, out.stdout.as_str()), (0, FORMATTED));
    assert_eq!(read(&dir.join("a.mission")), UNFORMATTED);
}

#[test]
fn fmt_path_and_usage_problems_exit_with_2() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("robots.robot.xml"), "<robots/>").unwrap();
    let out = semo_in(dir, &["fmt", "missing.mission"]);
    assert_eq!(out.code, 2);
    assert!(out.stderr.contains("missing.mission"), "{}", out.stderr);
    let out = semo_in(dir, &["fmt", "robots.robot.xml"]);
    assert_eq!(out.code, 2);
    assert!(
        out.stderr.contains("not a mission script"),
        "{}",
        out.stderr
    );
    let out = semo_in(dir, &["fmt", "--check", "--stdout", "."]);
    assert_eq!(out.code, 2);
}

#[cfg(unix)]
#[test]
fn fmt_through_a_symbolic_link_rewrites_the_file_and_keeps_the_link() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/a.mission"), UNFORMATTED).unwrap();
    std::os::unix::fs::symlink("real/a.mission", dir.join("link.mission")).unwrap();
    let out = semo_in(dir, &["fmt", "link.mission"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        std::fs::symlink_metadata(dir.join("link.mission"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(read(&dir.join("real/a.mission")), FORMATTED);
    assert_eq!(names(&dir.join("real")), ["a.mission"]);
}

#[test]
fn fmt_does_not_replace_a_read_only_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let path = dir.join("locked.mission");
    std::fs::write(&path, UNFORMATTED).unwrap();
    let mut permissions = std::fs::metadata(&path).unwrap().permissions();
    permissions.set_readonly(true);
    std::fs::set_permissions(&path, permissions).unwrap();
    let out = semo_in(dir, &["fmt", "locked.mission"]);
    assert_eq!(out.code, 2);
    assert!(
        out.stderr
            .contains("locked.mission: cannot write the formatted text: the file is read-only"),
        "{}",
        out.stderr
    );
    assert_eq!(read(&path), UNFORMATTED);
    assert_eq!(names(dir), ["locked.mission"]);
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_dir(&path, &target);
        } else {
            std::fs::copy(&path, &target).unwrap();
            // The examples may be read-only; their copies are ours to change.
            let mut permissions = std::fs::metadata(&target).unwrap().permissions();
            #[allow(clippy::permissions_set_readonly_false)]
            permissions.set_readonly(false);
            std::fs::set_permissions(&target, permissions).unwrap();
        }
    }
}

#[test]
fn the_examples_are_formatted_and_formatting_changes_nothing_that_semo_check_finds() {
    let clean = semo_in(&examples(), &["fmt", "--check", "."]);
    assert_eq!(
        (clean.code, clean.stdout.as_str()),
        (0, ""),
        "{}",
        clean.stderr
    );
    // Each example with its indentation stripped: the same findings, and
    // `semo fmt` gives back the example exactly.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_dir(&examples(), &dir.join("examples"));
    let findings = || {
        let (code, diags) = check_json_in(dir, &["."]);
        let found: Vec<(String, String, String)> = diags
            .into_iter()
            .map(|d| (d.file, d.code, d.message))
            .collect();
        (code, found)
    };
    let before = findings();
    assert!(!before.1.is_empty());
    let missions: Vec<(std::path::PathBuf, String)> = walkdir::WalkDir::new(dir)
        .into_iter()
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x == "mission"))
        .map(|e| {
            let text = std::fs::read_to_string(e.path()).unwrap();
            (e.into_path(), text)
        })
        .collect();
    assert!(missions.len() >= 5, "{missions:?}");
    for (path, text) in &missions {
        let stripped: String = text
            .lines()
            .map(|l| format!("{}\n", l.trim_start()))
            .collect();
        assert_ne!(&stripped, text, "{}", path.display());
        std::fs::write(path, stripped).unwrap();
    }
    assert_eq!(findings(), before);
    let out = semo_in(dir, &["fmt", "."]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.contains("scouting.mission"), "{}", out.stdout);
    for (path, text) in &missions {
        assert_eq!(
            &std::fs::read_to_string(path).unwrap(),
            text,
            "{}",
            path.display()
        );
    }
}

#[test]
fn strategy_files_are_checked_against_their_missions() {
    let out = semo_in(&examples(), &["check", "scouting"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("checked 1 mission and 0 catalog files, 1 strategy file: 0 errors"),
        "{}",
        out.stderr
    );
    assert!(
        semo(&["check", "--help"]).stdout.contains("*.strategy.xml"),
        "check --help names strategy files"
    );

    // A target robot outside the team: shown in the strategy file, with the
    // team's declaration in the mission beside it.
    let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
    let out = semo_in(&fixtures, &["check", "E090_strategy_robot_not_in_team"]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(out.stderr.contains("[E090] Error"), "{}", out.stderr);
    assert!(
        out.stderr.contains("Scouts.strategy.xml:5:26"),
        "{}",
        out.stderr
    );
    assert!(out.stderr.contains("scouts.mission:3:3"), "{}", out.stderr);
    assert!(
        out.stderr.contains("team Scouts is declared here"),
        "{}",
        out.stderr
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
    let document: serde_json::Value = serde_json::from_str(&json.stdout).unwrap();
    let v = &document["diagnostics"][0];
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

    // Named alone, a strategy file is checked against the missions that see
    // it (those beside it), exactly as when its folder is checked.
    let (code, alone) = check_json_in(
        &fixtures,
        &["E090_strategy_robot_not_in_team/Scouts.strategy.xml"],
    );
    let (_, folder) = check_json_in(&fixtures, &["E090_strategy_robot_not_in_team"]);
    assert_eq!(code, 1);
    assert_eq!(support::listing(&alone), support::listing(&folder));
}

#[test]
fn a_plain_lt_in_a_condition_points_at_the_lt_with_the_fix() {
    let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
    let out = semo_in(&fixtures, &["check", "E081_strategy_plain_lt"]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(
        out.stderr.contains("Scouts.strategy.xml:25:40"),
        "{}",
        out.stderr
    );
    assert!(
        out.stderr.contains("did you mean `&lt;`?"),
        "{}",
        out.stderr
    );
    let (_, diags) = check_json_in(&fixtures, &["E081_strategy_plain_lt"]);
    assert!(diags.iter().all(|d| d.code == "E081"), "{diags:#?}");
    assert_eq!(diags[0].suggestion.as_deref(), Some("&lt;"));
    assert_eq!((diags[0].start, diags[0].end), ((25, 40), (25, 41)));
}
