//! Counted groups' live members, walked once per instant for the robots
//! that see their team alike (issues 34 and 36).
//!
//! A `GroupAllocate` pass, and a `throw E broadcast` written in arms of
//! counted groups, ask which members share the robot's arms
//! ([`members_sharing_arms`]): a walk over the statement's members, each
//! looked up in the robot's view of its team's heartbeats. Every robot of
//! the team walks, so a team of n robots made n walks of n members per
//! pass: 400 robots in nested counted groups took 3.5 times as long as 200,
//! and half of it was these walks.
//!
//! In a run that folds heartbeats (`folded.rs`), most robots of a team hear
//! every one's last heartbeat, and then count alive the same robots
//! ([`TeamView::seen_alike_by`]). For them the walk is made once per
//! instant, statement and team and its answer shared; each robot adds
//! itself where the answer leaves it out, as its own walk would. Any other
//! robot (just restarted, taking heartbeats one by one, not yet past its
//! first two heartbeat periods) walks its own view as before. Debug builds
//! walk both ways and compare, so every test of counted groups checks that
//! the answer is the robot's own.

use super::folded::TeamView;
use super::{EnclosingArm, PeerId, Sim, members_sharing_arms};
use crate::fasthash::FastMap;
use std::hash::{Hash, Hasher};
use std::rc::Rc;

/// The members a robot splits with (as [`members_sharing_arms`] gives
/// them, ascending): a list, and the robot itself where the list, shared
/// by the robots that see their team alike, leaves it out.
pub(super) struct Sharing {
    list: Rc<[PeerId]>,
    added: Option<PeerId>,
}

impl Sharing {
    pub(super) fn len(&self) -> usize {
        self.list.len() + usize::from(self.added.is_some())
    }

    /// The place of `peer` among them, if it is one.
    pub(super) fn position(&self, peer: PeerId) -> Option<usize> {
        let before = self.list.partition_point(|&p| p < peer);
        let added_before = self.added.is_some_and(|a| a < peer);
        if self.list.get(before) == Some(&peer) {
            return Some(before + usize::from(added_before));
        }
        (self.added == Some(peer)).then_some(before)
    }

    pub(super) fn contains(&self, peer: PeerId) -> bool {
        self.position(peer).is_some()
    }

    #[cfg(debug_assertions)]
    fn to_vec(&self) -> Vec<PeerId> {
        let mut all = self.list.to_vec();
        all.extend(self.added);
        all.sort_unstable();
        all
    }
}

/// What the walks of one instant found. A cache only: a copy of the
/// simulator (`semo verify`'s states) starts without one.
#[derive(Default)]
pub(super) struct Counted {
    /// Per team (its first robot): its view at a stamp.
    views: FastMap<usize, (Stamp, TeamView)>,
    /// The statements met, by where their lists are (one per robot's
    /// program), to a number shared by the lists alike.
    statements: FastMap<(usize, usize), usize>,
    /// The numbers by the lists' contents' hash: (number, the lists).
    by_content: FastMap<u64, Vec<(usize, Lists)>>,
    /// Per number: its answer at a stamp, in its team's view.
    answers: Vec<Option<(Stamp, Rc<[PeerId]>)>>,
    /// Per number: its answer with everyone alive.
    everyone: Vec<Option<Rc<[PeerId]>>>,
    /// Members looked at by the walks ([`super::Run::members_walked`]).
    pub(super) walked: u64,
}

impl Clone for Counted {
    fn clone(&self) -> Counted {
        Counted {
            walked: self.walked,
            ..Counted::default()
        }
    }
}

/// (mission ms, folded deliveries so far, the team's `lost` ms): the view
/// of a team changes only with these.
type Stamp = (i64, u64, i64);

/// A statement's enclosing arms and members.
type Lists = (Vec<EnclosingArm>, Vec<PeerId>);

impl Counted {
    /// The number of the statement whose lists these are.
    fn statement(&mut self, within: &[EnclosingArm], members: &[PeerId]) -> usize {
        let at = (within.as_ptr() as usize, members.as_ptr() as usize);
        if let Some(&n) = self.statements.get(&at) {
            return n;
        }
        let mut hasher = crate::fasthash::FastHasher::default();
        for arm in within {
            (&arm.members, &arm.mins, arm.has_others, arm.arm).hash(&mut hasher);
        }
        members.hash(&mut hasher);
        let alike = self.by_content.entry(hasher.finish()).or_default();
        let n = match alike.iter().find(|(_, (w, m))| w == within && m == members) {
            Some(&(n, _)) => n,
            None => {
                let n = self.answers.len();
                self.answers.push(None);
                self.everyone.push(None);
                alike.push((n, (within.to_vec(), members.to_vec())));
                n
            }
        };
        self.statements.insert(at, n);
        n
    }
}

