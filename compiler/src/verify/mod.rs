//! `semo verify`: everything the team can do, explored on the simulator's
//! own step semantics (the refined programs `semo build` turns into C, run
//! by [`crate::sim::Sim`]; no second meaning), with nothing for the user to
//! write.
//!
//! - `inputs.rs`: the world's choices, from the programs' comparisons.
//! - `search.rs`: the breadth-first search over the fleet's states.
//! - `properties.rs`: the user's properties (a scenario's `expect`, with
//!   `always`, `eventually`, `leads_to`) judged over every behaviour.
//!
//! Properties checked, only when the search is exhaustive (a bounded one
//! proves neither): every mode is entered in some behaviour (V001); a
//! robot that finishes in some behaviour can finish from every state it
//! can reach (V002); a robot never waits in a `receive` from which no
//! behaviour frees it (V003); V002 and V003 with the shortest way to such
//! a state as a scenario `semo simulate` replays. With faults (`--faults
//! N`: kills, restarts, a robot cut off), also: no two robots lead one
//! `leader(...)` statement at once (V004), judged on every state seen (a
//! state found is a witness, bounded search or not). And on every step:
//! a plan's `throw` never ends its mode in the instant another plan of the
//! mode would send or throw (V005, a race the plans' order decides:
//! `sim::Race`).

mod inputs;
mod properties;
mod search;

pub use inputs::{CommandInput, Inputs, ResultInput, SensorInput};
pub use properties::{MAX_PROPERTIES, Outcome, Property, properties_of};
pub use search::{apply, choices};

use crate::diag::{Code, Diagnostic, FileId};
use crate::refine::{RobotProgram, SENSOR_PERIOD_MS, ServiceMachineId, StateId};
use crate::sim;
use crate::span::Span;
use crate::text::LineIndex;
use std::collections::HashSet;
use std::fmt::Write;

#[derive(Clone, Debug)]
pub struct Options {
    /// The world's clock: it may choose every `step_ms` (a multiple of the
    /// sensors' 100 ms period).
    pub step_ms: i64,
    /// Mission ms beyond which no state is explored.
    pub horizon_ms: i64,
    /// States beyond which the search stops (bounded).
    pub max_states: usize,
    /// Bytes beyond which the search stops (bounded): about what the
    /// states it keeps to explore and its graph of states met hold
    /// (`Sim::approx_bytes`; a state of 20 robots is about 70 KB).
    pub max_memory: usize,
    /// How many times after the start the world may choose (a sensor
    /// value into another class, an operator command) along one behaviour.
    pub changes: u32,
    /// How many faults the world may make along one behaviour: kill a
    /// running robot, restart a killed one, cut one robot off from the
    /// others, heal the cut (0: none, the default).
    pub faults: u32,
    /// How many times the network may misbehave along one behaviour: lose
    /// the messages between two robots for one step, or delay them by one
    /// step (0: never, the default).
    pub network: u32,
    /// Merge a state with one met at another instant when they would go on
    /// alike (the reduction); without it only states of one instant merge,
    /// the reference the reduction is tested against.
    pub merge_in_time: bool,
    /// Keep every trace event seen, without its times (`Report::observed`:
    /// what the reduction is tested on).
    pub observe: bool,
    /// Set by another thread to stop the search at its next state (the
    /// editor's run after a save, when the mission changes again).
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// [`Options::max_memory`] by default: 1 GiB.
pub const DEFAULT_MAX_MEMORY: usize = 1 << 30;

/// What stopped a search before it explored every behaviour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// Every state up to the horizon was explored, and some go on.
    Horizon,
    /// `Options::max_states`.
    States,
    /// `Options::max_memory`.
    Memory,
    /// `Options::cancel`.
    Cancelled,
}

impl Bound {
    /// As the JSON document and the headline name it.
    pub fn name(self) -> &'static str {
        match self {
            Bound::Horizon => "horizon",
            Bound::States => "states",
            Bound::Memory => "memory",
            Bound::Cancelled => "cancelled",
        }
    }

    /// What the headline adds after how far the search got (nothing for
    /// the horizon: "the first T ms" says it).
    fn said(self) -> &'static str {
        match self {
            Bound::Horizon => "",
            Bound::States => " (stopped by the state budget)",
            Bound::Memory => " (stopped by the memory budget)",
            Bound::Cancelled => " (cancelled)",
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            step_ms: 500,
            horizon_ms: 120_000,
            max_states: 50_000,
            max_memory: DEFAULT_MAX_MEMORY,
            changes: 2,
            faults: 0,
            network: 0,
            merge_in_time: true,
            observe: false,
            cancel: None,
        }
    }
}

