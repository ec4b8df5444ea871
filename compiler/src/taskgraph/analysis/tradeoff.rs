//! The storage/throughput trade-off of a level: how small the channels'
//! buffers can be for each iteration period, as SDF3's buffer sizing
//! (Stuijk et al., DAC 2006) defines it.
//!
//! Model: a channel of capacity α holding `d` initial samples gets a reverse
//! edge with α − d samples ("space"); a firing claims space for its output
//! samples when it starts and frees the space of its input samples when it
//! ends (SDF3's `startActorFiring`/`endActorFiring`). The period of a
//! distribution of capacities is then the period of the level with those
//! reverse edges ([`super::throughput`], the same concurrency), exactly.
//!
//! Search: from SDF3's per-channel lower bounds (`p + c − gcd(p, c) + d mod
//! gcd(p, c)`, at least `d`; `p + max(c, d)` on a self-loop), grow the
//! capacity of a channel whose space edge lies on the critical cycle (or on
//! the blocking cycle while the distribution deadlocks) by its step
//! `gcd(p, c)`, trying each such channel and keeping the one giving the
//! smallest period, until the period with unbounded buffers is reached. Every
//! point found is a distribution that reaches its period (so its size is an
//! upper bound on the smallest one that does). Lower bound on the smallest
//! total reaching the maximal throughput: the sum, over channels, of the
//! smallest capacity of that channel alone (all others unbounded) that keeps
//! the maximal throughput, found by bisection on the channel's steps while
//! the budget lasts, else SDF3's per-channel lower bounds. When both bounds
//! meet, the minimum is exact; and where those per-channel minima together
//! reach the maximal throughput (one more evaluation), they are the smallest
//! distribution that does, whatever the search found (mp3playback: 2910,
//! where growing and shrinking found 2916). Where growing from below does not reach the maximal throughput
//! within the budget (large levels), the channels are doubled from above
//! until it is reached, the last doubling is taken back along the way
//! between the two distributions as far as one bisected fraction of every
//! channel's growth allows, and each channel is then shrunk alone while the
//! budget lasts: on 5,000 and 20,000 actors the bounds stay about 2.5 times
//! apart (the lower one is SDF3's per-channel bounds, which ignore that
//! channels share cycles; closing the gap needs a search over thousands of
//! channels at once, which no budget of a second allows).
//!
//! Cost: each step evaluates one period per candidate channel (at most
//! [`MAX_CANDIDATES`] tried one by one; beyond, all are grown together).
//! Every evaluation is counted in work units (the size of the HSDF it
//! expands) and none starts that would take the work past [`MAX_WORK`]:
//! the budget is checked before each one, inside every loop, so a level
//! with large rates (where one evaluation is large) stops after a few with
//! what it has found, stating the bounds and that the budget stopped it.
//!
//! A level whose throughput only the buffers bound (period 0: an acyclic
//! level under auto-concurrency) has no finite distribution reaching its
//! maximal throughput: the search answers that at once, and grows only
//! towards a period the caller asks for ([`trade_off_towards`]).

use super::consistency::repetition_vector;
use super::level::{Edge, Level};
use super::ratio::{Ratio, gcd};
use super::throughput::{Concurrency, throughput};
use crate::fasthash::FastSet;

mod exact;

/// Candidate channels tried one at a time per step; more are grown together.
const MAX_CANDIDATES: usize = 8;
/// The work the search may do, counted as Σ over evaluated distributions of
/// the level's firings plus edges (an evaluation is linear in the HSDF per
/// policy iteration); half of it for the trade-off, the rest for the lower
/// bound. Beyond it, the search stops with what it has and says so.
pub const MAX_WORK: u64 = 6_000_000;
/// The work the exact exploration may do before the greedy search takes
/// over with its own [`MAX_WORK`].
pub const EXACT_WORK: u64 = MAX_WORK;
/// The exact exploration's budget on a level of at most
/// [`FEW_CHANNELS`] channels whose evaluations are cheap enough that it
/// holds [`MANY_EVALUATIONS`]: the distributions of each size are few there,
/// so a longer exploration is likely to finish (SDF3's `h263decoder`: 1,478
/// evaluations, 12.3M units), where on a level of thousands of channels, or
/// of evaluations so large that few fit, no budget of a second would.
pub const SMALL_EXACT_WORK: u64 = MAX_WORK * 5 / 2;
const FEW_CHANNELS: usize = 16;
const MANY_EVALUATIONS: u64 = 1_000;
/// The exact exploration is not tried when its budget holds fewer
/// evaluations than this: it could not finish.
const MIN_EXACT_EVALUATIONS: u64 = 32;

