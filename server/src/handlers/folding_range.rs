//! `textDocument/foldingRange`: blocks, `case`s, group statements and comment
//! banners spanning lines (`host::Analysis::folding_ranges`), as whole lines.

use crate::world::Snapshot;
use semo::ide::mission::folding::FoldKind;
use semo::text::ColumnUnit;
use tower_lsp_server::ls_types::{FoldingRange, FoldingRangeKind};

pub fn folding_range(snapshot: &Snapshot) -> Option<Vec<FoldingRange>> {
    super::with_mission(snapshot, |_, lines| {
        // Whole lines: no column to count in the client's encoding.
        let line = |offset| {
            lines
                .index
                .line_col(lines.text, offset, ColumnUnit::Utf8)
                .line
        };
        let mut ranges: Vec<FoldingRange> = Vec::new();
        for fold in snapshot.host().folding_ranges(snapshot.id) {
            let (start_line, end_line) = (line(fold.span.start), line(fold.span.end));
            let duplicate = ranges
                .iter()
                .rev()
                .take_while(|r| r.start_line == start_line)
                .any(|r| r.end_line == end_line);
            if end_line <= start_line || duplicate {
                continue;
            }
            ranges.push(FoldingRange {
                start_line,
                end_line,
                kind: match fold.kind {
                    FoldKind::Comment => Some(FoldingRangeKind::Comment),
                    FoldKind::Block => None,
                },
                ..FoldingRange::default()
            });
        }
        ranges
    })
}
