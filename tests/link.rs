//! The serial link's two definitions held to each other: `semo_link.c`
//! (driven line by line through `runtime/tests/link_test.c`, built with
//! AddressSanitizer and UBSan) against `semo::link` in Rust. Frames made on
//! one side are read on the other, byte for byte the same; bad bytes (a
//! flipped bit, a frame cut short, a flood without a zero, a kind nobody
//! sends) are counted and never taken; a lost `Ack` brings the frame again,
//! and the copy is acknowledged but not taken twice. Time is stepped by the
//! test (`t MS`), never read from a clock.

mod support;

use semo::link::{Endpoint, Frame, Kind, PAYLOAD_MAX, RETRY_MS, Reader};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::OnceLock;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
        .collect()
}

/// The payload bound of the board the second driver stands for (the
/// scouting `ti`'s).
const BOARD_PAYLOAD_MAX: usize = 164;
/// ... and the longest it sends, its status (the scouting `ti`'s).
const BOARD_SEND_MAX: usize = 200;

/// `link_test.c` with `semo_link.c`, built once per test process.
fn driver() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| build_driver(None))
}

/// The same, built with a board's smaller `SEMO_LINK_PAYLOAD_MAX` and
/// `SEMO_LINK_SEND_MAX`.
fn board_driver() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| build_driver(Some((BOARD_PAYLOAD_MAX, BOARD_SEND_MAX))))
}

