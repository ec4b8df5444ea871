//! Services implemented by SDF/L task graphs (`graph=` in the catalog): the
//! generated service task runs one iteration of the graph's looped schedule
//! per call, its inner tasks in the schedule's order, D-type loops exactly
//! `loopCount` times, C-type loops until their exit task sets the exit flag
//! (in `linux-sim`, in the iteration the scenario's `loops` names), its
//! channels carrying tokens between the inner tasks (the trace's `read` and
//! `wrote`). Checked
//! from the trace of the generated `linux-sim` program and of `semo
//! simulate`, on `tests/fixtures/loops/` (the thesis's k-means graph and the
//! two loop examples, copied from `examples/taskgraphs/`; a tracking graph
//! whose task stands for a sub-graph file), compiled with gcc and clang at
//! `-Wpedantic -Werror`.

mod support;

use std::path::PathBuf;
use support::robots::{
    PEDANTIC, build, compilers, events, field, make, robot_folders, run_in_simulation, scratch,
};
use support::{repo_root, semo_in};

fn fixture(name: &str) -> PathBuf {
    repo_root().join("tests/fixtures/loops").join(name)
}

/// The graph events of a trace: `graph/task` for a firing, `graph/loop×n`
/// for a loop's end.
fn graph_events(events: &[support::robots::Event]) -> Vec<String> {
    events
        .iter()
        .filter_map(|e| match field(e, "event") {
            "graph_fire" => Some(format!("{}/{}", field(e, "graph"), field(e, "task"))),
            "graph_loop" => Some(format!(
                "{}/{}×{}",
                field(e, "graph"),
                field(e, "loop"),
                field(e, "iterations")
            )),
            _ => None,
        })
        .collect()
}

/// The looped schedules written out (`semo graph schedule` gives
/// `ReadPoints InitCenters 500(Select 16(Nearest) ReplaceCenter) Output` and
/// `A 10(B C) D` for both loop examples), with the scenario's exits:
/// `kmeans/Converge` after 3 iterations, `convergent_loop/L` after 4 (an
/// exit for the D-type `data_loop/L` is no exit: it runs all 10).
fn expected() -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut push = |s: &str| out.push(s.to_string());
    push("kmeans/ReadPoints");
    push("kmeans/InitCenters");
    for _ in 0..3 {
        push("kmeans/Converge/Select");
        for _ in 0..16 {
            push("kmeans/Converge/Assign/Nearest");
        }
        push("kmeans/Converge/Assign×16");
        push("kmeans/Converge/ReplaceCenter");
    }
    push("kmeans/Converge×3");
    push("kmeans/Output");
    push("data_loop/A");
    for _ in 0..10 {
        push("data_loop/L/B");
        push("data_loop/L/C");
    }
    push("data_loop/L×10");
    push("data_loop/D");
    push("convergent_loop/A");
    for _ in 0..4 {
        push("convergent_loop/L/B");
        push("convergent_loop/L/C");
    }
    push("convergent_loop/L×4");
    push("convergent_loop/D");
    out
}

/// The data of a trace's inner firings: `graph/task read→wrote`.
fn graph_data(events: &[support::robots::Event]) -> Vec<String> {
    events
        .iter()
        .filter(|e| field(e, "event") == "graph_fire")
        .map(|e| {
            format!(
                "{}/{} {}→{}",
                field(e, "graph"),
                field(e, "task"),
                field(e, "read"),
                field(e, "wrote")
            )
        })
        .collect()
}

fn numbers(range: std::ops::RangeInclusive<i64>) -> String {
    range.map(|n| n.to_string()).collect::<Vec<_>>().join(",")
}

