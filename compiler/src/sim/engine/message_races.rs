//! Races between robots, for `semo verify` (V006). Messages that reach one
//! robot in one instant are taken by its receive task one after the other:
//! the simulator takes them in its event queue's order (the order they were
//! sent in), the lock-step coordinator of `--engine c` in the senders' peer
//! order, but over MQTT the two messages of two different senders may come
//! in either order. When the order decides what the robot does next, what
//! the team does depends on which of two things that happen at once comes
//! first.
//!
//! What is compared: at the first delivery of an instant, for each robot
//! that takes, in that instant, messages from two different senders that
//! it acts on (a value for a `receive`, a published value it subscribes to,
//! a broadcast event of its team, a shared value it keeps) and that are not
//! the same message (same kind, team, key and value), the instant's
//! deliveries run on two copies of the fleet: one in the run's order, one
//! with the later sender's messages taken before the earlier one's (each
//! sender's own messages keep their order, as MQTT keeps them). Both then
//! run to the robot's control firing that reacts (the firing a message
//! wakes, else the end of the instant), and on, firing by firing, until
//! both have taken all of the instant's messages (none held up by a full
//! channel or behind one; at most [`TAKING_FIRINGS`] firings): compared
//! while one still waits, two orders that end the same would differ only
//! in which message waits. Then the two are compared by the search's
//! fingerprint, leaving out what nothing the team does reads ([`Unread`]:
//! a received value read only by `send(USER, ...)`, a report to the
//! operator, or by nothing, in its slot, the library and the channel that
//! feeds it). Should the robot go to another mode in one than in the
//! other, that is a race: another thing the team does. Otherwise both run
//! on, instant by instant, until the world's next choice (the search's
//! step: nothing new comes in before it); if they come to one state on the
//! way (a published value replaced before anything read it), the order
//! changed nothing. Two states that still differ there go on differently.
//! (When every message the robot takes from the two is a value for unread
//! slots only, filling the same channels in either order, the two orders
//! differ in those values alone: nothing is run.)
//! The run itself is not changed. Publishes are compared too: a publish's
//! next value replaces it, but two publishes of one key in one instant race
//! on which value stays, and a `subscribe` reads that one until then.
//! Heartbeats and arrivals at a group statement are left out: each peer's
//! has its own place, so their order never matters.

use super::{Event, Memory, Message, Robot, Sim};
use crate::refine::value::Value;
use crate::refine::{AttributeId, Expr, ModeId, Operand, SlotSource, StateKind};
use std::rc::Rc;

/// One delivery of an instant: the robots it reaches (each with its epoch
/// when it was sent) and the message.
type Delivery = (Rc<[(usize, u32)]>, Rc<Message>);

/// How many of the robot's firings the two orders run, at most, for it to
/// take the instant's messages (each firing takes one from a full channel,
/// or the one after drops it).
const TAKING_FIRINGS: usize = 8;

/// What a message is to the robot it reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Taken {
    /// A value for a `receive` (the incoming message's index).
    Received(usize),
    /// A published value of a group it subscribes to (the group's index).
    Subscribed(usize),
    /// A broadcast event of its team.
    Event,
    /// A value of the team's shared information.
    Shared,
}

/// One of the two messages of a race: who sent it and what it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Arrival {
    /// The sender (an index into the programs).
    pub from: usize,
    /// The sending team's name.
    pub from_team: String,
    pub key: String,
    pub publish: bool,
    pub value: Option<Value>,
    pub taken: Taken,
}

/// What differs between the two orders at the robot's reaction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Differs {
    /// The mode it is in or goes to: (in the run's order, in the other).
    Mode(Option<ModeId>, Option<ModeId>),
    /// A value it holds (received, subscribed, shared).
    Values,
    /// What it does next (what waits to be taken, what it sent).
    Next,
}

/// Robot `robot` took, at `at`, `first` then `second` from two different
/// senders; in the other order its reaction differs (`differs`).
#[derive(Clone, Debug, PartialEq)]
pub struct MessageRace {
    /// The receiver (an index into the programs).
    pub robot: usize,
    /// Mission ms of the instant.
    pub at: i64,
    /// The receiver's mode then.
    pub mode: Option<ModeId>,
    pub first: Arrival,
    pub second: Arrival,
    pub differs: Differs,
}