/// `payload_max`: a board's bounds, what it takes and what it sends.
fn build_driver(payload_max: Option<(usize, usize)>) -> PathBuf {
    {
        let runtime = support::repo_root().join("compiler/src/codegen/runtime");
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("link");
        std::fs::create_dir_all(&dir).unwrap();
        let exe = dir.join(format!(
            "link_test-{}-{}",
            std::process::id(),
            payload_max.map_or(PAYLOAD_MAX, |(n, _)| n)
        ));
        let out = Command::new("gcc")
            .current_dir(&runtime)
            .args(payload_max.into_iter().flat_map(|(takes, sends)| {
                [
                    format!("-DSEMO_LINK_PAYLOAD_MAX={takes}"),
                    format!("-DSEMO_LINK_SEND_MAX={sends}"),
                ]
            }))
            .args([
                "-std=c11",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-g",
                "-fsanitize=address,undefined",
                "-fno-sanitize-recover=all",
                "tests/link_test.c",
                "semo_link.c",
                "-o",
            ])
            .arg(&exe)
            .output()
            .expect("gcc runs");
        assert!(
            out.status.success(),
            "link_test.c does not build:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        exe
    }
}

/// The C side, one command at a time.
struct CSide {
    child: Child,
    input: ChildStdin,
    output: BufReader<ChildStdout>,
}

/// What one command made the C side do.
#[derive(Debug, Default)]
struct Said {
    wire: Vec<u8>,
    taken: Vec<Frame>,
    lines: Vec<String>,
}

impl CSide {
    fn start() -> CSide {
        CSide::start_taking(driver(), PAYLOAD_MAX)
    }

    /// The C side built with `payload_max` (the driver built so).
    fn start_taking(driver: &Path, payload_max: usize) -> CSide {
        let mut child = Command::new(driver)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("the driver starts");
        let input = child.stdin.take().unwrap();
        let output = BufReader::new(child.stdout.take().unwrap());
        let mut c = CSide {
            child,
            input,
            output,
        };
        let hello = c.read_until_dot();
        assert_eq!(
            hello.lines,
            vec![format!("payload_max {payload_max}")],
            "both sides agree on the longest payload"
        );
        c
    }

    fn read_until_dot(&mut self) -> Said {
        let mut said = Said::default();
        loop {
            let mut line = String::new();
            assert!(
                self.output.read_line(&mut line).unwrap() > 0,
                "the C side ended"
            );
            let line = line.trim_end();
            if line == "." {
                return said;
            }
            if let Some(w) = line.strip_prefix("wire ") {
                said.wire.extend(unhex(w));
            } else if let Some(t) = line.strip_prefix("take ") {
                let mut parts = t.splitn(3, ' ');
                let kind = Kind::from_byte(parts.next().unwrap().as_bytes()[0]).unwrap();
                let seq = parts.next().unwrap().parse().unwrap();
                said.taken
                    .push(Frame::new(kind, seq, unhex(parts.next().unwrap_or(""))));
            } else {
                said.lines.push(line.to_string());
            }
        }
    }

    fn command(&mut self, line: &str) -> Said {
        writeln!(self.input, "{line}").unwrap();
        self.input.flush().unwrap();
        self.read_until_dot()
    }

    fn time(&mut self, ms: u64) -> Said {
        self.command(&format!("t {ms}"))
    }

    fn bytes(&mut self, bytes: &[u8]) -> Said {
        self.command(&format!("b {}", hex(bytes)))
    }

    fn queue(&mut self, kind: Kind, payload: &[u8]) -> Said {
        self.command(&format!("q {} {}", kind.byte() as char, hex(payload)))
    }

    fn stats(&mut self) -> String {
        self.command("s").lines.join("\n")
    }
}

impl Drop for CSide {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn frames(wire: &[u8]) -> Vec<Frame> {
    Reader::new()
        .push_all(wire)
        .into_iter()
        .map(|r| r.expect("the C side writes only frames"))
        .collect()
}

/// The C side (as the robot) and a Rust endpoint (as the gateway), their
/// session started: the C side's Hello answered.
fn connected() -> (CSide, Endpoint) {
    let mut c = CSide::start();
    let mut rust = Endpoint::new(8);
    let hello = c.time(0);
    assert_eq!(
        frames(&hello.wire),
        vec![Frame::new(
            Kind::Hello,
            0,
            (PAYLOAD_MAX as u16).to_be_bytes().to_vec()
        )]
    );
    let mut answer = Vec::new();
    assert!(rust.feed(&hello.wire, 0, &mut answer).is_empty());
    // Welcome, then the Rust side's own Hello.
    let answered = c.bytes(&answer);
    let mut back = Vec::new();
    rust.feed(&answered.wire, 0, &mut back);
    assert!(rust.outgoing.welcomed());
    assert!(c.stats().contains("welcomed=1"));
    (c, rust)
}

#[test]
fn frames_made_in_c_read_in_rust_and_back_byte_for_byte() {
    let mut c = CSide::start();
    // An unreliable frame C writes is the frame Rust writes, byte for byte.
    let datagram = b"SEMO\x02p\x09SlaveTeam\x02ti\x03POS\x05\x033,4".to_vec();
    let made = Frame::addressed(Kind::Publish, 0, "MasterTeam", &datagram).unwrap();
    let said = c.command(&format!("e P {}", hex(&made.payload)));
    assert_eq!(said.wire, made.encode().unwrap());
    // Payloads with zeros and 0xFF runs, up to the longest.
    for payload in [
        vec![0u8; 3],
        (0..=255u8).collect::<Vec<_>>(),
        vec![0xFF; PAYLOAD_MAX],
    ] {
        let frame = Frame::new(Kind::Status, 0, payload.clone());
        let said = c.command(&format!("e T {}", hex(&payload)));
        assert_eq!(
            said.wire,
            frame.encode().unwrap(),
            "{} bytes",
            payload.len()
        );
    }
    // One byte too long: refused by C as by Rust.
    let said = c.command(&format!("e T {}", hex(&vec![1u8; PAYLOAD_MAX + 1])));
    assert_eq!(said.lines, vec!["refused"]);
    assert!(
        Frame::new(Kind::Status, 0, vec![1; PAYLOAD_MAX + 1])
            .encode()
            .is_none()
    );

    // Rust's frames taken by C with the same payloads.
    let (mut c, mut rust) = connected();
    let mut wire = Vec::new();
    for n in 0..3u8 {
        rust.queue(Kind::Message, vec![n, 0, n]).unwrap();
    }
    rust.tick(10, &mut wire);
    let mut taken = Vec::new();
    for _ in 0..3 {
        let said = c.bytes(&std::mem::take(&mut wire));
        taken.extend(said.taken);
        // The Ack lets the next one go.
        let answers = rust.feed(&said.wire, 10, &mut wire);
        assert!(answers.is_empty());
    }
    assert_eq!(
        taken,
        (0..3u8)
            .map(|n| Frame::new(Kind::Message, n as u16, vec![n, 0, n]))
            .collect::<Vec<_>>()
    );
    assert_eq!(rust.outgoing.pending(), 0);
}

#[test]
fn corrupted_truncated_and_flooding_bytes_are_counted_never_taken() {
    let (mut c, _rust) = connected();
    let good = Frame::new(Kind::Message, 0, b"datagram".to_vec())
        .encode()
        .unwrap();
    let mut flipped = good.clone();
    flipped[4] ^= 0x01;
    let truncated: Vec<u8> = good[..good.len() - 4].iter().copied().chain([0]).collect();
    let mut stream = Vec::new();
    stream.extend(&flipped);
    stream.extend(&truncated);
    stream.extend(vec![0xA5; 5000]); // a flood without a zero
    stream.push(0);
    stream.extend(
        Frame::new(Kind::Ack, 0, b"x".to_vec()).encode().unwrap(), // a payload its kind has not
    );
    let said = c.bytes(&stream);
    assert!(said.taken.is_empty(), "{:?}", said.taken);
    assert!(
        said.wire.is_empty(),
        "nothing acknowledged: {:?}",
        said.wire
    );
    assert!(c.stats().contains("bad=4"), "{}", c.stats());
    // And the next good frame is read.
    let said = c.bytes(&good);
    assert_eq!(
        said.taken,
        vec![Frame::new(Kind::Message, 0, b"datagram".to_vec())]
    );
    // Random bytes: the sanitizers would stop the driver on any fault.
    let mut x = 0x2545F491u32;
    let noise: Vec<u8> = (0..20000)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x >> 24) as u8
        })
        .collect();
    c.bytes(&noise);
    assert!(c.stats().starts_with("stats"));
}

