//! Helpers for the unit tests of the IDE features: a mission analysed against
//! the built-in catalog (and optionally one catalog file), and readable spans.

use crate::CheckedMission;
use crate::catalog::{Catalog, CatalogSource, load_catalog};
use crate::diag::FileId;
use crate::span::Span;
use crate::text::{ColumnUnit, LineIndex};

pub(crate) struct Fixture {
    pub text: String,
    pub analysis: CheckedMission,
    pub catalog: Catalog,
}

impl Fixture {
    pub const FILE: FileId = FileId(0);
    pub const CATALOG_FILE: FileId = FileId(1);

    pub fn new(text: &str) -> Fixture {
        Fixture::build(text, &[])
    }

    pub fn with_catalog(text: &str, xml: &str) -> Fixture {
        Fixture::build(
            text,
            &[CatalogSource {
                file: Fixture::CATALOG_FILE,
                text: xml,
                base_dir: None,
            }],
        )
    }

    fn build(text: &str, sources: &[CatalogSource<'_>]) -> Fixture {
        let (catalog, diagnostics) = load_catalog(sources);
        assert!(diagnostics.is_empty(), "{diagnostics:#?}");
        let analysis = crate::check_source(Fixture::FILE, text, &catalog);
        Fixture {
            text: text.to_string(),
            analysis,
            catalog,
        }
    }

    /// The offset where `marker` starts; it must occur exactly once.
    pub fn offset_of(&self, marker: &str) -> usize {
        let mut found = self.text.match_indices(marker);
        let (offset, _) = found.next().unwrap_or_else(|| panic!("no `{marker}`"));
        assert!(found.next().is_none(), "`{marker}` occurs twice");
        offset
    }

    /// One-based line and column (in bytes) of an offset.
    pub fn line_col(&self, offset: usize) -> (u32, u32) {
        line_col(&self.text, offset)
    }
}

fn line_col(text: &str, offset: usize) -> (u32, u32) {
    let lc = LineIndex::new(text).line_col(text, offset, ColumnUnit::Utf8);
    (lc.line + 1, lc.col + 1)
}

/// `line:col text` of each span, comma-separated.
pub(crate) fn spans_text(text: &str, spans: impl IntoIterator<Item = Span>) -> String {
    spans
        .into_iter()
        .map(|s| {
            let (line, col) = line_col(text, s.start);
            format!("{line}:{col} {}", &text[s.range()])
        })
        .collect::<Vec<_>>()
        .join(", ")
}
