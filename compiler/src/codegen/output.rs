//! Writing robot folders (codegen.md §5) as a transaction that owns only
//! its own files, and only while it holds the output folder.
//!
//! - **One generation per output folder at a time.** [`Transaction::begin`]
//!   takes an exclusive lock on `<out>/.semo.lock` (an OS file lock, so the
//!   CLI and the server, and two requests of one server, exclude each other);
//!   a second generation waits for it, and gives up with a clear message
//!   after [`LOCK_WAIT`].
//! - **Only its own files.** Each robot folder holds a manifest
//!   ([`manifest::FILE_NAME`]) of the files generation wrote, with their
//!   target and SHA-256. Generation replaces a file only if the manifest says
//!   it wrote it and its bytes are still the ones it wrote (or an earlier
//!   version without a manifest wrote it, outside `tasks/`); it creates a
//!   file only where there is none. A generated file the user edited, a task
//!   file the user filled that the new target generates (`linux` →
//!   `linux-sim`), or anything else in the way is a [`Conflict`]: the
//!   generation is refused before anything is written, naming the files,
//!   unless forced, which moves them under
//!   `<out>/.semo-backup/<UTC time>/<team>/<robot>/` instead of discarding
//!   them. Every other entry of a robot folder is never opened, moved or
//!   removed: files the user creates while a generation runs, and edits
//!   saved by writing a new file and renaming it over the old, stay.
//!   Unchanged generated files are not rewritten.
//! - **Edits racing a generation are kept.** All robots are staged first in
//!   `<out>/.semo-work/` (nothing in the robot folders changes); then each
//!   file is replaced on its own: its bytes checked against what generation
//!   saw, the old file renamed aside, its bytes checked again (an edit
//!   between the check and the rename is caught here), the new file renamed
//!   in with `RENAME_NOREPLACE` (a file the user saved there meanwhile
//!   stays). A file found changed is put back and reported at the end as a
//!   conflict ([`Transaction::commit`]); the set-aside old files are checked
//!   once more before they are removed, and one that a program still holding
//!   it open changed meanwhile is moved under the backup folder and reported.
//!   What is left: a write through a descriptor opened before the generation
//!   set the file aside, landing between that last check and the removal (a
//!   window of one `unlink`); and on a file system with neither
//!   `RENAME_NOREPLACE` nor hard links, a file created between a check of
//!   the name and the rename over it.
//! - **Confined.** Everything is done relative to the output folder's
//!   descriptor, opened once, one name at a time with `O_NOFOLLOW`: a team
//!   or robot folder that is a link is refused, `.semo-backup` that is a link
//!   is refused, a folder turned into a link during the generation stops
//!   what would go through it (a conflict), and links, FIFOs, sockets and
//!   devices in a robot folder are never opened (those in the way of a
//!   generated file are conflicts; the others are reported,
//!   [`Written::left_alone`]). The output folder named on the command line
//!   may itself be (or lie under) a link: it is the folder the link leads
//!   to, resolved once at the start, and swapping the link afterwards does
//!   not move the generation. The server's output folder must lie in the
//!   workspace ([`confine`]) and is opened from the workspace folder down,
//!   one name at a time without following links
//!   ([`Transaction::begin_inside`]).
//! - **Cancellable.** A generation stops before its next robot, or before it
//!   replaces the first file, once its cancel flag is set
//!   ([`Transaction::cancel_with`]); so does one dropped before
//!   [`Transaction::commit`]: the staged files are removed and the robot
//!   folders are as they were.
//! - **A crash leaves old files or new ones, and the next run finishes.**
//!   The journal (`.semo-work/journal`, [`journal`]) names every file the
//!   generation replaces, with the hashes of the old and new bytes, before
//!   the first is replaced. After a crash, [`Transaction::begin`] finishes
//!   a generation whose journal is complete (each file found new is left, each
//!   found old is replaced as above, set-aside files removed) and removes a
//!   staging area without one; it reports what it did
//!   ([`Transaction::recovered`]). After the recovery each robot folder is
//!   the old or the new one (less any conflict it reports); between the two,
//!   each generated file is its old or its new version, or missing for the
//!   instant between the two renames, its old version then in the work
//!   folder.
//! - **Durable, in two syncs.** Files are written without `fsync`. One
//!   `syncfs` on the output folder's file system after staging (and the
//!   journal) makes everything durable before the first rename publishes
//!   anything; one after the renames, before the journal and the set-aside
//!   files go. After a power cut the journal thus either is incomplete (no
//!   rename happened: the staging area is removed) or names files whose new
//!   bytes are on disk (the generation is finished). Two syncs per
//!   generation, whatever the number of robots and files (all through
//!   `fsops`, counted steps).

mod fsops;
mod journal;
pub mod manifest;
mod plan;

use super::{GeneratedFile, RUNTIME_FOLDER, RobotOutput, Target};
use journal::{Aside, Entry, Journal, Old};
use std::collections::HashMap;
use std::fs::File;
use std::io;
use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The lock file in the output folder.
pub const LOCK_FILE: &str = ".semo.lock";
/// Where forced generations save the files they replace.
pub const BACKUP_FOLDER: &str = ".semo-backup";
/// Where a generation stages its files and keeps its journal while it runs.
pub const WORK_FOLDER: &str = ".semo-work";
/// How long a generation waits for another one on the same folder.
pub const LOCK_WAIT: Duration = Duration::from_secs(120);