#[test]
fn a_lost_ack_brings_the_frame_again_and_the_copy_is_not_taken() {
    // Rust to C: the C side's Ack is lost.
    let (mut c, mut rust) = connected();
    let mut wire = Vec::new();
    rust.queue(Kind::Message, b"once".to_vec()).unwrap();
    rust.tick(1000, &mut wire);
    let said = c.bytes(&std::mem::take(&mut wire));
    assert_eq!(said.taken.len(), 1);
    // ... its Ack never reaches Rust: after RETRY_MS the frame goes again.
    rust.tick(1000 + RETRY_MS - 1, &mut wire);
    assert!(wire.is_empty(), "not before its time");
    rust.tick(1000 + RETRY_MS, &mut wire);
    assert_eq!(frames(&wire)[0].payload, b"once");
    assert_eq!(rust.outgoing.retransmissions, 1);
    let said = c.bytes(&std::mem::take(&mut wire));
    assert!(said.taken.is_empty(), "the copy is not taken");
    assert_eq!(frames(&said.wire), vec![Frame::new(Kind::Ack, 0, vec![])]);
    assert!(c.stats().contains("dup=1"));
    rust.feed(&said.wire, 1300, &mut wire);
    assert_eq!(rust.outgoing.pending(), 0);

    // C to Rust: Rust's Ack is lost.
    c.time(2000);
    let said = c.queue(Kind::Send, b"\x04Teamdatagram");
    let taken = rust.feed(&said.wire, 2000, &mut wire);
    assert_eq!(taken.len(), 1);
    assert_eq!(
        taken[0].destination(),
        Some((&b"Team"[..], &b"datagram"[..]))
    );
    wire.clear(); // the Ack is lost
    assert!(c.time(2000 + RETRY_MS - 1).wire.is_empty());
    let again = c.time(2000 + RETRY_MS);
    assert!(c.stats().contains("retx=1"));
    assert!(rust.feed(&again.wire, 2200, &mut wire).is_empty());
    assert_eq!(rust.incoming.duplicates, 1);
    c.bytes(&wire);
    assert!(c.stats().contains("pending=0"));
}

