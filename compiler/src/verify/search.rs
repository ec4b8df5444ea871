//! The breadth-first search over everything the team can do: from each
//! state, at each step of the world's clock, the world keeps still or makes
//! one choice (a sensor value into another class, an operator command),
//! and the simulator runs the robots to the next step. States are told
//! apart by [`Sim::fingerprint`]; a state met before is not explored again,
//! so a mission that repeats itself is explored to the end (exhaustive),
//! else up to the horizon or the state budget (bounded).

use super::inputs::Inputs;
use super::properties::{self, Label, Outcome, Property};
use super::{Bound, Choice, Counterexample, Options, World};
use crate::refine::{RobotProgram, ServiceMachineId, StateId};
use crate::sim::{self, Memory, MessageRace, Race, Scenario, Sim};
use std::collections::{HashMap, HashSet};

/// What the search saw, for the properties to judge.
pub struct Explored {
    pub states: usize,
    pub transitions: u64,
    /// Every successor of every state was explored: a proof, not a sample.
    pub exhaustive: bool,
    /// How far in mission time the deepest state explored lies.
    pub reached_ms: i64,
    /// (team, mode) entered in some behaviour.
    pub entered: HashSet<(String, String)>,
    /// What stopped the search before it explored every behaviour.
    pub bound: Option<Bound>,
    pub cancelled: bool,
    /// With `Options::observe`: every trace event of every behaviour
    /// explored, without its times.
    pub observed: HashSet<String>,
    /// Per robot that finishes in some behaviour but can reach a state from
    /// which it never does (only when exhaustive): the shortest way there
    /// and the mode it is in then.
    pub stuck: Vec<(usize, Counterexample, Option<usize>)>,
    /// Per `receive` (robot, service, state) that a robot can reach and
    /// then wait in for ever, whatever the world does (only when
    /// exhaustive): the shortest way there.
    pub waits_for_ever: Vec<((usize, ServiceMachineId, StateId), Counterexample)>,
    /// Per `leader(...)` statement (team, mission line) that two robots
    /// lead at once in some state: the two, and the shortest way there.
    /// A state seen is a witness: judged bounded or not.
    pub two_leaders: Vec<TwoLeaders>,
    /// Per race between two plans of one mode (the team and the two
    /// statements): its first instant met and the shortest way there. A
    /// race seen is a witness: judged bounded or not.
    pub races: Vec<(Race, Counterexample)>,
    /// Per race between robots (the receiver's team and mode, and the two
    /// messages' teams, keys and kinds, in either order): its first
    /// instant met and the shortest way there. A witness too.
    pub message_races: Vec<(MessageRace, Counterexample)>,
    /// Per property of the user's (same order): what became of it.
    pub properties: Vec<Outcome>,
}

/// A `leader(...)` statement (team, mission line), the two robots that
/// lead it at once, and the shortest way there.
pub type TwoLeaders = ((String, u32), (usize, usize), Counterexample);

/// A (service, state) of a robot's program.
type StateAt = (ServiceMachineId, StateId);

struct Node {
    parent: Option<u32>,
    choice: Choice,
    /// Mission ms the choice was made at.
    at: i64,
    /// Per robot: it has finished (not killed: it ended its mission).
    finished: Box<[bool]>,
    /// Per robot: the world killed it and has not restarted it.
    down: Box<[bool]>,
    /// Per robot: the mode it is in (an index into its program's modes).
    modes: Box<[Option<u16>]>,
    /// The `receive` states robots wait in: (robot, service, state).
    waiting: Box<[(u32, u32, u32)]>,
    /// The robots that act (call, send, throw, change mode, finish) in
    /// some step out of this state.
    moved: Vec<u32>,
}

