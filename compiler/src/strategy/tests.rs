use super::*;
use crate::catalog::{Catalog, CatalogSource, builtin_catalog, load_catalog};
use crate::sema::CheckedMission;
use crate::span::Span;
use crate::syntax::ast::{CmpOp, ExprKind};

const FILE: FileId = FileId(7);
const MISSION: FileId = FileId(1);

const SCOUTING_STRATEGY: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/scouting/MasterTeam.strategy.xml"
));
const SCOUTING: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/scouting/scouting.mission"
));

fn load(text: &str) -> (Strategy, Vec<Diagnostic>) {
    let (strategy, diags) = load_strategy(FILE, text);
    (strategy.expect("a <Strategy> element"), diags)
}

fn codes(diags: &[Diagnostic]) -> Vec<&'static str> {
    diags.iter().map(|d| d.code.as_str()).collect()
}

fn at(text: &str, span: Span) -> &str {
    &text[span.range()]
}

/// A strategy for team `T` with one service `move` of plan `Action` whose
/// actions are `actions`.
fn with_actions(actions: &str) -> String {
    format!(
        r#"<Strategy name="T"><ServiceInfo><Service plan_name="Action" name="move">
<TargetRobot name="iRobotCreate"/><ActionInfo>
{actions}
</ActionInfo></Service></ServiceInfo></Strategy>"#
    )
}

#[test]
fn the_scouting_strategy_loads_cleanly_with_positions() {
    let text = SCOUTING_STRATEGY;
    let (s, diags) = load(text);
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(s.team.as_ref().unwrap().name, "MasterTeam");
    assert_eq!(at(text, s.team.unwrap().span), "MasterTeam");
    assert_eq!(s.values.len(), 2);
    let distance = &s.values[0];
    assert_eq!(distance.name.as_ref().unwrap().name, "DISTANCE");
    assert_eq!(
        distance.targets[0].name.as_ref().unwrap().name,
        "iRobotCreate"
    );
    let sensor = &distance.tasks[0];
    assert_eq!(sensor.kind, TaskUseKind::CheckSensor);
    let p = &sensor.parameters[0];
    assert_eq!(p.data, Some(DataCharacteristic::Channel));
    assert_eq!(p.size, Some(1));
    assert_eq!(at(text, p.src_task.as_ref().unwrap().span), "ultrasonic");

    let service = &s.services[0];
    assert_eq!(service.plan.as_ref().unwrap().name, "Action");
    assert_eq!(service.name.as_ref().unwrap().name, "move");
    assert!(service.complete);
    assert_eq!(service.actions.len(), 5);
    let first = &service.actions[0];
    assert!(first.initial.is_yes());
    assert_eq!(first.id.unwrap().value, 0);
    assert_eq!(first.transitions.len(), 2);
    assert_eq!(first.transitions[0].dst.unwrap().value, 4);
    assert!(service.actions[4].is_final.is_yes());
    assert_eq!(
        service.action_by_id(3).unwrap().name.as_ref().unwrap().name,
        "AvoidObstacle"
    );
    let params: Vec<&str> = service
        .parameters()
        .filter_map(|p| p.name.as_ref())
        .map(|n| n.name.as_str())
        .collect();
    // Action by action: its own parameters, then those of its task uses.
    assert_eq!(params[..3], ["goalLocation", "currentLocation", "distance"]);

    // `distance&gt;20`: the condition reads `distance>20`, positioned in the file.
    let cond = service.actions[1].transitions[0]
        .condition
        .as_ref()
        .unwrap();
    assert_eq!(cond.text, "distance>20");
    assert_eq!(at(text, cond.span), "distance&gt;20");
    let expr = cond.expr.as_ref().unwrap();
    assert_eq!(at(text, expr.span), "distance&gt;20");
    let ExprKind::Compare(lhs, CmpOp::Gt, rhs) = &expr.kind else {
        panic!("{expr:?}")
    };
    assert_eq!(at(text, lhs.span), "distance");
    assert_eq!(at(text, rhs.span), "20");

    assert!(s.grouping.is_none());
    assert_eq!(s.battery_rules.len(), 1);
    let rule = &s.battery_rules[0];
    assert_eq!(rule.condition.as_ref().unwrap().text, "Battery<30");
    assert_eq!(rule.sensors.len(), 2);
    assert_eq!(rule.actuators[0].level, Some(2));
}

