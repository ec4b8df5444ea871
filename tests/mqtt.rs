//! The MQTT transport as a user runs it: a private `mosquitto` broker on a
//! free loopback port, the scouting mission built with `semo build` and
//! `make TRANSPORT=mqtt`, its robots started as processes with `--transport
//! mqtt --broker mqtt://127.0.0.1:PORT`. They must behave as over the
//! loopback UDP transport (same modes, the master hears every slave's
//! color), and a `send` (QoS 1, persistent session) must reach a robot that
//! was away when it was sent.
//!
//! Needs `mosquitto` and `libmosquitto-dev` (Debian). Skipped with a message
//! when the broker is missing, unless `SEMO_MQTT_TESTS=require` (CI).

mod support;

use semo::deploy::topics;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use support::mosquitto::free_port;
use support::mqtt::{Fleet, Processes, Started, folder_of, read_trace, robot_name};
use support::robots::{Event, PEDANTIC, build_sim, events, field, modes, robot_folders, scratch};
use support::{examples, repo_root};

/// `semo build` of the scouting mission for linux-sim, each robot made with
/// the MQTT transport built in (`make TRANSPORT=mqtt`), warnings as errors.
fn build_scouting(out: &Path) -> Vec<PathBuf> {
    build_scouting_with(out, &[])
}

/// The same with more `semo build` arguments (`--deploy FILE`).
fn build_scouting_with(out: &Path, extra: &[&str]) -> Vec<PathBuf> {
    support::mqtt::build(&examples().join("scouting/scouting.mission"), out, extra)
}

fn scenario() -> PathBuf {
    repo_root().join("tests/fixtures/build/scouting.scenario.json")
}

/// Runs every robot together with `transport_args` and returns its trace.
fn run_together(
    folders: &[PathBuf],
    out: &Path,
    tag: &str,
    transport_args: &[String],
    processes: &mut Processes,
) -> BTreeMap<String, Vec<Event>> {
    // tests/build.rs's block of ports for this process id, at an offset it
    // does not use: runs in parallel do not hear each other.
    let port_base = 20000 + (std::process::id() % 250) * 40 + 30;
    let mut started = Vec::new();
    for folder in folders {
        let robot = robot_name(folder);
        let trace = out.join(format!("{robot}.{tag}.jsonl"));
        let child = support::mqtt::robot_on(folder, &scenario(), &trace, port_base)
            .args(transport_args)
            .stderr(Stdio::piped())
            .spawn()
            .expect("the robot program starts");
        started.push((robot, trace, processes.push(child)));
    }
    let mut traces = BTreeMap::new();
    for (robot, trace, index) in started {
        processes.wait_success(index, &format!("{robot} ({tag})"));
        traces.insert(robot, read_trace(&trace));
    }
    traces
}

fn received_from(events: &[Event], robot: &str, key: &str) -> Vec<String> {
    events
        .iter()
        .filter(|e| {
            field(e, "event") == "receive"
                && field(e, "from_robot") == robot
                && field(e, "key") == key
        })
        .map(|e| field(e, "value").to_string())
        .collect()
}

#[test]
fn scouting_over_mqtt_behaves_as_over_udp() {
    let Some(mut fleet) = Fleet::start("mqtt-scouting") else {
        return;
    };
    let folders = build_scouting(&fleet.out);
    let udp = run_together(
        &folders,
        &fleet.out,
        "udp",
        &["--transport".into(), "udp".into()],
        &mut fleet.processes,
    );
    let mqtt = fleet.run_all(&folders, &scenario(), "mqtt", &[]);

    assert_eq!(mqtt.len(), 3, "three robots");
    for (robot, events) in &mqtt {
        assert_eq!(
            modes(events),
            modes(&udp[robot]),
            "{robot}'s modes over MQTT and over UDP"
        );
        assert_eq!(modes(events).last().map(String::as_str), Some("FINISH"));
    }
    for slave in ["ti", "nxt"] {
        let heard = received_from(&mqtt["irobot"], slave, "SlaveTeam.COLOR");
        assert!(
            !heard.is_empty()
                && !received_from(&udp["irobot"], slave, "SlaveTeam.COLOR").is_empty(),
            "the master receives SlaveTeam.COLOR from {slave} over both transports"
        );
        assert!(
            heard.iter().any(|v| v == "RGB"),
            "the master hears {slave}'s complete set of colors over MQTT: {heard:?}"
        );
    }
}

#[test]
fn a_send_reaches_a_robot_that_was_away_when_it_was_sent() {
    let Some(mut fleet) = Fleet::start("mqtt-qos1") else {
        return;
    };
    let folders = build_scouting(&fleet.out);
    let folder = |robot: &str| folder_of(&folders, robot);

    // The master connects once (its session and subscriptions now exist at
    // the broker) and goes away.
    fleet.run(
        &folder("irobot"),
        &scenario(),
        "first",
        &["--duration", "10"],
    );
    // The broker restarts (its state survives in its persistence file).
    fleet.stop_broker();
    fleet.start_broker();
    // A slave runs its whole mission while the master is away.
    let ti = fleet.run(&folder("ti"), &scenario(), "alone", &[]);
    assert!(
        ti.iter().any(|e| field(e, "event") == "send"
            && field(e, "key") == "SlaveTeam.COLOR"
            && field(e, "value") == "RGB"),
        "ti sends its colors"
    );
    // The master comes back and gets what was sent meanwhile.
    let back = fleet.run(
        &folder("irobot"),
        &scenario(),
        "back",
        &["--duration", "3000"],
    );
    let heard = received_from(&back, "ti", "SlaveTeam.COLOR");
    assert!(
        !heard.is_empty(),
        "the master, back, receives the colors ti sent while it was away"
    );
    // All of them: the burst of hundreds of queued messages at reconnection
    // is held back by a full inbox, never dropped there. (The master, in
    // AUTO_MODE, takes none of the colors: its channel for them drops what
    // does not fit, `channel full`, as the simulator's does.)
    let sent = sent_to(&ti, "MasterTeam");
    assert!(sent.len() > 64, "more than an inbox holds: {}", sent.len());
    assert_eq!(
        received_all_from(&back, "ti"),
        sent,
        "every send of ti arrives"
    );
    assert!(
        !back
            .iter()
            .any(|e| field(e, "event") == "drop" && field(e, "reason") != "channel full"),
        "nothing is dropped from the inbox"
    );
}

/// The first of `sent` (with its index) that `received` lacks, taking them
/// in order, duplicates in `received` skipped: None when `sent` is a
/// subsequence of `received`.
fn missing_from(
    sent: &[(String, String)],
    received: &[(String, String)],
) -> Option<(usize, (String, String))> {
    let mut rest = received.iter();
    sent.iter()
        .enumerate()
        .find(|(_, m)| !rest.any(|r| r == *m))
        .map(|(i, m)| (i, m.clone()))
}

/// The (key, value) of every `send` to `to`, in order.
fn sent_to(events: &[Event], to: &str) -> Vec<(String, String)> {
    events
        .iter()
        .filter(|e| field(e, "event") == "send" && field(e, "to") == to)
        .map(|e| (field(e, "key").to_string(), field(e, "value").to_string()))
        .collect()
}

/// The (key, value) of everything received from `robot`, in order.
fn received_all_from(events: &[Event], robot: &str) -> Vec<(String, String)> {
    events
        .iter()
        .filter(|e| field(e, "event") == "receive" && field(e, "from_robot") == robot)
        .map(|e| (field(e, "key").to_string(), field(e, "value").to_string()))
        .collect()
}

/// Runs a robot program with `args` and returns its exit code and stderr.
fn run_with(folder: &Path, args: &[&str]) -> (Option<i32>, String) {
    run_with_env(folder, args, &[])
}

/// The same with environment variables `env`.
fn run_with_env(folder: &Path, args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String) {
    let mut processes = Processes::default();
    let child = Command::new(folder.join(robot_name(folder)))
        .args(args)
        .envs(env.iter().copied())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the robot program starts");
    let index = processes.push(child);
    let child = &mut processes.0[index];
    let status = child.wait().unwrap();
    let mut stderr = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    (status.code(), stderr)
}

