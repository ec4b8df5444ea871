//! A recorded run read back (`semo replay`): the trace lines a field run
//! wrote (each robot's `--trace` file of the generated programs, or one
//! merged file, or `semo simulate --trace`) turned into the [`Run`] the
//! simulator would have given, so that the summary, the timeline picture
//! and the expectations are the simulator's own functions on it (one
//! meaning: [`super::expect::judge`], [`super::summary`], [`super::svg`]).
//!
//! Every line is checked against the trace format of
//! `docs/scenario-and-trace.md` and the mission: a mistake is a
//! [`TraceError`] at its line and column (the robot a mission lacks with a
//! did-you-mean), never a panic. Each line costs in proportion to its
//! length; the lines of all files are merged by time with a stable sort,
//! which takes files already in time order (as every robot writes its own)
//! in one merge pass per file.

use super::engine::Run;
use super::json::{self, Kind, Value as Json};
use super::trace::TraceEvent;
use crate::fasthash::{FastMap, FastSet};
use crate::refine::RobotProgram;
use crate::refine::value::Value;

/// The longest trace line read, in bytes (a `graph_fire` line, the longest
/// the runtime writes, is under 9 KiB); longer is an error at the line.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Largest mission time a line may carry (the scenario's bound, `10^15` ms).
const MAX_MS: i64 = 1_000_000_000_000_000;

/// Every kind of trace line the simulator and the generated programs write
/// (`docs/scenario-and-trace.md`, `codegen/runtime/README.md`).
pub const EVENTS: &[&str] = &[
    "start",
    "mode",
    "service_start",
    "service_end",
    "call_start",
    "actuate",
    "call_end",
    "result",
    "actions_start",
    "actions_end",
    "timeout",
    "throw",
    "catch",
    "leader",
    "fenced",
    "group_sync",
    "group",
    "allocated",
    "send",
    "receive",
    "shared_set",
    "shared_value",
    "shared_owner",
    "battery_policy",
    "period",
    "speed",
    "graph_fire",
    "graph_error",
    "graph_loop",
    "finish",
    "stop",
    "fault",
    "drop",
    "dropped",
    "reject",
    "comm_error",
    "signal",
];

/// Every field key of a trace line besides `t`, `robot` and `event`.
pub const FIELDS: &[&str] = &[
    "team",
    "type",
    "mission",
    "mode",
    "plan",
    "service",
    "why",
    "task",
    "statement",
    "name",
    "broadcast",
    "leader",
    "heard",
    "line",
    "rank",
    "size",
    "alive",
    "to",
    "key",
    "from",
    "from_robot",
    "owner",
    "library",
    "lost",
    "condition",
    "holds",
    "level",
    "period_ms",
    "graph",
    "read",
    "wrote",
    "release",
    "channel",
    "error",
    "loop",
    "iterations",
    "fault",
    "reason",
    "count",
    "signal",
    "time_scale",
];

/// The keys that hold a mission value (typed: a number, `true`/`false`, a
/// string or `null`); every other field is a string.
const TYPED: &[&str] = &["value", "arg"];

/// The fields a line of a kind must have: those the summary, the picture
/// and the expectations read.
const REQUIRED: &[(&str, &[&str])] = &[
    ("start", &["team"]),
    ("mode", &["mode"]),
    ("service_start", &["plan", "service"]),
    ("service_end", &["plan", "service"]),
    ("throw", &["name"]),
    ("catch", &["name", "mode"]),
    ("send", &["to", "key"]),
    ("receive", &["from_robot", "key"]),
    ("fault", &["fault"]),
];

/// A mistake in a trace line, at a 1-based line and column (in characters).
#[derive(Clone, Debug, PartialEq)]
pub struct TraceError {
    pub line: u64,
    pub column: u64,
    /// What is wrong, a did-you-mean included.
    pub message: String,
    /// The name the user most likely meant, for an unknown one close to it.
    pub suggestion: Option<String>,
}

/// The lines of one or more trace files, read one at a time against a
/// mission's programs; [`Replay::finish`] gives the run.
pub struct Replay<'p> {
    programs: &'p [RobotProgram],
    robot_of: FastMap<&'p str, usize>,
    modes: Vec<FastSet<&'p str>>,
    trace: Vec<TraceEvent>,
    /// Per robot, the time of its last line in the current file.
    last_t: Vec<Option<i64>>,
    lines: u64,
}

