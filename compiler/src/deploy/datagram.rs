//! The runtime's datagram (`semo__encode_message` in `semo_core.c`, the
//! format in `semo_internal.h`), written once on this side for the programs
//! that speak to robots without being one: the operator console and the
//! tests that forge operator commands.
//!
//! `"SEMO" 0x02 <kind>`, then team, robot and key (each a length byte and
//! that many bytes), then the value: a type byte and, by type, nothing
//! (none), 8 bytes big-endian (integer; a real's IEEE 754 bits), one byte
//! (truth value), or a length byte and the text (word, text).

use crate::refine::Value;

const MAGIC: &[u8] = b"SEMO\x02";
/// The type bytes (`semo_type`).
const NONE: u8 = 0;
const INT: u8 = 1;
const REAL: u8 = 2;
const BOOL: u8 = 3;
const WORD: u8 = 4;
const TEXT: u8 = 5;

/// A decoded datagram.
#[derive(Clone, Debug, PartialEq)]
pub struct Datagram {
    pub publish: bool,
    pub team: String,
    pub robot: String,
    pub key: String,
    pub value: Option<Value>,
}

fn put_field(out: &mut Vec<u8>, text: &str) {
    let mut end = text.len().min(255);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    out.push(end as u8);
    out.extend_from_slice(&text.as_bytes()[..end]);
}

/// A `send` from `team`/`robot` (a `USER` command: team `USER`). An
/// operator's command goes as text: the robot reads it as the type its
/// mission declares for the key (`semo_value_coerce`).
pub fn encode(d: &Datagram) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    out.push(if d.publish { b'p' } else { b's' });
    for field in [&d.team, &d.robot, &d.key] {
        put_field(&mut out, field);
    }
    match &d.value {
        None => out.push(NONE),
        Some(Value::Int(i)) => {
            out.push(INT);
            out.extend_from_slice(&i.to_be_bytes());
        }
        Some(Value::Real(r)) => {
            out.push(REAL);
            out.extend_from_slice(&r.to_bits().to_be_bytes());
        }
        Some(Value::Bool(b)) => out.extend_from_slice(&[BOOL, *b as u8]),
        Some(Value::Word(w)) => {
            out.push(WORD);
            put_field(&mut out, w);
        }
        Some(Value::Text(t)) => {
            out.push(TEXT);
            put_field(&mut out, t);
        }
    }
    out
}

/// The bytes of a SHA-256 digest: the tag a signed datagram ends with.
pub const TAG_LEN: usize = 32;

/// The bytes between a signed datagram and its tag: the sender's place in
/// the mission (u32: its `semo_peer.index`, [`OUTSIDER`] for a sender outside
/// it) and its counter (u64), little-endian, signed with it.
pub const STAMP_LEN: usize = 12;

/// The sender index of a signer outside the mission's peer table (the
/// operator's console, a test): every such signer shares one counter slot
/// at each robot.
pub const OUTSIDER: u32 = u32::MAX;

/// A counter as `semo_udp.c` stamps one: the machine's monotonic clock
/// (`CLOCK_MONOTONIC`, system-wide, never steps back) in ns. A robot takes
/// from a sender only a counter later than the last it took from it and at
/// most 5 s old, so a replayed datagram is refused.
pub fn counter_now() -> u64 {
    let now = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    (now.tv_sec as u64) * 1_000_000_000 + now.tv_nsec as u64
}

/// `datagram` signed with a `linux-sim` run's key (`$SEMO_UDP_KEY`, 16 to
/// 64 bytes) as `semo_udp.c` sends and checks it: the datagram, the stamp
/// (`sender`, `counter`: see [`STAMP_LEN`], [`counter_now`]) and the
/// HMAC-SHA256 under the key (RFC 2104) of both. HMAC is the formula over
/// `sha2` rather than another crate: the C side carries its own SHA-256
/// anyway (robots link nothing but libc), and both are held to RFC 4231's
/// vectors.
pub fn sign(key: &[u8], sender: u32, counter: u64, datagram: &[u8]) -> Vec<u8> {
    let mut out = datagram.to_vec();
    out.extend_from_slice(&sender.to_le_bytes());
    out.extend_from_slice(&counter.to_le_bytes());
    out.extend_from_slice(&hmac_sha256(key, &out));
    out
}

