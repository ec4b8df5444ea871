//! The discrete-event engine: every robot's [`RobotProgram`] run at once in
//! virtual time, exactly as the generated C runs it (`codegen/control.rs`
//! writes the control task; `codegen/files.rs` the communication, service
//! and library tasks; `codegen/runtime/` the runtime they call). Where the
//! generated program has threads, the simulator has events, ordered by
//! (time, kind, sequence number), so a run is a function of the programs,
//! the scenario and the seed alone.
//!
//! Correspondence (C → here):
//! - `task_control_go` every `CONTROL_PERIOD_MS` → [`Sim::fire`];
//! - a sensor task every `SENSOR_PERIOD_MS`, writing the scenario's latest
//!   value → the value as of the robot's last sensor period ([`Sim::sensor`]);
//! - a service task called with `UFControl_CallTask`, busy for the
//!   scenario's duration → [`Sim::request`] and a `ServiceDone` event (a
//!   graph service's iteration first, its time-triggered tasks' waits
//!   traced when due by `GraphTrace` events: `engine/loops.rs`);
//! - `semo_comm_send` → [`Sim::comm_send`] (the network: latency, loss and
//!   link faults), the receive task's routing → [`Sim::deliver`];
//! - `comm_heard` and `elected` → `heard` and [`Sim::elected`];
//! - the library task's values → `Robot::library`.
//!
//! Idle firings are skipped: a firing that traced nothing and changed no
//! state (`Robot::progressed`) would repeat itself exactly until something
//! it reads changes, so the robot's next firing is put at its next wake-up
//! ([`Sim::wake_up`]: a timer, a sensor sample, a heartbeat) or at the first
//! firing after a message or a call's end reaches it ([`Sim::wake`]). The
//! firing of a control task is on the same 10 ms grid and in the same order
//! among robots as when every firing is simulated ([`Options::every_firing`],
//! the reference the skipping is tested against), so the trace is the same.

use super::loss::LossDraws;
use super::scenario::{Command, DEFAULT_SERVICE_MS, FaultKind, RobotWorld, Scenario};
use super::trace::{Fields, TraceEvent};
use crate::fasthash::FastMap;
use crate::refine::SENSOR_PERIOD_MS;
use crate::refine::graph::CONTROL_PERIOD_MS;
use crate::refine::value::{self, Value};
use crate::refine::{
    ActionId, ActionMachine, AttributeId, Broadcast, ControlMachine, EnclosingArm, Expr,
    IncomingId, LeaderAlgorithm, ModeId, Operand, OutgoingId, PeerId, RobotProgram, RoleKind,
    ServiceMachineId, SlotId, SlotSource, StateId, StateKind, SyncPointId, counted_allocation,
    members_sharing_arms,
};
use fleet::Fleet;
use smallvec::smallvec;
use std::cell::OnceCell;
use std::collections::{BinaryHeap, HashMap, VecDeque};
use std::rc::Rc;

mod battery;
mod counted;
mod explore;
mod fleet;
mod folded;
mod loops;
mod message_races;
mod races;
mod shared;

pub use message_races::{Arrival, Differs, MessageRace, Taken};
pub use races::Race;

pub use explore::Memory;

/// State transitions a region may take in one firing (`control.rs`).
const STEPS_PER_FIRING: usize = 64;
/// What a slot, a channel sample or a message holds: a typed value, or none
/// (`SEMO_NONE`: never set).
type Held = Option<Value>;
/// A sensor value's scenario entries: (at, the value read as its type).
type SensorSeries = Vec<(i64, Option<Value>)>;
/// Default length of a run when neither the caller nor the scenario bounds it.
pub const DEFAULT_UNTIL_MS: i64 = 10 * 60 * 1000;

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Mission ms to run (default: the scenario's `duration`, else 10 min).
    pub until_ms: Option<i64>,
    /// Seeds message loss; a run is a function of programs, scenario and seed.
    pub seed: u64,
    /// Simulates every control firing, idle ones too: the slow reference
    /// against which skipping idle firings is tested (the trace is the same),
    /// and every message sent to each robot through `Sim::link`, which a
    /// network without faults or links of its own skips.
    pub every_firing: bool,
    /// Makes no `send` and `receive` trace events, for a caller whose sink
    /// reads none (a summary without expectations reads only `start`,
    /// `mode`, `finish` and `fault`): they are most of a swarm's trace (a
    /// team of 200 robots hears 199 heartbeats every 200 ms each), and
    /// making them was most of its run. What the robots do, the other
    /// events, `events` and `end_ms` are the same.
    pub untraced_messages: bool,
}

/// The outcome of a run.
#[derive(Clone, Debug)]
pub struct Run {
    /// Every robot, in formation order: (team, robot).
    pub robots: Vec<(String, String)>,
    pub trace: Vec<TraceEvent>,
    /// When the run ended: when its last robot stopped for good (none
    /// running and no restart to come), else the time limit.
    pub end_ms: i64,
    /// Events the engine processed (for the cost per event).
    pub events: u64,
    /// Entries the engine's event queue took (a message's deliveries at
    /// one instant are one entry): with `events`, the run's work, which
    /// follows the robots (`compiler/tests/sim_scaling.rs`). 0 for a
    /// recorded run read back.
    pub queued: u64,
    /// Members of counted groups looked at to find who shares a robot's
    /// arms (`engine/counted.rs`): the groups' work, which follows the
    /// robots too. 0 for a recorded run read back.
    pub members_walked: u64,
}

impl Run {
    /// The run of `programs`' robots: its trace, end and event count.
    pub fn of(programs: &[RobotProgram], trace: Vec<TraceEvent>, end_ms: i64, events: u64) -> Run {
        Run {
            robots: Run::robots_of(programs),
            trace,
            end_ms,
            events,
            queued: 0,
            members_walked: 0,
        }
    }

    /// The robots of a run of `programs`, in formation order: (team, robot).
    pub fn robots_of(programs: &[RobotProgram]) -> Vec<(String, String)> {
        programs
            .iter()
            .map(|p| (p.team.clone(), p.robot.clone()))
            .collect()
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Step {
    Next,
    Wait,
    Done,
}

/// An event of the queue; at equal times faults come first (a robot killed
/// at an instant does nothing in it, one restarted runs in it: the
/// coordinator of `--engine c` kills and starts processes before it grants
/// the instant), then deliveries, service completions, operator commands,
/// and control firings last (a control firing sees everything that arrived
/// by its time).
#[derive(Clone, Debug)]
enum Event {
    /// One message reaching, at one instant, the robots it goes to there
    /// (`to`: each with the epoch it had when the message was sent), in
    /// the order it was sent to them: handled as one delivery event each,
    /// one after the other. One entry of the queue rather than one per
    /// robot: a swarm's messages go to whole teams, and the queue's work
    /// and size grew with every recipient (see [`Sim::comm_send`]).
    Deliver {
        to: Rc<[(usize, u32)]>,
        /// Shared by every robot the message goes to.
        message: Rc<Message>,
    },
    /// A heartbeat reaching its sender's whole team at one instant, kept
    /// once for the robots that take it at once (`engine/folded.rs`):
    /// handled as one delivery event per robot it goes to (`recipients`),
    /// as [`Event::Deliver`] would be.
    Heartbeat {
        message: Rc<Message>,
        recipients: u32,
        /// The queue number its send took.
        sent: u64,
    },
    /// The trace lines of a service graph's iteration under way that are
    /// due now (`loops.rs`: its time-triggered tasks wait for their periods).
    GraphTrace {
        robot: usize,
        epoch: u32,
    },
    ServiceDone {
        robot: usize,
        task: usize,
        generation: u64,
    },
    Fault(usize),
    Operator(usize),
    Fire {
        robot: usize,
        epoch: u32,
        /// Invalidates a firing moved earlier by [`Sim::wake`].
        token: u64,
    },
}

/// An event in the queue under its place in the order: (time, kind, tie)
/// packed into one number, so that the queue compares numbers only.
#[derive(Clone, Debug)]
struct Queued {
    key: u128,
    event: Event,
}

impl Queued {
    fn new(at: i64, event: Event, tie: u64) -> Queued {
        debug_assert!(tie < 1 << 56, "ties are counted from 0 by one");
        // The time's sign bit flipped: times order as their numbers do.
        let time = (at as u64 ^ 1 << 63) as u128;
        let key = time << 64 | (event.order() as u128) << 56 | tie as u128;
        Queued { key, event }
    }

    fn time(&self) -> i64 {
        ((self.key >> 64) as u64 ^ 1 << 63) as i64
    }

    fn order(&self) -> u8 {
        (self.key >> 56) as u8
    }
}

/// The queue's order is the reverse of the keys' (`BinaryHeap` takes the
/// greatest first).
impl Ord for Queued {
    fn cmp(&self, other: &Queued) -> std::cmp::Ordering {
        other.key.cmp(&self.key)
    }
}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Queued) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Queued {
    fn eq(&self, other: &Queued) -> bool {
        self.key == other.key
    }
}

impl Eq for Queued {}

impl Event {
    fn order(&self) -> u8 {
        match self {
            Event::Fault(_) => 0,
            Event::Deliver { .. } | Event::Heartbeat { .. } => 1,
            Event::GraphTrace { .. } => 2,
            Event::ServiceDone { .. } => 3,
            Event::Operator(_) => 4,
            Event::Fire { .. } => 5,
        }
    }
}

/// A received message waiting for room in its channels into the control
/// task, as the runtime's CommReceive waits (`semo_port_offer`): until the
/// control task takes from the channel, or until a control firing begun
/// after `mark` (the firings begun when it started waiting) ends without
/// making room; it is then dropped.
#[derive(Clone)]
struct Holding {
    /// The channels still to write, with the value for each, in order
    /// (inline: a message feeds one channel or two, and the receive task
    /// takes every message through here).
    pending: smallvec::SmallVec<[(usize, Held); 2]>,
    mark: u64,
    from: Rc<str>,
    key: Rc<str>,
}

#[derive(Clone, Debug)]
struct Message {
    publish: bool,
    from_team: Rc<str>,
    from_robot: Rc<str>,
    /// The sender among the peers (operator: `None`).
    from_peer: Option<PeerId>,
    /// The sender among the robots (operator: `None`).
    from: Option<usize>,
    key: Rc<str>,
    value: Held,
    sent_at: i64,
    /// What a heartbeat's text says, read once for all the robots it
    /// reaches (`Heard::parse` of the same text gives the same words).
    said: OnceCell<Heard>,
}

impl Message {
    /// Whether it is a heartbeat to a team whose alive key is `alive_key`:
    /// published under that key, its value text.
    fn is_heartbeat(&self, alive_key: &str) -> bool {
        self.publish && matches!(self.value, Some(Value::Text(_))) && *self.key == *alive_key
    }

