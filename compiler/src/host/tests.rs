use super::*;
use crate::diag::Code;

fn roots(roots: &[&str]) -> Roots {
    Roots {
        roots: roots.iter().map(PathBuf::from).collect(),
        seen_by_all: Vec::new(),
    }
}

#[test]
fn a_file_sees_its_folder_below_it_and_the_folders_above_it_up_to_its_root() {
    let r = roots(&["/w"]);
    // Folders with missions of their own.
    let projects = |d: &Path| d == Path::new("/w/a/other") || d == Path::new("/w/a");
    let sees = |r: &Roots, m: &Path, f: &Path| sees(r, projects, None, m, f);
    let m = Path::new("/w/a/m.mission");
    // Its folder and below.
    assert!(sees(&r, m, Path::new("/w/a/x.robot.xml")));
    assert!(sees(&r, m, Path::new("/w/a/robots/x.robot.xml")));
    // Directly in the folders above, up to the root.
    assert!(sees(&r, m, Path::new("/w/x.robot.xml")));
    // Not a sibling folder, not another branch above, not above the root.
    assert!(!sees(&r, m, Path::new("/w/b/x.robot.xml")));
    assert!(!sees(&r, m, Path::new("/w/b/c/x.robot.xml")));
    assert!(!sees(&r, m, Path::new("/x.robot.xml")));
    // Under no root, its own folder is the root.
    assert!(!sees(&roots(&[]), m, Path::new("/w/x.robot.xml")));
    assert!(sees(&roots(&[]), m, Path::new("/w/a/b/x.robot.xml")));
    // The innermost root holding the file counts.
    assert!(!sees(
        &roots(&["/w", "/w/a"]),
        m,
        Path::new("/w/x.robot.xml")
    ));
    // Files named for all (`semo build --strategy`).
    let all = Roots {
        roots: vec![PathBuf::from("/w")],
        seen_by_all: vec![PathBuf::from("/elsewhere")],
    };
    assert!(sees(&all, m, Path::new("/elsewhere/s/x.strategy.xml")));
    // Not into a folder below that is a project of its own.
    assert!(!sees(&r, m, Path::new("/w/a/other/x.robot.xml")));
    assert!(!sees(&r, m, Path::new("/w/a/other/robots/x.robot.xml")));
    // Down to SEEN_DEPTH folders below its own, no deeper.
    assert!(sees(&r, m, Path::new("/w/a/1/2/3/x.robot.xml")));
    assert!(!sees(&r, m, Path::new("/w/a/1/2/3/4/x.robot.xml")));
}

#[test]
fn under_a_project_file_a_file_sees_the_folders_it_names_and_nothing_else() {
    let text = "[project]\ncatalogs = [\"robots\", \"../common\"]\nstrategies = [\"s\"]\n";
    let (project, diagnostics) = crate::project::parse(FileId(0), Path::new("/w/p"), text);
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    let r = roots(&["/w"]);
    let sees = |m: &str, f: &str| sees(&r, |_| false, Some(&project), Path::new(m), Path::new(f));
    let m = "/w/p/missions/m.mission";
    assert!(sees(m, "/w/p/robots/deep/down/below/x.robot.xml"));
    assert!(sees(m, "/w/common/x.robot.xml"));
    assert!(sees(m, "/w/p/s/x.strategy.xml"));
    // A strategy file in a catalog folder, a catalog beside the mission,
    // one in the project root: not named, not seen.
    assert!(!sees(m, "/w/p/robots/x.strategy.xml"));
    assert!(!sees(m, "/w/p/missions/x.robot.xml"));
    assert!(!sees(m, "/w/p/x.robot.xml"));
}

const MISSION: &str = "{ A: Turtlebot3_Burger tb }\n\
    A.P.S { move(\"1,1\") }\n\
    A.M { set(P, S) }\n\
    A.main { default: mode = M }\n";

