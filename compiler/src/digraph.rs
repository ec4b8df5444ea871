//! Strongly connected components of a graph over node indices `0..n`: the
//! one routine that the task-graph analyses and the layered drawing all use,
//! rather than each its own copy.
//!
//! Kosaraju's algorithm, walked with explicit stacks (its depth bounded by
//! nothing but memory: a recursive Tarjan overflowed the main thread's stack
//! on a chain of 139,000 tasks), on adjacency arrays built once from the
//! edges. It numbers the components exactly as petgraph's `kosaraju_scc` on a
//! `DiGraph` with the same edges added in the same order lists them (the
//! first pass visits a node's predecessors in the order petgraph's linked
//! lists give them, newest edge first), which this module ran before and the
//! outputs' order of components depends on; the test below checks the two
//! agree. Petgraph's graph of linked edge lists, its reversed view and its
//! two visit maps cost twice as many instructions on `random_1000`.

/// The strongly connected component of each node `0..n` of the graph with
/// `edges` (pairs of node indices, each below `n`), and how many there are.
/// Components are numbered in reverse topological order of the condensation:
/// an edge between two components goes from a higher number to a lower one.
pub fn components(
    n: usize,
    edges: impl IntoIterator<Item = (usize, usize)>,
) -> (Vec<usize>, usize) {
    let edges: Vec<(usize, usize)> = edges.into_iter().collect();
    // Predecessors, newest edge first (petgraph's incoming list), and
    // successors in any order.
    let mut pred_start = vec![0usize; n + 1];
    let mut succ_start = vec![0usize; n + 1];
    for &(a, b) in &edges {
        assert!(a < n && b < n, "edge ({a}, {b}) outside 0..{n}");
        pred_start[b + 1] += 1;
        succ_start[a + 1] += 1;
    }
    for v in 0..n {
        pred_start[v + 1] += pred_start[v];
        succ_start[v + 1] += succ_start[v];
    }
    let mut pred = vec![0usize; edges.len()];
    let mut succ = vec![0usize; edges.len()];
    {
        let mut pred_at = pred_start.clone();
        let mut succ_at = succ_start.clone();
        for &(a, b) in edges.iter().rev() {
            pred[pred_at[b]] = a;
            pred_at[b] += 1;
            succ[succ_at[a]] = b;
            succ_at[a] += 1;
        }
    }

    // First pass: petgraph's `DfsPostOrder` over the reversed graph from each
    // node in turn, recording the order in which nodes finish.
    let mut discovered = vec![false; n];
    let mut finished = vec![false; n];
    let mut finish_order = Vec::with_capacity(n);
    let mut stack: Vec<usize> = Vec::new();
    for start in 0..n {
        if discovered[start] {
            continue;
        }
        stack.push(start);
        while let Some(&v) = stack.last() {
            if !discovered[v] {
                discovered[v] = true;
                for &u in &pred[pred_start[v]..pred_start[v + 1]] {
                    if !discovered[u] {
                        stack.push(u);
                    }
                }
            } else {
                stack.pop();
                if !finished[v] {
                    finished[v] = true;
                    finish_order.push(v);
                }
            }
        }
    }

    // Second pass: from each node by decreasing finishing time not yet in a
    // component, everything it reaches that is not yet in one is its
    // component (whatever the order of the walk).
    const NONE: usize = usize::MAX;
    let mut component = vec![NONE; n];
    let mut count = 0;
    for &leader in finish_order.iter().rev() {
        if component[leader] != NONE {
            continue;
        }
        component[leader] = count;
        stack.push(leader);
        while let Some(v) = stack.pop() {
            for &w in &succ[succ_start[v]..succ_start[v + 1]] {
                if component[w] == NONE {
                    component[w] = count;
                    stack.push(w);
                }
            }
        }
        count += 1;
    }
    (component, count)
}

#[cfg(test)]
mod tests {
    use super::components;
    use petgraph::algo::kosaraju_scc;
    use petgraph::graph::{DiGraph, NodeIndex};
    use proptest::prelude::*;

    /// Petgraph's numbering, as this module computed it before.
    fn by_petgraph(n: usize, edges: &[(usize, usize)]) -> (Vec<usize>, usize) {
        let mut graph: DiGraph<(), ()> = DiGraph::with_capacity(n, edges.len());
        for _ in 0..n {
            graph.add_node(());
        }
        for &(a, b) in edges {
            graph.add_edge(NodeIndex::new(a), NodeIndex::new(b), ());
        }
        let found = kosaraju_scc(&graph);
        let mut component = vec![0; n];
        for (number, members) in found.iter().enumerate() {
            for v in members {
                component[v.index()] = number;
            }
        }
        (component, found.len())
    }

    proptest! {
        /// The same components, numbered the same, as petgraph's
        /// `kosaraju_scc`: the order of components in the outputs stays.
        #[test]
        fn numbered_as_petgraph_numbers_them(
            (n, edges) in (1usize..24).prop_flat_map(|n| {
                (Just(n), proptest::collection::vec((0..n, 0..n), 0..3 * n))
            })
        ) {
            prop_assert_eq!(components(n, edges.iter().copied()), by_petgraph(n, &edges));
        }
    }

    #[test]
    fn cycles_share_a_component_numbered_after_their_successors() {
        // 0 → 1 → 2 → 0 is a cycle; 2 → 3; 4 alone; a self-loop on 4.
        let (of, count) = components(5, [(0, 1), (1, 2), (2, 0), (2, 3), (4, 4)]);
        assert_eq!(count, 3);
        assert!(of[0] == of[1] && of[1] == of[2]);
        assert_ne!(of[2], of[3]);
        assert!(of[2] > of[3], "an edge goes to a lower number: {of:?}");
        assert_ne!(of[4], of[0]);
        assert_eq!(components(0, []), (Vec::new(), 0));
    }

    #[test]
    fn a_long_chain_needs_no_deep_stack() {
        // A recursive walk overflowed a 2 MiB test thread's stack far below
        // this; each node is its own component, the last one a sink.
        let n = 1_000_000;
        let (of, count) = components(n, (1..n).map(|v| (v - 1, v)));
        assert_eq!(count, n);
        assert!(
            of.windows(2).all(|w| w[0] > w[1]),
            "edges go to lower numbers"
        );
    }
}