    /// What a heartbeat says, as of `now` (`heard_alive`; a value that is
    /// not text says nothing).
    fn heard_at(&self, now: i64) -> Heard {
        let text = match &self.value {
            Some(Value::Text(t)) => t,
            _ => "",
        };
        let said = *self.said.get_or_init(|| Heard::parse(0, text));
        Heard { seen: now, ..said }
    }
}

/// The slots a robot's control task reads its inputs into at each firing
/// (`read_inputs`), found once: a firing reads these, not every slot of
/// its program (a swarm's run spent a fifth of its memory traffic there).
struct Inputs {
    /// The slots fed by a sensor.
    sensors: Vec<usize>,
    /// The shared slots, each with its value's place in the library.
    shared: Vec<(usize, AttributeId)>,
}

impl Inputs {
    fn of(robot: &Robot<'_>) -> Inputs {
        let slots = &robot.program.control.slots;
        Inputs {
            sensors: (0..slots.len())
                .filter(|&i| matches!(slots[i].source, SlotSource::Sensor { .. }))
                .collect(),
            shared: (0..slots.len())
                .filter(|&i| slots[i].source == SlotSource::Shared)
                .filter_map(|i| Some((i, robot.library_index[i]?)))
                .collect(),
        }
    }
}

#[derive(Clone, Debug)]
struct Region {
    service: Option<ServiceMachineId>,
    pc: usize,
    phase: u8,
    /// The current action of the action machine a `RunActions` state runs
    /// (set to its initial action when the state starts).
    action: ActionId,
    done: bool,
    started: i64,
    pass_start: i64,
    timeout_ms: i64,
    marks: Vec<i64>,
    plan: String,
}

#[derive(Clone, Debug, Default)]
struct TaskState {
    busy: bool,
    /// The call's request, written in the firing under way and not yet
    /// taken by the task (`take_requests`): a stop before then cancels it
    /// unseen, as the generated control task's `request` drops a request
    /// still queued when its task was stopped before it fired.
    untaken: Option<Vec<Held>>,
    service: Rc<str>,
    /// Invalidates the completion of a call that was stopped.
    generation: u64,
    /// When the service graph's iteration the call runs ends (its
    /// time-triggered tasks wait for their periods): a stop ends the call
    /// then, not before.
    graph_until: i64,
    /// What the last call gave back when it was done, as the scenario
    /// wrote it (`None`: it was stopped, has not ended yet, or the scenario
    /// gives its service no results): the control task reads it into the
    /// call's result slots.
    reply: Option<Rc<[Option<String>]>>,
    /// The call under way was stopped (it ends when its graph's iteration
    /// does, giving nothing back).
    stopped: bool,
}

/// One robot's running program (one process of `linux-sim`).
#[derive(Clone)]
struct Robot<'p> {
    program: &'p RobotProgram,
    alive: bool,
    /// Counts restarts: events of an earlier incarnation are ignored.
    epoch: u32,
    started_at: i64,
    slots: Vec<Held>,
    /// The library task's values, one per shared key (`lib_<name>.c`).
    library: Vec<Held>,
    /// Per slot: its value's place in `library` (shared slots only).
    library_index: Rc<[Option<AttributeId>]>,
    /// A library value was written since the control task last read the
    /// library into its slots (otherwise every shared slot holds its value
    /// already, and reading them again, comparing text, is skipped).
    library_written: bool,
    /// The owner of the library's globally shared values now (`shared.rs`).
    owner: PeerId,
    /// Per incoming message: the channel to the control task (capacity).
    inbox: Vec<(VecDeque<Held>, usize)>,
    /// The receive task held up by a full channel ([`Holding`]), and the
    /// messages behind it, not yet taken from the transport.
    holding: Option<Holding>,
    behind: VecDeque<Rc<Message>>,
    /// Per incoming message: its channel is stalled (the receive task gave
    /// up waiting for room in it; until the control task next takes from
    /// it, a message that finds it full is dropped at once).
    stalled: Vec<bool>,
    /// Per incoming message: the messages its channel dropped, reported when
    /// the robot stops (the runtime's `dropped` summary).
    dropped: Vec<u64>,
    /// Control firings begun.
    firings: u64,
    /// Per subscribed group: the latest value.
    groups: Vec<Option<Held>>,
    regions: Vec<Region>,
    current_mode: Option<ModeId>,
    pending_mode: Option<ModeId>,
    /// Broadcast events received and not yet looked at by the control task:
    /// (the thrower, the event's index in `events_heard`), in arrival
    /// order, at most `EVENT_QUEUE` (`comm_event_take`).
    events: VecDeque<(PeerId, usize)>,
    last_heartbeat: i64,
    /// Per peer: what its last heartbeat said (`comm_heard`), where it was
    /// heard one by one ([`Sim::heard`] reads it with the folded ones).
    heard: Hearing,
    /// In a run that folds heartbeats (`engine/folded.rs`): since which
    /// folded delivery it takes its team's heartbeats folded, while it does.
    folded_from: Option<u64>,
    /// The queue's number when this process of the robot started: a
    /// message sent before was for an earlier one.
    epoch_seq: u64,
    /// Its receive task takes each heartbeat of its team at once when it
    /// is free ([`Sim::hear_heartbeat`]): it can take them folded.
    heartbeats_at_once: bool,
    /// Whether the last election this robot decided named it (what its
    /// heartbeats say).
    leading: bool,
    /// Its last heartbeat's words (leading, battery, term) and text: sent
    /// again as they are while they hold (most heartbeats say what the
    /// last one said; formatting each one was a tenth of a swarm's run).
    said: Option<(HeartbeatWords, Value)>,
    /// The highest term (leadership epoch, `docs/groups.md`, "Terms") this
    /// robot knows: heard in a heartbeat, or its own.
    term: i64,
    /// The term it leads under (while `leading`): one past the highest it
    /// knew when it began; a higher one heard since deposes it.
    term_led: i64,
    /// Joined the mission under way (restarted after one heartbeat period):
    /// listens first, and follows a live claimant instead of claiming.
    rejoining: bool,
    /// Fenced at an election since it last led (`Some`), with when it heard
    /// a majority again (`Some(Some(t))`: it listens until `t` + the
    /// listening time before it claims).
    fenced: Option<Option<i64>>,
    /// How often this robot reached each `GroupSync` state, by (service, pc).
    sync_pass: FastMap<(ServiceMachineId, StateId), i64>,
    /// The last pass each (peer, sync point) announced (`comm_sync_arrived`).
    sync_arrived: FastMap<(PeerId, SyncPointId), i64>,
    /// The last leader each `LeaderBranch` state saw, by (service, pc).
    leaders: FastMap<(ServiceMachineId, StateId), Leader>,
    /// The group each `GroupAllocate` state last gave this robot, by
    /// (service, pc): its index, or `None` for the others.
    allocated: FastMap<(ServiceMachineId, StateId), Option<usize>>,
    /// The last (rank, size) in the team's group this robot traced
    /// (`semo_group_set`); `None` before its first heartbeat.
    group: Option<(usize, usize)>,
    /// Service tasks by name (the `request_tasks` and those of action commands).
    tasks: Vec<(Rc<str>, TaskState)>,
    has_receiver: bool,
    /// Per slot fed by a sensor: its value's entries (at, value read as the
    /// sensor's type; `None` when the text is not one, which the sensor
    /// task skips: `semo_sim_sensor` is false), by time.
    sensor_series: Vec<Option<SensorSeries>>,
    /// The scenario's battery levels (read only, as `service_ms` and
    /// `library_index`: shared by the clones `semo verify` makes).
    battery: Rc<[(i64, f64)]>,
    /// The scenario's time of each service (the last entry of a name counts).
    service_ms: Rc<[(String, i64)]>,
    /// The scenario's results of each service's calls, in call order.
    service_results: Rc<[(String, crate::refine::CallResults)]>,
    /// How many calls of each service (with results in the scenario) were
    /// done, to pick the next one's results.
    calls_done: Vec<u64>,
    /// Orders the control firings of robots at the same time: robots that
    /// started earlier fire first, as each firing schedules the next.
    chain: u64,
    /// When the control task fires next (`None`: when woken).
    next_fire: Option<i64>,
    /// The token of the firing scheduled at `next_fire`.
    fire_token: u64,
    /// Whether the current firing changed any state (see [`Sim::wake_up`]).
    progressed: bool,
    /// The battery policies' state: levels and levelled sensors' samples.
    resources: battery::Resources,
    /// The channels, time-triggered tasks' starts and due trace lines of
    /// the service graphs run so far (`loops.rs`).
    graphs: loops::GraphState,
}

/// What a heartbeat says: whether its robot leads, its battery, its term.
type HeartbeatWords = (bool, Option<i64>, i64);

/// A link `semo verify` disturbs ([`Sim::disturb`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Disturbance {
    pub a: usize,
    pub b: usize,
    /// Messages sent before this mission ms are disturbed.
    pub until: i64,
    /// `None`: lost; else delayed by this many ms.
    pub delay: Option<i64>,
}

/// Cloned by `semo verify` to branch on the world's choices (`explore.rs`).
#[derive(Clone)]
pub struct Sim<'p> {
    programs: &'p [RobotProgram],
    scenario: &'p Scenario,
    robots: Vec<Robot<'p>>,
    queue: BinaryHeap<Queued>,
    /// Entries put in `queue` so far ([`Run::queued`]).
    queued: u64,
    seq: u64,
    now: i64,
    losses: LossDraws,
    trace: Vec<TraceEvent>,
    /// Next occurrence of each operator command.
    operator_next: Vec<i64>,
    /// Operator commands given while running (`semo verify`'s choices),
    /// numbered after the scenario's: each one as a scenario command given
    /// once at that instant.
    commands: Vec<Command>,
    /// The fleet's tables (names, teams, recipients, worlds, network),
    /// made once and shared by every robot and clone.
    fleet: Rc<Fleet>,
    /// Per robot (program): the slots a firing reads its inputs into.
    inputs: Rc<[Inputs]>,
    /// Per robot (program): its elections ([`ControlMachine::elections`]),
    /// found once: each heartbeat decides them again, and looking for them
    /// walked every state of the program (3% of a swarm's run).
    elections: Rc<[Vec<crate::refine::Election<'p>>]>,
    /// The last control firing handled: (time, chain).
    last_fire: (i64, u64),
    every_firing: bool,
    /// A robot cut off from every other now (`semo verify`'s choice): as
    /// the scenario's partition `[[robot]]` from now on.
    isolated: Option<usize>,
    /// Links `semo verify` disturbs now: the messages between robots `a`
    /// and `b` sent before `until` are lost, or take `delay` ms longer (as
    /// the scenario's `drop` and `delay` faults from the instant chosen).
    disturbed: Vec<Disturbance>,
    /// How many robots run now (the run ends when none does and no restart
    /// is to come): counted, so that no event asks every robot.
    running: usize,
    /// The scenario's restarts still in the queue.
    restarts_due: usize,
    /// The reason of a `drop` for a full channel, made once (a swarm drops
    /// often).
    channel_full: Rc<str>,
    /// `semo verify`'s races, when it watches for them ([`Sim::watch_races`]).
    races: Option<Vec<Race>>,
    /// `semo verify`'s races between robots, when it watches for them
    /// ([`Sim::watch_message_races`]).
    message_races: Option<Box<message_races::Watch>>,
    /// A send's arrivals (instant, order, robot, its epoch), kept between
    /// sends for its room: a send allocates no list of its own.
    arrivals: Vec<(i64, u64, usize, u32)>,
    /// Makes no `send` and `receive` trace events ([`Options::untraced_messages`]).
    untraced_messages: bool,
    /// Trace events not made ([`Sim::untraced_messages`]) so far: a firing
    /// that would have traced one is no idle firing.
    unmade: u64,
    /// The heartbeats kept once for a team, when the run folds them
    /// (`engine/folded.rs`): untraced messages on a plain network.
    folded: Option<folded::Folded>,
    /// Counted groups' walks over their members, shared by the robots
    /// that see their team alike at an instant (`engine/counted.rs`).
    counted: counted::Counted,
    /// The robots a folded heartbeat reaches one by one, kept between
    /// heartbeats for its room (as `arrivals`).
    one_by_one: Vec<usize>,
}

impl<'p> Robot<'p> {
    /// Robot `program` started at `at`, in its `epoch`th process; `world`:
    /// its entry of the scenario; `team`: the peers of its team.
    fn new(
        program: &'p RobotProgram,
        world: Option<&RobotWorld>,
        team: std::ops::Range<usize>,
        at: i64,
        epoch: u32,
    ) -> Robot<'p> {
        let m = &program.control;
        let sensor_series = m
            .slots
            .iter()
            .map(|s| match &s.source {
                SlotSource::Sensor { port, .. } => {
                    let mut series: SensorSeries = world
                        .map(|w| {
                            w.sensors
                                .iter()
                                .filter(|(_, v, _)| v == port)
                                .map(|(at, _, is)| (*at, s.kind.parse(is)))
                                .collect()
                        })
                        .unwrap_or_default();
                    // Stable: equal times keep file order, and the later wins.
                    series.sort_by_key(|(at, _)| *at);
                    Some(series)
                }
                _ => None,
            })
            .collect();
        let mut tasks: Vec<(Rc<str>, TaskState)> = m
            .request_tasks
            .iter()
            .map(|t| (t.as_str().into(), TaskState::default()))
            .collect();
        for am in &m.actions {
            for action in &am.actions {
                for (task, _) in &action.commands {
                    if !tasks.iter().any(|(t, _)| **t == **task) {
                        tasks.push((task.as_str().into(), TaskState::default()));
                    }
                }
            }
        }
        let regions = m.region_count();
        let marks = m.mark_count();
        // Each channel's capacity: the buffer analysis's bound, at least one.
        let inbox = inbox_channels(program)
            .into_iter()
            .map(|c| {
                let capacity = c.and_then(|c| program.capacities.get(c)).copied();
                (VecDeque::new(), capacity.map_or(1, |c| c.max(1) as usize))
            })
            .collect();
        // One value per shared key, as the library task holds them.
        let mut library_keys: Vec<&str> = Vec::new();
        for slot in &m.slots {
            if slot.source == SlotSource::Shared && !library_keys.contains(&slot.key.as_str()) {
                library_keys.push(&slot.key);
            }
        }
        Robot {
            program,
            alive: true,
            epoch,
            started_at: at,
            slots: vec![None; m.slots.len()],
            library: vec![None; library_keys.len()],
            // Read from the program's library (whose attributes are
            // `library_keys`, made by the same rule).
            library_index: m
                .slots
                .iter()
                .map(|s| {
                    let lib = program.library.as_ref()?;
                    (s.source == SlotSource::Shared)
                        .then(|| lib.attributes.iter().position(|k| *k == s.key))
                        .flatten()
                        .map(AttributeId::new)
                })
                .collect(),
            library_written: false,
            owner: program
                .library
                .as_ref()
                .and_then(|l| l.ownership.as_ref())
                .map_or(program.self_peer, |o| o.owners[0]),
            inbox,
            holding: None,
            behind: VecDeque::new(),
            stalled: vec![false; m.incoming.len()],
            dropped: vec![0; m.incoming.len()],
            firings: 0,
            groups: vec![None; m.subscribed.len()],
            regions: vec![
                Region {
                    service: None,
                    pc: 0,
                    phase: 0,
                    // As the C's zeroed region; no action runs before a
                    // `RunActions` state sets its machine's initial one.
                    action: ActionId::new(0),
                    done: true,
                    started: 0,
                    pass_start: 0,
                    timeout_ms: 0,
                    marks: vec![0; marks],
                    plan: String::new(),
                };
                regions
            ],
            current_mode: None,
            pending_mode: None,
            events: VecDeque::new(),
            last_heartbeat: at - m.heartbeat_ms,
            heard: Hearing::new(team),
            folded_from: None,
            epoch_seq: 0,
            // With shared values the receive task first looks for their
            // keys (`Sim::shared_heard`), never the alive key.
            heartbeats_at_once: m.has_receiver() && m.heartbeat,
            leading: false,
            said: None,
            term: 0,
            term_led: 0,
            rejoining: m.heartbeat && at > m.heartbeat_ms,
            fenced: None,
            sync_pass: FastMap::default(),
            sync_arrived: FastMap::default(),
            leaders: FastMap::default(),
            allocated: FastMap::default(),
            group: None,
            tasks,
            has_receiver: m.has_receiver(),
            sensor_series,
            battery: world.map_or_else(|| Rc::from([]), |w| Rc::from(w.battery.as_slice())),
            service_ms: world.map_or_else(|| Rc::from([]), |w| Rc::from(w.services.as_slice())),
            service_results: world.map_or_else(|| Rc::from([]), |w| Rc::from(w.results.as_slice())),
            calls_done: vec![0; world.map_or(0, |w| w.results.len())],
            chain: 0,
            next_fire: None,
            fire_token: 0,
            progressed: false,
            resources: battery::Resources::new(program, at),
            graphs: loops::GraphState::default(),
        }
    }

    fn task_index(&self, task: &str) -> usize {
        self.tasks
            .iter()
            .position(|(t, _)| **t == *task)
            .expect("every called task is listed when the robot starts")
    }
}

