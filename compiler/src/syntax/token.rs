//! Tokens and the lexer (a hand-written scanner, see [`lex`]). Comments and whitespace are dropped; characters
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

/// The tokens of `text` in one pass over its bytes; whitespace and `#`
/// comments are skipped. Written out rather than combined from parsers: the
/// lexer reads every character of every file, and a combinator per
/// character cost it about seventy instructions a byte.
///
/// - A word is `[A-Za-z_][A-Za-z0-9_]*`; a reserved one is a [`Kw`].
/// - A number is `-?[0-9]+(\.[0-9]+)?` (a `.` not followed by a digit is a
///   [`Token::Dot`] after the number).
/// - A string runs from `"` to the next unescaped `"`; a `\` escapes any
///   character but a newline. Without its closing quote on the line it is a
///   [`Token::Unterminated`] that ends before the newline (or the `\` that
///   precedes it).
/// - Two-character operators are taken before their one-character prefixes.
/// - Any other character is a [`Token::Error`], with the characters right
///   after it that cannot start a token either: one token per run of junk.
fn scan(text: &str) -> Vec<Spanned<'_>> {
    let bytes = text.as_bytes();
    let at = |i: usize| bytes.get(i).copied();
    let mut out = Vec::with_capacity(text.len() / 4);
    let mut i = 0;
    while let Some(b) = at(i) {
        if b == b'#' {
            i += bytes[i..]
                .iter()
                .position(|&c| c == b'\n')
                .unwrap_or(bytes.len() - i);
            continue;
        }
        if b.is_ascii_whitespace() || b == 0x0B {
            i += 1;
            continue;
        }
        let start = i;
        let token = match b {
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                i += 1;
                while at(i).is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
                    i += 1;
                }
                let word = &text[start..i];
                Kw::from_word(word).map_or(Token::Ident(word), Token::Kw)
            }
            b'{' | b'}' | b'(' | b')' | b':' | b';' | b',' | b'.' => {
                i += 1;
                match b {
                    b'{' => Token::LBrace,
                    b'}' => Token::RBrace,
                    b'(' => Token::LParen,
                    b')' => Token::RParen,
                    b':' => Token::Colon,
                    b';' => Token::Semi,
                    b',' => Token::Comma,
                    _ => Token::Dot,
                }
            }
            b'"' => {
                i += 1;
                loop {
                    match at(i) {
                        Some(b'"') => {
                            i += 1;
                            break Token::Str(&text[start..i]);
                        }
                        Some(b'\\') if at(i + 1).is_some_and(|c| c != b'\n') => i += 2,
                        Some(b'\\' | b'\n') | None => break Token::Unterminated(&text[start..i]),
                        // A byte of a longer character is never one of the above.
                        Some(_) => i += 1,
                    }
                }
            }
            b'0'..=b'9' | b'-' if b != b'-' || at(i + 1).is_some_and(|c| c.is_ascii_digit()) => {
                let digits = |mut i: usize| {
                    while at(i).is_some_and(|c| c.is_ascii_digit()) {
                        i += 1;
                    }
                    i
                };
                i = digits(if b == b'-' { i + 1 } else { i });
                if at(i) == Some(b'.') && at(i + 1).is_some_and(|c| c.is_ascii_digit()) {
                    i = digits(i + 1);
                }
                Token::Number(&text[start..i])
            }
            _ => {
                let pair = match (b, at(i + 1)) {
                    (b'[', Some(b'[')) => Some(Token::GroupOpen),
                    (b']', Some(b']')) => Some(Token::GroupClose),
                    (b'=', Some(b'=')) => Some(Token::EqEq),
                    (b'!', Some(b'=')) => Some(Token::NotEq),
                    (b'<', Some(b'=')) => Some(Token::Le),
                    (b'>', Some(b'=')) => Some(Token::Ge),
                    (b'&', Some(b'&')) => Some(Token::AndAnd),
                    (b'|', Some(b'|')) => Some(Token::OrOr),
                    _ => None,
                };
                let single = match b {
                    b'[' => Some(Token::LBracket),
                    b']' => Some(Token::RBracket),
                    b'=' => Some(Token::Assign),
                    b'<' => Some(Token::Lt),
                    b'>' => Some(Token::Gt),
                    b'!' => Some(Token::Bang),
                    _ => None,
                };
                if let Some(token) = pair {
                    i += 2;
                    token
                } else if let Some(token) = single {
                    i += 1;
                    token
                } else {
                    let c = text[i..].chars().next().expect("a character starts here");
                    i += c.len_utf8();
                    if c.is_whitespace() {
                        continue;
                    }
                    for rest in text[i..].chars() {
                        if !never_starts_token(rest) {
                            break;
                        }
                        i += rest.len_utf8();
                    }
                    Token::Error(c)
                }
            }
        };
        out.push((token, SimpleSpan::from(start..i)));
    }
    out
}

