//! Generation never loses a user's code and never writes where it should not
//! (issue 21), through `semo build` as a user (careless or hostile) runs it:
//! concurrent generations, a crash after any file operation, target switches,
//! links, FIFOs and devices, hostile file names, unbounded inputs.

mod support;

use std::collections::BTreeMap;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use support::{examples, repo_root, semo_in};

/// A fresh folder under cargo's scratch space for tests.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("generation")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A copy of an example's folder in `dir`; the mission's path.
fn copy_example(example: &str, mission: &str, dir: &Path) -> PathBuf {
    for entry in std::fs::read_dir(examples().join(example)).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), dir.join(entry.file_name())).unwrap();
    }
    dir.join(mission)
}

/// The follow example's scenario (a path from the repository's root, where
/// [`build`] runs): what a simulation of it is built with.
const FOLLOW_SCENARIO: &str = "tests/fixtures/cortex_m/follow.scenario.json";

fn build(mission: &Path, out: &Path, extra: &[&str]) -> support::Output {
    let (mission, out) = (mission.display().to_string(), out.display().to_string());
    let mut args = vec!["build", &mission, "-o", &out];
    args.extend(extra);
    semo_in(&repo_root(), &args)
}

/// Runs `semo ARGS` with environment variables; `None` when it was killed
/// by a signal.
fn semo_env(args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .envs(env.iter().copied())
        .env("NO_COLOR", "1")
        .output()
        .expect("semo runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// What an entry is, links and special files described, never opened.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Content {
    /// The bytes' hash (shown short when a comparison fails).
    File(u64),
    Dir,
    Link(PathBuf),
    Fifo,
}

/// Everything under `dir` (relative path → content), links not followed.
fn contents(dir: &Path) -> BTreeMap<PathBuf, Content> {
    let mut found = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let rel = path.strip_prefix(dir).unwrap().to_path_buf();
            let t = std::fs::symlink_metadata(&path).unwrap().file_type();
            let content = if t.is_symlink() {
                Content::Link(std::fs::read_link(&path).unwrap())
            } else if t.is_dir() {
                stack.push(path.clone());
                Content::Dir
            } else if t.is_fifo() {
                Content::Fifo
            } else {
                Content::File(hash(&std::fs::read(&path).unwrap()))
            };
            found.insert(rel, content);
        }
    }
    found
}

/// Hidden entries generation leaves only while it runs (or after a crash):
/// its work folder, and the folders earlier versions swapped in.
fn leftovers(out: &Path) -> Vec<PathBuf> {
    contents(out)
        .into_keys()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name == ".semo-work" || name.ends_with(".semo-new") || name.ends_with(".semo-old")
        })
        .collect()
}

/// The folders a generation writes under `out`, relative: the robot folders
/// (`<team>/<robot>`, sorted) and then the runtime's (`semo-runtime`).
fn generated_folders(out: &Path) -> Vec<PathBuf> {
    let mut folders = Vec::new();
    for team in std::fs::read_dir(out).unwrap() {
        let team = team.unwrap().path();
        let name = team.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') || name == RUNTIME || !team.is_dir() {
            continue;
        }
        for robot in std::fs::read_dir(&team).unwrap() {
            let robot = robot.unwrap().path();
            if !robot
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with('.')
            {
                folders.push(robot.strip_prefix(out).unwrap().to_path_buf());
            }
        }
    }
    folders.sort();
    if out.join(RUNTIME).is_dir() {
        folders.push(PathBuf::from(RUNTIME));
    }
    folders
}

/// The runtime's folder, beside the team folders.
const RUNTIME: &str = "semo-runtime";

fn hash(bytes: &[u8]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    bytes.hash(&mut hasher);
    hasher.finish()
}

const MY_TASK: &str = "/* my follow algorithm */\n#include \"../program.h\"\nTASK_INIT {}\nTASK_GO {}\nTASK_WRAPUP {}\n";

