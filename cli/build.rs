//! Link flags for the `semo` binary.
//!
//! On Linux with glibc the binary is linked position-dependent (`-no-pie`):
//! a position-independent `semo` is 15 MB with about 11,000 relative
//! relocations that the dynamic loader applies at every start, touching the
//! pages they are on, and a `semo graph analyze` of a small graph is mostly
//! start-up (on `mp3playback`, 2.24 ms of CPU against 2.08 ms without them:
//! `perf stat -r 40`). The code stays position-independent; only the
//! executable's own load address is fixed (shared libraries are still placed
//! at random).
fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let env = std::env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
    if os == "linux" && env == "gnu" {
        println!("cargo:rustc-link-arg-bins=-no-pie");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
