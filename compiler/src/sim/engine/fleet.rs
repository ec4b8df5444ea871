//! The fleet's tables: what the engine asks about robots other than the one
//! it runs (names, teams, who a message to a name reaches, each robot's
//! world in the scenario, the network between two robots), made once per
//! run from the programs and the scenario and shared by every robot and by
//! every clone `semo verify` makes ([`Fleet`], behind an `Rc`).
//!
//! Each answer is a look-up: asking them by walking the robots (a robot's
//! world found among the scenario's, its team's peers by comparing names,
//! an operator command's robots, a fault's robot, a partition's groups by
//! name for each message) made a run of a swarm cost the square of its
//! robots.

use super::super::scenario::{FaultKind, RobotWorld, Scenario};
use crate::fasthash::FastMap;
use crate::refine::RobotProgram;
use std::collections::HashMap;
use std::ops::Range;
use std::rc::Rc;
use std::sync::Arc;

/// A robot's names as its messages and trace carry them, shared rather
/// than copied (most of a large run's trace is messages), and each text
/// once for the whole run ([`Interner`]): a message's key is then the same
/// `Rc` as the key a robot listens for, which compares equal without
/// reading either text (a swarm's receptions compared them byte by byte).
pub(super) struct Names {
    pub(super) team: Rc<str>,
    /// Its name (messages carry it; its heartbeat's value is its name as text).
    pub(super) heartbeat: Rc<str>,
    pub(super) alive_key: Rc<str>,
    pub(super) sync_key: Rc<str>,
    /// The key of its team's broadcast events (`refine::event_key`).
    pub(super) event_key: Rc<str>,
    /// Per outgoing message: (to, key).
    pub(super) outgoing: Vec<(Rc<str>, Rc<str>)>,
    /// Per incoming message: (from team, key).
    pub(super) incoming: Vec<(Rc<str>, Rc<str>)>,
    /// Per subscribed group: its key.
    pub(super) subscribed: Vec<Rc<str>>,
}

impl Names {
    fn new(program: &RobotProgram, intern: &mut Interner) -> Names {
        let m = &program.control;
        Names {
            team: intern.text(&program.team),
            heartbeat: intern.text(&program.robot),
            alive_key: intern.text(&crate::refine::protocol::alive_key(program)),
            sync_key: intern.text(&crate::refine::protocol::sync_key(program)),
            event_key: intern.text(&crate::refine::event_key(&program.team)),
            outgoing: m
                .outgoing
                .iter()
                .map(|o| (intern.text(&o.to_team), intern.text(&o.key)))
                .collect(),
            incoming: m
                .incoming
                .iter()
                .map(|i| (intern.text(&i.from_team), intern.text(&i.key)))
                .collect(),
            subscribed: m.subscribed.iter().map(|g| intern.text(g)).collect(),
        }
    }
}

/// One `Rc` per distinct text of the programs' names and keys.
#[derive(Default)]
struct Interner(HashMap<String, Rc<str>>);

impl Interner {
    fn text(&mut self, text: &str) -> Rc<str> {
        if let Some(shared) = self.0.get(text) {
            return shared.clone();
        }
        let shared: Rc<str> = text.into();
        self.0.insert(text.to_string(), shared.clone());
        shared
    }
}

/// The fleet's tables, by robot (program index) unless said otherwise.
pub(super) struct Fleet {
    pub(super) names: Box<[Names]>,
    /// For every team and robot name, the robots (program indices) a
    /// message or an operator command to that name goes to, in program
    /// order: the robots of the team, or the robot itself.
    recipients: FastMap<String, Rc<[usize]>>,
    /// Each robot by its name (the scenario's faults name robots).
    by_name: FastMap<String, usize>,
    /// The peers of the robot's team, among its program's peers (a team
    /// is a run of peers, in formation order): the only robots whose
    /// heartbeats reach it.
    team: Box<[Range<usize>]>,
    /// The robot's entry among the scenario's robots, if it has one.
    world: Box<[Option<usize>]>,
    /// The scenario's network between two robots.
    network: Network,
}

