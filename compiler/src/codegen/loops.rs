//! A service task that runs a task graph ([`GraphService`]: a catalog
//! service implemented by `graph=`, SDF/L loop nodes opened): its channels,
//! its inner tasks as functions, and `run_graph`, one iteration of the
//! graph's looped schedule, which the service task runs at each call before
//! the service's time.
//!
//! Each channel is a FIFO of tokens (`semo_value`) in a static ring of the
//! analysis's buffer bound ([`GraphChannel::capacity`]), kept from call to
//! call (a channel's initial tokens are the integer 0); a firing short of
//! tokens or over the bound is a generator bug, traced (`graph_error`) and
//! aborted. An inner task takes its inputs' tokens, runs its work function
//! (`work_<n>_<task>`: its inputs and outputs as arrays, one parameter per
//! port; the outputs start as the integer 0), traces `graph_fire` with the
//! tokens it read and wrote, and puts its outputs. In `linux-sim` the work
//! is the simulator's (`sim/engine/loops.rs`): every output token `k` of a
//! port is `(sum of the tokens read + k + 1) mod 1000`; for `linux` its body
//! is the user's (the service task file is created once).
//!
//! A task standing for a sub-graph file fires as one iteration of the
//! sub-graph's schedule: its inputs' tokens move to the channels joining
//! the sub-graph's open ports of the same names before it, its outputs'
//! back after it (`graph_move`); the sub-graph's tasks are inner tasks like
//! the others (`graph_fire`, their path below the task: `Track/Predict`).
//!
//! A time-triggered inner task ([`InnerTask::period_ms`]) fires at most
//! once per period: before each of its firings the service task waits
//! (`release_<n>`) until its previous firing's start + the period, the
//! first firing in the program's life at once, and traces the firing's
//! start (`graph_fire`'s `release`); so a call waits as long as its
//! iteration's firings need. A stop request does not cut an iteration (its
//! channels must hold the next call's tokens): the call ends when the
//! iteration does, without its service time; the program stopping abandons
//! it. `sim/engine/loops.rs` times the firings by the same rule.
//!
//! Port arrays (a firing's tokens, a loop's staged tokens) are static:
//! each is no larger than the channel it fills or drains ([`check`]), and
//! refinement bounds the channels' tokens (`MAX_GRAPH_TOKENS`), so the
//! service task's stack does not grow with the graph's rates.
//!
//! D-type loops repeat their body exactly `loop_count` times; C-type loops
//! repeat it until their exit task sets the exit flag (checked after each
//! iteration, so the exit task's iteration completes), at most `loop_count`
//! times. A loop node takes its inputs' tokens when it starts, gives each
//! iteration its share (distributing) or the same tokens (broadcasting),
//! takes its body's outputs after each iteration and puts the last ones
//! when it ends ([`LoopPort`]); its end is traced with its iterations
//! (`graph_loop`). In `linux-sim` an exit task sets the flag in the
//! iteration the scenario's `loops` names for `graph/loop`
//! (`semo_sim_loop_exit`).

use super::c;
use super::template::{Template, fill, template};
use crate::refine::protocol::GRAPH_TEXT_MAX;
use crate::refine::{
    GraphChannelId, GraphService, GraphStep, InnerTask, InnerTaskId, LoopPort, PortUse,
    SubgraphPort,
};
use std::fmt::Write;

/// Characters a token takes in a trace field, at most, for sizing: an
/// integer and its comma.
const TOKEN_TEXT: u64 = 24;

