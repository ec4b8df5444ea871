//! What a target refuses to generate, robot by robot (each on the target
//! the build's plan chose for it, named with why in the message and
//! pointed at where it was written). A board reaches other robots only
//! through its serial link to `semo gateway` (`platform::SerialLink`,
//! `semo_static_link.c`): a robot that sends to, receives from, publishes
//! to or subscribes to other robots is built with the link
//! ([`peer_messages`]; every board has one), never with its messages
//! silently dropped. Messages to and from the operator (`USER`) need no
//! link: the trace is the operator console's record, and in simulation the
//! operator's commands are compiled in.

use super::{Emit, Layer};
use crate::diag::{Code, Diagnostic};
use crate::refine::RobotProgram;
use crate::refine::{BuildInput, CompiledScenario, robot_span};
use crate::targets::Chosen;

/// The operator console's team name in messages.
const USER: &str = "USER";

/// The diagnostics that refuse `programs`, each on its own target
/// (`targets`, in the same order). `scenarios`: the compiled world of each
/// program, in the same order, when the build was given a scenario.
pub fn check(
    build: &BuildInput<'_>,
    programs: &[RobotProgram],
    targets: &[Chosen],
    emit: Emit,
    scenarios: &[CompiledScenario],
) -> Vec<Diagnostic> {
    let has_scenarios = scenarios.len() == programs.len();
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
    // A board's messages to other robots go through its serial link and
    // `semo gateway`, which cannot lose or delay one on the scenario's
    // say: link faults need linux-sim's udp transport. Said here rather
    // than when the board starts.
    if has_scenarios {
        for ((program, chosen), world) in programs.iter().zip(targets).zip(scenarios) {
            if chosen.target.layer() != Layer::Static
                || world.links.is_empty()
                || peer_messages(program).is_none()
            {
                continue;
            }
            let mut d = Diagnostic::new(
                Code::TargetUnsupported,
                build.mission,
                robot_span(build, &program.robot),
                format!(
                    "robot `{}` is built for {}: the scenario's link faults on its messages (`drop`, `delay`, `partition`) need the udp transport of linux-sim, which a board on its serial link to `semo gateway` has not: build it for linux-sim, or leave it out of the scenario's link faults",
                    program.robot,
                    chosen.describe(),
                ),
            );
            relate_choice(&mut d, chosen);
            found.push(d);
        }
    }
    found
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

/// How the robot talks to other robots, if it does (then a board builds it
/// with its link).
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
