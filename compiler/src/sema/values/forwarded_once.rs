//! W023: a received value sent on once each time its mode starts, while
//! another plan of the mode keeps receiving it.
//!
//! A `send` or `publish` of a value the robot holds (no `= ...`), written in
//! a service without `repeat` and outside any `loop`, runs at most once each
//! time the service starts, that is each time a mode that sets it starts.
//! When the value is another team's or the operator's (what the robot
//! received of it) and, in every mode that runs the service, another plan's
//! service repeated for ever (`repeat()` or `repeat(P)`, no condition, no
//! `set` timeout) receives or subscribes to it on the same robots, every
//! value taken after the send stays on the robot: no other statement of the
//! mode sends it to the same team (else it is not reported). This is the
//! forwarding service of a leader or a relay that forwards the first
//! command only.
//!
//! Cost: the checks of each send against its modes are bounded by a budget
//! proportional to the mission's size; past it nothing more is reported.

use super::timeline::Timeline;
use super::{Finding, some};
use crate::diag::Code;
use crate::fasthash::{FastMap, FastSet};
use crate::sema::Checker;
use crate::sema::ir::{AttrKey, Message, ModeId, Peer, RobotId, ServiceId, TeamId};
use crate::span::Span;
use crate::syntax::ast::{self, StmtKind};

/// Work units the checks may take per message and mode `set` of the mission.
const WORK_PER_ITEM: usize = 32;

/// The messages a send is checked against, by what they carry.
struct Traffic<'m> {
    /// Receives and subscribes in services repeated for ever, by (team, value).
    repeated: FastMap<(TeamId, &'m AttrKey), Vec<usize>>,
    /// Sends and publishes, by (team, peer, value).
    sent: FastMap<(TeamId, Peer, &'m AttrKey), Vec<usize>>,
}

impl<'a> Checker<'a> {
    pub(super) fn forwarded_once(&self, timeline: &Timeline) -> Vec<Finding> {
        let once = self.sends_once(timeline);
        if once.is_empty() {
            return Vec::new();
        }
        // Of another team's or the operator's value: what the robot
        // received (its own values are readings or variables it sets).
        let candidates: Vec<usize> = (self.mission.messages.iter().enumerate())
            .filter(|(_, m)| m.kind.is_outgoing() && once.contains(&m.span))
            .filter(|(_, m)| m.value.owner != self.team(m.team).name)
            .map(|(i, _)| i)
            .collect();
        if candidates.is_empty() {
            return Vec::new();
        }
        let traffic = self.traffic();
        let sets: usize = (self.mission.teams.iter())
            .flat_map(|t| &t.modes)
            .map(|m| m.sets.len())
            .sum();
        let mut budget = WORK_PER_ITEM * (self.mission.messages.len() + sets + 1);
        let mut findings = Vec::new();
        for i in candidates {
            let m = &self.mission.messages[i];
            let modes = timeline.modes(m.team, m.service);
            let mut receivers = Vec::with_capacity(modes.len());
            for &mode in modes {
                match self.keeps_receiving(i, mode, &traffic, &mut budget) {
                    Some(receiver) => receivers.push(receiver),
                    None => break,
                }
            }
            if budget == 0 {
                break;
            }
            if !modes.is_empty() && receivers.len() == modes.len() {
                findings.push(self.forwarded(m, modes, &receivers));
            }
        }
        findings
    }

    /// The ranges of the sends that run at most once each time their
    /// service starts: written in a service without `repeat`, outside loops
    /// and functions, of a value the robot holds.
    fn sends_once(&self, timeline: &Timeline) -> FastSet<Span> {
        let mut once = FastSet::default();
        for (t, services) in self.service_syntax.iter().enumerate() {
            for (s, syntax) in services.iter().enumerate() {
                if syntax.repeat.is_none() && timeline.runs(TeamId(t as u32), ServiceId::new(s)) {
                    sends_outside_loops(&syntax.body, &mut once);
                }
            }
        }
        once
    }

    fn traffic(&self) -> Traffic<'_> {
        let mut traffic = Traffic {
            repeated: FastMap::default(),
            sent: FastMap::default(),
        };
        for (i, m) in self.mission.messages.iter().enumerate() {
            if m.kind.is_outgoing() {
                traffic
                    .sent
                    .entry((m.team, m.peer, &m.value))
                    .or_default()
                    .push(i);
            } else if self.repeats_for_ever(m.team, m.service) {
                traffic
                    .repeated
                    .entry((m.team, &m.value))
                    .or_default()
                    .push(i);
            }
        }
        traffic
    }

    fn repeats_for_ever(&self, team: TeamId, service: ServiceId) -> bool {
        let syntax = self.service_syntax[team.0 as usize][service.index()];
        syntax
            .repeat
            .as_ref()
            .is_some_and(|r| r.condition.is_none())
    }

    /// A receive of what message `send` sends, by another plan of `mode`
    /// repeated for ever on some of the same robots, when no other
    /// statement of the mode sends the value to the same peer; `None`
    /// otherwise or when the budget runs out.
    fn keeps_receiving(
        &self,
        send: usize,
        mode: ModeId,
        traffic: &Traffic,
        budget: &mut usize,
    ) -> Option<usize> {
        let m = &self.mission.messages[send];
        let sets = &self.team(m.team).mode(mode).sets;
        let mut spend = |n: usize| {
            *budget = budget.saturating_sub(n);
            *budget > 0
        };
        let others = traffic.sent.get(&(m.team, m.peer, &m.value));
        for &o in others.into_iter().flatten() {
            let other = &self.mission.messages[o];
            if !spend(sets.len()) {
                return None;
            }
            if other.span != m.span && sets.iter().any(|s| s.service == Some(other.service)) {
                return None; // also sent on elsewhere in the mode
            }
        }
        let receives = traffic.repeated.get(&(m.team, &m.value))?;
        receives.iter().copied().find(|&r| {
            let receive = &self.mission.messages[r];
            let robots = (&self.message_robots[send], &self.message_robots[r]);
            spend(sets.len() + robots.0.len() + robots.1.len())
                && sets
                    .iter()
                    .any(|s| s.service == Some(receive.service) && s.timeout_ms.is_none())
                && overlap(robots.0, robots.1)
        })
    }

    fn forwarded(&self, m: &Message, modes: &[ModeId], receivers: &[usize]) -> Finding {
        let team = self.team(m.team);
        let path = team.service_path(m.service);
        let names: Vec<&str> = modes
            .iter()
            .map(|&mode| team.mode(mode).name.as_str())
            .collect();
        let first = &self.mission.messages[receivers[0]];
        let verb = if m.kind == ast::CommKind::Publish {
            "published"
        } else {
            "sent"
        };
        let message = format!(
            "`{}` is {verb} on here at most once each time {} {} starts (`{path}` has no `repeat`), but `{}` keeps receiving it there: what comes after this {} is never {verb} on",
            m.value,
            if modes.len() == 1 {
                "mode"
            } else {
                "one of the modes"
            },
            some(&names),
            team.service_path(first.service),
            m.kind.as_str(),
        );
        let related = receivers
            .iter()
            .map(|&r| {
                let r = &self.mission.messages[r];
                (
                    r.span,
                    format!(
                        "`{}` is taken here again at every pass of `{}`",
                        r.value,
                        team.service_path(r.service)
                    ),
                )
            })
            .collect();
        Finding {
            code: Code::ForwardedOnce,
            span: m.span,
            message,
            related,
        }
    }
}

