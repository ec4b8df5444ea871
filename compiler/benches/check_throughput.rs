//! Check throughput on a large generated mission (200 teams, 10k+ lines):
//! parse alone, parse+check, and `semo fmt`'s formatting (parse, layout and
//! the check of its own output), in MB/s and lines/s. Run with `cargo bench`.
//! The target is at least 30 MB/s for parse+check on a 2-core machine, and a
//! few milliseconds per 10k lines for formatting.

mod common;
use common::fastest;
use common::mission::generate;

use semo::catalog::builtin_catalog;
use semo::diag::FileId;
use std::hint::black_box;
use std::time::Duration;

fn main() {
    // `cargo bench` passes `--bench`; a filter argument is accepted and ignored.
    let teams: usize = std::env::var("SEMO_BENCH_TEAMS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let text = generate(teams);
    if let Ok(path) = std::env::var("SEMO_BENCH_DUMP") {
        std::fs::write(&path, &text).expect("write the generated mission");
    }
    let catalog = builtin_catalog();
    let lines = text.lines().count();
    let mb = text.len() as f64 / 1e6;

    let analysis = semo::check_source(FileId(0), &text, &catalog);
    let errors: Vec<_> = analysis
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert!(
        errors.is_empty(),
        "the generated mission must be valid: {:#?}",
        &errors[..errors.len().min(5)]
    );

    println!(
        "mission: {teams} teams, {lines} lines, {:.2} MB, {} diagnostics (warnings/hints)",
        mb,
        analysis.diagnostics.len()
    );
    let formatted = semo::format::format_source(&text).expect("the generated mission formats");
    assert_eq!(
        semo::format::format_source(&formatted).as_ref(),
        Ok(&formatted),
        "formatting is stable"
    );

    let budget = Duration::from_secs(3);
    let parse = fastest(budget, || {
        black_box(semo::syntax::parse(FileId(0), black_box(&text)));
    });
    let check = fastest(budget, || {
        black_box(semo::check_source(FileId(0), black_box(&text), &catalog));
    });
    let format = fastest(budget, || {
        black_box(semo::format::format_source(black_box(&text)).ok());
    });
    for (what, d) in [("parse", parse), ("parse+check", check), ("format", format)] {
        let s = d.as_secs_f64();
        println!(
            "{what:>12}: {:>8.2} ms  {:>7.1} MB/s  {:>10.0} lines/s",
            s * 1e3,
            mb / s,
            lines as f64 / s
        );
    }
}
