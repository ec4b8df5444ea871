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
use semo::catalog::Catalog;
use semo::diag::{Diagnostic, FileId};
use semo::host::{self, AnalysisHost, CatalogResult, Dropper, Roots};
use semo::ide::FilePosition;
use semo::sema::CheckedMission;
use semo::text::LineIndex;
use semo::workspace::{FileKind, GraphRun};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use tower_lsp_server::ls_types::{Position, TextDocumentContentChangeEvent, Uri};

/// The catalog a file sees (built on first use, outside the world's lock),
/// and the texts of its files.
pub struct CatalogState {
    analysis: host::Analysis,
    /// The file whose view it is; `None` for the workspace root's view.
    file: Option<FileId>,
    built: OnceLock<Arc<CatalogResult>>,
}

impl CatalogState {
    fn built(&self) -> &CatalogResult {
        self.built.get_or_init(|| match self.file {
            Some(file) => self.analysis.catalog(file),
            None => self.analysis.root_catalog(),
        })
    }

    pub fn catalog(&self) -> &Catalog {
        &self.built().catalog
    }

    pub fn text_of(&self, file: FileId) -> Option<&str> {
        self.analysis.file(file).map(|f| &*f.text)
    }
}

/// One version of one file, with the workspace analysis it is part of.
pub struct Snapshot {
    pub uri: Uri,
    pub id: FileId,
    pub kind: FileKind,
    /// The client's version for open documents; `None` for files read from disk.
    pub version: Option<i32>,
    pub text: Arc<str>,
    pub catalog: Arc<CatalogState>,
    pub encoding: Encoding,
    /// The workspace as it was when this snapshot was taken.
    host: host::Analysis,
    analysis: OnceLock<Arc<FileAnalysis>>,
}

/// What is known about a snapshot once analysed.
pub struct FileAnalysis {
    pub lines: LineIndex,
    diagnostics: Vec<Diagnostic>,
    pub mission: Option<Arc<CheckedMission>>,
    pub graph: Option<Arc<GraphRun>>,
}

impl FileAnalysis {
    /// Diagnostics of this file, sorted.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }
}

impl Snapshot {
    /// Analyses the snapshot once; concurrent callers wait for the first.
    pub fn analysis(&self) -> Arc<FileAnalysis> {
        self.analysis
            .get_or_init(|| Arc::new(self.analyse()))
            .clone()
    }

    /// The host answers; the snapshot only gathers what the handlers read.
    fn analyse(&self) -> FileAnalysis {
        let host = &self.host;
        FileAnalysis {
            lines: LineIndex::new(&self.text),
            diagnostics: host.diagnostics(self.id),
            mission: host.mission(self.id),
            graph: host.graph(self.id),
        }
    }

    /// The text of another file this snapshot's analysis refers to.
    pub fn text_of(&self, file: FileId) -> Option<&str> {
        if file == self.id {
            return Some(&self.text);
        }
        self.host.file(file).map(|f| &*f.text)
    }

    /// The workspace analysis this snapshot belongs to.
    pub fn host(&self) -> &host::Analysis {
        &self.host
    }

