//! Writing robot folders (codegen.md §5) as a transaction that never loses
//! what the user has there.
//!
//! - **One generation per output folder at a time.** [`Transaction::begin`]
//!   takes an exclusive lock on `<out>/.semo.lock` (an OS file lock, so the
//!   CLI and the server, and two requests of one server, exclude each other);
//!   a second generation waits for it, and gives up with a clear message
//!   after [`LOCK_WAIT`].
//! - **Old or new, never a mix.** A robot folder `<out>/<team>/<robot>` is
//!   filled as `.<robot>.semo-new` beside it, then swapped in with one
//!   `renameat2(RENAME_EXCHANGE)`; where the filesystem refuses that, the old
//!   folder is renamed to `.<robot>.semo-old` first. Those two names are the
//!   journal: [`Transaction::begin`] restores `.<robot>.semo-old` when the
//!   robot folder is missing, removes every other leftover, and reports what it
//!   did ([`Transaction::recovered`]). A crash at any point thus leaves the old
//!   or the new folder.
//! - **User files are sacred.** Each folder holds a manifest
//!   ([`manifest::FILE_NAME`]) of the files generation wrote, with their
//!   target and SHA-256. Generation replaces only files it wrote that are
//!   unchanged since; a generated file the user edited, a task file the user
//!   filled that the new target generates (`linux` → `linux-sim`), or anything
//!   else in the way is a [`Conflict`]: the generation is refused, naming the
//!   files, unless forced, which first saves them under
//!   `<out>/.semo-backup/<UTC time>/<team>/<robot>/`. Every other entry of the
//!   folder is carried over into the new one (hard-linked: never opened).
//! - **Confined.** Nothing follows a symbolic link: a team or robot folder
//!   that is a link is refused, links inside a robot folder are carried over
//!   as links, and FIFOs, sockets and devices are carried over unopened and
//!   reported ([`Written::left_alone`]). The server's output folder must lie
//!   in the workspace ([`confine`]).
//! - **Durable.** Every file written is synced; the new robot folder is synced
//!   whole before the swap, the team folder after every rename, exchange and
//!   removal, backups before what they save is replaced (all through
//!   `fsops`, counted steps). After a power cut each robot folder is thus
//!   the old or the new one, or the old one under its journal name (restored
//!   by the next run); only the interrupted generation itself may be lost.

mod fsops;
pub mod manifest;

use super::{Owner, RobotOutput, Target};
use manifest::{Entry, Kind, Manifest};
use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io;
use std::path::{Component, Path, PathBuf};
use std::time::Duration;

/// The lock file in the output folder.
pub const LOCK_FILE: &str = ".semo.lock";
/// Where forced generations save the files they replace.
pub const BACKUP_FOLDER: &str = ".semo-backup";
/// How long a generation waits for another one on the same folder.
pub const LOCK_WAIT: Duration = Duration::from_secs(120);

