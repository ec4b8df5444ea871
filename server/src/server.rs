//! The `LanguageServer` implementation: each method is a thin translation to
//! the [`World`](crate::world::World) (notifications) or to a handler in
//! [`crate::handlers`] (requests), which work on immutable snapshots.

use crate::encoding::Encoding;
use crate::handlers;
use crate::world::{self, Snapshot};
use crate::{State, diagnostics};
use semo::codegen::output;
use semo::host;
use semo::ide::CompletionConfig;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use tower_lsp_server::jsonrpc::{Error, Result};
use tower_lsp_server::ls_types::*;
use tower_lsp_server::{Bounded, Client, LanguageServer, NotCancellable, OngoingProgress};

pub struct Backend {
    client: Client,
    state: Arc<State>,
    /// Whether the client lets us register file watchers at run time.
    can_watch: std::sync::atomic::AtomicBool,
    /// Whether the client takes snippets in completion items (from `initialize`).
    snippets: AtomicBool,
    /// Whether the client shows `$/progress` (`window.workDoneProgress`).
    progress: AtomicBool,
    /// Whether the client applies edits that create files
    /// (`workspace.workspaceEdit`: document changes with `create`).
    creates_files: AtomicBool,
    /// Whether the client tells the user itself how a `semo.generateCode`
    /// ended, from its answer (`initializationOptions`:
    /// `generateCodeOutcome: true`, as the VS Code extension says): the
    /// server then shows no message of its own for it, so that one
    /// generation is one notification.
    client_tells_generation: AtomicBool,
    /// The live robot monitors, one per mission document.
    monitors: crate::monitor::Monitors,
}

impl Backend {
    /// Starts the diagnostics task; called by `LspService` inside the runtime.
    pub fn new(client: Client) -> Backend {
        let state = Arc::new(State::default());
        tokio::spawn(diagnostics::publish_loop(state.clone(), client.clone()));
        Backend {
            client,
            state,
            can_watch: Default::default(),
            snippets: AtomicBool::new(false),
            client_tells_generation: AtomicBool::new(false),
            progress: AtomicBool::new(false),
            creates_files: AtomicBool::new(false),
            monitors: Default::default(),
        }
    }

