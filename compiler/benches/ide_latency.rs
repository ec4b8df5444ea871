//! Editor features on a large mission (200 teams, 10k+ lines) once it is
//! analysed: the fastest of repeated runs for each feature at a team name
//! used all over the file, and completion's median, p99 and maximum over
//! hundreds of places. Lookups are binary searches or one pass over the
//! occurrences, so every figure should stay in the low milliseconds (p99 of
//! completion: target 5 ms). Run with `cargo bench --bench ide_latency`.
//! (These were timed assertions inside the test suite; timing belongs here.)

mod common;
use common::fastest;
use common::mission::generate;

use semo::catalog::builtin_catalog;
use semo::diag::FileId;
use semo::ide::CompletionConfig;
use semo::ide::mission::completion::completions;
use semo::ide::mission::{folding, hover, navigation, rename, selection, semantic_tokens, symbols};
use std::hint::black_box;
use std::time::Duration;

fn main() {
    let text = generate(200);
    let catalog = builtin_catalog();
    let a = semo::check_source(FileId(0), &text, &catalog);
    assert!(!a.has_errors(), "the generated mission has errors");
    let at = text
        .rfind("Team199.Alarm == DARK")
        .expect("the generated mission reads Team199.Alarm");
    let budget = Duration::from_millis(200);
    let catalog = &catalog;
    let text = text.as_str();
    let a = &a;
    let features: [(&str, Duration); 11] = [
        (
            "definition",
            fastest(budget, || {
                drop(black_box(navigation::definition(a, catalog, at)))
            }),
        ),
        (
            "references",
            fastest(budget, || drop(black_box(navigation::references(a, at)))),
        ),
        (
            "hover",
            fastest(budget, || {
                drop(black_box(hover::hover(a, catalog, text, at)))
            }),
        ),
        (
            "prepare rename",
            fastest(budget, || {
                drop(black_box(rename::prepare_rename(a, text, at)))
            }),
        ),
        (
            "rename",
            fastest(budget, || {
                drop(black_box(rename::rename(a, catalog, text, at, "Renamed")))
            }),
        ),
        (
            "document symbols",
            fastest(budget, || {
                drop(black_box(symbols::document_symbols(a, text)))
            }),
        ),
        (
            "workspace symbols",
            fastest(budget, || {
                drop(black_box(symbols::workspace_symbols(a, "patr")))
            }),
        ),
        (
            "semantic tokens",
            fastest(budget, || {
                drop(black_box(semantic_tokens::semantic_tokens(a, None)))
            }),
        ),
        (
            "folding ranges",
            fastest(budget, || drop(black_box(folding::folding_ranges(a, text)))),
        ),
        (
            "selection ranges",
            fastest(budget, || {
                drop(black_box(selection::selection_ranges(a, text, at)))
            }),
        ),
        (
            "completion at the name",
            fastest(budget, || {
                drop(black_box(completions(
                    a,
                    catalog,
                    text,
                    at,
                    CompletionConfig { snippets: true },
                )))
            }),
        ),
    ];
    println!("{} lines, {} bytes", text.lines().count(), text.len());
    for (what, took) in features {
        println!("{what:>24}: {took:?}");
    }

    // Completion all over the file: statements, conditions, `Team.`, calls.
    let mut offsets: Vec<usize> = Vec::new();
    for needle in [
        "  light_on()",
        "LIGHTNESS <",
        "Team",
        "send(",
        "others{",
        "  [[",
    ] {
        offsets.extend(
            text.match_indices(needle)
                .step_by(7)
                .map(|(i, _)| i + needle.len()),
        );
    }
    let mut times: Vec<Duration> = offsets
        .iter()
        .map(|&offset| {
            fastest(Duration::ZERO, || {
                black_box(completions(
                    a,
                    catalog,
                    text,
                    offset,
                    CompletionConfig { snippets: true },
                ));
            })
        })
        .collect();
    times.sort();
    println!(
        "completion at {} places: median {:?}, p99 {:?}, max {:?} (target: p99 <= 5 ms)",
        times.len(),
        times[times.len() / 2],
        times[times.len() * 99 / 100],
        times[times.len() - 1]
    );
}
