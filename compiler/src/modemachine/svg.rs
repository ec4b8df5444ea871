//! Mode machines as one SVG: a panel per team, modes as rounded boxes laid
//! out left to right by the task-graph picture's layering stage
//! ([`crate::layout::layered`]: cycles broken, longest-path layers,
//! virtual nodes on long edges, barycenter ordering), mode changes as arrows
//! labelled with their events, the default mode drawn bold with an initial
//! dot pointing at it. Changes against the flow (closing a cycle) bow below
//! their straight line so that a pair `A → B`, `B → A` stays two arrows; a
//! change from a mode to itself is a loop above the box.
//!
//! Coordinates are written with one decimal and nothing depends on hash
//! order: the same mission always gives the same bytes.

use super::ModeMachine;
use crate::layout::layered::{self, Pin};
use crate::layout::text_width;
use crate::xmlpos::escape;
use std::fmt::Write;

const FONT: f64 = 12.0;
const LABEL_FONT: f64 = 10.0;
const BOX_H: f64 = 30.0;
/// Vertical room per node slot in a layer (box and the gap below it): room
/// for a self-loop and its label above a box, clear of an arrow passing
/// through the slot above.
const SLOT: f64 = 84.0;
const MIN_GAP: f64 = 60.0;
const MARGIN: f64 = 20.0;
/// Left of the first layer: room for the default mode's initial dot.
const LEFT: f64 = 40.0;
/// Room above the boxes for the title, self-loops and the initial dot.
const HEAD: f64 = 60.0;
/// How far a change against the flow bows below its straight line.
const BOW: f64 = 18.0;

#[derive(Clone, Copy)]
struct P {
    x: f64,
    y: f64,
}

fn num(v: f64) -> String {
    let r = (v * 10.0).round() / 10.0;
    if r == r.trunc() {
        format!("{}", r as i64)
    } else {
        format!("{r:.1}")
    }
}