#[test]
fn concurrent_generations_over_edited_task_files_lose_nothing() {
    let dir = scratch("concurrent");
    let mission = copy_example("follow", "follow.mission", &dir);
    let out = dir.join("out");
    assert_eq!(build(&mission, &out, &[]).code, 0);
    let task = out.join("Team1/create1/tasks/follow.c");
    std::fs::write(&task, MY_TASK).unwrap();
    let notes = out.join("Team1/create1/NOTES.txt");
    std::fs::write(&notes, "mine").unwrap();
    let (mission_arg, out_arg) = (mission.display().to_string(), out.display().to_string());
    for trial in 0..12 {
        let at_once = if trial % 2 == 0 { 2 } else { 8 };
        let children: Vec<_> = (0..at_once)
            .map(|_| {
                Command::new(env!("CARGO_BIN_EXE_semo"))
                    .args(["build", &mission_arg, "-o", &out_arg])
                    .stdout(Stdio::piped())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for child in children {
            let done = child.wait_with_output().unwrap();
            assert!(
                done.status.success(),
                "trial {trial}: {}",
                String::from_utf8_lossy(&done.stderr)
            );
        }
        assert_eq!(
            std::fs::read_to_string(&task).unwrap(),
            MY_TASK,
            "trial {trial}"
        );
        assert_eq!(
            std::fs::read_to_string(&notes).unwrap(),
            "mine",
            "trial {trial}"
        );
        assert_eq!(leftovers(&out), Vec::<PathBuf>::new(), "trial {trial}");
    }
}

/// The entries of `all` under `folder`.
fn part(all: &BTreeMap<PathBuf, Content>, folder: &Path) -> BTreeMap<PathBuf, Content> {
    all.iter()
        .filter(|(p, _)| p.starts_with(folder))
        .map(|(p, c)| (p.clone(), c.clone()))
        .collect()
}

/// The user's entries that `kill_after_every_operation` puts in robot folders.
fn is_users(path: &Path) -> bool {
    let name = path.file_name().unwrap().to_string_lossy();
    ["NOTES.txt", "link", "fifo"].contains(&name.as_ref())
}

/// Kills `semo build` right after its 1st, 2nd, ... file operation until a
/// run completes. After each kill every file of a robot folder is its old or
/// its new version (a generated one may be missing, set aside in the work
/// folder between two renames) and the user's entries are all there; a run
/// that only recovers (killed as it begins generating) reports what it did
/// and leaves each robot folder the old or the new one whole; the next run
/// ends as a clean run.
fn kill_after_every_operation(name: &str, env: &[(&str, &str)]) -> u64 {
    let dir = scratch(name);
    let mission = copy_example("scouting", "scouting.mission", &dir);
    let before = dir.join("before");
    assert_eq!(build(&mission, &before, &[]).code, 0);
    // The user's work in every robot folder, and in one a FIFO and a link.
    let folders = generated_folders(&before);
    for folder in &folders {
        std::fs::write(before.join(folder).join("NOTES.txt"), "mine").unwrap();
    }
    let first = before.join(&folders[0]);
    std::os::unix::fs::symlink("/nonexistent/elsewhere", first.join("link")).unwrap();
    let status = Command::new("mkfifo")
        .arg(first.join("fifo"))
        .status()
        .unwrap();
    assert!(status.success());
    // The new generation differs in every robot folder: each generated
    // file's header names the mission's file.
    let renamed = dir.join("renamed.mission");
    std::fs::rename(&mission, &renamed).unwrap();
    let mission = renamed;
    let after = dir.join("after");
    copy_tree(&before, &after);
    assert_eq!(build(&mission, &after, &[]).code, 0);
    let (old, new) = (contents(&before), contents(&after));
    // The runtime does not name the mission: the same.
    for folder in folders.iter().filter(|f| *f != Path::new(RUNTIME)) {
        assert_ne!(part(&old, folder), part(&new, folder), "{folder:?} changes");
    }
    let (mission_arg, out) = (mission.display().to_string(), dir.join("out"));
    let out_arg = out.display().to_string();
    let args = ["build", mission_arg.as_str(), "-o", out_arg.as_str()];
    // The operations of a run; a kill right after a check (a read) is one
    // right after the operation before it, so those are not repeated.
    copy_tree(&before, &out);
    let log = dir.join("ops.log");
    let steps = logged_operations(&args, env, &log);
    assert_eq!(contents(&out), new, "a run that was not killed");
    for (n, kind) in (1..).zip(&steps) {
        if kind == "check" {
            continue;
        }
        let _ = std::fs::remove_dir_all(&out);
        copy_tree(&before, &out);
        let fault = n.to_string();
        let mut with_fault = env.to_vec();
        with_fault.push(("SEMO_FAULT_AFTER_FS_OPS", &fault));
        let (code, _, stderr) = semo_env(&args, &with_fault);
        assert_eq!(code, None, "killed after operation {n}: {stderr}");
        let now = contents(&out);
        for folder in &folders {
            let (mine, was, will) = (part(&now, folder), part(&old, folder), part(&new, folder));
            for (path, content) in &mine {
                assert!(
                    was.get(path) == Some(content) || will.get(path) == Some(content),
                    "killed after operation {n}: {path:?} is neither its old nor its new version"
                );
            }
            for path in was.keys().chain(will.keys()) {
                assert!(
                    mine.contains_key(path) || !is_users(path),
                    "killed after operation {n}: {path:?} is missing"
                );
            }
        }
        let had_leftovers = !leftovers(&out).is_empty();
        let mut recovering = env.to_vec();
        recovering.push(("SEMO_FAULT_AFTER_RECOVERY", "1"));
        let (code, stdout, stderr) = semo_env(&args, &recovering);
        assert_eq!(code, None, "the recovery after operation {n}: {stderr}");
        assert_eq!(
            stdout.contains("recovered: "),
            had_leftovers,
            "after operation {n}: {stdout}"
        );
        assert_eq!(
            leftovers(&out),
            Vec::<PathBuf>::new(),
            "after operation {n}"
        );
        let recovered = contents(&out);
        for folder in &folders {
            let mine = part(&recovered, folder);
            assert!(
                mine == part(&old, folder) || mine == part(&new, folder),
                "recovered after operation {n}: {folder:?} is neither the old nor the new folder"
            );
        }
        let (code, _, stderr) = semo_env(&args, env);
        assert_eq!(code, Some(0), "the run after operation {n}: {stderr}");
        let mut finished = contents(&out);
        // Backups and the lock are not robot folders.
        finished.retain(|p, _| !p.starts_with(".semo-backup"));
        assert_eq!(finished, new, "the run after operation {n}");
    }
    steps.len() as u64
}

/// The kinds of the file operations `semo ARGS` does, in order
/// (`SEMO_FS_OPS_LOG`).
fn logged_operations(args: &[&str], env: &[(&str, &str)], log: &Path) -> Vec<String> {
    let _ = std::fs::remove_file(log);
    let log_arg = log.display().to_string();
    let mut logged = env.to_vec();
    logged.push(("SEMO_FS_OPS_LOG", &log_arg));
    let (code, _, stderr) = semo_env(args, &logged);
    assert_eq!(code, Some(0), "{stderr}");
    let text = std::fs::read_to_string(log).unwrap_or_default();
    text.lines()
        .map(|line| line.split_once(' ').unwrap().1.to_string())
        .collect()
}

fn copy_tree(from: &Path, to: &Path) {
    let status = Command::new("cp")
        .args(["-a"])
        .arg(from)
        .arg(to)
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn a_kill_after_any_file_operation_leaves_old_or_new_and_the_next_run_recovers() {
    let operations = kill_after_every_operation("kill-no-replace", &[]);
    assert!(operations > 30, "{operations} operations");
}

#[test]
fn without_rename_noreplace_the_link_and_unlink_fallback_recovers_too() {
    let operations =
        kill_after_every_operation("kill-fallback", &[("SEMO_NO_RENAME_NOREPLACE", "1")]);
    assert!(operations > 30, "{operations} operations");
}

#[test]
fn switching_target_keeps_edited_task_files() {
    let dir = scratch("switch");
    let mission = copy_example("follow", "follow.mission", &dir);
    let out = dir.join("out");
    let folder = out.join("Team1/create1");
    assert_eq!(build(&mission, &out, &["--target", "linux"]).code, 0);
    let task = folder.join("tasks/follow.c");
    std::fs::write(&task, MY_TASK).unwrap();
    let before = contents(&out);
    // Refused, naming the file and the flag; nothing written.
    let refused = build(
        &mission,
        &out,
        &["--target", "linux-sim", "--scenario", FOLLOW_SCENARIO],
    );
    assert_eq!(refused.code, 1, "{}", refused.stdout);
    assert!(
        refused.stderr.contains("tasks/follow.c"),
        "{}",
        refused.stderr
    );
    assert!(
        refused.stderr.contains("target linux-sim generates it"),
        "{}",
        refused.stderr
    );
    assert!(refused.stderr.contains("--force"), "{}", refused.stderr);
    assert_eq!(contents(&out), before);
    // Forced: the edit is saved first, under a dated backup folder.
    let forced = build(
        &mission,
        &out,
        &[
            "--target",
            "linux-sim",
            "--scenario",
            FOLLOW_SCENARIO,
            "--force",
        ],
    );
    assert_eq!(forced.code, 0, "{}", forced.stderr);
    let saved: Vec<_> = contents(&out.join(".semo-backup"))
        .into_iter()
        .filter(|(p, _)| p.ends_with("Team1/create1/tasks/follow.c"))
        .collect();
    assert_eq!(saved.len(), 1, "{saved:?}");
    assert_eq!(saved[0].1, Content::File(hash(MY_TASK.as_bytes())));
    let stamp = saved[0].0.components().next().unwrap();
    assert!(
        stamp.as_os_str().to_string_lossy().starts_with("20"),
        "{stamp:?}"
    );
    assert!(
        forced.stdout.contains("saved the file in the way"),
        "{}",
        forced.stdout
    );
    assert_ne!(std::fs::read_to_string(&task).unwrap(), MY_TASK);
    // Back to linux: the simulated task file, unchanged, becomes the template again.
    assert_eq!(build(&mission, &out, &["--target", "linux"]).code, 0);
    let fresh = dir.join("fresh");
    assert_eq!(build(&mission, &fresh, &["--target", "linux"]).code, 0);
    assert_eq!(
        std::fs::read_to_string(&task).unwrap(),
        std::fs::read_to_string(fresh.join("Team1/create1/tasks/follow.c")).unwrap()
    );
    // A generated file edited by hand stops generation too.
    std::fs::write(folder.join("main.c"), "my change").unwrap();
    let refused = build(&mission, &out, &[]);
    assert_eq!(refused.code, 1);
    assert!(
        refused
            .stderr
            .contains("main.c: was edited since semo generated it"),
        "{}",
        refused.stderr
    );
    assert_eq!(
        std::fs::read_to_string(folder.join("main.c")).unwrap(),
        "my change"
    );
}

/// The SHA-256 of a file, in hex, as the manifest records it.
fn sha256_of(path: &Path) -> String {
    let out = Command::new("sha256sum").arg(path).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    text.split(' ').next().unwrap().to_string()
}

/// Robot folders an earlier version generated held copies of the runtime,
/// which would shadow the shared one: a build removes the copies unchanged
/// since, and one the user edited stops it (forced: saved under the backup
/// folder).
#[test]
fn runtime_copies_an_earlier_version_left_in_a_robot_folder_go() {
    let dir = scratch("retired");
    let mission = copy_example("follow", "follow.mission", &dir);
    let out = dir.join("out");
    assert_eq!(
        build(
            &mission,
            &out,
            &["--target", "linux-sim", "--scenario", FOLLOW_SCENARIO]
        )
        .code,
        0
    );
    let folder = out.join("Team1/create1");
    // What an earlier version left: the runtime's files in the robot
    // folder, recorded as generated.
    let mut manifest = std::fs::read_to_string(folder.join(".semo-manifest")).unwrap();
    for name in ["semo_runtime.h", "semo_core.c", "semo_udp.c"] {
        let copy = folder.join(name);
        std::fs::copy(out.join("semo-runtime").join(name), &copy).unwrap();
        manifest.push_str(&format!("generated {} {name}\n", sha256_of(&copy)));
    }
    std::fs::write(folder.join(".semo-manifest"), manifest).unwrap();
    let edited = folder.join("semo_udp.c");
    std::fs::write(&edited, "/* my fix */\n").unwrap();
    let before = contents(&out);
    let refused = build(
        &mission,
        &out,
        &["--target", "linux-sim", "--scenario", FOLLOW_SCENARIO],
    );
    assert_eq!(refused.code, 1, "{}", refused.stdout);
    assert!(
        refused.stderr.contains(
            "semo_udp.c: was edited since semo generated it; the runtime is no longer copied"
        ),
        "{}",
        refused.stderr
    );
    assert!(
        !refused.stderr.contains("semo_core.c"),
        "{}",
        refused.stderr
    );
    assert_eq!(contents(&out), before);
    let forced = build(
        &mission,
        &out,
        &[
            "--target",
            "linux-sim",
            "--scenario",
            FOLLOW_SCENARIO,
            "--force",
        ],
    );
    assert_eq!(forced.code, 0, "{}", forced.stderr);
    for name in ["semo_runtime.h", "semo_core.c", "semo_udp.c"] {
        assert!(!folder.join(name).exists(), "{name}");
    }
    let manifest = std::fs::read_to_string(folder.join(".semo-manifest")).unwrap();
    for name in [" semo_runtime.h", " semo_core.c", " semo_udp.c"] {
        assert!(!manifest.contains(name), "{manifest}");
    }
    let saved: Vec<_> = contents(&out.join(".semo-backup"))
        .into_iter()
        .filter(|(p, _)| p.ends_with("Team1/create1/semo_udp.c"))
        .collect();
    assert_eq!(saved.len(), 1, "{saved:?}");
    assert_eq!(saved[0].1, Content::File(hash(b"/* my fix */\n")));
}

#[test]
fn links_fifos_and_folders_in_the_way_are_refused_or_left_alone() {
    let dir = scratch("links");
    let mission = copy_example("follow", "follow.mission", &dir);
    let elsewhere = dir.join("elsewhere");
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::fs::write(elsewhere.join("victim"), "precious").unwrap();
    // A team folder that is a link out of the output folder.
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("Team1")).unwrap();
    let refused = build(&mission, &out, &[]);
    assert_eq!(refused.code, 2);
    assert!(
        refused.stderr.contains("is a symbolic link"),
        "{}",
        refused.stderr
    );
    assert_eq!(
        contents(&elsewhere).len(),
        1,
        "nothing written through the link"
    );
    std::fs::remove_file(out.join("Team1")).unwrap();
    assert_eq!(build(&mission, &out, &[]).code, 0);
    let folder = out.join("Team1/create1");
    // A generated file replaced by a link to a file outside: refused.
    std::fs::remove_file(folder.join("main.c")).unwrap();
    std::os::unix::fs::symlink(elsewhere.join("victim"), folder.join("main.c")).unwrap();
    let refused = build(&mission, &out, &[]);
    assert_eq!(refused.code, 1);
    assert!(
        refused.stderr.contains("main.c: is a symbolic link"),
        "{}",
        refused.stderr
    );
    // Forced: the link itself is saved and replaced; the file outside is untouched.
    assert_eq!(build(&mission, &out, &["--force"]).code, 0);
    assert_eq!(
        std::fs::read_to_string(elsewhere.join("victim")).unwrap(),
        "precious"
    );
    assert!(
        !std::fs::symlink_metadata(folder.join("main.c"))
            .unwrap()
            .is_symlink()
    );
    // A FIFO: left alone and reported, never opened (a run that opened it would hang).
    let fifo = folder.join("my.fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let again = build(&mission, &out, &[]);
    assert_eq!(again.code, 0, "{}", again.stderr);
    assert!(again.stdout.contains("left alone"), "{}", again.stdout);
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    // A FIFO where a generated file goes: refused, not opened.
    std::fs::remove_file(folder.join("Makefile")).unwrap();
    assert!(
        Command::new("mkfifo")
            .arg(folder.join("Makefile"))
            .status()
            .unwrap()
            .success()
    );
    let refused = build(&mission, &out, &[]);
    assert_eq!(refused.code, 1);
    assert!(
        refused
            .stderr
            .contains("Makefile: is a FIFO, socket or device"),
        "{}",
        refused.stderr
    );
}

#[test]
fn unbounded_inputs_are_refused_with_clear_messages() {
    let dir = scratch("inputs");
    // A mission that is a FIFO: refused without waiting for a writer.
    let fifo = dir.join("stuck.mission");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let fifo_arg = fifo.display().to_string();
    let checked = semo_in(&dir, &["check", &fifo_arg]);
    assert_eq!(checked.code, 2);
    assert!(
        checked.stderr.contains("is a FIFO, not a regular file"),
        "{}",
        checked.stderr
    );
    std::fs::remove_file(&fifo).unwrap();
    // A mission over the size limit.
    let big = dir.join("big.mission");
    std::fs::write(&big, vec![b' '; 16 * 1024 * 1024 + 1]).unwrap();
    let big_arg = big.display().to_string();
    let checked = semo_in(&dir, &["check", &big_arg]);
    assert_eq!(checked.code, 2);
    assert!(
        checked.stderr.contains("more than the 16777216 bytes"),
        "{}",
        checked.stderr
    );
    std::fs::remove_file(&big).unwrap();
    // A sub-graph reference to /dev/zero: a positioned diagnostic.
    let graph = dir.join("g.taskgraph.xml");
    std::fs::write(
        &graph,
        "<TaskGraph name=\"g\" xmlns=\"urn:semo:taskgraph:1\">\n  <Task name=\"t\" subgraph=\"/dev/zero\"/>\n</TaskGraph>\n",
    )
    .unwrap();
    let graph_arg = graph.display().to_string();
    let checked = semo_in(&dir, &["check", &graph_arg]);
    assert_eq!(checked.code, 1, "{}{}", checked.stderr, checked.stderr);
    assert!(checked.stderr.contains("E067"), "{}", checked.stderr);
    assert!(
        checked.stderr.contains("is a device, not a regular file"),
        "{}",
        checked.stderr
    );
    assert!(
        checked.stderr.contains("g.taskgraph.xml:2:"),
        "{}",
        checked.stderr
    );
    std::fs::remove_file(&graph).unwrap();
    // Folders holding links to themselves and to their parent: the walk ends.
    let mission = copy_example("follow", "follow.mission", &dir);
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::os::unix::fs::symlink(&dir, dir.join("sub/up")).unwrap();
    std::os::unix::fs::symlink(".", dir.join("self")).unwrap();
    let dir_arg = dir.display().to_string();
    let checked = semo_in(&dir, &["check", &dir_arg]);
    assert_eq!(checked.code, 0, "{}{}", checked.stderr, checked.stderr);
    assert_eq!(build(&mission, &dir.join("out"), &[]).code, 0);
}

/// C code with the contents of its string literals removed (a name in a
/// string, escaped, is data; outside one it would be code).
fn without_string_literals(code: &str) -> String {
    let mut out = String::new();
    let (mut in_string, mut escaped) = (false, false);
    for c in code.chars() {
        match (in_string, escaped, c) {
            (true, true, _) => escaped = false,
            (true, false, '\\') => escaped = true,
            (true, false, '"') => {
                in_string = false;
                out.push(c);
            }
            (true, false, _) => {}
            (false, _, '"') => {
                in_string = true;
                out.push(c);
            }
            (false, _, _) => out.push(c),
        }
    }
    out
}

#[test]
fn hostile_file_names_are_escaped_in_every_generated_language() {
    let names = [
        "x*\\ int injected = 42; \\*.mission",
        "a-->b--->c.mission",
        "$(shell touch pwned) ${HOME} `id` \"q\" 'q' \\.mission",
        "new\nline ??= \\\n int injected;.mission",
    ];
    for (i, name) in names.iter().enumerate() {
        let dir = scratch(&format!("hostile-{i}"));
        let original = copy_example("follow", "follow.mission", &dir);
        let mission = dir.join(name);
        std::fs::rename(&original, &mission).unwrap();
        let out = dir.join("out");
        let built = build(&mission, &out, &[]);
        assert_eq!(built.code, 0, "{name}: {}", built.stderr);
        let folder = out.join("Team1/create1");
        // C: with comments removed, nothing of the name is left in any file.
        for file in ["main.c", "control_task.c", "program.h", "tasks/follow.c"] {
            let stripped = Command::new("gcc")
                .args(["-fpreprocessed", "-dD", "-E", "-P", "-x", "c"])
                .arg(folder.join(file))
                .output()
                .unwrap();
            assert!(stripped.status.success(), "{name}: {file}");
            let code = without_string_literals(&String::from_utf8_lossy(&stripped.stdout));
            assert!(!code.contains("injected"), "{name}: {file}: {code}");
            assert!(!code.contains("pwned"), "{name}: {file}");
        }
        // XML: the task graph still reads as one.
        let graph = folder.join("taskgraph.xml").display().to_string();
        let checked = semo_in(&dir, &["check", &graph]);
        assert_eq!(
            checked.code, 0,
            "{name}: {}{}",
            checked.stdout, checked.stderr
        );
        // Makefile: make runs it and nothing in the name is executed.
        let made = Command::new("make")
            .args(["-s", "-n"])
            .current_dir(&folder)
            .output()
            .unwrap();
        assert!(
            made.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&made.stderr)
        );
        assert!(
            !folder.join("pwned").exists() && !dir.join("pwned").exists(),
            "{name}"
        );
        // The manifest names only generation's own files.
        let manifest = std::fs::read_to_string(folder.join(".semo-manifest")).unwrap();
        assert!(
            manifest.starts_with("semo-manifest 1 target linux\n"),
            "{manifest}"
        );
        assert!(
            !manifest.contains("injected") && !manifest.contains("pwned"),
            "{manifest}"
        );
    }
}

#[test]
fn a_nonsense_time_scale_is_refused_and_the_bounds_run_clean_under_ubsan() {
    let dir = scratch("time-scale");
    let mission = copy_example("follow", "follow.mission", &dir);
    let out = dir.join("out");
    let scenario = dir.join("s.json");
    let build_on = |text: &str| {
        std::fs::write(&scenario, text).unwrap();
        let scenario = scenario.display().to_string();
        build(
            &mission,
            &out,
            &["--target", "linux-sim", "--scenario", &scenario],
        )
    };
    // A scenario's time scale out of the runtime's range is refused by the
    // build that would compile it in.
    for scale in ["1e-18", "0", "-1", "1e300", "nan"] {
        let built = build_on(&format!("{{\"time_scale\": {scale}}}"));
        assert_eq!(built.code, 2, "{scale}: {}", built.stderr);
        if scale != "nan" {
            // `nan` is not JSON: refused by the reader before the range.
            assert!(
                built
                    .stderr
                    .contains("\"time_scale\" must be a positive number from"),
                "{scale}: {}",
                built.stderr
            );
        }
    }
    // The fastest scale allowed runs a second of mission time and stops.
    let built = build_on("{\"time_scale\": 0.000001, \"duration\": 1000}");
    assert_eq!(built.code, 0, "{}", built.stderr);
    let folder = out.join("Team1/create1");
    let ubsan = "-std=c11 -O1 -g -fsanitize=undefined -fno-sanitize-recover=all";
    let made = Command::new("make")
        .args([
            "-s",
            &format!("CFLAGS={ubsan}"),
            "LDFLAGS=-fsanitize=undefined",
        ])
        .current_dir(&folder)
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let run = |args: &[&str]| {
        let done = Command::new(folder.join("create1"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&done.stderr).into_owned();
        assert!(!stderr.contains("runtime error"), "UBSan: {stderr}");
        (done.status.code(), stderr)
    };
    for scale in ["1e-18", "0", "-1", "1e300", "nan"] {
        let (code, stderr) = run(&["--time-scale", scale, "--duration", "10"]);
        assert_eq!(code, Some(2), "{scale}: {stderr}");
        assert!(
            stderr.contains("--time-scale must be a positive number from"),
            "{scale}: {stderr}"
        );
    }
    let (code, stderr) = run(&["--trace", "trace.jsonl"]);
    assert_eq!(code, Some(0), "{stderr}");
}

#[test]
fn junk_gets_a_bounded_number_of_diagnostics() {
    let dir = scratch("junk");
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let junk: Vec<u8> = (0..1 << 20)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 24) as u8
        })
        .collect();
    std::fs::write(dir.join("junk.mission"), &junk).unwrap();
    std::fs::write(dir.join("nul.mission"), vec![0u8; 200_000]).unwrap();
    for name in ["junk.mission", "nul.mission"] {
        let (code, diags) = support::check_json_in(&dir, &[name]);
        assert_eq!(code, 1, "{name}");
        // Syntax problems (E001–E004), not counting the per-file cap's E004.
        let syntax = diags
            .iter()
            .filter(|d| d.code.starts_with("E00") && !d.message.contains("in this file"))
            .count();
        assert!(syntax <= 101, "{name}: {syntax} syntax diagnostics");
        // Every stream together is capped per file, with one E004 at the end.
        assert!(
            diags.len() <= semo::diag::MAX_PER_FILE + 1,
            "{name}: {} diagnostics",
            diags.len()
        );
    }
    let (_, diags) = support::check_json_in(&dir, &["junk.mission"]);
    assert!(
        diags.iter().any(|d| d.code == "E004"),
        "{}",
        support::listing(&diags)
    );
    // A run of unknown characters is one diagnostic.
    let (_, diags) = support::check_json_in(&dir, &["nul.mission"]);
    assert_eq!(diags.iter().filter(|d| d.code == "E001").count(), 1);
}

