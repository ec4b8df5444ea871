//! Comparisons that decide the same way at every run. A team variable
//! holds only what its writers put in it: when every writer puts a literal
//! (a word, a string, a number), its possible values are known, and a
//! comparison with a constant outside them decides the same way at every
//! run: `T.X == C` never holds (W020), `T.X != C` holds whenever `T.X` has
//! a value (W021: a comparison with a variable not yet set is false, `!=`
//! too). Both name the writers as related information.
//!
//! A variable with any writer whose value is not a literal (a sensor
//! reading, another variable), or that the operator may send, has unknown
//! values and is never reported.
//!
//! A parameter of a function, a composite service or a mode stands for
//! its argument, which the mission writes: when every argument reaching it
//! is a literal ([`super::arguments`], following a mode's or a function's
//! parameter passed on), `PARAM == C` with a constant none of them gives
//! never holds (W020) and `PARAM != C` always holds (W021: a parameter
//! always has its argument). Both name the arguments as related
//! information. A parameter any argument of which is read at run time, or
//! that nothing gives an argument, is never reported.

use super::arguments::Values;
use super::literal::Literal;
use super::{RELATED, VariableWrite, list};
use crate::diag::{Code, Sink};
use crate::fasthash::{FastMap, FastSet};
use crate::sema::Checker;
use crate::sema::ir::{AttrKey, Compared, ParamOwner};
use crate::sema::suggestion;
use crate::span::Span;
use crate::syntax::ast::Name;

/// A comparison of a team variable with a literal: `T.X == C` (`equal`) or
/// `T.X != C`.
#[derive(Clone, Debug)]
pub(in crate::sema) struct VariableTest {
    pub key: AttrKey,
    pub equal: bool,
    pub constant: Literal,
    pub compared: Compared,
    /// The constant's range (a did-you-mean replaces it).
    pub span: Span,
}

/// A comparison of a parameter with a literal: `PARAM == C` (`equal`) or
/// `PARAM != C`.
#[derive(Clone, Debug)]
pub(in crate::sema) struct ParameterTest {
    pub param: (ParamOwner, u32),
    pub name: Name,
    pub equal: bool,
    pub constant: Literal,
    pub compared: Compared,
    /// The constant's range (a did-you-mean replaces it).
    pub span: Span,
}

impl Checker<'_> {
    pub(super) fn check_comparisons(&mut self) {
        self.check_variable_comparisons();
        self.check_parameter_comparisons();
    }

    /// W020, W021 for parameters: see the module's documentation.
    fn check_parameter_comparisons(&mut self) {
        let Some(mut given) = self.given.take() else {
            return;
        };
        let tests = std::mem::take(&mut self.parameter_tests);
        // A body walked for several sets of robots records its tests once
        // per walk.
        let mut seen: FastSet<(Span, bool)> = FastSet::default();
        for test in &tests {
            if !seen.insert((test.span, test.equal)) {
                continue;
            }
            let Values::Known {
                values,
                given: arguments,
            } = given.values(test.param)
            else {
                continue; // some argument is not known when the mission is written
            };
            if values.is_empty()
                || !values.iter().all(|v| v.compared_as(test.compared))
                || values.contains(&test.constant)
            {
                continue;
            }
            let name = &test.name;
            let owner = self.mission.owner_name(test.param.0);
            let related = arguments
                .iter()
                .map(|(span, literal)| {
                    (
                        *span,
                        format!("`{name}` is given `{}` here", literal.text()),
                    )
                })
                .collect();
            report_undecided(
                &mut self.diagnostics,
                Undecided {
                    span: test.span,
                    equal: test.equal,
                    subject: name.to_string(),
                    constant: &test.constant,
                    always: "always holds",
                },
                values.iter(),
                |possible, constant| {
                    format!(
                        "the parameter `{name}` of `{owner}` is only ever given {possible}, never `{constant}`"
                    )
                },
                related,
            );
        }
    }

    fn check_variable_comparisons(&mut self) {
        let mut writes: FastMap<&AttrKey, Vec<&VariableWrite>> = FastMap::default();
        for write in &self.variable_writes {
            writes.entry(&write.key).or_default().push(write);
        }
        let mut findings = Vec::new();
        for test in &self.variable_tests {
            let Some(writers) = writes.get(&test.key) else {
                continue; // never written: W004 says so where it is received
            };
            let Some(values) = writers
                .iter()
                .map(|w| w.value.as_ref())
                .collect::<Option<Vec<&Literal>>>()
            else {
                continue; // some writer's value is unknown
            };
            if !values.iter().all(|v| v.compared_as(test.compared)) {
                continue; // the comparison reads another kind: no exact answer here
            }
            if values.contains(&&test.constant) {
                continue;
            }
            findings.push((test, writers.clone(), values));
        }
        for (test, writers, values) in findings {
            let key = &test.key;
            let related = writers
                .iter()
                .zip(&values)
                .map(|(w, v)| (w.span, format!("`{key}` is set to `{}` here", v.text())))
                .collect();
            report_undecided(
                &mut self.diagnostics,
                Undecided {
                    span: test.span,
                    equal: test.equal,
                    subject: key.to_string(),
                    constant: &test.constant,
                    always: "holds whenever it has a value",
                },
                values.iter().copied(),
                |possible, constant| {
                    format!("`{key}` is only ever set to {possible}, never to `{constant}`")
                },
                related,
            );
        }
    }
}

