//! Hierarchy by reference: a `<Task subgraph="file">` stands for the task
//! graph in that file, looked up relative to the referencing file. This
//! module follows the references (reading files only through a [`Resolver`]
//! the caller passes in: the CLI reads the disk, the language server its open
//! documents first) and checks each one:
//!
//! - the file can be read (E067) and is a task graph without errors of its
//!   own, its own references included (E068: one summary on the reference;
//!   the problems themselves belong to that file);
//! - following references never leads back to a file on the way (E069, on
//!   the reference of the file the cycle returns to), and does not nest
//!   deeper than [`MAX_DEPTH`] nor read more than [`MAX_REFERENCES`] files;
//! - the task's data ports and the sub-graph's *open ports* correspond one to
//!   one, by name and direction (E078). The open ports of a graph are the
//!   data ports of its top-level tasks (loop nodes included) that no channel
//!   of that level joins: they are its interface, so any graph file can be
//!   used as a sub-graph without declaring one.
//!
//! Rates are checked by the analysis ([`super::analysis::analyze_with`]): the
//! sub-graph becomes a hierarchy level of the task (`top/task`) whose
//! boundary fires once per firing of the task, as a loop body's does once per
//! iteration. So one firing of the task runs exactly one iteration of its
//! sub-graph (E079 when the rates do not allow it).

use super::model::{Direction, Named, Task, TaskGraph};
use crate::diag::{Code, Diagnostic, FileId};
use crate::span::Span;
use crate::text::{ColumnUnit, LineIndex};
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

/// A referenced file's text, with the id the caller gives it.
#[derive(Clone, Debug)]
pub struct SubgraphSource {
    pub file: FileId,
    pub text: Arc<str>,
}

/// Reads referenced files: the text at a path (already joined to the
/// referencing file's folder), or why it cannot be read.
pub trait Resolver {
    fn read(&mut self, path: &Path) -> Result<SubgraphSource, String>;
}

impl<F: FnMut(&Path) -> Result<SubgraphSource, String>> Resolver for F {
    fn read(&mut self, path: &Path) -> Result<SubgraphSource, String> {
        self(path)
    }
}

/// References followed from one root file, at most (further ones are E069).
pub const MAX_REFERENCES: usize = 256;
/// Sub-graphs nested in sub-graphs, at most.
pub const MAX_DEPTH: usize = 16;

/// A task's data port and the open port of its sub-graph it stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortLink {
    /// Index in the task's `ports`.
    pub outer: usize,
    /// The sub-graph's top-level task and the index in its `ports`.
    pub inner_task: usize,
    pub inner_port: usize,
}

/// A reference that resolved to a usable sub-graph.
#[derive(Clone, Debug)]
pub struct Subgraph {
    /// The path of the level holding the referencing task, in the
    /// referencing graph (`top`, `top/L`).
    pub level: String,
    /// The task's index in that level's graph.
    pub task: usize,
    pub file: FileId,
    /// Where the file was read from.
    pub location: PathBuf,
    pub graph: Arc<TaskGraph>,
    pub links: Vec<PortLink>,
    /// The sub-graph's own references.
    pub nested: Hierarchy,
}

/// A `subgraph` attribute of the root file and the file it names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Reference {
    /// The attribute value.
    pub span: Span,
    pub location: PathBuf,
    /// Whether the file could be read (go-to-definition opens only those).
    pub readable: bool,
}

/// Every sub-graph a graph references, resolved.
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    pub subgraphs: Vec<Subgraph>,
    /// The graph's own `subgraph` attributes.
    pub references: Vec<Reference>,
    /// Problems of the graph's references, in the graph's file.
    pub diagnostics: Vec<Diagnostic>,
    /// Every file read while following references (to know whom to re-check
    /// when one changes).
    pub reads: Vec<PathBuf>,
}

/// The errors of a sub-graph analysed alone, with its own sub-graphs: a
/// sub-graph with errors is not usable. Passed in by [`crate::taskgraph::resolve`]
/// (the analyses stand above the references they read).
pub type CheckAlone<'c> = &'c dyn Fn(&TaskGraph, &Hierarchy) -> Vec<Diagnostic>;