/// What watching for races between robots keeps.
#[derive(Clone)]
pub(super) struct Watch {
    found: Vec<MessageRace>,
    /// The last instant whose deliveries were looked at.
    checked: i64,
    memory: Rc<Memory>,
    /// Per robot: what only reaches the operator ([`Unread`]).
    unread: Rc<[Unread]>,
    /// The world's clock (`semo verify`'s step): it chooses nothing
    /// between two of its ticks.
    step_ms: i64,
}

/// A robot's values that nothing it does reads: each read only by a
/// `send(USER, ...)` (a report to the operator, which the team does not act
/// on), or never. Two orders that differ only there differ in nothing the
/// team does: [`Sim::forget_unread`] blanks them before the comparison.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Unread {
    /// Per slot.
    slots: Vec<bool>,
    /// Per place of the library (every slot it feeds unread).
    library: Vec<bool>,
}

impl Unread {
    /// Robot `robot`'s: a slot is unread when it holds a received value
    /// (`SlotSource::Shared`) that is not one of the team's globally shared
    /// values (a write of those is told to the team), and no statement
    /// reads it but as the value of a `send(USER, ...)` that stores it
    /// nowhere: no condition, no call's or action's argument, no send to a
    /// robot, no action machine's command or transition, no battery
    /// policy.
    fn of(robot: &Robot) -> Unread {
        let program = robot.program;
        let m = &program.control;
        let mut read = vec![false; m.slots.len()];
        fn operand(read: &mut [bool], op: &Operand) {
            if let Operand::Slot(s) = op {
                read[s.index()] = true;
            }
        }
        fn expr(read: &mut [bool], e: &Expr) {
            e.for_each_operand(&mut |op| operand(read, op));
        }
        for state in m.services.iter().flat_map(|s| &s.states) {
            match &state.kind {
                StateKind::Send { items } => {
                    for item in items {
                        let report = m.outgoing_message(item.message).to_team == "USER"
                            && item.store.is_none()
                            && item.own_group.is_none();
                        if !report {
                            operand(&mut read, &item.value);
                        }
                    }
                }
                StateKind::Call { args, .. } | StateKind::RunActions { args, .. } => {
                    args.iter().for_each(|a| operand(&mut read, a));
                }
                StateKind::Branch { condition, .. } => expr(&mut read, condition),
                StateKind::LoopHead { condition, .. } | StateKind::Repeat { condition, .. } => {
                    condition.iter().for_each(|c| expr(&mut read, c));
                }
                StateKind::Receive { .. }
                | StateKind::Subscribe { .. }
                | StateKind::Throw { .. }
                | StateKind::LeaderBranch { .. }
                | StateKind::GroupAllocate { .. }
                | StateKind::GroupSync { .. }
                | StateKind::Jump { .. }
                | StateKind::LoopTail { .. } => {}
            }
        }
        for action in m.actions.iter().flat_map(|a| &a.actions) {
            action
                .commands
                .iter()
                .for_each(|(_, op)| operand(&mut read, op));
            (action.transitions.iter())
                .filter_map(|(e, _)| e.as_ref())
                .for_each(|e| expr(&mut read, e));
        }
        m.battery.iter().for_each(|b| expr(&mut read, &b.condition));
        let global: Vec<AttributeId> = (program.library.as_ref())
            .and_then(|l| l.ownership.as_ref())
            .map(|o| o.global.iter().map(|g| g.at).collect())
            .unwrap_or_default();
        let slots: Vec<bool> = (m.slots.iter().enumerate())
            .map(|(i, slot)| {
                slot.source == SlotSource::Shared
                    && !read[i]
                    && robot.library_index[i].is_none_or(|k| !global.contains(&k))
            })
            .collect();
        // A place is unread when every slot it feeds is (one pass over the slots).
        let mut library = vec![true; robot.library.len()];
        for (i, at) in robot.library_index.iter().enumerate() {
            if let Some(at) = at {
                library[at.index()] &= slots[i];
            }
        }
        Unread { slots, library }
    }
}

