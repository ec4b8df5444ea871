//! `semo build --deploy FILE` (reading the deployment file) and `semo
//! deploy broker-config`: the broker's configuration and ACL for a mission.

use super::render;
use semo::codegen;
use semo::deploy::{self, Deployment, broker};
use semo::diag::{Diagnostic, FileId};
use semo::host;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A deployment file as read: its text, for rendering its diagnostics.
pub struct DeployFile {
    pub path: PathBuf,
    pub text: String,
}

/// The id the deployment file's diagnostics carry: past every file of the
/// check, so never one of them.
const DEPLOY_FILE: FileId = FileId(u32::MAX);

/// Reads and parses a deployment file. `Err(2)`: unreadable (said on
/// stderr); `Err(1)`: its diagnostics were printed.
pub fn load(
    path: &Path,
    color: bool,
    out: &mut impl Write,
) -> Result<(Deployment, DeployFile), i32> {
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
    let file = DeployFile {
        path: path.to_path_buf(),
        text,
    };
    let base = path.parent().unwrap_or(Path::new("."));
    match deploy::parse(&file.text, DEPLOY_FILE, base) {
        Ok(deployment) => Ok((deployment, file)),
        Err(found) => Err(refuse(&file, &found, color, out)),
    }
}

/// Prints the deployment file's diagnostics and says the command was
/// refused; returns 1.
pub fn refuse(file: &DeployFile, found: &[Diagnostic], color: bool, out: &mut impl Write) -> i32 {
    let _ = render_in(file, found, color, out);
    let errors = found.iter().filter(|d| d.is_error()).count();
    let _ = writeln!(
        out,
        "error: refused: {errors} error{} in the deployment file",
        if errors == 1 { "" } else { "s" }
    );
    1
}

/// Diagnostics in the deployment file, as `render` shows a check's.
fn render_in(
    file: &DeployFile,
    found: &[Diagnostic],
    colored: bool,
    out: &mut impl Write,
) -> std::io::Result<()> {
    use ariadne::{Config, IndexType, Label, Report};
    let config = Config::default()
        .with_color(colored)
        .with_index_type(IndexType::Byte);
    let name = file.path.display().to_string();
    let mut cache = ariadne::sources([(name.clone(), file.text.clone())]);
    for d in found {
        let range = render::safe_range(&file.text, d.span);
        let mut report = Report::build(render::kind(d.severity), (name.clone(), range.clone()))
            .with_config(config)
            .with_code(d.code.as_str())
            .with_message(&d.message)
            .with_label(
                Label::new((name.clone(), range))
                    .with_message(d.code.summary())
                    .with_color(render::color(d.severity)),
            );
        if let Some(s) = &d.suggestion {
            report = report.with_help(format!("did you mean `{s}`?"));
        }
        report.finish().write(&mut cache, &mut *out)?;
    }
    Ok(())
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
    let (deployment, file) = match load(deploy_file, color, out) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let Some(input) = run.analysis().build_input(mission) else {
        eprintln!("internal error: the mission was loaded but not checked");
        return 2;
    };
    let input = input.input();
    let refined = codegen::refine_checked(&input);
    if refined.programs.is_empty() {
        run.diagnostics = refined.diagnostics;
        let _ = render::human(&run, color, out);
        let _ = writeln!(out, "error: refused: fix the errors above first");
        return 1;
    }
    let mut found = deploy::check(&deployment, &input.analysis.mission);
    let out_dir = std::path::absolute(out_dir).unwrap_or_else(|_| out_dir.to_path_buf());
    let source = deploy_file.display().to_string();
    let files = match broker::files(&deployment, &refined.programs, &out_dir, &source) {
        Ok(files) if !found.iter().any(|d| d.is_error()) => files,
        Ok(_) => return refuse(&file, &found, color, out),
        Err(more) => {
            found.extend(more);
            return refuse(&file, &found, color, out);
        }
    };
    let written = std::fs::create_dir_all(&out_dir)
        .and_then(|()| write_file(&out_dir.join(broker::ACL_FILE), &files.acl))
        .and_then(|()| write_file(&out_dir.join(broker::CONFIG_FILE), &files.config));
    if let Err(e) = written {
        eprintln!("error: cannot write into {}: {e}", out_dir.display());
        return 2;
    }
    let _ = writeln!(
        out,
        "wrote {} and {} (start the broker with `mosquitto -c {}`)",
        out_dir.join(broker::CONFIG_FILE).display(),
        out_dir.join(broker::ACL_FILE).display(),
        out_dir.join(broker::CONFIG_FILE).display()
    );
    0
}

/// Written beside and renamed over: a broker never reads half a file.
fn write_file(path: &Path, text: &str) -> std::io::Result<()> {
    let partial = path.with_extension("partial");
    std::fs::write(&partial, text)?;
    std::fs::rename(&partial, path)
}
