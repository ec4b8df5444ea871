//! Signature help: inside the parentheses of a call, the signature of the
//! built-in service (as the robots running the statement provide it) or of
//! the function, with the parameter at the cursor; also for the language's
//! own forms `set`, `send`/`receive`/`publish`/`subscribe`, `loop` and `repeat`.

use super::context::{self, Lt, Paren, Trivia};
use super::docs;
use super::robots::{self, RobotsHere};
use crate::catalog::Catalog;
use crate::sema::CheckedMission;
use crate::syntax::ast::CommKind;
use crate::syntax::token::Token;
use std::ops::Range;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SignatureHelp {
    /// `move(goal?: location)`.
    pub label: String,
    /// Markdown.
    pub documentation: Option<String>,
    /// Each parameter's byte range in `label`, with its documentation.
    pub parameters: Vec<(Range<usize>, Option<String>)>,
    /// The parameter at the cursor; `None` when there is none (past the last).
    pub active_parameter: Option<usize>,
}

/// The signature of the call whose parentheses hold `offset`.
pub fn signature_help(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    offset: usize,
) -> Option<SignatureHelp> {
    let offset = offset.min(text.len());
    // Inside a string argument the call is still the one to show.
    if context::trivia_at(text, offset) == Trivia::Comment {
        return None;
    }
    let scan = context::scan(analysis, text, offset);
    // The innermost parentheses of a call or form; a nested `( ... )` in an
    // argument is part of that argument.
    let frame = scan
        .frames
        .iter()
        .rev()
        .take_while(|f| f.opener == Token::LParen)
        .find(|f| f.paren.as_ref().is_some_and(|p| *p != Paren::Expr))?;
    let index = frame.argument_index();
    let help = match frame.paren.as_ref()? {
        Paren::Call { name, .. } => {
            if let Some(f) = analysis.mission.functions.iter().find(|f| f.name == *name) {
                let doc = match f.params.is_empty() {
                    true => "A function: it takes no arguments; its statements run here.",
                    false => {
                        "A function: its statements run here, each parameter standing for its argument."
                    }
                };
                // Each parameter with what its uses ask of the argument.
                let params = f
                    .params
                    .iter()
                    .map(|p| {
                        let asks: Vec<String> = p.needs.iter().map(docs::param_need).collect();
                        let doc = (!asks.is_empty()).then(|| asks.join("; "));
                        (p.name.to_string(), doc)
                    })
                    .collect();
                return Some(build(&f.name, params, Some(doc.to_string()), index));
            }
            if let Some(help) = parameterised(analysis, scan.head.team(), name, index) {
                return Some(help);
            }
            let here = RobotsHere::at(analysis, offset, scan.head.team().map(|t| t.as_str()));
            let types = here.types(&analysis.mission);
            let def = types
                .iter()
                .chain(&robots::service_providers(catalog, name))
                .find_map(|ty| catalog.get(*ty).service(name))?;
            let params = def
                .params
                .iter()
                .map(|p| {
                    let optional = if p.optional { "?" } else { "" };
                    let label = format!("{}{optional}: {}", p.name, p.ty);
                    (label, p.optional.then(|| "Optional.".to_string()))
                })
                .collect();
            let doc = (!def.doc.is_empty()).then(|| def.doc.clone());
            build(&def.name, params, doc, index)
        }
        Paren::Set => build(
            "set",
            vec![
                ("plan".to_string(), Some("A plan of the team.".to_string())),
                (
                    "service | OFF".to_string(),
                    Some("A composite service of that plan, or `OFF`.".to_string()),
                ),
                (
                    "timeout = period".to_string(),
                    Some("Optional: the most time the service may take.".to_string()),
                ),
            ],
            Some("What a plan runs in this mode.".to_string()),
            index,
        ),
        Paren::Comm(kind) => {
            let (doc, value) = match kind {
                CommKind::Send => (
                    "Deliver values reliably to every robot of a team (or to USER).",
                    "value | Team.VARIABLE = expr, ...",
                ),
                CommKind::Receive => (
                    "Wait for values coming from a team (or from USER).",
                    "Team.VALUE, ...",
                ),
                CommKind::Publish => (
                    "Broadcast a value, best effort, to every robot of a team.",
                    "value | Team.VARIABLE = expr",
                ),
                CommKind::Subscribe => (
                    "Read, without waiting, the latest value published by a team.",
                    "Team.VALUE",
                ),
            };
            let params = vec![
                ("team".to_string(), Some("A team, or USER.".to_string())),
                (value.to_string(), None),
            ];
            // `send` and `receive` take any number of values after the team.
            let many = matches!(kind, CommKind::Send | CommKind::Receive);
            let index = if many { index.min(1) } else { index };
            build(kind.as_str(), params, Some(doc.to_string()), index)
        }
        paren @ (Paren::Loop | Paren::Repeat) => {
            let (name, doc) = match paren {
                Paren::Loop => (
                    "loop",
                    "Run the block every period, or while the condition holds, or both.",
                ),
                _ => (
                    "repeat",
                    "Run the service again every period, or while the condition holds, or both; `repeat()` runs it forever.",
                ),
            };
            let params = vec![
                ("period?".to_string(), Some("Such as `2 SEC`.".to_string())),
                ("condition?".to_string(), None),
            ];
            // A single argument that is not a period is the condition.
            let index = match (index, frame.level.first()) {
                (0, None | Some(Lt::Tok(Token::Number(_), _))) => 0,
                (0, _) => 1,
                (i, _) => i,
            };
            build(name, params, Some(doc.to_string()), index)
        }
        _ => return None,
    };
    Some(help)
}

/// `name(p1, p2)` with each parameter's range in the label.
/// `MOVE(TARGET)` after `mode =`, `Go(PLACE)` in `set`: a mode or a
/// composite service with parameters of the item's team, each parameter
/// with what its uses ask of the argument.
fn parameterised(
    analysis: &CheckedMission,
    team: Option<&crate::syntax::ast::Name>,
    name: &str,
    index: usize,
) -> Option<SignatureHelp> {
    use crate::sema::ParamOwner;
    let mission = &analysis.mission;
    let id = mission.team_by_name(team?)?;
    let t = mission.team(id);
    let (owner, doc) = match t.template_by_name(name) {
        Some(template) => (
            ParamOwner::Mode(id, template),
            "A mode with parameters: each list of fixed arguments is a mode of its own.",
        ),
        None => {
            let service = t
                .service_ids()
                .find(|s| t.service(*s).name == name && !t.service(*s).params.is_empty())?;
            (
                ParamOwner::Service(id, service),
                "A composite service with parameters: it runs with each parameter standing for its fixed argument.",
            )
        }
    };
    let params = mission
        .params(owner)
        .iter()
        .map(|p| {
            let asks: Vec<String> = p.needs.iter().map(docs::param_need).collect();
            (
                p.name.to_string(),
                (!asks.is_empty()).then(|| asks.join("; ")),
            )
        })
        .collect();
    Some(build(name, params, Some(doc.to_string()), index))
}

fn build(
    name: &str,
    params: Vec<(String, Option<String>)>,
    documentation: Option<String>,
    index: usize,
) -> SignatureHelp {
    let mut label = format!("{name}(");
    let mut parameters = Vec::new();
    for (i, (p, doc)) in params.into_iter().enumerate() {
        if i > 0 {
            label.push_str(", ");
        }
        let start = label.len();
        label.push_str(&p);
        parameters.push((start..label.len(), doc));
    }
    label.push(')');
    let active_parameter = (index < parameters.len()).then_some(index);
    SignatureHelp {
        label,
        documentation,
        parameters,
        active_parameter,
    }
}
