//! The checker is linear in robots: `semo check` of a mission with twice the
//! teams (and so twice the robots) needs at most about twice the memory.
//!
//! Measured with a counting allocator (the peak of live bytes), not a clock:
//! the figure is the same on an idle and on a loaded machine. The check is
//! what `semo check FILE` runs (`host::load_check`): the diagnostics and
//! the dataflow warnings, which refine one robot of each declaration. When
//! each refined robot carried its own copy of the fleet's robot list, the
//! peak grew with the square of the robots (8.2 GB for a 3 MB mission).

#[path = "../benches/common/mission.rs"]
mod mission;

#[path = "support/counting.rs"]
mod counting;

/// `semo check FILE` of a generated mission of `teams` teams (six robots
/// each), and the peak of live bytes above the start while it ran. Every
/// test of this file checks through here, one at a time: the counters are
/// the process's, and a check running beside a measurement would count in it.
fn check_generated(teams: usize) -> (semo::host::CheckRun, usize) {
    let text = mission::generate(teams);
    let _one = counting::MEASURING
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let folder = tempfile::tempdir().expect("a temporary folder");
    let path = folder.path().join("swarm.mission");
    let (run, peak, _) = counting::measure(|| {
        std::fs::write(&path, text).expect("write the mission");
        semo::host::load_check(std::slice::from_ref(&path)).expect("the mission loads")
    });
    (run, peak)
}

/// The peak of live bytes while checking a generated mission of `teams`
/// teams, which must be valid.
fn peak_bytes_of_check(teams: usize) -> usize {
    let (run, peak) = check_generated(teams);
    assert_eq!(run.error_count(), 0, "the generated mission is valid");
    peak
}

/// The editor's and the checker's benches time an edit's check of this
/// mission: with warnings, they would time publishing them too (154 W020
/// on 10k lines once made an edit's diagnostics twice as slow to arrive).
#[test]
fn the_generated_benchmark_mission_checks_without_a_warning() {
    let (run, _) = check_generated(3);
    let said: Vec<String> = (run.diagnostics.iter())
        .filter(|d| d.severity <= semo::diag::Severity::Warning)
        .map(|d| format!("{:?} {}", d.code, d.message))
        .collect();
    assert!(said.is_empty(), "{said:#?}");
}

#[test]
fn checking_twice_the_robots_takes_at_most_about_twice_the_memory() {
    let (small, large) = (60, 120);
    // Once first, so that what is built once per process (the built-in
    // catalog, thread pools) is not counted against the small mission.
    peak_bytes_of_check(2);
    let one = peak_bytes_of_check(small);
    let two = peak_bytes_of_check(large);
    let ratio = two as f64 / one as f64;
    eprintln!("peak: {one} bytes for {small} teams, {two} for {large}: x{ratio:.2}");
    assert!(
        ratio < 2.4,
        "twice the robots took x{ratio:.2} the memory ({one} -> {two} bytes): the check is not linear in robots"
    );
}