/// What writing one robot's folder did.
#[derive(Debug, Default)]
pub struct Written {
    pub folder: PathBuf,
    /// Generated files written.
    pub generated: usize,
    /// User files created from their template.
    pub created: usize,
    /// User files left as they were.
    pub kept: usize,
    /// Files saved under the backup folder before being replaced (forced).
    pub backed_up: Vec<PathBuf>,
    /// Entries that are neither regular files, folders nor links (FIFOs,
    /// sockets, devices): carried over without being opened.
    pub left_alone: Vec<PathBuf>,
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
            OutputError::Io(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for OutputError {}

fn at(path: &Path) -> impl FnOnce(io::Error) -> OutputError + '_ {
    move |e| OutputError::Io(path.to_path_buf(), e)
}

/// One generation into an output folder, holding its lock until dropped.
pub struct Transaction {
    out: PathBuf,
    _lock: File,
    /// What was repaired after an interrupted generation, one line each.
    pub recovered: Vec<String>,
    backup: PathBuf,
}

impl Transaction {
    /// Creates the output folder if needed, takes its lock (waiting up to
    /// [`LOCK_WAIT`]; `on_wait` is called once if it has to), and recovers
    /// what an interrupted generation left.
    pub fn begin(out: &Path, on_wait: impl FnOnce()) -> Result<Transaction, OutputError> {
        std::fs::create_dir_all(out).map_err(at(out))?;
        let lock_path = out.join(LOCK_FILE);
        let lock = fsops::open_lock(&lock_path).map_err(at(&lock_path))?;
        if !fsops::try_lock(&lock).map_err(at(&lock_path))? {
            on_wait();
            let deadline = std::time::Instant::now() + LOCK_WAIT;
            while !fsops::try_lock(&lock).map_err(at(&lock_path))? {
                if std::time::Instant::now() >= deadline {
                    return Err(OutputError::Busy(out.to_path_buf()));
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        let backup = out.join(BACKUP_FOLDER).join(utc_stamp());
        let mut transaction = Transaction {
            out: out.to_path_buf(),
            _lock: lock,
            recovered: Vec::new(),
            backup,
        };
        transaction.recover()?;
        Ok(transaction)
    }

    pub fn out(&self) -> &Path {
        &self.out
    }

    /// Restores or removes what interrupted generations left in each team
    /// folder (see the module's documentation).
    fn recover(&mut self) -> Result<(), OutputError> {
        let out = self.out.clone();
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
            // Old folders first: one is the robot folder when that is missing.
            for (path, robot, _) in leftovers.iter().filter(|l| l.2) {
                let folder = team_dir.join(robot);
                if std::fs::symlink_metadata(&folder).is_err() {
                    fsops::rename(path, &folder).map_err(at(path))?;
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
            if !leftovers.is_empty() {
                fsops::sync_dir(&team_dir).map_err(at(&team_dir))?;
            }
        }
        Ok(())
    }

    /// The files that writing `robots` for `target` would replace against
    /// the user's will, over all robots: checked before writing any.
    pub fn conflicts(
        &self,
        robots: &[RobotOutput],
        target: Target,
    ) -> Result<Vec<Conflict>, OutputError> {
        let mut all = Vec::new();
        for robot in robots {
            let folder = self.robot_folder(robot)?;
            all.extend(Plan::new(&folder, robot, target)?.conflicts);
        }
        Ok(all)
    }

    /// Writes `robot`'s folder for `target`. Refused with
    /// [`OutputError::Conflicts`] unless `force`, which saves the files in
    /// the way under the backup folder first.
    pub fn write_robot(
        &mut self,
        robot: &RobotOutput,
        target: Target,
        force: bool,
    ) -> Result<Written, OutputError> {
        let folder = self.robot_folder(robot)?;
        let plan = Plan::new(&folder, robot, target)?;
        if !plan.conflicts.is_empty() && !force {
            return Err(OutputError::Conflicts(plan.conflicts));
        }
        let mut written = Written {
            folder: folder.clone(),
            ..Written::default()
        };
        for conflict in &plan.conflicts {
            let rel = conflict
                .path
                .strip_prefix(&folder)
                .unwrap_or(&conflict.path);
            let saved = self.backup.join(&robot.team).join(&robot.robot).join(rel);
            let kind = plan.old.get(rel).copied().unwrap_or(EntryKind::File);
            save(&conflict.path, &saved, kind, &plan.old, rel).map_err(at(&saved))?;
            written.backed_up.push(saved);
        }
        if !plan.conflicts.is_empty() {
            // The saved copies are on disk before anything they save goes.
            fsops::sync_tree(&self.backup).map_err(at(&self.backup))?;
            for folder in self.backup.ancestors().skip(1).take(2) {
                fsops::sync_dir(folder).map_err(at(folder))?;
            }
        }
        let temp = sibling(&folder, "semo-new");
        if std::fs::symlink_metadata(&temp).is_ok() {
            fsops::remove_tree(&temp).map_err(at(&temp))?;
        }
        plan.fill(&temp, &folder, &mut written).map_err(at(&temp))?;
        // The new folder whole on disk before it replaces the old one.
        fsops::sync_tree(&temp).map_err(at(&temp))?;
        swap(&temp, &folder)?;
        Ok(written)
    }

    /// `<out>/<team>/<robot>`, after checking that the team folder is a real
    /// folder (created if missing) and the robot folder, if any, too.
    fn robot_folder(&self, robot: &RobotOutput) -> Result<PathBuf, OutputError> {
        for name in [&robot.team, &robot.robot] {
            safe_relative(name)
                .map_err(|e| OutputError::Unsafe(self.out.join(name), e.to_string()))?;
        }
        let team_dir = self.out.join(&robot.team);
        match std::fs::symlink_metadata(&team_dir) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                fsops::create_dir(&team_dir).map_err(at(&team_dir))?;
                fsops::sync_dir(&self.out).map_err(at(&self.out))?
            }
            Err(e) => return Err(OutputError::Io(team_dir, e)),
            Ok(m) => check_real_dir(&team_dir, &m)?,
        }
        let folder = team_dir.join(&robot.robot);
        if let Ok(m) = std::fs::symlink_metadata(&folder) {
            check_real_dir(&folder, &m)?;
        }
        Ok(folder)
    }
}

fn check_real_dir(path: &Path, meta: &std::fs::Metadata) -> Result<(), OutputError> {
    if meta.file_type().is_symlink() {
        Err(OutputError::Unsafe(
            path.to_path_buf(),
            "it is a symbolic link; generation never follows links out of the output folder".into(),
        ))
    } else if !meta.is_dir() {
        Err(OutputError::Unsafe(
            path.to_path_buf(),
            "it is not a folder".into(),
        ))
    } else {
        Ok(())
    }
}

/// `.<robot>.semo-new` and the like beside `folder`.
fn sibling(folder: &Path, suffix: &str) -> PathBuf {
    let name = folder.file_name().unwrap_or_default().to_string_lossy();
    folder.with_file_name(format!(".{name}.{suffix}"))
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

/// Swaps the filled `temp` in as `folder`; then the old folder goes. The
/// team folder is synced after each change of its names, so that after a
/// power cut it holds what the journal says (see the module's documentation).
fn swap(temp: &Path, folder: &Path) -> Result<(), OutputError> {
    let parent = folder.parent().unwrap_or(Path::new("."));
    let sync = || fsops::sync_dir(parent).map_err(at(parent));
    if std::fs::symlink_metadata(folder).is_err() {
        fsops::rename(temp, folder).map_err(at(folder))?;
        return sync();
    }
    if fsops::exchange(temp, folder).map_err(at(folder))? {
        sync()?;
        // `temp` now holds the old folder.
        fsops::remove_tree(temp).map_err(at(temp))?;
        return sync();
    }
    let old = sibling(folder, "semo-old");
    if std::fs::symlink_metadata(&old).is_ok() {
        fsops::remove_tree(&old).map_err(at(&old))?;
        sync()?;
    }
    fsops::rename(folder, &old).map_err(at(folder))?;
    sync()?;
    fsops::rename(temp, folder).map_err(at(folder))?;
    sync()?;
    fsops::remove_tree(&old).map_err(at(&old))?;
    sync()
}

/// What an entry of the old folder is (without following links).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum EntryKind {
    File,
    Dir,
    Symlink,
    /// FIFO, socket or device.
    Special,
}

impl EntryKind {
    fn of(t: std::fs::FileType) -> EntryKind {
        if t.is_symlink() {
            EntryKind::Symlink
        } else if t.is_dir() {
            EntryKind::Dir
        } else if t.is_file() {
            EntryKind::File
        } else {
            EntryKind::Special
        }
    }
}

/// What to do with one robot folder, decided before touching anything.
struct Plan<'r> {
    robot: &'r RobotOutput,
    target: Target,
    /// Every entry of the old folder, relative, links not followed.
    old: BTreeMap<PathBuf, EntryKind>,
    manifest: Option<Manifest>,
    /// New files written, by index into `robot.files`.
    write: Vec<usize>,
    /// Old entries not carried over (replaced by a new file, or a build product).
    replaced: BTreeSet<PathBuf>,
    conflicts: Vec<Conflict>,
}

impl<'r> Plan<'r> {
    fn new(folder: &Path, robot: &'r RobotOutput, target: Target) -> Result<Plan<'r>, OutputError> {
        let mut old = BTreeMap::new();
        if std::fs::symlink_metadata(folder).is_ok() {
            for entry in walkdir::WalkDir::new(folder)
                .min_depth(1)
                .follow_links(false)
            {
                let entry = entry.map_err(|e| OutputError::Io(folder.to_path_buf(), e.into()))?;
                let rel = entry.path().strip_prefix(folder).expect("under the folder");
                old.insert(rel.to_path_buf(), EntryKind::of(entry.file_type()));
            }
        }
        let manifest = Manifest::read(folder);
        let mut plan = Plan {
            robot,
            target,
            old,
            manifest,
            write: Vec::new(),
            replaced: BTreeSet::new(),
            conflicts: Vec::new(),
        };
        plan.replaced.insert(PathBuf::from(manifest::FILE_NAME));
        let mut seen = BTreeSet::new();
        for (i, file) in robot.files.iter().enumerate() {
            // A task two roles run is listed once per role: written once.
            if !seen.insert(file.path.as_str()) {
                continue;
            }
            let rel = safe_relative(&file.path)
                .map_err(|e| OutputError::Unsafe(folder.join(&file.path), e.to_string()))?;
            plan.decide(folder, i, rel);
        }
        // Build products of generated sources are left behind, so `make`
        // rebuilds everything. (Files an earlier generation wrote that this
        // one does not, say with `--emit taskgraph`, stay, still recorded.)
        for (rel, kind) in &plan.old {
            let text = rel.to_string_lossy();
            if *kind == EntryKind::File && (text.ends_with(".o") || text == robot.robot.as_str()) {
                plan.replaced.insert(rel.clone());
            }
        }
        Ok(plan)
    }

    fn decide(&mut self, folder: &Path, index: usize, rel: &Path) {
        let file = &self.robot.files[index];
        let conflict = |why: String| Conflict {
            path: folder.join(rel),
            why,
        };
        // A folder on the way that is a link or a file is in the way.
        for ancestor in rel
            .ancestors()
            .skip(1)
            .filter(|a| !a.as_os_str().is_empty())
        {
            match self.old.get(ancestor) {
                None | Some(EntryKind::Dir) => {}
                Some(kind) => {
                    let c = Conflict {
                        path: folder.join(ancestor),
                        why: format!("is {}, where generation needs a folder", describe(*kind)),
                    };
                    if !self.conflicts.contains(&c) {
                        self.conflicts.push(c);
                    }
                    self.replaced.insert(ancestor.to_path_buf());
                }
            }
        }
        let Some(kind) = self.old.get(rel).copied() else {
            self.write.push(index);
            return;
        };
        let recorded = self.manifest.as_ref().and_then(|m| m.files.get(&file.path));
        let unchanged = || {
            kind == EntryKind::File
                && read_bounded(&folder.join(rel)).is_some_and(|bytes| {
                    bytes == file.text.as_bytes()
                        || recorded.is_some_and(|e| e.sha256 == manifest::sha256(&bytes))
                })
        };
        match file.owner {
            Owner::User => {
                // A file generated for the previous target and unchanged
                // becomes this target's template; otherwise it is the user's.
                let was_generated = recorded.is_some_and(|e| e.kind == Kind::Generated);
                if was_generated && unchanged() {
                    self.write.push(index);
                    self.replaced.insert(rel.to_path_buf());
                }
            }
            Owner::Generated => {
                // Earlier versions wrote no manifest: their generated files
                // are theirs, except task files, which may have been a user's.
                let legacy = self.manifest.is_none()
                    && kind == EntryKind::File
                    && !file.path.starts_with("tasks/");
                if legacy || unchanged() {
                    self.write.push(index);
                    self.replaced.insert(rel.to_path_buf());
                    return;
                }
                let why = match (kind, recorded) {
                    (EntryKind::File, Some(e)) if e.kind == Kind::Generated => {
                        "was edited since semo generated it".to_string()
                    }
                    (EntryKind::File, Some(_)) => format!(
                        "is a task file you filled in (target {}); target {} generates it",
                        self.manifest.as_ref().map_or("?", |m| m.target.as_str()),
                        self.target.name()
                    ),
                    (EntryKind::File, None) => format!(
                        "is not a file semo generated (target {} generates it)",
                        self.target.name()
                    ),
                    (other, _) => format!("is {}, where generation writes a file", describe(other)),
                };
                self.conflicts.push(conflict(why));
                self.write.push(index);
                self.replaced.insert(rel.to_path_buf());
            }
        }
    }

    /// Writes the new folder at `temp`: the new files, then every old entry
    /// not replaced, then the manifest.
    fn fill(&self, temp: &Path, folder: &Path, written: &mut Written) -> io::Result<()> {
        fsops::create_dir(temp)?;
        let mut manifest = Manifest {
            target: self.target.name().to_string(),
            files: BTreeMap::new(),
        };
        let mut made = BTreeSet::new();
        for &i in &self.write {
            let file = &self.robot.files[i];
            let rel = Path::new(&file.path);
            make_parents(temp, rel, &mut made)?;
            fsops::write_new(&temp.join(rel), file.text.as_bytes())?;
            let kind = match file.owner {
                Owner::Generated => {
                    written.generated += 1;
                    Kind::Generated
                }
                Owner::User => {
                    written.created += 1;
                    Kind::Template
                }
            };
            let sha256 = manifest::sha256(file.text.as_bytes());
            manifest
                .files
                .insert(file.path.clone(), Entry { kind, sha256 });
        }
        let previous = self.manifest.as_ref();
        for (rel, kind) in &self.old {
            if self.replaced.iter().any(|r| rel.starts_with(r)) {
                continue;
            }
            let (from, to) = (folder.join(rel), temp.join(rel));
            match kind {
                EntryKind::Dir => {
                    if made.insert(rel.clone()) {
                        fsops::create_dir(&to)?;
                    }
                    continue;
                }
                EntryKind::File => {
                    if fsops::hard_link(&from, &to).is_err() {
                        fsops::copy_regular(&from, &to)?;
                    }
                }
                EntryKind::Symlink => {
                    if fsops::hard_link(&from, &to).is_err() {
                        fsops::copy_symlink(&from, &to)?;
                    }
                }
                EntryKind::Special => {
                    fsops::hard_link(&from, &to)?;
                    written.left_alone.push(from.clone());
                }
            }
            let text = rel.to_string_lossy().replace('\\', "/");
            if self.robot.files.iter().any(|f| f.path == text) {
                written.kept += 1;
            }
            // A kept template stays recorded as one, so a later target
            // switch still knows whether the user changed it.
            if let Some(entry) = previous.and_then(|m| m.files.get(&text)) {
                manifest.files.insert(text, entry.clone());
            }
        }
        fsops::write_new(
            &temp.join(manifest::FILE_NAME),
            manifest.to_text().as_bytes(),
        )
    }
}

fn describe(kind: EntryKind) -> &'static str {
    match kind {
        EntryKind::File => "a file",
        EntryKind::Dir => "a folder",
        EntryKind::Symlink => "a symbolic link",
        EntryKind::Special => "a FIFO, socket or device",
    }
}

/// Creates the folders of `rel` under `root` that `made` does not hold yet.
fn make_parents(root: &Path, rel: &Path, made: &mut BTreeSet<PathBuf>) -> io::Result<()> {
    let mut parents: Vec<&Path> = rel
        .ancestors()
        .skip(1)
        .filter(|a| !a.as_os_str().is_empty())
        .collect();
    parents.reverse();
    for parent in parents {
        if made.insert(parent.to_path_buf()) {
            fsops::create_dir(&root.join(parent))?;
        }
    }
    Ok(())
}

/// Saves the old entry `from` (of kind `kind`, at `rel` in the old folder)
/// at `to` without opening it: hard links, folders recreated.
fn save(
    from: &Path,
    to: &Path,
    kind: EntryKind,
    old: &BTreeMap<PathBuf, EntryKind>,
    rel: &Path,
) -> io::Result<()> {
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)?;
    }
    match kind {
        EntryKind::Dir => {
            fsops::create_dir(to)?;
            for (inner, inner_kind) in old.range(rel.to_path_buf()..) {
                let Ok(tail) = inner.strip_prefix(rel) else {
                    break;
                };
                if tail.as_os_str().is_empty() {
                    continue;
                }
                let (src, dst) = (from.join(tail), to.join(tail));
                if *inner_kind == EntryKind::Dir {
                    fsops::create_dir(&dst)?;
                } else {
                    fsops::hard_link(&src, &dst)?;
                }
            }
            Ok(())
        }
        EntryKind::File => fsops::hard_link(from, to).or_else(|_| fsops::copy_regular(from, to)),
        _ => fsops::hard_link(from, to),
    }
}

/// A regular file's bytes, if it is one and not larger than any file
/// generation writes could be (a larger one is the user's).
fn read_bounded(path: &Path) -> Option<Vec<u8>> {
    crate::fsread::read_text_limited(path, crate::fsread::MAX_FILE_BYTES)
        .ok()
        .map(String::into_bytes)
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

/// The output folder the editor asked for, resolved (`..` and symbolic
/// links) and checked to lie inside one of `allowed` (the workspace folders,
/// or the mission's folder when there is none).
pub fn confine(requested: &Path, allowed: &[PathBuf]) -> Result<PathBuf, String> {
    let resolved = resolve(requested).map_err(|e| {
        format!(
            "the output folder {} cannot be used: {e}",
            requested.display()
        )
    })?;
    let inside = allowed
        .iter()
        .filter_map(|root| std::fs::canonicalize(root).ok())
        .any(|root| resolved.starts_with(&root));
    if inside {
        Ok(resolved)
    } else {
        let roots: Vec<String> = allowed.iter().map(|r| r.display().to_string()).collect();
        Err(format!(
            "the output folder {} (resolved to {}) is outside the workspace ({}): choose a folder inside it",
            requested.display(),
            resolved.display(),
            roots.join(", ")
        ))
    }
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
