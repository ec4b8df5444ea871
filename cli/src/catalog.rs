//! `semo catalog [TYPE]`: the robot types missions may use, with their
//! services (signatures) and values (types): the built-in catalog and the
//! project's own catalog files (those under the catalog folders of the
//! `semo.toml` above the current folder, else those under the current
//! folder), as text or one JSON document. The operator console, `USER`, is
//! listed apart: it is no robot type.

use super::output::{self, Format};
use semo::catalog::{BUILTIN_FILE, Catalog, CatalogSource, RobotType, load_catalog};
use semo::diag::{Diagnostic, FileId};
use semo::workspace::{self, Bound, FileKind, Files};
use std::io::Write;
use std::path::PathBuf;

/// A robot type to list, or the operator console.
#[derive(Clone, Copy)]
enum Listed<'c> {
    Robot(&'c RobotType),
    Operator(&'c RobotType),
}

impl<'c> Listed<'c> {
    fn robot(self) -> &'c RobotType {
        match self {
            Listed::Robot(r) | Listed::Operator(r) => r,
        }
    }
}

pub fn run(type_name: Option<&str>, json: bool, color: bool, out: &mut impl Write) -> i32 {
    let format = if json { Format::Json } else { Format::Human };
    let (files, catalog, diagnostics) = match load() {
        Ok(loaded) => loaded,
        Err((path, message)) => return output::refused(format, "catalog", &path, &message, out),
    };
    let listed = match type_name {
        None => everything(&catalog),
        Some(name) => match one(&catalog, name) {
            Ok(listed) => vec![listed],
            Err(message) => {
                return output::refused(format, "catalog", &PathBuf::from("."), &message, out);
            }
        },
    };
    // People get the catalog files' diagnostics on standard error, the
    // listing on standard output; JSON, one document with both.
    let data = match format {
        Format::Json => document_fields(&listed, &files),
        _ => serde_json::Value::Null,
    };
    let mut written = output::report(format, "catalog", &files, &diagnostics, color, data, out);
    if format == Format::Human {
        written = written.and_then(|()| out.write_all(text(&listed, &files).as_bytes()));
    }
    if let Err(code) = output::written(written) {
        return code;
    }
    if diagnostics.iter().any(Diagnostic::is_error) {
        1
    } else {
        0
    }
}

/// The project's catalog files read, the catalog they make on top of the
/// built-in one, and their diagnostics.
fn load() -> Result<(Files, Catalog, Vec<Diagnostic>), (PathBuf, String)> {
    let mut files = Files::default();
    for path in catalog_files()? {
        let text = workspace::load_text(&path).map_err(|e| (path.clone(), e.message))?;
        files.add(path, FileKind::Catalog, text);
    }
    let sources: Vec<CatalogSource<'_>> = files
        .iter()
        .map(|f| CatalogSource {
            file: f.id,
            text: &f.text,
            base_dir: f.path.parent(),
        })
        .collect();
    let (catalog, mut diagnostics) = load_catalog(&sources);
    semo::diag::sort_and_dedup(&mut diagnostics);
    Ok((files, catalog, diagnostics))
}

/// The catalog files of the project around the current folder: under its
/// `semo.toml`'s catalog folders, else under the current folder (as deep as
/// a mission sees them, `host::SEEN_DEPTH`), as the user would name them.
fn catalog_files() -> Result<Vec<PathBuf>, (PathBuf, String)> {
    let found = match semo::project::find(&PathBuf::from(".")) {
        Some(root) => {
            let file = root.join(semo::project::FILE_NAME);
            // Its own mistakes are `semo check`'s to report.
            let text = workspace::load_text(&file).map_err(|e| (file.clone(), e.message))?;
            let (project, _) = semo::project::parse(FileId::default(), &root, &text);
            let folders: Vec<PathBuf> = project
                .catalogs
                .iter()
                .map(|f| f.path.clone())
                .filter(|f| f.is_dir())
                .collect();
            workspace::collect(&folders).map_err(|e| (e.path, e.message))?
        }
        None => {
            let bound = Bound {
                depth: semo::host::SEEN_DEPTH,
                entries: semo::host::MAX_ENTRIES,
            };
            workspace::collect_bounded(&PathBuf::from("."), bound)
                .map_err(|e| (e.path, e.message))?
                .0
        }
    };
    let mut paths: Vec<PathBuf> = found
        .into_iter()
        .filter(|(_, kind)| *kind == FileKind::Catalog)
        .map(|(path, _)| shown(&path))
        .collect();
    paths.sort();
    paths.dedup();
    Ok(paths)
}

/// A path found from the current folder, as the user would write it.
fn shown(path: &std::path::Path) -> PathBuf {
    if path.is_absolute() {
        super::defaults::from_here(path)
    } else {
        path.strip_prefix(".").unwrap_or(path).to_path_buf()
    }
}