/// The tokens each inner task read and wrote, worked out by hand from the
/// graphs and the `linux-sim` work (each output token `k` is `(sum of the
/// tokens read + k + 1) mod 1000`): k-means's points and centres pass
/// through the distributing and broadcasting ports, the feedback channel's
/// initial token (0) reaches the first `Select`, and each convergent
/// iteration's centre the next one.
fn check_data(data: &[String]) {
    let of = |task: &str| -> Vec<&str> {
        data.iter()
            .filter_map(|d| d.strip_prefix(task)?.strip_prefix(' '))
            .collect()
    };
    let sixteen = numbers(1..=16);
    assert_eq!(of("kmeans/ReadPoints"), [format!("→{sixteen}")]);
    assert_eq!(of("kmeans/InitCenters"), ["→1"]);
    assert_eq!(
        of("kmeans/Converge/Select"),
        ["1,0→2", "1,185→187", "1,145→147"]
    );
    let nearest = of("kmeans/Converge/Assign/Nearest");
    assert_eq!(nearest.len(), 48);
    assert_eq!(nearest[0], "1,2→4");
    assert_eq!(nearest[15], "16,2→19");
    assert_eq!(nearest[16], "1,187→189");
    assert_eq!(
        of("kmeans/Converge/ReplaceCenter"),
        [
            format!("{}→185,185", numbers(4..=19)),
            format!("{}→145,145", numbers(189..=204)),
            format!("{}→505,505", numbers(149..=164)),
        ]
    );
    assert_eq!(of("kmeans/Output"), ["505→"]);
    assert_eq!(of("data_loop/L/B")[9], "10→11");
    assert_eq!(of("data_loop/D"), [format!("{}→", numbers(3..=12))]);
    assert_eq!(
        of("convergent_loop/L/B"),
        ["1,0→2", "1,3→5", "1,6→8", "1,9→11"]
    );
    assert_eq!(of("convergent_loop/L/C")[3], "11→12,12");
    assert_eq!(of("convergent_loop/D"), ["12→"]);
}

#[test]
fn graph_services_run_their_looped_schedule_in_linux_sim_and_the_simulator() {
    let scenario = std::fs::read_to_string(fixture("loops.scenario.json")).unwrap();
    let out = scratch("loops/run");
    let traces = run_in_simulation(&fixture("loops.mission"), &out, &scenario);
    let c = graph_events(&events(&traces["c"]));
    assert_eq!(c, expected(), "linux-sim");
    let data = graph_data(&events(&traces["c"]));
    check_data(&data);
    let simulated = semo_in(
        &repo_root(),
        &[
            "simulate",
            &fixture("loops.mission").display().to_string(),
            "--scenario",
            &fixture("loops.scenario.json").display().to_string(),
            "--trace",
            "-",
        ],
    );
    assert_eq!(simulated.code, 0, "{}", simulated.stderr);
    let lines: Vec<String> = simulated.stdout.lines().map(str::to_string).collect();
    assert_eq!(graph_events(&events(&lines)), expected(), "semo simulate");
    assert_eq!(graph_data(&events(&lines)), data, "semo simulate");
}

/// Without an exit in the scenario, a convergent loop runs `loopCount`
/// iterations (k-means: 500), never more.
#[test]
fn a_convergent_loop_without_an_exit_stops_at_its_loop_count() {
    let out = scratch("loops/no-exit");
    let traces = run_in_simulation(
        &fixture("loops.mission"),
        &out,
        r#"{"time_scale": 0.2, "duration": 3000}"#,
    );
    let c = graph_events(&events(&traces["c"]));
    let ends: Vec<&String> = c.iter().filter(|e| e.contains('×')).collect();
    assert!(
        ends.contains(&&"kmeans/Converge×500".to_string()),
        "{ends:?}"
    );
    assert!(
        ends.contains(&&"convergent_loop/L×10".to_string()),
        "{ends:?}"
    );
    let nearest = c.iter().filter(|e| e.ends_with("/Nearest")).count();
    assert_eq!(nearest, 500 * 16);
}

/// `semo simulate`'s trace of `mission` with `scenario` (fixtures).
fn simulate(mission: &str, scenario: &str) -> Vec<String> {
    let simulated = semo_in(
        &repo_root(),
        &[
            "simulate",
            &fixture(mission).display().to_string(),
            "--scenario",
            &fixture(scenario).display().to_string(),
            "--trace",
            "-",
        ],
    );
    assert_eq!(simulated.code, 0, "{}", simulated.stderr);
    simulated.stdout.lines().map(str::to_string).collect()
}

