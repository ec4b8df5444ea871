//! One test per warning, through the workspace analysis (`semo::host`) as
//! every door reaches it: a mission, a catalog whose service is implemented
//! by a task graph, and that graph, in a folder on disk (the catalog checks
//! that its `graph=` file exists).

use crate::diag::{Code, Diagnostic, FileId};
use crate::host::{AnalysisHost, Roots};
use crate::refine::Robots;
use crate::taskgraph::analysis::ratio::Ratio;
use crate::workspace::FileKind;
use std::path::PathBuf;
use std::sync::Arc;

const CATALOG: &str = r#"<?xml version="1.0"?>
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Rover">
    <Service name="scan" graph="graphs/scan.taskgraph.xml" doc="Scan the ground."/>
    <Service name="dig" task="dig_task"/>
  </Robot>
</Catalog>
"#;

/// A consistent graph: `A` then `B`, 30 and 50 ms; one firing of a task at
/// a time, so an iteration every 50 ms.
const TIMED: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="A" wcet="30"><Port name="o" dir="out"/></Task>
  <Task name="B" wcet="50"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>
"#;

const INCONSISTENT: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="A"><Port name="o1" dir="out"/><Port name="o2" dir="out"/></Task>
  <Task name="B"><Port name="i1" dir="in"/><Port name="i2" dir="in" rate="2"/></Task>
  <Channel src="A.o1" dst="B.i1"/>
  <Channel src="A.o2" dst="B.i2"/>
</TaskGraph>
"#;

const DEADLOCK: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="X"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>
  <Task name="Y"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>
  <Channel src="X.o" dst="Y.i"/>
  <Channel src="Y.o" dst="X.i"/>
</TaskGraph>
"#;

const SMALL_BUFFER: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="A"><Port name="o" dir="out" rate="2"/></Task>
  <Task name="B"><Port name="i" dir="in" rate="3"/></Task>
  <Channel src="A.o" dst="B.i" capacity="3"/>
</TaskGraph>
"#;

fn mission(body: &str) -> String {
    format!("{{ T: Rover r[2] }}\n{body}\nT.M {{ set(P, S) }}\nT.main {{ default: mode = M }}\n")
}

/// A folder on disk holding the three files, loaded into a host.
struct Workspace {
    dir: PathBuf,
    host: AnalysisHost,
}

const MISSION_ID: FileId = FileId(0);
const GRAPH_ID: FileId = FileId(2);

impl Workspace {
    fn new(name: &str, mission: &str, graph: &str) -> Workspace {
        Workspace::with_catalog(name, mission, CATALOG, graph)
    }

