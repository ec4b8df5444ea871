//! The task-graph analyses are bounded on any graph: a chain of a million
//! tasks is analysed (what `semo graph analyze` and `semo graph schedule`
//! run) without a deep recursion, and in linear memory and work: twice the
//! tasks take at most about twice the peak of live bytes and twice the
//! allocations. Measured with a counting allocator, not a clock, so the
//! figures are the same on an idle and on a loaded machine.
//!
//! A recursive strongly-connected-components walk overflowed the stack at
//! 139,000 tasks; a search per channel end for its task made `graph dot`
//! quadratic.

#[path = "support/counting.rs"]
mod counting;

use semo::diag::FileId;

/// A chain `t0 → t1 → … → t(n-1)` in our format, every task of time 1.
fn chain(n: usize) -> String {
    let mut text = String::with_capacity(n * 100);
    text.push_str("<TaskGraph name=\"chain\" xmlns=\"urn:semo:taskgraph:1\">\n");
    for v in 0..n {
        text.push_str(&format!("<Task name=\"t{v}\" wcet=\"1\">"));
        if v > 0 {
            text.push_str("<Port name=\"i\" dir=\"in\"/>");
        }
        if v + 1 < n {
            text.push_str("<Port name=\"o\" dir=\"out\"/>");
        }
        text.push_str("</Task>\n");
    }
    for v in 1..n {
        text.push_str(&format!("<Channel src=\"t{}.o\" dst=\"t{v}.i\"/>\n", v - 1));
    }
    text.push_str("</TaskGraph>\n");
    text
}

/// Loads and analyses a chain of `n` tasks as `semo graph analyze` does,
/// and draws it in DOT: its peak of live bytes and its allocations.
fn analysis_of_chain(n: usize) -> (usize, usize) {
    let text = chain(n);
    let _one = counting::MEASURING
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let ((), peak, allocations) = counting::measure(|| {
        let (graph, diagnostics) = semo::taskgraph::load_task_graph(FileId(0), &text);
        assert!(diagnostics.is_empty(), "{:?}", &diagnostics[..1]);
        let graph = graph.expect("the chain loads");
        let report = semo::taskgraph::analysis::analyze(&graph);
        assert!(report.diagnostics.is_empty());
        let level = &report.levels[0];
        assert_eq!(level.deadlock_free, Some(true));
        // One firing at a time: every task alone bounds the period at 1.
        let period = level.throughput.as_ref().expect("a period").period;
        assert_eq!(period.to_string(), "1");
        assert!(report.looped_schedule.is_some());
        let dot = semo::taskgraph::dot::to_dot(&graph);
        assert_eq!(dot.matches(" -> ").count(), n - 1);
    });
    (peak, allocations)
}

/// Twice the tasks take at most about twice the memory and the work.
fn scales_linearly(small: usize, large: usize) {
    // Once first, so that what is built once per process is not counted.
    analysis_of_chain(100);
    let (peak_small, work_small) = analysis_of_chain(small);
    let (peak_large, work_large) = analysis_of_chain(large);
    let memory = peak_large as f64 / peak_small as f64;
    let work = work_large as f64 / work_small as f64;
    eprintln!(
        "{small} tasks: {peak_small} bytes, {work_small} allocations; {large}: {peak_large} bytes, {work_large} allocations (x{memory:.2}, x{work:.2})"
    );
    assert!(
        memory < 2.4,
        "twice the tasks took x{memory:.2} the memory: not linear"
    );
    assert!(
        work < 2.4,
        "twice the tasks took x{work:.2} the allocations: not linear"
    );
}

/// Past the 139,000 tasks where the recursive walk overflowed (in CI: the
/// million-task run below takes 4 GB and 96 s in a debug build).
#[test]
fn chains_past_the_old_stack_limit_are_analysed_in_linear_memory_and_work() {
    scales_linearly(150_000, 300_000);
}

#[test]
#[ignore = "4 GB and about 100 s in a debug build (cargo test --test chain_scaling -- --ignored)"]
fn a_chain_of_a_million_tasks_is_analysed_in_linear_memory_and_work() {
    scales_linearly(500_000, 1_000_000);
}