/// W020 (`==`) or W021 (`!=`) on a comparison of `subject` with a
/// constant none of `values` equals: the message says what it is
/// compared with (`why`: the values listed, the constant), suggests the
/// closest value, and points at where the values come from (`related`,
/// in the file's order, the first [`RELATED`]).
fn report_undecided<'v>(
    diagnostics: &mut Sink,
    test: Undecided<'_>,
    values: impl Iterator<Item = &'v Literal>,
    why: impl FnOnce(&str, &str) -> String,
    mut related: Vec<(Span, String)>,
) {
    let mut possible: Vec<String> = values.map(Literal::text).collect();
    possible.sort();
    possible.dedup();
    let constant = test.constant.text();
    let subject = &test.subject;
    let (code, op, verdict) = if test.equal {
        (Code::ComparisonNeverHolds, "==", "never holds")
    } else {
        (Code::ComparisonAlwaysHolds, "!=", test.always)
    };
    let guess = suggestion(&constant, possible.iter().map(String::as_str));
    let why = why(&list(&possible), &constant);
    let diagnostic = diagnostics
        .report(
            code,
            test.span,
            format!("`{subject} {op} {constant}` {verdict}: {why}"),
        )
        .suggest(guess);
    related.sort_by_key(|(span, _)| span.start);
    related.dedup_by_key(|(span, _)| *span);
    for (span, message) in related.into_iter().take(RELATED) {
        diagnostic.relate(span, message);
    }
}

/// A comparison W020/W021 reports ([`report_undecided`]).
struct Undecided<'a> {
    span: Span,
    equal: bool,
    /// The variable or parameter compared, as written in the message.
    subject: String,
    constant: &'a Literal,
    /// W021's verdict: a parameter always has its argument, a variable
    /// only once it is set.
    always: &'a str,
}

#[cfg(test)]
mod tests {
    use crate::diag::Code;

