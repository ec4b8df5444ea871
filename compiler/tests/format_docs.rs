//! The references of the three XML formats as a test, the way
//! `tests/language_reference.rs` holds the language's: `docs/catalog.md`,
//! `docs/strategy.md` and `docs/taskgraph.md` cannot fall behind the formats
//! the loaders read.
//!
//! - Every element of a format has a section whose heading names it
//!   (`` ### `<Robot>` ``), and every attribute the loader accepts on it is
//!   named (`` `type` ``) in such a section: the tables are the catalog's and
//!   strategy's schemas (`catalog::schema::ELEMENTS`,
//!   `strategy::schema::ELEMENTS`) and the task-graph reader's vocabularies
//!   (`taskgraph::SEMO_VOCABULARY`, `taskgraph::SDF3_VOCABULARY`). The words
//!   an attribute may be (value types, platforms, `dataCharacteristic`,
//!   leader algorithms) and every type, value and service of the built-in
//!   catalog are named too.
//! - Every fenced ```` ```xml ```` block is a whole file that its format's
//!   loader reads without any diagnostic (`catalog::load_catalog`,
//!   `strategy::load_strategy`, `taskgraph::load_task_graph` and the
//!   analysis of the graph it reads); ```` ```xml fragment ```` is a piece of
//!   a file, not loaded. Any other `xml…` tag fails, so that an example
//!   cannot escape by a typo.

use semo::catalog::{self, CatalogSource};
use semo::diag::{Diagnostic, FileId};
use semo::strategy::{self, DataCharacteristic, LeaderAlgorithm};
use semo::taskgraph::{self, analysis};
use std::path::{Path, PathBuf};

#[path = "../../tests/support/markdown.rs"]
mod markdown;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace root")
        .to_path_buf()
}

fn page(name: &str) -> String {
    let path = repo_root().join("docs").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The sections of a page whose heading names `` `<element>` ``: each from its
/// heading to the next heading of the same or a higher level.
fn sections<'p>(page: &'p str, element: &str) -> Vec<&'p str> {
    let named = format!("`<{element}>`");
    let headings: Vec<(usize, usize, &str)> = page
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .chain(std::iter::once(0))
        .filter_map(|start| {
            let line = page[start..].lines().next()?;
            let level = line.bytes().take_while(|b| *b == b'#').count();
            (level > 0 && line[level..].starts_with(' ')).then_some((start, level, line))
        })
        .collect();
    let mut headings = headings;
    headings.sort_unstable();
    headings
        .iter()
        .enumerate()
        .filter(|(_, (_, _, line))| line.contains(&named))
        .map(|(i, &(start, level, _))| {
            let end = headings[i + 1..]
                .iter()
                .find(|(_, l, _)| *l <= level)
                .map_or(page.len(), |(s, _, _)| *s);
            &page[start..end]
        })
        .collect()
}

/// What the page lacks of a format: elements without a section, attributes
/// not named in their element's sections.
fn missing_names(page: &str, vocabulary: &[(&str, &[&str])]) -> Vec<String> {
    let mut missing = Vec::new();
    for (element, attributes) in vocabulary {
        let sections = sections(page, element);
        if sections.is_empty() {
            missing.push(format!("a section headed `<{element}>`"));
            continue;
        }
        for attribute in *attributes {
            let named = format!("`{attribute}`");
            if !sections.iter().any(|s| s.contains(&named)) {
                missing.push(format!("`{attribute}` in the section of `<{element}>`"));
            }
        }
    }
    missing
}

/// The words that must appear in a page as `` `word` ``, absent ones.
fn missing_words<'w>(page: &str, words: impl IntoIterator<Item = &'w str>) -> Vec<String> {
    words
        .into_iter()
        .filter(|w| !page.contains(&format!("`{w}`")))
        .map(|w| format!("`{w}`"))
        .collect()
}