/// Every robot type, in the catalog's order (built-in first, then the
/// project's), and the operator console last.
fn everything(catalog: &Catalog) -> Vec<Listed<'_>> {
    catalog
        .types()
        .map(|(_, r)| Listed::Robot(r))
        .chain(catalog.user().map(Listed::Operator))
        .collect()
}

/// The type named `name` (or an alias; `USER` is the operator console),
/// else why not, with a did-you-mean.
fn one<'c>(catalog: &'c Catalog, name: &str) -> Result<Listed<'c>, String> {
    if let Some(robot) = catalog.robot(name) {
        return Ok(Listed::Robot(robot));
    }
    let operator = catalog
        .user()
        .filter(|u| u.name == name || u.aliases.iter().any(|a| a == name));
    if let Some(user) = operator {
        return Ok(Listed::Operator(user));
    }
    let mut known: Vec<&str> = catalog.types().map(|(_, r)| r.name.as_str()).collect();
    let message = format!(
        "no robot type `{name}` in the catalog (types: {})",
        known.join(", ")
    );
    known.extend(catalog.names());
    Err(
        match semo::suggest::did_you_mean(name, known.iter().copied()) {
            Some(close) => format!("{message} (did you mean `{close}`?)"),
            None => message,
        },
    )
}

/// Where a type was written: `built-in`, or its catalog file.
fn source(robot: &RobotType, files: &Files) -> String {
    if robot.origin.file == BUILTIN_FILE {
        "built-in".to_string()
    } else {
        files.get(robot.origin.file).path.display().to_string()
    }
}

/// `; also: a, b` for names with aliases.
fn also_in(aliases: &[String]) -> String {
    if aliases.is_empty() {
        String::new()
    } else {
        format!("; also: {}", aliases.join(", "))
    }
}

/// ` (also: a, b)` for names with aliases.
fn also(aliases: &[String]) -> String {
    if aliases.is_empty() {
        String::new()
    } else {
        format!(" (also: {})", aliases.join(", "))
    }
}

/// The listing for people: each type, its doc, then its services and
/// values, one per line with the doc aligned after the signature.
fn text(listed: &[Listed<'_>], files: &Files) -> String {
    let mut text = String::new();
    for (i, entry) in listed.iter().enumerate() {
        if i > 0 {
            text.push('\n');
        }
        let robot = entry.robot();
        let (what, values_title) = match entry {
            Listed::Robot(_) => (String::new(), "values:".to_string()),
            Listed::Operator(_) => (
                ": the operator console, not a robot type".to_string(),
                format!("values (what missions receive from {}):", robot.name),
            ),
        };
        text.push_str(&format!(
            "{}{what} ({}{})\n",
            robot.name,
            source(robot, files),
            also_in(&robot.aliases)
        ));
        if !robot.doc.is_empty() {
            text.push_str(&format!("  {}\n", robot.doc));
        }
        let services = robot.services.iter().map(|s| {
            (
                format!("{}{}{}", s.signature(), gives(s), also(&s.aliases)),
                &s.doc,
            )
        });
        section(&mut text, "services:", services.collect());
        let values = robot.values.iter().map(|v| {
            let unit = v.unit.as_ref().map_or(String::new(), |u| format!(" ({u})"));
            let line = format!("{}: {}{unit}{}", v.name, v.ty, also(&v.aliases));
            (line, &v.doc)
        });
        section(&mut text, &values_title, values.collect());
    }
    text
}

/// A titled list of `(signature, doc)` lines, the docs aligned; nothing when
/// empty.
fn section(text: &mut String, title: &str, lines: Vec<(String, &String)>) {
    if lines.is_empty() {
        return;
    }
    let width = lines
        .iter()
        .map(|(l, _)| l.chars().count())
        .max()
        .unwrap_or(0);
    text.push_str(&format!("  {title}\n"));
    for (line, doc) in lines {
        let line = if doc.is_empty() {
            line
        } else {
            format!("{line:width$}  {doc}")
        };
        text.push_str(&format!("    {}\n", line.trim_end()));
    }
}

/// `--format json`'s own fields: `robots` (the editor's `semo/catalog`
/// shape, with each type's `source`) and `operator` (the same, or null).
fn document_fields(listed: &[Listed<'_>], files: &Files) -> serde_json::Value {
    let shaped = |robot: &RobotType| {
        let mut value = semo_server::handlers::catalog::robot(robot);
        value["source"] = source(robot, files).into();
        value
    };
    let robots: Vec<serde_json::Value> = listed
        .iter()
        .filter_map(|l| match l {
            Listed::Robot(r) => Some(shaped(r)),
            Listed::Operator(_) => None,
        })
        .collect();
    let operator = listed.iter().find_map(|l| match l {
        Listed::Operator(u) => Some(shaped(u)),
        Listed::Robot(_) => None,
    });
    serde_json::json!({ "robots": robots, "operator": operator })
}

/// ` -> FOUND: bool, WHERE: location` after a service that gives results back.
fn gives(s: &semo::catalog::ServiceDef) -> String {
    match s.results.is_empty() {
        true => String::new(),
        false => format!(" -> {}", s.results_signature()),
    }
}