/// The channels, inner task functions and `run_graph` for `service`, placed
/// before the task's functions; `simulated`: the work is the simulator's and
/// the exit tasks ask the scenario.
pub(super) fn graph_runner(service: &GraphService, simulated: bool) -> String {
    let mut out = String::new();
    // target::check refuses a graph without a schedule before generation.
    let Ok(steps_of) = &service.steps else {
        return out;
    };
    let mut exits: Vec<(InnerTaskId, &str)> = Vec::new();
    collect_exits(steps_of, &mut exits);
    let graph = c::string(&service.graph);
    let has_loops = has_loop_nodes(steps_of);
    let any_port = service
        .tasks
        .iter()
        .any(|t| !t.inputs.is_empty() || !t.outputs.is_empty());
    let keeps = has_loop_outputs(steps_of);
    let _ = writeln!(
        out,
        "/* Task graph `{}`, run by this service task: one iteration per call. */",
        c::comment(&service.graph)
    );
    let periodic = service.tasks.iter().any(|t| t.period_ms.is_some());
    if has_loops || periodic || !service.channels.is_empty() {
        out.push_str("#include <stdio.h>\n");
    }
    if !service.channels.is_empty() {
        out.push_str("#include <stdlib.h>\n");
    }
    if any_port || keeps {
        out.push_str("#include <string.h>\n");
    }
    out.push('\n');
    channels(
        &mut out,
        service,
        &graph,
        any_port,
        keeps,
        has_subgraphs(steps_of),
    );
    for (index, task) in InnerTaskId::all(service.tasks.len()).zip(&service.tasks) {
        let exit_of = exits.iter().find(|(t, _)| *t == index).map(|(_, l)| *l);
        if let Some(period) = task.period_ms {
            release(&mut out, service, index, task, period);
        }
        inner_task(&mut out, service, index, task, exit_of, simulated, &graph);
    }
    if has_loops {
        out.push_str(&fill(&LOOP_ENDED, &[("graph", &graph)]));
    }
    out.push_str(
        "/* One iteration of the graph's looped schedule. */\nstatic void run_graph(void)\n{\n",
    );
    let mut depth = 0;
    steps(&mut out, service, steps_of, 1, &mut depth, None);
    out.push_str("}\n\n");
    out
}

/// The ring of tokens of a channel between inner tasks.
const GRAPH_CHANNEL: Template = template!("loops/graph_channel.c.in", []);
/// `graph_broken`, `graph_take` and `graph_put` (every graph with channels).
const GRAPH_TAKE_PUT: Template = template!("loops/graph_take_put.c.in", ["graph"]);
const GRAPH_MOVE: Template = template!("loops/graph_move.c.in", []);
const GRAPH_TEXT: Template = template!("loops/graph_text.c.in", ["max"]);
const GRAPH_KEEP: Template = template!("loops/graph_keep.c.in", []);
const LOOP_ENDED: Template = template!("loops/loop_ended.c.in", ["graph"]);
/// The head of an inner task's work function.
const WORK_HEAD: Template = template!(
    "loops/work_head.c.in",
    [
        "path",
        "reads",
        "writes",
        "exit",
        "returns",
        "name",
        "signature"
    ]
);
/// A time-triggered inner task's release.
const RELEASE: Template = template!("loops/release.c.in", ["path", "period", "name"]);

/// Every template of a graph service's runner.
#[cfg(test)]
pub(super) const TEMPLATES: &[Template] = &[
    GRAPH_CHANNEL,
    GRAPH_TAKE_PUT,
    GRAPH_MOVE,
    GRAPH_TEXT,
    GRAPH_KEEP,
    LOOP_ENDED,
    RELEASE,
    WORK_HEAD,
];