    /// The world for a request: once the workspace folders were read.
    async fn world(&self) -> std::sync::MutexGuard<'_, world::World> {
        self.state.indexed.wait().await;
        self.state.world()
    }

    /// The current snapshot of a document, or an error for files never opened
    /// nor found in the workspace.
    async fn snapshot(&self, uri: &Uri) -> Result<Arc<Snapshot>> {
        self.world()
            .await
            .snapshot(uri)
            .ok_or_else(|| unknown_document(uri))
    }

    /// Runs `f` on a document's snapshot and the workspace analysis taken
    /// with it (under one lock, so the analysis holds the snapshot's text),
    /// off the async threads: for the position queries, which may read other
    /// files of the workspace (a strategy file the mission's own snapshot
    /// predates).
    async fn on_query<T: Send + 'static>(
        &self,
        uri: &Uri,
        f: impl FnOnce(&Snapshot, &host::Analysis) -> T + Send + 'static,
    ) -> Result<T> {
        let (snapshot, workspace) = {
            let world = self.world().await;
            (world.snapshot(uri), world.analysis())
        };
        let snapshot = snapshot.ok_or_else(|| unknown_document(uri))?;
        tokio::task::spawn_blocking(move || f(&snapshot, &workspace))
            .await
            .map_err(|e| Error {
                code: tower_lsp_server::jsonrpc::ErrorCode::InternalError,
                message: format!("the request failed: {e}").into(),
                data: None,
            })
    }

    /// Runs `f` on a snapshot off the async threads. A panic inside a handler
    /// becomes an internal error for this request only.
    async fn on_snapshot<T: Send + 'static>(
        &self,
        uri: &Uri,
        f: impl FnOnce(&Snapshot) -> T + Send + 'static,
    ) -> Result<T> {
        let snapshot = self.snapshot(uri).await?;
        tokio::task::spawn_blocking(move || f(&snapshot))
            .await
            .map_err(|e| Error {
                code: tower_lsp_server::jsonrpc::ErrorCode::InternalError,
                message: format!("the request failed: {e}").into(),
                data: None,
            })
    }

    /// `semo/catalog`: the robot types the workspace sees (for the robot panel).
    pub async fn catalog(
        &self,
        params: handlers::catalog::CatalogParams,
    ) -> Result<serde_json::Value> {
        let catalog = {
            let world = self.world().await;
            match params.uri.as_ref().and_then(|u| world.snapshot(u)) {
                Some(snapshot) => snapshot.catalog.clone(),
                None => world.catalog(),
            }
        };
        tokio::task::spawn_blocking(move || handlers::catalog::catalog(catalog.catalog()))
            .await
            .map_err(|_| Error::internal_error())
    }

    /// `semo/graphSvg`: the SVG of a task graph, or of a mission's mode
    /// machines (for the editor's graph view).
    pub async fn graph_svg(
        &self,
        params: handlers::graph_svg::GraphSvgParams,
    ) -> Result<serde_json::Value> {
        let uri = params.text_document.uri.clone();
        self.on_snapshot(&uri, move |s| handlers::graph_svg::graph_svg(s, &params))
            .await?
    }

    /// `semo/monitor/start`: the mission's robots and broker; then the
    /// session's `semo/monitor` notifications (`handlers/monitor.rs`).
    pub async fn monitor_start(
        &self,
        params: handlers::monitor::StartParams,
    ) -> Result<serde_json::Value> {
        use handlers::monitor;
        let job = monitor::job(&*self.world().await, params).map_err(handlers::request_failed)?;
        let plan = tokio::task::spawn_blocking(move || monitor::plan(&job))
            .await
            .map_err(|_| Error::internal_error())?
            .map_err(handlers::request_failed)?;
        let answer = monitor::started(&plan);
        let (notify, mut notifications) = tokio::sync::mpsc::unbounded_channel();
        let client = self.client.clone();
        tokio::spawn(async move {
            while let Some(params) = notifications.recv().await {
                client
                    .send_notification::<monitor::MonitorNotification>(params)
                    .await;
            }
        });
        self.monitors
            .start(plan, notify)
            .map_err(|e| handlers::request_failed(format!("cannot start the monitor: {e}")))?;
        Ok(answer)
    }

    /// `semo/monitor/stop`: ends the mission's monitor; whether one ran.
    pub async fn monitor_stop(
        &self,
        params: handlers::monitor::StopParams,
    ) -> Result<serde_json::Value> {
        let stopped = self.monitors.stop(params.uri.as_str());
        Ok(serde_json::json!({ "stopped": stopped }))
    }

    /// `semo/viewFileText`: the server's text of a document, to debug
    /// synchronisation (as rust-analyzer's `viewFileText`).
    pub async fn view_file_text(&self, params: TextDocumentIdentifier) -> Result<String> {
        Ok(self.snapshot(&params.uri).await?.text.to_string())
    }

    /// `semo.simulate`: the mission's robots run on a scenario; the summary,
    /// the timeline SVG and the expectations, or the reason for refusing;
    /// the scenario file's diagnostics published.
    async fn simulate(&self, arguments: &[serde_json::Value]) -> Result<serde_json::Value> {
        use handlers::simulate;
        let params = simulate::params(arguments).map_err(Error::invalid_params)?;
        let job = {
            let world = self.world().await;
            simulate::job(&world, params).map_err(handlers::request_failed)?
        };
        let outcome = tokio::task::spawn_blocking(move || simulate::simulate(&job))
            .await
            .map_err(|_| Error::internal_error())?;
        if let Some((uri, diagnostics)) = outcome.scenario {
            self.client
                .publish_diagnostics(uri, diagnostics, None)
                .await;
        }
        outcome.answer.map_err(handlers::request_failed)
    }

    /// `semo.verify`: the mission's behaviours explored on demand; a
    /// cancelled request stops the search at its next state.
    async fn verify(&self, arguments: &[serde_json::Value]) -> Result<serde_json::Value> {
        use handlers::verify_mission;
        let params = verify_mission::params(arguments).map_err(Error::invalid_params)?;
        let cancel = CancelOnDrop::default();
        let job = {
            let world = self.world().await;
            verify_mission::job(&world, params, cancel.0.clone())
                .map_err(handlers::request_failed)?
        };
        let answer = tokio::task::spawn_blocking(move || verify_mission::verify(&job))
            .await
            .map_err(|_| Error::internal_error())?;
        drop(cancel);
        answer.map_err(handlers::request_failed)
    }

    /// `semo.generateCode`: generates the code of a mission, reporting each
    /// robot as `$/progress`; a refusal publishes its reasons as the mission's
    /// diagnostics and is shown to the user.
    async fn generate_code(
        &self,
        arguments: &[serde_json::Value],
        token: Option<ProgressToken>,
    ) -> Result<serde_json::Value> {
        use handlers::generate_code as generate;
        let params = generate::params(arguments).map_err(Error::invalid_params)?;
        let (job, encoding) = {
            let world = self.world().await;
            let job = generate::job(&world, params).map_err(handlers::request_failed)?;
            (job, world.encoding)
        };
        let job = Arc::new(job);
        let work = job.clone();
        let (result, text) = tokio::task::spawn_blocking(move || generate::generate(&work))
            .await
            .map_err(|_| Error::internal_error())?
            .map_err(|e| handlers::request_failed(e.to_string()))?;
        if result.refused() {
            let errors = result.diagnostics.iter().filter(|d| d.is_error()).count();
            let diagnostics =
                generate::mission_diagnostics(&job, &text, &result.diagnostics, encoding);
            self.client
                .publish_diagnostics(job.mission_uri.clone(), diagnostics, None)
                .await;
            let message = format!(
                "SeMo: code generation refused: {errors} error(s) in {} (see Problems)",
                job.mission_path.display()
            );
            self.tell_generation(MessageType::ERROR, &message).await;
            let reasons: Vec<String> = result
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .map(|d| format!("[{}] {}", d.code.as_str(), d.message))
                .collect();
            return Ok(serde_json::json!({ "refused": true, "errors": reasons }));
        }
        let token = match token {
            Some(t) => Some(t),
            None if self.progress.load(Ordering::Relaxed) => {
                // One token per generation: two at once must not share one.
                static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
                let n = NEXT.fetch_add(1, Ordering::Relaxed);
                let t = ProgressToken::String(format!("semo-generate-{n}"));
                self.client
                    .create_work_done_progress(t.clone())
                    .await
                    .ok()
                    .map(|_| t)
            }
            None => None,
        };
        let progress = match token {
            Some(t) => Some(
                self.client
                    .progress(t, "SeMo: generating code")
                    .with_percentage(0)
                    .begin()
                    .await,
            ),
            None => None,
        };
        let total = result.robots.len().max(1);
        let mut robots = Vec::new();
        // Set when this future is dropped (the request cancelled): the
        // blocking work then stops before its next robot and writes nothing.
        let cancelled = CancelOnDrop::default();
        let work = job.clone();
        let (begun, result) = tokio::task::spawn_blocking(move || {
            let begun = generate::begin(&work, &result);
            (begun, result)
        })
        .await
        .map_err(|_| Error::internal_error())?;
        let all = Arc::new(result.robots);
        let mut transaction = match begun {
            Ok(t) => t,
            Err(refused) => {
                if let Some(p) = progress {
                    p.finish_with_message("refused").await;
                }
                let message = format!("SeMo: {}", refused.message);
                self.tell_generation(MessageType::ERROR, &message).await;
                return Err(Error {
                    data: refused.data,
                    ..handlers::request_failed(message)
                });
            }
        };
        transaction.cancel_with(cancelled.0.clone());
        let recovered = transaction.recovered.clone();
        for line in &recovered {
            let message = format!("SeMo: recovered: {line}");
            self.tell_generation(MessageType::WARNING, &message).await;
        }
        for i in 0..all.len() {
            if let Some(p) = &progress {
                let percent = (100 * i / total) as u32;
                p.report_with_message(format!("{}/{}", all[i].team, all[i].robot), percent)
                    .await;
            }
            let (force, robots_of) = (job.force, all.clone());
            let (back, written) = tokio::task::spawn_blocking(move || {
                let written = transaction.stage_robot(&robots_of[i], force);
                (transaction, written)
            })
            .await
            .map_err(|_| Error::internal_error())?;
            transaction = back;
            match written {
                Ok(w) => robots.push(generate::robot_summary(&all[i], &w)),
                Err(e) => return Err(self.generation_failed(progress, e).await),
            }
        }
        // A cancel that comes once files are being replaced is too late: the
        // generation finishes, and the user is told so (the client got
        // `Canceled` and shows no outcome).
        let late = Arc::new(LateCancel {
            cancelled: cancelled.0.clone(),
            committed: AtomicBool::new(false),
            answered: AtomicBool::new(false),
            told: AtomicBool::new(false),
            client: self.client.clone(),
            runtime: tokio::runtime::Handle::current(),
            message: format!(
                "SeMo: Generate Code was cancelled too late: the code of {} robot(s) was written to {}",
                all.len(),
                job.out.path().display()
            ),
        });
        let _told_when_dropped = LateCancelGuard(late.clone());
        let committing = late.clone();
        let kept = match tokio::task::spawn_blocking(move || {
            let kept = transaction.commit();
            if kept.is_ok() {
                committing.committed.store(true, Ordering::SeqCst);
                committing.tell_if_late();
            }
            kept
        })
        .await
        .map_err(|_| Error::internal_error())?
        {
            Ok(kept) => kept,
            Err(e) => return Err(self.generation_failed(progress, e).await),
        };
        if !kept.is_empty() {
            let message = format!("SeMo: {}", output::kept_message(&kept));
            self.tell_generation(MessageType::WARNING, &message).await;
        }
        if let Some(p) = progress {
            p.finish_with_message(format!("{} robot(s)", robots.len()))
                .await;
        }
        // What the plan found in the project file (a `[build.targets]` name
        // the mission does not have): built anyway, said.
        let warnings: Vec<String> = job
            .plan
            .diagnostics
            .iter()
            .map(|d| format!("[{}] {}", d.code.as_str(), d.message))
            .collect();
        for warning in &warnings {
            let message = format!("SeMo: {}: {warning}", semo::project::FILE_NAME);
            self.tell_generation(MessageType::WARNING, &message).await;
        }
        let targets = semo::targets::distinct(all.iter().map(|r| r.target));
        let message = format!(
            "SeMo: generated code for {} robot(s) ({}) in {}",
            robots.len(),
            generate::target_names(&targets),
            job.out.path().display()
        );
        self.tell_generation(MessageType::INFO, &message).await;
        late.answered.store(true, Ordering::SeqCst);
        Ok(serde_json::json!({
            "refused": false,
            "outputFolder": job.out.path().display().to_string(),
            "kept": kept
                .iter()
                .map(|c| serde_json::json!({ "path": c.path.display().to_string(), "why": c.why }))
                .collect::<Vec<_>>(),
            // The build's one target (else null: each robot's is in `robots`).
            "target": match targets.as_slice() {
                [one] => serde_json::json!(one.name()),
                _ => serde_json::Value::Null,
            },
            "targets": targets.iter().map(|t| t.name()).collect::<Vec<_>>(),
            "robots": robots,
            "warnings": warnings,
            "recovered": recovered,
        }))
    }

    /// Ends the progress and tells the user why the generation stopped.
    async fn generation_failed(
        &self,
        progress: Option<OngoingProgress<Bounded, NotCancellable>>,
        error: output::OutputError,
    ) -> Error {
        if let Some(p) = progress {
            p.finish_with_message("failed").await;
        }
        let message = format!("SeMo: cannot write the generated code: {error}");
        self.tell_generation(MessageType::ERROR, &message).await;
        handlers::request_failed(message)
    }

    /// A message about a code generation, unless the client tells the user
    /// itself (`client_tells_generation`).
    async fn tell_generation(&self, kind: MessageType, message: &str) {
        if !self.client_tells_generation.load(Ordering::Relaxed) {
            self.client.show_message(kind, message).await;
        }
    }

    async fn register_watchers(&self) {
        if !self.can_watch.load(std::sync::atomic::Ordering::Relaxed) {
            return;
        }
        let watchers = [
            "**/*.mission",
            "**/*.robot.xml",
            "**/*.strategy.xml",
            "**/*.taskgraph.xml",
            "**/semo.toml",
        ]
        .into_iter()
        .map(|glob| FileSystemWatcher {
            glob_pattern: GlobPattern::String(glob.to_string()),
            kind: None,
        })
        .collect();
        let registration = Registration {
            id: "semo-files".to_string(),
            method: "workspace/didChangeWatchedFiles".to_string(),
            register_options: serde_json::to_value(DidChangeWatchedFilesRegistrationOptions {
                watchers,
            })
            .ok(),
        };
        // Not awaited here: a client that exits before answering would leave
        // `initialized` waiting for ever, and the server could not stop.
        let client = self.client.clone();
        tokio::spawn(async move {
            let _ = client.register_capability(vec![registration]).await;
        });
    }

    async fn index_workspace(&self) {
        let roots = self.state.world().roots().to_vec();
        if let Ok(found) = tokio::task::spawn_blocking(move || world::read_roots(&roots)).await {
            let changed = self.state.world().index(found);
            self.state.queue.push(changed.files);
        }
        self.state.indexed.open();
    }
}