pub fn explore(
    programs: &[RobotProgram],
    inputs: &Inputs,
    options: &Options,
    properties: &[Property],
) -> Explored {
    let scenario = Scenario::default();
    let memory = Memory::of(programs);
    let mut root = Sim::new(programs, &scenario, &sim::Options::default());
    root.watch_races();
    root.watch_message_races(options.step_ms);
    let mut explored = Explored {
        states: 0,
        transitions: 0,
        exhaustive: false,
        reached_ms: 0,
        entered: HashSet::new(),
        bound: None,
        cancelled: false,
        observed: HashSet::new(),
        stuck: Vec::new(),
        waits_for_ever: Vec::new(),
        two_leaders: Vec::new(),
        races: Vec::new(),
        message_races: Vec::new(),
        properties: Vec::new(),
    };
    let mut judge = Judge::new(programs, properties);
    // (team, thrower's statement, lost statement) → the race.
    let mut races: HashMap<(&str, u32, u32), (Race, Counterexample)> = HashMap::new();
    // (receiver's team, its mode, the two messages as (team, key, kind),
    // sorted) → the race.
    type Crossing<'a> = (&'a str, Option<u32>, [(String, String, sim::Taken); 2]);
    let mut message_races: HashMap<Crossing, (MessageRace, Counterexample)> = HashMap::new();
    let mut nodes: Vec<Node> = Vec::new();
    // Keyed by fingerprints, themselves hashes: the fast hasher suffices.
    let mut seen: crate::fasthash::FastMap<u128, u32> = Default::default();
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut leaders = Leaders::new(programs);
    // Each state with what the world has set and has left to do, and the
    // bytes it holds.
    let mut frontier: Vec<(u32, Sim, World, usize)> = Vec::new();
    // The bytes of the states kept to explore (`frontier` and `next`).
    let mut kept_bytes = 0;
    let mut bound = None;
    let over = |nodes: &Vec<Node>, edges: &Vec<(u32, u32)>, kept: usize| {
        if cancelled(options) {
            Some(Bound::Cancelled)
        } else if nodes.len() >= options.max_states {
            Some(Bound::States)
        } else if kept + graph_bytes(nodes, edges, programs.len()) > options.max_memory {
            Some(Bound::Memory)
        } else {
            None
        }
    };
    for start in start_classes(inputs) {
        bound = over(&nodes, &edges, kept_bytes);
        if bound.is_some() {
            break;
        }
        let mut sim = root.clone();
        let mut world = World::new(inputs, options, programs.len());
        apply(
            &mut sim,
            &mut world,
            inputs,
            &mut Choice::Start(start.clone()),
        );
        let fp = key(sim.fingerprint(&memory), &world, 0, options);
        if !seen.contains_key(&fp) {
            let id = admit(
                &mut nodes,
                &mut seen,
                fp,
                &sim,
                &world,
                None,
                Choice::Start(start),
                0,
            );
            leaders.look(&sim, id);
            let bytes = sim.approx_bytes();
            kept_bytes += bytes;
            frontier.push((id, sim, world, bytes));
        }
    }
    let mut t = 0;
    let mut trace_hint = 0;
    while !frontier.is_empty() && bound.is_none() {
        if t >= options.horizon_ms {
            break;
        }
        let next_t = t + options.step_ms;
        let mut next = Vec::new();
        for (id, sim, world, bytes) in std::mem::take(&mut frontier) {
            let node = &nodes[id as usize];
            if (0..node.finished.len()).all(|r| node.finished[r] || node.down[r]) {
                continue;
            }
            let all = choices(inputs, &world);
            let last = all.len() - 1;
            // The last choice takes the state itself: a clone (and a drop)
            // fewer per state.
            let mut state = Some((sim, world));
            for (c, mut choice) in all.into_iter().enumerate() {
                bound = over(&nodes, &edges, kept_bytes);
                if bound.is_some() {
                    break;
                }
                let (mut child, mut child_world) = if c == last {
                    state.take().expect("only the last choice takes the state")
                } else {
                    let (sim, world) = state.as_ref().expect("kept until the last choice");
                    (sim.clone(), world.clone())
                };
                apply(&mut child, &mut child_world, inputs, &mut choice);
                // About as many events as the step before.
                child.reserve_trace(trace_hint);
                child.run_to(next_t);
                explored.transitions += 1;
                let trace = child.take_trace();
                trace_hint = trace.len();
                let label = judge.label(&nodes[id as usize], &trace);
                for race in child.take_races() {
                    let statement = |(service, state): StateAt| {
                        programs[race.robot].control.service(service).states[state.index()]
                            .span
                            .start as u32
                    };
                    let at = (
                        programs[race.robot].team.as_str(),
                        statement(race.thrower),
                        statement(race.lost),
                    );
                    // Breadth first: the first met is the shallowest.
                    races.entry(at).or_insert_with(|| {
                        (
                            race,
                            counterexample(&nodes, id, &choice, t, options.step_ms),
                        )
                    });
                }
                for race in child.take_message_races() {
                    let said = |a: &sim::Arrival| (a.from_team.clone(), a.key.clone(), a.taken);
                    let mut pair = [said(&race.first), said(&race.second)];
                    pair.sort_by(|x, y| (&x.0, &x.1).cmp(&(&y.0, &y.1)));
                    let at = (
                        programs[race.robot].team.as_str(),
                        race.mode.map(|m| m.index() as u32),
                        pair,
                    );
                    message_races.entry(at).or_insert_with(|| {
                        (
                            race,
                            counterexample(&nodes, id, &choice, t, options.step_ms),
                        )
                    });
                }
                for e in trace {
                    // What a robot does (not what merely reaches it): it
                    // left any `receive` it waited in, or works beside it.
                    let moved = &mut nodes[id as usize].moved;
                    if matches!(e.event, "call" | "send" | "throw" | "mode" | "finish")
                        && !moved.contains(&(e.robot as u32))
                    {
                        moved.push(e.robot as u32);
                    }
                    if options.observe {
                        // The event without its times: what happened, not when.
                        explored.observed.insert(format!(
                            "{} {} {:?} {:?}",
                            e.robot, e.event, e.fields, e.value
                        ));
                    }
                    if e.event == "mode"
                        && let Some(mode) = e.field("mode")
                    {
                        let team = &programs[e.robot].team;
                        explored.entered.insert((team.clone(), mode.to_string()));
                    }
                }
                let fp = key(child.fingerprint(&memory), &child_world, next_t, options);
                if judge.always_broken(label) {
                    let way = || counterexample(&nodes, id, &choice, t, options.step_ms);
                    judge.witness(label, way);
                }
                let child_id = match seen.get(&fp) {
                    Some(&known) => {
                        edges.push((id, known));
                        judge.step(id, known, &choice, label);
                        None
                    }
                    None => {
                        let new = admit(
                            &mut nodes,
                            &mut seen,
                            fp,
                            &child,
                            &child_world,
                            Some(id),
                            choice.clone(),
                            t,
                        );
                        edges.push((id, new));
                        judge.step(id, new, &choice, label);
                        leaders.look(&child, new);
                        Some(new)
                    }
                };
                if let Some(child_id) = child_id {
                    let bytes = child.approx_bytes();
                    kept_bytes += bytes;
                    next.push((child_id, child, child_world, bytes));
                    explored.reached_ms = next_t;
                }
            }
            // Its successors made, the state itself is gone.
            kept_bytes -= bytes;
            if bound.is_some() {
                break;
            }
        }
        frontier = next;
        t = next_t;
    }
    explored.states = nodes.len();
    explored.exhaustive = frontier.is_empty() && bound.is_none();
    if !explored.exhaustive {
        explored.bound = Some(bound.unwrap_or(Bound::Horizon));
    }
    explored.cancelled = cancelled(options);
    explored.two_leaders = leaders
        .found
        .into_iter()
        .map(|(statement, (n, pair))| {
            (statement, pair, way_to(&nodes, n as usize, options.step_ms))
        })
        .collect();
    explored.two_leaders.sort_by(|a, b| a.0.cmp(&b.0));
    explored.races = races.into_values().collect();
    explored
        .races
        .sort_by_key(|(race, _)| (race.robot, race.thrower, race.lost));
    explored.message_races = message_races.into_values().collect();
    explored
        .message_races
        .sort_by_key(|(race, _)| (race.robot, race.at, race.first.from, race.second.from));
    explored.properties = judge.outcomes(&nodes, explored.exhaustive, options.step_ms);
    if explored.exhaustive {
        let graph = Graph {
            nodes: &nodes,
            into: reversed(nodes.len(), &edges),
            step_ms: options.step_ms,
        };
        explored.stuck = graph.stuck(programs.len());
        explored.waits_for_ever = graph.waits_for_ever();
    }
    explored
}

