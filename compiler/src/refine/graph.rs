//! The robot's task graph (codegen.md §1.2–1.4, 1.6): sensor tasks feeding
//! the control task, the tasks implementing services and actuator commands
//! it requests, the communication tasks and the team's library task.
//!
//! Communication is two tasks, one per direction, so that a message sent and
//! a message received do not form a cycle through the control task: the
//! control task does not wait for its own sends, and SDF would report such a
//! cycle as a deadlock.

use super::program::{RobotProgram, RoleKind, StateKind, SubscriptionId};
use crate::diag::{Code, Diagnostic, FileId, Severity};
use crate::span::Span;
use crate::taskgraph::{
    Channel, Direction, Endpoint, Library, LibraryFunction, LibraryPort, MulticastPort, Named,
    Port, Task, TaskGraph, TaskKind, Trigger,
};

pub const CONTROL_TASK: &str = "ControlTask";
pub const COMM_SEND: &str = "CommSend";
pub const COMM_RECEIVE: &str = "CommReceive";
/// The control task's period, in mission milliseconds: how often the state
/// machine advances.
pub const CONTROL_PERIOD_MS: i64 = 10;
/// Samples a channel holds at least (the analysis of these rate-1 graphs
/// gives 1, but producers and consumers run at different rates).
const SENSOR_CAPACITY: u64 = 4;
const REQUEST_CAPACITY: u64 = 2;
const MESSAGE_CAPACITY: u64 = 16;

/// The library function names for a shared attribute (`SlaveTeam.COLOR`).
pub fn getter(key: &str) -> String {
    format!("get_{}", key.replace('.', "_"))
}

pub fn setter(key: &str) -> String {
    format!("set_{}", key.replace('.', "_"))
}

fn named(name: &str) -> Named {
    Named {
        name: name.into(),
        span: Span::default(),
    }
}

fn port(name: &str, dir: Direction) -> Port {
    Port {
        name: named(name),
        span: Span::default(),
        dir,
        rate: 1,
        rate_span: None,
        sample_type: Some("semo_value".into()),
        size: None,
        kind: None,
        inner_rate: None,
    }
}

/// A port carrying service requests (`semo_request`: a service and its arguments).
fn request_port(name: &str, dir: Direction) -> Port {
    Port {
        sample_type: Some("semo_request".into()),
        ..port(name, dir)
    }
}

fn task(name: &str, kind: TaskKind, trigger: Trigger) -> Task {
    Task {
        name: named(name),
        span: Span::default(),
        kind,
        trigger,
        wcet: None,
        source: None,
        subgraph: None,
        ports: Vec::new(),
        library_ports: Vec::new(),
        multicast_ports: Vec::new(),
        loop_node: None,
    }
}

fn channel(src: (&str, &str), dst: (&str, &str), capacity: u64) -> Channel {
    let end = |(task, port): (&str, &str)| Endpoint {
        task: task.into(),
        port: port.into(),
        span: Span::default(),
    };
    Channel {
        src: end(src),
        dst: end(dst),
        initial_tokens: 0,
        capacity: Some(capacity),
        span: Span::default(),
    }
}