#[test]
fn transport_options_are_checked_and_an_unreachable_broker_is_reported() {
    let out = scratch("mqtt-options");
    let folders = build_scouting(&out);
    let irobot = folders.iter().find(|f| robot_name(f) == "irobot").unwrap();
    for (args, says) in [
        (
            &["--transport", "tcp"][..],
            "the transport must be udp or mqtt",
        ),
        (
            &["--broker", "mqtts://example.org"],
            "an mqtts:// broker needs the CA that signed its certificate",
        ),
        (&["--broker", "mqtt://host:99999"], "port from 1 to 65535"),
        (
            &["--broker", "tcp://host:1883"],
            "the broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT]",
        ),
    ] {
        let (code, stderr) = run_with(irobot, args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    // Nothing listens on a port just freed: the robot says so and stops.
    let port = free_port();
    let broker = format!("mqtt://127.0.0.1:{port}");
    let (code, stderr) = run_with(irobot, &["--transport", "mqtt", "--broker", &broker]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!("cannot reach the MQTT broker at 127.0.0.1:{port}")),
        "{stderr}"
    );
    // A run id (`--run`, `$SEMO_RUN`) is refused as `topics::RunId` refuses
    // it: never a topic level of several, a wildcard, or a name a file
    // system gives a meaning to. One that is fine goes on to the broker.
    let (long, too_long) = ("x".repeat(63), "x".repeat(64));
    for id in [
        "r1",
        "2024-05-01.b",
        &long,
        "a/b",
        "+",
        "#",
        "a+",
        ".",
        "..",
        "-x",
        "a b",
        "é",
        &too_long,
    ] {
        let fine = topics::RunId::parse(id).is_ok();
        for (args, env, name) in [
            (&["--run", id][..], &[][..], "--run"),
            (&[][..], &[("SEMO_RUN", id)][..], "SEMO_RUN"),
        ] {
            let args = [&["--transport", "mqtt", "--broker", &broker][..], args].concat();
            let (code, stderr) = run_with_env(irobot, &args, env);
            assert_eq!(
                code,
                Some(if fine { 1 } else { 2 }),
                "{name} {id:?}: {stderr}"
            );
            assert_eq!(
                stderr.contains(&format!(
                    "{name} must be 1 to 63 letters, digits, '-', '_' and '.', starting with a letter or a digit"
                )),
                !fine,
                "{name} {id:?}: {stderr}"
            );
        }
    }
    let (code, stderr) = run_with(irobot, &["--run", ""]);
    assert_eq!(code, Some(2), "{stderr}");
    // Built with the default of linux-sim (udp only), mqtt is not there.
    let udp_only = scratch("mqtt-options-udp");
    let built = build_sim(
        &examples().join("scouting/scouting.mission"),
        "linux-sim",
        &scenario(),
        &udp_only,
    );
    assert_eq!(built.code, 0, "{}{}", built.stdout, built.stderr);
    let folder = robot_folders(&udp_only)
        .into_iter()
        .find(|f| robot_name(f) == "irobot")
        .unwrap();
    support::robots::make(&folder, "gcc", PEDANTIC).unwrap_or_else(|e| panic!("{e}"));
    let (code, stderr) = run_with(&folder, &["--transport", "mqtt"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("built without the mqtt transport"),
        "{stderr}"
    );
}

/// Each user's password file `USER.pw` in `dir`, and the broker's password
/// file `passwd` for all of them, made with `mosquitto_passwd -b`.
fn password_files(dir: &Path, users: &[(&str, &str)]) {
    for (i, (user, password)) in users.iter().enumerate() {
        std::fs::write(dir.join(format!("{user}.pw")), format!("{password}\n")).unwrap();
        let mut command = Command::new("mosquitto_passwd");
        if i == 0 {
            command.arg("-c");
        }
        let made = command
            .arg("-b")
            .arg(dir.join("passwd"))
            .args([user, password])
            .output()
            .expect("mosquitto_passwd runs");
        assert!(made.status.success(), "{made:?}");
    }
}

/// A scouting deployment in `dir` for a broker on `port`: the master with
/// its own user, the slaves sharing their team's, the operator; the
/// broker's password file made with `mosquitto_passwd -b`. `tls`: also the
/// CA and certificates (`tls_files`).
fn scouting_deployment(dir: &Path, port: u16, tls: bool) -> PathBuf {
    let users = [
        ("irobot", "irobot-secret"),
        ("slaves", "slaves-secret"),
        ("operator", "operator-secret"),
    ];
    password_files(dir, &users);
    let file = dir.join("scouting.deploy.toml");
    std::fs::write(&file, scouting_deployment_text(port, tls)).unwrap();
    file
}

/// The text of [`scouting_deployment`]'s file. With TLS every client (the
/// master, the slaves' team, the operator) has a client certificate, so the
/// broker requires one.
fn scouting_deployment_text(port: u16, tls: bool) -> String {
    let client = |name: &str| {
        if tls {
            format!("cert = \"{name}.crt\"\nkey = \"{name}.key\"\n")
        } else {
            String::new()
        }
    };
    let (scheme, tls_top, tls_broker) = if tls {
        ("mqtts", "ca = \"ca.crt\"\n", client("server"))
    } else {
        ("mqtt", "", String::new())
    };
    format!(
        "# The scouting robots on a private broker (tests/mqtt.rs).\nbroker = \"{scheme}://127.0.0.1:{port}\"\n{tls_top}\n[broker_config]\npassword_file = \"passwd\"\n{tls_broker}\n[operator]\nuser = \"operator\"\npassword_file = \"operator.pw\"\n{}\n[teams.SlaveTeam]\nuser = \"slaves\"\npassword_file = \"slaves.pw\"\n{}\n[robots.irobot]\nuser = \"irobot\"\npassword_file = \"irobot.pw\"\n{}",
        client("operator"),
        client("slaves"),
        client("irobot")
    )
}

/// `semo deploy broker-config` into `dir/broker`, run as this user, logging
/// to `dir/broker/mosquitto.log`; returns the configuration's path.
fn broker_config(dir: &Path, deploy: &Path) -> PathBuf {
    broker_config_for(dir, &examples().join("scouting/scouting.mission"), deploy)
}

/// The same for another mission.
fn broker_config_for(dir: &Path, mission: &Path, deploy: &Path) -> PathBuf {
    let out = dir.join("broker");
    let written = support::semo_in(
        dir,
        &[
            "deploy",
            "broker-config",
            &mission.display().to_string(),
            "--deploy",
            &deploy.display().to_string(),
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(written.code, 0, "{}{}", written.stdout, written.stderr);
    let config = out.join("mosquitto.conf");
    let text = std::fs::read_to_string(&config).unwrap();
    // The tests' broker runs as the user running them, whoever that is,
    // and logs into their folder.
    let mut text: String = text
        .lines()
        .filter(|line| !line.starts_with("user "))
        .map(|line| format!("{line}\n"))
        .collect();
    text.push_str(&format!(
        "user {}\nlog_dest file {}\n",
        support::mosquitto::current_user(),
        out.join("mosquitto.log").display()
    ));
    std::fs::write(&config, text).unwrap();
    config
}

/// The scouting mission's topics in run `run`.
fn scouting_run(run: &str) -> topics::Scope {
    topics::Scope::run("scouting", &topics::RunId::parse(run).unwrap())
}

/// The topics the ACL file `acl` lets `user` write in run `run` (the ACL
/// names them in every run: `+` at the run's level).
fn writable(acl: &str, user: &str, run: &str) -> Vec<String> {
    let mut current = None;
    let mut topics = Vec::new();
    for line in acl.lines() {
        if let Some(name) = line.strip_prefix("user ") {
            current = Some(name);
        } else if let Some(topic) = line.strip_prefix("topic write ") {
            if current == Some(user) {
                let mut levels: Vec<&str> = topic.split('/').collect();
                assert_eq!(levels[2], "+", "{topic}: every run");
                levels[2] = run;
                topics.push(levels.join("/"));
            }
        }
    }
    topics
}

/// An attacker holding `user`'s credentials (rumqttc): publishes `datagram`
/// at QoS 1 on each of `topics` in turn, a round every 20 ms, until `stop`
/// is set. Returns how many publishes it made (mosquitto acknowledges one
/// its ACL denies too: MQTT 3.1.1 has no way to say no).
fn forge(
    port: u16,
    (user, password): (&'static str, &'static str),
    topics: Vec<String>,
    datagram: Vec<u8>,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> std::thread::JoinHandle<usize> {
    let mut options = rumqttc::MqttOptions::new(format!("forger-{user}"), "127.0.0.1", port);
    options.set_credentials(user, password);
    forge_with(options, topics, datagram, stop)
}

/// [`forge`] as the client `options` describe (TLS with a client
/// certificate).
fn forge_with(
    options: rumqttc::MqttOptions,
    topics: Vec<String>,
    datagram: Vec<u8>,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> std::thread::JoinHandle<usize> {
    std::thread::spawn(move || {
        let (client, mut connection) = rumqttc::Client::new(options, 256);
        let network = std::thread::spawn(move || {
            for event in connection.iter() {
                if matches!(
                    event,
                    Ok(rumqttc::Event::Outgoing(rumqttc::Outgoing::Disconnect)) | Err(_)
                ) {
                    break;
                }
            }
        });
        let mut made = 0;
        while !stop.load(std::sync::atomic::Ordering::SeqCst) {
            for topic in &topics {
                let sent =
                    client.publish(topic, rumqttc::QoS::AtLeastOnce, false, datagram.clone());
                made += usize::from(sent.is_ok());
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let _ = client.disconnect();
        network.join().unwrap();
        made
    })
}

/// A datagram as `team`/`robot` with `key` and a text value.
fn datagram_from(team: &str, robot: &str, key: &str, value: &str, publish: bool) -> Vec<u8> {
    semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
        publish,
        team: team.into(),
        robot: robot.into(),
        key: key.into(),
        value: Some(semo::refine::Value::text(value)),
    })
}

/// An attack: whose credentials, on which topics, which datagram.
struct Forgery {
    user: (&'static str, &'static str),
    topics: Vec<String>,
    datagram: Vec<u8>,
}

/// The run of the robots [`run_while_forging`] runs: the ACL lets their
/// users work in any run.
const FORGED_RUN: &str = "acl-7";

/// Runs the scouting robots (built with the deployment: no --broker, the
/// baked defaults connect them) in run [`FORGED_RUN`] while each of
/// `forgeries` goes on; returns the traces and how many publishes each
/// forgery made.
fn run_while_forging(
    folders: &[PathBuf],
    out: &Path,
    tag: &str,
    port: u16,
    forgeries: Vec<Forgery>,
    processes: &mut Processes,
) -> (BTreeMap<String, Vec<Event>>, Vec<usize>) {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let threads: Vec<_> = forgeries
        .into_iter()
        .map(|f| forge(port, f.user, f.topics, f.datagram, stop.clone()))
        .collect();
    let traces = run_together(
        folders,
        out,
        tag,
        &[
            "--transport".into(),
            "mqtt".into(),
            "--run".into(),
            FORGED_RUN.into(),
        ],
        processes,
    );
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    let made = threads.into_iter().map(|t| t.join().unwrap()).collect();
    (traces, made)
}

/// How many messages a robot refused because their datagram named another
/// sender or key than their topic.
fn refused(events: &[Event]) -> usize {
    events
        .iter()
        .filter(|e| field(e, "event") == "reject" && field(e, "reason") == "sender not its topic")
        .count()
}

/// A fleet whose broker runs the configuration `semo deploy broker-config`
/// writes for the scouting deployment (`scouting_deployment`, with TLS
/// files when `tls`), and the deployment file.
fn deployed_fleet(name: &str, tls: bool) -> Option<(Fleet, PathBuf)> {
    let mut deploy = None;
    let fleet = Fleet::start_configured(name, |broker_dir, port| {
        let out = broker_dir
            .parent()
            .expect("the broker folder is in the test's");
        if tls {
            tls_files(out);
        }
        let file = scouting_deployment(out, port, tls);
        let config = broker_config(out, &file);
        deploy = Some(file);
        config
    })?;
    Some((fleet, deploy.expect("configured")))
}

/// A fleet whose broker runs the configuration `semo deploy broker-config`
/// writes for `mission` under the deployment `deployment` makes (from the
/// test's folder and the broker's port), and that deployment file.
fn fleet_deployed_for(
    name: &str,
    mission: &Path,
    deployment: fn(&Path, u16) -> PathBuf,
) -> Option<(Fleet, PathBuf)> {
    let mut deploy = None;
    let fleet = Fleet::start_configured(name, |broker_dir, port| {
        let out = broker_dir
            .parent()
            .expect("the broker folder is in the test's");
        let file = deployment(out, port);
        let config = broker_config_for(out, mission, &file);
        deploy = Some(file);
        config
    })?;
    Some((fleet, deploy.expect("configured")))
}

#[test]
fn robots_take_messages_only_from_the_sender_their_topic_names_and_the_acl_lets() {
    let Some((mut fleet, deploy)) = deployed_fleet("mqtt-acl", false) else {
        return;
    };
    let (out, port) = (fleet.out.clone(), fleet.port);
    let config = out.join("broker/mosquitto.conf");
    let acl = std::fs::read_to_string(out.join("broker/semo.acl")).unwrap();
    insta::assert_snapshot!(
        "scouting_acl",
        acl.replace(&deploy.display().to_string(), "scouting.deploy.toml")
    );
    let conf = std::fs::read_to_string(&config).unwrap();
    for line in [
        "allow_anonymous false",
        "set_tcp_nodelay true",
        "acl_file ",
        "password_file ",
    ] {
        assert!(conf.contains(line), "{line}: {conf}");
    }
    let folders = build_scouting_with(&out, &["--deploy", &deploy.display().to_string()]);
    let header = std::fs::read_to_string(folders[0].join("semo_deploy.h")).unwrap();
    assert!(
        header.contains("SEMO_DEPLOY_PASSWORD_FILE") && !header.contains("secret\""),
        "the password file's path, not the password: {header}"
    );

    // The slaves' credentials cannot command the master: the operator's
    // datagram ("from USER, RC_CMD = RC_MODE") on every topic their ACL lets
    // them write, and on the operator's own command topic. Nor can the
    // master's credentials keep slave ti alive: ti's heartbeat (battery
    // 777, which ti never says) on every topic the master may write.
    let operator_topic = topics::to_team(
        &scouting_run(FORGED_RUN),
        "MasterTeam",
        "USER.RC_CMD",
        topics::OPERATOR,
    );
    let mut slave_topics = writable(&acl, "slaves", FORGED_RUN);
    slave_topics.push(operator_topic.clone());
    let forgeries = vec![
        Forgery {
            user: ("slaves", "slaves-secret"),
            topics: slave_topics,
            datagram: semo_server::live::operator_datagram("USER.RC_CMD", "RC_MODE"),
        },
        Forgery {
            user: ("irobot", "irobot-secret"),
            topics: writable(&acl, "irobot", FORGED_RUN),
            datagram: datagram_from("SlaveTeam", "ti", "SlaveTeam.__alive", "leader 777 9", true),
        },
    ];
    let (forged, made) = run_while_forging(
        &folders,
        &out,
        "forged",
        port,
        forgeries,
        &mut fleet.processes,
    );
    for (robot, events) in &forged {
        assert_eq!(
            modes(events).last().map(String::as_str),
            Some("FINISH"),
            "{robot}: {:?}",
            modes(events)
        );
    }
    let commands_taken = received_from(&forged["irobot"], "operator", "USER.RC_CMD").len();
    let heartbeats_taken = received_from(&forged["nxt"], "ti", "SlaveTeam.__alive")
        .iter()
        .filter(|v| v.contains("777"))
        .count();
    eprintln!(
        "forged: {} RC_CMD publishes with the slaves' credentials, {} taken, {} refused by irobot; {} heartbeat publishes with irobot's, {} taken, {} refused by nxt",
        made[0],
        commands_taken,
        refused(&forged["irobot"]),
        made[1],
        heartbeats_taken,
        refused(&forged["nxt"])
    );
    assert!(
        made.iter().all(|&n| n > 0),
        "the forgers published: {made:?}"
    );
    assert!(
        !modes(&forged["irobot"]).iter().any(|m| m == "RC_MODE") && commands_taken == 0,
        "a forged USER command reached the master: {:?}",
        modes(&forged["irobot"])
    );
    assert_eq!(heartbeats_taken, 0, "a forged heartbeat of ti reached nxt");
    // The broker delivered forgeries on topics the forgers may write, and
    // the robots refused them: the ACL alone would not have stopped them.
    assert!(refused(&forged["irobot"]) > 0, "irobot refused none");
    assert!(refused(&forged["nxt"]) > 0, "nxt refused none");
    for slave in ["ti", "nxt"] {
        assert!(
            received_from(&forged["irobot"], slave, "SlaveTeam.COLOR")
                .iter()
                .any(|v| v == "RGB"),
            "the master hears {slave} through the ACL"
        );
    }
    // The same command from the operator's user on its topic does switch
    // it: the forgeries above failed because of who sent them, not for
    // another reason.
    let (commanded, _) = run_while_forging(
        &folders,
        &out,
        "operator",
        port,
        vec![Forgery {
            user: ("operator", "operator-secret"),
            topics: vec![operator_topic],
            datagram: semo_server::live::operator_datagram("USER.RC_CMD", "RC_MODE"),
        }],
        &mut fleet.processes,
    );
    assert!(
        modes(&commanded["irobot"]).iter().any(|m| m == "RC_MODE"),
        "the operator's USER command switches the master: {:?}",
        modes(&commanded["irobot"])
    );
    assert!(
        received_from(&commanded["irobot"], "operator", "USER.RC_CMD")
            .iter()
            .any(|v| v == "RC_MODE"),
        "the master took the operator's command"
    );
}

/// `mosquitto_sub` as the operator with the persistent session `semo-root-
/// test` on the operator consoles' topics, with `args`; its output.
fn operator_session(port: u16, args: &[&str]) -> std::process::Output {
    Command::new("mosquitto_sub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string(), "-q", "1", "-c"])
        .args([
            "-i",
            "semo-root-test",
            "-u",
            "operator",
            "-P",
            "operator-secret",
        ])
        .args(["-t", &topics::team_inbox(&scouting_run("default"), "USER")])
        .args(args)
        .output()
        .expect("mosquitto_sub runs (Debian mosquitto-clients)")
}

/// Started as root, the broker of the generated configuration runs as its
/// `user` (`mosquitto`). With the password file and the persistence folder
/// given to that user as `semo deploy broker-config` says (and
/// `docs/deployment.md`), it starts, and a QoS 1 message for a session that
/// is away survives a restart of the broker. Needs root and the `mosquitto`
/// account (CI); skipped otherwise.
#[test]
fn the_generated_broker_started_as_root_keeps_qos1_messages_across_a_restart() {
    let Some(binary) = support::mqtt::broker_or_skip("root broker") else {
        return;
    };
    let account = Command::new("id")
        .arg("mosquitto")
        .output()
        .expect("id runs");
    if support::mosquitto::current_user() != "root" || !account.status.success() {
        eprintln!("skipping: needs root and the `mosquitto` account");
        return;
    }
    // Its own folder under the system's temporary folder: every folder on
    // the way must be searchable by the broker's account (a build folder
    // may not be).
    let dir = tempfile::Builder::new()
        .prefix("semo-root-broker")
        .tempdir()
        .unwrap();
    let reachable = Command::new("chmod")
        .arg("0755")
        .arg(dir.path())
        .status()
        .unwrap();
    assert!(reachable.success());
    let dir = dir.path();
    let port = free_port();
    let deploy = scouting_deployment(dir, port, false);
    let passwd = dir.join("passwd");
    let chmod = Command::new("chmod")
        .arg("0600")
        .arg(&passwd)
        .status()
        .unwrap();
    assert!(chmod.success());
    let out = dir.join("broker");
    let written = support::semo_in(
        dir,
        &[
            "deploy",
            "broker-config",
            &examples()
                .join("scouting/scouting.mission")
                .display()
                .to_string(),
            "--deploy",
            &deploy.display().to_string(),
            "-o",
            &out.display().to_string(),
        ],
    );
    assert_eq!(written.code, 0, "{}", written.stderr);
    let persistence = out.join("persistence");
    let told = format!(
        "`chown mosquitto {} {}`",
        persistence.display(),
        passwd.display()
    );
    assert!(written.stdout.contains(&told), "{}", written.stdout);
    let config = std::fs::read_to_string(out.join("mosquitto.conf")).unwrap();
    assert!(config.contains("\nuser mosquitto\n"), "{config}");
    // What it says to do.
    let chown = Command::new("chown")
        .arg("mosquitto")
        .args([&persistence, &passwd])
        .status()
        .unwrap();
    assert!(chown.success());

    let mut processes = Processes::default();
    let start = |processes: &mut Processes, run: &str| {
        let log = std::fs::File::create(dir.join(format!("mosquitto.{run}.log"))).unwrap();
        let child = Command::new(&binary)
            .arg("-c")
            .arg(out.join("mosquitto.conf"))
            .stderr(log)
            .spawn()
            .expect("mosquitto starts");
        let index = processes.push(child);
        let log = || std::fs::read_to_string(dir.join(format!("mosquitto.{run}.log"))).unwrap();
        assert!(support::mosquitto::listening(port), "{}", log());
        index
    };
    let broker = start(&mut processes, "first");
    let subscribed = operator_session(port, &["-E"]);
    assert!(subscribed.status.success(), "{subscribed:?}");
    let irobot = topics::Sender {
        team: "MasterTeam",
        robot: "irobot",
    };
    let published = Command::new("mosquitto_pub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string(), "-q", "1"])
        .args(["-u", "irobot", "-P", "irobot-secret", "-m", "kept"])
        .args([
            "-t",
            &topics::to_team(
                &scouting_run("default"),
                "USER",
                "MasterTeam.CAMERA",
                irobot,
            ),
        ])
        .output()
        .expect("mosquitto_pub runs");
    assert!(published.status.success(), "{published:?}");
    processes.terminate(broker);
    assert!(
        persistence.join("mosquitto.db").is_file(),
        "the broker kept its state in {}",
        persistence.display()
    );
    start(&mut processes, "second");
    let kept = operator_session(port, &["-C", "1", "-W", "5"]);
    assert_eq!(
        String::from_utf8_lossy(&kept.stdout).trim(),
        "kept",
        "{kept:?}"
    );
}

/// `openssl ARGS` in `dir`; a failure fails the test.
fn openssl(dir: &Path, args: &[&str]) {
    let out = Command::new("openssl")
        .args(args)
        .current_dir(dir)
        .output()
        .expect("openssl runs");
    assert!(
        out.status.success(),
        "openssl {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A throwaway CA in `dir` (`ca.crt`, `ca.key`), made with `openssl`.
fn certificate_authority(dir: &Path) {
    openssl(
        dir,
        &[
            "req",
            "-x509",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-days",
            "2",
            "-subj",
            "/CN=semo test CA",
            "-keyout",
            "ca.key",
            "-out",
            "ca.crt",
        ],
    );
}

/// A throwaway CA in `dir` (`ca.crt`), the broker's certificate for
/// 127.0.0.1 (`server.crt`/`server.key`) and client certificates for the
/// master, the slaves' team and the operator (`irobot`, `slaves`,
/// `operator` `.crt`/`.key`), made with `openssl`.
fn tls_files(dir: &Path) {
    let openssl = |args: &[&str]| openssl(dir, args);
    certificate_authority(dir);
    // X.509 v3 certificates (an extension makes `openssl x509` write v3; a
    // v1 certificate is refused by rustls, as by most modern TLS stacks).
    std::fs::write(dir.join("server.ext"), "subjectAltName = IP:127.0.0.1\n").unwrap();
    std::fs::write(dir.join("client.ext"), "extendedKeyUsage = clientAuth\n").unwrap();
    for (name, extensions) in [
        ("server", Some("server.ext")),
        ("irobot", Some("client.ext")),
        ("slaves", Some("client.ext")),
        ("operator", Some("client.ext")),
    ] {
        let (key, csr, crt) = (
            format!("{name}.key"),
            format!("{name}.csr"),
            format!("{name}.crt"),
        );
        openssl(&[
            "req",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-subj",
            &format!("/CN={name}"),
            "-keyout",
            &key,
            "-out",
            &csr,
        ]);
        let mut sign = vec![
            "x509",
            "-req",
            "-in",
            &csr,
            "-CA",
            "ca.crt",
            "-CAkey",
            "ca.key",
            "-CAcreateserial",
            "-days",
            "2",
            "-out",
            &crt,
        ];
        if let Some(file) = extensions {
            sign.extend(["-extfile", file]);
        }
        openssl(&sign);
    }
}

#[test]
fn robots_run_over_tls_with_client_certificates() {
    let Some((mut fleet, deploy)) = deployed_fleet("mqtt-tls", true) else {
        return;
    };
    let (out, port) = (fleet.out.clone(), fleet.port);
    let config = out.join("broker/mosquitto.conf");
    let conf = std::fs::read_to_string(&config).unwrap();
    assert!(
        conf.contains("certfile ")
            && conf.contains("cafile ")
            && conf.contains("require_certificate true"),
        "every client has a certificate, so the broker requires one: {conf}"
    );
    let folders = build_scouting_with(&out, &["--deploy", &deploy.display().to_string()]);
    let traces = run_together(
        &folders,
        &out,
        "tls",
        &["--transport".into(), "mqtt".into()],
        &mut fleet.processes,
    );
    assert_eq!(traces.len(), 3);
    for (robot, events) in &traces {
        assert_eq!(
            modes(events).last().map(String::as_str),
            Some("FINISH"),
            "{robot} over TLS: {:?}",
            modes(events)
        );
    }
    for slave in ["ti", "nxt"] {
        assert!(
            received_from(&traces["irobot"], slave, "SlaveTeam.COLOR")
                .iter()
                .any(|v| v == "RGB"),
            "the master hears {slave} over TLS"
        );
    }
    // The broker speaks only TLS: a plain connection with the slaves'
    // credentials is refused, so the robots above did use TLS. (A robot
    // program cannot try: its baked client certificate needs mqtts://.)
    let nxt = folders.iter().find(|f| robot_name(f) == "nxt").unwrap();
    let (code, stderr) = run_with(
        nxt,
        &[
            "--transport",
            "mqtt",
            "--broker",
            &format!("mqtt://127.0.0.1:{port}"),
            "--duration",
            "100",
        ],
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("a client certificate needs an mqtts:// broker"),
        "{stderr}"
    );
    let plain = Command::new("mosquitto_pub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string()])
        .args(["-u", "slaves", "-P", "slaves-secret"])
        .args(["-t", "semo/scouting/default/SlaveTeam/x", "-m", "x"])
        .output()
        .expect("mosquitto_pub runs (Debian mosquitto-clients)");
    assert!(!plain.status.success(), "{plain:?}");
}

/// The retained status of `robot` on the broker at `port` (anonymous), as
/// a JSON object; None when there is none within a few seconds.
fn retained_status(port: u16, robot: &str) -> Option<serde_json::Value> {
    let out = Command::new("mosquitto_sub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string()])
        .args(["-t", &format!("semo/scouting/default/status/{robot}")])
        .args(["-C", "1", "-W", "3", "--retained-only"])
        .output()
        .expect("mosquitto_sub runs (Debian mosquitto-clients)");
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().next()?;
    Some(serde_json::from_str(line).unwrap_or_else(|e| panic!("{line}: {e}")))
}

/// The topics under `filter` that the broker at `port` keeps a retained
/// message on (anonymous).
fn retained_topics(port: u16, filter: &str) -> Vec<String> {
    let out = Command::new("mosquitto_sub")
        .args(["-h", "127.0.0.1", "-p", &port.to_string()])
        .args(["-t", filter, "-v", "-W", "2", "--retained-only"])
        .output()
        .expect("mosquitto_sub runs (Debian mosquitto-clients)");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|line| line.split_once(' ').map(|(topic, _)| topic.to_string()))
        .collect()
}

#[test]
fn each_robot_keeps_a_retained_status_and_a_killed_one_is_lost() {
    let Some(mut fleet) = Fleet::start("mqtt-status") else {
        return;
    };
    let port = fleet.port;
    let folders = build_scouting(&fleet.out);
    let traces = fleet.run_all(&folders, &scenario(), "status", &[]);
    // After the run: each robot stopped, in its last mode, as its trace says.
    for (robot, events) in &traces {
        let status = retained_status(port, robot).unwrap_or_else(|| panic!("{robot}: no status"));
        assert_eq!(status["robot"], robot.as_str(), "{status}");
        assert_eq!(status["state"], "stopped", "{robot}: {status}");
        assert_eq!(
            status["mode"].as_str(),
            modes(events).last().map(String::as_str),
            "{robot}: {status}"
        );
        // The scenario gives no battery and no robot reads one: absent.
        assert_eq!(status.get("battery"), None, "{robot}: {status}");
        // When its mission time 0 was (Unix ms): which run is the newest.
        assert!(
            status["started"]
                .as_str()
                .is_some_and(|t| t.parse::<u64>().is_ok()),
            "{robot}: {status}"
        );
    }
    // A robot killed while running: the broker publishes its last will.
    // Its scenario gives it a battery level of 80: its status says so.
    let mut with_battery: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scenario()).unwrap()).unwrap();
    with_battery["robots"]["irobot"]["battery"] = serde_json::json!([{"at": 0, "level": 80}]);
    let battery_scenario = fleet.out.join("battery.scenario.json");
    std::fs::write(&battery_scenario, with_battery.to_string()).unwrap();
    let irobot = folder_of(&folders, "irobot");
    let killed = fleet.spawn(
        &irobot,
        &battery_scenario,
        "killed",
        &["--duration", "1000000"],
    );
    let mut running = None;
    for _ in 0..50 {
        // Running, and past its first firing: a service in each plan.
        running = retained_status(port, "irobot").filter(|s| {
            s["state"] == "running"
                && s["services"]
                    .as_str()
                    .is_some_and(|s| s.contains("Action="))
        });
        if running.is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let running = running.expect("the running robot's status names the service each plan runs");
    assert_eq!(running["battery"], "80", "{running}");
    assert!(
        running["mode"]
            .as_str()
            .is_some_and(|m| m.ends_with("_MODE")),
        "{running}"
    );
    fleet.processes.kill(killed.index);
    let mut lost = None;
    for _ in 0..50 {
        lost = retained_status(port, "irobot").filter(|s| s["state"] == "lost");
        if lost.is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let lost = lost.expect("the killed robot's status says lost");
    assert_eq!(lost["started"], running["started"], "{lost}");
}

/// `tests/fixtures/counted_groups/alarm.mission` over MQTT: five robots in
/// two rooms, until an operator's `fire` to tb_3 makes it throw `fire` to
/// its room, which goes to FIGHT (no counted groups there). Each robot's
/// last status says its groups as its trace's last `allocated` does while
/// it searches, and none once in FIGHT: a new mode starts with none. Built
/// with the address and undefined-behaviour sanitizers: the status's list
/// of groups is kept without a report.
#[test]
fn a_robots_status_has_its_counted_group_until_its_mode_changes() {
    let Some(mut fleet) = Fleet::start("mqtt-status-groups") else {
        return;
    };
    let port = fleet.port;
    let fixture = repo_root().join("tests/fixtures/counted_groups/alarm.mission");
    let folders = support::mqtt::build_with(
        &fixture,
        &fleet.out,
        &[],
        "gcc",
        &format!("{SANITIZED} -fsanitize=address,undefined -fno-sanitize-recover=all"),
    );
    let scenario = fleet.out.join("alarm.scenario.json");
    std::fs::write(
        &scenario,
        r#"{"duration": 3000, "operator": [{"at": 1500, "to": "tb_3", "value": "RC_CMD", "is": "fire"}]}"#,
    )
    .unwrap();
    let env = [
        ("ASAN_OPTIONS", "detect_leaks=1:abort_on_error=1"),
        ("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1"),
    ];
    let started: Vec<Started> = folders
        .iter()
        .map(|folder| fleet.spawn_with(folder, &scenario, "alarm", &[], &env))
        .collect();
    let mut traces = BTreeMap::new();
    for run in &started {
        let stderr = fleet
            .processes
            .wait_success(run.index, &format!("{} (alarm)", run.robot));
        assert!(stderr.trim().is_empty(), "{}: {stderr}", run.robot);
        traces.insert(run.robot.clone(), read_trace(&run.trace));
    }
    let mut fighting = 0;
    for (robot, events) in &traces {
        let out = Command::new("mosquitto_sub")
            .args(["-h", "127.0.0.1", "-p", &port.to_string()])
            .args(["-t", &format!("semo/alarm/default/status/{robot}")])
            .args(["-C", "1", "-W", "3", "--retained-only"])
            .output()
            .expect("mosquitto_sub runs (Debian mosquitto-clients)");
        let payload = String::from_utf8_lossy(&out.stdout);
        let status = semo_server::live::Status::decode(robot, payload.trim().as_bytes())
            .unwrap_or_else(|| panic!("{robot}: no status: {payload}"));
        assert_eq!(status.state, "stopped", "{payload}");
        let last = events
            .iter()
            .rfind(|e| field(e, "event") == "allocated")
            .map(|e| {
                (
                    field(e, "name").to_string(),
                    field(e, "alive").parse().unwrap(),
                )
            });
        match modes(events).last().map(String::as_str) {
            Some("FIGHT") => {
                fighting += 1;
                assert_eq!(status.groups, [], "{robot}: {payload}");
                assert!(!payload.contains("\"groups\""), "{payload}");
            }
            Some("SEARCH") => {
                let last = last.unwrap_or_else(|| panic!("{robot} was allocated"));
                assert!(last.0.starts_with("Room"), "{robot}: {last:?}");
                assert_eq!(status.groups, [last], "{robot}: {payload}");
            }
            other => panic!("{robot} ends in {other:?}"),
        }
    }
    assert!(
        (2..5).contains(&fighting),
        "tb_3's room fights, the other room searches on: {fighting} fighting"
    );
}

/// The burst mission (`tests/fixtures/messages`: twenty sends at once, pass
/// after pass, a listener that takes every one) over MQTT, with the
/// talker's sending made to last `sending_ms` and the listener to run
/// `listening_ms`, both at real time.
fn burst_over_mqtt(fleet: &Fleet, sending_ms: i64, listening_ms: i64) -> (Vec<PathBuf>, PathBuf) {
    let fixture = repo_root().join("tests/fixtures/messages");
    let folders = support::mqtt::build(&fixture.join("burst.mission"), &fleet.out, &[]);
    let mut scenario: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(fixture.join("burst.scenario.json")).unwrap(),
    )
    .unwrap();
    scenario["duration"] = listening_ms.into();
    scenario["robots"]["talker"]["sensors"][2]["at"] = sending_ms.into();
    let path = fleet.out.join("burst.scenario.json");
    std::fs::write(&path, scenario.to_string()).unwrap();
    (folders, path)
}

/// Waits until the trace of `run` holds `count` lines with `needle` (the
/// robot ending first fails the test).
fn wait_for_lines(fleet: &mut Fleet, run: &Started, needle: &str, count: usize) {
    while std::fs::read_to_string(&run.trace).map_or(0, |t| t.matches(needle).count()) < count {
        let child = &mut fleet.processes.0[run.index];
        assert!(
            child.try_wait().unwrap().is_none(),
            "{} ended before {count} lines with {needle}",
            run.robot
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

#[test]
fn robots_reconnect_after_a_broker_restart_and_no_send_is_lost() {
    let Some(mut fleet) = Fleet::start("mqtt-broker-restart") else {
        return;
    };
    // The talker sends for 3 s; the listener listens 10 s, time for both to
    // reconnect (libmosquitto waits 1 s first) and take the backlog.
    let (folders, scenario) = burst_over_mqtt(&fleet, 3000, 10000);
    support::mqtt::compile_in(&folders, &scenario);
    let (_, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let started: Vec<Started> = folders
        .iter()
        .map(|f| fleet.spawn(f, &scenario, "restart", &["--start-at", &start_at]))
        .collect();
    let listener = started.iter().find(|s| s.robot == "listener").unwrap();
    // Once the listener has taken the first two passes, while the talker
    // sends, the broker goes down (saving its state, as a service stop
    // does) and comes back.
    wait_for_lines(&mut fleet, listener, "\"event\":\"receive\"", 40);
    fleet.stop_broker();
    fleet.start_broker();
    let mut traces = BTreeMap::new();
    for run in &started {
        traces.insert(run.robot.clone(), fleet.finish(run, "broker restart"));
    }
    let (talker, listener) = (&traces["talker"], &traces["listener"]);
    let sent = sent_to(talker, "Listeners");
    let passes = support::robots::calls(talker).len();
    assert_eq!(
        sent.len(),
        20 * passes,
        "every pass's twenty sends leave the talker, the outage or not"
    );
    assert!(
        !talker.iter().any(|e| field(e, "event") == "comm_error"),
        "the talker's sends during the outage wait for the broker"
    );
    // QoS 1 is at least once: a message the broker had not seen
    // acknowledged comes again after the restart, never one less; each
    // reaches the listener's mission: none is dropped on the way in, the
    // burst of the backlog included.
    let received = received_all_from(listener, "talker");
    let missing = missing_from(&sent, &received);
    assert!(
        missing.is_none(),
        "every send reaches the listener across the broker's restart, in order: {} sent, {} received, the first missing {missing:?}",
        sent.len(),
        received.len()
    );
    let lost: Vec<&Event> = listener
        .iter()
        .filter(|e| matches!(field(e, "event"), "drop" | "dropped"))
        .collect();
    assert!(lost.is_empty(), "the listener drops nothing: {lost:?}");
    let log = std::fs::read_to_string(fleet.broker_dir().join("mosquitto.log")).unwrap_or_default();
    assert!(
        log.matches("New client connected").count() >= 4,
        "each robot connected twice: {log}"
    );
}

/// The slaves' sends to the master so far, counted in a live trace file
/// (the robot flushes each line; a line still being written is not counted).
fn sends_to_master_so_far(trace: &Path) -> usize {
    let text = std::fs::read_to_string(trace).unwrap_or_default();
    let whole = &text[..text.rfind('\n').map_or(0, |end| end + 1)];
    events(&whole.lines().map(str::to_string).collect::<Vec<_>>())
        .iter()
        .filter(|e| field(e, "event") == "send" && field(e, "to") == "MasterTeam")
        .count()
}

/// Waits until `trace`'s robot has sent the master more than `than`
/// messages; fails if the robot ends first.
fn wait_for_sends(
    fleet: &mut Fleet,
    index: usize,
    robot: &str,
    trace: &Path,
    than: usize,
) -> usize {
    loop {
        let sent = sends_to_master_so_far(trace);
        if sent > than {
            return sent;
        }
        assert!(
            fleet.processes.is_running(index),
            "{robot} ended having sent the master {sent} message(s), waiting for more than {than}"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// The master is killed while the slaves send it their colors, and restarted
/// after each slave has sent it something more: what they sent meanwhile
/// reaches its second life (its persistent session kept it). "Meanwhile" is
/// read from the order of each slave's own trace (the sends after the ones
/// counted at the kill, up to the ones counted at the restart), not from
/// clocks, so a loaded machine cannot move a send out of the window.
#[test]
fn a_killed_robot_restarts_and_gets_what_was_sent_while_it_was_dead() {
    let Some(mut fleet) = Fleet::start("mqtt-robot-restart") else {
        return;
    };
    let folders = build_scouting(&fleet.out);
    // The fixture's scenario with the slaves searching longer (their last
    // color at 5.5 s instead of 3.5 s), so that they are still sending when
    // the master comes back; the master's own mission is unchanged.
    let mut world: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scenario()).unwrap()).unwrap();
    for (slave, rgb) in [("ti", 5500), ("nxt", 5700)] {
        for sensor in world["robots"][slave]["sensors"].as_array_mut().unwrap() {
            let at = sensor["at"].as_i64().unwrap();
            match (
                sensor["value"].as_str().unwrap(),
                sensor["is"].as_str().unwrap(),
            ) {
                ("COLOR", "RGB") => sensor["at"] = serde_json::json!(rgb),
                ("LOCATION", "0,0") if at > 0 => sensor["at"] = serde_json::json!(rgb + 1000),
                _ => {}
            }
        }
    }
    let world_file = fleet.out.join("longer-search.scenario.json");
    std::fs::write(&world_file, world.to_string()).unwrap();
    const SCALE: f64 = 0.4; // wall ms per mission ms
    let scale = SCALE.to_string();
    let spawn = |fleet: &mut Fleet, folder: &Path, tag: &str| {
        let run = fleet.spawn(folder, &world_file, tag, &["--time-scale", &scale]);
        (run.trace, run.index)
    };
    let mut slaves = Vec::new();
    let mut master = None;
    for folder in &folders {
        let (trace, index) = spawn(&mut fleet, folder, "life");
        if robot_name(folder) == "irobot" {
            master = Some((folder.clone(), index));
        } else {
            slaves.push((robot_name(folder), trace, index));
        }
    }
    let (irobot, first) = master.unwrap();
    // Killed once every slave is sending; back once every slave has sent
    // it something more.
    for (robot, trace, index) in &slaves {
        wait_for_sends(&mut fleet, *index, robot, trace, 0);
    }
    fleet.processes.kill(first);
    let at_kill: Vec<usize> = (slaves.iter())
        .map(|(_, trace, _)| sends_to_master_so_far(trace))
        .collect();
    for ((robot, trace, index), &before) in slaves.iter().zip(&at_kill) {
        wait_for_sends(&mut fleet, *index, robot, trace, before);
    }
    let at_restart: Vec<usize> = (slaves.iter())
        .map(|(_, trace, _)| sends_to_master_so_far(trace))
        .collect();
    let (second_trace, second) = spawn(&mut fleet, &irobot, "second-life");
    let mut slave_traces = BTreeMap::new();
    for ((robot, trace, index), window) in
        slaves.into_iter().zip(at_kill.into_iter().zip(at_restart))
    {
        fleet.processes.wait_success(index, &robot);
        slave_traces.insert(robot, (read_trace(&trace), window));
    }
    fleet.processes.wait_success(second, "irobot (second life)");
    let second_life = read_trace(&second_trace);
    assert_eq!(
        modes(&second_life).last().map(String::as_str),
        Some("FINISH"),
        "the restarted master runs its mission: {:?}",
        modes(&second_life)
    );
    // What each slave sent while the master was dead reaches the master's
    // second life: its persistent session kept it.
    for (slave, (events, (at_kill, at_restart))) in &slave_traces {
        let meanwhile: Vec<(String, String)> = events
            .iter()
            .filter(|e| field(e, "event") == "send" && field(e, "to") == "MasterTeam")
            .skip(*at_kill)
            .take(at_restart - at_kill)
            .map(|e| (field(e, "key").to_string(), field(e, "value").to_string()))
            .collect();
        assert!(
            !meanwhile.is_empty(),
            "{slave} sent while the master was dead"
        );
        let mut received = received_all_from(&second_life, slave);
        for message in &meanwhile {
            let at = received.iter().position(|r| r == message);
            assert!(
                at.is_some(),
                "{slave}'s {message:?}, sent while the master was dead, reaches its second life"
            );
            received.remove(at.unwrap());
        }
        assert!(
            !events.iter().any(|e| field(e, "event") == "comm_error"),
            "{slave} never fails to send"
        );
    }
}

/// The two-runs mission (`tests/fixtures/messages`) built into the
/// fleet's folder.
fn build_two_runs(fleet: &Fleet) -> Vec<PathBuf> {
    let mission = repo_root().join("tests/fixtures/messages/two_runs.mission");
    support::mqtt::build(&mission, &fleet.out, &[])
}

/// Its run `n`'s scenario: the boss's COLOR is `run N` until 800 ms, then
/// `done` (the worker finishes on it); its DISTANCE is N.
fn two_runs_scenario(fleet: &Fleet, n: i64) -> PathBuf {
    let fixture = repo_root().join("tests/fixtures/messages/two_runs.scenario.json");
    let mut scenario: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture).unwrap()).unwrap();
    let sensors = &mut scenario["robots"]["boss"]["sensors"];
    sensors[0]["is"] = format!("run {n}").into();
    sensors[1]["is"] = n.to_string().into();
    let path = fleet.out.join(format!("two_runs.{n}.scenario.json"));
    std::fs::write(&path, scenario.to_string()).unwrap();
    path
}

/// The values (set) of `key` a robot received, in order.
fn values_received(events: &[Event], key: &str) -> Vec<serde_json::Value> {
    events
        .iter()
        .filter(|e| field(e, "event") == "receive" && field(e, "key") == key)
        .map(|e| e["value"].clone())
        .filter(|v| !v.is_null())
        .collect()
}

/// One mission run twice on one broker, each run with its own id (`--run`,
/// then `$SEMO_RUN`): the second hears nothing of the first. Without run
/// ids, the worker of the second run got at once the boss's sends made
/// after the first run's worker had finished (its persistent session kept
/// them), and the `done` the first run left retained when publishes were.
#[test]
fn a_second_run_on_the_same_broker_hears_nothing_of_the_first() {
    let Some(mut fleet) = Fleet::start("mqtt-two-runs") else {
        return;
    };
    let folders = build_two_runs(&fleet);
    for (n, run) in [(1, "first"), (2, "second")] {
        let scenario = two_runs_scenario(&fleet, n);
        // Started together, the worker's subscription stands before the
        // boss's first publication.
        support::mqtt::compile_in(&folders, &scenario);
        let (_, start_at) = support::robots::start_barrier(folders.len());
        let start_at = start_at.to_string();
        let mut args = vec!["--start-at", start_at.as_str()];
        let mut env = Vec::new();
        if n == 1 {
            args.extend(["--run", run]);
        } else {
            env.push(("SEMO_RUN", run));
        }
        let tag = format!("run{n}");
        let started: Vec<Started> = folders
            .iter()
            .map(|folder| fleet.spawn_with(folder, &scenario, &tag, &args, &env))
            .collect();
        let traces: BTreeMap<String, Vec<Event>> = started
            .iter()
            .map(|s| (s.robot.clone(), fleet.finish(s, &tag)))
            .collect();
        let worker = &traces["worker"];
        let colors = values_received(worker, "Boss.COLOR");
        assert_eq!(
            colors.first(),
            Some(&serde_json::json!(format!("run {n}"))),
            "run {n}: the worker first hears its own run's boss: {colors:?}"
        );
        assert!(
            colors.contains(&serde_json::json!("done")),
            "run {n}: the boss says done: {colors:?}"
        );
        let distances = values_received(worker, "Boss.DISTANCE");
        assert!(
            !distances.is_empty() && distances.iter().all(|d| *d == serde_json::json!(n)),
            "run {n}: every send the worker takes is its own run's: {distances:?}"
        );
        assert_eq!(modes(worker), ["WORK", "FINISH"], "run {n}");
        assert_eq!(
            refused(worker),
            0,
            "run {n}: nothing of another run is refused"
        );
    }
}

#[test]
fn the_operator_console_drives_scouting_to_finish() {
    operator_console_drives_scouting_to_finish("mqtt-operator", false);
}

/// The same over `mqtts://`: the console checks the broker with the
/// deployment's CA and presents the operator's client certificate (the
/// broker requires one: every client has one).
#[test]
fn the_operator_console_drives_scouting_to_finish_over_tls() {
    operator_console_drives_scouting_to_finish("mqtt-operator-tls", true);
}

/// `semo operator` as a process, with the scouting deployment (`tls` or
/// not): it shows the master waiting, the operator sends it home, every
/// robot finishes; the console printed the command, what the master sent
/// the operator and its final status.
fn operator_console_drives_scouting_to_finish(name: &str, tls: bool) {
    let Some((mut fleet, deploy)) = deployed_fleet(name, tls) else {
        return;
    };
    let out = fleet.out.clone();
    let folders = build_scouting_with(&out, &["--deploy", &deploy.display().to_string()]);
    let processes = &mut fleet.processes;
    // The scouting world without its simulated operator: only the console
    // can tell the master to return (it waits in WAIT_MODE until then).
    let mut world: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scenario()).unwrap()).unwrap();
    world["operator"] = serde_json::json!([]);
    world.as_object_mut().unwrap().remove("expect");
    let alone = out.join("no-operator.scenario.json");
    std::fs::write(&alone, world.to_string()).unwrap();

    let mut console = operator_console([std::ffi::OsStr::new("--deploy"), deploy.as_os_str()]);
    let mut stdin = console.stdin.take().unwrap();
    let stdout = console.stdout.take().unwrap();
    let (lines_tx, lines) = std::sync::mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        let mut all = Vec::new();
        for line in std::io::BufReader::new(stdout).lines() {
            let line = line.unwrap();
            let _ = lines_tx.send(line.clone());
            all.push(line);
        }
        all
    });
    let console = processes.push(console);
    let first = lines
        .recv_timeout(std::time::Duration::from_secs(30))
        .expect("the console says what it can send");
    assert!(first.contains("RC_CMD (to MasterTeam)"), "{first}");
    let scheme = if tls { "mqtts" } else { "mqtt" };
    assert!(
        first.starts_with(&format!("operator on {scheme}://127.0.0.1:")),
        "{first}"
    );

    let mut started = Vec::new();
    for folder in &folders {
        let robot = robot_name(folder);
        let trace = out.join(format!("{robot}.operated.jsonl"));
        let child = support::mqtt::robot_on(folder, &alone, &trace, 1)
            .args(["--transport", "mqtt"])
            .stderr(Stdio::piped())
            .spawn()
            .expect("the robot program starts");
        started.push((robot, trace, processes.push(child)));
    }
    // When the console shows the master waiting, the operator sends it home.
    let waiting =
        std::iter::from_fn(|| lines.recv_timeout(std::time::Duration::from_secs(30)).ok())
            .find(|l| l.starts_with("status irobot: running WAIT_MODE"));
    assert!(waiting.is_some(), "the console shows the master waiting");
    use std::io::Write;
    writeln!(stdin, "RC_CMD RETURN_MODE").unwrap();
    stdin.flush().unwrap();
    let mut traces = BTreeMap::new();
    for (robot, trace, index) in started {
        processes.wait_success(index, &format!("{robot} (operated)"));
        traces.insert(robot, read_trace(&trace));
    }
    drop(stdin);
    processes.wait_success(console, "semo operator");
    let printed = reader.join().unwrap();
    let master = modes(&traces["irobot"]);
    assert_eq!(
        master,
        ["AUTO_MODE", "WAIT_MODE", "RETURN_MODE", "FINISH"],
        "the console's command drives the master to FINISH"
    );
    for (robot, events) in &traces {
        assert_eq!(
            modes(events).last().map(String::as_str),
            Some("FINISH"),
            "{robot}"
        );
    }
    assert!(
        printed
            .iter()
            .any(|l| l == "sent USER.RC_CMD = RETURN_MODE"),
        "{printed:?}"
    );
    assert!(
        printed
            .iter()
            .any(|l| l.starts_with("irobot: send(USER, MasterTeam.DISTANCE) = ")),
        "the console prints what the master sends the operator: {printed:?}"
    );
    assert!(
        printed
            .iter()
            .any(|l| l.starts_with("status irobot: stopped FINISH")),
        "{printed:?}"
    );
}

/// `semo operator` on scouting with `args`, started with piped standard
/// streams.
fn operator_console<A: AsRef<std::ffi::OsStr>>(args: impl IntoIterator<Item = A>) -> Child {
    Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("operator")
        .arg(examples().join("scouting/scouting.mission"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("semo operator starts")
}

/// `semo operator` on scouting with `args`, `input` on its standard input
/// (then its end): its exit code, standard output and standard error.
fn operator_with(args: &[&str], input: &str) -> (Option<i32>, String, String) {
    let mut console = operator_console(args);
    use std::io::Write;
    let mut stdin = console.stdin.take().unwrap();
    // A console refused at once has closed its input already.
    let _ = stdin.write_all(input.as_bytes());
    drop(stdin);
    let out = console.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The console commands one run: a run id that is not one is refused at
/// once; without one, a command has nowhere to go until a robot's status
/// names the newest run; given one, the command goes to that run's topic.
#[test]
fn the_operator_console_commands_one_run() {
    let (code, _, stderr) = operator_with(&["--run", "a/b"], "");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("--run: a run id is 1 to 63 letters"),
        "{stderr}"
    );
    let Some(fleet) = Fleet::start("mqtt-operator-run") else {
        return;
    };
    let url = fleet.url();
    let (code, _, stderr) = operator_with(&["--broker", &url], "RC_CMD RETURN_MODE\n");
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("no run of mission scouting is known yet"),
        "{stderr}"
    );
    // A persistent session on run r1's command topic keeps what comes.
    let topic = topics::to_team(
        &scouting_run("r1"),
        "MasterTeam",
        "USER.RC_CMD",
        topics::OPERATOR,
    );
    let session = |args: &[&str]| {
        Command::new("mosquitto_sub")
            .args(["-h", "127.0.0.1", "-p", &fleet.port.to_string()])
            .args(["-q", "1", "-c", "-i", "run-r1-listener", "-t", &topic])
            .args(args)
            .output()
            .expect("mosquitto_sub runs (Debian mosquitto-clients)")
    };
    assert!(session(&["-E"]).status.success());
    let (code, stdout, stderr) =
        operator_with(&["--broker", &url, "--run", "r1"], "RC_CMD RETURN_MODE\n");
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains(", run r1;"), "{stdout}");
    assert!(
        stdout.contains("sent USER.RC_CMD = RETURN_MODE"),
        "{stdout}"
    );
    let kept = session(&["-C", "1", "-W", "10"]);
    let datagram = semo_server::live::operator_datagram("USER.RC_CMD", "RETURN_MODE");
    assert_eq!(
        kept.stdout.strip_suffix(b"\n"),
        Some(&datagram[..]),
        "{kept:?}"
    );
}

/// A command typed while nothing listens on the broker's port is not sent,
/// and the console says so (exit 1), never "sent"; it ends when its input
/// does, its connection still failing.
#[test]
fn the_operator_console_says_a_command_was_not_sent_without_a_broker() {
    let url = format!("mqtt://127.0.0.1:{}", free_port());
    let (code, stdout, stderr) =
        operator_with(&["--broker", &url, "--run", "r1"], "RC_CMD RETURN_MODE\n");
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    assert!(!stdout.contains("sent"), "{stdout}");
    assert!(
        stderr.contains(&format!(
            "operator: not sent: USER.RC_CMD = RETURN_MODE: no connection to the broker {url} ("
        )),
        "{stderr}"
    );
}

/// The `semo/monitor` notification of the server behind `client` whose
/// robots satisfy `wanted`; one that never comes fails the test.
async fn monitor_view(
    client: &mut semo_server::harness::TestClient,
    wanted: impl Fn(&serde_json::Value) -> bool,
) -> serde_json::Value {
    let last = std::sync::Mutex::new(serde_json::Value::Null);
    let seen = |p: &serde_json::Value| {
        *last.lock().unwrap() = p.clone();
        wanted(p)
    };
    let found = tokio::time::timeout(
        std::time::Duration::from_secs(60),
        client.notification("semo/monitor", seen),
    )
    .await;
    found.unwrap_or_else(|_| {
        panic!(
            "the awaited semo/monitor notification did not come; the last one: {}",
            last.lock().unwrap()
        )
    })
}

fn shown<'v>(view: &'v serde_json::Value, robot: &str) -> &'v serde_json::Value {
    view["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["robot"] == robot)
        .unwrap_or_else(|| panic!("{robot} is shown: {view}"))
}

/// A workspace for the editor: `files` copied in, and a `semo.toml` whose
/// `[build] deployment` is `deploy`.
fn monitor_workspace(out: &Path, deploy: &Path, files: &[PathBuf]) -> PathBuf {
    let workspace = out.join("workspace");
    std::fs::create_dir_all(&workspace).unwrap();
    for file in files {
        std::fs::copy(file, workspace.join(file.file_name().unwrap())).unwrap();
    }
    std::fs::write(
        workspace.join("semo.toml"),
        format!("[build]\ndeployment = \"{}\"\n", deploy.display()),
    )
    .unwrap();
    workspace
}

/// The language server (in-process) on `workspace`, `mission` open and
/// checked, and its monitor started with no broker named (so the
/// deployment file's); the client, the mission's URI and the answer.
async fn start_monitor(
    workspace: &Path,
    mission: &str,
) -> (semo_server::harness::TestClient, String, serde_json::Value) {
    let mut client = semo_server::harness::TestClient::start();
    let root = format!("file://{}", workspace.display());
    client
        .initialize_with(serde_json::json!({}), Some(&root))
        .await;
    let uri = client.open_file(&workspace.join(mission)).await;
    let answer = client
        .request("semo/monitor/start", serde_json::json!({ "uri": uri }))
        .await
        .expect("the monitor starts");
    (client, uri, answer)
}

#[test]
fn the_editor_monitor_shows_the_running_robots_and_a_killed_one_lost() {
    editor_monitor_shows_the_running_robots_and_a_killed_one_lost("mqtt-monitor", false);
}

/// The same over `mqtts://` with the operator's client certificate.
#[test]
fn the_editor_monitor_shows_the_running_robots_and_a_killed_one_lost_over_tls() {
    editor_monitor_shows_the_running_robots_and_a_killed_one_lost("mqtt-monitor-tls", true);
}

fn editor_monitor_shows_the_running_robots_and_a_killed_one_lost(name: &str, tls: bool) {
    // The broker of the deployment file with its ACL: the monitor finds it
    // through the project's semo.toml and connects as the operator.
    let Some((mut fleet, deploy)) = deployed_fleet(name, tls) else {
        return;
    };
    let (out, port) = (fleet.out.clone(), fleet.port);
    let folders = build_scouting_with(&out, &["--deploy", &deploy.display().to_string()]);
    // The broker is process 0.
    let processes = &mut fleet.processes;
    let workspace = monitor_workspace(
        &out,
        &deploy,
        &[
            examples().join("scouting/scouting.mission"),
            examples().join("scouting/MasterTeam.strategy.xml"),
        ],
    );
    // Without the simulated operator the master waits in WAIT_MODE: the
    // robots stay running.
    let mut world: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scenario()).unwrap()).unwrap();
    world["operator"] = serde_json::json!([]);
    world.as_object_mut().unwrap().remove("expect");
    let alone = out.join("no-operator.scenario.json");
    std::fs::write(&alone, world.to_string()).unwrap();

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let (mut client, uri, answer) = start_monitor(&workspace, "scouting.mission").await;
        let scheme = if tls { "mqtts" } else { "mqtt" };
        assert_eq!(answer["broker"], format!("{scheme}://127.0.0.1:{port}"));
        let view = monitor_view(&mut client, |p| p["connection"] == "connected").await;
        let names: Vec<String> = folders.iter().map(|f| robot_name(f)).collect();
        for robot in &names {
            assert_eq!(shown(&view, robot)["state"], "waiting", "{view}");
        }

        for folder in &folders {
            let robot = robot_name(folder);
            let trace = out.join(format!("{robot}.monitored.jsonl"));
            let child = support::mqtt::robot_on(folder, &alone, &trace, 1)
                .args(["--transport", "mqtt", "--duration", "1000000"])
                .stderr(Stdio::piped())
                .spawn()
                .expect("the robot program starts");
            processes.push(child);
        }
        // Every robot running in a mode with its services; the master
        // waiting for the operator, listening.
        let view = monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|robots| {
                robots.iter().all(|r| {
                    r["state"] == "running"
                        && r["mode"].is_string()
                        && r["services"].as_array().is_some_and(|s| !s.is_empty())
                }) && robots
                    .iter()
                    .any(|r| r["robot"] == "irobot" && r["mode"] == "WAIT_MODE")
            })
        })
        .await;
        // The robots were given no run: the default one, the newest.
        assert_eq!(view["run"], "default", "{view}");
        let master = shown(&view, "irobot");
        assert_eq!(master["team"], "MasterTeam");
        assert!(
            master["services"]
                .as_array()
                .unwrap()
                .iter()
                .any(|s| s["plan"] == "Listen" && s["service"] == "ReportStatus"),
            "{view}"
        );

        // Killed: the broker's last will marks it lost, the others run on.
        let irobot = names.iter().position(|n| n == "irobot").unwrap();
        // The broker is process 0, the robots follow in folder order.
        processes.0[1 + irobot].kill().unwrap();
        processes.0[1 + irobot].wait().unwrap();
        let view = monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|r| {
                r.iter()
                    .any(|r| r["robot"] == "irobot" && r["lost"] == true)
            })
        })
        .await;
        assert_eq!(shown(&view, "irobot")["lostBecause"], "lastWill");
        for robot in names.iter().filter(|n| *n != "irobot") {
            assert_eq!(shown(&view, robot)["state"], "running", "{view}");
        }
        let stopped = client
            .request("semo/monitor/stop", serde_json::json!({ "uri": uri }))
            .await
            .unwrap();
        assert_eq!(stopped["stopped"], true);
        client.shutdown().await;
    });
}

