//! The other files of a robot's folder: `program.h`, `main.c`, `channels.c`,
//! `comm_task.c`, `lib_<name>.c`, `tasks/<task>.c` and the `Makefile`.

use super::c;
use super::peers::Peers;
use super::values::Words;
use super::{CompiledScenario, Layer, Target};
use crate::refine::graph::{COMM_RECEIVE, COMM_SEND, CONTROL_TASK};
use crate::refine::{RobotProgram, RoleKind, ValueKind};
use crate::taskgraph::Trigger;
use std::fmt::Write;

/// The key of the heartbeats a team's robots publish for leader elections.
pub fn alive_key(program: &RobotProgram) -> String {
    format!("{}.__alive", program.team)
}

/// The key of the announcements a team's robots send when they reach a
/// group statement they synchronize at (`GroupSync`).
pub fn sync_key(program: &RobotProgram) -> String {
    format!("{}.__sync", program.team)
}

/// Samples of a request channel: a service name and its arguments.
fn is_request_channel(src_task: &str, src_port: &str) -> bool {
    src_task == CONTROL_TASK && src_port.starts_with("req_")
}

/// Every task of the program with the C prefix of its functions.
fn task_functions(program: &RobotProgram) -> Vec<(String, String)> {
    program
        .graph
        .tasks
        .iter()
        .map(|t| {
            (
                t.name.name.to_string(),
                format!("task_{}", c::ident(&t.name.name)),
            )
        })
        .collect()
}

pub fn program_h(program: &RobotProgram, header: &str) -> String {
    let mut out = String::from(header);
    out.push_str(
        "#ifndef SEMO_PROGRAM_H\n#define SEMO_PROGRAM_H\n\n#include \"semo_runtime.h\"\n\n",
    );
    out.push_str("/* A service request from the control task to a task: the service (or\n * actuator command) and its arguments. */\n#define SEMO_MAX_ARGS 4\ntypedef struct {\n    char service[32];\n    int argc;\n    semo_value args[SEMO_MAX_ARGS];\n} semo_request;\n\n");
    out.push_str("/* Task files: `TASK_INIT { }`, `TASK_GO { }` (one firing), `TASK_WRAPUP { }`;\n * the Makefile compiles tasks/<name>.c with SEMO_TASK=task_<name>. */\n#define SEMO_CAT_(a, b) a##b\n#define SEMO_CAT(a, b) SEMO_CAT_(a, b)\n#define SEMO_STR_(a) #a\n#define SEMO_STR(a) SEMO_STR_(a)\n#define TASK_INIT void SEMO_CAT(SEMO_TASK, _init)(void)\n#define TASK_GO void SEMO_CAT(SEMO_TASK, _go)(void)\n#define TASK_WRAPUP void SEMO_CAT(SEMO_TASK, _wrapup)(void)\n/* The task's name, for UFPort_Initialize and UFControl_*. */\n#define TASK_NAME (&SEMO_STR(SEMO_TASK)[5])\n\n");
    for (_, prefix) in task_functions(program) {
        let _ = writeln!(
            out,
            "void {prefix}_init(void);\nvoid {prefix}_go(void);\nvoid {prefix}_wrapup(void);"
        );
    }
    if program.control.heartbeat {
        out.push_str("\n/* What the last heartbeat of a robot said (comm_task.c): when it came\n * (mission ms), whether the robot claimed leadership, its battery level\n * (-1: unknown), its term (docs/groups.md, \"Terms\"). */\ntypedef struct {\n    int64_t seen;\n    bool leads;\n    long battery;\n    int64_t term;\n} comm_heartbeat;\ncomm_heartbeat comm_heard(size_t peer);\n/* The highest term any heartbeat heard said (0 before any). */\nint64_t comm_highest_term(void);\n");
        if !program.control.sync_points.is_empty() {
            out.push_str("/* The last pass of a robot through sync point `point` (an index into\n * the program's sync points) that it announced; 0 before any. */\nlong comm_sync_arrived(size_t peer, size_t point);\n");
        }
    }
    if !program.control.events_heard.is_empty() {
        out.push_str("\n/* The next broadcast event received (comm_task.c), in arrival order: the\n * thrower's peer index and the event's name; false when none waits. */\nbool comm_event_take(size_t *from, const char **event);\n");
    }
    out.push_str(&super::shared::declarations(program));
    let _ = writeln!(
        out,
        "\n/* The task graph's channels (channels.c). */\n#define SEMO_CHANNEL_COUNT {}\nextern const semo_channel_desc semo_program_channels[];",
        program.graph.channels.len()
    );
    out.push_str("\n#endif\n");
    out
}

pub fn channels_c(program: &RobotProgram, target: Target, header: &str) -> String {
    let mut out = String::from(header);
    out.push_str("#include \"program.h\"\n\n");
    let sample = |ch: &crate::taskgraph::model::Channel| {
        if is_request_channel(&ch.src.task, &ch.src.port) {
            "sizeof(semo_request)"
        } else {
            "sizeof(semo_value)"
        }
    };
    // Without a heap, every channel's ring is a static buffer of its own.
    let fixed = target.layer() == Layer::Static;
    if fixed {
        out.push_str("/* Each channel's samples and ring state (no heap on this target). */\n");
        for (i, (ch, capacity)) in program
            .graph
            .channels
            .iter()
            .zip(&program.capacities)
            .enumerate()
        {
            let _ = writeln!(
                out,
                "static unsigned char buffer_{i}[{capacity} * {}];\nstatic semo_channel_state state_{i};",
                sample(ch)
            );
        }
        out.push('\n');
    }
    out.push_str("/* The channels of the task graph; capacities from the buffer analysis. */\nconst semo_channel_desc semo_program_channels[] = {\n");
    for (i, (ch, capacity)) in program
        .graph
        .channels
        .iter()
        .zip(&program.capacities)
        .enumerate()
    {
        let storage = if fixed {
            format!("buffer_{i}, &state_{i}")
        } else {
            "NULL, NULL".to_string()
        };
        let _ = writeln!(
            out,
            "    {{{}, {}, {}, {}, {}, {capacity}, {}, {storage}}},",
            c::string(&ch.src.task),
            c::string(&ch.src.port),
            c::string(&ch.dst.task),
            c::string(&ch.dst.port),
            sample(ch),
            ch.initial_tokens
        );
    }
    if program.graph.channels.is_empty() {
        out.push_str("    {\"\", \"\", \"\", \"\", sizeof(semo_value), 1, 0, NULL, NULL},\n");
    }
    out.push_str("};\n");
    out
}

