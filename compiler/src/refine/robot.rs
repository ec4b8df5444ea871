//! One robot's program: the control machine and the tasks it uses.

use super::RefineInput;
use super::program::*;
use super::value::{Value, ValueKind};
use crate::catalog::{Implementation, RobotType};
use crate::diag::{Code, Diagnostic};
use crate::sema::{Compared, ServiceId, Symbol, Team, TeamId};
use crate::span::Span;
use crate::strategy::{DataCharacteristic, Parameter, Passed, ServiceEntry, Strategy, TaskUseKind};
use crate::syntax::ast::{self, ExprKind, StmtKind};
use crate::text::LineIndex;
use std::collections::{BTreeMap, BTreeSet, HashMap};

mod battery;
mod loops;
pub(super) mod shared;

#[cfg(test)]
pub(super) use loops::steps_of;

/// How often sensor tasks sample, in mission milliseconds.
pub const SENSOR_PERIOD_MS: i64 = 100;
/// How deep function calls may nest before refinement gives up (sema
/// already rejects recursion; this only bounds the work).
const MAX_INLINE_DEPTH: usize = 32;

pub(super) fn refine_robot(
    input: &RefineInput<'_>,
    lines: &LineIndex,
    peers: &std::sync::Arc<[(String, String)]>,
    team_id: TeamId,
    first_peer: usize,
    robot_index: usize,
    runners: &mut TeamRunners,
) -> (Option<RobotProgram>, Vec<Diagnostic>) {
    let mission = &input.analysis.mission;
    let team = mission.team(team_id);
    let robot = &team.robots[robot_index];
    let Some(robot_type) = robot.robot_type.map(|id| input.catalog.get(id)) else {
        return (None, Vec::new()); // an unknown type is a check error
    };
    let mut builder = Builder {
        input,
        lines,
        team_id,
        team,
        first_peer,
        robot_index,
        robot_type,
        machine: ControlMachine::default(),
        slot_index: HashMap::new(),
        sensors: BTreeMap::new(),
        services: BTreeMap::new(),
        service_machines: HashMap::new(),
        action_machines: HashMap::new(),
        current_service: None,
        arguments: Vec::new(),
        counted_within: Vec::new(),
        runners,
        diagnostics: Vec::new(),
    };
    builder.build_modes();
    builder.machine.battery = builder.battery_policies();
    builder.machine.events_heard = builder.events_heard();
    let graph_services = builder.graph_services();
    let first_peer = builder.first_peer();
    let self_peer = PeerId::new(first_peer + robot_index);
    let team_leader = builder.team_leader_algorithm();
    let Builder {
        mut machine,
        mut sensors,
        services,
        diagnostics,
        ..
    } = builder;
    separate_sensor_tasks(&mut machine, &mut sensors, &services);
    link_own_publications(&mut machine);
    let library = shared::library(team, first_peer, team_leader, &mut machine);
    let mut tasks: Vec<TaskRole> = sensors
        .into_iter()
        .map(|(task, values)| TaskRole {
            task,
            kind: RoleKind::Sensor {
                values: values.into_iter().collect(),
                period_ms: SENSOR_PERIOD_MS,
            },
        })
        .collect();
    tasks.extend(services.into_iter().map(|(task, services)| TaskRole {
        task,
        kind: RoleKind::Service {
            services: services.into_iter().collect(),
        },
    }));
    if !machine.outgoing.is_empty() {
        tasks.push(TaskRole {
            task: graph::COMM_SEND.into(),
            kind: RoleKind::CommSend,
        });
    }
    if machine.has_receiver() {
        tasks.push(TaskRole {
            task: graph::COMM_RECEIVE.into(),
            kind: RoleKind::CommReceive,
        });
    }
    let mut program = RobotProgram {
        mission: input.mission_name.to_string(),
        team: team.name.to_string(),
        robot: robot.name.to_string(),
        robot_type: robot_type.name.clone(),
        capacities: Vec::new(),
        graph: crate::taskgraph::TaskGraph {
            name: robot.name.to_string(),
            file: input.file,
            span: team.name_span,
            tasks: Vec::new(),
            channels: Vec::new(),
            libraries: Vec::new(),
        },
        control: std::sync::Arc::new(machine),
        tasks,
        peers: std::sync::Arc::clone(peers),
        self_peer,
        library,
        graph_services,
    };
    program.graph = graph::build(&program);
    let (capacities, found) = graph::check(&program.graph, input.file, robot.name_span);
    program.capacities = capacities;
    let mut diagnostics = diagnostics;
    diagnostics.extend(found);
    (Some(program), diagnostics)
}

use super::graph;

struct Builder<'a, 'i> {
    input: &'a RefineInput<'i>,
    lines: &'a LineIndex,
    team_id: TeamId,
    team: &'a Team,
    /// The peer index of the team's first robot (peers are in formation order).
    first_peer: usize,
    robot_index: usize,
    robot_type: &'a RobotType,
    machine: ControlMachine,
    slot_index: HashMap<(String, bool), SlotId>,
    /// Sensor task → the values it provides.
    sensors: BTreeMap<String, BTreeSet<String>>,
    /// Service task → the services or actuator commands it runs.
    services: BTreeMap<String, BTreeSet<String>>,
    /// Team service → machine index.
    /// Team service and its arguments as written (none for a service
    /// without parameters) → machine index: a service with parameters is
    /// one machine per distinct list of arguments, as written by hand.
    service_machines: HashMap<(ServiceId, Vec<String>), ServiceMachineId>,
    /// (strategy file, entry index) → action machine index.
    action_machines: HashMap<(u32, usize), ActionMachineId>,
    /// The team service whose machine is being built (for the strategy's
    /// leader selection scoped to a composite service).
    current_service: Option<ServiceId>,
    /// The arguments of the function calls being inlined, innermost last:
    /// in a function's body its parameter `i` is its call's argument `i`,
    /// refined where the parameter is used, in the caller's frame, as a
    /// hand-written copy would be (the same slots, made in the same order).
    arguments: Vec<Vec<ast::Arg>>,
    /// The arms of counted groups the statement being refined is written
    /// in, outermost first (a nested statement splits only its arm's robots).
    counted_within: Vec<EnclosingArm>,
    /// The team's robots that run each scope, shared by its robots.
    runners: &'a mut TeamRunners,
    diagnostics: Vec<Diagnostic>,
}

/// The robots of one team that run each scope (by its span), found once for
/// the team: every robot of the team asks for the same scopes, and a set
/// made per robot (the `others` of a swarm's group statements hold every
/// robot) cost the square of the team's robots.
#[derive(Default)]
pub(super) struct TeamRunners(HashMap<Span, Option<std::rc::Rc<BTreeSet<usize>>>>);

impl<'i> Builder<'_, 'i> {
    /// The strategy files written for this robot's team, in file order.
    fn team_strategies(&self) -> impl Iterator<Item = &'i Strategy> + use<'_, 'i> {
        let team = self.team.name.as_str();
        self.input
            .strategies
            .iter()
            .filter(move |s| s.team.as_ref().is_some_and(|t| t.name == team))
    }
}

impl Builder<'_, '_> {
    fn line(&self, span: Span) -> u32 {
        let text = self.input.text;
        let offset = span.start.min(text.len());
        self.lines
            .line_col(text, offset, crate::text::ColumnUnit::Utf8)
            .line
            + 1
    }

    /// The statement's first line as written, for a comment.
    fn excerpt(&self, span: Span) -> String {
        let text = self.input.text;
        let start = span.start.min(text.len());
        let end = span.end.clamp(start, text.len());
        let first = text[start..end].lines().next().unwrap_or("").trim();
        let mut short: String = first.chars().take(70).collect();
        if short.len() < first.len() {
            short.push_str("...");
        }
        short
    }

    /// The peer index of the team's first robot (peers are in formation order).
    fn first_peer(&self) -> usize {
        self.first_peer
    }

    /// A condition the checker should have excluded: refinement refuses
    /// rather than generate a program that differs from the mission.
    /// The name a strategy file is shown by in generated comments.
    fn strategy_name(&self, strategy: &Strategy) -> String {
        self.input
            .strategy_names
            .iter()
            .find(|(f, _)| *f == strategy.file)
            .map(|(_, n)| n.clone())
            .unwrap_or_default()
    }

