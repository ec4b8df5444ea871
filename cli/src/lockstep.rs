//! The lock-step coordinator of `semo simulate --engine c`: it runs the
//! built `linux-sim` programs of a mission as processes, each with
//! `--lockstep SOCKET`, and is their clock and their network
//! (`codegen/runtime/semo_lockstep.c` says the robot's side and the frames).
//!
//! Mission time moves only when every robot is idle (each has said so with
//! the earliest time it wants to wake at), to the earliest of those times,
//! of the messages' arrivals and of the scenario's process faults. Messages
//! arrive after the scenario's network latency; those arriving at one
//! instant are delivered in the order they were sent. At one instant the
//! robots run one at a time, in the order they started (as the simulator
//! fires them), each after the messages that reached it by then: over a
//! link of no latency a message reaches the robots that run after its
//! sender at the instant it was sent. A run is then a function of
//! the programs and the scenario: no clock is read and the machine's load
//! changes nothing but how long it takes.
//!
//! A robot pauses after its `start` line (it reports itself idle at that
//! instant), so a fault at the instant it starts (a kill at 0 ms, a kill
//! right after a restart) comes before anything else it does, as in the
//! simulator.

use std::collections::{BTreeMap, VecDeque};
use std::io::{self, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use rustix::event::{PollFd, PollFlags, poll};
use semo::sim::loss::LossDraws;

/// A built robot program of the run.
pub struct Robot {
    /// Its name (its trace files are named after it).
    pub name: String,
    pub launch: Launch,
}

/// How a robot of the run is started.
pub enum Launch {
    /// A `linux-sim` program (`<folder>/<robot>`), as a process with
    /// `--trace FILE --lockstep SOCKET`.
    Program(PathBuf),
    /// A board's simulation firmware made with `make LOCKSTEP=1`
    /// (`semo_static_lockstep.c`), in the board's emulator: its trace port
    /// written to the trace file, its link port connected to the socket.
    Board {
        elf: PathBuf,
        board: &'static semo::platform::Board,
    },
}

impl Launch {
    fn command(&self, trace: &Path, socket: &Path) -> Command {
        match self {
            Launch::Program(exe) => {
                let mut command = Command::new(exe);
                command
                    .arg("--trace")
                    .arg(trace)
                    .arg("--lockstep")
                    .arg(socket);
                command
            }
            Launch::Board { elf, board } => {
                let mut command = Command::new(board.emulator);
                command
                    .args(["-M", board.machine, "-display", "none", "-monitor", "none"])
                    .args(["-semihosting", "-serial"])
                    .arg(chardev("file", trace))
                    .arg("-serial")
                    .arg(chardev("unix", socket))
                    .arg("-kernel")
                    .arg(elf);
                command
            }
        }
    }

    fn path(&self) -> &Path {
        match self {
            Launch::Program(exe) => exe,
            Launch::Board { elf, .. } => elf,
        }
    }

    /// A board's serial port cannot close: it is told the run ended.
    fn is_board(&self) -> bool {
        matches!(self, Launch::Board { .. })
    }
}

/// A QEMU character device on `path` (`file:PATH`, `unix:PATH`).
fn chardev(kind: &str, path: &Path) -> std::ffi::OsString {
    let mut arg = std::ffi::OsString::from(format!("{kind}:"));
    arg.push(path);
    arg
}

/// What happens to a process from outside, at a mission time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProcessFault {
    Kill,
    Restart,
}

pub struct Run<'a> {
    /// In peer order (the programs' peer tables).
    pub robots: &'a [Robot],
    /// (at, peer, fault), in time order.
    pub faults: Vec<(i64, usize, ProcessFault)>,
    /// The link from one peer to another: its latency (mission ms) and
    /// the probability that a message on it is lost.
    pub link: &'a dyn Fn(usize, usize) -> (i64, f64),
    /// Seeds the losses: the simulator's draws for the same seed
    /// (`semo::sim::loss`).
    pub seed: u64,
    /// Mission time after which the run ends (the robots are stopped).
    pub until_ms: i64,
    /// Where the socket, the traces and the robots' error output go.
    pub work: &'a Path,
}

/// Each robot's trace (its incarnations' in order), in peer order.
pub fn run(run: &Run<'_>) -> Result<Vec<String>, String> {
    let socket = run.work.join("lockstep.sock");
    let listener = UnixListener::bind(&socket)
        .map_err(|e| format!("cannot listen on {}: {e}", socket.display()))?;
    let mut coordinator = Coordinator::new(run, listener);
    let result = coordinator.drive();
    coordinator.stop_all(result.is_ok());
    result?;
    let mut traces = Vec::new();
    for (peer, robot) in run.robots.iter().enumerate() {
        let mut text = String::new();
        for incarnation in 0..coordinator.incarnations[peer] {
            let path = trace_path(run.work, robot, incarnation);
            text.push_str(&std::fs::read_to_string(&path).unwrap_or_default());
            if let Some(faults) = coordinator.faults_after[peer].get(&incarnation) {
                text.push_str(faults);
            }
        }
        traces.push(text);
    }
    Ok(traces)
}

