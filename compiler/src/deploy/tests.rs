//! The deployment format: what a file means, and each mistake positioned.

use super::*;
use crate::diag::FileId;
use std::collections::BTreeSet;

/// A certificate and a private key as PEM (what is checked of them: the
/// PEM framing and its base64, not the DER inside).
const PEM_CERTIFICATE: &str = "-----BEGIN CERTIFICATE-----\nMIIBAA==\n-----END CERTIFICATE-----\n";
const PEM_KEY: &str = "-----BEGIN PRIVATE KEY-----\nMIIBAA==\n-----END PRIVATE KEY-----\n";

/// A folder with the files a deployment names: `*.crt` a PEM certificate,
/// `*.key` a PEM private key, the others a line of text.
fn folder(files: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in files {
        let text = if name.ends_with(".crt") {
            PEM_CERTIFICATE
        } else if name.ends_with(".key") {
            PEM_KEY
        } else {
            "x\n"
        };
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

/// Each diagnostic as `CODE 'the text it points at': message`.
fn mistakes(text: &str, files: &[&str]) -> Vec<String> {
    let dir = folder(files);
    match parse(text, FileId(7), dir.path()) {
        Ok(d) => panic!("expected mistakes, got {d:?}"),
        Err(found) => found
            .iter()
            .map(|d| {
                assert_eq!(d.file, FileId(7));
                format!(
                    "{} '{}': {}",
                    d.code,
                    &text[d.span.start..d.span.end],
                    d.message
                )
            })
            .collect(),
    }
}

const FULL: &str = r#"
broker = "mqtts://lab.example:8884"
ca = "ca.crt"

[broker_config]
password_file = "/etc/mosquitto/semo.passwd"
cert = "server.crt"
key = "server.key"

[operator]
user = "operator"
password_file = "operator.pw"

[teams.SlaveTeam]
user = "slaves"
password_file = "slaves.pw"

[robots.irobot]
id = "create-7"
user = "irobot"
password_file = "irobot.pw"
cert = "irobot.crt"
key = "irobot.key"

[robots.ti]
cert = "ti.crt"
key = "ti.key"
"#;

#[test]
fn a_robot_takes_its_entry_then_its_team_then_the_file() {
    let files = [
        "ca.crt",
        "operator.pw",
        "slaves.pw",
        "irobot.pw",
        "irobot.crt",
        "irobot.key",
        "ti.crt",
        "ti.key",
    ];
    let dir = folder(&files);
    let d = parse(FULL, FileId(0), dir.path()).unwrap();
    assert!(d.broker.tls);
    assert_eq!(
        (d.broker.host.as_str(), d.broker.port),
        ("lab.example", 8884)
    );
    let abs = |name: &str| Some(std::path::absolute(dir.path().join(name)).unwrap());
    let irobot = d.robot("MasterTeam", "irobot");
    assert_eq!(irobot.client_id.as_deref(), Some("create-7"));
    assert_eq!(irobot.credentials.user.as_deref(), Some("irobot"));
    assert_eq!(irobot.credentials.password_file, abs("irobot.pw"));
    assert_eq!(irobot.credentials.ca, abs("ca.crt"));
    let ti = d.robot("SlaveTeam", "ti");
    assert_eq!(ti.credentials.user.as_deref(), Some("slaves"));
    assert_eq!(ti.credentials.password_file, abs("slaves.pw"));
    assert_eq!(ti.credentials.cert, abs("ti.crt"));
    assert_eq!(ti.client_id, None);
    assert_eq!(d.operator_credentials().user.as_deref(), Some("operator"));
    // The broker's own files are not checked (they are on its machine).
    assert_eq!(
        d.broker_config.password_file.as_deref(),
        Some(std::path::Path::new("/etc/mosquitto/semo.passwd"))
    );
}

#[test]
fn the_baked_header_names_paths_and_never_a_secret() {
    let dir = folder(&["irobot.pw"]);
    std::fs::write(dir.path().join("irobot.pw"), "s3cret\n").unwrap();
    let text = "broker = \"mqtt://10.0.0.2\"\n[robots.irobot]\nuser = \"irobot\"\npassword_file = \"irobot.pw\"\n";
    let d = parse(text, FileId(0), dir.path()).unwrap();
    assert_eq!(d.broker.port, 1883);
    let header = header(&d.robot("MasterTeam", "irobot"));
    assert!(
        header.contains("#define SEMO_DEPLOY_BROKER \"mqtt://10.0.0.2\"\n"),
        "{header}"
    );
    assert!(
        header.contains("#define SEMO_DEPLOY_USER \"irobot\"\n"),
        "{header}"
    );
    assert!(header.contains("SEMO_DEPLOY_PASSWORD_FILE"), "{header}");
    assert!(!header.contains("s3cret"), "{header}");
    assert!(!header.contains("SEMO_DEPLOY_CA"), "{header}");
}

#[test]
fn mistakes_are_positioned() {
    assert_eq!(
        mistakes("broker = \"tcp://x:1\"\n", &[]),
        [
            "E122 '\"tcp://x:1\"': the broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT], not \"tcp://x:1\""
        ]
    );
    assert_eq!(
        mistakes("broker = \"mqtt://x:99999\"\n", &[]),
        [
            "E122 '\"mqtt://x:99999\"': the broker must be mqtt://HOST[:PORT] with a host name or address and a port from 1 to 65535, not \"mqtt://x:99999\""
        ]
    );
    assert_eq!(
        mistakes("brokr = \"mqtt://x\"\n", &[]),
        [
            "E120 'brokr': the deployment file has no key `brokr` (it has `broker`, `ca`, `broker_config`, `operator`, `teams`, `robots`) (did you mean `broker`?)",
            "E120 '': the deployment file has no `broker = \"mqtt://HOST[:PORT]\"`"
        ]
    );
    let missing = &mistakes(
        "broker = \"mqtt://x\"\n[robots.ti]\nuser = \"ti\"\npassword_file = \"ti.pw\"\n",
        &[],
    )[0];
    assert!(
        missing.starts_with("E123 '\"ti.pw\"': `password_file`: no file /")
            && missing.ends_with("/ti.pw"),
        "{missing}"
    );
    assert_eq!(
        mistakes(
            "broker = \"mqtt://x\"\n[robots.ti]\ncert = \"c.crt\"\nid = 4\n",
            &["c.crt"]
        ),
        [
            "E120 '4': `id` must be a string",
            "E120 'cert': [robots.ti] has a `cert` but no `key`: a client certificate needs both"
        ]
    );
    assert_eq!(
        mistakes(
            "broker = \"mqtt://x\"\n[robots.a]\nid = \"x\"\n[robots.b]\nid = \"x\"\n",
            &[]
        ),
        ["E120 'b': robot `b` has the `id` \"x\" of another robot"]
    );
    let toml = mistakes("broker = \"mqtt://x\n", &[]);
    assert_eq!(toml.len(), 1);
    assert!(toml[0].starts_with("E120 "), "{toml:?}");
}

#[test]
fn a_value_the_broker_files_cannot_carry_is_positioned() {
    let found = mistakes(
        "broker = \"mqtt://x\"\n[teams.T]\nuser = \"slaves\\npattern readwrite #\"\npassword_file = \"t.pw\"\n[operator]\nuser = \"op:1\"\n[broker_config]\npassword_file = \"p \"\nuser = \"\"\n",
        &["t.pw"],
    );
    assert_eq!(found.len(), 4, "{found:#?}");
    // The broker's own path first: its table is read before the users'.
    assert!(
        found[0].starts_with("E127 '\"p \"': `password_file` \"/")
            && found[0].ends_with("/p \" cannot be written into the broker's configuration: it starts or ends with a space, which mosquitto trims"),
        "{found:#?}"
    );
    assert_eq!(
        found[1..],
        [
            "E127 '\"\"': `user` \"\" cannot be written into the broker's files: it is empty",
            "E127 '\"op:1\"': `user` \"op:1\" cannot be written into the broker's files: it holds `:`, which ends a user name in mosquitto's password file",
            "E127 '\"slaves\\npattern readwrite #\"': `user` \"slaves\\npattern readwrite #\" cannot be written into the broker's files: it holds the control character U+000A, which would end the line or be taken for another",
        ]
    );
    // A host with a line break is no host (`listener PORT HOST`).
    assert_eq!(
        mistakes(
            "broker = \"mqtt://127.0.0.1\\nallow_anonymous true:1883\"\n",
            &[]
        )
        .len(),
        1
    );
}

#[test]
fn a_tls_file_that_holds_no_pem_certificate_or_key_is_positioned() {
    // A certificate where the key should be, text where the CA should be,
    // broken base64: each refused at the value that names the file.
    let found = mistakes(
        "broker = \"mqtts://x\"\nca = \"ca.txt\"\n[operator]\nuser = \"op\"\ncert = \"op.crt\"\nkey = \"op-key.crt\"\n",
        &["ca.txt", "op.crt", "op-key.crt"],
    );
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(
        found[0].starts_with("E126 '\"ca.txt\"': `ca`: /")
            && found[0]
                .ends_with("ca.txt holds no PEM certificate (`-----BEGIN CERTIFICATE-----`)"),
        "{found:?}"
    );
    assert!(
        found[1].starts_with("E126 '\"op-key.crt\"': `key`: /")
            && found[1].ends_with("holds no PEM private key (`-----BEGIN PRIVATE KEY-----`)"),
        "{found:?}"
    );
    let dir = folder(&[]);
    std::fs::write(
        dir.path().join("bad.crt"),
        "-----BEGIN CERTIFICATE-----\n%%%\n-----END CERTIFICATE-----\n",
    )
    .unwrap();
    let found = parse(
        "broker = \"mqtts://x\"\nca = \"bad.crt\"\n",
        FileId(0),
        dir.path(),
    )
    .unwrap_err();
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].code, Code::DeployBadTlsFile);
    assert!(
        found[0].message.contains("is not valid PEM"),
        "{}",
        found[0].message
    );
}

