//! `semo check --watch`: check, then check again whenever a SeMo file under
//! the checked paths changes. File events come from the platform's watcher
//! (inotify, FSEvents, …) through `notify`; only changes count (a file
//! written, created, removed or renamed), never a file being opened or read,
//! or the check's own reading would start the next check. The changes of one
//! save (often a write, a rename and a metadata change) are gathered into
//! one re-check.

use notify::event::ModifyKind;
use notify::{Event, EventKind, RecommendedWatcher, RecursiveMode, Watcher};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::Duration;

/// How long after a change further changes are gathered into the same
/// re-check (the rest of an editor's save).
const DEBOUNCE: Duration = Duration::from_millis(200);

/// The folders whose changes matter: a folder given, or a named file's
/// folder (its catalog and strategy files are there and below, and the
/// check reads them too).
fn watched(paths: &[PathBuf]) -> Vec<PathBuf> {
    let paths = if paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        paths.to_vec()
    };
    let mut folders: Vec<PathBuf> = paths
        .iter()
        .map(|p| {
            if p.is_dir() {
                p.clone()
            } else {
                p.parent()
                    .filter(|f| !f.as_os_str().is_empty())
                    .unwrap_or(Path::new("."))
                    .to_path_buf()
            }
        })
        .collect();
    folders.sort();
    folders.dedup();
    folders
}

/// Whether an event says something changed: a file written, created,
/// removed or renamed, or the watcher lost events and the folder must be
/// looked at again. Opening, reading and closing a file change nothing, nor
/// do metadata changes (the check's reads may touch access times).
fn is_change(event: &Event) -> bool {
    event.need_rescan()
        || match event.kind {
            EventKind::Create(_) | EventKind::Remove(_) => true,
            EventKind::Modify(kind) => !matches!(kind, ModifyKind::Metadata(_)),
            EventKind::Access(_) | EventKind::Any | EventKind::Other => false,
        }
}

/// Whether a changed path can change the report: a file of a SeMo kind
/// (by name: the generated `out/…/taskgraph.xml` is not one), or a path
/// the user named.
fn matters(changed: &Path, named: &[PathBuf]) -> bool {
    semo::workspace::FileKind::of(changed).is_some()
        || named.iter().any(|n| {
            std::fs::canonicalize(n).is_ok_and(|n| std::fs::canonicalize(changed).ok() == Some(n))
        })
}

/// What the watcher said since the last look.
enum Watched {
    /// Something that matters changed.
    Changed,
    /// The watcher stopped (it can only stop with the process).
    Stopped,
    /// The watcher failed.
    Failed(notify::Error),
}

/// Waits for a change that matters, then gathers the changes that follow
/// it within `DEBOUNCE` of each other.
fn next_change(events: &Receiver<notify::Result<Event>>, named: &[PathBuf]) -> Watched {
    let matters_now = |event: notify::Result<Event>| match event {
        Ok(event) => Ok(is_change(&event) && event.paths.iter().any(|p| matters(p, named))),
        Err(e) => Err(Watched::Failed(e)),
    };
    loop {
        let Ok(event) = events.recv() else {
            return Watched::Stopped;
        };
        match matters_now(event) {
            Ok(true) => break,
            Ok(false) => {}
            Err(failed) => return failed,
        }
    }
    loop {
        match events.recv_timeout(DEBOUNCE) {
            Ok(event) => {
                if let Err(failed) = matters_now(event) {
                    return failed;
                }
            }
            Err(RecvTimeoutError::Timeout) => return Watched::Changed,
            Err(RecvTimeoutError::Disconnected) => return Watched::Stopped,
        }
    }
}

/// Runs `check` now and after every change that matters, until the
/// process is stopped; gives 2 when the paths cannot be watched.
pub fn run(paths: &[PathBuf], mut check: impl FnMut() -> i32) -> i32 {
    if paths.iter().any(|p| p.as_os_str() == "-") {
        eprintln!("error: --watch watches files and folders: standard input (`-`) cannot change");
        return 2;
    }
    let (sender, events) = mpsc::channel::<notify::Result<Event>>();
    let mut watcher = match RecommendedWatcher::new(sender, notify::Config::default()) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: cannot watch files: {e}");
            return 2;
        }
    };
    for folder in watched(paths) {
        if let Err(e) = watcher.watch(&folder, RecursiveMode::Recursive) {
            eprintln!("error: cannot watch {}: {e}", folder.display());
            return 2;
        }
    }
    loop {
        check();
        eprintln!("watching for changes (stop with Ctrl-C)");
        match next_change(&events, paths) {
            Watched::Changed => {}
            Watched::Stopped => return 0,
            Watched::Failed(e) => {
                eprintln!("error: watching files: {e}");
                return 2;
            }
        }
    }
}
