//! Coordinates and edge routes for the levels of a scene, inner levels first:
//! a loop body is laid out on its own, and its size and the positions of its
//! ports on the border become the cluster node's size and fixed attach points
//! one level up.
//!
//! Layers are columns, left to right. Within a column, vertical positions
//! come from a few sweeps that put each node at the weighted mean of where its
//! edges would be straight, then keep the layer's order and spacing with the
//! closest such positions (isotonic regression, pool-adjacent-violators: linear
//! per layer). Gaps between columns are wide enough for the rate and sample
//! labels of the edges crossing them. Edges run straight through columns
//! (through their virtual nodes) and as S-curves across gaps; several edge ends
//! on one side of a box are spread out in the order of the nodes they go to.

use super::scene::{Edge, Level, Node, Shape, Side, Style};
use super::{DETAIL_FONT, LABEL_FONT, NODE_FONT, TITLE_FONT};
use crate::layout::layered::{self, Layers, Pin};
use crate::layout::text_width;

/// Space around the whole picture.
const MARGIN: f64 = 16.0;
/// Space inside a cluster's border.
const PAD: f64 = 14.0;
/// A cluster's title band.
const TITLE_H: f64 = 28.0;
/// The least space between two columns.
const GAP_MIN: f64 = 48.0;
/// Between boxes in a column; between an edge and anything else.
const NODE_GAP: f64 = 18.0;
const VIRTUAL_GAP: f64 = 8.0;
/// Between the edge ends on one side of a box.
const ATTACH: f64 = 14.0;
/// Between the lanes of edges going around a cluster.
const LANE: f64 = 10.0;
/// Between the tops of nested self-loops (room for a label between).
const LOOP_STEP: f64 = 16.0;
/// The smallest box.
const MIN_W: f64 = 54.0;
/// Position sweeps (each one down and one up).
const ROUNDS: usize = 6;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct P {
    pub x: f64,
    pub y: f64,
}

