//! Fixes for strategy files, each an edit after which the file checks
//! without the diagnostic it fixes:
//!
//! - E081 (a plain `<` in an attribute value), and malformed XML in a value
//!   with a plain `&`: escape the value's `<`, `>` and `&`;
//! - a did-you-mean (any code with a suggestion): write the suggestion, and
//!   for an element name also in its end tag.
//!
//! And for missions, [`create_entry`]: the `<Service>` entry for a built-in
//! call that the team's strategy file does not refine yet.

use super::raw::{matching_close, position_at};
use crate::catalog::Catalog;
use crate::diag::{Code, Diagnostic};
pub use crate::edit::CodeAction;
use crate::edit::TextEdit;
use crate::sema::CheckedMission;
use crate::span::Span;
use crate::strategy::model::Strategy;
use crate::strategy::{StrategyLinks, team_calls};

/// The fixes for the `diagnostics` of a strategy file (`text`) that touch `range`.
pub fn code_actions(text: &str, diagnostics: &[Diagnostic], range: Span) -> Vec<CodeAction> {
    let mut out = Vec::new();
    for (index, d) in diagnostics.iter().enumerate() {
        if d.span.end < range.start
            || d.span.start > range.end
            || text.get(d.span.range()).is_none()
        {
            continue;
        }
        if d.code == Code::StrategyRawLt {
            out.extend(escape_value(text, d.span.start, index));
            continue;
        }
        // Malformed XML inside a value with a plain `&`.
        if d.code == Code::StrategyXml
            && let Some(action) = escape_value(text, d.span.start, index)
            && text[d.span.start..]
                .split(['"', '\''])
                .next()
                .is_some_and(|v| v.contains('&'))
        {
            out.push(action);
            continue;
        }
        if let Some(suggestion) = &d.suggestion {
            out.push(did_you_mean(text, d, suggestion, index));
        }
    }
    out
}

/// `s` with `<`, `>` and every `&` that starts no entity escaped.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 8);
    for (i, c) in s.char_indices() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' if !starts_entity(&s[i..]) => out.push_str("&amp;"),
            c => out.push(c),
        }
    }
    out
}

/// Whether `s` (starting with `&`) starts `&name;` or `&#...;`.
fn starts_entity(s: &str) -> bool {
    let body = &s[1..];
    let Some(end) = body.find(';') else {
        return false;
    };
    let name = &body[..end];
    !name.is_empty()
        && (name.starts_with('#') && name[1..].chars().all(|c| c.is_ascii_alphanumeric())
            || name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
}

/// Escapes the attribute value holding `at`.
fn escape_value(text: &str, at: usize, diagnostic: usize) -> Option<CodeAction> {
    let tag = position_at(text, at + 1).tag?;
    let attr = tag
        .attrs
        .iter()
        .find(|a| a.closed && a.value_span.is_some_and(|v| v.contains(at)))?;
    let span = attr.value_span?;
    let value = &text[span.range()];
    let escaped = escape(value);
    if escaped == value {
        return None;
    }
    let raw: Vec<&str> = ["<", ">", "&"]
        .into_iter()
        .filter(|c| escape(c) != *c && value.contains(c))
        .collect();
    let title = match raw.as_slice() {
        ["<"] => format!("Write `<` as `&lt;` in `{}`", attr.name),
        _ => format!(
            "Escape {} in `{}`",
            raw.iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", "),
            attr.name
        ),
    };
    Some(CodeAction {
        title,
        diagnostic,
        edits: vec![TextEdit {
            span,
            new_text: escaped,
        }],
        preferred: true,
    })
}

fn did_you_mean(text: &str, d: &Diagnostic, suggestion: &str, index: usize) -> CodeAction {
    let mut edits = vec![TextEdit {
        span: d.span,
        new_text: suggestion.to_string(),
    }];
    // An element name: its end tag is renamed too.
    if d.code == Code::StrategyUnknownElement
        && let Some(start) = text[..d.span.start]
            .rfind('<')
            .filter(|&i| i + 1 == d.span.start)
        && let Some(close) = matching_close(text, start)
        && text[close.name_span.range()] == text[d.span.range()]
    {
        edits.push(TextEdit {
            span: close.name_span,
            new_text: suggestion.to_string(),
        });
    }
    CodeAction {
        title: format!("Change to `{suggestion}`"),
        diagnostic: index,
        edits,
        preferred: true,
    }
}

