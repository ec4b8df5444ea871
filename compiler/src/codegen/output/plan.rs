//! What generation changes in one robot folder, decided by looking (never
//! opening anything but regular files, never following a link) before it
//! stages anything: the files to write and what each replaces, the
//! conflicts, and the new manifest.

use super::journal::{Aside, Old};
use super::manifest::{self, Entry, Kind, Manifest};
use super::{Conflict, FolderFiles, OutputError, Written, at, fsops, not_a_folder, safe_relative};
use crate::codegen::{GeneratedFile, Owner};
use std::borrow::Cow;
use std::collections::BTreeSet;
use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::path::{Path, PathBuf};

/// The largest manifest read back (a folder's list of files is a few KB).
const MAX_MANIFEST_BYTES: u64 = 1 << 20;

/// One change to the robot folder: `rel` (with `/`) gets `bytes` (none: the
/// entry in the way of a folder only goes), replacing `old`, set aside to
/// `aside` meanwhile.
pub struct Change<'r> {
    pub rel: String,
    pub bytes: Option<Cow<'r, [u8]>>,
    pub old: Old,
    pub aside: Aside,
}

pub struct Plan<'r> {
    pub changes: Vec<Change<'r>>,
    pub conflicts: Vec<Conflict>,
    pub written: Written,
}

/// What is at a path of the robot folder.
enum Look {
    Absent,
    /// A regular file's bytes.
    File(Vec<u8>),
    /// A folder, link, FIFO, socket or device; a file larger than
    /// generation ever writes.
    Other(rustix::fs::Stat),
    /// A folder on the way is something else, at this path.
    InTheWay(String, Box<Look>),
}

struct Folder {
    dir: Option<OwnedFd>,
    path: PathBuf,
    backup: PathBuf,
    previous: Option<Manifest>,
    /// What generation writes it for (a target's name, or the runtime
    /// folder's targets).
    target: String,
}

