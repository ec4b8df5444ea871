//! Builders of small task-graph models for the analyses' unit tests.

use crate::diag::FileId;
use crate::span::Span;
use crate::taskgraph::model::*;

pub(crate) fn named(name: &str) -> Named {
    Named {
        name: name.to_string(),
        span: Span::default(),
    }
}

pub(crate) fn port(spec: &str) -> Port {
    // "o>2": output o, rate 2; "i<3": input i, rate 3.
    let (name, dir, rate) = match spec.split_once('>') {
        Some((n, r)) => (n, Direction::Out, r),
        None => {
            let (n, r) = spec.split_once('<').unwrap();
            (n, Direction::In, r)
        }
    };
    Port {
        name: named(name),
        span: Span::default(),
        dir,
        rate: rate.parse().unwrap(),
        rate_span: None,
        sample_type: None,
        size: None,
        kind: None,
        inner_rate: None,
    }
}

pub(crate) fn task(name: &str, ports: &[&str]) -> Task {
    Task {
        name: named(name),
        span: Span::default(),
        kind: TaskKind::Computational,
        trigger: Trigger::Data,
        wcet: None,
        source: None,
        subgraph: None,
        ports: ports.iter().map(|p| port(p)).collect(),
        library_ports: Vec::new(),
        multicast_ports: Vec::new(),
        loop_node: None,
    }
}

pub(crate) fn channel(src: &str, dst: &str, tokens: u64, at: usize) -> Channel {
    let end = |s: &str| {
        let (task, port) = s.split_once('.').unwrap();
        Endpoint {
            task: task.into(),
            port: port.into(),
            span: Span::default(),
        }
    };
    Channel {
        src: end(src),
        dst: end(dst),
        initial_tokens: tokens,
        capacity: None,
        span: Span::new(at, at + 1),
    }
}

pub(crate) fn graph(name: &str, tasks: Vec<Task>, channels: Vec<Channel>) -> TaskGraph {
    TaskGraph {
        name: name.into(),
        file: FileId(0),
        span: Span::default(),
        tasks,
        channels,
        libraries: Vec::new(),
    }
}

/// `shared/examples/taskgraphs/data_loop`: A 10→ L (D-loop × 10 over B, C) 10→ D.
pub(crate) fn data_loop() -> TaskGraph {
    let mut l = task("L", &["in<10", "out>10"]);
    l.kind = TaskKind::Loop;
    for p in &mut l.ports {
        p.inner_rate = Some(1);
    }
    l.loop_node = Some(Box::new(LoopNode {
        loop_type: LoopType::D,
        loop_count: 10,
        exit_task: None,
        body: graph(
            "L_body",
            vec![task("B", &["i<1", "o>1"]), task("C", &["i<1", "o>1"])],
            vec![
                channel("L.in", "B.i", 0, 1),
                channel("B.o", "C.i", 0, 2),
                channel("C.o", "L.out", 0, 3),
            ],
        ),
    }));
    graph(
        "data_loop",
        vec![task("A", &["o>10"]), l, task("D", &["i<10"])],
        vec![channel("A.o", "L.in", 0, 4), channel("L.out", "D.i", 0, 5)],
    )
}
