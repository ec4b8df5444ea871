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
