//! Every change generation makes to the disk, in one place, so that each is
//! one counted step; also the checks a change relies on (is this file still
//! what generation saw?), so that a test can stop or pause between a check
//! and the change.
//!
//! Everything is relative to an open folder (`openat` and friends) and one
//! name at a time: no path is resolved twice, and no symbolic link is
//! followed (`O_NOFOLLOW` on every open, `renameat`, `linkat`, `unlinkat`
//! act on names). Files are created with `O_EXCL` (which refuses an existing
//! link) and put in place with `renameat2(RENAME_NOREPLACE)`, so that an
//! entry someone else made meanwhile is never replaced.
//!
//! Durability is not per file: files are written without `fsync`, and
//! [`sync`] (`syncfs` on the output folder's file system) makes everything
//! durable at once, at the two points the transaction needs it.
//!
//! Hidden environment variables for the tests (`tests/generation.rs`,
//! `server/tests/lsp_generate_cancel.rs`); users never set them. Steps are
//! counted from the start of each transaction ([`restart_count`]).
//!
//! - `SEMO_FAULT_AFTER_FS_OPS=N` aborts the process (`SIGABRT`, no clean-up
//!   of any kind) right after its Nth step, as a crash or `kill -9` would.
//! - `SEMO_FAULT_AFTER_RECOVERY=1` aborts when a generation proper begins,
//!   after recovering what an interrupted one left (and after the caller
//!   reported it).
//! - `SEMO_PAUSE_AFTER_FS_OPS=N[,M...]` with `SEMO_PAUSE_SOCKET=PATH` pauses
//!   after those steps: the process connects to the Unix socket the test
//!   listens on at PATH, writes `paused N KIND` and reads until the test
//!   closes the connection, so the test does something at that exact point
//!   and lets it go on. One connection per pause: two pauses (of two
//!   generations of a server) never read each other's answer, as they could
//!   through one FIFO.
//! - `SEMO_FS_OPS_LOG=PATH` appends `N KIND` per step to PATH.
//! - `SEMO_NO_RENAME_NOREPLACE=1` behaves as on a file system that refuses
//!   `renameat2(RENAME_NOREPLACE)`, so the `link` + `unlink` fallback is
//!   tested too.

use rustix::fs::{AtFlags, Mode, OFlags, RenameFlags};
use rustix::io::Errno;
use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::fd::{BorrowedFd, OwnedFd};
use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

static DONE: AtomicU64 = AtomicU64::new(0);

/// What a step did, as the log names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    MakeDir,
    Write,
    Rename,
    Link,
    Remove,
    /// Made durable: `syncfs` (or, for an earlier version's leftovers, `fsync`).
    Sync,
    /// Compared an entry with what generation saw before changing it.
    Check,
}

impl Op {
    fn name(self) -> &'static str {
        match self {
            Op::MakeDir => "mkdir",
            Op::Write => "write",
            Op::Rename => "rename",
            Op::Link => "link",
            Op::Remove => "remove",
            Op::Sync => "sync",
            Op::Check => "check",
        }
    }
}

fn env_number(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

fn fault_after() -> Option<u64> {
    static LIMIT: OnceLock<Option<u64>> = OnceLock::new();
    *LIMIT.get_or_init(|| env_number("SEMO_FAULT_AFTER_FS_OPS"))
}

fn pauses() -> &'static [u64] {
    static AT: OnceLock<Vec<u64>> = OnceLock::new();
    AT.get_or_init(|| {
        let Ok(list) = std::env::var("SEMO_PAUSE_AFTER_FS_OPS") else {
            return Vec::new();
        };
        list.split(',')
            .filter_map(|n| n.trim().parse().ok())
            .collect()
    })
}

/// Steps are counted per transaction (from its first step, the output
/// folder's creation): the fault injection and the pauses name the Nth step
/// of a generation, also in a server that runs many.
pub fn restart_count() {
    DONE.store(0, Ordering::SeqCst);
}

/// `SEMO_FAULT_AFTER_RECOVERY`: see the module's documentation.
pub fn generation_begins() {
    if std::env::var_os("SEMO_FAULT_AFTER_RECOVERY").is_some() {
        std::process::abort();
    }
}

/// Counts one completed operation; the injected crash, the log and the
/// pauses happen here.
fn step<T>(op: Op, result: io::Result<T>) -> io::Result<T> {
    if result.is_ok() {
        let done = DONE.fetch_add(1, Ordering::SeqCst) + 1;
        if let Some(log) = std::env::var_os("SEMO_FS_OPS_LOG") {
            let line = format!("{done} {}\n", op.name());
            let _ = OpenOptions::new()
                .create(true)
                .append(true)
                .open(log)
                .and_then(|mut f| f.write_all(line.as_bytes()));
        }
        if fault_after() == Some(done) {
            std::process::abort();
        }
        if pauses().contains(&done) {
            pause(done, op);
        }
    }
    result
}

