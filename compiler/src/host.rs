//! One analysis of a workspace for every door: `semo check FILE`, `semo check
//! DIR`, `semo build` and the language server all put their files into an
//! [`AnalysisHost`] and ask its [`Analysis`] snapshots for diagnostics, the
//! checked mission, a strategy file's links, or what a mission is built from
//! ([`Analysis::build_input`]). The doors only decide which files to load and
//! how to show the answers (as rust-analyzer's `AnalysisHost`/`Analysis`).
//!
//! # Which files belong together
//!
//! A file under a project file (`semo.toml` in its folder or one above it,
//! the innermost; see [`crate::project`]) sees the catalog files in the
//! project's catalog folders and the strategy files in its strategy folders,
//! wherever they are, and nothing else of the disk.
//!
//! Without a project file, a file sees the catalog (`*.robot.xml`) and
//! strategy (`*.strategy.xml`) files in its own folder and the folders under
//! it down to [`SEEN_DEPTH`] levels (but not into a folder holding missions
//! of its own: that is another project, as each example or fixture folder
//! is), and those directly in each folder above it up to its workspace root
//! (the innermost root that holds it; a file under no root is its own
//! folder's root).
//!
//! Either way it sees the files named to be seen by all (`semo build
//! --strategy`). A document that is not a file (an unsaved editor buffer)
//! sees what a file directly in the first workspace root would. Nothing
//! else: two sibling folders do not see each other. [`sees`] is that rule,
//! and the only place it is written. A project's `[lints]` levels apply to
//! the diagnostics of every file under it ([`Analysis::diagnostics`],
//! [`Analysis::dataflow`]).
//!
//! The missions of one folder see the same files: they form a *unit*. A
//! unit's catalog files (sorted by path) make its catalog; its missions are
//! checked against it; its strategy files are cross-checked together against
//! its catalog and missions (so an entry refined in two files is found). A
//! unit without strategy files needs its missions for nothing: each is
//! checked when it is asked for, so `semo check FILE` checks no sibling. A
//! file's diagnostics are its own plus those found in it by every unit that
//! sees it; a catalog or strategy file no unit sees is checked with the
//! files its own folder sees. Task graphs are analysed on their own,
//! following `subgraph` references through the host's files, else the disk.
//!
//! # Snapshots
//!
//! An [`Analysis`] is immutable and cheap to clone: the files as they were
//! when it was taken. Results are computed on demand, without any lock held
//! while computing, and kept in a memo shared by all snapshots of a host,
//! keyed by the revisions of the files they read, so a new snapshot after a
//! keystroke in a mission recomputes only that mission (parsed incrementally
//! from its previous version's [`ParseCache`]) and what reads it.

use crate::catalog::{Catalog, CatalogSource, load_catalog};
use crate::diag::{self, Diagnostic, FileId};
use crate::project::{self, Project};
use crate::refine::BuildInput;
use crate::sema::{self, check_parsed};
use crate::strategy::{Strategy, StrategyLinks, cross_check, load_strategy};
use crate::syntax::{self, ParseCache, parse_incremental};
use crate::taskgraph::subgraph::{self, SubgraphSource};
use crate::workspace::{FileKind, FileResolver, GraphRun, analyze_graph_at};
use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use view::View;

/// Where a workspace is: its roots, and the files or folders every file
/// sees besides (`semo build --strategy`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Roots {
    pub roots: Vec<PathBuf>,
    pub seen_by_all: Vec<PathBuf>,
}

/// How many folders below its own a file without a project file looks for
/// catalog and strategy files (`semo check`, `semo build` read no deeper).
pub const SEEN_DEPTH: usize = 3;

/// Whether a file at `reader` sees the catalog or strategy file at `file`
/// (see the module documentation); `has_missions` tells which folders hold
/// missions, `project` is the project file `reader` is under, if any.
pub fn sees(
    roots: &Roots,
    has_missions: impl Fn(&Path) -> bool,
    project: Option<&Project>,
    reader: &Path,
    file: &Path,
) -> bool {
    if roots.seen_by_all.iter().any(|p| file.starts_with(p)) {
        return true;
    }
    if let Some(project) = project {
        return match FileKind::of(file) {
            Some(FileKind::Catalog) => Project::in_folders(&project.catalogs, file),
            Some(FileKind::Strategy) => Project::in_folders(&project.strategies, file),
            _ => false,
        };
    }
    let (Some(reader_dir), Some(file_dir)) = (folder(reader), folder(file)) else {
        return false;
    };
    if file_dir.starts_with(reader_dir) {
        let depth = file_dir.components().count() - reader_dir.components().count();
        // Not into a folder below with missions of its own.
        return depth <= SEEN_DEPTH
            && !file_dir
                .ancestors()
                .take_while(|d| *d != reader_dir)
                .any(has_missions);
    }
    let roots = &roots.roots;
    let root = roots
        .iter()
        .filter(|r| reader_dir.starts_with(r))
        .max_by_key(|r| r.components().count())
        .map_or(reader_dir, PathBuf::as_path);
    reader_dir.starts_with(file_dir) && file_dir.starts_with(root)
}

