//! The robots a generated program names: its peer table (`peers[]` in
//! `main.c`) lists only the robots it exchanges messages with or must know,
//! so that a build's output grows with the robots, not with their square.
//!
//! Those are, from the refined program: the robot itself; the robots of its
//! team (heartbeats, leader elections, groups, sync points, broadcast events
//! and the owners of shared values are all among them); and the robots its
//! messages go to (`ControlMachine::outgoing`: every robot of a team sent
//! to, or the one robot named). A receiver needs no table of its senders:
//! it takes a message by its key (and, over MQTT, by the topic that names
//! the sender). Each entry keeps the robot's place among the mission's
//! robots (`semo_peer::index`: its UDP port over `port_base` and its id in
//! lock-step), so the transports address it as before.
//!
//! Refinement speaks of robots by their index in the fleet's table
//! (`RobotProgram::peers`); generation writes the local index. A robot the
//! table lacks is recorded (`missing`) and refuses the build (E102), never
//! written as another robot's index.

use crate::refine::{PeerId, RobotProgram};
use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap};

/// The fleet's table indexed once per build: each team's robots and each
/// robot by name, so that every program's peers are found in time linear
/// in its own peers.
pub struct Fleet<'a> {
    table: &'a [(String, String)],
    teams: HashMap<&'a str, Vec<PeerId>>,
    robots: HashMap<&'a str, PeerId>,
}

impl<'a> Fleet<'a> {
    pub fn of(table: &'a [(String, String)]) -> Fleet<'a> {
        let mut teams: HashMap<&str, Vec<PeerId>> = HashMap::new();
        let mut robots = HashMap::new();
        for (i, (team, robot)) in PeerId::all(table.len()).zip(table) {
            teams.entry(team.as_str()).or_default().push(i);
            robots.insert(robot.as_str(), i);
        }
        Fleet {
            table,
            teams,
            robots,
        }
    }

    /// Whether `program`'s fleet table is this one.
    pub fn holds(&self, program: &RobotProgram) -> bool {
        std::ptr::eq(self.table, &*program.peers)
    }

    /// The robots a message addressed to `to` (a team or a robot) reaches.
    fn addressed(&self, to: &str) -> &[PeerId] {
        match self.teams.get(to) {
            Some(team) => team,
            None => self.robots.get(to).map_or(&[], std::slice::from_ref),
        }
    }
}

/// One program's peer table: fleet indices, ascending (formation order, so
/// a message to a team reaches its robots in the order it always did).
pub struct Peers {
    list: Vec<PeerId>,
    /// The robot itself, as a local index.
    own: usize,
    missing: RefCell<BTreeSet<PeerId>>,
}

impl Peers {
    pub fn of(program: &RobotProgram, fleet: &Fleet<'_>) -> Peers {
        let mut robots = BTreeSet::from([program.self_peer]);
        robots.extend(fleet.addressed(&program.team));
        for message in &program.control.outgoing {
            robots.extend(fleet.addressed(&message.to_team));
        }
        let list: Vec<PeerId> = robots.into_iter().collect();
        let own = list.binary_search(&program.self_peer).unwrap_or(0);
        Peers {
            list,
            own,
            missing: RefCell::new(BTreeSet::new()),
        }
    }

    /// The fleet indices of the peers, in table order.
    pub fn list(&self) -> &[PeerId] {
        &self.list
    }

    /// The robot itself, as a local index (`semo_program_desc::self`).
    pub fn own(&self) -> usize {
        self.own
    }

    /// How many robots the table holds (at least 1: the robot itself).
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The local index of the robot at `fleet` in the fleet's table. `of`
    /// takes in every robot refinement can name for this program (its team
    /// and the robots it sends to), so a miss is a generator bug: it is
    /// recorded for [`Peers::missing`] and the index returned is past the
    /// table's end (the program is refused, never written with it).
    pub fn local(&self, fleet: PeerId) -> usize {
        self.list.binary_search(&fleet).unwrap_or_else(|_| {
            self.missing.borrow_mut().insert(fleet);
            self.list.len()
        })
    }

    /// `fleet` indices as a C initializer list of local indices.
    pub fn locals(&self, fleet: &[PeerId]) -> String {
        let list: Vec<String> = fleet.iter().map(|&i| self.local(i).to_string()).collect();
        list.join(", ")
    }

    /// The fleet indices asked for that the table lacks, ascending.
    pub fn missing(&self) -> Vec<PeerId> {
        self.missing.borrow().iter().copied().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(rows: &[(&str, &str)]) -> Vec<(String, String)> {
        rows.iter()
            .map(|(t, r)| (t.to_string(), r.to_string()))
            .collect()
    }

    #[test]
    fn a_message_to_a_team_reaches_its_robots_and_to_a_robot_that_robot() {
        let rows = table(&[("A", "a1"), ("B", "b1"), ("A", "a2"), ("B", "b2")]);
        let fleet = Fleet::of(&rows);
        assert_eq!(fleet.addressed("A"), &[PeerId::new(0), PeerId::new(2)]);
        assert_eq!(fleet.addressed("b2"), &[PeerId::new(3)]);
        assert!(fleet.addressed("USER").is_empty());
    }
}
