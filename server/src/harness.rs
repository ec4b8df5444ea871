//! An in-memory LSP client: the real server on one end of an in-process pipe,
//! JSON-RPC framing on the other. Tests and benchmarks drive the server through
//! it exactly as an editor would, without a process or a socket.

use crate::transport::{Frame, read_frame, write_frame};
use serde_json::{Value, json};
use std::collections::VecDeque;
use tokio::io::{AsyncWriteExt, BufReader, DuplexStream};
use tokio::task::JoinHandle;

pub struct TestClient {
    to_server: tokio::io::WriteHalf<DuplexStream>,
    from_server: BufReader<tokio::io::ReadHalf<DuplexStream>>,
    next_id: i64,
    /// Notifications read while waiting for something else, oldest first.
    pending: VecDeque<Value>,
    server: JoinHandle<()>,
}

impl TestClient {
    /// Starts a server in this runtime (not yet initialized).
    pub fn start() -> TestClient {
        let (client_end, server_end) = tokio::io::duplex(1 << 16);
        let (server_in, server_out) = tokio::io::split(server_end);
        let server = tokio::spawn(crate::transport::serve_guarded(server_in, server_out));
        let (from_server, to_server) = tokio::io::split(client_end);
        TestClient {
            to_server,
            from_server: BufReader::new(from_server),
            next_id: 0,
            pending: VecDeque::new(),
            server,
        }
    }

    /// `initialize` + `initialized`. `encodings` are the position encodings
    /// the client offers (e.g. `["utf-8", "utf-16"]`); `root` a workspace folder.
    /// The client takes snippets in completion items and applies edits
    /// that create, rename and delete files (as VS Code and Neovim do).
    pub async fn initialize(&mut self, encodings: &[&str], root: Option<&str>) -> Value {
        let capabilities = json!({
            "general": { "positionEncodings": encodings },
            "workspace": {
                "didChangeWatchedFiles": { "dynamicRegistration": true },
                "workspaceEdit": {
                    "documentChanges": true,
                    "resourceOperations": ["create", "rename", "delete"]
                }
            },
            "textDocument": {
                "completion": { "completionItem": { "snippetSupport": true } }
            }
        });
        self.initialize_with(capabilities, root).await
    }

    /// `initialize` + `initialized` with the given client capabilities.
    pub async fn initialize_with(&mut self, capabilities: Value, root: Option<&str>) -> Value {
        self.initialize_with_options(capabilities, Value::Null, root)
            .await
    }

    /// `initialize` + `initialized` with the given client capabilities and
    /// `initializationOptions`.
    pub async fn initialize_with_options(
        &mut self,
        capabilities: Value,
        options: Value,
        root: Option<&str>,
    ) -> Value {
        let folders = root.map(|r| json!([{ "uri": r, "name": "workspace" }]));
        let result = self
            .request(
                "initialize",
                json!({
                    "processId": null,
                    "rootUri": root,
                    "workspaceFolders": folders,
                    "capabilities": capabilities,
                    "initializationOptions": options,
                }),
            )
            .await
            .expect("initialize succeeds");
        self.notify("initialized", json!({})).await;
        result
    }

    /// Sends a request and waits for its response: `Ok(result)` or `Err(error)`.
    pub async fn request(&mut self, method: &str, params: Value) -> Result<Value, Value> {
        let id = self.send_request(method, params).await;
        self.response(id).await
    }

