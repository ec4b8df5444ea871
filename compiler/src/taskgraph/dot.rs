//! A picture of a task graph in Graphviz DOT: tasks as boxes (control tasks
//! bold, library tasks as components), loop nodes as clusters holding their
//! inner graphs, channels labelled with their rates, initial samples as black
//! squares (●), library calls as dashed edges, multicast groups as notes; a
//! task standing for a sub-graph file is a box naming the file (`⤷ file`).

use super::model::*;
use crate::fasthash::FastMap;
use std::fmt::Write;

/// The DOT text of `graph`.
pub fn to_dot(graph: &TaskGraph) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph {} {{", quote(&graph.name));
    out.push_str("  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n  edge [fontname=\"Helvetica\", fontsize=10];\n");
    level(&mut out, graph, "", 1);
    out.push_str("}\n");
    out
}

/// DOT identifiers are quoted so that any name is safe.
fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// The DOT node id of a task at a level (`prefix` keeps nested names apart).
fn id(prefix: &str, task: &str) -> String {
    quote(&format!("{prefix}{task}"))
}

fn level(out: &mut String, graph: &TaskGraph, prefix: &str, depth: usize) {
    let pad = "  ".repeat(depth);
    for task in &graph.tasks {
        let name = &task.name.name;
        match &task.loop_node {
            Some(l) => {
                let inner = format!("{prefix}{name}/");
                let kind = match l.loop_type {
                    LoopType::D => "D",
                    LoopType::C => "C",
                };
                let _ = writeln!(
                    out,
                    "{pad}subgraph {} {{",
                    quote(&format!("cluster_{prefix}{name}"))
                );
                let _ = writeln!(
                    out,
                    "{pad}  label={}; style=rounded;",
                    quote(&format!("{name} ({kind}-loop × {})", l.loop_count))
                );
                // The loop's own ports, seen from inside, as small points.
                for port in &task.ports {
                    let _ = writeln!(
                        out,
                        "{pad}  {} [shape=point, xlabel={}];",
                        id(&inner, &format!("{}.{}", name, port.name.name)),
                        quote(&port.name.name)
                    );
                }
                level(out, &l.body, &inner, depth + 1);
                let _ = writeln!(out, "{pad}}}");
            }
            None => {
                let style = match task.kind {
                    TaskKind::Control => ", style=bold",
                    TaskKind::Library => ", shape=component",
                    _ => "",
                };
                let mut label = match task.wcet {
                    Some(w) => format!("{name}\\n{w}"),
                    None => name.to_string(),
                };
                // A sub-graph is not drawn inside its task: the task names
                // its file (`semo graph dot` on that file draws it).
                if let Some(sub) = &task.subgraph {
                    label.push_str(&format!("\\n⤷ {}", sub.name));
                }
                let _ = writeln!(
                    out,
                    "{pad}{} [label=\"{}\"{style}];",
                    id(prefix, name),
                    label.replace('"', "\\\"")
                );
            }
        }
        for port in &task.library_ports {
            if port.master {
                let _ = writeln!(
                    out,
                    "{pad}{} -> {} [style=dashed, arrowhead=odot, label={}];",
                    id(prefix, name),
                    id("", &format!("library {}", port.library.name)),
                    quote(&port.name.name)
                );
            }
        }
        for port in &task.multicast_ports {
            let group = id("", &format!("multicast {}", port.group.name));
            let _ = writeln!(
                out,
                "{pad}{group} [shape=note, label={}];",
                quote(&port.group.name)
            );
            let (a, b) = match port.dir {
                Direction::Out => (id(prefix, name), group),
                Direction::In => (group, id(prefix, name)),
            };
            let _ = writeln!(out, "{pad}{a} -> {b} [style=dotted];");
        }
    }
    for library in &graph.libraries {
        let _ = writeln!(
            out,
            "{pad}{} [shape=component, label={}];",
            id("", &format!("library {}", library.name.name)),
            quote(&library.name.name)
        );
    }
    // Looked up twice per channel: an index keeps a long chain linear (a
    // search per end took minutes on 139,000 tasks).
    let index: FastMap<&str, usize> = graph
        .tasks
        .iter()
        .enumerate()
        .map(|(i, t)| (t.name.name.as_str(), i))
        .collect();
    let task_index = |name: &str| index.get(name).copied();
    for c in &graph.channels {
        let end = |e: &Endpoint| match task_index(&e.task) {
            Some(t) if graph.tasks[t].loop_node.is_some() => id(
                &format!("{prefix}{}/", e.task),
                &format!("{}.{}", e.task, e.port),
            ),
            Some(_) => id(prefix, &e.task),
            // The enclosing loop's own port, from inside the body.
            None => id(prefix, &format!("{}.{}", e.task, e.port)),
        };
        let rate = |e: &Endpoint, dir| {
            let task = task_index(&e.task).map(|t| &graph.tasks[t]);
            task.and_then(|t| {
                t.ports
                    .iter()
                    .find(|p| p.name.name == e.port && p.dir == dir)
            })
            .map_or(1, |p| p.rate)
        };
        let tokens = match c.initial_tokens {
            0 => String::new(),
            1 => " ●".to_string(),
            n => format!(" ●×{n}"),
        };
        let _ = writeln!(
            out,
            "{pad}{} -> {} [taillabel={}, headlabel={}, label={}];",
            end(&c.src),
            end(&c.dst),
            quote(&rate(&c.src, Direction::Out).to_string()),
            quote(&rate(&c.dst, Direction::In).to_string()),
            quote(tokens.trim()),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::FileId;

    #[test]
    fn loops_are_clusters_and_channels_carry_rates_and_samples() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/taskgraphs/kmeans.taskgraph.xml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let graph = super::super::load_task_graph(FileId(0), &text).0.unwrap();
        let dot = to_dot(&graph);
        assert!(dot.starts_with("digraph \"kmeans\" {"));
        assert!(dot.contains("subgraph \"cluster_Converge\""), "{dot}");
        assert!(
            dot.contains("subgraph \"cluster_Converge/Assign\""),
            "{dot}"
        );
        assert!(dot.contains("label=\"Converge (C-loop × 500)\""), "{dot}");
        // ReplaceCenter.fb → Select.prev holds one initial sample.
        assert!(
            dot.contains("\"Converge/ReplaceCenter\" -> \"Converge/Select\" [taillabel=\"1\", headlabel=\"1\", label=\"●\"]"),
            "{dot}"
        );
        // ReadPoints produces 16 per firing into the loop's port.
        assert!(
            dot.contains("\"ReadPoints\" -> \"Converge/Converge.pts\" [taillabel=\"16\""),
            "{dot}"
        );
        assert_eq!(dot.matches('{').count(), dot.matches('}').count());
    }
}