/// The pause handshake through `SEMO_PAUSE_SOCKET` (see the module's doc).
fn pause(done: u64, op: Op) {
    let Some(socket) = std::env::var_os("SEMO_PAUSE_SOCKET") else {
        return;
    };
    if let Ok(mut test) = std::os::unix::net::UnixStream::connect(&socket) {
        let _ = writeln!(test, "paused {done} {}", op.name());
        let _ = io::copy(&mut test, &mut io::sink());
    }
}

/// Counts a check (a read that a change relies on) as a step.
pub fn checked<T>(result: io::Result<T>) -> io::Result<T> {
    step(Op::Check, result)
}

fn dir_flags() -> OFlags {
    OFlags::RDONLY | OFlags::DIRECTORY | OFlags::NOFOLLOW | OFlags::CLOEXEC
}

/// Opens the folder `name` (one component) inside `dir`, never following a
/// link: a link or a file there is `ELOOP`/`ENOTDIR`.
pub fn open_dir(dir: BorrowedFd<'_>, name: &Path) -> io::Result<OwnedFd> {
    Ok(rustix::fs::openat(dir, name, dir_flags(), Mode::empty())?)
}

/// Opens a folder by its path as given, following links on the way: the
/// output folder the user named on the command line.
pub fn open_dir_path(path: &Path) -> io::Result<OwnedFd> {
    let flags = OFlags::RDONLY | OFlags::DIRECTORY | OFlags::CLOEXEC;
    Ok(rustix::fs::open(path, flags, Mode::empty())?)
}

/// Creates the folder `name` inside `dir`.
pub fn make_dir(dir: BorrowedFd<'_>, name: &Path) -> io::Result<()> {
    step(
        Op::MakeDir,
        rustix::fs::mkdirat(dir, name, Mode::from_raw_mode(0o777)).map_err(Into::into),
    )
}

/// Creates `name` in `dir` (which must not exist, not even as a symbolic
/// link) with `bytes`. Not synced: [`sync`] makes it durable later.
pub fn write_new(dir: BorrowedFd<'_>, name: &Path, bytes: &[u8]) -> io::Result<()> {
    let flags = OFlags::WRONLY | OFlags::CREATE | OFlags::EXCL | OFlags::NOFOLLOW | OFlags::CLOEXEC;
    let written = rustix::fs::openat(dir, name, flags, Mode::from_raw_mode(0o666))
        .map_err(io::Error::from)
        .and_then(|fd| File::from(fd).write_all(bytes));
    step(Op::Write, written)
}

