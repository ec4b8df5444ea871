//! A picture of a task graph in SVG, drawn by our own layered layout (no
//! Graphviz): the same content as [`super::dot`] — tasks as boxes (control
//! tasks bold, library tasks and libraries as components, multicast groups as
//! notes), loop nodes as labelled clusters holding their inner graphs, channels
//! with the production rate at the tail, the consumption rate at the head and
//! initial samples (●) in the middle, library calls dashed, multicast dotted.
//!
//! The pipeline: [`scene`] turns the model into levels of drawable nodes and
//! edges (a loop body is a level inside a cluster node; its ports sit on the
//! cluster's border), [`crate::layout::layered`] ranks and orders the nodes of one level
//! (Sugiyama: cycle breaking, longest-path layers, virtual nodes, barycenter
//! sweeps), [`place`] gives coordinates and routes edges (inner levels first,
//! so a cluster is one big node outside), and [`render`] writes the SVG.
//! Data flows left to right, as in the DOT output (`rankdir=LR`).
//!
//! Text widths are estimated from the characters ([`crate::layout::text_width`], no font metrics), numbers
//! are written with one decimal, and nothing depends on hash order: the same
//! graph always gives the same bytes.

mod place;
mod render;
mod scene;
#[cfg(test)]
mod tests;

use super::analysis::GraphReport;
use super::model::TaskGraph;

/// The SVG picture of `graph`: a standalone document (`xmlns`, `viewBox`).
/// Accepts any graph the loader returns, including ones with errors (a
/// channel end naming no task is drawn as a dashed placeholder).
pub fn to_svg(graph: &TaskGraph) -> String {
    draw(graph, None)
}

/// [`to_svg`] with what the analysis of `graph` found marked: the tasks and
/// channels of a cycle that deadlocks are drawn in red (class `deadlock`).
pub fn to_svg_analyzed(graph: &TaskGraph, report: &GraphReport) -> String {
    draw(graph, Some(report))
}

fn draw(graph: &TaskGraph, report: Option<&GraphReport>) -> String {
    let scene = scene::build(graph, report);
    let placed = place::layout(&scene);
    render::svg(&graph.name, &scene, &placed)
}

/// Font sizes (px) of the picture's texts.
const NODE_FONT: f64 = 12.0;
const DETAIL_FONT: f64 = 10.0;
const LABEL_FONT: f64 = 10.0;
const PORT_FONT: f64 = 9.0;
const TITLE_FONT: f64 = 12.0;
