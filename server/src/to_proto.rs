//! The library's editor vocabulary ([`semo::ide`]) in protocol types: the
//! one place that knows both. Handlers ask the workspace analysis
//! (`Snapshot::host`) and hand its answers here.

use crate::encoding::{Encoding, LineMap};
use crate::world::Snapshot;
use semo::diag::{Code, FileId, Severity};
use semo::host::Analysis;
use semo::ide::{
    self, Access, CompletionKind, Fold, FoldKind, HighlightToken, HoverResult, InlayKind,
    NavigationTarget, Reference, SourceChange, StructureNode, TokenKind,
};
use semo::span::Span;
use semo::text::{ColumnUnit, LineIndex};
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
        K::TeamVariable | K::Robot | K::Parameter | K::Result => CompletionItemKind::VARIABLE,
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

/// The library's quick fixes as protocol actions: each an edit of the file
/// (`uri`), attached to the client's copy of the diagnostic it fixes when
/// the request carries it (same code and range), else to the diagnostic as
/// published (`published`, in the order of `Analysis::diagnostics`).
pub fn quick_fixes(
    uri: &Uri,
    lines: &LineMap<'_>,
    published: &[Diagnostic],
    from_client: &[Diagnostic],
    actions: Vec<ide::CodeAction>,
) -> Vec<CodeActionOrCommand> {
    actions
        .into_iter()
        .filter_map(|action| {
            let ours = published.get(action.diagnostic)?;
            let diagnostic = from_client
                .iter()
                .find(|d| d.range == ours.range && d.code == ours.code)
                .unwrap_or(ours)
                .clone();
            let edits = text_edits(action.edits, lines);
            Some(CodeActionOrCommand::CodeAction(CodeAction {
                title: action.title,
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![diagnostic]),
                edit: Some(WorkspaceEdit {
                    changes: Some(HashMap::from([(uri.clone(), edits)])),
                    ..WorkspaceEdit::default()
                }),
                is_preferred: Some(action.preferred),
                ..CodeAction::default()
            }))
        })
        .collect()
}

/// An assist (`ide::Assist`) whose edits are in protocol ranges and named files.
pub fn assist(title: String, changes: HashMap<Uri, Vec<TextEdit>>) -> CodeActionOrCommand {
    CodeActionOrCommand::CodeAction(CodeAction {
        title,
        kind: Some(CodeActionKind::REFACTOR),
        edit: Some(WorkspaceEdit {
            changes: Some(changes),
            ..WorkspaceEdit::default()
        }),
        ..CodeAction::default()
    })
}

/// Edits of the file `lines` maps.
pub fn text_edits(edits: Vec<ide::TextEdit>, lines: &LineMap<'_>) -> Vec<TextEdit> {
    edits
        .into_iter()
        .map(|e| TextEdit::new(lines.range(e.span), e.new_text))
        .collect()
}

pub fn highlights(found: Vec<Reference>, lines: &LineMap<'_>) -> Vec<DocumentHighlight> {
    found
        .into_iter()
        .map(|r| DocumentHighlight {
            range: lines.range(r.span),
            kind: Some(match r.access {
                Access::Write => DocumentHighlightKind::WRITE,
                Access::Read => DocumentHighlightKind::READ,
            }),
        })
        .collect()
}

pub fn symbol_kind(kind: ide::SymbolKind) -> SymbolKind {
    use ide::SymbolKind as K;
    match kind {
        K::Team => SymbolKind::CLASS,
        K::Robot | K::Value => SymbolKind::FIELD,
        K::Plan => SymbolKind::NAMESPACE,
        K::Service | K::Function => SymbolKind::FUNCTION,
        K::Mode | K::Action => SymbolKind::ENUM_MEMBER,
        K::Main => SymbolKind::EVENT,
        K::Result => SymbolKind::VARIABLE,
    }
}

/// An outline, nested.
pub fn document_symbols(
    outline: Vec<StructureNode>,
    lines: &LineMap<'_>,
) -> DocumentSymbolResponse {
    DocumentSymbolResponse::Nested(outline.iter().map(|s| document_symbol(s, lines)).collect())
}

fn document_symbol(symbol: &StructureNode, lines: &LineMap<'_>) -> DocumentSymbol {
    #[allow(deprecated)] // `deprecated` must be written, even as None
    DocumentSymbol {
        name: symbol.name.clone(),
        detail: symbol.detail.clone(),
        kind: symbol_kind(symbol.kind),
        tags: None,
        deprecated: None,
        range: lines.range(symbol.span),
        selection_range: lines.range(symbol.name_span),
        children: (!symbol.children.is_empty()).then(|| {
            symbol
                .children
                .iter()
                .map(|c| document_symbol(c, lines))
                .collect()
        }),
    }
}

