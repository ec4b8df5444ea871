//! The outline of a mission (document symbols) and the symbols a workspace
//! search finds.
//!
//! The outline has one entry per team, holding its robots, its plans with
//! their composite services, its modes and its main block; functions are at
//! the top level. A function or service holds the names its body binds to
//! action results (`FOUND, WHERE = search(red)`), each at its first binding.
//! Items of undeclared teams and duplicate definitions (both reported by the
//! checker) are not in it.

use crate::CheckedMission;
use crate::ide::{NavigationTarget, StructureNode, SymbolKind, WorkspaceSymbol};
use crate::sema::Team;
use crate::syntax::ast::{self, Item};

/// The outline of the mission, in file order.
pub fn document_symbols(analysis: &CheckedMission, text: &str) -> Vec<StructureNode> {
    let mission = &analysis.mission;
    let decls: Vec<&ast::TeamDecl> = analysis
        .syntax
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Formation(f) => Some(&f.teams),
            _ => None,
        })
        .flatten()
        .collect();
    let mains: Vec<&ast::MainDef> = analysis
        .syntax
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Main(m) => Some(m),
            _ => None,
        })
        .collect();
    let mut symbols: Vec<StructureNode> = mission
        .teams
        .iter()
        .filter_map(|team| {
            let decl = decls.iter().find(|d| d.name.span == team.name_span)?;
            Some(team_symbol(team, decl, &mains, text))
        })
        .collect();
    symbols.extend(mission.functions.iter().map(|f| {
        // `(PLACE, WAIT)`: a function's parameters, as its header lists them.
        let names: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
        StructureNode {
            name: f.name.to_string(),
            detail: (!names.is_empty()).then(|| format!("({})", names.join(", "))),
            kind: SymbolKind::Function,
            span: analysis
                .function_syntax(f)
                .map_or(f.name_span, |syntax| syntax.span),
            name_span: f.name_span,
            children: result_symbols(&f.results),
        }
    }));
    symbols.sort_by_key(|s| s.span.start);
    symbols
}

