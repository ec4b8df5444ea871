//! `textDocument/semanticTokens/full` and `/range` (one file: they share the
//! legend and the encoding). Every resolved name is a token: its kind says
//! what it is (team, robotType, plan, service, mode, event, value, constant,
//! function, variable, ...), `declaration` marks definitions and
//! `defaultLibrary` names from the robot catalog (built-in services, robot
//! types, values) and `USER`.

use crate::encoding::Encoding;
use crate::world::Snapshot;
use semo::ide::mission::semantic_tokens::{self as ide, HighlightToken, TokenKind};
use semo::span::Span;
use semo::text::{ColumnUnit, LineIndex};
use tower_lsp_server::ls_types::{
    Range, SemanticToken, SemanticTokenModifier, SemanticTokenType, SemanticTokens,
    SemanticTokensLegend,
};

/// The legend announced at `initialize`: token types in [`TokenKind::ALL`]
/// order, modifiers in [`ide::MODIFIERS`] order.
pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TokenKind::ALL
            .iter()
            .map(|k| SemanticTokenType::new(k.name()))
            .collect(),
        token_modifiers: ide::MODIFIERS
            .iter()
            .map(|m| SemanticTokenModifier::new(m))
            .collect(),
    }
}

/// The tokens of the whole file (`range` `None`) or of a range of it.
pub fn semantic_tokens(snapshot: &Snapshot, range: Option<Range>) -> Option<SemanticTokens> {
    let analysis = snapshot.analysis();
    let mission = analysis.mission.as_ref()?;
    let span = range.map(|r| snapshot.line_map(&analysis).span(r));
    let tokens = ide::semantic_tokens(mission, span);
    Some(SemanticTokens {
        result_id: None,
        data: encode(&snapshot.text, &analysis.lines, snapshot.encoding, &tokens),
    })
}

/// The protocol's relative encoding, in one pass over the sorted tokens: the
/// column is carried forward along a line instead of recounted from its start.
fn encode(
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
