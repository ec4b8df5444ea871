//! What a target refuses to generate, robot by robot (each on the target
//! the build's plan chose for it, named with why in the message and
//! pointed at where it was written). A board reaches other robots only
//! through its serial link to `semo gateway` (`platform::SerialLink`,
//! `semo_static_link.c`): a robot that sends to, receives from, publishes
//! to or subscribes to other robots is built with the link on a board that
//! has one (`cortex-m`'s UART1) and refused on a board that has none yet
//! (`stm32f4`, E103), never built with its messages silently dropped.
//! Messages to and from the operator (`USER`) need no link: the trace is
//! the operator console's record, and in simulation the operator's
//! commands are compiled in.

use super::{Emit, Layer};
use crate::diag::{Code, Diagnostic};
use crate::refine::RobotProgram;
use crate::refine::{BuildInput, robot_span};
use crate::sema::Peer;
use crate::targets::Chosen;

/// The operator console's team name in messages.
const USER: &str = "USER";

/// The diagnostics that refuse `programs`, each on its own target
/// (`targets`, in the same order). `has_scenarios`: a compiled world was
/// given for every program.
pub fn check(
    build: &BuildInput<'_>,
    programs: &[RobotProgram],
    targets: &[Chosen],
    emit: Emit,
    has_scenarios: bool,
) -> Vec<Diagnostic> {
    let mut found = Vec::new();
    if emit == Emit::TaskGraph {
        return found;
    }
    let mut scenario_asked = Vec::new();
    for chosen in targets {
        let target = chosen.target;
        if target.needs_scenario() && !has_scenarios && !scenario_asked.contains(&target) {
            scenario_asked.push(target);
            found.push(Diagnostic::new(
                Code::TargetUnsupported,
                build.mission,
                Default::default(),
                format!(
                    "target {} compiles a scenario into each robot: build with `semo build --scenario FILE`",
                    target.name(),
                ),
            ));
        }
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
    let on_static = || {
        programs
            .iter()
            .zip(targets)
            .filter(|(_, chosen)| chosen.target.layer() == Layer::Static)
    };
    for (program, _) in on_static() {
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
    for (program, chosen) in on_static() {
        if let Some(graph) = program.graph_services.first() {
            let mut d = Diagnostic::new(
                Code::TargetUnsupported,
                build.mission,
                robot_span(build, &program.robot),
                format!(
                    "robot `{}` is built for {}: its service task `{}` runs task graph `{}`, which {} cannot run yet: build it for linux or linux-sim",
                    program.robot,
                    chosen.describe(),
                    graph.task,
                    graph.graph,
                    chosen.target.name()
                ),
            );
            relate_choice(&mut d, chosen);
            found.push(d);
        }
    }
    // One diagnostic per team and target: its robots share the statements.
    let mut teams: Vec<(&str, &Chosen, Vec<&str>, String, crate::span::Span)> = Vec::new();
    let without_link = on_static().filter(|(_, chosen)| {
        chosen
            .target
            .platform()
            .board
            .as_ref()
            .is_none_or(|b| b.link.is_none())
    });
    for (program, chosen) in without_link {
        let Some(why) = peer_messages(program) else {
            continue;
        };
        let same = |(team, c, ..): &&mut (&str, &Chosen, Vec<&str>, String, _)| {
            *team == program.team && *c == chosen
        };
        match teams.iter_mut().find(same) {
            Some((_, _, robots, ..)) => robots.push(&program.robot),
            None => {
                let span = message_span(build, &program.team)
                    .unwrap_or_else(|| robot_span(build, &program.robot));
                teams.push((&program.team, chosen, vec![&program.robot], why, span));
            }
        }
    }
    // The boards that have a link, named in the message (the platform table's).
    let linked: Vec<(&str, &str)> = crate::platform::PLATFORMS
        .iter()
        .filter_map(|p| Some((p.name, p.board.as_ref()?.link.as_ref()?.port)))
        .collect();
    for (team, chosen, robots, why, span) in teams {
        let who = if robots.len() == 1 {
            format!("robot `{}` (team `{team}`)", robots[0])
        } else {
            format!("the robots of team `{team}` ({})", robots.join(", "))
        };
        let mut d = Diagnostic::new(
            Code::TargetUnsupported,
            build.mission,
            span,
            format!(
                "{who} {} {}: {why}, but {} has no serial link to other robots yet ({}): build {} for {} or linux, or message only USER",
                if robots.len() == 1 { "is" } else { "are" },
                built_for(chosen),
                chosen.target.name(),
                linked
                    .iter()
                    .map(|(name, port)| format!("{name} has one, on {port} to `semo gateway`"))
                    .collect::<Vec<_>>()
                    .join("; "),
                if robots.len() == 1 { "it" } else { "them" },
                linked
                    .iter()
                    .map(|(name, _)| *name)
                    .collect::<Vec<_>>()
                    .join(" or "),
            ),
        );
        relate_choice(&mut d, chosen);
        found.push(d);
    }
    found
}

/// `built for cortex-m, the platform its type ... names`.
fn built_for(chosen: &Chosen) -> String {
    format!("built for {}", chosen.describe())
}

/// Points at where the target was chosen (the catalog's `target=`, the
/// project file's key), when it was written in a file.
fn relate_choice(diagnostic: &mut Diagnostic, chosen: &Chosen) {
    if let Some((file, span)) = chosen.written_at() {
        diagnostic.related.push(crate::diag::Related {
            file,
            span,
            message: format!("{} is chosen here", chosen.target.name()),
        });
    }
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
pub(super) fn peer_messages(program: &RobotProgram) -> Option<String> {
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
