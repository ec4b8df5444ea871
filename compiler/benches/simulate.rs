//! The simulator (`semo simulate`): the scouting scenario (about 9 s of
//! mission time until every robot finished, 3 robots; goal under 20 ms of
//! wall time) and the generated benchmark mission for 10 minutes of
//! mission time with 102 robots (goal under 1 s) and 1,002 robots (goal
//! under 10 s), each with the cost per simulated event. The swarms run as
//! `semo simulate` runs them: the trace streamed into the summary's digest
//! (`sim::simulate_into`), not kept; the 1,002 robots once (a run takes
//! tens of seconds). Scouting and the 102 robots are measured also with
//! every control firing simulated (`Options::every_firing`), which skipping
//! idle firings replaces. Run with `cargo bench --bench simulate`.
//!
//! Measured (release, 10 minutes of mission time, a shared two-core
//! machine): 102 robots 4,156,664 events in about 0.9 s of CPU (1.0 s
//! before), 42 MB; 1,002 robots 40,723,064 events in 27.6 s (27.9 s
//! before), 331 MB. Per event the
//! instructions are the same for both (about 2,200, `valgrind --tool=
//! cachegrind`: 2,180 and 2,260 before a message's deliveries at one
//! instant shared a queue entry and firings read only their input slots,
//! 2,130 and 2,170 after); the misses of a 1 MB cache are not (1.4 against
//! 28.0 before, 23.4 after): the large swarm's robots and programs outgrow
//! the caches, which is the rest of its cost per event.
//!
//! Robots of one declaration sharing one control machine (`refine`'s
//! `share_control_machines`; the benchmark's teams of six then hold three
//! machines, not six) took the last-level misses of 1,002 robots x 20 s of
//! `semo simulate` (`valgrind --tool=cachegrind --LL=1048576,16,64`) from
//! 37.10M to 31.55M for the same 3.92G instructions; 10 minutes of mission
//! time: 311.7 MB -> 304.7 MB of peak memory (`/usr/bin/time`), the same
//! 40,723,064 events and summary; 102 robots x 10 minutes: 39 MB either way,
//! 997.2M -> 995.1M instructions for 1 minute (callgrind).
//!
//! Words and text shared (`Arc<str>`), trace fields inline, a send's
//! arrivals in a kept list, the scenario's read-only tables shared by
//! clones: allocations per event 5.42 -> 3.16 (`sim_scaling`); 102 robots x
//! 1 minute of `semo simulate` 1,106.1M -> 964.1M instructions, 1,002
//! robots x 10 s 2,426.1M -> 2,180.8M (callgrind, whole command, the same
//! output).
//!
//! A heartbeat's text made only when its words change and read once per
//! message, the recipients of an instant listed once, `wake_up` over the
//! sensor slots only: whole `semo simulate`, 10 minutes of mission time
//! (perf stat, instructions; the same trace and summaries), 102 robots
//! 7,722M -> 6,461M (about 1.2 s of CPU at 2 instructions per cycle and
//! 3 GHz), 1,002 robots 77,769M -> 65,412M (about 21-22 s of CPU either
//! way: at one instruction per cycle the large swarm waits on memory);
//! peak RSS 37 -> 40 MB and 290 -> 312 MB.
//!
//! Issue 36's target: a team of 200 robots in nested counted groups
//! (`common::mission::nested_groups`, also `benches/fixtures/
//! nested_groups.mission` for `semo simulate`, with its scenario there),
//! 10 minutes of mission time, 120,535,145 events, 99.9% of them heartbeats
//! heard. The runs here make no message's trace event, as `semo simulate`
//! without `--trace` on a scenario without expectations
//! (`Options::untraced_messages`), which on a plain network also folds
//! heartbeats (`sim/engine/folded.rs`): 0.93 s here (8 ns per event), the
//! 1,002 robots 29.4 s -> about 21 s; since counted groups walk their
//! members once per instant for the robots that see their team alike
//! (`sim/engine/counted.rs`) 0.33 s (3 ns per event), and the 1,002 robots
//! 11.1 s (2026-12-03, an idle machine); the numbers are in
//! `docs/scenario-and-trace.md`, "How long a simulation takes".
//!
//! A receive task freed from a full channel takes every message behind it
//! (it took one, and a swarm's backlog grew with the run): 1,002 robots x
//! 10 minutes 40,723,064 -> 42,991,620 events, 354 -> 64 MB of peak memory,
//! CPU time 1.03x (paired, a loaded machine: the runs deliver 5.6% more
//! events); 102 robots 52 -> 22 MB, 0.90x (2026-12-04).

