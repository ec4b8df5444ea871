//! Reading a deployment file: TOML through `toml_edit` (which keeps every
//! key's and value's position), then the format's own rules. Every mistake
//! is a positioned diagnostic; all of them are reported at once.

use super::{BrokerSide, BrokerUrl, Credentials, Deployment, Named, RobotEntry};
use crate::diag::{Code, Diagnostic, FileId};
use crate::span::Span;
use std::path::{Path, PathBuf};
use toml_edit::{Item, TableLike};

const TOP: &[&str] = &[
    "broker",
    "ca",
    "broker_config",
    "operator",
    "teams",
    "robots",
];
const CREDENTIALS: &[&str] = &["user", "password_file", "ca", "cert", "key"];
const ROBOT: &[&str] = &["id", "user", "password_file", "ca", "cert", "key"];
const BROKER_SIDE: &[&str] = &["password_file", "user", "cert", "key"];

/// Parses a deployment file's `text`; relative paths are resolved against
/// `base` (the file's folder) and files a robot reads must exist.
pub fn parse(text: &str, file: FileId, base: &Path) -> Result<Deployment, Vec<Diagnostic>> {
    let mut reader = Reader {
        file,
        base,
        found: Vec::new(),
    };
    let document = match toml_edit::Document::parse(text) {
        Ok(document) => document,
        Err(e) => {
            let span = e.span().map_or(Span::default(), |r| span(&r));
            return Err(vec![Diagnostic::new(
                Code::DeployInvalid,
                file,
                span,
                format!("not valid TOML: {}", e.message().trim()),
            )]);
        }
    };
    let top = document.as_table();
    reader.known_keys(top, TOP, "the deployment file");
    let broker = match top.get_key_value("broker") {
        None => {
            reader.error(
                Code::DeployInvalid,
                Span::default(),
                "the deployment file has no `broker = \"mqtt://HOST[:PORT]\"`".into(),
            );
            None
        }
        Some((_, item)) => reader
            .string(item, "broker")
            .and_then(|(url, at)| reader.broker_url(&url, at)),
    };
    // The CA goes into the broker's configuration too (`cafile`).
    let ca = reader
        .broker_line_path(top, "ca")
        .then(|| reader.tls_file(top, "ca", Pem::Certificates))
        .flatten();
    let broker_config = match reader.table(top, "broker_config") {
        Some(table) => {
            reader.known_keys(table, BROKER_SIDE, "[broker_config]");
            for key in ["password_file", "cert", "key"] {
                reader.broker_line_path(table, key);
            }
            BrokerSide {
                // The broker's files are on the broker's machine: not checked here.
                password_file: reader.path_of(table, "password_file", false),
                user: reader.broker_line_value(table, "user", super::lines::value_problem),
                cert: reader.path_of(table, "cert", false),
                key: reader.path_of(table, "key", false),
            }
        }
        None => BrokerSide::default(),
    };
    let operator = reader.table(top, "operator").map(|table| {
        reader.known_keys(table, CREDENTIALS, "[operator]");
        let at = top
            .get_key_value("operator")
            .and_then(|(k, _)| k.span())
            .map_or(Span::default(), |r| span(&r));
        Named {
            name: "operator".into(),
            span: at,
            value: reader.credentials(table, "[operator]"),
        }
    });
    let teams = reader.named_tables(top, "teams", |reader, table, name| {
        reader.known_keys(table, CREDENTIALS, &format!("[teams.{name}]"));
        reader.credentials(table, &format!("[teams.{name}]"))
    });
    let robots = reader.named_tables(top, "robots", |reader, table, name| {
        reader.known_keys(table, ROBOT, &format!("[robots.{name}]"));
        let id = table.get("id").and_then(|item| reader.string(item, "id"));
        if let Some((id, at)) = &id {
            if id.is_empty() || id.len() > 64 || id.chars().any(|c| c.is_control() || c == ' ') {
                reader.error(
                    Code::DeployInvalid,
                    *at,
                    format!("`id` must be 1 to 64 characters without spaces, not {id:?}"),
                );
            }
        }
        RobotEntry {
            id: id.map(|(id, _)| id),
            credentials: reader.credentials(table, &format!("[robots.{name}]")),
        }
    });
    // Two robots with one client id would throw each other off the broker.
    for (i, robot) in robots.iter().enumerate() {
        let Some(id) = &robot.value.id else { continue };
        if robots[..i].iter().any(|r| r.value.id.as_ref() == Some(id)) {
            reader.error(
                Code::DeployInvalid,
                robot.span,
                format!(
                    "robot `{}` has the `id` {id:?} of another robot",
                    robot.name
                ),
            );
        }
    }
    match broker {
        Some(broker) if reader.found.is_empty() => Ok(Deployment {
            file,
            broker,
            ca,
            broker_config,
            operator,
            teams,
            robots,
        }),
        _ => Err(reader.found),
    }
}