impl Options {
    /// Why these options cannot run a search, if they cannot.
    pub fn problem(&self) -> Option<String> {
        (self.step_ms <= 0 || self.step_ms % SENSOR_PERIOD_MS != 0).then(|| {
            format!(
                "the world's step must be a positive multiple of {SENSOR_PERIOD_MS}ms (the sensors' period), not {}ms",
                self.step_ms
            )
        })
    }
}

/// One choice of the world.
#[derive(Clone, Debug, PartialEq)]
pub enum Choice {
    /// At the start: the class of each sensor input, then of each result
    /// input ([`Inputs::results`]).
    Start(Vec<usize>),
    Nothing,
    /// What a robot's calls of a service give back becomes class `value`
    /// of result input `input`, from its `at_call`th call on (counting the
    /// calls of every process of the robot: a call done is never given
    /// back something else; set when the choice is made).
    Results {
        input: usize,
        value: usize,
        at_call: usize,
    },
    Sensor {
        input: usize,
        value: usize,
    },
    Command {
        input: usize,
        value: usize,
    },
    /// A fault: the robot (an index into the programs) is killed.
    Kill {
        robot: usize,
    },
    /// A fault: the killed robot starts again.
    Restart {
        robot: usize,
    },
    /// A fault: the robot reaches no other robot and no other reaches it.
    Isolate {
        robot: usize,
    },
    /// The cut robot reaches the others again.
    Heal,
    /// The network: the messages between robots `a` and `b` sent in the
    /// next step are lost.
    Lose {
        a: usize,
        b: usize,
    },
    /// The network: the messages between robots `a` and `b` sent in the
    /// next step arrive one step later than they would.
    Delay {
        a: usize,
        b: usize,
    },
}

/// What the world has set and what it may still do along one behaviour.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// Per sensor input: its class now.
    pub classes: Vec<usize>,
    /// Per result input: its class now, what its calls give back per call
    /// (as a scenario's `"results"`), and how many calls an earlier
    /// process of its robot did (those entries stay as they were given).
    pub results: Vec<ResultsNow>,
    /// Sensor changes and operator commands left.
    pub changes: u32,
    /// Faults left.
    pub faults: u32,
    /// Losses and delays left.
    pub network: u32,
    /// The world's step (ms): how long a loss or delay lasts, and by how
    /// much a delay delays.
    pub step_ms: i64,
    /// Per robot: killed and not restarted.
    pub down: Vec<bool>,
    /// The robot cut off from the others now.
    pub isolated: Option<usize>,
}

impl World {
    /// At the start: every class the first, every budget full.
    pub fn new(inputs: &Inputs, options: &Options, robots: usize) -> World {
        World {
            classes: vec![0; inputs.sensors.len()],
            results: vec![ResultsNow::default(); inputs.results.len()],
            changes: options.changes,
            faults: options.faults,
            network: options.network,
            step_ms: options.step_ms,
            down: vec![false; robots],
            isolated: None,
        }
    }
}

/// What the world gives back for one result input ([`World::results`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ResultsNow {
    pub class: usize,
    pub calls: crate::refine::CallResults,
    pub used: usize,
}

impl ResultsNow {
    /// From call `at` on, the calls give back `values`: the entries before
    /// are kept (filled with the last one up to `at`), the later dropped.
    pub fn give_from(&mut self, at: usize, values: Vec<Option<String>>) {
        self.calls.truncate(at);
        if let Some(last) = self.calls.last().cloned() {
            self.calls.resize(at, last);
        }
        self.calls.push(values);
    }
}

/// A way to a finding: the world's choices, each with the mission ms it
/// was made at, written as a scenario by [`Counterexample::scenario_json`].
#[derive(Clone, Debug, PartialEq)]
pub struct Counterexample {
    pub choices: Vec<(i64, Choice)>,
    /// The mission ms the finding shows at: the scenario's duration.
    pub end_ms: i64,
    /// The world's step: how long a loss or delay lasts.
    pub step_ms: i64,
}

