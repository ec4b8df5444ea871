//! Editor support for task-graph files, over the loaded model and its
//! analysis report: hover on tasks, ports and channels (repetition counts,
//! rates, buffer bounds), repetition counts as inlay hints, and completion of
//! `task.port` names inside a channel's `src`/`dst`. Plain data with byte
//! ranges; the language server turns it into protocol types.

use crate::ide::{CompletionItem, CompletionKind, HoverResult, InlayHint, InlayKind};
use crate::span::Span;
use crate::taskgraph::analysis::{GraphReport, LevelReport};
use crate::taskgraph::model::{
    Channel, Direction, LevelRef, LoopType, Task, TaskGraph, TaskKind, Trigger,
};
use std::fmt::Write;

fn level_report<'r>(report: &'r GraphReport, path: &str) -> Option<&'r LevelReport> {
    report.levels.iter().find(|l| l.path == path)
}

/// Firings of `task` per iteration of its level, when the level is consistent.
fn repetition(report: &GraphReport, path: &str, task: &str) -> Option<u64> {
    let level = level_report(report, path)?;
    let i = level.nodes.iter().position(|n| n == task)?;
    level.repetition.as_ref()?.get(i).copied()
}

/// What is under `offset`: a channel endpoint, a port, or a task (by its name
/// or anywhere in its element outside ports and inner graphs).
pub fn hover(graph: &TaskGraph, report: &GraphReport, offset: usize) -> Option<HoverResult> {
    let levels = graph.levels();
    // Innermost level first: a body's elements lie inside its loop's element.
    for level in levels.iter().rev() {
        for channel in &level.graph.channels {
            for end in [&channel.src, &channel.dst] {
                if end.span.touches(offset) {
                    return Some(HoverResult {
                        range: end.span,
                        markdown: channel_doc(level, report, channel),
                    });
                }
            }
        }
        for task in &level.graph.tasks {
            if let Some(port) = task.ports.iter().find(|p| p.span.contains(offset)) {
                let mut md = format!(
                    "**port** `{}.{}`: {}, rate {}",
                    task.name.name,
                    port.name.name,
                    direction(port.dir),
                    port.rate
                );
                if let Some(inner) = port.inner_rate {
                    let _ = write!(md, " (inner rate {inner})");
                }
                if let Some(t) = &port.sample_type {
                    let _ = write!(md, "\n\nsamples of type `{t}`");
                }
                if let Some(size) = port.size {
                    let _ = write!(md, ", {size} bytes each");
                }
                return Some(HoverResult {
                    range: port.name.span,
                    markdown: md,
                });
            }
            let in_body = task
                .loop_node
                .as_ref()
                .is_some_and(|l| l.body.span.contains(offset));
            if task.span.contains(offset) && !in_body {
                return Some(HoverResult {
                    range: task.name.span,
                    markdown: task_doc(level, report, task),
                });
            }
        }
    }
    None
}

fn direction(dir: Direction) -> &'static str {
    match dir {
        Direction::In => "input",
        Direction::Out => "output",
    }
}