pub fn main_c(
    program: &RobotProgram,
    words: &Words,
    peers: &Peers,
    target: Target,
    header: &str,
) -> String {
    let mut out = String::from(header);
    out.push_str(match target.layer() {
        Layer::Threads => "#include \"program.h\"\n\n/* Tasks: one thread each. */\nstatic const semo_task_desc tasks[] = {\n",
        Layer::Static => "#include \"program.h\"\n\n/* Tasks: fired by Core_1_go in the order of `schedule`. */\nstatic const semo_task_desc tasks[] = {\n",
    });
    for task in &program.graph.tasks {
        let prefix = format!("task_{}", c::ident(&task.name.name));
        let (trigger, period) = match &task.trigger {
            Trigger::Time { period_ms } => ("SEMO_TRIGGER_TIME", period_ms.round() as i64),
            Trigger::Data => ("SEMO_TRIGGER_DATA", 0),
            Trigger::Control => ("SEMO_TRIGGER_CONTROL", 0),
        };
        let _ = writeln!(
            out,
            "    {{{}, {trigger}, {period}, {prefix}_init, {prefix}_go, {prefix}_wrapup}},",
            c::string(&task.name.name)
        );
    }
    out.push_str("};\n\n");
    let groups = &program.control.subscribed;
    if !groups.is_empty() {
        out.push_str("/* Multicast groups: the latest published value of each. */\nstatic const semo_multicast_desc groups[] = {\n");
        for g in groups {
            let _ = writeln!(out, "    {{{}, sizeof(semo_value)}},", c::string(g));
        }
        out.push_str("};\n\n");
    }
    let static_schedule = target.layer() == Layer::Static;
    if static_schedule {
        match super::schedule::firings(&program.graph) {
            Ok(firings) => {
                out.push_str("/* One iteration of the task graph's single-appearance schedule:\n * (task index, consecutive firings). */\nstatic const semo_firing schedule[] = {\n");
                for (task, count) in &firings {
                    let name = program.graph.tasks.get(*task).map_or("", |t| &t.name.name);
                    let _ = writeln!(out, "    {{{task}, {count}}}, /* {} */", c::comment(name));
                }
                out.push_str("};\n\n");
            }
            // The build refuses such a program first (E102); a folder
            // generated anyway must not compile into a different program.
            Err(why) => {
                let _ = writeln!(out, "#error \"no static schedule: {}\"\n", c::comment(&why));
            }
        }
    }
    if !words.list().is_empty() {
        out.push_str("/* The words of the program: a word value is an index into it. */\nstatic const char *const words[] = {\n");
        for w in words.list() {
            let _ = writeln!(out, "    {},", c::string(w));
        }
        out.push_str("};\n\n");
    }
    out.push_str("/* The robots this one sends to or hears from (its team and those its\n * messages go to), each with its place among the mission's robots: over\n * UDP it listens on port base + place. */\nstatic const semo_peer peers[] = {\n");
    for &i in peers.list() {
        let (team, robot) = &program.peers[i];
        let _ = writeln!(
            out,
            "    {{{}, {}, {i}}},",
            c::string(team),
            c::string(robot)
        );
    }
    out.push_str("};\n\n");
    let threads = target.layer() == Layer::Threads;
    if threads {
        out.push_str(DEPLOY_DEFAULTS);
    }
    let _ = writeln!(
        out,
        "static const semo_program_desc program = {{\n    .mission = {},\n    .team = {},\n    .robot = {},\n    .robot_type = {},\n    .tasks = tasks,\n    .task_count = sizeof tasks / sizeof tasks[0],\n    .channels = semo_program_channels,\n    .channel_count = SEMO_CHANNEL_COUNT,\n    .groups = {},\n    .group_count = {},\n    .peers = peers,\n    .peer_count = sizeof peers / sizeof peers[0],\n    .self = {},\n    .robot_count = {},\n{}{}{}}};\n\nint main(int argc, char **argv)\n{{\n    return semo_main(argc, argv, &program);\n}}",
        c::string(&program.mission),
        c::string(&program.team),
        c::string(&program.robot),
        c::string(&program.robot_type),
        if groups.is_empty() { "NULL" } else { "groups" },
        groups.len(),
        peers.own(),
        program.peers.len(),
        if static_schedule {
            "    .schedule = schedule,\n    .schedule_count = sizeof schedule / sizeof schedule[0],\n"
        } else {
            ""
        },
        if words.list().is_empty() {
            ""
        } else {
            "    .words = words,\n    .word_count = sizeof words / sizeof words[0],\n"
        },
        if threads {
            "    .deploy = &deploy,\n"
        } else {
            ""
        }
    );
    out
}

/// The connection defaults of a threads robot, read from its own
/// `semo_deploy.h` here (the runtime every robot of a build shares cannot
/// include one robot's header).
const DEPLOY_DEFAULTS: &str = "/* The connection defaults `semo build --deploy` baked into semo_deploy.h;\n * NULL where it gave none. */\n#include \"semo_deploy.h\"\n#ifndef SEMO_DEPLOY_BROKER\n#define SEMO_DEPLOY_BROKER NULL\n#endif\n#ifndef SEMO_DEPLOY_CLIENT_ID\n#define SEMO_DEPLOY_CLIENT_ID NULL\n#endif\n#ifndef SEMO_DEPLOY_USER\n#define SEMO_DEPLOY_USER NULL\n#endif\n#ifndef SEMO_DEPLOY_PASSWORD_FILE\n#define SEMO_DEPLOY_PASSWORD_FILE NULL\n#endif\n#ifndef SEMO_DEPLOY_CA\n#define SEMO_DEPLOY_CA NULL\n#endif\n#ifndef SEMO_DEPLOY_CERT\n#define SEMO_DEPLOY_CERT NULL\n#endif\n#ifndef SEMO_DEPLOY_KEY\n#define SEMO_DEPLOY_KEY NULL\n#endif\nstatic const semo_deploy_defaults deploy = {\n    .broker = SEMO_DEPLOY_BROKER,\n    .client_id = SEMO_DEPLOY_CLIENT_ID,\n    .user = SEMO_DEPLOY_USER,\n    .password_file = SEMO_DEPLOY_PASSWORD_FILE,\n    .ca = SEMO_DEPLOY_CA,\n    .cert = SEMO_DEPLOY_CERT,\n    .key = SEMO_DEPLOY_KEY,\n};\n\n";

