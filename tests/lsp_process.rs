//! The real `semo lsp` process driven over stdio by an independent client
//! (pytest-lsp, on pygls): the tests are in `tests/lsp_e2e/`. The first run
//! creates a Python virtual environment under the target folder and installs
//! the client there (`tests/lsp_e2e/requirements.txt`).

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

/// A virtual environment with pytest-lsp, made once.
fn python_with_pytest_lsp(e2e: &Path) -> PathBuf {
    let requirements = e2e.join("requirements.txt").display().to_string();
    support::python::venv_with("lsp-e2e-venv", "pytest_lsp", &["-r", &requirements])
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

/// The real `semo lsp` process given `messages`, then `exit`; its exit code.
fn lsp_exit_code(messages: &[serde_json::Value]) -> i32 {
    use std::io::{Read, Write};
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("lsp")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let exit = serde_json::json!({ "jsonrpc": "2.0", "method": "exit" });
    for message in messages.iter().chain([&exit]) {
        let body = message.to_string();
        write!(stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
    }
    stdin.flush().unwrap();
    let mut answers = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut answers)
        .unwrap();
    drop(stdin);
    child.wait().unwrap().code().unwrap_or(-1)
}

#[test]
fn exit_without_shutdown_exits_1_and_after_it_0() {
    let initialize = serde_json::json!({
        "jsonrpc": "2.0", "id": 1, "method": "initialize",
        "params": { "processId": null, "rootUri": null, "capabilities": {} }
    });
    let initialized =
        serde_json::json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} });
    let shutdown = serde_json::json!({ "jsonrpc": "2.0", "id": 2, "method": "shutdown" });
    assert_eq!(lsp_exit_code(&[initialize.clone(), initialized.clone()]), 1);
    assert_eq!(lsp_exit_code(&[initialize, initialized, shutdown]), 0);
}
