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

/// Hidden entries generation leaves only while it runs (or after a crash).
fn leftovers(out: &Path) -> Vec<PathBuf> {
    contents(out)
        .into_keys()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.ends_with(".semo-new") || name.ends_with(".semo-old")
        })
        .collect()
}

fn robot_folders(out: &Path) -> Vec<PathBuf> {
    let mut folders = Vec::new();
    for team in std::fs::read_dir(out).unwrap() {
        let team = team.unwrap().path();
        if team.file_name().unwrap().to_string_lossy().starts_with('.') || !team.is_dir() {
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
    folders
}

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

/// Kills `semo build` right after its 1st, 2nd, ... file operation until a
/// run completes; after each kill every robot folder is the old one or the
/// new one, and the next run recovers, says so, and ends as a clean run.
fn kill_after_every_operation(name: &str, env: &[(&str, &str)], with_journal: bool) -> u64 {
    let dir = scratch(name);
    let mission = copy_example("scouting", "scouting.mission", &dir);
    let before = dir.join("before");
    assert_eq!(build(&mission, &before, &[]).code, 0);
    // The user's work in every robot folder, and in one a FIFO and a link.
    for robot in robot_folders(&before) {
        std::fs::write(before.join(&robot).join("NOTES.txt"), "mine").unwrap();
    }
    let first = before.join(&robot_folders(&before)[0]);
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
    let folders = robot_folders(&before);
    let part = |all: &BTreeMap<PathBuf, Content>, folder: &Path| -> BTreeMap<PathBuf, Content> {
        all.iter()
            .filter(|(p, _)| p.starts_with(folder))
            .map(|(p, c)| (p.clone(), c.clone()))
            .collect()
    };
    for folder in &folders {
        assert_ne!(part(&old, folder), part(&new, folder), "{folder:?} changes");
    }
    let (mission_arg, out) = (mission.display().to_string(), dir.join("out"));
    let out_arg = out.display().to_string();
    let args = ["build", mission_arg.as_str(), "-o", out_arg.as_str()];
    for n in 1.. {
        let _ = std::fs::remove_dir_all(&out);
        copy_tree(&before, &out);
        let fault = n.to_string();
        let mut with_fault = env.to_vec();
        with_fault.push(("SEMO_FAULT_AFTER_FS_OPS", &fault));
        let (code, _, stderr) = semo_env(&args, &with_fault);
        if code == Some(0) {
            assert_eq!(contents(&out), new, "a run that was not killed");
            return n;
        }
        assert_eq!(code, None, "killed after operation {n}: {stderr}");
        let now = contents(&out);
        for folder in &folders {
            let mine = part(&now, folder);
            // Without an exchange, between the two renames the old folder
            // is whole under its journal name, and the next run restores it.
            let journal = {
                let name = folder.file_name().unwrap().to_string_lossy();
                let aside = folder.with_file_name(format!(".{name}.semo-old"));
                let moved: BTreeMap<PathBuf, Content> = part(&now, &aside)
                    .into_iter()
                    .map(|(p, c)| (folder.join(p.strip_prefix(&aside).unwrap()), c))
                    .collect();
                with_journal && mine.is_empty() && moved == part(&old, folder)
            };
            assert!(
                mine == part(&old, folder) || mine == part(&new, folder) || journal,
                "killed after operation {n}: {folder:?} is neither the old nor the new folder"
            );
        }
        let had_leftovers = !leftovers(&out).is_empty();
        let (code, stdout, stderr) = semo_env(&args, env);
        assert_eq!(code, Some(0), "the run after operation {n}: {stderr}");
        assert_eq!(
            stdout.contains("recovered: "),
            had_leftovers,
            "after operation {n}: {stdout}"
        );
        let mut recovered = contents(&out);
        // Backups and the lock are not robot folders.
        recovered.retain(|p, _| !p.starts_with(".semo-backup"));
        assert_eq!(recovered, new, "the run after operation {n}");
    }
    unreachable!()
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
    let operations = kill_after_every_operation("kill-exchange", &[], false);
    assert!(operations > 30, "{operations} operations");
}

#[test]
fn without_rename_exchange_the_journal_of_names_recovers_too() {
    let operations =
        kill_after_every_operation("kill-fallback", &[("SEMO_NO_RENAME_EXCHANGE", "1")], true);
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
    let refused = build(&mission, &out, &["--target", "linux-sim"]);
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
    let forced = build(&mission, &out, &["--target", "linux-sim", "--force"]);
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
    assert_eq!(build(&mission, &out, &["--target", "linux-sim"]).code, 0);
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
        std::fs::write(dir.join("s.json"), format!("{{\"time_scale\": {scale}}}")).unwrap();
        let (code, stderr) = run(&["--scenario", "s.json", "--duration", "10"]);
        if scale != "nan" {
            // `nan` is not JSON: refused by the reader before the range.
            assert!(
                stderr.contains("\"time_scale\" must be a positive number from"),
                "{scale}: {stderr}"
            );
        }
        assert_ne!(code, Some(0), "{scale}");
        let (code, stderr) = run(&["--time-scale", scale, "--duration", "10"]);
        assert_eq!(code, Some(2), "{scale}: {stderr}");
        assert!(
            stderr.contains("--time-scale must be a positive number from"),
            "{scale}: {stderr}"
        );
    }
    // The fastest scale allowed runs a second of mission time and stops.
    std::fs::write(
        dir.join("s.json"),
        "{\"time_scale\": 0.000001, \"duration\": 1000}",
    )
    .unwrap();
    let (code, stderr) = run(&["--scenario", "s.json", "--trace", "trace.jsonl"]);
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
