//! A picture of a task graph in SVG, drawn by our own layered layout (no
//! Graphviz): the same content as [`super::dot`] — tasks as boxes (control
//! tasks bold, library tasks and libraries as components, multicast groups as
//! notes), loop nodes as labelled clusters holding their inner graphs, channels
//! with the production rate at the tail, the consumption rate at the head and
//! initial samples (●) in the middle, library calls dashed, multicast dotted.
//!
//! The pipeline: [`scene`] turns the model into levels of drawable nodes and
//! edges (a loop body is a level inside a cluster node; its ports sit on the
//! cluster's border), [`layered`] ranks and orders the nodes of one level
//! (Sugiyama: cycle breaking, longest-path layers, virtual nodes, barycenter
//! sweeps), [`place`] gives coordinates and routes edges (inner levels first,
//! so a cluster is one big node outside), and [`render`] writes the SVG.
//! Data flows left to right, as in the DOT output (`rankdir=LR`).
//!
//! Text widths are estimated from the characters (no font metrics), numbers
//! are written with one decimal, and nothing depends on hash order: the same
//! graph always gives the same bytes.

pub(crate) mod layered;
mod place;
mod render;
mod scene;
#[cfg(test)]
mod tests;

use super::model::TaskGraph;

/// The SVG picture of `graph`: a standalone document (`xmlns`, `viewBox`).
/// Accepts any graph the loader returns, including ones with errors (a
/// channel end naming no task is drawn as a dashed placeholder).
pub fn to_svg(graph: &TaskGraph) -> String {
    let scene = scene::build(graph);
    let placed = place::layout(&scene);
    render::svg(&graph.name, &scene, &placed)
}

/// Font sizes (px) of the picture's texts.
const NODE_FONT: f64 = 12.0;
const DETAIL_FONT: f64 = 10.0;
const LABEL_FONT: f64 = 10.0;
const PORT_FONT: f64 = 9.0;
const TITLE_FONT: f64 = 12.0;

/// An estimate of the width of `text` in Helvetica at `size` px: a width per
/// character class, erring on the wide side so that boxes hold their labels.
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    let ems: f64 = text
        .chars()
        .map(|c| match c {
            'i' | 'j' | 'l' | 'I' | '.' | ',' | ':' | ';' | '!' | '|' | '\'' => 0.3,
            ' ' | 'f' | 't' | 'r' | '(' | ')' | '[' | ']' | '/' | '-' => 0.4,
            'm' | 'w' | 'M' | 'W' | '@' => 0.88,
            'A'..='Z' => 0.7,
            c if c.is_ascii() => 0.58,
            c if is_wide(c) => 1.0,
            _ => 0.7,
        })
        .sum();
    ems * size
}

/// East Asian wide characters and emoji, drawn about one em wide.
fn is_wide(c: char) -> bool {
    matches!(c as u32,
        0x1100..=0x115F
        | 0x2E80..=0xA4CF
        | 0xAC00..=0xD7A3
        | 0xF900..=0xFAFF
        | 0xFE30..=0xFE4F
        | 0xFF00..=0xFF60
        | 0xFFE0..=0xFFE6
        | 0x1F300..=0x1FAFF
        | 0x20000..=0x3FFFD)
}