/// A workspace-search result at `location` (its name).
pub fn symbol_information(symbol: ide::WorkspaceSymbol, location: Location) -> SymbolInformation {
    #[allow(deprecated)] // `deprecated` must be written, even as None
    SymbolInformation {
        name: symbol.name,
        kind: symbol_kind(symbol.kind),
        tags: None,
        deprecated: None,
        location,
        container_name: symbol.container,
    }
}

/// Folds as whole lines (no column to count in the client's encoding); a
/// fold within one line, or on the same lines as the one before it, is left
/// out (editors show one fold per line).
pub fn folding_ranges(folds: Vec<Fold>, lines: &LineMap<'_>) -> Vec<FoldingRange> {
    let line = |offset| {
        lines
            .index
            .line_col(lines.text, offset, ColumnUnit::Utf8)
            .line
    };
    let mut ranges: Vec<FoldingRange> = Vec::new();
    for fold in folds {
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
}

pub fn inlay_hint(hint: ide::InlayHint, lines: &LineMap<'_>) -> InlayHint {
    InlayHint {
        position: lines.position(hint.offset),
        label: InlayHintLabel::String(hint.label),
        kind: Some(match hint.kind {
            InlayKind::Robots => InlayHintKind::PARAMETER,
            InlayKind::Schedule | InlayKind::Repetitions => InlayHintKind::TYPE,
        }),
        text_edits: None,
        tooltip: hint
            .tooltip
            .map(|value| InlayHintTooltip::MarkupContent(markdown(value))),
        // A repetition count follows a quoted name: apart from it.
        padding_left: Some(hint.kind == InlayKind::Repetitions),
        padding_right: Some(false),
        data: None,
    }
}

/// The semantic-token legend announced at `initialize`: token types in
/// [`TokenKind::ALL`] order, modifiers in [`ide::TOKEN_MODIFIERS`] order
/// (the bit order of `HighlightToken::modifiers`).
pub fn semantic_tokens_legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TokenKind::ALL
            .iter()
            .map(|k| SemanticTokenType::new(k.name()))
            .collect(),
        token_modifiers: ide::TOKEN_MODIFIERS
            .iter()
            .map(|m| SemanticTokenModifier::new(m))
            .collect(),
    }
}

/// Sorted tokens in the protocol's relative encoding.
pub fn semantic_tokens(tokens: &[HighlightToken], lines: &LineMap<'_>) -> SemanticTokens {
    SemanticTokens {
        result_id: None,
        data: encode_tokens(lines.text, lines.index, lines.encoding, tokens),
    }
}

/// The relative encoding in one pass over the sorted tokens: the column is
/// carried forward along a line instead of recounted from its start.
fn encode_tokens(
    text: &str,
    index: &LineIndex,
    encoding: Encoding,
    tokens: &[HighlightToken],
) -> Vec<SemanticToken> {
    let units = |s: &str| -> u32 {
        match encoding {
            Encoding::Utf8 => s.len() as u32,
            Encoding::Utf16 => s.chars().map(|c| c.len_utf16() as u32).sum(),
        }
    };
    let slice = |span: Span| text.get(span.range()).unwrap_or("");
    let mut data = Vec::with_capacity(tokens.len());
    let (mut prev_line, mut prev_col) = (0u32, 0u32);
    let (mut line, mut next_line_start) = (0u32, index.line_start(1));
    // Where the column was last counted, and the column there.
    let (mut counted_to, mut col) = (0usize, 0u32);
    for token in tokens {
        let start = token.span.start.min(text.len());
        if start >= next_line_start || start < counted_to {
            line = index.line_col(text, start, ColumnUnit::Utf8).line;
            next_line_start = index.line_start(line as usize + 1);
            counted_to = index.line_start(line as usize);
            col = 0;
        }
        col += units(slice(Span::new(counted_to, start)));
        counted_to = start;
        let length = units(slice(token.span));
        data.push(SemanticToken {
            delta_line: line.saturating_sub(prev_line),
            delta_start: if line == prev_line {
                col.saturating_sub(prev_col)
            } else {
                col
            },
            length,
            token_type: token.kind.index(),
            token_modifiers_bitset: token.modifiers,
        });
        (prev_line, prev_col) = (line, col);
    }
    data
}

