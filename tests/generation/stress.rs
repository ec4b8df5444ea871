//! Stress runs of issue 33's generation findings, measured as counts: real
//! `semo build` processes over the scouting example while another thread
//! acts as a user (or an attacker) on the output folder at whatever moments
//! the scheduler gives it. Each run prints its counts as one line
//! (`stress: ...`) and asserts the zero; what can be lost must be 0 whatever
//! the interleaving, so a small run of each is a plain test too. The sizes
//! the closing note quotes are the `#[ignore]`d runs.

use super::{Content, contents, copy_example, generated_folders, hash, leftovers, rename_save};
use super::{Pauses, build, build_paused, scratch};
use crate::support::swap::{clear_set_aside, swapper};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

/// Scouting copied into `dir` twice under two names (every generated file
/// names its mission, so alternating the two rewrites them all), built once
/// into `<dir>/out`: the two missions and the output folder.
fn scouting_pair(dir: &Path) -> ([PathBuf; 2], PathBuf) {
    let first = copy_example("scouting", "scouting.mission", dir);
    let second = dir.join("renamed.mission");
    std::fs::copy(&first, &second).unwrap();
    let out = dir.join("out");
    let built = build(&first, &out, &[]);
    assert_eq!(built.code, 0, "{}", built.stderr);
    ([first, second], out)
}

/// `semo build MISSION -o OUT EXTRA` started; its standard error is read
/// by a thread (a long conflict list never blocks it).
fn start_build(
    mission: &Path,
    out: &Path,
    extra: &[&str],
) -> (std::process::Child, JoinHandle<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("build")
        .arg(mission)
        .arg("-o")
        .arg(out)
        .args(extra)
        .env("NO_COLOR", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        stderr.read_to_string(&mut text).unwrap();
        text
    });
    (child, reader)
}

/// The files of the robot folders (and the runtime's) under `out`: the task
/// files (under `tasks/`) and the generated ones (the rest but manifests).
fn files_of(out: &Path) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let (mut tasks, mut generated) = (Vec::new(), Vec::new());
    for folder in generated_folders(out) {
        for (rel, content) in contents(&out.join(&folder)) {
            let name = rel.file_name().unwrap().to_string_lossy().into_owned();
            if content == Content::Dir || name.starts_with('.') {
                continue;
            }
            let path = out.join(&folder).join(&rel);
            if rel.starts_with("tasks") {
                tasks.push(path);
            } else {
                generated.push(path);
            }
        }
    }
    (tasks, generated)
}

/// How one edit of a generated file was saved.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Save {
    /// `open(O_TRUNC)` and write, as `echo > file` does.
    InPlace,
    /// A new file renamed over the old, as many editors save.
    Rename,
}

/// What the user did during the builds and what became of it.
#[derive(Default, Debug)]
struct UserCounts {
    builds: usize,
    builds_kept_changes: usize,
    builds_refused: usize,
    created: usize,
    created_lost: usize,
    saves: usize,
    saves_lost: usize,
    edits: usize,
    edits_in_place: usize,
    /// Kept in place and named by the build's report (kept while it
    /// generated, or a conflict that stopped it).
    edits_reported: usize,
    /// Kept in place, made after the build had replaced the file (the next
    /// build reports it as a conflict).
    edits_after: usize,
    /// Found under `.semo-backup/` (an in-place write through a descriptor
    /// opened before the build set the file aside), named by the report.
    edits_backed_up: usize,
    /// Found nowhere, or saved without the report saying so.
    edits_lost: usize,
}

/// Every file under `out/.semo-backup` by the hash of its bytes.
fn backed_up(out: &Path) -> BTreeMap<u64, PathBuf> {
    let backup = out.join(".semo-backup");
    if !backup.is_dir() {
        return BTreeMap::new();
    }
    contents(&backup)
        .into_iter()
        .filter_map(|(p, c)| match c {
            Content::File(h) => Some((h, p)),
            _ => None,
        })
        .collect()
}

