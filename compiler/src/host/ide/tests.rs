//! The facade's position queries over small workspaces written as one
//! fixture (rust-analyzer's style): `//- /path` starts a file, `$0` marks the
//! cursor (exactly once). Each test shows that the query reaches the right
//! kind of file with what that kind reads from the workspace (the catalog
//! beside a mission, the missions that see a strategy file); the features
//! themselves are tested in `crate::ide`, the protocol in `semo-server`.

use crate::diag::FileId;
use crate::host::{AnalysisHost, Roots};
use crate::ide::{CompletionConfig, FilePosition, NavigationTarget};
use crate::text::{ColumnUnit, LineIndex};
use crate::workspace::FileKind;
use std::path::{Path, PathBuf};

struct Workspace {
    host: AnalysisHost,
    paths: Vec<String>,
    texts: Vec<String>,
    cursor: FilePosition,
}

/// The files of `fixture` in a host rooted at `/w`, and the cursor.
fn workspace(fixture: &str) -> Workspace {
    let mut host = AnalysisHost::new(Roots {
        roots: vec![PathBuf::from("/w")],
        seen_by_all: Vec::new(),
    });
    let (mut paths, mut texts, mut cursor) = (Vec::new(), Vec::new(), None);
    for chunk in fixture.split("//- ").filter(|c| !c.trim().is_empty()) {
        let (path, text) = chunk.split_once('\n').expect("a path line");
        let id = FileId(paths.len() as u32);
        let text = match text.find("$0") {
            Some(offset) => {
                assert!(cursor.is_none(), "one `$0` in the fixture");
                cursor = Some(FilePosition { file: id, offset });
                text.replacen("$0", "", 1)
            }
            None => text.to_string(),
        };
        let kind = FileKind::of(Path::new(path)).expect("a SeMo file name");
        host.set_file(id, Some(PathBuf::from(path)), kind, text.as_str().into());
        paths.push(path.to_string());
        texts.push(text);
    }
    Workspace {
        host,
        paths,
        texts,
        cursor: cursor.expect("a `$0` in the fixture"),
    }
}

