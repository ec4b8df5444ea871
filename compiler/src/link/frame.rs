//! A frame: `kind` (one byte), `seq` (two bytes, big-endian), the payload,
//! then the CRC-16/CCITT-FALSE of all of them (big-endian); COBS-stuffed
//! and closed by a zero byte on the wire.

use super::cobs;

/// The longest payload: a `send` to a name of 255 bytes with the runtime's
/// largest datagram (`SEMO__DATAGRAM_MAX`, 1031) fits, and a status line of
/// that order (`SEMO_LINK_PAYLOAD_MAX` in `semo_link.c`, the same).
pub const PAYLOAD_MAX: usize = 1536;
/// Kind, sequence number, payload, CRC.
pub const BODY_MAX: usize = 3 + PAYLOAD_MAX + 2;
/// The stuffed body and its closing zero.
pub const WIRE_MAX: usize = BODY_MAX + BODY_MAX / 254 + 1 + 1;

/// What a frame is for. The reliable kinds are acknowledged and sent again
/// until they are; the others go once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// `H`: a side (re)starts a session: the other forgets the sequence
    /// numbers it saw and answers `Welcome`. Two bytes (big-endian): the
    /// longest payload the sender takes (a board's may be smaller than
    /// [`PAYLOAD_MAX`]).
    Hello,
    /// `W`: the answer to `Hello` (its `seq`); one byte of flags, bit 0: the
    /// broker kept the robot's session (`semo_session_resumed`), then the
    /// sender's longest payload, as in `Hello`.
    Welcome,
    /// `S` (robot to gateway, reliable): a `send`: the destination (a team,
    /// a robot or `USER`) as a length byte and its bytes, then the datagram.
    Send,
    /// `P` (robot to gateway): a `publish`, as `Send`, at most once.
    Publish,
    /// `T` (robot to gateway, reliable): the robot's status (JSON).
    Status,
    /// `M` (gateway to robot, reliable): a datagram the broker delivered on
    /// one of the robot's topics.
    Message,
    /// `R` (gateway to robot, reliable): a message the gateway refused; one
    /// byte says why ([`Refusal`]).
    Refused,
    /// `A`: the reliable frame `seq` arrived. Empty.
    Ack,
}

impl Kind {
    pub const ALL: [Kind; 8] = [
        Kind::Hello,
        Kind::Welcome,
        Kind::Send,
        Kind::Publish,
        Kind::Status,
        Kind::Message,
        Kind::Refused,
        Kind::Ack,
    ];

    pub fn byte(self) -> u8 {
        match self {
            Kind::Hello => b'H',
            Kind::Welcome => b'W',
            Kind::Send => b'S',
            Kind::Publish => b'P',
            Kind::Status => b'T',
            Kind::Message => b'M',
            Kind::Refused => b'R',
            Kind::Ack => b'A',
        }
    }

    pub fn from_byte(byte: u8) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.byte() == byte)
    }

    /// Acknowledged, sent again until it is, taken once.
    pub fn reliable(self) -> bool {
        matches!(
            self,
            Kind::Send | Kind::Status | Kind::Message | Kind::Refused
        )
    }
}

/// Why the gateway refused a message from the broker (an `R`'s byte).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// `T`: its datagram names another sender or key than its topic.
    Topic,
    /// `L`: it is longer than the robot takes (the bound its `Hello` or
    /// `Welcome` said).
    Length,
}

impl Refusal {
    pub fn byte(self) -> u8 {
        match self {
            Refusal::Topic => b'T',
            Refusal::Length => b'L',
        }
    }
}

/// Why bytes between two zeros are no frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// More bytes than the longest frame before a zero.
    TooLong,
    /// Not a COBS stuffing.
    Stuffing,
    /// Shorter than a kind, a sequence number and a CRC.
    TooShort,
    /// The CRC does not match: bytes were changed or lost.
    Checksum,
    /// A kind byte no side sends.
    UnknownKind(u8),
    /// The payload does not fit its kind (an `Ack` with bytes, a `Send`
    /// whose destination runs past the end, ...).
    Payload(Kind),
}

impl std::fmt::Display for FrameError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FrameError::TooLong => write!(f, "longer than {WIRE_MAX} bytes"),
            FrameError::Stuffing => write!(f, "not COBS-stuffed"),
            FrameError::TooShort => write!(f, "too short"),
            FrameError::Checksum => write!(f, "CRC mismatch"),
            FrameError::UnknownKind(k) => write!(f, "unknown kind 0x{k:02x}"),
            FrameError::Payload(k) => write!(f, "payload does not fit a {k:?} frame"),
        }
    }
}

