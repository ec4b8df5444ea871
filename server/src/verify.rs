//! `semo verify` in the editor: after a mission is saved, its behaviours
//! are explored in the background (the library's `semo::verify`, the call
//! `semo verify` makes, with a budget the editor can afford) and the
//! findings join the mission's diagnostics while that saved text is the
//! current one. An edit, a close or the next save cancels a search under
//! way (its flag is checked at every state) and drops its findings, so a
//! search never delays typing and never shows findings of another text.

use crate::State;
use crate::world::Snapshot;
use semo::workspace::FileKind;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use tower_lsp_server::ls_types::Uri;

/// The editor's search: a minute of mission time, twenty thousand states,
/// 256 MiB (beside the editor's own memory: a swarm's states are large).
fn options(cancel: Arc<AtomicBool>) -> semo::verify::Options {
    semo::verify::Options {
        horizon_ms: 60_000,
        max_states: 20_000,
        max_memory: 256 << 20,
        cancel: Some(cancel),
        ..semo::verify::Options::default()
    }
}

/// Per mission: the search under way, or the findings of the text saved.
#[derive(Default)]
pub struct Verified {
    missions: Mutex<HashMap<Uri, Entry>>,
}

struct Entry {
    cancel: Arc<AtomicBool>,
    /// The snapshot searched.
    snapshot: std::sync::Weak<Snapshot>,
    /// Once the search has ended.
    findings: Option<Vec<Finding>>,
}

/// A finding, and the scenario that replays its counterexample when it has
/// one (`semo verify --counterexamples` writes the same text).
#[derive(Clone)]
struct Finding {
    diagnostic: semo::diag::Diagnostic,
    scenario: Option<String>,
}

