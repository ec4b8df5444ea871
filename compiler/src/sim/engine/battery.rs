//! Adaptive resource management in the simulator, as `codegen/battery.rs`
//! generates it: after reading its inputs, a control firing checks every
//! battery policy, traces those that start or stop holding, and gives each
//! task a policy names the highest level of the policies that hold (1 when
//! none does), tracing a change. A sensor task at period level L samples
//! every `L × SENSOR_PERIOD_MS` (the level it has when it samples sets the
//! time of its next sample, as the generated task's `semo_next_firing`); an
//! actuator task at speed level L takes L times the scenario's time for a
//! call (the level when the call starts).

use super::{Robot, SENSOR_PERIOD_MS, Sim};
use smallvec::smallvec;
use std::rc::Rc;

/// When a sensor task a policy names samples: the last sample, the next
/// one, and its level.
#[derive(Clone, Debug)]
pub(super) struct Sampling {
    pub task: String,
    pub last: i64,
    pub next: i64,
    pub level: u64,
}

/// The battery state of a robot's run.
#[derive(Clone, Debug, Default)]
pub(super) struct Resources {
    /// Per policy: whether it held at the last firing.
    holds: Vec<bool>,
    /// Per task of `ControlMachine::battery_tasks`: its current level.
    levels: Vec<u64>,
    /// The sensor tasks some policy names.
    sampling: Vec<Sampling>,
}

impl Resources {
    pub(super) fn new(program: &crate::refine::RobotProgram, started_at: i64) -> Resources {
        let m = &program.control;
        Resources {
            holds: vec![false; m.battery.len()],
            levels: vec![1; m.battery_tasks().count()],
            sampling: m
                .battery_tasks()
                .filter(|(_, sensor)| *sensor)
                .map(|(task, _)| Sampling {
                    task: task.to_string(),
                    last: started_at,
                    next: started_at + SENSOR_PERIOD_MS,
                    level: 1,
                })
                .collect(),
        }
    }

    /// The state as numbers, its times relative to `now` (`explore.rs`).
    pub(super) fn relative(&self, now: i64) -> Vec<i64> {
        let mut out: Vec<i64> = self.holds.iter().map(|h| *h as i64).collect();
        out.extend(self.levels.iter().map(|l| *l as i64));
        for s in &self.sampling {
            out.extend([s.last - now, s.next - now, s.level as i64]);
        }
        out
    }

    /// About the bytes it holds (`Sim::approx_bytes`).
    pub(super) fn approx_bytes(&self) -> usize {
        self.holds.len()
            + self.levels.len() * 8
            + self
                .sampling
                .iter()
                .map(|s| std::mem::size_of::<Sampling>() + s.task.len())
                .sum::<usize>()
    }

    /// The sensor task's sampling, when a policy names it.
    fn sampling(&self, task: &str) -> Option<&Sampling> {
        self.sampling.iter().find(|s| s.task == task)
    }

    /// Moves every levelled sensor task's samples up to `now`.
    pub(super) fn advance(&mut self, now: i64) {
        for s in &mut self.sampling {
            while s.next <= now {
                s.last = s.next;
                s.next += s.level as i64 * SENSOR_PERIOD_MS;
            }
        }
    }
}

impl Robot<'_> {
    /// When sensor task `task` last sampled by `now` (at or before it).
    pub(super) fn sampled_at(&self, task: &str, now: i64) -> i64 {
        match self.resources.sampling(task) {
            Some(s) => s.last,
            None => self.started_at + (now - self.started_at) / SENSOR_PERIOD_MS * SENSOR_PERIOD_MS,
        }
    }

    /// The first sample of sensor task `task` at or after `t` (which is
    /// after its last sample).
    pub(super) fn sample_at_or_after(&self, task: &str, t: i64) -> i64 {
        match self.resources.sampling(task) {
            Some(s) if t <= s.next => s.next,
            Some(s) => {
                let step = s.level as i64 * SENSOR_PERIOD_MS;
                s.next + (t - s.next + step - 1) / step * step
            }
            None => {
                let periods = (t - self.started_at + SENSOR_PERIOD_MS - 1) / SENSOR_PERIOD_MS;
                self.started_at + periods * SENSOR_PERIOD_MS
            }
        }
    }

    /// How many times the scenario's time a call of `task` takes now (its
    /// speed level, 1 without a policy).
    pub(super) fn speed_scale(&self, task: &str) -> i64 {
        let m = &self.program.control;
        m.battery_tasks()
            .position(|t| t == (task, false))
            .map_or(1, |k| self.resources.levels[k] as i64)
    }
}

impl Sim<'_> {
    /// `manage_resources` of the generated control task.
    pub(super) fn manage_resources(&mut self, r: usize) {
        let program = self.robots[r].program;
        let m = &program.control;
        if m.battery.is_empty() {
            return;
        }
        for (i, policy) in m.battery.iter().enumerate() {
            let holds = self.eval(r, &policy.condition);
            if holds != self.robots[r].resources.holds[i] {
                self.robots[r].resources.holds[i] = holds;
                self.robots[r].progressed = true;
                let fields = smallvec![
                    ("condition", Rc::from(policy.text.as_str())),
                    ("holds", Rc::from(if holds { "true" } else { "false" })),
                ];
                self.emit(r, "battery_policy", fields);
            }
        }
        for (k, (task, sensor)) in m.battery_tasks().enumerate() {
            let level = m.battery_level(task, sensor, &self.robots[r].resources.holds);
            if level == self.robots[r].resources.levels[k] {
                continue;
            }
            let resources = &mut self.robots[r].resources;
            resources.levels[k] = level;
            let mut fields = smallvec![
                ("task", Rc::from(task)),
                ("level", Rc::from(level.to_string().as_str())),
            ];
            if sensor {
                if let Some(s) = resources.sampling.iter_mut().find(|s| s.task == task) {
                    s.level = level;
                }
                let period = SENSOR_PERIOD_MS * level as i64;
                fields.push(("period_ms", Rc::from(period.to_string().as_str())));
            }
            self.emit(r, if sensor { "period" } else { "speed" }, fields);
        }
    }
}