/// Collects the values sent (without `= ...`) by `block`'s sends and
/// publishes outside loops; a function's body is shared by its callers and
/// is not followed.
fn sends_outside_loops(block: &ast::Block, once: &mut FastSet<Span>) {
    for stmt in &block.stmts {
        stmt_sends_outside_loops(stmt, once);
    }
}

fn stmt_sends_outside_loops(stmt: &ast::Stmt, once: &mut FastSet<Span>) {
    match &stmt.kind {
        StmtKind::Comm(comm) if comm.kind.is_outgoing() => {
            let held = comm.items.iter().filter(|i| i.value.is_none());
            once.extend(held.map(|i| i.attr.span));
        }
        StmtKind::If(i) => {
            sends_outside_loops(&i.then_block, once);
            match i.else_branch.as_deref() {
                Some(ast::Else::If(s)) => stmt_sends_outside_loops(s, once),
                Some(ast::Else::Block(b)) => sends_outside_loops(b, once),
                None => {}
            }
        }
        StmtKind::Group(g) => {
            for arm in &g.arms {
                sends_outside_loops(&arm.body, once);
            }
            if let Some(others) = &g.others {
                sends_outside_loops(&others.body, once);
            }
        }
        StmtKind::Comm(_)
        | StmtKind::Loop(_)
        | StmtKind::Throw(_)
        | StmtKind::Call(_)
        | StmtKind::Error => {}
    }
}

/// Whether two sorted lists of robots share one.
fn overlap(a: &[RobotId], b: &[RobotId]) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => return true,
        }
    }
    false
}
