//! `textDocument/codeAction`: the quick fixes of [`semo::ide::mission::code_actions`],
//! each attached to the diagnostic it fixes.
//!
//! Fixes are computed from the snapshot's own diagnostics (so that their
//! edits match the text the server has); each is attached to the client's
//! copy of its diagnostic when the request carries it (same code and range),
//! else to the diagnostic as the server publishes it. In a mission, a
//! `refactor` action also creates the strategy entry of the built-in call at
//! the cursor (see [`super::strategy::create_entries`]).

use crate::diagnostics;
use crate::world::{FileAnalysis, Snapshot};
use semo::workspace::FileKind;
use std::collections::HashMap;
use std::sync::Arc;
use tower_lsp_server::ls_types::*;

pub fn code_actions(
    snapshot: &Snapshot,
    strategies: &[Arc<Snapshot>],
    params: &CodeActionParams,
) -> Option<CodeActionResponse> {
    let wanted = |kind: &CodeActionKind| {
        params.context.only.as_ref().is_none_or(|only| {
            only.iter()
                .any(|k| k.as_str().is_empty() || kind.as_str().starts_with(k.as_str()))
        })
    };
    let mut assists = Vec::new();
    if wanted(&CodeActionKind::REFACTOR) && snapshot.kind == FileKind::Mission {
        assists = super::strategy::create_entries(snapshot, strategies, params.range);
    }
    if !wanted(&CodeActionKind::QUICKFIX) {
        return Some(assists);
    }
    if snapshot.kind == FileKind::Strategy {
        return Some(super::strategy::code_actions(snapshot, params));
    }
    let analysis = snapshot.analysis();
    let Some(mission) = analysis.mission.as_ref() else {
        return Some(assists);
    };
    let lines = snapshot.line_map(&analysis);
    let span = lines.span(params.range);
    let catalog = snapshot.catalog.catalog();
    let actions =
        semo::ide::mission::code_actions::code_actions(mission, catalog, &snapshot.text, span);
    if actions.is_empty() {
        return Some(assists);
    }
    let response = quick_fixes(snapshot, &analysis, params, actions)
        .into_iter()
        .chain(assists)
        .collect();
    Some(response)
}

/// The library's fixes as protocol actions: each edit of the snapshot's text,
/// attached to the client's copy of the diagnostic it fixes when the request
/// carries it (same code and range), else to the diagnostic as published.
pub fn quick_fixes(
    snapshot: &Snapshot,
    analysis: &FileAnalysis,
    params: &CodeActionParams,
    actions: Vec<semo::ide::mission::code_actions::CodeAction>,
) -> Vec<CodeActionOrCommand> {
    let lines = snapshot.line_map(analysis);
    let published = diagnostics::to_lsp(snapshot, analysis, &HashMap::new());
    actions
        .into_iter()
        .filter_map(|action| {
            let ours = published.get(action.diagnostic)?;
            let diagnostic = params
                .context
                .diagnostics
                .iter()
                .find(|d| d.range == ours.range && d.code == ours.code)
                .unwrap_or(ours)
                .clone();
            let edits = action
                .edits
                .into_iter()
                .map(|e| TextEdit {
                    range: lines.range(e.span),
                    new_text: e.new_text,
                })
                .collect();
            Some(CodeActionOrCommand::CodeAction(CodeAction {
                title: action.title,
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![diagnostic]),
                edit: Some(WorkspaceEdit {
                    changes: Some(HashMap::from([(snapshot.uri.clone(), edits)])),
                    ..WorkspaceEdit::default()
                }),
                is_preferred: Some(action.preferred),
                ..CodeAction::default()
            }))
        })
        .collect()
}
