//! Writes a task graph in our `*.taskgraph.xml` format (the refined graphs of
//! `semo build`), readable again by [`super::load_task_graph`].

use super::model::*;
use crate::xmlpos::escape;
use std::fmt::Write;

/// The graph as `*.taskgraph.xml` text, after a comment naming its origin.
pub fn to_xml(graph: &TaskGraph, comment: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(out, "<!-- {} -->", crate::xmlpos::comment(comment));
    write_graph(&mut out, graph, 0, true);
    out
}

fn indent(out: &mut String, depth: usize) {
    out.push_str(&"  ".repeat(depth));
}

fn write_graph(out: &mut String, graph: &TaskGraph, depth: usize, root: bool) {
    indent(out, depth);
    let ns = if root {
        " xmlns=\"urn:semo:taskgraph:1\""
    } else {
        ""
    };
    let _ = writeln!(out, "<TaskGraph name=\"{}\"{ns}>", escape(&graph.name));
    for task in &graph.tasks {
        write_task(out, task, depth + 1);
    }
    for library in &graph.libraries {
        indent(out, depth + 1);
        let _ = writeln!(out, "<Library name=\"{}\">", escape(&library.name.name));
        for f in &library.functions {
            indent(out, depth + 2);
            let returns = f
                .returns
                .as_ref()
                .map(|r| format!(" returns=\"{}\"", escape(r)))
                .unwrap_or_default();
            if f.params.is_empty() {
                let _ = writeln!(
                    out,
                    "<Function name=\"{}\"{returns}/>",
                    escape(&f.name.name)
                );
                continue;
            }
            let _ = writeln!(out, "<Function name=\"{}\"{returns}>", escape(&f.name.name));
            for (name, ty) in &f.params {
                indent(out, depth + 3);
                let _ = writeln!(
                    out,
                    "<Param name=\"{}\" type=\"{}\"/>",
                    escape(name),
                    escape(ty)
                );
            }
            indent(out, depth + 2);
            out.push_str("</Function>\n");
        }
        indent(out, depth + 1);
        out.push_str("</Library>\n");
    }
    for c in &graph.channels {
        indent(out, depth + 1);
        let _ = write!(
            out,
            "<Channel src=\"{}.{}\" dst=\"{}.{}\"",
            escape(&c.src.task),
            escape(&c.src.port),
            escape(&c.dst.task),
            escape(&c.dst.port)
        );
        if c.initial_tokens > 0 {
            let _ = write!(out, " initialTokens=\"{}\"", c.initial_tokens);
        }
        if let Some(capacity) = c.capacity {
            let _ = write!(out, " capacity=\"{capacity}\"");
        }
        out.push_str("/>\n");
    }
    indent(out, depth);
    out.push_str("</TaskGraph>\n");
}