/// What staging one robot's folder will do once committed.
#[derive(Debug, Default)]
pub struct Written {
    pub folder: PathBuf,
    /// Generated files (written, or already as generation would write them).
    pub generated: usize,
    /// User files created from their template.
    pub created: usize,
    /// User files left as they were.
    pub kept: usize,
    /// Where the files in the way are moved (forced).
    pub backed_up: Vec<PathBuf>,
    /// Entries that are neither regular files, folders nor links (FIFOs,
    /// sockets, devices): never opened.
    pub left_alone: Vec<PathBuf>,
}

/// A folder generation writes: its path under the output folder, one name
/// at a time, its files, and the names of files an earlier version of semo
/// generated there that this one no longer does and removes (unchanged).
pub(crate) struct FolderFiles<'r> {
    pub names: Vec<&'r str>,
    pub files: &'r [GeneratedFile],
    pub retired: fn(&str) -> bool,
    /// What the files are generated for: a robot's target, or the targets
    /// of the robots the runtime folder serves (its manifest and messages
    /// say it).
    pub target: String,
}

/// `<team>/<robot>/`: its files; the runtime's files that earlier versions
/// copied into it are retired, so that no stale copy of a runtime header
/// shadows the shared one.
fn robot_folder(robot: &RobotOutput) -> FolderFiles<'_> {
    FolderFiles {
        names: vec![&robot.team, &robot.robot],
        files: &robot.files,
        retired: super::is_runtime_file,
        target: robot.target.name().to_string(),
    }
}

/// [`RUNTIME_FOLDER`]: the runtime's files, for robots of `targets`.
fn runtime_folder<'r>(files: &'r [GeneratedFile], targets: &[Target]) -> FolderFiles<'r> {
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    FolderFiles {
        names: vec![RUNTIME_FOLDER],
        files,
        retired: |_| false,
        target: names.join(" and "),
    }
}

/// A file generation would replace although the user changed it or owns it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Conflict {
    pub path: PathBuf,
    pub why: String,
}

#[derive(Debug)]
pub enum OutputError {
    /// Another generation holds the output folder's lock.
    Busy(PathBuf),
    /// Files in the way; nothing was written.
    Conflicts(Vec<Conflict>),
    /// A folder generation would write through is a link or not a folder.
    Unsafe(PathBuf, String),
    /// The generation was cancelled before it replaced anything.
    Cancelled,
    Io(PathBuf, io::Error),
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputError::Busy(out) => write!(
                f,
                "another generation is writing to {} (it holds {}); try again when it has finished",
                out.display(),
                out.join(LOCK_FILE).display()
            ),
            OutputError::Conflicts(conflicts) => {
                write!(
                    f,
                    "generation would replace {} file(s) that are not as semo wrote them:",
                    conflicts.len()
                )?;
                for c in conflicts {
                    write!(f, "\n  {}: {}", c.path.display(), c.why)?;
                }
                write!(
                    f,
                    "\nnothing was written; to replace them, generate again with --force \
                     (the editor's `force`): they are first saved under {BACKUP_FOLDER}/ in the output folder"
                )
            }
            OutputError::Unsafe(path, why) => {
                write!(f, "refusing to write through {}: {why}", path.display())
            }
            OutputError::Cancelled => {
                write!(f, "the generation was cancelled; nothing was written")
            }
            OutputError::Io(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for OutputError {}

/// What a commit's conflicts say to the user: the files changed while the
/// generation ran, kept as they are.
pub fn kept_message(kept: &[Conflict]) -> String {
    let mut text = format!(
        "{} file(s) changed while semo was generating; they were kept as they are:",
        kept.len()
    );
    for c in kept {
        text.push_str(&format!("\n  {}: {}", c.path.display(), c.why));
    }
    text.push_str(
        "\nthe rest was generated; generate again to replace them (they are conflicts now, \
         which --force saves under .semo-backup/ first)",
    );
    text
}

fn at(path: &Path) -> impl FnOnce(io::Error) -> OutputError + '_ {
    move |e| OutputError::Io(path.to_path_buf(), e)
}

/// A folder that is a link or not a folder, as the error for `path`;
/// other errors as they are.
fn not_a_folder(path: &Path) -> impl FnOnce(io::Error) -> OutputError + '_ {
    move |e| match why_not_a_folder(path, &e) {
        Some(why) => OutputError::Unsafe(path.to_path_buf(), why.into()),
        None => OutputError::Io(path.to_path_buf(), e),
    }
}

/// Why opening `path` as a folder without following links failed, when it
/// is a link or not a folder (`O_DIRECTORY | O_NOFOLLOW` says `ENOTDIR` or
/// `ELOOP` for a link, so the name is looked at again for the message).
fn why_not_a_folder(path: &Path, e: &io::Error) -> Option<&'static str> {
    use rustix::io::Errno;
    match Errno::from_io_error(e)? {
        Errno::LOOP | Errno::NOTDIR => {
            let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.is_symlink());
            Some(if link { LINK } else { "it is not a folder" })
        }
        _ => None,
    }
}

const LINK: &str = "it is a symbolic link; generation never follows links out of the output folder";

/// One generation into an output folder, holding its lock until dropped.
/// Robots are staged ([`Transaction::stage_robot`]) then all replaced at
/// once ([`Transaction::commit`]); dropped before, it leaves the folder as
/// it was.
pub struct Transaction {
    out: PathBuf,
    dir: OwnedFd,
    _lock: File,
    /// What was repaired after an interrupted generation, one line each.
    pub recovered: Vec<String>,
    stamp: String,
    /// The work folder, once the first file is staged.
    work: Option<OwnedFd>,
    entries: Vec<Entry>,
    cancel: Option<Arc<AtomicBool>>,
    /// The journal is written: from here on the generation is finished, by
    /// this run or the next.
    committed: bool,
    generating: bool,
}

