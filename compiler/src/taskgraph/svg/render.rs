//! Writing the laid-out scene as SVG: cluster backgrounds first (outer ones
//! under inner ones), then every edge with its labels, then every node on top.
//! Elements carry `class` and `data-path` (`data-from`/`data-to` for edges)
//! so that tools and tests can find them; every node has a `<title>` shown on
//! hover.

use super::place::{Anchor, Label, Placed, Route, Seg};
use super::scene::{End, Level, Shape, Side, Style};
use super::{LABEL_FONT, NODE_FONT, PORT_FONT, TITLE_FONT};
use crate::layout::text_width;
use crate::xmlpos::escape;
use std::fmt::Write;

/// Cluster fills by nesting depth.
const CLUSTER_FILLS: [&str; 3] = ["#f4f4f4", "#e9e9e9", "#dedede"];

pub(super) fn svg(name: &str, root: &Level, placed: &Placed) -> String {
    let mut bounds = Bounds {
        min_x: 0.0,
        min_y: 0.0,
        max_x: placed.width,
        max_y: placed.height,
    };
    bounds.level(root, placed, 0.0, 0.0);
    let (x0, y0) = (bounds.min_x.floor(), bounds.min_y.floor());
    let (w, h) = (
        (bounds.max_x - x0).ceil().max(1.0),
        (bounds.max_y - y0).ceil().max(1.0),
    );
    let mut out = String::with_capacity(4096);
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"{} {} {} {}\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"{}\">",
        num(w),
        num(h),
        num(x0),
        num(y0),
        num(w),
        num(h),
        num(NODE_FONT)
    );
    let _ = writeln!(out, "<title>{}</title>", escape(name));
    out.push_str(concat!(
        "<defs>\n",
        "<marker id=\"semo-arrow\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" orient=\"auto\"><path d=\"M0,1L10,5L0,9z\" fill=\"#333\"/></marker>\n",
        "<marker id=\"semo-odot\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" orient=\"auto\"><circle cx=\"5\" cy=\"5\" r=\"4\" fill=\"#fff\" stroke=\"#2e7d32\" stroke-width=\"1.5\"/></marker>\n",
        "<marker id=\"semo-open\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" orient=\"auto\"><path d=\"M1,1L10,5L1,9\" fill=\"none\" stroke=\"#7b1fa2\" stroke-width=\"1.5\"/></marker>\n",
    ));
    if has_deadlock(root) {
        out.push_str("<marker id=\"semo-arrow-deadlock\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"6\" markerHeight=\"6\" orient=\"auto\"><path d=\"M0,1L10,5L0,9z\" fill=\"#c62828\"/></marker>\n");
    }
    out.push_str("</defs>\n");
    let _ = writeln!(
        out,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fff\"/>",
        num(x0),
        num(y0),
        num(w),
        num(h)
    );
    let mut writer = Writer { out };
    writer.clusters(root, placed, 0.0, 0.0, 0);
    writer.edges(root, placed, 0.0, 0.0);
    writer.nodes(root, placed, 0.0, 0.0);
    writer.out.push_str("</svg>\n");
    writer.out
}

struct Writer {
    out: String,
}

impl Writer {
    fn clusters(&mut self, level: &Level, placed: &Placed, ox: f64, oy: f64, depth: usize) {
        for (v, node) in level.nodes.iter().enumerate() {
            let (Some(body), Some(Some(inner))) = (&node.cluster, placed.inner.get(v)) else {
                continue;
            };
            let b = placed.boxes[v];
            let (x, y) = (ox + b.x, oy + b.y);
            let _ = write!(
                self.out,
                "<g class=\"cluster\" data-path=\"{}\"><title>{}</title>",
                escape(&node.path),
                escape(&node.tooltip)
            );
            let _ = write!(
                self.out,
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"10\" fill=\"{}\" stroke=\"#888\" stroke-width=\"1.2\"/>",
                num(x),
                num(y),
                num(b.w),
                num(b.h),
                CLUSTER_FILLS[depth % CLUSTER_FILLS.len()]
            );
            let title = node.lines.first().map_or("", String::as_str);
            let _ = writeln!(
                self.out,
                "<text x=\"{}\" y=\"{}\" font-size=\"{}\" font-weight=\"bold\" fill=\"#333\">{}</text></g>",
                num(x + 10.0),
                num(y + 18.0),
                num(TITLE_FONT),
                escape(title)
            );
            self.clusters(body, inner, x, y, depth + 1);
        }
    }

