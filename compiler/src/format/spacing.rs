//! Which two tokens written on the same line take a space between them.

use crate::syntax::token::{Kw, Token};

/// Whether `next`, written on the same line right after `prev`, is preceded by
/// one space. Never glues two tokens that would lex as one (`[` `[`, `=` `=`):
/// such pairs do not occur in a valid script, and get a space anyway.
pub fn space_between(prev: Token<'_>, next: Token<'_>) -> bool {
    use Token as T;
    match (prev, next) {
        // Punctuation that hugs what precedes it.
        (_, T::Comma | T::Semi | T::Colon | T::Dot | T::RParen | T::RBracket) => false,
        // Punctuation that hugs what follows it.
        (T::Dot | T::LParen | T::LBracket | T::Bang, _) => false,
        // `move(`, `if(`, `repeat(`, `group(`; but `case (M):`, `catch (e):`,
        // and a word operator before a parenthesised condition: `not (a)`.
        (T::Ident(_), T::LParen) => false,
        (T::Kw(k), T::LParen) => matches!(k, Kw::Case | Kw::Catch | Kw::And | Kw::Or | Kw::Not),
        // `burger[2]`
        (T::Ident(_), T::LBracket) => false,
        // An empty body: `{}`.
        (T::LBrace, T::RBrace) => false,
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::token::lex;

    /// `text`'s tokens joined by the spacing rule.
    fn spaced(text: &str) -> String {
        let tokens = lex(text);
        let mut out = String::new();
        for (i, (tok, span)) in tokens.iter().enumerate() {
            if i > 0 && space_between(tokens[i - 1].0, *tok) {
                out.push(' ');
            }
            out.push_str(&text[span.start..span.end]);
        }
        out
    }

    #[test]
    fn calls_and_keywords_hug_their_parenthesis_but_case_and_catch_do_not() {
        assert_eq!(
            spaced("move ( \"5,5\" ) , timeout=10 SEC"),
            "move(\"5,5\"), timeout = 10 SEC"
        );
        assert_eq!(spaced("if ( a==b )"), "if(a == b)");
        assert_eq!(spaced("repeat ( )"), "repeat()");
        assert_eq!(
            spaced("case(M):catch(e):mode=N"),
            "case (M): catch (e): mode = N"
        );
    }

    #[test]
    fn operators_dots_brackets_and_negation() {
        assert_eq!(
            spaced("! a&&not(b)||c . d>=-4"),
            "!a && not (b) || c.d >= -4"
        );
        assert_eq!(spaced("T : A a , B b [ 2 ] ;"), "T: A a, B b[2];");
        assert_eq!(
            spaced("[[ group ( instance of X ) { } ]]"),
            "[[ group(instance of X) {} ]]"
        );
    }
}
