//! A strict JSON reader that keeps the byte position of every value, for the
//! scenario file. The library takes no serde (it depends on no door), and a
//! scenario mistake found after parsing (an unknown robot, a mode the mission
//! does not have) must still point at the value that holds it — which a
//! position-free JSON tree cannot do. Mirrors the runtime's reader
//! (`semo_sim.c`): strict JSON only, duplicate keys refused, depth bounded.

/// Nesting deeper than this is refused (the runtime's `JSON_MAX_DEPTH`).
pub const MAX_DEPTH: usize = 32;

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    Null,
    Bool(bool),
    /// The number's value and its text as written.
    Number(f64, String),
    String(String),
    Array(Vec<Value>),
    /// Members in file order (duplicates are refused while reading).
    Object(Vec<(String, Value)>),
}

/// A value and the byte offset where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Value {
    pub at: usize,
    pub kind: Kind,
}

impl Value {
    pub fn member(&self, key: &str) -> Option<&Value> {
        match &self.kind {
            Kind::Object(members) => members.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }
}

/// A syntax error at a byte offset.
#[derive(Clone, Debug, PartialEq)]
pub struct JsonError {
    pub at: usize,
    pub message: String,
}

pub fn parse(text: &str) -> Result<Value, JsonError> {
    parse_one(text, "unexpected text after the scenario object")
}

/// One line of a trace (`sim::replay`): one JSON value, nothing after it.
pub fn parse_line(text: &str) -> Result<Value, JsonError> {
    parse_one(text, "unexpected text after the trace line's object")
}

fn parse_one(text: &str, after: &str) -> Result<Value, JsonError> {
    let mut reader = Reader {
        s: text.as_bytes(),
        text,
        pos: 0,
    };
    let value = reader.value(0)?;
    reader.space();
    if reader.pos < reader.s.len() {
        return Err(reader.fail(after));
    }
    Ok(value)
}

/// Objects with more members than this find a repeated key by hash rather
/// than by comparing it with every key before it (linear in the object).
const FEW_KEYS: usize = 16;

struct Reader<'a> {
    s: &'a [u8],
    text: &'a str,
    pos: usize,
}

