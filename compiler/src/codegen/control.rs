//! `control_task.c`: the control task's hierarchical state machine as C.
//!
//! Every firing (one per control period) the task reads its inputs, then
//! advances each region of the current mode until it waits, and finally
//! applies a mode change that an event asked for. A region's service is a
//! `switch` over its states (`pc`); a state returns `STEP_NEXT` (go on in
//! this firing), `STEP_WAIT` (try again next firing) or `STEP_DONE`.

use super::c;
use super::peers::Peers;
use super::template::{Template, fill, template};
use super::values::Words;
use crate::refine::graph::{CONTROL_TASK, getter, setter};
use crate::refine::protocol::{self, TERM_MAX, UNLED_REASON, lease_ms, listen_ms, lost_after_ms};
use crate::refine::{
    ActionMachine, ActionMachineId, Broadcast, ControlMachine, CountedGroup, EnclosingArm, Expr,
    IncomingId, LeaderAlgorithm, MarkId, ModeId, Operand, OutgoingId, PeerId, RobotProgram,
    SendItem, SlotId, SlotSource, State, StateId, StateKind, SubscriptionId, SyncPointId,
    ValueKind, event_key,
};
use std::fmt::Write;

/// The region record, the mode variables and `wake_at`, before the machine.
const REGION: Template = template!("control/region.c.in", []);
/// `catch_event`'s head, before the `switch` of its catches.
const CATCH_EVENT_HEAD: Template = template!("control/catch_event_head.c.in", []);
/// `throw_event` beside `catch_event`.
const THROW_EVENT: Template = template!("control/throw_event.c.in", []);
/// `throw_event`'s head, before its own `switch` of catches (a program that
/// neither broadcasts nor hears events).
const THROW_EVENT_HEAD: Template = template!("control/throw_event_head.c.in", []);
const THROW_BROADCAST: Template = template!("control/throw_broadcast.c.in", []);
const TAKE_EVENTS: Template = template!("control/take_events.c.in", []);
/// `request`: a service request written to its task's queue.
const REQUEST: Template = template!("control/request.c.in", []);
/// The states, one template per kind (or per part of one).
const RECEIVE_TIMEOUT: Template = template!(
    "control/receive_timeout.c.in",
    ["mark", "ready", "t", "next"]
);
const CALL_REQUEST: Template = template!(
    "control/call_request.c.in",
    [
        "port", "task", "service", "argc", "args", "mark", "wake", "started"
    ]
);
const CALL_TIMEOUT: Template = template!(
    "control/call_timeout.c.in",
    ["mark", "t", "task", "service"]
);
const CALL_WAIT: Template = template!("control/call_wait.c.in", ["task", "next", "taken"]);
const REPLIES: Template = template!("control/replies.c.in", ["tasks", "most", "names"]);
const ACTIONS_ENTER: Template =
    template!("control/actions_enter.c.in", ["initial", "mark", "service"]);
const ACTIONS_TIMEOUT: Template = template!(
    "control/actions_timeout.c.in",
    ["mark", "t", "service", "next"]
);
const ACTIONS_RUN: Template = template!("control/actions_run.c.in", ["machine", "service", "next"]);
const LEADER_BRANCH: Template = template!("control/leader_branch.c.in", ["election"]);
/// `election_K`: the election of a `leader(...)` statement, called at its
/// state and at each heartbeat ([`ControlMachine::elections`]).
const ELECTION: Template = template!(
    "control/election.c.in",
    [
        "election",
        "line",
        "list",
        "count",
        "algorithm",
        "led",
        "drop"
    ]
);
const GROUP_ALLOCATE: Template = template!(
    "control/group_allocate.c.in",
    [
        "members_list",
        "mins",
        "names",
        "at",
        "groups",
        "has_others",
        "others",
        "narrow",
        "sharing",
        "last",
        "forget",
        "statement"
    ]
);
const GROUP_SYNC: Template = template!(
    "control/group_sync.c.in",
    [
        "list",
        "mark",
        "count",
        "offset",
        "team",
        "key",
        "point",
        "lost",
        "timeout_ms",
        "line",
        "next"
    ]
);
/// A strategy's action machine's head, before its actions.
const ACTIONS_HEAD: Template =
    template!("control/actions_head.c.in", ["service", "source", "index"]);
const ENTER_MODE_HEAD: Template = template!("control/enter_mode_head.c.in", []);
const ENTER_MODE_TAIL: Template = template!("control/enter_mode_tail.c.in", []);
const LEAVE_MODE_HEAD: Template = template!("control/leave_mode_head.c.in", []);
/// The control task's firing: its head, the heartbeat, its tail.
const GO_HEAD: Template = template!("control/go_head.c.in", ["name"]);
const HEARTBEAT: Template = template!(
    "control/heartbeat.c.in",
    ["hb", "elect", "team", "key", "group"]
);
const GO_TAIL: Template = template!(
    "control/go_tail.c.in",
    ["steps_per_firing", "flush", "name"]
);
const GROUP_UPDATE: Template = template!("control/group_update.c.in", ["list", "count", "lost"]);

/// Every template of `control_task.c`.
#[cfg(test)]
pub(super) const TEMPLATES: &[Template] = &[
    DROP_UNLED,
    ELECTED,
    GROUP_OF,
    NARROW_TO_ARM,
    THROW_BROADCAST_WITHIN,
    LEADING,
    REGION,
    CATCH_EVENT_HEAD,
    THROW_EVENT,
    THROW_EVENT_HEAD,
    THROW_BROADCAST,
    TAKE_EVENTS,
    REQUEST,
    RECEIVE_TIMEOUT,
    CALL_REQUEST,
    CALL_TIMEOUT,
    CALL_WAIT,
    REPLIES,
    ACTIONS_ENTER,
    ACTIONS_TIMEOUT,
    ACTIONS_RUN,
    LEADER_BRANCH,
    ELECTION,
    GROUP_ALLOCATE,
    GROUP_SYNC,
    ACTIONS_HEAD,
    ENTER_MODE_HEAD,
    ENTER_MODE_TAIL,
    LEAVE_MODE_HEAD,
    GO_HEAD,
    HEARTBEAT,
    GO_TAIL,
    GROUP_UPDATE,
];

/// State transitions a region may take in one firing: a service whose
/// states never wait (only sends and branches) still yields to the others.
const STEPS_PER_FIRING: usize = 64;

/// Drops what a channel holds now, oldest first, each traced: a robot that
/// has just become the leader drops the messages waiting for its leader's
/// block (`StateKind::LeaderBranch`). Only the count seen first: a message
/// the receive task writes meanwhile arrived after.
const DROP_UNLED: Template = template!("control/drop_unled.c.in", ["reason"]);