/// What a finding claims, for tests that hold it to the simulator.
#[derive(Clone, Debug, PartialEq)]
pub enum Claim {
    /// No robot of `team` enters `mode` in any behaviour.
    NeverEntered { team: String, mode: String },
    /// From the counterexample's state, robot `robot` (an index into the
    /// programs) never finishes.
    NeverFinishes { robot: usize },
    /// From the counterexample's state, robot `robot` waits for ever in
    /// state `state` of service `service`.
    WaitsForEver {
        robot: usize,
        service: ServiceMachineId,
        state: StateId,
    },
    /// At the counterexample's end, robots `robots` (indices into the
    /// programs) of `team` both lead the `leader(...)` statement at `line`.
    TwoLeaders {
        team: String,
        line: u32,
        robots: (usize, usize),
    },
    /// At the counterexample's last instants, robot `robot`'s throw at
    /// (service, state) `thrower` ends its mode in the instant its send or
    /// throw at `lost` would have run.
    Race {
        robot: usize,
        thrower: (ServiceMachineId, StateId),
        lost: (ServiceMachineId, StateId),
    },
    /// At the counterexample's last instants, robot `robot` takes messages
    /// of robots `senders` in one instant, and in the other order it
    /// reacts otherwise.
    MessageRace {
        robot: usize,
        senders: (usize, usize),
    },
}

/// What a search found and how far it looked.
pub struct Report {
    pub findings: Vec<Diagnostic>,
    /// Per finding (same order): the way to it, if it has one.
    pub counterexamples: Vec<Option<Counterexample>>,
    /// Per finding (same order): what it claims.
    pub claims: Vec<Claim>,
    pub states: usize,
    pub transitions: u64,
    pub exhaustive: bool,
    /// What stopped the search, when it is not exhaustive.
    pub bound: Option<Bound>,
    pub cancelled: bool,
    pub reached_ms: i64,
    pub inputs: Inputs,
    /// (team, mode) entered in some behaviour explored, sorted.
    pub entered: Vec<(String, String)>,
    /// With `Options::observe`: each trace event of a behaviour explored,
    /// without its times, sorted.
    pub observed: Vec<String>,
    /// The user's properties, each with what became of it.
    pub properties: Vec<(Property, Outcome)>,
}

impl Report {
    /// How far the search looked, in one line: `explored every behaviour: N
    /// state(s), M transition(s): a proof for the choices explored`, or
    /// `explored (bounded): ...: the first T ms` (and what stopped it, when
    /// not the horizon).
    pub fn headline(&self) -> String {
        format!(
            "{} {} state(s), {} transition(s): {}",
            if self.exhaustive {
                "explored every behaviour:"
            } else {
                "explored (bounded):"
            },
            self.states,
            self.transitions,
            match self.bound {
                Some(bound) if !self.exhaustive => {
                    format!("the first {} ms{}", self.reached_ms, bound.said())
                }
                _ => "a proof for the choices explored".to_string(),
            }
        )
    }

    /// The findings at the levels of the project's `[lints]`: allowed ones
    /// dropped (with their counterexamples and claims), denied ones errors.
    pub fn apply_lints(&mut self, project: &crate::project::Project) {
        let findings = std::mem::take(&mut self.findings);
        let counterexamples = std::mem::take(&mut self.counterexamples);
        let claims = std::mem::take(&mut self.claims);
        for ((finding, way), claim) in findings.into_iter().zip(counterexamples).zip(claims) {
            let mut one = vec![finding];
            project.apply_lints(&mut one);
            if let Some(finding) = one.pop() {
                self.findings.push(finding);
                self.counterexamples.push(way);
                self.claims.push(claim);
            }
        }
    }
}

/// Explores `programs` (refined from the mission `text`, which is `file`);
/// options that cannot run a search are refused with the reason.
pub fn verify(
    programs: &[RobotProgram],
    file: FileId,
    text: &str,
    options: &Options,
) -> Result<Report, String> {
    verify_expecting(programs, file, text, options, Vec::new())
}

