//! The server's state: every file it knows (open documents and files indexed
//! from the workspace folders), the workspace catalog, and immutable
//! [`Snapshot`]s that handlers analyse without holding the lock.
//!
//! Invariant: the [`World`] is only touched under its `std::sync::Mutex`, and
//! every notification applies its change synchronously, before its handler's
//! first `.await`, so changes are applied in the order the client sent them.
//! A snapshot is replaced (never mutated) when its text or the catalog changes;
//! a result computed for a snapshot that is no longer current is stale.

use crate::document::Document;
use crate::encoding::{Encoding, LineMap};
use semo::catalog::{Catalog, CatalogSource, load_catalog};
use semo::diag::{self, Diagnostic, FileId};
use semo::sema::{Analysis, check_parsed};
use semo::strategy::{Strategy, StrategyLinks, cross_check, load_strategy};
use semo::syntax::{ParseCache, parse_incremental};
use semo::taskgraph::subgraph::{self, SubgraphSource};
use semo::text::LineIndex;
use semo::workspace::{FileKind, GraphRun, analyze_graph_at};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock, PoisonError, mpsc};
use tower_lsp_server::ls_types::{TextDocumentContentChangeEvent, Uri};

/// The catalog files of the workspace and, built on first use, the catalog they
/// form with the built-in one.
pub struct CatalogState {
    pub files: Vec<CatalogFile>,
    built: OnceLock<(Catalog, Vec<Diagnostic>)>,
}

pub struct CatalogFile {
    pub id: FileId,
    pub path: Option<PathBuf>,
    pub text: Arc<str>,
}

impl CatalogState {
    fn new(files: Vec<CatalogFile>) -> CatalogState {
        CatalogState {
            files,
            built: OnceLock::new(),
        }
    }

    fn built(&self) -> &(Catalog, Vec<Diagnostic>) {
        self.built.get_or_init(|| {
            let sources: Vec<CatalogSource<'_>> = self
                .files
                .iter()
                .map(|f| CatalogSource {
                    file: f.id,
                    text: &f.text,
                    base_dir: f.path.as_deref().and_then(Path::parent),
                })
                .collect();
            load_catalog(&sources)
        })
    }

    pub fn catalog(&self) -> &Catalog {
        &self.built().0
    }

    /// The catalog diagnostics of one catalog file.
    pub fn diagnostics_of(&self, file: FileId) -> impl Iterator<Item = &Diagnostic> {
        self.built().1.iter().filter(move |d| d.file == file)
    }

    pub fn text_of(&self, file: FileId) -> Option<&str> {
        self.files.iter().find(|f| f.id == file).map(|f| &*f.text)
    }
}

/// The parse cache of the version of a file analysed last, shared by all
/// snapshots of the file: a mission's analysis parses incrementally from it
/// and leaves its own cache. Any cache gives the same result (only unchanged
/// text is reused); a recent one only makes it faster.
#[derive(Default)]
struct ParseSlot(Mutex<Option<Arc<ParseCache>>>);

impl ParseSlot {
    fn get(&self) -> Option<Arc<ParseCache>> {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    fn put(&self, cache: ParseCache) {
        *self.0.lock().unwrap_or_else(PoisonError::into_inner) = Some(Arc::new(cache));
    }
}

/// One version of one file, with the catalog it is checked against.
pub struct Snapshot {
    pub uri: Uri,
    pub id: FileId,
    pub kind: FileKind,
    /// The client's version for open documents; `None` for files read from disk.
    pub version: Option<i32>,
    pub text: Arc<str>,
    pub catalog: Arc<CatalogState>,
    pub encoding: Encoding,
    /// For a strategy file: the missions it is cross-checked against.
    pub missions: Vec<Arc<Snapshot>>,
    /// For a task graph: the task-graph files the server knows, by path,
    /// where its `subgraph` references are looked up before the disk.
    pub graphs: GraphFiles,
    parses: Arc<ParseSlot>,
    analysis: OnceLock<Arc<FileAnalysis>>,
}

/// Task-graph texts by (normalized) path: open documents as the client has
/// them, workspace files as read from the disk.
pub type GraphFiles = Arc<HashMap<PathBuf, SubgraphSource>>;

/// Looks referenced sub-graph files up in the server's files, else reads
/// them from the disk. Files the server does not know get ids counting down
/// from below the built-in catalog's: they are read for this analysis only
/// and nothing is published for them.
struct GraphResolver<'a> {
    known: &'a GraphFiles,
    next: u32,
}

