//! Shared by the benches.

#[allow(dead_code)] // not every bench generates a mission
pub mod mission;

mod allocator;

use std::time::{Duration, Instant};

/// Runs `f` at least three times and for about `budget`; gives the fastest run.
pub fn fastest(budget: Duration, mut f: impl FnMut()) -> Duration {
    let start = Instant::now();
    let mut best = Duration::MAX;
    let mut runs = 0;
    while runs < 3 || start.elapsed() < budget {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed());
        runs += 1;
    }
    best
}
