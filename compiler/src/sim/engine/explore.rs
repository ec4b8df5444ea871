//! What `semo verify` asks of the engine: run to an instant, let the world
//! choose there (a sensor value, an operator command) exactly as a scenario
//! entry at that instant would, and say when two runs are in the same
//! state. The run is the simulator's own: verification has no second
//! meaning of a mission.
//!
//! Two states are the same when everything that decides what happens next
//! is equal: every robot's slots, regions, channels, elections and pending
//! events, with each time taken relative to now. A time further in the past
//! than [`Memory`] says (longer than every period, timeout and heartbeat the
//! programs compare against) is the same as any older one, and a time no
//! period or timeout reads is left out, so a mission that repeats itself
//! reaches a state it has been in before and the search ends. What only the
//! trace shows (how many messages a channel dropped, the ids of events) is
//! left out too.

use super::{Event, Held, Message, Queued, Robot, SENSOR_PERIOD_MS, Sim};
use crate::refine::value::Value;
use crate::refine::{
    CallResults, ModeId, RobotProgram, ServiceMachine, ServiceMachineId, SlotSource, StateId,
    StateKind,
};
use crate::sim::scenario::Command;
use crate::sim::trace::TraceEvent;

impl<'p> Sim<'p> {
    /// Runs the instants before `until`; the robots still alive then go on
    /// at `until`, where the world may choose before anything happens.
    pub fn run_to(&mut self, until: i64) {
        self.advance(until, None);
        self.now = self.now.max(until);
    }

    /// Mission ms now.
    pub fn now(&self) -> i64 {
        self.now
    }

    /// The sensor value `port` of robot `r` becomes `text` now: as the
    /// scenario entry `{"at": now, "value": port, "is": text}` would make it.
    pub fn set_sensor(&mut self, r: usize, port: &str, text: &str) {
        let now = self.now;
        let robot = &mut self.robots[r];
        let mut first_sample: Option<i64> = None;
        for (i, slot) in robot.program.control.slots.iter().enumerate() {
            let (SlotSource::Sensor { port: p, task }, Some(series)) =
                (&slot.source, robot.sensor_series[i].as_mut())
            else {
                continue;
            };
            if p != port {
                continue;
            }
            series.push((now, slot.kind.parse(text)));
            let at = robot.sample_at_or_after(task, now);
            first_sample = Some(first_sample.map_or(at, |f| f.min(at)));
        }
        // An idle robot fires when the sample brings the value, as it
        // would have planned had the entry been in the scenario.
        if let Some(at) = first_sample
            && self.robots[r].alive
            && !self.every_firing
        {
            let at = self.grid_at_or_after(r, at);
            if self.robots[r].next_fire.is_none_or(|next| at < next) {
                self.schedule_fire(r, at);
            }
        }
    }

    /// How many calls of `service` robot `r`'s process has done that gave
    /// back results of a scenario's (or [`Sim::set_call_results`]') list.
    pub fn calls_done(&self, r: usize, service: &str) -> usize {
        let robot = &self.robots[r];
        (robot.service_results.iter())
            .rposition(|(s, _)| s == service)
            .map_or(0, |k| robot.calls_done[k] as usize)
    }

    /// What robot `r`'s calls of `service` give back becomes `calls`, per
    /// call of its process in order (the last one again past the list): as
    /// the scenario's `"results"` for the service would make it.
    pub fn set_call_results(&mut self, r: usize, service: &str, calls: CallResults) {
        let robot = &mut self.robots[r];
        let mut all = robot.service_results.to_vec();
        match all.iter().rposition(|(s, _)| s == service) {
            Some(k) => all[k].1 = calls,
            None => {
                all.push((service.to_string(), calls));
                robot.calls_done.push(0);
            }
        }
        robot.service_results = all.into();
    }

    /// The operator sends `key` = `value` to `to` (a robot or a team) now:
    /// the scenario command `{"at": now, "to": to, "value": key, "is": value}`.
    pub fn give_command(&mut self, to: &str, key: &str, value: &str) {
        self.commands.push(Command {
            to: to.to_string(),
            key: key.to_string(),
            value: value.to_string(),
            first: self.now,
            every: None,
            until: self.now,
        });
        let i = self.scenario.operator.len() + self.commands.len() - 1;
        self.schedule(self.now, Event::Operator(i));
    }