    fn internal_error(&mut self, span: Span, what: &str) {
        let line = self.line(span);
        self.diagnostics.push(Diagnostic::new(
            Code::CodegenInternal,
            self.input.file,
            span,
            format!(
                "internal error while refining robot `{}` (line {line}): {what}; please report it",
                self.team.robots[self.robot_index].name
            ),
        ));
    }

    fn unsupported(&mut self, span: Span, what: &str) {
        self.diagnostics.push(Diagnostic::new(
            Code::CodegenUnsupported,
            self.input.file,
            span,
            format!("code generation does not support {what} yet"),
        ));
    }

    fn build_modes(&mut self) {
        let team = self.team;
        for mode in &team.modes {
            let mut regions = Vec::new();
            for set in &mode.sets {
                let (Some(plan), Some(service)) = (set.plan, set.service) else {
                    continue; // OFF
                };
                let machine = self.service_machine(service, &set.args);
                regions.push(Region {
                    plan: team.plans[plan.index()].name.to_string(),
                    service: machine,
                    timeout_ms: set.timeout_ms.map(|t| t.round() as i64),
                });
            }
            let line = self.line(mode.name_span);
            self.machine.modes.push(ModeState {
                name: mode.name.to_string(),
                line,
                regions,
            });
        }
        if let Some(main) = &team.main {
            // One mode state per team mode, in order (`build_modes`): the
            // team's mode position is the machine's.
            self.machine.default_mode = main.default.map(|d| ModeId::new(d.index()));
            for t in &main.transitions {
                let line = self.line(t.span);
                self.machine.transitions.push(ModeTransition {
                    from: ModeId::new(t.from.index()),
                    event: t.event.to_string(),
                    to: ModeId::new(t.to.index()),
                    line,
                });
            }
        }
    }

    /// The machine of `service` run with `args` (the mode's `set` gives
    /// them, fixed): in its body each parameter is its argument, as in a
    /// copy of the body with the arguments written in place.
    fn service_machine(&mut self, service: ServiceId, args: &[ast::Arg]) -> ServiceMachineId {
        let written: Vec<String> = args.iter().map(ast::Arg::written).collect();
        let key = (service, written);
        if let Some(&m) = self.service_machines.get(&key) {
            return m;
        }
        let info = &self.team.services[service.index()];
        if info.params.len() != args.len() {
            let what = format!(
                "`{}` takes {} arguments, yet the checker let a mode set it with {}",
                info.name,
                info.params.len(),
                args.len()
            );
            self.internal_error(info.name_span, &what);
        }
        let name = match key.1.is_empty() {
            true => info.name.to_string(),
            false => format!("{}({})", info.name, key.1.join(", ")),
        };
        let index = ServiceMachineId::new(self.machine.services.len());
        self.service_machines.insert(key, index);
        self.machine.services.push(ServiceMachine {
            plan: self.team.plans[info.plan.index()].name.to_string(),
            name,
            line: self.line(info.name_span),
            states: Vec::new(),
            marks: 0,
        });
        let mut states = Vec::new();
        let mut marks = 0;
        let outer = self.current_service.replace(service);
        // The service's parameters are its arguments: the frame under any
        // function call its body inlines.
        self.arguments.push(args.to_vec());
        if let Some(syntax) = self.input.analysis.service_syntax(info) {
            self.block(&syntax.body, &mut states, &mut marks, 0);
            let (period_ms, condition, forever, span, period_span) = match &syntax.repeat {
                Some(r) => (
                    r.period.as_ref().and_then(period_ms),
                    r.condition.as_ref().map(|c| self.condition(c)),
                    r.period.is_none() && r.condition.is_none(),
                    r.span,
                    r.period.as_ref().map_or(r.span, |p| p.span),
                ),
                None => (None, None, false, syntax.body.span, syntax.body.span),
            };
            let line = self.line(span);
            let text = if syntax.repeat.is_some() {
                self.excerpt(span)
            } else {
                "end of the service".into()
            };
            states.push(State {
                kind: StateKind::Repeat {
                    period_ms,
                    condition,
                    forever,
                },
                line,
                span: period_span,
                text,
            });
        }
        self.arguments.pop();
        self.current_service = outer;
        let m = &mut self.machine.services[index.index()];
        m.states = states;
        m.marks = marks;
        index
    }

    /// The robot sends heartbeats at least every `period_ms`: one heartbeat
    /// serves every election and sync of the robot, at the shortest period
    /// any of them asks for.
    fn need_heartbeat(&mut self, period_ms: i64) {
        if !self.machine.heartbeat || period_ms < self.machine.heartbeat_ms {
            self.machine.heartbeat_ms = period_ms;
        }
        self.machine.heartbeat = true;
    }

    /// `<GroupSync timeout>` of the team's strategy: the robots that run any
    /// arm of a group statement meet at its start (a `GroupSync` state) when
    /// this robot is one of them and not alone. Membership is the checker's
    /// (`scopes`); liveness comes from heartbeats.
    fn group_sync(
        &mut self,
        group: &ast::GroupStmt,
        span: Span,
        states: &mut Vec<State>,
        marks: &mut usize,
    ) {
        let timeout = self
            .team_strategies()
            .find_map(|s| s.grouping.as_ref()?.sync_timeout);
        let Some(timeout) = timeout else {
            return;
        };
        let bodies = group
            .arms
            .iter()
            .map(|a| a.body.span)
            .chain(group.others.as_ref().map(|o| o.body.span));
        let mut members: BTreeSet<usize> = BTreeSet::new();
        for body in bodies.collect::<Vec<_>>() {
            members.extend(self.runners_of(body).iter().flat_map(|r| r.iter()));
        }
        if !members.contains(&self.robot_index) || members.len() < 2 {
            return;
        }
        let first_peer = self.first_peer();
        let point = match self
            .machine
            .sync_points
            .iter()
            .position(|&p| p == span.start)
        {
            Some(i) => SyncPointId::new(i),
            None => {
                self.machine.sync_points.push(span.start);
                SyncPointId::new(self.machine.sync_points.len() - 1)
            }
        };
        let (_, heartbeat_ms) = self.leader_selection();
        self.need_heartbeat(heartbeat_ms.unwrap_or(HEARTBEAT_MS));
        let mark = next_mark(marks);
        let state = self.push(
            states,
            StateKind::GroupSync {
                members: members
                    .into_iter()
                    .map(|i| PeerId::new(first_peer + i))
                    .collect(),
                point,
                timeout_ms: (timeout.millis.round() as i64).max(0),
                mark,
            },
            span,
        );
        states[state.index()].text = "GroupSync: the group meets here".into();
    }

    /// The strategy's leader selection for an election in the service being
    /// built: the team's `LeaderSelectionInfo` when it names no composite
    /// service or names this one; its algorithm (default lowest id) and its
    /// heartbeat period (mission ms, if given).
    fn leader_selection(&self) -> (LeaderAlgorithm, Option<i64>) {
        let service = self.current_service.map(|s| &self.team.services[s.index()]);
        let applies = |l: &crate::strategy::LeaderSelection| match (&l.plan, &l.service, service) {
            (Some(plan), Some(cs), Some(s)) => {
                cs.name == s.name.as_str()
                    && plan.name == self.team.plans[s.plan.index()].name.as_str()
            }
            (Some(_), Some(_), None) => false,
            _ => true,
        };
        let selection = self
            .team_strategies()
            .filter_map(|s| s.grouping.as_ref()?.leader_selection.as_ref())
            .find(|l| applies(l));
        match selection {
            Some(l) => (
                l.algorithm.unwrap_or(LeaderAlgorithm::LowestId),
                l.heartbeat.map(|d| (d.millis.round() as i64).max(1)),
            ),
            None => (LeaderAlgorithm::LowestId, None),
        }
    }

    /// The team's leader selection algorithm: its `LeaderSelectionInfo`
    /// that names no composite service, else `lowest_id` (who owns the
    /// team's globally shared values, `shared::owners_of_team`).
    fn team_leader_algorithm(&self) -> LeaderAlgorithm {
        self.team_strategies()
            .filter_map(|s| s.grouping.as_ref()?.leader_selection.as_ref())
            .find(|l| l.plan.is_none() && l.service.is_none())
            .and_then(|l| l.algorithm)
            .unwrap_or(LeaderAlgorithm::LowestId)
    }

    fn block(
        &mut self,
        block: &ast::Block,
        states: &mut Vec<State>,
        marks: &mut usize,
        depth: usize,
    ) {
        for stmt in &block.stmts {
            self.stmt(stmt, states, marks, depth);
        }
    }