/// The sender of `message` among `program`'s peers (robot names are unique
/// in a mission): the sender's own index when the peers are the same
/// mission's, found without reading every robot's name (a heartbeat is
/// heard by the whole team, so a scan made a swarm's run quadratic).
fn sender_peer(program: &RobotProgram, message: &Message) -> Option<PeerId> {
    let named = |p: PeerId| *program.peer(p).1 == *message.from_robot;
    match message.from_peer {
        Some(p) if p.index() < program.peers.len() && named(p) => Some(p),
        _ => PeerId::all(program.peers.len()).find(|&p| named(p)),
    }
}

/// Per incoming message of `program`'s control task: the graph channel
/// that carries it into the control task (by its port), if any.
fn inbox_channels(program: &RobotProgram) -> Vec<Option<usize>> {
    let into_control: HashMap<&str, usize> = program
        .graph
        .channels
        .iter()
        .enumerate()
        .filter(|(_, c)| c.dst.task == crate::refine::graph::CONTROL_TASK)
        .map(|(i, c)| (c.dst.port.as_str(), i))
        .collect();
    program
        .control
        .incoming
        .iter()
        .map(|m| into_control.get(m.port.as_str()).copied())
        .collect()
}

impl<'p> Sim<'p> {
    pub fn new(programs: &'p [RobotProgram], scenario: &'p Scenario, options: &Options) -> Sim<'p> {
        let fleet = Fleet::new(programs, scenario);
        let mut sim = Sim {
            programs,
            scenario,
            robots: (programs.iter().enumerate())
                .map(|(r, p)| Robot::new(p, fleet.world(scenario, r), fleet.team(r), 0, 0))
                .collect(),
            queue: BinaryHeap::new(),
            queued: 0,
            seq: 0,
            now: 0,
            losses: LossDraws::new(options.seed),
            trace: Vec::new(),
            operator_next: scenario.operator.iter().map(|c| c.first).collect(),
            commands: Vec::new(),
            fleet: Rc::new(fleet),
            inputs: Rc::from([]),
            elections: Rc::from([]),
            last_fire: (-1, 0),
            every_firing: options.every_firing,
            isolated: None,
            disturbed: Vec::new(),
            running: programs.len(),
            restarts_due: 0,
            channel_full: "channel full".into(),
            races: None,
            message_races: None,
            arrivals: Vec::new(),
            untraced_messages: options.untraced_messages,
            unmade: 0,
            folded: None,
            counted: counted::Counted::default(),
            one_by_one: Vec::new(),
        };
        // Peers are the mission's robots, in order, for every robot.
        let peers_are_robots = (programs.iter().enumerate())
            .all(|(r, p)| p.self_peer.index() == r && p.peers.len() == programs.len());
        if options.untraced_messages && sim.plain_network() && peers_are_robots {
            sim.folded = Some(folded::Folded::new(programs.len()));
        }
        sim.inputs = sim.robots.iter().map(Inputs::of).collect();
        sim.elections = (programs.iter())
            .map(|p| p.control.elections().collect())
            .collect();
        for r in 0..programs.len() {
            sim.start_folding(r);
            sim.start(r);
        }
        for (i, c) in scenario.operator.iter().enumerate() {
            if c.first <= c.until {
                sim.schedule(c.first, Event::Operator(i));
            }
        }
        for (i, fault) in scenario.faults.iter().enumerate() {
            if let FaultKind::Kill { at, .. } | FaultKind::Restart { at, .. } = fault.kind {
                sim.schedule(at, Event::Fault(i));
            }
            if let FaultKind::Restart { .. } = fault.kind {
                sim.restarts_due += 1;
            }
        }
        sim
    }

    fn schedule(&mut self, at: i64, event: Event) {
        self.seq += 1;
        let tie = match event {
            Event::Fire { robot, .. } => self.robots[robot].chain,
            _ => self.seq,
        };
        self.queue.push(Queued::new(at, event, tie));
        self.queued += 1;
    }

    /// Puts robot `r`'s next control firing at `at` (a time of its grid).
    fn schedule_fire(&mut self, r: usize, at: i64) {
        let robot = &mut self.robots[r];
        robot.fire_token += 1;
        robot.next_fire = Some(at);
        let (epoch, token) = (robot.epoch, robot.fire_token);
        self.schedule(
            at,
            Event::Fire {
                robot: r,
                epoch,
                token,
            },
        );
    }

    fn emit(&mut self, robot: usize, event: &'static str, fields: Fields) {
        self.trace.push(TraceEvent {
            t: self.now,
            robot,
            event,
            fields,
            value: None,
            sent_at: None,
        });
    }

    fn start(&mut self, r: usize) {
        let p = self.robots[r].program;
        self.emit(
            r,
            "start",
            smallvec![
                ("team", p.team.as_str().into()),
                ("type", p.robot_type.as_str().into()),
                ("mission", p.mission.as_str().into()),
            ],
        );
        self.seq += 1;
        self.robots[r].chain = self.seq;
        self.schedule_fire(r, self.now);
    }

    /// Runs until `until` mission ms or until every robot has stopped. The
    /// run is the instants before `until`: at `until` the robots still
    /// alive stop before anything else of that instant happens (as the
    /// generated program's main thread, first in the turns, stops it).
    pub fn run(self, options: &Options) -> Run {
        let mut trace = Vec::new();
        let mut run = self.run_into(options, &mut |e| trace.push(e));
        run.trace = trace;
        run
    }

    /// [`Sim::run`] giving each trace event to `sink` as it is made, in
    /// the trace's order, and keeping none: the run's `trace` is empty, so
    /// that a run's memory follows its robots, not its length.
    pub fn run_into(mut self, options: &Options, sink: &mut dyn FnMut(TraceEvent)) -> Run {
        let until = options
            .until_ms
            .or(self.scenario.duration_ms)
            .unwrap_or(DEFAULT_UNTIL_MS);
        let events = self.advance(until, Some(sink));
        if self.running > 0 || self.restarts_due > 0 {
            // Still running, or every robot down with a restart to come
            // after the run's end: the run lasted to its end.
            self.now = until;
        }
        for r in 0..self.robots.len() {
            if self.robots[r].alive {
                self.stop(r);
            }
        }
        self.trace.drain(..).for_each(&mut *sink);
        Run {
            queued: self.queued,
            members_walked: self.counted.walked,
            ..Run::of(self.programs, Vec::new(), self.now, events)
        }
    }

    /// Handles the events of the instants before `until`, or until every
    /// robot has stopped for good; returns how many it handled. With a
    /// `sink`, the trace each event makes goes to it after the event.
    fn advance(&mut self, until: i64, mut sink: Option<&mut dyn FnMut(TraceEvent)>) -> u64 {
        let mut events = 0u64;
        while let Some(t) = self.queue.peek().map(Queued::time) {
            if t >= until {
                break;
            }
            let Some(Queued { event, .. }) = self.queue.pop() else {
                break;
            };
            self.now = t;
            // A message's deliveries at one instant count one event each.
            events += match &event {
                Event::Deliver { to, .. } => to.len() as u64,
                Event::Heartbeat { recipients, .. } => u64::from(*recipients),
                _ => 1,
            };
            self.handle(event);
            if let Some(sink) = sink.as_mut() {
                self.trace.drain(..).for_each(&mut **sink);
            }
            if self.running == 0 && self.restarts_due == 0 {
                break;
            }
        }
        events
    }

    fn handle(&mut self, event: Event) {
        match event {
            Event::Fire {
                robot,
                epoch,
                token,
            } => {
                let r = &self.robots[robot];
                if r.alive && r.epoch == epoch && r.fire_token == token {
                    self.last_fire = (self.now, r.chain);
                    self.robots[robot].progressed = false;
                    self.robots[robot].firings += 1;
                    let traced = self.trace.len() as u64 + self.unmade;
                    self.fire(robot);
                    if self.robots[robot].alive {
                        self.take_requests(robot);
                        let idle = !self.every_firing
                            && !self.robots[robot].progressed
                            && self.trace.len() as u64 + self.unmade == traced;
                        match if idle {
                            self.wake_up(robot)
                        } else {
                            Some(self.now + CONTROL_PERIOD_MS)
                        } {
                            Some(at) => self.schedule_fire(robot, at),
                            None => self.robots[robot].next_fire = None,
                        }
                        self.release(robot, true);
                    }
                }
            }
            Event::GraphTrace { robot, epoch } => {
                let r = &self.robots[robot];
                if r.alive && r.epoch == epoch {
                    self.graph_trace(robot);
                }
            }
            Event::ServiceDone {
                robot,
                task,
                generation,
            } => {
                let state = &self.robots[robot].tasks[task].1;
                if self.robots[robot].alive && state.busy && state.generation == generation {
                    let done = !state.stopped;
                    self.end_call(robot, task, done);
                    self.wake(robot);
                }
            }
            // Each recipient in turn, as if each had its own place in the
            // queue: they were scheduled one after the other, so nothing
            // else comes between them. (A delivery stops no robot: the run
            // cannot end among them.)
            Event::Deliver { to, message } => {
                if self.message_races.is_some() {
                    self.look_for_message_races(&to, &message);
                }
                self.deliver_all(&to, &message)
            }
            Event::Heartbeat { message, sent, .. } => self.deliver_folded(&message, sent),
            Event::Operator(i) => self.operator(i),
            Event::Fault(i) => self.fault(i),
        }
    }

    /// Operator command `i`: the scenario's, then those given while running.
    fn command(&self, i: usize) -> &Command {
        let given = self.scenario.operator.len();
        self.scenario
            .operator
            .get(i)
            .unwrap_or_else(|| &self.commands[i - given])
    }

    fn operator(&mut self, i: usize) {
        let command = self.command(i).clone();
        let message = Rc::new(Message {
            publish: false,
            from_team: "USER".into(),
            from_robot: "USER".into(),
            from_peer: None,
            from: None,
            key: command.key.as_str().into(),
            value: Some(Value::text(&command.value)),
            sent_at: self.now,
            said: OnceCell::new(),
        });
        // The robots of the team or the robot named, in formation order.
        let fleet = self.fleet.clone();
        for &r in fleet
            .recipients(&command.to)
            .into_iter()
            .flat_map(|to| to.iter())
        {
            if self.robots[r].alive {
                self.deliver(r, &message);
            }
        }
        if let Some(every) = command.every {
            let next = self.operator_next[i] + every;
            if next <= command.until {
                self.operator_next[i] = next;
                self.schedule(next, Event::Operator(i));
            }
        }
    }

    fn fault(&mut self, i: usize) {
        match &self.scenario.faults[i].kind {
            FaultKind::Kill { robot, .. } => {
                if let Some(r) = self.index_of(robot) {
                    self.kill(r);
                }
            }
            FaultKind::Restart { robot, .. } => {
                self.restarts_due -= 1;
                if let Some(r) = self.index_of(robot) {
                    self.restart(r);
                }
            }
            _ => {}
        }
    }

    /// Robot `r` is killed now, if it runs: without a word (no `stop`).
    pub(crate) fn kill(&mut self, r: usize) {
        if self.robots[r].alive {
            self.robots[r].alive = false;
            self.stop_folding(r);
            self.running -= 1;
            self.emit(r, "fault", smallvec![("fault", "kill".into())]);
        }
    }

    /// Robot `r` starts again now, if it does not run: a new process, from
    /// its default mode.
    pub(crate) fn restart(&mut self, r: usize) {
        if !self.robots[r].alive {
            let epoch = self.robots[r].epoch + 1;
            let (world, team) = (self.fleet.world(self.scenario, r), self.fleet.team(r));
            let program = self.robots[r].program;
            self.robots[r] = Robot::new(program, world, team, self.now, epoch);
            self.robots[r].epoch_seq = self.seq;
            self.start_folding(r);
            self.running += 1;
            self.emit(r, "fault", smallvec![("fault", "restart".into())]);
            self.start(r);
        }
    }

    fn index_of(&self, robot: &str) -> Option<usize> {
        self.fleet.index_of(robot)
    }

    /// The robot stops (its mission ended, or the run did): the calls under
    /// way end with it, as the runtime's task threads end them.
    fn stop(&mut self, r: usize) {
        for t in 0..self.robots[r].tasks.len() {
            let state = &mut self.robots[r].tasks[t].1;
            if state.untaken.take().is_some() {
                state.busy = false;
            } else if state.busy {
                self.end_call(r, t, false);
            }
        }
        self.robots[r].alive = false;
        self.stop_folding(r);
        self.running -= 1;
        self.trace_dropped(r);
        self.emit(r, "stop", Fields::new());
    }

    /// The runtime's summary at stop (`semo__trace_dropped_samples`): per
    /// channel into the control task, in the graph's order, how many
    /// messages it dropped.
    fn trace_dropped(&mut self, r: usize) {
        let program = self.robots[r].program;
        let mut dropped: Vec<(usize, u64)> = inbox_channels(program)
            .into_iter()
            .zip(&self.robots[r].dropped)
            .filter_map(|(c, &count)| Some((c?, count)).filter(|_| count > 0))
            .collect();
        dropped.sort_unstable();
        for (c, count) in dropped {
            let c = &program.graph.channels[c];
            let channel = format!(
                "{}.{}->{}.{}",
                c.src.task, c.src.port, c.dst.task, c.dst.port
            );
            let fields = smallvec![
                ("channel", channel.into()),
                ("count", count.to_string().into()),
            ];
            self.emit(r, "dropped", fields);
        }
    }

    // ------------------------------------------------------------ values

    fn value(&self, r: usize, op: &Operand) -> Held {
        self.value_ref(r, op).cloned()
    }

    /// An operand's value without copying it (conditions are read every firing).
    fn value_ref<'a>(&'a self, r: usize, op: &'a Operand) -> Option<&'a Value> {
        match op {
            Operand::Slot(s) => self.robots[r].slots[s.index()].as_ref(),
            Operand::Literal(v) => Some(v),
        }
    }

    fn eval(&self, r: usize, e: &Expr) -> bool {
        match e {
            Expr::Or(a, b) => self.eval(r, a) || self.eval(r, b),
            Expr::And(a, b) => self.eval(r, a) && self.eval(r, b),
            Expr::Not(a) => !self.eval(r, a),
            Expr::Bool(b) => *b,
            Expr::Truthy(o) => value::truthy(self.value_ref(r, o)),
            Expr::Compare(a, op, b, compared) => {
                value::holds(self.value_ref(r, a), *op, self.value_ref(r, b), *compared)
            }
        }
    }

    /// `store`: the slot, and the library for shared information.
    fn store(&mut self, r: usize, slot: SlotId, value: Held) {
        let robot = &mut self.robots[r];
        robot.progressed = true;
        let library = robot.library_index[slot.index()];
        if let Some(k) = library {
            robot.library[k.index()].clone_from(&value);
            robot.library_written = true;
        }
        robot.slots[slot.index()].clone_from(&value);
        if let Some(k) = library {
            self.shared_set(r, k, &value);
        }
    }

    /// Reads the latest sensor samples (the scenario's latest value at the
    /// robot's last sensor period) and the shared information into the
    /// slots (`read_inputs`); a slot is written only when its value changed.
    fn read_inputs(&mut self, r: usize) {
        let now = self.now;
        // The getters of globally shared values ask who owns them first.
        self.current_owner(r);
        let robot = &mut self.robots[r];
        let program = robot.program;
        robot.resources.advance(now);
        let inputs = &self.inputs[r];
        for &i in inputs.sensors.iter() {
            let Some(series) = &robot.sensor_series[i] else {
                continue;
            };
            if series.is_empty() && robot.battery.is_empty() {
                continue; // nothing to read (the slot's program not looked at)
            }
            let s = &program.control.slots[i];
            let SlotSource::Sensor { port, task } = &s.source else {
                continue;
            };
            let sampled = robot.sampled_at(task, now);
            let n = series.partition_point(|(at, _)| *at <= sampled);
            let read = if n > 0 {
                series[n - 1].1.clone()
            } else if port == "BATTERY"
                && let Some(level) = battery_level(&robot.battery, sampled)
            {
                s.kind.parse(&format!("{}", level.round()))
            } else {
                None
            };
            if let Some(v) = read
                && robot.slots[i].as_ref() != Some(&v)
            {
                robot.slots[i] = Some(v);
                robot.progressed = true;
            }
        }
        // Unless the library was written since, every shared slot holds
        // its value already.
        if std::mem::take(&mut robot.library_written) {
            for &(i, k) in inputs.shared.iter() {
                if robot.slots[i] != robot.library[k.index()] {
                    robot.slots[i].clone_from(&robot.library[k.index()]);
                    robot.progressed = true;
                }
            }
        }
    }

    // ---------------------------------------------------- communication

    /// `semo_comm_send`: traced, then to every other robot of `to` (team or
    /// robot name) through the network; `USER` only traces.
    fn comm_send(&mut self, r: usize, to: Rc<str>, publish: bool, key: Rc<str>, value: Held) {
        if self.untraced_messages {
            self.unmade += 1;
        } else {
            self.trace.push(TraceEvent {
                t: self.now,
                robot: r,
                event: "send",
                fields: smallvec![("to", to.clone()), ("key", key.clone())],
                value: Some(("value", value.clone())),
                sent_at: None,
            });
        }
        if &*to == "USER" {
            return;
        }
        let program = self.robots[r].program;
        let fleet = self.fleet.clone();
        let Some(targets) = fleet.recipients(&to) else {
            return;
        };
        let message = Rc::new(Message {
            publish,
            from_team: fleet.names[r].team.clone(),
            from_robot: fleet.names[r].heartbeat.clone(),
            from_peer: Some(program.self_peer),
            from: Some(r),
            key,
            value,
            sent_at: self.now,
            said: OnceCell::new(),
        });
        // Each recipient in turn takes the next number of the queue's
        // order; those reached at the same instant share one entry, under
        // the first one's number (nothing else is numbered between them).
        if self.plain_network() {
            // Every link the network's: the message reaches every
            // recipient at one instant, each as `link` would say.
            let at = self.now + self.scenario.network.latency_ms;
            if self.folds(r, targets, &message) {
                // `folds`: the targets are the sender's team, the sender
                // among them (counting them was a walk over the team per
                // heartbeat, a third of 800 robots' run).
                let recipients = targets.len() - 1;
                debug_assert_eq!(recipients, targets.iter().filter(|&&d| d != r).count());
                if recipients > 0 {
                    let sent = self.seq + 1;
                    self.seq += recipients as u64;
                    let recipients = recipients as u32;
                    let event = Event::Heartbeat {
                        message,
                        recipients,
                        sent,
                    };
                    self.queue.push(Queued::new(at, event, sent));
                    self.queued += 1;
                }
                return;
            }
            let robots = &self.robots;
            let to: Rc<[(usize, u32)]> = (targets.iter())
                .filter(|&&dst| dst != r)
                .map(|&dst| (dst, robots[dst].epoch))
                .collect();
            if !to.is_empty() {
                let tie = self.seq + 1;
                self.seq += to.len() as u64;
                self.queue
                    .push(Queued::new(at, Event::Deliver { to, message }, tie));
                self.queued += 1;
            }
            return;
        }
        let mut arrivals = std::mem::take(&mut self.arrivals);
        for &dst in targets.iter() {
            if dst == r {
                continue;
            }
            let Some(latency) = self.link(r, dst, &message.key) else {
                continue;
            };
            self.seq += 1;
            arrivals.push((self.now + latency, self.seq, dst, self.robots[dst].epoch));
        }
        // By instant, each instant's robots in the order they were sent
        // to (the numbers are distinct), then one entry per instant: one
        // pass, not one over the arrivals per instant. Mostly sorted already
        // (one latency), and sorted in place (a stable sort takes room).
        arrivals.sort_unstable_by_key(|&(at, tie, _, _)| (at, tie));
        for instant in arrivals.chunk_by(|a, b| a.0 == b.0) {
            let (at, tie, _, _) = instant[0];
            let to: Rc<[(usize, u32)]> = instant.iter().map(|&(_, _, dst, e)| (dst, e)).collect();
            let message = message.clone();
            self.queue
                .push(Queued::new(at, Event::Deliver { to, message }, tie));
            self.queued += 1;
        }
        arrivals.clear();
        self.arrivals = arrivals;
    }

    /// Whether every message now takes the network's latency and none is
    /// lost ([`Sim::link`] of every pair): no link of its own, no loss, no
    /// fault of the network, none of `semo verify`'s disturbances.
    fn plain_network(&self) -> bool {
        !self.every_firing
            && self.fleet.plain_network()
            && self.scenario.network.loss <= 0.0
            && self.isolated.is_none()
            && self.disturbed.is_empty()
    }

    /// The latency of a message from `a` to `b` now, or `None` when it is lost.
    fn link(&mut self, a: usize, b: usize, key: &str) -> Option<i64> {
        let (na, nb) = (&self.programs[a].robot, &self.programs[b].robot);
        let network = &self.scenario.network;
        let link = self.fleet.link(a, b).map(|l| &network.links[l]);
        let mut latency = link
            .and_then(|l| l.latency_ms)
            .unwrap_or(network.latency_ms);
        let loss = link.and_then(|l| l.loss).unwrap_or(network.loss);
        let now = self.now;
        if self.isolated.is_some_and(|i| i == a || i == b) {
            return None;
        }
        for d in &self.disturbed {
            if ((d.a, d.b) == (a, b) || (d.a, d.b) == (b, a)) && now < d.until {
                match d.delay {
                    None => return None,
                    Some(by) => latency += by,
                }
            }
        }
        latency += self.fleet.faults(a, b, now)?;
        if self.losses.lost(na, nb, key, loss) {
            return None;
        }
        Some(latency)
    }

    /// A message reaches the robots `to` at one instant (each with the epoch
    /// it had when the message was sent), each in turn. A heartbeat, most
    /// of a swarm's messages, reaching a robot whose receive task takes it
    /// at once is heard here without the receive task's general path
    /// ([`Sim::take_in`]: the same trace event and the same [`Hearing`]).
    fn deliver_all(&mut self, to: &[(usize, u32)], message: &Rc<Message>) {
        for &(r, epoch) in to {
            let robot = &self.robots[r];
            if robot.alive && robot.epoch == epoch {
                self.deliver_one(r, message);
            }
        }
    }

    /// `message` reaches robot `r` (alive, the process it was sent to).
    fn deliver_one(&mut self, r: usize, message: &Rc<Message>) {
        let robot = &self.robots[r];
        let at_once = robot.heartbeats_at_once
            && robot.holding.is_none()
            && message.is_heartbeat(&self.fleet.names[r].alive_key);
        if at_once {
            self.trace_receive(r, message);
            self.hear_heartbeat(r, message);
        } else {
            self.deliver(r, message);
        }
    }

    /// A message reaches the robot: the receive task takes it, unless it is
    /// held up by a full channel (then it waits behind, in order).
    fn deliver(&mut self, r: usize, message: &Rc<Message>) {
        if !self.robots[r].has_receiver {
            return; // no receive task reads the inbox
        }
        if self.robots[r].holding.is_some() {
            self.robots[r].behind.push_back(message.clone());
            return;
        }
        self.take_in(r, message);
        self.release(r, false);
    }

    /// The receive task held up: writes what now fits into the channels
    /// and, at the end of a control firing (`firing_ended`) begun since it
    /// started waiting, drops what does not (a `drop` event; the channel
    /// is then stalled, and drops at once until its next take); then takes
    /// the messages behind, in order, until one is held up again. Waiting
    /// wakes the control task, as `semo_port_offer` does.
    fn release(&mut self, r: usize, firing_ended: bool) {
        self.take_behind(r, firing_ended);
        // Held up, it takes heartbeats one by one; free, folded again.
        let robot = &self.robots[r];
        debug_assert!(
            robot.holding.is_some() || robot.behind.is_empty(),
            "a free receive task takes every message behind"
        );
        let folds = robot.heartbeats_at_once && robot.holding.is_none();
        if self.folded.is_some() && folds != robot.folded_from.is_some() {
            if folds {
                self.start_folding(r);
            } else {
                self.stop_folding(r);
            }
        }
    }

    /// [`Sim::release`]'s work: the channels written, the messages behind taken.
    fn take_behind(&mut self, r: usize, firing_ended: bool) {
        loop {
            let robot = &mut self.robots[r];
            let Some(holding) = &mut robot.holding else {
                // Free: it takes the messages behind, in order, until one
                // is held up again (CommReceive's loop).
                let Some(next) = robot.behind.pop_front() else {
                    return;
                };
                self.take_in(r, &next);
                continue;
            };
            let give_up = firing_ended && robot.firings > holding.mark;
            let (mut queued, mut dropped) = (false, false);
            while let Some((channel, _)) = holding.pending.first() {
                let (queue, capacity) = &mut robot.inbox[*channel];
                if queue.len() < *capacity {
                    let (_, value) = holding.pending.remove(0);
                    queue.push_back(value);
                    queued = true;
                } else if give_up || robot.stalled[*channel] {
                    robot.stalled[*channel] = true;
                    robot.dropped[*channel] += 1;
                    holding.pending.remove(0);
                    dropped = true;
                } else {
                    break;
                }
            }
            let (from, key) = (holding.from.clone(), holding.key.clone());
            let waits = !holding.pending.is_empty();
            if dropped {
                let fields = smallvec![
                    ("from", from),
                    ("key", key),
                    ("reason", self.channel_full.clone()),
                ];
                self.emit(r, "drop", fields);
            }
            // Only a `receive` waits for a message: waking it also lets a
            // waiting writer's decisive firing come at once.
            if queued || waits {
                self.wake(r);
            }
            if waits {
                return;
            }
            self.robots[r].holding = None;
        }
    }

    /// The receive task: traced, then a heartbeat, a published value for a
    /// group, or a message for the control task's channels (held up while
    /// one is full: [`Sim::release`]).
    fn take_in(&mut self, r: usize, message: &Message) {
        self.trace_receive(r, message);
        if self.shared_heard(r, message) {
            return;
        }
        let robot = &mut self.robots[r];
        let m = &robot.program.control;
        // Keys and names compare as their interned `Rc`s (`Names`).
        let names = &self.fleet.names[r];
        if m.heartbeat && message.publish && message.key == names.alive_key {
            self.hear_heartbeat(r, message);
            return;
        }
        // `heard_sync`: an arrival at a group statement; wakes the control task.
        if !m.sync_points.is_empty() && message.key == names.sync_key {
            // Its value is text ("<point> <pass>"); anything else says nothing.
            let text = match &message.value {
                Some(Value::Text(t)) => t,
                _ => "",
            };
            let mut words = text.split(' ');
            let number = |w: Option<&str>| w.and_then(|w| w.parse::<i64>().ok()).unwrap_or(0);
            let (offset, pass) = (number(words.next()), number(words.next()));
            let peer = sender_peer(robot.program, message);
            let point = m.sync_points.iter().position(|&p| p as i64 == offset);
            let point = point.map(SyncPointId::new);
            if let (Some(peer), Some(point)) = (peer, point) {
                let last = robot.sync_arrived.entry((peer, point)).or_insert(0);
                *last = (*last).max(pass);
            }
            self.wake(r);
            return;
        }
        // `heard_event`: a broadcast event of its team.
        if !m.events_heard.is_empty()
            && !message.publish
            && message.key == names.event_key
            && message.from_team == names.team
        {
            self.hear_event(r, message);
            return;
        }
        if !m.subscribed.is_empty() && message.publish {
            for (i, g) in names.subscribed.iter().enumerate() {
                if *g == message.key {
                    robot.groups[i] = Some(message.value.clone());
                }
            }
            return;
        }
        // A value of another type than the key's is refused
        // (`semo_value_coerce`); text is read as the type.
        let mut pending = smallvec::SmallVec::new();
        let mut rejected = false;
        for (i, (incoming, (from_team, key))) in m.incoming.iter().zip(&names.incoming).enumerate()
        {
            if *from_team == message.from_team && *key == message.key {
                let kind = &m.slots[incoming.slot.index()].kind;
                let Some(value) = (match &message.value {
                    Some(v) => kind.coerce(v).map(Some),
                    None => Some(None),
                }) else {
                    rejected = true;
                    continue;
                };
                pending.push((i, value));
            }
        }
        if !pending.is_empty() {
            robot.holding = Some(Holding {
                pending,
                mark: robot.firings,
                from: message.from_team.clone(),
                key: message.key.clone(),
            });
        }
        if rejected {
            let fields = smallvec![
                ("key", message.key.clone()),
                ("reason", "not a value of its type".into()),
            ];
            self.emit(r, "reject", fields);
        }
    }

    /// The receive task's trace event of `message` (unless
    /// [`Options::untraced_messages`]).
    fn trace_receive(&mut self, r: usize, message: &Message) {
        if self.untraced_messages {
            self.unmade += 1;
            return;
        }
        self.trace.push(TraceEvent {
            t: self.now,
            robot: r,
            event: "receive",
            fields: smallvec![
                ("from", message.from_team.clone()),
                ("from_robot", message.from_robot.clone()),
                ("key", message.key.clone()),
            ],
            value: Some(("value", message.value.clone())),
            sent_at: Some(message.sent_at),
        });
    }

    /// A heartbeat taken by robot `r`'s receive task (`heard_alive`): what
    /// its sender's says, as of now.
    fn hear_heartbeat(&mut self, r: usize, message: &Message) {
        let heard = message.heard_at(self.now);
        let robot = &mut self.robots[r];
        if let Some(peer) = sender_peer(robot.program, message) {
            robot.heard.set(peer, heard);
            robot.term = robot.term.max(heard.term);
        }
    }

    // ------------------------------------------------------ service tasks

    /// `request`: a service task starts one call unless it is busy.
    fn request(&mut self, r: usize, task: &str, service: &str, args: Vec<Held>) -> bool {
        let t = self.robots[r].task_index(task);
        if self.robots[r].tasks[t].1.busy {
            return false;
        }
        let state = &mut self.robots[r].tasks[t].1;
        state.busy = true;
        state.reply = None;
        state.untaken = Some(args);
        if *state.service != *service {
            state.service = service.into();
        }
        state.generation += 1;
        true
    }

    /// After a firing: the tasks it called take their requests (the C
    /// task's thread runs after the control task's firing), trace the
    /// call and start the service.
    fn take_requests(&mut self, r: usize) {
        for t in 0..self.robots[r].tasks.len() {
            if let Some(args) = self.robots[r].tasks[t].1.untaken.take() {
                self.take(r, t, args);
            }
        }
    }

    fn take(&mut self, r: usize, t: usize, args: Vec<Held>) {
        let (task, state) = &self.robots[r].tasks[t];
        let (task, service, generation) = (task.clone(), state.service.clone(), state.generation);
        let arg = match args.first() {
            Some(v) => v.clone(),
            None => Some(Value::text("")),
        };
        let robot = &self.robots[r];
        let ms = robot
            .service_ms
            .iter()
            .rev()
            .find(|(s, _)| **s == *service)
            .map_or(DEFAULT_SERVICE_MS, |(_, ms)| *ms)
            * robot.speed_scale(&task);
        self.trace.push(TraceEvent {
            t: self.now,
            robot: r,
            event: "call_start",
            fields: smallvec![("task", task.clone()), ("service", service)],
            value: Some(("arg", arg.clone())),
            sent_at: None,
        });
        if !args.is_empty() {
            self.trace.push(TraceEvent {
                t: self.now,
                robot: r,
                event: "actuate",
                fields: smallvec![("task", task.clone())],
                value: Some(("value", arg)),
                sent_at: None,
            });
        }
        // The service's time counts from the end of the graph's iteration.
        let until = self.run_graph(r, &task);
        self.robots[r].tasks[t].1.graph_until = until;
        self.schedule(
            until + ms,
            Event::ServiceDone {
                robot: r,
                task: t,
                generation,
            },
        );
    }

    /// The call under way ends; `done`: it was not stopped, so it gives
    /// back the scenario's results for it (the `n`th done call of its
    /// service the `n`th entry, the last one past the list).
    fn end_call(&mut self, r: usize, t: usize, done: bool) {
        let robot = &mut self.robots[r];
        let service = robot.tasks[t].1.service.clone();
        let reply = match robot
            .service_results
            .iter()
            .rposition(|(s, _)| **s == *service)
        {
            Some(k) if done => {
                let calls = &robot.service_results[k].1;
                let n = robot.calls_done[k] as usize;
                robot.calls_done[k] += 1;
                let values = calls.get(n).or(calls.last()).map_or(&[][..], Vec::as_slice);
                Some(Rc::from(values))
            }
            // Nothing in the scenario: every result none.
            _ => None,
        };
        let (task, state) = &mut robot.tasks[t];
        state.busy = false;
        state.stopped = false;
        state.reply = reply;
        let fields = smallvec![("task", task.clone()), ("service", state.service.clone())];
        self.emit(r, "call_end", fields);
    }

    /// `UFControl_StopTask`: the call ends now, or when its graph's
    /// iteration ends (a stop does not cut one: `codegen/loops.rs`).
    fn stop_task(&mut self, r: usize, task: &str) {
        let t = self.robots[r].task_index(task);
        let state = &mut self.robots[r].tasks[t].1;
        if !state.busy {
            return;
        }
        if state.untaken.take().is_some() {
            state.busy = false;
            return;
        }
        if state.graph_until > self.now {
            state.stopped = true;
            state.generation += 1;
            let (at, generation) = (state.graph_until, state.generation);
            self.schedule(
                at,
                Event::ServiceDone {
                    robot: r,
                    task: t,
                    generation,
                },
            );
        } else {
            self.end_call(r, t, false);
        }
    }

    /// A call binding results is done: each slot takes what the task gave
    /// back, read as the slot's type (a text not of it, or a result the
    /// scenario does not give, is none), and is traced (`result`).
    fn take_results(
        &mut self,
        r: usize,
        m: &ControlMachine,
        task: &str,
        service: &str,
        results: &[SlotId],
    ) {
        let t = self.robots[r].task_index(task);
        let reply = self.robots[r].tasks[t].1.reply.clone();
        for (k, slot) in results.iter().enumerate() {
            let text = reply
                .as_ref()
                .and_then(|values| values.get(k).cloned().flatten());
            let decl = &m.slots[slot.index()];
            let value = text.and_then(|text| decl.kind.parse(&text));
            self.store(r, *slot, value.clone());
            self.trace.push(TraceEvent {
                t: self.now,
                robot: r,
                event: "result",
                fields: smallvec![
                    ("service", service.into()),
                    ("name", result_name(&decl.key))
                ],
                value: Some(("value", value)),
                sent_at: None,
            });
        }
    }

    fn busy(&self, r: usize, task: &str) -> bool {
        let robot = &self.robots[r];
        robot.tasks[robot.task_index(task)].1.busy
    }

    // -------------------------------------------------------- the machine

    fn throw_event(&mut self, r: usize, event: &str) {
        self.emit(r, "throw", smallvec![("name", event.into())]);
        self.catch_event(r, event);
    }

    /// `throw E broadcast` (`throw_broadcast`): traced once, the others of
    /// the thrower's group told (the event's name as text, key
    /// `Team.__event`), then caught here as `throw E` is.
    /// In arms of counted groups, only the robots that share this one's
    /// arms are told (`throw_broadcast_within` in the C).
    fn throw_broadcast(&mut self, r: usize, event: &str, broadcast: &Broadcast) {
        let fields = smallvec![("name", event.into()), ("broadcast", "true".into())];
        self.emit(r, "throw", fields);
        let told: Vec<OutgoingId> = if broadcast.within.is_empty() {
            broadcast.messages.clone()
        } else {
            let sharing = self.sharing_arms(r, &broadcast.within, &broadcast.to);
            (broadcast.to.iter().zip(&broadcast.messages))
                .filter(|&(&peer, _)| sharing.contains(peer))
                .map(|(_, &message)| message)
                .collect()
        };
        for message in told {
            let (to, key) = self.fleet.names[r].outgoing[message.index()].clone();
            self.comm_send(r, to, false, key, Some(Value::text(event)));
        }
        self.catch_event(r, event);
    }

    /// The current mode's catch of `event`, unless a mode change is asked
    /// for already: whether it was caught.
    fn catch_event(&mut self, r: usize, event: &str) -> bool {
        self.catch_event_from(r, event, None)
    }

    /// [`Sim::catch_event`], for an event told by `from` (a broadcast: the
    /// `catch` names its thrower).
    fn catch_event_from(&mut self, r: usize, event: &str, from: Option<Rc<str>>) -> bool {
        let robot = &self.robots[r];
        let m = &robot.program.control;
        let Some(current) = robot.current_mode else {
            return false;
        };
        if robot.pending_mode.is_some() {
            return false;
        }
        let Some(t) = m
            .transitions
            .iter()
            .find(|t| t.from == current && t.event == event)
        else {
            return false;
        };
        self.robots[r].pending_mode = Some(t.to);
        let mode = m.mode(t.to).name.clone();
        let mut fields = smallvec![("name", event.into()), ("mode", mode.into())];
        if let Some(from) = from {
            fields.push(("from", from));
        }
        self.emit(r, "catch", fields);
        true
    }

    /// The receive task's `heard_event`: a broadcast event of its team
    /// queued for the control task, which it wakes; an event this robot
    /// hears of no one (`events_heard`) is refused, one past the queue's
    /// room dropped.
    fn hear_event(&mut self, r: usize, message: &Message) {
        let robot = &self.robots[r];
        let heard = &robot.program.control.events_heard;
        let event = match &message.value {
            Some(Value::Text(t)) => heard.binary_search_by(|e| e.as_str().cmp(t)).ok(),
            _ => None,
        };
        let (Some(event), Some(peer)) = (event, sender_peer(robot.program, message)) else {
            let fields = smallvec![
                ("key", message.key.clone()),
                ("reason", "not an event it hears".into()),
            ];
            self.emit(r, "reject", fields);
            return;
        };
        if robot.events.len() >= crate::refine::EVENT_QUEUE {
            let fields = smallvec![
                ("from", message.from_robot.clone()),
                ("name", heard[event].as_str().into()),
                ("reason", "too many events".into()),
            ];
            self.emit(r, "drop", fields);
            return;
        }
        self.robots[r].events.push_back((peer, event));
        self.wake(r);
    }

    /// At the start of a control firing, in its mode (`comm_event_take`):
    /// each broadcast event received since the last one, in order, handled
    /// as its own `throw` would be, but traced as a `catch` naming the
    /// thrower, or a `drop` (`not caught`) when the mode does not catch it
    /// or a mode change is asked for already.
    fn take_events(&mut self, r: usize) {
        while let Some((peer, event)) = self.robots[r].events.pop_front() {
            let program = self.robots[r].program;
            let name = program.control.events_heard[event].as_str();
            let from: Rc<str> = program.peer(peer).1.as_str().into();
            if !self.catch_event_from(r, name, Some(from.clone())) {
                let fields = smallvec![
                    ("from", from),
                    ("name", name.into()),
                    ("reason", "not caught".into()),
                ];
                self.emit(r, "drop", fields);
            }
        }
    }

    fn enter_mode(&mut self, r: usize, mode: ModeId) {
        let m: &ControlMachine = &self.robots[r].program.control;
        for region in &mut self.robots[r].regions {
            region.service = None;
            region.done = true;
        }
        self.robots[r].current_mode = Some(mode);
        self.emit(
            r,
            "mode",
            smallvec![("mode", m.mode(mode).name.as_str().into())],
        );
        for (i, region) in m.mode(mode).regions.iter().enumerate() {
            let slot = &mut self.robots[r].regions[i];
            slot.service = Some(region.service);
            slot.plan = region.plan.clone();
            slot.timeout_ms = region.timeout_ms.unwrap_or(0);
        }
        let now = self.now;
        for i in 0..self.robots[r].regions.len() {
            let region = &mut self.robots[r].regions[i];
            let Some(service) = region.service else {
                continue;
            };
            region.pc = 0;
            region.phase = 0;
            region.done = false;
            region.started = now;
            region.pass_start = now;
            let fields = smallvec![
                ("plan", region.plan.as_str().into()),
                ("service", m.service(service).name.as_str().into()),
            ];
            self.emit(r, "service_start", fields);
        }
    }

    fn leave_mode(&mut self, r: usize) {
        let m = &self.robots[r].program.control;
        for i in 0..self.robots[r].regions.len() {
            let region = &self.robots[r].regions[i];
            if let Some(service) = region.service
                && !region.done
            {
                let fields = smallvec![
                    ("plan", region.plan.as_str().into()),
                    ("service", m.service(service).name.as_str().into()),
                    ("why", "mode change".into()),
                ];
                self.emit(r, "service_end", fields);
            }
        }
        for task in &m.request_tasks {
            self.stop_task(r, task);
        }
    }

    /// `task_control_go`: one firing of the control task.
    fn fire(&mut self, r: usize) {
        let program = self.robots[r].program;
        let m = &program.control;
        self.read_inputs(r);
        self.manage_resources(r);
        if m.heartbeat && self.now - self.robots[r].last_heartbeat >= m.heartbeat_ms {
            self.robots[r].last_heartbeat = self.now;
            self.elect_at_heartbeat(r);
            self.fold_term(r);
            let robot = &self.robots[r];
            let term = if robot.leading {
                robot.term_led
            } else {
                robot.term
            };
            let words = (robot.leading, own_battery(robot, self.now), term);
            let value = match &robot.said {
                Some((said, value)) if *said == words => value.clone(),
                _ => {
                    let (leading, battery, term) = words;
                    let value = Value::text(&heartbeat_value(leading, battery, term));
                    self.robots[r].said = Some((words, value.clone()));
                    value
                }
            };
            let names = &self.fleet.names[r];
            let (team, key) = (names.team.clone(), names.alive_key.clone());
            self.comm_send(r, team, true, key, Some(value));
            self.group_update(r);
        }
        if self.robots[r].current_mode.is_none() {
            match m.default_mode {
                Some(d) => self.enter_mode(r, d),
                None => {
                    self.emit(r, "finish", smallvec![("why", "no default mode".into())]);
                    self.stop(r);
                    return;
                }
            }
        }
        self.take_events(r);
        let mut running = false;
        for i in 0..self.robots[r].regions.len() {
            if self.robots[r].pending_mode.is_some() {
                break;
            }
            let region = &self.robots[r].regions[i];
            let Some(service) = region.service else {
                continue;
            };
            if region.done {
                continue;
            }
            if region.timeout_ms > 0 && self.now - region.started > region.timeout_ms {
                let plan: Rc<str> = region.plan.as_str().into();
                self.robots[r].regions[i].done = true;
                let fields = smallvec![
                    ("plan", plan),
                    ("service", m.service(service).name.as_str().into()),
                    ("why", "timeout".into()),
                ];
                self.emit(r, "service_end", fields);
                continue;
            }
            let mut result = Step::Next;
            let mut n = 0;
            let mut pc = self.robots[r].regions[i].pc;
            while n < STEPS_PER_FIRING
                && result == Step::Next
                && self.robots[r].pending_mode.is_none()
            {
                pc = self.robots[r].regions[i].pc;
                result = self.step(r, i, service);
                n += 1;
            }
            if self.robots[r].pending_mode.is_some() {
                // This plan's throw ends the mode: the later plans do not
                // run in this firing.
                self.look_for_races(r, i, pc);
            }
            if result == Step::Done {
                let region = &mut self.robots[r].regions[i];
                region.done = true;
                let fields = smallvec![
                    ("plan", region.plan.as_str().into()),
                    ("service", m.service(service).name.as_str().into()),
                ];
                self.emit(r, "service_end", fields);
            } else {
                running = true;
            }
        }
        if let Some(next) = self.robots[r].pending_mode {
            self.leave_mode(r);
            self.robots[r].pending_mode = None;
            self.enter_mode(r, next);
            return;
        }
        if !running {
            let mode = self.robots[r]
                .current_mode
                .map(|c| m.mode(c).name.clone())
                .unwrap_or_default();
            self.emit(r, "finish", smallvec![("mode", mode.into())]);
            self.stop(r);
        }
    }

    /// The first firing of robot `r`'s grid at or after `at`, and after the
    /// firing under way (a robot fires every period from its start).
    fn grid_at_or_after(&self, r: usize, at: i64) -> i64 {
        let start = self.robots[r].started_at;
        let k = (at - start + CONTROL_PERIOD_MS - 1).div_euclid(CONTROL_PERIOD_MS);
        let t = start + k.max(0) * CONTROL_PERIOD_MS;
        // At the current time, a robot whose firing would come before the
        // one just handled has had it (idle) already.
        if t == self.now && self.last_fire.0 == self.now && self.robots[r].chain <= self.last_fire.1
        {
            t + CONTROL_PERIOD_MS
        } else {
            t
        }
    }

    /// Something a waiting firing reads (a message in the inbox, the end of
    /// a call) changed: a sleeping robot fires at its next period.
    fn wake(&mut self, r: usize) {
        if self.every_firing || !self.robots[r].alive {
            return;
        }
        let at = self.grid_at_or_after(r, self.now);
        if self.robots[r].next_fire.is_none_or(|next| at < next) {
            self.schedule_fire(r, at);
        }
    }

    /// After an idle firing of robot `r`, its next firing that can differ:
    /// every firing until then would read the same state and do nothing,
    /// except where time passes a threshold the firing compares against
    /// (a timeout, a period, the heartbeat) or a sensor sample changes.
    /// Messages and the ends of calls wake it ([`Sim::wake`]); `None` when
    /// only they can.
    fn wake_up(&self, r: usize) -> Option<i64> {
        let robot = &self.robots[r];
        let m = &robot.program.control;
        let mut at: Option<i64> = None;
        let mut at_least = |t: i64| at = Some(at.map_or(t, |a| a.min(t)));
        if m.heartbeat {
            at_least(robot.last_heartbeat + m.heartbeat_ms);
        }
        if let Some(t) = self.owner_lost_at(r) {
            at_least(t);
        }
        for region in &robot.regions {
            let Some(service) = region.service.filter(|_| !region.done) else {
                continue;
            };
            if region.timeout_ms > 0 {
                at_least(region.started + region.timeout_ms + 1);
            }
            let Some(state) = m.service(service).states.get(region.pc) else {
                continue;
            };
            match &state.kind {
                StateKind::Receive {
                    timeout_ms, mark, ..
                }
                | StateKind::Call {
                    timeout_ms, mark, ..
                }
                | StateKind::RunActions {
                    timeout_ms, mark, ..
                } => {
                    if let Some(t) = timeout_ms
                        && region.phase > 0
                    {
                        at_least(region.marks[mark.index()] + t + 1);
                    }
                }
                StateKind::LoopTail {
                    period_ms: Some(p),
                    mark,
                    ..
                } => at_least(region.marks[mark.index()] + p),
                StateKind::Repeat {
                    period_ms: Some(p), ..
                } => at_least(region.pass_start + p),
                // Not a state that waits: fire again next period.
                _ => at_least(self.now + CONTROL_PERIOD_MS),
            }
        }
        // The next sensor sample that brings a new value (the slots a
        // sensor feeds, listed once: not every slot of the program).
        for &i in self.inputs[r].sensors.iter() {
            let s = &m.slots[i];
            let (SlotSource::Sensor { port, task }, Some(series)) =
                (&s.source, &robot.sensor_series[i])
            else {
                continue;
            };
            let sampled = robot.sampled_at(task, self.now);
            let n = series.partition_point(|(t, _)| *t <= sampled);
            if let Some((t, _)) = series.get(n) {
                at_least(robot.sample_at_or_after(task, *t));
            }
            if n == 0
                && port == "BATTERY"
                && robot.battery.last().is_some_and(|(t, _)| *t > sampled)
            {
                at_least(robot.sample_at_or_after(task, sampled + 1));
            }
        }
        at.map(|t| self.grid_at_or_after(r, t.max(self.now + 1)))
    }

    /// Region `i` to change: the firing progressed.
    fn region(&mut self, r: usize, i: usize) -> &mut Region {
        self.robots[r].progressed = true;
        &mut self.robots[r].regions[i]
    }

    /// One state of region `i`'s service (`service_<n>` of the C).
    fn step(&mut self, r: usize, i: usize, service: ServiceMachineId) -> Step {
        let program: &'p RobotProgram = self.robots[r].program;
        let m = &program.control;
        let pc = self.robots[r].regions[i].pc;
        let Some(state) = m.service(service).states.get(pc) else {
            return Step::Done;
        };
        let next = pc + 1;
        let now = self.now;
        match &state.kind {
            StateKind::Receive {
                messages,
                timeout_ms,
                mark,
            } => {
                if timeout_ms.is_some() && self.robots[r].regions[i].phase == 0 {
                    let region = self.region(r, i);
                    region.marks[mark.index()] = now;
                    region.phase = 1;
                }
                let ready = messages
                    .iter()
                    .all(|&k| !self.robots[r].inbox[k.index()].0.is_empty());
                if !ready {
                    let Some(t) = timeout_ms else {
                        return Step::Wait;
                    };
                    if now - self.robots[r].regions[i].marks[mark.index()] <= *t {
                        return Step::Wait;
                    }
                    self.emit(r, "timeout", smallvec![("statement", "receive".into())]);
                    let region = self.region(r, i);
                    region.phase = 0;
                    region.pc = next;
                    return Step::Next;
                }
                if timeout_ms.is_some() {
                    self.region(r, i).phase = 0;
                }
                for &k in messages {
                    if let Some(v) = self.robots[r].inbox[k.index()].0.pop_front() {
                        self.robots[r].stalled[k.index()] = false;
                        self.store(r, m.incoming_message(k).slot, v);
                    }
                }
                // Room for a message the receive task holds up.
                self.release(r, false);
                self.region(r, i).pc = next;
                Step::Next
            }
            StateKind::Send { items } => {
                for item in items {
                    let value = self.value(r, &item.value);
                    let sent = match item.store {
                        Some(s) => {
                            self.store(r, s, value);
                            self.robots[r].slots[s.index()].clone()
                        }
                        None => value,
                    };
                    if let Some(group) = item.own_group {
                        // Its own publication is the latest its subscription sees.
                        self.robots[r].groups[group.index()] = Some(sent.clone());
                    }
                    let publish = m.outgoing_message(item.message).publish;
                    let (to, key) = self.fleet.names[r].outgoing[item.message.index()].clone();
                    self.comm_send(r, to, publish, key, sent);
                }
                self.region(r, i).pc = next;
                Step::Next
            }
            StateKind::Subscribe { group, slot } => {
                if let Some(v) = self.robots[r].groups[group.index()].clone() {
                    self.store(r, *slot, v);
                }
                self.region(r, i).pc = next;
                Step::Next
            }
            StateKind::Throw { event, broadcast } => {
                match broadcast {
                    None => self.throw_event(r, event),
                    Some(broadcast) => self.throw_broadcast(r, event, broadcast),
                }
                self.region(r, i).pc = next;
                Step::Next
            }
            StateKind::Call {
                service,
                task,
                args,
                timeout_ms,
                mark,
                results,
            } => {
                if self.robots[r].regions[i].phase == 0 {
                    let values = args.iter().map(|a| self.value(r, a)).collect();
                    if !self.request(r, task, service, values) {
                        return Step::Wait;
                    }
                    // Its results are none until it is done.
                    for slot in results {
                        self.store(r, *slot, None);
                    }
                    let region = self.region(r, i);
                    region.marks[mark.index()] = now;
                    region.phase = 1;
                    return Step::Wait;
                }
                let timed_out = timeout_ms
                    .is_some_and(|t| now - self.robots[r].regions[i].marks[mark.index()] > t);
                if timed_out {
                    self.stop_task(r, task);
                    self.emit(
                        r,
                        "timeout",
                        smallvec![("service", service.as_str().into())],
                    );
                } else if self.busy(r, task) {
                    return Step::Wait;
                } else if !results.is_empty() {
                    self.take_results(r, m, task, service, results);
                }
                let region = self.region(r, i);
                region.phase = 0;
                region.pc = next;
                Step::Next
            }
            StateKind::RunActions {
                service,
                machine,
                args,
                timeout_ms,
                mark,
            } => {
                let am = m.action_machine(*machine);
                if self.robots[r].regions[i].phase == 0 {
                    for (k, slot) in am.arguments.iter().enumerate() {
                        if let Some(arg) = args.get(k) {
                            let v = self.value(r, arg);
                            self.store(r, *slot, v);
                        }
                    }
                    let region = self.region(r, i);
                    region.action = am.initial;
                    region.phase = 1;
                    region.marks[mark.index()] = now;
                    self.emit(
                        r,
                        "actions_start",
                        smallvec![("service", service.as_str().into())],
                    );
                }
                if let Some(t) = timeout_ms
                    && now - self.robots[r].regions[i].marks[mark.index()] > *t
                {
                    self.emit(
                        r,
                        "timeout",
                        smallvec![("service", service.as_str().into())],
                    );
                    let region = self.region(r, i);
                    region.phase = 0;
                    region.pc = next;
                    return Step::Next;
                }
                if self.actions(r, i, am) != Step::Done {
                    return Step::Wait;
                }
                self.emit(
                    r,
                    "actions_end",
                    smallvec![("service", service.as_str().into())],
                );
                let region = self.region(r, i);
                region.phase = 0;
                region.pc = next;
                Step::Next
            }
            StateKind::LeaderBranch {
                candidates,
                algorithm,
                others_at,
                receives,
            } => {
                match self.election(
                    r,
                    (service, StateId::new(pc)),
                    candidates,
                    *algorithm,
                    receives,
                ) {
                    None => Step::Wait, // still listening
                    Some(elected) => {
                        self.region(r, i).pc = if elected { next } else { others_at.index() };
                        Step::Next
                    }
                }
            }
            StateKind::GroupAllocate {
                members,
                groups,
                others_at,
                within,
                nested,
            } => {
                let me = program.self_peer;
                let live = self.sharing_arms(r, within, members);
                let position = live.position(me).unwrap_or(0);
                let mins: Vec<usize> = groups.iter().map(|g| g.min).collect();
                let chosen = counted_allocation(&mins, others_at.is_some(), position);
                let (name, at) = match (chosen, others_at) {
                    (Some(k), _) => (groups[k].name.as_str(), groups[k].at.index()),
                    (None, Some(at)) => ("others", at.index()),
                    (None, None) => ("others", next),
                };
                let robot = &mut self.robots[r];
                if robot.allocated.insert((service, StateId::new(pc)), chosen) != Some(chosen) {
                    for &inner in nested {
                        robot.allocated.remove(&(service, inner));
                    }
                    let fields = smallvec![
                        ("name", name.into()),
                        ("alive", live.len().to_string().into()),
                    ];
                    self.emit(r, "allocated", fields);
                }
                self.region(r, i).pc = at;
                Step::Next
            }
            StateKind::GroupSync {
                members,
                point,
                timeout_ms,
                mark,
            } => {
                if self.robots[r].regions[i].phase == 0 {
                    let robot = &mut self.robots[r];
                    let pass = robot
                        .sync_pass
                        .entry((service, StateId::new(pc)))
                        .or_insert(0);
                    *pass += 1;
                    let value = format!("{} {}", m.sync_point(*point), *pass);
                    let region = self.region(r, i);
                    region.marks[mark.index()] = now;
                    region.phase = 1;
                    let names = &self.fleet.names[r];
                    let (team, key) = (names.team.clone(), names.sync_key.clone());
                    self.comm_send(r, team, false, key, Some(Value::text(&value)));
                }
                let robot = &self.robots[r];
                let heard = self.heard(r);
                let pass = robot.sync_pass[&(service, StateId::new(pc))];
                let lost = crate::refine::protocol::lost_after_ms(m.heartbeat_ms);
                let me = program.self_peer;
                let waiting = members.iter().any(|&peer| {
                    peer != me
                        && robot
                            .sync_arrived
                            .get(&(peer, *point))
                            .copied()
                            .unwrap_or(0)
                            < pass
                        && now - heard.get(peer).seen <= lost
                });
                let started = robot.regions[i].marks[mark.index()];
                if waiting && now - started <= *timeout_ms {
                    return Step::Wait;
                }
                if waiting {
                    self.emit(r, "timeout", smallvec![("statement", "GroupSync".into())]);
                } else {
                    let line = state.line.to_string();
                    self.emit(r, "group_sync", smallvec![("line", line.into())]);
                }
                let region = self.region(r, i);
                region.phase = 0;
                region.pc = next;
                Step::Next
            }
            StateKind::Branch { condition, else_to } => {
                let holds = self.eval(r, condition);
                self.region(r, i).pc = if holds { next } else { else_to.index() };
                Step::Next
            }
            StateKind::Jump { to } => {
                self.region(r, i).pc = to.index();
                Step::Next
            }
            StateKind::LoopHead {
                condition,
                exit_to,
                mark,
            } => {
                if let Some(cond) = condition
                    && !self.eval(r, cond)
                {
                    self.region(r, i).pc = exit_to.index();
                    return Step::Next;
                }
                let region = self.region(r, i);
                region.marks[mark.index()] = now;
                region.pc = next;
                Step::Next
            }
            StateKind::LoopTail {
                period_ms,
                mark,
                to,
            } => match period_ms {
                Some(p) => {
                    if now - self.robots[r].regions[i].marks[mark.index()] < *p {
                        return Step::Wait;
                    }
                    self.region(r, i).pc = to.index();
                    Step::Next
                }
                None => {
                    self.region(r, i).pc = to.index();
                    Step::Wait
                }
            },
            StateKind::Repeat {
                period_ms,
                condition,
                forever,
            } => {
                if let Some(cond) = condition
                    && !self.eval(r, cond)
                {
                    return Step::Done;
                }
                if let Some(p) = period_ms {
                    if now - self.robots[r].regions[i].pass_start < *p {
                        return Step::Wait;
                    }
                    let region = self.region(r, i);
                    region.pass_start = now;
                    region.pc = 0;
                    Step::Next
                } else if *forever || condition.is_some() {
                    let region = self.region(r, i);
                    region.pass_start = now;
                    region.pc = 0;
                    Step::Wait
                } else {
                    Step::Done
                }
            }
        }
    }

    /// `actions_<n>`: phase 1 enters the current action (issues its
    /// commands), phase 2 waits for them and takes the first transition that holds.
    fn actions(&mut self, r: usize, i: usize, am: &'p ActionMachine) -> Step {
        let Some(action) = am.actions.get(self.robots[r].regions[i].action.index()) else {
            return Step::Done;
        };
        if action.is_final {
            return Step::Done;
        }
        if !action.commands.is_empty() {
            if self.robots[r].regions[i].phase == 1 {
                for (task, command) in &action.commands {
                    let name = actuator_name(self.robots[r].program, task);
                    let given = self.value(r, command);
                    if !self.request(r, task, &name, vec![given]) {
                        return Step::Wait;
                    }
                }
                self.region(r, i).phase = 2;
                return Step::Wait;
            }
            for (task, _) in &action.commands {
                if self.busy(r, task) {
                    return Step::Wait;
                }
            }
        }
        for (condition, to) in &action.transitions {
            if condition.as_ref().is_none_or(|c| self.eval(r, c)) {
                let region = self.region(r, i);
                region.action = *to;
                region.phase = 1;
                return Step::Next;
            }
        }
        Step::Wait
    }

    /// This robot has just become the leader at a `leader(...)` arm: the
    /// messages waiting for the receives of the leader's block (`messages`)
    /// arrived before it led, and are dropped, each traced. Only those in
    /// the channels now, oldest first, as the C's `drop_unled` takes them;
    /// a message the receive task holds up then finds room, as after a
    /// `receive`.
    fn drop_unled(&mut self, r: usize, messages: &[IncomingId]) {
        let mut took = false;
        for &k in messages {
            let robot = &mut self.robots[r];
            let waiting = robot.inbox[k.index()].0.len();
            if waiting == 0 {
                continue;
            }
            robot.inbox[k.index()].0.clear();
            robot.stalled[k.index()] = false;
            took = true;
            let incoming = robot.program.control.incoming_message(k);
            let (from, key): (Rc<str>, Rc<str>) = (
                incoming.from_team.as_str().into(),
                incoming.key.as_str().into(),
            );
            for _ in 0..waiting {
                let fields = smallvec![
                    ("from", from.clone()),
                    ("key", key.clone()),
                    ("reason", crate::refine::protocol::UNLED_REASON.into()),
                ];
                self.emit(r, "drop", fields);
            }
        }
        if took {
            self.release(r, false);
        }
    }

    /// `election_K` in the C: the election of the `LeaderBranch` state
    /// `state` ([`Sim::elected`]); a robot that has just become the leader
    /// drops what waits for its leader's block (`receives`).
    fn election(
        &mut self,
        r: usize,
        state: (ServiceMachineId, StateId),
        candidates: &[PeerId],
        algorithm: LeaderAlgorithm,
        receives: &[IncomingId],
    ) -> Option<bool> {
        let me = self.robots[r].program.self_peer;
        let led = self.robots[r].leaders.get(&state) == Some(&Leader::Robot(me));
        let elected = self.elected(r, state, candidates, algorithm);
        if elected == Some(true) && !led {
            self.drop_unled(r, receives);
        }
        elected
    }

    /// At each heartbeat, before it is sent: every election this robot has
    /// decided at least once (at its statement) is decided again, in
    /// service and state order, so that a lost leader is replaced, and a
    /// leader whose lease lapsed steps down, within a heartbeat period of
    /// the instant the rule says so, whether or not the statement is
    /// reached then (`docs/groups.md`, "Takeover"); the heartbeat says the
    /// outcome.
    fn elect_at_heartbeat(&mut self, r: usize) {
        let elections = self.elections.clone();
        for e in &elections[r] {
            if self.robots[r].leaders.contains_key(&e.at) {
                self.election(r, e.at, e.candidates, e.algorithm, e.receives);
            }
        }
    }

    /// `elected` (`codegen/control.rs`'s `ELECTED`): among the live
    /// candidates (this robot, or heard from within `lost_after_ms`) the
    /// algorithm's choice; a robot that must listen first (restarted, or a
    /// `highest_battery` election) answers `None` until it has; a rejoining
    /// robot follows a live claimant instead of claiming. Fenced: a robot
    /// the election would choose that has not heard a majority of the
    /// candidates within its lease ([`crate::refine::protocol::lease_ms`]) answers
    /// `None`, traced once, and rejoins after. A change of leader is traced.
    fn elected(
        &mut self,
        r: usize,
        state: (ServiceMachineId, StateId),
        candidates: &[PeerId],
        algorithm: LeaderAlgorithm,
    ) -> Option<bool> {
        self.fold_term(r);
        let now = self.now;
        let robot = &self.robots[r];
        let heard = self.heard(r);
        let hb = robot.program.control.heartbeat_ms;
        let listens = robot.rejoining || algorithm == LeaderAlgorithm::HighestBattery;
        if listens && now - robot.started_at < crate::refine::protocol::listen_ms(hb) {
            return None;
        }
        let me = robot.program.self_peer;
        let lost = crate::refine::protocol::lost_after_ms(hb);
        let alive = |c: PeerId| c == me || now - heard.get(c).seen <= lost;
        let level = |c: PeerId| {
            if c == me {
                own_battery(robot, now)
            } else {
                heard.get(c).battery
            }
        };
        let mut live = candidates.iter().copied().filter(|&c| alive(c));
        let chosen = match algorithm {
            LeaderAlgorithm::LowestId => live.next(),
            LeaderAlgorithm::Bully => live.next_back(),
            // The highest level, the first of equals; unknown is lowest.
            LeaderAlgorithm::HighestBattery => {
                live.fold(None, |best: Option<PeerId>, c| match best {
                    Some(b) if level(c).unwrap_or(-1) <= level(b).unwrap_or(-1) => Some(b),
                    _ => Some(c),
                })
            }
        };
        let mut leader = chosen.unwrap_or(me);
        // Terms: a leader that has heard a higher term than its own since it
        // began is deposed, and like a rejoining robot it follows a live
        // claimant; a claim counts only under the highest term known (an
        // older one is stale).
        let was_leading = robot.leading;
        let deposed = was_leading && robot.term > robot.term_led;
        if (robot.rejoining || deposed) && leader == me {
            let claimant = heard
                .iter()
                .find(|&(i, h)| i != me && h.leads && h.term >= robot.term && now - h.seen <= lost)
                .map(|(i, _)| i);
            if let Some(c) = claimant {
                leader = c;
            }
        }
        if leader == me {
            // Fencing: without a majority heard within its lease this robot
            // may be the one cut off; it waits, and rejoins after.
            let lease = crate::refine::protocol::lease_ms(hb);
            let heard = candidates
                .iter()
                .filter(|&&c| c == me || now - heard.get(c).seen <= lease)
                .count();
            let robot = &mut self.robots[r];
            robot.leading = false;
            if 2 * heard <= candidates.len() {
                robot.rejoining = true;
                robot.fenced = Some(None);
                if robot.leaders.insert(state, Leader::Fenced) != Some(Leader::Fenced) {
                    let counted = crate::refine::protocol::fenced_heard(heard, candidates.len());
                    self.emit(r, "fenced", smallvec![("heard", counted.into())]);
                }
                return None;
            }
            if let Some(regained) = robot.fenced {
                // A majority again: listen before claiming, so that the
                // heartbeat of a robot leading meanwhile has come.
                let regained = regained.unwrap_or(now);
                if now - regained < crate::refine::protocol::listen_ms(hb) {
                    robot.fenced = Some(Some(regained));
                    return None;
                }
                robot.fenced = None;
            }
            robot.rejoining = false;
        }
        let robot = &mut self.robots[r];
        if leader != me {
            // It follows a live robot: it has heard the team again.
            robot.fenced = None;
        } else if !was_leading || deposed {
            // It begins to lead (again, when deposed): under a new term.
            robot.term = crate::refine::protocol::next_term(robot.term);
            robot.term_led = robot.term;
        }
        robot.leading = leader == me;
        if robot.leaders.get(&state) != Some(&Leader::Robot(leader)) {
            robot.leaders.insert(state, Leader::Robot(leader));
            let name = robot.program.peer(leader).1.clone();
            self.emit(r, "leader", smallvec![("leader", name.into())]);
        }
        Some(leader == me)
    }
}