impl Sim<'_> {
    /// Of `members`, robot `r` and the live robots that every enclosing
    /// counted group (`within`) puts in the arms `r` runs
    /// ([`members_sharing_arms`]); alive as `group_of` in the generated C
    /// says: heard within `lost_after_ms` since `r` joined.
    pub(super) fn sharing_arms(
        &mut self,
        r: usize,
        within: &[EnclosingArm],
        members: &[PeerId],
    ) -> Sharing {
        let shared = self.shared_sharing(r, within, members);
        #[cfg(debug_assertions)]
        if let Some(shared) = &shared {
            let own = self.own_sharing_arms(r, within, members);
            debug_assert_eq!(shared.to_vec(), own, "robot {r}'s own view differs");
        }
        shared.unwrap_or_else(|| {
            self.counted.walked += walk_length(within, members);
            Sharing {
                list: self.own_sharing_arms(r, within, members).into(),
                added: None,
            }
        })
    }

    /// [`Sim::sharing_arms`] from `r`'s own view: one walk.
    fn own_sharing_arms(
        &self,
        r: usize,
        within: &[EnclosingArm],
        members: &[PeerId],
    ) -> Vec<PeerId> {
        let robot = &self.robots[r];
        let heard = self.heard(r);
        let me = robot.program.self_peer;
        let lost = crate::refine::protocol::lost_after_ms(robot.program.control.heartbeat_ms);
        let now = self.now;
        let alive =
            |peer: PeerId| peer == me || now - heard.get(peer).seen.max(robot.started_at) <= lost;
        members_sharing_arms(within, members, me, alive)
    }

    /// [`Sim::sharing_arms`] from a view `r` shares: everyone alive in its
    /// first `lost` ms (its start counts as a heartbeat from each), else
    /// its team's view when it sees the team as that view does. One walk
    /// per statement for the first, per instant for the second.
    fn shared_sharing(
        &mut self,
        r: usize,
        within: &[EnclosingArm],
        members: &[PeerId],
    ) -> Option<Sharing> {
        let robot = &self.robots[r];
        let me = robot.program.self_peer;
        let lost = crate::refine::protocol::lost_after_ms(robot.program.control.heartbeat_ms);
        let list = if self.now - robot.started_at <= lost {
            let counted = &mut self.counted;
            let n = counted.statement(within, members);
            if let Some(list) = &counted.everyone[n] {
                list.clone()
            } else {
                counted.walked += walk_length(within, members);
                let list: Rc<[PeerId]> =
                    members_sharing_arms(within, members, nobody(), |_| true).into();
                counted.everyone[n] = Some(list.clone());
                list
            }
        } else {
            self.team_sharing(r, lost, within, members)?
        };
        // The answer counts `r` alive (everyone is, or the view does), so
        // only where the enclosing arms leave it out does it lack `r`.
        let added =
            (list.binary_search(&me).is_err() && members.binary_search(&me).is_ok()).then_some(me);
        Some(Sharing { list, added })
    }

    /// The answer of `r`'s team's view, when `r` sees the team as it does.
    fn team_sharing(
        &mut self,
        r: usize,
        lost: i64,
        within: &[EnclosingArm],
        members: &[PeerId],
    ) -> Option<Rc<[PeerId]>> {
        let folded = self.folded.as_ref()?;
        let team = self.fleet.team(r);
        let in_team = |list: &[PeerId]| {
            list.first().is_none_or(|p| team.contains(&p.index()))
                && list.last().is_none_or(|p| team.contains(&p.index()))
        };
        if !in_team(members) || !within.iter().all(|arm| in_team(&arm.members)) {
            return None;
        }
        let stamp = (self.now, folded.delivered(), lost);
        let counted = &mut self.counted;
        let (at, view) = counted
            .views
            .entry(team.start)
            .or_insert_with(|| (stamp, folded.team_view(team.clone(), stamp.0, lost)));
        if *at != stamp {
            *view = folded.team_view(team.clone(), stamp.0, lost);
            *at = stamp;
        }
        if !view.seen_alike_by(&self.robots[r], self.now, lost) {
            return None;
        }
        let n = counted.statement(within, members);
        if let Some((at, list)) = &counted.answers[n]
            && *at == stamp
        {
            return Some(list.clone());
        }
        counted.walked += walk_length(within, members);
        let view = &counted.views[&team.start].1;
        let list: Rc<[PeerId]> =
            members_sharing_arms(within, members, nobody(), |p| view.alive(p)).into();
        counted.answers[n] = Some((stamp, list.clone()));
        Some(list)
    }
}

/// No robot: the shared walks are nobody's own (the robot asking is added
/// to their answer where it lacks it).
fn nobody() -> PeerId {
    PeerId::new(u32::MAX as usize)
}

/// The members a walk of [`members_sharing_arms`] looks at.
fn walk_length(within: &[EnclosingArm], members: &[PeerId]) -> u64 {
    (within.iter().map(|arm| arm.members.len()).sum::<usize>() + members.len()) as u64
}