impl<'r> Plan<'r> {
    pub fn new(
        out: BorrowedFd<'_>,
        out_path: &Path,
        backup: &Path,
        files: &FolderFiles<'r>,
    ) -> Result<Plan<'r>, OutputError> {
        let folder = open_folder(out, out_path, &files.names, backup, &files.target)?;
        let mut plan = Plan {
            changes: Vec::new(),
            conflicts: Vec::new(),
            written: Written {
                folder: folder.path.clone(),
                left_alone: specials(&folder)?,
                ..Written::default()
            },
        };
        let mut manifest = Manifest {
            target: files.target.clone(),
            files: Default::default(),
        };
        let mut seen = BTreeSet::new();
        for file in files.files {
            // A task two roles run is listed once per role: written once.
            if !seen.insert(file.path.as_str()) {
                continue;
            }
            safe_relative(&file.path)
                .map_err(|e| OutputError::Unsafe(folder.path.join(&file.path), e.to_string()))?;
            let look = folder.look(&file.path)?;
            if let Some(entry) = plan.decide(&folder, file, look)? {
                manifest.files.insert(file.path.clone(), entry);
            }
        }
        // Files an earlier generation wrote that this one does not (say with
        // `--emit taskgraph`) stay, still recorded; retired ones go.
        for (path, entry) in folder.previous.iter().flat_map(|m| &m.files) {
            if seen.contains(path.as_str()) {
                continue;
            }
            if let Look::File(bytes) = folder.look(path)? {
                if (files.retired)(path) {
                    plan.retire(&folder, path, entry, bytes);
                } else {
                    manifest.files.insert(path.clone(), entry.clone());
                }
            }
        }
        plan.record(&folder, manifest)?;
        Ok(plan)
    }

    /// What to do with `file`, given what is at its path; its manifest entry.
    fn decide(
        &mut self,
        folder: &Folder,
        file: &'r GeneratedFile,
        look: Look,
    ) -> Result<Option<Entry>, OutputError> {
        let look = match look {
            Look::InTheWay(at, blocking) => {
                let why = format!(
                    "is {}, where generation needs a folder",
                    describe(&blocking)
                );
                let old = old_of(&blocking);
                if !self.changes.iter().any(|c| c.rel == at) {
                    self.conflict(folder, &at, why, None, old);
                }
                Look::Absent
            }
            look => look,
        };
        let new = file.text.as_bytes();
        let recorded = folder
            .previous
            .as_ref()
            .and_then(|m| m.files.get(&file.path));
        let written_by = |kind| {
            Some(Entry {
                kind,
                sha256: manifest::sha256(new),
            })
        };
        let unchanged = |bytes: &[u8]| {
            bytes == new || recorded.is_some_and(|e| e.sha256 == manifest::sha256(bytes))
        };
        match (file.owner, look) {
            (owner, Look::Absent) => {
                self.write(&file.path, new, Old::Absent);
                Ok(written_by(self.count(owner)))
            }
            (owner, Look::File(bytes)) if bytes == new => {
                if owner == Owner::User && recorded.is_none_or(|e| e.kind != Kind::Generated) {
                    self.written.kept += 1;
                    return Ok(recorded.cloned());
                }
                Ok(written_by(self.count(owner)))
            }
            (Owner::User, Look::File(bytes)) => {
                // A file generated for the previous target and unchanged
                // becomes this target's template; otherwise it is the user's.
                let was_generated = recorded.is_some_and(|e| e.kind == Kind::Generated);
                if was_generated && unchanged(&bytes) {
                    self.write(
                        &file.path,
                        new,
                        Old::File {
                            sha256: manifest::sha256(&bytes),
                        },
                    );
                    return Ok(written_by(self.count(Owner::User)));
                }
                self.written.kept += 1;
                Ok(recorded.cloned())
            }
            (Owner::User, _) => {
                self.written.kept += 1;
                Ok(recorded.cloned())
            }
            (Owner::Generated, Look::File(bytes)) => {
                // Earlier versions wrote no manifest: their generated files
                // are theirs, except task files, which may have been a user's.
                let legacy = folder.previous.is_none() && !file.path.starts_with("tasks/");
                let old = Old::File {
                    sha256: manifest::sha256(&bytes),
                };
                if legacy || unchanged(&bytes) {
                    self.write(&file.path, new, old);
                } else {
                    let why = match recorded {
                        Some(e) if e.kind == Kind::Generated => {
                            "was edited since semo generated it".to_string()
                        }
                        Some(_) => format!(
                            "is a task file you filled in (target {}); target {} generates it",
                            folder.previous.as_ref().map_or("?", |m| m.target.as_str()),
                            folder.target
                        ),
                        None => format!(
                            "is not a file semo generated (target {} generates it)",
                            folder.target
                        ),
                    };
                    self.conflict(folder, &file.path, why, Some(new), old);
                }
                Ok(written_by(self.count(Owner::Generated)))
            }
            (Owner::Generated, other) => {
                let why = format!("is {}, where generation writes a file", describe(&other));
                self.conflict(folder, &file.path, why, Some(new), old_of(&other));
                Ok(written_by(self.count(Owner::Generated)))
            }
        }
    }

    /// A file an earlier version generated at `rel` and this one no longer
    /// does: removed if unchanged since, else in the way (the user's edit is
    /// kept, under the backup folder when forced).
    fn retire(&mut self, folder: &Folder, rel: &str, recorded: &Entry, bytes: Vec<u8>) {
        let old = Old::File {
            sha256: manifest::sha256(&bytes),
        };
        if recorded.kind == Kind::Generated && recorded.sha256 == manifest::sha256(&bytes) {
            self.changes.push(Change {
                rel: rel.to_string(),
                bytes: None,
                old,
                aside: Aside::Work,
            });
        } else {
            let why = format!(
                "was edited since semo generated it; the runtime is no longer copied into robot folders (it is in `{}`)",
                crate::codegen::RUNTIME_FOLDER
            );
            self.conflict(folder, rel, why, None, old);
        }
    }

    fn count(&mut self, owner: Owner) -> Kind {
        match owner {
            Owner::Generated => {
                self.written.generated += 1;
                Kind::Generated
            }
            Owner::User => {
                self.written.created += 1;
                Kind::Template
            }
        }
    }

    fn write(&mut self, rel: &str, bytes: &'r [u8], old: Old) {
        self.changes.push(Change {
            rel: rel.to_string(),
            bytes: Some(Cow::Borrowed(bytes)),
            old,
            aside: Aside::Work,
        });
    }

    /// `rel` is in the way: a conflict, and (if forced) a change that moves
    /// it under the backup folder.
    fn conflict(
        &mut self,
        folder: &Folder,
        rel: &str,
        why: String,
        new: Option<&'r [u8]>,
        old: Old,
    ) {
        self.conflicts.push(Conflict {
            path: folder.path.join(rel),
            why,
        });
        self.written.backed_up.push(folder.backup.join(rel));
        self.changes.push(Change {
            rel: rel.to_string(),
            bytes: new.map(Cow::Borrowed),
            old,
            aside: Aside::Backup,
        });
    }

    /// The new manifest, written last, if it differs from the one there.
    fn record(&mut self, folder: &Folder, manifest: Manifest) -> Result<(), OutputError> {
        let text = manifest.to_text().into_bytes();
        let old = match folder.look(manifest::FILE_NAME)? {
            Look::File(bytes) if bytes == text => return Ok(()),
            Look::Absent => Old::Absent,
            Look::File(bytes) => Old::File {
                sha256: manifest::sha256(&bytes),
            },
            other => {
                let why = format!(
                    "is {}, where generation keeps its manifest",
                    describe(&other)
                );
                let old = old_of(&other);
                self.conflicts.push(Conflict {
                    path: folder.path.join(manifest::FILE_NAME),
                    why,
                });
                self.written
                    .backed_up
                    .push(folder.backup.join(manifest::FILE_NAME));
                self.changes.push(Change {
                    rel: manifest::FILE_NAME.to_string(),
                    bytes: Some(Cow::Owned(text)),
                    old,
                    aside: Aside::Backup,
                });
                return Ok(());
            }
        };
        self.changes.push(Change {
            rel: manifest::FILE_NAME.to_string(),
            bytes: Some(Cow::Owned(text)),
            old,
            aside: Aside::Work,
        });
        Ok(())
    }
}

