//! Freeing replaced results off the thread that replaced them, with a bounded
//! backlog. Freeing a 10k-line mission's analysis takes about a millisecond,
//! which the next edit should not wait for; but on a loaded machine the
//! freeing thread can fall behind, and an unbounded queue then holds dozens of
//! dead analyses at once (the language server's peak memory tripled that way).
//! So at most [`BACKLOG`] values wait: beyond that the caller frees the value
//! itself, which slows a burst of edits a little and keeps memory bounded.

use std::sync::OnceLock;
use std::sync::mpsc::{self, SyncSender, TrySendError};

/// How many values may wait to be freed before callers free them themselves.
pub const BACKLOG: usize = 4;

/// The name of the process-wide freeing thread.
pub const THREAD: &str = "semo-drop";

type Boxed = Box<dyn Send>;

/// A handle to a thread that frees what it is given, in order. Cloning it
/// shares the thread, which ends when the last handle is gone.
#[derive(Clone)]
pub struct Dropper {
    /// `None` if the thread could not start: values are then freed in place.
    send: Option<SyncSender<Boxed>>,
}

impl Dropper {
    /// Starts a thread named `name` with room for `backlog` waiting values.
    pub fn start(name: &str, backlog: usize) -> Dropper {
        let (send, receive) = mpsc::sync_channel::<Boxed>(backlog);
        let started = std::thread::Builder::new()
            .name(name.to_string())
            .spawn(move || receive.into_iter().for_each(drop));
        Dropper {
            send: started.ok().map(|_| send),
        }
    }

    /// The process-wide dropper ([`THREAD`], [`BACKLOG`]) the host and the
    /// language server share.
    pub fn shared() -> &'static Dropper {
        static SHARED: OnceLock<Dropper> = OnceLock::new();
        SHARED.get_or_init(|| Dropper::start(THREAD, BACKLOG))
    }

    /// Frees `value` on the thread, or here when the backlog is full (or the
    /// thread is gone).
    pub fn drop_later<T: Send + 'static>(&self, value: T) {
        let Some(send) = &self.send else {
            return drop(value);
        };
        match send.try_send(Box::new(value)) {
            Ok(()) => {}
            Err(TrySendError::Full(value) | TrySendError::Disconnected(value)) => drop(value),
        }
    }
}

impl Default for Dropper {
    fn default() -> Dropper {
        Dropper::shared().clone()
    }
}

/// Frees `value` through the shared dropper.
pub fn drop_later<T: Send + 'static>(value: T) {
    Dropper::shared().drop_later(value);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc::{Receiver, Sender, channel};

    /// Tells, when freed, the name of the thread that freed it.
    struct Probe(Sender<Option<String>>);

    impl Drop for Probe {
        fn drop(&mut self) {
            let _ = self.0.send(std::thread::current().name().map(String::from));
        }
    }

    /// Holds the thread that frees it until `release` says so, after telling
    /// `started` that it is being freed.
    struct Blocker {
        started: Sender<()>,
        release: Receiver<()>,
    }

    impl Drop for Blocker {
        fn drop(&mut self) {
            let _ = self.started.send(());
            let _ = self.release.recv();
        }
    }

    #[test]
    fn values_are_freed_on_the_droppers_thread() {
        let dropper = Dropper::start("test-drop-a", 2);
        let (tell, told) = channel();
        dropper.drop_later(Probe(tell));
        assert_eq!(told.recv().ok().flatten().as_deref(), Some("test-drop-a"));
    }

    #[test]
    fn a_full_backlog_is_freed_by_the_caller() {
        let dropper = Dropper::start("test-drop-b", 2);
        let (started, is_started) = channel();
        let (release, released) = channel();
        dropper.drop_later(Blocker {
            started,
            release: released,
        });
        // The thread is now inside the blocker's drop: the queue is empty.
        is_started.recv().expect("the blocker reaches the thread");
        let (tell, told) = channel();
        for _ in 0..2 {
            dropper.drop_later(Probe(tell.clone()));
        }
        // The queue is full: the third is freed here, before the others.
        dropper.drop_later(Probe(tell.clone()));
        let here = std::thread::current().name().map(String::from);
        assert_eq!(told.recv().ok().flatten(), here);
        release.send(()).expect("the blocker waits");
        for _ in 0..2 {
            assert_eq!(told.recv().ok().flatten().as_deref(), Some("test-drop-b"));
        }
    }
}