/// `builds` builds of scouting alternating its two names (so each rewrites
/// every generated file) while the user, as long as a build runs, creates
/// files in the robot folders, rename-saves task files (each checked still
/// as last saved before the next save) and edits generated files (one edit
/// per file per build; `in_place` lets half of them be written in place).
/// After each build: every created file, task save and edit is where the
/// user left it (an edit may instead be under `.semo-backup/`, named by the
/// report). Then the created files and the edited generated files are
/// removed, so that the next build generates every file again.
fn user_during_builds(name: &str, builds: usize, in_place: bool) -> UserCounts {
    let dir = scratch(name);
    let (missions, out) = scouting_pair(&dir);
    let (tasks, generated) = files_of(&out);
    assert!(
        !tasks.is_empty() && generated.len() > 5,
        "{tasks:?} {generated:?}"
    );
    let robots: Vec<PathBuf> = generated_folders(&out)
        .into_iter()
        .map(|f| out.join(f))
        .collect();
    let mut saved: BTreeMap<PathBuf, String> = tasks
        .iter()
        .map(|t| (t.clone(), std::fs::read_to_string(t).unwrap()))
        .collect();
    let mut counts = UserCounts::default();
    let mut last_actions = 30;
    for round in 0..builds {
        let (mut child, stderr) = start_build(&missions[(round + 1) % 2], &out, &[]);
        let mut made: Vec<(PathBuf, String)> = Vec::new();
        let mut edited: Vec<(PathBuf, String, Save)> = Vec::new();
        let mut action = 0;
        // Edits begin at a point that moves from build to build through
        // the length of the last one, in tenths (a build refuses edits it
        // finds before it looks, keeps those made while it replaces files,
        // and never sees later ones).
        let first_edit = (round * 3) % 10 * last_actions / 8;
        loop {
            let robot = &robots[action % robots.len()];
            let path = robot.join(format!("made-{round}-{action}.txt"));
            let text = format!("made during build {round}, action {action}\n");
            std::fs::write(&path, &text).unwrap();
            made.push((path, text));
            if action % 2 == 0 {
                let task = &tasks[(action / 2) % tasks.len()];
                let now = std::fs::read_to_string(task).unwrap_or_default();
                if now != saved[task] {
                    eprintln!("lost save of {}", task.display());
                    counts.saves_lost += 1;
                }
                let text = format!("/* saved during build {round}, action {action} */\n");
                rename_save(task, &text);
                saved.insert(task.clone(), text);
                counts.saves += 1;
            }
            if action >= first_edit && action % 3 == 1 && edited.len() < generated.len() {
                let file = &generated[(round * 5 + edited.len()) % generated.len()];
                let text = format!("/* edited during build {round}, action {action} */\n");
                let how = if in_place && edited.len() % 2 == 0 {
                    std::fs::write(file, &text).unwrap();
                    Save::InPlace
                } else {
                    rename_save(file, &text);
                    Save::Rename
                };
                edited.push((file.clone(), text, how));
            }
            action += 1;
            // Two actions at least, whatever the build's speed: every build
            // gets a file and a save, and the first (its edits begin at
            // once) an edit.
            if action >= 2 && child.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        let code = child.wait().unwrap().code();
        let report = stderr.join().unwrap();
        counts.builds += 1;
        match code {
            // The length of a build that generated (a refused one stops
            // early) is where the next one's edits are spread.
            Some(0) => last_actions = action,
            Some(1) if report.contains("while semo was") => {
                counts.builds_kept_changes += 1;
                last_actions = action;
            }
            // An edit made before the build looked: a conflict, nothing written.
            Some(1) if report.contains("nothing was written") => counts.builds_refused += 1,
            other => panic!("build {round}: {other:?}: {report}"),
        }
        for (path, text) in made {
            counts.created += 1;
            if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
                eprintln!("lost created file {}", path.display());
                counts.created_lost += 1;
            }
            std::fs::remove_file(&path).unwrap();
        }
        let backups = backed_up(&out);
        for (file, text, how) in edited {
            counts.edits += 1;
            counts.edits_in_place += usize::from(how == Save::InPlace);
            let rel = file.strip_prefix(&out).unwrap().display().to_string();
            let named = report.contains(&rel);
            let now = std::fs::read_to_string(&file).ok();
            if now.as_deref() == Some(text.as_str()) {
                if named {
                    counts.edits_reported += 1;
                } else {
                    counts.edits_after += 1;
                }
            } else if backups.contains_key(&hash(text.as_bytes())) && named {
                counts.edits_backed_up += 1;
            } else {
                eprintln!("lost edit of {rel} ({how:?}): {report}");
                counts.edits_lost += 1;
            }
            let _ = std::fs::remove_file(&file);
        }
        let _ = std::fs::remove_dir_all(out.join(".semo-backup"));
        assert_eq!(leftovers(&out), Vec::<PathBuf>::new(), "build {round}");
    }
    for (task, text) in &saved {
        counts.saves_lost += usize::from(std::fs::read_to_string(task).unwrap() != *text);
    }
    counts
}

