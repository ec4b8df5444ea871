//! The command-line conventions users expect of a tool (issue 18, "CLI"),
//! each through the `semo` binary: `-` for standard input, `--deny
//! warnings`, colour by `--color` then `NO_COLOR`, `CLICOLOR_FORCE` and
//! `TERM=dumb`, hints called hints, one `-o/--output` meaning, `--help`
//! saying what the tool does, and a mission's terminal controls shown in
//! diagnostics, not obeyed.

mod support;

use std::process::Command;
use support::{repo_root, semo, semo_with_stdin};

fn fixture(name: &str) -> String {
    std::fs::read_to_string(repo_root().join("tests/fixtures/diagnostics").join(name)).unwrap()
}

#[test]
fn check_dash_reads_a_mission_from_standard_input() {
    let root = repo_root();
    let good = std::fs::read_to_string(root.join("examples/follow/follow.mission")).unwrap();
    let out = semo_with_stdin(&root, &["check", "-"], &good);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(out.stderr.contains("checked 1 mission"), "{}", out.stderr);

    let bad = fixture("E015_unknown_team.mission");
    let out = semo_with_stdin(&root, &["check", "--format", "json", "-"], &bad);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    let diags = support::parse_json_report(&out.stdout);
    assert!(
        diags
            .iter()
            .any(|d| d.code == "E015" && d.file == "<stdin>"),
        "{}",
        support::listing(&diags)
    );
    // `-` stands alone: mixed with paths it is a usage error.
    let out = semo_with_stdin(&root, &["check", "-", "examples"], &good);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("standard input"), "{}", out.stderr);
}

#[test]
fn deny_warnings_makes_a_warning_fail_the_check() {
    let root = repo_root();
    let warned = fixture("W011_team_without_main.mission");
    let out = semo_with_stdin(&root, &["check", "-"], &warned);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stderr.contains("W011"), "{}", out.stderr);
    let out = semo_with_stdin(&root, &["check", "--deny", "warnings", "-"], &warned);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(
        out.stderr.contains("denied by --deny warnings"),
        "{}",
        out.stderr
    );
    // Nothing to deny: still 0.
    let good = std::fs::read_to_string(root.join("examples/follow/follow.mission")).unwrap();
    let out = semo_with_stdin(&root, &["check", "--deny", "warnings", "-"], &good);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
}

#[test]
fn hints_are_called_hints() {
    let out = semo_with_stdin(
        &repo_root(),
        &["check", "-"],
        &fixture("W009_catch_never_thrown.mission"),
    );
    assert!(out.stderr.contains("[W009] Hint:"), "{}", out.stderr);
    assert!(!out.stderr.contains("Advice"), "{}", out.stderr);
    // Without colour, not a single escape sequence, the hint's header too.
    assert!(!out.stderr.contains('\u{1b}'), "{:?}", out.stderr);
}

/// A mission's text quoted in a diagnostic is shown, never obeyed: the
/// terminal controls in a line (an escape sequence setting the window's
/// title, a carriage return hiding what came before it) come out as their
/// control pictures, and a line too long to quote (a file of 400,000 NULs
/// printed 2.8 MB for one error) gets the one-line form and a note.
#[test]
fn a_missions_terminal_controls_are_shown_and_its_long_lines_not_quoted() {
    let root = repo_root();
    let mission =
        "{\n  R: iRobotCreate r\n}\nR.A.S { mvoe(\"1,1\") } # \u{1b}]0;PWNED\u{7} \rhidden\n";
    for format in ["human", "concise"] {
        let out = semo_with_stdin(&root, &["check", "--format", format, "-"], mission);
        assert_eq!(out.code, 1, "{}", out.stderr);
        assert!(out.stderr.contains("E024"), "{}", out.stderr);
        assert!(
            !out.stderr.contains(['\u{1b}', '\u{7}', '\r']),
            "{format}: {:?}",
            out.stderr
        );
    }
    let out = semo_with_stdin(&root, &["check", "-"], mission);
    assert!(
        out.stderr.contains("# ␛]0;PWNED␇ ␍hidden"),
        "{}",
        out.stderr
    );

    let junk = "\0".repeat(400_000);
    let out = semo_with_stdin(&root, &["check", "-"], &junk);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(
        out.stderr.contains("E001")
            && out
                .stderr
                .contains("(line 1 is 400000 bytes long: no snippet)"),
        "{}",
        out.stderr
    );
    assert!(out.stderr.len() < 2_000, "{} bytes", out.stderr.len());
}

/// `semo check` of a mission with an error, its output not a terminal, in
/// the environment `env` (nothing else inherited that concerns colour).
fn coloured(args: &[&str], env: &[(&str, &str)]) -> bool {
    let mission = repo_root().join("tests/fixtures/diagnostics/E015_unknown_team.mission");
    let mut command = Command::new(env!("CARGO_BIN_EXE_semo"));
    command
        .arg("check")
        .args(args)
        .arg(&mission)
        .env_remove("NO_COLOR")
        .env_remove("CLICOLOR_FORCE")
        .env_remove("TERM");
    for (k, v) in env {
        command.env(k, v);
    }
    let out = command.output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    out.stderr.contains(&0x1b)
}