#[test]
fn a_plain_lt_is_reported_at_the_lt_and_read_as_meant() {
    let text = with_actions(
        r#"<Action name="A" initial="Yes" actionId="0"><Parameter name="distance" type="integer" dataCharacteristic="variable"/>
<TransitionInfo><Transition srcId="0" dstId="1"><Condition cond="distance<20"/></Transition><Transition srcId="0" dstId="1"><Condition cond="distance &gt;= 20"/></Transition></TransitionInfo></Action>
<Action name="B" actionId="1" final="Yes"/>"#,
    );
    let (s, diags) = load(&text);
    assert_eq!(codes(&diags), ["E081"], "{diags:#?}");
    let lt = text.find("distance<").unwrap() + "distance".len();
    assert_eq!(diags[0].span, Span::new(lt, lt + 1));
    assert_eq!(diags[0].suggestion.as_deref(), Some("&lt;"));
    let cond = s.services[0].actions[0].transitions[0]
        .condition
        .as_ref()
        .unwrap();
    let ExprKind::Compare(_, CmpOp::Lt, rhs) = &cond.expr.as_ref().unwrap().kind else {
        panic!("{cond:?}")
    };
    assert_eq!(at(&text, rhs.span), "20");
}

#[test]
fn conditions_that_do_not_parse_use_the_mission_syntax_codes() {
    let text = with_actions(
        r#"<Action name="A" initial="Yes" actionId="0"><Parameter name="d" type="integer" dataCharacteristic="variable"/>
<TransitionInfo><Transition srcId="0" dstId="1"><Condition cond="d &gt;= "/></Transition></TransitionInfo></Action>
<Action name="B" actionId="1" final="Yes"/>"#,
    );
    let (_, diags) = load(&text);
    assert_eq!(codes(&diags), ["E003"], "{diags:#?}");
    // At the end of the value, past `&gt;= `.
    let end = text.find("\"/></Transition>").unwrap();
    assert_eq!(diags[0].span, Span::new(end, end));
}

#[test]
fn a_malformed_initial_is_reported_once() {
    let text = with_actions(
        r#"<Action name="A" initial="maybe" actionId="0"/><Action name="B" actionId="1" final="Yes"/>"#,
    );
    let (s, diags) = load(&text);
    assert_eq!(codes(&diags), ["E084"], "{diags:#?}");
    assert!(s.services[0].actions[0].initial.is_malformed());
}

#[test]
fn every_action_of_several_initial_ones_counts_as_a_start() {
    let text = with_actions(
        r#"<Action name="A" initial="Yes" actionId="0"/>
<Action name="B" initial="Yes" actionId="1"><TransitionInfo><Transition srcId="1" dstId="2"/></TransitionInfo></Action>
<Action name="C" actionId="2" final="Yes"/>"#,
    );
    let (_, diags) = load(&text);
    assert_eq!(codes(&diags), ["E087"], "{diags:#?}");
    assert_eq!(at(&text, diags[0].span), "Yes");
    assert!(diags[0].span.start > text.find("name=\"B\"").unwrap());
}

