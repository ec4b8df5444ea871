//! The doors agree: for every example mission, `semo check FILE`, `semo check
//! DIR` (the examples folder), `semo build` and the language server's
//! published diagnostics report the same problems for the mission and the
//! catalog and strategy files it reads, because all of them ask the library's
//! one workspace analysis (`semo::host`) by its one rule.

mod support;

use semo_server::harness::TestClient;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use support::{check_json_in, examples, semo_in};

/// `(file, code, start line, start column, message)`, lines and columns from 1.
type Problem = (String, String, u64, u64, String);

fn missions(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            missions(&path, out);
        } else if path.extension().is_some_and(|e| e == "mission") {
            out.push(path);
        }
    }
}

fn absolute(file: &str, dir: &Path) -> String {
    let path = Path::new(file);
    let path = if path.is_absolute() {
        path.to_path_buf()
    } else {
        dir.join(path)
    };
    let normalized: PathBuf = path.components().collect();
    normalized.display().to_string()
}

fn from_check(dir: &Path, paths: &[&str]) -> (i32, BTreeSet<Problem>) {
    let (code, diags) = check_json_in(dir, paths);
    let problems = diags
        .into_iter()
        .map(|d| {
            (
                absolute(&d.file, dir),
                d.code,
                d.start.0,
                d.start.1,
                d.message,
            )
        })
        .collect();
    (code, problems)
}

/// The files compared for a mission: itself and the catalog and strategy
/// files under its folder (what it reads in the examples, which keep their
/// files beside their missions).
fn compared_files(mission: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    out.insert(mission.display().to_string());
    let mut stack = vec![mission.parent().unwrap().to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.to_string_lossy().into_owned();
            if path.is_dir() {
                stack.push(path);
            } else if name.ends_with(".robot.xml") || name.ends_with(".strategy.xml") {
                out.insert(name);
            }
        }
    }
    out
}

/// The diagnostics the server publishes for each file of `files`, with no
/// workspace root (each file's folder is its root) and every SeMo file of
/// the mission's folder open; each file is opened last in its own session,
/// so its first publication already sees all the others.
fn from_server(mission: &Path, files: &BTreeSet<String>) -> BTreeSet<Problem> {
    let folder = mission.parent().unwrap();
    let mut all: Vec<PathBuf> = Vec::new();
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        let name = path.to_string_lossy().into_owned();
        if name.ends_with(".mission") || name.ends_with(".strategy.xml") {
            all.push(path);
        }
    }
    for file in files {
        if !all.iter().any(|p| p.display().to_string() == *file) {
            all.push(PathBuf::from(file));
        }
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let mut problems = BTreeSet::new();
    for file in files {
        let found: Vec<Value> = runtime.block_on(async {
            let mut client = TestClient::start();
            client.initialize(&["utf-16"], None).await;
            let others = all.iter().filter(|p| p.display().to_string() != *file);
            for path in others.chain(std::iter::once(&PathBuf::from(file))) {
                let text = std::fs::read_to_string(path).unwrap();
                client
                    .open(&format!("file://{}", path.display()), &text)
                    .await;
            }
            let uri = format!("file://{file}");
            let found = client.diagnostics(&uri, Some(1)).await;
            client.shutdown().await;
            found
        });
        for d in found {
            problems.insert((
                file.clone(),
                d["code"].as_str().unwrap().to_string(),
                d["range"]["start"]["line"].as_u64().unwrap() + 1,
                d["range"]["start"]["character"].as_u64().unwrap() + 1,
                d["message"].as_str().unwrap().to_string(),
            ));
        }
    }
    problems
}

fn listing(problems: &BTreeSet<Problem>) -> String {
    problems
        .iter()
        .map(|(f, c, l, col, m)| format!("  {f}:{l}:{col} {c} {m}\n"))
        .collect()
}