/// A task standing for a sub-graph file fires as one iteration of the
/// sub-graph's schedule: `track`'s `Detect Filter Steer` is
/// `Detect 2(Predict) Update Steer`, the sub-graph's tasks named below
/// `Filter`, its boundary passing Detect's two tokens to Predict's `in` and
/// Update's `out` to Steer, in `linux-sim` and in the simulator alike.
#[test]
fn a_sub_graph_task_runs_one_iteration_of_its_sub_graph_in_the_looped_schedule() {
    let scenario = std::fs::read_to_string(fixture("tracking.scenario.json")).unwrap();
    let out = scratch("loops/tracking");
    let traces = run_in_simulation(&fixture("tracking.mission"), &out, &scenario);
    let c = events(&traces["c"]);
    let expected = [
        "track/Detect",
        "track/Filter/Predict",
        "track/Filter/Predict",
        "track/Filter/Update",
        "track/Steer",
    ];
    assert_eq!(graph_events(&c), expected, "linux-sim");
    // Detect writes 1,2 (nothing read); each Predict reads one of them;
    // Update reads both predictions (2+3) and writes 6, which Steer reads.
    let data = graph_data(&c);
    assert_eq!(
        data,
        [
            "track/Detect →1,2",
            "track/Filter/Predict 1→2",
            "track/Filter/Predict 2→3",
            "track/Filter/Update 2,3→6",
            "track/Steer 6→",
        ]
    );
    let simulated = events(&simulate("tracking.mission", "tracking.scenario.json"));
    assert_eq!(graph_events(&simulated), expected, "semo simulate");
    assert_eq!(graph_data(&simulated), data, "semo simulate");
}

/// How much later than the simulator's a `linux-sim` release may be (mission
/// ms), as `tests/differential.rs` bounds its times: each release waits from
/// the previous one's actual start, so a thread woken late delays the ones
/// after it too (at `time_scale` 0.2 a wall ms is 5 mission ms).
const LATE_MS: i64 = 500;
/// How much earlier: never, but for the start barrier (the robots of a run
/// start within 3 mission ms of each other, `tests/differential.rs`).
const EARLY_MS: i64 = 10;

/// The releases of `task`'s firings in a trace (`graph_fire`'s `release`),
/// each checked against the line's own time (a firing is traced after it
/// starts).
fn releases(events: &[support::robots::Event], task: &str) -> Vec<i64> {
    events
        .iter()
        .filter(|e| field(e, "event") == "graph_fire" && field(e, "task") == task)
        .map(|e| {
            let release: i64 = field(e, "release")
                .parse()
                .unwrap_or_else(|_| panic!("no release: {e:?}"));
            let t = e["t"].as_i64().unwrap();
            assert!(t >= release, "traced before its release: {e:?}");
            release
        })
        .collect()
}

/// A time-triggered inner task (`sampler`'s Sample, every 200 ms, twice per
/// call of `sample()`, which `repeat()` calls again as soon as one ends)
/// fires at most once per period across calls, in the `linux-sim` program
/// as in `semo simulate`: its releases are at least 200 ms apart (exactly
/// 200 in the simulator, which has no late threads), the C ones never
/// earlier than the simulator's and at most [`LATE_MS`] later, and the
/// graph's firings come in the same order (the C run, later, may end with
/// fewer of them).
#[test]
fn a_time_triggered_inner_task_fires_once_per_period_in_linux_sim_and_the_simulator() {
    let scenario = std::fs::read_to_string(fixture("periodic.scenario.json")).unwrap();
    let out = scratch("loops/periodic");
    let traces = run_in_simulation(&fixture("periodic.mission"), &out, &scenario);
    let c = events(&traces["c"]);
    let simulated = events(&simulate("periodic.mission", "periodic.scenario.json"));
    let (c_releases, sim_releases) = (releases(&c, "Sample"), releases(&simulated, "Sample"));
    assert!(c_releases.len() >= 4, "{c_releases:?}");
    for (name, releases) in [("linux-sim", &c_releases), ("semo simulate", &sim_releases)] {
        assert!(
            releases.windows(2).all(|w| w[1] - w[0] >= 200),
            "{name}: {releases:?}"
        );
    }
    assert!(
        sim_releases.windows(2).all(|w| w[1] - w[0] == 200),
        "{sim_releases:?}"
    );
    for (k, (c, sim)) in c_releases.iter().zip(&sim_releases).enumerate() {
        assert!(
            (sim - EARLY_MS..=sim + LATE_MS).contains(c),
            "release {k}: linux-sim {c}, simulator {sim}\n{c_releases:?}\n{sim_releases:?}"
        );
    }
    let (c_order, sim_order) = (graph_events(&c), graph_events(&simulated));
    assert!(
        sim_order.starts_with(&c_order),
        "linux-sim {c_order:?}\nsemo simulate {sim_order:?}"
    );
    assert_eq!(
        c_order[..3],
        ["sampler/Sample", "sampler/Sample", "sampler/Average"]
    );
}

