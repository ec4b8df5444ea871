//! The timeline of a run as SVG: one swim lane per robot with its modes as
//! coloured bands, one row of bars per plan (a colour per plan) for the
//! services that ran, named where they are wide enough, messages as arrows
//! between lanes coloured by their key, throws and catches as markers, each
//! robot's group in counted groups where it changes, how each robot's run
//! ended (finished, stopped, killed), faults marked, and a
//! legend of the plans, keys and markers. Every band and bar carries the
//! mission line that caused it (`data-line`), so that an editor can jump
//! there. Labels are drawn last, on a white halo, so that no arrow hides
//! them; arrows of one key between two robots less than a pixel apart are
//! drawn once (a 10 ms publish would otherwise be a solid block).

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
const PLAN_HEIGHT: f64 = 12.0;
const LEGEND_ROW: f64 = 16.0;
const LANE_GAP: f64 = 8.0;
const AXIS_HEIGHT: f64 = 24.0;
/// Colours of modes, picked by the mode's name so a mode keeps its colour.
const PALETTE: [&str; 10] = [
    "#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5",
    "#d9d9d9", "#bc80bd",
];

/// Colours of plans' service bars, by their order of appearance.
const PLAN_COLOURS: [&str; 8] = [
    "#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#ff7f0e",
];
/// Colours of message keys (another set, so that an arrow is not read as a
/// plan), by their order of appearance.
const KEY_COLOURS: [&str; 8] = [
    "#d95f02", "#1b9e77", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#666666",
];
/// Arrows of one key between two robots closer than this (pixels, about an
/// arrowhead) are drawn once.
const ARROW_SPACING: f64 = 6.0;

fn colour(name: &str) -> &'static str {
    let hash = name
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    PALETTE[hash as usize % PALETTE.len()]
}

/// Names in order of first appearance, each with its colour of `palette`.
struct Legend {
    names: Vec<String>,
    palette: &'static [&'static str],
}

impl Legend {
    fn new(palette: &'static [&'static str]) -> Legend {
        Legend {
            names: Vec::new(),
            palette,
        }
    }

    fn colour(&mut self, name: &str) -> &'static str {
        let at = match self.names.iter().position(|n| n == name) {
            Some(at) => at,
            None => {
                self.names.push(name.to_string());
                self.names.len() - 1
            }
        };
        self.palette[at % self.palette.len()]
    }
}

/// `text` at (`x`, `y`) with a white halo, so that it stays readable over
/// bars and arrows.
fn label(out: &mut String, class: &str, x: f64, y: f64, size: f64, text: &str) {
    let _ = writeln!(
        out,
        "<text class=\"{class}\" x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"{size}\" stroke=\"#fff\" stroke-width=\"3\" stroke-linejoin=\"round\" paint-order=\"stroke\" pointer-events=\"none\">{}</text>",
        escape(text)
    );
}

