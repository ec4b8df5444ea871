//! `textDocument/selectionRange`: for each position, the ranges holding it
//! from the name outward to the file (`host::Analysis::selection_ranges`).

use crate::world::Snapshot;
use tower_lsp_server::ls_types::{Position, SelectionRange};

pub fn selection_range(snapshot: &Snapshot, positions: &[Position]) -> Option<Vec<SelectionRange>> {
    super::with_mission(snapshot, |_, lines| {
        positions
            .iter()
            .map(|&position| {
                let offset = lines.offset(position);
                let at = snapshot.position(&lines, position);
                let spans = snapshot.host().selection_ranges(at);
                let mut chain: Option<Box<SelectionRange>> = None;
                for span in spans.iter().rev() {
                    chain = Some(Box::new(SelectionRange {
                        range: lines.range(*span),
                        parent: chain,
                    }));
                }
                chain.map_or(
                    SelectionRange {
                        range: lines.range(semo::span::Span::new(offset, offset)),
                        parent: None,
                    },
                    |innermost| *innermost,
                )
            })
            .collect()
    })
}
