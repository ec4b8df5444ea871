//! Check throughput on a large generated mission (200 teams, 10k+ lines):
//! parse alone, parse+check, and `semo fmt`'s formatting (parse, layout and
//! the check of its own output), in MB/s and lines/s; then one-character
//! edits parsed incrementally (alone and with the check). Run with
//! `cargo bench`. The target is at least 30 MB/s for parse+check on a 2-core
//! machine.

mod common;
use common::fastest;
use common::mission::generate;

use semo::catalog::builtin_catalog;
use semo::diag::FileId;
use semo::sema::check_parsed;
use semo::syntax::parse_incremental;
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

    // One-character edits, as typed in an editor: an `x` typed into a string
    // in the middle of the mission, then deleted, each version parsed with
    // the previous version's cache (what the language server does).
    let half = text.len() / 2;
    let at = half + text[half..].find('"').map_or(0, |i| i + 1);
    let edited = format!("{}x{}", &text[..at], &text[at..]);
    let versions = [edited.as_str(), text.as_str()];
    let mut cache = parse_incremental(FileId(0), &text, None).1;
    let mut turn = 0;
    let mut next = || {
        turn += 1;
        versions[turn % 2]
    };
    let reparse = fastest(budget, || {
        let (parse, new) = parse_incremental(FileId(0), black_box(next()), Some(&cache));
        black_box(parse);
        cache = new;
    });
    let recheck = fastest(budget, || {
        let (parse, new) = parse_incremental(FileId(0), black_box(next()), Some(&cache));
        black_box(check_parsed(FileId(0), parse, &catalog));
        cache = new;
    });
    println!("one-character edits, with the previous version's cache:");
    for (what, d, scratch) in [
        ("reparse", reparse, parse),
        ("reparse+check", recheck, check),
    ] {
        println!(
            "{what:>14}: {:>8.2} ms  ({:.1}x faster than from scratch)",
            d.as_secs_f64() * 1e3,
            scratch.as_secs_f64() / d.as_secs_f64()
        );
    }
}