/// The task graph of `program` (its `graph` field is ignored).
pub fn build(program: &RobotProgram) -> TaskGraph {
    let machine = &program.control;
    let mut control = task(
        CONTROL_TASK,
        TaskKind::Control,
        Trigger::Time {
            period_ms: CONTROL_PERIOD_MS as f64,
        },
    );
    control.source = Some("control_task.c".into());
    let mut tasks = Vec::new();
    let mut channels = Vec::new();
    for role in &program.tasks {
        match &role.kind {
            RoleKind::Sensor { values, period_ms } => {
                let mut t = task(
                    &role.task,
                    TaskKind::Computational,
                    Trigger::Time {
                        period_ms: *period_ms as f64,
                    },
                );
                for value in values {
                    t.ports.push(port(value, Direction::Out));
                    control.ports.push(port(value, Direction::In));
                    channels.push(channel(
                        (&role.task, value),
                        (CONTROL_TASK, value),
                        SENSOR_CAPACITY,
                    ));
                }
                t.source = Some(format!("tasks/{}.c", role.task));
                tasks.push(t);
            }
            RoleKind::Service { .. } => {
                let mut t = task(&role.task, TaskKind::Computational, Trigger::Control);
                t.ports.push(request_port("request", Direction::In));
                let out = format!("req_{}", role.task);
                control.ports.push(request_port(&out, Direction::Out));
                channels.push(channel(
                    (CONTROL_TASK, &out),
                    (&role.task, "request"),
                    REQUEST_CAPACITY,
                ));
                t.source = Some(format!("tasks/{}.c", role.task));
                tasks.push(t);
            }
            RoleKind::CommSend => {
                let mut t = task(
                    COMM_SEND,
                    TaskKind::Computational,
                    Trigger::Time {
                        period_ms: CONTROL_PERIOD_MS as f64,
                    },
                );
                for m in &machine.outgoing {
                    t.ports.push(port(&m.port, Direction::In));
                    control.ports.push(port(&m.port, Direction::Out));
                    channels.push(channel(
                        (CONTROL_TASK, &m.port),
                        (COMM_SEND, &m.port),
                        MESSAGE_CAPACITY,
                    ));
                }
                t.source = Some("comm_task.c".into());
                tasks.push(t);
            }
            RoleKind::CommReceive => {
                let mut t = task(COMM_RECEIVE, TaskKind::Computational, Trigger::Data);
                for m in &machine.incoming {
                    t.ports.push(port(&m.port, Direction::Out));
                    control.ports.push(port(&m.port, Direction::In));
                    channels.push(channel(
                        (COMM_RECEIVE, &m.port),
                        (CONTROL_TASK, &m.port),
                        MESSAGE_CAPACITY,
                    ));
                }
                for (i, group) in machine.subscribed.iter().enumerate() {
                    let name = format!("sub_{i}");
                    t.multicast_ports.push(MulticastPort {
                        name: named(&name),
                        span: Span::default(),
                        dir: Direction::Out,
                        group: named(group),
                    });
                    control.multicast_ports.push(MulticastPort {
                        name: named(&name),
                        span: Span::default(),
                        dir: Direction::In,
                        group: named(group),
                    });
                }
                t.source = Some("comm_task.c".into());
                tasks.push(t);
            }
        }
    }
    let mut libraries = Vec::new();
    if let Some(lib) = &program.library {
        let mut functions = Vec::new();
        for key in &lib.attributes {
            functions.push(LibraryFunction {
                name: named(&getter(key)),
                returns: Some("semo_value".into()),
                params: Vec::new(),
            });
            functions.push(LibraryFunction {
                name: named(&setter(key)),
                returns: Some("void".into()),
                params: vec![("value".into(), "semo_value".into())],
            });
        }
        control.library_ports.push(LibraryPort {
            name: named("shared"),
            span: Span::default(),
            library: named(&lib.name),
            master: true,
            calls: functions.iter().map(|f| f.name.clone()).collect(),
        });
        libraries.push(Library {
            name: named(&lib.name),
            span: Span::default(),
            functions,
        });
    }
    // The control task writes its own publications to the groups it reads.
    let own_groups: std::collections::BTreeSet<SubscriptionId> = machine
        .services
        .iter()
        .flat_map(|s| &s.states)
        .filter_map(|s| match &s.kind {
            StateKind::Send { items } => Some(items),
            _ => None,
        })
        .flatten()
        .filter_map(|i| i.own_group)
        .collect();
    for g in own_groups {
        control.multicast_ports.push(MulticastPort {
            name: named(&format!("own_{g}")),
            span: Span::default(),
            dir: Direction::Out,
            group: named(&machine.subscribed[g.index()]),
        });
    }
    // The control task comes after every task that feeds it and before
    // the sender it feeds: in lock-step the threads of one instant take
    // turns in this order, so a firing sees every sensor sample, call end
    // and message of its instant (as the simulator's firing does), and its
    // sends leave in the same instant.
    tasks.push(control);
    if let Some(at) = tasks.iter().position(|t| t.name.name == COMM_SEND) {
        let sender = tasks.remove(at);
        tasks.push(sender);
    }
    TaskGraph {
        name: program.robot.clone(),
        file: program.graph.file,
        span: program.graph.span,
        tasks,
        channels,
        libraries,
    }
}

/// Runs the SDF/L analyses on the refined graph: every error stops the
/// generation (reported on the robot's declaration). Returns each channel's
/// buffer size: the analysis's bound, at least the declared capacity.
/// (The rules of the file format itself are checked where the graph is
/// written, on the text written: `codegen::build_refined` reads every
/// `taskgraph.xml` back. Refining for the dataflow warnings or the simulator
/// writes none, and reading one back per robot was most of their time.)
pub fn check(graph: &TaskGraph, file: FileId, robot: Span) -> (Vec<u64>, Vec<Diagnostic>) {
    let report = crate::taskgraph::analysis::analyze(graph);
    let diagnostics = report
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .map(|d| {
            Diagnostic::new(
                Code::CodegenInternal,
                file,
                robot,
                format!(
                    "the task graph refined for robot `{}` fails its own analysis: [{}] {}",
                    graph.name, d.code, d.message
                ),
            )
        })
        .collect();
    let bounds = report.levels.first().map(|l| &l.buffers);
    let capacities = graph
        .channels
        .iter()
        .map(|c| {
            let label = format!(
                "{}.{} → {}.{}",
                c.src.task, c.src.port, c.dst.task, c.dst.port
            );
            let bound = bounds
                .and_then(|b| b.iter().find(|b| b.channel == label))
                .map_or(1, |b| b.samples);
            bound.max(c.capacity.unwrap_or(1))
        })
        .collect();
    (capacities, diagnostics)
}