/// [`verify`], judging the user's `properties` ([`properties_of`]) over
/// every behaviour too.
pub fn verify_expecting(
    programs: &[RobotProgram],
    file: FileId,
    text: &str,
    options: &Options,
    properties: Vec<Property>,
) -> Result<Report, String> {
    if let Some(problem) = options.problem() {
        return Err(problem);
    }
    if properties.len() > MAX_PROPERTIES {
        return Err(format!("at most {MAX_PROPERTIES} properties at once"));
    }
    let inputs = inputs::derive(programs);
    let mut explored = search::explore(programs, &inputs, options, &properties);
    let outcomes = std::mem::take(&mut explored.properties);
    let mut findings = Vec::new();
    let mut counterexamples = Vec::new();
    let mut claims = Vec::new();
    let lines = LineIndex::new(text);
    // V001: per team, each mode in the order written; only after an
    // exhaustive search (a bounded one may stop before a mode's turn).
    let mut judged: HashSet<(&str, &str)> = HashSet::new();
    for program in programs.iter().filter(|_| explored.exhaustive) {
        for mode in &program.control.modes {
            if !judged.insert((&program.team, &mode.name)) {
                continue;
            }
            if !explored
                .entered
                .contains(&(program.team.clone(), mode.name.clone()))
            {
                findings.push(Diagnostic::new(
                    Code::ModeNeverEntered,
                    file,
                    line_span(text, &lines, mode.line),
                    format!(
                        "no robot of {} enters mode {} in any behaviour",
                        program.team, mode.name
                    ),
                ));
                counterexamples.push(None);
                claims.push(Claim::NeverEntered {
                    team: program.team.clone(),
                    mode: mode.name.clone(),
                });
            }
        }
    }
    for (r, way, mode) in &explored.stuck {
        let program = &programs[*r];
        let mode = mode.and_then(|m| program.control.modes.get(m));
        let (span, in_mode) = match mode {
            Some(m) => (
                line_span(text, &lines, m.line),
                format!(" in mode {}", m.name),
            ),
            None => (Span { start: 0, end: 0 }, String::new()),
        };
        findings.push(Diagnostic::new(
            Code::NeverFinishes,
            file,
            span,
            format!(
                "{} finishes in some behaviours, but{in_mode} at {} ms it can no longer finish in any{}",
                program.robot,
                way.end_ms,
                faults_aside(way, programs)
            ),
        ));
        counterexamples.push(Some(way.clone()));
        claims.push(Claim::NeverFinishes { robot: *r });
    }
    for ((r, service, state), way) in &explored.waits_for_ever {
        let program = &programs[*r];
        let statement = &program.control.service(*service).states[state.index()];
        findings.push(Diagnostic::new(
            Code::WaitsForEver,
            file,
            statement.span,
            format!(
                "{} waits here for ever from {} ms on: no behaviour brings what `{}` waits for{}",
                program.robot,
                way.end_ms,
                statement.text.trim(),
                faults_aside(way, programs)
            ),
        ));
        counterexamples.push(Some(way.clone()));
        claims.push(Claim::WaitsForEver {
            robot: *r,
            service: *service,
            state: *state,
        });
    }
    for ((team, line), (a, b), way) in &explored.two_leaders {
        findings.push(Diagnostic::new(
            Code::TwoLeaders,
            file,
            line_span(text, &lines, *line),
            format!(
                "{} and {} of {team} both lead here at {} ms: {}",
                programs[*a].robot,
                programs[*b].robot,
                way.end_ms,
                way.faults_said(programs)
                    .unwrap_or_else(|| "with no fault".to_string())
            ),
        ));
        counterexamples.push(Some(way.clone()));
        claims.push(Claim::TwoLeaders {
            team: team.clone(),
            line: *line,
            robots: (*a, *b),
        });
    }
    for (race, way) in &explored.races {
        let program = &programs[race.robot];
        let m = &program.control;
        let plan = |service: ServiceMachineId| {
            m.mode(race.mode)
                .regions
                .iter()
                .find(|region| region.service == service)
                .map_or_else(|| m.service(service).name.clone(), |r| r.plan.clone())
        };
        let thrower = &m.service(race.thrower.0).states[race.thrower.1.index()];
        let lost = &m.service(race.lost.0).states[race.lost.1.index()];
        let mut finding = Diagnostic::new(
            Code::PlansRace,
            file,
            thrower.span,
            format!(
                "at {} ms {}'s plan {} ends mode {} here, in the instant its plan {} would run `{}` (line {}), which so never runs: the plans of a mode run in the order of its `set`s, and that order alone decides which happens{}",
                race.at,
                program.robot,
                plan(race.thrower.0),
                m.mode(race.mode).name,
                plan(race.lost.0),
                lost.text.trim(),
                lost.line,
                faults_aside(way, programs)
            ),
        );
        finding.relate(
            lost.span,
            format!("this does not run at {} ms: the mode ends first", race.at),
        );
        findings.push(finding);
        counterexamples.push(Some(way.clone()));
        claims.push(Claim::Race {
            robot: race.robot,
            thrower: race.thrower,
            lost: race.lost,
        });
    }
    // One finding per (statement, robots, keys): the search keeps a race
    // per mode and per kind of message, which may name the same ones.
    type Told<'a> = (Span, usize, [(usize, &'a str); 2]);
    let mut told: HashSet<Told> = HashSet::new();
    for (race, way) in &explored.message_races {
        let program = &programs[race.robot];
        let m = &program.control;
        let taken_at = |a: &sim::Arrival| receive_of(m, race.mode, a);
        let said = |a: &sim::Arrival| {
            let value = a.value.as_ref().map_or("none".to_string(), |v| v.as_text());
            let what = match a.taken {
                sim::Taken::Event => format!("event {value}"),
                _ if a.publish => format!("{} = {value} (published)", a.key),
                _ => format!("{} = {value}", a.key),
            };
            format!("{what} from {}", programs[a.from].robot)
        };
        let mode_name = |mode: Option<crate::refine::ModeId>| {
            mode.map_or("no mode".to_string(), |id| {
                format!("mode {}", m.mode(id).name)
            })
        };
        let differs = match race.differs {
            sim::Differs::Mode(ran, other) => format!(
                "it would be in {} instead of {}",
                mode_name(other),
                mode_name(ran)
            ),
            sim::Differs::Values => "it would hold another value".to_string(),
            sim::Differs::Next => "what it does next would differ".to_string(),
        };
        let first_at = taken_at(&race.first);
        let second_at = taken_at(&race.second);
        let sends = [&race.first, &race.second].map(|a| send_of(&programs[a.from], a));
        let span = first_at
            .or(second_at)
            .map(|(span, line)| span.unwrap_or_else(|| line_span(text, &lines, line)))
            .or_else(|| sends.iter().flatten().next().map(|s| s.span))
            .unwrap_or(Span { start: 0, end: 0 });
        let mut pair = [&race.first, &race.second].map(|a| (a.from, a.key.as_str()));
        pair.sort_unstable();
        if !told.insert((span, race.robot, pair)) {
            continue;
        }
        let mut finding = Diagnostic::new(
            Code::RobotsRace,
            file,
            span,
            format!(
                "at {} ms {} takes {} and {} in one instant, in that order; taken the other way round, as the network may deliver them, {differs}: which robot's message comes first decides it{}",
                race.at,
                program.robot,
                said(&race.first),
                said(&race.second),
                faults_aside(way, programs)
            ),
        );
        if let (Some(a), Some(b)) = (first_at, second_at)
            && a != b
        {
            let (span, line) = b;
            finding.relate(
                span.unwrap_or_else(|| line_span(text, &lines, line)),
                format!("{} is taken here", said(&race.second)),
            );
        }
        for (arrival, send) in [&race.first, &race.second].into_iter().zip(&sends) {
            if let Some(send) = send {
                finding.relate(
                    send.span,
                    format!(
                        "{} sends this; it arrives at {} ms, in the instant the other does",
                        programs[arrival.from].robot, race.at
                    ),
                );
            }
        }
        findings.push(finding);
        counterexamples.push(Some(way.clone()));
        claims.push(Claim::MessageRace {
            robot: race.robot,
            senders: (race.first.from, race.second.from),
        });
    }
    Ok(Report {
        findings,
        counterexamples,
        claims,
        states: explored.states,
        transitions: explored.transitions,
        exhaustive: explored.exhaustive,
        bound: explored.bound,
        cancelled: explored.cancelled,
        reached_ms: explored.reached_ms,
        inputs,
        observed: {
            let mut observed: Vec<_> = explored.observed.into_iter().collect();
            observed.sort();
            observed
        },
        entered: {
            let mut entered: Vec<_> = explored.entered.into_iter().collect();
            entered.sort();
            entered
        },
        properties: properties.into_iter().zip(outcomes).collect(),
    })
}

