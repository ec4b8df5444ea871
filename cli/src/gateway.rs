//! `semo gateway MISSION --link ROBOT=LINK…`: a robot on a serial link
//! (`docs/link.md`) becomes a member of the fleet on the MQTT broker. For
//! each link the gateway is that robot's MQTT client, with its client id and
//! credentials from the deployment file (so the broker's ACL applies to it
//! as to a Linux robot), subscribed to its topics; it publishes the robot's
//! `send`s (QoS 1), `publish`es (QoS 0) and status (retained), and passes
//! down the link what the broker delivers to it.
//!
//! Trust comes from the link, never from a frame: a frame's datagram must
//! name the link's robot as its sender (else it is refused and counted),
//! the topic's sender levels are the link's robot, and a message from the
//! broker whose datagram names another sender or key than its topic goes
//! down as `R` (the robot traces a `reject`), as `semo_mqtt.c` refuses it.
//! The topics are `semo::deploy::topics`, the runtime's.
//!
//! A link is `tcp:HOST:PORT` (the gateway connects, and again when the
//! connection is lost: QEMU's `-serial tcp:HOST:PORT,server`), `listen:HOST:PORT`
//! (the gateway listens, one robot at a time), or the path of a serial
//! device (set up beforehand, e.g. `stty -F /dev/ttyUSB0 115200 raw`).

use semo::deploy::datagram;
use semo::deploy::topics::{self, RunId, Scope, Sender};

use semo::link::{Endpoint, Frame, Kind, Refusal};
use semo_server::live::{BrokerAccess, DEFAULT_BROKER};
use std::collections::{BTreeSet, HashMap, VecDeque};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

pub struct Options {
    pub mission: PathBuf,
    pub strategy: Vec<PathBuf>,
    pub links: Vec<String>,
    pub broker: Option<String>,
    pub deploy: Option<PathBuf>,
    pub run: Option<String>,
    pub color: bool,
}

/// Where a link's bytes come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Place {
    Connect(String),
    Listen(String),
    Device(PathBuf),
}

/// `ROBOT=LINK` as given.
pub fn parse_link(text: &str) -> Result<(String, Place), String> {
    let Some((robot, link)) = text.split_once('=') else {
        return Err(format!(
            "`{text}` is not ROBOT=LINK (e.g. ti=tcp:127.0.0.1:5000, ti=listen:127.0.0.1:5000, ti=/dev/ttyUSB0)"
        ));
    };
    let address = |rest: &str, what: &str| -> Result<String, String> {
        match rest.rsplit_once(':') {
            Some((host, port)) if !host.is_empty() && port.parse::<u16>().is_ok() => {
                Ok(rest.to_string())
            }
            _ => Err(format!(
                "`{what}{rest}` needs HOST:PORT (e.g. 127.0.0.1:5000)"
            )),
        }
    };
    let place = if let Some(rest) = link.strip_prefix("tcp:") {
        Place::Connect(address(rest, "tcp:")?)
    } else if let Some(rest) = link.strip_prefix("listen:") {
        Place::Listen(address(rest, "listen:")?)
    } else if link.is_empty() {
        return Err(format!("`{text}` names no link"));
    } else {
        Place::Device(PathBuf::from(link))
    };
    if robot.is_empty() {
        return Err(format!("`{text}` names no robot"));
    }
    Ok((robot.to_string(), place))
}

/// What the link thread hears.
enum Event {
    /// Bytes from the line.
    Bytes(Vec<u8>),
    /// The line closed (it is opened again).
    Closed(String),
    /// The broker accepted the connection and the subscriptions:
    /// whether it kept the robot's session.
    Ready(bool),
    /// A message the broker delivered on one of the robot's topics, not
    /// yet acknowledged to the broker: that waits until the robot has it
    /// (its `Ack` on the link), so a gateway that stops in between loses
    /// none: the broker delivers it again to the next gateway.
    Message(rumqttc::Publish),
    /// The broker acknowledged the publish of the robot's reliable frame
    /// with this sequence number: the robot may now hear its `Ack`.
    Acked(u16),
}

/// What became of a frame the robot sent.
enum Handed {
    /// A reliable one, handed to the broker connection: acknowledged to
    /// the robot when the broker acknowledges it ([`Event::Acked`]).
    Awaiting,
    /// Unreliable, handed or not: nothing to acknowledge.
    Unreliable,
    /// Refused: acknowledged at once (it will never be published).
    Refused,
    /// Reliable, but the broker connection's queue was full: not
    /// acknowledged, so the robot sends it again and it is taken again.
    NotTaken,
}

