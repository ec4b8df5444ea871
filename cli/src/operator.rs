//! `semo operator MISSION --broker URL`: the operator console on a live
//! mission (rumqttc; `mqtt://`, or `mqtts://` with the deployment's CA and
//! the operator's client certificate, through `semo_server::live::BrokerAccess`). It sends the `USER` commands the mission receives
//! (one per line on standard input: `RC_CMD RETURN_MODE`), prints what the
//! robots `send(USER, …)`, and prints each robot's status whenever it
//! changes (the retained `semo/<mission>/status/<robot>` topics). It ends
//! when standard input does.
//!
//! The commands and their receivers come from the refined programs (each
//! robot's incoming messages from `USER`); the topics and the datagram are
//! the runtime's (`deploy::topics`; the status and the datagram read and
//! written by `semo_server::live`, which the editor's monitor shares).

use semo::codegen;
use semo::deploy::topics;
use semo::host;
use semo_server::live::{BrokerAccess, DEFAULT_BROKER, Status, datagram_fields, operator_datagram};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, Write};
use std::path::PathBuf;

pub struct Options {
    pub mission: PathBuf,
    pub strategy: Vec<PathBuf>,
    pub broker: Option<String>,
    pub deploy: Option<PathBuf>,
    pub color: bool,
}

/// A `USER` command and the teams that receive it.
struct Command {
    key: String,
    teams: BTreeSet<String>,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let (run, mission) = match host::load_build(&options.mission, &options.strategy) {
        Ok(loaded) => loaded,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let mut run = run;
    let deployment = match &options.deploy {
        None => None,
        Some(path) => {
            match super::deploy::load(
                &mut run,
                path,
                super::output::Format::Human,
                options.color,
                out,
            ) {
                Ok(deployment) => Some(deployment),
                Err(code) => return code,
            }
        }
    };
    let input = match super::build_files(&run.analysis(), mission) {
        Ok(files) => files,
        Err(code) => return code,
    };
    let input = input.input();
    let refined = codegen::refine_checked(&input);
    let Some(first) = refined.programs.first() else {
        run.diagnostics = refined.diagnostics;
        let _ = super::render::human(&run, options.color, &mut std::io::stderr());
        eprintln!("error: refused: fix the errors above first");
        return 1;
    };
    let mission_topic = topics::mission(&first.mission);
    let mut commands: BTreeMap<String, Command> = BTreeMap::new();
    for program in &refined.programs {
        for incoming in program
            .control
            .incoming
            .iter()
            .filter(|i| i.from_team == "USER")
        {
            let name = incoming.key.strip_prefix("USER.").unwrap_or(&incoming.key);
            commands
                .entry(name.to_string())
                .or_insert_with(|| Command {
                    key: incoming.key.clone(),
                    teams: BTreeSet::new(),
                })
                .teams
                .insert(program.team.clone());
        }
    }
    let url = match (&options.broker, &deployment) {
        (Some(url), _) => url.clone(),
        (None, Some(d)) => d.broker.url.clone(),
        (None, None) => DEFAULT_BROKER.to_string(),
    };
    let access = match BrokerAccess::new(&url, deployment.as_ref()) {
        Ok(access) => access,
        Err(why) => {
            eprintln!("error: {why}");
            return 2;
        }
    };
    let mut mqtt = access.options(format!(
        "semo-operator-{}-{}",
        mission_topic,
        std::process::id()
    ));
    mqtt.set_keep_alive(std::time::Duration::from_secs(10));
    let (client, mut connection) = rumqttc::Client::new(mqtt, 64);
    for topic in [
        topics::statuses(&mission_topic),
        topics::team_inbox(&mission_topic, "USER"),
    ] {
        if let Err(e) = client.subscribe(topic, rumqttc::QoS::AtLeastOnce) {
            eprintln!("error: {e}");
            return 2;
        }
    }
    let listing: Vec<String> = commands
        .iter()
        .map(|(name, c)| {
            format!(
                "{name} (to {})",
                c.teams.iter().cloned().collect::<Vec<_>>().join(", ")
            )
        })
        .collect();
    let _ = writeln!(
        out,
        "operator on {url}, mission {mission_topic}; commands: {}; type `NAME VALUE` per line",
        if listing.is_empty() {
            "none".to_string()
        } else {
            listing.join(", ")
        }
    );
    let _ = out.flush();
    // The broker's messages and the operator's lines come to this thread
    // (which holds standard output) as they arrive.
    enum Input {
        Broker(String),
        Line(String),
        End,
        /// The broker cannot be reached this way (its certificate is not
        /// trusted, it refused ours): retrying would only hang.
        Refused(String),
    }
    let (tx, rx) = std::sync::mpsc::channel();
    let listener = {
        let tx = tx.clone();
        let mission_topic = mission_topic.clone();
        std::thread::spawn(move || {
            let mut printed = BTreeMap::new();
            for event in connection.iter() {
                match event {
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) => {
                        match describe(&mission_topic, &p.topic, &p.payload, &mut printed) {
                            Heard::Line(line) => {
                                let _ = tx.send(Input::Broker(line));
                            }
                            Heard::Refused => eprintln!(
                                "operator: refused a message on {}: not a runtime message from the sender its topic names",
                                p.topic
                            ),
                            Heard::Nothing => {}
                        }
                    }
                    Ok(rumqttc::Event::Outgoing(rumqttc::Outgoing::Disconnect)) => break,
                    Ok(_) => {}
                    Err(e) => {
                        let failure = access.failure(&e);
                        if failure.permanent {
                            let _ = tx.send(Input::Refused(failure.message));
                            break;
                        }
                        eprintln!(
                            "operator: connection to the broker: {} (retrying)",
                            failure.message
                        );
                        std::thread::sleep(std::time::Duration::from_secs(1));
                    }
                }
            }
        })
    };
    std::thread::spawn(move || {
        for line in std::io::stdin().lock().lines() {
            let Ok(line) = line else { break };
            if tx.send(Input::Line(line)).is_err() {
                return;
            }
        }
        let _ = tx.send(Input::End);
    });
    let mut status = 0;
    for input in rx.iter() {
        let line = match input {
            Input::Broker(line) => {
                let _ = writeln!(out, "{line}");
                let _ = out.flush();
                continue;
            }
            Input::End => break,
            Input::Refused(why) => {
                eprintln!("error: cannot connect to {url}: {why}");
                status = 2;
                break;
            }
            Input::Line(line) => line,
        };
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let (name, value) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let name = name.strip_prefix("USER.").unwrap_or(name);
        let Some(command) = commands.get(name) else {
            eprintln!(
                "operator: the mission receives no USER command `{name}` (it receives: {})",
                commands.keys().cloned().collect::<Vec<_>>().join(", ")
            );
            status = 1;
            continue;
        };
        let payload = operator_datagram(&command.key, value.trim());
        for team in &command.teams {
            let topic = topics::to_team(&mission_topic, team, &command.key, topics::OPERATOR);
            if let Err(e) = client.publish(topic, rumqttc::QoS::AtLeastOnce, false, payload.clone())
            {
                eprintln!("operator: {e}");
                status = 1;
            }
        }
        let _ = writeln!(out, "sent {} = {}", command.key, value.trim());
        let _ = out.flush();
    }
    let _ = client.disconnect();
    let _ = listener.join();
    status
}

