//! Task graphs (extended SDF, SDF/L): the model, its loaders, and its analyses.

pub mod analysis;
pub mod dot;
pub mod model;
pub mod subgraph;
pub mod svg;
mod xml;

#[cfg(test)]
mod tests;
pub mod write;

pub use model::*;
pub use svg::{to_svg, to_svg_analyzed};
pub use xml::{
    ExecutionTimes, GraphFormat, SDF3_VOCABULARY, SEMO_VOCABULARY, detect_format, load_task_graph,
    load_task_graph_as,
};

/// Follows the references of `graph` (read from `location`) to its
/// sub-graphs, each usable only when its own analysis finds no error.
pub fn resolve(
    graph: &TaskGraph,
    location: Option<&std::path::Path>,
    resolver: &mut dyn subgraph::Resolver,
) -> subgraph::Hierarchy {
    let check = |child: &TaskGraph, nested: &subgraph::Hierarchy| {
        analysis::analyze_with(child, nested).diagnostics
    };
    subgraph::resolve_checked(graph, location, resolver, &check)
}
