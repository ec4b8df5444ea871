//! The simulator scales with the robots, not with the run: simulated as
//! `semo simulate` runs a mission without `--svg` or `--mcap` (the trace
//! streamed, `sim::simulate_into`, into the summary's digest and the trace
//! file's lines), a swarm of the generated benchmark mission (teams of six,
//! each talking to its neighbours) with twice the teams takes at most about
//! twice the events, entries of the event queue, allocations and peak of
//! live bytes, and four times the mission time of a mission takes about the
//! same memory, and an event costs under two and a half allocations. One test, so
//! that nothing else allocates while it counts.
//!
//! Measured with a counting allocator and the engine's event count, not a
//! clock, so the figures are the same on an idle and on a loaded machine.
//! The kept trace made 102 robots x 10 minutes take 958 MB and 1,000 robots
//! 4.4 GB; a table of every robot's heartbeats in every robot made the
//! memory grow with the square of the robots.

#[path = "../benches/common/mission.rs"]
mod mission;

#[path = "support/counting.rs"]
mod counting;

use semo::refine::RobotProgram;
use semo::sim::{self, scenario};

/// The refined programs of `mission` (a file name and its text).
fn programs(name: &str, text: String) -> Vec<RobotProgram> {
    let mut files = semo::workspace::Files::default();
    let id = files.add(name.into(), semo::workspace::FileKind::Mission, text);
    let mut host = semo::host::AnalysisHost::default();
    for f in files.iter() {
        host.set_file(f.id, Some(f.path.clone()), f.kind, f.text.as_str().into());
    }
    let build = host
        .analysis()
        .build_input(id)
        .expect("the mission was checked");
    let refined = semo::refine::refine_checked(&build.input());
    assert!(!refined.programs.is_empty(), "{:#?}", refined.diagnostics);
    refined.programs
}

/// What simulating `programs` for `until_ms` costs: (events, entries of
/// the event queue, peak of live bytes, allocations). Each trace event goes
/// to the summary's digest and is written as its line, as `semo simulate
/// --trace FILE` does.
fn cost(programs: &[RobotProgram], until_ms: i64) -> (u64, u64, usize, usize) {
    let scenario = scenario::parse("{}", programs).expect("an empty scenario reads");
    let options = sim::Options {
        until_ms: Some(until_ms),
        ..sim::Options::default()
    };
    let ((events, queued), peak, allocations) = counting::measure(|| {
        let robots = sim::Run::robots_of(programs);
        let mut digest = sim::Digest::new(&robots, &scenario.expect);
        let mut bytes = 0;
        let run = sim::simulate_into(programs, &scenario, &options, &mut |e| {
            digest.see(&e);
            bytes += e.to_json(&robots[e.robot].1).len();
        });
        assert!(bytes > 0 && run.trace.is_empty());
        assert!(!sim::summary_of(&run, &digest, &[]).contains("no mode"));
        (run.events, run.queued)
    });
    (events, queued, peak, allocations)
}

/// `large` over `small`, said and checked against `at_most`.
fn ratio(what: &str, small: usize, large: usize, at_most: f64) {
    let ratio = large as f64 / small as f64;
    eprintln!("{what}: {small} -> {large} (x{ratio:.2})");
    assert!(
        ratio <= at_most,
        "{what} grew x{ratio:.2} ({small} -> {large})"
    );
}