/// `semo operator` on scouting with `deploy`, as a process whose standard
/// input stays open (so only a refusal ends it): its exit code and stderr.
/// One that does not end fails the test rather than hanging it.
fn operator_refused(deploy: &Path) -> (Option<i32>, String) {
    let mut console = Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("operator")
        .arg(examples().join("scouting/scouting.mission"))
        .arg("--deploy")
        .arg(deploy)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("semo operator starts");
    let stdin = console.stdin.take();
    let stderr = console.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        use std::io::Read;
        let _ = std::io::BufReader::new(stderr).read_to_string(&mut text);
        text
    });
    for _ in 0..600 {
        if let Some(status) = console.try_wait().unwrap() {
            drop(stdin);
            return (status.code(), reader.join().unwrap());
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let _ = console.kill();
    let _ = console.wait();
    panic!(
        "semo operator kept trying a broker it cannot reach this way: {}",
        reader.join().unwrap()
    );
}

#[test]
fn a_broker_the_operator_cannot_trust_or_that_refuses_it_is_said_at_once() {
    let Some((fleet, _deploy)) = deployed_fleet("mqtt-tls-refused", true) else {
        return;
    };
    let (out, port) = (fleet.out.clone(), fleet.port);
    let text = scouting_deployment_text(port, true);
    let variant = |name: &str, from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        let file = out.join(name);
        std::fs::write(&file, text.replace(from, to)).unwrap();
        file
    };
    // The operator trusts another CA than the one that signed the broker.
    let other = out.join("other");
    std::fs::create_dir_all(&other).unwrap();
    certificate_authority(&other);
    let wrong_ca = variant(
        "wrong-ca.deploy.toml",
        "ca = \"ca.crt\"",
        "ca = \"other/ca.crt\"",
    );
    let (code, stderr) = operator_refused(&wrong_ca);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("the broker's certificate is not trusted: the CA ")
            && stderr.contains("other/ca.crt"),
        "{stderr}"
    );
    // The broker requires a client certificate; without one the operator
    // is refused (so the console over TLS did present its own).
    let operator_cert = "cert = \"operator.crt\"\nkey = \"operator.key\"\n";
    let no_cert = variant("no-cert.deploy.toml", operator_cert, "");
    let (code, stderr) = operator_refused(&no_cert);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("client certificate"), "{stderr}");
    // A CA file that is no certificate: positioned in the deployment file
    // before anything connects.
    std::fs::write(out.join("note.crt"), "ask the lab for the CA\n").unwrap();
    let not_pem = variant(
        "not-pem.deploy.toml",
        "ca = \"ca.crt\"",
        "ca = \"note.crt\"",
    );
    let (code, stderr) = operator_refused(&not_pem);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("E126") && stderr.contains("not-pem.deploy.toml:3:"),
        "{stderr}"
    );

    // The editor's monitor says the same: connection down, the reason, no
    // robot shown as anything but waiting; a bad file refuses the start.
    let files = [
        examples().join("scouting/scouting.mission"),
        examples().join("scouting/MasterTeam.strategy.xml"),
    ];
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let workspace = monitor_workspace(&out.join("wrong-ca"), &wrong_ca, &files);
        let (mut client, _, answer) = start_monitor(&workspace, "scouting.mission").await;
        assert_eq!(answer["broker"], format!("mqtts://127.0.0.1:{port}"));
        let view = monitor_view(&mut client, |p| p["connection"] == "disconnected").await;
        assert!(
            view["error"]
                .as_str()
                .is_some_and(|e| e.contains("the broker's certificate is not trusted")),
            "{view}"
        );
        assert_eq!(shown(&view, "irobot")["state"], "waiting");
        client.shutdown().await;

        let workspace = monitor_workspace(&out.join("not-pem"), &not_pem, &files);
        let mut client = semo_server::harness::TestClient::start();
        client
            .initialize_with(
                serde_json::json!({}),
                Some(&format!("file://{}", workspace.display())),
            )
            .await;
        let uri = client.open_file(&workspace.join("scouting.mission")).await;
        let refused = client
            .request("semo/monitor/start", serde_json::json!({ "uri": uri }))
            .await
            .expect_err("a CA file that is no certificate refuses the monitor");
        let message = refused["message"].as_str().unwrap_or("");
        assert!(
            message.contains("not-pem.deploy.toml:3:") && message.contains("[E126]"),
            "{message}"
        );
        client.shutdown().await;
    });
}