#[test]
fn a_broker_url_reads_the_same_everywhere() {
    let address = |url: &str| broker_address(url).map(|a| (a.tls, a.host, a.port));
    assert_eq!(address("mqtt://h:99"), Ok((false, "h".into(), 99)));
    assert_eq!(address("mqtt://h/"), Ok((false, "h".into(), 1883)));
    assert_eq!(
        address("mqtts://10.0.0.2"),
        Ok((true, "10.0.0.2".into(), 8883))
    );
    assert!(address("mqtt://:1").is_err());
    assert!(address("mqtts://h:0").is_err());
    assert!(
        address("tcp://h")
            .unwrap_err()
            .contains("mqtt://HOST[:PORT]")
    );
}

#[test]
fn names_are_checked_against_the_mission() {
    let text = "{\n  MasterTeam: iRobotCreate irobot\n}\nMasterTeam.main {\n  default: mode = A\n}\nMasterTeam.A {\n}\n";
    let catalog = crate::catalog::builtin_catalog();
    let analysis = crate::sema::check_source(FileId(0), text, &catalog);
    let deploy =
        "broker = \"mqtts://x\"\n[operator]\nuser = \"op\"\n[teams.MasterTeem]\n[robots.irobt]\n";
    let d = parse(deploy, FileId(1), std::path::Path::new("/")).unwrap();
    let found: Vec<String> = check(&d, &analysis.mission)
        .iter()
        .map(|d| {
            format!(
                "{} '{}': {}",
                d.code,
                &deploy[d.span.start..d.span.end],
                d.message
            )
        })
        .collect();
    assert_eq!(
        found,
        [
            "E121 'MasterTeem': the mission has no team `MasterTeem` (did you mean `MasterTeam`?)",
            "E121 'irobt': the mission has no robot `irobt` (did you mean `irobot`?)",
            "E120 '\"mqtts://x\"': the operator connects with TLS (mqtts://) but has no `ca` to check the broker with: give `ca` at the top or in [operator]",
            "E120 '\"mqtts://x\"': robot `irobot` connects with TLS (mqtts://) but has no `ca` to check the broker with: give `ca` at the top, in [teams.MasterTeam] or in [robots.irobot]"
        ]
    );
}