/// The `leader(...)` statements two robots lead at once, met while
/// exploring: the first state (the shallowest) of each.
struct Leaders {
    /// Per robot: its team and, per (service, state) of its program, the
    /// statement's mission line.
    statements: Vec<(String, HashMap<StateAt, u32>)>,
    /// (team, line) → (state, the two robots).
    found: HashMap<(String, u32), (u32, (usize, usize))>,
}

impl Leaders {
    fn new(programs: &[RobotProgram]) -> Leaders {
        let statements = programs
            .iter()
            .map(|p| {
                let services = &p.control.services;
                let lines = ServiceMachineId::all(services.len())
                    .zip(services)
                    .flat_map(|(s, service)| {
                        StateId::all(service.states.len())
                            .zip(&service.states)
                            .filter_map(move |(pc, state)| {
                                matches!(state.kind, crate::refine::StateKind::LeaderBranch { .. })
                                    .then_some(((s, pc), state.line))
                            })
                    });
                (p.team.clone(), lines.collect())
            })
            .collect();
        Leaders {
            statements,
            found: HashMap::new(),
        }
    }

    /// Notes state `id` if two robots lead one statement in it.
    fn look(&mut self, sim: &Sim, id: u32) {
        // Most missions elect no one: nothing to look at in any state.
        if self.statements.iter().all(|(_, lines)| lines.is_empty()) {
            return;
        }
        let mut leading: HashMap<(&str, u32), usize> = HashMap::new();
        for r in 0..sim.robot_count() {
            let (team, lines) = &self.statements[r];
            for state in sim.leads(r) {
                let Some(&line) = lines.get(&state) else {
                    continue;
                };
                match leading.insert((team, line), r) {
                    Some(other) if other != r => {
                        self.found
                            .entry((team.clone(), line))
                            .or_insert((id, (other, r)));
                    }
                    _ => {}
                }
            }
        }
    }
}

