//! `semo deploy broker-config`: a mosquitto configuration and its ACL from
//! a deployment and the mission's refined programs. Each robot's user may
//! write only the topics its program sends and publishes on, each naming
//! that robot as the sender (and its own status), and read only its team's
//! and its own topics; only the operator's user may write the `USER`
//! commands the mission receives (topics whose sender is `USER/operator`);
//! anonymous clients are refused. The topics are `topics.rs`'s, as the
//! runtime uses.

use super::{Deployment, topics};
use crate::diag::{Code, Diagnostic};
use crate::refine::RobotProgram;
use crate::span::Span;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The files to write: `mosquitto.conf` and `semo.acl`.
pub struct BrokerFiles {
    pub config: String,
    pub acl: String,
}

pub const CONFIG_FILE: &str = "mosquitto.conf";
pub const ACL_FILE: &str = "semo.acl";

/// What the user may do: `(read, write)` topics.
#[derive(Default)]
struct Rights {
    read: BTreeSet<String>,
    write: BTreeSet<String>,
}

/// The configuration for a broker whose files go to `out` (the ACL's and
/// the persistence's absolute paths are written into the configuration).
/// Refused with diagnostics when a robot has no user or the broker's
/// password file is not named.
pub fn files(
    deployment: &Deployment,
    programs: &[RobotProgram],
    out: &Path,
    source: &str,
) -> Result<BrokerFiles, Vec<Diagnostic>> {
    let mut found = Vec::new();
    let file = deployment.file;
    let error =
        |message: String| Diagnostic::new(Code::DeployInvalid, file, Span::default(), message);
    let Some(password_file) = &deployment.broker_config.password_file else {
        return Err(vec![error(
            "the broker needs a password file: give `password_file` in [broker_config] (made with `mosquitto_passwd`)".into(),
        )]);
    };
    let mission = programs
        .first()
        .map(|p| topics::mission(&p.mission))
        .unwrap_or_default();
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
                    .insert(topics::to_team(&mission, &out.to_team, &out.key, me));
            } else if let Some(team) = team_of(&out.to_team) {
                rights
                    .write
                    .insert(topics::to_robot(&mission, team, &out.to_team, &out.key, me));
            }
        }
        if program.control.heartbeat {
            rights.write.insert(topics::heartbeat(program));
        }
        // The owner protocol of globally shared values: the owner tells the
        // team, a writer tells whichever teammate owns (any may, in turn).
        let ownership = program.library.as_ref().and_then(|l| l.ownership.as_ref());
        for global in ownership.map_or(&[][..], |o| &o.global) {
            rights.write.insert(topics::to_team(
                &mission,
                &program.team,
                &global.value_key,
                me,
            ));
            for &owner in ownership.map_or(&[][..], |o| &o.owners) {
                let (team, robot) = &program.peers[owner];
                if *robot != program.robot {
                    rights.write.insert(topics::to_robot(
                        &mission,
                        team,
                        robot,
                        &global.set_key,
                        me,
                    ));
                }
            }
        }
        if !program.control.sync_points.is_empty() {
            let key = crate::codegen::files::sync_key(program);
            rights
                .write
                .insert(topics::to_team(&mission, &program.team, &key, me));
        }
        rights
            .write
            .insert(topics::status(&mission, &program.robot));
        // Exactly the runtime's two subscriptions.
        rights
            .read
            .insert(topics::team_inbox(&mission, &program.team));
        rights
            .read
            .insert(topics::robot_inbox(&mission, &program.team, &program.robot));
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
                    &mission,
                    &program.team,
                    &incoming.key,
                    topics::OPERATOR,
                ));
                rights.write.insert(topics::to_robot(
                    &mission,
                    &program.team,
                    &program.robot,
                    &incoming.key,
                    topics::OPERATOR,
                ));
            }
        }
        rights.read.insert(topics::statuses(&mission));
        rights.read.insert(topics::team_inbox(&mission, "USER"));
        // The editor's robot monitor tells a robot that stops heart-beating.
        for program in programs.iter().filter(|p| p.control.heartbeat) {
            rights.read.insert(topics::heartbeat(program));
        }
    }
    if !found.is_empty() {
        return Err(found);
    }
    let mut acl = format!(
        "# The ACL of mission {mission}, written by `semo deploy broker-config` from {source}.\n# Each robot's user writes only what its program sends and publishes, on\n# topics naming that robot as the sender (and its status), and reads only its\n# team's and its own topics; {}.\n",
        match &operator {
            Some(user) => format!("only `{user}` (the operator) writes USER commands"),
            None => "no operator is deployed: nobody writes USER commands".into(),
        }
    );
    for (user, rights) in &users {
        acl.push_str(&format!("\nuser {user}\n"));
        for topic in &rights.write {
            acl.push_str(&format!("topic write {topic}\n"));
        }
        for topic in &rights.read {
            acl.push_str(&format!("topic read {topic}\n"));
        }
    }
    let broker = &deployment.broker;
    let loopback =
        matches!(broker.host.as_str(), "localhost" | "::1") || broker.host.starts_with("127.");
    let mut config = format!(
        "# mosquitto configuration for mission {mission}, written by `semo deploy\n# broker-config` from {source}: no anonymous clients, the ACL {acl_file},\n# and TCP_NODELAY (without it a QoS 1 round trip waits for Nagle's algorithm).\nper_listener_settings false\nallow_anonymous false\npassword_file {passwords}\nacl_file {acl_path}\nset_tcp_nodelay true\npersistence true\npersistence_location {persistence}/\n\nlistener {port}{bind}\n",
        acl_file = ACL_FILE,
        passwords = password_file.display(),
        acl_path = out.join(ACL_FILE).display(),
        persistence = out.display(),
        port = broker.port,
        bind = if loopback {
            format!(" {}", broker.host)
        } else {
            String::new()
        },
    );
    if broker.tls {
        let side = &deployment.broker_config;
        let (Some(cert), Some(key), Some(ca)) = (&side.cert, &side.key, &deployment.ca) else {
            return Err(vec![error(
                "an mqtts:// broker needs its certificate and key ([broker_config] `cert`, `key`) and the `ca` at the top".into(),
            )]);
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
            ca.display(),
            cert.display(),
            key.display()
        ));
    }
    Ok(BrokerFiles { config, acl })
}