/// An edit of a strategy file, offered from a mission.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EntryEdit {
    pub title: String,
    pub edit: TextEdit,
}

/// For the built-in call at `offset` of `mission`, run by the team of
/// `strategy` and not refined by it (no link in `links`, the strategy's own):
/// a `<Service>` skeleton added to the strategy file (`text`), for the team's
/// robot types that provide the service. A single action, initial and final,
/// so that the new entry checks as it is.
pub fn create_entry(
    mission: &CheckedMission,
    catalog: &Catalog,
    offset: usize,
    strategy: &Strategy,
    text: &str,
    links: &StrategyLinks,
) -> Option<EntryEdit> {
    // Cheap refusal first (code actions are asked for at every cursor move):
    // the cursor must be on a built-in service's name.
    let on_builtin = crate::sema::lookup::at(&mission.mission, offset)
        .iter()
        .any(|o| matches!(o.symbol, crate::sema::Symbol::BuiltinService(_)));
    if !on_builtin {
        return None;
    }
    let team_name = &strategy.team.as_ref()?.name;
    let team_id = mission.mission.team_by_name(team_name)?;
    let team = mission.mission.team(team_id);
    let call = team_calls(mission, team_id)
        .into_iter()
        .find(|c| c.span.touches(offset))?;
    let file = mission.mission.file;
    if links
        .at(file, offset)
        .any(|l| l.entry.file == strategy.file && l.call == call.span)
    {
        return None;
    }
    let plan = &team.plans[call.plan.index()].name;
    let mut types: Vec<&str> = Vec::new();
    for robot in &team.robots {
        let provides = robot
            .robot_type
            .is_some_and(|id| catalog.get(id).service(&call.name).is_some());
        if provides && !types.contains(&robot.type_name.as_str()) {
            types.push(&robot.type_name);
        }
    }
    if types.is_empty() {
        return None;
    }
    let (at, base, wrap) = insertion_point(text)?;
    let indent = format!("{base}  ");
    let mut entry = format!(
        "{indent}<Service plan_name=\"{plan}\" name=\"{}\">\n",
        call.name
    );
    for t in &types {
        entry.push_str(&format!("{indent}  <TargetRobot name=\"{t}\"/>\n"));
    }
    entry.push_str(&format!("{indent}  <ActionInfo>\n"));
    entry.push_str(&format!(
        "{indent}    <Action name=\"Run\" initial=\"Yes\" final=\"Yes\" actionId=\"0\"/>\n"
    ));
    entry.push_str(&format!("{indent}  </ActionInfo>\n{indent}</Service>\n"));
    let new_text = if wrap {
        // No `<ServiceInfo>` yet: one around the entry, before `</Strategy>`.
        let inner: String = entry.lines().map(|l| format!("  {l}\n")).collect();
        format!("{indent}<ServiceInfo>\n{inner}{indent}</ServiceInfo>\n")
    } else {
        entry
    };
    Some(EntryEdit {
        title: format!(
            "Create the strategy entry for `{}` in plan {plan} ({team_name})",
            call.name
        ),
        edit: TextEdit {
            span: Span::new(at, at),
            new_text,
        },
    })
}

/// Where a new entry goes: the start of the line of `</ServiceInfo>` (or of
/// `</Strategy>`, `true`: the entry needs its `<ServiceInfo>`), with that
/// line's indentation.
fn insertion_point(text: &str) -> Option<(usize, String, bool)> {
    let (close, wrap) = match text.rfind("</ServiceInfo") {
        Some(i) => (i, false),
        None => (text.rfind("</Strategy")?, true),
    };
    let line_start = text[..close].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..close];
    if before.chars().all(|c| c == ' ' || c == '\t') {
        Some((line_start, before.to_string(), wrap))
    } else {
        None
    }
}
