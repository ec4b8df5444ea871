//! The timeline of a run as SVG: one swim lane per robot with its modes as
//! coloured bands, one row of bars per plan for the services that ran,
//! messages as arrows between lanes, throws and catches as markers, faults
//! marked. Every band and bar carries the mission line that caused it
//! (`data-line`), so that an editor can jump there.

use super::engine::Run;
use super::scenario::{FaultKind, Scenario};
use super::trace::TraceEvent;
use crate::fasthash::FastMap;
use crate::refine::RobotProgram;
use crate::xmlpos::escape;
use std::fmt::Write;

const LABEL_WIDTH: f64 = 150.0;
const PLOT_WIDTH: f64 = 1200.0;
const MODE_HEIGHT: f64 = 16.0;
const PLAN_HEIGHT: f64 = 9.0;
const LANE_GAP: f64 = 8.0;
const AXIS_HEIGHT: f64 = 24.0;
/// Colours of modes, picked by the mode's name so a mode keeps its colour.
const PALETTE: [&str; 10] = [
    "#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5",
    "#d9d9d9", "#bc80bd",
];

fn colour(name: &str) -> &'static str {
    let hash = name
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    PALETTE[hash as usize % PALETTE.len()]
}

/// A lane's rows: the mode band, then one row per plan.
struct Lane {
    top: f64,
    plans: Vec<String>,
}

impl Lane {
    fn height(&self) -> f64 {
        MODE_HEIGHT + self.plans.len() as f64 * PLAN_HEIGHT
    }
    fn middle(&self) -> f64 {
        self.top + MODE_HEIGHT / 2.0
    }
}

