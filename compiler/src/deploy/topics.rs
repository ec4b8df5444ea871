//! The MQTT topics of a mission, as `semo_mqtt.c` names them: the broker's
//! ACL (`broker.rs`) must allow exactly what the robots use, so this mirrors
//! the C functions `mission_name`, `valid_run`, `append_level` and
//! `topic_of`.
//!
//! Every topic of one run of a mission starts with its [`Scope`],
//! `semo/<mission>/<run>`: a run hears nothing of another, not even the
//! values an earlier one left retained on the broker. A message's topic
//! then names its receiver and its sender: `<scope>/<team>/<key>/<from
//! team>/<from robot>` to every robot of a team,
//! `<scope>/<team>/<robot>/<key>/<from team>/<from robot>` to one robot
//! (seven and eight levels, so a team's subscription never matches a
//! robot's topic). The ACL lets each user write only topics whose sender
//! levels are its own robots' (the operator's: [`OPERATOR`]), in any run
//! (`+` at the run's level: [`Scope::every_run`]), and every receiver
//! refuses a message whose datagram names another sender or key than its
//! topic ([`carries`]): who sent a message is what the broker vouched for,
//! never what the payload says (`docs/security.md`).

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

/// The id of one run of a mission (a robot program's `--run ID` or
/// `$SEMO_RUN`, else [`RunId::DEFAULT`]; `semo operator --run`): 1 to
/// [`RunId::MAX_LEN`] ASCII letters, digits, `-`, `_` and `.`, starting
/// with a letter or a digit. So it is one topic level as it is (never a
/// `/`, `+` or `#`) and a file name (never `.`, `..` nor an option). The
/// runtime's `valid_run`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RunId(String);

impl RunId {
    pub const MAX_LEN: usize = 63;
    /// The run of a robot program that is given none.
    pub const DEFAULT: &'static str = "default";

