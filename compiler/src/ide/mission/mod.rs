//! Editor features over one analysed mission, as plain data: what the
//! language server answers, without any protocol type (as rust-analyzer's
//! `ide` crate). Every function takes the [`CheckedMission`](crate::CheckedMission) of a
//! text (with the [`Catalog`](crate::catalog::Catalog) it was checked against
//! and the text itself where needed) and byte offsets or
//! [`Span`](crate::span::Span)s, and returns byte spans and plain data. None
//! of them panics, whatever the text and offsets (past the end included).

pub mod code_actions;
pub mod completion;
mod context;
mod docs;
pub mod folding;
pub mod formatting;
pub mod hover;
pub mod inlay_hints;
pub mod keywords;
pub mod navigation;
pub mod rename;
mod robots;
pub mod selection;
pub mod semantic_tokens;
pub mod signature_help;
pub mod snippets;
pub mod symbols;
mod values;

#[cfg(test)]
mod testing;
#[cfg(test)]
mod tests;
