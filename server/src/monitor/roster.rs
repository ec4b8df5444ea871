//! The monitor's picture of a mission's robots in one run, from what the
//! broker delivers: every robot of the checked mission, `waiting` until
//! its first status, then its state, mode, services, counted groups and leader, and `lost`
//! when its last will arrives or when it stops heart-beating. The run is
//! the one given, else the newest heard of (`live::RunChoice`): a newer
//! run's status starts the picture over. Pure: the time is the monitor's
//! clock in ms, passed in, so the rules are tested without one.

use crate::live::{RunChoice, Status};
use semo::deploy::topics::{self, Scope};
use serde_json::{Value, json};

/// A robot of the mission, as refinement made it.
#[derive(Clone, Debug)]
pub struct Member {
    pub robot: String,
    pub team: String,
    /// Whether it publishes heartbeats (its team elects a leader), with
    /// this key (`semo::refine::protocol::alive_key`) on its own topic
    /// (`topics::heartbeat`).
    pub heartbeat_key: Option<String>,
    /// Where its modes and services are written in the mission, so that an
    /// editor can mark the lines a running robot is at.
    pub lines: std::sync::Arc<MissionLines>,
}

/// The mission lines (1-based) of a team's modes and services.
#[derive(Clone, Debug, Default)]
pub struct MissionLines {
    pub modes: std::collections::HashMap<String, u32>,
    /// By (plan, service).
    pub services: std::collections::HashMap<(String, String), u32>,
}

impl Member {
    /// Its heartbeats' topic in `scope`.
    fn heartbeat_topic(&self, scope: &Scope) -> Option<String> {
        let me = topics::Sender {
            team: &self.team,
            robot: &self.robot,
        };
        let key = self.heartbeat_key.as_ref()?;
        Some(topics::to_team(scope, &self.team, key, me))
    }
}

struct Robot {
    member: Member,
    status: Option<Status>,
    /// When the robot was last heard from (a heartbeat or a status), once
    /// a heartbeat has been heard: only then can its silence be told.
    heard_at: Option<i64>,
    silent: bool,
}

pub struct Roster {
    /// The mission's topic name.
    mission: String,
    run: RunChoice,
    robots: Vec<Robot>,
    silent_after_ms: i64,
}

impl Roster {
    /// `mission` is the mission's topic name (`topics::mission`); `run`
    /// the run to show; `heartbeat_ms` the runtime's heartbeat period.
    pub fn new(mission: &str, members: Vec<Member>, heartbeat_ms: i64, run: RunChoice) -> Roster {
        Roster {
            mission: mission.to_string(),
            run,
            robots: members.into_iter().map(Robot::waiting).collect(),
            // A robot that heart-beats is lost by the robots' own rule
            // (elections, groups, owners): silent for longer than this.
            silent_after_ms: semo::refine::protocol::lost_after_ms(heartbeat_ms),
        }
    }

    /// The run shown, once known.
    pub fn run(&self) -> Option<&topics::RunId> {
        self.run.run()
    }

    /// The topics to subscribe to: every status, and the heartbeats of the
    /// robots whose teams elect a leader, of the run given, else of every
    /// run (the newest may change).
    pub fn topics(&self) -> Vec<String> {
        let scope = self.run.scope(&self.mission);
        let mut topics = vec![topics::statuses(&scope)];
        for robot in &self.robots {
            if let Some(topic) = robot.member.heartbeat_topic(&scope) {
                if !topics.contains(&topic) {
                    topics.push(topic);
                }
            }
        }
        topics
    }

    /// A message from the broker at time `now`; messages of another run
    /// than the one shown, of robots that are not in the mission, anything
    /// unreadable, and a payload naming another robot or key than its
    /// topic (the broker vouches only for the topic) are ignored. A status
    /// of a newer run (when none is given) starts the picture over.
    pub fn message(&mut self, topic: &str, payload: &[u8], now: i64) {
        if let Some((run, level)) = crate::live::status_topic(&self.mission, topic) {
            let Some(status) = Status::decode(&level, payload) else {
                return;
            };
            if self.run.heard(&run, status.started) {
                for robot in &mut self.robots {
                    *robot = Robot::waiting(robot.member.clone());
                }
            }
            if self.run.run() != Some(&run) {
                return;
            }
            if let Some(robot) = self
                .robots
                .iter_mut()
                .find(|r| topics::level(&r.member.robot) == level)
            {
                robot.status = Some(status);
                robot.heard(now);
            }
            return;
        }
        let Some(run) = self.run.run() else {
            return;
        };
        let scope = Scope::run(&self.mission, run);
        let Some(robot) = self
            .robots
            .iter_mut()
            .find(|r| r.member.heartbeat_topic(&scope).as_deref() == Some(topic))
        else {
            return;
        };
        if crate::live::datagram_fields(topic, &scope, &robot.member.team, payload).is_some() {
            robot.heard_at = Some(now);
            robot.silent = false;
        }
    }

