//! `semo deploy broker-config`: a mosquitto configuration and its ACL from
//! a deployment and the mission's refined programs. Each robot's user may
//! write only the topics its program sends and publishes on, each naming
//! that robot as the sender (and its own status), and read only its team's
//! and its own topics; only the operator's user may write the `USER`
//! commands the mission receives (topics whose sender is `USER/operator`);
//! anonymous clients are refused. The topics are `topics.rs`'s, as the
//! runtime uses, in every run (`+` at the run's level: the credentials do
//! not depend on the run, the topics' other levels still do); why this is
//! enough to trust a topic's sender is `docs/security.md`. Every value written is one mosquitto reads back as
//! it is (`lines.rs`); anything else is refused, never written.

use super::{Deployment, lines, topics};
use crate::diag::{Code, Diagnostic};
use crate::refine::RobotProgram;
use crate::span::Span;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The files to write: `mosquitto.conf` and `semo.acl`.
#[derive(Debug)]
pub struct BrokerFiles {
    pub config: String,
    pub acl: String,
}

pub const CONFIG_FILE: &str = "mosquitto.conf";
pub const ACL_FILE: &str = "semo.acl";
/// The folder of the output folder where the broker keeps its state: its
/// own, so that the account it runs as can be given it alone.
pub const PERSISTENCE_DIR: &str = "persistence";
/// The account mosquitto runs as when started as root, unless
/// `[broker_config] user` names another: the one its Debian package makes.
pub const DEFAULT_BROKER_USER: &str = "mosquitto";

/// Why the broker's files were not made.
#[derive(Debug)]
pub enum Refusal {
    /// The deployment's mistakes (a robot without a user, a broker without
    /// its password file), in its file.
    Deployment(Vec<Diagnostic>),
    /// A name or path that no broker file can carry as it is: the
    /// mission's (its file name), the output folder, or a value of a
    /// deployment not read by `parse` (which reports those, E127).
    Unwritable(String),
}

/// What the user may do: `(read, write)` topics.
#[derive(Default)]
struct Rights {
    read: BTreeSet<String>,
    write: BTreeSet<String>,
}

/// The configuration for a broker whose files go to `out` (the ACL's and
/// the persistence's absolute paths are written into the configuration).
/// Refused when a robot has no user, the broker's password file is not
/// named, or a value cannot be written as it is.
pub fn files(
    deployment: &Deployment,
    programs: &[RobotProgram],
    out: &Path,
    source: &str,
) -> Result<BrokerFiles, Refusal> {
    let mission = programs
        .first()
        .map(|p| topics::mission(&p.mission))
        .unwrap_or_default();
    if let Some(why) = lines::text_problem(&mission) {
        return Err(Refusal::Unwritable(format!(
            "the mission's name {mission:?} (its file name) cannot be written into the broker's ACL: {why}; rename the mission file"
        )));
    }
    let users = rights(deployment, programs, &topics::Scope::every_run(&mission))
        .map_err(Refusal::Deployment)?;
    let acl = acl(&mission, source, deployment, &users)?;
    let config = config(&mission, source, deployment, programs, out)?;
    Ok(BrokerFiles { config, acl })
}

/// A positioned mistake of the deployment as a whole.
fn mistake(deployment: &Deployment, message: String) -> Diagnostic {
    Diagnostic::new(
        Code::DeployInvalid,
        deployment.file,
        Span::default(),
        message,
    )
}

