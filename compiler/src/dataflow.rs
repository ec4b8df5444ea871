//! Dataflow warnings of a mission (taskgraph.md's "SDF consistency
//! warnings", while editing the mission): the refined per-robot graphs are
//! analysed, and what the analyses find is reported on the mission lines
//! that caused it.
//!
//! A robot's refined graph (`refine::graph`) joins its control task to the
//! tasks implementing the services it calls, one request per call. A catalog
//! service implemented by a task graph (`graph="…"`) stands for that graph:
//! each call runs one iteration of it. The refined graph's own channels are
//! rate-1 and checked by refinement (E102); what can go wrong is inside the
//! service graphs, and it matters where the mission calls them:
//!
//! - W070: the graph's sample rates are inconsistent (no iteration exists);
//! - W071: the graph deadlocks (an iteration never completes);
//! - W072: a channel of the graph holds fewer samples than its schedule needs;
//! - W073: the graph's iteration period (its throughput, exact, one firing
//!   of a task at a time as generated) is longer than the period the mission
//!   asks for around the call (`repeat(P)` of its service, or the innermost
//!   `loop(P)` holding it): the robot cannot keep up;
//! - W074: the graph's latency from one of its tasks to another (a sensor's
//!   sample to the actuator's command it causes) is over the bound the
//!   catalog states on the service (`<Latency>`); W075: such a bound cannot
//!   be checked, and why ([`latency`]).
//!
//! Execution times (`wcet`) of the service graphs count milliseconds of
//! mission time, the unit a mission's periods are compared in. A
//! time-triggered task fires at most once per period, so a graph's
//! iteration period is also at least, for each of them, its firings per
//! iteration × its period (`taskgraph::analysis::triggers`): the period
//! W073 and the hover use is the larger of that bound and the throughput's.
//!
//! A robot's iteration period is that of the slowest service graph it
//! calls: the graphs only meet at the control task, which takes no time, so
//! each runs at its own pace and the slowest bounds how often the robot can
//! complete one iteration of all of them.
//!
//! The analyses are the task graphs' own (`taskgraph::analysis`, through the
//! caller's [`GraphRun`]s): nothing is re-derived here. A graph that cannot
//! be read, or has format errors, is reported in its own file (and E055 in
//! the catalog) and gives no warning here.

mod latency;

use crate::catalog::latency::LatencyBound;
use crate::catalog::{Catalog, Implementation, RobotType};
use crate::diag::{self, Code, Diagnostic, FileId, Related};
use crate::refine::{RobotProgram, State, StateKind};
use crate::sema::Mission;
use crate::span::Span;
use crate::taskgraph::analysis::ratio::Ratio;
use crate::workspace::GraphRun;
use std::collections::HashMap;
use std::sync::Arc;

/// What the analyses of a mission's refined graphs found.
#[derive(Clone, Debug, Default)]
pub struct MissionDataflow {
    /// Every robot of the mission that was refined, in formation order.
    pub robots: Vec<RobotDataflow>,
    /// Warnings in the mission file, sorted.
    pub diagnostics: Vec<Diagnostic>,
    /// The service graph files analysed (a change to one changes this).
    pub graphs: Vec<FileId>,
    /// How many latency analyses ran for the catalog's bounds: one per
    /// distinct (graph, source, sink), however many robots and calls.
    pub latency_analyses: usize,
}

/// One robot's dataflow.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotDataflow {
    pub team: String,
    pub robot: String,
    /// Milliseconds per iteration, exact; `None` when no service graph the
    /// robot calls has execution times or a time-triggered task (nothing
    /// bounds it).
    pub period: Option<Ratio>,
    /// The service whose graph bounds the period, and that graph as the
    /// catalog names it.
    pub bounded_by: Option<(String, String)>,
}

/// The analysed task graph implementing a catalog service: the catalog file
/// naming it and the path as written there (relative to that file).
pub type ServiceGraphs<'a> = dyn Fn(FileId, &str) -> Option<Arc<GraphRun>> + 'a;

/// Everything the dataflow analysis reads.
pub struct DataflowInput<'a> {
    /// The mission file (where the warnings go).
    pub file: FileId,
    pub mission: &'a Mission,
    pub catalog: &'a Catalog,
    /// What refinement gave for the mission: a program for at least one
    /// robot of each declaration (`refine::refine_checked_robots` with
    /// `Robots::OnePerDeclaration`). The robots of a declaration are refined
    /// alike, so one program stands for all of them.
    pub programs: &'a [RobotProgram],
    /// The service graphs, analysed; `None` when one cannot be read.
    pub service_graph: &'a ServiceGraphs<'a>,
}

