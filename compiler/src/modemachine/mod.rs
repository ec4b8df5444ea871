//! A team's mode machine: its modes, the mode it starts in (`default` in its
//! `main` block) and the mode changes `main` makes on events
//! (`case (FROM): catch (EVENT): mode = TO`), read from the Mission IR.
//! [`to_svg`] draws the machines of a mission (`semo graph modes`, the
//! language server's `semo/graphSvg` for missions).

mod svg;
#[cfg(test)]
mod tests;

use crate::sema::{Mission, ModeId};
use crate::syntax::ast::Name;

pub use svg::to_svg;

/// One team's modes and mode changes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModeMachine {
    pub team: Name,
    /// Every mode of the team, in the order they are written.
    pub modes: Vec<Name>,
    /// The index in `modes` of the mode the team starts in.
    pub default: Option<usize>,
    /// The modes the checker found can never be entered (W002).
    pub unreachable: Vec<usize>,
    /// The mode changes, one per (from, to) pair, with the events that make
    /// it in the order they are written.
    pub changes: Vec<ModeChange>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModeChange {
    pub from: usize,
    pub to: usize,
    pub events: Vec<Name>,
    /// The events of `events` that no service of the `from` mode throws, as
    /// the checker found (W009): those catches never fire.
    pub never_thrown: Vec<Name>,
}

impl ModeChange {
    /// Whether no event of this change is ever thrown in its `from` mode.
    pub fn is_dead(&self) -> bool {
        self.events.iter().all(|e| self.never_thrown.contains(e))
    }
}

/// The mode machine of each team of `mission` that has modes, in the order
/// the teams are declared.
pub fn machines(mission: &Mission) -> Vec<ModeMachine> {
    mission
        .teams
        .iter()
        .filter(|team| !team.modes.is_empty())
        .map(|team| {
            let modes: Vec<Name> = team.modes.iter().map(|m| m.name.clone()).collect();
            let valid = |i: ModeId| i.index() < modes.len();
            let mut changes: Vec<ModeChange> = Vec::new();
            let main = team.main.as_ref();
            for t in main.iter().flat_map(|m| &m.transitions) {
                if !valid(t.from) || !valid(t.to) {
                    continue;
                }
                let (from, to) = (t.from.index(), t.to.index());
                let change = match changes.iter().position(|c| c.from == from && c.to == to) {
                    Some(i) => &mut changes[i],
                    None => {
                        changes.push(ModeChange {
                            from,
                            to,
                            events: Vec::new(),
                            never_thrown: Vec::new(),
                        });
                        changes.last_mut().expect("just pushed")
                    }
                };
                if !change.events.contains(&t.event) {
                    change.events.push(t.event.clone());
                }
                if t.never_thrown && !change.never_thrown.contains(&t.event) {
                    change.never_thrown.push(t.event.clone());
                }
            }
            ModeMachine {
                team: team.name.clone(),
                default: main
                    .and_then(|m| m.default)
                    .filter(|&d| valid(d))
                    .map(|d| d.index()),
                unreachable: main
                    .iter()
                    .flat_map(|m| &m.unreachable)
                    .filter(|&&i| valid(i))
                    .map(|&i| i.index())
                    .collect(),
                modes,
                changes,
            }
        })
        .collect()
}
