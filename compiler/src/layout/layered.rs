//! The rank and order phases of a layered (Sugiyama) layout of one level:
//! cycles are broken by reversing the back edges of a depth-first search,
//! nodes get layers by longest path, edges spanning several layers get a
//! virtual node in each layer between, and the order within each layer is
//! improved by barycenter sweeps (at most [`MAX_PASSES`], keeping the order
//! with the fewest crossings). Each pass is linear in the size of the layered
//! graph apart from sorting; crossings are counted in O(E log V).

/// Sweeps down and up, at most this many times.
const MAX_PASSES: usize = 8;

/// Where a node must go: anywhere, the first layer alone (a loop body's input
/// ports), or the last layer alone (its output ports).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pin {
    Free,
    First,
    Last,
}

/// The way one input edge runs through the layers.
#[derive(Clone, Debug)]
pub(crate) struct Chain {
    /// The node in the lower layer, the virtual nodes between, the node in
    /// the higher layer.
    pub nodes: Vec<usize>,
    /// The lower-layer node is the edge's head: it runs against the flow.
    pub reversed: bool,
    /// Both ends in one layer.
    pub flat: bool,
}

pub(crate) struct Layers {
    /// Nodes `0..real` are the input's; the others are virtual.
    pub real: usize,
    /// Every node's layer.
    pub rank: Vec<usize>,
    /// The nodes of each layer, in order.
    pub layers: Vec<Vec<usize>>,
    /// Every node's index in its layer.
    pub pos: Vec<usize>,
    /// Per input edge; `None` for a self-loop.
    pub chains: Vec<Option<Chain>>,
}

/// Ranks and orders the graph of `pins.len()` nodes and `edges` (tail,
/// head); `weak` edges are the first to be drawn against the flow.
pub(crate) fn layer(pins: &[Pin], edges: &[(usize, usize)], weak: &[bool]) -> Layers {
    let n = pins.len();
    let reversed = orient(pins, edges, weak);
    let oriented: Vec<(usize, usize)> = edges
        .iter()
        .zip(&reversed)
        .map(|(&(a, b), &r)| if r { (b, a) } else { (a, b) })
        .collect();
    let mut rank = ranks(pins, &oriented);
    let layer_count = rank.iter().map(|&r| r + 1).max().unwrap_or(0);
    let mut layers: Vec<Vec<usize>> = vec![Vec::new(); layer_count];
    for (v, &r) in rank.iter().enumerate() {
        layers[r].push(v);
    }
    let mut chains = Vec::with_capacity(edges.len());
    for (&(a, b), &r) in oriented.iter().zip(&reversed) {
        if a == b {
            chains.push(None);
            continue;
        }
        // Ranks may contradict the orientation only around pinned nodes.
        let (a, b, r) = if rank[a] > rank[b] {
            (b, a, !r)
        } else {
            (a, b, r)
        };
        let mut nodes = vec![a];
        let (from, to) = (rank[a] + 1, rank[b]);
        for (layer, members) in layers.iter_mut().enumerate().take(to).skip(from) {
            let v = rank.len();
            rank.push(layer);
            members.push(v);
            nodes.push(v);
        }
        nodes.push(b);
        chains.push(Some(Chain {
            nodes,
            reversed: r,
            flat: rank[a] == rank[b],
        }));
    }
    let mut layers = Layers {
        real: n,
        pos: vec![0; rank.len()],
        rank,
        layers,
        chains,
    };
    order(&mut layers);
    layers
}

