//! `workspace/symbol`: the teams, composite services, modes and functions of
//! every mission the server knows (open, or indexed from the workspace
//! folders) whose name matches the query, best matches first
//! ([`semo::host::Analysis::workspace_symbols`]); the caller names the files.

use crate::encoding::{Encoding, LineMap};
use semo::diag::FileId;
use semo::host::Analysis;
use semo::text::LineIndex;
use std::collections::HashMap;
use tower_lsp_server::ls_types::{Location, SymbolInformation, Uri};

pub fn workspace_symbol(
    workspace: &Analysis,
    encoding: Encoding,
    uri_of: impl Fn(FileId) -> Option<Uri>,
    query: &str,
) -> Vec<SymbolInformation> {
    let mut indexes: HashMap<FileId, LineIndex> = HashMap::new();
    let mut out = Vec::new();
    for symbol in workspace.workspace_symbols(query) {
        let file = symbol.target.file;
        let (Some(uri), Some(source)) = (uri_of(file), workspace.file(file)) else {
            continue;
        };
        let text = &*source.text;
        let index = indexes.entry(file).or_insert_with(|| LineIndex::new(text));
        let lines = LineMap {
            text,
            index,
            encoding,
        };
        let range = lines.range(symbol.target.span);
        out.push(crate::to_proto::symbol_information(
            symbol,
            Location::new(uri, range),
        ));
    }
    out
}