pub fn to_svg(run: &Run, programs: &[RobotProgram], scenario: &Scenario) -> String {
    let end = run.end_ms.max(1) as f64;
    let x = |t: i64| LABEL_WIDTH + t as f64 / end * PLOT_WIDTH;
    let mut lanes = Vec::new();
    let mut top = AXIS_HEIGHT;
    for program in programs {
        let mut plans: Vec<String> = Vec::new();
        for mode in &program.control.modes {
            for region in &mode.regions {
                if !plans.contains(&region.plan) {
                    plans.push(region.plan.clone());
                }
            }
        }
        let lane = Lane { top, plans };
        top += lane.height() + LANE_GAP;
        lanes.push(lane);
    }
    let height = top + 4.0;
    let width = LABEL_WIDTH + PLOT_WIDTH + 20.0;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"11\" data-end-ms=\"{}\">",
        run.end_ms
    );
    out.push_str("<defs><marker id=\"arrow\" viewBox=\"0 0 6 6\" refX=\"6\" refY=\"3\" markerWidth=\"6\" markerHeight=\"6\" orient=\"auto\"><path d=\"M0,0 L6,3 L0,6 z\" fill=\"#555\"/></marker></defs>\n");

    // Time axis: about ten ticks at a round step.
    out.push_str("<g class=\"axis\">\n");
    let step = [
        10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000, 30000, 60000, 120000, 300000,
        600000, 1200000, 3600000,
    ]
    .into_iter()
    .find(|s| run.end_ms / s <= 12)
    .unwrap_or(3600000);
    let mut t = 0;
    while t <= run.end_ms {
        let label = if step >= 1000 {
            format!("{}s", t / 1000)
        } else {
            format!("{t}ms")
        };
        let _ = writeln!(
            out,
            "<line x1=\"{0:.1}\" y1=\"{1}\" x2=\"{0:.1}\" y2=\"{height}\" stroke=\"#eee\"/><text x=\"{0:.1}\" y=\"14\" text-anchor=\"middle\">{label}</text>",
            x(t),
            AXIS_HEIGHT - 4.0
        );
        t += step;
    }
    out.push_str("</g>\n");

    // Each robot's events, in one pass over the trace (every cost below is
    // in proportion to the trace: a recorded run may be long).
    let mut of_robot: Vec<Vec<&TraceEvent>> = vec![Vec::new(); programs.len()];
    for e in &run.trace {
        if let Some(events) = of_robot.get_mut(e.robot) {
            events.push(e);
        }
    }
    for ((program, lane), events) in programs.iter().zip(&lanes).zip(&of_robot) {
        let robot_end = events.last().map_or(run.end_ms, |e| e.t);
        let _ = writeln!(
            out,
            "<g class=\"lane\" data-robot=\"{}\" data-team=\"{}\">",
            escape(&program.robot),
            escape(&program.team)
        );
        let _ = writeln!(
            out,
            "<rect class=\"lane-background\" x=\"{LABEL_WIDTH}\" y=\"{:.1}\" width=\"{PLOT_WIDTH}\" height=\"{:.1}\" fill=\"#fafafa\"/>",
            lane.top,
            lane.height()
        );
        let _ = writeln!(
            out,
            "<text class=\"lane-label\" x=\"6\" y=\"{:.1}\">{}</text>",
            lane.top + 12.0,
            escape(&format!("{}/{}", program.team, program.robot))
        );
        for (p, plan) in lane.plans.iter().enumerate() {
            let _ = writeln!(
                out,
                "<text class=\"plan-label\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"8\" text-anchor=\"end\" fill=\"#777\">{}</text>",
                LABEL_WIDTH - 4.0,
                lane.top + MODE_HEIGHT + (p + 1) as f64 * PLAN_HEIGHT - 1.0,
                escape(plan)
            );
        }
        // Modes: from each `mode` event to the next, or to the robot's end
        // (its first `stop` or `fault` at or after the mode's start: the
        // modes and those come in time order, so one cursor finds each).
        let modes: Vec<_> = events.iter().filter(|e| e.event == "mode").collect();
        let stops: Vec<i64> = events
            .iter()
            .filter(|f| matches!(f.event, "stop" | "fault"))
            .map(|f| f.t)
            .collect();
        let mut stop = 0;
        for (k, e) in modes.iter().enumerate() {
            let name = e.field("mode").unwrap_or_default();
            let next_mode = modes.get(k + 1).map_or(robot_end, |n| n.t);
            while stops.get(stop).is_some_and(|&t| t < e.t) {
                stop += 1;
            }
            let ended = stops.get(stop).copied().unwrap_or(robot_end);
            let until = next_mode.min(ended);
            let line = program
                .control
                .modes
                .iter()
                .find(|m| m.name == name)
                .map_or(0, |m| m.line);
            let _ = writeln!(
                out,
                "<rect class=\"mode\" data-mode=\"{}\" data-line=\"{line}\" data-start=\"{}\" data-end=\"{until}\" x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{MODE_HEIGHT}\" fill=\"{}\" stroke=\"#fff\"><title>{} {}: {} ms to {until} ms (line {line})</title></rect>",
                escape(name),
                e.t,
                x(e.t),
                lane.top,
                (x(until) - x(e.t)).max(0.5),
                colour(name),
                escape(&program.robot),
                escape(name),
                e.t
            );
            if x(until) - x(e.t) > 7.0 * name.len() as f64 {
                let _ = writeln!(
                    out,
                    "<text class=\"mode-label\" x=\"{:.1}\" y=\"{:.1}\" pointer-events=\"none\">{}</text>",
                    x(e.t) + 2.0,
                    lane.top + 12.0,
                    escape(name)
                );
            }
        }
        // Service runs: `service_start` to the next `service_end` of the
        // plan (or `stop`, `fault`), found in one walk with the runs open
        // per plan.
        let mut ends: Vec<Option<i64>> = vec![None; events.len()];
        let mut open: FastMap<&str, Vec<usize>> = FastMap::default();
        for (k, e) in events.iter().enumerate() {
            match e.event {
                "service_start" => {
                    let plan = e.field("plan").unwrap_or_default();
                    open.entry(plan).or_default().push(k);
                }
                "service_end" => {
                    let plan = e.field("plan").unwrap_or_default();
                    for started in open.remove(plan).unwrap_or_default() {
                        ends[started] = Some(e.t);
                    }
                }
                "stop" | "fault" => {
                    for (_, runs) in open.drain() {
                        for started in runs {
                            ends[started] = Some(e.t);
                        }
                    }
                }
                _ => {}
            }
        }
        for (k, e) in events.iter().enumerate() {
            if e.event != "service_start" {
                continue;
            }
            let plan = e.field("plan").unwrap_or_default();
            let service = e.field("service").unwrap_or_default();
            let until = ends[k].unwrap_or(robot_end);
            let row = lane.plans.iter().position(|p| p == plan).unwrap_or(0);
            let line = program
                .control
                .services
                .iter()
                .find(|s| s.plan == plan && s.name == service)
                .map_or(0, |s| s.line);
            let _ = writeln!(
                out,
                "<rect class=\"service\" data-plan=\"{}\" data-service=\"{}\" data-line=\"{line}\" data-start=\"{}\" data-end=\"{until}\" x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#4a7ab0\" opacity=\"0.75\"><title>{}.{}: {} ms to {until} ms (line {line})</title></rect>",
                escape(plan),
                escape(service),
                e.t,
                x(e.t),
                lane.top + MODE_HEIGHT + row as f64 * PLAN_HEIGHT + 1.0,
                (x(until) - x(e.t)).max(0.5),
                PLAN_HEIGHT - 2.0,
                escape(plan),
                escape(service),
                e.t
            );
        }
        // Throws and catches.
        for e in events.iter() {
            let (class, shape) = match e.event {
                "throw" => ("throw", "M-3,0 L0,-4 L3,0 L0,4 z"),
                "catch" => ("catch", "M-3,-3 L3,3 M-3,3 L3,-3"),
                _ => continue,
            };
            let _ = writeln!(
                out,
                "<path class=\"{class}\" data-event=\"{}\" data-t=\"{}\" transform=\"translate({:.1},{:.1})\" d=\"{shape}\" fill=\"#d62728\" stroke=\"#d62728\"><title>{class} {} at {} ms</title></path>",
                escape(e.field("name").unwrap_or_default()),
                e.t,
                x(e.t),
                lane.middle(),
                escape(e.field("name").unwrap_or_default()),
                e.t
            );
        }
        out.push_str("</g>\n");
    }

    // Messages between robots (heartbeats left out: they would hide the rest).
    let lane_of_robot: FastMap<&str, usize> = programs
        .iter()
        .enumerate()
        .map(|(i, p)| (p.robot.as_str(), i))
        .collect();
    out.push_str(
        "<g class=\"messages\" stroke=\"#555\" stroke-width=\"0.6\" marker-end=\"url(#arrow)\">\n",
    );
    for e in &run.trace {
        if e.event != "receive" {
            continue;
        }
        let key = e.field("key").unwrap_or_default();
        if key.ends_with(".__alive") {
            continue;
        }
        let from = e.field("from_robot").unwrap_or_default();
        let Some(&sender) = lane_of_robot.get(from) else {
            continue; // the operator
        };
        let sent = e.sent_at.unwrap_or(e.t);
        let _ = writeln!(
            out,
            "<line class=\"message\" data-key=\"{}\" data-from=\"{}\" data-to=\"{}\" x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\"><title>{} from {} at {sent} ms to {} at {} ms</title></line>",
            escape(key),
            escape(from),
            escape(&run.robots[e.robot].1),
            x(sent),
            lanes[sender].middle(),
            x(e.t),
            lanes[e.robot].middle(),
            escape(key),
            escape(from),
            escape(&run.robots[e.robot].1),
            e.t
        );
    }
    out.push_str("</g>\n");

    // Faults: kills and restarts on their lane, link faults across both lanes.
    out.push_str("<g class=\"faults\">\n");
    let lane_of = |robot: &str| programs.iter().position(|p| p.robot == robot);
    for fault in &scenario.faults {
        match &fault.kind {
            FaultKind::Kill { robot, at } | FaultKind::Restart { robot, at } => {
                let Some(l) = lane_of(robot) else { continue };
                let what = if matches!(fault.kind, FaultKind::Kill { .. }) {
                    "kill"
                } else {
                    "restart"
                };
                let _ = writeln!(
                    out,
                    "<line class=\"fault\" data-fault=\"{what}\" data-robot=\"{}\" x1=\"{0:.1}\" y1=\"{:.1}\" x2=\"{0:.1}\" y2=\"{:.1}\" stroke=\"#000\" stroke-width=\"2\"><title>{what} {} at {at} ms</title></line>",
                    x(*at),
                    lanes[l].top,
                    lanes[l].top + lanes[l].height(),
                    escape(robot),
                );
            }
            FaultKind::Drop {
                between,
                from,
                until,
            }
            | FaultKind::Delay {
                between,
                from,
                until,
                ..
            } => {
                let what = if matches!(fault.kind, FaultKind::Drop { .. }) {
                    "drop"
                } else {
                    "delay"
                };
                for robot in [&between.0, &between.1] {
                    let Some(l) = lane_of(robot) else { continue };
                    let _ = writeln!(
                        out,
                        "<rect class=\"fault\" data-fault=\"{what}\" data-robot=\"{}\" x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"#000\" stroke-dasharray=\"3,2\"><title>{what} between {} and {}: {from} ms to {until} ms</title></rect>",
                        escape(robot),
                        x(*from),
                        lanes[l].top,
                        x(*until) - x(*from),
                        lanes[l].height(),
                        escape(&between.0),
                        escape(&between.1)
                    );
                }
            }
            FaultKind::Partition {
                groups,
                from,
                until,
            } => {
                let _ = writeln!(
                    out,
                    "<rect class=\"fault\" data-fault=\"partition\" x=\"{:.1}\" y=\"{AXIS_HEIGHT}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#000\" opacity=\"0.06\"><title>partition {}: {from} ms to {until} ms</title></rect>",
                    x(*from),
                    x(*until) - x(*from),
                    height - AXIS_HEIGHT,
                    escape(
                        &groups
                            .iter()
                            .map(|g| g.join(", "))
                            .collect::<Vec<_>>()
                            .join(" | ")
                    )
                );
            }
        }
    }
    out.push_str("</g>\n</svg>\n");
    out
}
