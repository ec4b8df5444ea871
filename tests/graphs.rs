//! Task graphs end to end: `semo graph analyze` on the reference examples, and
//! every SDF3 benchmark graph loaded, consistent and deadlock-free, with the
//! repetition vector checked against the balance equations independently.

mod support;

use semo::diag::FileId;
use semo::taskgraph::{Direction, TaskGraph, analysis, load_task_graph};
use support::{examples, sdf3, semo_in};

fn analyze_json(dir: &std::path::Path, file: &str) -> (i32, serde_json::Value) {
    let out = semo_in(dir, &["graph", "analyze", "--format", "json", file]);
    assert!(
        out.code == 0 || out.code == 1,
        "exit {}: {}",
        out.code,
        out.stderr
    );
    (
        out.code,
        serde_json::from_str(&out.stdout).expect("one JSON object"),
    )
}

fn repetition(level: &serde_json::Value, node: &str) -> u64 {
    level["repetition"][node]
        .as_u64()
        .unwrap_or_else(|| panic!("{node} in {level}"))
}

#[test]
fn consistent_example_has_its_repetition_vector() {
    let (code, v) = analyze_json(&examples().join("taskgraphs"), "consistent.taskgraph.xml");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["levels"][0]["consistent"], true);
    assert_eq!(v["levels"][0]["deadlock_free"], true);
    assert_eq!(v["diagnostics"], serde_json::json!([]));
}

#[test]
fn inconsistent_example_names_the_channel_and_ratios() {
    let (code, v) = analyze_json(&examples().join("taskgraphs"), "inconsistent.taskgraph.xml");
    assert_eq!(code, 1);
    let d = &v["diagnostics"][0];
    assert_eq!(d["code"], "E070");
    let message = d["message"].as_str().unwrap();
    assert!(message.contains("C.o → D.i2"), "{message}");
    assert!(message.contains("fire once per firing of C"), "{message}");
    assert!(message.contains("fire 2 times"), "{message}");
}

#[test]
fn deadlock_example_names_the_cycle_and_the_fix() {
    let dir = examples().join("taskgraphs");
    let (code, v) = analyze_json(&dir, "deadlock.taskgraph.xml");
    assert_eq!(code, 1);
    let d = &v["diagnostics"][0];
    assert_eq!(d["code"], "E071");
    let message = d["message"].as_str().unwrap();
    assert!(message.contains("X → Y → X"), "{message}");
    assert!(
        message.contains("1 more initial sample on channel Y.back → X.fb"),
        "{message}"
    );
    // The range is the feedback channel's element.
    let text = std::fs::read_to_string(dir.join("deadlock.taskgraph.xml")).unwrap();
    let line = text.lines().position(|l| l.contains("Y.back")).unwrap() as u64 + 1;
    assert_eq!(d["start"]["line"], line);
}

#[test]
fn data_loop_body_fires_once_per_iteration() {
    let (code, v) = analyze_json(&examples().join("taskgraphs"), "data_loop.taskgraph.xml");
    assert_eq!(code, 0, "{v}");
    let top = &v["levels"][0];
    assert_eq!(
        (
            repetition(top, "A"),
            repetition(top, "L"),
            repetition(top, "D")
        ),
        (1, 1, 1)
    );
    let body = &v["levels"][1];
    assert_eq!(body["path"], "data_loop/L");
    assert_eq!((repetition(body, "B"), repetition(body, "C")), (1, 1));
}

#[test]
fn human_report_lists_levels() {
    let out = semo_in(
        &examples().join("taskgraphs"),
        &["graph", "analyze", "kmeans.taskgraph.xml"],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("kmeans: consistent, deadlock-free"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("kmeans/Converge/Assign (per iteration)"),
        "{}",
        out.stdout
    );
}

#[test]
fn every_reference_example_loads() {
    let dir = examples().join("taskgraphs");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, diags) = load_task_graph(FileId(0), &text);
        assert!(graph.is_some(), "{}", path.display());
        let load_errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
        assert!(
            load_errors.is_empty(),
            "{}: {load_errors:#?}",
            path.display()
        );
    }
}

