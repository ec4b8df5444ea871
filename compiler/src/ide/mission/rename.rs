//! Rename: teams, robots, plans, composite services, modes, events, functions
//! and team variables. Names from the robot catalog (robot types, built-in
//! services, values, capabilities), `USER`, symbolic constants and keywords
//! cannot be renamed here.
//!
//! A mission is self-contained: a team `Base` in another mission is another
//! team, so a rename changes one file, every name in it that means the
//! renamed symbol. (Strategy files, `<Team>.strategy.xml`, also name teams,
//! plans and robots; the server does not read them yet, so they are not
//! renamed.) When one of those names also means another symbol (a
//! function called by two teams raises an event of each with one `throw`),
//! that symbol is renamed too, so the file keeps its meaning; if it cannot be
//! renamed, neither can the first.
//!
//! The new name must be a name for the lexer (`[A-Za-z_][A-Za-z0-9_]*`), not a
//! keyword, and must not clash with a symbol of the same kind and scope (a
//! mode of the same team, a service of the same plan, ...) or change what
//! other names mean (a function named like a robot service would take over
//! its calls).

use super::navigation;
use crate::CheckedMission;
use crate::catalog::Catalog;
use crate::sema::Symbol;
use crate::sema::lookup;
use crate::span::Span;
use crate::syntax::token::{self, Kw, Token};
use std::fmt;

/// Why a rename is refused, in words for the user.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenameError(pub String);

impl fmt::Display for RenameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for RenameError {}

fn refuse<T>(message: impl Into<String>) -> Result<T, RenameError> {
    Err(RenameError(message.into()))
}

/// The range of the name at `offset` if it can be renamed, else why not.
pub fn prepare_rename(
    analysis: &CheckedMission,
    text: &str,
    offset: usize,
) -> Result<Span, RenameError> {
    let Some(name) = navigation::name_at(analysis, offset) else {
        return match word_at(text, offset) {
            Some(word) if Kw::from_word(word).is_some() => refuse(format!(
                "`{word}` is a keyword of the language; it cannot be renamed"
            )),
            _ => refuse("there is no name to rename here"),
        };
    };
    for symbol in &name.symbols {
        renamable(symbol)?;
    }
    Ok(name.span)
}

/// The ranges to replace with `new_name` to rename the name at `offset`,
/// sorted, or why the rename is refused.
pub fn rename(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    offset: usize,
    new_name: &str,
) -> Result<Vec<Span>, RenameError> {
    prepare_rename(analysis, text, offset)?;
    check_name(new_name)?;
    let Some(name) = navigation::name_at(analysis, offset) else {
        return refuse("there is no name to rename here");
    };
    let mission = &analysis.mission;
    // The symbols to rename: those of the name, and those sharing a name with
    // one of them (closure), each checked.
    let first = name.symbols.len();
    let mut symbols = name.symbols;
    let mut spans: Vec<Span> = Vec::new();
    let mut next = 0;
    while let Some(symbol) = symbols.get(next).cloned() {
        next += 1;
        renamable(&symbol).map_err(|e| match next > first {
            true => RenameError(format!(
                "{e} (a function body here is shared with another team, for which this name means that)"
            )),
            false => e,
        })?;
        if let Some(clash) = clash(analysis, catalog, text, &symbol, new_name) {
            return refuse(clash);
        }
        let uses = mission.occurrences_of(&symbol).map(|o| o.span);
        for span in uses.chain(navigation::definition_spans(analysis, &symbol)) {
            spans.push(span);
            for o in lookup::with_span(mission, span) {
                if !symbols.contains(&o.symbol) {
                    symbols.push(o.symbol.clone());
                }
            }
        }
    }
    spans.sort();
    spans.dedup();
    Ok(spans)
}

