//! `control_task.c`: the control task's hierarchical state machine as C.
//!
//! Every firing (one per control period) the task reads its inputs, then
//! advances each region of the current mode until it waits, and finally
//! applies a mode change that an event asked for. A region's service is a
//! `switch` over its states (`pc`); a state returns `STEP_NEXT` (go on in
//! this firing), `STEP_WAIT` (try again next firing) or `STEP_DONE`.

use super::c;
use super::peers::Peers;
use super::values::Words;
use crate::refine::graph::{CONTROL_TASK, getter, setter};
use crate::refine::{
    ActionMachine, ControlMachine, Expr, LeaderAlgorithm, Operand, RobotProgram, SlotSource, State,
    StateKind,
};
use crate::sema::Compared;
use crate::syntax::ast::CmpOp;
use std::fmt::Write;

/// State transitions a region may take in one firing: a service whose
/// states never wait (only sends and branches) still yields to the others.
const STEPS_PER_FIRING: usize = 64;

/// How long a robot that must first hear its team (a restarted robot, or
/// every robot of a `highest_battery` election at start) listens before an
/// election: one heartbeat period and half of one more, so that the
/// heartbeat each robot sends once per period has arrived even when its
/// sender's firing was a little late. The simulator uses the same.
pub fn listen_ms(heartbeat_ms: i64) -> i64 {
    heartbeat_ms + heartbeat_ms / 2
}

/// A leader's lease (`docs/groups.md`, "Fencing"): a robot the election
/// would choose leads only while it has heard a strict majority of the
/// candidates, itself included, within the last two heartbeat periods. Two
/// is less than the three silent periods after which the others count it
/// lost, so a leader cut off from the majority steps down at its first
/// election after its lease lapsed, before they elect another (at their
/// first election after three). The simulator uses the same.
pub fn lease_ms(heartbeat_ms: i64) -> i64 {
    2 * heartbeat_ms
}

/// The largest term (`docs/groups.md`, "Terms"): a heartbeat saying more
/// says this, and a robot that knows it begins to lead under it again, so
/// that a rogue heartbeat cannot overflow the count (`int64_t` in the C,
/// on every target).
pub const TERM_MAX: i64 = 1_000_000_000_000_000;

/// The term a robot begins to lead under: one past the highest it knows.
pub fn next_term(highest: i64) -> i64 {
    (highest + 1).min(TERM_MAX)
}

/// The term a heartbeat says (`heard_alive` in the C): its leading digits,
/// at most [`TERM_MAX`]; none is 0.
pub fn parse_term(word: &str) -> i64 {
    let digits = word.bytes().take_while(u8::is_ascii_digit);
    digits.fold(0i64, |term, d| {
        (term * 10 + i64::from(d - b'0')).min(TERM_MAX)
    })
}

/// The `heard` field of the `fenced` event: "2 of 5".
pub fn fenced_heard(heard: usize, candidates: usize) -> String {
    format!("{heard} of {candidates}")
}

/// The `reason` of the `drop` event of a message dropped because it arrived
/// before its robot became the leader of the `leader(...)` arm whose block
/// receives it (`drop_unled`). The simulator uses the same.
pub const UNLED_REASON: &str = "arrived before it led";

/// Drops what a channel holds now, oldest first, each traced: a robot that
/// has just become the leader drops the messages waiting for its leader's
/// block (`StateKind::LeaderBranch`). Only the count seen first: a message
/// the receive task writes meanwhile arrived after.
const DROP_UNLED_C: &str = "/* Drops the messages a channel holds now (they arrived before this robot\n * led), oldest first, each traced; one the receive task writes meanwhile stays. */\nstatic void drop_unled(int port, const char *from, const char *key)\n{\n    semo_value stale;\n    for (int n = UFPort_GetNumOfAvailableData(port); n > 0; n--)\n        if (UFPort_ReadFromQueue(port, &stale, sizeof stale) > 0)\n            semo_trace(\"drop\", \"from\", from, \"key\", key, \"reason\", @REASON@, NULL);\n}\n\n";