/// The lock of state shared between tasks: a mutex on threads, nothing on
/// the static schedule (one task runs at a time). `(include, declare, lock,
/// unlock)` for a lock named `name`.
pub(super) fn lock(target: Target, name: &str) -> (&'static str, String, String, String) {
    match target.layer() {
        Layer::Threads => (
            "#include <pthread.h>\n",
            format!("static pthread_mutex_t {name} = PTHREAD_MUTEX_INITIALIZER;\n"),
            format!("pthread_mutex_lock(&{name});"),
            format!("pthread_mutex_unlock(&{name});"),
        ),
        Layer::Static => (
            "",
            String::new(),
            "/* no lock: one task runs at a time */".into(),
            "/* end of the access */".into(),
        ),
    }
}

pub fn comm_task_c(
    program: &RobotProgram,
    words: &Words,
    peers: &Peers,
    target: Target,
    header: &str,
) -> String {
    let m = &program.control;
    let mut out = String::from(header);
    let (include, declare, lock_seen, unlock_seen) = lock(target, "seen_lock");
    let _ = write!(
        out,
        "#include \"program.h\"\n{}{}#include <string.h>\n\n",
        if m.heartbeat { include } else { "" },
        if m.heartbeat {
            "#include <stdlib.h>\n"
        } else {
            ""
        }
    );
    if !m.outgoing.is_empty() {
        out.push_str("/* CommSend: every value the control task sends goes to the robots of its\n * team (through the transport). */\nstatic const struct {\n    const char *port;\n    const char *to_team;\n    semo_msg_kind kind;\n    const char *key;\n} outgoing[] = {\n");
        for o in &m.outgoing {
            let _ = writeln!(
                out,
                "    {{{}, {}, {}, {}}},",
                c::string(&o.port),
                c::string(&o.to_team),
                if o.publish {
                    "SEMO_MSG_PUBLISH"
                } else {
                    "SEMO_MSG_SEND"
                },
                c::string(&o.key)
            );
        }
        let n = m.outgoing.len();
        let _ = writeln!(
            out,
            "}};\nstatic int outgoing_port[{n}];\n\nvoid task_{send}_init(void)\n{{\n    for (int i = 0; i < {n}; i++)\n        outgoing_port[i] = UFPort_Initialize({send_name}, outgoing[i].port);\n}}\n\nvoid task_{send}_go(void)\n{{\n    for (int i = 0; i < {n}; i++) {{\n        semo_value v;\n        while (UFPort_GetNumOfAvailableData(outgoing_port[i]) > 0\n               && UFPort_ReadFromQueue(outgoing_port[i], &v, sizeof v) > 0)\n            semo_comm_send(outgoing[i].to_team, outgoing[i].kind, outgoing[i].key, &v);\n    }}\n    /* Nothing to send until the control task writes again. */\n    semo_next_firing(INT64_MAX);\n}}\n\nvoid task_{send}_wrapup(void)\n{{\n}}\n",
            send = c::ident(COMM_SEND),
            send_name = c::string(COMM_SEND)
        );
    }
    if m.heartbeat {
        let _ = writeln!(
            out,
            "/* Heartbeats of the team's robots, for leader elections: when each robot\n * was last heard from, and what it said (`leader 87 3`: it claims\n * leadership under term 3, battery 87; `member - 2`: it does not, battery\n * unknown, the highest term it knows is 2). Every robot counts as alive at\n * start. */\n{declare}static comm_heartbeat heard[{peers}];\nstatic int64_t highest_term;\n\ncomm_heartbeat comm_heard(size_t peer)\n{{\n    comm_heartbeat h = {{0, false, -1, 0}};\n    {lock_seen}\n    if (peer < {peers})\n        h = heard[peer];\n    {unlock_seen}\n    return h;\n}}\n\nint64_t comm_highest_term(void)\n{{\n    {lock_seen}\n    int64_t t = highest_term;\n    {unlock_seen}\n    return t;\n}}\n\n/* A term's leading digits, at most {term_max} (a larger one says this). */\nstatic int64_t parse_term(const char *s)\n{{\n    int64_t t = 0;\n    for (; *s >= '0' && *s <= '9'; s++) {{\n        t = t * 10 + (*s - '0');\n        if (t > {term_max}LL)\n            t = {term_max}LL;\n    }}\n    return t;\n}}\n\nstatic bool heard_alive(const semo_message *m)\n{{\n    if (m->kind != SEMO_MSG_PUBLISH || strcmp(m->key, {key}) != 0)\n        return false;\n    /* The value is text; of another type it says only that the robot lives. */\n    const char *said = m->value.type == SEMO_TEXT ? m->value.text : \"\";\n    const char *battery = strchr(said, ' ');\n    const char *term = battery ? strchr(battery + 1, ' ') : NULL;\n    comm_heartbeat h = {{semo_now_ms(), strncmp(said, \"leader \", 7) == 0, -1, 0}};\n    if (battery && battery[1] >= '0' && battery[1] <= '9')\n        h.battery = strtol(battery + 1, NULL, 10);\n    if (term)\n        h.term = parse_term(term + 1);\n    const semo_program_desc *p = semo_program();\n    for (size_t i = 0; i < p->peer_count && i < {peers}; i++)\n        if (strcmp(p->peers[i].robot, m->from_robot) == 0) {{\n            {lock_seen}\n            heard[i] = h;\n            if (h.term > highest_term)\n                highest_term = h.term;\n            {unlock_seen}\n        }}\n    return true;\n}}\n",
            peers = peers.len(),
            key = c::string(&alive_key(program)),
            term_max = super::control::TERM_MAX,
        );
    }
    if !m.sync_points.is_empty() {
        let points: Vec<String> = m.sync_points.iter().map(|p| p.to_string()).collect();
        let _ = writeln!(
            out,
            "/* GroupSync: for each robot and sync point (the group statement's offset\n * in the mission), the last pass it announced (`Team.__sync` = \"<point>\n * <pass>\"). A new one wakes the control task, which may be waiting. */\nstatic const long sync_point[] = {{{list}}};\nstatic long arrived[{peers}][{n}];\n\nlong comm_sync_arrived(size_t peer, size_t point)\n{{\n    long pass = 0;\n    {lock_seen}\n    if (peer < {peers} && point < {n})\n        pass = arrived[peer][point];\n    {unlock_seen}\n    return pass;\n}}\n\nstatic bool heard_sync(const semo_message *m)\n{{\n    if (strcmp(m->key, {key}) != 0)\n        return false;\n    /* The value is text; of another type it says nothing. */\n    const char *said = m->value.type == SEMO_TEXT ? m->value.text : \"\";\n    char *end;\n    long point = strtol(said, &end, 10), pass = strtol(end, NULL, 10);\n    const semo_program_desc *p = semo_program();\n    for (size_t i = 0; i < p->peer_count && i < {peers}; i++)\n        for (size_t k = 0; k < {n}; k++)\n            if (strcmp(p->peers[i].robot, m->from_robot) == 0 && sync_point[k] == point) {{\n                {lock_seen}\n                if (pass > arrived[i][k])\n                    arrived[i][k] = pass;\n                {unlock_seen}\n            }}\n    semo_wake({control});\n    return true;\n}}\n",
            list = points.join(", "),
            n = m.sync_points.len(),
            peers = peers.len(),
            key = c::string(&sync_key(program)),
            control = c::string(CONTROL_TASK),
        );
    }
    if !m.events_heard.is_empty() {
        comm_events(&mut out, program, target);
    }
    if m.has_receiver() {
        out.push_str("/* CommReceive: each message received goes to the control task's port for\n * it (sends) or to its multicast group (publishes). */\n");
        let n = m.incoming.len();
        if n > 0 {
            out.push_str("static const struct {\n    const char *port;\n    const char *from_team;\n    const char *key;\n    semo_type type; /* as declared: a value of another type is refused */\n    const unsigned short *domain; /* an enumeration's words (indices), or NULL */\n    unsigned short domain_len;\n} incoming[] = {\n");
            for i in &m.incoming {
                let kind = &m.slots[i.slot.index()].kind;
                // A word of another enumeration is refused, as the simulator does.
                let domain = match kind {
                    // `{0}` with length 0: an empty enumeration refuses every word.
                    ValueKind::Word(domain) if domain.is_empty() => {
                        "(const unsigned short[]){0}, 0".into()
                    }
                    ValueKind::Word(domain) => format!(
                        "(const unsigned short[]){{{}}}, {}",
                        domain
                            .iter()
                            .map(|w| words.index(w).to_string())
                            .collect::<Vec<_>>()
                            .join(", "),
                        domain.len()
                    ),
                    _ => "NULL, 0".into(),
                };
                let _ = writeln!(
                    out,
                    "    {{{}, {}, {}, {}, {domain}}},",
                    c::string(&i.port),
                    c::string(&i.from_team),
                    c::string(&i.key),
                    kind.c_tag()
                );
            }
            let _ = writeln!(out, "}};\nstatic int incoming_port[{n}];\n");
        }
        if !m.subscribed.is_empty() {
            out.push_str("static const char *const subscribed[] = {");
            for (i, g) in m.subscribed.iter().enumerate() {
                let _ = write!(out, "{}{}", if i == 0 { " " } else { ", " }, c::string(g));
            }
            out.push_str(" };\n\n");
        }
        let recv = c::ident(COMM_RECEIVE);
        let _ = writeln!(out, "void task_{recv}_init(void)\n{{");
        if m.heartbeat {
            let _ = writeln!(
                out,
                "    for (size_t i = 0; i < {}; i++)\n        heard[i].battery = -1;",
                peers.len()
            );
        }
        if n > 0 {
            let _ = writeln!(
                out,
                "    for (int i = 0; i < {n}; i++)\n        incoming_port[i] = UFPort_Initialize({}, incoming[i].port);",
                c::string(COMM_RECEIVE)
            );
        }
        let _ = writeln!(
            out,
            "}}\n\nvoid task_{recv}_go(void)\n{{\n    semo_message m;\n    if (!semo_comm_poll(&m, -1))\n        return;"
        );
        if m.heartbeat {
            out.push_str("    if (heard_alive(&m))\n        return;\n");
        }
        if !m.sync_points.is_empty() {
            out.push_str("    if (heard_sync(&m))\n        return;\n");
        }
        if !m.events_heard.is_empty() {
            out.push_str("    if (heard_event(&m))\n        return;\n");
        }
        if let Some(dispatch) = super::shared::comm_dispatch(program) {
            out.push_str(&dispatch);
        }
        if !m.subscribed.is_empty() {
            let _ = writeln!(
                out,
                "    if (m.kind == SEMO_MSG_PUBLISH) {{\n        for (size_t i = 0; i < sizeof subscribed / sizeof subscribed[0]; i++)\n            if (strcmp(subscribed[i], m.key) == 0)\n                UFMulticast_Write(subscribed[i], &m.value, sizeof m.value);\n        return;\n    }}"
            );
        }
        if n > 0 {
            let _ = writeln!(
                out,
                "    for (int i = 0; i < {n}; i++) {{\n        if (strcmp(incoming[i].from_team, m.from_team) != 0 || strcmp(incoming[i].key, m.key) != 0)\n            continue;\n        semo_value v = m.value;\n        if (semo_value_coerce(&v, incoming[i].type) && semo_value_in(&v, incoming[i].domain, incoming[i].domain_len)) {{\n            if (!semo_port_offer(incoming_port[i], &v, sizeof v))\n                semo_trace(\"drop\", \"from\", m.from_team, \"key\", m.key, \"reason\", semo_running() ? \"channel full\" : \"stopping\", NULL);\n        }} else\n            semo_trace(\"reject\", \"key\", m.key, \"reason\", \"not a value of its type\", NULL);\n    }}"
            );
        }
        let _ = writeln!(out, "}}\n\nvoid task_{recv}_wrapup(void)\n{{\n}}");
    }
    if m.outgoing.is_empty() && !m.has_receiver() {
        out.push_str(
            "/* This robot exchanges no messages. */\ntypedef int semo_no_communication;\n",
        );
    }
    out
}

