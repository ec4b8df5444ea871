//! The command-line conventions users expect of a tool (issue 18, "CLI"),
//! each through the `semo` binary: `-` for standard input, `--deny
//! warnings`, colour by `--color` then `NO_COLOR`, `CLICOLOR_FORCE` and
//! `TERM=dumb`, hints called hints, one `-o/--output` meaning, and `--help`
//! saying what the tool does.

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
    assert!(out.stdout.contains("checked 1 mission"), "{}", out.stdout);

    let bad = fixture("E015_unknown_team.mission");
    let out = semo_with_stdin(&root, &["check", "--format", "json", "-"], &bad);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    let diags = support::parse_json_lines(&out.stdout);
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
    assert_eq!(out.code, 0, "{}", out.stdout);
    assert!(out.stdout.contains("W011"), "{}", out.stdout);
    let out = semo_with_stdin(&root, &["check", "--deny", "warnings", "-"], &warned);
    assert_eq!(out.code, 1, "{}", out.stdout);
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
    assert!(out.stdout.contains("[W009] Hint:"), "{}", out.stdout);
    assert!(!out.stdout.contains("Advice"), "{}", out.stdout);
    // Without colour, not a single escape sequence, the hint's header too.
    assert!(!out.stdout.contains('\u{1b}'), "{:?}", out.stdout);
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
    out.stdout.contains(&0x1b)
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
