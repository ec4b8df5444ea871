//! The live robot monitor as the editor reaches it: `semo/monitor/start`
//! on an open mission, a private `mosquitto` on a free loopback port, robots
//! played by MQTT clients that publish exactly what the runtime publishes
//! (retained status with its last will, heartbeats as datagrams), and the
//! `semo/monitor` notifications read back: every robot of the mission
//! waiting at first, then its mode, services and leader; lost when its last
//! will arrives or when it stops heart-beating; the newest run, or the one
//! asked for. (`tests/mqtt.rs` does the same with real generated robot
//! processes.)
//!
//! Needs `mosquitto` (Debian). Skipped with a message when it is missing,
//! unless `SEMO_MQTT_TESTS=require` (CI).

mod support;

use rumqttc::{AsyncClient, LastWill, MqttOptions, QoS};
use semo_server::harness::TestClient;
use serde_json::{Value, json};
use std::path::Path;
use std::time::Duration;
use support::broker::{Broker, free_port, mosquitto};

/// A robot as the broker sees it: connected with the runtime's last will
/// on its retained status; `kill` drops the connection without a word.
struct FakeRobot {
    client: AsyncClient,
    robot: String,
    /// Its run, and when its mission time 0 was (Unix ms).
    run: String,
    started: i64,
    poller: tokio::task::JoinHandle<()>,
}

impl FakeRobot {
    /// In the run of a robot program given none.
    fn connect(port: u16, robot: &str) -> FakeRobot {
        FakeRobot::connect_in(port, robot, "default", 1)
    }

    fn connect_in(port: u16, robot: &str, run: &str, started: i64) -> FakeRobot {
        let mut options = MqttOptions::new(
            format!("semo-patrol_groups-{run}-{robot}"),
            "127.0.0.1",
            port,
        );
        options.set_last_will(LastWill::new(
            status_topic(run, robot),
            format!(
                r#"{{"robot":"{robot}","event":"status","state":"lost","started":"{started}"}}"#
            ),
            QoS::AtLeastOnce,
            true,
        ));
        let (client, mut eventloop) = AsyncClient::new(options, 16);
        let poller = tokio::spawn(async move {
            loop {
                if eventloop.poll().await.is_err() {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            }
        });
        FakeRobot {
            client,
            robot: robot.to_string(),
            run: run.to_string(),
            started,
            poller,
        }
    }

    /// The status the runtime publishes (`docs/deployment.md`).
    async fn status(&self, state: &str, mode: &str, leader: &str, services: &str) {
        let (robot, run) = (&self.robot, &self.run);
        self.status_of(robot, run, self.started, [state, mode, leader, services])
            .await;
    }

    /// The status of `robot` of run `run` that started at `started`, on
    /// this connection (after what it published before): `[state, mode,
    /// leader, services]`.
    async fn status_of(
        &self,
        robot: &str,
        run: &str,
        started: i64,
        [state, mode, leader, services]: [&str; 4],
    ) {
        let payload = json!({
            "t": 1, "robot": robot, "event": "status", "state": state,
            "started": started.to_string(),
            "mode": mode, "leader": leader, "services": services,
        });
        self.client
            .publish(
                status_topic(run, robot),
                QoS::AtLeastOnce,
                true,
                payload.to_string(),
            )
            .await
            .unwrap();
    }

    /// A heartbeat of team Guards's leader election: the runtime's datagram.
    async fn heartbeat(&self) {
        // The runtime's datagram (`semo::deploy::datagram`): a heartbeat's
        // value is text.
        let datagram = semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: true,
            team: "Guards".into(),
            robot: self.robot.clone(),
            key: "Guards.__alive".into(),
            value: Some(semo::refine::Value::text("member -")),
        });
        let sender = semo::deploy::topics::Sender {
            team: "Guards",
            robot: &self.robot,
        };
        let run = semo::deploy::topics::RunId::parse(&self.run).unwrap();
        let scope = semo::deploy::topics::Scope::run("patrol_groups", &run);
        self.client
            .publish(
                semo::deploy::topics::to_team(&scope, "Guards", "Guards.__alive", sender),
                QoS::AtMostOnce,
                false,
                datagram,
            )
            .await
            .unwrap();
    }

    fn kill(self) {
        self.poller.abort();
    }
}

fn status_topic(run: &str, robot: &str) -> String {
    format!("semo/patrol_groups/{run}/status/{robot}")
}

/// A workspace with the patrol_groups example (team Guards elects a leader).
fn workspace() -> (tempfile::TempDir, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let source =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/swarm/patrol_groups.mission");
    let text = std::fs::read_to_string(source).unwrap();
    let mission = dir.path().join("patrol_groups.mission");
    std::fs::write(&mission, &text).unwrap();
    (dir, format!("file://{}", mission.display()), text)
}

async fn started(client: &mut TestClient, root: &Path, uri: &str, text: &str) {
    client
        .initialize_with(json!({}), Some(&format!("file://{}", root.display())))
        .await;
    client.open(uri, text).await;
    client.diagnostics(uri, Some(1)).await;
}