fn assert_complete(name: &str, missing: Vec<String>) {
    assert!(
        missing.is_empty(),
        "docs/{name} does not name:\n{}",
        missing.join("\n")
    );
}

#[test]
fn catalog_page_names_every_element_attribute_and_builtin_entry() {
    let text = page("catalog.md");
    let vocabulary: Vec<(&str, &[&str])> = catalog::schema::ELEMENTS
        .iter()
        .map(|e| (e.name, e.attributes))
        .collect();
    let mut missing = missing_names(&text, &vocabulary);
    missing.extend(missing_words(
        &text,
        catalog::schema::TYPE_NAMES.iter().copied(),
    ));
    missing.extend(missing_words(&text, semo::platform::platform_names()));
    let builtin = catalog::builtin_catalog();
    let user = builtin.user().expect("the operator console");
    let mut entries: Vec<&str> = Vec::new();
    for robot in builtin.types().map(|(_, r)| r).chain(std::iter::once(user)) {
        entries.push(&robot.name);
        entries.extend(robot.aliases.iter().map(String::as_str));
        entries.extend(robot.values.iter().map(|v| v.name.as_str()));
        entries.extend(
            robot
                .services
                .iter()
                .flat_map(|s| &s.aliases)
                .map(String::as_str),
        );
        entries.extend(robot.capabilities.iter().map(String::as_str));
        // A service is named by its signature: `move(goal?: location)`.
        for service in &robot.services {
            if !text.contains(&format!("`{}(", service.name)) {
                missing.push(format!("`{}(...)` of `{}`", service.name, robot.name));
            }
        }
    }
    entries.sort_unstable();
    entries.dedup();
    missing.extend(missing_words(&text, entries));
    assert_complete("catalog.md", missing);
}

#[test]
fn strategy_page_names_every_element_attribute_and_word() {
    let text = page("strategy.md");
    let vocabulary: Vec<(&str, &[&str])> = strategy::schema::ELEMENTS
        .iter()
        .map(|e| (e.name, e.attributes))
        .collect();
    let mut missing = missing_names(&text, &vocabulary);
    missing.extend(missing_words(
        &text,
        DataCharacteristic::ALL.iter().map(|(w, _)| *w),
    ));
    missing.extend(missing_words(
        &text,
        LeaderAlgorithm::ALL.iter().map(|(w, _)| *w),
    ));
    assert_complete("strategy.md", missing);
}

#[test]
fn taskgraph_page_names_every_element_and_attribute_of_both_formats() {
    let text = page("taskgraph.md");
    let mut missing = missing_names(&text, taskgraph::SEMO_VOCABULARY);
    missing.extend(missing_names(&text, taskgraph::SDF3_VOCABULARY));
    assert_complete("taskgraph.md", missing);
}

