//! Semantic highlighting: every name of the mission that the checker resolved,
//! with what it is. Keywords, strings, numbers and comments are left to the
//! editor's grammar.

use crate::CheckedMission;
use crate::sema::Symbol;
use crate::sema::lookup;
use crate::span::Span;

/// What a highlighted name is. The protocol legend lists [`TokenKind::ALL`]
/// by [`TokenKind::name`], in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TokenKind {
    Team,
    Robot,
    RobotType,
    Capability,
    Plan,
    Service,
    Mode,
    Event,
    Function,
    Variable,
    Value,
    Constant,
    Group,
    Parameter,
}

impl TokenKind {
    pub const ALL: [TokenKind; 14] = [
        TokenKind::Team,
        TokenKind::Robot,
        TokenKind::RobotType,
        TokenKind::Capability,
        TokenKind::Plan,
        TokenKind::Service,
        TokenKind::Mode,
        TokenKind::Event,
        TokenKind::Function,
        TokenKind::Variable,
        TokenKind::Value,
        TokenKind::Constant,
        TokenKind::Group,
        TokenKind::Parameter,
    ];

    pub fn name(self) -> &'static str {
        match self {
            TokenKind::Team => "team",
            TokenKind::Robot => "robot",
            TokenKind::RobotType => "robotType",
            TokenKind::Capability => "capability",
            TokenKind::Plan => "plan",
            TokenKind::Service => "service",
            TokenKind::Mode => "mode",
            TokenKind::Event => "event",
            TokenKind::Function => "function",
            TokenKind::Variable => "variable",
            TokenKind::Value => "value",
            TokenKind::Constant => "constant",
            TokenKind::Group => "group",
            TokenKind::Parameter => "parameter",
        }
    }

    /// The index of this kind in [`TokenKind::ALL`].
    pub fn index(self) -> u32 {
        self as u32
    }
}

/// Modifier bits; bit `i` is [`MODIFIERS`]`[i]`.
pub const DECLARATION: u32 = 1 << 0;
/// A name from the robot catalog or built into the language (`USER`).
pub const DEFAULT_LIBRARY: u32 = 1 << 1;
pub const MODIFIERS: [&str; 2] = ["declaration", "defaultLibrary"];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HighlightToken {
    pub span: Span,
    pub kind: TokenKind,
    pub modifiers: u32,
}

/// The highlighted names, sorted and not overlapping, of the whole file or
/// of those overlapping `range`. Each is one identifier, so on one line.
pub fn semantic_tokens(analysis: &CheckedMission, range: Option<Span>) -> Vec<HighlightToken> {
    let mission = &analysis.mission;
    let occurrences = match range {
        Some(range) => lookup::in_range(mission, range),
        None => &mission.occurrences[..],
    };
    // Throws declare events (see `navigation`).
    let mut throws: Vec<Span> = mission
        .teams
        .iter()
        .flat_map(|t| t.events.iter().flat_map(|e| e.thrown_at.iter().copied()))
        .collect();
    throws.sort_unstable();
    let mut tokens: Vec<HighlightToken> = Vec::new();
    let mut rest = occurrences;
    while let Some(first) = rest.first() {
        // All occurrences of one name are adjacent; the definition wins.
        let same = rest.iter().take_while(|o| o.span == first.span).count();
        let (run, next) = rest.split_at(same);
        rest = next;
        let o = run.iter().find(|o| o.is_definition).unwrap_or(first);
        if tokens.last().is_some_and(|t| t.span.end > o.span.start) {
            continue; // never overlap, whatever sema recorded
        }
        let (kind, mut modifiers) = classify(&o.symbol);
        let is_throw =
            matches!(o.symbol, Symbol::Event { .. }) && throws.binary_search(&o.span).is_ok();
        if o.is_definition || is_throw {
            modifiers |= DECLARATION;
        }
        tokens.push(HighlightToken {
            span: o.span,
            kind,
            modifiers,
        });
    }
    tokens
}

