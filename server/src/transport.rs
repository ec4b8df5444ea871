//! A guard between the client's byte stream and tower-lsp's reader. tower-lsp
//! stops reading for good after one frame it cannot decode (bad JSON, a
//! header it rejects), which would silence the server for the rest of the
//! session. Here every frame is read and checked first: a valid JSON-RPC
//! message is passed on, re-framed with only its `Content-Length`; anything
//! else is answered with the JSON-RPC error it deserves and skipped.
//!
//! The guard also keeps two promises of the protocol tower-lsp does not: a
//! request whose method starts with `$/` (protocol-internal, and unknown to
//! us) is answered with MethodNotFound rather than never, and the process's
//! exit code says whether `shutdown` came before the end (0) or not (1).

use serde_json::{Value, json};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use tokio::io::{AsyncBufReadExt, AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, BufReader};
use tokio::sync::mpsc;
use tower_lsp_server::jsonrpc::{Request, Response};

/// Frames larger than this are refused (and their bytes skipped) rather than
/// held in memory.
const MAX_FRAME: usize = 512 * 1024 * 1024;

/// Serves the protocol on `input`/`output`, with the guard in front.
pub async fn serve_guarded<I, O>(input: I, output: O)
where
    I: AsyncRead + Unpin + Send + 'static,
    O: AsyncWrite + Unpin + Send + 'static,
{
    serve_guarded_status(input, output).await;
}

/// [`serve_guarded`], giving the exit code the protocol asks for: 0 when
/// the client sent `shutdown` before the session ended, else 1.
pub async fn serve_guarded_status<I, O>(input: I, output: O) -> i32
where
    I: AsyncRead + Unpin + Send + 'static,
    O: AsyncWrite + Unpin + Send + 'static,
{
    let (to_server, server_in) = tokio::io::duplex(1 << 16);
    let (server_out, from_server) = tokio::io::duplex(1 << 16);
    // Whole frame bodies to write out: the server's, and our error replies.
    let (out_tx, out_rx) = mpsc::unbounded_channel();
    let shutdown = Arc::new(AtomicBool::new(false));
    let reader = tokio::spawn(forward_valid(
        input,
        to_server,
        out_tx.clone(),
        shutdown.clone(),
    ));
    let pump = tokio::spawn(pump_frames(from_server, out_tx));
    let writer = tokio::spawn(write_frames(out_rx, output));
    crate::serve(server_in, server_out).await;
    reader.abort();
    let _ = reader.await;
    let _ = pump.await;
    let _ = writer.await;
    if shutdown.load(Ordering::SeqCst) {
        0
    } else {
        1
    }
}

/// A frame as read: its body, or why there is none.
pub(crate) enum Frame {
    Body(Vec<u8>),
    /// Headers without a usable `Content-Length`.
    BadHeader(String),
    End,
}

pub(crate) async fn read_frame<R: AsyncRead + Unpin>(input: &mut BufReader<R>) -> Frame {
    let mut length: Option<Result<usize, String>> = None;
    let mut saw_header = false;
    loop {
        let mut line = Vec::new();
        match input.read_until(b'\n', &mut line).await {
            Ok(0) | Err(_) => return Frame::End,
            Ok(_) => {}
        }
        let line = String::from_utf8_lossy(&line);
        // Bytes left over from a broken frame may precede the next header.
        let line = match line.find("Content-Length:") {
            Some(i) => &line[i..],
            None => &line[..],
        };
        let line = line.trim_end_matches(['\r', '\n']);
        if line.is_empty() {
            if saw_header {
                break;
            }
            continue;
        }
        saw_header = true;
        if let Some(value) = line.strip_prefix("Content-Length:") {
            length = Some(
                value
                    .trim()
                    .parse::<usize>()
                    .map_err(|_| format!("bad Content-Length `{}`", value.trim())),
            );
        }
        // Other headers (Content-Type) are accepted as they are.
    }
    let length = match length {
        None => return Frame::BadHeader("a message without Content-Length".into()),
        Some(Err(e)) => return Frame::BadHeader(e),
        Some(Ok(n)) => n,
    };
    if length > MAX_FRAME {
        // Skip the bytes without holding them.
        let skipped = tokio::io::copy(&mut input.take(length as u64), &mut tokio::io::sink()).await;
        return match skipped {
            Ok(n) if n == length as u64 => {
                Frame::BadHeader(format!("a message of {length} bytes is too large"))
            }
            _ => Frame::End,
        };
    }
    let mut body = vec![0; length];
    match input.read_exact(&mut body).await {
        Ok(_) => Frame::Body(body),
        Err(_) => Frame::End,
    }
}

