//! Task graphs (extended SDF, SDF/L): the model, its loaders, and its analyses.

pub mod analysis;
pub mod dot;
pub mod model;
pub mod subgraph;
pub mod svg;
mod xml;

pub mod write;
pub use model::*;
pub use svg::{to_svg, to_svg_analyzed};
pub use xml::{ExecutionTimes, GraphFormat, detect_format, load_task_graph, load_task_graph_as};