    /// The trace written since the last call.
    pub fn take_trace(&mut self) -> Vec<TraceEvent> {
        std::mem::take(&mut self.trace)
    }

    /// Makes room for `events` more trace events at once (a step's trace
    /// grown one event at a time is copied at every doubling).
    pub fn reserve_trace(&mut self, events: usize) {
        self.trace.reserve(events);
    }

    /// How many robots the mission has.
    pub fn robot_count(&self) -> usize {
        self.robots.len()
    }

    /// Whether robot `r` runs (it has neither finished nor been killed).
    pub fn is_running(&self, r: usize) -> bool {
        self.robots[r].alive
    }

    /// The `receive` states robot `r` waits in: (service, state) of each
    /// region of its mode that is at one and has not taken its messages.
    pub fn waiting_receives(&self, r: usize) -> Vec<(ServiceMachineId, StateId)> {
        let robot = &self.robots[r];
        if !robot.alive {
            return Vec::new();
        }
        let m = &robot.program.control;
        robot
            .regions
            .iter()
            .filter(|region| !region.done)
            .filter_map(|region| {
                let s = region.service?;
                let state = m.service(s).states.get(region.pc)?;
                matches!(state.kind, StateKind::Receive { .. })
                    .then_some((s, StateId::new(region.pc)))
            })
            .collect()
    }

    /// From now on robot `r` reaches no other robot and no other robot
    /// reaches it (`None`: every link as the scenario says), as a scenario
    /// partition `[[r]]` from now; messages already under way arrive.
    pub fn isolate(&mut self, r: Option<usize>) {
        // A folding run's heartbeats reach whole teams at once.
        debug_assert!(self.folded.is_none());
        self.isolated = r;
    }

    /// From now until `until`, the messages between robots `a` and `b` are
    /// lost (`delay` `None`) or take `delay` ms longer: the scenario's
    /// `drop` or `delay` fault `[now, until)` of that pair.
    pub fn disturb(&mut self, a: usize, b: usize, until: i64, delay: Option<i64>) {
        debug_assert!(self.folded.is_none());
        let now = self.now;
        self.disturbed.retain(|d| d.until > now);
        self.disturbed
            .push(super::Disturbance { a, b, until, delay });
    }

    /// The `leader(...)` statements robot `r` leads now, as (service,
    /// state) of its program: it runs and its last election there chose it.
    pub fn leads(&self, r: usize) -> Vec<(ServiceMachineId, StateId)> {
        let robot = &self.robots[r];
        if !robot.alive {
            return Vec::new();
        }
        let me = robot.program.self_peer;
        let mut led: Vec<(ServiceMachineId, StateId)> = robot
            .leaders
            .iter()
            .filter(|(_, leader)| **leader == super::Leader::Robot(me))
            .map(|(state, _)| *state)
            .collect();
        led.sort_unstable();
        led
    }

    /// The mode robot `r` is in: an index into its program's modes.
    pub fn mode_of(&self, r: usize) -> Option<ModeId> {
        self.robots[r].current_mode
    }

    /// About how many bytes this state holds of its own: its robots, event
    /// queue and trace, by their lengths and the sizes of their elements
    /// (words and text values are shared between clones and not counted,
    /// nor the allocator's own overhead). What `semo verify`'s memory
    /// budget counts per state it keeps.
    pub fn approx_bytes(&self) -> usize {
        use std::mem::size_of;
        size_of::<Sim>()
            + self.queue.len() * size_of::<Queued>()
            + self.trace.capacity() * size_of::<TraceEvent>()
            + self.commands.len() * size_of::<Command>()
            + self.disturbed.len() * size_of::<super::Disturbance>()
            + self.robots.iter().map(Robot::approx_bytes).sum::<usize>()
    }

