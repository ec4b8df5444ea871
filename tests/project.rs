//! The project file through the binary: `semo init`, which files a mission
//! reads with and without a `semo.toml`, `[lints]` levels in `check` and
//! `build`, and `semo build`'s target and output from the project.

mod support;

use std::path::{Path, PathBuf};
use support::{check_json_in, semo_in};

/// A folder removed at the end, marked as a repository root so that the
/// search for a project file stops in it whatever lies above it.
fn workspace() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join(".git")).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// A catalog with the type `Rover` (service `beep`).
const ROVER: &str = r#"<?xml version="1.0"?>
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Service name="beep" task="buzzer"/>
  </Robot>
</Catalog>
"#;

const BROKEN_CATALOG: &str = "<Catalog xmlns=\"urn:semo:catalog:1\"><Robot";

const ROVER_MISSION: &str = "{ A: Rover r }\nA.P.S { beep() } repeat(1 SEC)\nA.M { set(P, S) }\nA.main { default: mode = M }\n";

/// A mission with one W010 (a function never called) and one W002 (a mode
/// never reached) and nothing else.
const TWO_WARNINGS: &str = "{ A: iRobotCreate scout }\n\
def zigzag{\n  go_forward()\n}\n\
A.Action.Explore{\n  move(\"5,5\")\n} repeat(1 SEC)\n\
A.EXPLORE{ set(Action, Explore) }\n\
A.REST{ set(Action, OFF) }\n\
A.main{\n  default: mode = EXPLORE\n}\n";

fn codes(dir: &Path, paths: &[&str]) -> (i32, Vec<String>) {
    let (code, diags) = check_json_in(dir, paths);
    let listed = diags
        .iter()
        .map(|d| format!("{} {} {}", d.code, d.severity, d.file))
        .collect();
    (code, listed)
}

