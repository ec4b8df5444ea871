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
    assert_eq!(svg.matches("<g class=\"change").count(), 5);
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

/// `(x0, y0, x1, y1)` of every element of the picture whose tag starts
/// with `prefix` (`<rect class="label"`, a mode's `<rect x=`), in panel
/// coordinates offset by the panel's translation.
fn boxes(svg: &str, prefix: &str) -> Vec<(f64, f64, f64, f64)> {
    let attr = |tag: &str, name: &str| -> f64 {
        let at = tag.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
        tag[at..at + tag[at..].find('"').unwrap()].parse().unwrap()
    };
    let mut out = Vec::new();
    for panel in svg.split("<g class=\"team\"").skip(1) {
        let dy: f64 = panel
            .split_once("translate(0 ")
            .and_then(|(_, rest)| rest.split_once(')'))
            .map(|(y, _)| y.parse().unwrap())
            .unwrap();
        for (i, _) in panel.match_indices(prefix) {
            let tag = &panel[i..i + panel[i..].find("/>").unwrap()];
            let (x, y) = (attr(tag, "x"), attr(tag, "y") + dy);
            out.push((x, y, x + attr(tag, "width"), y + attr(tag, "height")));
        }
    }
    out
}

fn overlap(a: (f64, f64, f64, f64), b: (f64, f64, f64, f64)) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Every mission of the examples and the diagnostics fixtures.
fn every_mission() -> Vec<(std::path::PathBuf, String)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for folder in [
        "examples",
        "tests/fixtures/diagnostics",
        "tests/fixtures/build",
    ] {
        for entry in walkdir::WalkDir::new(root.join(folder)).sort_by_file_name() {
            let entry = entry.unwrap();
            if entry.path().extension().is_some_and(|e| e == "mission") {
                let text = std::fs::read_to_string(entry.path()).unwrap();
                found.push((entry.path().to_path_buf(), text));
            }
        }
    }
    assert!(found.len() > 20, "{} missions", found.len());
    found
}

#[test]
fn labels_never_cover_each_other_or_a_mode_and_arrowheads_never_stack() {
    let mut drawn = 0;
    for (path, text) in every_mission() {
        let svg = to_svg(&machines_of(&text));
        let labels = boxes(&svg, "<rect class=\"label\"");
        let modes = boxes(&svg, "<rect x=");
        drawn += labels.len();
        for (i, a) in labels.iter().enumerate() {
            for b in &labels[i + 1..] {
                assert!(
                    !overlap(*a, *b),
                    "{}: labels {a:?} and {b:?}",
                    path.display()
                );
            }
            for m in &modes {
                assert!(
                    !overlap(*a, *m),
                    "{}: label {a:?} on mode {m:?}",
                    path.display()
                );
            }
        }
        // The arrows' ends (the last point of each change's path).
        let mut heads: Vec<(f64, f64)> = svg
            .split("<g class=\"change")
            .skip(1)
            .filter_map(|g| {
                let d = g.split_once(" d=\"")?.1.split_once('"')?.0;
                let nums: Vec<f64> = d
                    .split(|c: char| c.is_ascii_alphabetic() || c == ' ')
                    .filter_map(|n| n.parse().ok())
                    .collect();
                Some((nums[nums.len() - 2], nums[nums.len() - 1]))
            })
            .collect();
        heads.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for pair in heads.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            assert!(
                (a.0 - b.0).abs() + (a.1 - b.1).abs() > 3.0,
                "{}: two arrowheads at {a:?} and {b:?}",
                path.display()
            );
        }
    }
    assert!(drawn > 30, "only {drawn} labels drawn");
}

#[test]
fn unreachable_modes_and_catches_that_never_fire_are_drawn_apart() {
    let text = "\
{
  T: iRobotCreate a
}
T.Work.Go{
  throw DONE
} repeat()
T.BUSY{ set(Work, Go) }
T.IDLE{ set(Work, OFF) }
T.LOST{ set(Work, OFF) }
T.main{
  case (BUSY):
    catch (DONE): mode = IDLE
  case (IDLE):
    catch (DONE): mode = BUSY
  default: mode = BUSY
}
";
    let found = machines_of(text);
    assert_eq!(found[0].unreachable, [2], "LOST is never entered");
    let dead: Vec<bool> = found[0].changes.iter().map(|c| c.is_dead()).collect();
    assert_eq!(dead, [false, true], "IDLE runs nothing that throws DONE");
    let svg = to_svg(&found);
    assert!(svg.contains("<g class=\"mode unreachable\" data-mode=\"LOST\">"));
    assert!(svg.contains("<g class=\"change dead\" data-from=\"IDLE\" data-to=\"BUSY\">"));
    assert!(svg.contains("<g class=\"change\" data-from=\"BUSY\" data-to=\"IDLE\">"));
    assert_eq!(svg.matches("stroke-dasharray").count(), 2);
}

/// A mode with parameters is drawn once per list of arguments it is
/// entered with, each named as entered (`MOVE(kitchen)`); a `case` for it
/// holds in each; a string argument's quotes are escaped in the picture.
#[test]
fn a_mode_with_parameters_is_one_box_per_list_of_arguments() {
    let text = "{ R: iRobotCreate r }\n\
                R.Action.Go(PLACE) { move(PLACE) throw arrived }\n\
                R.MOVE(TARGET) { set(Action, Go(TARGET)) }\n\
                R.main {\n  case (MOVE):\n    catch (arrived): mode = MOVE(\"a<b\")\n  default: mode = MOVE(kitchen)\n}\n";
    let found = machines_of(text);
    let m = &found[0];
    assert_eq!(m.modes, ["MOVE(kitchen)", "MOVE(\"a<b\")"]);
    assert_eq!(m.default, Some(0));
    let changes: Vec<(usize, usize)> = m.changes.iter().map(|c| (c.from, c.to)).collect();
    assert_eq!(changes, [(0, 1), (1, 1)]);
    let svg = to_svg(&found);
    assert!(svg.contains(">MOVE(kitchen)</text>"), "{svg}");
    assert!(
        svg.contains(">MOVE(&quot;a&lt;b&quot;)</text>")
            || svg.contains(">MOVE(\"a&lt;b\")</text>"),
        "{svg}"
    );
}
