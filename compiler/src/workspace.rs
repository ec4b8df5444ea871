//! Files on disk: their kinds, reading them (the one place that reads files),
//! listing folders (a folder stands for every `.mission`, `.robot.xml`,
//! `.strategy.xml` and `.taskgraph.xml` file and every `semo.toml` under it), the texts of a check for
//! rendering ([`Files`]), and task graphs analysed with their sub-graphs.
//! Which files belong together is the host's rule (`crate::host`).

use crate::catalog::{BUILTIN_FILE, BUILTIN_NAME, BUILTIN_SOURCE};
use crate::diag::{self, Diagnostic, FileId};
use crate::taskgraph::subgraph::{self, Hierarchy, Resolver, SubgraphSource};
use crate::text::LineIndex;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Mission,
    Catalog,
    /// `*.taskgraph.xml`, or an SDF3 graph named explicitly.
    TaskGraph,
    /// `*.strategy.xml`.
    Strategy,
    /// `semo.toml`, the project file (`crate::project`).
    Project,
}

impl FileKind {
    pub fn of(path: &Path) -> Option<FileKind> {
        let name = path.file_name()?.to_str()?;
        if name == crate::project::FILE_NAME {
            Some(FileKind::Project)
        } else if name.ends_with(".robot.xml") {
            Some(FileKind::Catalog)
        } else if name.ends_with(".taskgraph.xml") {
            Some(FileKind::TaskGraph)
        } else if name.ends_with(".strategy.xml") {
            Some(FileKind::Strategy)
        } else if name.ends_with(".mission") {
            Some(FileKind::Mission)
        } else {
            None
        }
    }
}

impl FileKind {
    /// The kind of a file the user named: as [`FileKind::of`], else any other
    /// `.xml` file is a task graph (an SDF3 benchmark, say) and anything else a
    /// mission, whatever its extension.
    pub fn named_explicitly(path: &Path) -> FileKind {
        FileKind::of(path).unwrap_or_else(|| match path.extension().and_then(|e| e.to_str()) {
            Some(ext) if ext.eq_ignore_ascii_case("xml") => FileKind::TaskGraph,
            _ => FileKind::Mission,
        })
    }
}

/// A loaded source file.
#[derive(Clone, Debug)]
pub struct SourceFile {
    pub id: FileId,
    pub path: PathBuf,
    pub kind: FileKind,
    pub text: String,
    pub lines: LineIndex,
}

/// The files of one check, addressable by [`FileId`]. The built-in catalog is
/// always there, so diagnostics that point into it can be shown.
#[derive(Clone, Debug)]
pub struct Files {
    files: Vec<SourceFile>,
    builtin: SourceFile,
}

impl Default for Files {
    fn default() -> Self {
        Files {
            files: Vec::new(),
            builtin: SourceFile {
                id: BUILTIN_FILE,
                path: PathBuf::from(format!("<built-in>/{BUILTIN_NAME}")),
                kind: FileKind::Catalog,
                text: BUILTIN_SOURCE.to_string(),
                lines: LineIndex::new(BUILTIN_SOURCE),
            },
        }
    }
}

impl Files {
    pub fn add(&mut self, path: PathBuf, kind: FileKind, text: String) -> FileId {
        let id = FileId(self.files.len() as u32);
        let lines = LineIndex::new(&text);
        self.files.push(SourceFile {
            id,
            path,
            kind,
            text,
            lines,
        });
        id
    }

    pub fn get(&self, id: FileId) -> &SourceFile {
        if id == BUILTIN_FILE {
            return &self.builtin;
        }
        &self.files[id.0 as usize]
    }

    pub fn iter(&self) -> impl Iterator<Item = &SourceFile> {
        self.files.iter()
    }
}

/// A problem reading the paths given (reported with exit code 2).
#[derive(Debug)]
pub struct LoadError {
    pub path: PathBuf,
    pub message: String,
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.message)
    }
}

/// Expands the paths given on the command line: files as they are (see
/// [`FileKind::named_explicitly`]), folders recursively (their `.mission`,
/// `.robot.xml`, `.strategy.xml` and `.taskgraph.xml` files), sorted for
/// stable output.
pub fn collect(paths: &[PathBuf]) -> Result<Vec<(PathBuf, FileKind)>, LoadError> {
    let mut found = Vec::new();
    for path in paths {
        let meta = std::fs::metadata(path).map_err(|e| LoadError {
            path: path.clone(),
            message: e.to_string(),
        })?;
        if meta.is_dir() {
            walk(path, &mut found)?;
        } else {
            found.push((path.clone(), FileKind::named_explicitly(path)));
        }
    }
    Ok(found)
}

