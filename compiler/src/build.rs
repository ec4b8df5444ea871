//! One build of a mission, the same for every door: `semo build` and the
//! editor's Generate Code both ask [`generate`] with the plan's targets and,
//! for a simulated robot, the scenario's text, and only render what it gives
//! (the CLI as text or JSON, the server as the request's error or the
//! mission's diagnostics).
//!
//! The mission's refined programs are the analysis host's memoised query
//! (`host::Analysis::refined`); a refusal stops there, its diagnostics in the
//! build's result. Otherwise the scenario, if any, is read by the
//! simulator's one reader against those programs (its names are the
//! programs'), each robot's world compiled from it (`refine::CompiledScenario`)
//! and handed to the C generator. So this module stands above both back ends,
//! which read neither each other nor it.

use crate::codegen::{self, BuildResult, Emit};
use crate::diag::FileId;
use crate::host::Analysis;
use crate::sim::scenario::{self, ScenarioError};
use crate::targets::Targets;

/// A build that ran: its result (which may be a refusal, with its
/// diagnostics) and the scenario's warnings (a sensor value no robot
/// samples), for the door to show beside it.
pub struct Built {
    pub result: BuildResult,
    pub scenario_warnings: Vec<ScenarioError>,
}

/// Why a build did not run.
#[derive(Clone, Debug, PartialEq)]
pub enum NotBuilt {
    /// The file is no mission of the analysis: the door's mistake.
    NoMission,
    /// The scenario's mistake, positioned in its text.
    Scenario(ScenarioError),
}

/// Builds `mission` with each robot for its target in `targets`. `scenario`:
/// the text of the scenario compiled into the robots whose target
/// [needs one](crate::platform::Target::needs_scenario); the mission's own
/// errors come before any of the scenario's.
pub fn generate(
    analysis: &Analysis,
    mission: FileId,
    targets: &Targets,
    emit: Emit,
    scenario: Option<&str>,
) -> Result<Built, NotBuilt> {
    let files = analysis.build_input(mission).ok_or(NotBuilt::NoMission)?;
    let refined = analysis.refined(mission).ok_or(NotBuilt::NoMission)?;
    let mut scenario_warnings = Vec::new();
    let worlds = match scenario {
        // Refused: nothing to compile a world into.
        Some(text) if !refined.programs.is_empty() => {
            let mut read = scenario::parse(text, &refined.programs).map_err(NotBuilt::Scenario)?;
            scenario_warnings = std::mem::take(&mut read.warnings);
            read.compiled_for_each(&refined.programs)
        }
        _ => Vec::new(),
    };
    let result = codegen::build_refined_each(&files.input(), &refined, targets, emit, &worlds);
    Ok(Built {
        result,
        scenario_warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platform::Target;
    use std::path::Path;

    /// `generate` on the mission at `path` (loaded as `semo build` loads
    /// it), every robot for `linux-sim`, with `scenario`.
    fn linux_sim(path: &Path, scenario: &str) -> Result<Built, NotBuilt> {
        let (run, mission) = crate::host::load_build(path, &[]).expect("the mission loads");
        let targets = Targets::all(Target::LinuxSim);
        generate(
            &run.analysis(),
            mission,
            &targets,
            Emit::All,
            Some(scenario),
        )
    }

    fn scouting() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scouting/scouting.mission")
    }

    #[test]
    fn each_simulated_robot_gets_its_world_and_the_scenario_s_warnings_come_back() {
        let text = r#"{"robots": {"nxt": {"sensors": [{"at": 0, "value": "LOCATOIN", "is": 1}]}}}"#;
        let Ok(built) = linux_sim(&scouting(), text) else {
            panic!("the scenario is read");
        };
        assert!(!built.result.refused(), "{:#?}", built.result.diagnostics);
        assert!(!built.result.robots.is_empty());
        for robot in &built.result.robots {
            assert!(
                robot.files.iter().any(|f| f.path == "scenario.c"),
                "robot {} has no compiled world",
                robot.robot
            );
        }
        let warnings: Vec<_> = built
            .scenario_warnings
            .iter()
            .map(|w| (w.line_col(text), w.suggestion.as_deref()))
            .collect();
        assert_eq!(warnings, [((1, 52), Some("LOCATION"))]);
    }

    #[test]
    fn a_scenario_s_mistake_is_data_at_its_offset() {
        let text = r#"{"robots": {"nxtt": {}}}"#;
        match linux_sim(&scouting(), text) {
            Err(NotBuilt::Scenario(e)) => {
                // At the unknown robot's world, as the reader points at
                // every mistake's value.
                assert_eq!(e.at, text.find("{}").unwrap(), "{e:?}");
                assert_eq!(e.suggestion.as_deref(), Some("nxt"), "{e:?}");
            }
            Err(other) => panic!("not the scenario's mistake: {other:?}"),
            Ok(built) => panic!("built: {:#?}", built.result.diagnostics),
        }
    }

    #[test]
    fn a_refused_mission_is_reported_before_its_scenario_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let mission = dir.path().join("broken.mission");
        std::fs::write(&mission, "{\n  Team1: NoSuchRobotType r1\n}\n").unwrap();
        let Ok(built) = linux_sim(&mission, "not a scenario") else {
            panic!("the scenario was read although the mission is refused");
        };
        assert!(built.result.refused());
        assert!(built.result.robots.is_empty());
        assert!(built.scenario_warnings.is_empty());
    }

    #[test]
    fn a_file_that_is_no_mission_is_said_so() {
        let (run, _) = crate::host::load_build(&scouting(), &[]).expect("the mission loads");
        let none = generate(
            &run.analysis(),
            FileId(u32::MAX),
            &Targets::all(Target::Linux),
            Emit::All,
            None,
        );
        assert!(matches!(none, Err(NotBuilt::NoMission)));
    }
}