fn task_doc(level: &LevelRef<'_>, report: &GraphReport, task: &Task) -> String {
    let kind = match task.kind {
        TaskKind::Computational => "task",
        TaskKind::Control => "control task",
        TaskKind::Library => "library task",
        TaskKind::Loop => "loop node",
    };
    let trigger = match &task.trigger {
        Trigger::Time { period_ms } => format!("time-triggered, every {period_ms} ms"),
        Trigger::Data => "data-triggered".to_string(),
        Trigger::Control => "run by the control task".to_string(),
    };
    let mut md = format!("**{kind}** `{}` ({trigger})\n\n", task.name.name);
    match repetition(report, &level.path, &task.name.name) {
        Some(n) => {
            let _ = write!(md, "fires **{n}×** per iteration of `{}`", level.path);
        }
        None => {
            let _ = write!(
                md,
                "no repetition count: `{}` is not consistent",
                level.path
            );
        }
    }
    if let Some(wcet) = task.wcet {
        let _ = write!(md, "; execution time {wcet}");
    }
    let rates: Vec<String> = task
        .ports
        .iter()
        .map(|p| {
            let arrow = if p.dir == Direction::In { "←" } else { "→" };
            format!("`{}` {arrow} {}", p.name.name, p.rate)
        })
        .collect();
    if !rates.is_empty() {
        let _ = write!(md, "\n\nrates: {}", rates.join(", "));
    }
    if let Some(sub) = &task.subgraph {
        let inner = format!("{}/{}", level.path, task.name.name);
        let per_firing = level_report(report, &inner).and_then(|r| {
            let counts = r.repetition.as_ref()?;
            Some(
                r.nodes
                    .iter()
                    .zip(counts)
                    .filter(|(n, _)| !n.ends_with(')'))
                    .map(|(n, c)| format!("{n}×{c}"))
                    .collect::<Vec<_>>(),
            )
        });
        match per_firing {
            Some(rep) => {
                let _ = write!(
                    md,
                    "\n\nstands for the sub-graph `{}`: each firing runs one iteration of it ({})",
                    sub.name,
                    rep.join(", ")
                );
            }
            None => {
                let _ = write!(
                    md,
                    "\n\nstands for the sub-graph `{}` (not analysed here)",
                    sub.name
                );
            }
        }
    }
    if let Some(l) = &task.loop_node {
        let kind = match l.loop_type {
            LoopType::D => "data loop (D)",
            LoopType::C => "convergent loop (C)",
        };
        let _ = write!(md, "\n\n{kind}, up to {} iterations", l.loop_count);
        let inner = format!("{}/{}", level.path, task.name.name);
        if let Some(rep) = level_report(report, &inner).and_then(|r| {
            let counts = r.repetition.as_ref()?;
            Some(
                r.nodes
                    .iter()
                    .zip(counts)
                    .filter(|(n, _)| l.body.task_index(n).is_some())
                    .map(|(n, c)| format!("{n}×{c}"))
                    .collect::<Vec<_>>(),
            )
        }) {
            let _ = write!(md, "; per iteration: {}", rep.join(", "));
        }
    }
    if let Some(source) = &task.source {
        let _ = write!(md, "\n\nsource: `{source}`");
    }
    md
}

fn channel_doc(level: &LevelRef<'_>, report: &GraphReport, channel: &Channel) -> String {
    let rate = |task: &str, port: &str| -> Option<u64> {
        if let Some(t) = level.graph.tasks.iter().find(|t| t.name.name == task) {
            return t.port(port).map(|p| p.rate);
        }
        // A body's channel to its own loop's port runs at the inner rate.
        let l = level.enclosing.filter(|l| l.name.name == task)?;
        l.port(port).map(|p| p.inner_rate.unwrap_or(1))
    };
    let name = format!(
        "{}.{} → {}.{}",
        channel.src.task, channel.src.port, channel.dst.task, channel.dst.port
    );
    let mut md = format!("**channel** `{name}`");
    if let (Some(p), Some(c)) = (
        rate(&channel.src.task, &channel.src.port),
        rate(&channel.dst.task, &channel.dst.port),
    ) {
        let _ = write!(md, "\n\nproduces {p}, consumes {c} per firing");
    }
    let _ = write!(md, "\n\ninitial samples: {}", channel.initial_tokens);
    let bound = level_report(report, &level.path)
        .and_then(|l| l.buffers.iter().find(|b| b.channel == name))
        .map(|b| b.samples);
    if let Some(bound) = bound {
        let _ = write!(md, "; holds at most {bound} under the schedule");
    }
    if let Some(cap) = channel.capacity {
        let _ = write!(md, "; declared capacity {cap}");
    }
    md
}

/// `×N` after the name of every task of a consistent level (after the
/// value's closing quote).
pub fn inlay_hints(graph: &TaskGraph, report: &GraphReport) -> Vec<InlayHint> {
    let mut hints = Vec::new();
    for level in graph.levels() {
        for task in &level.graph.tasks {
            if let Some(n) = repetition(report, &level.path, &task.name.name) {
                hints.push(InlayHint {
                    offset: task.name.span.end + 1,
                    label: format!("×{n}"),
                    kind: InlayKind::Repetitions,
                    tooltip: Some(
                        "firings per iteration of this level (repetition vector)".to_string(),
                    ),
                });
            }
        }
    }
    hints.sort_by_key(|h| h.offset);
    hints
}

