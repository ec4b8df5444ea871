use super::*;
use crate::diag::{Code, Diagnostic, FileId, Severity};
use crate::span::Span;
use std::path::Path;

const FILE: FileId = FileId(7);

fn read(text: &str) -> (Project, Vec<Diagnostic>) {
    parse(FILE, Path::new("/p"), text)
}

/// `CODE 'written text' message` per diagnostic.
fn listing(text: &str, diagnostics: &[Diagnostic]) -> Vec<String> {
    diagnostics
        .iter()
        .map(|d| {
            format!(
                "{} '{}' {}",
                d.code,
                &text[d.span.start..d.span.end],
                d.message
            )
        })
        .collect()
}

#[test]
fn a_full_project_file_is_read() {
    let text = r#"
[project]
version = 1
name = "scouting"
catalogs = ["robots", "../common/robots"]
strategies = ["./strategies"]
task-graphs = ["graphs"]

[build]
output = "gen"
target = "linux-sim"
deployment = "field.deploy.toml"

[lints]
W007 = "allow"
W001 = "deny"
W009 = "warn"
E019 = "deny"
"#;
    let (project, diagnostics) = read(text);
    assert_eq!(listing(text, &diagnostics), Vec::<String>::new());
    let paths = |ps: &[ProjectPath]| -> Vec<String> {
        ps.iter().map(|p| p.path.display().to_string()).collect()
    };
    assert_eq!(project.name.as_deref(), Some("scouting"));
    assert_eq!(paths(&project.catalogs), ["/p/robots", "/common/robots"]);
    assert_eq!(paths(&project.strategies), ["/p/strategies"]);
    assert_eq!(paths(&project.task_graphs), ["/p/graphs"]);
    assert_eq!(project.output.as_ref().unwrap().path, Path::new("/p/gen"));
    assert_eq!(
        project.deployment.as_ref().unwrap().path,
        Path::new("/p/field.deploy.toml")
    );
    assert_eq!(
        project.target.map(|t| t.target),
        Some(crate::platform::Target::LinuxSim)
    );
    assert_eq!(project.level(Code::UnknownAttribute), Some(Level::Allow));
    assert_eq!(project.level(Code::EventNeverCaught), Some(Level::Deny));
    assert_eq!(project.level(Code::ServiceNotProvided), Some(Level::Deny));
}

#[test]
fn an_empty_file_is_the_whole_project_with_defaults() {
    let (project, diagnostics) = read("");
    assert!(diagnostics.is_empty());
    assert_eq!(project, Project::new(Path::new("/p")));
    assert_eq!(project.catalogs[0].path, Path::new("/p"));
}