/// Whether a symbol is the mission's own (else why it cannot be renamed).
fn renamable(symbol: &Symbol) -> Result<(), RenameError> {
    let from_catalog = |what: &str, name: &str| {
        refuse(format!(
            "`{name}` is a {what} from the robot catalog; rename it in the catalog, not in a mission"
        ))
    };
    match symbol {
        Symbol::Team(_)
        | Symbol::Robot { .. }
        | Symbol::Plan { .. }
        | Symbol::Service { .. }
        | Symbol::Mode { .. }
        | Symbol::ModeTemplate { .. }
        | Symbol::Event { .. }
        | Symbol::Function(_)
        | Symbol::TeamVariable { .. }
        | Symbol::Parameter { .. }
        | Symbol::Result { .. }
        | Symbol::CountedGroup { .. } => Ok(()),
        Symbol::User => {
            refuse("`USER` is the operator's console, a built-in name; it cannot be renamed")
        }
        Symbol::RobotType(name) => from_catalog("robot type", name),
        Symbol::Capability(name) => from_catalog("capability", name),
        Symbol::BuiltinService(name) => from_catalog("robot service", name),
        Symbol::Value { name, .. } => from_catalog("robot value", name),
        Symbol::Constant(name) => refuse(format!(
            "`{name}` is a symbolic constant: it is not declared in the mission, so it cannot be renamed"
        )),
    }
}

/// Whether `name` can name something: one identifier token, not a keyword.
fn check_name(name: &str) -> Result<(), RenameError> {
    match token::lex(name).as_slice() {
        [(Token::Ident(s), span)] if *s == name && span.start == 0 => Ok(()),
        [(Token::Kw(kw), _)] if kw.as_str() == name => refuse(format!(
            "`{name}` is a keyword of the language; choose another name"
        )),
        _ => refuse(format!(
            "`{name}` is not a valid name: a name starts with a letter or `_` and has only letters, digits and `_`"
        )),
    }
}

/// What `symbol`, renamed to `new`, would clash with.
fn clash(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    symbol: &Symbol,
    new: &str,
) -> Option<String> {
    let mission = &analysis.mission;
    let team_of = |id: crate::sema::TeamId| mission.teams.get(id.0 as usize);
    match symbol {
        // Named once, in its statement; a name another group of the
        // statement has is E038, which the check after the rename reports.
        Symbol::CountedGroup { .. } => None,
        Symbol::Team(id) => {
            if crate::sema::is_user(new) {
                return Some(format!(
                    "`{new}` is the operator's console; choose another team name"
                ));
            }
            let other = mission
                .teams
                .iter()
                .enumerate()
                .find(|(i, t)| *i != id.0 as usize && t.name == new)?;
            Some(format!("there is already a team `{}`", other.1.name))
        }
        Symbol::Robot { team, robot } => {
            let decl = team_of(*team)?.robots.get(robot.index())?.name_span;
            let written = text.get(decl.range())?;
            // `tb[3]` declares tb_0, tb_1, tb_2: they become new_0, new_1, new_2.
            let renamed: Vec<String> = mission
                .teams
                .iter()
                .flat_map(|t| &t.robots)
                .filter(|r| r.name_span == decl)
                .map(|r| format!("{new}{}", r.name.strip_prefix(written).unwrap_or("")))
                .collect();
            let (t, r) = mission.teams.iter().find_map(|t| {
                t.robots
                    .iter()
                    .find(|r| r.name_span != decl && renamed.iter().any(|n| *n == r.name))
                    .map(|r| (t, r))
            })?;
            Some(format!(
                "there is already a robot `{}` (in team {})",
                r.name, t.name
            ))
        }
        Symbol::Plan { team, plan } => {
            let t = team_of(*team)?;
            let other = t.plan_by_name(new).filter(|p| p != plan)?;
            Some(format!(
                "team {} already has a plan `{}`",
                t.name,
                t.plans[other.index()].name
            ))
        }
        Symbol::Service { team, service } => {
            let t = team_of(*team)?;
            let plan = t.services.get(service.index())?.plan;
            let other = t.service_in_plan(plan, new).filter(|s| s != service)?;
            Some(format!(
                "there is already a composite service `{}`",
                t.service_path(other)
            ))
        }
        Symbol::Mode { team, mode } => {
            let t = team_of(*team)?;
            if t.template_by_name(new).is_some() {
                return Some(format!("team {} already has a mode `{new}`", t.name));
            }
            let other = t.mode_by_name(new).filter(|m| m != mode)?;
            Some(format!(
                "team {} already has a mode `{}`",
                t.name,
                t.modes[other.index()].name
            ))
        }
        Symbol::ModeTemplate { team, template } => {
            let t = team_of(*team)?;
            let other = t.template_by_name(new).filter(|m| m != template);
            (other.is_some() || t.mode_by_name(new).is_some())
                .then(|| format!("team {} already has a mode `{new}`", t.name))
        }
        Symbol::Event { team, name } => {
            let t = team_of(*team)?;
            let other = t.events.iter().find(|e| e.name == new && e.name != *name)?;
            Some(format!(
                "team {} already has an event `{}`; renaming would merge the two",
                t.name, other.name
            ))
        }
        Symbol::Function(id) => {
            if let Some(other) = mission
                .functions
                .iter()
                .enumerate()
                .find(|(i, f)| *i != id.0 as usize && f.name == new)
            {
                return Some(format!("there is already a function `{}`", other.1.name));
            }
            catalog
                .types()
                .find_map(|(_, r)| r.service(new).map(|s| (r, s)))
                .map(|(r, s)| {
                    format!(
                        "`{}` is a robot service (of {}): its calls would call the function instead",
                        s.name, r.name
                    )
                })
        }
        Symbol::TeamVariable { team, name } => {
            let teams: Vec<&crate::sema::Team> = match team {
                Some(id) => team_of(*id).into_iter().collect(),
                None => mission.teams.iter().collect(),
            };
            for t in &teams {
                if let Some(other) = t.variables.iter().find(|v| *v == new && *v != name) {
                    return Some(format!(
                        "team {} already has a team variable `{other}`",
                        t.name
                    ));
                }
                let value = t
                    .robots
                    .iter()
                    .filter_map(|r| r.robot_type)
                    .find_map(|ty| catalog.get(ty).value(new).map(|v| (ty, v)));
                if let Some((ty, v)) = value {
                    return Some(format!(
                        "the robots of team {} have a value `{}` ({}): the variable would read it instead",
                        t.name,
                        v.name,
                        catalog.get(ty).name
                    ));
                }
            }
            None
        }
        Symbol::Parameter { owner, .. } => {
            parameter_clash(analysis, catalog, text, symbol, *owner, new)
        }
        Symbol::Result { owner, .. } => result_clash(analysis, catalog, *owner, new),
        Symbol::User
        | Symbol::RobotType(_)
        | Symbol::Capability(_)
        | Symbol::BuiltinService(_)
        | Symbol::Value { .. }
        | Symbol::Constant(_) => None,
    }
}

