//! The formatter's last step checks its own output: the same tokens, written
//! the same, and the same comments between the same tokens, each still ending
//! a line of code or standing on its own line as before. Output that fails is
//! never returned, so a bug in the layout can cost a reformat but never a token
//! or a comment of the user's.

use super::trivia::{self, Trivia};
use crate::syntax::token::{Spanned, lex};

/// What differs between the original and the formatted text, if anything.
pub fn faithful(tokens: &[Spanned<'_>], trivia: &Trivia<'_>, output: &str) -> Result<(), String> {
    let formatted = lex(output);
    if formatted.len() != tokens.len() {
        return Err(format!(
            "the output has {} tokens instead of {}",
            formatted.len(),
            tokens.len()
        ));
    }
    if let Some(((a, _), (b, _))) = tokens.iter().zip(&formatted).find(|(a, b)| a.0 != b.0) {
        return Err(format!("the token `{a}` would become `{b}`"));
    }
    let after = trivia::scan(output, &formatted)
        .map_err(|at| format!("unexpected text at byte {} of the output", at.0))?;
    for i in 0..trivia.gaps.len() {
        let (was, now) = (trivia.all(i), after.all(i));
        if texts(was) != texts(now) {
            return Err(format!(
                "the comments {:?} would become {:?}",
                texts(was),
                texts(now)
            ));
        }
        if trivia.trailing(i).is_some() != after.trailing(i).is_some() {
            let moved = was.first().map_or("", |c| c.text);
            return Err(format!(
                "the comment `{moved}` would move to or from the end of a line"
            ));
        }
    }
    Ok(())
}

fn texts<'s>(comments: &[trivia::Comment<'s>]) -> Vec<&'s str> {
    comments.iter().map(|c| c.text).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(original: &str, output: &str) -> Result<(), String> {
        let tokens = lex(original);
        let trivia = trivia::scan(original, &tokens).unwrap();
        faithful(&tokens, &trivia, output)
    }

    #[test]
    fn whitespace_changes_pass() {
        assert_eq!(
            check("a( b ,c ) # x\n# y\nd", "a(b, c) # x\n  # y\nd\n"),
            Ok(())
        );
    }

    #[test]
    fn lost_changed_or_moved_tokens_and_comments_fail() {
        assert!(check("a b", "a").is_err());
        assert!(check("a == b", "a = = b").is_err());
        assert!(check("or", "||").is_err());
        assert!(check("a # x\nb", "a\nb").is_err());
        assert!(check("a # x\nb", "a # y\nb").is_err());
        assert!(check("a # x\nb", "a b # x\n").is_err());
        assert!(check("a # x\nb", "a\n# x\nb").is_err());
        assert!(check("a\n# x\nb", "a # x\nb").is_err());
    }
}