fn roots(params: &InitializeParams) -> Vec<std::path::PathBuf> {
    let folders = params.workspace_folders.iter().flatten().map(|f| &f.uri);
    #[allow(deprecated)] // rootUri is what older clients send
    let root = params.root_uri.iter();
    folders.chain(root).filter_map(world::file_path).collect()
}

impl LanguageServer for Backend {
    async fn initialize(&self, params: InitializeParams) -> Result<InitializeResult> {
        let encoding = Encoding::negotiate(&params.capabilities);
        let can_watch = params
            .capabilities
            .workspace
            .as_ref()
            .and_then(|w| w.did_change_watched_files.as_ref())
            .and_then(|w| w.dynamic_registration)
            .unwrap_or(false);
        self.can_watch
            .store(can_watch, std::sync::atomic::Ordering::Relaxed);
        let progress = params
            .capabilities
            .window
            .as_ref()
            .and_then(|w| w.work_done_progress)
            .unwrap_or(false);
        self.progress.store(progress, Ordering::Relaxed);
        let edits = params
            .capabilities
            .workspace
            .as_ref()
            .and_then(|w| w.workspace_edit.as_ref());
        let creates_files = edits.is_some_and(|e| {
            e.document_changes == Some(true)
                && e.resource_operations
                    .as_ref()
                    .is_some_and(|ops| ops.contains(&ResourceOperationKind::Create))
        });
        self.creates_files.store(creates_files, Ordering::Relaxed);
        let snippets = handlers::completion::snippet_support(&params.capabilities);
        self.snippets.store(snippets, Ordering::Relaxed);
        let tells = params
            .initialization_options
            .as_ref()
            .and_then(|o| o.get("generateCodeOutcome"))
            .and_then(serde_json::Value::as_bool)
            .unwrap_or(false);
        self.client_tells_generation.store(tells, Ordering::Relaxed);
        {
            let mut world = self.state.world();
            world.encoding = encoding;
            world.set_roots(roots(&params));
            // With no folder to read there is nothing to wait for: opened
            // here, a client that never sends `initialized` (the protocol
            // asks it to) still gets answers.
            if world.roots().is_empty() {
                self.state.indexed.open();
            }
        }
        Ok(InitializeResult {
            server_info: Some(ServerInfo {
                name: "semo".to_string(),
                version: Some(env!("CARGO_PKG_VERSION").to_string()),
            }),
            capabilities: handlers::capabilities(encoding),
            offset_encoding: None,
        })
    }

