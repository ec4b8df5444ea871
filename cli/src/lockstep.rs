//! The lock-step coordinator of `semo simulate --engine c`: it runs the
//! built `linux-sim` programs of a mission as processes, each with
//! `--lockstep SOCKET`, and is their clock and their network
//! (`codegen/runtime/semo_lockstep.c` says the robot's side and the frames).
//!
//! Mission time moves only when every robot is idle (each has said so with
//! the earliest time it wants to wake at), to the earliest of those times,
//! of the messages' arrivals and of the scenario's process faults. Messages
//! arrive after the scenario's network latency, delivered in the order of
//! their senders' peer indices, each sender's in the order it sent them. A
//! run is then a function of the programs and the scenario: no clock is read
//! and the machine's load changes nothing but how long it takes.
//!
//! A robot pauses after its `start` line (it reports itself idle at that
//! instant), so a fault at the instant it starts (a kill at 0 ms, a kill
//! right after a restart) comes before anything else it does, as in the
//! simulator.

use std::collections::BTreeMap;
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
    /// The program (`<folder>/<robot>`).
    pub exe: PathBuf,
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
    coordinator.stop_all();
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

/// What a robot's stream brought.
enum Frame {
    /// Idle until the given time (`None`: until a message or for ever).
    Idle(Option<i64>),
    /// A datagram for a peer.
    Message { to: usize, datagram: Vec<u8> },
    /// The stream ended (the process ended or was killed), broke, or
    /// brought a frame no robot sends.
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
                datagram: payload[4..].to_vec(),
            },
            Ok(_) | Err(_) => Frame::End,
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
    /// (arrival, sender, sequence) → (receiver, datagram): the delivery order.
    in_flight: BTreeMap<(i64, usize, u64), (usize, Vec<u8>)>,
    sent: u64,
    losses: LossDraws,
    /// Per peer, by incarnation: the trace lines of the faults done to it
    /// after that incarnation's own lines (a killed process writes nothing
    /// more; the simulator traces the same `fault` events).
    faults_after: Vec<BTreeMap<u32, String>>,
    /// The processor of the run (given back when the coordinator goes).
    cpu: OneCpu,
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
            sent: 0,
            losses: LossDraws::new(run.seed),
            faults_after: vec![BTreeMap::new(); run.robots.len()],
            cpu: OneCpu::take(),
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
            let next_fault = faults.peek().map(|f| f.0);
            let Some(next) = [next_wake, next_arrival, next_fault]
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
            self.deliver_due()?;
            for peer in 0..self.live.len() {
                let due = self.live[peer]
                    .as_ref()
                    .is_some_and(|l| l.idle && l.wakes_at.is_some_and(|t| t <= self.now));
                if due {
                    self.grant(peer)?;
                }
            }
        }
    }

    /// Starts the robot `peer` at the current time.
    fn start(&mut self, peer: usize) -> Result<(), String> {
        let robot = &self.run.robots[peer];
        let incarnation = self.incarnations[peer];
        self.incarnations[peer] += 1;
        let errors = std::fs::File::create(
            self.run
                .work
                .join(format!("{}.{incarnation}.stderr", robot.name)),
        )
        .map_err(|e| format!("{}: {e}", self.run.work.display()))?;
        let mut child = Command::new(&robot.exe)
            .arg("--trace")
            .arg(trace_path(self.run.work, robot, incarnation))
            .arg("--lockstep")
            .arg(self.run.work.join("lockstep.sock"))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(errors)
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", robot.exe.display()))?;
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
            Frame::Message { to, datagram } => {
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
                let arrival = self.now + latency;
                self.in_flight
                    .insert((arrival, peer, self.sent), (to, datagram));
                self.sent += 1;
            }
            Frame::End => {
                if let Some(mut live) = self.live[peer].take() {
                    let _ = live.child.wait();
                }
            }
        }
        Ok(())
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
    /// granted the time (they run what the messages wake).
    fn deliver_due(&mut self) -> Result<(), String> {
        let mut woken = vec![false; self.live.len()];
        while let Some(entry) = self.in_flight.first_entry() {
            if entry.key().0 > self.now {
                break;
            }
            let (to, datagram) = entry.remove();
            // A message for a robot that is not running is lost.
            if let Some(live) = self.live[to].as_mut()
                && write_frame(&mut live.stream, b'D', &datagram).is_ok()
            {
                woken[to] = true;
            }
        }
        for (peer, woken) in woken.into_iter().enumerate() {
            if woken {
                self.grant(peer)?;
            }
        }
        Ok(())
    }

    fn grant(&mut self, peer: usize) -> Result<(), String> {
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
    fn stop_all(&mut self) {
        for live in self.live.iter_mut().filter_map(Option::take) {
            let Live {
                mut child, stream, ..
            } = live;
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

/// Builds the mission's `linux-sim` programs in a private folder, makes
/// them, and runs them on the scenario until `until_ms`: each robot's name
/// and trace, in peer order.
pub fn simulate(
    input: &semo::refine::BuildInput<'_>,
    refined: &semo::refine::Refined,
    scenario: &semo::sim::scenario::Scenario,
    until_ms: i64,
    seed: u64,
) -> Result<Vec<(String, String)>, String> {
    use semo::sim::scenario::FaultKind;
    let network = &scenario.network;
    let peers: Vec<(String, semo::refine::PeerId)> = refined
        .programs
        .iter()
        .map(|p| (p.robot.clone(), p.self_peer))
        .collect();
    // Each program gets its robot's world compiled in: the scenario is
    // read once, here, by the simulator's reader.
    let worlds = scenario.compiled_for_each(&refined.programs);
    let built = semo::codegen::build_refined(
        input,
        refined,
        semo::codegen::Target::LinuxSim,
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
            "the mission cannot be built for linux-sim:\n  {}",
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
    for output in &built.robots {
        let folder = work.path().join(&output.team).join(&output.robot);
        write_files(&folder, &output.files)?;
        make(&folder)?;
        let Some(&(_, peer)) = peers.iter().find(|(name, _)| *name == output.robot) else {
            return Err(format!(
                "internal error: robot {} is not in the peer table",
                output.robot
            ));
        };
        // One program per robot of the mission (`refine_checked`), so a
        // peer's position is a place in `robots`.
        robots[peer.index()] = Some(Robot {
            name: output.robot.clone(),
            exe: folder.join(&output.robot),
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
    Ok(robots.iter().map(|r| r.name.clone()).zip(traces).collect())
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

/// `make` in a robot's folder (quiet; its errors are shown).
fn make(folder: &Path) -> Result<(), String> {
    let made = Command::new("make")
        .arg("-s")
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
pub fn merged(robots: &[(String, String)]) -> String {
    let mut lines: Vec<(i64, usize, usize, &str)> = Vec::new();
    for (peer, (_, text)) in robots.iter().enumerate() {
        for (i, line) in text.lines().enumerate() {
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
