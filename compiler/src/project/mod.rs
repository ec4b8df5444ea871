//! The project file, `semo.toml`: one file at a project's root (found by
//! walking up from a file, as Cargo finds `Cargo.toml`, see [`find`]) that
//! says which catalog, strategy and task-graph folders the project's missions
//! read, where `semo build` writes and for which target (every robot's,
//! `[build] target`, or a team's or robot's, `[build.targets]`), which
//! deployment file the project uses, and the level of each diagnostic code
//! (`[lints]`). The format is documented in `docs/project-file.md`.
//!
//! [`parse`] reads it with positions (toml_edit keeps every key's and value's
//! byte range), so each mistake is a diagnostic on the project file itself:
//! invalid TOML (E110), a value of the wrong form (E111), an error code
//! allowed (E112), an unknown key (W110, with a did-you-mean), a folder that
//! does not exist ([`Project::missing_paths`], W111); a `[build.targets]`
//! name that names no team or robot of the mission built is W110 when it
//! is built ([`Project::unknown_names`]: one project serves several
//! missions, so only a build knows which names it must have). Whatever is wrong, the
//! rest of the file is still read. The host applies the project to the files
//! under its root (`host::sees`, [`Project::apply_lints`]); `completion.rs`
//! completes keys, tables, lint codes and values for the editor.

mod completion;
#[cfg(test)]
mod tests;

pub use completion::{Completion, CompletionKind, Named, completions};

use crate::diag::{Code, Diagnostic, FileId, Severity};
use crate::platform::Target;
use crate::span::Span;
use crate::suggest::did_you_mean;
use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// The project file's name.
pub const FILE_NAME: &str = "semo.toml";

/// The format version this semo reads (`[project] version`).
pub const VERSION: i64 = 1;

/// How many folders [`find`] looks at, its own included, before giving up.
pub const MAX_LEVELS: usize = 32;

/// What a `[lints]` entry makes of a diagnostic code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Not reported (warnings and hints only).
    Allow,
    /// Reported as a warning.
    Warn,
    /// Reported as an error: checks fail and builds are refused.
    Deny,
}

impl Level {
    pub const NAMES: [&'static str; 3] = ["allow", "warn", "deny"];

    pub fn from_name(name: &str) -> Option<Level> {
        match name {
            "allow" => Some(Level::Allow),
            "warn" => Some(Level::Warn),
            "deny" => Some(Level::Deny),
            _ => None,
        }
    }
}

/// A path written in the project file: where it leads (the root joined,
/// `.` and `..` folded) and where it is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProjectPath {
    pub path: PathBuf,
    /// As written (messages quote it).
    pub written: String,
    pub span: Span,
}

/// A target written in the project file, and where its value is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProjectTarget {
    pub target: Target,
    pub span: Span,
}

/// `name = "target"` in `[build.targets]`: the robots of the team `name`,
/// or the robot `name` (or the robots of its `name[N]` declaration), are
/// built for `target`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NamedTarget {
    pub name: String,
    pub name_span: Span,
    pub target: ProjectTarget,
}

/// A project file read. Folders default to the whole project (its root).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Project {
    /// The folder holding `semo.toml`.
    pub root: PathBuf,
    pub name: Option<String>,
    pub catalogs: Vec<ProjectPath>,
    pub strategies: Vec<ProjectPath>,
    pub task_graphs: Vec<ProjectPath>,
    /// `semo build`'s output folder when `-o` is not given.
    pub output: Option<ProjectPath>,
    /// `semo build`'s target for every robot when `--target` is not given
    /// (`[build] target`).
    pub target: Option<ProjectTarget>,
    /// A team's or robot's target (`[build.targets]`), in file order.
    pub targets: Vec<NamedTarget>,
    /// The deployment file (`*.deploy.toml`).
    pub deployment: Option<ProjectPath>,
    pub lints: BTreeMap<Code, Level>,
}

