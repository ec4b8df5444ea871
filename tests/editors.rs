//! The editor clients in the real editors, against the real `semo lsp`: Neovim headless
//! (`editors/nvim`, driven by `tests/editors/nvim_test.lua`) and Emacs in batch mode
//! (`editors/emacs/semo-mode.el` with eglot, driven by `tests/editors/emacs_test.el`). Each
//! opens `tests/editors/workspace/rover.mission`, which names a mode that does not exist.
//!
//! An editor that is not installed (or an Emacs without eglot) is skipped with a message, unless
//! `SEMO_EDITOR_TESTS=require` (as in CI, which installs Debian's `neovim`, `emacs-nox` and
//! `elpa-eglot`): then its absence fails the test.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .expect("the repository exists")
}

/// Whether `program` runs with `args`; if not, the reason the test stops here, `missing`
/// (or a failure if the editors are required).
fn editor_available(program: &str, args: &[&str], missing: &str) -> bool {
    let found = Command::new(program)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        let required = std::env::var("SEMO_EDITOR_TESTS").is_ok_and(|v| v == "require");
        assert!(!required, "{missing}, and SEMO_EDITOR_TESTS=require");
        eprintln!("skipping: {missing} (apt-get install neovim emacs-nox elpa-eglot)");
    }
    found
}

/// Emacs with eglot as `emacs_test.el` loads it (Debian's `elpa-eglot`; Emacs before 29
/// has no eglot of its own): an Emacs without it is skipped, not failed.
fn emacs_with_eglot() -> bool {
    let load_eglot = "(progn (require 'package) \
        (add-to-list 'package-directory-list \"/usr/share/emacs/site-lisp/elpa\") \
        (package-initialize) (require 'eglot))";
    editor_available(
        "emacs",
        &["--batch", "-Q", "--eval", load_eglot],
        "`emacs` is not installed or has no eglot",
    )
}

/// A fresh copy of the test workspace (a git root, so editors find the project there), with
/// a home and XDG folders of its own so that no user configuration is read.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("editors-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    let workspace = dir.join("workspace");
    std::fs::create_dir_all(workspace.join(".git")).expect("scratch folder");
    for entry in std::fs::read_dir(repo().join("tests/editors/workspace")).expect("fixtures") {
        let entry = entry.expect("fixture entry");
        std::fs::copy(entry.path(), workspace.join(entry.file_name())).expect("copy fixture");
    }
    for sub in ["home", "cache", "config", "data", "state"] {
        std::fs::create_dir_all(dir.join(sub)).expect("scratch folder");
    }
    dir
}

/// Runs the editor with the scratch environment; fails with its output if it fails or
/// takes more than two minutes.
fn run_editor(mut cmd: Command, scratch: &Path) -> String {
    cmd.env("HOME", scratch.join("home"))
        .env("XDG_CACHE_HOME", scratch.join("cache"))
        .env("XDG_CONFIG_HOME", scratch.join("config"))
        .env("XDG_DATA_HOME", scratch.join("data"))
        .env("XDG_STATE_HOME", scratch.join("state"))
        .env("SEMO_BIN", env!("CARGO_BIN_EXE_semo"))
        .env("SEMO_REPO", repo())
        .env("SEMO_WORKSPACE", scratch.join("workspace"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("the editor starts");
    let started = Instant::now();
    while child.try_wait().expect("waiting for the editor").is_none() {
        if started.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().expect("editor output");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    println!("{stdout}");
    assert!(
        output.status.success(),
        "the editor test failed ({}):\n{stdout}\n{stderr}",
        output.status
    );
    stdout
}

#[test]
fn neovim_shows_the_diagnostic_completes_and_highlights_a_mission() {
    if !editor_available("nvim", &["--version"], "`nvim` is not installed") {
        return;
    }
    let scratch = scratch("nvim");
    let mut cmd = Command::new("nvim");
    cmd.arg("--headless")
        .arg("--clean")
        .arg("--cmd")
        .arg(format!(
            "set rtp^={}",
            repo().join("editors/nvim").display()
        ))
        .arg("-c")
        .arg(format!(
            "luafile {}",
            repo().join("tests/editors/nvim_test.lua").display()
        ))
        .env("SEMO_SITE", scratch.join("site"));
    let out = run_editor(cmd, &scratch);
    for expected in [
        "diagnostic: 24:24 E017: team Rover has no mode `MOVNG` (did you mean `MOVING`?)",
        "captures at `throw GO`: @keyword.exception / @label",
        "completion in `set(Action, `: Drive OFF Wait",
        "plain.xml: filetype xml, 0 semo client(s)",
        "simulate: IDLE@0 -> MOVING@1000, ok false",
        "scenario diagnostic: 4:13 expectation failed: r never enters IDLE: entered at 0 ms",
        "verify: explored every behaviour: 542 state(s), 1130 transition(s): a proof for the choices explored; eventually r in MOVING: broken",
        "verify quickfix: 1 finding(s)",
        "monitor: r          Rover        waiting",
        "monitor window: r          Rover        waiting",
        "marks: ◀ in this mode: r",
    ] {
        assert!(out.contains(expected), "missing {expected:?} in:\n{out}");
    }
}

#[test]
fn emacs_shows_the_diagnostic_through_eglot() {
    if !emacs_with_eglot() {
        return;
    }
    let scratch = scratch("emacs");
    let mut cmd = Command::new("emacs");
    cmd.args(["--batch", "-Q", "-l"])
        .arg(repo().join("tests/editors/emacs_test.el"));
    let out = run_editor(cmd, &scratch);
    for expected in [
        "faces at `throw GO': font-lock-keyword-face / font-lock-constant-face",
        "indent-region: unchanged",
        "diagnostic: 24:24 eglot-error: semo [E017]: team Rover has no mode `MOVNG`",
    ] {
        assert!(out.contains(expected), "missing {expected:?} in:\n{out}");
    }
}

/// Neovim reads its queries from `editors/nvim/queries/semo/`: they are copies of the
/// grammar's (a plugin folder cannot point elsewhere), kept identical.
#[test]
fn neovim_queries_are_the_grammars() {
    let grammar = repo().join("grammars/tree-sitter-semo/queries");
    let nvim = repo().join("editors/nvim/queries/semo");
    let mut names: Vec<_> = std::fs::read_dir(&grammar)
        .expect("grammar queries")
        .map(|e| e.expect("entry").file_name())
        .collect();
    names.sort();
    assert!(
        names.len() >= 3,
        "the grammar has highlights, folds and locals queries"
    );
    for name in names {
        let ours = std::fs::read_to_string(grammar.join(&name)).expect("grammar query");
        let theirs = std::fs::read_to_string(nvim.join(&name)).unwrap_or_default();
        assert_eq!(
            ours,
            theirs,
            "editors/nvim/queries/semo/{} differs from the grammar's; copy it again",
            name.to_string_lossy()
        );
    }
}