/// Each user's rights: its robots' topics in `scope` (every run), and the
/// operator's.
fn rights(
    deployment: &Deployment,
    programs: &[RobotProgram],
    scope: &topics::Scope,
) -> Result<BTreeMap<String, Rights>, Vec<Diagnostic>> {
    let mut found = Vec::new();
    let error = |message: String| mistake(deployment, message);
    let teams: BTreeSet<&str> = programs.iter().map(|p| p.team.as_str()).collect();
    let team_of = |robot: &str| {
        programs
            .iter()
            .find(|p| p.robot == robot)
            .map(|p| p.team.as_str())
    };
    let mut users: BTreeMap<String, Rights> = BTreeMap::new();
    for program in programs {
        let connection = deployment.robot(&program.team, &program.robot);
        let Some(user) = connection.credentials.user else {
            found.push(error(format!(
                "robot `{}` has no `user`: the broker refuses anonymous clients (give one in [robots.{}] or [teams.{}])",
                program.robot, program.robot, program.team
            )));
            continue;
        };
        // Every topic a robot writes names it as the sender: its user can
        // speak for its own robots only.
        let me = topics::Sender::of(program);
        let rights = users.entry(user).or_default();
        for out in &program.control.outgoing {
            if teams.contains(out.to_team.as_str()) || out.to_team == "USER" {
                // A team, or what the robot tells the operator consoles.
                rights
                    .write
                    .insert(topics::to_team(scope, &out.to_team, &out.key, me));
            } else if let Some(team) = team_of(&out.to_team) {
                rights
                    .write
                    .insert(topics::to_robot(scope, team, &out.to_team, &out.key, me));
            }
        }
        if program.control.heartbeat {
            rights.write.insert(topics::heartbeat(scope, program));
        }
        // The owner protocol of globally shared values: the owner tells the
        // team, a writer tells whichever teammate owns (any may, in turn).
        let ownership = program.library.as_ref().and_then(|l| l.ownership.as_ref());
        for global in ownership.map_or(&[][..], |o| &o.global) {
            rights
                .write
                .insert(topics::to_team(scope, &program.team, &global.value_key, me));
            for &owner in ownership.map_or(&[][..], |o| &o.owners) {
                let (team, robot) = program.peer(owner);
                if *robot != program.robot {
                    rights
                        .write
                        .insert(topics::to_robot(scope, team, robot, &global.set_key, me));
                }
            }
        }
        if !program.control.sync_points.is_empty() {
            let key = crate::refine::protocol::sync_key(program);
            rights
                .write
                .insert(topics::to_team(scope, &program.team, &key, me));
        }
        rights.write.insert(topics::status(scope, &program.robot));
        // Exactly the runtime's two subscriptions.
        rights.read.insert(topics::team_inbox(scope, &program.team));
        rights
            .read
            .insert(topics::robot_inbox(scope, &program.team, &program.robot));
    }
    let operator = deployment.operator_credentials().user;
    if let Some(user) = &operator {
        if users.contains_key(user) {
            found.push(error(format!(
                "the operator's user `{user}` is also a robot's: robots must not write USER commands"
            )));
        }
        let rights = users.entry(user.clone()).or_default();
        for program in programs {
            for incoming in program
                .control
                .incoming
                .iter()
                .filter(|i| i.from_team == "USER")
            {
                rights.write.insert(topics::to_team(
                    scope,
                    &program.team,
                    &incoming.key,
                    topics::OPERATOR,
                ));
                rights.write.insert(topics::to_robot(
                    scope,
                    &program.team,
                    &program.robot,
                    &incoming.key,
                    topics::OPERATOR,
                ));
            }
        }
        rights.read.insert(topics::statuses(scope));
        rights.read.insert(topics::team_inbox(scope, "USER"));
        // The editor's robot monitor tells a robot that stops heart-beating.
        for program in programs.iter().filter(|p| p.control.heartbeat) {
            rights.read.insert(topics::heartbeat(scope, program));
        }
    }
    if !found.is_empty() {
        return Err(found);
    }
    Ok(users)
}

/// `semo.acl`: per user, its topics.
fn acl(
    mission: &str,
    source: &str,
    deployment: &Deployment,
    users: &BTreeMap<String, Rights>,
) -> Result<String, Refusal> {
    let operator = deployment.operator_credentials().user;
    let mut acl = format!(
        "# The ACL of mission {}, written by `semo deploy broker-config` from\n# {}.\n# Each robot's user writes only what its program sends and publishes, on\n# topics naming that robot as the sender (and its status), and reads only its\n# team's and its own topics, in every run of the mission (the `+` after its\n# name); {}.\n",
        lines::comment(mission),
        lines::comment(source),
        match &operator {
            Some(user) => format!(
                "only {} (the operator) writes USER commands",
                lines::comment(user)
            ),
            None => "no operator is deployed: nobody writes USER commands".into(),
        }
    );
    for (user, rights) in users {
        if let Some(why) = lines::user_problem(user) {
            return Err(Refusal::Unwritable(format!(
                "the user {user:?} cannot be written into the broker's ACL: {why}"
            )));
        }
        acl.push_str(&format!("\nuser {user}\n"));
        let lines = [("write", &rights.write), ("read", &rights.read)];
        for (access, topic) in lines
            .iter()
            .flat_map(|(a, t)| t.iter().map(move |t| (a, t)))
        {
            if let Some(why) = lines::value_problem(topic) {
                return Err(Refusal::Unwritable(format!(
                    "the topic {topic:?} cannot be written into the broker's ACL: {why}"
                )));
            }
            acl.push_str(&format!("topic {access} {topic}\n"));
        }
    }
    Ok(acl)
}

