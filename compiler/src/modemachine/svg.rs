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
    let width = (x - gap.last().copied().unwrap_or(0.0) + MARGIN)
        .max(text_width(&format!("{} modes", machine.team), FONT) + 2.0 * MARGIN);
    let tallest = layers.layers.iter().map(Vec::len).max().unwrap_or(0) as f64;
    let height = HEAD + tallest * SLOT + MARGIN;
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

    let mut out = String::new();
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"22\" font-size=\"{}\" font-weight=\"bold\" fill=\"#333\">{} modes</text>",
        num(MARGIN),
        num(FONT),
        escape(&machine.team)
    );
    for (change, chain) in machine.changes.iter().zip(&layers.chains) {
        let label = label_of(&change.events);
        let _ = write!(
            out,
            "<g class=\"change\" data-from=\"{}\" data-to=\"{}\">",
            escape(&machine.modes[change.from]),
            escape(&machine.modes[change.to])
        );
        match chain {
            None => self_loop(&mut out, centre[change.from], &label),
            Some(chain) => {
                let mut points: Vec<P> = chain.nodes.iter().map(|&v| centre[v]).collect();
                if chain.reversed {
                    points.reverse();
                }
                let mut ends = chain.nodes.clone();
                if chain.reversed {
                    ends.reverse();
                }
                let widths: Vec<f64> = ends.iter().map(|&v| width_of(v)).collect();
                arrow(&mut out, &points, &widths, chain.reversed, &label);
            }
        }
        out.push_str("</g>\n");
    }
    for (v, name) in machine.modes.iter().enumerate() {
        let c = centre[v];
        let w = width_of(v);
        let is_default = machine.default == Some(v);
        let _ = write!(
            out,
            "<g class=\"mode{}\" data-mode=\"{}\"><title>{}{}</title>",
            if is_default { " default" } else { "" },
            escape(name),
            escape(name),
            if is_default {
                " (default: the team starts here)"
            } else {
                ""
            }
        );
        let _ = write!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"12\" fill=\"#e8f0fe\" stroke=\"#1a4d8f\" stroke-width=\"{}\"/>",
            num(c.x - w / 2.0),
            num(c.y - BOX_H / 2.0),
            num(w),
            num(BOX_H),
            if is_default { "2.6" } else { "1.2" }
        );
        let _ = write!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" fill=\"#111\"{}>{}</text>",
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

/// A change between different modes along `points` (tail first); `widths`
/// are the widths of the boxes at those points, so that the arrow starts and
/// ends at the boxes' sides.
fn arrow(out: &mut String, points: &[P], widths: &[f64], bowed: bool, label: &str) {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return;
    };
    if points.len() < 2 || widths.len() != points.len() {
        return;
    }
    let mut pts = points.to_vec();
    let dir = if last.x >= first.x { 1.0 } else { -1.0 };
    let k = pts.len() - 1;
    pts[0].x += dir * widths[0] / 2.0;
    pts[k].x -= dir * widths[k] / 2.0;
    let bow = if bowed { BOW } else { 0.0 };
    if bowed {
        // Leave and enter the boxes lower, clear of the forward arrow.
        pts[0].y += 7.0;
        pts[k].y += 7.0;
    }
    let mut d = format!("M{} {}", num(pts[0].x), num(pts[0].y));
    for pair in pts.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let _ = write!(
            d,
            " Q{} {} {} {}",
            num((a.x + b.x) / 2.0),
            num((a.y + b.y) / 2.0 + 2.0 * bow),
            num(b.x),
            num(b.y)
        );
    }
    let _ = write!(
        out,
        "<path d=\"{d}\" fill=\"none\" stroke=\"#333\" stroke-width=\"1.2\" marker-end=\"url(#semo-mode-arrow)\"/>"
    );
    // The label on the first segment's midpoint (on the bow's apex).
    let (a, b) = (pts[0], pts[1]);
    let at = P {
        x: (a.x + b.x) / 2.0,
        y: (a.y + b.y) / 2.0 + bow,
    };
    write_label(out, at, label, bowed);
}

fn self_loop(out: &mut String, c: P, label: &str) {
    let top = c.y - BOX_H / 2.0;
    let _ = write!(
        out,
        "<path d=\"M{} {} C{} {} {} {} {} {}\" fill=\"none\" stroke=\"#333\" stroke-width=\"1.2\" marker-end=\"url(#semo-mode-arrow)\"/>",
        num(c.x - 10.0),
        num(top),
        num(c.x - 30.0),
        num(top - 32.0),
        num(c.x + 30.0),
        num(top - 32.0),
        num(c.x + 10.0),
        num(top)
    );
    write_label(
        out,
        P {
            x: c.x,
            y: top - 30.0,
        },
        label,
        false,
    );
}

/// An event label centred on `at`, on a white ground so that it stays
/// readable over other arrows; below the point when `below`.
fn write_label(out: &mut String, at: P, label: &str, below: bool) {
    let w = text_width(label, LABEL_FONT) + 6.0;
    let y = if below { at.y + 8.0 } else { at.y - 4.0 };
    let _ = write!(
        out,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"13\" fill=\"#fff\" fill-opacity=\"0.85\"/><text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" fill=\"#7a2e00\">{}</text>",
        num(at.x - w / 2.0),
        num(y - 10.0),
        num(w),
        num(at.x),
        num(y),
        num(LABEL_FONT),
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