fn label_of(events: &[crate::syntax::ast::Name]) -> String {
    events
        .iter()
        .map(|e| e.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// One team's panel, drawn at the origin; `(width, height, svg body)`.
fn panel(machine: &ModeMachine) -> (f64, f64, String) {
    let n = machine.modes.len();
    let pins = vec![Pin::Free; n];
    let edges: Vec<(usize, usize)> = machine.changes.iter().map(|c| (c.from, c.to)).collect();
    let weak = vec![false; edges.len()];
    let layers = layered::layer(&pins, &edges, &weak);
    let total = layers.rank.len();
    let width_of = |v: usize| {
        if v < n {
            text_width(&machine.modes[v], FONT) + 28.0
        } else {
            0.0
        }
    };
    // Each layer as wide as its widest box; each gap as wide as the widest
    // label of a change leaving the layer.
    let layer_w: Vec<f64> = layers
        .layers
        .iter()
        .map(|members| members.iter().map(|&v| width_of(v)).fold(16.0, f64::max))
        .collect();
    let mut gap = vec![MIN_GAP; layers.layers.len()];
    for (change, chain) in machine.changes.iter().zip(&layers.chains) {
        if let Some(chain) = chain {
            let r = layers.rank[chain.nodes[0]];
            let w = text_width(&label_of(&change.events), LABEL_FONT) + 30.0;
            gap[r] = gap[r].max(w);
        }
    }
    let mut layer_x = Vec::with_capacity(layer_w.len());
    let mut x = LEFT;
    for (w, g) in layer_w.iter().zip(&gap) {
        layer_x.push(x);
        x += w + g;
    }
    let mut width = (x - gap.last().copied().unwrap_or(0.0) + MARGIN)
        .max(text_width(&format!("{} modes", machine.team), FONT) + 2.0 * MARGIN);
    let tallest = layers.layers.iter().map(Vec::len).max().unwrap_or(0) as f64;
    let mut height = HEAD + tallest * SLOT + MARGIN;
    let mut centre = vec![P { x: 0.0, y: 0.0 }; total];
    for (r, members) in layers.layers.iter().enumerate() {
        let top = HEAD + (tallest - members.len() as f64) * SLOT / 2.0;
        for (i, &v) in members.iter().enumerate() {
            centre[v] = P {
                x: layer_x[r] + layer_w[r] / 2.0,
                y: top + i as f64 * SLOT + BOX_H / 2.0,
            };
        }
    }

    let routes = routes(machine, &layers.chains, &centre, &width_of);
    // Labels go where they cover no box and no other label.
    let mut taken: Vec<Rect> = (0..n)
        .map(|v| Rect::around(centre[v], width_of(v), BOX_H).grow(2.0))
        .collect();
    let mut labels = Vec::with_capacity(routes.len());
    for (change, route) in machine.changes.iter().zip(&routes) {
        let label = label_of(&change.events);
        let w = text_width(&label, LABEL_FONT) + 6.0;
        let spot = place_label(&route.label_spots, w, &taken);
        taken.push(spot.grow(1.0));
        width = width.max(spot.x1 + MARGIN);
        height = height.max(spot.y1 + MARGIN);
        labels.push((label, spot));
    }

    let mut out = String::new();
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"22\" font-size=\"{}\" font-weight=\"bold\" fill=\"#333\">{} modes</text>",
        num(MARGIN),
        num(FONT),
        escape(&machine.team)
    );
    for ((change, route), (label, spot)) in machine.changes.iter().zip(&routes).zip(&labels) {
        let dead = change.is_dead();
        let _ = write!(
            out,
            "<g class=\"change{}\" data-from=\"{}\" data-to=\"{}\">",
            if dead { " dead" } else { "" },
            escape(&machine.modes[change.from]),
            escape(&machine.modes[change.to])
        );
        if !change.never_thrown.is_empty() {
            let _ = write!(
                out,
                "<title>never fires on {}: no service of {} throws it</title>",
                escape(&label_of(&change.never_thrown)),
                escape(&machine.modes[change.from])
            );
        }
        let (stroke, dash) = if dead {
            ("#999", " stroke-dasharray=\"5 4\"")
        } else {
            ("#333", "")
        };
        let _ = write!(
            out,
            "<path d=\"{}\" fill=\"none\" stroke=\"{stroke}\" stroke-width=\"1.2\"{dash} marker-end=\"url(#semo-mode-arrow)\"/>",
            route.path
        );
        write_label(&mut out, *spot, label, dead);
        out.push_str("</g>\n");
    }
    for (v, name) in machine.modes.iter().enumerate() {
        let c = centre[v];
        let w = width_of(v);
        let is_default = machine.default == Some(v);
        let unreachable = machine.unreachable.contains(&v);
        let _ = write!(
            out,
            "<g class=\"mode{}{}\" data-mode=\"{}\"><title>{}{}</title>",
            if is_default { " default" } else { "" },
            if unreachable { " unreachable" } else { "" },
            escape(name),
            escape(name),
            if is_default {
                " (default: the team starts here)"
            } else if unreachable {
                " (unreachable: no catch leads here from the default mode)"
            } else {
                ""
            }
        );
        let (fill, stroke, dash, ink) = if unreachable {
            ("#f2f2f2", "#888", " stroke-dasharray=\"5 4\"", "#777")
        } else {
            ("#e8f0fe", "#1a4d8f", "", "#111")
        };
        let _ = write!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"12\" fill=\"{fill}\" stroke=\"{stroke}\" stroke-width=\"{}\"{dash}/>",
            num(c.x - w / 2.0),
            num(c.y - BOX_H / 2.0),
            num(w),
            num(BOX_H),
            if is_default { "2.6" } else { "1.2" }
        );
        let _ = write!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" fill=\"{ink}\"{}>{}</text>",
            num(c.x),
            num(c.y + FONT * 0.35),
            num(FONT),
            if is_default {
                " font-weight=\"bold\""
            } else {
                ""
            },
            escape(name)
        );
        if is_default {
            // The initial dot, left of the box, pointing at it.
            let _ = write!(
                out,
                "<circle class=\"initial\" cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"#111\"/><path d=\"M{} {} L{} {}\" stroke=\"#111\" stroke-width=\"1.2\" marker-end=\"url(#semo-mode-arrow)\"/>",
                num(c.x - w / 2.0 - 22.0),
                num(c.y - BOX_H / 2.0 - 16.0),
                num(c.x - w / 2.0 - 18.0),
                num(c.y - BOX_H / 2.0 - 12.0),
                num(c.x - w / 2.0 + 6.0),
                num(c.y - BOX_H / 2.0 + 1.0),
            );
        }
        out.push_str("</g>\n");
    }
    (width, height, out)
}