    async fn initialized(&self, _: InitializedParams) {
        self.register_watchers().await;
        self.index_workspace().await;
    }

    async fn shutdown(&self) -> Result<()> {
        self.monitors.stop_all();
        Ok(())
    }

    // Notifications change the world synchronously, before any `.await`, so
    // they apply in the order the client sent them.

    async fn did_open(&self, p: DidOpenTextDocumentParams) {
        let d = p.text_document;
        let changed = self
            .state
            .world()
            .open(d.uri, &d.language_id, &d.text, d.version);
        self.state.queue.push(changed.files);
    }

    async fn did_change(&self, p: DidChangeTextDocumentParams) {
        let d = p.text_document;
        self.state.verified.forget(&d.uri);
        let changed = self
            .state
            .world()
            .change(&d.uri, d.version, p.content_changes);
        self.state.queue.push(changed.files);
    }

    async fn did_save(&self, p: DidSaveTextDocumentParams) {
        // The text is already current; re-publishing confirms the saved
        // state, and a saved mission's behaviours are explored.
        crate::verify::after_save(&self.state, &p.text_document.uri);
        self.state.queue.push([p.text_document.uri]);
    }

    async fn did_close(&self, p: DidCloseTextDocumentParams) {
        self.monitors.stop(p.text_document.uri.as_str());
        self.state.verified.forget(&p.text_document.uri);
        let changed = self.state.world().close(&p.text_document.uri);
        self.state.queue.push(changed.files);
    }

