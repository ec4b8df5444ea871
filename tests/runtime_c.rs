//! The C runtime that generated robot programs link with
//! (`compiler/src/codegen/runtime/`): its test program
//! (`tests/runtime_test.c`, tables written the way the generator writes them)
//! built with gcc and clang at `-std=c11 -Wall -Wextra -Werror -pedantic`,
//! and under AddressSanitizer+UBSan and ThreadSanitizer; every program is run
//! and its JSON-lines trace read back. Any compiler message or sanitizer
//! report fails the test.
//!
//! ThreadSanitizer needs a memory layout that some kernels' address
//! randomisation breaks ("unexpected memory mapping"); when the first TSan
//! run says so, every TSan run goes through `setarch <arch> -R` (no ASLR for
//! that process only).

mod support;

use proptest::prelude::*;
use serde_json::Value;
use std::collections::HashMap;
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

// ------------------------------------------------------------------ builds

/// How the runtime and its test program are built.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Flavor {
    /// The generator's flags with a given compiler; `sim` adds `-DSEMO_SIM`.
    Plain {
        cc: &'static str,
        sim: bool,
    },
    AsanUbsan,
    Tsan,
}

impl Flavor {
    fn name(self) -> String {
        match self {
            Flavor::Plain { cc, sim } => format!("{cc}{}", if sim { "-sim" } else { "" }),
            Flavor::AsanUbsan => "asan-ubsan".into(),
            Flavor::Tsan => "tsan".into(),
        }
    }

    fn sim(self) -> bool {
        !matches!(self, Flavor::Plain { sim: false, .. })
    }

    fn flags(self) -> Vec<&'static str> {
        let mut flags = vec![
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-pthread",
        ];
        match self {
            Flavor::Plain { .. } => flags.push("-O2"),
            Flavor::AsanUbsan => flags.extend([
                "-g",
                "-O1",
                "-fno-omit-frame-pointer",
                "-fsanitize=address,undefined",
                "-fno-sanitize-recover=all",
            ]),
            Flavor::Tsan => flags.extend(["-g", "-O1", "-fsanitize=thread"]),
        }
        if self.sim() {
            flags.push("-DSEMO_SIM");
        }
        flags
    }
}

fn has_clang() -> bool {
    Command::new("clang")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Every flavor this machine can build: gcc and clang (when installed, else
/// a note), each with and without simulation, and the two sanitizer builds.
fn flavors() -> Vec<Flavor> {
    let mut all = vec![
        Flavor::Plain {
            cc: "gcc",
            sim: false,
        },
        Flavor::Plain {
            cc: "gcc",
            sim: true,
        },
    ];
    if has_clang() {
        all.push(Flavor::Plain {
            cc: "clang",
            sim: false,
        });
        all.push(Flavor::Plain {
            cc: "clang",
            sim: true,
        });
    } else {
        eprintln!("note: clang is not installed; the runtime is tested with gcc only");
    }
    all.extend([Flavor::AsanUbsan, Flavor::Tsan]);
    all
}

fn runtime_dir() -> PathBuf {
    support::repo_root().join("compiler/src/codegen/runtime")
}

fn work_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("runtime-c");
    std::fs::create_dir_all(&dir).expect("target dir is writable");
    dir
}

/// A built test program, and whether it must run without ASLR.
#[derive(Clone)]
struct Program {
    flavor: Flavor,
    exe: PathBuf,
    no_aslr: bool,
}

/// Builds once per flavor for the whole test process, with a simulated
/// world that has nothing in it (`tests/runtime_test_world.c`).
fn program(flavor: Flavor) -> Program {
    built(flavor, false)
}

/// As [`program`], with robot irobot's world compiled in (what `semo build
/// --scenario` writes: `tests/runtime_test_world.c` with
/// `-DRUNTIME_TEST_WORLD`), for mode `sim`.
fn program_with_world(flavor: Flavor) -> Program {
    built(flavor, true)
}

fn built(flavor: Flavor, world: bool) -> Program {
    static BUILT: Mutex<Option<HashMap<(String, bool), Program>>> = Mutex::new(None);
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    let built = built.get_or_insert_with(HashMap::new);
    if let Some(p) = built.get(&(flavor.name(), world)) {
        return p.clone();
    }
    let p = compile(flavor, world);
    built.insert((flavor.name(), world), p.clone());
    p
}

fn compile(flavor: Flavor, world: bool) -> Program {
    let dir = runtime_dir();
    let exe = work_dir().join(format!(
        "runtime_test-{}{}",
        flavor.name(),
        if world { "-world" } else { "" }
    ));
    // Built beside and renamed, so that a concurrent test run never sees half a file.
    let partial = exe.with_extension(format!("partial-{}", std::process::id()));
    let cc = match flavor {
        Flavor::Plain { cc, .. } => cc,
        _ => "gcc",
    };
    let out = Command::new(cc)
        .args(flavor.flags())
        .args(world.then_some("-DRUNTIME_TEST_WORLD"))
        .args([
            "tests/runtime_test.c",
            "tests/runtime_test_world.c",
            "semo_core.c",
            "semo_runtime.c",
            "semo_udp.c",
            "semo_link.c",
            "semo_link_transport.c",
            "semo_sim.c",
            "semo_lockstep.c",
            "-o",
        ])
        .arg(&partial)
        .current_dir(&dir)
        .output()
        .unwrap_or_else(|e| panic!("{cc} runs: {e}"));
    let messages = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && messages.trim().is_empty(),
        "{} build of the runtime is not clean:\n{messages}",
        flavor.name()
    );
    std::fs::rename(&partial, &exe).expect("rename the built program");
    let mut program = Program {
        flavor,
        exe,
        no_aslr: false,
    };
    if flavor == Flavor::Tsan {
        let probe = program.run(&["values"], &[]);
        if probe.stderr.contains("unexpected memory mapping") {
            program.no_aslr = true;
        }
    }
    program
}