/// The file name an unsaved document is read as having (see `Analysis::place`).
const UNSAVED: &str = "<unsaved>";

fn folder(path: &Path) -> Option<&Path> {
    path.parent()
}

/// The parse cache of the version of a mission analysed last, handed from
/// each version of the file to the next: any cache gives the same result
/// (only unchanged text is reused); a recent one makes it faster.
#[derive(Default, Debug)]
struct ParseSlot(Mutex<Option<Arc<ParseCache>>>);

impl ParseSlot {
    fn get(&self) -> Option<Arc<ParseCache>> {
        lock(&self.0).clone()
    }

    fn put(&self, cache: ParseCache) {
        *lock(&self.0) = Some(Arc::new(cache));
    }
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // Every update of a memo or slot is one assignment: a panic elsewhere
    // leaves it consistent.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// One version of one file.
#[derive(Debug)]
pub struct SourceText {
    pub id: FileId,
    /// Where the file is, as the door named it (messages show it); `None`
    /// for a document that is not a file (it then sees no other file).
    pub path: Option<PathBuf>,
    /// `path` made absolute and without `.`/`..`: what the rule compares.
    key: Option<PathBuf>,
    pub kind: FileKind,
    pub text: Arc<str>,
    /// Changes with every new text of the file (unique within a host).
    revision: u64,
    parses: Arc<ParseSlot>,
}

type Files = Arc<BTreeMap<FileId, Arc<SourceText>>>;

/// The files of a workspace, changed by the door; see the module documentation.
pub struct AnalysisHost {
    roots: Arc<Roots>,
    files: Files,
    next_revision: u64,
    /// Bumped whenever a task graph changes (they read each other).
    graphs_revision: u64,
    /// How many missions each folder holds.
    mission_folders: Arc<BTreeMap<PathBuf, usize>>,
    /// Every project file, read.
    projects: Projects,
    /// What sees what: kept while the layout stays (see [`view`]).
    view: Arc<View>,
    memo: Arc<Memo>,
    /// Whether a mission's parse leaves a cache for the file's next version
    /// (see [`AnalysisHost::without_parse_caches`]).
    parse_caches: bool,
}

/// A project file read: the project (rooted at the file's folder; a
/// document that is not a file is the project of no file) and the
/// diagnostics of its text.
#[derive(Debug)]
pub struct LoadedProject {
    pub file: FileId,
    pub project: Project,
    pub diagnostics: Vec<Diagnostic>,
    /// Whether it is a file on disk (only those are the project of files).
    on_disk: bool,
}

type Projects = Arc<BTreeMap<FileId, Arc<LoadedProject>>>;

impl Default for AnalysisHost {
    fn default() -> Self {
        AnalysisHost::new(Roots::default())
    }
}

impl AnalysisHost {
    pub fn new(roots: Roots) -> AnalysisHost {
        AnalysisHost {
            roots: Arc::new(roots),
            files: Files::default(),
            next_revision: 0,
            graphs_revision: 0,
            mission_folders: Arc::default(),
            projects: Projects::default(),
            view: Arc::default(),
            memo: Arc::default(),
            parse_caches: true,
        }
    }

    /// A host whose missions are parsed from scratch, without leaving a parse
    /// cache: for a door that analyses each text once (the command line).
    /// The parse is the same; the cache (the tokens, and each chunk's tree
    /// beside the file's) would be a third of a large mission's peak memory,
    /// kept for an edit that never comes.
    pub fn without_parse_caches(mut self) -> AnalysisHost {
        self.parse_caches = false;
        self
    }

    pub fn set_roots(&mut self, roots: Roots) {
        self.roots = Arc::new(roots);
        self.view = Arc::default();
    }

    pub fn roots(&self) -> &Roots {
        &self.roots
    }