impl<'p> Replay<'p> {
    pub fn new(programs: &'p [RobotProgram]) -> Self {
        let robot_of = programs
            .iter()
            .enumerate()
            .map(|(i, p)| (p.robot.as_str(), i))
            .collect();
        let modes = programs
            .iter()
            .map(|p| p.control.modes.iter().map(|m| m.name.as_str()).collect())
            .collect();
        Replay {
            programs,
            robot_of,
            modes,
            trace: Vec::new(),
            last_t: vec![None; programs.len()],
            lines: 0,
        }
    }

    /// The next file begins: its robots' lines are in time order again
    /// from their start.
    pub fn start_file(&mut self) {
        self.last_t.fill(None);
    }

    /// Reads line `number` (1-based) of the current file, without its
    /// line break. A blank line is skipped.
    pub fn line(&mut self, number: u64, bytes: &[u8]) -> Result<(), TraceError> {
        let at = |column: u64, message: String| TraceError {
            line: number,
            column,
            message,
            suggestion: None,
        };
        if bytes.len() > MAX_LINE_BYTES {
            return Err(at(
                1,
                format!("a trace line is at most {MAX_LINE_BYTES} bytes; this one is longer"),
            ));
        }
        let text = match std::str::from_utf8(bytes) {
            Ok(text) => text,
            Err(e) => {
                let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
                return Err(at(
                    valid.chars().count() as u64 + 1,
                    "not UTF-8 text".to_string(),
                ));
            }
        };
        let text = text.strip_suffix('\r').unwrap_or(text);
        if text.trim().is_empty() {
            return Ok(());
        }
        let column = |offset: usize| text[..offset.min(text.len())].chars().count() as u64 + 1;
        let fail = |v: &Json, message: String| at(column(v.at), message);
        let root = json::parse_line(text).map_err(|e| at(column(e.at), e.message))?;
        let Kind::Object(members) = &root.kind else {
            return Err(fail(
                &root,
                "expected a trace event: an object {\"t\": ..., \"robot\": ..., \"event\": ...}"
                    .into(),
            ));
        };
        let missing = |key: &str| at(1, format!("a trace line needs \"{key}\""));
        let t_value = root.member("t").ok_or_else(|| missing("t"))?;
        let t = match &t_value.kind {
            Kind::Number(n, written)
                if !written.contains(['.', 'e', 'E']) && (0.0..=MAX_MS as f64).contains(n) =>
            {
                *n as i64
            }
            _ => {
                return Err(fail(
                    t_value,
                    format!("\"t\" is whole mission milliseconds, 0 to {MAX_MS}"),
                ));
            }
        };
        let robot_value = root.member("robot").ok_or_else(|| missing("robot"))?;
        let Kind::String(robot_name) = &robot_value.kind else {
            return Err(fail(robot_value, "\"robot\" is a robot's name".into()));
        };
        let Some(&robot) = self.robot_of.get(robot_name.as_str()) else {
            return Err(self.suggesting(
                at(
                    column(robot_value.at),
                    format!("the mission has no robot \"{robot_name}\""),
                ),
                robot_name,
                self.programs.iter().map(|p| p.robot.as_str()),
            ));
        };
        let event_value = root.member("event").ok_or_else(|| missing("event"))?;
        let Kind::String(event_name) = &event_value.kind else {
            return Err(fail(event_value, "\"event\" is the kind of line".into()));
        };
        let Some(event) = known(event_name, EVENTS) else {
            return Err(self.suggesting(
                at(
                    column(event_value.at),
                    format!("unknown trace event \"{event_name}\""),
                ),
                event_name,
                EVENTS.iter().copied(),
            ));
        };
        let mut fields = super::trace::Fields::new();
        let mut typed = None;
        for (key, v) in members {
            if matches!(key.as_str(), "t" | "robot" | "event") {
                continue;
            }
            if let Some(key) = known(key, TYPED) {
                typed = Some((key, value_of(v).map_err(|m| fail(v, m))?));
                continue;
            }
            let Some(key) = known(key, FIELDS) else {
                let message = format!("unknown field \"{key}\" of a trace line");
                // Keys are not positioned by the reader: the value is.
                return Err(self.suggesting(
                    fail(v, message),
                    key,
                    FIELDS.iter().chain(TYPED).copied(),
                ));
            };
            let Kind::String(text) = &v.kind else {
                return Err(fail(v, format!("\"{key}\" is a string")));
            };
            fields.push((key, text.as_str().into()));
        }
        let field = |key: &str| fields.iter().find(|(k, _)| *k == key).map(|(_, v)| &**v);
        if let Some((_, needed)) = REQUIRED.iter().find(|(e, _)| *e == event)
            && let Some(absent) = needed.iter().find(|k| field(k).is_none())
        {
            return Err(fail(
                event_value,
                format!("a \"{event}\" line needs \"{absent}\""),
            ));
        }
        let program = &self.programs[robot];
        let positioned = |key: &str, message: String| {
            let v = root.member(key).unwrap_or(event_value);
            fail(v, message)
        };
        // A robot's team is the mission's: a trace of another mission's
        // robot of the same name is refused. (The `mission` field, the
        // mission file's name, is not compared: a renamed copy of the
        // mission file is the same mission.)
        if event == "start"
            && let Some(team) = field("team")
            && team != program.team
        {
            return Err(positioned(
                "team",
                format!(
                    "robot \"{}\" is of team \"{}\" in the mission, not \"{team}\"",
                    program.robot, program.team
                ),
            ));
        }
        if event == "mode"
            && let Some(mode) = field("mode")
            && !self.modes[robot].contains(mode)
        {
            let error = positioned(
                "mode",
                format!("robot \"{}\" has no mode \"{mode}\"", program.robot),
            );
            return Err(self.suggesting(error, mode, self.modes[robot].iter().copied()));
        }
        if let Some(last) = self.last_t[robot]
            && t < last
        {
            return Err(fail(
                t_value,
                format!(
                    "time goes back for robot \"{}\": {t} ms after {last} ms (each robot's lines are in time order)",
                    program.robot
                ),
            ));
        }
        self.last_t[robot] = Some(t);
        self.lines += 1;
        self.trace.push(TraceEvent {
            t,
            robot,
            event,
            fields,
            value: typed,
            sent_at: None,
        });
        Ok(())
    }

