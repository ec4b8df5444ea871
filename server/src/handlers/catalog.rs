//! `semo/catalog`: the robot types a document (or the workspace) sees, with
//! their services and values, for the editor's robot panel.

use semo::catalog::{Catalog, RobotType};
use serde::Deserialize;
use serde_json::{Value, json};
use tower_lsp_server::ls_types::Uri;

#[derive(Debug, Default, Deserialize)]
pub struct CatalogParams {
    /// The document whose catalog is wanted; the workspace's when absent.
    #[serde(default)]
    pub uri: Option<Uri>,
}

pub fn catalog(catalog: &Catalog) -> Value {
    let robots: Vec<Value> = catalog.types().map(|(_, r)| robot(r)).collect();
    json!({
        "robots": robots,
        "user": catalog.user().map(robot),
    })
}

/// One robot type (or the operator console) as `semo/catalog` gives it;
/// `semo catalog --format json` gives the same shape.
pub fn robot(r: &RobotType) -> Value {
    json!({
        "name": r.name,
        "aliases": r.aliases,
        "doc": r.doc,
        "capabilities": r.capabilities,
        "services": r.services.iter().map(|s| json!({
            "name": s.name,
            "signature": s.signature(),
            "params": s.params.iter().map(|p| json!({
                "name": p.name,
                "type": p.ty.to_string(),
                "optional": p.optional,
            })).collect::<Vec<_>>(),
            "results": s.results.iter().map(|r| json!({
                "name": r.name,
                "type": r.ty.to_string(),
                "doc": r.doc,
            })).collect::<Vec<_>>(),
            "doc": s.doc,
        })).collect::<Vec<_>>(),
        "values": r.values.iter().map(|v| json!({
            "name": v.name,
            "type": v.ty.to_string(),
            "unit": v.unit,
            "doc": v.doc,
        })).collect::<Vec<_>>(),
    })
}
