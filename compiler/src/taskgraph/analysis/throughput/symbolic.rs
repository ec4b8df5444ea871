//! The period without expanding to the HSDF: one iteration executed
//! symbolically in max-plus algebra (Geilen 2009, "Reduction techniques for
//! synchronous dataflow graphs"; SDF3's own state-space method computes the
//! same number).
//!
//! Every initial sample (one per sample on a channel, and one per node
//! `chained` for its previous firing) gets a coordinate. A sample made during
//! the iteration carries a vector: for each initial sample, the longest time
//! from that sample to it (−∞: it does not depend on it). A firing starts at
//! the max of its input samples' vectors and ends `wcet` later. After one
//! iteration every channel holds as many samples as it started with, in the
//! same order: their vectors are the rows of the iteration's max-plus matrix
//! G, and the period of the self-timed execution is G's largest cycle mean,
//! found by the same policy iteration as the HSDF's ([`max_cycle_ratio`]) on
//! G's graph (token j → token i weighing G[i][j]).
//!
//! The cost is D·(Σγ + the samples' runs moved), D the number of initial
//! samples, against the HSDF's Σγ nodes and their edges: far less on a level
//! with few initial samples and large repetition counts (`mp3playback`:
//! D = 6, Σγ = 10 601). Samples made by one firing share its vector, so a
//! channel holds runs (origin, count), not samples.
//!
//! The critical cycle is traced back through the firings: each vector entry
//! remembers which input gave its max.

use super::{Hsdf, Rates, Sdf, max_cycle_ratio};
use crate::taskgraph::analysis::ratio::Ratio;
use std::collections::VecDeque;

const NEG_INF: i64 = i64::MIN;

/// Initial samples beyond which the vectors cost more than they save.
const MAX_SAMPLES: u64 = 4096;

/// The level's channels and, for each chained node, a self-loop of one
/// sample.
fn channels(sdf: &Sdf, chained: &[bool]) -> Vec<Rates> {
    let loops = (0..sdf.nodes).filter(|&v| chained[v]).map(|v| Rates {
        src: v,
        dst: v,
        produce: 1,
        consume: 1,
        initial_tokens: 1,
    });
    sdf.edges.iter().copied().chain(loops).collect()
}

/// D·(Σγ + Σ over channels of γ(src) + γ(dst)): the work of [`period`], to
/// compare with the HSDF's size. `None` when it does not apply (too many
/// initial samples, vectors beyond the HSDF's memory budget, overflow).
pub(super) fn cost(sdf: &Sdf, counts: &[u64], chained: &[bool]) -> Option<u64> {
    let channels = channels(sdf, chained);
    let samples = channels
        .iter()
        .try_fold(0u64, |sum, c| sum.checked_add(c.initial_tokens))?;
    if samples > MAX_SAMPLES {
        return None;
    }
    let firings = counts.iter().try_fold(0u64, |s, &c| s.checked_add(c))?;
    // One vector of D entries per firing is kept (for the critical cycle):
    // within the HSDF's memory budget.
    if firings.checked_mul(samples)? > super::MAX_HSDF {
        return None;
    }
    let mut moves = firings;
    for c in &channels {
        moves = moves.checked_add(counts[c.src].checked_add(counts[c.dst])?)?;
    }
    samples.max(1).checked_mul(moves)
}

/// The origin of a run of samples: initial sample `o` when `o < D`, else
/// firing `o - D` of the iteration.
type Origin = usize;