const CATALOG: &str = r#"<?xml version="1.0"?>
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Service name="dig" task="dig_task"/>
  </Robot>
</Catalog>
"#;

fn host_with(files: &[(u32, &str, FileKind, &str)]) -> AnalysisHost {
    let mut host = AnalysisHost::new(roots(&["/w"]));
    for &(id, path, kind, text) in files {
        host.set_file(FileId(id), Some(PathBuf::from(path)), kind, text.into());
    }
    host
}

#[test]
fn sibling_folders_do_not_share_catalogs() {
    let dig = "{ T: Rover r }\nT.P.S { dig() } repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n";
    let host = host_with(&[
        (0, "/w/a/dig.mission", FileKind::Mission, dig),
        (1, "/w/a/rover.robot.xml", FileKind::Catalog, CATALOG),
        (2, "/w/b/dig.mission", FileKind::Mission, dig),
    ]);
    let analysis = host.analysis();
    assert_eq!(analysis.diagnostics(FileId(0)), Vec::new());
    assert_eq!(analysis.reads(FileId(0)), vec![FileId(0), FileId(1)]);
    let codes: Vec<Code> = analysis
        .diagnostics(FileId(2))
        .iter()
        .map(|d| d.code)
        .collect();
    assert!(codes.contains(&Code::UnknownRobotType), "{codes:?}");
    assert_eq!(analysis.reads(FileId(2)), vec![FileId(2)]);
}

#[test]
fn an_edit_recomputes_only_what_reads_the_edited_file() {
    let mut host = host_with(&[
        (0, "/w/a/one.mission", FileKind::Mission, MISSION),
        (1, "/w/a/two.mission", FileKind::Mission, MISSION),
        (2, "/w/a/rover.robot.xml", FileKind::Catalog, CATALOG),
    ]);
    let before = host.analysis();
    let (one, two, catalog) = (
        before.mission(FileId(0)).unwrap(),
        before.mission(FileId(1)).unwrap(),
        before.catalog(FileId(0)),
    );
    host.set_file(
        FileId(0),
        Some(PathBuf::from("/w/a/one.mission")),
        FileKind::Mission,
        MISSION.replace("1,1", "2,2").into(),
    );
    let after = host.analysis();
    assert!(Arc::ptr_eq(&catalog, &after.catalog(FileId(0))));
    assert!(Arc::ptr_eq(&two, &after.mission(FileId(1)).unwrap()));
    assert!(!Arc::ptr_eq(&one, &after.mission(FileId(0)).unwrap()));
    // Parsed from the previous version's cache: one chunk of four.
    let cache = after.parse_cache(FileId(0)).unwrap();
    assert_eq!((cache.chunks(), cache.reparsed()), (4, 1));
    // A catalog change reaches the missions that see it, not the others.
    assert_eq!(
        after.affected_by(FileId(2)),
        vec![FileId(0), FileId(1), FileId(2)]
    );
    assert_eq!(after.affected_by(FileId(0)), vec![FileId(0)]);
}

#[test]
fn a_host_without_parse_caches_checks_alike_and_keeps_no_cache() {
    let files = [
        (0, "/w/a/one.mission", FileKind::Mission, MISSION),
        (1, "/w/a/rover.robot.xml", FileKind::Catalog, CATALOG),
    ];
    let cached = host_with(&files).analysis();
    let mut host = AnalysisHost::new(roots(&["/w"])).without_parse_caches();
    for &(id, path, kind, text) in &files {
        host.set_file(FileId(id), Some(PathBuf::from(path)), kind, text.into());
    }
    let once = host.analysis();
    assert_eq!(
        once.mission(FileId(0)).unwrap().syntax,
        cached.mission(FileId(0)).unwrap().syntax
    );
    assert_eq!(once.diagnostics(FileId(0)), cached.diagnostics(FileId(0)));
    assert!(cached.parse_cache(FileId(0)).is_some());
    assert!(once.parse_cache(FileId(0)).is_none());
}

