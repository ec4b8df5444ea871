//! The deployment format: what a file means, and each mistake positioned.

use super::*;
use crate::diag::FileId;

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
