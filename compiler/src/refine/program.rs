//! What refinement produces for one robot: its task graph and the control
//! task's hierarchical state machine, as plain data the code generator walks.
//!
//! Levels of the machine (codegen.md §1.5): modes (top) → one concurrent
//! region per plan → the statement machine of the composite service the mode
//! sets for that plan → for a built-in call the strategy refines, that
//! entry's action machine (bottom).

use super::value::{Value, ValueKind};
use crate::index::newtype_index;
use crate::span::Span;
use crate::taskgraph::TaskGraph;
use std::sync::Arc;

newtype_index! {
    /// A state of its service machine: an index into [`ServiceMachine::states`]
    /// (the generated C's `pc`).
    pub struct StateId;
}

newtype_index! {
    /// A value of the control machine: an index into [`ControlMachine::slots`]
    /// (the generated C's `slot[]`).
    pub struct SlotId;
}

newtype_index! {
    /// A mode of the control machine: an index into [`ControlMachine::modes`]
    /// (the generated C's `MODE_<name>` enumerator has its value), at the
    /// position of the team's mode (`sema::ModeId`) it refines.
    pub struct ModeId;
}

newtype_index! {
    /// A service machine of the control machine: an index into
    /// [`ControlMachine::services`] (the generated C's `regions[].service`).
    /// Not the team's `sema::ServiceId`: a machine is made for each service
    /// a mode sets, in the order the modes first set them.
    pub struct ServiceMachineId;
}

newtype_index! {
    /// A message the control task receives: an index into
    /// [`ControlMachine::incoming`] (the generated C's `in_port[]`).
    pub struct IncomingId;
}

newtype_index! {
    /// A message the control task sends: an index into
    /// [`ControlMachine::outgoing`] (the generated C's `out_port[]`).
    pub struct OutgoingId;
}

newtype_index! {
    /// A latest-value group the control task reads: an index into
    /// [`ControlMachine::subscribed`] (the generated C's `subscribed[]`).
    pub struct SubscriptionId;
}

newtype_index! {
    /// A mark (a timer: when a loop pass, a call or a wait started) of its
    /// service machine: below [`ServiceMachine::marks`] (the generated C's
    /// `r->mark[]`).
    pub struct MarkId;
}

newtype_index! {
    /// A strategy entry's action machine: an index into
    /// [`ControlMachine::actions`] (the generated C's `actions_<n>`).
    pub struct ActionMachineId;
}

newtype_index! {
    /// An action of its action machine: an index into
    /// [`ActionMachine::actions`].
    pub struct ActionId;
}

newtype_index! {
    /// A group statement this robot synchronizes at: an index into
    /// [`ControlMachine::sync_points`].
    pub struct SyncPointId;
}

newtype_index! {
    /// A value of the team's library: an index into
    /// [`SharedLibrary::attributes`] (the generated library's `values[]`).
    pub struct AttributeId;
}

newtype_index! {
    /// A robot of the mission: an index into [`RobotProgram::peers`]
    /// (formation order, across teams).
    pub struct PeerId;
}

newtype_index! {
    /// A channel of a service graph: an index into [`GraphService::channels`]
    /// (the generated C's `ch<N>`).
    pub struct GraphChannelId;
}

newtype_index! {
    /// An inner task of a service graph: an index into [`GraphService::tasks`].
    pub struct InnerTaskId;
}

/// The robot's battery level, a catalog value: what a strategy's battery
/// condition reads (`Battery`), and what the robot's status reports.
pub const BATTERY_VALUE: &str = "BATTERY";

/// One robot's refined program.
#[derive(Clone, Debug)]
pub struct RobotProgram {
    pub mission: String,
    pub team: String,
    pub robot: String,
    pub robot_type: String,
    pub graph: TaskGraph,
    /// Per channel of `graph`: the samples its buffer holds (the buffer
    /// analysis's bound, at least the capacity refinement declared).
    pub capacities: Vec<u64>,
    /// The control task's machine: one per distinct machine, shared by
    /// the robots whose machines are equal (the robots of one declaration,
    /// `name[N]`, are refined alike), so a swarm's programs hold one copy
    /// per kind of robot, not one per robot, and what reads them (the
    /// simulator, code generation) reads the same data for each.
    pub control: Arc<ControlMachine>,
    /// The non-control tasks of `graph` and what each one does.
    pub tasks: Vec<TaskRole>,
    /// Every robot of the mission, in formation order: (team, robot). One
    /// table shared by every program of a refinement, so a fleet's programs
    /// cost memory linear in its robots, not quadratic.
    pub peers: Arc<[(String, String)]>,
    /// This robot's index in `peers`.
    pub self_peer: PeerId,
    /// The team's shared information, held by the library task.
    pub library: Option<SharedLibrary>,
    /// The service tasks that run a task graph (`graph=` in the catalog).
    pub graph_services: Vec<GraphService>,
}

