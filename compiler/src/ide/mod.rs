//! Editor features over one analysed mission, as plain data: what the
//! language server answers, without any protocol type (as rust-analyzer's
//! `ide` crate). Every function takes the [`Analysis`](crate::Analysis) of a
//! text, the [`Catalog`](crate::catalog::Catalog) it was checked against, the
//! text itself and byte offsets or [`Span`](crate::span::Span)s, and returns
//! byte spans. None of them panics, whatever the text and offsets.

pub mod code_actions;
pub mod completion;
mod context;
mod docs;
pub mod hover;
pub mod inlay_hints;
mod robots;
pub mod signature_help;
pub mod snippets;

#[cfg(test)]
mod tests;