    /// The state, as a 128-bit hash of what decides the rest of the run
    /// (see the module's comment): equal states give equal fingerprints.
    pub fn fingerprint(&self, memory: &Memory) -> u128 {
        // The last firing handled (`last_fire`) is left out: it decides
        // only a firing at its own instant, which is past at a step.
        let mut fp = Fingerprint::new(self.now, memory.ms);
        // `semo verify` traces messages, so its runs never fold heartbeats
        // (`engine/folded.rs`): what a robot heard is its own table.
        debug_assert!(self.folded.is_none());
        for (robot, timed) in self.robots.iter().zip(&memory.timed) {
            fp.robot(robot, timed);
        }
        fp.int(self.isolated.map_or(-1, |r| r as i64));
        // The disturbances still under way, their ends relative to now.
        let now = self.now;
        fp.int(self.disturbed.iter().filter(|d| d.until > now).count() as i64);
        for d in self.disturbed.iter().filter(|d| d.until > now) {
            fp.int(d.a as i64);
            fp.int(d.b as i64);
            fp.int(d.until - self.now);
            fp.int(d.delay.unwrap_or(-1));
        }
        // The events still to come, in the order they will be handled;
        // those a robot will ignore (an earlier life's, a firing moved
        // earlier, a stopped call's end) are left out.
        let mut queue: Vec<&Queued> = self.queue.iter().collect();
        queue.sort_unstable_by_key(|q| q.key);
        for queued in queue {
            let (t, order, event) = (queued.time(), queued.order(), &queued.event);
            let alive = |r: usize, epoch: u32| {
                let robot = &self.robots[r];
                robot.alive && robot.epoch == epoch
            };
            // Each event to come as its time, its kind and what it does.
            let comes = |fp: &mut Fingerprint, what: &[i64]| {
                fp.time(t);
                fp.int(order as i64);
                what.iter().for_each(|&v| fp.int(v));
            };
            match event {
                Event::Fire {
                    robot,
                    epoch,
                    token,
                } => {
                    if alive(*robot, *epoch) && self.robots[*robot].fire_token == *token {
                        comes(&mut fp, &[*robot as i64]);
                    }
                }
                Event::GraphTrace { robot, epoch } => {
                    if alive(*robot, *epoch) {
                        comes(&mut fp, &[*robot as i64]);
                    }
                }
                // A message's deliveries at one instant: each its own event.
                Event::Deliver { to, message } => {
                    for &(r, _) in to.iter().filter(|&&(r, epoch)| alive(r, epoch)) {
                        comes(&mut fp, &[r as i64]);
                        fp.message(message);
                    }
                }
                // A folded heartbeat (`engine/folded.rs`): each robot of the
                // sender's team alive and started before it was sent.
                Event::Heartbeat { message, sent, .. } => {
                    let from = message.from.expect("a heartbeat is a robot's");
                    for r in self.fleet.team(from).filter(|&r| r != from) {
                        let robot = &self.robots[r];
                        if robot.alive && robot.epoch_seq < *sent {
                            comes(&mut fp, &[r as i64]);
                            fp.message(message);
                        }
                    }
                }
                Event::ServiceDone {
                    robot,
                    task,
                    generation,
                } => {
                    let state = &self.robots[*robot].tasks[*task].1;
                    if self.robots[*robot].alive && state.busy && state.generation == *generation {
                        comes(&mut fp, &[*robot as i64, *task as i64]);
                    }
                }
                Event::Fault(i) => comes(&mut fp, &[*i as i64]),
                Event::Operator(i) => {
                    comes(&mut fp, &[]);
                    let c = self.command(*i);
                    fp.text(&c.to);
                    fp.text(&c.key);
                    fp.text(&c.value);
                    fp.int(c.every.unwrap_or(-1));
                    fp.time(c.until);
                }
            }
        }
        fp.finish()
    }
}