fn listing(diagnostics: &[Diagnostic]) -> String {
    diagnostics
        .iter()
        .map(|d| format!("{} {}", d.code.as_str(), d.message))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Loads every whole-file ```` ```xml ```` block of `name` with `load`
/// (which says what went wrong, if anything), and counts them.
fn load_blocks(name: &str, load: impl Fn(&str) -> Result<(), String>) -> usize {
    let text = page(name);
    let mut failures = Vec::new();
    let mut loaded = 0;
    for block in markdown::blocks(&text) {
        let place = format!("docs/{name}:{}", block.line);
        match block.info.as_str() {
            "xml" => match load(&block.body) {
                Ok(()) => loaded += 1,
                Err(e) => failures.push(format!("{place}: {e}")),
            },
            "xml fragment" => {}
            other if other.starts_with("xml") => failures.push(format!(
                "{place}: a block tagged `{other}`: write `xml` (a whole file) or `xml fragment`"
            )),
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    loaded
}

#[test]
fn catalog_page_examples_load() {
    let loaded = load_blocks("catalog.md", |text| {
        let (catalog, diagnostics) = catalog::load_catalog(&[CatalogSource {
            file: FileId(1),
            text,
            base_dir: None,
        }]);
        if !diagnostics.is_empty() {
            return Err(listing(&diagnostics));
        }
        // A whole file defines a robot type (or the operator console).
        let ours = |r: &catalog::RobotType| r.origin.file == FileId(1);
        if catalog.types().any(|(_, r)| ours(r)) || catalog.user().is_some_and(ours) {
            Ok(())
        } else {
            Err("the file defines no robot type".into())
        }
    });
    assert!(loaded >= 2, "{loaded} whole catalog files");
}

#[test]
fn strategy_page_examples_load() {
    let loaded = load_blocks("strategy.md", |text| {
        match strategy::load_strategy(FileId(1), text) {
            (Some(_), diagnostics) if diagnostics.is_empty() => Ok(()),
            (Some(_), diagnostics) => Err(listing(&diagnostics)),
            (None, diagnostics) => Err(format!("no strategy read\n{}", listing(&diagnostics))),
        }
    });
    assert!(loaded >= 2, "{loaded} whole strategy files");
}

#[test]
fn taskgraph_page_examples_load_and_analyse_cleanly() {
    let loaded = load_blocks("taskgraph.md", |text| {
        match taskgraph::load_task_graph(FileId(1), text) {
            (Some(graph), diagnostics) if diagnostics.is_empty() => {
                let report = analysis::analyze(&graph);
                if report.diagnostics.is_empty() {
                    Ok(())
                } else {
                    Err(format!("analysis: {}", listing(&report.diagnostics)))
                }
            }
            (Some(_), diagnostics) => Err(listing(&diagnostics)),
            (None, diagnostics) => Err(format!("no graph read\n{}", listing(&diagnostics))),
        }
    });
    assert!(loaded >= 2, "{loaded} whole task-graph files");
}

/// Every relative link of the three pages leads to a file, and to a heading
/// of it when it names one (as `tests/language_reference.rs` checks the
/// language pages).
#[test]
fn every_link_of_the_pages_leads_somewhere() {
    let docs = repo_root().join("docs");
    let broken: Vec<String> = ["catalog.md", "strategy.md", "taskgraph.md"]
        .into_iter()
        .flat_map(|name| markdown::broken_links(&docs, &format!("docs/{name}"), &page(name)))
        .collect();
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// The files of the repository: git's list, else every file under the root
/// but build output, dependencies and `.git`.
fn repository_files() -> Vec<PathBuf> {
    let root = repo_root();
    let listed = std::process::Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(&root)
        .output()
        .ok()
        .filter(|out| out.status.success() && !out.stdout.is_empty());
    if let Some(out) = listed {
        return String::from_utf8_lossy(&out.stdout)
            .split('\0')
            .filter(|p| !p.is_empty())
            .map(|p| root.join(p))
            .collect();
    }
    let mut files = Vec::new();
    let mut folders = vec![root];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).into_iter().flatten().flatten() {
            let path = entry.path();
            let name = entry.file_name();
            if path.is_dir() {
                if !matches!(name.to_str(), Some("target" | "node_modules" | ".git")) {
                    folders.push(path);
                }
            } else {
                files.push(path);
            }
        }
    }
    files
}

#[test]
fn no_file_refers_to_the_specification_folder_outside_the_repository() {
    // Spelled in pieces so that this file does not name them itself.
    let outside: Vec<String> = ["spec", "examples"]
        .iter()
        .map(|folder| format!("shared/{folder}"))
        .collect();
    let mut found = Vec::new();
    let files = repository_files();
    assert!(files.len() > 100, "{} files", files.len());
    for path in files {
        // Binary files and files removed from the work tree are skipped.
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        for (number, line) in text.lines().enumerate() {
            if outside.iter().any(|o| line.contains(o.as_str())) {
                found.push(format!("{}:{}: {line}", path.display(), number + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "these point at files a clone of the repository does not have (the formats are in docs/):\n{}",
        found.join("\n")
    );
}
