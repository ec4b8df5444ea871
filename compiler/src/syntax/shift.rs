//! Moving parsed text: every position in a syntax tree (and in the syntax
//! diagnostics about it) shifted by the same number of bytes, for a chunk
//! whose text moved because something before it was edited.
//!
//! Every node is destructured completely, without `..`: a field added to the
//! tree does not compile until it is shifted here too.

use super::ast::*;
use crate::diag::{Diagnostic, Related};
use crate::span::Span;

/// A value holding byte positions that can be moved by `delta` bytes.
pub(crate) trait Shift {
    fn shift(&mut self, delta: isize);
}

impl Shift for Span {
    fn shift(&mut self, delta: isize) {
        *self = self.shifted(delta);
    }
}

impl<T: Shift> Shift for Vec<T> {
    fn shift(&mut self, delta: isize) {
        for x in self {
            x.shift(delta);
        }
    }
}

impl<T: Shift> Shift for Option<T> {
    fn shift(&mut self, delta: isize) {
        if let Some(x) = self {
            x.shift(delta);
        }
    }
}

impl<T: Shift> Shift for Box<T> {
    fn shift(&mut self, delta: isize) {
        (**self).shift(delta);
    }
}

impl Shift for Diagnostic {
    fn shift(&mut self, delta: isize) {
        let Diagnostic {
            code: _,
            severity: _,
            file: _,
            span,
            message: _,
            suggestion: _,
            related,
        } = self;
        span.shift(delta);
        related.shift(delta);
    }
}

impl Shift for Related {
    fn shift(&mut self, delta: isize) {
        let Related {
            file: _,
            span,
            message: _,
        } = self;
        span.shift(delta);
    }
}

impl Shift for Ident {
    fn shift(&mut self, delta: isize) {
        let Ident { name: _, span } = self;
        span.shift(delta);
    }
}

impl Shift for Item {
    fn shift(&mut self, delta: isize) {
        match self {
            Item::Formation(f) => f.shift(delta),
            Item::Service(s) => s.shift(delta),
            Item::Function(f) => f.shift(delta),
            Item::Mode(m) => m.shift(delta),
            Item::Main(m) => m.shift(delta),
            Item::Error(span) => span.shift(delta),
        }
    }
}

impl Shift for Formation {
    fn shift(&mut self, delta: isize) {
        let Formation {
            teams,
            braced: _,
            span,
        } = self;
        teams.shift(delta);
        span.shift(delta);
    }
}

impl Shift for TeamDecl {
    fn shift(&mut self, delta: isize) {
        let TeamDecl { name, robots, span } = self;
        name.shift(delta);
        robots.shift(delta);
        span.shift(delta);
    }
}