/// Records a new state, reached by `choice` made at `at`; its id.
#[allow(clippy::too_many_arguments)]
fn admit(
    nodes: &mut Vec<Node>,
    seen: &mut crate::fasthash::FastMap<u128, u32>,
    fingerprint: u128,
    sim: &Sim,
    world: &World,
    parent: Option<u32>,
    choice: Choice,
    at: i64,
) -> u32 {
    let id = nodes.len() as u32;
    seen.insert(fingerprint, id);
    let robots = 0..sim.robot_count();
    let finished = robots
        .clone()
        .map(|r| !sim.is_running(r) && !world.down[r])
        .collect();
    let modes = robots
        .map(|r| sim.mode_of(r).and_then(|m| u16::try_from(m.index()).ok()))
        .collect();
    let waiting = (0..sim.robot_count())
        .flat_map(|r| {
            sim.waiting_receives(r)
                .into_iter()
                .map(move |(service, state)| {
                    (r as u32, service.index() as u32, state.index() as u32)
                })
        })
        .collect();
    nodes.push(Node {
        parent,
        choice,
        at,
        finished,
        down: world.down.clone().into_boxed_slice(),
        modes,
        waiting,
        moved: Vec::new(),
    });
    id
}

/// Every combination of the sensor inputs' classes and then the result
/// inputs', the first classes first, made one at a time (there are
/// exponentially many: the search takes what its budget allows).
fn start_classes(inputs: &Inputs) -> impl Iterator<Item = Vec<usize>> + '_ {
    let sizes: Vec<usize> = (inputs.sensors.iter().map(|s| s.values.len()))
        .chain(inputs.results.iter().map(|r| r.values.len()))
        .collect();
    let mut next = Some(vec![0; sizes.len()]);
    std::iter::from_fn(move || {
        let current = next.take()?;
        // An odometer whose last input turns fastest.
        let mut following = current.clone();
        for s in (0..following.len()).rev() {
            following[s] += 1;
            if following[s] < sizes[s] {
                next = Some(following);
                break;
            }
            following[s] = 0;
        }
        Some(current)
    })
}

