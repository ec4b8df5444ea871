//! `semo init [DIR]`: a new project: `semo.toml`, a first mission and a
//! catalog with one robot type, which `semo check` accepts as they are (and
//! `semo fmt --check`: the mission is in the canonical layout). It
//! writes nothing if any of them is already there (nothing the user wrote is
//! overwritten), and each file is created new, never opened for writing if
//! it appeared meanwhile.

use std::io::Write;
use std::path::{Path, PathBuf};

const MISSION: &str = "\
# A first mission: every rover of the team beeps once a second.
# `semo check` checks it, `semo build` writes one C program per robot (see semo.toml).
{
  Rovers: Rover rover[2]
}

Rovers.Work.Beep {
  beep()
} repeat(1 SEC)

Rovers.WORK {
  set(Work, Beep)
}

Rovers.main {
  default: mode = WORK
}
";

const CATALOG: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<!-- Robot types of this project, added to the built-in catalog: describe your robots here. -->
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Doc>A robot type to start from: rename it and describe your robot.</Doc>
    <!-- `semo build` builds its programs for this platform: linux or cortex-m. -->
    <Platform target="linux" os="linux"/>
    <Capability name="buzzer"/>
    <Service name="beep" task="buzzer" doc="Sound the buzzer once."/>
  </Robot>
</Catalog>
"#;

/// The project file, for a project named `name`.
fn project_file(name: &str) -> String {
    // A TOML basic string: quotes and backslashes escaped, control
    // characters dropped (a folder name may hold anything).
    let name: String = name
        .chars()
        .filter(|c| !c.is_control())
        .flat_map(|c| match c {
            '"' | '\\' => vec!['\\', c],
            c => vec![c],
        })
        .collect();
    format!(
        "# The SeMo project file (docs/project-file.md): the missions under this folder\n\
         # read the catalogs and strategies it names.\n\
         [project]\n\
         version = 1\n\
         name = \"{name}\"\n\
         catalogs = [\"robots\"]\n\
         # strategies = [\"strategies\"]   (default: the whole project)\n\
         \n\
         [build]\n\
         output = \"out\"\n\
         # target = \"linux\"   (every robot; default: the platform its robot type names)\n\
         \n\
         # [build.targets]     (a team's or robot's own target)\n\
         # Rovers = \"linux-sim\"\n\
         \n\
         [lints]\n\
         # W010 = \"allow\"   (allow, warn or deny a warning by its code; see `semo explain`)\n"
    )
}

/// The files `semo init` writes in `dir`.
fn files(dir: &Path) -> Vec<(PathBuf, String)> {
    let name = std::path::absolute(dir)
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "mission".to_string());
    vec![
        (dir.join(semo::project::FILE_NAME), project_file(&name)),
        (dir.join("main.mission"), MISSION.to_string()),
        (dir.join("robots/rover.robot.xml"), CATALOG.to_string()),
    ]
}

pub fn run(dir: Option<PathBuf>, out: &mut impl Write) -> i32 {
    let dir = dir.unwrap_or_else(|| PathBuf::from("."));
    let files = files(&dir);
    let existing: Vec<&PathBuf> = files
        .iter()
        .map(|(path, _)| path)
        .filter(|path| path.symlink_metadata().is_ok())
        .collect();
    if !existing.is_empty() {
        for path in existing {
            eprintln!("error: {} already exists", path.display());
        }
        eprintln!("error: semo init writes nothing over existing files; nothing was written");
        return 1;
    }
    for (path, text) in &files {
        if let Err(e) = create_new(path, text) {
            eprintln!("error: {}: {e}", path.display());
            return 2;
        }
        let _ = writeln!(out, "created {}", path.display());
    }
    let _ = writeln!(
        out,
        "next: `semo check {}` checks the project, `semo build {}` generates its code",
        dir.display(),
        dir.join("main.mission").display()
    );
    0
}

fn create_new(path: &Path, text: &str) -> std::io::Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)?;
    }
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)?;
    file.write_all(text.as_bytes())?;
    file.sync_all()
}
