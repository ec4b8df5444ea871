//! Expectations of a scenario, judged on a run's trace.

use super::engine::Run;
use super::scenario::{ExpectKind, Expectation};
use super::temporal::Timeline;
use super::trace::TraceEvent;
use crate::fasthash::FastMap;
use std::rc::Rc;

/// One expectation and whether the run met it, with the evidence.
#[derive(Clone, Debug)]
pub struct Verdict {
    pub expectation: Expectation,
    pub met: bool,
    /// What the run showed: when the mode was entered, the robot's last
    /// mode, the messages received, ...
    pub why: String,
}

/// The modes a robot entered, with their times.
pub fn modes(run: &Run, robot: usize) -> Vec<(i64, &str)> {
    run.trace
        .iter()
        .filter(|e| e.robot == robot && e.event == "mode")
        .filter_map(|e| Some((e.t, e.field("mode")?)))
        .collect()
}

/// Every expectation judged on the run, in order: the one judgement of a
/// simulated run (`semo simulate`) and a recorded one (`semo replay`,
/// [`super::replay`]), on the run's [`Digest`].
pub fn judge(run: &Run, expectations: &[Expectation]) -> Vec<Verdict> {
    Digest::of(run, expectations).verdicts()
}

/// What the summary and the expectations read of a run, gathered from its
/// trace one event at a time ([`Digest::see`]), so that a run written
/// straight to a file is judged without keeping its trace: per robot its
/// modes and its last word, and per `receives` expectation the first
/// `receive` it names. Its size follows the robots, their modes and the
/// expectations, not the trace.
pub struct Digest<'a> {
    robots: &'a [(String, String)],
    expectations: &'a [Expectation],
    robot_of: FastMap<&'a str, usize>,
    /// Per robot, the modes it entered with their times.
    modes: Vec<Vec<(i64, Rc<str>)>>,
    /// Per robot, its latest start, finish or kill.
    words: Vec<Option<Word>>,
    /// Per robot, the time of its latest trace line.
    last_line: Vec<Option<i64>>,
    /// Per robot, the `receives` expectations naming it.
    receivers: Vec<Vec<usize>>,
    /// Per expectation, the first receive it names: (time, value JSON).
    received: Vec<Option<(i64, String)>>,
    /// The `always`, `eventually` and `leads_to` expectations, instant by
    /// instant.
    timeline: Timeline<'a>,
}

/// A robot's last word in the summary.
#[derive(Clone, Copy)]
enum Word {
    Finished(i64),
    Killed(i64),
    Running,
}

