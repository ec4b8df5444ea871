use semo::taskgraph::analysis::{consistency, deadlock, level::Level};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let (g, _) = semo::taskgraph::load_task_graph(semo::diag::FileId(0), &text);
    let g = g.unwrap();
    let t = std::time::Instant::now();
    let level = Level::build(&g, None, g.name.clone());
    let t1 = t.elapsed();
    let counts = consistency::repetition_vector(&level).unwrap();
    let t2 = t.elapsed();
    let d = deadlock::find_deadlock(&level, &counts);
    let t3 = t.elapsed();
    println!(
        "build {:?} rep {:?} dead {:?} sum {} edges {} {:?}",
        t1,
        t2 - t1,
        t3 - t2,
        counts.iter().sum::<u64>(),
        level.edges.len(),
        d.is_some()
    );
}