/// Where robot program `m` takes `arrival` in `mode`: the `receive` or
/// `subscribe` statement (preferring one of the mode's plans) as its span,
/// or a broadcast event's `catch` as its line.
fn receive_of(
    m: &crate::refine::ControlMachine,
    mode: Option<crate::refine::ModeId>,
    arrival: &sim::Arrival,
) -> Option<(Option<Span>, u32)> {
    use crate::refine::StateKind;
    let takes = |state: &crate::refine::State| match (&state.kind, arrival.taken) {
        (StateKind::Receive { messages, .. }, sim::Taken::Received(i)) => {
            messages.iter().any(|k| k.index() == i)
        }
        (StateKind::Subscribe { group, .. }, sim::Taken::Subscribed(g)) => group.index() == g,
        _ => false,
    };
    if arrival.taken == sim::Taken::Event {
        let event = arrival.value.as_ref().map(|v| v.as_text())?;
        return (m.transitions.iter())
            .find(|t| Some(t.from) == mode && t.event == event)
            .or_else(|| m.transitions.iter().find(|t| t.event == event))
            .map(|t| (None, t.line));
    }
    let in_mode: Vec<ServiceMachineId> = mode
        .map(|id| m.mode(id).regions.iter().map(|r| r.service).collect())
        .unwrap_or_default();
    let services = (m.services.iter().enumerate())
        .map(|(i, s)| (ServiceMachineId::new(i), s))
        .filter(|(id, _)| in_mode.contains(id))
        .chain(
            (m.services.iter().enumerate())
                .map(|(i, s)| (ServiceMachineId::new(i), s))
                .filter(|(id, _)| !in_mode.contains(id)),
        );
    for (_, service) in services {
        if let Some(state) = service.states.iter().find(|s| takes(s)) {
            return Some((Some(state.span), state.line));
        }
    }
    None
}

