//! The live robot monitor (`semo/monitor/start`, `semo/monitor/stop`, the
//! `semo/monitor` notifications; `docs/live-monitor.md`): one session per
//! mission document, each its own thread with its own MQTT connection
//! (rumqttc), so that nothing of the server waits on the network and no
//! lock is held while the broker is slow or away.
//!
//! A session subscribes to the mission's statuses and heartbeats (of the
//! run it is given, else of every run: it shows the newest), keeps the
//! [`roster::Roster`] and sends its view whenever it changes (a message,
//! the connection coming or going, a robot falling silent) through a
//! channel to the server's task that writes notifications. It ends when its
//! [`Session`] is dropped: stopped, replaced, the document closed, or the
//! server gone.

pub mod roster;

use roster::{Member, Roster};
use serde_json::{Value, json};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tokio::sync::{mpsc, oneshot};

/// What a session connects to and watches, worked out by the handler.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The mission document's URI, echoed in every notification.
    pub uri: String,
    /// The mission's name in topics.
    pub mission: String,
    /// The run to show; None: the newest (`live::RunChoice`).
    pub run: Option<semo::deploy::topics::RunId>,
    pub broker: String,
    /// How to reach it: address, the operator's user and password and TLS
    /// configuration (from the deployment file).
    pub access: crate::live::BrokerAccess,
    pub members: Vec<Member>,
    pub heartbeat_ms: i64,
}

/// A running session; dropping it ends the session.
pub struct Session {
    _stop: oneshot::Sender<()>,
}

/// The sessions, one per mission URI.
#[derive(Default)]
pub struct Monitors {
    sessions: Mutex<HashMap<String, Session>>,
}

impl Monitors {
    /// Starts monitoring `plan.uri`, ending the session it had.
    /// Notifications go to `notify` until the session ends.
    pub fn start(&self, plan: Plan, notify: mpsc::UnboundedSender<Value>) -> std::io::Result<()> {
        let uri = plan.uri.clone();
        let session = spawn(plan, notify)?;
        let old = self.lock().insert(uri, session);
        drop(old);
        Ok(())
    }

    /// Ends the session of `uri`; whether there was one.
    pub fn stop(&self, uri: &str) -> bool {
        let old = self.lock().remove(uri);
        old.is_some()
    }

    /// Ends every session (the server shuts down).
    pub fn stop_all(&self) {
        let all = std::mem::take(&mut *self.lock());
        drop(all);
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Session>> {
        self.sessions.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn spawn(plan: Plan, notify: mpsc::UnboundedSender<Value>) -> std::io::Result<Session> {
    let (stop, stopped) = oneshot::channel();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    std::thread::Builder::new()
        .name(format!("semo-monitor-{}", plan.mission))
        .spawn(move || runtime.block_on(run(plan, stopped, notify)))?;
    Ok(Session { _stop: stop })
}

#[derive(Clone, Copy, PartialEq)]
enum Link {
    Connecting,
    Connected,
    Disconnected,
}

/// The session: the broker's events, a tick per heartbeat period and the
/// stop signal, until stopped or nobody listens.
async fn run(plan: Plan, mut stopped: oneshot::Receiver<()>, notify: mpsc::UnboundedSender<Value>) {
    use rumqttc::{Event, Packet, QoS};
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut options = plan.access.options(format!(
        "semo-monitor-{}-{}-{n}",
        plan.mission,
        std::process::id()
    ));
    options.set_keep_alive(Duration::from_secs(5));
    options.set_clean_session(true);
    let (client, mut eventloop) = rumqttc::AsyncClient::new(options, 64);
    // The event loop is polled without interruption on its own task (a
    // poll cancelled half-way through a connection would start it over);
    // its events come here through a channel.
    let (events_in, mut events) = mpsc::channel(256);
    let poller = tokio::spawn(async move {
        loop {
            let event = eventloop.poll().await;
            let failed = event.is_err();
            if events_in.send(event).await.is_err() {
                return;
            }
            if failed {
                // rumqttc reconnects on the next poll; not at once.
                tokio::time::sleep(Duration::from_secs(1)).await;
            }
        }
    });
    let mut roster = Roster::new(
        &plan.mission,
        plan.members.clone(),
        plan.heartbeat_ms,
        crate::live::RunChoice::new(plan.run.clone()),
    );
    let topics = roster.topics();
    let clock = Instant::now();
    let now = || clock.elapsed().as_millis() as i64;
    let mut link = Link::Connecting;
    let mut error: Option<String> = None;
    let mut tick = tokio::time::interval(Duration::from_millis(plan.heartbeat_ms.max(1) as u64));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut sent = None;
    loop {
        let view = json!({
            "uri": plan.uri,
            "mission": plan.mission,
            "run": roster.run().map(|r| r.as_str()),
            "broker": plan.broker,
            "connection": match link {
                Link::Connecting => "connecting",
                Link::Connected => "connected",
                Link::Disconnected => "disconnected",
            },
            "error": error,
            "robots": roster.view(),
        });
        if sent.as_ref() != Some(&view) {
            if notify.send(view.clone()).is_err() {
                break;
            }
            sent = Some(view);
        }
        tokio::select! {
            _ = &mut stopped => break,
            event = events.recv() => match event {
                None => break,
                Some(Ok(Event::Incoming(Packet::ConnAck(_)))) => {
                    link = Link::Connected;
                    error = None;
                    // A clean session forgets subscriptions: again after
                    // every (re)connection. Retained statuses come with them.
                    for topic in &topics {
                        let qos = if topic.ends_with('+') { QoS::AtLeastOnce } else { QoS::AtMostOnce };
                        if client.subscribe(topic.clone(), qos).await.is_err() {
                            break;
                        }
                    }
                }
                Some(Ok(Event::Incoming(Packet::Publish(p)))) => {
                    roster.message(&p.topic, &p.payload, now());
                }
                Some(Ok(_)) => {}
                Some(Err(e)) => {
                    link = Link::Disconnected;
                    // A certificate the CA does not vouch for is said so
                    // (and retried: the files may be fixed meanwhile).
                    error = Some(plan.access.failure(&e).message);
                }
            },
            _ = tick.tick() => roster.tick(now()),
        }
    }
    let _ = client.try_disconnect();
    poller.abort();
}