    async fn did_change_watched_files(&self, p: DidChangeWatchedFilesParams) {
        let mut changed = Vec::new();
        for event in p.changes {
            let text = if event.typ == FileChangeType::DELETED {
                None
            } else {
                world::file_path(&event.uri).and_then(|path| world::read_text(&path))
            };
            let mut world = self.state.world();
            changed.extend(match text {
                None if event.typ == FileChangeType::DELETED => {
                    world.disk_deleted(&event.uri).files
                }
                text => world.disk_changed(&event.uri, text).files,
            });
        }
        self.state.queue.push(changed);
    }

    // Requests: a snapshot, and a handler off the async threads.

    async fn completion(&self, p: CompletionParams) -> Result<Option<CompletionResponse>> {
        let position = p.text_document_position.position;
        let config = CompletionConfig {
            snippets: self.snippets.load(Ordering::Relaxed),
        };
        let uri = &p.text_document_position.text_document.uri;
        let scenario = handlers::scenario::job(&*self.world().await, uri);
        if let Some(job) = scenario {
            return tokio::task::spawn_blocking(move || {
                Some(handlers::scenario::completion(&job, position))
            })
            .await
            .map_err(|e| Error {
                code: tower_lsp_server::jsonrpc::ErrorCode::InternalError,
                message: format!("the request failed: {e}").into(),
                data: None,
            });
        }
        self.on_query(uri, move |s, w| {
            handlers::completion::completion(s, w, position, config)
        })
        .await
    }

