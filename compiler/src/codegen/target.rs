//! What a target refuses to generate: a static-schedule target has no
//! transport to other robots yet (a serial link to a gateway is a later
//! step), so a robot that sends to, receives from, publishes to or
//! subscribes to other robots is refused there (E103), never built with its
//! messages silently dropped. Messages to and from the operator (`USER`)
//! stay: the trace is the operator console's record, and in simulation the
//! operator's commands are compiled in.

use super::{BuildInput, Emit, Platform, Target};
use crate::diag::{Code, Diagnostic};
use crate::refine::RobotProgram;
use crate::sema::Peer;

/// The operator console's team name in messages.
const USER: &str = "USER";

/// The diagnostics that refuse `programs` on `target`. `has_scenarios`: a
/// compiled world was given for every program.
pub fn check(
    build: &BuildInput<'_>,
    programs: &[RobotProgram],
    target: Target,
    emit: Emit,
    has_scenarios: bool,
) -> Vec<Diagnostic> {
    let mut found = Vec::new();
    if emit == Emit::TaskGraph {
        return found;
    }
    if target.needs_scenario() && !has_scenarios {
        found.push(Diagnostic::new(
            Code::TargetUnsupported,
            build.mission,
            Default::default(),
            format!(
                "target {} compiles a scenario into each robot: build with `semo build --target {} --scenario FILE`",
                target.name(),
                target.name()
            ),
        ));
    }
    // A service graph without a schedule cannot be run (the dataflow
    // warnings say why on the call).
    for program in programs {
        for graph in &program.graph_services {
            if let Err(why) = super::loops::check(graph) {
                found.push(Diagnostic::new(
                    Code::CodegenInternal,
                    build.mission,
                    graph.call,
                    format!("task graph `{}`: {why}", graph.graph),
                ));
            }
            if let Err(refused) = &graph.steps {
                let mut d =
                    Diagnostic::new(refused.code, build.mission, graph.call, &refused.message);
                d.related.extend(refused.related.iter().cloned());
                found.push(d);
            }
        }
    }
    if target.platform() == Platform::Static {
        for program in programs {
            if let Err(why) = super::schedule::firings(&program.graph) {
                found.push(Diagnostic::new(
                    Code::CodegenInternal,
                    build.mission,
                    robot_span(build, &program.robot),
                    format!("robot `{}`: no static schedule: {why}", program.robot),
                ));
            }
        }
        // A task graph run inside a service task needs the hosted runtime
        // (its loop ends are formatted with snprintf, its exit from the
        // threads simulation's scenario).
        for program in programs {
            if let Some(graph) = program.graph_services.first() {
                found.push(Diagnostic::new(
                    Code::TargetUnsupported,
                    build.mission,
                    robot_span(build, &program.robot),
                    format!(
                        "robot `{}`: its service task `{}` runs task graph `{}`, which target {} cannot run yet: build for linux or linux-sim",
                        program.robot,
                        graph.task,
                        graph.graph,
                        target.name()
                    ),
                ));
            }
        }
        // One diagnostic per team: its robots share the statements.
        let mut teams: Vec<(&str, Vec<&str>, String, crate::span::Span)> = Vec::new();
        for program in programs {
            let Some(why) = peer_messages(program) else {
                continue;
            };
            match teams.iter_mut().find(|(team, ..)| *team == program.team) {
                Some((_, robots, ..)) => robots.push(&program.robot),
                None => {
                    let span = message_span(build, &program.team)
                        .unwrap_or_else(|| robot_span(build, &program.robot));
                    teams.push((&program.team, vec![&program.robot], why, span));
                }
            }
        }
        for (team, robots, why, span) in teams {
            let who = if robots.len() == 1 {
                format!("robot `{}`", robots[0])
            } else {
                format!("the robots of team `{team}` ({})", robots.join(", "))
            };
            found.push(Diagnostic::new(
                Code::TargetUnsupported,
                build.mission,
                span,
                format!(
                    "{who}: {why}, but target {} has no transport to other robots yet: build for linux, or message only USER",
                    target.name()
                ),
            ));
        }
    }
    found
}

/// Where the robot is declared (diagnostics about one robot point there).
pub(super) fn robot_span(build: &BuildInput<'_>, robot: &str) -> crate::span::Span {
    build
        .analysis
        .mission
        .teams
        .iter()
        .flat_map(|t| &t.robots)
        .find(|r| r.name == robot)
        .map(|r| r.name_span)
        .unwrap_or_default()
}

/// The first statement of `team` that messages another team (the checker's
/// `messages`); `None` for a robot that only exchanges heartbeats.
fn message_span(build: &BuildInput<'_>, team: &str) -> Option<crate::span::Span> {
    let mission = &build.analysis.mission;
    let id = mission.teams.iter().position(|t| t.name == team)?;
    mission
        .messages
        .iter()
        .filter(|m| m.team.0 as usize == id && m.peer != Peer::User)
        .map(|m| m.span)
        .min_by_key(|s| s.start)
}

/// How the robot talks to other robots, if it does.
fn peer_messages(program: &RobotProgram) -> Option<String> {
    let m = &program.control;
    if let Some(o) = m.outgoing.iter().find(|o| o.to_team != USER) {
        let verb = if o.publish { "publish" } else { "send" };
        return Some(format!("{verb} `{}` to team `{}`", o.key, o.to_team));
    }
    if let Some(i) = m.incoming.iter().find(|i| i.from_team != USER) {
        return Some(format!("receive `{}` from team `{}`", i.key, i.from_team));
    }
    if let Some(g) = m.subscribed.first() {
        return Some(format!("subscribe to `{g}`"));
    }
    if let Some(service) = m.group_services.first() {
        return Some(format!(
            "share the group service `{service}` with the team (heartbeats)"
        ));
    }
    if m.heartbeat {
        return Some("elect a leader among the team (heartbeats)".to_string());
    }
    None
}
