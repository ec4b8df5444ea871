//! Heartbeats heard without a delivery per robot (issues 34 and 36).
//!
//! Every robot of a team publishes a heartbeat every period and every other
//! robot of the team hears it: a team of 200 robots makes 199 × 200 × 5
//! deliveries a second, 99.9% of a swarm's events, each touching the state
//! of the robot that hears it. On a plain network (one latency, no loss, no
//! link or fault of its own) a heartbeat reaches the whole team at one
//! instant, and a robot whose receive task takes it at once only notes what
//! it said ([`Sim::hear_heartbeat`]). So, when the run makes no `send` or
//! `receive` trace events ([`super::Options::untraced_messages`]), the
//! heartbeat is kept once, as its sender's last one ([`Beat`]), and each
//! robot reads it when it looks ([`Sim::heard`]): a robot has heard its
//! peer's last kept heartbeat when it has been taking heartbeats at once
//! since before that heartbeat came (`Robot::folded_from`) and was not
//! restarted since it was sent (`Robot::epoch_seq`). A robot that cannot
//! take a heartbeat at once (its receive task is held up by a full channel,
//! or its program routes heartbeats otherwise) copies what it had heard into
//! its own table ([`Sim::stop_folding`]) and takes each heartbeat one by one
//! as before, until it can again. The run is the same as with a delivery
//! per robot: the queue's numbers, the event count, the trace
//! (`compiler/src/sim/tests.rs` compares every example both ways).

use super::{Heard, Hearing, Message, Robot, Sim};
use crate::refine::PeerId;

/// A robot's last heartbeat heard by its team at once.
#[derive(Clone, Copy, Debug)]
pub(super) struct Beat {
    /// What it said, `seen` when it came.
    heard: Heard,
    /// The queue number its send took ([`Sim::seq`]): a robot restarted
    /// after it was sent did not hear it (the C's receive task drops what
    /// came for an earlier process).
    sent: u64,
    /// Which folded delivery it was (1, 2, …).
    delivery: u64,
}

/// The heartbeats of a run that folds them.
#[derive(Clone, Debug)]
pub(super) struct Folded {
    /// Per robot: its last heartbeat delivered folded.
    last: Vec<Option<Beat>>,
    /// Folded deliveries so far.
    delivered: u64,
    /// Per team (by its first robot): its live robots that take heartbeats
    /// one by one now, in formation order.
    one_by_one: Vec<Vec<usize>>,
    /// Per team (by its first robot): the highest term a folded heartbeat
    /// said; a robot whose own term is as high learns nothing from them.
    max_term: Vec<i64>,
}

impl Folded {
    pub(super) fn new(robots: usize) -> Folded {
        Folded {
            last: vec![None; robots],
            delivered: 0,
            one_by_one: vec![Vec::new(); robots],
            max_term: vec![0; robots],
        }
    }
}

/// Who a team's robots that hear it alike count alive at one instant
/// (`engine/counted.rs`): the team's robots whose last folded heartbeat
/// came within `lost` ms, and what a robot must have heard folded for its
/// own view to be this one ([`TeamView::seen_alike_by`]).
#[derive(Clone, Debug)]
pub(super) struct TeamView {
    /// Per robot of the team, in order.
    alive: Vec<bool>,
    first: usize,
    /// The oldest folded delivery and send among the team's last
    /// heartbeats (`u64::MAX` when none has one).
    oldest_delivery: u64,
    oldest_send: u64,
    /// Every robot of the team has a last folded heartbeat.
    every_one_beat: bool,
}

impl TeamView {
    pub(super) fn alive(&self, peer: PeerId) -> bool {
        (peer.index().checked_sub(self.first)).is_some_and(|i| self.alive.get(i) == Some(&true))
    }

    /// Whether `robot` counts alive whom this view does, `lost` ms after
    /// each one's last heartbeat, as `Sim::sharing_arms` asks its own view
    /// now: it takes its team's heartbeats folded and heard each one's last
    /// (so [`View::get`] gives that one), or heard none of a robot that sent
    /// none folded and has no table of its own (so it reads as never heard);
    /// and it joined more than `lost` ms ago (so its start counts no one
    /// alive); and it counts itself alive in this view as in its own.
    pub(super) fn seen_alike_by(&self, robot: &Robot, now: i64, lost: i64) -> bool {
        let Some(from) = robot.folded_from else {
            return false;
        };
        self.oldest_delivery > from
            && self.oldest_send > robot.epoch_seq
            && (self.every_one_beat || robot.heard.heard.is_empty())
            && now - robot.started_at > lost
            && self.alive(robot.program.self_peer)
    }
}