impl Robot<'_> {
    /// [`Sim::approx_bytes`] of one robot.
    fn approx_bytes(&self) -> usize {
        use std::mem::size_of;
        let held = size_of::<Held>();
        // A hash map's entries, with its control bytes.
        let map = |len: usize, entry: usize| len * (entry + 1);
        size_of::<Robot>()
            + (self.slots.len() + self.library.len()) * held
            + self
                .inbox
                .iter()
                .map(|(queue, _)| {
                    size_of::<(std::collections::VecDeque<Held>, usize)>() + queue.len() * held
                })
                .sum::<usize>()
            + self.behind.len() * (size_of::<Message>() + 16)
            + self.stalled.len()
            + self.dropped.len() * 8
            + self.groups.len() * size_of::<Option<Held>>()
            + self
                .regions
                .iter()
                .map(|r| size_of::<super::Region>() + r.marks.len() * 8 + r.plan.len())
                .sum::<usize>()
            + self.events.len() * 16
            + self.heard.approx_bytes()
            + map(self.sync_pass.len(), 24)
            + map(self.sync_arrived.len(), 24)
            + map(self.leaders.len(), 24)
            + map(self.allocated.len(), 32)
            + self
                .tasks
                .iter()
                .map(|(_, t)| {
                    size_of::<(std::rc::Rc<str>, super::TaskState)>()
                        + t.untaken.as_ref().map_or(0, |a| a.len() * held)
                })
                .sum::<usize>()
            + self
                .sensor_series
                .iter()
                .flatten()
                .map(|series| series.len() * size_of::<(i64, Option<Value>)>())
                .sum::<usize>()
            + self.resources.approx_bytes()
            + self.graphs.approx_bytes()
    }
}

/// Which times of a run the programs read, computed once for a search (the
/// fingerprint is taken at every step of it).
pub struct Memory {
    /// How long ago a time can still matter: longer than every period,
    /// timeout and heartbeat the programs compare against.
    ms: i64,
    /// Per robot, per service of its program: the times its regions read.
    timed: Vec<Vec<Timed>>,
}

impl Memory {
    pub fn of(programs: &[RobotProgram]) -> Memory {
        let mut longest = 1000;
        for program in programs {
            let m = &program.control;
            longest = longest.max(4 * m.heartbeat_ms);
            for region in m.modes.iter().flat_map(|mode| &mode.regions) {
                longest = longest.max(region.timeout_ms.unwrap_or(0));
            }
            for state in m.services.iter().flat_map(|s| &s.states) {
                let t = match &state.kind {
                    StateKind::Receive { timeout_ms, .. }
                    | StateKind::Call { timeout_ms, .. }
                    | StateKind::RunActions { timeout_ms, .. } => timeout_ms.unwrap_or(0),
                    StateKind::GroupSync { timeout_ms, .. } => *timeout_ms,
                    StateKind::LoopTail { period_ms, .. } | StateKind::Repeat { period_ms, .. } => {
                        period_ms.unwrap_or(0)
                    }
                    _ => 0,
                };
                longest = longest.max(t);
            }
        }
        Memory {
            ms: 2 * longest + 1000,
            timed: programs
                .iter()
                .map(|p| p.control.services.iter().map(Timed::of).collect())
                .collect(),
        }
    }
}

/// Which times of a region running a service are compared with a period
/// or a timeout.
#[derive(Clone, Copy, Default)]
struct Timed {
    /// The start of its pass (`repeat(P)`).
    pass: bool,
    /// Its marks (`loop(P)`, `receive`/calls with a timeout, group syncs).
    marks: bool,
}

impl Timed {
    fn of(service: &ServiceMachine) -> Timed {
        let mut timed = Timed::default();
        for state in &service.states {
            match &state.kind {
                StateKind::Repeat {
                    period_ms: Some(_), ..
                } => timed.pass = true,
                StateKind::LoopTail {
                    period_ms: Some(_), ..
                }
                | StateKind::GroupSync { .. } => timed.marks = true,
                StateKind::Receive { timeout_ms, .. }
                | StateKind::Call { timeout_ms, .. }
                | StateKind::RunActions { timeout_ms, .. } => timed.marks |= timeout_ms.is_some(),
                _ => {}
            }
        }
        timed
    }
}

