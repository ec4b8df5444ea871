//! Adaptive resource management: the team strategy's battery requirements
//! (`<NonFunctionalInfo><BatteryRequirement><Condition cond="Battery&lt;30">`)
//! as [`BatteryPolicy`]s of one robot's control machine.
//!
//! A policy names sensors and actuators as the strategy does (`Ultrasonic`,
//! `Move`); here each name becomes the tasks of this robot it means: the
//! tasks a `<CheckSensor>` (or `<ExecuteActuator>`) of that name in the same
//! strategy reads from (writes to), and a task of that name (any case).
//! Names that mean no task of this robot are left out: a strategy serves
//! every robot type of the team, and a robot without a camera has nothing to
//! slow down; a name that means no task of any robot of the team, or a
//! policy naming nothing, is warned about (W130, at the strategy's name). The policy reads the robot's own `BATTERY` value, so a robot
//! with policies samples it (its sensor task is added to the graph).

use super::{Builder, convert};
use crate::diag::{Code, Diagnostic};
use crate::refine::program::{BatteryPolicy, Operand};
use crate::sema::Compared;
use crate::strategy::{Strategy, TaskUseKind};
use crate::syntax::ast::ExprKind;

use crate::refine::program::BATTERY_VALUE;

impl Builder<'_, '_> {
    /// The policies of every strategy of the robot's team, in file order.
    pub(super) fn battery_policies(&mut self) -> Vec<BatteryPolicy> {
        let strategies: Vec<&Strategy> = self
            .team_strategies()
            .filter(|s| !s.battery_rules.is_empty())
            .collect();
        if strategies.is_empty() {
            return Vec::new();
        }
        let battery = self.sensor_slot(BATTERY_VALUE, self.team.name_span);
        let mut policies = Vec::new();
        for strategy in strategies {
            let source = self.strategy_name(strategy);
            for rule in &strategy.battery_rules {
                let Some(condition) = &rule.condition else {
                    self.internal_error(
                        self.team.name_span,
                        "a battery requirement has no condition",
                    );
                    continue;
                };
                let Some(expr) = &condition.expr else {
                    let what = format!("the battery condition `{}` did not parse", condition.text);
                    self.internal_error(self.team.name_span, &what);
                    continue;
                };
                // The strategy checker allows `Battery` only (any case), and
                // reads it as a number (strategy::guards).
                let mut resolve = |attr: &crate::syntax::ast::Attr| {
                    if attr.last().as_str().eq_ignore_ascii_case("battery") {
                        Operand::Slot(battery)
                    } else {
                        Operand::Literal(crate::refine::Value::Word(attr.dotted().into()))
                    }
                };
                let mut compare_as = |e: &crate::syntax::ast::Expr| match &e.kind {
                    ExprKind::Compare(a, _, b)
                        if matches!(a.kind, ExprKind::Number(_))
                            || matches!(b.kind, ExprKind::Number(_)) =>
                    {
                        Compared::Numbers
                    }
                    _ => Compared::Words,
                };
                let condition_expr = convert(expr, &mut resolve, &mut compare_as);
                if rule.sensors.is_empty() && rule.actuators.is_empty() {
                    self.names_no_task(
                        strategy,
                        rule.span,
                        format!(
                            "the battery policy `{}` names no sensor and no actuator: it changes nothing",
                            condition.text
                        ),
                    );
                }
                let mut policy = BatteryPolicy {
                    text: condition.text.clone(),
                    condition: condition_expr,
                    source: source.clone(),
                    sensors: Vec::new(),
                    actuators: Vec::new(),
                };
                for (settings, kind) in [
                    (&rule.sensors, TaskUseKind::CheckSensor),
                    (&rule.actuators, TaskUseKind::ExecuteActuator),
                ] {
                    for setting in settings {
                        let (Some(name), Some(level)) = (&setting.name, setting.level) else {
                            continue; // reported by the loader
                        };
                        if level == 0 {
                            let what = format!("`{}` has level 0", name.name);
                            self.internal_error(self.team.name_span, &what);
                            continue;
                        }
                        let tasks = self.tasks_named(strategy, &name.name, kind);
                        if tasks.is_empty() {
                            let what = match kind {
                                TaskUseKind::CheckSensor => "sensor",
                                _ => "actuator",
                            };
                            self.names_no_task(
                                strategy,
                                name.span,
                                format!(
                                    "the battery policy `{}` names {what} `{}`, which is no task of any robot of team `{}`: it changes nothing there",
                                    condition.text, name.name, self.team.name
                                ),
                            );
                        }
                        for task in tasks {
                            let list = match kind {
                                TaskUseKind::CheckSensor => &mut policy.sensors,
                                _ => &mut policy.actuators,
                            };
                            if !list.iter().any(|(t, _)| *t == task) {
                                list.push((task, level));
                            }
                        }
                    }
                }
                policies.push(policy);
            }
        }
        policies
    }

    /// W130 for this robot: kept by `refine` only when every robot of the
    /// team gives it (a name may mean tasks of some robot types only).
    fn names_no_task(&mut self, strategy: &Strategy, span: crate::span::Span, message: String) {
        self.diagnostics.push(Diagnostic::new(
            Code::BatteryPolicyNamesNoTask,
            strategy.file,
            span,
            message,
        ));
    }

    /// The tasks of this robot a policy's sensor (or actuator) `name` means.
    fn tasks_named(&self, strategy: &Strategy, name: &str, kind: TaskUseKind) -> Vec<String> {
        let sensor = kind == TaskUseKind::CheckSensor;
        // The strategy's own uses of that name.
        let uses = strategy
            .values
            .iter()
            .flat_map(|v| &v.tasks)
            .chain(
                strategy
                    .services
                    .iter()
                    .flat_map(|s| &s.actions)
                    .flat_map(|a| &a.tasks),
            )
            .filter(|u| u.kind == kind && u.name.as_ref().is_some_and(|n| n.name == name));
        let mut named: Vec<String> = Vec::new();
        for u in uses {
            for p in &u.parameters {
                let task = if sensor { &p.src_task } else { &p.dst_task };
                if let Some(t) = task
                    && !named.contains(&t.name)
                {
                    named.push(t.name.clone());
                }
            }
        }
        let runs: Vec<&String> = if sensor {
            self.sensors.keys().collect()
        } else {
            self.services.keys().collect()
        };
        runs.into_iter()
            .filter(|t| named.contains(t) || t.eq_ignore_ascii_case(name))
            .cloned()
            .collect()
    }
}
