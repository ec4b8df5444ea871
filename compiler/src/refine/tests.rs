//! Refinement as a specification: which robot runs what, which tasks its
//! graph gets, and which services become strategy action machines.

use super::*;
use crate::catalog::builtin_catalog;
use crate::diag::FileId;
use crate::strategy::{StrategyLinks, cross_check, load_strategy};

fn shared(path: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The programs of a mission (with the given strategy files), asserting that
/// refinement reports nothing.
fn programs(text: &str, strategies: &[&str]) -> Vec<RobotProgram> {
    let catalog = builtin_catalog();
    let analysis = crate::check_source(FileId(0), text, &catalog);
    assert!(!analysis.has_errors(), "{:#?}", analysis.diagnostics);
    let strategies: Vec<_> = strategies
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let (strategy, diagnostics) = load_strategy(FileId(1 + i as u32), s);
            assert!(diagnostics.is_empty(), "{diagnostics:#?}");
            strategy
        })
        .collect();
    let (links, cross) = if strategies.is_empty() {
        (StrategyLinks::default(), Vec::new())
    } else {
        cross_check(
            &strategies.iter().collect::<Vec<_>>(),
            &[&analysis],
            &catalog,
        )
    };
    let errors: Vec<_> = cross
        .iter()
        .filter(|d| d.severity == crate::diag::Severity::Error)
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    let names: Vec<_> = strategies
        .iter()
        .map(|s| (s.file, "strategy.xml".to_string()))
        .collect();
    let input = RefineInput {
        mission_name: "test.mission",
        file: FileId(0),
        text,
        analysis: &analysis,
        catalog: &catalog,
        strategies: &strategies,
        strategy_names: &names,
        links: &links,
        service_graphs: &[],
    };
    let (programs, diagnostics) = refine(&input);
    assert!(diagnostics.is_empty(), "{diagnostics:#?}");
    programs
}

fn program<'p>(programs: &'p [RobotProgram], robot: &str) -> &'p RobotProgram {
    programs.iter().find(|p| p.robot == robot).unwrap()
}

/// The built-in calls a robot's services make, in order.
fn calls(program: &RobotProgram) -> Vec<String> {
    program
        .control
        .services
        .iter()
        .flat_map(|s| &s.states)
        .filter_map(|s| match &s.kind {
            StateKind::Call { service, .. } => Some(service.clone()),
            StateKind::RunActions { service, .. } => Some(format!("{service} (strategy)")),
            _ => None,
        })
        .collect()
}

fn task_names(program: &RobotProgram) -> Vec<&str> {
    program
        .graph
        .tasks
        .iter()
        .map(|t| t.name.name.as_str())
        .collect()
}

/// A strategy refining `search(ROOM2)` by an algorithm: what each of its
/// parameters gives the `search` task, `room` declared as the action's
/// variable (so the call's first argument) and `target` the catalog's own
/// name of `search`'s parameter.
fn searching_strategy(parameters: &str) -> String {
    format!(
        r#"<Strategy name="Finders" xmlns="urn:semo:strategy:1">
  <ServiceInfo>
    <Service plan_name="Act" name="search">
      <TargetRobot name="TIEvalbot"/>
      <ActionInfo>
        <Action name="Search" initial="Yes" actionId="0">
          <Parameter name="room" type="string" dataCharacteristic="variable"/>
          <ExecuteAlgorithm name="Search">
            {parameters}
          </ExecuteAlgorithm>
          <TransitionInfo><Transition srcId="0" dstId="1"/></TransitionInfo>
        </Action>
        <Action name="Done" final="Yes" actionId="1"/>
      </ActionInfo>
    </Service>
  </ServiceInfo>
</Strategy>"#
    )
}

const SEARCHING_MISSION: &str = "{ Finders: TIEvalbot ti }
Finders.Act.Look{ search(ROOM2) }
Finders.LOOK{ set(Act, Look) }
Finders.main{ default: mode = LOOK }
";

/// What the `search` task is given, per command of the action machine.
fn algorithm_inputs(parameters: &str) -> Vec<Operand> {
    let programs = programs(SEARCHING_MISSION, &[&searching_strategy(parameters)]);
    let machine = &program(&programs, "ti").control.actions[0];
    let commands = &machine.actions[0].commands;
    assert!(
        commands.iter().all(|(task, _)| task == "search"),
        "{commands:?}"
    );
    commands.iter().map(|(_, given)| given.clone()).collect()
}