    fn edges(&mut self, level: &Level, placed: &Placed, ox: f64, oy: f64) {
        for (v, node) in level.nodes.iter().enumerate() {
            if let (Some(body), Some(Some(inner))) = (&node.cluster, placed.inner.get(v)) {
                let b = placed.boxes[v];
                self.edges(body, inner, ox + b.x, oy + b.y);
            }
        }
        for (e, (edge, route)) in level.edges.iter().zip(&placed.routes).enumerate() {
            let deadlocked = level.deadlocked_edges.contains(&e);
            let (class, stroke) = match edge.style {
                Style::Data if deadlocked => {
                    ("data deadlock", "stroke=\"#c62828\" stroke-width=\"2.4\"")
                }
                Style::Data => ("data", "stroke=\"#333\" stroke-width=\"1.2\""),
                Style::Call => (
                    "call",
                    "stroke=\"#2e7d32\" stroke-width=\"1.2\" stroke-dasharray=\"5,3\"",
                ),
                Style::Serve => (
                    "serve",
                    "stroke=\"#2e7d32\" stroke-width=\"1.2\" stroke-dasharray=\"5,3\"",
                ),
                Style::Multicast => (
                    "multicast",
                    "stroke=\"#7b1fa2\" stroke-width=\"1.2\" stroke-dasharray=\"2,3\"",
                ),
            };
            // A library or multicast connection ends with its marker only
            // where it reaches its library or group, not at a relay.
            let marker = match edge.style {
                _ if edge.style != Style::Data && is_relay(level, edge.to) => "",
                Style::Data if deadlocked => " marker-end=\"url(#semo-arrow-deadlock)\"",
                Style::Data => " marker-end=\"url(#semo-arrow)\"",
                Style::Call => " marker-end=\"url(#semo-odot)\"",
                Style::Serve => "",
                Style::Multicast => " marker-end=\"url(#semo-open)\"",
            };
            let _ = write!(
                self.out,
                "<g class=\"edge {class}\" data-from=\"{}\" data-to=\"{}\"><path d=\"{}\" fill=\"none\" {stroke}{marker}/>",
                escape(end_path(level, edge.from)),
                escape(end_path(level, edge.to)),
                path_data(route, ox, oy)
            );
            if deadlocked {
                self.out.push_str(
                    "<title>a channel of a deadlocked cycle: too few initial samples for one iteration</title>",
                );
            }
            for label in [&route.tail, &route.head].into_iter().flatten() {
                self.label(label, ox, oy, false);
            }
            if let Some(label) = &route.mid {
                self.label(label, ox, oy, edge.style == Style::Data);
            }
            self.out.push_str("</g>\n");
        }
    }

    fn label(&mut self, label: &Label, ox: f64, oy: f64, strong: bool) {
        let anchor = match label.anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let (fill, weight) = if strong {
            ("#000", " font-weight=\"bold\"")
        } else {
            ("#555", "")
        };
        let _ = write!(
            self.out,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"{anchor}\" font-size=\"{}\" fill=\"{fill}\"{weight} stroke=\"#fff\" stroke-width=\"3\" stroke-linejoin=\"round\" paint-order=\"stroke\">{}</text>",
            num(ox + label.at.x),
            num(oy + label.at.y),
            num(LABEL_FONT),
            escape(&label.text)
        );
    }