/// The broadcast events the team's robots tell this one (`throw E
/// broadcast`, key `Team.__event`): queued in arrival order for the control
/// task (`comm_event_take`), as the simulator's `hear_event` does.
fn comm_events(out: &mut String, program: &RobotProgram, target: Target) {
    let m = &program.control;
    let (include, declare, lock, unlock) = lock(target, "event_lock");
    let names: Vec<String> = m.events_heard.iter().map(|e| c::string(e)).collect();
    let _ = writeln!(
        out,
        "{include}/* Broadcast events (`throw E broadcast`: key `{key_comment}`, the event's name\n * as text) that the team's robots tell this one, queued in arrival order\n * until the control task takes them at its next firing; one arriving while\n * {cap} wait is dropped. */\nstatic const char *const event_heard[] = {{{list}}};\n#define EVENT_KINDS {n}\n#define EVENT_QUEUE {cap}\n{declare}static struct {{\n    size_t from;\n    size_t event;\n}} event_queue[EVENT_QUEUE];\nstatic size_t event_first, event_count;\n\nbool comm_event_take(size_t *from, const char **event)\n{{\n    bool taken = false;\n    {lock}\n    if (event_count > 0) {{\n        *from = event_queue[event_first].from;\n        *event = event_heard[event_queue[event_first].event];\n        event_first = (event_first + 1) % EVENT_QUEUE;\n        event_count--;\n        taken = true;\n    }}\n    {unlock}\n    return taken;\n}}\n\nstatic bool heard_event(const semo_message *m)\n{{\n    if (m->kind != SEMO_MSG_SEND || strcmp(m->key, {key}) != 0 || strcmp(m->from_team, {team}) != 0)\n        return false;\n    const semo_program_desc *p = semo_program();\n    size_t from = p->peer_count, event = EVENT_KINDS;\n    for (size_t i = 0; i < p->peer_count && from == p->peer_count; i++)\n        if (strcmp(p->peers[i].robot, m->from_robot) == 0)\n            from = i;\n    /* The value is the event's name as text; anything else names none. */\n    for (size_t k = 0; k < EVENT_KINDS && m->value.type == SEMO_TEXT && event == EVENT_KINDS; k++)\n        if (strcmp(event_heard[k], m->value.text) == 0)\n            event = k;\n    if (from == p->peer_count || event == EVENT_KINDS) {{\n        semo_trace(\"reject\", \"key\", m->key, \"reason\", \"not an event it hears\", NULL);\n        return true;\n    }}\n    {lock}\n    bool room = event_count < EVENT_QUEUE;\n    if (room) {{\n        size_t at = (event_first + event_count) % EVENT_QUEUE;\n        event_queue[at].from = from;\n        event_queue[at].event = event;\n        event_count++;\n    }}\n    {unlock}\n    if (!room) {{\n        semo_trace(\"drop\", \"from\", m->from_robot, \"name\", event_heard[event], \"reason\", \"too many events\", NULL);\n        return true;\n    }}\n    semo_wake({control});\n    return true;\n}}\n",
        key_comment = c::comment(&crate::refine::event_key(&program.team)),
        list = names.join(", "),
        n = names.len(),
        cap = crate::refine::EVENT_QUEUE,
        key = c::string(&crate::refine::event_key(&program.team)),
        team = c::string(&program.team),
        control = c::string(CONTROL_TASK),
    );
}