    fn push(&self, states: &mut Vec<State>, kind: StateKind, span: Span) -> StateId {
        states.push(State {
            kind,
            line: self.line(span),
            span,
            text: self.excerpt(span),
        });
        StateId::new(states.len() - 1)
    }

    /// Pushes a state that jumps forward past a block not refined yet
    /// (`Branch`, `Jump`, `LoopHead`, `LeaderBranch`): `make` builds it with
    /// its target, which is the state itself until [`land`] sets it.
    fn push_forward(
        &self,
        states: &mut Vec<State>,
        span: Span,
        make: impl FnOnce(StateId) -> StateKind,
    ) -> Forward {
        let at = StateId::new(states.len());
        Forward(self.push(states, make(at), span))
    }

    fn stmt(&mut self, stmt: &ast::Stmt, states: &mut Vec<State>, marks: &mut usize, depth: usize) {
        match &stmt.kind {
            StmtKind::If(i) => {
                let condition = self.condition(&i.condition);
                let branch = self.push_forward(states, stmt.span, |else_to| StateKind::Branch {
                    condition,
                    else_to,
                });
                self.block(&i.then_block, states, marks, depth);
                match &i.else_branch {
                    None => land(states, branch),
                    Some(else_branch) => {
                        let jump =
                            self.push_forward(states, stmt.span, |to| StateKind::Jump { to });
                        states[jump.0.index()].text = "end of the `if` branch".into();
                        land(states, branch);
                        match else_branch.as_ref() {
                            ast::Else::If(s) => self.stmt(s, states, marks, depth),
                            ast::Else::Block(b) => self.block(b, states, marks, depth),
                        }
                        land(states, jump);
                    }
                }
            }
            StmtKind::Loop(l) => {
                let mark = next_mark(marks);
                let condition = l.condition.as_ref().map(|c| self.condition(c));
                let head = self.push_forward(states, stmt.span, |exit_to| StateKind::LoopHead {
                    condition,
                    exit_to,
                    mark,
                });
                self.block(&l.body, states, marks, depth);
                let tail = self.push(
                    states,
                    StateKind::LoopTail {
                        period_ms: l.period.as_ref().and_then(period_ms),
                        mark,
                        to: head.0,
                    },
                    stmt.span,
                );
                states[tail.index()].text = "end of the loop body".into();
                if let Some(period) = &l.period {
                    states[tail.index()].span = period.span;
                }
                land(states, head);
            }
            StmtKind::Group(g) => {
                self.group_sync(g, stmt.span, states, marks);
                // Group membership is static for a robot: its type and
                // capabilities decide which arm it joins (the others are
                // dropped from its program).
                if g.arms
                    .first()
                    .is_some_and(|a| a.condition.kind == ast::CondKind::Counted)
                {
                    return self.counted_groups(g, stmt.span, states, marks, depth);
                }
                match self.chosen_arm(g) {
                    ArmChoice::Static(Some(body)) => self.block(body, states, marks, depth),
                    ArmChoice::Static(None) => {}
                    ArmChoice::Leader {
                        body,
                        others,
                        candidates,
                    } => {
                        // Peer indices of the candidates, in formation order:
                        // the first one alive leads.
                        let first_peer = self.first_peer();
                        let candidates = candidates
                            .iter()
                            .map(|i| PeerId::new(first_peer + i))
                            .collect();
                        let (algorithm, heartbeat_ms) = self.leader_selection();
                        self.need_heartbeat(heartbeat_ms.unwrap_or(HEARTBEAT_MS));
                        let branch = self.push_forward(states, stmt.span, |others_at| {
                            StateKind::LeaderBranch {
                                candidates,
                                algorithm,
                                others_at,
                                receives: Vec::new(),
                            }
                        });
                        self.block(body, states, marks, depth);
                        let body_states = &states[branch.0.index() + 1..];
                        let received = received_in(body_states);
                        if let StateKind::LeaderBranch { receives, .. } =
                            &mut states[branch.0.index()].kind
                        {
                            *receives = received;
                        }
                        let jump =
                            self.push_forward(states, stmt.span, |to| StateKind::Jump { to });
                        states[jump.0.index()].text = "end of the leader's block".into();
                        land(states, branch);
                        if let Some(others) = others {
                            self.block(others, states, marks, depth);
                        }
                        land(states, jump);
                    }
                }
            }
            StmtKind::Comm(c) => self.comm(c, stmt.span, states, marks),
            StmtKind::Throw(throw) => {
                let broadcast = match throw.broadcast {
                    Some(_) => match self.broadcast_messages(&throw.event) {
                        Some(messages) => Some(messages),
                        None => {
                            self.internal_error(
                                stmt.span,
                                "the checker recorded no robots for this broadcast",
                            );
                            return;
                        }
                    },
                    None => None,
                };
                self.push(
                    states,
                    StateKind::Throw {
                        event: throw.event.name.to_string(),
                        broadcast,
                    },
                    stmt.span,
                );
            }
            StmtKind::Call(call) => self.call(call, stmt.span, states, marks, depth),
            StmtKind::Error => {}
        }
    }

    /// `[[ group(Name, min = N) ... ]]`: every arm is in the program (which
    /// one this robot runs is decided at run time, `GroupAllocate`), each
    /// ending in a jump past the others; `others` last. The members are the
    /// robots the checker walked the statement with (every arm's runners).
    fn counted_groups(
        &mut self,
        g: &ast::GroupStmt,
        span: Span,
        states: &mut Vec<State>,
        marks: &mut usize,
        depth: usize,
    ) {
        let Some(first) = g.arms.first() else {
            return;
        };
        let Some(runners) = self.runners_of(first.body.span) else {
            return;
        };
        if !runners.contains(&self.robot_index) {
            return;
        }
        let first_peer = self.first_peer();
        let members: Vec<PeerId> = runners
            .iter()
            .map(|i| PeerId::new(first_peer + i))
            .collect();
        let (_, heartbeat_ms) = self.leader_selection();
        self.need_heartbeat(heartbeat_ms.unwrap_or(HEARTBEAT_MS));
        let mut named = Vec::new();
        for arm in &g.arms {
            let (Some(name), Some(min)) = (arm.condition.counted_name(), &arm.condition.min) else {
                self.internal_error(
                    arm.condition.span,
                    "a counted group without its name or min",
                );
                return;
            };
            let Some(min) = min.count.value.filter(|&n| n > 0) else {
                self.internal_error(min.count.span, "a counted group's min the checker refused");
                return;
            };
            named.push((name.name.to_string(), min as usize));
        }
        let allocate = self.push(
            states,
            StateKind::GroupAllocate {
                members: members.clone(),
                groups: Vec::new(),
                others_at: None,
                within: self.counted_within.clone(),
                nested: Vec::new(),
            },
            span,
        );
        states[allocate.index()].text = "counted groups: this robot's group".into();
        let enclosing = |arm| EnclosingArm {
            members: members.clone(),
            mins: named.iter().map(|(_, min)| *min).collect(),
            has_others: g.others.is_some(),
            arm,
        };
        let mut groups = Vec::new();
        let mut ends = Vec::new();
        for (k, (arm, (name, min))) in g.arms.iter().zip(named.iter().cloned()).enumerate() {
            let at = StateId::new(states.len());
            self.counted_within.push(enclosing(Some(k)));
            self.block(&arm.body, states, marks, depth);
            self.counted_within.pop();
            let jump = self.push_forward(states, span, |to| StateKind::Jump { to });
            states[jump.0.index()].text = format!("end of group {name}");
            ends.push(jump);
            groups.push(CountedGroup { name, min, at });
        }
        let others_at = g.others.as_ref().map(|others| {
            let at = StateId::new(states.len());
            self.counted_within.push(enclosing(None));
            self.block(&others.body, states, marks, depth);
            self.counted_within.pop();
            at
        });
        let inner: Vec<StateId> = (allocate.index() + 1..states.len())
            .filter(|&i| matches!(states[i].kind, StateKind::GroupAllocate { .. }))
            .map(StateId::new)
            .collect();
        if let StateKind::GroupAllocate {
            groups: g,
            others_at: o,
            nested,
            ..
        } = &mut states[allocate.index()].kind
        {
            *g = groups;
            *o = others_at;
            *nested = inner;
        }
        for jump in ends {
            land(states, jump);
        }
    }

