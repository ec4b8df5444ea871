//! Every change generation makes to the disk, in one place, so that each is
//! one counted step.
//!
//! Two hidden environment variables exist for the tests that kill a
//! generation half-way (`tests/generation.rs`); users never set them:
//!
//! - `SEMO_FAULT_AFTER_FS_OPS=N` aborts the process (`SIGABRT`, no clean-up
//!   of any kind) right after its Nth file operation, as a crash or `kill -9`
//!   would at that point.
//! - `SEMO_NO_RENAME_EXCHANGE=1` behaves as on a filesystem that refuses
//!   `renameat2(RENAME_EXCHANGE)`, so the two-rename fallback is tested too.
//!
//! Nothing here follows a symbolic link: files are created with `O_EXCL`
//! (which refuses an existing link), links and renames act on the names.
//!
//! Durability: a file written here is on disk (`fsync`) before its step
//! counts; a change of names (create, link, rename, exchange, remove) is on
//! disk once its folder is synced ([`sync_dir`], [`sync_tree`]), which the
//! transaction does before every step that relies on it. Syncs are counted
//! steps too, so the fault injection kills between them as well.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

static DONE: AtomicU64 = AtomicU64::new(0);

fn fault_after() -> Option<u64> {
    static LIMIT: OnceLock<Option<u64>> = OnceLock::new();
    *LIMIT.get_or_init(|| {
        std::env::var("SEMO_FAULT_AFTER_FS_OPS")
            .ok()
            .and_then(|v| v.parse().ok())
    })
}

/// Counts one completed operation; the injected crash happens here.
fn step<T>(result: io::Result<T>) -> io::Result<T> {
    if result.is_ok() {
        let done = DONE.fetch_add(1, Ordering::SeqCst) + 1;
        if fault_after() == Some(done) {
            std::process::abort();
        }
    }
    result
}

pub fn create_dir(path: &Path) -> io::Result<()> {
    step(std::fs::create_dir(path))
}

/// Creates `path` (which must not exist, not even as a symbolic link) with
/// `bytes`.
pub fn write_new(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(rustix::fs::OFlags::NOFOLLOW.bits() as i32)
        .open(path)?;
    file.write_all(bytes)?;
    step(file.sync_all())
}

/// A second name for the entry `from` (a file, a FIFO, a symbolic link
/// itself: Linux's `link` does not follow links), without opening it.
pub fn hard_link(from: &Path, to: &Path) -> io::Result<()> {
    step(std::fs::hard_link(from, to))
}

/// Copies a regular file's bytes, for filesystems without hard links.
pub fn copy_regular(from: &Path, to: &Path) -> io::Result<()> {
    let source = OpenOptions::new()
        .read(true)
        .custom_flags((rustix::fs::OFlags::NOFOLLOW | rustix::fs::OFlags::NONBLOCK).bits() as i32)
        .open(from)?;
    if !source.metadata()?.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not a regular file", from.display()),
        ));
    }
    let mut target = OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(rustix::fs::OFlags::NOFOLLOW.bits() as i32)
        .open(to)?;
    io::copy(&mut &source, &mut target)?;
    step(target.sync_all())
}

/// Makes the names in the folder `path` durable (its entries created,
/// linked, renamed or removed so far): `fsync` on the folder itself.
pub fn sync_dir(path: &Path) -> io::Result<()> {
    step(open_dir(path)?.sync_all())
}

/// [`sync_dir`] on `path` and every folder inside it (links not followed),
/// as one step: a new robot folder made durable before it is swapped in.
pub fn sync_tree(path: &Path) -> io::Result<()> {
    for entry in walkdir::WalkDir::new(path).contents_first(true) {
        let entry = entry.map_err(io::Error::other)?;
        if entry.file_type().is_dir() {
            open_dir(entry.path())?.sync_all()?;
        }
    }
    step(Ok(()))
}

fn open_dir(path: &Path) -> io::Result<File> {
    OpenOptions::new()
        .read(true)
        .custom_flags((rustix::fs::OFlags::DIRECTORY | rustix::fs::OFlags::NOFOLLOW).bits() as i32)
        .open(path)
}

/// Recreates the symbolic link `from` at `to` (its target is not touched).
pub fn copy_symlink(from: &Path, to: &Path) -> io::Result<()> {
    let target = std::fs::read_link(from)?;
    step(std::os::unix::fs::symlink(target, to))
}

pub fn rename(from: &Path, to: &Path) -> io::Result<()> {
    step(std::fs::rename(from, to))
}

/// Swaps two existing folders in one step. `Ok(false)`: the filesystem (or
/// kernel) cannot, and nothing happened.
pub fn exchange(a: &Path, b: &Path) -> io::Result<bool> {
    if std::env::var_os("SEMO_NO_RENAME_EXCHANGE").is_some() {
        return Ok(false);
    }
    let cwd = rustix::fs::CWD;
    match rustix::fs::renameat_with(cwd, a, cwd, b, rustix::fs::RenameFlags::EXCHANGE) {
        Ok(()) => step(Ok(true)),
        Err(e)
            if e == rustix::io::Errno::INVAL
                || e == rustix::io::Errno::NOSYS
                || e == rustix::io::Errno::OPNOTSUPP =>
        {
            Ok(false)
        }
        Err(e) => Err(e.into()),
    }
}

/// Removes a folder and everything in it, entry by entry (each a step), never
/// following a symbolic link out of it.
pub fn remove_tree(path: &Path) -> io::Result<()> {
    for entry in walkdir::WalkDir::new(path).contents_first(true) {
        let entry = entry.map_err(io::Error::other)?;
        if entry.file_type().is_dir() {
            step(std::fs::remove_dir(entry.path()))?;
        } else {
            step(std::fs::remove_file(entry.path()))?;
        }
    }
    Ok(())
}

/// The lock file of an output folder, opened without following a link.
pub fn open_lock(path: &Path) -> io::Result<File> {
    OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .custom_flags(rustix::fs::OFlags::NOFOLLOW.bits() as i32)
        .open(path)
}

/// Takes an exclusive `flock` on `file` if no one holds it: `Ok(false)` if
/// another open file (of this or another process) does. Released when the
/// file is closed, also when the process dies.
pub fn try_lock(file: &File) -> io::Result<bool> {
    use rustix::fs::{FlockOperation, flock};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(e) if e == rustix::io::Errno::WOULDBLOCK => Ok(false),
        Err(e) => Err(e.into()),
    }
}