/// `v` rounded to the tenth, as the picture writes coordinates.
fn tenth(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

/// Roughly how wide `text` is at font size `size`.
fn text_width(text: &str, size: f64) -> f64 {
    text.chars().count() as f64 * size * 0.6
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
    let lanes_bottom = top;
    // What is drawn in the plot, then the labels over it.
    let mut body = String::new();
    let mut labels = String::new();
    let mut plan_colours = Legend::new(&PLAN_COLOURS);
    let mut key_colours = Legend::new(&KEY_COLOURS);

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
            body,
            "<g class=\"lane\" data-robot=\"{}\" data-team=\"{}\">",
            escape(&program.robot),
            escape(&program.team)
        );
        let _ = writeln!(
            body,
            "<rect class=\"lane-background\" x=\"{LABEL_WIDTH}\" y=\"{:.1}\" width=\"{PLOT_WIDTH}\" height=\"{:.1}\" fill=\"#fafafa\"/>",
            lane.top,
            lane.height()
        );
        let _ = writeln!(
            body,
            "<text class=\"lane-label\" x=\"6\" y=\"{:.1}\">{}</text>",
            lane.top + 12.0,
            escape(&format!("{}/{}", program.team, program.robot))
        );
        for (p, plan) in lane.plans.iter().enumerate() {
            let _ = writeln!(
                body,
                "<text class=\"plan-label\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\" text-anchor=\"end\" fill=\"{}\">{}</text>",
                LABEL_WIDTH - 4.0,
                lane.top + MODE_HEIGHT + (p + 1) as f64 * PLAN_HEIGHT - 2.0,
                plan_colours.colour(plan),
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
                body,
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
            if x(until) - x(e.t) > text_width(name, 11.0) + 4.0 {
                label(
                    &mut labels,
                    "mode-label",
                    x(e.t) + 2.0,
                    lane.top + 12.0,
                    11.0,
                    name,
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
            let bar_top = lane.top + MODE_HEIGHT + row as f64 * PLAN_HEIGHT + 1.0;
            let _ = writeln!(
                body,
                "<rect class=\"service\" data-plan=\"{}\" data-service=\"{}\" data-line=\"{line}\" data-start=\"{}\" data-end=\"{until}\" x=\"{:.1}\" y=\"{bar_top:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{}\" opacity=\"0.8\"><title>{}.{}: {} ms to {until} ms (line {line})</title></rect>",
                escape(plan),
                escape(service),
                e.t,
                x(e.t),
                (x(until) - x(e.t)).max(0.5),
                PLAN_HEIGHT - 2.0,
                plan_colours.colour(plan),
                escape(plan),
                escape(service),
                e.t
            );
            if x(until) - x(e.t) > text_width(service, 8.0) + 4.0 {
                label(
                    &mut labels,
                    "service-label",
                    x(e.t) + 2.0,
                    bar_top + PLAN_HEIGHT - 4.0,
                    8.0,
                    service,
                );
            }
        }
        // Throws and catches (a broadcast is one throw at its thrower, and
        // a catch at each robot it changed the mode of).
        for e in events.iter() {
            let (class, shape) = match e.event {
                "throw" if e.field("broadcast").is_some() => {
                    ("throw broadcast", "M-4,0 L0,-5 L4,0 L0,5 z")
                }
                "throw" => ("throw", "M-3,0 L0,-4 L3,0 L0,4 z"),
                "catch" => ("catch", "M-3,-3 L3,3 M-3,3 L3,-3"),
                _ => continue,
            };
            let _ = writeln!(
                body,
                "<path class=\"{class}\" data-event=\"{}\" data-t=\"{}\" transform=\"translate({:.1},{:.1})\" d=\"{shape}\" fill=\"#d62728\" stroke=\"#d62728\"><title>{class} {} at {} ms</title></path>",
                escape(e.field("name").unwrap_or_default()),
                e.t,
                x(e.t),
                lane.middle(),
                escape(e.field("name").unwrap_or_default()),
                e.t
            );
        }
        // Its group in statements of counted groups, at each change: a
        // triangle on the lane's top edge, named above the lane where the
        // name fits before the robot's next change.
        let allocations: Vec<&&TraceEvent> =
            events.iter().filter(|e| e.event == "allocated").collect();
        for (k, e) in allocations.iter().enumerate() {
            let group = e.field("name").unwrap_or_default();
            let alive = e.field("alive").unwrap_or_default();
            let _ = writeln!(
                body,
                "<g class=\"allocated\" data-group=\"{}\" data-alive=\"{}\" data-t=\"{}\"><path transform=\"translate({:.1},{:.1})\" d=\"M0,0 L3,5 L-3,5 z\" fill=\"#1f3b73\"/><title>{} in {} at {} ms ({} alive)</title></g>",
                escape(group),
                escape(alive),
                e.t,
                x(e.t),
                lane.top,
                escape(&program.robot),
                escape(group),
                e.t,
                escape(alive)
            );
            let room = allocations
                .get(k + 1)
                .map_or(LABEL_WIDTH + PLOT_WIDTH, |next| x(next.t))
                - x(e.t);
            if room > text_width(group, 7.0) + 4.0 {
                label(
                    &mut labels,
                    "allocated-label",
                    x(e.t) + 2.0,
                    lane.top - 1.0,
                    7.0,
                    group,
                );
            }
        }
        // How the robot's run ended: its latest finish or kill (a restart
        // after a kill runs it again), else a stop before the run's end; a
        // robot still running when the run ends is not marked.
        let latest = events
            .iter()
            .rev()
            .find(|e| matches!(e.event, "finish" | "fault"));
        let ending = match latest {
            Some(e) if e.event == "finish" => Some(("finished", e.t)),
            Some(e) if e.field("fault") == Some("kill") => Some(("killed", e.t)),
            _ => events
                .iter()
                .rev()
                .find(|e| e.event == "stop" && e.t < run.end_ms)
                .map(|e| ("stopped", e.t)),
        };
        if let Some((why, at)) = ending {
            let _ = writeln!(
                body,
                "<g class=\"end\" data-why=\"{why}\" data-t=\"{at}\"><rect x=\"{:.1}\" y=\"{:.1}\" width=\"3\" height=\"{:.1}\" fill=\"#333\"/><title>{} {why} at {at} ms</title></g>",
                x(at),
                lane.top,
                lane.height(),
                escape(&program.robot)
            );
            let width = text_width(why, 9.0);
            let at_x = if x(at) + 6.0 + width <= LABEL_WIDTH + PLOT_WIDTH {
                x(at) + 6.0
            } else {
                x(at) - 4.0 - width
            };
            label(&mut labels, "end-label", at_x, lane.top + 12.0, 9.0, why);
        }
        body.push_str("</g>\n");
    }

    // Messages between robots (heartbeats left out: they would hide the
    // rest), one arrow per key and pair every ARROW_SPACING pixels.
    body.push_str("<g class=\"messages\" stroke-width=\"0.8\" marker-end=\"url(#arrow)\">\n");
    let mut drawn = std::collections::HashSet::new();
    let lane_of_robot: FastMap<&str, usize> = programs
        .iter()
        .enumerate()
        .map(|(i, p)| (p.robot.as_str(), i))
        .collect();
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
        // As written (a tenth of a pixel), so that a reader of the picture
        // finds the same spacing.
        let (x1, x2) = (tenth(x(sent)), tenth(x(e.t)));
        let pixel = (
            (x1 / ARROW_SPACING).floor() as i64,
            (x2 / ARROW_SPACING).floor() as i64,
        );
        if !drawn.insert((key, sender, e.robot, pixel)) {
            continue;
        }
        let _ = writeln!(
            body,
            "<line class=\"message\" data-key=\"{}\" data-from=\"{}\" data-to=\"{}\" x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" opacity=\"0.7\"><title>{} from {} at {sent} ms to {} at {} ms</title></line>",
            escape(key),
            escape(from),
            escape(&run.robots[e.robot].1),
            x1,
            lanes[sender].middle(),
            x2,
            lanes[e.robot].middle(),
            key_colours.colour(key),
            escape(key),
            escape(from),
            escape(&run.robots[e.robot].1),
            e.t
        );
    }
    body.push_str("</g>\n");

    // Faults: kills and restarts on their lane, link faults across both lanes.
    body.push_str("<g class=\"faults\">\n");
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
                    body,
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
                        body,
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
                    body,
                    "<rect class=\"fault\" data-fault=\"partition\" x=\"{:.1}\" y=\"{AXIS_HEIGHT}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#000\" opacity=\"0.06\"><title>partition {}: {from} ms to {until} ms</title></rect>",
                    x(*from),
                    x(*until) - x(*from),
                    lanes_bottom - AXIS_HEIGHT,
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
    body.push_str("</g>\n");

    let (legend, legend_height) = legend(lanes_bottom, &plan_colours, &key_colours);
    let height = lanes_bottom + legend_height + 4.0;
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
        let tick = if step >= 1000 {
            format!("{}s", t / 1000)
        } else {
            format!("{t}ms")
        };
        let _ = writeln!(
            out,
            "<line x1=\"{0:.1}\" y1=\"{1}\" x2=\"{0:.1}\" y2=\"{lanes_bottom}\" stroke=\"#eee\"/><text x=\"{0:.1}\" y=\"14\" text-anchor=\"middle\">{tick}</text>",
            x(t),
            AXIS_HEIGHT - 4.0
        );
        t += step;
    }
    out.push_str("</g>\n");
    out.push_str(&body);
    out.push_str("<g class=\"labels\">\n");
    out.push_str(&labels);
    out.push_str("</g>\n");
    out.push_str(&legend);
    out.push_str("</svg>\n");
    out
}