// ---------------------------------------------------------------- running

struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

const SANITIZER_ENV: [(&str, &str); 3] = [
    (
        "ASAN_OPTIONS",
        "detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=1",
    ),
    ("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1"),
    ("TSAN_OPTIONS", "halt_on_error=1:second_deadlock_stack=1"),
];

/// No run may take this long; a hang fails instead of blocking the suite.
const RUN_LIMIT: Duration = Duration::from_secs(60);

impl Program {
    fn command(&self, args: &[&str], env: &[(&str, &str)]) -> Command {
        let mut cmd = if self.no_aslr {
            let mut c = Command::new("setarch");
            c.arg(std::env::consts::ARCH).arg("-R").arg(&self.exe);
            c
        } else {
            Command::new(&self.exe)
        };
        cmd.args(args)
            .envs(SANITIZER_ENV)
            .env_remove("SEMO_PORT_BASE")
            .envs(env.iter().copied())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        cmd
    }

    fn spawn(&self, args: &[&str], env: &[(&str, &str)]) -> (Child, Instant) {
        let child = self
            .command(args, env)
            .spawn()
            .unwrap_or_else(|e| panic!("{} starts: {e}", self.exe.display()));
        (child, Instant::now())
    }

    fn run(&self, args: &[&str], env: &[(&str, &str)]) -> Run {
        let child = self
            .command(args, env)
            .spawn()
            .unwrap_or_else(|e| panic!("{} starts: {e}", self.exe.display()));
        finish(
            child,
            Instant::now(),
            &format!("{} {args:?}", self.flavor.name()),
        )
    }

    /// Runs a mode that must succeed: exit 0, nothing on stderr.
    fn run_ok(&self, args: &[&str]) -> Run {
        let run = self.run(args, &[]);
        self.assert_clean(&run, args);
        run
    }

    fn assert_clean(&self, run: &Run, args: &[&str]) {
        assert!(
            run.code == 0 && run.stderr.trim().is_empty(),
            "{} {args:?} exited {} with:\n{}",
            self.flavor.name(),
            run.code,
            run.stderr
        );
    }
}

