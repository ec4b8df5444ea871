//! `textDocument/signatureHelp`: [`semo::host::Analysis::signature_help`] in protocol types.

use crate::encoding::Encoding;
use crate::world::Snapshot;
use semo::host::Analysis;
use tower_lsp_server::ls_types::*;

pub fn signature_help(
    snapshot: &Snapshot,
    workspace: &Analysis,
    position: Position,
) -> Option<SignatureHelp> {
    let analysis = snapshot.analysis();
    let lines = snapshot.line_map(&analysis);
    let help = workspace.signature_help(snapshot.position(&lines, position))?;
    // Parameter offsets count in the negotiated encoding, as positions do.
    let units = |s: &str| -> u32 {
        match snapshot.encoding {
            Encoding::Utf8 => s.len() as u32,
            Encoding::Utf16 => s.encode_utf16().count() as u32,
        }
    };
    let parameters = help
        .parameters
        .iter()
        .map(|(range, doc)| ParameterInformation {
            label: ParameterLabel::LabelOffsets([
                units(&help.label[..range.start]),
                units(&help.label[..range.end]),
            ]),
            documentation: doc.clone().map(markdown),
        })
        .collect();
    let active = help.active_parameter.map(|i| i as u32);
    Some(SignatureHelp {
        signatures: vec![SignatureInformation {
            label: help.label,
            documentation: help.documentation.map(markdown),
            parameters: Some(parameters),
            active_parameter: active,
        }],
        active_signature: Some(0),
        active_parameter: active,
    })
}

fn markdown(value: String) -> Documentation {
    Documentation::MarkupContent(MarkupContent {
        kind: MarkupKind::Markdown,
        value,
    })
}
