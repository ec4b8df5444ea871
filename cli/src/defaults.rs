//! What `semo build` and `semo simulate` work on when the command line does
//! not name it, chosen as the editors choose it: the one mission of the
//! project around the current folder (the folder of its `semo.toml`, else
//! the current folder), and the mission's own scenario beside it
//! (`<mission>.scenario.json`, else the only scenario named after the
//! mission, `sim::complete::mission_for`'s rule). When the choice is not
//! one file, the error names the choices.

use semo::workspace::{self, Bound, FileKind};
use std::path::{Path, PathBuf};

/// How many choices an error lists before it says how many more there are.
const LISTED: usize = 8;

/// How deep below a project's root its missions are looked for.
const PROJECT_DEPTH: usize = 32;

/// Why nothing was chosen: the folder looked in and what to say.
pub struct NoChoice {
    pub folder: PathBuf,
    pub message: String,
}

/// The mission a command runs: the one `named`, else the project's
/// ([`mission`]); when there is no one mission, the refusal is reported in
/// `format` for `command` and its exit status returned.
pub fn mission_or_refuse(
    named: Option<PathBuf>,
    command: &str,
    format: super::output::Format,
    out: &mut impl std::io::Write,
) -> Result<PathBuf, i32> {
    match named {
        Some(named) => Ok(named),
        None => mission(&format!("`semo {command} MISSION`"))
            .map_err(|e| super::output::refused(format, command, &e.folder, &e.message, out)),
    }
}

/// What a command that reads a mission's folder (`build`, `simulate`,
/// `replay`, `verify`) works on: [`mission_or_refuse`], then refused in one
/// line unless it is a mission file (not `-`; `also` and `note` as
/// [`input::mission_is_a_file`](super::input::mission_is_a_file) says them)
/// and the `--strategy` paths are files. Gives the file, or the exit status.
pub fn mission_file(
    named: Option<PathBuf>,
    strategy: &[PathBuf],
    command: &str,
    (also, note): (&str, &str),
    format: super::output::Format,
    out: &mut impl std::io::Write,
) -> Result<PathBuf, i32> {
    use super::input::{self, Content};
    let file = mission_or_refuse(named, command, format, out)?;
    let fits = input::mission_is_a_file(&file, command, also, note)
        && input::strategy_paths_are_files(strategy)
        && input::file_is_kind(&file, Content::Mission, &format!("semo {command}"));
    if fits { Ok(file) } else { Err(2) }
}

/// The mission file loaded with what it reads (`host::load_build`), or the
/// exit status (2) after saying why.
pub fn load(
    mission: &Path,
    strategy: &[PathBuf],
) -> Result<(semo::host::CheckRun, semo::diag::FileId), i32> {
    semo::host::load_build(mission, strategy).map_err(|e| {
        eprintln!("error: {e}");
        2
    })
}

/// The one mission of the project around the current folder: every
/// `*.mission` under the project's root (the folder holding the nearest
/// `semo.toml`, down to `PROJECT_DEPTH` folders), or without a project file
/// under the current folder down to the folders a mission sees
/// (`host::SEEN_DEPTH`). `usage` says how to name
/// one (`semo build MISSION`).
pub fn mission(usage: &str) -> Result<PathBuf, NoChoice> {
    let here = PathBuf::from(".");
    let (root, place, depth) = match semo::project::find(&here) {
        Some(root) => (from_here(&root), "the project", PROJECT_DEPTH),
        None => (here, "this folder", semo::host::SEEN_DEPTH),
    };
    let no_choice = |message: String| NoChoice {
        folder: root.clone(),
        message,
    };
    let where_ = format!("{place} ({})", root.display());
    let bound = Bound {
        depth,
        entries: semo::host::MAX_ENTRIES,
    };
    let (found, cut) = workspace::collect_bounded(&root, bound)
        .map_err(|e| no_choice(format!("looking for the mission: {e}")))?;
    let missions: Vec<PathBuf> = found
        .into_iter()
        .filter(|(_, kind)| *kind == FileKind::Mission)
        .map(|(path, _)| {
            path.strip_prefix(".")
                .map(Path::to_path_buf)
                .unwrap_or(path)
        })
        .collect();
    match missions.as_slice() {
        [one] if !cut => Ok(one.clone()),
        [] if !cut => Err(no_choice(format!(
            "no mission (*.mission) in {where_}: name one ({usage})"
        ))),
        _ if cut => Err(no_choice(format!(
            "{where_} has more than {} entries to look through for its mission: name it ({usage})",
            semo::host::MAX_ENTRIES
        ))),
        many => Err(no_choice(format!(
            "{} missions in {where_}, which one? {} ({usage})",
            many.len(),
            listed(many)
        ))),
    }
}

/// The scenario `mission` runs on: `<mission>.scenario.json` beside it (the
/// one the editors offer first), else the only scenario beside it named
/// after the mission (`<mission>.<anything>.scenario.json`).
pub fn scenario(mission: &Path) -> Result<PathBuf, NoChoice> {
    let own = semo::sim::complete::own_scenario(mission);
    let folder = mission
        .parent()
        .filter(|f| !f.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let no_choice = |message: String| NoChoice {
        folder: folder.to_path_buf(),
        message,
    };
    let named = semo::sim::complete::scenarios_of(mission)
        .map_err(|e| no_choice(format!("{}: {e}", folder.display())))?;
    match named.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(no_choice(format!(
            "no scenario for {}: looked for {} (name one with --scenario FILE)",
            mission.display(),
            own.display()
        ))),
        many => Err(no_choice(format!(
            "{} scenarios for {}, which one? {} (name it with --scenario FILE)",
            many.len(),
            mission.display(),
            listed(many)
        ))),
    }
}

/// The first choices, comma-separated, and how many more there are.
fn listed(paths: &[PathBuf]) -> String {
    let mut text = paths
        .iter()
        .take(LISTED)
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    if paths.len() > LISTED {
        text.push_str(&format!(" and {} more", paths.len() - LISTED));
    }
    text
}

/// `path` (absolute) as the user would write it from the current folder:
/// `.`, `..`, `../robots/rover.robot.xml`, …; as it is when the two share
/// no folder but the root.
pub fn from_here(path: &Path) -> PathBuf {
    let Ok(here) = std::env::current_dir() else {
        return path.to_path_buf();
    };
    let shared = here
        .components()
        .zip(path.components())
        .take_while(|(a, b)| a == b)
        .count();
    if shared <= 1 {
        return path.to_path_buf();
    }
    let up = here.components().count() - shared;
    let relative: PathBuf = std::iter::repeat_n(Path::new(".."), up)
        .chain(
            path.components()
                .skip(shared)
                .map(|c| Path::new(c.as_os_str())),
        )
        .collect();
    if relative.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        relative
    }
}