/// The last leader a `LeaderBranch` state saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Leader {
    Robot(PeerId),
    /// None: this robot is fenced (`ELECT_FENCED` in the C).
    Fenced,
}

impl Leader {
    /// As the exploration fingerprint hashes it: the peer's position, -1
    /// when fenced (what the `usize::MAX` that stood for it came to).
    pub(super) fn code(self) -> i64 {
        match self {
            Leader::Robot(peer) => peer.index() as i64,
            Leader::Fenced => -1,
        }
    }
}

/// What each peer's last heartbeat said, kept for the peers of the robot's
/// team, the only robots whose heartbeats reach it (published to the team
/// under its alive key), so that each robot of a swarm does not hold a
/// table of the whole swarm; a peer of another team heard is kept aside.
/// The team's table is made at the first heartbeat heard: only robots that
/// take heartbeats (`ControlMachine::heartbeat`) hear any, and a table per
/// robot made when it starts was the square of a team's robots.
/// A peer never heard reads as the C's static table: heard at mission
/// time 0, claiming nothing, battery unknown.
#[derive(Clone, Debug)]
struct Hearing {
    /// The peers of the team.
    team: std::ops::Range<usize>,
    /// Per peer of the team, in order; empty until one is heard.
    heard: Vec<Heard>,
    /// Other peers heard, in peer order.
    others: Vec<(PeerId, Heard)>,
}