fn span(range: &std::ops::Range<usize>) -> Span {
    Span {
        start: range.start,
        end: range.end,
    }
}

struct Reader<'a> {
    file: FileId,
    base: &'a Path,
    found: Vec<Diagnostic>,
}

impl Reader<'_> {
    fn error(&mut self, code: Code, at: Span, message: String) {
        self.found
            .push(Diagnostic::new(code, self.file, at, message));
    }

    fn known_keys(&mut self, table: &dyn TableLike, known: &[&str], within: &str) {
        for (key, _) in table.iter() {
            if known.contains(&key) {
                continue;
            }
            let at = table
                .get_key_value(key)
                .and_then(|(k, _)| k.span())
                .map_or(Span::default(), |r| span(&r));
            let mut d = Diagnostic::new(
                Code::DeployInvalid,
                self.file,
                at,
                format!(
                    "{within} has no key `{key}` (it has {})",
                    known
                        .iter()
                        .map(|k| format!("`{k}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
            d.suggest(crate::suggest::did_you_mean(key, known.iter().copied()));
            self.found.push(d);
        }
    }

    fn item_span(item: &Item) -> Span {
        item.span().map_or(Span::default(), |r| span(&r))
    }

    fn string(&mut self, item: &Item, key: &str) -> Option<(String, Span)> {
        let at = Self::item_span(item);
        match item.as_str() {
            Some(s) => Some((s.to_string(), at)),
            None => {
                self.error(Code::DeployInvalid, at, format!("`{key}` must be a string"));
                None
            }
        }
    }

    fn table<'t>(&mut self, parent: &'t dyn TableLike, key: &str) -> Option<&'t dyn TableLike> {
        let item = parent.get(key)?;
        match item.as_table_like() {
            Some(table) => Some(table),
            None => {
                self.error(
                    Code::DeployInvalid,
                    Self::item_span(item),
                    format!("`{key}` must be a table (`[{key}]`)"),
                );
                None
            }
        }
    }

    /// `[<key>.NAME]` tables, each read by `read`.
    fn named_tables<T>(
        &mut self,
        top: &dyn TableLike,
        key: &str,
        mut read: impl FnMut(&mut Self, &dyn TableLike, &str) -> T,
    ) -> Vec<Named<T>> {
        let Some(tables) = self.table(top, key) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (name, item) in tables.iter() {
            let at = tables
                .get_key_value(name)
                .and_then(|(k, _)| k.span())
                .map_or(Span::default(), |r| span(&r));
            match item.as_table_like() {
                Some(table) => {
                    let value = read(self, table, name);
                    out.push(Named {
                        name: name.to_string(),
                        span: at,
                        value,
                    });
                }
                None => self.error(
                    Code::DeployInvalid,
                    at,
                    format!("`{key}.{name}` must be a table (`[{key}.{name}]`)"),
                ),
            }
        }
        out
    }

    fn credentials(&mut self, table: &dyn TableLike, within: &str) -> Credentials {
        // Every user is a line of the broker's ACL and of its password file.
        let user = self.broker_line_value(table, "user", super::lines::user_problem);
        let credentials = Credentials {
            user,
            password_file: self.path_of(table, "password_file", true),
            ca: self.tls_file(table, "ca", Pem::Certificates),
            cert: self.tls_file(table, "cert", Pem::Certificates),
            key: self.tls_file(table, "key", Pem::PrivateKey),
        };
        if credentials.password_file.is_some() && credentials.user.is_none() {
            self.key_error(
                table,
                "password_file",
                format!("{within} has a `password_file` but no `user`"),
            );
        }
        if credentials.cert.is_some() != credentials.key.is_some() {
            let (has, lacks) = if credentials.cert.is_some() {
                ("cert", "key")
            } else {
                ("key", "cert")
            };
            self.key_error(
                table,
                has,
                format!("{within} has a `{has}` but no `{lacks}`: a client certificate needs both"),
            );
        }
        credentials
    }

    /// A string value written as it is into a line of the broker's files
    /// (its configuration, its ACL): one that `problem` finds cannot be is
    /// reported at its position (E127), the file then refused.
    fn broker_line_value(
        &mut self,
        table: &dyn TableLike,
        key: &str,
        problem: fn(&str) -> Option<String>,
    ) -> Option<String> {
        let (value, at) = self.string(table.get(key)?, key)?;
        if let Some(why) = problem(&value) {
            self.error(
                Code::DeployUnwritableValue,
                at,
                format!("`{key}` {value:?} cannot be written into the broker's files: {why}"),
            );
        }
        Some(value)
    }

    /// The same for a path the broker's configuration names (its own
    /// files, the CA), resolved against the deployment's folder as it will
    /// be written; false when reported (or not a string: `path_of` says so).
    fn broker_line_path(&mut self, table: &dyn TableLike, key: &str) -> bool {
        let Some((text, at)) = table
            .get(key)
            .and_then(|item| item.as_str().map(|t| (t, item)))
        else {
            return true;
        };
        let path =
            std::path::absolute(self.base.join(text)).unwrap_or_else(|_| self.base.join(text));
        if let Some(why) = super::lines::path_problem(&path) {
            self.error(
                Code::DeployUnwritableValue,
                Self::item_span(at),
                format!(
                    "`{key}` {:?} cannot be written into the broker's configuration: {why}",
                    path.display().to_string()
                ),
            );
            return false;
        }
        true
    }

    fn key_error(&mut self, table: &dyn TableLike, key: &str, message: String) {
        let at = table
            .get_key_value(key)
            .and_then(|(k, _)| k.span())
            .map_or(Span::default(), |r| span(&r));
        self.error(Code::DeployInvalid, at, message);
    }

    /// A path value, absolute (resolved against the file's folder); with
    /// `must_exist`, a regular file (E123 otherwise).
    fn path_of(&mut self, table: &dyn TableLike, key: &str, must_exist: bool) -> Option<PathBuf> {
        let (text, at) = self.string(table.get(key)?, key)?;
        if text.is_empty() {
            self.error(Code::DeployInvalid, at, format!("`{key}` is empty"));
            return None;
        }
        let path = self.base.join(&text);
        let path = std::path::absolute(&path).unwrap_or(path);
        if must_exist && !path.is_file() {
            self.error(
                Code::DeployMissingFile,
                at,
                format!("`{key}`: no file {} ", path.display())
                    .trim_end()
                    .to_string(),
            );
        }
        Some(path)
    }

    /// A CA, certificate or key file a client reads: it must exist (E123)
    /// and hold what its key says in PEM (E126), so that a robot or the
    /// operator does not find out only when it connects.
    fn tls_file(&mut self, table: &dyn TableLike, key: &str, holds: Pem) -> Option<PathBuf> {
        let path = self.path_of(table, key, true)?;
        let at = Self::item_span(table.get(key)?);
        if path.is_file() {
            if let Err(why) = holds.check(&path) {
                self.error(
                    Code::DeployBadTlsFile,
                    at,
                    format!("`{key}`: {} {why}", path.display()),
                );
            }
        }
        Some(path)
    }

    /// `mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]`.
    fn broker_url(&mut self, url: &str, at: Span) -> Option<BrokerUrl> {
        match broker_address(url) {
            Ok(address) => Some(BrokerUrl {
                url: url.to_string(),
                tls: address.tls,
                host: address.host,
                port: address.port,
                span: at,
            }),
            Err(message) => {
                self.error(Code::DeployBadBroker, at, message);
                None
            }
        }
    }
}

/// Where a broker URL points: the one reading of `mqtt://HOST[:PORT]` and
/// `mqtts://HOST[:PORT]` (deployment files, `semo operator --broker`, the
/// editor's monitor).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BrokerAddress {
    pub tls: bool,
    pub host: String,
    pub port: u16,
}

