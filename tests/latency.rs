//! `semo graph latency` end to end: a pipeline worked by hand, the answers
//! checked against a step-by-step execution written here from the task
//! graph model alone (our graphs and SDF3 benchmarks), and the refusals:
//! unknown tasks, tasks no path joins, graphs that deadlock or whose rates
//! contradict.

mod support;

use semo::diag::FileId;
use semo::taskgraph::{Direction, TaskGraph, load_task_graph};
use support::{examples, sdf3, semo_in};

/// Sensor (2) → Filter (5) → Actuator (1), the actuator giving a sample
/// back to the sensor: at most two samples in the pipeline.
const PIPELINE: &str = r#"<TaskGraph name="pipeline" xmlns="urn:semo:taskgraph:1">
  <Task name="Sensor" wcet="2"><Port name="o" dir="out"/><Port name="back" dir="in"/></Task>
  <Task name="Filter" wcet="5"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>
  <Task name="Actuator" wcet="1"><Port name="i" dir="in"/><Port name="back" dir="out"/></Task>
  <Channel src="Sensor.o" dst="Filter.i"/>
  <Channel src="Filter.o" dst="Actuator.i"/>
  <Channel src="Actuator.back" dst="Sensor.back" initialTokens="2"/>
</TaskGraph>"#;

/// Camera (3) makes 2 samples a firing, Detector (4) takes 3 and makes 1,
/// Control (2) takes 2 and gives 3 back, of which Camera takes 1 a firing:
/// counts 3, 2, 1; one sample waits on Camera → Detector, four on the way
/// back.
const MULTIRATE: &str = r#"<TaskGraph name="multirate" xmlns="urn:semo:taskgraph:1">
  <Task name="Camera" wcet="3"><Port name="o" dir="out" rate="2"/><Port name="back" dir="in"/></Task>
  <Task name="Detector" wcet="4"><Port name="i" dir="in" rate="3"/><Port name="o" dir="out"/></Task>
  <Task name="Control" wcet="2"><Port name="i" dir="in" rate="2"/><Port name="back" dir="out" rate="3"/></Task>
  <Channel src="Camera.o" dst="Detector.i" initialTokens="1"/>
  <Channel src="Detector.o" dst="Control.i"/>
  <Channel src="Control.back" dst="Camera.back" initialTokens="4"/>
</TaskGraph>"#;

fn write(name: &str, text: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(name), text).unwrap();
    dir
}

/// `semo graph latency` in JSON: its exit status and document.
fn latency_json(
    dir: &std::path::Path,
    file: &str,
    from: &str,
    to: &str,
    flags: &[&str],
) -> (i32, serde_json::Value) {
    let mut args = vec![
        "graph", "latency", file, "--from", from, "--to", to, "--format", "json",
    ];
    args.extend(flags);
    let out = semo_in(dir, &args);
    let doc = serde_json::from_str(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}{}", out.stdout, out.stderr));
    (out.code, doc)
}