    fn with_catalog(name: &str, mission: &str, catalog: &str, graph: &str) -> Workspace {
        let dir = std::env::temp_dir().join(format!("semo-dataflow-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("graphs")).unwrap();
        let files = [
            (MISSION_ID, "m.mission", FileKind::Mission, mission),
            (FileId(1), "rover.robot.xml", FileKind::Catalog, catalog),
            (
                GRAPH_ID,
                "graphs/scan.taskgraph.xml",
                FileKind::TaskGraph,
                graph,
            ),
        ];
        let mut host = AnalysisHost::new(Roots {
            roots: vec![dir.clone()],
            seen_by_all: Vec::new(),
        });
        for (id, name, kind, text) in files {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            host.set_file(id, Some(path), kind, Arc::from(text));
        }
        Workspace { dir, host }
    }

    fn warnings(&self) -> Vec<Diagnostic> {
        let analysis = self.host.analysis();
        assert_eq!(
            analysis
                .diagnostics(MISSION_ID)
                .iter()
                .filter(|d| d.is_error())
                .count(),
            0,
            "{:#?}",
            analysis.diagnostics(MISSION_ID)
        );
        analysis.dataflow(MISSION_ID).unwrap().diagnostics.clone()
    }

    fn text_at(&self, mission: &str, d: &Diagnostic) -> String {
        mission[d.span.range()].to_string()
    }
}

impl Drop for Workspace {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn codes(found: &[Diagnostic]) -> Vec<Code> {
    found.iter().map(|d| d.code).collect()
}

#[test]
fn an_inconsistent_service_graph_is_reported_on_the_call() {
    let text = mission("T.P.S { dig()\n scan() }");
    let w = Workspace::new("inconsistent", &text, INCONSISTENT);
    let found = w.warnings();
    // Both robots call it on the same line: one warning.
    assert_eq!(codes(&found), [Code::DataflowInconsistent], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "scan()");
    assert!(found[0].message.contains("graphs/scan.taskgraph.xml"));
    // It points at the channel in the graph where the rates contradict.
    assert_eq!(found[0].related[0].file, GRAPH_ID);
    assert_eq!(
        &INCONSISTENT[found[0].related[0].span.range()],
        r#"<Channel src="A.o2" dst="B.i2"/>"#
    );
}

#[test]
fn a_deadlocking_service_graph_is_reported_on_the_call() {
    let text = mission("T.P.S { scan() }");
    let w = Workspace::new("deadlock", &text, DEADLOCK);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowDeadlock], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "scan()");
    assert!(
        found[0].message.contains("deadlock"),
        "{}",
        found[0].message
    );
}

#[test]
fn a_buffer_too_small_in_a_service_graph_is_reported_on_the_call() {
    let text = mission("T.P.S { scan() }");
    let w = Workspace::new("buffer", &text, SMALL_BUFFER);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowBufferTooSmall], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "scan()");
}

#[test]
fn a_repeat_period_shorter_than_the_graph_period_is_reported_on_the_period() {
    let text = mission("T.P.S { scan() } repeat(40 MSEC)");
    let w = Workspace::new("repeat", &text, TIMED);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowTooSlow], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "40 MSEC");
    assert!(found[0].message.contains("50 ms"), "{}", found[0].message);
    assert_eq!(&text[found[0].related[0].span.range()], "scan()");
}

#[test]
fn the_innermost_loop_period_is_the_one_asked_for() {
    // The repeat leaves 100 ms, but the loop asks for an iteration every 20.
    let text = mission("T.P.S { loop(20 MSEC) { scan() } } repeat(100 MSEC)");
    let w = Workspace::new("loop", &text, TIMED);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowTooSlow], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "20 MSEC");
}

#[test]
fn a_period_the_graph_keeps_up_with_gives_no_warning_and_each_robot_its_period() {
    let text = mission("T.P.S { loop(50 MSEC) { scan() } } repeat(60 MSEC)");
    let w = Workspace::new("fast-enough", &text, TIMED);
    assert_eq!(w.warnings(), Vec::new());
    let dataflow = w.host.analysis().dataflow(MISSION_ID).unwrap();
    let periods: Vec<(&str, Option<Ratio>)> = dataflow
        .robots
        .iter()
        .map(|r| (r.robot.as_str(), r.period))
        .collect();
    let fifty = Ratio::new(50, 1);
    assert_eq!(periods, [("r_0", fifty), ("r_1", fifty)]);
    assert_eq!(
        dataflow.robots[0].bounded_by,
        Some(("scan".to_string(), "graphs/scan.taskgraph.xml".to_string()))
    );
}

#[test]
fn a_robot_calling_no_service_graph_has_no_period() {
    let text = mission("T.P.S { dig() } repeat(10 MSEC)");
    let w = Workspace::new("no-graph", &text, TIMED);
    assert_eq!(w.warnings(), Vec::new());
    let dataflow = w.host.analysis().dataflow(MISSION_ID).unwrap();
    assert!(dataflow.robots.iter().all(|r| r.period.is_none()));
}

#[test]
fn a_mission_with_errors_is_not_refined_and_gives_no_dataflow() {
    let text = mission("T.P.S { scan() } repeat(40 MSEC)\nT.P.S { dig() }");
    let w = Workspace::new("errors", &text, TIMED);
    let analysis = w.host.analysis();
    assert!(
        analysis
            .diagnostics(MISSION_ID)
            .iter()
            .any(|d| d.is_error())
    );
    let dataflow = analysis.dataflow(MISSION_ID).unwrap();
    assert!(dataflow.diagnostics.is_empty() && dataflow.robots.is_empty());
}