/// One distribution of buffer capacities and the period it reaches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Point {
    /// Σ capacities.
    pub size: u64,
    pub period: Ratio,
    /// Per edge of the level, its capacity in samples.
    pub capacities: Vec<u64>,
}

/// The trade-off found for one level.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TradeOff {
    /// The period with unbounded buffers (the maximal throughput).
    pub max_period: Ratio,
    /// Distributions found, by increasing size and strictly decreasing
    /// period; the last reaches `max_period` when `complete`.
    pub points: Vec<Point>,
    /// No distribution smaller than this reaches `max_period`.
    pub lower_bound: u64,
    /// Whether the search reached `max_period` within its budget.
    pub complete: bool,
    /// Periods evaluated.
    pub evaluations: usize,
    /// Work units of the evaluations after the maximal throughput's own
    /// (see [`MAX_WORK`]): with it, at most `work_limit`.
    pub work: u64,
    /// The budget of the search that gave `points`: [`MAX_WORK`], or the
    /// exact exploration's ([`EXACT_WORK`], [`SMALL_EXACT_WORK`]).
    pub work_limit: u64,
    /// Work units of one evaluation of a distribution.
    pub evaluation_cost: u64,
    /// Whether the work budget stopped some part of the search.
    pub budget_exhausted: bool,
    /// Whether `points` is the exact front: every Pareto point up to the
    /// period searched for, each proven (the exploration of
    /// [`exact::front`] finished); otherwise each point is a distribution
    /// found, an upper bound on the smallest size for its period.
    pub exact_front: bool,
}

impl TradeOff {
    /// Whether nothing but the buffers bounds the throughput (period 0,
    /// which no finite distribution reaches: the level's cycles through
    /// its buffers take time).
    pub fn unbounded_throughput(&self) -> bool {
        self.max_period.num == 0 && self.for_max_throughput().is_none() && !self.budget_exhausted
    }

    /// The smallest distribution found that reaches the maximal throughput.
    pub fn for_max_throughput(&self) -> Option<&Point> {
        self.points
            .last()
            .filter(|p| self.complete && p.period == self.max_period)
    }

    /// Whether the smallest total size for the maximal throughput is known
    /// exactly (found, and equal to the lower bound).
    pub fn exact(&self) -> bool {
        self.for_max_throughput()
            .is_some_and(|p| p.size == self.lower_bound)
    }

    /// The smallest distribution found whose period is at most `period`.
    pub fn for_period(&self, period: Ratio) -> Option<&Point> {
        self.points.iter().find(|p| p.period <= period)
    }
}

/// SDF3's lower bound on a channel's capacity for a positive throughput.
pub fn minimal_capacity(e: &Edge) -> u64 {
    let (p, c, d) = (e.produce, e.consume, e.initial_tokens);
    if e.src == e.dst {
        return p + c.max(d);
    }
    let g = gcd(p, c).max(1);
    (p + c - g + d % g).max(d)
}

/// The step by which a channel's capacity grows: `gcd(p, c)`, since its
/// samples are claimed and freed in multiples of it, so that a capacity
/// between `d + k·gcd` and the next is no better than `d + k·gcd`. SDF3's
/// lower bound is such a capacity on every channel of a consistent, live
/// level (a self-loop there has `p = c ≤ d`); should it not be, the step is
/// 1, which is always safe, only slower.
fn step(e: &Edge, minimal: u64) -> u64 {
    let g = gcd(e.produce, e.consume).max(1);
    if (minimal - e.initial_tokens) % g == 0 {
        g
    } else {
        1
    }
}

/// The level with a space edge for each capacity: its edges, then per edge
/// `i` an edge from its destination to its source carrying `caps[i] − d`.
fn bounded<'g>(level: &Level<'g>, caps: &[Option<u64>]) -> Level<'g> {
    let mut out = level.clone();
    for (e, cap) in level.edges.iter().zip(caps) {
        if let Some(cap) = cap {
            out.edges.push(Edge {
                src: e.dst,
                dst: e.src,
                produce: e.consume,
                consume: e.produce,
                initial_tokens: cap.saturating_sub(e.initial_tokens),
                channel: e.channel,
                span: e.span,
                label: e.label.clone(),
            });
        }
    }
    out
}