/// Waits (polling, bounded by RUN_LIMIT) and collects the output.
fn finish(mut child: Child, started: Instant, what: &str) -> Run {
    loop {
        match child.try_wait().expect("wait for the program") {
            Some(_) => break,
            None if started.elapsed() > RUN_LIMIT => {
                let _ = child.kill();
                panic!("{what} did not end within {RUN_LIMIT:?}");
            }
            None => std::thread::sleep(Duration::from_millis(10)),
        }
    }
    let out = child.wait_with_output().expect("program output");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn trace_path(test: &str, flavor: Flavor) -> PathBuf {
    work_dir().join(format!(
        "{test}-{}-{}.jsonl",
        flavor.name(),
        std::process::id()
    ))
}

/// Every line one JSON object with an integer, never decreasing "t" and
/// this robot's name; the first event is "start", the last "stop".
fn read_trace(path: &Path, robot: &str) -> Vec<Value> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let _ = std::fs::remove_file(path);
    let events: Vec<Value> = text
        .lines()
        .map(|line| {
            serde_json::from_str(line).unwrap_or_else(|e| panic!("trace line {line:?}: {e}"))
        })
        .collect();
    let mut last = 0;
    for e in &events {
        let t = e["t"]
            .as_u64()
            .unwrap_or_else(|| panic!("integer t in {e}"));
        assert!(t >= last, "time goes back at {e}");
        last = t;
        assert_eq!(e["robot"], robot, "{e}");
    }
    assert_eq!(
        events.first().map(|e| &e["event"]),
        Some(&Value::from("start")),
        "{text}"
    );
    assert_eq!(
        events.last().map(|e| &e["event"]),
        Some(&Value::from("stop")),
        "{text}"
    );
    events
}

fn events<'a>(trace: &'a [Value], event: &str) -> Vec<&'a Value> {
    trace.iter().filter(|e| e["event"] == event).collect()
}

// ------------------------------------------------------------------ tests

#[test]
fn values_are_typed_and_compare_as_the_checker_typed_them() {
    for flavor in flavors() {
        program(flavor).run_ok(&["values"]);
    }
}