/// `tasks/<task>.c`: the simulation's own body for `linux-sim`; for `linux`
/// a template for the user to fill (written only when absent).
pub fn task_c(
    program: &RobotProgram,
    role: &crate::refine::TaskRole,
    target: Target,
    header: &str,
) -> Option<String> {
    let mut out = String::from(header);
    // The user's service template compares service names (`strcmp`).
    let needs_string_h = !target.simulated() && matches!(role.kind, RoleKind::Service { .. });
    out.push_str(if needs_string_h {
        "#include \"../program.h\"\n#include <string.h>\n\n"
    } else {
        "#include \"../program.h\"\n\n"
    });
    match (&role.kind, target) {
        (RoleKind::Sensor { values, period_ms }, _) => {
            let _ = writeln!(
                out,
                "/* Sensor task `{}` of robot {}: every {period_ms} ms, one sample of {}. */",
                c::comment(&role.task),
                c::comment(&program.robot),
                c::comment(&values.join(", "))
            );
            for v in values {
                let _ = writeln!(out, "static int port_{} = -1;", c::ident(v));
            }
            out.push_str("\nTASK_INIT\n{\n");
            for v in values {
                let _ = writeln!(
                    out,
                    "    port_{} = UFPort_Initialize(TASK_NAME, {});",
                    c::ident(v),
                    c::string(v)
                );
            }
            let level_hint = super::battery::sensor_level_hint(program, &role.task, *period_ms);
            out.push_str("}\n\nTASK_GO\n{\n    semo_value value;\n");
            if level_hint.is_some() {
                out.push_str("    int64_t fired = semo_now_ms();\n");
            }
            for v in values {
                // Refinement gives every sensor value a slot of its type.
                let Some(kind) = program.control.sensor_kind(&role.task, v) else {
                    let _ = writeln!(out, "#error \"sensor value {} has no type\"", c::comment(v));
                    continue;
                };
                match target.simulated() {
                    true => {
                        let _ = writeln!(
                            out,
                            "    if (semo_sim_sensor({}, {}, &value))\n        UFPort_WriteToQueue(port_{}, &value, sizeof value);",
                            c::string(v),
                            kind.c_tag(),
                            c::ident(v)
                        );
                    }
                    false => {
                        let _ = writeln!(
                            out,
                            "    /* TODO: read {v} ({ty}) from the sensor, e.g. {example},\n     * then write it: UFPort_WriteToQueue(port_{id}, &value, sizeof value). */\n    (void)value;\n    (void)port_{id};",
                            v = c::comment(v),
                            ty = c::comment(&kind.describe()),
                            example = setter_example(kind),
                            id = c::ident(v)
                        );
                    }
                }
            }
            out.push_str(&level_hint.unwrap_or_default());
            out.push_str("}\n\nTASK_WRAPUP\n{\n}\n");
        }
        (RoleKind::Service { services }, _)
            if target.simulated() && target.layer() == Layer::Static =>
        {
            let speed_scale = super::battery::actuator_speed_scale(program, &role.task);
            out.push_str(speed_scale.as_deref().unwrap_or_default());
            // Nothing may block on the static schedule: the call spans
            // passes of the loop (semo_firing_continues) until its time is up.
            let _ = writeln!(
                out,
                "/* Task `{}` of robot {}: runs {} when the control task calls it; the\n * simulated service takes the scenario's time for it, over several passes\n * of the schedule. */\nstatic int port_request = -1;\nstatic semo_request req;\nstatic bool busy;\nstatic int64_t end;\n\nTASK_INIT\n{{\n    port_request = UFPort_Initialize(TASK_NAME, \"request\");\n}}\n\nTASK_GO\n{{\n    if (!busy) {{\n        if (UFPort_ReadFromQueue(port_request, &req, sizeof req) == 0)\n            return;\n        semo_trace_value(\"call_start\", \"arg\", req.argc > 0 ? &req.args[0] : SEMO_LIT(\"\"), \"task\", TASK_NAME, \"service\", req.service, NULL);\n        if (req.argc > 0)\n            semo_sim_actuate(TASK_NAME, &req.args[0]);\n        end = semo_now_ms() + semo_sim_service_ms(req.service){scale};\n        busy = true;\n    }}\n    if (semo_running() && !UFControl_StopRequested(TASK_NAME) && semo_now_ms() < end) {{\n        semo_firing_continues();\n        semo_next_firing(end); /* or a stop request, whichever is first */\n        return;\n    }}\n    busy = false;\n    semo_trace(\"call_end\", \"task\", TASK_NAME, \"service\", req.service, NULL);\n}}\n\nTASK_WRAPUP\n{{\n}}",
                c::comment(&role.task),
                c::comment(&program.robot),
                c::comment(&services.join(", ")),
                scale = if speed_scale.is_some() {
                    " * speed_scale()"
                } else {
                    ""
                },
            );
        }
        (RoleKind::Service { services }, _) => {
            let _ = writeln!(
                out,
                "/* Task `{}` of robot {}: runs {} when the control task calls it. */\nstatic int port_request = -1;\n\nTASK_INIT\n{{\n    port_request = UFPort_Initialize(TASK_NAME, \"request\");\n}}\n\nTASK_GO\n{{\n    semo_request req;\n    if (UFPort_ReadFromQueue(port_request, &req, sizeof req) == 0)\n        return;",
                c::comment(&role.task),
                c::comment(&program.robot),
                c::comment(&services.join(", "))
            );
            // A service implemented by a task graph runs one iteration of
            // it per call (target::check refuses it on static schedules).
            let graph = program.graph_services.iter().find(|g| g.task == role.task);
            if let Some(graph) = graph {
                let at = out.find("TASK_INIT").unwrap_or(out.len());
                out.insert_str(at, &super::loops::graph_runner(graph, target.simulated()));
            }
            let run_graph = if graph.is_some() {
                "    run_graph();\n"
            } else {
                ""
            };
            match (target.simulated(), target.layer()) {
                (true, Layer::Threads) => {
                    let scale = match super::battery::actuator_speed_scale(program, &role.task) {
                        Some(function) => {
                            // Before the task's functions.
                            let at = out.find("TASK_INIT").unwrap_or(out.len());
                            out.insert_str(at, &function);
                            " * speed_scale()"
                        }
                        None => "",
                    };
                    out.push_str("    semo_trace_value(\"call_start\", \"arg\", req.argc > 0 ? &req.args[0] : SEMO_LIT(\"\"), \"task\", TASK_NAME, \"service\", req.service, NULL);\n    if (req.argc > 0)\n        semo_sim_actuate(TASK_NAME, &req.args[0]);\n");
                    out.push_str(run_graph);
                    out.push_str("    /* The simulated service takes the scenario's time for it, or ends when\n     * the control task stops it. */\n    UFControl_WaitStop(TASK_NAME, semo_now_ms() + semo_sim_service_ms(req.service)");
                    out.push_str(scale);
                    out.push_str(");\n    semo_trace(\"call_end\", \"task\", TASK_NAME, \"service\", req.service, NULL);\n");
                }
                // The static simulation's body is the arm above.
                (true, Layer::Static) => {}
                (false, _) => {
                    out.push_str(run_graph);
                    out.push_str("    /* TODO: perform the service; req.args[0 .. req.argc - 1] are its arguments.\n     * Check UFControl_StopRequested(TASK_NAME) during long work. */\n");
                    for s in services {
                        let _ = writeln!(
                            out,
                            "    if (strcmp(req.service, {}) == 0) {{\n        /* {} */\n    }}",
                            c::string(s),
                            c::comment(s)
                        );
                    }
                }
            }
            out.push_str("}\n\nTASK_WRAPUP\n{\n}\n");
        }
        (RoleKind::CommSend | RoleKind::CommReceive, _) => return None,
    }
    Some(out)
}