    /// What this robot runs of a group statement, as the checker decided it
    /// (`Mission::scopes`: each arm's body with the robots that run it): the
    /// first arm it runs, else `others`. For a `leader` arm it runs, the choice
    /// is made at run time among the robots that run that arm (see
    /// [`StateKind::LeaderBranch`]).
    fn chosen_arm<'s>(&mut self, group: &'s ast::GroupStmt) -> ArmChoice<'s> {
        let others = group.others.as_ref().map(|o| &o.body);
        for arm in &group.arms {
            let Some(runners) = self.runners_of(arm.body.span) else {
                return ArmChoice::Static(None);
            };
            if !runners.contains(&self.robot_index) {
                continue;
            }
            if arm.kind == ast::ArmKind::Leader {
                // A robot the checker does not let run `others` (the only
                // candidate always leads) has no `others` branch.
                let others = match others {
                    Some(body) => self
                        .runners_of(body.span)
                        .filter(|r| r.contains(&self.robot_index))
                        .map(|_| body),
                    None => None,
                };
                return ArmChoice::Leader {
                    body: &arm.body,
                    others,
                    candidates: runners.iter().copied().collect(),
                };
            }
            return ArmChoice::Static(Some(&arm.body));
        }
        match others {
            Some(body) => match self.runners_of(body.span) {
                Some(runners) if runners.contains(&self.robot_index) => {
                    ArmChoice::Static(Some(body))
                }
                _ => ArmChoice::Static(None),
            },
            None => ArmChoice::Static(None),
        }
    }

    /// The robots of this robot's team that run the scope at `span`, as the
    /// checker recorded them (every context it was checked in). A body the
    /// checker did not record is an internal error.
    fn runners_of(&mut self, span: Span) -> Option<std::rc::Rc<BTreeSet<usize>>> {
        let (mission, team) = (&self.input.analysis.mission, self.team_id);
        let runners = self.runners.0.entry(span).or_insert_with(|| {
            let first = mission
                .scopes
                .partition_point(|s| s.span.start < span.start);
            let scope = mission.scopes[first..]
                .iter()
                .take_while(|s| s.span.start == span.start)
                .find(|s| s.span == span)?;
            let robots = (scope.runs.iter())
                .filter(|r| r.team == Some(team))
                .flat_map(|r| r.robots.iter().map(|&i| i.index()));
            Some(std::rc::Rc::new(robots.collect()))
        });
        let runners = runners.clone();
        if runners.is_none() {
            self.internal_error(span, "the checker recorded no robots for this block");
        }
        runners
    }

    fn comm(&mut self, comm: &ast::Comm, span: Span, states: &mut Vec<State>, marks: &mut usize) {
        let peer = if crate::sema::is_user(&comm.team.name) {
            "USER".to_string()
        } else {
            comm.team.name.to_string()
        };
        match comm.kind {
            ast::CommKind::Send | ast::CommKind::Publish => {
                let publish = comm.kind == ast::CommKind::Publish;
                let mut items = Vec::new();
                for item in &comm.items {
                    let key = self.attr_key(&item.attr);
                    let message = self.outgoing(&peer, publish, &key);
                    // The value sent: the assigned expression's value (kept in
                    // the team's shared slot), else the attribute's own value.
                    let (value, store) = match &item.value {
                        Some(v) => (
                            self.condition_operand(v),
                            Some(self.shared_slot(&item.attr)),
                        ),
                        None => (self.attr_operand(&item.attr), None),
                    };
                    items.push(SendItem {
                        message,
                        value,
                        store,
                        own_group: None,
                    });
                }
                self.push(states, StateKind::Send { items }, span);
            }
            ast::CommKind::Receive => {
                let mut messages = Vec::new();
                for item in &comm.items {
                    messages.push(self.incoming(&peer, &item.attr));
                }
                let timeout_ms = comm.timeout.as_ref().and_then(period_ms);
                let mark = next_mark(marks);
                self.push(
                    states,
                    StateKind::Receive {
                        messages,
                        timeout_ms,
                        mark,
                    },
                    span,
                );
            }
            ast::CommKind::Subscribe => {
                for item in &comm.items {
                    let key = self.attr_key(&item.attr);
                    let slot = self.shared_slot(&item.attr);
                    let group = match self.machine.subscribed.iter().position(|g| *g == key) {
                        Some(g) => SubscriptionId::new(g),
                        None => {
                            self.machine.subscribed.push(key.clone());
                            SubscriptionId::new(self.machine.subscribed.len() - 1)
                        }
                    };
                    self.push(states, StateKind::Subscribe { group, slot }, span);
                }
            }
        }
    }

    fn call(
        &mut self,
        call: &ast::Call,
        span: Span,
        states: &mut Vec<State>,
        marks: &mut usize,
        depth: usize,
    ) {
        let symbols = crate::sema::lookup::with_span(&self.input.analysis.mission, call.name.span);
        let timeout_ms = call.timeout.as_ref().and_then(period_ms);
        if let Some(function) = symbols.iter().find_map(|o| match o.symbol {
            Symbol::Function(f) => Some(f),
            _ => None,
        }) {
            if depth >= MAX_INLINE_DEPTH {
                self.unsupported(call.name.span, "function calls nested this deep");
                return;
            }
            let info = &self.input.analysis.mission.functions[function.0 as usize];
            if let Some(ast::Item::Function(f)) = self.input.analysis.syntax.items.get(info.item) {
                if call.args.len() != f.params.len() {
                    let what = format!(
                        "`{}` takes {} arguments, yet the checker let a call give {}",
                        f.name.name,
                        f.params.len(),
                        call.args.len()
                    );
                    self.internal_error(call.args_span, &what);
                    return;
                }
                self.arguments.push(call.args.clone());
                self.block(&f.body, states, marks, depth + 1);
                self.arguments.pop();
            }
            return;
        }
        // The built-in service the checker resolved the name to.
        let Some(name) = symbols.iter().find_map(|o| match &o.symbol {
            Symbol::BuiltinService(name) => Some(name.to_string()),
            _ => None,
        }) else {
            let what = format!(
                "the checker resolved the call `{}` to no service or function",
                call.name.name
            );
            self.internal_error(call.name.span, &what);
            return;
        };
        let Some(def) = self.robot_type.service(&name) else {
            let what = format!(
                "robot type `{}` has no service `{name}`, yet the checker let this robot call it",
                self.robot_type.name
            );
            self.internal_error(call.name.span, &what);
            return;
        };
        let service = def.name.clone();
        let args: Vec<Operand> = call.args.iter().map(|a| self.arg(a)).collect();
        self.note_group_service(&service);
        let results = self.result_slots(call);
        let mark = next_mark(marks);
        if let Some(machine) = self.strategy_machine(call.name.span, &service) {
            if !call.results.is_empty() {
                self.unsupported(
                    call.name.span,
                    "action results of a service a strategy refines into actions",
                );
            }
            self.push(
                states,
                StateKind::RunActions {
                    service,
                    machine,
                    args,
                    timeout_ms,
                    mark,
                },
                span,
            );
            return;
        }
        let task = implementing_task(&def.implementation, &service);
        note_gives_back(&mut self.machine.gives_back, def);
        self.services
            .entry(task.clone())
            .or_default()
            .insert(service.clone());
        self.request_task(&task);
        self.push(
            states,
            StateKind::Call {
                service,
                task,
                args,
                timeout_ms,
                mark,
                results,
            },
            span,
        );
    }

    /// The slots of the names `call` binds to its service's results, as
    /// the checker resolved them (one slot per result name of its body).
    fn result_slots(&mut self, call: &ast::Call) -> Vec<SlotId> {
        let mut slots = Vec::with_capacity(call.results.len());
        for name in &call.results {
            let symbols = crate::sema::lookup::with_span(&self.input.analysis.mission, name.span);
            let Some(slot) = symbols.iter().find_map(|o| match o.symbol {
                Symbol::Result { owner, index } if self.owns_body(owner) => Some((owner, index)),
                _ => None,
            }) else {
                let what = format!("the checker resolved the result `{}` to nothing", name.name);
                self.internal_error(name.span, &what);
                continue;
            };
            slots.push(self.result_slot(slot.0, slot.1, name.span));
        }
        slots
    }

    /// Whether the body of `owner` is one this robot's team runs: a
    /// function's, or a service of its team (a shared service's body has a
    /// copy per team).
    fn owns_body(&self, owner: crate::sema::ParamOwner) -> bool {
        match owner {
            crate::sema::ParamOwner::Service(team, _) => team == self.team_id,
            _ => true,
        }
    }

    /// The slot of result `index` of `owner`'s body, typed as the checker
    /// typed it.
    fn result_slot(&mut self, owner: crate::sema::ParamOwner, index: u32, span: Span) -> SlotId {
        let mission = &self.input.analysis.mission;
        let result = &mission.results(owner)[index as usize];
        let key = format!("{}.{}", mission.owner_name(owner), result.name);
        let Some(ty) = result.ty.clone() else {
            let what = format!("the checker gave the result `{}` no type", result.name);
            self.internal_error(span, &what);
            return self.slot(&key, SlotSource::Result, ValueKind::Variable);
        };
        self.slot(&key, SlotSource::Result, ValueKind::declared(&ty))
    }

    /// A call of a service the team's strategy declares a group service
    /// (`<GroupService>`: the catalog's name, in its plan when it names one)
    /// makes this robot a member of the team's group ([`ControlMachine::group`],
    /// filled in once every robot is refined): it then sends heartbeats, whose
    /// absence tells the other members it failed.
    fn note_group_service(&mut self, service: &str) {
        let team = self.team;
        let plan = self
            .current_service
            .map(|s| team.plan(team.service(s).plan).name.as_str());
        let robot_type = self.robot_type;
        let declared = self
            .team_strategies()
            .filter_map(|s| s.grouping.as_ref())
            .flat_map(|g| &g.group_services)
            .any(|g| {
                g.name
                    .as_ref()
                    .and_then(|n| robot_type.service(&n.name))
                    .is_some_and(|d| d.name == service)
                    && g.plan
                        .as_ref()
                        .is_none_or(|p| Some(p.name.as_str()) == plan)
            });
        if !declared || self.machine.group_services.iter().any(|s| s == service) {
            return;
        }
        self.machine.group_services.push(service.to_string());
        let (_, heartbeat_ms) = self.leader_selection();
        self.need_heartbeat(heartbeat_ms.unwrap_or(HEARTBEAT_MS));
    }

    fn request_task(&mut self, task: &str) {
        if !self.machine.request_tasks.iter().any(|t| t == task) {
            self.machine.request_tasks.push(task.to_string());
        }
    }

    fn arg(&mut self, arg: &ast::Arg) -> Operand {
        match arg {
            ast::Arg::Words { text, .. } => Operand::Literal(Value::text(text)),
            ast::Arg::Expr(e) => self.condition_operand(e),
        }
    }

    /// The strategy entry refining the call at `span` for this robot's type.
    fn strategy_machine(&mut self, span: Span, service: &str) -> Option<ActionMachineId> {
        let link = self
            .input
            .links
            .at(self.input.file, span.start)
            .find(|l| l.team == self.team_id && l.call == span)?;
        let strategy = self
            .input
            .strategies
            .iter()
            .find(|s| s.file == link.entry.file)?;
        let entry = strategy.services.get(link.entry.index)?;
        let robot = &self.team.robots[self.robot_index];
        let targeted = entry.targets.is_empty()
            || entry.targets.iter().any(|t| {
                t.name.as_ref().is_some_and(|n| {
                    n.name == self.robot_type.name || self.robot_type.aliases.contains(&n.name)
                }) || t.nick_name.as_ref().is_some_and(|n| n.name == robot.name)
            });
        if !targeted {
            return None;
        }
        let key = (link.entry.file.0, link.entry.index);
        if let Some(&m) = self.action_machines.get(&key) {
            return Some(m);
        }
        let source = self.strategy_name(strategy);
        let machine = self.action_machine(entry, service, source, strategy, span);
        self.machine.actions.push(machine);
        let index = ActionMachineId::new(self.machine.actions.len() - 1);
        self.action_machines.insert(key, index);
        Some(index)
    }

    fn action_machine(
        &mut self,
        entry: &ServiceEntry,
        service: &str,
        source: String,
        strategy: &crate::strategy::Strategy,
        call: Span,
    ) -> ActionMachine {
        // Parameter names the conditions read, to their operands.
        let mut names: HashMap<String, Operand> = HashMap::new();
        let mut arguments = Vec::new();
        for action in &entry.actions {
            for task_use in &action.tasks {
                for p in &task_use.parameters {
                    let Some(name) = &p.name else { continue };
                    match task_use.kind {
                        TaskUseKind::CheckSensor => {
                            let task = p
                                .src_task
                                .as_ref()
                                .map(|t| t.name.clone())
                                .unwrap_or_else(|| name.name.to_lowercase());
                            let value = self
                                .value_of_task(&task, strategy)
                                .unwrap_or_else(|| name.name.clone());
                            let slot = self.sensor_slot_with_task(&value, &task, call);
                            names.insert(name.name.clone(), Operand::Slot(slot));
                        }
                        TaskUseKind::ExecuteActuator | TaskUseKind::ExecuteAlgorithm => {}
                    }
                }
            }
            for p in &action.parameters {
                let Some(name) = &p.name else { continue };
                if p.data == Some(DataCharacteristic::Variable) && p.value.is_none() {
                    let kind = self.parameter_kind(service, arguments.len(), call);
                    let slot =
                        self.slot(&format!("{service}.{}", name.name), SlotSource::Local, kind);
                    if !arguments.contains(&slot) {
                        arguments.push(slot);
                    }
                    names.insert(name.name.clone(), Operand::Slot(slot));
                } else if let Some(v) = &p.value {
                    names.insert(
                        name.name.clone(),
                        Operand::Literal(Value::strategy(&v.name)),
                    );
                }
            }
        }
        // One action state per action of the entry, in order (below).
        let index_of: HashMap<u64, ActionId> = ActionId::all(entry.actions.len())
            .zip(&entry.actions)
            .filter_map(|(i, a)| a.id.as_ref().map(|id| (id.value, i)))
            .collect();
        let mut actions = Vec::new();
        for action in &entry.actions {
            let mut commands = Vec::new();
            for task_use in &action.tasks {
                if task_use.kind == TaskUseKind::CheckSensor {
                    continue;
                }
                let actuator = task_use
                    .name
                    .as_ref()
                    .map(|n| n.name.clone())
                    .unwrap_or_default();
                for p in &task_use.parameters {
                    let task = p
                        .dst_task
                        .as_ref()
                        .map(|t| t.name.clone())
                        .unwrap_or_else(|| actuator.to_lowercase());
                    let command = self.passed(entry, p, service, &names, &mut arguments, call);
                    self.services
                        .entry(task.clone())
                        .or_default()
                        .insert(actuator.clone());
                    self.request_task(&task);
                    commands.push((task, command));
                }
            }
            let mut transitions = Vec::new();
            for t in &action.transitions {
                let Some(to) = t.dst.as_ref().and_then(|d| index_of.get(&d.value)) else {
                    let what = format!(
                        "a transition of strategy action {} of `{service}` goes to no action",
                        action.describe()
                    );
                    self.internal_error(call, &what);
                    continue;
                };
                let condition = match &t.condition {
                    None => None,
                    Some(c) => match &c.expr {
                        Some(e) => Some(self.strategy_condition(e, &names)),
                        None => {
                            let what = format!("the condition `{}` did not parse", c.text);
                            self.internal_error(call, &what);
                            continue;
                        }
                    },
                };
                transitions.push((condition, *to));
            }
            actions.push(ActionState {
                name: action
                    .name
                    .as_ref()
                    .map(|n| n.name.clone())
                    .unwrap_or_default(),
                id: action.id.as_ref().map_or(0, |i| i.value),
                is_final: action.is_final.is_yes(),
                commands,
                transitions,
            });
        }
        let initial = match entry.actions.iter().position(|a| a.initial.is_yes()) {
            Some(i) => ActionId::new(i),
            None => {
                let what = format!("the strategy of `{service}` has no initial action");
                self.internal_error(call, &what);
                ActionId::new(0)
            }
        };
        ActionMachine {
            service: service.to_string(),
            source,
            actions,
            initial,
            arguments,
        }
    }

    /// What a parameter of an actuator or algorithm passes to its task
    /// (`ServiceEntry::passed`, the rule the strategy checker applies): a
    /// parameter of the entry, the call's argument (its slot, one per
    /// position, so that every argument up to it is stored), or a value as
    /// written. Nothing at all the checker refuses (E042).
    fn passed(
        &mut self,
        entry: &ServiceEntry,
        parameter: &Parameter,
        service: &str,
        names: &HashMap<String, Operand>,
        arguments: &mut Vec<SlotId>,
        call: Span,
    ) -> Operand {
        let service_params: Vec<&str> = self
            .robot_type
            .service(service)
            .map(|def| def.params.iter().map(|p| p.name.as_str()).collect())
            .unwrap_or_default();
        match entry.passed(parameter, &service_params) {
            Passed::Named(name) => names[name].clone(),
            Passed::Argument(index) => {
                while arguments.len() <= index {
                    let position = arguments.len();
                    let kind = self.parameter_kind(service, position, call);
                    let key = format!("{service}.{}", service_params[position]);
                    arguments.push(self.slot(&key, SlotSource::Local, kind));
                }
                Operand::Slot(arguments[index])
            }
            Passed::Literal(text) => Operand::Literal(Value::strategy(text)),
            Passed::Nothing => {
                let what =
                    format!("a parameter of `{service}`'s strategy passes nothing to its task",);
                self.internal_error(call, &what);
                Operand::Literal(Value::text(""))
            }
        }
    }

    /// The mission value a strategy task provides (`vicon` → `LOCATION`).
    fn value_of_task(&self, task: &str, strategy: &crate::strategy::Strategy) -> Option<String> {
        for value in &strategy.values {
            let provides = value
                .tasks
                .iter()
                .flat_map(|t| &t.parameters)
                .any(|p| p.src_task.as_ref().is_some_and(|t| t.name == task));
            if provides {
                return value.name.as_ref().map(|n| n.name.clone());
            }
        }
        self.robot_type
            .values
            .iter()
            .find(|v| v.implementation == Implementation::Task(task.to_string()))
            .map(|v| v.name.clone())
    }

    fn strategy_condition(&mut self, expr: &ast::Expr, names: &HashMap<String, Operand>) -> Expr {
        let mut resolve = |attr: &ast::Attr| {
            names
                .get(attr.last().as_str())
                .cloned()
                .unwrap_or_else(|| Operand::Literal(Value::Word(attr.dotted().into())))
        };
        // The strategy checker reads a guard as a variable against numbers
        // (strategy::guards): a comparison with a number compares numbers.
        let mut compare_as = |e: &ast::Expr| match &e.kind {
            ExprKind::Compare(a, _, b)
                if matches!(a.kind, ExprKind::Number(_))
                    || matches!(b.kind, ExprKind::Number(_)) =>
            {
                Compared::Numbers
            }
            _ => Compared::Words,
        };
        convert(expr, &mut resolve, &mut compare_as)
    }

    fn condition(&mut self, expr: &ast::Expr) -> Expr {
        let mut operands = Vec::new();
        collect_attrs(expr, &mut operands);
        let resolved: HashMap<Span, Operand> = operands
            .into_iter()
            .map(|attr| (attr.span, self.attr_operand(attr)))
            .collect();
        let mission = &self.input.analysis.mission;
        let mut untyped = Vec::new();
        let converted = convert(
            expr,
            &mut |attr| {
                resolved
                    .get(&attr.span)
                    .cloned()
                    .unwrap_or_else(|| Operand::Literal(Value::Word(attr.dotted().into())))
            },
            &mut |e| {
                mission.compared_at(e.span).unwrap_or_else(|| {
                    untyped.push(e.span);
                    Compared::Words
                })
            },
        );
        for span in untyped {
            self.internal_error(span, "the checker did not type this comparison");
        }
        converted
    }

    /// An expression used as a value (a call argument, an assignment).
    fn condition_operand(&mut self, expr: &ast::Expr) -> Operand {
        match &expr.kind {
            ExprKind::Attr(a) => self.attr_operand(a),
            other => Operand::Literal(literal_value(other)),
        }
    }

    /// What the checker resolved the attribute to for this robot's team. A
    /// body that several teams run (a service shared by teams, a function
    /// their services call) has one symbol per team at a bare name: this
    /// team's own value or variable is the one its robots read.
    fn symbol_of(&self, attr: &ast::Attr) -> Option<Symbol> {
        let symbols =
            crate::sema::lookup::with_span(&self.input.analysis.mission, attr.last().span);
        let own = symbols.iter().find(|o| match &o.symbol {
            Symbol::Value { owner, .. } => *owner == Some(self.team_id),
            Symbol::TeamVariable { team, .. } => *team == Some(self.team_id),
            // A shared service's result: this team's copy of the body.
            Symbol::Result { owner, .. } => self.owns_body(*owner),
            _ => false,
        });
        own.or(symbols.first()).map(|o| o.symbol.clone())
    }

    /// What an attribute in an expression reads: a sensor, a shared value or
    /// a constant.
    fn attr_operand(&mut self, attr: &ast::Attr) -> Operand {
        match self.symbol_of(attr) {
            // The robot's own value: its sensor when its type has one, else
            // the value its team receives (spec §3: no sensor needed).
            Some(Symbol::Value {
                owner: Some(owner),
                name,
            }) if owner == self.team_id => {
                if self.robot_type.value(&name).is_some() {
                    Operand::Slot(self.sensor_slot(&name, attr.span))
                } else if self.team_receives(&name) {
                    Operand::Slot(self.shared_slot(attr))
                } else {
                    let what = format!(
                        "robot type `{}` has no value `{name}` and its team does not receive it",
                        self.robot_type.name
                    );
                    self.internal_error(attr.span, &what);
                    Operand::Literal(Value::text(""))
                }
            }
            Some(Symbol::Value { .. }) | Some(Symbol::TeamVariable { .. }) => {
                Operand::Slot(self.shared_slot(attr))
            }
            Some(Symbol::Constant(name)) => Operand::Literal(Value::Word(name.into())),
            // The argument of the call being inlined, as its caller gave it.
            Some(Symbol::Parameter { index, .. }) => self.parameter_operand(index, attr),
            Some(Symbol::Result { owner, index }) => {
                Operand::Slot(self.result_slot(owner, index, attr.span))
            }
            other => {
                let what = format!(
                    "`{}` is read as a value, but the checker resolved it to {other:?}",
                    attr.dotted()
                );
                self.internal_error(attr.span, &what);
                Operand::Literal(Value::text(""))
            }
        }
    }

    /// The `index`th argument of the call being inlined, refined in its
    /// caller's frame (an argument that is itself a parameter is the
    /// caller's caller's argument, and so on).
    fn parameter_operand(&mut self, index: u32, attr: &ast::Attr) -> Operand {
        let Some(frame) = self.arguments.pop() else {
            let what = format!(
                "the parameter `{}` is read outside a call of its function",
                attr.dotted()
            );
            self.internal_error(attr.span, &what);
            return Operand::Literal(Value::text(""));
        };
        let operand = match frame.get(index as usize) {
            Some(arg) => self.arg(arg),
            None => {
                let what = format!("the parameter `{}` has no argument", attr.dotted());
                self.internal_error(attr.span, &what);
                Operand::Literal(Value::text(""))
            }
        };
        self.arguments.push(frame);
        operand
    }

    /// Whether the robot's team receives or subscribes to its own value `name`
    /// (the checker's record of every communication).
    fn team_receives(&self, name: &str) -> bool {
        self.input.analysis.mission.messages.iter().any(|m| {
            m.team == self.team_id
                && !m.kind.is_outgoing()
                && m.value.owner == self.team.name
                && m.value.name == name
        })
    }

    /// `Team.NAME` for an attribute as communication keys write it.
    fn attr_key(&self, attr: &ast::Attr) -> String {
        let name = attr.last().name.to_string();
        let name = self.canonical_value_name(attr, &name);
        match attr.segments.as_slice() {
            [_] => format!("{}.{name}", self.team.name),
            [team, _] if crate::sema::is_user(&team.name) => format!("USER.{name}"),
            [team, ..] => format!("{}.{name}", team.name),
            [] => name,
        }
    }

    /// A value's catalog name for an alias (`USER.cmd` → `RC_CMD`).
    fn canonical_value_name(&self, attr: &ast::Attr, name: &str) -> String {
        let symbols =
            crate::sema::lookup::with_span(&self.input.analysis.mission, attr.last().span);
        symbols
            .iter()
            .find_map(|o| match &o.symbol {
                Symbol::Value { name, .. } => Some(name.to_string()),
                _ => None,
            })
            .unwrap_or_else(|| name.to_string())
    }

    fn slot(&mut self, key: &str, source: SlotSource, kind: ValueKind) -> SlotId {
        let sensor = matches!(source, SlotSource::Sensor { .. });
        if let Some(&i) = self.slot_index.get(&(key.to_string(), sensor)) {
            return i;
        }
        self.machine.slots.push(Slot {
            key: key.to_string(),
            source,
            kind,
        });
        let i = SlotId::new(self.machine.slots.len() - 1);
        self.slot_index.insert((key.to_string(), sensor), i);
        i
    }

    /// The team's shared slot of the attribute (a value received, sent or
    /// published, or a team variable), typed as the checker resolved it.
    fn shared_slot(&mut self, attr: &ast::Attr) -> SlotId {
        let key = self.attr_key(attr);
        if let Some(&i) = self.slot_index.get(&(key.clone(), false)) {
            return i;
        }
        let kind = self.attr_kind(attr);
        self.slot(&key, SlotSource::Shared, kind)
    }

    /// How the values of an attribute are stored: the catalog's type of the
    /// value the checker resolved it to (of the owner team's robots; `USER`'s
    /// from the catalog's operator), or a team variable. Anything else is an
    /// internal error: the build is refused, never typed by guess.
    fn attr_kind(&mut self, attr: &ast::Attr) -> ValueKind {
        // This team's symbol first, then any value or variable recorded there.
        let symbols =
            crate::sema::lookup::with_span(&self.input.analysis.mission, attr.last().span);
        let candidates: Vec<Symbol> = (self.symbol_of(attr).into_iter())
            .chain(symbols.iter().map(|o| o.symbol.clone()))
            .collect();
        let catalog = self.input.catalog;
        let mission = &self.input.analysis.mission;
        let declared = candidates.iter().find_map(|symbol| match symbol {
            Symbol::TeamVariable { .. } => Some(Some(ValueKind::Variable)),
            Symbol::Value { owner, name } => {
                let of_team = owner.and_then(|team| {
                    mission.team(team).robots.iter().find_map(|r| {
                        let ty = catalog.get(r.robot_type?);
                        ty.value(name).map(|v| ValueKind::declared(&v.ty))
                    })
                });
                // `USER.X`: the catalog's operator, as the checker resolves it.
                let of_user = || {
                    let user = catalog.user().filter(|_| owner.is_none())?;
                    user.value(name).map(|v| ValueKind::declared(&v.ty))
                };
                Some(of_team.or_else(of_user))
            }
            _ => None,
        });
        match declared {
            Some(Some(kind)) => kind,
            _ => {
                let what = format!(
                    "`{}` is read as a value, but no catalog type declares it",
                    attr.dotted()
                );
                self.internal_error(attr.span, &what);
                ValueKind::Variable
            }
        }
    }

    /// The catalog type of the `index`th parameter of `service` (a strategy
    /// variable set from the call's argument at that position).
    fn parameter_kind(&mut self, service: &str, index: usize, call: Span) -> ValueKind {
        let declared = self
            .robot_type
            .service(service)
            .and_then(|def| def.params.get(index))
            .map(|p| ValueKind::declared(&p.ty));
        declared.unwrap_or_else(|| {
            let what = format!(
                "a strategy variable of `{service}` takes argument {} of the call, which the catalog does not declare",
                index + 1
            );
            self.internal_error(call, &what);
            ValueKind::Variable
        })
    }

    /// The robot's own value `name`, read from the task that implements it
    /// (the strategy's `ValueInfo` first, else the catalog).
    fn sensor_slot(&mut self, name: &str, span: Span) -> SlotId {
        let task = self.value_task(name);
        self.sensor_slot_with_task(name, &task, span)
    }

    fn sensor_slot_with_task(&mut self, value: &str, task: &str, span: Span) -> SlotId {
        let key = format!("{}.{value}", self.team.name);
        if let Some(&i) = self.slot_index.get(&(key.clone(), true)) {
            return i;
        }
        let kind = match self.robot_type.value(value) {
            Some(v) => ValueKind::declared(&v.ty),
            None => {
                let what = format!(
                    "robot type `{}` has no value `{value}` for its sensor task `{task}`",
                    self.robot_type.name
                );
                self.internal_error(span, &what);
                ValueKind::Variable
            }
        };
        self.sensors
            .entry(task.to_string())
            .or_default()
            .insert(value.to_string());
        self.slot(
            &key,
            SlotSource::Sensor {
                task: task.to_string(),
                port: value.to_string(),
            },
            kind,
        )
    }

    fn value_task(&self, name: &str) -> String {
        for strategy in self.input.strategies {
            if strategy
                .team
                .as_ref()
                .is_none_or(|t| t.name != self.team.name)
            {
                continue;
            }
            for value in &strategy.values {
                if value.name.as_ref().is_none_or(|n| n.name != name) {
                    continue;
                }
                let task = value
                    .tasks
                    .iter()
                    .flat_map(|t| &t.parameters)
                    .find_map(|p| p.src_task.as_ref());
                if let Some(task) = task {
                    return task.name.clone();
                }
            }
        }
        match self.robot_type.value(name).map(|v| &v.implementation) {
            Some(implementation) => implementing_task(implementation, &name.to_lowercase()),
            None => name.to_lowercase(),
        }
    }

    fn outgoing(&mut self, to_team: &str, publish: bool, key: &str) -> OutgoingId {
        if let Some(i) = self
            .machine
            .outgoing
            .iter()
            .position(|m| m.to_team == to_team && m.publish == publish && m.key == key)
        {
            return OutgoingId::new(i);
        }
        let port = format!(
            "{}_{}_{}",
            if publish { "pub" } else { "to" },
            to_team,
            key.replace('.', "_")
        );
        self.machine.outgoing.push(OutgoingMessage {
            to_team: to_team.to_string(),
            publish,
            key: key.to_string(),
            port,
        });
        OutgoingId::new(self.machine.outgoing.len() - 1)
    }

    /// Who a `throw E broadcast` tells ([`Broadcast`]), of the group the
    /// checker recorded; in arms of counted groups, each other robot that
    /// may share this one's arm. `None` when the checker recorded no
    /// broadcast there.
    fn broadcast_messages(&mut self, event: &ast::Ident) -> Option<Broadcast> {
        let team = self.team;
        let receivers = team.broadcast_at(event.span)?.receivers.clone();
        if event.name.len() > MAX_EVENT_NAME_BYTES {
            self.unsupported(
                event.span,
                &format!(
                    "a broadcast event whose name is longer than {MAX_EVENT_NAME_BYTES} bytes (the runtime's text values carry no more)"
                ),
            );
        }
        let key = event_key(&team.name);
        let within = self.counted_within.clone();
        if within.is_empty() && receivers.len() == team.robots.len() && receivers.len() > 1 {
            let messages = vec![self.outgoing(&team.name, false, &key)];
            return Some(Broadcast {
                messages,
                to: Vec::new(),
                within,
            });
        }
        let others = receivers.iter().filter(|r| r.index() != self.robot_index);
        let (names, to): (Vec<String>, Vec<PeerId>) = others
            .map(|r| {
                let name = team.robots[r.index()].name.to_string();
                (name, PeerId::new(self.first_peer() + r.index()))
            })
            .unzip();
        let messages = (names.iter())
            .map(|name| self.outgoing(name, false, &key))
            .collect();
        let to = if within.is_empty() { Vec::new() } else { to };
        Some(Broadcast {
            messages,
            to,
            within,
        })
    }

    /// The events another robot may tell this one (`events_heard`).
    fn events_heard(&self) -> Vec<String> {
        let mine = |b: &&crate::sema::Broadcast| {
            b.receivers.len() > 1 && b.receivers.iter().any(|r| r.index() == self.robot_index)
        };
        let mut events: Vec<String> = (self.team.broadcasts.iter().filter(mine))
            .map(|b| b.event.to_string())
            .collect();
        events.sort_unstable();
        events.dedup();
        events
    }

    fn incoming(&mut self, from_team: &str, attr: &ast::Attr) -> IncomingId {
        let key = self.attr_key(attr);
        if let Some(i) = self
            .machine
            .incoming
            .iter()
            .position(|m| m.from_team == from_team && *m.key == key)
        {
            return IncomingId::new(i);
        }
        let slot = self.shared_slot(attr);
        let port = format!("from_{}_{}", from_team, key.replace('.', "_"));
        self.machine.incoming.push(IncomingMessage {
            from_team: from_team.to_string(),
            key: key.to_string(),
            slot,
            port,
        });
        IncomingId::new(self.machine.incoming.len() - 1)
    }
}