#[test]
fn editing_the_graph_gives_a_new_answer_and_an_unchanged_workspace_the_same_one() {
    let text = mission("T.P.S { scan() } repeat(40 MSEC)");
    let mut w = Workspace::new("edit", &text, TIMED);
    let first = w.host.analysis().dataflow(MISSION_ID).unwrap();
    let again = w.host.analysis().dataflow_if_known(MISSION_ID).unwrap();
    assert!(Arc::ptr_eq(&first, &again));
    assert_eq!(codes(&first.diagnostics), [Code::DataflowTooSlow]);
    // The editor re-publishes the mission when the graph changes.
    assert!(
        w.host
            .analysis()
            .affected_by(GRAPH_ID)
            .contains(&MISSION_ID)
    );
    let faster = TIMED.replace("wcet=\"50\"", "wcet=\"40\"");
    w.host.set_file(
        GRAPH_ID,
        Some(w.dir.join("graphs/scan.taskgraph.xml")),
        FileKind::TaskGraph,
        Arc::from(faster.as_str()),
    );
    assert!(w.host.analysis().dataflow_if_known(MISSION_ID).is_none());
    assert_eq!(w.warnings(), Vec::new());
}

/// The refined mission is one memoised query: a second request on the same
/// files refines nothing (the same answer), an edit of what it reads gives
/// a new one, and a file that is no mission has none.
#[test]
fn the_refined_mission_is_computed_once_per_version_of_what_it_reads() {
    let text = mission("T.P.S { scan() } repeat(40 MSEC)");
    let mut w = Workspace::new("refined", &text, TIMED);
    let first = w.host.analysis().refined(MISSION_ID).unwrap();
    assert!(!first.programs.is_empty(), "{:#?}", first.diagnostics);
    let again = w.host.analysis().refined(MISSION_ID).unwrap();
    assert!(Arc::ptr_eq(&first, &again));
    assert!(w.host.analysis().refined(FileId(1)).is_none());
    let renamed = text.replace("T.P.S", "T.P.S ");
    w.host.set_file(
        MISSION_ID,
        Some(w.dir.join("m.mission")),
        FileKind::Mission,
        Arc::from(renamed.as_str()),
    );
    let edited = w.host.analysis().refined(MISSION_ID).unwrap();
    assert!(!Arc::ptr_eq(&first, &edited));
    assert_eq!(edited.programs.len(), first.programs.len());
}

#[test]
fn a_team_hover_lists_its_robots_periods() {
    let text = mission("T.P.S { scan() } repeat(60 MSEC)");
    let w = Workspace::new("hover", &text, TIMED);
    let analysis = w.host.analysis();
    let mission = analysis.mission(MISSION_ID).unwrap();
    let at_team = text.find("T:").unwrap();
    let periods = crate::dataflow::team_periods_at(&mission.mission, at_team, || {
        analysis.dataflow(MISSION_ID)
    });
    assert_eq!(
        periods.as_deref(),
        Some(
            "**Iteration period** (dataflow):\n\
             - `r_0`: 50 ms (`scan`: `graphs/scan.taskgraph.xml`)\n\
             - `r_1`: 50 ms (`scan`: `graphs/scan.taskgraph.xml`)"
        )
    );
    let at_call = text.find("scan()").unwrap();
    let asked = std::cell::Cell::new(false);
    let none = crate::dataflow::team_periods_at(&mission.mission, at_call, || {
        asked.set(true);
        analysis.dataflow(MISSION_ID)
    });
    assert_eq!(none, None);
    assert!(!asked.get(), "the dataflow is asked only on a team");
}

