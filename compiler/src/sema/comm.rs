//! Phase 4: communication matching. `receive(T, v)` in team X needs a
//! `send(X, v)` in team T, `subscribe(T, v)` a `publish(X, v)`, and the reverse.
//! The operator console (`USER`) sends and receives anything. A statement naming
//! an unknown team (already reported) may be the counterpart of any team's.

use super::Checker;
use super::ir::*;
use crate::diag::Code;
use crate::fasthash::FastSet;
use crate::syntax::ast::CommKind;

/// The statement that would feed (or drain) `kind`.
fn counterpart(kind: CommKind) -> CommKind {
    match kind {
        CommKind::Send => CommKind::Receive,
        CommKind::Receive => CommKind::Send,
        CommKind::Publish => CommKind::Subscribe,
        CommKind::Subscribe => CommKind::Publish,
    }
}

impl Checker<'_> {
    pub(super) fn check_communication(&mut self) {
        // (kind, running team, other team, value)
        let present: FastSet<(CommKind, TeamId, TeamId, &AttrKey)> = self
            .mission
            .messages
            .iter()
            .filter_map(|m| match m.peer {
                Peer::Team(other) => Some((m.kind, m.team, other, &m.value)),
                Peer::User => None,
            })
            .collect();
        let mut findings = Vec::new();
        for m in &self.mission.messages {
            let Peer::Team(other) = m.peer else { continue };
            if present.contains(&(counterpart(m.kind), other, m.team, &m.value)) {
                continue;
            }
            // A counterpart naming a misspelt team is already reported (E021).
            let misaddressed = self
                .comms_with_unknown_team
                .iter()
                .any(|(kind, team, value)| {
                    *kind == counterpart(m.kind) && *team == other && *value == m.value
                });
            if misaddressed {
                continue;
            }
            let team = self.team(m.team);
            let path = team.service_path(m.service);
            let (me, them) = (&team.name, &self.team(other).name);
            let value = &m.value;
            let (code, message) = match m.kind {
                CommKind::Receive => (
                    Code::ReceiveWithoutSend,
                    format!(
                        "`{path}` receives `{value}` from {them}, but no service of {them} sends it to {me}"
                    ),
                ),
                CommKind::Subscribe => (
                    Code::ReceiveWithoutSend,
                    format!(
                        "`{path}` subscribes to `{value}` from {them}, but no service of {them} publishes it to {me}"
                    ),
                ),
                CommKind::Send => (
                    Code::SendWithoutReceive,
                    format!(
                        "`{path}` sends `{value}` to {them}, but no service of {them} receives it from {me}"
                    ),
                ),
                CommKind::Publish => (
                    Code::SendWithoutReceive,
                    format!(
                        "`{path}` publishes `{value}` to {them}, but no service of {them} subscribes to it from {me}"
                    ),
                ),
            };
            findings.push((code, m.span, message));
        }
        for (code, span, message) in findings {
            self.diagnostics.report(code, span, message);
        }
    }
}
