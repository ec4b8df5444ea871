//! Editor features for strategy files, as plain data with byte ranges (the
//! language server turns them into protocol types):
//!
//! - `raw`: the XML around the cursor read from the text itself, so that
//!   half-typed tags (`<Serv`, `name="`) are understood;
//! - `completion`: element names allowed in the parent, missing attributes,
//!   and attribute values from the missions and the catalog;
//! - `hover`: what elements and attributes mean, and what names refer to;
//! - `navigation`: from strategy entries to the mission lines they refine and
//!   back, and to team, plan and robot type definitions;
//! - `symbols`: the outline (values, services and their actions);
//! - `code_actions`: escapes, did-you-means, and creating the entry for a
//!   mission call that has none.

pub mod code_actions;
pub mod completion;
pub mod hover;
pub mod navigation;
pub mod raw;
pub mod symbols;

use crate::catalog::{Catalog, RobotType, RobotTypeId};
use crate::sema::{CheckedMission, Team, TeamId};
use crate::strategy::model::{ServiceEntry, Strategy, TargetRobot, ValueEntry};

/// What the editor features of one strategy file read: its text, its model
/// (`None` when it has no `<Strategy>` yet), the workspace's missions and the
/// catalog.
#[derive(Clone, Copy)]
pub struct StrategyFile<'a> {
    pub text: &'a str,
    pub strategy: Option<&'a Strategy>,
    pub missions: &'a [&'a CheckedMission],
    pub catalog: &'a Catalog,
}

impl<'a> StrategyFile<'a> {
    /// The strategy's team: from the model, else (the file does not load
    /// yet) from the `<Strategy name="...">` tag as written.
    pub fn team_name(&self) -> Option<&'a str> {
        if let Some(team) = self.strategy.and_then(|s| s.team.as_ref()) {
            return Some(&team.name);
        }
        let start = self.text.find("<Strategy")?;
        raw::read_tag(self.text, start).value("name").map(str::trim)
    }

    /// The strategy's team in each mission that declares it.
    pub fn teams(&self) -> Vec<(&'a CheckedMission, TeamId, &'a Team)> {
        let Some(name) = self.team_name() else {
            return Vec::new();
        };
        self.missions
            .iter()
            .filter_map(|a| {
                let id = a.mission.team_by_name(name)?;
                Some((*a, id, a.mission.team(id)))
            })
            .collect()
    }

    /// The robot types of the strategy's team (in mission order, once each).
    pub fn team_types(&self) -> Vec<RobotTypeId> {
        let mut out = Vec::new();
        for (_, _, team) in self.teams() {
            for id in team.robots.iter().filter_map(|r| r.robot_type) {
                if !out.contains(&id) {
                    out.push(id);
                }
            }
        }
        out
    }

    /// The team's robot types, else (no mission declares the team) every
    /// robot type of the catalog.
    pub fn team_or_catalog_types(&self) -> Vec<&'a RobotType> {
        let team = self.team_types();
        if team.is_empty() {
            return self.catalog.types().map(|(_, r)| r).collect();
        }
        team.into_iter().map(|id| self.catalog.get(id)).collect()
    }

    /// The known robot types among `targets`, else the team's.
    pub fn types_for(&self, targets: &[TargetRobot]) -> Vec<&'a RobotType> {
        let named: Vec<RobotTypeId> = targets
            .iter()
            .filter_map(|t| t.name.as_ref())
            .filter_map(|n| self.catalog.lookup(&n.name))
            .collect();
        let ids = if named.is_empty() {
            self.team_types()
        } else {
            named
        };
        ids.into_iter().map(|id| self.catalog.get(id)).collect()
    }

    /// The `<Service>` entry around `offset` (also one cut short by an error).
    pub fn service_at(&self, offset: usize) -> Option<(usize, &'a ServiceEntry)> {
        let services = &self.strategy?.services;
        services
            .iter()
            .enumerate()
            .rev()
            .find(|(_, s)| s.tag.start < offset && (offset <= s.span.end || !s.complete))
    }

    /// The `<Value>` entry around `offset`.
    pub fn value_at(&self, offset: usize) -> Option<&'a ValueEntry> {
        let values = &self.strategy?.values;
        values
            .iter()
            .rev()
            .find(|v| v.tag.start < offset && offset <= v.span.end)
    }

    /// The target robot types of the entry around `offset`, else the team's.
    pub fn types_at(&self, offset: usize) -> Vec<&'a RobotType> {
        if let Some((_, service)) = self.service_at(offset) {
            return self.types_for(&service.targets);
        }
        if let Some(value) = self.value_at(offset) {
            return self.types_for(&value.targets);
        }
        self.types_for(&[])
    }
}

/// `names` once each, in their first order.
fn distinct(names: impl IntoIterator<Item = String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for name in names {
        if !out.contains(&name) {
            out.push(name);
        }
    }
    out
}

#[cfg(test)]
mod tests;
