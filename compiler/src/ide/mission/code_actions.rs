//! Quick fixes for the diagnostics of a mission, each an edit of its text
//! after which the mission checks without that diagnostic:
//!
//! - a did-you-mean: replace the name with the suggestion (any code);
//! - E017, a mode that is not defined: create it (`T.NAME{ set(P, OFF) ... }`);
//! - E016, `set` naming a service that the plan lacks: create the composite
//!   service (`T.P.S{ } repeat()`), which also creates a missing plan;
//! - E018, a main block without `default`: add `default: mode = M`;
//! - W001, an event no mode catches: add `catch (E): mode = M` to the case of
//!   a mode that runs a service throwing it;
//! - E041, a bare word that is also a value the robots read: one fix for each
//!   meaning, the word as a string (`"FIRE"`) and the value with its team
//!   (`T.FIRE`), neither preferred (only the user knows which was meant);
//! - W022, a value read once at the start before any robot can have sent
//!   it: add `repeat()` to the service that reads it, which then reads it
//!   again until it comes.

use crate::catalog::Catalog;
use crate::diag::{Code, Diagnostic};
pub use crate::edit::{CodeAction, TextEdit};
use crate::sema::{CheckedMission, ModeId, PlanId, Symbol, Team, TeamId};
use crate::span::Span;
use crate::syntax::ast::{self, Item, SetTarget};

/// The quick fixes for the diagnostics that touch `range`.
pub fn code_actions(
    analysis: &CheckedMission,
    _catalog: &Catalog,
    text: &str,
    range: Span,
) -> Vec<CodeAction> {
    let mut actions = Vec::new();
    for (index, d) in analysis.diagnostics.iter().enumerate() {
        if d.span.end < range.start || d.span.start > range.end {
            continue;
        }
        if text.get(d.span.range()).is_none() {
            continue;
        }
        let fixes = Fixes {
            analysis,
            text,
            diagnostic: d,
            index,
        };
        fixes.all(&mut actions);
    }
    actions
}

struct Fixes<'a> {
    analysis: &'a CheckedMission,
    text: &'a str,
    diagnostic: &'a Diagnostic,
    index: usize,
}

