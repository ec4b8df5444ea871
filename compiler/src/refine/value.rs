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
use std::sync::Arc;

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
                Value::Word(text.into())
            }
            ValueKind::Text | ValueKind::Variable => Value::Text(cut_text(text).into()),
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
                domain.iter().any(|d| **d == **w).then(|| value.clone())
            }
            (ValueKind::Text, Value::Word(w)) => Some(Value::Text(cut_text(w).into())),
            (kind, Value::Text(t)) => kind.parse(t),
            _ => None,
        }
    }
}

/// A value: a literal of the program, or what a slot holds at run time.
///
/// Words and text are shared (`Arc<str>`): the simulator copies a value into
/// every slot, channel and message that carries it, and `semo verify` clones
/// whole fleets of them per state, so a copy is a count, not an allocation.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Int(i64),
    Real(f64),
    Bool(bool),
    Word(Arc<str>),
    Text(Arc<str>),
}

impl Value {
    /// A mission literal as the checker typed it: a whole number is an
    /// integer, another number a real, a string text.
    pub fn number(text: &str) -> Value {
        match parse_int(text) {
            Some(i) => Value::Int(i),
            None => match parse_real(text) {
                Some(r) => Value::Real(r),
                None => Value::Text(cut_text(text).into()),
            },
        }
    }

    pub fn text(text: &str) -> Value {
        Value::Text(cut_text(text).into())
    }

    /// A value written in a strategy file (a parameter's or an actuator
    /// command's `value`): a number, `true`/`false`, else a word.
    pub fn strategy(text: &str) -> Value {
        match text {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            _ if parse_real(text).is_some() => Value::number(text),
            _ => Value::Word(text.into()),
        }
    }