/// Inside the value of a `<Channel>`'s `src` or `dst`: the ports that can go
/// there, each replacing the whole value: outputs of the level's
/// tasks for `src` (and, in a loop body, the loop's inputs), inputs for `dst`.
pub fn complete_endpoint(text: &str, graph: &TaskGraph, offset: usize) -> Vec<CompletionItem> {
    let Some((element, attribute, value)) = attribute_value_at(text, offset) else {
        return Vec::new();
    };
    if element != "Channel" || !matches!(attribute, "src" | "dst") {
        return Vec::new();
    }
    let wanted = if attribute == "src" {
        Direction::Out
    } else {
        Direction::In
    };
    // The innermost level whose element holds the cursor.
    let all = graph.levels();
    let level = all
        .iter()
        .rev()
        .find(|l| l.graph.span.contains(offset))
        .or(all.first());
    let Some(level) = level else {
        return Vec::new();
    };
    let mut items = Vec::new();
    for task in &level.graph.tasks {
        for port in task.ports.iter().filter(|p| p.dir == wanted) {
            let label = format!("{}.{}", task.name.name, port.name.name);
            items.push(
                CompletionItem::new(label, CompletionKind::Port, value).detail(format!(
                    "{} port of {}, rate {}",
                    direction(port.dir),
                    task.name.name,
                    port.rate
                )),
            );
        }
    }
    if let Some(l) = level.enclosing {
        // Inside the body the loop's inputs are sources and its outputs sinks.
        let inside = if wanted == Direction::Out {
            Direction::In
        } else {
            Direction::Out
        };
        for port in l.ports.iter().filter(|p| p.dir == inside) {
            let label = format!("{}.{}", l.name.name, port.name.name);
            items.push(
                CompletionItem::new(label, CompletionKind::Port, value).detail(format!(
                    "{} port of the enclosing loop, inner rate {}",
                    direction(port.dir),
                    port.inner_rate.unwrap_or(1)
                )),
            );
        }
    }
    items
}

