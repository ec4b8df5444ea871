//! What a running mission says on its MQTT broker, read by the two live
//! doors: `semo operator` (the console) and the editor's robot monitor
//! (`crate::monitor`). One decoding of the robots' retained status
//! (`docs/deployment.md`, "Status"; written by `semo_runtime.c`'s
//! `observe_status` and `semo_mqtt.c`'s last will) and of the runtime's
//! datagram (`semo_core.c`'s `semo__encode_message`, through
//! `semo::deploy::datagram`), so that both read the
//! same thing the same way. Which run both show ([`RunChoice`]: the one
//! given, else the newest). And how both reach the broker (`connect`:
//! `mqtt://` or `mqtts://`, the deployment's operator).

mod connect;

pub use connect::{BrokerAccess, Failure};
use semo::deploy::topics::{self, RunId, Scope};

/// A robot's status message on `semo/<mission>/<run>/status/<robot>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    pub robot: String,
    /// `running`, `finished`, `stopped`, or `lost` (the broker's last will).
    pub state: String,
    /// Empty in the last will, which knows nothing but the robot.
    pub mode: String,
    /// The leader the robot follows (empty without a leader election).
    pub leader: String,
    /// The service each plan runs, in the robot's order: `(plan, service)`.
    pub services: Vec<(String, String)>,
    /// The robot's group at each statement of counted groups
    /// (`group(Name, min = N)`) it passed since its mode started, in the
    /// statements' order: `(group, alive)`, the group (`others` for a
    /// spare) and how many members it counted alive when it took it. Empty
    /// for a board robot, which does not say its groups.
    pub groups: Vec<(String, u32)>,
    /// The battery level, when the runtime reports one.
    pub battery: Option<f64>,
    /// The robot's mission time of the change (ms), when given.
    pub t: Option<i64>,
    /// The wall-clock instant of the robot's mission time 0 (Unix ms),
    /// when given: which run is the newest.
    pub started: Option<i64>,
}

impl Status {
    /// Reads a status payload; `robot` is the topic's last level, used
    /// when the payload does not name the robot. `None` for anything that
    /// is not a JSON object, and for a status naming another robot than its
    /// topic: only the robot's user may write its topic, so the topic says
    /// whose status it is, never the payload.
    pub fn decode(robot: &str, payload: &[u8]) -> Option<Status> {
        let value: serde_json::Value = serde_json::from_slice(payload).ok()?;
        let object = value.as_object()?;
        let text = |key: &str| {
            object
                .get(key)
                .and_then(serde_json::Value::as_str)
                .unwrap_or("")
                .to_string()
        };
        let services = text("services")
            .split(',')
            .filter_map(|pair| {
                let (plan, service) = pair.split_once('=')?;
                Some((plan.to_string(), service.to_string()))
            })
            .collect();
        // Entries that are not `group=count` are skipped: a status is
        // shown as well as it can be read.
        let groups = text("groups")
            .split(',')
            .filter_map(|pair| {
                let (group, alive) = pair.split_once('=')?;
                let alive = alive.parse().ok()?;
                (!group.is_empty()).then(|| (group.to_string(), alive))
            })
            .collect();
        let named = text("robot");
        if !named.is_empty() && topics::level(&named) != robot {
            return None;
        }
        Some(Status {
            robot: if named.is_empty() {
                robot.to_string()
            } else {
                named
            },
            state: text("state"),
            mode: text("mode"),
            leader: text("leader"),
            services,
            groups,
            // The runtime writes trace fields as text (`"battery":"87"`).
            battery: object.get("battery").and_then(|v| {
                v.as_f64()
                    .or_else(|| v.as_str().and_then(|s| s.parse().ok()))
            }),
            t: object.get("t").and_then(serde_json::Value::as_i64),
            started: object.get("started").and_then(|v| {
                v.as_i64()
                    .or_else(|| v.as_str().and_then(|s| s.parse().ok()))
            }),
        })
    }

