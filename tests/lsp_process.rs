//! The real `semo lsp` process driven over stdio by an independent client
//! (pytest-lsp, on pygls): the tests are in `tests/lsp_e2e/`. The first run
//! creates a Python virtual environment under the target folder and installs
//! the client there (`tests/lsp_e2e/requirements.txt`).

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(cmd: &mut Command) -> bool {
    cmd.status().map(|s| s.success()).unwrap_or(false)
}

/// A virtual environment with pytest-lsp, made once.
fn python_with_pytest_lsp(e2e: &Path) -> PathBuf {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lsp-e2e-venv");
    let python = venv.join("bin/python");
    let ready = || run(Command::new(&python).args(["-c", "import pytest_lsp"]));
    if !ready() {
        assert!(
            run(Command::new("python3").args(["-m", "venv"]).arg(&venv)),
            "python3 -m venv failed: Python 3 with venv is needed for this test"
        );
        assert!(
            run(Command::new(&python)
                .args(["-m", "pip", "install", "--quiet", "-r"])
                .arg(e2e.join("requirements.txt"))),
            "installing pytest-lsp failed (PyPI must be reachable)"
        );
        assert!(ready(), "pytest-lsp is not importable after installing it");
    }
    python
}

#[test]
fn semo_lsp_over_stdio_with_pytest_lsp() {
    let e2e = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/lsp_e2e");
    let python = python_with_pytest_lsp(&e2e);
    let status = Command::new(python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .current_dir(&e2e)
        .env("SEMO_BIN", env!("CARGO_BIN_EXE_semo"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .status()
        .expect("pytest starts");
    assert!(
        status.success(),
        "the pytest-lsp suite failed (output above)"
    );
}
