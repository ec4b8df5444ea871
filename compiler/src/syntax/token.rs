//! Tokens and the chumsky lexer. Comments and whitespace are dropped; characters
//! the language does not use become [`Token::Error`] so the parser can go on.

use crate::span::Span;
use chumsky::prelude::*;
use std::fmt;

/// Reserved words. Unit words (`SEC`, ...) are not reserved: they are recognised
/// after a number, case-insensitively.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kw {
    If,
    Else,
    Loop,
    Repeat,
    Throw,
    Send,
    Receive,
    Publish,
    Subscribe,
    Set,
    Off,
    Def,
    Main,
    Case,
    Catch,
    Default,
    Mode,
    Group,
    Leader,
    Others,
    Instance,
    Of,
    Capable,
    Timeout,
    True,
    False,
    And,
    Or,
    Not,
}

impl Kw {
    pub const ALL: &'static [Kw] = &[
        Kw::If,
        Kw::Else,
        Kw::Loop,
        Kw::Repeat,
        Kw::Throw,
        Kw::Send,
        Kw::Receive,
        Kw::Publish,
        Kw::Subscribe,
        Kw::Set,
        Kw::Off,
        Kw::Def,
        Kw::Main,
        Kw::Case,
        Kw::Catch,
        Kw::Default,
        Kw::Mode,
        Kw::Group,
        Kw::Leader,
        Kw::Others,
        Kw::Instance,
        Kw::Of,
        Kw::Capable,
        Kw::Timeout,
        Kw::True,
        Kw::False,
        Kw::And,
        Kw::Or,
        Kw::Not,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Kw::If => "if",
            Kw::Else => "else",
            Kw::Loop => "loop",
            Kw::Repeat => "repeat",
            Kw::Throw => "throw",
            Kw::Send => "send",
            Kw::Receive => "receive",
            Kw::Publish => "publish",
            Kw::Subscribe => "subscribe",
            Kw::Set => "set",
            Kw::Off => "OFF",
            Kw::Def => "def",
            Kw::Main => "main",
            Kw::Case => "case",
            Kw::Catch => "catch",
            Kw::Default => "default",
            Kw::Mode => "mode",
            Kw::Group => "group",
            Kw::Leader => "leader",
            Kw::Others => "others",
            Kw::Instance => "instance",
            Kw::Of => "of",
            Kw::Capable => "capable",
            Kw::Timeout => "timeout",
            Kw::True => "true",
            Kw::False => "false",
            Kw::And => "and",
            Kw::Or => "or",
            Kw::Not => "not",
        }
    }

    pub fn from_word(word: &str) -> Option<Kw> {
        Kw::ALL.iter().copied().find(|k| k.as_str() == word)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Token<'src> {
    Ident(&'src str),
    Kw(Kw),
    /// A number as written (`12`, `3.5`, `-4`).
    Number(&'src str),
    /// A string literal, including its quotes, escapes not yet processed.
    Str(&'src str),
    LBrace,
    RBrace,
    LParen,
    RParen,
    LBracket,
    RBracket,
    /// `[[`
    GroupOpen,
    /// `]]`
    GroupClose,
    Colon,
    Semi,
    Comma,
    Dot,
    Assign,
    EqEq,
    NotEq,
    Lt,
    Le,
    Gt,
    Ge,
    AndAnd,
    OrOr,
    Bang,
    /// A character the language does not use.
    Error(char),
    /// A string literal whose closing quote is missing (runs to end of line).
    Unterminated(&'src str),
}

impl fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Token::Ident(s) | Token::Number(s) | Token::Str(s) | Token::Unterminated(s) => {
                write!(f, "{s}")
            }
            Token::Kw(k) => f.write_str(k.as_str()),
            Token::LBrace => f.write_str("{"),
            Token::RBrace => f.write_str("}"),
            Token::LParen => f.write_str("("),
            Token::RParen => f.write_str(")"),
            Token::LBracket => f.write_str("["),
            Token::RBracket => f.write_str("]"),
            Token::GroupOpen => f.write_str("[["),
            Token::GroupClose => f.write_str("]]"),
            Token::Colon => f.write_str(":"),
            Token::Semi => f.write_str(";"),
            Token::Comma => f.write_str(","),
            Token::Dot => f.write_str("."),
            Token::Assign => f.write_str("="),
            Token::EqEq => f.write_str("=="),
            Token::NotEq => f.write_str("!="),
            Token::Lt => f.write_str("<"),
            Token::Le => f.write_str("<="),
            Token::Gt => f.write_str(">"),
            Token::Ge => f.write_str(">="),
            Token::AndAnd => f.write_str("&&"),
            Token::OrOr => f.write_str("||"),
            Token::Bang => f.write_str("!"),
            Token::Error(c) => write!(f, "{c}"),
        }
    }
}

pub type Spanned<'src> = (Token<'src>, SimpleSpan);

