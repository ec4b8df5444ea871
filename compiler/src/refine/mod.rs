//! Refinement (codegen.md §1): a checked mission, its strategy files and the
//! catalog become, for every robot, a task graph and the control task's
//! hierarchical state machine ([`RobotProgram`]).
//!
//! - `robot.rs`: one robot's program: which services it runs (group arms it
//!   can never join are dropped), statement machines, strategy action machines,
//!   the values it reads (typed as the catalog declares them), the messages
//!   it exchanges.
//! - `value.rs`: typed values and the operations the generated C and the
//!   simulator both perform on them.
//! - `graph.rs`: the robot's task graph from what the machine uses, checked
//!   with the SDF/L analyses.
//! - `world.rs`: a robot's world compiled from a scenario
//!   ([`CompiledScenario`]), which both back ends read.
//!
//! Refinement reads only checked input: the caller refuses missions with errors.

mod build;
pub mod graph;
pub mod program;
pub mod protocol;
mod robot;
pub mod value;
mod world;

pub use build::{
    BuildInput, Refined, is_plain_name, refine_checked, refine_checked_robots, robot_span,
};
pub use program::*;
pub use robot::SENSOR_PERIOD_MS;
pub use value::{Value, ValueKind};
pub use world::{CallResults, CompiledLink, CompiledScenario, LinkEffect, OperatorCommand};

use crate::CheckedMission;
use crate::catalog::Catalog;
use crate::diag::{self, Diagnostic, FileId};
use crate::strategy::{Strategy, StrategyLinks};
use crate::text::LineIndex;

/// Everything refinement reads.
pub struct RefineInput<'a> {
    /// The mission's file name (for traces and file headers).
    pub mission_name: &'a str,
    pub file: FileId,
    pub text: &'a str,
    pub analysis: &'a CheckedMission,
    pub catalog: &'a Catalog,
    pub strategies: &'a [Strategy],
    /// Strategy file names, by `Strategy::file`, for comments.
    pub strategy_names: &'a [(FileId, String)],
    pub links: &'a StrategyLinks,
    /// The task graphs implementing catalog services that the workspace holds.
    pub service_graphs: &'a [ServiceGraph],
}

/// A task graph a catalog names (`graph="path"` in catalog file `catalog`), as loaded.
#[derive(Clone, Debug)]
pub struct ServiceGraph {
    pub catalog: FileId,
    pub path: String,
    pub graph: std::sync::Arc<crate::taskgraph::TaskGraph>,
    /// The sub-graph files its tasks reference, resolved as the workspace
    /// resolved them (their problems are the graph file's diagnostics).
    pub hierarchy: std::sync::Arc<crate::taskgraph::subgraph::Hierarchy>,
}

/// Which robots [`refine_robots`] refines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Robots {
    /// Every robot: what code generation and the simulator run.
    All,
    /// One robot of each declaration (`name[N]` is one, see
    /// [`crate::sema::Team::declarations`]): its last, whose name is the
    /// longest. The robots of a declaration are refined alike but for their
    /// names and their place among the peers, so what depends on neither
    /// (the dataflow warnings, whether refinement finds an error) is found
    /// from one of them: the cost is per declaration, not per robot. What
    /// joins the robots of a team (shared information's owners, a group's
    /// members) then lists only the robots refined.
    OnePerDeclaration,
}

/// One program per robot of the mission, in formation order, and the
/// diagnostics that stop generation (constructs code generation does not
/// support yet, inconsistent refined graphs).
pub fn refine(input: &RefineInput<'_>) -> (Vec<RobotProgram>, Vec<Diagnostic>) {
    refine_robots(input, Robots::All)
}