    async fn formatting(&self, p: DocumentFormattingParams) -> Result<Option<Vec<TextEdit>>> {
        self.on_snapshot(&p.text_document.uri, handlers::formatting::formatting)
            .await?
    }

    async fn hover(&self, p: HoverParams) -> Result<Option<Hover>> {
        let position = p.text_document_position_params.position;
        self.on_query(
            &p.text_document_position_params.text_document.uri,
            move |s, w| handlers::hover::hover(s, w, position),
        )
        .await
    }

    async fn signature_help(&self, p: SignatureHelpParams) -> Result<Option<SignatureHelp>> {
        let position = p.text_document_position_params.position;
        self.on_query(
            &p.text_document_position_params.text_document.uri,
            move |s, w| handlers::signature_help::signature_help(s, w, position),
        )
        .await
    }

    async fn inlay_hint(&self, p: InlayHintParams) -> Result<Option<Vec<InlayHint>>> {
        let range = p.range;
        self.on_snapshot(&p.text_document.uri, move |s| {
            handlers::inlay_hints::inlay_hints(s, range)
        })
        .await
    }

    async fn code_action(&self, p: CodeActionParams) -> Result<Option<CodeActionResponse>> {
        let uri = p.text_document.uri.clone();
        let asked = p.context.diagnostics.clone();
        let quick_fixes = p.context.only.as_ref().is_none_or(|only| {
            only.iter()
                .any(|k| CodeActionKind::QUICKFIX.as_str().starts_with(k.as_str()))
        });
        let found = self
            .on_query(&uri, move |s, w| {
                handlers::code_actions::code_actions(s, w, &p)
            })
            .await?;
        let world = self.state.world();
        let mut response = found.response(|id| world.uri_of(id).cloned());
        // `semo verify`'s findings: write the scenario that shows each (a
        // new file: only for a client that creates files).
        let creates_files = self.creates_files.load(Ordering::Relaxed);
        if let Some(snapshot) = world
            .snapshot(&uri)
            .filter(|_| quick_fixes && creates_files)
        {
            let found = self.state.verified.counterexamples(&snapshot);
            if !found.is_empty() {
                let analysis = snapshot.analysis();
                let lines = snapshot.line_map(&analysis);
                response.extend(crate::to_proto::scenario_actions(found, &lines, &asked));
            }
        }
        Ok(Some(response))
    }

