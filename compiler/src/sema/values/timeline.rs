//! When a service can run, from the mode machines: each robot starts in its
//! team's default mode (its services run from the first control firing, at
//! the mission's first instant) and changes mode only when a service of its
//! mode throws an event the mode catches; the services of the new mode run
//! from the next firing. So the modes a robot can be in are those reached
//! from the default through catches of events their mode's services throw
//! (a catch that W009 finds never firing leads nowhere), and a service runs
//! only in those of them that set it.
//!
//! Built on every check: flat vectors and buffers reused from team to team,
//! no map and no allocation per team or service.

use crate::sema::ir::{Mission, ModeId, ServiceId, Team, TeamId};
use std::ops::Range;

pub(super) struct Timeline {
    teams: Vec<TeamTimeline>,
    /// Per service of every team, the teams' one after the other (from
    /// `TeamTimeline::services`): where its modes are in `modes`.
    services: Vec<Range<u32>>,
    /// The modes the robots can be in that set each service, in order.
    modes: Vec<ModeId>,
}

struct TeamTimeline {
    /// The mode the robots start in; `None` when the team has no main
    /// block (its robots run nothing).
    start: Option<ModeId>,
    /// Whether a catch can lead into the start mode again (its services
    /// then start again later).
    start_again: bool,
    /// Where the team's services are in `Timeline::services`.
    services: u32,
}

/// What one team's pass needs, kept from team to team.
#[derive(Default)]
struct Buffers {
    /// The catches that can fire, as (from, to), sorted.
    edges: Vec<(ModeId, ModeId)>,
    reached: Vec<bool>,
    stack: Vec<ModeId>,
    /// (service, mode) for every `set` of a reached mode.
    sets: Vec<(ServiceId, ModeId)>,
}

impl Timeline {
    pub fn new(mission: &Mission) -> Timeline {
        let services = mission.teams.iter().map(|t| t.services.len()).sum();
        let mut timeline = Timeline {
            teams: Vec::with_capacity(mission.teams.len()),
            services: Vec::with_capacity(services),
            modes: Vec::new(),
        };
        let mut buffers = Buffers::default();
        for team in &mission.teams {
            timeline.add_team(team, &mut buffers);
        }
        timeline
    }

    /// The modes the robots can be in that run `service`, in order.
    pub fn modes(&self, team: TeamId, service: ServiceId) -> &[ModeId] {
        let first = self.teams[team.0 as usize].services as usize;
        let range = &self.services[first + service.index()];
        &self.modes[range.start as usize..range.end as usize]
    }

    /// Whether `service` runs at all.
    pub fn runs(&self, team: TeamId, service: ServiceId) -> bool {
        !self.modes(team, service).is_empty()
    }

    /// Whether `service` runs from the mission's first instant (its team's
    /// robots start in a mode that sets it).
    pub fn runs_at_start(&self, team: TeamId, service: ServiceId) -> bool {
        let start = self.teams[team.0 as usize].start;
        start.is_some_and(|start| self.modes(team, service).binary_search(&start).is_ok())
    }

    /// The start mode, when `service` starts only there and only once: at
    /// the mission's first instant, in a mode no catch leads back to, and
    /// in no other mode the robots can be in.
    pub fn starts_only_at_start(&self, team: TeamId, service: ServiceId) -> Option<ModeId> {
        let timeline = &self.teams[team.0 as usize];
        let start = timeline.start.filter(|_| !timeline.start_again)?;
        (self.modes(team, service) == [start]).then_some(start)
    }

    fn add_team(&mut self, team: &Team, buffers: &mut Buffers) {
        let first = self.services.len() as u32;
        let start = team.main.as_ref().and_then(|main| main.default);
        let mut start_again = false;
        buffers.sets.clear();
        if let (Some(main), Some(start)) = (&team.main, start) {
            buffers.edges.clear();
            for tr in main.transitions.iter().filter(|tr| !tr.never_thrown) {
                buffers.edges.push((tr.from, tr.to));
                start_again |= tr.to == start;
            }
            buffers.edges.sort_unstable();
            reach(start, team.modes.len(), buffers);
            for mode in team.mode_ids().filter(|m| buffers.reached[m.index()]) {
                let sets = &team.modes[mode.index()].sets;
                let services = sets.iter().filter_map(|s| s.service);
                buffers.sets.extend(services.map(|s| (s, mode)));
            }
            // By service, each one's modes in order, once.
            buffers.sets.sort_unstable();
            buffers.sets.dedup();
        }
        let mut sets = buffers.sets.iter().peekable();
        for service in team.service_ids() {
            let from = self.modes.len() as u32;
            while let Some(&(_, mode)) = sets.next_if(|(s, _)| *s == service) {
                self.modes.push(mode);
            }
            self.services.push(from..self.modes.len() as u32);
        }
        self.teams.push(TeamTimeline {
            start,
            start_again,
            services: first,
        });
    }
}

/// Marks in `buffers.reached` the modes reached from `start` through
/// `buffers.edges` (sorted by their first mode).
fn reach(start: ModeId, modes: usize, buffers: &mut Buffers) {
    buffers.reached.clear();
    buffers.reached.resize(modes, false);
    buffers.reached[start.index()] = true;
    buffers.stack.clear();
    buffers.stack.push(start);
    while let Some(mode) = buffers.stack.pop() {
        let from = buffers.edges.partition_point(|&(m, _)| m < mode);
        for &(m, to) in &buffers.edges[from..] {
            if m != mode {
                break;
            }
            if !buffers.reached[to.index()] {
                buffers.reached[to.index()] = true;
                buffers.stack.push(to);
            }
        }
    }
}
