//! The user's properties, checked over every behaviour: a scenario's
//! `expect` (`docs/scenario-and-trace.md`) read as `always`, `eventually`
//! and `leads_to` ([`crate::sim::temporal`], the meaning `semo simulate`
//! gives them on one run), judged on the search's state graph.
//!
//! Each step the search explores is judged instant by instant, from the
//! state it starts in, into a label per property (`Label`). Then:
//!
//! - `always C` is broken by a step with an instant where C does not hold:
//!   a witness, found bounded or not.
//! - `eventually C` is broken by a behaviour that never reaches an instant
//!   where C holds: from a start, a path of steps without C that ends (every
//!   robot finished or killed) or goes round a cycle. Judged only when the
//!   search is exhaustive (else some behaviour was not followed to its end).
//! - `A leads_to B` is broken by a step that leaves an A unanswered by a B,
//!   from whose end such a path without B starts; exhaustive only, too.
//!
//! A broken property's counterexample is the way to the step (and on along
//! the path without the awaited condition), as a scenario whose `expect`
//! holds the property, so `semo simulate` replays it and finds it broken.

use super::{Choice, Counterexample};
use crate::sim::scenario::{Condition, ExpectKind, Expectation, ScenarioError};

/// At most this many properties in one search: each takes two bits of a
/// step's label.
pub const MAX_PROPERTIES: usize = 32;

/// A property of the user's, as written and as judged.
#[derive(Clone, Debug)]
pub struct Property {
    pub expectation: Expectation,
    /// The temporal form judged: `enters` is `eventually` its condition,
    /// `never_enters` `always not` it, `receives` `eventually` it.
    pub judged: ExpectKind,
}

/// What became of a property.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// It holds in every behaviour explored: a proof when the search was
    /// exhaustive, else only as far as it looked (`always`).
    Holds { proof: bool },
    /// A behaviour breaks it; `way` replays it.
    Broken { way: Counterexample, why: String },
    /// A bounded search proves nothing of `eventually` or `leads_to`.
    NotJudged,
}

impl Outcome {
    /// The verdict's word: `holds`, `broken` or `not judged`.
    pub fn verdict(&self) -> &'static str {
        match self {
            Outcome::Holds { .. } => "holds",
            Outcome::Broken { .. } => "broken",
            Outcome::NotJudged => "not judged",
        }
    }

    /// The verdict for people, without the way to it.
    pub fn said(&self) -> String {
        match self {
            Outcome::Holds { proof: true } => "holds in every behaviour".to_string(),
            Outcome::Holds { proof: false } => {
                "holds as far as the search looked (bounded)".to_string()
            }
            Outcome::NotJudged => {
                "not judged: the search was bounded, and only an exhaustive one proves it"
                    .to_string()
            }
            Outcome::Broken { why, .. } => format!("broken: {why}"),
        }
    }
}

/// The properties of a scenario's expectations, each in the form judged
/// over every behaviour; one that only a single run can judge (a deadline,
/// `all_end_in`) is refused at its position.
pub fn properties_of(expect: &[Expectation]) -> Result<Vec<Property>, ScenarioError> {
    let refuse = |at: usize, message: &str| ScenarioError {
        at,
        message: message.to_string(),
        suggestion: None,
    };
    if let Some(extra) = expect.get(MAX_PROPERTIES) {
        return Err(refuse(
            extra.at_offset,
            &format!("`semo verify` checks at most {MAX_PROPERTIES} properties at once"),
        ));
    }
    expect
        .iter()
        .map(|e| {
            let judged = match &e.kind {
                ExpectKind::Enters {
                    before: Some(_), ..
                }
                | ExpectKind::Receives {
                    before: Some(_), ..
                } => {
                    return Err(refuse(
                        e.at_offset,
                        "a deadline (\"before\") is judged on one run by `semo simulate`: `semo verify` merges states met at different times, so over every behaviour write it without one",
                    ));
                }
                ExpectKind::AllEndIn { .. } => {
                    return Err(refuse(
                        e.at_offset,
                        "\"all_end_in\" is judged on one run by `semo simulate`; over every behaviour write {\"eventually\": {\"all\": [{\"robot\": ..., \"in\": ...}, ...]}}",
                    ));
                }
                ExpectKind::Enters { robot, mode, .. } => {
                    ExpectKind::Eventually(Condition::Enters {
                        robot: robot.clone(),
                        mode: mode.clone(),
                    })
                }
                ExpectKind::NeverEnters { robot, mode } => {
                    ExpectKind::Always(Condition::Not(Box::new(Condition::Enters {
                        robot: robot.clone(),
                        mode: mode.clone(),
                    })))
                }
                ExpectKind::Receives {
                    robot, key, from, ..
                } => ExpectKind::Eventually(Condition::Receives {
                    robot: robot.clone(),
                    key: key.clone(),
                    from: from.clone(),
                }),
                temporal => temporal.clone(),
            };
            Ok(Property {
                expectation: e.clone(),
                judged,
            })
        })
        .collect()
}

/// A step's label: per property `p`, bit `2p` says its condition held at
/// an instant of the step (for `always`: did not hold), bit `2p + 1` that a
/// `leads_to`'s first condition is left unanswered at the step's end.
pub type Label = u64;

pub fn held(label: Label, p: usize) -> bool {
    label & (1 << (2 * p)) != 0
}

pub fn pending(label: Label, p: usize) -> bool {
    label & (1 << (2 * p + 1)) != 0
}

