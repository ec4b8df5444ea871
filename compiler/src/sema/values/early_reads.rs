//! W022: a value read once, when the mission starts, before any robot can
//! have sent it.
//!
//! A service without `repeat` that runs only in its team's start mode, a
//! mode no catch leads back to, runs once, from the mission's first instant.
//! What its opening reads (its statements up to the first that may wait: a
//! `receive`, a call, a `loop`, a group statement) is read at that instant
//! and never again. A value of another team (`Other.X`) holds only what the
//! robot received of it; when every `send` and `publish` of it to the
//! reading team is in a service that does not run at the first instant
//! (every mode that sets it is entered later), no robot has sent it by
//! then, whatever the network's latency, so the read gives none. Left out:
//! a value the reading team also sets itself (`Other.X = ...`), or that the
//! operator sends (the scenario's commands come at any instant, the first
//! included).

use super::timeline::Timeline;
use super::{Finding, some};
use crate::diag::Code;
use crate::fasthash::{FastMap, FastSet};
use crate::sema::ir::{AttrKey, ModeId, Peer, ServiceId, Symbol, TeamId};
use crate::sema::{Checker, lookup};
use crate::syntax::ast::{self, Arg, CommKind, Expr, ExprKind, StmtKind};

/// A value read in the opening of a service that starts once, at the
/// mission's first instant.
struct OpeningRead<'a> {
    team: TeamId,
    service: ServiceId,
    start: ModeId,
    attr: &'a ast::Attr,
}

impl<'a> Checker<'a> {
    pub(super) fn early_reads(&self, timeline: &Timeline) -> Vec<Finding> {
        let reads: Vec<(OpeningRead, AttrKey)> = self
            .opening_reads(timeline)
            .into_iter()
            .filter_map(|read| {
                let key = self.received_key(&read)?;
                Some((read, key))
            })
            .collect();
        if reads.is_empty() {
            return Vec::new();
        }
        let senders = self.senders_to_teams();
        let set_in_team: FastSet<(TeamId, &AttrKey)> = self
            .variable_writes
            .iter()
            .filter_map(|w| Some((w.team?, &w.key)))
            .collect();
        // Per (reading team, value): the sends that cannot have reached it
        // at the first instant, or `None` when one may have.
        let mut verdicts: FastMap<(TeamId, &AttrKey), Option<&[usize]>> = FastMap::default();
        let mut reported: FastSet<(TeamId, ServiceId, &AttrKey)> = FastSet::default();
        let mut findings = Vec::new();
        for (read, key) in &reads {
            let late_senders = *verdicts.entry((read.team, key)).or_insert_with(|| {
                if set_in_team.contains(&(read.team, key)) {
                    return None;
                }
                let sends = senders.get(&(read.team, key))?;
                let late = sends.iter().all(|&m| {
                    let m = &self.mission.messages[m];
                    !timeline.runs_at_start(m.team, m.service)
                });
                late.then_some(sends.as_slice())
            });
            let Some(sends) = late_senders else { continue };
            if reported.insert((read.team, read.service, key)) {
                findings.push(self.early_read(read, key, sends, timeline));
            }
        }
        findings
    }