/// An axis-aligned box: `(x0, y0)` top left, `(x1, y1)` bottom right.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn around(c: P, w: f64, h: f64) -> Rect {
        Rect {
            x0: c.x - w / 2.0,
            y0: c.y - h / 2.0,
            x1: c.x + w / 2.0,
            y1: c.y + h / 2.0,
        }
    }

    fn grow(self, by: f64) -> Rect {
        Rect {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }

    fn shifted(self, dy: f64) -> Rect {
        Rect {
            y0: self.y0 + dy,
            y1: self.y1 + dy,
            ..self
        }
    }

    fn overlaps(&self, other: &Rect) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }
}

/// A change drawn: its path, and the points along it where its label may
/// sit, best first.
struct Route {
    path: String,
    label_spots: Vec<P>,
}

/// Where each arrow leaves and enters its boxes. The arrows at one side of
/// a box get ports of their own, spread over the side in the order of where
/// they come from, so arrowheads never stack and arrows do not cross at the
/// box.
fn routes(
    machine: &ModeMachine,
    chains: &[Option<layered::Chain>],
    centre: &[P],
    width_of: &dyn Fn(usize) -> f64,
) -> Vec<Route> {
    // Each chain's points, tail first, and whether it runs against the flow.
    let lines: Vec<Option<(Vec<usize>, bool)>> = chains
        .iter()
        .map(|chain| {
            chain.as_ref().map(|chain| {
                let mut nodes = chain.nodes.clone();
                if chain.reversed {
                    nodes.reverse();
                }
                (nodes, chain.reversed)
            })
        })
        .collect();
    // Ports per (box, side): (order key, change, is the tail).
    let mut ports: Vec<((usize, bool), f64, usize, bool)> = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some((nodes, bowed)) = line else { continue };
        let k = nodes.len() - 1;
        let rightward = centre[nodes[k]].x >= centre[nodes[0]].x;
        let lower = if *bowed { 2.0 * BOW } else { 0.0 };
        ports.push(((nodes[0], rightward), centre[nodes[1]].y + lower, i, true));
        ports.push((
            (nodes[k], !rightward),
            centre[nodes[k - 1]].y + lower,
            i,
            false,
        ));
    }
    ports.sort_by(|a, b| {
        (a.0.cmp(&b.0))
            .then(a.1.total_cmp(&b.1))
            .then(a.2.cmp(&b.2))
            .then(a.3.cmp(&b.3))
    });
    let mut offset = vec![(0.0, 0.0); lines.len()];
    for group in ports.chunk_by(|a, b| a.0 == b.0) {
        let room = BOX_H - 10.0;
        for (j, &(_, _, change, tail)) in group.iter().enumerate() {
            let dy = room * ((j as f64 + 0.5) / group.len() as f64 - 0.5);
            if tail {
                offset[change].0 = dy;
            } else {
                offset[change].1 = dy;
            }
        }
    }

    let mut out = Vec::with_capacity(lines.len());
    for (i, (change, line)) in machine.changes.iter().zip(&lines).enumerate() {
        let Some((nodes, bowed)) = line else {
            out.push(self_loop(centre[change.from]));
            continue;
        };
        let mut pts: Vec<P> = nodes.iter().map(|&v| centre[v]).collect();
        let k = pts.len() - 1;
        let dir = if pts[k].x >= pts[0].x { 1.0 } else { -1.0 };
        pts[0].x += dir * width_of(nodes[0]) / 2.0;
        pts[0].y += offset[i].0;
        pts[k].x -= dir * width_of(nodes[k]) / 2.0;
        pts[k].y += offset[i].1;
        let bow = if *bowed { BOW } else { 0.0 };
        let mut d = format!("M{} {}", num(pts[0].x), num(pts[0].y));
        let mut spots = Vec::new();
        for pair in pts.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let c = P {
                x: (a.x + b.x) / 2.0,
                y: (a.y + b.y) / 2.0 + 2.0 * bow,
            };
            let _ = write!(d, " Q{} {} {} {}", num(c.x), num(c.y), num(b.x), num(b.y));
            for t in [0.5, 0.35, 0.65, 0.2, 0.8] {
                let u = 1.0 - t;
                spots.push(P {
                    x: u * u * a.x + 2.0 * u * t * c.x + t * t * b.x,
                    y: u * u * a.y + 2.0 * u * t * c.y + t * t * b.y,
                });
            }
        }
        out.push(Route {
            path: d,
            label_spots: spots,
        });
    }
    out
}