fn trace_path(work: &Path, robot: &Robot, incarnation: u32) -> PathBuf {
    work.join(format!("{}.{incarnation}.jsonl", robot.name))
}

/// The run's one processor: the coordinator's thread and every robot's
/// threads run on it (the processor the coordinator was on, when it may
/// stay there). In lock-step they take turns, one at a time; a turn handed
/// to a thread on another processor waits for that processor to wake (on a
/// virtual machine tens of microseconds, a dozen times per robot instant),
/// which is most of a run's time on an idle machine. Where the affinity
/// cannot be set the run goes on anywhere, only slower; the outcome is the
/// same (lock-step fixes the order of everything).
struct OneCpu {
    one: rustix::thread::CpuSet,
    /// The coordinator thread's affinity before, given back at the end.
    before: Option<rustix::thread::CpuSet>,
}

impl OneCpu {
    fn take() -> Self {
        use rustix::thread::{CpuSet, sched_getaffinity, sched_getcpu, sched_setaffinity};
        let before = sched_getaffinity(None).ok();
        let mut one = CpuSet::new();
        let here = sched_getcpu();
        match &before {
            Some(allowed) if here < CpuSet::MAX_CPU && allowed.is_set(here) => one.set(here),
            Some(allowed) => match (0..CpuSet::MAX_CPU).find(|&c| allowed.is_set(c)) {
                Some(c) => one.set(c),
                None => return OneCpu { one, before: None },
            },
            None => return OneCpu { one, before: None },
        }
        let _ = sched_setaffinity(None, &one);
        OneCpu { one, before }
    }

    /// Set before the robot connects, so that every thread it starts
    /// inherits it.
    fn keep(&self, child: &Child) {
        if self.before.is_some() {
            let pid = rustix::process::Pid::from_child(child);
            let _ = rustix::thread::sched_setaffinity(Some(pid), &self.one);
        }
    }
}

impl Drop for OneCpu {
    fn drop(&mut self) {
        if let Some(before) = &self.before {
            let _ = rustix::thread::sched_setaffinity(None, before);
        }
    }
}

/// A message on its way.
struct InFlight {
    to: usize,
    /// The receiver's process when it was sent (its count of starts).
    incarnation: u32,
    datagram: Vec<u8>,
}

/// What became of a message offered to a robot.
enum Offered {
    Taken,
    /// Refused for now (given back).
    Busy(Vec<u8>),
    /// The robot is not running, or its stream ended.
    Lost,
}

/// What a robot's stream brought.
enum Frame {
    /// Idle until the given time (`None`: until a message or for ever).
    Idle(Option<i64>),
    /// A datagram for a peer, to arrive `delay_ms` after the link's
    /// latency.
    Message {
        to: usize,
        delay_ms: i64,
        datagram: Vec<u8>,
    },
    /// A board took the message it was sent.
    Taken,
    /// A board cannot take the message it was sent yet.
    Busy,
    /// A frame no robot sends (its kind).
    Unexpected(u8),
    /// The stream ended (the process ended or was killed) or broke.
    End,
}

impl Frame {
    /// The next frame of a robot's stream (it waits for a whole frame).
    fn read(stream: &mut UnixStream) -> Frame {
        match read_frame(stream) {
            Ok((b'I', payload)) if payload.len() == 8 => {
                let at = i64::from_le_bytes(payload[..8].try_into().expect("eight bytes"));
                Frame::Idle((at >= 0).then_some(at))
            }
            Ok((b'M', payload)) if payload.len() >= 4 => Frame::Message {
                to: u32::from_le_bytes(payload[..4].try_into().expect("four bytes")) as usize,
                delay_ms: 0,
                datagram: payload[4..].to_vec(),
            },
            Ok((b'L', payload)) if payload.len() >= 12 => Frame::Message {
                to: u32::from_le_bytes(payload[..4].try_into().expect("four bytes")) as usize,
                delay_ms: i64::from_le_bytes(payload[4..12].try_into().expect("eight bytes")),
                datagram: payload[12..].to_vec(),
            },
            Ok((b'A', payload)) if payload.is_empty() => Frame::Taken,
            Ok((b'B', payload)) if payload.is_empty() => Frame::Busy,
            Ok((kind, _)) => Frame::Unexpected(kind),
            Err(_) => Frame::End,
        }
    }
}

struct Live {
    child: Child,
    stream: UnixStream,
    idle: bool,
    wakes_at: Option<i64>,
}