/// The state's 128-bit hash: two 64-bit lanes, each a chain of folded
/// multiplies (the mixing step of wyhash: the 128-bit product of the lane
/// and a word, its halves xored), with different keys and starts. Not
/// cryptographic, and it need not be: the states are the mission's own,
/// not an adversary's. Taken as a random function of the state, two
/// different states of a search of `n` share a fingerprint with odds of
/// about n²/2^129 (10^7 states: about 10^-25), and a collision would merge
/// two states, never report a behaviour that does not exist. SipHash, twice,
/// did the same at ten times the cost (a tenth of a search's time).
struct Fingerprint {
    a: u64,
    b: u64,
    /// Words hashed: folded into the end, so that a prefix differs from
    /// the whole.
    words: u64,
    now: i64,
    memory: i64,
}

/// The lanes' keys and starts: odd, with bits well spread (wyhash's).
const KEY_A: u64 = 0xa076_1d64_78bd_642f;
const KEY_B: u64 = 0xe703_7ed1_a0b4_28db;
const START_A: u64 = 0x8ebc_6af0_9c88_c6e3;
const START_B: u64 = 0x5899_65cc_7537_4cc3;

/// The 128-bit product of `x` and `key`, its halves xored.
#[inline]
fn fold(x: u64, key: u64) -> u64 {
    let product = u128::from(x) * u128::from(key);
    (product as u64) ^ ((product >> 64) as u64)
}

impl Fingerprint {
    fn new(now: i64, memory: i64) -> Fingerprint {
        Fingerprint {
            a: START_A,
            b: START_B,
            words: 0,
            now,
            memory,
        }
    }

    #[inline]
    fn word(&mut self, w: u64) {
        // The lane is xored with the word and a key before the product, so
        // that a word of 0 still moves it (a product of 0 would forget
        // everything before it).
        self.a = fold(self.a ^ w ^ KEY_B, KEY_A);
        self.b = fold(self.b ^ w.rotate_left(32) ^ KEY_A, KEY_B);
        self.words += 1;
    }

    fn int(&mut self, v: i64) {
        self.word(v as u64);
    }

    /// A mission time, relative to now; anything older than `memory` as
    /// the same "long ago".
    fn time(&mut self, t: i64) {
        self.int((t - self.now).max(-self.memory));
    }

    fn text(&mut self, s: &str) {
        // The length, hashed first, tells "a" from "a\0".
        self.int(s.len() as i64);
        crate::fasthash::le_words(s.as_bytes(), |word, _| self.word(word));
    }

    /// A value by its kind and content (no text made: this runs for every
    /// value at every step).
    fn held(&mut self, v: &Held) {
        match v {
            None => self.int(-1),
            Some(Value::Int(i)) => {
                self.int(0);
                self.int(*i);
            }
            Some(Value::Real(r)) => {
                self.int(1);
                self.int(r.to_bits() as i64);
            }
            Some(Value::Bool(b)) => {
                self.int(2);
                self.int(*b as i64);
            }
            Some(Value::Word(w)) => {
                self.int(3);
                self.text(w);
            }
            Some(Value::Text(t)) => {
                self.int(4);
                self.text(t);
            }
        }
    }

    fn message(&mut self, m: &Message) {
        self.int(m.publish as i64);
        self.text(&m.from_team);
        self.text(&m.from_robot);
        self.int(m.from_peer.map_or(-1, |p| p.index() as i64));
        self.text(&m.key);
        self.held(&m.value);
        self.time(m.sent_at);
    }