    // Navigation and structure.

    async fn goto_definition(
        &self,
        p: GotoDefinitionParams,
    ) -> Result<Option<GotoDefinitionResponse>> {
        let at = p.text_document_position_params;
        let found = self
            .on_query(&at.text_document.uri, move |s, w| {
                handlers::definition::definition(s, w, at.position)
            })
            .await?;
        let world = self.state.world();
        Ok(handlers::definition::response(found, |id| {
            world.uri_of(id).cloned()
        }))
    }

    async fn references(&self, p: ReferenceParams) -> Result<Option<Vec<Location>>> {
        let uri = p.text_document_position.text_document.uri.clone();
        let found = self
            .on_query(&uri, move |s, w| handlers::references::references(s, w, &p))
            .await?;
        let world = self.state.world();
        let locations: Vec<Location> = found
            .into_iter()
            .filter_map(|(file, range)| Some(Location::new(world.uri_of(file)?.clone(), range)))
            .collect();
        Ok((!locations.is_empty()).then_some(locations))
    }

    async fn document_highlight(
        &self,
        p: DocumentHighlightParams,
    ) -> Result<Option<Vec<DocumentHighlight>>> {
        let at = p.text_document_position_params;
        self.on_snapshot(&at.text_document.uri, move |s| {
            handlers::document_highlight::document_highlight(s, at.position)
        })
        .await
    }

    async fn prepare_rename(
        &self,
        p: TextDocumentPositionParams,
    ) -> Result<Option<PrepareRenameResponse>> {
        self.on_snapshot(&p.text_document.uri, move |s| {
            handlers::prepare_rename::prepare_rename(s, p.position)
        })
        .await?
    }

    async fn rename(&self, p: RenameParams) -> Result<Option<WorkspaceEdit>> {
        let uri = p.text_document_position.text_document.uri.clone();
        let Some(edits) = self
            .on_query(&uri, move |s, w| handlers::rename::rename(s, w, &p))
            .await??
        else {
            return Ok(None);
        };
        let world = self.state.world();
        let changes = edits
            .into_iter()
            .filter_map(|(file, edits)| Some((world.uri_of(file)?.clone(), edits)))
            .collect();
        Ok(Some(WorkspaceEdit {
            changes: Some(changes),
            ..WorkspaceEdit::default()
        }))
    }

    async fn document_symbol(
        &self,
        p: DocumentSymbolParams,
    ) -> Result<Option<DocumentSymbolResponse>> {
        self.on_snapshot(
            &p.text_document.uri,
            handlers::document_symbol::document_symbol,
        )
        .await
    }

    async fn symbol(&self, p: WorkspaceSymbolParams) -> Result<Option<WorkspaceSymbolResponse>> {
        let (workspace, encoding, uris) = {
            let world = self.world().await;
            (world.analysis(), world.encoding, world.file_uris())
        };
        let found = tokio::task::spawn_blocking(move || {
            let uri_of = |id: semo::diag::FileId| uris.get(id.0 as usize).cloned();
            handlers::workspace_symbol::workspace_symbol(&workspace, encoding, uri_of, &p.query)
        })
        .await
        .map_err(|_| Error::internal_error())?;
        Ok(Some(WorkspaceSymbolResponse::Flat(found)))
    }