/// Worked by hand (every count 1; no Actuator firing comes before the
/// Sensor's, so iteration k runs from the Sensor's firing k to the
/// Actuator's firing k). Minimal: Sensor 0–2, Filter 2–7, Actuator 7–8: 8.
/// Self-timed, one firing of a task at a time (start–end of firing k):
///
/// | k | Sensor | Filter | Actuator | L(k)    |
/// |---|--------|--------|----------|---------|
/// | 0 | 0–2    | 2–7    | 7–8      | 8 − 0   |
/// | 1 | 2–4    | 7–12   | 12–13    | 13 − 2  |
/// | 2 | 8–10   | 12–17  | 17–18    | 18 − 8  |
/// | 3 | 13–15  | 17–22  | 22–23    | 23 − 13 |
///
/// The Sensor's firing 2 waits for the Actuator's firing 0 to give a
/// sample back (at 8); the Filter, busy until 7, starts its firing 1 then.
/// From iteration 2 on every latency is 10: the largest is 11, at
/// iteration 1. With auto-concurrency the Sensor and the Filter fire twice
/// at once (0–2, 2–7), the Actuator twice 7–8, the samples back at 8: 8
/// every iteration. From the Filter: Filter 0–5, Actuator 5–6 alone; in the
/// self-timed execution the Filter's firings start at 2, 7, 12, … and the
/// Actuator's end at 8, 13, 18, …: 6.
#[test]
fn a_pipeline_worked_by_hand() {
    let dir = write("pipeline.taskgraph.xml", PIPELINE);
    let out = semo_in(
        dir.path(),
        &[
            "graph",
            "latency",
            "pipeline.taskgraph.xml",
            "--from",
            "Sensor",
            "--to",
            "Actuator",
        ],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(
        out.stdout,
        "concurrency: single (one firing of a task at a time)\n\
         iteration k: from the start of Sensor's firing k to the end of Actuator's firing k \
         (Actuator fires 0 times before Sensor first does)\n\
         minimal latency: 8\n\
         self-timed latency: 11 (the largest, first at iteration 1; the latencies repeat \
         every 1 iteration from iteration 3 on at the latest)\n"
    );
    let (code, doc) = latency_json(
        dir.path(),
        "pipeline.taskgraph.xml",
        "Sensor",
        "Actuator",
        &[],
    );
    assert_eq!(code, 0);
    assert_eq!(doc["command"], "graph latency");
    assert_eq!(doc["concurrency"], "single");
    assert_eq!(doc["minimal"], 8);
    assert_eq!(doc["self_timed"]["latency"], 11);
    assert_eq!(doc["self_timed"]["worst_iteration"], 1);
    assert_eq!(doc["no_self_timed"], serde_json::Value::Null);
    let (_, auto) = latency_json(
        dir.path(),
        "pipeline.taskgraph.xml",
        "Sensor",
        "Actuator",
        &["--concurrency", "auto"],
    );
    assert_eq!(
        (&auto["minimal"], &auto["self_timed"]["latency"]),
        (&8.into(), &8.into())
    );
    let (_, filter) = latency_json(
        dir.path(),
        "pipeline.taskgraph.xml",
        "Filter",
        "Actuator",
        &[],
    );
    assert_eq!(
        (&filter["minimal"], &filter["self_timed"]["latency"]),
        (&6.into(), &6.into())
    );
}

/// The self-timed execution of a task graph's tasks that `sink` depends on
/// (no other can change when its firings end), written from the model
/// alone: every firing under way in one list, each instant scanned whole.
struct Execution {
    wcet: Vec<u64>,
    /// (source task, destination task, produced, consumed) per channel.
    channels: Vec<(usize, usize, u64, u64)>,
    tokens: Vec<u64>,
    single: bool,
    time: u64,
    /// (task, end time) of the firings under way.
    running: Vec<(usize, u64)>,
    /// Per task, the most firings it may start.
    most: Vec<u64>,
    started: Vec<u64>,
    starts: Vec<Vec<u64>>,
    ends: Vec<Vec<u64>>,
}

impl Execution {
    fn new(graph: &TaskGraph, single: bool, sink: usize) -> Execution {
        let index = |name: &str| {
            graph
                .tasks
                .iter()
                .position(|t| t.name.name == name)
                .unwrap()
        };
        let rate = |task: usize, port: &str, dir: Direction| {
            let p = graph.tasks[task].port(port).unwrap();
            assert_eq!(p.dir, dir);
            p.rate
        };
        let channels: Vec<(usize, usize, u64, u64)> = graph
            .channels
            .iter()
            .map(|c| {
                let (a, b) = (index(&c.src.task), index(&c.dst.task));
                (
                    a,
                    b,
                    rate(a, &c.src.port, Direction::Out),
                    rate(b, &c.dst.port, Direction::In),
                )
            })
            .collect();
        let n = graph.tasks.len();
        let mut before_sink = vec![false; n];
        before_sink[sink] = true;
        while let Some(&(a, _, _, _)) = channels
            .iter()
            .find(|&&(a, b, _, _)| before_sink[b] && !before_sink[a])
        {
            before_sink[a] = true;
        }
        Execution {
            wcet: graph.tasks.iter().map(|t| t.wcet.unwrap_or(0)).collect(),
            tokens: graph.channels.iter().map(|c| c.initial_tokens).collect(),
            channels,
            single,
            time: 0,
            running: Vec::new(),
            most: (0..n)
                .map(|v| if before_sink[v] { u64::MAX } else { 0 })
                .collect(),
            started: vec![0; n],
            starts: vec![Vec::new(); n],
            ends: vec![Vec::new(); n],
        }
    }

    fn finish(&mut self, v: usize) {
        self.ends[v].push(self.time);
        for (i, &(a, _, p, _)) in self.channels.iter().enumerate() {
            if a == v {
                self.tokens[i] += p;
            }
        }
    }

    fn can_start(&self, v: usize) -> bool {
        let inputs = self
            .channels
            .iter()
            .enumerate()
            .all(|(i, &(_, b, _, c))| b != v || self.tokens[i] >= c);
        let idle = !self.single || self.running.iter().all(|&(u, _)| u != v);
        inputs && idle && self.started[v] < self.most[v]
    }

    /// The firings due now end, then firings start until none can.
    fn instant(&mut self) {
        let now = self.time;
        let mut due: Vec<usize> = Vec::new();
        self.running.retain(|&(v, end)| {
            if end == now {
                due.push(v);
            }
            end != now
        });
        for v in due {
            self.finish(v);
        }
        let mut fired = 0;
        while let Some(v) = (0..self.wcet.len()).find(|&v| self.can_start(v)) {
            fired += 1;
            assert!(fired < 1_000_000, "firings without end at {now}");
            for (i, &(_, b, _, c)) in self.channels.iter().enumerate() {
                if b == v {
                    self.tokens[i] -= c;
                }
            }
            self.started[v] += 1;
            self.starts[v].push(now);
            if self.wcet[v] == 0 {
                self.finish(v);
            } else {
                self.running.push((v, now + self.wcet[v]));
            }
        }
    }

    /// On to the next end of a firing; `false` when none is under way.
    fn next(&mut self) -> bool {
        match self.running.iter().map(|&(_, end)| end).min() {
            Some(t) => {
                self.time = t;
                true
            }
            None => false,
        }
    }
}

/// What the execution says of `from` → `to`, with γ from the analysis:
/// `d`, the minimal latency, and `L(k)` for the first `iterations`.
fn executed(
    graph: &TaskGraph,
    single: bool,
    (from, to): (usize, usize),
    (gamma_from, gamma_to): (u64, u64),
    iterations: u64,
) -> (u64, u64, Vec<u64>) {
    let mut held = Execution::new(graph, single, to);
    held.most[from] = 0;
    for instants in 0.. {
        held.instant();
        if !held.next() {
            break;
        }
        assert!(
            instants < 1_000_000,
            "the source held back, the rest never stops"
        );
    }
    let before = held.ends[to].len() as u64;
    let offset = before / gamma_to * gamma_to + gamma_to - 1;
    held.most[from] = gamma_from;
    let release = held.time;
    let minimal = loop {
        held.instant();
        if held.ends[to].len() as u64 > offset {
            break held.time - release;
        }
        assert!(held.next(), "the sink's firing never came");
    };
    let mut free = Execution::new(graph, single, to);
    let needed = usize::try_from(iterations * gamma_to + offset).unwrap();
    while free.ends[to].len() <= needed {
        free.instant();
        assert!(free.next());
    }
    let latencies = (0..iterations)
        .map(|k| {
            let end = free.ends[to][usize::try_from(k * gamma_to + offset).unwrap()];
            end - free.starts[from][usize::try_from(k * gamma_from).unwrap()]
        })
        .collect();
    (before, minimal, latencies)
}

/// On our graphs (both readings of concurrency) and SDF3 benchmarks, the
/// minimal latency, `d` and the self-timed latency (the largest `L(k)` over
/// the iterations until the latencies repeat) are the execution's.
#[test]
fn latencies_are_those_of_a_step_by_step_execution() {
    let ours = write("m.taskgraph.xml", MULTIRATE);
    std::fs::write(ours.path().join("p.taskgraph.xml"), PIPELINE).unwrap();
    let cases: Vec<(std::path::PathBuf, &str, &str, &str)> = vec![
        (
            ours.path().join("p.taskgraph.xml"),
            "Sensor",
            "Actuator",
            "single",
        ),
        (
            ours.path().join("p.taskgraph.xml"),
            "Sensor",
            "Actuator",
            "auto",
        ),
        (
            ours.path().join("p.taskgraph.xml"),
            "Filter",
            "Sensor",
            "single",
        ),
        (
            ours.path().join("m.taskgraph.xml"),
            "Camera",
            "Control",
            "single",
        ),
        (
            ours.path().join("m.taskgraph.xml"),
            "Camera",
            "Control",
            "auto",
        ),
        (
            ours.path().join("m.taskgraph.xml"),
            "Detector",
            "Camera",
            "single",
        ),
        // Every task before the sink after the source: the source held
        // back, the execution stops.
        (sdf3().join("modem.xml"), "in", "deco", "auto"),
        (sdf3().join("satellite.xml"), "a", "t", "auto"),
        (sdf3().join("random_50.xml"), "a0", "a48", "auto"),
        (sdf3().join("random_200.xml"), "a0", "a193", "auto"),
    ];
    let mut unequal = 0;
    for (path, from, to, concurrency) in cases {
        let what = format!("{} {from}→{to} {concurrency}", path.display());
        let file = path.to_str().unwrap();
        let (code, doc) = latency_json(
            &std::env::temp_dir(),
            file,
            from,
            to,
            &["--concurrency", concurrency],
        );
        assert_eq!(code, 0, "{what}: {doc}");
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, _) = load_task_graph(FileId(0), &text);
        let graph = graph.unwrap();
        let index = |name: &str| {
            graph
                .tasks
                .iter()
                .position(|t| t.name.name == name)
                .unwrap()
        };
        let gamma = (
            doc["firings"]["from"].as_u64().unwrap(),
            doc["firings"]["to"].as_u64().unwrap(),
        );
        let st = &doc["self_timed"];
        let iterations = st["periodic_from"].as_u64().unwrap() + st["cycle"].as_u64().unwrap();
        let (before, minimal, latencies) = executed(
            &graph,
            concurrency == "single",
            (index(from), index(to)),
            gamma,
            iterations,
        );
        assert_eq!(doc["sink_firings_before"], before, "{what}");
        assert_eq!(doc["minimal"], minimal, "{what}");
        let worst = *latencies.iter().max().unwrap();
        assert_eq!(st["latency"], worst, "{what}: {latencies:?}");
        let at = latencies.iter().position(|&l| l == worst).unwrap();
        assert_eq!(st["worst_iteration"], at, "{what}");
        unequal += usize::from(minimal != worst);
    }
    // Some of these pipeline several iterations, so that the self-timed
    // latency is not the minimal one.
    assert!(unequal >= 3, "{unequal}");
}