/// Records what `def`, a service the control task calls, gives back
/// ([`ControlMachine::gives_back`]), once per service.
fn note_gives_back(gives_back: &mut Vec<ServiceResults>, def: &crate::catalog::ServiceDef) {
    if gives_back.iter().any(|g| g.service == def.name) {
        return;
    }
    gives_back.push(ServiceResults {
        service: def.name.clone(),
        results: def
            .results
            .iter()
            .map(|r| (r.name.clone(), ValueKind::declared(&r.ty)))
            .collect(),
    });
}

/// Each publication of a value the robot subscribes to also goes to its own
/// multicast group (known only once every statement is refined).
fn link_own_publications(machine: &mut ControlMachine) {
    let ControlMachine {
        services,
        outgoing,
        subscribed,
        ..
    } = machine;
    for state in services.iter_mut().flat_map(|s| s.states.iter_mut()) {
        if let StateKind::Send { items } = &mut state.kind {
            for item in items {
                let message = &outgoing[item.message.index()];
                if message.publish {
                    let group = subscribed.iter().position(|g| *g == message.key);
                    item.own_group = group.map(SubscriptionId::new);
                }
            }
        }
    }
}

/// A catalog task may both provide values and serve services (`Ev3_Robot`'s
/// `search` provides `SEARCHEDCOLOR` and runs `search()`). The generated
/// program runs the two roles as two tasks (a periodic sensor task and a
/// called service task), so the sensor role is named `<task>_values` (with
/// more `_` until the name is free) everywhere the machine refers to it.
fn separate_sensor_tasks(
    machine: &mut ControlMachine,
    sensors: &mut BTreeMap<String, BTreeSet<String>>,
    services: &BTreeMap<String, BTreeSet<String>>,
) {
    let clashing: Vec<String> = sensors
        .keys()
        .filter(|t| services.contains_key(*t))
        .cloned()
        .collect();
    for task in clashing {
        let mut name = format!("{task}_values");
        while sensors.contains_key(&name) || services.contains_key(&name) {
            name.push('_');
        }
        let values = sensors.remove(&task).unwrap_or_default();
        sensors.insert(name.clone(), values);
        for slot in &mut machine.slots {
            if let SlotSource::Sensor { task: t, .. } = &mut slot.source
                && *t == task
            {
                *t = name.clone();
            }
        }
        for policy in &mut machine.battery {
            for (t, _) in &mut policy.sensors {
                if *t == task {
                    *t = name.clone();
                }
            }
        }
    }
}

