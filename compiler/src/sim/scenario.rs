//! The scenario file (`*.scenario.json`, schema version 1, documented in
//! `docs/scenario-and-trace.md`): what the world does around the robots
//! (timed sensor values, service durations, operator commands, the network,
//! faults) and what the run is expected to show. This is the one reader of
//! the format: a simulated robot program (`linux-sim`, `cortex-m-sim`) gets
//! its robot's part of the world compiled in by `semo build --scenario FILE`
//! ([`Scenario::compiled_for`], written as C tables by `codegen`), and reads
//! no file at run time.
//!
//! Every mistake is reported at the value that holds it (a byte offset,
//! turned into line and column by [`ScenarioError::line_col`]), including
//! names the mission does not have.

use super::json::{self, Kind, Value};
use crate::fasthash::{FastMap, FastSet};
use crate::refine::RobotProgram;

/// The schema version this reader understands.
pub const VERSION: i64 = 1;
/// A built-in service's duration when the scenario gives none (`semo_sim.c`).
pub const DEFAULT_SERVICE_MS: i64 = 100;
/// Longest time the scenario may name (the runtime's `MAX_MS`).
const MAX_MS: f64 = 1e15;
/// Largest battery level in size (the runtime's `MAX_LEVEL`): it and its
/// rounding fit an integer exactly.
const MAX_LEVEL: f64 = 1e15;
/// The time scales a program runs at (the runtime's `SEMO_TIME_SCALE_MIN`
/// and `SEMO_TIME_SCALE_MAX`, which bound its `--time-scale` too).
pub const TIME_SCALE: std::ops::RangeInclusive<f64> = 1e-6..=1e6;

/// The keys each kind of object of the format takes: the reader's one list
/// of each, which the editor's JSON Schema
/// (`vscode-extension/schemas/scenario.schema.json`: validation, completion
/// and hover of scenario files) must name exactly, no more and no fewer
/// (`the_schema_names_exactly_the_keys_the_reader_takes`, `sim/tests.rs`).
pub mod keys {
    pub const SCENARIO: &[&str] = &[
        "version",
        "time_scale",
        "duration",
        "robots",
        "operator",
        "network",
        "faults",
        "expect",
    ];
    pub const ROBOT: &[&str] = &["sensors", "services", "battery", "loops"];
    /// A service's entry when it gives results: `{"ms": 300, "results": [...]}`.
    pub const SERVICE: &[&str] = &["ms", "results"];
    pub const SENSOR: &[&str] = &["at", "value", "is"];
    pub const BATTERY: &[&str] = &["at", "level"];
    pub const COMMAND: &[&str] = &["at", "every", "from", "until", "to", "value", "is"];
    pub const NETWORK: &[&str] = &["latency", "loss", "links"];
    pub const LINK: &[&str] = &["between", "latency", "loss"];
    pub const FAULT: &[&str] = &[
        "at",
        "kill",
        "restart",
        "drop",
        "delay",
        "by",
        "partition",
        "from",
        "until",
    ];
    /// An `expect` entry that is a property of the run's instants.
    pub const PROPERTY: &[&str] = &["always", "eventually", "leads_to"];
    /// Any other `expect` entry.
    pub const EXPECTATION: &[&str] = &[
        "robot",
        "enters",
        "never_enters",
        "receives",
        "from",
        "before",
        "all_end_in",
    ];
    pub const CONDITION: &[&str] = &[
        "robot", "in", "enters", "receives", "from", "not", "all", "any",
    ];
}

#[derive(Clone, Debug, Default)]
pub struct Scenario {
    /// Mission ms the run lasts (`duration`; `None`: until every robot finished).
    pub duration_ms: Option<i64>,
    /// Wall ms per mission ms of a program run on the wall clock
    /// (`time_scale`; the simulator's time is virtual and ignores it).
    pub time_scale: Option<f64>,
    /// Per robot of the mission, by name.
    pub robots: Vec<RobotWorld>,
    pub operator: Vec<Command>,
    pub network: Network,
    pub faults: Vec<Fault>,
    pub expect: Vec<Expectation>,
    /// What the file says that has no effect on the run, likely a typo (a
    /// sensor value the robot does not sample): positioned as errors are.
    pub warnings: Vec<ScenarioError>,
}

#[derive(Clone, Debug, Default)]
pub struct RobotWorld {
    pub robot: String,
    /// (at, value name, value), in file order.
    pub sensors: Vec<(i64, String, String)>,
    pub services: Vec<(String, i64)>,
    /// (service, what each call gives back, in call order): see
    /// [`crate::refine::CompiledScenario::results`].
    pub results: Vec<(String, crate::refine::CallResults)>,
    /// (at, level): the `BATTERY` sensor value, linear between points.
    pub battery: Vec<(i64, f64)>,
    /// (SDF/L loop path, iteration): when a convergent loop's exit task
    /// sets the exit flag.
    pub loops: Vec<(String, u64)>,
}

/// An operator command: `USER.<value>` sent to a robot or team.
#[derive(Clone, Debug)]
pub struct Command {
    pub to: String,
    pub key: String,
    pub value: String,
    pub first: i64,
    pub every: Option<i64>,
    pub until: i64,
}

#[derive(Clone, Debug)]
pub struct Network {
    pub latency_ms: i64,
    pub loss: f64,
    /// Per pair of robots (either direction).
    pub links: Vec<Link>,
}

impl Default for Network {
    fn default() -> Self {
        Network {
            latency_ms: DEFAULT_LATENCY_MS,
            loss: 0.0,
            links: Vec::new(),
        }
    }
}

/// Delivery time of a message when the scenario names none: one mission ms.
pub const DEFAULT_LATENCY_MS: i64 = 1;

#[derive(Clone, Debug)]
pub struct Link {
    pub between: (String, String),
    pub latency_ms: Option<i64>,
    pub loss: Option<f64>,
}