impl Hearing {
    /// About the bytes it holds (`Sim::approx_bytes`).
    fn approx_bytes(&self) -> usize {
        self.heard.len() * std::mem::size_of::<Heard>()
            + self.others.len() * std::mem::size_of::<(PeerId, Heard)>()
    }

    fn new(team: std::ops::Range<usize>) -> Hearing {
        Hearing {
            team,
            heard: Vec::new(),
            others: Vec::new(),
        }
    }

    fn get(&self, peer: PeerId) -> Heard {
        if self.team.contains(&peer.index()) {
            let heard = self.heard.get(peer.index() - self.team.start);
            return heard.copied().unwrap_or(Heard::NEVER);
        }
        self.others
            .binary_search_by_key(&peer, |(p, _)| *p)
            .map_or(Heard::NEVER, |i| self.others[i].1)
    }

    fn set(&mut self, peer: PeerId, heard: Heard) {
        if self.team.contains(&peer.index()) {
            if self.heard.is_empty() {
                self.heard = vec![Heard::NEVER; self.team.len()];
            }
            self.heard[peer.index() - self.team.start] = heard;
            return;
        }
        match self.others.binary_search_by_key(&peer, |(p, _)| *p) {
            Ok(i) => self.others[i].1 = heard,
            Err(i) => self.others.insert(i, (peer, heard)),
        }
    }