    /// A file was added or its text changed. The caller chooses the ids
    /// (diagnostics name files by them).
    pub fn set_file(&mut self, id: FileId, path: Option<PathBuf>, kind: FileKind, text: Arc<str>) {
        self.next_revision += 1;
        let parses = self
            .files
            .get(&id)
            .filter(|old| old.kind == kind)
            .map(|old| old.parses.clone())
            .unwrap_or_default();
        let was_graph = self
            .files
            .get(&id)
            .is_some_and(|f| f.kind == FileKind::TaskGraph);
        if kind == FileKind::TaskGraph || was_graph {
            self.graphs_revision += 1;
        }
        let key = path.as_deref().map(|p| {
            let absolute = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
            subgraph::normalize(&absolute)
        });
        // What sees what depends on where files are and on project files,
        // not on other texts.
        let same_place = self
            .files
            .get(&id)
            .is_some_and(|old| old.kind == kind && old.path == path && old.key == key);
        if !same_place || kind == FileKind::Project {
            self.view = Arc::default();
        }
        let file = SourceText {
            id,
            path,
            key,
            kind,
            text,
            revision: self.next_revision,
            parses,
        };
        let old = Arc::make_mut(&mut self.files).insert(id, Arc::new(file));
        if let Some(old) = old {
            self.count_mission(&old, -1);
        }
        let new = self.files[&id].clone();
        self.count_mission(&new, 1);
        self.read_project(&new);
    }

    /// Keeps the project files read (they decide what every file sees, so
    /// they are read once per version, not per question).
    fn read_project(&mut self, file: &SourceText) {
        let projects = Arc::make_mut(&mut self.projects);
        if file.kind != FileKind::Project {
            projects.remove(&file.id);
            return;
        }
        let root = file
            .key
            .as_deref()
            .and_then(folder)
            .unwrap_or(Path::new("."));
        let (project, diagnostics) = project::parse(file.id, root, &file.text);
        let loaded = LoadedProject {
            file: file.id,
            project,
            diagnostics,
            on_disk: file.key.is_some(),
        };
        projects.insert(file.id, Arc::new(loaded));
    }

    fn count_mission(&mut self, file: &SourceText, delta: isize) {
        let Some(dir) = file.key.as_deref().and_then(folder) else {
            return;
        };
        if file.kind != FileKind::Mission {
            return;
        }
        let counts = Arc::make_mut(&mut self.mission_folders);
        let count = counts.entry(dir.to_path_buf()).or_insert(0);
        *count = count.saturating_add_signed(delta);
        if *count == 0 {
            counts.remove(dir);
        }
    }

    /// A file went away.
    pub fn remove_file(&mut self, id: FileId) {
        if let Some(old) = Arc::make_mut(&mut self.files).remove(&id) {
            if old.kind == FileKind::TaskGraph {
                self.graphs_revision += 1;
            }
            self.count_mission(&old, -1);
            Arc::make_mut(&mut self.projects).remove(&id);
            self.view = Arc::default();
            self.memo.forget(id);
        }
    }

    /// A snapshot of the files as they are now.
    pub fn analysis(&self) -> Analysis {
        Analysis {
            roots: self.roots.clone(),
            files: self.files.clone(),
            graphs_revision: self.graphs_revision,
            mission_folders: self.mission_folders.clone(),
            projects: self.projects.clone(),
            view: self.view.clone(),
            memo: self.memo.clone(),
            parse_caches: self.parse_caches,
        }
    }
}

/// The catalog a group of files sees, with the diagnostics of its files.
#[derive(Debug)]
pub struct CatalogResult {
    pub catalog: Catalog,
    pub diagnostics: Vec<Diagnostic>,
    /// The catalog files it was made of, in order.
    pub files: Vec<FileId>,
}

/// A strategy file on its own: its model (`None` when the file has no
/// `<Strategy>` element; its diagnostics say why) and per-file diagnostics.
#[derive(Debug)]
pub struct LoadedStrategy {
    pub strategy: Option<Strategy>,
    pub diagnostics: Vec<Diagnostic>,
}

/// The missions of one folder with everything they see, checked together.
/// The strategies are those the folder's files see, which are the ones each
/// of its missions sees.
#[derive(Debug)]
pub struct Unit {
    pub catalog: Arc<CatalogResult>,
    /// The missions, checked, that its strategy files were cross-checked
    /// against: none when it sees no strategy file.
    pub missions: Vec<(FileId, Arc<sema::CheckedMission>)>,
    pub strategies: Vec<(FileId, Arc<LoadedStrategy>)>,
    /// The missions' built-in calls linked to the entries refining them.
    pub links: StrategyLinks,
    /// The cross-check's diagnostics (in the strategy files).
    pub cross: Vec<Diagnostic>,
}

/// Revisions of the files a result was computed from: equal keys, equal results.
type Key = Vec<(FileId, u64)>;

/// Results kept between snapshots; each map holds only the newest result per
/// file or folder, so it is bounded by the workspace's size. A replaced result
/// is freed by [`drop_later`] (off this thread, with a bounded backlog).
#[derive(Default)]
struct Memo {
    /// By folder (`None`: documents that are not files).
    catalogs: Memoised<Option<PathBuf>, Key, CatalogResult>,
    /// By file: (its revision, its catalog's key).
    missions: Memoised<FileId, (u64, Key), sema::CheckedMission>,
    strategies: Memoised<FileId, u64, LoadedStrategy>,
    units: Memoised<Option<PathBuf>, Key, Unit>,
    /// By file: (its revision, the task graphs' revision).
    graphs: Memoised<FileId, (u64, u64), GraphRun>,
    /// By mission: the revisions of what it reads and of the task graphs.
    dataflow: Memoised<FileId, Key, crate::dataflow::MissionDataflow>,
    /// By mission, with the same key as `dataflow`.
    refined: Memoised<FileId, Key, crate::refine::Refined>,
}

/// Results by slot, each with the key it was computed from.
type Memoised<Slot, K, V> = Mutex<HashMap<Slot, (K, Arc<V>)>>;

/// The memo's result if it was computed from `key`.
fn fresh<K: PartialEq, V: Clone>(entry: Option<&(K, V)>, key: &K) -> Option<V> {
    entry.filter(|(k, _)| k == key).map(|(_, v)| v.clone())
}

impl Memo {
    fn forget(&self, id: FileId) {
        drop_later(lock(&self.missions).remove(&id));
        drop_later(lock(&self.strategies).remove(&id));
        drop_later(lock(&self.graphs).remove(&id));
        drop_later(lock(&self.dataflow).remove(&id));
        drop_later(lock(&self.refined).remove(&id));
    }
}

/// An immutable snapshot of a host's files; see the module documentation.
#[derive(Clone)]
pub struct Analysis {
    roots: Arc<Roots>,
    files: Files,
    graphs_revision: u64,
    mission_folders: Arc<BTreeMap<PathBuf, usize>>,
    projects: Projects,
    view: Arc<View>,
    memo: Arc<Memo>,
    parse_caches: bool,
}

impl Analysis {
    pub fn file(&self, id: FileId) -> Option<&SourceText> {
        self.files.get(&id).map(|f| &**f)
    }