    /// The words and texts of a value as text (completion, the wire).
    pub fn as_text(&self) -> String {
        match self {
            Value::Int(i) => i.to_string(),
            Value::Real(r) => format_real(*r),
            Value::Bool(b) => b.to_string(),
            Value::Word(w) | Value::Text(w) => w.to_string(),
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
/// Whether `a op b` holds, compared as the checker typed the comparison
/// (`semo_value_numbers`, `semo_value_words`): numbers by value, false when
/// a side is not a number; words by identity, never ordered.
pub fn holds(
    a: Option<&Value>,
    op: crate::syntax::ast::CmpOp,
    b: Option<&Value>,
    compared: crate::sema::Compared,
) -> bool {
    use crate::sema::Compared;
    use crate::syntax::ast::CmpOp;
    use std::cmp::Ordering::*;
    let ord = match compared {
        Compared::Numbers => compare_numbers(a, b),
        Compared::Words => match op {
            CmpOp::Eq | CmpOp::Ne => Some(if words_equal(a, b) { Equal } else { Less }),
            _ => None,
        },
    };
    let Some(ord) = ord else {
        return false;
    };
    match op {
        CmpOp::Eq => ord == Equal,
        CmpOp::Ne => ord != Equal,
        CmpOp::Lt => ord == Less,
        CmpOp::Le => ord != Greater,
        CmpOp::Gt => ord == Greater,
        CmpOp::Ge => ord != Less,
    }
}

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

/// A real as the runtime prints it (`format_real` in `semo_core.c`), from
/// its exact binary value, so that traces agree to the byte: below 1e15 in
/// magnitude, rounded half up to six decimals, trailing zeros dropped but
/// one (`2.0`, `0.125`, `0.333333`); from 1e15 on, the first fifteen
/// significant digits rounded half up and an exponent (`1.5e20` is
/// `150000000000000e6`); a set sign bit is a `-` (`-0.0`). Not a number in
/// JSON: `inf`, `-inf`, `nan` (the trace writes those as `null`).
pub fn format_real(r: f64) -> String {
    if r.is_nan() {
        return "nan".into();
    }
    let mut out = String::new();
    if r.is_sign_negative() {
        out.push('-');
    }
    let x = r.abs();
    if x.is_infinite() {
        out.push_str("inf");
    } else if x >= 1e15 {
        push_scientific(&mut out, x);
    } else {
        push_fixed(&mut out, x);
    }
    out
}

/// `digits` e `exponent`: the first fifteen significant digits of `x`'s
/// integer part (at least 10^15 here), rounded half up on the sixteenth.
fn push_scientific(out: &mut String, x: f64) {
    // A whole f64 prints exactly with no decimals: every digit of it.
    let whole = format!("{:.0}", x.trunc());
    let (kept, rest) = whole.split_at(15);
    let mut digits: u64 = kept.parse().expect("decimal digits");
    let mut exponent = rest.len();
    if rest.as_bytes()[0] >= b'5' {
        digits += 1;
        if digits == 1_000_000_000_000_000 {
            digits /= 10;
            exponent += 1;
        }
    }
    let _ = write!(out, "{digits}e{exponent}");
}

/// `whole`.`fraction` of `x` (below 10^15), rounded half up to six decimals.
fn push_fixed(out: &mut String, x: f64) {
    let (mantissa, shift) = binary_parts(x);
    let (mut whole, fraction_bits) = match shift {
        0..64 => (mantissa >> shift, mantissa & ((1u64 << shift) - 1)),
        _ => (0, mantissa),
    };
    // Seven decimals of fraction_bits / 2^shift, cut: the seventh rounds.
    // fraction_bits * 10^7 < 2^77, so a shift of 128 or more leaves nothing.
    let seven = match shift {
        0..128 => ((u128::from(fraction_bits) * 10_000_000) >> shift) as u64,
        _ => 0,
    };
    let mut fraction = seven / 10 + u64::from(seven % 10 >= 5);
    if fraction == 1_000_000 {
        fraction = 0;
        whole += 1;
    }
    let _ = write!(out, "{whole}.");
    let mut digits = 6;
    while digits > 1 && fraction % 10 == 0 {
        fraction /= 10;
        digits -= 1;
    }
    let _ = write!(out, "{fraction:0digits$}");
}

/// A finite, non-negative `x` below 10^15 as `mantissa` / 2^`shift`
/// exactly (a whole number's shift is 0).
fn binary_parts(x: f64) -> (u64, u32) {
    let bits = x.to_bits();
    let biased = (bits >> 52) as i32; // the sign bit is clear
    let fraction = bits & ((1 << 52) - 1);
    let (mantissa, exponent) = match biased {
        0 => (fraction, -1074),
        _ => (fraction | 1 << 52, biased - 1075),
    };
    match u32::try_from(-exponent) {
        Ok(shift) => (mantissa, shift),
        // Below 10^15 < 2^50: the shifted mantissa fits.
        Err(_) => (mantissa << exponent, 0),
    }
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
    fn reals_print_over_the_whole_range() {
        // Between 2^63 / 10^6 and 10^15 the scaled value once overflowed.
        assert_eq!(format_real(9.3e12), "9300000000000.0");
        assert_eq!(format_real(-123456789012345.67), "-123456789012345.671875");
        assert_eq!(format_real(999999999999999.9), "999999999999999.875");
        assert_eq!(format_real(1e15), "100000000000000e1");
        assert_eq!(format_real(f64::MAX), "179769313486232e294");
        assert_eq!(format_real(1e300), "100000000000000e286");
        assert_eq!(format_real(0.0078125), "0.007813"); // a tie, rounded up
        assert_eq!(format_real(0.00000049999999999999), "0.0");
        assert_eq!(format_real(f64::MIN_POSITIVE), "0.0");
        assert_eq!(format_real(-5e-324), "-0.0");
        assert_eq!(format_real(-0.0), "-0.0");
        assert_eq!(format_real(0.9999996), "1.0");
        assert_eq!(format_real(f64::INFINITY), "inf");
        assert_eq!(format_real(f64::NEG_INFINITY), "-inf");
        assert_eq!(format_real(f64::NAN), "nan");
    }

    /// What `format_real` should print, from `x`'s exact decimal expansion
    /// (Rust prints an f64 exactly given enough decimals: a double has at
    /// most 1074), rounded half up as text.
    fn exact_rounding(x: f64) -> String {
        let sign = if x.is_sign_negative() { "-" } else { "" };
        let exact = format!("{:.1074}", x.abs());
        let (whole, decimals) = exact.split_once('.').unwrap();
        let (mut kept, next, exponent) = if x.abs() >= 1e15 {
            (
                whole[..15].to_string(),
                whole.as_bytes()[15],
                Some(whole.len() - 15),
            )
        } else {
            (
                format!("{whole}{}", &decimals[..6]),
                decimals.as_bytes()[6],
                None,
            )
        };
        if next >= b'5' {
            kept = increment(&kept);
        }
        match exponent {
            Some(e) if kept.len() > 15 => format!("{sign}{}e{}", &kept[..15], e + 1),
            Some(e) => format!("{sign}{kept}e{e}"),
            None => {
                let (whole, decimals) = kept.split_at(kept.len() - 6);
                let decimals = decimals.trim_end_matches('0');
                let decimals = if decimals.is_empty() { "0" } else { decimals };
                let whole = whole.trim_start_matches('0');
                let whole = if whole.is_empty() { "0" } else { whole };
                format!("{sign}{whole}.{decimals}")
            }
        }
    }

    /// A decimal numeral plus one, as text.
    fn increment(digits: &str) -> String {
        let mut bytes = digits.as_bytes().to_vec();
        for b in bytes.iter_mut().rev() {
            if *b == b'9' {
                *b = b'0';
            } else {
                *b += 1;
                return String::from_utf8(bytes).unwrap();
            }
        }
        format!("1{}", String::from_utf8(bytes).unwrap())
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(4000))]

        #[test]
        fn every_finite_real_prints_its_exact_value_rounded(bits in proptest::prelude::any::<u64>()) {
            let x = f64::from_bits(bits);
            proptest::prop_assume!(x.is_finite());
            proptest::prop_assert_eq!(format_real(x), exact_rounding(x));
        }

        /// A decimal with at most six decimals below 1e15 reads back as
        /// the same double, and prints as written where a double holds six
        /// decimals (below 2^33).
        #[test]
        fn six_decimals_read_back_the_same(negative: bool, whole in 0u64..1_000_000_000_000_000, micros in 0u32..1_000_000) {
            let sign = if negative { "-" } else { "" };
            let decimals = format!("{micros:06}");
            let decimals = match decimals.trim_end_matches('0') {
                "" => "0",
                trimmed => trimmed,
            };
            let written = format!("{sign}{whole}.{decimals}");
            let x: f64 = written.parse().unwrap();
            let printed = format_real(x);
            proptest::prop_assert_eq!(printed.parse::<f64>().unwrap().to_bits(), x.to_bits());
            if x.abs() < 8_589_934_592.0 {
                proptest::prop_assert_eq!(printed, written);
            }
        }

        /// Fifteen significant digits and an exponent print as written and
        /// read back as the same double.
        #[test]
        fn fifteen_digits_read_back_the_same(digits in 100_000_000_000_000u64..1_000_000_000_000_000, exponent in 1u32..294) {
            let written = format!("{digits}e{exponent}");
            let x: f64 = written.parse().unwrap();
            proptest::prop_assert_eq!(format_real(x), written);
        }
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