/// A real worth printing, and whether the format promises that it reads
/// back as itself: any bit pattern (every exponent alike, so huge, tiny,
/// subnormal, zero, infinite and NaN all come; promised from 2^33 to 1e15,
/// where six decimals are finer than the double's own steps), the nearest
/// double to a decimal with six decimals below 1e15, or to fifteen
/// significant digits and an exponent (both promised).
fn real_bits() -> impl Strategy<Value = (u64, bool)> {
    prop_oneof![
        any::<u64>().prop_map(|bits| {
            let magnitude = f64::from_bits(bits).abs();
            (bits, (8_589_934_592.0..1e15).contains(&magnitude))
        }),
        (any::<bool>(), 0u64..1_000_000_000_000_000, 0u32..1_000_000).prop_map(
            |(negative, whole, micros)| {
                let sign = if negative { "-" } else { "" };
                let x: f64 = format!("{sign}{whole}.{micros:06}").parse().unwrap();
                (x.to_bits(), true)
            }
        ),
        (100_000_000_000_000u64..1_000_000_000_000_000, 1u32..294).prop_map(
            |(digits, exponent)| {
                let x: f64 = format!("{digits}e{exponent}").parse().unwrap();
                (x.to_bits(), true)
            }
        ),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The runtime prints every double as the simulator does, byte for byte
    /// (compiled with gcc, and under UBSan: an overflow in the arithmetic
    /// fails there even where the digits happen to agree), as a JSON number
    /// (`null` for what JSON has no number for), reading back as the same
    /// double wherever the format promises it.
    #[test]
    fn reals_print_the_same_in_c_and_in_the_simulator(batch in proptest::collection::vec(real_bits(), 500)) {
        let args: Vec<String> = std::iter::once("reals".to_string())
            .chain(batch.iter().map(|(bits, _)| format!("{bits:016x}")))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        for flavor in [Flavor::Plain { cc: "gcc", sim: false }, Flavor::AsanUbsan] {
            let run = program(flavor).run_ok(&args);
            let lines: Vec<&str> = run.stdout.lines().collect();
            prop_assert_eq!(lines.len(), batch.len());
            for ((bits, promised), c) in batch.iter().zip(lines) {
                let x = f64::from_bits(*bits);
                let mut simulator = String::new();
                semo::sim::trace::write_value(&mut simulator, Some(&semo::refine::Value::Real(x)));
                prop_assert_eq!(c, simulator.as_str(), "{:e} ({:016x}) in {}", x, bits, flavor.name());
                let json: Value = serde_json::from_str(c)
                    .unwrap_or_else(|e| panic!("{c} is not JSON: {e}"));
                if !x.is_finite() {
                    prop_assert!(json.is_null());
                    continue;
                }
                let back = json.as_f64().unwrap_or_else(|| panic!("{c} is not a number"));
                prop_assert_eq!(back.is_sign_negative(), x.is_sign_negative(), "{}", c);
                if *promised {
                    prop_assert_eq!(back.to_bits(), x.to_bits(), "{} does not read back as {:e}", c, x);
                }
            }
        }
    }
}

#[test]
fn tasks_channels_control_timers_and_trace_escaping() {
    for flavor in flavors() {
        let p = program(flavor);
        let trace = trace_path("tasks", flavor);
        p.run_ok(&["tasks", "--trace", trace.to_str().unwrap()]);
        let trace = read_trace(&trace, "r1");
        let start = &trace[0];
        assert_eq!(start["team"], "TestTeam");
        assert_eq!(start["type"], "TestBot");
        assert_eq!(start["mission"], "test.mission");
        let notes = events(&trace, "note");
        assert_eq!(
            notes[0]["text"],
            "quote\" backslash\\ newline\n tab\t ctl\u{1} é bad\u{fffd}\u{fffd} end"
        );
        assert_eq!(notes[1]["text"], Value::Null);
        // semo_group_set traces a change only.
        let groups: Vec<(&Value, &Value)> = events(&trace, "group")
            .iter()
            .map(|e| (&e["rank"], &e["size"]))
            .collect();
        assert_eq!(
            groups,
            [(&"2".into(), &"3".into()), (&"1".into(), &"2".into())]
        );
        let sends = events(&trace, "send");
        assert_eq!(sends[0]["to"], "USER");
        assert_eq!(sends[0]["key"], "Team.STATUS");
        assert_eq!(sends[0]["value"], "ok");
        // A word is traced as its text, an integer as a JSON number.
        assert_eq!(sends[1]["key"], "Team.TURN");
        assert_eq!(sends[1]["value"], "RIGHT");
        assert_eq!(sends[2]["value"], -3);
        let dropped = events(&trace, "dropped");
        let spill = dropped
            .iter()
            .find(|e| e["channel"] == "Control.SPILL->Sink.IN")
            .unwrap_or_else(|| panic!("{dropped:?}"));
        assert_eq!(spill["count"], "1");
    }
}

/// A time-driven task that calls `semo_next_firing(INT64_MAX)` sleeps
/// through its periods and fires again only when a sample arrives (the
/// program checks its own counts: 2 firings, 1 sample, over 300 ms of
/// 10 ms periods).
#[test]
fn a_task_waiting_for_events_does_not_poll() {
    for flavor in flavors() {
        program(flavor).run_ok(&["wake"]);
    }
}

/// A port base with the three ports of the test mission's places free: the
/// two robots listen on base and base + 2 (their places 0 and 2; place 1 is
/// a robot of the mission neither knows).
fn free_port_pair() -> u16 {
    for _ in 0..100 {
        let a = UdpSocket::bind("127.0.0.1:0").expect("bind a UDP port");
        let base = a.local_addr().unwrap().port();
        let free = |port: u16| UdpSocket::bind(("127.0.0.1", port)).is_ok();
        if base < 65534 && free(base + 1) && free(base + 2) {
            return base;
        }
    }
    panic!("no three adjacent free UDP ports");
}

/// The port of robot `b` (place 2 of the test mission) over `base`.
fn port_of_b(base: &str) -> u16 {
    base.parse::<u16>().unwrap() + 2
}

fn wait_for_start(trace: &Path, child: &mut Child) {
    let started = Instant::now();
    while !std::fs::read_to_string(trace).is_ok_and(|t| t.contains("\"start\"")) {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the program ended before it started: {status}");
        }
        assert!(started.elapsed() < RUN_LIMIT, "the program never started");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Datagrams the receiver must reject (each traced as "reject"), and one
/// well-formed message in the documented wire format.
fn send_datagrams_to(port: u16) {
    let junk: [&[u8]; 9] = [
        b"hello",
        b"SEMO\x02s\x05Alpha",                   // cut short
        &[b'x'; 2000],                           // larger than any message
        b"SEMO\x02z\x01A\x01a\x01k\x05\x01v",    // unknown kind
        b"SEMO\x02s\x01\x00\x01a\x01k\x05\x01v", // NUL inside a field
        b"SEMO\x02s\x01A\x01a\x01k\x05\x01vX",   // bytes after the value
        b"SEMO\x02s\x01A\x01a\x01k\x01\x00\x07", // an integer cut short
        b"SEMO\x01s\x01A\x01a\x01k\x01v",        // the old text format
        b"SEMO\x02s\x28AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA\x01a\x01k\x05\x01v", // team too long
    ];
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    for datagram in junk {
        socket.send_to(datagram, ("127.0.0.1", port)).unwrap();
    }
    socket
        .send_to(
            &semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
                publish: false,
                team: "Alpha".into(),
                robot: "a".into(),
                key: "Alpha.NOTE".into(),
                value: Some(semo::refine::Value::text("hi")),
            }),
            ("127.0.0.1", port),
        )
        .unwrap();
}