/// The tables and keys of the format, with what each means (for unknown-key
/// suggestions and completion).
pub const TABLES: &[(&str, &str)] = &[
    (
        "project",
        "the format version, the name and the input folders",
    ),
    (
        "build",
        "`semo build`'s output folder and target, the deployment file",
    ),
    (
        "build.targets",
        "a team's or robot's target: `Scouts = \"cortex-m\"`",
    ),
    ("lints", "the level of diagnostic codes: `W007 = \"allow\"`"),
];

pub const PROJECT_KEYS: &[(&str, &str)] = &[
    ("version", "the format version of this file (1)"),
    ("name", "the project's name"),
    (
        "catalogs",
        "folders of robot catalogs (*.robot.xml); default: the project root",
    ),
    (
        "strategies",
        "folders of strategy files (*.strategy.xml); default: the project root",
    ),
    (
        "task-graphs",
        "folders of task graphs (*.taskgraph.xml); default: the project root",
    ),
];

pub const BUILD_KEYS: &[(&str, &str)] = &[
    (
        "output",
        "the output folder of `semo build` (default: `out` beside the mission)",
    ),
    (
        "target",
        "the target of every robot (default: each robot type's platform in the catalog, else linux)",
    ),
    ("deployment", "the deployment file (*.deploy.toml)"),
];

impl Project {
    /// A project with every default, rooted at `root`.
    pub fn new(root: &Path) -> Project {
        let whole = || {
            vec![ProjectPath {
                path: root.to_path_buf(),
                written: ".".to_string(),
                span: Span::default(),
            }]
        };
        Project {
            root: root.to_path_buf(),
            name: None,
            catalogs: whole(),
            strategies: whole(),
            task_graphs: whole(),
            output: None,
            target: None,
            targets: Vec::new(),
            deployment: None,
            lints: BTreeMap::new(),
        }
    }

    /// Whether `path` lies in one of `folders`.
    pub fn in_folders(folders: &[ProjectPath], path: &Path) -> bool {
        folders.iter().any(|f| path.starts_with(&f.path))
    }

    /// The level the project gives `code`, if any.
    pub fn level(&self, code: Code) -> Option<Level> {
        self.lints.get(&code).copied()
    }

    /// Applies `[lints]` to diagnostics of a file of this project: allowed
    /// codes are dropped, denied ones become errors, `warn` ones warnings.
    /// An error code is never lowered ([`parse`] refuses it).
    pub fn apply_lints(&self, diagnostics: &mut Vec<Diagnostic>) {
        if self.lints.is_empty() {
            return;
        }
        diagnostics.retain_mut(|d| {
            let lowerable = d.code.default_severity() != Severity::Error;
            match self.level(d.code) {
                Some(Level::Allow) if lowerable => false,
                Some(Level::Warn) if lowerable => {
                    d.severity = Severity::Warning;
                    true
                }
                Some(Level::Deny) => {
                    d.severity = Severity::Error;
                    true
                }
                _ => true,
            }
        });
    }

    /// W110 for each `[build.targets]` name that names none of `known`
    /// (the teams, robots and robot declarations of the mission `mission`
    /// being built), with a did-you-mean among them: its robots would
    /// silently keep another target.
    pub fn unknown_names(&self, file: FileId, mission: &str, known: &[&str]) -> Vec<Diagnostic> {
        self.targets
            .iter()
            .filter(|t| !known.contains(&t.name.as_str()))
            .map(|t| {
                let mut d = Diagnostic::new(
                    Code::ProjectUnknownKey,
                    file,
                    t.name_span,
                    format!(
                        "`[build.targets]` names `{}`, which is no team or robot of {mission}: its target is not used",
                        t.name
                    ),
                );
                d.suggest(did_you_mean(&t.name, known.iter().copied()));
                d
            })
            .collect()
    }

