//! Python tools from PyPI for the tests that check our output with a
//! reference implementation: a virtual environment under cargo's scratch
//! folder, made once per name and kept between runs.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(cmd: &mut Command) -> bool {
    cmd.status().map(|s| s.success()).unwrap_or(false)
}

/// The Python of a virtual environment `name` in which `module` imports,
/// made with `python3 -m venv` and `pip install INSTALL...` when it does not
/// yet (`install`: pip's arguments, `["-r", "requirements.txt"]` or package
/// names with their versions).
pub fn venv_with(name: &str, module: &str, install: &[&str]) -> PathBuf {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let python = venv.join("bin/python");
    let ready = || run(Command::new(&python).args(["-c", &format!("import {module}")]));
    if !ready() {
        assert!(
            run(Command::new("python3").args(["-m", "venv"]).arg(&venv)),
            "python3 -m venv failed: Python 3 with venv is needed for this test"
        );
        assert!(
            run(Command::new(&python)
                .args(["-m", "pip", "install", "--quiet"])
                .args(install)),
            "installing {install:?} failed (PyPI must be reachable)"
        );
        assert!(ready(), "{module} is not importable after installing it");
    }
    python
}