    /// Every peer of the team and every other peer kept, in peer order (a
    /// peer not kept was never heard).
    fn iter(&self) -> impl Iterator<Item = (PeerId, Heard)> + '_ {
        let team = self.team.clone();
        let (first, end) = (team.start, team.end);
        let before = self.others.iter().filter(move |(p, _)| p.index() < first);
        let after = self.others.iter().filter(move |(p, _)| p.index() >= end);
        let team = team.map(move |p| (PeerId::new(p), self.get(PeerId::new(p))));
        before.copied().chain(team).chain(after.copied())
    }
}

/// What a robot's last heartbeat said (`comm_heartbeat` in the C).
#[derive(Clone, Copy, Debug)]
struct Heard {
    /// When it came (mission ms).
    seen: i64,
    /// It claimed leadership.
    leads: bool,
    battery: Option<i64>,
    /// The term it said: the one it leads under, or the highest it knows.
    term: i64,
}

impl Heard {
    const NEVER: Heard = Heard {
        seen: 0,
        leads: false,
        battery: None,
        term: 0,
    };

    /// `heard_alive`: `leader 87 3` or `member - 2` (a missing or
    /// malformed term is 0, a larger one [`crate::refine::protocol::TERM_MAX`]).
    fn parse(now: i64, value: &str) -> Heard {
        let mut words = value.split(' ').skip(1);
        let battery = words
            .next()
            .filter(|b| b.starts_with(|c: char| c.is_ascii_digit()))
            .and_then(|b| {
                // The leading digits, read in place (a copy per heartbeat).
                let end = b.find(|c: char| !c.is_ascii_digit()).unwrap_or(b.len());
                b[..end].parse().ok()
            });
        Heard {
            seen: now,
            leads: value.starts_with("leader "),
            battery,
            term: crate::refine::protocol::parse_term(words.next().unwrap_or("")),
        }
    }
}

