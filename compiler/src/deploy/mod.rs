//! Deployment files (`*.deploy.toml`, documented in `docs/deployment.md`):
//! where the MQTT broker is and which credentials each robot, team and the
//! operator use. `semo build --deploy FILE` bakes each robot's defaults into
//! its folder ([`bake`]: `semo_deploy.h`, paths to secrets, never a secret);
//! `semo deploy broker-config` writes the broker's configuration and ACL
//! from the checked mission ([`broker`]).
//!
//! - `parse`/`load`: the file's own mistakes (TOML, unknown keys, a bad
//!   broker URL, a file it names that is not there), positioned.
//! - `check`: its names against the checked mission (unknown robots and
//!   teams, a TLS robot without a CA).
//! - `topics`: the topic scheme of `semo_mqtt.c`, written once on this side.
//! - `lines`: what a line of the broker's files can carry.
//! - `datagram`: the runtime's datagram, for the operator console and tests.

pub mod broker;
pub mod datagram;
pub mod lines;
mod parse;
pub mod topics;

use crate::codegen::{BuildResult, DEPLOY_HEADER, c_string};
use crate::diag::{Code, Diagnostic, FileId};
use crate::sema::Mission;
use crate::span::Span;
use std::path::{Path, PathBuf};

pub use parse::{BrokerAddress, broker_address, parse};

/// A deployment file, read and checked on its own. Paths are absolute
/// (relative ones are resolved against the file's folder).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Deployment {
    pub file: FileId,
    pub broker: BrokerUrl,
    /// The CA every robot and the operator trust (mqtts), unless their own
    /// entry names another.
    pub ca: Option<PathBuf>,
    /// What `semo deploy broker-config` writes for the broker itself.
    pub broker_config: BrokerSide,
    /// The operator's credentials (the only user that may write `USER` commands).
    pub operator: Option<Named<Credentials>>,
    pub teams: Vec<Named<Credentials>>,
    pub robots: Vec<Named<RobotEntry>>,
}

/// `mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]` (ports 1883 and 8883 when
/// left out).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BrokerUrl {
    pub url: String,
    pub tls: bool,
    pub host: String,
    pub port: u16,
    pub span: Span,
}

/// The broker's side: its password file (made with `mosquitto_passwd`),
/// the account it runs as when started as root (`user`, default
/// `broker::DEFAULT_BROKER_USER`) and, for `mqtts://`, its certificate and
/// key.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BrokerSide {
    pub password_file: Option<PathBuf>,
    pub user: Option<String>,
    pub cert: Option<PathBuf>,
    pub key: Option<PathBuf>,
}

impl BrokerSide {
    /// The account mosquitto runs as when started as root.
    pub fn run_as(&self) -> &str {
        self.user.as_deref().unwrap_or(broker::DEFAULT_BROKER_USER)
    }
}

/// Who a client is at the broker. The password is never in the deployment
/// file nor in generated code: `password_file` holds it (its first line).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Credentials {
    pub user: Option<String>,
    pub password_file: Option<PathBuf>,
    pub ca: Option<PathBuf>,
    pub cert: Option<PathBuf>,
    pub key: Option<PathBuf>,
}

/// `[robots.NAME]`: credentials that win over its team's, and its client id.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RobotEntry {
    /// The MQTT client id (default `semo-<mission>-<robot>`).
    pub id: Option<String>,
    pub credentials: Credentials,
}

/// A table of the file named by its key (`[teams.SlaveTeam]`), with the
/// key's position for diagnostics.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Named<T> {
    pub name: String,
    pub span: Span,
    pub value: T,
}

/// What one robot connects with: its entry over its team's over the file's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotConnection {
    pub broker: String,
    pub client_id: Option<String>,
    pub credentials: Credentials,
}

impl Deployment {
    /// The connection of robot `robot` of team `team`.
    pub fn robot(&self, team: &str, robot: &str) -> RobotConnection {
        let entry = self
            .robots
            .iter()
            .find(|r| r.name == robot)
            .map(|r| &r.value);
        let team = self.teams.iter().find(|t| t.name == team).map(|t| &t.value);
        let pick = |get: fn(&Credentials) -> &Option<PathBuf>| {
            entry
                .and_then(|e| get(&e.credentials).clone())
                .or_else(|| team.and_then(|t| get(t).clone()))
        };
        // Credentials go together: a robot's own user comes with its own
        // password file, never with its team's.
        let (user, password_file) = match entry.filter(|e| e.credentials.user.is_some()) {
            Some(e) => (
                e.credentials.user.clone(),
                e.credentials.password_file.clone(),
            ),
            None => (
                team.and_then(|t| t.user.clone()),
                team.and_then(|t| t.password_file.clone()),
            ),
        };
        RobotConnection {
            broker: self.broker.url.clone(),
            client_id: entry.and_then(|e| e.id.clone()),
            credentials: Credentials {
                user,
                password_file,
                ca: pick(|c| &c.ca).or_else(|| self.ca.clone()),
                cert: pick(|c| &c.cert),
                key: pick(|c| &c.key),
            },
        }
    }

