//! The deployment format: what a file means, and each mistake positioned.

use super::*;
use crate::diag::FileId;

/// A folder with the files a deployment names.
fn folder(files: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in files {
        std::fs::write(dir.path().join(name), "x\n").unwrap();
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
            "broker = \"mqtt://x\"\n[robots.ti]\ncert = \"c\"\nid = 4\n",
            &["c"]
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
fn names_are_checked_against_the_mission() {
    let text = "{\n  MasterTeam: iRobotCreate irobot\n}\nMasterTeam.main {\n  default: mode = A\n}\nMasterTeam.A {\n}\n";
    let catalog = crate::catalog::builtin_catalog();
    let analysis = crate::sema::check_source(FileId(0), text, &catalog);
    let deploy = "broker = \"mqtts://x\"\n[teams.MasterTeem]\n[robots.irobt]\n";
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
            "E120 '\"mqtts://x\"': robot `irobot` connects with TLS (mqtts://) but has no `ca` to check the broker with: give `ca` at the top, in [teams.MasterTeam] or in [robots.irobot]"
        ]
    );
}
