//! When a service can run, from the mode machines: each robot starts in its
//! team's default mode (its services run from the first control firing, at
//! the mission's first instant) and changes mode only when a service of its
//! mode throws an event the mode catches; the services of the new mode run
//! from the next firing. So the modes a robot can be in are those reached
//! from the default through catches of events their mode's services throw
//! (a catch that W009 finds never firing leads nowhere), and a service runs
//! only in those of them that set it.

use crate::fasthash::{FastMap, FastSet};
use crate::sema::ir::{Mission, ModeId, ServiceId, Team, TeamId};

pub(super) struct Timeline {
    teams: Vec<TeamTimeline>,
}

#[derive(Default)]
struct TeamTimeline {
    /// The mode the robots start in; `None` when the team has no main
    /// block (its robots run nothing).
    start: Option<ModeId>,
    /// Whether a catch can lead into the start mode again (its services
    /// then start again later).
    start_again: bool,
    /// Per service: the modes the robots can be in that set it, in order.
    modes: Vec<Vec<ModeId>>,
}

impl Timeline {
    pub fn new(mission: &Mission) -> Timeline {
        Timeline {
            teams: mission.teams.iter().map(TeamTimeline::new).collect(),
        }
    }

    /// The modes the robots can be in that run `service`.
    pub fn modes(&self, team: TeamId, service: ServiceId) -> &[ModeId] {
        &self.teams[team.0 as usize].modes[service.index()]
    }

    /// Whether `service` runs at all.
    pub fn runs(&self, team: TeamId, service: ServiceId) -> bool {
        !self.modes(team, service).is_empty()
    }

    /// Whether `service` runs from the mission's first instant (its team's
    /// robots start in a mode that sets it).
    pub fn runs_at_start(&self, team: TeamId, service: ServiceId) -> bool {
        let start = self.teams[team.0 as usize].start;
        // The modes are in order (`TeamTimeline::new`).
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
}

impl TeamTimeline {
    fn new(team: &Team) -> TeamTimeline {
        let mut timeline = TeamTimeline {
            modes: vec![Vec::new(); team.services.len()],
            ..TeamTimeline::default()
        };
        let Some(main) = &team.main else {
            return timeline;
        };
        let Some(start) = main.default else {
            return timeline;
        };
        let mut leaving: FastMap<ModeId, Vec<ModeId>> = FastMap::default();
        for tr in main.transitions.iter().filter(|tr| !tr.never_thrown) {
            leaving.entry(tr.from).or_default().push(tr.to);
            timeline.start_again |= tr.to == start;
        }
        let mut reached = FastSet::from_iter([start]);
        let mut queue = vec![start];
        while let Some(mode) = queue.pop() {
            for &to in leaving.get(&mode).into_iter().flatten() {
                if reached.insert(to) {
                    queue.push(to);
                }
            }
        }
        // In mode order, so that messages name modes as written.
        for mode in team.mode_ids().filter(|m| reached.contains(m)) {
            for service in team.modes[mode.index()]
                .sets
                .iter()
                .filter_map(|s| s.service)
            {
                let modes = &mut timeline.modes[service.index()];
                if modes.last() != Some(&mode) {
                    modes.push(mode);
                }
            }
        }
        timeline.start = Some(start);
        timeline
    }
}