#[test]
fn two_robots_exchange_messages_over_udp_and_reject_malformed_datagrams() {
    for flavor in flavors() {
        let p = program(flavor);
        let base = free_port_pair().to_string();
        let (trace_a, trace_b) = (trace_path("udp-a", flavor), trace_path("udp-b", flavor));
        let args = |mode: &'static str, trace: &Path| {
            vec![
                mode.to_string(),
                "--trace".into(),
                trace.display().to_string(),
                format!("--port-base={base}"),
                "--duration".into(),
                "20000".into(),
            ]
        };
        let b_args = args("udp-b", &trace_b);
        let (mut b, b_started) =
            p.spawn(&b_args.iter().map(String::as_str).collect::<Vec<_>>(), &[]);
        wait_for_start(&trace_b, &mut b);
        send_datagrams_to(port_of_b(&base));
        let a_args = args("udp-a", &trace_a);
        let a = p.run(&a_args.iter().map(String::as_str).collect::<Vec<_>>(), &[]);
        let b = finish(b, b_started, "udp-b");
        p.assert_clean(&a, &["udp-a"]);
        p.assert_clean(&b, &["udp-b"]);

        let a_trace = read_trace(&trace_a, "a");
        let b_trace = read_trace(&trace_b, "b");
        assert!(
            events(&a_trace, "send")
                .iter()
                .any(|e| e["to"] == "Beta" && e["key"] == "Alpha.PING")
        );
        let pong = events(&a_trace, "receive");
        let pong = pong
            .iter()
            .find(|e| e["key"] == "Beta.PONG")
            .expect("PONG received");
        assert_eq!(pong["from"], "Beta");
        assert_eq!(pong["from_robot"], "b");
        assert_eq!(pong["value"], "pong \"1\"");
        let received = events(&b_trace, "receive");
        let note = received
            .iter()
            .find(|e| e["key"] == "Alpha.NOTE")
            .expect("well-formed datagram");
        assert_eq!(note["value"], "hi");
        assert!(received.iter().any(|e| e["key"] == "Alpha.BYE"));
        assert_eq!(events(&b_trace, "reject").len(), 9, "{b_trace:#?}");
    }
}

/// A message from robot `a` of team Alpha with `key` and a text value.
fn note(key: &str, value: &str) -> Vec<u8> {
    semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
        publish: false,
        team: "Alpha".into(),
        robot: "a".into(),
        key: key.into(),
        value: Some(semo::refine::Value::text(value)),
    })
}

