//! Scenario completion on the scouting example: each fixture is a scenario
//! text with the cursor at `$0`, and the labels offered there.

use super::*;
use crate::sim::tests::programs;

fn labels_at(fixture: &str) -> Vec<String> {
    at(fixture).into_iter().map(|c| c.label).collect()
}

fn at(fixture: &str) -> Vec<ScenarioCompletion> {
    let offset = fixture.find("$0").expect("a cursor marker $0");
    let text = fixture.replacen("$0", "", 1);
    completions(
        &text,
        offset,
        &programs("examples/scouting/scouting.mission"),
    )
}

#[test]
fn robot_names_in_every_key_that_names_a_robot() {
    let robots = ["irobot", "ti", "nxt"];
    for fixture in [
        r#"{"expect": [{"robot": "$0"}]}"#,
        r#"{"expect": [{"robot": "i$0rob", "enters": "X"}]}"#,
        r#"{"faults": [{"at": 1, "kill": "$0"}]}"#,
        r#"{"faults": [{"from": 1, "until": 2, "drop": ["ti", "$0"]}]}"#,
        r#"{"faults": [{"from": 1, "until": 2, "partition": [["ti"], ["$0"]]}]}"#,
        r#"{"network": {"links": [{"between": ["$0"]}]}}"#,
        r#"{"robots": {"$0"#,
        r#"{"robots": {"ti": {}, $0}}"#,
    ] {
        assert_eq!(labels_at(fixture), robots, "{fixture}");
    }
}

#[test]
fn operator_commands_go_to_robots_and_teams_with_the_user_values_they_read() {
    assert_eq!(
        labels_at(r#"{"operator": [{"at": 0, "to": "$0"}]}"#),
        ["irobot", "ti", "nxt", "MasterTeam", "SlaveTeam"]
    );
    assert_eq!(
        labels_at(r#"{"operator": [{"at": 0, "to": "irobot", "value": "$0"}]}"#),
        ["RC_CMD"]
    );
    // The constants irobot compares USER.RC_CMD with, whichever key comes first.
    assert_eq!(
        labels_at(r#"{"operator": [{"is": "$0", "to": "irobot", "value": "RC_CMD"}]}"#),
        ["RC_MODE", "AUTO_MODE", "RETURN_MODE"]
    );
}

#[test]
fn sensor_values_services_and_their_constants_are_the_robots_own() {
    assert_eq!(
        labels_at(r#"{"robots": {"ti": {"sensors": [{"at": 0, "value": "$0"}]}}}"#),
        ["COLOR", "LOCATION"]
    );
    assert_eq!(
        labels_at(r#"{"robots": {"ti": {"sensors": [{"value": "COLOR", "is": "$0"}]}}}"#),
        ["RGB"]
    );
    assert_eq!(
        labels_at(r#"{"robots": {"ti": {"services": {"$0"}}}}"#),
        ["process", "search", "move"]
    );
}

#[test]
fn modes_are_the_named_robots_and_receives_its_incoming_keys() {
    let master = ["RC_MODE", "AUTO_MODE", "WAIT_MODE", "RETURN_MODE", "FINISH"];
    assert_eq!(
        labels_at(r#"{"expect": [{"robot": "irobot", "enters": "$0"}]}"#),
        master
    );
    assert_eq!(
        labels_at(r#"{"expect": [{"never_enters": "$0", "robot": "ti"}]}"#),
        [
            "AUTO_MODE",
            "SEARCH_MODE",
            "RC_MODE",
            "RETURN_MODE",
            "FINISH"
        ]
    );
    assert_eq!(
        labels_at(r#"{"expect": [{"robot": "irobot", "receives": "$0"}]}"#),
        ["USER.RC_CMD", "SlaveTeam.COLOR", "SlaveTeam.LOCATION"]
    );
}

/// Inside a property's conditions, however deep: the modes of the
/// condition's robot, the robots, the keys it receives.
#[test]
fn a_propertys_conditions_complete_the_missions_names() {
    assert_eq!(
        labels_at(r#"{"expect": [{"always": {"not": {"all": [{"robot": "ti", "in": "S$0"}]}}}]}"#),
        [
            "AUTO_MODE",
            "SEARCH_MODE",
            "RC_MODE",
            "RETURN_MODE",
            "FINISH"
        ]
    );
    assert_eq!(
        labels_at(r#"{"expect": [{"leads_to": [{"robot": "$0"}]}]}"#),
        ["irobot", "ti", "nxt"]
    );
    assert_eq!(
        labels_at(r#"{"expect": [{"eventually": {"robot": "irobot", "receives": "$0"}}]}"#),
        ["USER.RC_CMD", "SlaveTeam.COLOR", "SlaveTeam.LOCATION"]
    );
}

#[test]
fn a_string_is_replaced_inside_its_quotes_and_a_bare_place_gets_quotes() {
    let text = r#"{"expect": [{"robot": "ir", "enters": "X"}]}"#;
    let inside = at(r#"{"expect": [{"robot": "ir$0", "enters": "X"}]}"#);
    let start = text.find("ir\"").unwrap();
    assert_eq!(inside[0].replace, Span::new(start, start + 2));
    assert_eq!(inside[0].insert, "irobot");
    let bare = at(r#"{"expect": [{"robot": $0}]}"#);
    assert_eq!(bare[0].insert, "\"irobot\"");
    assert!(bare[0].replace.is_empty());
}

#[test]
fn nothing_outside_the_keys_that_name_something() {
    for fixture in [
        r#"{"duration": $0}"#,
        r#"{"expect": [{"robot": "ti", "before": 1$0}]}"#,
        r#"{"$0"}"#,
        r#"{"robots": {"ti": {"sensors": [{"at": "$0"}]}}}"#,
        r#"$0"#,
    ] {
        assert_eq!(labels_at(fixture), Vec::<String>::new(), "{fixture}");
    }
}

#[test]
fn the_mission_of_a_scenario_is_named_by_its_file_name() {
    assert_eq!(
        mission_for(Path::new("/m/scouting.scenario.json")),
        Some(PathBuf::from("/m/scouting.mission"))
    );
    assert_eq!(
        mission_for(Path::new("/m/scouting.faults.scenario.json")),
        Some(PathBuf::from("/m/scouting.mission"))
    );
    assert!(is_scenario(Path::new("a/b.scenario.json")));
    assert!(!is_scenario(Path::new("a/b.json")));
}

#[test]
fn any_cursor_in_any_prefix_of_a_scenario_is_answered_without_a_panic() {
    let programs = programs("examples/scouting/scouting.mission");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/fixtures/build/scouting.scenario.json"),
    )
    .unwrap();
    let text = format!("{text}\"é\\\"\u{1F600}\\");
    let mut offered = 0;
    for end in (0..=text.len())
        .filter(|&e| text.is_char_boundary(e))
        .step_by(61)
    {
        let prefix = &text[..end];
        for offset in (0..=end).filter(|&o| prefix.is_char_boundary(o)) {
            for c in completions(prefix, offset, &programs) {
                assert!(c.replace.start <= offset && offset <= c.replace.end.max(offset));
                assert!(
                    prefix.is_char_boundary(c.replace.start)
                        && prefix.is_char_boundary(c.replace.end)
                );
                offered += 1;
            }
        }
    }
    assert!(offered > 0);
}