#[test]
fn colour_follows_the_flag_then_no_color_clicolor_force_and_term() {
    // Not a terminal: plain, unless forced.
    assert!(!coloured(&[], &[]));
    assert!(coloured(&[], &[("CLICOLOR_FORCE", "1")]));
    assert!(!coloured(&[], &[("CLICOLOR_FORCE", "0")]));
    assert!(coloured(&[], &[("CLICOLOR_FORCE", "1"), ("TERM", "dumb")]));
    // NO_COLOR wins over CLICOLOR_FORCE; an empty NO_COLOR is not set.
    assert!(!coloured(
        &[],
        &[("CLICOLOR_FORCE", "1"), ("NO_COLOR", "1")]
    ));
    assert!(coloured(&[], &[("CLICOLOR_FORCE", "1"), ("NO_COLOR", "")]));
    // The flag wins over everything.
    assert!(coloured(&["--color", "always"], &[("NO_COLOR", "1")]));
    assert!(!coloured(&["--color", "never"], &[("CLICOLOR_FORCE", "1")]));
}

#[test]
fn help_says_what_the_tool_does_now() {
    let out = semo(&["--help"]);
    assert_eq!(out.code, 0);
    assert!(!out.stdout.contains("will "), "{}", out.stdout);
    for command in [
        "semo build",
        "semo simulate",
        "semo check",
        "semo lsp",
        "NO_COLOR",
    ] {
        assert!(out.stdout.contains(command), "{command}: {}", out.stdout);
    }
}

#[test]
fn dash_o_and_output_mean_the_output_everywhere() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_conventions_output");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mission = dir.join("follow.mission");
    std::fs::copy(repo_root().join("examples/follow/follow.mission"), &mission).unwrap();
    let mission = mission.display().to_string();
    for (flag, folder) in [("-o", "a"), ("--output", "b"), ("--out", "c")] {
        let out = dir.join(folder).display().to_string();
        let run = semo(&["build", &mission, flag, &out, "--emit", "taskgraph"]);
        assert_eq!(run.code, 0, "{flag}: {}{}", run.stdout, run.stderr);
        assert!(dir.join(folder).join("Team1").is_dir(), "{flag}");
    }
    let svg = dir.join("modes.svg");
    for flag in ["-o", "--output"] {
        let _ = std::fs::remove_file(&svg);
        let run = semo(&["graph", "modes", &mission, flag, &svg.display().to_string()]);
        assert_eq!(run.code, 0, "{flag}: {}", run.stderr);
        assert!(
            std::fs::read_to_string(&svg).unwrap().contains("<svg"),
            "{flag}"
        );
    }
    // The help names one meaning.
    let help = semo(&["build", "--help"]).stdout;
    assert!(help.contains("-o, --output <OUT>"), "{help}");
}

/// A scratch folder for one test, emptied first.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_conventions")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn path_str(path: &std::path::Path) -> String {
    path.display().to_string()
}

fn example(path: &str) -> String {
    path_str(&repo_root().join("examples").join(path))
}

fn fixture_path(name: &str) -> String {
    path_str(&repo_root().join("tests/fixtures/diagnostics").join(name))
}

/// A scenario that runs follow.mission for a second.
const SHORT_SCENARIO: &str = "{\"duration\": 1000}\n";

#[test]
fn diagnostics_go_to_stderr_and_data_to_stdout_in_every_command() {
    let dir = scratch("streams");
    // check: the whole report for people is diagnostics.
    let out = semo(&["check", &fixture_path("E015_unknown_team.mission")]);
    assert_eq!(out.code, 1);
    assert_eq!(out.stdout, "");
    assert!(out.stderr.contains("[E015] Error"), "{}", out.stderr);
    assert!(out.stderr.contains("checked 1 mission"), "{}", out.stderr);
    // graph analyze: the errors on stderr, the analysis on stdout.
    let out = semo(&[
        "graph",
        "analyze",
        &example("taskgraphs/deadlock.taskgraph.xml"),
    ]);
    assert_eq!(out.code, 1);
    assert!(out.stderr.contains("[E071] Error"), "{}", out.stderr);
    assert!(!out.stdout.contains("E071"), "{}", out.stdout);
    assert!(out.stdout.contains("deadlocks"), "{}", out.stdout);
    // graph modes: the picture on stdout, the mission's errors on stderr.
    let out = semo(&["graph", "modes", &fixture_path("E017_unknown_mode.mission")]);
    assert_eq!(out.code, 1);
    assert!(out.stdout.starts_with("<svg"), "{}", out.stdout);
    assert!(out.stderr.contains("[E017] Error"), "{}", out.stderr);
    // graph dot: a graph that does not load prints no picture.
    let broken = dir.join("broken.taskgraph.xml");
    std::fs::write(
        &broken,
        "<TaskGraph name=\"g\" xmlns=\"urn:semo:taskgraph:1\">\n  <Task/>\n</TaskGraph>\n",
    )
    .unwrap();
    let out = semo(&["graph", "dot", &path_str(&broken)]);
    assert_eq!(out.code, 1);
    assert_eq!(out.stdout, "");
    assert!(out.stderr.contains("[E062] Error"), "{}", out.stderr);
    // build: what was written on stdout; a refusal and its reasons on stderr.
    let mission = dir.join("bad.mission");
    std::fs::copy(
        repo_root().join("tests/fixtures/diagnostics/E015_unknown_team.mission"),
        &mission,
    )
    .unwrap();
    let out = semo(&[
        "build",
        &path_str(&mission),
        "-o",
        &path_str(&dir.join("out")),
    ]);
    assert_eq!(out.code, 1);
    assert_eq!(out.stdout, "");
    assert!(out.stderr.contains("[E015] Error"), "{}", out.stderr);
    assert!(out.stderr.contains("refused"), "{}", out.stderr);
    let out = semo(&[
        "build",
        &example("follow/follow.mission"),
        "-o",
        &path_str(&dir.join("out")),
        "--emit",
        "taskgraph",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.contains("built 1 robot(s)"), "{}", out.stdout);
    // simulate: a mission with errors is reported on stderr.
    let scenario = dir.join("s.scenario.json");
    std::fs::write(&scenario, SHORT_SCENARIO).unwrap();
    let out = semo(&[
        "simulate",
        &path_str(&mission),
        "--scenario",
        &path_str(&scenario),
    ]);
    assert_eq!(out.code, 2);
    assert_eq!(out.stdout, "");
    assert!(out.stderr.contains("[E015] Error"), "{}", out.stderr);
}

/// One diagnostic of any command's JSON document, with exactly the fields
/// docs/diagnostics-json.md lists.
#[derive(serde::Deserialize, Debug)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct JsonDiagnostic {
    code: Option<String>,
    severity: String,
    file: String,
    start: JsonPosition,
    end: JsonPosition,
    message: String,
    suggestion: Option<String>,
    related: Vec<JsonRelated>,
}