/// The channel rings and the helpers that move tokens (each written only
/// when used: an unused static function fails -Werror).
fn channels(
    out: &mut String,
    service: &GraphService,
    graph: &str,
    any_port: bool,
    keeps: bool,
    moves: bool,
) {
    if service.channels.is_empty() {
        return;
    }
    out.push_str(GRAPH_CHANNEL.text);
    for (i, ch) in service.channels.iter().enumerate() {
        let initial = if ch.initial_tokens > 0 {
            let zeros = vec!["{.type = SEMO_INT}"; ch.initial_tokens.min(ch.capacity) as usize];
            format!(" = {{{}}}", zeros.join(", "))
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "static semo_value channel{i}_token[{}]{initial}; /* {} */",
            ch.capacity,
            c::comment(&ch.label)
        );
    }
    let _ = writeln!(
        out,
        "static graph_channel channel[{}] = {{",
        service.channels.len()
    );
    for (i, ch) in service.channels.iter().enumerate() {
        let _ = writeln!(
            out,
            "    {{channel{i}_token, {}, 0, {}, {}}},",
            ch.capacity,
            ch.initial_tokens,
            c::string(&ch.label)
        );
    }
    out.push_str("};\n\n");
    out.push_str(&fill(&GRAPH_TAKE_PUT, &[("graph", &graph)]));
    if moves {
        out.push_str(GRAPH_MOVE.text);
    }
    if any_port {
        out.push_str(&fill(&GRAPH_TEXT, &[("max", &(GRAPH_TEXT_MAX - 1))]));
    }
    if keeps {
        out.push_str(GRAPH_KEEP.text);
    }
}

fn param(port: &PortUse, input: bool) -> String {
    format!(
        "{}_{}",
        if input { "in" } else { "out" },
        c::ident(&port.port)
    )
}

/// Bytes of a trace field for `ports`' tokens.
fn text_size(ports: &[PortUse]) -> u64 {
    let tokens: u64 = ports.iter().map(|p| p.rate).sum();
    tokens
        .saturating_mul(TOKEN_TEXT)
        .saturating_add(1)
        .min(GRAPH_TEXT_MAX)
}

/// The release of time-triggered inner task `task` (`release_<n>`, called
/// before each of its firings): its first firing in the program's life
/// starts at once, each later one no earlier than `period` ms after the
/// previous one's start; the start is kept for the trace (`release`). A stop
/// request does not cut the wait (an iteration is never left half run: its
/// channels would not hold the next call's tokens); the program stopping
/// does, and the iteration is abandoned (false).
fn release(
    out: &mut String,
    service: &GraphService,
    index: InnerTaskId,
    task: &InnerTask,
    period: u64,
) {
    let name = task_name(service, index);
    out.push_str(&fill(
        &RELEASE,
        &[
            ("path", &c::comment(&task.path)),
            ("period", &period),
            ("name", &name),
        ],
    ));
}