/// `<out>/<names...>` (`<team>/<robot>`), opened if it exists, after
/// checking that each folder on the way is a real folder.
fn open_folder(
    out: BorrowedFd<'_>,
    out_path: &Path,
    names: &[&str],
    backup: &Path,
    target: &str,
) -> Result<Folder, OutputError> {
    let mut path = out_path.to_path_buf();
    let mut dir: Option<OwnedFd> = None;
    let mut missing = false;
    for name in names {
        let single = safe_relative(name).is_ok_and(|p| p.components().count() == 1);
        if !single {
            return Err(OutputError::Unsafe(
                path.join(name),
                format!("`{name}` would leave the output folder"),
            ));
        }
        path.push(name);
        if missing {
            continue;
        }
        let parent = dir.as_ref().map_or(out, |d| d.as_fd());
        match fsops::open_dir(parent, Path::new(name)) {
            Ok(fd) => dir = Some(fd),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                missing = true;
                dir = None;
            }
            Err(e) => return Err(not_a_folder(&path)(e)),
        }
    }
    let previous = match &dir {
        None => None,
        Some(d) => fsops::read_regular(
            d.as_fd(),
            Path::new(manifest::FILE_NAME),
            MAX_MANIFEST_BYTES,
        )
        .map_err(at(&path))?
        .and_then(|bytes| Manifest::parse(&String::from_utf8_lossy(&bytes))),
    };
    Ok(Folder {
        dir,
        backup: names.iter().fold(backup.to_path_buf(), |b, n| b.join(n)),
        path,
        previous,
        target: target.to_string(),
    })
}

impl Folder {
    /// What is at `rel` (with `/`), the folders on the way opened one by
    /// one without following links.
    fn look(&self, rel: &str) -> Result<Look, OutputError> {
        let Some(robot) = &self.dir else {
            return Ok(Look::Absent);
        };
        let err = |e| OutputError::Io(self.path.join(rel), e);
        let mut held: Option<OwnedFd> = None;
        let mut walked = String::new();
        let mut parts = rel.split('/').peekable();
        while let Some(part) = parts.next() {
            let here = held.as_ref().unwrap_or(robot).as_fd();
            let name = Path::new(part);
            let Some(stat) = fsops::stat(here, name).map_err(err)? else {
                return Ok(Look::Absent);
            };
            if !walked.is_empty() {
                walked.push('/');
            }
            walked.push_str(part);
            let kind = rustix::fs::FileType::from_raw_mode(stat.st_mode);
            let look = match kind {
                rustix::fs::FileType::RegularFile => {
                    match fsops::read_regular(here, name, crate::fsread::MAX_FILE_BYTES)
                        .map_err(err)?
                    {
                        Some(bytes) => Look::File(bytes),
                        None => Look::Other(stat),
                    }
                }
                _ => Look::Other(stat),
            };
            if parts.peek().is_none() {
                return Ok(look);
            }
            if kind != rustix::fs::FileType::Directory {
                return Ok(Look::InTheWay(walked, Box::new(look)));
            }
            let below = fsops::open_dir(here, name).map_err(err)?;
            held = Some(below);
        }
        Ok(Look::Absent)
    }
}

/// The FIFOs, sockets and devices in the robot folder (reported, never
/// opened), links not followed.
fn specials(folder: &Folder) -> Result<Vec<PathBuf>, OutputError> {
    if folder.dir.is_none() {
        return Ok(Vec::new());
    }
    let mut found = Vec::new();
    for entry in walkdir::WalkDir::new(&folder.path)
        .min_depth(1)
        .follow_links(false)
    {
        let entry = entry.map_err(|e| OutputError::Io(folder.path.clone(), e.into()))?;
        let t = entry.file_type();
        if !t.is_file() && !t.is_dir() && !t.is_symlink() {
            found.push(entry.path().to_path_buf());
        }
    }
    Ok(found)
}

fn old_of(look: &Look) -> Old {
    match look {
        Look::Absent => Old::Absent,
        Look::File(bytes) => Old::File {
            sha256: manifest::sha256(bytes),
        },
        Look::InTheWay(_, blocking) => old_of(blocking),
        Look::Other(stat) => Old::Other {
            dev: stat.st_dev,
            ino: stat.st_ino,
        },
    }
}

fn describe(look: &Look) -> &'static str {
    use rustix::fs::FileType;
    match look {
        Look::Absent | Look::InTheWay(..) => "missing",
        Look::File(_) => "a file",
        Look::Other(stat) => match FileType::from_raw_mode(stat.st_mode) {
            FileType::Directory => "a folder",
            FileType::Symlink => "a symbolic link",
            _ => "a FIFO, socket or device",
        },
    }
}