/// The period and the level nodes of a critical cycle's firings (in flow
/// order, before [`super::level_cycle`] merges them); `None` on overflow or when the iteration cannot
/// complete (the caller then uses the HSDF).
pub(super) fn period(
    sdf: &Sdf,
    counts: &[u64],
    wcet: &[u64],
    chained: &[bool],
) -> Option<(Ratio, Vec<usize>)> {
    // Within the bounds (samples, memory) whatever the caller checked.
    cost(sdf, counts, chained)?;
    let n = sdf.nodes;
    let channels = channels(sdf, chained);
    let mut base = Vec::with_capacity(channels.len());
    let mut d = 0usize;
    for c in &channels {
        base.push(d);
        d = d.checked_add(usize::try_from(c.initial_tokens).ok()?)?;
    }
    let mut inputs = vec![Vec::new(); n];
    let mut outputs = vec![Vec::new(); n];
    for (i, c) in channels.iter().enumerate() {
        inputs[c.dst].push(i);
        outputs[c.src].push(i);
    }
    let mut queues: Vec<VecDeque<(Origin, u64)>> = channels
        .iter()
        .zip(&base)
        .map(|(c, &b)| (b..b + c.initial_tokens as usize).map(|o| (o, 1)).collect())
        .collect();
    let mut available: Vec<u64> = channels.iter().map(|c| c.initial_tokens).collect();
    let mut remaining = counts.to_vec();
    let total = usize::try_from(counts.iter().try_fold(0u64, |s, &c| s.checked_add(c))?).ok()?;
    // Per firing: its actor and which origin gave each entry of its vector
    // (32 bits: memory touched for the first time is most of the time on a
    // graph like `mp3playback`), and the vectors still needed.
    u32::try_from(d.checked_add(total)?).ok()?;
    let mut actor: Vec<u32> = Vec::with_capacity(total);
    let mut from: Vec<u32> = Vec::with_capacity(total.checked_mul(d)?);
    let mut ends = Ends::new(d, total);
    let mut end = vec![NEG_INF; d];
    let mut start = vec![NEG_INF; d];
    let mut start_from = vec![u32::MAX; d];
    let mut pending: Vec<usize> = (0..n).rev().collect();
    let mut queued = vec![true; n];
    while let Some(v) = pending.pop() {
        queued[v] = false;
        let mut fired = false;
        while remaining[v] > 0
            && inputs[v]
                .iter()
                .all(|&i| available[i] >= channels[i].consume)
        {
            start.fill(NEG_INF);
            start_from.fill(u32::MAX);
            for &i in &inputs[v] {
                let mut need = channels[i].consume;
                available[i] -= need;
                while need > 0 {
                    let (origin, count) = queues[i].front_mut()?;
                    let origin = *origin;
                    let taken = need.min(*count);
                    *count -= taken;
                    need -= taken;
                    let emptied = *count == 0;
                    merge(origin, d, &ends, &mut start, &mut start_from);
                    if emptied {
                        queues[i].pop_front();
                        if origin >= d {
                            ends.release(origin - d);
                        }
                    }
                }
            }
            let f = actor.len();
            actor.push(v as u32);
            let w = i64::try_from(wcet[v]).ok()?;
            for (e, s) in end.iter_mut().zip(&start) {
                *e = if *s == NEG_INF {
                    NEG_INF
                } else {
                    s.checked_add(w)?
                };
            }
            from.extend_from_slice(&start_from);
            ends.push(&end, outputs[v].len());
            for &i in &outputs[v] {
                queues[i].push_back((d + f, channels[i].produce));
                available[i] = available[i].checked_add(channels[i].produce)?;
            }
            remaining[v] -= 1;
            fired = true;
        }
        if fired {
            for &i in &outputs[v] {
                let u = channels[i].dst;
                if !queued[u] {
                    queued[u] = true;
                    pending.push(u);
                }
            }
        }
    }
    if remaining.iter().any(|&r| r > 0) {
        return None;
    }
    // The rows of G: the final samples, channel by channel in order.
    let mut rows: Vec<Origin> = Vec::with_capacity(d);
    for q in &queues {
        for &(origin, count) in q {
            for _ in 0..count {
                rows.push(origin);
            }
        }
    }
    if rows.len() != d {
        return None;
    }
    let entry = |origin: Origin, j: usize| -> i64 {
        if origin < d {
            if origin == j { 0 } else { NEG_INF }
        } else {
            ends.row(origin - d)[j]
        }
    };
    // G's graph: token nodes 0..d weigh nothing; an entry G[i][j] is a node
    // of its weight between j and i, the edge into i carrying one sample.
    let mut weight = vec![0u64; d];
    let mut edges = Vec::new();
    let mut entries = Vec::new();
    for (i, &origin) in rows.iter().enumerate() {
        for j in 0..d {
            let g = entry(origin, j);
            if g != NEG_INF {
                let mid = weight.len();
                weight.push(u64::try_from(g).ok()?);
                entries.push((i, j));
                edges.push((j, mid, 0));
                edges.push((mid, i, 1));
            }
        }
    }
    let Some(graph) = Hsdf::from_edges(weight, edges, Vec::new()).on_cycles() else {
        return Some((Ratio { num: 0, den: 1 }, Vec::new()));
    };
    let (ratio, cycle) = max_cycle_ratio(&graph)?;
    // Each entry node on the cycle: the firings from sample j to sample i.
    let mut walk = Vec::new();
    for v in cycle {
        let original = graph.actor(v);
        let Some(&(i, j)) = original.checked_sub(d).and_then(|m| entries.get(m)) else {
            continue;
        };
        let mut path = Vec::new();
        let mut origin = rows[i];
        while origin >= d {
            let f = origin - d;
            path.push(actor[f] as usize);
            origin = from[f * d + j] as usize;
        }
        path.reverse();
        walk.extend(path);
    }
    Some((ratio, walk))
}

