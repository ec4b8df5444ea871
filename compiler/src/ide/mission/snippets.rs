//! Snippets: one for each construct of the language and one for a whole new
//! mission (the template of spec §6), in the LSP snippet syntax (`${1:Team}`
//! placeholders, `${1|a,b|}` choices, `$0` for the final cursor, `\t` for one
//! indentation level). [`to_plain`] turns one into plain text for editors
//! without snippets.

/// A construct's snippet.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Snippet {
    /// What the editor lists (`if`, `[[ group ]]`, `mission template`).
    pub label: &'static str,
    /// One line on what it writes.
    pub detail: &'static str,
    pub body: String,
}

/// The skeleton a new mission starts from (spec §6), as plain text.
pub const MISSION_TEMPLATE: &str = "\
# 1. Team formation:  TeamName: RobotType robot_name
{
}
# 2. Behaviour of each team
# Part 1. Composite services:  TeamName.PlanName.ServiceName { ... } repeat(...)
# Part 2. Modes:               TeamName.ModeName { set(PlanName, ServiceName or OFF) }
# Part 3. Mode changes:        TeamName.main { case (Mode): catch (event): mode = Other  default: mode = Mode }
";

/// `name(${1:A}, ${2:B})`: a call with a stop at each parameter, named
/// (functions, composite services and modes with parameters).
pub fn call<'p>(name: &str, params: impl IntoIterator<Item = &'p str>) -> String {
    let stops: Vec<String> = params
        .into_iter()
        .enumerate()
        .map(|(i, p)| format!("${{{}:{}}}", i + 1, escape(p)))
        .collect();
    format!("{}({})", escape(name), stops.join(", "))
}

/// Escapes text for use inside a snippet.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if matches!(c, '\\' | '$' | '}') {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// A placeholder: a choice among `options` when there are some, else `default`.
pub fn choice(index: usize, options: &[&str], default: &str) -> String {
    if options.is_empty() {
        return format!("${{{index}:{}}}", escape(default));
    }
    let escaped: Vec<String> = options
        .iter()
        .map(|o| {
            o.chars()
                .flat_map(|c| {
                    let escape = matches!(c, ',' | '|' | '\\' | '$' | '}');
                    escape.then_some('\\').into_iter().chain([c])
                })
                .collect()
        })
        .collect();
    format!("${{{index}|{}|}}", escaped.join(","))
}

/// The mission template, with the cursor inside the formation braces.
pub fn mission_template() -> Snippet {
    let (before, after) = MISSION_TEMPLATE
        .split_once("{\n}")
        .unwrap_or((MISSION_TEMPLATE, ""));
    let body = format!("{}{{\n\t$0\n}}{}", escape(before), escape(after));
    Snippet {
        label: "mission template",
        detail: "the skeleton of a new mission: formation, services, modes, main",
        body,
    }
}

/// Snippets that start an item: `teams` and `types` fill the choices.
pub fn item_snippets(teams: &[&str], types: &[&str]) -> Vec<Snippet> {
    let team = |i| choice(i, teams, "Team");
    vec![
        Snippet {
            label: "formation",
            detail: "the team formation block: `Team: RobotType robot`",
            body: format!(
                "{{\n\t${{1:Team}}: {} ${{3:robot}}\n}}",
                choice(2, types, "RobotType")
            ),
        },
        Snippet {
            label: "composite service",
            detail: "`Team.Plan.Service { ... } repeat()`",
            body: format!(
                "{}.${{2:Plan}}.${{3:Service}}{{\n\t$0\n}} repeat(${{4}})",
                team(1)
            ),
        },
        Snippet {
            label: "mode",
            detail: "`Team.MODE { set(Plan, Service) }`",
            body: format!(
                "{}.${{2:MODE}}{{\n\tset(${{3:Plan}}, ${{4:Service}})\n}}",
                team(1)
            ),
        },
        Snippet {
            label: "main",
            detail: "`Team.main { case ... default: mode = MODE }`",
            body: format!(
                "{}.main{{\n\tcase (${{2:MODE}}):\n\t\tcatch (${{3:event}}): mode = ${{4:OTHER_MODE}}\n\tdefault: mode = ${{2:MODE}}\n}}",
                team(1)
            ),
        },
        Snippet {
            label: "def",
            detail: "a function: statements copied where it is called",
            body: "def ${1:name}{\n\t$0\n}".to_string(),
        },
    ]
}

