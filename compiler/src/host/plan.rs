//! What "build this mission" means, decided once for every door: `semo
//! build` on the command line and the editor's Generate Code ask
//! [`Analysis::build_plan`] with what their user said, and get the same
//! target, output folder and deployment file: what the door says, else the
//! project file's `[build]`, else the defaults (`linux`, `out` beside the
//! mission, no deployment).

use crate::codegen::Target;
use crate::diag::FileId;
use crate::host::Analysis;
use std::path::{Path, PathBuf};

/// What a door's user said (each `None`: not said).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PlanRequest {
    pub target: Option<Target>,
    /// The output folder, as a path the door resolved (the CLI: against the
    /// current folder; the editor: against the mission's folder).
    pub output: Option<PathBuf>,
    pub deployment: Option<PathBuf>,
}

/// Where and for what a mission's code is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildPlan {
    pub target: Target,
    pub output: PathBuf,
    pub deployment: Option<PathBuf>,
}

/// The output folder when neither the door nor the project says: `out`
/// beside the mission.
pub const DEFAULT_OUTPUT: &str = "out";

impl Analysis {
    /// The plan for building `mission` (saved at `mission_path`), given
    /// what the door's user asked.
    pub fn build_plan(
        &self,
        mission: FileId,
        mission_path: &Path,
        asked: PlanRequest,
    ) -> BuildPlan {
        let project = self.project(mission);
        let project = project.as_ref().map(|p| &p.project);
        let target = asked
            .target
            .or(project.and_then(|p| p.target))
            .unwrap_or(Target::Linux);
        let output = asked
            .output
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
        let deployment = asked.deployment.or_else(|| {
            project
                .and_then(|p| p.deployment.as_ref())
                .map(|d| d.path.clone())
        });
        BuildPlan {
            target,
            output,
            deployment,
        }
    }
}