impl RobotProgram {
    /// Robot `id` of [`RobotProgram::peers`]: (team, robot).
    pub fn peer(&self, id: PeerId) -> &(String, String) {
        &self.peers[id.index()]
    }
}

/// A service the robot's type implements by a task graph: each call runs
/// one iteration of the graph's looped schedule (`taskgraph::analysis`),
/// its inner tasks fired in that order inside the service task.
#[derive(Clone, Debug)]
pub struct GraphService {
    /// The service task (named after the graph file).
    pub task: String,
    /// The graph's name (`kmeans`).
    pub graph: String,
    /// The first call of the service in the mission.
    pub call: Span,
    /// One iteration of the top level, or why the graph has none (it is
    /// inconsistent or deadlocks, which the dataflow warnings report on the
    /// call, or a sub-graph it references cannot be used); code generation
    /// refuses it with the refusal's code on the call.
    pub steps: Result<Vec<GraphStep>, GraphRefused>,
    /// Every channel of every level (empty without steps), the index a
    /// [`PortUse`] or [`LoopPort`] names.
    pub channels: Vec<GraphChannel>,
    /// The inner tasks fired (loop nodes are steps), in first-firing order.
    pub tasks: Vec<InnerTask>,
}

/// Why a service graph cannot run: a diagnostic for its call.
#[derive(Clone, Debug, PartialEq)]
pub struct GraphRefused {
    /// `E100` (no schedule, a construct not supported) or `E135` (a
    /// sub-graph reference that cannot be followed).
    pub code: crate::diag::Code,
    pub message: String,
    /// Where in the graph files the reason lies.
    pub related: Vec<crate::diag::Related>,
}

/// A channel between inner tasks: a bounded FIFO of tokens. `capacity` is
/// the analysis's buffer bound (`taskgraph::analysis::buffers`) for the
/// order in which the service task runs its level: a loop body's boundary
/// feeds the inputs first and takes the outputs last.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GraphChannel {
    /// `Converge: ReplaceCenter.fb → Select.prev` (the level below the graph).
    pub label: String,
    pub capacity: u64,
    /// Tokens held before the first iteration (each the integer 0).
    pub initial_tokens: u64,
}

/// An inner task: the channels its data ports read and write, in the
/// order its ports are declared (a port no channel joins is left out).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InnerTask {
    /// Its path below the graph (`Converge/Assign/Nearest`; a sub-graph's
    /// task below the task standing for it: `Track/Predict`).
    pub path: String,
    pub inputs: Vec<PortUse>,
    pub outputs: Vec<PortUse>,
    /// A time-triggered task's period (`trigger="time" period=…`), in whole
    /// mission milliseconds: it fires at most once per period. Its first
    /// firing in the robot's life starts when the schedule reaches it; each
    /// later one waits until the previous firing's start + `period_ms` (a
    /// firing reached later starts at once), however many calls apart, so
    /// the call running it waits too. `None`: a data-triggered task, fired
    /// when the schedule reaches it.
    pub period_ms: Option<u64>,
}

/// A data port of an inner task: `rate` tokens per firing on `channel`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PortUse {
    pub port: String,
    pub channel: GraphChannelId,
    pub rate: u64,
}

/// A data port of an SDF/L loop node: an input takes `outer_rate` tokens
/// from `outer` when the loop starts and gives each iteration `inner_rate`
/// of them on `inner` (distributing: the iteration's share, in order;
/// broadcasting: the same first ones); an output takes `inner_rate` from
/// `inner` after each iteration and, when the loop ends, puts the last
/// `outer_rate` taken on `outer`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoopPort {
    pub port: String,
    pub input: bool,
    pub distributing: bool,
    pub outer_rate: u64,
    pub inner_rate: u64,
    pub outer: GraphChannelId,
    pub inner: GraphChannelId,
}

/// A term of a service graph's looped schedule, loop nodes opened.
#[derive(Clone, Debug, PartialEq)]
pub enum GraphStep {
    /// `count` firings of inner task `task`, an index in
    /// [`GraphService::tasks`].
    Fire { task: InnerTaskId, count: u64 },
    /// A loop of the schedule: `body` `count` times.
    Repeat { count: u64, body: Vec<GraphStep> },
    /// An SDF/L loop node (`path` as for tasks): its body's schedule,
    /// exactly `loop_count` times (D-type) or until its exit task sets the
    /// exit flag, at most `loop_count` times (C-type, `exit_task` its index
    /// in [`GraphService::tasks`]).
    Loop {
        path: String,
        convergent: bool,
        loop_count: u64,
        exit_task: Option<InnerTaskId>,
        /// Its data ports, in declaration order.
        ports: Vec<LoopPort>,
        body: Vec<GraphStep>,
    },
    /// A firing of a task standing for a sub-graph file (`subgraph=`, path
    /// as for tasks): one iteration of the sub-graph's looped schedule,
    /// `body`. Its inputs' tokens move to the sub-graph's side before it,
    /// its outputs' back after it.
    Subgraph {
        path: String,
        /// Its data ports that a channel joins outside, in declaration order.
        ports: Vec<SubgraphPort>,
        body: Vec<GraphStep>,
    },
}