    /// The value-flow codes of a mission where `S` sets `S.V` with `sends`
    /// and `G` tests it with `test` (the condition of an `if`).
    fn findings(sends: &str, test: &str) -> Vec<(Code, String)> {
        let text = format!(
            "{{\n  G: iRobotCreate irobot\n  S: TIEvalbot ti\n}}\n\
             S.Report.Tell{{\n{sends}\n}} repeat(1 SEC)\n\
             G.Listen.Hear{{\n  receive(S, S.V)\n  if ({test}) throw stop\n}} repeat(1 SEC)\n\
             G.WATCH{{ set(Listen, Hear) }}\nG.DONE{{ set(Listen, OFF) }}\n\
             G.main{{\n  case (WATCH):\n    catch (stop): mode = DONE\n  default: mode = WATCH\n}}\n\
             S.TELL{{ set(Report, Tell) }}\nS.main{{ default: mode = TELL }}\n"
        );
        let codes = [Code::ComparisonNeverHolds, Code::ComparisonAlwaysHolds];
        super::super::tests::diagnostics_with(&text, &codes)
            .iter()
            .map(|d| (d.code, text[d.span.start..d.span.end].to_string()))
            .collect()
    }

    const HIDE_OR_FINISH: &str =
        "  send(G, S.V = SUGGEST_HIDE)\n  send(G, S.V = \"SUGGEST_FINISH\")";

    #[test]
    fn a_constant_no_writer_sets_never_equals_and_always_differs() {
        assert_eq!(
            findings(HIDE_OR_FINISH, "S.V == CMD_HIDE"),
            [(Code::ComparisonNeverHolds, "CMD_HIDE".to_string())]
        );
        assert_eq!(
            findings(HIDE_OR_FINISH, "CMD_HIDE == S.V"),
            [(Code::ComparisonNeverHolds, "CMD_HIDE".to_string())]
        );
        assert_eq!(
            findings(HIDE_OR_FINISH, "S.V != \"STAY\""),
            [(Code::ComparisonAlwaysHolds, "\"STAY\"".to_string())]
        );
    }

    #[test]
    fn a_constant_some_writer_sets_is_not_reported() {
        // A word and a string with the same text are equal as words.
        assert!(findings(HIDE_OR_FINISH, "S.V == SUGGEST_FINISH").is_empty());
        assert!(findings(HIDE_OR_FINISH, "S.V != \"SUGGEST_HIDE\"").is_empty());
    }

    #[test]
    fn numbers_compare_by_value() {
        let sends = "  send(G, S.V = 5)";
        assert!(findings(sends, "S.V == 5.0").is_empty());
        assert_eq!(
            findings(sends, "S.V == 6"),
            [(Code::ComparisonNeverHolds, "6".to_string())]
        );
    }

    /// The W020/W021 findings of a mission where the mode `MOVE(TARGET)`
    /// sets `Go(TARGET)`, `Go(PLACE)` tests `test` and passes `PLACE` to
    /// `def look(AREA)`; `entries` enters the modes: (code, the constant,
    /// the related places' texts). Errors are allowed.
    fn parameter_findings(test: &str, entries: &str) -> Vec<(Code, String, Vec<String>)> {
        let text = format!(
            "{{ R: TIEvalbot ti }}\n\
             def look(AREA) {{\n  if (AREA != attic) standby()\n}}\n\
             R.Action.Go(PLACE) {{\n  move(PLACE)\n  look(PLACE)\n  if ({test}) throw arrived\n}} repeat(1 SEC)\n\
             R.MOVE(TARGET) {{ set(Action, Go(TARGET)) }}\n\
             R.DOOR {{ set(Action, Go(door)) }}\n\
             R.main {{\n  case (MOVE):\n    catch (arrived): mode = DOOR\n{entries}\n}}\n"
        );
        let analysis = crate::check_source(
            crate::diag::FileId(0),
            &text,
            &crate::catalog::builtin_catalog(),
        );
        let at = |span: crate::span::Span| text[span.start..span.end].to_string();
        analysis
            .diagnostics
            .iter()
            .filter(|d| [Code::ComparisonNeverHolds, Code::ComparisonAlwaysHolds].contains(&d.code))
            .map(|d| {
                (
                    d.code,
                    at(d.span),
                    d.related.iter().map(|r| at(r.span)).collect(),
                )
            })
            .collect()
    }