#[derive(Clone, Debug)]
pub struct Fault {
    /// Byte offset of the fault's object (for pictures and messages).
    pub at_offset: usize,
    pub kind: FaultKind,
}

#[derive(Clone, Debug)]
pub enum FaultKind {
    /// The robot stops at `at` without a word (as a killed process).
    Kill { robot: String, at: i64 },
    /// The robot starts again from its default mode.
    Restart { robot: String, at: i64 },
    /// Messages between the two robots are lost during [from, until).
    Drop {
        between: (String, String),
        from: i64,
        until: i64,
    },
    /// Messages between the two robots take `by` ms longer during [from, until).
    Delay {
        between: (String, String),
        by: i64,
        from: i64,
        until: i64,
    },
    /// Robots in different groups cannot talk during [from, until).
    Partition {
        groups: Vec<Vec<String>>,
        from: i64,
        until: i64,
    },
}

#[derive(Clone, Debug)]
pub struct Expectation {
    /// Byte offset of the expectation's object in the scenario.
    pub at_offset: usize,
    pub kind: ExpectKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExpectKind {
    /// The robot enters the mode (at or) before `before` ms (any time if `None`).
    Enters {
        robot: String,
        mode: String,
        before: Option<i64>,
    },
    NeverEnters {
        robot: String,
        mode: String,
    },
    /// The robot receives `key` from robot `from` (any sender if `None`).
    Receives {
        robot: String,
        key: String,
        from: Option<String>,
        before: Option<i64>,
    },
    /// Every robot's last mode is this one.
    AllEndIn {
        mode: String,
    },
    /// The condition holds at every instant of the run.
    Always(Condition),
    /// The condition holds at some instant of the run.
    Eventually(Condition),
    /// Each instant at which the first condition holds is followed, at that
    /// instant or a later one, by one at which the second does.
    LeadsTo(Condition, Condition),
}

impl ExpectKind {
    /// The expectation as a scenario's `expect` entry (what `parse` reads
    /// back to the same expectation).
    pub fn to_json(&self) -> String {
        let text = |s: &str| {
            let mut out = String::new();
            super::trace::json_string(&mut out, s);
            out
        };
        let robot_and = |robot: &str, key: &str, value: &str| {
            format!("{{\"robot\": {}, \"{key}\": {}", text(robot), text(value))
        };
        let before = |b: &Option<i64>| b.map_or(String::new(), |b| format!(", \"before\": {b}"));
        match self {
            ExpectKind::Enters {
                robot,
                mode,
                before: b,
            } => format!("{}{}}}", robot_and(robot, "enters", mode), before(b)),
            ExpectKind::NeverEnters { robot, mode } => {
                format!("{}}}", robot_and(robot, "never_enters", mode))
            }
            ExpectKind::Receives {
                robot,
                key,
                from,
                before: b,
            } => format!(
                "{}{}{}}}",
                robot_and(robot, "receives", key),
                from.as_ref()
                    .map_or(String::new(), |f| format!(", \"from\": {}", text(f))),
                before(b)
            ),
            ExpectKind::AllEndIn { mode } => format!("{{\"all_end_in\": {}}}", text(mode)),
            ExpectKind::Always(c) => format!("{{\"always\": {}}}", c.to_json()),
            ExpectKind::Eventually(c) => format!("{{\"eventually\": {}}}", c.to_json()),
            ExpectKind::LeadsTo(a, b) => {
                format!("{{\"leads_to\": [{}, {}]}}", a.to_json(), b.to_json())
            }
        }
    }
}

impl Condition {
    /// The condition as a scenario's JSON.
    pub fn to_json(&self) -> String {
        let text = |s: &str| {
            let mut out = String::new();
            super::trace::json_string(&mut out, s);
            out
        };
        let list = |all: &[Condition]| {
            all.iter()
                .map(Condition::to_json)
                .collect::<Vec<_>>()
                .join(", ")
        };
        match self {
            Condition::In { robot, mode } => {
                format!("{{\"robot\": {}, \"in\": {}}}", text(robot), text(mode))
            }
            Condition::Enters { robot, mode } => {
                format!("{{\"robot\": {}, \"enters\": {}}}", text(robot), text(mode))
            }
            Condition::Receives { robot, key, from } => format!(
                "{{\"robot\": {}, \"receives\": {}{}}}",
                text(robot),
                text(key),
                from.as_ref()
                    .map_or(String::new(), |f| format!(", \"from\": {}", text(f)))
            ),
            Condition::Not(c) => format!("{{\"not\": {}}}", c.to_json()),
            Condition::All(all) => format!("{{\"all\": [{}]}}", list(all)),
            Condition::Any(any) => format!("{{\"any\": [{}]}}", list(any)),
        }
    }
}

/// What holds or not at an instant of a run (`temporal.rs`): the instant's
/// happenings and, at its end, each robot's mode.
#[derive(Clone, Debug, PartialEq)]
pub enum Condition {
    /// The robot is in the mode (running or finished in it; a killed robot
    /// is in none until it enters one again).
    In {
        robot: String,
        mode: String,
    },
    /// The robot enters the mode at this instant.
    Enters {
        robot: String,
        mode: String,
    },
    /// The robot takes a message of `key` (from robot `from`) at this
    /// instant.
    Receives {
        robot: String,
        key: String,
        from: Option<String>,
    },
    Not(Box<Condition>),
    All(Vec<Condition>),
    Any(Vec<Condition>),
}

impl std::fmt::Display for Condition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let joined = |f: &mut std::fmt::Formatter<'_>, all: &[Condition], word: &str| {
            write!(f, "(")?;
            for (i, c) in all.iter().enumerate() {
                if i > 0 {
                    write!(f, " {word} ")?;
                }
                write!(f, "{c}")?;
            }
            write!(f, ")")
        };
        match self {
            Condition::In { robot, mode } => write!(f, "{robot} in {mode}"),
            Condition::Enters { robot, mode } => write!(f, "{robot} enters {mode}"),
            Condition::Receives { robot, key, from } => {
                write!(f, "{robot} receives {key}")?;
                match from {
                    Some(from) => write!(f, " from {from}"),
                    None => Ok(()),
                }
            }
            Condition::Not(c) => write!(f, "not {c}"),
            Condition::All(all) => joined(f, all, "and"),
            Condition::Any(any) => joined(f, any, "or"),
        }
    }
}