/// patrol_groups's deployment: a user per team and the operator, on a
/// private broker at `port`.
fn patrol_deployment(dir: &Path, port: u16) -> PathBuf {
    let users = [
        ("base", "base-secret"),
        ("guards", "guards-secret"),
        ("operator", "operator-secret"),
    ];
    password_files(dir, &users);
    let file = dir.join("patrol_groups.deploy.toml");
    std::fs::write(
        &file,
        format!(
            "broker = \"mqtt://127.0.0.1:{port}\"\n\n[broker_config]\npassword_file = \"passwd\"\n\n[operator]\nuser = \"operator\"\npassword_file = \"operator.pw\"\n\n[teams.Base]\nuser = \"base\"\npassword_file = \"base.pw\"\n\n[teams.Guards]\nuser = \"guards\"\npassword_file = \"guards.pw\"\n"
        ),
    )
    .unwrap();
    file
}

/// Sends `signal` (`STOP`, `CONT`) to a process.
fn signal(child: &Child, signal: &str) {
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success(), "kill -{signal} {}", child.id());
}

#[test]
fn the_editor_monitor_marks_a_hung_leader_lost_and_shows_its_successor() {
    // Team Guards elects a leader among its Turtlebots tb_0..tb_2 with
    // heartbeats; the broker's ACL lets the operator (the monitor) read them.
    let mission = examples().join("swarm/patrol_groups.mission");
    let Some((mut fleet, deploy)) =
        fleet_deployed_for("mqtt-monitor-leader", &mission, patrol_deployment)
    else {
        return;
    };
    let out = fleet.out.clone();
    let acl = std::fs::read_to_string(out.join("broker/semo.acl")).unwrap();
    assert!(
        acl.contains("user operator\n")
            && acl.contains("topic read semo/patrol_groups/+/Guards/Guards.__alive/Guards/tb_0\n"),
        "{acl}"
    );
    let folders =
        support::mqtt::build(&mission, &out, &["--deploy", &deploy.display().to_string()]);
    let processes = &mut fleet.processes;
    let workspace = monitor_workspace(&out, &deploy, std::slice::from_ref(&mission));
    let world = out.join("patrol.scenario.json");
    std::fs::write(&world, r#"{"time_scale": 1, "duration": 1000000}"#).unwrap();

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let (mut client, uri, _) = start_monitor(&workspace, "patrol_groups.mission").await;
        let mut robots = BTreeMap::new();
        for folder in &folders {
            let robot = robot_name(folder);
            let trace = out.join(format!("{robot}.jsonl"));
            let child = support::mqtt::robot_on(folder, &world, &trace, 1)
                .args(["--transport", "mqtt"])
                .stderr(Stdio::piped())
                .spawn()
                .expect("the robot program starts");
            robots.insert(robot, processes.push(child));
        }
        let leader_is = |robot: &'static str| {
            move |p: &serde_json::Value| {
                p["robots"].as_array().is_some_and(|all| {
                    all.iter().all(|r| r["state"] == "running")
                        && all
                            .iter()
                            .filter(|r| r["robot"].as_str().is_some_and(|n| n.starts_with("tb_")))
                            .all(|r| r["leader"] == robot)
                })
            }
        };
        let view = monitor_view(&mut client, leader_is("tb_0")).await;
        assert_eq!(shown(&view, "tb_0")["isLeader"], true, "{view}");
        assert_eq!(shown(&view, "tb_1")["isLeader"], false, "{view}");

        // The leader hangs (its connection stays open: no last will). It
        // is shown lost once silent for three heartbeats, and tb_1 leads.
        signal(&processes.0[robots["tb_0"]], "STOP");
        let view = monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|all| {
                all.iter()
                    .any(|r| r["robot"] == "tb_0" && r["lostBecause"] == "silent")
                    && all
                        .iter()
                        .any(|r| r["robot"] == "tb_1" && r["isLeader"] == true)
                    && all
                        .iter()
                        .any(|r| r["robot"] == "tb_2" && r["leader"] == "tb_1")
            })
        })
        .await;
        assert_eq!(shown(&view, "base")["state"], "running", "{view}");

        // Back: heard again, running again.
        signal(&processes.0[robots["tb_0"]], "CONT");
        monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|all| {
                all.iter()
                    .any(|r| r["robot"] == "tb_0" && r["state"] == "running")
            })
        })
        .await;
        let stopped = client
            .request("semo/monitor/stop", serde_json::json!({ "uri": uri }))
            .await
            .unwrap();
        assert_eq!(stopped["stopped"], true);
        client.shutdown().await;
    });
}