/// A heartbeat's value: whether the robot claims leadership, its battery,
/// and its term (`docs/groups.md`, "Terms").
fn heartbeat_value(leading: bool, battery: Option<i64>, term: i64) -> String {
    let role = if leading { "leader" } else { "member" };
    match battery {
        Some(level) => format!("{role} {level} {term}"),
        None => format!("{role} - {term}"),
    }
}

impl Sim<'_> {
    /// At a heartbeat of a member of its team's group (`group_update` in
    /// `codegen/control.rs`): its rank among the live members (formation
    /// order) and their number, traced when they change. A member is alive
    /// when it is this robot or was heard from within `lost_after_ms`,
    /// counted from when this robot joined.
    fn group_update(&mut self, r: usize) {
        let robot = &self.robots[r];
        let m = &robot.program.control;
        if m.group.is_empty() {
            return;
        }
        let me = robot.program.self_peer;
        let now = self.now;
        let heard = self.heard(r);
        let alive = |peer: PeerId| {
            peer == me
                || now - heard.get(peer).seen.max(robot.started_at)
                    <= crate::refine::protocol::lost_after_ms(m.heartbeat_ms)
        };
        // Its place among the live members (0 when it is none of them),
        // and their number, counted without listing them.
        let (mut rank, mut live) = (None, 0);
        for &peer in m.group.iter().filter(|&&p| alive(p)) {
            if peer == me && rank.is_none() {
                rank = Some(live);
            }
            live += 1;
        }
        let rank = rank.unwrap_or(0);
        let now_group = (rank, live);
        if self.robots[r].group == Some(now_group) {
            return;
        }
        self.robots[r].group = Some(now_group);
        self.emit(
            r,
            "group",
            smallvec![
                ("rank", rank.to_string().into()),
                ("size", live.to_string().into()),
            ],
        );
    }
}

