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