/// `semo/monitor/start` on `uri` with `broker`: the monitor's answer.
async fn monitor_start(client: &mut TestClient, uri: &str, broker: &str) -> Value {
    client
        .request(
            "semo/monitor/start",
            json!({ "uri": uri, "broker": broker }),
        )
        .await
        .expect("the monitor starts")
}

/// The next `semo/monitor` notification whose robots satisfy `wanted`; a
/// monitor that never sends it fails the test instead of hanging it.
async fn view_where(client: &mut TestClient, wanted: impl Fn(&Value) -> bool) -> Value {
    let last = std::sync::Mutex::new(Value::Null);
    let seen = |p: &Value| {
        *last.lock().unwrap() = p.clone();
        wanted(p)
    };
    let found = tokio::time::timeout(
        Duration::from_secs(30),
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

fn robot<'v>(view: &'v Value, name: &str) -> &'v Value {
    view["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["robot"] == name)
        .unwrap_or_else(|| panic!("{name} is shown: {view}"))
}

fn state(view: &Value, name: &str) -> String {
    robot(view, name)["state"]
        .as_str()
        .unwrap_or("")
        .to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn robots_appear_with_their_modes_and_a_killed_or_silent_one_is_lost() {
    let Some(binary) = mosquitto() else { return };
    let broker = Broker::start(&binary);
    let (dir, uri, text) = workspace();
    let mut client = TestClient::start();
    started(&mut client, dir.path(), &uri, &text).await;

    let answer = monitor_start(&mut client, &uri, &broker.url()).await;
    assert_eq!(answer["mission"], "patrol_groups");
    assert_eq!(answer["broker"], broker.url());
    let names: Vec<&str> = answer["robots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["robot"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["base", "tb_0", "tb_1", "tb_2", "ev_0", "ev_1"]);

    // Every robot of the mission, waiting, once connected.
    let view = view_where(&mut client, |p| p["connection"] == "connected").await;
    assert_eq!(view["uri"], uri.as_str());
    for name in &names {
        assert_eq!(state(&view, name), "waiting", "{view}");
    }

    // A robot reports: its mode, services and leadership show.
    let tb_0 = FakeRobot::connect(broker.port, "tb_0");
    tb_0.status(
        "running",
        "PATROL",
        "tb_0",
        "Action=Patrol,Report=ToBase,Listen=Hear",
    )
    .await;
    let view = view_where(&mut client, |p| p["robots"][1]["mode"] == "PATROL").await;
    let shown = robot(&view, "tb_0");
    assert_eq!(shown["state"], "running");
    assert_eq!(shown["team"], "Guards");
    assert_eq!(shown["isLeader"], true);
    assert_eq!(
        shown["services"],
        json!([
            {"plan": "Action", "service": "Patrol", "line": 40},
            {"plan": "Report", "service": "ToBase", "line": 55},
            {"plan": "Listen", "service": "Hear", "line": 64},
        ])
    );
    // Where the mission writes them (examples/swarm/patrol_groups.mission).
    assert_eq!(shown["modeLine"], 84);
    assert_eq!(state(&view, "tb_1"), "waiting");

    // Killed: the broker publishes its last will.
    tb_0.kill();
    let view = view_where(&mut client, |p| p["robots"][1]["state"] == "lost").await;
    assert_eq!(robot(&view, "tb_0")["lostBecause"], "lastWill", "{view}");

    // Alive and heart-beating, then silent (a hung robot keeps its
    // connection, so no last will): lost after three heartbeat periods;
    // heard again, running again.
    let tb_1 = FakeRobot::connect(broker.port, "tb_1");
    tb_1.status("running", "PATROL", "tb_0", "Action=Patrol")
        .await;
    tb_1.heartbeat().await;
    let view = view_where(&mut client, |p| p["robots"][2]["state"] == "running").await;
    assert_eq!(robot(&view, "tb_1")["isLeader"], false);
    let view = view_where(&mut client, |p| p["robots"][2]["state"] == "lost").await;
    assert_eq!(robot(&view, "tb_1")["lostBecause"], "silent", "{view}");
    tb_1.heartbeat().await;
    view_where(&mut client, |p| p["robots"][2]["state"] == "running").await;

    // Stopping ends the session; closing the document ends a new one.
    let stopped = client
        .request("semo/monitor/stop", json!({ "uri": uri }))
        .await
        .unwrap();
    assert_eq!(stopped["stopped"], true);
    monitor_start(&mut client, &uri, &broker.url()).await;
    // Retained statuses come with the subscription: tb_1 is known at once.
    let view = view_where(&mut client, |p| p["robots"][2]["state"] == "running").await;
    assert_eq!(robot(&view, "tb_0")["lostBecause"], "lastWill");
    client
        .notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": uri } }),
        )
        .await;
    let stopped = client
        .request("semo/monitor/stop", json!({ "uri": uri }))
        .await
        .unwrap();
    assert_eq!(
        stopped["stopped"], false,
        "closing the mission ended its monitor"
    );
    tb_1.kill();
    client.shutdown().await;
}

/// Without a run asked for, the monitor shows the newest: the run whose
/// robots started last, whatever order the broker hands the statuses in;
/// asked for a run, it shows that one.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_monitor_shows_the_newest_run_or_the_one_asked_for() {
    let Some(binary) = mosquitto() else { return };
    let broker = Broker::start(&binary);
    let (dir, uri, text) = workspace();
    let mut client = TestClient::start();
    started(&mut client, dir.path(), &uri, &text).await;
    let answer = monitor_start(&mut client, &uri, &broker.url()).await;
    assert_eq!(answer["run"], Value::Null);
    let first = FakeRobot::connect_in(broker.port, "tb_0", "r1", 1000);
    first.status("running", "PATROL", "tb_0", "").await;
    let view = view_where(&mut client, |p| p["robots"][1]["state"] == "running").await;
    assert_eq!(view["run"], "r1");
    // A newer run: the picture starts over with it.
    let second = FakeRobot::connect_in(broker.port, "tb_1", "r2", 2000);
    second.status("running", "HIDE", "tb_1", "").await;
    let view = view_where(&mut client, |p| p["robots"][2]["state"] == "running").await;
    assert_eq!(view["run"], "r2");
    assert_eq!(state(&view, "tb_0"), "waiting", "{view}");
    // The older run's robots no longer count (tb_2's status of run r1 comes
    // before tb_1's new mode: one connection).
    second
        .status_of("tb_2", "r1", 1000, ["running", "PATROL", "tb_0", ""])
        .await;
    second.status("running", "PATROL", "tb_1", "").await;
    let view = view_where(&mut client, |p| p["robots"][2]["mode"] == "PATROL").await;
    assert_eq!(state(&view, "tb_2"), "waiting", "{view}");
    client
        .request("semo/monitor/stop", json!({ "uri": uri }))
        .await
        .unwrap();
    // Asked for the older run: its retained statuses only.
    let answer = client
        .request(
            "semo/monitor/start",
            json!({ "uri": uri, "broker": broker.url(), "run": "r1" }),
        )
        .await
        .expect("the monitor starts");
    assert_eq!(answer["run"], "r1");
    let view = view_where(&mut client, |p| {
        p["robots"][1]["state"] == "running" && p["robots"][3]["state"] == "running"
    })
    .await;
    assert_eq!(view["run"], "r1");
    assert_eq!(state(&view, "tb_1"), "waiting", "{view}");
    // A run id that is not one topic level is refused.
    for bad in ["a/b", "#", "+"] {
        let refused = client
            .request(
                "semo/monitor/start",
                json!({ "uri": uri, "broker": broker.url(), "run": bad }),
            )
            .await
            .expect_err("refused");
        assert!(
            refused["message"]
                .as_str()
                .is_some_and(|m| m.contains("cannot monitor: a run id is")),
            "{refused}"
        );
    }
    for robot in [first, second] {
        robot.kill();
    }
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unreachable_broker_is_shown_and_bad_requests_are_refused() {
    let (dir, uri, text) = workspace();
    let mut client = TestClient::start();
    started(&mut client, dir.path(), &uri, &text).await;
    // Nobody listens on this port: the robots stay waiting, the connection
    // is shown down with the reason.
    let url = format!("mqtt://127.0.0.1:{}", free_port());
    client
        .request("semo/monitor/start", json!({ "uri": uri, "broker": url }))
        .await
        .expect("the monitor starts");
    let view = view_where(&mut client, |p| p["connection"] == "disconnected").await;
    assert!(
        view["error"].as_str().is_some_and(|e| !e.is_empty()),
        "{view}"
    );
    assert_eq!(state(&view, "ev_1"), "waiting");
    client
        .request("semo/monitor/stop", json!({ "uri": uri }))
        .await
        .unwrap();

    let refused = |answer: Result<Value, Value>| {
        answer.expect_err("refused")["message"]
            .as_str()
            .unwrap_or("")
            .to_string()
    };
    let tls = client
        .request(
            "semo/monitor/start",
            json!({ "uri": uri, "broker": "mqtts://127.0.0.1:8883" }),
        )
        .await;
    // A TLS broker without a deployment file: no CA to check it with.
    assert!(refused(tls).contains("is a TLS broker"));
    let elsewhere = client
        .request(
            "semo/monitor/start",
            json!({ "uri": "file:///nowhere/x.mission" }),
        )
        .await;
    assert!(refused(elsewhere).contains("not a mission the server knows"));
    // A mission with errors has no robots to show.
    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": uri, "version": 2 },
                "contentChanges": [{ "text": "{\n  Base: NoSuchRobot base\n}\n" }],
            }),
        )
        .await;
    let broken = client
        .request("semo/monitor/start", json!({ "uri": uri }))
        .await;
    assert!(refused(broken).contains("cannot monitor"));
    client.shutdown().await;
}