/// A frame, decoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    pub kind: Kind,
    pub seq: u16,
    pub payload: Vec<u8>,
}

/// CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection,
/// no final xor (check value of "123456789": 0x29B1).
pub fn crc16(bytes: &[u8]) -> u16 {
    let mut crc = 0xFFFFu16;
    for &b in bytes {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

impl Frame {
    pub fn new(kind: Kind, seq: u16, payload: Vec<u8>) -> Frame {
        Frame { kind, seq, payload }
    }

    /// A `Send` or `Publish` to `to` carrying `datagram`; `None` when `to`
    /// is empty or longer than 255 bytes, or the whole does not fit.
    pub fn addressed(kind: Kind, seq: u16, to: &str, datagram: &[u8]) -> Option<Frame> {
        if to.is_empty() || to.len() > 255 || 1 + to.len() + datagram.len() > PAYLOAD_MAX {
            return None;
        }
        let mut payload = Vec::with_capacity(1 + to.len() + datagram.len());
        payload.push(to.len() as u8);
        payload.extend_from_slice(to.as_bytes());
        payload.extend_from_slice(datagram);
        Some(Frame::new(kind, seq, payload))
    }

    /// A `Send`'s or `Publish`'s destination bytes and datagram.
    pub fn destination(&self) -> Option<(&[u8], &[u8])> {
        if !matches!(self.kind, Kind::Send | Kind::Publish) {
            return None;
        }
        let (&n, rest) = self.payload.split_first()?;
        let n = n as usize;
        (n > 0 && rest.len() >= n).then(|| rest.split_at(n))
    }

    /// The frame on the wire: stuffed, closed by a zero. `None` when the
    /// payload is longer than [`PAYLOAD_MAX`].
    pub fn encode(&self) -> Option<Vec<u8>> {
        if self.payload.len() > PAYLOAD_MAX {
            return None;
        }
        let mut body = Vec::with_capacity(5 + self.payload.len());
        body.push(self.kind.byte());
        body.extend_from_slice(&self.seq.to_be_bytes());
        body.extend_from_slice(&self.payload);
        let crc = crc16(&body);
        body.extend_from_slice(&crc.to_be_bytes());
        let mut wire = Vec::with_capacity(body.len() + body.len() / 254 + 2);
        cobs::encode(&body, &mut wire);
        wire.push(0);
        Some(wire)
    }

    /// The payload bound a `Hello` or `Welcome` says.
    pub fn payload_max(&self) -> Option<usize> {
        let bytes = match self.kind {
            Kind::Hello => &self.payload[..],
            Kind::Welcome => self.payload.get(1..)?,
            _ => return None,
        };
        Some(u16::from_be_bytes(bytes.try_into().ok()?) as usize)
    }

    /// The frame of the bytes between two zeros (without them).
    pub fn decode(stuffed: &[u8]) -> Result<Frame, FrameError> {
        if stuffed.len() + 1 > WIRE_MAX {
            return Err(FrameError::TooLong);
        }
        let body = cobs::decode(stuffed).ok_or(FrameError::Stuffing)?;
        if body.len() < 5 {
            return Err(FrameError::TooShort);
        }
        let (content, crc) = body.split_at(body.len() - 2);
        if crc16(content) != u16::from_be_bytes([crc[0], crc[1]]) {
            return Err(FrameError::Checksum);
        }
        let kind = Kind::from_byte(content[0]).ok_or(FrameError::UnknownKind(content[0]))?;
        let frame = Frame::new(
            kind,
            u16::from_be_bytes([content[1], content[2]]),
            content[3..].to_vec(),
        );
        if frame.payload.len() > PAYLOAD_MAX || !frame.fits() {
            return Err(FrameError::Payload(kind));
        }
        Ok(frame)
    }

    /// Whether the payload has its kind's shape.
    fn fits(&self) -> bool {
        match self.kind {
            Kind::Ack => self.payload.is_empty(),
            Kind::Refused => self.payload.len() == 1,
            Kind::Hello => self.payload.len() == 2,
            Kind::Welcome => self.payload.len() == 3,
            Kind::Send | Kind::Publish => self.destination().is_some(),
            Kind::Status | Kind::Message => !self.payload.is_empty(),
        }
    }
}