/// With a run key (`$SEMO_UDP_KEY`), robots that share it talk as before,
/// and a datagram from a local process that does not know it (unsigned, or
/// signed with another key, or altered) is refused and traced; one signed
/// with the key (by `semo::deploy::datagram::sign`, which holds the C side
/// to the Rust one: a short datagram and one longer than a SHA-256 block) is
/// taken. A replay is refused and traced: the same signed datagram again,
/// one whose counter is older than the last from its sender, and a capture
/// of robot `a` older than 5 s (as replayed to a robot restarted since).
#[test]
fn with_a_run_key_a_datagram_without_its_signature_is_refused() {
    const KEY: &str = "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f";
    let key: Vec<u8> = (0..32).collect();
    // Text values are shorter than SEMO_TEXT_MAX (64): with its fields, a
    // datagram of 86 bytes, past a SHA-256 block.
    let long = "x".repeat(60);
    for flavor in flavors() {
        let p = program(flavor);
        let base = free_port_pair().to_string();
        let (trace_a, trace_b) = (
            trace_path("udp-key-a", flavor),
            trace_path("udp-key-b", flavor),
        );
        let args = |mode: &'static str, trace: &Path| {
            vec![
                mode.to_string(),
                "--trace".into(),
                trace.display().to_string(),
                format!("--port-base={base}"),
                "--duration".into(),
                "20000".into(),
            ]
        };
        let env = [("SEMO_UDP_KEY", KEY)];
        let b_args = args("udp-b", &trace_b);
        let (mut b, b_started) =
            p.spawn(&b_args.iter().map(String::as_str).collect::<Vec<_>>(), &env);
        wait_for_start(&trace_b, &mut b);
        let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
        let port = port_of_b(&base);
        use semo::deploy::datagram::{OUTSIDER, counter_now, sign};
        let at = counter_now();
        let mut altered = sign(&key, OUTSIDER, at, &note("Alpha.NOTE", "forged"));
        altered[12] ^= 1;
        let wrong_key = [7u8; 32];
        let hi = sign(&key, OUTSIDER, at + 1, &note("Alpha.NOTE", "hi"));
        let stale = at.checked_sub(6_000_000_000).expect("up for 6 s");
        for datagram in [
            note("Alpha.NOTE", "unsigned"),
            sign(&wrong_key, OUTSIDER, at, &note("Alpha.NOTE", "other key")),
            altered,
            hi.clone(),
            sign(&key, OUTSIDER, at + 2, &note("Alpha.NOTE", &long)),
            hi,
            sign(&key, OUTSIDER, at + 1, &note("Alpha.NOTE", "older")),
            sign(&key, 0, stale, &note("Alpha.NOTE", "captured")),
        ] {
            socket.send_to(&datagram, ("127.0.0.1", port)).unwrap();
        }
        let a_args = args("udp-a", &trace_a);
        let a = p.run(&a_args.iter().map(String::as_str).collect::<Vec<_>>(), &env);
        let b = finish(b, b_started, "udp-b");
        p.assert_clean(&a, &["udp-a"]);
        p.assert_clean(&b, &["udp-b"]);

        let a_trace = read_trace(&trace_a, "a");
        let b_trace = read_trace(&trace_b, "b");
        assert!(
            events(&a_trace, "receive")
                .iter()
                .any(|e| e["key"] == "Beta.PONG"),
            "robots with the key talk"
        );
        let notes: Vec<&Value> = events(&b_trace, "receive")
            .into_iter()
            .filter(|e| e["key"] == "Alpha.NOTE")
            .collect();
        assert_eq!(notes.len(), 2, "{notes:#?}");
        assert_eq!(notes[0]["value"], "hi");
        assert_eq!(notes[1]["value"], long.as_str());
        let reasons: Vec<&Value> = events(&b_trace, "reject")
            .into_iter()
            .map(|e| &e["reason"])
            .collect();
        let unsigned = "not signed with the run's key";
        let replayed = "replayed: not newer than the last from its sender";
        assert_eq!(
            reasons,
            [unsigned, unsigned, unsigned, replayed, replayed, replayed],
            "{b_trace:#?}"
        );
    }
    // A key that is no key stops the program before it starts.
    let p = program(flavors()[0]);
    let run = p.run(&["udp-a"], &[("SEMO_UDP_KEY", "abc")]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("SEMO_UDP_KEY must be"),
        "{}",
        run.stderr
    );
}

