//! The library task's globally shared values as `codegen/shared.rs`
//! generates them (`docs/shared-information.md`): one robot of the team owns
//! them; a write elsewhere is sent to the owner (`Team.__set.X`), the owner
//! tells the team each value it takes (`Team.__value.X`), and a lost owner
//! (no heartbeat for `protocol::lost_after_ms`) is followed by the first live robot of
//! the owner order, which tells the team the values it last saw.

use super::{Held, Message, Sim};
use crate::refine::{AttributeId, GlobalValue, PeerId};
use smallvec::smallvec;
use std::rc::Rc;

impl Sim<'_> {
    /// The global value of library place `at`, if it is one: (its index in
    /// the ownership, the value).
    fn global_at(&self, r: usize, at: AttributeId) -> Option<(usize, &GlobalValue)> {
        let ownership = self.robots[r]
            .program
            .library
            .as_ref()?
            .ownership
            .as_ref()?;
        ownership
            .global
            .iter()
            .enumerate()
            .find(|(_, g)| g.at == at)
    }

    /// `current_owner`: the owner stays while it lives (this robot, or heard
    /// from within `lost_after_ms`); a lost one is followed by the first
    /// live robot of the owner order. A change is traced; a robot that
    /// becomes the owner tells the team the values it last saw.
    pub(super) fn current_owner(&mut self, r: usize) -> PeerId {
        let robot = &self.robots[r];
        let program = robot.program;
        let Some(ownership) = program.library.as_ref().and_then(|l| l.ownership.as_ref()) else {
            return program.self_peer;
        };
        let lost_after = crate::refine::protocol::lost_after_ms(program.control.heartbeat_ms);
        let heard = self.heard(r);
        let lives = |peer: PeerId| {
            peer == program.self_peer || self.now - heard.get(peer).seen <= lost_after
        };
        let was = robot.owner;
        if lives(was) {
            return was;
        }
        // The first live robot of the order, or by `highest_battery` the
        // live one with the highest level its heartbeat said (the first of
        // equals; unknown counts lowest; its own level for itself).
        let level = |peer: PeerId| {
            if peer == program.self_peer {
                super::own_battery(robot, self.now)
            } else {
                heard.get(peer).battery
            }
            .unwrap_or(-1)
        };
        let mut live = ownership.owners.iter().copied().filter(|&c| lives(c));
        let chosen = if ownership.rule.by_battery() {
            live.fold(None, |best: Option<PeerId>, c| match best {
                Some(b) if level(c) <= level(b) => Some(b),
                _ => Some(c),
            })
        } else {
            live.next()
        };
        let Some(next) = chosen else {
            return was;
        };
        self.robots[r].owner = next;
        self.robots[r].progressed = true;
        let library: Rc<str> = program.library.as_ref().map_or("", |l| &l.name).into();
        let fields = smallvec![
            ("library", library),
            ("owner", program.peer(next).1.as_str().into()),
            ("lost", program.peer(was).1.as_str().into()),
        ];
        self.emit(r, "shared_owner", fields);
        if next == program.self_peer {
            for (k, g) in ownership.global.iter().enumerate() {
                let value = self.robots[r].library[g.at.index()].clone();
                if value.is_some() {
                    self.tell(r, k, next, value);
                }
            }
        }
        next
    }

    /// When the robot would notice that its owner is lost: the firing after
    /// `lost_after_ms` without one (for [`Sim::wake_up`]).
    pub(super) fn owner_lost_at(&self, r: usize) -> Option<i64> {
        let robot = &self.robots[r];
        let program = robot.program;
        program.library.as_ref()?.ownership.as_ref()?;
        (robot.owner != program.self_peer).then(|| {
            self.heard(r).get(robot.owner).seen
                + crate::refine::protocol::lost_after_ms(program.control.heartbeat_ms)
                + 1
        })
    }

    /// `tell`: a write of global value `k` to the owner `to`, or to the team
    /// when this robot owns it.
    fn tell(&mut self, r: usize, k: usize, to: PeerId, value: Held) {
        let program = self.robots[r].program;
        let Some(g) = program
            .library
            .as_ref()
            .and_then(|l| l.ownership.as_ref())
            .map(|o| &o.global[k])
        else {
            return;
        };
        if to == program.self_peer {
            let team = self.fleet.names[r].team.clone();
            self.comm_send(r, team, false, g.value_key.as_str().into(), value);
        } else {
            let owner: Rc<str> = program.peer(to).1.as_str().into();
            self.comm_send(r, owner, false, g.set_key.as_str().into(), value);
        }
    }

    /// The setter of library place `at` after the value is stored: a global
    /// value's write is traced and told to its owner (or the team).
    pub(super) fn shared_set(&mut self, r: usize, at: AttributeId, value: &Held) {
        let Some((k, g)) = self.global_at(r, at) else {
            return;
        };
        let key: Rc<str> = self.robots[r]
            .program
            .library
            .as_ref()
            .map_or("", |l| l.attribute(g.at))
            .into();
        let to = self.current_owner(r);
        let program = self.robots[r].program;
        self.trace.push(super::TraceEvent {
            t: self.now,
            robot: r,
            event: "shared_set",
            fields: smallvec![("key", key), ("owner", program.peer(to).1.as_str().into())],
            value: Some(("value", value.clone())),
            sent_at: None,
        });
        self.tell(r, k, to, value.clone());
    }

    /// `<library>_heard`: a write sent to this robot (taken when it owns the
    /// value, else refused) or the owner's value. False when the message is
    /// none of the protocol's.
    pub(super) fn shared_heard(&mut self, r: usize, message: &Message) -> bool {
        let program = self.robots[r].program;
        let Some(lib) = &program.library else {
            return false;
        };
        let Some(ownership) = &lib.ownership else {
            return false;
        };
        let Some((k, g, set)) = ownership.global.iter().enumerate().find_map(|(k, g)| {
            if *g.set_key == *message.key {
                Some((k, g, true))
            } else if *g.value_key == *message.key {
                Some((k, g, false))
            } else {
                None
            }
        }) else {
            return false;
        };
        let Some(value) = (match &message.value {
            Some(v) => g.kind.coerce(v).map(Some),
            None => Some(None),
        }) else {
            let fields = smallvec![
                ("key", message.key.clone()),
                ("reason", "not a value of its type".into()),
            ];
            self.emit(r, "reject", fields);
            return true;
        };
        let key: Rc<str> = lib.attribute(g.at).into();
        if set {
            let to = self.current_owner(r);
            if to != program.self_peer {
                let fields = smallvec![
                    ("key", message.key.clone()),
                    ("reason", "not the owner".into()),
                ];
                self.emit(r, "reject", fields);
                return true;
            }
            self.robots[r].library[g.at.index()].clone_from(&value);
            self.robots[r].library_written = true;
            self.trace.push(super::TraceEvent {
                t: self.now,
                robot: r,
                event: "shared_set",
                fields: smallvec![
                    ("key", key),
                    ("owner", program.robot.as_str().into()),
                    ("from", message.from_robot.clone()),
                ],
                value: Some(("value", value.clone())),
                sent_at: None,
            });
            self.tell(r, k, to, value);
        } else {
            self.robots[r].library[g.at.index()].clone_from(&value);
            self.robots[r].library_written = true;
            self.trace.push(super::TraceEvent {
                t: self.now,
                robot: r,
                event: "shared_value",
                fields: smallvec![("key", key), ("from", message.from_robot.clone())],
                value: Some(("value", value)),
                sent_at: None,
            });
        }
        // The control task reads it at its next firing.
        self.wake(r);
        true
    }
}
