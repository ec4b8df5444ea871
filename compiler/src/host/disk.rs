//! The command line's doors into the host: which files `semo check PATH…` and
//! `semo build MISSION` load from the disk and report on. The rule for what a
//! file sees is the host's ([`super::sees`]); these only choose the roots and
//! load every file the rule could make a reported file see: the project
//! file above a path (`project::find`) and the folders it names, else the
//! named file's folder down to [`super::SEEN_DEPTH`] folders and at most
//! [`MAX_ENTRIES`] entries (past them, W112 on the file: a mission in
//! `/tmp` does not read all of `/tmp`).

use super::{Analysis, AnalysisHost, Roots, SEEN_DEPTH};
use crate::diag::{self, Code, Diagnostic, FileId};
use crate::project;
use crate::span::Span;
use crate::workspace::{Bound, FileKind, Files, LoadError, collect, collect_bounded, load_text};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Files loaded from disk into a host: their texts for rendering, the host,
/// the files the report covers, and their diagnostics (sorted by file and
/// position).
pub struct CheckRun {
    pub files: Files,
    pub host: AnalysisHost,
    /// The files the user asked about and those they read, in load order.
    pub checked: Vec<FileId>,
    pub diagnostics: Vec<Diagnostic>,
}

impl CheckRun {
    pub fn error_count(&self) -> usize {
        self.diagnostics.iter().filter(|d| d.is_error()).count()
    }

    pub fn analysis(&self) -> Analysis {
        self.host.analysis()
    }
}

/// Where a path is for the host: absolute and without `.`/`..`, so that
/// folders compare by prefix whatever way the user wrote them.
fn absolute(path: &Path) -> PathBuf {
    let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    crate::taskgraph::subgraph::normalize(&path)
}

fn folder_of(path: &Path) -> PathBuf {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf()
}

/// How many directory entries the search beside a named file looks at
/// when no project file says where to look.
pub const MAX_ENTRIES: usize = 20_000;

struct Loader {
    files: Files,
    host: AnalysisHost,
    by_path: HashMap<PathBuf, FileId>,
    checked: Vec<FileId>,
    /// Project roots whose folders are loaded.
    projects: Vec<PathBuf>,
    /// Found while loading (W112), reported with the rest.
    notes: Vec<Diagnostic>,
}

impl Default for Loader {
    fn default() -> Self {
        Loader {
            files: Files::default(),
            // Each text is analysed once.
            host: AnalysisHost::default().without_parse_caches(),
            by_path: HashMap::new(),
            checked: Vec::new(),
            projects: Vec::new(),
            notes: Vec::new(),
        }
    }
}

impl Loader {
    fn add(&mut self, path: &Path, kind: FileKind) -> Result<FileId, LoadError> {
        // A file reached two ways (`--strategy DIR` inside the mission's
        // folder, a link) is loaded once.
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| absolute(path));
        if let Some(&id) = self.by_path.get(&key) {
            return Ok(id);
        }
        let text = load_text(path)?;
        let shared: Arc<str> = text.as_str().into();
        let id = self.files.add(path.to_path_buf(), kind, text);
        self.host
            .set_file(id, Some(path.to_path_buf()), kind, shared);
        self.by_path.insert(key, id);
        Ok(id)
    }

    fn check(&mut self, id: FileId) {
        if !self.checked.contains(&id) {
            self.checked.push(id);
        }
    }

    /// Every SeMo file under `folder`, so that whatever sees what, the
    /// files are there.
    fn add_folder(&mut self, folder: &Path) -> Result<Vec<FileId>, LoadError> {
        let mut ids = Vec::new();
        for (path, kind) in collect(&[folder.to_path_buf()])? {
            ids.push(self.add(&path, kind)?);
        }
        Ok(ids)
    }

    /// A file named by the user, with the files it may read: it is
    /// reported with them.
    fn add_named_file(&mut self, path: &Path) -> Result<FileId, LoadError> {
        let id = self.add(path, FileKind::named_explicitly(path))?;
        self.add_beside(path, id)?;
        Ok(id)
    }

    /// What the file `id` at `path` may read: its project's folders and the
    /// other missions of its folder (its unit), else what is beside it.
    fn add_beside(&mut self, path: &Path, id: FileId) -> Result<(), LoadError> {
        let folder = folder_of(path);
        let depth = if self.add_project(&folder)? {
            0
        } else {
            SEEN_DEPTH
        };
        self.add_bounded(&folder, depth, id)
    }

    /// The files under `folder` within `depth` folders and [`MAX_ENTRIES`]
    /// entries; a W112 on `named` when the entries ran out.
    fn add_bounded(&mut self, folder: &Path, depth: usize, named: FileId) -> Result<(), LoadError> {
        let bound = Bound {
            depth,
            entries: MAX_ENTRIES,
        };
        let (found, stopped) = collect_bounded(folder, bound)?;
        for (path, kind) in found {
            self.add(&path, kind)?;
        }
        if stopped {
            self.notes.push(Diagnostic::new(
                Code::SearchBounded,
                named,
                Span::new(0, 0),
                format!(
                    "looked at only the first {MAX_ENTRIES} entries under {} for catalog and \
                     strategy files; put a semo.toml at the project root to say where they are",
                    absolute(folder).display()
                ),
            ));
        }
        Ok(())
    }

    /// The project file that applies to `folder` and every file of the
    /// folders it names; whether there is one.
    fn add_project(&mut self, folder: &Path) -> Result<bool, LoadError> {
        let Some(inputs) = project_inputs(folder) else {
            return Ok(false);
        };
        if self.projects.contains(&inputs.file) {
            return Ok(true);
        }
        self.projects.push(inputs.file.clone());
        self.add(&inputs.file, FileKind::Project)?;
        for folder in &inputs.folders {
            self.add_folder(folder)?;
        }
        Ok(true)
    }

    fn finish(self, roots: Roots, named: Vec<FileId>) -> CheckRun {
        let mut loader = self;
        loader.host.set_roots(roots);
        let analysis = loader.host.analysis();
        for id in named {
            for read in analysis.reads(id) {
                loader.check(read);
            }
        }
        // Each mission's dataflow warnings too: the editor shows them after
        // the keystroke's diagnostics; here there is no hurry. They refine
        // every robot, most of a check's work: the files are shared out
        // among the processors (the snapshot's memo is shared; the order
        // does not matter, the result is sorted).
        let mut diagnostics = on_every_processor(&loader.checked, |id| {
            let dataflow = analysis.dataflow(id);
            let mut found = analysis.diagnostics(id);
            found.extend(dataflow.iter().flat_map(|d| d.diagnostics.iter().cloned()));
            found
        });
        diagnostics.extend(loader.notes.iter().cloned());
        diag::sort_and_dedup(&mut diagnostics);
        CheckRun {
            files: loader.files,
            host: loader.host,
            checked: loader.checked,
            diagnostics,
        }
    }
}