#[test]
fn init_writes_a_project_that_check_and_build_accept() {
    let dir = workspace();
    let out = semo_in(dir.path(), &["init", "field"]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let project = dir.path().join("field");
    for file in ["semo.toml", "main.mission", "robots/rover.robot.xml"] {
        assert!(project.join(file).is_file(), "{file} written");
    }
    let toml = std::fs::read_to_string(project.join("semo.toml")).unwrap();
    assert!(toml.contains("name = \"field\""), "{toml}");
    // Accepted as written: no error, no warning, in the folder or by file.
    assert_eq!(codes(&project, &["."]), (0, vec![]));
    assert_eq!(codes(&project, &["main.mission"]), (0, vec![]));
    // Written in the canonical layout, as the user's own missions will be.
    let fmt = semo_in(&project, &["fmt", "--check"]);
    assert_eq!(fmt.code, 0, "{}{}", fmt.stdout, fmt.stderr);
    // The project's one mission, output folder and target, from anywhere
    // in the project.
    let build = semo_in(&project.join("robots"), &["build", "--emit", "taskgraph"]);
    assert_eq!(build.code, 0, "{}{}", build.stdout, build.stderr);
    assert!(
        build.stdout.contains("for target linux"),
        "{}",
        build.stdout
    );
    assert!(project.join("out/Rovers/rover_0/taskgraph.xml").is_file());
}

/// A scenario of `ROVER_MISSION` whose one expectation holds or not.
fn rover_scenario(holds: bool) -> String {
    let expect = if holds { "enters" } else { "never_enters" };
    format!("{{\"duration\": 1000, \"expect\": [{{\"robot\": \"r\", \"{expect}\": \"M\"}}]}}\n")
}

#[test]
fn build_and_simulate_take_the_projects_one_mission_and_its_scenario() {
    let dir = workspace();
    let root = dir.path();
    write(&root.join("semo.toml"), "[project]\nversion = 1\n");
    write(&root.join("robots/rover.robot.xml"), ROVER);
    let missions = root.join("missions");
    write(&missions.join("a.mission"), ROVER_MISSION);
    // Its own scenario first, as the editors offer it, over another one
    // named after it (whose expectation fails).
    write(&missions.join("a.scenario.json"), &rover_scenario(true));
    write(
        &missions.join("a.slow.scenario.json"),
        &rover_scenario(false),
    );
    let simulated = semo_in(root, &["simulate"]);
    assert_eq!(
        simulated.code, 0,
        "{}{}",
        simulated.stdout, simulated.stderr
    );
    assert!(
        simulated.stdout.contains("A/r: M@0"),
        "{}",
        simulated.stdout
    );
    // Without it, the only scenario named after the mission.
    std::fs::remove_file(missions.join("a.scenario.json")).unwrap();
    let simulated = semo_in(&missions, &["simulate"]);
    assert_eq!(
        simulated.code, 1,
        "{}{}",
        simulated.stdout, simulated.stderr
    );
    // Two of them: which one is the user's to say.
    write(
        &missions.join("a.fast.scenario.json"),
        &rover_scenario(true),
    );
    let ambiguous = semo_in(&missions, &["simulate", "a.mission"]);
    assert_eq!(ambiguous.code, 2, "{}", ambiguous.stderr);
    assert_eq!(
        ambiguous.stderr.trim_end(),
        "error: 2 scenarios for a.mission, which one? a.fast.scenario.json, \
         a.slow.scenario.json (name it with --scenario FILE)"
    );
    let built = semo_in(&missions, &["build", "--emit", "taskgraph"]);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert!(missions.join("out/A/r/taskgraph.xml").is_file());
    // Two missions in the project: named, in one line, and in the JSON
    // document as its one diagnostic.
    write(&root.join("b.mission"), ROVER_MISSION);
    let ambiguous = semo_in(&missions, &["build", "--format", "json"]);
    assert_eq!(ambiguous.code, 2, "{}", ambiguous.stderr);
    let message = "2 missions in the project (..), which one? ../b.mission, \
                   ../missions/a.mission (`semo build MISSION`)";
    assert_eq!(ambiguous.stderr.trim_end(), format!("error: {message}"));
    let document: serde_json::Value = serde_json::from_str(&ambiguous.stdout).unwrap();
    assert_eq!(document["diagnostics"][0]["message"], message, "{document}");
    // Without a project file, the missions under the current folder.
    std::fs::remove_file(root.join("semo.toml")).unwrap();
    let ambiguous = semo_in(root, &["simulate"]);
    assert_eq!(ambiguous.code, 2, "{}", ambiguous.stderr);
    assert_eq!(
        ambiguous.stderr.trim_end(),
        "error: 2 missions in this folder (.), which one? b.mission, missions/a.mission \
         (`semo simulate MISSION`)"
    );
}

#[test]
fn catalog_lists_the_built_in_types_and_the_projects_own() {
    let dir = workspace();
    let root = dir.path();
    write(
        &root.join("semo.toml"),
        "[project]\nversion = 1\ncatalogs = [\"robots\"]\n",
    );
    write(&root.join("robots/rover.robot.xml"), ROVER);
    // Not in a catalog folder of the project: not the project's.
    write(
        &root.join("missions/stray.robot.xml"),
        &ROVER.replace("Rover", "Stray"),
    );
    let missions = root.join("missions");
    let listed = semo_in(&missions, &["catalog"]);
    assert_eq!(listed.code, 0, "{}{}", listed.stdout, listed.stderr);
    assert!(listed.stderr.is_empty(), "{}", listed.stderr);
    let text = &listed.stdout;
    for expected in [
        "iRobotCreate (built-in)\n",
        "    move(goal?: location)       Drive to a goal position",
        "    DISTANCE: int (cm)      Distance to the nearest obstacle ahead, in centimetres.\n",
        "Rover (../robots/rover.robot.xml)\n  services:\n    beep()\n",
        "USER: the operator console, not a robot type (built-in; also: user)\n",
        "    RC_CMD: string (also: cmd)  The latest remote-control command",
    ] {
        assert!(text.contains(expected), "{expected:?} in:\n{text}");
    }
    assert!(!text.contains("Stray"), "{text}");
    // One type, by name or alias; a misspelt one gets a did-you-mean.
    let one = semo_in(&missions, &["catalog", "lego_robot"]);
    assert_eq!(one.code, 0, "{}", one.stderr);
    assert!(
        one.stdout
            .starts_with("NXTLego (built-in; also: lego_robot)\n"),
        "{}",
        one.stdout
    );
    assert!(!one.stdout.contains("iRobotCreate"), "{}", one.stdout);
    let unknown = semo_in(&missions, &["catalog", "Rovr"]);
    assert_eq!(unknown.code, 2, "{}", unknown.stderr);
    assert!(
        unknown.stderr.contains("no robot type `Rovr`")
            && unknown.stderr.contains("(did you mean `Rover`?)"),
        "{}",
        unknown.stderr
    );
    // JSON: one document; USER is the operator, not among the robots.
    let json = semo_in(&missions, &["catalog", "--format", "json"]);
    assert_eq!(json.code, 0, "{}", json.stderr);
    let document: serde_json::Value = serde_json::from_str(&json.stdout).expect(&json.stdout);
    assert_eq!(document["command"], "catalog");
    let robots = document["robots"].as_array().unwrap();
    let names: Vec<&str> = robots.iter().map(|r| r["name"].as_str().unwrap()).collect();
    assert!(
        names.contains(&"TIEvalbot") && names.contains(&"Rover"),
        "{names:?}"
    );
    assert!(!names.contains(&"USER"), "{names:?}");
    let rover = robots.iter().find(|r| r["name"] == "Rover").unwrap();
    assert_eq!(rover["source"], "../robots/rover.robot.xml");
    assert_eq!(rover["services"][0]["signature"], "beep()");
    assert_eq!(document["operator"]["name"], "USER");
    assert_eq!(document["operator"]["values"][0]["type"], "string");
    // A broken catalog file: its errors, and what loaded still listed.
    write(&root.join("robots/broken.robot.xml"), BROKEN_CATALOG);
    let broken = semo_in(&missions, &["catalog"]);
    assert_eq!(broken.code, 1, "{}", broken.stderr);
    assert!(
        broken.stderr.contains("broken.robot.xml"),
        "{}",
        broken.stderr
    );
    assert!(
        broken.stdout.contains("Rover (../robots/rover.robot.xml)"),
        "{}",
        broken.stdout
    );
}

#[test]
fn init_refuses_to_overwrite_and_writes_nothing() {
    let dir = workspace();
    let mine = "# my own mission\n";
    write(&dir.path().join("main.mission"), mine);
    let out = semo_in(dir.path(), &["init"]);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("main.mission already exists"),
        "{}",
        out.stderr
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("main.mission")).unwrap(),
        mine
    );
    assert!(!dir.path().join("semo.toml").exists());
    assert!(!dir.path().join("robots").exists());
}