impl std::fmt::Display for ExpectKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExpectKind::Enters {
                robot,
                mode,
                before,
            } => {
                write!(f, "{robot} enters {mode}")?;
                if let Some(t) = before {
                    write!(f, " before {t} ms")?;
                }
                Ok(())
            }
            ExpectKind::NeverEnters { robot, mode } => write!(f, "{robot} never enters {mode}"),
            ExpectKind::Receives {
                robot,
                key,
                from,
                before,
            } => {
                write!(f, "{robot} receives {key}")?;
                if let Some(from) = from {
                    write!(f, " from {from}")?;
                }
                if let Some(t) = before {
                    write!(f, " before {t} ms")?;
                }
                Ok(())
            }
            ExpectKind::AllEndIn { mode } => write!(f, "all robots end in {mode}"),
            ExpectKind::Always(c) => write!(f, "always {c}"),
            ExpectKind::Eventually(c) => write!(f, "eventually {c}"),
            ExpectKind::LeadsTo(a, b) => write!(f, "{a} leads to {b}"),
        }
    }
}

/// A mistake in the scenario (or a warning), at a byte offset of its text.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    pub at: usize,
    /// What is wrong, a did-you-mean included.
    pub message: String,
    /// The name the user most likely meant, for an unknown one close to it.
    pub suggestion: Option<String>,
}

impl ScenarioError {
    /// 1-based line and column (in characters) of the mistake.
    pub fn line_col(&self, text: &str) -> (u32, u32) {
        let index = crate::text::LineIndex::new(text);
        let lc = index.line_col(text, self.at, crate::text::ColumnUnit::Char);
        (lc.line + 1, lc.col + 1)
    }
}

type Result<T> = std::result::Result<T, ScenarioError>;

/// The one member of `kinds` that the object `v` has (`what`: "a fault"),
/// else an error at `v` listing them.
fn one_of(v: &Value, what: &str, kinds: &[&'static str]) -> Result<&'static str> {
    let mut given = kinds.iter().copied().filter(|k| v.member(k).is_some());
    match (given.next(), given.next()) {
        (Some(kind), None) => Ok(kind),
        _ => {
            let listed: Vec<String> = kinds.iter().map(|k| format!("\"{k}\"")).collect();
            fail(v, format!("{what} is exactly one of {}", listed.join(", ")))
        }
    }
}

fn fail<T>(v: &Value, message: impl Into<String>) -> Result<T> {
    Err(ScenarioError {
        at: v.at,
        message: message.into(),
        suggestion: None,
    })
}

/// [`fail`] about the unknown `name`, with a did-you-mean ([`suggesting`]).
fn fail_suggesting<T>(v: &Value, message: String, name: &str, known: &[&str]) -> Result<T> {
    Err(suggesting(v, message, name, known))
}

/// `message` at `v` about the unknown `name`, with the known name closest
/// to it as a did-you-mean when one is close enough to be a typo.
fn suggesting(v: &Value, message: String, name: &str, known: &[&str]) -> ScenarioError {
    let suggestion = crate::suggest::did_you_mean(name, known.iter().copied());
    ScenarioError {
        at: v.at,
        message: match &suggestion {
            Some(close) => format!("{message} (did you mean \"{close}\"?)"),
            None => message,
        },
        suggestion,
    }
}

impl Scenario {
    /// [`Scenario::compiled_for`] each program, in order: the worlds a
    /// simulated build compiles in (`codegen::build_refined_each`).
    pub fn compiled_for_each(
        &self,
        programs: &[RobotProgram],
    ) -> Vec<crate::refine::CompiledScenario> {
        let lookup = Lookup::of(self);
        programs
            .iter()
            .map(|p| self.compiled_with(p, &lookup))
            .collect()
    }

    /// The world of `program`'s robot, to compile into a simulated program
    /// (`semo build --target linux-sim|cortex-m-sim --scenario FILE`):
    /// everything the program itself reads or does from the scenario. Its
    /// sensors, battery, services and loop exits; the operator's commands
    /// to it or its team; the link faults on its messages (what
    /// [`super::engine`]'s `link` applies to a message this robot sends);
    /// the run's duration and time scale. Process faults (kill, restart)
    /// and the network's latency and loss are not in it: the lock-step
    /// coordinator applies those from outside (`semo simulate --engine c`).
    pub fn compiled_for(&self, program: &RobotProgram) -> crate::refine::CompiledScenario {
        self.compiled_with(program, &Lookup::of(self))
    }

    /// [`Scenario::compiled_for`] with the scenario's entries found through
    /// `lookup`, built once for a whole fleet: each robot's part is then
    /// found without walking every robot's (a swarm's build was quadratic).
    fn compiled_with(
        &self,
        program: &RobotProgram,
        lookup: &Lookup<'_>,
    ) -> crate::refine::CompiledScenario {
        use crate::refine::{CompiledLink, LinkEffect, OperatorCommand};
        let world = lookup.worlds.get(program.robot.as_str()).copied();
        let me = program.robot.as_str();
        let mission_robots = || program.peers.iter().map(|(_, robot)| robot.as_str());
        let links = (self.faults.iter().zip(&lookup.partitions))
            .filter_map(|(fault, group_of)| {
                let (effect, from, until, robots) = match &fault.kind {
                    FaultKind::Kill { .. } | FaultKind::Restart { .. } => return None,
                    FaultKind::Drop {
                        between,
                        from,
                        until,
                    } => (LinkEffect::Lost, *from, *until, other_end(between, me)?),
                    FaultKind::Delay {
                        between,
                        by,
                        from,
                        until,
                    } => (
                        LinkEffect::Delayed(*by),
                        *from,
                        *until,
                        other_end(between, me)?,
                    ),
                    FaultKind::Partition { from, until, .. } => {
                        // Robots of different groups (no group is one more)
                        // cannot talk: the engine's `link`.
                        let group_of = |robot: &str| group_of.get(robot).copied();
                        let mine = group_of(me);
                        let cut: Vec<String> = mission_robots()
                            .filter(|&robot| robot != me && group_of(robot) != mine)
                            .map(str::to_string)
                            .collect();
                        (LinkEffect::Lost, *from, *until, cut)
                    }
                };
                (!robots.is_empty()).then_some(CompiledLink {
                    effect,
                    from,
                    until,
                    robots,
                })
            })
            .collect();
        crate::refine::CompiledScenario {
            duration_ms: self.duration_ms,
            time_scale: self.time_scale,
            sensors: world.map(|w| w.sensors.clone()).unwrap_or_default(),
            services: world.map(|w| w.services.clone()).unwrap_or_default(),
            results: world.map(|w| w.results.clone()).unwrap_or_default(),
            battery: world.map(|w| w.battery.clone()).unwrap_or_default(),
            loops: world.map(|w| w.loops.clone()).unwrap_or_default(),
            operator: lookup
                .operator_to(&program.robot, &program.team)
                .map(|c| OperatorCommand {
                    key: c.key.clone(),
                    value: c.value.clone(),
                    first: c.first,
                    every: c.every,
                    until: c.until,
                })
                .collect(),
            links,
        }
    }
}

/// The scenario's entries by the robot they concern, for
/// [`Scenario::compiled_with`].
struct Lookup<'s> {
    worlds: FastMap<&'s str, &'s RobotWorld>,
    /// The operator's commands by their `to` (a robot or a team), each list
    /// in file order, with its index in the file to merge a robot's and its
    /// team's back into file order.
    operator: FastMap<&'s str, Vec<(usize, &'s Command)>>,
    /// Per fault, in order: for a partition, each robot's group (a robot
    /// in none is absent); empty for the other faults.
    partitions: Vec<FastMap<&'s str, usize>>,
}

