//! `--mcap FILE` of `semo simulate` and `semo replay`: a run written as an
//! MCAP file (mcap.dev), for the robotics tools that read one (Foxglove,
//! the `mcap` readers). One channel per robot and kind of event,
//! `/<team>/<robot>/<kind>`: `modes` (`mode`), `services` (services,
//! calls, action machines, timeouts), `messages` (`send`, `receive`),
//! `values` (actuator commands and globally shared values) and `events`
//! (every other line: starts, stops, throws, catches, leaders, ...), so
//! that each trace line is in exactly one channel. A message is the trace
//! line itself (JSON, as `--trace` writes it), logged and published at its
//! mission time in nanoseconds; each kind has a JSON Schema. Uncompressed
//! (the crate's compressions build C code; every reader reads plain chunks).

use semo::refine::RobotProgram;
use semo::sim::Run;
use std::collections::BTreeMap;
use std::io::{Seek, Write};
use std::path::Path;

/// The channels of a robot, by kind: the kind's name and its events
/// (`None`: every event no other kind takes).
pub const KINDS: [(&str, Option<&[&str]>); 5] = [
    ("modes", Some(&["mode"])),
    (
        "services",
        Some(&[
            "service_start",
            "service_end",
            "call_start",
            "call_end",
            "actions_start",
            "actions_end",
            "timeout",
        ]),
    ),
    ("messages", Some(&["send", "receive"])),
    ("values", Some(&["actuate", "shared_set", "shared_value"])),
    ("events", None),
];

/// The kind (index into [`KINDS`]) of an event.
fn kind_of(event: &str) -> usize {
    KINDS
        .iter()
        .position(|(_, events)| events.is_some_and(|e| e.contains(&event)))
        .unwrap_or(KINDS.len() - 1)
}

/// The JSON Schema of a kind's messages: a trace line of its events.
fn schema(kind: &str, events: Option<&[&str]>) -> String {
    let event = match events {
        Some(events) => serde_json::json!({"type": "string", "enum": events}),
        None => serde_json::json!({"type": "string"}),
    };
    let value = serde_json::json!({
        "description": "a mission value: a number, true or false, a word or text, or null (never set)",
        "type": ["number", "boolean", "string", "null"]
    });
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": format!("semo {kind}"),
        "description": "One line of a SeMo trace (docs/scenario-and-trace.md): t in mission ms, the robot, the event and its fields.",
        "type": "object",
        "properties": {
            "t": {"type": "integer", "minimum": 0, "description": "mission ms"},
            "robot": {"type": "string"},
            "event": event,
            "value": value,
            "arg": value,
        },
        "required": ["t", "robot", "event"],
        "additionalProperties": {"type": "string"},
    })
    .to_string()
}

/// Writes the run to `path` (`-`: standard output, through `out`); on
/// failure says so and returns 2.
pub fn write(path: &Path, run: &Run, programs: &[RobotProgram], out: &mut impl Write) -> i32 {
    let written = if path == Path::new("-") {
        let mut buffer = std::io::Cursor::new(Vec::new());
        to(&mut buffer, run, programs)
            .and_then(|()| out.write_all(buffer.get_ref()).map_err(Into::into))
    } else {
        std::fs::File::create(path)
            .map_err(mcap::McapError::from)
            .and_then(|file| {
                let mut file = std::io::BufWriter::new(file);
                to(&mut file, run, programs)?;
                file.flush().map_err(Into::into)
            })
    };
    match written {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            2
        }
    }
}

/// The MCAP file of the run, written to `w`: every robot's channels (in
/// the mission's order, each kind), then every trace line on its channel.
fn to<W: Write + Seek>(w: W, run: &Run, programs: &[RobotProgram]) -> mcap::McapResult<()> {
    let mut writer = mcap::WriteOptions::new()
        .compression(None)
        .profile("")
        .library(concat!("semo ", env!("CARGO_PKG_VERSION")))
        .create(w)?;
    let mut schemas = Vec::new();
    for (kind, events) in KINDS {
        let text = schema(kind, events);
        schemas.push(writer.add_schema(&format!("semo.{kind}"), "jsonschema", text.as_bytes())?);
    }
    // channels[robot][kind], and the next sequence number of each.
    let mut channels: Vec<Vec<(u16, u32)>> = Vec::with_capacity(run.robots.len());
    let mission = programs.first().map_or("", |p| p.mission.as_str());
    for (team, robot) in &run.robots {
        let metadata: BTreeMap<String, String> = [
            ("team".to_string(), team.clone()),
            ("robot".to_string(), robot.clone()),
            ("mission".to_string(), mission.to_string()),
        ]
        .into();
        let mut of_robot = Vec::with_capacity(KINDS.len());
        for ((kind, _), &schema) in KINDS.iter().zip(&schemas) {
            let topic = format!("/{team}/{robot}/{kind}");
            of_robot.push((writer.add_channel(schema, &topic, "json", &metadata)?, 0));
        }
        channels.push(of_robot);
    }
    for e in &run.trace {
        let (channel, sequence) = &mut channels[e.robot][kind_of(e.event)];
        let nanoseconds = u64::try_from(e.t).unwrap_or(0).saturating_mul(1_000_000);
        let header = mcap::records::MessageHeader {
            channel_id: *channel,
            sequence: *sequence,
            log_time: nanoseconds,
            publish_time: nanoseconds,
        };
        *sequence = sequence.wrapping_add(1);
        writer.write_to_known_channel(&header, e.to_json(&run.robots[e.robot].1).as_bytes())?;
    }
    writer.finish()?;
    Ok(())
}