    pub fn files(&self) -> impl Iterator<Item = &SourceText> {
        self.files.values().map(|f| &**f)
    }

    /// [`sees`] over this snapshot's files.
    fn sees(&self, reader: &Path, file: &Path) -> bool {
        sees(
            &self.roots,
            |d| self.mission_folders.contains_key(d),
            self.project_at(reader).map(|p| &p.project),
            reader,
            file,
        )
    }

    /// The project a file at `path` is under: the project file on disk in
    /// its folder or the nearest one above.
    fn project_at(&self, path: &Path) -> Option<&Arc<LoadedProject>> {
        let dir = folder(path)?;
        self.projects
            .values()
            .filter(|p| p.on_disk && dir.starts_with(&p.project.root))
            .max_by_key(|p| (p.project.root.components().count(), p.file))
    }

    /// The project file `id` belongs to (see [`Analysis::project_at`]); for
    /// a project file, itself.
    pub fn project(&self, id: FileId) -> Option<Arc<LoadedProject>> {
        if let Some(own) = self.projects.get(&id) {
            return Some(own.clone());
        }
        let file = self.file(id)?;
        self.project_at(&self.place(file)?).cloned()
    }

    /// `diagnostics` of `id` at the levels of its project's `[lints]`.
    fn apply_lints(&self, id: FileId, diagnostics: &mut Vec<Diagnostic>) {
        if let Some(project) = self.project(id) {
            project.project.apply_lints(diagnostics);
        }
    }