fn write_task(out: &mut String, task: &Task, depth: usize) {
    indent(out, depth);
    if let Some(l) = &task.loop_node {
        let kind = match l.loop_type {
            LoopType::D => "D",
            LoopType::C => "C",
        };
        let _ = write!(
            out,
            "<Loop name=\"{}\" type=\"{kind}\" loopCount=\"{}\"",
            escape(&task.name.name),
            l.loop_count
        );
        if let Some(exit) = &l.exit_task {
            let _ = write!(out, " exitTask=\"{}\"", escape(&exit.name));
        }
        out.push_str(">\n");
        for p in &task.ports {
            indent(out, depth + 1);
            let _ = write!(
                out,
                "<Port name=\"{}\" dir=\"{}\"",
                escape(&p.name.name),
                dir(p.dir)
            );
            if let Some(kind) = p.kind {
                let kind = match kind {
                    PortKind::Distributing => "distributing",
                    PortKind::Broadcasting => "broadcasting",
                };
                let _ = write!(out, " kind=\"{kind}\"");
            }
            let _ = write!(out, " outerRate=\"{}\"", p.rate);
            if let Some(inner) = p.inner_rate {
                let _ = write!(out, " innerRate=\"{inner}\"");
            }
            out.push_str("/>\n");
        }
        write_graph(out, &l.body, depth + 1, false);
        indent(out, depth);
        out.push_str("</Loop>\n");
        return;
    }
    let kind = match task.kind {
        TaskKind::Computational => "computational",
        TaskKind::Control => "control",
        TaskKind::Library => "library",
        TaskKind::Loop => "loop",
    };
    let _ = write!(
        out,
        "<Task name=\"{}\" kind=\"{kind}\"",
        escape(&task.name.name)
    );
    match &task.trigger {
        Trigger::Time { period_ms } => {
            let _ = write!(out, " trigger=\"time\" period=\"{period_ms} MSEC\"");
        }
        Trigger::Data => out.push_str(" trigger=\"data\""),
        Trigger::Control => out.push_str(" trigger=\"control\""),
    }
    if let Some(wcet) = task.wcet {
        let _ = write!(out, " wcet=\"{wcet}\"");
    }
    if let Some(source) = &task.source {
        let _ = write!(out, " source=\"{}\"", escape(source));
    }
    if let Some(sub) = &task.subgraph {
        let _ = write!(out, " subgraph=\"{}\"", escape(&sub.name));
    }
    let empty =
        task.ports.is_empty() && task.library_ports.is_empty() && task.multicast_ports.is_empty();
    if empty {
        out.push_str("/>\n");
        return;
    }
    out.push_str(">\n");
    for p in &task.ports {
        indent(out, depth + 1);
        let _ = write!(
            out,
            "<Port name=\"{}\" dir=\"{}\" rate=\"{}\"",
            escape(&p.name.name),
            dir(p.dir),
            p.rate
        );
        if let Some(ty) = &p.sample_type {
            let _ = write!(out, " type=\"{}\"", escape(ty));
        }
        if let Some(size) = p.size {
            let _ = write!(out, " size=\"{size}\"");
        }
        out.push_str("/>\n");
    }
    for l in &task.library_ports {
        indent(out, depth + 1);
        let element = if l.master {
            "LibraryMasterPort"
        } else {
            "LibrarySlavePort"
        };
        let _ = write!(
            out,
            "<{element} name=\"{}\" library=\"{}\"",
            escape(&l.name.name),
            escape(&l.library.name)
        );
        if l.master && !l.calls.is_empty() {
            let calls: Vec<&str> = l.calls.iter().map(|c| c.name.as_str()).collect();
            let _ = write!(out, " calls=\"{}\"", escape(&calls.join(" ")));
        }
        out.push_str("/>\n");
    }
    for m in &task.multicast_ports {
        indent(out, depth + 1);
        let _ = writeln!(
            out,
            "<MulticastPort name=\"{}\" dir=\"{}\" group=\"{}\"/>",
            escape(&m.name.name),
            dir(m.dir),
            escape(&m.group.name)
        );
    }
    indent(out, depth);
    out.push_str("</Task>\n");
}

fn dir(d: Direction) -> &'static str {
    match d {
        Direction::In => "in",
        Direction::Out => "out",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::FileId;

    /// Every reference graph survives writing and reading back: the same
    /// tasks, ports, channels and libraries, and no diagnostics.
    #[test]
    fn reference_graphs_round_trip() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/taskgraphs");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).expect("shared examples") {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let (Some(graph), _) = crate::taskgraph::load_task_graph(FileId(0), &text) else {
                continue;
            };
            let written = to_xml(&graph, "round trip");
            let (again, diags) = crate::taskgraph::load_task_graph(FileId(0), &written);
            let again = again.unwrap_or_else(|| panic!("{}: {diags:?}", path.display()));
            assert!(
                diags.iter().all(|d| !d.is_error()),
                "{}: {diags:?}\n{written}",
                path.display()
            );
            assert_eq!(summary(&graph), summary(&again), "{}", path.display());
            seen += 1;
        }
        assert!(seen >= 8);
    }

    /// The graph without positions.
    fn summary(g: &TaskGraph) -> String {
        let mut out = format!(
            "{} libs={:?}\n",
            g.name,
            g.libraries
                .iter()
                .map(|l| (&l.name.name, l.functions.len()))
                .collect::<Vec<_>>()
        );
        for t in &g.tasks {
            let ports: Vec<_> = t
                .ports
                .iter()
                .map(|p| (&p.name.name, p.dir, p.rate, p.kind, p.inner_rate))
                .collect();
            let _ = writeln!(
                out,
                "{} {:?} {:?} {:?} {ports:?} {}",
                t.name.name,
                t.kind,
                t.trigger,
                t.wcet,
                t.library_ports.len() + t.multicast_ports.len()
            );
            if let Some(l) = &t.loop_node {
                let _ = writeln!(
                    out,
                    "loop {:?} {} {:?}\n{}",
                    l.loop_type,
                    l.loop_count,
                    l.exit_task.as_ref().map(|e| &e.name),
                    summary(&l.body)
                );
            }
        }
        for c in &g.channels {
            let _ = writeln!(
                out,
                "{}.{} {}.{} {} {:?}",
                c.src.task, c.src.port, c.dst.task, c.dst.port, c.initial_tokens, c.capacity
            );
        }
        out
    }
}