/// How many `write` calls `semo ARGS` makes in `dir` (all its threads),
/// counted by strace; `None` where strace is not installed.
fn writes_of(dir: &Path, args: &[&str]) -> Option<u64> {
    let counts = dir.join("strace.txt");
    let semo = env!("CARGO_BIN_EXE_semo");
    let out = Command::new("strace")
        .args(["-f", "-c", "-e", "trace=write", "-o"])
        .arg(&counts)
        .arg(semo)
        .args(args)
        .current_dir(dir)
        .output()
        .ok()?;
    assert!(out.status.code().is_some(), "{out:?}");
    let table = std::fs::read_to_string(&counts).unwrap();
    // `% time  seconds  usecs/call  calls  [errors]  syscall`
    let row = table
        .lines()
        .find(|l| l.split_whitespace().last() == Some("write"))
        .unwrap_or_else(|| panic!("no write row in:\n{table}"));
    let calls = row.split_whitespace().nth(3).unwrap();
    Some(calls.parse().unwrap())
}

/// A line of 400,000 NULs is shown for people in a few writes per
/// diagnostic: each report goes to the unbuffered standard error at once
/// (ariadne's pieces once made 650,000 writes of it).
#[test]
fn junk_is_shown_for_people_in_a_few_writes() {
    let dir = scratch("junk-writes");
    std::fs::write(dir.join("nul.mission"), vec![0u8; 400_000]).unwrap();
    let (_, diags) = support::check_json_in(&dir, &["nul.mission"]);
    let Some(writes) = writes_of(&dir, &["check", "--color", "never", "nul.mission"]) else {
        eprintln!(
            "note: strace is not installed here; the writes were not counted (CI installs it)"
        );
        return;
    };
    // One per report, the summary line and a few of the process's own,
    // and as many more as a pipe takes a long report in (64 KiB at a time
    // on Linux; 4 KiB allowed).
    let shown = semo_in(&dir, &["check", "--color", "never", "nul.mission"]);
    let bound = diags.len() as u64 + shown.stderr.len() as u64 / 4096 + 8;
    assert!(
        writes <= bound,
        "{writes} writes for {} diagnostics in {} bytes",
        diags.len(),
        shown.stderr.len()
    );
}

