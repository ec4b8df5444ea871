//! A service task that runs a task graph ([`GraphService`]: a catalog
//! service implemented by `graph=`, SDF/L loop nodes opened): its inner
//! tasks as functions, and `run_graph`, one iteration of the graph's looped
//! schedule, which the service task runs at each call before the service's
//! time. D-type loops repeat their body exactly `loop_count` times; C-type
//! loops repeat it until their exit task sets the exit flag (checked after
//! each iteration, so the exit task's iteration completes), at most
//! `loop_count` times. Every inner firing is traced (`graph_fire`), and
//! every SDF/L loop's end with its iterations (`graph_loop`). In
//! `linux-sim` an exit task sets the flag in the iteration the scenario's
//! `loops` names for `graph/loop` (`semo_sim_loop_exit`); for `linux` its body is the user's
//! (the service task file is created once). The simulator runs the same
//! steps (`sim/engine/loops.rs`).

use super::c;
use crate::refine::{GraphService, GraphStep};
use std::fmt::Write;

/// The inner task functions and `run_graph` for `service`, placed before
/// the task's functions; `simulated`: the exit tasks ask the scenario.
pub(super) fn graph_runner(service: &GraphService, simulated: bool) -> String {
    let mut out = String::new();
    // target::check refuses a graph without a schedule before generation.
    let Ok(steps_of) = &service.steps else {
        return out;
    };
    let mut fired: Vec<&str> = Vec::new();
    let mut exits: Vec<(&str, &str)> = Vec::new();
    collect(steps_of, &mut fired, &mut exits);
    // Only a graph with loop nodes traces their ends (an unused static
    // function fails -Werror).
    let has_loops = has_loop_nodes(steps_of);
    let _ = writeln!(
        out,
        "/* Task graph `{}`, run by this service task: one iteration per call. */\n{}",
        c::comment(&service.graph),
        if has_loops {
            "#include <stdio.h>\n"
        } else {
            ""
        }
    );
    for task in &fired {
        let exit_of = exits.iter().find(|(t, _)| t == task).map(|(_, l)| *l);
        let _ = writeln!(out, "/* Inner task `{}`. */", c::comment(task));
        match exit_of {
            None => {
                let _ = writeln!(out, "static void inner_{}(void)\n{{", c::ident(task));
            }
            Some(_) => {
                let _ = writeln!(
                    out,
                    "/* The exit task of its convergent loop: true to set the exit flag. */\nstatic bool inner_{}(unsigned long iteration)\n{{",
                    c::ident(task)
                );
            }
        }
        let _ = writeln!(
            out,
            "    semo_trace(\"graph_fire\", \"graph\", {}, \"task\", {}, NULL);",
            c::string(&service.graph),
            c::string(task)
        );
        match (exit_of, simulated) {
            (None, true) => {}
            (None, false) => out.push_str("    /* TODO: the task's work. */\n"),
            (Some(l), true) => {
                let _ = writeln!(
                    out,
                    "    int64_t exit_at = semo_sim_loop_exit({});\n    return exit_at > 0 && (int64_t)iteration >= exit_at;",
                    c::string(&format!("{}/{l}", service.graph))
                );
            }
            (Some(_), false) => out.push_str(
                "    /* TODO: the task's work; true when the loop has converged. */\n    (void)iteration;\n    return false;\n",
            ),
        }
        out.push_str("}\n\n");
    }
    if has_loops {
        out.push_str("/* Traces the end of an SDF/L loop with the iterations it ran. */\nstatic void loop_ended(const char *loop, unsigned long iterations)\n{\n    char text[24];\n    snprintf(text, sizeof text, \"%lu\", iterations);\n");
        let _ = writeln!(
            out,
            "    semo_trace(\"graph_loop\", \"graph\", {}, \"loop\", loop, \"iterations\", text, NULL);\n}}\n",
            c::string(&service.graph)
        );
    }
    out.push_str(
        "/* One iteration of the graph's looped schedule. */\nstatic void run_graph(void)\n{\n",
    );
    let mut depth = 0;
    steps(&mut out, steps_of, 1, &mut depth, None);
    out.push_str("}\n\n");
    out
}

fn has_loop_nodes(steps: &[GraphStep]) -> bool {
    steps.iter().any(|s| match s {
        GraphStep::Fire { .. } => false,
        GraphStep::Repeat { body, .. } => has_loop_nodes(body),
        GraphStep::Loop { .. } => true,
    })
}

/// Every inner task fired, in first-firing order, and the exit tasks with
/// their loop's path.
fn collect<'s>(
    steps: &'s [GraphStep],
    fired: &mut Vec<&'s str>,
    exits: &mut Vec<(&'s str, &'s str)>,
) {
    for step in steps {
        match step {
            GraphStep::Fire { task, .. } => {
                if !fired.contains(&task.as_str()) {
                    fired.push(task);
                }
            }
            GraphStep::Repeat { body, .. } => collect(body, fired, exits),
            GraphStep::Loop {
                path,
                exit_task,
                body,
                convergent,
                ..
            } => {
                if let (true, Some(exit)) = (*convergent, exit_task) {
                    exits.push((exit, path));
                }
                collect(body, fired, exits);
            }
        }
    }
}

/// The statements of `steps` at `indent` levels; `exit` names the flag of
/// the innermost convergent loop and its exit task.
fn steps(
    out: &mut String,
    steps_of: &[GraphStep],
    indent: usize,
    depth: &mut usize,
    exit: Option<(&str, usize)>,
) {
    let pad = "    ".repeat(indent);
    for step in steps_of {
        match step {
            GraphStep::Fire { task, count } => {
                let call = match exit {
                    Some((exit_task, d)) if exit_task == task => format!(
                        "if (inner_{}(n{d}))\n{pad}    exit_flag{d} = true;",
                        c::ident(task)
                    ),
                    _ => format!("inner_{}();", c::ident(task)),
                };
                if *count == 1 {
                    let _ = writeln!(out, "{pad}{call}");
                } else {
                    *depth += 1;
                    let i = format!("i{depth}");
                    let call = call.replace('\n', "\n    ");
                    let _ = writeln!(
                        out,
                        "{pad}for (unsigned long {i} = 0; {i} < {count}; {i}++)\n{pad}    {call}"
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
                self::steps(out, body, indent + 1, depth, exit);
                let _ = writeln!(out, "{pad}}}");
            }
            GraphStep::Loop {
                path,
                convergent,
                loop_count,
                exit_task,
                body,
            } => {
                *depth += 1;
                let d = *depth;
                let kind = if *convergent { "C-type" } else { "D-type" };
                let _ = writeln!(out, "{pad}{{ /* {kind} loop `{}` */", c::comment(path));
                let inner_exit = match (convergent, exit_task) {
                    (true, Some(e)) => {
                        let _ = writeln!(out, "{pad}    bool exit_flag{d} = false;");
                        Some((e.as_str(), d))
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
                self::steps(out, body, indent + 2, depth, inner_exit);
                let _ = writeln!(
                    out,
                    "{pad}    }}\n{pad}    loop_ended({}, n{d});\n{pad}}}",
                    c::string(path)
                );
            }
        }
    }
}