/// Reads a broker URL (ports 1883 and 8883 when left out); the error says
/// what a broker URL must be.
pub fn broker_address(url: &str) -> Result<BrokerAddress, String> {
    let (tls, rest) = if let Some(rest) = url.strip_prefix("mqtts://") {
        (true, rest)
    } else if let Some(rest) = url.strip_prefix("mqtt://") {
        (false, rest)
    } else {
        return Err(format!(
            "the broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT], not {url:?}"
        ));
    };
    let rest = rest.strip_suffix('/').unwrap_or(rest);
    let default_port = if tls { 8883 } else { 1883 };
    let (host, port) = match rest.rsplit_once(':') {
        Some((host, port)) => (host, port.parse::<u16>().ok().filter(|p| *p > 0)),
        None => (rest, Some(default_port)),
    };
    // Nothing a line of the broker's configuration could not carry either
    // (`listener PORT HOST`).
    let bad_host = host.is_empty()
        || host.len() > 255
        || host.contains(['/', '@', '?', '#'])
        || host.chars().any(|c| c.is_control() || c.is_whitespace());
    match port {
        Some(port) if !bad_host => Ok(BrokerAddress {
            tls,
            host: host.to_string(),
            port,
        }),
        _ => Err(format!(
            "the broker must be {}://HOST[:PORT] with a host name or address and a port from 1 to 65535, not {url:?}",
            if tls { "mqtts" } else { "mqtt" }
        )),
    }
}