/// Follows the references of `graph`, read from `location` (`None` for text
/// that has no place on disk: its references cannot be looked up); each
/// sub-graph found is usable only when `check` finds no error in it.
pub fn resolve_checked(
    graph: &TaskGraph,
    location: Option<&Path>,
    resolver: &mut dyn Resolver,
    check: CheckAlone<'_>,
) -> Hierarchy {
    let mut walk = Walk {
        resolver,
        check,
        budget: MAX_REFERENCES,
        reads: Vec::new(),
    };
    let chain: Vec<PathBuf> = location.map(normalize).into_iter().collect();
    let (mut hierarchy, _) = walk.graph(graph, location, &chain);
    hierarchy.reads = walk.reads;
    hierarchy
}

struct Walk<'r> {
    resolver: &'r mut dyn Resolver,
    check: CheckAlone<'r>,
    budget: usize,
    reads: Vec<PathBuf>,
}

/// What following one graph's references found, for the referencing graph.
struct Outcome {
    /// The smallest index in the chain that a reference cycle below returns to.
    cycle_to: Option<usize>,
    /// The cycle, as file names, when `cycle_to` is set.
    cycle: Vec<String>,
}

impl Walk<'_> {
    /// Resolves the references of `graph` (at `chain.last()`).
    fn graph(
        &mut self,
        graph: &TaskGraph,
        location: Option<&Path>,
        chain: &[PathBuf],
    ) -> (Hierarchy, Outcome) {
        let mut out = Hierarchy::default();
        let mut outcome = Outcome {
            cycle_to: None,
            cycle: Vec::new(),
        };
        let here = chain.len().saturating_sub(1);
        for level in graph.levels() {
            for (index, task) in level.graph.tasks.iter().enumerate() {
                let Some(attr) = &task.subgraph else { continue };
                let Some(found) = self.reference(graph.file, attr, location, chain, &mut out)
                else {
                    continue;
                };
                match found {
                    Found::Usable(usable) => {
                        let (target, source, child, nested) = *usable;
                        if let Some(links) = match_ports(
                            graph.file,
                            task,
                            attr,
                            &target,
                            &child,
                            &mut out.diagnostics,
                        ) {
                            out.subgraphs.push(Subgraph {
                                level: level.path.clone(),
                                task: index,
                                file: source.file,
                                location: target,
                                graph: Arc::new(child),
                                links,
                                nested,
                            });
                        }
                    }
                    Found::Cycle(k, cycle) => {
                        if k == here {
                            out.diagnostics.push(Diagnostic::new(
                                Code::SubgraphCycle,
                                graph.file,
                                attr.span,
                                format!(
                                    "`{}` leads back to this file: {}",
                                    attr.name,
                                    cycle.join(" → ")
                                ),
                            ));
                        } else if outcome.cycle_to.is_none_or(|c| k < c) {
                            // The cycle returns to a file further up: it is
                            // reported there.
                            outcome.cycle_to = Some(k);
                            outcome.cycle = cycle;
                        }
                    }
                    Found::Broken => {}
                }
            }
        }
        (out, outcome)
    }

    /// Reads, loads and checks the file one reference names.
    fn reference(
        &mut self,
        file: FileId,
        attr: &Named,
        location: Option<&Path>,
        chain: &[PathBuf],
        out: &mut Hierarchy,
    ) -> Option<Found> {
        let report = |out: &mut Hierarchy, code: Code, message: String| {
            out.diagnostics
                .push(Diagnostic::new(code, file, attr.span, message));
        };
        if attr.name.is_empty() {
            report(
                out,
                Code::SubgraphUnreadable,
                "`subgraph` names no file".into(),
            );
            return None;
        }
        let Some(location) = location else {
            report(
                out,
                Code::SubgraphUnreadable,
                format!(
                    "`{}` cannot be looked up: this graph is not saved in a folder",
                    attr.name
                ),
            );
            return None;
        };
        let target = normalize(&location.parent().unwrap_or(Path::new("")).join(&attr.name));
        let name = file_name(&target);
        if let Some(k) = chain.iter().position(|p| *p == target) {
            let mut cycle: Vec<String> = chain[k..].iter().map(|p| file_name(p)).collect();
            cycle.push(name);
            out.references.push(Reference {
                span: attr.span,
                location: target,
                readable: true,
            });
            return Some(Found::Cycle(k, cycle));
        }
        if chain.len() > MAX_DEPTH || self.budget == 0 {
            report(
                out,
                Code::SubgraphCycle,
                format!(
                    "`{}` is not followed: sub-graphs nest more than {MAX_DEPTH} deep or reference more than {MAX_REFERENCES} files",
                    attr.name
                ),
            );
            return None;
        }
        self.budget -= 1;
        if !self.reads.contains(&target) {
            self.reads.push(target.clone());
        }
        let source = match self.resolver.read(&target) {
            Ok(source) => source,
            Err(why) => {
                out.references.push(Reference {
                    span: attr.span,
                    location: target,
                    readable: false,
                });
                report(
                    out,
                    Code::SubgraphUnreadable,
                    format!("the sub-graph file `{}` cannot be read: {why}", attr.name),
                );
                return None;
            }
        };
        out.references.push(Reference {
            span: attr.span,
            location: target.clone(),
            readable: true,
        });
        let (child, load) = super::load_task_graph(source.file, &source.text);
        let mut errors: Vec<Diagnostic> = load.into_iter().filter(Diagnostic::is_error).collect();
        let Some(child) = child else {
            report(
                out,
                Code::SubgraphHasErrors,
                format!(
                    "`{}` is not a task graph{}",
                    attr.name,
                    first_error(&source.text, &errors)
                ),
            );
            return Some(Found::Broken);
        };
        if !errors.is_empty() {
            report(
                out,
                Code::SubgraphHasErrors,
                has_errors(attr, &source.text, &errors),
            );
            return Some(Found::Broken);
        }
        let mut inner_chain = chain.to_vec();
        inner_chain.push(target.clone());
        let (nested, outcome) = self.graph(&child, Some(&target), &inner_chain);
        if let Some(k) = outcome.cycle_to {
            return Some(Found::Cycle(k, outcome.cycle));
        }
        // The sub-graph's own problems, as if it were checked alone.
        errors.extend(nested.diagnostics.iter().filter(|d| d.is_error()).cloned());
        if errors.is_empty() {
            errors.extend(
                (self.check)(&child, &nested)
                    .into_iter()
                    .filter(Diagnostic::is_error),
            );
        }
        if !errors.is_empty() {
            report(
                out,
                Code::SubgraphHasErrors,
                has_errors(attr, &source.text, &errors),
            );
            return Some(Found::Broken);
        }
        Some(Found::Usable(Box::new((target, source, child, nested))))
    }
}

