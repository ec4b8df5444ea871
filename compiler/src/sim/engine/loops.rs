//! A service task that runs a task graph, as `codegen/loops.rs` generates
//! it: when the call starts, one iteration of the graph's looped schedule,
//! every inner firing traced (`graph_fire`) and every SDF/L loop's end with
//! its iterations (`graph_loop`); a convergent loop stops after the
//! iteration in which its exit task sets the exit flag (the scenario's
//! `loops`), at most `loop_count` iterations.

use super::Sim;
use crate::refine::GraphStep;
use std::rc::Rc;

impl Sim<'_> {
    /// `run_graph` of service task `task`, if it runs a graph.
    pub(super) fn run_graph(&mut self, r: usize, task: &str) {
        let program = self.robots[r].program;
        // A graph without a schedule: warned on the call (W070, W071) and
        // refused by code generation; simulated as its call's time alone.
        let Some((service, steps)) = program
            .graph_services
            .iter()
            .find(|g| g.task == task)
            .and_then(|g| Some((g, g.steps.as_ref().ok()?)))
        else {
            return;
        };
        let graph: Rc<str> = service.graph.as_str().into();
        let exits: Vec<(String, u64)> = self
            .scenario
            .robots
            .iter()
            .find(|w| w.robot == program.robot)
            .map(|w| w.loops.clone())
            .unwrap_or_default();
        let mut run = GraphRun {
            sim: self,
            robot: r,
            graph,
            exits: &exits,
        };
        run.steps(steps, None);
    }
}

struct GraphRun<'s, 'p> {
    sim: &'s mut Sim<'p>,
    robot: usize,
    graph: Rc<str>,
    exits: &'s [(String, u64)],
}

/// The innermost convergent loop: its exit task, iteration and flag.
struct Exit<'a> {
    task: &'a str,
    iteration: u64,
    at: u64,
    flag: bool,
}

impl GraphRun<'_, '_> {
    fn fire(&mut self, task: &str) {
        let fields = vec![("graph", self.graph.clone()), ("task", Rc::from(task))];
        self.sim.emit(self.robot, "graph_fire", fields);
    }

    fn steps(&mut self, steps: &[GraphStep], mut exit: Option<&mut Exit<'_>>) {
        for step in steps {
            match step {
                GraphStep::Fire { task, count } => {
                    for _ in 0..*count {
                        self.fire(task);
                        if let Some(e) = exit.as_deref_mut()
                            && e.task == task
                            && e.at > 0
                            && e.iteration >= e.at
                        {
                            e.flag = true;
                        }
                    }
                }
                GraphStep::Repeat { count, body } => {
                    for _ in 0..*count {
                        self.steps(body, exit.as_deref_mut());
                    }
                }
                GraphStep::Loop {
                    path,
                    convergent,
                    loop_count,
                    exit_task,
                    body,
                } => {
                    let at = self
                        .exits
                        .iter()
                        .find(|(p, _)| {
                            p.strip_prefix(&*self.graph)
                                .and_then(|p| p.strip_prefix('/'))
                                == Some(path.as_str())
                        })
                        .map_or(0, |(_, n)| *n);
                    let mut n = 0;
                    match (convergent, exit_task) {
                        (true, Some(task)) => {
                            let mut own = Exit {
                                task,
                                iteration: 0,
                                at,
                                flag: false,
                            };
                            while n < *loop_count && !own.flag {
                                n += 1;
                                own.iteration = n;
                                self.steps(body, Some(&mut own));
                            }
                        }
                        _ => {
                            while n < *loop_count {
                                n += 1;
                                self.steps(body, exit.as_deref_mut());
                            }
                        }
                    }
                    let fields = vec![
                        ("graph", self.graph.clone()),
                        ("loop", Rc::from(path.as_str())),
                        ("iterations", Rc::from(n.to_string().as_str())),
                    ];
                    self.sim.emit(self.robot, "graph_loop", fields);
                }
            }
        }
    }
}