/// What a distribution gives: its period, or the space edges (as level
/// edge indices) of a cycle that blocks it.
enum Outcome {
    Period(Ratio, Vec<usize>),
    Blocked(Vec<usize>),
}

struct Search<'l, 'g> {
    level: &'l Level<'g>,
    counts: Vec<u64>,
    concurrency: Concurrency,
    evaluations: usize,
    work: u64,
    /// [`evaluation_cost`] of the level, which the search does not change.
    cost: u64,
    /// Whether [`Search::within`] said no once.
    exhausted: bool,
    /// Whether a critical cycle's space edges are those joining two
    /// consecutive firings of the cycle (the exact exploration: the fewer,
    /// the fewer distributions it grows), or those joining two consecutive
    /// nodes of the level's cycle, a node's self-loop whenever the node is
    /// on it (the greedy search, whose points depend on the ties it breaks).
    precise: bool,
}

/// The work of one evaluation: the size of the HSDF with space edges (as
/// `throughput` expands it).
fn evaluation_cost(level: &Level<'_>, g: &[u64]) -> u64 {
    let mut size: u64 = g.iter().sum();
    for e in &level.edges {
        let data = g[e.dst].saturating_mul((e.consume.div_ceil(e.produce) + 1).min(g[e.src]));
        let space = g[e.src].saturating_mul((e.produce.div_ceil(e.consume) + 1).min(g[e.dst]));
        size = size.saturating_add(data).saturating_add(space);
    }
    size
}

impl Search<'_, '_> {
    /// Whether one more evaluation fits `budget` (remembered when not).
    fn within(&mut self, budget: u64) -> bool {
        let fits = self.work.saturating_add(self.cost) <= budget;
        self.exhausted |= !fits;
        fits
    }

    /// The period of the distribution `caps` (every channel bounded), if
    /// it is live.
    fn period_of(&mut self, caps: &[u64]) -> Option<Ratio> {
        let all: Vec<Option<u64>> = caps.iter().map(|&c| Some(c)).collect();
        match self.evaluate(&all)? {
            Outcome::Period(period, _) => Some(period),
            Outcome::Blocked(_) => None,
        }
    }

    fn evaluate(&mut self, caps: &[Option<u64>]) -> Option<Outcome> {
        self.evaluations += 1;
        self.work = self.work.saturating_add(self.cost);
        let n = self.level.edges.len();
        let with_space = bounded(self.level, caps);
        // Space edge k of `with_space` (k ≥ n) belongs to the k-th bounded edge.
        let owner: Vec<usize> = (0..n).filter(|&i| caps[i].is_some()).collect();
        if let Some(blocked) = super::deadlock::find_deadlock(&with_space, &self.counts) {
            let space: Vec<usize> = blocked
                .edges
                .iter()
                .filter(|&&k| k >= n)
                .map(|&k| owner[k - n])
                .collect();
            return Some(Outcome::Blocked(space));
        }
        let t = throughput(&with_space, &self.counts, self.concurrency).ok()?;
        // Space edges joining consecutive nodes of the critical cycle (a
        // self-loop's when the cycle is one node), or, `precise`, of its
        // firings (a self-loop's only between two firings of its node).
        // (As sets: on a large level the cycle can have thousands of nodes.)
        let cycle = if self.precise {
            &t.walk
        } else {
            &t.critical_cycle
        };
        let nodes: FastSet<usize> = cycle.iter().copied().collect();
        let steps: FastSet<(usize, usize)> = (0..cycle.len())
            .map(|i| (cycle[i], cycle[(i + 1) % cycle.len()]))
            .collect();
        let mut on_cycle = Vec::new();
        for (k, e) in with_space.edges.iter().enumerate().skip(n) {
            let joins = if e.src == e.dst && !self.precise {
                nodes.contains(&e.src)
            } else {
                steps.contains(&(e.src, e.dst))
            };
            if joins {
                on_cycle.push(owner[k - n]);
            }
        }
        Some(Outcome::Period(t.period, on_cycle))
    }
}

/// The storage/throughput trade-off of a consistent, deadlock-free level
/// under `concurrency`; `None` when the level is inconsistent or its period
/// cannot be computed (see [`throughput`]).
pub fn trade_off(level: &Level<'_>, concurrency: Concurrency) -> Option<TradeOff> {
    trade_off_towards(level, concurrency, None)
}