/// Leader elections (`hb`: the heartbeat period, `listen`: [`listen_ms`],
/// `lease`: [`lease_ms`], `term_max`: [`TERM_MAX`]).
/// `leading` is what this robot's heartbeats say: whether the last election
/// it decided named it. A robot that joined a mission under way (restarted:
/// its mission time was past one heartbeat period when it started, or the
/// MQTT broker still held its session) listens first, and while another
/// live robot claims leadership it follows that robot instead of claiming:
/// the claimant gives way at its own next election, so that two robots never
/// both lead after a restart.
const ELECTED: Template = template!(
    "control/elected.c.in",
    ["hb", "lost", "listen", "lease", "term_max"]
);

/// At each heartbeat of a member of its team's group (group services,
/// `docs/groups.md`): its rank among the live members (formation order) and
/// their number, for `semo_group_rank()`/`semo_group_size()`. A member is
/// alive when it is this robot or was heard from within [`lost_after_ms`]
/// (counted from when this robot joined: until then it had no chance to
/// hear, so a robot starting or restarting counts every member alive).
fn group_update(m: &ControlMachine, peers: &Peers) -> String {
    if m.group.is_empty() {
        return String::new();
    }
    fill(
        &GROUP_UPDATE,
        &[
            ("list", &peers.locals(&m.group)),
            ("count", &m.group.len()),
            ("lost", &lost_after_ms(m.heartbeat_ms)),
        ],
    )
}

/// Counted groups (`StateKind::GroupAllocate`): the rule of
/// `refine::counted_allocation` over the live members, as the simulator's
/// `GroupAllocate` applies it.
const GROUP_OF: Template = template!("control/group_of.c.in", ["lost"]);

/// Nested counted groups: the members a robot splits with, by the rule of
/// `refine::members_sharing_arms`.
const NARROW_TO_ARM: Template = template!("control/narrow_to_arm.c.in", []);
/// `throw E broadcast` in arms of counted groups: told to those of the other
/// robots that may run the arm (`to`, their ports `ports`) that share this
/// robot's arms now (`Broadcast` in `refine`).
const THROW_BROADCAST_WITHIN: Template = template!(
    "control/throw_broadcast_within.c.in",
    [
        "narrow", "to", "ports", "n", "kept", "n_kept", "event", "key"
    ]
);

/// `leading` and the terms a robot's heartbeats say, and `own_battery`:
/// this robot's battery level for its heartbeats, the scenario's (in
/// simulation), else unknown (-1).
const LEADING: Template = template!("control/leading.c.in", []);

pub fn control_task(program: &RobotProgram, words: &Words, peers: &Peers, header: &str) -> String {
    let m = &program.control;
    let mut out = String::new();
    out.push_str(header);
    out.push_str("#include \"program.h\"\n");
    if m.heartbeat {
        out.push_str("#include <stdio.h>\n");
    }
    out.push_str("#include <string.h>\n\n");
    let _ = writeln!(
        out,
        "/* The hierarchical state machine of robot {} (team {}): modes, then one\n * region per plan running its composite service, then strategy actions. */\n",
        c::comment(&program.robot),
        c::comment(&program.team)
    );
    out.push_str("enum { STEP_NEXT, STEP_WAIT, STEP_DONE };\n\n");

    // Values.
    let _ = writeln!(out, "/* Values the machine reads and writes. */");
    // A robot that reads no values has no slots (an unused array fails -Werror).
    if !m.slots.is_empty() {
        let _ = writeln!(out, "static semo_value slot[{}];", m.slots.len());
    }
    for (i, s) in m.slots.iter().enumerate() {
        let from = match &s.source {
            SlotSource::Sensor { task, .. } => format!("sensor task {task}"),
            SlotSource::Shared => "shared information (library)".into(),
            SlotSource::Local => "strategy variable".into(),
            SlotSource::Result => "action result".into(),
        };
        let _ = writeln!(
            out,
            "/* slot[{i}]: {} ({from}): {} */",
            c::comment(&s.key),
            c::comment(&s.kind.describe())
        );
    }
    out.push('\n');

    // Ports.
    // Modes.
    out.push_str("/* Modes (top level). */\nenum {");
    let idents = mode_idents(m);
    for (i, ident) in idents.iter().enumerate() {
        let _ = write!(out, "{}MODE_{ident}", if i == 0 { " " } else { ", " });
    }
    if m.modes.is_empty() {
        out.push_str(" MODE_NONE_");
    }
    out.push_str(" };\nstatic const char *const mode_name[] = {");
    for (i, mode) in m.modes.iter().enumerate() {
        let _ = write!(
            out,
            "{}{}",
            if i == 0 { " " } else { ", " },
            c::string(&mode.name)
        );
    }
    if m.modes.is_empty() {
        out.push_str(" \"\"");
    }
    out.push_str(" };\n\n");

    let regions = m.region_count();
    let marks = m.mark_count();
    let _ = writeln!(
        out,
        "#define REGION_COUNT {regions}\n#define MARK_COUNT {marks}"
    );
    out.push_str(REGION.text);

    // The machine first, so that only the helpers and port tables it uses
    // are written (unused static functions and arrays fail -Werror).
    let mut body = String::new();
    for (i, machine) in m.actions.iter().enumerate() {
        emit_action_machine(&mut body, program, words, i, machine);
    }
    for (k, election) in m.elections().enumerate() {
        emit_election(&mut body, program, peers, k, &election);
    }
    // `election_K` of each `LeaderBranch` state, counted in the order of
    // `ControlMachine::elections`.
    let mut election = 0;
    for (i, service) in m.services.iter().enumerate() {
        // The group each statement of counted groups last gave this robot
        // (-1 others, -2 none yet): at file scope, so that a statement can
        // make the ones nested in its arms forget theirs.
        for (pc, state) in service.states.iter().enumerate() {
            if matches!(state.kind, StateKind::GroupAllocate { .. }) {
                let _ = writeln!(body, "static long allocated_{i}_{pc} = -2;");
            }
        }
        let _ = writeln!(
            body,
            "/* {}.{}.{} ({}:{}) */\nstatic int service_{i}(region *r)\n{{\n    switch (r->pc) {{",
            c::comment(&program.team),
            c::comment(&service.plan),
            c::comment(&service.name),
            c::comment(&program.mission),
            service.line
        );
        for (pc, state) in service.states.iter().enumerate() {
            emit_state(&mut body, program, words, peers, (i, pc, election), state);
            if matches!(state.kind, StateKind::LeaderBranch { .. }) {
                election += 1;
            }
        }
        body.push_str("    default:\n        return STEP_DONE;\n    }\n}\n\n");
    }
    body.push_str(&super::battery::resource_manager(program, words));
    emit_dispatch(&mut body, program);
    emit_modes(&mut body, program);
    emit_task(&mut body, program, peers);
    let mut helpers = String::new();
    emit_helpers(&mut helpers, program, &body);
    let tables = [
        (
            "sensor_port",
            m.slots
                .iter()
                .filter(|s| matches!(s.source, SlotSource::Sensor { .. }))
                .count(),
        ),
        ("request_port", m.request_tasks.len()),
        ("out_port", m.outgoing.len()),
        ("in_port", m.incoming.len()),
    ];
    for (name, len) in tables {
        if len > 0 {
            let _ = writeln!(out, "static int {name}[{len}];");
        }
    }
    out.push('\n');
    out.push_str(&helpers);
    out.push_str(&body);
    out
}