fn team_symbol(
    team: &Team,
    decl: &ast::TeamDecl,
    mains: &[&ast::MainDef],
    text: &str,
) -> StructureNode {
    let mut children = Vec::new();
    for robot in &decl.robots {
        if !team.robots.iter().any(|r| r.name_span == robot.name.span) {
            continue; // a duplicate name, reported
        }
        // `tb[3]` as written.
        let name = match robot.count {
            Some(_) => text
                .get(robot.name.span.start..robot.span.end)
                .unwrap_or(&robot.name.name)
                .to_string(),
            None => robot.name.name.to_string(),
        };
        children.push(StructureNode {
            name,
            detail: Some(robot.robot_type.name.to_string()),
            kind: SymbolKind::Robot,
            span: robot.span,
            name_span: robot.name.span,
            children: Vec::new(),
        });
    }
    for (p, plan) in team.plans.iter().enumerate() {
        let services: Vec<StructureNode> = team
            .services
            .iter()
            .filter(|s| s.plan.index() == p)
            .map(|s| StructureNode {
                name: s.name.to_string(),
                detail: Some(format!(
                    "{}.{}.{}{}",
                    team.name,
                    plan.name,
                    s.name,
                    param_list(&s.params)
                )),
                kind: SymbolKind::Service,
                span: s.span,
                name_span: s.name_span,
                children: result_symbols(&s.results),
            })
            .collect();
        let span = services
            .iter()
            .fold(plan.span, |span, s| span.cover(s.span));
        children.push(StructureNode {
            name: plan.name.to_string(),
            detail: None,
            kind: SymbolKind::Plan,
            span,
            name_span: plan.span,
            children: services,
        });
    }
    let set_list = |sets: &[crate::sema::ModeSet]| -> Vec<String> {
        sets.iter()
            .filter_map(|set| {
                let plan = &team.plans.get(set.plan?.index())?.name;
                let service = match set.service {
                    Some(s) => team.services.get(s.index())?.name.to_string(),
                    None => "OFF".to_string(),
                };
                let args: Vec<String> = set.args.iter().map(ast::Arg::written).collect();
                Some(match args.is_empty() {
                    true => format!("{plan}: {service}"),
                    false => format!("{plan}: {service}({})", args.join(", ")),
                })
            })
            .collect()
    };
    // The modes as declared, in the file's order: a mode with parameters
    // once (with its parameters), not once per list of arguments it is
    // entered with.
    let modes_from = children.len();
    for mode in team.modes.iter().filter(|m| m.instance.is_none()) {
        let sets = set_list(&mode.sets);
        children.push(StructureNode {
            name: mode.name.to_string(),
            detail: (!sets.is_empty()).then(|| sets.join(", ")),
            kind: SymbolKind::Mode,
            span: mode.span,
            name_span: mode.name_span,
            children: Vec::new(),
        });
    }
    for template in &team.templates {
        let sets = set_list(&template.sets);
        let params = param_list(&template.params);
        children.push(StructureNode {
            name: template.name.to_string(),
            detail: Some(match sets.is_empty() {
                true => params,
                false => format!("{params} {}", sets.join(", ")),
            }),
            kind: SymbolKind::Mode,
            span: template.span,
            name_span: template.name_span,
            children: Vec::new(),
        });
    }
    children[modes_from..].sort_by_key(|node| node.span.start);
    if let Some(main) = &team.main
        && let Some(syntax) = mains.iter().find(|m| m.span == main.span)
    {
        let default = main
            .default
            .and_then(|m| team.modes.get(m.index()))
            .map(|m| format!("default: {}", m.name));
        children.push(StructureNode {
            name: "main".to_string(),
            detail: default,
            kind: SymbolKind::Main,
            span: main.span,
            name_span: syntax.main_span,
            children: Vec::new(),
        });
    }
    let span = children
        .iter()
        .fold(decl.span, |span, c| span.cover(c.span));
    let robots = team.robots.len();
    StructureNode {
        name: team.name.to_string(),
        detail: Some(format!(
            "{robots} robot{}",
            if robots == 1 { "" } else { "s" }
        )),
        kind: SymbolKind::Team,
        span,
        name_span: team.name_span,
        children,
    }
}

/// The teams, composite services, modes and functions of the mission whose
/// name matches `query`, best first.
pub fn workspace_symbols(analysis: &CheckedMission, query: &str) -> Vec<WorkspaceSymbol> {
    let mission = &analysis.mission;
    let mut found = Vec::new();
    let mut add = |name: &str, kind, container: Option<String>, name_span| {
        if let Some(score) = match_score(query, name) {
            found.push(WorkspaceSymbol {
                name: name.to_string(),
                kind,
                container,
                target: NavigationTarget {
                    file: mission.file,
                    span: name_span,
                },
                score,
            });
        }
    };
    for team in &mission.teams {
        add(&team.name, SymbolKind::Team, None, team.name_span);
        for s in &team.services {
            let plan = team
                .plans
                .get(s.plan.index())
                .map_or("", |p| p.name.as_str());
            let container = Some(format!("{}.{plan}", team.name));
            add(&s.name, SymbolKind::Service, container, s.name_span);
        }
        // Modes as declared: a mode with parameters once.
        let declared = team.modes.iter().filter(|m| m.instance.is_none());
        let declared = declared.map(|m| (&m.name, m.name_span));
        let templates = team.templates.iter().map(|m| (&m.name, m.name_span));
        for (name, name_span) in declared.chain(templates) {
            add(
                name,
                SymbolKind::Mode,
                Some(team.name.to_string()),
                name_span,
            );
        }
    }
    for f in &mission.functions {
        add(&f.name, SymbolKind::Function, None, f.name_span);
    }
    found.sort_by(|a, b| (a.score, &a.name, a.target).cmp(&(b.score, &b.name, b.target)));
    found
}

