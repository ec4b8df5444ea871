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
    ControlMachine, GlobalValue, HEARTBEAT_MS, Ownership, RobotProgram, SharedLibrary, SlotSource,
};
use super::super::value::ValueKind;
use crate::sema::Team;

/// The library of a robot of `team` (peer indices `first_peer..` in
/// formation order): one value per shared slot of the machine, and who owns
/// the globally shared ones. A team of several robots sharing globally
/// needs heartbeats to notice a lost owner: the machine gets them.
pub(super) fn library(
    team: &Team,
    first_peer: usize,
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
    let global: Vec<GlobalValue> = attributes
        .iter()
        .enumerate()
        .filter(|(_, key)| key.starts_with(&own) && !machine.subscribed.contains(key))
        .map(|(at, key)| GlobalValue {
            at,
            kind: kinds[at].clone(),
            set_key: set_key(&team.name, key),
            value_key: value_key(&team.name, key),
        })
        .collect();
    let ownership = (team.robots.len() > 1 && !global.is_empty()).then(|| Ownership {
        global,
        owners: (first_peer..first_peer + team.robots.len()).collect(),
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

/// The owner order of `team`: its robots that hold globally shared values,
/// in formation order (a robot whose program reads and writes none, e.g.
/// one that runs none of the statements using them, sends no heartbeats and
/// cannot own them). Known only once every robot of the team is refined.
pub(in crate::refine) fn owners_of_team(programs: &mut [RobotProgram], team: &str) {
    let sharing: Vec<usize> = programs
        .iter()
        .filter(|p| p.team == team)
        .filter(|p| p.library.as_ref().is_some_and(|l| l.ownership.is_some()))
        .map(|p| p.self_peer)
        .collect();
    for program in programs.iter_mut().filter(|p| p.team == team) {
        if let Some(ownership) = program.library.as_mut().and_then(|l| l.ownership.as_mut()) {
            ownership.owners.clone_from(&sharing);
        }
    }
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