/// The work function of inner task `task` and its firing, `inner_<n>`.
fn inner_task(
    out: &mut String,
    service: &GraphService,
    index: InnerTaskId,
    task: &InnerTask,
    exit_of: Option<&str>,
    simulated: bool,
    graph: &str,
) {
    let name = task_name(service, index);
    let ports: Vec<(&PortUse, bool)> = task
        .inputs
        .iter()
        .map(|p| (p, true))
        .chain(task.outputs.iter().map(|p| (p, false)))
        .collect();
    let mut params: Vec<String> = ports
        .iter()
        .map(|(p, input)| {
            format!(
                "{}semo_value *{}",
                if *input { "const " } else { "" },
                param(p, *input)
            )
        })
        .collect();
    if exit_of.is_some() {
        params.insert(0, "unsigned long iteration".into());
    }
    let signature = if params.is_empty() {
        "void".to_string()
    } else {
        params.join(", ")
    };
    let returns = if exit_of.is_some() { "bool" } else { "void" };
    let rates = |ports: &[PortUse]| {
        ports
            .iter()
            .map(|p| format!("{}[{}]", c::comment(&p.port), p.rate))
            .collect::<Vec<_>>()
            .join(", ")
    };
    out.push_str(&fill(
        &WORK_HEAD,
        &[
            ("path", &c::comment(&task.path)),
            (
                "reads",
                &if task.inputs.is_empty() {
                    "nothing".into()
                } else {
                    rates(&task.inputs)
                },
            ),
            (
                "writes",
                &if task.outputs.is_empty() {
                    "nothing".into()
                } else {
                    rates(&task.outputs)
                },
            ),
            (
                "exit",
                &if exit_of.is_some() {
                    " The exit task of its convergent loop: true to set the exit flag."
                } else {
                    ""
                },
            ),
            ("returns", &returns),
            ("name", &name),
            ("signature", &signature),
        ],
    ));
    for (p, input) in &ports {
        let _ = writeln!(out, "    (void){};", param(p, *input));
    }
    match (simulated, exit_of) {
        (true, _) => {
            if !task.outputs.is_empty() {
                out.push_str("    /* The simulator's work: (sum of the tokens read + k + 1) mod 1000. */\n    int64_t sum = 0;\n");
                for p in &task.inputs {
                    let _ = writeln!(
                        out,
                        "    for (unsigned long k = 0; k < {}; k++)\n        sum = (sum + ({v}[k].type == SEMO_INT ? ({v}[k].i % 1000 + 1000) % 1000 : 0)) % 1000;",
                        p.rate,
                        v = param(p, true)
                    );
                }
                for p in &task.outputs {
                    let _ = writeln!(
                        out,
                        "    for (unsigned long k = 0; k < {}; k++)\n        semo_value_set_int(&{}[k], (sum + (int64_t)(k % 1000) + 1) % 1000);",
                        p.rate,
                        param(p, false)
                    );
                }
            }
            if let Some(l) = exit_of {
                let _ = writeln!(
                    out,
                    "    int64_t exit_at = semo_sim_loop_exit({});\n    return exit_at > 0 && (int64_t)iteration >= exit_at;",
                    c::string(&format!("{}/{l}", service.graph))
                );
            }
        }
        (false, None) => out.push_str("    /* TODO: the task's work. */\n"),
        (false, Some(_)) => out.push_str(
            "    /* TODO: the task's work; true when the loop has converged. */\n    (void)iteration;\n    return false;\n",
        ),
    }
    out.push_str("}\n\n");
    // The firing: take, work, trace, put.
    let _ = writeln!(
        out,
        "/* A firing of inner task `{}`. */\nstatic {returns} inner_{name}({})\n{{",
        c::comment(&task.path),
        if exit_of.is_some() {
            "unsigned long iteration"
        } else {
            "void"
        }
    );
    // Static, not on the stack: a port array is no larger than its
    // channel, and refinement bounds the channels' tokens
    // (`MAX_GRAPH_TOKENS`); the one service task runs its graph, never
    // re-entered.
    for (p, input) in &ports {
        let _ = writeln!(
            out,
            "    static semo_value {}[{}];",
            param(p, *input),
            p.rate
        );
    }
    let texts = [("read", &task.inputs), ("wrote", &task.outputs)];
    for (field, ports) in texts {
        if !ports.is_empty() {
            let _ = writeln!(out, "    char {field}[{}] = \"\";", text_size(ports));
        }
    }
    for p in &task.inputs {
        let _ = writeln!(
            out,
            "    graph_take(&channel[{}], {1}, {2});\n    graph_text(read, sizeof read, {1}, {2});",
            p.channel,
            param(p, true),
            p.rate
        );
    }
    for p in &task.outputs {
        let _ = writeln!(
            out,
            "    for (unsigned long k = 0; k < {}; k++)\n        semo_value_set_int(&{}[k], 0);",
            p.rate,
            param(p, false)
        );
    }
    let mut args: Vec<String> = ports.iter().map(|(p, input)| param(p, *input)).collect();
    if exit_of.is_some() {
        args.insert(0, "iteration".into());
        let _ = writeln!(out, "    bool exit = work_{name}({});", args.join(", "));
    } else {
        let _ = writeln!(out, "    work_{name}({});", args.join(", "));
    }
    for p in &task.outputs {
        let _ = writeln!(
            out,
            "    graph_text(wrote, sizeof wrote, {}, {});",
            param(p, false),
            p.rate
        );
    }
    let text_of = |field: &str, ports: &[PortUse]| {
        if ports.is_empty() {
            "\"\"".to_string()
        } else {
            field.to_string()
        }
    };
    let released = match task.period_ms {
        Some(_) => {
            let _ = writeln!(
                out,
                "    char released[24];\n    snprintf(released, sizeof released, \"%lld\", (long long)start_{name});"
            );
            ", \"release\", released"
        }
        None => "",
    };
    let _ = writeln!(
        out,
        "    semo_trace(\"graph_fire\", \"graph\", {graph}, \"task\", {}, \"read\", {}, \"wrote\", {}{released}, NULL);",
        c::string(&task.path),
        text_of("read", &task.inputs),
        text_of("wrote", &task.outputs)
    );
    for p in &task.outputs {
        let _ = writeln!(
            out,
            "    graph_put(&channel[{}], {}, {});",
            p.channel,
            param(p, false),
            p.rate
        );
    }
    if exit_of.is_some() {
        out.push_str("    return exit;\n");
    }
    out.push_str("}\n\n");
}