/// Snippets that start a statement: `teams` and `types` (of the robots that
/// run it) fill the choices.
pub fn statement_snippets(teams: &[&str], types: &[&str]) -> Vec<Snippet> {
    let team = |i| choice(i, teams, "Team");
    let ty = |i| choice(i, types, "RobotType");
    // `send`, `receive`, `publish`, `subscribe`: a team and a value.
    let message = |label: &'static str, detail: &'static str| Snippet {
        label,
        detail,
        body: format!("{label}({}, ${{2:VALUE}})", team(1)),
    };
    vec![
        Snippet {
            label: "if",
            detail: "if (condition) { ... }",
            body: "if (${1:condition}) {\n\t$0\n}".to_string(),
        },
        Snippet {
            label: "if else",
            detail: "if (condition) { ... } else { ... }",
            body: "if (${1:condition}) {\n\t$2\n} else {\n\t$0\n}".to_string(),
        },
        Snippet {
            label: "loop",
            detail: "loop(period, condition) { ... }: again every period while the condition holds",
            body: "loop(${1:1 SEC}) {\n\t$0\n}".to_string(),
        },
        Snippet {
            label: "throw",
            detail: "throw EVENT: the main block may change mode",
            body: "throw ${1:EVENT}".to_string(),
        },
        message(
            "send",
            "send(Team, value): deliver reliably to every robot of a team",
        ),
        message(
            "receive",
            "receive(Team, Team.VALUE): wait for a value from a team",
        ),
        message("publish", "publish(Team, value): broadcast, best effort"),
        message(
            "subscribe",
            "subscribe(Team, Team.VALUE): read the latest value published by a team",
        ),
        Snippet {
            label: "[[ group ]]",
            detail: "split the robots: each runs the first group it belongs to",
            body: format!("[[\n\tgroup(instance of {}) {{\n\t\t$0\n\t}}\n]]", ty(1)),
        },
        Snippet {
            label: "[[ group others ]]",
            detail: "a group, and the other robots",
            body: format!(
                "[[\n\tgroup(instance of {}) {{\n\t\t$2\n\t}}\n\tothers {{\n\t\t$0\n\t}}\n]]",
                ty(1)
            ),
        },
        Snippet {
            label: "[[ leader ]]",
            detail: "one robot, elected among those meeting the condition",
            body: format!("[[\n\tleader(instance of {}) {{\n\t\t$0\n\t}}\n]]", ty(1)),
        },
    ]
}

/// Snippets for an arm inside `[[ ... ]]`.
pub fn arm_snippets(types: &[&str], first: bool, leader: bool) -> Vec<Snippet> {
    let mut out = Vec::new();
    if first || !leader {
        out.push(Snippet {
            label: "group",
            detail: "group(instance of Type) { ... }",
            body: format!(
                "group(instance of {}) {{\n\t$0\n}}",
                choice(1, types, "RobotType")
            ),
        });
    }
    if first {
        out.push(Snippet {
            label: "leader",
            detail: "leader(instance of Type) { ... }: one elected robot",
            body: format!(
                "leader(instance of {}) {{\n\t$0\n}}",
                choice(1, types, "RobotType")
            ),
        });
    } else {
        out.push(Snippet {
            label: "others",
            detail: "others { ... }: the robots of no group above",
            body: "others {\n\t$0\n}".to_string(),
        });
    }
    out
}

/// `set(Plan, Service)` in a mode; `plans` fill the choice.
pub fn set_snippet(plans: &[&str]) -> Snippet {
    Snippet {
        label: "set",
        detail: "set(Plan, Service or OFF): what a plan runs in this mode",
        body: format!("set({}, ${{2:Service}})", choice(1, plans, "Plan")),
    }
}

