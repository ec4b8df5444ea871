//! Every feature stays fast on a large mission (10k+ lines) once it is
//! analysed: lookups are binary searches or one pass over the occurrences,
//! never a scan per name. The bound is loose (unoptimised test builds on a
//! shared machine); a quadratic scan would exceed it by far.

use super::testing::{Fixture, large_mission};
use super::*;
use std::time::{Duration, Instant};

/// The fastest of three runs.
fn fastest(mut f: impl FnMut()) -> Duration {
    (0..3)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

#[test]
fn every_request_is_fast_on_a_large_mission() {
    let f = Fixture::new(&large_mission(200));
    assert!(f.text.lines().count() > 10_000);
    assert!(
        !f.analysis.has_errors(),
        "{:#?}",
        &f.analysis.diagnostics[..3]
    );
    let (a, text, catalog) = (&f.analysis, f.text.as_str(), &f.catalog);
    // A team name used all over the file, near its end.
    let at = f.text.rfind("Team199.Alarm == DARK").unwrap();
    let timings = [
        (
            "definition",
            fastest(|| drop(navigation::definition(a, catalog, at))),
        ),
        (
            "references",
            fastest(|| drop(navigation::references(a, at))),
        ),
        (
            "prepare rename",
            fastest(|| drop(rename::prepare_rename(a, text, at))),
        ),
        (
            "rename",
            fastest(|| drop(rename::rename(a, catalog, text, at, "Renamed"))),
        ),
        (
            "document symbols",
            fastest(|| drop(symbols::document_symbols(a, text))),
        ),
        (
            "workspace symbols",
            fastest(|| drop(symbols::workspace_symbols(a, "patr"))),
        ),
        (
            "semantic tokens",
            fastest(|| drop(semantic_tokens::semantic_tokens(a, None))),
        ),
        (
            "folding ranges",
            fastest(|| drop(folding::folding_ranges(a, text))),
        ),
        (
            "selection ranges",
            fastest(|| drop(selection::selection_ranges(a, text, at))),
        ),
    ];
    for (what, took) in timings {
        eprintln!("{what}: {took:?}");
        assert!(took < Duration::from_millis(100), "{what} took {took:?}");
    }
}