/// A data port of a task standing for a sub-graph: `rate` tokens per
/// firing between the channel `outer` joining the task and the channel
/// `inner` joining the sub-graph's open port of the same name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SubgraphPort {
    pub port: String,
    pub input: bool,
    pub rate: u64,
    pub outer: GraphChannelId,
    pub inner: GraphChannelId,
}

/// The control task's machine.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ControlMachine {
    pub modes: Vec<ModeState>,
    pub default_mode: Option<ModeId>,
    /// `case (from): catch (event): mode = to`, with the line of the catch.
    pub transitions: Vec<ModeTransition>,
    pub services: Vec<ServiceMachine>,
    pub actions: Vec<ActionMachine>,
    /// Every value the machine reads or writes.
    pub slots: Vec<Slot>,
    /// Channels the control task writes a service request to, by task.
    pub request_tasks: Vec<String>,
    /// Outgoing messages: one control-task port each.
    pub outgoing: Vec<OutgoingMessage>,
    /// Incoming messages: one control-task port each.
    pub incoming: Vec<IncomingMessage>,
    /// Latest-value groups the control task reads (`subscribe`).
    pub subscribed: Vec<String>,
    /// Whether the robot takes part in a leader election: it then tells its
    /// team it is alive every `heartbeat_ms` and listens for theirs.
    pub heartbeat: bool,
    /// The heartbeat period (mission ms): the strategy's
    /// `LeaderSelectionInfo heartbeatPeriod` (the shortest of those that
    /// apply to the robot's elections), else [`HEARTBEAT_MS`]; 0 without
    /// `heartbeat`.
    pub heartbeat_ms: i64,
    /// The group statements this robot synchronizes at (`GroupSync`), by
    /// their offset in the mission: what a sync announcement names.
    pub sync_points: Vec<usize>,
    /// The group services (`<GroupService>`, by the catalog's name) this
    /// robot calls: non-empty makes it a member of its team's group.
    pub group_services: Vec<String>,
    /// The team's group (peer indices, in formation order): the robots whose
    /// programs call any of the team's group services; empty when this robot
    /// is not one of them. Each member's rank is its place among the live
    /// members (this robot, or heard from within `protocol::lost_after_ms`).
    pub group: Vec<PeerId>,
    /// Adaptive resource management: the team strategy's battery policies,
    /// checked at every firing against the robot's `BATTERY` value.
    pub battery: Vec<BatteryPolicy>,
    /// The events another robot of its group may broadcast to this one
    /// (`throw E broadcast` that this robot and another run), sorted: its
    /// receive task takes a message of key [`event_key`] naming one of
    /// them into the event queue its control task reads at the start of
    /// each firing; empty when no one can tell it anything.
    pub events_heard: Vec<String>,
    /// Each built-in service the control task calls (`StateKind::Call`),
    /// once, in the order first called, with what the robot type's catalog
    /// entry says it gives back: the scenario's reader checks a service's
    /// `results` against it (`sim::scenario`), so a value the call's slots
    /// would read as none is refused where it is written.
    pub gives_back: Vec<ServiceResults>,
}

/// A built-in service and its results (`<Result>`), in order: each one's
/// name and the kind of value it is ([`ValueKind::declared`]); empty when
/// the service gives nothing back.
#[derive(Clone, Debug, PartialEq)]
pub struct ServiceResults {
    pub service: String,
    pub results: Vec<(String, ValueKind)>,
}

/// The key of the messages that carry a team's broadcast events
/// (`throw E broadcast`; the value is the event's name as text), beside the
/// heartbeats' `Team.__alive` and the group statements' `Team.__sync`.
pub fn event_key(team: &str) -> String {
    format!("{team}.__event")
}

/// The longest name of a broadcast event: its message carries the name as a
/// text value, which the runtime bounds (`SEMO_TEXT_MAX` - 1 bytes).
pub const MAX_EVENT_NAME_BYTES: usize = 63;

/// The most broadcast events a robot keeps between two control firings;
/// one more arriving before the control task takes them is dropped (trace
/// `drop`, reason `too many events`), in the generated C and the simulator
/// alike.
pub const EVENT_QUEUE: usize = 16;

impl ControlMachine {
    /// Mode `id` of [`ControlMachine::modes`].
    pub fn mode(&self, id: ModeId) -> &ModeState {
        &self.modes[id.index()]
    }