/// [`trade_off`], which on a level whose throughput is unbounded (period 0)
/// searches for a distribution reaching `goal` (a period) instead of the
/// maximal throughput, which no finite one reaches; without a goal it
/// returns at once, with no point. On other levels `goal` changes nothing.
pub fn trade_off_towards(
    level: &Level<'_>,
    concurrency: Concurrency,
    goal: Option<Ratio>,
) -> Option<TradeOff> {
    let counts = repetition_vector(level).ok()?;
    let max_period = throughput(level, &counts, concurrency).ok()?.period;
    let cost = evaluation_cost(level, &counts);
    let mut search = Search {
        level,
        counts,
        concurrency,
        evaluations: 1,
        work: cost,
        cost,
        exhausted: false,
        precise: false,
    };
    let minimal: Vec<u64> = level.edges.iter().map(minimal_capacity).collect();
    // Nothing found: SDF3's per-channel bounds hold for any positive
    // throughput.
    let nothing = |search: &Search<'_, '_>| TradeOff {
        max_period,
        points: Vec::new(),
        lower_bound: minimal.iter().sum(),
        complete: false,
        evaluations: search.evaluations,
        work: search.work - search.cost,
        work_limit: MAX_WORK,
        evaluation_cost: search.cost,
        budget_exhausted: search.exhausted,
        exact_front: false,
    };
    // The period the search grows towards: on a level whose throughput
    // only the buffers bound, the goal, if any.
    let target = match goal {
        Some(goal) if max_period.num == 0 && goal.num > 0 => goal,
        _ => max_period,
    };
    // Large rates make one evaluation large: past the budget, none is made.
    if !search.within(MAX_WORK) {
        return Some(nothing(&search));
    }
    let steps: Vec<u64> = level
        .edges
        .iter()
        .zip(&minimal)
        .map(|(e, &m)| step(e, m))
        .collect();
    // Exact where the exploration fits its budget: every Pareto point.
    let small = level.edges.len() <= FEW_CHANNELS
        && search.cost.saturating_mul(MANY_EVALUATIONS) <= SMALL_EXACT_WORK;
    let exact_work = if small { SMALL_EXACT_WORK } else { EXACT_WORK };
    if target.num > 0 && search.cost.saturating_mul(MIN_EXACT_EVALUATIONS) <= exact_work {
        let before = search.work;
        search.precise = true;
        let front = exact::front(&mut search, &minimal, &steps, target, before + exact_work);
        search.precise = false;
        if let Some(points) = front {
            let lower_bound = match points.last() {
                Some(last) if target == max_period => last.size,
                _ => minimal.iter().sum(),
            };
            return Some(TradeOff {
                max_period,
                points,
                lower_bound,
                complete: true,
                evaluations: search.evaluations,
                work: search.work - search.cost,
                work_limit: exact_work,
                evaluation_cost: search.cost,
                budget_exhausted: false,
                exact_front: true,
            });
        }
        // Too large to finish: the greedy search, on its own budget.
        search.work = before;
        search.exhausted = false;
    }
    let mut caps = minimal.clone();

    let mut points: Vec<Point> = Vec::new();
    let mut complete = false;
    let bounded_caps = |caps: &[u64]| caps.iter().map(|&c| Some(c)).collect::<Vec<_>>();
    let mut current = search.evaluate(&bounded_caps(&caps))?;
    // Steps in a row that did not lower the period: past a few per channel,
    // growing one channel at a time is stuck on ties, and the search from
    // above takes over.
    let mut stale = 0usize;
    // Steps in a row that left the distribution blocked.
    let mut blocked = 0usize;
    while search.within(MAX_WORK / 3) && stale <= caps.len() + 4 {
        let grow: Vec<usize> = match &current {
            Outcome::Period(period, on_cycle) => {
                let size = caps.iter().sum();
                blocked = 0;
                stale += 1;
                if points.last().is_none_or(|p| *period < p.period) {
                    stale = 0;
                    points.push(Point {
                        size,
                        period: *period,
                        capacities: caps.clone(),
                    });
                }
                if *period <= target {
                    complete = true;
                    break;
                }
                if target.num == 0 {
                    // A live distribution whose period is not 0 has a cycle
                    // of tasks that take time, which every larger one keeps:
                    // none reaches period 0 (only a level whose cycles take
                    // no time does, at its first live distribution).
                    return Some(nothing(&search));
                }
                on_cycle.clone()
            }
            Outcome::Blocked(space) if !space.is_empty() && blocked > 8 => {
                // Still not live after a few steps (a large graph far from
                // live): double the blocking cycle's channels (the lower
                // bound still says how far from the minimum it lands).
                let mut trial = caps.clone();
                for &i in space {
                    trial[i] = trial[i].saturating_mul(2).max(trial[i] + steps[i]);
                }
                current = search.evaluate(&bounded_caps(&trial))?;
                caps = trial;
                continue;
            }
            Outcome::Blocked(space) => {
                blocked += 1;
                space.clone()
            }
        };
        let grow = if grow.is_empty() {
            // No space edge found on the cycle (ties between cycles): grow
            // every channel, which only moves towards unbounded buffers.
            (0..caps.len()).collect()
        } else {
            grow
        };
        let mut best: Option<(Ratio, Vec<u64>, Outcome)> = None;
        if grow.len() <= MAX_CANDIDATES {
            for &i in &grow {
                if !search.within(MAX_WORK / 3) {
                    break;
                }
                let mut trial = caps.clone();
                trial[i] = trial[i].saturating_add(steps[i]);
                let Some(outcome) = search.evaluate(&bounded_caps(&trial)) else {
                    continue;
                };
                let rank = match &outcome {
                    Outcome::Period(p, _) => *p,
                    Outcome::Blocked(_) => Ratio {
                        num: u64::MAX,
                        den: 1,
                    },
                };
                if best.as_ref().is_none_or(|b| rank < b.0) {
                    best = Some((rank, trial, outcome));
                }
            }
        }
        let (trial, outcome) = match best {
            Some((_, trial, outcome)) => (trial, outcome),
            None if !search.within(MAX_WORK / 3) => break,
            None => {
                let mut trial = caps.clone();
                for &i in &grow {
                    trial[i] = trial[i].saturating_add(steps[i]);
                }
                let outcome = search.evaluate(&bounded_caps(&trial))?;
                (trial, outcome)
            }
        };
        caps = trial;
        current = outcome;
    }
    let reaching = if complete {
        Some(caps.clone())
    } else {
        grown(&mut search, &caps, &steps, target)
    };
    if let Some(reaching) = reaching {
        // Each channel alone brought down as far as the others allow.
        let caps = shrink(&mut search, reaching, &minimal, &steps, target);
        let size: u64 = caps.iter().sum();
        // The points grown from below that are no smaller are dominated.
        points.retain(|p| p.size < size && p.period > target);
        // Shrinking keeps the period at most the target: a goal above the
        // maximal throughput may be passed, so the period is evaluated.
        let period = if target == max_period || !search.within(MAX_WORK) {
            target // (an upper bound when the budget is spent)
        } else {
            search.period_of(&caps).unwrap_or(target)
        };
        points.push(Point {
            size,
            period,
            capacities: caps,
        });
        complete = true;
    }
    let reached = points
        .last()
        .filter(|p| complete && p.period == max_period)
        .map(|p| p.capacities.clone());
    // Towards a goal, SDF3's per-channel bounds (they hold for any
    // positive throughput): the search's bound is for the maximal one.
    let lower_bound = if target == max_period {
        // One evaluation is kept for the minima together: where they reach
        // the maximal throughput, no smaller distribution does.
        let budget = MAX_WORK.saturating_sub(search.cost);
        let minima = channel_minima(
            &mut search,
            max_period,
            reached.as_deref(),
            &minimal,
            &steps,
            budget,
        );
        let bound: u64 = minima.iter().sum();
        let above = reached.is_none_or(|caps| caps.iter().sum::<u64>() > bound);
        if above
            && search.within(MAX_WORK)
            && search.period_of(&minima).is_some_and(|p| p <= max_period)
        {
            points.retain(|p| p.size < bound);
            points.push(Point {
                size: bound,
                period: max_period,
                capacities: minima,
            });
            complete = true;
        }
        bound
    } else {
        minimal.iter().sum()
    };
    Some(TradeOff {
        max_period,
        points,
        lower_bound,
        complete,
        evaluations: search.evaluations,
        work: search.work - search.cost,
        work_limit: MAX_WORK,
        evaluation_cost: search.cost,
        budget_exhausted: search.exhausted,
        exact_front: false,
    })
}