/// γ(src)·produce = γ(dst)·consume on every channel, and the vector is the
/// smallest such (its entries share no factor) — checked from the model, not
/// from the analysis.
fn assert_balanced(graph: &TaskGraph, counts: &[u64]) {
    for c in &graph.channels {
        let (s, d) = (
            graph.task_index(&c.src.task).unwrap(),
            graph.task_index(&c.dst.task).unwrap(),
        );
        let produce = graph.tasks[s].port(&c.src.port).unwrap();
        let consume = graph.tasks[d].port(&c.dst.port).unwrap();
        assert_eq!(produce.dir, Direction::Out);
        assert_eq!(
            counts[s] * produce.rate,
            counts[d] * consume.rate,
            "{}: channel {}.{} → {}.{}",
            graph.name,
            c.src.task,
            c.src.port,
            c.dst.task,
            c.dst.port
        );
    }
    let divisor = counts.iter().fold(0, |g, &n| gcd(g, n));
    assert_eq!(divisor, 1, "{}: {counts:?} is not the smallest", graph.name);
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[test]
fn every_sdf3_benchmark_is_consistent_and_deadlock_free() {
    let dir = sdf3();
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("xml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, diags) = load_task_graph(FileId(0), &text);
        // Four of SDF3's files mark two processors of some actors default.
        assert!(
            diags
                .iter()
                .all(|d| d.code == semo::diag::Code::Sdf3TwoDefaultProcessors),
            "{}: {diags:#?}",
            path.display()
        );
        let graph = graph.unwrap();
        let report = analysis::analyze(&graph);
        assert!(
            report.diagnostics.is_empty(),
            "{}: {:#?}",
            path.display(),
            report.diagnostics
        );
        assert!(
            report.is_consistent() && report.is_deadlock_free(),
            "{}",
            path.display()
        );
        assert_balanced(&graph, report.levels[0].repetition.as_ref().unwrap());
        checked += 1;
    }
    assert_eq!(checked, 11);
}

#[test]
fn check_reports_task_graph_problems_in_folders() {
    let (code, diags) = support::check_json_in(&examples(), &["taskgraphs"]);
    assert_eq!(code, 1);
    let codes: Vec<&str> = diags.iter().map(|d| d.code.as_str()).collect();
    assert!(
        codes.contains(&"E070") && codes.contains(&"E071"),
        "{codes:?}"
    );
}

#[test]
fn dot_draws_the_graph_and_refuses_a_broken_file() {
    let out = semo_in(
        &examples().join("taskgraphs"),
        &["graph", "dot", "data_loop.taskgraph.xml"],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stdout.starts_with("digraph \"data_loop\" {"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("subgraph \"cluster_L\""),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("\"A\" -> \"L/L.in\" [taillabel=\"10\""),
        "{}",
        out.stdout
    );
    let broken = semo_in(
        &support::repo_root().join("tests/fixtures/diagnostics/E064_graph_unknown_endpoint"),
        &["graph", "dot", "graph.taskgraph.xml"],
    );
    assert_eq!(broken.code, 1);
    assert!(broken.stdout.is_empty());
    assert!(broken.stderr.contains("E064"), "{}", broken.stderr);
}

#[test]
fn svg_draws_the_graph_to_stdout_or_a_file_and_refuses_a_broken_file() {
    let dir = examples().join("taskgraphs");
    let out = semo_in(&dir, &["graph", "svg", "kmeans.taskgraph.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stdout
            .starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""),
        "{}",
        out.stdout
    );
    assert!(out.stdout.trim_end().ends_with("</svg>"), "{}", out.stdout);
    assert!(
        out.stdout
            .contains("<g class=\"cluster\" data-path=\"Converge/Assign\">"),
        "{}",
        out.stdout
    );
    assert!(out.stdout.contains(">Assign (D-loop × 16)</text>"));
    // The same picture into a file with -o.
    let target = std::env::temp_dir().join(format!("semo-svg-{}.svg", std::process::id()));
    let target_arg = target.to_string_lossy().into_owned();
    let written = semo_in(
        &dir,
        &["graph", "svg", "kmeans.taskgraph.xml", "-o", &target_arg],
    );
    assert_eq!(written.code, 0, "{}", written.stderr);
    assert!(written.stdout.is_empty(), "{}", written.stdout);
    let file = std::fs::read_to_string(&target).expect("the SVG file is written");
    let _ = std::fs::remove_file(&target);
    assert_eq!(file, out.stdout);
    // An SDF3 benchmark.
    let sdf3 = semo_in(&sdf3(), &["graph", "svg", "modem.xml"]);
    assert_eq!(sdf3.code, 0, "{}", sdf3.stderr);
    assert!(
        sdf3.stdout.contains("data-path=\"deci\""),
        "{}",
        sdf3.stdout
    );
    let broken = semo_in(
        &support::repo_root().join("tests/fixtures/diagnostics/E064_graph_unknown_endpoint"),
        &["graph", "svg", "graph.taskgraph.xml"],
    );
    assert_eq!(broken.code, 1);
    assert!(broken.stdout.is_empty());
    assert!(broken.stderr.contains("E064"), "{}", broken.stderr);
    // A graph that deadlocks is drawn, its blocking cycle in red.
    let deadlock = semo_in(
        &support::repo_root().join("tests/fixtures/diagnostics/E071_deadlock"),
        &["graph", "svg", "graph.taskgraph.xml"],
    );
    assert_eq!(deadlock.code, 0, "{}", deadlock.stderr);
    for task in ["X", "Y"] {
        let marked = format!("<g class=\"node task deadlock\" data-path=\"{task}\">");
        assert!(deadlock.stdout.contains(&marked), "{}", deadlock.stdout);
    }
    assert_eq!(
        deadlock
            .stdout
            .matches("<g class=\"edge data deadlock\"")
            .count(),
        2,
        "{}",
        deadlock.stdout
    );
    let missing = semo_in(&dir, &["graph", "svg", "no_such.taskgraph.xml"]);
    assert_eq!(missing.code, 2, "{}", missing.stderr);
}

#[test]
fn data_loop_has_the_looped_single_appearance_schedule() {
    let dir = examples().join("taskgraphs");
    let out = semo_in(&dir, &["graph", "schedule", "data_loop.taskgraph.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout, "A 10(B C) D\n");
    let (_, v) = analyze_json(&dir, "data_loop.taskgraph.xml");
    assert_eq!(v["looped_schedule"], "A 10(B C) D");
    assert_eq!(v["levels"][0]["buffers"]["A.o → L.in"], 10);
}

#[test]
fn multicore_schedule_lists_each_core() {
    let dir = examples().join("taskgraphs");
    let out = semo_in(
        &dir,
        &[
            "graph",
            "schedule",
            "--cores",
            "2",
            "consistent.taskgraph.xml",
        ],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stdout.contains("on 2 cores:\n  core 0: "),
        "{}",
        out.stdout
    );
    assert!(out.stdout.contains("\n  core 1: "), "{}", out.stdout);
}

fn period_as(file: &str, flags: &[&str]) -> (String, serde_json::Value) {
    let mut args = vec!["graph", "analyze", "--format", "json"];
    args.extend(flags);
    args.push(file);
    let out = semo_in(&sdf3(), &args);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).expect("one JSON object");
    (
        v["concurrency"].as_str().unwrap().to_string(),
        v["levels"][0]["throughput"].clone(),
    )
}

#[test]
fn throughput_names_the_period_and_critical_cycle() {
    // Verified by an independent self-timed simulation in the unit tests.
    let cycle = serde_json::json!([
        "motion_estimation",
        "mb_encoding",
        "mb_decoding",
        "motion_compensation"
    ]);
    // An SDF3 file means auto-concurrency; the file's default="true" times.
    let (concurrency, t) = period_as("h263encoder.xml", &[]);
    assert_eq!(concurrency, "auto");
    assert_eq!(t["period"], "408448");
    assert_eq!(t["critical_cycle"], cycle);
    // SDF3's reading of the times: SDF3's own answer (1/4.72981e-06).
    let (_, t) = period_as("h263encoder.xml", &["--sdf3-compat"]);
    assert_eq!(t["period"], "211425");
    // One firing at a time, as the generated code runs a task.
    let (concurrency, t) = period_as("h263encoder.xml", &["--concurrency", "single"]);
    assert_eq!(concurrency, "single");
    assert_eq!(t["period"], "1232530");
    assert_eq!(t["critical_cycle"], cycle);
}

/// A graph of several strongly connected parts is bounded by its slowest
/// part, each at its own rate; of parts that tie, the first-declared task's
/// is named.
#[test]
fn the_slowest_part_bounds_the_period() {
    let says = |dir: &std::path::Path, file: &str, line: &str| {
        let out = semo_in(dir, &["graph", "analyze", file]);
        assert_eq!(out.code, 0, "{}", out.stderr);
        assert!(out.stdout.contains(line), "{}", out.stdout);
    };
    says(
        &sdf3(),
        "mp3playback.xml",
        "iteration period: 120000 (bounded by src alone)",
    );
    // filter fires twice at 2, merge once at 4: a tie.
    says(
        &subgraph_fixtures(),
        "detect.taskgraph.xml",
        "iteration period: 4 (bounded by filter alone)",
    );
}

/// `semo graph analyze --sdf3-compat` gives SDF3's iteration period on every
/// SDF3 benchmark graph (the table in `tests/data/sdf3/README.md`: SDF3's
/// `sdf3analysis-sdf --algo throughput`, the period its inverse).
#[test]
fn sdf3_compat_gives_sdf3_periods_on_its_benchmarks() {
    let expected = [
        ("h263decoder", "332046"),
        ("h263encoder", "211425"),
        ("modem", "16"),
        ("mp3decoder_block_parallelism", "278650"),
        ("mp3decoder_granule_parallelism", "278650"),
        ("mp3playback", "120000"),
        ("random_1000", "463"),
        ("random_200", "170"),
        ("random_50", "104"),
        ("samplerate", "960"),
        ("satellite", "1056"),
    ];
    for (name, period) in expected {
        let (concurrency, t) = period_as(&format!("{name}.xml"), &["--sdf3-compat"]);
        assert_eq!(concurrency, "auto", "{name}");
        assert_eq!(t["period"], period, "{name}");
    }
}

#[test]
fn human_report_says_which_concurrency() {
    let out = semo_in(&sdf3(), &["graph", "analyze", "random_50.xml"]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.starts_with("concurrency: auto"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("iteration period: 104 ("),
        "{}",
        out.stdout
    );
    let out = semo_in(
        &sdf3(),
        &[
            "graph",
            "analyze",
            "--concurrency",
            "single",
            "random_50.xml",
        ],
    );
    assert!(
        out.stdout.starts_with("concurrency: single"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("iteration period: 280 ("),
        "{}",
        out.stdout
    );
    let out = semo_in(
        &examples().join("taskgraphs"),
        &["graph", "analyze", "kmeans.taskgraph.xml"],
    );
    assert!(
        out.stdout.starts_with("concurrency: single"),
        "{}",
        out.stdout
    );
}

#[test]
fn check_reads_an_explicitly_named_sdf3_file_as_a_task_graph() {
    let out = semo_in(&sdf3(), &["check", "modem.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(
        out.stderr,
        "checked 0 missions and 0 catalog files, 1 task graph: 0 errors, 0 warnings, 0 hints\n"
    );
}

fn subgraph_fixtures() -> std::path::PathBuf {
    support::repo_root().join("tests/fixtures/subgraph")
}

#[test]
fn a_task_runs_one_iteration_of_its_sub_graph_as_a_nested_level() {
    let (code, v) = analyze_json(&subgraph_fixtures(), "tracker.taskgraph.xml");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["diagnostics"], serde_json::json!([]));
    let top = &v["levels"][0];
    assert_eq!(repetition(top, "detect"), 1);
    // Without a wcet, `detect` takes one iteration of its sub-graph on one
    // processor: 2 firings of filter (2) + 1 of merge (4) = 8.
    assert_eq!(top["throughput"]["period"], "8");
    assert_eq!(
        top["throughput"]["critical_cycle"],
        serde_json::json!(["detect"])
    );
    let inner = &v["levels"][1];
    assert_eq!(inner["path"], "tracker/detect");
    assert_eq!(
        (repetition(inner, "filter"), repetition(inner, "merge")),
        (2, 1)
    );
    assert_eq!(inner["deadlock_free"], true);
    assert_eq!(v["looped_schedule"], "camera 2filter merge track");
}

#[test]
fn schedule_and_check_follow_sub_graph_references() {
    let dir = subgraph_fixtures();
    let out = semo_in(&dir, &["graph", "schedule", "tracker.taskgraph.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout, "camera 2filter merge track\n");
    let cores = semo_in(
        &dir,
        &["graph", "schedule", "--cores", "1", "tracker.taskgraph.xml"],
    );
    // `detect` takes its sub-graph's time, 8: track starts at 1 + 8.
    assert!(
        cores.stdout.contains("core 0: camera@0 detect@1 track@9"),
        "{}",
        cores.stdout
    );
    assert!(
        cores
            .stdout
            .contains("tracker/detect on 1 core:\n  core 0: filter@0 filter@2 merge@4"),
        "{}",
        cores.stdout
    );
    let (code, diags) =
        support::check_json_in(&support::repo_root().join("tests/fixtures"), &["subgraph"]);
    assert_eq!((code, diags.len()), (0, 0), "{}", support::listing(&diags));
}

#[test]
fn dot_and_svg_name_the_sub_graph_file_on_its_task() {
    let dir = subgraph_fixtures();
    let dot = semo_in(&dir, &["graph", "dot", "tracker.taskgraph.xml"]);
    assert_eq!(dot.code, 0, "{}", dot.stderr);
    assert!(
        dot.stdout
            .contains("\"detect\" [label=\"detect\\n⤷ detect.taskgraph.xml\"];"),
        "{}",
        dot.stdout
    );
    let svg = semo_in(&dir, &["graph", "svg", "tracker.taskgraph.xml"]);
    assert_eq!(svg.code, 0, "{}", svg.stderr);
    assert!(
        svg.stdout.contains(">⤷ detect.taskgraph.xml</text>"),
        "{}",
        svg.stdout
    );
}

#[test]
fn a_missing_sub_graph_fails_the_analysis_on_the_reference() {
    let dir = support::repo_root().join("tests/fixtures/diagnostics/E067_subgraph_unreadable");
    let (code, v) = analyze_json(&dir, "graph.taskgraph.xml");
    assert_eq!(code, 1, "{v}");
    let d = &v["diagnostics"][0];
    assert_eq!(d["code"], "E067");
    let text = std::fs::read_to_string(dir.join("graph.taskgraph.xml")).unwrap();
    let line = text
        .lines()
        .position(|l| l.contains("missing.taskgraph"))
        .unwrap() as u64
        + 1;
    assert_eq!(d["start"]["line"], line);
    // The graph itself is still analysed: B stands for nothing it could time.
    assert_eq!(v["levels"].as_array().map(Vec::len), Some(1));
}

#[test]
fn modes_draws_each_team_or_one_and_reports_errors_and_unknown_teams() {
    let dir = examples().join("scouting");
    let all = semo_in(&dir, &["graph", "modes", "scouting.mission"]);
    assert_eq!(all.code, 0, "{}", all.stderr);
    assert!(
        all.stdout
            .starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\"")
    );
    assert!(all.stdout.contains("data-team=\"MasterTeam\""));
    assert!(all.stdout.contains("data-team=\"SlaveTeam\""));
    // SlaveTeam starts in AUTO_MODE and leaves RETURN_MODE on CHANGE_FINISH.
    let slave = semo_in(
        &dir,
        &["graph", "modes", "scouting.mission", "--team", "SlaveTeam"],
    );
    assert_eq!(slave.code, 0, "{}", slave.stderr);
    assert!(!slave.stdout.contains("data-team=\"MasterTeam\""));
    assert!(
        slave
            .stdout
            .contains("<g class=\"mode default\" data-mode=\"AUTO_MODE\">")
    );
    assert!(
        slave
            .stdout
            .contains("data-from=\"RETURN_MODE\" data-to=\"FINISH\"")
    );
    assert!(slave.stdout.contains(">CHANGE_FINISH</text>"));
    let unknown = semo_in(
        &dir,
        &["graph", "modes", "scouting.mission", "--team", "Nobody"],
    );
    assert_eq!(unknown.code, 2);
    assert!(
        unknown.stderr.contains("MasterTeam, SlaveTeam"),
        "{}",
        unknown.stderr
    );
    // A mission with an error: drawn as far as understood, the error on stderr, exit 1.
    let broken = semo_in(
        &support::repo_root().join("tests/fixtures/modes"),
        &["graph", "modes", "unknown_mode.mission"],
    );
    assert_eq!(broken.code, 1, "{}", broken.stderr);
    assert!(broken.stderr.contains("E0"), "{}", broken.stderr);
    assert!(
        broken.stdout.contains("data-mode=\"IDLE\""),
        "{}",
        broken.stdout
    );
    let missing = semo_in(&dir, &["graph", "modes", "no_such.mission"]);
    assert_eq!(missing.code, 2);
}

/// `semo graph buffers`: SDF3's storage/throughput front on modem (its
/// `sdf3analysis-sdf --algo buffersize`: 70 → 1/0.03125, 71 → 1/0.0555556,
/// 72 → 1/0.0625), the channel sizes of a chosen point, and bounds where the
/// minimum is not known exactly.
#[test]
fn buffers_give_the_trade_off_and_a_chosen_point() {
    let out = semo_in(
        &sdf3(),
        &["graph", "buffers", "--format", "json", "modem.xml"],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    assert_eq!(v["concurrency"], "auto");
    assert_eq!(v["max_period"], "16");
    assert_eq!(
        v["points"],
        serde_json::json!([
            {"size": 70, "period": "32", "proof": "exact"},
            {"size": 71, "period": "18", "proof": "exact"},
            {"size": 72, "period": "16", "proof": "exact"}
        ])
    );
    assert_eq!(v["exact_front"], true);
    assert_eq!(
        v["minimal_size"],
        serde_json::json!({"lower_bound": 72, "found": 72, "exact": true})
    );
    let channels = v["chosen"]["channels"].as_object().unwrap();
    let total: u64 = channels.values().map(|c| c.as_u64().unwrap()).sum();
    assert_eq!(total, 72);

    // A throughput of 1/18 chooses the point of size 71.
    let out = semo_in(
        &sdf3(),
        &["graph", "buffers", "--throughput", "1/18", "modem.xml"],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout
            .contains("channel sizes for period at most 18 (71 → 18):"),
        "{}",
        out.stdout
    );
    // h263encoder at SDF3's period 226098: the exact front's 352, where
    // the greedy search alone answered 401.
    let out = semo_in(
        &sdf3(),
        &[
            "graph",
            "buffers",
            "--sdf3-compat",
            "--throughput",
            "1/226098",
            "h263encoder.xml",
        ],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("the exact Pareto front")
            && out
                .stdout
                .contains("channel sizes for period at most 226098 (352 → 226098):"),
        "{}",
        out.stdout
    );
    // Where the search cannot tell the minimum exactly, it says so, and
    // that its points are distributions found.
    let out = semo_in(
        &sdf3(),
        &["graph", "buffers", "mp3decoder_block_parallelism.xml"],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("each point a distribution found"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("smallest total size for the maximal throughput: between 3130 and 3172"),
        "{}",
        out.stdout
    );
    // Where the front is too large to explore but every channel at its own
    // minimum (the others unbounded) reaches the maximal throughput, the
    // minimum is exact all the same.
    let out = semo_in(&sdf3(), &["graph", "buffers", "mp3playback.xml"]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("each point a distribution found")
            && out.stdout.contains(
                "smallest total size for the maximal throughput: 2910 (exact: the lower bound is reached)"
            ),
        "{}",
        out.stdout
    );
    // A throughput no distribution reaches, and one that is not a number.
    let out = semo_in(
        &sdf3(),
        &["graph", "buffers", "--throughput", "1", "modem.xml"],
    );
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("no buffer distribution found reaches"),
        "{}",
        out.stderr
    );
    let out = semo_in(
        &sdf3(),
        &["graph", "buffers", "--throughput", "fast", "modem.xml"],
    );
    assert_eq!(out.code, 2);
    assert!(
        out.stderr.contains("`fast` is not a throughput"),
        "{}",
        out.stderr
    );
}

/// Every point of SDF3's storage/throughput front on its benchmark graphs
/// is on `semo graph buffers --sdf3-compat`'s front: the same total size
/// with the same throughput. The points are SDF3's own answers (its
/// `sdf3analysis-sdf --algo buffersize`, throughputs to its six
/// significant digits), kept as data in `tests/data/sdf3/buffersize.json`;
/// the three benchmarks SDF3 does not finish within 120 s are not there.
#[test]
fn sdf3_buffer_fronts_are_on_semos_fronts() {
    let data = std::fs::read_to_string(sdf3().join("buffersize.json")).unwrap();
    let fronts: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&data).unwrap();
    assert!(fronts.len() >= 8, "{}", fronts.len());
    let period = |text: &str| -> f64 {
        match text.split_once('/') {
            Some((n, d)) => n.parse::<f64>().unwrap() / d.parse::<f64>().unwrap(),
            None => text.parse().unwrap(),
        }
    };
    for (graph, points) in &fronts {
        let v = sdf3_buffers_json(graph);
        // Where SDF3's exploration finishes, semo's does too: the whole
        // front proven, within the budget the JSON states.
        assert_eq!(v["exact_front"], true, "{graph}: {}", v["budget"]);
        assert_eq!(v["minimal_size"]["exact"], true, "{graph}");
        assert!(
            v["budget"]["work"].as_u64() <= v["budget"]["limit"].as_u64(),
            "{graph}: {}",
            v["budget"]
        );
        let ours: Vec<(u64, f64)> = (v["points"].as_array().unwrap().iter())
            .map(|p| {
                (
                    p["size"].as_u64().unwrap(),
                    period(p["period"].as_str().unwrap()),
                )
            })
            .collect();
        for point in points.as_array().unwrap() {
            let size = point[0].as_u64().unwrap();
            let throughput: f64 = point[1].as_str().unwrap().parse().unwrap();
            if throughput == 0.0 {
                // SDF3 lists the distribution that deadlocks (size 0) as a
                // point of throughput 0; semo's front starts at the
                // smallest live distribution.
                assert_eq!(size, 0, "{graph}");
                continue;
            }
            let found = ours.iter().find(|(s, _)| *s == size);
            let Some(&(_, p)) = found else {
                panic!("{graph}: SDF3's point of size {size} is not on semo's front {ours:?}");
            };
            assert!(
                ((1.0 / p) - throughput).abs() <= throughput * 1e-5,
                "{graph}: size {size}: semo's period {p}, SDF3's throughput {throughput}"
            );
        }
    }
}

/// `semo graph buffers --sdf3-compat --format json` of an SDF3 graph (a path
/// under `tests/data/sdf3`), which must succeed.
fn sdf3_buffers_json(graph: &str) -> serde_json::Value {
    let args = [
        "graph",
        "buffers",
        "--sdf3-compat",
        "--format",
        "json",
        graph,
    ];
    let out = semo_in(&sdf3(), &args);
    assert_eq!(out.code, 0, "{graph}: {}{}", out.stdout, out.stderr);
    serde_json::from_str(&out.stdout).unwrap()
}

/// The generated graphs with a self-loop on every actor or on about half of
/// them where the exact exploration used to run out of its budget: every
/// point of `semo graph buffers --sdf3-compat`'s front is proven (`exact`),
/// the front ends at the maximal throughput and its minimum is exact, and
/// any SDF3 point `buffersize.json` holds for them is on it.
#[test]
fn self_looped_generated_graphs_have_exact_buffer_fronts() {
    let data = std::fs::read_to_string(sdf3().join("buffersize.json")).unwrap();
    let fronts: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&data).unwrap();
    for graph in [
        "generated/r12_1_selfloops.xml",
        "generated/r12_1_somelooped.xml",
        "generated/r12_6_selfloops.xml",
        "generated/r12_6_somelooped.xml",
    ] {
        let v = sdf3_buffers_json(graph);
        assert_eq!(v["exact_front"], true, "{graph}: {v}");
        let points = v["points"].as_array().unwrap();
        assert!(!points.is_empty(), "{graph}");
        for p in points {
            assert_eq!(p["proof"], "exact", "{graph}: {p}");
        }
        assert_eq!(points.last().unwrap()["period"], v["max_period"], "{graph}");
        let minimal = &v["minimal_size"];
        assert_eq!(minimal["exact"], true, "{graph}: {minimal}");
        assert_eq!(minimal["found"], points.last().unwrap()["size"], "{graph}");
        let key = graph.trim_start_matches("generated/");
        for point in fronts
            .get(key)
            .and_then(|f| f.as_array())
            .into_iter()
            .flatten()
        {
            let size = point[0].as_u64().unwrap();
            assert!(
                size == 0 || points.iter().any(|p| p["size"] == size),
                "{graph}: SDF3's point of size {size} is not on semo's front"
            );
        }
    }
}

/// A file starting with a byte-order mark (as some Windows editors save it)
/// gets its diagnostics where they are: the mark is one column, and every
/// range, to the end of the element, is one column on from the same file
/// without it.
#[test]
fn a_byte_order_mark_leaves_diagnostics_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let graph = r#"<sdf3 type="sdf" version="1.0"><applicationGraph name="app"><sdf name="g" type="G"><actor name="a" type="A"><port name="o" type="out" rate="2"/><port name="i" type="in" rate="1"/></actor><actor name="b" type="B"><port name="i" type="in" rate="1"/><port name="o" type="out" rate="1"/></actor><channel name="c0" srcActor="a" srcPort="o" dstActor="b" dstPort="i"/><channel name="c1" srcActor="b" srcPort="o" dstActor="a" dstPort="i" initialTokens="1"/></sdf></applicationGraph></sdf3>"#;
    std::fs::write(dir.path().join("plain.xml"), graph).unwrap();
    std::fs::write(dir.path().join("marked.xml"), format!("\u{feff}{graph}")).unwrap();
    let range = |file: &str| {
        let (code, json) = analyze_json(dir.path(), file);
        assert_eq!(code, 1, "{json}");
        let d = &json["diagnostics"][0];
        assert_eq!(d["code"], "E070", "{json}");
        (
            d["start"]["column"].as_u64().unwrap(),
            d["end"]["column"].as_u64().unwrap(),
        )
    };
    let (start, end) = range("plain.xml");
    // The whole `<channel name="c1" .../>` element.
    let c1 = graph.find(r#"<channel name="c1""#).unwrap();
    assert_eq!(
        (start, end),
        (c1 as u64 + 1, graph.find("</sdf>").unwrap() as u64 + 1)
    );
    assert_eq!(range("marked.xml"), (start + 1, end + 1));
}

/// The first level's period, or why there is none, of `text` written to a
/// file `name` and analysed with `flags`: the human line about the period
/// and the JSON `no_period` reason (both exit 0: the analysis is complete).
fn period_or_why(name: &str, text: &str, flags: &[&str]) -> (String, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(name), text).unwrap();
    let run = |format: &str| {
        let mut args = vec!["graph", "analyze", "--format", format];
        args.extend(flags);
        args.push(name);
        let out = semo_in(dir.path(), &args);
        assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
        out.stdout
    };
    let human = run("human");
    let line = human
        .lines()
        .find(|l| l.contains("iteration period"))
        .unwrap_or_else(|| panic!("no period line: {human}"))
        .trim()
        .to_string();
    let json: serde_json::Value = serde_json::from_str(&run("json")).unwrap();
    let level = &json["levels"][0];
    assert!(
        level["throughput"].is_null() != level["no_period"].is_null(),
        "a period or a reason: {level}"
    );
    (line, level["no_period"].clone())
}

/// A period is never silently missing: without execution times, on
/// overflow, with an expansion too large, and under `--sdf3-compat` with no
/// processor marked default, the text and the JSON say why.
#[test]
fn a_missing_period_says_why() {
    let untimed = r#"<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A"><Port name="o" dir="out"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>"#;
    let (line, why) = period_or_why("g.taskgraph.xml", untimed, &[]);
    assert_eq!(
        line,
        "iteration period: none: no task has an execution time above 0"
    );
    assert_eq!(why["reason"], "untimed");
    let huge = untimed
        .replace(r#"name="A""#, r#"name="A" wcet="18446744073709551615""#)
        .replace(r#"name="B""#, r#"name="B" wcet="18446744073709551615""#)
        .replace(
            r#"<Port name="o" dir="out"/></Task>"#,
            r#"<Port name="o" dir="out"/><Port name="back" dir="in"/></Task>"#,
        )
        .replace(
            r#"<Port name="i" dir="in"/></Task>"#,
            r#"<Port name="i" dir="in"/><Port name="back" dir="out"/></Task>"#,
        )
        .replace(
            "</TaskGraph>",
            r#"<Channel src="B.back" dst="A.back" initialTokens="1"/></TaskGraph>"#,
        );
    let (line, why) = period_or_why("g.taskgraph.xml", &huge, &[]);
    assert!(line.contains("overflows"), "{line}");
    assert_eq!(why["reason"], "overflow");
    // 10^9 + 1 firings per iteration on a cycle: too large to expand.
    let expansion = r#"<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A" wcet="1"><Port name="o" dir="out" rate="1000000000"/><Port name="i" dir="in" rate="1000000000"/></Task>
  <Task name="B" wcet="1"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>
  <Channel src="A.o" dst="B.i"/>
  <Channel src="B.o" dst="A.i" initialTokens="1000000000"/>
</TaskGraph>"#;
    let (line, why) = period_or_why("g.taskgraph.xml", expansion, &[]);
    assert!(line.contains("too many firings"), "{line}");
    assert_eq!(why["reason"], "too_large");
    let no_default = r#"<?xml version="1.0"?>
<sdf3 type="sdf" version="1.0"><applicationGraph name="g"><sdf name="g" type="G">
  <actor name="a" type="A"><port name="o" type="out" rate="1"/><port name="i" type="in" rate="1"/></actor>
  <channel name="l" srcActor="a" srcPort="o" dstActor="a" dstPort="i" initialTokens="1"/>
</sdf><sdfProperties><actorProperties actor="a">
  <processor type="p"><executionTime time="5"/></processor>
</actorProperties></sdfProperties></applicationGraph></sdf3>"#;
    // The file's reading takes the only processor; SDF3's takes none.
    let (line, _) = period_or_why("g.xml", no_default, &[]);
    assert_eq!(line, "iteration period: 5 (bounded by a alone)");
    let (line, why) = period_or_why("g.xml", no_default, &["--sdf3-compat"]);
    assert!(line.contains("--sdf3-compat"), "{line}");
    assert_eq!(why["reason"], "untimed");
    assert!(
        why["message"]
            .as_str()
            .unwrap()
            .contains("marked `default`")
    );
}

/// An SDF3 chain of tasks of time 3 with channels of the given rates.
fn sdf3_chain(rates: &[(u64, u64)]) -> String {
    let mut actors = String::new();
    let mut properties = String::new();
    for v in 0..=rates.len() {
        let mut ports = String::new();
        if v > 0 {
            let rate = rates[v - 1].1;
            ports.push_str(&format!(r#"<port name="i" type="in" rate="{rate}"/>"#));
        }
        if let Some((rate, _)) = rates.get(v) {
            ports.push_str(&format!(r#"<port name="o" type="out" rate="{rate}"/>"#));
        }
        actors.push_str(&format!(
            "<actor name=\"t{v}\" type=\"T\">{ports}</actor>\n"
        ));
        properties.push_str(&format!(
            r#"<actorProperties actor="t{v}"><processor type="p" default="true"><executionTime time="3"/></processor></actorProperties>"#
        ));
    }
    let channels: String = (0..rates.len())
        .map(|k| {
            format!(
                r#"<channel name="c{k}" srcActor="t{k}" srcPort="o" dstActor="t{}" dstPort="i"/>"#,
                k + 1
            )
        })
        .collect();
    format!(
        r#"<?xml version="1.0"?>
<sdf3 type="sdf" version="1.0"><applicationGraph name="chain"><sdf name="chain" type="G">
{actors}{channels}
</sdf><sdfProperties>{properties}</sdfProperties></applicationGraph></sdf3>"#
    )
}

/// `graph buffers` on an acyclic pipeline under auto-concurrency (SDF3's
/// meaning): nothing but the buffers bounds its throughput, so it says at
/// once that no finite distribution reaches the maximal one (it printed
/// 500,003 lines for two tasks), and sizes the buffers for a period asked.
#[test]
fn buffers_of_an_unbounded_throughput_say_so_at_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("pipe.xml"), sdf3_chain(&[(1, 1)])).unwrap();
    let out = semo_in(dir.path(), &["graph", "buffers", "pipe.xml"]);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert_eq!(out.stdout.lines().count(), 2, "{}", out.stdout);
    assert!(
        out.stdout.contains("the throughput is unbounded"),
        "{}",
        out.stdout
    );
    assert!(
        out.stderr
            .contains("no finite buffer distribution reaches it"),
        "{}",
        out.stderr
    );
    let out = semo_in(
        dir.path(),
        &["graph", "buffers", "--format", "json", "pipe.xml"],
    );
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    assert_eq!(v["unbounded_throughput"], true);
    assert_eq!(v["max_period"], "0");
    assert_eq!(v["points"], serde_json::json!([]));
    assert!(v["chosen"].is_null());
    assert!(v["message"].as_str().unwrap().contains("unbounded"), "{v}");
    // A period asked for: the smallest distribution found reaching it.
    let out = semo_in(
        dir.path(),
        &["graph", "buffers", "--throughput", "1/1", "pipe.xml"],
    );
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout
            .contains("channel sizes for period at most 1 (6 → 1):"),
        "{}",
        out.stdout
    );
}

/// Chains with rates 2^20: one evaluation of a distribution is beyond the
/// search's work budget, so the search makes none and says so, at once.
#[test]
fn buffers_of_large_rates_stop_at_the_work_budget() {
    let r = 1u64 << 20;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("rates.xml"),
        sdf3_chain(&[(r, 1), (1, r), (r, 1)]),
    )
    .unwrap();
    let args = ["graph", "buffers", "--concurrency", "single", "rates.xml"];
    let out = semo_in(dir.path(), &args);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("maximal throughput: period 3145728"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("more than the search's budget of 6000000"),
        "{}",
        out.stdout
    );
    assert!(
        out.stderr.contains("stopped at its work budget"),
        "{}",
        out.stderr
    );
    let mut json = args.to_vec();
    json.splice(2..2, ["--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&semo_in(dir.path(), &json).stdout).unwrap();
    assert_eq!(v["budget"]["exhausted"], true);
    assert_eq!(v["budget"]["work"], 0);
    assert!(
        v["budget"]["per_evaluation"].as_u64().unwrap() > 6_000_000,
        "{v}"
    );
}

/// The longest chain of tasks `semo` reads (a file of at most 16 MiB: about
/// 144,000 tasks), analysed, scheduled and checked through the CLI: the
/// analyses walk graphs without recursion (a 139,000-task chain overflowed
/// the stack in all three). A million tasks, beyond the file size, are
/// analysed in-process by `compiler/tests/chain_scaling.rs`.
#[test]
fn the_longest_chain_a_file_can_hold_is_analysed() {
    let limit = usize::try_from(semo::fsread::MAX_FILE_BYTES).unwrap();
    let head = "<TaskGraph name=\"chain\" xmlns=\"urn:semo:taskgraph:1\">\n";
    let tail = "</TaskGraph>\n";
    let (mut tasks, mut channels) = (String::new(), String::new());
    let mut n = 0;
    loop {
        let task = format!(
            "<Task name=\"t{n}\"><Port name=\"i\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>\n"
        );
        let channel = format!("<Channel src=\"t{n}.o\" dst=\"t{}.i\"/>\n", n + 1);
        if head.len() + tasks.len() + channels.len() + task.len() + channel.len() + tail.len()
            > limit
        {
            break;
        }
        tasks.push_str(&task);
        channels.push_str(&channel);
        n += 1;
    }
    // The last task's output closes no channel: an unconnected port.
    let text = format!("{head}{tasks}{channels}{tail}").replace(
        &format!("<Channel src=\"t{}.o\" dst=\"t{n}.i\"/>\n", n - 1),
        "",
    );
    assert!(n > 139_000, "{n} tasks");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("chain.taskgraph.xml"), text).unwrap();
    let (code, v) = analyze_json(dir.path(), "chain.taskgraph.xml");
    assert_eq!(code, 0);
    assert_eq!(v["levels"][0]["deadlock_free"], true);
    assert_eq!(v["levels"][0]["repetition"].as_object().unwrap().len(), n);
    let out = semo_in(dir.path(), &["graph", "schedule", "chain.taskgraph.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stdout.starts_with("t0 t1 t2 "), "{}", &out.stdout[..40]);
    let out = semo_in(dir.path(), &["check", "chain.taskgraph.xml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
}