/// The statement of `program` that sends `arrival`: a `send` or `publish`
/// of its key (one that writes its value as a literal first), or the
/// `throw ... broadcast` of its event.
fn send_of<'a>(
    program: &'a RobotProgram,
    arrival: &sim::Arrival,
) -> Option<&'a crate::refine::State> {
    use crate::refine::{Operand, StateKind};
    let m = &program.control;
    let event = arrival.value.as_ref().map(|v| v.as_text());
    // Per statement: whether it sends the key, and whether it writes the
    // arrival's value as a literal.
    let sends = |state: &crate::refine::State| match &state.kind {
        StateKind::Send { items } if arrival.taken != sim::Taken::Event => {
            let mut sends = (false, false);
            for item in items {
                let message = m.outgoing_message(item.message);
                if message.key == arrival.key && message.publish == arrival.publish {
                    sends.0 = true;
                    if let Operand::Literal(v) = &item.value {
                        sends.1 |= Some(v.as_text()) == event;
                    }
                }
            }
            sends
        }
        StateKind::Throw {
            event: thrown,
            broadcast: Some(_),
        } if arrival.taken == sim::Taken::Event => {
            let same = Some(thrown) == event.as_ref();
            (same, same)
        }
        _ => (false, false),
    };
    let states = || m.services.iter().flat_map(|s| &s.states);
    states()
        .find(|state| sends(state).1)
        .or_else(|| states().find(|state| sends(state).0))
}

/// " (after help killed at 0 ms)" when the way has faults, else nothing.
fn faults_aside(way: &Counterexample, programs: &[RobotProgram]) -> String {
    way.faults_said(programs)
        .map_or(String::new(), |said| format!(" ({said})"))
}

/// Line `line` (1-based) of `text`, without its indentation.
fn line_span(text: &str, lines: &LineIndex, line: u32) -> Span {
    let start = lines.line_start((line as usize).saturating_sub(1));
    let end = lines.line_start(line as usize).min(text.len());
    let body = &text[start..end];
    let indent = body.len() - body.trim_start().len();
    Span {
        start: start + indent.min(body.trim_end().len()),
        end: start + body.trim_end().len(),
    }
}