    /// W111 for each input folder or deployment file written in the file
    /// that `exists` says is not there (the output folder is made by `semo
    /// build`, so it need not exist).
    pub fn missing_paths(&self, file: FileId, exists: impl Fn(&Path) -> bool) -> Vec<Diagnostic> {
        let written = |p: &&ProjectPath| !p.span.is_empty();
        let folders = self
            .catalogs
            .iter()
            .chain(&self.strategies)
            .chain(&self.task_graphs)
            .filter(written)
            .map(|p| (p, "folder"));
        let deployment = self.deployment.iter().filter(written).map(|p| (p, "file"));
        folders
            .chain(deployment)
            .filter(|(p, _)| !exists(&p.path))
            .map(|(p, what)| {
                Diagnostic::new(
                    Code::ProjectMissingPath,
                    file,
                    p.span,
                    format!("there is no {what} `{}` in the project", p.written),
                )
            })
            .collect()
    }
}

/// The folder holding the project file that applies to `start` (a folder):
/// `start` or the nearest folder above it with a `semo.toml`. The walk stops
/// after a folder that is a version-control root (`.git`, `.hg`, `.jj`,
/// `.svn`), at the filesystem root, or after [`MAX_LEVELS`] folders.
pub fn find(start: &Path) -> Option<PathBuf> {
    let start = normalize(&std::path::absolute(start).ok()?);
    for dir in start.ancestors().take(MAX_LEVELS) {
        if dir.join(FILE_NAME).is_file() {
            return Some(dir.to_path_buf());
        }
        let vcs_root = [".git", ".hg", ".jj", ".svn"]
            .iter()
            .any(|v| dir.join(v).exists());
        if vcs_root {
            return None;
        }
    }
    None
}

/// `path` without `.` and with each `..` folding the folder before it.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push(component);
                }
            }
            other => out.push(other),
        }
    }
    out
}

/// Whether `text` is a TOML document with at least one key or table: a
/// project file, and never a mission (whose text opens with `{`, which TOML
/// does not allow there), whatever its first line looks like.
pub fn is_toml(text: &str) -> bool {
    // TOML's first expression is a key (bare or quoted) or a table header:
    // a text opening otherwise (a mission's `{`) is not TOML, known without
    // parsing it whole (the parser reads to the end, a mission's size).
    let first = text
        .lines()
        .map(str::trim_start)
        .find(|line| !line.is_empty() && !line.starts_with('#'))
        .and_then(|line| line.chars().next());
    let can_open = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '"' | '\'' | '[');
    first.is_some_and(can_open)
        && toml_edit::Document::parse(text).is_ok_and(|document| !document.as_table().is_empty())
}

/// Reads the project file `text` of the project at `root` (the folder
/// holding it), with its diagnostics (see the module documentation).
pub fn parse(file: FileId, root: &Path, text: &str) -> (Project, Vec<Diagnostic>) {
    let mut reader = Reader {
        file,
        root,
        project: Project::new(root),
        diagnostics: Vec::new(),
    };
    match toml_edit::Document::parse(text) {
        Ok(document) => reader.document(document.as_table()),
        Err(error) => {
            let span = error
                .span()
                .map_or(Span::new(0, 0), |r| Span::new(r.start, r.end));
            let message = error.message().trim().to_string();
            reader.error(
                Code::ProjectSyntax,
                span,
                format!("invalid TOML: {message}"),
            );
        }
    }
    (reader.project, reader.diagnostics)
}

struct Reader<'a> {
    file: FileId,
    root: &'a Path,
    project: Project,
    diagnostics: Vec<Diagnostic>,
}

fn span_of(range: Option<std::ops::Range<usize>>) -> Span {
    range.map_or(Span::new(0, 0), |r| Span::new(r.start, r.end))
}

/// Where an item is written: its value, else its key.
fn item_span(key: &toml_edit::Key, item: &toml_edit::Item) -> Span {
    match item.span() {
        Some(r) => Span::new(r.start, r.end),
        None => span_of(key.span()),
    }
}