/// The nested counted groups fixture's deployment: the crew's user and the
/// operator, on a private broker at `port`.
fn rooms_deployment(dir: &Path, port: u16) -> PathBuf {
    let users = [("crew", "crew-secret"), ("operator", "operator-secret")];
    password_files(dir, &users);
    let file = dir.join("nested.deploy.toml");
    std::fs::write(
        &file,
        format!(
            "broker = \"mqtt://127.0.0.1:{port}\"\n\n[broker_config]\npassword_file = \"passwd\"\n\n[operator]\nuser = \"operator\"\npassword_file = \"operator.pw\"\n\n[teams.Crew]\nuser = \"crew\"\npassword_file = \"crew.pw\"\n"
        ),
    )
    .unwrap();
    file
}

/// The groups a monitor view shows of `robot`: `group=alive` each.
fn groups_shown(view: &serde_json::Value, robot: &str) -> Vec<String> {
    let groups = shown(view, robot)["groups"].as_array().cloned();
    groups
        .unwrap_or_default()
        .iter()
        .map(|g| format!("{}={}", g["group"].as_str().unwrap_or("?"), g["alive"]))
        .collect()
}

/// `tests/fixtures/counted_groups/nested.mission` (six TurtleBots in two
/// rooms of at least two, one sweeper in each room) built for MQTT and run
/// as processes on a private broker, with the editor's monitor and the
/// operator console watching: each shows every robot's counted groups from
/// its status, and, once tb_0 (Room1's sweeper) is killed, the groups the
/// others move to, as the robots' own `allocated` lines say.
#[test]
fn the_monitor_and_the_console_show_each_robots_counted_groups() {
    let mission = repo_root().join("tests/fixtures/counted_groups/nested.mission");
    let Some((mut fleet, deploy)) =
        fleet_deployed_for("mqtt-monitor-groups", &mission, rooms_deployment)
    else {
        return;
    };
    let out = fleet.out.clone();
    let folders =
        support::mqtt::build(&mission, &out, &["--deploy", &deploy.display().to_string()]);
    let processes = &mut fleet.processes;
    let workspace = monitor_workspace(&out, &deploy, std::slice::from_ref(&mission));
    let world = out.join("rooms.scenario.json");
    std::fs::write(&world, r#"{"time_scale": 1, "duration": 1000000}"#).unwrap();

    let mut console = Command::new(env!("CARGO_BIN_EXE_semo"))
        .arg("operator")
        .arg(&mission)
        .arg("--deploy")
        .arg(&deploy)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("semo operator starts");
    let stdin = console.stdin.take().unwrap();
    let stdout = console.stdout.take().unwrap();
    let (lines_tx, lines) = std::sync::mpsc::channel::<String>();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if lines_tx.send(line).is_err() {
                break;
            }
        }
    });
    processes.push(console);
    lines
        .recv_timeout(std::time::Duration::from_secs(30))
        .expect("the console starts");

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let mut robots = BTreeMap::new();
    runtime.block_on(async {
        let (mut client, uri, _) = start_monitor(&workspace, "nested.mission").await;
        for folder in &folders {
            let robot = robot_name(folder);
            let trace = out.join(format!("{robot}.jsonl"));
            let child = support::mqtt::robot_on(folder, &world, &trace, 1)
                .args(["--transport", "mqtt"])
                .stderr(Stdio::piped())
                .spawn()
                .expect("the robot program starts");
            robots.insert(robot, (processes.push(child), trace));
        }
        // Every robot in a room and a role; each room has at least two
        // robots and exactly one sweeper.
        let view = monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|all| {
                all.len() == 6
                    && all.iter().all(|r| {
                        r["state"] == "running"
                            && r["groups"].as_array().is_some_and(|g| g.len() == 2)
                    })
            })
        })
        .await;
        for room in ["Room1", "Room2"] {
            let members: Vec<Vec<String>> = robots
                .keys()
                .map(|r| groups_shown(&view, r))
                .filter(|g| g[0].starts_with(&format!("{room}=")))
                .collect();
            assert!(members.len() >= 2, "{room}: {view}");
            let sweepers = members.iter().filter(|g| g[1].starts_with("Sweeper=")).count();
            assert_eq!(sweepers, 1, "{room}: {view}");
        }

        // tb_0 killed: the five left fill the rooms again (tb_1, tb_2, tb_5
        // in Room1; tb_3, tb_4 in Room2) and Room1's first, tb_1, sweeps.
        let (tb_0, _) = &robots["tb_0"];
        processes.0[*tb_0].kill().unwrap();
        processes.0[*tb_0].wait().unwrap();
        let view = monitor_view(&mut client, |p| {
            p["robots"].as_array().is_some_and(|all| {
                let groups = |robot: &str| {
                    let r = all.iter().find(|r| r["robot"] == robot);
                    r.map(|r| r["groups"].clone()).unwrap_or_default()
                };
                all.iter().any(|r| r["robot"] == "tb_0" && r["lost"] == true)
                    && groups("tb_1")[1]["group"] == "Sweeper"
                    && groups("tb_2")
                        == serde_json::json!([{"group": "Room1", "alive": 5}, {"group": "others", "alive": 3}])
            })
        })
        .await;
        assert_eq!(groups_shown(&view, "tb_1")[0], "Room1=6", "{view}");
        let stopped = client
            .request("semo/monitor/stop", serde_json::json!({ "uri": uri }))
            .await
            .unwrap();
        assert_eq!(stopped["stopped"], true);
        client.shutdown().await;
    });
    // The console printed tb_2's move, as its status said it.
    let moved = std::iter::from_fn(|| lines.recv_timeout(std::time::Duration::from_secs(10)).ok())
        .find(|l| {
            l.starts_with("status tb_2: running ROOMS")
                && l.contains(" groups Room1 (5 alive), others (3 alive)")
        });
    assert!(moved.is_some(), "the console shows tb_2 in Room1");
    drop(stdin);
    // The status says what the robot's trace says: tb_2's last `allocated`
    // lines name Room1 (5 alive) and others (3 alive). SIGTERM ends it
    // cleanly, its trace closed.
    let (tb_2, trace) = &robots["tb_2"];
    signal(&fleet.processes.0[*tb_2], "TERM");
    fleet.processes.0[*tb_2].wait().unwrap();
    let allocated: Vec<String> = read_trace(trace)
        .iter()
        .filter(|e| field(e, "event") == "allocated")
        .map(|e| format!("{}={}", field(e, "name"), field(e, "alive")))
        .collect();
    assert!(
        allocated.ends_with(&["Room1=5".to_string(), "others=3".to_string()]),
        "{allocated:?}"
    );
}