impl Fleet {
    pub(super) fn new(programs: &[RobotProgram], scenario: &Scenario) -> Fleet {
        let mut intern = Interner::default();
        let by_name: FastMap<String, usize> = programs
            .iter()
            .enumerate()
            .map(|(i, p)| (p.robot.clone(), i))
            .collect();
        let mut world = vec![None; programs.len()];
        for (w, entry) in scenario.robots.iter().enumerate() {
            // The first entry of a name counts (a scenario names each once).
            if let Some(&r) = by_name.get(&entry.robot) {
                world[r].get_or_insert(w);
            }
        }
        Fleet {
            names: programs
                .iter()
                .map(|p| Names::new(p, &mut intern))
                .collect(),
            recipients: recipients(programs),
            team: teams(programs),
            world: world.into(),
            network: Network::new(scenario, &by_name, programs.len()),
            by_name,
        }
    }

    /// The robots a message or command to `name` (a team or a robot) goes to.
    pub(super) fn recipients(&self, name: &str) -> Option<&Rc<[usize]>> {
        self.recipients.get(name)
    }

    /// The robot named `robot`.
    pub(super) fn index_of(&self, robot: &str) -> Option<usize> {
        self.by_name.get(robot).copied()
    }

    /// The peers of robot `r`'s team.
    pub(super) fn team(&self, r: usize) -> Range<usize> {
        self.team[r].clone()
    }

    /// Robot `r`'s world in `scenario` (the one the fleet was made with).
    pub(super) fn world<'s>(&self, scenario: &'s Scenario, r: usize) -> Option<&'s RobotWorld> {
        self.world[r].map(|w| &scenario.robots[w])
    }

    /// The scenario's link between robots `a` and `b` (either way round):
    /// an index into its network's links, the first that names them.
    pub(super) fn link(&self, a: usize, b: usize) -> Option<usize> {
        self.network.links.get(&pair(a, b)).copied()
    }

    /// Whether the scenario names no link and no network fault (the
    /// network's latency and loss are then every link's).
    pub(super) fn plain_network(&self) -> bool {
        let network = &self.network;
        network.links.is_empty() && network.pairs.is_empty() && network.partitions.is_empty()
    }

    /// What the scenario's faults do now to a message between robots `a`
    /// and `b`: `None` when one of them loses it (a `drop` of the pair, a
    /// partition between them), else the ms the `delay`s of the pair add.
    pub(super) fn faults(&self, a: usize, b: usize, now: i64) -> Option<i64> {
        let during = |from: i64, until: i64| (from..until).contains(&now);
        let mut added = 0;
        for fault in self.network.pairs.get(&pair(a, b)).into_iter().flatten() {
            match *fault {
                PairFault::Drop { from, until } if during(from, until) => return None,
                PairFault::Delay { by, from, until } if during(from, until) => added += by,
                _ => {}
            }
        }
        for partition in &self.network.partitions {
            if during(partition.from, partition.until) && partition.group[a] != partition.group[b] {
                return None;
            }
        }
        Some(added)
    }
}