mod common;
use common::fastest;

use semo::refine::RobotProgram;
use semo::sim::{self, scenario};
use std::path::Path;
use std::time::{Duration, Instant};

fn programs(files: semo::workspace::Files, id: semo::diag::FileId) -> Vec<RobotProgram> {
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

fn measure(name: &str, programs: &[RobotProgram], scenario_text: &str, until_ms: Option<i64>) {
    for every_firing in [false, true] {
        let name = if every_firing {
            format!("{name} (every firing, the reference)")
        } else {
            name.to_string()
        };
        measure_once(&name, programs, scenario_text, until_ms, every_firing);
    }
}

fn measure_once(
    name: &str,
    programs: &[RobotProgram],
    scenario_text: &str,
    until_ms: Option<i64>,
    every_firing: bool,
) {
    let scenario = scenario::parse(scenario_text, programs).expect("the scenario reads");
    let options = sim::Options {
        until_ms,
        seed: 1,
        every_firing,
        untraced_messages: scenario.expect.is_empty(),
    };
    let (run, lines) = streamed(programs, &scenario, &options);
    let best = fastest(Duration::from_secs(3), || {
        std::hint::black_box(streamed(programs, &scenario, &options));
    });
    report(name, programs, &run, lines, best);
}

/// A run as `semo simulate` makes it without `--svg` or `--mcap`: each
/// trace event into the digest of the summary and the expectations; the
/// run and how many trace lines it made.
fn streamed(
    programs: &[RobotProgram],
    scenario: &scenario::Scenario,
    options: &sim::Options,
) -> (sim::Run, usize) {
    let robots = sim::Run::robots_of(programs);
    let mut digest = sim::Digest::new(&robots, &scenario.expect);
    let mut lines = 0;
    let run = sim::simulate_into(programs, scenario, options, &mut |e| {
        digest.see(&e);
        lines += 1;
    });
    std::hint::black_box(sim::summary_of(&run, &digest, &digest.verdicts()));
    (run, lines)
}

/// One streamed run of a long mission on a scenario, timed once.
fn measure_long(name: &str, programs: &[RobotProgram], scenario: &str, until_ms: i64) {
    let scenario = scenario::parse(scenario, programs).expect("the scenario reads");
    let options = sim::Options {
        until_ms: Some(until_ms),
        seed: 1,
        every_firing: false,
        untraced_messages: scenario.expect.is_empty(),
    };
    let start = Instant::now();
    let (run, lines) = streamed(programs, &scenario, &options);
    report(name, programs, &run, lines, start.elapsed());
}

fn report(name: &str, programs: &[RobotProgram], run: &sim::Run, lines: usize, took: Duration) {
    println!(
        "simulate {name}: {} robots, {} ms of mission time, {} events, {lines} trace lines: {:.2} ms ({:.0} ns per event)",
        programs.len(),
        run.end_ms,
        run.events,
        took.as_secs_f64() * 1e3,
        took.as_secs_f64() * 1e9 / run.events.max(1) as f64
    );
}

/// The generated benchmark mission of `teams` teams of six robots, each
/// talking to its neighbouring teams.
fn swarm(teams: usize) -> Vec<RobotProgram> {
    let mut files = semo::workspace::Files::default();
    let id = files.add(
        "swarm.mission".into(),
        semo::workspace::FileKind::Mission,
        common::mission::generate(teams),
    );
    programs(files, id)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let (run, id) = semo::host::load_build(&root.join("examples/scouting/scouting.mission"), &[])
        .expect("the example loads");
    let scouting = programs(run.files, id);
    let scenario =
        std::fs::read_to_string(root.join("tests/fixtures/build/scouting.scenario.json"))
            .expect("the scenario fixture");
    measure("scouting", &scouting, &scenario, None);

    let ten_minutes = 10 * 60 * 1000;
    measure("swarm", &swarm(17), "{}", Some(ten_minutes));
    measure_long("swarm of 1,002", &swarm(167), "{}", ten_minutes);

    // Issue 36's target: a team of 200 robots in nested counted groups.
    let mut files = semo::workspace::Files::default();
    let id = files.add(
        "nested_groups.mission".into(),
        semo::workspace::FileKind::Mission,
        common::mission::nested_groups(200),
    );
    let nested = programs(files, id);
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/fixtures");
    let scenario = std::fs::read_to_string(fixtures.join("nested_groups.scenario.json"))
        .expect("the benchmark scenario");
    measure_long("nested groups of 200", &nested, &scenario, ten_minutes);
}