/// `start = max(start, the vector of origin)`, remembering where each
/// entry's max came from.
fn merge(origin: Origin, d: usize, ends: &Ends, start: &mut [i64], start_from: &mut [u32]) {
    if origin < d {
        if start[origin] < 0 {
            start[origin] = 0;
            start_from[origin] = origin as u32;
        }
        return;
    }
    let row = ends.row(origin - d);
    for ((s, f), &e) in start.iter_mut().zip(start_from.iter_mut()).zip(row) {
        if e > *s {
            *s = e;
            *f = origin as u32;
        }
    }
}

/// The end vectors of the firings whose samples are still on a channel: a
/// firing's vector is dropped (its slot reused) once the last run of
/// samples it made is consumed, so the memory is that of the samples in
/// flight, not of every firing (`mp3playback`: 10,601 firings, a few
/// thousand runs in flight).
struct Ends {
    d: usize,
    /// `d` entries per slot.
    values: Vec<i64>,
    /// Per slot, the runs of samples still referring to it.
    refs: Vec<usize>,
    free: Vec<usize>,
    /// Per firing, its slot (`usize::MAX`: it made no samples).
    slot: Vec<usize>,
}

impl Ends {
    fn new(d: usize, firings: usize) -> Ends {
        Ends {
            d,
            values: Vec::new(),
            refs: Vec::new(),
            free: Vec::new(),
            slot: Vec::with_capacity(firings),
        }
    }

    /// The vector of the next firing, which made `runs` runs of samples.
    fn push(&mut self, vector: &[i64], runs: usize) {
        if runs == 0 {
            self.slot.push(usize::MAX);
            return;
        }
        let slot = match self.free.pop() {
            Some(slot) => {
                self.values[slot * self.d..(slot + 1) * self.d].copy_from_slice(vector);
                self.refs[slot] = runs;
                slot
            }
            None => {
                self.values.extend_from_slice(vector);
                self.refs.push(runs);
                self.refs.len() - 1
            }
        };
        self.slot.push(slot);
    }

    /// The vector of firing `f`, which still has samples on a channel.
    fn row(&self, f: usize) -> &[i64] {
        let slot = self.slot[f];
        &self.values[slot * self.d..(slot + 1) * self.d]
    }

    /// One run of firing `f`'s samples is consumed.
    fn release(&mut self, f: usize) {
        let slot = self.slot[f];
        self.refs[slot] -= 1;
        if self.refs[slot] == 0 {
            self.free.push(slot);
        }
    }
}
