//! The exact comparison of two runs' traces, by robot and mission instant
//! (`tests/differential.rs`, `tests/board_lockstep.rs`): per robot and per
//! instant the same events, compared as a set (the order in which a robot
//! writes the lines of one instant is not part of the meaning; which
//! instant each happens in is).

use std::collections::BTreeMap;
use std::path::Path;

pub type Event = serde_json::Map<String, serde_json::Value>;

pub fn field<'e>(event: &'e Event, key: &str) -> &'e str {
    event.get(key).and_then(|v| v.as_str()).unwrap_or("")
}

pub fn parse_trace(text: &str) -> Vec<Event> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("bad trace line {l}: {e}")))
        .collect()
}

/// The events of a merged trace, by robot.
pub fn by_robot(events: Vec<Event>) -> BTreeMap<String, Vec<Event>> {
    let mut traces: BTreeMap<String, Vec<Event>> = BTreeMap::new();
    for event in events {
        traces
            .entry(field(&event, "robot").to_string())
            .or_default()
            .push(event);
    }
    traces
}

/// Each robot's events by mission instant, every event as canonical JSON
/// (its fields in name order), the events of one instant sorted.
pub fn by_instant<'e>(events: impl Iterator<Item = &'e Event>) -> BTreeMap<i64, Vec<String>> {
    let mut instants: BTreeMap<i64, Vec<String>> = BTreeMap::new();
    for e in events {
        let canonical: BTreeMap<&String, &serde_json::Value> = e.iter().collect();
        instants
            .entry(e["t"].as_i64().expect("every trace line has its time"))
            .or_default()
            .push(serde_json::to_string(&canonical).unwrap());
    }
    for events in instants.values_mut() {
        events.sort_unstable();
    }
    instants
}

/// The differences between `robot`'s events in C and in the simulator: the
/// first few instants at which they differ, with the events of each side
/// that the other lacks.
pub fn differences(robot: &str, c: &[Event], sim: &[Event]) -> Vec<String> {
    let (c, sim) = (
        by_instant(c.iter()),
        by_instant(sim.iter().filter(|e| field(e, "robot") == robot)),
    );
    let mut instants: Vec<i64> = c.keys().chain(sim.keys()).copied().collect();
    instants.sort_unstable();
    instants.dedup();
    let none = Vec::new();
    let mut out = Vec::new();
    for t in instants {
        let (in_c, in_sim) = (c.get(&t).unwrap_or(&none), sim.get(&t).unwrap_or(&none));
        if in_c == in_sim {
            continue;
        }
        let mut text = format!("{robot} at {t} ms:");
        for (side, events, other) in [("C  ", in_c, in_sim), ("sim", in_sim, in_c)] {
            for e in events.iter().filter(|e| !other.contains(e)) {
                text.push_str(&format!("\n  only in {side}: {e}"));
            }
        }
        out.push(text);
        if out.len() == 5 {
            out.push(format!("{robot}: more instants differ"));
            break;
        }
    }
    out
}

/// The differences of a whole run: per robot, as [`differences`]; a robot
/// with events on one side only counts too.
pub fn run_differences(c: &BTreeMap<String, Vec<Event>>, sim: &[Event]) -> Vec<String> {
    let mut robots: Vec<&str> = c.keys().map(String::as_str).collect();
    for e in sim {
        if !robots.contains(&field(e, "robot")) {
            robots.push(field(e, "robot"));
        }
    }
    robots
        .into_iter()
        .flat_map(|robot| differences(robot, c.get(robot).map_or(&[][..], |v| v), sim))
        .collect()
}

/// The robots of `mission`, in peer order: `semo build --target linux`
/// into `out`, without compiling them (the robots of a simulation are the
/// same).
pub fn robots_of(out: &Path, mission: &Path) -> Vec<String> {
    let built = super::semo_in(
        &super::repo_root(),
        &[
            "build",
            &mission.display().to_string(),
            "--target",
            "linux",
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    super::robots::robot_folders(out)
        .into_iter()
        .map(|folder| folder.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}