#[test]
fn an_algorithm_is_given_the_call_argument_its_parameter_names() {
    let refined = programs(
        SEARCHING_MISSION,
        &[&searching_strategy(
            r#"<Parameter name="where" type="string" value="room" dataCharacteristic="sysRequest" dstTask="search"/>"#,
        )],
    );
    let ti = program(&refined, "ti");
    let machine = &ti.control.actions[0];
    let room = machine.arguments[0];
    // The call stores ROOM2 in the argument's slot; the algorithm reads it.
    let args = ti
        .control
        .services
        .iter()
        .flat_map(|s| &s.states)
        .find_map(|s| match &s.kind {
            StateKind::RunActions { args, .. } => Some(args.clone()),
            _ => None,
        });
    assert_eq!(
        args,
        Some(vec![Operand::Literal(Value::Word("ROOM2".into()))])
    );
    assert_eq!(
        machine.actions[0].commands,
        [("search".to_string(), Operand::Slot(room))]
    );
    // The service's own parameter by its catalog name is the same argument;
    // a value naming nothing is the word as written.
    let given = algorithm_inputs(
        r#"<Parameter name="target" type="string" dataCharacteristic="sysRequest" dstTask="search"/>
           <Parameter name="mode" type="string" value="fast" dataCharacteristic="sysRequest" dstTask="search"/>"#,
    );
    assert_eq!(
        given,
        [
            Operand::Slot(room),
            Operand::Literal(Value::Word("fast".into()))
        ]
    );
    // Without the variable, the catalog's name alone binds the argument.
    let given = programs(
        SEARCHING_MISSION,
        &[&searching_strategy(
            r#"<Parameter name="target" type="string" dataCharacteristic="sysRequest" dstTask="search"/>"#,
        )
        .replace(r#"<Parameter name="room" type="string" dataCharacteristic="variable"/>"#, "")],
    );
    let machine = &program(&given, "ti").control.actions[0];
    assert_eq!(machine.arguments.len(), 1);
    assert_eq!(
        machine.actions[0].commands,
        [("search".to_string(), Operand::Slot(machine.arguments[0]))]
    );
}

#[test]
fn every_robot_gets_a_program_with_its_peers() {
    let programs = programs(&shared("scouting/scouting.mission"), &[]);
    let robots: Vec<_> = programs
        .iter()
        .map(|p| (p.team.as_str(), p.robot.as_str()))
        .collect();
    assert_eq!(
        robots,
        [
            ("MasterTeam", "irobot"),
            ("SlaveTeam", "ti"),
            ("SlaveTeam", "nxt")
        ]
    );
    assert_eq!(programs[2].self_peer, PeerId::new(2));
    assert_eq!(programs[0].peers.len(), 3);
}

#[test]
fn the_strategy_refines_the_masters_move_only() {
    let programs = programs(
        &shared("scouting/scouting.mission"),
        &[&shared("scouting/MasterTeam.strategy.xml")],
    );
    let master = program(&programs, "irobot");
    // Services in the order the modes set them (RC_MODE first).
    assert_eq!(
        calls(master),
        ["process", "move (strategy)", "standby", "move (strategy)"]
    );
    let actions = &master.control.actions[0];
    let names: Vec<_> = actions.actions.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "CheckGoal",
            "CheckObstacle",
            "MoveToGoal",
            "AvoidObstacle",
            "Finish"
        ]
    );
    assert_eq!(
        actions.actions[2].commands,
        [(
            "wheel".to_string(),
            Operand::Literal(crate::refine::Value::Word("Forward".into()))
        )]
    );
    // The slaves have no strategy: their move calls the implementing task.
    assert_eq!(
        calls(program(&programs, "ti")),
        ["move", "search", "process", "move"]
    );
}