/// What generation relies on in a graph refinement opened: every step
/// names a task it lists, every port array fits the channel it fills or
/// drains (a failure is an internal error, E102).
pub(super) fn check(service: &GraphService) -> Result<(), String> {
    let Ok(steps_of) = &service.steps else {
        return Ok(());
    };
    let capacity =
        |channel: GraphChannelId| service.channels.get(channel.index()).map(|c| c.capacity);
    for task in &service.tasks {
        for p in task.inputs.iter().chain(&task.outputs) {
            if capacity(p.channel).is_none_or(|c| p.rate > c) {
                return Err(format!(
                    "port `{}.{}` takes {} tokens from channel {} that holds fewer",
                    task.path, p.port, p.rate, p.channel
                ));
            }
        }
    }
    fn walk(
        steps: &[GraphStep],
        tasks: usize,
        capacity: &dyn Fn(GraphChannelId) -> Option<u64>,
    ) -> Result<(), String> {
        for step in steps {
            match step {
                GraphStep::Fire { task, .. } if task.index() >= tasks => {
                    return Err(format!("a firing names task {task} of {tasks}"));
                }
                GraphStep::Fire { .. } => {}
                GraphStep::Repeat { body, .. } => walk(body, tasks, capacity)?,
                GraphStep::Loop {
                    path,
                    exit_task,
                    ports,
                    body,
                    ..
                } => {
                    if exit_task.is_some_and(|e| e.index() >= tasks) {
                        return Err(format!("loop `{path}` names exit task out of {tasks}"));
                    }
                    for p in ports {
                        let fits = capacity(p.outer).is_some_and(|c| p.outer_rate <= c)
                            && capacity(p.inner).is_some_and(|c| p.inner_rate <= c);
                        if !fits {
                            return Err(format!(
                                "loop port `{path}.{}` overflows its channels",
                                p.port
                            ));
                        }
                    }
                    walk(body, tasks, capacity)?;
                }
                GraphStep::Subgraph { path, ports, body } => {
                    for p in ports {
                        let fits = [p.outer, p.inner]
                            .iter()
                            .all(|&c| capacity(c).is_some_and(|c| p.rate <= c));
                        if !fits {
                            return Err(format!(
                                "sub-graph port `{path}.{}` overflows its channels",
                                p.port
                            ));
                        }
                    }
                    walk(body, tasks, capacity)?;
                }
            }
        }
        Ok(())
    }
    walk(steps_of, service.tasks.len(), &capacity)
}

fn has_loop_nodes(steps: &[GraphStep]) -> bool {
    steps.iter().any(|s| match s {
        GraphStep::Fire { .. } => false,
        GraphStep::Repeat { body, .. } | GraphStep::Subgraph { body, .. } => has_loop_nodes(body),
        GraphStep::Loop { .. } => true,
    })
}

fn has_subgraphs(steps: &[GraphStep]) -> bool {
    steps.iter().any(|s| match s {
        GraphStep::Fire { .. } => false,
        GraphStep::Repeat { body, .. } | GraphStep::Loop { body, .. } => has_subgraphs(body),
        GraphStep::Subgraph { .. } => true,
    })
}