impl Transaction {
    /// Creates the output folder if needed (following links in `out`: the
    /// folder the user named), takes its lock (waiting up to [`LOCK_WAIT`];
    /// `on_wait` is called once if it has to), and recovers what an
    /// interrupted generation left.
    pub fn begin(out: &Path, on_wait: impl FnOnce()) -> Result<Transaction, OutputError> {
        fsops::restart_count();
        std::fs::create_dir_all(out).map_err(at(out))?;
        let dir = fsops::open_dir_path(out).map_err(at(out))?;
        Transaction::locked(out.to_path_buf(), dir, on_wait)
    }

    /// [`Transaction::begin`] on `root/rel`, with `rel`'s folders opened (or
    /// created) one by one from `root` without following a link: a folder of
    /// `rel` turned into a link is refused, whatever it points to.
    pub fn begin_inside(
        root: &Path,
        rel: &Path,
        on_wait: impl FnOnce(),
    ) -> Result<Transaction, OutputError> {
        fsops::restart_count();
        let mut dir = fsops::open_dir_path(root).map_err(at(root))?;
        let mut path = root.to_path_buf();
        for component in rel.components() {
            let Component::Normal(name) = component else {
                return Err(OutputError::Unsafe(
                    root.join(rel),
                    "it is not a plain folder path inside the workspace".into(),
                ));
            };
            path.push(name);
            dir = open_or_make_dir(dir.as_fd(), Path::new(name)).map_err(not_a_folder(&path))?;
        }
        Transaction::locked(path, dir, on_wait)
    }

    fn locked(
        out: PathBuf,
        dir: OwnedFd,
        on_wait: impl FnOnce(),
    ) -> Result<Transaction, OutputError> {
        let lock_path = out.join(LOCK_FILE);
        let lock = fsops::open_lock(dir.as_fd(), Path::new(LOCK_FILE)).map_err(at(&lock_path))?;
        if !fsops::try_lock(&lock).map_err(at(&lock_path))? {
            on_wait();
            let deadline = std::time::Instant::now() + LOCK_WAIT;
            while !fsops::try_lock(&lock).map_err(at(&lock_path))? {
                if std::time::Instant::now() >= deadline {
                    return Err(OutputError::Busy(out));
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        let mut transaction = Transaction {
            out,
            dir,
            _lock: lock,
            recovered: Vec::new(),
            stamp: utc_stamp(),
            work: None,
            entries: Vec::new(),
            cancel: None,
            committed: false,
            generating: false,
        };
        transaction.recover()?;
        Ok(transaction)
    }

    pub fn out(&self) -> &Path {
        &self.out
    }

    /// Once `flag` is set, the generation stops before its next robot or
    /// before it replaces anything, whichever comes first, and leaves the
    /// folder as it was ([`OutputError::Cancelled`]).
    pub fn cancel_with(&mut self, flag: Arc<AtomicBool>) {
        self.cancel = Some(flag);
    }

    fn stop_if_cancelled(&mut self) -> Result<(), OutputError> {
        if self
            .cancel
            .as_ref()
            .is_some_and(|f| f.load(Ordering::SeqCst))
        {
            self.discard()?;
            return Err(OutputError::Cancelled);
        }
        Ok(())
    }

    /// The files that writing `robots` (each for its target) and the
    /// `runtime` they share would replace against the user's will, over all
    /// of them: checked before staging any.
    pub fn conflicts(
        &self,
        robots: &[RobotOutput],
        runtime: &[GeneratedFile],
    ) -> Result<Vec<Conflict>, OutputError> {
        let mut all = Vec::new();
        if !runtime.is_empty() {
            let targets = super::distinct(robots.iter().map(|r| r.target));
            all.extend(self.plan(&runtime_folder(runtime, &targets))?.conflicts);
        }
        for robot in robots {
            all.extend(self.plan(&robot_folder(robot))?.conflicts);
        }
        Ok(all)
    }

    fn plan<'r>(&self, folder: &FolderFiles<'r>) -> Result<plan::Plan<'r>, OutputError> {
        let backup = self.out.join(BACKUP_FOLDER).join(&self.stamp);
        plan::Plan::new(self.dir.as_fd(), &self.out, &backup, folder)
    }

    /// Stages `robot`'s files (for its target) in the work folder; nothing
    /// in the robot folder changes until [`Transaction::commit`]. Refused
    /// with [`OutputError::Conflicts`] unless `force`, which moves the files
    /// in the way under the backup folder instead of discarding them.
    pub fn stage_robot(
        &mut self,
        robot: &RobotOutput,
        force: bool,
    ) -> Result<Written, OutputError> {
        self.stage(&robot_folder(robot), force)
    }

    /// Stages the runtime's folder ([`RUNTIME_FOLDER`]) the robots of the
    /// build compile (their targets: `targets`), as
    /// [`Transaction::stage_robot`] stages a robot's.
    pub fn stage_runtime(
        &mut self,
        runtime: &[GeneratedFile],
        targets: &[Target],
        force: bool,
    ) -> Result<Written, OutputError> {
        self.stage(&runtime_folder(runtime, targets), force)
    }

    fn stage(&mut self, folder: &FolderFiles<'_>, force: bool) -> Result<Written, OutputError> {
        self.stop_if_cancelled()?;
        if !self.generating {
            self.generating = true;
            fsops::generation_begins();
        }
        let plan = self.plan(folder)?;
        if !plan.conflicts.is_empty() {
            if !force {
                return Err(OutputError::Conflicts(plan.conflicts));
            }
            self.check_backup_folder()?;
        }
        let prefix = folder.names.join("/");
        for change in plan.changes {
            let index = self.entries.len();
            let entry = Entry {
                index,
                path: format!("{prefix}/{}", change.rel),
                new: change.bytes.as_deref().map(manifest::sha256),
                old: change.old,
                aside: change.aside,
            };
            if let Some(bytes) = &change.bytes {
                let staged = entry.staged();
                let work = self.work()?;
                fsops::write_new(work, Path::new(&staged), bytes)
                    .map_err(at(&self.out.join(WORK_FOLDER).join(&staged)))?;
            }
            self.entries.push(entry);
        }
        Ok(plan.written)
    }

    /// A forced generation moves files under `.semo-backup`: a link there
    /// would take them out of the output folder.
    fn check_backup_folder(&self) -> Result<(), OutputError> {
        let path = self.out.join(BACKUP_FOLDER);
        match fsops::stat(self.dir.as_fd(), Path::new(BACKUP_FOLDER)).map_err(at(&path))? {
            Some(stat) if !is_dir(&stat) => Err(OutputError::Unsafe(
                path,
                if is_link(&stat) {
                    LINK
                } else {
                    "it is not a folder"
                }
                .into(),
            )),
            _ => Ok(()),
        }
    }

    /// The work folder, made on first use.
    fn work(&mut self) -> Result<BorrowedFd<'_>, OutputError> {
        if self.work.is_none() {
            let path = self.out.join(WORK_FOLDER);
            fsops::make_dir(self.dir.as_fd(), Path::new(WORK_FOLDER)).map_err(at(&path))?;
            let work = fsops::open_dir(self.dir.as_fd(), Path::new(WORK_FOLDER))
                .map_err(not_a_folder(&path))?;
            self.work = Some(work);
        }
        Ok(self.work.as_ref().expect("made above").as_fd())
    }

