//! `semo operator MISSION --broker URL`: the operator console on a live
//! mission (rumqttc; `mqtt://`, or `mqtts://` with the deployment's CA and
//! the operator's client certificate, through `semo_server::live::BrokerAccess`). It sends the `USER` commands the mission receives
//! (one per line on standard input: `RC_CMD RETURN_MODE`), prints what the
//! robots `send(USER, …)`, and prints each robot's status whenever it
//! changes (the retained `semo/<mission>/<run>/status/<robot>` topics). All
//! of it in one run of the mission: `--run ID`, else the newest
//! (`semo_server::live::RunChoice`), followed as newer ones start. It ends
//! when standard input does.
//!
//! The commands and their receivers come from the refined programs (each
//! robot's incoming messages from `USER`); the topics and the datagram are
//! the runtime's (`deploy::topics`; the status and the datagram read and
//! written by `semo_server::live`, which the editor's monitor shares).
//!
//! A command is said to be sent when the broker has acknowledged it (QoS 1);
//! one typed while the broker cannot be reached is not sent, and said so
//! (exit status 1), never queued to go out later.

use semo::deploy::topics::{self, RunId, Scope};

use semo_server::live::{
    BrokerAccess, DEFAULT_BROKER, RunChoice, Status, datagram_fields, operator_datagram,
    status_topic,
};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::io::{BufRead, Write};
use std::path::PathBuf;

pub struct Options {
    pub mission: PathBuf,
    pub strategy: Vec<PathBuf>,
    pub broker: Option<String>,
    pub deploy: Option<PathBuf>,
    /// The run to show and command; None: the newest.
    pub run: Option<String>,
    pub color: bool,
}

