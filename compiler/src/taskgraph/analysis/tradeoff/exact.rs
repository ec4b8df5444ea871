//! The exact storage/throughput front: every Pareto point, by exploring
//! distributions in order of total size, each grown only along its storage
//! dependencies (Stuijk et al., DAC 2006).
//!
//! Why it is exact: let D′ be a Pareto point (no smaller distribution
//! reaches its period) and E ≤ D′ (channel by channel) an explored
//! distribution whose period is larger than D′'s, or which deadlocks. The
//! cycle that bounds E's period (or blocks it) keeps its samples unless one
//! of its space edges grows, so D′ has more capacity than E on some channel
//! of that cycle, and E grown by that channel's step is still ≤ D′. From
//! SDF3's per-channel lower bounds (≤ every live distribution) a chain of
//! such steps, each explored, reaches D′; exploring by increasing size meets
//! it before anything larger. A distribution off the steps' lattice is no
//! better than the lattice point below it (the steps are `gcd(p, c)`), so
//! the lattice holds every Pareto point.
//!
//! The exploration ends when every distribution of the size that first
//! reaches the goal period has been evaluated, or when its work budget runs
//! out: then there is no exact answer and the caller falls back to the
//! greedy search, whose points are only distributions found.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{Outcome, Point, Search};
use crate::fasthash::FastSet;
use crate::taskgraph::analysis::ratio::Ratio;

/// The Pareto points up to `goal` (by increasing size, strictly decreasing
/// period, the last reaching `goal`), or `None` when `budget` ran out first.
/// Each evaluation costs the search's work per evaluation, each distribution
/// queued its number of channels, so memory is bounded by the budget too.
pub(super) fn front(
    search: &mut Search<'_, '_>,
    minimal: &[u64],
    steps: &[u64],
    goal: Ratio,
    budget: u64,
) -> Option<Vec<Point>> {
    let channels = minimal.len() as u64;
    let mut queue: BinaryHeap<Reverse<(u64, Vec<u64>)>> = BinaryHeap::new();
    let mut seen: FastSet<Vec<u64>> = FastSet::default();
    let mut points: Vec<Point> = Vec::new();
    // The size at which the goal was first reached: the distributions of
    // that size are still evaluated (one of them may do better), no larger.
    let mut reached_at: Option<u64> = None;
    seen.insert(minimal.to_vec());
    queue.push(Reverse((minimal.iter().sum(), minimal.to_vec())));
    while let Some(Reverse((size, caps))) = queue.pop() {
        if reached_at.is_some_and(|s| size > s) {
            break;
        }
        if !search.within(budget) {
            return None;
        }
        let all: Vec<Option<u64>> = caps.iter().map(|&c| Some(c)).collect();
        let grow = match search.evaluate(&all)? {
            Outcome::Period(period, on_cycle) => {
                record(&mut points, size, period, &caps);
                if period <= goal {
                    reached_at.get_or_insert(size);
                    continue; // larger ones are dominated by this one
                }
                on_cycle
            }
            Outcome::Blocked(space) => space,
        };
        // No space edge found on the cycle (ties between cycles): every
        // channel, which is a superset of the dependencies.
        let grow: Vec<usize> = if grow.is_empty() {
            (0..caps.len()).collect()
        } else {
            grow
        };
        for i in grow {
            let mut next = caps.clone();
            next[i] = next[i].checked_add(steps[i])?;
            if seen.contains(&next) {
                continue;
            }
            search.work = search.work.saturating_add(channels);
            seen.insert(next.clone());
            queue.push(Reverse((size + steps[i], next)));
        }
    }
    reached_at.map(|_| points)
}

/// Adds a live distribution to the front explored so far (sizes come in
/// increasing order): a new point when its period beats every smaller one,
/// or the better of two points of one size.
fn record(points: &mut Vec<Point>, size: u64, period: Ratio, caps: &[u64]) {
    let point = || Point {
        size,
        period,
        capacities: caps.to_vec(),
    };
    match points.last_mut() {
        Some(last) if last.size == size => {
            if period < last.period {
                *last = point();
            }
        }
        Some(last) if period >= last.period => {}
        _ => points.push(point()),
    }
}