/// The lines of a main block.
pub fn main_snippets(in_case: bool, has_default: bool) -> Vec<Snippet> {
    let mut out = Vec::new();
    if in_case {
        out.push(Snippet {
            label: "catch",
            detail: "catch (event): mode = MODE",
            body: "catch (${1:event}): mode = ${2:MODE}".to_string(),
        });
    }
    out.push(Snippet {
        label: "case",
        detail: "case (MODE): what events change the mode",
        body: "case (${1:MODE}):\n\tcatch (${2:event}): mode = ${3:OTHER_MODE}".to_string(),
    });
    if !has_default {
        out.push(Snippet {
            label: "default",
            detail: "default: mode = MODE: the mode the team starts in",
            body: "default: mode = ${1:MODE}".to_string(),
        });
    }
    out
}

/// The snippet as the plain text it stands for: placeholders keep their
/// default text (a choice its first option), tab stops vanish, `\t` is two
/// spaces.
pub fn to_plain(snippet: &str) -> String {
    let chars: Vec<char> = snippet.chars().collect();
    let mut out = String::with_capacity(snippet.len());
    plain_into(&chars, &mut 0, &mut out, false);
    out
}

/// Copies `chars[*i..]` as plain text until the end, or (when `nested`) until
/// the `}` closing the current placeholder.
fn plain_into(chars: &[char], i: &mut usize, out: &mut String, nested: bool) {
    while let Some(&c) = chars.get(*i) {
        match c {
            '\\' => {
                if let Some(&next) = chars.get(*i + 1) {
                    out.push(next);
                }
                *i += 2;
            }
            '}' if nested => {
                *i += 1;
                return;
            }
            '\t' => {
                out.push_str("  ");
                *i += 1;
            }
            '$' => {
                *i += 1;
                match chars.get(*i) {
                    Some(d) if d.is_ascii_digit() => {
                        while chars.get(*i).is_some_and(|d| d.is_ascii_digit()) {
                            *i += 1;
                        }
                    }
                    Some('{') => {
                        *i += 1;
                        while chars.get(*i).is_some_and(|d| d.is_ascii_digit()) {
                            *i += 1;
                        }
                        match chars.get(*i) {
                            Some(':') => {
                                *i += 1;
                                plain_into(chars, i, out, true);
                            }
                            Some('|') => {
                                *i += 1;
                                choice_into(chars, i, out);
                            }
                            Some('}') => *i += 1,
                            _ => {}
                        }
                    }
                    _ => out.push('$'),
                }
            }
            c => {
                out.push(c);
                *i += 1;
            }
        }
    }
}

/// Copies the first option of a choice and skips the rest, up to its `|}`.
fn choice_into(chars: &[char], i: &mut usize, out: &mut String) {
    let mut first = true;
    while let Some(&c) = chars.get(*i) {
        match c {
            '\\' => {
                if first && let Some(&next) = chars.get(*i + 1) {
                    out.push(next);
                }
                *i += 2;
            }
            ',' => {
                first = false;
                *i += 1;
            }
            '|' => {
                *i += 1;
                if chars.get(*i) == Some(&'}') {
                    *i += 1;
                }
                return;
            }
            c => {
                if first {
                    out.push(c);
                }
                *i += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_text_keeps_defaults_and_first_choices() {
        assert_eq!(
            to_plain("set(${1|Listen,Action|}, ${2:Service})$0"),
            "set(Listen, Service)"
        );
        assert_eq!(
            to_plain("if (${1:a \\} b}) {\n\t$0\n}"),
            "if (a } b) {\n  \n}"
        );
        assert_eq!(to_plain("move(${1})"), "move()");
        assert_eq!(to_plain("a $ b"), "a $ b");
    }

    #[test]
    fn the_template_is_the_spec_skeleton() {
        assert_eq!(
            to_plain(&mission_template().body),
            MISSION_TEMPLATE.replacen("{\n}", "{\n  \n}", 1)
        );
        assert_eq!(choice(1, &["a,b", "c"], "x"), "${1|a\\,b,c|}");
        assert_eq!(choice(1, &[], "x$"), "${1:x\\$}");
    }
}
