//! One side of a link, whole: bytes in, the frames for the caller out, and
//! the bytes to write (acknowledgements, welcomes, the reliable frames and
//! their copies), as `semo_link_feed` and `semo_link_tick` do in C.

use super::frame::{Frame, FrameError, Kind, PAYLOAD_MAX};
use super::reader::Reader;
use super::session::{Incoming, Outgoing, QueueFull};

#[derive(Debug)]
pub struct Endpoint {
    pub outgoing: Outgoing,
    pub incoming: Incoming,
    reader: Reader,
    /// What this side's `Welcome` says (bit 0: the robot's broker session
    /// was kept).
    pub welcome_flags: u8,
    /// What the other side's `Welcome` said when it started this side's
    /// session (`semo_link`'s `peer_flags`: on the robot,
    /// `semo_session_resumed`).
    pub peer_flags: u8,
    /// The longest payload this side takes (said in its `Hello` and
    /// `Welcome`); a longer frame is a bad frame.
    payload_max: usize,
    /// The longest payload the other side takes, as its last `Hello` or
    /// `Welcome` said ([`PAYLOAD_MAX`] until then): a frame for it must not
    /// be longer (the gateway refuses such a message with `R`).
    pub peer_payload_max: usize,
    /// Bytes between zeros that were no frame, by why.
    pub bad_frames: Vec<FrameError>,
    /// A new reliable frame is taken without its `Ack`, which the caller
    /// gives with [`Endpoint::acknowledge`] once the frame is passed on
    /// (the gateway: when the broker has it); its copies meanwhile get
    /// none either. Otherwise every reliable frame is acknowledged as it
    /// comes.
    pub defer_acks: bool,
    /// `Hello`s taken: the other side (re)started its session, each
    /// answered with a `Welcome` (a board's mission time starts at it).
    pub hellos: u64,
}

impl Endpoint {
    /// `capacity`: reliable frames waiting behind the one in flight.
    pub fn new(capacity: usize) -> Endpoint {
        Endpoint::taking(capacity, PAYLOAD_MAX as u16)
    }

    /// An endpoint that takes payloads of at most `payload_max` bytes (as a
    /// board built with a smaller `SEMO_LINK_PAYLOAD_MAX`), at most
    /// [`PAYLOAD_MAX`].
    pub fn taking(capacity: usize, payload_max: u16) -> Endpoint {
        let payload_max = payload_max.min(PAYLOAD_MAX as u16);
        Endpoint {
            outgoing: Outgoing::new(capacity, payload_max),
            incoming: Incoming::new(),
            reader: Reader::new(),
            welcome_flags: 0,
            peer_flags: 0,
            payload_max: payload_max as usize,
            peer_payload_max: PAYLOAD_MAX,
            bad_frames: Vec::new(),
            defer_acks: false,
            hellos: 0,
        }
    }

    /// Queues a reliable frame.
    pub fn queue(&mut self, kind: Kind, payload: Vec<u8>) -> Result<(), QueueFull> {
        self.outgoing.push(kind, payload)
    }

    /// Bytes from the line at `now`: the new frames for the caller (a new
    /// reliable frame, acknowledged, or an unreliable one); what to write
    /// goes to `write`.
    pub fn feed(&mut self, bytes: &[u8], now: u64, write: &mut Vec<u8>) -> Vec<Frame> {
        let mut taken = Vec::new();
        for &byte in bytes {
            let Some(result) = self.reader.push(byte) else {
                continue;
            };
            let frame = match result {
                Ok(frame) if frame.payload.len() > self.payload_max => {
                    if self.bad_frames.len() < 1024 {
                        self.bad_frames.push(FrameError::Payload(frame.kind));
                    }
                    continue;
                }
                Ok(frame) => frame,
                Err(e) => {
                    // Bounded: the caller counts and clears them.
                    if self.bad_frames.len() < 1024 {
                        self.bad_frames.push(e);
                    }
                    continue;
                }
            };
            if let Some(max) = frame.payload_max() {
                self.peer_payload_max = max.min(PAYLOAD_MAX);
            }
            match frame.kind {
                Kind::Welcome if !self.outgoing.welcomed() => {
                    self.peer_flags = frame.payload[0];
                    self.outgoing.heard(&frame);
                }
                Kind::Ack | Kind::Welcome => self.outgoing.heard(&frame),
                Kind::Hello => {
                    self.hellos += 1;
                    self.incoming.restart();
                    let [high, low] = (self.payload_max as u16).to_be_bytes();
                    let welcome = vec![self.welcome_flags, high, low];
                    put(write, &Frame::new(Kind::Welcome, frame.seq, welcome));
                    self.outgoing.heard(&frame);
                }
                kind if kind.reliable() => {
                    let new = self.incoming.accept(frame.seq);
                    if !self.defer_acks || (!new && self.incoming.acked) {
                        self.incoming.acked = true;
                        put(write, &Frame::new(Kind::Ack, frame.seq, Vec::new()));
                    }
                    if new {
                        taken.push(frame);
                    }
                }
                _ => taken.push(frame),
            }
            self.tick(now, write);
        }
        taken
    }

    /// Acknowledges reliable frame `seq`, taken with `defer_acks` (nothing
    /// when it is not the last one taken: the session restarted since).
    pub fn acknowledge(&mut self, seq: u16, write: &mut Vec<u8>) {
        if self.incoming.unacked() == Some(seq) {
            self.incoming.acked = true;
            put(write, &Frame::new(Kind::Ack, seq, Vec::new()));
        }
    }

    /// Writes what is due at `now`.
    pub fn tick(&mut self, now: u64, write: &mut Vec<u8>) {
        while let Some(frame) = self.outgoing.poll(now) {
            put(write, &frame);
            if frame.kind == Kind::Hello || self.outgoing.deadline().is_some_and(|d| d > now) {
                break;
            }
        }
    }

    /// An unreliable frame, written now.
    pub fn emit(&self, frame: &Frame, write: &mut Vec<u8>) {
        put(write, frame);
    }
}

fn put(write: &mut Vec<u8>, frame: &Frame) {
    // Every frame made here fits: payloads are checked when queued.
    if let Some(wire) = frame.encode() {
        write.extend(wire);
    }
}
