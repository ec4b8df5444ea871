//! Task-graph analysis times: every SDF3 benchmark graph, and generated
//! multirate graphs of 1k, 10k and 100k tasks. Run with `cargo bench`.
//! Targets: repetition vector linear in size (100k tasks under 100 ms), the full
//! analysis of each SDF3 benchmark under 10 ms ("analyse" below: consistency,
//! deadlock, schedules, buffers, throughput and the SDF/L rules). "svg" is the
//! picture (`semo graph svg`: layout and SVG text), for the SDF3 graphs and the
//! generated 1k and 10k graphs.

mod common;
use common::fastest;

use semo::diag::FileId;
use semo::taskgraph::analysis::{self, consistency, deadlock, level::Level, throughput};
use semo::taskgraph::{load_task_graph, to_svg};
use std::fmt::Write;
use std::hint::black_box;
use std::time::Duration;

/// A chain of `n` tasks with alternating rates (2 out, 1 in; then 1 out, 2 in)
/// so the repetition vector alternates 1, 2, plus side branches and a feedback
/// channel with enough initial samples.
fn generate(n: usize) -> String {
    let mut g = String::from("<TaskGraph name=\"generated\">\n");
    for i in 0..n {
        let (out, inp) = if i % 2 == 0 { (2, 2) } else { (1, 1) };
        writeln!(
            g,
            "<Task name=\"t{i}\" wcet=\"{}\"><Port name=\"i\" dir=\"in\" rate=\"{inp}\"/><Port name=\"o\" dir=\"out\" rate=\"{out}\"/><Port name=\"side\" dir=\"out\" rate=\"1\"/><Port name=\"fromside\" dir=\"in\" rate=\"1\"/></Task>",
            1 + i % 7
        )
        .unwrap();
    }
    for i in 0..n {
        let next = (i + 1) % n;
        let tokens = if next == 0 { 4 } else { 0 };
        writeln!(
            g,
            "<Channel src=\"t{i}.o\" dst=\"t{next}.i\" initialTokens=\"{tokens}\"/>"
        )
        .unwrap();
        writeln!(
            g,
            "<Channel src=\"t{i}.side\" dst=\"t{i}.fromside\" initialTokens=\"1\"/>"
        )
        .unwrap();
    }
    g.push_str("</TaskGraph>\n");
    g
}

fn main() {
    let budget = Duration::from_millis(700);
    let sdf3 = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sdf3");
    println!(
        "{:<40} {:>8} {:>10} {:>12} {:>12}",
        "SDF3 graph", "tasks", "load", "analyse", "svg"
    );
    let mut paths: Vec<_> = std::fs::read_dir(sdf3)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    paths.retain(|p| p.extension().and_then(|e| e.to_str()) == Some("xml"));
    paths.sort();
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, _) = load_task_graph(FileId(0), &text);
        let graph = graph.expect("SDF3 graph loads");
        let report = analysis::analyze(&graph);
        assert!(report.is_consistent() && report.is_deadlock_free());
        let load = fastest(budget, || {
            black_box(load_task_graph(FileId(0), black_box(&text)));
        });
        let analyse = fastest(budget, || {
            black_box(analysis::analyze(black_box(&graph)));
        });
        let svg = fastest(budget, || {
            black_box(to_svg(black_box(&graph)));
        });
        println!(
            "{:<40} {:>8} {:>8.3}ms {:>10.3}ms {:>10.3}ms",
            path.file_name().unwrap().to_string_lossy(),
            graph.tasks.len(),
            load.as_secs_f64() * 1e3,
            analyse.as_secs_f64() * 1e3,
            svg.as_secs_f64() * 1e3
        );
    }
    println!();
    println!(
        "{:<12} {:>12} {:>16} {:>12} {:>12} {:>12}",
        "generated", "load", "repetition", "deadlock", "throughput", "svg"
    );
    for n in [1_000, 10_000, 100_000] {
        let text = generate(n);
        let (graph, diags) = load_task_graph(FileId(0), &text);
        assert!(diags.is_empty(), "{:?}", &diags[..diags.len().min(3)]);
        let graph = graph.unwrap();
        let level = Level::build(&graph, None, graph.name.clone());
        let counts = consistency::repetition_vector(&level).expect("consistent");
        assert!(deadlock::find_deadlock(&level, &counts).is_none());
        let load = fastest(budget, || {
            black_box(load_task_graph(FileId(0), black_box(&text)));
        });
        let repetition = fastest(budget, || {
            black_box(consistency::repetition_vector(black_box(&level)).ok());
        });
        let dead = fastest(budget, || {
            black_box(deadlock::find_deadlock(black_box(&level), &counts));
        });
        let period = fastest(budget, || {
            let _ = black_box(throughput::throughput(
                black_box(&level),
                &counts,
                throughput::Concurrency::Single,
            ));
        });
        // The picture of 100k tasks is a few tens of megabytes: not timed.
        let svg = (n <= 10_000).then(|| {
            let t = fastest(budget, || {
                black_box(to_svg(black_box(&graph)));
            });
            format!("{:.2}ms", t.as_secs_f64() * 1e3)
        });
        println!(
            "{:<12} {:>10.2}ms {:>14.2}ms {:>10.2}ms {:>10.2}ms {:>12}",
            format!("{n} tasks"),
            load.as_secs_f64() * 1e3,
            repetition.as_secs_f64() * 1e3,
            dead.as_secs_f64() * 1e3,
            period.as_secs_f64() * 1e3,
            svg.unwrap_or_else(|| "-".to_string())
        );
    }
}
