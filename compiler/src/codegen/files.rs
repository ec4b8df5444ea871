//! The other files of a robot's folder: `program.h`, `main.c`, `channels.c`,
//! `comm_task.c`, `lib_<name>.c`, `tasks/<task>.c` and the `Makefile`.

use super::c;
use super::peers::Peers;
use super::template::{Template, fill, template};
use super::values::Words;
use super::{Layer, Target};
use crate::refine::graph::{COMM_RECEIVE, COMM_SEND, CONTROL_TASK};
use crate::refine::protocol::{TERM_MAX, alive_key, sync_key};
use crate::refine::{CompiledScenario, LinkEffect};
use crate::refine::{PeerId, RobotProgram, RoleKind, ValueKind};
use crate::taskgraph::Trigger;
use std::fmt::Write;

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

/// `program.h` down to the task functions' declarations.
const PROGRAM_H_HEAD: Template = template!("files/program_h_head.h.in", []);
/// `program.h`'s declarations of what `comm_task.c` heard.
const HEARD_ALIVE: Template = template!("files/heard_alive.h.in", []);
const HEARD_SYNC: Template = template!("files/heard_sync.h.in", []);
const HEARD_EVENT: Template = template!("files/heard_event.h.in", []);
/// `program.h`'s declaration of the channels.
const CHANNELS_DECLARATION: Template = template!("files/channels_declaration.h.in", ["count"]);
/// `main.c` down to its task table, per layer.
const MAIN_THREADS_HEAD: Template = template!("files/main_threads_head.c.in", []);
const MAIN_STATIC_HEAD: Template = template!("files/main_static_head.c.in", []);
/// `main.c`'s program description and `main`.
const PROGRAM_DESC: Template = template!(
    "files/program_desc.c.in",
    [
        "mission",
        "team",
        "robot",
        "robot_type",
        "groups",
        "group_count",
        "self",
        "robot_count",
        "receives",
        "schedule",
        "words",
        "deploy",
        "sim"
    ]
);
/// `comm_task.c`'s parts: sending, heartbeats, sync points, events, receiving.
const SENDING_HEAD: Template = template!("files/comm_send_head.c.in", []);
const SENDING: Template = template!("files/comm_send.c.in", ["n", "send", "send_name"]);
const COMM_HEARTBEATS: Template = template!(
    "files/comm_heartbeats.c.in",
    [
        "declare",
        "peers",
        "key",
        "term_max",
        "lock_seen",
        "unlock_seen"
    ]
);
const COMM_SYNC: Template = template!(
    "files/comm_sync.c.in",
    [
        "list",
        "n",
        "peers",
        "key",
        "control",
        "lock_seen",
        "unlock_seen"
    ]
);
const COMM_EVENTS: Template = template!(
    "files/comm_events.c.in",
    [
        "include",
        "declare",
        "lock",
        "unlock",
        "key_comment",
        "list",
        "n",
        "cap",
        "key",
        "team",
        "control"
    ]
);
const COMM_RECEIVE_HEAD: Template = template!("files/comm_receive_head.c.in", []);
const COMM_INCOMING_HEAD: Template = template!("files/comm_incoming_head.c.in", []);
const COMM_SUBSCRIBED: Template = template!("files/comm_subscribed.c.in", []);
const COMM_INCOMING: Template = template!("files/comm_incoming.c.in", ["n"]);
/// A service task's file: the static simulation's whole body, the others'
/// head, the threads simulation's call, the user's TODO.
const TASK_SERVICE_STATIC_SIM: Template = template!(
    "files/task_service_static_sim.c.in",
    ["task", "robot", "services", "scale", "reply"]
);
const TASK_SERVICE: Template = template!("files/task_service.c.in", ["task", "robot", "services"]);
const TASK_SERVICE_SIM_START: Template = template!("files/task_service_sim_start.c.in", []);
const TASK_SERVICE_SIM_WAIT: Template = template!("files/task_service_sim_wait.c.in", []);
const TASK_SERVICE_TODO: Template = template!("files/task_service_todo.c.in", []);
/// A sensor task's TODO for the user, per value it samples.
const SENSOR_TODO: Template =
    template!("files/sensor_todo.c.in", ["value", "kind", "example", "id"]);
