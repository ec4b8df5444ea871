//! Completion, hover, navigation, outline and fixes in `*.strategy.xml`
//! files: [`semo::ide::strategy`] in protocol types. The request handlers
//! hand strategy files over to these; a strategy snapshot carries the
//! missions it was checked against, so names lead into them.

use crate::encoding::LineMap;
use crate::to_proto;
use crate::world::{FileAnalysis, Snapshot};
use semo::Analysis;
use semo::diag::FileId;
use semo::ide::strategy::{self as ide, StrategyFile};
use std::collections::HashMap;
use std::sync::Arc;
use tower_lsp_server::ls_types::*;

/// Runs `f` on the strategy file of `snapshot` with its missions analysed.
fn with_file<T>(
    snapshot: &Snapshot,
    f: impl FnOnce(&StrategyFile<'_>, &FileAnalysis, LineMap<'_>) -> T,
) -> T {
    let analysis = snapshot.analysis();
    let analyses: Vec<Arc<FileAnalysis>> = snapshot.missions.iter().map(|m| m.analysis()).collect();
    let missions: Vec<&Analysis> = analyses
        .iter()
        .filter_map(|a| a.mission.as_deref())
        .collect();
    let file = StrategyFile {
        text: &snapshot.text,
        strategy: analysis.strategy.as_ref(),
        missions: &missions,
        catalog: snapshot.catalog.catalog(),
    };
    f(&file, &analysis, snapshot.line_map(&analysis))
}

pub fn references(
    snapshot: &Snapshot,
    position: Position,
    include_declaration: bool,
) -> Vec<Location> {
    let targets = with_file(snapshot, |file, analysis, lines| {
        let offset = lines.offset(position);
        ide::navigation::references(file, &analysis.strategy_links, offset, include_declaration)
    });
    let uri_of = |id: FileId| {
        if id == snapshot.id {
            return Some(snapshot.uri.clone());
        }
        snapshot
            .missions
            .iter()
            .find(|m| m.id == id)
            .map(|m| m.uri.clone())
    };
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    to_proto::target_ranges(snapshot, snapshot.host(), &lines, targets)
        .into_iter()
        .filter_map(|(file, range)| Some(Location::new(uri_of(file)?, range)))
        .collect()
}

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