#[test]
fn a_team_without_timed_service_graphs_gets_no_period_section() {
    let text = mission("T.P.S { dig() }");
    let w = Workspace::new("hover-untimed", &text, TIMED);
    let analysis = w.host.analysis();
    let mission = analysis.mission(MISSION_ID).unwrap();
    let at_team = text.find("T:").unwrap();
    let periods = crate::dataflow::team_periods_at(&mission.mission, at_team, || {
        analysis.dataflow(MISSION_ID)
    });
    assert_eq!(periods, None);
}

#[test]
fn a_declaration_of_many_robots_is_analysed_once_with_the_same_answer_as_each_robot() {
    // `r[3]` and `t[2]` are refined once each (one robot per declaration):
    // the warning is still reported once, on the mission line, and every
    // robot has its period under its own name, in formation order.
    let text = "{ T: Rover r[3], Rover s, Rover t[2] }\nT.P.S { scan() } repeat(40 MSEC)\nT.M { set(P, S) }\nT.main { default: mode = M }\n";
    let w = Workspace::new("declarations", text, TIMED);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowTooSlow], "{found:#?}");
    assert_eq!(w.text_at(text, &found[0]), "40 MSEC");
    let analysis = w.host.analysis();
    let dataflow = analysis.dataflow(MISSION_ID).unwrap();
    let fifty = Ratio::new(50, 1);
    let periods: Vec<(&str, Option<Ratio>)> = dataflow
        .robots
        .iter()
        .map(|r| (r.robot.as_str(), r.period))
        .collect();
    assert_eq!(
        periods,
        [
            ("r_0", fifty),
            ("r_1", fifty),
            ("r_2", fifty),
            ("s", fifty),
            ("t_0", fifty),
            ("t_1", fifty)
        ]
    );
    // Exactly what analysing every robot's own program gives.
    let build = analysis.build_input(MISSION_ID).unwrap();
    let every_robot = crate::refine::refine_checked(&build.input());
    assert_eq!(every_robot.programs.len(), 6);
    let service_graph = |catalog: FileId, path: &str| analysis.service_graph(catalog, path);
    let from_every_robot = crate::dataflow::analyze(&crate::dataflow::DataflowInput {
        file: MISSION_ID,
        mission: &build.analysis.mission,
        catalog: &build.unit.catalog.catalog,
        programs: &every_robot.programs,
        service_graph: &service_graph,
    });
    assert_eq!(from_every_robot.diagnostics, dataflow.diagnostics);
    assert_eq!(from_every_robot.robots, dataflow.robots);
    assert_eq!(from_every_robot.graphs, dataflow.graphs);
    let refined = crate::refine::refine_checked_robots(&build.input(), Robots::OnePerDeclaration);
    let names: Vec<&str> = refined.programs.iter().map(|p| p.robot.as_str()).collect();
    assert_eq!(names, ["r_2", "s", "t_1"]);
}

#[test]
fn a_declaration_refused_for_its_last_robots_name_gives_no_dataflow() {
    // `x…x_9` is 64 characters, `x…x_10` 65: too long for a C identifier
    // (E101), which only the declaration's last robot shows.
    let base = "x".repeat(62);
    let text = mission("T.P.S { scan() } repeat(40 MSEC)").replace("r[2]", &format!("{base}[11]"));
    let w = Workspace::new("long-name", &text, TIMED);
    assert_eq!(w.warnings(), Vec::new());
    let analysis = w.host.analysis();
    assert!(analysis.dataflow(MISSION_ID).unwrap().robots.is_empty());
    let build = analysis.build_input(MISSION_ID).unwrap();
    let refused = crate::refine::refine_checked(&build.input());
    assert!(refused.programs.is_empty());
    assert!(
        refused
            .diagnostics
            .iter()
            .any(|d| d.code == Code::OutputNameEscapes),
        "{:#?}",
        refused.diagnostics
    );
}

/// `A` is time-triggered every 30 ms and fires twice per iteration (`B`
/// takes two samples); no execution times: only the period bounds it.
const TIME_TRIGGERED: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="A" trigger="time" period="30 MSEC"><Port name="o" dir="out"/></Task>
  <Task name="B"><Port name="i" dir="in" rate="2"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>