/// The Makefile's parts: the runtime's folder, what every Makefile has,
/// the rules, each layer's head, a board's `size` and `run`.
const RUNTIME_MK: Template = template!("files/runtime.mk.in", ["folder", "sources"]);
const COMMON_MK: Template = template!("files/common.mk.in", ["robot", "elf", "sources", "tasks"]);
const RULES_MK: Template = template!("files/rules.mk.in", []);
const MAKEFILE_THREADS: Template = template!(
    "files/Makefile.threads.in",
    [
        "robot",
        "target",
        "transport",
        "sim",
        "deploy",
        "runtime",
        "common",
        "rules"
    ]
);
const MAKEFILE_STATIC: Template = template!(
    "files/Makefile.static.in",
    [
        "robot",
        "target",
        "board",
        "cpu",
        "cc",
        "size",
        "libc",
        "specs",
        "serial",
        "timer",
        "emulator",
        "arch",
        "stack",
        "clock",
        "ld",
        "value_bytes",
        "task_count",
        "groups",
        "inbox",
        "link_sizes",
        "link_flags",
        "no_reals",
        "exit",
        "sim",
        "runtime",
        "common"
    ]
);
const BOARD_RUN_MK: Template = template!("files/board_run.mk.in", ["machine", "link_serial"]);
/// `scenario.c`'s tables.
const SCENARIO_TABLES: Template = template!(
    "files/scenario_tables.c.in",
    [
        "operator_slots",
        "duration_ms",
        "sensor_count",
        "service_count",
        "operator_count",
        "more_tables",
        "more_fields"
    ]
);

/// Every template of the files `files.rs` writes.
#[cfg(test)]
pub(super) const TEMPLATES: &[Template] = &[
    PROGRAM_H_HEAD,
    HEARD_ALIVE,
    HEARD_SYNC,
    HEARD_EVENT,
    CHANNELS_DECLARATION,
    MAIN_THREADS_HEAD,
    MAIN_STATIC_HEAD,
    PROGRAM_DESC,
    DEPLOY_DEFAULTS,
    SENDING_HEAD,
    SENDING,
    COMM_HEARTBEATS,
    COMM_SYNC,
    COMM_EVENTS,
    COMM_RECEIVE_HEAD,
    COMM_INCOMING_HEAD,
    COMM_SUBSCRIBED,
    COMM_INCOMING,
    TASK_SERVICE_STATIC_SIM,
    TASK_SERVICE,
    TASK_SERVICE_SIM_START,
    TASK_SERVICE_SIM_WAIT,
    TASK_SERVICE_TODO,
    SENSOR_TODO,
    RUNTIME_MK,
    COMMON_MK,
    RULES_MK,
    MAKEFILE_THREADS,
    MAKEFILE_STATIC,
    BOARD_RUN_MK,
    SCENARIO_TABLES,
];

pub fn program_h(program: &RobotProgram, header: &str) -> String {
    let mut out = String::from(header);
    out.push_str(PROGRAM_H_HEAD.text);
    for (_, prefix) in task_functions(program) {
        let _ = writeln!(
            out,
            "void {prefix}_init(void);\nvoid {prefix}_go(void);\nvoid {prefix}_wrapup(void);"
        );
    }
    if program.control.heartbeat {
        out.push_str(HEARD_ALIVE.text);
        if !program.control.sync_points.is_empty() {
            out.push_str(HEARD_SYNC.text);
        }
    }
    if !program.control.events_heard.is_empty() {
        out.push_str(HEARD_EVENT.text);
    }
    out.push_str(&super::shared::declarations(program));
    out.push_str(&fill(
        &CHANNELS_DECLARATION,
        &[("count", &program.graph.channels.len())],
    ));
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
        Layer::Threads => MAIN_THREADS_HEAD.text,
        Layer::Static => MAIN_STATIC_HEAD.text,
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
        let (team, robot) = program.peer(i);
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
        out.push_str(DEPLOY_DEFAULTS.text);
    }
    out.push_str(&fill(
        &PROGRAM_DESC,
        &[
            ("mission", &c::string(&program.mission)),
            ("team", &c::string(&program.team)),
            ("robot", &c::string(&program.robot)),
            ("robot_type", &c::string(&program.robot_type)),
            (
                "groups",
                &if groups.is_empty() { "NULL" } else { "groups" },
            ),
            ("group_count", &groups.len()),
            ("self", &peers.own()),
            ("robot_count", &program.peers.len()),
            ("receives", &receives(program)),
            (
                "schedule",
                &if static_schedule {
                    "    .schedule = schedule,\n    .schedule_count = sizeof schedule / sizeof schedule[0],\n"
                } else {
                    ""
                },
            ),
            (
                "words",
                &if words.list().is_empty() {
                    ""
                } else {
                    "    .words = words,\n    .word_count = sizeof words / sizeof words[0],\n"
                },
            ),
            (
                "deploy",
                &if threads { "    .deploy = &deploy,\n" } else { "" },
            ),
            (
                "sim",
                &if threads && target.simulated() {
                    "    .sim = &semo_sim_platform,\n"
                } else {
                    ""
                },
            ),
        ],
    ));
    out
}