    /// Replaces the staged files (see the module's documentation). The files
    /// found changed on the way are kept as they are and returned: conflicts
    /// for the user, as are the generated files they stand for from now on.
    pub fn commit(mut self) -> Result<Vec<Conflict>, OutputError> {
        self.stop_if_cancelled()?;
        if self.entries.is_empty() {
            self.discard()?;
            return Ok(Vec::new());
        }
        let journal = Journal {
            stamp: self.stamp.clone(),
            entries: std::mem::take(&mut self.entries),
        };
        let journal_path = self.out.join(WORK_FOLDER).join(journal::FILE_NAME);
        let work = self.work()?;
        fsops::write_new(
            work,
            Path::new(journal::FILE_NAME),
            journal.to_text().as_bytes(),
        )
        .map_err(at(&journal_path))?;
        // The staged files and the journal on disk before anything is replaced.
        fsops::sync(self.dir.as_fd()).map_err(at(&self.out))?;
        self.entries = journal.entries;
        // The last moment a cancel undoes everything.
        self.stop_if_cancelled()?;
        self.committed = true;
        self.finish()
    }

    /// Replaces every entry of the journal, makes that durable, and clears
    /// the work folder away; the conflicts met on the way.
    fn finish(&mut self) -> Result<Vec<Conflict>, OutputError> {
        let mut folders = Folders::default();
        let mut conflicts = Vec::new();
        for entry in &self.entries {
            conflicts.extend(self.replace(entry, &mut folders)?);
        }
        // Replaced on disk before the journal that would finish it goes.
        fsops::sync(self.dir.as_fd()).map_err(at(&self.out))?;
        for entry in &self.entries {
            conflicts.extend(self.clear(entry)?);
        }
        self.remove_work()?;
        self.entries.clear();
        Ok(conflicts)
    }

    /// Removes the work folder and everything in it (files generation made).
    fn discard(&mut self) -> Result<(), OutputError> {
        self.entries.clear();
        if self.work.is_none() {
            return Ok(());
        }
        self.remove_work()
    }

    fn remove_work(&mut self) -> Result<(), OutputError> {
        let path = self.out.join(WORK_FOLDER);
        let Some(work) = self.work.take() else {
            return Ok(());
        };
        // The journal first: a crash while this runs leaves no journal that
        // would finish what is being taken away.
        let mut names = fsops::names(work.as_fd()).map_err(at(&path))?;
        names.sort_by_key(|n| n != journal::FILE_NAME);
        for name in names {
            fsops::remove_file(work.as_fd(), Path::new(&name)).map_err(at(&path.join(&name)))?;
        }
        fsops::remove_dir(self.dir.as_fd(), Path::new(WORK_FOLDER)).map_err(at(&path))
    }

