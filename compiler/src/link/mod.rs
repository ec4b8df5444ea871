//! The serial link between a small robot and `semo gateway` (docs/link.md):
//! one definition of its frames, written twice, here and in the runtime's
//! `semo_link.c`, and tested against each other (`tests/link.rs`).
//!
//! - `frame`: a frame's kinds and bytes (COBS framing, CRC-16/CCITT-FALSE).
//! - `reader`: frames out of a byte stream, whatever the stream holds.
//! - `session`: acknowledgement and retransmission of the reliable kinds,
//!   duplicate suppression by sequence number, the hello that starts a
//!   session; driven by the caller's clock, so tests step it.
//! - `endpoint`: one side whole (bytes in, frames out, what to write), as
//!   `semo_link_feed`/`semo_link_tick` are in C.
//!
//! Nothing here trusts a frame: a frame carries a destination and the
//! runtime's datagram, never who sent it. The gateway knows the robot from
//! the link it came on.

mod cobs;
mod endpoint;
mod frame;
mod reader;
mod session;

pub use endpoint::Endpoint;
pub use frame::{BODY_MAX, Frame, FrameError, Kind, PAYLOAD_MAX, Refusal, WIRE_MAX, crc16};
pub use reader::Reader;
pub use session::{HELLO_RETRY_MS, Incoming, Outgoing, QueueFull, RETRY_MS};

#[cfg(test)]
mod tests;
