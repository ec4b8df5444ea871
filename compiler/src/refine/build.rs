//! What a build starts from: a checked mission with the catalog and strategy
//! files it sees ([`BuildInput`]), refined into every robot's program
//! ([`refine_checked`]) for both back ends, the C generator (`codegen`) and
//! the simulator (`sim`). Any error of the check refuses, as does a name
//! that cannot be a file or a C identifier (E101).

use super::RoleKind;

/// What a mission is built from: its analysis, the catalog and the strategy
/// files it sees (as the workspace analysis decided), and every diagnostic of
/// those files, since any error among them refuses generation.
pub struct BuildInput<'a> {
    pub mission: crate::diag::FileId,
    /// The mission's file name, written into generated headers.
    pub mission_name: String,
    pub text: &'a str,
    pub analysis: &'a crate::sema::CheckedMission,
    pub catalog: &'a crate::catalog::Catalog,
    pub strategies: &'a [crate::strategy::Strategy],
    /// Each strategy file's name, for generated headers.
    pub strategy_names: Vec<(crate::diag::FileId, String)>,
    pub links: &'a crate::strategy::StrategyLinks,
    /// The diagnostics of the mission, the catalog and the strategies.
    pub diagnostics: &'a [crate::diag::Diagnostic],
    /// The task graphs implementing catalog services, as loaded.
    pub service_graphs: &'a [super::ServiceGraph],
}

/// A mission's refined programs, as code generation and the simulator
/// (`sim`) read them.
pub struct Refined {
    /// One per robot, in formation order; empty when refused.
    pub programs: Vec<super::RobotProgram>,
    /// The check's diagnostics and refinement's; any error refuses.
    pub diagnostics: Vec<crate::diag::Diagnostic>,
    /// The mission's and the strategy files' names (file headers).
    pub sources: Vec<String>,
}

/// Refines a mission: every error of the check (mission, catalog,
/// strategies) refuses, as do problems found while refining and names that
/// cannot be files or C identifiers (E101).
pub fn refine_checked(build: &BuildInput<'_>) -> Refined {
    refine_checked_robots(build, super::Robots::All)
}

/// [`refine_checked`] of the robots `robots` selects. With
/// [`Robots::OnePerDeclaration`](super::Robots) it refuses exactly
/// when `refine_checked` does: the other robots of a declaration differ
/// only by the number ending their name, and the one refined has the
/// longest (E101 bounds a name's length).
pub fn refine_checked_robots(build: &BuildInput<'_>, robots: super::Robots) -> Refined {
    use crate::diag::{Code, Diagnostic};
    let mut diagnostics: Vec<Diagnostic> = build.diagnostics.to_vec();
    let refused = |diagnostics| Refined {
        programs: Vec::new(),
        diagnostics,
        sources: Vec::new(),
    };
    if diagnostics.iter().any(Diagnostic::is_error) {
        return refused(diagnostics);
    }
    let (mission, analysis) = (build.mission, build.analysis);
    let (mission_name, strategy_names) = (&build.mission_name, &build.strategy_names);
    let input = super::RefineInput {
        mission_name,
        file: mission,
        text: build.text,
        analysis,
        catalog: build.catalog,
        strategies: build.strategies,
        strategy_names,
        links: build.links,
        service_graphs: build.service_graphs,
    };
    let (programs, found) = super::refine_robots(&input, robots);
    diagnostics.extend(found);
    // Names become folders, files and C identifiers: only plain identifiers.
    for program in &programs {
        // Looked up only for a diagnostic: finding each robot's declaration
        // walks the teams' robots, and doing it for every robot cost the
        // square of a swarm's robots.
        let span = || robot_span(build, &program.robot);
        let names = [&program.team, &program.robot]
            .into_iter()
            .chain(program.tasks.iter().map(|t| &t.task))
            .chain(program.library.iter().map(|l| &l.name));
        let reserved = [
            super::graph::CONTROL_TASK,
            super::graph::COMM_SEND,
            super::graph::COMM_RECEIVE,
        ];
        for role in &program.tasks {
            let clashes = reserved.contains(&role.task.as_str())
                && !matches!(role.kind, RoleKind::CommSend | RoleKind::CommReceive);
            if clashes {
                diagnostics.push(Diagnostic::new(
                    Code::OutputNameEscapes,
                    mission,
                    span(),
                    format!(
                        "task `{}` (of robot `{}`) has the name of a task the generator adds: rename it in the catalog or strategy",
                        role.task, program.robot
                    ),
                ));
            }
        }
        for name in names {
            if !is_plain_name(name) {
                diagnostics.push(Diagnostic::new(
                    Code::OutputNameEscapes,
                    mission,
                    span(),
                    format!(
                        "`{name}` (of robot `{}`) cannot name a file or C identifier: use letters, digits and `_` only",
                        program.robot
                    ),
                ));
            }
        }
    }
    crate::diag::sort_and_dedup(&mut diagnostics);
    if diagnostics.iter().any(Diagnostic::is_error) {
        return refused(diagnostics);
    }
    let mut sources = vec![mission_name.clone()];
    sources.extend(strategy_names.iter().map(|(_, n)| n.clone()));
    Refined {
        programs,
        diagnostics,
        sources,
    }
}

/// Where the robot is declared (diagnostics about one robot point there).
pub fn robot_span(build: &BuildInput<'_>, robot: &str) -> crate::span::Span {
    build
        .analysis
        .mission
        .teams
        .iter()
        .flat_map(|t| &t.robots)
        .find(|r| r.name == robot)
        .map(|r| r.name_span)
        .unwrap_or_default()
}

/// Whether `name` can be a file or folder name and a C identifier as it is
/// (both back ends make files and identifiers of the names they are given).
pub fn is_plain_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && name.len() <= 64
}
