//! `semo verify` as a user reaches it: the findings of the fixtures at
//! their lines and nothing else, each counterexample replayed by `semo
//! simulate` to the state the finding names, and the examples free of
//! findings (the false-positive count of the closing notes).

mod support;

use support::semo;

/// (code, line, message) of each finding of `semo verify MISSION --format
/// json ARGS`, and the document's data.
fn verify(mission: &str, args: &[&str]) -> (i32, Vec<(String, u64, String)>, serde_json::Value) {
    let mut all = vec!["verify", mission, "--format", "json"];
    all.extend(args);
    let out = semo(&all);
    assert!(out.code <= 1, "{all:?}: {}{}", out.stdout, out.stderr);
    let document: serde_json::Value =
        serde_json::from_str(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", out.stdout));
    assert_eq!(document["command"], "verify", "{document}");
    let findings = document["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            (
                d["code"].as_str().unwrap().to_string(),
                d["start"]["line"].as_u64().unwrap(),
                d["message"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    (out.code, findings, document)
}

#[test]
fn a_mode_behind_an_endless_loop_is_never_entered() {
    let (code, findings, data) = verify("tests/fixtures/verify/never_entered/main.mission", &[]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    assert_eq!(findings.len(), 1, "{findings:?}");
    let (code, line, message) = &findings[0];
    assert_eq!((code.as_str(), *line), ("V001", 17), "{message}");
    assert!(message.contains("REST"), "{message}");
}

#[test]
fn a_mode_with_no_way_out_is_found_and_its_counterexample_replays() {
    let dir = support::robots::scratch("verify-never-finishes");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/never_finishes/main.mission";
    let (code, findings, data) = verify(mission, &["--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(findings.len(), 1, "{findings:?}");
    let (code, line, message) = &findings[0];
    // On the mode the robot is stuck in.
    assert_eq!((code.as_str(), *line), ("V002", 18), "{message}");
    assert!(message.contains("WANDER"), "{message}");
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    // Its timeline beside it.
    let svg = std::fs::read_to_string(scenario.replace(".scenario.json", ".svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("WANDER"), "{svg}");
    // The replay ends with the robot in WANDER, not finished.
    let out = semo(&[
        "simulate",
        mission,
        "--scenario",
        &scenario,
        "--format",
        "json",
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let run: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let text = run.to_string();
    assert!(text.contains("WANDER"), "{text}");
    assert!(!text.contains("FINISH"), "{text}");
}

#[test]
fn two_robots_that_each_wait_for_the_other_wait_for_ever() {
    let dir = support::robots::scratch("verify-waits");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/waits_for_ever/main.mission";
    let (code, findings, data) = verify(mission, &["--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    // On each robot's first `receive`.
    assert_eq!(found, [("V003", 7), ("V003", 12)], "{findings:?}");
    // The replay ends with both waiting: the leader never sent.
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(!out.stdout.contains("\"event\":\"send\""), "{}", out.stdout);
}

/// Two plans of one mode get their messages in one instant: the first
/// throws and ends the mode before the second passes a value on (V005, on
/// the throw, the send as related information), so the carrier waits for
/// it for ever (V003). The counterexample replayed: the base throws and
/// never sends to the carriers.
#[test]
fn a_throw_that_ends_the_mode_before_another_plan_sends_is_a_race() {
    let dir = support::robots::scratch("verify-race");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/plans_race/main.mission";
    let (code, findings, data) = verify(mission, &["--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    assert_eq!(found, [("V003", 30), ("V005", 17)], "{findings:?}");
    let race = &data["diagnostics"][1];
    let message = race["message"].as_str().unwrap();
    assert!(
        message.contains("plan Listen") && message.contains("plan Forward"),
        "{message}"
    );
    assert_eq!(race["related"][0]["line"], 22, "{race}");
    // The replay: the base throws `located` and never sends the colour on.
    let scenario = data["counterexamples"][1].as_str().unwrap().to_string();
    assert!(
        scenario.ends_with("main.V005-2.scenario.json"),
        "{scenario}"
    );
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let base: Vec<&str> = (out.stdout.lines())
        .filter(|l| l.contains("\"robot\":\"base\""))
        .collect();
    assert!(
        base.iter().any(|l| l.contains("\"name\":\"located\"")),
        "{base:?}"
    );
    assert!(
        !base.iter().any(|l| l.contains("\"to\":\"Carriers\"")),
        "{base:?}"
    );
    // The cure of `semo explain V005`: one plan relays, then throws.
    let (code, findings, _) = verify("tests/fixtures/verify/clean_relay/main.mission", &[]);
    assert_eq!((code, findings), (0, Vec::new()));
}

/// Two scouts answer the base in one instant and the base decides on the
/// first answer it takes: the network may bring either first (V006, on the
/// base's `receive`, the two sends as related information, and nothing
/// else). The counterexample replayed: the base takes both at that instant,
/// the first being the one the finding names. Answers under keys of their
/// own that the base takes both of commute, and an answer only reported to
/// the operator changes nothing the team does: nothing.
#[test]
fn two_robots_whose_messages_reach_a_third_in_one_instant_race() {
    let dir = support::robots::scratch("verify-robots-race");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/robots_race/main.mission";
    let (code, findings, data) = verify(mission, &["--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    assert_eq!(found, [("V006", 18)], "{findings:?}");
    let race = &data["diagnostics"][0];
    let message = race["message"].as_str().unwrap();
    assert!(
        message.contains("base takes Scouts.SEEN")
            && message.contains("from north")
            && message.contains("from south")
            && message.contains("instead of mode"),
        "{message}"
    );
    let mut related: Vec<u64> = (race["related"].as_array().unwrap().iter())
        .map(|r| r["line"].as_u64().unwrap())
        .collect();
    related.sort();
    assert_eq!(related, [10, 12], "{race}");
    // The replay: both answers reach the base at the finding's instant.
    let at: String = message
        .strip_prefix("at ")
        .and_then(|m| m.split(' ').next())
        .unwrap()
        .to_string();
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    assert!(
        scenario.ends_with("main.V006-1.scenario.json"),
        "{scenario}"
    );
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let taken: Vec<&str> = (out.stdout.lines())
        .filter(|l| {
            l.contains("\"robot\":\"base\"")
                && l.contains("\"event\":\"receive\"")
                && l.contains(&format!("\"t\":{at},"))
        })
        .collect();
    assert_eq!(taken.len(), 2, "{}", out.stdout);
    assert!(
        taken[0].contains("\"value\":\"YES\"") != taken[1].contains("\"value\":\"YES\""),
        "{taken:?}"
    );
    // The cure of `semo explain V006`: keys of their own, both taken. And
    // an answer the base only reports to the operator: the order changes
    // the report alone.
    for mission in [
        "tests/fixtures/verify/robots_commute/main.mission",
        "tests/fixtures/verify/robots_report/main.mission",
    ] {
        let (code, findings, data) = verify(mission, &[]);
        assert_eq!((code, findings), (0, Vec::new()), "{mission}");
        assert_eq!(data["exhaustive"], true, "{mission}: {data}");
    }
}

/// The user's properties (a scenario's `expect`: `always`, `eventually`,
/// `leads_to` and the one-run expectations without a deadline), judged
/// over every behaviour: each broken one with a scenario whose replay by
/// `semo simulate` breaks the same property; the repaired mission keeps
/// what the race broke. A deadline is refused at its position.
#[test]
fn the_users_properties_are_judged_over_every_behaviour_and_broken_ones_replay() {
    let properties = "tests/fixtures/verify/plans_race/properties.json";
    for (mission, verdicts) in [
        (
            "tests/fixtures/verify/plans_race/main.mission",
            ["broken", "broken", "broken", "holds", "broken"],
        ),
        (
            "tests/fixtures/verify/clean_relay/main.mission",
            ["holds", "holds", "broken", "holds", "broken"],
        ),
    ] {
        let dir = support::robots::scratch("verify-properties");
        let dir_text = dir.to_string_lossy().to_string();
        let (code, _, data) = verify(
            mission,
            &["--expect", properties, "--counterexamples", &dir_text],
        );
        assert_eq!(code, 1, "{data}");
        let judged = data["properties"].as_array().unwrap();
        let said: Vec<&str> = judged
            .iter()
            .map(|p| p["verdict"].as_str().unwrap())
            .collect();
        assert_eq!(said, verdicts, "{mission}: {data}");
        for property in judged {
            // Exhaustive: a proof either way.
            assert_eq!(property["proof"], true, "{property}");
            let Some(scenario) = property["counterexample"].as_str() else {
                assert_eq!(property["verdict"], "holds", "{property}");
                continue;
            };
            let out = semo(&[
                "simulate",
                mission,
                "--scenario",
                scenario,
                "--format",
                "json",
            ]);
            assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
            let run: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
            let replayed = &run["expectations"][0];
            assert_eq!(replayed["expectation"], property["expectation"], "{run}");
            assert_eq!(replayed["met"], false, "{run}");
        }
    }
    let dir = support::robots::scratch("verify-properties-refused");
    let deadline = dir.join("deadline.json");
    std::fs::write(
        &deadline,
        "{\"expect\": [\n  {\"robot\": \"base\", \"enters\": \"DONE\", \"before\": 100}\n]}",
    )
    .unwrap();
    let out = semo(&[
        "verify",
        "tests/fixtures/verify/plans_race/main.mission",
        "--expect",
        &deadline.to_string_lossy(),
    ]);
    assert_eq!(out.code, 2, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr
            .contains("deadline.json:2:3: a deadline (\"before\")"),
        "{}",
        out.stderr
    );
    // A file that is not there: bad input, named.
    let missing = dir.join("missing.json");
    let out = semo(&[
        "verify",
        "tests/fixtures/verify/plans_race/main.mission",
        "--expect",
        &missing.to_string_lossy(),
    ]);
    assert_eq!(out.code, 2, "{}{}", out.stdout, out.stderr);
    assert!(out.stderr.contains("missing.json"), "{}", out.stderr);
    // A whole scenario: its world is the search's to choose, and the user
    // is told that only its `expect` is read.
    let scenario = dir.join("whole.scenario.json");
    std::fs::write(
        &scenario,
        "{\"operator\": [{\"at\": 5, \"to\": \"base\", \"value\": \"RC_CMD\", \"is\": \"go\"}],\n \"expect\": [{\"eventually\": {\"robot\": \"base\", \"in\": \"DONE\"}}]}",
    )
    .unwrap();
    let out = semo(&[
        "verify",
        "tests/fixtures/verify/plans_race/main.mission",
        "--expect",
        &scenario.to_string_lossy(),
    ]);
    assert!(
        out.stderr
            .contains("of this scenario only `expect` is read"),
        "{}",
        out.stderr
    );
    assert!(
        out.stdout
            .contains("property `eventually base in DONE`: holds in every behaviour"),
        "{}",
        out.stdout
    );
}

/// The scouting example's master takes both slaves' colours in one instant
/// but only reports them to the operator: no race (V006 leaves out what
/// only `send(USER, ...)` reads). The patrol's guards, though, publish
/// DARK and BRIGHT under one key, each as its own light says: when both
/// come in one instant (one guard patrols while another hides), which one
/// a guard's `subscribe` reads, and so whether it hides, is the network's
/// choice. That is a race between robots, on the `subscribe`, and the
/// only finding there.
#[test]
fn the_repaired_missions_and_the_small_examples_have_no_finding() {
    for (mission, exhaustive) in [
        ("tests/fixtures/verify/clean/main.mission", true),
        ("examples/follow/follow.mission", true),
        ("examples/swarm/march.mission", true),
        ("examples/scouting/scouting.mission", false),
        // The benchmark's five robots in three teams (compiler/benches/verify.rs).
        ("tests/fixtures/verify/three_teams/main.mission", false),
    ] {
        let (code, findings, data) = verify(mission, &["--max-states", "3000"]);
        assert_eq!((code, &findings), (0, &Vec::new()), "{mission}");
        assert_eq!(data["exhaustive"], exhaustive, "{mission}: {data}");
        assert!(data["states"].as_u64().unwrap() > 0, "{mission}");
    }
    let mission = "examples/swarm/patrol_groups.mission";
    let (code, findings, data) = verify(mission, &["--max-states", "3000"]);
    assert_eq!(code, 1, "{findings:?}");
    assert_eq!(data["exhaustive"], false, "{data}");
    assert!(
        !findings.is_empty()
            && findings.iter().all(|(code, line, message)| code == "V006"
                && *line == 65
                && message.contains("Guards.Alarm = DARK (published)")
                && message.contains("Guards.Alarm = BRIGHT (published)")),
        "{findings:?}"
    );
}

/// With faults (`--faults 1`): a leader whose block never ends still
/// decides its election at each heartbeat, so cut off it is fenced before
/// the others count it lost: no finding, exhaustively (docs/groups.md,
/// "Fencing"). With a lost link too (`--network 1`): the messages between
/// tb_0 and tb_1 lost while each still hears tb_2, a majority with itself,
/// tb_1 leads while tb_0 keeps leading (V004, on the statement); the
/// counterexample's drop replayed by `semo simulate` ends with both leading.
#[test]
fn a_leader_cut_off_is_fenced_but_a_lost_link_leaves_two_leaders() {
    let dir = support::robots::scratch("verify-two-leaders");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/two_leaders/main.mission";
    let (code, findings, _) = verify(mission, &[]);
    assert_eq!((code, findings.len()), (0, 0), "{findings:?}");
    let (code, findings, data) = verify(mission, &["--faults", "1"]);
    assert_eq!((code, findings.len()), (0, 0), "{findings:?}");
    assert_eq!(data["exhaustive"], true, "{data}");
    let (code, findings, data) = verify(
        mission,
        &[
            "--faults",
            "1",
            "--network",
            "1",
            "--counterexamples",
            &dir_text,
        ],
    );
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    assert_eq!(found, [("V004", 6)], "{findings:?}");
    let message = &findings[0].2;
    assert!(
        message.contains("tb_0 and tb_1")
            && message.contains("messages between tb_0 and tb_1 lost"),
        "{message}"
    );
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    let text = std::fs::read_to_string(&scenario).unwrap();
    assert!(text.contains("\"drop\": [\"tb_0\", \"tb_1\"]"), "{text}");
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // Each robot's last leader: tb_0 still itself, tb_1 itself.
    let mut last: std::collections::BTreeMap<String, String> = Default::default();
    for line in out.stdout.lines() {
        let e: serde_json::Value = serde_json::from_str(line).unwrap();
        if e["event"] == "leader" {
            last.insert(
                e["robot"].as_str().unwrap().into(),
                e["leader"].as_str().unwrap().into(),
            );
        }
        assert_ne!(e["event"], "fenced", "{line}");
    }
    assert_eq!(last["tb_0"], "tb_0", "{last:?}");
    assert_eq!(last["tb_1"], "tb_1", "{last:?}");
}

/// With faults, a robot whose partner is killed waits for ever at its
/// `receive` (V003, the fault named in the message), where the mission
/// without faults is clean; the counterexample kills the partner.
#[test]
fn a_robot_whose_partner_is_killed_waits_for_ever() {
    let dir = support::robots::scratch("verify-partner-killed");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/partner_killed/main.mission";
    let (code, findings, _) = verify(mission, &[]);
    assert_eq!((code, findings.len()), (0, 0), "{findings:?}");
    let (code, findings, data) =
        verify(mission, &["--faults", "1", "--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    assert_eq!(found, [("V003", 8), ("V003", 12)], "{findings:?}");
    assert!(
        findings[0].2.contains("(after help killed at 0 ms)"),
        "{findings:?}"
    );
    let scenario = data["counterexamples"][0].as_str().unwrap().to_string();
    let text = std::fs::read_to_string(&scenario).unwrap();
    assert!(text.contains("{\"at\": 0, \"kill\": \"help\"}"), "{text}");
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // help is killed before it answers: lead never receives.
    let events: Vec<serde_json::Value> = (out.stdout.lines())
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let of = |robot: &str, event: &str| {
        (events.iter()).any(|e| e["robot"] == robot && e["event"] == event)
    };
    assert!(of("help", "fault") && of("lead", "send"), "{}", out.stdout);
    assert!(!of("lead", "receive"), "{}", out.stdout);
}

/// The project's `[lints]` apply to the findings: allowed, a finding is
/// not reported; denied, it is an error.
#[test]
fn lint_levels_of_the_project_apply_to_the_findings() {
    let dir = support::robots::scratch("verify-lints");
    let mission = std::fs::read_to_string(
        support::repo_root().join("tests/fixtures/verify/never_entered/main.mission"),
    )
    .unwrap();
    std::fs::write(dir.join("main.mission"), mission).unwrap();
    let path = dir.join("main.mission").to_string_lossy().to_string();
    for (level, expected) in [("allow", (0, None)), ("deny", (1, Some("error")))] {
        std::fs::write(
            dir.join("semo.toml"),
            format!("[lints]\nV001 = \"{level}\"\n"),
        )
        .unwrap();
        let out = semo(&["verify", &path, "--format", "json"]);
        let document: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
        let severity = document["diagnostics"][0]["severity"].as_str();
        assert_eq!((out.code, severity), expected, "{level}: {}", out.stdout);
    }
}

/// What a person reads: the findings on standard error, and on standard
/// output how far the search looked, the world's choices and how to
/// replay each counterexample.
#[test]
fn the_human_report_names_the_choices_and_how_to_replay() {
    let dir = support::robots::scratch("verify-human");
    let dir_text = dir.to_string_lossy().to_string();
    let mission = "tests/fixtures/verify/never_finishes/main.mission";
    let out = semo(&["verify", mission, "--counterexamples", &dir_text]);
    assert_eq!(out.code, 1, "{}", out.stderr);
    assert!(out.stderr.contains("[V002]"), "{}", out.stderr);
    assert!(
        out.stdout.starts_with("explored every behaviour:"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout.contains("  sensor ti.LOCATION: 5,5 | OTHER\n"),
        "{}",
        out.stdout
    );
    let replay = format!(
        "  V002: replay with `semo simulate {mission} --scenario {dir_text}/main.V002-1.scenario.json`"
    );
    assert!(out.stdout.contains(&replay), "{}", out.stdout);
}

/// The start's combinations of sensor classes are exponential in the
/// robots (two classes each: 2^40 for forty robots); they are made one at
/// a time, so the budget bounds the search however many robots there are,
/// and doubling the swarm keeps it within the budget.
#[test]
fn a_swarm_with_more_start_combinations_than_the_budget_stops_at_the_budget() {
    let dir = support::robots::scratch("verify-swarm");
    for robots in [20, 40] {
        let path = scouts_swarm(&dir, robots);
        let (code, findings, data) = verify(&path, &["--max-states", "300"]);
        assert_eq!((code, &findings), (0, &Vec::new()), "{robots}");
        assert_eq!(data["exhaustive"], false, "{robots}: {data}");
        assert_eq!(data["states"], 300, "{robots}: {data}");
        assert_eq!(data["bounded_by"], "states", "{robots}: {data}");
    }
}

/// A mission of `robots` TIEvalbots in one team, each comparing its
/// location (so every robot's sensor has two classes: 2^robots start
/// combinations), written into `dir`; its path.
fn scouts_swarm(dir: &std::path::Path, robots: usize) -> String {
    let mission = dir.join(format!("swarm{robots}.mission"));
    std::fs::write(
        &mission,
        format!(
            "{{\n  Scouts: TIEvalbot s[{robots}]\n}}\n\nScouts.Action.Go {{\n  if (LOCATION == \"5,5\")\n    throw ARRIVED\n}} repeat(1 SEC)\n\nScouts.GO {{ set(Action, Go) }}\nScouts.DONE {{ set(Action, OFF) }}\n\nScouts.main {{\n  case (GO):\n    catch (ARRIVED): mode = DONE\n  default: mode = GO\n}}\n"
        ),
    )
    .unwrap();
    mission.to_string_lossy().to_string()
}

/// The memory budget bounds a swarm's search by what its states hold: a
/// swarm twice as large keeps about half the states in the same budget
/// (each state twice the bytes), and the report says the budget stopped it.
/// Without it, the start states of `tb[20]` took 3.6 GB before the state
/// budget was reached.
#[test]
fn a_swarm_search_stops_at_the_memory_budget_with_states_in_inverse_proportion_to_robots() {
    let dir = support::robots::scratch("verify-swarm-memory");
    let mut states = Vec::new();
    for robots in [20, 40] {
        let path = scouts_swarm(&dir, robots);
        let (code, findings, data) = verify(&path, &["--max-memory", "16MiB"]);
        assert_eq!((code, &findings), (0, &Vec::new()), "{robots}");
        assert_eq!(data["exhaustive"], false, "{robots}: {data}");
        assert_eq!(data["bounded_by"], "memory", "{robots}: {data}");
        states.push(data["states"].as_u64().unwrap());
    }
    let (small, large) = (states[0], states[1]);
    eprintln!("{small} states of 20 robots, {large} of 40 in 16 MiB");
    assert!(
        small > 100 && large * 10 < small * 6 && large * 10 > small * 3,
        "{small} states of 20 robots, {large} of 40 in 16 MiB"
    );
    // A size the command line cannot read is bad input.
    let out = semo(&["verify", "--max-memory", "1TB", "x.mission"]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("unknown unit `TB`"), "{}", out.stderr);
}

#[test]
fn a_step_off_the_sensors_period_is_bad_input() {
    let out = semo(&[
        "verify",
        "examples/follow/follow.mission",
        "--step",
        "250ms",
    ]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("multiple of 100ms"), "{}", out.stderr);
}

/// The random missions of `seeds` (`support/missiongen.rs`) that refine
/// without errors, each written in turn as `main.mission` in the scratch
/// folder `scratch`: (seed, text, refined programs, the mission's file id).
fn random_missions(
    scratch: &str,
    seeds: std::ops::Range<u64>,
) -> impl Iterator<
    Item = (
        u64,
        String,
        Vec<semo::refine::RobotProgram>,
        semo::diag::FileId,
    ),
> {
    let catalog = semo::catalog::builtin_catalog();
    let path = support::robots::scratch(scratch).join("main.mission");
    seeds.filter_map(move |seed| {
        let text = support::missiongen::mission(seed, &catalog);
        std::fs::write(&path, &text).unwrap();
        let (run, id) = semo::host::load_build(&path, &[]).ok()?;
        let build = run.analysis().build_input(id)?;
        let refined = semo::refine::refine_checked(&build.input());
        (!refined.diagnostics.iter().any(|d| d.is_error())).then_some((
            seed,
            text,
            refined.programs,
            id,
        ))
    })
}

/// What a random behaviour showed.
struct Behaviour {
    /// (team, mode) entered.
    entered: Vec<(String, String)>,
    /// Per robot: it has finished by the end.
    finished: Vec<bool>,
    /// Per robot: it acted (called, sent, threw, changed mode, finished)
    /// after the prefix.
    acted: Vec<bool>,
    /// Per robot: the `receive` states it waits in at the end.
    waiting: Vec<Vec<(semo::refine::ServiceMachineId, semo::refine::StateId)>>,
}

/// One random behaviour of the world `semo verify` explores: the choices
/// of `prefix` (else a random start), then at each step a random one of
/// those the search could make, up to the horizon.
fn random_behaviour(
    programs: &[semo::refine::RobotProgram],
    inputs: &semo::verify::Inputs,
    options: &semo::verify::Options,
    prefix: &[(i64, semo::verify::Choice)],
    rng: &mut support::missiongen::Rng,
) -> Behaviour {
    random_behaviour_seen(programs, inputs, options, prefix, rng, &mut |_| {})
}

/// [`random_behaviour`], each trace event also given to `see`.
fn random_behaviour_seen(
    programs: &[semo::refine::RobotProgram],
    inputs: &semo::verify::Inputs,
    options: &semo::verify::Options,
    prefix: &[(i64, semo::verify::Choice)],
    rng: &mut support::missiongen::Rng,
    see: &mut dyn FnMut(&semo::sim::TraceEvent),
) -> Behaviour {
    use semo::verify::Choice;
    let empty = semo::sim::Scenario::default();
    let mut sim = semo::sim::Sim::new(programs, &empty, &semo::sim::Options::default());
    let mut world = semo::verify::World::new(inputs, options, programs.len());
    let mut seen = Behaviour {
        entered: Vec::new(),
        finished: Vec::new(),
        acted: vec![false; programs.len()],
        waiting: Vec::new(),
    };
    let mut note = |sim: &mut semo::sim::Sim, seen: &mut Behaviour, after_prefix: bool| {
        for e in sim.take_trace() {
            see(&e);
            if let (true, Some(mode)) = (e.event == "mode", e.field("mode")) {
                seen.entered
                    .push((programs[e.robot].team.clone(), mode.to_string()));
            }
            if after_prefix && matches!(e.event, "call" | "send" | "throw" | "mode" | "finish") {
                seen.acted[e.robot] = true;
            }
        }
    };
    let mut t = 0;
    if prefix.is_empty() {
        let start = random_start(inputs, rng);
        semo::verify::apply(&mut sim, &mut world, inputs, &mut Choice::Start(start));
    }
    for (at, choice) in prefix {
        sim.run_to(*at);
        note(&mut sim, &mut seen, false);
        semo::verify::apply(&mut sim, &mut world, inputs, &mut choice.clone());
        t = *at;
    }
    if !prefix.is_empty() {
        t += options.step_ms;
        sim.run_to(t);
        note(&mut sim, &mut seen, false);
    }
    while t < options.horizon_ms {
        let all = semo::verify::choices(inputs, &world);
        // Mostly still, as most steps of a run are.
        let mut choice = if rng.chance(80) {
            Choice::Nothing
        } else {
            all[rng.below(all.len())].clone()
        };
        semo::verify::apply(&mut sim, &mut world, inputs, &mut choice);
        t += options.step_ms;
        sim.run_to(t);
        note(&mut sim, &mut seen, true);
    }
    // Killed is not finished.
    seen.finished = (0..programs.len())
        .map(|r| !sim.is_running(r) && !world.down[r])
        .collect();
    seen.waiting = (0..programs.len())
        .map(|r| sim.waiting_receives(r))
        .collect();
    seen
}

/// A random class for each sensor input, then each result input.
fn random_start(inputs: &semo::verify::Inputs, rng: &mut support::missiongen::Rng) -> Vec<usize> {
    (inputs.sensors.iter().map(|s| s.values.len()))
        .chain(inputs.results.iter().map(|r| r.values.len()))
        .map(|n| rng.below(n))
        .collect()
}

/// Soundness of the search and its merged states, over random missions: a
/// mode V001 says no robot enters is entered in no random behaviour of the
/// same world, a robot V002 says can no longer finish finishes in no
/// random continuation of its counterexample, and one V003 says waits for
/// ever in a `receive` still waits there, having done nothing, at the end
/// of every random continuation.
#[test]
fn findings_on_random_missions_hold_in_random_behaviours() {
    let options = semo::verify::Options {
        horizon_ms: 20_000,
        max_states: 4_000,
        ..semo::verify::Options::default()
    };
    let (missions, exhaustive, held) = random_findings_hold("verify-random", 0..30, &options);
    eprintln!("{missions} missions, {exhaustive} explored exhaustively, {held} findings held");
    assert!(exhaustive >= 6, "only {exhaustive} exhaustive searches");
}

/// The same with one fault along each behaviour (a robot killed,
/// restarted, cut off or healed), and each V004 replayed: its scenario,
/// run by the simulator, ends with the two robots leading the statement.
#[test]
fn findings_with_faults_on_random_missions_hold_in_random_behaviours() {
    let options = semo::verify::Options {
        horizon_ms: 10_000,
        max_states: 4_000,
        changes: 1,
        faults: 1,
        ..semo::verify::Options::default()
    };
    let (missions, exhaustive, held) =
        random_findings_hold("verify-random-faults", 0..16, &options);
    eprintln!(
        "{missions} missions with faults, {exhaustive} explored exhaustively, {held} findings held"
    );
    assert!(exhaustive >= 3, "only {exhaustive} exhaustive searches");
}

/// The same with the network losing or delaying one step's messages
/// between two robots once along each behaviour.
#[test]
fn findings_with_network_faults_on_random_missions_hold_in_random_behaviours() {
    let options = semo::verify::Options {
        horizon_ms: 10_000,
        max_states: 4_000,
        changes: 1,
        network: 1,
        ..semo::verify::Options::default()
    };
    let (missions, exhaustive, held) =
        random_findings_hold("verify-random-network", 40..56, &options);
    eprintln!(
        "{missions} missions with network faults, {exhaustive} explored exhaustively, {held} findings held"
    );
    assert!(exhaustive >= 3, "only {exhaustive} exhaustive searches");
}

/// Runs `semo verify` with `options` on the random missions of `seeds` and
/// holds each claim to random behaviours: (missions, exhaustive searches,
/// findings held).
fn random_findings_hold(
    scratch: &str,
    seeds: std::ops::Range<u64>,
    options: &semo::verify::Options,
) -> (usize, usize, usize) {
    use semo::verify::Claim;
    let mut rng = support::missiongen::Rng::new(7);
    let (mut exhaustive, mut held, mut missions) = (0, 0, 0);
    for (seed, text, programs, id) in random_missions(scratch, seeds) {
        missions += 1;
        let report = semo::verify::verify(&programs, id, &text, options).unwrap();
        exhaustive += usize::from(report.exhaustive);
        for (claim, way) in report.claims.iter().zip(&report.counterexamples) {
            if let Claim::TwoLeaders {
                line,
                robots: (a, b),
                ..
            } = claim
            {
                let way = way.as_ref().expect("V004 has its way");
                let scenario = way.scenario_json(&report.inputs, &programs);
                let scenario = semo::sim::scenario::parse(&scenario, &programs).unwrap();
                let mut sim =
                    semo::sim::Sim::new(&programs, &scenario, &semo::sim::Options::default());
                sim.run_to(way.end_ms);
                for r in [*a, *b] {
                    let m = &programs[r].control;
                    let led: Vec<u32> = (sim.leads(r).into_iter())
                        .map(|(service, state)| m.service(service).states[state.index()].line)
                        .collect();
                    assert!(
                        led.contains(line),
                        "seed {seed}: {} does not lead line {line} at {} ms\n{text}",
                        programs[r].robot,
                        way.end_ms
                    );
                }
                held += 1;
                eprintln!("seed {seed}: V004 on line {line} replayed");
                continue;
            }
            if let Claim::Race {
                robot,
                thrower,
                lost,
            } = claim
            {
                let way = way.as_ref().expect("V005 has its way");
                let scenario = way.scenario_json(&report.inputs, &programs);
                let scenario = semo::sim::scenario::parse(&scenario, &programs).unwrap();
                let mut sim =
                    semo::sim::Sim::new(&programs, &scenario, &semo::sim::Options::default());
                sim.watch_races();
                sim.run_to(way.end_ms);
                let races = sim.take_races();
                assert!(
                    races
                        .iter()
                        .any(|race| (race.robot, race.thrower, race.lost)
                            == (*robot, *thrower, *lost)),
                    "seed {seed}: the race of {} is not replayed by {races:?}\n{text}",
                    programs[*robot].robot
                );
                held += 1;
                eprintln!("seed {seed}: V005 replayed");
                continue;
            }
            if let Claim::MessageRace { robot, senders } = claim {
                let way = way.as_ref().expect("V006 has its way");
                let scenario = way.scenario_json(&report.inputs, &programs);
                let scenario = semo::sim::scenario::parse(&scenario, &programs).unwrap();
                let mut sim =
                    semo::sim::Sim::new(&programs, &scenario, &semo::sim::Options::default());
                sim.watch_message_races(options.step_ms);
                sim.run_to(way.end_ms);
                let races = sim.take_message_races();
                let pair = |a: usize, b: usize| (a.min(b), a.max(b));
                assert!(
                    races.iter().any(|race| race.robot == *robot
                        && pair(race.first.from, race.second.from) == pair(senders.0, senders.1)),
                    "seed {seed}: the race at {} is not replayed by {races:?}\n{text}",
                    programs[*robot].robot
                );
                held += 1;
                eprintln!("seed {seed}: V006 replayed");
                continue;
            }
            for _ in 0..4 {
                let way = way.as_ref().map_or(&[][..], |w| &w.choices[..]);
                let seen = random_behaviour(&programs, &report.inputs, options, way, &mut rng);
                match claim {
                    Claim::NeverEntered { team, mode } => assert!(
                        !seen.entered.contains(&(team.clone(), mode.clone())),
                        "seed {seed}: {team} entered {mode}\n{text}"
                    ),
                    Claim::NeverFinishes { robot } => assert!(
                        !seen.finished[*robot],
                        "seed {seed}: {} finished\n{text}",
                        programs[*robot].robot
                    ),
                    Claim::WaitsForEver {
                        robot,
                        service,
                        state,
                    } => assert!(
                        !seen.acted[*robot] && seen.waiting[*robot].contains(&(*service, *state)),
                        "seed {seed}: {} left its receive\n{text}",
                        programs[*robot].robot
                    ),
                    Claim::TwoLeaders { .. } | Claim::Race { .. } | Claim::MessageRace { .. } => {
                        unreachable!("replayed above")
                    }
                }
            }
            held += 1;
        }
    }
    (missions, exhaustive, held)
}

/// A message lost over the network (`--network 1`): the helper, told its
/// goal once, waits for ever (V003) and never finishes (V002), each message
/// naming the loss; the counterexample's `drop` fault replays it. Without
/// a network fault the mission has no finding.
#[test]
fn a_message_the_network_loses_leaves_its_receiver_waiting_for_ever() {
    let mission = "tests/fixtures/verify/message_lost/main.mission";
    let (code, findings, _) = verify(mission, &[]);
    assert_eq!((code, findings), (0, Vec::new()));
    let dir = support::robots::scratch("verify-message-lost");
    let dir_text = dir.to_string_lossy().to_string();
    let (code, findings, data) =
        verify(mission, &["--network", "1", "--counterexamples", &dir_text]);
    assert_eq!(code, 1);
    assert_eq!(data["exhaustive"], true, "{data}");
    let found: Vec<(&str, u64)> = findings.iter().map(|(c, l, _)| (c.as_str(), *l)).collect();
    assert_eq!(found, [("V002", 18), ("V003", 13)], "{findings:?}");
    for (_, _, message) in &findings {
        assert!(
            message.contains("the messages between lead and help lost from 0 ms to 500 ms"),
            "{message}"
        );
    }
    let scenario = data["counterexamples"][1].as_str().unwrap().to_string();
    let text = std::fs::read_to_string(&scenario).unwrap();
    assert!(text.contains("\"drop\": [\"lead\", \"help\"]"), "{text}");
    let out = semo(&["simulate", mission, "--scenario", &scenario, "--trace", "-"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        !out.stdout
            .contains("\"robot\":\"help\",\"event\":\"receive\""),
        "{}",
        out.stdout
    );
}

/// Every choice the search makes is written into its counterexamples as
/// the scenario entry that makes the same run: over random missions,
/// random behaviours with sensor changes, operator commands, faults and
/// network losses and delays, run live by `verify::apply` and replayed
/// from `Counterexample::scenario_json`, give the same trace.
#[test]
fn a_counterexample_scenario_replays_the_run_its_choices_made() {
    use semo::verify::Choice;
    let options = semo::verify::Options {
        changes: 2,
        faults: 2,
        network: 3,
        ..semo::verify::Options::default()
    };
    let mut rng = support::missiongen::Rng::new(5);
    let (mut compared, mut network) = (0, 0);
    for (seed, text, programs, _) in random_missions("verify-replay-choices", 300..316) {
        let made = replay_a_random_behaviour(&programs, &options, &mut rng, 8_000)
            .unwrap_or_else(|(scenario, why)| panic!("seed {seed}: {why}\n{scenario}\n{text}"));
        network += (made.iter())
            .filter(|c| matches!(c, Choice::Lose { .. } | Choice::Delay { .. }))
            .count();
        compared += 1;
    }
    eprintln!("{compared} random behaviours replayed, {network} network choices among them");
    assert!(
        compared >= 8 && network >= 10,
        "{compared} compared, {network} network choices"
    );
}

/// One random behaviour of `programs` up to `end_ms`, every choice a
/// random one of those the search could make, against the replay of its
/// counterexample scenario by the simulator: the choices made, or the
/// scenario and why the replay differs.
fn replay_a_random_behaviour(
    programs: &[semo::refine::RobotProgram],
    options: &semo::verify::Options,
    rng: &mut support::missiongen::Rng,
    end_ms: i64,
) -> Result<Vec<semo::verify::Choice>, (String, String)> {
    use semo::verify::{Choice, Counterexample};
    let inputs = semo::verify::Inputs::derive(programs);
    let empty = semo::sim::Scenario::default();
    let mut live = semo::sim::Sim::new(programs, &empty, &semo::sim::Options::default());
    let mut world = semo::verify::World::new(&inputs, options, programs.len());
    let mut start = Choice::Start(random_start(&inputs, rng));
    semo::verify::apply(&mut live, &mut world, &inputs, &mut start);
    let mut made = vec![(0, start)];
    let mut trace = Vec::new();
    let mut t = 0;
    while t < end_ms {
        let all = semo::verify::choices(&inputs, &world);
        let mut choice = all[rng.below(all.len())].clone();
        semo::verify::apply(&mut live, &mut world, &inputs, &mut choice);
        made.push((t, choice));
        t += options.step_ms;
        live.run_to(t);
        trace.extend(live.take_trace().iter().map(|e| format!("{e:?}")));
    }
    let way = Counterexample {
        choices: made,
        end_ms: t,
        step_ms: options.step_ms,
    };
    let scenario = way.scenario_json(&inputs, programs);
    let parsed = semo::sim::scenario::parse(&scenario, programs)
        .map_err(|e| (scenario.clone(), format!("{e:?}")))?;
    let mut replay = semo::sim::Sim::new(programs, &parsed, &semo::sim::Options::default());
    replay.run_to(t);
    let replayed: Vec<String> = (replay.take_trace().iter())
        .map(|e| format!("{e:?}"))
        .collect();
    if replayed != trace {
        let at = (replayed.iter().zip(&trace))
            .position(|(a, b)| a != b)
            .unwrap_or(replayed.len().min(trace.len()));
        let why = format!(
            "the replay differs at event {at}: {:?} against {:?}",
            replayed.get(at),
            trace.get(at)
        );
        return Err((scenario, why));
    }
    Ok(way.choices.into_iter().map(|(_, c)| c).collect())
}

/// What a robot's calls give back is the world's to choose: `semo verify`
/// finds the mode only a search that found something leads to, and
/// random behaviours that change what the calls give back, with robots
/// killed and restarted between (a restarted robot's calls are given
/// back, in order, what its first process's were), replay exactly from
/// their scenarios.
#[test]
fn action_results_are_explored_and_their_choices_replay() {
    let mission = "tests/fixtures/verify/results/main.mission";
    let (code, findings, data) = verify(mission, &[]);
    assert_eq!((code, &findings), (0, &vec![]), "{data}");
    let (run, id) = semo::host::load_build(&support::repo_root().join(mission), &[]).unwrap();
    let build = run.analysis().build_input(id).unwrap();
    let programs = semo::refine::refine_checked(&build.input()).programs;
    let inputs = semo::verify::Inputs::derive(&programs);
    let services: Vec<(&str, &str, usize)> = (inputs.results.iter())
        .map(|r| (r.robot_name.as_str(), r.service.as_str(), r.values.len()))
        .collect();
    assert_eq!(services, [("ti", "search", 2)]);
    let options = semo::verify::Options {
        changes: 6,
        faults: 4,
        ..semo::verify::Options::default()
    };
    let mut rng = support::missiongen::Rng::new(11);
    let (mut changed, mut restarted) = (0, 0);
    for _ in 0..24 {
        let made = replay_a_random_behaviour(&programs, &options, &mut rng, 6_000)
            .unwrap_or_else(|(scenario, why)| panic!("{why}\n{scenario}"));
        changed += made
            .iter()
            .filter(|c| matches!(c, semo::verify::Choice::Results { .. }))
            .count();
        restarted += made
            .iter()
            .filter(|c| matches!(c, semo::verify::Choice::Restart { .. }))
            .count();
    }
    assert!(
        changed >= 10 && restarted >= 5,
        "{changed} result changes, {restarted} restarts"
    );
}

/// The user's properties over random missions: random `always`,
/// `eventually` and `leads_to` about the missions' robots and modes. Each
/// broken one's scenario, replayed by the simulator, breaks it (the same
/// judgement `semo simulate` makes); each `always` that holds holds in
/// random behaviours of the same world too.
#[test]
fn properties_on_random_missions_replay_broken_and_hold_in_random_behaviours() {
    use semo::sim::scenario::{Condition, ExpectKind, Expectation};
    let options = semo::verify::Options {
        horizon_ms: 10_000,
        max_states: 3_000,
        changes: 1,
        ..semo::verify::Options::default()
    };
    let mut rng = support::missiongen::Rng::new(11);
    let (mut broken, mut held, mut proved) = (0, 0, 0);
    for (seed, text, programs, id) in random_missions("verify-properties-random", 200..216) {
        if programs.iter().any(|p| p.control.modes.is_empty()) {
            continue;
        }
        let some_mode = |rng: &mut support::missiongen::Rng| {
            let p = &programs[rng.below(programs.len())];
            let m = &p.control.modes[rng.below(p.control.modes.len())];
            (p.robot.clone(), m.name.clone())
        };
        let (r1, m1) = some_mode(&mut rng);
        let (r2, m2) = some_mode(&mut rng);
        let (r3, m3) = some_mode(&mut rng);
        let kinds = [
            ExpectKind::Always(Condition::Not(Box::new(Condition::In {
                robot: r1.clone(),
                mode: m1.clone(),
            }))),
            ExpectKind::Eventually(Condition::Enters {
                robot: r2.clone(),
                mode: m2.clone(),
            }),
            ExpectKind::LeadsTo(
                Condition::Enters {
                    robot: r1,
                    mode: m1,
                },
                Condition::Any(vec![
                    Condition::In {
                        robot: r2,
                        mode: m2,
                    },
                    Condition::Enters {
                        robot: r3,
                        mode: m3,
                    },
                ]),
            ),
        ];
        let expect: Vec<Expectation> = kinds
            .iter()
            .map(|kind| Expectation {
                at_offset: 0,
                kind: kind.clone(),
            })
            .collect();
        let properties = semo::verify::properties_of(&expect).unwrap();
        let report =
            semo::verify::verify_expecting(&programs, id, &text, &options, properties).unwrap();
        for (property, outcome) in &report.properties {
            let kind = &property.expectation.kind;
            match outcome {
                semo::verify::Outcome::Broken { way, .. } => {
                    let scenario =
                        way.scenario_json_expecting(&report.inputs, &programs, Some(kind));
                    let scenario = semo::sim::scenario::parse(&scenario, &programs).unwrap();
                    let run =
                        semo::sim::simulate(&programs, &scenario, &semo::sim::Options::default());
                    let verdicts = semo::sim::expect::judge(&run, &scenario.expect);
                    assert!(
                        !verdicts[0].met,
                        "seed {seed}: `{kind}` broken, but its replay meets it: {}\n{text}",
                        verdicts[0].why
                    );
                    broken += 1;
                }
                semo::verify::Outcome::Holds { proof } => {
                    proved += usize::from(*proof);
                    if !matches!(kind, ExpectKind::Always(_)) {
                        continue;
                    }
                    for _ in 0..3 {
                        let robots: Vec<&str> = programs.iter().map(|p| p.robot.as_str()).collect();
                        let mut timeline = semo::sim::temporal::Timeline::new(
                            robots,
                            [kind],
                            vec![None; programs.len()],
                        );
                        random_behaviour_seen(
                            &programs,
                            &report.inputs,
                            &options,
                            &[],
                            &mut rng,
                            &mut |e| timeline.see(e),
                        );
                        timeline.close_instant();
                        let (_, status) = timeline.status().next().unwrap();
                        assert_eq!(
                            status.broken_at, None,
                            "seed {seed}: `{kind}` broken in a random behaviour\n{text}"
                        );
                    }
                    held += 1;
                }
                semo::verify::Outcome::NotJudged => {}
            }
        }
    }
    eprintln!(
        "{broken} broken properties replayed, {held} `always` held in random behaviours, {proved} proved"
    );
    assert!(broken >= 5, "only {broken} broken properties");
    assert!(held >= 3, "only {held} `always` held");
}

/// `--no-reduction` is the search without merging states across instants,
/// as the user reaches it: the document says which reductions ran, the
/// same race is found with and without, and merging never needs more
/// states than the unreduced search on the same horizon.
#[test]
fn no_reduction_runs_the_unreduced_search_and_finds_the_same_race() {
    let mission = "tests/fixtures/verify/plans_race/main.mission";
    let horizon = ["--horizon", "6s"];
    let (code, reduced, merged) = verify(mission, &horizon);
    let (full_code, unreduced, full) =
        verify(mission, &[&horizon[..], &["--no-reduction"]].concat());
    assert_eq!((code, full_code), (1, 1));
    assert_eq!(
        merged["reductions"],
        serde_json::json!(["merge_in_time"]),
        "{merged}"
    );
    assert_eq!(full["reductions"], serde_json::json!([]), "{full}");
    let races = |found: &[(String, u64, String)]| -> Vec<(String, u64)> {
        found
            .iter()
            .filter(|(code, _, _)| code == "V005")
            .map(|(code, line, _)| (code.clone(), *line))
            .collect()
    };
    assert_eq!(races(&reduced), [("V005".to_string(), 17)], "{reduced:?}");
    assert_eq!(races(&unreduced), races(&reduced), "{unreduced:?}");
    let states = |data: &serde_json::Value| data["states"].as_u64().unwrap();
    assert!(
        states(&merged) < states(&full),
        "merging saved nothing: {} and {} states",
        states(&merged),
        states(&full)
    );
}

/// The reduction is sound: over random missions, merging a state with one
/// met at an earlier instant (times relative to now) sees every event (a
/// mode entered, a call, a message, without its time) that the unreduced
/// search (only states of one instant merge) sees within the same
/// horizon, and no other: a later state's future is the earlier one's,
/// shifted.
#[test]
fn merging_states_across_instants_finds_what_the_unreduced_search_finds() {
    let reduced = semo::verify::Options {
        horizon_ms: 6_000,
        max_states: 20_000,
        changes: 1,
        observe: true,
        ..semo::verify::Options::default()
    };
    let unreduced = semo::verify::Options {
        merge_in_time: false,
        ..reduced.clone()
    };
    let (mut compared, mut saved) = (0, 0);
    for (seed, text, programs, id) in random_missions("verify-reduction", 100..118) {
        let full = semo::verify::verify(&programs, id, &text, &unreduced).unwrap();
        if full
            .bound
            .is_some_and(|b| b != semo::verify::Bound::Horizon)
        {
            continue;
        }
        let merged = semo::verify::verify(&programs, id, &text, &reduced).unwrap();
        assert!(
            merged
                .bound
                .is_none_or(|b| b == semo::verify::Bound::Horizon),
            "seed {seed}"
        );
        assert_eq!(merged.entered, full.entered, "seed {seed}\n{text}");
        let only = |a: &[String], b: &[String]| -> Vec<String> {
            a.iter()
                .filter(|x| b.binary_search(x).is_err())
                .cloned()
                .collect()
        };
        assert_eq!(
            (
                only(&merged.observed, &full.observed),
                only(&full.observed, &merged.observed)
            ),
            (Vec::new(), Vec::new()),
            "seed {seed}: events seen by one search only\n{text}"
        );
        compared += 1;
        saved += full.states - merged.states;
    }
    eprintln!("{compared} missions compared; merging saved {saved} states");
    assert!(compared >= 8, "only {compared} missions compared");
    assert!(saved > 0, "merging never merged");
}
