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
    Broadcast,
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
        Kw::Broadcast,
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
            Kw::Broadcast => "broadcast",
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

    /// The keyword spelled `word`, if any (a `match` is much faster than a search).
    pub fn from_word(word: &str) -> Option<Kw> {
        Some(match word {
            "if" => Kw::If,
            "else" => Kw::Else,
            "loop" => Kw::Loop,
            "repeat" => Kw::Repeat,
            "throw" => Kw::Throw,
            "broadcast" => Kw::Broadcast,
            "send" => Kw::Send,
            "receive" => Kw::Receive,
            "publish" => Kw::Publish,
            "subscribe" => Kw::Subscribe,
            "set" => Kw::Set,
            "OFF" => Kw::Off,
            "def" => Kw::Def,
            "main" => Kw::Main,
            "case" => Kw::Case,
            "catch" => Kw::Catch,
            "default" => Kw::Default,
            "mode" => Kw::Mode,
            "group" => Kw::Group,
            "leader" => Kw::Leader,
            "others" => Kw::Others,
            "instance" => Kw::Instance,
            "of" => Kw::Of,
            "capable" => Kw::Capable,
            "timeout" => Kw::Timeout,
            "true" => Kw::True,
            "false" => Kw::False,
            "and" => Kw::And,
            "or" => Kw::Or,
            "not" => Kw::Not,
            _ => return None,
        })
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
    let word = text::ascii::ident().map(|word: &str| match Kw::from_word(word) {
        Some(kw) => Token::Kw(kw),
        None => Token::Ident(word),
    });

    let number = just('-')
        .or_not()
        .then(text::digits(10))
        .then(just('.').then(text::digits(10)).or_not())
        .to_slice()
        .map(Token::Number);

    let escape = just('\\').then(none_of('\n'));
    let string = just('"')
        .ignore_then(escape.ignored().or(none_of("\"\\\n").ignored()).repeated())
        .ignore_then(just('"').or_not())
        .map_with(|close, e| {
            let raw: &str = e.slice();
            match close {
                Some(_) => Token::Str(raw),
                None => Token::Unterminated(raw),
            }
        });

    let two_chars = choice((
        just("[[").to(Token::GroupOpen),
        just("]]").to(Token::GroupClose),
        just("==").to(Token::EqEq),
        just("!=").to(Token::NotEq),
        just("<=").to(Token::Le),
        just(">=").to(Token::Ge),
        just("&&").to(Token::AndAnd),
        just("||").to(Token::OrOr),
    ));
    // Punctuation that never starts a two-character operator, matched first.
    let single = select! {
        '{' => Token::LBrace,
        '}' => Token::RBrace,
        '(' => Token::LParen,
        ')' => Token::RParen,
        ':' => Token::Colon,
        ';' => Token::Semi,
        ',' => Token::Comma,
        '.' => Token::Dot,
    };
    let prefix_of_two = select! {
        '[' => Token::LBracket,
        ']' => Token::RBracket,
        '=' => Token::Assign,
        '<' => Token::Lt,
        '>' => Token::Gt,
        '!' => Token::Bang,
    };

    let token = choice((
        word,
        single,
        string,
        number,
        two_chars,
        prefix_of_two,
        // An unknown character, with the ones right after it that cannot
        // start a token either: junk is one token per run, not per byte.
        any().map(Token::Error).then_ignore(unknown_run_rest()),
    ));

    // Whitespace and `#` comments, skipped in one tight loop: trivia is most of
    // the characters of a script, and combinators per character cost far more.
    let trivia = custom::<_, &'src str, (), extra::Default>(|inp| {
        while let Some(c) = inp.peek() {
            if c == '#' {
                while inp.peek().is_some_and(|c| c != '\n') {
                    inp.skip();
                }
            } else if c.is_whitespace() {
                inp.skip();
            } else {
                break;
            }
        }
        Ok(())
    });

    trivia
        .ignore_then(token.map_with(|tok, e| (tok, e.span())))
        .repeated()
        .collect()
        .then_ignore(trivia)
}

/// Whether `c` can never start a token or trivia (see the lexer above): such
/// characters after an unknown one join its run.
fn never_starts_token(c: char) -> bool {
    !(c.is_ascii_alphanumeric()
        || c == '_'
        || c.is_whitespace()
        || "-\"{}():;,.[]=<>!&|#".contains(c))
}

/// The rest of a run of unknown characters, skipped in one tight loop.
fn unknown_run_rest<'src>() -> impl Parser<'src, &'src str, (), extra::Default> + Clone {
    custom::<_, &'src str, (), extra::Default>(|inp| {
        while inp.peek().is_some_and(never_starts_token) {
            inp.skip();
        }
        Ok(())
    })
}

/// Splits `text` into tokens. Never fails: unknown characters and unterminated
/// strings become tokens that the parser reports.
pub fn lex(text: &str) -> Vec<Spanned<'_>> {
    let tokens = lexer().parse(text).into_output().unwrap_or_default();
    let mut out = Vec::with_capacity(tokens.len());
    for (tok, span) in tokens {
        match tok {
            Token::Unterminated(raw) => match missing_quote_before(raw) {
                Some(cut) => {
                    let end = span.start + cut;
                    out.push((
                        Token::Unterminated(&raw[..cut]),
                        SimpleSpan::from(span.start..end),
                    ));
                    let rest = lexer().parse(&text[end..span.end]).into_output();
                    out.extend(
                        rest.unwrap_or_default()
                            .into_iter()
                            .map(|(t, s)| (t, SimpleSpan::from(s.start + end..s.end + end))),
                    );
                }
                None => out.push((tok, span)),
            },
            _ => out.push((tok, span)),
        }
    }
    out
}

/// Where an unterminated string most likely lacks its closing quote: before a
/// `)` that it does not open itself, as in `move("5,5)`. The rest of the line is
/// then read as code, so the statement still parses. `None` when there is no such
/// `)`, or when the rest holds a quote or backslash (it would not lex as code).
fn missing_quote_before(raw: &str) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in raw.char_indices() {
        match c {
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            ')' => {
                let rest = &raw[i..];
                return (!rest.contains(['"', '\\'])).then_some(i);
            }
            _ => {}
        }
    }
    None
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
    fn unterminated_strings_end_before_an_unopened_paren() {
        let toks = kinds("move(\"5,5) stop()\nsay(\"a (b) c");
        assert_eq!(
            toks,
            vec![
                Token::Ident("move"),
                Token::LParen,
                Token::Unterminated("\"5,5"),
                Token::RParen,
                Token::Ident("stop"),
                Token::LParen,
                Token::RParen,
                Token::Ident("say"),
                Token::LParen,
                Token::Unterminated("\"a (b) c"),
            ]
        );
        assert_eq!(lex("move(\"5,5)")[3].1, SimpleSpan::from(9..10));
    }

    #[test]
    fn every_keyword_round_trips() {
        for &kw in Kw::ALL {
            assert_eq!(Kw::from_word(kw.as_str()), Some(kw));
        }
        assert_eq!(Kw::from_word("If"), None);
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