/// What is at a name, the link itself if it is one.
pub fn stat(dir: BorrowedFd<'_>, name: &Path) -> io::Result<Option<rustix::fs::Stat>> {
    match rustix::fs::statat(dir, name, AtFlags::SYMLINK_NOFOLLOW) {
        Ok(stat) => Ok(Some(stat)),
        Err(Errno::NOENT) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// A regular file's bytes, up to `limit`: `Ok(None)` when it is missing,
/// not a regular file (never opened then: a FIFO would block) or larger.
pub fn read_regular(dir: BorrowedFd<'_>, name: &Path, limit: u64) -> io::Result<Option<Vec<u8>>> {
    let flags = OFlags::RDONLY | OFlags::NOFOLLOW | OFlags::NONBLOCK | OFlags::CLOEXEC;
    let fd = match rustix::fs::openat(dir, name, flags, Mode::empty()) {
        Ok(fd) => fd,
        Err(Errno::NOENT | Errno::LOOP | Errno::NXIO | Errno::ISDIR) => return Ok(None),
        Err(e) => return Err(e.into()),
    };
    let file = File::from(fd);
    let meta = file.metadata()?;
    if !meta.is_file() || meta.len() > limit {
        return Ok(None);
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    Ok((bytes.len() as u64 <= limit).then_some(bytes))
}

fn no_replace_refused() -> bool {
    static REFUSED: OnceLock<bool> = OnceLock::new();
    *REFUSED.get_or_init(|| std::env::var_os("SEMO_NO_RENAME_NOREPLACE").is_some())
}

/// Moves `from` (in `from_dir`) to `to` (in `to_dir`) unless something is
/// there: `Ok(false)`, and nothing moved. Where the file system refuses
/// `RENAME_NOREPLACE`, a hard link then an unlink (the link fails if the
/// name is taken); where it has no hard links either, a check then a plain
/// rename (the one case with a window, see `output`'s documentation).
pub fn rename_no_replace(
    from_dir: BorrowedFd<'_>,
    from: &Path,
    to_dir: BorrowedFd<'_>,
    to: &Path,
) -> io::Result<bool> {
    if !no_replace_refused() {
        match rustix::fs::renameat_with(from_dir, from, to_dir, to, RenameFlags::NOREPLACE) {
            Ok(()) => return step(Op::Rename, Ok(true)),
            Err(Errno::EXIST) => return Ok(false),
            Err(Errno::INVAL | Errno::NOSYS | Errno::OPNOTSUPP) => {}
            Err(e) => return Err(e.into()),
        }
    }
    match rustix::fs::linkat(from_dir, from, to_dir, to, AtFlags::empty()) {
        Ok(()) => {
            step(Op::Link, Ok(()))?;
            remove_file(from_dir, from)?;
            Ok(true)
        }
        Err(Errno::EXIST) => Ok(false),
        Err(Errno::PERM | Errno::OPNOTSUPP | Errno::XDEV | Errno::MLINK) => {
            if stat(to_dir, to)?.is_some() {
                return Ok(false);
            }
            let renamed = rustix::fs::renameat(from_dir, from, to_dir, to);
            step(Op::Rename, renamed.map(|()| true).map_err(Into::into))
        }
        Err(e) => Err(e.into()),
    }
}

/// Removes the name `name` (a file, a link, a FIFO: never what a link
/// points to).
pub fn remove_file(dir: BorrowedFd<'_>, name: &Path) -> io::Result<()> {
    step(
        Op::Remove,
        rustix::fs::unlinkat(dir, name, AtFlags::empty()).map_err(Into::into),
    )
}

/// Removes the empty folder `name`.
pub fn remove_dir(dir: BorrowedFd<'_>, name: &Path) -> io::Result<()> {
    step(
        Op::Remove,
        rustix::fs::unlinkat(dir, name, AtFlags::REMOVEDIR).map_err(Into::into),
    )
}

/// Everything written, renamed or removed so far on the file system of
/// `dir` made durable, in one `syncfs`.
pub fn sync(dir: BorrowedFd<'_>) -> io::Result<()> {
    step(Op::Sync, rustix::fs::syncfs(dir).map_err(Into::into))
}

/// The names in the folder `dir` (without `.` and `..`).
pub fn names(dir: BorrowedFd<'_>) -> io::Result<Vec<std::ffi::OsString>> {
    use std::os::unix::ffi::OsStringExt;
    let mut names = Vec::new();
    for entry in rustix::fs::Dir::read_from(dir)? {
        let name = entry?.file_name().to_bytes().to_vec();
        if name != b"." && name != b".." {
            names.push(std::ffi::OsString::from_vec(name));
        }
    }
    names.sort();
    Ok(names)
}

/// The lock file of an output folder, opened without following a link.
pub fn open_lock(dir: BorrowedFd<'_>, name: &Path) -> io::Result<File> {
    let flags = OFlags::RDWR | OFlags::CREATE | OFlags::NOFOLLOW | OFlags::CLOEXEC;
    let fd = rustix::fs::openat(dir, name, flags, Mode::from_raw_mode(0o666))?;
    Ok(File::from(fd))
}

/// Takes an exclusive `flock` on `file` if no one holds it: `Ok(false)` if
/// another open file (of this or another process) does. Released when the
/// file is closed, also when the process dies.
pub fn try_lock(file: &File) -> io::Result<bool> {
    use rustix::fs::{FlockOperation, flock};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(Errno::WOULDBLOCK) => Ok(false),
        Err(e) => Err(e.into()),
    }
}

// What earlier versions left (`.<robot>.semo-new`, `.<robot>.semo-old`
// folders): recovered by path, names only, links never followed.

/// Renames by path.
pub fn rename_path(from: &Path, to: &Path) -> io::Result<()> {
    step(Op::Rename, std::fs::rename(from, to))
}

/// Removes a folder and everything in it, entry by entry (each a step), never
/// following a symbolic link out of it.
pub fn remove_tree(path: &Path) -> io::Result<()> {
    for entry in walkdir::WalkDir::new(path).contents_first(true) {
        let entry = entry.map_err(io::Error::other)?;
        if entry.file_type().is_dir() {
            step(Op::Remove, std::fs::remove_dir(entry.path()))?;
        } else {
            step(Op::Remove, std::fs::remove_file(entry.path()))?;
        }
    }
    Ok(())
}