#[test]
fn battery_requirements_become_policies_over_the_robots_own_tasks() {
    let programs = programs(
        &shared("scouting/scouting.mission"),
        &[&shared("scouting/MasterTeam.strategy.xml")],
    );
    let master = program(&programs, "irobot");
    let [policy] = &master.control.battery[..] else {
        panic!("{:?}", master.control.battery);
    };
    assert_eq!(policy.text, "Battery<30");
    // `Camera` is the task of that name; `Ultrasonic` the task its
    // `CheckSensor` reads; `Move` the task its `ExecuteActuator` drives.
    let named = |list: &[(String, u64)]| -> Vec<(String, u64)> { list.to_vec() };
    assert_eq!(
        named(&policy.sensors),
        [("camera".to_string(), 2), ("ultrasonic".to_string(), 2)]
    );
    assert_eq!(named(&policy.actuators), [("wheel".to_string(), 2)]);
    // The condition reads the robot's own battery, sampled by its task.
    let Expr::Compare(
        Operand::Slot(slot),
        _,
        Operand::Literal(limit),
        crate::sema::Compared::Numbers,
    ) = &policy.condition
    else {
        panic!("{:?}", policy.condition);
    };
    assert_eq!(limit, &crate::refine::Value::Int(30));
    assert!(matches!(
        &master.control.slots[slot.index()].source,
        SlotSource::Sensor { port, .. } if port == "BATTERY"
    ));
    assert!(task_names(master).contains(&"battery"));
    // Levels: the highest of the policies that hold, 1 when none does.
    assert_eq!(master.control.battery_level("wheel", false, &[true]), 2);
    assert_eq!(master.control.battery_level("wheel", false, &[false]), 1);
    assert_eq!(master.control.battery_level("wheel", true, &[true]), 1);
    // The slaves' team has no strategy, so no policy.
    assert!(program(&programs, "ti").control.battery.is_empty());
}

#[test]
fn the_task_graph_has_sensor_service_and_communication_tasks() {
    let programs = programs(&shared("scouting/scouting.mission"), &[]);
    assert_eq!(
        task_names(program(&programs, "ti")),
        // The control task after the tasks that feed it, before the one
        // it feeds (in lock-step, the order of one instant's turns).
        [
            "color",
            "odometry",
            "remote_control",
            "search",
            "wheel",
            "CommReceive",
            "ControlTask",
            "CommSend"
        ]
    );
    let ti = program(&programs, "ti");
    let lib = ti.library.as_ref().unwrap();
    assert_eq!(lib.name, "SlaveTeamShared");
    assert!(
        lib.attributes.contains(&"USER.RC_CMD".to_string()),
        "{lib:?}"
    );
    // One capacity per channel, at least what refinement declared.
    assert_eq!(ti.capacities.len(), ti.graph.channels.len());
    assert!(ti.capacities.iter().all(|&c| c >= 2));
}

#[test]
fn robots_of_one_declaration_share_one_control_machine() {
    let programs = programs(&shared("swarm/patrol_groups.mission"), &[]);
    let machine = |robot: &str| &program(&programs, robot).control;
    // `tb[3]`: one machine for the three turtlebots, the same in memory
    // (not a copy), and another for the Ev3 robots, whose group arm
    // differs.
    assert!(std::sync::Arc::ptr_eq(machine("tb_0"), machine("tb_1")));
    assert!(std::sync::Arc::ptr_eq(machine("tb_0"), machine("tb_2")));
    assert!(std::sync::Arc::ptr_eq(machine("ev_0"), machine("ev_1")));
    assert!(!std::sync::Arc::ptr_eq(machine("tb_0"), machine("ev_0")));
    assert_ne!(**machine("tb_0"), **machine("ev_0"));
    // What differs between them lies outside the machine.
    assert_ne!(
        program(&programs, "tb_0").self_peer,
        program(&programs, "tb_1").self_peer
    );
}

#[test]
fn group_arms_a_robot_can_never_join_are_dropped() {
    let programs = programs(&shared("swarm/patrol_groups.mission"), &[]);
    // Turtlebots watch the light (group arm); Ev3 robots patrol (others).
    let tb = calls(program(&programs, "tb_1"));
    let ev = calls(program(&programs, "ev_0"));
    assert!(!tb.contains(&"move".to_string()), "{tb:?}");
    assert!(ev.iter().filter(|c| *c == "move").count() >= 2, "{ev:?}");
    assert!(!ev.contains(&"light_on".to_string()), "{ev:?}");
    // `leader(instance of Turtlebot3_Burger)`: every turtlebot can lead, and
    // an election at run time among peers 1-3 (tb_0..tb_2) decides; the Ev3
    // robots never take part.
    let branches = |robot: &str| -> Vec<Vec<usize>> {
        program(&programs, robot)
            .control
            .services
            .iter()
            .flat_map(|s| &s.states)
            .filter_map(|s| match &s.kind {
                StateKind::LeaderBranch { candidates, .. } => {
                    Some(candidates.iter().map(|p| p.index()).collect())
                }
                _ => None,
            })
            .collect()
    };
    assert_eq!(branches("tb_1"), [vec![1, 2, 3]]);
    assert!(calls(program(&programs, "tb_1")).contains(&"light_on".to_string()));
    assert!(program(&programs, "tb_1").control.heartbeat);
    assert!(branches("ev_0").is_empty());
    assert!(!program(&programs, "ev_0").control.heartbeat);
}

