//! Compiles the generated parser (`src/parser.c`, committed) so that neither the
//! tree-sitter CLI nor Node is needed to build or test the grammar.

fn main() {
    let src_dir = std::path::Path::new("src");
    cc::Build::new()
        .std("c11")
        .include(src_dir)
        .file(src_dir.join("parser.c"))
        .warnings(false)
        .compile("tree-sitter-semo");
    println!("cargo:rerun-if-changed=src/parser.c");
    println!("cargo:rerun-if-changed=src/tree_sitter/parser.h");
}