"#;

/// The same task inside a D-type loop of 4 iterations, with `B` taking
/// 50 ms: 4 × 30 = 120 ms beats the throughput's 50.
const TIME_TRIGGERED_IN_A_LOOP: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Loop name="L" type="D" loopCount="4">
    <Port name="o" dir="out" outerRate="4" innerRate="1"/>
    <TaskGraph name="L_body">
      <Task name="A" trigger="time" period="30 MSEC"><Port name="o" dir="out"/></Task>
      <Channel src="A.o" dst="L.o"/>
    </TaskGraph>
  </Loop>
  <Task name="B" wcet="50"><Port name="i" dir="in" rate="4"/></Task>
  <Channel src="L.o" dst="B.i"/>
</TaskGraph>
"#;

#[test]
fn a_repeat_shorter_than_a_time_triggered_tasks_firings_times_its_period_is_reported() {
    let text = mission("T.P.S { scan() } repeat(40 MSEC)");
    let w = Workspace::new("time-triggered", &text, TIME_TRIGGERED);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowTooSlow], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "40 MSEC");
    assert!(
        found[0].message.contains(
            "takes at least 60 ms per iteration (its time-triggered task `A` fires 2 times per iteration, at most once every 30 ms)"
        ),
        "{}",
        found[0].message
    );
    // It points at the task in the graph.
    let task = &found[0].related[1];
    assert_eq!(
        (task.file, &TIME_TRIGGERED[task.span.range()]),
        (GRAPH_ID, "A")
    );
    // 60 ms is enough: no warning, and the robots' period is the bound.
    let text = mission("T.P.S { scan() } repeat(60 MSEC)");
    let w = Workspace::new("time-triggered-enough", &text, TIME_TRIGGERED);
    assert_eq!(w.warnings(), Vec::new());
    let dataflow = w.host.analysis().dataflow(MISSION_ID).unwrap();
    assert_eq!(dataflow.robots[0].period, Ratio::new(60, 1));
}

#[test]
fn a_time_triggered_task_in_a_loop_counts_every_iteration() {
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let w = Workspace::new("time-triggered-loop", &text, TIME_TRIGGERED_IN_A_LOOP);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowTooSlow], "{found:#?}");
    assert!(
        found[0]
            .message
            .contains("at least 120 ms per iteration (its time-triggered task `L/A` fires 4 times"),
        "{}",
        found[0].message
    );
    let analysis = w.host.analysis();
    let mission = analysis.mission(MISSION_ID).unwrap();
    let periods =
        crate::dataflow::team_periods_at(&mission.mission, text.find("T:").unwrap(), || {
            analysis.dataflow(MISSION_ID)
        });
    assert!(
        periods
            .as_deref()
            .is_some_and(|p| p.contains("`r_0`: 120 ms (`scan`")),
        "{periods:?}"
    );
}

/// `scan`'s graph with a latency bound of `max` from `A` to `B`.
fn bounded_catalog(max: &str) -> String {
    CATALOG.replace(
        r#"doc="Scan the ground."/>"#,
        &format!(r#"doc="Scan the ground."><Latency from="A" to="B" max="{max}"/></Service>"#),
    )
}

/// `A` (30 ms) sets the pace, `B` (20 ms) follows: by hand, the minimal
/// latency from `A` to `B` is 30 + 20 = 50 ms, and the self-timed one too
/// (iteration k: `A` runs 30k..30k+30, `B` 30k+30..30k+50).
const PACED: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="A" wcet="30"><Port name="o" dir="out"/></Task>
  <Task name="B" wcet="20"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>
"#;

#[test]
fn a_latency_over_the_catalogs_bound_is_reported_on_the_call_with_its_numbers() {
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let w = Workspace::with_catalog("latency-over", &text, &bounded_catalog("49 MSEC"), PACED);
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowLatencyExceeded], "{found:#?}");
    assert_eq!(w.text_at(&text, &found[0]), "scan()");
    assert_eq!(
        found[0].message,
        "`scan` runs the task graph `graphs/scan.taskgraph.xml`, whose latency from `A` to `B` is over the 49 MSEC (49 ms) its catalog allows: minimal latency 50 ms, self-timed latency 50 ms"
    );
    let related: Vec<(FileId, &str)> = found[0]
        .related
        .iter()
        .map(|r| (r.file, r.message.as_str()))
        .collect();
    assert_eq!(
        related,
        [
            (FileId(1), "the bound, 49 MSEC (49 ms), is stated here"),
            (GRAPH_ID, "`A`, the path's source"),
            (GRAPH_ID, "`B`, the path's sink"),
        ]
    );
}

