//! `semo simulate` as a user runs it: the scouting scenario (the same file
//! `tests/build.rs` runs the generated C programs on) meets its expectations,
//! a failing expectation exits 1, a bad scenario exits 2 with its position,
//! a killed leader is replaced, a seed gives the same run, and the timeline
//! picture has a lane per robot with bands, bars and labels that do not overlap.

mod support;

use std::path::{Path, PathBuf};
use support::{examples, repo_root, semo};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("simulate")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scouting() -> String {
    examples()
        .join("scouting/scouting.mission")
        .display()
        .to_string()
}

fn scouting_scenario() -> PathBuf {
    repo_root().join("tests/fixtures/build/scouting.scenario.json")
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn scouting_meets_its_expectations() {
    let scenario = scouting_scenario().display().to_string();
    let out = semo(&["simulate", &scouting(), "--scenario", &scenario]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let lines: Vec<&str> = out.stdout.lines().collect();
    assert!(
        lines.contains(&"  MasterTeam/irobot: AUTO_MODE@0 -> WAIT_MODE@1050 -> RETURN_MODE@6000 -> FINISH@9010 (finished at 9020 ms)"),
        "{}",
        out.stdout
    );
    for slave in ["ti", "nxt"] {
        let line = lines
            .iter()
            .find(|l| l.starts_with(&format!("  SlaveTeam/{slave}: ")))
            .unwrap();
        let modes: Vec<&str> = line
            .split(": ")
            .nth(1)
            .unwrap()
            .split(" (")
            .next()
            .unwrap()
            .split(" -> ")
            .map(|m| m.split('@').next().unwrap())
            .collect();
        assert_eq!(
            modes,
            ["AUTO_MODE", "SEARCH_MODE", "RETURN_MODE", "FINISH"],
            "{slave}"
        );
    }
    assert!(
        out.stdout.contains("expectations: 8 of 8 met"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("  ok   irobot receives SlaveTeam.COLOR from ti: received at")
    );
}

#[test]
fn a_failing_expectation_exits_1_and_says_why() {
    let dir = scratch("failing");
    let text = std::fs::read_to_string(scouting_scenario())
        .unwrap()
        .replacen(
            "\"expect\": [",
            r#""expect": [{"robot": "irobot", "never_enters": "RETURN_MODE"},"#,
            1,
        );
    let scenario = write(&dir, "s.scenario.json", &text);
    let out = semo(&["simulate", &scouting(), "--scenario", &scenario]);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("expectations: 8 of 9 met"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("  FAIL irobot never enters RETURN_MODE: entered at 6000 ms"),
        "{}",
        out.stdout
    );
    let json = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scenario,
        "--format",
        "json",
    ]);
    assert_eq!(json.code, 1);
    let summary: serde_json::Value = serde_json::from_str(&json.stdout).unwrap();
    assert_eq!(summary["ok"], false);
    assert_eq!(summary["expectations"][0]["met"], false);
    assert_eq!(summary["robots"][0]["modes"][1]["mode"], "WAIT_MODE");
}

#[test]
fn a_bad_scenario_exits_2_with_its_position() {
    let dir = scratch("bad");
    for (text, message) in [
        (
            "{\n  \"expect\": [\n    {\"robot\": \"irobot\", \"enters\": \"SEARCH_MODE\"}\n  ]\n}\n",
            ":3:35: no mode \"SEARCH_MODE\" for robot irobot (modes: AUTO_MODE, FINISH, RC_MODE, RETURN_MODE, WAIT_MODE)",
        ),
        ("{\"duration\": 100,}", ":1:18: expected a key in quotes"),
        (
            "{\"faults\": [{\"at\": 10, \"kill\": \"r2d2\"}]}",
            ":1:32: robot \"r2d2\" is not in the mission (robots: irobot, ti, nxt)",
        ),
        (
            "{\"faults\": [{\"at\": 10, \"kill\": \"irobt\"}]}",
            ":1:32: robot \"irobt\" is not in the mission (robots: irobot, ti, nxt) (did you mean \"irobot\"?)",
        ),
    ] {
        let scenario = write(&dir, "bad.scenario.json", text);
        let out = semo(&["simulate", &scouting(), "--scenario", &scenario]);
        assert_eq!(out.code, 2, "{text}: {}{}", out.stdout, out.stderr);
        assert_eq!(
            out.stderr.trim_end(),
            format!("scenario {scenario}{message}"),
            "{text}"
        );
        assert!(out.stdout.is_empty());
    }
    let document = |out: &support::Output| -> serde_json::Value {
        serde_json::from_str(&out.stdout).expect(&out.stdout)
    };
    // The did-you-mean is the JSON diagnostic's suggestion too.
    let scenario = write(
        &dir,
        "bad.scenario.json",
        "{\"faults\": [{\"at\": 10, \"kill\": \"irobt\"}]}",
    );
    let out = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scenario,
        "--format",
        "json",
    ]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert_eq!(document(&out)["diagnostics"][0]["suggestion"], "irobot");
    let missing = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &dir.join("none.json").display().to_string(),
    ]);
    assert_eq!(missing.code, 2);
    let until = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scouting_scenario().display().to_string(),
        "--until",
        "5 parsecs",
    ]);
    assert_eq!(until.code, 2, "{}", until.stderr);
}

