//! Task graphs (extended SDF, SDF/L): the model, its loaders, and its analyses.

pub mod analysis;
pub mod dot;
pub mod model;
mod xml;

pub use model::*;
pub use xml::{GraphFormat, detect_format, load_task_graph};