/// [`refine`] of the robots `robots` selects, in formation order.
pub fn refine_robots(
    input: &RefineInput<'_>,
    robots: Robots,
) -> (Vec<RobotProgram>, Vec<Diagnostic>) {
    let lines = LineIndex::new(input.text);
    let mission = &input.analysis.mission;
    let peers: std::sync::Arc<[(String, String)]> = mission
        .teams
        .iter()
        .flat_map(|t| {
            t.robots
                .iter()
                .map(|r| (t.name.to_string(), r.name.to_string()))
        })
        .collect();
    let mut programs = Vec::new();
    let mut diagnostics = Vec::new();
    // The peer index of each team's first robot, counted as the teams go
    // (not summed again per robot: refinement stays linear in teams).
    let mut first_peer = 0;
    for (team_index, team) in mission.teams.iter().enumerate() {
        let selected: Vec<crate::sema::RobotId> = match robots {
            Robots::All => team.robot_ids().collect(),
            Robots::OnePerDeclaration => team
                .declarations()
                .iter()
                .filter_map(|d| d.last().copied())
                .collect(),
        };
        // W130 for a team: what every one of its robots gives.
        let mut names_no_task: Vec<Vec<Diagnostic>> = Vec::new();
        let mut team_programs = Vec::new();
        let mut runners = robot::TeamRunners::default();
        for robot in selected {
            let (program, found) = robot::refine_robot(
                input,
                &lines,
                &peers,
                crate::sema::TeamId(team_index as u32),
                first_peer,
                robot.index(),
                &mut runners,
            );
            let (warned, found): (Vec<Diagnostic>, Vec<Diagnostic>) = found
                .into_iter()
                .partition(|d| d.code == diag::Code::BatteryPolicyNamesNoTask);
            names_no_task.push(warned);
            diagnostics.extend(found);
            team_programs.extend(program);
        }
        // Only this team's programs: the owners are the team's business, and
        // passing the whole fleet would make refinement quadratic in teams.
        diagnostics.extend(robot::shared::owners_of_team(
            &mut team_programs,
            &team.name,
            input.strategies,
        ));
        programs.append(&mut team_programs);
        first_peer += team.robots.len();
        if let Some((first, others)) = names_no_task.split_first() {
            diagnostics.extend(
                first
                    .iter()
                    .filter(|d| others.iter().all(|o| o.contains(d)))
                    .cloned(),
            );
        }
    }
    assign_groups(&mut programs);
    share_control_machines(&mut programs);
    diag::sort_and_dedup(&mut diagnostics);
    (programs, diagnostics)
}

/// Each team's group (`<GroupService>`): the robots whose refined programs
/// call one of the team's group services, given to each of them.
fn assign_groups(programs: &mut [RobotProgram]) {
    let mut groups: std::collections::BTreeMap<String, Vec<PeerId>> = Default::default();
    for p in programs.iter() {
        if !p.control.group_services.is_empty() {
            groups.entry(p.team.clone()).or_default().push(p.self_peer);
        }
    }
    for p in programs.iter_mut() {
        if !p.control.group_services.is_empty() {
            let mut members = groups[&p.team].clone();
            members.sort_unstable();
            // Each program's machine is still its own (shared only below).
            std::sync::Arc::make_mut(&mut p.control).group = members;
        }
    }
}

/// Robots whose control machines are equal share one: each program's
/// machine is compared with the one before it in formation order, where the
/// robots of a declaration (`name[N]`, refined alike but for their names
/// and places, which the machine does not hold) sit side by side. One
/// comparison per robot keeps refinement linear in robots, and a swarm of
/// one kind of robot holds one machine (the simulator and code generation
/// read the same machine for each of them).
fn share_control_machines(programs: &mut [RobotProgram]) {
    for i in 1..programs.len() {
        let (before, rest) = programs.split_at_mut(i);
        let (previous, program) = (&before[i - 1], &mut rest[0]);
        if previous.team == program.team
            && !std::sync::Arc::ptr_eq(&previous.control, &program.control)
            && previous.control == program.control
        {
            program.control = std::sync::Arc::clone(&previous.control);
        }
    }
}

#[cfg(test)]
mod tests;