/// About the bytes of the graph of states met: per state its node (with
/// its per-robot lists), its place in the seen set; per transition its edge.
fn graph_bytes(nodes: &[Node], edges: &[(u32, u32)], robots: usize) -> usize {
    let per_node =
        std::mem::size_of::<Node>() + robots * 6 + 2 * std::mem::size_of::<(u128, u32)>();
    nodes.len() * per_node + std::mem::size_of_val(edges)
}

fn cancelled(options: &Options) -> bool {
    options
        .cancel
        .as_ref()
        .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
}

/// What tells states apart: the fingerprint, what the world has left to
/// do and which robots it killed, and without `merge_in_time` the mission
/// time too (then only states of one instant merge: the unreduced search).
fn key(fingerprint: u128, world: &World, now: i64, options: &Options) -> u128 {
    let now = if options.merge_in_time {
        0
    } else {
        now as u128 + 1
    };
    let mut down: u128 = 0;
    for (r, &d) in world.down.iter().enumerate() {
        if d {
            down = down.rotate_left(7) ^ (r as u128 + 1);
        }
    }
    fingerprint
        ^ (u128::from(world.changes) << 96).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (u128::from(world.faults) << 64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
        ^ (u128::from(world.network) << 80).wrapping_mul(0x27d4_eb2f_1656_67c5)
        ^ down.wrapping_mul(0x1656_67b1_9e37_79f9_85eb_ca77_c2b2_ae63)
        ^ now.wrapping_mul(0xd6e8_feb8_6659_fd93_a5a1_ee3b_8f1c_2d4b)
}

/// What the world may do at a step: nothing; with a change left, one
/// sensor input into another class or one operator command; with a fault
/// left, kill a running robot, restart a killed one, cut one off from
/// the others or heal the cut.
pub fn choices(inputs: &Inputs, world: &World) -> Vec<Choice> {
    let mut all = vec![Choice::Nothing];
    if world.changes > 0 {
        for (s, input) in inputs.sensors.iter().enumerate() {
            for v in 0..input.values.len() {
                if v != world.classes[s] {
                    all.push(Choice::Sensor { input: s, value: v });
                }
            }
        }
        for (c, input) in inputs.commands.iter().enumerate() {
            for v in 0..input.values.len() {
                all.push(Choice::Command { input: c, value: v });
            }
        }
        for (i, input) in inputs.results.iter().enumerate() {
            for v in 0..input.values.len() {
                if v != world.results[i].class {
                    // Where it takes effect is known when it is made.
                    all.push(Choice::Results {
                        input: i,
                        value: v,
                        at_call: 0,
                    });
                }
            }
        }
    }
    if world.network > 0 {
        // Each pair of robots that may exchange a message, both alive now.
        for &(a, b) in &inputs.links {
            if !world.down[a] && !world.down[b] {
                all.push(Choice::Lose { a, b });
                all.push(Choice::Delay { a, b });
            }
        }
    }
    if world.faults > 0 {
        for (robot, &down) in world.down.iter().enumerate() {
            all.push(if down {
                Choice::Restart { robot }
            } else {
                Choice::Kill { robot }
            });
        }
        match world.isolated {
            Some(_) => all.push(Choice::Heal),
            None => all.extend((0..world.down.len()).map(|robot| Choice::Isolate { robot })),
        }
    }
    all
}

/// Makes `choice` in `sim` now, keeping `world` (what is set, what is
/// left) up to date; a [`Choice::Results`] learns the call it takes effect
/// from.
pub fn apply(sim: &mut Sim, world: &mut World, inputs: &Inputs, choice: &mut Choice) {
    match *choice {
        Choice::Nothing | Choice::Start(_) => {}
        Choice::Sensor { .. } | Choice::Command { .. } | Choice::Results { .. } => {
            world.changes -= 1
        }
        Choice::Lose { .. } | Choice::Delay { .. } => world.network -= 1,
        Choice::Kill { .. } | Choice::Restart { .. } | Choice::Isolate { .. } | Choice::Heal => {
            world.faults -= 1
        }
    }
    match *choice {
        Choice::Nothing => {}
        Choice::Start(ref start) => {
            let (of_sensors, of_results) = start.split_at(inputs.sensors.len().min(start.len()));
            for (s, &v) in of_sensors.iter().enumerate() {
                let input = &inputs.sensors[s];
                sim.set_sensor(input.robot, &input.port, &input.values[v]);
                world.classes[s] = v;
            }
            for (i, &v) in of_results.iter().enumerate() {
                let input = &inputs.results[i];
                let now = &mut world.results[i];
                now.class = v;
                now.give_from(0, input.values[v].clone());
                sim.set_call_results(input.robot, &input.service, now.calls.clone());
            }
        }
        Choice::Results {
            input,
            value,
            ref mut at_call,
        } => {
            let results = &inputs.results[input];
            let now = &mut world.results[input];
            // The calls done (by this process or an earlier one) keep
            // what they were given.
            let done = sim.calls_done(results.robot, &results.service);
            *at_call = now.used.max(done);
            now.class = value;
            now.give_from(*at_call, results.values[value].clone());
            sim.set_call_results(results.robot, &results.service, now.calls.clone());
        }
        Choice::Sensor { input, value } => {
            let s = &inputs.sensors[input];
            sim.set_sensor(s.robot, &s.port, &s.values[value]);
            world.classes[input] = value;
        }
        Choice::Command { input, value } => {
            let c = &inputs.commands[input];
            sim.give_command(&c.to, &format!("USER.{}", c.value), &c.values[value]);
        }
        Choice::Kill { robot } => {
            for (input, now) in inputs.results.iter().zip(&mut world.results) {
                if input.robot == robot {
                    now.used = now.used.max(sim.calls_done(robot, &input.service));
                }
            }
            sim.kill(robot);
            world.down[robot] = true;
        }
        Choice::Restart { robot } => {
            sim.restart(robot);
            world.down[robot] = false;
            // A new process reads the world as it is now (a replay's
            // scenario holds every value set so far).
            for (s, input) in inputs.sensors.iter().enumerate() {
                if input.robot == robot {
                    sim.set_sensor(robot, &input.port, &input.values[world.classes[s]]);
                }
            }
            // Its calls count from the first again, as a replay's would.
            for (input, now) in inputs.results.iter().zip(&world.results) {
                if input.robot == robot {
                    sim.set_call_results(robot, &input.service, now.calls.clone());
                }
            }
        }
        Choice::Isolate { robot } => {
            sim.isolate(Some(robot));
            world.isolated = Some(robot);
        }
        Choice::Heal => {
            sim.isolate(None);
            world.isolated = None;
        }
        Choice::Lose { a, b } => sim.disturb(a, b, sim.now() + world.step_ms, None),
        Choice::Delay { a, b } => sim.disturb(a, b, sim.now() + world.step_ms, Some(world.step_ms)),
    }
}

/// The choices from the start to node `id`, then `last` at `at`, the run
/// ending a step (`step_ms`) later.
fn counterexample(nodes: &[Node], id: u32, last: &Choice, at: i64, step_ms: i64) -> Counterexample {
    let mut choices = vec![(at, last.clone())];
    let mut here = Some(id);
    while let Some(n) = here {
        let node = &nodes[n as usize];
        choices.push((node.at, node.choice.clone()));
        here = node.parent;
    }
    choices.reverse();
    Counterexample {
        choices,
        end_ms: at + step_ms,
        step_ms,
    }
}

/// The shortest way to state `n` (its state shows at the end).
fn way_to(nodes: &[Node], n: usize, step_ms: i64) -> Counterexample {
    let node = &nodes[n];
    match node.parent {
        Some(p) => counterexample(nodes, p, &node.choice, node.at, step_ms),
        None => Counterexample {
            choices: vec![(0, node.choice.clone())],
            end_ms: step_ms,
            step_ms,
        },
    }
}

/// Per state: the states with a step into it.
fn reversed(states: usize, edges: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut into = vec![Vec::new(); states];
    for &(from, to) in edges {
        into[to as usize].push(from);
    }
    into
}

/// The state graph of an exhaustive search, for the properties judged on
/// every state's future.
struct Graph<'a> {
    nodes: &'a [Node],
    /// Per state: the states with a step into it.
    into: Vec<Vec<u32>>,
    step_ms: i64,
}