impl<'p> Sim<'p> {
    /// From now on, note every race between robots
    /// ([`Sim::take_message_races`]), the world choosing at most every
    /// `step_ms` (a multiple of the sensor period: `semo verify`'s step).
    pub fn watch_message_races(&mut self, step_ms: i64) {
        if self.message_races.is_none() {
            self.message_races = Some(Box::new(Watch {
                found: Vec::new(),
                checked: i64::MIN,
                memory: Rc::new(Memory::of(self.programs)),
                unread: self.robots.iter().map(Unread::of).collect(),
                step_ms: step_ms.max(1),
            }));
        }
    }

    /// The races between robots noted since the last call.
    pub fn take_message_races(&mut self) -> Vec<MessageRace> {
        self.message_races
            .as_mut()
            .map(|w| std::mem::take(&mut w.found))
            .unwrap_or_default()
    }

    /// What `message` is to robot `r`, or `None` when its order among
    /// others cannot matter (a heartbeat, an arrival at a group statement,
    /// a message it does not take): as [`Sim::take_in`] routes it.
    fn taken(&self, r: usize, message: &Message) -> Option<Taken> {
        let robot = &self.robots[r];
        if !robot.has_receiver {
            return None;
        }
        let program = robot.program;
        if let Some(ownership) = program.library.as_ref().and_then(|l| l.ownership.as_ref())
            && ownership
                .global
                .iter()
                .any(|g| *g.set_key == *message.key || *g.value_key == *message.key)
        {
            return Some(Taken::Shared);
        }
        let m = &program.control;
        let names = &self.fleet.names[r];
        if m.heartbeat && message.publish && message.key == names.alive_key {
            return None;
        }
        if !m.sync_points.is_empty() && message.key == names.sync_key {
            return None;
        }
        if !m.events_heard.is_empty()
            && !message.publish
            && message.key == names.event_key
            && message.from_team == names.team
        {
            return Some(Taken::Event);
        }
        if !m.subscribed.is_empty() && message.publish {
            return (names.subscribed.iter())
                .position(|g| *g == message.key)
                .map(Taken::Subscribed);
        }
        (names.incoming.iter())
            .position(|(team, key)| *team == message.from_team && *key == message.key)
            .map(Taken::Received)
    }

    /// The first delivery of this instant is about to be handled (`message`
    /// to `to`, already out of the queue): for each robot that takes
    /// messages of two senders in it, compares its reaction in the run's
    /// order and with each two senders next to each other swapped.
    pub(super) fn look_for_message_races(
        &mut self,
        to: &Rc<[(usize, u32)]>,
        message: &Rc<Message>,
    ) {
        let Some(watch) = self.message_races.as_mut() else {
            return;
        };
        if watch.checked == self.now {
            return;
        }
        watch.checked = self.now;
        let now = self.now;
        // The instant's deliveries in the order they will be handled.
        let mut rest: Vec<_> = (self.queue.iter())
            .filter(|q| q.time() == now && matches!(q.event, Event::Deliver { .. }))
            .collect();
        if rest.is_empty() {
            return;
        }
        rest.sort_unstable_by_key(|q| q.key);
        let mut batch: Vec<Delivery> = vec![(to.clone(), message.clone())];
        for q in rest {
            if let Event::Deliver { to, message } = &q.event {
                batch.push((to.clone(), message.clone()));
            }
        }
        // Per receiver: the messages it takes, in order, with their kind.
        let mut by_robot: Vec<Vec<(Rc<Message>, Taken)>> = vec![Vec::new(); self.robots.len()];
        for (to, message) in &batch {
            if message.from.is_none() {
                continue;
            }
            for &(r, epoch) in to.iter() {
                let robot = &self.robots[r];
                if robot.alive
                    && robot.epoch == epoch
                    && let Some(taken) = self.taken(r, message)
                {
                    by_robot[r].push((message.clone(), taken));
                }
            }
        }
        let mut found = Vec::new();
        for (r, taken) in by_robot.iter().enumerate() {
            // The senders in the order their first message comes.
            let mut senders: Vec<usize> = Vec::new();
            for (message, _) in taken {
                let from = message.from.expect("robots' messages only");
                if !senders.contains(&from) {
                    senders.push(from);
                }
            }
            for pair in senders.windows(2) {
                found.extend(self.race_between(r, taken, (pair[0], pair[1]), &batch));
            }
        }
        if let Some(watch) = self.message_races.as_mut() {
            watch.found.extend(found);
        }
    }