fn has_loop_outputs(steps: &[GraphStep]) -> bool {
    steps.iter().any(|s| match s {
        GraphStep::Fire { .. } => false,
        GraphStep::Repeat { body, .. } | GraphStep::Subgraph { body, .. } => has_loop_outputs(body),
        GraphStep::Loop { ports, body, .. } => {
            ports.iter().any(|p| !p.input) || has_loop_outputs(body)
        }
    })
}

/// The exit tasks of convergent loops (their index), with their loop's path.
fn collect_exits<'s>(steps: &'s [GraphStep], exits: &mut Vec<(InnerTaskId, &'s str)>) {
    for step in steps {
        match step {
            GraphStep::Fire { .. } => {}
            GraphStep::Repeat { body, .. } | GraphStep::Subgraph { body, .. } => {
                collect_exits(body, exits)
            }
            GraphStep::Loop {
                path,
                exit_task,
                body,
                convergent,
                ..
            } => {
                if let (true, Some(exit)) = (*convergent, exit_task) {
                    exits.push((*exit, path));
                }
                collect_exits(body, exits);
            }
        }
    }
}

/// The C name of inner task `index`'s firing function (refinement lists
/// every task it fires: `target::check` refuses a graph that names another
/// as an internal error before generation).
fn firing(service: &GraphService, index: InnerTaskId) -> String {
    format!("inner_{}", task_name(service, index))
}

/// The name inner task `index` goes by in C (`<n>_<path>`): its firing is
/// `inner_<name>`, a time-triggered one's release `release_<name>`.
fn task_name(service: &GraphService, index: InnerTaskId) -> String {
    let path = service
        .tasks
        .get(index.index())
        .map_or("", |t| t.path.as_str());
    format!("{index}_{}", c::ident(path))
}

/// The statements of `steps` at `indent` levels; `exit` names the flag of
/// the innermost convergent loop and its exit task.
fn steps(
    out: &mut String,
    service: &GraphService,
    steps_of: &[GraphStep],
    indent: usize,
    depth: &mut usize,
    exit: Option<(InnerTaskId, usize)>,
) {
    let pad = "    ".repeat(indent);
    for step in steps_of {
        match step {
            GraphStep::Fire { task, count } => {
                let function = firing(service, *task);
                let mut call = match exit {
                    Some((exit_task, d)) if exit_task == *task => {
                        format!("if ({function}(n{d}))\n{pad}    exit_flag{d} = true;")
                    }
                    _ => format!("{function}();"),
                };
                // A time-triggered task waits for its release; the program
                // stopping abandons the iteration.
                let periodic = service
                    .tasks
                    .get(task.index())
                    .is_some_and(|t| t.period_ms.is_some());
                if periodic {
                    call = format!(
                        "if (!release_{}())\n{pad}    return;\n{pad}{call}",
                        task_name(service, *task)
                    );
                }
                if *count == 1 {
                    let _ = writeln!(out, "{pad}{call}");
                } else {
                    *depth += 1;
                    let i = format!("i{depth}");
                    let call = call.replace('\n', "\n    ");
                    let (open, close) = match periodic {
                        true => (" {", format!("\n{pad}}}")),
                        false => ("", String::new()),
                    };
                    let _ = writeln!(
                        out,
                        "{pad}for (unsigned long {i} = 0; {i} < {count}; {i}++){open}\n{pad}    {call}{close}"
                    );
                }
            }
            GraphStep::Repeat { count, body } => {
                *depth += 1;
                let i = format!("i{depth}");
                let _ = writeln!(
                    out,
                    "{pad}for (unsigned long {i} = 0; {i} < {count}; {i}++) {{"
                );
                self::steps(out, service, body, indent + 1, depth, exit);
                let _ = writeln!(out, "{pad}}}");
            }
            GraphStep::Loop {
                path,
                convergent,
                loop_count,
                exit_task,
                ports,
                body,
            } => {
                *depth += 1;
                let d = *depth;
                let kind = if *convergent { "C-type" } else { "D-type" };
                let _ = writeln!(out, "{pad}{{ /* {kind} loop `{}` */", c::comment(path));
                loop_start(out, &pad, d, ports);
                let inner_exit = match (convergent, exit_task) {
                    (true, Some(e)) => {
                        let _ = writeln!(out, "{pad}    bool exit_flag{d} = false;");
                        Some((*e, d))
                    }
                    _ => exit,
                };
                let until = if inner_exit.is_some_and(|(_, x)| x == d) {
                    format!(" && !exit_flag{d}")
                } else {
                    String::new()
                };
                let _ = writeln!(
                    out,
                    "{pad}    unsigned long n{d} = 0;\n{pad}    while (n{d} < {loop_count}{until}) {{\n{pad}        n{d}++;"
                );
                iteration_inputs(out, &pad, d, ports);
                self::steps(out, service, body, indent + 2, depth, inner_exit);
                for (j, p) in ports.iter().enumerate().filter(|(_, p)| !p.input) {
                    let _ = writeln!(
                        out,
                        "{pad}        graph_keep(&channel[{}], loop{d}_port{j}, {}, &held{d}_port{j}, {});",
                        p.inner, p.outer_rate, p.inner_rate
                    );
                }
                let _ = writeln!(
                    out,
                    "{pad}    }}\n{pad}    loop_ended({}, n{d});",
                    c::string(path)
                );
                for (j, p) in ports.iter().enumerate().filter(|(_, p)| !p.input) {
                    let _ = writeln!(
                        out,
                        "{pad}    graph_put(&channel[{}], loop{d}_port{j}, {});",
                        p.outer, p.outer_rate
                    );
                }
                let _ = writeln!(out, "{pad}}}");
            }
            GraphStep::Subgraph { path, ports, body } => {
                let _ = writeln!(out, "{pad}{{ /* sub-graph `{}` */", c::comment(path));
                subgraph_moves(out, &pad, ports, true);
                self::steps(out, service, body, indent + 1, depth, exit);
                subgraph_moves(out, &pad, ports, false);
                let _ = writeln!(out, "{pad}}}");
            }
        }
    }
}

