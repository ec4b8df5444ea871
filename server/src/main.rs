//! The `semo` binary: the compiler's command line.
fn main() {
    std::process::exit(semo::cli::main());
}
