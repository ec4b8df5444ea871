//! Strongly connected components of a graph over node indices `0..n`: the
//! one routine (petgraph's Tarjan) that the task-graph schedule and the
//! layered drawing both use, rather than each its own copy.

use petgraph::algo::TarjanScc;
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
    // Numbered as they are found (as `tarjan_scc` lists them), without a
    // vector per component.
    let mut component = vec![0; n];
    let mut count = 0;
    TarjanScc::new().run(&graph, |members| {
        for v in members {
            component[v.index()] = count;
        }
        count += 1;
    });
    (component, count)
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
}