struct Coordinator<'r, 'a> {
    run: &'r Run<'a>,
    listener: UnixListener,
    live: Vec<Option<Live>>,
    incarnations: Vec<u32>,
    now: i64,
    /// (arrival, sequence) → the message: the delivery order, the order
    /// the messages were sent in for those arriving at one instant (as the
    /// simulator's queue numbers them; the robots run one at a time, so the
    /// order the coordinator hears them in is the order they were sent in).
    in_flight: BTreeMap<(i64, u64), InFlight>,
    /// Per robot, the messages that arrived for it, in order, from the
    /// first it refused (a board whose inbox is full and unpolled).
    kept: Vec<VecDeque<Vec<u8>>>,
    /// Per robot: it ran since it last refused a message.
    may_offer: Vec<bool>,
    sent: u64,
    losses: LossDraws,
    /// Per peer, by incarnation: the trace lines of the faults done to it
    /// after that incarnation's own lines (a killed process writes nothing
    /// more; the simulator traces the same `fault` events).
    faults_after: Vec<BTreeMap<u32, String>>,
    /// The processor of the run (given back when the coordinator goes).
    cpu: OneCpu,
    /// Per peer, the order of its last start among all starts: the order in
    /// which the robots due at one instant run (the simulator's).
    started: Vec<u64>,
    starts: u64,
}

impl<'r, 'a> Coordinator<'r, 'a> {
    fn new(run: &'r Run<'a>, listener: UnixListener) -> Self {
        Coordinator {
            run,
            listener,
            live: run.robots.iter().map(|_| None).collect(),
            incarnations: vec![0; run.robots.len()],
            now: 0,
            in_flight: BTreeMap::new(),
            kept: vec![VecDeque::new(); run.robots.len()],
            may_offer: vec![false; run.robots.len()],
            sent: 0,
            losses: LossDraws::new(run.seed),
            faults_after: vec![BTreeMap::new(); run.robots.len()],
            cpu: OneCpu::take(),
            started: vec![0; run.robots.len()],
            starts: 0,
        }
    }

    fn drive(&mut self) -> Result<(), String> {
        for peer in 0..self.run.robots.len() {
            self.start(peer)?;
        }
        let mut faults = self.run.faults.iter().copied().peekable();
        loop {
            self.wait_until_all_idle()?;
            if self.live.iter().all(Option::is_none) {
                return Ok(());
            }
            let next_wake = self.live.iter().flatten().filter_map(|l| l.wakes_at).min();
            let next_arrival = self.in_flight.keys().next().map(|k| k.0);
            // Messages a board refused are offered again once it ran.
            let next_offer = self.may_offer.iter().any(|&m| m).then_some(self.now);
            let next_fault = faults.peek().map(|f| f.0);
            let Some(next) = [next_wake, next_arrival, next_offer, next_fault]
                .into_iter()
                .flatten()
                .min()
            else {
                return Ok(()); // every robot waits for a message no one will send
            };
            if next > self.run.until_ms {
                return Ok(());
            }
            self.now = self.now.max(next);
            while let Some(&(at, peer, fault)) = faults.peek() {
                if at > self.now {
                    break;
                }
                faults.next();
                // As the simulator: a kill of a robot that is not running
                // and a restart of one that is are no faults at all.
                let running = self.live[peer].is_some();
                match fault {
                    ProcessFault::Kill if running => {
                        self.trace_fault(peer, "kill");
                        self.kill(peer);
                    }
                    ProcessFault::Restart if !running => {
                        self.trace_fault(peer, "restart");
                        self.start(peer)?;
                        // Its `start` is written before a later fault of
                        // this instant (it pauses after it).
                        self.wait_until_all_idle()?;
                    }
                    ProcessFault::Kill | ProcessFault::Restart => {}
                }
            }
            self.run_instant()?;
        }
    }

    /// Runs the robots due now, or told of messages now, one at a time in
    /// the order of their starts (as the simulator fires them), each after
    /// the messages that reached it by then: a message sent at this instant
    /// over a link of no latency reaches the robots that run after its
    /// sender, as in the simulator.
    fn run_instant(&mut self) -> Result<(), String> {
        let mut asked: Vec<Option<bool>> = vec![None; self.live.len()];
        loop {
            for (peer, runs) in self.deliver_due()? {
                asked[peer] = Some(asked[peer].unwrap_or(false) || runs);
            }
            for (peer, asked) in asked.iter_mut().enumerate() {
                let due = self.live[peer]
                    .as_ref()
                    .is_some_and(|l| l.idle && l.wakes_at.is_some_and(|t| t <= self.now));
                if due {
                    *asked = Some(true);
                }
            }
            let Some(peer) = (0..asked.len())
                .filter(|&p| asked[p].is_some())
                .min_by_key(|&p| self.started[p])
            else {
                return Ok(());
            };
            let runs = asked[peer].take().unwrap_or(true);
            self.grant_as(peer, runs)?;
            self.wait_until_all_idle()?;
        }
    }