/// The runtime's table sizes on the static schedule, from the program; the
/// Makefile's defaults (`make SEMO_STACK_BYTES=4096` overrides).
pub struct StaticSizes {
    /// Bytes of a text value (`SEMO_TEXT_MAX`): the program's longest text
    /// literal and scenario value fit, and at least 16.
    pub value_bytes: usize,
    pub tasks: usize,
    pub groups: usize,
    /// Messages received and not yet taken.
    pub inbox: usize,
    /// Whether the program holds reals (else `-DSEMO_NO_REALS`).
    pub reals: bool,
}

impl StaticSizes {
    pub fn of(program: &RobotProgram, longest_value: usize) -> StaticSizes {
        let receives = program
            .tasks
            .iter()
            .any(|t| t.kind == RoleKind::CommReceive);
        StaticSizes {
            value_bytes: (longest_value + 1).max(16).next_multiple_of(4),
            tasks: program.graph.tasks.len().max(1),
            groups: program.control.subscribed.len().max(1),
            inbox: if receives { 4 } else { 1 },
            reals: super::values::uses_reals(program),
        }
    }
}

/// The sources a robot's Makefile compiles: the robot's own (in its folder),
/// its task files, and the runtime's (in the shared runtime folder).
pub struct MakeSources<'a> {
    pub robot: &'a [String],
    pub tasks: &'a [String],
    pub runtime: &'a [&'a str],
}