    /// Robot `robot`, whose services read the times `timed` says.
    fn robot(&mut self, robot: &Robot, timed: &[Timed]) {
        self.int(robot.alive as i64);
        if !robot.alive {
            return;
        }
        self.time(robot.started_at);
        // The grids of its firings (10 ms) and samples (100 ms) run from
        // its start: where now falls on them.
        self.int((self.now - robot.started_at).rem_euclid(SENSOR_PERIOD_MS));
        for v in robot.slots.iter().chain(&robot.library) {
            self.held(v);
        }
        self.int(robot.owner.index() as i64);
        for (queue, _) in &robot.inbox {
            self.int(queue.len() as i64);
            for v in queue {
                self.held(v);
            }
        }
        match &robot.holding {
            None => self.int(-1),
            Some(h) => {
                self.int(robot.firings as i64 - h.mark as i64);
                for (c, v) in &h.pending {
                    self.int(*c as i64);
                    self.held(v);
                }
                self.text(&h.from);
                self.text(&h.key);
            }
        }
        for m in &robot.behind {
            self.message(m);
        }
        for s in &robot.stalled {
            self.int(*s as i64);
        }
        for g in &robot.groups {
            match g {
                None => self.int(-1),
                Some(v) => self.held(v),
            }
        }
        for region in &robot.regions {
            self.int(region.service.map_or(-1, |s| s.index() as i64));
            self.int(region.pc as i64);
            self.int(region.phase as i64);
            self.int(region.action.index() as i64);
            self.int(region.done as i64);
            // A time only a period or a timeout reads: otherwise when a
            // pass started changes nothing, and hashing it would tell apart
            // states that differ only in the phase of their passes.
            if region.timeout_ms > 0 {
                self.time(region.started);
            }
            let timed = region.service.map(|s| timed[s.index()]).unwrap_or_default();
            if timed.pass {
                self.time(region.pass_start);
            }
            self.int(region.timeout_ms);
            if timed.marks {
                for m in &region.marks {
                    self.time(*m);
                }
            }
            self.text(&region.plan);
        }
        self.int(robot.current_mode.map_or(-1, |m| m.index() as i64));
        self.int(robot.pending_mode.map_or(-1, |m| m.index() as i64));
        self.int(robot.events.len() as i64);
        for &(peer, event) in &robot.events {
            self.int(peer.index() as i64);
            self.int(event as i64);
        }
        self.time(robot.last_heartbeat);
        for (peer, h) in robot.heard.iter() {
            self.int(peer.index() as i64);
            self.time(h.seen);
            self.int(h.leads as i64);
            self.int(h.battery.unwrap_or(i64::MIN));
            self.int(h.term);
        }
        self.int(robot.leading as i64);
        self.int(robot.term);
        self.int(robot.term_led);
        self.int(robot.rejoining as i64);
        match robot.fenced {
            None => self.int(-1),
            Some(None) => self.int(-2),
            Some(Some(t)) => self.time(t),
        }
        // A sync state by its positions, as a (peer, point) is.
        let passes = robot.sync_pass.iter();
        let passes = passes.map(|(&(s, pc), &v)| ((s.index(), pc.index()), v));
        let arrived = robot.sync_arrived.iter();
        let arrived = arrived.map(|(&(peer, point), &v)| ((peer.index(), point.index()), v));
        for mut entries in [passes.collect::<Vec<_>>(), arrived.collect()] {
            entries.sort_unstable();
            for ((a, b), v) in entries {
                self.int(a as i64);
                self.int(b as i64);
                self.int(v);
            }
        }
        // A leader as its code: a peer's position, or -1 when fenced.
        let leaders = robot.leaders.iter().map(|(&at, &v)| (at, v.code()));
        // The others as -1: the bytes hashed before `None` stood for them.
        let allocated = robot
            .allocated
            .iter()
            .map(|(&at, &v)| (at, v.map_or(-1, |k| k as i64)));
        for mut entries in [leaders.collect::<Vec<_>>(), allocated.collect()] {
            entries.sort_unstable();
            self.int(entries.len() as i64);
            for ((a, b), v) in entries {
                self.int(a.index() as i64);
                self.int(b.index() as i64);
                self.int(v);
            }
        }
        match robot.group {
            None => self.int(-1),
            Some((rank, size)) => {
                self.int(rank as i64);
                self.int(size as i64);
            }
        }
        for (name, task) in &robot.tasks {
            self.text(name);
            self.int(task.busy as i64);
            match &task.untaken {
                None => self.int(-1),
                Some(args) => {
                    for v in args {
                        self.held(v);
                    }
                }
            }
            self.text(&task.service);
            // Read only while the graph's iteration is under way.
            self.int((task.graph_until - self.now).max(0));
            // What a call gives back, read only when the scenario gives
            // results (a state without them fingerprints as before).
            if robot.service_results.is_empty() {
                continue;
            }
            self.int(task.stopped as i64);
            match &task.reply {
                None => self.int(-1),
                Some(values) => {
                    self.int(values.len() as i64);
                    for v in values.iter() {
                        match v {
                            None => self.int(-1),
                            Some(text) => self.text(text),
                        }
                    }
                }
            }
        }
        // What the later calls give back: the rest of each list from the
        // next call (its last entry once past it), not how many were done.
        for ((_, calls), &n) in robot.service_results.iter().zip(&robot.calls_done) {
            let rest = &calls[(n as usize).min(calls.len().saturating_sub(1))..];
            self.int(rest.len() as i64);
            for values in rest {
                self.int(values.len() as i64);
                for v in values {
                    match v {
                        None => self.int(-1),
                        Some(text) => self.text(text),
                    }
                }
            }
        }
        // The sensor values: the latest entry and when it came (a sample
        // may not have read it yet).
        for series in robot.sensor_series.iter().flatten() {
            match series.last() {
                None => self.int(-1),
                Some((at, v)) => {
                    // Once a sample period has passed, every sample reads it.
                    self.int((at - self.now).max(-2 * SENSOR_PERIOD_MS));
                    self.held(v);
                }
            }
        }
        self.int(robot.chain as i64);
        self.int(robot.next_fire.map_or(i64::MIN, |t| t - self.now));
        self.int(robot.progressed as i64);
        for v in robot.resources.relative(self.now) {
            self.int(v);
        }
        // Most robots run no graph: nothing to write out as text.
        if robot.graphs.is_empty() {
            self.int(-1);
        } else {
            self.text(&robot.graphs.relative(self.now));
        }
    }

