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

use super::{RELATED, VariableWrite, list};
use crate::diag::Code;
use crate::fasthash::FastMap;
use crate::sema::Checker;
use crate::sema::ir::{AttrKey, Compared};
use crate::sema::suggestion;
use crate::span::Span;

/// A literal as a comparison reads it: words and strings by their text,
/// numbers by their value.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::sema) enum Literal {
    Word(String),
    Number(f64),
}

impl Literal {
    /// What the comparison compares, if this literal is of its kind.
    fn compared_as(&self, compared: Compared) -> bool {
        matches!(
            (self, compared),
            (Literal::Word(_), Compared::Words) | (Literal::Number(_), Compared::Numbers)
        )
    }

    fn text(&self) -> String {
        match self {
            Literal::Word(w) => w.clone(),
            Literal::Number(n) => n.to_string(),
        }
    }
}

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

impl Checker<'_> {
    pub(super) fn check_comparisons(&mut self) {
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
            let mut possible: Vec<String> = values.iter().map(|v| v.text()).collect();
            possible.sort();
            possible.dedup();
            let constant = test.constant.text();
            let key = &test.key;
            let (code, op, verdict) = if test.equal {
                (Code::ComparisonNeverHolds, "==", "never holds")
            } else {
                (
                    Code::ComparisonAlwaysHolds,
                    "!=",
                    "holds whenever it has a value",
                )
            };
            let guess = suggestion(&constant, possible.iter().map(String::as_str));
            let diagnostic = self
                .diagnostics
                .report(
                    code,
                    test.span,
                    format!(
                        "`{key} {op} {constant}` {verdict}: `{key}` is only ever set to {}, never to `{constant}`",
                        list(&possible)
                    ),
                )
                .suggest(guess);
            let mut related: Vec<(Span, String)> = writers
                .iter()
                .zip(&values)
                .map(|(w, v)| (w.span, format!("`{key}` is set to `{}` here", v.text())))
                .collect();
            related.sort_by_key(|(span, _)| span.start);
            related.dedup_by_key(|(span, _)| *span);
            for (span, message) in related.into_iter().take(RELATED) {
                diagnostic.relate(span, message);
            }
        }
    }
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

    #[test]
    fn a_variable_any_writer_sets_from_a_reading_may_hold_anything() {
        let sends = "  send(G, S.V = SUGGEST_HIDE)\n  send(G, S.V = S.LOCATION)";
        assert!(findings(sends, "S.V == CMD_HIDE").is_empty());
    }
}