/// A distribution reaching `max_period`, for levels where growing from below
/// did not get there within its budget: the channels on the critical (or
/// blocking) cycle are doubled until the period is reached (every channel,
/// on a level with more channels than evaluations left), then brought back
/// down part of the way ([`between`]). `None` if the budget runs out first.
fn grown(
    search: &mut Search<'_, '_>,
    from: &[u64],
    steps: &[u64],
    max_period: Ratio,
) -> Option<Vec<u64>> {
    let budget = 2 * MAX_WORK / 3;
    let all = |caps: &[u64]| caps.iter().map(|&c| Some(c)).collect::<Vec<_>>();
    let mut caps = from.to_vec();
    // The last distribution that did not reach `max_period`.
    let mut below = from.to_vec();
    let mut last = None;
    loop {
        if !search.within(budget) {
            return None;
        }
        let (period, grow) = match search.evaluate(&all(&caps))? {
            Outcome::Period(p, _) if p <= max_period => break,
            Outcome::Period(p, on_cycle) => (Some(p), on_cycle),
            Outcome::Blocked(on_cycle) => (None, on_cycle),
        };
        // Every channel when the cycle's did not help last time, or when
        // there are more channels than evaluations left (a large graph: a
        // cycle at a time could not get there; all doubled, the period is
        // reached in a few steps, and `shrink` and the lower bound say how
        // far above the minimum that is).
        let stuck = period.is_some() && period == last;
        last = period;
        let left = budget.saturating_sub(search.work) / search.cost.max(1);
        let large = caps.len() as u64 > 4 * left;
        let grow: Vec<usize> = if grow.is_empty() || stuck || large {
            (0..caps.len()).collect()
        } else {
            grow
        };
        below.clone_from(&caps);
        for i in grow {
            caps[i] = caps[i].checked_mul(2)?.max(caps[i] + steps[i]);
        }
    }
    Some(between(search, &below, caps, budget, max_period))
}