/// A `USER` command and the teams that receive it.
struct Command {
    key: String,
    teams: BTreeSet<String>,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let given_run = match options.run.as_deref().map(RunId::parse).transpose() {
        Ok(run) => run,
        Err(why) => {
            eprintln!("error: --run: {why}");
            return 2;
        }
    };
    let (mut run, mission, deployment) = match super::deploy::load_fleet(
        &options.mission,
        &options.strategy,
        options.deploy.as_deref(),
        options.color,
        out,
    ) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let analysis = run.analysis();
    // The check's errors, reported as every door reports them.
    if let Err(code) = super::build_files(&analysis, mission) {
        return code;
    }
    let Some(refined) = analysis.refined(mission) else {
        eprintln!("error: internal error: the mission is not in the workspace analysis");
        return 2;
    };
    let Some(first) = refined.programs.first() else {
        run.diagnostics = refined.diagnostics.clone();
        let _ = super::render::human(
            &run,
            super::output::Format::Human,
            options.color,
            &mut std::io::stderr(),
        );
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
    let mut view = View {
        mission: mission_topic.clone(),
        run: RunChoice::new(given_run.clone()),
        printed: BTreeMap::new(),
    };
    let scope = view.run.scope(&mission_topic);
    for topic in [topics::statuses(&scope), topics::team_inbox(&scope, "USER")] {
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
        "operator on {url}, mission {mission_topic}, {}; commands: {}; type `NAME VALUE` per line",
        match &given_run {
            Some(run) => format!("run {run}"),
            None => "the newest run".to_string(),
        },
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
        Broker {
            topic: String,
            payload: Vec<u8>,
        },
        Line(String),
        End,
        /// The broker accepted the connection.
        Connected,
        /// The connection failed or was lost (retried): why.
        Lost(String),
        /// The broker acknowledged a command (QoS 1: in the order sent).
        Acked,
        /// The broker cannot be reached this way (its certificate is not
        /// trusted, it refused ours): retrying would only hang.
        Refused(String),
    }
    let (tx, rx) = std::sync::mpsc::channel();
    let listener = {
        let tx = tx.clone();
        std::thread::spawn(move || {
            for event in connection.iter() {
                match event {
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) => {
                        let _ = tx.send(Input::Broker {
                            topic: p.topic,
                            payload: p.payload.to_vec(),
                        });
                    }
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::ConnAck(_))) => {
                        let _ = tx.send(Input::Connected);
                    }
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::PubAck(_))) => {
                        let _ = tx.send(Input::Acked);
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
                        // Nobody listens any more: the console has ended
                        // without a connection to close.
                        if tx.send(Input::Lost(failure.message)).is_err() {
                            break;
                        }
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
    let console = Console {
        mission: &mission_topic,
        commands: &commands,
        client: &client,
    };
    let mut sending = Sending::default();
    let mut status = 0;
    let mut ended = false;
    for input in rx.iter() {
        let typed = match input {
            Input::Broker { topic, payload } => {
                match view.message(&topic, &payload) {
                    Heard::Lines(lines) => {
                        for line in lines {
                            let _ = writeln!(out, "{line}");
                        }
                    }
                    Heard::Refused => eprintln!(
                        "operator: refused a message on {}: not a runtime message from the sender its topic names",
                        crate::terminal::visible(&topic)
                    ),
                }
                Vec::new()
            }
            Input::Connected => sending.link_is(Link::Up),
            Input::Lost(why) => sending.link_is(Link::Down(why)),
            Input::Acked => {
                if let Some(command) = sending.acknowledged() {
                    let _ = writeln!(out, "sent {command}");
                }
                Vec::new()
            }
            // Typed before the connection's first outcome: held until it
            // says whether the line can go.
            Input::Line(line) if sending.link == Link::Connecting => {
                sending.held.push(line);
                Vec::new()
            }
            Input::Line(line) => vec![line],
            Input::End => {
                ended = true;
                Vec::new()
            }
            Input::Refused(why) => {
                eprintln!("error: cannot connect to {url}: {why}");
                status = 2;
                break;
            }
        };
        for line in typed {
            match console.command(&line, view.run.run(), &sending.link) {
                Typed::Nothing => {}
                Typed::Refused => status = 1,
                Typed::Published {
                    command,
                    messages,
                    missed,
                } => {
                    sending.unacknowledged.push_back((command, messages));
                    if missed {
                        status = 1;
                    }
                }
            }
        }
        let _ = out.flush();
        if ended && sending.settled() {
            break;
        }
    }
    for (command, _) in &sending.unacknowledged {
        eprintln!(
            "operator: not confirmed: {command}: the broker did not acknowledge it before the connection was lost"
        );
        status = 1;
    }
    drop(rx);
    let _ = client.disconnect();
    let _ = listener.join();
    status
}

/// The console's connection to the broker.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
enum Link {
    /// No outcome yet.
    #[default]
    Connecting,
    Up,
    /// Failed or lost (retried): why.
    Down(String),
}

/// Where the operator's commands stand: the link, the lines typed before
/// its first outcome, and the commands published and not yet acknowledged,
/// each with the number of its messages (one per receiving team) the
/// broker has still to acknowledge (QoS 1, in the order received). A
/// command is said to be sent only once all its messages are acknowledged.
#[derive(Default)]
struct Sending {
    link: Link,
    held: Vec<String>,
    unacknowledged: VecDeque<(String, usize)>,
}

impl Sending {
    /// The link's new state; gives the lines held for it.
    fn link_is(&mut self, link: Link) -> Vec<String> {
        self.link = link;
        std::mem::take(&mut self.held)
    }

    /// One acknowledgement: the command it completes, if it does.
    fn acknowledged(&mut self) -> Option<String> {
        let (_, left) = self.unacknowledged.front_mut()?;
        *left = left.saturating_sub(1);
        match left {
            0 => self.unacknowledged.pop_front().map(|(command, _)| command),
            _ => None,
        }
    }

    /// Whether nothing typed is still on its way: no line held, and every
    /// command acknowledged unless the link is down (then it cannot be).
    fn settled(&self) -> bool {
        self.held.is_empty()
            && (self.unacknowledged.is_empty() || matches!(self.link, Link::Down(_)))
    }
}

/// What the operator's lines are read against and published with.
struct Console<'a> {
    mission: &'a str,
    commands: &'a BTreeMap<String, Command>,
    client: &'a rumqttc::Client,
}

/// What became of a line the operator typed.
enum Typed {
    /// An empty line.
    Nothing,
    /// Not sent, and said why.
    Refused,
    /// Published as `messages` messages (one per receiving team), to be
    /// acknowledged: `command` is `KEY = VALUE`; `missed`: not to every
    /// team (said).
    Published {
        command: String,
        messages: usize,
        missed: bool,
    },
}

impl Console<'_> {
    /// Reads `NAME VALUE` and publishes the command to every team that
    /// receives it in `run`, if the link is up.
    fn command(&self, line: &str, run: Option<&RunId>, link: &Link) -> Typed {
        let line = line.trim();
        if line.is_empty() {
            return Typed::Nothing;
        }
        let (name, value) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let name = name.strip_prefix("USER.").unwrap_or(name);
        let Some(command) = self.commands.get(name) else {
            eprintln!(
                "operator: the mission receives no USER command `{name}` (it receives: {})",
                self.commands.keys().cloned().collect::<Vec<_>>().join(", ")
            );
            return Typed::Refused;
        };
        let Some(run) = run else {
            eprintln!(
                "operator: no run of mission {} is known yet (no robot's status has come): wait for one, or give --run",
                self.mission
            );
            return Typed::Refused;
        };
        let said = format!("{} = {}", command.key, value.trim());
        if let Link::Down(why) = link {
            eprintln!("operator: not sent: {said}: no connection to the broker {why}");
            return Typed::Refused;
        }
        let scope = Scope::run(self.mission, run);
        let payload = operator_datagram(&command.key, value.trim());
        let mut messages = 0;
        for team in &command.teams {
            let topic = topics::to_team(&scope, team, &command.key, topics::OPERATOR);
            match self
                .client
                .publish(topic, rumqttc::QoS::AtLeastOnce, false, payload.clone())
            {
                Ok(()) => messages += 1,
                Err(e) => eprintln!("operator: not sent to {team}: {said}: {e}"),
            }
        }
        match messages {
            0 => Typed::Refused,
            _ => Typed::Published {
                command: said,
                messages,
                missed: messages < command.teams.len(),
            },
        }
    }
}