    /// One entry of the journal: the old entry set aside and checked, the
    /// new file put in its place. Resumable: after a crash it goes on from
    /// wherever the entry's names show it stopped.
    fn replace(
        &self,
        entry: &Entry,
        folders: &mut Folders,
    ) -> Result<Option<Conflict>, OutputError> {
        let target = self.out.join(&entry.path);
        let conflict = |why: &str| {
            Ok(Some(Conflict {
                path: target.clone(),
                why: why.to_string(),
            }))
        };
        let (parent_rel, name) = split(&entry.path);
        let parent = match folders.open(self.dir.as_fd(), &self.out, parent_rel, true) {
            Ok(fd) => fd,
            Err(why) => return conflict(&why),
        };
        let work = self
            .work
            .as_ref()
            .expect("a journal has its work folder")
            .as_fd();
        let staged = entry.staged();
        let staged = Path::new(&staged);
        let is_staged =
            entry.new.is_some() && fsops::stat(work, staged).map_err(at(&target))?.is_some();
        if is_staged && same_entry(work, staged, parent.as_fd(), name)? {
            // A `link` + `unlink` move that was interrupted.
            fsops::remove_file(work, staged).map_err(at(&target))?;
            return Ok(None);
        }
        if entry.new.is_some() && !is_staged {
            return Ok(None);
        }
        if entry.old != Old::Absent {
            let aside = self.aside(entry, folders)?;
            let (aside_dir, aside_name) = (aside.0.as_fd(), aside.1.as_path());
            let was_set_aside = fsops::stat(aside_dir, aside_name)
                .map_err(at(&target))?
                .is_some();
            if !was_set_aside {
                match self.matches(parent.as_fd(), name, &entry.old)? {
                    Seen::Other => {
                        return conflict(
                            "changed while semo was generating; left as it is (generate again to replace it)",
                        );
                    }
                    // Removed meanwhile: nothing of the user's to keep.
                    Seen::Gone => {}
                    Seen::Same => {
                        match fsops::rename_no_replace(parent.as_fd(), name, aside_dir, aside_name)
                        {
                            Ok(true) => {}
                            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                            Ok(false) => {
                                let taken =
                                    io::Error::other("the name to set it aside under is taken");
                                return Err(OutputError::Io(target, taken));
                            }
                            Err(e) => return Err(OutputError::Io(target, e)),
                        }
                    }
                }
            }
            let moved = fsops::stat(aside_dir, aside_name)
                .map_err(at(&target))?
                .is_some();
            if moved {
                if same_entry(aside_dir, aside_name, parent.as_fd(), name)? {
                    // A `link` + `unlink` move that was interrupted.
                    fsops::remove_file(parent.as_fd(), name).map_err(at(&target))?;
                }
                if self.matches(aside_dir, aside_name, &entry.old)? != Seen::Same {
                    return self.put_back(entry, (aside_dir, aside_name), (parent.as_fd(), name));
                }
            }
        }
        if entry.new.is_some()
            && !fsops::rename_no_replace(work, staged, parent.as_fd(), name).map_err(at(&target))?
        {
            return conflict(
                "created while semo was generating; left as it is (generate again to replace it)",
            );
        }
        Ok(None)
    }