impl Workspace {
    /// `path:line:col text` of each target.
    fn show(&self, targets: &[NavigationTarget]) -> String {
        targets
            .iter()
            .map(|t| {
                let text = &self.texts[t.file.0 as usize];
                let lc = LineIndex::new(text).line_col(text, t.span.start, ColumnUnit::Utf8);
                let path = &self.paths[t.file.0 as usize];
                format!(
                    "{path}:{}:{} {}",
                    lc.line + 1,
                    lc.col + 1,
                    &text[t.span.range()]
                )
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn hover(&self) -> String {
        let found = self.host.analysis().hover(self.cursor).expect("a hover");
        let text = &self.texts[self.cursor.file.0 as usize];
        format!("[{}]\n{}", &text[found.range.range()], found.markdown)
    }

    /// The labels of the completions, in order.
    fn completion_labels(&self) -> Vec<String> {
        let config = CompletionConfig { snippets: false };
        let items = self.host.analysis().completions(self.cursor, config);
        items
            .expect("completion in this file")
            .into_iter()
            .map(|i| i.label)
            .collect()
    }

    fn definition(&self) -> String {
        self.show(&self.host.analysis().definition(self.cursor))
    }
}

const MISSION: &str = "//- /w/a/m.mission
{ A: Rover r }
A.P.S { dig() } repeat(1 SEC)
A.M { set(P, S) }
A.main { default: mode = M }
";

const CATALOG: &str = r#"//- /w/a/rover.robot.xml
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Service name="dig" task="dig_task" doc="Digs a hole."/>
  </Robot>
</Catalog>
"#;

const STRATEGY: &str = r#"//- /w/a/A.strategy.xml
<Strategy name="A" xmlns="urn:semo:strategy:1">
  <ServiceInfo>
    <Service plan_name="P" name="dig">
      <TargetRobot name="Rover"/>
    </Service>
  </ServiceInfo>
</Strategy>
"#;

#[test]
fn hover_in_a_mission_reads_the_catalog_beside_it() {
    let w = workspace(&format!(
        "{}{CATALOG}",
        MISSION.replace("{ dig() }", "{ d$0ig() }")
    ));
    let hover = w.hover();
    assert!(hover.starts_with("[dig]\n"), "{hover}");
    assert!(hover.contains("Digs a hole."), "{hover}");
}

#[test]
fn hover_in_a_strategy_file_and_a_task_graph() {
    let w = workspace(&format!(
        "{MISSION}{CATALOG}{}",
        STRATEGY.replace("<Service plan", "<Serv$0ice plan")
    ));
    assert!(w.hover().starts_with("[Service]\n"), "{}", w.hover());
    let w = workspace(
        r#"//- /w/g.taskgraph.xml
<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A" trigger="time" period="100 MSEC"><Port name="o" dir="out" rate="2"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B$0.i"/>
</TaskGraph>
"#,
    );
    let hover = w.hover();
    assert!(hover.starts_with("[B.i]\n"), "{hover}");
}

#[test]
fn completion_dispatches_by_kind_of_file() {
    // A mission: the services its robots' type provides, from the catalog.
    let w = workspace(&format!(
        "{}{CATALOG}",
        MISSION.replace("{ dig() }", "{ d$0 }")
    ));
    assert!(w.completion_labels().contains(&"dig".to_string()));
    // A strategy file: the plans of the missions that see it.
    let w = workspace(&format!(
        "{MISSION}{CATALOG}{}",
        STRATEGY.replace("plan_name=\"P\"", "plan_name=\"$0\"")
    ));
    assert_eq!(w.completion_labels(), vec!["P"]);
    // A task graph: the output ports for a channel's source.
    let w = workspace(
        r#"//- /w/g.taskgraph.xml
<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A"><Port name="o" dir="out"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="$0" dst="B.i"/>
</TaskGraph>
"#,
    );
    assert_eq!(w.completion_labels(), vec!["A.o"]);
    // A project file: in `[build.targets]`, the teams and robots of the
    // missions under it (not of a mission of another project).
    let w = workspace(&format!(
        "{MISSION}{CATALOG}//- /w/a/semo.toml\n[build.targets]\n$0\n//- /w/b/n.mission\n{{ B: Rover q }}\n"
    ));
    assert_eq!(w.completion_labels(), vec!["A", "r"]);
    // A catalog file has none.
    let w = workspace(&CATALOG.replace("<Robot", "<$0Robot"));
    let config = CompletionConfig::default();
    assert_eq!(w.host.analysis().completions(w.cursor, config), None);
}

#[test]
fn definition_of_a_call_leads_to_its_strategy_entry_then_to_the_catalog() {
    let w = workspace(&format!(
        "{}{CATALOG}{STRATEGY}",
        MISSION.replace("{ dig() }", "{ d$0ig() }")
    ));
    insta::assert_snapshot!(w.definition(), @r#"
    /w/a/A.strategy.xml:3:34 dig
    /w/a/rover.robot.xml:3:5 <Service name="dig" task="dig_task" doc="Digs a hole."/>
    "#);
}

#[test]
fn definition_in_a_strategy_file_leads_to_the_mission_lines() {
    let w = workspace(&format!(
        "{MISSION}{CATALOG}{}",
        STRATEGY.replace("name=\"dig\"", "name=\"d$0ig\"")
    ));
    insta::assert_snapshot!(w.definition(), @"/w/a/m.mission:2:9 dig");
}

#[test]
fn a_strategy_in_a_sibling_folder_is_not_a_definition() {
    let w = workspace(&format!(
        "{}{CATALOG}{}",
        MISSION.replace("{ dig() }", "{ d$0ig() }"),
        STRATEGY.replace("/w/a/", "/w/b/")
    ));
    insta::assert_snapshot!(w.definition(), @r#"/w/a/rover.robot.xml:3:5 <Service name="dig" task="dig_task" doc="Digs a hole."/>"#);
}

#[test]
fn references_of_a_strategy_entry_are_its_name_and_the_calls_it_refines() {
    let w = workspace(&format!(
        "{MISSION}{CATALOG}{}",
        STRATEGY.replace("name=\"dig\"", "name=\"d$0ig\"")
    ));
    let found = w.host.analysis().references(w.cursor, true);
    insta::assert_snapshot!(w.show(&found), @r"
    /w/a/A.strategy.xml:3:34 dig
    /w/a/m.mission:2:9 dig
    ");
    let found = w.host.analysis().references(w.cursor, false);
    insta::assert_snapshot!(w.show(&found), @"/w/a/m.mission:2:9 dig");
}

#[test]
fn rename_in_a_mission_is_a_change_of_that_mission() {
    let w = workspace(&format!(
        "{}{CATALOG}",
        MISSION.replace("A.M { set(P, S) }", "A.M { set($0P, S) }")
    ));
    let change = w.host.analysis().rename(w.cursor, "Q").expect("a mission");
    let change = change.expect("a valid rename");
    let [(file, edits)] = &change.edits[..] else {
        panic!("one file: {change:?}");
    };
    assert_eq!(*file, w.cursor.file);
    let targets: Vec<NavigationTarget> = edits
        .iter()
        .map(|e| NavigationTarget {
            file: *file,
            span: e.span,
        })
        .collect();
    insta::assert_snapshot!(w.show(&targets), @r"
    /w/a/m.mission:2:3 P
    /w/a/m.mission:3:11 P
    ");
    assert!(edits.iter().all(|e| e.new_text == "Q"));
    let refused = w.host.analysis().rename(w.cursor, "not a name");
    assert!(matches!(refused, Some(Err(_))), "{refused:?}");
}

#[test]
fn structure_queries_answer_for_missions_and_nothing_for_other_files() {
    let w = workspace(&format!(
        "{}{CATALOG}{STRATEGY}",
        MISSION.replace("A.M { set", "A.$0M { set")
    ));
    let analysis = w.host.analysis();
    let mission = w.cursor.file;
    let text = &w.texts[mission.0 as usize];
    // The mode `M`: its definition is a write; `mode = M` a read.
    let highlights: Vec<String> = analysis
        .highlights(w.cursor)
        .iter()
        .map(|r| {
            format!(
                "{}@{} {:?}",
                &text[r.span.start..r.span.end],
                r.span.start,
                r.access
            )
        })
        .collect();
    insta::assert_snapshot!(highlights.join("\n"), @r"
    M@47 Write
    M@88 Read
    ");
    let selection = analysis.selection_ranges(w.cursor);
    assert_eq!(
        selection.last().map(|s| s.len()),
        Some(text.len()),
        "ends at the file"
    );
    // A strategy file has none of these (its outline is separate).
    let strategy = FilePosition {
        file: FileId(2),
        offset: 10,
    };
    assert!(analysis.highlights(strategy).is_empty());
    assert!(analysis.selection_ranges(strategy).is_empty());
    assert!(analysis.folding_ranges(FileId(2)).is_empty());
}

/// `path:line:col label` of each hint.
fn show_hints(w: &Workspace, hints: &[crate::ide::InlayHint], file: FileId) -> String {
    let targets: Vec<NavigationTarget> = hints
        .iter()
        .map(|h| NavigationTarget {
            file,
            span: crate::span::Span::new(h.offset, h.offset),
        })
        .collect();
    w.show(&targets)
        .lines()
        .zip(hints)
        .map(|(place, h)| format!("{place}{} {:?}", h.label, h.kind))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn a_quick_fix_points_at_the_diagnostic_as_published() {
    // A mission and a strategy file: the fix of the mission's did-you-mean
    // names its diagnostic among the file's published diagnostics.
    let w = workspace(&format!(
        "{}{CATALOG}{STRATEGY}",
        MISSION.replace("{ dig() }", "{ $0dgi() }")
    ));
    let analysis = w.host.analysis();
    let file = w.cursor.file;
    let at = crate::span::Span::new(w.cursor.offset, w.cursor.offset);
    let actions = analysis.code_actions(file, at);
    assert!(!actions.is_empty(), "a fix for `dgi`");
    let published = analysis.diagnostics(file);
    for action in &actions {
        let d = &published[action.diagnostic];
        assert!(d.span.touches(w.cursor.offset), "{d:?} for {action:?}");
    }
    assert!(
        actions.iter().any(|a| a.edits[0].new_text == "dig"),
        "{actions:?}"
    );
    // A strategy file: its own fixes (a misspelt element).
    let w = workspace(&format!(
        "{MISSION}{CATALOG}{}",
        STRATEGY.replace("<TargetRobot", "<$0TargetRobt")
    ));
    let analysis = w.host.analysis();
    let at = crate::span::Span::new(w.cursor.offset, w.cursor.offset + 1);
    let actions = analysis.code_actions(w.cursor.file, at);
    let published = analysis.diagnostics(w.cursor.file);
    assert!(!actions.is_empty(), "{published:?}");
    assert!(actions.iter().all(|a| a.diagnostic < published.len()));
}

#[test]
fn the_entry_of_a_call_is_created_in_each_strategy_file_the_mission_sees() {
    let bare = STRATEGY.replace(
        r#"    <Service plan_name="P" name="dig">
      <TargetRobot name="Rover"/>
    </Service>
"#,
        "",
    );
    let w = workspace(&format!(
        "{}{CATALOG}{bare}{}",
        MISSION.replace("{ dig() }", "{ d$0ig() }"),
        bare.replace("/w/a/", "/w/b/")
    ));
    let assists = w.host.analysis().assists(w.cursor);
    let [assist] = &assists[..] else {
        panic!("one assist, in the strategy file beside the mission: {assists:?}");
    };
    let [(file, edits)] = &assist.change.edits[..] else {
        panic!("one file: {assist:?}");
    };
    assert_eq!(w.paths[file.0 as usize], "/w/a/A.strategy.xml");
    assert!(edits[0].new_text.contains("name=\"dig\""), "{edits:?}");
    // Refined already: nothing to create.
    let w = workspace(&format!(
        "{}{CATALOG}{STRATEGY}",
        MISSION.replace("{ dig() }", "{ d$0ig() }")
    ));
    assert_eq!(w.host.analysis().assists(w.cursor), Vec::new());
}

#[test]
fn the_outline_of_a_mission_and_of_a_strategy_file() {
    let w = workspace(&format!(
        "{CATALOG}{STRATEGY}{}",
        MISSION.replace("{ A", "{$0 A")
    ));
    let analysis = w.host.analysis();
    let show = |nodes: &[crate::ide::StructureNode]| {
        fn walk(nodes: &[crate::ide::StructureNode], depth: usize, out: &mut String) {
            for n in nodes {
                out.push_str(&format!("{}{:?} {}\n", "  ".repeat(depth), n.kind, n.name));
                walk(&n.children, depth + 1, out);
            }
        }
        let mut out = String::new();
        walk(nodes, 0, &mut out);
        out
    };
    insta::assert_snapshot!(show(&analysis.document_symbols(w.cursor.file)), @r"
    Team A
      Robot r
      Plan P
        Service S
      Mode M
      Main main
    ");
    insta::assert_snapshot!(show(&analysis.document_symbols(FileId(1))), @"Service P.dig");
    assert_eq!(analysis.document_symbols(FileId(0)), Vec::new());
}

#[test]
fn workspace_symbols_search_every_mission() {
    let other = MISSION
        .replace("/w/a/m.mission", "/w/b/n.mission")
        .replace("A.", "B.")
        .replace("{ A:", "{ B:");
    let w = workspace(&format!(
        "{CATALOG}{other}{}",
        MISSION.replace("{ A", "{$0 A")
    ));
    let found = w.host.analysis().workspace_symbols("m");
    let targets: Vec<NavigationTarget> = found.iter().map(|s| s.target).collect();
    insta::assert_snapshot!(w.show(&targets), @r"
    /w/a/m.mission:3:3 M
    /w/b/n.mission:3:3 M
    ");
}

#[test]
fn inlay_hints_in_a_mission_and_a_task_graph() {
    let w = workspace(&format!("{CATALOG}{}", MISSION.replace("{ A", "{$0 A")));
    let all = crate::span::Span::new(0, w.texts[1].len());
    let hints = w.host.analysis().inlay_hints(w.cursor.file, all);
    insta::assert_snapshot!(show_hints(&w, &hints, w.cursor.file), @"/w/a/m.mission:3:15 : repeat(1 SEC) Schedule");
    let w = workspace(
        r#"//- /w/g.taskgraph.xml
<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A$0"><Port name="o" dir="out" rate="2"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>
"#,
    );
    let all = crate::span::Span::new(0, w.texts[0].len());
    let hints = w.host.analysis().inlay_hints(w.cursor.file, all);
    insta::assert_snapshot!(show_hints(&w, &hints, w.cursor.file), @r"
    /w/g.taskgraph.xml:2:17 ×1 Repetitions
    /w/g.taskgraph.xml:3:17 ×2 Repetitions
    ");
    // Only those in the range asked for.
    let first_line = crate::span::Span::new(0, w.cursor.offset + 2);
    assert_eq!(
        w.host
            .analysis()
            .inlay_hints(w.cursor.file, first_line)
            .len(),
        1
    );
}

#[test]
fn semantic_tokens_formatting_and_prepare_rename_are_for_missions() {
    let w = workspace(&format!(
        "{CATALOG}{}",
        MISSION.replace("A.M { set", "A.$0M  { set")
    ));
    let analysis = w.host.analysis();
    let mission = w.cursor.file;
    let text = &w.texts[mission.0 as usize];
    let tokens = analysis.semantic_tokens(mission, None).expect("a mission");
    assert!(
        tokens.iter().any(|t| &text[t.span.range()] == "M"),
        "{tokens:?}"
    );
    assert_eq!(analysis.semantic_tokens(FileId(0), None), None);
    let edits = analysis
        .formatting(mission)
        .expect("a mission")
        .expect("formats");
    let mut formatted = text.clone();
    for e in edits.iter().rev() {
        formatted.replace_range(e.span.range(), &e.new_text);
    }
    assert!(formatted.contains("A.M {"), "{formatted}");
    assert_eq!(analysis.formatting(FileId(0)), None);
    let span = analysis
        .prepare_rename(w.cursor)
        .expect("a mission")
        .expect("a mode");
    assert_eq!(&text[span.range()], "M");
    let on_catalog_name = FilePosition {
        file: mission,
        offset: text.find("Rover").unwrap(),
    };
    assert!(matches!(
        analysis.prepare_rename(on_catalog_name),
        Some(Err(_))
    ));
}

#[test]
fn a_picture_for_task_graphs_and_missions_only() {
    let w = workspace(&format!("{CATALOG}{}", MISSION.replace("{ A", "{$0 A")));
    let analysis = w.host.analysis();
    let svg = analysis.picture(w.cursor.file, None).expect("modes");
    assert!(svg.starts_with("<svg") && svg.contains(">M<"), "{svg}");
    assert!(analysis.picture(w.cursor.file, Some("A")).is_ok());
    let refused = analysis.picture(w.cursor.file, Some("Z")).unwrap_err();
    assert_eq!(refused.0, "no team `Z` with modes in this mission");
    assert!(analysis.picture(FileId(0), None).is_err());
}
