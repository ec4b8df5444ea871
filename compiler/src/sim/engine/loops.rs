//! A service task that runs a task graph, as `codegen/loops.rs` generates
//! it for `linux-sim`: when the call starts, one iteration of the graph's
//! looped schedule. Its channels are FIFOs of tokens kept from call to call
//! (initial tokens are 0); an inner firing takes its inputs, writes each
//! output token `k` as `(sum of the tokens read + k + 1) mod 1000`, is
//! traced (`graph_fire`, with the tokens read and written) and puts its
//! outputs; a loop node takes its inputs when it starts, gives each
//! iteration its share (distributing) or the same tokens (broadcasting),
//! keeps the last outputs its iterations gave and puts them when it ends
//! (`graph_loop`, with its iterations); a convergent loop stops after the
//! iteration in which its exit task sets the exit flag (the scenario's
//! `loops`), at most `loop_count` iterations; a task standing for a
//! sub-graph moves its inputs' tokens to the sub-graph's channels, runs one
//! iteration of the sub-graph's schedule and moves its outputs' back. A
//! channel short of tokens or
//! over its bound is traced (`graph_error`) and ends the run, where the
//! generated program aborts.
//!
//! A time-triggered inner task fires at most once per period, as the
//! generated `release_<n>` waits: its first firing in the robot's life
//! (a restart is a new life) starts when the iteration reaches it, each
//! later one at `max(reached, previous start + period)`, the iteration's
//! clock moving on to that start. The iteration is still computed when the
//! call starts (nothing outside the service task sees its channels), its
//! trace lines put out when due (`Event::GraphTrace`; `graph_fire`'s
//! `release` is the start), and the call's service time counts from the
//! iteration's end; a stop ends the call then (`Sim::stop_task`).

use super::{Event, Fields, Sim};
use crate::refine::protocol::GRAPH_TEXT_MAX;
use crate::refine::{GraphChannelId, GraphService, GraphStep, InnerTaskId, LoopPort};
use crate::sim::trace::TraceEvent;
use smallvec::smallvec;
use std::collections::{HashMap, VecDeque};
use std::rc::Rc;

/// One robot's service graphs: channels by service task, the last start
/// of each time-triggered task by (service task, inner task), and the
/// trace lines of an iteration under way not yet due, in time order.
#[derive(Clone, Debug, Default)]
pub(super) struct GraphState {
    channels: HashMap<String, Vec<VecDeque<i64>>>,
    starts: HashMap<(String, InnerTaskId), i64>,
    due: VecDeque<TraceEvent>,
}

impl GraphState {
    /// No graph has run (`explore.rs` then hashes no text).
    pub(super) fn is_empty(&self) -> bool {
        self.channels.is_empty() && self.starts.is_empty() && self.due.is_empty()
    }

    /// About the bytes it holds (`Sim::approx_bytes`).
    pub(super) fn approx_bytes(&self) -> usize {
        let channels: usize = self
            .channels
            .iter()
            .map(|(name, queues)| {
                64 + name.len() + queues.iter().map(|q| 32 + q.len() * 8).sum::<usize>()
            })
            .sum();
        channels
            + self
                .starts
                .iter()
                .map(|((task, _), _)| 48 + task.len())
                .sum::<usize>()
            + self.due.len() * std::mem::size_of::<TraceEvent>()
    }

    /// The state as text, its times relative to `now` (`explore.rs`).
    pub(super) fn relative(&self, now: i64) -> String {
        let mut channels: Vec<_> = self.channels.iter().collect();
        channels.sort_unstable_by(|a, b| a.0.cmp(b.0));
        let mut starts: Vec<_> = self
            .starts
            .iter()
            // By position, as before the index was typed: the same text.
            .map(|((task, inner), t)| ((task.clone(), inner.index()), t - now))
            .collect();
        starts.sort_unstable();
        let due: Vec<_> = self
            .due
            .iter()
            .map(|e| (e.t - now, e.robot, e.event, format!("{:?}", e.fields)))
            .collect();
        format!("{channels:?}{starts:?}{due:?}")
    }
}

/// A channel that is short of tokens or full: the run stops.
struct Broken;