    /// Whether robot `r`, taking `taken` in this instant, reacts otherwise
    /// with sender `b`'s messages before sender `a`'s (`a`'s come first in
    /// the run): the race, if so.
    fn race_between(
        &self,
        r: usize,
        taken: &[(Rc<Message>, Taken)],
        (a, b): (usize, usize),
        batch: &[Delivery],
    ) -> Option<MessageRace> {
        let now = self.now;
        let of = |s: usize| taken.iter().filter(move |(m, _)| m.from == Some(s));
        // The same message from both commutes.
        let (m0, t0) = of(a).next().expect("a sends");
        let same = of(a).chain(of(b)).all(|(m, t)| {
            *t == *t0
                && m.publish == m0.publish
                && m.from_team == m0.from_team
                && m.key == m0.key
                && m.value == m0.value
        });
        if same {
            return None;
        }
        // b's messages where a's and b's were, before a's.
        let mut swapped: Vec<&Rc<Message>> = Vec::with_capacity(taken.len());
        let mut moved = of(b).chain(of(a)).map(|(m, _)| m);
        for (m, _) in taken {
            if m.from == Some(a) || m.from == Some(b) {
                swapped.push(moved.next().expect("as many"));
            } else {
                swapped.push(m);
            }
        }
        let plain: Vec<&Rc<Message>> = taken.iter().map(|(m, _)| m).collect();
        if self.alike_but_unread(r, &plain, &swapped) {
            return None;
        }
        let mut ordered = self.delivered(r, batch, &plain);
        let mut other = self.delivered(r, batch, &swapped);
        // Both run to the firing the messages woke (the later one,
        // should the orders wake different ones), else to the end
        // of the instant; then on, firing by firing, while either
        // has not taken all of them yet (one held up by a full
        // channel, or behind it): a few firings take or drop them.
        let fires = |sim: &Sim| sim.robots[r].next_fire.unwrap_or(sim.now).max(sim.now);
        let waits = |sim: &Sim| {
            let robot = &sim.robots[r];
            robot.alive && (robot.holding.is_some() || !robot.behind.is_empty())
        };
        for _ in 0..TAKING_FIRINGS {
            let until = fires(&ordered).max(fires(&other)) + 1;
            ordered.run_to(until);
            other.run_to(until);
            if !waits(&ordered) && !waits(&other) {
                break;
            }
        }
        let watch = self.message_races.as_ref().expect("watching");
        ordered.forget_unread(&watch.unread);
        other.forget_unread(&watch.unread);
        if ordered.fingerprint(&watch.memory) == other.fingerprint(&watch.memory) {
            return None;
        }
        // What differs once both took them, the robot's reaction.
        let mode = |sim: &Sim| {
            let robot = &sim.robots[r];
            robot.pending_mode.or(robot.current_mode)
        };
        let differs = if mode(&ordered) != mode(&other) {
            Differs::Mode(mode(&ordered), mode(&other))
        } else {
            let (x, y) = (&ordered.robots[r], &other.robots[r]);
            if x.slots != y.slots || x.groups != y.groups || x.library != y.library {
                Differs::Values
            } else {
                Differs::Next
            }
        };
        // Another mode is another thing the team does, whatever
        // comes after. Otherwise, until the world's next choice
        // nothing new comes in: a difference that is gone by then
        // (a published value replaced before anything read it)
        // changes nothing.
        let horizon = (now.div_euclid(watch.step_ms) + 1) * watch.step_ms;
        if !matches!(differs, Differs::Mode(..))
            && ordered.converge(&mut other, horizon, &watch.unread, &watch.memory)
        {
            return None;
        }
        let arrival = |s: usize| {
            let (m, t) = of(s).next().expect("sends");
            Arrival {
                from: s,
                from_team: m.from_team.to_string(),
                key: m.key.to_string(),
                publish: m.publish,
                value: m.value.clone(),
                taken: *t,
            }
        };
        Some(MessageRace {
            robot: r,
            at: now,
            mode: self.robots[r].current_mode,
            first: arrival(a),
            second: arrival(b),
            differs,
        })
    }