#[test]
fn a_service_cut_short_by_malformed_xml_is_not_checked_as_a_machine() {
    let text = with_actions(r#"<Action name="A" actionId="0"><Oops></Action>"#);
    let (s, diags) = load(&text);
    // No initial or final action is asked for: the rest of the file was not read.
    assert_eq!(codes(&diags), ["E082", "E080"], "{diags:#?}");
    assert!(!s.services[0].complete);
}

#[test]
fn no_strategy_element_gives_no_strategy() {
    let (s, diags) = load_strategy(FILE, "<Catalog/>");
    assert!(s.is_none());
    assert_eq!(codes(&diags), ["E082"]);
    assert_eq!(diags[0].suggestion, None);
    let (s, diags) = load_strategy(FILE, "<Stratgy name=\"T\"/>");
    assert!(s.is_none());
    assert_eq!(diags[0].suggestion.as_deref(), Some("Strategy"));
    let (s, diags) = load_strategy(FILE, "");
    assert!(s.is_none());
    assert_eq!(codes(&diags), ["E080"]);
}

// --- against the catalog and the missions ------------------------------------

fn mission(file: FileId, text: &str, catalog: &Catalog) -> CheckedMission {
    let analysis = crate::check_source(file, text, catalog);
    let errors: Vec<_> = analysis
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    analysis
}

fn cross(
    strategies: &[&Strategy],
    missions: &[&CheckedMission],
) -> (StrategyLinks, Vec<Diagnostic>) {
    cross_check(strategies, missions, &builtin_catalog())
}

#[test]
fn the_scouting_calls_of_move_are_linked_to_the_strategy_entry() {
    let catalog = builtin_catalog();
    let analysis = mission(MISSION, SCOUTING, &catalog);
    let (s, _) = load(SCOUTING_STRATEGY);
    let (links, diags) = cross(&[&s], &[&analysis]);
    assert!(diags.is_empty(), "{diags:#?}");
    let calls = links.calls();
    assert_eq!(calls.len(), 2, "{calls:#?}");
    let team = analysis.mission.team_by_name("MasterTeam").unwrap();
    let entry = ServiceEntryRef {
        file: FILE,
        index: 0,
    };
    for (link, service) in calls.iter().zip(["AutonomousReturn", "AutonomousMove"]) {
        assert_eq!(at(SCOUTING, link.call), "move");
        assert_eq!(link.mission, MISSION);
        assert_eq!(link.team, team);
        assert_eq!(link.entry, entry);
        let t = analysis.mission.team(team);
        assert_eq!(t.services[link.service.index()].name, service);
    }
    // Go-to-definition from inside, or right after, the called name.
    let offset = calls[1].call.start + 2;
    assert_eq!(links.at(MISSION, offset).count(), 1);
    assert_eq!(links.at(MISSION, calls[1].call.end).count(), 1);
    assert_eq!(links.at(MISSION, calls[1].call.end + 1).count(), 0);
    assert_eq!(links.at(FileId(99), offset).count(), 0);
    assert_eq!(links.of_entry(entry).count(), 2);
}

const SMALL: &str = r#"{ T: iRobotCreate a }
def go { stand_by() }
T.Action.Go { go() } repeat()
T.Report.Say { stop() } repeat()
T.M { set(Action, Go) set(Report, Say) }
T.main { default: mode = M }
"#;

#[test]
fn calls_through_functions_and_aliases_are_linked() {
    let catalog = builtin_catalog();
    let analysis = mission(MISSION, SMALL, &catalog);
    let text = r#"<Strategy name="T"><ServiceInfo><Service plan_name="Action" name="standby">
<TargetRobot name="iRobotCreate"/><ActionInfo><Action name="A" initial="Yes" final="Yes" actionId="0"/></ActionInfo>
</Service></ServiceInfo></Strategy>"#;
    let (s, diags) = load(text);
    assert!(diags.is_empty(), "{diags:#?}");
    let (links, diags) = cross(&[&s], &[&analysis]);
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(links.calls().len(), 1);
    let link = &links.calls()[0];
    assert_eq!(at(SMALL, link.call), "stand_by");
    let team = analysis.mission.team(link.team);
    assert_eq!(team.services[link.service.index()].name, "Go");
}

#[test]
fn a_team_of_two_missions_is_checked_against_each() {
    let catalog = builtin_catalog();
    let one = mission(MISSION, SMALL, &catalog);
    let other_text = SMALL.replace("stand_by()", "stop()");
    let other = mission(FileId(2), &other_text, &catalog);
    let text = r#"<Strategy name="T"><ServiceInfo><Service plan_name="Action" name="standby">
<TargetRobot name="iRobotCreate"/><ActionInfo><Action name="A" initial="Yes" final="Yes" actionId="0"/></ActionInfo>
</Service></ServiceInfo></Strategy>"#;
    let (s, _) = load(text);
    let (links, diags) = cross(&[&s], &[&one, &other]);
    assert_eq!(links.calls().len(), 1);
    assert_eq!(codes(&diags), ["E091"], "{diags:#?}");
    assert_eq!(diags[0].related[0].file, FileId(2));
    assert!(
        diags[0]
            .message
            .contains("calls `standby` in plan Action: team T never calls it")
    );
}

#[test]
fn without_missions_only_the_catalog_is_checked() {
    let text = r#"<Strategy name="Nobody"><ServiceInfo><Service plan_name="Nowhere" name="move">
<TargetRobot name="iRobotCreat"/><ActionInfo><Action name="A" initial="Yes" final="Yes" actionId="0"/></ActionInfo>
</Service></ServiceInfo></Strategy>"#;
    let (s, _) = load(text);
    let (links, diags) = cross(&[&s], &[]);
    assert!(links.calls().is_empty());
    assert_eq!(codes(&diags), ["E010"], "{diags:#?}");
    assert_eq!(diags[0].suggestion.as_deref(), Some("iRobotCreate"));
}

#[test]
fn tasks_of_robots_with_task_graphs_are_not_checked() {
    let robot = r#"<Catalog><Robot type="GraphBot">
<Value name="HEAT" type="int" task="heat"/>
<Service name="move" graph="move.taskgraph.xml"/>
</Robot></Catalog>"#;
    let (catalog, diags) = load_catalog(&[CatalogSource {
        file: FileId(3),
        text: robot,
        base_dir: None,
    }]);
    assert!(diags.is_empty(), "{diags:#?}");
    let strategy = |robot: &str| {
        format!(
            r#"<Strategy name="T"><ValueInfo><Value name="HEAT"><TargetRobot name="{robot}"/>
<CheckSensor name="S"><Parameter name="h" type="int" dataCharacteristic="channel" srcTask="thermo" dstTask="ControlTask"/></CheckSensor>
</Value></ValueInfo></Strategy>"#
        )
    };
    let (s, _) = load(&strategy("GraphBot"));
    let (_, diags) = cross_check(&[&s], &[], &catalog);
    assert!(diags.is_empty(), "{diags:#?}");
    // With a fully known library, the task is checked.
    let (s, _) = load(&strategy("iRobotCreate").replace("HEAT", "DISTANCE"));
    let (_, diags) = cross_check(&[&s], &[], &catalog);
    assert_eq!(codes(&diags), ["E094"], "{diags:#?}");
}

#[test]
fn an_entry_refined_in_two_files_of_a_team_is_a_duplicate() {
    let text = r#"<Strategy name="T"><ServiceInfo><Service plan_name="Report" name="stop">
<TargetRobot name="iRobotCreate"/><ActionInfo><Action name="A" initial="Yes" final="Yes" actionId="0"/></ActionInfo>
</Service></ServiceInfo></Strategy>"#;
    let (a, _) = load_strategy(FileId(4), text);
    let (b, _) = load_strategy(FileId(5), text);
    let (a, b) = (a.unwrap(), b.unwrap());
    let catalog = builtin_catalog();
    let analysis = mission(MISSION, SMALL, &catalog);
    let (links, diags) = cross(&[&a, &b], &[&analysis]);
    assert_eq!(codes(&diags), ["E085"], "{diags:#?}");
    assert_eq!(diags[0].file, FileId(5));
    assert_eq!(diags[0].related[0].file, FileId(4));
    // Both entries refine the call.
    assert_eq!(links.calls().len(), 2);
}

#[test]
fn a_team_with_a_robot_of_unknown_type_is_not_blamed_for_its_targets() {
    let catalog = builtin_catalog();
    let text = SMALL.replace("iRobotCreate a", "iRobotCreat a");
    let analysis = crate::check_source(MISSION, &text, &catalog);
    let strategy = r#"<Strategy name="T"><ValueInfo><Value name="DISTANCE"><TargetRobot name="iRobotCreate"/>
</Value></ValueInfo></Strategy>"#;
    let (s, _) = load(strategy);
    let (_, diags) = cross(&[&s], &[&analysis]);
    assert!(diags.is_empty(), "{diags:#?}");
    // With the type known, another type is not of the team.
    let analysis = mission(MISSION, SMALL, &catalog);
    let (s, _) = load(&strategy.replace("iRobotCreate", "TIEvalbot"));
    let (_, diags) = cross(&[&s], &[&analysis]);
    assert_eq!(codes(&diags), ["E090"], "{diags:#?}");
    assert_eq!(diags[0].related[0].file, MISSION);
    assert_eq!(at(SMALL, diags[0].related[0].span), "T");
}

#[test]
fn group_services_are_read_with_their_positions() {
    let text = r#"<Strategy name="T"><GroupingInfo>
<GroupService name="search" plan_name="Explore"/>
<GroupService name="move"/>
<GroupService plan_name="Explore" nmae="x"/>
</GroupingInfo></Strategy>"#;
    let (s, diags) = load(text);
    let declared = &s.grouping.as_ref().unwrap().group_services;
    assert_eq!(declared.len(), 3);
    let first = &declared[0];
    assert_eq!(at(text, first.name.as_ref().unwrap().span), "search");
    assert_eq!(at(text, first.plan.as_ref().unwrap().span), "Explore");
    assert!(declared[1].plan.is_none());
    // The third lacks `name` (E083) and misspells it (W080).
    assert!(declared[2].name.is_none());
    assert_eq!(codes(&diags), ["E083", "W080"]);
    assert!(at(text, diags[0].span).starts_with("<GroupService plan_name"));
}
