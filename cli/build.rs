//! Link flags for the `semo` binary, and the version it prints.
//!
//! On Linux with glibc the binary is linked position-dependent (`-no-pie`):
//! a position-independent `semo` is 15 MB with about 11,000 relative
//! relocations that the dynamic loader applies at every start, touching the
//! pages they are on, and a `semo graph analyze` of a small graph is mostly
//! start-up (on `mp3playback`, 2.24 ms of CPU against 2.08 ms without them:
//! `perf stat -r 40`). The code stays position-independent; only the
//! executable's own load address is fixed (shared libraries are still placed
//! at random).
//!
//! `semo --version` names the commit it was built from (`0.1.0 (1a2b3c4d5e6f
//! 2026-11-29)`), so a bug report says which code it is about; built outside
//! a git checkout (a source archive), it is the package version alone.
use std::path::Path;
use std::process::Command;

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let env = std::env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
    if os == "linux" && env == "gnu" {
        println!("cargo:rustc-link-arg-bins=-no-pie");
    }
    println!("cargo:rerun-if-changed=build.rs");

    let package = std::env::var("CARGO_PKG_VERSION").unwrap_or_default();
    let version = match git(&["log", "-1", "--format=%h %cs", "--abbrev=12"]) {
        Some(commit) => format!("{package} ({commit})"),
        None => package,
    };
    println!("cargo:rustc-env=SEMO_VERSION={version}");
    // Run again when HEAD moves: HEAD itself (another branch), the branch's
    // ref, and the packed refs. Only files that exist: a missing one would
    // make cargo run this script at every build.
    let mut watched = vec!["HEAD".to_string(), "packed-refs".to_string()];
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watched.push(branch);
    }
    for name in watched {
        let path = git(&["rev-parse", "--git-path", &name]);
        if let Some(path) = path.filter(|p| Path::new(p).exists()) {
            println!("cargo:rerun-if-changed={path}");
        }
    }
}

/// The output of `git ARGS` in this package's folder, trimmed, if git ran
/// and succeeded (no git, or not a checkout: `None`).
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    (out.status.success() && !text.trim().is_empty()).then(|| text.trim().to_string())
}