/// A pair of robots as the network's tables key it: either way round.
fn pair(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

/// The scenario's links and network faults, by the robots they name.
struct Network {
    /// By pair: the first link naming it.
    links: FastMap<(usize, usize), usize>,
    /// By pair: its `drop` and `delay` faults, in the scenario's order.
    pairs: FastMap<(usize, usize), Vec<PairFault>>,
    partitions: Vec<Partition>,
}

enum PairFault {
    Drop { from: i64, until: i64 },
    Delay { by: i64, from: i64, until: i64 },
}

/// A partition during [from, until): robots of different groups cannot
/// talk, a robot of no group being one more group.
struct Partition {
    /// Per robot: the first of the partition's groups that names it.
    group: Box<[Option<u32>]>,
    from: i64,
    until: i64,
}

impl Network {
    fn new(scenario: &Scenario, by_name: &FastMap<String, usize>, robots: usize) -> Network {
        let robot = |name: &String| by_name.get(name).copied();
        let named = |(a, b): &(String, String)| Some(pair(robot(a)?, robot(b)?));
        let mut links = FastMap::default();
        for (i, link) in scenario.network.links.iter().enumerate() {
            if let Some(between) = named(&link.between) {
                links.entry(between).or_insert(i);
            }
        }
        let mut pairs: FastMap<(usize, usize), Vec<PairFault>> = FastMap::default();
        let mut partitions = Vec::new();
        for fault in &scenario.faults {
            match &fault.kind {
                FaultKind::Drop {
                    between,
                    from,
                    until,
                } => {
                    if let Some(between) = named(between) {
                        let (from, until) = (*from, *until);
                        let fault = PairFault::Drop { from, until };
                        pairs.entry(between).or_default().push(fault);
                    }
                }
                FaultKind::Delay {
                    between,
                    by,
                    from,
                    until,
                } => {
                    if let Some(between) = named(between) {
                        let (by, from, until) = (*by, *from, *until);
                        let fault = PairFault::Delay { by, from, until };
                        pairs.entry(between).or_default().push(fault);
                    }
                }
                FaultKind::Partition {
                    groups,
                    from,
                    until,
                } => {
                    let mut group = vec![None; robots];
                    for (g, members) in groups.iter().enumerate() {
                        for r in members.iter().filter_map(robot) {
                            group[r].get_or_insert(g as u32);
                        }
                    }
                    partitions.push(Partition {
                        group: group.into(),
                        from: *from,
                        until: *until,
                    });
                }
                FaultKind::Kill { .. } | FaultKind::Restart { .. } => {}
            }
        }
        Network {
            links,
            pairs,
            partitions,
        }
    }
}

/// For every team and robot name, the robots (program indices) a message
/// to that name goes to: the robots of the team, or the robot itself.
fn recipients(programs: &[RobotProgram]) -> FastMap<String, Rc<[usize]>> {
    let mut map: FastMap<String, Vec<usize>> = FastMap::default();
    for (i, p) in programs.iter().enumerate() {
        map.entry(p.team.clone()).or_default().push(i);
        if p.robot != p.team {
            map.entry(p.robot.clone()).or_default().push(i);
        }
    }
    map.into_iter().map(|(k, v)| (k, v.into())).collect()
}

/// Per program, the peers of its team: its run of peers (teams are in
/// formation order). Found once per list of peers (the programs of a
/// mission share one), not by walking the team from each robot.
fn teams(programs: &[RobotProgram]) -> Box<[Range<usize>]> {
    type Peers = Arc<[(String, String)]>;
    let mut found: Vec<(&Peers, Rc<[Range<usize>]>)> = Vec::new();
    programs
        .iter()
        .map(|program| {
            let peers = &program.peers;
            let runs = match found.iter().find(|(p, _)| Arc::ptr_eq(p, peers)) {
                Some((_, runs)) => runs.clone(),
                None => {
                    let runs = team_runs(peers);
                    found.push((peers, runs.clone()));
                    runs
                }
            };
            let me = program.self_peer.index();
            runs.get(me).cloned().unwrap_or(me..me)
        })
        .collect()
}

/// Per peer, the run of peers of its team around it.
fn team_runs(peers: &[(String, String)]) -> Rc<[Range<usize>]> {
    let mut runs = Vec::with_capacity(peers.len());
    let mut start = 0;
    while start < peers.len() {
        let team = &peers[start].0;
        let end = start + peers[start..].iter().take_while(|p| p.0 == *team).count();
        runs.extend(std::iter::repeat_n(start..end, end - start));
        start = end;
    }
    runs.into()
}