fn names(keys: &[(&'static str, &str)]) -> impl Iterator<Item = &'static str> + Clone {
    keys.iter().map(|(k, _)| *k)
}

/// The tables of the document itself (`build.targets` is inside `build`).
fn top_tables() -> impl Iterator<Item = &'static str> + Clone {
    names(TABLES).filter(|t| !t.contains('.'))
}

impl Reader<'_> {
    fn error(&mut self, code: Code, span: Span, message: String) {
        self.diagnostics
            .push(Diagnostic::new(code, self.file, span, message));
    }

    /// W110 on `key`, with a did-you-mean among `known`.
    fn unknown<'k>(
        &mut self,
        key: &toml_edit::Key,
        message: String,
        known: impl IntoIterator<Item = &'k str>,
    ) {
        let mut d = Diagnostic::new(
            Code::ProjectUnknownKey,
            self.file,
            span_of(key.span()),
            message,
        );
        d.suggest(did_you_mean(key.get(), known));
        self.diagnostics.push(d);
    }

    /// W110 for a table or key the format does not have, listing `known`.
    fn unknown_key<'k>(
        &mut self,
        key: &toml_edit::Key,
        what: &str,
        known: impl IntoIterator<Item = &'k str> + Clone,
    ) {
        let listed: Vec<&str> = known.clone().into_iter().collect();
        let message = format!(
            "unknown {what} `{}` (known: {})",
            key.get(),
            listed.join(", ")
        );
        self.unknown(key, message, known);
    }

    fn document(&mut self, table: &toml_edit::Table) {
        for (name, item) in table.iter() {
            let Some((key, _)) = table.get_key_value(name) else {
                continue;
            };
            let Some(inner) = item.as_table_like() else {
                if top_tables().any(|t| t == name) {
                    self.error(
                        Code::ProjectBadValue,
                        item_span(key, item),
                        format!("`{name}` must be a table (`[{name}]`)"),
                    );
                } else {
                    self.unknown_key(key, "table", top_tables());
                }
                continue;
            };
            match name {
                "project" => self.entries(inner, PROJECT_KEYS, "key of [project]", Self::project),
                "build" => self.build_table(inner),
                "lints" => self.lints(inner),
                _ => self.unknown_key(key, "table", top_tables()),
            }
        }
    }

    /// Each known key of `table` through `read`; unknown ones are W110.
    fn entries(
        &mut self,
        table: &dyn toml_edit::TableLike,
        known: &[(&'static str, &str)],
        what: &str,
        read: fn(&mut Self, &str, &toml_edit::Key, &toml_edit::Item),
    ) {
        for (name, item) in table.iter() {
            let Some((key, _)) = table.get_key_value(name) else {
                continue;
            };
            if names(known).any(|k| k == name) {
                read(self, name, key, item);
            } else {
                self.unknown_key(key, what, names(known));
            }
        }
    }

    fn project(&mut self, name: &str, key: &toml_edit::Key, item: &toml_edit::Item) {
        let span = item_span(key, item);
        match name {
            "version" => match item.as_integer() {
                Some(VERSION) => {}
                Some(other) => self.error(
                    Code::ProjectBadValue,
                    span,
                    format!(
                        "format version {other} is not one this semo reads (it reads {VERSION})"
                    ),
                ),
                None => self.error(
                    Code::ProjectBadValue,
                    span,
                    format!("`version` must be an integer ({VERSION})"),
                ),
            },
            "name" => match item.as_str() {
                Some(s) => self.project.name = Some(s.to_string()),
                None => self.error(
                    Code::ProjectBadValue,
                    span,
                    "`name` must be a string".into(),
                ),
            },
            _ => {
                let Some(folders) = self.folders(name, item, span) else {
                    return;
                };
                match name {
                    "catalogs" => self.project.catalogs = folders,
                    "strategies" => self.project.strategies = folders,
                    _ => self.project.task_graphs = folders,
                }
            }
        }
    }

    /// A list of folders, each relative to the root (or absolute).
    fn folders(
        &mut self,
        name: &str,
        item: &toml_edit::Item,
        span: Span,
    ) -> Option<Vec<ProjectPath>> {
        let wrong = |reader: &mut Self, span: Span| {
            reader.error(
                Code::ProjectBadValue,
                span,
                format!("`{name}` must be a list of folders, such as [\"robots\"]"),
            );
        };
        let Some(array) = item.as_array() else {
            wrong(self, span);
            return None;
        };
        let mut out = Vec::new();
        for value in array.iter() {
            match value.as_str() {
                Some(s) => out.push(self.path(s, span_of(value.span()))),
                None => wrong(self, span_of(value.span())),
            }
        }
        Some(out)
    }

    fn path(&self, written: &str, span: Span) -> ProjectPath {
        ProjectPath {
            path: normalize(&self.root.join(written)),
            written: written.to_string(),
            span,
        }
    }

    /// `[build]`: its keys, and its `targets` table.
    fn build_table(&mut self, table: &dyn toml_edit::TableLike) {
        for (name, item) in table.iter() {
            let Some((key, _)) = table.get_key_value(name) else {
                continue;
            };
            if name == "targets" {
                self.targets(key, item);
            } else if names(BUILD_KEYS).any(|k| k == name) {
                self.build(name, key, item);
            } else {
                let known = names(BUILD_KEYS).chain(["targets"]);
                self.unknown_key(key, "key of [build]", known);
            }
        }
    }

    fn build(&mut self, name: &str, key: &toml_edit::Key, item: &toml_edit::Item) {
        let span = item_span(key, item);
        let Some(value) = item.as_str() else {
            self.error(
                Code::ProjectBadValue,
                span,
                format!("`{name}` must be a string"),
            );
            return;
        };
        match name {
            "output" => self.project.output = Some(self.path(value, span)),
            "deployment" => self.project.deployment = Some(self.path(value, span)),
            _ => self.project.target = self.target(value, span),
        }
    }

    /// A target's name, else E111 with a did-you-mean.
    fn target(&mut self, value: &str, span: Span) -> Option<ProjectTarget> {
        if let Some(target) = Target::from_name(value) {
            return Some(ProjectTarget { target, span });
        }
        let mut d = Diagnostic::new(
            Code::ProjectBadValue,
            self.file,
            span,
            format!(
                "unknown target `{value}` (targets: {})",
                Target::names().collect::<Vec<_>>().join(", ")
            ),
        );
        d.suggest(did_you_mean(value, Target::names()));
        self.diagnostics.push(d);
        None
    }

    /// `[build.targets]` (or `targets = { ... }` in `[build]`): team and
    /// robot names, each with its target.
    fn targets(&mut self, key: &toml_edit::Key, item: &toml_edit::Item) {
        let Some(table) = item.as_table_like() else {
            self.error(
                Code::ProjectBadValue,
                item_span(key, item),
                "`targets` must be a table of team and robot names, `[build.targets]` with `Scouts = \"cortex-m\"`".into(),
            );
            return;
        };
        for (name, item) in table.iter() {
            let Some((key, _)) = table.get_key_value(name) else {
                continue;
            };
            let span = item_span(key, item);
            let Some(value) = item.as_str() else {
                self.error(
                    Code::ProjectBadValue,
                    span,
                    format!("the target of `{name}` must be a string, such as \"linux\""),
                );
                continue;
            };
            if let Some(target) = self.target(value, span) {
                self.project.targets.push(NamedTarget {
                    name: name.to_string(),
                    name_span: span_of(key.span()),
                    target,
                });
            }
        }
    }

    fn lints(&mut self, table: &dyn toml_edit::TableLike) {
        for (name, item) in table.iter() {
            let Some((key, _)) = table.get_key_value(name) else {
                continue;
            };
            let Some(code) = Code::from_code(name) else {
                // Too many codes to list: the did-you-mean only.
                let codes = Code::ALL.iter().map(|c| c.as_str());
                self.unknown(key, format!("unknown diagnostic code `{name}`"), codes);
                continue;
            };
            let span = item_span(key, item);
            let Some(level) = item.as_str().and_then(Level::from_name) else {
                self.error(
                    Code::ProjectBadValue,
                    span,
                    format!("the level of {name} must be \"allow\", \"warn\" or \"deny\""),
                );
                continue;
            };
            if code.default_severity() == Severity::Error && level != Level::Deny {
                self.error(
                    Code::ProjectErrorAllowed,
                    span,
                    format!(
                        "{name} is an error: it cannot be allowed or made a warning (only \"deny\")"
                    ),
                );
                continue;
            }
            self.project.lints.insert(code, level);
        }
    }
}
