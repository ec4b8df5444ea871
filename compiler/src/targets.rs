//! Which target each robot of a build is for, and why: [`Chosen`], a
//! robot's target with its [`Reason`] (the door asked it for every robot,
//! the project file says it, the robot type's platform in the catalog, or
//! the default), and [`Targets`], each robot's by name. The build plan
//! (`host::Analysis::build_plan`) decides them; code generation (`codegen`)
//! reads them, and names the reason in what a target refuses. Below both,
//! so that the analysis host does not read the C generator.

use crate::diag::FileId;
use crate::platform::Target;
use crate::span::Span;

/// `targets` each once, in [`Target::ALL`]'s order.
pub fn distinct(targets: impl IntoIterator<Item = Target>) -> Vec<Target> {
    let used: Vec<Target> = targets.into_iter().collect();
    Target::ALL
        .into_iter()
        .filter(|t| used.contains(t))
        .collect()
}

/// Why a robot is generated for its target: the messages of what the
/// target refuses say it, and point at where it was said.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reason {
    /// The door's user asked it for every robot (`semo build --target`,
    /// the editor's `target`).
    Asked,
    /// The project file says it (`[build] target` for every robot, or
    /// `[build.targets]` for the robot or its team): the key as written,
    /// and where its value is.
    Project { key: String, at: FileId, span: Span },
    /// The robot's type names its platform in the catalog (`<Platform
    /// target="...">`), there.
    Catalog {
        robot_type: String,
        at: FileId,
        span: Span,
    },
    /// Nobody said: the default platform, `linux`.
    Default,
}

/// A robot's target and why; `simulated`: `--sim` turned the chosen
/// platform into its simulation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chosen {
    pub target: Target,
    pub reason: Reason,
    pub simulated: bool,
}

impl Chosen {
    /// How the target came to be, for messages: `cortex-m, as its type
    /// `Evalbot` says in the catalog`.
    pub fn describe(&self) -> String {
        let why = match &self.reason {
            Reason::Asked => "as the build asked for every robot".to_string(),
            Reason::Project { key, .. } => format!("as the project file's `{key}` says"),
            Reason::Catalog { robot_type, .. } => {
                format!("the platform its type `{robot_type}` names in the catalog")
            }
            Reason::Default => "the default platform".to_string(),
        };
        let sim = if self.simulated {
            " (simulated: --sim)"
        } else {
            ""
        };
        format!("{}{sim}, {why}", self.target.name())
    }

    /// Where the target was written, if in a file.
    pub fn written_at(&self) -> Option<(FileId, Span)> {
        match &self.reason {
            Reason::Project { at, span, .. } | Reason::Catalog { at, span, .. } => {
                Some((*at, *span))
            }
            Reason::Asked | Reason::Default => None,
        }
    }
}

/// The target of each robot of a build, by robot name (what the build plan
/// decided, `host::Analysis::build_plan`); or one target for every robot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Targets {
    every: Option<Chosen>,
    robots: std::collections::BTreeMap<String, Chosen>,
}

impl Targets {
    /// `target` for every robot, as asked.
    pub fn all(target: Target) -> Targets {
        Targets {
            every: Some(Chosen {
                target,
                reason: Reason::Asked,
                simulated: false,
            }),
            robots: Default::default(),
        }
    }

    /// Each robot's own (a robot not named has none: an internal error).
    pub fn each(robots: impl IntoIterator<Item = (String, Chosen)>) -> Targets {
        Targets {
            every: None,
            robots: robots.into_iter().collect(),
        }
    }

    /// The target of robot `robot`.
    pub fn of(&self, robot: &str) -> Option<&Chosen> {
        self.robots.get(robot).or(self.every.as_ref())
    }
}