#[test]
fn the_build_input_carries_the_diagnostics_of_every_file_the_mission_reads() {
    let broken = CATALOG.replace("</Catalog>", "");
    let host = host_with(&[
        (0, "/w/a/one.mission", FileKind::Mission, MISSION),
        (1, "/w/a/rover.robot.xml", FileKind::Catalog, &broken),
    ]);
    let analysis = host.analysis();
    let catalog_errors = analysis.diagnostics(FileId(1));
    assert!(catalog_errors.iter().any(Diagnostic::is_error));
    let build = analysis.build_input(FileId(0)).unwrap();
    for d in &catalog_errors {
        assert!(build.diagnostics.contains(d), "{d:?}");
    }
    assert!(analysis.build_input(FileId(1)).is_none());
}

#[test]
fn an_unsaved_document_sees_the_workspace_roots_catalogs() {
    let dig = "{ T: Rover r }\nT.P.S { dig() } repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n";
    let mut host = host_with(&[(1, "/w/rover.robot.xml", FileKind::Catalog, CATALOG)]);
    host.set_file(FileId(0), None, FileKind::Mission, dig.into());
    let analysis = host.analysis();
    assert_eq!(analysis.diagnostics(FileId(0)), Vec::new());
    assert_eq!(analysis.reads(FileId(0)), vec![FileId(0), FileId(1)]);
    // A change of that catalog re-checks it.
    assert!(analysis.affected_by(FileId(1)).contains(&FileId(0)));
    // With no workspace root it sees only the built-in catalog.
    let mut alone = AnalysisHost::default();
    alone.set_file(FileId(0), None, FileKind::Mission, dig.into());
    let codes: Vec<Code> = alone
        .analysis()
        .diagnostics(FileId(0))
        .iter()
        .map(|d| d.code)
        .collect();
    assert!(codes.contains(&Code::UnknownRobotType), "{codes:?}");
}

#[test]
fn a_project_file_in_the_host_decides_what_is_seen_and_at_which_level() {
    use crate::diag::Severity;
    // W010: a function never called; W002: a mode never reached.
    let warned = "{ T: Rover r }\ndef f{\n  dig()\n}\nT.P.S { dig() } repeat()\nT.M { set(P, S) }\nT.N { set(P, OFF) }\nT.main { default: mode = M }\n";
    let mut host = host_with(&[
        (0, "/w/p/m/dig.mission", FileKind::Mission, warned),
        (1, "/w/p/robots/rover.robot.xml", FileKind::Catalog, CATALOG),
    ]);
    let levels = |analysis: &Analysis| -> Vec<(Code, Severity)> {
        analysis
            .diagnostics(FileId(0))
            .iter()
            .map(|d| (d.code, d.severity))
            .collect()
    };
    // Without a project file, the catalog in the sibling folder is not seen.
    let before = host.analysis();
    assert!(levels(&before).contains(&(Code::UnknownRobotType, Severity::Error)));
    let project =
        "[project]\ncatalogs = [\"robots\"]\n[lints]\nW010 = \"allow\"\nW002 = \"deny\"\n";
    host.set_file(
        FileId(2),
        Some(PathBuf::from("/w/p/semo.toml")),
        FileKind::Project,
        project.into(),
    );
    let after = host.analysis();
    assert_eq!(levels(&after), [(Code::UnreachableMode, Severity::Error)]);
    assert_eq!(after.reads(FileId(0)), [FileId(0), FileId(1), FileId(2)]);
    assert_eq!(after.project(FileId(0)).unwrap().file, FileId(2));
    // A project file change affects every file.
    assert_eq!(
        after.affected_by(FileId(2)),
        [FileId(0), FileId(1), FileId(2)]
    );
    // An unsaved project file is the project of no file.
    host.set_file(FileId(2), None, FileKind::Project, project.into());
    assert!(host.analysis().project(FileId(0)).is_none());
    host.remove_file(FileId(2));
    assert_eq!(levels(&host.analysis()), levels(&before));
}

