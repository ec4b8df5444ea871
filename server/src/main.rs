//! The `semo` binary: the compiler's command line, with `semo lsp` served by
//! this crate.
fn main() {
    std::process::exit(semo::cli::main(semo_server::run_stdio));
}