/// What a message from the broker comes to.
enum Heard {
    /// Lines to print (none: nothing new, a status unchanged, another
    /// run's message).
    Lines(Vec<String>),
    /// A message whose payload claims another sender than its topic: the
    /// broker vouches only for the topic, so it is said and dropped.
    Refused,
}

/// What the console shows: the run, and what each robot's status line last
/// printed said of it ([`what_counts`]).
struct View {
    /// The mission's topic name.
    mission: String,
    run: RunChoice,
    printed: BTreeMap<String, String>,
}

/// What makes a robot's status worth a new line: its state, mode, leader
/// and counted groups, which an operator acts on. Its services (which come and go
/// every period) and battery level are shown on that line, but their
/// changes alone print nothing: three robots printed 45 lines in 10 s.
fn what_counts(status: &Status) -> String {
    format!(
        "{} {} {} {}",
        status.state,
        status.mode,
        status.leader,
        status.groups_text()
    )
}

impl View {
    /// The lines to print for a message: a robot's `send(USER, …)`, or its
    /// status when it changed, of the run shown; a newer run's status (when
    /// no run is given) is said and followed. What robots say is theirs:
    /// its control characters are shown, never obeyed by the terminal
    /// (`terminal.rs`).
    fn message(&mut self, topic: &str, payload: &[u8]) -> Heard {
        match self.lines(topic, payload) {
            Heard::Lines(lines) => Heard::Lines(
                (lines.iter())
                    .map(|line| crate::terminal::visible(line).into_owned())
                    .collect(),
            ),
            Heard::Refused => Heard::Refused,
        }
    }