impl Shift for RobotDecl {
    fn shift(&mut self, delta: isize) {
        let RobotDecl {
            robot_type,
            name,
            count,
            span,
        } = self;
        robot_type.shift(delta);
        name.shift(delta);
        count.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Count {
    fn shift(&mut self, delta: isize) {
        let Count { value: _, span } = self;
        span.shift(delta);
    }
}

impl Shift for CompositeService {
    fn shift(&mut self, delta: isize) {
        let CompositeService {
            team,
            more_teams,
            plan,
            name,
            params,
            params_span,
            body,
            repeat,
            span,
        } = self;
        team.shift(delta);
        for more in more_teams {
            more.shift(delta);
        }
        plan.shift(delta);
        name.shift(delta);
        params.shift(delta);
        params_span.shift(delta);
        body.shift(delta);
        repeat.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Repeat {
    fn shift(&mut self, delta: isize) {
        let Repeat {
            period,
            condition,
            span,
        } = self;
        period.shift(delta);
        condition.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Function {
    fn shift(&mut self, delta: isize) {
        let Function {
            name,
            params,
            params_span,
            body,
            span,
        } = self;
        name.shift(delta);
        for param in params {
            param.shift(delta);
        }
        params_span.shift(delta);
        body.shift(delta);
        span.shift(delta);
    }
}

impl Shift for ModeDef {
    fn shift(&mut self, delta: isize) {
        let ModeDef {
            team,
            name,
            params,
            params_span,
            sets,
            span,
        } = self;
        team.shift(delta);
        name.shift(delta);
        params.shift(delta);
        params_span.shift(delta);
        sets.shift(delta);
        span.shift(delta);
    }
}

impl Shift for SetStmt {
    fn shift(&mut self, delta: isize) {
        let SetStmt {
            plan,
            service,
            args,
            timeout,
            span,
        } = self;
        plan.shift(delta);
        service.shift(delta);
        args.shift(delta);
        timeout.shift(delta);
        span.shift(delta);
    }
}

impl Shift for ArgList {
    fn shift(&mut self, delta: isize) {
        let ArgList { args, span } = self;
        args.shift(delta);
        span.shift(delta);
    }
}

impl Shift for SetTarget {
    fn shift(&mut self, delta: isize) {
        match self {
            SetTarget::Service(name) => name.shift(delta),
            SetTarget::Off(span) => span.shift(delta),
        }
    }
}

impl Shift for MainDef {
    fn shift(&mut self, delta: isize) {
        let MainDef {
            team,
            main_span,
            cases,
            default,
            default_args,
            span,
        } = self;
        team.shift(delta);
        main_span.shift(delta);
        cases.shift(delta);
        default.shift(delta);
        default_args.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Case {
    fn shift(&mut self, delta: isize) {
        let Case {
            mode,
            catches,
            span,
        } = self;
        mode.shift(delta);
        catches.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Catch {
    fn shift(&mut self, delta: isize) {
        let Catch {
            event,
            target,
            target_args,
            span,
        } = self;
        event.shift(delta);
        target.shift(delta);
        target_args.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Block {
    fn shift(&mut self, delta: isize) {
        let Block { stmts, span } = self;
        stmts.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Stmt {
    fn shift(&mut self, delta: isize) {
        let Stmt { kind, span } = self;
        kind.shift(delta);
        span.shift(delta);
    }
}

impl Shift for StmtKind {
    fn shift(&mut self, delta: isize) {
        match self {
            StmtKind::If(i) => i.shift(delta),
            StmtKind::Loop(l) => l.shift(delta),
            StmtKind::Group(g) => g.shift(delta),
            StmtKind::Comm(c) => c.shift(delta),
            StmtKind::Throw(Throw { event, broadcast }) => {
                event.shift(delta);
                if let Some(b) = broadcast {
                    b.shift(delta);
                }
            }
            StmtKind::Call(c) => c.shift(delta),
            StmtKind::Error => {}
        }
    }
}

impl Shift for If {
    fn shift(&mut self, delta: isize) {
        let If {
            condition,
            then_block,
            else_branch,
        } = self;
        condition.shift(delta);
        then_block.shift(delta);
        else_branch.shift(delta);
    }
}

impl Shift for Else {
    fn shift(&mut self, delta: isize) {
        match self {
            Else::If(stmt) => stmt.shift(delta),
            Else::Block(block) => block.shift(delta),
        }
    }
}

impl Shift for Loop {
    fn shift(&mut self, delta: isize) {
        let Loop {
            period,
            condition,
            body,
        } = self;
        period.shift(delta);
        condition.shift(delta);
        body.shift(delta);
    }
}

impl Shift for Call {
    fn shift(&mut self, delta: isize) {
        let Call {
            results,
            name,
            args,
            timeout,
            args_span,
        } = self;
        results.shift(delta);
        name.shift(delta);
        args.shift(delta);
        timeout.shift(delta);
        args_span.shift(delta);
    }
}

impl Shift for Arg {
    fn shift(&mut self, delta: isize) {
        match self {
            Arg::Expr(e) => e.shift(delta),
            Arg::Words { text: _, span } => span.shift(delta),
        }
    }
}

impl Shift for Comm {
    fn shift(&mut self, delta: isize) {
        let Comm {
            kind: _,
            keyword_span,
            team,
            items,
            timeout,
        } = self;
        keyword_span.shift(delta);
        team.shift(delta);
        items.shift(delta);
        timeout.shift(delta);
    }
}

impl Shift for CommItem {
    fn shift(&mut self, delta: isize) {
        let CommItem { attr, value } = self;
        attr.shift(delta);
        value.shift(delta);
    }
}

impl Shift for GroupStmt {
    fn shift(&mut self, delta: isize) {
        let GroupStmt { arms, others } = self;
        arms.shift(delta);
        others.shift(delta);
    }
}

impl Shift for GroupArm {
    fn shift(&mut self, delta: isize) {
        let GroupArm {
            kind: _,
            keyword_span,
            condition,
            body,
            span,
        } = self;
        keyword_span.shift(delta);
        condition.shift(delta);
        body.shift(delta);
        span.shift(delta);
    }
}

impl Shift for Others {
    fn shift(&mut self, delta: isize) {
        let Others { keyword_span, body } = self;
        keyword_span.shift(delta);
        body.shift(delta);
    }
}

impl Shift for GroupCond {
    fn shift(&mut self, delta: isize) {
        let GroupCond {
            kind: _,
            names,
            min,
            span,
        } = self;
        names.shift(delta);
        min.shift(delta);
        span.shift(delta);
    }
}

impl Shift for GroupMin {
    fn shift(&mut self, delta: isize) {
        let GroupMin {
            keyword_span,
            count,
        } = self;
        keyword_span.shift(delta);
        count.shift(delta);
    }
}

impl Shift for Period {
    fn shift(&mut self, delta: isize) {
        let Period {
            amount: _,
            unit: _,
            span,
        } = self;
        span.shift(delta);
    }
}

impl Shift for Expr {
    fn shift(&mut self, delta: isize) {
        let Expr { kind, span } = self;
        kind.shift(delta);
        span.shift(delta);
    }
}

impl Shift for ExprKind {
    fn shift(&mut self, delta: isize) {
        match self {
            ExprKind::Or(a, b) | ExprKind::And(a, b) | ExprKind::Compare(a, _, b) => {
                a.shift(delta);
                b.shift(delta);
            }
            ExprKind::Not(a) => a.shift(delta),
            ExprKind::Period(p) => p.shift(delta),
            ExprKind::Attr(a) => a.shift(delta),
            ExprKind::Str(_) | ExprKind::Number(_) | ExprKind::Bool(_) | ExprKind::Error => {}
        }
    }
}

impl Shift for Attr {
    fn shift(&mut self, delta: isize) {
        let Attr { segments, span } = self;
        segments.shift(delta);
        span.shift(delta);
    }
}