/// A change from a mode to itself: a loop above its box.
fn self_loop(c: P) -> Route {
    let top = c.y - BOX_H / 2.0;
    Route {
        path: format!(
            "M{} {} C{} {} {} {} {} {}",
            num(c.x - 10.0),
            num(top),
            num(c.x - 30.0),
            num(top - 32.0),
            num(c.x + 30.0),
            num(top - 32.0),
            num(c.x + 10.0),
            num(top)
        ),
        label_spots: vec![P {
            x: c.x,
            y: top - 26.0,
        }],
    }
}

/// The label box of width `w` nearest the best spot that covers nothing in
/// `taken` and stays below the panel's title: just above or below a spot on
/// the arrow if one is free, else the first spot moved up or down.
fn place_label(spots: &[P], w: f64, taken: &[Rect]) -> Rect {
    const H: f64 = 13.0;
    let free = |r: &Rect| r.y0 >= 28.0 && r.x0 >= 2.0 && !taken.iter().any(|t| t.overlaps(r));
    let box_at = |p: P, dy: f64| Rect {
        x0: p.x - w / 2.0,
        y0: p.y + dy,
        x1: p.x + w / 2.0,
        y1: p.y + dy + H,
    };
    for &p in spots {
        for dy in [-H - 1.0, 2.0] {
            let r = box_at(p, dy);
            if free(&r) {
                return r;
            }
        }
    }
    let first = box_at(
        spots.first().copied().unwrap_or(P { x: w, y: 40.0 }),
        -H - 1.0,
    );
    (1..)
        .map(|step| {
            let reach = (step / 2 + 1) as f64 * (H + 2.0);
            first.shifted(if step % 2 == 1 { reach } else { -reach })
        })
        .find(free)
        .expect("a free place below everything exists")
}

/// An event label in `spot`, on a white ground so that it stays readable
/// over other arrows; greyed for a change that never fires.
fn write_label(out: &mut String, spot: Rect, label: &str, dead: bool) {
    let _ = write!(
        out,
        "<rect class=\"label\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fff\" fill-opacity=\"0.85\"/><text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" fill=\"{}\">{}</text>",
        num(spot.x0),
        num(spot.y0),
        num(spot.x1 - spot.x0),
        num(spot.y1 - spot.y0),
        num((spot.x0 + spot.x1) / 2.0),
        num(spot.y0 + 10.0),
        num(LABEL_FONT),
        if dead { "#999" } else { "#7a2e00" },
        escape(label)
    );
}

/// The SVG picture of `machines`, one panel per team stacked top to bottom;
/// a mission without modes gives a picture saying so.
pub fn to_svg(machines: &[ModeMachine]) -> String {
    let panels: Vec<(f64, f64, String)> = machines.iter().map(panel).collect();
    let width = panels.iter().map(|p| p.0).fold(
        text_width("This mission has no modes.", FONT) + 2.0 * MARGIN,
        f64::max,
    );
    let height = if panels.is_empty() {
        60.0
    } else {
        panels.iter().map(|p| p.1).sum::<f64>() + 10.0 * (panels.len() - 1) as f64
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"Helvetica, Arial, sans-serif\">",
        w = num(width),
        h = num(height)
    );
    out.push_str(
        "<defs><marker id=\"semo-mode-arrow\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"8\" markerHeight=\"8\" orient=\"auto-start-reverse\"><path d=\"M0 0 L10 5 L0 10 z\" fill=\"#333\"/></marker></defs>\n",
    );
    if panels.is_empty() {
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"34\" font-size=\"{}\" fill=\"#555\">This mission has no modes.</text>",
            num(MARGIN),
            num(FONT)
        );
    }
    let mut y = 0.0;
    for (machine, (_, h, body)) in machines.iter().zip(&panels) {
        let _ = writeln!(
            out,
            "<g class=\"team\" data-team=\"{}\" transform=\"translate(0 {})\">",
            escape(&machine.team),
            num(y)
        );
        out.push_str(body);
        out.push_str("</g>\n");
        y += h + 10.0;
    }
    out.push_str("</svg>\n");
    out
}
