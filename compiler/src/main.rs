fn main() {
    std::process::exit(semo::cli::main());
}
