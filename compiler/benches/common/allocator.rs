//! The `semo` binary's allocator (`cli/src/main.rs`; why: the workspace's
//! `Cargo.toml`), so that a bench measures what a user runs. Every bench
//! that runs the library or the server in its own process includes this one
//! file: the compiler's through `common`, `verify` and the server's by its
//! path (the CLI's benches run `semo` and the robots as processes).

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