    /// Sends a request without waiting for its response; its id (for
    /// [`TestClient::response`], or to cancel it).
    pub async fn send_request(&mut self, method: &str, params: Value) -> i64 {
        self.next_id += 1;
        let id = self.next_id;
        self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }))
            .await;
        id
    }

    /// Waits for the response to the request `id`.
    pub async fn response(&mut self, id: i64) -> Result<Value, Value> {
        loop {
            let msg = self.read_message().await.expect("the server answers");
            if msg.get("id") == Some(&json!(id)) && msg.get("method").is_none() {
                return match msg.get("error") {
                    Some(e) => Err(e.clone()),
                    None => Ok(msg.get("result").cloned().unwrap_or(Value::Null)),
                };
            }
            self.keep(msg).await;
        }
    }

    /// Sends every request before reading any answer (as an editor does on
    /// a double click); the answers in the order of `requests`.
    pub async fn requests_at_once(
        &mut self,
        requests: &[(&str, Value)],
    ) -> Vec<Result<Value, Value>> {
        let first = self.next_id + 1;
        for (method, params) in requests {
            self.next_id += 1;
            let id = self.next_id;
            self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }))
                .await;
        }
        let mut answers = vec![None; requests.len()];
        while answers.iter().any(Option::is_none) {
            let msg = self.read_message().await.expect("the server answers");
            let slot = msg
                .get("id")
                .and_then(Value::as_i64)
                .filter(|_| msg.get("method").is_none());
            match slot {
                Some(id) if (first..=self.next_id).contains(&id) => {
                    answers[(id - first) as usize] = Some(match msg.get("error") {
                        Some(e) => Err(e.clone()),
                        None => Ok(msg.get("result").cloned().unwrap_or(Value::Null)),
                    });
                }
                _ => self.keep(msg).await,
            }
        }
        answers.into_iter().map(|a| a.expect("answered")).collect()
    }

    pub async fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({ "jsonrpc": "2.0", "method": method, "params": params }))
            .await;
    }

    pub async fn open(&mut self, uri: &str, text: &str) {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": {
                "uri": uri, "languageId": "mission", "version": 1, "text": text
            }}),
        )
        .await;
    }

    /// Opens the file at `path` as the editor does when a user opens it (its
    /// text from disk, version 1) and waits for its first diagnostics: its
    /// `file://` URI.
    pub async fn open_file(&mut self, path: &std::path::Path) -> String {
        let uri = format!("file://{}", path.display());
        let text =
            std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        self.open(&uri, &text).await;
        self.diagnostics(&uri, Some(1)).await;
        uri
    }

    /// Waits for the diagnostics of `uri` published for `version` (any
    /// version when `None`), skipping older publications.
    pub async fn diagnostics(&mut self, uri: &str, version: Option<i64>) -> Vec<Value> {
        let msg = self
            .notification("textDocument/publishDiagnostics", |p| {
                p["uri"] == uri && (version.is_none() || p["version"] == json!(version))
            })
            .await;
        msg["diagnostics"].as_array().cloned().unwrap_or_default()
    }

    /// `textDocument/didChange` replacing the whole text of `uri` with
    /// `text` at `version`.
    pub async fn change(&mut self, uri: &str, version: i64, text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": uri, "version": version },
                "contentChanges": [{ "text": text }],
            }),
        )
        .await;
    }

    /// Waits for a notification whose params satisfy `wanted`; the ones
    /// skipped are dropped.
    pub async fn notification(&mut self, method: &str, wanted: impl Fn(&Value) -> bool) -> Value {
        loop {
            let msg = match self.pending.pop_front() {
                Some(m) => m,
                None => self.read_message().await.expect("the server is alive"),
            };
            if msg.get("id").is_some() && msg.get("method").is_some() {
                self.answer(&msg).await;
                continue;
            }
            if msg["method"] == method && wanted(&msg["params"]) {
                return msg["params"].clone();
            }
        }
    }

    /// Bytes as they are, for robustness tests (malformed frames and JSON).
    pub async fn send_raw(&mut self, bytes: &[u8]) {
        self.to_server.write_all(bytes).await.expect("pipe open");
        self.to_server.flush().await.expect("pipe open");
    }

    /// `shutdown` + `exit`; the server task ends.
    pub async fn shutdown(mut self) {
        let _ = self.request("shutdown", Value::Null).await;
        self.notify("exit", Value::Null).await;
        // A server that does not stop after `exit` fails the test, not hangs it.
        let stopped = tokio::time::timeout(std::time::Duration::from_secs(20), self.server).await;
        assert!(stopped.is_ok(), "the server did not stop after `exit`");
    }

    /// The messages read but not yet consumed (notifications, and responses
    /// to no request such as parse errors), oldest first.
    pub fn take_unclaimed(&mut self) -> Vec<Value> {
        self.pending.drain(..).collect()
    }

    pub fn server_is_running(&self) -> bool {
        !self.server.is_finished()
    }

    async fn send(&mut self, msg: &Value) {
        write_frame(&mut self.to_server, msg.to_string().as_bytes())
            .await
            .expect("pipe open");
    }

    /// A message that is not the awaited response: server requests are
    /// answered at once, notifications kept for later.
    async fn keep(&mut self, msg: Value) {
        if msg.get("id").is_some() && msg.get("method").is_some() {
            self.answer(&msg).await;
        } else {
            self.pending.push_back(msg);
        }
    }

    /// Answers a request from the server (registrations, progress tokens) with
    /// success, as an accommodating editor would.
    async fn answer(&mut self, request: &Value) {
        let reply = json!({ "jsonrpc": "2.0", "id": request["id"], "result": null });
        self.send(&reply).await;
    }

    /// The next message from the server, framed as the server frames it
    /// (the transport's own reader); `None` when the server has gone.
    async fn read_message(&mut self) -> Option<Value> {
        match read_frame(&mut self.from_server).await {
            Frame::Body(body) => serde_json::from_slice(&body).ok(),
            Frame::BadHeader(_) | Frame::End => None,
        }
    }
}
