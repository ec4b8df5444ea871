//! `.semo-manifest.json`: which files of a robot folder generation wrote, for
//! which target, and their SHA-256 at the time. A file whose hash still
//! matches is generation's to replace; any other file is the user's.

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;

pub const FILE_NAME: &str = ".semo-manifest.json";

/// The largest manifest read back (a folder's list of files is a few KB).
const MAX_BYTES: u64 = 1 << 20;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Rewritten by every generation of this target.
    Generated,
    /// A task template written for the user to fill.
    Template,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Entry {
    pub kind: Kind,
    pub sha256: String,
}

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Manifest {
    pub target: String,
    /// Relative paths with `/`, sorted.
    pub files: BTreeMap<String, Entry>,
}

impl Manifest {
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("plain data serialises");
        text.push('\n');
        text
    }

    /// The manifest in `folder`, if there is a readable one (a regular file
    /// of sane size holding valid JSON).
    pub fn read(folder: &std::path::Path) -> Option<Manifest> {
        let text = crate::workspace::read_text_limited(&folder.join(FILE_NAME), MAX_BYTES).ok()?;
        serde_json::from_str(&text).ok()
    }
}

pub fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}