    /// Starts the robot `peer` at the current time.
    fn start(&mut self, peer: usize) -> Result<(), String> {
        let robot = &self.run.robots[peer];
        let incarnation = self.incarnations[peer];
        self.incarnations[peer] += 1;
        self.started[peer] = self.starts;
        self.starts += 1;
        let errors = std::fs::File::create(
            self.run
                .work
                .join(format!("{}.{incarnation}.stderr", robot.name)),
        )
        .map_err(|e| format!("{}: {e}", self.run.work.display()))?;
        let mut child = robot
            .launch
            .command(
                &trace_path(self.run.work, robot, incarnation),
                &self.run.work.join("lockstep.sock"),
            )
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(errors)
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", robot.launch.path().display()))?;
        self.cpu.keep(&child);
        let (stream, who) = match self.accept(&mut child) {
            Ok(accepted) => accepted,
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!("robot {}: {e}", robot.name));
            }
        };
        if who != peer {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "robot {} says it is peer {who}, not {peer}: the programs are not of one build",
                robot.name
            ));
        }
        let mut live = Live {
            child,
            stream,
            idle: false,
            wakes_at: None,
        };
        write_frame(&mut live.stream, b'G', &self.now.to_le_bytes())
            .map_err(|e| format!("robot {}: {e}", robot.name))?;
        self.live[peer] = Some(live);
        Ok(())
    }

    /// The robot's connection and the peer index it says it is, or why not:
    /// it ended first. No timeout: a robot that starts connects at once.
    fn accept(&self, child: &mut Child) -> Result<(UnixStream, usize), String> {
        self.listener
            .set_nonblocking(true)
            .map_err(|e| e.to_string())?;
        let mut stream = loop {
            match self.listener.accept() {
                Ok((stream, _)) => break stream,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                    if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
                        return Err(format!(
                            "ended before it connected ({status}); its errors are beside its trace"
                        ));
                    }
                    std::thread::sleep(std::time::Duration::from_millis(1));
                }
                Err(e) => return Err(e.to_string()),
            }
        };
        stream.set_nonblocking(false).map_err(|e| e.to_string())?;
        match read_frame(&mut stream) {
            Ok((b'H', payload)) if payload.len() == 4 => {
                let who = u32::from_le_bytes(payload[..4].try_into().expect("four bytes"));
                Ok((stream, who as usize))
            }
            Ok(_) => Err("did not say who it is".to_string()),
            Err(e) => Err(e.to_string()),
        }
    }

    /// The `fault` line of the robot's trace, after its last incarnation's.
    fn trace_fault(&mut self, peer: usize, fault: &str) {
        let line = serde_json::json!({
            "t": self.now,
            "robot": self.run.robots[peer].name,
            "event": "fault",
            "fault": fault,
        });
        let last = self.incarnations[peer].saturating_sub(1);
        let after = self.faults_after[peer].entry(last).or_default();
        after.push_str(&line.to_string());
        after.push('\n');
    }

    fn kill(&mut self, peer: usize) {
        // What it had not taken goes with it, as what arrives after.
        self.kept[peer].clear();
        self.may_offer[peer] = false;
        if let Some(mut live) = self.live[peer].take() {
            let _ = live.child.kill();
            let _ = live.child.wait();
        }
    }

    /// Reads the robots' frames until every live robot is idle. The
    /// coordinator reads them itself, waiting on all the running robots'
    /// streams at once: a reader thread per robot would cost a thread switch
    /// per frame, and a run is mostly switches.
    fn wait_until_all_idle(&mut self) -> Result<(), String> {
        loop {
            let running: Vec<usize> = (0..self.live.len())
                .filter(|&p| self.live[p].as_ref().is_some_and(|l| !l.idle))
                .collect();
            if running.is_empty() {
                return Ok(());
            }
            for peer in self.readable(&running)? {
                self.take_frame(peer)?;
            }
        }
    }

    /// Those of `peers` whose streams have something to read (or ended).
    fn readable(&self, peers: &[usize]) -> Result<Vec<usize>, String> {
        let streams: Vec<&UnixStream> = peers
            .iter()
            .filter_map(|&p| self.live[p].as_ref().map(|l| &l.stream))
            .collect();
        let mut fds: Vec<PollFd<'_>> = streams
            .iter()
            .map(|s| PollFd::new(*s, PollFlags::IN))
            .collect();
        loop {
            match poll(&mut fds, None) {
                Ok(_) => break,
                Err(rustix::io::Errno::INTR) => continue,
                Err(e) => return Err(format!("internal error: waiting for the robots: {e}")),
            }
        }
        Ok(peers
            .iter()
            .zip(&fds)
            .filter(|(_, fd)| !fd.revents().is_empty())
            .map(|(&p, _)| p)
            .collect())
    }

    /// Reads and acts on one frame of the robot `peer`.
    fn take_frame(&mut self, peer: usize) -> Result<(), String> {
        let Some(live) = self.live[peer].as_mut() else {
            return Ok(());
        };
        match Frame::read(&mut live.stream) {
            Frame::Idle(wakes_at) => {
                live.idle = true;
                live.wakes_at = wakes_at;
            }
            Frame::Message {
                to,
                delay_ms,
                datagram,
            } => self.route(peer, to, delay_ms, datagram)?,
            frame @ (Frame::Taken | Frame::Busy | Frame::Unexpected(_)) => {
                return Err(self.unexpected(peer, &frame));
            }
            Frame::End => {
                if let Some(mut live) = self.live[peer].take() {
                    // A robot ends by itself when its mission finished or
                    // its scenario's time is up; anything else is a failure
                    // the run must not hide.
                    match live.child.wait() {
                        Ok(status) if !status.success() => {
                            let robot = &self.run.robots[peer];
                            let incarnation = self.incarnations[peer] - 1;
                            // The work folder goes with the run: what the
                            // robot said goes into the error. A board says
                            // it on its trace port, after its trace.
                            let said = |path: PathBuf| {
                                let text = std::fs::read_to_string(path).unwrap_or_default();
                                text.lines()
                                    .filter(|l| !l.starts_with('{'))
                                    .map(|l| format!("\n  {l}"))
                                    .collect::<String>()
                            };
                            return Err(format!(
                                "robot {} failed ({status}){}{}",
                                robot.name,
                                said(trace_path(self.run.work, robot, incarnation)),
                                said(
                                    self.run
                                        .work
                                        .join(format!("{}.{incarnation}.stderr", robot.name))
                                ),
                            ));
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(())
    }

    /// A message `peer` sent to `to` now, on its way (or lost, as the
    /// scenario says), `delay_ms` later than the link's latency (a delay
    /// fault the sender's runtime applies).
    fn route(
        &mut self,
        peer: usize,
        to: usize,
        delay_ms: i64,
        datagram: Vec<u8>,
    ) -> Result<(), String> {
        if to >= self.live.len() {
            return Err(format!(
                "robot {} sent a message to peer {to}, which does not exist",
                self.run.robots[peer].name
            ));
        }
        let (latency, loss) = (self.run.link)(peer, to);
        if loss > 0.0 && self.lost(peer, to, &datagram, loss)? {
            return Ok(());
        }
        // A scenario's times are at most 10^15 ms, so a sum of them cannot
        // overflow; a robot saying otherwise is not of this build.
        if !(0..=1_000_000_000_000_000).contains(&delay_ms) {
            return Err(format!(
                "internal error: robot {} delayed a message by {delay_ms} ms",
                self.run.robots[peer].name
            ));
        }
        let arrival = self.now + latency + delay_ms;
        // It reaches the process the receiver ran when it was sent, as in
        // the simulator (a robot restarted meanwhile, or down then, does
        // not hear it).
        let message = InFlight {
            to,
            incarnation: self.incarnations[to],
            datagram,
        };
        self.in_flight.insert((arrival, self.sent), message);
        self.sent += 1;
        Ok(())
    }

    fn unexpected(&self, peer: usize, frame: &Frame) -> String {
        let what = match frame {
            Frame::Idle(_) => "an idle report".to_string(),
            Frame::Taken | Frame::Busy => "an answer to a message".to_string(),
            Frame::Unexpected(kind) => format!("a frame of kind {kind:#04x}"),
            Frame::Message { .. } | Frame::End => "a frame".to_string(),
        };
        format!(
            "internal error: robot {} sent {what} out of turn in lock-step",
            self.run.robots[peer].name
        )
    }

    /// Reads what a board sends until it answers the message it was sent:
    /// whether it took it (else it will, later). Its messages meanwhile (a
    /// full inbox runs the task that reads it, which may send) go on their
    /// way.
    fn until_taken(&mut self, peer: usize) -> Result<bool, String> {
        loop {
            let Some(live) = self.live[peer].as_mut() else {
                return Ok(true);
            };
            match Frame::read(&mut live.stream) {
                Frame::Taken => return Ok(true),
                Frame::Busy => return Ok(false),
                Frame::Message {
                    to,
                    delay_ms,
                    datagram,
                } => self.route(peer, to, delay_ms, datagram)?,
                frame @ (Frame::Idle(_) | Frame::Unexpected(_)) => {
                    return Err(self.unexpected(peer, &frame));
                }
                Frame::End => {
                    return Err(format!(
                        "robot {} ended while it took a message; its trace says why",
                        self.run.robots[peer].name
                    ));
                }
            }
        }
    }

    /// Whether the scenario's random loss takes this message, drawn as the
    /// simulator draws it: by sender, receiver and key.
    fn lost(&mut self, from: usize, to: usize, datagram: &[u8], loss: f64) -> Result<bool, String> {
        let names = |peer: usize| self.run.robots[peer].name.as_str();
        let message = semo::deploy::datagram::decode(datagram).ok_or_else(|| {
            format!(
                "internal error: robot {} sent a datagram that is no message",
                names(from)
            )
        })?;
        Ok(self.losses.lost(names(from), names(to), &message.key, loss))
    }

    /// Delivers every message due by now; the robots that got one are
    /// granted the time (they run what the messages wake). The messages a
    /// board refused go first once it has run since (they arrived before the
    /// others), and stay in order before any that arrive after them.
    fn deliver_due(&mut self) -> Result<Vec<(usize, bool)>, String> {
        let robots = self.live.len();
        let (mut woken, mut told) = (vec![false; robots], vec![false; robots]);
        for (to, woken) in woken.iter_mut().enumerate() {
            if !self.may_offer[to] {
                continue;
            }
            self.may_offer[to] = false;
            while let Some(datagram) = self.kept[to].pop_front() {
                match self.offer(to, datagram, &mut told)? {
                    Offered::Taken => *woken = true,
                    Offered::Busy(datagram) => {
                        self.kept[to].push_front(datagram);
                        break;
                    }
                    Offered::Lost => {}
                }
            }
        }
        while let Some(entry) = self.in_flight.first_entry() {
            if entry.key().0 > self.now {
                break;
            }
            let InFlight {
                to,
                incarnation,
                datagram,
            } = entry.remove();
            if incarnation != self.incarnations[to] {
                continue;
            }
            if !self.kept[to].is_empty() {
                self.kept[to].push_back(datagram);
                continue;
            }
            match self.offer(to, datagram, &mut told)? {
                Offered::Taken => woken[to] = true,
                Offered::Busy(datagram) => self.kept[to].push_back(datagram),
                Offered::Lost => {}
            }
        }
        let mut grants = Vec::new();
        for peer in 0..robots {
            if woken[peer] {
                grants.push((peer, true));
            } else if told[peer] {
                // It refused every message, and waits for the time: it runs
                // only what was due anyway, which alone may make room.
                let due = self.live[peer]
                    .as_ref()
                    .is_some_and(|l| l.wakes_at.is_some_and(|t| t <= self.now));
                grants.push((peer, due));
            }
        }
        Ok(grants)
    }

    /// Sends robot `to` one message: a board is told the instant first
    /// (once per round, in `told`) and says whether it took it.
    fn offer(
        &mut self,
        to: usize,
        datagram: Vec<u8>,
        told: &mut [bool],
    ) -> Result<Offered, String> {
        let board = self.run.robots[to].launch.is_board();
        // A message for a robot that is not running is lost.
        let Some(live) = self.live[to].as_mut() else {
            return Ok(Offered::Lost);
        };
        // A board takes a message at once (it may run the task that reads
        // its inbox): it is told the time first.
        if board && !told[to] {
            if write_frame(&mut live.stream, b'N', &self.now.to_le_bytes()).is_err() {
                return Ok(Offered::Lost); // it ended: its reader reports the end
            }
            told[to] = true;
        }
        if write_frame(&mut live.stream, b'D', &datagram).is_err() {
            return Ok(Offered::Lost);
        }
        // A serial port has no flow control: a board is sent the next
        // message once it has answered this one.
        if board && !self.until_taken(to)? {
            return Ok(Offered::Busy(datagram));
        }
        Ok(Offered::Taken)
    }

    /// Grants `peer` the time; `runs`: it will run something (what was due,
    /// or a message), so the messages it refused may be offered again
    /// after.
    fn grant_as(&mut self, peer: usize, runs: bool) -> Result<(), String> {
        if runs && !self.kept[peer].is_empty() {
            self.may_offer[peer] = true;
        }
        let now = self.now;
        let Some(live) = self.live[peer].as_mut() else {
            return Ok(());
        };
        if !live.idle {
            return Ok(()); // granted already at this instant
        }
        live.idle = false;
        if write_frame(&mut live.stream, b'G', &now.to_le_bytes()).is_err() {
            // It ended: its reader reports the end.
            live.idle = true;
            live.wakes_at = None;
        }
        Ok(())
    }

    /// Ends the run: a robot whose coordinator is gone stops (its wrap-ups
    /// run and its trace is closed).
    fn stop_all(&mut self, well: bool) {
        for (peer, live) in self.live.iter_mut().enumerate() {
            let Some(Live {
                mut child,
                mut stream,
                ..
            }) = live.take()
            else {
                continue;
            };
            // A board's serial port does not close: it is told. It stops
            // as a program does when its socket closes (at the last time
            // it was granted). After a failure, when it may be in the middle
            // of anything, it is stopped.
            if self.run.robots[peer].launch.is_board() {
                if well {
                    let _ = write_frame(&mut stream, b'E', &[]);
                } else {
                    let _ = child.kill();
                }
            }
            let _ = stream.shutdown(std::net::Shutdown::Both);
            drop(stream);
            let _ = child.wait();
        }
    }
}

/// The longest payload a robot may send: a datagram and its peer index.
const FRAME_MAX: usize = 64 * 1024;

fn read_frame(stream: &mut UnixStream) -> io::Result<(u8, Vec<u8>)> {
    let mut header = [0u8; 5];
    stream.read_exact(&mut header)?;
    let len = u32::from_le_bytes(header[1..].try_into().expect("four bytes")) as usize;
    if len > FRAME_MAX {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("a frame of {len} bytes"),
        ));
    }
    let mut payload = vec![0u8; len];
    stream.read_exact(&mut payload)?;
    Ok((header[0], payload))
}

fn write_frame(stream: &mut UnixStream, kind: u8, payload: &[u8]) -> io::Result<()> {
    let mut frame = Vec::with_capacity(5 + payload.len());
    frame.push(kind);
    frame.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    frame.extend_from_slice(payload);
    stream.write_all(&frame)
}

/// A robot of a lock-step run.
pub struct Ran {
    pub name: String,
    /// Its incarnations' trace lines, in order.
    pub trace: String,
    /// The board whose emulator ran it, if any (else a `linux-sim` process).
    pub board: Option<&'static semo::platform::Board>,
    pub target: semo::platform::Target,
}

/// Builds the mission's programs in a private folder, each robot for its
/// simulation target in `targets` (`linux-sim`, or a board's `-sim` made
/// with `LOCKSTEP=1` and run in its emulator), makes them, and runs them on
/// the scenario until `until_ms`: each robot, in peer order.
pub fn simulate(
    input: &semo::refine::BuildInput<'_>,
    refined: &semo::refine::Refined,
    targets: &semo::targets::Targets,
    scenario: &semo::sim::scenario::Scenario,
    until_ms: i64,
    seed: u64,
) -> Result<Vec<Ran>, String> {
    use semo::sim::scenario::FaultKind;
    let network = &scenario.network;
    let peers: Vec<(String, semo::refine::PeerId)> = refined
        .programs
        .iter()
        .map(|p| (p.robot.clone(), p.self_peer))
        .collect();
    no_latency_on_a_board(refined, targets, network)?;
    // Each program gets its robot's world compiled in: the scenario is
    // read once, here, by the simulator's reader.
    let worlds = scenario.compiled_for_each(&refined.programs);
    let built = semo::codegen::build_refined_each(
        input,
        refined,
        targets,
        semo::codegen::Emit::All,
        &worlds,
    );
    if built.refused() {
        let why: Vec<String> = built
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .map(|d| format!("{}: {}", d.code.as_str(), d.message))
            .collect();
        return Err(format!(
            "the mission cannot be built for its simulations:\n  {}",
            why.join("\n  ")
        ));
    }
    let work = tempfile::Builder::new()
        .prefix("semo-lockstep-")
        .tempdir()
        .map_err(|e| format!("cannot make a work folder: {e}"))?;
    let runtime = work.path().join(semo::codegen::RUNTIME_FOLDER);
    write_files(&runtime, &built.runtime)?;
    let mut robots: Vec<Option<Robot>> = peers.iter().map(|_| None).collect();
    let mut targets_of: Vec<Option<semo::platform::Target>> = peers.iter().map(|_| None).collect();
    for output in &built.robots {
        let folder = work.path().join(&output.team).join(&output.robot);
        write_files(&folder, &output.files)?;
        if !output.target.simulated() {
            return Err(format!(
                "internal error: robot {} was built for {}, which is no simulation",
                output.robot, output.target
            ));
        }
        let board = output.target.platform().board.as_ref();
        make(&folder, board.is_some())?;
        let Some(&(_, peer)) = peers.iter().find(|(name, _)| *name == output.robot) else {
            return Err(format!(
                "internal error: robot {} is not in the peer table",
                output.robot
            ));
        };
        // One program per robot of the mission (`refine_checked`), so a
        // peer's position is a place in `robots`.
        targets_of[peer.index()] = Some(output.target);
        robots[peer.index()] = Some(Robot {
            name: output.robot.clone(),
            launch: match board {
                Some(board) => Launch::Board {
                    elf: folder.join(format!("{}.elf", output.robot)),
                    board,
                },
                None => Launch::Program(folder.join(&output.robot)),
            },
        });
    }
    let robots: Vec<Robot> = robots
        .into_iter()
        .collect::<Option<_>>()
        .ok_or("internal error: a peer has no program")?;
    let peer_of = |name: &str| robots.iter().position(|r| r.name == name);
    let mut faults = Vec::new();
    for fault in &scenario.faults {
        let (robot, at, kind) = match &fault.kind {
            FaultKind::Kill { robot, at } => (robot, *at, ProcessFault::Kill),
            FaultKind::Restart { robot, at } => (robot, *at, ProcessFault::Restart),
            _ => continue, // the programs act on link faults themselves
        };
        let peer = peer_of(robot).ok_or_else(|| {
            format!("internal error: the scenario's robot {robot} has no program")
        })?;
        faults.push((at, peer, kind));
    }
    faults.sort_by_key(|f| f.0);
    let names: Vec<&str> = robots.iter().map(|r| r.name.as_str()).collect();
    let link = |a: usize, b: usize| {
        let pair = |(x, y): &(String, String)| {
            (x == names[a] && y == names[b]) || (x == names[b] && y == names[a])
        };
        let link = network.links.iter().find(|l| pair(&l.between));
        (
            link.and_then(|l| l.latency_ms)
                .unwrap_or(network.latency_ms),
            link.and_then(|l| l.loss).unwrap_or(network.loss),
        )
    };
    let traces = run(&Run {
        robots: &robots,
        faults,
        link: &link,
        seed,
        until_ms,
        work: work.path(),
    })?;
    Ok(robots
        .into_iter()
        .zip(targets_of)
        .zip(traces)
        .map(|((robot, target), trace)| Ran {
            board: match robot.launch {
                Launch::Board { board, .. } => Some(board),
                Launch::Program(_) => None,
            },
            name: robot.name,
            trace,
            target: target.unwrap_or(semo::platform::Target::LinuxSim),
        })
        .collect())
}

/// Refuses a board robot with a link of no latency. A message of no
/// latency reaches the robots that run after its sender in the instant it
/// was sent, and one that arrives before a robot's first step, into an
/// inbox no task has read yet, must wait for the task that reads it within
/// that step: a `linux-sim` robot's receiver waits so, but a board takes
/// messages only between its steps, so it would act first and take them
/// after (or never, if that step ends its mission).
fn no_latency_on_a_board<'r>(
    refined: &'r semo::refine::Refined,
    targets: &semo::targets::Targets,
    network: &semo::sim::scenario::Network,
) -> Result<(), String> {
    let on_board = |robot: &'r str| {
        targets
            .of(robot)
            .and_then(|chosen| chosen.target.platform().board.as_ref())
            .map(|board| (robot, board))
    };
    let latency = |a: &str, b: &str| {
        network
            .links
            .iter()
            .find(|l| {
                (l.between.0 == a && l.between.1 == b) || (l.between.0 == b && l.between.1 == a)
            })
            .and_then(|l| l.latency_ms)
            .unwrap_or(network.latency_ms)
    };
    for (robot, board) in refined.programs.iter().filter_map(|p| on_board(&p.robot)) {
        let other = refined
            .programs
            .iter()
            .find(|o| o.robot != robot && latency(robot, &o.robot) == 0);
        if let Some(other) = other {
            return Err(format!(
                "robot {robot} runs on the {} board's emulator, which takes the messages of an \
                 instant only between its steps: a link of no latency (here to {}: a message \
                 arriving at the instant it is sent) is modelled for linux-sim robots only. Give \
                 {robot}'s links a latency of 1 ms or more, or run without --boards",
                board.name, other.robot
            ));
        }
    }
    Ok(())
}

