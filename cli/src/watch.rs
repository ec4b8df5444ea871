//! `semo check --watch`: check, then check again whenever a SeMo file under
//! the checked paths changes. File events come from the platform's watcher
//! (inotify, FSEvents, …) through `notify`, debounced so that an editor's
//! save (often a write, a rename and a metadata change) gives one re-check.

use notify_debouncer_mini::notify::RecursiveMode;
use notify_debouncer_mini::{DebounceEventResult, new_debouncer};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// How long the events of one save are gathered before checking again.
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

/// Whether a changed path can change the report: a file of a SeMo kind
/// (by name: the generated `out/…/taskgraph.xml` is not one), or a path
/// the user named.
fn matters(changed: &Path, named: &[PathBuf]) -> bool {
    semo::workspace::FileKind::of(changed).is_some()
        || named.iter().any(|n| {
            std::fs::canonicalize(n).is_ok_and(|n| std::fs::canonicalize(changed).ok() == Some(n))
        })
}

/// Runs `check` now and after every change that matters, until the
/// process is stopped; gives 2 when the paths cannot be watched.
pub fn run(paths: &[PathBuf], mut check: impl FnMut() -> i32) -> i32 {
    if paths.iter().any(|p| p.as_os_str() == "-") {
        eprintln!("error: --watch watches files and folders: standard input (`-`) cannot change");
        return 2;
    }
    let (events, changes) = mpsc::channel::<DebounceEventResult>();
    let mut debouncer = match new_debouncer(DEBOUNCE, events) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: cannot watch files: {e}");
            return 2;
        }
    };
    for folder in watched(paths) {
        if let Err(e) = debouncer.watcher().watch(&folder, RecursiveMode::Recursive) {
            eprintln!("error: cannot watch {}: {e}", folder.display());
            return 2;
        }
    }
    check();
    eprintln!("watching for changes (stop with Ctrl-C)");
    for batch in changes {
        match batch {
            Ok(events) if events.iter().any(|e| matters(&e.path, paths)) => {
                check();
                eprintln!("watching for changes (stop with Ctrl-C)");
            }
            Ok(_) => {}
            Err(e) => {
                eprintln!("error: watching files: {e}");
                return 2;
            }
        }
    }
    0
}