/// The task implementing a service or value: the catalog's task, a task
/// named after a task-graph file, or one named after the service.
pub(super) fn implementing_task(implementation: &Implementation, fallback: &str) -> String {
    match implementation {
        Implementation::Task(t) => t.clone(),
        Implementation::Graph(g) => {
            let file = g.rsplit(['/', '\\']).next().unwrap_or(g);
            file.split('.').next().unwrap_or(file).to_string()
        }
        Implementation::Unspecified => fallback.to_string(),
    }
}

/// What a robot runs of a group statement.
enum ArmChoice<'s> {
    /// Decided by its type and capabilities: an arm, `others`, or nothing.
    Static(Option<&'s ast::Block>),
    /// A `leader` arm it can run: decided at run time by election among
    /// `candidates` (indices into the team's robots).
    Leader {
        body: &'s ast::Block,
        others: Option<&'s ast::Block>,
        candidates: Vec<usize>,
    },
}

/// A new mark of the service machine whose `marks` (a count) it raises.
fn next_mark(marks: &mut usize) -> MarkId {
    *marks += 1;
    MarkId::new(*marks - 1)
}

/// A state pushed by [`Builder::push_forward`] whose target is the state
/// after a block still being refined: [`land`] sets it once that block is.
#[must_use = "a forward state must land, or it jumps to itself"]
struct Forward(StateId);

