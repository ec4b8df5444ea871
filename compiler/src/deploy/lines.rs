//! What a line of the broker's files can carry. mosquitto reads its
//! configuration and its ACL a line at a time (`KEYWORD VALUE`): it cuts
//! the text at line breaks, drops the blanks at a line's end, takes a line
//! starting with `#` for a comment, and takes a value as the rest of the
//! line with the blanks at both ends trimmed (mosquitto 2's `conf.c` and
//! `security_default.c`); its password file is `user:hash` lines. So a value
//! with a control character (a line break starts a directive of its own),
//! with a blank at an end, or empty, cannot be written as it is, nor can a
//! user name with `:` be in the password file. `broker.rs` checks every
//! value it writes here; `parse.rs` reports the deployment file's values
//! that fail, at their position (E127).

use std::path::Path;

/// Why `text` cannot be inside a line of mosquitto's files (a topic's
/// level); `None` when it can.
pub fn text_problem(text: &str) -> Option<String> {
    let c = text.chars().find(|c| c.is_control())?;
    Some(format!(
        "it holds the control character U+{:04X}, which would end the line or be taken for another",
        u32::from(c)
    ))
}

/// Why `value` cannot be a value of a line of mosquitto's files; `None`
/// when it can.
pub fn value_problem(value: &str) -> Option<String> {
    if value.is_empty() {
        return Some("it is empty".into());
    }
    if let Some(problem) = text_problem(value) {
        return Some(problem);
    }
    if value.starts_with(' ') || value.ends_with(' ') {
        return Some("it starts or ends with a space, which mosquitto trims".into());
    }
    None
}

/// Why `user` cannot be a user of the broker's ACL and password file.
pub fn user_problem(user: &str) -> Option<String> {
    value_problem(user).or_else(|| {
        user.contains(':').then(|| {
            "it holds `:`, which ends a user name in mosquitto's password file".to_string()
        })
    })
}

/// Why `path` cannot be written as a path of mosquitto's configuration.
pub fn path_problem(path: &Path) -> Option<String> {
    match path.to_str() {
        Some(text) => value_problem(text),
        None => Some("it is not UTF-8, which mosquitto's configuration must be".into()),
    }
}

/// `text` for a `#` comment: on one line, quoted, its control characters
/// escaped (a line break would end the comment and start a directive).
pub fn comment(text: &str) -> String {
    format!("{text:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_is_one_line_without_blanks_at_its_ends() {
        assert_eq!(value_problem("semo/m/T/+/+/+"), None);
        assert_eq!(value_problem("/etc/mosquitto/my passwords"), None);
        assert!(value_problem("slaves\npattern readwrite #").is_some_and(|p| p.contains("U+000A")));
        assert!(value_problem("a\rb").is_some());
        assert!(value_problem("a\u{0}").is_some());
        assert!(value_problem(" a").is_some() && value_problem("a ").is_some());
        assert!(value_problem("").is_some());
        assert!(user_problem("a:b").is_some_and(|p| p.contains("password file")));
        assert_eq!(user_problem("ops team"), None);
        assert_eq!(
            comment("a\nlistener 1 0.0.0.0"),
            "\"a\\nlistener 1 0.0.0.0\""
        );
    }
}