    /// [`View::message`]'s lines, as the robots said them.
    fn lines(&mut self, topic: &str, payload: &[u8]) -> Heard {
        let Some((run, robot)) = status_topic(&self.mission, topic) else {
            return self.sent(topic, payload);
        };
        let Some(status) = Status::decode(&robot, payload) else {
            return Heard::Refused;
        };
        let mut lines = Vec::new();
        if self.run.heard(&run, status.started) {
            self.printed.clear();
            lines.push(format!("following run {run} (the newest)"));
        }
        if self.run.run() == Some(&run) {
            let counts = what_counts(&status);
            if self.printed.get(&robot) != Some(&counts) {
                lines.push(status_line(&robot, &status));
                self.printed.insert(robot, counts);
            }
        }
        Heard::Lines(lines)
    }

    /// A robot's `send(USER, …)` of the run shown.
    fn sent(&self, topic: &str, payload: &[u8]) -> Heard {
        let run = topics::run_of(&self.mission, topic);
        let Some(run) = run.filter(|r| self.run.run() == Some(r)) else {
            return Heard::Lines(Vec::new());
        };
        match datagram_fields(topic, &Scope::run(&self.mission, &run), "USER", payload) {
            Some([_, robot, key, value]) => {
                Heard::Lines(vec![format!("{robot}: send(USER, {key}) = {value}")])
            }
            None => Heard::Refused,
        }
    }
}