    fn nodes(&mut self, level: &Level, placed: &Placed, ox: f64, oy: f64) {
        for (v, node) in level.nodes.iter().enumerate() {
            let b = placed.boxes[v];
            let (x, y, w, h) = (ox + b.x, oy + b.y, b.w, b.h);
            let path = escape(&node.path);
            let tooltip = escape(&node.tooltip);
            let style = match node.shape {
                Shape::Cluster => {
                    if let (Some(body), Some(Some(inner))) = (&node.cluster, placed.inner.get(v)) {
                        self.nodes(body, inner, x, y);
                    }
                    continue;
                }
                Shape::Port => {
                    let (tx, anchor) = match node.side {
                        Some(Side::Right) => (x - 6.0, "end"),
                        _ => (x + 6.0, "start"),
                    };
                    let name = node.lines.first().map_or("", String::as_str);
                    let _ = writeln!(
                        self.out,
                        "<g class=\"port\" data-path=\"{path}\"><title>{tooltip}</title><circle cx=\"{}\" cy=\"{}\" r=\"3.5\" fill=\"#fff\" stroke=\"#333\" stroke-width=\"1.2\"/><text x=\"{}\" y=\"{}\" text-anchor=\"{anchor}\" font-size=\"{}\" fill=\"#555\">{}</text></g>",
                        num(x),
                        num(y),
                        num(tx),
                        num(y + 13.0),
                        num(PORT_FONT),
                        escape(name)
                    );
                    continue;
                }
                Shape::Relay => {
                    let _ = writeln!(
                        self.out,
                        "<g class=\"relay\" data-path=\"{path}\"><title>{tooltip}</title><circle cx=\"{}\" cy=\"{}\" r=\"2\" fill=\"#777\"/></g>",
                        num(x),
                        num(y)
                    );
                    continue;
                }
                Shape::Task => (
                    "task",
                    "fill=\"#e8f1fb\" stroke=\"#2b5d8a\" stroke-width=\"1.2\"",
                ),
                Shape::Control => (
                    "control",
                    "fill=\"#fff3d6\" stroke=\"#8a6d2b\" stroke-width=\"2.6\"",
                ),
                Shape::LibraryTask => (
                    "library-task",
                    "fill=\"#e9f5e9\" stroke=\"#2e7d32\" stroke-width=\"1.2\"",
                ),
                Shape::Library => (
                    "library",
                    "fill=\"#e9f5e9\" stroke=\"#2e7d32\" stroke-width=\"1.2\"",
                ),
                Shape::Group => (
                    "multicast",
                    "fill=\"#f5ecf8\" stroke=\"#7b1fa2\" stroke-width=\"1.2\"",
                ),
                Shape::Missing => (
                    "missing",
                    "fill=\"#fdecea\" stroke=\"#c62828\" stroke-width=\"1.2\" stroke-dasharray=\"4,3\"",
                ),
            };
            let (class, paint) = style;
            let (class, paint, tooltip) = if level.deadlocked_nodes.contains(&v) {
                // The node's own fill, a red border.
                let fill = paint.split(" stroke=").next().unwrap_or(paint);
                (
                    format!("{class} deadlock"),
                    format!("{fill} stroke=\"#c62828\" stroke-width=\"2.6\""),
                    format!("{tooltip} (in a deadlocked cycle)"),
                )
            } else {
                (class.to_string(), paint.to_string(), tooltip.to_string())
            };
            let _ = write!(
                self.out,
                "<g class=\"node {class}\" data-path=\"{path}\"><title>{tooltip}</title><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"4\" {paint}/>",
                num(x),
                num(y),
                num(w),
                num(h)
            );
            match node.shape {
                // A component: two tabs on the left side.
                Shape::Library | Shape::LibraryTask => {
                    for ty in [y + h * 0.3 - 3.5, y + h * 0.7 - 3.5] {
                        let _ = write!(
                            self.out,
                            "<rect x=\"{}\" y=\"{}\" width=\"10\" height=\"7\" {paint}/>",
                            num(x - 5.0),
                            num(ty)
                        );
                    }
                }
                // A note: the top right corner folded.
                Shape::Group => {
                    let _ = write!(
                        self.out,
                        "<path d=\"M{},{}L{},{}L{},{}z\" fill=\"#fff\" stroke=\"none\"/><path d=\"M{},{}L{},{}L{},{}z\" {paint}/>",
                        num(x + w - 10.0),
                        num(y - 1.0),
                        num(x + w + 1.0),
                        num(y - 1.0),
                        num(x + w + 1.0),
                        num(y + 10.0),
                        num(x + w - 10.0),
                        num(y),
                        num(x + w - 10.0),
                        num(y + 10.0),
                        num(x + w),
                        num(y + 10.0)
                    );
                }
                _ => {}
            }
            let cx = x + w / 2.0;
            let cy = y + h / 2.0;
            let weight = if node.shape == Shape::Control {
                " font-weight=\"bold\""
            } else {
                ""
            };
            let name = node.lines.first().map_or("", String::as_str);
            match node.lines.get(1) {
                Some(detail) => {
                    let _ = write!(
                        self.out,
                        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\"{weight}>{}</text><text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"{}\" fill=\"#555\">{}</text>",
                        num(cx),
                        num(cy - 3.0),
                        escape(name),
                        num(cx),
                        num(cy + 11.0),
                        num(super::DETAIL_FONT),
                        escape(detail)
                    );
                }
                None => {
                    let _ = write!(
                        self.out,
                        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\"{weight}>{}</text>",
                        num(cx),
                        num(cy + 4.0),
                        escape(name)
                    );
                }
            }
            self.out.push_str("</g>\n");
        }
    }
}

/// The `data-path` of what an edge end attaches to (a cluster's port or relay,
/// or the node itself).
/// Whether `level` or a loop body inside it has a deadlocked channel, so
/// that its arrowhead is defined only in pictures that use it.
fn has_deadlock(level: &Level) -> bool {
    !level.deadlocked_edges.is_empty()
        || level
            .nodes
            .iter()
            .filter_map(|n| n.cluster.as_deref())
            .any(has_deadlock)
}

