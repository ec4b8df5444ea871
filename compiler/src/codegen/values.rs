//! Typed values in the generated C: the program's word table and literals
//! (`semo_value`, `semo_runtime.h`). Words are indices into one table per
//! program, `words[]` in `main.c`, sorted; the runtime writes and sends their
//! text, so tables of different robots need not agree.

use super::c;
use crate::refine::{Expr, Operand, RobotProgram, StateKind, Value, ValueKind};
use crate::sema::Compared;
use crate::syntax::ast::CmpOp;
use std::cell::RefCell;
use std::collections::BTreeSet;

/// The words a program uses: its word literals and the domains of its
/// enumerated values, sorted. A word asked for that the table lacks is
/// recorded (`missing`): generation then refuses the program with an
/// internal error (E102) instead of writing another word's index.
pub struct Words {
    list: Vec<String>,
    missing: RefCell<BTreeSet<String>>,
}

impl Words {
    /// A condition's operand in C: a pointer to its slot or a literal.
    pub fn operand(&self, op: &Operand) -> String {
        match op {
            Operand::Slot(s) => format!("&slot[{s}]"),
            Operand::Literal(value) => self.literal(value),
        }
    }

    /// A refined condition in C (the control task's branches and loops,
    /// the battery policies').
    pub fn condition(&self, e: &Expr) -> String {
        match e {
            Expr::Or(a, b) => format!("({} || {})", self.condition(a), self.condition(b)),
            Expr::And(a, b) => format!("({} && {})", self.condition(a), self.condition(b)),
            Expr::Not(a) => format!("!{}", self.condition(a)),
            Expr::Bool(b) => b.to_string(),
            Expr::Truthy(o) => format!("semo_value_truthy({})", self.operand(o)),
            // As the checker typed the comparison: the runtime never guesses
            // from the values whether they are numbers.
            Expr::Compare(a, op, b, compared) => {
                let function = match compared {
                    Compared::Numbers => "semo_value_numbers",
                    Compared::Words => "semo_value_words",
                };
                let op = match op {
                    CmpOp::Eq => "SEMO_EQ",
                    CmpOp::Ne => "SEMO_NE",
                    CmpOp::Lt => "SEMO_LT",
                    CmpOp::Le => "SEMO_LE",
                    CmpOp::Gt => "SEMO_GT",
                    CmpOp::Ge => "SEMO_GE",
                };
                format!("{function}({}, {op}, {})", self.operand(a), self.operand(b))
            }
        }
    }

    pub fn of(program: &RobotProgram) -> Words {
        let mut words = BTreeSet::new();
        for slot in &program.control.slots {
            if let ValueKind::Word(domain) = &slot.kind {
                words.extend(domain.iter().cloned());
            }
        }
        each_literal(program, &mut |v| {
            if let Value::Word(w) = v {
                words.insert(w.to_string());
            }
        });
        Words {
            list: words.into_iter().collect(),
            missing: RefCell::new(BTreeSet::new()),
        }
    }

    pub fn list(&self) -> &[String] {
        &self.list
    }

    /// The index of `word` in the table. `of` collects every word the
    /// program holds, so a miss is a generator bug: it is recorded for
    /// [`Words::missing`] and the index returned is past the table's end
    /// (the program is refused, never written with it).
    pub(super) fn index(&self, word: &str) -> usize {
        self.list
            .binary_search_by(|w| w.as_str().cmp(word))
            .unwrap_or_else(|_| {
                self.missing.borrow_mut().insert(word.to_string());
                self.list.len()
            })
    }

    /// The words asked for that the table lacks, sorted.
    pub fn missing(&self) -> Vec<String> {
        self.missing.borrow().iter().cloned().collect()
    }

    /// A literal as a `const semo_value *` expression.
    pub fn literal(&self, value: &Value) -> String {
        match value {
            Value::Int(i) if *i == i64::MIN => "SEMO_LIT_INT(INT64_MIN)".into(),
            Value::Int(i) => format!("SEMO_LIT_INT({i})"),
            Value::Real(r) if r.is_infinite() => format!(
                "SEMO_LIT_REAL({}__builtin_inf())",
                if *r < 0.0 { "-" } else { "" }
            ),
            // `{:e}` writes the shortest digits that read back exactly.
            Value::Real(r) => format!("SEMO_LIT_REAL({r:e})"),
            Value::Bool(b) => format!("SEMO_LIT_BOOL({b})"),
            Value::Word(w) => format!("SEMO_LIT_WORD({}) /* {} */", self.index(w), c::comment(w)),
            Value::Text(t) => format!("SEMO_LIT({})", c::string(t)),
        }
    }
}

/// Whether the program holds a real anywhere: a slot the catalog declares
/// `float`, or a real literal. Without one the static targets build with
/// `-DSEMO_NO_REALS` (no soft float linked). A team variable holds only what
/// the program assigns or receives; on the static targets it receives only
/// the operator's text.
pub fn uses_reals(program: &RobotProgram) -> bool {
    let mut reals = program
        .control
        .slots
        .iter()
        .any(|s| s.kind == ValueKind::Real);
    each_literal(program, &mut |v| reals |= matches!(v, Value::Real(_)));
    reals
}

/// Every literal of the program's machine.
fn each_literal(program: &RobotProgram, f: &mut dyn FnMut(&Value)) {
    let m = &program.control;
    let mut add = |op: &Operand| {
        if let Operand::Literal(v) = op {
            f(v);
        }
    };
    for state in m.services.iter().flat_map(|s| &s.states) {
        match &state.kind {
            StateKind::Send { items } => items.iter().for_each(|i| add(&i.value)),
            StateKind::Call { args, .. } | StateKind::RunActions { args, .. } => {
                args.iter().for_each(&mut add)
            }
            StateKind::Branch { condition, .. } => condition.for_each_operand(&mut add),
            StateKind::LoopHead {
                condition: Some(c), ..
            }
            | StateKind::Repeat {
                condition: Some(c), ..
            } => c.for_each_operand(&mut add),
            _ => {}
        }
    }
    for policy in &m.battery {
        policy.condition.for_each_operand(&mut add);
    }
    for action in m.actions.iter().flat_map(|a| &a.actions) {
        for (_, command) in &action.commands {
            add(command);
        }
        for (condition, _) in action.transitions.iter() {
            if let Some(c) = condition {
                c.for_each_operand(&mut add);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(words: &[&str]) -> Words {
        Words {
            list: words.iter().map(|w| w.to_string()).collect(),
            missing: RefCell::new(BTreeSet::new()),
        }
    }

    #[test]
    fn a_word_in_the_table_is_its_index_and_nothing_is_missing() {
        let words = table(&["east", "north", "west"]);
        assert_eq!(words.index("north"), 1);
        assert_eq!(
            words.literal(&Value::Word("west".into())),
            "SEMO_LIT_WORD(2) /* west */"
        );
        assert!(words.missing().is_empty());
    }

    /// A word the table lacks is never another word's index (word 0 was
    /// the old fallback): it is recorded, and generation refuses (E102).
    #[test]
    fn a_word_the_table_lacks_is_recorded_as_missing_not_word_zero() {
        let words = table(&["east", "north"]);
        let index = words.index("south");
        assert!(index >= words.list().len(), "{index}");
        words.literal(&Value::Word("up".into()));
        assert_eq!(words.missing(), vec!["south".to_string(), "up".to_string()]);
    }
}