#[test]
fn functions_are_inlined_into_the_services_that_call_them() {
    let text = "{ T: iRobotCreate r }\ndef patrol { move(\"1,1\")\n stop() }\nT.A.S{ patrol()\n patrol() }\nT.M{ set(A, S) }\nT.main{ default: mode = M }\n";
    let programs = programs(text, &[]);
    assert_eq!(calls(&programs[0]), ["move", "stop", "move", "stop"]);
}

#[test]
fn control_structures_become_states_with_jumps() {
    let text = "{ T: iRobotCreate r }\nT.A.S{\n loop(1 SEC, DISTANCE > 10) { go_forward() }\n if (DISTANCE < 5) throw near else stop()\n} repeat(2 SEC)\nT.M{ set(A, S) }\nT.N{ set(A, OFF) }\nT.main{ case (M): catch (near): mode = N\n default: mode = M }\n";
    let programs = programs(text, &[]);
    let states: Vec<String> = programs[0].control.services[0]
        .states
        .iter()
        .map(|s| match &s.kind {
            StateKind::LoopHead { exit_to, .. } => format!("loop-head exit {exit_to}"),
            StateKind::LoopTail { to, period_ms, .. } => format!("loop-tail {period_ms:?} to {to}"),
            StateKind::Call { service, .. } => service.clone(),
            StateKind::Branch { else_to, .. } => format!("branch else {else_to}"),
            StateKind::Jump { to } => format!("jump {to}"),
            StateKind::Throw {
                event,
                broadcast: None,
            } => format!("throw {event}"),
            StateKind::Repeat { period_ms, .. } => format!("repeat {period_ms:?}"),
            other => format!("{other:?}"),
        })
        .collect();
    assert_eq!(
        states,
        [
            "loop-head exit 3",
            "go_forward",
            "loop-tail Some(1000) to 0",
            "branch else 6",
            "throw near",
            "jump 7",
            "stop",
            "repeat Some(2000)",
        ]
    );
    let machine = &programs[0].control;
    assert_eq!(machine.modes.len(), 2);
    assert!(machine.modes[1].regions.is_empty(), "N sets every plan OFF");
    assert_eq!(machine.transitions[0].event, "near");
}

/// A comparison compares as the checker typed it (`sema::Compared`): an
/// `int` value against a number by value, the operator's `string` command
/// against a constant by its text. Generated code and the simulator read
/// this, never the values, to decide.
#[test]
fn comparisons_carry_the_checkers_typing() {
    let text = "{\n  Team1: iRobotCreate r\n}\n\nTeam1.Act.Go{\n  if(DISTANCE < 30) throw near\n  if(USER.RC_CMD == LEFT) throw left\n} repeat(1 SEC)\n\nTeam1.M{\n  set(Act, Go)\n}\n\nTeam1.main{\n  case (M):\n    catch (near): mode = M\n    catch (left): mode = M\n  default: mode = M\n}\n";
    let programs = programs(text, &[]);
    let machine = format!("{:?}", program(&programs, "r").control.services);
    assert!(
        machine.contains("Lt, Literal(Int(30)), Numbers)"),
        "{machine}"
    );
    assert!(
        machine.contains("Eq, Literal(Word(\"LEFT\")), Words)"),
        "{machine}"
    );
}