/// The counts of [`user_during_builds`] as the issue quotes them.
fn print_user(c: &UserCounts) {
    eprintln!(
        "stress: {} builds ({} reported changes they kept, {} refused over edits made before they looked); {} user files created during them, {} lost; \
         {} rename-saves of task files, {} lost; {} edits of generated files ({} in place), \
         {} kept and reported, {} kept (made after the file was replaced), {} saved under .semo-backup and reported, \
         {} lost or unreported",
        c.builds,
        c.builds_kept_changes,
        c.builds_refused,
        c.created,
        c.created_lost,
        c.saves,
        c.saves_lost,
        c.edits,
        c.edits_in_place,
        c.edits_reported,
        c.edits_after,
        c.edits_backed_up,
        c.edits_lost
    );
}

fn assert_nothing_lost(c: &UserCounts) {
    assert!(c.created > 0 && c.saves > 0 && c.edits > 0, "{c:?}");
    assert_eq!(
        (c.created_lost, c.saves_lost, c.edits_lost),
        (0, 0, 0),
        "{c:?}"
    );
}

/// A small run that CI keeps: edits of generated files saved by renaming
/// only (an in-place write racing the last check of a set-aside file is
/// the one window `output.rs` documents).
#[test]
fn what_the_user_does_during_repeated_builds_is_never_lost() {
    let counts = user_during_builds("stress-user-small", 4, false);
    print_user(&counts);
    assert_nothing_lost(&counts);
}

#[test]
#[ignore = "stress run (a few minutes): cargo test --test generation -- --ignored stress_"]
fn stress_what_the_user_does_during_builds() {
    let builds = sized("SEMO_STRESS_BUILDS", 200);
    let counts = user_during_builds("stress-user", builds, true);
    print_user(&counts);
    assert_nothing_lost(&counts);
}