    /// The old entry, found changed once set aside (an edit between the
    /// check and the rename), back in its place; else (the user saved a new
    /// one there meanwhile) kept under the backup folder.
    fn put_back(
        &self,
        entry: &Entry,
        (aside_dir, aside_name): (BorrowedFd<'_>, &Path),
        (parent, name): (BorrowedFd<'_>, &Path),
    ) -> Result<Option<Conflict>, OutputError> {
        let target = self.out.join(&entry.path);
        if fsops::rename_no_replace(aside_dir, aside_name, parent, name).map_err(at(&target))? {
            return Ok(Some(Conflict {
                path: target,
                why: "changed while semo was replacing it; your version is back in place (generate again to replace it)".into(),
            }));
        }
        let saved = self.rescue(entry, aside_dir, aside_name)?;
        Ok(Some(Conflict {
            path: target,
            why: format!(
                "changed twice while semo was replacing it; the newer version is in place, the other saved as {}",
                saved.display()
            ),
        }))
    }

    /// Moves a set-aside entry from the work folder under the backup folder
    /// (where it stays); its path there.
    fn rescue(
        &self,
        entry: &Entry,
        dir: BorrowedFd<'_>,
        name: &Path,
    ) -> Result<PathBuf, OutputError> {
        let saved = self
            .out
            .join(BACKUP_FOLDER)
            .join(&self.stamp)
            .join(&entry.path);
        if entry.aside == Aside::Backup {
            return Ok(saved);
        }
        let mut folders = Folders::default();
        let backup = self.backup_folder(entry, &mut folders)?;
        let (_, last) = split(&entry.path);
        if !fsops::rename_no_replace(dir, name, backup.as_fd(), last).map_err(at(&saved))? {
            return Err(OutputError::Io(saved, io::Error::other("already exists")));
        }
        Ok(saved)
    }

    /// After the sync: a set-aside old file goes, once checked unchanged
    /// (else it is kept under the backup folder); a staged file a conflict
    /// left goes too.
    fn clear(&self, entry: &Entry) -> Result<Option<Conflict>, OutputError> {
        let work = self
            .work
            .as_ref()
            .expect("a journal has its work folder")
            .as_fd();
        let target = self.out.join(&entry.path);
        if entry.new.is_some() {
            let staged = entry.staged();
            if fsops::stat(work, Path::new(&staged))
                .map_err(at(&target))?
                .is_some()
            {
                fsops::remove_file(work, Path::new(&staged)).map_err(at(&target))?;
            }
        }
        if entry.aside != Aside::Work || entry.old == Old::Absent {
            return Ok(None);
        }
        let aside = entry.set_aside();
        let aside = Path::new(&aside);
        if fsops::stat(work, aside).map_err(at(&target))?.is_none() {
            return Ok(None);
        }
        if self.matches(work, aside, &entry.old)? == Seen::Same {
            fsops::remove_file(work, aside).map_err(at(&target))?;
            return Ok(None);
        }
        let saved = self.rescue(entry, work, aside)?;
        Ok(Some(Conflict {
            path: target,
            why: format!(
                "the old version was changed after semo had replaced it (a program still had it open); saved as {}",
                saved.display()
            ),
        }))
    }

    /// Where `entry`'s old entry is set aside: a folder and a name in it.
    fn aside(
        &self,
        entry: &Entry,
        folders: &mut Folders,
    ) -> Result<(OwnedFd, PathBuf), OutputError> {
        match entry.aside {
            Aside::Work => {
                let work = self.work.as_ref().expect("a journal has its work folder");
                let work = work.try_clone().map_err(at(&self.out.join(WORK_FOLDER)))?;
                Ok((work, PathBuf::from(entry.set_aside())))
            }
            Aside::Backup => {
                let folder = self.backup_folder(entry, folders)?;
                Ok((folder, PathBuf::from(split(&entry.path).1)))
            }
        }
    }

    /// `.semo-backup/<stamp>/<team>/<robot>/...`: the folder `entry`'s old
    /// entry is saved in, made if needed, never through a link.
    fn backup_folder(&self, entry: &Entry, folders: &mut Folders) -> Result<OwnedFd, OutputError> {
        let (parent, _) = split(&entry.path);
        let rel = format!("{BACKUP_FOLDER}/{}/{parent}", self.stamp);
        folders
            .open(self.dir.as_fd(), &self.out, &rel, true)
            .map_err(|why| OutputError::Unsafe(self.out.join(&rel), why))
    }

    /// Whether the entry `name` in `dir` is still `old` (a counted check).
    fn matches(&self, dir: BorrowedFd<'_>, name: &Path, old: &Old) -> Result<Seen, OutputError> {
        let err = |e| OutputError::Io(self.out.join(name), e);
        let seen = match old {
            Old::Absent => match fsops::stat(dir, name).map_err(err)? {
                None => Seen::Same,
                Some(_) => Seen::Other,
            },
            Old::File { sha256 } => match fsops::stat(dir, name).map_err(err)? {
                None => Seen::Gone,
                Some(_) => match fsops::read_regular(dir, name, crate::fsread::MAX_FILE_BYTES)
                    .map_err(|e| OutputError::Io(self.out.join(name), e))?
                {
                    Some(bytes) if manifest::sha256(&bytes) == *sha256 => Seen::Same,
                    _ => Seen::Other,
                },
            },
            Old::Other { dev, ino } => match fsops::stat(dir, name).map_err(err)? {
                None => Seen::Gone,
                Some(st) if st.st_dev == *dev && st.st_ino == *ino => Seen::Same,
                Some(_) => Seen::Other,
            },
        };
        fsops::checked(Ok(seen)).map_err(|e| OutputError::Io(self.out.join(name), e))
    }

    /// Finishes or removes what an interrupted generation left (see the
    /// module's documentation).
    fn recover(&mut self) -> Result<(), OutputError> {
        self.recover_swapped_folders()?;
        let path = self.out.join(WORK_FOLDER);
        if fsops::stat(self.dir.as_fd(), Path::new(WORK_FOLDER))
            .map_err(at(&path))?
            .is_none()
        {
            return Ok(());
        }
        let work = fsops::open_dir(self.dir.as_fd(), Path::new(WORK_FOLDER))
            .map_err(not_a_folder(&path))?;
        let journal = fsops::read_regular(work.as_fd(), Path::new(journal::FILE_NAME), 16 << 20)
            .map_err(at(&path))?
            .and_then(|bytes| Journal::parse(&String::from_utf8_lossy(&bytes)));
        self.work = Some(work);
        let Some(journal) = journal.filter(|j| self.journal_holds(j)) else {
            self.discard()?;
            self.recovered.push(format!(
                "removed the files an interrupted generation had staged in {} (it had not begun replacing files)",
                path.display()
            ));
            return Ok(());
        };
        let stamp = std::mem::replace(&mut self.stamp, journal.stamp);
        self.entries = journal.entries;
        let count = self.entries.len();
        self.committed = true;
        let conflicts = self.finish()?;
        self.committed = false;
        self.stamp = stamp;
        self.recovered.push(format!(
            "finished a generation that was interrupted while replacing {count} file(s) in {}",
            self.out.display()
        ));
        for c in conflicts {
            self.recovered
                .push(format!("kept {}: {}", c.path.display(), c.why));
        }
        Ok(())
    }

    /// Whether a complete journal can be finished: once it has begun (a
    /// staged file gone, an old one set aside), the sync before the first
    /// rename made every staged file whole; before, each must be checked (a
    /// power cut may have kept the journal but not all of them).
    fn journal_holds(&self, journal: &Journal) -> bool {
        let work = self.work.as_ref().expect("set by recover").as_fd();
        let exists = |name: String| fsops::stat(work, Path::new(&name)).ok().flatten().is_some();
        let begun = journal.entries.iter().any(|e| {
            (e.new.is_some() && !exists(e.staged()))
                || (e.aside == Aside::Work && e.old != Old::Absent && exists(e.set_aside()))
        });
        begun
            || journal.entries.iter().all(|e| match &e.new {
                None => true,
                Some(sha) => {
                    fsops::read_regular(work, Path::new(&e.staged()), crate::fsread::MAX_FILE_BYTES)
                        .ok()
                        .flatten()
                        .is_some_and(|bytes| manifest::sha256(&bytes) == *sha)
                }
            })
    }

    /// What versions before the journal left: `.<robot>.semo-new` and
    /// `.<robot>.semo-old` folders beside a robot folder (they swapped whole
    /// folders). An old folder is restored when the robot folder is missing;
    /// the rest goes.
    fn recover_swapped_folders(&mut self) -> Result<(), OutputError> {
        let out = self.out.clone();
        let mut changed = false;
        for team in read_dir_sorted(&out)? {
            let is_team = team.file_type().is_ok_and(|t| t.is_dir())
                && !team.file_name().to_string_lossy().starts_with('.');
            if !is_team {
                continue;
            }
            let team_dir = team.path();
            let leftovers: Vec<(PathBuf, String, bool)> = read_dir_sorted(&team_dir)?
                .iter()
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    let (robot, old) = leftover(&name)?;
                    let is_dir = e.file_type().is_ok_and(|t| t.is_dir());
                    is_dir.then(|| (e.path(), robot.to_string(), old))
                })
                .collect();
            for (path, robot, _) in leftovers.iter().filter(|l| l.2) {
                let folder = team_dir.join(robot);
                if std::fs::symlink_metadata(&folder).is_err() {
                    fsops::rename_path(path, &folder).map_err(at(path))?;
                    self.recovered.push(format!(
                        "restored {} from {} (a generation was interrupted while replacing it)",
                        folder.display(),
                        path.display()
                    ));
                }
            }
            for (path, _, _) in &leftovers {
                if std::fs::symlink_metadata(path).is_ok() {
                    fsops::remove_tree(path).map_err(at(path))?;
                    self.recovered.push(format!(
                        "removed {}, left by an interrupted generation",
                        path.display()
                    ));
                }
            }
            changed |= !leftovers.is_empty();
        }
        if changed {
            fsops::sync(self.dir.as_fd()).map_err(at(&out))?;
        }
        Ok(())
    }
}