/// How `name` matches `query`, ignoring case: 0 equal (case too), 1 equal,
/// 2 prefix, 3 substring, 4 the query's characters in order (`amm` for
/// `AutonomousMove`); `None` if not at all. An empty query matches all (4).
pub fn match_score(query: &str, name: &str) -> Option<u32> {
    if query.is_empty() {
        return Some(4);
    }
    if query == name {
        return Some(0);
    }
    let (q, n) = (query.to_lowercase(), name.to_lowercase());
    if q == n {
        Some(1)
    } else if n.starts_with(&q) {
        Some(2)
    } else if n.contains(&q) {
        Some(3)
    } else {
        let mut chars = n.chars();
        q.chars()
            .all(|c| chars.by_ref().any(|d| d == c))
            .then_some(4)
    }
}

/// The names a body binds to action results, at their first binding, in
/// the order bound: `FOUND` with the detail `FOUND: bool of search` (the
/// catalog's result and type, once a call binding it was checked).
fn result_symbols(results: &[crate::sema::ResultInfo]) -> Vec<StructureNode> {
    results
        .iter()
        .map(|r| StructureNode {
            name: r.name.to_string(),
            detail: Some(match (&r.catalog_name, &r.ty) {
                (Some(result), Some(ty)) => format!("{result}: {ty} of {}", r.service),
                _ => format!("of {}", r.service),
            }),
            kind: SymbolKind::Result,
            span: r.span,
            name_span: r.span,
            children: Vec::new(),
        })
        .collect()
}