/// Whether `c` can never start a token or trivia (see [`scan`]): such
/// characters after an unknown one join its run.
fn never_starts_token(c: char) -> bool {
    !(c.is_ascii_alphanumeric()
        || c == '_'
        || c.is_whitespace()
        || "-\"{}():;,.[]=<>!&|#".contains(c))
}

/// Splits `text` into tokens. Never fails: unknown characters and unterminated
/// strings become tokens that the parser reports.
pub fn lex(text: &str) -> Vec<Spanned<'_>> {
    let tokens = scan(text);
    if !tokens
        .iter()
        .any(|(t, _)| matches!(t, Token::Unterminated(_)))
    {
        return tokens;
    }
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
                    out.extend(
                        scan(&text[end..span.end])
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
    fn numbers_minus_signs_and_dots_lex_as_the_grammar_says() {
        assert_eq!(
            kinds("-4 - x 1.5 2. 3.y 7ab"),
            vec![
                Token::Number("-4"),
                Token::Error('-'),
                Token::Ident("x"),
                Token::Number("1.5"),
                Token::Number("2"),
                Token::Dot,
                Token::Number("3"),
                Token::Dot,
                Token::Ident("y"),
                Token::Number("7"),
                Token::Ident("ab"),
            ]
        );
    }

    #[test]
    fn a_string_ends_at_its_quote_or_before_the_end_of_its_line() {
        assert_eq!(
            kinds("\"a\\\"\" \"b\\\nc \"d\u{a0}\nx"),
            vec![
                Token::Str("\"a\\\"\""),
                Token::Unterminated("\"b"),
                Token::Error('\\'),
                Token::Ident("c"),
                Token::Unterminated("\"d\u{a0}"),
                Token::Ident("x"),
            ]
        );
    }

    #[test]
    fn operators_take_two_characters_before_one_and_junk_runs_are_one_token() {
        assert_eq!(
            kinds("[[[ ]]] <= < == = != ! && & || | @~é x\u{2028}#c\ny"),
            vec![
                Token::GroupOpen,
                Token::LBracket,
                Token::GroupClose,
                Token::RBracket,
                Token::Le,
                Token::Lt,
                Token::EqEq,
                Token::Assign,
                Token::NotEq,
                Token::Bang,
                Token::AndAnd,
                Token::Error('&'),
                Token::OrOr,
                Token::Error('|'),
                Token::Error('@'),
                Token::Ident("x"),
                Token::Ident("y"),
            ]
        );
    }

    proptest::proptest! {
        /// Whatever the text, the tokens follow each other on character
        /// boundaries, each non-empty, with only whitespace and comments
        /// between them.
        #[test]
        fn tokens_tile_the_text_but_for_whitespace_and_comments(
            pieces in proptest::collection::vec(proptest::sample::select(vec![
                "a", "Z", "_", "if", "x1", "0", "9", "-", ".", "\"", "\\", "\n", " ", "\t",
                "\u{b}", "\r", "#", "{", "}", "(", ")", ":", ";", ",", "[", "]", "=", "<", ">",
                "!", "&", "|", "@", "é", "😀", "\u{a0}", "\u{2028}", "$",
            ]), 0..40)
        ) {
            let text: String = pieces.concat();
            let mut end = 0;
            for (token, span) in lex(&text) {
                proptest::prop_assert!(span.start < span.end, "{:?} empty in {:?}", token, text);
                proptest::prop_assert!(text.is_char_boundary(span.start) && text.is_char_boundary(span.end));
                let gap = &text[end..span.start];
                let trivia = gap.split('\n').all(|line| {
                    let code = line.split_once('#').map_or(line, |(code, _)| code);
                    code.chars().all(char::is_whitespace)
                });
                proptest::prop_assert!(trivia, "{:?} between tokens in {:?}", gap, text);
                end = span.end;
            }
        }
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