enum Found {
    Usable(Box<(PathBuf, SubgraphSource, TaskGraph, Hierarchy)>),
    /// A cycle returning to the file at this index of the chain, as file names.
    Cycle(usize, Vec<String>),
    /// Reported on the reference already.
    Broken,
}

fn has_errors(attr: &Named, text: &str, errors: &[Diagnostic]) -> String {
    let n = errors.len();
    format!(
        "the sub-graph `{}` has {n} error{} of its own{}",
        attr.name,
        if n == 1 { "" } else { "s" },
        first_error(text, errors)
    )
}

/// `; first: line 4: message`, pointing into the sub-graph's text.
fn first_error(text: &str, errors: &[Diagnostic]) -> String {
    let Some(first) = errors.iter().min_by_key(|d| d.span.start) else {
        return String::new();
    };
    let line = LineIndex::new(text)
        .line_col(text, first.span.start, ColumnUnit::Utf8)
        .line
        + 1;
    format!("; first, line {line}: {} {}", first.code, first.message)
}

/// The last component of a path, for messages.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// `a/./b/../c` → `a/c`, without touching the file system (so the same file
/// named two ways is recognised on a cycle; symbolic links are not followed,
/// [`MAX_DEPTH`] bounds what they could add).
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// The open ports of a graph's top level: `(task, port)` indexes of the data
/// ports that no channel of the level joins.
pub fn open_ports(graph: &TaskGraph) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (t, task) in graph.tasks.iter().enumerate() {
        for (p, port) in task.ports.iter().enumerate() {
            let joined = graph.channels.iter().any(|c| {
                let end = match port.dir {
                    Direction::Out => &c.src,
                    Direction::In => &c.dst,
                };
                end.task == task.name.name && end.port == port.name.name
            });
            if !joined {
                out.push((t, p));
            }
        }
    }
    out
}