/// The view answers what asking [`sees`] of every file answers, and is kept
/// across a keystroke but not across a new file.
#[test]
fn the_view_agrees_with_the_rule_and_lives_as_long_as_the_layout() {
    let mut host = AnalysisHost::new(roots(&["/w"]));
    let paths = [
        "/w/a/m.mission",
        "/w/a/x.robot.xml",
        "/w/a/robots/y.robot.xml",
        "/w/a/other/n.mission",
        "/w/a/other/z.robot.xml",
        "/w/a/1/2/3/4/deep.robot.xml",
        "/w/top.strategy.xml",
        "/w/b/k.mission",
        "/w/b/s.strategy.xml",
        "/w/ab/t.robot.xml",
        "/elsewhere/e.robot.xml",
    ];
    for (i, path) in paths.iter().enumerate() {
        let kind = FileKind::of(Path::new(path)).expect("a SeMo file");
        host.set_file(FileId(i as u32), Some(path.into()), kind, "".into());
    }
    let analysis = host.analysis();
    let folders = [
        "/w",
        "/w/a",
        "/w/a/other",
        "/w/b",
        "/w/ab",
        "/elsewhere",
        "/x",
    ];
    for folder in folders {
        let reader = Path::new(folder).join("_");
        let mut expected: Vec<(&Path, FileId)> = analysis
            .files()
            .filter(|f| matches!(f.kind, FileKind::Catalog | FileKind::Strategy))
            .filter_map(|f| Some((f.key.as_deref()?, f.id)))
            .filter(|(p, _)| analysis.sees(&reader, p))
            .collect();
        expected.sort();
        let expected: Vec<FileId> = expected.into_iter().map(|(_, id)| id).collect();
        assert_eq!(&*analysis.seen_ids(Path::new(folder)), expected, "{folder}");
    }
    // `/w/top.strategy.xml` is seen from /w/a, /w/a/other and /w/b.
    let seeing: Vec<FileId> = analysis.missions_seeing(FileId(6));
    assert_eq!(seeing, vec![FileId(0), FileId(3), FileId(7)]);

    // A keystroke keeps the view; a new file replaces it.
    let kept = host.analysis().view;
    host.set_file(
        FileId(0),
        Some(paths[0].into()),
        FileKind::Mission,
        "x".into(),
    );
    assert!(Arc::ptr_eq(&kept, &host.analysis().view));
    let path = PathBuf::from("/w/a/new.robot.xml");
    host.set_file(FileId(99), Some(path), FileKind::Catalog, "".into());
    assert!(!Arc::ptr_eq(&kept, &host.analysis().view));
}