#[test]
fn a_latency_exactly_at_the_bound_holds_in_any_unit() {
    for max in ["50 MSEC", "0.05 SEC", "1 MIN"] {
        let text = mission("T.P.S { scan() } repeat(100 MSEC)");
        let w = Workspace::with_catalog("latency-holds", &text, &bounded_catalog(max), PACED);
        assert_eq!(w.warnings(), [], "{max}");
    }
    // A thousandth of a millisecond less is over it: the comparison is exact.
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let w = Workspace::with_catalog(
        "latency-exact",
        &text,
        &bounded_catalog("0.049999 SEC"),
        PACED,
    );
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowLatencyExceeded], "{found:#?}");
    assert!(
        found[0].message.contains("0.049999 SEC (49999/1000 ms)"),
        "{}",
        found[0].message
    );
}

#[test]
fn a_self_timed_latency_growing_without_bound_is_over_any_bound() {
    // `A` (30 ms) starts an iteration every 30 ms, `B` (50 ms) ends one
    // every 50: the minimal latency, 80 ms, is within 100 ms, but the
    // self-timed one grows every iteration.
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let w = Workspace::with_catalog(
        "latency-unbounded",
        &text,
        &bounded_catalog("100 MSEC"),
        TIMED,
    );
    let found = w.warnings();
    assert_eq!(codes(&found), [Code::DataflowLatencyExceeded], "{found:#?}");
    assert!(
        found[0]
            .message
            .contains("minimal latency 80 ms, self-timed latency unbounded (`B` takes 50"),
        "{}",
        found[0].message
    );
}

