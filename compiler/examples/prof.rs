fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let what = std::env::args().nth(2).unwrap_or_default();
    let n: usize = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let catalog = semo::catalog::builtin_catalog();
    let t = std::time::Instant::now();
    for _ in 0..n {
        match what.as_str() {
            "lex" => {
                std::hint::black_box(semo::syntax::token::lex(&text));
            }
            "parse" => {
                std::hint::black_box(semo::syntax::parse(semo::diag::FileId(0), &text));
            }
            _ => {
                std::hint::black_box(semo::check_source(semo::diag::FileId(0), &text, &catalog));
            }
        }
    }
    let per = t.elapsed().as_secs_f64() / n as f64;
    println!(
        "{what}: {:.2} ms/iter, {:.1} MB/s",
        per * 1e3,
        text.len() as f64 / 1e6 / per
    );
}
