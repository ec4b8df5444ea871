//! Compiling many generated robot folders quickly and strictly: the runtime
//! (the output folder's `semo-runtime`) once per compiler and target, each
//! robot's own files at `-O0` linked against it, on a pool bounded by the
//! machine's cores. Every warning is a failure (`PEDANTIC`).

use super::robots::{PEDANTIC, compilers, robot_folders};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// What a robot folder's Makefile says it is built from.
struct Sources {
    /// Generated files (`main.c`, ...) and task files, each with the extra
    /// flags it is compiled with.
    own: Vec<(String, Vec<String>)>,
    /// The runtime's sources, in `runtime_dir`.
    runtime: Vec<String>,
    runtime_dir: PathBuf,
    flags: Vec<String>,
}

fn makefile_sources(folder: &Path) -> Sources {
    let makefile = std::fs::read_to_string(folder.join("Makefile")).unwrap();
    let line = |key: &str| -> Vec<String> {
        makefile
            .lines()
            .find_map(|l| l.strip_prefix(key))
            .unwrap_or("")
            .split_whitespace()
            .map(str::to_string)
            .collect()
    };
    // `RUNTIME ?= ../../semo-runtime`, relative to the robot folder.
    let runtime_dir = folder.join(line("RUNTIME ?= ").concat());
    let mut own: Vec<(String, Vec<String>)> = line("SOURCES = ")
        .into_iter()
        .map(|s| (s, Vec::new()))
        .collect();
    for task in line("TASKS = ") {
        let stem = Path::new(&task)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        own.push((task, vec![format!("-DSEMO_TASK=task_{stem}")]));
    }
    let runtime_flag = runtime_dir.display().to_string();
    Sources {
        own,
        runtime: line("RUNTIME_SOURCES = "),
        flags: line("SEMO_CFLAGS = ")
            .into_iter()
            .map(|flag| flag.replace("$(RUNTIME)", &runtime_flag))
            .collect(),
        runtime_dir,
    }
}

fn pedantic() -> Vec<String> {
    PEDANTIC.split_whitespace().map(str::to_string).collect()
}

/// Runs `cc args`; its complaints if it fails or warns.
fn cc(compiler: &str, args: &[String], dir: &Path) -> Result<(), String> {
    let out = Command::new(compiler)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the compiler runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.success() && stderr.trim().is_empty() {
        Ok(())
    } else {
        Err(format!("{compiler} {}: {stderr}", args.join(" ")))
    }
}

/// One robot folder to compile with one compiler.
struct Job<'a> {
    label: String,
    target: &'a str,
    compiler: &'static str,
    folder: PathBuf,
}

/// Compiles and links every robot folder of `outputs` (a label, the target
/// it was built for, the output folder) with every compiler; scratch files go
/// under `root`. Panics listing every failure.
pub fn compile_all<L: std::fmt::Display>(
    root: &Path,
    outputs: &[(L, &str, PathBuf)],
    targets: &[&str],
) {
    let compilers = compilers();
    // The runtime, once per compiler and target.
    let mut runtime_objects = std::collections::HashMap::new();
    for &target in targets {
        let Some(first) = outputs
            .iter()
            .filter(|(_, t, _)| *t == target)
            .flat_map(|(_, _, out)| robot_folders(out))
            .next()
        else {
            continue;
        };
        let sources = makefile_sources(&first);
        for &compiler in &compilers {
            let dir = root.join(format!("runtime-{compiler}-{target}"));
            std::fs::create_dir_all(&dir).unwrap();
            let mut objects = Vec::new();
            for file in &sources.runtime {
                let object = dir.join(file.replace(".c", ".o"));
                let mut args = pedantic();
                args.extend(sources.flags.iter().cloned());
                args.extend([
                    "-c".into(),
                    sources.runtime_dir.join(file).display().to_string(),
                    "-o".into(),
                    object.display().to_string(),
                ]);
                cc(compiler, &args, &first).unwrap_or_else(|e| panic!("the runtime: {e}"));
                objects.push(object);
            }
            runtime_objects.insert((compiler, target), objects);
        }
    }
    let mut jobs = Vec::new();
    for (label, target, out) in outputs {
        for folder in robot_folders(out) {
            for &compiler in &compilers {
                jobs.push(Job {
                    label: label.to_string(),
                    target,
                    compiler,
                    folder: folder.clone(),
                });
            }
        }
    }
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(job) = jobs.get(i) else { break };
                    let runtime = &runtime_objects[&(job.compiler, job.target)];
                    if let Err(e) = compile_robot(job, runtime) {
                        failures.lock().unwrap().push(format!(
                            "{} ({}, {}): {e}",
                            job.label, job.target, job.compiler
                        ));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} robot builds fail (scratch files under {}):\n{}",
        failures.len(),
        jobs.len(),
        root.display(),
        failures.join("\n")
    );
    eprintln!(
        "{} robot programs compiled and linked with {}",
        jobs.len() / compilers.len(),
        compilers.join(" and ")
    );
}

/// Compiles a robot's own files and links them with the runtime's objects:
/// each task file on its own (it is compiled with its task's name), then the
/// generated files and the link in one compiler run.
fn compile_robot(job: &Job<'_>, runtime: &[PathBuf]) -> Result<(), String> {
    let sources = makefile_sources(&job.folder);
    let objects_dir = job.folder.join(format!("obj-{}", job.compiler));
    std::fs::create_dir_all(objects_dir.join("tasks")).map_err(|e| e.to_string())?;
    let mut generated = Vec::new();
    let mut task_objects = Vec::new();
    for (file, extra) in &sources.own {
        if extra.is_empty() {
            generated.push(file.clone());
            continue;
        }
        let object = objects_dir.join(file.replace(".c", ".o"));
        let mut args = pedantic();
        args.extend(sources.flags.iter().cloned());
        args.extend(extra.iter().cloned());
        args.extend([
            "-c".into(),
            file.clone(),
            "-o".into(),
            object.display().to_string(),
        ]);
        cc(job.compiler, &args, &job.folder)?;
        task_objects.push(object.display().to_string());
    }
    let mut args = pedantic();
    args.extend(sources.flags.iter().cloned());
    args.extend([
        "-o".into(),
        objects_dir.join("program").display().to_string(),
    ]);
    args.extend(generated);
    args.extend(task_objects);
    args.extend(runtime.iter().map(|o| o.display().to_string()));
    args.extend(["-lpthread".into(), "-lm".into()]);
    cc(job.compiler, &args, &job.folder)?;
    // Thousands of robots: keep only what a failure needs to be looked at.
    let _ = std::fs::remove_dir_all(&objects_dir);
    Ok(())
}
