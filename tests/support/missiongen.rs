//! Random valid missions over the grammar and a robot catalog (the built-in
//! one in the tests), seeded and deterministic: the same seed gives the same
//! text. Every mission it writes is meant to be accepted by `semo check`
//! (warnings allowed); the property tests hold it to that.
//!
//! What a mission may hold: one to three teams of mixed robot types (`name[N]`
//! included); plans, composite services with every `repeat` form, modes with
//! `set` (and `OFF`, timeouts), a main block catching the team's events;
//! functions; statements `if`/`else`, `loop`, `throw`, built-in calls with
//! arguments of the right types, `[[ group ... others ]]` with `instance of`
//! and `capable of` one or more, `[[ leader ... others ]]`, and all four
//! communication forms over team variables, the team's values and `USER`.
//!
//! Validity by construction: each statement is generated for the robots that
//! run it, narrowed inside group arms exactly as the checker narrows them, so
//! it calls only services and reads only values that all of them have.
//!
//! [`odd_mission`] writes the same missions with some statements whose names
//! have odd shapes (three or four parts, unknown teams, `USER` values the
//! console lacks, catalog values where words may stand, dotted keys sent and
//! received, operators and peers mixed): `semo check` may refuse those, and
//! what it accepts must build.
//!
//! Reusable by other tests (the simulator's differential tests): depends only
//! on `semo::catalog`.

use semo::catalog::{Catalog, RobotType, ValueType};
use std::fmt::Write;

/// SplitMix64: tiny, seedable, and the same on every platform, which is all a
/// generator of test inputs needs (no dependency for it).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x005E_ED0F_5E40)
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// True with probability `percent` / 100.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The shape of one team, decided before any statement is written.
struct TeamPlan {
    name: String,
    /// Robot type of each robot (after `name[N]` expansion).
    robots: Vec<usize>,
    plans: Vec<(String, Vec<String>)>,
    modes: Vec<String>,
    events: Vec<String>,
    /// Team variables this team sends or publishes (`T.V0`).
    variables: Vec<String>,
}

/// Whether a robot type meets a group condition.
type Meets = Box<dyn Fn(&RobotType) -> bool>;

const TEAM_NAMES: [&str; 3] = ["Alpha", "Bravo", "Charlie"];
const PLAN_NAMES: [&str; 2] = ["Act", "Talk"];

struct Generator<'c> {
    rng: Rng,
    /// Whether some statements get odd name shapes ([`odd_mission`]).
    odd: bool,
    types: Vec<&'c RobotType>,
    teams: Vec<TeamPlan>,
    functions: Vec<String>,
    out: String,
}

/// A random mission that `semo check` accepts against `catalog` (the
/// built-in catalog: every robot type there is used as it is described).
pub fn mission(seed: u64, catalog: &Catalog) -> String {
    generate(seed, catalog, false)
}

/// A random mission like [`mission`]'s, some of whose statements name
/// things in odd shapes: `semo check` may refuse it.
pub fn odd_mission(seed: u64, catalog: &Catalog) -> String {
    generate(seed, catalog, true)
}

fn generate(seed: u64, catalog: &Catalog, odd: bool) -> String {
    let types: Vec<&RobotType> = catalog.types().map(|(_, t)| t).collect();
    let mut g = Generator {
        rng: Rng::new(seed),
        odd,
        types,
        teams: Vec::new(),
        functions: Vec::new(),
        out: String::new(),
    };
    g.plan_teams();
    g.write(seed);
    g.out
}