fn end_path(level: &Level, end: End) -> &str {
    let node = &level.nodes[end.node];
    match (end.port, &node.cluster) {
        (Some(p), Some(body)) => body.nodes.get(p).map_or(&node.path, |n| &n.path),
        _ => &node.path,
    }
}

fn is_relay(level: &Level, end: End) -> bool {
    let node = &level.nodes[end.node];
    match (end.port, &node.cluster) {
        (Some(p), Some(body)) => body.nodes.get(p).is_some_and(|n| n.shape == Shape::Relay),
        _ => node.shape == Shape::Relay,
    }
}

fn path_data(route: &Route, ox: f64, oy: f64) -> String {
    let mut d = String::new();
    let pt = |d: &mut String, q: super::place::P| {
        let _ = write!(d, "{},{}", num(ox + q.x), num(oy + q.y));
    };
    d.push('M');
    pt(&mut d, route.start);
    for seg in &route.segs {
        match *seg {
            Seg::Line(e) => {
                d.push('L');
                pt(&mut d, e);
            }
            Seg::Cubic(a, b, e) => {
                d.push('C');
                pt(&mut d, a);
                d.push(' ');
                pt(&mut d, b);
                d.push(' ');
                pt(&mut d, e);
            }
        }
    }
    d
}

/// Everything drawn, so that the view box holds labels that stick out.
struct Bounds {
    min_x: f64,
    min_y: f64,
    max_x: f64,
    max_y: f64,
}

impl Bounds {
    fn add(&mut self, x: f64, y: f64) {
        if x.is_finite() && y.is_finite() {
            self.min_x = self.min_x.min(x);
            self.min_y = self.min_y.min(y);
            self.max_x = self.max_x.max(x);
            self.max_y = self.max_y.max(y);
        }
    }

    fn level(&mut self, level: &Level, placed: &Placed, ox: f64, oy: f64) {
        for (v, b) in placed.boxes.iter().enumerate() {
            self.add(ox + b.x - 6.0, oy + b.y - 4.0);
            self.add(ox + b.x + b.w + 4.0, oy + b.y + b.h + 16.0);
            if let (Some(body), Some(Some(inner))) = (
                level.nodes.get(v).and_then(|n| n.cluster.as_ref()),
                placed.inner.get(v),
            ) {
                self.level(body, inner, ox + b.x, oy + b.y);
            }
        }
        for route in &placed.routes {
            route.each_point(|q| {
                self.add(ox + q.x - 4.0, oy + q.y - 4.0);
                self.add(ox + q.x + 4.0, oy + q.y + 4.0);
            });
            for label in [&route.tail, &route.head, &route.mid].into_iter().flatten() {
                let w = text_width(&label.text, LABEL_FONT) + 3.0;
                let x = ox + label.at.x;
                let (left, right) = match label.anchor {
                    Anchor::Start => (x - 2.0, x + w),
                    Anchor::Middle => (x - w / 2.0, x + w / 2.0),
                    Anchor::End => (x - w, x + 2.0),
                };
                self.add(left, oy + label.at.y - LABEL_FONT - 2.0);
                self.add(right, oy + label.at.y + 4.0);
            }
        }
    }
}

/// A coordinate with at most one decimal (no `-0`, no exponent), written
/// without an intermediate string.
#[derive(Clone, Copy)]
struct Num(f64);

fn num(v: f64) -> Num {
    Num(v)
}

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let tenths = (self.0 * 10.0).round();
        // Far beyond any drawing; keeps the integer conversion exact.
        if !tenths.is_finite() || tenths.abs() > 1e17 {
            return f.write_str("0");
        }
        let tenths = tenths as i64;
        let sign = if tenths < 0 { "-" } else { "" };
        let (whole, tenth) = (tenths.abs() / 10, tenths.abs() % 10);
        match tenth {
            0 if whole == 0 => f.write_str("0"),
            0 => write!(f, "{sign}{whole}"),
            _ => write!(f, "{sign}{whole}.{tenth}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{escape, num};

    #[test]
    fn numbers_have_one_decimal_at_most() {
        let shown: Vec<String> = [0.0, -0.04, 1.0, 2.25, -3.96, 130.85, 1e20, f64::NAN]
            .iter()
            .map(|&v| num(v).to_string())
            .collect();
        assert_eq!(shown, ["0", "0", "1", "2.3", "-4", "130.9", "0", "0"]);
    }

    #[test]
    fn special_characters_are_escaped() {
        assert_eq!(
            escape("a<b>&\"c'\u{1}d\u{FFFF}é").to_string(),
            "a&lt;b&gt;&amp;&quot;c&apos;\u{FFFD}d\u{FFFD}é"
        );
    }
}