/// The refined programs of a small mission in the file `file_name`: Base
/// asks Rover, Rover answers, the operator commands Base.
fn programs(file_name: &str) -> Vec<crate::refine::RobotProgram> {
    let text = "{\n  Base: iRobotCreate base\n  Rover: iRobotCreate rover\n}\nBase.Talk.Ask{\n  receive(USER, USER.GO)\n  send(Rover, Base.LOCATION)\n} repeat(1 SEC)\nRover.Talk.Hear{ receive(Base, Base.LOCATION) } repeat()\nBase.RUN{ set(Talk, Ask) }\nBase.main{ default: mode = RUN }\nRover.RUN{ set(Talk, Hear) }\nRover.main{ default: mode = RUN }\n";
    let catalog = crate::catalog::builtin_catalog();
    let analysis = crate::sema::check_source(FileId(0), text, &catalog);
    let links = crate::strategy::StrategyLinks::default();
    let input = crate::refine::BuildInput {
        mission: FileId(0),
        mission_name: file_name.to_string(),
        text,
        analysis: &analysis,
        catalog: &catalog,
        strategies: &[],
        strategy_names: Vec::new(),
        links: &links,
        diagnostics: &analysis.diagnostics,
        service_graphs: &[],
    };
    let refined = crate::refine::refine_checked(&input);
    assert_eq!(refined.programs.len(), 2, "{:?}", refined.diagnostics);
    refined.programs
}

