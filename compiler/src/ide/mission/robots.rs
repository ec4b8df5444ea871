//! Who runs the statements at a place of the file, and what those robots
//! share: the services and values that are valid there.

use crate::catalog::{Catalog, RobotTypeId, ServiceDef, ValueDef};
use crate::sema::{CheckedMission, Mission, Occurrence, RobotId, ScopeKind, TeamId};
use std::sync::Arc;

/// The robots that run the statements at a place, by team.
#[derive(Clone, Debug, Default)]
pub(crate) struct RobotsHere {
    pub runs: Vec<(TeamId, Arc<[RobotId]>)>,
    /// The scope the place is in, if the checker recorded one.
    pub kind: Option<ScopeKind>,
}

impl RobotsHere {
    /// The robots running `offset`: from the innermost scope the checker
    /// recorded there; else (text too broken to be a scope yet) every robot of
    /// `fallback_team`; else unknown (no runs).
    pub fn at(analysis: &CheckedMission, offset: usize, fallback_team: Option<&str>) -> RobotsHere {
        let mission = &analysis.mission;
        if let Some(scope) = mission.scope_at(offset) {
            let runs = scope
                .runs
                .iter()
                .filter_map(|r| Some((r.team?, r.robots.clone())))
                .collect();
            return RobotsHere {
                runs,
                kind: Some(scope.kind),
            };
        }
        let team = fallback_team.and_then(|t| mission.team_by_name(t));
        RobotsHere {
            runs: team
                .map(|t| (t, mission.team(t).robot_ids().collect::<Arc<[RobotId]>>()))
                .into_iter()
                .collect(),
            kind: None,
        }
    }

    /// The robots around the innermost scope at `offset` (outside the
    /// `group` arm the offset is in), if it has a parent scope.
    pub fn around(analysis: &CheckedMission, offset: usize) -> Option<RobotsHere> {
        let mission = &analysis.mission;
        let parent = mission.scope_at(offset)?.parent?;
        let scope = mission.scopes.get(parent as usize)?;
        Some(RobotsHere {
            runs: scope
                .runs
                .iter()
                .filter_map(|r| Some((r.team?, r.robots.clone())))
                .collect(),
            kind: Some(scope.kind),
        })
    }

    pub fn teams(&self) -> Vec<TeamId> {
        let mut teams: Vec<TeamId> = self.runs.iter().map(|(t, _)| *t).collect();
        teams.sort();
        teams.dedup();
        teams
    }

    /// The distinct known robot types of these robots, in order of appearance.
    pub fn types(&self, mission: &Mission) -> Vec<RobotTypeId> {
        let mut types = Vec::new();
        for (team, robots) in &self.runs {
            let t = mission.team(*team);
            for &r in robots.iter() {
                if let Some(ty) = t.robots.get(r.index()).and_then(|r| r.robot_type) {
                    if !types.contains(&ty) {
                        types.push(ty);
                    }
                }
            }
        }
        types
    }

    /// The robots of `team` among these, with the names of each type.
    pub fn robots_of_type(&self, mission: &Mission, ty: RobotTypeId) -> Vec<String> {
        let mut names = Vec::new();
        for (team, robots) in &self.runs {
            let t = mission.team(*team);
            for &r in robots.iter() {
                if let Some(robot) = t.robots.get(r.index())
                    && robot.robot_type == Some(ty)
                {
                    names.push(robot.name.to_string());
                }
            }
        }
        names
    }
}

/// The services that every type of `types` provides (each once, by name), or
/// every service of the catalog when no type is known.
pub(crate) fn shared_services<'c>(
    catalog: &'c Catalog,
    types: &[RobotTypeId],
) -> Vec<&'c ServiceDef> {
    let mut out: Vec<&ServiceDef> = Vec::new();
    match types.split_first() {
        Some((first, rest)) => {
            for s in &catalog.get(*first).services {
                if rest
                    .iter()
                    .all(|ty| catalog.get(*ty).service(&s.name).is_some())
                {
                    out.push(s);
                }
            }
        }
        None => {
            for (_, r) in catalog.types() {
                for s in &r.services {
                    if !out.iter().any(|o| o.name == s.name) {
                        out.push(s);
                    }
                }
            }
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    out
}

/// The values that every type of `types` has, or every value of the catalog
/// when no type is known.
pub(crate) fn shared_values<'c>(catalog: &'c Catalog, types: &[RobotTypeId]) -> Vec<&'c ValueDef> {
    match types.split_first() {
        Some((first, rest)) => {
            let mut out: Vec<&ValueDef> = catalog
                .get(*first)
                .values
                .iter()
                .filter(|v| {
                    rest.iter()
                        .all(|ty| catalog.get(*ty).value(&v.name).is_some())
                })
                .collect();
            out.sort_by(|a, b| a.name.cmp(&b.name));
            out
        }
        None => any_values(
            catalog,
            &catalog.types().map(|(id, _)| id).collect::<Vec<_>>(),
        ),
    }
}

/// The values that some type of `types` has (each once, by name).
pub(crate) fn any_values<'c>(catalog: &'c Catalog, types: &[RobotTypeId]) -> Vec<&'c ValueDef> {
    let mut out: Vec<&ValueDef> = Vec::new();
    for ty in types {
        for v in &catalog.get(*ty).values {
            if !out.iter().any(|o| o.name == v.name) {
                out.push(v);
            }
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    out
}

/// The distinct known robot types of a whole team.
pub(crate) fn team_types(mission: &Mission, team: TeamId) -> Vec<RobotTypeId> {
    let mut types = Vec::new();
    for r in &mission.team(team).robots {
        if let Some(ty) = r.robot_type
            && !types.contains(&ty)
        {
            types.push(ty);
        }
    }
    types
}

/// The names of the catalog types that provide service `name` (by name or alias).
pub(crate) fn service_providers(catalog: &Catalog, name: &str) -> Vec<RobotTypeId> {
    catalog
        .types()
        .filter(|(_, r)| r.service(name).is_some())
        .map(|(id, _)| id)
        .collect()
}

/// The innermost occurrence at `offset` (touching it, so that a cursor right
/// after a name finds it), by binary search: occurrences are sorted by
/// position, and names do not overlap (a name may be recorded more than once).
pub(crate) fn occurrence_at(mission: &Mission, offset: usize) -> Option<&Occurrence> {
    let occurrences = &mission.occurrences;
    let after = occurrences.partition_point(|o| o.span.start <= offset);
    occurrences[..after]
        .iter()
        .rev()
        .take_while(|o| o.span.end >= offset)
        .min_by_key(|o| o.span.len())
}