impl subgraph::Resolver for GraphResolver<'_> {
    fn read(&mut self, path: &Path) -> Result<SubgraphSource, String> {
        if let Some(source) = self.known.get(path) {
            return Ok(source.clone());
        }
        let text = read_text(path)
            .ok_or_else(|| format!("there is no readable file {}", path.display()))?;
        self.next -= 1;
        Ok(SubgraphSource {
            file: FileId(self.next),
            text: text.into(),
        })
    }
}

/// What is known about a snapshot once analysed.
pub struct FileAnalysis {
    pub lines: LineIndex,
    /// The diagnostics of catalog and strategy files (missions and task
    /// graphs keep theirs in their own results).
    other_diagnostics: Vec<Diagnostic>,
    pub mission: Option<Analysis>,
    pub graph: Option<GraphRun>,
    pub strategy: Option<Strategy>,
    /// For a strategy file: the mission calls its entries refine (against
    /// the snapshot's `missions`).
    pub strategy_links: StrategyLinks,
}

impl FileAnalysis {
    fn new(lines: LineIndex) -> FileAnalysis {
        FileAnalysis {
            lines,
            other_diagnostics: Vec::new(),
            mission: None,
            graph: None,
            strategy: None,
            strategy_links: StrategyLinks::default(),
        }
    }

    /// Diagnostics of this file, sorted.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match (&self.mission, &self.graph) {
            (Some(mission), _) => &mission.diagnostics,
            (_, Some(run)) => &run.diagnostics,
            _ => &self.other_diagnostics,
        }
    }
}

impl Snapshot {
    /// Analyses the snapshot once; concurrent callers wait for the first.
    pub fn analysis(&self) -> Arc<FileAnalysis> {
        self.analysis
            .get_or_init(|| Arc::new(self.analyse()))
            .clone()
    }

    fn analyse(&self) -> FileAnalysis {
        let mut out = FileAnalysis::new(LineIndex::new(&self.text));
        match self.kind {
            FileKind::Mission => {
                let previous = self.parses.get();
                let (parse, cache) = parse_incremental(self.id, &self.text, previous.as_deref());
                drop(previous);
                self.parses.put(cache);
                out.mission = Some(check_parsed(self.id, parse, self.catalog.catalog()));
            }
            FileKind::Catalog => {
                out.other_diagnostics = self.catalog.diagnostics_of(self.id).cloned().collect();
                diag::sort_and_dedup(&mut out.other_diagnostics);
            }
            FileKind::TaskGraph => {
                let location = self.uri.to_file_path();
                let mut resolver = GraphResolver {
                    known: &self.graphs,
                    next: semo::catalog::BUILTIN_FILE.0,
                };
                out.graph = Some(analyze_graph_at(
                    self.id,
                    &self.text,
                    location.as_deref(),
                    &mut resolver,
                ));
            }
            FileKind::Strategy => {
                let (strategy, mut diagnostics) = load_strategy(self.id, &self.text);
                if let Some(strategy) = &strategy {
                    let analyses: Vec<Arc<FileAnalysis>> =
                        self.missions.iter().map(|m| m.analysis()).collect();
                    let missions: Vec<&Analysis> =
                        analyses.iter().filter_map(|a| a.mission.as_ref()).collect();
                    let (links, cross) =
                        cross_check(&[strategy], &missions, self.catalog.catalog());
                    diagnostics.extend(cross.into_iter().filter(|d| d.file == self.id));
                    out.strategy_links = links;
                    diag::sort_and_dedup(&mut diagnostics);
                }
                out.other_diagnostics = diagnostics;
                out.strategy = strategy;
            }
        }
        out
    }

    /// The text of another file this snapshot's analysis refers to: one of
    /// its missions or a catalog file.
    pub fn text_of(&self, file: FileId) -> Option<&str> {
        if file == self.id {
            return Some(&self.text);
        }
        if let Some(m) = self.missions.iter().find(|m| m.id == file) {
            return Some(&m.text);
        }
        self.catalog.text_of(file)
    }