impl Counterexample {
    /// The faults on the way, for a finding's message: "after tb_0 cut off
    /// at 1500 ms"; `None` without one.
    pub fn faults_said(&self, robots: &[RobotProgram]) -> Option<String> {
        let said: Vec<String> = self
            .choices
            .iter()
            .filter_map(|(at, choice)| {
                let (robot, what) = match choice {
                    Choice::Kill { robot } => (robot, "killed"),
                    Choice::Restart { robot } => (robot, "restarted"),
                    Choice::Isolate { robot } => (robot, "cut off"),
                    Choice::Heal => return Some(format!("the cut healed at {at} ms")),
                    Choice::Lose { a, b } | Choice::Delay { a, b } => {
                        let what = if matches!(choice, Choice::Lose { .. }) {
                            "lost"
                        } else {
                            "delayed"
                        };
                        return Some(format!(
                            "the messages between {} and {} {what} from {at} ms to {} ms",
                            robots[*a].robot,
                            robots[*b].robot,
                            at + self.step_ms
                        ));
                    }
                    _ => return None,
                };
                Some(format!("{} {what} at {at} ms", robots[*robot].robot))
            })
            .collect();
        (!said.is_empty()).then(|| format!("after {}", said.join(", ")))
    }

    /// The scenario (`docs/scenario-and-trace.md`) that replays the way:
    /// `semo simulate` on it shows the finding at its end.
    pub fn scenario_json(&self, inputs: &Inputs, robots: &[RobotProgram]) -> String {
        self.scenario_json_expecting(inputs, robots, None)
    }