/// A program that broadcasts or hears events: `catch_event` (the current
/// mode's catch, with the thrower of a broadcast one), the throws `body`
/// uses, and `take_events` (the broadcast events received since the last
/// firing, `comm_event_take`) when it hears any. A program without either
/// keeps `throw_event` as it always was.
fn emit_catch_event(out: &mut String, program: &RobotProgram, throws: bool, broadcasts: bool) {
    let m = &program.control;
    out.push_str(CATCH_EVENT_HEAD.text);
    emit_catches(
        out,
        program,
        "semo_trace(\"catch\", \"name\", event, \"mode\", mode_name[pending_mode], from ? \"from\" : NULL, from, NULL);\n            return true;",
    );
    out.push_str("    return false;\n}\n\n");
    if throws {
        out.push_str(THROW_EVENT.text);
    }
    if broadcasts {
        out.push_str(THROW_BROADCAST.text);
    }
    if !m.events_heard.is_empty() {
        out.push_str(TAKE_EVENTS.text);
    }
}

/// The `switch` on the current mode of `throw_event` and `catch_event`: per
/// mode with catches, per catch of `event`, the mode change asked for and
/// then `caught` (C statements, indented for the case).
fn emit_catches(out: &mut String, program: &RobotProgram, caught: &str) {
    let m = &program.control;
    out.push_str("    switch (current_mode) {\n");
    let idents = mode_idents(m);
    for (from, ident) in ModeId::all(m.modes.len()).zip(&idents) {
        let catches: Vec<_> = m.transitions.iter().filter(|t| t.from == from).collect();
        if catches.is_empty() {
            continue;
        }
        let _ = writeln!(out, "    case MODE_{ident}:");
        for t in catches {
            let _ = writeln!(
                out,
                "        if (strcmp(event, {}) == 0 && pending_mode < 0) {{ /* {}:{} */\n            pending_mode = MODE_{};\n            {caught}\n        }}",
                c::string(&t.event),
                c::comment(&program.mission),
                t.line,
                idents[t.to.index()]
            );
        }
        out.push_str("        break;\n");
    }
    out.push_str("    default:\n        break;\n    }\n");
}

/// The helpers `body` calls: `store`, `read_inputs`, `throw_event`, `request`.
fn emit_helpers(out: &mut String, program: &RobotProgram, body: &str) {
    let m = &program.control;
    let uses = |name: &str| body.contains(&format!("{name}("));
    // Storing a shared value goes through the library task.
    if uses("store") {
        out.push_str("/* Stores a value in its slot and, for shared information, in the library task. */\nstatic void store(int s, const semo_value *v)\n{\n    if (&slot[s] != v)\n        slot[s] = *v;\n    switch (s) {\n");
        for (i, s) in m.slots.iter().enumerate() {
            if s.source == SlotSource::Shared
                && let Some(lib) = &program.library
            {
                let _ = writeln!(
                    out,
                    "    case {i}:\n        LIBCALL(shared, {}_{}, &slot[{i}]);\n        break;",
                    c::ident(&lib.name),
                    setter(&s.key)
                );
            }
        }
        out.push_str("    default:\n        break;\n    }\n}\n\n");
    }

    out.push_str("/* Reads the inputs at the start of a firing: the latest sensor samples and\n * the shared information. */\nstatic void read_inputs(void)\n{\n");
    let mut sensor = 0;
    for (i, s) in m.slots.iter().enumerate() {
        match &s.source {
            SlotSource::Sensor { port, .. } => {
                let _ = writeln!(
                    out,
                    "    while (UFPort_GetNumOfAvailableData(sensor_port[{sensor}]) > 0)\n        UFPort_ReadFromQueue(sensor_port[{sensor}], &slot[{i}], sizeof slot[{i}]);"
                );
                if port == crate::refine::BATTERY_VALUE {
                    // The robot's status carries the level it read.
                    let _ = writeln!(out, "    semo_battery_report(&slot[{i}]);");
                }
                sensor += 1;
            }
            SlotSource::Shared => {
                if let Some(lib) = &program.library {
                    let _ = writeln!(
                        out,
                        "    slot[{i}] = LIBCALL(shared, {}_{}, );",
                        c::ident(&lib.name),
                        getter(&s.key)
                    );
                }
            }
            SlotSource::Local | SlotSource::Result => {}
        }
    }
    if let Some(lib) = program.library.as_ref().filter(|l| l.ownership.is_some()) {
        // The getters ask who owns the values when they are read; the
        // firing that finds a lost owner comes when it is lost.
        let _ = writeln!(
            out,
            "    wake_at({}_owner_lost_at());",
            super::shared::prefix(lib)
        );
    }
    out.push_str("}\n\n");

    let broadcasts = uses("throw_broadcast") || !m.events_heard.is_empty();
    if broadcasts {
        emit_catch_event(out, program, uses("throw_event"), uses("throw_broadcast"));
    } else if uses("throw_event") {
        out.push_str(THROW_EVENT_HEAD.text);
        emit_catches(
            out,
            program,
            "semo_trace(\"catch\", \"name\", event, \"mode\", mode_name[pending_mode], NULL);",
        );
        out.push_str("}\n\n");
    }

    if m.heartbeat {
        out.push_str(LEADING.text);
    }
    if uses("elected") {
        out.push_str(&fill(
            &ELECTED,
            &[
                ("hb", &m.heartbeat_ms),
                ("lost", &lost_after_ms(m.heartbeat_ms)),
                ("listen", &listen_ms(m.heartbeat_ms)),
                ("lease", &lease_ms(m.heartbeat_ms)),
                ("term_max", &TERM_MAX),
            ],
        ));
    }

    if uses("group_of") {
        out.push_str(&fill(
            &GROUP_OF,
            &[("lost", &lost_after_ms(m.heartbeat_ms))],
        ));
    }

    if uses("narrow_to_arm") {
        out.push_str(NARROW_TO_ARM.text);
    }

    if uses("drop_unled") {
        out.push_str(&fill(&DROP_UNLED, &[("reason", &c::string(UNLED_REASON))]));
    }

    if uses("request") {
        out.push_str(REQUEST.text);
    }

    if uses("take_result") {
        let most = m
            .services
            .iter()
            .flat_map(|s| &s.states)
            .filter_map(|state| match &state.kind {
                StateKind::Call { results, .. } => Some(results.len()),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        let names: Vec<String> = m.request_tasks.iter().map(|t| c::string(t)).collect();
        out.push_str(&fill(
            &REPLIES,
            &[
                ("tasks", &m.request_tasks.len()),
                ("most", &most),
                ("names", &names.join(", ")),
            ],
        ));
    }
}

fn request_index(program: &RobotProgram, task: &str) -> usize {
    program
        .control
        .request_tasks
        .iter()
        .position(|t| t == task)
        .unwrap_or(0)
}

fn args_array(args: &[Operand], words: &Words) -> String {
    if args.is_empty() {
        return "NULL".into();
    }
    let items: Vec<String> = args.iter().map(|a| words.operand(a)).collect();
    format!("(const semo_value *const[]){{{}}}", items.join(", "))
}

/// A robot that has just become the leader here (`led`: the leader before,
/// `leader`: the variable of the leader now) drops what waits for the
/// receives of the leader's block (`receives`).
fn emit_drop_unled(
    out: &mut String,
    program: &RobotProgram,
    receives: &[IncomingId],
    leader: &str,
) {
    if receives.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "    if (chosen > 0 && led != {leader}) {{ /* it leads from now on */"
    );
    for &k in receives {
        let incoming = program.control.incoming_message(k);
        let _ = writeln!(
            out,
            "        drop_unled(in_port[{k}], {}, {});",
            c::string(&incoming.from_team),
            c::string(&incoming.key)
        );
    }
    out.push_str("    }\n");
}

/// What the C of every state reads: the program, its words and peers, the
/// state's line in the mission and the state after it.
#[derive(Clone, Copy)]
struct StateCx<'a> {
    program: &'a RobotProgram,
    words: &'a Words,
    peers: &'a Peers,
    /// The index of the state's election among
    /// [`ControlMachine::elections`] (for a `LeaderBranch` state).
    election: usize,
    /// The state's service (`service_K`) and its own number.
    service: usize,
    pc: usize,
    next: usize,
    line: u32,
}