/// A sensor value no sensor task of the robot samples is read by nobody:
/// the run goes on (a scenario may serve variants of a mission), with a
/// positioned warning and a did-you-mean, never in silence.
#[test]
fn a_misspelt_sensor_value_is_a_warning_with_a_did_you_mean() {
    let dir = scratch("unsampled");
    let scenario = write(
        &dir,
        "colour.scenario.json",
        "{\"robots\": {\"ti\": {\"sensors\": [{\"at\": 0, \"value\": \"COLOUR\", \"is\": \"RED\"}]}}}",
    );
    let message = "robot ti samples no sensor value \"COLOUR\": nothing reads this entry \
                   (it samples: COLOR, LOCATION) (did you mean \"COLOR\"?)";
    let out = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scenario,
        "--until",
        "1s",
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert_eq!(
        out.stderr.trim_end(),
        format!("scenario {scenario}:1:51: warning: {message}")
    );
    let out = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scenario,
        "--until",
        "1s",
        "--format",
        "json",
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(out.stderr.is_empty(), "{}", out.stderr);
    let document: serde_json::Value = serde_json::from_str(&out.stdout).expect(&out.stdout);
    let warning = &document["diagnostics"][0];
    assert_eq!(
        (
            &warning["severity"],
            &warning["message"],
            &warning["suggestion"],
            &warning["start"]
        ),
        (
            &serde_json::json!("warning"),
            &serde_json::json!(message),
            &serde_json::json!("COLOR"),
            &serde_json::json!({"line": 1, "column": 51})
        ),
        "{document}"
    );
    assert_eq!(document["ok"], true, "{document}");
}