    /// `plan=service,…` as the runtime writes it.
    pub fn services_text(&self) -> String {
        self.services
            .iter()
            .map(|(plan, service)| format!("{plan}={service}"))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// `group (N alive), group (M alive)`, in the statements' order; empty without
    /// counted groups.
    pub fn groups_text(&self) -> String {
        self.groups
            .iter()
            .map(|(group, alive)| format!("{group} ({alive} alive)"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Which run of a mission a console shows: the one it was given, else the
/// newest it has heard of, the run of the status with the latest `started`
/// (its robots' mission time 0 came last; a status without one counts
/// oldest). The broker hands the retained statuses of every run in no
/// order of time, so arrival cannot say which run is the newest.
#[derive(Clone, Debug)]
pub struct RunChoice {
    given: bool,
    /// The run shown, and the latest `started` heard of it.
    shown: Option<(RunId, i64)>,
}

impl RunChoice {
    /// `Some(run)`: that run only; `None`: the newest.
    pub fn new(given: Option<RunId>) -> RunChoice {
        RunChoice {
            given: given.is_some(),
            shown: given.map(|run| (run, i64::MIN)),
        }
    }

    /// The run shown; None until a status of a run is heard.
    pub fn run(&self) -> Option<&RunId> {
        self.shown.as_ref().map(|(run, _)| run)
    }

    /// Where to subscribe: the given run's topics, else every run's.
    pub fn scope(&self, mission: &str) -> Scope {
        match (&self.shown, self.given) {
            (Some((run, _)), true) => Scope::run(mission, run),
            _ => Scope::every_run(mission),
        }
    }

    /// A status of `run` whose robot started at `started`: whether the
    /// run shown changed (to this newer one).
    pub fn heard(&mut self, run: &RunId, started: Option<i64>) -> bool {
        let started = started.unwrap_or(i64::MIN);
        match &mut self.shown {
            Some((shown, latest)) if shown == run => {
                *latest = (*latest).max(started);
                false
            }
            Some((_, latest)) if self.given || started <= *latest => false,
            _ => {
                self.shown = Some((run.clone(), started));
                true
            }
        }
    }
}

/// The run and robot of a status topic of mission `mission` (its topic
/// name), `semo/<mission>/<run>/status/<robot>`; None for any other topic.
pub fn status_topic(mission: &str, topic: &str) -> Option<(RunId, String)> {
    let run = topics::run_of(mission, topic)?;
    let statuses = topics::statuses(&Scope::run(mission, &run));
    let robot = topic.strip_prefix(statuses.trim_end_matches('+'))?;
    (!robot.is_empty() && !robot.contains('/')).then(|| (run, robot.to_string()))
}

/// The broker a robot uses when nothing says otherwise.
pub const DEFAULT_BROKER: &str = "mqtt://127.0.0.1:1883";

/// A `send` from the operator as the runtime's datagram
/// (`semo::deploy::datagram`, the bytes `semo_core.c` reads): from
/// `topics::OPERATOR` (team `USER`, robot `operator`), the value as text
/// (the robot reads it as the type its mission declares for the key).
pub fn operator_datagram(key: &str, value: &str) -> Vec<u8> {
    let operator = semo::deploy::topics::OPERATOR;
    semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
        publish: false,
        team: operator.team.into(),
        robot: operator.robot.into(),
        key: key.into(),
        value: Some(semo::refine::Value::text(value)),
    })
}

/// The fields of a runtime datagram to team `to` of the run `scope` that
/// came on `topic`: (team, robot, key, value), the value as text (`(none)`
/// for a value never set). `None` for anything else, and for a datagram
/// whose sender or key is not its topic's (`topics::carries`): the broker
/// vouches for the topic only.
pub fn datagram_fields(topic: &str, scope: &Scope, to: &str, data: &[u8]) -> Option<[String; 4]> {
    let d = semo::deploy::datagram::decode(data)?;
    if !topics::carries(topic, scope, to, &d) {
        return None;
    }
    let value = d.value.map_or_else(|| "(none)".into(), |v| v.as_text());
    Some([d.team, d.robot, d.key, value])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_status_reads_as_the_runtime_writes_it() {
        let payload = br#"{"t":5230,"robot":"irobot","event":"status","state":"running","mode":"WAIT_MODE","leader":"","services":"Listen=ReportStatus,Action=Wait"}"#;
        let status = Status::decode("irobot", payload).unwrap();
        assert_eq!(status.state, "running");
        assert_eq!(status.mode, "WAIT_MODE");
        assert_eq!(
            status.services,
            [
                ("Listen".to_string(), "ReportStatus".to_string()),
                ("Action".to_string(), "Wait".to_string())
            ]
        );
        assert_eq!(status.services_text(), "Listen=ReportStatus,Action=Wait");
        assert_eq!((status.t, status.battery), (Some(5230), None));
        assert_eq!(status.started, None);
        assert_eq!(
            Status::decode("r", br#"{"state":"lost","started":"1700000000123"}"#)
                .map(|s| s.started),
            Some(Some(1_700_000_000_123))
        );
        // The last will names only the robot and the state.
        let will = Status::decode(
            "irobot",
            br#"{"robot":"irobot","event":"status","state":"lost"}"#,
        )
        .unwrap();
        assert_eq!(
            (will.robot.as_str(), will.state.as_str()),
            ("irobot", "lost")
        );
        assert!(will.services.is_empty() && will.mode.is_empty());
        assert_eq!(
            Status::decode("r", br#"{"state":"running","battery":42.5}"#)
                .map(|s| (s.robot, s.battery)),
            Some(("r".to_string(), Some(42.5)))
        );
        assert_eq!(
            Status::decode("r", br#"{"state":"running","battery":"87"}"#).map(|s| s.battery),
            Some(Some(87.0))
        );
        assert_eq!(
            Status::decode("r", br#"{"state":"running","battery":"none"}"#).map(|s| s.battery),
            Some(None)
        );
        assert_eq!(Status::decode("r", b"[1]"), None);
        // Another robot's status on r's topic is nobody's.
        assert_eq!(
            Status::decode("r", br#"{"robot":"s","state":"running"}"#),
            None
        );
        assert_eq!(Status::decode("r", b"\xff"), None);
    }

    #[test]
    fn a_status_says_the_robots_counted_groups() {
        let payload = br#"{"t":2000,"robot":"tb_2","event":"status","state":"running","mode":"ROOMS","leader":"","services":"Work=Rooms","groups":"Room1=5,others=3"}"#;
        let status = Status::decode("tb_2", payload).unwrap();
        assert_eq!(
            status.groups,
            [("Room1".to_string(), 5), ("others".to_string(), 3)]
        );
        assert_eq!(status.groups_text(), "Room1 (5 alive), others (3 alive)");
        // Without the field (no counted groups, a board, the last will): none.
        let none = Status::decode("r", br#"{"state":"running","mode":"M"}"#).unwrap();
        assert!(none.groups.is_empty() && none.groups_text().is_empty());
        // What cannot be read is skipped, never a panic.
        for (groups, read) in [
            (r#""Room1""#, vec![]),
            (r#""=3,Room2=x,Room3=-1,Room4=99999999999""#, vec![]),
            (
                r#""Room1=2,,junk,Room2=1=1,Room3=1""#,
                vec![("Room1", 2), ("Room3", 1)],
            ),
            (r#""""#, vec![]),
            ("7", vec![]),
            ("null", vec![]),
            (r#"["Room1=2"]"#, vec![]),
            (r#""Räum=2""#, vec![("Räum", 2)]),
        ] {
            let payload = format!(r#"{{"state":"running","groups":{groups}}}"#);
            let status = Status::decode("r", payload.as_bytes()).unwrap();
            let read: Vec<(String, u32)> = read.iter().map(|(g, a)| (g.to_string(), *a)).collect();
            assert_eq!(status.groups, read, "{groups}");
        }
    }

    fn run(id: &str) -> RunId {
        RunId::parse(id).unwrap()
    }

    #[test]
    fn the_newest_run_is_the_one_whose_robots_started_last() {
        let mut choice = RunChoice::new(None);
        assert_eq!(choice.run(), None);
        assert_eq!(choice.scope("m").as_str(), "semo/m/+");
        assert!(choice.heard(&run("b"), Some(200)));
        // An older run's status, whenever it comes, does not take over.
        assert!(!choice.heard(&run("a"), Some(100)));
        assert!(!choice.heard(&run("a"), None));
        assert!(!choice.heard(&run("b"), Some(150)));
        assert_eq!(choice.run(), Some(&run("b")));
        assert!(choice.heard(&run("c"), Some(300)));
        assert_eq!(choice.run(), Some(&run("c")));
        assert_eq!(choice.scope("m").as_str(), "semo/m/+");
        // A run given is the only one shown.
        let mut given = RunChoice::new(Some(run("a")));
        assert!(!given.heard(&run("c"), Some(300)));
        assert_eq!(given.run(), Some(&run("a")));
        assert_eq!(given.scope("m").as_str(), "semo/m/a");
    }

    #[test]
    fn a_status_topic_says_its_run_and_robot() {
        assert_eq!(
            status_topic("m", "semo/m/r1/status/irobot"),
            Some((run("r1"), "irobot".into()))
        );
        for other in [
            "semo/m/r1/status/",
            "semo/m/r1/status/a/b",
            "semo/m/r1/T/status/a",
            "semo/n/r1/status/a",
            "semo/m/+/status/a",
        ] {
            assert_eq!(status_topic("m", other), None, "{other}");
        }
    }

    #[test]
    fn a_command_is_the_runtimes_datagram_and_reads_back_on_its_topic_only() {
        use semo::deploy::topics::OPERATOR;
        let d = operator_datagram("USER.RC_CMD", "RETURN_MODE");
        let m = Scope::run("m", &run("r1"));
        let topic = topics::to_team(&m, "MasterTeam", "USER.RC_CMD", OPERATOR);
        assert_eq!(
            datagram_fields(&topic, &m, "MasterTeam", &d),
            Some([
                "USER".into(),
                "operator".into(),
                "USER.RC_CMD".into(),
                "RETURN_MODE".into()
            ])
        );
        assert_eq!(
            datagram_fields(&topic, &m, "MasterTeam", &d[..d.len() - 1]),
            None
        );
        // The same command read as another run's.
        let other = Scope::run("m", &run("r2"));
        assert_eq!(datagram_fields(&topic, &other, "MasterTeam", &d), None);
        // The same datagram on a topic another user may write.
        let slaves = topics::Sender {
            team: "SlaveTeam",
            robot: "ti",
        };
        let elsewhere = topics::to_team(&m, "MasterTeam", "SlaveTeam.COLOR", slaves);
        assert_eq!(datagram_fields(&elsewhere, &m, "MasterTeam", &d), None);
    }
}