/// Analyses each declaration's refined graph with the service graphs it
/// calls, once, and gives its result to each of the declaration's robots.
pub fn analyze(input: &DataflowInput<'_>) -> MissionDataflow {
    let mut out = MissionDataflow::default();
    let mut latencies = latency::Latencies::default();
    let programs: HashMap<(&str, &str), &RobotProgram> = input
        .programs
        .iter()
        .map(|p| ((p.team.as_str(), p.robot.as_str()), p))
        .collect();
    for team in &input.mission.teams {
        for declaration in team.declarations() {
            let robots = declaration.iter().map(|&r| team.robot(r));
            let refined = robots
                .clone()
                .find_map(|r| Some((r, *programs.get(&(team.name.as_str(), r.name.as_str()))?)));
            let Some((refined, program)) = refined else {
                continue; // not refined: its type is unknown (a check error)
            };
            let robot_type = refined.robot_type.map(|id| input.catalog.get(id));
            let found = robot(
                input,
                program,
                robot_type,
                &mut out.diagnostics,
                &mut out.graphs,
                &mut latencies,
            );
            out.robots.extend(robots.map(|r| RobotDataflow {
                robot: r.name.to_string(),
                ..found.clone()
            }));
        }
    }
    out.latency_analyses = latencies.analyses;
    diag::sort_and_dedup(&mut out.diagnostics);
    out.graphs.sort();
    out.graphs.dedup();
    out
}

/// For a hover on a team's name at `offset`: each of its robots' iteration
/// period, in markdown; `None` elsewhere, when no robot of the team calls a
/// service graph with execution times, or when the mission was not refined
/// (it has errors). `dataflow` is asked only on a team's name.
pub fn team_periods_at(
    mission: &Mission,
    offset: usize,
    dataflow: impl FnOnce() -> Option<Arc<MissionDataflow>>,
) -> Option<String> {
    let team = crate::sema::lookup::at(mission, offset)
        .iter()
        .find_map(|o| match o.symbol {
            crate::sema::Symbol::Team(t) => Some(mission.team(t)),
            _ => None,
        })?;
    let dataflow = dataflow()?;
    let robots: Vec<&RobotDataflow> = dataflow
        .robots
        .iter()
        .filter(|r| team.name == r.team.as_str())
        .collect();
    // Nothing to say of a team none of whose robots runs a timed graph.
    if robots.iter().all(|r| r.period.is_none()) {
        return None;
    }
    let mut out = String::from("**Iteration period** (dataflow):");
    for r in robots {
        let line = match (&r.period, &r.bounded_by) {
            (Some(p), Some((service, graph))) => {
                format!("\n- `{}`: {p} ms (`{service}`: `{graph}`)", r.robot)
            }
            _ => format!(
                "\n- `{}`: not bounded (it calls no service graph with execution times or time-triggered tasks)",
                r.robot
            ),
        };
        out.push_str(&line);
    }
    Some(out)
}

/// One call of a service implemented by a graph.
struct GraphCall<'p> {
    service: &'p str,
    path: &'p str,
    run: Arc<GraphRun>,
    state: &'p State,
    /// The period asked for around the call, and where.
    asked: Option<(i64, Span)>,
    /// The latency bounds the catalog states on the service, and its file.
    bounds: &'p [LatencyBound],
    catalog: FileId,
}

fn robot(
    input: &DataflowInput<'_>,
    program: &RobotProgram,
    robot_type: Option<&RobotType>,
    diagnostics: &mut Vec<Diagnostic>,
    graphs: &mut Vec<FileId>,
    latencies: &mut latency::Latencies,
) -> RobotDataflow {
    let mut found = RobotDataflow {
        team: program.team.clone(),
        robot: program.robot.clone(),
        period: None,
        bounded_by: None,
    };
    for call in graph_calls(input, program, robot_type) {
        graphs.extend(call.run.graph.as_ref().map(|g| g.file));
        diagnostics.extend(graph_problems(input.file, &call));
        let bounded = latency::BoundedCall {
            file: input.file,
            span: call.state.span,
            service: call.service,
            path: call.path,
            catalog: call.catalog,
            run: &call.run,
        };
        diagnostics.extend(latencies.check(&bounded, call.bounds));
        let throughput = iteration_period(&call.run);
        // The time-triggered tasks bound it when the throughput does not
        // say more.
        let by_time = call
            .run
            .report
            .time_bound
            .as_ref()
            .filter(|b| throughput.is_none_or(|p| b.period > p));
        let Some(period) = by_time.map(|b| b.period).or(throughput) else {
            continue;
        };
        if found.period.is_none_or(|p| period > p) {
            found.period = Some(period);
            found.bounded_by = Some((call.service.to_string(), call.path.to_string()));
        }
        if let Some((asked, span)) = call.asked
            && let Ok(asked_ms) = u64::try_from(asked)
            && period > Ratio::new(asked_ms, 1).unwrap_or(Ratio::ONE)
        {
            let why = match by_time {
                Some(b) => format!(
                    "at least {} ms per iteration (its time-triggered task `{}` fires {} time{} per iteration, at most once every {} ms)",
                    b.period,
                    b.task,
                    b.firings,
                    if b.firings == 1 { "" } else { "s" },
                    b.period_ms
                ),
                None => format!("{period} ms per iteration (its throughput)"),
            };
            let mut d = Diagnostic::new(
                Code::DataflowTooSlow,
                input.file,
                span,
                format!(
                    "the task graph `{}` of `{}` takes {why}, longer than the {asked} ms period asked for here: the robots running it cannot keep up",
                    call.path, call.service
                ),
            );
            d.relate(
                call.state.span,
                format!("`{}` is called here", call.service),
            );
            if let Some(b) = by_time {
                d.related.push(Related {
                    file: b.file,
                    span: b.span,
                    message: format!("`{}` bounds the period", b.task),
                });
            } else if let Some(graph) = &call.run.graph {
                for task in critical_tasks(&call.run) {
                    if let Some(t) = graph.tasks.iter().find(|t| t.name.name == *task) {
                        d.related.push(Related {
                            file: graph.file,
                            span: t.name.span,
                            message: format!("`{task}` bounds the period"),
                        });
                    }
                }
            }
            diagnostics.push(d);
        }
    }
    found
}