/// What a result name of `owner`'s body, renamed to `new`, would clash
/// with: another result or a parameter of the body, a value robots read or
/// a team variable (E045).
fn result_clash(
    analysis: &CheckedMission,
    catalog: &Catalog,
    owner: crate::sema::ParamOwner,
    new: &str,
) -> Option<String> {
    let mission = &analysis.mission;
    let whose = mission.owner_name(owner);
    if mission.results(owner).iter().any(|r| r.name == new) {
        return Some(format!("`{whose}` already binds a result `{new}`"));
    }
    if mission.params(owner).iter().any(|p| p.name == new) {
        return Some(format!("`{whose}` already has a parameter `{new}`"));
    }
    Some(match hidden_by(analysis, catalog, new)? {
        Hidden::Value(ty) => {
            format!("robot type {ty} has a value `{new}`: the result would hide it")
        }
        Hidden::Variable => format!("`{new}` is a team variable: the result would hide it"),
    })
}

/// What a parameter or result renamed to `new` would hide (E045): a value
/// some robot type reads (that type), or a team variable.
enum Hidden<'c> {
    Value(&'c str),
    Variable,
}

fn hidden_by<'c>(analysis: &CheckedMission, catalog: &'c Catalog, new: &str) -> Option<Hidden<'c>> {
    if let Some((_, r)) = catalog.types().find(|(_, r)| r.value(new).is_some()) {
        return Some(Hidden::Value(&r.name));
    }
    let variable = (analysis.mission.teams.iter()).any(|t| t.variables.iter().any(|v| v == new));
    variable.then_some(Hidden::Variable)
}