/// Pairs the task's ports with the sub-graph's open ports by name and
/// direction, reporting every port left without its partner (E078).
fn match_ports(
    file: FileId,
    task: &Task,
    attr: &Named,
    location: &Path,
    child: &TaskGraph,
    diagnostics: &mut Vec<Diagnostic>,
) -> Option<Vec<PortLink>> {
    let open = open_ports(child);
    let name = file_name(location);
    let mut links = Vec::new();
    let mut used = vec![false; open.len()];
    let mut ok = true;
    let mut problem = |message: String, port: Option<Span>| {
        let mut d = Diagnostic::new(Code::SubgraphPortMismatch, file, attr.span, message);
        if let Some(span) = port {
            d.relate(span, "the task's port");
        }
        diagnostics.push(d);
    };
    let dir = |d: Direction| match d {
        Direction::In => "input",
        Direction::Out => "output",
    };
    for (outer, port) in task.ports.iter().enumerate() {
        let same_name: Vec<usize> = (0..open.len())
            .filter(|&i| {
                let (t, p) = open[i];
                child.tasks[t].ports[p].name.name == port.name.name
            })
            .collect();
        let qualified = |i: usize| {
            let (t, p) = open[i];
            format!(
                "`{}.{}`",
                child.tasks[t].name.name, child.tasks[t].ports[p].name.name
            )
        };
        match same_name.as_slice() {
            [] => {
                ok = false;
                let listed: Vec<String> = (0..open.len()).map(qualified).collect();
                let listed = if listed.is_empty() {
                    "it has none".to_string()
                } else {
                    format!("its open ports are {}", listed.join(", "))
                };
                problem(
                    format!(
                        "`{name}` has no open {} port `{}` for `{}.{}` to stand for ({listed})",
                        dir(port.dir),
                        port.name.name,
                        task.name.name,
                        port.name.name,
                    ),
                    Some(port.name.span),
                );
            }
            [i] => {
                let (t, p) = open[*i];
                let inner = &child.tasks[t].ports[p];
                if inner.dir != port.dir {
                    ok = false;
                    problem(
                        format!(
                            "`{}.{}` is an {}, but {} in `{name}` is an {}",
                            task.name.name,
                            port.name.name,
                            dir(port.dir),
                            qualified(*i),
                            dir(inner.dir)
                        ),
                        Some(port.name.span),
                    );
                } else {
                    used[*i] = true;
                    links.push(PortLink {
                        outer,
                        inner_task: t,
                        inner_port: p,
                    });
                }
            }
            many => {
                ok = false;
                for &i in many {
                    used[i] = true;
                }
                let names: Vec<String> = many.iter().map(|&i| qualified(i)).collect();
                problem(
                    format!(
                        "`{}.{}` could stand for several open ports of `{name}`: {}; give them different names",
                        task.name.name,
                        port.name.name,
                        names.join(", ")
                    ),
                    Some(port.name.span),
                );
            }
        }
    }
    for (i, &(t, p)) in open.iter().enumerate() {
        if used[i] {
            continue;
        }
        ok = false;
        let inner = &child.tasks[t].ports[p];
        problem(
            format!(
                "the open {} port `{}.{}` of `{name}` has no port `{}` on `{}`: nothing would {} it",
                dir(inner.dir),
                child.tasks[t].name.name,
                inner.name.name,
                inner.name.name,
                task.name.name,
                if inner.dir == Direction::In {
                    "feed"
                } else {
                    "drain"
                }
            ),
            None,
        );
    }
    ok.then_some(links)
}