    /// Incoming message `id` of [`ControlMachine::incoming`].
    pub fn incoming_message(&self, id: IncomingId) -> &IncomingMessage {
        &self.incoming[id.index()]
    }

    /// Outgoing message `id` of [`ControlMachine::outgoing`].
    pub fn outgoing_message(&self, id: OutgoingId) -> &OutgoingMessage {
        &self.outgoing[id.index()]
    }

    /// The key of subscribed group `id` of [`ControlMachine::subscribed`].
    pub fn subscription(&self, id: SubscriptionId) -> &str {
        &self.subscribed[id.index()]
    }

    /// Action machine `id` of [`ControlMachine::actions`].
    pub fn action_machine(&self, id: ActionMachineId) -> &ActionMachine {
        &self.actions[id.index()]
    }

    /// The mission offset sync point `id` names ([`ControlMachine::sync_points`]).
    pub fn sync_point(&self, id: SyncPointId) -> usize {
        self.sync_points[id.index()]
    }

    /// Service machine `id` of [`ControlMachine::services`].
    pub fn service(&self, id: ServiceMachineId) -> &ServiceMachine {
        &self.services[id.index()]
    }

    /// The most plans any mode runs at once (at least 1): the size of the
    /// machine's per-plan state, in C and in the simulator alike.
    pub fn region_count(&self) -> usize {
        self.modes
            .iter()
            .map(|mode| mode.regions.len())
            .max()
            .unwrap_or(0)
            .max(1)
    }

    /// Whether the robot has a receive task: it receives values, a group's
    /// publications, heartbeats or broadcast events.
    pub fn has_receiver(&self) -> bool {
        !self.incoming.is_empty()
            || !self.subscribed.is_empty()
            || self.heartbeat
            || !self.events_heard.is_empty()
    }

    /// The most marks any service machine uses (at least 1).
    pub fn mark_count(&self) -> usize {
        self.services
            .iter()
            .map(|s| s.marks)
            .max()
            .unwrap_or(0)
            .max(1)
    }

    /// The elections of the `leader(...)` statements: the `LeaderBranch`
    /// states in service and state order. `election_K` in the C is the
    /// K-th; both the C and the simulator decide each at its state and,
    /// once decided there, again at each heartbeat, in this order
    /// (`docs/groups.md`, "Takeover").
    pub fn elections(&self) -> impl Iterator<Item = Election<'_>> {
        let services = ServiceMachineId::all(self.services.len()).zip(&self.services);
        let states = services.flat_map(|(service, s)| {
            StateId::all(s.states.len())
                .zip(&s.states)
                .map(move |(pc, state)| ((service, pc), state))
        });
        states.filter_map(|(at, state)| match &state.kind {
            StateKind::LeaderBranch {
                candidates,
                algorithm,
                receives,
                ..
            } => Some(Election {
                at,
                line: state.line,
                candidates,
                algorithm: *algorithm,
                receives,
            }),
            _ => None,
        })
    }
}

/// A `leader(...)` statement's election ([`ControlMachine::elections`]): its
/// `LeaderBranch` state's place and fields.
#[derive(Clone, Copy, Debug)]
pub struct Election<'a> {
    /// (service, pc) of the state.
    pub at: (ServiceMachineId, StateId),
    pub line: u32,
    pub candidates: &'a [PeerId],
    pub algorithm: LeaderAlgorithm,
    /// The incoming messages the leader's block receives.
    pub receives: &'a [IncomingId],
}

impl ControlMachine {
    /// The period level (sensor) or speed level (actuator) of `task` while
    /// the policies for which `holds` is true hold: the highest level any of
    /// them gives it (the most saving one), 1 (unchanged) when none does.
    pub fn battery_level(&self, task: &str, sensor: bool, holds: &[bool]) -> u64 {
        self.battery
            .iter()
            .zip(holds)
            .filter(|(_, h)| **h)
            .flat_map(|(p, _)| if sensor { &p.sensors } else { &p.actuators })
            .filter(|(t, _)| t == task)
            .map(|(_, level)| *level)
            .max()
            .unwrap_or(1)
    }

    /// The tasks some policy gives a level, in first-mention order: sensors
    /// (`true`) then actuators (`false`). Made as they are read, nothing
    /// allocated: the simulator asks for a call's speed level at every call.
    pub fn battery_tasks(&self) -> impl Iterator<Item = (&str, bool)> + Clone {
        [true, false].into_iter().flat_map(move |sensor| {
            let mentions = self.battery.iter().flat_map(move |p| {
                let listed = if sensor { &p.sensors } else { &p.actuators };
                listed.iter().map(|(task, _)| task.as_str())
            });
            // A task's first mention only (a handful of tasks per robot).
            let earlier = mentions.clone();
            mentions
                .enumerate()
                .filter(move |&(k, task)| !earlier.clone().take(k).any(|t| t == task))
                .map(move |(_, task)| (task, sensor))
        })
    }
}