/// One state of a region's service: a `case` of its `switch`, written by
/// the function of its kind (one per `StateKind`, in the order of the
/// simulator's step).
fn emit_state(
    out: &mut String,
    program: &RobotProgram,
    words: &Words,
    peers: &Peers,
    (service, pc, election): (usize, usize, usize),
    state: &State,
) {
    let _ = writeln!(
        out,
        "    case {pc}: /* line {}: {} */",
        state.line,
        c::comment(&state.text)
    );
    let cx = StateCx {
        program,
        words,
        peers,
        election,
        service,
        pc,
        next: pc + 1,
        line: state.line,
    };
    match &state.kind {
        StateKind::Receive {
            messages,
            timeout_ms,
            mark,
        } => emit_receive(out, &cx, messages, timeout_ms, mark),
        StateKind::Send { items } => emit_send(out, &cx, items),
        StateKind::Subscribe { group, slot } => emit_subscribe(out, &cx, group, slot),
        StateKind::Throw {
            event,
            broadcast: None,
        } => emit_throw(out, &cx, event),
        StateKind::Throw {
            event,
            broadcast: Some(broadcast),
        } => emit_throw_broadcast(out, &cx, event, broadcast),
        StateKind::Call {
            service,
            task,
            args,
            timeout_ms,
            mark,
            results,
        } => emit_call(out, &cx, service, task, args, (timeout_ms, mark), results),
        StateKind::RunActions {
            service,
            machine,
            args,
            timeout_ms,
            mark,
        } => emit_run_actions(out, &cx, service, machine, args, timeout_ms, mark),
        StateKind::LeaderBranch { others_at, .. } => emit_leader_branch(out, &cx, others_at),
        StateKind::GroupAllocate {
            members,
            groups,
            others_at,
            within,
            nested,
        } => emit_group_allocate(out, &cx, members, groups, others_at, (within, nested)),
        StateKind::GroupSync {
            members,
            point,
            timeout_ms,
            mark,
        } => emit_group_sync(out, &cx, members, point, timeout_ms, mark),
        StateKind::Branch { condition, else_to } => emit_branch(out, &cx, condition, else_to),
        StateKind::Jump { to } => emit_jump(out, &cx, to),
        StateKind::LoopHead {
            condition,
            exit_to,
            mark,
        } => emit_loop_head(out, &cx, condition, exit_to, mark),
        StateKind::LoopTail {
            period_ms,
            mark,
            to,
        } => emit_loop_tail(out, &cx, period_ms, mark, to),
        StateKind::Repeat {
            period_ms,
            condition,
            forever,
        } => emit_repeat(out, &cx, period_ms, condition, forever),
    }
}

/// `receive(...)`: waits until every message has come (or its timeout), then stores them.
fn emit_receive(
    out: &mut String,
    cx: &StateCx,
    messages: &[IncomingId],
    timeout_ms: &Option<i64>,
    mark: &MarkId,
) {
    let StateCx { program, next, .. } = *cx;
    let m = &program.control;
    let ready: Vec<String> = messages
        .iter()
        .map(|i| format!("UFPort_GetNumOfAvailableData(in_port[{i}]) > 0"))
        .collect();
    let ready = ready.join(" && ");
    match timeout_ms {
        // `receive(...), timeout = P`: go on without the values after P.
        Some(t) => {
            out.push_str(&fill(
                &RECEIVE_TIMEOUT,
                &[
                    ("mark", &mark),
                    ("ready", &ready),
                    ("t", &t),
                    ("next", &next),
                ],
            ));
        }
        None => {
            let _ = writeln!(
                out,
                "        if (!({ready}))\n            return STEP_WAIT;"
            );
        }
    }
    for &i in messages {
        let s = m.incoming_message(i).slot;
        let _ = writeln!(
            out,
            "        {{\n            semo_value v;\n            if (UFPort_ReadFromQueue(in_port[{i}], &v, sizeof v) > 0)\n                store({s}, &v);\n        }}"
        );
    }
    let _ = writeln!(out, "        r->pc = {next};\n        return STEP_NEXT;");
}

