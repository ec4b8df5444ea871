//! Edits of a file's text and the code actions made of them: the vocabulary
//! the editor features of every file kind share (missions in `ide`, strategy
//! files in `strategy::ide`). It sits below both so that neither reads the
//! other for it.

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
