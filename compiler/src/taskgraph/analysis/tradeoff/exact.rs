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
//! "The cycle that bounds E's period" needs only be a superset of the space
//! edges of one critical cycle of E: the space edges joining two
//! consecutive firings on the cycle the throughput analysis finds (a
//! self-loop's only where two firings of its node follow each other on it),
//! not every self-loop of a node on it, which would grow self-loops that no
//! firing on the cycle waits for.
//!
//! Fewer evaluations: let X be E grown by one step on a channel whose space
//! edge is not on E's cycle. Capacity only ever helps, so X's period is at
//! most E's; E's cycle is still in X with the same samples, so it is at
//! least E's: X has E's period, and E's cycle is a critical cycle of X (if
//! E deadlocks, E's blocking cycle still cannot complete its firings in X:
//! a cycle blocked in a maximal execution is blocked on its own samples).
//! So X takes E's outcome without an evaluation, and the argument above
//! holds with it unchanged. X's parents (one step less on one channel) are
//! smaller than X, so popped before it; a digest that is a sum over the
//! channels finds each in constant time.
//!
//! The exploration ends when every distribution of the size that first
//! reaches the goal period has been evaluated, or when its work budget runs
//! out: then there is no exact answer and the caller falls back to the
//! greedy search, whose points are only distributions found.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{Outcome, Point, Search};
use crate::fasthash::FastMap;
use crate::taskgraph::analysis::ratio::Ratio;

/// The Pareto points up to `goal` (by increasing size, strictly decreasing
/// period, the last reaching `goal`), or `None` when `budget` ran out first.
/// Each evaluation costs the search's work per evaluation, each distribution
/// queued its number of channels (so memory is bounded by the budget too),
/// each parent looked up one unit and its number of channels when a digest
/// matches (the capacities compared).
pub(super) fn front(
    search: &mut Search<'_, '_>,
    minimal: &[u64],
    steps: &[u64],
    goal: Ratio,
    budget: u64,
) -> Option<Vec<Point>> {
    let channels = minimal.len() as u64;
    let mut queue: BinaryHeap<Reverse<(u64, Vec<u64>, u32)>> = BinaryHeap::new();
    let mut table = Table::default();
    let mut outcomes: Vec<Known> = Vec::new();
    let mut points: Vec<Point> = Vec::new();
    // The size at which the goal was first reached: the distributions of
    // that size are still evaluated (one of them may do better), no larger.
    let mut reached_at: Option<u64> = None;
    let first = table.insert(minimal.to_vec(), digest(minimal))?;
    queue.push(Reverse((minimal.iter().sum(), minimal.to_vec(), first)));
    while let Some(Reverse((size, caps, entry))) = queue.pop() {
        if reached_at.is_some_and(|s| size > s) {
            break;
        }
        if !search.within(budget) {
            return None;
        }
        let hash = table.entries[entry as usize].hash;
        // A parent (one step less on one channel; smaller, so popped
        // before) whose cycle keeps its samples here gives its outcome:
        // the channel grown is not on it.
        let mut inherited = None;
        for (j, (&cap, (&low, &step))) in caps.iter().zip(minimal.iter().zip(steps)).enumerate() {
            if cap < low.saturating_add(step) {
                continue;
            }
            search.work = search.work.saturating_add(1);
            let parent = hash
                .wrapping_sub(part(j, cap))
                .wrapping_add(part(j, cap - step));
            let found = table.find(parent, |other| {
                search.work = search.work.saturating_add(channels);
                other.iter().zip(&caps).enumerate().all(|(i, (&o, &c))| {
                    if i == j {
                        o.checked_add(step) == Some(c)
                    } else {
                        o == c
                    }
                })
            });
            let Some(o) = found.and_then(|e| table.entries[e as usize].outcome) else {
                continue;
            };
            let known = &outcomes[o as usize];
            if !known.cycle.is_empty() && !known.cycle.contains(&j) {
                inherited = Some(o);
                break;
            }
        }
        let index = match inherited {
            Some(o) => o,
            None => {
                if !search.within(budget) {
                    return None;
                }
                let all: Vec<Option<u64>> = caps.iter().map(|&c| Some(c)).collect();
                outcomes.push(match search.evaluate(&all)? {
                    Outcome::Period(period, on_cycle) => Known {
                        period: Some(period),
                        cycle: on_cycle,
                    },
                    Outcome::Blocked(space) => Known {
                        period: None,
                        cycle: space,
                    },
                });
                u32::try_from(outcomes.len() - 1).ok()?
            }
        };
        table.entries[entry as usize].outcome = Some(index);
        let known = &outcomes[index as usize];
        if let Some(period) = known.period {
            record(&mut points, size, period, &caps);
            if period <= goal {
                reached_at.get_or_insert(size);
                continue; // larger ones are dominated by this one
            }
        }
        // No space edge found on the cycle (ties between cycles): every
        // channel, which is a superset of the dependencies.
        let grow: Vec<usize> = if known.cycle.is_empty() {
            (0..caps.len()).collect()
        } else {
            known.cycle.clone()
        };
        for i in grow {
            let mut next = caps.clone();
            next[i] = next[i].checked_add(steps[i])?;
            let next_hash = hash
                .wrapping_sub(part(i, caps[i]))
                .wrapping_add(part(i, next[i]));
            if table
                .find(next_hash, |other| other == next.as_slice())
                .is_some()
            {
                continue;
            }
            search.work = search.work.saturating_add(channels);
            let at = table.insert(next.clone(), next_hash)?;
            queue.push(Reverse((size + steps[i], next, at)));
        }
    }
    reached_at.map(|_| points)
}