    /// Where a file reads from: its path, else (a document that is not a
    /// file, such as an unsaved editor buffer) a place in the first workspace
    /// root, so that it sees what a file there would; with no root, nowhere
    /// (it sees only the built-in catalog).
    fn place<'a>(&self, file: &'a SourceText) -> Option<Cow<'a, Path>> {
        match &file.key {
            Some(key) => Some(Cow::Borrowed(key)),
            None => self
                .roots
                .roots
                .first()
                .map(|root| Cow::Owned(root.join(UNSAVED))),
        }
    }

    /// The folder a file's view starts from (see [`Analysis::place`]).
    fn folder_of(&self, id: FileId) -> Option<PathBuf> {
        let path = self.place(self.file(id)?)?;
        folder(&path).map(Path::to_path_buf)
    }

    /// The catalog and strategy files the files of `folder` see, sorted by
    /// path (catalogs replace built-in types in this order).
    fn seen_from(&self, folder: Option<&Path>) -> Vec<&SourceText> {
        let Some(folder) = folder else {
            return Vec::new();
        };
        let seen = self.seen_ids(folder);
        seen.iter().filter_map(|&id| self.file(id)).collect()
    }

    /// The files `id` reads besides itself: the catalog and strategy files it
    /// sees (for a mission, what its build reads).
    pub fn seen_by(&self, id: FileId) -> Vec<FileId> {
        let folder = self.folder_of(id);
        self.seen_from(folder.as_deref())
            .into_iter()
            .map(|f| f.id)
            .filter(|&f| f != id)
            .collect()
    }

    fn catalog_from(&self, folder: Option<&Path>) -> Arc<CatalogResult> {
        let sources: Vec<&SourceText> = self
            .seen_from(folder)
            .into_iter()
            .filter(|f| f.kind == FileKind::Catalog)
            .collect();
        self.catalog_of(sources, folder.map(Path::to_path_buf))
    }

    /// The catalog `sources` make (memoised in `slot`).
    fn catalog_of(&self, sources: Vec<&SourceText>, slot: Option<PathBuf>) -> Arc<CatalogResult> {
        let key: Key = sources.iter().map(|f| (f.id, f.revision)).collect();
        if let Some(found) = fresh(lock(&self.memo.catalogs).get(&slot), &key) {
            return found;
        }
        let (catalog, diagnostics) = load_catalog(
            &sources
                .iter()
                .map(|f| CatalogSource {
                    file: f.id,
                    text: &f.text,
                    base_dir: f.path.as_deref().and_then(Path::parent),
                })
                .collect::<Vec<_>>(),
        );
        let result = Arc::new(CatalogResult {
            catalog,
            diagnostics,
            files: sources.iter().map(|f| f.id).collect(),
        });
        let old = lock(&self.memo.catalogs).insert(slot, (key, result.clone()));
        drop_later(old);
        result
    }

    /// The catalog `id` is checked against (the built-in one and the catalog
    /// files it sees).
    pub fn catalog(&self, id: FileId) -> Arc<CatalogResult> {
        self.catalog_from(self.folder_of(id).as_deref())
    }

    /// The catalog every catalog file of the workspace makes (for requests
    /// about no file in particular: the editor's list of robot types).
    pub fn root_catalog(&self) -> Arc<CatalogResult> {
        let mut sources: Vec<&SourceText> = self
            .files()
            .filter(|f| f.kind == FileKind::Catalog)
            .collect();
        sources.sort_by(|a, b| a.key.cmp(&b.key).then(a.id.0.cmp(&b.id.0)));
        // A slot no folder has.
        self.catalog_of(sources, Some(PathBuf::new()))
    }

    /// The parse cache a mission's last analysis left (to see what an edit
    /// re-parsed).
    pub fn parse_cache(&self, id: FileId) -> Option<Arc<ParseCache>> {
        self.files.get(&id)?.parses.get()
    }

    /// A mission checked against its catalog; `None` for other files.
    pub fn mission(&self, id: FileId) -> Option<Arc<sema::CheckedMission>> {
        let file = self
            .files
            .get(&id)
            .filter(|f| f.kind == FileKind::Mission)?;
        let catalog = self.catalog(id);
        let key: Key = catalog
            .files
            .iter()
            .map(|&c| (c, self.revision(c)))
            .collect();
        let memo_key = (file.revision, key);
        if let Some(found) = fresh(lock(&self.memo.missions).get(&id), &memo_key) {
            return Some(found);
        }
        let parse = if self.parse_caches {
            let previous = file.parses.get();
            let (parse, cache) = parse_incremental(id, &file.text, previous.as_deref());
            drop(previous);
            file.parses.put(cache);
            parse
        } else {
            syntax::parse(id, &file.text)
        };
        let analysis = Arc::new(check_parsed(id, parse, &catalog.catalog));
        let old = lock(&self.memo.missions).insert(id, (memo_key, analysis.clone()));
        drop_later(old);
        Some(analysis)
    }

    fn revision(&self, id: FileId) -> u64 {
        self.files.get(&id).map_or(0, |f| f.revision)
    }

    /// A strategy file loaded on its own; `None` for other files.
    pub fn strategy(&self, id: FileId) -> Option<Arc<LoadedStrategy>> {
        let file = self
            .files
            .get(&id)
            .filter(|f| f.kind == FileKind::Strategy)?;
        if let Some(found) = fresh(lock(&self.memo.strategies).get(&id), &file.revision) {
            return Some(found);
        }
        let (strategy, diagnostics) = load_strategy(id, &file.text);
        let loaded = Arc::new(LoadedStrategy {
            strategy,
            diagnostics,
        });
        let old = lock(&self.memo.strategies).insert(id, (file.revision, loaded.clone()));
        drop_later(old);
        Some(loaded)
    }

    /// The missions of `folder` (directly in it) and what they see, checked
    /// together. A folder without missions makes a unit too (its catalog and
    /// strategy files are checked with what they see).
    fn unit_of(&self, folder: Option<&Path>) -> Arc<Unit> {
        let missions: Vec<&SourceText> = match folder {
            Some(folder) => self
                .missions_in(folder)
                .iter()
                .filter_map(|&id| self.file(id))
                .collect(),
            None => Vec::new(),
        };
        let seen = self.seen_from(folder);
        let key: Key = missions
            .iter()
            .chain(&seen)
            .map(|f| (f.id, f.revision))
            .collect();
        let slot = folder.map(Path::to_path_buf);
        if let Some(found) = fresh(lock(&self.memo.units).get(&slot), &key) {
            return found;
        }
        let catalog = self.catalog_from(folder);
        let strategies: Vec<(FileId, Arc<LoadedStrategy>)> = seen
            .iter()
            .filter(|f| f.kind == FileKind::Strategy)
            .filter_map(|f| Some((f.id, self.strategy(f.id)?)))
            .collect();
        // The missions matter to the unit only against its strategy files:
        // without one, a check of one mission (`semo check FILE`, an
        // edit) does not check its siblings.
        let missions: Vec<(FileId, Arc<sema::CheckedMission>)> = if strategies.is_empty() {
            Vec::new()
        } else {
            missions
                .iter()
                .filter_map(|m| Some((m.id, self.mission(m.id)?)))
                .collect()
        };
        let models: Vec<&Strategy> = strategies
            .iter()
            .filter_map(|(_, s)| s.strategy.as_ref())
            .collect();
        let analyses: Vec<&sema::CheckedMission> = missions.iter().map(|(_, a)| &**a).collect();
        let (links, cross) = cross_check(&models, &analyses, &catalog.catalog);
        let unit = Arc::new(Unit {
            catalog,
            missions,
            strategies,
            links,
            cross,
        });
        let old = lock(&self.memo.units).insert(slot, (key, unit.clone()));
        drop_later(old);
        unit
    }

    /// The unit a mission belongs to (its folder's); `None` for other files.
    pub fn unit(&self, mission: FileId) -> Option<Arc<Unit>> {
        self.files
            .get(&mission)
            .filter(|f| f.kind == FileKind::Mission)?;
        Some(self.unit_of(self.folder_of(mission).as_deref()))
    }

    /// The folders whose units see the catalog or strategy file `id`: the
    /// folders of the missions that see it, else its own folder.
    fn units_seeing(&self, id: FileId) -> Vec<Option<PathBuf>> {
        let Some(path) = self.file(id).and_then(|f| f.key.as_deref()) else {
            return vec![None];
        };
        let folders = self.folders_seeing(id);
        if folders.is_empty() {
            return vec![folder(path).map(Path::to_path_buf)];
        }
        folders.iter().cloned().map(Some).collect()
    }

    /// The missions that see the strategy (or catalog) file `id`.
    pub fn missions_seeing(&self, id: FileId) -> Vec<FileId> {
        if self.file(id).and_then(|f| f.key.as_deref()).is_none() {
            return Vec::new();
        }
        let mut missions: Vec<FileId> = self
            .folders_seeing(id)
            .iter()
            .flat_map(|dir| self.missions_in(dir))
            .copied()
            .collect();
        missions.sort();
        missions
    }

    /// A strategy file's links: the calls of the missions that see it that
    /// its entries (and the other entries of those missions' units) refine.
    pub fn strategy_links(&self, id: FileId) -> StrategyLinks {
        let units: Vec<Arc<Unit>> = self
            .units_seeing(id)
            .iter()
            .map(|f| self.unit_of(f.as_deref()))
            .collect();
        StrategyLinks::merged(units.iter().map(|u| &u.links))
    }

    /// A task graph analysed with its sub-graphs; `None` for other files.
    pub fn graph(&self, id: FileId) -> Option<Arc<GraphRun>> {
        let file = self
            .files
            .get(&id)
            .filter(|f| f.kind == FileKind::TaskGraph)?;
        let key = (file.revision, self.graphs_revision);
        if let Some(found) = fresh(lock(&self.memo.graphs).get(&id), &key) {
            return Some(found);
        }
        let known = self.graphs_as_named().iter().filter_map(|(path, id)| {
            let source = SubgraphSource {
                file: *id,
                text: self.file(*id)?.text.clone(),
            };
            Some((path.clone(), source))
        });
        // Files the host does not hold get ids counting down from below the
        // built-in catalog's: read for this analysis only.
        let mut resolver = FileResolver::below(known, crate::catalog::BUILTIN_FILE);
        let run = Arc::new(analyze_graph_at(
            id,
            &file.text,
            file.path.as_deref(),
            &mut resolver,
        ));
        let old = lock(&self.memo.graphs).insert(id, (key, run.clone()));
        drop_later(old);
        Some(run)
    }

    /// The diagnostics of one file, sorted: its own, and those every unit
    /// that sees it found in it; at most [`diag::MAX_PER_FILE`], then one E004
    /// (every door reports through here, so all report the same).
    pub fn diagnostics(&self, id: FileId) -> Vec<Diagnostic> {
        let Some(file) = self.file(id) else {
            return Vec::new();
        };
        let mut found: Vec<Diagnostic> = match file.kind {
            FileKind::Mission => self
                .mission(id)
                .map(|m| m.diagnostics.clone())
                .unwrap_or_default(),
            FileKind::TaskGraph => self
                .graph(id)
                .map(|g| g.diagnostics.clone())
                .unwrap_or_default(),
            FileKind::Project => match self.projects.get(&id) {
                Some(loaded) => {
                    let mut found = loaded.diagnostics.clone();
                    if loaded.on_disk {
                        let exists = |p: &Path| p.exists();
                        found.extend(loaded.project.missing_paths(id, exists));
                    }
                    found
                }
                None => Vec::new(),
            },
            FileKind::Catalog | FileKind::Strategy if file.key.is_none() => {
                // A document that is not a file sees nothing: checked alone.
                let mut found = self
                    .strategy(id)
                    .map(|s| s.diagnostics.clone())
                    .unwrap_or_default();
                if file.kind == FileKind::Catalog {
                    let source = CatalogSource {
                        file: id,
                        text: &file.text,
                        base_dir: None,
                    };
                    found.extend(load_catalog(&[source]).1);
                }
                found
            }
            FileKind::Catalog | FileKind::Strategy => {
                let mut found = self
                    .strategy(id)
                    .map(|s| s.diagnostics.clone())
                    .unwrap_or_default();
                for folder in self.units_seeing(id) {
                    let unit = self.unit_of(folder.as_deref());
                    let in_file = |d: &&Diagnostic| d.file == id;
                    found.extend(unit.catalog.diagnostics.iter().filter(in_file).cloned());
                    found.extend(unit.cross.iter().filter(in_file).cloned());
                }
                found
            }
        };
        self.apply_lints(id, &mut found);
        diag::sort_and_dedup(&mut found);
        diag::cap_per_file(&mut found);
        found
    }

    /// The files a check of `id` reports on: itself, the catalog and
    /// strategy files it sees (what its build reads) and its project file.
    pub fn reads(&self, id: FileId) -> Vec<FileId> {
        let mut out = vec![id];
        out.extend(self.seen_by(id));
        if let Some(project) = self.project(id).filter(|p| p.file != id) {
            out.push(project.file);
        }
        out
    }

    /// What a mission is built from: the mission checked, the catalog and
    /// strategy files it sees, and the diagnostics of all of them
    /// ([`Analysis::diagnostics`] of each of [`Analysis::reads`]; any error
    /// refuses the build). `None` for other files.
    pub fn build_input(&self, mission: FileId) -> Option<BuildFiles> {
        let unit = self.unit(mission)?;
        let analysis = self.mission(mission)?;
        let file = self.files.get(&mission)?.clone();
        let name_of = |id: FileId| -> String {
            match self.file(id).and_then(|f| f.path.as_deref()) {
                Some(path) => path.file_name().map_or_else(
                    || path.display().to_string(),
                    |n| n.to_string_lossy().into_owned(),
                ),
                None => format!("file {}", id.0),
            }
        };
        let strategies: Vec<Strategy> = unit
            .strategies
            .iter()
            .filter_map(|(_, s)| s.strategy.clone())
            .collect();
        // The task graphs of the catalog's services that the workspace holds.
        let mut service_graphs: Vec<crate::refine::ServiceGraph> = Vec::new();
        for (_, robot_type) in unit.catalog.catalog.types() {
            for def in &robot_type.services {
                let crate::catalog::Implementation::Graph(path) = &def.implementation else {
                    continue;
                };
                let known = service_graphs
                    .iter()
                    .any(|g| g.catalog == def.origin.file && g.path == *path);
                if known {
                    continue;
                }
                let loaded = self.service_graph(def.origin.file, path);
                if let Some(run) = loaded
                    && let Some(graph) = run.graph.clone()
                {
                    service_graphs.push(crate::refine::ServiceGraph {
                        catalog: def.origin.file,
                        path: path.clone(),
                        graph: Arc::new(graph),
                        hierarchy: Arc::new(run.hierarchy.clone()),
                    });
                }
            }
        }
        Some(BuildFiles {
            service_graphs,
            mission_name: name_of(mission),
            strategy_names: strategies
                .iter()
                .map(|s| (s.file, name_of(s.file)))
                .collect(),
            diagnostics: {
                let mut all: Vec<Diagnostic> = self
                    .reads(mission)
                    .into_iter()
                    .flat_map(|f| self.diagnostics(f))
                    .collect();
                diag::sort_and_dedup(&mut all);
                all
            },
            strategies,
            analysis,
            file,
            unit,
        })
    }

    /// The files whose results may change when `id` changes (itself
    /// included): for a mission, the strategy files it sees (cross-checked
    /// against it) (a mission added or removed can change what the files
    /// above its folder see: the door re-checks everything then); for a strategy file, the strategy files sharing a unit
    /// with it (an entry refined in two files); for a catalog file, the
    /// missions, catalog and strategy files sharing a unit with it; for a
    /// task graph, the graphs that read it (or were not analysed yet) and the
    /// missions whose dataflow ([`Analysis::dataflow`]) read it; for a
    /// project file, every file (it decides what each sees and its levels).
    pub fn affected_by(&self, id: FileId) -> Vec<FileId> {
        let Some(file) = self.file(id) else {
            return Vec::new();
        };
        let mut out = vec![id];
        match file.kind {
            FileKind::Project => out.extend(self.files.keys().copied()),
            FileKind::Mission => out.extend(
                self.seen_by(id)
                    .into_iter()
                    .filter(|&f| self.file(f).is_some_and(|f| f.kind == FileKind::Strategy)),
            ),
            FileKind::Catalog | FileKind::Strategy => {
                // Strategy files share a unit with every strategy file it
                // sees; catalog files also with its catalog files and missions.
                let shares = |kind: FileKind| {
                    kind == FileKind::Strategy
                        || (file.kind == FileKind::Catalog && kind == FileKind::Catalog)
                };
                for unit_folder in self.units_seeing(id) {
                    let Some(unit_folder) = unit_folder else {
                        continue;
                    };
                    if file.kind == FileKind::Catalog {
                        out.extend(self.missions_in(&unit_folder));
                    }
                    let seen = self.seen_ids(&unit_folder);
                    out.extend(
                        seen.iter()
                            .filter(|&&f| self.file(f).is_some_and(|f| shares(f.kind))),
                    );
                    // Documents that are not files read as files in the
                    // first root: the rule decides for them one by one.
                    let reader = unit_folder.join("_");
                    for other in self.files().filter(|f| f.key.is_none() && shares(f.kind)) {
                        if self.place(other).is_some_and(|p| self.sees(&reader, &p)) {
                            out.push(other.id);
                        }
                    }
                }
            }
            FileKind::TaskGraph => {
                let path = file.path.as_deref().map(subgraph::normalize);
                // The missions whose dataflow read it (as a service graph).
                for (mission, (_, found)) in lock(&self.memo.dataflow).iter() {
                    if found.graphs.contains(&id) {
                        out.push(*mission);
                    }
                }
                let graphs = lock(&self.memo.graphs);
                for other in self.files().filter(|f| f.kind == FileKind::TaskGraph) {
                    let reads = match (graphs.get(&other.id), &path) {
                        (None, _) => true,
                        (Some((_, run)), Some(path)) => run.hierarchy.reads.contains(path),
                        (Some(_), None) => false,
                    };
                    if reads {
                        out.push(other.id);
                    }
                }
            }
        }
        out.sort();
        out.dedup();
        out
    }
}

