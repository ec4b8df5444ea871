//! A literal of the mission (a word, a string, a number) as a comparison
//! reads it: what a team variable is set to, an argument given to a
//! parameter, the constant compared with either.

use crate::sema::ir::Compared;

/// A literal as a comparison reads it: words and strings by their text,
/// numbers by their value.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::sema) enum Literal {
    Word(String),
    Number(f64),
}

impl Literal {
    /// What the comparison compares, if this literal is of its kind.
    pub(super) fn compared_as(&self, compared: Compared) -> bool {
        matches!(
            (self, compared),
            (Literal::Word(_), Compared::Words) | (Literal::Number(_), Compared::Numbers)
        )
    }

    pub(super) fn text(&self) -> String {
        match self {
            Literal::Word(w) => w.clone(),
            Literal::Number(n) => n.to_string(),
        }
    }
}
