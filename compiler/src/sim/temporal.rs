//! `always`, `eventually` and `leads_to` judged instant by instant: one
//! meaning for a run of `semo simulate` (the whole trace, [`super::Digest`])
//! and for each step `semo verify` explores (the step's trace, from the
//! state it starts in). An instant is a mission ms at which something
//! happens; a condition is judged on what happens at it (a robot enters a
//! mode, takes a message) and on each robot's mode at its end.

use super::scenario::{Condition, ExpectKind};
use super::trace::TraceEvent;
use crate::fasthash::FastMap;
use std::rc::Rc;

/// What happened at an instant.
#[derive(Clone, Debug)]
enum Happening {
    Entered {
        robot: usize,
        mode: Rc<str>,
    },
    Received {
        robot: usize,
        key: Rc<str>,
        from: Option<Rc<str>>,
    },
}

/// How far one property got: the first instant it broke (`always`), the
/// first at which its condition held (`eventually`; `leads_to`'s second),
/// and the first instant of `leads_to`'s first condition not yet followed
/// by the second.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Status {
    pub broken_at: Option<i64>,
    pub held_at: Option<i64>,
    pub pending_since: Option<i64>,
}

/// The properties of a scenario's `expect`, followed through a trace.
#[derive(Clone)]
pub struct Timeline<'a> {
    /// The robots' indices by name (shared: `semo verify` makes a timeline
    /// per step it explores).
    robots: Rc<FastMap<&'a str, usize>>,
    /// The properties followed: (index in the expectations, the property).
    properties: Vec<(usize, &'a ExpectKind)>,
    /// Per robot: its mode now (none before its first, or once killed).
    modes: Vec<Option<Rc<str>>>,
    now: Option<i64>,
    happened: Vec<Happening>,
    /// Per property followed (same order).
    status: Vec<Status>,
}

impl<'a> Timeline<'a> {
    /// Follows the temporal properties among `expectations` for a run of
    /// `robots` (names in the programs' order), each robot in `modes` at
    /// the start.
    pub fn new(
        robots: Vec<&'a str>,
        expectations: impl IntoIterator<Item = &'a ExpectKind>,
        modes: Vec<Option<Rc<str>>>,
    ) -> Timeline<'a> {
        Timeline::sharing(Timeline::index(robots), expectations, modes)
    }

    /// The robots' indices by name, for [`Timeline::sharing`].
    pub fn index(robots: Vec<&'a str>) -> Rc<FastMap<&'a str, usize>> {
        Rc::new(
            robots
                .into_iter()
                .enumerate()
                .map(|(i, r)| (r, i))
                .collect(),
        )
    }

    /// [`Timeline::new`] with the robots' index made once for many.
    pub fn sharing(
        robots: Rc<FastMap<&'a str, usize>>,
        expectations: impl IntoIterator<Item = &'a ExpectKind>,
        modes: Vec<Option<Rc<str>>>,
    ) -> Timeline<'a> {
        let properties: Vec<(usize, &ExpectKind)> = expectations
            .into_iter()
            .enumerate()
            .filter(|(_, kind)| is_temporal(kind))
            .collect();
        Timeline {
            status: vec![Status::default(); properties.len()],
            robots,
            properties,
            modes,
            now: None,
            happened: Vec::new(),
        }
    }

    /// Whether any property is followed (most scenarios have none).
    pub fn is_empty(&self) -> bool {
        self.properties.is_empty()
    }

    /// The next event of the trace.
    pub fn see(&mut self, e: &TraceEvent) {
        if self.properties.is_empty() || e.robot >= self.modes.len() {
            return;
        }
        if self.now != Some(e.t) {
            self.close_instant();
            self.now = Some(e.t);
        }
        match (e.event, e.field("fault")) {
            ("mode", _) => {
                if let Some((_, mode)) = e.fields.iter().find(|(k, _)| *k == "mode") {
                    self.modes[e.robot] = Some(mode.clone());
                    self.happened.push(Happening::Entered {
                        robot: e.robot,
                        mode: mode.clone(),
                    });
                }
            }
            ("fault", Some("kill" | "restart")) => self.modes[e.robot] = None,
            ("receive", _) => {
                let field = |name: &str| {
                    e.fields
                        .iter()
                        .find(|(k, _)| *k == name)
                        .map(|(_, v)| v.clone())
                };
                if let Some(key) = field("key") {
                    self.happened.push(Happening::Received {
                        robot: e.robot,
                        key,
                        from: field("from_robot"),
                    });
                }
            }
            _ => {}
        }
    }

    /// Judges the instant under way, if any: call at the end of the trace
    /// (or of a step) before reading [`Timeline::status`].
    pub fn close_instant(&mut self) {
        let Some(now) = self.now.take() else {
            return;
        };
        for (status, (_, kind)) in self.status.iter_mut().zip(&self.properties) {
            let holds = |c: &Condition| holds(c, &self.robots, &self.modes, &self.happened);
            match kind {
                ExpectKind::Always(c) if !holds(c) => {
                    status.broken_at.get_or_insert(now);
                }
                ExpectKind::Eventually(c) if holds(c) => {
                    status.held_at.get_or_insert(now);
                }
                ExpectKind::LeadsTo(a, b) => {
                    if holds(a) {
                        status.pending_since.get_or_insert(now);
                    }
                    if holds(b) {
                        status.held_at.get_or_insert(now);
                        status.pending_since = None;
                    }
                }
                _ => {}
            }
        }
        self.happened.clear();
    }

    /// Per property followed: its index among the expectations and how far
    /// it got.
    pub fn status(&self) -> impl Iterator<Item = (usize, Status)> + '_ {
        self.properties
            .iter()
            .zip(&self.status)
            .map(|((x, _), status)| (*x, *status))
    }

    /// How far the property at index `x` of the expectations got.
    pub fn status_of(&self, x: usize) -> Option<Status> {
        self.status().find(|(i, _)| *i == x).map(|(_, s)| s)
    }
}

/// `always`, `eventually` or `leads_to`: judged instant by instant.
pub fn is_temporal(kind: &ExpectKind) -> bool {
    matches!(
        kind,
        ExpectKind::Always(_) | ExpectKind::Eventually(_) | ExpectKind::LeadsTo(..)
    )
}

fn holds(
    c: &Condition,
    robots: &FastMap<&str, usize>,
    modes: &[Option<Rc<str>>],
    happened: &[Happening],
) -> bool {
    let index = |robot: &str| robots.get(robot).copied();
    match c {
        Condition::In { robot, mode } => {
            index(robot).is_some_and(|r| modes[r].as_deref() == Some(mode.as_str()))
        }
        Condition::Enters { robot, mode } => index(robot).is_some_and(|r| {
            happened.iter().any(|h| {
                matches!(h, Happening::Entered { robot, mode: m } if *robot == r && **m == **mode)
            })
        }),
        Condition::Receives { robot, key, from } => index(robot).is_some_and(|r| {
            happened.iter().any(|h| match h {
                Happening::Received {
                    robot,
                    key: k,
                    from: f,
                } => {
                    *robot == r
                        && **k == **key
                        && from
                            .as_deref()
                            .is_none_or(|from| f.as_deref() == Some(from))
                }
                Happening::Entered { .. } => false,
            })
        }),
        Condition::Not(c) => !holds(c, robots, modes, happened),
        Condition::All(all) => all.iter().all(|c| holds(c, robots, modes, happened)),
        Condition::Any(any) => any.iter().any(|c| holds(c, robots, modes, happened)),
    }
}