impl Folded {
    /// The view of `team` (robot indices, which are its peers' in a run
    /// that folds) at `now`: alive when its last folded heartbeat came
    /// within `lost` ms.
    pub(super) fn team_view(&self, team: std::ops::Range<usize>, now: i64, lost: i64) -> TeamView {
        let mut view = TeamView {
            alive: Vec::with_capacity(team.len()),
            first: team.start,
            oldest_delivery: u64::MAX,
            oldest_send: u64::MAX,
            every_one_beat: true,
        };
        for beat in &self.last[team] {
            match beat {
                Some(beat) => {
                    view.alive.push(now - beat.heard.seen <= lost);
                    view.oldest_delivery = view.oldest_delivery.min(beat.delivery);
                    view.oldest_send = view.oldest_send.min(beat.sent);
                }
                None => {
                    view.alive.push(false);
                    view.every_one_beat = false;
                }
            }
        }
        view
    }

    /// Folded deliveries so far: the view of a team changes only with them
    /// and with time.
    pub(super) fn delivered(&self) -> u64 {
        self.delivered
    }
}

/// Whether `robot` heard `beat` (taking heartbeats at once since `from`).
fn heard_it(robot: &Robot, from: u64, beat: &Beat) -> bool {
    beat.delivery > from && beat.sent > robot.epoch_seq
}

/// What a robot has heard from each peer: its own table, and its peers'
/// last heartbeats where it heard them folded.
pub(super) struct View<'a> {
    hearing: &'a Hearing,
    /// (the peers' last folded heartbeats, the robot, since when it takes
    /// them at once) while it does.
    folded: Option<(&'a [Option<Beat>], &'a Robot<'a>, u64)>,
}

impl View<'_> {
    pub(super) fn get(&self, peer: PeerId) -> Heard {
        self.folded_beat(peer)
            .unwrap_or_else(|| self.hearing.get(peer))
    }

    /// Every peer of the team and every other peer kept, in peer order (as
    /// [`Hearing::iter`]).
    pub(super) fn iter(&self) -> impl Iterator<Item = (PeerId, Heard)> + '_ {
        (self.hearing.iter()).map(|(peer, own)| (peer, self.folded_beat(peer).unwrap_or(own)))
    }

    /// The peer's last folded heartbeat, if the robot heard it.
    fn folded_beat(&self, peer: PeerId) -> Option<Heard> {
        let (last, robot, from) = self.folded?;
        let beat = last.get(peer.index())?.as_ref()?;
        (self.hearing.team.contains(&peer.index()) && heard_it(robot, from, beat))
            .then_some(beat.heard)
    }
}

