//! The language reference (`docs/language/`) as a test: every fenced block of
//! its pages is run through the real `semo` binary as its tag says
//! (`docs/language/README.md`, "How the examples are tested"):
//!
//! - ```` ```semo ```` a mission that `semo check` finds no error or warning in;
//! - ```` ```semo expect=E041,W004 ```` a mission that gives exactly these codes;
//! - ```` ```scenario ```` after a mission: `semo simulate` runs it on the scenario;
//! - ```` ```trace ```` after a scenario: lines the simulation writes, in this order;
//! - ```` ```syntax ```` the form of a construct, not checked.
//!
//! A block with any other tag fails, so an example cannot escape by a typo. The
//! index must list every page, and every relative link must lead to a file (and
//! to a heading of it, when it names one).

mod support;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use support::markdown::{blocks, broken_links, links};
use support::{parse_json_report, repo_root, semo_in};

/// A page of the reference: its file name and text.
struct Page {
    name: String,
    text: String,
}

/// Every page of `docs/language/`, by file name.
fn pages() -> Vec<Page> {
    let dir = repo_root().join("docs/language");
    let mut pages: Vec<Page> = std::fs::read_dir(&dir)
        .expect("docs/language exists")
        .map(|entry| entry.expect("a readable entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "md"))
        .map(|path| Page {
            name: path.file_name().unwrap().to_string_lossy().into_owned(),
            text: std::fs::read_to_string(&path).expect("a page is UTF-8"),
        })
        .collect();
    pages.sort_by(|a, b| a.name.cmp(&b.name));
    assert!(pages.len() > 1, "no pages in {}", dir.display());
    pages
}

/// What a block's tag asks for.
enum Tag {
    Mission { expect: BTreeSet<String> },
    Scenario,
    Trace,
    Syntax,
}

impl Tag {
    fn of(info: &str) -> Result<Tag, String> {
        match info.split_once(' ') {
            None if info == "semo" => Ok(Tag::Mission {
                expect: BTreeSet::new(),
            }),
            None if info == "scenario" => Ok(Tag::Scenario),
            None if info == "trace" => Ok(Tag::Trace),
            None if info == "syntax" => Ok(Tag::Syntax),
            Some(("semo", codes)) => match codes.strip_prefix("expect=") {
                Some(codes) if !codes.is_empty() => Ok(Tag::Mission {
                    expect: codes.split(',').map(str::to_string).collect(),
                }),
                _ => Err(format!("`{info}`: write `semo expect=CODE,CODE`")),
            },
            _ => Err(format!(
                "a block tagged `{info}`: the reference's tags are semo, semo expect=..., scenario, trace and syntax"
            )),
        }
    }
}

/// Where the examples run: a fresh folder per example (no catalog beside
/// it: the built-in one applies).
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("language_reference")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The codes `semo check` gives the mission in `dir`, hints left out.
fn codes_of(dir: &Path) -> Result<BTreeSet<String>, String> {
    let out = semo_in(dir, &["check", "--format", "json", "example.mission"]);
    if out.code > 1 {
        return Err(format!(
            "semo check exited with {}: {}",
            out.code, out.stderr
        ));
    }
    Ok(parse_json_report(&out.stdout)
        .into_iter()
        .filter(|d| d.severity != "hint")
        .map(|d| d.code)
        .collect())
}

/// The trace lines of `semo simulate` on the mission and scenario in `dir`.
fn simulate(dir: &Path) -> Result<Vec<String>, String> {
    let out = semo_in(
        dir,
        &[
            "simulate",
            "example.mission",
            "--scenario",
            "example.scenario.json",
            "--trace",
            "trace.jsonl",
        ],
    );
    if out.code != 0 {
        return Err(format!(
            "semo simulate exited with {}: {}{}",
            out.code, out.stdout, out.stderr
        ));
    }
    let trace = std::fs::read_to_string(dir.join("trace.jsonl")).map_err(|e| e.to_string())?;
    Ok(trace.lines().map(str::to_string).collect())
}

/// The first of `expected` that is not found in `trace` after the ones before it.
fn first_missing<'e>(trace: &[String], expected: &'e str) -> Option<&'e str> {
    let mut rest = trace.iter();
    expected
        .lines()
        .filter(|l| !l.trim().is_empty())
        .find(|line| !rest.any(|t| t == line))
}

/// Runs the blocks of one page, adding what fails to `failures`.
fn run_page(page: &Page, failures: &mut Vec<String>) {
    // The folder of the mission a scenario may follow, and the trace of the
    // scenario a trace may follow: each only right after its block.
    let mut mission: Option<PathBuf> = None;
    let mut trace: Option<Vec<String>> = None;
    for (index, block) in blocks(&page.text).iter().enumerate() {
        let place = format!("docs/language/{}:{}", page.name, block.line);
        let (after_mission, after_scenario) = (mission.take(), trace.take());
        let result = match Tag::of(&block.info) {
            Err(e) => Err(e),
            Ok(Tag::Syntax) => Ok(()),
            Ok(Tag::Mission { expect }) => {
                let dir = scratch(&format!("{}-{index}", page.name.trim_end_matches(".md")));
                std::fs::write(dir.join("example.mission"), &block.body).unwrap();
                codes_of(&dir).and_then(|found| {
                    if found != expect {
                        return Err(format!(
                            "the mission gives {found:?}, the reference says {expect:?}"
                        ));
                    }
                    if !found.iter().any(|c| c.starts_with('E')) {
                        mission = Some(dir);
                    }
                    Ok(())
                })
            }
            Ok(Tag::Scenario) => match after_mission {
                None => Err("a scenario must follow a mission without errors".into()),
                Some(dir) => {
                    std::fs::write(dir.join("example.scenario.json"), &block.body).unwrap();
                    simulate(&dir).map(|lines| trace = Some(lines))
                }
            },
            Ok(Tag::Trace) => match after_scenario {
                None => Err("a trace must follow a scenario".into()),
                Some(lines) => match first_missing(&lines, &block.body) {
                    Some(line) => Err(format!(
                        "the simulation does not write, in this order, {line}\nits trace:\n{}",
                        lines.join("\n")
                    )),
                    None => Ok(()),
                },
            },
        };
        if let Err(why) = result {
            failures.push(format!("{place}: {why}"));
        }
    }
}

#[test]
fn every_example_of_the_reference_checks_and_runs_as_it_says() {
    let mut failures = Vec::new();
    let mut missions = 0;
    for page in pages() {
        missions += blocks(&page.text)
            .iter()
            .filter(|b| b.info.starts_with("semo"))
            .count();
        run_page(&page, &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(missions >= 20, "only {missions} examples");
}

#[test]
fn every_page_is_listed_in_the_index() {
    let pages = pages();
    let index = pages
        .iter()
        .find(|p| p.name == "README.md")
        .expect("docs/language/README.md");
    let listed: BTreeSet<String> = links(&index.text).into_iter().map(|(f, _)| f).collect();
    let unlisted: Vec<&str> = pages
        .iter()
        .map(|p| p.name.as_str())
        .filter(|name| *name != "README.md" && !listed.contains(*name))
        .collect();
    assert!(
        unlisted.is_empty(),
        "pages the index (docs/language/README.md) does not list: {unlisted:?}"
    );
}

#[test]
fn every_link_of_the_reference_leads_somewhere() {
    let dir = repo_root().join("docs/language");
    let broken: Vec<String> = (pages().iter())
        .flat_map(|page| broken_links(&dir, &page.name, &page.text))
        .collect();
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}
