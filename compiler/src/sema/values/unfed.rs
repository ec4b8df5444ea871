//! W024: a receive or subscribe that no robot can ever feed.
//!
//! W004 says when no `send` (`publish`) of the value to the receiving team
//! is written at all. Written ones may still never run: they are in
//! services that no mode the sending team's robots can be in sets
//! ([`Timeline`]). And a robot does not get its own messages: a `receive`
//! from its own team that only one robot runs, where every `send` that runs
//! is run by that robot alone, waits for nothing that can come. (A robot
//! does see its own publications, so a `subscribe` is reported only when
//! no `publish` runs.)
//!
//! Messages wait in a robot's inbox until a `receive` takes them, across
//! mode changes: a send that runs at any time feeds a receive that runs
//! later. So what cannot feed a receive is only what never runs, or runs
//! on the receiving robot alone; a receive is reported only when it runs
//! itself. A publication reaches a `receive` too when the robot subscribes
//! to nothing, so the publishes of the value count as feeding a receive.

use super::Finding;
use super::timeline::Timeline;
use crate::diag::Code;
use crate::fasthash::{FastMap, FastSet};
use crate::sema::Checker;
use crate::sema::ir::{AttrKey, Peer, RobotId, TeamId};
use crate::span::Span;
use crate::syntax::ast::CommKind;

/// Who can feed the receives of one (kind, sending team, receiving team,
/// value).
enum Feed {
    /// No send of them runs.
    Never,
    /// Every send that runs is run by this robot alone (of a team that
    /// sends to itself).
    OnlyBy(RobotId),
    /// Some other robot may send them.
    Fed,
    /// None is written (W004 says so).
    Unwritten,
}

/// (kind of statement, sending team, receiving team, value).
type Channel<'m> = (CommKind, TeamId, TeamId, &'m AttrKey);

impl Checker<'_> {
    pub(super) fn unfed(&self, timeline: &Timeline) -> Vec<Finding> {
        let mut written_to: FastMap<Channel, Vec<usize>> = FastMap::default();
        for (i, m) in self.mission.messages.iter().enumerate() {
            if let (true, Peer::Team(to)) = (m.kind.is_outgoing(), m.peer) {
                written_to
                    .entry((m.kind, m.team, to, &m.value))
                    .or_default()
                    .push(i);
            }
        }
        // Per (receive or subscribe, team, team, value): who can feed it.
        let mut feeds: FastMap<Channel, Feed> = FastMap::default();
        // The receives no robot feeds, and where the others are written: a
        // receive in a function has one message per caller, and is
        // reported only when no caller's robots are fed.
        let (mut unfed, mut fed) = (Vec::new(), Vec::new());
        for (i, m) in self.mission.messages.iter().enumerate() {
            let Peer::Team(from) = m.peer else { continue };
            if m.kind.is_outgoing() || !timeline.runs(m.team, m.service) {
                continue;
            }
            let channel = (m.kind, from, m.team, &m.value);
            let feed = feeds
                .entry(channel)
                .or_insert_with(|| self.feed(feeders(&written_to, channel), timeline));
            let never_fed = match feed {
                Feed::Never => true,
                Feed::OnlyBy(robot) => {
                    m.kind == CommKind::Receive && *self.message_robots[i] == [*robot]
                }
                Feed::Fed | Feed::Unwritten => false,
            };
            if never_fed {
                unfed.push((i, channel));
            } else {
                fed.push(m.span);
            }
        }
        if unfed.is_empty() {
            return Vec::new();
        }
        let mut seen: FastSet<Span> = fed.into_iter().collect();
        unfed
            .into_iter()
            .filter(|(i, _)| seen.insert(self.mission.messages[*i].span))
            .map(|(i, channel)| {
                self.unfed_finding(i, channel, feeders(&written_to, channel), timeline)
            })
            .collect()
    }

    fn feed(&self, sends: [&[usize]; 2], timeline: &Timeline) -> Feed {
        if sends[0].is_empty() {
            return Feed::Unwritten;
        }
        let mut only: Option<RobotId> = None;
        for &s in sends.iter().copied().flatten() {
            let send = &self.mission.messages[s];
            if !timeline.runs(send.team, send.service) {
                continue;
            }
            let by_itself = send.peer == Peer::Team(send.team);
            match (&*self.message_robots[s], only) {
                (&[robot], None) if by_itself => only = Some(robot),
                (&[robot], Some(o)) if robot == o => {}
                _ => return Feed::Fed,
            }
        }
        match only {
            Some(robot) => Feed::OnlyBy(robot),
            None => Feed::Never,
        }
    }

    /// The finding on message `i`, a receive of `channel` that `sends`
    /// never feed.
    fn unfed_finding(
        &self,
        i: usize,
        channel: Channel,
        sends: [&[usize]; 2],
        timeline: &Timeline,
    ) -> Finding {
        let m = &self.mission.messages[i];
        let team = self.team(m.team);
        let path = team.service_path(m.service);
        let from = &self.team(channel.1).name;
        let value = &m.value;
        let message = if m.kind == CommKind::Receive {
            format!(
                "`{path}` receives `{value}` from {from} here, but no robot can ever send it: this `receive` never takes a message (it waits for ever, or until its timeout)"
            )
        } else {
            format!(
                "`{path}` subscribes to `{value}` from {from} here, but no robot can ever publish it: the value stays as it was"
            )
        };
        let related = (sends.iter().copied().flatten())
            .map(|&s| (self.mission.messages[s].span, self.why_not_fed(s, timeline)))
            .collect();
        Finding {
            code: Code::ReceiveNeverFed,
            span: m.span,
            message,
            related,
        }
    }

    /// Why send `s` (an index into the messages) feeds no receive.
    fn why_not_fed(&self, s: usize, timeline: &Timeline) -> String {
        let send = &self.mission.messages[s];
        let team = self.team(send.team);
        let verb = if send.kind == CommKind::Publish {
            "published"
        } else {
            "sent"
        };
        if !timeline.runs(send.team, send.service) {
            return format!(
                "`{}` is {verb} here, in `{}`, which never runs: no mode {}'s robots can be in sets it",
                send.value,
                team.service_path(send.service),
                team.name
            );
        }
        let robot = self.message_robots[s]
            .first()
            .map(|&r| team.robot(r).name.as_str())
            .unwrap_or_default();
        format!(
            "`{}` is {verb} here only by {robot}, the robot that receives it: a robot does not get its own messages",
            send.value
        )
    }
}

/// The sends and publishes that may feed the receives or subscribes of
/// `channel`: the statements of its own kind (none: W004 says so), then the
/// others that reach it. A publication reaches a `receive` too, on a robot
/// that subscribes to nothing (the simulator's and the runtime's receive
/// task); only publications set what `subscribe` reads.
fn feeders<'w>(
    written_to: &'w FastMap<Channel, Vec<usize>>,
    channel: Channel<'w>,
) -> [&'w [usize]; 2] {
    let (kind, from, to, value) = channel;
    let of = |kind| {
        written_to
            .get(&(kind, from, to, value))
            .map_or(&[][..], Vec::as_slice)
    };
    match kind {
        CommKind::Receive => [of(CommKind::Send), of(CommKind::Publish)],
        _ => [of(CommKind::Publish), &[]],
    }
}