    /// `text` as a run id, or why it cannot be one.
    pub fn parse(text: &str) -> Result<RunId, String> {
        let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
        let fits = text.len() <= Self::MAX_LEN
            && text.starts_with(|c: char| c.is_ascii_alphanumeric())
            && text.chars().all(allowed);
        if fits {
            Ok(RunId(text.to_string()))
        } else {
            Err(format!(
                "a run id is 1 to {} letters, digits, `-`, `_` and `.`, starting with a letter or a digit, not {text:?}",
                Self::MAX_LEN
            ))
        }
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl Default for RunId {
    fn default() -> RunId {
        RunId(Self::DEFAULT.to_string())
    }
}

impl std::fmt::Display for RunId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Where the topics of one run of a mission start, `semo/<mission>/<run>`,
/// or of every run, `semo/<mission>/+` (the ACL, and the subscriptions of
/// the consoles that follow the newest run).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scope(String);

impl Scope {
    /// The run `run` of the mission whose topic name is `mission`
    /// ([`mission`]).
    pub fn run(mission: &str, run: &RunId) -> Scope {
        Scope(format!("semo/{}/{run}", level(mission)))
    }

    /// Every run of the mission whose topic name is `mission`.
    pub fn every_run(mission: &str) -> Scope {
        Scope(format!("semo/{}/+", level(mission)))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

/// The run of a topic of the mission whose topic name is `mission`: the
/// level after the mission's. None for a topic of another mission, and for
/// a level that no run can have.
pub fn run_of(mission: &str, topic: &str) -> Option<RunId> {
    let rest = topic
        .strip_prefix("semo/")?
        .strip_prefix(level(mission).as_str())?
        .strip_prefix('/')?;
    RunId::parse(rest.split('/').next()?).ok()
}

/// `<scope>/<team>`: where everything to `team` starts.
fn team_prefix(scope: &Scope, team: &str) -> String {
    format!("{}/{}", scope.0, level(team))
}

/// `<scope>/<team>/<key>/<from team>/<from robot>`: a message from `from`
/// to every robot of `team` (`USER`: to every operator console).
pub fn to_team(scope: &Scope, team: &str, key: &str, from: Sender) -> String {
    format!(
        "{}/{}{}",
        team_prefix(scope, team),
        level(key),
        from.levels()
    )
}

/// `<scope>/<team>/<robot>/<key>/<from team>/<from robot>`: a message from
/// `from` to one robot.
pub fn to_robot(scope: &Scope, team: &str, robot: &str, key: &str, from: Sender) -> String {
    format!(
        "{}/{}/{}{}",
        team_prefix(scope, team),
        level(robot),
        level(key),
        from.levels()
    )
}

/// `<scope>/<team>/+/+/+`: every message to `team`, what a robot of it
/// subscribes to (and the operator consoles, `team` `USER`).
pub fn team_inbox(scope: &Scope, team: &str) -> String {
    format!("{}/+/+/+", team_prefix(scope, team))
}

/// `<scope>/<team>/<robot>/+/+/+`: every message to one robot.
pub fn robot_inbox(scope: &Scope, team: &str, robot: &str) -> String {
    format!("{}/{}/+/+/+", team_prefix(scope, team), level(robot))
}

/// `<scope>/status/<robot>`: the robot's retained status (five levels: no
/// message topic).
pub fn status(scope: &Scope, robot: &str) -> String {
    format!("{}/status/{}", scope.0, level(robot))
}

/// `<scope>/status/+`: every robot's status.
pub fn statuses(scope: &Scope) -> String {
    format!("{}/status/+", scope.0)
}

/// The key of the heartbeats of the robot of `program` for leader
/// elections (when `program.control.heartbeat`): `<team>.__alive`.
pub fn heartbeat_key(program: &crate::refine::RobotProgram) -> String {
    crate::refine::protocol::alive_key(program)
}

/// Where the robot of `program` publishes its heartbeats: its team's topic
/// of [`heartbeat_key`] from itself.
pub fn heartbeat(scope: &Scope, program: &crate::refine::RobotProgram) -> String {
    to_team(
        scope,
        &program.team,
        &heartbeat_key(program),
        Sender::of(program),
    )
}

/// Whether a message to team `to` came on `topic` of the run `scope` from
/// the sender and with the key its datagram names: a receiver takes
/// nothing else, since the broker vouches only for the topic
/// (`semo_mqtt.c`'s `sent_on_its_topic`).
pub fn carries(topic: &str, scope: &Scope, to: &str, datagram: &Datagram) -> bool {
    topic == to_team(scope, to, &datagram.key, Sender::claimed_by(datagram))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TI: Sender = Sender {
        team: "SlaveTeam",
        robot: "ti",
    };

    fn run(mission: &str) -> Scope {
        Scope::run(mission, &RunId::parse("r1").unwrap())
    }

    #[test]
    fn names_become_levels_as_the_runtime_makes_them() {
        assert_eq!(mission("scouting.mission"), "scouting");
        assert_eq!(mission(".mission"), ".mission");
        assert_eq!(mission(""), "mission");
        assert_eq!(
            to_team(&run("a+b.mission"), "T#", "K/x", TI),
            "semo/a_b.mission/r1/T_/K_x/SlaveTeam/ti"
        );
        let m = run("m");
        assert_eq!(
            to_robot(&m, "MasterTeam", "irobot", "SlaveTeam.COLOR", TI),
            "semo/m/r1/MasterTeam/irobot/SlaveTeam.COLOR/SlaveTeam/ti"
        );
        assert_eq!(
            to_team(&m, "MasterTeam", "USER.RC_CMD", OPERATOR),
            "semo/m/r1/MasterTeam/USER.RC_CMD/USER/operator"
        );
        assert_eq!(team_inbox(&m, "USER"), "semo/m/r1/USER/+/+/+");
        assert_eq!(robot_inbox(&m, "T", "r"), "semo/m/r1/T/r/+/+/+");
        assert_eq!(status(&m, "r"), "semo/m/r1/status/r");
        assert_eq!(
            to_team(&Scope::every_run("m"), "T", "T.X", TI),
            "semo/m/+/T/T.X/SlaveTeam/ti"
        );
        assert_eq!(
            Scope::run("m", &RunId::default()).as_str(),
            "semo/m/default"
        );
        assert_eq!(mission(&"x".repeat(80)).len(), 63);
        assert_eq!(mission(&"é".repeat(40)), "é".repeat(31));
    }

    /// A run id is one topic level and a file name as it is: nothing MQTT
    /// or a file system gives a meaning to gets in.
    #[test]
    fn a_run_id_is_a_plain_level() {
        for good in ["r1", "2024-05-01.b", "A_b-c.d", &"x".repeat(63), "0"] {
            assert_eq!(RunId::parse(good).map(|r| r.to_string()), Ok(good.into()));
        }
        for bad in [
            "",
            "a/b",
            "+",
            "#",
            "a+b",
            "x#",
            ".",
            "..",
            ".hidden",
            "-x",
            "_x",
            "a b",
            "é",
            "a\nb",
            "a\0b",
            &"x".repeat(64),
        ] {
            let why = RunId::parse(bad).unwrap_err();
            assert!(
                why.contains("a run id is 1 to 63 letters"),
                "{bad:?}: {why}"
            );
        }
    }

    #[test]
    fn a_topic_says_its_run() {
        let topic = to_team(&run("a/b"), "T", "T.X", TI);
        assert_eq!(
            run_of("a/b", &topic).map(|r| r.to_string()),
            Some("r1".into())
        );
        assert_eq!(run_of("a", &topic), None);
        assert_eq!(run_of("a_b", "semo/a_b/+/T/T.X/SlaveTeam/ti"), None);
        assert_eq!(run_of("m", "semo/m"), None);
        assert_eq!(run_of("m", "semo/mm/r1/status/r"), None);
    }

    /// A team's subscription matches its messages and never a robot's
    /// (nor a status, nor another run's), whatever the names: the levels
    /// are counted.
    #[test]
    fn a_subscription_matches_exactly_its_level() {
        let matches = |filter: &str, topic: &str| {
            let (f, t): (Vec<&str>, Vec<&str>) =
                (filter.split('/').collect(), topic.split('/').collect());
            f.len() == t.len() && f.iter().zip(&t).all(|(f, t)| *f == "+" || f == t)
        };
        let m = run("m");
        let team = team_inbox(&m, "T");
        let robot = robot_inbox(&m, "T", "r");
        assert!(matches(&team, &to_team(&m, "T", "T.X", TI)));
        assert!(!matches(&team, &to_robot(&m, "T", "r", "T.X", TI)));
        assert!(matches(&robot, &to_robot(&m, "T", "r", "T.X", TI)));
        assert!(!matches(&robot, &to_team(&m, "T", "T.X", TI)));
        assert!(!matches(&team, &status(&m, "r")));
        assert!(!matches(&team_inbox(&m, "status"), &status(&m, "r")));
        let other = Scope::run("m", &RunId::parse("r2").unwrap());
        assert!(!matches(&team, &to_team(&other, "T", "T.X", TI)));
        // The ACL's every run matches each run's topics.
        let every = Scope::every_run("m");
        assert!(matches(
            &to_team(&every, "T", "T.X", TI),
            &to_team(&other, "T", "T.X", TI)
        ));
        assert!(matches(&statuses(&every), &status(&m, "r")));
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
        let m = run("m");
        let own = to_team(&m, "MasterTeam", "USER.RC_CMD", OPERATOR);
        assert!(carries(&own, &m, "MasterTeam", &forged));
        // The slaves' user may write this topic; the datagram says USER.
        let slaves = to_team(&m, "MasterTeam", "SlaveTeam.COLOR", TI);
        assert!(!carries(&slaves, &m, "MasterTeam", &forged));
        // The right sender with another key than the topic's.
        let colour = Datagram {
            team: TI.team.into(),
            robot: TI.robot.into(),
            ..forged.clone()
        };
        assert!(!carries(&slaves, &m, "MasterTeam", &colour));
        assert!(!carries(&own, &m, "SlaveTeam", &forged));
        // Another run's message is not this run's.
        let other = Scope::run("m", &RunId::parse("r2").unwrap());
        assert!(!carries(&own, &other, "MasterTeam", &forged));
    }
}