#[test]
fn a_bound_that_cannot_be_checked_says_why() {
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let untimed = PACED
        .replace(r#" wcet="30""#, "")
        .replace(r#" wcet="20""#, "");
    for (catalog, graph, why) in [
        (
            bounded_catalog("50 MSEC").replace(r#"to="B""#, r#"to="b""#),
            PACED.to_string(),
            "the graph's top level has no task `b` (did you mean `B`?)",
        ),
        (
            bounded_catalog("50 MSEC").replace(r#"from="A" to="B""#, r#"from="B" to="A""#),
            PACED.to_string(),
            "no latency: no path of channels leads from the source to the sink",
        ),
        (
            bounded_catalog("50 MSEC"),
            untimed,
            "the task graph states no execution times (`wcet`)",
        ),
        (
            bounded_catalog("50 MSEC"),
            DEADLOCK.replace('X', "A").replace('Y', "B"),
            "an iteration deadlocks",
        ),
    ] {
        let w = Workspace::with_catalog("latency-unchecked", &text, &catalog, &graph);
        let found: Vec<Diagnostic> = w
            .warnings()
            .into_iter()
            .filter(|d| d.code == Code::DataflowLatencyUnchecked)
            .collect();
        assert_eq!(found.len(), 1, "{why}: {found:#?}");
        assert!(found[0].message.contains(why), "{}", found[0].message);
        assert_eq!(w.text_at(&text, &found[0]), "scan()");
        assert_eq!(found[0].related[0].file, FileId(1));
    }
    // An unknown task is pointed at where the catalog names it.
    let catalog = bounded_catalog("50 MSEC").replace(r#"to="B""#, r#"to="b""#);
    let w = Workspace::with_catalog("latency-unknown", &text, &catalog, PACED);
    let found = w.warnings();
    assert_eq!(
        codes(&found),
        [Code::DataflowLatencyUnchecked],
        "{found:#?}"
    );
    let at = &found[0].related[1];
    assert_eq!((at.file, &catalog[at.span.range()]), (FileId(1), "b"));
    assert_eq!(at.message, "`b`: no such task in the graph's top level");
}

/// `Z` (10 ms) beside the source `A` (30 ms) both feed `B` (10 ms): `Z`'s
/// samples pile up on its channel, so the self-timed execution never
/// repeats and its latency is not known; the minimal one is, by hand
/// 30 + 10 = 40 ms (`Z`'s sample is there when `A`'s comes).
const RUNS_AHEAD: &str = r#"<TaskGraph name="scan" xmlns="urn:semo:taskgraph:1">
  <Task name="Z" wcet="10"><Port name="o" dir="out"/></Task>
  <Task name="A" wcet="30"><Port name="o" dir="out"/></Task>
  <Task name="B" wcet="10"><Port name="z" dir="in"/><Port name="a" dir="in"/></Task>
  <Channel src="Z.o" dst="B.z"/>
  <Channel src="A.o" dst="B.a"/>
</TaskGraph>
"#;

#[test]
fn a_bound_the_minimal_latency_meets_while_the_self_timed_one_is_unknown_is_checked_in_part() {
    let text = mission("T.P.S { scan() } repeat(100 MSEC)");
    let w = Workspace::with_catalog(
        "latency-in-part",
        &text,
        &bounded_catalog("50 MSEC"),
        RUNS_AHEAD,
    );
    let found: Vec<Diagnostic> = w
        .warnings()
        .into_iter()
        .filter(|d| {
            matches!(
                d.code,
                Code::DataflowLatencyUnchecked | Code::DataflowLatencyExceeded
            )
        })
        .collect();
    assert_eq!(
        codes(&found),
        [Code::DataflowLatencyUnchecked],
        "{found:#?}"
    );
    let message = &found[0].message;
    assert!(
        message.contains(
            "is checked only in part: the minimal latency, 40 ms, is within 50 MSEC (50 ms), but the self-timed latency is not known (samples pile up on channel"
        ),
        "{message}"
    );
    // Over the minimal latency, the bound is broken whatever the other.
    let w = Workspace::with_catalog(
        "latency-in-part-over",
        &text,
        &bounded_catalog("39 MSEC"),
        RUNS_AHEAD,
    );
    let over: Vec<Code> = w
        .warnings()
        .into_iter()
        .map(|d| d.code)
        .filter(|c| {
            matches!(
                c,
                Code::DataflowLatencyUnchecked | Code::DataflowLatencyExceeded
            )
        })
        .collect();
    assert_eq!(over, [Code::DataflowLatencyExceeded]);
}

#[test]
fn each_latency_is_analysed_once_however_many_robots_and_calls() {
    // Separate declarations are refined apart, and one robot calls `scan`
    // twice: the latency of the one graph is analysed once all the same,
    // and twice the robots make no more analyses.
    let analyses = |robots: usize| {
        let declarations: Vec<String> = (0..robots).map(|i| format!("Rover r{i}")).collect();
        let text = format!(
            "{{ T: {} }}\nT.P.S {{ scan() scan() }} repeat(100 MSEC)\nT.M {{ set(P, S) }}\nT.main {{ default: mode = M }}\n",
            declarations.join(", ")
        );
        let w = Workspace::with_catalog(
            &format!("latency-once-{robots}"),
            &text,
            &bounded_catalog("49 MSEC"),
            PACED,
        );
        let found = w.warnings();
        assert_eq!(
            codes(&found),
            [Code::DataflowLatencyExceeded; 2],
            "{found:#?}"
        );
        let analysis = w.host.analysis();
        let dataflow = analysis.dataflow(MISSION_ID).unwrap();
        assert_eq!(dataflow.robots.len(), robots);
        dataflow.latency_analyses
    };
    assert_eq!(analyses(2), 1);
    assert_eq!(analyses(4), 1);
}