#[derive(serde::Deserialize, Debug)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct JsonPosition {
    line: u32,
    column: u32,
}

#[derive(serde::Deserialize, Debug)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct JsonRelated {
    file: String,
    line: u32,
    column: u32,
    message: String,
}

/// A command's `--format json` output as the one document shape: its
/// version, its command, its diagnostics (each in the one shape).
fn document(stdout: &str, command: &str) -> (serde_json::Value, Vec<JsonDiagnostic>) {
    assert_eq!(
        stdout.lines().count(),
        1,
        "one document on one line: {stdout}"
    );
    let value: serde_json::Value = serde_json::from_str(stdout).expect(stdout);
    assert_eq!(value["version"], 1, "{value}");
    assert_eq!(value["command"], command, "{value}");
    let diagnostics: Vec<JsonDiagnostic> =
        serde_json::from_value(value["diagnostics"].clone()).expect("the one diagnostic shape");
    (value, diagnostics)
}

#[test]
fn every_commands_json_is_one_document_with_one_diagnostic_shape() {
    let dir = scratch("json");
    let codes =
        |d: &[JsonDiagnostic]| -> Vec<String> { d.iter().filter_map(|d| d.code.clone()).collect() };
    // check, with a related location.
    let out = semo(&[
        "check",
        "--format",
        "json",
        &fixture_path("E090_strategy_robot_not_in_team"),
    ]);
    assert_eq!(out.code, 1);
    let (_, diags) = document(&out.stdout, "check");
    assert!(codes(&diags).contains(&"E090".to_string()));
    assert!(diags.iter().any(|d| !d.related.is_empty()));
    // build, refused, then done.
    let mission = dir.join("bad.mission");
    std::fs::copy(
        repo_root().join("tests/fixtures/diagnostics/E015_unknown_team.mission"),
        &mission,
    )
    .unwrap();
    let out_dir = path_str(&dir.join("out"));
    let out = semo(&[
        "build",
        "--format",
        "json",
        &path_str(&mission),
        "-o",
        &out_dir,
    ]);
    assert_eq!(out.code, 1);
    let (value, diags) = document(&out.stdout, "build");
    assert!(codes(&diags).contains(&"E015".to_string()));
    assert_eq!(value["robots"], serde_json::json!([]));
    let out = semo(&[
        "build",
        "--format",
        "json",
        &example("follow/follow.mission"),
        "-o",
        &out_dir,
        "--emit",
        "taskgraph",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let (value, diags) = document(&out.stdout, "build");
    assert!(diags.is_empty());
    assert_eq!(value["robots"][0]["robot"], "create1");
    // graph analyze and graph buffers, on a graph with an error.
    let deadlock = example("taskgraphs/deadlock.taskgraph.xml");
    let out = semo(&["graph", "analyze", "--format", "json", &deadlock]);
    assert_eq!(out.code, 1);
    let (value, diags) = document(&out.stdout, "graph analyze");
    assert!(codes(&diags).contains(&"E071".to_string()));
    assert!(value["levels"].is_array());
    let out = semo(&["graph", "buffers", "--format", "json", &deadlock]);
    assert_eq!(out.code, 1);
    let (_, diags) = document(&out.stdout, "graph buffers");
    assert!(codes(&diags).contains(&"E071".to_string()));
    // simulate: a mission with errors, a bad scenario (no code), a run.
    let scenario = dir.join("s.scenario.json");
    std::fs::write(&scenario, SHORT_SCENARIO).unwrap();
    let scenario = path_str(&scenario);
    let out = semo(&[
        "simulate",
        "--format",
        "json",
        &path_str(&mission),
        "--scenario",
        &scenario,
    ]);
    assert_eq!(out.code, 2);
    let (_, diags) = document(&out.stdout, "simulate");
    assert!(codes(&diags).contains(&"E015".to_string()));
    let bad = dir.join("bad.scenario.json");
    std::fs::write(&bad, "{\"duration\": 100,}").unwrap();
    let follow = example("follow/follow.mission");
    let out = semo(&[
        "simulate",
        "--format",
        "json",
        &follow,
        "--scenario",
        &path_str(&bad),
    ]);
    assert_eq!(out.code, 2);
    let (_, diags) = document(&out.stdout, "simulate");
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, None);
    assert_eq!((diags[0].start.line, diags[0].start.column), (1, 18));
    let out = semo(&[
        "simulate",
        "--format",
        "json",
        &follow,
        "--scenario",
        &scenario,
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let (value, diags) = document(&out.stdout, "simulate");
    assert!(diags.is_empty());
    assert_eq!(value["ok"], true);
    // catalog: the built-in types (no catalog file in the folder).
    let out = support::semo_in(&dir, &["catalog", "--format", "json"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let (value, diags) = document(&out.stdout, "catalog");
    assert!(diags.is_empty(), "{diags:?}");
    assert_eq!(value["robots"][0]["name"], "iRobotCreate");
    // ... and a refusal is its document's one diagnostic.
    let out = support::semo_in(&dir, &["catalog", "NoSuchType", "--format", "json"]);
    assert_eq!(out.code, 2);
    let (_, diags) = document(&out.stdout, "catalog");
    assert_eq!(diags.len(), 1);
}

/// The official SARIF 2.1.0 schema (tests/data/sarif/README.md says where
/// it comes from), compiled once per test.
fn sarif_validator() -> jsonschema::Validator {
    let text =
        std::fs::read_to_string(repo_root().join("tests/data/sarif/sarif-schema-2.1.0.json"))
            .unwrap();
    let schema: serde_json::Value = serde_json::from_str(&text).unwrap();
    // The schema is a draft-04 one; formats (`uri-reference`, …) checked.
    jsonschema::draft4::options()
        .should_validate_formats(true)
        .build(&schema)
        .expect("the SARIF schema compiles")
}

fn valid_sarif(validator: &jsonschema::Validator, stdout: &str) -> serde_json::Value {
    let log: serde_json::Value = serde_json::from_str(stdout).expect(stdout);
    let errors: Vec<String> = validator
        .iter_errors(&log)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(errors.is_empty(), "{errors:#?}\n{log:#}");
    log
}

#[test]
fn sarif_output_validates_against_the_official_schema() {
    let validator = sarif_validator();
    // The schema is not a rubber stamp: a log without its version fails.
    assert!(!validator.is_valid(&serde_json::json!({"runs": []})));
    let results = |log: &serde_json::Value| log["runs"][0]["results"].as_array().unwrap().clone();

    // Errors, warnings and hints, with related locations, in several files.
    let fixtures = repo_root().join("tests/fixtures/diagnostics");
    let args = [
        "E090_strategy_robot_not_in_team",
        "W009_catch_never_thrown.mission",
        "E010_unknown_robot_type.mission",
    ];
    let mut command = vec!["check", "--format", "sarif"];
    command.extend(args);
    let out = semo_in_dir(&fixtures, &command);
    assert_eq!(out.code, 1, "{}", out.stderr);
    let log = valid_sarif(&validator, &out.stdout);
    let mut json_command = vec!["check", "--format", "json"];
    json_command.extend(args);
    let json = semo_in_dir(&fixtures, &json_command);
    let (_, diags) = document(&json.stdout, "check");
    // The same findings as the JSON document, in the same order.
    let found: Vec<(String, String, u64)> = results(&log)
        .iter()
        .map(|r| {
            (
                r["ruleId"].as_str().unwrap().to_string(),
                r["level"].as_str().unwrap().to_string(),
                r["locations"][0]["physicalLocation"]["region"]["startLine"]
                    .as_u64()
                    .unwrap(),
            )
        })
        .collect();
    let expected: Vec<(String, String, u64)> = diags
        .iter()
        .map(|d| {
            let level = match d.severity.as_str() {
                "hint" => "note",
                other => other,
            };
            (
                d.code.clone().unwrap(),
                level.to_string(),
                d.start.line as u64,
            )
        })
        .collect();
    assert_eq!(found, expected);
    assert!(found.iter().any(|(_, level, _)| level == "note"));
    assert!(
        results(&log)
            .iter()
            .any(|r| r["relatedLocations"].is_array())
    );
    let rules = log["runs"][0]["tool"]["driver"]["rules"]
        .as_array()
        .unwrap();
    assert!(rules.iter().any(|r| r["id"] == "E090"));

    // Standard input (`<stdin>` is not a URI as it stands) and absolute paths.
    let out = semo_with_stdin(
        &repo_root(),
        &["check", "--format", "sarif", "-"],
        &fixture("E015_unknown_team.mission"),
    );
    assert_eq!(out.code, 1);
    let log = valid_sarif(&validator, &out.stdout);
    assert_eq!(
        results(&log)[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
        "%3Cstdin%3E"
    );
    let out = semo(&[
        "graph",
        "analyze",
        "--format",
        "sarif",
        &example("taskgraphs/deadlock.taskgraph.xml"),
    ]);
    assert_eq!(out.code, 1);
    let log = valid_sarif(&validator, &out.stdout);
    let uri = results(&log)[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(uri.starts_with("file:///"), "{uri}");
    // A clean build: a valid log with no results.
    let dir = scratch("sarif");
    let out = semo(&[
        "build",
        "--format",
        "sarif",
        &example("follow/follow.mission"),
        "-o",
        &path_str(&dir.join("out")),
        "--emit",
        "taskgraph",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(results(&valid_sarif(&validator, &out.stdout)).is_empty());
}

fn semo_in_dir(dir: &std::path::Path, args: &[&str]) -> support::Output {
    support::semo_in(dir, args)
}

#[test]
fn every_file_argument_accepts_dash_for_standard_input() {
    let root = repo_root();
    let graph =
        std::fs::read_to_string(root.join("examples/taskgraphs/consistent.taskgraph.xml")).unwrap();
    let from_file = semo(&[
        "graph",
        "analyze",
        "examples/taskgraphs/consistent.taskgraph.xml",
    ]);
    let from_stdin = semo_with_stdin(&root, &["graph", "analyze", "-"], &graph);
    assert_eq!(from_stdin.code, 0, "{}", from_stdin.stderr);
    assert_eq!(from_stdin.stdout, from_file.stdout);
    for command in [
        &["graph", "dot", "-"][..],
        &["graph", "svg", "-"],
        &["graph", "schedule", "-"],
        &["graph", "buffers", "-"],
    ] {
        let file: Vec<&str> = command[..2]
            .iter()
            .copied()
            .chain(["examples/taskgraphs/consistent.taskgraph.xml"])
            .collect();
        let expected = semo(&file);
        let out = semo_with_stdin(&root, command, &graph);
        assert_eq!(out.code, 0, "{command:?}: {}", out.stderr);
        assert!(!out.stdout.is_empty(), "{command:?}");
        assert_eq!(out.stdout, expected.stdout, "{command:?}");
    }
    let tasks = ["--from", "A", "--to", "D"];
    let file = [
        "graph",
        "latency",
        "examples/taskgraphs/consistent.taskgraph.xml",
    ];
    let expected = semo(&[&file[..], &tasks].concat());
    let out = semo_with_stdin(
        &root,
        &[&["graph", "latency", "-"][..], &tasks].concat(),
        &graph,
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.contains("minimal latency: 0"), "{}", out.stdout);
    assert_eq!(out.stdout, expected.stdout);
    // A graph's diagnostics name standard input.
    let out = semo_with_stdin(
        &root,
        &["graph", "analyze", "--format", "json", "-"],
        "<TaskGraph name=\"g\" xmlns=\"urn:semo:taskgraph:1\">\n  <Task/>\n</TaskGraph>\n",
    );
    assert_eq!(out.code, 1);
    let (_, diags) = document(&out.stdout, "graph analyze");
    assert!(diags.iter().all(|d| d.file == "<stdin>"), "{diags:?}");

    let mission = std::fs::read_to_string(root.join("examples/follow/follow.mission")).unwrap();
    let out = semo_with_stdin(&root, &["graph", "modes", "-"], &mission);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.contains("AUTO_MODE"), "{}", out.stdout);

    // simulate: the mission or the scenario from standard input.
    let dir = scratch("stdin");
    let scenario = dir.join("s.scenario.json");
    std::fs::write(&scenario, SHORT_SCENARIO).unwrap();
    let from_file = semo(&[
        "simulate",
        "examples/follow/follow.mission",
        "--scenario",
        &path_str(&scenario),
    ]);
    assert_eq!(from_file.code, 0, "{}", from_file.stderr);
    let out = semo_with_stdin(
        &root,
        &[
            "simulate",
            "examples/follow/follow.mission",
            "--scenario",
            "-",
        ],
        SHORT_SCENARIO,
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout, from_file.stdout);

    // build and simulate read the mission's folder: one line says so.
    let out_dir = path_str(&dir.join("out"));
    for command in [
        &["build", "-", "-o", &out_dir][..],
        &["simulate", "-", "--scenario", &path_str(&scenario)],
    ] {
        let out = semo_with_stdin(&root, command, &mission);
        assert_eq!(out.code, 2, "{command:?}");
        assert_eq!(out.stdout, "", "{command:?}");
        assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
        assert!(out.stderr.contains("mission's folder"), "{}", out.stderr);
    }
    assert!(!dir.join("out").exists());
    // Nor can a strategy file, seen by its path, be standard input.
    let out = semo(&[
        "build",
        "examples/follow/follow.mission",
        "--strategy",
        "-",
        "-o",
        &out_dir,
    ]);
    assert_eq!(out.code, 2);
    assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
    assert!(!dir.join("out").exists());
    // A picture's `-o -` is standard output.
    let out = semo(&[
        "graph",
        "modes",
        "examples/follow/follow.mission",
        "-o",
        "-",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.starts_with("<svg"), "{}", out.stdout);
    assert!(!repo_root().join("-").exists());
    // build's compiled-in scenario from standard input: a mistake in it is
    // positioned at `<stdin>`, and nothing is written.
    let out = semo_with_stdin(
        &root,
        &[
            "build",
            "examples/follow/follow.mission",
            "--target",
            "cortex-m-sim",
            "--scenario",
            "-",
            "-o",
            &out_dir,
        ],
        "{\"duration\": 100,}",
    );
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("scenario <stdin>:1:18:"),
        "{}",
        out.stderr
    );
    assert!(!dir.join("out").exists());
}

/// `semo ARGS` refuses a file of the wrong kind: exit 2, one line on
/// stderr naming what the file is and what was wanted, nothing on stdout.
fn refused(args: &[&str], is: &str, wanted: &str) {
    let out = semo(args);
    assert_eq!(out.code, 2, "{args:?}: {}{}", out.stdout, out.stderr);
    assert_eq!(out.stdout, "", "{args:?}");
    assert_eq!(out.stderr.lines().count(), 1, "{args:?}: {}", out.stderr);
    assert!(
        out.stderr.contains(&format!("is {is}, not {wanted}")),
        "{args:?}: {}",
        out.stderr
    );
}

#[test]
fn a_file_of_the_wrong_kind_is_refused_in_one_line_and_nothing_is_written() {
    let dir = scratch("wrong_kind");
    let graph = example("taskgraphs/kmeans.taskgraph.xml");
    let mission = example("follow/follow.mission");
    let catalog = example("patrol/robots/beacon.robot.xml");
    let strategy = example("scouting/MasterTeam.strategy.xml");
    let svg = dir.join("modes.svg");
    refused(
        &["graph", "modes", &graph, "-o", &path_str(&svg)],
        "a task graph",
        "a mission script",
    );
    assert!(!svg.exists());
    for command in ["analyze", "dot", "svg", "schedule", "buffers"] {
        refused(
            &["graph", command, &mission],
            "a mission script",
            "a task graph",
        );
    }
    refused(
        &["graph", "latency", &mission, "--from", "A", "--to", "B"],
        "a mission script",
        "a task graph",
    );
    refused(
        &["graph", "analyze", &strategy],
        "a strategy file",
        "a task graph",
    );
    let out = dir.join("out");
    refused(
        &["build", &catalog, "-o", &path_str(&out)],
        "a robot catalog",
        "a mission script",
    );
    assert!(!out.exists());
    // A mission given as the scenario.
    let trace = dir.join("trace.jsonl");
    refused(
        &[
            "simulate",
            &mission,
            "--scenario",
            &mission,
            "--trace",
            &path_str(&trace),
        ],
        "a mission script",
        "a scenario (JSON)",
    );
    assert!(!trace.exists());
    refused(
        &["simulate", &graph, "--scenario", &mission],
        "a task graph",
        "a mission script",
    );
    // `semo check` knows a file by its name: a name that lies is refused.
    let lying = dir.join("graph.mission");
    std::fs::copy(
        repo_root().join("examples/taskgraphs/kmeans.taskgraph.xml"),
        &lying,
    )
    .unwrap();
    let out = semo(&["check", &path_str(&lying)]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("is a task graph, but its name makes it a mission script"),
        "{}",
        out.stderr
    );
    // XML of no known kind where XML is wanted is left to the reader, which
    // points at the root element.
    let odd = dir.join("odd.taskgraph.xml");
    std::fs::write(&odd, "<TaskGrap name=\"g\"/>\n").unwrap();
    let out = semo(&["graph", "analyze", &path_str(&odd)]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(out.stderr.contains("[E061]"), "{}", out.stderr);
}

#[test]
fn check_watch_checks_again_only_when_a_file_changes() {
    use std::io::BufRead;
    use std::process::Stdio;
    use std::time::Duration;
    let dir = scratch("watch");
    let mission = dir.join("m.mission");
    std::fs::copy(repo_root().join("examples/follow/follow.mission"), &mission).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(["check", "--watch", "--format", "json"])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let (lines, reports) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stdout).lines() {
            if lines.send(line.unwrap()).is_err() {
                break;
            }
        }
    });
    // Generous: the machine may be busy; this waits, it measures nothing.
    let next = || reports.recv_timeout(Duration::from_secs(120));
    let first = next().expect("the first report");
    let (_, diags) = document(&first, "check");
    assert!(diags.is_empty(), "{diags:?}");
    // Reading the files is no change (the check reads them too): spread
    // over a second, so that a watcher taking reads for changes would have
    // checked again before the change below. What is asserted is the
    // number of reports, not a time.
    for _ in 0..5 {
        std::fs::read_to_string(&mission).unwrap();
        std::fs::read_dir(&dir).unwrap().for_each(drop);
        std::thread::sleep(Duration::from_millis(200));
    }
    // One change, made as editors save: written aside, renamed over.
    let aside = dir.join("m.mission.new");
    std::fs::write(&aside, fixture("E015_unknown_team.mission")).unwrap();
    std::fs::rename(&aside, &mission).unwrap();
    let second = next().expect("a report after the change");
    child.kill().unwrap();
    child.wait().unwrap();
    let after: Vec<String> = reports.iter().collect();
    assert!(after.is_empty(), "checked again with no change: {after:?}");
    let (_, diags) = document(&second, "check");
    assert!(
        diags.iter().any(|d| d.code.as_deref() == Some("E015")),
        "the report after the first one is not the change's: the reads were checked again: \
         {diags:?}"
    );
}

/// One example of an explanation: its files (name, text) and the command
/// it is checked with (`semo check` when it names none).
#[derive(Default, Clone)]
struct Example {
    files: Vec<(String, String)>,
    command: Option<Vec<String>>,
}

/// The `## Wrong` and `## Right` examples of `semo explain CODE`'s text:
/// fenced blocks named by their file, and an optional `$ semo …` line.
fn examples(text: &str) -> (Example, Example) {
    let (mut wrong, mut right) = (Example::default(), Example::default());
    let mut section: Option<&mut Example> = None;
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line == "## Wrong" {
            section = Some(&mut wrong);
        } else if line == "## Right" {
            section = Some(&mut right);
        } else if let Some(example) = section.as_deref_mut() {
            if let Some(command) = line.strip_prefix("$ semo ") {
                example.command = Some(command.split(' ').map(str::to_string).collect());
            } else if let Some(name) = line.strip_prefix("```").filter(|n| !n.is_empty()) {
                let body: Vec<&str> = lines.by_ref().take_while(|l| *l != "```").collect();
                example
                    .files
                    .push((name.to_string(), body.join("\n") + "\n"));
            }
        }
    }
    (wrong, right)
}

/// The codes an example's files give through the binary, in a fresh folder
/// that also holds `crowd` empty files in `big/crowd/` (an example cannot
/// show the thousands of files that make a folder too big to search).
fn codes_of(dir: &std::path::Path, example: &Example, crowd: usize) -> Vec<String> {
    let _ = std::fs::remove_dir_all(dir);
    if crowd > 0 {
        let folder = dir.join("big/crowd");
        std::fs::create_dir_all(&folder).unwrap();
        for i in 0..crowd {
            std::fs::write(folder.join(format!("f{i}")), "").unwrap();
        }
    }
    for (name, text) in &example.files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    let out_dir = path_str(&dir.join("out"));
    let args: Vec<String> = match &example.command {
        None => ["check", "--format", "json", "."]
            .map(String::from)
            .to_vec(),
        Some(command) => {
            let mut args = command.clone();
            args.extend(["--format", "json"].map(String::from));
            // Only commands that write take an output folder.
            if args[0] == "build" {
                args.extend(["-o", &out_dir].map(String::from));
            }
            args
        }
    };
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = support::semo_in(dir, &args);
    assert!(out.code <= 1, "{args:?}: {}{}", out.stdout, out.stderr);
    let (_, diags) = document(&out.stdout, args[0]);
    diags.into_iter().filter_map(|d| d.code).collect()
}

#[test]
fn explain_gives_every_code_a_wrong_example_that_has_it_and_a_right_one_that_does_not() {
    let scratch = scratch("explain");
    for code in semo::diag::Code::ALL {
        let code = code.as_str();
        let out = semo(&["explain", code]);
        assert_eq!(out.code, 0, "{code}");
        assert!(
            out.stdout.starts_with(&format!("{code} (")),
            "{}",
            out.stdout
        );
        let (wrong, mut right) = examples(&out.stdout);
        assert!(!wrong.files.is_empty(), "{code}: no wrong example");
        assert!(!right.files.is_empty(), "{code}: no right example");
        // The right example shows the files it changes; the others are the
        // wrong example's.
        for (name, text) in &wrong.files {
            if !right.files.iter().any(|(n, _)| n == name) {
                right.files.push((name.clone(), text.clone()));
            }
        }
        let dir = scratch.join(code);
        // W112 is about a folder with more entries than the search reads.
        let crowd = if code == "W112" { 20_001 } else { 0 };
        let mut wrong = wrong;
        if code == "E048" {
            // Thousands of modes' copies, which an example cannot show.
            let many = support::missiongen::mode_entered_with_many_rooms(64, 1000);
            wrong.files.push(("many.mission".into(), many));
        }
        let found = codes_of(&dir, &wrong, crowd);
        assert!(
            found.iter().any(|c| c == code),
            "{code}: the wrong example gives {found:?}"
        );
        let found = codes_of(&dir, &right, crowd);
        assert!(
            !found.iter().any(|c| c == code),
            "{code}: the right example gives {found:?}"
        );
    }
    // Without a code: one line per code.
    let all = semo(&["explain"]);
    assert_eq!(all.stdout.lines().count(), semo::diag::Code::ALL.len());
}

#[test]
fn completions_complete_commands_and_option_values_in_a_real_bash() {
    let script = semo(&["completions", "bash"]);
    assert_eq!(script.code, 0, "{}", script.stderr);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("semo.bash"), &script.stdout).unwrap();
    // What bash offers after the words typed so far, as a user's Tab would.
    let offered = |words: &[&str]| -> Vec<String> {
        let words_array = words
            .iter()
            .map(|w| format!("'{w}'"))
            .collect::<Vec<_>>()
            .join(" ");
        let program = format!(
            "source semo.bash; COMP_WORDS=({words_array}); COMP_CWORD={}; \
             _semo semo '{}' '{}'; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
            words.len() - 1,
            words[words.len() - 1],
            words[words.len() - 2],
        );
        let out = Command::new("bash")
            .args(["--norc", "-c", &program])
            .current_dir(dir.path())
            .output()
            .expect("bash runs");
        assert!(out.status.success(), "{out:?}");
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect()
    };
    assert_eq!(offered(&["semo", "ver"]), ["verify"]);
    let formats = offered(&["semo", "check", "--format", ""]);
    for format in ["human", "json", "sarif"] {
        assert!(formats.iter().any(|f| f == format), "{formats:?}");
    }
    // The other shells' scripts come from the same definition.
    let zsh = semo(&["completions", "zsh"]);
    assert!(zsh.stdout.starts_with("#compdef semo"), "{}", zsh.stdout);
    let fish = semo(&["completions", "fish"]);
    assert!(
        fish.stdout.contains("complete -c semo") && fish.stdout.contains("verify"),
        "{}",
        fish.stdout
    );
    let unknown = semo(&["completions", "tcsh"]);
    assert_eq!(unknown.code, 2, "{}", unknown.stderr);
}

#[test]
fn man_prints_semo_1_and_writes_a_page_per_command() {
    let page = semo(&["man"]);
    assert_eq!(page.code, 0, "{}", page.stderr);
    assert!(page.stdout.contains(".TH semo 1"), "{}", page.stdout);
    for command in ["check", "fmt", "build", "simulate", "verify", "completions"] {
        assert!(page.stdout.contains(command), "{command} not in semo(1)");
    }
    let dir = tempfile::tempdir().unwrap();
    let out = semo(&["man", "-o", &dir.path().join("man1").display().to_string()]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let check = std::fs::read_to_string(dir.path().join("man1/semo-check.1")).unwrap();
    assert!(check.contains(".TH semo-check 1"), "{check}");
    assert!(check.contains("deny"), "{check}");
    assert!(dir.path().join("man1/semo-graph-analyze.1").is_file());
}

#[test]
fn version_names_the_commit_it_was_built_from() {
    let out = semo(&["--version"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // Built from a git checkout (as every test run is): `semo 0.1.0 (1a2b3c4d5e6f 2026-11-29)`.
    let head = Command::new("git")
        .args(["log", "-1", "--format=%h %cs", "--abbrev=12"])
        .current_dir(repo_root())
        .output()
        .expect("git runs");
    let head = String::from_utf8(head.stdout).unwrap();
    if head.trim().is_empty() {
        eprintln!("skipping the commit: not a git checkout");
        return;
    }
    assert_eq!(
        out.stdout.trim(),
        format!("semo {} ({})", env!("CARGO_PKG_VERSION"), head.trim())
    );
}

/// A copy of `tests/fixtures/diagnostics` (every kind of file, most with
/// problems) in a temporary folder.
fn fixtures_copy() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let from = repo_root().join("tests/fixtures/diagnostics");
    for entry in walkdir::WalkDir::new(&from) {
        let entry = entry.unwrap();
        let to = tmp.path().join(entry.path().strip_prefix(&from).unwrap());
        if entry.file_type().is_dir() {
            std::fs::create_dir_all(&to).unwrap();
        } else {
            std::fs::copy(entry.path(), &to).unwrap();
        }
    }
    tmp
}

/// Every file under `dir` with its text.
fn contents(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut found: Vec<_> = walkdir::WalkDir::new(dir)
        .into_iter()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().is_file())
        .map(|e| (e.path().to_path_buf(), std::fs::read(e.path()).unwrap()))
        .collect();
    found.sort();
    found
}

/// `semo check --statistics --format json` in `dir`: (code, count, fixable) per code.
fn statistics_in(dir: &std::path::Path) -> Vec<(String, u64, u64)> {
    let out = semo_in_dir(dir, &["check", "--statistics", "--format", "json", "."]);
    let document: serde_json::Value = serde_json::from_str(&out.stdout).expect("one document");
    document["statistics"]
        .as_array()
        .expect("statistics")
        .iter()
        .map(|s| {
            (
                s["code"].as_str().unwrap().to_string(),
                s["count"].as_u64().unwrap(),
                s["fixable"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn check_fix_applies_every_preferred_fix_and_a_second_run_changes_nothing() {
    let tmp = fixtures_copy();
    let dir = tmp.path();
    let before = statistics_in(dir);
    let fixable: u64 = before.iter().map(|s| s.2).sum();
    assert!(fixable >= 10, "{before:?}");
    let out = semo_in_dir(dir, &["check", "--fix", "--format", "json", "."]);
    let document: serde_json::Value = serde_json::from_str(&out.stdout).expect("one document");
    let fixes = document["fixes"].as_array().expect("the fixes applied");
    // A fix can uncover another: at least every one counted before is applied.
    assert!(fixes.len() as u64 >= fixable, "{fixes:#?}");
    for fix in fixes {
        let file = dir.join(fix["file"].as_str().unwrap());
        assert!(file.is_file(), "{fix}");
        assert!(fix["code"].as_str().unwrap().len() == 4, "{fix}");
    }
    // Nothing fixable is left, and each code has at most as many problems.
    let after = statistics_in(dir);
    assert!(after.iter().all(|s| s.2 == 0), "{after:?}");
    for (code, count, _) in &after {
        let was = before.iter().find(|s| &s.0 == code).map_or(0, |s| s.1);
        assert!(
            *count <= was || code.starts_with('W'),
            "{code}: {was} -> {count}"
        );
    }
    let fixed = contents(dir);
    let again = semo_in_dir(dir, &["check", "--fix", "."]);
    assert!(!again.stderr.contains("fixed "), "{}", again.stderr);
    assert!(contents(dir) == fixed, "a second --fix changed a file");
}

#[test]
fn check_fix_of_standard_input_prints_the_fixed_mission() {
    let mission = fixture("E017_unknown_mode.mission");
    let out = semo_with_stdin(&repo_root(), &["check", "--fix", "-"], &mission);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(
        out.stdout,
        mission.replace("mode = RETUN_MODE", "mode = RETURN_MODE")
    );
    assert!(
        out.stderr
            .contains("fixed <stdin>:21:29: [E017] Change `RETUN_MODE` to `RETURN_MODE`"),
        "{}",
        out.stderr
    );
}

#[test]
fn concise_gives_one_line_per_problem_and_statistics_count_them_by_code() {
    let dir = repo_root().join("tests/fixtures/diagnostics");
    let json = semo_in_dir(&dir, &["check", "--format", "json", "."]);
    let diags = support::parse_json_report(&json.stdout);
    let concise = semo_in_dir(&dir, &["check", "--format", "concise", "."]);
    assert_eq!(concise.code, 1);
    let line =
        regex::Regex::new(r"^[^:]+:\d+:\d+: (error|warning|hint)\[[EW]\d{3}\]: .+$").unwrap();
    let problems: Vec<&str> = concise
        .stderr
        .lines()
        .filter(|l| !l.starts_with("checked ") && !l.contains("semo check --fix"))
        .collect();
    assert_eq!(problems.len(), diags.len(), "{}", concise.stderr);
    for (text, d) in problems.iter().zip(&diags) {
        assert!(line.is_match(text), "{text}");
        let at = format!(
            "{}:{}:{}: {}[{}]: ",
            d.file, d.start.0, d.start.1, d.severity, d.code
        );
        assert!(text.starts_with(&at), "{text} is not {at}");
    }
    let statistics = statistics_in(&dir);
    for (code, count, _) in &statistics {
        let listed = diags.iter().filter(|d| &d.code == code).count() as u64;
        assert_eq!(*count, listed, "{code}");
    }
    assert_eq!(
        statistics.iter().map(|s| s.1).sum::<u64>(),
        diags.len() as u64
    );
    let people = semo_in_dir(&dir, &["check", "--statistics", "."]);
    let first = people.stderr.lines().next().unwrap_or_default();
    let top = &statistics[0];
    assert!(
        first
            .trim_start()
            .starts_with(&format!("{}  {}", top.1, top.0)),
        "{}",
        people.stderr
    );
}
