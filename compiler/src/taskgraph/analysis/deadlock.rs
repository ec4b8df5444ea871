//! Deadlock: whether one iteration (every node firing its repetition count)
//! can complete from the initial samples, found by executing it symbolically.
//! When it cannot, the cycle that blocks is named, with how many initial
//! samples on one of its channels would suffice.

use super::level::Level;
use std::collections::VecDeque;

/// A cycle of nodes waiting for each other.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Blocked {
    /// Nodes around the cycle, in flow order.
    pub nodes: Vec<usize>,
    /// The edges of the cycle, in flow order.
    pub edges: Vec<usize>,
    /// An edge of the cycle and the initial samples to add there so that one
    /// iteration completes, if adding samples there is enough.
    pub fix: Option<(usize, u64)>,
}

/// Runs one iteration; on failure gives each node's remaining firings and each
/// edge's samples when it stopped.
fn execute(
    level: &Level<'_>,
    counts: &[u64],
    extra: Option<(usize, u64)>,
) -> Result<(), (Vec<u64>, Vec<u64>)> {
    let n = level.nodes.len();
    let mut tokens: Vec<u64> = level.edges.iter().map(|e| e.initial_tokens).collect();
    if let Some((e, add)) = extra {
        tokens[e] = tokens[e].saturating_add(add);
    }
    let (inputs, outputs) = level.adjacency();
    let (inputs, outputs) = (inputs.slices(), outputs.slices());
    let mut remaining = counts.to_vec();
    let mut queued = vec![true; n];
    let mut queue: VecDeque<usize> = (0..n).collect();
    while let Some(v) = queue.pop_front() {
        queued[v] = false;
        // Fire as many times as the inputs allow at once; a self-loop returns
        // what it takes (consistent rates), so it allows one firing at a time.
        let mut k = remaining[v];
        for &i in inputs[v] {
            let e = &level.edges[i];
            let allowed = if e.src == v {
                u64::from(tokens[i] >= e.consume)
            } else {
                tokens[i] / e.consume
            };
            k = k.min(allowed);
        }
        if k == 0 {
            continue;
        }
        for &i in inputs[v] {
            tokens[i] -= k * level.edges[i].consume;
        }
        for &i in outputs[v] {
            let e = &level.edges[i];
            tokens[i] = tokens[i].saturating_add(k.saturating_mul(e.produce));
            if !queued[e.dst] {
                queued[e.dst] = true;
                queue.push_back(e.dst);
            }
        }
        remaining[v] -= k;
        if remaining[v] > 0 && !queued[v] {
            queued[v] = true;
            queue.push_back(v);
        }
    }
    if remaining.iter().all(|&r| r == 0) {
        Ok(())
    } else {
        Err((remaining, tokens))
    }
}

/// `None` when one iteration completes; otherwise the blocking cycle.
pub fn find_deadlock(level: &Level<'_>, counts: &[u64]) -> Option<Blocked> {
    let (remaining, tokens) = execute(level, counts, None).err()?;
    // Each node's input edges, in edge order: a walk along a long chain of
    // waits reads each node's inputs, not every edge, per step.
    let (inputs, _) = level.adjacency();
    // Each blocked node waits on an input edge short of samples whose source
    // is blocked too; following these waits must come back round to a node.
    let waits_for = |v: usize| {
        inputs[v]
            .iter()
            .map(|&i| (i, &level.edges[i]))
            .find(|(i, e)| tokens[*i] < e.consume && remaining[e.src] > 0)
    };
    let start = (0..level.nodes.len()).find(|&v| remaining[v] > 0)?;
    let mut seen: Vec<Option<usize>> = vec![None; level.nodes.len()];
    let mut walk: Vec<(usize, usize)> = Vec::new(); // (node, edge it waits on)
    let mut v = start;
    let cycle_start = loop {
        if let Some(at) = seen[v] {
            break at;
        }
        let Some((edge, e)) = waits_for(v) else {
            // Blocked without a blocked predecessor: report the node alone.
            return Some(Blocked {
                nodes: vec![v],
                edges: Vec::new(),
                fix: None,
            });
        };
        seen[v] = Some(walk.len());
        walk.push((v, edge));
        v = e.src;
    };
    // The walk goes against the flow; reversed, each node follows the edge
    // that enters it.
    let mut cycle: Vec<(usize, usize)> = walk[cycle_start..].to_vec();
    cycle.reverse();
    // Start from the task written first, as a reader would tell the cycle.
    if let Some(first) = (0..cycle.len()).min_by_key(|&i| cycle[i].0) {
        cycle.rotate_left(first);
    }
    let nodes: Vec<usize> = cycle.iter().map(|&(node, _)| node).collect();
    let edges: Vec<usize> = cycle.iter().map(|&(_, edge)| edge).collect();
    // A channel going back against the order the tasks are written in is the
    // feedback channel, where initial samples belong.
    let back = edges
        .iter()
        .copied()
        .find(|&e| level.edges[e].src > level.edges[e].dst)
        .unwrap_or(edges[0]);
    Some(Blocked {
        nodes,
        edges,
        fix: samples_needed(level, counts, back).map(|n| (back, n)),
    })
}

/// The fewest extra initial samples on `edge` that let one iteration complete.
fn samples_needed(level: &Level<'_>, counts: &[u64], edge: usize) -> Option<u64> {
    let e = &level.edges[edge];
    let mut high = counts[e.dst].checked_mul(e.consume)?.max(1);
    execute(level, counts, Some((edge, high))).ok()?;
    let mut low = 0; // fails with `low`, succeeds with `high`
    while high - low > 1 {
        let middle = low + (high - low) / 2;
        if execute(level, counts, Some((edge, middle))).is_ok() {
            high = middle;
        } else {
            low = middle;
        }
    }
    Some(high)
}
