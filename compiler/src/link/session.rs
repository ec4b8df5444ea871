//! Reliability over the link: the reliable kinds go one at a time (stop and
//! wait: a serial line carries one frame at a time anyway), each with the
//! next sequence number, sent again every [`RETRY_MS`] until its `Ack`
//! comes; the receiver acknowledges every copy and takes a frame only when
//! its sequence number is not the last one it took (a copy whose `Ack` was
//! lost). At least once, never twice in a row: the sender sends a new
//! number only after the old one's `Ack`.
//!
//! A session starts with `Hello`: the side that (re)starts sends it (every
//! [`HELLO_RETRY_MS`]) until a `Welcome` answers, and sends no reliable frame
//! before, so the other side has forgotten the numbers of an earlier session
//! before the first new one comes (a restarted robot numbers from 0 again).
//! Time is the caller's (ms of any monotonic clock): tests step it.

use super::frame::{Frame, Kind};
use std::collections::VecDeque;

/// How long a reliable frame waits for its `Ack` before it goes again.
pub const RETRY_MS: u64 = 200;
/// How long a `Hello` waits for its `Welcome` before it goes again.
pub const HELLO_RETRY_MS: u64 = 500;

/// The reliable queue was full: the frame was not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QueueFull;

/// One side's sending half.
#[derive(Debug)]
pub struct Outgoing {
    capacity: usize,
    /// The longest payload this side takes, said in its `Hello`.
    payload_max: u16,
    queue: VecDeque<(Kind, Vec<u8>)>,
    next_seq: u16,
    /// The frame waiting for its `Ack`, and when it goes again.
    in_flight: Option<(Frame, u64)>,
    welcomed: bool,
    hello_at: Option<u64>,
    /// Reliable frames sent again (their `Ack` late or lost).
    pub retransmissions: u64,
}

impl Outgoing {
    /// A sending half holding at most `capacity` reliable frames besides
    /// the one in flight; it starts its session with `Hello`, saying
    /// `payload_max`.
    pub fn new(capacity: usize, payload_max: u16) -> Outgoing {
        Outgoing {
            capacity,
            payload_max,
            queue: VecDeque::new(),
            next_seq: 0,
            in_flight: None,
            welcomed: false,
            hello_at: None,
            retransmissions: 0,
        }
    }

    /// Queues a reliable frame.
    pub fn push(&mut self, kind: Kind, payload: Vec<u8>) -> Result<(), QueueFull> {
        if !kind.reliable()
            || payload.len() > super::frame::PAYLOAD_MAX
            || self.queue.len() >= self.capacity
        {
            return Err(QueueFull);
        }
        self.queue.push_back((kind, payload));
        Ok(())
    }

    /// Reliable frames not yet acknowledged (queued or in flight).
    pub fn pending(&self) -> usize {
        self.queue.len() + usize::from(self.in_flight.is_some())
    }

    pub fn welcomed(&self) -> bool {
        self.welcomed
    }

    /// What to write now: a `Hello` while not welcomed, the frame in flight
    /// when its wait is over, else the next queued one.
    pub fn poll(&mut self, now: u64) -> Option<Frame> {
        if !self.welcomed {
            if self.hello_at.is_some_and(|at| now < at + HELLO_RETRY_MS) {
                return None;
            }
            self.hello_at = Some(now);
            return Some(Frame::new(
                Kind::Hello,
                0,
                self.payload_max.to_be_bytes().to_vec(),
            ));
        }
        if let Some((frame, due)) = &mut self.in_flight {
            if now < *due {
                return None;
            }
            *due = now + RETRY_MS;
            self.retransmissions += 1;
            return Some(frame.clone());
        }
        let (kind, payload) = self.queue.pop_front()?;
        let frame = Frame::new(kind, self.next_seq, payload);
        self.next_seq = self.next_seq.wrapping_add(1);
        self.in_flight = Some((frame.clone(), now + RETRY_MS));
        Some(frame)
    }

    /// When [`Outgoing::poll`] next has something without a new frame or
    /// answer (`None`: only then).
    pub fn deadline(&self) -> Option<u64> {
        if !self.welcomed {
            return Some(self.hello_at.map_or(0, |at| at + HELLO_RETRY_MS));
        }
        match &self.in_flight {
            Some((_, due)) => Some(*due),
            None => (!self.queue.is_empty()).then_some(0),
        }
    }

    /// A frame from the other side that concerns the sending half: an
    /// `Ack` ends the wait of the frame in flight with its number; a
    /// `Welcome` starts the session; a `Hello` (the other side restarted)
    /// makes the frame in flight go again at once.
    pub fn heard(&mut self, frame: &Frame) {
        match frame.kind {
            Kind::Ack
                if self
                    .in_flight
                    .as_ref()
                    .is_some_and(|(f, _)| f.seq == frame.seq) =>
            {
                self.in_flight = None;
            }
            Kind::Welcome => self.welcomed = true,
            Kind::Hello => {
                if let Some((_, due)) = &mut self.in_flight {
                    *due = 0;
                }
            }
            _ => {}
        }
    }

    /// The link went away (a TCP connection closed): the next one starts a
    /// new session; what was not acknowledged goes again.
    pub fn restart(&mut self) {
        self.welcomed = false;
        self.hello_at = None;
        if let Some((_, due)) = &mut self.in_flight {
            *due = 0;
        }
    }
}

/// One side's receiving half: which reliable frames are new.
#[derive(Debug, Default)]
pub struct Incoming {
    last: Option<u16>,
    /// The last frame taken was acknowledged (its copies are then
    /// acknowledged again; before, they wait with it: `Endpoint::defer_acks`).
    pub acked: bool,
    /// Copies of a frame already taken (their `Ack` was lost).
    pub duplicates: u64,
}

impl Incoming {
    pub fn new() -> Incoming {
        Incoming::default()
    }

    /// Whether reliable frame `seq` is new (to take); every copy is
    /// acknowledged either way.
    pub fn accept(&mut self, seq: u16) -> bool {
        if self.last == Some(seq) {
            self.duplicates += 1;
            return false;
        }
        self.last = Some(seq);
        self.acked = false;
        true
    }

    /// The last frame taken, if it is `seq` and not yet acknowledged.
    pub fn unacked(&self) -> Option<u16> {
        self.last.filter(|_| !self.acked)
    }

    /// Forgets that `seq` was taken (not acknowledged, it could not be
    /// passed on): its next copy is taken again.
    pub fn forget(&mut self, seq: u16) {
        if self.unacked() == Some(seq) {
            self.last = None;
        }
    }

    /// The other side said `Hello`: its numbers start again.
    pub fn restart(&mut self) {
        self.last = None;
    }
}