/// One battery requirement (`<Condition cond="Battery&lt;30">`) for one
/// robot: while `condition` holds, each listed sensor task samples every
/// `period × level` and each listed actuator task runs at `1 / level` of its
/// speed (a call takes `level` times as long); when it stops holding, they
/// return to level 1.
#[derive(Clone, Debug, PartialEq)]
pub struct BatteryPolicy {
    /// The condition as written (`Battery<30`): the trace names the policy by it.
    pub text: String,
    /// Over the robot's `BATTERY` slot.
    pub condition: Expr,
    /// The strategy file it comes from (for comments).
    pub source: String,
    /// (sensor task, period level), each a task of this robot.
    pub sensors: Vec<(String, u64)>,
    /// (actuator task, speed level), each a task of this robot.
    pub actuators: Vec<(String, u64)>,
}

/// How often a robot that can be elected leader tells its team it is alive
/// (mission ms) when its strategy names no `heartbeatPeriod`; a robot not
/// heard from for two periods (`protocol::lost_after_ms`) counts as failed.
pub const HEARTBEAT_MS: i64 = 200;

/// How a leader is chosen among the live candidates of a `leader(...)` arm:
/// the strategy's `LeaderSelectionInfo algorithm`, else
/// [`LeaderAlgorithm::LowestId`] (the first in formation order).
pub use crate::strategy::LeaderAlgorithm;

