//! The trace: one event per line, the schema `linux-sim` programs write
//! (`semo_trace` in the runtime; `docs/scenario-and-trace.md`):
//! `{"t":<mission ms>,"robot":"<robot>","event":"<event>", <string fields>}`,
//! and for events that carry a value (`send`, `receive`, `call_start`,
//! `actuate`) that value last, its JSON type following its type.

use crate::refine::value::{self, Value};
use std::fmt::Write;
use std::rc::Rc;

/// A trace event's string fields: inline up to three (most events), so
/// that making an event allocates no list.
pub type Fields = smallvec::SmallVec<[(&'static str, Rc<str>); 3]>;

#[derive(Clone, Debug, PartialEq)]
pub struct TraceEvent {
    /// Mission ms.
    pub t: i64,
    /// Index of the robot in the run's `robots`.
    pub robot: usize,
    pub event: &'static str,
    /// String fields in the order the runtime writes them.
    pub fields: Fields,
    /// The typed value written after them (`semo_trace_value`): its key and
    /// the value (`None`: no value, `null`).
    pub value: Option<(&'static str, Option<Value>)>,
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
        // Room for most lines at once: a message's line (sender, key and
        // value) is about 100 bytes, and from 64 each grew once more.
        let mut out = String::with_capacity(128);
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
        if let Some((k, v)) = &self.value {
            out.push(',');
            json_string(&mut out, k);
            out.push(':');
            write_value(&mut out, v.as_ref());
        }
        out.push('}');
        out
    }

    /// The typed value as JSON (`null` when the event has none).
    pub fn value_json(&self) -> String {
        let mut out = String::new();
        write_value(&mut out, self.value.as_ref().and_then(|(_, v)| v.as_ref()));
        out
    }
}

/// A value's JSON as the runtime writes it (`semo_value_json`): integers and
/// finite reals as numbers, truth values as `true`/`false`, words and text
/// as strings, no value (and an infinite real) as `null`.
pub fn write_value(out: &mut String, v: Option<&Value>) {
    match v {
        None => out.push_str("null"),
        Some(Value::Int(i)) => {
            let _ = write!(out, "{i}");
        }
        Some(Value::Real(r)) if !r.is_finite() => out.push_str("null"),
        Some(Value::Real(r)) => out.push_str(&value::format_real(*r)),
        Some(Value::Bool(b)) => {
            let _ = write!(out, "{b}");
        }
        Some(Value::Word(w) | Value::Text(w)) => json_string(out, w),
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
            fields: smallvec::smallvec![("to", "USER".into())],
            value: Some(("value", Some(Value::text("a\"b\n")))),
            sent_at: None,
        };
        assert_eq!(
            e.to_json("irobot"),
            r#"{"t":40,"robot":"irobot","event":"send","to":"USER","value":"a\"b\n"}"#
        );
        let typed = |v: Option<Value>| TraceEvent {
            value: Some(("value", v)),
            ..e.clone()
        };
        let line = |v| typed(v).to_json("r");
        assert!(line(Some(Value::Int(-42))).ends_with(r#""value":-42}"#));
        assert!(line(Some(Value::Real(2.5))).ends_with(r#""value":2.5}"#));
        assert!(line(Some(Value::Bool(true))).ends_with(r#""value":true}"#));
        assert!(line(Some(Value::Word("LEFT".into()))).ends_with(r#""value":"LEFT"}"#));
        assert!(line(None).ends_with(r#""value":null}"#));
    }
}