#[test]
fn every_mistake_is_positioned_in_the_file() {
    let text = r#"[project]
version = 2
catalogs = "robots"
catalog = ["s"]

[biuld]
target = "x"

[build]
target = "linux-simm"
output = 3

[lints]
W007 = "quiet"
E019 = "allow"
E010 = "warn"
W999 = "allow"
w001 = "allow"
"#;
    let (project, diagnostics) = read(text);
    insta::assert_snapshot!(listing(text, &diagnostics).join("\n"), @r#"
    E111 '2' format version 2 is not one this semo reads (it reads 1)
    E111 '"robots"' `catalogs` must be a list of folders, such as ["robots"]
    W110 'catalog' unknown key of [project] `catalog` (known: version, name, catalogs, strategies, task-graphs) (did you mean `catalogs`?)
    W110 'biuld' unknown table `biuld` (known: project, build, lints) (did you mean `build`?)
    E111 '"linux-simm"' unknown target `linux-simm` (targets: linux, linux-sim, cortex-m, cortex-m-sim, stm32f4, stm32f4-sim) (did you mean `linux-sim`?)
    E111 '3' `output` must be a string
    E111 '"quiet"' the level of W007 must be "allow", "warn" or "deny"
    E112 '"allow"' E019 is an error: it cannot be allowed or made a warning (only "deny")
    E112 '"warn"' E010 is an error: it cannot be allowed or made a warning (only "deny")
    W110 'W999' unknown diagnostic code `W999`
    W110 'w001' unknown diagnostic code `w001` (did you mean `W001`?)
    "#);
    // What was right is still read; what was wrong keeps its default.
    assert_eq!(project.catalogs, Project::new(Path::new("/p")).catalogs);
    assert!(project.lints.is_empty());
    assert_eq!(project.target, None);
}

#[test]
fn invalid_toml_is_one_positioned_error() {
    let text = "[project]\nname = \"unterminated\n";
    let (_, diagnostics) = read(text);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(diagnostics[0].code, Code::ProjectSyntax);
    assert!(diagnostics[0].span.start >= "[project]\n".len());
}

#[test]
fn lints_allow_drop_deny_raise_and_never_lower_an_error() {
    let (project, _) =
        read("[lints]\nW007 = \"allow\"\nW001 = \"deny\"\nW009 = \"warn\"\nE019 = \"allow\"\n");
    let at = |code: Code| Diagnostic::new(code, FILE, Span::new(0, 1), "x");
    let mut diagnostics = vec![
        at(Code::UnknownAttribute),
        at(Code::EventNeverCaught),
        at(Code::CatchNeverThrown),
        at(Code::ServiceNotProvided),
        at(Code::UnreachableMode),
    ];
    project.apply_lints(&mut diagnostics);
    let seen: Vec<(Code, Severity)> = diagnostics.iter().map(|d| (d.code, d.severity)).collect();
    assert_eq!(
        seen,
        [
            (Code::EventNeverCaught, Severity::Error),
            (Code::CatchNeverThrown, Severity::Warning),
            (Code::ServiceNotProvided, Severity::Error),
            (Code::UnreachableMode, Severity::Warning),
        ]
    );
}

#[test]
fn missing_folders_are_warnings_on_where_they_are_written() {
    let text = "[project]\ncatalogs = [\"robots\", \"gone\"]\n[build]\noutput = \"out\"\ndeployment = \"x.deploy.toml\"\n";
    let (project, _) = read(text);
    let there = |p: &Path| p == Path::new("/p/robots");
    let missing = project.missing_paths(FILE, there);
    assert_eq!(
        listing(text, &missing),
        [
            "W111 '\"gone\"' there is no folder `gone` in the project",
            "W111 '\"x.deploy.toml\"' there is no file `x.deploy.toml` in the project",
        ]
    );
    // Defaults (the root itself) are not written, so never reported.
    assert!(read("").0.missing_paths(FILE, |_| false).is_empty());
}

#[test]
fn find_walks_up_to_the_project_file_and_stops_at_a_repository_root() {
    let dir = tempfile_dir();
    let project = dir.join("proj");
    let deep = project.join("a/b/c");
    std::fs::create_dir_all(&deep).unwrap();
    assert_eq!(find(&deep), None);
    std::fs::write(dir.join(FILE_NAME), "").unwrap();
    // Above: found, as long as no repository root is on the way.
    assert_eq!(find(&deep).as_deref(), Some(dir.as_path()));
    std::fs::create_dir(project.join(".git")).unwrap();
    assert_eq!(find(&deep), None);
    std::fs::write(project.join(FILE_NAME), "").unwrap();
    assert_eq!(find(&deep).as_deref(), Some(project.as_path()));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn tempfile_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "semo-project-find-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The labels offered at `$0`.
fn offered(text: &str) -> Vec<String> {
    offered_with(text, &[])
}

/// The labels offered at `$0` in a project whose missions have `named`.
fn offered_with(text: &str, named: &[(&str, &str)]) -> Vec<String> {
    let offset = text.find("$0").unwrap();
    let text = text.replace("$0", "");
    let named: Vec<Named> = named
        .iter()
        .map(|(name, detail)| Named {
            name: name.to_string(),
            detail: detail.to_string(),
        })
        .collect();
    completions(&text, offset, &named)
        .into_iter()
        .map(|c| format!("{}→{}", c.label, c.insert))
        .collect()
}

#[test]
fn completion_offers_tables_keys_codes_and_values() {
    assert_eq!(
        offered("$0"),
        [
            "project→[project]",
            "build→[build]",
            "build.targets→[build.targets]",
            "lints→[lints]"
        ]
    );
    assert_eq!(
        offered("[bu$0"),
        [
            "project→project",
            "build→build",
            "build.targets→build.targets",
            "lints→lints"
        ]
    );
    assert_eq!(
        offered("[build]\nta$0"),
        [
            "output→output = ",
            "target→target = ",
            "deployment→deployment = "
        ]
    );
    assert_eq!(
        offered("[build]\ntarget = $0"),
        [
            "linux→\"linux\"",
            "linux-sim→\"linux-sim\"",
            "cortex-m→\"cortex-m\"",
            "cortex-m-sim→\"cortex-m-sim\"",
            "stm32f4→\"stm32f4\"",
            "stm32f4-sim→\"stm32f4-sim\""
        ]
    );
    let codes = offered("[project]\nversion = 1\n[lints]\nW0$0");
    // Warnings by code: `semo verify`'s V… before the checker's W….
    assert_eq!(codes[0], "V001→V001 = ");
    assert!(codes.contains(&"W001→W001 = ".to_string()));
    assert!(codes.contains(&"W007→W007 = ".to_string()));
    // Errors after warnings and hints.
    let first_error = codes.iter().position(|c| c.starts_with('E')).unwrap();
    assert!(codes[first_error..].iter().all(|c| c.starts_with('E')));
    assert_eq!(
        offered("[lints]\nW007 = \"$0\""),
        ["allow→allow", "warn→warn", "deny→deny"]
    );
    assert_eq!(offered("[lints]\nE019 = $0"), ["deny→\"deny\""]);
    assert!(offered("[project]\n# a comment $0").is_empty());
    // Keys and codes already written in the table are not offered again.
    assert_eq!(
        offered("[build]\ntarget = \"linux\"\n$0\noutput = \"out\"\n[project]\n"),
        ["deployment→deployment = "]
    );
    let codes = offered("[lints]\nW001 = \"allow\"\nW0$0");
    assert!(!codes.contains(&"W001→W001 = ".to_string()));
    assert!(codes.contains(&"W002→W002 = ".to_string()));
}

#[test]
fn completion_replaces_the_word_being_typed() {
    let text = "[lints]\nW00";
    let all = completions(text, text.len(), &[]);
    assert!(all.iter().all(|c| c.replace == Span::new(8, 11)));
}

#[test]
fn build_targets_give_teams_and_robots_their_own_target() {
    use crate::platform::Target;
    let text = r#"[build]
target = "linux-sim"

[build.targets]
Scouts = "cortex-m"
"ti" = "linux"
"#;
    let (project, diagnostics) = read(text);
    assert_eq!(listing(text, &diagnostics), Vec::<String>::new());
    let written: Vec<(String, &str, Target, &str)> = project
        .targets
        .iter()
        .map(|t| {
            (
                t.name.clone(),
                &text[t.name_span.start..t.name_span.end],
                t.target.target,
                &text[t.target.span.start..t.target.span.end],
            )
        })
        .collect();
    assert_eq!(
        written,
        [
            (
                "Scouts".to_string(),
                "Scouts",
                Target::CortexM,
                "\"cortex-m\""
            ),
            ("ti".to_string(), "\"ti\"", Target::Linux, "\"linux\""),
        ]
    );
    // The same as an inline table of `[build]`.
    let (inline, diagnostics) = read("[build]\ntargets = { Scouts = \"cortex-m\" }\n");
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    assert_eq!(inline.targets.len(), 1);
}

#[test]
fn build_targets_mistakes_are_positioned_with_a_did_you_mean() {
    let text = r#"[build]
targets = "cortex-m"
tagrets = 1
"#;
    let (_, diagnostics) = read(text);
    insta::assert_snapshot!(listing(text, &diagnostics).join("\n"), @r#"
    E111 '"cortex-m"' `targets` must be a table of team and robot names, `[build.targets]` with `Scouts = "cortex-m"`
    W110 'tagrets' unknown key of [build] `tagrets` (known: output, target, deployment, targets) (did you mean `targets`?)
    "#);
    let text = r#"[build.targets]
Scouts = "cortx-m"
ti = 3
"#;
    let (project, diagnostics) = read(text);
    insta::assert_snapshot!(listing(text, &diagnostics).join("\n"), @r#"
    E111 '"cortx-m"' unknown target `cortx-m` (targets: linux, linux-sim, cortex-m, cortex-m-sim, stm32f4, stm32f4-sim) (did you mean `cortex-m`?)
    E111 '3' the target of `ti` must be a string, such as "linux"
    "#);
    assert!(project.targets.is_empty());
}

#[test]
fn a_build_targets_name_the_mission_lacks_is_w110_with_a_did_you_mean() {
    let text = "[build.targets]\nScouts = \"cortex-m\"\ntii = \"linux\"\n";
    let (project, _) = read(text);
    let found = project.unknown_names(FILE, "scouting.mission", &["Scouts", "ti", "irobot"]);
    assert_eq!(
        listing(text, &found),
        [
            "W110 'tii' `[build.targets]` names `tii`, which is no team or robot of scouting.mission: its target is not used (did you mean `ti`?)"
        ]
    );
}

#[test]
fn completion_in_build_targets_offers_the_missions_names_and_the_targets() {
    let named = [
        ("Scouts", "team, m.mission"),
        ("ti", "robot of team Scouts (TIEvalbot), m.mission"),
    ];
    assert_eq!(
        offered_with("[build.targets]\nScouts = \"linux\"\n$0", &named),
        ["ti→ti = "]
    );
    assert_eq!(
        offered_with("[build.targets]\nti = $0", &named),
        [
            "linux→\"linux\"",
            "linux-sim→\"linux-sim\"",
            "cortex-m→\"cortex-m\"",
            "cortex-m-sim→\"cortex-m-sim\"",
            "stm32f4→\"stm32f4\"",
            "stm32f4-sim→\"stm32f4-sim\""
        ]
    );
}