/// The connection defaults of a threads robot, read from its own
/// `semo_deploy.h` here (the runtime every robot of a build shares cannot
/// include one robot's header).
const DEPLOY_DEFAULTS: Template = template!("files/deploy_defaults.c.in", []);

pub fn comm_task_c(
    program: &RobotProgram,
    words: &Words,
    peers: &Peers,
    target: Target,
    header: &str,
) -> String {
    let m = &program.control;
    let mut out = String::from(header);
    let (include, declare, lock_seen, unlock_seen) = c::lock(target, "seen_lock");
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
        out.push_str(SENDING_HEAD.text);
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
        out.push_str(&fill(
            &SENDING,
            &[
                ("n", &n),
                ("send", &c::ident(COMM_SEND)),
                ("send_name", &c::string(COMM_SEND)),
            ],
        ));
    }
    if m.heartbeat {
        out.push_str(&fill(
            &COMM_HEARTBEATS,
            &[
                ("declare", &declare),
                ("peers", &peers.len()),
                ("key", &c::string(&alive_key(program))),
                ("term_max", &TERM_MAX),
                ("lock_seen", &lock_seen),
                ("unlock_seen", &unlock_seen),
            ],
        ));
    }
    if !m.sync_points.is_empty() {
        let points: Vec<String> = m.sync_points.iter().map(|p| p.to_string()).collect();
        out.push_str(&fill(
            &COMM_SYNC,
            &[
                ("list", &points.join(", ")),
                ("n", &m.sync_points.len()),
                ("peers", &peers.len()),
                ("key", &c::string(&sync_key(program))),
                ("control", &c::string(CONTROL_TASK)),
                ("lock_seen", &lock_seen),
                ("unlock_seen", &unlock_seen),
            ],
        ));
    }
    if !m.events_heard.is_empty() {
        comm_events(&mut out, program, target);
    }
    if m.has_receiver() {
        out.push_str(COMM_RECEIVE_HEAD.text);
        let n = m.incoming.len();
        if n > 0 {
            out.push_str(COMM_INCOMING_HEAD.text);
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
            out.push_str(COMM_SUBSCRIBED.text);
        }
        if n > 0 {
            out.push_str(&fill(&COMM_INCOMING, &[("n", &n)]));
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
    let (include, declare, lock, unlock) = c::lock(target, "event_lock");
    let names: Vec<String> = m.events_heard.iter().map(|e| c::string(e)).collect();
    out.push_str(&fill(
        &COMM_EVENTS,
        &[
            ("include", &include),
            ("declare", &declare),
            ("lock", &lock),
            ("unlock", &unlock),
            (
                "key_comment",
                &c::comment(&crate::refine::event_key(&program.team)),
            ),
            ("list", &names.join(", ")),
            ("n", &names.len()),
            ("cap", &crate::refine::EVENT_QUEUE),
            ("key", &c::string(&crate::refine::event_key(&program.team))),
            ("team", &c::string(&program.team)),
            ("control", &c::string(CONTROL_TASK)),
        ],
    ));
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
                        out.push_str(&fill(
                            &SENSOR_TODO,
                            &[
                                ("value", &c::comment(v)),
                                ("kind", &c::comment(&kind.describe())),
                                ("example", &setter_example(kind)),
                                ("id", &c::ident(v)),
                            ],
                        ));
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
            out.push_str(&fill(
                &TASK_SERVICE_STATIC_SIM,
                &[
                    ("task", &c::comment(&role.task)),
                    ("robot", &c::comment(&program.robot)),
                    ("services", &c::comment(&services.join(", "))),
                    (
                        "scale",
                        &if speed_scale.is_some() {
                            " * speed_scale()"
                        } else {
                            ""
                        },
                    ),
                    (
                        "reply",
                        &gives_results(program, &role.task).map_or(String::new(), |most| {
                            format!(
                                "\n    bool stopped = !semo_running() || UFControl_StopRequested(TASK_NAME);\n{}",
                                sim_reply(most).trim_end()
                            )
                        }),
                    ),
                ],
            ));
        }
        (RoleKind::Service { services }, _) => {
            out.push_str(&fill(
                &TASK_SERVICE,
                &[
                    ("task", &c::comment(&role.task)),
                    ("robot", &c::comment(&program.robot)),
                    ("services", &c::comment(&services.join(", "))),
                ],
            ));
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
                    out.push_str(TASK_SERVICE_SIM_START.text);
                    out.push_str(run_graph);
                    let replies = gives_results(program, &role.task);
                    let wait = TASK_SERVICE_SIM_WAIT.text;
                    match replies {
                        Some(_) => out.push_str(&wait.replace(
                            "    UFControl_WaitStop(",
                            "    bool stopped = UFControl_WaitStop(",
                        )),
                        None => out.push_str(wait),
                    }
                    out.push_str(scale);
                    out.push_str(");\n");
                    if let Some(most) = replies {
                        out.push_str(&sim_reply(most));
                    }
                    out.push_str("    semo_trace(\"call_end\", \"task\", TASK_NAME, \"service\", req.service, NULL);\n");
                }
                // The static simulation's body is the arm above.
                (true, Layer::Static) => {}
                (false, _) => {
                    out.push_str(run_graph);
                    out.push_str(TASK_SERVICE_TODO.text);
                    if gives_results(program, &role.task).is_some() {
                        out.push_str("    /* A call binding results: give them back before returning,\n     * semo_reply(TASK_NAME, n, values), in the order of the service's results. */\n");
                    }
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

/// A simulated service task whose call was done (not stopped) gives back
/// the scenario's results for it (`semo_sim_results`), as the simulator's
/// task does.
fn sim_reply(most: usize) -> String {
    format!(
        "    if (!stopped) {{\n        semo_value results[{most}];\n        int n = semo_sim_results(req.service, results, {most});\n        semo_reply(TASK_NAME, n, results);\n    }}\n"
    )
}

/// The most results a call of the program that `task` performs binds
/// (`None`: none binds any): then the task gives back what its calls
/// found (`semo_reply`, defined by the control task only then).
fn gives_results(program: &crate::refine::RobotProgram, task: &str) -> Option<usize> {
    program
        .control
        .services
        .iter()
        .flat_map(|s| &s.states)
        .filter_map(|state| match &state.kind {
            crate::refine::StateKind::Call {
                task: t, results, ..
            } if t == task && !results.is_empty() => Some(results.len()),
            _ => None,
        })
        .max()
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
    /// The serial link, for a robot that messages other robots.
    pub link: Option<LinkSizes>,
}

/// A board robot's serial link (`-DSEMO_LINK`): its port and buffers.
pub struct LinkSizes {
    pub port: &'static str,
    pub pins: &'static str,
    pub baud: u32,
    /// The largest frame payload it takes (`SEMO_LINK_PAYLOAD_MAX`,
    /// `board_link::payload_max`).
    pub payload: usize,
    /// The largest it sends, its status included (`SEMO_LINK_SEND_MAX`,
    /// `board_link::send_max`).
    pub send: usize,
    pub queue: usize,
    /// The plans its status follows (`SEMO_STATUS_PLANS`).
    pub plans: usize,
    /// Its statements of counted groups, whose groups its status says
    /// (`SEMO_STATUS_GROUPS`).
    pub groups: usize,
}

/// Whether a task of the robot takes messages from its inbox (its
/// communication task): without one, what arrives is ignored.
fn receives(program: &RobotProgram) -> bool {
    program
        .tasks
        .iter()
        .any(|t| t.kind == RoleKind::CommReceive)
}

impl StaticSizes {
    /// `simulated_battery`: the robot's scenario gives it a battery level
    /// (its status may then say one without a `BATTERY` value).
    pub fn of(
        program: &RobotProgram,
        longest_value: usize,
        link: Option<&crate::platform::SerialLink>,
        simulated_battery: bool,
    ) -> StaticSizes {
        let receives = receives(program);
        let value_bytes = (longest_value + 1).max(16).next_multiple_of(4);
        StaticSizes {
            link: link.map(|l| LinkSizes {
                port: l.port,
                pins: l.pins,
                baud: l.baud,
                payload: super::board_link::payload_max(program, value_bytes),
                send: super::board_link::send_max(
                    program,
                    value_bytes,
                    super::board_link::knows_battery(program, simulated_battery),
                ),
                queue: super::board_link::QUEUE,
                plans: super::board_link::status_plans(program),
                groups: super::board_link::status_groups(program),
            }),
            value_bytes,
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
    let runtime = fill(
        &RUNTIME_MK,
        &[
            ("folder", &super::RUNTIME_FOLDER),
            ("sources", &sources.runtime.join(" ")),
        ],
    );
    let common = fill(
        &COMMON_MK,
        &[
            ("robot", &program.robot),
            (
                "elf",
                &if target.layer() == Layer::Static {
                    ".elf"
                } else {
                    ""
                },
            ),
            ("sources", &sources.robot.join(" ")),
            ("tasks", &sources.tasks.join(" ")),
        ],
    );
    let rules = RULES_MK.text;
    if let Some(board) = &target.platform().board {
        static_makefile(&mut out, program, target, board, &runtime, &common, sizes);
        out.push_str(rules);
        let link_serial = match &sizes.link {
            Some(l) => format!(
                " -serial mon:stdio -serial $(SEMO_LINK_SERIAL)\n\n# {} in QEMU: `semo gateway MISSION --link {}=tcp:127.0.0.1:4560` connects to it.\nSEMO_LINK_SERIAL ?= tcp:127.0.0.1:4560,server=on,wait=off,nodelay=on",
                l.port, program.robot
            ),
            None => String::new(),
        };
        out.push_str(&fill(
            &BOARD_RUN_MK,
            &[("machine", &board.machine), ("link_serial", &link_serial)],
        ));
        return out;
    }
    out.push_str(&fill(
        &MAKEFILE_THREADS,
        &[
            ("robot", &program.robot),
            ("target", &target.name()),
            ("transport", &target.transport().map_or("udp", |t| t.name())),
            (
                "sim",
                &if target.simulated() {
                    " -DSEMO_SIM"
                } else {
                    ""
                },
            ),
            ("deploy", &super::DEPLOY_HEADER),
            ("runtime", &runtime),
            ("common", &common),
            ("rules", &rules),
        ],
    ));
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
    out.push_str(&fill(
        &MAKEFILE_STATIC,
        &[
            ("robot", &program.robot),
            ("target", &target.name()),
            ("board", &board.name),
            ("cpu", &board.cpu),
            ("cc", &board.toolchain.cc),
            ("size", &board.toolchain.size),
            ("libc", &board.toolchain.libc),
            ("specs", &board.toolchain.specs),
            ("serial", &board.serial),
            ("timer", &board.timer),
            ("emulator", &board.emulator),
            ("arch", &board.arch),
            ("stack", &board.stack_bytes),
            ("clock", &board.clock_hz),
            ("ld", &board.link_script),
            ("value_bytes", &sizes.value_bytes),
            ("task_count", &sizes.tasks),
            ("groups", &sizes.groups),
            ("inbox", &sizes.inbox),
            (
                "link_sizes",
                &sizes.link.as_ref().map_or(String::new(), |l| {
                    format!(
                        "# The serial link to `semo gateway` on {} ({}, {} baud; docs/link.md):\n# the largest frame payload it takes and sends (its status), from the mission's\n# names, the frames queued, and the plans its status follows.\nSEMO_LINK_BAUD ?= {}\nSEMO_LINK_PAYLOAD_MAX ?= {}\nSEMO_LINK_SEND_MAX ?= {}\nSEMO_LINK_QUEUE ?= {}\nSEMO_STATUS_PLANS ?= {}\n{}",
                        l.port, l.pins, l.baud, l.baud, l.payload, l.send, l.queue, l.plans,
                        // Only a robot with counted groups has the table.
                        if l.groups > 0 {
                            format!("# Its statements of counted groups, whose groups its status says.\nSEMO_STATUS_GROUPS ?= {}\n", l.groups)
                        } else {
                            String::new()
                        }
                    )
                }),
            ),
            (
                "link_flags",
                &match &sizes.link {
                    Some(l) => format!(
                        " -DSEMO_LINK -DSEMO_LINK_BAUD=$(SEMO_LINK_BAUD)u -DSEMO_LINK_PAYLOAD_MAX=$(SEMO_LINK_PAYLOAD_MAX) -DSEMO_LINK_SEND_MAX=$(SEMO_LINK_SEND_MAX) -DSEMO_LINK_QUEUE=$(SEMO_LINK_QUEUE) -DSEMO_STATUS_PLANS=$(SEMO_STATUS_PLANS){}",
                        if l.groups > 0 { " -DSEMO_STATUS_GROUPS=$(SEMO_STATUS_GROUPS)" } else { "" }
                    ),
                    None => String::new(),
                },
            ),
            (
                "no_reals",
                &if sizes.reals { "" } else { " -DSEMO_NO_REALS" },
            ),
            (
                "exit",
                &if target.simulated() {
                    "; it exits when the scenario ends"
                } else {
                    ""
                },
            ),
            (
                "sim",
                &if !target.simulated() {
                    ""
                } else if sizes.link.is_some() {
                    " -DSEMO_SIM -DSEMO_SEMIHOSTING$(if $(LOCKSTEP), -DSEMO_LOCKSTEP)"
                } else {
                    // In lock-step a robot that messages no one speaks on
                    // the link's port too (its sizes the runtime's defaults).
                    " -DSEMO_SIM -DSEMO_SEMIHOSTING$(if $(LOCKSTEP), -DSEMO_LOCKSTEP -DSEMO_LINK)"
                },
            ),
            ("runtime", &runtime),
            ("common", &common),
        ],
    ));
}

/// `scenario.c` of a simulated program (either runtime): the robot's world
/// from the scenario as constant tables (`semo__sim_tables`,
/// `semo_internal.h`). A table the world leaves empty (battery, loop exits,
/// link faults, a time scale) is not written: its fields stay zero. A link
/// fault's robots are written as the program's peer indices (`peers`);
/// a robot not among them is one the program never sends to.
pub fn scenario_c(
    world: &CompiledScenario,
    header: &str,
    program: &crate::refine::RobotProgram,
    peers: &super::peers::Peers,
) -> String {
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
    let (tables, fields) = scenario_extra_tables(world, program, peers);
    out.push_str(&fill(
        &SCENARIO_TABLES,
        &[
            ("operator_slots", &world.operator.len().max(1)),
            ("duration_ms", &world.duration_ms.unwrap_or(0)),
            ("sensor_count", &world.sensors.len()),
            ("service_count", &world.services.len()),
            ("operator_count", &world.operator.len()),
            ("more_tables", &tables),
            ("more_fields", &fields),
        ],
    ));
    out
}

/// The tables of `scenario.c` written only when the world has them, and
/// their fields of `semo__scenario`.
fn scenario_extra_tables(
    world: &CompiledScenario,
    program: &crate::refine::RobotProgram,
    peers: &super::peers::Peers,
) -> (String, String) {
    let (mut tables, mut fields) = (String::new(), String::new());
    if let Some(scale) = world.time_scale {
        let _ = writeln!(fields, "    .time_scale = {},", c::real(scale));
    }
    if !world.battery.is_empty() {
        tables.push_str("static const semo__sim_battery_entry battery[] = {\n");
        for (at, level) in &world.battery {
            let _ = writeln!(tables, "    {{{at}, {}}},", c::real(*level));
        }
        tables.push_str("};\n");
        let _ = writeln!(
            fields,
            "    .battery = battery,\n    .battery_count = {},",
            world.battery.len()
        );
    }
    if !world.results.is_empty() {
        // Per service, per call done, its values' texts (NULL: none).
        let mut entries = Vec::new();
        for (i, (service, calls)) in world.results.iter().enumerate() {
            let mut names = Vec::new();
            let mut counts = Vec::new();
            for (k, values) in calls.iter().enumerate() {
                let texts: Vec<String> = values
                    .iter()
                    .map(|v| v.as_deref().map_or("NULL".to_string(), c::string))
                    .collect();
                let texts = if texts.is_empty() {
                    vec!["NULL".to_string()]
                } else {
                    texts
                };
                let _ = writeln!(
                    tables,
                    "static const char *const results_{i}_{k}[] = {{{}}};",
                    texts.join(", ")
                );
                names.push(format!("results_{i}_{k}"));
                counts.push(values.len().to_string());
            }
            if calls.is_empty() {
                names.push("NULL".to_string());
                counts.push("0".to_string());
            }
            let _ = writeln!(
                tables,
                "static const char *const *const results_{i}[] = {{{}}};\nstatic const size_t results_{i}_counts[] = {{{}}};",
                names.join(", "),
                counts.join(", ")
            );
            entries.push(format!(
                "    {{{}, results_{i}, results_{i}_counts, {}}},\n",
                c::string(service),
                calls.len()
            ));
        }
        tables.push_str("static const semo__sim_results_entry results[] = {\n");
        tables.extend(entries.iter().map(String::as_str));
        let _ = writeln!(
            tables,
            "}};\nstatic size_t results_done[{}];",
            entries.len()
        );
        let _ = writeln!(
            fields,
            "    .results = results,\n    .results_done = results_done,\n    .results_count = {},",
            entries.len()
        );
    }
    if !world.loops.is_empty() {
        tables.push_str("static const semo__sim_loop_entry loops[] = {\n");
        for (path, iteration) in &world.loops {
            let _ = writeln!(tables, "    {{{}, {iteration}}},", c::string(path));
        }
        tables.push_str("};\n");
        let _ = writeln!(
            fields,
            "    .loops = loops,\n    .loop_count = {},",
            world.loops.len()
        );
    }
    // Each fault's peers (local indices), then the faults naming them.
    let mut links = Vec::new();
    for link in &world.links {
        let mut locals: Vec<usize> = link
            .robots
            .iter()
            .filter_map(|robot| program.peers.iter().position(|(_, r)| r == robot))
            .filter_map(|fleet| peers.list().binary_search(&PeerId::new(fleet)).ok())
            .collect();
        locals.sort_unstable();
        locals.dedup();
        if locals.is_empty() {
            continue;
        }
        let i = links.len();
        let list: Vec<String> = locals.iter().map(usize::to_string).collect();
        let _ = writeln!(
            tables,
            "static const size_t link_{i}_peers[] = {{{}}};",
            list.join(", ")
        );
        let (lost, by) = match link.effect {
            LinkEffect::Lost => ("true", 0),
            LinkEffect::Delayed(by) => ("false", by),
        };
        links.push(format!(
            "    {{{}, {}, {by}, {lost}, link_{i}_peers, {}}},\n",
            link.from,
            link.until,
            locals.len()
        ));
    }
    if !links.is_empty() {
        tables.push_str("static const semo__sim_link_entry links[] = {\n");
        tables.extend(links.iter().map(String::as_str));
        tables.push_str("};\n");
        let _ = writeln!(
            fields,
            "    .links = links,\n    .link_count = {},",
            links.len()
        );
    }
    (tables, fields)
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