impl Reader<'_> {
    fn fail(&self, message: &str) -> JsonError {
        JsonError {
            at: self.pos,
            message: message.to_string(),
        }
    }

    fn space(&mut self) {
        while let Some(b' ' | b'\t' | b'\n' | b'\r') = self.s.get(self.pos) {
            self.pos += 1;
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value, JsonError> {
        self.space();
        if depth > MAX_DEPTH {
            return Err(self.fail("nesting deeper than 32 levels"));
        }
        let at = self.pos;
        let kind = match self.s.get(self.pos) {
            None => return Err(self.fail("unexpected end of the file")),
            Some(b'{') => self.object(depth)?,
            Some(b'[') => self.array(depth)?,
            Some(b'"') => Kind::String(self.string()?),
            Some(b't') => self.word("true", Kind::Bool(true))?,
            Some(b'f') => self.word("false", Kind::Bool(false))?,
            Some(b'n') => self.word("null", Kind::Null)?,
            Some(b'-' | b'0'..=b'9') => self.number()?,
            Some(_) => return Err(self.fail("expected a JSON value")),
        };
        Ok(Value { at, kind })
    }

    fn word(&mut self, word: &str, kind: Kind) -> Result<Kind, JsonError> {
        if self.s[self.pos..].starts_with(word.as_bytes()) {
            self.pos += word.len();
            Ok(kind)
        } else {
            Err(self.fail("expected a JSON value"))
        }
    }

    fn digits(&mut self) -> usize {
        let start = self.pos;
        while self.s.get(self.pos).is_some_and(u8::is_ascii_digit) {
            self.pos += 1;
        }
        self.pos - start
    }

    fn number(&mut self) -> Result<Kind, JsonError> {
        let start = self.pos;
        if self.s[self.pos] == b'-' {
            self.pos += 1;
        }
        let int_start = self.pos;
        let n = self.digits();
        let malformed = JsonError {
            at: start,
            message: "malformed number".into(),
        };
        if n == 0 || (n > 1 && self.s[int_start] == b'0') {
            return Err(malformed);
        }
        if self.s.get(self.pos) == Some(&b'.') {
            self.pos += 1;
            if self.digits() == 0 {
                return Err(malformed);
            }
        }
        if let Some(b'e' | b'E') = self.s.get(self.pos) {
            self.pos += 1;
            if let Some(b'+' | b'-') = self.s.get(self.pos) {
                self.pos += 1;
            }
            if self.digits() == 0 {
                return Err(malformed);
            }
        }
        let text = &self.text[start..self.pos];
        let value: f64 = text.parse().map_err(|_| malformed)?;
        // `1e400` reads as infinity: refused, as the runtime's reader
        // refuses it (`semo_sim.c`), rather than taken for a number.
        if !value.is_finite() {
            return Err(JsonError {
                at: start,
                message: "number out of range".into(),
            });
        }
        Ok(Kind::Number(value, text.to_string()))
    }

    fn hex4(&mut self) -> Result<u32, JsonError> {
        let digits = self.s.get(self.pos..self.pos + 4).unwrap_or_default();
        let text = std::str::from_utf8(digits).unwrap_or("");
        let code = (text.len() == 4)
            .then(|| u32::from_str_radix(text, 16).ok())
            .flatten()
            .ok_or_else(|| self.fail("expected four hex digits after \\u"))?;
        self.pos += 4;
        Ok(code)
    }

    fn string(&mut self) -> Result<String, JsonError> {
        self.pos += 1; // the opening quote
        let mut out = String::new();
        loop {
            let run = self.pos;
            while let Some(&b) = self.s.get(self.pos) {
                if b == b'"' || b == b'\\' || b < 0x20 {
                    break;
                }
                self.pos += 1;
            }
            out.push_str(&self.text[run..self.pos]);
            match self.s.get(self.pos) {
                None => return Err(self.fail("unterminated string")),
                Some(b'"') => {
                    self.pos += 1;
                    return Ok(out);
                }
                Some(b'\\') => {
                    self.pos += 1;
                    let escaped = match self.s.get(self.pos) {
                        Some(b'"') => '"',
                        Some(b'\\') => '\\',
                        Some(b'/') => '/',
                        Some(b'b') => '\u{8}',
                        Some(b'f') => '\u{c}',
                        Some(b'n') => '\n',
                        Some(b'r') => '\r',
                        Some(b't') => '\t',
                        Some(b'u') => {
                            self.pos += 1;
                            let high = self.hex4()?;
                            let code = if (0xD800..0xDC00).contains(&high) {
                                if !self.s[self.pos..].starts_with(b"\\u") {
                                    return Err(self.fail("unpaired surrogate in \\u escape"));
                                }
                                self.pos += 2;
                                let low = self.hex4()?;
                                if !(0xDC00..0xE000).contains(&low) {
                                    return Err(self.fail("unpaired surrogate in \\u escape"));
                                }
                                0x10000 + ((high - 0xD800) << 10) + (low - 0xDC00)
                            } else {
                                high
                            };
                            out.push(
                                char::from_u32(code)
                                    .ok_or_else(|| self.fail("invalid \\u escape"))?,
                            );
                            continue;
                        }
                        _ => return Err(self.fail("invalid escape in string")),
                    };
                    out.push(escaped);
                    self.pos += 1;
                }
                Some(_) => return Err(self.fail("control character in string")),
            }
        }
    }

    fn array(&mut self, depth: usize) -> Result<Kind, JsonError> {
        self.pos += 1;
        let mut items = Vec::new();
        self.space();
        if self.s.get(self.pos) == Some(&b']') {
            self.pos += 1;
            return Ok(Kind::Array(items));
        }
        loop {
            items.push(self.value(depth + 1)?);
            self.space();
            match self.s.get(self.pos) {
                Some(b',') => self.pos += 1,
                Some(b']') => {
                    self.pos += 1;
                    return Ok(Kind::Array(items));
                }
                _ => return Err(self.fail("expected ',' or ']'")),
            }
        }
    }

    fn object(&mut self, depth: usize) -> Result<Kind, JsonError> {
        self.pos += 1;
        let mut members: Vec<(String, Value)> = Vec::new();
        let mut keys: crate::fasthash::FastSet<String> = Default::default();
        self.space();
        if self.s.get(self.pos) == Some(&b'}') {
            self.pos += 1;
            return Ok(Kind::Object(members));
        }
        loop {
            self.space();
            if self.s.get(self.pos) != Some(&b'"') {
                return Err(self.fail("expected a key in quotes"));
            }
            let key_at = self.pos;
            let key = self.string()?;
            let repeated = if members.len() < FEW_KEYS {
                members.iter().any(|(k, _)| *k == key)
            } else {
                if keys.is_empty() {
                    keys.extend(members.iter().map(|(k, _)| k.clone()));
                }
                !keys.insert(key.clone())
            };
            if repeated {
                return Err(JsonError {
                    at: key_at,
                    message: format!("duplicate key \"{key}\""),
                });
            }
            self.space();
            if self.s.get(self.pos) != Some(&b':') {
                return Err(self.fail("expected ':'"));
            }
            self.pos += 1;
            let value = self.value(depth + 1)?;
            members.push((key, value));
            self.space();
            match self.s.get(self.pos) {
                Some(b',') => self.pos += 1,
                Some(b'}') => {
                    self.pos += 1;
                    return Ok(Kind::Object(members));
                }
                _ => return Err(self.fail("expected ',' or '}'")),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_keep_their_offsets() {
        let v = parse(r#"{"a": [1, "x\u00e9"], "b": {"c": null}}"#).unwrap();
        let a = v.member("a").unwrap();
        assert_eq!(a.at, 6);
        let Kind::Array(items) = &a.kind else {
            panic!()
        };
        assert_eq!(items[1].kind, Kind::String("xé".into()));
        assert_eq!(items[1].at, 10);
    }

    #[test]
    fn mistakes_are_positioned() {
        for (text, at, message) in [
            ("{\"a\": 1,}", 8, "expected a key in quotes"),
            ("{\"a\": 1, \"a\": 2}", 9, "duplicate key \"a\""),
            ("[01]", 1, "malformed number"),
            ("{} x", 3, "unexpected text after the scenario object"),
            ("\"abc", 4, "unterminated string"),
            ("[0, 1e400]", 4, "number out of range"),
            ("{\"a\": -1E+309}", 6, "number out of range"),
        ] {
            let e = parse(text).unwrap_err();
            assert_eq!((e.at, e.message.as_str()), (at, message), "{text}");
        }
        // Past a few keys, a repeated one is found by hash: still at its place.
        let many: Vec<String> = (0..40).map(|i| format!("\"k{i}\": {i}")).collect();
        let text = format!("{{{}, \"k3\": 0}}", many.join(", "));
        let e = parse(&text).unwrap_err();
        assert_eq!(
            (e.at, e.message.as_str()),
            (text.rfind("\"k3\"").unwrap(), "duplicate key \"k3\"")
        );
        assert!(parse(&format!("{{{}}}", many.join(", "))).is_ok());
        let deep = "[".repeat(40);
        assert!(parse(&deep).unwrap_err().message.contains("nesting"));
    }
}
