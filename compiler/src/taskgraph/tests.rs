//! Sub-graph references resolved and analysed together (`subgraph`
//! follows the references, `analysis` checks each sub-graph alone: the
//! tests read both).

use crate::diag::{Code, FileId};
use crate::taskgraph::analysis::analyze_with;
use crate::taskgraph::resolve;
use crate::taskgraph::subgraph::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Files in memory, numbered from 1 in the order given; the root is 0.
fn files(list: &[(&str, &str)]) -> impl FnMut(&Path) -> Result<SubgraphSource, String> {
    let map: HashMap<PathBuf, SubgraphSource> = list
        .iter()
        .enumerate()
        .map(|(i, (path, text))| {
            let source = SubgraphSource {
                file: FileId(i as u32 + 1),
                text: (*text).into(),
            };
            (PathBuf::from(path), source)
        })
        .collect();
    move |path: &Path| map.get(path).cloned().ok_or_else(|| "absent".to_string())
}

fn run(root: &str, list: &[(&str, &str)]) -> (Hierarchy, crate::taskgraph::analysis::GraphReport) {
    let (graph, diags) = crate::taskgraph::load_task_graph(FileId(0), root);
    assert!(diags.is_empty(), "{diags:#?}");
    let graph = graph.unwrap();
    let mut resolver = files(list);
    let hierarchy = resolve(
        &graph,
        Some(Path::new("/p/root.taskgraph.xml")),
        &mut resolver,
    );
    let report = analyze_with(&graph, &hierarchy);
    (hierarchy, report)
}

fn codes(h: &Hierarchy, r: &crate::taskgraph::analysis::GraphReport) -> Vec<&'static str> {
    h.diagnostics
        .iter()
        .chain(&r.diagnostics)
        .map(|d| d.code.as_str())
        .collect()
}

const ROOT: &str = r#"<TaskGraph name="root">
  <Task name="A" wcet="1"><Port name="o" dir="out" rate="2"/></Task>
  <Task name="S" subgraph="sub/mid.taskgraph.xml"><Port name="in" dir="in" rate="2"/></Task>
  <Channel src="A.o" dst="S.in"/>
</TaskGraph>"#;

/// Two firings of M per iteration, each running one of `leaf`'s.
const MID: &str = r#"<TaskGraph name="mid">
  <Task name="M" subgraph="../leaf.taskgraph.xml"><Port name="in" dir="in"/></Task>
</TaskGraph>"#;

const LEAF: &str = r#"<TaskGraph name="leaf">
  <Task name="L" wcet="5"><Port name="in" dir="in"/></Task>
</TaskGraph>"#;

#[test]
fn nested_sub_graphs_are_levels_timed_from_the_inside_out() {
    let (h, r) = run(
        ROOT,
        &[
            ("/p/sub/mid.taskgraph.xml", MID),
            ("/p/leaf.taskgraph.xml", LEAF),
        ],
    );
    assert_eq!(codes(&h, &r), Vec::<&str>::new());
    let paths: Vec<&str> = r.levels.iter().map(|l| l.path.as_str()).collect();
    assert_eq!(paths, ["root", "root/S", "root/S/M"]);
    assert_eq!(r.levels[1].repetition.as_deref(), Some(&[2, 1, 1][..]));
    // S = 2 firings of M, each one of leaf (5): 10, and bounds the period.
    let t = r.levels[0].throughput.as_ref().unwrap();
    assert_eq!(
        (t.period.to_string(), t.critical_cycle.clone()),
        ("10".into(), vec!["S".to_string()])
    );
    // M runs one iteration of leaf (L) per firing, twice.
    assert_eq!(r.looped_schedule.as_deref(), Some("A 2(L)"));
    assert_eq!(
        h.reads,
        [
            PathBuf::from("/p/sub/mid.taskgraph.xml"),
            PathBuf::from("/p/leaf.taskgraph.xml")
        ]
    );
}

#[test]
fn a_cycle_below_a_sub_graph_is_that_sub_graph_s_own_error() {
    // root → mid → leaf → mid: the cycle returns to mid, not to root.
    let leaf = LEAF.replace(
        "<Task name=\"L\" wcet=\"5\">",
        "<Task name=\"L\" subgraph=\"sub/mid.taskgraph.xml\">",
    );
    let (h, r) = run(
        ROOT,
        &[
            ("/p/sub/mid.taskgraph.xml", MID),
            ("/p/leaf.taskgraph.xml", &leaf),
        ],
    );
    assert_eq!(codes(&h, &r), ["E068"]);
    assert!(
        h.diagnostics[0].message.contains("E069"),
        "{}",
        h.diagnostics[0].message
    );
    assert_eq!(r.levels.len(), 1);
}

#[test]
fn normalize_resolves_dots_without_the_file_system() {
    assert_eq!(
        normalize(Path::new("/a/./b/../c.xml")),
        PathBuf::from("/a/c.xml")
    );
    assert_eq!(normalize(Path::new("../x")), PathBuf::from("../x"));
}

#[test]
fn references_of_text_without_a_place_cannot_be_looked_up() {
    let (graph, _) = crate::taskgraph::load_task_graph(FileId(0), ROOT);
    let mut nothing = |_: &Path| -> Result<SubgraphSource, String> { unreachable!() };
    let h = resolve(&graph.unwrap(), None, &mut nothing);
    assert_eq!(h.diagnostics.len(), 1);
    assert_eq!(h.diagnostics[0].code, Code::SubgraphUnreadable);
}