impl<'s> Lookup<'s> {
    fn of(scenario: &'s Scenario) -> Self {
        let worlds = (scenario.robots.iter())
            .map(|w| (w.robot.as_str(), w))
            .collect();
        let mut operator: FastMap<&str, Vec<(usize, &Command)>> = FastMap::default();
        for (i, c) in scenario.operator.iter().enumerate() {
            operator.entry(c.to.as_str()).or_default().push((i, c));
        }
        let partitions = (scenario.faults.iter())
            .map(|fault| match &fault.kind {
                FaultKind::Partition { groups, .. } => (groups.iter().enumerate())
                    .flat_map(|(g, members)| members.iter().map(move |m| (m.as_str(), g)))
                    // The first group naming a robot is its group.
                    .rev()
                    .collect(),
                _ => FastMap::default(),
            })
            .collect();
        Lookup {
            worlds,
            operator,
            partitions,
        }
    }

    /// The commands to `robot` or to its `team`, in file order.
    fn operator_to(&self, robot: &str, team: &str) -> impl Iterator<Item = &'s Command> {
        let of = |to: &str| self.operator.get(to).into_iter().flatten().copied();
        let mut both: Vec<(usize, &Command)> = of(robot).collect();
        if team != robot {
            both.extend(of(team));
            both.sort_by_key(|(i, _)| *i);
        }
        both.into_iter().map(|(_, c)| c)
    }
}

/// The robot at the other end of a link fault `between` two robots, as
/// the robots whose messages from `me` it touches: none when `me` is at
/// neither end.
fn other_end(between: &(String, String), me: &str) -> Option<Vec<String>> {
    let (a, b) = between;
    match (a == me, b == me) {
        (true, _) => Some(vec![b.clone()]),
        (false, true) => Some(vec![a.clone()]),
        (false, false) => None,
    }
}

/// Reads a scenario and checks its names against the mission's programs.
pub fn parse(text: &str, programs: &[RobotProgram]) -> Result<Scenario> {
    let root = json::parse(text).map_err(|e| ScenarioError {
        at: e.at,
        message: e.message,
        suggestion: None,
    })?;
    let by_robot = programs.iter().map(|p| (p.robot.as_str(), p)).collect();
    let teams = programs.iter().map(|p| p.team.as_str()).collect();
    Reader {
        programs,
        by_robot,
        teams,
        every_mode: std::cell::OnceCell::new(),
    }
    .scenario(&root)
}

struct Reader<'a> {
    programs: &'a [RobotProgram],
    /// Each robot's program: a scenario names robots one entry at a time,
    /// and a lookup per entry must not walk the fleet (a swarm's scenario
    /// would cost the square of its robots).
    by_robot: FastMap<&'a str, &'a RobotProgram>,
    teams: FastSet<&'a str>,
    /// The modes of every team, made at the first expectation about every
    /// robot (`all_end_in`): one walk of the fleet, not one per expectation.
    every_mode: std::cell::OnceCell<FastSet<&'a str>>,
}

fn object<'v>(v: &'v Value, what: &str, keys: &[&str]) -> Result<&'v [(String, Value)]> {
    let Kind::Object(members) = &v.kind else {
        return fail(v, format!("expected {what}"));
    };
    for (key, value) in members {
        if !keys.contains(&key.as_str()) {
            return fail(
                value,
                format!(
                    "unknown key \"{key}\" in {what} (expected one of: {})",
                    keys.join(", ")
                ),
            );
        }
    }
    Ok(members)
}

fn array<'v>(v: &'v Value, what: &str) -> Result<&'v [Value]> {
    match &v.kind {
        Kind::Array(items) => Ok(items),
        _ => fail(v, format!("expected {what}")),
    }
}