/// `semo build ARGS` paused after its `step`th file operation
/// (`SEMO_PAUSE_AFTER_FS_OPS`, through a connection to `pauses`): `during`
/// runs while it waits, then it goes on. Its exit code and standard error.
fn build_paused(
    args: &[&str],
    step: u64,
    pauses: &Pauses,
    during: impl FnOnce(),
) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .env("SEMO_PAUSE_AFTER_FS_OPS", step.to_string())
        .env("SEMO_PAUSE_SOCKET", &pauses.path)
        .env("NO_COLOR", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (paused, line) = pauses.next(&mut child);
    assert!(line.starts_with(&format!("paused {step} ")), "{line}");
    during();
    // Closing the connection lets the generation go on.
    drop(paused);
    let done = child.wait_with_output().unwrap();
    (
        done.status.code(),
        String::from_utf8_lossy(&done.stderr).into_owned(),
    )
}

/// The Unix socket paused generations connect to (`SEMO_PAUSE_SOCKET`).
struct Pauses {
    path: PathBuf,
    listener: std::os::unix::net::UnixListener,
}

impl Pauses {
    fn at(path: PathBuf) -> Pauses {
        let _ = std::fs::remove_file(&path);
        let listener = std::os::unix::net::UnixListener::bind(&path).unwrap();
        // Accepting never blocks: a generation that ends without pausing is seen.
        listener.set_nonblocking(true).unwrap();
        Pauses { path, listener }
    }

