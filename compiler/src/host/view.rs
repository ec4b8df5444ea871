//! Which files see which, decided once per layout of the workspace.
//!
//! The rule is [`super::sees`]; asking it of every catalog and strategy file
//! for every question (a mission's catalog, its unit, what a strategy file is
//! checked with) made `semo check DIR` quadratic in the workspace's files. A
//! [`View`] answers the same questions from maps built on first use, and the
//! host keeps one `View` for as long as no file is added, removed, moved or
//! changes kind and no project file changes (a keystroke in a mission keeps
//! it): what a file sees depends on where files are, never on their texts,
//! except for project files.
//!
//! The rule is still asked for every answer, but only of the files it can
//! say yes to: without a project file or files seen by all, a file sees only
//! files in its own folder, below it or above it, which an ordered map of
//! folders gives without looking at the others.

use super::{Analysis, folder, lock};
use crate::diag::FileId;
use crate::taskgraph::subgraph;
use crate::workspace::FileKind;
use std::collections::{BTreeMap, HashMap};
use std::ops::Bound;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// The answers of [`super::sees`] for one layout, each computed on first use.
#[derive(Default)]
pub(super) struct View {
    maps: OnceLock<Maps>,
    /// By folder: the catalog and strategy files its files see, sorted by
    /// path (catalogs replace built-in types in this order).
    seen: Mutex<HashMap<PathBuf, Arc<[FileId]>>>,
    /// By catalog or strategy file: the folders of the missions that see it.
    seeing: OnceLock<HashMap<FileId, Vec<PathBuf>>>,
}

/// The files of the layout by where they are.
struct Maps {
    /// The missions by the folder they read from (see `Analysis::place`).
    missions: BTreeMap<PathBuf, Vec<FileId>>,
    /// The catalog and strategy files on disk, by folder. Paths order by
    /// components, so a folder's subfolders follow it in this map.
    seeable: BTreeMap<PathBuf, Vec<FileId>>,
    /// The task graphs by their path as named (normalized), and by their
    /// absolute path.
    graphs_as_named: Vec<(PathBuf, FileId)>,
    graphs_by_key: HashMap<PathBuf, FileId>,
}

impl Analysis {
    fn maps(&self) -> &Maps {
        self.view.maps.get_or_init(|| {
            let mut maps = Maps {
                missions: BTreeMap::new(),
                seeable: BTreeMap::new(),
                graphs_as_named: Vec::new(),
                graphs_by_key: HashMap::new(),
            };
            for file in self.files() {
                match file.kind {
                    FileKind::Mission => {
                        let place = self.place(file);
                        if let Some(dir) = place.as_deref().and_then(folder) {
                            let missions = maps.missions.entry(dir.to_path_buf()).or_default();
                            missions.push(file.id);
                        }
                    }
                    FileKind::Catalog | FileKind::Strategy => {
                        if let Some(dir) = file.key.as_deref().and_then(folder) {
                            maps.seeable
                                .entry(dir.to_path_buf())
                                .or_default()
                                .push(file.id);
                        }
                    }
                    FileKind::TaskGraph => {
                        if let Some(path) = &file.path {
                            maps.graphs_as_named
                                .push((subgraph::normalize(path), file.id));
                        }
                        if let Some(key) = &file.key {
                            maps.graphs_by_key.entry(key.clone()).or_insert(file.id);
                        }
                    }
                    FileKind::Project => {}
                }
            }
            maps
        })
    }

    /// The missions whose files read from `folder` (directly in it).
    pub(super) fn missions_in(&self, folder: &Path) -> &[FileId] {
        self.maps().missions.get(folder).map_or(&[], Vec::as_slice)
    }

    /// The catalog and strategy files the files of `folder` see, sorted by
    /// path, then id.
    pub(super) fn seen_ids(&self, folder: &Path) -> Arc<[FileId]> {
        if let Some(found) = lock(&self.view.seen).get(folder) {
            return found.clone();
        }
        let found: Arc<[FileId]> = self.compute_seen(folder).into();
        lock(&self.view.seen).insert(folder.to_path_buf(), found.clone());
        found
    }

    fn compute_seen(&self, folder: &Path) -> Vec<FileId> {
        let maps = self.maps();
        // A file in `folder` (the name does not matter to the rule).
        let reader = folder.join("_");
        let anywhere = !self.roots.seen_by_all.is_empty() || self.project_at(&reader).is_some();
        let candidates: Vec<FileId> = if anywhere {
            maps.seeable.values().flatten().copied().collect()
        } else {
            let below = maps
                .seeable
                .range::<Path, _>((Bound::Included(folder), Bound::Unbounded))
                .take_while(|(dir, _)| dir.starts_with(folder));
            let above = folder
                .ancestors()
                .skip(1)
                .filter_map(|dir| maps.seeable.get_key_value(dir));
            below
                .chain(above)
                .flat_map(|(_, ids)| ids)
                .copied()
                .collect()
        };
        let mut seen: Vec<(&Path, FileId)> = candidates
            .into_iter()
            .filter_map(|id| Some((self.file(id)?.key.as_deref()?, id)))
            .filter(|(path, _)| self.sees(&reader, path))
            .collect();
        seen.sort();
        seen.into_iter().map(|(_, id)| id).collect()
    }

    /// The folders of the missions that see the catalog or strategy file
    /// `id` (sorted).
    pub(super) fn folders_seeing(&self, id: FileId) -> &[PathBuf] {
        let seeing = self.view.seeing.get_or_init(|| {
            let mut seeing: HashMap<FileId, Vec<PathBuf>> = HashMap::new();
            // Folders in order, so each file's list is sorted.
            for dir in self.maps().missions.keys() {
                for &file in self.seen_ids(dir).iter() {
                    seeing.entry(file).or_default().push(dir.clone());
                }
            }
            seeing
        });
        seeing.get(&id).map_or(&[], Vec::as_slice)
    }

    /// The task graphs the host holds, by their path as named (normalized):
    /// what sub-graph references are resolved against.
    pub(super) fn graphs_as_named(&self) -> &[(PathBuf, FileId)] {
        &self.maps().graphs_as_named
    }

    /// The task graph at the absolute, normalized `path`, if the host holds it.
    pub(super) fn graph_at(&self, path: &Path) -> Option<FileId> {
        self.maps().graphs_by_key.get(path).copied()
    }
}