/// The label of a step from its properties' statuses (judged from the
/// state the step starts in, nothing pending).
pub fn label_of(
    properties: &[Property],
    status: impl Iterator<Item = (usize, crate::sim::temporal::Status)>,
) -> Label {
    let mut label = 0;
    for (p, status) in status {
        let held = match properties[p].judged {
            ExpectKind::Always(_) => status.broken_at.is_some(),
            _ => status.held_at.is_some(),
        };
        if held {
            label |= 1 << (2 * p);
        }
        if status.pending_since.is_some() {
            label |= 1 << (2 * p + 1);
        }
    }
    label
}

/// The search's state graph as the liveness judgement reads it.
pub struct Steps<'a> {
    /// Per state: (parent, the choice into it, the ms it was made at) of
    /// the breadth-first tree; a start has no parent.
    pub tree: &'a [(Option<u32>, Choice, i64)],
    /// Every step explored: from, to, the choice, its label.
    pub steps: &'a [(u32, u32, Choice, Label)],
    pub step_ms: i64,
}

impl Steps<'_> {
    /// The ms state `n` is at on the tree's way to it.
    fn time(&self, n: u32) -> i64 {
        let (parent, _, at) = &self.tree[n as usize];
        if parent.is_some() {
            at + self.step_ms
        } else {
            0
        }
    }

    /// The way from a start to state `n` along the tree, and the ms `n` is
    /// at on it.
    fn tree_way(&self, n: u32) -> (Vec<(i64, Choice)>, i64) {
        let mut choices = Vec::new();
        let mut here = Some(n);
        while let Some(m) = here {
            let (parent, choice, at) = &self.tree[m as usize];
            choices.push((*at, choice.clone()));
            here = *parent;
        }
        choices.reverse();
        (choices, self.time(n))
    }

    /// Per state: it can go on for ever, or end, without a step whose bit
    /// `held` of property `p` is set; and from each such state the next
    /// step of a shortest way to a state that ends or goes round.
    fn can_avoid(&self, p: usize) -> (Vec<bool>, Vec<Option<usize>>) {
        let n = self.tree.len();
        let avoiding = |label: Label| !held(label, p);
        let mut has_step = vec![false; n];
        for (from, _, _, _) in self.steps {
            has_step[*from as usize] = true;
        }
        let edges = self
            .steps
            .iter()
            .filter(|s| avoiding(s.3))
            .map(|s| (s.0 as usize, s.1 as usize));
        let (component, count) = crate::digraph::components(n, edges);
        let mut size = vec![0usize; count];
        for &c in &component {
            size[c] += 1;
        }
        // Ends (no step at all) and states on a cycle of avoiding steps.
        let mut avoid: Vec<bool> = (0..n).map(|s| !has_step[s]).collect();
        for (from, to, _, label) in self.steps {
            let (from, to) = (*from as usize, *to as usize);
            if avoiding(*label)
                && component[from] == component[to]
                && (size[component[from]] > 1 || from == to)
            {
                avoid[from] = true;
            }
        }
        // Backwards over avoiding steps, breadth first from those: each
        // state's next step is on a shortest way there.
        let mut into: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (i, s) in self.steps.iter().enumerate() {
            if avoiding(s.3) {
                into[s.1 as usize].push(i);
            }
        }
        let mut next = vec![None; n];
        let mut queue: std::collections::VecDeque<usize> = (0..n).filter(|&s| avoid[s]).collect();
        while let Some(s) = queue.pop_front() {
            for &i in &into[s] {
                let from = self.steps[i].0 as usize;
                if !avoid[from] {
                    avoid[from] = true;
                    next[from] = Some(i);
                    queue.push_back(from);
                }
            }
        }
        (avoid, next)
    }

    /// The way of `prefix` (ending at ms `time` in state `at`) followed on
    /// along `next` until a state that ends or goes round.
    fn follow(
        &self,
        mut choices: Vec<(i64, Choice)>,
        mut time: i64,
        mut at: usize,
        next: &[Option<usize>],
    ) -> Counterexample {
        while let Some(i) = next[at] {
            let (_, to, choice, _) = &self.steps[i];
            choices.push((time, choice.clone()));
            time += self.step_ms;
            at = *to as usize;
        }
        Counterexample {
            choices,
            end_ms: time + self.step_ms,
            step_ms: self.step_ms,
        }
    }

    /// `eventually` (property `p`): a start from which it can be avoided.
    pub fn eventually_broken(&self, p: usize) -> Option<Counterexample> {
        let (avoid, next) = self.can_avoid(p);
        let start = (0..self.tree.len()).find(|&s| self.tree[s].0.is_none() && avoid[s])?;
        let (choices, time) = self.tree_way(start as u32);
        Some(self.follow(choices, time, start, &next))
    }

    /// `leads_to` (property `p`): a step that leaves its first condition
    /// unanswered into a state from which the second can be avoided.
    pub fn leads_to_broken(&self, p: usize) -> Option<Counterexample> {
        let (avoid, next) = self.can_avoid(p);
        let (from, to, choice, _) = self
            .steps
            .iter()
            .filter(|s| pending(s.3, p) && avoid[s.1 as usize])
            .min_by_key(|s| self.time(s.0))?;
        let (mut choices, time) = self.tree_way(*from);
        choices.push((time, choice.clone()));
        Some(self.follow(choices, time + self.step_ms, *to as usize, &next))
    }
}
