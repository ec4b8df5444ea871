//! The checker's timing facts held to the simulator. W022 says that no robot
//! can have sent a value by the mission's first instant; W024 that no robot
//! can ever feed a receive. Each such finding on a mission (the fixtures and
//! the random missions of `support/missiongen.rs`) is checked against the
//! traces of `semo simulate` on scenarios made to contradict it: one with no
//! latency (a message sent in the first instant arrives in it) and operator
//! commands to every team every 10 ms from the start, one with the default
//! network. W022: no robot of the reading team takes the value at instant 0
//! (nothing sent it then). W024: the robots that run the receive never take
//! a message of its value from its team (for a subscribe, seen only when no
//! send of the value is written: a trace does not tell a publication from a
//! message sent).
//!
//! W023 is a fact about the mission's text (a send that runs once per start
//! of its mode, a receive repeated in the same mode), tested in
//! `compiler/src/sema/values/tests.rs`.

mod support;

use semo::catalog::builtin_catalog;
use semo::diag::{Code, FileId};
use semo::sema::{CheckedMission, Peer, Symbol};
use semo::syntax::ast::CommKind;
use support::missiongen;
use support::robots::{events, field, scratch};
use support::simulate_trace;

/// What a finding says the runs never show: `robots` taking `key` (from
/// team `from`, when given), at or before `until` ms when given.
#[derive(Debug)]
struct Claim {
    finding: String,
    robots: Vec<String>,
    key: String,
    from: Option<String>,
    until: Option<i64>,
}

/// The claims of the W022 and W024 findings of a mission.
fn claims(analysis: &CheckedMission) -> Vec<Claim> {
    let mission = &analysis.mission;
    let mut claims = Vec::new();
    for d in &analysis.diagnostics {
        let robots = || -> Vec<String> {
            let scope = mission.scope_at(d.span.start).expect("a finding in a body");
            let mut robots: Vec<String> = scope
                .runs
                .iter()
                .filter_map(|runners| {
                    let team = mission.team(runners.team?);
                    Some(
                        runners
                            .robots
                            .iter()
                            .map(|&r| team.robot(r).name.to_string()),
                    )
                })
                .flatten()
                .collect();
            robots.sort();
            robots.dedup();
            robots
        };
        let finding = format!("{} at {:?}: {}", d.code, d.span, d.message);
        match d.code {
            Code::ReadBeforeSent => {
                let read = mission
                    .occurrence_at(d.span.end - 1)
                    .expect("the value read");
                let (Symbol::Value {
                    owner: Some(owner),
                    name,
                }
                | Symbol::TeamVariable {
                    team: Some(owner),
                    name,
                }) = &read.symbol
                else {
                    panic!("{finding}: reads {:?}", read.symbol)
                };
                claims.push(Claim {
                    robots: robots(),
                    key: format!("{}.{name}", mission.team(*owner).name),
                    from: None,
                    until: Some(0),
                    finding,
                });
            }
            Code::ReceiveNeverFed => {
                let m = mission
                    .messages
                    .iter()
                    .find(|m| m.span == d.span)
                    .expect("the receive");
                let Peer::Team(from) = m.peer else {
                    panic!("{finding}: from the operator")
                };
                // A trace does not say whether a message came from a send
                // or a publish: a subscribe's claim (no publication) is
                // seen in it only when no send of the value is written.
                let sent = mission.messages.iter().any(|s| {
                    s.kind == CommKind::Send
                        && s.team == from
                        && s.peer == Peer::Team(m.team)
                        && s.value == m.value
                });
                if m.kind == CommKind::Subscribe && sent {
                    continue;
                }
                claims.push(Claim {
                    robots: robots(),
                    key: m.value.to_string(),
                    from: Some(mission.team(from).name.to_string()),
                    until: None,
                    finding,
                });
            }
            _ => {}
        }
    }
    claims
}

/// The scenarios a mission's claims are held to.
fn scenarios(analysis: &CheckedMission) -> [String; 2] {
    let commands: Vec<String> = analysis
        .mission
        .teams
        .iter()
        .map(|t| {
            format!(
                r#"{{"every": 10, "from": 0, "to": "{}", "value": "RC_CMD", "is": "GO"}}"#,
                t.name
            )
        })
        .collect();
    [
        format!(
            r#"{{"duration": 3000, "network": {{"latency": 0}}, "operator": [{}]}}"#,
            commands.join(", ")
        ),
        r#"{"duration": 3000}"#.to_string(),
    ]
}