/// Leader elections (`@HB@`: the heartbeat period, `@LISTEN@`: [`listen_ms`]).
/// `leading` is what this robot's heartbeats say: whether the last election
/// it decided named it. A robot that joined a mission under way (restarted:
/// its mission time was past one heartbeat period when it started, or the
/// MQTT broker still held its session) listens first, and while another
/// live robot claims leadership it follows that robot instead of claiming:
/// the claimant gives way at its own next election, so that two robots never
/// both lead after a restart.
const ELECTION_C: &str = "/* Leader elections: each `leader(...)` arm's candidates (peer indices, in\n * formation order) and algorithm. A candidate is alive when it is this\n * robot or was heard from within three heartbeats. lowest_id: the first\n * alive; bully: the last alive (the highest id); highest_battery: the\n * highest battery level its heartbeat said (unknown counts lowest; ties: the\n * first), after every robot has listened at start. A robot that joined the\n * mission under way (restarted) listens too, and while another live robot\n * claims leadership it follows that one instead of claiming. A change of\n * leader is traced. Fencing: a robot the election would choose leads only\n * while its lease holds, a strict majority of the candidates (itself\n * included) heard from within the lease; without one it is fenced (traced\n * once), waits, and with a majority again listens as a restarted robot does\n * before it claims, following a live claimant. Returns 1 (this\n * robot leads), 0, or -1 while listening or fenced. */\nenum { ELECT_LOWEST_ID, ELECT_HIGHEST_BATTERY, ELECT_BULLY };\n/* `*last` of an arm whose robot is fenced (no robot has index -2). */\n#define ELECT_FENCED (-2L)\nstatic int elected(const size_t *candidates, size_t n, int algorithm, long *last)\n{\n    static int rejoining = -1;\n    static bool fenced;      /* fenced since it last led or followed */\n    static int64_t regained = -1; /* when it heard a majority again */\n    const semo_program_desc *p = semo_program();\n    int64_t now = semo_now_ms();\n    if (rejoining < 0)\n        rejoining = semo_joined_ms() > @HB@ || semo_session_resumed();\n    if ((rejoining || algorithm == ELECT_HIGHEST_BATTERY) && now - semo_joined_ms() < @LISTEN@) {\n        wake_at(semo_joined_ms() + @LISTEN@);\n        return -1;\n    }\n    size_t leader = p->self;\n    bool found = false;\n    long best = -1;\n    for (size_t k = 0; k < n; k++) {\n        size_t c = candidates[algorithm == ELECT_BULLY ? n - 1 - k : k];\n        comm_heartbeat h = comm_heard(c);\n        if (c != p->self && now - h.seen > 3 * @HB@)\n            continue;\n        long level = c == p->self ? own_battery() : h.battery;\n        if (!found || (algorithm == ELECT_HIGHEST_BATTERY && level > best)) {\n            leader = c;\n            best = level;\n            found = true;\n        }\n        if (algorithm != ELECT_HIGHEST_BATTERY)\n            break;\n    }\n    /* Terms: a leader that has heard a higher term than its own since it\n     * began is deposed, and like a rejoining robot it follows a live\n     * claimant; a claim counts only under the highest term known. */\n    bool was_leading = leading;\n    int64_t highest = known_term();\n    bool deposed = was_leading && highest > term_led;\n    if ((rejoining || deposed) && leader == p->self) {\n        for (size_t i = 0; i < p->peer_count; i++) {\n            comm_heartbeat h = comm_heard(i);\n            if (i != p->self && h.leads && h.term >= highest && now - h.seen <= 3 * @HB@) {\n                leader = i;\n                break;\n            }\n        }\n    }\n    if (leader == p->self) {\n        size_t heard = 0;\n        for (size_t k = 0; k < n; k++)\n            if (candidates[k] == p->self || now - comm_heard(candidates[k]).seen <= @LEASE@)\n                heard++;\n        if (2 * heard <= n) {\n            leading = false;\n            rejoining = 1;\n            fenced = true;\n            regained = -1;\n            if (*last != ELECT_FENCED) {\n                char counted[48];\n                snprintf(counted, sizeof counted, \"%lu of %lu\", (unsigned long)heard, (unsigned long)n);\n                *last = ELECT_FENCED;\n                semo_trace(\"fenced\", \"heard\", counted, NULL);\n            }\n            /* Heartbeats heard wake nothing: ask again at the next firing\n             * of the period, as the simulator does at a waiting election. */\n            wake_at(now + 1);\n            return -1;\n        }\n        if (fenced) {\n            /* A majority again: listen before claiming, so that the\n             * heartbeat of a robot leading meanwhile has come. */\n            if (regained < 0)\n                regained = now;\n            if (now - regained < @LISTEN@) {\n                wake_at(now + 1);\n                return -1;\n            }\n            fenced = false;\n        }\n        rejoining = 0;\n    } else {\n        fenced = false; /* it follows a live robot: it has heard the team again */\n        regained = -1;\n    }\n    if (leader == p->self && (!was_leading || deposed)) {\n        /* It begins to lead (again, when deposed): under a new term. */\n        term_known = term_known < @TERM_MAX@LL ? term_known + 1 : term_known;\n        term_led = term_known;\n    }\n    leading = leader == p->self;\n    if ((long)leader != *last) {\n        *last = (long)leader;\n        semo_trace(\"leader\", \"leader\", p->peers[leader].robot, NULL);\n    }\n    return leading;\n}\n";

/// At each heartbeat of a member of its team's group (group services,
/// `docs/groups.md`): its rank among the live members (formation order) and
/// their number, for `semo_group_rank()`/`semo_group_size()`. A member is
/// alive when it is this robot or was heard from within three heartbeats
/// (counted from when this robot joined: until then it had no chance to
/// hear, so a robot starting or restarting counts every member alive).
fn group_update(m: &ControlMachine, peers: &Peers) -> String {
    if m.group.is_empty() {
        return String::new();
    }
    format!(
        "        static const size_t members[] = {{{list}}};\n        const semo_program_desc *p = semo_program();\n        int rank = 0, size = 0;\n        for (size_t k = 0; k < {count}; k++) {{\n            comm_heartbeat h = comm_heard(members[k]);\n            int64_t seen = h.seen > semo_joined_ms() ? h.seen : semo_joined_ms();\n            if (members[k] != p->self && last_heartbeat - seen > 3 * {hb})\n                continue; /* failed: silent for three heartbeats */\n            if (members[k] == p->self)\n                rank = size;\n            size++;\n        }}\n        semo_group_set(rank, size);\n",
        list = peers.locals(&m.group),
        count = m.group.len(),
        hb = m.heartbeat_ms,
    )
}

