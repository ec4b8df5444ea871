//! The outline of a strategy file: its values, and its services with their
//! actions.

use crate::ide::{StructureNode, SymbolKind};
use crate::span::Span;
use crate::strategy::model::{Named, Strategy, TargetRobot};

fn name_of(named: &Option<Named>, fallback: &str) -> (String, Option<Span>) {
    match named {
        Some(n) if !n.name.is_empty() => (n.name.clone(), Some(n.span)),
        _ => (fallback.to_string(), None),
    }
}

/// `for iRobotCreate, TIEvalbot`.
fn targets(targets: &[TargetRobot]) -> Option<String> {
    let names: Vec<&str> = targets
        .iter()
        .filter_map(|t| t.name.as_ref())
        .map(|n| n.name.as_str())
        .collect();
    (!names.is_empty()).then(|| format!("for {}", names.join(", ")))
}

pub fn document_symbols(strategy: &Strategy) -> Vec<StructureNode> {
    let mut out = Vec::new();
    for value in &strategy.values {
        let (name, span) = name_of(&value.name, "(value)");
        out.push(StructureNode {
            name,
            detail: targets(&value.targets),
            kind: SymbolKind::Value,
            span: value.span,
            name_span: span.unwrap_or(value.tag),
            children: Vec::new(),
        });
    }
    for service in &strategy.services {
        let (name, span) = name_of(&service.name, "(service)");
        let name = match &service.plan {
            Some(plan) => format!("{}.{name}", plan.name),
            None => name,
        };
        let actions = service
            .actions
            .iter()
            .map(|action| {
                let (name, span) = name_of(&action.name, "(action)");
                let mut detail: Vec<String> = Vec::new();
                if let Some(id) = action.id {
                    detail.push(id.value.to_string());
                }
                if action.initial.is_yes() {
                    detail.push("initial".to_string());
                }
                if action.is_final.is_yes() {
                    detail.push("final".to_string());
                }
                StructureNode {
                    name,
                    detail: (!detail.is_empty()).then(|| detail.join(", ")),
                    kind: SymbolKind::Action,
                    span: action.span,
                    name_span: span.unwrap_or(action.tag),
                    children: Vec::new(),
                }
            })
            .collect();
        out.push(StructureNode {
            name,
            detail: targets(&service.targets),
            kind: SymbolKind::Service,
            span: service.span,
            name_span: span.unwrap_or(service.tag),
            children: actions,
        });
    }
    out
}