impl Graph<'_> {
    /// The states from which some state in `target` can be reached.
    fn can_reach(&self, target: impl Fn(&Node) -> bool) -> Vec<bool> {
        let mut reached: Vec<bool> = self.nodes.iter().map(target).collect();
        let mut work: Vec<u32> = (0..self.nodes.len() as u32)
            .filter(|&n| reached[n as usize])
            .collect();
        while let Some(n) = work.pop() {
            for &p in &self.into[n as usize] {
                if !reached[p as usize] {
                    reached[p as usize] = true;
                    work.push(p);
                }
            }
        }
        reached
    }

    fn way_to(&self, n: usize) -> Counterexample {
        way_to(self.nodes, n, self.step_ms)
    }

    /// Per robot that finishes in some state: the first state (the
    /// shallowest) from which no state where it has finished can be reached.
    fn stuck(&self, robots: usize) -> Vec<(usize, Counterexample, Option<usize>)> {
        let mut found = Vec::new();
        for r in 0..robots {
            if !self.nodes.iter().any(|n| n.finished[r]) {
                continue;
            }
            let can_finish = self.can_reach(|n| n.finished[r]);
            // A robot the world killed is not stuck: it is gone.
            let stuck = (0..self.nodes.len()).find(|&n| !can_finish[n] && !self.nodes[n].down[r]);
            if let Some(n) = stuck {
                let mode = self.nodes[n].modes[r].map(usize::from);
                found.push((r, self.way_to(n), mode));
            }
        }
        found
    }

    /// Per `receive` a robot waits in in some state: the first state (the
    /// shallowest) from which it waits there for ever, if any.
    fn waits_for_ever(&self) -> Vec<((usize, ServiceMachineId, StateId), Counterexample)> {
        let mut receives: Vec<(u32, u32, u32)> = self
            .nodes
            .iter()
            .flat_map(|n| n.waiting.iter().copied())
            .collect();
        receives.sort_unstable();
        receives.dedup();
        let mut found = Vec::new();
        for w in receives {
            // It leaves from a state where it does not wait there, or from
            // which it acts in some step (the step may take it through the
            // `receive` and back between two looks).
            let leaves = self.can_reach(|n| !n.waiting.contains(&w) || n.moved.contains(&w.0));
            if let Some(n) = leaves.iter().position(|l| !l) {
                // Packed from `Sim::waiting_receives` in `admit`.
                let (service, state) = (w.1 as usize, w.2 as usize);
                let at = (ServiceMachineId::new(service), StateId::new(state));
                found.push(((w.0 as usize, at.0, at.1), self.way_to(n)));
            }
        }
        found
    }
}

