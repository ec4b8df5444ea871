//! Parses and checks arbitrary text as a mission: must never panic, and every
//! diagnostic range must lie inside the text on character boundaries.
#![no_main]

use libfuzzer_sys::fuzz_target;
use semo::catalog::builtin_catalog;
use semo::diag::FileId;
use std::sync::OnceLock;

fuzz_target!(|data: &[u8]| {
    static CATALOG: OnceLock<semo::catalog::Catalog> = OnceLock::new();
    let catalog = CATALOG.get_or_init(builtin_catalog);
    let text = String::from_utf8_lossy(data);
    let analysis = semo::check_source(FileId(0), &text, catalog);
    for d in &analysis.diagnostics {
        assert!(d.span.start <= d.span.end && d.span.end <= text.len());
        assert!(text.is_char_boundary(d.span.start) && text.is_char_boundary(d.span.end));
    }
});