    fn suggesting<'a>(
        &self,
        mut error: TraceError,
        name: &str,
        known: impl Iterator<Item = &'a str>,
    ) -> TraceError {
        error.suggestion = crate::suggest::did_you_mean(name, known);
        if let Some(close) = &error.suggestion {
            error.message = format!("{} (did you mean \"{close}\"?)", error.message);
        }
        error
    }

    /// The run the lines recorded: every robot of the mission (those
    /// without a line too), the lines merged by time (at one instant, in
    /// the order of the files and their lines), ending at the last line.
    /// A `receive` from a robot is drawn from that robot's latest `send`
    /// of the key by then.
    pub fn finish(self) -> Run {
        let mut trace = self.trace;
        // Stable: each robot's lines keep their order; runs already in
        // time order (every file) are merged, not sorted again.
        trace.sort_by_key(|e| e.t);
        let mut sent: FastMap<(usize, &str), i64> = FastMap::default();
        let mut sent_at: Vec<(usize, i64)> = Vec::new();
        for (k, e) in trace.iter().enumerate() {
            match (e.event, e.field("key")) {
                ("send", Some(key)) => {
                    sent.insert((e.robot, key), e.t);
                }
                ("receive", Some(key)) => {
                    let from = e.field("from_robot").and_then(|r| self.robot_of.get(r));
                    if let Some(&t) = from.and_then(|&from| sent.get(&(from, key))) {
                        sent_at.push((k, t));
                    }
                }
                _ => {}
            }
        }
        for (k, t) in sent_at {
            trace[k].sent_at = Some(t);
        }
        let end_ms = trace.last().map_or(0, |e| e.t);
        Run::of(self.programs, trace, end_ms, self.lines)
    }
}

