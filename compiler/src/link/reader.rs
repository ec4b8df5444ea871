//! Frames out of a byte stream. Bytes are kept up to the next zero, never
//! more than a frame can be: a longer run (noise, a flood without zeros) is
//! one `TooLong` error at its zero, in bounded memory.

use super::frame::{Frame, FrameError, WIRE_MAX};

#[derive(Debug, Default)]
pub struct Reader {
    buf: Vec<u8>,
    overflow: bool,
}

impl Reader {
    pub fn new() -> Reader {
        Reader::default()
    }

    /// One byte of the stream: a frame (or why it is none) at each zero
    /// that ends some bytes; nothing for the zero of an empty frame (a
    /// sender may send zeros to resynchronise).
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, FrameError>> {
        if byte != 0 {
            if self.buf.len() + 1 < WIRE_MAX {
                self.buf.push(byte);
            } else {
                self.overflow = true;
            }
            return None;
        }
        let result = if self.overflow {
            Some(Err(FrameError::TooLong))
        } else if self.buf.is_empty() {
            None
        } else {
            Some(Frame::decode(&self.buf))
        };
        self.buf.clear();
        self.overflow = false;
        result
    }

    /// Every frame (or error) the bytes end.
    pub fn push_all(&mut self, bytes: &[u8]) -> Vec<Result<Frame, FrameError>> {
        bytes.iter().filter_map(|&b| self.push(b)).collect()
    }
}