    /// Whether robot `r` takes the messages `plain` and `swapped` (the
    /// same, in two orders) alike but for values nothing it does reads:
    /// each is a value for `receive`s of unread slots only, of their type,
    /// and the two orders fill the same channels one after the other. The
    /// receive task then holds up, drops and wakes alike, and the two
    /// fleets differ in [`Unread`] values alone: nothing to run.
    fn alike_but_unread(&self, r: usize, plain: &[&Rc<Message>], swapped: &[&Rc<Message>]) -> bool {
        let Some(watch) = self.message_races.as_ref() else {
            return false;
        };
        let unread = &watch.unread[r];
        let m = &self.robots[r].program.control;
        let names = &self.fleet.names[r];
        // The channels a message fills, when all of them feed unread slots
        // and take its value.
        let channels = |message: &Message| -> Option<Vec<usize>> {
            if self
                .taken(r, message)
                .is_none_or(|t| !matches!(t, Taken::Received(_)))
            {
                return None;
            }
            let mut filled = Vec::new();
            for (c, (team, key)) in names.incoming.iter().enumerate() {
                if *team != message.from_team || *key != message.key {
                    continue;
                }
                let slot = m.incoming[c].slot.index();
                let fits = message
                    .value
                    .as_ref()
                    .is_none_or(|v| m.slots[slot].kind.coerce(v).is_some());
                if !unread.slots[slot] || !fits {
                    return None;
                }
                filled.push(c);
            }
            Some(filled)
        };
        plain
            .iter()
            .zip(swapped)
            .all(|(x, y)| match (channels(x), channels(y)) {
                (Some(a), Some(b)) => a == b,
                _ => false,
            })
    }

    /// Runs `self` and `other` on, instant by instant, before `until`;
    /// whether they come to the same state (unread values aside) on the way.
    fn converge(
        &mut self,
        other: &mut Sim,
        until: i64,
        unread: &[Unread],
        memory: &Memory,
    ) -> bool {
        loop {
            let next = |sim: &Sim| sim.queue.peek().map_or(i64::MAX, |q| q.time());
            let t = next(self).min(next(other));
            if t >= until {
                return false;
            }
            self.run_to(t + 1);
            other.run_to(t + 1);
            self.forget_unread(unread);
            other.forget_unread(unread);
            if self.fingerprint(memory) == other.fingerprint(memory) {
                return true;
            }
        }
    }

    /// Blanks every robot's values that nothing it does reads
    /// ([`Unread`]): in its slots and library, and waiting in the channels
    /// that feed those slots (the messages waiting are still counted).
    fn forget_unread(&mut self, unread: &[Unread]) {
        for (robot, unread) in self.robots.iter_mut().zip(unread) {
            let m = &robot.program.control;
            let forget = |v: &mut Option<Value>| *v = None;
            (robot.slots.iter_mut().zip(&unread.slots))
                .filter(|(_, u)| **u)
                .for_each(|(v, _)| forget(v));
            (robot.library.iter_mut().zip(&unread.library))
                .filter(|(_, u)| **u)
                .for_each(|(v, _)| forget(v));
            let channel = |c: usize| unread.slots[m.incoming[c].slot.index()];
            for (c, (queue, _)) in robot.inbox.iter_mut().enumerate() {
                if channel(c) {
                    queue.iter_mut().for_each(forget);
                }
            }
            if let Some(holding) = &mut robot.holding {
                (holding.pending.iter_mut())
                    .filter(|(c, _)| channel(*c))
                    .for_each(|(_, v)| forget(v));
            }
        }
    }

    /// A copy of the fleet with the instant's deliveries (`batch`) taken,
    /// robot `r` taking its own in `order`; watching nothing.
    fn delivered(&self, r: usize, batch: &[Delivery], order: &[&Rc<Message>]) -> Sim<'p> {
        let now = self.now;
        let mut copy = self.clone();
        copy.races = None;
        copy.message_races = None;
        copy.queue
            .retain(|q| !(q.time() == now && matches!(q.event, Event::Deliver { .. })));
        for (to, message) in batch {
            for &(dst, epoch) in to.iter() {
                let robot = &copy.robots[dst];
                if dst != r && robot.alive && robot.epoch == epoch {
                    copy.deliver(dst, message);
                }
            }
        }
        for message in order {
            copy.deliver(r, message);
        }
        copy
    }
}