/// What the deployment of [`programs`] is made of, each value as hostile
/// as a test likes.
#[derive(Clone, Debug)]
struct Values {
    mission_file: String,
    out: String,
    base_user: String,
    rover_user: String,
    operator_user: String,
    broker_user: Option<String>,
    host: String,
    password_file: String,
    ca: String,
    cert: String,
    key: String,
    tls: bool,
}

impl Values {
    fn deployment(&self) -> Deployment {
        let credentials = |user: &str| Credentials {
            user: Some(user.to_string()),
            ..Credentials::default()
        };
        let named = |name: &str, value| Named {
            name: name.to_string(),
            span: Span::default(),
            value,
        };
        Deployment {
            file: FileId(1),
            broker: BrokerUrl {
                url: String::new(),
                tls: self.tls,
                host: self.host.clone(),
                port: 1883,
                span: Span::default(),
            },
            ca: Some(PathBuf::from(&self.ca)),
            broker_config: BrokerSide {
                password_file: Some(PathBuf::from(&self.password_file)),
                user: self.broker_user.clone(),
                cert: Some(PathBuf::from(&self.cert)),
                key: Some(PathBuf::from(&self.key)),
            },
            operator: Some(named("operator", credentials(&self.operator_user))),
            teams: vec![
                named("Base", credentials(&self.base_user)),
                named("Rover", credentials(&self.rover_user)),
            ],
            robots: Vec::new(),
        }
    }