#[test]
fn the_simulators_work_follows_the_robots_and_its_memory_not_the_runs_length() {
    let _one = counting::MEASURING
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let swarm = |teams| programs("swarm.mission", mission::generate(teams));
    // Once first, so that what is built once per process is not counted.
    cost(&swarm(1), 100);
    let (small, large) = (swarm(8), swarm(16));
    assert_eq!((small.len(), large.len()), (48, 96));
    let (events_small, queued_small, peak_small, work_small) = cost(&small, 5000);
    let (events_large, queued_large, peak_large, work_large) = cost(&large, 5000);
    ratio("events", events_small as usize, events_large as usize, 2.1);
    ratio(
        "queue entries",
        queued_small as usize,
        queued_large as usize,
        2.1,
    );
    // A message to a team is one entry for the robots it reaches at one
    // instant, not one per robot: the queue took an entry per event.
    assert!(
        queued_large * 4 < events_large * 3,
        "{queued_large} queue entries for {events_large} events"
    );
    ratio("allocations", work_small, work_large, 2.2);
    // Under two and a half allocations per event, the trace line's text
    // among them: each trace event's fields in a list of their own on the
    // heap, and a text value copied into every slot and message that
    // carries it, took 5.4 (5.42 on the 96 robots); each heartbeat's text
    // made anew and each instant's recipients listed twice, 3.16 (2.90
    // since); a trace line's text grown from 64 bytes and a list of the
    // channels each message taken writes, 3.00 (2.02 since).
    let per_event = work_large as f64 / events_large as f64;
    eprintln!("allocations per event: {per_event:.2}");
    assert!(
        per_event <= 2.5,
        "{per_event:.2} allocations per event ({work_large} for {events_large})"
    );
    ratio("peak bytes", peak_small, peak_large, 2.2);

    // (A receive task held up by a full channel takes every message behind
    // it once free: no backlog grows with the run. It took one message at
    // a time, and the 1,002-robot benchmark's grew to 290 of its 362 MB.)
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let patrol = std::fs::read_to_string(root.join("examples/swarm/patrol_groups.mission"))
        .expect("the example");
    let patrol = programs("patrol_groups.mission", patrol);
    let (events_short, _, peak_short, _) = cost(&patrol, 20_000);
    let (events_long, _, peak_long, _) = cost(&patrol, 80_000);
    ratio("events", events_short as usize, events_long as usize, 4.2);
    // A kept trace took four times the memory.
    ratio("peak bytes", peak_short, peak_long, 1.1);
}

/// What simulating `programs` for `until_ms` as `semo simulate` runs a
/// scenario without expectations and without `--trace` costs (no message
/// traced, `Options::untraced_messages`): (events, entries of the event
/// queue, allocations, members of counted groups walked).
fn untraced_cost(programs: &[RobotProgram], until_ms: i64) -> (u64, u64, usize, u64) {
    let scenario = scenario::parse("{}", programs).expect("an empty scenario reads");
    let options = sim::Options {
        until_ms: Some(until_ms),
        untraced_messages: true,
        ..sim::Options::default()
    };
    let ((events, queued, walked), _, allocations) = counting::measure(|| {
        let robots = sim::Run::robots_of(programs);
        let mut digest = sim::Digest::new(&robots, &scenario.expect);
        let run = sim::simulate_into(programs, &scenario, &options, &mut |e| digest.see(&e));
        assert!(!sim::summary_of(&run, &digest, &[]).contains("no mode"));
        (run.events, run.queued, run.members_walked)
    });
    (events, queued, allocations, walked)
}

#[test]
fn a_heartbeat_heard_costs_no_allocation_and_a_heartbeat_sent_one_queue_entry() {
    let _one = counting::MEASURING
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    // The benchmark's input is the generator's (`cargo bench --bench simulate`).
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let fixture = std::fs::read_to_string(root.join("benches/fixtures/nested_groups.mission"))
        .expect("the benchmark mission");
    assert_eq!(fixture, mission::nested_groups(200));

    let team = |robots| programs("nested_groups.mission", mission::nested_groups(robots));
    untraced_cost(&team(10), 100);
    let (small, large) = (team(20), team(40));
    let (events_small, queued_small, work_small, walked_small) = untraced_cost(&small, 5000);
    let (events_large, queued_large, work_large, walked_large) = untraced_cost(&large, 5000);
    // Every robot hears every other: twice the robots, four times the
    // heartbeats heard; but a heartbeat sent is one entry of the queue
    // for all its robots, and hearing one allocates nothing.
    ratio("events", events_small as usize, events_large as usize, 4.3);
    ratio(
        "queue entries",
        queued_small as usize,
        queued_large as usize,
        2.2,
    );
    ratio("allocations", work_small, work_large, 2.5);
    // Every robot passes through the rooms each second, but the robots
    // that count alive the same ones share one walk over the members
    // (`engine/counted.rs`): each robot walking its own took 3.4 times
    // as many members here, and 400 robots 3.5 times as long as 200.
    ratio(
        "members walked",
        walked_small as usize,
        walked_large as usize,
        2.1,
    );
    // What twice the mission time adds (the robots' start and the summary
    // left out): a heartbeat's message and list of robots for its 39
    // hearers, and each pass through the counted groups' lists of live
    // members (0.23 per event); an allocation per hearer took one per
    // event more.
    let (events_longer, _, work_longer, _) = untraced_cost(&large, 10_000);
    let per_event = (work_longer - work_large) as f64 / (events_longer - events_large) as f64;
    eprintln!("allocations per event, no message traced: {per_event:.3}");
    assert!(
        per_event <= 0.5,
        "{per_event:.3} allocations per event ({work_large} for {events_large}, {work_longer} for {events_longer})"
    );
}