pub fn makefile(
    program: &RobotProgram,
    target: Target,
    sources: &MakeSources<'_>,
    header: &str,
    sizes: &StaticSizes,
) -> String {
    let mut out = String::new();
    for line in header.lines() {
        let text = line
            .trim_start_matches("/*")
            .trim_end_matches("*/")
            .trim_start_matches(" *")
            .trim();
        if !text.is_empty() {
            let _ = writeln!(out, "# {text}");
        }
    }
    let runtime = format!(
        "# The runtime this robot shares with the others of the build: another\n# folder with `make RUNTIME=...` (robot folders copied elsewhere).\nRUNTIME ?= ../../{folder}\nRUNTIME_SOURCES = {sources}\n",
        folder = super::RUNTIME_FOLDER,
        sources = sources.runtime.join(" "),
    );
    let common = format!(
        "PROGRAM = {robot}{elf}\nSOURCES = {sources}\nTASKS = {tasks}\nOBJECTS = $(SOURCES:.c=.o) $(TASKS:.c=.o)\ninclude $(RUNTIME)/semo_runtime.mk\n",
        robot = program.robot,
        elf = if target.layer() == Layer::Static {
            ".elf"
        } else {
            ""
        },
        sources = sources.robot.join(" "),
        tasks = sources.tasks.join(" "),
    );
    let rules = "# Objects depend on the Makefile too: a new generation (another target, a\n# deployment baked in) rebuilds them.\n\ntasks/%.o: tasks/%.c $(HEADERS) Makefile\n\t$(CC) $(CFLAGS) $(SEMO_CFLAGS) -DSEMO_TASK=task_$* -c $< -o $@\n\n%.o: %.c $(HEADERS) Makefile\n\t$(CC) $(CFLAGS) $(SEMO_CFLAGS) -c $< -o $@\n";
    if let Some(board) = &target.platform().board {
        static_makefile(&mut out, program, target, board, &runtime, &common, sizes);
        out.push_str(rules);
        out.push_str(&format!(
            "\nsize: $(PROGRAM)\n\t$(SIZE) $(PROGRAM)\n\nrun: $(PROGRAM)\n\t$(QEMU) -M {machine} -nographic -semihosting -kernel $(PROGRAM)\n\nclean:\n\trm -f $(PROGRAM) $(OBJECTS)\n\n.PHONY: all size run clean\n",
            machine = board.machine,
        ));
        return out;
    }
    let _ = writeln!(
        out,
        "\n# `make` builds the program `{robot}` for target {target}; CC and CFLAGS may be\n# overridden (`make CC=clang CFLAGS=\"-O1 -fsanitize=thread\"`). `make STATIC=1`\n# links statically with musl (Debian musl-tools) and 64 KiB thread stacks: the\n# smallest footprint (`make clean` first when switching). TRANSPORT is the\n# default transport, udp (loopback) or mqtt (links libmosquitto, Debian\n# libmosquitto-dev; the program's --transport chooses among those built in;\n# musl has no libmosquitto: `make STATIC=1 TRANSPORT=udp`).\n{runtime}CFLAGS ?= -std=c11 -Wall -Wextra -O2\nTRANSPORT ?= {transport}\nSEMO_CFLAGS = -std=c11 -D_POSIX_C_SOURCE=200809L{sim} -I. -I$(RUNTIME)\nLDLIBS += -lpthread -lm\nifeq ($(TRANSPORT),mqtt)\nSEMO_CFLAGS += -DSEMO_MQTT\nLDLIBS += -lmosquitto\nendif\nifeq ($(STATIC),1)\nCC = musl-gcc\nLDFLAGS += -static\nSEMO_CFLAGS += -DSEMO_STACK_BYTES=65536\nendif\n\n{common}HEADERS = program.h {deploy} $(RUNTIME_HEADERS)\n\nall: $(PROGRAM)\n\n$(PROGRAM): $(OBJECTS) $(RUNTIME_OBJECTS)\n\t$(CC) $(CFLAGS) $(LDFLAGS) -o $@ $(OBJECTS) $(RUNTIME_OBJECTS) $(LDLIBS)\n\n{rules}\nclean:\n\trm -f $(PROGRAM) $(OBJECTS)\n\n.PHONY: all clean",
        robot = program.robot,
        target = target.name(),
        transport = target.transport().map_or("udp", |t| t.name()),
        sim = if target.simulated() {
            " -DSEMO_SIM"
        } else {
            ""
        },
        deploy = super::DEPLOY_HEADER,
    );
    out
}