    /// The reads in the openings of the services that start once, at the
    /// mission's first instant.
    fn opening_reads(&self, timeline: &Timeline) -> Vec<OpeningRead<'a>> {
        let mut reads = Vec::new();
        for (t, services) in self.service_syntax.iter().enumerate() {
            let team = TeamId(t as u32);
            for (s, syntax) in services.iter().enumerate() {
                let service = ServiceId::new(s);
                if syntax.repeat.is_some() {
                    continue;
                }
                let Some(start) = timeline.starts_only_at_start(team, service) else {
                    continue;
                };
                let mut attrs = Vec::new();
                self.opening(&syntax.body, &mut attrs);
                reads.extend(attrs.into_iter().map(|attr| OpeningRead {
                    team,
                    service,
                    start,
                    attr,
                }));
            }
        }
        reads
    }

    /// Collects the values that `block`'s statements read before anything
    /// can make the service wait. False when the block may wait: what
    /// follows may run later.
    fn opening(&self, block: &'a ast::Block, reads: &mut Vec<&'a ast::Attr>) -> bool {
        block
            .stmts
            .iter()
            .all(|stmt| self.opening_stmt(stmt, reads))
    }

    fn opening_stmt(&self, stmt: &'a ast::Stmt, reads: &mut Vec<&'a ast::Attr>) -> bool {
        match &stmt.kind {
            StmtKind::Comm(comm) => match comm.kind {
                CommKind::Receive => false,
                // Copies the latest publication that came, if any: no wait.
                CommKind::Subscribe => true,
                CommKind::Send | CommKind::Publish => {
                    for item in &comm.items {
                        match &item.value {
                            Some(value) => attrs_in(value, reads),
                            None => reads.push(&item.attr),
                        }
                    }
                    true
                }
            },
            StmtKind::If(i) => {
                attrs_in(&i.condition, reads);
                let then = self.opening(&i.then_block, reads);
                let otherwise = match i.else_branch.as_deref() {
                    Some(ast::Else::If(s)) => self.opening_stmt(s, reads),
                    Some(ast::Else::Block(b)) => self.opening(b, reads),
                    None => true,
                };
                then && otherwise
            }
            // Whether caught or dropped, what runs after it runs now.
            StmtKind::Throw(_) => true,
            StmtKind::Call(call) => {
                // A built-in call reads its arguments as it starts, then
                // waits. A function's body is shared by its callers, some
                // of which may run it later: not followed.
                if !self.functions_by_name.contains_key(&call.name.name) {
                    for arg in &call.args {
                        if let Arg::Expr(e) = arg {
                            attrs_in(e, reads);
                        }
                    }
                }
                false
            }
            // A loop's condition and body run again later; a group statement
            // may wait for an election or the other members.
            StmtKind::Loop(_) | StmtKind::Group(_) | StmtKind::Error => false,
        }
    }

    /// The key of a read that is a value of another team than the reading
    /// one (what its robots received of it).
    fn received_key(&self, read: &OpeningRead) -> Option<AttrKey> {
        let occurrences = lookup::with_span(&self.mission, read.attr.last().span);
        occurrences.iter().find_map(|o| match &o.symbol {
            Symbol::Value {
                owner: Some(owner),
                name,
            }
            | Symbol::TeamVariable {
                team: Some(owner),
                name,
            } if *owner != read.team => Some(AttrKey {
                owner: self.team(*owner).name.clone(),
                name: name.clone(),
            }),
            _ => None,
        })
    }

    /// The sends and publishes to each team, by (team, value): indices
    /// into the mission's messages.
    fn senders_to_teams(&self) -> FastMap<(TeamId, &AttrKey), Vec<usize>> {
        let mut senders: FastMap<(TeamId, &AttrKey), Vec<usize>> = FastMap::default();
        for (i, m) in self.mission.messages.iter().enumerate() {
            if let (true, Peer::Team(to)) = (m.kind.is_outgoing(), m.peer) {
                senders.entry((to, &m.value)).or_default().push(i);
            }
        }
        senders
    }

    fn early_read(
        &self,
        read: &OpeningRead,
        key: &AttrKey,
        sends: &[usize],
        timeline: &Timeline,
    ) -> Finding {
        let team = self.team(read.team);
        let path = team.service_path(read.service);
        let start = &team.mode(read.start).name;
        let message = format!(
            "`{key}` is read here only when the mission starts, before any robot can have sent it: `{path}` has no `repeat` and runs only in the mode its robots start in ({start}), so this reads none, and never what is sent later"
        );
        let related = sends
            .iter()
            .map(|&m| {
                let m = &self.mission.messages[m];
                (m.span, self.sent_later(m, timeline))
            })
            .collect();
        Finding {
            code: Code::ReadBeforeSent,
            span: read.attr.span,
            message,
            related,
        }
    }

    /// Why a send does not run at the mission's first instant.
    fn sent_later(&self, m: &crate::sema::ir::Message, timeline: &Timeline) -> String {
        let team = self.team(m.team);
        let verb = if m.kind == CommKind::Publish {
            "published"
        } else {
            "sent"
        };
        let modes: Vec<&str> = timeline
            .modes(m.team, m.service)
            .iter()
            .map(|&mode| team.mode(mode).name.as_str())
            .collect();
        if modes.is_empty() {
            return format!(
                "`{}` is {verb} here, in `{}`, which never runs: no mode {}'s robots can be in sets it",
                m.value,
                team.service_path(m.service),
                team.name
            );
        }
        format!(
            "`{}` is {verb} here, only in {} {} of {}, entered after the start",
            m.value,
            if modes.len() == 1 { "mode" } else { "modes" },
            some(&modes),
            team.name
        )
    }
}

/// Collects the values `e` reads.
fn attrs_in<'a>(e: &'a Expr, reads: &mut Vec<&'a ast::Attr>) {
    match &e.kind {
        ExprKind::Or(a, b) | ExprKind::And(a, b) | ExprKind::Compare(a, _, b) => {
            attrs_in(a, reads);
            attrs_in(b, reads);
        }
        ExprKind::Not(a) => attrs_in(a, reads),
        ExprKind::Attr(attr) => reads.push(attr),
        ExprKind::Str(_)
        | ExprKind::Number(_)
        | ExprKind::Period(_)
        | ExprKind::Bool(_)
        | ExprKind::Error => {}
    }
}