#[test]
fn simulation_feeds_scenario_sensors_and_operator_commands() {
    for flavor in flavors().into_iter().filter(|f| f.sim()) {
        let p = program_with_world(flavor);
        let trace = trace_path("sim", flavor);
        p.run_ok(&["sim", "--trace", trace.to_str().unwrap()]);
        let trace = read_trace(&trace, "irobot");
        // The scenario's speed is the one the robot ran at.
        assert_eq!(trace[0]["time_scale"], "0.05", "{}", trace[0]);
        assert_eq!(trace[0]["team"], "RemoteTeam");
        assert_eq!(trace[0]["type"], "iRobot");
        let commands: Vec<_> = events(&trace, "receive")
            .iter()
            .map(|e| {
                assert_eq!(
                    (&e["from"], &e["from_robot"]),
                    (&"USER".into(), &"USER".into())
                );
                assert_eq!(e["key"], "USER.RC_CMD");
                (
                    e["t"].as_u64().unwrap(),
                    e["value"].as_str().unwrap().to_string(),
                )
            })
            .collect();
        let values: Vec<_> = commands.iter().map(|(_, v)| v.as_str()).collect();
        assert_eq!(
            values,
            [
                "NONE",
                "NONE",
                "AUTO_MODE",
                "NONE",
                "NONE",
                "NONE",
                "NONE",
                "FINISH"
            ]
        );
        // Each command arrives at (not before) its scenario time.
        for ((t, _), due) in commands
            .iter()
            .zip([0, 400, 500, 800, 1200, 1600, 2000, 3000])
        {
            assert!(*t >= due, "{commands:?}");
        }
        let actuate = events(&trace, "actuate");
        assert_eq!(
            (&actuate[0]["task"], &actuate[0]["value"]),
            (&"Move".into(), &"5,5".into())
        );
        assert!(trace.last().unwrap()["t"].as_u64().unwrap() >= 3000);
    }
}

/// `--start-at`: an instant ahead holds the start until then (no line of
/// the trace before mission time 0); an instant passed starts the clock
/// there, as for a robot restarted in a running mission.
#[test]
fn the_start_barrier_holds_the_start_and_a_passed_start_continues_mission_time() {
    let p = program(Flavor::Plain {
        cc: "gcc",
        sim: false,
    });
    let unix_ms = || {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_millis() as i64
    };
    let base = free_port_pair().to_string();
    let run = |start_at: i64, duration: &str, name: &str| {
        let trace = trace_path(
            name,
            Flavor::Plain {
                cc: "gcc",
                sim: false,
            },
        );
        p.run_ok(&[
            "minimal",
            "--start-at",
            &start_at.to_string(),
            "--duration",
            duration,
            "--port-base",
            &base,
            "--trace",
            trace.to_str().unwrap(),
        ]);
        read_trace(&trace, "solo")
    };
    let ahead = run(unix_ms() + 300, "50", "start-ahead");
    assert_eq!(ahead[0]["event"], "start");
    assert!(
        ahead.iter().all(|e| e["t"].as_i64().unwrap() >= 0),
        "{ahead:?}"
    );
    let passed = run(unix_ms() - 10_000, "10050", "start-passed");
    assert_eq!(passed[0]["event"], "start");
    assert!(passed[0]["t"].as_i64().unwrap() >= 10_000, "{passed:?}");
    assert_eq!(passed.last().unwrap()["event"], "stop");
}

#[test]
fn duration_is_in_mission_time_and_the_command_line_beats_the_scenario() {
    for flavor in flavors() {
        let p = program(flavor);
        let trace = trace_path("duration", flavor);
        let base = free_port_pair().to_string();
        // The wall time is not checked from here (the program may have run a
        // while before `spawn` returned); its own clock is in the trace.
        p.run_ok(&[
            "minimal",
            "--duration",
            "100",
            "--port-base",
            &base,
            "--trace",
            trace.to_str().unwrap(),
        ]);
        let trace = read_trace(&trace, "solo");
        assert!(trace.last().unwrap()["t"].as_u64().unwrap() >= 100);
        if flavor.sim() {
            // The compiled-in scenario's speed and duration (0.05, 20000 ms),
            // each beaten by the command line's: the trace says which speed
            // the robot ran at and how far its mission clock went (no wall
            // clock is read here).
            let p = program_with_world(flavor);
            let ran = |name: &str, extra: &[&str]| {
                let trace = trace_path(name, flavor);
                let mut args = vec![
                    "minimal",
                    "--port-base",
                    &base,
                    "--trace",
                    trace.to_str().unwrap(),
                ];
                args.extend_from_slice(extra);
                p.run_ok(&args);
                read_trace(&trace, "solo")
            };
            let scenario_s_speed = ran("scenario-speed", &["--duration", "5000"]);
            assert_eq!(
                scenario_s_speed[0]["time_scale"], "0.05",
                "{}",
                scenario_s_speed[0]
            );
            let stop = |trace: &[Value]| trace.last().unwrap()["t"].as_u64().unwrap();
            assert!((5000..20000).contains(&stop(&scenario_s_speed)));
            let scenario_s_duration = ran("scenario-duration", &["--time-scale", "0.005"]);
            assert_eq!(
                scenario_s_duration[0]["time_scale"], "0.005",
                "{}",
                scenario_s_duration[0]
            );
            assert!(stop(&scenario_s_duration) >= 20000);
        }
    }
}

