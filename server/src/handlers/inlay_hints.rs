//! `textDocument/inlayHint`: [`semo::host::Analysis::inlay_hints`] (a
//! mission's group arms and set services, a task graph's repetition counts)
//! in protocol types.

use crate::to_proto;
use crate::world::Snapshot;
use semo::workspace::FileKind;
use tower_lsp_server::ls_types::{InlayHint, Range};

pub fn inlay_hints(snapshot: &Snapshot, range: Range) -> Option<Vec<InlayHint>> {
    if !matches!(snapshot.kind, FileKind::Mission | FileKind::TaskGraph) {
        return None;
    }
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let hints = snapshot.host().inlay_hints(snapshot.id, lines.span(range));
    Some(
        hints
            .into_iter()
            .map(|h| to_proto::inlay_hint(h, &lines))
            .collect(),
    )
}
