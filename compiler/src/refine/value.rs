//! Typed values: what a slot, a channel sample or a message holds, as the
//! catalog declares it (`catalog::ValueType`), and the operations on values
//! that the generated C (`semo_core.c`'s `semo_value`) and the simulator
//! (`sim::engine`) both perform. This module is the simulator's side and the
//! specification of the C side: the two agree by the differential tests.
//!
//! - integers are `int64`, reals `double`, truth values `bool`;
//! - words (an `enum` value's constants, and the mission's symbolic
//!   constants) are compared by identity: in C an index into the program's
//!   word table, on the wire and in traces their text;
//! - text (catalog `string`, `location` "x,y", `image`) is a bounded buffer
//!   (`SEMO_TEXT_MAX`, [`TEXT_MAX`]): longer text is cut at a character.

use crate::catalog::ValueType;
use std::fmt::Write;

/// The bytes a text value holds in the simulator and in a POSIX build
/// (`SEMO_TEXT_MAX`, `semo_runtime.h`): 63 bytes and the terminating NUL.
pub const TEXT_MAX: usize = 64;

/// How the values of a slot (and of the channels and messages carrying it)
/// are stored, from the catalog's type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ValueKind {
    Int,
    Real,
    Bool,
    /// An enumeration: one of these words.
    Word(Vec<String>),
    /// Catalog `string`, `location` and `image`.
    Text,
    /// A team variable (`send(T, T.X = v)`): the language gives it no type,
    /// it holds the value last assigned, with that value's own type.
    Variable,
}

impl ValueKind {
    /// The storage of a catalog value type.
    pub fn declared(ty: &ValueType) -> ValueKind {
        match ty {
            ValueType::Int => ValueKind::Int,
            ValueType::Float => ValueKind::Real,
            ValueType::Bool => ValueKind::Bool,
            ValueType::Enum(domain) => ValueKind::Word(domain.clone()),
            ValueType::String | ValueType::Location | ValueType::Image => ValueKind::Text,
        }
    }

    /// The C tag (`semo_type`); `SEMO_NONE` for a variable (any tag).
    pub fn c_tag(&self) -> &'static str {
        match self {
            ValueKind::Int => "SEMO_INT",
            ValueKind::Real => "SEMO_REAL",
            ValueKind::Bool => "SEMO_BOOL",
            ValueKind::Word(_) => "SEMO_WORD",
            ValueKind::Text => "SEMO_TEXT",
            ValueKind::Variable => "SEMO_NONE",
        }
    }

    /// For comments: `int`, `enum {A, B}`, ...
    pub fn describe(&self) -> String {
        match self {
            ValueKind::Int => "int".into(),
            ValueKind::Real => "real".into(),
            ValueKind::Bool => "bool".into(),
            ValueKind::Word(domain) => format!("enum {{{}}}", domain.join(", ")),
            ValueKind::Text => "text".into(),
            ValueKind::Variable => "team variable".into(),
        }
    }

    /// The value `text` stands for, read as this kind (`semo_value_parse`):
    /// scenario sensor values, and text received where this kind is
    /// declared (operator commands). `None` when it is not one.
    pub fn parse(&self, text: &str) -> Option<Value> {
        Some(match self {
            ValueKind::Int => Value::Int(parse_int(text)?),
            ValueKind::Real => Value::Real(parse_real(text)?),
            ValueKind::Bool => match text {
                "true" => Value::Bool(true),
                "false" => Value::Bool(false),
                _ => return None,
            },
            ValueKind::Word(domain) => {
                if !domain.iter().any(|d| d == text) {
                    return None;
                }
                Value::Word(text.to_string())
            }
            ValueKind::Text | ValueKind::Variable => Value::Text(cut_text(text)),
        })
    }

    /// A received value where this kind is declared (`semo_value_coerce`):
    /// the same type passes, an integer widens to a real, text (what the
    /// operator types) is read as the kind; anything else is refused.
    pub fn coerce(&self, value: &Value) -> Option<Value> {
        match (self, value) {
            (ValueKind::Variable, v) => Some(v.clone()),
            (ValueKind::Int, Value::Int(_))
            | (ValueKind::Real, Value::Real(_))
            | (ValueKind::Bool, Value::Bool(_))
            | (ValueKind::Text, Value::Text(_)) => Some(value.clone()),
            (ValueKind::Real, Value::Int(i)) => Some(Value::Real(*i as f64)),
            (ValueKind::Word(domain), Value::Word(w)) => {
                domain.iter().any(|d| d == w).then(|| value.clone())
            }
            (ValueKind::Text, Value::Word(w)) => Some(Value::Text(cut_text(w))),
            (kind, Value::Text(t)) => kind.parse(t),
            _ => None,
        }
    }
}

