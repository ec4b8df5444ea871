//! C spelling: string literals, comments and identifiers from mission names,
//! and each layer's lock of state shared between tasks.

use super::{Layer, Target};

/// A C string literal for `text`: quotes, backslashes, control characters,
/// non-ASCII bytes (as octal) and `?` (no trigraphs) escaped.
pub fn string(text: &str) -> String {
    let mut out = String::from("\"");
    for b in text.bytes() {
        match b {
            b'"' => out.push_str("\\\""),
            b'\\' => out.push_str("\\\\"),
            b'?' => out.push_str("\\?"),
            b'\n' => out.push_str("\\n"),
            0x20..=0x7e => out.push(b as char),
            other => out.push_str(&format!("\\{other:03o}")),
        }
    }
    out.push('"');
    out
}

/// A C `double` literal that reads back as `x` exactly (Rust's shortest
/// round-trip spelling: `0.01`, `1e-6`, `100.0`, all C). The scenario's
/// numbers are finite (its reader refuses others); a non-finite one is
/// written as `<math.h>`'s name, which the file does not include, so that
/// it fails to compile rather than reading as another number.
pub fn real(x: f64) -> String {
    if x.is_nan() {
        "NAN".into()
    } else if x.is_infinite() {
        if x > 0.0 { "INFINITY" } else { "-INFINITY" }.into()
    } else {
        format!("{x:?}")
    }
}

/// Text safe inside a `/* */` comment on one line: no line breaks or other
/// control characters, no backslash (a line splice before the comment's end),
/// and no `*/`, `/*` or `??` however the pieces meet (one pass, so no
/// replacement can create what an earlier one removed).
pub fn comment(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        let c = if c == '\\' { '/' } else { c };
        match c {
            c if c.is_control() => out.push(' '),
            '*' if out.ends_with('/') => out.push_str(" *"),
            '/' if out.ends_with('*') => out.push_str(" /"),
            '?' if out.ends_with('?') => out.push_str(" ?"),
            c => out.push(c),
        }
    }
    out
}

/// An identifier fragment: letters, digits and `_`, everything else `_`.
pub fn ident(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The lock of state shared between tasks: a mutex on threads, nothing on
/// the static schedule (one task runs at a time). `(include, declare, lock,
/// unlock)` for a lock named `name`.
pub fn lock(target: Target, name: &str) -> (&'static str, String, String, String) {
    match target.layer() {
        Layer::Threads => (
            "#include <pthread.h>\n",
            format!("static pthread_mutex_t {name} = PTHREAD_MUTEX_INITIALIZER;\n"),
            format!("pthread_mutex_lock(&{name});"),
            format!("pthread_mutex_unlock(&{name});"),
        ),
        Layer::Static => (
            "",
            String::new(),
            "/* no lock: one task runs at a time */".into(),
            "/* end of the access */".into(),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_are_c_literals_that_read_back_exactly() {
        for x in [0.01, 1e-6, 100.0, -5.5, 1e15, 1e16, 0.1 + 0.2, 1e6] {
            let written = real(x);
            assert!(
                written.contains('.') || written.contains('e'),
                "{written}: a double, not an int"
            );
            assert_eq!(written.parse::<f64>(), Ok(x));
        }
        assert_eq!(real(f64::NAN), "NAN");
    }

    #[test]
    fn strings_are_escaped() {
        assert_eq!(string("a\"b\\c"), r#""a\"b\\c""#);
        assert_eq!(string("??="), r#""\?\?=""#);
        assert_eq!(string("é"), r#""\303\251""#);
    }

    #[test]
    fn comments_cannot_end_early() {
        assert_eq!(comment("x */ y ??/"), "x * / y ? ?/");
        // A backslash becomes `/`, which must not close the comment either.
        assert_eq!(comment("x*\\ int i; \\*"), "x* / int i; / *");
        assert_eq!(comment("*/*/"), "* / * /");
        assert_eq!(comment("a\nb\r\tc"), "a b  c");
    }

    #[test]
    fn unsafe_names() {}
}
