//! Go to definition, find references and document highlights.
//!
//! What a name's definition is, per kind of symbol:
//! - team, robot, composite service, mode, function: where it is declared
//!   (the formation entry, the robot's name, the name in `T.P.S {`, `T.M {`,
//!   `def f {`); a plan: the first service header that names it;
//! - event: every `throw` of it in its team (a `catch (e)` goes to the
//!   `throw e`s that it catches), none if it is never thrown;
//! - team variable: every `T.X = ...` in `send`/`publish`, or, for a
//!   variable that is only received, the `receive`/`subscribe`s of it;
//! - robot type, built-in service, value: its element in the workspace's
//!   `*.robot.xml` file (the robot types of the team running the statement
//!   first); the built-in catalog has no file, so none;
//! - `USER`, constants and capabilities: none.
//!
//! References and highlights stay in the mission: every name of the file
//! that means the same symbol. When one name means several symbols (the
//! robots of `tb[3]`; a function called by several teams, whose `throw e`
//! raises an event of each), the results of all of them are given.

use crate::CheckedMission;
use crate::catalog::{BUILTIN_FILE, Catalog, Origin, RobotTypeId};
use crate::ide::NavigationTarget;
use crate::sema::lookup;
use crate::sema::{Symbol, TeamId};
use crate::span::Span;
use crate::syntax::ast::{Item, StmtKind};

/// The name at an offset and the symbols it means (usually one).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NameAt {
    pub span: Span,
    pub symbols: Vec<Symbol>,
}

/// How a reference uses its symbol (for highlights).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    /// A definition, a `throw` of an event, a team variable assigned or received.
    Write,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reference {
    pub span: Span,
    /// Whether this is one of the symbol's definitions (see the module docs).
    pub is_definition: bool,
    pub access: Access,
}

/// The name at `offset` (containing it or ending there) and what it means.
pub fn name_at(analysis: &CheckedMission, offset: usize) -> Option<NameAt> {
    let occurrences = lookup::at(&analysis.mission, offset);
    let first = occurrences.first()?;
    Some(NameAt {
        span: first.span,
        symbols: lookup::symbols(occurrences),
    })
}

/// The definitions of the name at `offset`, sorted; empty when there is no
/// name there or its definition has no place (see the module docs).
pub fn definition(
    analysis: &CheckedMission,
    catalog: &Catalog,
    offset: usize,
) -> Vec<NavigationTarget> {
    let Some(name) = name_at(analysis, offset) else {
        return Vec::new();
    };
    let mut targets: Vec<NavigationTarget> = Vec::new();
    for symbol in &name.symbols {
        if let Some(origins) = catalog_origins(analysis, catalog, symbol, offset) {
            targets.extend(
                origins
                    .into_iter()
                    .filter(|o| o.file != BUILTIN_FILE)
                    .map(|o| NavigationTarget {
                        file: o.file,
                        span: o.span,
                    }),
            );
        } else {
            let file = analysis.mission.file;
            targets.extend(
                definition_spans(analysis, symbol)
                    .into_iter()
                    .map(|span| NavigationTarget { file, span }),
            );
        }
    }
    targets.sort();
    targets.dedup();
    targets
}

/// Every name of the mission meaning what the name at `offset` means, sorted.
pub fn references(analysis: &CheckedMission, offset: usize) -> Vec<Reference> {
    let Some(name) = name_at(analysis, offset) else {
        return Vec::new();
    };
    let mut refs: Vec<Reference> = Vec::new();
    for symbol in &name.symbols {
        let definitions = definition_spans(analysis, symbol);
        let writes = write_spans(analysis, symbol, &definitions);
        let uses = analysis.mission.occurrences_of(symbol).map(|o| o.span);
        // Events have no defining occurrence: their throws are in `definitions`.
        for span in uses.chain(definitions.iter().copied()) {
            refs.push(Reference {
                span,
                is_definition: definitions.binary_search(&span).is_ok(),
                access: if writes.binary_search(&span).is_ok() {
                    Access::Write
                } else {
                    Access::Read
                },
            });
        }
    }
    refs.sort_by_key(|r| (r.span, !r.is_definition));
    refs.dedup_by_key(|r| r.span);
    refs
}

/// The definitions of `symbol` in the mission (see the module docs), sorted.
pub(crate) fn definition_spans(analysis: &CheckedMission, symbol: &Symbol) -> Vec<Span> {
    let mission = &analysis.mission;
    let mut spans: Vec<Span> = match symbol {
        Symbol::Event { team, name } => mission
            .teams
            .get(team.0 as usize)
            .and_then(|t| t.events.iter().find(|e| e.name == *name))
            .map(|e| e.thrown_at.clone())
            .unwrap_or_default(),
        _ => mission
            .occurrences_of(symbol)
            .filter(|o| o.is_definition)
            .map(|o| o.span)
            .collect(),
    };
    if spans.is_empty() && matches!(symbol, Symbol::TeamVariable { .. }) {
        let incoming = incoming_spans(analysis);
        spans = mission
            .occurrences_of(symbol)
            .map(|o| o.span)
            .filter(|s| incoming.binary_search(s).is_ok())
            .collect();
    }
    spans.sort();
    spans.dedup();
    spans
}