/// A value: a literal of the program, or what a slot holds at run time.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Int(i64),
    Real(f64),
    Bool(bool),
    Word(String),
    Text(String),
}

impl Value {
    /// A mission literal as the checker typed it: a whole number is an
    /// integer, another number a real, a string text.
    pub fn number(text: &str) -> Value {
        match parse_int(text) {
            Some(i) => Value::Int(i),
            None => match parse_real(text) {
                Some(r) => Value::Real(r),
                None => Value::Text(cut_text(text)),
            },
        }
    }

    pub fn text(text: &str) -> Value {
        Value::Text(cut_text(text))
    }

    /// A value written in a strategy file (a parameter's or an actuator
    /// command's `value`): a number, `true`/`false`, else a word.
    pub fn strategy(text: &str) -> Value {
        match text {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            _ if parse_real(text).is_some() => Value::number(text),
            _ => Value::Word(text.to_string()),
        }
    }

    /// The words and texts of a value as text (completion, the wire).
    pub fn as_text(&self) -> String {
        match self {
            Value::Int(i) => i.to_string(),
            Value::Real(r) => format_real(*r),
            Value::Bool(b) => b.to_string(),
            Value::Word(w) | Value::Text(w) => w.clone(),
        }
    }

    fn as_number(&self) -> Option<f64> {
        match self {
            Value::Int(i) => Some(*i as f64),
            Value::Real(r) => Some(*r),
            _ => None,
        }
    }

    /// Words and text: the text compared (a text value may hold a
    /// constant's name: `USER.RC_CMD == RETURN_MODE`).
    fn as_word(&self) -> Option<&str> {
        match self {
            Value::Word(w) | Value::Text(w) => Some(w),
            _ => None,
        }
    }
}

/// `semo_value_numbers`: integers exactly, else as reals; false (None) when
/// a side is missing or not a number.
pub fn compare_numbers(a: Option<&Value>, b: Option<&Value>) -> Option<std::cmp::Ordering> {
    match (a?, b?) {
        (Value::Int(x), Value::Int(y)) => Some(x.cmp(y)),
        (x, y) => x.as_number()?.partial_cmp(&y.as_number()?),
    }
}

/// `semo_value_words`: whether two values are the same (`==`; `!=` is its
/// negation, words are never ordered). Words by identity, a word and a text
/// by their text, numbers by value, truth values by value, no value only as
/// no value; values of other types differ.
pub fn words_equal(a: Option<&Value>, b: Option<&Value>) -> bool {
    let (a, b) = match (a, b) {
        (Some(a), Some(b)) => (a, b),
        (a, b) => return a.is_none() && b.is_none(),
    };
    match (a, b) {
        (Value::Int(x), Value::Int(y)) => x == y,
        (Value::Bool(x), Value::Bool(y)) => x == y,
        _ => match (a.as_number(), b.as_number()) {
            (Some(x), Some(y)) => x == y,
            _ => matches!((a.as_word(), b.as_word()), (Some(x), Some(y)) if x == y),
        },
    }
}

/// `semo_value_truthy`: `true`, or a number other than zero.
pub fn truthy(v: Option<&Value>) -> bool {
    match v {
        Some(Value::Bool(b)) => *b,
        Some(Value::Int(i)) => *i != 0,
        Some(Value::Real(r)) => *r != 0.0,
        _ => false,
    }
}

/// Text cut to [`TEXT_MAX`]` - 1` bytes, never inside a character.
pub fn cut_text(text: &str) -> String {
    let mut end = text.len().min(TEXT_MAX - 1);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    text[..end].to_string()
}