impl Generator<'_> {
    fn plan_teams(&mut self) {
        let team_count = 1 + self.rng.below(3);
        for name in TEAM_NAMES.iter().take(team_count) {
            let mut robots = Vec::new();
            for _ in 0..1 + self.rng.below(2) {
                let ty = self.rng.below(self.types.len());
                let count = if self.rng.chance(20) { 2 } else { 1 };
                robots.extend(std::iter::repeat_n(ty, count));
            }
            let plans = (0..1 + self.rng.below(2))
                .map(|p| {
                    let services = (0..1 + self.rng.below(2))
                        .map(|s| format!("S{p}{s}"))
                        .collect();
                    (PLAN_NAMES[p].to_string(), services)
                })
                .collect();
            let modes = (0..1 + self.rng.below(3))
                .map(|m| format!("M{m}"))
                .collect();
            let events = (0..1 + self.rng.below(2))
                .map(|e| format!("E{e}"))
                .collect();
            let variables = (0..self.rng.below(3)).map(|v| format!("V{v}")).collect();
            self.teams.push(TeamPlan {
                name: name.to_string(),
                robots,
                plans,
                modes,
                events,
                variables,
            });
        }
        if self.rng.chance(50) {
            self.functions.push("helper0".into());
        }
    }

    fn write(&mut self, seed: u64) {
        let _ = writeln!(self.out, "# Generated mission, seed {seed}.");
        self.formation();
        for f in self.functions.clone() {
            self.function(&f);
        }
        for t in 0..self.teams.len() {
            self.team(t);
        }
    }

    fn formation(&mut self) {
        self.out.push_str("{\n");
        for (t, team) in self.teams.iter().enumerate() {
            let mut decls = Vec::new();
            let mut i = 0;
            while i < team.robots.len() {
                let ty = team.robots[i];
                let same = team.robots[i..].iter().take_while(|&&r| r == ty).count();
                let name = format!("r{t}_{i}");
                // Runs of one type are written `name[N]` half of the time.
                if same > 1 && (seed_bit(t + i)) {
                    decls.push(format!("{} {name}[{same}]", self.types[ty].name));
                    i += same;
                } else {
                    decls.push(format!("{} {name}", self.types[ty].name));
                    i += 1;
                }
            }
            let _ = writeln!(self.out, "  {}: {}", team.name, decls.join(", "));
        }
        self.out.push_str("}\n\n");
    }

    /// A function: statements every robot type can run (functions are
    /// checked with the robots of every caller).
    fn function(&mut self, name: &str) {
        let all: Vec<usize> = (0..self.types.len()).collect();
        let _ = writeln!(self.out, "def {name} {{");
        let mut body = String::new();
        let count = 1 + self.rng.below(2);
        for _ in 0..count {
            self.call(&all, &mut body, 1);
        }
        if self.rng.chance(50) {
            let cond = self.condition(&all, None);
            let _ = writeln!(body, "  if({cond})");
            self.call(&all, &mut body, 2);
        }
        self.out.push_str(&body);
        self.out.push_str("}\n\n");
    }

    fn team(&mut self, t: usize) {
        let team_name = self.teams[t].name.clone();
        let plans = self.teams[t].plans.clone();
        let robots: Vec<usize> = (0..self.teams[t].robots.len()).collect();
        for (plan, services) in &plans {
            for service in services {
                let mut body = String::new();
                let count = 1 + self.rng.below(4);
                for _ in 0..count {
                    self.statement(t, &robots, &mut body, 1, 0);
                }
                let repeat = self.repeat(t, &robots);
                let _ = write!(
                    self.out,
                    "{team_name}.{plan}.{service}{{\n{body}}}{repeat}\n\n"
                );
            }
        }
        let modes = self.teams[t].modes.clone();
        for mode in &modes {
            let mut sets = Vec::new();
            for (plan, services) in &plans {
                let target = if self.rng.chance(15) {
                    "OFF".to_string()
                } else {
                    self.rng.pick(services).clone()
                };
                let timeout = if target != "OFF" && self.rng.chance(20) {
                    ", timeout = 3 SEC"
                } else {
                    ""
                };
                sets.push(format!("set({plan}, {target}{timeout})"));
            }
            let _ = writeln!(self.out, "{team_name}.{mode}{{ {} }}", sets.join("; "));
        }
        let events = self.teams[t].events.clone();
        let _ = writeln!(self.out, "\n{team_name}.main{{");
        for mode in &modes {
            let mut catches = Vec::new();
            for event in &events {
                if self.rng.chance(60) {
                    let to = self.rng.pick(&modes).clone();
                    catches.push(format!("    catch ({event}): mode = {to}"));
                }
            }
            if !catches.is_empty() {
                let _ = writeln!(self.out, "  case ({mode}):\n{}", catches.join("\n"));
            }
        }
        let _ = writeln!(self.out, "  default: mode = {}\n}}\n", modes[0]);
    }

    fn repeat(&mut self, t: usize, robots: &[usize]) -> String {
        let types = self.types_of(t, robots);
        match self.rng.below(5) {
            0 => String::new(),
            1 => " repeat()".into(),
            2 => format!(" repeat({} MSEC)", 100 * (1 + self.rng.below(10))),
            3 => format!(" repeat({})", self.condition(&types, Some(t))),
            _ => format!(" repeat(1 SEC, {})", self.condition(&types, Some(t))),
        }
    }

    /// The robot types of some robots of team `t`.
    fn types_of(&self, t: usize, robots: &[usize]) -> Vec<usize> {
        let mut types: Vec<usize> = robots.iter().map(|&r| self.teams[t].robots[r]).collect();
        types.sort_unstable();
        types.dedup();
        types
    }

    /// One statement run by `robots` (indices into team `t`'s robots).
    fn statement(
        &mut self,
        t: usize,
        robots: &[usize],
        out: &mut String,
        indent: usize,
        depth: usize,
    ) {
        let types = self.types_of(t, robots);
        let pad = "  ".repeat(indent);
        let nested = depth < 2;
        // Only odd missions draw this number: the others stay as they were.
        if self.odd && self.rng.chance(12) {
            self.odd_statement(t, &types, out, indent);
            return;
        }
        match self.rng.below(if nested { 10 } else { 6 }) {
            0 | 1 => self.call(&types, out, indent),
            2 => {
                let event = self.rng.pick(&self.teams[t].events).clone();
                let _ = writeln!(out, "{pad}throw {event}");
            }
            3 | 4 => self.communication(t, &types, out, indent),
            5 if !self.functions.is_empty() => {
                let f = self.rng.pick(&self.functions).clone();
                let _ = writeln!(out, "{pad}{f}()");
            }
            5 => self.call(&types, out, indent),
            6 => {
                let cond = self.condition(&types, Some(t));
                let _ = writeln!(out, "{pad}if({cond}){{");
                self.statement(t, robots, out, indent + 1, depth + 1);
                if self.rng.chance(50) {
                    let _ = writeln!(out, "{pad}}} else {{");
                    self.statement(t, robots, out, indent + 1, depth + 1);
                }
                let _ = writeln!(out, "{pad}}}");
            }
            7 => {
                let head = match self.rng.below(3) {
                    0 => format!("{} MSEC", 100 * (1 + self.rng.below(5))),
                    1 => self.condition(&types, Some(t)),
                    _ => format!("500 MSEC, {}", self.condition(&types, Some(t))),
                };
                let _ = writeln!(out, "{pad}loop({head}){{");
                self.statement(t, robots, out, indent + 1, depth + 1);
                let _ = writeln!(out, "{pad}}}");
            }
            _ => self.group(t, robots, out, indent, depth),
        }
    }

    /// `[[ group ... others ]]` or `[[ leader ... others ]]`, each arm's body
    /// written for the robots the checker gives it.
    fn group(&mut self, t: usize, robots: &[usize], out: &mut String, indent: usize, depth: usize) {
        let pad = "  ".repeat(indent);
        let leader = self.rng.chance(30);
        let arm_count = if leader { 1 } else { 1 + self.rng.below(2) };
        let mut taken: Vec<usize> = Vec::new();
        let mut arms = String::new();
        for _ in 0..arm_count {
            // A condition some robot running the statement meets.
            let r = *self.rng.pick(robots);
            let ty = self.types[self.teams[t].robots[r]];
            let instance = ty.capabilities.is_empty() || self.rng.chance(50);
            let (condition, meets): (String, Meets) = if instance {
                let mut names = vec![ty.name.clone()];
                if self.rng.chance(30) {
                    let other = self.types[self.rng.below(self.types.len())].name.clone();
                    if !names.contains(&other) {
                        names.push(other);
                    }
                }
                let cond = format!("instance of {}", names.join(", "));
                (cond, Box::new(move |r: &RobotType| names.contains(&r.name)))
            } else {
                let count = 1 + self.rng.below(ty.capabilities.len().min(2));
                let mut caps: Vec<String> = Vec::new();
                while caps.len() < count {
                    let c = self.rng.pick(&ty.capabilities).clone();
                    if !caps.contains(&c) {
                        caps.push(c);
                    }
                }
                let cond = format!("capable of {}", caps.join(", "));
                (
                    cond,
                    Box::new(move |r: &RobotType| caps.iter().all(|c| r.has_capability(c))),
                )
            };
            let members: Vec<usize> = robots
                .iter()
                .copied()
                .filter(|&r| meets(self.types[self.teams[t].robots[r]]))
                .collect();
            let fresh: Vec<usize> = members
                .iter()
                .copied()
                .filter(|r| !taken.contains(r))
                .collect();
            if fresh.is_empty() {
                continue; // every robot meeting it is in an earlier arm
            }
            let (keyword, runners) = if leader {
                ("leader", members.clone())
            } else {
                ("group", fresh)
            };
            let _ = writeln!(arms, "{pad}  {keyword}({condition}){{");
            let count = 1 + self.rng.below(2);
            for _ in 0..count {
                self.statement(t, &runners, &mut arms, indent + 2, depth + 1);
            }
            let _ = writeln!(arms, "{pad}  }}");
            if !leader || members.len() == 1 {
                taken.extend(members);
            }
        }
        if arms.is_empty() {
            let types = self.types_of(t, robots);
            self.call(&types, out, indent);
            return;
        }
        let rest: Vec<usize> = robots
            .iter()
            .copied()
            .filter(|r| !taken.contains(r))
            .collect();
        if !rest.is_empty() && self.rng.chance(70) {
            let _ = writeln!(arms, "{pad}  others{{");
            self.statement(t, &rest, &mut arms, indent + 2, depth + 1);
            let _ = writeln!(arms, "{pad}  }}");
        }
        let _ = write!(out, "{pad}[[\n{arms}{pad}]]\n");
    }

    /// A built-in call every one of `types` provides, with fitting arguments.
    fn call(&mut self, types: &[usize], out: &mut String, indent: usize) {
        let pad = "  ".repeat(indent);
        let first = self.types[types[0]];
        let common: Vec<&semo::catalog::ServiceDef> = first
            .services
            .iter()
            .filter(|s| {
                types
                    .iter()
                    .all(|&t| self.types[t].service(&s.name).is_some())
            })
            .collect();
        let service = (*self.rng.pick(&common)).clone();
        // Every robot's definition must accept the arguments: use the
        // parameters all of them declare alike.
        let mut args = Vec::new();
        for (i, param) in service.params.iter().enumerate() {
            let everywhere = types.iter().all(|&t| {
                self.types[t]
                    .service(&service.name)
                    .and_then(|s| s.params.get(i))
                    .is_some_and(|p| p.ty == param.ty)
            });
            if param.optional && (!everywhere || self.rng.chance(40)) {
                break;
            }
            args.push(match &param.ty {
                ValueType::Location => format!("\"{},{}\"", self.rng.below(9), self.rng.below(9)),
                ValueType::String => match self.rng.below(3) {
                    0 => "USER.RC_CMD".to_string(),
                    1 => "colored_paper".to_string(),
                    _ => "\"target\"".to_string(),
                },
                ValueType::Int => self.rng.below(100).to_string(),
                ValueType::Float => "1.5".to_string(),
                ValueType::Bool => "true".to_string(),
                ValueType::Enum(domain) => self.rng.pick(domain).clone(),
                ValueType::Image => "\"picture\"".to_string(),
            });
        }
        let timeout = if self.rng.chance(15) {
            ", timeout = 2 SEC"
        } else {
            ""
        };
        let _ = writeln!(out, "{pad}{}({}){timeout}", service.name, args.join(", "));
    }

    /// A condition over values every one of `types` has, team variables of
    /// `team`'s mission, and numbers.
    fn condition(&mut self, types: &[usize], team: Option<usize>) -> String {
        let first = self.types[types[0]];
        let values: Vec<(String, ValueType)> = first
            .values
            .iter()
            .filter(|v| v.ty != ValueType::Image)
            .filter(|v| {
                types
                    .iter()
                    .all(|&t| self.types[t].value(&v.name).is_some_and(|w| w.ty == v.ty))
            })
            .map(|v| (v.name.clone(), v.ty.clone()))
            .collect();
        let variables: Vec<String> = match team {
            Some(_) => self
                .teams
                .iter()
                .flat_map(|t| t.variables.iter().map(move |v| format!("{}.{v}", t.name)))
                .collect(),
            None => Vec::new(),
        };
        let simple = |g: &mut Generator<'_>| -> String {
            if !variables.is_empty() && g.rng.chance(30) {
                let v = g.rng.pick(&variables).clone();
                let op = g.rng.pick(&["<", ">=", "==", "!="]).to_string();
                return format!("{v} {op} {}", g.rng.below(10));
            }
            if values.is_empty() {
                return "true".into();
            }
            let (name, ty) = g.rng.pick(&values).clone();
            match ty {
                ValueType::Int | ValueType::Float => {
                    let op = g.rng.pick(&["<", "<=", ">", ">=", "==", "!="]).to_string();
                    format!("{name} {op} {}", 10 * g.rng.below(10))
                }
                ValueType::Bool => format!("{name} == true"),
                ValueType::Location => {
                    format!("{name} != \"{},{}\"", g.rng.below(9), g.rng.below(9))
                }
                ValueType::Enum(domain) => format!("{name} == {}", g.rng.pick(&domain)),
                _ => format!("{name} == \"R\""),
            }
        };
        match self.rng.below(5) {
            0 => format!("{} and {}", simple(self), simple(self)),
            1 => format!("{} or not {}", simple(self), simple(self)),
            _ => simple(self),
        }
    }

    /// send / receive / publish / subscribe over team variables, the team's
    /// common values and the operator.
    fn communication(&mut self, t: usize, types: &[usize], out: &mut String, indent: usize) {
        let pad = "  ".repeat(indent);
        let me = self.teams[t].name.clone();
        let other = self.rng.below(self.teams.len());
        let other_name = self.teams[other].name.clone();
        let own_vars = self.teams[t].variables.clone();
        let their_vars = self.teams[other].variables.clone();
        let first = self.types[types[0]];
        let common_values: Vec<String> = first
            .values
            .iter()
            .filter(|v| {
                types
                    .iter()
                    .all(|&ty| self.types[ty].value(&v.name).is_some())
            })
            .map(|v| v.name.clone())
            .collect();
        match self.rng.below(6) {
            0 if !own_vars.is_empty() => {
                let v = self.rng.pick(&own_vars).clone();
                let _ = writeln!(
                    out,
                    "{pad}send({other_name}, {me}.{v} = {})",
                    self.rng.below(10)
                );
            }
            1 if !own_vars.is_empty() => {
                let v = self.rng.pick(&own_vars).clone();
                let _ = writeln!(out, "{pad}publish({me}, {me}.{v} = {})", self.rng.below(10));
            }
            2 if !their_vars.is_empty() => {
                let v = self.rng.pick(&their_vars).clone();
                let timeout = if self.rng.chance(50) {
                    ", timeout = 1 SEC"
                } else {
                    ""
                };
                let _ = writeln!(out, "{pad}receive({other_name}, {other_name}.{v}){timeout}");
            }
            3 if !their_vars.is_empty() => {
                let v = self.rng.pick(&their_vars).clone();
                let _ = writeln!(out, "{pad}subscribe({other_name}, {other_name}.{v})");
            }
            4 if !common_values.is_empty() => {
                let v = self.rng.pick(&common_values).clone();
                let to = if self.rng.chance(50) {
                    "USER".to_string()
                } else {
                    other_name
                };
                let _ = writeln!(out, "{pad}send({to}, {me}.{v})");
            }
            _ => {
                let _ = writeln!(out, "{pad}receive(USER, USER.RC_CMD), timeout = 1 SEC");
            }
        }
    }
}