/// Which edges to reverse so that the graph has no cycle. Edges into
/// first-layer nodes and out of last-layer nodes are turned round first.
/// Then the strong edges: the back edges of a depth-first search (started
/// from first-layer nodes, then sources, then the others, in index order) are
/// reversed. Weak edges (channels with initial samples: the feedback of a
/// cycle) follow a topological order of the strong ones, so that a cycle is
/// broken at its initial samples where it can be.
fn orient(pins: &[Pin], edges: &[(usize, usize)], weak: &[bool]) -> Vec<bool> {
    let n = pins.len();
    let pre: Vec<bool> = edges
        .iter()
        .map(|&(a, b)| pins[b] == Pin::First || pins[a] == Pin::Last)
        .collect();
    let turned = |e: usize| {
        let (a, b) = edges[e];
        if pre[e] { (b, a) } else { (a, b) }
    };
    // Only an edge on a cycle can be feedback: weak ones elsewhere count as strong.
    let (component, _) = crate::digraph::components(n, (0..edges.len()).map(turned));
    let weak: Vec<bool> = (0..edges.len())
        .map(|e| {
            let (a, b) = turned(e);
            weak.get(e).copied().unwrap_or(false) && component[a] == component[b]
        })
        .collect();
    let strong = |e: usize| !weak[e];
    let mut out: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    let mut indegree = vec![0usize; n];
    for e in (0..edges.len()).filter(|&e| strong(e)) {
        let (a, b) = turned(e);
        if a != b {
            out[a].push((e, b));
            indegree[b] += 1;
        }
    }
    let mut back = vec![false; edges.len()];
    // 0: not seen, 1: on the stack, 2: done.
    let mut state = vec![0u8; n];
    let roots = (0..n)
        .filter(|&v| pins[v] == Pin::First)
        .chain((0..n).filter(|&v| indegree[v] == 0))
        .chain(0..n);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for root in roots {
        if state[root] != 0 {
            continue;
        }
        state[root] = 1;
        stack.push((root, 0));
        while let Some(top) = stack.last_mut() {
            let (v, i) = *top;
            if let Some(&(e, w)) = out[v].get(i) {
                top.1 += 1;
                match state[w] {
                    0 => {
                        state[w] = 1;
                        stack.push((w, 0));
                    }
                    1 => back[e] = true,
                    _ => {}
                }
            } else {
                state[v] = 2;
                stack.pop();
            }
        }
    }
    // A topological order of the strong edges as now oriented (Kahn's
    // algorithm; first-layer nodes first, last-layer nodes last).
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut left = vec![0usize; n];
    for list in &out {
        for &(e, w) in list {
            let v = edges[e].0 + edges[e].1 - w;
            let (a, b) = if back[e] { (w, v) } else { (v, w) };
            succ[a].push(b);
            left[b] += 1;
        }
    }
    let pin_order = |v: &usize| match pins[*v] {
        Pin::First => 0,
        Pin::Free => 1,
        Pin::Last => 2,
    };
    let mut queue: Vec<usize> = (0..n).filter(|&v| left[v] == 0).collect();
    queue.sort_by_key(pin_order);
    let mut order = vec![usize::MAX; n];
    let mut head = 0;
    while let Some(&v) = queue.get(head) {
        order[v] = head;
        head += 1;
        for &w in &succ[v] {
            left[w] -= 1;
            if left[w] == 0 {
                queue.push(w);
            }
        }
    }
    (0..edges.len())
        .map(|e| {
            if strong(e) {
                pre[e] != back[e]
            } else {
                let (a, b) = turned(e);
                pre[e] != (order[a] > order[b])
            }
        })
        .collect()
}

/// Longest-path layers of the acyclic `edges`; sources move right next to
/// their nearest successor; empty layers are dropped; first-layer nodes get
/// layer 0 alone and last-layer nodes the last layer alone.
fn ranks(pins: &[Pin], edges: &[(usize, usize)]) -> Vec<usize> {
    let n = pins.len();
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut indegree = vec![0usize; n];
    for &(a, b) in edges {
        if a != b {
            out[a].push(b);
            indegree[b] += 1;
        }
    }
    let mut rank = vec![0usize; n];
    let mut left = indegree.clone();
    let mut queue: Vec<usize> = (0..n).filter(|&v| left[v] == 0).collect();
    let mut head = 0;
    while let Some(&v) = queue.get(head) {
        head += 1;
        for &w in &out[v] {
            rank[w] = rank[w].max(rank[v] + 1);
            left[w] -= 1;
            if left[w] == 0 {
                queue.push(w);
            }
        }
    }
    for v in 0..n {
        if pins[v] == Pin::Free
            && indegree[v] == 0
            && let Some(nearest) = out[v].iter().map(|&w| rank[w]).min()
        {
            rank[v] = nearest.saturating_sub(1);
        }
    }
    let free = |v: &usize| pins[*v] == Pin::Free;
    let mut used: Vec<usize> = (0..n).filter(free).map(|v| rank[v]).collect();
    used.sort_unstable();
    used.dedup();
    let has_first = pins.contains(&Pin::First);
    let shift = usize::from(has_first);
    for v in (0..n).filter(free) {
        rank[v] = used.binary_search(&rank[v]).unwrap_or(0) + shift;
    }
    let last = used.len() + shift;
    for v in 0..n {
        match pins[v] {
            Pin::First => rank[v] = 0,
            Pin::Last => rank[v] = last,
            Pin::Free => {}
        }
    }
    rank
}

