//! What a value can hold, as the mission says it: the literals it is
//! compared with (`COLOR == "RGB"`, `T.Mode != HIDING`) and, for a team
//! variable, the literals it is set to (`send(T, T.Mode = HIDING)`). Read
//! from the syntax tree, each name matched by the symbol the checker
//! recorded for it, so `SlaveTeam.COLOR` in one service and `COLOR` in a
//! service of `SlaveTeam` are the same value. Completion offers these after
//! `==` and `!=`.

use crate::sema::{CheckedMission, Symbol, lookup};
use crate::syntax::ast::{self, CmpOp, Expr, ExprKind, Item, StmtKind};

/// A literal written with a value in the mission.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Constant {
    /// As written: `"RGB"`, `HIDING`, `3`, `true`.
    pub text: String,
    /// `compared` or `set`: how the mission uses it with the value first.
    pub how: &'static str,
}

/// The literals written with `value` in the mission, each once (by its
/// text), in the order they first appear.
pub(crate) fn constants_of(analysis: &CheckedMission, text: &str, value: &Symbol) -> Vec<Constant> {
    let mut found = Finder {
        analysis,
        text,
        value,
        out: Vec::new(),
    };
    for item in &analysis.syntax.items {
        let body = match item {
            Item::Service(s) => {
                if let Some(condition) = s.repeat.as_ref().and_then(|r| r.condition.as_ref()) {
                    found.expr(condition);
                }
                &s.body
            }
            Item::Function(f) => &f.body,
            _ => continue,
        };
        body.walk(&mut |stmt| found.stmt(stmt));
    }
    found.out
}

struct Finder<'a> {
    analysis: &'a CheckedMission,
    text: &'a str,
    value: &'a Symbol,
    out: Vec<Constant>,
}

impl Finder<'_> {
    fn stmt(&mut self, stmt: &ast::Stmt) {
        match &stmt.kind {
            StmtKind::If(i) => self.expr(&i.condition),
            StmtKind::Loop(l) => {
                if let Some(c) = &l.condition {
                    self.expr(c);
                }
            }
            StmtKind::Comm(comm) => {
                for item in &comm.items {
                    let Some(value) = &item.value else { continue };
                    if self.is_the_value(&item.attr) {
                        self.literal(value, "set");
                    }
                    self.expr(value);
                }
            }
            StmtKind::Call(call) => {
                for arg in &call.args {
                    if let ast::Arg::Expr(e) = arg {
                        self.expr(e);
                    }
                }
            }
            StmtKind::Group(_) | StmtKind::Throw(_) | StmtKind::Error => {}
        }
    }

    /// Every `==` and `!=` comparison inside `e`.
    fn expr(&mut self, e: &Expr) {
        match &e.kind {
            ExprKind::Or(a, b) | ExprKind::And(a, b) => {
                self.expr(a);
                self.expr(b);
            }
            ExprKind::Not(a) => self.expr(a),
            ExprKind::Compare(lhs, CmpOp::Eq | CmpOp::Ne, rhs) => {
                for (side, other) in [(lhs, rhs), (rhs, lhs)] {
                    if let ExprKind::Attr(attr) = &side.kind
                        && self.is_the_value(attr)
                    {
                        self.literal(other, "compared");
                    }
                }
            }
            _ => {}
        }
    }

    /// Whether the checker took `attr` for the value looked for.
    fn is_the_value(&self, attr: &ast::Attr) -> bool {
        let Some(last) = attr.segments.last() else {
            return false;
        };
        lookup::with_span(&self.analysis.mission, last.span)
            .iter()
            .any(|o| o.symbol == *self.value)
    }

    /// Keeps `e` if it is a literal: a string, a number, `true` or `false`,
    /// or a name the checker took for a word.
    fn literal(&mut self, e: &Expr, how: &'static str) {
        let literal = match &e.kind {
            ExprKind::Str(_) | ExprKind::Number(_) | ExprKind::Bool(_) => true,
            ExprKind::Attr(attr) => attr.segments.last().is_some_and(|last| {
                lookup::with_span(&self.analysis.mission, last.span)
                    .iter()
                    .any(|o| matches!(o.symbol, Symbol::Constant(_)))
            }),
            _ => false,
        };
        let Some(written) = self.text.get(e.span.range()) else {
            return;
        };
        if literal && !self.out.iter().any(|c| c.text == written) {
            self.out.push(Constant {
                text: written.to_string(),
                how,
            });
        }
    }
}