    /// Converts positions of this snapshot's text.
    pub fn line_map<'a>(&'a self, analysis: &'a FileAnalysis) -> LineMap<'a> {
        LineMap {
            text: &self.text,
            index: &analysis.lines,
            encoding: self.encoding,
        }
    }
}

/// Lets go of a snapshot that a newer one replaced. Freeing an analysed
/// mission (its tree and IR) takes about a millisecond on a 10k-line file:
/// that is done on a background thread, so that it delays neither the next
/// edit's diagnostics nor, under the world's lock, other requests.
pub fn retire(snapshot: Arc<Snapshot>) {
    static DROPPER: OnceLock<Option<mpsc::Sender<Arc<Snapshot>>>> = OnceLock::new();
    if snapshot.analysis.get().is_none() {
        return; // little to free
    }
    let dropper = DROPPER.get_or_init(|| {
        let (send, receive) = mpsc::channel::<Arc<Snapshot>>();
        std::thread::Builder::new()
            .name("semo-drop".into())
            .spawn(move || receive.into_iter().for_each(drop))
            .ok()
            .map(|_| send)
    });
    // Without the thread (it could not start), the snapshot is dropped here.
    if let Some(send) = dropper {
        let _ = send.send(snapshot);
    }
}

struct FileEntry {
    kind: FileKind,
    /// Set while the client has the file open.
    document: Option<Document>,
    /// Where the file is on disk, if it is a `file:` URI.
    path: Option<PathBuf>,
    snapshot: Arc<Snapshot>,
}

#[derive(Default)]
pub struct World {
    pub encoding: Encoding,
    pub roots: Vec<PathBuf>,
    files: HashMap<Uri, FileEntry>,
    /// `FileId(i)` is `uris[i]`; ids are never reused within a session.
    uris: Vec<Uri>,
    ids: HashMap<Uri, FileId>,
    catalog: Option<Arc<CatalogState>>,
    /// The task-graph files by path, built when a task graph needs it.
    graph_files: Option<GraphFiles>,
}

/// What a change did, so the caller knows which files to re-check.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Changed {
    pub files: Vec<Uri>,
}

impl World {
    /// The kind of file a URI names, from its file name, else (for unsaved
    /// buffers) from the client's language id.
    pub fn kind_of(uri: &Uri, language_id: Option<&str>) -> Option<FileKind> {
        let path = uri.path().as_str();
        let name = path.rsplit('/').next().unwrap_or(path);
        FileKind::of(Path::new(name)).or(match language_id {
            Some("mission" | "semo") => Some(FileKind::Mission),
            _ => None,
        })
    }

    pub fn file_id(&mut self, uri: &Uri) -> FileId {
        if let Some(&id) = self.ids.get(uri) {
            return id;
        }
        let id = FileId(self.uris.len() as u32);
        self.uris.push(uri.clone());
        self.ids.insert(uri.clone(), id);
        id
    }

    pub fn uri_of(&self, id: FileId) -> Option<&Uri> {
        self.uris.get(id.0 as usize)
    }

    pub fn snapshot(&self, uri: &Uri) -> Option<Arc<Snapshot>> {
        self.files.get(uri).map(|f| f.snapshot.clone())
    }

    /// Whether `snapshot` is still the newest of its file (else its results are stale).
    pub fn is_current(&self, snapshot: &Arc<Snapshot>) -> bool {
        self.files
            .get(&snapshot.uri)
            .is_some_and(|f| Arc::ptr_eq(&f.snapshot, snapshot))
    }

    pub fn is_open(&self, uri: &Uri) -> bool {
        self.files.get(uri).is_some_and(|f| f.document.is_some())
    }

    pub fn uris(&self) -> impl Iterator<Item = &Uri> {
        self.files.keys()
    }

    /// The current snapshot of every file the server knows.
    pub fn snapshots(&self) -> impl Iterator<Item = &Arc<Snapshot>> {
        self.files.values().map(|f| &f.snapshot)
    }

    /// The current snapshot of every strategy file (for features of missions
    /// that lead into strategies).
    pub fn strategies(&self) -> Vec<Arc<Snapshot>> {
        self.files
            .values()
            .filter(|f| f.kind == FileKind::Strategy)
            .map(|f| f.snapshot.clone())
            .collect()
    }