/// Each robot's target in the build plan: the door's for every robot, else
/// the project file's for the robot (or its `name[N]` declaration), else for
/// its team, else `[build] target`, else its robot type's platform, else
/// linux; `sim` then simulates each; a `[build.targets]` name the mission
/// lacks is W110 on the project file.
#[test]
fn the_build_plan_gives_each_robot_its_target_and_says_why() {
    use crate::host::PlanRequest;
    use crate::platform::Target;
    use crate::targets::Reason;
    let mut host = AnalysisHost::new(roots(&["/w"]));
    let catalog = "<Catalog xmlns=\"urn:semo:catalog:1\">\n  <Robot type=\"Board\">\n    <Platform os=\"none\" target=\"cortex-m\"/>\n    <Service name=\"beep\" task=\"buzzer\"/>\n  </Robot>\n  <Robot type=\"Pc\">\n    <Service name=\"beep\" task=\"buzzer\"/>\n  </Robot>\n</Catalog>\n";
    let mission = "{\n  A: Board a, Pc p, Board many[2]\n  B: Board b\n}\nA.P.S{ beep() } repeat(1 SEC)\nA.M{ set(P, S) }\nA.main{ default: mode = M }\nB.P.S{ beep() } repeat(1 SEC)\nB.M{ set(P, S) }\nB.main{ default: mode = M }\n";
    let files: [(&str, FileKind, &str); 2] = [
        ("/w/p/robots/r.robot.xml", FileKind::Catalog, catalog),
        ("/w/p/m.mission", FileKind::Mission, mission),
    ];
    for (i, (path, kind, text)) in files.into_iter().enumerate() {
        host.set_file(FileId(i as u32), Some(path.into()), kind, text.into());
    }
    let mission_id = FileId(1);
    let plan = |host: &AnalysisHost, asked: PlanRequest| -> Vec<String> {
        let analysis = host.analysis();
        let plan = analysis.build_plan(mission_id, Path::new("/w/p/m.mission"), asked);
        let mut out: Vec<String> = plan
            .robots
            .iter()
            .map(|r| {
                let why = match &r.chosen.reason {
                    Reason::Asked => "asked".to_string(),
                    Reason::Project { key, .. } => format!("project {key}"),
                    Reason::Catalog { robot_type, .. } => format!("catalog {robot_type}"),
                    Reason::Default => "default".to_string(),
                };
                let sim = if r.chosen.simulated { " sim" } else { "" };
                format!("{}/{} {} ({why}{sim})", r.team, r.robot, r.chosen.target)
            })
            .collect();
        out.extend(plan.diagnostics.iter().map(|d| {
            let at = &analysis.file(d.file).unwrap().text[d.span.range()];
            format!("{} '{at}' {}", d.code, d.message)
        }));
        out
    };
    // No project file: the catalog's platform, else linux.
    assert_eq!(
        plan(&host, PlanRequest::default()),
        [
            "A/a cortex-m (catalog Board)",
            "A/p linux (default)",
            "A/many_0 cortex-m (catalog Board)",
            "A/many_1 cortex-m (catalog Board)",
            "B/b cortex-m (catalog Board)",
        ]
    );
    // `--sim`: each platform's simulation.
    let sim = PlanRequest {
        sim: true,
        ..PlanRequest::default()
    };
    assert_eq!(
        plan(&host, sim.clone()),
        [
            "A/a cortex-m-sim (catalog Board sim)",
            "A/p linux-sim (default sim)",
            "A/many_0 cortex-m-sim (catalog Board sim)",
            "A/many_1 cortex-m-sim (catalog Board sim)",
            "B/b cortex-m-sim (catalog Board sim)",
        ]
    );
    let project = "[project]\ncatalogs = [\"robots\"]\n[build]\ntarget = \"linux-sim\"\n[build.targets]\nA = \"cortex-m\"\np = \"linux\"\nmany = \"linux-sim\"\nmanny = \"linux\"\n";
    host.set_file(
        FileId(2),
        Some(PathBuf::from("/w/p/semo.toml")),
        FileKind::Project,
        project.into(),
    );
    // The robot (or its declaration) first, then its team, then every robot.
    assert_eq!(
        plan(&host, PlanRequest::default()),
        [
            "A/a cortex-m (project [build.targets] A)",
            "A/p linux (project [build.targets] p)",
            "A/many_0 linux-sim (project [build.targets] many)",
            "A/many_1 linux-sim (project [build.targets] many)",
            "B/b linux-sim (project [build] target)",
            "W110 'manny' `[build.targets]` names `manny`, which is no team or robot of m.mission: its target is not used (did you mean `many`?)",
        ]
    );
    // The door's target wins for every robot, and `sim` still applies.
    let asked = PlanRequest {
        target: Some(Target::CortexM),
        sim: true,
        ..PlanRequest::default()
    };
    let planned = plan(&host, asked);
    assert_eq!(
        planned[..2],
        [
            "A/a cortex-m-sim (asked sim)",
            "A/p cortex-m-sim (asked sim)"
        ]
    );
}
