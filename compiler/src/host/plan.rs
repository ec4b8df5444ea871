//! What "build this mission" means, decided once for every door: `semo
//! build` on the command line and the editor's Generate Code ask
//! [`Analysis::build_plan`] with what their user said, and get the same
//! targets, output folder and deployment file.
//!
//! Each robot gets its own target, the first of: what the door says for
//! every robot (`--target`); the project file's `[build.targets]` for the
//! robot (its name, or its `name[N]` declaration's), then for its team;
//! the project file's `[build] target`, for every robot; the platform its
//! robot type names in the catalog (`<Platform target="cortex-m">`); else
//! `linux`. With `sim` (`--sim`), each is then its platform's simulation.
//! The output folder and the deployment are the door's, else the project
//! file's `[build]`, else `out` beside the mission and none.

use crate::diag::{Diagnostic, FileId};
use crate::host::Analysis;
use crate::platform::Target;
use crate::project::{NamedTarget, ProjectTarget};
use crate::targets::{Chosen, Reason, Targets};
use std::path::{Path, PathBuf};

/// What a door's user said (each `None`, or `false`: not said).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PlanRequest {
    /// Every robot's target.
    pub target: Option<Target>,
    /// Every robot built for its platform's simulation (`--sim`).
    pub sim: bool,
    /// The output folder, as a path the door resolved (the CLI: against the
    /// current folder; the editor: against the mission's folder).
    pub output: Option<PathBuf>,
    pub deployment: Option<PathBuf>,
}

/// One robot of the plan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlannedRobot {
    pub team: String,
    pub robot: String,
    pub chosen: Chosen,
}

/// Where and for what a mission's code is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildPlan {
    /// Every robot of the mission, in formation order, with its target.
    pub robots: Vec<PlannedRobot>,
    pub output: PathBuf,
    pub deployment: Option<PathBuf>,
    /// What the plan found wrong in the project file: `[build.targets]`
    /// names that are no team or robot of the mission (W110), at the
    /// project's levels.
    pub diagnostics: Vec<Diagnostic>,
}

impl BuildPlan {
    /// Each robot's target, as code generation takes them.
    pub fn targets(&self) -> Targets {
        Targets::each(
            self.robots
                .iter()
                .map(|r| (r.robot.clone(), r.chosen.clone())),
        )
    }

    /// The targets of its robots, each once, in [`Target::ALL`]'s order.
    pub fn distinct_targets(&self) -> Vec<Target> {
        crate::targets::distinct(self.robots.iter().map(|r| r.chosen.target))
    }

    /// The target of robot `robot`.
    pub fn target_of(&self, robot: &str) -> Option<&Chosen> {
        self.robots
            .iter()
            .find(|r| r.robot == robot)
            .map(|r| &r.chosen)
    }
}

/// The output folder when neither the door nor the project says: `out`
/// beside the mission.
pub const DEFAULT_OUTPUT: &str = "out";

/// The platform a robot is built for when nobody says.
pub const DEFAULT_TARGET: Target = Target::Linux;

impl Analysis {
    /// The plan for building `mission` (saved at `mission_path`), given
    /// what the door's user asked.
    pub fn build_plan(
        &self,
        mission: FileId,
        mission_path: &Path,
        asked: PlanRequest,
    ) -> BuildPlan {
        let loaded = self.project(mission);
        let project = loaded.as_ref().map(|p| &p.project);
        let output = asked
            .output
            .clone()
            .or_else(|| {
                project
                    .and_then(|p| p.output.as_ref())
                    .map(|o| o.path.clone())
            })
            .unwrap_or_else(|| {
                mission_path
                    .parent()
                    .unwrap_or(Path::new("."))
                    .join(DEFAULT_OUTPUT)
            });
        let deployment = asked.deployment.clone().or_else(|| {
            project
                .and_then(|p| p.deployment.as_ref())
                .map(|d| d.path.clone())
        });
        let (robots, known) = self.robot_targets(mission, &asked);
        let mut diagnostics = Vec::new();
        if let Some(loaded) = &loaded {
            let name = mission_path
                .file_name()
                .map_or_else(|| "the mission".into(), |n| n.to_string_lossy());
            let known: Vec<&str> = known.iter().map(String::as_str).collect();
            diagnostics = loaded.project.unknown_names(loaded.file, &name, &known);
            loaded.project.apply_lints(&mut diagnostics);
        }
        BuildPlan {
            robots,
            output,
            deployment,
            diagnostics,
        }
    }