/// How far [`collect_bounded`] goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bound {
    /// Folders below the first one (0: only its own entries).
    pub depth: usize,
    /// Directory entries looked at, at most.
    pub entries: usize,
}

/// [`collect`] for one folder within `bound`, nearest first: the folder's
/// entries, then those of its sub-folders, and so on (breadth first), so
/// the bound cuts what is farthest away. Skips and links as [`walk`]. The
/// flag says whether it stopped at `bound.entries` (entries past it were not
/// looked at); the files come sorted by path.
pub fn collect_bounded(
    dir: &Path,
    bound: Bound,
) -> Result<(Vec<(PathBuf, FileKind)>, bool), LoadError> {
    let error = |path: &Path, e: std::io::Error| LoadError {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut found: Vec<(PathBuf, FileKind)> = Vec::new();
    let mut level = vec![dir.to_path_buf()];
    let mut seen = 0usize;
    for depth in 0..=bound.depth {
        let mut below = Vec::new();
        for folder in &level {
            let mut entries = std::fs::read_dir(folder)
                .map_err(|e| error(folder, e))?
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| error(folder, e))?;
            entries.sort_by_key(|e| e.file_name());
            for entry in entries {
                if skipped(&entry.file_name()) {
                    continue;
                }
                seen += 1;
                if seen > bound.entries {
                    found.sort_by(|a, b| a.0.cmp(&b.0));
                    return Ok((found, true));
                }
                let path = entry.path();
                let kind = entry.file_type().map_err(|e| error(&path, e))?;
                if kind.is_dir() {
                    if depth < bound.depth {
                        below.push(path);
                    }
                    continue;
                }
                let is_file = kind.is_file()
                    || (kind.is_symlink() && std::fs::metadata(&path).is_ok_and(|m| m.is_file()));
                if let (true, Some(kind)) = (is_file, FileKind::of(&path)) {
                    found.push((path, kind));
                }
            }
        }
        level = below;
    }
    found.sort_by(|a, b| a.0.cmp(&b.0));
    Ok((found, false))
}

/// Entries no walk goes into: hidden ones, `target`, `node_modules`.
fn skipped(name: &std::ffi::OsStr) -> bool {
    name.to_str()
        .is_some_and(|n| n.starts_with('.') || n == "target" || n == "node_modules")
}

/// A folder's files of the kinds above, sorted. Hidden entries, `target` and
/// `node_modules` are skipped; symbolic links to files are read, but links to
/// folders are not followed, so a link to the folder itself or an ancestor
/// cannot make the walk loop (nor can a link to `/` make it read the disk).
fn walk(dir: &Path, found: &mut Vec<(PathBuf, FileKind)>) -> Result<(), LoadError> {
    let skipped = |e: &walkdir::DirEntry| e.depth() > 0 && skipped(e.file_name());
    let entries = walkdir::WalkDir::new(dir)
        .follow_links(false)
        .sort_by_file_name()
        .into_iter()
        .filter_entry(|e| !skipped(e));
    for entry in entries {
        let entry = entry.map_err(|e| LoadError {
            path: e.path().unwrap_or(dir).to_path_buf(),
            message: e.to_string(),
        })?;
        let is_file = match entry.file_type() {
            t if t.is_file() => true,
            // A link is read when it leads to a file (`metadata` follows it once).
            t if t.is_symlink() => std::fs::metadata(entry.path()).is_ok_and(|m| m.is_file()),
            _ => false,
        };
        if let (true, Some(kind)) = (is_file, FileKind::of(entry.path())) {
            found.push((entry.into_path(), kind));
        }
    }
    Ok(())
}

pub use crate::fsread::{MAX_FILE_BYTES, read_text, read_text_limited};