#[test]
fn a_restarted_robot_is_heard_from_sequence_zero_again() {
    let (mut c, mut rust) = connected();
    let mut wire = Vec::new();
    let said = c.queue(Kind::Send, b"\x01Tfirst");
    assert_eq!(rust.feed(&said.wire, 0, &mut wire).len(), 1);
    c.bytes(&std::mem::take(&mut wire));
    drop(c);
    // A new robot (numbering from 0 again) starts with Hello.
    let mut c = CSide::start();
    let hello = c.time(5000);
    rust.feed(&hello.wire, 5000, &mut wire);
    let said = c.bytes(&std::mem::take(&mut wire));
    let said = c
        .queue(Kind::Send, b"\x01Tsecond")
        .wire
        .into_iter()
        .chain(said.wire)
        .collect::<Vec<_>>();
    let taken = rust.feed(&said, 5000, &mut wire);
    assert_eq!(taken.len(), 1, "sequence 0 of the new session is new");
    assert_eq!(taken[0].destination().unwrap().1, b"second");
}

/// A publish (`P`, as at QoS 0) made while no session stands (before the
/// gateway's `Welcome`, or once the line went away: a gateway restarting)
/// is lost: counted (`lost`, which the robot's trace says at its end),
/// never written; one made in a session goes at once. A send waits for the
/// next session instead.
#[test]
fn a_publish_without_a_session_is_counted_lost_and_a_send_waits() {
    let publish = |value: i64| {
        semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: true,
            team: "SlaveTeam".into(),
            robot: "ti".into(),
            key: "SlaveTeam.LOCATION".into(),
            value: Some(semo::refine::Value::Int(value)),
        })
    };
    let mut c = CSide::start();
    let before = c.command(&format!("d SlaveTeam {}", hex(&publish(1))));
    assert!(
        before.wire.is_empty() && before.lines.is_empty(),
        "{before:?}"
    );
    assert!(c.stats().contains("lost=1"), "{}", c.stats());
    drop(c);

    let (mut c, mut rust) = connected();
    let said = c.command(&format!("d SlaveTeam {}", hex(&publish(2))));
    let mut wire = Vec::new();
    let taken = rust.feed(&said.wire, 0, &mut wire);
    assert_eq!(taken.len(), 1);
    assert_eq!(taken[0].kind, Kind::Publish);
    assert_eq!(taken[0].destination().unwrap().1, publish(2));
    assert!(c.stats().contains("lost=0"), "{}", c.stats());

    c.command("r");
    let gone = c.command(&format!("d SlaveTeam {}", hex(&publish(3))));
    assert!(gone.wire.is_empty(), "nothing written without a session");
    assert!(c.stats().contains("lost=1"), "{}", c.stats());
    let send = c.queue(Kind::Send, b"\x01Tlater");
    assert!(
        frames(&send.wire).iter().all(|f| f.kind == Kind::Hello),
        "a send waits for the next session: {:?}",
        frames(&send.wire)
    );
    assert!(c.stats().contains("pending=1"), "{}", c.stats());
}

/// A board sends frames up to its `SEMO_LINK_SEND_MAX` (its status), longer
/// than the ones it takes: the gateway's side reads them; one byte more is
/// refused on the board.
#[test]
fn a_board_sends_frames_longer_than_it_takes() {
    let mut c = CSide::start_taking(board_driver(), BOARD_PAYLOAD_MAX);
    let mut gateway = Endpoint::new(8);
    let mut answer = Vec::new();
    gateway.feed(&c.time(0).wire, 0, &mut answer);
    let mut back = Vec::new();
    gateway.feed(&c.bytes(&answer).wire, 0, &mut back);
    let status = vec![b's'; BOARD_SEND_MAX];
    let said = c.queue(Kind::Status, &status);
    assert!(said.lines.is_empty(), "{said:?}");
    let taken = gateway.feed(&said.wire, 0, &mut back);
    assert_eq!(taken, vec![Frame::new(Kind::Status, 0, status)]);
    let said = c.queue(Kind::Status, &vec![b's'; BOARD_SEND_MAX + 1]);
    assert_eq!(said.lines, vec!["refused"]);
}