/// The calls of `program` whose service the robot's type (as the checker
/// resolved it) implements by a task graph that could be read.
fn graph_calls<'p>(
    input: &DataflowInput<'p>,
    program: &'p RobotProgram,
    robot_type: Option<&'p RobotType>,
) -> Vec<GraphCall<'p>> {
    let Some(robot_type) = robot_type else {
        return Vec::new();
    };
    let mut calls = Vec::new();
    for machine in &program.control.services {
        for (index, state) in machine.states.iter().enumerate() {
            let StateKind::Call { service, .. } = &state.kind else {
                continue;
            };
            let Some(def) = robot_type.service(service) else {
                continue;
            };
            let Implementation::Graph(path) = &def.implementation else {
                continue;
            };
            let Some(run) = (input.service_graph)(def.origin.file, path) else {
                continue;
            };
            calls.push(GraphCall {
                service,
                path,
                run,
                state,
                asked: asked_period(&machine.states, index),
                bounds: &def.latency,
                catalog: def.origin.file,
            });
        }
    }
    calls
}

/// The period asked for around state `index`: the innermost `loop(P)`
/// holding it, else its service's `repeat(P)`.
fn asked_period(states: &[State], index: usize) -> Option<(i64, Span)> {
    let innermost_loop = states
        .iter()
        .enumerate()
        .filter_map(|(tail, s)| match s.kind {
            StateKind::LoopTail {
                period_ms: Some(p),
                to: head,
                ..
            } if head.index() < index && index < tail => Some((tail - head.index(), (p, s.span))),
            _ => None,
        })
        .min_by_key(|(width, _)| *width)
        .map(|(_, asked)| asked);
    innermost_loop.or_else(|| {
        states.iter().find_map(|s| match s.kind {
            StateKind::Repeat {
                period_ms: Some(p), ..
            } => Some((p, s.span)),
            _ => None,
        })
    })
}

/// The period of the graph's top level, when it has execution times.
fn iteration_period(run: &GraphRun) -> Option<Ratio> {
    let period = run.report.levels.first()?.throughput.as_ref().ok()?.period;
    (period.num > 0).then_some(period)
}

/// The tasks around the cycle that bounds the graph's period.
fn critical_tasks(run: &GraphRun) -> &[String] {
    run.report
        .levels
        .first()
        .and_then(|l| l.throughput.as_ref().ok())
        .map_or(&[], |t| &t.critical_cycle)
}

/// The graph's inconsistency, deadlock and buffer warnings, each on the call.
fn graph_problems(file: FileId, call: &GraphCall<'_>) -> Vec<Diagnostic> {
    let own_file = call.run.graph.as_ref().map(|g| g.file);
    call.run
        .report
        .diagnostics
        .iter()
        // A sub-graph's own warnings stay in it (its errors are moved to the
        // reference, in this file).
        .filter(|found| Some(found.file) == own_file)
        .filter_map(|found| {
            let (code, what) = match found.code {
                Code::InconsistentRates | Code::RateOverflow | Code::SubgraphBoundaryRate => {
                    (Code::DataflowInconsistent, "has inconsistent sample rates")
                }
                Code::Deadlock => (Code::DataflowDeadlock, "deadlocks"),
                Code::BufferTooSmall => (Code::DataflowBufferTooSmall, "has a buffer too small"),
                _ => return None,
            };
            let mut d = Diagnostic::new(
                code,
                file,
                call.state.span,
                format!(
                    "`{}` runs the task graph `{}`, which {what}: {}",
                    call.service, call.path, found.message
                ),
            );
            d.related.push(Related {
                file: found.file,
                span: found.span,
                message: format!("[{}] in the task graph", found.code),
            });
            Some(d)
        })
        .collect()
}

// Tested through the workspace analysis, as the doors reach it:
// `host/dataflow/tests.rs`.
