//! Structural rules of SDF/L beyond rates: loop-node boundaries (spec: outer
//! rate = inner rate × loopCount for distributing inputs and D-loop outputs,
//! outer = inner for broadcasting inputs and C-loop outputs; no distributing
//! input on a C loop; the exit task inside its loop), library ports (the library
//! and the called functions exist), and multicast groups (written and read).

use crate::diag::{Code, Diagnostic};
use crate::suggest::did_you_mean;
use crate::taskgraph::model::*;
use std::collections::BTreeMap;

/// Every structural problem of `graph` and of the graphs nested in it.
pub fn check(graph: &TaskGraph) -> Vec<Diagnostic> {
    let mut diagnostics = Vec::new();
    let mut groups: BTreeMap<String, Group> = BTreeMap::new();
    level(graph, &[], &mut groups, &mut diagnostics);
    for (name, group) in groups {
        let (code, ports, message) = match (group.writers.is_empty(), group.readers.is_empty()) {
            (false, true) => (
                Code::MulticastWithoutReader,
                group.writers,
                format!("tasks write to the multicast group `{name}`, but no task reads it"),
            ),
            (true, false) => (
                Code::MulticastWithoutWriter,
                group.readers,
                format!("tasks read the multicast group `{name}`, but no task writes to it"),
            ),
            _ => continue,
        };
        for span in ports {
            diagnostics.push(Diagnostic::new(code, graph.file, span, message.clone()));
        }
    }
    diagnostics
}

#[derive(Default)]
struct Group {
    writers: Vec<crate::span::Span>,
    readers: Vec<crate::span::Span>,
}

/// Checks one level; `libraries` are those declared in the enclosing levels.
fn level<'g>(
    graph: &'g TaskGraph,
    outer_libraries: &[&'g Library],
    groups: &mut BTreeMap<String, Group>,
    out: &mut Vec<Diagnostic>,
) {
    let mut libraries: Vec<&Library> = outer_libraries.to_vec();
    libraries.extend(graph.libraries.iter());
    for task in &graph.tasks {
        for port in &task.library_ports {
            library_port(graph, &libraries, port, out);
        }
        for port in &task.multicast_ports {
            let group = groups.entry(port.group.name.to_string()).or_default();
            match port.dir {
                Direction::Out => group.writers.push(port.group.span),
                Direction::In => group.readers.push(port.group.span),
            }
        }
        if let Some(l) = &task.loop_node {
            loop_node(graph, task, l, out);
            level(&l.body, &libraries, groups, out);
        }
    }
}

fn library_port(
    graph: &TaskGraph,
    libraries: &[&Library],
    port: &LibraryPort,
    out: &mut Vec<Diagnostic>,
) {
    let Some(library) = libraries.iter().find(|l| l.name.name == port.library.name) else {
        let mut d = Diagnostic::new(
            Code::UnknownLibrary,
            graph.file,
            port.library.span,
            format!("there is no library named `{}`", port.library.name),
        );
        d.suggest(did_you_mean(
            &port.library.name,
            libraries.iter().map(|l| l.name.name.as_str()),
        ));
        out.push(d);
        return;
    };
    for call in &port.calls {
        if library.functions.iter().any(|f| f.name.name == call.name) {
            continue;
        }
        let mut d = Diagnostic::new(
            Code::UnknownLibraryFunction,
            graph.file,
            call.span,
            format!(
                "the library `{}` has no function `{}`",
                library.name.name, call.name
            ),
        );
        d.suggest(did_you_mean(
            &call.name,
            library.functions.iter().map(|f| f.name.name.as_str()),
        ));
        out.push(d);
    }
}

fn loop_node(graph: &TaskGraph, task: &Task, l: &LoopNode, out: &mut Vec<Diagnostic>) {
    let name = &task.name.name;
    for port in &task.ports {
        let inner = port.inner_rate.unwrap_or(port.rate);
        let distributing = match (port.dir, port.kind, l.loop_type) {
            (Direction::In, Some(PortKind::Distributing), LoopType::C) => {
                out.push(Diagnostic::new(
                    Code::DistributingOnConvergentLoop,
                    graph.file,
                    port.name.span,
                    format!(
                        "`{name}` is a C-type loop: it takes its inputs once, at the first iteration, so its input `{}` must be broadcasting, not distributing",
                        port.name.name
                    ),
                ));
                continue;
            }
            (Direction::In, Some(kind), _) => kind == PortKind::Distributing,
            // An input without a kind is distributing in a data loop.
            (Direction::In, None, loop_type) => loop_type == LoopType::D,
            (Direction::Out, _, loop_type) => loop_type == LoopType::D,
        };
        let expected = if distributing {
            inner.checked_mul(l.loop_count)
        } else {
            Some(inner)
        };
        if expected == Some(port.rate) {
            continue;
        }
        let rule = if distributing {
            format!("inner rate {inner} × loopCount {}", l.loop_count)
        } else {
            format!("its inner rate {inner}")
        };
        let expected = expected.map_or("more than 64 bits hold".to_string(), |e| e.to_string());
        out.push(Diagnostic::new(
            Code::LoopBoundaryRate,
            graph.file,
            port.rate_span.unwrap_or(port.span),
            format!(
                "the outer rate of `{name}.{}` is {}, but it must be {rule} = {expected}",
                port.name.name, port.rate
            ),
        ));
    }
    if let Some(exit) = &l.exit_task
        && l.body.task_index(&exit.name).is_none()
    {
        let mut d = Diagnostic::new(
            Code::ExitTaskNotInLoop,
            graph.file,
            exit.span,
            format!(
                "the exit task `{}` is not a task inside the loop `{name}`",
                exit.name
            ),
        );
        d.suggest(did_you_mean(
            &exit.name,
            l.body.tasks.iter().map(|t| t.name.name.as_str()),
        ));
        out.push(d);
    }
}