/// Counted groups (`StateKind::GroupAllocate`): the rule of
/// `refine::counted_allocation` over the live members, as the simulator's
/// `GroupAllocate` applies it.
const GROUP_OF_C: &str = "/* Counted groups: this robot's group among `groups` (declaration order) from\n * the live `members` (peer indices, formation order; a member is alive when it\n * is this robot or was heard from within three heartbeats since this robot\n * joined). The live members in formation order fill the minimums in\n * declaration order; a spare goes to `others` (-1) when the statement has one,\n * else to the groups round-robin. `*alive`: how many were counted. */\nstatic long group_of(const size_t *members, size_t n, const size_t *mins, size_t groups, bool has_others, size_t *alive)\n{\n    const semo_program_desc *p = semo_program();\n    int64_t now = semo_now_ms();\n    size_t position = 0, live = 0;\n    for (size_t k = 0; k < n; k++) {\n        comm_heartbeat h = comm_heard(members[k]);\n        int64_t seen = h.seen > semo_joined_ms() ? h.seen : semo_joined_ms();\n        if (members[k] != p->self && now - seen > 3 * @HB@)\n            continue; /* lost: silent for three heartbeats */\n        if (members[k] == p->self)\n            position = live;\n        live++;\n    }\n    *alive = live;\n    size_t filled = 0;\n    for (size_t g = 0; g < groups; g++) {\n        filled += mins[g];\n        if (position < filled)\n            return (long)g;\n    }\n    if (has_others || groups == 0)\n        return -1;\n    return (long)((position - filled) % groups);\n}\n\n";