/// A stop does not cut an iteration: `periodic_timeout.mission`'s call times
/// out at 100 ms while Sample waits for its period (due at 200 ms), and the
/// `linux-sim` program, like the simulator, still fires the second Sample
/// and Average before it ends the call. Run at `time_scale` 1, so the
/// timeout (control thread) comes 90 wall ms before the second Sample.
#[test]
fn a_stop_ends_a_graph_call_when_its_iteration_ends_in_linux_sim_and_the_simulator() {
    let scenario =
        r#"{"time_scale": 1, "duration": 700, "robots": {"c": {"services": {"sample": 50}}}}"#;
    let out = scratch("loops/periodic-timeout");
    let traces = run_in_simulation(&fixture("periodic_timeout.mission"), &out, scenario);
    let first_call = |events: &[support::robots::Event]| -> Vec<String> {
        events
            .iter()
            .map(|e| match field(e, "event") {
                "graph_fire" => format!("{}/{}", field(e, "graph"), field(e, "task")),
                other => other.to_string(),
            })
            .skip_while(|e| e != "call_start")
            .take(6)
            .collect()
    };
    let expected = [
        "call_start",
        "sampler/Sample",
        "timeout",
        "sampler/Sample",
        "sampler/Average",
        "call_end",
    ];
    assert_eq!(first_call(&events(&traces["c"])), expected, "linux-sim");
    std::fs::write(out.join("scenario.json"), scenario).unwrap();
    let simulated = semo_in(
        &repo_root(),
        &[
            "simulate",
            &fixture("periodic_timeout.mission").display().to_string(),
            "--scenario",
            &out.join("scenario.json").display().to_string(),
            "--trace",
            "-",
        ],
    );
    assert_eq!(simulated.code, 0, "{}", simulated.stderr);
    let lines: Vec<String> = simulated.stdout.lines().map(str::to_string).collect();
    assert_eq!(first_call(&events(&lines)), expected, "semo simulate");
}

#[test]
fn graph_services_compile_pedantically_with_gcc_and_clang() {
    for target in ["linux", "linux-sim"] {
        for cc in compilers() {
            for mission in ["loops.mission", "tracking.mission", "periodic.mission"] {
                let out = scratch(&format!("loops/compile-{target}-{cc}-{mission}"));
                let built = support::robots::build_for(&fixture(mission), target, &out);
                assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
                for folder in robot_folders(&out) {
                    make(&folder, cc, PEDANTIC)
                        .unwrap_or_else(|e| panic!("{mission} {target} {cc}: {e}"));
                }
            }
        }
    }
}

/// Targets with a static schedule cannot run a graph inside a service task
/// yet: the build says so (E103) instead of generating a stub.
#[test]
fn a_graph_service_on_cortex_m_is_refused() {
    let out = scratch("loops/cortex-m");
    let built = build(&fixture("loops.mission"), "cortex-m", &out);
    assert_eq!(built.code, 1, "{}{}", built.stdout, built.stderr);
    assert!(
        built.stderr.contains("E103") && built.stderr.contains("runs task graph"),
        "{}",
        built.stderr
    );
}