/// When each life's leading changes, in time order (`lives`: every robot's
/// incarnations, each a robot's name and its events): a robot leads from a
/// `leader` event naming itself until one naming another, a `fenced`, or
/// `ends[life]` (when it was killed). Within one ms, steps down come first.
fn leadership_changes(
    lives: &[(String, Vec<Event>)],
    ends: &BTreeMap<usize, i64>,
) -> Vec<(i64, usize, bool)> {
    let mut changes: Vec<(i64, usize, bool)> = Vec::new();
    for (life, (robot, events)) in lives.iter().enumerate() {
        for e in events.iter() {
            let t = e["t"].as_i64().unwrap();
            match field(e, "event") {
                "leader" => changes.push((t, life, field(e, "leader") == robot)),
                "fenced" => changes.push((t, life, false)),
                _ => {}
            }
        }
        if let Some(&end) = ends.get(&life) {
            changes.push((end, life, false));
        }
    }
    changes.sort_by_key(|&(t, life, leads)| (t, leads, life));
    changes
}

/// The first mission time at which two robots both lead by their own
/// traces ([`leadership_changes`]), with the two.
fn two_leaders(
    lives: &[(String, Vec<Event>)],
    ends: &BTreeMap<usize, i64>,
) -> Option<(i64, String, String)> {
    let mut leading = vec![false; lives.len()];
    for (t, life, leads) in leadership_changes(lives, ends) {
        leading[life] = leads;
        let both: Vec<&String> = (0..lives.len())
            .filter(|&l| leading[l])
            .map(|l| &lives[l].0)
            .collect();
        if let [a, b, ..] = both.as_slice() {
            return Some((t, a.to_string(), b.to_string()));
        }
    }
    None
}

