//! Completion in a scenario file (`*.scenario.json`): the names the
//! scenario reader accepts at the cursor's key, taken from the refined
//! programs the reader checks against (robot and team names, the sensor
//! values a robot reads, its built-in services, modes, the keys it receives,
//! `USER` commands and the constants the mission compares values with).
//!
//! The text being edited is rarely valid JSON, so the cursor's place is found
//! by a tolerant scan ([`Place`]): the keys and arrays from the root down to
//! it, whether it is in a key or a value, and the string values beside it in
//! its object (an expectation's `"robot"`, a command's `"value"`).
//!
//! Which mission a scenario belongs to is [`mission_for`]'s rule.

use crate::refine::{Expr, Operand, RobotProgram, RoleKind, SlotSource, StateKind};
use crate::span::Span;
use std::path::{Path, PathBuf};

/// The mission a scenario file belongs to: the `.mission` beside it named
/// by the scenario's file name up to its first dot (`scouting.scenario.json`
/// and `scouting.faults.scenario.json` both belong to `scouting.mission`).
pub fn mission_for(scenario: &Path) -> Option<PathBuf> {
    let name = scenario.file_name()?.to_str()?;
    let stem = name.split('.').next().filter(|s| !s.is_empty())?;
    Some(scenario.with_file_name(format!("{stem}.mission")))
}

/// Whether a file is a scenario, by its name.
pub fn is_scenario(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with(".scenario.json"))
}

/// The mission's own scenario, `<mission>.scenario.json` beside it (the
/// first the doors look for, and the editors offer).
pub fn own_scenario(mission: &Path) -> PathBuf {
    let name = mission
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let stem = name.strip_suffix(".mission").unwrap_or(name);
    mission.with_file_name(format!("{stem}.scenario.json"))
}