#[test]
fn a_service_graph_becomes_its_looped_schedule_with_loop_nodes_opened() {
    use crate::refine::GraphStep::{Fire, Loop};
    use crate::refine::LoopPort;
    use crate::taskgraph::subgraph::Hierarchy;
    let fire = |task: usize| Fire {
        task: InnerTaskId::new(task),
        count: 1,
    };
    let load = |name: &str| {
        let text = shared(&format!("taskgraphs/{name}.taskgraph.xml"));
        crate::taskgraph::load_task_graph(FileId(9), &text)
            .0
            .unwrap()
    };
    // `A 10(B C) D`: the D-type loop node is the `10(...)`, its ports
    // joining the channels outside (0, 1) to those of its body (2, 4).
    let none = Hierarchy::default();
    let data_loop = robot::steps_of(&load("data_loop"), &none).unwrap();
    let port = |port: &str, input, distributing, outer, inner| LoopPort {
        port: port.into(),
        input,
        distributing,
        outer_rate: 10,
        inner_rate: 1,
        outer: GraphChannelId::new(outer),
        inner: GraphChannelId::new(inner),
    };
    assert_eq!(
        data_loop.steps,
        [
            fire(0),
            Loop {
                path: "L".into(),
                convergent: false,
                loop_count: 10,
                exit_task: None,
                ports: vec![
                    port("in", true, true, 0, 2),
                    port("out", false, false, 1, 4)
                ],
                body: vec![fire(1), fire(2)],
            },
            fire(3),
        ]
    );
    // Each channel bounded by the analysis for the order it runs in: ten
    // tokens outside the loop, one per iteration inside.
    let bounded: Vec<(&str, u64)> = data_loop
        .channels
        .iter()
        .map(|c| (c.label.as_str(), c.capacity))
        .collect();
    assert_eq!(
        bounded,
        [
            ("A.o → L.in", 10),
            ("L.out → D.i", 10),
            ("L: L.in → B.i", 1),
            ("L: B.o → C.i", 1),
            ("L: C.o → L.out", 1),
        ]
    );
    let b = data_loop.tasks.iter().find(|t| t.path == "L/B").unwrap();
    assert_eq!(
        (
            &b.inputs[0].port,
            b.inputs[0].channel,
            &b.outputs[0].port,
            b.outputs[0].channel
        ),
        (
            &"i".to_string(),
            GraphChannelId::new(2),
            &"o".to_string(),
            GraphChannelId::new(3)
        )
    );
    // k-means: a C-type loop (exit task ReplaceCenter) around a D-type one.
    let kmeans = robot::steps_of(&load("kmeans"), &none).unwrap();
    let paths: Vec<&str> = kmeans.tasks.iter().map(|t| t.path.as_str()).collect();
    let kmeans = kmeans.steps;
    let Loop {
        convergent: true,
        loop_count: 500,
        exit_task: Some(exit),
        body,
        ..
    } = &kmeans[2]
    else {
        panic!("{kmeans:?}");
    };
    assert_eq!(paths[exit.index()], "Converge/ReplaceCenter");
    assert!(
        matches!(&body[1], Loop { path, loop_count: 16, convergent: false, .. } if path == "Converge/Assign")
    );
    // No schedule, no program: a deadlocked graph is refused.
    assert!(robot::steps_of(&load("deadlock"), &none).is_err());
}

/// Slots carry the catalog's type of their value (a team variable has
/// none: it holds what was assigned, typed as written), and literals are
/// typed as written.
#[test]
fn slots_and_literals_are_typed_as_the_catalog_declares() {
    let text = "{\n  Team1: iRobotCreate r\n}\n\nTeam1.Act.Go{\n  receive(USER, USER.RC_CMD)\n  send(Team1, Team1.count = 2.5)\n  if(DISTANCE < 30) throw near\n  move(\"5,5\")\n} repeat(1 SEC)\n\nTeam1.M{\n  set(Act, Go)\n}\n\nTeam1.main{\n  case (M):\n    catch (near): mode = M\n  default: mode = M\n}\n";
    let programs = programs(text, &[]);
    let m = &program(&programs, "r").control;
    let kind = |key: &str| &m.slots.iter().find(|s| s.key == key).unwrap().kind;
    assert_eq!(kind("Team1.DISTANCE"), &ValueKind::Int);
    assert_eq!(kind("USER.RC_CMD"), &ValueKind::Text);
    assert_eq!(kind("Team1.count"), &ValueKind::Variable);
    let states = format!("{:?}", m.services);
    assert!(states.contains("Literal(Real(2.5))"), "{states}");
    assert!(states.contains("Literal(Text(\"5,5\"))"), "{states}");
}

