//! The facade's queries about a file's structure: its outline, the symbols a
//! workspace search finds, inlay hints, semantic tokens, and its picture.

use crate::diag::FileId;
use crate::host::Analysis;
use crate::ide::{self, HighlightToken, InlayHint, StructureNode, WorkspaceSymbol};
use crate::span::Span;
use crate::workspace::FileKind;

/// A workspace search returns at most this many symbols (the editor asks
/// again as the query grows).
pub const WORKSPACE_SYMBOL_LIMIT: usize = 128;

/// Why a file has no picture, in words for the user.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PictureError(pub String);

impl std::fmt::Display for PictureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PictureError {}

impl Analysis {
    /// The file's outline: a mission's teams (robots, plans with their
    /// services, modes, main) and functions; a strategy file's values and
    /// services with their actions; nothing for other kinds of files.
    pub fn document_symbols(&self, file: FileId) -> Vec<StructureNode> {
        let Some(source) = self.file(file) else {
            return Vec::new();
        };
        match source.kind {
            FileKind::Mission => match self.mission(file) {
                Some(mission) => ide::mission::symbols::document_symbols(&mission, &source.text),
                None => Vec::new(),
            },
            FileKind::Strategy => match self.strategy(file) {
                Some(loaded) => loaded
                    .strategy
                    .as_ref()
                    .map(ide::strategy::symbols::document_symbols)
                    .unwrap_or_default(),
                None => Vec::new(),
            },
            FileKind::TaskGraph | FileKind::Catalog | FileKind::Project => Vec::new(),
        }
    }

    /// The teams, composite services, modes and functions of every mission
    /// of the workspace whose name matches `query`, best matches first (then
    /// by name, file and place), at most [`WORKSPACE_SYMBOL_LIMIT`].
    pub fn workspace_symbols(&self, query: &str) -> Vec<WorkspaceSymbol> {
        let mut found: Vec<(WorkspaceSymbol, Option<&std::path::Path>)> = Vec::new();
        for source in self.files().filter(|f| f.kind == FileKind::Mission) {
            let Some(mission) = self.mission(source.id) else {
                continue;
            };
            let path = source.path.as_deref();
            found.extend(
                ide::mission::symbols::workspace_symbols(&mission, query)
                    .into_iter()
                    .map(|s| (s, path)),
            );
        }
        found.sort_by(|(a, a_path), (b, b_path)| {
            (a.score, &a.name, a_path, a.target).cmp(&(b.score, &b.name, b_path, b.target))
        });
        found.truncate(WORKSPACE_SYMBOL_LIMIT);
        found.into_iter().map(|(s, _)| s).collect()
    }

    /// The hints whose place lies in `range`: in a mission, the robots a
    /// group arm selects and how a set service runs; in a task graph, each
    /// task's repetition count.
    pub fn inlay_hints(&self, file: FileId, range: Span) -> Vec<InlayHint> {
        let Some(source) = self.file(file) else {
            return Vec::new();
        };
        match source.kind {
            FileKind::Mission => match self.mission(file) {
                Some(mission) => {
                    let catalog = self.catalog(file);
                    ide::mission::inlay_hints::inlay_hints(
                        &mission,
                        &catalog.catalog,
                        &source.text,
                        range,
                    )
                }
                None => Vec::new(),
            },
            FileKind::TaskGraph => match self.graph(file) {
                Some(run) => match &run.graph {
                    Some(graph) => ide::taskgraph::inlay_hints(graph, &run.report)
                        .into_iter()
                        .filter(|h| range.touches(h.offset))
                        .collect(),
                    None => Vec::new(),
                },
                None => Vec::new(),
            },
            FileKind::Strategy | FileKind::Catalog | FileKind::Project => Vec::new(),
        }
    }

    /// Every resolved name of a mission (of `range`, or all) with what it
    /// is, sorted; `None` for other kinds of files (they have none).
    pub fn semantic_tokens(
        &self,
        file: FileId,
        range: Option<Span>,
    ) -> Option<Vec<HighlightToken>> {
        let (mission, _) = self.mission_of_kind(file)?;
        Some(ide::mission::semantic_tokens::semantic_tokens(
            &mission, range,
        ))
    }

    /// The file's picture as SVG: a task graph's (`semo graph svg`), a
    /// mission's mode machines (`semo graph modes`; only `team`'s if
    /// named). Refused, with the reason, for other files, a task graph
    /// that did not load, or a team without modes.
    pub fn picture(&self, file: FileId, team: Option<&str>) -> Result<String, PictureError> {
        let kind = self.file(file).map(|f| f.kind);
        match kind {
            Some(FileKind::TaskGraph) => match self.graph(file) {
                Some(run) => match &run.graph {
                    Some(graph) => Ok(crate::taskgraph::to_svg_analyzed(graph, &run.report)),
                    None => Err(PictureError(
                        "the task graph could not be read; see its diagnostics".to_string(),
                    )),
                },
                None => Err(PictureError("the task graph is not known".to_string())),
            },
            Some(FileKind::Mission) => {
                let mission = self
                    .mission(file)
                    .ok_or_else(|| PictureError("the mission is not known".to_string()))?;
                let mut machines = crate::modemachine::machines(&mission.mission);
                if let Some(team) = team {
                    machines.retain(|m| m.team == team);
                    if machines.is_empty() {
                        return Err(PictureError(format!(
                            "no team `{team}` with modes in this mission"
                        )));
                    }
                }
                Ok(crate::modemachine::to_svg(&machines))
            }
            _ => Err(PictureError(
                "only task graphs (*.taskgraph.xml) and missions (*.mission) have a picture"
                    .to_string(),
            )),
        }
    }

    /// A robot's refined task graph as SVG (`semo build`'s `taskgraph.xml`,
    /// drawn as `semo graph svg` draws it, with its analysis): `robot`, or
    /// the mission's first robot when `None`. Refused, with the reason, when
    /// the file is no mission, the mission does not refine (its errors), or
    /// no robot has that name (the robots named).
    pub fn robot_picture(
        &self,
        mission: FileId,
        robot: Option<&str>,
    ) -> Result<RobotPicture, PictureError> {
        let refined = self
            .refined(mission)
            .ok_or_else(|| PictureError("only a mission has robots to draw".to_string()))?;
        if refined.programs.is_empty() {
            let errors = refined.diagnostics.iter().filter(|d| d.is_error()).count();
            return Err(PictureError(format!(
                "the mission does not refine into robots: {errors} error(s) (see Problems)"
            )));
        }
        let robots: Vec<String> = refined.programs.iter().map(|p| p.robot.clone()).collect();
        let program = match robot {
            None => &refined.programs[0],
            Some(name) => refined
                .programs
                .iter()
                .find(|p| p.robot == name)
                .ok_or_else(|| {
                    PictureError(format!(
                        "the mission has no robot `{name}` (robots: {})",
                        robots.join(", ")
                    ))
                })?,
        };
        let report = crate::taskgraph::analysis::analyze(&program.graph);
        Ok(RobotPicture {
            svg: crate::taskgraph::to_svg_analyzed(&program.graph, &report),
            robot: program.robot.clone(),
            team: program.team.clone(),
            robots,
        })
    }
}

/// A robot's refined task graph drawn ([`Analysis::robot_picture`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotPicture {
    pub svg: String,
    pub robot: String,
    pub team: String,
    /// Every robot of the mission, in formation order.
    pub robots: Vec<String>,
}