/// What a message from the broker comes to.
enum Heard {
    /// A line to print.
    Line(String),
    /// A message whose payload claims another sender than its topic: the
    /// broker vouches only for the topic, so it is said and dropped.
    Refused,
    /// Nothing new (a status unchanged, a topic we do not read).
    Nothing,
}

/// The line to print for a message of mission `mission` (its topic name):
/// a robot's `send(USER, …)`, or its status when it changed.
fn describe(
    mission: &str,
    topic: &str,
    payload: &[u8],
    printed: &mut BTreeMap<String, String>,
) -> Heard {
    let status_prefix = topics::statuses(mission);
    let status_prefix = status_prefix.trim_end_matches('+');
    let Some(last) = topic.strip_prefix(status_prefix) else {
        return match datagram_fields(topic, mission, "USER", payload) {
            Some([_, robot, key, value]) => {
                Heard::Line(format!("{robot}: send(USER, {key}) = {value}"))
            }
            None => Heard::Refused,
        };
    };
    let Some(status) = Status::decode(last, payload) else {
        return Heard::Refused;
    };
    let line = format!(
        "status {last}: {} {}{}{}{}",
        status.state,
        status.mode,
        match status.services_text().as_str() {
            "" => String::new(),
            s => format!(" [{s}]"),
        },
        match status.leader.as_str() {
            "" => String::new(),
            l => format!(" leader {l}"),
        },
        match status.battery {
            Some(level) => format!(" battery {level}"),
            None => String::new(),
        }
    );
    if printed.get(last) == Some(&line) {
        return Heard::Nothing;
    }
    printed.insert(last.to_string(), line.clone());
    Heard::Line(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn heard(topic: &str, payload: &[u8], printed: &mut BTreeMap<String, String>) -> String {
        match describe("scouting", topic, payload, printed) {
            Heard::Line(line) => line,
            Heard::Refused => "refused".into(),
            Heard::Nothing => "nothing".into(),
        }
    }

    #[test]
    fn a_message_is_printed_only_from_the_sender_its_topic_names() {
        let irobot = topics::Sender {
            team: "MasterTeam",
            robot: "irobot",
        };
        let told = semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: false,
            team: "MasterTeam".into(),
            robot: "irobot".into(),
            key: "MasterTeam.DISTANCE".into(),
            value: Some(semo::refine::Value::Int(50)),
        });
        let own = topics::to_team("scouting", "USER", "MasterTeam.DISTANCE", irobot);
        let printed = &mut BTreeMap::new();
        assert_eq!(
            heard(&own, &told, printed),
            "irobot: send(USER, MasterTeam.DISTANCE) = 50"
        );
        // The same datagram on a topic the slaves' user may write.
        let ti = topics::Sender {
            team: "SlaveTeam",
            robot: "ti",
        };
        let slaves = topics::to_team("scouting", "USER", "MasterTeam.DISTANCE", ti);
        assert_eq!(heard(&slaves, &told, printed), "refused");
        let status = br#"{"robot":"irobot","state":"running","mode":"WAIT_MODE"}"#;
        assert_eq!(
            heard("semo/scouting/status/irobot", status, printed),
            "status irobot: running WAIT_MODE"
        );
        assert_eq!(
            heard("semo/scouting/status/irobot", status, printed),
            "nothing"
        );
        // Another robot's status on ti's topic is nobody's.
        assert_eq!(heard("semo/scouting/status/ti", status, printed), "refused");
    }
}