    /// Marks the running robots that heart-beat and have been silent for
    /// too long at `now`.
    pub fn tick(&mut self, now: i64) {
        for robot in &mut self.robots {
            let running = robot.status.as_ref().is_some_and(|s| s.state == "running");
            if let Some(at) = robot.heard_at {
                if running && now - at > self.silent_after_ms {
                    robot.silent = true;
                }
            }
        }
    }

    /// The robots as the `semo/monitor` notification shows them
    /// (`docs/live-monitor.md`).
    pub fn view(&self) -> Value {
        Value::Array(self.robots.iter().map(Robot::view).collect())
    }
}

impl Robot {
    fn waiting(member: Member) -> Robot {
        Robot {
            member,
            status: None,
            heard_at: None,
            silent: false,
        }
    }

    fn heard(&mut self, now: i64) {
        if self.heard_at.is_some() {
            self.heard_at = Some(now);
        }
        self.silent = false;
    }

    fn view(&self) -> Value {
        let Some(status) = &self.status else {
            return json!({
                "robot": self.member.robot,
                "team": self.member.team,
                "state": "waiting",
                "lost": false,
                "mode": null,
                "modeLine": null,
                "services": [],
                "groups": [],
                "leader": null,
                "isLeader": false,
                "battery": null,
            });
        };
        let will = status.state == "lost";
        let lost_because = if will {
            Some("lastWill")
        } else if self.silent {
            Some("silent")
        } else {
            None
        };
        let lines = &self.member.lines;
        let services: Vec<Value> = status
            .services
            .iter()
            .map(|(plan, service)| {
                let line = lines.services.get(&(plan.clone(), service.clone()));
                json!({ "plan": plan, "service": service, "line": line })
            })
            .collect();
        let groups: Vec<Value> = status
            .groups
            .iter()
            .map(|(group, alive)| json!({ "group": group, "alive": alive }))
            .collect();
        let mut view = json!({
            "robot": self.member.robot,
            "team": self.member.team,
            "state": if lost_because.is_some() { "lost" } else { status.state.as_str() },
            "lost": lost_because.is_some(),
            "mode": (!status.mode.is_empty()).then_some(&status.mode),
            "modeLine": lines.modes.get(&status.mode),
            "services": services,
            "groups": groups,
            "leader": (!status.leader.is_empty()).then_some(&status.leader),
            "isLeader": status.leader == self.member.robot,
            "battery": status.battery,
        });
        if let Some(why) = lost_because {
            view["lostBecause"] = json!(why);
        }
        view
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alive(robot: &str) -> String {
        format!("semo/m/r1/Team/Team.__alive/Team/{robot}")
    }

    fn roster() -> Roster {
        roster_of(None)
    }

    /// Team's mode M at line 7, its service P.S at line 3.
    fn team_lines() -> std::sync::Arc<MissionLines> {
        std::sync::Arc::new(MissionLines {
            modes: [("M".to_string(), 7)].into(),
            services: [(("P".to_string(), "S".to_string()), 3)].into(),
        })
    }

    fn roster_of(run: Option<&str>) -> Roster {
        let run = run.map(|r| topics::RunId::parse(r).unwrap());
        Roster::new(
            "m",
            vec![
                Member {
                    robot: "a".into(),
                    team: "Team".into(),
                    heartbeat_key: Some("Team.__alive".into()),
                    lines: team_lines(),
                },
                Member {
                    robot: "b".into(),
                    team: "Team".into(),
                    heartbeat_key: Some("Team.__alive".into()),
                    lines: team_lines(),
                },
                Member {
                    robot: "c".into(),
                    team: "Solo".into(),
                    heartbeat_key: None,
                    lines: Default::default(),
                },
            ],
            200,
            RunChoice::new(run),
        )
    }

    fn states(roster: &Roster) -> Vec<String> {
        roster
            .view()
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                format!(
                    "{}={}",
                    r["robot"].as_str().unwrap(),
                    r["state"].as_str().unwrap()
                )
            })
            .collect()
    }

    fn heartbeat(robot: &str) -> Vec<u8> {
        semo::deploy::datagram::encode(&semo::deploy::datagram::Datagram {
            publish: true,
            team: "Team".into(),
            robot: robot.into(),
            key: "Team.__alive".into(),
            value: Some(semo::refine::Value::text(robot)),
        })
    }

    const RUNNING_A: &[u8] = br#"{"t":1,"robot":"a","event":"status","state":"running","started":"1000","mode":"M","leader":"a","services":"P=S"}"#;

    #[test]
    fn every_robot_waits_until_its_status_comes() {
        let mut r = roster();
        assert_eq!(
            r.topics(),
            [
                "semo/m/+/status/+",
                "semo/m/+/Team/Team.__alive/Team/a",
                "semo/m/+/Team/Team.__alive/Team/b"
            ]
        );
        assert_eq!(states(&r), ["a=waiting", "b=waiting", "c=waiting"]);
        r.message("semo/m/r1/status/a", RUNNING_A, 0);
        r.message("semo/m/r1/status/stranger", RUNNING_A, 0);
        assert_eq!(states(&r), ["a=running", "b=waiting", "c=waiting"]);
        let a = &r.view()[0];
        assert_eq!(a["mode"], "M");
        assert_eq!(a["isLeader"], true);
        assert_eq!(
            a["services"],
            json!([{ "plan": "P", "service": "S", "line": 3 }])
        );
        // The lines an editor marks: the mode's and each service's.
        assert_eq!(a["modeLine"], 7);
        assert_eq!(r.view()[1]["modeLine"], Value::Null);
        // No counted groups: none, as for a robot still waiting.
        assert_eq!(
            (&a["groups"], &r.view()[1]["groups"]),
            (&json!([]), &json!([]))
        );
        r.message(
            "semo/m/r1/status/b",
            br#"{"robot":"b","state":"running","mode":"M","leader":"a","services":"P=S","groups":"Room1=4,Sweeper=2"}"#,
            1,
        );
        assert_eq!(
            r.view()[1]["groups"],
            json!([{ "group": "Room1", "alive": 4 }, { "group": "Sweeper", "alive": 2 }])
        );
    }

    #[test]
    fn the_last_will_makes_a_robot_lost() {
        let mut r = roster();
        r.message("semo/m/r1/status/c", RUNNING_A, 0);
        r.message(
            "semo/m/r1/status/c",
            br#"{"robot":"c","event":"status","state":"lost"}"#,
            5,
        );
        let c = &r.view()[2];
        assert_eq!(
            (c["state"].as_str(), c["lostBecause"].as_str()),
            (Some("lost"), Some("lastWill"))
        );
    }

    #[test]
    fn a_running_robot_silent_past_the_loss_rule_is_lost_until_heard_again() {
        let mut r = roster();
        let lost = semo::refine::protocol::lost_after_ms(200);
        r.message("semo/m/r1/status/a", RUNNING_A, 0);
        // Without any heartbeat heard its silence means nothing (a broker
        // whose ACL hides the heartbeats from the monitor).
        r.tick(10_000);
        assert_eq!(states(&r)[0], "a=running");
        r.message(&alive("a"), &heartbeat("a"), 10_000);
        r.tick(10_000 + lost);
        assert_eq!(states(&r)[0], "a=running");
        r.tick(10_000 + lost + 1);
        assert_eq!(states(&r)[0], "a=lost");
        assert_eq!(r.view()[0]["lostBecause"], "silent");
        r.message(&alive("a"), &heartbeat("a"), 10_700);
        assert_eq!(states(&r)[0], "a=running");
        // A stopped robot stops heart-beating: it is not lost.
        r.message(
            "semo/m/r1/status/a",
            br#"{"robot":"a","state":"stopped","mode":"M"}"#,
            10_800,
        );
        r.tick(20_000);
        assert_eq!(states(&r)[0], "a=stopped");
        // A heartbeat on another team's topic is not this robot's.
        r.message(
            "semo/m/r1/Other/Other.__alive/Team/b",
            &heartbeat("b"),
            20_000,
        );
        assert_eq!(r.robots[1].heard_at, None);
        // Nor is one on its topic that names another robot: whoever may
        // write a's topic cannot keep b alive.
        r.message(&alive("a"), &heartbeat("b"), 20_000);
        assert_eq!(r.robots[1].heard_at, None);
        assert_eq!(r.robots[0].heard_at, Some(10_800));
    }

    #[test]
    fn a_newer_run_starts_the_picture_over_and_an_older_one_is_ignored() {
        let mut r = roster();
        r.message("semo/m/r1/status/a", RUNNING_A, 0);
        r.message(&alive("a"), &heartbeat("a"), 0);
        assert_eq!(r.run().map(|r| r.as_str()), Some("r1"));
        let newer = br#"{"robot":"b","state":"running","started":"2000","mode":"N"}"#;
        r.message("semo/m/r2/status/b", newer, 10);
        assert_eq!(r.run().map(|r| r.as_str()), Some("r2"));
        assert_eq!(states(&r), ["a=waiting", "b=running", "c=waiting"]);
        assert_eq!(r.robots[0].heard_at, None);
        // The older run's status and heartbeats no longer count.
        r.message("semo/m/r1/status/c", RUNNING_A, 20);
        r.message(&alive("a"), &heartbeat("a"), 20);
        assert_eq!(states(&r), ["a=waiting", "b=running", "c=waiting"]);
        assert_eq!(r.robots[0].heard_at, None);
        // A topic whose run level no run can have is nobody's.
        r.message("semo/m/+/status/a", RUNNING_A, 30);
        assert_eq!(states(&r)[0], "a=waiting");
    }

    #[test]
    fn a_given_run_is_the_only_one_shown() {
        let mut r = roster_of(Some("r1"));
        assert_eq!(
            r.topics(),
            [
                "semo/m/r1/status/+",
                "semo/m/r1/Team/Team.__alive/Team/a",
                "semo/m/r1/Team/Team.__alive/Team/b"
            ]
        );
        let newer = br#"{"robot":"a","state":"running","started":"9000","mode":"N"}"#;
        r.message("semo/m/r2/status/a", newer, 0);
        assert_eq!(states(&r)[0], "a=waiting");
        r.message("semo/m/r1/status/a", RUNNING_A, 0);
        assert_eq!(states(&r)[0], "a=running");
    }
}