#[test]
fn every_example_gets_the_same_diagnostics_at_every_door() {
    let root = examples();
    let mut all = Vec::new();
    missions(&root, &mut all);
    assert!(all.len() >= 5, "{all:?}");
    let (_, whole) = from_check(&root, &["."]);
    let out = std::env::temp_dir().join(format!("semo-doors-{}", std::process::id()));
    for mission in &all {
        let files = compared_files(mission);
        let keep = |problems: &BTreeSet<Problem>| -> BTreeSet<Problem> {
            problems
                .iter()
                .filter(|p| files.contains(&p.0))
                .cloned()
                .collect()
        };
        let name = mission.display().to_string();
        let (code, single) = from_check(&root, &[name.as_str()]);
        // `semo check FILE` reports only the mission and what it reads.
        assert_eq!(
            single,
            keep(&single),
            "{name}: check FILE reports other files"
        );
        assert_eq!(
            listing(&single),
            listing(&keep(&whole)),
            "{name}: check FILE and check DIR disagree"
        );
        assert_eq!(
            listing(&single),
            listing(&from_server(mission, &files)),
            "{name}: check FILE and the editor disagree"
        );
        let has_errors = code == 1;
        let build = semo_in(
            &root,
            &[
                "build",
                &name,
                "--emit",
                "taskgraph",
                "--out",
                &out.display().to_string(),
                "--color",
                "never",
            ],
        );
        assert_eq!(
            build.code,
            if has_errors { 1 } else { 0 },
            "{name}: check exit {code}, build said:\n{}{}",
            build.stdout,
            build.stderr
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn checking_a_mission_reads_the_catalog_beside_it() {
    // The bug this analysis fixed: the patrol mission's robot type and its
    // service live in `robots/beacon.robot.xml` beside it.
    let root = examples();
    let (code, problems) = from_check(&root, &["patrol/patrol.mission"]);
    assert_eq!(code, 0, "{}", listing(&problems));
    let out = semo_in(&root, &["check", "patrol/patrol.mission"]);
    assert!(
        out.stderr.contains("checked 1 mission and 1 catalog file"),
        "{}",
        out.stderr
    );
}

/// The mission's dataflow warnings as the server publishes them: the
/// fixture folder is the workspace root (indexed, so the catalog and the
/// service graph are there), the mission open; the publication that has
/// `code`.
fn dataflow_from_server(dir: &Path, mission: &Path, code: &str) -> BTreeSet<Problem> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let file = mission.display().to_string();
    let found: Vec<Value> = runtime.block_on(async {
        let mut client = TestClient::start();
        client
            .initialize(&["utf-16"], Some(&format!("file://{}", dir.display())))
            .await;
        let uri = format!("file://{file}");
        let text = std::fs::read_to_string(mission).unwrap();
        client.open(&uri, &text).await;
        let published = client
            .notification("textDocument/publishDiagnostics", |p| {
                p["uri"] == uri.as_str()
                    && p["version"] == 1
                    && p["diagnostics"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .any(|d| d["code"] == code)
            })
            .await;
        client.shutdown().await;
        published["diagnostics"].as_array().unwrap().clone()
    });
    found
        .iter()
        .map(|d| {
            (
                file.clone(),
                d["code"].as_str().unwrap().to_string(),
                d["range"]["start"]["line"].as_u64().unwrap() + 1,
                d["range"]["start"]["character"].as_u64().unwrap() + 1,
                d["message"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn dataflow_warnings_are_the_same_at_every_door() {
    let fixtures = support::repo_root().join("tests/fixtures/diagnostics");
    // Every fixture of every dataflow warning (W073 has more than one), in
    // a fixed order; each folder holds one mission.
    let mut dirs: Vec<(String, PathBuf)> = std::fs::read_dir(&fixtures)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter_map(|p| {
            let name = p.file_name()?.to_string_lossy().into_owned();
            let code = ["W070", "W071", "W072", "W073", "W074", "W075"]
                .into_iter()
                .find(|c| name.starts_with(c))?;
            Some((code.to_string(), p))
        })
        .collect();
    dirs.sort();
    let codes: BTreeSet<&str> = dirs.iter().map(|(c, _)| c.as_str()).collect();
    assert_eq!(
        codes.len(),
        6,
        "a fixture for each dataflow warning: {dirs:?}"
    );
    for (code, dir) in &dirs {
        let code = code.as_str();
        let mission = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "mission"))
            .unwrap_or_else(|| panic!("{}: no mission", dir.display()));
        let name = mission.display().to_string();
        let in_mission = |problems: BTreeSet<Problem>| -> BTreeSet<Problem> {
            problems.into_iter().filter(|p| p.0 == name).collect()
        };
        let (_, single) = from_check(dir, &[name.as_str()]);
        let (_, whole) = from_check(dir, &["."]);
        let single = in_mission(single);
        assert!(single.iter().any(|p| p.1 == code), "{}", listing(&single));
        assert_eq!(
            listing(&single),
            listing(&in_mission(whole)),
            "{code}: FILE and DIR"
        );
        assert_eq!(
            listing(&single),
            listing(&dataflow_from_server(dir, &mission, code)),
            "{code}: check and the editor"
        );
        // Warnings: the mission builds.
        let out = std::env::temp_dir().join(format!("semo-doors-{code}-{}", std::process::id()));
        let build = semo_in(
            dir,
            &[
                "build",
                &name,
                "--emit",
                "taskgraph",
                "--out",
                &out.display().to_string(),
            ],
        );
        assert_eq!(build.code, 0, "{}{}", build.stdout, build.stderr);
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The diagnostics the server publishes for `mission` when `root` is the
/// workspace folder (indexed from disk, the mission unopened).
fn indexed_from_server(root: &Path, mission: &Path) -> BTreeSet<Problem> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let file = mission.display().to_string();
    let found = runtime.block_on(async {
        let mut client = TestClient::start();
        client
            .initialize(&["utf-16"], Some(&format!("file://{}", root.display())))
            .await;
        let found = client.diagnostics(&format!("file://{file}"), None).await;
        client.shutdown().await;
        found
    });
    found
        .iter()
        .map(|d| {
            (
                file.clone(),
                d["code"].as_str().unwrap().to_string(),
                d["range"]["start"]["line"].as_u64().unwrap() + 1,
                d["range"]["start"]["character"].as_u64().unwrap() + 1,
                d["message"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn a_project_files_folders_and_levels_are_the_same_at_every_door() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    // A repository root: the search for a project file stops here.
    std::fs::create_dir(root.join(".git")).unwrap();
    let write = |path: &str, text: &str| {
        let path = root.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    };
    write(
        "semo.toml",
        "[project]\nversion = 1\ncatalogs = [\"robots\"]\n\n[lints]\nW010 = \"allow\"\nW002 = \"deny\"\n",
    );
    write(
        "robots/rover.robot.xml",
        "<Catalog xmlns=\"urn:semo:catalog:1\">\n  <Robot type=\"Rover\">\n    <Service name=\"beep\" task=\"buzzer\"/>\n  </Robot>\n</Catalog>\n",
    );
    // Beside the mission but in no catalog folder of the project: unread.
    write("missions/stray.robot.xml", "<Catalog");
    // A W010 (allowed) and a W002 (denied).
    write(
        "missions/m.mission",
        "{ A: Rover r }\ndef zigzag{\n  beep()\n}\nA.P.S{\n  beep()\n} repeat(1 SEC)\nA.M{ set(P, S) }\nA.REST{ set(P, OFF) }\nA.main{\n  default: mode = M\n}\n",
    );
    let mission = root.join("missions/m.mission");
    let name = mission.display().to_string();
    let only_mission = |problems: BTreeSet<Problem>| -> BTreeSet<Problem> {
        problems.into_iter().filter(|p| p.0 == name).collect()
    };
    let (code, single) = from_check(root, &[name.as_str()]);
    assert_eq!(code, 1, "W002 denied: an error\n{}", listing(&single));
    let codes: Vec<&str> = single.iter().map(|p| p.1.as_str()).collect();
    assert_eq!(codes, ["W002"], "{}", listing(&single));
    let (_, whole) = from_check(root, &["."]);
    assert_eq!(
        listing(&single),
        listing(&only_mission(whole)),
        "FILE and DIR"
    );
    // The editor opened on the missions folder: the project file above it
    // and its catalog folder beside it are found as the CLI finds them.
    assert_eq!(
        listing(&single),
        listing(&indexed_from_server(&root.join("missions"), &mission)),
        "check and the editor"
    );
    let out = root.join("out");
    let build = semo_in(
        root,
        &[
            "build",
            &name,
            "--emit",
            "taskgraph",
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(build.code, 1, "{}{}", build.stdout, build.stderr);
    assert!(!out.exists());
}

/// Every file under `dir` (relative path → bytes).
fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    walkdir::WalkDir::new(dir)
        .into_iter()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().is_file())
        .map(|e| {
            let relative = e.path().strip_prefix(dir).unwrap().display().to_string();
            (relative, std::fs::read(e.path()).unwrap())
        })
        .collect()
}

/// The editor's Generate Code (no folder or target asked) of `mission` in
/// the workspace `root`, as a user runs it once the mission is open: the
/// server's answer.
fn generate_in_editor(root: &Path, mission: &str) -> Value {
    generate_in_editor_with(root, serde_json::json!({ "mission": mission }))
}

/// [`generate_in_editor`] with more of the command's arguments than the
/// mission (`arguments["mission"]`, a path under `root`, becomes its URI).
fn generate_in_editor_with(root: &Path, mut arguments: Value) -> Value {
    let mission = arguments["mission"].as_str().unwrap().to_string();
    arguments.as_object_mut().unwrap().remove("mission");
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let mut client = TestClient::start();
        let workspace = format!("file://{}", root.display());
        client.initialize(&["utf-16"], Some(&workspace)).await;
        let uri = client.open_file(&root.join(mission)).await;
        arguments["uri"] = uri.as_str().into();
        let answer = client
            .request(
                "workspace/executeCommand",
                serde_json::json!({ "command": "semo.generateCode", "arguments": [arguments] }),
            )
            .await
            .expect("generated");
        client.shutdown().await;
        answer
    })
}

/// The two doors wrote the same files, byte for byte.
fn same_files(
    from_cli: &std::collections::BTreeMap<String, Vec<u8>>,
    from_editor: &std::collections::BTreeMap<String, Vec<u8>>,
) {
    assert_eq!(
        from_cli.keys().collect::<Vec<_>>(),
        from_editor.keys().collect::<Vec<_>>()
    );
    for (file, bytes) in from_cli {
        assert!(from_editor[file] == *bytes, "{file} differs");
    }
}

/// A project whose `semo.toml` says where and for what to build.
fn planned_project(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::create_dir_all(dir.join(".git")).unwrap();
    std::fs::write(
        dir.join("semo.toml"),
        "[build]\noutput = \"build\"\ntarget = \"linux-sim\"\n",
    )
    .unwrap();
    std::fs::copy(
        examples().join("follow/follow.mission"),
        dir.join("follow.mission"),
    )
    .unwrap();
    // The simulation's scenario (compiled in: both doors are given it).
    std::fs::write(dir.join("follow.scenario.json"), r#"{"duration": 2000}"#).unwrap();
}

/// `semo build` and the editor's Generate Code (no folder or target asked)
/// build the same plan for the same project: the project file's target and
/// folder, and the same files written.
#[test]
fn the_cli_and_the_editor_build_the_project_files_plan() {
    let tmp = tempfile::tempdir().unwrap();
    let (cli, editor) = (tmp.path().join("cli"), tmp.path().join("editor"));
    planned_project(&cli);
    planned_project(&editor);
    let built = semo_in(&cli, &["build", "--scenario", "follow.scenario.json"]);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);

    let answer = generate_in_editor_with(
        &editor,
        serde_json::json!({ "mission": "follow.mission", "scenario": "follow.scenario.json" }),
    );
    assert_eq!(answer["target"], "linux-sim", "{answer}");
    assert_eq!(
        answer["outputFolder"],
        editor.join("build").display().to_string()
    );
    let (from_cli, from_editor) = (tree(&cli.join("build")), tree(&editor.join("build")));
    assert!(
        from_cli.contains_key("Team1/create1/main.c"),
        "{:?}",
        from_cli.keys()
    );
    same_files(&from_cli, &from_editor);
    assert!(!cli.join("out").exists() && !editor.join("out").exists());
}

/// `tests/fixtures/mixed_fleet` (its Evalbot's catalog platform is
/// cortex-m, its iRobot Creates are linux) copied to `dir`, a repository root.
fn mixed_fleet(dir: &Path) {
    let fixture = support::repo_root().join("tests/fixtures/mixed_fleet");
    for file in ["semo.toml", "fleet.mission", "robots/fleet.robot.xml"] {
        let to = dir.join(file);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(fixture.join(file), to).unwrap();
    }
    std::fs::create_dir_all(dir.join(".git")).unwrap();
}

/// A mixed fleet: `semo build` and the editor's Generate Code read the same
/// plan, so each robot gets the same target at both doors (the Evalbot
/// cortex-m from its catalog, the Creates linux) and the same files, the
/// runtime folder with both targets' files included.
#[test]
fn the_cli_and_the_editor_build_a_mixed_fleet_alike() {
    let tmp = tempfile::tempdir().unwrap();
    let (cli, editor) = (tmp.path().join("cli"), tmp.path().join("editor"));
    mixed_fleet(&cli);
    mixed_fleet(&editor);
    let built = semo_in(&cli, &["build"]);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);

    let answer = generate_in_editor(&editor, "fleet.mission");
    assert_eq!(answer["target"], Value::Null, "{answer}");
    assert_eq!(
        answer["targets"],
        serde_json::json!(["linux", "cortex-m"]),
        "{answer}"
    );
    let targets: Vec<(&str, &str)> = answer["robots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["robot"].as_str().unwrap(), r["target"].as_str().unwrap()))
        .collect();
    assert_eq!(
        targets,
        [("ev", "cortex-m"), ("a", "linux"), ("b", "linux")]
    );
    let (from_cli, from_editor) = (tree(&cli.join("out")), tree(&editor.join("out")));
    assert!(
        from_cli.contains_key("Scouts/ev/Makefile")
            && from_cli.contains_key("semo-runtime/semo_lm3s6965.c")
            && from_cli.contains_key("semo-runtime/semo_runtime.c"),
        "{:?}",
        from_cli.keys()
    );
    same_files(&from_cli, &from_editor);
}
