//! A link-swapping attacker for the stress runs of generation, shared by
//! `tests/generation/stress.rs` (the CLI) and
//! `server/tests/lsp_generate_safety/stress.rs` (the editor), which
//! includes this file by path.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;

/// Swaps `real` for a link to `target` and back, in a loop as tight as the
/// scheduler allows, until `stop`; returns how many times it put the link.
/// Whatever the build made meanwhile where the folder was is put aside
/// (under `<real>.made-<n>`): inside the output folder, not counted.
pub fn swapper(real: PathBuf, target: PathBuf, stop: Arc<AtomicBool>) -> JoinHandle<usize> {
    std::thread::spawn(move || {
        let moved = real.with_extension("swapped-away");
        let mut swaps = 0;
        while !stop.load(Ordering::SeqCst) {
            if std::fs::rename(&real, &moved).is_err() {
                std::thread::yield_now();
                continue;
            }
            if std::os::unix::fs::symlink(&target, &real).is_ok() {
                swaps += 1;
                std::thread::yield_now();
                let _ = std::fs::remove_file(&real);
            }
            restore(&real, &moved);
            std::thread::yield_now();
        }
        swaps
    })
}

/// Removes what the swapper set aside beside `real` (the `<real>.made-<n>`
/// folders), so that the next run starts from a clean output folder.
pub fn clear_set_aside(real: &Path) {
    let folder = real.parent().expect("a swapped folder has a parent");
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        if path
            .extension()
            .is_some_and(|e| e.to_string_lossy().starts_with("made-"))
        {
            std::fs::remove_dir_all(&path).unwrap();
        }
    }
}

/// `moved` back at `real` (anything the build made there meanwhile is set
/// aside beside it).
fn restore(real: &Path, moved: &Path) {
    // The build may make the folder again between any two of these steps
    // (it found none): whatever is at `real` is set aside until the
    // rename back wins.
    static ASIDE: AtomicUsize = AtomicUsize::new(0);
    for _ in 0..10_000 {
        if let Ok(meta) = std::fs::symlink_metadata(real) {
            if meta.is_symlink() {
                let _ = std::fs::remove_file(real);
            } else {
                let n = ASIDE.fetch_add(1, Ordering::SeqCst);
                let _ = std::fs::rename(real, real.with_extension(format!("made-{n}")));
            }
        }
        if std::fs::rename(moved, real).is_ok() {
            return;
        }
    }
    panic!(
        "{} could not be put back at {}",
        moved.display(),
        real.display()
    );
}