/// The head of a board's Makefile, down to its `all` rule: every fact of
/// the board (toolchain, core, memory, link script, clock, timer, serial
/// port, emulator) from its row of the platform table.
fn static_makefile(
    out: &mut String,
    program: &RobotProgram,
    target: Target,
    board: &crate::platform::Board,
    runtime: &str,
    common: &str,
    sizes: &StaticSizes,
) {
    let _ = writeln!(
        out,
        "\n# `make` builds `{robot}.elf` for target {target} ({board}, a\n# {cpu}) with {cc} and {libc}; `make size` prints its\n# flash and RAM, `make run` runs it in QEMU ({serial} on standard output{exit}).\n# CFLAGS may be overridden; the runtime's static tables (sized from the task\n# graph) and the stack with\n# make variables (`make SEMO_STACK_BYTES=4096`). Mission time is counted by\n# {timer} at the core clock, SEMO_CPU_HZ.\n{runtime}CC = {cc}\nSIZE = {size}\nQEMU = {emulator}\nCFLAGS ?= -std=c11 -Wall -Wextra -Os\nARCH = {arch}\nSEMO_STACK_BYTES ?= {stack}\nSEMO_CPU_HZ ?= {clock}\nSEMO_TEXT_MAX ?= {value_bytes}\nSEMO_MAX_TASKS ?= {task_count}\nSEMO_MAX_GROUPS ?= {groups}\nSEMO_INBOX ?= {inbox}\nSIZES = -DSEMO_STACK_BYTES=$(SEMO_STACK_BYTES) -DSEMO_CPU_HZ=$(SEMO_CPU_HZ)u -DSEMO_TEXT_MAX=$(SEMO_TEXT_MAX) -DSEMO_MAX_TASKS=$(SEMO_MAX_TASKS) -DSEMO_MAX_GROUPS=$(SEMO_MAX_GROUPS) -DSEMO_INBOX=$(SEMO_INBOX)\nSEMO_CFLAGS = -std=c11 $(ARCH) -ffunction-sections -fdata-sections -DSEMO_STATIC{sim}{no_reals} $(SIZES) -I. -I$(RUNTIME)\nLDFLAGS += $(ARCH) -nostartfiles --specs={specs} -T $(RUNTIME)/{ld} -Wl,--gc-sections\n\n{common}HEADERS = program.h $(RUNTIME_HEADERS)\n\nall: $(PROGRAM)\n\n$(PROGRAM): $(OBJECTS) $(RUNTIME_OBJECTS) $(RUNTIME)/{ld}\n\t$(CC) $(CFLAGS) $(LDFLAGS) -o $@ $(OBJECTS) $(RUNTIME_OBJECTS) $(LDLIBS)\n",
        robot = program.robot,
        target = target.name(),
        board = board.name,
        cpu = board.cpu,
        cc = board.toolchain.cc,
        size = board.toolchain.size,
        libc = board.toolchain.libc,
        specs = board.toolchain.specs,
        serial = board.serial,
        timer = board.timer,
        emulator = board.emulator,
        arch = board.arch,
        stack = board.stack_bytes,
        clock = board.clock_hz,
        ld = board.link_script,
        value_bytes = sizes.value_bytes,
        task_count = sizes.tasks,
        groups = sizes.groups,
        inbox = sizes.inbox,
        no_reals = if sizes.reals { "" } else { " -DSEMO_NO_REALS" },
        exit = if target.simulated() {
            "; it exits when the scenario ends"
        } else {
            ""
        },
        sim = if target.simulated() {
            " -DSEMO_SIM -DSEMO_SEMIHOSTING"
        } else {
            ""
        },
    );
}

/// `scenario.c` of a static-schedule simulation: the robot's world from the
/// scenario as constant tables (`semo__sim_tables`, `semo_internal.h`).
pub fn scenario_c(world: &CompiledScenario, header: &str) -> String {
    let mut out = String::from(header);
    out.push_str("#include \"semo_internal.h\"\n\n/* This robot's world from the scenario, compiled in. */\n");
    let _ = writeln!(out, "static const semo__sim_sensor_entry sensors[] = {{");
    for (at, value, is) in &world.sensors {
        let _ = writeln!(
            out,
            "    {{{at}, {}, {}}},",
            c::string(value),
            c::string(is)
        );
    }
    if world.sensors.is_empty() {
        out.push_str("    {0, \"\", \"\"}, /* none: the count below is 0 */\n");
    }
    out.push_str("};\nstatic const semo__sim_service_entry services[] = {\n");
    for (service, ms) in &world.services {
        let _ = writeln!(out, "    {{{}, {ms}}},", c::string(service));
    }
    if world.services.is_empty() {
        out.push_str("    {\"\", 0}, /* none */\n");
    }
    out.push_str("};\nstatic const semo__sim_command_entry operator_commands[] = {\n");
    for command in &world.operator {
        let _ = writeln!(
            out,
            "    {{{}, {}, {}, {}, {}}},",
            command.first,
            command.every.unwrap_or(0),
            command.until,
            c::string(&command.key),
            c::string(&command.value)
        );
    }
    if world.operator.is_empty() {
        out.push_str("    {0, 0, -1, \"\", \"\"}, /* none */\n");
    }
    let _ = writeln!(
        out,
        "}};\nstatic int64_t operator_next[{}];\n\nconst semo__sim_tables semo__scenario = {{\n    .duration_ms = {},\n    .sensors = sensors,\n    .sensor_count = {},\n    .services = services,\n    .service_count = {},\n    .operator_commands = operator_commands,\n    .operator_next = operator_next,\n    .operator_count = {},\n}};",
        world.operator.len().max(1),
        world.duration_ms.unwrap_or(0),
        world.sensors.len(),
        world.services.len(),
        world.operator.len()
    );
    out
}

/// How a sensor task a user writes sets a value of this kind.
fn setter_example(kind: &crate::refine::ValueKind) -> &'static str {
    use crate::refine::ValueKind as K;
    match kind {
        K::Int => "semo_value_set_int(&value, 42)",
        K::Real => "semo_value_set_real(&value, 0.5)",
        K::Bool => "semo_value_set_bool(&value, true)",
        K::Word(_) => "semo_value_set_word(&value, \"...\")",
        K::Text | K::Variable => "semo_value_set(&value, \"...\")",
    }
}