/// The scenarios a mission runs on when none is named (`semo simulate`,
/// `semo build` of a simulation, the editor's Generate Code and Simulate):
/// `<mission>.scenario.json` beside it when it exists, else every scenario
/// beside it that belongs to it ([`mission_for`]), sorted. One is the
/// choice; none or several, the door asks the user to name one.
pub fn scenarios_of(mission: &Path) -> std::io::Result<Vec<PathBuf>> {
    let own = own_scenario(mission);
    if own.is_file() {
        return Ok(vec![own]);
    }
    let folder = mission
        .parent()
        .filter(|f| !f.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut named: Vec<PathBuf> = std::fs::read_dir(folder)?
        .filter_map(|entry| Some(mission.with_file_name(entry.ok()?.file_name())))
        .filter(|path| is_scenario(path) && mission_for(path).as_deref() == Some(mission))
        .collect();
    named.sort();
    Ok(named)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScenarioCompletionKind {
    Robot,
    Team,
    /// A sensor value, or a key the robot receives.
    Value,
    Service,
    Mode,
    /// A `USER` command.
    Command,
    /// A constant the mission compares a value with.
    Constant,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScenarioCompletion {
    pub label: String,
    pub kind: ScenarioCompletionKind,
    /// Where it comes from (`robot of MasterTeam`, `mode`, ...).
    pub detail: String,
    /// The text replaced: the string's contents inside quotes, else the word
    /// typed at the cursor.
    pub replace: Span,
    /// Quoted when the cursor is not inside a string.
    pub insert: String,
}

/// The completions at byte `offset` of the scenario `text` in the editor's
/// vocabulary, against the refined programs of `mission` as `analysis` has
/// it (open documents as typed); none when there is no mission or it does not
/// refine (it has errors: they are shown on it).
pub fn editor_completions(
    analysis: &crate::host::Analysis,
    mission: Option<crate::diag::FileId>,
    text: &str,
    offset: usize,
) -> Vec<crate::ide::CompletionItem> {
    let programs = mission
        .and_then(|id| analysis.refined(id))
        .filter(|refined| !refined.diagnostics.iter().any(|d| d.is_error()));
    let programs = programs.as_ref().map_or(&[][..], |r| &r.programs[..]);
    completions(text, offset, programs)
        .into_iter()
        .map(ScenarioCompletion::into_item)
        .collect()
}

impl ScenarioCompletion {
    /// The item in the editor vocabulary.
    fn into_item(self) -> crate::ide::CompletionItem {
        use crate::ide::CompletionKind as E;
        let kind = match self.kind {
            ScenarioCompletionKind::Robot => E::Robot,
            ScenarioCompletionKind::Team => E::Team,
            ScenarioCompletionKind::Value => E::Value,
            ScenarioCompletionKind::Service => E::Service,
            ScenarioCompletionKind::Mode => E::Mode,
            ScenarioCompletionKind::Command => E::Event,
            ScenarioCompletionKind::Constant => E::Constant,
        };
        crate::ide::CompletionItem::new(self.label, kind, self.replace)
            .detail(self.detail)
            .insert(self.insert)
    }
}

/// The completions at byte `offset` of `text`, against the mission's programs.
pub fn completions(
    text: &str,
    offset: usize,
    programs: &[RobotProgram],
) -> Vec<ScenarioCompletion> {
    let Some(place) = Place::find(text, offset) else {
        return Vec::new();
    };
    let names = Names { programs };
    let path: Vec<&str> = place.path.iter().map(String::as_str).collect();
    let sibling = |key: &str| place.sibling(key);
    use ScenarioCompletionKind as K;
    let candidates: Vec<(String, K, String)> = match (path.as_slice(), place.in_key) {
        (["robots"], true) => names.robots(),
        (["robots", robot, "services"], true) => names.services(robot),
        (["robots", robot, "sensors", "[]", "value"], false) => names.sensor_values(robot),
        (["robots", robot, "sensors", "[]", "is"], false) => match sibling("value") {
            Some(value) => names.constants(
                Some(robot),
                |source, _| matches!(source, SlotSource::Sensor { port, .. } if port == value),
            ),
            None => Vec::new(),
        },
        (["operator", "[]", "to"], false) => {
            let mut all = names.robots();
            all.extend(names.teams());
            all
        }
        (["operator", "[]", "value"], false) => names.commands(sibling("to")),
        (["operator", "[]", "is"], false) => match sibling("value") {
            Some(value) => {
                let key = format!("USER.{value}");
                names.constants(sibling("to"), |_, k| k == key)
            }
            None => Vec::new(),
        },
        (["network", "links", "[]", "between", "[]"], false)
        | (["faults", "[]", "kill" | "restart"], false)
        | (["faults", "[]", "drop" | "delay", "[]"], false)
        | (["faults", "[]", "partition", "[]", "[]"], false)
        | (["expect", "[]", "robot" | "from"], false) => names.robots(),
        (["expect", "[]", "enters" | "never_enters"], false) => names.modes(sibling("robot")),
        (["expect", "[]", "all_end_in"], false) => names.modes(None),
        (["expect", "[]", "receives"], false) => names.received(sibling("robot")),
        // A condition of a property, however deep in `not`, `all`, `any`.
        (
            [
                "expect",
                "[]",
                "always" | "eventually" | "leads_to",
                ..,
                last,
            ],
            false,
        ) => match *last {
            "robot" | "from" => names.robots(),
            "in" | "enters" => names.modes(sibling("robot")),
            "receives" => names.received(sibling("robot")),
            _ => Vec::new(),
        },
        _ => Vec::new(),
    };
    let mut seen = std::collections::HashSet::new();
    candidates
        .into_iter()
        .filter(|(label, _, _)| seen.insert(label.clone()))
        .map(|(label, kind, detail)| ScenarioCompletion {
            insert: match place.quoted {
                true => json_escape(&label),
                false => format!("\"{}\"", json_escape(&label)),
            },
            label,
            kind,
            detail,
            replace: place.replace,
        })
        .collect()
}

fn json_escape(s: &str) -> String {
    let mut quoted = String::new();
    super::trace::json_string(&mut quoted, s);
    quoted[1..quoted.len() - 1].to_string()
}

/// The names of the mission's programs, as the scenario reader checks them.
struct Names<'a> {
    programs: &'a [RobotProgram],
}

type Candidates = Vec<(String, ScenarioCompletionKind, String)>;

impl Names<'_> {
    /// The programs of `robot` (a robot or team name), or all of them.
    fn of(&self, robot: Option<&str>) -> impl Iterator<Item = &RobotProgram> {
        let robot = robot.map(str::to_string);
        self.programs
            .iter()
            .filter(move |p| robot.as_deref().is_none_or(|r| p.robot == r || p.team == r))
    }

    fn robots(&self) -> Candidates {
        self.programs
            .iter()
            .map(|p| {
                let detail = format!("robot of {} ({})", p.team, p.robot_type);
                (p.robot.clone(), ScenarioCompletionKind::Robot, detail)
            })
            .collect()
    }

    fn teams(&self) -> Candidates {
        self.programs
            .iter()
            .map(|p| (p.team.clone(), ScenarioCompletionKind::Team, "team".into()))
            .collect()
    }

    fn sensor_values(&self, robot: &str) -> Candidates {
        self.of(Some(robot))
            .flat_map(|p| &p.tasks)
            .filter_map(|t| match &t.kind {
                RoleKind::Sensor { values, period_ms } => Some(values.iter().map(move |v| {
                    let detail = format!("sensor value of task {} (every {period_ms} ms)", t.task);
                    (v.clone(), ScenarioCompletionKind::Value, detail)
                })),
                _ => None,
            })
            .flatten()
            .collect()
    }

    fn services(&self, robot: &str) -> Candidates {
        self.of(Some(robot))
            .flat_map(|p| &p.tasks)
            .filter_map(|t| match &t.kind {
                RoleKind::Service { services } => Some(services.iter().map(move |s| {
                    let detail = format!("built-in service of task {} (ms it takes)", t.task);
                    (s.clone(), ScenarioCompletionKind::Service, detail)
                })),
                _ => None,
            })
            .flatten()
            .collect()
    }

    fn modes(&self, robot: Option<&str>) -> Candidates {
        self.of(robot)
            .flat_map(|p| {
                p.control.modes.iter().map(move |m| {
                    let detail = format!("mode of {} (line {})", p.team, m.line);
                    (m.name.clone(), ScenarioCompletionKind::Mode, detail)
                })
            })
            .collect()
    }

    fn received(&self, robot: Option<&str>) -> Candidates {
        self.of(robot)
            .flat_map(|p| {
                p.control.incoming.iter().map(move |m| {
                    let detail = format!("{} receives it from {}", p.robot, m.from_team);
                    (m.key.clone(), ScenarioCompletionKind::Value, detail)
                })
            })
            .collect()
    }

    /// The `USER` commands the robots `to` names (or all) read.
    fn commands(&self, to: Option<&str>) -> Candidates {
        self.of(to)
            .flat_map(|p| {
                p.control.slots.iter().filter_map(move |s| {
                    let command = s.key.strip_prefix("USER.")?;
                    let detail = format!("operator command {} reads", p.robot);
                    Some((command.to_string(), ScenarioCompletionKind::Command, detail))
                })
            })
            .collect()
    }

    /// The literals the programs of `robot` (or all) compare a slot with,
    /// for the slots `wanted` takes (by source and key).
    fn constants(
        &self,
        robot: Option<&str>,
        wanted: impl Fn(&SlotSource, &str) -> bool,
    ) -> Candidates {
        let mut out = Vec::new();
        for p in self.of(robot) {
            let slot_wanted = |operand: &Operand| match operand {
                Operand::Slot(i) => p
                    .control
                    .slots
                    .get(i.index())
                    .is_some_and(|s| wanted(&s.source, &s.key)),
                Operand::Literal(_) => false,
            };
            let mut add = |expr: &Expr| {
                compared_literals(expr, &slot_wanted, &mut |literal| {
                    let detail = format!("compared with in {}'s program", p.robot);
                    out.push((
                        literal.to_string(),
                        ScenarioCompletionKind::Constant,
                        detail,
                    ));
                })
            };
            for state in p.control.services.iter().flat_map(|s| &s.states) {
                match &state.kind {
                    StateKind::Branch { condition, .. } => add(condition),
                    StateKind::LoopHead {
                        condition: Some(condition),
                        ..
                    }
                    | StateKind::Repeat {
                        condition: Some(condition),
                        ..
                    } => add(condition),
                    _ => {}
                }
            }
            for action in p.control.actions.iter().flat_map(|a| &a.actions) {
                for condition in action.transitions.iter().filter_map(|(c, _)| c.as_ref()) {
                    add(condition);
                }
            }
        }
        out
    }
}

fn compared_literals(expr: &Expr, wanted: &dyn Fn(&Operand) -> bool, found: &mut dyn FnMut(&str)) {
    match expr {
        Expr::Or(a, b) | Expr::And(a, b) => {
            compared_literals(a, wanted, found);
            compared_literals(b, wanted, found);
        }
        Expr::Not(a) => compared_literals(a, wanted, found),
        Expr::Compare(a, _, b, _) => match (a, b) {
            (slot, Operand::Literal(l)) | (Operand::Literal(l), slot) if wanted(slot) => {
                found(&l.as_text())
            }
            _ => {}
        },
        Expr::Truthy(_) | Expr::Bool(_) => {}
    }
}

/// Where the cursor is in a (possibly unfinished) JSON text.
#[derive(Debug, PartialEq, Eq)]
struct Place {
    /// From the root down: each object's key the cursor is under, `[]` for
    /// each array; ends with the cursor's own key when it is in a value.
    path: Vec<String>,
    /// The cursor is where a key goes.
    in_key: bool,
    /// The cursor is inside a string.
    quoted: bool,
    replace: Span,
    /// The string members of the object holding the cursor (all of them,
    /// before and after it), but the cursor's own.
    siblings: Vec<(String, String)>,
}

impl Place {
    fn sibling(&self, key: &str) -> Option<&str> {
        self.siblings
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The cursor's place, or `None` outside any object or array (or
    /// inside a number or a literal).
    fn find(text: &str, offset: usize) -> Option<Place> {
        if offset > text.len() || !text.is_char_boundary(offset) {
            return None;
        }
        let bytes = text.as_bytes();
        let mut stack: Vec<Frame> = Vec::new();
        let mut place: Option<(Place, usize)> = None;
        let mut i = 0;
        while i <= bytes.len() {
            if place.is_none() && i >= offset {
                // The cursor is between tokens (or in a bare word).
                let start = text[..offset]
                    .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .map_or(0, |p| p + 1);
                if start < offset && text[start..offset].starts_with(|c: char| c.is_ascii_digit()) {
                    return None; // a number
                }
                place = Some((
                    Place::at(&stack, false, Span::new(start, offset))?,
                    stack.len(),
                ));
            }
            let Some(&b) = bytes.get(i) else { break };
            match b {
                b'"' => {
                    let (content_end, next) = string_end(bytes, i + 1);
                    if place.is_none() && offset > i && offset <= content_end {
                        let replace = Span::new(i + 1, content_end);
                        place = Some((Place::at(&stack, true, replace)?, stack.len()));
                    }
                    let s = unescape(&text[i + 1..content_end]);
                    if let Some(Frame::Object {
                        key,
                        expect_key,
                        strings,
                    }) = stack.last_mut()
                    {
                        if *expect_key {
                            *key = Some(s);
                        } else if let Some(k) = key.clone() {
                            strings.push((k, s));
                        }
                    }
                    i = next;
                    continue;
                }
                b'{' => stack.push(Frame::Object {
                    key: None,
                    expect_key: true,
                    strings: Vec::new(),
                }),
                b'[' => stack.push(Frame::Array),
                b'}' | b']' => {
                    let popped = stack.pop();
                    if let Some((found, depth)) = &mut place
                        && stack.len() + 1 == *depth
                    {
                        if let Some(Frame::Object { strings, .. }) = popped {
                            found.siblings = strings;
                        }
                        break;
                    }
                }
                b':' => {
                    if let Some(Frame::Object { expect_key, .. }) = stack.last_mut() {
                        *expect_key = false;
                    }
                }
                b',' => {
                    if let Some(Frame::Object {
                        key, expect_key, ..
                    }) = stack.last_mut()
                    {
                        *key = None;
                        *expect_key = true;
                    }
                }
                _ => {}
            }
            i += 1;
        }
        let (mut found, depth) = place?;
        if found.siblings.is_empty()
            && let Some(Frame::Object { strings, .. }) = stack.get(depth.wrapping_sub(1))
        {
            found.siblings = strings.clone(); // the object was never closed
        }
        let own = found.path.last().cloned().filter(|_| !found.in_key);
        found.siblings.retain(|(k, _)| Some(k) != own.as_ref());
        Some(found)
    }

    fn at(stack: &[Frame], quoted: bool, replace: Span) -> Option<Place> {
        let (last, outer) = stack.split_last()?;
        let mut path = Vec::new();
        for frame in outer {
            match frame {
                Frame::Object { key, .. } => path.push(key.clone()?),
                Frame::Array => path.push("[]".into()),
            }
        }
        let in_key = match last {
            Frame::Object {
                key, expect_key, ..
            } => {
                if !expect_key {
                    path.push(key.clone()?);
                }
                *expect_key
            }
            Frame::Array => {
                path.push("[]".into());
                false
            }
        };
        Some(Place {
            path,
            in_key,
            quoted,
            replace,
            siblings: Vec::new(),
        })
    }
}

enum Frame {
    Object {
        /// The key just read (the one whose value comes next).
        key: Option<String>,
        expect_key: bool,
        /// String members read so far.
        strings: Vec<(String, String)>,
    },
    Array,
}

/// The end of a string's contents starting at `from` (the closing quote,
/// or the line's end for a string not closed on its line) and where
/// scanning goes on.
fn string_end(bytes: &[u8], from: usize) -> (usize, usize) {
    let mut i = from;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return (i, i + 1),
            b'\n' | b'\r' => return (i, i),
            _ => i += 1,
        }
    }
    (bytes.len(), bytes.len())
}

/// A string's contents with the common escapes undone (enough for names).
fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        match (c, c == '\\') {
            (_, true) => match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => {}
            },
            (c, false) => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests;