#[test]
fn a_killed_leader_is_replaced() {
    let dir = scratch("leader");
    let scenario = write(
        &dir,
        "kill.scenario.json",
        r#"{
  "duration": 3500,
  "faults": [{"at": 1200, "kill": "tb_0"}],
  "expect": [{"robot": "tb_1", "receives": "SwarmTeam.__alive", "from": "tb_2"}]
}"#,
    );
    let mission = examples()
        .join("swarm/patrol_groups.mission")
        .display()
        .to_string();
    let trace = dir.join("trace.jsonl");
    let svg = dir.join("kill.svg");
    let out = semo(&[
        "simulate",
        &mission,
        "--scenario",
        &scenario,
        "--trace",
        &trace.display().to_string(),
        "--svg",
        &svg.display().to_string(),
    ]);
    assert!(out.code <= 1, "{}{}", out.stdout, out.stderr);
    // The timeline marks the killed robot's end, and no end of the robots
    // still running when the run ends.
    let elements = svg_elements(&std::fs::read_to_string(&svg).unwrap());
    let ends: Vec<(&str, &str)> = elements
        .iter()
        .filter(|(_, a)| attr(a, "class") == Some("end"))
        .map(|(_, a)| (attr(a, "data-why").unwrap(), attr(a, "data-t").unwrap()))
        .collect();
    assert_eq!(ends, [("killed", "1200")]);
    assert!(
        out.stdout.contains("kill at 1200 ms") || out.stdout.contains("killed at 1200 ms"),
        "{}",
        out.stdout
    );
    let events: Vec<serde_json::Value> = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let leaders = |robot: &str| -> Vec<String> {
        events
            .iter()
            .filter(|e| e["robot"] == robot && e["event"] == "leader")
            .map(|e| e["leader"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(leaders("tb_1"), ["tb_0", "tb_1"]);
    assert_eq!(leaders("tb_2"), ["tb_0", "tb_1"]);
    assert!(leaders("ev_0").is_empty());
}

#[test]
fn a_seed_gives_the_same_run() {
    let dir = scratch("seed");
    let text = std::fs::read_to_string(scouting_scenario())
        .unwrap()
        .replacen('{', r#"{"network": {"loss": 0.2},"#, 1);
    let scenario = write(&dir, "lossy.scenario.json", &text);
    let trace = |seed: &str| {
        let out = semo(&[
            "simulate",
            &scouting(),
            "--scenario",
            &scenario,
            "--seed",
            seed,
            "--trace",
            "-",
        ]);
        assert!(out.code <= 1, "{}", out.stderr);
        out.stdout
    };
    let a = trace("3");
    assert_eq!(a, trace("3"));
    assert_ne!(a, trace("4"));
    for line in a.lines() {
        let event: serde_json::Value = serde_json::from_str(line).unwrap();
        let object = event.as_object().unwrap();
        assert!(object["t"].is_i64());
        // Every field is a string but a mission value (`value`, `arg`),
        // which keeps its type: a number, true/false, a string or null.
        assert!(
            object
                .iter()
                .filter(|(k, _)| *k != "t")
                .all(|(k, v)| v.is_string()
                    || (["value", "arg"].contains(&k.as_str()) && !v.is_object() && !v.is_array())),
            "{line}"
        );
    }
}

/// Elements of the SVG by class, with their attributes.
fn svg_elements(svg: &str) -> Vec<(String, Vec<(String, String)>)> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(svg);
    let mut found = Vec::new();
    loop {
        match reader.read_event().expect("the SVG is well-formed XML") {
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e) => {
                let attrs = e
                    .attributes()
                    .map(|a| {
                        let a = a.unwrap();
                        (
                            String::from_utf8(a.key.as_ref().to_vec()).unwrap(),
                            a.unescape_value().unwrap().into_owned(),
                        )
                    })
                    .collect();
                found.push((
                    String::from_utf8(e.name().as_ref().to_vec()).unwrap(),
                    attrs,
                ));
            }
            _ => {}
        }
    }
    found
}

fn attr<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

#[test]
fn the_timeline_has_a_lane_per_robot_with_its_modes_and_services() {
    let dir = scratch("svg");
    let svg = dir.join("scouting.svg");
    let scenario = scouting_scenario().display().to_string();
    let out = semo(&[
        "simulate",
        &scouting(),
        "--scenario",
        &scenario,
        "--svg",
        &svg.display().to_string(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let elements = svg_elements(&std::fs::read_to_string(&svg).unwrap());
    let class = |c: &str| -> Vec<&Vec<(String, String)>> {
        elements
            .iter()
            .filter(|(_, a)| attr(a, "class") == Some(c))
            .map(|(_, a)| a)
            .collect()
    };
    let lanes = class("lane");
    let robots: Vec<&str> = lanes
        .iter()
        .map(|a| attr(a, "data-robot").unwrap())
        .collect();
    assert_eq!(robots, ["irobot", "ti", "nxt"]);
    // Four mode bands per robot, each with the line of its mode.
    let modes = class("mode");
    assert_eq!(modes.len(), 12);
    let mission = std::fs::read_to_string(scouting()).unwrap();
    for band in &modes {
        let line: usize = attr(band, "data-line").unwrap().parse().unwrap();
        let mode = attr(band, "data-mode").unwrap();
        let text = mission.lines().nth(line - 1).unwrap();
        assert!(text.contains(&format!(".{mode} {{")), "line {line}: {text}");
    }
    // Service bars point at their service's line.
    let bars = class("service");
    assert!(bars.len() >= 12, "{}", bars.len());
    for bar in &bars {
        let line: usize = attr(bar, "data-line").unwrap().parse().unwrap();
        let service = attr(bar, "data-service").unwrap();
        let text = mission.lines().nth(line - 1).unwrap();
        assert!(
            text.contains(&format!(".{service} {{")),
            "line {line}: {text}"
        );
    }
    assert!(!class("message").is_empty());
    assert!(!class("throw").is_empty() && !class("catch").is_empty());
    // Lane labels do not overlap: at least a line of text apart.
    let mut ys: Vec<f64> = class("lane-label")
        .iter()
        .map(|a| attr(a, "y").unwrap().parse().unwrap())
        .collect();
    assert_eq!(ys.len(), 3);
    ys.sort_by(f64::total_cmp);
    assert!(ys.windows(2).all(|w| w[1] - w[0] >= 12.0), "{ys:?}");

    // Each plan has its colour, the same in every lane, and the legend says which.
    let mut plan_fill = std::collections::BTreeMap::new();
    for bar in &bars {
        let (plan, fill) = (attr(bar, "data-plan").unwrap(), attr(bar, "fill").unwrap());
        assert_eq!(*plan_fill.entry(plan).or_insert(fill), fill, "plan {plan}");
    }
    let fills: std::collections::BTreeSet<_> = plan_fill.values().collect();
    assert_eq!(fills.len(), plan_fill.len(), "{plan_fill:?}");
    let legend = |kind: &str| -> std::collections::BTreeSet<&str> {
        class("legend-entry")
            .iter()
            .filter(|a| attr(a, "data-kind") == Some(kind))
            .map(|a| attr(a, "data-name").unwrap())
            .collect()
    };
    assert_eq!(legend("plans"), plan_fill.keys().copied().collect());
    // Messages: coloured by key, each key in the legend, and not a solid
    // block (one arrow per key and pair every 6 pixels of sending and arrival).
    let messages = class("message");
    let keys: std::collections::BTreeSet<&str> = messages
        .iter()
        .map(|m| attr(m, "data-key").unwrap())
        .collect();
    assert_eq!(legend("messages"), keys);
    let mut seen = std::collections::HashSet::new();
    for m in &messages {
        let bucket =
            |end: &str| (attr(m, end).unwrap().parse::<f64>().unwrap() / 6.0).floor() as i64;
        let at = (
            attr(m, "data-key"),
            attr(m, "data-from"),
            attr(m, "data-to"),
            bucket("x1"),
            bucket("x2"),
        );
        assert!(seen.insert(at), "two arrows within 6 px: {at:?}");
    }
    // Services are named on their bars (where wide enough), and every
    // label comes after the arrows, so none is hidden under them.
    let text = std::fs::read_to_string(&svg).unwrap();
    let service_labels = text.matches("class=\"service-label\"").count();
    assert!(service_labels >= 12, "{service_labels}");
    for service in ["ReceiveCmd", "CheckStatus", "AutonomousReturn"] {
        assert!(
            text.contains(&format!(">{service}</text>")),
            "{service} is not named"
        );
    }
    let labels_at = text.find("<g class=\"labels\">").unwrap();
    assert!(text.find("<g class=\"messages\"").unwrap() < labels_at);
    // How each robot's run ended is marked: all three finish (FINISH).
    let ends: Vec<&str> = class("end")
        .iter()
        .map(|a| attr(a, "data-why").unwrap())
        .collect();
    assert_eq!(ends, ["finished", "finished", "finished"]);
}

/// The refined programs of a mission text, as `semo simulate` gets them.
fn refined(text: &str) -> Vec<semo::refine::RobotProgram> {
    let mut files = semo::workspace::Files::default();
    let id = files.add(
        "random.mission".into(),
        semo::workspace::FileKind::Mission,
        text.to_string(),
    );
    let mut host = semo::host::AnalysisHost::default();
    for f in files.iter() {
        host.set_file(f.id, Some(f.path.clone()), f.kind, f.text.as_str().into());
    }
    let build = host
        .analysis()
        .build_input(id)
        .expect("a generated mission checks");
    semo::refine::refine_checked(&build.input()).programs
}

/// A scenario exercising everything a control firing waits for: sensor
/// values and battery levels changing over time, operator commands, latency
/// and loss, a robot killed and restarted, dropped, delayed and partitioned links.
fn busy_scenario(seed: u64, programs: &[semo::refine::RobotProgram]) -> String {
    use semo::refine::SlotSource;
    let mut rng = support::missiongen::Rng::new(seed);
    let values = [
        "0", "15", "50", "250", "DARK", "BRIGHT", "done", "0,0", "3,3", "true", "false",
    ];
    let names: Vec<&str> = programs.iter().map(|p| p.robot.as_str()).collect();
    let mut robots = Vec::new();
    let mut operator = Vec::new();
    for p in programs {
        let mut sensors = Vec::new();
        for slot in &p.control.slots {
            if let SlotSource::Sensor { port, .. } = &slot.source {
                // A sensor gives values of its catalog type (the scenario
                // reader refuses others); the operator's text may be of
                // any (a robot refuses a command not of its key's type).
                let fitting: Vec<&str> = values
                    .iter()
                    .copied()
                    .filter(|v| slot.kind.parse(v).is_some())
                    .collect();
                for _ in 0..3 {
                    sensors.push(format!(
                        r#"{{"at": {}, "value": "{port}", "is": "{}"}}"#,
                        rng.below(3000),
                        rng.pick(&fitting)
                    ));
                }
            }
        }
        for incoming in &p.control.incoming {
            if let Some(key) = incoming.key.strip_prefix("USER.") {
                operator.push(format!(
                    r#"{{"at": {}, "to": "{}", "value": "{key}", "is": "{}"}}"#,
                    rng.below(3000),
                    p.robot,
                    rng.pick(&values)
                ));
            }
        }
        robots.push(format!(
            r#""{}": {{"sensors": [{}], "services": {{"move": {}}}, "battery": [{{"at": 0, "level": 100}}, {{"at": 2500, "level": 10}}]}}"#,
            p.robot,
            sensors.join(", "),
            50 + rng.below(300)
        ));
    }
    let (a, b) = (names[0], names[names.len() - 1]);
    let mut faults = vec![
        format!(r#"{{"from": 200, "until": 900, "drop": ["{a}", "{b}"]}}"#),
        format!(r#"{{"from": 900, "until": 1600, "delay": ["{a}", "{b}"], "by": 150}}"#),
        format!(r#"{{"from": 1600, "until": 2200, "partition": [["{a}"], ["{b}"]]}}"#),
    ];
    if names.len() > 1 {
        faults.push(format!(
            r#"{{"at": {}, "kill": "{b}"}}"#,
            300 + rng.below(500)
        ));
        faults.push(format!(
            r#"{{"at": {}, "restart": "{b}"}}"#,
            1200 + rng.below(500)
        ));
    }
    format!(
        r#"{{"duration": 3000, "robots": {{{}}}, "operator": [{}], "network": {{"latency": {}, "loss": 0.2}}, "faults": [{}]}}"#,
        robots.join(", "),
        operator.join(", "),
        rng.below(4),
        faults.join(", ")
    )
}

/// Skipping idle control firings (the simulator's speed) changes no trace:
/// random missions on busy scenarios give, for two seeds each, the same
/// trace as when every firing is simulated.
#[test]
fn skipping_idle_firings_changes_no_trace() {
    let catalog = semo::catalog::builtin_catalog();
    let mut firings_saved = 0;
    for seed in 0..16 {
        let programs = refined(&support::missiongen::mission(seed, &catalog));
        let text = busy_scenario(seed, &programs);
        let scenario = semo::sim::scenario::parse(&text, &programs)
            .unwrap_or_else(|e| panic!("seed {seed}: {e:?}\n{text}"));
        for sim_seed in [1, 2] {
            let options = semo::sim::Options {
                seed: sim_seed,
                ..semo::sim::Options::default()
            };
            let skipping = semo::sim::simulate(&programs, &scenario, &options);
            let every = semo::sim::simulate(
                &programs,
                &scenario,
                &semo::sim::Options {
                    every_firing: true,
                    ..options
                },
            );
            assert_eq!(
                skipping.trace_lines(),
                every.trace_lines(),
                "seed {seed}/{sim_seed}, scenario {text}"
            );
            firings_saved += every.events - skipping.events;
        }
    }
    // The skipping is exercised, not only harmless.
    assert!(firings_saved > 0);
}

/// The files of a built folder, by path, each as a program reads it: the
/// mission's file name `rename.0` written as `rename.1`, C comments (`/* */`),
/// XML comments and Makefile comment lines left out (they cite the source
/// lines, which differ between a function and its hand-written copy), and
/// without the manifest of the files' hashes.
fn built_files(out: &Path, renames: &[(&str, &str)]) -> std::collections::BTreeMap<String, String> {
    fn strip(text: &str, open: &str, close: &str) -> String {
        let mut kept = String::new();
        let mut rest = text;
        while let Some(start) = rest.find(open) {
            kept.push_str(&rest[..start]);
            let after = &rest[start + open.len()..];
            rest = after
                .find(close)
                .map_or("", |end| &after[end + close.len()..]);
        }
        kept + rest
    }
    let mut files = std::collections::BTreeMap::new();
    let mut folders = vec![out.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            let name = path.strip_prefix(out).unwrap().display().to_string();
            if name.ends_with(".semo-manifest") {
                continue;
            }
            let text = renames.iter().fold(
                std::fs::read_to_string(&path).unwrap(),
                |text, (from, to)| text.replace(from, to),
            );
            let text = strip(&strip(&text, "/*", "*/"), "<!--", "-->");
            let text: Vec<&str> = text
                .lines()
                .filter(|l| !(name.ends_with("Makefile") && l.starts_with('#')))
                .collect();
            files.insert(name, text.join("\n"));
        }
    }
    files
}

/// Functions with parameters (issue 36) are inlined with each argument in
/// its parameter's place: `tests/fixtures/parameters/patrol.mission` (a word,
/// bare words, a number, a robot value, passed on from one function to
/// another, compared, sent) simulates to the same trace as the same mission
/// with every call written out by hand, and builds to the same programs
/// (but for the comments that cite the mission's lines).
#[test]
fn a_function_with_parameters_runs_and_builds_as_its_hand_written_copy() {
    let trace = runs_and_builds_alike("parameters", "patrol", "patrol_by_hand");
    assert!(
        trace.contains(r#""service":"move","arg":"hall door""#)
            && trace.contains(r#""key":"Scouts.Seen","value":"2,3""#)
            && trace.contains(r#""mode":"HOME""#),
        "the run does not reach what it should show:\n{trace}"
    );
}

/// Simulates (on `<a>.scenario.json`) and builds the missions `a` and `b` of
/// the fixture folder `tests/fixtures/<folder>`, which must agree: the same
/// trace, and the same generated files but for the comments that cite the
/// mission's lines (`b`'s file name read as `a`'s). `a`'s trace.
fn runs_and_builds_alike(folder: &str, a: &str, b: &str) -> String {
    runs_and_builds_alike_renamed(folder, a, b, &[])
}

/// [`runs_and_builds_alike`], `a`'s trace and files read with each of
/// `names` (`a`'s name of a mode or service, `b`'s) replaced by `b`'s.
fn runs_and_builds_alike_renamed(folder: &str, a: &str, b: &str, names: &[(&str, &str)]) -> String {
    let fixtures = repo_root().join("tests/fixtures").join(folder);
    let scenario = fixtures.join(format!("{a}.scenario.json"));
    let dir = scratch(folder);
    let file = (format!("{b}.mission"), format!("{a}.mission"));
    let mut traces = Vec::new();
    let mut builds = Vec::new();
    for name in [a, b] {
        let renames: Vec<(&str, &str)> = match name == a {
            true => names.to_vec(),
            false => vec![(file.0.as_str(), file.1.as_str())],
        };
        let mission = fixtures.join(format!("{name}.mission"));
        let out = support::simulate_trace(&mission, &scenario, "sim");
        assert_eq!(out.code, 0, "{name}: {}{}", out.stdout, out.stderr);
        let trace = renames
            .iter()
            .fold(out.stdout, |text, (from, to)| text.replace(from, to));
        traces.push(trace);
        let folder = dir.join(name);
        let mission = mission.display().to_string();
        let built = semo(&["build", &mission, "-o", &folder.display().to_string()]);
        assert_eq!(built.code, 0, "{name}: {}{}", built.stdout, built.stderr);
        builds.push(built_files(&folder, &renames));
    }
    assert_eq!(traces[0], traces[1]);
    assert_eq!(
        builds[0].keys().collect::<Vec<_>>(),
        builds[1].keys().collect::<Vec<_>>()
    );
    for (file, text) in &builds[0] {
        assert_eq!(text, &builds[1][file], "{file}");
    }
    traces.swap_remove(0)
}

/// Modes with parameters (issue 36) are one mode of the machine per list
/// of arguments they are entered with, each running its services with the
/// mode's arguments in place of the parameters:
/// `tests/fixtures/mode_params/rounds.mission` (two modes with parameters,
/// a `case` for each holding in every mode it is entered as, a service set
/// with a word, bare words and a number, compared, sent, inside a group)
/// simulates to the same trace as the same mission with those modes and
/// services written out by hand, and builds to the same programs (but for
/// the comments that cite the mission's lines and the names' texts).
#[test]
fn a_mode_with_parameters_runs_and_builds_as_its_hand_written_copy() {
    let names = [
        ("MOVE(kitchen, 2)", "MOVE_kitchen__2_"),
        ("SEARCH(hall door)", "SEARCH_hall_door_"),
        ("Go(kitchen, 2)", "Go_kitchen__2_"),
        ("Look(hall door)", "Look_hall_door_"),
    ];
    let trace = runs_and_builds_alike_renamed("mode_params", "rounds", "rounds_by_hand", &names);
    assert!(
        trace.contains(r#""service":"move","arg":"kitchen""#)
            && trace.contains(r#""key":"Scouts.Area","value":"hall door""#)
            && trace.contains(r#""catch","name":"arrived","mode":"SEARCH_hall_door_""#)
            && trace.contains(r#""mode":"HOME""#),
        "the run does not reach what it should show:\n{trace}"
    );
}

/// A service shared by teams (`tests/fixtures/shared_services/rescue.mission`,
/// `Scouts, Rovers.Action.Search`) is each team's own: it simulates to the
/// same trace as the mission with one copy per team, and builds to the same
/// programs but for the comments that cite the mission's lines.
#[test]
fn a_service_shared_by_teams_runs_and_builds_as_one_copy_per_team() {
    let trace = runs_and_builds_alike("shared_services", "rescue", "rescue_copies");
    for robot in ["ti", "ir", "tb"] {
        let started = format!(
            r#""robot":"{robot}","event":"service_start","plan":"Action","service":"Search""#
        );
        assert!(trace.contains(&started), "{robot} runs Search:\n{trace}");
    }
}

/// Action results (`FOUND, WHERE = search(...)`): each call done takes the
/// scenario's next entry for its service (a function's call too), the last
/// one again past the list; a call stopped by its timeout gives nothing back
/// and takes no entry, so its result stays none; what a result took is
/// traced (`result`) and decides what the robot does next.
#[test]
fn action_results_take_the_scenario_s_values_call_by_call() {
    let fixtures = repo_root().join("tests/fixtures/action_results");
    let out = semo(&[
        "simulate",
        &fixtures.join("survey.mission").display().to_string(),
        "--scenario",
        &fixtures.join("survey.scenario.json").display().to_string(),
        "--trace",
        "-",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let lines: Vec<String> = out
        .stdout
        .lines()
        .filter(|l| {
            ["result", "send", "timeout", "call_start"]
                .iter()
                .any(|e| l.contains(&format!("\"event\":\"{e}\"")))
        })
        .map(|l| {
            l.replace("{\"t\":", "")
                .replace(",\"robot\":\"ti\",\"event\":", " ")
        })
        .collect();
    let expected = [
        r#"0 "call_start","task":"search","service":"search","arg":"red paper"}"#,
        r#"200 "result","service":"search","name":"FOUND","value":true}"#,
        r#"200 "result","service":"search","name":"WHERE","value":"3,4"}"#,
        r#"200 "call_start","task":"wheel","service":"move","arg":"3,4"}"#,
        r#"300 "send","to":"USER","key":"R.Spot","value":"3,4"}"#,
        r#"1000 "call_start","task":"search","service":"search","arg":"red paper"}"#,
        r#"1200 "result","service":"search","name":"FOUND","value":false}"#,
        r#"1200 "result","service":"search","name":"WHERE","value":null}"#,
        r#"1200 "call_start","task":"search","service":"search","arg":"blue"}"#,
        r#"1310 "timeout","service":"search"}"#,
        r#"1310 "send","to":"USER","key":"R.Spot","value":null}"#,
        r#"2000 "call_start","task":"search","service":"search","arg":"red paper"}"#,
        r#"2200 "result","service":"search","name":"FOUND","value":true}"#,
        r#"2200 "result","service":"search","name":"WHERE","value":"7"}"#,
        r#"2200 "call_start","task":"wheel","service":"move","arg":"7"}"#,
        r#"2300 "send","to":"USER","key":"R.Spot","value":"7"}"#,
        r#"3000 "call_start","task":"search","service":"search","arg":"red paper"}"#,
        r#"3200 "result","service":"search","name":"FOUND","value":true}"#,
        r#"3200 "result","service":"search","name":"WHERE","value":"7"}"#,
        r#"3200 "call_start","task":"wheel","service":"move","arg":"7"}"#,
        r#"3300 "send","to":"USER","key":"R.Spot","value":"7"}"#,
    ];
    assert_eq!(lines, expected, "{}", out.stdout);

    // A result that is not an array of values is refused with its position.
    let dir = scratch("results");
    let scenario = write(
        &dir,
        "bad.scenario.json",
        r#"{"robots": {"ti": {"services": {"search": {"ms": 10, "results": [[{"x": 1}]]}}}}}"#,
    );
    let bad = semo(&[
        "simulate",
        &fixtures.join("survey.mission").display().to_string(),
        "--scenario",
        &scenario,
    ]);
    assert_eq!(bad.code, 2, "{}", bad.stderr);
    assert!(
        bad.stderr
            .contains(":1:67: a result is true, false, a number, a string or null"),
        "{}",
        bad.stderr
    );

    // A value the result's type does not read is refused where it is
    // written, not taken as none (FOUND is a bool in the catalog).
    let scenario = write(
        &dir,
        "wrong.scenario.json",
        r#"{"robots": {"ti": {"services": {"search": {"ms": 10, "results": [["yes", "3,4"]]}}}}}"#,
    );
    let wrong = semo(&[
        "simulate",
        &fixtures.join("survey.mission").display().to_string(),
        "--scenario",
        &scenario,
    ]);
    assert_eq!(wrong.code, 2, "{}", wrong.stderr);
    assert!(
        wrong.stderr.contains(
            ":1:67: result FOUND of search must be a value of its type (bool), not \"yes\""
        ),
        "{}",
        wrong.stderr
    );
}

/// The fire example (issue 36: counted groups, action results and a
/// broadcast in a counted arm together): the searcher that finds the fire
/// tells its own room only, whose two robots fight it; the other rooms go
/// on searching, the leader reports to the base, and robot `fb_0`, lost and
/// restarted, moves the others between the rooms without a fight. The
/// scenario's own expectations say which robots fight; the trace says the
/// base heard of it.
#[test]
fn in_the_fire_example_only_the_room_that_found_the_fire_fights_it() {
    let fire = examples().join("fire");
    let svg = scratch("fire").join("fire.svg");
    let out = semo(&[
        "simulate",
        &fire.join("fire.mission").display().to_string(),
        "--scenario",
        &fire.join("fire.scenario.json").display().to_string(),
        "--trace",
        "-",
        "--svg",
        &svg.display().to_string(),
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let events: Vec<serde_json::Value> = out
        .stdout
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let fighters: std::collections::BTreeSet<&str> = events
        .iter()
        .filter(|e| e["event"] == "mode" && e["mode"] == "FIGHT")
        .map(|e| e["robot"].as_str().unwrap())
        .collect();
    assert_eq!(fighters.into_iter().collect::<Vec<_>>(), ["fb_3", "fb_4"]);
    assert!(
        events.iter().any(|e| e["robot"] == "base"
            && e["event"] == "send"
            && e["to"] == "USER"
            && e["value"] == "6,2"),
        "the base never warned the operator"
    );
    // The timeline marks each robot's group where it changes, as traced.
    let traced: Vec<(String, String)> = (events.iter())
        .filter(|e| e["event"] == "allocated")
        .map(|e| (e["t"].to_string(), e["name"].as_str().unwrap().to_string()))
        .collect();
    let elements = svg_elements(&std::fs::read_to_string(&svg).unwrap());
    let mut drawn: Vec<(String, String)> = (elements.iter())
        .filter(|(_, a)| attr(a, "class") == Some("allocated"))
        .map(|(_, a)| {
            let at = attr(a, "data-t").unwrap().to_string();
            (at, attr(a, "data-group").unwrap().to_string())
        })
        .collect();
    let mut sorted = traced.clone();
    sorted.sort();
    drawn.sort();
    assert!(traced.iter().any(|(_, group)| group == "Hall"));
    assert_eq!(drawn, sorted);
}
