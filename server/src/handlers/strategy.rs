//! The outline and fixes of `*.strategy.xml` files, and a mission's fix
//! creating a strategy entry: [`semo::ide::strategy`] in protocol types (the
//! features not yet behind `semo::host::Analysis`'s position queries).

use crate::encoding::LineMap;
use crate::world::Snapshot;
use semo::ide::strategy as ide;
use std::collections::HashMap;
use std::sync::Arc;
use tower_lsp_server::ls_types::*;

/// The strategy snapshots checked against this very version of `mission`
/// (whose links and positions therefore point into it).
fn checked_against<'s>(
    mission: &'s Snapshot,
    strategies: &'s [Arc<Snapshot>],
) -> impl Iterator<Item = &'s Arc<Snapshot>> {
    strategies
        .iter()
        .filter(move |s| s.missions.iter().any(|m| std::ptr::eq(&**m, mission)))
}

pub fn document_symbol(snapshot: &Snapshot) -> Option<DocumentSymbolResponse> {
    let analysis = snapshot.analysis();
    let strategy = analysis.strategy.as_ref()?;
    let lines = snapshot.line_map(&analysis);
    let symbols = ide::symbols::document_symbols(strategy);
    Some(DocumentSymbolResponse::Nested(
        symbols.iter().map(|s| symbol(s, &lines)).collect(),
    ))
}

fn symbol(s: &ide::symbols::Symbol, lines: &LineMap<'_>) -> DocumentSymbol {
    use ide::symbols::SymbolKind as K;
    #[allow(deprecated)] // `deprecated` must be written, even as None
    DocumentSymbol {
        name: s.name.clone(),
        detail: s.detail.clone(),
        kind: match s.kind {
            K::Value => SymbolKind::FIELD,
            K::Service => SymbolKind::FUNCTION,
            K::Action => SymbolKind::ENUM_MEMBER,
        },
        tags: None,
        deprecated: None,
        range: lines.range(s.span),
        selection_range: lines.range(s.name_span),
        children: (!s.children.is_empty())
            .then(|| s.children.iter().map(|c| symbol(c, lines)).collect()),
    }
}

/// The quick fixes of the strategy's diagnostics that touch `range`.
pub fn code_actions(snapshot: &Snapshot, params: &CodeActionParams) -> Vec<CodeActionOrCommand> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let span = lines.span(params.range);
    let actions = ide::code_actions::code_actions(&snapshot.text, analysis.diagnostics(), span);
    if actions.is_empty() {
        return Vec::new();
    }
    super::code_actions::quick_fixes(snapshot, &analysis, params, actions)
}

/// From a mission: create the entry of the built-in call in `range` in each
/// strategy file of its team that does not refine it yet.
pub fn create_entries(
    mission: &Snapshot,
    strategies: &[Arc<Snapshot>],
    range: Range,
) -> Vec<CodeActionOrCommand> {
    let analysis = mission.analysis();
    let Some(checked) = analysis.mission.as_ref() else {
        return Vec::new();
    };
    let offset = mission.line_map(&analysis).offset(range.start);
    let catalog = mission.catalog.catalog();
    let mut out = Vec::new();
    for strategy in checked_against(mission, strategies) {
        let s_analysis = strategy.analysis();
        let Some(model) = &s_analysis.strategy else {
            continue;
        };
        let Some(found) = ide::code_actions::create_entry(
            checked,
            catalog,
            offset,
            model,
            &strategy.text,
            &s_analysis.strategy_links,
        ) else {
            continue;
        };
        let lines = strategy.line_map(&s_analysis);
        let edit = TextEdit {
            range: lines.range(found.edit.span),
            new_text: found.edit.new_text,
        };
        out.push(CodeActionOrCommand::CodeAction(CodeAction {
            title: found.title,
            kind: Some(CodeActionKind::REFACTOR),
            edit: Some(WorkspaceEdit {
                changes: Some(HashMap::from([(strategy.uri.clone(), vec![edit])])),
                ..WorkspaceEdit::default()
            }),
            ..CodeAction::default()
        }));
    }
    out
}