/// What a client's TLS file must hold.
#[derive(Clone, Copy)]
enum Pem {
    /// One or more certificates (a CA bundle, or a certificate and its chain).
    Certificates,
    /// A private key (PKCS #8, PKCS #1 or SEC1).
    PrivateKey,
}

/// The largest TLS file read (a system CA bundle is about 200 KB).
const MAX_PEM_BYTES: u64 = 4 * 1024 * 1024;

impl Pem {
    /// Why the file at `path` does not hold what it should, as the end of a
    /// sentence starting with its path.
    fn check(self, path: &Path) -> Result<(), String> {
        use rustls_pki_types::pem::PemObject;
        use rustls_pki_types::{CertificateDer, PrivateKeyDer};
        let text = crate::fsread::read_text_limited(path, MAX_PEM_BYTES)
            .map_err(|e| format!("cannot be read: {e}"))?;
        match self {
            Pem::Certificates => {
                let mut found = 0;
                for certificate in CertificateDer::pem_slice_iter(text.as_bytes()) {
                    certificate.map_err(|e| format!("is not valid PEM: {e}"))?;
                    found += 1;
                }
                if found == 0 {
                    return Err("holds no PEM certificate (`-----BEGIN CERTIFICATE-----`)".into());
                }
            }
            Pem::PrivateKey => {
                PrivateKeyDer::from_pem_slice(text.as_bytes()).map_err(|e| match e {
                    rustls_pki_types::pem::Error::NoItemsFound => {
                        "holds no PEM private key (`-----BEGIN PRIVATE KEY-----`)".to_string()
                    }
                    e => format!("is not valid PEM: {e}"),
                })?;
            }
        }
        Ok(())
    }
}
