//! The resource manager of `control_task.c`: adaptive resource management
//! from the strategy's battery requirements ([`BatteryPolicy`]).
//!
//! At every firing, after reading its inputs, the control task checks each
//! policy's condition on the robot's `BATTERY` value. A policy that starts
//! or stops holding is traced (`battery_policy`); then every task a policy
//! names gets the highest level of the policies that hold (1 when none
//! does), and a change is traced (`period`, `speed`) and handed to the task
//! as its task parameter (`semo_period_level`, `semo_speed_level`): a sensor
//! task then samples every `period × level` (it tells the runtime its next
//! firing, [`sensor_level_hint`]), an actuator task runs at `1 / level` of
//! its speed (simulated: a call takes `level` times as long). The simulator
//! does the same (`sim/engine/battery.rs`).

use super::c;
use super::template::{Template, fill, template};
use crate::refine::{BatteryPolicy, RobotProgram, RoleKind};
use std::fmt::Write;

/// The resource manager's tables, its head and one policy's check.
const POLICIES: Template = template!("battery/policies.c.in", ["policies", "tasks", "levels"]);
const MANAGE_RESOURCES_HEAD: Template = template!("battery/manage_resources_head.c.in", []);
const POLICY: Template = template!(
    "battery/policy.c.in",
    ["text", "source", "condition", "i", "text_string"]
);
/// A levelled sensor task's next firing; a levelled actuator's `speed_scale`.
const SENSOR_LEVEL: Template = template!("battery/sensor_level.c.in", ["param", "period_ms"]);
const SPEED_SCALE: Template = template!("battery/speed_scale.c.in", ["param"]);

/// Every template of the resource manager.
#[cfg(test)]
pub(super) const TEMPLATES: &[Template] = &[
    POLICIES,
    MANAGE_RESOURCES_HEAD,
    POLICY,
    SENSOR_LEVEL,
    SPEED_SCALE,
];

/// The task parameter holding a sensor task's period level.
pub const PERIOD_LEVEL_PARAM: &str = "semo_period_level";
/// The task parameter holding an actuator task's speed level.
pub const SPEED_LEVEL_PARAM: &str = "semo_speed_level";

/// `static void manage_resources(void)` and its state, or nothing for a
/// robot without policies.
pub(super) fn resource_manager(program: &RobotProgram, words: &super::values::Words) -> String {
    let m = &program.control;
    let sensor_period_ms = |task: &str| {
        program
            .tasks
            .iter()
            .find_map(|role| match &role.kind {
                RoleKind::Sensor { period_ms, .. } if role.task == task => Some(*period_ms),
                _ => None,
            })
            .unwrap_or(0)
    };
    if m.battery.is_empty() {
        return String::new();
    }
    let tasks: Vec<(&str, bool)> = m.battery_tasks().collect();
    let mut out = String::new();
    out.push_str(&fill(
        &POLICIES,
        &[
            ("policies", &m.battery.len()),
            ("tasks", &tasks.len().max(1)),
            ("levels", &vec!["1"; tasks.len().max(1)].join(", ")),
        ],
    ));
    out.push_str(MANAGE_RESOURCES_HEAD.text);
    for (i, policy) in m.battery.iter().enumerate() {
        out.push_str(&fill(
            &POLICY,
            &[
                ("text", &c::comment(&policy.text)),
                ("source", &c::comment(&policy.source)),
                ("condition", &words.condition(&policy.condition)),
                ("i", &i),
                ("text_string", &c::string(&policy.text)),
            ],
        ));
    }
    for (k, (task, sensor)) in tasks.iter().enumerate() {
        let levels = levels_of(&m.battery, task, *sensor);
        let _ = writeln!(out, "    level = 1;\n    level_text = \"1\";");
        let mut period_texts = vec![(1u64, sensor_period_ms(task))];
        for (i, level) in &levels {
            let _ = writeln!(
                out,
                "    if (policy_holds[{i}] && level < {level}) {{\n        level = {level};\n        level_text = \"{level}\";\n    }}"
            );
            period_texts.push((*level, sensor_period_ms(task) * *level as i64));
        }
        let (kind, param) = if *sensor {
            ("period", PERIOD_LEVEL_PARAM)
        } else {
            ("speed", SPEED_LEVEL_PARAM)
        };
        let _ = writeln!(
            out,
            "    if (level != task_level[{k}]) {{\n        task_level[{k}] = level;\n        UFTask_SetIntegerParameter({task}, {param}, level);",
            task = c::string(task),
            param = c::string(param),
        );
        if *sensor {
            // The period as text: one constant per level the policies give.
            out.push_str("        const char *period_text = \"\";\n");
            period_texts.sort();
            period_texts.dedup();
            for (level, period) in period_texts {
                let _ = writeln!(
                    out,
                    "        if (level == {level})\n            period_text = \"{period}\";"
                );
            }
            let _ = writeln!(
                out,
                "        semo_trace(\"{kind}\", \"task\", {task}, \"level\", level_text, \"period_ms\", period_text, NULL);",
                task = c::string(task)
            );
        } else {
            let _ = writeln!(
                out,
                "        semo_trace(\"{kind}\", \"task\", {task}, \"level\", level_text, NULL);",
                task = c::string(task)
            );
        }
        out.push_str("    }\n");
    }
    out.push_str("}\n\n");
    out
}

/// (policy index, level) of every policy giving `task` a level.
fn levels_of(policies: &[BatteryPolicy], task: &str, sensor: bool) -> Vec<(usize, u64)> {
    policies
        .iter()
        .enumerate()
        .flat_map(|(i, p)| {
            let list = if sensor { &p.sensors } else { &p.actuators };
            list.iter()
                .filter(|(t, _)| t == task)
                .map(move |(_, level)| (i, *level))
        })
        .collect()
}

/// For the body of a sensor task some policy slows down: after sampling, its
/// next firing is not needed before `period × level` from this one (level 1:
/// the period, as without a policy). `fired` is the firing's start.
pub(super) fn sensor_level_hint(
    program: &RobotProgram,
    task: &str,
    period_ms: i64,
) -> Option<String> {
    let levelled = program.control.battery_tasks().any(|t| t == (task, true));
    levelled.then(|| {
        fill(
            &SENSOR_LEVEL,
            &[
                ("param", &c::string(PERIOD_LEVEL_PARAM)),
                ("period_ms", &period_ms),
            ],
        )
    })
}

/// For a simulated actuator task some policy slows down: `speed_scale()`,
/// the factor its calls' duration is multiplied by (its speed level, at
/// least 1), read when a call starts.
pub(super) fn actuator_speed_scale(program: &RobotProgram, task: &str) -> Option<String> {
    let levelled = program.control.battery_tasks().any(|t| t == (task, false));
    levelled.then(|| fill(&SPEED_SCALE, &[("param", &c::string(SPEED_LEVEL_PARAM))]))
}
