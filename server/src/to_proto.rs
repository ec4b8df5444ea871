//! The library's editor vocabulary ([`semo::ide`]) in protocol types: the
//! one place that knows both. Handlers ask the workspace analysis
//! (`Snapshot::host`) and hand its answers here.

use crate::encoding::LineMap;
use crate::world::Snapshot;
use semo::diag::FileId;
use semo::host::Analysis;
use semo::ide::{self, CompletionKind, HoverResult, NavigationTarget, SourceChange};
use semo::text::LineIndex;
use std::collections::HashMap;
use tower_lsp_server::ls_types::*;

pub fn hover(found: HoverResult, lines: &LineMap<'_>) -> Hover {
    Hover {
        contents: HoverContents::Markup(markdown(found.markdown)),
        range: Some(lines.range(found.range)),
    }
}

fn markdown(value: String) -> MarkupContent {
    MarkupContent {
        kind: MarkupKind::Markdown,
        value,
    }
}

/// A complete list (the server sends every candidate, the editor filters),
/// kept in the library's order (most specific first) rather than the
/// editor's alphabetical one.
pub fn completion_list(items: Vec<ide::CompletionItem>, lines: &LineMap<'_>) -> CompletionResponse {
    let items = items
        .into_iter()
        .enumerate()
        .map(|(index, item)| completion_item(index, item, lines))
        .collect();
    CompletionResponse::List(CompletionList {
        is_incomplete: false,
        items,
    })
}

fn completion_item(index: usize, item: ide::CompletionItem, lines: &LineMap<'_>) -> CompletionItem {
    CompletionItem {
        kind: Some(completion_kind(item.kind)),
        detail: item.detail,
        documentation: item
            .documentation
            .map(|value| Documentation::MarkupContent(markdown(value))),
        insert_text_format: Some(match item.snippet {
            true => InsertTextFormat::SNIPPET,
            false => InsertTextFormat::PLAIN_TEXT,
        }),
        sort_text: Some(format!("{index:05}")),
        filter_text: Some(item.label.clone()),
        text_edit: Some(CompletionTextEdit::Edit(TextEdit {
            range: lines.range(item.replace),
            new_text: item.insert,
        })),
        label: item.label,
        ..CompletionItem::default()
    }
}

pub fn completion_kind(kind: CompletionKind) -> CompletionItemKind {
    use CompletionKind as K;
    match kind {
        K::BuiltinService | K::Function => CompletionItemKind::FUNCTION,
        K::Value | K::Port => CompletionItemKind::FIELD,
        K::TeamVariable | K::Robot => CompletionItemKind::VARIABLE,
        K::Team | K::User | K::Task => CompletionItemKind::MODULE,
        K::RobotType | K::Element => CompletionItemKind::CLASS,
        K::Capability | K::Attribute => CompletionItemKind::PROPERTY,
        K::Plan => CompletionItemKind::STRUCT,
        K::Service => CompletionItemKind::METHOD,
        K::Mode | K::Choice | K::Action => CompletionItemKind::ENUM_MEMBER,
        K::Event => CompletionItemKind::EVENT,
        K::Constant => CompletionItemKind::CONSTANT,
        K::Unit => CompletionItemKind::UNIT,
        K::Keyword => CompletionItemKind::KEYWORD,
        K::Snippet => CompletionItemKind::SNIPPET,
    }
}

/// Per file, its edits in protocol ranges (the caller names the files).
pub type FileEdits = Vec<(FileId, Vec<TextEdit>)>;

/// A change of several files: per file, its edits in protocol ranges.
pub fn source_change(
    snapshot: &Snapshot,
    workspace: &Analysis,
    lines: &LineMap<'_>,
    change: SourceChange,
) -> FileEdits {
    change
        .edits
        .into_iter()
        .map(|(file, edits)| {
            let targets = edits
                .iter()
                .map(|e| NavigationTarget { file, span: e.span })
                .collect();
            let ranges = target_ranges(snapshot, workspace, lines, targets);
            let edits = ranges
                .into_iter()
                .zip(edits)
                .map(|((_, range), e)| TextEdit::new(range, e.new_text))
                .collect();
            (file, edits)
        })
        .collect()
}

/// Targets as ranges of their files (the snapshot's own text, or another
/// file of the workspace analysis); targets in files it does not hold are
/// left out.
pub fn target_ranges(
    snapshot: &Snapshot,
    workspace: &Analysis,
    lines: &LineMap<'_>,
    targets: Vec<NavigationTarget>,
) -> Vec<(FileId, Range)> {
    let mut indexes: HashMap<FileId, LineIndex> = HashMap::new();
    targets
        .into_iter()
        .filter_map(|t| {
            if t.file == snapshot.id {
                return Some((t.file, lines.range(t.span)));
            }
            let text = &*workspace.file(t.file)?.text;
            let index = indexes
                .entry(t.file)
                .or_insert_with(|| LineIndex::new(text));
            let map = LineMap {
                text,
                index,
                encoding: snapshot.encoding,
            };
            Some((t.file, map.range(t.span)))
        })
        .collect()
}
