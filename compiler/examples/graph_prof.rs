//! Times each analysis of one level of a task graph (for finding slow parts).
use semo::taskgraph::analysis::{
    buffers, consistency, deadlock, level::Level, schedule, throughput,
};
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).expect("a task graph file");
    let text = std::fs::read_to_string(path).expect("readable");
    let (graph, _) = semo::taskgraph::load_task_graph(semo::diag::FileId(0), &text);
    let graph = graph.expect("loads");
    let level = Level::build(&graph, None, graph.name.clone());
    let t = Instant::now();
    let counts = consistency::repetition_vector(&level).expect("consistent");
    println!("repetition   {:?}", t.elapsed());
    let t = Instant::now();
    deadlock::find_deadlock(&level, &counts);
    println!("deadlock     {:?}", t.elapsed());
    let t = Instant::now();
    let sas = schedule::single_appearance(&level, &counts);
    println!(
        "single-app.  {:?} ({})",
        t.elapsed(),
        if sas.is_some() { "found" } else { "none" }
    );
    let t = Instant::now();
    let flat = schedule::flat_schedule(&level, &counts).expect("live");
    println!("flat         {:?}", t.elapsed());
    let t = Instant::now();
    buffers::buffer_bounds(&level, &flat);
    println!("buffers      {:?}", t.elapsed());
    let t = Instant::now();
    // (Timed whether or not there is a period.)
    let _ = throughput::throughput(&level, &counts, throughput::Concurrency::Auto);
    println!("throughput   {:?}", t.elapsed());
}
