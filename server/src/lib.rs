//! The SeMo language server, served by the `semo` binary's `semo lsp` (the
//! `semo-cli` crate calls [`run_stdio`]).
//!
//! - [`world`]: files, documents and snapshots (the state, under one std lock).
//! - [`diagnostics`]: the queue and task that publish diagnostics.
//! - [`server`]: the `LanguageServer` implementation, one line per method,
//!   delegating to [`handlers`] (one file per request).
//! - [`to_proto`]: the library's editor vocabulary in protocol types.
//! - [`encoding`], [`document`]: positions and incremental edits at the door.
//! - [`transport`]: a guard that keeps malformed frames away from tower-lsp.
//! - [`live`]: a running mission's status and datagrams on its broker (shared
//!   with `semo operator`); [`monitor`]: the live robot monitor's sessions.
//! - [`harness`]: an in-memory client, for tests and benchmarks.

pub mod diagnostics;
pub mod document;
pub mod encoding;
pub mod handlers;
pub mod harness;
pub mod live;
pub mod monitor;
pub mod server;
pub mod to_proto;
pub mod transport;
pub mod verify;
pub mod world;

use std::sync::{Mutex, MutexGuard};
use tokio::io::{AsyncRead, AsyncWrite};
use tower_lsp_server::{LspService, Server};

/// State shared by the handlers and the diagnostics task.
#[derive(Default)]
pub struct State {
    world: Mutex<world::World>,
    pub queue: diagnostics::Queue,
    /// `semo verify`'s findings of saved missions (`verify.rs`).
    pub verified: verify::Verified,
    /// Whether the workspace folders were read at start.
    pub indexed: Indexed,
}

/// Opens once the workspace folders were read (after `initialized`), or at
/// `initialize` when there are none.
/// Requests and the diagnostics task wait for it, so that the first answer
/// after start sees the project file and the catalogs as later ones do: a
/// request sent at once after `initialized` would otherwise race the read
/// (a live monitor started at once used the default broker, not the one
/// of the project's deployment file).
pub struct Indexed(tokio::sync::watch::Sender<bool>);

impl Default for Indexed {
    fn default() -> Indexed {
        Indexed(tokio::sync::watch::channel(false).0)
    }
}

impl Indexed {
    pub fn open(&self) {
        self.0.send_replace(true);
    }

    pub async fn wait(&self) {
        // The sender lives as long as `self`: the wait ends only by opening.
        let _ = self.0.subscribe().wait_for(|open| *open).await;
    }
}

impl State {
    /// The world, locked. A handler that panicked while holding the lock
    /// leaves it poisoned; the state is still consistent (every mutation is
    /// one assignment), so later handlers carry on.
    pub fn world(&self) -> MutexGuard<'_, world::World> {
        self.world.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Serves the protocol on the given streams until the client exits. Editors
/// and tests use [`transport::serve_guarded`], which puts a guard in front.
pub async fn serve<I, O>(input: I, output: O)
where
    I: AsyncRead + Unpin,
    O: AsyncWrite,
{
    let (service, socket) = LspService::build(server::Backend::new)
        .custom_method("semo/catalog", server::Backend::catalog)
        .custom_method("semo/graphSvg", server::Backend::graph_svg)
        .custom_method("semo/viewFileText", server::Backend::view_file_text)
        .custom_method(handlers::monitor::START, server::Backend::monitor_start)
        .custom_method(handlers::monitor::STOP, server::Backend::monitor_stop)
        .finish();
    Server::new(input, output, socket).serve(service).await;
}

/// `semo lsp`: serves on stdin/stdout; gives the process exit code.
pub fn run_stdio() -> i32 {
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("error: cannot start the language server: {e}");
            return 2;
        }
    };
    let code = runtime.block_on(transport::serve_guarded_status(
        tokio::io::stdin(),
        tokio::io::stdout(),
    ));
    // tokio reads stdin on a blocking thread that would hold a normal shutdown
    // until the client writes again: after `exit`, do not wait for it.
    runtime.shutdown_background();
    code
}
