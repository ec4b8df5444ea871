//! Where a command's input comes from (a file, or standard input for `-`),
//! and whether it is the kind of file the command takes: a command given the
//! wrong kind says so in one line and does nothing, instead of reading, say,
//! a task graph as a mission and reporting every line of it.

use semo::workspace::FileKind;
use std::io::Read;
use std::path::{Path, PathBuf};

/// How standard input is named in reports (the library's name for it).
pub const STDIN_NAME: &str = semo::host::STDIN_NAME;

pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// A command that reads the mission's folder (its catalog and strategy
/// files, and `also` there) cannot take the mission on standard input:
/// says so in one line, with `note` after it.
pub fn mission_is_a_file(mission: &Path, command: &str, also: &str, note: &str) -> bool {
    if is_stdin(mission) {
        eprintln!(
            "error: `semo {command}` reads the mission's folder (its catalog and strategy files{also}): give the mission's file, not `-`{note}"
        );
        return false;
    }
    true
}

/// `--strategy` paths are seen by path (by the files under the same
/// roots), so standard input cannot be one: says so in one line.
pub fn strategy_paths_are_files(paths: &[PathBuf]) -> bool {
    if paths.iter().any(|p| is_stdin(p)) {
        eprintln!(
            "error: --strategy takes files and folders (strategy and catalog files are seen by their paths), not `-`"
        );
        return false;
    }
    true
}

/// All of standard input as text (at most the limit any input file has).
pub fn read_stdin() -> Result<String, String> {
    let limit = semo::fsread::MAX_FILE_BYTES;
    let mut bytes = Vec::new();
    std::io::stdin()
        .lock()
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read standard input: {e}"))?;
    if bytes.len() as u64 > limit {
        return Err(format!(
            "standard input is larger than {limit} bytes, the most an input file may be"
        ));
    }
    // As for files: invalid UTF-8 is replaced, and then reported where it is.
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// The text of `path` (standard input for `-`) and the name reports give it;
/// on failure the message is printed.
pub fn read(path: &Path) -> Option<(PathBuf, String)> {
    if is_stdin(path) {
        return match read_stdin() {
            Ok(text) => Some((PathBuf::from(STDIN_NAME), text)),
            Err(e) => {
                eprintln!("error: {e}");
                None
            }
        };
    }
    match semo::workspace::read_text(path) {
        Ok(text) => Some((path.to_path_buf(), text)),
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            None
        }
    }
}

/// What a file holds, judged by its first element or character (not its
/// name: the point is to catch a file given in the wrong place).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Content {
    Mission,
    Catalog,
    TaskGraph,
    Strategy,
    /// JSON: a scenario (`*.scenario.json`).
    Scenario,
    /// TOML: the project file (`semo.toml`).
    Project,
    /// XML of a kind SeMo does not read.
    OtherXml,
}

impl Content {
    pub fn of(text: &str) -> Content {
        let text = text.trim_start_matches('\u{feff}').trim_start();
        // A mission opens with its team declarations, `{ Team: … }`; a
        // scenario is a JSON object, `{ "duration": … }`.
        if let Some(object) = text.strip_prefix('{').map(str::trim_start)
            && (object.starts_with('"')
                || object
                    .strip_prefix('}')
                    .is_some_and(|r| r.trim().is_empty()))
        {
            return Content::Scenario;
        }
        // Whatever its first line looks like (`[lints]`, `[[ group(…) ]]`),
        // a text is a project file only when it is TOML: no mission is.
        if !text.starts_with('<') {
            return match semo::project::is_toml(text) {
                true => Content::Project,
                false => Content::Mission,
            };
        }
        match root_element(text) {
            Some("Catalog") => Content::Catalog,
            Some("TaskGraph" | "sdf3") => Content::TaskGraph,
            Some("Strategy") => Content::Strategy,
            _ => Content::OtherXml,
        }
    }

    /// The kind in words, with an article ("a task graph").
    pub fn words(self) -> &'static str {
        match self {
            Content::Mission => "a mission script",
            Content::Catalog => "a robot catalog",
            Content::TaskGraph => "a task graph",
            Content::Strategy => "a strategy file",
            Content::Scenario => "a scenario (JSON)",
            Content::Project => "a project file (TOML)",
            Content::OtherXml => "an XML file SeMo does not read",
        }
    }
}

/// The local name of an XML text's root element, past the declaration,
/// comments, processing instructions and a doctype.
fn root_element(mut text: &str) -> Option<&str> {
    loop {
        text = text.trim_start();
        let skip_past = |text: &str, end: &str| text.find(end).map(|i| i + end.len());
        let rest = if text.starts_with("<?") {
            skip_past(text, "?>")?
        } else if text.starts_with("<!--") {
            skip_past(text, "-->")?
        } else if text.starts_with("<!") {
            skip_past(text, ">")?
        } else if let Some(tag) = text.strip_prefix('<') {
            let name = tag
                .split(|c: char| c.is_whitespace() || c == '>' || c == '/')
                .next()?;
            // A prefixed root (`<s:Strategy>`) is known by its local name.
            return Some(name.rsplit(':').next().unwrap_or(name));
        } else {
            return None;
        };
        text = &text[rest..];
    }
}