/// The spans where `symbol` is given a value, sorted: its definitions, and
/// for a team variable also where it is received.
fn write_spans(analysis: &CheckedMission, symbol: &Symbol, definitions: &[Span]) -> Vec<Span> {
    let mut writes = definitions.to_vec();
    if matches!(symbol, Symbol::TeamVariable { .. }) {
        let incoming = incoming_spans(analysis);
        writes.extend(
            analysis
                .mission
                .occurrences_of(symbol)
                .map(|o| o.span)
                .filter(|s| incoming.binary_search(s).is_ok()),
        );
        writes.sort();
    }
    writes
}

/// The last name of every attribute of a `receive` or `subscribe`, sorted.
fn incoming_spans(analysis: &CheckedMission) -> Vec<Span> {
    let mut spans = Vec::new();
    for item in &analysis.syntax.items {
        let body = match item {
            Item::Service(s) => &s.body,
            Item::Function(f) => &f.body,
            _ => continue,
        };
        body.walk(&mut |stmt| {
            if let StmtKind::Comm(comm) = &stmt.kind
                && !comm.kind.is_outgoing()
            {
                spans.extend(comm.items.iter().map(|i| i.attr.last().span));
            }
        });
    }
    spans.sort();
    spans
}

/// Where a catalog symbol is defined; `None` for symbols of the mission.
fn catalog_origins(
    analysis: &CheckedMission,
    catalog: &Catalog,
    symbol: &Symbol,
    offset: usize,
) -> Option<Vec<Origin>> {
    let origins = match symbol {
        Symbol::RobotType(name) => catalog.robot(name).map(|r| r.origin).into_iter().collect(),
        Symbol::BuiltinService(name) => {
            let running = running_types(analysis, lookup::enclosing_team(analysis, offset));
            let of = |types: &mut dyn Iterator<Item = RobotTypeId>| -> Vec<Origin> {
                types
                    .filter_map(|t| catalog.get(t).service(name).map(|s| s.origin))
                    .collect()
            };
            let origins = of(&mut running.into_iter());
            if origins.is_empty() {
                of(&mut catalog.types().map(|(id, _)| id))
            } else {
                origins
            }
        }
        Symbol::Value {
            owner: Some(team),
            name,
        } => running_types(analysis, Some(*team))
            .into_iter()
            .filter_map(|t| catalog.get(t).value(name).map(|v| v.origin))
            .collect(),
        Symbol::Value { owner: None, name } => catalog
            .user()
            .and_then(|u| u.value(name))
            .map(|v| v.origin)
            .into_iter()
            .collect(),
        Symbol::User | Symbol::Constant(_) | Symbol::Capability(_) => Vec::new(),
        _ => return None,
    };
    Some(origins)
}