/// Whether tower-lsp will accept the body (and the method of a request),
/// else the error to answer with.
fn check(body: &[u8]) -> Result<Option<String>, Value> {
    let value: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => return Err(error(Value::Null, -32700, &format!("Parse error: {e}"))),
    };
    let request_id = value
        .get("id")
        .filter(|id| matches!(id, Value::Number(_) | Value::String(_)));
    let method = value.get("method").and_then(Value::as_str);
    if let (Some(id), Some(method)) = (request_id, method) {
        if method.starts_with("$/") {
            // tower-lsp drops these without an answer; every request gets one.
            let message = format!("Method not found: {method}");
            return Err(error(id.clone(), -32601, &message));
        }
    }
    if serde_json::from_value::<Request>(value.clone()).is_ok() {
        return Ok(request_id.and(method).map(str::to_string));
    }
    if serde_json::from_value::<Response>(value.clone()).is_ok() {
        return Ok(None);
    }
    // Answer with the request's id when it has a usable one.
    let id = match value.get("id") {
        Some(id @ (Value::Number(_) | Value::String(_))) => id.clone(),
        _ => Value::Null,
    };
    Err(error(
        id,
        -32600,
        "Invalid request: not a JSON-RPC 2.0 message",
    ))
}

fn error(id: Value, code: i64, message: &str) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } })
}

async fn forward_valid<R, W>(
    input: R,
    mut to_server: W,
    out: mpsc::UnboundedSender<Vec<u8>>,
    shutdown: Arc<AtomicBool>,
) where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin,
{
    let mut input = BufReader::new(input);
    loop {
        let reply = match read_frame(&mut input).await {
            Frame::End => break,
            Frame::BadHeader(why) => error(Value::Null, -32700, &format!("Parse error: {why}")),
            Frame::Body(body) => match check(&body) {
                Ok(method) => {
                    if method.as_deref() == Some("shutdown") {
                        shutdown.store(true, Ordering::SeqCst);
                    }
                    if write_frame(&mut to_server, &body).await.is_err() {
                        return; // the server is gone
                    }
                    continue;
                }
                Err(reply) => reply,
            },
        };
        let _ = out.send(reply.to_string().into_bytes());
    }
    // End of input: the server sees its input close, as it would without us.
    let _ = to_server.shutdown().await;
}

/// Passes the server's frames on, whole, to the writer.
async fn pump_frames<R: AsyncRead + Unpin>(from_server: R, out: mpsc::UnboundedSender<Vec<u8>>) {
    let mut from_server = BufReader::new(from_server);
    while let Frame::Body(body) = read_frame(&mut from_server).await {
        if out.send(body).is_err() {
            break;
        }
    }
}

async fn write_frames<W: AsyncWrite + Unpin>(
    mut frames: mpsc::UnboundedReceiver<Vec<u8>>,
    mut output: W,
) {
    while let Some(body) = frames.recv().await {
        if write_frame(&mut output, &body).await.is_err() {
            break;
        }
    }
}

pub(crate) async fn write_frame<W: AsyncWrite + Unpin>(
    output: &mut W,
    body: &[u8],
) -> std::io::Result<()> {
    output
        .write_all(format!("Content-Length: {}\r\n\r\n", body.len()).as_bytes())
        .await?;
    output.write_all(body).await?;
    output.flush().await
}