    pub fn catalog(&mut self) -> Arc<CatalogState> {
        if let Some(c) = &self.catalog {
            return c.clone();
        }
        let mut files: Vec<CatalogFile> = self
            .files
            .iter()
            .filter(|(_, f)| f.kind == FileKind::Catalog)
            .map(|(uri, f)| CatalogFile {
                id: self.ids[uri],
                path: f.path.clone(),
                text: f.snapshot.text.clone(),
            })
            .collect();
        // A stable order, so "defined in another catalog file" always names the same one.
        files.sort_by(|a, b| a.path.cmp(&b.path).then(a.id.0.cmp(&b.id.0)));
        let state = Arc::new(CatalogState::new(files));
        self.catalog = Some(state.clone());
        state
    }

    /// The client opened a document.
    pub fn open(&mut self, uri: Uri, language_id: &str, text: &str, version: i32) -> Changed {
        let Some(kind) = World::kind_of(&uri, Some(language_id)) else {
            return Changed::default();
        };
        let document = Document::new(text, version);
        let path = uri.to_file_path().map(|p| p.into_owned());
        self.set_text(uri, kind, path, Some(document), text.into())
    }

    /// The client changed an open document. Changes to unknown documents are
    /// ignored (the client will open them first).
    pub fn change(
        &mut self,
        uri: &Uri,
        version: i32,
        changes: Vec<TextDocumentContentChangeEvent>,
    ) -> Changed {
        let encoding = self.encoding;
        let Some(entry) = self.files.get_mut(uri) else {
            return Changed::default();
        };
        let Some(document) = entry.document.as_mut() else {
            return Changed::default();
        };
        document.apply(changes, version, encoding);
        let text: Arc<str> = document.rope.to_string().into();
        let (kind, path, document) = (entry.kind, entry.path.clone(), entry.document.take());
        self.set_text(uri.clone(), kind, path, document, text)
    }

    /// The client closed a document: it falls back to its text on disk if it
    /// is in the workspace, else it is forgotten.
    pub fn close(&mut self, uri: &Uri) -> Changed {
        let Some(entry) = self.files.get(uri) else {
            return Changed::default();
        };
        let (kind, path) = (entry.kind, entry.path.clone());
        let on_disk = path
            .as_ref()
            .filter(|p| self.in_workspace(p))
            .and_then(|p| read_text(p));
        match on_disk {
            Some(text) => self.set_text(uri.clone(), kind, path, None, text.into()),
            None => self.remove(uri),
        }
    }

    /// A file of the workspace was created or changed on disk (`text`, read
    /// by the caller outside the lock; `None` if it could not be read). Open
    /// documents keep the client's text.
    pub fn disk_changed(&mut self, uri: &Uri, text: Option<String>) -> Changed {
        if self.is_open(uri) {
            return Changed::default();
        }
        let path = uri.to_file_path().map(|p| p.into_owned());
        let kind = World::kind_of(uri, None);
        match (path, kind, text) {
            (Some(path), Some(kind), Some(text)) => {
                self.set_text(uri.clone(), kind, Some(path), None, text.into())
            }
            _ => self.remove(uri),
        }
    }

    /// A file was deleted on disk. An open document stays as the client has it.
    pub fn disk_deleted(&mut self, uri: &Uri) -> Changed {
        if self.is_open(uri) {
            return Changed::default();
        }
        self.remove(uri)
    }

    fn in_workspace(&self, path: &Path) -> bool {
        self.roots.iter().any(|r| path.starts_with(r))
    }

    fn remove(&mut self, uri: &Uri) -> Changed {
        let Some(entry) = self.files.remove(uri) else {
            return Changed::default();
        };
        retire(entry.snapshot.clone());
        let mut changed = match entry.kind {
            FileKind::Catalog => self.catalog_changed(),
            FileKind::Mission => self.missions_changed(),
            FileKind::TaskGraph => self.graph_changed(uri, entry.path.as_deref()),
            _ => Changed::default(),
        };
        changed.files.push(uri.clone());
        changed
    }

