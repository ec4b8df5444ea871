//! Strongly connected components of a graph over node indices `0..n`: the
//! one routine (petgraph's Kosaraju) that the task-graph analyses and the
//! layered drawing all use, rather than each its own copy.
//!
//! Kosaraju, not Tarjan: petgraph's `TarjanScc` recurses once per node on a
//! path, so a chain of 139,000 tasks overflowed the main thread's stack;
//! `kosaraju_scc` walks with explicit stacks (`Dfs`, `DfsPostOrder`), its
//! depth bounded by nothing but memory, linear in the graph.

use petgraph::algo::kosaraju_scc;
use petgraph::graph::{DiGraph, NodeIndex};

/// The strongly connected component of each node `0..n` of the graph with
/// `edges` (pairs of node indices, each below `n`), and how many there are.
/// Components are numbered in reverse topological order of the condensation:
/// an edge between two components goes from a higher number to a lower one.
pub fn components(
    n: usize,
    edges: impl IntoIterator<Item = (usize, usize)>,
) -> (Vec<usize>, usize) {
    let mut graph: DiGraph<(), ()> = DiGraph::with_capacity(n, 0);
    for _ in 0..n {
        graph.add_node(());
    }
    for (a, b) in edges {
        graph.add_edge(NodeIndex::new(a), NodeIndex::new(b), ());
    }
    // Numbered as `kosaraju_scc` lists them: sinks of the condensation first.
    let found = kosaraju_scc(&graph);
    let mut component = vec![0; n];
    for (number, members) in found.iter().enumerate() {
        for v in members {
            component[v.index()] = number;
        }
    }
    (component, found.len())
}

#[cfg(test)]
mod tests {
    use super::components;

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