impl Verified {
    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<Uri, Entry>> {
        self.missions.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The mission changed or closed: stop its search, forget its findings.
    pub fn forget(&self, uri: &Uri) {
        if let Some(entry) = self.lock().remove(uri) {
            entry.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// The findings of `snapshot`, once its search has ended.
    pub fn findings(&self, snapshot: &Arc<Snapshot>) -> Vec<semo::diag::Diagnostic> {
        self.found(snapshot)
            .into_iter()
            .map(|f| f.diagnostic)
            .collect()
    }

    fn found(&self, snapshot: &Arc<Snapshot>) -> Vec<Finding> {
        self.lock()
            .get(&snapshot.uri)
            .filter(|e| std::ptr::eq(e.snapshot.as_ptr(), Arc::as_ptr(snapshot)))
            .and_then(|e| e.findings.clone())
            .unwrap_or_default()
    }

    /// The findings of `snapshot` that have a counterexample: each with the
    /// file its scenario is written to beside the mission, as `semo verify
    /// --counterexamples` names it (the quick fix of `to_proto::scenario_action`).
    pub fn counterexamples(&self, snapshot: &Arc<Snapshot>) -> Vec<Counterexample> {
        let found = self.found(snapshot);
        let Some(path) = snapshot.uri.to_file_path() else {
            return Vec::new();
        };
        let stem = path
            .file_stem()
            .map_or("mission".into(), |s| s.to_string_lossy().into_owned());
        let mut out = Vec::new();
        for (n, finding) in found.into_iter().enumerate() {
            let Some(scenario) = finding.scenario else {
                continue;
            };
            let name = semo::verify::counterexample_name(&stem, finding.diagnostic.code, n + 1);
            let file = path.with_file_name(format!("{name}.scenario.json"));
            let Some(uri) = Uri::from_file_path(&file) else {
                continue;
            };
            out.push(Counterexample {
                diagnostic: finding.diagnostic,
                name,
                uri,
                scenario,
            });
        }
        out
    }
}

/// A finding with its counterexample's scenario and where it is written.
pub struct Counterexample {
    pub diagnostic: semo::diag::Diagnostic,
    /// The file's name without `.scenario.json`.
    pub name: String,
    pub uri: Uri,
    pub scenario: String,
}

/// After a save: search the mission's current text in the background; when
/// the search ends and the text is still current, publish again.
pub fn after_save(state: &Arc<State>, uri: &Uri) {
    let Some(snapshot) = state.world().snapshot(uri) else {
        return;
    };
    if snapshot.kind != FileKind::Mission {
        return;
    }
    let cancel = Arc::new(AtomicBool::new(false));
    {
        let mut missions = state.verified.lock();
        if let Some(old) = missions.insert(
            uri.clone(),
            Entry {
                cancel: cancel.clone(),
                snapshot: Arc::downgrade(&snapshot),
                findings: None,
            },
        ) {
            old.cancel.store(true, Ordering::Relaxed);
        }
    }
    let state = state.clone();
    tokio::spawn(async move {
        let searched = snapshot.clone();
        let flag = cancel.clone();
        let Ok(Some(findings)) = tokio::task::spawn_blocking(move || search(&searched, flag)).await
        else {
            return;
        };
        if cancel.load(Ordering::Relaxed) || !state.world().is_current(&snapshot) {
            return;
        }
        if let Some(entry) = state.verified.lock().get_mut(&snapshot.uri)
            && Arc::ptr_eq(&entry.cancel, &cancel)
        {
            entry.findings = Some(findings);
        }
        state.queue.push([snapshot.uri.clone()]);
    });
}

/// Why a search of a snapshot gave no report.
pub enum NoReport {
    /// The mission has errors: there is nothing to run (its diagnostics say why).
    Errors,
    /// The expectations file, or the options, could not be used.
    Refused(String),
    Cancelled,
}

/// The snapshot's mission refined and explored with `options`, judging the
/// properties `properties` reads against the refined programs, the
/// project's lint levels applied: the one search of the background run
/// after a save and of the `semo.verify` command.
pub fn explore(
    snapshot: &Snapshot,
    options: &semo::verify::Options,
    properties: impl FnOnce(
        &[semo::refine::RobotProgram],
    ) -> Result<Vec<semo::verify::Property>, String>,
) -> Result<(semo::verify::Report, Arc<semo::refine::Refined>), NoReport> {
    let refined = snapshot
        .host()
        .refined(snapshot.id)
        .ok_or(NoReport::Errors)?;
    if refined.diagnostics.iter().any(|d| d.is_error()) {
        return Err(NoReport::Errors);
    }
    let properties = properties(&refined.programs).map_err(NoReport::Refused)?;
    let mut report = semo::verify::verify_expecting(
        &refined.programs,
        snapshot.id,
        &snapshot.text,
        options,
        properties,
    )
    .map_err(NoReport::Refused)?;
    if report.cancelled {
        return Err(NoReport::Cancelled);
    }
    if let Some(project) = snapshot.host().project(snapshot.id) {
        report.apply_lints(&project.project);
    }
    Ok((report, refined))
}

/// The findings of a search of the snapshot's mission; `None` when it has
/// errors (nothing to run) or the search was cancelled.
fn search(snapshot: &Snapshot, cancel: Arc<AtomicBool>) -> Option<Vec<Finding>> {
    let (report, refined) = match explore(snapshot, &options(cancel), |_| Ok(Vec::new())) {
        Ok(found) => found,
        Err(NoReport::Refused(problem)) => {
            // The editor's options are fixed: refusing them is a bug.
            eprintln!("semo-server: internal error: verify refused its options: {problem}");
            return None;
        }
        Err(NoReport::Errors | NoReport::Cancelled) => return None,
    };
    let scenarios = report.counterexamples.iter().map(|way| {
        way.as_ref()
            .map(|w| w.scenario_json(&report.inputs, &refined.programs))
    });
    Some(
        report
            .findings
            .iter()
            .cloned()
            .zip(scenarios)
            .map(|(diagnostic, scenario)| Finding {
                diagnostic,
                scenario,
            })
            .collect(),
    )
}