    /// The operator's connection (CA defaulting to the file's).
    pub fn operator_credentials(&self) -> Credentials {
        let mut c = self
            .operator
            .as_ref()
            .map(|o| o.value.clone())
            .unwrap_or_default();
        if c.ca.is_none() {
            c.ca = self.ca.clone();
        }
        c
    }
}

/// Reads and parses a deployment file; its diagnostics are in `file`. A file
/// that cannot be read is one diagnostic at its start.
pub fn load(path: &Path, file: FileId) -> Result<Deployment, Vec<Diagnostic>> {
    let text = crate::fsread::read_text(path).map_err(|e| {
        vec![Diagnostic::new(
            Code::DeployInvalid,
            file,
            Span::default(),
            format!("cannot read the deployment file {}: {e}", path.display()),
        )]
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    parse(&text, file, base)
}

/// The deployment's names against the checked mission: every `[robots.X]`
/// a robot of it, every `[teams.X]` a team; with `mqtts://` every robot
/// needs a CA to check the broker with.
pub fn check(deployment: &Deployment, mission: &Mission) -> Vec<Diagnostic> {
    let mut found = Vec::new();
    let teams: Vec<&str> = mission.teams.iter().map(|t| t.name.as_str()).collect();
    let robots: Vec<(&str, &str)> = mission
        .teams
        .iter()
        .flat_map(|t| {
            t.robots
                .iter()
                .map(move |r| (t.name.as_str(), r.name.as_str()))
        })
        .collect();
    for team in &deployment.teams {
        if !teams.contains(&team.name.as_str()) {
            let mut d = Diagnostic::new(
                Code::DeployUnknownName,
                deployment.file,
                team.span,
                format!("the mission has no team `{}`", team.name),
            );
            d.suggest(crate::suggest::did_you_mean(
                &team.name,
                teams.iter().copied(),
            ));
            found.push(d);
        }
    }
    for robot in &deployment.robots {
        if !robots.iter().any(|(_, r)| *r == robot.name) {
            let mut d = Diagnostic::new(
                Code::DeployUnknownName,
                deployment.file,
                robot.span,
                format!("the mission has no robot `{}`", robot.name),
            );
            d.suggest(crate::suggest::did_you_mean(
                &robot.name,
                robots.iter().map(|(_, r)| *r),
            ));
            found.push(d);
        }
    }
    if deployment.broker.tls {
        if deployment.operator.is_some() && deployment.operator_credentials().ca.is_none() {
            found.push(Diagnostic::new(
                Code::DeployInvalid,
                deployment.file,
                deployment.broker.span,
                "the operator connects with TLS (mqtts://) but has no `ca` to check the broker with: give `ca` at the top or in [operator]".to_string(),
            ));
        }
        for (team, robot) in &robots {
            if deployment.robot(team, robot).credentials.ca.is_none() {
                found.push(Diagnostic::new(
                    Code::DeployInvalid,
                    deployment.file,
                    deployment.broker.span,
                    format!(
                        "robot `{robot}` connects with TLS (mqtts://) but has no `ca` to check the broker with: give `ca` at the top, in [teams.{team}] or in [robots.{robot}]"
                    ),
                ));
            }
        }
    }
    found
}

/// Bakes the deployment into every robot folder of a build whose target
/// has a network transport: its `semo_deploy.h` names the broker, client
/// id, user and the paths of the password file and TLS files (the runtime
/// reads the password at start). A robot on a platform without one (a
/// board: it reaches the fleet through its serial link and `semo gateway`,
/// which reads its credentials from the deployment file itself, or talks
/// to nobody) has nothing to bake. Returns false when
/// no robot of the build has a network transport.
pub fn bake(deployment: &Deployment, result: &mut BuildResult) -> bool {
    let mut baked = false;
    for robot in &mut result.robots {
        if robot.target.transport().is_none() {
            continue;
        }
        let connection = deployment.robot(&robot.team, &robot.robot);
        if let Some(file) = robot.files.iter_mut().find(|f| f.path == DEPLOY_HEADER) {
            file.text = header(&connection);
            baked = true;
        }
    }
    baked
}

/// `semo_deploy.h` for one robot.
fn header(connection: &RobotConnection) -> String {
    let mut out = String::from(
        "/* The deployment baked in by `semo build --deploy`: the defaults of this\n * robot's connection (options and environment variables override them; see\n * docs/deployment.md). No secret is here: the password is read from its file. */\n#ifndef SEMO_DEPLOY_H\n#define SEMO_DEPLOY_H\n",
    );
    let c = &connection.credentials;
    let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    let defines = [
        ("SEMO_DEPLOY_BROKER", Some(connection.broker.clone())),
        ("SEMO_DEPLOY_CLIENT_ID", connection.client_id.clone()),
        ("SEMO_DEPLOY_USER", c.user.clone()),
        ("SEMO_DEPLOY_PASSWORD_FILE", path(&c.password_file)),
        ("SEMO_DEPLOY_CA", path(&c.ca)),
        ("SEMO_DEPLOY_CERT", path(&c.cert)),
        ("SEMO_DEPLOY_KEY", path(&c.key)),
    ];
    for (name, value) in defines {
        if let Some(value) = value {
            out.push_str(&format!("#define {name} {}\n", c_string(&value)));
        }
    }
    out.push_str("#endif\n");
    out
}

#[cfg(test)]
mod tests;
