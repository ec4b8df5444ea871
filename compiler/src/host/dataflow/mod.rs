//! The dataflow warnings of a mission ([`crate::dataflow`]) over the
//! workspace: refined by refinement's public entry point
//! (`refine::refine_checked_robots`, from [`Analysis::build_input`]), one
//! robot of each declaration (`name[N]` is one: its robots are refined
//! alike, so the cost is per declaration, not per robot), with the service
//! graphs the workspace holds, analysed as [`Analysis::graph`] analyses
//! them.
//!
//! This is slower than checking (it refines), so it is not part of
//! [`Analysis::diagnostics`]: the doors ask for it apart (the language
//! server in the background, after the keystroke's diagnostics).

use super::{Analysis, Key, drop_later, fresh, lock};
use crate::dataflow::{self, DataflowInput, MissionDataflow};
use crate::diag::{self, FileId};
use crate::refine::Robots;
use crate::taskgraph::subgraph;
use crate::workspace::{FileKind, GraphRun};
use std::path::Path;
use std::sync::Arc;

impl Analysis {
    /// The dataflow of a mission's refined graphs: each robot's iteration
    /// period and the warnings in the mission. Empty when the mission or
    /// what it reads has errors (it is not refined then); `None` for other
    /// files. A service graph the workspace does not hold is not analysed.
    pub fn dataflow(&self, mission: FileId) -> Option<Arc<MissionDataflow>> {
        let file = self.file(mission).filter(|f| f.kind == FileKind::Mission)?;
        let key = self.reads_key(mission);
        if let Some(found) = fresh(lock(&self.memo.dataflow).get(&mission), &key) {
            return Some(found);
        }
        let build = self.build_input(mission)?;
        let input = build.input();
        // One robot per declaration: the warnings and each robot's period
        // are its declaration's (`dataflow::analyze`).
        let refined = crate::refine::refine_checked_robots(&input, Robots::OnePerDeclaration);
        let found = if refined.diagnostics.iter().any(|d| d.is_error()) {
            MissionDataflow::default()
        } else {
            let service_graph = |catalog: FileId, path: &str| self.service_graph(catalog, path);
            dataflow::analyze(&DataflowInput {
                file: file.id,
                mission: &build.analysis.mission,
                catalog: &build.unit.catalog.catalog,
                programs: &refined.programs,
                service_graph: &service_graph,
            })
        };
        let mut found = found;
        // Refinement's own warnings (W130: it reads the strategies as the
        // robots run them), after the input's diagnostics in `refined`.
        found.diagnostics.extend(
            refined.diagnostics[input.diagnostics.len().min(refined.diagnostics.len())..]
                .iter()
                .filter(|d| !d.is_error())
                .cloned(),
        );
        diag::sort_and_dedup(&mut found.diagnostics);
        self.apply_lints(mission, &mut found.diagnostics);
        let found = Arc::new(found);
        let old = lock(&self.memo.dataflow).insert(mission, (key, found.clone()));
        drop_later(old);
        Some(found)
    }

    /// Whether [`Analysis::dataflow`] of `mission` is known without
    /// computing: then it is given.
    pub fn dataflow_if_known(&self, mission: FileId) -> Option<Arc<MissionDataflow>> {
        let key = self.reads_key(mission);
        fresh(lock(&self.memo.dataflow).get(&mission), &key)
    }

    /// What a mission's refined programs and dataflow are computed from:
    /// the mission, the files it sees, its project file (the levels of its
    /// warnings), and every task graph (`FileId(u32::MAX)` carries their
    /// revision).
    pub(super) fn reads_key(&self, mission: FileId) -> Key {
        let project = self.project(mission).map(|p| p.file);
        let mut key: Key = self
            .reads(mission)
            .into_iter()
            .chain(project)
            .map(|f| (f, self.revision(f)))
            .collect();
        key.push((FileId(u32::MAX), self.graphs_revision));
        key
    }

    /// The task graph a catalog file names (`graph="path"`, relative to the
    /// catalog file), analysed, if the workspace holds it.
    pub(super) fn service_graph(&self, catalog: FileId, path: &str) -> Option<Arc<GraphRun>> {
        let catalog_path = self.file(catalog)?.key.as_deref()?;
        let wanted = subgraph::normalize(&catalog_path.parent()?.join(Path::new(path)));
        self.graph(self.graph_at(&wanted)?)
    }
}

#[cfg(test)]
mod tests;
