//! Consistent Overhead Byte Stuffing: a body without a zero byte, so that a
//! zero ends a frame and a receiver that lost bytes finds the next frame at
//! the next zero. At most one byte added per 254, plus one.

/// `body` stuffed (without the closing zero).
pub fn encode(body: &[u8], out: &mut Vec<u8>) {
    let mut code_at = out.len();
    out.push(0);
    let mut code = 1u8;
    for &byte in body {
        if byte == 0 {
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        } else {
            out.push(byte);
            code += 1;
            if code == 0xFF {
                out[code_at] = code;
                code_at = out.len();
                out.push(0);
                code = 1;
            }
        }
    }
    out[code_at] = code;
}

/// The body of stuffed bytes (no zero among them), or `None` when they are
/// not a stuffing of anything (a code that runs past the end, a zero).
pub fn decode(stuffed: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(stuffed.len());
    let mut at = 0;
    while at < stuffed.len() {
        let code = stuffed[at] as usize;
        if code == 0 || at + code > stuffed.len() {
            return None;
        }
        let run = &stuffed[at + 1..at + code];
        if run.contains(&0) {
            return None;
        }
        out.extend_from_slice(run);
        at += code;
        if code < 0xFF && at < stuffed.len() {
            out.push(0);
        }
    }
    Some(out)
}
