use super::*;
use crate::catalog::builtin_catalog;
use crate::diag::FileId;

const PATROL: &str = "\
{
  Guards: iRobotCreate a
  Scouts: iRobotCreate b
}
Guards.Patrol.Walk{
  throw ALARM
  throw CALM
  throw HOLD
} repeat()
Guards.IDLE{
  set(Patrol, OFF)
}
Guards.ACTIVE{
  set(Patrol, Walk)
}
Guards.ALERT{
  set(Patrol, OFF)
}
Guards.main{
  case (IDLE):
    catch (ALARM): mode = ALERT
    catch (CALM): mode = ACTIVE
  case (ACTIVE):
    catch (ALARM): mode = ALERT
    catch (HOLD): mode = ACTIVE
  case (ALERT):
    catch (CALM): mode = IDLE
    catch (HOLD): mode = IDLE
  default: mode = IDLE
}
";

fn machines_of(text: &str) -> Vec<ModeMachine> {
    let catalog = builtin_catalog();
    machines(&crate::check_source(FileId(0), text, &catalog).mission)
}

#[test]
fn a_machine_has_the_modes_the_default_and_one_change_per_pair_of_modes() {
    let found = machines_of(PATROL);
    // Scouts have no modes: no machine.
    assert_eq!(found.len(), 1);
    let m = &found[0];
    assert_eq!(m.team, "Guards");
    assert_eq!(m.modes, ["IDLE", "ACTIVE", "ALERT"]);
    assert_eq!(m.default, Some(0));
    let changes: Vec<(usize, usize, Vec<&str>)> = m
        .changes
        .iter()
        .map(|c| (c.from, c.to, c.events.iter().map(|e| e.as_str()).collect()))
        .collect();
    assert_eq!(
        changes,
        [
            (0, 2, vec!["ALARM"]),
            (0, 1, vec!["CALM"]),
            (1, 2, vec!["ALARM"]),
            (1, 1, vec!["HOLD"]),
            (2, 0, vec!["CALM", "HOLD"]),
        ]
    );
}

#[test]
fn the_picture_shows_modes_events_the_default_and_a_self_loop() {
    let svg = to_svg(&machines_of(PATROL));
    insta::assert_snapshot!(svg);
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(svg.contains("<g class=\"mode default\" data-mode=\"IDLE\">"));
    assert_eq!(svg.matches("class=\"initial\"").count(), 1);
    assert!(svg.contains(">CALM, HOLD</text>"));
    assert!(svg.contains("data-from=\"ACTIVE\" data-to=\"ACTIVE\""));
    assert_eq!(svg.matches("<g class=\"change\"").count(), 5);
}

#[test]
fn broken_missions_still_draw() {
    // A main naming unknown modes, a team without main, text that does not parse.
    for text in [
        "{\n T: iRobotCreate a\n}\nT.A{\n}\nT.main{\n case (A):\n  catch (E): mode = NOPE\n default: mode = GONE\n}\n",
        "{\n T: iRobotCreate a\n}\nT.A{\n}\n",
        "{ T: \nT.main{ case (",
        "",
    ] {
        let svg = to_svg(&machines_of(text));
        assert!(svg.trim_end().ends_with("</svg>"), "{text:?}: {svg}");
    }
    assert!(to_svg(&[]).contains("This mission has no modes."));
}

#[test]
fn the_scouting_example_draws_both_teams() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/scouting/scouting.mission"
    );
    let text = std::fs::read_to_string(path).expect("the scouting example");
    let found = machines_of(&text);
    assert_eq!(
        found.iter().map(|m| m.team.as_str()).collect::<Vec<_>>(),
        ["MasterTeam", "SlaveTeam"]
    );
    let svg = to_svg(&found);
    assert!(svg.contains("data-team=\"MasterTeam\""));
    assert!(svg.contains("data-team=\"SlaveTeam\""));
}