/// HMAC-SHA256 for a key of at most one block (64 bytes).
fn hmac_sha256(key: &[u8], data: &[u8]) -> [u8; TAG_LEN] {
    use sha2::{Digest, Sha256};
    assert!(key.len() <= 64, "a run key is at most 64 bytes");
    let mut pad = [0x36u8; 64];
    for (p, k) in pad.iter_mut().zip(key) {
        *p ^= k;
    }
    let inner = Sha256::new()
        .chain_update(pad)
        .chain_update(data)
        .finalize();
    for p in &mut pad {
        *p ^= 0x36 ^ 0x5c;
    }
    Sha256::new()
        .chain_update(pad)
        .chain_update(inner)
        .finalize()
        .into()
}

/// The datagram, or `None` for anything else.
pub fn decode(data: &[u8]) -> Option<Datagram> {
    let rest = data.strip_prefix(MAGIC)?;
    let (&kind, mut rest) = rest.split_first()?;
    let publish = match kind {
        b'p' => true,
        b's' => false,
        _ => return None,
    };
    let field = |rest: &mut &[u8]| -> Option<String> {
        let (&n, tail) = rest.split_first()?;
        let text = tail.get(..n as usize)?;
        *rest = &tail[n as usize..];
        String::from_utf8(text.to_vec()).ok()
    };
    let team = field(&mut rest)?;
    let robot = field(&mut rest)?;
    let key = field(&mut rest)?;
    let (&ty, mut rest) = rest.split_first()?;
    let value = match ty {
        NONE => None,
        INT | REAL => {
            let bytes: [u8; 8] = rest.get(..8)?.try_into().ok()?;
            rest = &rest[8..];
            Some(match ty {
                INT => Value::Int(i64::from_be_bytes(bytes)),
                _ => Value::Real(f64::from_bits(u64::from_be_bytes(bytes))),
            })
        }
        BOOL => {
            let (&b, tail) = rest.split_first()?;
            rest = tail;
            Some(Value::Bool(match b {
                0 => false,
                1 => true,
                _ => return None,
            }))
        }
        WORD => Some(Value::Word(field(&mut rest)?.into())),
        TEXT => Some(Value::Text(field(&mut rest)?.into())),
        _ => return None,
    };
    rest.is_empty().then_some(Datagram {
        publish,
        team,
        robot,
        key,
        value,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_reads_back() {
        for value in [
            None,
            Some(Value::Int(-42)),
            Some(Value::Real(2.5)),
            Some(Value::Bool(true)),
            Some(Value::Word("LEFT".into())),
            Some(Value::Text("5,5".into())),
        ] {
            let d = Datagram {
                publish: false,
                team: "USER".into(),
                robot: "operator".into(),
                key: "USER.RC_CMD".into(),
                value,
            };
            assert_eq!(decode(&encode(&d)), Some(d));
        }
        assert_eq!(decode(b"SEMO\x01sabc"), None);
    }

    /// RFC 4231's test cases 1 and 2 (the C side is held to the same
    /// function by `tests/runtime_c.rs`, which signs with `sign`).
    #[test]
    fn the_tag_is_hmac_sha256() {
        let hex = |bytes: &[u8]| bytes.iter().map(|b| format!("{b:02x}")).collect::<String>();
        assert_eq!(
            hex(&hmac_sha256(&[0x0b; 20], b"Hi There")),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7"
        );
        assert_eq!(
            hex(&hmac_sha256(b"Jefe", b"what do ya want for nothing?")),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
        );
        // What `sign` adds: the stamp, then the tag of all before it.
        let signed = sign(b"Jefe", 2, 0x0102, b"data");
        let (body, tag) = signed.split_at(signed.len() - TAG_LEN);
        assert_eq!(body, b"data\x02\0\0\0\x02\x01\0\0\0\0\0\0");
        assert_eq!(body.len(), 4 + STAMP_LEN);
        assert_eq!(tag, hmac_sha256(b"Jefe", body));
    }

    /// The bytes `semo_core.c` writes for an integer (the C side is held to
    /// the same bytes by `tests/runtime_c.rs`).
    #[test]
    fn an_integer_is_eight_bytes_big_endian() {
        let d = Datagram {
            publish: true,
            team: "T".into(),
            robot: "r".into(),
            key: "T.X".into(),
            value: Some(Value::Int(258)),
        };
        assert_eq!(
            encode(&d),
            b"SEMO\x02p\x01T\x01r\x03T.X\x01\x00\x00\x00\x00\x00\x00\x01\x02".to_vec()
        );
    }
}