fn classify(symbol: &Symbol) -> (TokenKind, u32) {
    match symbol {
        Symbol::Team(_) => (TokenKind::Team, 0),
        Symbol::User => (TokenKind::Team, DEFAULT_LIBRARY),
        Symbol::Robot { .. } => (TokenKind::Robot, 0),
        Symbol::RobotType(_) => (TokenKind::RobotType, DEFAULT_LIBRARY),
        Symbol::Capability(_) => (TokenKind::Capability, DEFAULT_LIBRARY),
        Symbol::Plan { .. } => (TokenKind::Plan, 0),
        Symbol::Service { .. } => (TokenKind::Service, 0),
        Symbol::BuiltinService(_) => (TokenKind::Service, DEFAULT_LIBRARY),
        Symbol::Mode { .. } | Symbol::ModeTemplate { .. } => (TokenKind::Mode, 0),
        Symbol::Event { .. } => (TokenKind::Event, 0),
        Symbol::Function(_) => (TokenKind::Function, 0),
        Symbol::TeamVariable { .. } => (TokenKind::Variable, 0),
        Symbol::Value { .. } => (TokenKind::Value, DEFAULT_LIBRARY),
        Symbol::Constant(_) => (TokenKind::Constant, 0),
        Symbol::CountedGroup { .. } => (TokenKind::Group, 0),
        Symbol::Parameter { .. } => (TokenKind::Parameter, 0),
        // A result is a variable of the robot running the body: the
        // standard type, which themes colour.
        Symbol::Result { .. } => (TokenKind::Variable, 0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::Fixture;

    const MISSION: &str = r#"{ T: Turtlebot3_Burger tb[2] }
def f { throw e }
T.P.S {
  [[ group(capable of light_sensor) { publish(T, T.X = DARK) } ]]
  if (LIGHTNESS < 200) f()
  send(USER, T.X)
} repeat()
T.M { set(P, S) }
T.main { case (M): catch (e): mode = M default: mode = M }
"#;

    fn show(f: &Fixture, tokens: &[HighlightToken]) -> String {
        tokens
            .iter()
            .map(|t| {
                let mut s = format!("{} {}", &f.text[t.span.range()], t.kind.name());
                for (i, m) in MODIFIERS.iter().enumerate() {
                    if t.modifiers & (1 << i) != 0 {
                        s.push_str(&format!(" +{m}"));
                    }
                }
                s
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    #[test]
    fn every_kind_of_name() {
        let f = Fixture::new(MISSION);
        let tokens = semantic_tokens(&f.analysis, None);
        assert_eq!(
            show(&f, &tokens),
            "\
T team +declaration
Turtlebot3_Burger robotType +defaultLibrary
tb robot +declaration
f function +declaration
e event +declaration
T team
P plan +declaration
S service +declaration
light_sensor capability +defaultLibrary
T team
T team
X variable +declaration
DARK constant
LIGHTNESS value +defaultLibrary
f function
USER team +defaultLibrary
T team
X variable
T team
M mode +declaration
P plan
S service
T team
M mode
e event
M mode
M mode"
        );
        assert!(tokens.windows(2).all(|w| w[0].span.end <= w[1].span.start));
    }

    #[test]
    fn a_range_gives_the_names_overlapping_it() {
        let f = Fixture::new(MISSION);
        let line = f.offset_of("  if (");
        let range = Span::new(line + 4, line + 10);
        assert_eq!(
            show(&f, &semantic_tokens(&f.analysis, Some(range))),
            "LIGHTNESS value +defaultLibrary"
        );
        let all = semantic_tokens(&f.analysis, None);
        let whole = Span::new(0, f.text.len());
        assert_eq!(semantic_tokens(&f.analysis, Some(whole)), all);
        assert!(semantic_tokens(&f.analysis, Some(Span::new(9999, 10000))).is_empty());
    }
}