/// What the evaluation of a distribution gave: its period (`None`: it
/// deadlocks) and the channels whose space edges lie on the cycle that
/// bounds it (or blocks it).
struct Known {
    period: Option<Ratio>,
    cycle: Vec<usize>,
}

/// The distributions queued, found by a digest that is a sum over the
/// channels ([`part`]): a neighbour's, one step away on one channel, is one
/// subtraction and one addition away, where hashing it whole would read
/// every channel.
#[derive(Default)]
struct Table {
    /// Digest → the last entry with it (the others chained by `next`).
    heads: FastMap<u64, u32>,
    entries: Vec<Entry>,
}

struct Entry {
    caps: Vec<u64>,
    hash: u64,
    next: Option<u32>,
    /// Its outcome, once popped (an index into the outcomes).
    outcome: Option<u32>,
}

impl Table {
    fn insert(&mut self, caps: Vec<u64>, hash: u64) -> Option<u32> {
        let at = u32::try_from(self.entries.len()).ok()?;
        let next = self.heads.insert(hash, at);
        self.entries.push(Entry {
            caps,
            hash,
            next,
            outcome: None,
        });
        Some(at)
    }

    /// The entry with digest `hash` whose capacities `same` accepts.
    fn find(&self, hash: u64, mut same: impl FnMut(&[u64]) -> bool) -> Option<u32> {
        let mut at = self.heads.get(&hash).copied();
        while let Some(e) = at {
            let entry = &self.entries[e as usize];
            if entry.hash == hash && same(&entry.caps) {
                return Some(e);
            }
            at = entry.next;
        }
        None
    }
}

/// Channel `i` at capacity `c`'s share of a distribution's digest
/// (SplitMix64's finaliser of the pair).
fn part(i: usize, c: u64) -> u64 {
    let mut z = (i as u64)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(c.wrapping_mul(0xd1b5_4a32_d192_ed03));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The digest of a distribution: the sum of its channels' parts.
fn digest(caps: &[u64]) -> u64 {
    caps.iter()
        .enumerate()
        .fold(0u64, |h, (i, &c)| h.wrapping_add(part(i, c)))
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