impl Generator<'_> {
    /// A statement naming things in an odd shape, for robots of `types` in
    /// team `t`: a communication, a condition or a call argument.
    fn odd_statement(&mut self, t: usize, types: &[usize], out: &mut String, indent: usize) {
        let pad = "  ".repeat(indent);
        let verb = *self
            .rng
            .pick(&["receive", "subscribe", "send", "publish", "if", "call"]);
        let line = match verb {
            "receive" | "subscribe" | "send" | "publish" => {
                let peer = self.odd_peer(t);
                let items = (0..1 + self.rng.below(2))
                    .map(|_| {
                        let name = self.odd_name(t, types);
                        if matches!(verb, "send" | "publish") {
                            match self.rng.below(3) {
                                0 => name,
                                _ => format!("{name} = {}", self.odd_operand(t, types)),
                            }
                        } else {
                            name
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", ");
                let timeout = if verb == "receive" && self.rng.chance(30) {
                    ", timeout = 1 SEC"
                } else {
                    ""
                };
                format!("{verb}({peer}, {items}){timeout}")
            }
            "if" => {
                let event = self.rng.pick(&self.teams[t].events).clone();
                let op = *self.rng.pick(&["==", "!=", "==", "!=", "<"]);
                let (a, b) = (self.odd_name(t, types), self.odd_operand(t, types));
                format!("if({a} {op} {b}) throw {event}")
            }
            _ => {
                let first = self.types[types[0]];
                let one_param: Vec<&semo::catalog::ServiceDef> = first
                    .services
                    .iter()
                    .filter(|s| !s.params.is_empty())
                    .filter(|s| {
                        types
                            .iter()
                            .all(|&ty| self.types[ty].service(&s.name).is_some())
                    })
                    .collect();
                if one_param.is_empty() {
                    let event = self.rng.pick(&self.teams[t].events).clone();
                    format!("throw {event}")
                } else {
                    let service = self.rng.pick(&one_param).name.clone();
                    format!("{service}({})", self.odd_name(t, types))
                }
            }
        };
        let _ = writeln!(out, "{pad}{line}");
    }

    /// Whom a communication names: a team of the mission, `USER`, or a
    /// misspelt team.
    fn odd_peer(&mut self, t: usize) -> String {
        match self.rng.below(10) {
            0 | 1 => "USER".into(),
            2 | 3 => self.teams[t].name.clone(),
            4 => "Nobody".into(),
            _ => self.teams[self.rng.below(self.teams.len())].name.clone(),
        }
    }

    /// A name in one of the shapes a user may write, right or wrong.
    fn odd_name(&mut self, t: usize, types: &[usize]) -> String {
        let me = self.teams[t].name.clone();
        let other = self.teams[self.rng.below(self.teams.len())].name.clone();
        let value = self.some_value(types);
        let variable = self
            .teams
            .iter()
            .flat_map(|team| {
                team.variables
                    .iter()
                    .map(move |v| (team.name.clone(), v.clone()))
            })
            .collect::<Vec<_>>();
        let variable = match variable.is_empty() {
            true => (me.clone(), "V9".to_string()),
            false => self.rng.pick(&variable).clone(),
        };
        match self.rng.below(14) {
            0 => "USER.RC.CMD".into(),
            1 => "USER.RC_CMD".into(),
            2 => "USER.NOTHING".into(),
            3 => format!("{me}.{value}.X"),
            4 => format!("{other}.{}.{}", variable.0, variable.1),
            5 => format!("{}.{}.part", variable.0, variable.1),
            6 => format!("{me}.A.B.C"),
            7 => format!("Nobody.{value}"),
            8 => value,
            9 => format!("{other}.{value}"),
            10 => format!("{}.{}", variable.0, variable.1),
            11 => "WORD".into(),
            12 => format!("{me}.{}", self.some_value(types)),
            _ => format!("{other}.V9"),
        }
    }

    /// An operand: an odd name, a number, a string or a truth value.
    fn odd_operand(&mut self, t: usize, types: &[usize]) -> String {
        match self.rng.below(6) {
            0 => self.rng.below(100).to_string(),
            1 => "\"text\"".into(),
            2 => "true".into(),
            _ => self.odd_name(t, types),
        }
    }

    /// A value some of `types` have (`COLOR` when none has any).
    fn some_value(&mut self, types: &[usize]) -> String {
        let ty = self.types[*self.rng.pick(types)];
        match ty.values.is_empty() {
            true => "COLOR".into(),
            false => self.rng.pick(&ty.values).name.clone(),
        }
    }
}

/// A fixed pattern for choices that must not consume random numbers (the
/// formation is written after the teams are planned).
fn seed_bit(i: usize) -> bool {
    i % 2 == 0
}

/// A random scenario for a generated mission's `robots` (its robot names):
/// each robot's battery falling over the run (the `BATTERY` value the
/// missions compare), and link faults (drop, delay, partition) over
/// intervals of the run, each decided by `seed`, within `duration`.
pub fn scenario(seed: u64, robots: &[String], duration: i64, time_scale: f64) -> String {
    // Faults begin after the robots' first firings, so that some of them
    // change what a robot already does.
    let settle_ms = 100;
    let mut rng = Rng::new(seed ^ 0xFA17);
    let ms = |rng: &mut Rng, from: i64, until: i64| {
        from + (rng.next() % (until - from).max(1) as u64) as i64 / 10 * 10
    };
    let mut worlds = Vec::new();
    for robot in robots {
        let start = 20 + rng.below(81);
        let end = rng.below(start);
        let at = ms(&mut rng, settle_ms, duration);
        worlds.push(format!(
            r#""{robot}": {{"battery": [{{"at": 0, "level": {start}}}, {{"at": {at}, "level": {end}}}]}}"#
        ));
    }
    let mut faults = Vec::new();
    // A link fault begins and ends halfway between two heartbeats (every
    // 200 ms from 0, HEARTBEAT_MS), so that the robots miss a whole number of
    // them whatever the processes' scheduling; never two, since a gap of
    // three periods is exactly when a silent robot counts as failed, a
    // boundary decided by microseconds in C (random seed 14).
    let interval = |rng: &mut Rng| {
        let periods = (duration / 200 - 1).max(2) as usize;
        let first = rng.below(periods - 1);
        let missed = *rng.pick(&[1usize, 3, 4, 5]);
        let last = (first + missed).min(periods);
        let missed = if last - first == 2 { 1 } else { last - first };
        let at = |k: usize| 100 + 200 * k as i64;
        (at(first), at(first + missed))
    };
    if robots.len() >= 2 {
        let pair = |rng: &mut Rng| {
            let a = rng.below(robots.len());
            let b = (a + 1 + rng.below(robots.len() - 1)) % robots.len();
            (&robots[a], &robots[b])
        };
        if rng.chance(60) {
            let ((a, b), (from, until)) = (pair(&mut rng), interval(&mut rng));
            faults.push(format!(
                r#"{{"from": {from}, "until": {until}, "drop": ["{a}", "{b}"]}}"#
            ));
        }
        if rng.chance(60) {
            let ((a, b), (from, until)) = (pair(&mut rng), interval(&mut rng));
            let by = 50 + 50 * rng.below(6);
            faults.push(format!(
                r#"{{"from": {from}, "until": {until}, "delay": ["{a}", "{b}"], "by": {by}}}"#
            ));
        }
        if rng.chance(40) {
            let (from, until) = interval(&mut rng);
            let (mut one, mut other) = (Vec::new(), Vec::new());
            for robot in robots {
                // Some robots in no group: cut off from every group.
                match rng.below(5) {
                    0 => {}
                    1 | 2 => one.push(format!("\"{robot}\"")),
                    _ => other.push(format!("\"{robot}\"")),
                }
            }
            faults.push(format!(
                r#"{{"from": {from}, "until": {until}, "partition": [[{}], [{}]]}}"#,
                one.join(", "),
                other.join(", ")
            ));
        }
    }
    // Random loss, drawn after the faults so that those stay the seed's: on
    // the whole network, or on one link.
    let mut network = Vec::new();
    if rng.chance(40) {
        let p = 5 + 5 * rng.below(6);
        network.push(if robots.len() >= 2 && rng.chance(50) {
            let a = rng.below(robots.len());
            let b = (a + 1 + rng.below(robots.len() - 1)) % robots.len();
            format!(
                r#""links": [{{"between": ["{}", "{}"], "loss": 0.{p:02}}}]"#,
                robots[a], robots[b]
            )
        } else {
            format!(r#""loss": 0.{p:02}"#)
        });
    }
    // A network of no latency, drawn last: a message then reaches the
    // robots that run after its sender in the instant it was sent.
    if rng.chance(30) {
        network.push(r#""latency": 0"#.to_string());
    }
    let network = if network.is_empty() {
        String::new()
    } else {
        format!(r#" "network": {{{}}},"#, network.join(", "))
    };
    format!(
        "{{\"time_scale\": {time_scale}, \"duration\": {duration},{network}\n \"robots\": {{{}}},\n \"faults\": [{}]}}\n",
        worlds.join(",\n  "),
        faults.join(",\n  ")
    )
}

/// A mission whose mode `MOVE(TARGET)` sets `sets` plans and one that
/// throws every event, and is entered with `entries` different rooms, each
/// from a catch of `case (MOVE)`: its copies hold about `(sets + entries) *
/// entries` `set`s and catches (E048 past 65,536).
pub fn mode_entered_with_many_rooms(sets: usize, entries: usize) -> String {
    let mut text = String::from("{ R: iRobotCreate scout }\n");
    for p in 0..sets {
        text.push_str(&format!("R.P{p}.Go(PLACE) {{ move(PLACE) }} repeat()\n"));
    }
    // One service throws every event the main catches.
    text.push_str("R.Watch.Look {\n");
    for room in 1..entries.max(1) {
        text.push_str(&format!("  if (DISTANCE < {room}) throw e{room}\n"));
    }
    text.push_str("} repeat()\nR.MOVE(TARGET) {\n  set(Watch, Look)\n");
    for p in 0..sets {
        text.push_str(&format!("  set(P{p}, Go(TARGET))\n"));
    }
    text.push_str("}\nR.main {\n  default: mode = MOVE(room0)\n  case (MOVE):\n");
    for room in 1..entries.max(1) {
        text.push_str(&format!("    catch (e{room}): mode = MOVE(room{room})\n"));
    }
    text.push_str("}\n");
    text
}