#[derive(Clone, Debug, PartialEq)]
pub struct ModeState {
    pub name: String,
    pub line: u32,
    /// One region per plan the mode runs (plans set to `OFF` have none).
    pub regions: Vec<Region>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub plan: String,
    pub service: ServiceMachineId,
    pub timeout_ms: Option<i64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ModeTransition {
    pub from: ModeId,
    pub event: String,
    pub to: ModeId,
    pub line: u32,
}

/// A composite service as a sequence of states; execution moves to the next
/// state unless a state says otherwise.
#[derive(Clone, Debug, PartialEq)]
pub struct ServiceMachine {
    pub plan: String,
    pub name: String,
    pub line: u32,
    pub states: Vec<State>,
    /// How many timers and marks the states use (loop starts, call
    /// starts): each [`MarkId`] of its states is below it.
    pub marks: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub kind: StateKind,
    /// The mission line the state comes from (1-based).
    pub line: u32,
    /// The mission text it comes from: the statement; for a loop's end and a
    /// `repeat`, the period when one is written (what the dataflow warnings
    /// point at).
    pub span: Span,
    /// The statement as written, for the comment beside the state.
    pub text: String,
}

#[derive(Clone, Debug, PartialEq)]
pub enum StateKind {
    /// Wait for one sample of each incoming message, storing each in its
    /// slot.
    Receive {
        messages: Vec<IncomingId>,
        /// `receive(...), timeout = P`: give up after P (mark holds the start).
        timeout_ms: Option<i64>,
        mark: MarkId,
    },
    /// Send each item (storing assigned values in their shared slot first).
    Send {
        items: Vec<SendItem>,
    },
    /// Read the latest published value of a group into its slot.
    Subscribe {
        group: SubscriptionId,
        slot: SlotId,
    },
    /// `throw E`: the current mode's catch of E asks for a mode change.
    /// With `broadcast` (`throw E broadcast`), the others of the thrower's
    /// group are told first ([`Broadcast`]).
    Throw {
        event: String,
        broadcast: Option<Broadcast>,
    },
    /// Call the task implementing a built-in service and wait until it is
    /// idle. `results`: the slots of the names the call binds
    /// (`FOUND, WHERE = search(red)`), in the order of the service's
    /// results: none from the call's start, then what the task gave back
    /// when it is done (they stay none after a timeout).
    Call {
        service: String,
        task: String,
        args: Vec<Operand>,
        timeout_ms: Option<i64>,
        mark: MarkId,
        results: Vec<SlotId>,
    },
    /// Run a strategy action machine to its final action.
    RunActions {
        service: String,
        machine: ActionMachineId,
        args: Vec<Operand>,
        timeout_ms: Option<i64>,
        mark: MarkId,
    },
    /// `leader(cond)` for a robot that meets `cond`: continue (run the
    /// leader's block) if `algorithm` chooses this robot among the live
    /// `candidates` (peer indices, in formation order), else go to
    /// `others_at`.
    ///
    /// `receives`: the incoming messages the leader's block receives. When
    /// this robot becomes the leader here (the last leader this state chose
    /// was another robot, or none yet), the messages waiting in their
    /// channels arrived before it led and are dropped: a leader-only
    /// `receive` takes only what arrived while this robot leads
    /// (`docs/groups.md`).
    LeaderBranch {
        candidates: Vec<PeerId>,
        algorithm: LeaderAlgorithm,
        others_at: StateId,
        receives: Vec<IncomingId>,
    },
    /// `[[ group(Name, min = N) ... ]]` (counted groups): give this robot a
    /// group from the `members` (peer indices, formation order: the robots
    /// that run the statement, as the checker decided) it knows alive (itself,
    /// and those heard from within `protocol::lost_after_ms` since it joined). The
    /// live members in formation order fill the groups up to their
    /// minimums in declaration order; a live member beyond the sum of the
    /// minimums (a spare) goes to `others_at` when the statement has
    /// `others`, else to the groups round-robin in declaration order. With
    /// fewer live members than the sum, the later groups are short
    /// ([`counted_allocation`]). The robot continues at its group's `at`;
    /// a change of its group is traced (`allocated`).
    ///
    /// Nested in arms of other counted groups (`within`, outermost first),
    /// the members are only those the enclosing statements put, by the same
    /// rule from the same view, in the arms this robot runs
    /// ([`members_sharing_arms`]): a room's robots split among themselves.
    /// `nested`: the statements of counted groups written in its arms (of
    /// this service): when this robot's group here changes, they forget the
    /// group they last gave it, so its group there is traced again.
    GroupAllocate {
        members: Vec<PeerId>,
        groups: Vec<CountedGroup>,
        others_at: Option<StateId>,
        within: Vec<EnclosingArm>,
        nested: Vec<StateId>,
    },
    /// The start of a group statement when the team's strategy has
    /// `<GroupSync timeout>`: tell the team this robot has arrived (its
    /// pass through the statement: `Team.__sync` = `"<point> <pass>"`), then
    /// wait until every other robot of `members` (peer indices: the robots
    /// that run any arm of the statement, as the checker decided) has
    /// arrived at that pass or is known dead (no heartbeat for three
    /// periods), or `timeout_ms` has passed.
    GroupSync {
        members: Vec<PeerId>,
        point: SyncPointId,
        timeout_ms: i64,
        mark: MarkId,
    },
    /// Continue at `else_to` unless the condition holds.
    Branch {
        condition: Expr,
        else_to: StateId,
    },
    Jump {
        to: StateId,
    },
    /// Head of `loop(period?, condition?)`: leave to `exit_to` when the
    /// condition fails; mark the iteration's start.
    LoopHead {
        condition: Option<Expr>,
        exit_to: StateId,
        mark: MarkId,
    },
    /// End of a loop body: wait for the period (from the mark), then `to`.
    LoopTail {
        period_ms: Option<i64>,
        mark: MarkId,
        to: StateId,
    },
    /// After the body: `repeat(period?, condition?)`; `forever` for `repeat()`;
    /// neither means the service runs once.
    Repeat {
        period_ms: Option<i64>,
        condition: Option<Expr>,
        forever: bool,
    },
}

/// Who a `throw E broadcast` tells ([`StateKind::Throw`]): the messages
/// (key [`event_key`], the event's name as text) to the others of the
/// thrower's group, one to the team when the group is the whole team, else
/// one to each other robot of it; none when the thrower is the group's only
/// robot.
///
/// Written in arms of counted groups (`within`, outermost first), the group
/// is the one this robot runs at run time: there is one message to each
/// other robot that may run the arm (`to`, the peer of each message, in
/// formation order), and only those [`members_sharing_arms`] keeps, by the
/// rule and the view of who is alive that allocated this robot, are told.
/// Outside counted groups `within` and `to` are empty.
#[derive(Clone, Debug, PartialEq)]
pub struct Broadcast {
    pub messages: Vec<OutgoingId>,
    pub to: Vec<PeerId>,
    pub within: Vec<EnclosingArm>,
}

/// One arm of a statement of counted groups ([`StateKind::GroupAllocate`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CountedGroup {
    pub name: String,
    pub min: usize,
    /// The first state of the arm's block.
    pub at: StateId,
}

/// An arm of counted groups that a nested statement of counted groups is
/// written in ([`StateKind::GroupAllocate`]'s `within`).
#[derive(Clone, Debug, PartialEq)]
pub struct EnclosingArm {
    /// The enclosing statement's members (formation order).
    pub members: Vec<PeerId>,
    /// Its groups' minimums (declaration order).
    pub mins: Vec<usize>,
    pub has_others: bool,
    /// The arm: `Some(k)`, the `k`-th group; `None`, `others`.
    pub arm: Option<usize>,
}

