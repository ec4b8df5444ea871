//! `semo replay` as a user runs it on the traces of a run: written by `semo
//! simulate --trace`, and by the generated `linux-sim` robots run as
//! processes (in lock-step virtual time, `support::robots::run_in_simulation`),
//! each robot its own file. The replay says what `semo simulate` says of the
//! same run (summary, expectations, timeline); a trace with an expected mode
//! taken out fails that expectation by name; a malformed line or a robot the
//! mission lacks is an error at its file, line and column.

mod support;

use std::path::{Path, PathBuf};
use support::{examples, repo_root, semo, semo_with_stdin};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("replay")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scouting() -> PathBuf {
    examples().join("scouting/scouting.mission")
}

fn scouting_scenario() -> PathBuf {
    repo_root().join("tests/fixtures/build/scouting.scenario.json")
}

fn text(path: &Path) -> String {
    path.display().to_string()
}

/// `semo replay TRACES --mission scouting --scenario scouting's, EXTRA`.
fn replay(traces: &[PathBuf], extra: &[&str]) -> support::Output {
    let mut args = vec!["replay".to_string()];
    args.extend(traces.iter().map(|t| text(t)));
    args.extend(["--mission".into(), text(&scouting())]);
    args.extend(["--scenario".into(), text(&scouting_scenario())]);
    args.extend(extra.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    semo(&args)
}

/// A summary without its first line (which says simulated or replayed).
fn body(summary: &str) -> &str {
    summary.split_once('\n').map_or("", |(_, rest)| rest)
}

/// `semo simulate` of scouting, its trace and timeline written to `dir`:
/// (its summary, the trace file, the picture).
fn simulated(dir: &Path) -> (String, PathBuf, String) {
    let trace = dir.join("scouting.trace");
    let svg = dir.join("simulated.svg");
    let out = semo(&[
        "simulate",
        &text(&scouting()),
        "--scenario",
        &text(&scouting_scenario()),
        "--trace",
        &text(&trace),
        "--svg",
        &text(&svg),
    ]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(out.stdout.contains("expectations: 8 of 8 met"));
    (out.stdout, trace, std::fs::read_to_string(svg).unwrap())
}

#[test]
fn a_simulated_run_replays_to_the_same_summary_verdicts_and_timeline() {
    let dir = scratch("simulated");
    let (summary, trace, picture) = simulated(&dir);
    let svg = dir.join("replayed.svg");
    let out = replay(std::slice::from_ref(&trace), &["--svg", &text(&svg)]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    let lines = std::fs::read_to_string(&trace).unwrap().lines().count();
    assert_eq!(
        out.stdout.lines().next().unwrap(),
        format!(
            "replayed 3 robot(s) from 1 trace file(s): {lines} lines to 9020 ms of mission time"
        )
    );
    assert_eq!(body(&out.stdout), body(&summary));
    // The same picture: lanes, bands, bars, and the arrows drawn from each
    // message's send, found again in the trace.
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), picture);
    // --format json: the same robots and expectations as simulate's.
    let json = |out: &support::Output| -> serde_json::Value {
        serde_json::from_str(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", out.stdout))
    };
    let replayed = json(&replay(std::slice::from_ref(&trace), &["--format", "json"]));
    let simulated = json(&semo(&[
        "simulate",
        &text(&scouting()),
        "--scenario",
        &text(&scouting_scenario()),
        "--format",
        "json",
    ]));
    assert_eq!(replayed["command"], "replay");
    for key in ["robots", "expectations", "ok", "end_ms"] {
        assert!(!replayed[key].is_null(), "{key}: {replayed}");
        assert_eq!(replayed[key], simulated[key], "{key}");
    }
    assert_eq!(replayed["ok"], true);
    assert_eq!(replayed["expectations"].as_array().unwrap().len(), 8);
    assert_eq!(replayed["events"], lines);
    // The trace on standard input reads the same.
    let piped = semo_with_stdin(
        &repo_root(),
        &[
            "replay",
            "-",
            "--mission",
            &text(&scouting()),
            "--scenario",
            &text(&scouting_scenario()),
        ],
        &std::fs::read_to_string(&trace).unwrap(),
    );
    assert_eq!(piped.code, 0, "{}", piped.stderr);
    assert_eq!(body(&piped.stdout), body(&summary));
}

#[test]
fn generated_robots_traces_replay_to_the_simulators_verdicts() {
    let dir = scratch("generated");
    let (summary, _, _) = simulated(&dir);
    let scenario = std::fs::read_to_string(scouting_scenario()).unwrap();
    let traces = support::robots::run_in_simulation(&scouting(), &dir.join("out"), &scenario);
    assert_eq!(traces.len(), 3, "{traces:?}");
    // Each robot's own file, as each process writes it with --trace.
    let mut files = Vec::new();
    for (robot, lines) in &traces {
        assert!(!lines.is_empty(), "{robot} wrote nothing");
        let file = dir.join(format!("{robot}.trace"));
        std::fs::write(&file, lines.join("\n") + "\n").unwrap();
        files.push(file);
    }
    let out = replay(&files, &[]);
    assert_eq!(out.code, 0, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout
            .starts_with("replayed 3 robot(s) from 3 trace file(s): "),
        "{}",
        out.stdout
    );
    // Lock-step runs give the simulator's trace event for event
    // (tests/differential.rs): the same modes, ends and verdicts.
    assert_eq!(body(&out.stdout), body(&summary));
}

#[test]
fn a_trace_without_an_expected_mode_fails_that_expectation_by_name() {
    let dir = scratch("modified");
    let (_, trace, _) = simulated(&dir);
    let all = std::fs::read_to_string(&trace).unwrap();
    let entered = r#""robot":"irobot","event":"mode","mode":"RETURN_MODE""#;
    assert_eq!(all.lines().filter(|l| l.contains(entered)).count(), 1);
    let cut: String = all
        .lines()
        .filter(|l| !l.contains(entered))
        .map(|l| format!("{l}\n"))
        .collect();
    let modified = dir.join("modified.trace");
    std::fs::write(&modified, cut).unwrap();
    let out = replay(&[modified], &[]);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("expectations: 7 of 8 met"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("  FAIL irobot enters RETURN_MODE: never entered\n"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("  MasterTeam/irobot: AUTO_MODE@0 -> WAIT_MODE@1050 -> FINISH@9010"),
        "{}",
        out.stdout
    );
}

#[test]
fn bad_lines_and_unknown_robots_are_errors_at_their_place() {
    let dir = scratch("mistakes");
    let (_, trace, _) = simulated(&dir);
    let good = std::fs::read_to_string(&trace).unwrap();
    let first: String = good.lines().take(4).map(|l| format!("{l}\n")).collect();
    let write = |name: &str, third: &str| {
        let lines: Vec<&str> = first.lines().collect();
        let text = format!("{}\n{}\n{third}\n{}\n", lines[0], lines[1], lines[3]);
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    for (name, line, expected) in [
        (
            "robot",
            r#"{"t":0,"robot":"nxtt","event":"stop"}"#,
            r#":3:16: the mission has no robot "nxtt" (did you mean "nxt"?)"#,
        ),
        (
            "json",
            r#"{"t":0,"robot":"nxt","event":"stop""#,
            ":3:36: expected ',' or '}'",
        ),
        (
            "event",
            r#"{"t":0,"robot":"nxt","event":"catched","name":"x"}"#,
            r#":3:30: unknown trace event "catched" (did you mean "catch"?)"#,
        ),
    ] {
        let bad = write(name, line);
        // After a good file: the mistake is the second file's.
        let out = replay(&[trace.clone(), bad.clone()], &[]);
        assert_eq!(out.code, 2, "{name}: {}{}", out.stdout, out.stderr);
        assert_eq!(
            out.stderr.trim_end(),
            format!("trace {}{expected}", bad.display()),
            "{name}"
        );
        assert!(out.stdout.is_empty(), "{name}: {}", out.stdout);
    }
    // The same as JSON: positioned, with the suggestion.
    let bad = write("robot_json", r#"{"t":0,"robot":"nxtt","event":"stop"}"#);
    let out = replay(std::slice::from_ref(&bad), &["--format", "json"]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    let document: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    assert_eq!(document["command"], "replay");
    let diagnostics = document["diagnostics"].as_array().unwrap();
    assert_eq!(diagnostics.len(), 1, "{}", out.stdout);
    let d = &diagnostics[0];
    assert_eq!(d["file"], text(&bad));
    assert_eq!(
        (&d["start"]["line"], &d["start"]["column"]),
        (&3.into(), &16.into())
    );
    assert_eq!(d["suggestion"], "nxt");
    assert_eq!(d["severity"], "error");
    // A file that is not there, and a folder.
    let out = replay(&[dir.join("absent.trace")], &[]);
    assert_eq!(out.code, 2);
    assert!(
        out.stderr.contains("absent.trace:1:1: cannot read it"),
        "{}",
        out.stderr
    );
    let out = replay(std::slice::from_ref(&dir), &[]);
    assert_eq!(out.code, 2);
    assert!(
        out.stderr.contains(":1:1: not a regular file"),
        "{}",
        out.stderr
    );
    // No trace at all is a usage error.
    let out = semo(&["replay", "--mission", &text(&scouting())]);
    assert_eq!(out.code, 2, "{}", out.stderr);
}

/// What the reference Python reader (PyPI `mcap`, `tests/mcap/read.py`)
/// finds in an MCAP file.
fn read_mcap(file: &Path) -> serde_json::Value {
    let python = support::python::venv_with("mcap-venv", "mcap", &["mcap>=1.1,<2"]);
    let out = std::process::Command::new(python)
        .arg(repo_root().join("tests/mcap/read.py"))
        .arg(file)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the reader prints one JSON object")
}

#[test]
fn runs_are_written_as_mcap_files_the_reference_reader_reads() {
    let dir = scratch("mcap");
    let (_, trace, _) = simulated(&dir);
    let simulated_mcap = dir.join("simulated.mcap");
    let out = semo(&[
        "simulate",
        &text(&scouting()),
        "--scenario",
        &text(&scouting_scenario()),
        "--mcap",
        &text(&simulated_mcap),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let replayed_mcap = dir.join("replayed.mcap");
    let out = replay(
        std::slice::from_ref(&trace),
        &["--mcap", &text(&replayed_mcap)],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let robots = [
        ("MasterTeam", "irobot"),
        ("SlaveTeam", "ti"),
        ("SlaveTeam", "nxt"),
    ];
    let kinds = ["modes", "services", "messages", "values", "events"];
    let mut read = Vec::new();
    for file in [&simulated_mcap, &replayed_mcap] {
        let found = read_mcap(file);
        // A channel per robot and kind, JSON messages with a JSON Schema.
        let channels = found["channels"].as_array().unwrap();
        let topics: Vec<&str> = channels
            .iter()
            .map(|c| c["topic"].as_str().unwrap())
            .collect();
        let expected: Vec<String> = robots
            .iter()
            .flat_map(|(team, robot)| kinds.iter().map(move |k| format!("/{team}/{robot}/{k}")))
            .collect();
        assert_eq!(topics, expected);
        let mut validators = std::collections::HashMap::new();
        for c in channels {
            assert_eq!(c["message_encoding"], "json");
            let schema = &found["schemas"][c["schema"].as_str().unwrap()];
            assert_eq!(schema["encoding"], "jsonschema");
            let validator = jsonschema::validator_for(&schema["data"]).expect("a JSON Schema");
            validators.insert(c["topic"].as_str().unwrap().to_string(), validator);
            let topic = c["topic"].as_str().unwrap();
            assert!(topic.starts_with(&format!(
                "/{}/{}/",
                c["metadata"]["team"].as_str().unwrap(),
                c["metadata"]["robot"].as_str().unwrap()
            )));
        }
        // Every trace line is one message, on its robot's channel of its
        // kind, at its mission time in nanoseconds, valid for its schema.
        let messages = found["messages"].as_array().unwrap();
        assert_eq!(messages.len(), lines.len());
        assert_eq!(found["message_count"], lines.len());
        let mut sequences: std::collections::HashMap<&str, u64> = Default::default();
        for m in messages {
            let data = &m["data"];
            let topic = m["topic"].as_str().unwrap();
            let (team, robot) = robots
                .iter()
                .find(|(_, r)| data["robot"] == *r)
                .expect("a robot of the mission");
            let kind = match data["event"].as_str().unwrap() {
                "mode" => "modes",
                "send" | "receive" => "messages",
                "service_start" | "service_end" | "call_start" | "call_end" => "services",
                "actuate" => "values",
                "start" | "stop" | "throw" | "catch" | "drop" | "finish" => "events",
                _ => topic.rsplit('/').next().unwrap(),
            };
            assert_eq!(topic, format!("/{team}/{robot}/{kind}"), "{data}");
            let nanoseconds = data["t"].as_u64().unwrap() * 1_000_000;
            assert_eq!(m["log_time"], nanoseconds);
            assert_eq!(m["publish_time"], nanoseconds);
            assert!(validators[topic].is_valid(data), "{topic}: {data}");
            let next = sequences.entry(topic).or_default();
            assert_eq!(m["sequence"], *next, "{topic}");
            *next += 1;
        }
        // Per channel, as many messages as the trace has lines of its kind.
        for (team, robot) in robots {
            let count = |events: &[&str]| {
                lines
                    .iter()
                    .filter(|l| {
                        l["robot"] == robot && events.contains(&l["event"].as_str().unwrap())
                    })
                    .count() as u64
            };
            let of = |kind: &str| sequences[format!("/{team}/{robot}/{kind}").as_str()];
            assert_eq!(of("modes"), count(&["mode"]), "{robot}");
            assert_eq!(of("messages"), count(&["send", "receive"]), "{robot}");
            assert_eq!(
                of("values"),
                count(&["actuate", "shared_set", "shared_value"]),
                "{robot}"
            );
        }
        // The payloads are the trace lines themselves.
        let mut payloads: Vec<String> = messages.iter().map(|m| m["data"].to_string()).collect();
        let mut written: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        payloads.sort();
        written.sort();
        assert_eq!(payloads, written);
        let irobot_modes: Vec<(u64, &str)> = messages
            .iter()
            .filter(|m| m["topic"] == "/MasterTeam/irobot/modes")
            .map(|m| {
                (
                    m["data"]["t"].as_u64().unwrap(),
                    m["data"]["mode"].as_str().unwrap(),
                )
            })
            .collect();
        assert_eq!(
            irobot_modes,
            [
                (0, "AUTO_MODE"),
                (1050, "WAIT_MODE"),
                (6000, "RETURN_MODE"),
                (9010, "FINISH")
            ]
        );
        read.push(found["messages"].clone());
    }
    // The simulated run and its replay are the same file to a reader.
    assert_eq!(read[0], read[1]);
}