    #[test]
    fn a_parameter_compared_with_a_constant_no_argument_gives() {
        // PLACE is given kitchen (through MOVE's TARGET) and door; AREA
        // what PLACE is given.
        let found = parameter_findings("PLACE == hall", "  default: mode = MOVE(kitchen)");
        assert_eq!(
            found,
            [
                (
                    Code::ComparisonAlwaysHolds,
                    "attic".to_string(),
                    vec!["door".to_string(), "kitchen".to_string()]
                ),
                (
                    Code::ComparisonNeverHolds,
                    "hall".to_string(),
                    vec!["door".to_string(), "kitchen".to_string()]
                ),
            ]
        );
        let found = parameter_findings("\"hall\" != PLACE", "  default: mode = MOVE(kitchen)");
        assert_eq!(found[1].0, Code::ComparisonAlwaysHolds);
        assert_eq!(found[1].1, "\"hall\"");
    }

    #[test]
    fn a_parameter_some_argument_gives_the_constant_is_not_reported() {
        // A word and a string with the same text are equal as words.
        let found = parameter_findings("PLACE == \"door\"", "  default: mode = MOVE(kitchen)");
        assert_eq!(found.len(), 1, "{found:?}"); // AREA != attic only
        let found = parameter_findings("PLACE == hall", "  default: mode = MOVE(hall)");
        assert_eq!(found.len(), 1, "{found:?}");
    }

    #[test]
    fn a_parameter_given_anything_read_at_run_time_is_not_reported() {
        // MOVE is entered with a word elsewhere, but look is also given the
        // robot's location.
        let text = "{ R: TIEvalbot ti }\n\
             def look(AREA) {\n  if (AREA == attic) standby()\n}\n\
             R.Action.Look {\n  look(cellar)\n  look(R.LOCATION)\n} repeat(1 SEC)\n\
             R.LOOK { set(Action, Look) }\nR.main { default: mode = LOOK }\n";
        let codes = [Code::ComparisonNeverHolds, Code::ComparisonAlwaysHolds];
        assert!(super::super::tests::diagnostics_with(text, &codes).is_empty());
        let without = text.replace("  look(R.LOCATION)\n", "");
        assert_eq!(
            super::super::tests::diagnostics_with(&without, &codes).len(),
            1
        );
    }

    #[test]
    fn a_mode_entered_with_the_wrong_count_makes_its_parameters_unknown() {
        // MOVE(hall, 2) is E046: what it would give TARGET is not known.
        let found = parameter_findings(
            "PLACE == hall",
            "  case (DOOR):\n    catch (arrived): mode = MOVE(hall, 2)\n  default: mode = MOVE(kitchen)",
        );
        assert!(found.is_empty(), "{found:?}");
    }

    #[test]
    fn a_parameter_compared_as_a_number_compares_its_arguments_by_value() {
        let text = "{ R: TIEvalbot ti }\n\
             def wait(N) {\n  if (N == 2) standby()\n  if (N == 3) standby()\n}\n\
             R.Action.Wait {\n  wait(2.0)\n} repeat(1 SEC)\n\
             R.WAIT { set(Action, Wait) }\nR.main { default: mode = WAIT }\n";
        let codes = [Code::ComparisonNeverHolds, Code::ComparisonAlwaysHolds];
        let found = super::super::tests::diagnostics_with(text, &codes);
        let spans: Vec<&str> = found
            .iter()
            .map(|d| &text[d.span.start..d.span.end])
            .collect();
        assert_eq!(spans, ["3"]);
    }

    #[test]
    fn a_variable_any_writer_sets_from_a_reading_may_hold_anything() {
        let sends = "  send(G, S.V = SUGGEST_HIDE)\n  send(G, S.V = S.LOCATION)";
        assert!(findings(sends, "S.V == CMD_HIDE").is_empty());
    }
}
