//! Loads arbitrary text as a `*.robot.xml` catalog file: must never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use semo::catalog::{load_catalog, CatalogSource};
use semo::diag::FileId;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let (_, diagnostics) = load_catalog(&[CatalogSource {
        file: FileId(0),
        text: &text,
        base_dir: None,
    }]);
    for d in &diagnostics {
        assert!(d.span.end <= text.len());
    }
});
