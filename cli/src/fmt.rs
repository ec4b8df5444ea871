//! `semo fmt`: rewrites mission scripts in the canonical layout
//! ([`semo::format`]). A file is rewritten only when its layout changes, by
//! writing a temporary file beside it and renaming it over the original, so
//! that a failure never leaves a truncated file. Files with syntax errors are
//! left as they are and reported.

use semo::format::{FormatRefusal, format_source};
use semo::text::{ColumnUnit, LineIndex};
use semo::workspace::{self, FileKind};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// What to do with the formatted text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Rewrite the files that change.
    InPlace,
    /// Write nothing; list the files that would change.
    Check,
    /// Print the formatted text.
    Stdout,
    /// Write nothing; print a unified diff of what would change.
    Diff,
}

/// Where a mission comes from.
enum Input {
    File(PathBuf),
    Stdin,
}

impl Input {
    fn name(&self) -> String {
        match self {
            Input::File(path) => path.display().to_string(),
            Input::Stdin => "<stdin>".to_string(),
        }
    }
}

/// Runs `semo fmt`. Exit code: 0 when every file is formatted (or, with
/// `--check`, already was), 1 when a file was refused (syntax errors, not
/// UTF-8) or, with `--check`, would change, 2 for a path or I/O problem.
pub fn run(paths: Vec<PathBuf>, mode: Mode, out: &mut impl Write) -> i32 {
    let paths = if paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        paths
    };
    let mut code = 0;
    let mut inputs = Vec::new();
    for path in paths {
        if path.as_os_str() == "-" {
            inputs.push(Input::Stdin);
            continue;
        }
        match workspace::collect(std::slice::from_ref(&path)) {
            Err(e) => {
                eprintln!("error: {e}");
                code = 2;
            }
            Ok(found) => {
                let named_file = found.len() == 1 && found[0].0 == path;
                for (file, kind) in found {
                    if kind == FileKind::Mission {
                        inputs.push(Input::File(file));
                    } else if named_file {
                        eprintln!(
                            "error: {}: not a mission script (`semo fmt` formats *.mission files)",
                            file.display()
                        );
                        code = 2;
                    }
                }
            }
        }
    }
    for input in &inputs {
        code = code.max(one(input, mode, out));
    }
    code
}

fn read(input: &Input) -> io::Result<Vec<u8>> {
    match input {
        Input::File(path) => std::fs::read(path),
        Input::Stdin => {
            let mut bytes = Vec::new();
            io::Read::read_to_end(&mut io::stdin(), &mut bytes)?;
            Ok(bytes)
        }
    }
}

/// Formats one input; gives its exit code.
fn one(input: &Input, mode: Mode, out: &mut impl Write) -> i32 {
    let name = input.name();
    let bytes = match read(input) {
        Ok(bytes) => bytes,
        Err(e) => {
            eprintln!("error: {name}: {e}");
            return 2;
        }
    };
    // Replacing invalid bytes would lose them: such a file is left alone.
    let Ok(text) = String::from_utf8(bytes) else {
        eprintln!("error: {name}: not UTF-8 text; not formatted");
        return 1;
    };
    let formatted = match format_source(&text) {
        Ok(formatted) => formatted,
        Err(refusal) => {
            eprintln!("error: {}; not formatted", describe(&name, &text, &refusal));
            return 1;
        }
    };
    let changed = formatted != text;
    let written = match (mode, input) {
        (Mode::Check, _) if changed => writeln!(out, "{name}").map(|()| 1),
        (Mode::Check, _) => Ok(0),
        (Mode::Diff, _) if changed => out
            .write_all(unified_diff(&name, &text, &formatted).as_bytes())
            .map(|()| 1),
        (Mode::Diff, _) => Ok(0),
        (Mode::Stdout, _) | (Mode::InPlace, Input::Stdin) => {
            out.write_all(formatted.as_bytes()).map(|()| 0)
        }
        (Mode::InPlace, Input::File(_)) if !changed => Ok(0),
        (Mode::InPlace, Input::File(path)) => match write_replacing(path, &formatted) {
            Ok(()) => writeln!(out, "formatted {name}").map(|()| 0),
            Err(e) => {
                eprintln!("error: {name}: cannot write the formatted text: {e}");
                Ok(2)
            }
        },
    };
    match written {
        Ok(code) => code,
        // The reader went away (`semo fmt --stdout f | head`).
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            eprintln!("error: cannot write the output: {e}");
            2
        }
    }
}

/// What formatting changes, as `git apply` and `patch -p1` read it: the old
/// text under `a/NAME`, the new under `b/NAME` (an absolute NAME as it is),
/// three lines of context.
fn unified_diff(name: &str, old: &str, new: &str) -> String {
    let (old_name, new_name) = if name.starts_with('/') {
        (name.to_string(), name.to_string())
    } else {
        (format!("a/{name}"), format!("b/{name}"))
    };
    similar::TextDiff::from_lines(old, new)
        .unified_diff()
        .context_radius(3)
        .header(&old_name, &new_name)
        .to_string()
}

/// `file:line:column: reason`, the position counted in characters from 1.
fn describe(name: &str, text: &str, refusal: &FormatRefusal) -> String {
    match refusal.span() {
        Some(span) => {
            let at = LineIndex::new(text).line_col(text, span.start, ColumnUnit::Char);
            format!("{name}:{}:{}: {refusal}", at.line + 1, at.col + 1)
        }
        None => format!("{name}: {refusal}"),
    }
}

/// Replaces the file at `path` (the file a symbolic link points to, not the
/// link) by `text`: a temporary file in the same folder, with the original's
/// permissions, renamed over it. Either the old text stays or the new one is
/// there whole. A read-only file is not replaced.
pub fn write_replacing(path: &Path, text: &str) -> io::Result<()> {
    let target = std::fs::canonicalize(path)?;
    let permissions = std::fs::metadata(&target)?.permissions();
    if permissions.readonly() {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only",
        ));
    }
    let folder = target.parent().unwrap_or(Path::new("."));
    let name = target
        .file_name()
        .map_or_else(|| "mission".into(), |n| n.to_string_lossy());
    let (temp, mut file) = create_temp(folder, &name)?;
    let written = (|| {
        file.write_all(text.as_bytes())?;
        file.sync_all()?;
        drop(file);
        std::fs::set_permissions(&temp, permissions)?;
        std::fs::rename(&temp, &target)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    written
}

/// A new file `.NAME.semo-fmt-PID-N` in `folder`, never one that exists.
fn create_temp(folder: &Path, name: &str) -> io::Result<(PathBuf, std::fs::File)> {
    let pid = std::process::id();
    let mut n = 0;
    loop {
        let temp = folder.join(format!(".{name}.semo-fmt-{pid}-{n}"));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
        {
            Ok(file) => return Ok((temp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && n < 100 => n += 1,
            Err(e) => return Err(e),
        }
    }
}