fn require<'v>(object: &'v Value, key: &str) -> Result<&'v Value> {
    match object.member(key) {
        Some(v) => Ok(v),
        None => fail(object, format!("missing \"{key}\"")),
    }
}

fn ms(v: &Value, key: &str, min: i64) -> Result<i64> {
    match &v.kind {
        Kind::Number(n, _) if *n >= min as f64 && *n <= MAX_MS && n.fract() == 0.0 => Ok(*n as i64),
        _ => fail(
            v,
            format!(
                "\"{key}\" must be a whole number of milliseconds{}",
                if min > 0 { " above 0" } else { "" }
            ),
        ),
    }
}

/// A service's `results`: per call, in call order, an array of what it
/// gives back in the order of the service's results (`true`, `"3,4"`, `2`;
/// `null` for none), checked against `gives` (what the service gives back,
/// as the robot's refined program has it from the catalog; `None` when the
/// robot never calls the service, so nothing reads the entry): a service
/// that gives nothing back, more values than it gives, or a value its
/// result's type does not read (which the call would take as none) is
/// refused at the value that holds it.
fn call_results(
    v: &Value,
    service: &str,
    gives: Option<&crate::refine::ServiceResults>,
) -> Result<crate::refine::CallResults> {
    const WHAT: &str = "an array of each call's results, [[true, \"3,4\"], [false]]";
    if let Some(gives) = gives
        && gives.results.is_empty()
    {
        return fail(
            v,
            format!(
                "service {service} gives nothing back: \"results\" are for a service with results"
            ),
        );
    }
    let mut calls = Vec::new();
    for call in array(v, WHAT)? {
        let mut values = Vec::new();
        for (k, value) in array(call, WHAT)?.iter().enumerate() {
            let text = match &value.kind {
                Kind::Null => None,
                Kind::Bool(b) => Some(b.to_string()),
                Kind::Number(_, text) => Some(text.clone()),
                Kind::String(text) => Some(text.clone()),
                _ => return fail(value, "a result is true, false, a number, a string or null"),
            };
            if let Some(gives) = gives {
                let Some((name, kind)) = gives.results.get(k) else {
                    let names: Vec<&str> = gives.results.iter().map(|(n, _)| n.as_str()).collect();
                    return fail(
                        value,
                        format!(
                            "service {service} gives back {} ({}): this call has more values",
                            match names.len() {
                                1 => "1 result".to_string(),
                                n => format!("{n} results"),
                            },
                            names.join(", ")
                        ),
                    );
                };
                if let Some(text) = &text
                    && kind.parse(text).is_none()
                {
                    return fail(
                        value,
                        format!(
                            "result {name} of {service} must be a value of its type ({}), not {text:?}",
                            kind.describe()
                        ),
                    );
                }
            }
            values.push(text);
        }
        calls.push(values);
    }
    Ok(calls)
}

fn opt_ms(object: &Value, key: &str, min: i64) -> Result<Option<i64>> {
    object.member(key).map(|v| ms(v, key, min)).transpose()
}

fn name<'v>(v: &'v Value, key: &str) -> Result<&'v str> {
    match &v.kind {
        Kind::String(s) if !s.is_empty() && s.len() < 48 => Ok(s),
        _ => fail(
            v,
            format!("\"{key}\" must be a non-empty string shorter than 48 bytes"),
        ),
    }
}

/// `"is"`: a string, or a number as written.
fn value_text(v: &Value) -> Result<String> {
    match &v.kind {
        Kind::String(s) | Kind::Number(_, s) if s.len() < 64 => Ok(s.clone()),
        _ => fail(v, "\"is\" must be a string or number shorter than 64 bytes"),
    }
}

fn probability(v: &Value, key: &str) -> Result<f64> {
    match &v.kind {
        Kind::Number(n, _) if (0.0..=1.0).contains(n) => Ok(*n),
        _ => fail(v, format!("\"{key}\" must be a number from 0 to 1")),
    }
}