/// The sequence number of the robot's reliable frame just handed to the
/// broker connection, for its thread to tie to the publish's packet id.
/// One at a time: the robot sends its next reliable frame only after this
/// one's `Ack`.
type Handing = Arc<Mutex<Option<u16>>>;

/// A robot of the mission, as the gateway speaks for it.
#[derive(Clone)]
struct Robot {
    team: String,
    robot: String,
}

/// What one link's robot may name as a destination: the mission's teams,
/// its robots (with their teams) and the operator.
#[derive(Clone)]
struct Roster {
    teams: BTreeSet<String>,
    robots: Vec<Robot>,
}

pub fn run(options: Options, out: &mut impl Write) -> i32 {
    let run_id = match options
        .run
        .clone()
        .or_else(|| std::env::var("SEMO_RUN").ok().filter(|r| !r.is_empty()))
        .map(|r| RunId::parse(&r))
        .transpose()
    {
        Ok(run) => run.unwrap_or_else(|| RunId::parse("default").expect("a valid run id")),
        Err(why) => {
            eprintln!("error: --run: {why}");
            return 2;
        }
    };
    if options.links.is_empty() {
        eprintln!("error: no link: give at least one --link ROBOT=LINK");
        return 2;
    }
    let mut links = Vec::new();
    for text in &options.links {
        match parse_link(text) {
            Ok(link) => links.push(link),
            Err(why) => {
                eprintln!("error: --link: {why}");
                return 2;
            }
        }
    }
    let (mut run, mission, deployment) = match super::deploy::load_fleet(
        &options.mission,
        &options.strategy,
        options.deploy.as_deref(),
        options.color,
        out,
    ) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    // The refined robots, or the mission's errors reported as `semo build` reports them.
    let human = super::output::Format::Human;
    let refined = match super::refine_or_report(
        &mut run,
        mission,
        human,
        options.color,
        "bridge its robots",
        out,
    ) {
        Ok((_, refined)) => refined,
        Err(code) => return code,
    };
    let Some(first) = refined.programs.first() else {
        eprintln!("error: the mission has no robot to bridge");
        return 2;
    };
    let roster = Roster {
        teams: refined.programs.iter().map(|p| p.team.clone()).collect(),
        robots: refined
            .programs
            .iter()
            .map(|p| Robot {
                team: p.team.clone(),
                robot: p.robot.clone(),
            })
            .collect(),
    };
    let mission_topic = topics::mission(&first.mission);
    let scope = Scope::run(&mission_topic, &run_id);
    let url = match (&options.broker, &deployment) {
        (Some(url), _) => url.clone(),
        (None, Some(d)) => d.broker.url.clone(),
        (None, None) => DEFAULT_BROKER.to_string(),
    };
    let mut seen = BTreeSet::new();
    let mut plans = Vec::new();
    for (name, place) in links {
        let Some(robot) = roster.robots.iter().find(|r| r.robot == name).cloned() else {
            let names: Vec<&str> = roster.robots.iter().map(|r| r.robot.as_str()).collect();
            eprintln!(
                "error: --link: the mission has no robot `{name}` (its robots: {})",
                names.join(", ")
            );
            return 2;
        };
        if !seen.insert(name.clone()) {
            eprintln!("error: --link: robot `{name}` is given two links");
            return 2;
        }
        let access = match BrokerAccess::robot(&url, deployment.as_ref(), &robot.team, &robot.robot)
        {
            Ok(access) => access,
            Err(why) => {
                eprintln!("error: {why}");
                return 2;
            }
        };
        let client_id = deployment
            .as_ref()
            .and_then(|d| d.robot(&robot.team, &robot.robot).client_id)
            .unwrap_or_else(|| format!("semo-{mission_topic}-{run_id}-{}", robot.robot));
        plans.push((robot, place, access, client_id));
    }
    let _ = writeln!(
        out,
        "gateway on {url}, mission {mission_topic}, run {run_id}: {}",
        plans
            .iter()
            .map(|(r, place, _, _)| format!("{} on {}", r.robot, describe(place)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = out.flush();
    let threads: Vec<_> = plans
        .into_iter()
        .map(|(robot, place, access, client_id)| {
            let gateway = LinkGateway {
                robot,
                place,
                scope: scope.clone(),
                roster: roster.clone(),
            };
            std::thread::spawn(move || gateway.serve(access, client_id))
        })
        .collect();
    for thread in threads {
        let _ = thread.join();
    }
    1
}

fn describe(place: &Place) -> String {
    match place {
        Place::Connect(address) => format!("tcp:{address}"),
        Place::Listen(address) => format!("listen:{address}"),
        Place::Device(path) => path.display().to_string(),
    }
}

/// Messages from the broker the link thread holds at most (queued behind
/// the one in flight and waiting); beyond, the broker holds them (the
/// connection's thread waits for room, as a Linux robot's full inbox holds
/// back its transport).
const ROOM: usize = 64;
/// Reliable frames behind the one in flight, per link.
const LINK_QUEUE: usize = 16;
/// How soon an acknowledgement to the broker that found the connection's
/// queue full is tried again.
const ACK_RETRY: Duration = Duration::from_millis(20);

/// Room for messages from the broker: the MQTT thread takes a place before
/// it hands a message over, the link thread gives it back when the robot
/// has acknowledged it.
struct Room {
    free: Mutex<usize>,
    freed: Condvar,
}

impl Room {
    fn take(&self) {
        let mut free = self.free.lock().unwrap_or_else(|e| e.into_inner());
        while *free == 0 {
            free = self.freed.wait(free).unwrap_or_else(|e| e.into_inner());
        }
        *free -= 1;
    }

    fn give(&self, n: usize) {
        if n > 0 {
            *self.free.lock().unwrap_or_else(|e| e.into_inner()) += n;
            self.freed.notify_all();
        }
    }
}

struct LinkGateway {
    robot: Robot,
    place: Place,
    scope: Scope,
    roster: Roster,
}

/// The counts a link keeps, said on standard error as they change.
#[derive(Default)]
struct Counts {
    refused_frames: u64,
    refused_messages: u64,
    /// Frames the broker connection could not take (its queue full).
    lost: u64,
}

/// The robot's MQTT connection as the link thread uses it: the client, and
/// the sequence number of the reliable frame just handed to it, for the
/// connection's thread to tie to the publish's packet id.
#[derive(Clone)]
struct Broker {
    client: rumqttc::Client,
    handing: Handing,
}

/// A publish the gateway makes for the robot.
struct Outbound {
    topic: String,
    qos: rumqttc::QoS,
    retain: bool,
    payload: Vec<u8>,
}

impl Broker {
    /// Hands `message` to the connection without waiting: the connection's
    /// thread may itself wait for room on the link (a robot slow to
    /// acknowledge), and a link thread waiting for it would wait forever.
    /// `reliable`: the sequence number of the robot's frame it publishes,
    /// acknowledged at the broker's PUBACK. A reliable one the full queue
    /// cannot take is not taken (the robot sends it again); an unreliable
    /// one is lost, counted and said.
    fn hand(
        &self,
        name: &str,
        counts: &mut Counts,
        message: Outbound,
        reliable: Option<u16>,
    ) -> Handed {
        // Said before the request, which the connection's thread may take at
        // once (a QoS 0 publish leaves it: it has no packet id to tie).
        let mut handed = self.handing.lock().unwrap_or_else(|e| e.into_inner());
        if reliable.is_some() {
            *handed = reliable;
        }
        let Outbound {
            topic,
            qos,
            retain,
            payload,
        } = message;
        if self
            .client
            .try_publish(topic.clone(), qos, retain, payload)
            .is_ok()
        {
            return match reliable {
                Some(_) => Handed::Awaiting,
                None => Handed::Unreliable,
            };
        }
        match reliable {
            Some(_) => {
                *handed = None;
                eprintln!(
                    "gateway: {name}: the broker connection's queue is full: the send to {topic} waits for the robot's next copy"
                );
                Handed::NotTaken
            }
            None => {
                counts.lost += 1;
                eprintln!(
                    "gateway: {name}: lost a publish to {topic}: the broker connection's queue is full ({} lost)",
                    counts.lost
                );
                Handed::Unreliable
            }
        }
    }
}

impl LinkGateway {
    fn name(&self) -> &str {
        &self.robot.robot
    }

    fn serve(self, access: BrokerAccess, client_id: String) {
        let (events, heard) = sync_channel::<Event>(256);
        let room = Arc::new(Room {
            free: Mutex::new(ROOM),
            freed: Condvar::new(),
        });
        let mut mqtt = access.options(client_id);
        mqtt.set_keep_alive(Duration::from_secs(10));
        mqtt.set_clean_session(false);
        // A message is acknowledged to the broker once the robot has it
        // (`settling` in the link's loop), not as it arrives.
        mqtt.set_manual_acks(true);
        let (client, connection) = rumqttc::Client::new(mqtt, 256);
        let broker = Broker {
            client,
            handing: Arc::new(Mutex::new(None)),
        };
        let subscriptions = [
            topics::team_inbox(&self.scope, &self.robot.team),
            topics::robot_inbox(&self.scope, &self.robot.team, &self.robot.robot),
        ];
        {
            let events = events.clone();
            let room = room.clone();
            let broker = broker.clone();
            let name = self.name().to_string();
            std::thread::spawn(move || {
                broker_thread(
                    connection,
                    broker,
                    subscriptions,
                    access,
                    events,
                    room,
                    name,
                )
            });
        }
        // The link opens once the broker is ready: a robot's Hello is
        // answered with what the broker says of its session.
        let mut early = VecDeque::new();
        let session_present = loop {
            match heard.recv() {
                Ok(Event::Ready(present)) => break present,
                // A kept session's messages come right after the broker's
                // CONNACK, before the SUBACK: they wait with the rest.
                Ok(Event::Message(publish)) => early.push_back(publish),
                Ok(_) => {}
                Err(_) => return,
            }
        };
        let mut held: VecDeque<rumqttc::Publish> = early;
        // The messages taken from `held`, in order, until the broker hears
        // they were passed on: each is done when the robot has acknowledged
        // its frame (or at once when no frame goes down).
        let mut settling: VecDeque<(rumqttc::Publish, bool)> = VecDeque::new();
        // Acknowledgements the broker connection's queue could not take yet.
        let mut acks: VecDeque<rumqttc::Publish> = VecDeque::new();
        let mut counts = Counts::default();
        let mut endpoint = Endpoint::new(LINK_QUEUE);
        endpoint.welcome_flags = u8::from(session_present);
        // A send is acknowledged to the robot once the broker has it, so a
        // gateway that stops in between loses none: the robot sends it again.
        endpoint.defer_acks = true;
        let started = Instant::now();
        let mut last_status: Option<String> = None;
        // When the robot's session last started (its `Hello` welcomed), on
        // the wall clock: its mission time 0, which its status cannot say
        // (a board has no clock) and the gateway then says for it.
        let mut welcomed_unix_ms: Option<i64> = None;
        loop {
            let Some(writer) = self.open(events.clone()) else {
                std::thread::sleep(Duration::from_millis(500));
                continue;
            };
            let mut writer = writer;
            eprintln!("gateway: {}: link open", self.name());
            endpoint.outgoing.restart();
            let mut wire = Vec::new();
            let now = || started.elapsed().as_millis() as u64;
            endpoint.tick(now(), &mut wire);
            let closed = loop {
                if !wire.is_empty() {
                    if let Err(e) = writer.write_all(&wire) {
                        break format!("write: {e}");
                    }
                    wire.clear();
                }
                let wait = endpoint
                    .outgoing
                    .deadline()
                    .map(|d| Duration::from_millis(d.saturating_sub(now())));
                // Acknowledgements waiting for room in the connection's queue
                // are tried again soon, whatever else comes.
                let wait = match wait {
                    _ if acks.is_empty() => wait,
                    Some(wait) => Some(wait.min(ACK_RETRY)),
                    None => Some(ACK_RETRY),
                };
                let event = match wait {
                    Some(wait) => match heard.recv_timeout(wait) {
                        Ok(event) => Some(event),
                        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => None,
                        Err(_) => return,
                    },
                    None => match heard.recv() {
                        Ok(event) => Some(event),
                        Err(_) => return,
                    },
                };
                let pending_before = endpoint.outgoing.pending();
                match event {
                    None => {}
                    Some(Event::Bytes(bytes)) => {
                        let hellos = endpoint.hellos;
                        let frames = endpoint.feed(&bytes, now(), &mut wire);
                        if endpoint.hellos != hellos {
                            welcomed_unix_ms = Some(unix_ms());
                        }
                        for frame in frames {
                            let handed = self.publish_for_robot(
                                &frame,
                                &broker,
                                &mut counts,
                                &mut last_status,
                                welcomed_unix_ms,
                            );
                            match handed {
                                Handed::Awaiting | Handed::Unreliable => {}
                                Handed::Refused => endpoint.acknowledge(frame.seq, &mut wire),
                                Handed::NotTaken => endpoint.incoming.forget(frame.seq),
                            }
                        }
                        for bad in endpoint.bad_frames.drain(..) {
                            eprintln!("gateway: {}: a bad frame ({bad}), dropped", self.name());
                        }
                    }
                    Some(Event::Closed(why)) => break why,
                    Some(Event::Ready(_)) => {}
                    Some(Event::Acked(seq)) => endpoint.acknowledge(seq, &mut wire),
                    Some(Event::Message(publish)) => held.push_back(publish),
                }
                // Messages from the broker go down as the link has room,
                // once the session stands: its Welcome (or the robot's
                // Hello) said how long a payload the robot takes.
                while let Some(publish) = held.front().filter(|_| endpoint.outgoing.welcomed()) {
                    let frame = self.down_the_link(
                        &publish.topic,
                        &publish.payload,
                        endpoint.peer_payload_max,
                        &mut counts,
                    );
                    let on_link = match frame {
                        None => {
                            room.give(1);
                            false
                        }
                        Some((kind, bytes)) => {
                            if endpoint.queue(kind, bytes).is_err() {
                                break;
                            }
                            true
                        }
                    };
                    let publish = held.pop_front().expect("the front was there");
                    settling.push_back((publish, !on_link));
                }
                // Room comes back as the robot acknowledges, and the broker
                // hears of each message the robot has, in order.
                let pending_after = endpoint.outgoing.pending();
                let acked = pending_before.saturating_sub(pending_after);
                room.give(acked);
                settling
                    .iter_mut()
                    .filter(|(_, done)| !done)
                    .take(acked)
                    .for_each(|(_, done)| *done = true);
                while settling.front().is_some_and(|(_, done)| *done) {
                    let (publish, _) = settling.pop_front().expect("the front was there");
                    acks.push_back(publish);
                }
                while let Some(publish) = acks.front() {
                    if broker.client.try_ack(publish).is_err() {
                        break;
                    }
                    acks.pop_front();
                }
                endpoint.tick(now(), &mut wire);
            };
            eprintln!("gateway: {}: link closed ({closed})", self.name());
            // A robot that comes back on its link (reset, its QEMU started
            // again) finds its broker session kept, the gateway's: its
            // Welcome says so, as a restarted Linux robot's CONNACK does,
            // so that its elections listen before they claim.
            if endpoint.outgoing.welcomed() {
                endpoint.welcome_flags = 1;
            }
            // A robot whose last status says it stopped ended as a Linux
            // robot that disconnects: no last will (a board's QEMU exits
            // after its `stop`, and its status stays `stopped`).
            if state_of(last_status.as_deref()).as_deref() != Some("stopped") {
                self.lost(&broker.client, last_status.as_deref());
            }
        }
    }

    /// Opens the link and starts its reader; the writing half, or `None`
    /// (said on standard error) when it cannot be opened now.
    fn open(&self, events: SyncSender<Event>) -> Option<Box<dyn Write + Send>> {
        let (reader, writer): (Box<dyn Read + Send>, Box<dyn Write + Send>) = match &self.place {
            Place::Connect(address) => match TcpStream::connect(address) {
                Ok(stream) => {
                    let _ = stream.set_nodelay(true);
                    (
                        Box::new(QuickAck(stream.try_clone().ok()?)),
                        Box::new(stream),
                    )
                }
                Err(e) => {
                    eprintln!("gateway: {}: tcp:{address}: {e} (retrying)", self.name());
                    return None;
                }
            },
            Place::Listen(address) => {
                let listener = match TcpListener::bind(address) {
                    Ok(listener) => listener,
                    Err(e) => {
                        eprintln!("gateway: {}: listen:{address}: {e} (retrying)", self.name());
                        return None;
                    }
                };
                let (stream, _) = listener.accept().ok()?;
                let _ = stream.set_nodelay(true);
                (
                    Box::new(QuickAck(stream.try_clone().ok()?)),
                    Box::new(stream),
                )
            }
            Place::Device(path) => {
                match std::fs::OpenOptions::new()
                    .read(true)
                    .write(true)
                    .open(path)
                {
                    Ok(file) => (Box::new(file.try_clone().ok()?), Box::new(file)),
                    Err(e) => {
                        eprintln!(
                            "gateway: {}: {}: {e} (retrying)",
                            self.name(),
                            path.display()
                        );
                        return None;
                    }
                }
            }
        };
        std::thread::spawn(move || read_link(reader, events));
        Some(writer)
    }

    /// A frame the robot sent: published for it, or refused.
    fn publish_for_robot(
        &self,
        frame: &Frame,
        broker: &Broker,
        counts: &mut Counts,
        last_status: &mut Option<String>,
        welcomed_unix_ms: Option<i64>,
    ) -> Handed {
        let me = Sender {
            team: &self.robot.team,
            robot: &self.robot.robot,
        };
        match frame.kind {
            Kind::Status => {
                let payload = with_start(&frame.payload, welcomed_unix_ms);
                let text = String::from_utf8_lossy(&payload).into_owned();
                let status = Outbound {
                    topic: topics::status(&self.scope, &self.robot.robot),
                    qos: rumqttc::QoS::AtLeastOnce,
                    retain: true,
                    payload,
                };
                let handed = broker.hand(self.name(), counts, status, Some(frame.seq));
                *last_status = Some(text);
                handed
            }
            Kind::Send | Kind::Publish => {
                let Some((to, data)) = frame.destination() else {
                    // Its shape was checked as it was read.
                    return Handed::Refused;
                };
                let to = String::from_utf8_lossy(to).into_owned();
                let publish = frame.kind == Kind::Publish;
                let mut handed = Handed::Refused;
                let refusal = match datagram::decode(data) {
                    None => Some("not a runtime datagram".to_string()),
                    Some(d) if d.team != me.team || d.robot != me.robot => Some(format!(
                        "its datagram names {}/{} as the sender, not this link's robot",
                        d.team.escape_debug(),
                        d.robot.escape_debug()
                    )),
                    Some(d) if d.publish != publish => {
                        Some("its datagram's kind is not its frame's".to_string())
                    }
                    Some(d) => match self.topic_to(&to, &d.key, me) {
                        Some(topic) => {
                            let qos = if publish {
                                rumqttc::QoS::AtMostOnce
                            } else {
                                rumqttc::QoS::AtLeastOnce
                            };
                            let message = Outbound {
                                topic,
                                qos,
                                retain: false,
                                payload: data.to_vec(),
                            };
                            let reliable = (!publish).then_some(frame.seq);
                            handed = broker.hand(self.name(), counts, message, reliable);
                            None
                        }
                        None => Some(format!(
                            "`{}` is no team, robot or USER of the mission",
                            to.escape_debug()
                        )),
                    },
                };
                if let Some(why) = refusal {
                    counts.refused_frames += 1;
                    eprintln!(
                        // What the frame says, escaped: it may hold any bytes.
                        "gateway: {}: refused a {} to {}: {why} ({} refused)",
                        self.name(),
                        if publish { "publish" } else { "send" },
                        to.escape_debug(),
                        counts.refused_frames
                    );
                }
                handed
            }
            _ => Handed::Unreliable,
        }
    }

    /// The topic of a message from `me` to `to` (a team, `USER`, or one
    /// robot), as `semo_mqtt.c` names it: a team wins over a robot of the
    /// same name.
    fn topic_to(&self, to: &str, key: &str, me: Sender) -> Option<String> {
        if self.roster.teams.contains(to) || to == "USER" {
            return Some(topics::to_team(&self.scope, to, key, me));
        }
        let robot = self.roster.robots.iter().find(|r| r.robot == to)?;
        Some(topics::to_robot(
            &self.scope,
            &robot.team,
            &robot.robot,
            key,
            me,
        ))
    }

    /// What a message from the broker becomes on the link: `M` with its
    /// datagram, `R` when its datagram names another sender or key than
    /// its topic or is longer than the robot takes (`payload_max`), nothing
    /// for the robot's own message to its team. (An `M` longer than the
    /// robot takes would be a bad frame there, never acknowledged, and sent
    /// again for ever ahead of every later message.)
    fn down_the_link(
        &self,
        topic: &str,
        payload: &[u8],
        payload_max: usize,
        counts: &mut Counts,
    ) -> Option<(Kind, Vec<u8>)> {
        let Some(d) = datagram::decode(payload) else {
            // The runtime rejects it as malformed, as over MQTT.
            return Some(self.message_down(topic, payload, payload_max, counts));
        };
        let sender = Sender::claimed_by(&d);
        let own_team = topics::to_team(&self.scope, &self.robot.team, &d.key, sender);
        let own_robot = topics::to_robot(
            &self.scope,
            &self.robot.team,
            &self.robot.robot,
            &d.key,
            sender,
        );
        let on_its_topic = topic == own_team || topic == own_robot;
        if on_its_topic && d.team == self.robot.team && d.robot == self.robot.robot {
            return None; // our own message to our team
        }
        if !on_its_topic {
            counts.refused_messages += 1;
            eprintln!(
                "gateway: {}: a message on {} names another sender or key ({} refused)",
                self.name(),
                topic.escape_debug(),
                counts.refused_messages
            );
            return Some((Kind::Refused, vec![Refusal::Topic.byte()]));
        }
        Some(self.message_down(topic, payload, payload_max, counts))
    }

    /// `M` with the message, or `R` when it is longer than the robot takes.
    fn message_down(
        &self,
        topic: &str,
        payload: &[u8],
        payload_max: usize,
        counts: &mut Counts,
    ) -> (Kind, Vec<u8>) {
        if payload.len() <= payload_max {
            return (Kind::Message, payload.to_vec());
        }
        counts.refused_messages += 1;
        eprintln!(
            "gateway: {}: a message of {} bytes on {} is longer than the robot takes ({payload_max} bytes) ({} refused)",
            self.name(),
            payload.len(),
            topic.escape_debug(),
            counts.refused_messages
        );
        (Kind::Refused, vec![Refusal::Length.byte()])
    }

    /// The link closed: the robot's status says it is lost (retained, as a
    /// Linux robot's last will says), with the `started` of its last status.
    fn lost(&self, client: &rumqttc::Client, last_status: Option<&str>) {
        let started = last_status
            .and_then(|s| serde_json::from_str::<serde_json::Value>(s).ok())
            .and_then(|v| v.get("started").cloned())
            .unwrap_or(serde_json::Value::String("0".to_string()));
        let status = serde_json::json!({
            "robot": self.robot.robot,
            "event": "status",
            "state": "lost",
            "started": started,
        });
        let _ = client.try_publish(
            topics::status(&self.scope, &self.robot.robot),
            rumqttc::QoS::AtLeastOnce,
            true,
            status.to_string().into_bytes(),
        );
    }
}

/// The `state` a status says, if it is a JSON object with one.
fn state_of(status: Option<&str>) -> Option<String> {
    let value: serde_json::Value = serde_json::from_str(status?).ok()?;
    Some(value.get("state")?.as_str()?.to_string())
}

/// A board's status with `started` said: the wall-clock time of its
/// session's welcome (its mission time 0, as a Linux robot's status says
/// its own), when the gateway welcomed it and the board says `"0"` (it has
/// no clock). Anything else goes on unchanged: the gateway never puts a
/// time in a status that says one, nor in what is not a status object.
fn with_start(payload: &[u8], welcomed_unix_ms: Option<i64>) -> Vec<u8> {
    let Some(at) = welcomed_unix_ms else {
        return payload.to_vec();
    };
    let Ok(serde_json::Value::Object(mut status)) = serde_json::from_slice(payload) else {
        return payload.to_vec();
    };
    match status.get_mut("started") {
        Some(started) if started.as_str() == Some("0") => {
            *started = serde_json::Value::String(at.to_string());
        }
        _ => return payload.to_vec(),
    }
    serde_json::to_vec(&status).unwrap_or_else(|_| payload.to_vec())
}

/// Now on the wall clock, in Unix ms.
fn unix_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// A link's TCP connection read with every byte acknowledged at once.
/// The robot's end writes a frame a few bytes at a time (a UART's bytes, as
/// QEMU's serial socket passes them on); with Nagle's algorithm there (QEMU
/// without `nodelay`) each write after the first waits for the last one's
/// acknowledgement, which Linux delays up to 40 ms when the gateway has
/// nothing to answer yet: a frame would take tens of ms to arrive.
/// `TCP_QUICKACK` lasts only until the next delayed acknowledgement, so it
/// is set again after each read.
struct QuickAck(TcpStream);

impl Read for QuickAck {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.0.read(buf)?;
        let _ = rustix::net::sockopt::set_tcp_quickack(&self.0, true);
        Ok(n)
    }
}

/// The link's bytes, as they come, until it closes.
fn read_link(mut reader: Box<dyn Read + Send>, events: SyncSender<Event>) {
    let mut buf = [0u8; 4096];
    loop {
        match reader.read(&mut buf) {
            Ok(0) => {
                let _ = events.send(Event::Closed("end of stream".to_string()));
                return;
            }
            Ok(n) => {
                if events.send(Event::Bytes(buf[..n].to_vec())).is_err() {
                    return;
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => {
                let _ = events.send(Event::Closed(e.to_string()));
                return;
            }
        }
    }
}

/// The robot's MQTT connection: subscribes on every connection, says when
/// the subscriptions stand, hands over what the broker delivers (waiting
/// for room, so the broker holds a burst).
fn broker_thread(
    mut connection: rumqttc::Connection,
    broker: Broker,
    subscriptions: [String; 2],
    access: BrokerAccess,
    events: SyncSender<Event>,
    room: Arc<Room>,
    name: String,
) {
    let mut session_present = false;
    let mut ready = false;
    // Packet id → the robot's frame it publishes (QoS 1, until its PubAck).
    let mut awaiting: HashMap<u16, u16> = HashMap::new();
    for event in connection.iter() {
        match event {
            // A new QoS 1 publish (a packet id not seen: not one sent again
            // after a reconnection): the robot's frame just handed, if any.
            Ok(rumqttc::Event::Outgoing(rumqttc::Outgoing::Publish(pkid)))
                if pkid != 0 && !awaiting.contains_key(&pkid) =>
            {
                let handed = broker
                    .handing
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .take();
                if let Some(seq) = handed {
                    awaiting.insert(pkid, seq);
                }
            }
            Ok(rumqttc::Event::Incoming(rumqttc::Packet::PubAck(ack))) => {
                if let Some(seq) = awaiting.remove(&ack.pkid)
                    && events.send(Event::Acked(seq)).is_err()
                {
                    return;
                }
            }
            Ok(rumqttc::Event::Incoming(rumqttc::Packet::ConnAck(ack))) => {
                session_present = ack.session_present;
                for topic in &subscriptions {
                    let _ = broker
                        .client
                        .try_subscribe(topic.clone(), rumqttc::QoS::AtLeastOnce);
                }
            }
            Ok(rumqttc::Event::Incoming(rumqttc::Packet::SubAck(_))) => {
                if !ready {
                    ready = true;
                    if events.send(Event::Ready(session_present)).is_err() {
                        return;
                    }
                }
            }
            Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) => {
                room.take();
                if events.send(Event::Message(p)).is_err() {
                    return;
                }
            }
            Ok(_) => {}
            Err(e) => {
                let failure = access.failure(&e);
                eprintln!(
                    "gateway: {name}: broker: {}{}",
                    failure.message,
                    if failure.permanent { "" } else { " (retrying)" }
                );
                if failure.permanent {
                    std::process::exit(1);
                }
                std::thread::sleep(Duration::from_secs(1));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_are_robot_equals_a_place() {
        assert_eq!(
            parse_link("ti=tcp:127.0.0.1:5000"),
            Ok((
                "ti".to_string(),
                Place::Connect("127.0.0.1:5000".to_string())
            ))
        );
        assert_eq!(
            parse_link("ti=listen:localhost:7"),
            Ok(("ti".to_string(), Place::Listen("localhost:7".to_string())))
        );
        assert_eq!(
            parse_link("ti=/dev/ttyUSB0"),
            Ok(("ti".to_string(), Place::Device("/dev/ttyUSB0".into())))
        );
        for bad in [
            "ti",
            "=tcp:a:1",
            "ti=",
            "ti=tcp:host",
            "ti=tcp::1",
            "ti=listen:h:99999",
        ] {
            assert!(parse_link(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_boards_status_gets_the_time_of_its_welcome() {
        let board =
            br#"{"t":0,"robot":"ti","event":"status","state":"running","started":"0","mode":"M"}"#;
        assert_eq!(
            String::from_utf8(with_start(board, Some(1_700_000_000_123))).unwrap(),
            r#"{"t":0,"robot":"ti","event":"status","state":"running","started":"1700000000123","mode":"M"}"#,
            "the fields in their order, only `started` said"
        );
        // Not welcomed by this gateway (it restarted under a running
        // board): nothing to say.
        assert_eq!(with_start(board, None), board.to_vec());
        // A status that says a time, or what is no status object, unchanged.
        let timed = br#"{"robot":"ti","started":"42"}"#;
        assert_eq!(with_start(timed, Some(7)), timed.to_vec());
        for odd in [&b"not json"[..], b"[1,2]", br#"{"started":0}"#] {
            assert_eq!(with_start(odd, Some(7)), odd.to_vec());
        }
    }
}