    /// A protocol position of this snapshot's text as the library's
    /// [`FilePosition`] (what the workspace analysis' queries take).
    pub fn position(&self, lines: &LineMap<'_>, position: Position) -> FilePosition {
        FilePosition {
            file: self.id,
            offset: lines.offset(position),
        }
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
/// the shared [`Dropper`] does it on its thread (backlog bounded), so that it
/// delays neither the next edit's diagnostics nor, under the world's lock,
/// other requests.
pub fn retire(snapshot: Arc<Snapshot>) {
    retire_to(Dropper::shared(), snapshot);
}

fn retire_to(dropper: &Dropper, snapshot: Arc<Snapshot>) {
    if snapshot.analysis.get().is_none() {
        return; // little to free
    }
    dropper.drop_later(snapshot);
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
    roots: Vec<PathBuf>,
    files: HashMap<Uri, FileEntry>,
    /// `FileId(i)` is `uris[i]`; ids are never reused within a session.
    uris: Vec<Uri>,
    ids: HashMap<Uri, FileId>,
    /// Every file's text: which files belong together, and every analysis,
    /// is the host's (the same as `semo check` and `semo build`).
    host: AnalysisHost,
    /// Frees replaced snapshots (the shared one; tests give their own).
    dropper: Dropper,
    /// Open scenario files (`*.scenario.json`): no part of any analysis,
    /// kept for their editor features (`handlers::scenario`).
    scenarios: HashMap<Uri, Document>,
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
        if name == "taskgraph.xml" {
            // A generated robot's task graph (`semo build` names it so),
            // opened: a task graph, though folder scans leave it out.
            return Some(FileKind::TaskGraph);
        }
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

    /// Every file's URI, `FileId(i)`'s at `i` (for answers naming files
    /// computed outside the lock).
    pub fn file_uris(&self) -> Vec<Uri> {
        self.uris.clone()
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

    /// The workspace folders: a file sees the catalog and strategy files up
    /// to the root that holds it (see `semo::host`).
    pub fn set_roots(&mut self, mut roots: Vec<PathBuf>) {
        roots.dedup();
        self.roots = roots.clone();
        self.host.set_roots(Roots {
            roots,
            seen_by_all: Vec::new(),
        });
    }

    pub fn roots(&self) -> &[PathBuf] {
        &self.roots
    }

    /// The catalog of the workspace root (for requests about no file).
    pub fn catalog(&self) -> Arc<CatalogState> {
        Arc::new(CatalogState {
            analysis: self.host.analysis(),
            file: None,
            built: OnceLock::new(),
        })
    }

    /// The workspace analysis now.
    pub fn analysis(&self) -> host::Analysis {
        self.host.analysis()
    }

    /// The text of an open scenario file.
    pub fn scenario_text(&self, uri: &Uri) -> Option<String> {
        self.scenarios.get(uri).map(|d| d.rope.to_string())
    }

    /// The client opened a document.
    pub fn open(&mut self, uri: Uri, language_id: &str, text: &str, version: i32) -> Changed {
        if is_scenario(&uri) {
            self.scenarios.insert(uri, Document::new(text, version));
            return Changed::default();
        }
        let Some(kind) = World::kind_of(&uri, Some(language_id)) else {
            return Changed::default();
        };
        let document = Document::new(text, version);
        let path = file_path(&uri);
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
        if let Some(scenario) = self.scenarios.get_mut(uri) {
            scenario.apply(changes, version, encoding);
            return Changed::default();
        }
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
        if self.scenarios.remove(uri).is_some() {
            return Changed::default();
        }
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
        let path = file_path(uri);
        let kind = World::kind_of(uri, None);
        match (path, kind, text) {
            (Some(path), Some(kind), Some(text)) => {
                self.set_text(uri.clone(), kind, Some(path), None, text.into())
            }
            _ => self.remove(uri),
        }
    }

    /// The workspace folders' files, read at start: all put into the host
    /// first, then every file gets its snapshot once (rather than the files
    /// added early being renewed for each file added after them).
    pub fn index(&mut self, found: Vec<(Uri, Option<String>)>) -> Changed {
        let mut read = Vec::new();
        for (uri, text) in found {
            if self.is_open(&uri) {
                continue;
            }
            let path = file_path(&uri);
            let (Some(path), Some(kind), Some(text)) = (path, World::kind_of(&uri, None), text)
            else {
                continue;
            };
            let id = self.file_id(&uri);
            let text: Arc<str> = text.into();
            self.host
                .set_file(id, Some(path.clone()), kind, text.clone());
            read.push((uri, id, kind, path, text));
        }
        // The snapshots once every file is in: a snapshot holds the host's
        // table of files, and setting a file while one is held copies the
        // whole table (a workspace of N files cost N copies of N entries).
        let mut fresh = Vec::new();
        for (uri, id, kind, path, text) in read {
            let snapshot = Arc::new(self.new_snapshot(&uri, id, kind, None, text));
            let entry = FileEntry {
                kind,
                document: None,
                path: Some(path),
                snapshot,
            };
            fresh.push(uri.clone());
            if let Some(old) = self.files.insert(uri, entry) {
                retire_to(&self.dropper, old.snapshot);
            }
        }
        // What the files known before (open documents among them) see may
        // have changed too; the files just read already see it all.
        let just_read: std::collections::HashSet<&Uri> = fresh.iter().collect();
        let known: Vec<FileId> = (self.files.iter())
            .filter(|(uri, _)| !just_read.contains(uri))
            .map(|(_, f)| f.snapshot.id)
            .collect();
        let mut changed = self.renew(&known);
        changed.files.extend(fresh);
        self.in_check_order(&mut changed.files);
        changed
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
        let Some(&id) = self.ids.get(uri) else {
            return Changed::default();
        };
        let Some(entry) = self.files.remove(uri) else {
            return Changed::default();
        };
        let affected = if entry.kind == FileKind::Mission {
            // Its folder may stop being a project of its own.
            self.all_ids()
        } else {
            self.host.analysis().affected_by(id)
        };
        retire_to(&self.dropper, entry.snapshot);
        self.host.remove_file(id);
        let mut changed = self.renew(&affected);
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
        // What read the old version (a task graph's readers, a catalog's
        // missions) and what reads the new one.
        let added_mission = kind == FileKind::Mission && !self.files.contains_key(&uri);
        let mut affected = self.host.analysis().affected_by(id);
        self.host.set_file(id, path.clone(), kind, text.clone());
        if added_mission {
            // Its folder may become a project of its own (see `semo::host`).
            affected.extend(self.all_ids());
        }
        affected.extend(self.host.analysis().affected_by(id));
        affected.sort();
        affected.dedup();
        let snapshot = Arc::new(self.new_snapshot(&uri, id, kind, version, text));
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
            retire_to(&self.dropper, old.snapshot);
        }
        // Renewed with the others (the snapshot just made is already current).
        if !affected.contains(&id) {
            affected.push(id);
        }
        self.renew(&affected)
    }

    fn new_snapshot(
        &self,
        uri: &Uri,
        id: FileId,
        kind: FileKind,
        version: Option<i32>,
        text: Arc<str>,
    ) -> Snapshot {
        let analysis = self.host.analysis();
        Snapshot {
            uri: uri.clone(),
            id,
            kind,
            version,
            text,
            catalog: Arc::new(CatalogState {
                analysis: analysis.clone(),
                file: Some(id),
                built: OnceLock::new(),
            }),
            encoding: self.encoding,
            host: analysis,
            analysis: OnceLock::new(),
        }
    }

    /// Every file but the task graphs.
    fn all_ids(&self) -> Vec<FileId> {
        self.files
            .values()
            .filter(|f| f.kind != FileKind::TaskGraph)
            .map(|f| f.snapshot.id)
            .collect()
    }

    /// Missions first, then catalogs, task graphs and project files, then
    /// strategies: the order their diagnostics are published in.
    fn in_check_order(&self, uris: &mut [Uri]) {
        uris.sort_by_key(|u| match self.files[u].kind {
            FileKind::Mission => 0,
            FileKind::Catalog | FileKind::TaskGraph | FileKind::Project => 1,
            FileKind::Strategy => 2,
        });
    }

    /// New snapshots (same text, the current workspace) for the files `ids`;
    /// the old ones are retired; listed in a fixed order by kind, missions
    /// first.
    fn renew(&mut self, ids: &[FileId]) -> Changed {
        let mut uris: Vec<Uri> = ids
            .iter()
            .filter_map(|&id| self.uri_of(id).cloned())
            .filter(|u| self.files.contains_key(u))
            .collect();
        self.in_check_order(&mut uris);
        for uri in &uris {
            let old = self.files[uri].snapshot.clone();
            let fresh =
                Arc::new(self.new_snapshot(uri, old.id, old.kind, old.version, old.text.clone()));
            let entry = self.files.get_mut(uri).expect("listed above");
            retire_to(&self.dropper, std::mem::replace(&mut entry.snapshot, fresh));
        }
        Changed { files: uris }
    }
}

/// Every mission, catalog, strategy, task graph and project file under the
/// given roots, with its text (read without holding any lock); and for each
/// root, the project file that applies to it and the folders that file
/// names, wherever they are (`semo::host::project_inputs`, as the CLI loads
/// them).
pub fn read_roots(roots: &[PathBuf]) -> Vec<(Uri, Option<String>)> {
    let mut found = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut add = |path: &Path, found: &mut Vec<(Uri, Option<String>)>| {
        if let Some(uri) = Uri::from_file_path(path)
            && seen.insert(uri.clone())
        {
            found.push((uri, read_text(path)));
        }
    };
    for root in roots {
        let mut folders = vec![root.clone()];
        if let Some(inputs) = semo::host::project_inputs(root) {
            add(&inputs.file, &mut found);
            folders.extend(inputs.folders);
        }
        for folder in folders {
            // A folder that cannot be listed has nothing to index.
            let Ok(files) = semo::workspace::collect(std::slice::from_ref(&folder)) else {
                continue;
            };
            for (path, _) in files {
                add(&path, &mut found);
            }
        }
    }
    found
}

/// Whether a URI names a scenario file (by its name, whatever the scheme).
fn is_scenario(uri: &Uri) -> bool {
    semo::sim::complete::is_scenario(Path::new(uri.path().as_str()))
}

/// Where a `file:` URI's file is; `None` for other schemes (an unsaved
/// buffer's `untitled:Untitled-1` is no file: the protocol crate's
/// `to_file_path` would make it the relative path `Untitled-1`).
pub fn file_path(uri: &Uri) -> Option<PathBuf> {
    let is_file = uri.scheme().as_str().eq_ignore_ascii_case("file");
    is_file
        .then(|| uri.to_file_path())
        .flatten()
        .map(|p| p.into_owned())
        .filter(|p| p.is_absolute())
}

/// A file's text, with invalid UTF-8 replaced (so the rest is still checked).
pub fn read_text(path: &Path) -> Option<String> {
    semo::workspace::read_text(path).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
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
        let cache = |s: &Snapshot| s.host().parse_cache(s.id);
        assert_eq!(cache(&first).map(|c| c.reparsed()), Some(4));
        // `move("1,1")` becomes `move("1,12")`: one chunk changes.
        let typed = TextDocumentContentChangeEvent {
            range: Some(Range::new(Position::new(1, 17), Position::new(1, 17))),
            range_length: None,
            text: "2".to_string(),
        };
        world.change(&uri, 2, vec![typed]);
        let second = world.snapshot(&uri).expect("open");
        let analysis = second.analysis();
        let left = cache(&second).expect("left by the analysis");
        assert_eq!((left.chunks(), left.reparsed()), (4, 1));
        let scratch = semo::check_source(second.id, &second.text, second.catalog.catalog());
        assert_eq!(analysis.diagnostics(), &scratch.diagnostics[..]);
        assert_eq!(
            analysis.mission.as_ref().map(|m| &m.syntax),
            Some(&scratch.syntax)
        );
        // Snapshots of the same text on a new catalog reuse every chunk.
        let catalog = Uri::from_file_path("/t/more.robot.xml").expect("a file URI");
        let changed = world.open(catalog, "xml", "<robots/>", 1);
        assert!(changed.files.contains(&uri), "{changed:?}");
        let third = world.snapshot(&uri).expect("open");
        assert!(!Arc::ptr_eq(&second, &third));
        third.analysis();
        assert_eq!(cache(&third).map(|c| c.reparsed()), Some(0));
    }

    /// Holds the thread that frees it until `release` says so, after telling
    /// `started` that it is being freed.
    struct Blocker {
        started: mpsc::Sender<()>,
        release: mpsc::Receiver<()>,
    }

    impl Drop for Blocker {
        fn drop(&mut self) {
            let _ = self.started.send(());
            let _ = self.release.recv();
        }
    }

    /// Tells when it is freed.
    struct Probe(mpsc::Sender<()>);

    impl Drop for Probe {
        fn drop(&mut self) {
            let _ = self.0.send(());
        }
    }

    #[test]
    fn replaced_snapshots_are_freed_by_the_droppers_thread() {
        let dropper = Dropper::start("test-world-drop", 8);
        let mut world = World {
            dropper: dropper.clone(),
            ..World::default()
        };
        let uri = Uri::from_file_path("/t/b.mission").expect("a file URI");
        world.open(uri.clone(), "mission", MISSION, 1);
        let first = world.snapshot(&uri).expect("open");
        first.analysis();
        let weak = Arc::downgrade(&first);
        drop(first);
        // The dropper's thread is held: whatever it is given waits.
        let (started, is_started) = mpsc::channel();
        let (release, released) = mpsc::channel();
        dropper.drop_later(Blocker {
            started,
            release: released,
        });
        is_started.recv().expect("the blocker reaches the thread");
        world.change(&uri, 2, Vec::new());
        assert!(
            weak.upgrade().is_some(),
            "the replaced snapshot was freed by the editing thread"
        );
        // Let the thread go; once it has freed a probe given after the
        // snapshot, it has freed the snapshot (it frees in order).
        release.send(()).expect("the blocker waits");
        let (tell, told) = mpsc::channel();
        dropper.drop_later(Probe(tell));
        told.recv().expect("the probe is freed");
        assert!(
            weak.upgrade().is_none(),
            "the replaced snapshot is still alive"
        );
    }
}
