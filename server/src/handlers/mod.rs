//! One module per request: each translates protocol types to library calls on
//! a [`Snapshot`](crate::world::Snapshot) and back.

pub mod catalog;
pub mod code_actions;
pub mod completion;
pub mod definition;
pub mod document_highlight;
pub mod document_symbol;
pub mod folding_range;
pub mod formatting;
pub mod generate_code;
pub mod graph_svg;
pub mod hover;
pub mod inlay_hints;
pub mod monitor;
pub mod prepare_rename;
pub mod references;
pub mod rename;
pub mod scenario;
pub mod selection_range;
pub mod semantic_tokens;
pub mod signature_help;
pub mod simulate;
pub mod verify_mission;
pub mod workspace_symbol;

use crate::encoding::{Encoding, LineMap};
use crate::world::Snapshot;
use semo::CheckedMission;
use tower_lsp_server::jsonrpc;
use tower_lsp_server::ls_types::*;

/// What this server can do, announced at `initialize`.
pub fn capabilities(encoding: Encoding) -> ServerCapabilities {
    ServerCapabilities {
        position_encoding: Some(encoding.kind()),
        document_formatting_provider: Some(OneOf::Left(true)),
        text_document_sync: Some(TextDocumentSyncCapability::Options(
            TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(TextDocumentSyncKind::INCREMENTAL),
                save: Some(TextDocumentSyncSaveOptions::Supported(true)),
                ..Default::default()
            },
        )),
        completion_provider: Some(CompletionOptions {
            // `"` opens a value in XML files (`src="`), `<` an element in
            // strategy files.
            trigger_characters: Some(
                [".", "(", "=", ",", ":", "[", "\"", "<"]
                    .map(String::from)
                    .to_vec(),
            ),
            ..Default::default()
        }),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        signature_help_provider: Some(SignatureHelpOptions {
            trigger_characters: Some(["(", ","].map(String::from).to_vec()),
            ..Default::default()
        }),
        inlay_hint_provider: Some(OneOf::Left(true)),
        code_action_provider: Some(CodeActionProviderCapability::Options(CodeActionOptions {
            code_action_kinds: Some(vec![CodeActionKind::QUICKFIX, CodeActionKind::REFACTOR]),
            ..Default::default()
        })),
        // Navigation and structure.
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        document_highlight_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: WorkDoneProgressOptions::default(),
        })),
        document_symbol_provider: Some(OneOf::Left(true)),
        workspace_symbol_provider: Some(OneOf::Left(true)),
        semantic_tokens_provider: Some(SemanticTokensServerCapabilities::SemanticTokensOptions(
            SemanticTokensOptions {
                legend: crate::to_proto::semantic_tokens_legend(),
                range: Some(true),
                full: Some(SemanticTokensFullOptions::Bool(true)),
                ..Default::default()
            },
        )),
        folding_range_provider: Some(FoldingRangeProviderCapability::Simple(true)),
        selection_range_provider: Some(SelectionRangeProviderCapability::Simple(true)),
        // Code generation.
        code_lens_provider: Some(CodeLensOptions {
            resolve_provider: Some(false),
        }),
        execute_command_provider: Some(ExecuteCommandOptions {
            commands: vec![
                generate_code::COMMAND.to_string(),
                simulate::COMMAND.to_string(),
                verify_mission::COMMAND.to_string(),
            ],
            work_done_progress_options: WorkDoneProgressOptions {
                work_done_progress: Some(true),
            },
        }),
        ..Default::default()
    }
}

/// Runs `f` on the analysed mission of a snapshot; `None` for files that are
/// not missions (catalogs, task graphs).
pub fn with_mission<T>(
    snapshot: &Snapshot,
    f: impl FnOnce(&CheckedMission, LineMap<'_>) -> T,
) -> Option<T> {
    let analysis = snapshot.analysis();
    let mission = analysis.mission.as_ref()?;
    Some(f(mission, snapshot.line_map(&analysis)))
}

/// The protocol's `RequestFailed`: a valid request that cannot be carried
/// out, with the reason for the user.
pub fn request_failed(message: String) -> jsonrpc::Error {
    jsonrpc::Error {
        code: jsonrpc::ErrorCode::ServerError(-32803),
        message: message.into(),
        data: None,
    }
}