/// `(A, B)`, or nothing without parameters.
fn param_list(params: &[crate::sema::ParamInfo]) -> String {
    if params.is_empty() {
        return String::new();
    }
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    format!("({})", names.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::Fixture;

    const MISSION: &str = r#"# Guarding
{
  Base: iRobotCreate base
  Guards: Turtlebot3_Burger tb[3], Ev3_Robot ev
}
def warn { throw alarm }
Base.Listen.Collect {
  warn()
} repeat(1 SEC)
Base.Action.Hold { standby() } repeat()
Guards.Action.Patrol { warn() } repeat()
Base.Action.AutonomousMove { move("1,1") }
Base.WATCH { set(Listen, Collect); set(Action, Hold) }
Base.ALERT { set(Listen, OFF); set(Action, AutonomousMove) }
Base.main {
  case (WATCH):
    catch (alarm): mode = ALERT
  default: mode = WATCH
}
Guards.GO { set(Action, Patrol) }
Guards.main { case (GO): catch (alarm): mode = GO default: mode = GO }
Nobody.Plan.Lost { standby() }
"#;

    fn outline(f: &Fixture, symbols: &[StructureNode], depth: usize, out: &mut String) {
        for s in symbols {
            let (line, _) = f.line_col(s.span.start);
            let (end, _) = f.line_col(s.span.end);
            assert!(
                s.span.start <= s.name_span.start && s.name_span.end <= s.span.end,
                "{s:?}"
            );
            out.push_str(&format!(
                "{:indent$}{:?} {} [{}] lines {line}-{end}{}\n",
                "",
                s.kind,
                s.name,
                &f.text[s.name_span.range()],
                s.detail
                    .as_ref()
                    .map(|d| format!(" ({d})"))
                    .unwrap_or_default(),
                indent = depth * 2
            ));
            outline(f, &s.children, depth + 1, out);
        }
    }

    #[test]
    fn outline_per_team() {
        let f = Fixture::new(MISSION);
        let mut out = String::new();
        outline(&f, &document_symbols(&f.analysis, &f.text), 0, &mut out);
        assert_eq!(
            out,
            "\
Team Base [Base] lines 3-19 (1 robot)
  Robot base [base] lines 3-3 (iRobotCreate)
  Plan Listen [Listen] lines 7-9
    Service Collect [Collect] lines 7-9 (Base.Listen.Collect)
  Plan Action [Action] lines 10-12
    Service Hold [Hold] lines 10-10 (Base.Action.Hold)
    Service AutonomousMove [AutonomousMove] lines 12-12 (Base.Action.AutonomousMove)
  Mode WATCH [WATCH] lines 13-13 (Listen: Collect, Action: Hold)
  Mode ALERT [ALERT] lines 14-14 (Listen: OFF, Action: AutonomousMove)
  Main main [main] lines 15-19 (default: WATCH)
Team Guards [Guards] lines 4-21 (4 robots)
  Robot tb[3] [tb] lines 4-4 (Turtlebot3_Burger)
  Robot ev [ev] lines 4-4 (Ev3_Robot)
  Plan Action [Action] lines 11-11
    Service Patrol [Patrol] lines 11-11 (Guards.Action.Patrol)
  Mode GO [GO] lines 20-20 (Action: Patrol)
  Main main [main] lines 21-21 (default: GO)
Function warn [warn] lines 6-6
"
        );
    }

    #[test]
    fn a_function_with_parameters_lists_them_as_its_detail() {
        let f = Fixture::new("def go_to(PLACE, WAIT) { move(PLACE) }\ndef home { stop() }\n");
        let mut out = String::new();
        outline(&f, &document_symbols(&f.analysis, &f.text), 0, &mut out);
        assert_eq!(
            out,
            "Function go_to [go_to] lines 1-1 ((PLACE, WAIT))\nFunction home [home] lines 2-2\n"
        );
    }

    #[test]
    fn results_a_body_binds_are_under_its_function_or_service() {
        let f = Fixture::new(
            "{ R: TIEvalbot ti }\n\
             def check {\n  SEEN = search(blue)\n}\n\
             R.Action.Survey {\n  FOUND, WHERE = search(red)\n  check()\n  FOUND, WHERE = search(red)\n} repeat(1 SEC)\n\
             R.SURVEY { set(Action, Survey) }\nR.main { default: mode = SURVEY }\n",
        );
        let mut out = String::new();
        outline(&f, &document_symbols(&f.analysis, &f.text), 0, &mut out);
        assert_eq!(
            out,
            "\
Team R [R] lines 1-11 (1 robot)
  Robot ti [ti] lines 1-1 (TIEvalbot)
  Plan Action [Action] lines 5-9
    Service Survey [Survey] lines 5-9 (R.Action.Survey)
      Result FOUND [FOUND] lines 6-6 (FOUND: bool of search)
      Result WHERE [WHERE] lines 6-6 (WHERE: location of search)
  Mode SURVEY [SURVEY] lines 10-10 (Action: Survey)
  Main main [main] lines 11-11 (default: SURVEY)
Function check [check] lines 2-4
  Result SEEN [SEEN] lines 3-3 (FOUND: bool of search)
"
        );
    }

    #[test]
    fn workspace_search_ranks_exact_prefix_substring_subsequence() {
        let f = Fixture::new(MISSION);
        let found = |query: &str| {
            workspace_symbols(&f.analysis, query)
                .iter()
                .map(|s| match &s.container {
                    Some(c) => format!("{c}.{}", s.name),
                    None => s.name.clone(),
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        assert_eq!(found("alert"), "Base.ALERT");
        assert_eq!(
            found("a"),
            "Base.ALERT, Base.Action.AutonomousMove, Base, Guards, Guards.Action.Patrol, Base.WATCH, warn"
        );
        assert_eq!(found("amv"), "Base.Action.AutonomousMove");
        assert_eq!(found("Lost"), "");
        assert_eq!(found("").split(", ").count(), 10);
        assert_eq!(match_score("GO", "GO"), Some(0));
        assert_eq!(match_score("go", "GO"), Some(1));
        assert_eq!(match_score("xyz", "GO"), None);
    }
}