#[test]
fn a_project_file_decides_which_catalogs_a_mission_reads() {
    let dir = workspace();
    let root = dir.path();
    write(
        &root.join("semo.toml"),
        "[project]\nversion = 1\ncatalogs = [\"robots\"]\n",
    );
    write(&root.join("robots/rover.robot.xml"), ROVER);
    // Not in a catalog folder of the project: never read.
    write(&root.join("missions/stray.robot.xml"), BROKEN_CATALOG);
    write(&root.join("missions/m.mission"), ROVER_MISSION);
    // From the mission's folder, the project file above is found, and the
    // same from the root.
    assert_eq!(
        codes(&root.join("missions"), &["m.mission"]),
        (0, vec![]),
        "check FILE"
    );
    let build = semo_in(
        &root.join("missions"),
        &["build", "m.mission", "--emit", "taskgraph"],
    );
    assert_eq!(build.code, 0, "{}{}", build.stdout, build.stderr);
    // Without the project file, the stray catalog beside the mission is read.
    std::fs::remove_file(root.join("semo.toml")).unwrap();
    let (code, found) = codes(&root.join("missions"), &["m.mission"]);
    assert_eq!(code, 1);
    assert!(found.iter().any(|c| c.starts_with("E050")), "{found:?}");
}

#[test]
fn lints_allow_one_warning_and_deny_another_in_check_and_build() {
    let dir = workspace();
    let root = dir.path();
    write(&root.join("m.mission"), TWO_WARNINGS);
    let (code, found) = codes(root, &["m.mission"]);
    assert_eq!(
        (code, found),
        (
            0,
            vec![
                "W010 warning m.mission".to_string(),
                "W002 warning m.mission".to_string()
            ]
        )
    );
    write(
        &root.join("semo.toml"),
        "[lints]\nW010 = \"allow\"\nW002 = \"deny\"\n",
    );
    let (code, found) = codes(root, &["m.mission"]);
    assert_eq!((code, found), (1, vec!["W002 error m.mission".to_string()]));
    let build = semo_in(root, &["build", "m.mission", "--emit", "taskgraph"]);
    assert_eq!(
        build.code, 1,
        "denied: refused\n{}{}",
        build.stdout, build.stderr
    );
    assert!(!root.join("out").exists());
}