fn leaders_of(events: &[Event]) -> Vec<String> {
    events
        .iter()
        .filter(|e| field(e, "event") == "leader")
        .map(|e| field(e, "leader").to_string())
        .collect()
}

/// The leaders a robot followed in turn: [`leaders_of`] with the same
/// leader twice in a row taken once. On a loaded machine a robot may hear no
/// majority for a moment (its process or the broker starved for more than
/// the lease: it traces `fenced`), drop its leader and elect the same one
/// again; that is one leadership, not a change of leader.
fn leaders_in_turn(events: &[Event]) -> Vec<String> {
    let mut leaders = leaders_of(events);
    leaders.dedup();
    leaders
}

/// Mission ms since the start barrier's instant `t0` (time scale 1;
/// negative before it).
fn mission_ms(t0: std::time::Instant) -> i64 {
    let now = std::time::Instant::now();
    match now.checked_duration_since(t0) {
        Some(after) => after.as_millis() as i64,
        None => -(t0.duration_since(now).as_millis() as i64),
    }
}

/// What [`kill_and_restart`] saw: each life's trace in start order (the
/// restarted life last), the killed life's place among them, and the
/// mission times the kill and the restart really came.
struct KillRestart {
    traces: Vec<(String, Vec<Event>)>,
    killed: usize,
    killed_at: i64,
    restarted_at: i64,
}

/// Runs every robot of `folders` behind one start barrier (time scale 1),
/// kills `robot` at mission time `kill_at` and starts it again at
/// `restart_at`; `what` names the run in a robot's failure.
fn kill_and_restart(
    fleet: &mut Fleet,
    folders: &[PathBuf],
    scenario: &Path,
    robot: &str,
    (kill_at, restart_at): (i64, i64),
    what: &str,
) -> KillRestart {
    support::mqtt::compile_in(folders, scenario);
    let (t0, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let barrier = ["--start-at", start_at.as_str()];
    let mut lives: Vec<Started> = folders
        .iter()
        .map(|f| fleet.spawn(f, scenario, "first", &barrier))
        .collect();
    let killed = lives.iter().position(|s| s.robot == robot).unwrap();
    sleep_until(t0, kill_at);
    fleet.processes.kill(lives[killed].index);
    let killed_at = mission_ms(t0);
    sleep_until(t0, restart_at);
    let restarted_at = mission_ms(t0);
    lives.push(fleet.spawn(&folder_of(folders, robot), scenario, "second", &barrier));
    let traces = lives
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let events = if i == killed {
                read_trace(&s.trace)
            } else {
                fleet.finish(s, what)
            };
            (s.robot.clone(), events)
        })
        .collect();
    KillRestart {
        traces,
        killed,
        killed_at,
        restarted_at,
    }
}

/// Sleeps until mission time `at` (time scale 1) of a run whose mission
/// time 0 is the instant `t0`.
fn sleep_until(t0: std::time::Instant, at: i64) {
    let when = t0 + std::time::Duration::from_millis(at as u64);
    std::thread::sleep(when.saturating_duration_since(std::time::Instant::now()));
}

/// patrol_groups, every robot a process over a private broker: the modes
/// the light levels call for, and the TurtleBots' leader killed and
/// restarted: a new leader takes over, and after the restart the restarted
/// robot listens and waits for the one that took over to give way: never
/// two leaders at once (judged from the traces' mission times, on one
/// clock: every process has the same `--start-at`).
#[test]
fn patrol_groups_over_mqtt_keeps_one_leader_across_a_restart() {
    let Some(mut fleet) = Fleet::start("mqtt-patrol-groups") else {
        return;
    };
    let folders = support::mqtt::build(
        &examples().join("swarm/patrol_groups.mission"),
        &fleet.out,
        &[],
    );
    // Dark from 1 s to 2.5 s: the TurtleBots warn the team, which hides.
    let dark = r#"{"sensors": [{"at": 1000, "value": "LIGHTNESS", "is": "100"}, {"at": 2500, "value": "LIGHTNESS", "is": "600"}]}"#;
    let scenario = fleet.out.join("patrol.scenario.json");
    std::fs::write(
        &scenario,
        format!(
            r#"{{"time_scale": 1, "duration": 9000, "robots": {{"tb_0": {dark}, "tb_1": {dark}, "tb_2": {dark}}}}}"#
        ),
    )
    .unwrap();
    // tb_0 is dead three heartbeats (600 ms) after it is killed, and tb_1
    // takes over at its next pass through the leader's statement (one a
    // second): the restart comes after that.
    const KILL_AT: i64 = 3500;
    const RESTART_AT: i64 = 6000;
    let KillRestart {
        traces,
        killed: first_tb_0,
        killed_at,
        restarted_at,
    } = kill_and_restart(
        &mut fleet,
        &folders,
        &scenario,
        "tb_0",
        (KILL_AT, RESTART_AT),
        "patrol_groups",
    );
    let of =
        |robot: &str| -> &Vec<Event> { &traces.iter().rev().find(|(r, _)| r == robot).unwrap().1 };

    // The TurtleBots hide while it is dark and patrol again once it is
    // bright (at the change, a robot may flip back and forth for a firing
    // or two: its `Hear` can read the last DARK before the first BRIGHT,
    // as in the simulator), then stay patrolling.
    let mode_at = |events: &[Event], t: i64| -> String {
        events
            .iter()
            .filter(|e| field(e, "event") == "mode" && e["t"].as_i64().unwrap() <= t)
            .map(|e| field(e, "mode").to_string())
            .next_back()
            .unwrap_or_default()
    };
    let first_life = &traces[first_tb_0].1;
    for (robot, events) in [
        ("tb_1", of("tb_1")),
        ("tb_2", of("tb_2")),
        ("tb_0", first_life),
    ] {
        assert_eq!(mode_at(events, 500), "PATROL", "{robot}");
        assert_eq!(
            mode_at(events, 2400),
            "HIDE",
            "{robot}: {:?}",
            modes(events)
        );
        assert_eq!(
            mode_at(events, 3400),
            "PATROL",
            "{robot}: {:?}",
            modes(events)
        );
        let late = events
            .iter()
            .filter(|e| field(e, "event") == "mode" && e["t"].as_i64().unwrap() > 3400)
            .count();
        assert_eq!(late, 0, "{robot} changes mode after the light settled");
    }
    assert_eq!(modes(of("tb_0")), ["PATROL"], "tb_0's second life");
    // What let tb_0's second life hide: a publish the broker kept (the last
    // DARK of a TurtleBot that resumed on another's BRIGHT before it sent
    // its own). Publishes are not retained, as over UDP and in the
    // simulator: the broker keeps the robots' statuses only.
    let kept = retained_topics(fleet.port, "semo/patrol_groups/#");
    assert!(
        !kept.is_empty() && kept.iter().all(|t| t.contains("/status/")),
        "{kept:?}"
    );
    // The base watches; whether the leader's report of the alarm reaches
    // it while it is DARK is a race of a few ms at the changes (ALERT or not).
    assert_eq!(modes(of("base")).first().map(String::as_str), Some("WATCH"));
    for robot in ["ev_0", "ev_1"] {
        let m = modes(of(robot));
        assert_eq!(m.first().map(String::as_str), Some("PATROL"), "{robot}");
        assert_eq!(m.last().map(String::as_str), Some("PATROL"), "{robot}");
    }

    // tb_1 takes over within three heartbeats of the last one tb_0 sent
    // (docs/groups.md, "Takeover": lost after two silent periods, decided
    // at tb_1's next heartbeat, whatever its phase); 300 ms for a late
    // firing and delivery on a loaded machine.
    let last_heartbeat = traces[first_tb_0]
        .1
        .iter()
        .filter(|e| field(e, "event") == "send" && field(e, "key") == "Guards.__alive")
        .map(|e| e["t"].as_i64().unwrap())
        .next_back()
        .expect("tb_0 sent heartbeats");
    let took_over = of("tb_1")
        .iter()
        .find(|e| field(e, "event") == "leader" && field(e, "leader") == "tb_1")
        .map(|e| e["t"].as_i64().unwrap())
        .expect("tb_1 takes over");
    assert!(
        took_over > killed_at - 50 && took_over <= last_heartbeat + 3 * 200 + 300,
        "tb_1 took over at {took_over}, tb_0's last heartbeat at {last_heartbeat}"
    );
    // After the restart tb_0 leads again, and the others follow it.
    assert_eq!(leaders_in_turn(of("tb_1")), ["tb_0", "tb_1", "tb_0"]);
    assert_eq!(leaders_in_turn(of("tb_2")), ["tb_0", "tb_1", "tb_0"]);
    let second = leaders_in_turn(of("tb_0"));
    assert_eq!(
        second.last().map(String::as_str),
        Some("tb_0"),
        "{second:?}"
    );
    let claimed = of("tb_0")
        .iter()
        .find(|e| field(e, "event") == "leader" && field(e, "leader") == "tb_0")
        .map(|e| e["t"].as_i64().unwrap())
        .unwrap();
    assert!(
        claimed >= restarted_at + 300,
        "the restarted tb_0 listened before claiming: restarted at {restarted_at}, claimed at {claimed}"
    );
    let ends = BTreeMap::from([(first_tb_0, killed_at)]);
    assert_eq!(two_leaders(&traces, &ends), None);
}

/// How long two robots led at once, in total ([`leadership_changes`]).
fn two_leaders_for(lives: &[(String, Vec<Event>)]) -> i64 {
    let mut leading = vec![false; lives.len()];
    let (mut total, mut since) = (0, None);
    for (t, life, leads) in leadership_changes(lives, &BTreeMap::new()) {
        leading[life] = leads;
        let two = leading.iter().filter(|&&l| l).count() >= 2;
        match (two, since) {
            (true, None) => since = Some(t),
            (false, Some(from)) => {
                total += t - from;
                since = None;
            }
            _ => {}
        }
    }
    total
}