/// The user's properties through the search: each step's label, the
/// steps themselves (kept only when there are properties), and the first
/// witness of each broken `always`.
struct Judge<'a> {
    properties: &'a [Property],
    /// The robots' index by name, made once for every step's timeline.
    robots: std::rc::Rc<crate::fasthash::FastMap<&'a str, usize>>,
    /// Per robot: its modes' names, shared by every step's timeline.
    modes: Vec<Vec<std::rc::Rc<str>>>,
    steps: Vec<(u32, u32, Choice, Label)>,
    /// Per property: the first way to a step that breaks it (`always`).
    witnesses: Vec<Option<Counterexample>>,
    /// The bits of the `always` properties in a label.
    always: Label,
}

impl<'a> Judge<'a> {
    fn new(programs: &'a [RobotProgram], properties: &'a [Property]) -> Judge<'a> {
        let always = (0..properties.len())
            .filter(|&p| {
                matches!(
                    properties[p].judged,
                    crate::sim::scenario::ExpectKind::Always(_)
                )
            })
            .fold(0, |bits, p| bits | 1 << (2 * p));
        Judge {
            properties,
            robots: crate::sim::temporal::Timeline::index(
                programs.iter().map(|p| p.robot.as_str()).collect(),
            ),
            modes: programs
                .iter()
                .map(|p| {
                    p.control
                        .modes
                        .iter()
                        .map(|m| m.name.as_str().into())
                        .collect()
                })
                .collect(),
            steps: Vec::new(),
            witnesses: vec![None; properties.len()],
            always,
        }
    }

    /// The label of the step out of `from` whose trace is `trace`.
    fn label(&self, from: &Node, trace: &[crate::sim::TraceEvent]) -> Label {
        if self.properties.is_empty() {
            return 0;
        }
        // Each robot's mode when the step starts; a killed one is in none.
        let modes = (0..self.modes.len())
            .map(|r| match (from.down[r], from.modes[r]) {
                (false, Some(m)) => self.modes[r].get(usize::from(m)).cloned(),
                _ => None,
            })
            .collect();
        let mut timeline = crate::sim::temporal::Timeline::sharing(
            self.robots.clone(),
            self.properties.iter().map(|p| &p.judged),
            modes,
        );
        for e in trace {
            timeline.see(e);
        }
        timeline.close_instant();
        properties::label_of(self.properties, timeline.status())
    }

    fn always_broken(&self, label: Label) -> bool {
        label & self.always != 0
    }

    /// Keeps the way (made only if needed) as the witness of each `always`
    /// the step breaks that has none yet (breadth first: the shallowest).
    fn witness(&mut self, label: Label, way: impl Fn() -> Counterexample) {
        for p in 0..self.properties.len() {
            if label & self.always & (1 << (2 * p)) != 0 && self.witnesses[p].is_none() {
                self.witnesses[p] = Some(way());
            }
        }
    }

    fn step(&mut self, from: u32, to: u32, choice: &Choice, label: Label) {
        if !self.properties.is_empty() {
            self.steps.push((from, to, choice.clone(), label));
        }
    }

    /// What became of each property.
    fn outcomes(&mut self, nodes: &[Node], exhaustive: bool, step_ms: i64) -> Vec<Outcome> {
        if self.properties.is_empty() {
            return Vec::new();
        }
        let tree: Vec<(Option<u32>, Choice, i64)> = nodes
            .iter()
            .map(|n| (n.parent, n.choice.clone(), n.at))
            .collect();
        let steps = properties::Steps {
            tree: &tree,
            steps: &self.steps,
            step_ms,
        };
        let broken = |way: Counterexample, why: &str| Outcome::Broken {
            why: why.to_string(),
            way,
        };
        (0..self.properties.len())
            .map(|p| match &self.properties[p].judged {
                crate::sim::scenario::ExpectKind::Always(_) => match self.witnesses[p].take() {
                    Some(way) => broken(way, "a behaviour reaches an instant where it does not hold"),
                    None => Outcome::Holds { proof: exhaustive },
                },
                _ if !exhaustive => Outcome::NotJudged,
                crate::sim::scenario::ExpectKind::Eventually(_) => match steps.eventually_broken(p) {
                    Some(way) => broken(way, "a behaviour never reaches an instant where it holds: it ends, or goes round for ever, without one"),
                    None => Outcome::Holds { proof: true },
                },
                _ => match steps.leads_to_broken(p) {
                    Some(way) => broken(way, "after an instant where the first condition holds, a behaviour never reaches one where the second does"),
                    None => Outcome::Holds { proof: true },
                },
            })
            .collect()
    }
}
