//! `.semo-manifest`: which files of a robot folder generation wrote, for
//! which target, and their SHA-256 at the time. A file whose hash still
//! matches is generation's to replace; any other file is the user's.
//!
//! The format is lines of text, so that it needs no parser: a first line
//! `semo-manifest 1 target <target>`, then one line per file,
//! `<generated|template> <sha256> <path>`; paths are generation's own
//! (letters, digits, `_`, `.`, `/`), never a name from the user's files.

use sha2::{Digest, Sha256};
use std::collections::BTreeMap;

pub const FILE_NAME: &str = ".semo-manifest";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Rewritten by every generation of this target.
    Generated,
    /// A task template written for the user to fill.
    Template,
}

impl Kind {
    fn as_str(self) -> &'static str {
        match self {
            Kind::Generated => "generated",
            Kind::Template => "template",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    pub kind: Kind,
    pub sha256: String,
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Manifest {
    pub target: String,
    /// Relative paths with `/`, sorted.
    pub files: BTreeMap<String, Entry>,
}

impl Manifest {
    pub fn to_text(&self) -> String {
        let mut text = format!("semo-manifest 1 target {}\n", self.target);
        for (path, entry) in &self.files {
            text.push_str(&format!(
                "{} {} {path}\n",
                entry.kind.as_str(),
                entry.sha256
            ));
        }
        text
    }

    /// Reads what [`Manifest::to_text`] wrote; `None` for anything else.
    pub fn parse(text: &str) -> Option<Manifest> {
        let mut lines = text.lines();
        let target = lines.next()?.strip_prefix("semo-manifest 1 target ")?;
        let mut manifest = Manifest {
            target: target.to_string(),
            files: BTreeMap::new(),
        };
        for line in lines {
            let mut fields = line.splitn(3, ' ');
            let kind = match fields.next()? {
                "generated" => Kind::Generated,
                "template" => Kind::Template,
                _ => return None,
            };
            let sha256 = fields.next()?;
            let path = fields.next()?;
            let is_hash = sha256.len() == 64 && sha256.bytes().all(|b| b.is_ascii_hexdigit());
            if !is_hash || path.is_empty() {
                return None;
            }
            let entry = Entry {
                kind,
                sha256: sha256.to_string(),
            };
            manifest.files.insert(path.to_string(), entry);
        }
        Some(manifest)
    }
}

pub fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifests_read_back_what_they_wrote() {
        let mut manifest = Manifest {
            target: "linux-sim".into(),
            files: BTreeMap::new(),
        };
        for (path, kind) in [("main.c", Kind::Generated), ("tasks/a.c", Kind::Template)] {
            let sha256 = sha256(path.as_bytes());
            manifest.files.insert(path.into(), Entry { kind, sha256 });
        }
        assert_eq!(Manifest::parse(&manifest.to_text()), Some(manifest));
        assert_eq!(Manifest::parse("{\"target\": \"linux\"}"), None);
        assert_eq!(
            Manifest::parse("semo-manifest 1 target linux\nedited x main.c"),
            None
        );
    }
}
