//! The MQTT topics of a mission, as `semo_mqtt.c` names them: the broker's
//! ACL (`broker.rs`) must allow exactly what the robots use, so this mirrors
//! the C functions `mission_name`, `append_level` and `topic_of`.
//!
//! A message's topic names its receiver and its sender:
//! `semo/<mission>/<team>/<key>/<from team>/<from robot>` to every robot of
//! a team, `semo/<mission>/<team>/<robot>/<key>/<from team>/<from robot>` to
//! one robot (six and seven levels, so a team's subscription never matches a
//! robot's topic). The ACL lets each user write only topics whose sender
//! levels are its own robots' (the operator's: [`OPERATOR`]), and every
//! receiver refuses a message whose datagram names another sender or key
//! than its topic ([`carries`]): who sent a message is what the broker
//! vouched for, never what the payload says (`docs/security.md`).

use super::datagram::Datagram;

/// Who sends a message: a robot, or the operator ([`OPERATOR`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sender<'a> {
    pub team: &'a str,
    pub robot: &'a str,
}

/// The operator console (`semo operator`), the one sender of `USER`
/// commands: team `USER`, which no mission may declare.
pub const OPERATOR: Sender<'static> = Sender {
    team: "USER",
    robot: "operator",
};

impl<'a> Sender<'a> {
    /// The robot of `program`.
    pub fn of(program: &'a crate::refine::RobotProgram) -> Sender<'a> {
        Sender {
            team: &program.team,
            robot: &program.robot,
        }
    }

    /// The sender a datagram claims to be.
    pub fn claimed_by(datagram: &'a Datagram) -> Sender<'a> {
        Sender {
            team: &datagram.team,
            robot: &datagram.robot,
        }
    }

    /// `/<from team>/<from robot>`.
    fn levels(self) -> String {
        format!("/{}/{}", level(self.team), level(self.robot))
    }
}

/// The mission's name in topics: the file name without `.mission`, at most
/// 63 bytes (the runtime's buffer), cut between characters.
pub fn mission(file_name: &str) -> String {
    let name = if file_name.is_empty() {
        "mission"
    } else {
        file_name
    };
    let mut end = name.len().min(63);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    let name = &name[..end];
    // As C's `strstr`: the first `.mission`, cut only where it ends the name.
    match name.find(".mission") {
        Some(at) if at > 0 && at + 8 == name.len() => name[..at].to_string(),
        _ => name.to_string(),
    }
}

/// One topic level: the characters MQTT gives a meaning to become `_`.
pub fn level(name: &str) -> String {
    name.replace(['/', '+', '#'], "_")
}

/// `semo/<mission>/<team>`: where everything to `team` starts.
fn team_prefix(mission: &str, team: &str) -> String {
    format!("semo/{}/{}", level(mission), level(team))
}

/// `semo/<mission>/<team>/<key>/<from team>/<from robot>`: a message from
/// `from` to every robot of `team` (`USER`: to every operator console).
pub fn to_team(mission: &str, team: &str, key: &str, from: Sender) -> String {
    format!(
        "{}/{}{}",
        team_prefix(mission, team),
        level(key),
        from.levels()
    )
}

/// `semo/<mission>/<team>/<robot>/<key>/<from team>/<from robot>`: a
/// message from `from` to one robot.
pub fn to_robot(mission: &str, team: &str, robot: &str, key: &str, from: Sender) -> String {
    format!(
        "{}/{}/{}{}",
        team_prefix(mission, team),
        level(robot),
        level(key),
        from.levels()
    )
}

/// `semo/<mission>/<team>/+/+/+`: every message to `team`, what a robot of
/// it subscribes to (and the operator consoles, `team` `USER`).
pub fn team_inbox(mission: &str, team: &str) -> String {
    format!("{}/+/+/+", team_prefix(mission, team))
}

/// `semo/<mission>/<team>/<robot>/+/+/+`: every message to one robot.
pub fn robot_inbox(mission: &str, team: &str, robot: &str) -> String {
    format!("{}/{}/+/+/+", team_prefix(mission, team), level(robot))
}

/// `semo/<mission>/status/<robot>`: the robot's retained status (four
/// levels: no message topic).
pub fn status(mission: &str, robot: &str) -> String {
    format!("semo/{}/status/{}", level(mission), level(robot))
}

/// `semo/<mission>/status/+`: every robot's status.
pub fn statuses(mission: &str) -> String {
    format!("semo/{}/status/+", level(mission))
}

/// Where the robot of `program` publishes its heartbeats for leader
/// elections (when `program.control.heartbeat`): its team's topic of
/// `<team>.__alive` from itself.
pub fn heartbeat(program: &crate::refine::RobotProgram) -> String {
    to_team(
        &mission(&program.mission),
        &program.team,
        &crate::codegen::files::alive_key(program),
        Sender::of(program),
    )
}

/// Whether a message to team `to` came on `topic` from the sender and with
/// the key its datagram names: a receiver takes nothing else, since the
/// broker vouches only for the topic (`semo_mqtt.c`'s `sent_on_its_topic`).
pub fn carries(topic: &str, mission: &str, to: &str, datagram: &Datagram) -> bool {
    topic == to_team(mission, to, &datagram.key, Sender::claimed_by(datagram))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TI: Sender = Sender {
        team: "SlaveTeam",
        robot: "ti",
    };

    #[test]
    fn names_become_levels_as_the_runtime_makes_them() {
        assert_eq!(mission("scouting.mission"), "scouting");
        assert_eq!(mission(".mission"), ".mission");
        assert_eq!(mission(""), "mission");
        assert_eq!(
            to_team("a+b.mission", "T#", "K/x", TI),
            "semo/a_b.mission/T_/K_x/SlaveTeam/ti"
        );
        assert_eq!(
            to_robot("m", "MasterTeam", "irobot", "SlaveTeam.COLOR", TI),
            "semo/m/MasterTeam/irobot/SlaveTeam.COLOR/SlaveTeam/ti"
        );
        assert_eq!(
            to_team("m", "MasterTeam", "USER.RC_CMD", OPERATOR),
            "semo/m/MasterTeam/USER.RC_CMD/USER/operator"
        );
        assert_eq!(team_inbox("m", "USER"), "semo/m/USER/+/+/+");
        assert_eq!(robot_inbox("m", "T", "r"), "semo/m/T/r/+/+/+");
        assert_eq!(mission(&"x".repeat(80)).len(), 63);
        assert_eq!(mission(&"é".repeat(40)), "é".repeat(31));
    }

    /// A team's subscription matches its messages and never a robot's
    /// (nor a status), whatever the names: the levels are counted.
    #[test]
    fn a_subscription_matches_exactly_its_level() {
        let matches = |filter: &str, topic: &str| {
            let (f, t): (Vec<&str>, Vec<&str>) =
                (filter.split('/').collect(), topic.split('/').collect());
            f.len() == t.len() && f.iter().zip(&t).all(|(f, t)| *f == "+" || f == t)
        };
        let team = team_inbox("m", "T");
        let robot = robot_inbox("m", "T", "r");
        assert!(matches(&team, &to_team("m", "T", "T.X", TI)));
        assert!(!matches(&team, &to_robot("m", "T", "r", "T.X", TI)));
        assert!(matches(&robot, &to_robot("m", "T", "r", "T.X", TI)));
        assert!(!matches(&robot, &to_team("m", "T", "T.X", TI)));
        assert!(!matches(&team, &status("m", "r")));
        assert!(!matches(&team_inbox("m", "status"), &status("m", "r")));
    }

    #[test]
    fn a_message_is_taken_only_on_its_senders_topic() {
        let forged = Datagram {
            publish: false,
            team: OPERATOR.team.into(),
            robot: OPERATOR.robot.into(),
            key: "USER.RC_CMD".into(),
            value: None,
        };
        let own = to_team("m", "MasterTeam", "USER.RC_CMD", OPERATOR);
        assert!(carries(&own, "m", "MasterTeam", &forged));
        // The slaves' user may write this topic; the datagram says USER.
        let slaves = to_team("m", "MasterTeam", "SlaveTeam.COLOR", TI);
        assert!(!carries(&slaves, "m", "MasterTeam", &forged));
        // The right sender with another key than the topic's.
        let colour = Datagram {
            team: TI.team.into(),
            robot: TI.robot.into(),
            ..forged.clone()
        };
        assert!(!carries(&slaves, "m", "MasterTeam", &colour));
        assert!(!carries(&own, "m", "SlaveTeam", &forged));
    }
}