fn p(x: f64, y: f64) -> P {
    P { x, y }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rect {
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Seg {
    Line(P),
    /// Two control points, then the end.
    Cubic(P, P, P),
}

impl Seg {
    fn end(&self) -> P {
        match *self {
            Seg::Line(e) | Seg::Cubic(_, _, e) => e,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Anchor {
    Start,
    Middle,
    End,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) struct Label {
    /// The text's baseline point.
    pub at: P,
    pub anchor: Anchor,
    pub text: String,
}

/// An edge's path from its tail to its head, and its labels.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Route {
    pub start: P,
    pub segs: Vec<Seg>,
    pub tail: Option<Label>,
    pub head: Option<Label>,
    pub mid: Option<Label>,
}

impl Route {
    pub fn end(&self) -> P {
        self.segs.last().map_or(self.start, Seg::end)
    }

    /// Calls `f` with every point of the path, control points included.
    pub fn each_point(&self, mut f: impl FnMut(P)) {
        f(self.start);
        for seg in &self.segs {
            match *seg {
                Seg::Line(e) => f(e),
                Seg::Cubic(a, b, e) => {
                    f(a);
                    f(b);
                    f(e);
                }
            }
        }
    }
}

/// One level laid out, in its own coordinates (a cluster's level: the
/// cluster's top-left corner is the origin).
pub(super) struct Placed {
    pub width: f64,
    pub height: f64,
    /// Per node: its box (ports and relays: a point on the border).
    pub boxes: Vec<Rect>,
    /// Per node: a cluster's inner level.
    pub inner: Vec<Option<Placed>>,
    /// Per edge.
    pub routes: Vec<Route>,
}

pub(super) fn layout(root: &Level) -> Placed {
    place(root, None)
}

/// The size of a box holding `node`'s text lines.
fn box_size(node: &Node) -> (f64, f64) {
    let mut w: f64 = 0.0;
    for (i, line) in node.lines.iter().enumerate() {
        let size = if i == 0 { NODE_FONT } else { DETAIL_FONT };
        w = w.max(text_width(line, size));
    }
    let h = if node.lines.len() > 1 { 42.0 } else { 30.0 };
    ((w + 20.0).max(MIN_W), h)
}

fn is_point(node: &Node) -> bool {
    matches!(node.shape, Shape::Port | Shape::Relay)
}

/// How one end of an edge meets its node.
#[derive(Clone, Copy, Debug, Default)]
struct Attach {
    /// From the node's centre, vertically.
    off: f64,
    /// The side of the box (ignored for points).
    side: Option<Side>,
    /// A fixed port on the side facing away from the edge's direction: the
    /// edge goes around below the node in this lane.
    lane: Option<usize>,
}

/// Lays out `level`; `title` is a cluster's title width (None: the top level).
fn place(level: &Level, title: Option<f64>) -> Placed {
    let nodes = &level.nodes;
    let edges = &level.edges;
    let inner: Vec<Option<Placed>> = nodes
        .iter()
        .map(|node| {
            node.cluster.as_ref().map(|body| {
                let title = node
                    .lines
                    .first()
                    .map_or(0.0, |t| text_width(t, TITLE_FONT));
                place(body, Some(title * 1.06))
            })
        })
        .collect();
    let mut size: Vec<(f64, f64)> = nodes
        .iter()
        .zip(&inner)
        .map(|(node, inner)| match inner {
            Some(c) => (c.width, c.height),
            None if is_point(node) => (0.0, 0.0),
            None => box_size(node),
        })
        .collect();
    let pins: Vec<Pin> = nodes
        .iter()
        .map(|node| match (is_point(node), node.side) {
            (true, Some(Side::Left)) => Pin::First,
            (true, Some(Side::Right)) => Pin::Last,
            _ => Pin::Free,
        })
        .collect();
    let pairs: Vec<(usize, usize)> = edges.iter().map(|e| (e.from.node, e.to.node)).collect();
    // Channels with initial samples close cycles: drawn backwards first.
    let weak: Vec<bool> = edges
        .iter()
        .map(|e| e.style == Style::Data && !e.mid.is_empty())
        .collect();
    let lay = layered::layer(&pins, &pairs, &weak);
    let mut g = Geometry::new(nodes, edges, &inner, &lay, &mut size);
    g.positions();
    g.columns(title, pins.contains(&Pin::First), pins.contains(&Pin::Last));
    let mut placed = g.finish(title.is_some());
    placed.inner = inner;
    placed
}

struct Geometry<'a> {
    nodes: &'a [Node],
    edges: &'a [Edge],
    inner: &'a [Option<Placed>],
    lay: &'a Layers,
    size: &'a [(f64, f64)],
    /// Per edge: the ends at the lower and the higher layer.
    attach: Vec<[Attach; 2]>,
    /// Per node (virtual ones too): extents above and below its centre.
    above: Vec<f64>,
    below: Vec<f64>,
    /// Per edge that is a self-loop: its number among its node's loops.
    loop_index: Vec<usize>,
    y: Vec<f64>,
    col_x: Vec<f64>,
    col_w: Vec<f64>,
    width: f64,
    height: f64,
}

impl<'a> Geometry<'a> {
    fn new(
        nodes: &'a [Node],
        edges: &'a [Edge],
        inner: &'a [Option<Placed>],
        lay: &'a Layers,
        size: &'a mut [(f64, f64)],
    ) -> Geometry<'a> {
        let n = nodes.len();
        let total = lay.rank.len();
        let mut attach = vec![[Attach::default(); 2]; edges.len()];
        // Edge ends spread along each side of each box: (neighbour position, edge, end).
        let mut spread: Vec<[Vec<(usize, usize, usize)>; 2]> =
            (0..n).map(|_| [Vec::new(), Vec::new()]).collect();
        let mut lanes = vec![0usize; n];
        let mut loops = vec![0usize; n];
        let mut fixed_loops = vec![0usize; n];
        let mut loop_index = vec![0usize; edges.len()];
        for (e, edge) in edges.iter().enumerate() {
            let Some(chain) = &lay.chains[e] else {
                let v = edge.from.node;
                if edge.from.port.is_some() || edge.to.port.is_some() {
                    loop_index[e] = fixed_loops[v];
                    fixed_loops[v] += 1;
                } else {
                    loop_index[e] = loops[v];
                    loops[v] += 1;
                }
                continue;
            };
            let (low, high) = if chain.reversed {
                (edge.to, edge.from)
            } else {
                (edge.from, edge.to)
            };
            let last = chain.nodes.len() - 1;
            for (which, end, natural, neighbour) in [
                (0, low, Side::Right, chain.nodes[1.min(last)]),
                (1, high, Side::Left, chain.nodes[last.saturating_sub(1)]),
            ] {
                let natural = if chain.flat { Side::Right } else { natural };
                let v = end.node;
                match (end.port, &inner[v]) {
                    (Some(port), Some(body)) => {
                        let side = nodes[v]
                            .cluster
                            .as_ref()
                            .and_then(|c| c.nodes.get(port))
                            .and_then(|n| n.side)
                            .unwrap_or(natural);
                        let at = body.boxes.get(port).map_or(0.0, |b| b.y);
                        let mut a = Attach {
                            off: at - size[v].1 / 2.0,
                            side: Some(side),
                            lane: None,
                        };
                        if side != natural && !chain.flat {
                            a.lane = Some(lanes[v]);
                            lanes[v] += 1;
                        }
                        attach[e][which] = a;
                    }
                    _ if is_point(&nodes[v]) => {}
                    _ => {
                        let s = usize::from(natural == Side::Right);
                        spread[v][s].push((lay.pos[neighbour], e, which));
                        attach[e][which].side = Some(natural);
                    }
                }
            }
        }
        for v in 0..n {
            if inner[v].is_some() || is_point(&nodes[v]) {
                continue;
            }
            let most = spread[v][0].len().max(spread[v][1].len());
            let h = &mut size[v].1;
            *h = h.max(most as f64 * ATTACH + 10.0);
            let h = *h;
            for list in &mut spread[v] {
                list.sort_unstable();
                let m = list.len();
                if m == 0 {
                    continue;
                }
                let step = ((h - 10.0) / m as f64).min(20.0);
                for (k, &(_, e, which)) in list.iter().enumerate() {
                    attach[e][which].off = (k as f64 - (m as f64 - 1.0) / 2.0) * step;
                }
            }
        }
        let size: &'a [(f64, f64)] = size;
        let mut above = vec![4.0; total];
        let mut below = vec![4.0; total];
        for v in 0..n {
            let h = size[v].1;
            if nodes[v].shape == Shape::Port {
                // The port's name is written below it.
                above[v] = 6.0;
                below[v] = 14.0;
                continue;
            }
            if nodes[v].shape == Shape::Relay {
                continue;
            }
            above[v] = h / 2.0;
            below[v] = h / 2.0;
            if loops[v] > 0 {
                above[v] += 16.0 + LOOP_STEP * (loops[v] - 1) as f64 + 14.0;
            }
            if fixed_loops[v] > 0 {
                above[v] = above[v].max(h / 2.0 + LANE * fixed_loops[v] as f64 + 18.0);
            }
            if lanes[v] > 0 {
                below[v] += 8.0 + LANE * lanes[v] as f64;
            }
        }
        for e in 0..edges.len() {
            for which in 0..2 {
                if let Some(lane) = attach[e][which].lane {
                    let v = [edges[e].from.node, edges[e].to.node];
                    let chain = lay.chains[e].as_ref();
                    let v = match chain {
                        Some(c) if c.reversed => v[1 - which],
                        _ => v[which],
                    };
                    attach[e][which].off = size[v].1 / 2.0 + 8.0 + LANE * lane as f64;
                }
            }
        }
        Geometry {
            nodes,
            edges,
            inner,
            lay,
            size,
            attach,
            above,
            below,
            loop_index,
            y: vec![0.0; total],
            col_x: Vec::new(),
            col_w: Vec::new(),
            width: 0.0,
            height: 0.0,
        }
    }

    fn is_virtual(&self, v: usize) -> bool {
        v >= self.lay.real
    }

    /// Vertical positions: sweeps towards straight edges, keeping order and spacing.
    fn positions(&mut self) {
        let total = self.lay.rank.len();
        // (other node, offset at the other node, offset here, weight)
        let mut links: Vec<Vec<(usize, f64, f64, f64)>> = vec![Vec::new(); total];
        for (e, chain) in self.lay.chains.iter().enumerate() {
            let Some(chain) = chain.as_ref().filter(|c| !c.flat) else {
                continue;
            };
            let last = chain.nodes.len() - 1;
            let off = |i: usize| match i {
                0 => self.attach[e][0].off,
                i if i == last => self.attach[e][1].off,
                _ => 0.0,
            };
            for i in 0..last {
                let (a, b) = (chain.nodes[i], chain.nodes[i + 1]);
                let weight = match (self.is_virtual(a), self.is_virtual(b)) {
                    (true, true) => 8.0,
                    (false, false) => 1.0,
                    _ => 2.0,
                };
                links[a].push((b, off(i + 1), off(i), weight));
                links[b].push((a, off(i), off(i + 1), weight));
            }
        }
        for layer in &self.lay.layers {
            let mut at = 0.0;
            for (i, &v) in layer.iter().enumerate() {
                if i > 0 {
                    at += self.separation(layer[i - 1], v);
                }
                self.y[v] = at;
            }
            for &v in layer {
                self.y[v] -= at / 2.0;
            }
        }
        let count = self.lay.layers.len();
        let mut want = Vec::new();
        let mut weight = Vec::new();
        let mut sep = Vec::new();
        for round in 0..ROUNDS * 2 {
            for step in 0..count {
                let i = if round % 2 == 0 {
                    step
                } else {
                    count - 1 - step
                };
                let layer = &self.lay.layers[i];
                want.clear();
                weight.clear();
                sep.clear();
                for (k, &v) in layer.iter().enumerate() {
                    let (mut sw, mut st) = (0.0, 0.0);
                    for &(u, off_u, off_v, w) in &links[v] {
                        sw += w;
                        st += w * (self.y[u] + off_u - off_v);
                    }
                    if sw > 0.0 {
                        want.push(st / sw);
                        weight.push(sw);
                    } else {
                        want.push(self.y[v]);
                        weight.push(0.05);
                    }
                    if k > 0 {
                        sep.push(self.separation(layer[k - 1], v));
                    }
                }
                let placed = closest_ordered(&want, &weight, &sep);
                for (&v, y) in layer.iter().zip(placed) {
                    self.y[v] = y;
                }
            }
        }
    }

    /// The least distance between the centres of `a` above `b` in a column.
    fn separation(&self, a: usize, b: usize) -> f64 {
        let gap = match (self.is_virtual(a), self.is_virtual(b)) {
            (true, true) => VIRTUAL_GAP,
            _ => NODE_GAP,
        };
        self.below[a] + gap + self.above[b]
    }

    /// Column widths and places; the gap after each column fits the labels
    /// of the edges crossing it.
    fn columns(&mut self, title: Option<f64>, first_pinned: bool, last_pinned: bool) {
        let count = self.lay.layers.len();
        self.col_w = vec![0.0; count];
        for v in 0..self.lay.real {
            let r = self.lay.rank[v];
            self.col_w[r] = self.col_w[r].max(self.size[v].0);
        }
        let mut gap = vec![GAP_MIN; count];
        for (e, chain) in self.lay.chains.iter().enumerate() {
            let Some(chain) = chain.as_ref().filter(|c| !c.flat) else {
                continue;
            };
            let edge = &self.edges[e];
            let (low, high) = if chain.reversed {
                (&edge.head, &edge.tail)
            } else {
                (&edge.tail, &edge.head)
            };
            let links = chain.nodes.len() - 1;
            let mid = (links - 1) / 2;
            for i in 0..links {
                let mut need = 30.0;
                if i == 0 {
                    need += text_width(low, LABEL_FONT);
                    if self.attach[e][0].lane.is_some() {
                        need += LANE;
                    }
                }
                if i == links - 1 {
                    need += text_width(high, LABEL_FONT);
                    if self.attach[e][1].lane.is_some() {
                        need += LANE;
                    }
                }
                if i == mid && !edge.mid.is_empty() {
                    need += text_width(&edge.mid, LABEL_FONT) + 12.0;
                }
                let r = self.lay.rank[chain.nodes[i]];
                gap[r] = gap[r].max(need);
            }
        }
        let start = match title {
            Some(_) if first_pinned => 0.0,
            Some(_) => PAD,
            None => MARGIN,
        };
        let mut x = start;
        self.col_x = self
            .col_w
            .iter()
            .zip(&gap)
            .map(|(w, g)| {
                let at = x;
                x += w + g;
                at
            })
            .collect();
        let right = match count {
            0 => start,
            _ => self.col_x[count - 1] + self.col_w[count - 1],
        };
        self.width = match title {
            Some(t) => {
                let w = if last_pinned { right } else { right + PAD };
                let w = w.max(t + 2.0 * PAD).max(60.0);
                if last_pinned && count > 0 {
                    self.col_x[count - 1] = w;
                }
                w
            }
            None => right + MARGIN,
        };
    }

    fn col_left(&self, r: usize) -> f64 {
        self.col_x[r]
    }

    fn col_right(&self, r: usize) -> f64 {
        self.col_x[r] + self.col_w[r]
    }

    /// Shifts everything below the title (or margin), then builds boxes and routes.
    fn finish(mut self, cluster: bool) -> Placed {
        let total = self.lay.rank.len();
        let top = (0..total)
            .map(|v| self.y[v] - self.above[v])
            .fold(f64::INFINITY, f64::min);
        let bottom = (0..total)
            .map(|v| self.y[v] + self.below[v])
            .fold(f64::NEG_INFINITY, f64::max);
        let (first, last) = if cluster {
            (TITLE_H + 4.0, PAD)
        } else {
            (MARGIN, MARGIN)
        };
        if total == 0 {
            self.height = first + last;
        } else {
            let shift = first - top;
            for y in &mut self.y {
                *y += shift;
            }
            self.height = bottom + shift + last;
        }
        let boxes: Vec<Rect> = (0..self.lay.real)
            .map(|v| {
                let (w, h) = self.size[v];
                let r = self.lay.rank[v];
                let x = self.col_x[r] + (self.col_w[r] - w) / 2.0;
                Rect {
                    x,
                    y: self.y[v] - h / 2.0,
                    w,
                    h,
                }
            })
            .collect();
        let routes = (0..self.edges.len())
            .map(|e| self.route(e, &boxes))
            .collect();
        Placed {
            width: self.width,
            height: self.height,
            boxes,
            inner: Vec::new(),
            routes,
        }
    }

    /// Where an end of edge `e` meets its node (`which`: 0 at the lower layer).
    fn point(&self, e: usize, which: usize, boxes: &[Rect]) -> P {
        let v = self.end_node(e, which);
        let b = boxes[v];
        if is_point(&self.nodes[v]) {
            return p(b.x, b.y);
        }
        let a = self.attach[e][which];
        let cy = b.y + b.h / 2.0;
        // A port on the side facing away: `off` is its lane, not the port.
        let off = match a.lane {
            Some(_) => self.port_offset(e, which),
            None => a.off,
        };
        match a.side {
            Some(Side::Left) => p(b.x, cy + off),
            Some(Side::Right) | None => p(b.x + b.w, cy + off),
        }
    }

    /// The offset of a fixed port from its cluster's centre.
    fn port_offset(&self, e: usize, which: usize) -> f64 {
        let v = self.end_node(e, which);
        let end = self.end(e, which);
        match (end.port, &self.inner[v]) {
            (Some(port), Some(body)) => {
                body.boxes.get(port).map_or(0.0, |b| b.y) - self.size[v].1 / 2.0
            }
            _ => 0.0,
        }
    }

    fn end(&self, e: usize, which: usize) -> super::scene::End {
        let edge = &self.edges[e];
        let reversed = self.lay.chains[e].as_ref().is_some_and(|c| c.reversed);
        if (which == 0) != reversed {
            edge.from
        } else {
            edge.to
        }
    }

    fn end_node(&self, e: usize, which: usize) -> usize {
        self.end(e, which).node
    }

    fn route(&self, e: usize, boxes: &[Rect]) -> Route {
        let edge = &self.edges[e];
        let Some(chain) = &self.lay.chains[e] else {
            return self.self_loop(e, boxes);
        };
        if chain.flat {
            return self.flat(e, boxes);
        }
        let last = chain.nodes.len() - 1;
        let mid_link = (last - 1) / 2;
        let start = self.point(e, 0, boxes);
        let mut path = Path::new(start);
        let r0 = self.lay.rank[chain.nodes[0]];
        if self.attach[e][0].lane.is_some() {
            let ly = self.lane_y(e, 0, boxes);
            path.line(p(start.x - LANE, start.y));
            path.line(p(start.x - LANE, ly));
            path.line(p(self.col_right(r0), ly));
        } else if start.x < self.col_right(r0) {
            path.line(p(self.col_right(r0), start.y));
        }
        let mut mid = None;
        for i in 1..last {
            let v = chain.nodes[i];
            let r = self.lay.rank[v];
            let to = p(self.col_left(r), self.y[v]);
            if i - 1 == mid_link {
                mid = Some(midpoint(path.at, to));
            }
            path.cross(to);
            if self.col_w[r] > 0.0 {
                path.line(p(self.col_right(r), self.y[v]));
            }
        }
        let end = self.point(e, 1, boxes);
        let rl = self.lay.rank[chain.nodes[last]];
        let arrive = if self.attach[e][1].lane.is_some() {
            p(self.col_left(rl), self.lane_y(e, 1, boxes))
        } else {
            p(self.col_left(rl), end.y)
        };
        if last - 1 == mid_link {
            mid = Some(midpoint(path.at, arrive));
        }
        path.cross(arrive);
        if self.attach[e][1].lane.is_some() {
            path.line(p(end.x + LANE, arrive.y));
            path.line(p(end.x + LANE, end.y));
            path.line(end);
        } else if end.x > arrive.x {
            path.line(end);
        }
        let mut route = path.route();
        if chain.reversed {
            route = reverse(route);
        }
        route.mid = mid.and_then(|m| middle_label(&edge.mid, m));
        label_ends(&mut route, edge);
        route
    }

    /// The lane below a cluster that edge `e` goes around it in.
    fn lane_y(&self, e: usize, which: usize, boxes: &[Rect]) -> f64 {
        let v = self.end_node(e, which);
        let b = boxes[v];
        let lane = self.attach[e][which].lane.unwrap_or(0);
        b.y + b.h + 8.0 + LANE * lane as f64
    }

    /// An edge between two nodes of one column: a bulge beside them.
    fn flat(&self, e: usize, boxes: &[Rect]) -> Route {
        let edge = &self.edges[e];
        let (a, b) = (self.point(e, 0, boxes), self.point(e, 1, boxes));
        let (from, to) = if self.lay.chains[e].as_ref().is_some_and(|c| c.reversed) {
            (b, a)
        } else {
            (a, b)
        };
        let v = edge.from.node;
        // Ports on the right border bulge inwards, to the left.
        let dir = if self.nodes[v].side == Some(Side::Right) && is_point(&self.nodes[v]) {
            -1.0
        } else {
            1.0
        };
        let bulge = (24.0 + 0.25 * (to.y - from.y).abs()).min(60.0) * dir;
        let mut route = Route {
            start: from,
            segs: vec![Seg::Cubic(
                p(from.x + bulge, from.y),
                p(to.x + bulge, to.y),
                to,
            )],
            tail: None,
            head: None,
            mid: None,
        };
        route.mid = middle_label(
            &edge.mid,
            p((from.x + to.x) / 2.0 + 0.75 * bulge, (from.y + to.y) / 2.0),
        );
        label_ends(&mut route, edge);
        route
    }

    /// An edge from a node to itself: a loop above it (around a cluster's
    /// top when it joins two of its ports).
    fn self_loop(&self, e: usize, boxes: &[Rect]) -> Route {
        let edge = &self.edges[e];
        let v = edge.from.node;
        let b = boxes[v];
        let k = self.loop_index[e] as f64;
        let fixed = |end: super::scene::End| {
            let (Some(port), Some(body)) = (end.port, &self.inner[v]) else {
                return None;
            };
            let side = self.nodes[v]
                .cluster
                .as_ref()
                .and_then(|c| c.nodes.get(port))
                .and_then(|n| n.side)?;
            let y = b.y + body.boxes.get(port).map_or(0.0, |r| r.y);
            Some(match side {
                Side::Left => (p(b.x, y), -1.0),
                Side::Right => (p(b.x + b.w, y), 1.0),
            })
        };
        let mut route = match (fixed(edge.from), fixed(edge.to)) {
            (Some((from, fd)), Some((to, td))) => {
                let ly = b.y - LANE * (k + 1.0) - 4.0;
                let out = 8.0 + 4.0 * k;
                let mut path = Path::new(from);
                path.line(p(from.x + fd * out, from.y));
                path.line(p(from.x + fd * out, ly));
                path.line(p(to.x + td * out, ly));
                path.line(p(to.x + td * out, to.y));
                path.line(to);
                let mut route = path.route();
                let m = p((from.x + to.x) / 2.0, ly);
                route.mid = middle_label(&edge.mid, m);
                route
            }
            _ => {
                let cx = b.x + b.w / 2.0;
                let top = b.y;
                let a = (8.0 + 12.0 * k).min((b.w / 2.0 - 4.0).max(6.0));
                let h = 16.0 + LOOP_STEP * k;
                let lift = h * 4.0 / 3.0;
                let mut route = Route {
                    start: p(cx + a, top),
                    segs: vec![Seg::Cubic(
                        p(cx + a + 8.0, top - lift),
                        p(cx - a - 8.0, top - lift),
                        p(cx - a, top),
                    )],
                    tail: None,
                    head: None,
                    mid: None,
                };
                if !edge.mid.is_empty() {
                    route.mid = Some(Label {
                        at: p(cx, top - h - 4.0),
                        anchor: Anchor::Middle,
                        text: edge.mid.clone(),
                    });
                }
                route.tail = end_label(&edge.tail, p(cx + a + 3.0, top - 3.0), Anchor::Start);
                route.head = end_label(&edge.head, p(cx - a - 3.0, top - 3.0), Anchor::End);
                return route;
            }
        };
        label_ends(&mut route, edge);
        route
    }
}

fn midpoint(a: P, b: P) -> P {
    p((a.x + b.x) / 2.0, (a.y + b.y) / 2.0)
}

/// A label centred on the edge's line at `at`.
fn middle_label(text: &str, at: P) -> Option<Label> {
    (!text.is_empty()).then(|| Label {
        at: p(at.x, at.y + 3.5),
        anchor: Anchor::Middle,
        text: text.to_string(),
    })
}

fn end_label(text: &str, at: P, anchor: Anchor) -> Option<Label> {
    (!text.is_empty()).then(|| Label {
        at,
        anchor,
        text: text.to_string(),
    })
}

/// The tail and head labels, just above the line where it leaves its ends.
fn label_ends(route: &mut Route, edge: &Edge) {
    let start = route.start;
    let next = match route.segs.first() {
        Some(Seg::Line(e)) => *e,
        Some(Seg::Cubic(c, _, _)) => *c,
        None => start,
    };
    let end = route.end();
    let before = match route.segs.last() {
        Some(Seg::Line(_)) if route.segs.len() > 1 => route.segs[route.segs.len() - 2].end(),
        Some(Seg::Line(_)) => start,
        Some(Seg::Cubic(_, c, _)) => *c,
        None => end,
    };
    // `away`: how far from the end along the line (clear of an arrowhead).
    let place = |at: P, toward: P, away: f64| {
        if toward.x >= at.x {
            (p(at.x + away, at.y - 4.0), Anchor::Start)
        } else {
            (p(at.x - away, at.y - 4.0), Anchor::End)
        }
    };
    let (at, anchor) = place(start, next, 4.0);
    route.tail = end_label(&edge.tail, at, anchor);
    let (at, anchor) = place(end, before, 9.0);
    route.head = end_label(&edge.head, at, anchor);
}

/// The same path the other way round.
fn reverse(route: Route) -> Route {
    let mut ends = vec![route.start];
    ends.extend(route.segs.iter().map(Seg::end));
    let mut segs = Vec::with_capacity(route.segs.len());
    for (i, seg) in route.segs.iter().enumerate().rev() {
        let to = ends[i];
        segs.push(match *seg {
            Seg::Line(_) => Seg::Line(to),
            Seg::Cubic(a, b, _) => Seg::Cubic(b, a, to),
        });
    }
    Route {
        start: route.end(),
        segs,
        tail: None,
        head: None,
        mid: None,
    }
}

/// A path being built: straight lines, and S-curves across gaps.
struct Path {
    start: P,
    at: P,
    segs: Vec<Seg>,
}

impl Path {
    fn new(start: P) -> Path {
        Path {
            start,
            at: start,
            segs: Vec::new(),
        }
    }

    fn line(&mut self, to: P) {
        if to != self.at {
            self.segs.push(Seg::Line(to));
            self.at = to;
        }
    }

    /// Across a gap: horizontal at both ends.
    fn cross(&mut self, to: P) {
        if (to.y - self.at.y).abs() < 0.05 {
            self.line(to);
            return;
        }
        let mx = (self.at.x + to.x) / 2.0;
        self.segs
            .push(Seg::Cubic(p(mx, self.at.y), p(mx, to.y), to));
        self.at = to;
    }

    fn route(self) -> Route {
        Route {
            start: self.start,
            segs: self.segs,
            tail: None,
            head: None,
            mid: None,
        }
    }
}

/// The positions closest to `want` (least squares, weighted) with
/// `y[i + 1] - y[i] >= sep[i]`: pool adjacent violators on `y[i] - offset[i]`.
fn closest_ordered(want: &[f64], weight: &[f64], sep: &[f64]) -> Vec<f64> {
    let n = want.len();
    let mut offset = Vec::with_capacity(n);
    let mut at = 0.0;
    for i in 0..n {
        if i > 0 {
            at += sep[i - 1];
        }
        offset.push(at);
    }
    // Blocks of (total weight, weighted sum, length).
    let mut blocks: Vec<(f64, f64, usize)> = Vec::new();
    for i in 0..n {
        let w = weight[i].max(1e-6);
        blocks.push((w, w * (want[i] - offset[i]), 1));
        while blocks.len() > 1 {
            let (w1, s1, n1) = blocks[blocks.len() - 1];
            let (w0, s0, n0) = blocks[blocks.len() - 2];
            if s0 / w0 <= s1 / w1 {
                break;
            }
            blocks.pop();
            let last = blocks.len() - 1;
            blocks[last] = (w0 + w1, s0 + s1, n0 + n1);
        }
    }
    let mut y = Vec::with_capacity(n);
    for (w, s, len) in blocks {
        let z = s / w;
        for _ in 0..len {
            let i = y.len();
            y.push(z + offset[i]);
        }
    }
    y
}