    fn finish(self) -> u128 {
        let a = fold(self.a ^ self.words, KEY_A ^ KEY_B);
        let b = fold(self.b ^ self.words.rotate_left(32), KEY_B ^ START_A);
        (u128::from(a) << 64) | u128::from(b)
    }
}

#[cfg(test)]
mod tests {
    use super::Fingerprint;

    fn of(words: &[i64], texts: &[&str]) -> u128 {
        let mut fp = Fingerprint::new(0, 1000);
        for &w in words {
            fp.int(w);
        }
        for t in texts {
            fp.text(t);
        }
        fp.finish()
    }

    #[test]
    fn fingerprints_tell_apart_order_length_and_trailing_zeros() {
        assert_eq!(of(&[1, 2], &["ab"]), of(&[1, 2], &["ab"]));
        assert_ne!(of(&[1, 2], &[]), of(&[2, 1], &[]));
        assert_ne!(of(&[0], &[]), of(&[0, 0], &[]));
        assert_ne!(of(&[], &[]), of(&[0], &[]));
        assert_ne!(of(&[], &["a"]), of(&[], &["a\0"]));
        assert_ne!(of(&[], &["abcdefgh"]), of(&[], &["abcdefgh\0"]));
        assert_ne!(of(&[], &["ab", "c"]), of(&[], &["a", "bc"]));
    }

    /// Every pair of small states that differ in one word, or in two words
    /// swapped, gets its own fingerprint: 200 000 of them, none shared,
    /// and no half of the 128 bits shared either (each lane mixes alone).
    #[test]
    fn near_states_get_distinct_fingerprints_in_both_lanes() {
        let mut seen = std::collections::HashSet::new();
        let mut halves = (
            std::collections::HashSet::new(),
            std::collections::HashSet::new(),
        );
        for a in 0..400i64 {
            for b in 0..250i64 {
                for words in [[a, b, 0, 7], [b - 1000, a, 7, 0]] {
                    let fp = of(&words, &[]);
                    assert!(seen.insert(fp), "{words:?} shares a fingerprint");
                    assert!(halves.0.insert((fp >> 64) as u64), "{words:?}: high lane");
                    assert!(halves.1.insert(fp as u64), "{words:?}: low lane");
                }
            }
        }
    }
}