/// `send`/`publish`: each value to its message's port (and its own group).
fn emit_send(out: &mut String, cx: &StateCx, items: &[SendItem]) {
    let StateCx {
        program,
        words,
        next,
        ..
    } = *cx;
    let m = &program.control;
    for item in items {
        let value = words.operand(&item.value);
        if let Some(s) = item.store {
            let _ = writeln!(out, "        store({s}, {value});");
        }
        let sent = match item.store {
            Some(s) => format!("&slot[{s}]"),
            None => value,
        };
        let _ = writeln!(
            out,
            "        semo_port_send(out_port[{}], {sent}, sizeof(semo_value)); /* {} */",
            item.message,
            c::comment(&m.outgoing_message(item.message).key)
        );
        if let Some(group) = item.own_group {
            // Its own publication is the latest its subscription sees.
            let _ = writeln!(
                out,
                "        UFMulticast_Write({}, {sent}, sizeof(semo_value));",
                c::string(m.subscription(group))
            );
        }
    }
    let _ = writeln!(out, "        r->pc = {next};\n        return STEP_NEXT;");
}

/// `subscribe`: the group's latest value, if any.
fn emit_subscribe(out: &mut String, cx: &StateCx, group: &SubscriptionId, slot: &SlotId) {
    let StateCx { program, next, .. } = *cx;
    let m = &program.control;
    let _ = writeln!(
        out,
        "        {{\n            semo_value v;\n            if (UFMulticast_Read({}, &v, sizeof v) > 0)\n                store({slot}, &v);\n        }}\n        r->pc = {next};\n        return STEP_NEXT;",
        c::string(m.subscription(*group))
    );
}

/// `throw E`.
fn emit_throw(out: &mut String, cx: &StateCx, event: &str) {
    let StateCx { next, .. } = *cx;
    let _ = writeln!(
        out,
        "        throw_event({});\n        r->pc = {next};\n        return STEP_NEXT;",
        c::string(event)
    );
}

/// `throw E broadcast`: the others of the group told first.
fn emit_throw_broadcast(out: &mut String, cx: &StateCx, event: &str, broadcast: &Broadcast) {
    let StateCx {
        program,
        peers,
        next,
        ..
    } = *cx;
    let m = &program.control;
    // The others of the group are told before the event acts here
    // (a caught event ends the firing's steps).
    if !broadcast.within.is_empty() {
        // Only those that share this robot's arms now.
        let (narrow, (kept, n_kept)) = narrow_to_arms(peers, &broadcast.within);
        let ports: Vec<String> = (broadcast.messages.iter())
            .map(|m| m.index().to_string())
            .collect();
        out.push_str(&fill(
            &THROW_BROADCAST_WITHIN,
            &[
                ("narrow", &narrow),
                ("to", &peers.locals(&broadcast.to)),
                ("ports", &ports.join(", ")),
                ("n", &broadcast.to.len()),
                ("kept", &kept),
                ("n_kept", &n_kept),
                ("event", &c::string(event)),
                ("key", &c::comment(&event_key(&program.team))),
            ],
        ));
    }
    let messages: &[OutgoingId] = if broadcast.within.is_empty() {
        &broadcast.messages
    } else {
        &[]
    };
    for &message in messages {
        let _ = writeln!(
            out,
            "        {{\n            semo_value told;\n            semo_value_set(&told, {});\n            semo_port_send(out_port[{message}], &told, sizeof told); /* {} to {} */\n        }}",
            c::string(event),
            c::comment(&m.outgoing_message(message).key),
            c::comment(&m.outgoing_message(message).to_team)
        );
    }
    let _ = writeln!(
        out,
        "        throw_broadcast({});\n        r->pc = {next};\n        return STEP_NEXT;",
        c::string(event)
    );
}

/// A service call: a request to its task, then waiting for the task to go idle (or the timeout).
fn emit_call(
    out: &mut String,
    cx: &StateCx,
    service: &str,
    task: &str,
    args: &[Operand],
    (timeout_ms, mark): (&Option<i64>, &MarkId),
    results: &[SlotId],
) {
    let StateCx {
        program,
        words,
        next,
        ..
    } = *cx;
    let port = request_index(program, task);
    // The called task going idle wakes the control task; a timeout
    // is a deadline of its own.
    let wake = timeout_ms.map_or(String::new(), |t| {
        format!("\n            wake_at(r->mark[{mark}] + {t} + 1);")
    });
    out.push_str(&fill(
        &CALL_REQUEST,
        &[
            ("port", &port),
            ("task", &c::string(task)),
            ("service", &c::string(service)),
            ("argc", &args.len()),
            ("args", &args_array(args, words)),
            ("mark", &mark),
            ("wake", &wake),
            ("started", &results_none(port, results)),
        ],
    ));
    if let Some(t) = timeout_ms {
        out.push_str(&fill(
            &CALL_TIMEOUT,
            &[
                ("mark", &mark),
                ("t", &t),
                ("task", &c::string(task)),
                ("service", &c::string(service)),
            ],
        ));
    }
    let taken = results_taken(cx, service, port, results);
    let taken = match (timeout_ms, taken.is_empty()) {
        (Some(t), false) => format!(
            "\n        if (semo_now_ms() - r->mark[{mark}] <= {t}) {{{}\n        }}",
            taken.replace("\n        ", "\n            ")
        ),
        _ => taken,
    };
    out.push_str(&fill(
        &CALL_WAIT,
        &[
            ("task", &c::string(task)),
            ("next", &next),
            ("taken", &taken),
        ],
    ));
}

/// A call binding results starts: they are none, and so is what its task
/// last gave back, until the call is done.
fn results_none(port: usize, results: &[SlotId]) -> String {
    if results.is_empty() {
        return String::new();
    }
    let mut out = format!("\n            reply_count[{port}] = 0;");
    for slot in results {
        let _ = write!(out, "\n            slot[{slot}].type = SEMO_NONE;");
    }
    out
}