/// patrol_groups over a private broker, the leader tb_0's connection to it
/// cut by a TCP proxy from 1.2 s to 3.5 s (docs/groups.md, "Fencing"): tb_0
/// hears no majority and steps down (`fenced`, "1 of 3"), tb_1 takes over,
/// and healed, tb_0 leads again once tb_1 has given way. How long two
/// robots led at once is printed: the documented bound for processes whose
/// heartbeats are out of phase (one and a half heartbeat periods) is a
/// real-time race of separate processes on a loaded machine (it measured
/// 800 ms at load 8), so it is asserted in virtual time instead
/// (`compiler/src/sim/tests.rs`, `tests/differential.rs`); without fencing
/// tb_0 led through the whole cut while tb_1 led from about 2 s, which the
/// single `fenced` event during the cut rules out here.
#[test]
fn a_leader_cut_off_from_the_broker_steps_down_before_another_is_elected() {
    let Some(mut fleet) = Fleet::start("mqtt-fencing") else {
        return;
    };
    let folders = support::mqtt::build(
        &examples().join("swarm/patrol_groups.mission"),
        &fleet.out,
        &[],
    );
    let scenario = fleet.out.join("fencing.scenario.json");
    std::fs::write(&scenario, r#"{"time_scale": 1, "duration": 9000}"#).unwrap();
    let proxy = support::proxy::Proxy::start(fleet.port);
    let through_proxy = format!("mqtt://127.0.0.1:{}", proxy.port);
    const CUT_AT: i64 = 1200;
    const HEAL_AT: i64 = 3500;
    support::mqtt::compile_in(&folders, &scenario);
    let (t0, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let lives: Vec<Started> = folders
        .iter()
        .map(|f| {
            let mut extra = vec!["--start-at", start_at.as_str()];
            if robot_name(f) == "tb_0" {
                extra.extend(["--broker", through_proxy.as_str()]);
            }
            fleet.spawn(f, &scenario, "fencing", &extra)
        })
        .collect();
    sleep_until(t0, CUT_AT);
    proxy.cut();
    sleep_until(t0, HEAL_AT);
    proxy.heal();
    assert!(proxy.dropped() > 0, "the cut dropped tb_0's traffic");
    let traces: Vec<(String, Vec<Event>)> = lives
        .iter()
        .map(|s| (s.robot.clone(), fleet.finish(s, "fencing")))
        .collect();
    let of = |robot: &str| -> &Vec<Event> { &traces.iter().find(|(r, _)| r == robot).unwrap().1 };

    let fenced: Vec<(i64, &str)> = of("tb_0")
        .iter()
        .filter(|e| field(e, "event") == "fenced")
        .map(|e| (e["t"].as_i64().unwrap(), field(e, "heard")))
        .collect();
    // Once during the cut; a loaded machine may starve a process or the
    // broker past the lease at other times too, which fences as well.
    let during_cut: Vec<&(i64, &str)> = fenced
        .iter()
        .filter(|(t, _)| (CUT_AT..HEAL_AT).contains(t))
        .collect();
    assert!(
        matches!(during_cut.as_slice(), [(_, "1 of 3")]),
        "tb_0 fenced: {fenced:?}"
    );
    assert_eq!(leaders_in_turn(of("tb_1")), ["tb_0", "tb_1", "tb_0"]);
    assert_eq!(leaders_in_turn(of("tb_2")), ["tb_0", "tb_1", "tb_0"]);
    // Healed, tb_0 follows tb_1 if tb_1's claim reaches it before tb_1,
    // at its next heartbeat, has seen tb_0 alive and given way: a race of
    // the two processes' heartbeats.
    let tb_0 = leaders_in_turn(of("tb_0"));
    assert!(
        tb_0 == ["tb_0", "tb_1", "tb_0"] || tb_0 == ["tb_0"],
        "{tb_0:?}"
    );
    // The time with two leaders is a race of real processes (their
    // heartbeats' phases, the broker's latency, the machine's load): printed,
    // not asserted. The bound itself is asserted where time is virtual
    // (compiler/src/sim/tests.rs, tests/differential.rs); what is asserted
    // here holds whatever the timing: tb_0 fenced itself once during the cut,
    // and the others moved to tb_1 and back.
    let overlap = two_leaders_for(&traces);
    eprintln!(
        "two leaders for {overlap} ms (documented bound out of phase: {} ms); tb_0 fenced at {:?}",
        3 * semo::refine::HEARTBEAT_MS / 2,
        fenced
    );
}

/// `highest_battery` (tests/fixtures/elections): the processes' heartbeats
/// carry the battery levels the scenario gives them, and the fullest robot
/// leads.
#[test]
fn highest_battery_over_mqtt_elects_the_fullest_robot() {
    let Some(mut fleet) = Fleet::start("mqtt-highest-battery") else {
        return;
    };
    let folders = support::mqtt::build(
        &repo_root().join("tests/fixtures/elections/highest_battery/election.mission"),
        &fleet.out,
        &[],
    );
    let scenario = fleet.out.join("battery.scenario.json");
    std::fs::write(
        &scenario,
        r#"{"time_scale": 1, "duration": 1500,
            "robots": {"tb_0": {"battery": [{"at": 0, "level": 40}]},
                       "tb_1": {"battery": [{"at": 0, "level": 90}]},
                       "tb_2": {"battery": [{"at": 0, "level": 60}]}}}"#,
    )
    .unwrap();
    support::mqtt::compile_in(&folders, &scenario);
    let (_, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let traces = fleet.run_all(&folders, &scenario, "battery", &["--start-at", &start_at]);
    let lives: Vec<(String, Vec<Event>)> = traces.clone().into_iter().collect();
    for (robot, events) in &traces {
        assert_eq!(leaders_in_turn(events), ["tb_1"], "{robot}");
        // Everyone listened one and a half heartbeats (100 ms) first.
        let first = events
            .iter()
            .find(|e| field(e, "event") == "leader")
            .map(|e| e["t"].as_i64().unwrap())
            .unwrap();
        assert!(first >= 150, "{robot} decided at {first}");
    }
    let heard: Vec<String> = traces["tb_0"]
        .iter()
        .filter(|e| {
            field(e, "event") == "receive"
                && field(e, "from_robot") == "tb_1"
                && field(e, "key") == "Crew.__alive"
        })
        .map(|e| field(e, "value").to_string())
        .collect();
    // Listening, tb_1 knows no term yet; then it leads under the first.
    assert!(heard.iter().any(|v| v == "member 90 0"), "{heard:?}");
    assert!(heard.iter().any(|v| v == "leader 90 1"), "{heard:?}");
    assert_eq!(two_leaders(&lives, &BTreeMap::new()), None);
}

/// The warnings every MQTT robot is built with for the sanitizer runs:
/// `-Wpedantic -Werror`, some optimisation (the sanitizers' own advice), and
/// debug information for their reports.
const SANITIZED: &str = "-std=c11 -Wall -Wextra -Wpedantic -Werror -O1 -g -fno-omit-frame-pointer";

/// Scouting with the MQTT transport built with `cc` and `sanitizer` flags,
/// its robots run over a private broker with `env`: each robot's mode
/// sequence ends in FINISH and no robot writes anything on stderr (a
/// sanitizer report, which also fails the robot: halt_on_error).
fn scouting_over_mqtt_is_clean(name: &str, cc: &str, sanitizer: &str, env: &[(&str, &str)]) {
    if !support::robots::has(cc) {
        eprintln!("skipping {name}: no {cc}");
        return;
    }
    let Some(mut fleet) = Fleet::start(name) else {
        return;
    };
    let folders = support::mqtt::build_with(
        &examples().join("scouting/scouting.mission"),
        &fleet.out,
        &[],
        cc,
        &format!("{SANITIZED} {sanitizer}"),
    );
    let started: Vec<Started> = folders
        .iter()
        .map(|folder| fleet.spawn_with(folder, &scenario(), name, &[], env))
        .collect();
    for run in &started {
        let stderr = fleet
            .processes
            .wait_success(run.index, &format!("{} ({name})", run.robot));
        assert!(
            stderr.trim().is_empty(),
            "{} ({name}): sanitizer report:\n{stderr}",
            run.robot
        );
        let events = read_trace(&run.trace);
        assert_eq!(
            modes(&events).last().map(String::as_str),
            Some("FINISH"),
            "{} ({name})",
            run.robot
        );
    }
}

#[test]
fn scouting_over_mqtt_is_clean_under_address_and_undefined_behaviour_sanitizers() {
    scouting_over_mqtt_is_clean(
        "mqtt-asan",
        "gcc",
        "-fsanitize=address,undefined -fno-sanitize-recover=all",
        &[
            ("ASAN_OPTIONS", "detect_leaks=1:abort_on_error=1"),
            ("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1"),
        ],
    );
}

#[test]
fn scouting_over_mqtt_is_clean_under_thread_sanitizer() {
    scouting_over_mqtt_is_clean(
        "mqtt-tsan",
        "clang",
        "-fsanitize=thread",
        &[("TSAN_OPTIONS", "halt_on_error=1")],
    );
}

/// The MQTT transport's code at `-Wpedantic -Werror` with clang too (gcc
/// builds every other test's robots).
#[test]
fn scouting_with_mqtt_compiles_pedantic_with_clang() {
    if !support::robots::has("clang") {
        eprintln!("skipping: no clang");
        return;
    }
    if support::mqtt::broker_or_skip("scouting_with_mqtt_compiles_pedantic_with_clang").is_none() {
        return;
    }
    let out = scratch("mqtt-clang");
    let folders = support::mqtt::build_with(
        &examples().join("scouting/scouting.mission"),
        &out,
        &[],
        "clang",
        PEDANTIC,
    );
    assert_eq!(folders.len(), 3);
}

/// GroupSync (tests/fixtures/group_sync), every robot a process over a
/// private broker: the robots drive 100, 700 and 1200 ms, tb_1 is killed
/// on the way; tb_0 and tb_2 meet when tb_2 arrives (not at the 2 s
/// timeout), and tb_0 waited for it.
#[test]
fn group_sync_over_mqtt_waits_for_the_live_members() {
    let Some(mut fleet) = Fleet::start("mqtt-group-sync") else {
        return;
    };
    let folders = support::mqtt::build(
        &repo_root().join("tests/fixtures/group_sync/sync.mission"),
        &fleet.out,
        &[],
    );
    let scenario = fleet.out.join("sync.scenario.json");
    std::fs::write(
        &scenario,
        r#"{"time_scale": 1, "duration": 4000,
            "robots": {"tb_0": {"services": {"move": 100}},
                       "tb_1": {"services": {"move": 700}},
                       "tb_2": {"services": {"move": 1200}}}}"#,
    )
    .unwrap();
    support::mqtt::compile_in(&folders, &scenario);
    let (t0, start_at) = support::robots::start_barrier(folders.len());
    let start_at = start_at.to_string();
    let started: Vec<Started> = folders
        .iter()
        .map(|f| fleet.spawn(f, &scenario, "sync", &["--start-at", &start_at]))
        .collect();
    sleep_until(t0, 300);
    let tb_1 = started.iter().find(|s| s.robot == "tb_1").unwrap();
    fleet.processes.kill(tb_1.index);
    let mut traces = BTreeMap::new();
    for s in &started {
        let events = if s.robot == "tb_1" {
            read_trace(&s.trace)
        } else {
            fleet.finish(s, "group sync")
        };
        traces.insert(s.robot.clone(), events);
    }
    let at = |robot: &str, event: &str| {
        traces[robot]
            .iter()
            .find(|e| field(e, "event") == event)
            .map(|e| e["t"].as_i64().unwrap())
    };
    let arrived = traces["tb_2"]
        .iter()
        .find(|e| field(e, "event") == "send" && field(e, "key") == "Crew.__sync")
        .map(|e| e["t"].as_i64().unwrap())
        .expect("tb_2 announces its arrival");
    assert!(arrived >= 1200, "tb_2 arrived at {arrived}");
    for robot in ["tb_0", "tb_2"] {
        let met = at(robot, "group_sync").unwrap_or_else(|| panic!("{robot} met the group"));
        assert!(
            met >= arrived && met < 2000,
            "{robot} met at {met}, tb_2 arrived at {arrived}"
        );
        assert_eq!(at(robot, "timeout"), None, "{robot}");
    }
    assert_eq!(at("tb_1", "group_sync"), None);
}

/// Group services (tests/fixtures/group_service: `move` is one, heartbeats
/// every 200 ms), every robot a process over a private broker: each member
/// traces its rank among the live members and their number; tb_1 is killed
/// and tb_0 and tb_2 re-divide (tb_2 moves up to rank 1 of 2); tb_1 is
/// restarted and they change back (2 of 3), the restarted tb_1 with them.
#[test]
fn group_service_over_mqtt_redivides_when_a_member_fails_and_returns() {
    let Some(mut fleet) = Fleet::start("mqtt-group-service") else {
        return;
    };
    let folders = support::mqtt::build(
        &repo_root().join("tests/fixtures/group_service/sweep.mission"),
        &fleet.out,
        &[],
    );
    let scenario = fleet.out.join("sweep.scenario.json");
    std::fs::write(&scenario, r#"{"time_scale": 1, "duration": 6000}"#).unwrap();
    // tb_1 is dead three heartbeats (600 ms) after it is killed.
    const KILL_AT: i64 = 1500;
    const RESTART_AT: i64 = 3500;
    let KillRestart {
        traces,
        killed: first_tb_1,
        ..
    } = kill_and_restart(
        &mut fleet,
        &folders,
        &scenario,
        "tb_1",
        (KILL_AT, RESTART_AT),
        "group service",
    );
    // (t, rank, size) of each `group` event of one life.
    let groups = |events: &[Event]| -> Vec<(i64, String, String)> {
        events
            .iter()
            .filter(|e| field(e, "event") == "group")
            .map(|e| {
                let t = e["t"].as_i64().unwrap();
                (
                    t,
                    field(e, "rank").to_string(),
                    field(e, "size").to_string(),
                )
            })
            .collect()
    };
    let of = |robot: &str| groups(&traces.iter().rev().find(|(r, _)| r == robot).unwrap().1);
    let rank_at = |list: &[(i64, String, String)], t: i64| -> (String, String) {
        list.iter()
            .filter(|(at, _, _)| *at <= t)
            .map(|(_, rank, size)| (rank.clone(), size.clone()))
            .next_back()
            .unwrap_or_default()
    };
    let pair = |rank: &str, size: &str| (rank.to_string(), size.to_string());
    let (tb_0, tb_2) = (of("tb_0"), of("tb_2"));
    // Before the kill: the whole group; between the failure's detection
    // and the restart: two; at the end: three again.
    let detected = KILL_AT + 4 * 200 + 400;
    for (robot, list, rank_before, rank_between) in
        [("tb_0", &tb_0, "0", "0"), ("tb_2", &tb_2, "2", "1")]
    {
        assert_eq!(
            rank_at(list, KILL_AT - 100),
            pair(rank_before, "3"),
            "{robot}: {list:?}"
        );
        assert_eq!(
            rank_at(list, detected),
            pair(rank_between, "2"),
            "{robot}: {list:?}"
        );
        assert_eq!(
            rank_at(list, RESTART_AT - 100),
            pair(rank_between, "2"),
            "{robot}: {list:?}"
        );
        assert_eq!(
            rank_at(list, i64::MAX),
            pair(rank_before, "3"),
            "{robot}: {list:?}"
        );
    }
    // tb_1: rank 1 of 3 in both lives.
    let first_life = groups(&traces[first_tb_1].1);
    assert_eq!(
        rank_at(&first_life, KILL_AT - 100),
        pair("1", "3"),
        "{first_life:?}"
    );
    let second_life = of("tb_1");
    assert_eq!(
        rank_at(&second_life, i64::MAX),
        pair("1", "3"),
        "{second_life:?}"
    );
}

/// The stress runs of issue 33 (forgeries taken, two leaders' time,
/// takeovers), all `#[ignore]`d.
#[path = "mqtt/stress.rs"]
mod stress;

/// One robot's send path at QoS 1: every message once and in order, and
/// (ignored) its rate next to `mosquitto_pub`'s and its memory.
#[path = "mqtt/send_rate.rs"]
mod send_rate;