impl Sim<'_> {
    /// `run_graph` of service task `task`, if it runs a graph: when its
    /// iteration ends (now, unless a time-triggered task waited).
    pub(super) fn run_graph(&mut self, r: usize, task: &str) -> i64 {
        let program = self.robots[r].program;
        // A graph without a schedule: warned on the call (W070, W071) and
        // refused by code generation; simulated as its call's time alone.
        let Some((service, steps)) = program
            .graph_services
            .iter()
            .find(|g| g.task == task)
            .and_then(|g| Some((g, g.steps.as_ref().ok()?)))
        else {
            return self.now;
        };
        let graph: Rc<str> = service.graph.as_str().into();
        let exits: Vec<(String, u64)> = self
            .scenario
            .robots
            .iter()
            .find(|w| w.robot == program.robot)
            .map(|w| w.loops.clone())
            .unwrap_or_default();
        let mut channels = self.robots[r]
            .graphs
            .channels
            .remove(task)
            .unwrap_or_else(|| {
                service
                    .channels
                    .iter()
                    .map(|c| std::iter::repeat_n(0, c.initial_tokens as usize).collect())
                    .collect()
            });
        let mut run = GraphRun {
            clock: self.now,
            scheduled: None,
            sim: self,
            robot: r,
            task,
            graph,
            service,
            exits: &exits,
            channels: &mut channels,
        };
        // A broken channel was traced; the generated program aborts there.
        let _ = run.steps(steps, None);
        let until = run.clock;
        self.robots[r]
            .graphs
            .channels
            .insert(task.to_string(), channels);
        until
    }

    /// `Event::GraphTrace`: the graph lines due by now.
    pub(super) fn graph_trace(&mut self, r: usize) {
        let now = self.now;
        let due = &mut self.robots[r].graphs.due;
        while due.front().is_some_and(|e| e.t <= now) {
            if let Some(line) = due.pop_front() {
                self.trace.push(line);
            }
        }
    }
}

struct GraphRun<'s, 'p> {
    sim: &'s mut Sim<'p>,
    robot: usize,
    /// The service task running the graph.
    task: &'s str,
    /// The iteration's time: the call's start, moved on by the waits of
    /// time-triggered tasks.
    clock: i64,
    /// The last time a `GraphTrace` event was scheduled for.
    scheduled: Option<i64>,
    graph: Rc<str>,
    service: &'p GraphService,
    exits: &'s [(String, u64)],
    channels: &'s mut Vec<VecDeque<i64>>,
}

/// The innermost convergent loop: its exit task, iteration and flag.
struct Exit {
    task: InnerTaskId,
    iteration: u64,
    at: u64,
    flag: bool,
}

/// Tokens as a trace field: comma separated, cut as the generated
/// `graph_text` cuts them.
fn text(tokens: &[i64]) -> Rc<str> {
    let mut out = tokens
        .iter()
        .map(i64::to_string)
        .collect::<Vec<_>>()
        .join(",");
    out.truncate(GRAPH_TEXT_MAX as usize - 1);
    out.into()
}

impl GraphRun<'_, '_> {
    /// A trace line at the iteration's time: now, or when it is due.
    fn emit(&mut self, event: &'static str, fields: Fields) {
        let line = TraceEvent {
            t: self.clock,
            robot: self.robot,
            event,
            fields,
            value: None,
            sent_at: None,
        };
        if self.clock <= self.sim.now {
            self.sim.trace.push(line);
            return;
        }
        // In time order with the lines of the robot's other graph services
        // (after those due at the same time).
        let due = &mut self.sim.robots[self.robot].graphs.due;
        let at = due.partition_point(|e| e.t <= line.t);
        due.insert(at, line);
        if self.scheduled != Some(self.clock) {
            self.scheduled = Some(self.clock);
            let epoch = self.sim.robots[self.robot].epoch;
            self.sim.schedule(
                self.clock,
                Event::GraphTrace {
                    robot: self.robot,
                    epoch,
                },
            );
        }
    }

    fn broken(&mut self, channel: GraphChannelId, what: &str) -> Broken {
        let label = self.service.channels[channel.index()].label.as_str();
        let fields = smallvec![
            ("graph", self.graph.clone()),
            ("channel", Rc::from(label)),
            ("error", Rc::from(what)),
        ];
        self.emit("graph_error", fields);
        Broken
    }

    fn take(&mut self, channel: GraphChannelId, n: u64, into: &mut Vec<i64>) -> Result<(), Broken> {
        for _ in 0..n {
            match self.channels[channel.index()].pop_front() {
                Some(token) => into.push(token),
                None => return Err(self.broken(channel, "is empty")),
            }
        }
        Ok(())
    }

    fn put(&mut self, channel: GraphChannelId, tokens: &[i64]) -> Result<(), Broken> {
        let capacity = self.service.channels[channel.index()].capacity as usize;
        for &token in tokens {
            if self.channels[channel.index()].len() >= capacity {
                return Err(self.broken(channel, "is full"));
            }
            self.channels[channel.index()].push_back(token);
        }
        Ok(())
    }