/// What a parameter of `owner` (a function, a service, a mode), renamed
/// to `new`, would clash with: another parameter of its list, a value
/// robots read or a team variable (E045), or a name its body (a mode's
/// `set`s) already writes with another meaning (which would then mean the
/// parameter).
fn parameter_clash(
    analysis: &CheckedMission,
    catalog: &Catalog,
    text: &str,
    symbol: &Symbol,
    owner: crate::sema::ParamOwner,
    new: &str,
) -> Option<String> {
    use crate::sema::ParamOwner;
    let mission = &analysis.mission;
    let whose = mission.owner_name(owner);
    if let Some(other) = mission.params(owner).iter().find(|p| p.name == new) {
        return Some(format!(
            "`{whose}` already has a parameter `{}`",
            other.name
        ));
    }
    match hidden_by(analysis, catalog, new) {
        Some(Hidden::Value(ty)) => {
            return Some(format!(
                "`{new}` is a value of robot type {ty}: the parameter would hide it"
            ));
        }
        Some(Hidden::Variable) => {
            return Some(format!(
                "`{new}` is a team variable: the parameter would hide it"
            ));
        }
        None => {}
    }
    let body = match owner {
        ParamOwner::Function(f) => {
            analysis
                .function_syntax(mission.functions.get(f.0 as usize)?)?
                .span
        }
        ParamOwner::Service(team, service) => mission.team(team).service(service).span,
        ParamOwner::Mode(team, template) => mission.team(team).template(template).span,
    };
    mission.occurrences.iter().find(|o| {
        body.contains(o.span.start) && o.symbol != *symbol && text.get(o.span.range()) == Some(new)
    })?;
    Some(format!(
        "`{new}` already means something else in the body of `{whose}`: it would mean the parameter"
    ))
}