/// A frame queued and not yet on the line may be written again in place (a
/// newer status takes the place of one that has not left): what goes is
/// the new payload, under its number; the frame on the line, or a last
/// frame of another kind, is never rewritten.
#[test]
fn a_waiting_frame_is_written_again_in_place_until_it_leaves() {
    let (mut c, mut rust) = connected();
    // The first goes on the line at once: it cannot be rewritten.
    let said = c.queue(Kind::Status, b"first");
    assert_eq!(frames(&said.wire)[0].payload, b"first");
    assert_eq!(c.command("w T 00").lines, vec!["none"]);
    // The second waits behind it: rewritten, shorter and longer.
    assert!(c.queue(Kind::Status, b"second").wire.is_empty());
    assert_eq!(c.command("w S 00").lines, vec!["none"], "another kind");
    assert!(c.command(&format!("w T {}", hex(b"2nd"))).lines.is_empty());
    assert!(
        c.command(&format!("w T {}", hex(b"the second, newer")))
            .lines
            .is_empty()
    );
    // The first's Ack lets it go, as last written.
    let mut wire = Vec::new();
    let taken = rust.feed(&said.wire, 0, &mut wire);
    assert_eq!(taken, vec![Frame::new(Kind::Status, 0, b"first".to_vec())]);
    let said = c.bytes(&wire);
    let taken = rust.feed(&said.wire, 0, &mut Vec::new());
    assert_eq!(
        taken,
        vec![Frame::new(Kind::Status, 1, b"the second, newer".to_vec())]
    );
    assert_eq!(c.command("w T 00").lines, vec!["none"], "on the line now");
}

/// A board built with a smaller `SEMO_LINK_PAYLOAD_MAX` says it in its
/// Hello and in its Welcome, so the gateway's side learns it however the
/// session starts; a frame longer than that is a bad frame on the board,
/// counted, never taken nor acknowledged; a refusal's reason byte is read.
#[test]
fn a_board_says_its_payload_bound_and_longer_frames_are_bad_there() {
    let mut c = CSide::start_taking(board_driver(), BOARD_PAYLOAD_MAX);
    let mut gateway = Endpoint::new(8);
    let hello = c.time(0);
    assert_eq!(
        frames(&hello.wire),
        vec![Frame::new(Kind::Hello, 0, vec![0, BOARD_PAYLOAD_MAX as u8])]
    );
    let mut answer = Vec::new();
    gateway.feed(&hello.wire, 0, &mut answer);
    assert_eq!(gateway.peer_payload_max, BOARD_PAYLOAD_MAX);
    // The board's Welcome (to the gateway's Hello) says it too.
    let answered = c.bytes(&answer);
    let welcome = frames(&answered.wire);
    assert_eq!(welcome[0].kind, Kind::Welcome);
    assert_eq!(welcome[0].payload_max(), Some(BOARD_PAYLOAD_MAX));
    let mut reconnected = Endpoint::new(8);
    reconnected.feed(&answered.wire, 0, &mut Vec::new());
    assert!(reconnected.outgoing.welcomed());
    assert_eq!(reconnected.peer_payload_max, BOARD_PAYLOAD_MAX);
    assert!(
        c.stats()
            .contains(&format!("peer_payload_max={PAYLOAD_MAX}"))
    );

    let too_long = Frame::new(Kind::Message, 0, vec![7; BOARD_PAYLOAD_MAX + 1]);
    let said = c.bytes(&too_long.encode().unwrap());
    assert!(said.taken.is_empty() && said.wire.is_empty(), "{said:?}");
    assert!(c.stats().contains("bad=1"), "{}", c.stats());
    let fits = Frame::new(Kind::Message, 1, vec![7; BOARD_PAYLOAD_MAX]);
    assert_eq!(c.bytes(&fits.encode().unwrap()).taken, vec![fits]);
    let refused = Frame::new(Kind::Refused, 2, b"L".to_vec());
    assert_eq!(c.bytes(&refused.encode().unwrap()).taken, vec![refused]);
}
