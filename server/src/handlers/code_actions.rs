//! `textDocument/codeAction`: the workspace analysis' quick fixes
//! ([`semo::host::Analysis::code_actions`]), each attached to the diagnostic
//! it fixes, then its assists ([`semo::host::Analysis::assists`]: in a
//! mission, creating the strategy entry of the built-in call at the cursor).
//! The caller names the files of the assists' edits.

use crate::to_proto::{self, FileEdits};
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::host::Analysis;
use std::collections::HashMap;
use tower_lsp_server::ls_types::*;

/// The actions found, before the files of the assists are named.
pub struct Found {
    fixes: Vec<CodeActionOrCommand>,
    assists: Vec<(String, FileEdits)>,
}

impl Found {
    /// The response, with each assist's files named by `uri_of` (a file it
    /// cannot name is left out of the edit).
    pub fn response(self, uri_of: impl Fn(FileId) -> Option<Uri>) -> CodeActionResponse {
        let assists = self.assists.into_iter().map(|(title, edits)| {
            let changes = edits
                .into_iter()
                .filter_map(|(file, edits)| Some((uri_of(file)?, edits)))
                .collect();
            to_proto::assist(title, changes)
        });
        self.fixes.into_iter().chain(assists).collect()
    }
}

pub fn code_actions(snapshot: &Snapshot, workspace: &Analysis, params: &CodeActionParams) -> Found {
    let wanted = |kind: &CodeActionKind| {
        params.context.only.as_ref().is_none_or(|only| {
            only.iter()
                .any(|k| k.as_str().is_empty() || kind.as_str().starts_with(k.as_str()))
        })
    };
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let mut found = Found {
        fixes: Vec::new(),
        assists: Vec::new(),
    };
    if wanted(&CodeActionKind::QUICKFIX) {
        let actions = workspace.code_actions(snapshot.id, lines.span(params.range));
        if !actions.is_empty() {
            let published =
                to_proto::diagnostics(snapshot, &analysis, analysis.diagnostics(), &HashMap::new());
            found.fixes = to_proto::quick_fixes(
                &snapshot.uri,
                &lines,
                &published,
                &params.context.diagnostics,
                actions,
            );
        }
    }
    if wanted(&CodeActionKind::REFACTOR) {
        let at = snapshot.position(&lines, params.range.start);
        found.assists = workspace
            .assists(at)
            .into_iter()
            .map(|a| {
                let edits = to_proto::source_change(snapshot, workspace, &lines, a.change);
                (a.title, edits)
            })
            .collect();
    }
    found
}
