//! The trace: one event per line, the schema `linux-sim` programs write
//! (`semo_trace` in the runtime; `docs/scenario-and-trace.md`):
//! `{"t":<mission ms>,"robot":"<robot>","event":"<event>", <string fields>}`.

use std::fmt::Write;
use std::rc::Rc;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TraceEvent {
    /// Mission ms.
    pub t: i64,
    /// Index of the robot in the run's `robots`.
    pub robot: usize,
    pub event: &'static str,
    /// String fields in the order the runtime writes them.
    pub fields: Vec<(&'static str, Rc<str>)>,
    /// For `receive`: when the message was sent (pictures draw the arrow
    /// from there; not part of the line).
    pub sent_at: Option<i64>,
}

impl TraceEvent {
    pub fn field(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| &**v)
    }

    /// The event as one JSON line (without the newline), as `semo_trace` writes it.
    pub fn to_json(&self, robot: &str) -> String {
        let mut out = String::with_capacity(64);
        let _ = write!(out, "{{\"t\":{},\"robot\":", self.t);
        json_string(&mut out, robot);
        out.push_str(",\"event\":");
        json_string(&mut out, self.event);
        for (k, v) in &self.fields {
            out.push(',');
            json_string(&mut out, k);
            out.push(':');
            json_string(&mut out, v);
        }
        out.push('}');
        out
    }
}

/// A JSON string literal (the runtime escapes the same characters).
pub fn json_string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_follow_the_runtime_schema() {
        let e = TraceEvent {
            t: 40,
            robot: 0,
            event: "send",
            fields: vec![("to", "USER".into()), ("value", "a\"b\n".into())],
            sent_at: None,
        };
        assert_eq!(
            e.to_json("irobot"),
            r#"{"t":40,"robot":"irobot","event":"send","to":"USER","value":"a\"b\n"}"#
        );
    }
}