/// A stress run's size: `var` if set, else `default`.
pub(crate) fn sized(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// What a swapper turns into a link: a folder of the output folder.
#[derive(Clone, Copy, Debug)]
enum Swapped {
    /// The output folder itself, once the build has opened it (a link given
    /// on the command line is the user's choice, followed at the start).
    Output,
    Team,
    Robot,
    /// `.semo-backup`, during builds forced over an edited file.
    Backup,
}

/// What the link-swap runs counted.
#[derive(Default, Debug)]
struct SwapCounts {
    builds: usize,
    swaps: usize,
    refused: usize,
    outside: usize,
}

/// `builds` builds of scouting (alternating its two names) while a swapper
/// turns `what` into a link to a folder outside and back: the entries that
/// appear outside.
fn links_swapped_during_builds(name: &str, what: Swapped, builds: usize) -> SwapCounts {
    let dir = scratch(name);
    let (missions, out) = scouting_pair(&dir);
    let robot = out.join(&generated_folders(&out)[0]);
    let outside = dir.join("outside");
    let pauses = Pauses::at(dir.join("pause"));
    let mut counts = SwapCounts::default();
    for round in 0..builds {
        let _ = std::fs::remove_dir_all(&outside);
        std::fs::create_dir_all(&outside).unwrap();
        let mission = missions[(round + 1) % 2].display().to_string();
        let out_arg = out.display().to_string();
        let mut args = vec!["build", mission.as_str(), "-o", out_arg.as_str()];
        let real = match what {
            Swapped::Output => out.clone(),
            Swapped::Team => robot.parent().unwrap().to_path_buf(),
            Swapped::Robot => robot.clone(),
            Swapped::Backup => {
                // An edited generated file, which the forced build backs up.
                std::fs::write(robot.join("main.c"), format!("mine {round}")).unwrap();
                std::fs::create_dir_all(out.join(".semo-backup")).unwrap();
                args.push("--force");
                out.join(".semo-backup")
            }
        };
        let stop = Arc::new(AtomicBool::new(false));
        let (code, report, swaps) = match what {
            Swapped::Output => {
                // Started once the build has opened the output folder
                // (its first step), then racing the rest of it.
                let mut handle = None;
                let (code, report) = build_paused(&args, 1, &pauses, || {
                    handle = Some(swapper(real.clone(), outside.clone(), stop.clone()));
                });
                stop.store(true, Ordering::SeqCst);
                (code, report, handle.unwrap().join().unwrap())
            }
            _ => {
                let handle = swapper(real.clone(), outside.clone(), stop.clone());
                let (mut child, stderr) = start_build(&missions[(round + 1) % 2], &out, &args[4..]);
                let code = child.wait().unwrap().code();
                stop.store(true, Ordering::SeqCst);
                (code, stderr.join().unwrap(), handle.join().unwrap())
            }
        };
        counts.builds += 1;
        counts.swaps += swaps;
        assert!(
            matches!(code, Some(0..=2)),
            "build {round}: {code:?}: {report}"
        );
        counts.refused += usize::from(code != Some(0));
        let written = contents(&outside);
        if !written.is_empty() {
            eprintln!("build {round}: written outside: {:?}", written.keys());
        }
        counts.outside += written.len();
        // Back to a clean output folder for the next build: what the build
        // made where a folder was for a moment, and any edit, go.
        clear_set_aside(&real);
        let _ = std::fs::remove_file(robot.join("main.c"));
        let _ = std::fs::remove_dir_all(out.join(".semo-backup"));
    }
    counts
}

fn print_swaps(what: Swapped, c: &SwapCounts) {
    eprintln!(
        "stress: {what:?} folder swapped for a link {} times during {} builds ({} stopped at a link or a conflict), {} entries written outside",
        c.swaps, c.builds, c.refused, c.outside
    );
}

#[test]
fn no_link_swapped_in_a_loop_during_builds_is_followed_out() {
    for what in [
        Swapped::Output,
        Swapped::Team,
        Swapped::Robot,
        Swapped::Backup,
    ] {
        let counts = links_swapped_during_builds(&format!("stress-links-small-{what:?}"), what, 2);
        print_swaps(what, &counts);
        assert_eq!(counts.outside, 0, "{what:?}: {counts:?}");
    }
}

#[test]
#[ignore = "stress run (a few minutes): cargo test --test generation -- --ignored stress_"]
fn stress_links_swapped_during_builds() {
    let builds = sized("SEMO_STRESS_BUILDS", 100);
    let mut outside = 0;
    for what in [
        Swapped::Output,
        Swapped::Team,
        Swapped::Robot,
        Swapped::Backup,
    ] {
        let counts = links_swapped_during_builds(&format!("stress-links-{what:?}"), what, builds);
        print_swaps(what, &counts);
        outside += counts.outside;
    }
    assert_eq!(outside, 0);
}