/// The legend below the lanes (from `top`): the plans' colours, the message
/// keys' colours, and what the markers mean. Gives it and its height.
fn legend(top: f64, plans: &Legend, keys: &Legend) -> (String, f64) {
    let mut out = String::from("<g class=\"legend\" font-size=\"10\">\n");
    let mut y = top + 4.0;
    let rows: [(&str, &Legend); 2] = [("plans", plans), ("messages", keys)];
    for (title, legend) in rows {
        if legend.names.is_empty() {
            continue;
        }
        let _ = writeln!(
            out,
            "<text x=\"6\" y=\"{:.1}\" fill=\"#555\">{title}</text>",
            y + 10.0
        );
        let mut at = LABEL_WIDTH;
        for (i, name) in legend.names.iter().enumerate() {
            let width = 16.0 + text_width(name, 10.0) + 12.0;
            if at + width > LABEL_WIDTH + PLOT_WIDTH {
                at = LABEL_WIDTH;
                y += LEGEND_ROW;
            }
            let colour = legend.palette[i % legend.palette.len()];
            // A plan's swatch is a bar, a key's an arrow's line.
            let swatch = if title == "plans" {
                format!(
                    "<rect x=\"{at:.1}\" y=\"{:.1}\" width=\"12\" height=\"8\" fill=\"{colour}\"/>",
                    y + 3.0
                )
            } else {
                format!(
                    "<line x1=\"{at:.1}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"{colour}\" stroke-width=\"2\"/>",
                    y + 7.0,
                    at + 12.0
                )
            };
            let _ = writeln!(
                out,
                "<g class=\"legend-entry\" data-kind=\"{title}\" data-name=\"{}\">{swatch}<text x=\"{:.1}\" y=\"{:.1}\">{}</text></g>",
                escape(name),
                at + 16.0,
                y + 10.0,
                escape(name)
            );
            at += width;
        }
        y += LEGEND_ROW;
    }
    let _ = writeln!(
        out,
        "<text x=\"6\" y=\"{0:.1}\" fill=\"#555\">markers</text><g class=\"legend-entry\" data-kind=\"markers\" transform=\"translate({LABEL_WIDTH},{1:.1})\"><path d=\"M3,4 L6,0 L9,4 L6,8 z\" fill=\"#d62728\"/><text x=\"14\" y=\"7\">throw</text><path d=\"M55,1 L61,7 M55,7 L61,1\" stroke=\"#d62728\"/><text x=\"66\" y=\"7\">catch</text><rect x=\"110\" y=\"0\" width=\"3\" height=\"8\" fill=\"#333\"/><text x=\"117\" y=\"7\">end of a robot's run</text><line x1=\"240\" y1=\"0\" x2=\"240\" y2=\"8\" stroke=\"#000\" stroke-width=\"2\"/><text x=\"245\" y=\"7\">kill / restart</text><rect x=\"325\" y=\"0\" width=\"14\" height=\"8\" fill=\"none\" stroke=\"#000\" stroke-dasharray=\"3,2\"/><text x=\"344\" y=\"7\">link dropped / delayed</text><rect x=\"470\" y=\"0\" width=\"14\" height=\"8\" fill=\"#000\" opacity=\"0.1\"/><text x=\"489\" y=\"7\">partition</text><path transform=\"translate(560,1)\" d=\"M0,0 L3,5 L-3,5 z\" fill=\"#1f3b73\"/><text x=\"567\" y=\"7\">group allocation</text></g>",
        y + 10.0,
        y + 3.0
    );
    y += LEGEND_ROW;
    out.push_str("</g>\n");
    (out, y - top)
}