/// `files` written into `folder` (a work folder of this run's own).
fn write_files(folder: &Path, files: &[semo::codegen::GeneratedFile]) -> Result<(), String> {
    for file in files {
        let path = folder.join(&file.path);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        }
        std::fs::write(&path, &file.text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// `make` in a robot's folder (quiet; its errors are shown); a board's
/// firmware with lock-step on its link's port.
fn make(folder: &Path, board: bool) -> Result<(), String> {
    let made = Command::new("make")
        .arg("-s")
        .args(board.then_some("LOCKSTEP=1"))
        .current_dir(folder)
        .output()
        .map_err(|e| format!("cannot run make (is it installed?): {e}"))?;
    if made.status.success() {
        Ok(())
    } else {
        Err(format!(
            "make failed in {}:\n{}",
            folder.display(),
            String::from_utf8_lossy(&made.stderr)
        ))
    }
}

/// The robots' traces as one, in time order; at one instant, robots in
/// peer order, each robot's lines in its order.
pub fn merged(robots: &[Ran]) -> String {
    let mut lines: Vec<(i64, usize, usize, &str)> = Vec::new();
    for (peer, robot) in robots.iter().enumerate() {
        for (i, line) in robot.trace.lines().enumerate() {
            lines.push((time_of(line), peer, i, line));
        }
    }
    lines.sort_unstable_by_key(|&(t, peer, i, _)| (t, peer, i));
    let mut out = String::new();
    for (_, _, _, line) in lines {
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// A trace line's `t` (every line starts `{"t":<ms>,`).
fn time_of(line: &str) -> i64 {
    line.strip_prefix("{\"t\":")
        .and_then(|rest| rest.split(',').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or(i64::MAX)
}
