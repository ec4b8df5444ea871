//! `.semo-work/journal`: the files one generation replaces, written (and made
//! durable) before the first of them is; what lets the next run finish an
//! interrupted generation (see `output`'s documentation).
//!
//! Lines of text: `semo-journal 1 backup <stamp>`, then one line per entry,
//! `<index> <new> <old> <aside> <path>`, then `end` (a journal without it
//! was cut short, so nothing was replaced yet):
//!
//! - `<new>`: the SHA-256 of the staged file `.semo-work/n<index>`, or `-`
//!   when the entry only moves what is in the way aside (a file where
//!   generation needs a folder, forced);
//! - `<old>`: what generation saw at `<path>` and replaces: `-` (nothing),
//!   `f:<sha256>` (a file with these bytes), `o:<dev>:<ino>` (a folder, link,
//!   FIFO, ... in the way, forced: named by its inode, never opened);
//! - `<aside>`: where the old entry goes while it is replaced: `w`
//!   (`.semo-work/o<index>`, removed at the end) or `b` (the backup folder,
//!   `.semo-backup/<stamp>/<path>`, kept: a forced replacement);
//! - `<path>`: `<team>/<robot>/<file>` in the output folder.

/// The journal's name in the work folder.
pub const FILE_NAME: &str = "journal";

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Old {
    Absent,
    File { sha256: String },
    Other { dev: u64, ino: u64 },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aside {
    Work,
    Backup,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    pub index: usize,
    /// `<team>/<robot>/<file>`, generation's own names.
    pub path: String,
    pub new: Option<String>,
    pub old: Old,
    pub aside: Aside,
}

impl Entry {
    /// The staged new file's name in the work folder.
    pub fn staged(&self) -> String {
        format!("n{}", self.index)
    }

    /// The name the old entry is set aside as in the work folder.
    pub fn set_aside(&self) -> String {
        format!("o{}", self.index)
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Journal {
    /// The backup folder's name under `.semo-backup/`.
    pub stamp: String,
    pub entries: Vec<Entry>,
}

impl Journal {
    pub fn to_text(&self) -> String {
        let mut text = format!("semo-journal 1 backup {}\n", self.stamp);
        for e in &self.entries {
            let new = e.new.as_deref().unwrap_or("-");
            let old = match &e.old {
                Old::Absent => "-".to_string(),
                Old::File { sha256 } => format!("f:{sha256}"),
                Old::Other { dev, ino } => format!("o:{dev}:{ino}"),
            };
            let aside = match e.aside {
                Aside::Work => 'w',
                Aside::Backup => 'b',
            };
            text.push_str(&format!("{} {new} {old} {aside} {}\n", e.index, e.path));
        }
        text.push_str("end\n");
        text
    }

    /// Reads what [`Journal::to_text`] wrote; `None` for anything else,
    /// a journal cut short among them.
    pub fn parse(text: &str) -> Option<Journal> {
        let mut lines = text.lines();
        let stamp = lines.next()?.strip_prefix("semo-journal 1 backup ")?;
        if !is_name(stamp) {
            return None;
        }
        let mut entries = Vec::new();
        for line in lines.by_ref() {
            if line == "end" {
                return lines.next().is_none().then(|| Journal {
                    stamp: stamp.to_string(),
                    entries,
                });
            }
            entries.push(parse_entry(line)?);
        }
        None
    }
}

fn parse_entry(line: &str) -> Option<Entry> {
    let mut fields = line.splitn(5, ' ');
    let index = fields.next()?.parse().ok()?;
    let new = match fields.next()? {
        "-" => None,
        sha => Some(hash(sha)?.to_string()),
    };
    let old = match fields.next()? {
        "-" => Old::Absent,
        other => match other.split_once(':')? {
            ("f", sha) => Old::File {
                sha256: hash(sha)?.to_string(),
            },
            ("o", inode) => {
                let (dev, ino) = inode.split_once(':')?;
                Old::Other {
                    dev: dev.parse().ok()?,
                    ino: ino.parse().ok()?,
                }
            }
            _ => return None,
        },
    };
    let aside = match fields.next()? {
        "w" => Aside::Work,
        "b" => Aside::Backup,
        _ => return None,
    };
    let path = fields.next()?;
    path.split('/').all(is_name).then(|| Entry {
        index,
        path: path.to_string(),
        new,
        old,
        aside,
    })
}

fn hash(text: &str) -> Option<&str> {
    (text.len() == 64 && text.bytes().all(|b| b.is_ascii_hexdigit())).then_some(text)
}

/// One path component that cannot leave its folder.
fn is_name(text: &str) -> bool {
    !text.is_empty() && text != "." && text != ".." && !text.contains(['/', '\0', '\n'])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn journals_read_back_what_they_wrote_and_nothing_cut_short() {
        let sha = "a".repeat(64);
        let journal = Journal {
            stamp: "2026-01-02T03-04-05Z-7".into(),
            entries: vec![
                Entry {
                    index: 0,
                    path: "Team1/r1/main.c".into(),
                    new: Some(sha.clone()),
                    old: Old::File {
                        sha256: sha.clone(),
                    },
                    aside: Aside::Work,
                },
                Entry {
                    index: 1,
                    path: "Team1/r1/tasks".into(),
                    new: None,
                    old: Old::Other { dev: 3, ino: 99 },
                    aside: Aside::Backup,
                },
                Entry {
                    index: 2,
                    path: "Team1/r1/tasks/a.c".into(),
                    new: Some(sha),
                    old: Old::Absent,
                    aside: Aside::Work,
                },
            ],
        };
        let text = journal.to_text();
        assert_eq!(Journal::parse(&text), Some(journal));
        let cut = text.trim_end().strip_suffix("end").unwrap();
        assert_eq!(Journal::parse(cut), None);
        assert_eq!(Journal::parse(&text.replace("Team1/r1", "../r1")), None);
    }
}