/// `[+-]digits`, within `int64` (`semo_core.c`'s `parse_int`).
pub fn parse_int(text: &str) -> Option<i64> {
    let digits = text.strip_prefix(['-', '+']).unwrap_or(text);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    text.parse().ok()
}

/// A real in the runtime's grammar (`parse_number`): digits with an optional
/// fraction and exponent, or `inf`; no spaces, no `nan`.
pub fn parse_real(text: &str) -> Option<f64> {
    let first = text.as_bytes().first()?;
    if first.is_ascii_whitespace() {
        return None;
    }
    text.parse::<f64>().ok().filter(|d| !d.is_nan())
}

/// A finite real as the runtime prints it (`semo__format_real`): up to six
/// decimals, trailing zeros dropped, at least one (`2.0`, `0.125`); from
/// 1e15 on, digits and an exponent (`1.5e20` is `150000000000000e6`). The
/// same arithmetic on both sides, so that traces agree to the byte.
pub fn format_real(r: f64) -> String {
    let mut out = String::new();
    let negative = r < 0.0;
    let mut x = r.abs();
    if negative {
        out.push('-');
    }
    if x >= 1e15 {
        let mut exponent = 0;
        while x >= 1e15 {
            x /= 10.0;
            exponent += 1;
        }
        let _ = write!(out, "{}e{exponent}", (x + 0.5) as i64);
        return out;
    }
    // Half up by adding 0.5, as the runtime does without libm.
    let scaled = (x * 1e6 + 0.5) as i64;
    let (whole, mut fraction) = (scaled / 1_000_000, scaled % 1_000_000);
    let _ = write!(out, "{whole}.");
    let mut digits = 6;
    while digits > 1 && fraction % 10 == 0 {
        fraction /= 10;
        digits -= 1;
    }
    let _ = write!(out, "{fraction:0digits$}");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_print_as_the_runtime_prints_them() {
        assert_eq!(format_real(2.0), "2.0");
        assert_eq!(format_real(0.125), "0.125");
        assert_eq!(format_real(-2.5), "-2.5");
        assert_eq!(format_real(1.0 / 3.0), "0.333333");
        assert_eq!(format_real(1.5e20), "150000000000000e6");
    }

    #[test]
    fn literals_are_typed_by_how_they_are_written() {
        assert_eq!(Value::number("30"), Value::Int(30));
        assert_eq!(Value::number("-2.5"), Value::Real(-2.5));
        assert_eq!(Value::strategy("LEFT"), Value::Word("LEFT".into()));
        assert_eq!(Value::strategy("10"), Value::Int(10));
    }

    #[test]
    fn comparisons_follow_the_types() {
        use std::cmp::Ordering::*;
        let (i, r) = (Value::Int(5), Value::Real(5.0));
        assert_eq!(compare_numbers(Some(&i), Some(&r)), Some(Equal));
        assert_eq!(compare_numbers(Some(&i), Some(&Value::text("5"))), None);
        assert_eq!(compare_numbers(None, Some(&i)), None);
        let word = Value::Word("LEFT".into());
        assert!(words_equal(Some(&word), Some(&Value::text("LEFT"))));
        assert!(words_equal(Some(&Value::Int(10)), Some(&Value::Real(10.0))));
        assert!(!words_equal(Some(&Value::Int(1)), Some(&Value::Bool(true))));
        assert!(!words_equal(None, Some(&word)) && words_equal(None, None));
        assert!(truthy(Some(&Value::Real(-0.5))) && !truthy(Some(&Value::text("true"))));
    }

    #[test]
    fn received_text_is_read_as_the_declared_kind() {
        let word = ValueKind::Word(vec!["A".into(), "B".into()]);
        assert_eq!(
            word.coerce(&Value::text("B")),
            Some(Value::Word("B".into()))
        );
        assert_eq!(word.coerce(&Value::text("C")), None);
        assert_eq!(
            ValueKind::Int.coerce(&Value::text("7")),
            Some(Value::Int(7))
        );
        assert_eq!(
            ValueKind::Real.coerce(&Value::Int(7)),
            Some(Value::Real(7.0))
        );
        assert_eq!(ValueKind::Int.coerce(&Value::Real(7.5)), None);
        assert_eq!(ValueKind::Text.coerce(&Value::Int(7)), None);
    }
}
