//! Edits of a file's text and the code actions made of them: part of the
//! editor vocabulary, re-exported by `ide` (a module of their own, below it,
//! so that the vocabulary of edits stays apart from the features).

use crate::span::Span;

/// Replace `span` with `new_text` (an insertion when `span` is empty).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextEdit {
    pub span: Span,
    pub new_text: String,
}

#[derive(Clone, Debug, PartialEq, Eq)]
/// A fix for one diagnostic: applying its edits removes that diagnostic.
pub struct CodeAction {
    pub title: String,
    /// The diagnostic it fixes: an index into the analysis' diagnostics.
    pub diagnostic: usize,
    /// Edits of the file's text, not overlapping, in order.
    pub edits: Vec<TextEdit>,
    /// The fix most likely wanted for that diagnostic.
    pub preferred: bool,
}