/// The robot types of a team's robots (of every team when `None`), each once.
fn running_types(analysis: &CheckedMission, team: Option<TeamId>) -> Vec<RobotTypeId> {
    let teams = &analysis.mission.teams;
    let teams = match team {
        Some(t) => teams.get(t.0 as usize..t.0 as usize + 1).unwrap_or(&[]),
        None => teams,
    };
    let mut types: Vec<RobotTypeId> = teams
        .iter()
        .flat_map(|t| t.robots.iter().filter_map(|r| r.robot_type))
        .collect();
    types.sort();
    types.dedup();
    types
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::{Fixture, spans_text};

    const MISSION: &str = r#"{
  Base: iRobotCreate base
  Guards: Turtlebot3_Burger tb[3], Ev3_Robot ev
}
def warn {
  throw alarm
}
Base.Listen.Collect {
  subscribe(Guards, Guards.Alarm)
  if (Guards.Alarm == DARK) throw alarm
  warn()
} repeat(1 SEC)
Base.Action.Hold { standby() } repeat()
Guards.Action.Patrol {
  publish(Guards, Guards.Alarm = DARK)
  warn()
} repeat()
Base.WATCH { set(Listen, Collect); set(Action, Hold) }
Base.ALERT { set(Listen, OFF); set(Action, Hold) }
Base.main {
  case (WATCH):
    catch (alarm): mode = ALERT
  default: mode = WATCH
}
Guards.GO { set(Action, Patrol) }
Guards.main { case (GO): catch (alarm): mode = GO  default: mode = GO }
"#;

    fn definitions_at(fixture: &Fixture, marker: &str) -> String {
        let offset = fixture.offset_of(marker);
        let targets = definition(&fixture.analysis, &fixture.catalog, offset);
        assert!(
            targets
                .iter()
                .all(|t| t.file == fixture.analysis.mission.file)
        );
        spans_text(&fixture.text, targets.iter().map(|t| t.span))
    }

    #[test]
    fn definitions_of_mission_symbols() {
        let f = Fixture::new(MISSION);
        assert_eq!(definitions_at(&f, "Base.Listen"), "2:3 Base");
        assert_eq!(definitions_at(&f, "Listen, Collect"), "8:6 Listen");
        assert_eq!(
            definitions_at(&f, "Collect); set(Action, Hold) }"),
            "8:13 Collect"
        );
        assert_eq!(definitions_at(&f, "ALERT\n"), "19:6 ALERT");
        assert_eq!(definitions_at(&f, "warn()\n} repeat(1"), "5:5 warn");
        // A catch goes to every throw of its team, in a function included.
        assert_eq!(
            definitions_at(&f, "alarm): mode = ALERT"),
            "6:9 alarm, 10:35 alarm"
        );
        // The function's throw raises an event of both teams.
        assert_eq!(
            definitions_at(&f, "alarm\n}\nBase.Listen"),
            "6:9 alarm, 10:35 alarm"
        );
        assert_eq!(definitions_at(&f, "Alarm)\n  if"), "15:26 Alarm");
        assert_eq!(definitions_at(&f, "tb[3]"), "3:29 tb");
    }

    #[test]
    fn builtin_catalog_entries_have_no_definition() {
        let f = Fixture::new(MISSION);
        assert_eq!(definitions_at(&f, "standby"), "");
        assert_eq!(definitions_at(&f, "Turtlebot3_Burger"), "");
        assert_eq!(definitions_at(&f, "DARK) throw"), "");
        assert_eq!(definitions_at(&f, "main {\n  case"), "");
    }

    #[test]
    fn catalog_entries_of_a_workspace_file() {
        let xml = r#"<Catalog>
  <Robot type="MyBot">
    <Value name="HEAT" type="int"/>
    <Service name="cool"/>
  </Robot>
</Catalog>"#;
        let mission = "{ T: MyBot m }\nT.P.S { cool() if (HEAT > 3) cool() } repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n";
        let f = Fixture::with_catalog(mission, xml);
        for (marker, element) in [
            ("MyBot m", "<Robot type=\"MyBot\">"),
            ("cool() if", "<Service name=\"cool\"/>"),
            ("HEAT >", "<Value name=\"HEAT\" type=\"int\"/>"),
        ] {
            let targets = definition(&f.analysis, &f.catalog, f.offset_of(marker));
            assert_eq!(targets.len(), 1, "{marker}");
            assert_eq!(targets[0].file, Fixture::CATALOG_FILE);
            assert!(
                xml[targets[0].span.range()].starts_with(element),
                "{marker}"
            );
        }
    }

    #[test]
    fn references_and_their_access() {
        let f = Fixture::new(MISSION);
        let show = |marker: &str| {
            references(&f.analysis, f.offset_of(marker))
                .iter()
                .map(|r| {
                    let (line, col) = f.line_col(r.span.start);
                    let access = match (r.is_definition, r.access) {
                        (true, _) => "def",
                        (false, Access::Write) => "write",
                        (false, Access::Read) => "read",
                    };
                    format!("{line}:{col} {access}")
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        assert_eq!(show("WATCH {"), "18:6 def, 21:9 read, 23:19 read");
        assert_eq!(
            show("alarm): mode = ALERT"),
            "6:9 def, 10:35 def, 22:12 read"
        );
        // The function's throw is an event of both teams, caught by both.
        assert_eq!(
            show("alarm\n}\nBase.Listen"),
            "6:9 def, 10:35 def, 22:12 read, 26:33 read"
        );
        // Assigned in Patrol, received in Collect, read in a condition.
        assert_eq!(show("Alarm == DARK"), "9:28 write, 10:14 read, 15:26 def");
        assert_eq!(
            show("Guards: Turtlebot3"),
            "3:3 def, 9:13 read, 9:21 read, 10:7 read, 14:1 read, 15:11 read, 15:19 read, 25:1 read, 26:1 read"
        );
        assert_eq!(show("def warn"), "");
    }

    #[test]
    fn any_offset_is_accepted() {
        let f = Fixture::new(MISSION);
        for offset in 0..=f.text.len() + 3 {
            definition(&f.analysis, &f.catalog, offset);
            references(&f.analysis, offset);
        }
    }
}