/// A path of the configuration, or why it cannot be one.
fn path_value(what: &str, path: &Path) -> Result<String, Refusal> {
    match lines::path_problem(path) {
        None => Ok(path.display().to_string()),
        Some(why) => Err(Refusal::Unwritable(format!(
            "{what} {:?} cannot be written into {CONFIG_FILE}: {why}",
            path.display().to_string()
        ))),
    }
}

/// `mosquitto.conf`.
fn config(
    mission: &str,
    source: &str,
    deployment: &Deployment,
    programs: &[RobotProgram],
    out: &Path,
) -> Result<String, Refusal> {
    let side = &deployment.broker_config;
    let Some(password_file) = &side.password_file else {
        return Err(Refusal::Deployment(vec![mistake(
            deployment,
            "the broker needs a password file: give `password_file` in [broker_config] (made with `mosquitto_passwd`)".into(),
        )]));
    };
    let password_file = path_value("the broker's `password_file`", password_file)?;
    let acl_path = path_value("the output folder", &out.join(ACL_FILE))?;
    let persistence = path_value("the output folder", &out.join(PERSISTENCE_DIR))?;
    let user = side.run_as();
    if let Some(why) = lines::value_problem(user) {
        return Err(Refusal::Unwritable(format!(
            "the broker's `user` {user:?} cannot be written into {CONFIG_FILE}: {why}"
        )));
    }
    let broker = &deployment.broker;
    let loopback =
        matches!(broker.host.as_str(), "localhost" | "::1") || broker.host.starts_with("127.");
    if let Some(why) = lines::value_problem(&broker.host) {
        return Err(Refusal::Unwritable(format!(
            "the broker's host {:?} cannot be written into {CONFIG_FILE}: {why}",
            broker.host
        )));
    }
    let mut config = format!(
        "# mosquitto configuration for mission {mission}, written by `semo deploy\n# broker-config` from {source}:\n# no anonymous clients, the ACL {ACL_FILE}, and TCP_NODELAY (without it a QoS 1\n# round trip waits for Nagle's algorithm).\n#\n# Started as root, mosquitto runs as `user` ({quoted_user}) and reads the password file\n# and the ACL, and keeps its state, as that user: it must be able to read\n# {password_file}\n# and own {persistence}/\n# (`chown {user} PASSWORD_FILE PERSISTENCE_FOLDER`; `chmod 0600 PASSWORD_FILE`),\n# else it refuses to start or cannot keep QoS 1 messages and sessions across a\n# restart. Started as another user, it stays that user. See docs/deployment.md.\nper_listener_settings false\nallow_anonymous false\npassword_file {password_file}\nacl_file {acl_path}\nset_tcp_nodelay true\npersistence true\npersistence_location {persistence}/\nuser {user}\n\nlistener {port}{bind}\n",
        mission = lines::comment(mission),
        source = lines::comment(source),
        quoted_user = lines::comment(user),
        port = broker.port,
        bind = if loopback {
            format!(" {}", broker.host)
        } else {
            String::new()
        },
    );
    if broker.tls {
        let (Some(cert), Some(key), Some(ca)) = (&side.cert, &side.key, &deployment.ca) else {
            return Err(Refusal::Deployment(vec![mistake(
                deployment,
                "an mqtts:// broker needs its certificate and key ([broker_config] `cert`, `key`) and the `ca` at the top".into(),
            )]));
        };
        // The operator (`semo operator`, the editor's monitor) is a client too.
        let every_client_has_a_certificate = programs.iter().all(|p| {
            deployment
                .robot(&p.team, &p.robot)
                .credentials
                .cert
                .is_some()
        }) && (deployment.operator.is_none()
            || deployment.operator_credentials().cert.is_some());
        config.push_str(&format!(
            "cafile {}\ncertfile {}\nkeyfile {}\nrequire_certificate {every_client_has_a_certificate}\n",
            path_value("the `ca`", ca)?,
            path_value("the broker's `cert`", cert)?,
            path_value("the broker's `key`", key)?
        ));
    }
    Ok(config)
}
