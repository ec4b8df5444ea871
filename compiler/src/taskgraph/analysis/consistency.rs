//! Consistency: the smallest positive integer repetition vector solving the
//! balance equations γ(src)·produce = γ(dst)·consume of every edge, per
//! connected component. Linear in the size of the level.

use super::level::{Level, Lists};
use super::ratio::{Ratio, gcd, lcm};

/// Why a level has no repetition vector.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RateProblem {
    /// The edge's rates ask `dst` to fire `required` times per firing of `src`,
    /// while the other paths between them ask for `established`.
    Inconsistent {
        edge: usize,
        established: Ratio,
        required: Ratio,
    },
    /// The repetition counts do not fit in 64 bits (found at this edge).
    Overflow { edge: Option<usize> },
    /// Inside a loop body, the boundary node would have to fire `count` times
    /// per iteration instead of once: inner rates do not fit the loop's ports.
    Boundary { node: usize, count: u64 },
}

/// The repetition vector of `level` (one count per node), or the first problem.
pub fn repetition_vector(level: &Level<'_>) -> Result<Vec<u64>, RateProblem> {
    let n = level.nodes.len();
    // Each node's edges, either way (a self-loop once).
    let adjacent = Lists::new(n, || {
        level.edges.iter().enumerate().flat_map(|(i, e)| {
            let other = (e.dst != e.src).then_some((e.dst, i));
            std::iter::once((e.src, i)).chain(other)
        })
    });
    let mut ratio: Vec<Option<Ratio>> = vec![None; n];
    let mut counts = vec![0u64; n];
    // Breadth-first in file order: a contradiction is found on the channel
    // written last among those that disagree.
    let mut queue = std::collections::VecDeque::new();
    let mut component = Vec::new();
    for root in 0..n {
        if ratio[root].is_some() {
            continue;
        }
        ratio[root] = Some(Ratio::ONE);
        queue.push_back(root);
        component.clear();
        while let Some(u) = queue.pop_front() {
            component.push(u);
            let ru = ratio[u].unwrap_or(Ratio::ONE);
            for &i in &adjacent[u] {
                let e = &level.edges[i];
                // γ(dst)/γ(src) = produce/consume.
                let (v, want) = if e.src == u {
                    (e.dst, ru.scale(e.produce, e.consume))
                } else {
                    (e.src, ru.scale(e.consume, e.produce))
                };
                let want = want.ok_or(RateProblem::Overflow { edge: Some(i) })?;
                match ratio[v] {
                    None => {
                        ratio[v] = Some(want);
                        queue.push_back(v);
                    }
                    Some(have) if have == want => {}
                    Some(_) => {
                        let (rs, rd) = (
                            ratio[e.src].unwrap_or(Ratio::ONE),
                            ratio[e.dst].unwrap_or(Ratio::ONE),
                        );
                        let established = rd
                            .divided_by(rs)
                            .ok_or(RateProblem::Overflow { edge: Some(i) })?;
                        let required = Ratio::new(e.produce, e.consume)
                            .ok_or(RateProblem::Overflow { edge: Some(i) })?;
                        return Err(RateProblem::Inconsistent {
                            edge: i,
                            established,
                            required,
                        });
                    }
                }
            }
        }
        integerize(&component, &ratio, &mut counts)?;
    }
    if let Some((inputs, outputs)) = level.boundary {
        for node in [inputs, outputs] {
            if counts[node] != 1 && !adjacent[node].is_empty() {
                return Err(RateProblem::Boundary {
                    node,
                    count: counts[node],
                });
            }
        }
    }
    Ok(counts)
}

/// Scales the component's ratios to the smallest positive integers.
fn integerize(
    component: &[usize],
    ratio: &[Option<Ratio>],
    counts: &mut [u64],
) -> Result<(), RateProblem> {
    let overflow = RateProblem::Overflow { edge: None };
    let mut common = 1u64;
    for &v in component {
        let r = ratio[v].unwrap_or(Ratio::ONE);
        common = lcm(common, r.den).ok_or(overflow.clone())?;
    }
    let mut divisor = 0u64;
    for &v in component {
        let r = ratio[v].unwrap_or(Ratio::ONE);
        let count = r.num.checked_mul(common / r.den).ok_or(overflow.clone())?;
        counts[v] = count;
        divisor = gcd(divisor, count);
    }
    for &v in component {
        counts[v] /= divisor.max(1);
    }
    Ok(())
}