/// The element name, attribute name and value range of the attribute value
/// holding `offset`, read from the text itself (the file may not load while
/// it is being typed).
pub fn attribute_value_at(text: &str, offset: usize) -> Option<(&str, &str, Span)> {
    let offset = offset.min(text.len());
    if !text.is_char_boundary(offset) {
        return None;
    }
    let before = &text[..offset];
    let tag_start = before.rfind('<')?;
    let tag = &before[tag_start + 1..];
    if tag.contains('>') {
        return None; // in content, not in a tag
    }
    let element = tag.split(|c: char| c.is_whitespace() || c == '/').next()?;
    // Inside a value when an odd number of quotes precede the cursor.
    let mut open: Option<(usize, char)> = None;
    for (i, c) in tag.char_indices() {
        match open {
            None if c == '"' || c == '\'' => open = Some((i, c)),
            Some((_, q)) if c == q => open = None,
            _ => {}
        }
    }
    let (quote_at, quote) = open?;
    let name_part = tag[..quote_at].trim_end().strip_suffix('=')?.trim_end();
    let attribute = name_part
        .rsplit(|c: char| c.is_whitespace())
        .next()
        .filter(|a| !a.is_empty())?;
    let value_start = tag_start + 1 + quote_at + 1;
    let value_end = text[offset..]
        .find([quote, '\n', '<', '>'])
        .map_or(text.len(), |i| offset + i);
    Some((element, attribute, Span::new(value_start, value_end)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::FileId;
    use crate::taskgraph::{analysis::analyze, load_task_graph};

    const DATA_LOOP: &str = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/taskgraphs/data_loop.taskgraph.xml"
    ));

    fn load(text: &str) -> (TaskGraph, GraphReport) {
        let (graph, _) = load_task_graph(FileId(0), text);
        let graph = graph.expect("loads");
        let report = analyze(&graph);
        (graph, report)
    }

    fn at(text: &str, needle: &str) -> usize {
        text.find(needle).unwrap_or_else(|| panic!("{needle}"))
    }

    #[test]
    fn hover_on_a_task_shows_its_repetition_count_and_rates() {
        let (graph, report) = load(DATA_LOOP);
        let h = hover(&graph, &report, at(DATA_LOOP, "name=\"B\"") + 7).expect("hover on B");
        assert_eq!(&DATA_LOOP[h.range.range()], "B");
        assert!(
            h.markdown
                .contains("fires **1×** per iteration of `data_loop/L`"),
            "{}",
            h.markdown
        );
        assert!(h.markdown.contains("`i` ← 1, `o` → 1"), "{}", h.markdown);

        let a = hover(&graph, &report, at(DATA_LOOP, "name=\"A\"") + 7).unwrap();
        assert!(a.markdown.contains("fires **1×**"), "{}", a.markdown);
        assert!(a.markdown.contains("every 1000 ms"), "{}", a.markdown);

        let l = hover(&graph, &report, at(DATA_LOOP, "name=\"L\"") + 7).unwrap();
        assert!(
            l.markdown.contains("data loop (D), up to 10 iterations"),
            "{}",
            l.markdown
        );
        assert!(
            l.markdown.contains("per iteration: B×1, C×1"),
            "{}",
            l.markdown
        );
    }

    #[test]
    fn hover_on_channels_and_ports() {
        let (graph, report) = load(DATA_LOOP);
        let c = hover(&graph, &report, at(DATA_LOOP, "src=\"A.o\"") + 6).unwrap();
        assert_eq!(&DATA_LOOP[c.range.range()], "A.o");
        assert!(c.markdown.contains("`A.o → L.in`"), "{}", c.markdown);
        assert!(
            c.markdown.contains("produces 10, consumes 10"),
            "{}",
            c.markdown
        );
        let inner = hover(&graph, &report, at(DATA_LOOP, "src=\"L.in\"") + 6).unwrap();
        assert!(
            inner.markdown.contains("produces 1, consumes 1"),
            "{}",
            inner.markdown
        );
        let p = hover(
            &graph,
            &report,
            at(DATA_LOOP, "name=\"o\" dir=\"out\" rate=\"10\"") + 7,
        )
        .unwrap();
        assert!(
            p.markdown.contains("**port** `A.o`: output, rate 10"),
            "{}",
            p.markdown
        );
    }

    #[test]
    fn inlay_hints_follow_every_task_name() {
        let (graph, report) = load(DATA_LOOP);
        let hints: Vec<(String, String)> = inlay_hints(&graph, &report)
            .into_iter()
            .map(|h| {
                let before = &DATA_LOOP[..h.offset - 1];
                let name = before.rsplit('"').next().unwrap().to_string();
                (name, h.label)
            })
            .collect();
        let expected: Vec<(String, String)> = [
            ("A", "×1"),
            ("L", "×1"),
            ("B", "×1"),
            ("C", "×1"),
            ("D", "×1"),
        ]
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
        assert_eq!(hints, expected);
    }

    #[test]
    fn endpoint_completion_offers_ports_of_the_level() {
        let (graph, _) = load(DATA_LOOP);
        let labels = |needle: &str, skip: usize| {
            let offset = at(DATA_LOOP, needle) + skip;
            let items = complete_endpoint(DATA_LOOP, &graph, offset);
            let span = items.first().expect("in a value").replace;
            assert!(items.iter().all(|i| i.replace == span));
            let labels: Vec<String> = items.into_iter().map(|i| i.label).collect();
            (DATA_LOOP[span.range()].to_string(), labels)
        };
        assert_eq!(
            labels("src=\"A.o\"", 5),
            ("A.o".into(), vec!["A.o".into(), "L.out".into()])
        );
        assert_eq!(
            labels("dst=\"D.i\"", 5),
            ("D.i".into(), vec!["L.in".into(), "D.i".into()])
        );
        // In the loop body: its tasks, and the loop's own ports turned round.
        assert_eq!(
            labels("src=\"B.o\"", 5),
            (
                "B.o".into(),
                vec!["B.o".into(), "C.o".into(), "L.in".into()]
            )
        );
        assert_eq!(
            complete_endpoint(DATA_LOOP, &graph, at(DATA_LOOP, "loopCount") + 2),
            Vec::new()
        );
    }

    #[test]
    fn attribute_values_are_found_in_half_typed_tags() {
        let text = "<Channel src=\"A.\n<Task name='x'>";
        assert_eq!(
            attribute_value_at(text, 16),
            Some(("Channel", "src", Span::new(14, 16)))
        );
        assert_eq!(
            attribute_value_at(text, 29).map(|(e, a, _)| (e, a)),
            Some(("Task", "name"))
        );
        assert_eq!(attribute_value_at(text, text.len()), None);
        assert_eq!(attribute_value_at("", 0), None);
        assert_eq!(
            attribute_value_at("<a b=\"한", 99).map(|(_, a, _)| a),
            Some("b")
        );
    }
}
