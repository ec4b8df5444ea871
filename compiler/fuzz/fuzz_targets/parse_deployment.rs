//! Reads arbitrary text as a `*.deploy.toml` deployment file, checks it
//! against a mission and writes the broker's files for it: must never
//! panic, every diagnostic range must lie inside the text on character
//! boundaries, and the broker's files must be lines mosquitto reads as
//! written (no control character but the line breaks).
#![no_main]

use libfuzzer_sys::fuzz_target;
use semo::deploy::broker::{self, Refusal};
use semo::diag::{Diagnostic, FileId};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

const FILE: FileId = FileId(0);

struct Mission {
    analysis: Arc<semo::CheckedMission>,
    programs: Vec<semo::refine::RobotProgram>,
}

/// The deployment fixtures' mission (teams Base and Rover), refined.
fn mission() -> &'static Mission {
    static MISSION: OnceLock<Mission> = OnceLock::new();
    MISSION.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/fixtures/build/E121_deploy_unknown_robot/pair.mission");
        let (run, id) = semo::host::load_build(&path, &[]).expect("the mission loads");
        let build = run.analysis().build_input(id).expect("the mission checks");
        let programs = semo::refine::refine_checked(&build.input()).programs;
        assert!(!programs.is_empty());
        Mission {
            analysis: build.analysis.clone(),
            programs,
        }
    })
}

/// The folder relative paths are read against: the files the fixtures name,
/// holding what they should.
fn folder() -> &'static Path {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join("semo-fuzz-deploy");
        std::fs::create_dir_all(&dir).unwrap();
        for (name, text) in [
            (
                "ca.crt",
                "-----BEGIN CERTIFICATE-----\nMIIBAA==\n-----END CERTIFICATE-----\n",
            ),
            (
                "rover.crt",
                "-----BEGIN CERTIFICATE-----\nMIIBAA==\n-----END CERTIFICATE-----\n",
            ),
            (
                "rover.key",
                "-----BEGIN PRIVATE KEY-----\nMIIBAA==\n-----END PRIVATE KEY-----\n",
            ),
            ("rovers.pw", "secret\n"),
        ] {
            std::fs::write(dir.join(name), text).unwrap();
        }
        dir
    })
}

fn inside(text: &str, d: &Diagnostic) {
    assert_eq!(d.file, FILE);
    assert!(d.span.start <= d.span.end && d.span.end <= text.len());
    assert!(text.is_char_boundary(d.span.start) && text.is_char_boundary(d.span.end));
    assert!(!d.message.contains('\n'));
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let deployment = match semo::deploy::parse(&text, FILE, folder()) {
        Ok(deployment) => deployment,
        Err(diagnostics) => {
            assert!(!diagnostics.is_empty());
            for d in &diagnostics {
                inside(&text, d);
            }
            return;
        }
    };
    let mission = mission();
    for d in &semo::deploy::check(&deployment, &mission.analysis.mission) {
        inside(&text, d);
    }
    match broker::files(
        &deployment,
        &mission.programs,
        Path::new("/srv/semo"),
        "fuzz.deploy.toml",
    ) {
        Ok(files) => {
            for file in [&files.config, &files.acl] {
                assert!(!file.chars().any(|c| c.is_control() && c != '\n'));
            }
        }
        Err(Refusal::Deployment(diagnostics)) => {
            for d in &diagnostics {
                inside(&text, d);
            }
        }
        Err(Refusal::Unwritable(why)) => assert!(!why.is_empty()),
    }
});