    /// The connection of `child`'s pause and the line it wrote (it then
    /// waits for the connection to close).
    fn next(&self, child: &mut std::process::Child) -> (std::os::unix::net::UnixStream, String) {
        use std::io::BufRead;
        loop {
            match self.listener.accept() {
                Ok((stream, _)) => {
                    stream.set_nonblocking(false).unwrap();
                    let mut line = String::new();
                    std::io::BufReader::new(&stream)
                        .read_line(&mut line)
                        .unwrap();
                    return (stream, line);
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(e) => panic!("{e}"),
            }
            if let Some(status) = child.try_wait().unwrap() {
                panic!("the generation ended ({status}) before it paused");
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
}

/// How many file operations (`SEMO_FS_OPS_LOG`) of each kind `semo ARGS` does.
fn operations(args: &[&str], log: &Path) -> BTreeMap<String, usize> {
    let mut kinds = BTreeMap::new();
    for kind in logged_operations(args, &[], log) {
        *kinds.entry(kind).or_insert(0) += 1;
    }
    kinds
}

/// Saves `text` as editors that write a new file and rename it over the old do.
fn rename_save(path: &Path, text: &str) {
    let temp = path.with_file_name(".editor-save.tmp");
    std::fs::write(&temp, text).unwrap();
    std::fs::rename(&temp, path).unwrap();
}

/// A previous generation of `follow` in `<dir>/before`, and the arguments of
/// a new one (its mission renamed, so every generated file changes) into
/// `<dir>/out`.
fn follow_regenerated(dir: &Path) -> (PathBuf, Vec<String>) {
    let mission = copy_example("follow", "follow.mission", dir);
    let before = dir.join("before");
    assert_eq!(build(&mission, &before, &[]).code, 0);
    let renamed = dir.join("renamed.mission");
    std::fs::rename(&mission, &renamed).unwrap();
    let out = dir.join("out");
    let args = vec![
        "build".to_string(),
        renamed.display().to_string(),
        "-o".to_string(),
        out.display().to_string(),
    ];
    (before, args)
}

#[test]
fn what_the_user_saves_during_a_generation_stays_at_every_step() {
    let dir = scratch("during");
    let (before, args) = follow_regenerated(&dir);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = dir.join("out");
    copy_tree(&before, &out);
    let steps: usize = operations(&args, &dir.join("ops.log")).values().sum();
    assert!(steps > 10, "{steps} operations");
    let pauses = Pauses::at(dir.join("pause"));
    let folder = out.join("Team1/create1");
    for step in 1..=steps as u64 {
        let _ = std::fs::remove_dir_all(&out);
        copy_tree(&before, &out);
        let made = format!("made at step {step}\n");
        let task = format!("{MY_TASK}/* saved at step {step} */\n");
        let main = format!("/* main.c edited at step {step} */\n");
        let header = format!("/* program.h edited in place at step {step} */\n");
        let (code, stderr) = build_paused(&args, step, &pauses, || {
            std::fs::write(folder.join("made-during.txt"), &made).unwrap();
            rename_save(&folder.join("tasks/follow.c"), &task);
            rename_save(&folder.join("main.c"), &main);
            std::fs::write(folder.join("program.h"), &header).unwrap();
        });
        let read = |name: &str| std::fs::read_to_string(folder.join(name)).unwrap();
        assert_eq!(read("made-during.txt"), made, "step {step}: {stderr}");
        assert_eq!(read("tasks/follow.c"), task, "step {step}: {stderr}");
        assert_eq!(read("main.c"), main, "step {step}: {stderr}");
        assert_eq!(read("program.h"), header, "step {step}: {stderr}");
        match code {
            Some(0) => {}
            Some(1) => assert!(
                stderr.contains("changed while semo was")
                    || stderr.contains("created while semo was"),
                "step {step}: {stderr}"
            ),
            other => panic!("step {step}: {other:?}: {stderr}"),
        }
        assert_eq!(leftovers(&out), Vec::<PathBuf>::new(), "step {step}");
    }
}

#[test]
fn no_link_swapped_in_during_a_generation_is_followed_out_of_the_output_folder() {
    let dir = scratch("swapped");
    let (before, args) = follow_regenerated(&dir);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = dir.join("out");
    copy_tree(&before, &out);
    let steps: usize = operations(&args, &dir.join("ops.log")).values().sum();
    let pauses = Pauses::at(dir.join("pause"));
    let outside = dir.join("outside");
    for step in 1..=steps as u64 {
        for swap_output_folder in [false, true] {
            let _ = std::fs::remove_dir_all(&out);
            let _ = std::fs::remove_dir_all(dir.join("moved"));
            let _ = std::fs::remove_dir_all(&outside);
            std::fs::create_dir_all(outside.join("create1")).unwrap();
            copy_tree(&before, &out);
            let (code, stderr) = build_paused(&args, step, &pauses, || {
                if swap_output_folder {
                    std::fs::rename(&out, dir.join("moved")).unwrap();
                    std::os::unix::fs::symlink(&outside, &out).unwrap();
                } else {
                    let robot = out.join("Team1/create1");
                    std::fs::rename(&robot, out.join("Team1/moved")).unwrap();
                    std::os::unix::fs::symlink(outside.join("create1"), &robot).unwrap();
                }
            });
            assert!(
                matches!(code, Some(0..=2)),
                "step {step}: {code:?}: {stderr}"
            );
            assert_eq!(
                contents(&outside).into_keys().collect::<Vec<_>>(),
                vec![PathBuf::from("create1")],
                "step {step} (output folder swapped: {swap_output_folder}): written through the link: {stderr}"
            );
        }
    }
}

#[test]
fn a_backup_folder_that_is_a_link_is_refused_and_a_linked_output_folder_works() {
    let dir = scratch("backup-link");
    let mission = copy_example("follow", "follow.mission", &dir);
    let outside = dir.join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let out = dir.join("out");
    assert_eq!(build(&mission, &out, &[]).code, 0);
    let main = out.join("Team1/create1/main.c");
    std::fs::write(&main, "my change").unwrap();
    std::os::unix::fs::symlink(&outside, out.join(".semo-backup")).unwrap();
    let forced = build(&mission, &out, &["--force"]);
    assert_eq!(forced.code, 2, "{}", forced.stderr);
    assert!(forced.stderr.contains(".semo-backup"), "{}", forced.stderr);
    assert!(
        forced.stderr.contains("is a symbolic link"),
        "{}",
        forced.stderr
    );
    assert_eq!(
        contents(&outside).len(),
        0,
        "nothing written through the link"
    );
    assert_eq!(std::fs::read_to_string(&main).unwrap(), "my change");
    assert_eq!(leftovers(&out), Vec::<PathBuf>::new());
    // An output folder given as a link is the folder it leads to, from the
    // first run on, backups included.
    let real = dir.join("real");
    std::fs::create_dir_all(&real).unwrap();
    let linked = dir.join("linked-out");
    std::os::unix::fs::symlink(&real, &linked).unwrap();
    let first = build(&mission, &linked, &[]);
    assert_eq!(first.code, 0, "{}", first.stderr);
    assert!(real.join("Team1/create1/main.c").is_file());
    std::fs::write(real.join("Team1/create1/main.c"), "mine").unwrap();
    let forced = build(&mission, &linked, &["--force"]);
    assert_eq!(forced.code, 0, "{}", forced.stderr);
    let saved: Vec<_> = contents(&real.join(".semo-backup"))
        .into_iter()
        .filter(|(p, _)| p.ends_with("Team1/create1/main.c"))
        .collect();
    assert_eq!(saved.len(), 1, "{saved:?}");
    assert!(std::fs::symlink_metadata(&linked).unwrap().is_symlink());
}

#[test]
fn a_build_syncs_twice_whatever_the_number_of_robots() {
    let dir = scratch("syncs");
    let text = std::fs::read_to_string(examples().join("swarm/march.mission")).unwrap();
    assert!(text.contains("quad[5]"));
    let log = dir.join("ops.log");
    let mut syncs = Vec::new();
    for robots in [1, 12] {
        let mission = dir.join(format!("march{robots}.mission"));
        std::fs::write(
            &mission,
            text.replace("quad[5]", &format!("quad[{robots}]")),
        )
        .unwrap();
        let (mission, out) = (
            mission.display().to_string(),
            dir.join(format!("out{robots}")),
        );
        let out = out.display().to_string();
        let fresh = operations(&["build", &mission, "-o", &out], &log);
        assert!(fresh["write"] > 5 * robots, "{fresh:?}");
        syncs.push(fresh["sync"]);
        // Nothing changed: nothing written, nothing synced.
        let again = operations(&["build", &mission, "-o", &out], &log);
        assert_eq!(again, BTreeMap::new(), "{robots} robot(s)");
    }
    assert_eq!(syncs, [2, 2]);
}

/// The stress runs of issue 33 (counts of what was lost or written outside).
#[path = "generation/stress.rs"]
mod stress;