/// The same refusal for a board the project file chose: the message names
/// the robot and how its target was chosen, and its related information
/// points at the project file's line that chose it.
#[test]
fn a_graph_service_on_a_board_the_project_file_chose_is_refused_pointing_at_the_choice() {
    let dir = scratch("loops/project-choice");
    std::fs::create_dir_all(dir.join("graphs")).unwrap();
    for file in ["loops.mission", "clusterer.robot.xml"] {
        std::fs::copy(fixture(file), dir.join(file)).unwrap();
    }
    for graph in std::fs::read_dir(fixture("graphs")).unwrap() {
        let graph = graph.unwrap().path();
        std::fs::copy(&graph, dir.join("graphs").join(graph.file_name().unwrap())).unwrap();
    }
    let project = "[project]\nversion = 1\nname = \"loops\"\ncatalogs = [\".\"]\n\n[build.targets]\nc = \"cortex-m\"\n";
    std::fs::write(dir.join("semo.toml"), project).unwrap();
    let built = semo_in(&dir, &["build", "--format", "json"]);
    assert_eq!(built.code, 1, "{}{}", built.stdout, built.stderr);
    let document: serde_json::Value = serde_json::from_str(&built.stdout).unwrap();
    let e103: Vec<&serde_json::Value> = document["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "E103")
        .collect();
    assert_eq!(e103.len(), 1, "{document}");
    let message = e103[0]["message"].as_str().unwrap();
    assert!(
        message.starts_with("robot `c` is built for cortex-m, ")
            && message.contains("runs task graph"),
        "{message}"
    );
    let related = &e103[0]["related"][0];
    assert_eq!(related["message"], "cortex-m is chosen here", "{document}");
    assert!(
        related["file"].as_str().unwrap().ends_with("semo.toml"),
        "{document}"
    );
    assert_eq!(related["line"], 7, "{document}");
    assert!(!dir.join("out").exists(), "nothing is written");
}

/// A sub-graph reference the workspace cannot follow refuses the build on
/// the service's call (E135), pointing at the graph file's own diagnostic:
/// a missing file (E067), a file leading back to the graph (E069) or one
/// whose open ports do not match the task's (E078). Nothing is written.
#[test]
fn a_service_graph_whose_sub_graph_cannot_be_used_is_refused_on_the_call() {
    let track = std::fs::read_to_string(fixture("graphs/track.taskgraph.xml")).unwrap();
    let filter = std::fs::read_to_string(fixture("graphs/filter.taskgraph.xml")).unwrap();
    let cases = [
        ("missing", None, "E067"),
        // filter.taskgraph.xml's Predict stands for track.taskgraph.xml again.
        (
            "cycle",
            Some(filter.replace(
                "<Task name=\"Predict\">",
                "<Task name=\"Predict\" subgraph=\"track.taskgraph.xml\">",
            )),
            "E069",
        ),
        (
            "ports",
            Some(filter.replace("name=\"out\"", "name=\"estimate\"")),
            "E078",
        ),
    ];
    for (name, sub, code) in cases {
        let dir = scratch(&format!("loops/unusable-{name}"));
        std::fs::create_dir_all(dir.join("graphs")).unwrap();
        for file in ["tracking.mission", "clusterer.robot.xml"] {
            std::fs::copy(fixture(file), dir.join(file)).unwrap();
        }
        for graph in ["kmeans", "data_loop", "convergent_loop", "sampler"] {
            let file = format!("graphs/{graph}.taskgraph.xml");
            std::fs::copy(fixture(&file), dir.join(&file)).unwrap();
        }
        std::fs::write(dir.join("graphs/track.taskgraph.xml"), &track).unwrap();
        if let Some(sub) = &sub {
            std::fs::write(dir.join("graphs/filter.taskgraph.xml"), sub).unwrap();
        }
        let out = dir.join("out");
        let built = semo_in(
            &dir,
            &[
                "build",
                "tracking.mission",
                "--target",
                "linux-sim",
                "--scenario",
                &fixture("tracking.scenario.json").display().to_string(),
                "-o",
                &out.display().to_string(),
                "--format",
                "json",
            ],
        );
        assert_eq!(built.code, 1, "{name}: {}", built.stderr);
        let json: serde_json::Value = serde_json::from_str(&built.stdout)
            .unwrap_or_else(|e| panic!("{name}: {e}: {}", built.stdout));
        let text = json.to_string();
        assert!(
            text.contains("\"E135\"") && text.contains(code),
            "{name}: {text}"
        );
        assert!(robot_folders(&out).is_empty(), "{name}: nothing is written");
    }
}