/// `status ROBOT: STATE MODE [SERVICES] leader L groups G (N alive), ... battery B`.
fn status_line(robot: &str, status: &Status) -> String {
    format!(
        "status {robot}: {} {}{}{}{}{}",
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
        match status.groups_text().as_str() {
            "" => String::new(),
            g => format!(" groups {g}"),
        },
        match status.battery {
            Some(level) => format!(" battery {level}"),
            None => String::new(),
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn heard(view: &mut View, topic: &str, payload: &[u8]) -> String {
        match view.message(topic, payload) {
            Heard::Lines(lines) if lines.is_empty() => "nothing".into(),
            Heard::Lines(lines) => lines.join("\n"),
            Heard::Refused => "refused".into(),
        }
    }

    fn view(run: Option<&str>) -> View {
        View {
            mission: "scouting".into(),
            run: RunChoice::new(run.map(|r| RunId::parse(r).unwrap())),
            printed: BTreeMap::new(),
        }
    }

    fn scope(run: &str) -> Scope {
        Scope::run("scouting", &RunId::parse(run).unwrap())
    }

    const WAITING: &[u8] =
        br#"{"robot":"irobot","state":"running","started":"1000","mode":"WAIT_MODE"}"#;

    /// irobot's datagram sending `MasterTeam.DISTANCE = 50`.
    fn irobot_tells_distance() -> Vec<u8> {
        semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: false,
            team: "MasterTeam".into(),
            robot: "irobot".into(),
            key: "MasterTeam.DISTANCE".into(),
            value: Some(semo::refine::Value::Int(50)),
        })
    }

    #[test]
    fn a_message_is_printed_only_from_the_sender_its_topic_names() {
        let irobot = topics::Sender {
            team: "MasterTeam",
            robot: "irobot",
        };
        let told = irobot_tells_distance();
        let r1 = scope("r1");
        let own = topics::to_team(&r1, "USER", "MasterTeam.DISTANCE", irobot);
        let view = &mut view(Some("r1"));
        assert_eq!(
            heard(view, &own, &told),
            "irobot: send(USER, MasterTeam.DISTANCE) = 50"
        );
        // The same datagram on a topic the slaves' user may write.
        let ti = topics::Sender {
            team: "SlaveTeam",
            robot: "ti",
        };
        let slaves = topics::to_team(&r1, "USER", "MasterTeam.DISTANCE", ti);
        assert_eq!(heard(view, &slaves, &told), "refused");
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", WAITING),
            "status irobot: running WAIT_MODE"
        );
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", WAITING),
            "nothing"
        );
        // Services and battery come and go: shown, but no new line alone.
        let busy = br#"{"robot":"irobot","state":"running","started":"1000","mode":"WAIT_MODE","services":"Action=Wander","battery":71}"#;
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", busy),
            "nothing"
        );
        let moving = br#"{"robot":"irobot","state":"running","started":"1000","mode":"AUTO_MODE","services":"Action=Wander","battery":70}"#;
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", moving),
            "status irobot: running AUTO_MODE [Action=Wander] battery 70"
        );
        // A robot's counted groups are what it does: a change is a new line.
        let room = br#"{"robot":"irobot","state":"running","started":"1000","mode":"AUTO_MODE","services":"Action=Wander","groups":"Room1=4","battery":70}"#;
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", room),
            "status irobot: running AUTO_MODE [Action=Wander] groups Room1 (4 alive) battery 70"
        );
        let moved = br#"{"robot":"irobot","state":"running","started":"1000","mode":"AUTO_MODE","services":"Action=Wander","groups":"Room2=3,Sweeper=1"}"#;
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", moved),
            "status irobot: running AUTO_MODE [Action=Wander] groups Room2 (3 alive), Sweeper (1 alive)"
        );
        // Another robot's status on ti's topic is nobody's.
        assert_eq!(
            heard(view, "semo/scouting/r1/status/ti", WAITING),
            "refused"
        );
    }

    /// A robot's value or status that holds terminal controls (an escape
    /// sequence clearing the screen, a carriage return hiding what came
    /// before) is shown, not obeyed.
    #[test]
    fn control_characters_a_robot_sends_are_shown_not_obeyed() {
        let irobot = topics::Sender {
            team: "MasterTeam",
            robot: "irobot",
        };
        let told = semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: false,
            team: "MasterTeam".into(),
            robot: "irobot".into(),
            key: "MasterTeam.DISTANCE".into(),
            value: Some(semo::refine::Value::text("\x1b[2J\rall clear")),
        });
        let own = topics::to_team(&scope("r1"), "USER", "MasterTeam.DISTANCE", irobot);
        let view = &mut view(Some("r1"));
        assert_eq!(
            heard(view, &own, &told),
            "irobot: send(USER, MasterTeam.DISTANCE) = ␛[2J␍all clear"
        );
        let status = br#"{"robot":"irobot","state":"running","started":"1000","mode":"WAIT\u001b]0;x\u0007"}"#;
        assert_eq!(
            heard(view, "semo/scouting/r1/status/irobot", status),
            "status irobot: running WAIT␛]0;x␇"
        );
    }

    /// Without a run given, the console follows the newest: a newer run's
    /// status is said and shown, an older run's messages are not.
    #[test]
    fn the_console_follows_the_newest_run() {
        let view = &mut view(None);
        assert_eq!(
            heard(view, "semo/scouting/r2/status/irobot", WAITING),
            "following run r2 (the newest)\nstatus irobot: running WAIT_MODE"
        );
        let older = br#"{"robot":"ti","state":"stopped","started":"500","mode":"FINISH"}"#;
        assert_eq!(heard(view, "semo/scouting/r1/status/ti", older), "nothing");
        let told = irobot_tells_distance();
        let irobot = topics::Sender {
            team: "MasterTeam",
            robot: "irobot",
        };
        let old = topics::to_team(&scope("r1"), "USER", "MasterTeam.DISTANCE", irobot);
        assert_eq!(heard(view, &old, &told), "nothing");
        let newer = br#"{"robot":"irobot","state":"running","started":"2000","mode":"AUTO_MODE"}"#;
        assert_eq!(
            heard(view, "semo/scouting/r3/status/irobot", newer),
            "following run r3 (the newest)\nstatus irobot: running AUTO_MODE"
        );
        assert_eq!(view.run.run().map(RunId::as_str), Some("r3"));
    }
}