impl Content {
    fn is_xml(self) -> bool {
        matches!(
            self,
            Content::Catalog | Content::TaskGraph | Content::Strategy | Content::OtherXml
        )
    }

    /// What a file of `kind` holds.
    fn of_kind(kind: FileKind) -> Content {
        match kind {
            FileKind::Mission => Content::Mission,
            FileKind::Catalog => Content::Catalog,
            FileKind::TaskGraph => Content::TaskGraph,
            FileKind::Strategy => Content::Strategy,
            FileKind::Project => Content::Project,
        }
    }

    /// Whether a file holding this can be read as `wanted`: the same kind,
    /// XML of no known kind where XML is wanted (its reader then points
    /// at the root element, with a did-you-mean), or text that is not TOML
    /// where the project file is (its reader then says where, E110).
    fn fits(self, wanted: Content) -> bool {
        self == wanted
            || (self == Content::OtherXml && wanted.is_xml())
            || (self == Content::Mission && wanted == Content::Project)
    }
}

/// For `semo check`, which knows a file by its name: why a file named on
/// the command line does not hold what its name makes it, in one line;
/// `None` when it does. Folders, `-` and unreadable files pass (the check
/// reports the latter).
pub fn named_file_misfit(path: &Path) -> Option<String> {
    if is_stdin(path) || path.is_dir() {
        return None;
    }
    let text = semo::workspace::read_text(path).ok()?;
    let wanted = Content::of_kind(FileKind::named_explicitly(path));
    let found = Content::of(&text);
    if found.fits(wanted) {
        return None;
    }
    Some(format!(
        "{} is {}, but its name makes it {}: `semo check` knows a file by its name (*.mission, *.robot.xml, *.strategy.xml, *.taskgraph.xml, another *.xml is a task graph)",
        path.display(),
        found.words(),
        wanted.words()
    ))
}

/// Whether `text` (of `path`) holds what `command` takes; if not, prints
/// the one line that says so and gives `false`.
pub fn is_kind(path: &Path, text: &str, wanted: Content, command: &str) -> bool {
    let found = Content::of(text);
    if found.fits(wanted) {
        return true;
    }
    eprintln!(
        "error: {} is {}, not {}: `{command}` takes {}",
        path.display(),
        found.words(),
        wanted.words(),
        wanted.words()
    );
    false
}

/// [`is_kind`] for a file on disk that the command reads later itself: a
/// file that cannot be read passes, the command reports that.
pub fn file_is_kind(path: &Path, wanted: Content, command: &str) -> bool {
    match semo::workspace::read_text(path) {
        Ok(text) => is_kind(path, &text, wanted, command),
        Err(_) => true,
    }
}

#[cfg(test)]
mod tests {
    use super::Content;

    #[test]
    fn content_is_judged_by_the_root_element_or_first_character() {
        let cases = [
            ("{ T: iRobotCreate a }", Content::Mission),
            ("// a mission\n{ T: x a }", Content::Mission),
            ("  {\"duration\": \"1min\"}", Content::Scenario),
            ("{ }\n", Content::Scenario),
            ("{ }\nT.main{ default: mode = M }", Content::Mission),
            ("<Catalog xmlns=\"urn:semo:catalog:1\">", Content::Catalog),
            (
                "<?xml version=\"1.0\"?>\n<!-- c -->\n<TaskGraph name=\"g\">",
                Content::TaskGraph,
            ),
            (
                "<?xml version='1.0'?><sdf3 type=\"sdf\">",
                Content::TaskGraph,
            ),
            ("\u{feff}<s:Strategy name=\"T\">", Content::Strategy),
            ("<!DOCTYPE html><html>", Content::OtherXml),
            ("<!-- never closed", Content::OtherXml),
            // TOML, and text whose first line only looks like it.
            ("[project]\nname = \"x\"\n", Content::Project),
            ("# lints\n[lints]\nW001 = \"allow\"\n", Content::Project),
            ("version = 1\n", Content::Project),
            ("[lints]\n{ T: x a }\n", Content::Mission),
            ("[[ group(instance of X) { stop() } ]]\n", Content::Mission),
            ("[T]\nT.main { default: mode = M }\n", Content::Mission),
            ("# only a comment\n", Content::Mission),
            ("\"quoted key\" = 1\n", Content::Project),
            ("  \r\n# c\n  'literal' = 2\n", Content::Project),
            // Known at its first expression: not parsed as TOML to its end.
            (
                "# a mission\n{ T: x a }\nT.main { default: mode = M }\n",
                Content::Mission,
            ),
        ];
        for (text, want) in cases {
            assert_eq!(Content::of(text), want, "{text}");
        }
    }
}