    /// Whether every value is one a line of the broker's files carries as
    /// it is (`lines`' rules, written out again here).
    fn all_writable(&self) -> bool {
        let value = |v: &str| {
            !v.is_empty()
                && !v.chars().any(char::is_control)
                && !v.starts_with(' ')
                && !v.ends_with(' ')
        };
        let users = [&self.base_user, &self.rover_user, &self.operator_user];
        let mut paths = vec![&self.password_file, &self.host];
        if self.tls {
            paths.extend([&self.ca, &self.cert, &self.key]);
        }
        users.iter().all(|u| value(u) && !u.contains(':'))
            && paths.iter().all(|p| value(p))
            && self.broker_user.as_deref().is_none_or(value)
            && !self.mission_file.chars().any(char::is_control)
            && value(&format!("{}/semo.acl", self.out))
            // Distinct users: the operator's must not be a robot's.
            && self.operator_user != self.base_user
            && self.operator_user != self.rover_user
    }
}

/// mosquitto's reading of its configuration and ACL files (`conf.c`,
/// `security_default.c`): lines cut at `\n`, blanks at the end dropped, a
/// `#` line a comment, the keyword up to the first space (leading spaces
/// skipped) and the value the rest, trimmed. `(keyword, value)` per line.
fn as_mosquitto_reads(text: &str) -> Vec<(String, String)> {
    let blank = |c: char| matches!(c, ' ' | '\t' | '\n' | '\x0b' | '\x0c' | '\r');
    text.split('\n')
        .map(|line| line.trim_end_matches(blank))
        .filter(|line| !line.is_empty() && !line.starts_with('#'))
        .map(|line| {
            let line = line.trim_start_matches(' ');
            let (keyword, rest) = line.split_once(' ').unwrap_or((line, ""));
            (
                keyword.to_string(),
                rest.trim_matches(|c| c == ' ' || c == '\t').to_string(),
            )
        })
        .collect()
}