    /// Each robot of `mission` with its target (module documentation), and
    /// the names a `[build.targets]` key may have there (its teams, robots
    /// and robot declarations).
    fn robot_targets(
        &self,
        mission: FileId,
        asked: &PlanRequest,
    ) -> (Vec<PlannedRobot>, Vec<String>) {
        let (Some(analysis), Some(file)) = (self.mission(mission), self.file(mission)) else {
            return (Vec::new(), Vec::new());
        };
        let loaded = self.project(mission);
        let catalog = self.catalog(mission);
        let project = loaded.as_ref().map(|p| (p.file, &p.project));
        let from_project = |key: String, target: &ProjectTarget| {
            let (file, _) = project.expect("a target read from the project file");
            (
                target.target,
                Reason::Project {
                    key,
                    at: file,
                    span: target.span,
                },
            )
        };
        let named = |name: &str| -> Option<&NamedTarget> {
            project.and_then(|(_, p)| p.targets.iter().find(|t| t.name == name))
        };
        let mut robots = Vec::new();
        let mut known: Vec<String> = Vec::new();
        for team in &analysis.mission.teams {
            known.push(team.name.to_string());
            for robot in &team.robots {
                let declared = file
                    .text
                    .get(robot.name_span.start..robot.name_span.end)
                    .unwrap_or_default();
                known.push(robot.name.to_string());
                known.push(declared.to_string());
                let by_name = [robot.name.as_str(), declared, team.name.as_str()]
                    .into_iter()
                    .find_map(named);
                let catalog_target = robot
                    .robot_type
                    .map(|id| catalog.catalog.get(id))
                    .and_then(|t| t.platform.target.map(|(target, span)| (t, target, span)));
                let (target, reason) = if let Some(target) = asked.target {
                    (target, Reason::Asked)
                } else if let Some(named) = by_name {
                    from_project(format!("[build.targets] {}", named.name), &named.target)
                } else if let Some(every) = project.and_then(|(_, p)| p.target.as_ref()) {
                    from_project("[build] target".into(), every)
                } else if let Some((robot_type, target, span)) = catalog_target {
                    let reason = Reason::Catalog {
                        robot_type: robot_type.name.clone(),
                        at: robot_type.origin.file,
                        span,
                    };
                    (target, reason)
                } else {
                    (DEFAULT_TARGET, Reason::Default)
                };
                let simulated = asked.sim && !target.simulated();
                let target = if asked.sim {
                    target.simulation()
                } else {
                    target
                };
                robots.push(PlannedRobot {
                    team: team.name.to_string(),
                    robot: robot.name.to_string(),
                    chosen: Chosen {
                        target,
                        reason,
                        simulated,
                    },
                });
            }
        }
        known.sort();
        known.dedup();
        (robots, known)
    }
}

impl Analysis {
    /// The teams and robots of the missions of the project file `project`
    /// (whose project it is), for completing `[build.targets]` keys: each
    /// name once, with what it is.
    pub(crate) fn project_names(&self, project: FileId) -> Vec<crate::project::Named> {
        let mut named: Vec<crate::project::Named> = Vec::new();
        let missions = self.files().filter(|f| {
            f.kind == crate::workspace::FileKind::Mission
                && self.project(f.id).is_some_and(|p| p.file == project)
        });
        let mut missions: Vec<_> = missions.collect();
        missions.sort_by_key(|f| f.path.clone());
        for file in missions {
            let Some(analysis) = self.mission(file.id) else {
                continue;
            };
            let in_mission = file
                .path
                .as_ref()
                .and_then(|p| p.file_name())
                .map_or_else(String::new, |n| format!(", {}", n.to_string_lossy()));
            let mut add = |name: &str, detail: String| {
                if !named.iter().any(|n| n.name == name) {
                    named.push(crate::project::Named {
                        name: name.to_string(),
                        detail,
                    });
                }
            };
            for team in &analysis.mission.teams {
                add(&team.name, format!("team{in_mission}"));
                for robot in &team.robots {
                    let detail = format!(
                        "robot of team {} ({}){in_mission}",
                        team.name, robot.type_name
                    );
                    add(&robot.name, detail);
                }
            }
        }
        named
    }
}