/// A call binding results is done: each slot takes what the task gave
/// back, read as the slot's type (`take_result`), and is traced as the
/// simulator traces it (`result`).
fn results_taken(cx: &StateCx, service: &str, port: usize, results: &[SlotId]) -> String {
    let mut out = String::new();
    for (k, slot) in results.iter().enumerate() {
        let declared = &cx.program.control.slots[slot.index()];
        let domain = match &declared.kind {
            ValueKind::Word(domain) if domain.is_empty() => "(const unsigned short[]){0}, 0".into(),
            ValueKind::Word(domain) => format!(
                "(const unsigned short[]){{{}}}, {}",
                domain
                    .iter()
                    .map(|w| cx.words.index(w).to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
                domain.len()
            ),
            _ => "NULL, 0".into(),
        };
        let name = declared.key.rsplit('.').next().unwrap_or(&declared.key);
        let _ = write!(
            out,
            "\n        take_result({port}, {k}, {}, {domain}, {slot});\n        semo_trace_value(\"result\", \"value\", &slot[{slot}], \"service\", {}, \"name\", {}, NULL);",
            declared.kind.c_tag(),
            c::string(service),
            c::string(name)
        );
    }
    out
}

/// A strategy's service: its action machine run until it is done (or the timeout).
fn emit_run_actions(
    out: &mut String,
    cx: &StateCx,
    service: &str,
    machine: &ActionMachineId,
    args: &[Operand],
    timeout_ms: &Option<i64>,
    mark: &MarkId,
) {
    let StateCx {
        program,
        words,
        next,
        ..
    } = *cx;
    let m = &program.control;
    let am = m.action_machine(*machine);
    let _ = writeln!(out, "        if (r->phase == 0) {{");
    for (i, slot) in am.arguments.iter().enumerate() {
        if let Some(arg) = args.get(i) {
            let _ = writeln!(out, "            store({slot}, {});", words.operand(arg));
        }
    }
    out.push_str(&fill(
        &ACTIONS_ENTER,
        &[
            ("initial", &am.initial),
            ("mark", &mark),
            ("service", &c::string(service)),
        ],
    ));
    if let Some(t) = timeout_ms {
        out.push_str(&fill(
            &ACTIONS_TIMEOUT,
            &[
                ("mark", &mark),
                ("t", &t),
                ("service", &c::string(service)),
                ("next", &next),
            ],
        ));
    }
    // An action taken (STEP_NEXT) enters the next action at the next
    // firing, as in the simulator, where a firing that progressed is
    // followed by the next: named here, since nothing else may wake
    // the machine (an action whose commands' task just went idle).
    out.push_str(&fill(
        &ACTIONS_RUN,
        &[
            ("machine", &machine),
            ("service", &c::string(service)),
            ("next", &next),
        ],
    ));
}

/// `election_K`: a `leader(...)` statement's election, and the drop of
/// what waits for its leader's block when this robot has just become the
/// leader.
fn emit_election(
    out: &mut String,
    program: &RobotProgram,
    peers: &Peers,
    k: usize,
    e: &crate::refine::Election,
) {
    let algorithm = match e.algorithm {
        LeaderAlgorithm::LowestId => "ELECT_LOWEST_ID",
        LeaderAlgorithm::HighestBattery => "ELECT_HIGHEST_BATTERY",
        LeaderAlgorithm::Bully => "ELECT_BULLY",
    };
    let leader = format!("election_{k}_leader");
    let mut drop = String::new();
    emit_drop_unled(&mut drop, program, e.receives, &leader);
    out.push_str(&fill(
        &ELECTION,
        &[
            ("election", &k),
            ("line", &e.line),
            ("list", &peers.locals(e.candidates)),
            ("count", &e.candidates.len()),
            ("algorithm", &algorithm),
            // The leader before this election, for the drop.
            (
                "led",
                &if e.receives.is_empty() {
                    String::new()
                } else {
                    format!("\n    long led = {leader};")
                },
            ),
            ("drop", &drop),
        ],
    ));
}

/// The heartbeat's elections: each `election_K` this robot has decided at
/// least once at its statement (its last leader is no longer -1).
fn elect_at_heartbeat(m: &ControlMachine) -> String {
    let mut out = String::new();
    for k in 0..m.elections().count() {
        let _ = writeln!(
            out,
            "        if (election_{k}_leader != -1)\n            election_{k}();"
        );
    }
    out
}

/// `leader(...)`: the election (`election_K`), then the leader's block or
/// the others'.
fn emit_leader_branch(out: &mut String, cx: &StateCx, others_at: &StateId) {
    let StateCx { election, next, .. } = *cx;
    out.push_str(&fill(&LEADER_BRANCH, &[("election", &election)]));
    let _ = writeln!(
        out,
        "        r->pc = chosen ? {next} : {others_at};\n        return STEP_NEXT;\n    }}"
    );
}

/// Counted groups: this robot's group among the live members.
fn emit_group_allocate(
    out: &mut String,
    cx: &StateCx,
    members: &[PeerId],
    groups: &[CountedGroup],
    others_at: &Option<StateId>,
    (within, nested): (&[EnclosingArm], &[StateId]),
) {
    let StateCx {
        peers,
        next,
        service,
        pc,
        ..
    } = *cx;
    let join = |items: Vec<String>| items.join(", ");
    let members_list = peers.locals(members);
    let mins_of = |mins: &[usize]| join(mins.iter().map(|m| m.to_string()).collect());
    let mins = mins_of(&groups.iter().map(|g| g.min).collect::<Vec<_>>());
    let names = join(groups.iter().map(|g| c::string(&g.name)).collect());
    let at = join(groups.iter().map(|g| g.at.index().to_string()).collect());
    let others = others_at.map_or(next, |o| o.index());
    let (mut narrow, from) = narrow_to_arms(peers, within);
    let forget: String = nested
        .iter()
        .map(|inner| {
            format!(
                "\n            allocated_{service}_{} = -2;\n            semo_status_group({}, NULL, 0);",
                inner.index(),
                group_statement(cx.program, service, inner.index())
            )
        })
        .collect();
    let sharing = if within.is_empty() {
        format!("members, {}", members.len())
    } else {
        let _ = write!(
            narrow,
            "\n        size_t sharing[{n}];\n        size_t n_sharing = sharing_arms(sharing, members, {n}, {}, {});",
            from.0,
            from.1,
            n = members.len(),
        );
        "sharing, n_sharing".to_string()
    };
    out.push_str(&fill(
        &GROUP_ALLOCATE,
        &[
            ("members_list", &members_list),
            ("mins", &mins),
            ("names", &names),
            ("at", &at),
            ("groups", &groups.len()),
            ("has_others", &others_at.is_some()),
            ("others", &others),
            ("narrow", &narrow),
            ("sharing", &sharing),
            ("last", &format!("allocated_{service}_{pc}")),
            ("forget", &forget),
            ("statement", &group_statement(cx.program, service, pc)),
        ],
    ));
}

/// The number of the statement of counted groups at state `pc` of service
/// `service` among all of the machine's, in the machine's order: the key of
/// the robot's group there in its status (`semo_status_group`).
fn group_statement(program: &RobotProgram, service: usize, pc: usize) -> usize {
    let is_allocate = |s: &State| matches!(s.kind, StateKind::GroupAllocate { .. });
    let services = &program.control.services;
    services[..service]
        .iter()
        .map(|s| s.states.iter().filter(|s| is_allocate(s)).count())
        .sum::<usize>()
        + services[service].states[..pc]
            .iter()
            .filter(|s| is_allocate(s))
            .count()
}

/// Nested in arms of counted groups (`within`): C statements that narrow the
/// members level by level to the arms this robot runs, and the array and
/// count of the last level (`NULL`, `0` with no level).
fn narrow_to_arms(peers: &Peers, within: &[EnclosingArm]) -> (String, (String, String)) {
    let mins_of = |mins: &[usize]| {
        let mins: Vec<String> = mins.iter().map(|m| m.to_string()).collect();
        mins.join(", ")
    };
    let mut narrow = String::new();
    let mut from = ("NULL".to_string(), "0".to_string());
    for (level, arm) in within.iter().enumerate() {
        let _ = write!(
            narrow,
            "\n        static const size_t within{level}_members[] = {{{}}};\n        static const size_t within{level}_mins[] = {{{}}};\n        size_t kept{level}[{n}];\n        size_t n_kept{level} = narrow_to_arm(kept{level}, {}, {}, within{level}_members, {n}, within{level}_mins, {}, {}, {});",
            peers.locals(&arm.members),
            mins_of(&arm.mins),
            from.0,
            from.1,
            arm.mins.len(),
            arm.has_others,
            arm.arm.map_or(-1, |k| k as i64),
            n = arm.members.len(),
        );
        from = (format!("kept{level}"), format!("n_kept{level}"));
    }
    (narrow, from)
}

/// `GroupSync`: waits for the group's live members to arrive (or the timeout).
fn emit_group_sync(
    out: &mut String,
    cx: &StateCx,
    members: &[PeerId],
    point: &SyncPointId,
    timeout_ms: &i64,
    mark: &MarkId,
) {
    let StateCx {
        program,
        peers,
        next,
        line,
        ..
    } = *cx;
    let m = &program.control;
    let list = peers.locals(members);
    let lost = lost_after_ms(m.heartbeat_ms);
    out.push_str(&fill(
        &GROUP_SYNC,
        &[
            ("list", &list),
            ("mark", &mark),
            ("count", &members.len()),
            ("offset", &m.sync_point(*point)),
            ("team", &c::string(&program.team)),
            ("key", &c::string(&protocol::sync_key(program))),
            ("point", &point),
            ("lost", &lost),
            ("timeout_ms", &timeout_ms),
            ("line", &line),
            ("next", &next),
        ],
    ));
}

/// `if`.
fn emit_branch(out: &mut String, cx: &StateCx, condition: &Expr, else_to: &StateId) {
    let StateCx { words, next, .. } = *cx;
    let _ = writeln!(
        out,
        "        r->pc = {} ? {next} : {else_to};\n        return STEP_NEXT;",
        words.condition(condition)
    );
}

/// A jump (the end of a branch).
fn emit_jump(out: &mut String, _cx: &StateCx, to: &StateId) {
    let _ = writeln!(out, "        r->pc = {to};\n        return STEP_NEXT;");
}

/// A loop's head: its condition, and the pass's start for its period.
fn emit_loop_head(
    out: &mut String,
    cx: &StateCx,
    condition: &Option<Expr>,
    exit_to: &StateId,
    mark: &MarkId,
) {
    let StateCx { words, next, .. } = *cx;
    if let Some(cond) = condition {
        let _ = writeln!(
            out,
            "        if (!{}) {{\n            r->pc = {exit_to};\n            return STEP_NEXT;\n        }}",
            words.condition(cond)
        );
    }
    let _ = writeln!(
        out,
        "        r->mark[{mark}] = semo_now_ms();\n        r->pc = {next};\n        return STEP_NEXT;"
    );
}

/// A loop's tail: back to its head once its period is over.
fn emit_loop_tail(
    out: &mut String,
    _cx: &StateCx,
    period_ms: &Option<i64>,
    mark: &MarkId,
    to: &StateId,
) {
    match period_ms {
        Some(p) => {
            let _ = writeln!(
                out,
                "        if (semo_now_ms() - r->mark[{mark}] < {p}) {{\n            wake_at(r->mark[{mark}] + {p});\n            return STEP_WAIT;\n        }}"
            );
            let _ = writeln!(out, "        r->pc = {to};\n        return STEP_NEXT;");
        }
        // Without a period, one iteration per firing.
        None => {
            let _ = writeln!(
                out,
                "        r->pc = {to};\n        wake_at(semo_now_ms());\n        return STEP_WAIT;"
            );
        }
    }
}

/// The end of a service's pass: `repeat(...)` or done.
fn emit_repeat(
    out: &mut String,
    cx: &StateCx,
    period_ms: &Option<i64>,
    condition: &Option<Expr>,
    forever: &bool,
) {
    let StateCx { words, .. } = *cx;
    if let Some(cond) = condition {
        let _ = writeln!(
            out,
            "        if (!{})\n            return STEP_DONE;",
            words.condition(cond)
        );
    }
    if let Some(p) = period_ms {
        let _ = writeln!(
            out,
            "        if (semo_now_ms() - r->pass_start < {p}) {{\n            wake_at(r->pass_start + {p});\n            return STEP_WAIT;\n        }}\n        r->pass_start = semo_now_ms();\n        r->pc = 0;\n        return STEP_NEXT;"
        );
    } else if *forever || condition.is_some() {
        // The next pass starts at the next firing.
        out.push_str("        r->pass_start = semo_now_ms();\n        r->pc = 0;\n        wake_at(semo_now_ms());\n        return STEP_WAIT;\n");
    } else {
        out.push_str("        return STEP_DONE;\n");
    }
}

fn emit_action_machine(
    out: &mut String,
    program: &RobotProgram,
    words: &Words,
    index: usize,
    am: &ActionMachine,
) {
    out.push_str(&fill(
        &ACTIONS_HEAD,
        &[
            ("service", &c::comment(&am.service)),
            ("source", &c::comment(&am.source)),
            ("index", &index),
        ],
    ));
    for (i, action) in am.actions.iter().enumerate() {
        let _ = writeln!(
            out,
            "    case {i}: /* action {} `{}`{} */",
            action.id,
            c::comment(&action.name),
            if action.is_final { ", final" } else { "" }
        );
        if action.is_final {
            out.push_str("        return STEP_DONE;\n");
            continue;
        }
        if !action.commands.is_empty() {
            out.push_str("        if (r->phase == 1) {\n");
            for (task, command) in &action.commands {
                let port = request_index(program, task);
                let _ = writeln!(
                    out,
                    "            if (!request(request_port[{port}], {}, {}, 1, {}))\n                return STEP_WAIT;",
                    c::string(task),
                    c::string(&actuator_name(program, task)),
                    args_array(std::slice::from_ref(command), words)
                );
            }
            out.push_str("            r->phase = 2;\n            return STEP_WAIT;\n        }\n");
            for (task, _) in &action.commands {
                let _ = writeln!(
                    out,
                    "        if (UFControl_GetTaskState({}) != SEMO_TASK_IDLE)\n            return STEP_WAIT;",
                    c::string(task)
                );
            }
        }
        for (condition, to) in &action.transitions {
            let test = condition
                .as_ref()
                .map_or_else(|| "true".to_string(), |c| words.condition(c));
            let _ = writeln!(
                out,
                "        if ({test}) {{\n            r->action = {to};\n            r->phase = 1;\n            return STEP_NEXT;\n        }}"
            );
        }
        out.push_str("        return STEP_WAIT;\n");
    }
    out.push_str("    default:\n        return STEP_DONE;\n    }\n}\n\n");
}

/// The actuator command name a task runs (`Move` for `wheel`).
fn actuator_name(program: &RobotProgram, task: &str) -> String {
    program
        .tasks
        .iter()
        .find(|t| t.task == task)
        .and_then(|t| match &t.kind {
            crate::refine::RoleKind::Service { services } => services.first().cloned(),
            _ => None,
        })
        .unwrap_or_else(|| task.to_string())
}

fn emit_dispatch(out: &mut String, program: &RobotProgram) {
    let m = &program.control;
    out.push_str("static int step(region *r)\n{\n    switch (r->service) {\n");
    for i in 0..m.services.len() {
        let _ = writeln!(out, "    case {i}:\n        return service_{i}(r);");
    }
    out.push_str("    default:\n        return STEP_DONE;\n    }\n}\n\n");
    out.push_str("static const char *const service_name[] = {");
    for (i, s) in m.services.iter().enumerate() {
        let _ = write!(
            out,
            "{}{}",
            if i == 0 { " " } else { ", " },
            c::string(&s.name)
        );
    }
    if m.services.is_empty() {
        out.push_str(" \"\"");
    }
    out.push_str(" };\n\n");
}

/// Each mode's C identifier (after `MODE_`): its name's, unless a mode
/// before it has that one (`MOVE(a b)` and `MOVE(a_b)` would both be
/// `MOVE_a_b_`), then with its index added until it is unique. Plain names
/// of one machine are distinct, so they keep their own.
fn mode_idents(m: &crate::refine::ControlMachine) -> Vec<String> {
    let mut taken = std::collections::HashSet::new();
    let mut idents = Vec::with_capacity(m.modes.len());
    for (i, mode) in m.modes.iter().enumerate() {
        let mut ident = c::ident(&mode.name);
        while !taken.insert(ident.clone()) {
            ident = format!("{ident}_{i}");
        }
        idents.push(ident);
    }
    idents
}

fn emit_modes(out: &mut String, program: &RobotProgram) {
    let m = &program.control;
    out.push_str(ENTER_MODE_HEAD.text);
    let idents = mode_idents(m);
    for (i, mode) in m.modes.iter().enumerate() {
        let _ = writeln!(
            out,
            "    case MODE_{}: /* {}:{} */",
            idents[i],
            c::comment(&program.mission),
            mode.line
        );
        for (i, region) in mode.regions.iter().enumerate() {
            let _ = writeln!(
                out,
                "        regions[{i}].service = {};\n        regions[{i}].plan = {};\n        regions[{i}].timeout_ms = {};",
                region.service,
                c::string(&region.plan),
                region.timeout_ms.unwrap_or(0)
            );
        }
        out.push_str("        break;\n");
    }
    out.push_str(ENTER_MODE_TAIL.text);
    out.push_str(LEAVE_MODE_HEAD.text);
    for task in &m.request_tasks {
        let _ = writeln!(
            out,
            "    if (UFControl_GetTaskState({0}) != SEMO_TASK_IDLE)\n        UFControl_StopTask({0});",
            c::string(task)
        );
    }
    out.push_str("}\n\n");
}

fn emit_task(out: &mut String, program: &RobotProgram, peers: &Peers) {
    let m = &program.control;
    let name = c::ident(CONTROL_TASK);
    let _ = writeln!(out, "void task_{name}_init(void)\n{{");
    let mut sensor = 0;
    for s in &m.slots {
        if let SlotSource::Sensor { port, .. } = &s.source {
            let _ = writeln!(
                out,
                "    sensor_port[{sensor}] = UFPort_Initialize({}, {});",
                c::string(CONTROL_TASK),
                c::string(port)
            );
            sensor += 1;
        }
    }
    for (i, task) in m.request_tasks.iter().enumerate() {
        let _ = writeln!(
            out,
            "    request_port[{i}] = UFPort_Initialize({}, {});",
            c::string(CONTROL_TASK),
            c::string(&format!("req_{task}"))
        );
    }
    for (i, o) in m.outgoing.iter().enumerate() {
        let _ = writeln!(
            out,
            "    out_port[{i}] = UFPort_Initialize({}, {});",
            c::string(CONTROL_TASK),
            c::string(&o.port)
        );
    }
    for (i, o) in m.incoming.iter().enumerate() {
        let _ = writeln!(
            out,
            "    in_port[{i}] = UFPort_Initialize({}, {});",
            c::string(CONTROL_TASK),
            c::string(&o.port)
        );
    }
    out.push_str(
        "    for (int i = 0; i < REGION_COUNT; i++)\n        regions[i].service = -1;\n}\n\n",
    );
    let default = m
        .default_mode
        .map(|d| format!("MODE_{}", mode_idents(m)[d.index()]));
    out.push_str(&fill(&GO_HEAD, &[("name", &name)]));
    if !m.battery.is_empty() {
        out.push_str("    manage_resources();\n");
    }
    if m.heartbeat {
        // Tell the team this robot is alive, for leader elections.
        out.push_str(&fill(
            &HEARTBEAT,
            &[
                ("hb", &m.heartbeat_ms),
                ("elect", &elect_at_heartbeat(m)),
                ("team", &c::string(&program.team)),
                ("key", &c::string(&protocol::alive_key(program))),
                ("group", &group_update(m, peers)),
            ],
        ));
    }
    match default {
        Some(d) => {
            let _ = writeln!(out, "    if (current_mode < 0)\n        enter_mode({d});");
        }
        None => out.push_str("    if (current_mode < 0) {\n        semo_trace(\"finish\", \"why\", \"no default mode\", NULL);\n        semo_stop_program();\n        return;\n    }\n"),
    }
    if !m.events_heard.is_empty() {
        out.push_str("    take_events();\n");
    }
    // Messages written in the last firing go out before the program ends
    // (the communication task would otherwise be stopped first).
    let flush = if m.outgoing.is_empty() {
        String::new()
    } else {
        format!(
            "        task_{}_go();\n",
            c::ident(crate::refine::graph::COMM_SEND)
        )
    };
    out.push_str(&fill(
        &GO_TAIL,
        &[
            ("steps_per_firing", &STEPS_PER_FIRING),
            ("flush", &flush),
            ("name", &name),
        ],
    ));
}