/// Steps of [`between`]: the distribution found is at most 1/2^6 of the last
/// growth above the smallest one on the way that reaches the period.
const BETWEEN_STEPS: u32 = 6;

/// `above` (reaching `max_period`) brought down towards `below` (which does
/// not reach it) along the way between them: every channel at the same
/// fraction of its growth, the fraction bisected while the budget lasts.
/// Capacity only ever helps, so the fractions that reach the period are
/// those above one threshold. Doubling every channel of a large level at
/// once overshoots by up to twice; this takes most of that back in a few
/// evaluations, before [`shrink`] tries channels one by one.
fn between(
    search: &mut Search<'_, '_>,
    below: &[u64],
    mut above: Vec<u64>,
    budget: u64,
    max_period: Ratio,
) -> Vec<u64> {
    let parts = 1u64 << BETWEEN_STEPS;
    let at = |fraction: u64| -> Vec<Option<u64>> {
        below
            .iter()
            .zip(&above)
            .map(|(&low, &high)| {
                let growth = u128::from(high.saturating_sub(low)) * u128::from(fraction);
                let part = u64::try_from(growth.div_ceil(u128::from(parts))).unwrap_or(u64::MAX);
                Some(low.saturating_add(part).min(high))
            })
            .collect()
    };
    // `low` does not reach the period, `high` does (fractions of `parts`).
    let (mut low, mut high) = (0, parts);
    let mut reaching = None;
    while high - low > 1 && search.within(budget) {
        let middle = low + (high - low) / 2;
        let trial = at(middle);
        match search.evaluate(&trial) {
            Some(Outcome::Period(p, _)) if p <= max_period => {
                high = middle;
                reaching = Some(trial);
            }
            _ => low = middle,
        }
    }
    if let Some(trial) = reaching {
        above = trial.into_iter().map(|c| c.unwrap_or(0)).collect();
    }
    above
}

/// The capacity `from` brought down to the lattice of its channel's steps
/// (`minimal + k·step`): a capacity between two lattice points is no better
/// than the one below it (space is freed and claimed in multiples of the
/// step), so it reaches exactly what that one reaches.
fn on_lattice(from: u64, minimal: u64, step: u64) -> u64 {
    minimal + from.saturating_sub(minimal) / step * step
}