/// The incoming messages the `Receive` states of `states` take, each once,
/// in index order (a leader's block: [`StateKind::LeaderBranch`]).
fn received_in(states: &[State]) -> Vec<IncomingId> {
    let mut messages: Vec<IncomingId> = states
        .iter()
        .filter_map(|s| match &s.kind {
            StateKind::Receive { messages, .. } => Some(messages.iter().copied()),
            _ => None,
        })
        .flatten()
        .collect();
    messages.sort_unstable();
    messages.dedup();
    messages
}

/// Sets the target of `forward` to the next state to be pushed.
fn land(states: &mut [State], forward: Forward) {
    let target = StateId::new(states.len());
    match &mut states[forward.0.index()].kind {
        StateKind::Branch { else_to: to, .. }
        | StateKind::Jump { to }
        | StateKind::LoopHead { exit_to: to, .. }
        | StateKind::LeaderBranch { others_at: to, .. } => *to = target,
        // `push_forward` is only given the four kinds above.
        other => unreachable!("a forward state cannot be {other:?}"),
    }
}

fn period_ms(period: &ast::Period) -> Option<i64> {
    period.millis().map(|m| m.round() as i64)
}

fn collect_attrs<'e>(expr: &'e ast::Expr, out: &mut Vec<&'e ast::Attr>) {
    match &expr.kind {
        ExprKind::Or(a, b) | ExprKind::And(a, b) | ExprKind::Compare(a, _, b) => {
            collect_attrs(a, out);
            collect_attrs(b, out);
        }
        ExprKind::Not(a) => collect_attrs(a, out),
        ExprKind::Attr(a) => out.push(a),
        _ => {}
    }
}