    fn set_text(
        &mut self,
        uri: Uri,
        kind: FileKind,
        path: Option<PathBuf>,
        document: Option<Document>,
        text: Arc<str>,
    ) -> Changed {
        let id = self.file_id(&uri);
        let version = document.as_ref().map(|d| d.version);
        let is_catalog = kind == FileKind::Catalog;
        if kind == FileKind::TaskGraph {
            // Its new text is looked up by the graphs referencing it.
            self.graph_files = None;
        }
        // A catalog file gets its snapshot on the new catalog just below.
        let catalog = if is_catalog {
            Arc::new(CatalogState::new(Vec::new()))
        } else {
            self.catalog()
        };
        let snapshot = Arc::new(self.new_snapshot(&uri, id, kind, version, text, catalog));
        let old = self.files.insert(
            uri.clone(),
            FileEntry {
                kind,
                document,
                path,
                snapshot,
            },
        );
        if let Some(old) = old {
            retire(old.snapshot);
        }
        let mut changed = if is_catalog {
            self.catalog_changed()
        } else if kind == FileKind::Mission {
            self.missions_changed()
        } else if kind == FileKind::TaskGraph {
            let path = self.files.get(&uri).and_then(|f| f.path.clone());
            self.graph_changed(&uri, path.as_deref())
        } else {
            Changed::default()
        };
        if !changed.files.contains(&uri) {
            changed.files.push(uri);
        }
        changed
    }

    fn new_snapshot(
        &mut self,
        uri: &Uri,
        id: FileId,
        kind: FileKind,
        version: Option<i32>,
        text: Arc<str>,
        catalog: Arc<CatalogState>,
    ) -> Snapshot {
        let missions = if kind == FileKind::Strategy {
            self.files
                .values()
                .filter(|f| f.kind == FileKind::Mission)
                .map(|f| f.snapshot.clone())
                .collect()
        } else {
            Vec::new()
        };
        let graphs = if kind == FileKind::TaskGraph {
            self.graph_files()
        } else {
            GraphFiles::default()
        };
        Snapshot {
            uri: uri.clone(),
            id,
            kind,
            version,
            text,
            catalog,
            encoding: self.encoding,
            missions,
            graphs,
            // Handed from each snapshot of the file to the next.
            parses: self
                .files
                .get(uri)
                .map(|f| f.snapshot.parses.clone())
                .unwrap_or_default(),
            analysis: OnceLock::new(),
        }
    }

    /// The task-graph files by path (built again after a task graph changed).
    fn graph_files(&mut self) -> GraphFiles {
        if let Some(files) = &self.graph_files {
            return files.clone();
        }
        let files: GraphFiles = Arc::new(
            self.files
                .values()
                .filter(|f| f.kind == FileKind::TaskGraph)
                .filter_map(|f| {
                    let path = subgraph::normalize(f.path.as_deref()?);
                    let source = SubgraphSource {
                        file: f.snapshot.id,
                        text: f.snapshot.text.clone(),
                    };
                    Some((path, source))
                })
                .collect(),
        );
        self.graph_files = Some(files.clone());
        files
    }

    /// The task graph at `uri` (at `path` on disk) changed or went away: the
    /// other task graphs that read it through `subgraph` references (or that
    /// were not analysed yet, so nobody knows) get new snapshots seeing its
    /// new text.
    fn graph_changed(&mut self, uri: &Uri, path: Option<&Path>) -> Changed {
        self.graph_files = None;
        let Some(path) = path.map(subgraph::normalize) else {
            return Changed::default();
        };
        self.renew(|other, entry| {
            entry.kind == FileKind::TaskGraph
                && other != uri
                && entry.snapshot.analysis.get().is_none_or(|a| {
                    a.graph
                        .as_ref()
                        .is_some_and(|run| run.hierarchy.reads.contains(&path))
                })
        })
    }

    /// Strategy files are cross-checked against the missions: they get new
    /// snapshots on the current missions.
    fn missions_changed(&mut self) -> Changed {
        self.renew(|_, f| f.kind == FileKind::Strategy)
    }

    /// Every file gets a new snapshot on the new catalog (missions are
    /// re-checked against it, catalog files get their new diagnostics).
    fn catalog_changed(&mut self) -> Changed {
        self.catalog = None;
        let mut changed =
            self.renew(|_, f| matches!(f.kind, FileKind::Mission | FileKind::Catalog));
        // Strategies last, on the missions' new snapshots.
        changed.files.extend(self.missions_changed().files);
        changed
    }