/// `each` of every item, on as many threads as there are processors (each
/// takes the next item when done), the results concatenated in any order.
fn on_every_processor<T: Send>(items: &[FileId], each: impl Fn(FileId) -> Vec<T> + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let work = || {
        let mut found = Vec::new();
        while let Some(&id) = items.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed)) {
            found.extend(each(id));
        }
        found
    };
    if threads < 2 || items.len() < 2 {
        return work();
    }
    std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..threads.min(items.len()))
            .map(|_| scope.spawn(work))
            .collect();
        let mut found = work();
        for helper in helpers {
            // A panic in a helper is a bug: raised here as it would have been.
            found.extend(
                helper
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e)),
            );
        }
        found
    })
}

/// A project file and the input folders it names that exist: what a door
/// loads, besides its own folders, for the files under the project.
pub struct ProjectInputs {
    pub file: PathBuf,
    pub folders: Vec<PathBuf>,
}

/// The project file that applies to `folder` ([`project::find`]) and its
/// catalog, strategy and task-graph folders (the CLI's loaders and the
/// language server's workspace scan both load these).
pub fn project_inputs(folder: &Path) -> Option<ProjectInputs> {
    let root = project::find(folder)?;
    let file = root.join(project::FILE_NAME);
    // An unreadable project file is reported when the door loads it.
    let text = load_text(&file).unwrap_or_default();
    let (project, _) = project::parse(FileId::default(), &root, &text);
    let mut folders: Vec<PathBuf> = project
        .catalogs
        .iter()
        .chain(&project.strategies)
        .chain(&project.task_graphs)
        .map(|f| f.path.clone())
        .filter(|f| f.is_dir())
        .collect();
    folders.sort();
    folders.dedup();
    Some(ProjectInputs { file, folders })
}

/// How a mission read from standard input is named in reports.
pub const STDIN_NAME: &str = "<stdin>";

/// `semo check -`: a mission given as text, not a file, so it sees no other
/// file (as an editor's unsaved document): checked against the built-in
/// catalog alone.
pub fn load_check_stdin(text: String) -> CheckRun {
    let mut loader = Loader::default();
    let shared: Arc<str> = text.as_str().into();
    let id = loader
        .files
        .add(PathBuf::from(STDIN_NAME), FileKind::Mission, text);
    loader.host.set_file(id, None, FileKind::Mission, shared);
    loader.finish(Roots::default(), vec![id])
}

/// `semo check PATH…`: a folder is a workspace root, and every file under it
/// is reported; a file's folder is its root, and the file is reported with
/// the catalog and strategy files it sees.
pub fn load_check(paths: &[PathBuf]) -> Result<CheckRun, LoadError> {
    let mut loader = Loader::default();
    let mut roots = Roots::default();
    let mut named = Vec::new();
    for path in paths {
        if path.is_dir() {
            roots.roots.push(absolute(path));
            named.extend(loader.add_folder(path)?);
            loader.add_project(path)?;
        } else {
            roots.roots.push(absolute(&folder_of(path)));
            named.push(loader.add_named_file(path)?);
        }
    }
    Ok(loader.finish(roots, named))
}

/// `semo build MISSION --strategy PATH…`: the mission's folder is its root;
/// the catalog and strategy files under each `--strategy` path are seen by
/// all. Gives the run (reporting the mission and what it reads) and the
/// mission's id.
pub fn load_build(mission: &Path, strategy: &[PathBuf]) -> Result<(CheckRun, FileId), LoadError> {
    let mut loader = Loader::default();
    let mut roots = Roots {
        roots: vec![absolute(&folder_of(mission))],
        seen_by_all: Vec::new(),
    };
    let id = loader.add(mission, FileKind::Mission)?;
    loader.add_beside(mission, id)?;
    for extra in strategy {
        for (path, kind) in collect(std::slice::from_ref(extra))? {
            if matches!(kind, FileKind::Catalog | FileKind::Strategy) {
                loader.add(&path, kind)?;
                roots.seen_by_all.push(absolute(&path));
            }
        }
    }
    Ok((loader.finish(roots, vec![id]), id))
}
