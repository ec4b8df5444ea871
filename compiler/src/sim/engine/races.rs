//! Races between the plans of one robot in one instant, for `semo verify`
//! (V005). A control firing runs the plans of the mode one after another,
//! in the order the mode sets them; the first caught `throw` ends the mode
//! at the end of the firing, and the plans that had not run yet in it do
//! not run again in that mode. When one of them would have sent a message
//! or thrown a caught event of its own in that instant, what the team does
//! depends on the order of two things that happen at once: the mission
//! wrote them as concurrent plans, and one of them wins only by its place.
//! (Publishes and reports to the operator are left out: a publish's next
//! value replaces it, and the team does not act on a report.)
//!
//! Looked for only when asked ([`Sim::watch_races`]): at each firing that
//! changes the mode, each later plan runs on a copy of the robot's state
//! as if the throw had not been, until it waits; a send or a caught throw
//! on the way is the race. The run itself is not changed.

use super::{STEPS_PER_FIRING, Sim, Step};
use crate::refine::{ModeId, ServiceMachineId, StateId, StateKind};

/// A plan's caught `throw` ended the mode in an instant in which a later
/// plan of the mode would have sent a message or thrown a caught event.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Race {
    /// The robot (an index into the programs).
    pub robot: usize,
    /// Mission ms of the instant.
    pub at: i64,
    /// The mode that ended.
    pub mode: ModeId,
    /// (service, state) of the throw that ended it.
    pub thrower: (ServiceMachineId, StateId),
    /// (service, state) of the send or throw that did not happen.
    pub lost: (ServiceMachineId, StateId),
}

impl Sim<'_> {
    /// From now on, note every race ([`Sim::take_races`]).
    pub fn watch_races(&mut self) {
        self.races.get_or_insert_with(Vec::new);
    }

    /// The races noted since the last call.
    pub fn take_races(&mut self) -> Vec<Race> {
        self.races.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Robot `r`'s plan in region `thrower_region` has just thrown, at
    /// state `thrower_state`, the event that ends its mode in this firing:
    /// notes each later plan that would have sent or thrown in it.
    pub(super) fn look_for_races(&mut self, r: usize, thrower_region: usize, thrower_state: usize) {
        if self.races.is_none() {
            return;
        }
        let robot = &self.robots[r];
        let (Some(mode), Some(thrower_service)) =
            (robot.current_mode, robot.regions[thrower_region].service)
        else {
            return;
        };
        let m = &robot.program.control;
        let caught = |event: &str| {
            m.transitions
                .iter()
                .any(|t| t.from == mode && t.event == event)
        };
        // A send to another robot; not a publish (its latest value stands
        // for the next one) and not a report to the operator's console,
        // which the team does not act on. Or a throw the mode catches.
        let acts = |state: &crate::refine::State| match &state.kind {
            StateKind::Send { items } => items.iter().any(|item| {
                let message = m.outgoing_message(item.message);
                !message.publish && message.to_team != "USER"
            }),
            StateKind::Throw { event, .. } => caught(event),
            _ => false,
        };
        let mut found = Vec::new();
        for j in thrower_region + 1..robot.regions.len() {
            let region = &robot.regions[j];
            let Some(service) = region.service else {
                continue;
            };
            let timed_out = region.timeout_ms > 0 && self.now - region.started > region.timeout_ms;
            // Copying the fleet's state costs in proportion to the fleet:
            // only for a plan whose service can act at all.
            if region.done || timed_out || !m.service(service).states.iter().any(acts) {
                continue;
            }
            // The plan's turn as it would have come without the throw.
            let mut alone = self.clone();
            alone.races = None;
            alone.robots[r].pending_mode = None;
            for _ in 0..STEPS_PER_FIRING {
                let pc = alone.robots[r].regions[j].pc;
                let Some(state) = m.service(service).states.get(pc) else {
                    break;
                };
                let acting = acts(state);
                if alone.step(r, j, service) != Step::Next {
                    break;
                }
                if acting {
                    found.push(Race {
                        robot: r,
                        at: self.now,
                        mode,
                        thrower: (thrower_service, StateId::new(thrower_state)),
                        lost: (service, StateId::new(pc)),
                    });
                    break;
                }
                if alone.robots[r].pending_mode.is_some() {
                    break;
                }
            }
        }
        if let Some(races) = self.races.as_mut() {
            races.extend(found);
        }
    }
}
