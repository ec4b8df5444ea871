//! `semo build --deploy FILE` (reading the deployment file) and `semo
//! deploy broker-config`: the broker's configuration and ACL for a mission.

use super::output::{self, Format};
use super::render;
use semo::deploy::{self, Deployment, broker};
use semo::diag::Diagnostic;
use semo::host::{self, CheckRun};
use semo::workspace::FileKind;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The mission's build and, with `--deploy FILE`, its deployment: what the
/// doors that join a running fleet (the operator console, the gateway)
/// start from. `Err`: the exit status, the reason said.
pub fn load_fleet(
    mission: &Path,
    strategy: &[PathBuf],
    deploy: Option<&Path>,
    color: bool,
    out: &mut impl Write,
) -> Result<(CheckRun, semo::diag::FileId, Option<Deployment>), i32> {
    let (mut run, id) = host::load_build(mission, strategy).map_err(|e| {
        eprintln!("error: {e}");
        2
    })?;
    let deployment = match deploy {
        None => None,
        Some(path) => Some(load(&mut run, path, Format::Human, color, out)?),
    };
    Ok((run, id, deployment))
}

/// Reads and parses a deployment file into `run.files` (so that its
/// diagnostics render and report like the check's; it is not one of
/// `run.checked`, and `Files` has no kind for it, so it is labelled a
/// mission only for that table). `Err(2)`: unreadable (said on stderr);
/// `Err(1)`: refused, its diagnostics reported.
pub fn load(
    run: &mut CheckRun,
    path: &Path,
    format: Format,
    color: bool,
    out: &mut impl Write,
) -> Result<Deployment, i32> {
    let text = match semo::workspace::read_text(path) {
        Ok(text) => text,
        Err(e) => {
            eprintln!(
                "error: cannot read the deployment file {}: {e}",
                path.display()
            );
            return Err(2);
        }
    };
    let file = run
        .files
        .add(path.to_path_buf(), FileKind::Mission, text.clone());
    let base = path.parent().unwrap_or(Path::new("."));
    deploy::parse(&text, file, base).map_err(|found| refuse(run, found, format, color, out))
}

/// Reports the deployment file's diagnostics as `format` says and that the
/// command was refused; returns 1 (2 when the report cannot be written).
pub fn refuse(
    run: &mut CheckRun,
    found: Vec<Diagnostic>,
    format: Format,
    color: bool,
    out: &mut impl Write,
) -> i32 {
    run.diagnostics = found;
    let reported = output::report(
        format,
        "build",
        &run.files,
        &run.diagnostics,
        color,
        serde_json::json!({ "robots": [] }),
        out,
    );
    if let Err(code) = output::written(reported) {
        return code;
    }
    let errors = run.diagnostics.iter().filter(|d| d.is_error()).count();
    eprintln!(
        "error: refused: {errors} error{} in the deployment file",
        if errors == 1 { "" } else { "s" }
    );
    1
}

/// `semo deploy broker-config MISSION --deploy FILE -o DIR`.
pub fn broker_config(
    mission: &Path,
    strategy: &[PathBuf],
    deploy_file: &Path,
    out_dir: &Path,
    color: bool,
    out: &mut impl Write,
) -> i32 {
    let (mut run, mission) = match host::load_build(mission, strategy) {
        Ok(loaded) => loaded,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let deployment = match load(&mut run, deploy_file, Format::Human, color, out) {
        Ok(deployment) => deployment,
        Err(code) => return code,
    };
    let analysis = run.analysis();
    let input = match super::build_files(&analysis, mission) {
        Ok(files) => files,
        Err(code) => return code,
    };
    let input = input.input();
    let Some(refined) = analysis.refined(mission) else {
        eprintln!("error: internal error: the mission is not in the workspace analysis");
        return 2;
    };
    if refined.programs.is_empty() {
        run.diagnostics = refined.diagnostics.clone();
        let _ = render::human(&run, Format::Human, color, &mut std::io::stderr());
        eprintln!("error: refused: fix the errors above first");
        return 1;
    }
    let mut found = deploy::check(&deployment, &input.analysis.mission);
    let out_dir = std::path::absolute(out_dir).unwrap_or_else(|_| out_dir.to_path_buf());
    let source = deploy_file.display().to_string();
    let files = match broker::files(&deployment, &refined.programs, &out_dir, &source) {
        Ok(files) if !found.iter().any(|d| d.is_error()) => files,
        Ok(_) => return refuse(&mut run, found, Format::Human, color, out),
        Err(broker::Refusal::Deployment(more)) => {
            found.extend(more);
            return refuse(&mut run, found, Format::Human, color, out);
        }
        Err(broker::Refusal::Unwritable(why)) => {
            eprintln!("error: refused: {why}");
            return 1;
        }
    };
    let persistence = out_dir.join(broker::PERSISTENCE_DIR);
    let written = std::fs::create_dir_all(&persistence)
        .and_then(|()| write_file(&out_dir.join(broker::ACL_FILE), &files.acl))
        .and_then(|()| write_file(&out_dir.join(broker::CONFIG_FILE), &files.config));
    if let Err(e) = written {
        eprintln!("error: cannot write into {}: {e}", out_dir.display());
        return 2;
    }
    let config = out_dir.join(broker::CONFIG_FILE);
    let user = deployment.broker_config.run_as();
    let _ = writeln!(
        out,
        "wrote {} and {} (start the broker with `mosquitto -c {}`; started as root it runs as `{user}`, which must own {} and read the password file: `chown {user} {} {}`)",
        config.display(),
        out_dir.join(broker::ACL_FILE).display(),
        config.display(),
        persistence.display(),
        persistence.display(),
        deployment
            .broker_config
            .password_file
            .as_ref()
            .map_or(String::new(), |p| p.display().to_string()),
    );
    0
}

/// Written beside and renamed over: a broker never reads half a file.
fn write_file(path: &Path, text: &str) -> std::io::Result<()> {
    let partial = path.with_extension("partial");
    std::fs::write(&partial, text)?;
    std::fs::rename(&partial, path)
}