/// A robot's battery level for its heartbeats (`own_battery`,
/// `semo_sim_battery`): the scenario's battery points at `now`, rounded.
fn own_battery(robot: &Robot<'_>, now: i64) -> Option<i64> {
    battery_level(&robot.battery, now).map(|l| l.round() as i64)
}

/// The actuator command name a task runs (`control.rs`'s `actuator_name`).
fn actuator_name(program: &RobotProgram, task: &str) -> String {
    program
        .tasks
        .iter()
        .find(|t| t.task == task)
        .and_then(|t| match &t.kind {
            RoleKind::Service { services } => services.first().cloned(),
            _ => None,
        })
        .unwrap_or_else(|| task.to_string())
}

/// The battery level at `t`: linear between the scenario's points, the
/// first before them and the last after them.
fn battery_level(points: &[(i64, f64)], t: i64) -> Option<f64> {
    let first = points.first()?;
    if t <= first.0 {
        return Some(first.1);
    }
    for pair in points.windows(2) {
        let ((t0, l0), (t1, l1)) = (pair[0], pair[1]);
        if t <= t1 {
            return Some(l0 + (l1 - l0) * (t - t0) as f64 / (t1 - t0) as f64);
        }
    }
    points.last().map(|p| p.1)
}

/// The name a mission binds a result to, from its slot's key
/// (`R.Action.Look.FOUND`, `go_home.FOUND`): after the last dot.
fn result_name(key: &str) -> Rc<str> {
    key.rsplit('.').next().unwrap_or(key).into()
}
