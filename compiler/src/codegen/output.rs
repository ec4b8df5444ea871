//! Writing robot folders (codegen.md §5): only under the output folder, one
//! robot folder at a time through a temporary folder renamed into place, so a
//! failure leaves the previous output intact; files the user owns (task
//! templates already filled, anything else the user put there) are carried
//! over, never overwritten.

use super::{Owner, RobotOutput};
use std::io;
use std::path::{Path, PathBuf};

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
}

/// Writes `robot` to `<out>/<team>/<robot>/`. Names were checked before
/// (identifiers only), and every path is checked again here to stay inside.
pub fn write_robot(out: &Path, robot: &RobotOutput) -> io::Result<Written> {
    let team_dir = out.join(&robot.team);
    std::fs::create_dir_all(&team_dir)?;
    let folder = team_dir.join(&robot.robot);
    let temp = team_dir.join(format!(".{}.tmp-{}", robot.robot, std::process::id()));
    let old = team_dir.join(format!(".{}.old-{}", robot.robot, std::process::id()));
    if temp.exists() {
        std::fs::remove_dir_all(&temp)?;
    }
    let result = fill(&temp, &folder, robot);
    let written = match result {
        Ok(w) => w,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&temp);
            return Err(e);
        }
    };
    // Swap: the old folder aside, the new one in, then the old one away.
    if folder.exists() {
        std::fs::rename(&folder, &old)?;
    }
    if let Err(e) = std::fs::rename(&temp, &folder) {
        if old.exists() {
            let _ = std::fs::rename(&old, &folder);
        }
        let _ = std::fs::remove_dir_all(&temp);
        return Err(e);
    }
    if old.exists() {
        std::fs::remove_dir_all(&old)?;
    }
    Ok(Written { folder, ..written })
}

fn fill(temp: &Path, previous: &Path, robot: &RobotOutput) -> io::Result<Written> {
    std::fs::create_dir_all(temp)?;
    let mut written = Written::default();
    let generated: Vec<&str> = robot
        .files
        .iter()
        .filter(|f| f.owner == Owner::Generated)
        .map(|f| f.path.as_str())
        .collect();
    // Carry over what the user has there: every file that generation does
    // not rewrite (build products of generated sources are left behind).
    if previous.is_dir() {
        for rel in files_under(previous)? {
            let rel_text = rel.to_string_lossy().replace('\\', "/");
            let is_build_product = rel_text.ends_with(".o") || rel_text == robot.robot;
            if generated.contains(&rel_text.as_str()) || is_build_product {
                continue;
            }
            let dest = temp.join(&rel);
            if let Some(parent) = dest.parent() {
                std::fs::create_dir_all(parent)?;
            }
            std::fs::copy(previous.join(&rel), &dest)?;
            if robot.files.iter().any(|f| f.path == rel_text) {
                written.kept += 1;
            }
        }
    }
    for file in &robot.files {
        let rel = safe_relative(&file.path)?;
        let dest = temp.join(rel);
        if file.owner == Owner::User && dest.exists() {
            continue;
        }
        if let Some(parent) = dest.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(&dest, &file.text)?;
        match file.owner {
            Owner::Generated => written.generated += 1,
            Owner::User => written.created += 1,
        }
    }
    Ok(written)
}

/// `path` as a relative path that cannot leave its folder.
fn safe_relative(path: &str) -> io::Result<&Path> {
    let p = Path::new(path);
    let safe = p
        .components()
        .all(|c| matches!(c, std::path::Component::Normal(_)));
    if safe && !path.is_empty() {
        Ok(p)
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("refusing to write `{path}`: it would leave the output folder"),
        ))
    }
}

/// Every file under `dir`, relative to it, in a stable order.
fn files_under(dir: &Path) -> io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(dir.join(&rel))?.collect::<Result<_, _>>()?;
        entries.sort_by_key(|e| e.file_name());
        for entry in entries {
            let child = rel.join(entry.file_name());
            if entry.file_type()?.is_dir() {
                stack.push(child);
            } else {
                out.push(child);
            }
        }
    }
    out.sort();
    Ok(out)
}
