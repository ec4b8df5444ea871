//! One module per request: each translates protocol types to library calls on
//! a [`Snapshot`](crate::world::Snapshot) and back.

pub mod catalog;
pub mod code_actions;
pub mod completion;
pub mod formatting;
pub mod hover;
pub mod inlay_hints;
pub mod signature_help;
pub mod taskgraph;

use crate::encoding::Encoding;
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
            // `"` opens a value in task-graph files (`src="`).
            trigger_characters: Some(
                [".", "(", "=", ",", ":", "[", "\""]
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
            code_action_kinds: Some(vec![CodeActionKind::QUICKFIX]),
            ..Default::default()
        })),
        ..Default::default()
    }
}
