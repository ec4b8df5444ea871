//! A workload for profilers: `prof FILE MODE [N] [AT]` runs MODE N times on
//! the mission in FILE and prints the time per run.
//!
//! Modes: `lex`, `parse`, `check` (parse and check, the default) from
//! scratch; `reparse` and `recheck` time one-character edits, alternately
//! typing and deleting an `x`, parsed with the previous version's cache
//! (`recheck` also checks, as the language server does). AT is where the edit
//! is: `start` (end of the first line) or `middle` (inside a string in the
//! middle of the file, the default).
//!
//! For instruction counts per edit, run under callgrind twice with different
//! N and divide the difference.

use semo::diag::FileId;
use semo::syntax::{ParseCache, parse_incremental};

fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let what = std::env::args().nth(2).unwrap_or_default();
    let n: usize = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let at = match std::env::args().nth(4).as_deref() {
        Some("start") => text.find('\n').unwrap_or(text.len()),
        _ => {
            let half = text.len() / 2;
            half + text[half..].find('"').map_or(0, |i| i + 1)
        }
    };
    let edited = format!("{}x{}", &text[..at], &text[at..]);
    let catalog = semo::catalog::builtin_catalog();
    let mut cache: Option<ParseCache> = None;
    if matches!(what.as_str(), "reparse" | "recheck") {
        cache = Some(parse_incremental(FileId(0), &text, None).1);
    }
    let t = std::time::Instant::now();
    for i in 0..n {
        let version = if i % 2 == 0 { &edited } else { &text };
        match what.as_str() {
            "lex" => {
                std::hint::black_box(semo::syntax::token::lex(&text));
            }
            "parse" => {
                std::hint::black_box(semo::syntax::parse(FileId(0), &text));
            }
            "reparse" => {
                let (parse, next) = parse_incremental(FileId(0), version, cache.as_ref());
                std::hint::black_box(parse);
                cache = Some(next);
            }
            "recheck" => {
                let (parse, next) = parse_incremental(FileId(0), version, cache.as_ref());
                std::hint::black_box(semo::sema::check_parsed(FileId(0), parse, &catalog));
                cache = Some(next);
            }
            _ => {
                std::hint::black_box(semo::check_source(FileId(0), &text, &catalog));
            }
        }
    }
    let per = t.elapsed().as_secs_f64() / n as f64;
    println!(
        "{what}: {:.3} ms/iter, {:.1} MB/s",
        per * 1e3,
        text.len() as f64 / 1e6 / per
    );
}