/// The members of a nested statement of counted groups that this robot
/// (`me`) splits with: those of `members` that are alive and that every
/// enclosing statement (`within`, outermost first) puts in the arm the
/// statement is written in, each level's rule ([`counted_allocation`])
/// applied to the live robots the levels above kept, in formation order;
/// and `me` itself, which runs the statement whatever its view says. With
/// no enclosing arm, the live members. One rule for the simulator and the
/// generated C (`narrow_to_arm` in `codegen/control.rs`). Every list is
/// ascending, so each level is one merge: linear in the members.
pub fn members_sharing_arms(
    within: &[EnclosingArm],
    members: &[PeerId],
    me: PeerId,
    alive: impl Fn(PeerId) -> bool,
) -> Vec<PeerId> {
    let mut kept: Option<Vec<PeerId>> = None;
    for level in within {
        let mut next = Vec::new();
        let mut position = 0;
        let mut cursor = Ascending::new(kept.as_deref());
        for &peer in &level.members {
            if !cursor.holds(peer) || !alive(peer) {
                continue;
            }
            if counted_allocation(&level.mins, level.has_others, position) == level.arm {
                next.push(peer);
            }
            position += 1;
        }
        kept = Some(next);
    }
    let mut cursor = Ascending::new(kept.as_deref());
    members
        .iter()
        .copied()
        .filter(|&peer| (cursor.holds(peer) && alive(peer)) || peer == me)
        .collect()
}

/// Membership in an ascending list, asked in ascending order: one merge.
/// `None` holds every peer.
struct Ascending<'a> {
    list: Option<&'a [PeerId]>,
    at: usize,
}

impl<'a> Ascending<'a> {
    fn new(list: Option<&'a [PeerId]>) -> Self {
        Ascending { list, at: 0 }
    }

    fn holds(&mut self, peer: PeerId) -> bool {
        let Some(list) = self.list else {
            return true;
        };
        while self.at < list.len() && list[self.at] < peer {
            self.at += 1;
        }
        self.at < list.len() && list[self.at] == peer
    }
}

/// Where a statement of counted groups puts the live member at `position`
/// (its place among the live members, formation order): `Some(k)`, the
/// `k`-th group (declaration order), or `None`, `others`. The one rule the
/// simulator and the generated C (`group_of` in `codegen/control.rs`)
/// follow: the minimums are filled in declaration order; a spare goes to
/// `others` when there is one (`has_others`), else round-robin.
pub fn counted_allocation(mins: &[usize], has_others: bool, position: usize) -> Option<usize> {
    let mut filled = 0usize;
    for (k, &min) in mins.iter().enumerate() {
        filled = filled.saturating_add(min);
        if position < filled {
            return Some(k);
        }
    }
    if has_others || mins.is_empty() {
        return None;
    }
    Some((position - filled) % mins.len())
}

/// One value of a `send`/`publish`.
#[derive(Clone, Debug, PartialEq)]
pub struct SendItem {
    pub message: OutgoingId,
    pub value: Operand,
    /// `send(T, T.X = v)`: the shared slot `v` is stored in first.
    pub store: Option<SlotId>,
    /// A publication of a value this robot also subscribes to: the group it
    /// is written to at once, since the latest value team T published
    /// includes the robot's own.
    pub own_group: Option<SubscriptionId>,
}