    /// [`Counterexample::scenario_json`] with `expect` as the scenario's one
    /// expectation: a property the replay breaks, as `semo simulate` says.
    pub fn scenario_json_expecting(
        &self,
        inputs: &Inputs,
        robots: &[RobotProgram],
        expect: Option<&crate::sim::scenario::ExpectKind>,
    ) -> String {
        // The sensor entries per robot, and the operator's commands, in
        // the order the choices were made.
        let mut sensors: Vec<Vec<(i64, &SensorInput, usize)>> = vec![Vec::new(); robots.len()];
        // What each result input gives back, rebuilt choice by choice.
        let mut results = vec![ResultsNow::default(); inputs.results.len()];
        let mut commands = Vec::new();
        // Each fault as a scenario entry; a cut runs to its heal, else to
        // the end.
        let mut faults: Vec<String> = Vec::new();
        let mut cut: Option<(i64, usize)> = None;
        let partition = |from: i64, until: i64, robot: usize| {
            format!(
                "{{\"from\": {from}, \"until\": {until}, \"partition\": [[{}]]}}",
                json_string(&robots[robot].robot)
            )
        };
        for (at, choice) in &self.choices {
            let mut sensor = |s: usize, v: usize| {
                let input = &inputs.sensors[s];
                sensors[input.robot].push((*at, input, v));
            };
            match choice {
                Choice::Start(classes) => {
                    let (of_sensors, of_results) =
                        classes.split_at(inputs.sensors.len().min(classes.len()));
                    for (s, &v) in of_sensors.iter().enumerate() {
                        sensor(s, v);
                    }
                    for (i, &v) in of_results.iter().enumerate() {
                        results[i].give_from(0, inputs.results[i].values[v].clone());
                    }
                }
                Choice::Sensor { input, value } => sensor(*input, *value),
                Choice::Results {
                    input,
                    value,
                    at_call,
                } => results[*input]
                    .give_from(*at_call, inputs.results[*input].values[*value].clone()),
                Choice::Command { input, value } => {
                    commands.push((*at, &inputs.commands[*input], *value))
                }
                Choice::Kill { robot } | Choice::Restart { robot } => {
                    let kind = if matches!(choice, Choice::Kill { .. }) {
                        "kill"
                    } else {
                        "restart"
                    };
                    faults.push(format!(
                        "{{\"at\": {at}, \"{kind}\": {}}}",
                        json_string(&robots[*robot].robot)
                    ));
                }
                Choice::Isolate { robot } => cut = Some((*at, *robot)),
                Choice::Lose { a, b } | Choice::Delay { a, b } => {
                    let pair = format!(
                        "[{}, {}]",
                        json_string(&robots[*a].robot),
                        json_string(&robots[*b].robot)
                    );
                    let until = at + self.step_ms;
                    faults.push(match choice {
                        Choice::Lose { .. } => {
                            format!("{{\"from\": {at}, \"until\": {until}, \"drop\": {pair}}}")
                        }
                        _ => format!(
                            "{{\"from\": {at}, \"until\": {until}, \"delay\": {pair}, \"by\": {}}}",
                            self.step_ms
                        ),
                    });
                }
                Choice::Heal => {
                    if let Some((from, robot)) = cut.take() {
                        faults.push(partition(from, *at, robot));
                    }
                }
                Choice::Nothing => {}
            }
        }
        if let Some((from, robot)) = cut {
            faults.push(partition(from, self.end_ms.max(from + 1), robot));
        }
        let mut out = String::new();
        let _ = write!(
            out,
            "{{\n  \"duration\": {},\n  \"robots\": {{",
            self.end_ms
        );
        let mut first_robot = true;
        for (r, (program, entries)) in robots.iter().zip(&sensors).enumerate() {
            let given: Vec<(&str, &ResultsNow)> = (inputs.results.iter().zip(&results))
                .filter(|(input, now)| input.robot == r && !now.calls.is_empty())
                .map(|(input, now)| (input.service.as_str(), now))
                .collect();
            if entries.is_empty() && given.is_empty() {
                continue;
            }
            let _ = write!(
                out,
                "{}\n    {}: {{",
                if first_robot { "" } else { "," },
                json_string(&program.robot)
            );
            first_robot = false;
            if !entries.is_empty() {
                out.push_str("\"sensors\": [");
                for (i, (at, input, v)) in entries.iter().enumerate() {
                    let _ = write!(
                        out,
                        "{}\n      {{\"at\": {at}, \"value\": {}, \"is\": {}}}",
                        if i == 0 { "" } else { "," },
                        json_string(&input.port),
                        json_string(&input.values[*v])
                    );
                }
                out.push_str("\n    ]");
            }
            if !given.is_empty() {
                if !entries.is_empty() {
                    out.push_str(", ");
                }
                out.push_str("\"services\": {");
                for (i, (service, now)) in given.iter().enumerate() {
                    let calls: Vec<String> = (now.calls.iter())
                        .map(|values| {
                            let values: Vec<String> = (values.iter())
                                .map(|v| match v.as_deref() {
                                    None => "null".to_string(),
                                    Some(b @ ("true" | "false")) => b.to_string(),
                                    Some(text) => json_string(text),
                                })
                                .collect();
                            format!("[{}]", values.join(", "))
                        })
                        .collect();
                    let _ = write!(
                        out,
                        "{}\n      {}: {{\"results\": [{}]}}",
                        if i == 0 { "" } else { "," },
                        json_string(service),
                        calls.join(", ")
                    );
                }
                out.push_str("\n    }");
            }
            out.push('}');
        }
        out.push_str(if first_robot { "},\n" } else { "\n  },\n" });
        out.push_str("  \"operator\": [");
        for (i, (at, command, v)) in commands.iter().enumerate() {
            let _ = write!(
                out,
                "{}\n    {{\"at\": {at}, \"to\": {}, \"value\": {}, \"is\": {}}}",
                if i == 0 { "" } else { "," },
                json_string(&command.to),
                json_string(&command.value),
                json_string(&command.values[*v])
            );
        }
        out.push_str(if commands.is_empty() { "]" } else { "\n  ]" });
        if !faults.is_empty() {
            out.push_str(",\n  \"faults\": [\n    ");
            out.push_str(&faults.join(",\n    "));
            out.push_str("\n  ]");
        }
        if let Some(expect) = expect {
            let _ = write!(out, ",\n  \"expect\": [\n    {}\n  ]", expect.to_json());
        }
        out.push_str("\n}\n");
        out
    }
}

/// The name of finding `n`'s (1-based, among a report's findings)
/// counterexample of a mission whose file stem is `stem`, without an
/// extension: `main.V002-1`; its scenario is `main.V002-1.scenario.json`.
/// The CLI's `--counterexamples` and the editor's action write these.
pub fn counterexample_name(stem: &str, code: Code, n: usize) -> String {
    format!("{stem}.{code}-{n}")
}

/// `text` as a JSON string.
fn json_string(text: &str) -> String {
    let mut out = String::new();
    crate::sim::trace::json_string(&mut out, text);
    out
}