/// Bisection on one channel's lattice between `low` (which does not reach,
/// on the lattice) and `high` (which does, on the lattice) while one more
/// evaluation fits `budget`: the pair narrowed, `high − low == step` when
/// it finished.
fn bisect(
    search: &mut Search<'_, '_>,
    (mut low, mut high): (u64, u64),
    step: u64,
    budget: u64,
    mut reaches: impl FnMut(&mut Search<'_, '_>, u64) -> bool,
) -> (u64, u64) {
    while high - low > step && search.within(budget) {
        let middle = low + (high - low) / step / 2 * step;
        if reaches(search, middle) {
            high = middle;
        } else {
            low = middle;
        }
    }
    (low, high)
}

/// `caps` (reaching `max_period`) with each channel in turn bisected down
/// to the smallest capacity (at least `minimal`) that keeps the period, the
/// others fixed, while the work budget lasts.
fn shrink(
    search: &mut Search<'_, '_>,
    mut caps: Vec<u64>,
    minimal: &[u64],
    steps: &[u64],
    max_period: Ratio,
) -> Vec<u64> {
    let budget = MAX_WORK * 2 / 3;
    let all = |caps: &[u64]| caps.iter().map(|&c| Some(c)).collect::<Vec<_>>();
    let reaches = |search: &mut Search<'_, '_>, caps: &[u64]| matches!(search.evaluate(&all(caps)), Some(Outcome::Period(p, _)) if p <= max_period);
    for i in 0..caps.len() {
        caps[i] = on_lattice(caps[i], minimal[i], steps[i]);
        let (low, high) = (minimal[i], caps[i]);
        if low >= high || !search.within(budget) {
            continue;
        }
        let mut trial = caps.clone();
        trial[i] = low;
        if reaches(search, &trial) {
            caps[i] = low;
            continue;
        }
        let (_, high) = bisect(search, (low, high), steps[i], budget, |search, cap| {
            trial[i] = cap;
            reaches(search, &trial)
        });
        caps[i] = high;
    }
    caps
}

/// Per channel, the smallest capacity of that channel alone (the others
/// unbounded) keeping `max_period`, each at least SDF3's lower bound
/// (`found`: the capacities of a distribution reaching it, if any): each a
/// sure lower bound on that channel's capacity in any distribution reaching
/// `max_period` (more room elsewhere never helps less than unbounded room),
/// so their sum bounds the total. A channel at its SDF3 lower bound in
/// `found` needs no search; the others are bisected on their lattice while
/// `budget` lasts, and keep the largest capacity known to fall short plus
/// one step (or SDF3's bound) beyond it.
fn channel_minima(
    search: &mut Search<'_, '_>,
    max_period: Ratio,
    found: Option<&[u64]>,
    minimal: &[u64],
    steps: &[u64],
    budget: u64,
) -> Vec<u64> {
    let level = search.level;
    let mut minima = Vec::with_capacity(minimal.len());
    for i in 0..level.edges.len() {
        let step = steps[i];
        let ceiling = found.map(|caps| on_lattice(caps[i], minimal[i], step));
        if ceiling == Some(minimal[i]) || !search.within(budget) {
            minima.push(minimal[i]);
            continue;
        }
        let reaches = |search: &mut Search<'_, '_>, cap: u64| {
            let mut caps = vec![None; level.edges.len()];
            caps[i] = Some(cap);
            matches!(search.evaluate(&caps), Some(Outcome::Period(p, _)) if p <= max_period)
        };
        let mut low = minimal[i];
        if reaches(search, low) {
            minima.push(low);
            continue;
        }
        let high = match ceiling {
            Some(high) => Some(high),
            None => {
                // Double until the channel alone no longer holds the period back.
                let mut high = low;
                let mut reached = None;
                while search.within(budget) {
                    let Some(next) = high.checked_mul(2) else {
                        break;
                    };
                    high = on_lattice(next, minimal[i], step);
                    if reaches(search, high) {
                        reached = Some(high);
                        break;
                    }
                    low = high;
                }
                reached
            }
        };
        let Some(high) = high else {
            minima.push(low + step);
            continue;
        };
        // `low` fails, `high` reaches (capacity only ever helps); cut
        // short, `low + step` is still a sure bound.
        let (low, _) = bisect(search, (low, high), step, budget, reaches);
        minima.push(low + step);
    }
    minima
}

#[cfg(test)]
mod tests;