/// A strategy entry's actions: the bottom level of the machine.
#[derive(Clone, Debug, PartialEq)]
pub struct ActionMachine {
    pub service: String,
    /// `Strategy file` line of the `<Service>` element.
    pub source: String,
    pub actions: Vec<ActionState>,
    pub initial: ActionId,
    /// Slots of the `variable` parameters set from the call's arguments, in order.
    pub arguments: Vec<SlotId>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ActionState {
    pub name: String,
    pub id: u64,
    pub is_final: bool,
    /// Actuator and algorithm commands issued on entry: (task, what it is
    /// given: a value as written, a sensor reading, the call's argument).
    pub commands: Vec<(String, Operand)>,
    /// Checked in order; the first that holds is taken. `None` = always.
    pub transitions: Vec<(Option<Expr>, ActionId)>,
}

/// A value of the machine and where it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    /// `MasterTeam.LOCATION`, `USER.RC_CMD`, or `move.goalLocation`.
    pub key: String,
    pub source: SlotSource,
    /// How its values are stored: the catalog's type of the value (of the
    /// service parameter for a strategy variable).
    pub kind: ValueKind,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SlotSource {
    /// The latest sample of a sensor task's output port.
    Sensor { task: String, port: String },
    /// Received from another robot, or set by `send(T, T.X = ...)`: held by
    /// the team's library task.
    Shared,
    /// A strategy variable parameter (set from a call's argument).
    Local,
    /// An action result (`FOUND` of `FOUND, WHERE = search(red)`): set by
    /// the control task when a call binding it starts (none) and ends.
    Result,
}

#[derive(Clone, Debug, PartialEq)]
pub struct OutgoingMessage {
    pub to_team: String,
    pub publish: bool,
    pub key: String,
    /// The control task's port (and the comm task's input port).
    pub port: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IncomingMessage {
    pub from_team: String,
    pub key: String,
    pub slot: SlotId,
    pub port: String,
}

/// The team's shared information (library task `lib_<name>`).
#[derive(Clone, Debug)]
pub struct SharedLibrary {
    pub name: String,
    /// Slot keys it holds a getter and a setter for.
    pub attributes: Vec<String>,
    /// Who holds the globally shared attributes (`docs/shared-information.md`);
    /// `None` when every attribute is a local copy (the team has one robot,
    /// or the library holds only other teams' values and multicast values).
    pub ownership: Option<Ownership>,
}

impl SharedLibrary {
    /// The key of attribute `id` of [`SharedLibrary::attributes`].
    pub fn attribute(&self, id: AttributeId) -> &str {
        &self.attributes[id.index()]
    }
}

/// The globally shared attributes of a team's library and the robots that
/// own them in turn: one robot of `owners` holds them, the others set them
/// through messages to it and read what it last told them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ownership {
    /// The globally shared attributes.
    pub global: Vec<GlobalValue>,
    /// Peer indices (into `RobotProgram::peers`) of the team's robots that
    /// may own them, in the order ownership passes when an owner is lost;
    /// the first is the owner at start: the strategy's `<SharedOwner>` and
    /// then the others in formation order, else the team's leader order
    /// (`lowest_id`, `highest_battery`: formation order; `bully`: the
    /// reverse).
    pub owners: Vec<PeerId>,
    /// Who follows a lost owner.
    pub rule: OwnerRule,
}

/// How the owner of a team's globally shared values is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OwnerRule {
    /// The strategy's `<SharedOwner>` first, then the first live robot of
    /// the owner order.
    Named,
    /// The team's leader by its leader selection (`LeaderSelectionInfo`
    /// without a composite service, else `lowest_id`) over the robots that
    /// hold the values: `lowest_id` and `bully` the first live robot of the
    /// owner order (formation order, reversed for `bully`);
    /// `highest_battery` the live one whose last heartbeat said the highest
    /// battery level (the first of equals; unknown counts lowest), the first
    /// of the order at start, when no level has been heard yet.
    Leader(LeaderAlgorithm),
}

impl OwnerRule {
    /// A lost owner is followed by the live robot with the highest battery.
    pub fn by_battery(self) -> bool {
        self == OwnerRule::Leader(LeaderAlgorithm::HighestBattery)
    }
}

/// One globally shared attribute of a library.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GlobalValue {
    /// Its place in [`SharedLibrary::attributes`].
    pub at: AttributeId,
    /// The type of its values (its shared slot's): a value of another type
    /// received is refused.
    pub kind: ValueKind,
    /// The key of a write sent to the owner (`Team.__set.X`).
    pub set_key: String,
    /// The key of the owner's value told to the team (`Team.__value.X`).
    pub value_key: String,
}

/// A non-control task of the robot and its job.
#[derive(Clone, Debug)]
pub struct TaskRole {
    pub task: String,
    pub kind: RoleKind,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RoleKind {
    /// Produces these values (port name = value name), every period.
    Sensor {
        values: Vec<String>,
        period_ms: i64,
    },
    /// Runs built-in services or actuator commands on request.
    Service {
        services: Vec<String>,
    },
    CommSend,
    CommReceive,
}

/// An expression of the machine: comparisons of operands.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Or(Box<Expr>, Box<Expr>),
    And(Box<Expr>, Box<Expr>),
    Not(Box<Expr>),
    /// Compared as the checker typed the comparison (numbers by value, words
    /// by text).
    Compare(
        Operand,
        crate::syntax::ast::CmpOp,
        Operand,
        crate::sema::Compared,
    ),
    /// A bare attribute as a condition: its value is `true` or non-zero.
    Truthy(Operand),
    Bool(bool),
}

impl Expr {
    /// Calls `f` on every operand of the expression, left to right.
    pub fn for_each_operand(&self, f: &mut dyn FnMut(&Operand)) {
        match self {
            Expr::Or(a, b) | Expr::And(a, b) => {
                a.for_each_operand(f);
                b.for_each_operand(f);
            }
            Expr::Not(a) => a.for_each_operand(f),
            Expr::Compare(a, _, b, _) => {
                f(a);
                f(b);
            }
            Expr::Truthy(o) => f(o),
            Expr::Bool(_) => {}
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Operand {
    Slot(SlotId),
    /// A literal, typed as written: a whole number an integer, another number
    /// a real, a string text, `true`/`false` a truth value, a symbolic
    /// constant a word.
    Literal(Value),
}

impl ControlMachine {
    /// The kind of the value a sensor task writes to `port` (the slot it feeds).
    pub fn sensor_kind(&self, task: &str, port: &str) -> Option<&ValueKind> {
        self.slots.iter().find_map(|s| match &s.source {
            SlotSource::Sensor { task: t, port: p } if t == task && p == port => Some(&s.kind),
            _ => None,
        })
    }
}