#[test]
fn build_takes_target_and_output_from_the_project_unless_given() {
    let dir = workspace();
    let root = dir.path();
    write(
        &root.join("semo.toml"),
        "[build]\noutput = \"gen\"\ntarget = \"linux-sim\"\n",
    );
    write(&root.join("robots/rover.robot.xml"), ROVER);
    write(&root.join("m.mission"), ROVER_MISSION);
    // A simulation compiles its scenario in: the command line's, else the
    // mission's own beside it (as `semo simulate` chooses); without either
    // the build says where it looked.
    let build = semo_in(root, &["build", "m.mission"]);
    assert_eq!(build.code, 2, "{}{}", build.stdout, build.stderr);
    assert!(
        build.stderr.contains(
            "target linux-sim compiles a scenario into each robot (r): no scenario for m.mission: looked for m.scenario.json (name one with --scenario FILE)"
        ),
        "{}",
        build.stderr
    );
    write(&root.join("m.scenario.json"), r#"{"duration": 2000}"#);
    let build = semo_in(root, &["build", "m.mission"]);
    assert_eq!(build.code, 0, "{}{}", build.stdout, build.stderr);
    assert!(
        build.stdout.contains("for target linux-sim"),
        "{}",
        build.stdout
    );
    let robot = root.join("gen/A/r");
    assert!(
        root.join("gen/semo-runtime/semo_sim.c").is_file() && robot.join("main.c").is_file(),
        "linux-sim runtime in gen/"
    );
    assert!(!root.join("out").exists());
    // The command line wins.
    let build = semo_in(
        root,
        &["build", "m.mission", "--target", "linux", "-o", "elsewhere"],
    );
    assert_eq!(build.code, 0, "{}{}", build.stdout, build.stderr);
    assert!(
        build.stdout.contains("for target linux in"),
        "{}",
        build.stdout
    );
    assert!(root.join("elsewhere/A/r/main.c").is_file());
}

/// A chain of `depth` folders under `base`, a broken catalog at the bottom.
fn deep_broken_catalog(base: &Path, depth: usize) -> PathBuf {
    let mut dir = base.to_path_buf();
    for i in 0..depth {
        dir.push(format!("d{i}"));
    }
    write(&dir.join("bad.robot.xml"), BROKEN_CATALOG);
    dir
}

#[test]
fn without_a_project_file_the_search_beside_a_mission_is_bounded() {
    let dir = workspace();
    let root = dir.path();
    write(&root.join("m.mission"), ROVER_MISSION);
    write(&root.join("robots/rover.robot.xml"), ROVER);
    // Deeper than the rule looks (host::SEEN_DEPTH = 3 folders below).
    deep_broken_catalog(&root.join("unrelated"), 4);
    assert_eq!(codes(root, &["m.mission"]), (0, vec![]));
    // Within the depth it is read (so the test above can fail).
    let near = deep_broken_catalog(&root.join("near"), 2);
    let (code, found) = codes(root, &["m.mission"]);
    assert_eq!(code, 1, "{found:?}");
    std::fs::remove_dir_all(root.join("near")).unwrap();
    assert!(!near.exists());
    // A huge unrelated tree beside the mission: the walk (nearest folders
    // first) stops at its entry bound, says so, and what lies past the
    // bound is not read.
    let huge = root.join("aaa-huge");
    for i in 0..20_050 {
        if i % 1000 == 0 {
            std::fs::create_dir_all(huge.join(format!("{:02}", i / 1000))).unwrap();
        }
        std::fs::File::create(huge.join(format!("{:02}/f{i}", i / 1000))).unwrap();
    }
    // As deep as the huge tree's files, listed after them.
    write(&root.join("zzz/1/bad.robot.xml"), BROKEN_CATALOG);
    let (code, found) = codes(root, &["m.mission"]);
    assert_eq!(
        (code, found),
        (0, vec!["W112 warning m.mission".to_string()])
    );
    // With a project file, the user says where to look: no search, no W112.
    write(
        &root.join("semo.toml"),
        "[project]\ncatalogs = [\"robots\"]\n",
    );
    assert_eq!(codes(root, &["m.mission"]), (0, vec![]));
}

/// `tests/fixtures/mixed_fleet` copied into a fresh repository root: a
/// project whose catalog puts its Evalbot on `cortex-m`, with two iRobot
/// Creates (built-in, no platform named: `linux`).
fn mixed_fleet() -> tempfile::TempDir {
    let dir = workspace();
    let fixture = support::repo_root().join("tests/fixtures/mixed_fleet");
    for file in [
        "semo.toml",
        "fleet.mission",
        "fleet.scenario.json",
        "robots/fleet.robot.xml",
    ] {
        let text = std::fs::read_to_string(fixture.join(file)).unwrap();
        write(&dir.path().join(file), &text);
    }
    dir
}

/// `robot → target` of each robot of a `semo build --format json` document,
/// with who chose it.
fn planned(stdout: &str) -> Vec<String> {
    let document: serde_json::Value = serde_json::from_str(stdout).expect(stdout);
    document["robots"]
        .as_array()
        .expect("robots")
        .iter()
        .map(|r| {
            let sim = if r["simulated"] == true { " sim" } else { "" };
            format!(
                "{} {} ({}{sim})",
                r["robot"].as_str().unwrap(),
                r["target"].as_str().unwrap(),
                r["chosen_by"].as_str().unwrap()
            )
        })
        .collect()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// One `semo build` writes each robot for the platform its type names: the
/// Evalbot's folder for cortex-m, the Creates' for linux, each with its
/// Makefile, and the runtime folder with what both need.
#[test]
fn one_build_gives_each_robot_the_platform_its_type_names() {
    let dir = mixed_fleet();
    let root = dir.path();
    let built = semo_in(root, &["build"]);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let lines: Vec<&str> = built.stdout.lines().collect();
    assert!(
        lines[0].starts_with("Scouts/ev: ")
            && lines[0].contains("(target cortex-m, its type `Evalbot`'s platform; "),
        "{}",
        built.stdout
    );
    assert!(
        lines[1].starts_with("Base/a: ") && lines[1].contains("(target linux; "),
        "{}",
        built.stdout
    );
    assert!(
        built
            .stdout
            .contains("built 3 robot(s) for targets linux (2), cortex-m (1) in"),
        "{}",
        built.stdout
    );
    let out = root.join("out");
    let ev = read(&out.join("Scouts/ev/Makefile"));
    assert!(
        ev.contains("for target cortex-m (TI Stellaris LM3S6965, a\n# Cortex-M3)")
            && ev.contains("\nCC = arm-none-eabi-gcc\n")
            && ev.contains("-T $(RUNTIME)/lm3s6965.ld"),
        "{ev}"
    );
    let a = read(&out.join("Base/a/Makefile"));
    assert!(
        a.contains("for target linux;") && a.contains("\nTRANSPORT ?= mqtt\n"),
        "{a}"
    );
    assert!(!a.contains("arm-none-eabi"), "{a}");
    // One runtime folder: the threads layer and the board, no simulation.
    let runtime = out.join("semo-runtime");
    for file in [
        "semo_core.c",
        "semo_runtime.c",
        "semo_mqtt.c",
        "semo_static.c",
        "semo_lm3s6965.c",
        "lm3s6965.ld",
        "semo_runtime.mk",
    ] {
        assert!(runtime.join(file).is_file(), "{file} in the runtime folder");
    }
    assert!(!runtime.join("semo_sim.c").exists());
    let ld = read(&runtime.join("lm3s6965.ld"));
    assert!(
        ld.contains("FLASH (rx) : ORIGIN = 0x00000000, LENGTH = 256K")
            && ld.contains("RAM (rwx)  : ORIGIN = 0x20000000, LENGTH = 64K"),
        "the board's memory from the platform table: {ld}"
    );
    assert!(
        read(&runtime.join(".semo-manifest"))
            .starts_with("semo-manifest 1 target linux and cortex-m\n")
    );
    // The JSON document says each robot's target and who chose it.
    let json = semo_in(root, &["build", "--format", "json"]);
    assert_eq!(json.code, 0, "{}", json.stderr);
    assert_eq!(
        planned(&json.stdout),
        [
            "ev cortex-m (catalog)",
            "a linux (default)",
            "b linux (default)"
        ]
    );
    let document: serde_json::Value = serde_json::from_str(&json.stdout).unwrap();
    assert_eq!(document["target"], serde_json::Value::Null);
    assert_eq!(
        document["targets"],
        serde_json::json!(["linux", "cortex-m"])
    );
    // `--sim`: each platform's simulation (which compiles the scenario in,
    // so it needs one: the fixture has one beside the mission, `fleet.scenario.json`,
    // but it is named here as a user would).
    let sim = semo_in(
        root,
        &[
            "build",
            "--sim",
            "--scenario",
            "fleet.scenario.json",
            "--format",
            "json",
        ],
    );
    assert_eq!(sim.code, 0, "{}{}", sim.stdout, sim.stderr);
    assert_eq!(
        planned(&sim.stdout),
        [
            "ev cortex-m-sim (catalog sim)",
            "a linux-sim (default sim)",
            "b linux-sim (default sim)"
        ]
    );
    assert!(out.join("Scouts/ev/scenario.c").is_file());
    assert!(out.join("Base/a/scenario.c").is_file());
    assert!(runtime.join("semo_sim.c").is_file());
    // `--target` is every robot's, whatever the catalog says.
    let linux = semo_in(root, &["build", "--target", "linux", "--format", "json"]);
    assert_eq!(linux.code, 0, "{}{}", linux.stdout, linux.stderr);
    assert_eq!(
        planned(&linux.stdout),
        [
            "ev linux (command line)",
            "a linux (command line)",
            "b linux (command line)"
        ]
    );
    assert!(read(&out.join("Scouts/ev/Makefile")).contains("for target linux;"));
}

/// `[build.targets]` gives a team or a robot its own target, over the
/// catalog's and `[build] target`; a name the mission lacks is W110 where
/// it is written, with a did-you-mean, and the robots keep their target.
#[test]
fn the_project_file_gives_a_team_or_a_robot_its_own_target() {
    let dir = mixed_fleet();
    let root = dir.path();
    let project = read(&root.join("semo.toml"));
    write(
        &root.join("semo.toml"),
        &format!(
            "{project}\n[build]\ntarget = \"linux-sim\"\n\n[build.targets]\nScouts = \"linux\"\nev = \"cortex-m\"\na = \"linux\"\nScuots = \"linux\"\n"
        ),
    );
    let scenario = ["--scenario", "fleet.scenario.json"];
    let built = semo_in(
        root,
        &[&["build", "--format", "json"][..], &scenario].concat(),
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert_eq!(
        planned(&built.stdout),
        [
            "ev cortex-m (project file)",
            "a linux (project file)",
            "b linux-sim (project file)"
        ]
    );
    let document: serde_json::Value = serde_json::from_str(&built.stdout).unwrap();
    let warnings = document["diagnostics"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{document}");
    let w = &warnings[0];
    assert_eq!(w["code"], "W110");
    assert!(w["file"].as_str().unwrap().ends_with("semo.toml"), "{w}");
    let written = read(&root.join("semo.toml"));
    let line = written
        .lines()
        .position(|l| l.starts_with("Scuots"))
        .unwrap() as u64
        + 1;
    assert_eq!(
        (&w["start"]["line"], &w["start"]["column"]),
        (&line.into(), &1.into()),
        "{w}"
    );
    assert_eq!(
        w["message"],
        "`[build.targets]` names `Scuots`, which is no team or robot of fleet.mission: its target is not used (did you mean `Scouts`?)"
    );
    // For people: on standard error, positioned in semo.toml.
    let human = semo_in(root, &[&["build"][..], &scenario].concat());
    assert_eq!(human.code, 0, "{}", human.stderr);
    assert!(
        human
            .stderr
            .contains("[W110] Warning: `[build.targets]` names `Scuots`")
            && human.stderr.contains(&format!("semo.toml:{line}:1")),
        "{}",
        human.stderr
    );
    assert!(
        human.stdout.contains("Scouts/ev: ")
            && human
                .stdout
                .contains("(target cortex-m from semo.toml's `[build.targets] ev`; ")
            && human
                .stdout
                .contains("(target linux-sim from semo.toml's `[build] target`; "),
        "{}",
        human.stdout
    );
    // Denied, it refuses the build, and nothing is written.
    write(
        &root.join("semo.toml"),
        &format!("{written}\n[lints]\nW110 = \"deny\"\n"),
    );
    std::fs::remove_dir_all(root.join("out")).unwrap();
    let denied = semo_in(root, &[&["build"][..], &scenario].concat());
    assert_eq!(denied.code, 1, "{}{}", denied.stdout, denied.stderr);
    assert!(
        denied
            .stderr
            .contains("[W110] Error: `[build.targets]` names `Scuots`"),
        "{}",
        denied.stderr
    );
    assert!(!root.join("out").exists());
    // An unknown target is E111 with a did-you-mean, and refuses the check.
    write(
        &root.join("semo.toml"),
        &format!("{project}\n[build.targets]\nScouts = \"cortx-m\"\n"),
    );
    let (code, found) = codes(root, &["."]);
    assert_eq!(code, 1, "{found:?}");
    assert!(
        found
            .iter()
            .any(|c| c.starts_with("E111 error") && c.ends_with("semo.toml")),
        "{found:?}"
    );
    let (_, diags) = check_json_in(root, &["."]);
    let e111 = diags.iter().find(|d| d.code == "E111").unwrap();
    assert_eq!(e111.suggestion.as_deref(), Some("cortex-m"));
}

/// A robot that talks to another robot is built, on either board, with its
/// board's serial link to `semo gateway`: on cortex-m (the catalog's
/// platform) on UART1, on stm32f4 on USART2; the project file can build it
/// for linux instead.
#[test]
fn a_talking_robot_on_either_board_is_built_with_its_link_and_the_project_file_can_choose_linux() {
    let dir = mixed_fleet();
    let root = dir.path();
    let mission = read(&root.join("fleet.mission")).replace(
        "  send(USER, Scouts.DISTANCE)\n",
        "  send(USER, Scouts.DISTANCE)\n  send(Base, Scouts.DISTANCE)\n",
    );
    write(&root.join("fleet.mission"), &mission);
    for (target, port) in [("cortex-m", "UART1"), ("stm32f4", "USART2")] {
        let catalog = read(&root.join("robots/fleet.robot.xml"));
        let catalog = catalog
            .replace("target=\"cortex-m\"", &format!("target=\"{target}\""))
            .replace("target=\"stm32f4\"", &format!("target=\"{target}\""));
        write(&root.join("robots/fleet.robot.xml"), &catalog);
        let built = semo_in(root, &["build", "--format", "json"]);
        assert_eq!(built.code, 0, "{target}: {}{}", built.stdout, built.stderr);
        assert_eq!(planned(&built.stdout)[0], format!("ev {target} (catalog)"));
        let makefile = read(&root.join("out/Scouts/ev/Makefile"));
        assert!(makefile.contains(" -DSEMO_LINK "), "{makefile}");
        assert!(
            makefile.contains(&format!("# The serial link to `semo gateway` on {port} ")),
            "{makefile}"
        );
        std::fs::remove_dir_all(root.join("out")).unwrap();
    }
    // The project file builds it for linux instead.
    let project = read(&root.join("semo.toml"));
    write(
        &root.join("semo.toml"),
        &format!("{project}\n[build.targets]\nev = \"linux\"\n"),
    );
    let built = semo_in(root, &["build", "--format", "json"]);
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert_eq!(
        planned(&built.stdout),
        [
            "ev linux (project file)",
            "a linux (default)",
            "b linux (default)"
        ]
    );
}

/// The built-in catalog's TIEvalbot is a Stellaris LM3S robot: the scouting
/// example built with no target has `ti` on cortex-m, with its serial link
/// (it talks to the other robots), and `irobot` and `nxt` on linux.
#[test]
fn the_scouting_example_builds_ti_for_its_board_and_the_others_for_linux() {
    let dir = workspace();
    let out = dir.path().join("out");
    let mission = support::examples().join("scouting/scouting.mission");
    let built = semo_in(
        &support::repo_root(),
        &[
            "build",
            mission.to_str().unwrap(),
            "--format",
            "json",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    assert_eq!(
        planned(&built.stdout),
        [
            "irobot linux (default)",
            "ti cortex-m (catalog)",
            "nxt linux (default)"
        ]
    );
    let makefile = read(&out.join("SlaveTeam/ti/Makefile"));
    assert!(makefile.contains(" -DSEMO_LINK "), "{makefile}");
}