impl Drop for Transaction {
    /// An uncommitted generation (cancelled, failed, or its caller gone)
    /// takes its staged files away; a committed one that failed half-way
    /// leaves its journal for the next run to finish.
    fn drop(&mut self) {
        if !self.committed {
            let _ = self.discard();
        }
    }
}

/// What a check found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Seen {
    Same,
    Gone,
    Other,
}

/// Whether two names are one entry (same inode): a `link` + `unlink` move
/// interrupted between the two.
fn same_entry(
    a: BorrowedFd<'_>,
    a_name: &Path,
    b: BorrowedFd<'_>,
    b_name: &Path,
) -> Result<bool, OutputError> {
    let stat = |dir, name: &Path| {
        fsops::stat(dir, name).map_err(|e| OutputError::Io(name.to_path_buf(), e))
    };
    Ok(match (stat(a, a_name)?, stat(b, b_name)?) {
        (Some(x), Some(y)) => x.st_dev == y.st_dev && x.st_ino == y.st_ino,
        _ => false,
    })
}

/// `team/robot/tasks/a.c` → (`team/robot/tasks`, `a.c`).
fn split(path: &str) -> (&str, &Path) {
    let (parent, name) = path.rsplit_once('/').unwrap_or(("", path));
    (parent, Path::new(name))
}

fn is_dir(stat: &rustix::fs::Stat) -> bool {
    rustix::fs::FileType::from_raw_mode(stat.st_mode) == rustix::fs::FileType::Directory
}

fn is_link(stat: &rustix::fs::Stat) -> bool {
    rustix::fs::FileType::from_raw_mode(stat.st_mode) == rustix::fs::FileType::Symlink
}

/// Opens `name` in `dir` as a folder, making it if it is missing.
fn open_or_make_dir(dir: BorrowedFd<'_>, name: &Path) -> io::Result<OwnedFd> {
    match fsops::open_dir(dir, name) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            match fsops::make_dir(dir, name) {
                Err(e) if e.kind() != io::ErrorKind::AlreadyExists => return Err(e),
                _ => {}
            }
            fsops::open_dir(dir, name)
        }
        opened => opened,
    }
}

/// The folders of the output folder a commit works in, opened once each
/// from the output folder down, never through a link.
#[derive(Default)]
struct Folders {
    open: HashMap<String, OwnedFd>,
}

impl Folders {
    /// The folder `rel` (`/`-separated) of the output folder `out`, made if
    /// `make`; why not, when a folder on the way is a link or not a folder.
    fn open(
        &mut self,
        out: BorrowedFd<'_>,
        out_path: &Path,
        rel: &str,
        make: bool,
    ) -> Result<OwnedFd, String> {
        if let Some(fd) = self.open.get(rel) {
            return fd.try_clone().map_err(|e| e.to_string());
        }
        let (dir, name) = match rel.rsplit_once('/') {
            Some((parent, name)) => (Some(self.open(out, out_path, parent, make)?), name),
            None if rel.is_empty() => return out.try_clone_to_owned().map_err(|e| e.to_string()),
            None => (None, rel),
        };
        let parent = dir.as_ref().map_or(out, |d| d.as_fd());
        let name = Path::new(name);
        let opened = if make {
            open_or_make_dir(parent, name)
        } else {
            fsops::open_dir(parent, name)
        };
        let fd = opened.map_err(|e| {
            let path = out_path.join(rel);
            match why_not_a_folder(&path, &e) {
                Some(why) => format!("{}: {why}; left as it is", path.display()),
                None => format!("{}: {e}", path.display()),
            }
        })?;
        let kept = fd.try_clone().map_err(|e| e.to_string())?;
        self.open.insert(rel.to_string(), kept);
        Ok(fd)
    }
}

/// The robot named by a leftover's name, and whether it holds an old folder.
/// Also the names earlier versions used (`.<robot>.tmp-<pid>`, `.<robot>.old-<pid>`).
fn leftover(name: &str) -> Option<(&str, bool)> {
    let rest = name.strip_prefix('.')?;
    if let Some(robot) = rest.strip_suffix(".semo-new") {
        return Some((robot, false));
    }
    if let Some(robot) = rest.strip_suffix(".semo-old") {
        return Some((robot, true));
    }
    let (robot, tail) = rest.rsplit_once('.')?;
    let pid_after = |prefix: &str| {
        tail.strip_prefix(prefix)
            .is_some_and(|pid| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
    };
    if pid_after("tmp-") {
        Some((robot, false))
    } else if pid_after("old-") {
        Some((robot, true))
    } else {
        None
    }
}

fn read_dir_sorted(dir: &Path) -> Result<Vec<std::fs::DirEntry>, OutputError> {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .and_then(|r| r.collect::<Result<Vec<_>, _>>())
        .map_err(at(dir))?;
    entries.sort_by_key(|e| e.file_name());
    Ok(entries)
}

/// `path` as a relative path that cannot leave its folder.
fn safe_relative(path: &str) -> io::Result<&Path> {
    let p = Path::new(path);
    let safe = p.components().all(|c| matches!(c, Component::Normal(_)));
    if safe && !path.is_empty() {
        Ok(p)
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("refusing to write `{path}`: it would leave the output folder"),
        ))
    }
}