    async fn semantic_tokens_full(
        &self,
        p: SemanticTokensParams,
    ) -> Result<Option<SemanticTokensResult>> {
        let tokens = self
            .on_snapshot(&p.text_document.uri, |s| {
                handlers::semantic_tokens::semantic_tokens(s, None)
            })
            .await?;
        Ok(tokens.map(SemanticTokensResult::Tokens))
    }

    async fn semantic_tokens_range(
        &self,
        p: SemanticTokensRangeParams,
    ) -> Result<Option<SemanticTokensRangeResult>> {
        let range = p.range;
        let tokens = self
            .on_snapshot(&p.text_document.uri, move |s| {
                handlers::semantic_tokens::semantic_tokens(s, Some(range))
            })
            .await?;
        Ok(tokens.map(SemanticTokensRangeResult::Tokens))
    }

    async fn folding_range(&self, p: FoldingRangeParams) -> Result<Option<Vec<FoldingRange>>> {
        self.on_snapshot(&p.text_document.uri, handlers::folding_range::folding_range)
            .await
    }

    async fn selection_range(
        &self,
        p: SelectionRangeParams,
    ) -> Result<Option<Vec<SelectionRange>>> {
        let positions = p.positions;
        self.on_snapshot(&p.text_document.uri, move |s| {
            handlers::selection_range::selection_range(s, &positions)
        })
        .await
    }

    async fn code_lens(&self, p: CodeLensParams) -> Result<Option<Vec<CodeLens>>> {
        let lenses = self
            .on_snapshot(&p.text_document.uri, handlers::generate_code::code_lenses)
            .await?;
        Ok(Some(lenses))
    }

    async fn execute_command(&self, p: ExecuteCommandParams) -> Result<Option<LSPAny>> {
        match p.command.as_str() {
            handlers::generate_code::COMMAND => self
                .generate_code(&p.arguments, p.work_done_progress_params.work_done_token)
                .await
                .map(Some),
            handlers::simulate::COMMAND => self.simulate(&p.arguments).await.map(Some),
            handlers::verify_mission::COMMAND => self.verify(&p.arguments).await.map(Some),
            other => Err(Error::invalid_params(format!("unknown command `{other}`"))),
        }
    }
}

fn unknown_document(uri: &Uri) -> Error {
    Error {
        code: tower_lsp_server::jsonrpc::ErrorCode::InvalidParams,
        message: format!("unknown document {}", uri.as_str()).into(),
        data: None,
    }
}

/// A Generate Code request whose files are being replaced: a cancel then
/// no longer stops it. Whichever sees both the cancel and the end of the
/// replacing second (the blocking work, or the dropped request) tells the
/// user, once.
struct LateCancel {
    cancelled: Arc<AtomicBool>,
    committed: AtomicBool,
    /// The request answered with its result: no cancel came in time to drop it.
    answered: AtomicBool,
    told: AtomicBool,
    client: Client,
    runtime: tokio::runtime::Handle,
    message: String,
}

impl LateCancel {
    fn tell_if_late(&self) {
        let late = self.cancelled.load(Ordering::SeqCst)
            && self.committed.load(Ordering::SeqCst)
            && !self.answered.load(Ordering::SeqCst);
        if late && !self.told.swap(true, Ordering::SeqCst) {
            let (client, message) = (self.client.clone(), self.message.clone());
            self.runtime.spawn(async move {
                client.show_message(MessageType::WARNING, message).await;
            });
        }
    }
}

/// Held by the request's future: dropped (the request cancelled, or
/// answered), it marks the cancel and tells the user if the files were
/// already replaced.
struct LateCancelGuard(Arc<LateCancel>);

impl Drop for LateCancelGuard {
    fn drop(&mut self) {
        self.0.cancelled.store(true, Ordering::SeqCst);
        self.0.tell_if_late();
    }
}

/// Sets its flag when dropped: held by a request's future, it tells the
/// blocking work that the request was cancelled (the server drops the
/// future of a cancelled request).
#[derive(Default)]
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::SeqCst);
    }
}