/// `found` (diagnostics in the snapshot's file) as the protocol has them;
/// `others`: the URIs of the other files their related information points
/// into.
pub fn diagnostics(
    snapshot: &Snapshot,
    analysis: &crate::world::FileAnalysis,
    found: &[semo::diag::Diagnostic],
    others: &HashMap<FileId, Uri>,
) -> Vec<Diagnostic> {
    let here = snapshot.line_map(analysis);
    // Line indexes of other (catalog) files, built once each.
    let mut other_lines: HashMap<FileId, LineIndex> = HashMap::new();
    found
        .iter()
        .map(|d| {
            let related = d
                .related
                .iter()
                .filter_map(|r| {
                    let (uri, range) = if r.file == snapshot.id {
                        (snapshot.uri.clone(), here.range(r.span))
                    } else {
                        let uri = others.get(&r.file)?;
                        let text = snapshot.text_of(r.file)?;
                        let index = other_lines
                            .entry(r.file)
                            .or_insert_with(|| LineIndex::new(text));
                        let map = LineMap {
                            text,
                            index,
                            encoding: snapshot.encoding,
                        };
                        (uri.clone(), map.range(r.span))
                    };
                    Some(DiagnosticRelatedInformation {
                        location: Location::new(uri, range),
                        message: r.message.clone(),
                    })
                })
                .collect::<Vec<_>>();
            Diagnostic {
                related_information: (!related.is_empty()).then_some(related),
                ..self::diagnostic(d, here.range(d.span))
            }
        })
        .collect()
}

/// One diagnostic at `range`, without related information.
pub fn diagnostic(d: &semo::diag::Diagnostic, range: Range) -> Diagnostic {
    Diagnostic {
        range,
        severity: Some(severity(d.severity)),
        code: Some(NumberOrString::String(d.code.as_str().to_string())),
        source: Some("semo".to_string()),
        message: d.message.clone(),
        related_information: None,
        tags: is_unnecessary(d.code).then(|| vec![DiagnosticTag::UNNECESSARY]),
        // The did-you-mean travels with the diagnostic, for quick fixes.
        data: d
            .suggestion
            .as_ref()
            .map(|s| serde_json::json!({ "suggestion": s })),
        code_description: None,
    }
}

fn severity(s: Severity) -> DiagnosticSeverity {
    match s {
        Severity::Error => DiagnosticSeverity::ERROR,
        Severity::Warning => DiagnosticSeverity::WARNING,
        Severity::Hint => DiagnosticSeverity::HINT,
    }
}

/// Code that is never used: editors grey it out.
fn is_unnecessary(code: Code) -> bool {
    matches!(
        code,
        Code::ServiceNeverSet | Code::FunctionNeverCalled | Code::UnreachableMode
    )
}

/// `textDocument/codeAction` on `semo verify`'s findings: for each
/// counterexample whose diagnostic is among those `asked` about, an action
/// that writes its scenario beside the mission. The file is created, never
/// overwritten (a file of that name stays as it is: the editor refuses the
/// edit).
pub fn scenario_actions(
    found: Vec<crate::verify::Counterexample>,
    lines: &LineMap<'_>,
    asked: &[Diagnostic],
) -> Vec<CodeActionOrCommand> {
    let mut actions = Vec::new();
    for example in found {
        let d = &example.diagnostic;
        let range = lines.range(d.span);
        let Some(diagnostic) = asked.iter().find(|a| {
            a.range == range && a.code == Some(NumberOrString::String(d.code.as_str().into()))
        }) else {
            continue;
        };
        let create = DocumentChangeOperation::Op(ResourceOp::Create(CreateFile {
            uri: example.uri.clone(),
            options: Some(CreateFileOptions {
                overwrite: Some(false),
                ignore_if_exists: Some(false),
            }),
            annotation_id: None,
        }));
        let write = DocumentChangeOperation::Edit(TextDocumentEdit {
            text_document: OptionalVersionedTextDocumentIdentifier {
                uri: example.uri,
                version: None,
            },
            edits: vec![OneOf::Left(TextEdit {
                range: Range::default(),
                new_text: example.scenario,
            })],
        });
        actions.push(CodeActionOrCommand::CodeAction(CodeAction {
            title: format!(
                "Write the scenario that shows this ({}.scenario.json; semo simulate replays it)",
                example.name
            ),
            kind: Some(CodeActionKind::QUICKFIX),
            diagnostics: Some(vec![diagnostic.clone()]),
            edit: Some(WorkspaceEdit {
                document_changes: Some(DocumentChanges::Operations(vec![create, write])),
                ..WorkspaceEdit::default()
            }),
            ..CodeAction::default()
        }));
    }
    actions
}