/// This robot's battery level for its heartbeats: the scenario's (in
/// simulation), else unknown (-1).
const OWN_BATTERY_C: &str = "/* Whether the last election this robot decided named it (its heartbeats say so). */\nstatic bool leading;\n/* Terms (docs/groups.md): the highest this robot knows (heard, or its own),\n * and the one it leads under while `leading`. */\nstatic int64_t term_known, term_led;\n\n/* The highest term known now: its own, or one a heartbeat said. */\nstatic int64_t known_term(void)\n{\n    int64_t heard = comm_highest_term();\n    if (heard > term_known)\n        term_known = heard;\n    return term_known;\n}\n\n/* A term (at most 10^15) as decimal digits: not every target's printf\n * has %lld. */\nstatic void term_text(int64_t t, char out[24])\n{\n    char digits[24];\n    int n = 0;\n    do {\n        digits[n++] = (char)('0' + t % 10);\n        t /= 10;\n    } while (t > 0 && n < 23);\n    for (int i = 0; i < n; i++)\n        out[i] = digits[n - 1 - i];\n    out[n] = '\\0';\n}\n\n/* This robot's battery level for its heartbeats: the scenario's in\n * simulation, else unknown (-1). */\nstatic long own_battery(void)\n{\n#ifdef SEMO_SIM\n    long long level;\n    if (semo_sim_battery(&level))\n        return (long)level;\n#endif\n    return -1;\n}\n\n";

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
    for (i, mode) in m.modes.iter().enumerate() {
        let _ = write!(
            out,
            "{}MODE_{}",
            if i == 0 { " " } else { ", " },
            c::ident(&mode.name)
        );
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
    out.push_str(
        "typedef struct {\n    int service;        /* running service machine, -1 when none */\n    int pc;             /* its current state */\n    int phase;          /* progress inside a state that takes several firings */\n    int action;         /* current strategy action */\n    bool done;\n    int64_t started;    /* when the service started (mode timeouts) */\n    int64_t pass_start; /* when the current pass started (repeat periods) */\n    int64_t timeout_ms; /* from `set(..., timeout = P)`, 0 for none */\n    int64_t mark[MARK_COUNT];\n    const char *plan;\n} region;\n\n",
    );
    out.push_str("static region regions[REGION_COUNT];\nstatic int current_mode = -1;\nstatic int pending_mode = -1;\n\n");
    out.push_str("/* When the machine next needs a firing without an event (data on its\n * channels, a task's state changed): the earliest deadline a waiting state\n * named in this firing. Waits on events name none: the task sleeps until one\n * comes (semo_next_firing). */\nstatic int64_t next_wake;\n\nstatic void wake_at(int64_t at)\n{\n    if (at < next_wake)\n        next_wake = at;\n}\n\n");

    // The machine first, so that only the helpers and port tables it uses
    // are written (unused static functions and arrays fail -Werror).
    let mut body = String::new();
    for (i, machine) in m.actions.iter().enumerate() {
        emit_action_machine(&mut body, program, words, i, machine);
    }
    for (i, service) in m.services.iter().enumerate() {
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
            emit_state(&mut body, program, words, peers, pc, state);
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

fn operand(op: &Operand, words: &Words) -> String {
    match op {
        Operand::Slot(s) => format!("&slot[{s}]"),
        Operand::Literal(value) => words.literal(value),
    }
}

pub(super) fn expr(e: &Expr, words: &Words) -> String {
    match e {
        Expr::Or(a, b) => format!("({} || {})", expr(a, words), expr(b, words)),
        Expr::And(a, b) => format!("({} && {})", expr(a, words), expr(b, words)),
        Expr::Not(a) => format!("!{}", expr(a, words)),
        Expr::Bool(b) => b.to_string(),
        Expr::Truthy(o) => format!("semo_value_truthy({})", operand(o, words)),
        // As the checker typed the comparison: the runtime never guesses
        // from the values whether they are numbers.
        Expr::Compare(a, op, b, compared) => {
            let function = match compared {
                Compared::Numbers => "semo_value_numbers",
                Compared::Words => "semo_value_words",
            };
            let op = match op {
                CmpOp::Eq => "SEMO_EQ",
                CmpOp::Ne => "SEMO_NE",
                CmpOp::Lt => "SEMO_LT",
                CmpOp::Le => "SEMO_LE",
                CmpOp::Gt => "SEMO_GT",
                CmpOp::Ge => "SEMO_GE",
            };
            format!(
                "{function}({}, {op}, {})",
                operand(a, words),
                operand(b, words)
            )
        }
    }
}

/// A program that broadcasts or hears events: `catch_event` (the current
/// mode's catch, with the thrower of a broadcast one), the throws `body`
/// uses, and `take_events` (the broadcast events received since the last
/// firing, `comm_event_take`) when it hears any. A program without either
/// keeps `throw_event` as it always was.
fn emit_catch_event(out: &mut String, program: &RobotProgram, throws: bool, broadcasts: bool) {
    let m = &program.control;
    out.push_str("/* The current mode's `catch` of `event` asks for its mode change, unless one\n * is asked for already: whether it did. `from`: the robot that broadcast the\n * event, or NULL for this robot's own throw. */\nstatic bool catch_event(const char *event, const char *from)\n{\n");
    emit_catches(
        out,
        program,
        "semo_trace(\"catch\", \"name\", event, \"mode\", mode_name[pending_mode], from ? \"from\" : NULL, from, NULL);\n            return true;",
    );
    out.push_str("    return false;\n}\n\n");
    if throws {
        out.push_str("/* `throw`: asks for the mode change that the current mode's `catch` names. */\nstatic void throw_event(const char *event)\n{\n    semo_trace(\"throw\", \"name\", event, NULL);\n    catch_event(event, NULL);\n}\n\n");
    }
    if broadcasts {
        out.push_str("/* `throw E broadcast`, once the others of the group are told: acts here as\n * `throw E` does. */\nstatic void throw_broadcast(const char *event)\n{\n    semo_trace(\"throw\", \"name\", event, \"broadcast\", \"true\", NULL);\n    catch_event(event, NULL);\n}\n\n");
    }
    if !m.events_heard.is_empty() {
        out.push_str("/* At the start of a firing, in its mode: each broadcast event received since\n * the last one, in order, handled as this robot's own throw would be; one\n * the mode does not catch (or after a caught one) is dropped. */\nstatic void take_events(void)\n{\n    size_t from;\n    const char *event;\n    while (comm_event_take(&from, &event)) {\n        const char *robot = semo_program()->peers[from].robot;\n        if (!catch_event(event, robot))\n            semo_trace(\"drop\", \"from\", robot, \"name\", event, \"reason\", \"not caught\", NULL);\n    }\n}\n\n");
    }
}

/// The `switch` on the current mode of `throw_event` and `catch_event`: per
/// mode with catches, per catch of `event`, the mode change asked for and
/// then `caught` (C statements, indented for the case).
fn emit_catches(out: &mut String, program: &RobotProgram, caught: &str) {
    let m = &program.control;
    out.push_str("    switch (current_mode) {\n");
    for (from, mode) in m.modes.iter().enumerate() {
        let catches: Vec<_> = m.transitions.iter().filter(|t| t.from == from).collect();
        if catches.is_empty() {
            continue;
        }
        let _ = writeln!(out, "    case MODE_{}:", c::ident(&mode.name));
        for t in catches {
            let _ = writeln!(
                out,
                "        if (strcmp(event, {}) == 0 && pending_mode < 0) {{ /* {}:{} */\n            pending_mode = MODE_{};\n            {caught}\n        }}",
                c::string(&t.event),
                c::comment(&program.mission),
                t.line,
                c::ident(&m.modes[t.to].name)
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
            SlotSource::Local => {}
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
        out.push_str("/* `throw`: asks for the mode change that the current mode's `catch` names. */\nstatic void throw_event(const char *event)\n{\n    semo_trace(\"throw\", \"name\", event, NULL);\n");
        emit_catches(
            out,
            program,
            "semo_trace(\"catch\", \"name\", event, \"mode\", mode_name[pending_mode], NULL);",
        );
        out.push_str("}\n\n");
    }

    if m.heartbeat {
        out.push_str(OWN_BATTERY_C);
    }
    if uses("elected") {
        out.push_str(
            &ELECTION_C
                .replace("@HB@", &m.heartbeat_ms.to_string())
                .replace("@LISTEN@", &listen_ms(m.heartbeat_ms).to_string())
                .replace("@LEASE@", &lease_ms(m.heartbeat_ms).to_string())
                .replace("@TERM_MAX@", &TERM_MAX.to_string()),
        );
        out.push('\n');
    }

    if uses("group_of") {
        out.push_str(&GROUP_OF_C.replace("@HB@", &m.heartbeat_ms.to_string()));
    }

    if uses("drop_unled") {
        out.push_str(&DROP_UNLED_C.replace("@REASON@", &c::string(UNLED_REASON)));
    }

    if uses("request") {
        out.push_str("/* Writes a service request to the task's queue and starts one firing of it. */\nstatic bool request(int port, const char *task, const char *service, int argc, const semo_value *const *args)\n{\n    semo_request req;\n    memset(&req, 0, sizeof req);\n    strncpy(req.service, service, sizeof req.service - 1);\n    for (int i = 0; i < argc && i < SEMO_MAX_ARGS; i++)\n        req.args[i] = *args[i];\n    req.argc = argc < SEMO_MAX_ARGS ? argc : SEMO_MAX_ARGS;\n    if (UFControl_GetTaskState(task) != SEMO_TASK_IDLE)\n        return false;\n    /* The task is idle: a request still queued was stopped before its task\n     * fired (a mode change, a timeout) and must not run now. */\n    semo_request stale;\n    while (UFPort_GetNumOfAvailableData(port) > 0)\n        UFPort_ReadFromQueue(port, &stale, sizeof stale);\n    if (UFPort_WriteToQueue(port, &req, sizeof req) == 0)\n        return false;\n    UFControl_CallTask(task);\n    return true;\n}\n\n");
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
    let items: Vec<String> = args.iter().map(|a| operand(a, words)).collect();
    format!("(const semo_value *const[]){{{}}}", items.join(", "))
}

/// A robot that has just become the leader here (`led`: the leader before)
/// drops what waits for the receives of the leader's block (`receives`).
fn emit_drop_unled(out: &mut String, program: &RobotProgram, receives: &[usize]) {
    if receives.is_empty() {
        return;
    }
    out.push_str("        if (chosen && led != leader) { /* it leads from now on */\n");
    for &k in receives {
        let incoming = &program.control.incoming[k];
        let _ = writeln!(
            out,
            "            drop_unled(in_port[{k}], {}, {});",
            c::string(&incoming.from_team),
            c::string(&incoming.key)
        );
    }
    out.push_str("        }\n");
}

fn emit_state(
    out: &mut String,
    program: &RobotProgram,
    words: &Words,
    peers: &Peers,
    pc: usize,
    state: &State,
) {
    let m = &program.control;
    let _ = writeln!(
        out,
        "    case {pc}: /* line {}: {} */",
        state.line,
        c::comment(&state.text)
    );
    let next = pc + 1;
    match &state.kind {
        StateKind::Receive {
            messages,
            timeout_ms,
            mark,
        } => {
            let ready: Vec<String> = messages
                .iter()
                .map(|i| format!("UFPort_GetNumOfAvailableData(in_port[{i}]) > 0"))
                .collect();
            let ready = ready.join(" && ");
            match timeout_ms {
                // `receive(...), timeout = P`: go on without the values after P.
                Some(t) => {
                    let _ = writeln!(
                        out,
                        "        if (r->phase == 0) {{\n            r->mark[{mark}] = semo_now_ms();\n            r->phase = 1;\n        }}\n        if (!({ready})) {{\n            if (semo_now_ms() - r->mark[{mark}] <= {t}) {{\n                wake_at(r->mark[{mark}] + {t} + 1);\n                return STEP_WAIT;\n            }}\n            semo_trace(\"timeout\", \"statement\", \"receive\", NULL);\n            r->phase = 0;\n            r->pc = {next};\n            return STEP_NEXT;\n        }}\n        r->phase = 0;"
                    );
                }
                None => {
                    let _ = writeln!(
                        out,
                        "        if (!({ready}))\n            return STEP_WAIT;"
                    );
                }
            }
            for &i in messages {
                let s = m.incoming[i].slot;
                let _ = writeln!(
                    out,
                    "        {{\n            semo_value v;\n            if (UFPort_ReadFromQueue(in_port[{i}], &v, sizeof v) > 0)\n                store({s}, &v);\n        }}"
                );
            }
            let _ = writeln!(out, "        r->pc = {next};\n        return STEP_NEXT;");
        }
        StateKind::Send { items } => {
            for item in items {
                let value = operand(&item.value, words);
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
                    c::comment(&m.outgoing[item.message].key)
                );
                if let Some(group) = item.own_group {
                    // Its own publication is the latest its subscription sees.
                    let _ = writeln!(
                        out,
                        "        UFMulticast_Write({}, {sent}, sizeof(semo_value));",
                        c::string(&m.subscribed[group])
                    );
                }
            }
            let _ = writeln!(out, "        r->pc = {next};\n        return STEP_NEXT;");
        }
        StateKind::Subscribe { group, slot } => {
            let _ = writeln!(
                out,
                "        {{\n            semo_value v;\n            if (UFMulticast_Read({}, &v, sizeof v) > 0)\n                store({slot}, &v);\n        }}\n        r->pc = {next};\n        return STEP_NEXT;",
                c::string(&m.subscribed[*group])
            );
        }
        StateKind::Throw {
            event,
            broadcast: None,
        } => {
            let _ = writeln!(
                out,
                "        throw_event({});\n        r->pc = {next};\n        return STEP_NEXT;",
                c::string(event)
            );
        }
        StateKind::Throw {
            event,
            broadcast: Some(messages),
        } => {
            // The others of the group are told before the event acts here
            // (a caught event ends the firing's steps).
            for &message in messages {
                let _ = writeln!(
                    out,
                    "        {{\n            semo_value told;\n            semo_value_set(&told, {});\n            semo_port_send(out_port[{message}], &told, sizeof told); /* {} to {} */\n        }}",
                    c::string(event),
                    c::comment(&m.outgoing[message].key),
                    c::comment(&m.outgoing[message].to_team)
                );
            }
            let _ = writeln!(
                out,
                "        throw_broadcast({});\n        r->pc = {next};\n        return STEP_NEXT;",
                c::string(event)
            );
        }
        StateKind::Call {
            service,
            task,
            args,
            timeout_ms,
            mark,
        } => {
            let port = request_index(program, task);
            // The called task going idle wakes the control task; a timeout
            // is a deadline of its own.
            let wake = timeout_ms.map_or(String::new(), |t| {
                format!("\n            wake_at(r->mark[{mark}] + {t} + 1);")
            });
            let _ = writeln!(
                out,
                "        if (r->phase == 0) {{\n            if (!request(request_port[{port}], {task}, {service}, {argc}, {args}))\n                return STEP_WAIT;\n            r->mark[{mark}] = semo_now_ms();\n            r->phase = 1;{wake}\n            return STEP_WAIT;\n        }}",
                task = c::string(task),
                service = c::string(service),
                argc = args.len(),
                args = args_array(args, words),
            );
            if let Some(t) = timeout_ms {
                let _ = writeln!(
                    out,
                    "        wake_at(r->mark[{mark}] + {t} + 1);\n        if (semo_now_ms() - r->mark[{mark}] > {t}) {{\n            UFControl_StopTask({});\n            semo_trace(\"timeout\", \"service\", {}, NULL);\n        }} else",
                    c::string(task),
                    c::string(service)
                );
            }
            let _ = writeln!(
                out,
                "        if (UFControl_GetTaskState({}) != SEMO_TASK_IDLE)\n            return STEP_WAIT;\n        r->phase = 0;\n        r->pc = {next};\n        return STEP_NEXT;",
                c::string(task)
            );
        }
        StateKind::RunActions {
            service,
            machine,
            args,
            timeout_ms,
            mark,
        } => {
            let am = &m.actions[*machine];
            let _ = writeln!(out, "        if (r->phase == 0) {{");
            for (i, slot) in am.arguments.iter().enumerate() {
                if let Some(arg) = args.get(i) {
                    let _ = writeln!(out, "            store({slot}, {});", operand(arg, words));
                }
            }
            let _ = writeln!(
                out,
                "            r->action = {};\n            r->phase = 1;\n            r->mark[{mark}] = semo_now_ms();\n            semo_trace(\"actions_start\", \"service\", {}, NULL);\n        }}",
                am.initial,
                c::string(service)
            );
            if let Some(t) = timeout_ms {
                let _ = writeln!(
                    out,
                    "        wake_at(r->mark[{mark}] + {t} + 1);\n        if (semo_now_ms() - r->mark[{mark}] > {t}) {{\n            semo_trace(\"timeout\", \"service\", {}, NULL);\n            r->phase = 0;\n            r->pc = {next};\n            return STEP_NEXT;\n        }}",
                    c::string(service)
                );
            }
            // An action taken (STEP_NEXT) enters the next action at the next
            // firing, as in the simulator, where a firing that progressed is
            // followed by the next: named here, since nothing else may wake
            // the machine (an action whose commands' task just went idle).
            let _ = writeln!(
                out,
                "        {{\n            int acted = actions_{machine}(r);\n            if (acted == STEP_NEXT)\n                wake_at(semo_now_ms());\n            if (acted != STEP_DONE)\n                return STEP_WAIT;\n        }}\n        semo_trace(\"actions_end\", \"service\", {}, NULL);\n        r->phase = 0;\n        r->pc = {next};\n        return STEP_NEXT;",
                c::string(service)
            );
        }
        StateKind::LeaderBranch {
            candidates,
            algorithm,
            others_at,
            receives,
        } => {
            let list = peers.locals(candidates);
            let algorithm = match algorithm {
                LeaderAlgorithm::LowestId => "ELECT_LOWEST_ID",
                LeaderAlgorithm::HighestBattery => "ELECT_HIGHEST_BATTERY",
                LeaderAlgorithm::Bully => "ELECT_BULLY",
            };
            let _ = writeln!(
                out,
                "    {{\n        static const size_t candidates[] = {{{}}};\n        static long leader = -1; /* the last leader seen (control thread only) */{led}\n        int chosen = elected(candidates, {}, {algorithm}, &leader);\n        if (chosen < 0)\n            return STEP_WAIT; /* still listening */",
                list,
                candidates.len(),
                // The leader before this election, for `emit_drop_unled`.
                led = if receives.is_empty() {
                    ""
                } else {
                    "\n        long led = leader;"
                },
            );
            emit_drop_unled(out, program, receives);
            let _ = writeln!(
                out,
                "        r->pc = chosen ? {next} : {others_at};\n        return STEP_NEXT;\n    }}"
            );
        }
        StateKind::GroupAllocate {
            members,
            groups,
            others_at,
        } => {
            let join = |items: Vec<String>| items.join(", ");
            let members_list = peers.locals(members);
            let mins = join(groups.iter().map(|g| g.min.to_string()).collect());
            let names = join(groups.iter().map(|g| c::string(&g.name)).collect());
            let at = join(groups.iter().map(|g| g.at.index().to_string()).collect());
            let others = others_at.map_or(next, |o| o.index());
            let _ = writeln!(
                out,
                "    {{\n        static const size_t members[] = {{{members_list}}};\n        static const size_t mins[] = {{{mins}}};\n        static const char *const names[] = {{{names}}};\n        static const int at[] = {{{at}}};\n        static long last = -2; /* the group last given, -1 others (control thread only) */\n        size_t alive;\n        long group = group_of(members, {}, mins, {}, {}, &alive);\n        if (group != last) {{\n            char counted[24];\n            snprintf(counted, sizeof counted, \"%lu\", (unsigned long)alive);\n            last = group;\n            semo_trace(\"allocated\", \"name\", group < 0 ? \"others\" : names[group], \"alive\", counted, NULL);\n        }}\n        r->pc = group < 0 ? {others} : at[group];\n        return STEP_NEXT;\n    }}",
                members.len(),
                groups.len(),
                others_at.is_some(),
            );
        }
        StateKind::GroupSync {
            members,
            point,
            timeout_ms,
            mark,
        } => {
            let list = peers.locals(members);
            let hb = m.heartbeat_ms;
            let _ = writeln!(
                out,
                "    {{\n        static const size_t members[] = {{{list}}};\n        static long pass; /* how often this robot reached the statement (control thread only) */\n        const semo_program_desc *p = semo_program();\n        int64_t now = semo_now_ms();\n        if (r->phase == 0) {{\n            semo_value arrived;\n            char text[48];\n            pass++;\n            r->mark[{mark}] = now;\n            r->phase = 1;\n            snprintf(text, sizeof text, \"{offset} %ld\", pass);\n            semo_value_set(&arrived, text);\n            semo_comm_send({team}, SEMO_MSG_SEND, {key}, &arrived);\n        }}\n        int waiting = 0;\n        for (size_t k = 0; k < {count}; k++) {{\n            size_t peer = members[k];\n            comm_heartbeat h = comm_heard(peer);\n            if (peer == p->self || comm_sync_arrived(peer, {point}) >= pass || now - h.seen > 3 * {hb})\n                continue; /* here, arrived, or known dead */\n            waiting++;\n            wake_at(h.seen + 3 * {hb} + 1);\n        }}\n        if (waiting > 0 && now - r->mark[{mark}] <= {timeout_ms}) {{\n            wake_at(r->mark[{mark}] + {timeout_ms} + 1);\n            return STEP_WAIT;\n        }}\n        if (waiting > 0)\n            semo_trace(\"timeout\", \"statement\", \"GroupSync\", NULL);\n        else\n            semo_trace(\"group_sync\", \"line\", \"{line}\", NULL);\n        r->phase = 0;\n        r->pc = {next};\n        return STEP_NEXT;\n    }}",
                count = members.len(),
                offset = m.sync_points[*point],
                team = c::string(&program.team),
                key = c::string(&super::files::sync_key(program)),
                line = state.line,
            );
        }
        StateKind::Branch { condition, else_to } => {
            let _ = writeln!(
                out,
                "        r->pc = {} ? {next} : {else_to};\n        return STEP_NEXT;",
                expr(condition, words)
            );
        }
        StateKind::Jump { to } => {
            let _ = writeln!(out, "        r->pc = {to};\n        return STEP_NEXT;");
        }
        StateKind::LoopHead {
            condition,
            exit_to,
            mark,
        } => {
            if let Some(cond) = condition {
                let _ = writeln!(
                    out,
                    "        if (!{}) {{\n            r->pc = {exit_to};\n            return STEP_NEXT;\n        }}",
                    expr(cond, words)
                );
            }
            let _ = writeln!(
                out,
                "        r->mark[{mark}] = semo_now_ms();\n        r->pc = {next};\n        return STEP_NEXT;"
            );
        }
        StateKind::LoopTail {
            period_ms,
            mark,
            to,
        } => {
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
        StateKind::Repeat {
            period_ms,
            condition,
            forever,
        } => {
            if let Some(cond) = condition {
                let _ = writeln!(
                    out,
                    "        if (!{})\n            return STEP_DONE;",
                    expr(cond, words)
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
    }
}

fn emit_action_machine(
    out: &mut String,
    program: &RobotProgram,
    words: &Words,
    index: usize,
    am: &ActionMachine,
) {
    let _ = writeln!(
        out,
        "/* Strategy actions of `{}` ({}): phase 1 enters r->action (issues its\n * commands), phase 2 waits for them and takes the first transition that holds. */\nstatic int actions_{index}(region *r)\n{{\n    switch (r->action) {{",
        c::comment(&am.service),
        c::comment(&am.source)
    );
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
                .map_or_else(|| "true".to_string(), |c| expr(c, words));
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

fn emit_modes(out: &mut String, program: &RobotProgram) {
    let m = &program.control;
    out.push_str("/* Enters a mode: every plan the mode sets starts its service. */\nstatic void enter_mode(int mode)\n{\n    for (int i = 0; i < REGION_COUNT; i++) {\n        regions[i].service = -1;\n        regions[i].done = true;\n    }\n    current_mode = mode;\n    semo_trace(\"mode\", \"mode\", mode_name[mode], NULL);\n    switch (mode) {\n");
    for mode in &m.modes {
        let _ = writeln!(
            out,
            "    case MODE_{}: /* {}:{} */",
            c::ident(&mode.name),
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
    out.push_str("    default:\n        break;\n    }\n    for (int i = 0; i < REGION_COUNT; i++) {\n        region *r = &regions[i];\n        if (r->service < 0)\n            continue;\n        r->pc = 0;\n        r->phase = 0;\n        r->done = false;\n        r->started = r->pass_start = semo_now_ms();\n        semo_trace(\"service_start\", \"plan\", r->plan, \"service\", service_name[r->service], NULL);\n    }\n}\n\n");
    out.push_str("/* Leaves the current mode: tasks its services called are stopped. */\nstatic void leave_mode(void)\n{\n    for (int i = 0; i < REGION_COUNT; i++) {\n        region *r = &regions[i];\n        if (r->service >= 0 && !r->done)\n            semo_trace(\"service_end\", \"plan\", r->plan, \"service\", service_name[r->service], \"why\", \"mode change\", NULL);\n    }\n");
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
        .map(|d| format!("MODE_{}", c::ident(&m.modes[d].name)));
    let _ = writeln!(
        out,
        "/* One firing: read inputs, advance every region, then change mode if an\n * event asked for it; the robot is finished when no region runs any more. */\nvoid task_{name}_go(void)\n{{\n    next_wake = INT64_MAX;\n    read_inputs();"
    );
    if !m.battery.is_empty() {
        out.push_str("    manage_resources();\n");
    }
    if m.heartbeat {
        // Tell the team this robot is alive, for leader elections.
        let _ = writeln!(
            out,
            "    static int64_t last_heartbeat = -{hb};\n    if (semo_now_ms() - last_heartbeat >= {hb}) {{\n        semo_value alive;\n        char text[64];\n        long battery = own_battery();\n        char said[24];\n        term_text(leading ? term_led : known_term(), said);\n        last_heartbeat = semo_now_ms();\n        if (battery < 0)\n            snprintf(text, sizeof text, \"%s - %s\", leading ? \"leader\" : \"member\", said);\n        else\n            snprintf(text, sizeof text, \"%s %ld %s\", leading ? \"leader\" : \"member\", battery, said);\n        semo_value_set(&alive, text);\n        semo_comm_send({team}, SEMO_MSG_PUBLISH, {key}, &alive);\n{group}    }}\n    wake_at(last_heartbeat + {hb});",
            hb = m.heartbeat_ms,
            team = c::string(&program.team),
            key = c::string(&super::files::alive_key(program)),
            group = group_update(m, peers),
        );
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
    let _ = writeln!(
        out,
        "    bool running = false;\n    for (int i = 0; i < REGION_COUNT && pending_mode < 0; i++) {{\n        region *r = &regions[i];\n        if (r->service < 0 || r->done)\n            continue;\n        if (r->timeout_ms > 0 && semo_now_ms() - r->started > r->timeout_ms) {{\n            r->done = true;\n            semo_trace(\"service_end\", \"plan\", r->plan, \"service\", service_name[r->service], \"why\", \"timeout\", NULL);\n            continue;\n        }}\n        if (r->timeout_ms > 0)\n            wake_at(r->started + r->timeout_ms + 1);\n        int result = STEP_NEXT;\n        for (int n = 0; n < {STEPS_PER_FIRING} && result == STEP_NEXT && pending_mode < 0; n++)\n            result = step(r);\n        if (result == STEP_NEXT)\n            wake_at(semo_now_ms()); /* more to do than one firing takes */\n        if (result == STEP_DONE) {{\n            r->done = true;\n            semo_trace(\"service_end\", \"plan\", r->plan, \"service\", service_name[r->service], NULL);\n        }} else {{\n            running = true;\n        }}\n    }}\n    if (pending_mode >= 0) {{\n        int next = pending_mode;\n        leave_mode();\n        pending_mode = -1;\n        enter_mode(next);\n        return;\n    }}\n    if (!running) {{\n        semo_trace(\"finish\", \"mode\", mode_name[current_mode], NULL);\n{flush}        semo_stop_program();\n        return;\n    }}\n    semo_next_firing(next_wake);\n}}\n\nvoid task_{name}_wrapup(void)\n{{\n}}"
    );
}
