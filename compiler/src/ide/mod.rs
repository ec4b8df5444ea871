//! IDE features over one analysed mission, in the manner of rust-analyzer's
//! `ide` crate: pure functions of an [`Analysis`](crate::Analysis) (with the
//! [`Catalog`](crate::catalog::Catalog) and the source text where they need
//! them) and a byte offset, returning byte [`Span`](crate::span::Span)s and
//! plain data. The language server turns them into protocol types; nothing
//! here knows of LSP.
//!
//! Every function accepts any offset (past the end included) and any tree
//! (syntax errors included) without panicking.

pub mod folding;
pub mod navigation;
pub mod rename;
pub mod selection;
pub mod semantic_tokens;
pub mod symbols;

#[cfg(test)]
mod latency;
mod lookup;
#[cfg(test)]
mod testing;