/// Barycenter sweeps; keeps the order with the fewest crossings.
fn order(l: &mut Layers) {
    let total = l.rank.len();
    let mut up: Vec<Vec<usize>> = vec![Vec::new(); total];
    let mut down: Vec<Vec<usize>> = vec![Vec::new(); total];
    for chain in l.chains.iter().flatten().filter(|c| !c.flat) {
        for pair in chain.nodes.windows(2) {
            down[pair[0]].push(pair[1]);
            up[pair[1]].push(pair[0]);
        }
    }
    initial_order(l, &down);
    let mut best = l.layers.clone();
    let mut fewest = crossings(l, &down);
    let mut stale = 0;
    for _ in 0..MAX_PASSES {
        if fewest == 0 {
            break;
        }
        for i in 1..l.layers.len() {
            reorder(&mut l.layers[i], &up, &mut l.pos);
        }
        for i in (0..l.layers.len().saturating_sub(1)).rev() {
            reorder(&mut l.layers[i], &down, &mut l.pos);
        }
        let now = crossings(l, &down);
        if now < fewest {
            fewest = now;
            best.clone_from(&l.layers);
            stale = 0;
        } else {
            stale += 1;
            if stale == 2 {
                break;
            }
        }
    }
    l.layers = best;
    set_positions(l);
}

/// A first order: each layer in the order a depth-first search along the
/// edges reaches its nodes, so that connected nodes start out together.
fn initial_order(l: &mut Layers, down: &[Vec<usize>]) {
    let total = l.rank.len();
    let mut seen = vec![false; total];
    let mut visit = vec![usize::MAX; total];
    let mut count = 0;
    let mut stack = Vec::new();
    let starts: Vec<usize> = l.layers.iter().flatten().copied().collect();
    for start in starts {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        while let Some(v) = stack.pop() {
            visit[v] = count;
            count += 1;
            for &w in down[v].iter().rev() {
                if !seen[w] {
                    seen[w] = true;
                    stack.push(w);
                }
            }
        }
    }
    for layer in &mut l.layers {
        layer.sort_by_key(|&v| visit[v]);
    }
    set_positions(l);
}

fn set_positions(l: &mut Layers) {
    for layer in &l.layers {
        for (i, &v) in layer.iter().enumerate() {
            l.pos[v] = i;
        }
    }
}

/// Sorts `layer` by the mean position of each node's neighbours in the
/// adjacent layer; nodes without neighbours keep their place.
fn reorder(layer: &mut [usize], neighbours: &[Vec<usize>], pos: &mut [usize]) {
    let mut movable: Vec<(f64, usize, usize)> = Vec::new();
    for (i, &v) in layer.iter().enumerate() {
        let near = &neighbours[v];
        if !near.is_empty() {
            let sum: usize = near.iter().map(|&u| pos[u]).sum();
            movable.push((sum as f64 / near.len() as f64, i, v));
        }
    }
    movable.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut sorted = movable.into_iter().map(|(_, _, v)| v);
    for i in 0..layer.len() {
        if !neighbours[layer[i]].is_empty()
            && let Some(v) = sorted.next()
        {
            layer[i] = v;
        }
    }
    for (i, &v) in layer.iter().enumerate() {
        pos[v] = i;
    }
}

/// Edge crossings between all adjacent layers (inversions counted with a
/// Fenwick tree).
fn crossings(l: &Layers, down: &[Vec<usize>]) -> u64 {
    let mut total = 0u64;
    let mut lower: Vec<usize> = Vec::new();
    for pair in l.layers.windows(2) {
        let size = pair[1].len();
        lower.clear();
        for &v in &pair[0] {
            let start = lower.len();
            lower.extend(down[v].iter().map(|&w| l.pos[w]));
            lower[start..].sort_unstable();
        }
        let mut tree = vec![0u64; size + 1];
        for (seen, &p) in lower.iter().enumerate() {
            // Entries so far at positions <= p.
            let mut at_most = 0u64;
            let mut i = p + 1;
            while i > 0 {
                at_most += tree[i];
                i &= i - 1;
            }
            total += seen as u64 - at_most;
            let mut i = p + 1;
            while i <= size {
                tree[i] += 1;
                i += i & i.wrapping_neg();
            }
        }
    }
    total
}