/// A literal as written (see [`Operand::Literal`]); a period is its
/// milliseconds.
fn literal_value(kind: &ExprKind) -> Value {
    match kind {
        ExprKind::Str(s) => Value::text(s),
        ExprKind::Number(s) => Value::number(s),
        ExprKind::Bool(b) => Value::Bool(*b),
        ExprKind::Period(p) => match p.millis() {
            Some(ms) if ms.fract() == 0.0 && ms.abs() < 9e15 => Value::Int(ms as i64),
            Some(ms) => Value::Real(ms),
            None => Value::text(""),
        },
        ExprKind::Attr(a) => Value::Word(a.dotted().into()),
        _ => Value::text(""),
    }
}

/// Converts a mission expression, resolving attributes with `resolve`.
/// How the comparison `expr` compares (see [`Compared`]).
type CompareAs<'c> = dyn FnMut(&ast::Expr) -> Compared + 'c;

fn convert(
    expr: &ast::Expr,
    resolve: &mut dyn FnMut(&ast::Attr) -> Operand,
    compare_as: &mut CompareAs<'_>,
) -> Expr {
    let operand = |e: &ast::Expr, resolve: &mut dyn FnMut(&ast::Attr) -> Operand| match &e.kind {
        ExprKind::Attr(a) => resolve(a),
        other => Operand::Literal(literal_value(other)),
    };
    match &expr.kind {
        ExprKind::Or(a, b) => Expr::Or(
            Box::new(convert(a, resolve, compare_as)),
            Box::new(convert(b, resolve, compare_as)),
        ),
        ExprKind::And(a, b) => Expr::And(
            Box::new(convert(a, resolve, compare_as)),
            Box::new(convert(b, resolve, compare_as)),
        ),
        ExprKind::Not(a) => Expr::Not(Box::new(convert(a, resolve, compare_as))),
        ExprKind::Compare(a, op, b) => {
            let is_boolean = |e: &ast::Expr| {
                matches!(
                    e.kind,
                    ExprKind::Or(..)
                        | ExprKind::And(..)
                        | ExprKind::Not(..)
                        | ExprKind::Compare(..)
                )
            };
            if is_boolean(a) || is_boolean(b) {
                // `(x < 3) == true`: compare truth values.
                let l = convert(a, resolve, compare_as);
                let r = convert(b, resolve, compare_as);
                let same = Expr::Or(
                    Box::new(Expr::And(Box::new(l.clone()), Box::new(r.clone()))),
                    Box::new(Expr::And(
                        Box::new(Expr::Not(Box::new(l))),
                        Box::new(Expr::Not(Box::new(r))),
                    )),
                );
                return match op {
                    ast::CmpOp::Eq => same,
                    _ => Expr::Not(Box::new(same)),
                };
            }
            let compared = compare_as(expr);
            Expr::Compare(operand(a, resolve), *op, operand(b, resolve), compared)
        }
        ExprKind::Bool(b) => Expr::Bool(*b),
        ExprKind::Attr(a) => Expr::Truthy(resolve(a)),
        ExprKind::Str(_) | ExprKind::Number(_) | ExprKind::Period(_) => {
            Expr::Truthy(operand(expr, resolve))
        }
        ExprKind::Error => Expr::Bool(false),
    }
}