impl<'p> Sim<'p> {
    /// What robot `r` has heard from its peers' heartbeats, as of now.
    pub(super) fn heard(&self, r: usize) -> View<'_> {
        let robot = &self.robots[r];
        let folded = match (&self.folded, robot.folded_from) {
            (Some(folded), Some(from)) => Some((&folded.last[..], robot, from)),
            _ => None,
        };
        View {
            hearing: &robot.heard,
            folded,
        }
    }

    /// Whether the run folds the heartbeat `message` robot `r` sends to
    /// `targets` (its team: the robots of the team's range, in order).
    pub(super) fn folds(&self, r: usize, targets: &[usize], message: &Message) -> bool {
        let team = self.fleet.team(r);
        self.folded.is_some()
            && message.is_heartbeat(&self.fleet.names[r].alive_key)
            && targets.len() == team.len()
            && targets.first() == Some(&team.start)
            && targets.last() == Some(&(team.end - 1))
    }

    /// Robot `r` (started, restarted, or its receive task free again) takes
    /// its team's heartbeats folded from now on when it can, else one by one.
    pub(super) fn start_folding(&mut self, r: usize) {
        if self.folded.is_none() || !self.robots[r].alive || self.robots[r].folded_from.is_some() {
            return;
        }
        let robot = &self.robots[r];
        let at_once = robot.heartbeats_at_once && robot.holding.is_none();
        let team = self.fleet.team(r).start;
        let folded = self.folded.as_mut().expect("checked above");
        let listed = folded.one_by_one[team].binary_search(&r);
        match (at_once, listed) {
            (true, Ok(i)) => {
                folded.one_by_one[team].remove(i);
                self.robots[r].folded_from = Some(folded.delivered);
            }
            (true, Err(_)) => self.robots[r].folded_from = Some(folded.delivered),
            (false, Err(i)) => folded.one_by_one[team].insert(i, r),
            (false, Ok(_)) => {}
        }
    }

    /// Robot `r` no longer takes its team's heartbeats folded (its receive
    /// task is held up, or it stopped): what it heard so far goes into its
    /// own table, its term with it; while it lives, it takes them one by one.
    pub(super) fn stop_folding(&mut self, r: usize) {
        let Some(folded) = &mut self.folded else {
            return;
        };
        let robot = &mut self.robots[r];
        let team = self.fleet.team(r);
        if let Some(from) = robot.folded_from.take() {
            for p in team.clone().filter(|&p| p != r) {
                if let Some(beat) = &folded.last[p]
                    && heard_it(robot, from, beat)
                {
                    robot.heard.set(PeerId::new(p), beat.heard);
                    robot.term = robot.term.max(beat.heard.term);
                }
            }
        }
        let list = &mut folded.one_by_one[team.start];
        match (robot.alive, list.binary_search(&r)) {
            (true, Err(i)) => list.insert(i, r),
            (false, Ok(i)) => {
                list.remove(i);
            }
            _ => {}
        }
    }

    /// Robot `r`'s term with what its folded heartbeats said: the highest
    /// it has heard, as hearing each one one by one would have made it.
    pub(super) fn fold_term(&mut self, r: usize) {
        let Some(folded) = &self.folded else {
            return;
        };
        let robot = &self.robots[r];
        let team = self.fleet.team(r);
        let Some(from) = robot.folded_from else {
            return;
        };
        if folded.max_term[team.start] <= robot.term {
            return;
        }
        let term = team
            .filter_map(|p| folded.last[p].as_ref())
            .filter(|beat| heard_it(robot, from, beat))
            .fold(robot.term, |term, beat| term.max(beat.heard.term));
        self.robots[r].term = term;
    }

    /// The heartbeat `message`, sent with queue number `sent`, reaches
    /// its team now: kept as its sender's last one for the robots that take
    /// it at once, delivered to each of the others in turn.
    pub(super) fn deliver_folded(&mut self, message: &std::rc::Rc<Message>, sent: u64) {
        let s = message.from.expect("a heartbeat is a robot's");
        let team = self.fleet.team(s);
        let heard = message.heard_at(self.now);
        let folded = self.folded.as_mut().expect("only a folding run folds");
        folded.delivered += 1;
        let beat = Beat {
            heard,
            sent,
            delivery: folded.delivered,
        };
        let before = folded.last[s].replace(beat);
        folded.max_term[team.start] = folded.max_term[team.start].max(heard.term);
        // A sender restarted says a lower term than before: the robots that
        // heard the higher one keep it.
        if let Some(before) = before
            && before.heard.term > heard.term
        {
            for p in team.clone().filter(|&p| p != s) {
                let robot = &mut self.robots[p];
                if let Some(from) = robot.folded_from
                    && heard_it(robot, from, &before)
                {
                    robot.term = robot.term.max(before.heard.term);
                }
            }
        }
        // A copy: taking the heartbeat can free a robot, which leaves the list.
        let mut one_by_one = std::mem::take(&mut self.one_by_one);
        one_by_one.extend_from_slice(&folded.one_by_one[team.start]);
        for &r in &one_by_one {
            // Alive (listed), and the process the heartbeat was sent to.
            if r != s && self.robots[r].epoch_seq < sent {
                self.deliver_one(r, message);
            }
        }
        one_by_one.clear();
        self.one_by_one = one_by_one;
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Options, Sim};
    use crate::refine::RobotProgram;
    use crate::sim::scenario;
    use crate::sim::tests::programs;

    fn repo(path: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(path)
    }

    /// Runs `programs` on the scenario `text` with every message traced,
    /// each heartbeat delivered to each robot, and untraced, heartbeats
    /// folded: the same run but for the messages' trace events. Returns how
    /// many heartbeats were folded.
    fn folded_alike(programs: &[RobotProgram], text: &str, what: &str) -> u64 {
        let scenario = scenario::parse(text, programs).unwrap_or_else(|e| panic!("{e:?}"));
        let traced = Options::default();
        let untraced = Options {
            untraced_messages: true,
            ..Options::default()
        };
        let tracing = Sim::new(programs, &scenario, &traced);
        assert!(tracing.folded.is_none());
        let one_by_one = tracing.run(&traced);
        let folding = Sim::new(programs, &scenario, &untraced);
        let mut counting = folding.clone();
        let folded = folding.run(&untraced);
        let one_by_one_lines = one_by_one.trace_lines();
        let without_messages: Vec<&str> = (one_by_one_lines.lines())
            .filter(|l| !l.contains(r#","event":"send","#) && !l.contains(r#","event":"receive","#))
            .collect();
        let folded_lines = folded.trace_lines();
        assert_eq!(
            without_messages,
            folded_lines.lines().collect::<Vec<_>>(),
            "{what}"
        );
        assert_eq!(
            (one_by_one.end_ms, one_by_one.events, one_by_one.queued),
            (folded.end_ms, folded.events, folded.queued),
            "{what}"
        );
        counting.advance(folded.end_ms, None);
        counting.folded.as_ref().map_or(0, |f| f.delivered)
    }

    /// Elections, counted and nested groups, broadcast events, shared
    /// values (whose owners take heartbeats one by one), with robots killed
    /// and restarted: folded, every run is the one heartbeat by heartbeat.
    #[test]
    fn folded_heartbeats_make_the_same_runs() {
        let cases = [
            (
                "examples/fire/fire.mission",
                "examples/fire/fire.scenario.json",
            ),
            (
                "tests/fixtures/counted_groups/alarm.mission",
                "tests/fixtures/counted_groups/alarm.scenario.json",
            ),
            (
                "tests/fixtures/counted_groups/nested.mission",
                "tests/fixtures/counted_groups/nested.scenario.json",
            ),
            (
                "tests/fixtures/counted_groups/rooms.mission",
                "tests/fixtures/counted_groups/rooms.scenario.json",
            ),
            (
                "tests/fixtures/counted_groups/search.mission",
                "tests/fixtures/counted_groups/search.scenario.json",
            ),
            (
                "tests/fixtures/broadcast/crew.mission",
                "tests/fixtures/broadcast/crew.scenario.json",
            ),
            (
                "tests/fixtures/broadcast/crowd.mission",
                "tests/fixtures/broadcast/crowd.scenario.json",
            ),
            (
                "tests/fixtures/semantics/leader_commands.mission",
                "tests/fixtures/semantics/leader_commands.scenario.json",
            ),
            (
                "tests/fixtures/shared/shared.mission",
                "tests/fixtures/shared/shared.scenario.json",
            ),
            (
                "tests/fixtures/shared_bully/shared.mission",
                "tests/fixtures/shared_bully/shared.scenario.json",
            ),
            (
                "examples/scouting/scouting.mission",
                "tests/fixtures/build/scouting.scenario.json",
            ),
        ];
        let mut folded = 0;
        for (mission, scenario) in cases {
            let text = std::fs::read_to_string(repo(scenario)).unwrap();
            folded += folded_alike(&programs(mission), &text, mission);
        }
        assert!(folded > 500, "{folded} heartbeats folded");
    }

    /// Robots killed and restarted at many moments, the leader among them,
    /// and restarted while heartbeats sent to their earlier process are
    /// still under way: folded, every run is the one heartbeat by heartbeat.
    #[test]
    fn folded_heartbeats_follow_kills_and_restarts() {
        let programs = programs("tests/fixtures/counted_groups/nested.mission");
        for robot in ["tb_0", "tb_1", "tb_3"] {
            for kill in [0, 190, 200, 205, 1000, 1399] {
                for down in [1, 3, 200, 650] {
                    let restart = kill + down;
                    let text = format!(
                        r#"{{"duration": 4000, "network": {{"latency": 20}},
                            "faults": [{{"at": {kill}, "kill": "{robot}"}},
                                       {{"at": {restart}, "restart": "{robot}"}},
                                       {{"at": 2500, "kill": "tb_2"}}]}}"#
                    );
                    folded_alike(&programs, &text, &format!("{robot} {kill} {restart}"));
                }
            }
        }
    }
}