    fn fire(&mut self, index: InnerTaskId) -> Result<(), Broken> {
        let service = self.service;
        // Refinement lists every task it fires (code generation checks it,
        // `codegen::loops::check`).
        let Some(task) = service.tasks.get(index.index()) else {
            return Ok(());
        };
        let path = task.path.as_str();
        // A time-triggered task waits for its period (`release_<n>`).
        let release = task.period_ms.map(|period| {
            let key = (self.task.to_string(), index);
            let starts = &mut self.sim.robots[self.robot].graphs.starts;
            let start = match starts.get(&key) {
                Some(last) => self
                    .clock
                    .max(last.saturating_add(i64::try_from(period).unwrap_or(i64::MAX))),
                None => self.clock,
            };
            starts.insert(key, start);
            self.clock = start;
            start
        });
        let mut read = Vec::new();
        for port in &task.inputs {
            self.take(port.channel, port.rate, &mut read)?;
        }
        let sum = read
            .iter()
            .fold(0i64, |sum, t| (sum + t.rem_euclid(1000)) % 1000);
        let written: Vec<Vec<i64>> = task
            .outputs
            .iter()
            .map(|port| {
                (0..port.rate)
                    .map(|k| (sum + (k % 1000) as i64 + 1) % 1000)
                    .collect()
            })
            .collect();
        let wrote: Vec<i64> = written.iter().flatten().copied().collect();
        let mut fields = smallvec![
            ("graph", self.graph.clone()),
            ("task", Rc::from(path)),
            ("read", text(&read)),
            ("wrote", text(&wrote)),
        ];
        if let Some(start) = release {
            fields.push(("release", Rc::from(start.to_string().as_str())));
        }
        self.emit("graph_fire", fields);
        for (port, tokens) in task.outputs.iter().zip(&written) {
            self.put(port.channel, tokens)?;
        }
        Ok(())
    }

    fn steps(&mut self, steps: &[GraphStep], mut exit: Option<&mut Exit>) -> Result<(), Broken> {
        for step in steps {
            match step {
                GraphStep::Fire { task, count } => {
                    for _ in 0..*count {
                        self.fire(*task)?;
                        if let Some(e) = exit.as_deref_mut()
                            && e.task == *task
                            && e.at > 0
                            && e.iteration >= e.at
                        {
                            e.flag = true;
                        }
                    }
                }
                GraphStep::Repeat { count, body } => {
                    for _ in 0..*count {
                        self.steps(body, exit.as_deref_mut())?;
                    }
                }
                GraphStep::Loop {
                    path,
                    convergent,
                    loop_count,
                    exit_task,
                    ports,
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
                    let mut staged: Vec<Vec<i64>> = Vec::with_capacity(ports.len());
                    for port in ports {
                        let mut tokens = Vec::new();
                        if port.input {
                            self.take(port.outer, port.outer_rate, &mut tokens)?;
                        }
                        staged.push(tokens);
                    }
                    let mut n = 0;
                    let mut own = match (convergent, exit_task) {
                        (true, Some(task)) => Some(Exit {
                            task: *task,
                            iteration: 0,
                            at,
                            flag: false,
                        }),
                        _ => None,
                    };
                    while n < *loop_count && !own.as_ref().is_some_and(|e| e.flag) {
                        n += 1;
                        self.iteration_inputs(ports, &staged, n)?;
                        match own.as_mut() {
                            Some(e) => {
                                e.iteration = n;
                                self.steps(body, Some(e))?;
                            }
                            None => self.steps(body, exit.as_deref_mut())?,
                        }
                        for (port, kept) in ports.iter().zip(&mut staged) {
                            if !port.input {
                                let mut tokens = Vec::new();
                                self.take(port.inner, port.inner_rate, &mut tokens)?;
                                kept.extend(tokens);
                                let over = kept.len().saturating_sub(port.outer_rate as usize);
                                kept.drain(..over);
                            }
                        }
                    }
                    let fields = smallvec![
                        ("graph", self.graph.clone()),
                        ("loop", Rc::from(path.as_str())),
                        ("iterations", Rc::from(n.to_string().as_str())),
                    ];
                    self.emit("graph_loop", fields);
                    for (port, kept) in ports.iter().zip(&staged) {
                        if !port.input {
                            self.put(port.outer, kept)?;
                        }
                    }
                }
                GraphStep::Subgraph { ports, body, .. } => {
                    for port in ports.iter().filter(|p| p.input) {
                        self.move_tokens(port.outer, port.inner, port.rate)?;
                    }
                    self.steps(body, exit.as_deref_mut())?;
                    for port in ports.iter().filter(|p| !p.input) {
                        self.move_tokens(port.inner, port.outer, port.rate)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// `n` tokens from channel `from` to `to`, one at a time as the
    /// generated `graph_move` moves them.
    fn move_tokens(
        &mut self,
        from: GraphChannelId,
        to: GraphChannelId,
        n: u64,
    ) -> Result<(), Broken> {
        for _ in 0..n {
            let mut token = Vec::with_capacity(1);
            self.take(from, 1, &mut token)?;
            self.put(to, &token)?;
        }
        Ok(())
    }

    /// Each input's tokens for iteration `n` (from 1), as the generated
    /// loop gives them.
    fn iteration_inputs(
        &mut self,
        ports: &[LoopPort],
        staged: &[Vec<i64>],
        n: u64,
    ) -> Result<(), Broken> {
        for (port, tokens) in ports.iter().zip(staged).filter(|(p, _)| p.input) {
            for k in 0..port.inner_rate {
                let index = if port.distributing {
                    ((n - 1) * port.inner_rate + k) % port.outer_rate
                } else {
                    k % port.outer_rate
                };
                self.put(port.inner, &[tokens[index as usize]])?;
            }
        }
        Ok(())
    }
}