/// What [`Analysis::build_input`] gathers, owned; [`BuildFiles::input`] lends
/// it to `codegen::build`.
pub struct BuildFiles {
    pub file: Arc<SourceText>,
    pub analysis: Arc<sema::CheckedMission>,
    pub unit: Arc<Unit>,
    pub strategies: Vec<Strategy>,
    pub mission_name: String,
    pub strategy_names: Vec<(FileId, String)>,
    pub diagnostics: Vec<Diagnostic>,
    pub service_graphs: Vec<crate::refine::ServiceGraph>,
}

impl BuildFiles {
    pub fn input(&self) -> BuildInput<'_> {
        BuildInput {
            mission: self.file.id,
            mission_name: self.mission_name.clone(),
            text: &self.file.text,
            analysis: &self.analysis,
            catalog: &self.unit.catalog.catalog,
            strategies: &self.strategies,
            strategy_names: self.strategy_names.clone(),
            links: &self.unit.links,
            diagnostics: &self.diagnostics,
            service_graphs: &self.service_graphs,
        }
    }
}

mod dataflow;
mod disk;
mod dropper;
mod ide;
mod plan;
mod refined;
#[cfg(test)]
mod tests;
mod view;

pub use disk::{
    CheckRun, MAX_ENTRIES, ProjectInputs, STDIN_NAME, load_build, load_check, load_check_stdin,
    project_inputs,
};
pub use dropper::{Dropper, drop_later};
pub use ide::{PictureError, RobotPicture, WORKSPACE_SYMBOL_LIMIT};
pub use plan::{BuildPlan, DEFAULT_OUTPUT, DEFAULT_TARGET, PlanRequest, PlannedRobot};
