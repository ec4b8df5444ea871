//! A TCP proxy on a free loopback port that a test can cut: a network
//! partition between one robot and its broker, made for real. While cut it
//! forwards nothing and drops what it reads (as a link that lost every
//! packet, the connections stay open, so the robot notices nothing but
//! silence); healed, it closes the connections it cut (their streams lost
//! bytes), and the robot's reconnections go through.

use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;

pub struct Proxy {
    pub port: u16,
    shared: Arc<Shared>,
}

struct Shared {
    cut: AtomicBool,
    /// Each connection made while it was healed, its two streams (closed at
    /// the heal: a cut stream lost bytes).
    open: Mutex<Vec<(TcpStream, TcpStream)>>,
    /// Bytes dropped while cut (a test can tell the cut was real).
    dropped: AtomicU64,
}

impl Proxy {
    /// Forwards 127.0.0.1:`port` (the proxy's) to 127.0.0.1:`upstream`.
    pub fn start(upstream: u16) -> Proxy {
        let listener = TcpListener::bind("127.0.0.1:0").expect("a free loopback port");
        let port = listener.local_addr().unwrap().port();
        let shared = Arc::new(Shared {
            cut: AtomicBool::new(false),
            open: Mutex::new(Vec::new()),
            dropped: AtomicU64::new(0),
        });
        let accepting = shared.clone();
        thread::spawn(move || {
            for client in listener.incoming() {
                let Ok(client) = client else { continue };
                if accepting.cut.load(Ordering::SeqCst) {
                    // No route: the connection attempt goes unanswered.
                    let _ = client.shutdown(Shutdown::Both);
                    continue;
                }
                let Ok(server) = TcpStream::connect(("127.0.0.1", upstream)) else {
                    continue;
                };
                let _ = client.set_nodelay(true);
                let _ = server.set_nodelay(true);
                accepting
                    .open
                    .lock()
                    .unwrap()
                    .push((client.try_clone().unwrap(), server.try_clone().unwrap()));
                for (from, to) in [
                    (client.try_clone().unwrap(), server.try_clone().unwrap()),
                    (server, client),
                ] {
                    let shared = accepting.clone();
                    thread::spawn(move || forward(from, to, &shared));
                }
            }
        });
        Proxy { port, shared }
    }

    /// From now on nothing passes either way.
    pub fn cut(&self) {
        self.shared.cut.store(true, Ordering::SeqCst);
    }

    /// Passes again: the connections that lost bytes are closed, new ones
    /// are forwarded.
    pub fn heal(&self) {
        let cut: Vec<_> = std::mem::take(&mut *self.shared.open.lock().unwrap());
        self.shared.cut.store(false, Ordering::SeqCst);
        for (client, server) in cut {
            let _ = client.shutdown(Shutdown::Both);
            let _ = server.shutdown(Shutdown::Both);
        }
    }

    /// Bytes that did not pass while it was cut.
    pub fn dropped(&self) -> u64 {
        self.shared.dropped.load(Ordering::SeqCst)
    }
}

fn forward(mut from: TcpStream, mut to: TcpStream, shared: &Shared) {
    let mut buffer = [0u8; 16 * 1024];
    loop {
        let n = match from.read(&mut buffer) {
            Ok(0) | Err(_) => break,
            Ok(n) => n,
        };
        if shared.cut.load(Ordering::SeqCst) {
            shared.dropped.fetch_add(n as u64, Ordering::SeqCst);
            continue;
        }
        if to.write_all(&buffer[..n]).is_err() {
            break;
        }
    }
    let _ = to.shutdown(Shutdown::Both);
    let _ = from.shutdown(Shutdown::Both);
}