/// The directives the configuration must hold, exactly.
fn expected_config(v: &Values, out: &Path) -> Vec<(String, String)> {
    let mut lines: Vec<(&str, String)> = vec![
        ("per_listener_settings", "false".into()),
        ("allow_anonymous", "false".into()),
        ("password_file", v.password_file.clone()),
        ("acl_file", out.join("semo.acl").display().to_string()),
        ("set_tcp_nodelay", "true".into()),
        ("persistence", "true".into()),
        (
            "persistence_location",
            format!("{}/", out.join("persistence").display()),
        ),
        (
            "user",
            v.broker_user.clone().unwrap_or_else(|| "mosquitto".into()),
        ),
        (
            "listener",
            if v.host.starts_with("127.") {
                format!("1883 {}", v.host)
            } else {
                "1883".into()
            },
        ),
    ];
    if v.tls {
        lines.extend([
            ("cafile", v.ca.clone()),
            ("certfile", v.cert.clone()),
            ("keyfile", v.key.clone()),
            ("require_certificate", "false".into()),
        ]);
    }
    lines.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// Checks the ACL as mosquitto reads it: exactly the deployment's users,
/// each followed only by `topic read|write` lines of the mission's topics,
/// in every run.
fn check_acl(acl: &str, v: &Values) -> Result<(), String> {
    let mission = crate::deploy::topics::level(&crate::deploy::topics::mission(&v.mission_file));
    let prefix = format!("semo/{mission}/+/");
    let mut users = BTreeSet::new();
    for (keyword, value) in as_mosquitto_reads(acl) {
        match keyword.as_str() {
            "user" => {
                users.insert(value);
            }
            "topic" if !users.is_empty() => {
                let (access, topic) = value.split_once(' ').ok_or(format!("topic {value:?}"))?;
                if !["read", "write"].contains(&access) || !topic.starts_with(&prefix) {
                    return Err(format!("topic {access} {topic:?}"));
                }
            }
            other => return Err(format!("directive {other:?} {value:?}")),
        }
    }
    let expected: BTreeSet<String> = [&v.base_user, &v.rover_user, &v.operator_user]
        .into_iter()
        .cloned()
        .collect();
    if users != expected {
        return Err(format!("users {users:?}, not {expected:?}"));
    }
    Ok(())
}

fn clean_values() -> Values {
    Values {
        mission_file: "pair.mission".into(),
        out: "/srv/semo broker".into(),
        base_user: "base".into(),
        rover_user: "rover".into(),
        operator_user: "operator".into(),
        broker_user: None,
        host: "127.0.0.1".into(),
        password_file: "/etc/mosquitto/semo.passwd".into(),
        ca: "/etc/ca.crt".into(),
        cert: "/etc/server.crt".into(),
        key: "/etc/server.key".into(),
        tls: true,
    }
}

/// Writes the broker's files for `v` and checks them as mosquitto reads
/// them; `Ok(false)` when refused.
fn round_trip(v: &Values) -> Result<bool, String> {
    let out = PathBuf::from(&v.out);
    let files = match broker::files(
        &v.deployment(),
        &programs(&v.mission_file),
        &out,
        "x.deploy.toml",
    ) {
        Ok(files) => files,
        Err(_) => return Ok(false),
    };
    let read = as_mosquitto_reads(&files.config);
    if read != expected_config(v, &out) {
        return Err(format!(
            "configuration read back as {read:?}:\n{}",
            files.config
        ));
    }
    check_acl(&files.acl, v).map_err(|e| format!("{e}:\n{}", files.acl))?;
    Ok(true)
}

#[test]
fn the_broker_files_read_back_as_written() {
    assert_eq!(round_trip(&clean_values()), Ok(true));
    let acl = broker::files(
        &clean_values().deployment(),
        &programs("pair.mission"),
        Path::new("/srv/b"),
        "x",
    )
    .unwrap()
    .acl;
    // Each user writes only topics naming its own robot as the sender.
    assert!(
        acl.contains("user base\ntopic write semo/pair/+/Rover/Base.LOCATION/Base/base\n"),
        "{acl}"
    );
    assert!(
        acl.contains("user operator\ntopic write semo/pair/+/Base/USER.GO/USER/operator\n"),
        "{acl}"
    );
}

#[test]
fn a_value_that_would_add_a_directive_is_refused_never_written() {
    let hostile = [
        Values {
            base_user: "slaves\npattern readwrite #".into(),
            ..clean_values()
        },
        Values {
            mission_file: "m\nlistener 1883 0.0.0.0\n.mission".into(),
            ..clean_values()
        },
        Values {
            out: "/srv/x\nallow_anonymous true".into(),
            ..clean_values()
        },
        Values {
            password_file: "/p\rallow_anonymous true".into(),
            ..clean_values()
        },
        Values {
            host: "127.0.0.1\nallow_anonymous true".into(),
            ..clean_values()
        },
        Values {
            rover_user: "rover:x".into(),
            ..clean_values()
        },
    ];
    for v in &hostile {
        assert_eq!(round_trip(v), Ok(false), "{v:?}");
    }
    // The refusal says what cannot be written and why.
    let Err(broker::Refusal::Unwritable(why)) = broker::files(
        &hostile[1].deployment(),
        &programs(&hostile[1].mission_file),
        Path::new("/srv"),
        "x",
    ) else {
        panic!("refused")
    };
    assert!(
        why.contains("mission's name") && why.contains("U+000A"),
        "{why}"
    );
}

/// The C string literals of `semo_deploy.h`, as a C11 compiler reads them
/// (escapes and trigraphs): `(macro, bytes)`; an error for any line that is
/// not the header's own.
fn as_c_reads(header: &str) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut defines = Vec::new();
    let mut in_comment = false;
    for line in header.split('\n') {
        if in_comment || line.starts_with("/*") {
            in_comment = !line.contains("*/");
            continue;
        }
        if [
            "#ifndef SEMO_DEPLOY_H",
            "#define SEMO_DEPLOY_H",
            "#endif",
            "",
        ]
        .contains(&line)
        {
            continue;
        }
        let rest = line
            .strip_prefix("#define ")
            .ok_or(format!("line {line:?}"))?;
        let (name, literal) = rest.split_once(' ').ok_or(format!("line {line:?}"))?;
        if literal.contains("??") || literal.contains('\r') {
            return Err(format!("a trigraph or a carriage return in {literal:?}"));
        }
        let body = literal
            .strip_prefix('"')
            .and_then(|l| l.strip_suffix('"'))
            .ok_or(format!("literal {literal:?}"))?;
        let mut bytes = Vec::new();
        let mut chars = body.bytes().peekable();
        while let Some(b) = chars.next() {
            match b {
                b'"' => return Err(format!("an unescaped quote in {literal:?}")),
                b'\\' => match chars.next() {
                    Some(b'n') => bytes.push(b'\n'),
                    Some(c @ (b'"' | b'\\' | b'?')) => bytes.push(c),
                    Some(d @ b'0'..=b'7') => {
                        let mut value = u32::from(d - b'0');
                        for _ in 0..2 {
                            match chars.peek() {
                                Some(&d @ b'0'..=b'7') => {
                                    value = value * 8 + u32::from(d - b'0');
                                    chars.next();
                                }
                                _ => break,
                            }
                        }
                        bytes.push(value as u8);
                    }
                    other => return Err(format!("escape {other:?} in {literal:?}")),
                },
                b => bytes.push(b),
            }
        }
        defines.push((name.to_string(), bytes));
    }
    Ok(defines)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

    /// Hostile names and paths (line breaks, carriage returns, NULs, `:`,
    /// `#`, blanks at the ends) through every writer of the broker's files:
    /// refused, or read back by mosquitto as exactly the lines intended,
    /// never an extra directive; and anything clean is written.
    #[test]
    fn hostile_values_never_add_a_directive(
        user in "[a-z \n\r\t:#\u{0}\u{85}é]{0,8}",
        path in "/[a-z \n\r/#\u{b}é]{0,8}",
        mission in "[a-z \n.\u{0}é]{0,10}",
        broker_user in proptest::option::of("[a-z \n]{0,6}"),
        tls in proptest::bool::ANY,
    ) {
        let v = Values {
            mission_file: mission,
            out: format!("/srv{path}"),
            base_user: user.clone(),
            broker_user,
            password_file: path.clone(),
            cert: format!("{path}.crt"),
            tls,
            ..clean_values()
        };
        let written = round_trip(&v).map_err(proptest::test_runner::TestCaseError::fail)?;
        proptest::prop_assert_eq!(written, v.all_writable(), "{:?}", v);
    }

    /// The same through `semo_deploy.h`: every value a C compiler reads
    /// back is exactly the value, whatever it holds (quotes, backslashes,
    /// `??` trigraphs, line breaks, bytes beyond ASCII).
    #[test]
    fn the_baked_header_reads_back_as_the_values(
        user in "[a-z\"\\\\?\n\r\t\u{0}é/*]{0,10}",
        path in "[a-z\"\\\\?\n/*é]{0,10}",
    ) {
        let connection = RobotConnection {
            broker: format!("mqtt://{path}"),
            client_id: Some(user.clone()),
            credentials: Credentials {
                user: Some(user.clone()),
                password_file: Some(PathBuf::from(&path)),
                ca: None,
                cert: None,
                key: None,
            },
        };
        let read = as_c_reads(&header(&connection)).map_err(proptest::test_runner::TestCaseError::fail)?;
        let expected: Vec<(String, Vec<u8>)> = [
            ("SEMO_DEPLOY_BROKER", format!("mqtt://{path}")),
            ("SEMO_DEPLOY_CLIENT_ID", user.clone()),
            ("SEMO_DEPLOY_USER", user),
            ("SEMO_DEPLOY_PASSWORD_FILE", path),
        ]
        .into_iter()
        .map(|(n, v)| (n.to_string(), v.into_bytes()))
        .collect();
        proptest::prop_assert_eq!(read, expected);
    }
}
