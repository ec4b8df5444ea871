//! Publishing diagnostics. Changes only queue their file; one task drains the
//! queue, analysing the *newest* snapshot of each file, so a burst of edits is
//! coalesced into one analysis without any fixed delay. A result whose
//! snapshot was replaced meanwhile is dropped: its file is queued again.
//!
//! A mission's dataflow warnings (`semo::dataflow`: it refines every robot)
//! are slower than its check: they never delay the keystroke's diagnostics.
//! Those are published at once, with the dataflow warnings when the host
//! already knows them for this snapshot; else a background task waits
//! [`DATAFLOW_DEBOUNCE`] (an edit meanwhile drops it), computes them, and
//! if there are any, publishes both again if the snapshot is still current.
//! A saved mission's `semo verify` findings (`verify.rs`) join them once
//! its search has ended, for that text only.

use crate::State;
use crate::to_proto;
use crate::world::{FileAnalysis, Snapshot, retire};
use semo::catalog::BUILTIN_FILE;
use semo::diag::FileId;
use semo::workspace::FileKind;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use tokio::sync::Notify;
use tower_lsp_server::Client;
use tower_lsp_server::ls_types::{self as lsp, Uri};

#[derive(Default)]
pub struct Queue {
    files: Mutex<Vec<Uri>>,
    wake: Notify,
}

impl Queue {
    /// Queues files for (re-)analysis; a file already queued keeps its place.
    pub fn push(&self, uris: impl IntoIterator<Item = Uri>) {
        let mut files = self.files.lock().unwrap_or_else(|e| e.into_inner());
        for uri in uris {
            if !files.contains(&uri) {
                files.push(uri);
            }
        }
        drop(files);
        self.wake.notify_one();
    }

    fn pop(&self) -> Option<Uri> {
        let mut files = self.files.lock().unwrap_or_else(|e| e.into_inner());
        (!files.is_empty()).then(|| files.remove(0))
    }
}

/// How long the typing must pause before a mission's dataflow is computed.
pub const DATAFLOW_DEBOUNCE: std::time::Duration = std::time::Duration::from_millis(300);

/// Runs for the life of the server.
pub async fn publish_loop(state: Arc<State>, client: Client) {
    state.indexed.wait().await;
    loop {
        state.queue.wake.notified().await;
        while let Some(uri) = state.queue.pop() {
            publish(&state, &client, uri).await;
        }
    }
}

async fn publish(state: &Arc<State>, client: &Client, uri: Uri) {
    let Some(snapshot) = state.world().snapshot(&uri) else {
        // Forgotten (closed and not in the workspace, or deleted): clear.
        client.publish_diagnostics(uri, Vec::new(), None).await;
        return;
    };
    let analysed = snapshot.clone();
    let Ok(analysis) = tokio::task::spawn_blocking(move || analysed.analysis()).await else {
        return;
    };
    let Some(others) = related_if_current(state, &snapshot, analysis.diagnostics()) else {
        // Stale: the newer snapshot is queued. This may be the last
        // reference to the old one: it is freed in the background.
        drop(analysis);
        return retire(snapshot);
    };
    let dataflow = match snapshot.kind {
        FileKind::Mission => snapshot.host().dataflow_if_known(snapshot.id),
        _ => None,
    };
    let later = snapshot.kind == FileKind::Mission && dataflow.is_none();
    let extra = dataflow.as_ref().map_or(&[][..], |d| &d.diagnostics[..]);
    // The file's own diagnostics are capped by the library (`diag::MAX_PER_FILE`);
    // the dataflow warnings are at most a few per service call.
    let mut diagnostics =
        to_proto::diagnostics(&snapshot, &analysis, analysis.diagnostics(), &others);
    diagnostics.extend(dataflow_to_lsp(state, &snapshot, &analysis, extra));
    let verified = state.verified.findings(&snapshot);
    diagnostics.extend(to_proto::diagnostics(
        &snapshot, &analysis, &verified, &others,
    ));
    let version = snapshot.version;
    drop(analysis);
    if later {
        tokio::spawn(publish_dataflow(
            state.clone(),
            client.clone(),
            Arc::downgrade(&snapshot),
        ));
    }
    retire(snapshot);
    client.publish_diagnostics(uri, diagnostics, version).await;
}

/// The mission's diagnostics again, with its dataflow warnings, unless the
/// snapshot is replaced before they are known. The pause holds the snapshot
/// weakly: while typing, every keystroke starts one of these, and holding
/// each version's analysis for the pause kept a dozen 10k-line analyses
/// alive at once (the server's peak memory went up sixfold that way).
async fn publish_dataflow(state: Arc<State>, client: Client, snapshot: Weak<Snapshot>) {
    tokio::time::sleep(DATAFLOW_DEBOUNCE).await;
    // Gone: a newer version replaced it and it was freed.
    let Some(snapshot) = snapshot.upgrade() else {
        return;
    };
    if !state.world().is_current(&snapshot) {
        return retire(snapshot);
    }
    let analysed = snapshot.clone();
    let Ok((analysis, dataflow)) = tokio::task::spawn_blocking(move || {
        (analysed.analysis(), analysed.host().dataflow(analysed.id))
    })
    .await
    else {
        return;
    };
    let Some(others) = related_if_current(&state, &snapshot, analysis.diagnostics()) else {
        drop(analysis);
        return retire(snapshot);
    };
    let extra = dataflow.as_ref().map_or(&[][..], |d| &d.diagnostics[..]);
    if extra.is_empty() {
        // What was published holds: nothing to add.
        drop(analysis);
        return retire(snapshot);
    }
    let mut diagnostics =
        to_proto::diagnostics(&snapshot, &analysis, analysis.diagnostics(), &others);
    diagnostics.extend(dataflow_to_lsp(&state, &snapshot, &analysis, extra));
    let verified = state.verified.findings(&snapshot);
    diagnostics.extend(to_proto::diagnostics(
        &snapshot, &analysis, &verified, &others,
    ));
    let (uri, version) = (snapshot.uri.clone(), snapshot.version);
    drop(analysis);
    retire(snapshot);
    client.publish_diagnostics(uri, diagnostics, version).await;
}

/// A mission's dataflow warnings, as the protocol has them.
fn dataflow_to_lsp(
    state: &State,
    snapshot: &Snapshot,
    analysis: &FileAnalysis,
    found: &[semo::diag::Diagnostic],
) -> Vec<lsp::Diagnostic> {
    if found.is_empty() {
        return Vec::new();
    }
    let others = {
        let world = state.world();
        related_files(found, |id| world.uri_of(id).cloned())
    };
    to_proto::diagnostics(snapshot, analysis, found, &others)
}

/// [`related_files`] of `diagnostics`, while `snapshot` is still the current
/// one (the world's lock is released before returning); `None` once it is not.
fn related_if_current(
    state: &State,
    snapshot: &Arc<Snapshot>,
    diagnostics: &[semo::diag::Diagnostic],
) -> Option<HashMap<FileId, Uri>> {
    let world = state.world();
    world
        .is_current(snapshot)
        .then(|| related_files(diagnostics, |id| world.uri_of(id).cloned()))
}

/// The URIs of the other files that related information points into.
fn related_files(
    diagnostics: &[semo::diag::Diagnostic],
    uri_of: impl Fn(FileId) -> Option<Uri>,
) -> HashMap<FileId, Uri> {
    let mut out = HashMap::new();
    for d in diagnostics {
        for r in &d.related {
            if r.file != d.file && r.file != BUILTIN_FILE {
                if let Some(uri) = uri_of(r.file) {
                    out.insert(r.file, uri);
                }
            }
        }
    }
    out
}