/// [`read_text`] for the CLI's loaders: the error names the file.
pub fn load_text(path: &Path) -> Result<String, LoadError> {
    read_text(path).map_err(|e| LoadError {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// A task graph file loaded and analysed.
pub struct GraphRun {
    /// `None` when the file could not be read as a task graph at all.
    pub graph: Option<crate::taskgraph::TaskGraph>,
    /// The sub-graphs its tasks reference, resolved.
    pub hierarchy: Hierarchy,
    pub report: crate::taskgraph::analysis::GraphReport,
    /// Loading, reference and analysis diagnostics, sorted.
    pub diagnostics: Vec<Diagnostic>,
}

/// Loads a task graph (ours or SDF3), follows its `subgraph` references from
/// the disk, and runs its analyses; a graph that did not load cleanly is not
/// analysed, so that its problems are not reported twice.
pub fn analyze_graph(file: &SourceFile, resolver: &mut FileResolver) -> GraphRun {
    analyze_graph_at(file.id, &file.text, Some(&file.path), resolver)
}

/// [`analyze_graph`] for text held anywhere (the language server's
/// documents), at `location` if it has one, reading referenced files through
/// `resolver`.
pub fn analyze_graph_at(
    file: FileId,
    text: &str,
    location: Option<&Path>,
    resolver: &mut dyn Resolver,
) -> GraphRun {
    analyze_graph_as(file, text, location, resolver, GraphReading::default())
}

/// How a task-graph file is read and analysed; by default as its format
/// means it (see [`GraphReading::concurrency`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GraphReading {
    /// Whether a task fires concurrently with itself; `None`: as the file's
    /// format means it (SDF3 files auto-concurrency, ours one at a time).
    pub concurrency: Option<crate::taskgraph::analysis::Concurrency>,
    /// Which of an SDF3 actor's execution times is its time.
    pub times: crate::taskgraph::ExecutionTimes,
}

/// [`analyze_graph_at`], read and analysed as `reading` says.
pub fn analyze_graph_as(
    file: FileId,
    text: &str,
    location: Option<&Path>,
    resolver: &mut dyn Resolver,
    reading: GraphReading,
) -> GraphRun {
    use crate::taskgraph::analysis::Concurrency;
    let (graph, mut diagnostics) = crate::taskgraph::load_task_graph_as(file, text, reading.times);
    let loaded_cleanly = !diagnostics.iter().any(Diagnostic::is_error);
    let concurrency = reading.concurrency.unwrap_or_else(|| {
        crate::taskgraph::detect_format(text).map_or(Concurrency::Single, Concurrency::of)
    });
    let (hierarchy, report) = match &graph {
        Some(g) if loaded_cleanly => {
            let hierarchy = crate::taskgraph::resolve(g, location, resolver);
            let report = crate::taskgraph::analysis::analyze_as(g, &hierarchy, concurrency);
            (hierarchy, report)
        }
        _ => (
            Hierarchy::default(),
            crate::taskgraph::analysis::GraphReport {
                concurrency,
                ..Default::default()
            },
        ),
    };
    diagnostics.extend(hierarchy.diagnostics.iter().cloned());
    diagnostics.extend(report.diagnostics.iter().cloned());
    diag::sort_and_dedup(&mut diagnostics);
    GraphRun {
        graph,
        hierarchy,
        report,
        diagnostics,
    }
}

/// The one reader of referenced sub-graph files, for every door: a file the
/// caller holds (the check's files, the host's documents) keeps its id and
/// text; any other is read from the disk once and given a fresh id.
pub struct FileResolver<'f> {
    known: std::collections::HashMap<PathBuf, SubgraphSource>,
    /// The caller's files by normalized path, their texts shared (copied
    /// into `known`) only when a reference names one: the CLI's one file
    /// may be large, and is rarely referenced.
    held: std::collections::HashMap<PathBuf, (FileId, &'f str)>,
    next: u32,
    /// Fresh ids count down from `next` (below ids in use) or up from it.
    downward: bool,
}

impl<'f> FileResolver<'f> {
    /// For the CLI: the check's files; fresh ids after theirs.
    pub fn new(files: &'f Files) -> FileResolver<'f> {
        let held = files
            .iter()
            .map(|f| (subgraph::normalize(&f.path), (f.id, f.text.as_str())));
        FileResolver {
            known: std::collections::HashMap::new(),
            held: held.collect(),
            next: files.iter().count() as u32,
            downward: false,
        }
    }

    /// Over `known` files (by normalized path); fresh ids count down from
    /// just below `below` (the host's ids are small and dense; those below
    /// the built-in catalog's are free).
    pub fn below(
        known: impl IntoIterator<Item = (PathBuf, SubgraphSource)>,
        below: FileId,
    ) -> Self {
        FileResolver {
            known: known.into_iter().collect(),
            held: std::collections::HashMap::new(),
            next: below.0,
            downward: true,
        }
    }

    fn fresh_id(&mut self) -> FileId {
        if self.downward {
            self.next -= 1;
            FileId(self.next)
        } else {
            self.next += 1;
            FileId(self.next - 1)
        }
    }
}

impl Resolver for FileResolver<'_> {
    fn read(&mut self, path: &Path) -> Result<SubgraphSource, String> {
        if let Some(source) = self.known.get(path) {
            return Ok(source.clone());
        }
        if let Some(&(file, text)) = self.held.get(path) {
            let source = SubgraphSource {
                file,
                text: text.into(),
            };
            self.known.insert(path.to_path_buf(), source.clone());
            return Ok(source);
        }
        let text = read_text(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => format!("there is no file {}", path.display()),
            _ => format!("{}: {e}", path.display()),
        })?;
        let source = SubgraphSource {
            file: self.fresh_id(),
            text: text.into(),
        };
        self.known.insert(path.to_path_buf(), source.clone());
        Ok(source)
    }
}