/// A task standing for a sub-graph file is one step running the
/// sub-graph's level once: its ports join the channels outside to the
/// sub-graph's boundary channels by port name, the sub-graph's tasks are
/// inner tasks below it, and the steps name tasks by index.
#[test]
fn a_sub_graph_reference_opens_into_a_step_running_its_schedule_once() {
    use crate::refine::GraphStep::{Fire, Subgraph};
    use crate::refine::SubgraphPort;
    use crate::taskgraph::{resolve, subgraph::SubgraphSource};
    use std::path::Path;
    let fixture = |name: &str| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/fixtures/loops/graphs")
            .join(name);
        std::fs::read_to_string(&path).unwrap()
    };
    let (track, diags) =
        crate::taskgraph::load_task_graph(FileId(1), &fixture("track.taskgraph.xml"));
    assert!(diags.is_empty(), "{diags:?}");
    let track = track.unwrap();
    let filter = fixture("filter.taskgraph.xml");
    let mut files = |path: &Path| -> Result<SubgraphSource, String> {
        match path == Path::new("/g/filter.taskgraph.xml") {
            true => Ok(SubgraphSource {
                file: FileId(2),
                text: filter.as_str().into(),
            }),
            false => Err("absent".into()),
        }
    };
    let hierarchy = resolve(
        &track,
        Some(Path::new("/g/track.taskgraph.xml")),
        &mut files,
    );
    assert!(
        hierarchy.diagnostics.is_empty(),
        "{:?}",
        hierarchy.diagnostics
    );
    let opened = robot::steps_of(&track, &hierarchy).unwrap();
    let paths: Vec<&str> = opened.tasks.iter().map(|t| t.path.as_str()).collect();
    assert_eq!(
        paths,
        ["Detect", "Filter/Predict", "Filter/Update", "Steer"]
    );
    let port = |port: &str, input, rate, outer, inner| SubgraphPort {
        port: port.into(),
        input,
        rate,
        outer: GraphChannelId::new(outer),
        inner: GraphChannelId::new(inner),
    };
    let fire = |task, count| Fire {
        task: InnerTaskId::new(task),
        count,
    };
    assert_eq!(
        opened.steps,
        [
            fire(0, 1),
            Subgraph {
                path: "Filter".into(),
                ports: vec![port("in", true, 2, 0, 3), port("out", false, 1, 1, 4)],
                body: vec![fire(1, 2), fire(2, 1)],
            },
            fire(3, 1),
        ]
    );
    let bounded: Vec<(&str, u64)> = opened
        .channels
        .iter()
        .map(|c| (c.label.as_str(), c.capacity))
        .collect();
    assert_eq!(
        bounded,
        [
            ("Detect.o → Filter.in", 2),
            ("Filter.out → Steer.i", 1),
            ("Filter: Predict.p → Update.i", 2),
            ("Filter: Filter.in → Predict.in", 2),
            ("Filter: Update.out → Filter.out", 1),
        ]
    );
    // Predict reads the boundary channel of `in`, Update writes that of `out`.
    assert_eq!(opened.tasks[1].inputs[0].channel, GraphChannelId::new(3));
    assert_eq!(opened.tasks[2].outputs[0].channel, GraphChannelId::new(4));
}