/// The current UTC time as `YYYY-MM-DDTHH-MM-SSZ` (a folder name), with the
/// process id so two backups in one second do not meet.
fn utc_stamp() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rest) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}-{:02}-{:02}Z-{}",
        rest / 3600,
        rest / 60 % 60,
        rest % 60,
        std::process::id()
    )
}

/// The editor's output folder, checked to lie in the workspace: the
/// workspace folder (resolved) it lies in, and the path from there (for
/// [`Transaction::begin_inside`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Confined {
    pub root: PathBuf,
    pub rel: PathBuf,
}

impl Confined {
    pub fn path(&self) -> PathBuf {
        self.root.join(&self.rel)
    }
}

/// The output folder the editor asked for, resolved (`..` and symbolic
/// links) and checked to lie inside one of `allowed` (the workspace folders,
/// or the mission's folder when there is none).
pub fn confine(requested: &Path, allowed: &[PathBuf]) -> Result<Confined, String> {
    let resolved = resolve(requested).map_err(|e| {
        format!(
            "the output folder {} cannot be used: {e}",
            requested.display()
        )
    })?;
    let inside = allowed
        .iter()
        .filter_map(|root| std::fs::canonicalize(root).ok())
        .find_map(|root| {
            let rel = resolved.strip_prefix(&root).ok()?.to_path_buf();
            Some(Confined { root, rel })
        });
    inside.ok_or_else(|| {
        let roots: Vec<String> = allowed.iter().map(|r| r.display().to_string()).collect();
        format!(
            "the output folder {} (resolved to {}) is outside the workspace ({}): choose a folder inside it",
            requested.display(),
            resolved.display(),
            roots.join(", ")
        )
    })
}

/// `path` with `..` and symbolic links resolved, component by component:
/// every prefix that exists is canonicalised (so a link is followed to where
/// it really leads, and a `..` after it leaves that place), the rest is
/// taken as written (what does not exist yet cannot be a link).
fn resolve(path: &Path) -> io::Result<PathBuf> {
    let mut resolved = PathBuf::new();
    for component in path.components() {
        match component {
            Component::Prefix(_) | Component::RootDir => resolved.push(component),
            Component::CurDir => {}
            Component::ParentDir => {
                resolved.pop();
            }
            Component::Normal(name) => {
                resolved.push(name);
                match std::fs::canonicalize(&resolved) {
                    Ok(real) => resolved = real,
                    Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                    Err(e) => return Err(e),
                }
            }
        }
    }
    Ok(resolved)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leftover_names() {
        assert_eq!(leftover(".r1.semo-new"), Some(("r1", false)));
        assert_eq!(leftover(".r1.semo-old"), Some(("r1", true)));
        assert_eq!(leftover(".r1.tmp-123"), Some(("r1", false)));
        assert_eq!(leftover(".r1.old-9"), Some(("r1", true)));
        assert_eq!(leftover(".r1.old-"), None);
        assert_eq!(leftover("r1"), None);
        assert_eq!(leftover(".notes"), None);
    }

    #[test]
    fn backup_stamps_are_dates() {
        let stamp = utc_stamp();
        assert_eq!(&stamp[4..5], "-");
        assert_eq!(&stamp[10..11], "T");
        assert!(stamp[..4].parse::<u32>().unwrap() >= 2024, "{stamp}");
    }

    #[test]
    fn an_output_folder_opened_inside_a_workspace_never_goes_through_a_link() {
        let root = std::env::temp_dir().join(format!("semo-inside-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let (ws, outside) = (root.join("ws"), root.join("outside"));
        std::fs::create_dir_all(&ws).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        // What `confine` resolved may have been swapped for a link since.
        std::os::unix::fs::symlink(&outside, ws.join("gen")).unwrap();
        let refused = Transaction::begin_inside(&ws, Path::new("gen/out"), || {});
        let Err(OutputError::Unsafe(path, why)) = refused else {
            panic!("not refused");
        };
        assert_eq!(path, ws.join("gen"));
        assert!(why.contains("symbolic link"), "{why}");
        assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 0);
        let made = Transaction::begin_inside(&ws, Path::new("new/out"), || {}).unwrap();
        assert_eq!(made.out(), ws.join("new/out"));
        assert!(ws.join("new/out/.semo.lock").is_file());
        drop(made);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn confinement_resolves_dots_and_links() {
        let root = std::env::temp_dir().join(format!("semo-confine-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let ws = root.join("ws");
        std::fs::create_dir_all(ws.join("sub")).unwrap();
        std::os::unix::fs::symlink(&root, ws.join("escape")).unwrap();
        let allowed = [ws.clone()];
        assert!(confine(&ws.join("out"), &allowed).is_ok());
        assert!(confine(&ws.join("sub/../out/deep"), &allowed).is_ok());
        assert!(confine(&ws.join(".."), &allowed).is_err());
        assert!(confine(&ws.join("../../.."), &allowed).is_err());
        assert!(confine(Path::new("/tmp/elsewhere"), &allowed).is_err());
        assert!(confine(&ws.join("escape/out"), &allowed).is_err());
        assert!(confine(&ws.join("new/../../x"), &allowed).is_err());
        assert!(confine(&ws.join("new/../sub/x"), &allowed).is_ok());
        assert!(confine(&ws.join("new/../escape/x"), &allowed).is_err());
        std::fs::remove_dir_all(&root).unwrap();
    }
}