    /// New snapshots (same text, the current catalog) for the files `which`
    /// selects; the old ones are retired.
    fn renew(&mut self, which: impl Fn(&Uri, &FileEntry) -> bool) -> Changed {
        let catalog = self.catalog();
        let uris: Vec<Uri> = self
            .files
            .iter()
            .filter(|(u, f)| which(u, f))
            .map(|(u, _)| u.clone())
            .collect();
        for uri in &uris {
            let old = self.files[uri].snapshot.clone();
            let fresh = Arc::new(self.new_snapshot(
                uri,
                old.id,
                old.kind,
                old.version,
                old.text.clone(),
                catalog.clone(),
            ));
            let entry = self.files.get_mut(uri).expect("listed above");
            retire(std::mem::replace(&mut entry.snapshot, fresh));
        }
        Changed { files: uris }
    }
}

/// Every mission, catalog and task graph under the given roots, with its text
/// (read without holding any lock).
pub fn read_roots(roots: &[PathBuf]) -> Vec<(Uri, Option<String>)> {
    let mut found = Vec::new();
    for root in roots {
        // A root that cannot be listed has nothing to index.
        let Ok(files) = semo::workspace::collect(std::slice::from_ref(root)) else {
            continue;
        };
        for (path, _) in files {
            if let Some(uri) = Uri::from_file_path(&path) {
                found.push((uri, read_text(&path)));
            }
        }
    }
    found
}

/// A file's text, with invalid UTF-8 replaced (so the rest is still checked).
pub fn read_text(path: &Path) -> Option<String> {
    semo::workspace::read_text(path).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tower_lsp_server::ls_types::{Position, Range};

    const MISSION: &str = "{ A: Turtlebot3_Burger tb }\n\
        A.P.S { move(\"1,1\") }\n\
        A.M { set(P, S) }\n\
        A.main { default: mode = M }\n";

    #[test]
    fn each_version_of_a_mission_is_parsed_from_the_cache_of_the_last() {
        let mut world = World::default();
        let uri = Uri::from_file_path("/t/a.mission").expect("a file URI");
        world.open(uri.clone(), "mission", MISSION, 1);
        let first = world.snapshot(&uri).expect("open");
        first.analysis();
        assert_eq!(first.parses.get().map(|c| c.reparsed()), Some(4));
        // `move("1,1")` becomes `move("1,12")`: one chunk changes.
        let typed = TextDocumentContentChangeEvent {
            range: Some(Range::new(Position::new(1, 17), Position::new(1, 17))),
            range_length: None,
            text: "2".to_string(),
        };
        world.change(&uri, 2, vec![typed]);
        let second = world.snapshot(&uri).expect("open");
        let analysis = second.analysis();
        let cache = second.parses.get().expect("left by the analysis");
        assert_eq!((cache.chunks(), cache.reparsed()), (4, 1));
        let scratch = semo::check_source(second.id, &second.text, second.catalog.catalog());
        assert_eq!(analysis.diagnostics(), &scratch.diagnostics[..]);
        assert_eq!(
            analysis.mission.as_ref().map(|m| &m.syntax),
            Some(&scratch.syntax)
        );
        // Snapshots of the same text on a new catalog reuse every chunk.
        world.catalog_changed();
        let third = world.snapshot(&uri).expect("open");
        assert!(!Arc::ptr_eq(&second, &third));
        third.analysis();
        assert_eq!(third.parses.get().map(|c| c.reparsed()), Some(0));
    }

    #[test]
    fn replaced_snapshots_are_freed_in_the_background() {
        let mut world = World::default();
        let uri = Uri::from_file_path("/t/b.mission").expect("a file URI");
        world.open(uri.clone(), "mission", MISSION, 1);
        let first = world.snapshot(&uri).expect("open");
        first.analysis();
        let weak = Arc::downgrade(&first);
        drop(first);
        world.change(&uri, 2, Vec::new());
        let start = std::time::Instant::now();
        while weak.upgrade().is_some() {
            assert!(
                start.elapsed().as_secs() < 10,
                "the old snapshot was never freed"
            );
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
}