/// The identifier-like word around `offset`, if any.
fn word_at(text: &str, offset: usize) -> Option<&str> {
    let bytes = text.as_bytes();
    let is_word = |b: &u8| b.is_ascii_alphanumeric() || *b == b'_';
    let offset = offset.min(bytes.len());
    let start = bytes[..offset]
        .iter()
        .rposition(|b| !is_word(b))
        .map_or(0, |i| i + 1);
    let end = bytes[offset..]
        .iter()
        .position(|b| !is_word(b))
        .map_or(bytes.len(), |i| offset + i);
    (start < end).then(|| &text[start..end])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::Fixture;

    const MISSION: &str = r#"{
  Base: iRobotCreate base
  Guards: Turtlebot3_Burger tb[2], Ev3_Robot ev
}
def warn { throw alarm }
Base.Listen.Collect {
  subscribe(Guards, Guards.Alarm)
  if (Guards.Alarm == DARK) throw alarm
  warn()
} repeat(1 SEC)
Base.Action.Hold { standby() } repeat()
Base.Action.Wait { standby() } repeat()
Guards.Action.Patrol {
  publish(Guards, Guards.Alarm = DARK)
  warn()
  if (LOCATION == "1,1") throw home
} repeat()
Base.WATCH { set(Listen, Collect); set(Action, Hold) }
Base.ALERT { set(Listen, OFF); set(Action, Wait) }
Base.main {
  case (WATCH):
    catch (alarm): mode = ALERT
  default: mode = WATCH
}
Guards.GO { set(Action, Patrol) }
Guards.main { case (GO): catch (alarm): mode = GO catch (home): mode = GO default: mode = GO }
"#;

    /// The text after renaming the name at `marker` to `new`.
    fn renamed(f: &Fixture, marker: &str, new: &str) -> Result<String, String> {
        let spans =
            rename(&f.analysis, &f.catalog, &f.text, f.offset_of(marker), new).map_err(|e| e.0)?;
        let mut text = f.text.clone();
        for span in spans.iter().rev() {
            text.replace_range(span.range(), new);
        }
        Ok(text)
    }

    /// Renaming gives a mission that checks exactly like the original.
    fn assert_same_meaning(f: &Fixture, renamed: &str) {
        let after = crate::check_source(Fixture::FILE, renamed, &f.catalog);
        let codes = |a: &CheckedMission| a.diagnostics.iter().map(|d| d.code).collect::<Vec<_>>();
        assert_eq!(codes(&after), codes(&f.analysis), "{renamed}");
        assert_eq!(
            after.mission.occurrences.len(),
            f.analysis.mission.occurrences.len()
        );
    }

    #[test]
    fn renames_every_kind_of_mission_symbol() {
        let f = Fixture::new(MISSION);
        for (marker, new, count) in [
            ("Base: ", "Home", 7),
            ("tb[2]", "bot", 1),
            ("Listen, Collect", "Ears", 3),
            ("Hold) }", "Idle", 2),
            ("ALERT\n", "ALARMED", 2),
            ("home\n", "back", 2),
            ("Alarm = DARK", "Level", 3),
            ("warn {", "raise_alarm", 3),
        ] {
            let text = renamed(&f, marker, new).unwrap_or_else(|e| panic!("{marker}: {e}"));
            assert_eq!(
                text.matches(new).count(),
                count + MISSION.matches(new).count(),
                "{marker}: {text}"
            );
            assert_same_meaning(&f, &text);
        }
    }

    #[test]
    fn an_event_thrown_by_a_shared_function_is_renamed_in_both_teams() {
        let f = Fixture::new(MISSION);
        let text = renamed(&f, "alarm\n  warn", "danger").unwrap();
        assert_eq!(text.matches("alarm").count(), 0, "{text}");
        assert_eq!(text.matches("danger").count(), 4);
        assert_same_meaning(&f, &text);
    }

    #[test]
    fn refuses_catalog_names_constants_and_keywords() {
        let f = Fixture::new(MISSION);
        let refusal = |marker: &str| {
            prepare_rename(&f.analysis, &f.text, f.offset_of(marker))
                .unwrap_err()
                .0
        };
        assert!(refusal("standby() } repeat()\nBase.Action.Wait").contains("robot service"));
        assert!(refusal("Turtlebot3_Burger").contains("robot type"));
        assert!(refusal("LOCATION").contains("robot value"));
        assert!(refusal("DARK) throw").contains("symbolic constant"));
        assert!(refusal("def warn").contains("`def` is a keyword"));
        assert!(refusal("repeat(1 SEC)").contains("`repeat` is a keyword"));
        assert_eq!(refusal("\"1,1\""), "there is no name to rename here");
        let ok = prepare_rename(&f.analysis, &f.text, f.offset_of("WATCH {")).unwrap();
        assert_eq!(&f.text[ok.range()], "WATCH");
    }

    #[test]
    fn refuses_invalid_names_and_clashes() {
        let f = Fixture::new(MISSION);
        for (marker, new, message) in [
            ("ALERT\n", "if", "`if` is a keyword"),
            ("ALERT\n", "2fast", "not a valid name"),
            ("ALERT\n", "a b", "not a valid name"),
            ("ALERT\n", "", "not a valid name"),
            ("ALERT\n", "한국", "not a valid name"),
            ("ALERT\n", "WATCH", "team Base already has a mode `WATCH`"),
            ("Base: ", "Guards", "there is already a team `Guards`"),
            ("Base: ", "user", "operator's console"),
            (
                "Hold) }",
                "Wait",
                "there is already a composite service `Base.Action.Wait`",
            ),
            (
                "Listen, Collect",
                "Action",
                "team Base already has a plan `Action`",
            ),
            (
                "home\n",
                "alarm",
                "team Guards already has an event `alarm`",
            ),
            ("warn {", "move", "`move` is a robot service"),
            ("Alarm = DARK", "LOCATION", "have a value `LOCATION`"),
            (
                "base\n",
                "ev",
                "there is already a robot `ev` (in team Guards)",
            ),
            ("ev\n", "tb_1", "there is already a robot `tb_1`"),
            ("ev\n", "tb", ""),
        ] {
            let result = renamed(&f, marker, new);
            match (message, result) {
                ("", Ok(_)) => {}
                ("", Err(e)) => panic!("{marker} -> {new}: {e}"),
                (_, Ok(text)) => panic!("{marker} -> {new} was accepted:\n{text}"),
                (_, Err(e)) => assert!(e.contains(message), "{marker} -> {new}: {e}"),
            }
        }
    }

    #[test]
    fn refuses_a_name_that_a_shared_function_gives_another_meaning() {
        // In `f`, `COLOR` is team A's variable but team B's robot value.
        let f = Fixture::new(
            r#"{ A: iRobotCreate a  B: NXTLego b }
def f { if (COLOR == "red") stop() }
A.P.S { publish(A, A.COLOR = "red") f() } repeat()
B.P.S { f() } repeat()
A.M { set(P, S) }
B.M { set(P, S) }
A.main { default: mode = M }
B.main { default: mode = M }
"#,
        );
        let error = renamed(&f, "COLOR = ", "SHADE").unwrap_err();
        assert!(error.contains("`COLOR` is a robot value"), "{error}");
        assert!(error.contains("shared with another team"), "{error}");
    }

    #[test]
    fn any_offset_is_accepted() {
        let f = Fixture::new(MISSION);
        for offset in 0..=f.text.len() + 2 {
            let _ = prepare_rename(&f.analysis, &f.text, offset);
            let _ = rename(&f.analysis, &f.catalog, &f.text, offset, "x");
        }
        // Inside a multi-byte character.
        let g = Fixture::new("# 한국어\n{ T: iRobotCreate r }");
        for offset in 0..=g.text.len() {
            let _ = prepare_rename(&g.analysis, &g.text, offset);
        }
    }
}