/// Runs the mission on each scenario and says which claims a trace breaks.
fn broken_claims(
    name: &str,
    text: &str,
    analysis: &CheckedMission,
    claims: &[Claim],
) -> Vec<String> {
    let dir = scratch(&format!("value-flow-{name}"));
    let mission = dir.join(format!("{name}.mission"));
    std::fs::write(&mission, text).unwrap();
    let mut broken = Vec::new();
    for (i, scenario) in scenarios(analysis).iter().enumerate() {
        let path = dir.join(format!("scenario{i}.json"));
        std::fs::write(&path, scenario).unwrap();
        let out = simulate_trace(&mission, &path, "sim");
        assert_eq!(out.code, 0, "{name}: {}\n{text}", out.stderr);
        let lines: Vec<String> = out.stdout.lines().map(str::to_string).collect();
        for (line, event) in lines.iter().zip(events(&lines)) {
            if field(&event, "event") != "receive" {
                continue;
            }
            let t = event["t"].as_i64().unwrap_or(0);
            for claim in claims {
                let breaks = claim.robots.iter().any(|r| r == field(&event, "robot"))
                    && field(&event, "key") == claim.key
                    && claim
                        .from
                        .as_ref()
                        .is_none_or(|f| f == field(&event, "from"))
                    && claim.until.is_none_or(|until| t <= until);
                if breaks {
                    broken.push(format!(
                        "{name}, scenario {scenario}:\n  {}\n  contradicted by {line}\n{text}",
                        claim.finding
                    ));
                }
            }
        }
    }
    broken
}

#[test]
fn the_fixtures_findings_hold_in_the_simulator() {
    let catalog = builtin_catalog();
    let dir = support::repo_root().join("tests/fixtures/diagnostics");
    for (name, code) in [
        ("W022_read_before_sent", Code::ReadBeforeSent),
        ("W024_receive_never_fed", Code::ReceiveNeverFed),
    ] {
        let text = std::fs::read_to_string(dir.join(format!("{name}.mission"))).unwrap();
        let analysis = semo::check_source(FileId(0), &text, &catalog);
        let claims = claims(&analysis);
        assert!(
            claims.iter().any(|c| c.finding.starts_with(code.as_str())),
            "{name}: {claims:?}"
        );
        let broken = broken_claims(name, &text, &analysis, &claims);
        assert!(broken.is_empty(), "{}", broken.join("\n"));
    }
}

/// Over random missions: every claim holds, and the missions make some.
fn random_missions_hold(seeds: std::ops::Range<u64>, at_least: usize) {
    let catalog = builtin_catalog();
    let (mut checked, mut broken) = (0, Vec::new());
    let mut by_code = std::collections::BTreeMap::new();
    for seed in seeds {
        let text = missiongen::mission(seed, &catalog);
        let analysis = semo::check_source(FileId(0), &text, &catalog);
        for d in &analysis.diagnostics {
            if matches!(d.code.as_str(), "W022" | "W023" | "W024") {
                *by_code.entry(d.code.as_str()).or_insert(0) += 1;
            }
        }
        let claims = claims(&analysis);
        if claims.is_empty() {
            continue;
        }
        checked += claims.len();
        broken.extend(broken_claims(
            &format!("seed{seed}"),
            &text,
            &analysis,
            &claims,
        ));
    }
    assert!(broken.is_empty(), "{}", broken.join("\n\n"));
    eprintln!("findings: {by_code:?}; {checked} of them held to the simulator");
    assert!(
        checked >= at_least,
        "only {checked} findings to check in the random missions"
    );
}

#[test]
fn random_missions_findings_hold_in_the_simulator() {
    random_missions_hold(0..200, 5);
}

#[test]
#[ignore = "thousands of missions: run on demand"]
fn thousands_of_random_missions_findings_hold_in_the_simulator() {
    random_missions_hold(1000..4000, 50);
}
