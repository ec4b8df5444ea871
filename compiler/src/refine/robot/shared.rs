//! The team's library task and its globally shared information
//! (`docs/shared-information.md`): which of the library's values one robot
//! of the team owns, who owns them in turn, and the message keys of the
//! protocol (a write sent to the owner, the owner's value told to the team).
//!
//! A library value is globally shared when it is the robot's own team's
//! (`Team.X` of its own team: a team variable, or a value the team sends
//! itself) and not read through `subscribe`: values published to a multicast
//! group are locally shared and stay a latest-value copy on each robot, and
//! another team's values (and the operator's) arrive at every robot that
//! receives them.

use super::super::program::{
    AttributeId, ControlMachine, GlobalValue, HEARTBEAT_MS, OwnerRule, Ownership, PeerId,
    RobotProgram, SharedLibrary, SlotSource,
};
use super::super::value::ValueKind;
use crate::diag::{Code, Diagnostic};
use crate::sema::Team;
use crate::strategy::{LeaderAlgorithm, Strategy};

/// The library of a robot of `team` (peer indices `first_peer..` in
/// formation order): one value per shared slot of the machine, and who owns
/// the globally shared ones (`leader`: the team's leader selection, until
/// [`owners_of_team`] knows the whole team). A team of several robots
/// sharing globally needs heartbeats to notice a lost owner: the machine
/// gets them.
pub(super) fn library(
    team: &Team,
    first_peer: usize,
    leader: LeaderAlgorithm,
    machine: &mut ControlMachine,
) -> Option<SharedLibrary> {
    let mut attributes: Vec<String> = Vec::new();
    let mut kinds: Vec<&ValueKind> = Vec::new();
    for slot in &machine.slots {
        if slot.source == SlotSource::Shared && !attributes.contains(&slot.key) {
            attributes.push(slot.key.clone());
            kinds.push(&slot.kind);
        }
    }
    if attributes.is_empty() {
        return None;
    }
    let own = format!("{}.", team.name);
    let global: Vec<GlobalValue> = AttributeId::all(attributes.len())
        .zip(&attributes)
        .filter(|(_, key)| key.starts_with(&own) && !machine.subscribed.contains(key))
        .map(|(at, key)| GlobalValue {
            at,
            kind: kinds[at.index()].clone(),
            set_key: set_key(&team.name, key),
            value_key: value_key(&team.name, key),
        })
        .collect();
    let ownership = (team.robots.len() > 1 && !global.is_empty()).then(|| Ownership {
        global,
        owners: (first_peer..first_peer + team.robots.len())
            .map(PeerId::new)
            .collect(),
        rule: OwnerRule::Leader(leader),
    });
    if ownership.is_some() && !machine.heartbeat {
        machine.heartbeat = true;
        machine.heartbeat_ms = HEARTBEAT_MS;
    }
    Some(SharedLibrary {
        name: format!("{}Shared", team.name),
        attributes,
        ownership,
    })
}

/// The owner order of `team`: its robots that hold globally shared values
/// (a robot whose program reads and writes none, e.g. one that runs none of
/// the statements using them, sends no heartbeats and cannot own them),
/// the robot the team's strategy names in `<SharedOwner>` first and the
/// others in formation order; without one, the team's leader order
/// (formation order, reversed for `bully`). Known only once every robot of
/// the team is refined. A named robot that holds none of the values is
/// W131 (when it was refined: one robot per declaration may leave it out).
pub(in crate::refine) fn owners_of_team(
    programs: &mut [RobotProgram],
    team: &str,
    strategies: &[Strategy],
) -> Vec<Diagnostic> {
    let team_programs = || programs.iter().filter(|p| p.team == team);
    let sharing: Vec<PeerId> = team_programs()
        .filter(|p| p.library.as_ref().is_some_and(|l| l.ownership.is_some()))
        .map(|p| p.self_peer)
        .collect();
    let named = strategies
        .iter()
        .filter(|s| s.team.as_ref().is_some_and(|t| t.name == team))
        .find_map(|s| {
            Some((
                s.file,
                s.grouping.as_ref()?.shared_owner.as_ref()?.robot.as_ref()?,
            ))
        });
    let mut diagnostics = Vec::new();
    let mut first = None;
    if let Some((file, robot)) = named {
        let program = team_programs().find(|p| p.robot == robot.name);
        match program {
            Some(p) if sharing.contains(&p.self_peer) => first = Some(p.self_peer),
            Some(p) if !sharing.is_empty() => diagnostics.push(Diagnostic::new(
                Code::SharedOwnerHoldsNone,
                file,
                robot.span,
                format!(
                    "{} holds none of team {team}'s globally shared values (it runs none of the statements using them): it cannot own them, the team's leader does",
                    p.robot
                ),
            )),
            // Not refined (one robot per declaration), no values to own,
            // or not a robot of the team (E131).
            _ => {}
        }
    }
    for program in programs.iter_mut().filter(|p| p.team == team) {
        if let Some(ownership) = program.library.as_mut().and_then(|l| l.ownership.as_mut()) {
            let mut owners = sharing.clone();
            match first {
                Some(first) => {
                    owners.retain(|&o| o != first);
                    owners.insert(0, first);
                    ownership.rule = OwnerRule::Named;
                }
                None if ownership.rule == OwnerRule::Leader(LeaderAlgorithm::Bully) => {
                    owners.reverse();
                }
                None => {}
            }
            ownership.owners = owners;
        }
    }
    diagnostics
}

/// `Team.__set.X`: a robot's write of `Team.X`, sent to the owner.
pub fn set_key(team: &str, key: &str) -> String {
    format!("{team}.__set.{}", attribute_name(team, key))
}

/// `Team.__value.X`: the owner's value of `Team.X`, sent to the team.
pub fn value_key(team: &str, key: &str) -> String {
    format!("{team}.__value.{}", attribute_name(team, key))
}

fn attribute_name<'k>(team: &str, key: &'k str) -> &'k str {
    key.strip_prefix(team)
        .and_then(|k| k.strip_prefix('.'))
        .unwrap_or(key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn protocol_keys_name_the_team_and_the_attribute() {
        assert_eq!(set_key("Scouts", "Scouts.FOUND"), "Scouts.__set.FOUND");
        assert_eq!(value_key("Scouts", "Scouts.FOUND"), "Scouts.__value.FOUND");
    }
}