impl Reader<'_> {
    fn robot(&self, v: &Value, key: &str) -> Result<String> {
        let robot = name(v, key)?;
        self.known_robot(v, robot)?;
        Ok(robot.to_string())
    }

    /// Fails at `v` unless `robot` is a robot of the mission.
    fn known_robot(&self, v: &Value, robot: &str) -> Result<()> {
        if self.by_robot.contains_key(robot) {
            return Ok(());
        }
        let known: Vec<&str> = self.programs.iter().map(|p| p.robot.as_str()).collect();
        let message = format!(
            "robot \"{robot}\" is not in the mission (robots: {})",
            known.join(", ")
        );
        fail_suggesting(v, message, robot, &known)
    }

    fn robot_or_team(&self, v: &Value, key: &str) -> Result<String> {
        let to = name(v, key)?;
        if self.by_robot.contains_key(to) || self.teams.contains(to) {
            return Ok(to.to_string());
        }
        let known: Vec<&str> = self
            .programs
            .iter()
            .flat_map(|p| [p.robot.as_str(), p.team.as_str()])
            .collect();
        let message = format!("\"{to}\" is neither a robot nor a team of the mission");
        fail_suggesting(v, message, to, &known)
    }

    /// A warning at `v` unless `robot`'s program samples the sensor value
    /// `value` (one of its sensor tasks' values): nobody would read it. A
    /// warning, not an error: one scenario may serve variants of a mission,
    /// not all of which read every value.
    fn unsampled(&self, v: &Value, robot: &str, value: &str) -> Option<ScenarioError> {
        let mut sampled: Vec<&str> = (self.by_robot.get(robot).into_iter())
            .flat_map(|p| &p.tasks)
            .filter_map(|t| match &t.kind {
                crate::refine::RoleKind::Sensor { values, .. } => Some(values),
                _ => None,
            })
            .flatten()
            .map(String::as_str)
            .collect();
        if sampled.contains(&value) {
            return None;
        }
        sampled.sort_unstable();
        sampled.dedup();
        let listed = if sampled.is_empty() {
            "none".to_string()
        } else {
            sampled.join(", ")
        };
        let message = format!(
            "robot {robot} samples no sensor value \"{value}\": nothing reads this entry (it samples: {listed})"
        );
        Some(suggesting(v, message, value, &sampled))
    }

    /// What `service` gives back as `robot`'s program calls it (its
    /// catalog's results, `ControlMachine::gives_back`); `None` when the
    /// robot never calls it.
    fn gives_back(&self, robot: &str, service: &str) -> Option<&crate::refine::ServiceResults> {
        self.by_robot
            .get(robot)?
            .control
            .gives_back
            .iter()
            .find(|g| g.service == service)
    }

    /// A mode of `robot`'s team (or of any team when `robot` is `None`).
    fn mode(&self, v: &Value, key: &str, robot: Option<&str>) -> Result<String> {
        let mode = name(v, key)?;
        let mut known: Vec<&str> = match robot {
            Some(robot) => {
                let modes = self
                    .by_robot
                    .get(robot)
                    .map_or(&[][..], |p| &p.control.modes[..]);
                if modes.iter().any(|m| m.name == mode) {
                    return Ok(mode.to_string());
                }
                modes.iter().map(|m| m.name.as_str()).collect()
            }
            None => {
                let every_mode = self.every_mode.get_or_init(|| {
                    (self.programs.iter())
                        .flat_map(|p| p.control.modes.iter().map(|m| m.name.as_str()))
                        .collect()
                });
                if every_mode.contains(mode) {
                    return Ok(mode.to_string());
                }
                every_mode.iter().copied().collect()
            }
        };
        known.sort_unstable();
        known.dedup();
        // No did-you-mean: modes share their `_MODE` endings, so the
        // closest one is often another mode, not the one meant.
        fail(
            v,
            format!(
                "no mode \"{mode}\"{} (modes: {})",
                robot.map_or(String::new(), |r| format!(" for robot {r}")),
                known.join(", ")
            ),
        )
    }

    fn pair(&self, v: &Value, key: &str) -> Result<(String, String)> {
        let items = array(v, &format!("\"{key}\": two robot names"))?;
        if items.len() != 2 {
            return fail(v, format!("\"{key}\" must name two robots"));
        }
        Ok((self.robot(&items[0], key)?, self.robot(&items[1], key)?))
    }

    fn scenario(&self, root: &Value) -> Result<Scenario> {
        object(
            root,
            "a scenario object {\"robots\": ..., \"operator\": ...}",
            keys::SCENARIO,
        )?;
        let mut scenario = Scenario::default();
        if let Some(v) = root.member("version") {
            match &v.kind {
                Kind::Number(n, _) if *n == VERSION as f64 => {}
                _ => return fail(v, format!("\"version\" must be {VERSION}")),
            }
        }
        if let Some(v) = root.member("time_scale") {
            match &v.kind {
                Kind::Number(n, _) if TIME_SCALE.contains(n) => scenario.time_scale = Some(*n),
                _ => {
                    return fail(
                        v,
                        "\"time_scale\" must be a positive number from 0.000001 (a million times faster) to 1000000",
                    );
                }
            }
        }
        scenario.duration_ms = opt_ms(root, "duration", 0)?;
        if let Some(robots) = root.member("robots") {
            let Kind::Object(members) = &robots.kind else {
                return fail(robots, "expected an object of robots {\"name\": {...}}");
            };
            for (robot, v) in members {
                let world = self.robot_world(robot, v, &mut scenario.warnings)?;
                scenario.robots.push(world);
            }
        }
        if let Some(commands) = root.member("operator") {
            for v in array(commands, "an array of operator commands")? {
                scenario.operator.push(self.command(v)?);
            }
        }
        if let Some(v) = root.member("network") {
            scenario.network = self.network(v)?;
        }
        if let Some(faults) = root.member("faults") {
            for v in array(faults, "an array of faults")? {
                scenario.faults.push(self.fault(v)?);
            }
        }
        if let Some(expect) = root.member("expect") {
            for v in array(expect, "an array of expectations")? {
                scenario.expect.push(self.expectation(v)?);
            }
        }
        Ok(scenario)
    }

    fn robot_world(
        &self,
        robot: &str,
        v: &Value,
        warnings: &mut Vec<ScenarioError>,
    ) -> Result<RobotWorld> {
        self.known_robot(v, robot)?;
        object(
            v,
            "a robot {\"sensors\": [...], \"services\": {...}, \"battery\": [...], \"loops\": {...}}",
            keys::ROBOT,
        )?;
        let mut world = RobotWorld {
            robot: robot.to_string(),
            ..RobotWorld::default()
        };
        if let Some(sensors) = v.member("sensors") {
            for entry in array(sensors, "an array of sensor entries")? {
                object(
                    entry,
                    "a sensor entry {\"at\", \"value\", \"is\"}",
                    keys::SENSOR,
                )?;
                let at = ms(require(entry, "at")?, "at", 0)?;
                let value_at = require(entry, "value")?;
                let value = name(value_at, "value")?.to_string();
                warnings.extend(self.unsampled(value_at, robot, &value));
                let is_value = require(entry, "is")?;
                let is = value_text(is_value)?;
                // Read as the catalog's type of the value, as the sensor task
                // reads it (`semo_sim_sensor`): say so here, not by silence.
                let kind = (self.by_robot.get(robot).into_iter())
                    .flat_map(|p| &p.control.slots)
                    .find_map(|s| match &s.source {
                        crate::refine::SlotSource::Sensor { port, .. } if *port == value => {
                            Some(&s.kind)
                        }
                        _ => None,
                    });
                if let Some(kind) = kind
                    && kind.parse(&is).is_none()
                {
                    return fail(
                        is_value,
                        format!(
                            "\"is\" must be a value of {value}'s type ({}), not {is:?}",
                            kind.describe()
                        ),
                    );
                }
                world.sensors.push((at, value, is));
            }
        }
        if let Some(services) = v.member("services") {
            let Kind::Object(members) = &services.kind else {
                return fail(
                    services,
                    "expected an object of service durations {\"move\": 300}",
                );
            };
            for (service, d) in members {
                if let Kind::Object(_) = d.kind {
                    // `{"ms": 300, "results": [[true, "3,4"], [false]]}`.
                    object(
                        d,
                        "a service {\"ms\": 300, \"results\": [[...], ...]}",
                        keys::SERVICE,
                    )?;
                    if let Some(t) = opt_ms(d, "ms", 0)? {
                        world.services.push((service.clone(), t));
                    }
                    if let Some(results) = d.member("results") {
                        let gives = self.gives_back(robot, service);
                        world
                            .results
                            .push((service.clone(), call_results(results, service, gives)?));
                    }
                    continue;
                }
                world.services.push((service.clone(), ms(d, service, 0)?));
            }
        }
        if let Some(loops) = v.member("loops") {
            let Kind::Object(members) = &loops.kind else {
                return fail(loops, "expected an object of loop exits {\"Converge\": 3}");
            };
            for (path, n) in members {
                let iteration = match n.kind {
                    Kind::Number(x, _) if (1.0..=1e9).contains(&x) && x.fract() == 0.0 => x as u64,
                    _ => {
                        return fail(
                            n,
                            format!("\"{path}\" must be a whole number of iterations, 1 or more"),
                        );
                    }
                };
                world.loops.push((path.clone(), iteration));
            }
        }
        if let Some(battery) = v.member("battery") {
            let mut last = -1;
            for entry in array(battery, "an array of battery levels {\"at\", \"level\"}")? {
                object(entry, "a battery level {\"at\", \"level\"}", keys::BATTERY)?;
                let at_value = require(entry, "at")?;
                let at = ms(at_value, "at", 0)?;
                if at <= last {
                    return fail(at_value, "battery levels must be in time order");
                }
                last = at;
                let level = require(entry, "level")?;
                let Kind::Number(n, _) = level.kind else {
                    return fail(level, "\"level\" must be a number");
                };
                // As the runtime's reader: a level that rounds to an
                // integer exactly (heartbeats carry it as one).
                if n.abs() > MAX_LEVEL {
                    return fail(level, "\"level\" must be between -1e15 and 1e15");
                }
                world.battery.push((at, n));
            }
        }
        Ok(world)
    }

    fn command(&self, v: &Value) -> Result<Command> {
        object(
            v,
            "an operator command {\"at\"|\"every\", \"to\", \"value\", \"is\"}",
            keys::COMMAND,
        )?;
        let to = self.robot_or_team(require(v, "to")?, "to")?;
        let key = format!("USER.{}", name(require(v, "value")?, "value")?);
        let value = value_text(require(v, "is")?)?;
        let (at, every) = (v.member("at"), v.member("every"));
        if at.is_some() == every.is_some() {
            return fail(v, "an operator command needs either \"at\" or \"every\"");
        }
        if at.is_some() && (v.member("from").is_some() || v.member("until").is_some()) {
            return fail(v, "\"from\" and \"until\" go with \"every\", not \"at\"");
        }
        Ok(match at {
            Some(at) => {
                let at = ms(at, "at", 0)?;
                Command {
                    to,
                    key,
                    value,
                    first: at,
                    every: None,
                    until: at,
                }
            }
            None => Command {
                to,
                key,
                value,
                first: opt_ms(v, "from", 0)?.unwrap_or(0),
                every: Some(ms(every.unwrap_or(v), "every", 1)?),
                until: opt_ms(v, "until", 0)?.unwrap_or(MAX_MS as i64),
            },
        })
    }

    fn network(&self, v: &Value) -> Result<Network> {
        object(
            v,
            "a network {\"latency\", \"loss\", \"links\"}",
            keys::NETWORK,
        )?;
        let mut network = Network {
            latency_ms: opt_ms(v, "latency", 0)?.unwrap_or(DEFAULT_LATENCY_MS),
            loss: v
                .member("loss")
                .map(|l| probability(l, "loss"))
                .transpose()?
                .unwrap_or(0.0),
            links: Vec::new(),
        };
        if let Some(links) = v.member("links") {
            for link in array(links, "an array of links")? {
                object(
                    link,
                    "a link {\"between\", \"latency\", \"loss\"}",
                    keys::LINK,
                )?;
                network.links.push(Link {
                    between: self.pair(require(link, "between")?, "between")?,
                    latency_ms: opt_ms(link, "latency", 0)?,
                    loss: link
                        .member("loss")
                        .map(|l| probability(l, "loss"))
                        .transpose()?,
                });
            }
        }
        Ok(network)
    }

    fn interval(&self, v: &Value) -> Result<(i64, i64)> {
        let from = ms(require(v, "from")?, "from", 0)?;
        let until_value = require(v, "until")?;
        let until = ms(until_value, "until", 0)?;
        if until <= from {
            return fail(until_value, "\"until\" must be after \"from\"");
        }
        Ok((from, until))
    }

    fn fault(&self, v: &Value) -> Result<Fault> {
        object(
            v,
            "a fault {\"kill\"|\"restart\"|\"drop\"|\"delay\"|\"partition\", ...}",
            keys::FAULT,
        )?;
        let given = one_of(
            v,
            "a fault",
            &["kill", "restart", "drop", "delay", "partition"],
        )?;
        let kind = match given {
            "kill" | "restart" => {
                let robot = self.robot(require(v, given)?, given)?;
                let at = ms(require(v, "at")?, "at", 0)?;
                if given == "kill" {
                    FaultKind::Kill { robot, at }
                } else {
                    FaultKind::Restart { robot, at }
                }
            }
            "drop" => {
                let (from, until) = self.interval(v)?;
                FaultKind::Drop {
                    between: self.pair(require(v, "drop")?, "drop")?,
                    from,
                    until,
                }
            }
            "delay" => {
                let (from, until) = self.interval(v)?;
                FaultKind::Delay {
                    between: self.pair(require(v, "delay")?, "delay")?,
                    by: ms(require(v, "by")?, "by", 0)?,
                    from,
                    until,
                }
            }
            _ => {
                let (from, until) = self.interval(v)?;
                let partition = require(v, "partition")?;
                let mut groups = Vec::new();
                for group in array(partition, "an array of groups of robot names")? {
                    let robots = array(group, "a group: an array of robot names")?;
                    groups.push(
                        robots
                            .iter()
                            .map(|r| self.robot(r, "partition"))
                            .collect::<Result<Vec<_>>>()?,
                    );
                }
                FaultKind::Partition {
                    groups,
                    from,
                    until,
                }
            }
        };
        Ok(Fault {
            at_offset: v.at,
            kind,
        })
    }

    fn expectation(&self, v: &Value) -> Result<Expectation> {
        if keys::PROPERTY.iter().any(|k| v.member(k).is_some()) {
            object(
                v,
                "a property {\"always\"|\"eventually\": CONDITION} or {\"leads_to\": [CONDITION, CONDITION]}",
                keys::PROPERTY,
            )?;
            let given = one_of(v, "a property", keys::PROPERTY)?;
            let value = require(v, given)?;
            let kind = match given {
                "always" => ExpectKind::Always(self.condition(value)?),
                "eventually" => ExpectKind::Eventually(self.condition(value)?),
                _ => match array(value, "[CONDITION, CONDITION]")? {
                    [from, to] => ExpectKind::LeadsTo(self.condition(from)?, self.condition(to)?),
                    _ => {
                        return fail(
                            value,
                            "\"leads_to\" takes two conditions: [CONDITION, CONDITION]",
                        );
                    }
                },
            };
            return Ok(Expectation {
                at_offset: v.at,
                kind,
            });
        }
        object(
            v,
            "an expectation {\"robot\", \"enters\"|\"never_enters\"|\"receives\", ...} or {\"all_end_in\"}",
            keys::EXPECTATION,
        )?;
        let given = one_of(
            v,
            "an expectation",
            &["enters", "never_enters", "receives", "all_end_in"],
        )?;
        let before = opt_ms(v, "before", 0)?;
        let kind = if given == "all_end_in" {
            if let Some(extra) = v.member("robot").or(v.member("before")) {
                return fail(
                    extra,
                    "\"all_end_in\" is about every robot: no \"robot\" or \"before\"",
                );
            }
            ExpectKind::AllEndIn {
                mode: self.mode(require(v, "all_end_in")?, "all_end_in", None)?,
            }
        } else {
            let robot = self.robot(require(v, "robot")?, "robot")?;
            match given {
                "enters" => ExpectKind::Enters {
                    mode: self.mode(require(v, "enters")?, "enters", Some(&robot))?,
                    robot,
                    before,
                },
                "never_enters" => {
                    if let Some(b) = v.member("before") {
                        return fail(b, "\"never_enters\" takes no \"before\"");
                    }
                    ExpectKind::NeverEnters {
                        mode: self.mode(
                            require(v, "never_enters")?,
                            "never_enters",
                            Some(&robot),
                        )?,
                        robot,
                    }
                }
                _ => ExpectKind::Receives {
                    key: name(require(v, "receives")?, "receives")?.to_string(),
                    from: v
                        .member("from")
                        .map(|f| self.robot(f, "from"))
                        .transpose()?,
                    robot,
                    before,
                },
            }
        };
        if given != "receives"
            && let Some(from) = v.member("from")
        {
            return fail(from, "\"from\" goes with \"receives\"");
        }
        Ok(Expectation {
            at_offset: v.at,
            kind,
        })
    }

    /// A condition of `always`, `eventually` or `leads_to` (nesting is
    /// bounded by the JSON reader's depth).
    fn condition(&self, v: &Value) -> Result<Condition> {
        const KINDS: [&str; 6] = ["in", "enters", "receives", "not", "all", "any"];
        object(
            v,
            "a condition {\"robot\", \"in\"|\"enters\"|\"receives\", \"from\"?} or {\"not\"|\"all\"|\"any\"}",
            keys::CONDITION,
        )?;
        let given = one_of(v, "a condition", &KINDS)?;
        let about_robot = matches!(given, "in" | "enters" | "receives");
        if !about_robot && let Some(extra) = v.member("robot").or(v.member("from")) {
            return fail(
                extra,
                format!("\"{given}\" combines conditions: no \"robot\" or \"from\" beside it"),
            );
        }
        if given != "receives"
            && let Some(from) = v.member("from")
        {
            return fail(from, "\"from\" goes with \"receives\"");
        }
        let value = require(v, given)?;
        let several = |what: &str| -> Result<Vec<Condition>> {
            let items = array(value, "an array of conditions")?;
            if items.is_empty() {
                return fail(value, format!("\"{what}\" needs at least one condition"));
            }
            items.iter().map(|c| self.condition(c)).collect()
        };
        Ok(match given {
            "not" => Condition::Not(Box::new(self.condition(value)?)),
            "all" => Condition::All(several("all")?),
            "any" => Condition::Any(several("any")?),
            _ => {
                let robot = self.robot(require(v, "robot")?, "robot")?;
                match given {
                    "in" => Condition::In {
                        mode: self.mode(value, "in", Some(&robot))?,
                        robot,
                    },
                    "enters" => Condition::Enters {
                        mode: self.mode(value, "enters", Some(&robot))?,
                        robot,
                    },
                    _ => Condition::Receives {
                        key: name(value, "receives")?.to_string(),
                        from: v
                            .member("from")
                            .map(|f| self.robot(f, "from"))
                            .transpose()?,
                        robot,
                    },
                }
            }
        })
    }
}