/// A time-triggered inner task carries its period, from the checked model,
/// in whole milliseconds; a period the service task's clock cannot count
/// (a fraction of a millisecond) and a time-triggered task standing for a
/// sub-graph refuse the graph instead of firing it as a data task.
#[test]
fn a_time_triggered_inner_task_carries_its_period() {
    use crate::taskgraph::subgraph::Hierarchy;
    let none = Hierarchy::default();
    let kmeans =
        crate::taskgraph::load_task_graph(FileId(9), &shared("taskgraphs/kmeans.taskgraph.xml"))
            .0
            .unwrap();
    let opened = robot::steps_of(&kmeans, &none).unwrap();
    let periods: Vec<(&str, Option<u64>)> = opened
        .tasks
        .iter()
        .map(|t| (t.path.as_str(), t.period_ms))
        .collect();
    assert_eq!(periods[0], ("ReadPoints", Some(1000)));
    assert!(periods[1..].iter().all(|(_, p)| p.is_none()), "{periods:?}");
    let graph = |period: &str, subgraph: &str| {
        let text = format!(
            r#"<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A" trigger="time" period="{period}"{subgraph}><Port name="o" dir="out"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>"#
        );
        let (graph, diagnostics) = crate::taskgraph::load_task_graph(FileId(9), &text);
        assert!(diagnostics.is_empty(), "{diagnostics:?}");
        graph.unwrap()
    };
    let opened = robot::steps_of(&graph("2 SEC", ""), &none).unwrap();
    assert_eq!(opened.tasks[0].period_ms, Some(2000));
    let refused = robot::steps_of(&graph("0.5 MSEC", ""), &none).unwrap_err();
    assert!(
        refused.contains("`A` with a period of 0.5 ms, not a whole number"),
        "{refused}"
    );
    let refused =
        robot::steps_of(&graph("1 SEC", r#" subgraph="s.taskgraph.xml""#), &none).unwrap_err();
    assert!(refused.contains("standing for a sub-graph"), "{refused}");
    let control = crate::taskgraph::load_task_graph(
        FileId(9),
        r#"<TaskGraph name="g" xmlns="urn:semo:taskgraph:1">
  <Task name="A" trigger="control"><Port name="o" dir="out"/></Task>
  <Task name="B"><Port name="i" dir="in"/></Task>
  <Channel src="A.o" dst="B.i"/>
</TaskGraph>"#,
    )
    .0
    .unwrap();
    let refused = robot::steps_of(&control, &none).unwrap_err();
    assert!(refused.contains("control-triggered task `A`"), "{refused}");
}

/// `throw E broadcast` is told to the robots the checker recorded: one
/// message to the team when they are the whole team, else one to each other
/// robot of the group; each of them hears the event, the others do not.
#[test]
fn a_broadcast_goes_to_the_throwers_group_as_the_checker_recorded_it() {
    let text = "{ T: Turtlebot3_Burger tb[3], Ev3_Robot ev }\nT.A.S{\n [[ group(instance of Turtlebot3_Burger) { scatter() throw near broadcast } ]]\n throw all broadcast\n} repeat(1 SEC)\nT.M{ set(A, S) }\nT.N{ set(A, OFF) }\nT.main{ case (M): catch (near): mode = N\n catch (all): mode = N\n default: mode = M }\n";
    let programs = programs(text, &[]);
    let told = |p: &RobotProgram| -> Vec<Vec<String>> {
        p.control.services[0]
            .states
            .iter()
            .filter_map(|s| match &s.kind {
                StateKind::Throw {
                    event,
                    broadcast: Some(broadcast),
                } => Some(
                    std::iter::once(event.clone())
                        .chain(broadcast.messages.iter().map(|&m| {
                            let o = p.control.outgoing_message(m);
                            assert_eq!((o.key.as_str(), o.publish), ("T.__event", false));
                            o.to_team.clone()
                        }))
                        .collect(),
                ),
                _ => None,
            })
            .collect()
    };
    let by_robot: Vec<(&str, &RobotProgram)> =
        programs.iter().map(|p| (p.robot.as_str(), p)).collect();
    assert_eq!(
        told(by_robot[1].1),
        [vec!["near", "tb_0", "tb_2"], vec!["all", "T"]],
        "tb_1"
    );
    assert_eq!(
        told(by_robot[3].1),
        [vec!["all", "T"]],
        "ev runs no group arm"
    );
    assert_eq!(by_robot[0].1.control.events_heard, ["all", "near"]);
    assert_eq!(by_robot[3].1.control.events_heard, ["all"]);
    assert!(by_robot[3].1.control.has_receiver());
}

/// In an arm of counted groups, the group is chosen at run time: the
/// thrower has one message to each other robot that may run the arm, with
/// the peer it goes to and the arms it is written in, never the team
/// message, even when every robot of the team may run the arm.
#[test]
fn a_broadcast_in_a_counted_arm_names_each_robot_and_the_arms_it_is_in() {
    let text = "{ T: Turtlebot3_Burger tb[3] }\nT.A.S{ [[ group(Room1, min = 1) { scatter() throw near broadcast }\n  group(Room2, min = 1) { standby() } ]] } repeat(1 SEC)\nT.M{ set(A, S) }\nT.N{ set(A, OFF) }\nT.main{ case (M): catch (near): mode = N\n default: mode = M }\n";
    let programs = programs(text, &[]);
    let p = program(&programs, "tb_1");
    let broadcasts: Vec<&Broadcast> = (p.control.services[0].states.iter())
        .filter_map(|s| match &s.kind {
            StateKind::Throw {
                broadcast: Some(b), ..
            } => Some(b),
            _ => None,
        })
        .collect();
    assert_eq!(broadcasts.len(), 1);
    let b = broadcasts[0];
    let to: Vec<usize> = b.to.iter().map(|p| p.index()).collect();
    assert_eq!(to, [0, 2], "the others, in formation order");
    let sent_to: Vec<&str> = (b.messages.iter())
        .map(|&m| p.control.outgoing_message(m).to_team.as_str())
        .collect();
    assert_eq!(sent_to, ["tb_0", "tb_2"], "one message to each, not to T");
    assert_eq!(b.within.len(), 1);
    assert_eq!(b.within[0].arm, Some(0));
    assert_eq!(b.within[0].mins, [1, 1]);
    let members: Vec<usize> = b.within[0].members.iter().map(|p| p.index()).collect();
    assert_eq!(members, [0, 1, 2]);
}

#[test]
fn counted_allocation_fills_the_minimums_in_order_then_spares_go_to_others_or_round_robin() {
    // Room1 min 2, Room2 min 1: positions 0 and 1 to Room1, 2 to Room2.
    let rooms = [2, 1];
    let without: Vec<Option<usize>> = (0..7)
        .map(|p| counted_allocation(&rooms, false, p))
        .collect();
    assert_eq!(
        without,
        [
            Some(0),
            Some(0),
            Some(1),
            Some(0),
            Some(1),
            Some(0),
            Some(1)
        ]
    );
    let with: Vec<Option<usize>> = (0..5)
        .map(|p| counted_allocation(&rooms, true, p))
        .collect();
    assert_eq!(with, [Some(0), Some(0), Some(1), None, None]);
    // Fewer alive than the sum: the first groups are filled, the later short.
    assert_eq!(counted_allocation(&[3, 2], false, 2), Some(0));
    // A minimum as large as the checker lets through does not overflow.
    assert_eq!(counted_allocation(&[usize::MAX, 1], false, 5), Some(0));
}

#[test]
fn counted_groups_put_every_arm_in_every_program_behind_one_allocation() {
    let text = "{ T: Turtlebot3_Burger tb[4], Ev3_Robot ev }\nT.A.S{ [[ group(instance of Turtlebot3_Burger) {\n  [[ group(Room1, min = 2) { scatter() }\n     group(Room2, min = 1) { standby() }\n     others { move(\"0,0\") } ]] }\n  others { move(\"1,1\") } ]] } repeat(1 SEC)\nT.M{ set(A, S) }\nT.main{ default: mode = M }\n";
    let programs = programs(text, &[]);
    // Per GroupAllocate state: its members, its groups (name, min), whether
    // it has `others`.
    type Allocation = (Vec<usize>, Vec<(String, usize)>, bool);
    let allocations = |robot: &str| -> Vec<Allocation> {
        program(&programs, robot)
            .control
            .services
            .iter()
            .flat_map(|s| &s.states)
            .filter_map(|s| match &s.kind {
                StateKind::GroupAllocate {
                    members,
                    groups,
                    others_at,
                    ..
                } => Some((
                    members.iter().map(|p| p.index()).collect(),
                    groups.iter().map(|g| (g.name.clone(), g.min)).collect(),
                    others_at.is_some(),
                )),
                _ => None,
            })
            .collect()
    };
    // The members are the TurtleBots (peers 0-3), as the checker walked the
    // inner statement; the Ev3 robot has no allocation and no heartbeat.
    let rooms = vec![("Room1".to_string(), 2), ("Room2".to_string(), 1)];
    assert_eq!(allocations("tb_3"), [(vec![0, 1, 2, 3], rooms, true)]);
    assert_eq!(
        calls(program(&programs, "tb_3")),
        ["scatter", "standby", "move"],
        "every arm is in the program"
    );
    assert!(program(&programs, "tb_3").control.heartbeat);
    assert!(allocations("ev").is_empty());
    assert!(!program(&programs, "ev").control.heartbeat);
}