#[test]
fn sigterm_stops_the_program_cleanly() {
    for flavor in flavors() {
        let p = program(flavor);
        let trace = trace_path("sigterm", flavor);
        let base = free_port_pair().to_string();
        let (mut child, started) = p.spawn(
            &[
                "minimal",
                "--port-base",
                &base,
                "--trace",
                trace.to_str().unwrap(),
            ],
            &[],
        );
        wait_for_start(&trace, &mut child);
        let killed = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(killed.success());
        let run = finish(child, started, "minimal");
        p.assert_clean(&run, &["minimal"]);
        let trace = read_trace(&trace, "solo");
        assert_eq!(events(&trace, "signal")[0]["signal"], "SIGTERM");
    }
}

#[test]
fn bad_command_lines_are_refused_with_usage() {
    let p = program(Flavor::Plain {
        cc: "gcc",
        sim: false,
    });
    let refused = |args: &[&str], env: &[(&str, &str)], says: &str| {
        let run = p.run(args, env);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(run.stderr.contains(says), "{args:?}: {}", run.stderr);
    };
    refused(&["minimal", "--bogus"], &[], "unknown option \"--bogus\"");
    refused(
        &["minimal", "--bogus"],
        &[],
        "usage: minimal [--trace FILE]",
    );
    refused(&["minimal", "--duration"], &[], "--duration needs a value");
    refused(
        &["minimal", "--start-at", "soon"],
        &[],
        "--start-at must be a time in ms since 1970",
    );
    refused(
        &["minimal"],
        &[("SEMO_START_AT", "-1")],
        "SEMO_START_AT must be a time in ms since 1970",
    );
    refused(
        &["minimal", "--duration", "-5"],
        &[],
        "whole number of milliseconds",
    );
    refused(
        &["minimal", "--port-base", "0"],
        &[],
        "port number from 1 to 65535",
    );
    refused(&["minimal", "--port-base=70000"], &[], "not \"70000\"");
    refused(
        &["minimal"],
        &[("SEMO_PORT_BASE", "x")],
        "SEMO_PORT_BASE must be a port number",
    );
    refused(
        &["minimal", "--scenario", "s.json"],
        &[],
        "build it with `semo build --sim --scenario FILE`",
    );
    let help = p.run(&["minimal", "--help"], &[]);
    assert_eq!(help.code, 0);
    assert!(help.stdout.starts_with("usage: minimal"), "{}", help.stdout);

    let sim = program(Flavor::Plain {
        cc: "gcc",
        sim: true,
    });
    let run = sim.run(&["minimal", "--time-scale", "0"], &[]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains("--time-scale must be a positive number"),
        "{}",
        run.stderr
    );
    let unreachable = sim.run(&["minimal", "--trace", "/nonexistent/dir/trace.jsonl"], &[]);
    assert_eq!(unreachable.code, 1);
    assert!(
        unreachable.stderr.contains("cannot write the trace"),
        "{}",
        unreachable.stderr
    );
}

/// No program reads a scenario file: the scenario is compiled in (`semo
/// build --scenario FILE`, whose reader's mistakes are the simulator's:
/// `compiler/src/sim/tests.rs`), and a simulated program given one says
/// how to build it instead.
#[test]
fn a_simulated_program_given_a_scenario_says_to_compile_it_in() {
    for flavor in flavors().into_iter().filter(|f| f.sim()) {
        let p = program(flavor);
        for args in [
            &["minimal", "--scenario", "s.json"][..],
            &["minimal", "--scenario=s.json"],
        ] {
            let run = p.run(args, &[]);
            assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
            assert_eq!(
                run.stderr.trim(),
                "minimal: --scenario is not read at run time: a simulation's scenario is compiled into the program; build it with `semo build --sim --scenario FILE`",
            );
        }
    }
}