impl Fixes<'_> {
    fn action(&self, title: String, edits: Vec<TextEdit>, preferred: bool) -> CodeAction {
        CodeAction {
            title,
            diagnostic: self.index,
            edits,
            preferred,
        }
    }

    fn all(&self, out: &mut Vec<CodeAction>) {
        let specific = match self.diagnostic.code {
            Code::UnknownMode => self.create_mode(),
            Code::ServiceNotInPlan => self.create_service(),
            Code::MissingDefault => self.add_default(),
            Code::EventNeverCaught => self.add_catches(),
            Code::WordIsAValue => self.word_or_value(),
            Code::ReadBeforeSent => self.add_repeat(),
            _ => Vec::new(),
        };
        let did_you_mean = self.did_you_mean();
        let preferred_set = did_you_mean.is_some();
        out.extend(did_you_mean);
        out.extend(specific.into_iter().map(|mut a| {
            a.preferred = a.preferred && !preferred_set;
            a
        }));
    }

    /// Replace the name with the suggestion.
    fn did_you_mean(&self) -> Option<CodeAction> {
        let d = self.diagnostic;
        let suggestion = d.suggestion.as_ref()?;
        let written = self.text.get(d.span.range())?;
        let (span, new_text) = if written.starts_with('"') {
            // A string compared with a value: keep it a string.
            (d.span, format!("\"{suggestion}\""))
        } else if written.contains('.') && !suggestion.contains('.') {
            // `Tem.X` where `Tem` is not a team: the suggestion is the team.
            let dot = written.find('.').unwrap_or(written.len());
            (
                Span::new(d.span.start, d.span.start + dot),
                suggestion.clone(),
            )
        } else {
            (d.span, suggestion.clone())
        };
        let old = self.text.get(span.range())?;
        if old == new_text {
            return None;
        }
        Some(self.action(
            format!("Change `{old}` to `{new_text}`"),
            vec![TextEdit { span, new_text }],
            true,
        ))
    }

    /// E041: `"FIRE"` (the word) or `T.FIRE` (the value of team `T`, the
    /// one the checker resolved the bare name to).
    fn word_or_value(&self) -> Vec<CodeAction> {
        let span = self.diagnostic.span;
        let Some(word) = self.text.get(span.range()) else {
            return Vec::new();
        };
        let team = self
            .analysis
            .mission
            .occurrence_at(span.start)
            .and_then(|o| match &o.symbol {
                Symbol::Value {
                    owner: Some(team), ..
                } => Some(&self.team(*team).name),
                _ => None,
            });
        let Some(team) = team else {
            return Vec::new();
        };
        [
            (format!("\"{word}\""), "the word"),
            (format!("{team}.{word}"), "the robots' value"),
        ]
        .into_iter()
        .map(|(new_text, meaning)| {
            self.action(
                format!("Write `{new_text}`: {meaning}"),
                vec![TextEdit { span, new_text }],
                false,
            )
        })
        .collect()
    }

    /// W022: `repeat()` after the composite service that holds the read.
    fn add_repeat(&self) -> Vec<CodeAction> {
        let span = self.diagnostic.span;
        let service = self
            .analysis
            .syntax
            .items
            .iter()
            .find_map(|item| match item {
                Item::Service(s)
                    if s.body.span.start <= span.start && span.end <= s.body.span.end =>
                {
                    Some(s)
                }
                _ => None,
            });
        let Some(service) = service.filter(|s| s.repeat.is_none()) else {
            return Vec::new();
        };
        let end = service.body.span.end;
        let path = format!(
            "{}.{}.{}",
            service.team.name, service.plan.name, service.name.name
        );
        vec![self.action(
            format!("Add `repeat()` to `{path}`: read it again until it comes"),
            vec![TextEdit {
                span: Span::new(end, end),
                new_text: " repeat()".to_string(),
            }],
            true,
        )]
    }

    /// The team of the main block whose range holds the diagnostic.
    fn main_at(&self) -> Option<(&ast::MainDef, TeamId)> {
        let span = self.diagnostic.span;
        let main = self.main_syntax(|m| m.span.start <= span.start && span.end <= m.span.end)?;
        let team = self.analysis.mission.team_by_name(&main.team.name)?;
        Some((main, team))
    }

    /// The first main block (as written) that `pick` accepts.
    fn main_syntax(&self, pick: impl Fn(&ast::MainDef) -> bool) -> Option<&ast::MainDef> {
        self.analysis
            .syntax
            .items
            .iter()
            .find_map(|item| match item {
                Item::Main(m) if pick(m) => Some(m),
                _ => None,
            })
    }

    fn team(&self, id: TeamId) -> &Team {
        self.analysis.mission.team(id)
    }

    /// E017: `T.NAME{ set(P, OFF) ... }`, after the team's last mode (or
    /// before its main block).
    fn create_mode(&self) -> Vec<CodeAction> {
        let Some((main, team)) = self.main_at() else {
            return Vec::new();
        };
        let Some(name) = self.text.get(self.diagnostic.span.range()) else {
            return Vec::new();
        };
        let t = self.team(team);
        let edit = self.insert_mode(t, name, main);
        vec![self.action(format!("Create mode `{}.{name}`", t.name), vec![edit], true)]
    }

    /// The definition of a new mode of `t`, where its modes are.
    fn insert_mode(&self, t: &Team, name: &str, main: &ast::MainDef) -> TextEdit {
        let mut body = String::new();
        for p in &t.plans {
            body.push_str(&format!("  set({}, OFF)\n", p.name));
        }
        let definition = format!("{}.{name}{{\n{body}}}", t.name);
        let last_mode = self
            .analysis
            .syntax
            .items
            .iter()
            .filter_map(|item| match item {
                Item::Mode(m) if m.team.name == t.name => Some(m.span),
                _ => None,
            })
            .next_back();
        insert_definition(self.text, definition, last_mode, "\n", main.span)
    }

    /// E016: `set(P, S)` where plan `P` has no service `S` (or there is no
    /// plan `P`): define `T.P.S`.
    fn create_service(&self) -> Vec<CodeAction> {
        let span = self.diagnostic.span;
        let found = self.analysis.syntax.items.iter().find_map(|item| {
            let Item::Mode(m) = item else { return None };
            let set = m.sets.iter().find(|s| {
                s.plan.span == span || matches!(&s.service, SetTarget::Service(n) if n.span == span)
            })?;
            Some((m, set))
        });
        let Some((mode, set)) = found else {
            return Vec::new();
        };
        let SetTarget::Service(service) = &set.service else {
            return Vec::new();
        };
        let Some(team) = self.analysis.mission.team_by_name(&mode.team.name) else {
            return Vec::new();
        };
        let t = self.team(team);
        let plan = t.plan_by_name(&set.plan.name);
        if plan.is_some_and(|p| t.service_in_plan(p, &service.name).is_some()) {
            return Vec::new();
        }
        let path = format!("{}.{}.{}", t.name, set.plan.name, service.name);
        let definition = format!("{path}{{\n  # what the robots do\n}} repeat()");
        // After the plan's last service, else the team's, else before the mode.
        let services = |plan: Option<PlanId>| {
            t.services
                .iter()
                .filter(move |s| plan.is_none_or(|p| s.plan == p))
                .map(|s| s.span)
                .max_by_key(|s| s.end)
        };
        let after = plan
            .and_then(|p| services(Some(p)))
            .or_else(|| services(None));
        let edit = insert_definition(self.text, definition, after, "\n\n", mode.span);
        let title = match plan {
            Some(_) => format!("Create composite service `{path}`"),
            None => format!("Create composite service `{path}` (and the plan)"),
        };
        vec![self.action(title, vec![edit], true)]
    }

    /// E018: `default: mode = M`, M the mode of the first case (or the first
    /// mode; a new mode when the team has none).
    fn add_default(&self) -> Vec<CodeAction> {
        let span = self.diagnostic.span;
        let Some(main) = self.main_syntax(|m| m.team.span.start == span.start) else {
            return Vec::new();
        };
        let Some(team) = self.analysis.mission.team_by_name(&main.team.name) else {
            return Vec::new();
        };
        let t = self.team(team);
        let close = main.span.end.saturating_sub(1);
        if self.text.as_bytes().get(close) != Some(&b'}') {
            return Vec::new();
        }
        let existing = main
            .cases
            .iter()
            .map(|c| c.mode.name.as_str())
            .chain(t.modes.iter().map(|m| m.name.as_str()))
            .find(|m| t.mode_by_name(m).is_some());
        let mut edits = Vec::new();
        let mode = match existing {
            Some(m) => m.to_string(),
            None => {
                let name = "START";
                edits.push(self.insert_mode(t, name, main));
                name.to_string()
            }
        };
        let line = format!("default: mode = {mode}");
        let before_close = &self.text[line_start(self.text, close)..close];
        let edit = if before_close.trim().is_empty() {
            let indent = main
                .cases
                .first()
                .and_then(|c| indentation(self.text, c.span.start))
                .unwrap_or("  ");
            let at = line_start(self.text, close);
            TextEdit {
                span: Span::new(at, at),
                new_text: format!("{indent}{line}\n"),
            }
        } else {
            let space = if before_close.ends_with(char::is_whitespace) {
                ""
            } else {
                " "
            };
            TextEdit {
                span: Span::new(close, close),
                new_text: format!("{space}{line} "),
            }
        };
        edits.push(edit);
        // Edits in text order: a new mode goes before the main block.
        edits.sort_by_key(|e| e.span.start);
        vec![self.action(
            format!("Add `{line}` to the main block of {}", t.name),
            edits,
            true,
        )]
    }

    /// W001: catch the event in the cases of the modes whose services throw it.
    fn add_catches(&self) -> Vec<CodeAction> {
        let span = self.diagnostic.span;
        let mission = &self.analysis.mission;
        let Some(t) = mission
            .teams
            .iter()
            .find(|t| t.events.iter().any(|e| e.thrown_at.contains(&span)))
        else {
            return Vec::new();
        };
        let Some(event) = self.text.get(span.range()) else {
            return Vec::new();
        };
        let Some(main_ir) = &t.main else {
            return Vec::new();
        };
        let Some(main) = self.main_syntax(|m| m.span == main_ir.span) else {
            return Vec::new();
        };
        // The modes that run a service throwing the event, else the default.
        let mut modes: Vec<ModeId> = t
            .mode_ids()
            .filter(|&m| {
                t.modes[m.index()].sets.iter().any(|s| {
                    s.service
                        .is_some_and(|s| t.services[s.index()].throws.iter().any(|e| e == event))
                })
            })
            .collect();
        if modes.is_empty() {
            modes.extend(main_ir.default);
        }
        let mut actions: Vec<CodeAction> = modes
            .into_iter()
            .take(3)
            .filter_map(|m| self.add_catch(t, main, event, m))
            .collect();
        // The first mode's is the likely one.
        for action in actions.iter_mut().skip(1) {
            action.preferred = false;
        }
        actions
    }

    fn add_catch(
        &self,
        t: &Team,
        main: &ast::MainDef,
        event: &str,
        mode: ModeId,
    ) -> Option<CodeAction> {
        let from = t.modes.get(mode.index())?.name.as_str();
        let default = t
            .main
            .as_ref()
            .and_then(|m| m.default)
            .filter(|&d| d != mode);
        let other = t.mode_ids().find(|&m| m != mode);
        let to = t.modes[default.or(other).unwrap_or(mode).index()]
            .name
            .as_str();
        let catch = format!("catch ({event}): mode = {to}");
        let edit = match main.cases.iter().find(|c| c.mode.name == from) {
            Some(case) => {
                let case_indent = indentation(self.text, case.span.start).unwrap_or("  ");
                let indent = case
                    .catches
                    .first()
                    .and_then(|c| indentation(self.text, c.span.start))
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("{case_indent}  "));
                TextEdit {
                    span: Span::new(case.span.end, case.span.end),
                    new_text: format!("\n{indent}{catch}"),
                }
            }
            None => {
                // A new case, first in the block.
                let after_brace = self
                    .text
                    .get(main.main_span.end..main.span.end)?
                    .find('{')?
                    + main.main_span.end
                    + 1;
                let indent = main
                    .cases
                    .first()
                    .and_then(|c| indentation(self.text, c.span.start))
                    .unwrap_or("  ");
                TextEdit {
                    span: Span::new(after_brace, after_brace),
                    new_text: format!("\n{indent}case ({from}):\n{indent}  {catch}"),
                }
            }
        };
        Some(self.action(
            format!("Catch `{event}` in mode `{from}`: switch to mode `{to}`"),
            vec![edit],
            true,
        ))
    }
}

/// Inserts `definition` right after `after` (`gap` between them), or else on
/// its own lines before the line of `before`.
fn insert_definition(
    text: &str,
    definition: String,
    after: Option<Span>,
    gap: &str,
    before: Span,
) -> TextEdit {
    match after {
        Some(after) => TextEdit {
            span: Span::new(after.end, after.end),
            new_text: format!("{gap}{definition}"),
        },
        None => {
            let at = line_start(text, before.start);
            TextEdit {
                span: Span::new(at, at),
                new_text: format!("{definition}\n\n"),
            }
        }
    }
}

fn line_start(text: &str, offset: usize) -> usize {
    text.get(..offset)
        .and_then(|before| before.rfind('\n'))
        .map_or(0, |i| i + 1)
}

/// The whitespace before `offset` on its line, if only whitespace is there.
fn indentation(text: &str, offset: usize) -> Option<&str> {
    let start = line_start(text, offset);
    let before = text.get(start..offset)?;
    before
        .chars()
        .all(|c| c == ' ' || c == '\t')
        .then_some(before)
}
