use super::cobs;
use super::*;

fn wire(kind: Kind, seq: u16, payload: &[u8]) -> Vec<u8> {
    Frame::new(kind, seq, payload.to_vec()).encode().unwrap()
}

#[test]
fn the_crc_is_ccitt_false() {
    assert_eq!(crc16(b"123456789"), 0x29B1);
    assert_eq!(crc16(b""), 0xFFFF);
}

#[test]
fn cobs_round_trips_zeros_and_long_runs() {
    let cases: Vec<Vec<u8>> = vec![
        vec![],
        vec![0],
        vec![0, 0],
        vec![1, 2, 0, 3],
        (1..=254).collect(),
        (1..=255).collect(),
        vec![7; 1000],
        (0..1000).map(|i| (i % 7) as u8).collect(),
    ];
    for body in cases {
        let mut stuffed = Vec::new();
        cobs::encode(&body, &mut stuffed);
        assert!(!stuffed.contains(&0), "{body:?}");
        assert!(stuffed.len() <= body.len() + body.len() / 254 + 1);
        assert_eq!(cobs::decode(&stuffed), Some(body));
    }
    assert_eq!(cobs::decode(&[5, 1, 2]), None, "a code past the end");
}

#[test]
fn every_kind_round_trips_through_the_reader() {
    let frames = vec![
        Frame::new(Kind::Hello, 0, vec![6, 0]),
        Frame::new(Kind::Welcome, 0, vec![1, 0, 164]),
        Frame::addressed(Kind::Send, 7, "SlaveTeam", b"SEMO\x02s\x00\x00\x00\x00").unwrap(),
        Frame::addressed(Kind::Publish, 0, "USER", &[0; 40]).unwrap(),
        Frame::new(Kind::Status, 65535, br#"{"state":"running"}"#.to_vec()),
        Frame::new(Kind::Message, 3, vec![0, 1, 2, 0]),
        Frame::new(Kind::Refused, 4, vec![Refusal::Length.byte()]),
        Frame::new(Kind::Ack, 9, vec![]),
        Frame::new(Kind::Message, 1, vec![0; PAYLOAD_MAX]),
    ];
    let mut stream = vec![0, 0];
    for f in &frames {
        stream.extend(f.encode().unwrap());
    }
    let got: Vec<Frame> = Reader::new()
        .push_all(&stream)
        .into_iter()
        .map(Result::unwrap)
        .collect();
    assert_eq!(got, frames);
    assert!(frames.iter().all(|f| f.encode().unwrap().len() <= WIRE_MAX));
}

#[test]
fn bad_bytes_are_errors_and_the_next_frame_is_read() {
    let good = wire(Kind::Ack, 1, &[]);
    let mut flipped = wire(Kind::Message, 2, b"hello");
    flipped[3] ^= 0x10;
    let truncated = {
        let w = wire(Kind::Message, 3, b"hello");
        let mut t = w[..w.len() - 3].to_vec();
        t.push(0);
        t
    };
    let unknown = {
        let body = [b'Z', 0, 1];
        let mut b = body.to_vec();
        b.extend(crc16(&body).to_be_bytes());
        let mut w = Vec::new();
        cobs::encode(&b, &mut w);
        w.push(0);
        w
    };
    let ack_with_bytes = wire(Kind::Ack, 1, b"x");
    let flood = vec![0x55; 10 * WIRE_MAX];
    let mut stream = Vec::new();
    for part in [
        &flipped,
        &truncated,
        &unknown,
        &ack_with_bytes,
        &flood,
        &vec![0],
        &good,
    ] {
        stream.extend_from_slice(part);
    }
    let got = Reader::new().push_all(&stream);
    assert_eq!(
        got,
        vec![
            Err(FrameError::Checksum),
            // Cut short: its last COBS code runs past the end.
            Err(FrameError::Stuffing),
            Err(FrameError::UnknownKind(b'Z')),
            Err(FrameError::Payload(Kind::Ack)),
            Err(FrameError::TooLong),
            Ok(Frame::new(Kind::Ack, 1, vec![])),
        ]
    );
}

#[test]
fn any_bytes_decode_without_panicking() {
    // Every prefix of a frame, every single-byte change of it.
    let w = wire(Kind::Send, 5, b"\x04Teamdatagram");
    for end in 0..w.len() {
        let _ = Frame::decode(&w[..end]);
    }
    for i in 0..w.len() - 1 {
        for bit in 0..8 {
            let mut b = w[..w.len() - 1].to_vec();
            b[i] ^= 1 << bit;
            if let Ok(f) = Frame::decode(&b) {
                // A change the CRC missed would have to keep the CRC: none
                // of one bit does.
                panic!("one flipped bit accepted: {f:?}");
            }
        }
    }
}

#[test]
fn a_send_names_a_destination_of_one_to_255_bytes() {
    assert!(Frame::addressed(Kind::Send, 0, "", b"d").is_none());
    assert!(Frame::addressed(Kind::Send, 0, &"x".repeat(256), b"d").is_none());
    let f = Frame::addressed(Kind::Send, 0, "ti", b"data").unwrap();
    assert_eq!(f.destination(), Some((&b"ti"[..], &b"data"[..])));
    assert_eq!(
        Frame::decode(&{
            let mut w = wire(Kind::Send, 0, b"\x09ab");
            w.pop();
            w
        }),
        Err(FrameError::Payload(Kind::Send))
    );
}

/// Two sessions over a lossy wire, stepped by hand.
#[test]
fn a_lost_ack_brings_a_retransmission_whose_copy_is_not_taken_twice() {
    let mut robot = Outgoing::new(4, PAYLOAD_MAX as u16);
    let mut gateway_in = Incoming::new();
    // The session starts: Hello, then nothing reliable before Welcome.
    robot.push(Kind::Send, b"\x01Tx".to_vec()).unwrap();
    assert_eq!(robot.poll(0).unwrap().kind, Kind::Hello);
    assert_eq!(robot.poll(10), None, "Hello waits for its Welcome");
    assert_eq!(robot.poll(HELLO_RETRY_MS).unwrap().kind, Kind::Hello);
    gateway_in.restart();
    robot.heard(&Frame::new(Kind::Welcome, 0, vec![0, 6, 0]));
    let first = robot.poll(600).unwrap();
    assert_eq!((first.kind, first.seq), (Kind::Send, 0));
    assert!(gateway_in.accept(first.seq));
    // Its Ack is lost: the same frame again after RETRY_MS, not before.
    assert_eq!(robot.poll(600 + RETRY_MS - 1), None);
    let again = robot.poll(600 + RETRY_MS).unwrap();
    assert_eq!(again, first);
    assert_eq!(robot.retransmissions, 1);
    assert!(!gateway_in.accept(again.seq), "a copy is not taken");
    assert_eq!(gateway_in.duplicates, 1);
    robot.heard(&Frame::new(Kind::Ack, again.seq, vec![]));
    assert_eq!(robot.pending(), 0);
    // The next frame has the next number and is taken.
    robot.push(Kind::Status, b"{}".to_vec()).unwrap();
    let next = robot.poll(900).unwrap();
    assert_eq!(next.seq, 1);
    assert!(gateway_in.accept(next.seq));
    // An Ack for another number ends nothing.
    robot.heard(&Frame::new(Kind::Ack, 0, vec![]));
    assert_eq!(robot.pending(), 1);
}

#[test]
fn a_restarted_side_is_heard_from_zero_again() {
    let mut incoming = Incoming::new();
    assert!(incoming.accept(0));
    // The robot restarts and numbers from 0: its Hello comes first.
    incoming.restart();
    assert!(incoming.accept(0));
}

#[test]
fn the_queue_is_bounded() {
    let mut out = Outgoing::new(2, PAYLOAD_MAX as u16);
    out.push(Kind::Message, vec![1]).unwrap();
    out.push(Kind::Message, vec![2]).unwrap();
    assert_eq!(out.push(Kind::Message, vec![3]), Err(QueueFull));
}

/// With `defer_acks` (the gateway's), a reliable frame is taken without its
/// `Ack`, and so are its copies, until the caller acknowledges it; one the
/// caller could not pass on is forgotten, so its next copy is taken again.
#[test]
fn deferred_acks_wait_for_the_caller_and_forgotten_frames_are_taken_again() {
    // Whether `out` holds the Ack of `seq` (beside the Hellos the gateway's
    // own side sends until welcomed).
    let acked = |out: &[u8], seq: u16| {
        let ack = wire(Kind::Ack, seq, b"");
        out.windows(ack.len()).any(|w| w == ack.as_slice())
    };
    let mut gateway = Endpoint::new(4);
    gateway.defer_acks = true;
    let send = wire(Kind::Send, 3, b"\x01Tx");
    let mut out = Vec::new();
    assert_eq!(gateway.feed(&send, 0, &mut out).len(), 1);
    assert!(!acked(&out, 3), "taken, not acknowledged");
    assert!(
        gateway.feed(&send, 200, &mut out).is_empty(),
        "a copy is not taken"
    );
    assert!(!acked(&out, 3), "nor acknowledged before the frame");
    gateway.acknowledge(3, &mut out);
    assert!(acked(&out, 3));
    out.clear();
    gateway.feed(&send, 400, &mut out);
    assert!(acked(&out, 3), "a later copy: its Ack was lost");
    // Not passed on (the broker connection full): forgotten, taken again.
    let next = wire(Kind::Send, 4, b"\x01Ty");
    out.clear();
    assert_eq!(gateway.feed(&next, 600, &mut out).len(), 1);
    gateway.incoming.forget(4);
    assert_eq!(gateway.feed(&next, 800, &mut out).len(), 1, "taken again");
    assert!(!acked(&out, 4));
    // An acknowledgement of another number writes no Ack.
    gateway.acknowledge(9, &mut out);
    assert!(!acked(&out, 9));
}

/// Each side says the longest payload it takes in its `Hello` and its
/// `Welcome`, so the gateway knows a board's smaller bound however the
/// session started (the board's reset, or the gateway's reconnection, which
/// the board answers with `Welcome` without saying `Hello` again); a longer
/// frame is a bad frame on the side that cannot take it, never taken.
#[test]
fn each_side_says_its_payload_bound_and_refuses_longer_frames() {
    let mut board = Endpoint::taking(2, 164);
    let mut gateway = Endpoint::new(4);
    assert_eq!(gateway.peer_payload_max, PAYLOAD_MAX, "until told");
    // The board's reset: its Hello says 164.
    let mut hello = Vec::new();
    board.tick(0, &mut hello);
    assert_eq!(
        frames(&hello),
        vec![Frame::new(Kind::Hello, 0, vec![0, 164])]
    );
    let mut welcome = Vec::new();
    gateway.feed(&hello, 0, &mut welcome);
    assert_eq!(gateway.peer_payload_max, 164);
    // The gateway's Welcome says its own bound, the most either takes.
    let answer = frames(&welcome);
    assert_eq!(answer[0].kind, Kind::Welcome);
    assert_eq!(answer[0].payload_max(), Some(PAYLOAD_MAX));
    board.feed(&welcome, 0, &mut Vec::new());
    assert_eq!(board.peer_payload_max, PAYLOAD_MAX);
    // A gateway that reconnects says Hello; the board's Welcome tells it.
    let mut again = Endpoint::new(4);
    let mut hello = Vec::new();
    again.tick(0, &mut hello);
    let mut welcome = Vec::new();
    board.feed(&hello, 0, &mut welcome);
    again.feed(&welcome, 0, &mut Vec::new());
    assert!(again.outgoing.welcomed());
    assert_eq!(again.peer_payload_max, 164);
    // A frame longer than the board takes is bad there, never taken.
    let long = wire(Kind::Message, 0, &[7; 165]);
    assert!(board.feed(&long, 0, &mut Vec::new()).is_empty());
    assert_eq!(board.bad_frames, vec![FrameError::Payload(Kind::Message)]);
    let fits = wire(Kind::Message, 1, &[7; 164]);
    assert_eq!(board.feed(&fits, 0, &mut Vec::new()).len(), 1);
}

fn frames(wire: &[u8]) -> Vec<Frame> {
    Reader::new()
        .push_all(wire)
        .into_iter()
        .map(Result::unwrap)
        .collect()
}
