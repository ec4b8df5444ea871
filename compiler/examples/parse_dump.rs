fn main() {
    let catalog = semo::catalog::builtin_catalog();
    for path in std::env::args().skip(1) {
        let text = std::fs::read_to_string(&path).unwrap();
        let a = semo::check_source(semo::diag::FileId(0), &text, &catalog);
        println!(
            "{path}: {} items, {} diags",
            a.syntax.items.len(),
            a.diagnostics.len()
        );
        for d in &a.diagnostics {
            println!("  {} {:?} {:?} {}", d.code, d.severity, d.span, d.message);
        }
    }
}
