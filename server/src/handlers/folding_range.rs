//! `textDocument/foldingRange`: blocks, `case`s, group statements and comment
//! banners spanning lines (`host::Analysis::folding_ranges`), as whole lines.

use crate::to_proto;
use crate::world::Snapshot;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::FoldingRange;

pub fn folding_range(snapshot: &Snapshot) -> Option<Vec<FoldingRange>> {
    if snapshot.kind != FileKind::Mission {
        return None;
    }
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let folds = snapshot.host().folding_ranges(snapshot.id);
    Some(to_proto::folding_ranges(folds, &lines))
}