fn lexer<'src>() -> impl Parser<'src, &'src str, Vec<Spanned<'src>>, extra::Default> {
    let ident = any()
        .filter(|c: &char| c.is_ascii_alphabetic() || *c == '_')
        .then(
            any()
                .filter(|c: &char| c.is_ascii_alphanumeric() || *c == '_')
                .repeated(),
        )
        .to_slice()
        .map(|word: &str| match Kw::from_word(word) {
            Some(kw) => Token::Kw(kw),
            None => Token::Ident(word),
        });

    let digits = any()
        .filter(|c: &char| c.is_ascii_digit())
        .repeated()
        .at_least(1);
    let number = just('-')
        .or_not()
        .then(digits)
        .then(just('.').then(digits).or_not())
        .to_slice()
        .map(Token::Number);

    let escape = just('\\').then(any().filter(|c: &char| *c != '\n'));
    let string_body = escape.ignored().or(none_of("\"\\\n").ignored()).repeated();
    let string = just('"')
        .ignore_then(string_body)
        .ignore_then(just('"').or_not())
        .map_with(|close, e| {
            let raw: &str = e.slice();
            match close {
                Some(_) => Token::Str(raw),
                None => Token::Unterminated(raw),
            }
        });

    let punct = choice((
        just("[[").to(Token::GroupOpen),
        just("]]").to(Token::GroupClose),
        just("==").to(Token::EqEq),
        just("!=").to(Token::NotEq),
        just("<=").to(Token::Le),
        just(">=").to(Token::Ge),
        just("&&").to(Token::AndAnd),
        just("||").to(Token::OrOr),
        just('{').to(Token::LBrace),
        just('}').to(Token::RBrace),
        just('(').to(Token::LParen),
        just(')').to(Token::RParen),
        just('[').to(Token::LBracket),
        just(']').to(Token::RBracket),
        just(':').to(Token::Colon),
        just(';').to(Token::Semi),
        just(',').to(Token::Comma),
        just('.').to(Token::Dot),
        just('=').to(Token::Assign),
        just('<').to(Token::Lt),
        just('>').to(Token::Gt),
        just('!').to(Token::Bang),
    ));

    let token = choice((ident, number, string, punct, any().map(Token::Error)));

    let comment = just('#').then(none_of('\n').repeated()).ignored();
    let trivia = choice((
        any().filter(|c: &char| c.is_whitespace()).ignored(),
        comment,
    ))
    .repeated();

    token
        .map_with(|tok, e| (tok, e.span()))
        .padded_by(trivia)
        .repeated()
        .collect()
        .padded_by(trivia)
}

/// Splits `text` into tokens. Never fails: unknown characters and unterminated
/// strings become tokens that the parser reports.
pub fn lex(text: &str) -> Vec<Spanned<'_>> {
    lexer().parse(text).into_output().unwrap_or_default()
}

/// The value of a string literal token (quotes removed, escapes applied).
pub fn unescape(raw: &str) -> String {
    let inner = raw.strip_prefix('"').unwrap_or(raw);
    let inner = inner.strip_suffix('"').unwrap_or(inner);
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => out.push('\\'),
            }
        } else {
            out.push(c);
        }
    }
    out
}

pub fn span_of(s: SimpleSpan) -> Span {
    Span::new(s.start, s.end)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<Token<'_>> {
        lex(text).into_iter().map(|(t, _)| t).collect()
    }

    #[test]
    fn lexes_group_brackets_periods_and_comments() {
        assert_eq!(
            kinds("[[ group ]] # done\nloop(2 SEC) x[3]"),
            vec![
                Token::GroupOpen,
                Token::Kw(Kw::Group),
                Token::GroupClose,
                Token::Kw(Kw::Loop),
                Token::LParen,
                Token::Number("2"),
                Token::Ident("SEC"),
                Token::RParen,
                Token::Ident("x"),
                Token::LBracket,
                Token::Number("3"),
                Token::RBracket,
            ]
        );
    }

    #[test]
    fn strings_with_escapes_and_unicode() {
        let toks = kinds(r#"move("a\"b😀") "open"#);
        assert_eq!(toks[2], Token::Str(r#""a\"b😀""#));
        assert_eq!(unescape(r#""a\"b😀""#), "a\"b😀");
        assert_eq!(toks.last(), Some(&Token::Unterminated("\"open")));
    }

    #[test]
    fn unknown_characters_become_error_tokens() {
        let toks = lex("a @ b");
        assert_eq!(toks[1].0, Token::Error('@'));
        assert_eq!(toks[1].1.start, 2);
    }

    #[test]
    fn spans_are_bytes_with_korean_comments() {
        let text = "# 한국어\nT";
        let toks = lex(text);
        assert_eq!(toks[0].1.start, text.find('T').unwrap());
    }
}