/// The static name equal to `name` among `names`.
fn known(name: &str, names: &[&'static str]) -> Option<&'static str> {
    names.iter().copied().find(|n| *n == name)
}

/// A typed field's mission value: a whole number is an integer, a number
/// with a fraction or exponent a real, a string a word or text (the trace
/// writes both alike), `null` no value.
fn value_of(v: &Json) -> Result<Option<Value>, String> {
    Ok(match &v.kind {
        Kind::Null => None,
        Kind::Bool(b) => Some(Value::Bool(*b)),
        Kind::Number(n, written) if written.contains(['.', 'e', 'E']) => Some(Value::Real(*n)),
        Kind::Number(_, written) => Some(Value::Int(
            written
                .parse()
                .map_err(|_| "an integer value out of range".to_string())?,
        )),
        Kind::String(s) => Some(Value::text(s)),
        Kind::Array(_) | Kind::Object(_) => {
            return Err("a value is a number, a string, true, false or null".into());
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{expect, scenario, simulate, summary};

    fn scouting() -> (Vec<RobotProgram>, scenario::Scenario, Run) {
        let programs = crate::sim::tests::programs("examples/scouting/scouting.mission");
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../tests/fixtures/build/scouting.scenario.json"),
        )
        .unwrap();
        let scenario = scenario::parse(&text, &programs).unwrap();
        let run = simulate(&programs, &scenario, &Default::default());
        (programs, scenario, run)
    }

    fn replayed(programs: &[RobotProgram], files: &[&str]) -> Result<Run, TraceError> {
        let mut replay = Replay::new(programs);
        for file in files {
            replay.start_file();
            for (i, line) in file.lines().enumerate() {
                replay.line(i as u64 + 1, line.as_bytes())?;
            }
        }
        Ok(replay.finish())
    }

    #[test]
    fn a_simulated_trace_reads_back_as_its_run() {
        let (programs, scenario, run) = scouting();
        let lines = run.trace_lines();
        let back = replayed(&programs, &[&lines]).unwrap();
        // Every line reads back to itself, byte for byte.
        assert_eq!(back.trace_lines(), lines);
        assert_eq!(back.robots, run.robots);
        assert_eq!(back.end_ms, run.end_ms);
        // Each message is drawn from when it was sent (here one ms earlier).
        let arrows = |r: &Run| -> Vec<Option<i64>> {
            r.trace
                .iter()
                .filter(|e| e.event == "receive" && e.field("from_robot") != Some("USER"))
                .map(|e| e.sent_at)
                .collect()
        };
        assert!(!arrows(&run).is_empty());
        assert_eq!(arrows(&back), arrows(&run));
        // The same verdicts and, under the heading, the same summary.
        let verdicts = expect::judge(&run, &scenario.expect);
        let again = expect::judge(&back, &scenario.expect);
        let said = |v: &[crate::sim::Verdict]| -> Vec<(bool, String)> {
            v.iter().map(|v| (v.met, v.why.clone())).collect()
        };
        assert_eq!(said(&again), said(&verdicts));
        let body = |s: String| s.split_once('\n').unwrap().1.to_string();
        assert_eq!(
            body(crate::sim::replay_summary(&back, &again, 1)),
            body(summary(&run, &verdicts))
        );
    }

    #[test]
    fn each_robots_file_merges_into_one_run() {
        let (programs, _, run) = scouting();
        let mut files: Vec<String> = vec![String::new(); programs.len()];
        for e in &run.trace {
            files[e.robot].push_str(&e.to_json(&run.robots[e.robot].1));
            files[e.robot].push('\n');
        }
        files.reverse();
        let files: Vec<&str> = files.iter().map(String::as_str).collect();
        let back = replayed(&programs, &files).unwrap();
        // Per robot, the same lines in the same order; all in time order.
        let per_robot = |r: &Run, robot: usize| -> Vec<String> {
            r.trace
                .iter()
                .filter(|e| e.robot == robot)
                .map(|e| e.to_json(&r.robots[robot].1))
                .collect()
        };
        for robot in 0..programs.len() {
            assert_eq!(per_robot(&back, robot), per_robot(&run, robot));
        }
        assert!(back.trace.windows(2).all(|w| w[0].t <= w[1].t));
        assert_eq!(back.trace.len(), run.trace.len());
    }

    #[test]
    fn mistakes_are_positioned_with_a_did_you_mean() {
        let (programs, _, _) = scouting();
        let good = r#"{"t":0,"robot":"ti","event":"mode","mode":"AUTO_MODE"}"#;
        for (line, column, message, suggestion) in [
            (
                r#"{"t":0,"robot":"tii","event":"stop"}"#,
                16,
                "the mission has no robot \"tii\" (did you mean \"ti\"?)",
                Some("ti"),
            ),
            (
                r#"{"t":0,"robot":"zzzzzz","event":"stop"}"#,
                16,
                "the mission has no robot \"zzzzzz\"",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"mdoe","mode":"X"}"#,
                29,
                "unknown trace event \"mdoe\" (did you mean \"mode\"?)",
                Some("mode"),
            ),
            (
                r#"{"t":0,"robot":"ti","event":"mode","mode":"SEARCH"}"#,
                43,
                "robot \"ti\" has no mode \"SEARCH\" (did you mean \"SEARCH_MODE\"?)",
                Some("SEARCH_MODE"),
            ),
            (
                r#"{"t":0,"robot":"ti","event":"mode"}"#,
                29,
                "a \"mode\" line needs \"mode\"",
                None,
            ),
            (
                r#"{"t":-1,"robot":"ti","event":"stop"}"#,
                6,
                "\"t\" is whole mission milliseconds, 0 to 1000000000000000",
                None,
            ),
            (
                r#"{"t":1.5,"robot":"ti","event":"stop"}"#,
                6,
                "\"t\" is whole mission milliseconds, 0 to 1000000000000000",
                None,
            ),
            (
                r#"{"robot":"ti","event":"stop"}"#,
                1,
                "a trace line needs \"t\"",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"stop","colour":"x"}"#,
                45,
                "unknown field \"colour\" of a trace line",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"send","to":"x","key":"k","value":[1]}"#,
                63,
                "a value is a number, a string, true, false or null",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"send","to":1,"key":"k"}"#,
                41,
                "\"to\" is a string",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"start","team":"MasterTeam","type":"","mission":"scouting"}"#,
                44,
                "robot \"ti\" is of team \"SlaveTeam\" in the mission, not \"MasterTeam\"",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti"} x"#,
                22,
                "unexpected text after the trace line's object",
                None,
            ),
            (
                r#"[1]"#,
                1,
                "expected a trace event: an object {\"t\": ..., \"robot\": ..., \"event\": ...}",
                None,
            ),
            (
                r#"{"t":0,"robot":"ti","event":"mode","mode":"AUTO_MODE","mode":"X"}"#,
                55,
                "duplicate key \"mode\"",
                None,
            ),
            // Columns count characters, not bytes.
            (
                "{\"t\":0,\"robot\":\"ti\",\"event\":\"stop\",\"why\":\"é\",\"colour\":1}",
                55,
                "unknown field \"colour\" of a trace line",
                None,
            ),
            (
                "{\"t\":0,\"robot\":\"irobót\",\"event\":\"stop\"}",
                16,
                "the mission has no robot \"irobót\" (did you mean \"irobot\"?)",
                Some("irobot"),
            ),
            (
                r#"{"t":0,"robot":"ti","event":"stop"}{"t":1}"#,
                36,
                "unexpected text after the trace line's object",
                None,
            ),
        ] {
            let text = format!("{good}\n\n{line}\n");
            let e = replayed(&programs, &[&text]).unwrap_err();
            assert_eq!(
                (
                    e.line,
                    e.column,
                    e.message.as_str(),
                    e.suggestion.as_deref()
                ),
                (3, column, message, suggestion),
                "{line}"
            );
        }
        // Time goes back for one robot within a file; another's may lag.
        let back = format!("{good}\n{}\n", good.replace("\"t\":0", "\"t\":5"));
        let lagging = format!("{back}{}\n", good.replace("ti", "nxt"));
        assert!(replayed(&programs, &[&lagging]).is_ok());
        let e = replayed(&programs, &[&format!("{back}{good}\n")]).unwrap_err();
        assert_eq!((e.line, e.column), (3, 6), "{}", e.message);
        // Not UTF-8: at the first byte that is not.
        let mut replay = Replay::new(&programs);
        let e = replay
            .line(7, b"{\"t\":0,\"robot\":\"\xc3\xa9\xff\"}")
            .unwrap_err();
        assert_eq!(
            (e.line, e.column, e.message.as_str()),
            (7, 18, "not UTF-8 text")
        );
        let long = vec![b' '; MAX_LINE_BYTES + 1];
        assert_eq!(replay.line(8, &long).unwrap_err().line, 8);
    }

    #[test]
    fn no_cut_or_changed_line_panics() {
        let (programs, _, run) = scouting();
        let lines = run.trace_lines();
        // Every cut of a few lines of each kind, and each byte replaced by
        // a character that changes the JSON: an error at a place on the
        // line, or a line read.
        let mut seen = FastSet::default();
        for line in lines.lines() {
            let kind = line.split("\"event\":").nth(1).unwrap_or_default();
            let kind = kind.split(',').next().unwrap_or_default().to_string();
            if !seen.insert(kind) {
                continue;
            }
            for cut in 0..=line.len() {
                for variant in [
                    line.as_bytes()[..cut].to_vec(),
                    [&line.as_bytes()[..cut], b"\"", &line.as_bytes()[cut..]].concat(),
                    [&line.as_bytes()[..cut], &[0xff], &line.as_bytes()[cut..]].concat(),
                ] {
                    let mut replay = Replay::new(&programs);
                    if let Err(e) = replay.line(1, &variant) {
                        assert!(e.column >= 1 && e.column <= variant.len() as u64 + 1);
                    }
                }
            }
        }
        assert!(seen.len() > 8, "{seen:?}");
    }
}