/// A slower task after the source: samples pile up, the latency grows
/// every iteration. An answer (exit 0), said in words and in JSON.
#[test]
fn a_slower_task_after_the_source_makes_the_latency_unbounded() {
    let text = r#"<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="Sensor" wcet="1"><Port name="o" dir="out"/></Task>
  <Task name="Planner" wcet="3"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>
  <Task name="Motor" wcet="1"><Port name="i" dir="in"/></Task>
  <Channel src="Sensor.o" dst="Planner.i"/>
  <Channel src="Planner.o" dst="Motor.i"/>
</TaskGraph>"#;
    let dir = write("g.taskgraph.xml", text);
    let out = semo_in(
        dir.path(),
        &[
            "graph",
            "latency",
            "g.taskgraph.xml",
            "--from",
            "Sensor",
            "--to",
            "Motor",
        ],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stdout.contains("minimal latency: 5\n"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains(
            "self-timed latency: unbounded: `Planner` takes 3 per iteration, but the source starts one every 1"
        ),
        "{}",
        out.stdout
    );
    let (code, doc) = latency_json(dir.path(), "g.taskgraph.xml", "Sensor", "Motor", &[]);
    assert_eq!(code, 0);
    assert_eq!(doc["self_timed"], serde_json::Value::Null);
    assert_eq!(doc["no_self_timed"]["reason"], "unbounded");
}

#[test]
fn unknown_tasks_are_refused_with_a_suggestion() {
    let dir = write("pipeline.taskgraph.xml", PIPELINE);
    let out = semo_in(
        dir.path(),
        &[
            "graph",
            "latency",
            "pipeline.taskgraph.xml",
            "--from",
            "Sensr",
            "--to",
            "Actuator",
        ],
    );
    assert_eq!(out.code, 2);
    assert_eq!(
        out.stderr,
        "error: no task `Sensr` in the graph's top level (did you mean `Sensor`?)\n"
    );
    let out = semo_in(
        dir.path(),
        &[
            "graph",
            "latency",
            "pipeline.taskgraph.xml",
            "--from",
            "Sensor",
            "--to",
            "Wheel",
        ],
    );
    assert_eq!(out.code, 2);
    assert!(
        out.stderr
            .contains("no task `Wheel` in the graph's top level (tasks: Sensor, Filter, Actuator)"),
        "{}",
        out.stderr
    );
    let (code, doc) = latency_json(
        dir.path(),
        "pipeline.taskgraph.xml",
        "Sensor",
        "actuator",
        &[],
    );
    assert_eq!(code, 2);
    let message = doc["diagnostics"][0]["message"].as_str().unwrap();
    assert!(message.contains("did you mean `Actuator`?"), "{message}");
}

#[test]
fn tasks_no_path_joins_have_no_latency() {
    let dir = write(
        "pipeline.taskgraph.xml",
        &PIPELINE
            .replace(
                r#"<Channel src="Actuator.back" dst="Sensor.back" initialTokens="2"/>"#,
                "",
            )
            .replace(r#"<Port name="back" dir="in"/>"#, "")
            .replace(r#"<Port name="back" dir="out"/>"#, ""),
    );
    let out = semo_in(
        dir.path(),
        &[
            "graph",
            "latency",
            "pipeline.taskgraph.xml",
            "--from",
            "Actuator",
            "--to",
            "Sensor",
        ],
    );
    assert_eq!(out.code, 1);
    assert!(
        out.stderr.contains(
            "no latency from `Actuator` to `Sensor`: no path of channels leads from the source to the sink"
        ),
        "{}",
        out.stderr
    );
    let (code, doc) = latency_json(
        dir.path(),
        "pipeline.taskgraph.xml",
        "Actuator",
        "Sensor",
        &[],
    );
    assert_eq!(code, 1);
    assert_eq!(doc["error"]["reason"], "no_path");
}

/// A graph that deadlocks or whose rates contradict: its diagnostics, at
/// their place in the file, and no latency.
#[test]
fn deadlocked_and_inconsistent_graphs_have_no_latency() {
    let dir = examples().join("taskgraphs");
    let out = semo_in(
        &dir,
        &[
            "graph",
            "latency",
            "deadlock.taskgraph.xml",
            "--from",
            "S",
            "--to",
            "Z",
        ],
    );
    assert_eq!(out.code, 1);
    assert!(out.stderr.contains("E071"), "{}", out.stderr);
    assert!(
        out.stderr.contains("deadlock.taskgraph.xml:10:"),
        "{}",
        out.stderr
    );
    assert!(
        out.stderr
            .contains("error: deadlock.taskgraph.xml: no latency: an iteration deadlocks"),
        "{}",
        out.stderr
    );
    let (code, doc) = latency_json(&dir, "deadlock.taskgraph.xml", "S", "Z", &[]);
    assert_eq!(code, 1);
    assert_eq!(doc["diagnostics"][0]["code"], "E071");
    let out = semo_in(
        &dir,
        &[
            "graph",
            "latency",
            "inconsistent.taskgraph.xml",
            "--from",
            "A",
            "--to",
            "D",
        ],
    );
    assert_eq!(out.code, 1);
    assert!(out.stderr.contains("E070"), "{}", out.stderr);
    assert!(
        out.stderr
            .contains("no latency: its rates are inconsistent"),
        "{}",
        out.stderr
    );
}