/// A sub-graph task's inputs' tokens moved in, or its outputs' out.
fn subgraph_moves(out: &mut String, pad: &str, ports: &[SubgraphPort], input: bool) {
    for p in ports.iter().filter(|p| p.input == input) {
        let (from, to) = if input {
            (p.outer, p.inner)
        } else {
            (p.inner, p.outer)
        };
        let _ = writeln!(
            out,
            "{pad}    graph_move(&channel[{from}], &channel[{to}], {}); /* {} */",
            p.rate,
            c::comment(&p.port)
        );
    }
}

/// A loop node's start: its inputs' tokens taken, room for its outputs'.
fn loop_start(out: &mut String, pad: &str, d: usize, ports: &[LoopPort]) {
    for (j, p) in ports.iter().enumerate() {
        // Static as the firings' port arrays are (`inner_task`).
        let _ = writeln!(
            out,
            "{pad}    static semo_value loop{d}_port{j}[{}]; /* {} */",
            p.outer_rate,
            c::comment(&p.port)
        );
        if p.input {
            let _ = writeln!(
                out,
                "{pad}    graph_take(&channel[{}], loop{d}_port{j}, {});",
                p.outer, p.outer_rate
            );
        } else {
            let _ = writeln!(out, "{pad}    unsigned long held{d}_port{j} = 0;");
        }
    }
}

/// Each input's tokens for iteration `n{d}` (from 1).
fn iteration_inputs(out: &mut String, pad: &str, d: usize, ports: &[LoopPort]) {
    for (j, p) in ports.iter().enumerate().filter(|(_, p)| p.input) {
        let index = if p.distributing {
            format!("((n{d} - 1) * {} + k) % {}", p.inner_rate, p.outer_rate)
        } else {
            format!("k % {}", p.outer_rate)
        };
        let _ = writeln!(
            out,
            "{pad}        for (unsigned long k = 0; k < {}; k++)\n{pad}            graph_put(&channel[{}], &loop{d}_port{j}[{index}], 1);",
            p.inner_rate, p.inner
        );
    }
}