impl<'a> Digest<'a> {
    /// An empty digest of a run of `robots` judged on `expectations`.
    pub fn new(robots: &'a [(String, String)], expectations: &'a [Expectation]) -> Digest<'a> {
        let robot_of: FastMap<&str, usize> = robots
            .iter()
            .enumerate()
            .map(|(i, (_, r))| (r.as_str(), i))
            .collect();
        let mut receivers = vec![Vec::new(); robots.len()];
        for (x, expectation) in expectations.iter().enumerate() {
            if let ExpectKind::Receives { robot, .. } = &expectation.kind
                && let Some(&r) = robot_of.get(robot.as_str())
            {
                receivers[r].push(x);
            }
        }
        let timeline = Timeline::new(
            robots.iter().map(|(_, r)| r.as_str()).collect(),
            expectations.iter().map(|e| &e.kind),
            vec![None; robots.len()],
        );
        Digest {
            timeline,
            robots,
            expectations,
            robot_of,
            modes: vec![Vec::new(); robots.len()],
            words: vec![None; robots.len()],
            last_line: vec![None; robots.len()],
            receivers,
            received: vec![None; expectations.len()],
        }
    }

    /// The digest of a whole run's trace.
    pub fn of(run: &'a Run, expectations: &'a [Expectation]) -> Digest<'a> {
        let mut digest = Digest::new(&run.robots, expectations);
        for e in &run.trace {
            digest.see(e);
        }
        digest
    }

    /// The next event of the trace.
    pub fn see(&mut self, e: &TraceEvent) {
        let r = e.robot;
        if r >= self.robots.len() {
            return;
        }
        self.last_line[r] = Some(e.t);
        self.timeline.see(e);
        // By the event's name first: most events are none of these, and
        // looking for a `fault` field in each cost a search of its fields.
        match e.event {
            "mode" => {
                if let Some((_, mode)) = e.fields.iter().find(|(k, _)| *k == "mode") {
                    self.modes[r].push((e.t, mode.clone()));
                }
            }
            "receive" => self.receive(e),
            "finish" => self.words[r] = Some(Word::Finished(e.t)),
            "fault" if e.field("fault") == Some("kill") => {
                self.words[r] = Some(Word::Killed(e.t));
            }
            "start" => self.words[r] = Some(Word::Running),
            _ => {}
        }
    }

    /// A `receive`: the first that each expectation on its robot names.
    fn receive(&mut self, e: &TraceEvent) {
        let Some(key) = e.field("key") else {
            return;
        };
        for &x in &self.receivers[e.robot] {
            let ExpectKind::Receives {
                key: wanted, from, ..
            } = &self.expectations[x].kind
            else {
                continue;
            };
            let sender = from.as_deref();
            if self.received[x].is_none()
                && wanted == key
                && sender.is_none_or(|f| e.field("from_robot") == Some(f))
            {
                self.received[x] = Some((e.t, e.value_json()));
            }
        }
    }

    /// Each robot's modes in order, with their times, indexed by robot.
    pub fn modes(&self) -> &[Vec<(i64, Rc<str>)>] {
        &self.modes
    }

    /// Each robot's last word, indexed by robot, for a run that ended at
    /// `end_ms`: finished, killed, still running, or (a recorded run) no
    /// trace line at all.
    pub fn last_words(&self, end_ms: i64) -> Vec<String> {
        self.words
            .iter()
            .zip(&self.last_line)
            .map(|(word, last)| match (word, last) {
                (Some(Word::Finished(t)), _) => format!("finished at {t} ms"),
                (Some(Word::Killed(t)), _) => format!("killed at {t} ms"),
                (Some(Word::Running), _) => format!("running at {end_ms} ms"),
                (None, Some(t)) => format!("last line at {t} ms"),
                (None, None) => "no trace line".to_string(),
            })
            .collect()
    }

    /// Every expectation judged, in order.
    pub fn verdicts(&self) -> Vec<Verdict> {
        // The last instant, judged on a copy: the digest may see more.
        let mut timeline = self.timeline.clone();
        timeline.close_instant();
        self.expectations
            .iter()
            .enumerate()
            .map(|(x, expectation)| {
                let (met, why) = match timeline.status_of(x) {
                    Some(status) => temporal_verdict(&expectation.kind, status),
                    None => self.judge_one(x, &expectation.kind),
                };
                Verdict {
                    expectation: expectation.clone(),
                    met,
                    why,
                }
            })
            .collect()
    }

    fn judge_one(&self, x: usize, kind: &ExpectKind) -> (bool, String) {
        let robot_index = |robot: &str| self.robot_of.get(robot).copied();
        let entered = |r: usize, mode: &str| {
            self.modes[r]
                .iter()
                .find(|(_, m)| **m == *mode)
                .map(|(t, _)| *t)
        };
        match kind {
            ExpectKind::Enters {
                robot,
                mode,
                before,
            } => {
                let Some(r) = robot_index(robot) else {
                    return (false, format!("no robot {robot}"));
                };
                match entered(r, mode) {
                    Some(t) if before.is_none_or(|b| t <= b) => {
                        (true, format!("entered at {t} ms"))
                    }
                    Some(t) => (false, format!("entered only at {t} ms")),
                    None => (false, "never entered".into()),
                }
            }
            ExpectKind::NeverEnters { robot, mode } => {
                let Some(r) = robot_index(robot) else {
                    return (false, format!("no robot {robot}"));
                };
                match entered(r, mode) {
                    Some(t) => (false, format!("entered at {t} ms")),
                    None => (true, "never entered".into()),
                }
            }
            ExpectKind::Receives { robot, before, .. } => {
                if robot_index(robot).is_none() {
                    return (false, format!("no robot {robot}"));
                }
                match &self.received[x] {
                    Some((t, value)) if before.is_none_or(|b| *t <= b) => {
                        (true, format!("received at {t} ms: {value}"))
                    }
                    Some((t, _)) => (false, format!("received only at {t} ms")),
                    None => (false, "never received".into()),
                }
            }
            ExpectKind::Always(_) | ExpectKind::Eventually(_) | ExpectKind::LeadsTo(..) => {
                unreachable!("judged by the timeline")
            }
            ExpectKind::AllEndIn { mode } => {
                let mut wrong = Vec::new();
                for ((_, robot), modes) in self.robots.iter().zip(&self.modes) {
                    let last = modes.last().map(|(_, m)| &**m);
                    if last != Some(mode.as_str()) {
                        wrong.push(format!("{robot} ends in {}", last.unwrap_or("no mode")));
                    }
                }
                if wrong.is_empty() {
                    (true, format!("every robot ends in {mode}"))
                } else {
                    (false, wrong.join(", "))
                }
            }
        }
    }
}

/// A property's verdict on one run, from how far it got.
pub fn temporal_verdict(kind: &ExpectKind, status: super::temporal::Status) -> (bool, String) {
    match (kind, status.broken_at, status.held_at, status.pending_since) {
        (ExpectKind::Always(_), Some(t), _, _) => (false, format!("broken at {t} ms")),
        (ExpectKind::Always(_), None, _, _) => (true, "held at every instant".into()),
        (ExpectKind::Eventually(_), _, Some(t), _) => (true, format!("held at {t} ms")),
        (ExpectKind::Eventually(_), _, None, _) => (false, "never held".into()),
        (_, _, _, Some(t)) => (
            false,
            format!("the first condition held at {t} ms, and the second never after"),
        ),
        (_, _, _, None) => (
            true,
            "the first condition was followed by the second each time".into(),
        ),
    }
}
