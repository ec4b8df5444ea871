//! Selection ranges ("expand selection"): from the name at a position outward
//! through the nodes of the tree that hold it: name → attribute → expression
//! → statement → block → item → file.

use crate::CheckedMission;
use crate::span::Span;
use crate::syntax::ast::{
    Arg, Attr, Block, Case, Catch, CommItem, Else, Expr, ExprKind, GroupArm, GroupCond, Ident,
    Item, Others, Repeat, RobotDecl, SetStmt, SetTarget, Stmt, StmtKind, TeamDecl,
};

/// The ranges holding `offset`, innermost first, each strictly inside the
/// next; the last is the whole file.
pub fn selection_ranges(analysis: &CheckedMission, text: &str, offset: usize) -> Vec<Span> {
    let file = Span::new(0, text.len());
    let offset = offset.min(text.len());
    let mut outward = vec![file];
    let mut children: Vec<Node<'_>> = analysis.syntax.items.iter().map(Node::Item).collect();
    while let Some(node) = pick(&children, offset) {
        let span = node.span();
        let outer = outward.last().copied().unwrap_or(file);
        if span != outer && outer.start <= span.start && span.end <= outer.end {
            outward.push(span);
        }
        children = node.children();
    }
    outward.reverse();
    outward
}

/// The child containing `offset`, else one ending right there.
fn pick<'a>(children: &[Node<'a>], offset: usize) -> Option<Node<'a>> {
    let found = children.iter().find(|c| c.span().contains(offset));
    found
        .or_else(|| children.iter().find(|c| c.span().touches(offset)))
        .copied()
}

/// A node of the tree, for walking it uniformly.
#[derive(Clone, Copy)]
enum Node<'a> {
    Item(&'a Item),
    TeamDecl(&'a TeamDecl),
    Robot(&'a RobotDecl),
    /// `T.P.S`, `T.M`, `T.main`: the names of an item's header.
    Header(Span, [Option<&'a Ident>; 3], Option<Span>),
    Ident(&'a Ident),
    Leaf(Span),
    Block(&'a Block),
    Stmt(&'a Stmt),
    Else(&'a Else),
    Repeat(&'a Repeat),
    Set(&'a SetStmt),
    Case(&'a Case),
    Catch(&'a Catch),
    Arm(&'a GroupArm),
    Others(&'a Others),
    Cond(&'a GroupCond),
    CommItem(&'a CommItem),
    Arg(&'a Arg),
    Expr(&'a Expr),
    Attr(&'a Attr),
}

impl<'a> Node<'a> {
    fn span(&self) -> Span {
        match self {
            Node::Item(i) => i.span(),
            Node::TeamDecl(d) => d.span,
            Node::Robot(r) => r.span,
            Node::Header(span, ..) | Node::Leaf(span) => *span,
            Node::Ident(i) => i.span,
            Node::Block(b) => b.span,
            Node::Stmt(s) => s.span,
            Node::Else(Else::If(s)) => s.span,
            Node::Else(Else::Block(b)) => b.span,
            Node::Repeat(r) => r.span,
            Node::Set(s) => s.span,
            Node::Case(c) => c.span,
            Node::Catch(c) => c.span,
            Node::Arm(a) => a.span,
            Node::Others(o) => o.keyword_span.cover(o.body.span),
            Node::Cond(c) => c.span,
            Node::CommItem(i) => match &i.value {
                Some(v) => i.attr.span.cover(v.span),
                None => i.attr.span,
            },
            Node::Arg(a) => a.span(),
            Node::Expr(e) => e.span,
            Node::Attr(a) => a.span,
        }
    }

    fn children(&self) -> Vec<Node<'a>> {
        let header = |names: [Option<&'a Ident>; 3], keyword: Option<Span>| {
            let mut span = names.iter().flatten().fold(None, |s: Option<Span>, i| {
                Some(s.map_or(i.span, |s| s.cover(i.span)))
            });
            if let Some(k) = keyword {
                span = Some(span.map_or(k, |s| s.cover(k)));
            }
            span.map(|span| Node::Header(span, names, keyword))
        };
        let mut out = Vec::new();
        match *self {
            Node::Item(item) => match item {
                Item::Formation(f) => out.extend(f.teams.iter().map(Node::TeamDecl)),
                Item::Service(s) => {
                    out.extend(header([Some(&s.team), Some(&s.plan), Some(&s.name)], None));
                    out.push(Node::Block(&s.body));
                    out.extend(s.repeat.as_ref().map(Node::Repeat));
                }
                Item::Function(f) => {
                    out.push(Node::Ident(&f.name));
                    out.push(Node::Block(&f.body));
                }
                Item::Mode(m) => {
                    out.extend(header([Some(&m.team), Some(&m.name), None], None));
                    out.extend(m.sets.iter().map(Node::Set));
                }
                Item::Main(m) => {
                    out.extend(header([Some(&m.team), None, None], Some(m.main_span)));
                    out.extend(m.cases.iter().map(Node::Case));
                    out.extend(m.default.as_ref().map(Node::Ident));
                }
                Item::Error(_) => {}
            },
            Node::TeamDecl(d) => {
                out.push(Node::Ident(&d.name));
                out.extend(d.robots.iter().map(Node::Robot));
            }
            Node::Robot(r) => {
                out.push(Node::Ident(&r.robot_type));
                out.push(Node::Ident(&r.name));
                out.extend(r.count.map(|c| Node::Leaf(c.span)));
            }
            Node::Header(_, names, keyword) => {
                out.extend(names.into_iter().flatten().map(Node::Ident));
                out.extend(keyword.map(Node::Leaf));
            }
            Node::Ident(_) | Node::Leaf(_) => {}
            Node::Block(b) => out.extend(b.stmts.iter().map(Node::Stmt)),
            Node::Stmt(s) => match &s.kind {
                StmtKind::If(i) => {
                    out.push(Node::Expr(&i.condition));
                    out.push(Node::Block(&i.then_block));
                    out.extend(i.else_branch.as_deref().map(Node::Else));
                }
                StmtKind::Loop(l) => {
                    out.extend(l.period.as_ref().map(|p| Node::Leaf(p.span)));
                    out.extend(l.condition.as_ref().map(Node::Expr));
                    out.push(Node::Block(&l.body));
                }
                StmtKind::Group(g) => {
                    out.extend(g.arms.iter().map(Node::Arm));
                    out.extend(g.others.as_ref().map(Node::Others));
                }
                StmtKind::Comm(c) => {
                    out.push(Node::Leaf(c.keyword_span));
                    out.push(Node::Ident(&c.team));
                    out.extend(c.items.iter().map(Node::CommItem));
                    out.extend(c.timeout.as_ref().map(|p| Node::Leaf(p.span)));
                }
                StmtKind::Throw(t) => out.push(Node::Ident(&t.event)),
                StmtKind::Call(c) => {
                    out.push(Node::Ident(&c.name));
                    out.push(Node::Leaf(c.args_span));
                    out.extend(c.args.iter().map(Node::Arg));
                    out.extend(c.timeout.as_ref().map(|p| Node::Leaf(p.span)));
                }
                StmtKind::Error => {}
            },
            Node::Else(Else::If(s)) => out.push(Node::Stmt(s)),
            Node::Else(Else::Block(b)) => out.push(Node::Block(b)),
            Node::Repeat(r) => {
                out.extend(r.period.as_ref().map(|p| Node::Leaf(p.span)));
                out.extend(r.condition.as_ref().map(Node::Expr));
            }
            Node::Set(s) => {
                out.push(Node::Ident(&s.plan));
                out.push(match &s.service {
                    SetTarget::Service(name) => Node::Ident(name),
                    SetTarget::Off(span) => Node::Leaf(*span),
                });
                out.extend(s.timeout.as_ref().map(|p| Node::Leaf(p.span)));
            }
            Node::Case(c) => {
                out.push(Node::Ident(&c.mode));
                out.extend(c.catches.iter().map(Node::Catch));
            }
            Node::Catch(c) => {
                out.push(Node::Ident(&c.event));
                out.push(Node::Ident(&c.target));
            }
            Node::Arm(a) => {
                out.push(Node::Leaf(a.keyword_span));
                out.push(Node::Cond(&a.condition));
                out.push(Node::Block(&a.body));
            }
            Node::Others(o) => {
                out.push(Node::Leaf(o.keyword_span));
                out.push(Node::Block(&o.body));
            }
            Node::Cond(c) => out.extend(c.names.iter().map(Node::Ident)),
            Node::CommItem(i) => {
                out.push(Node::Attr(&i.attr));
                out.extend(i.value.as_ref().map(Node::Expr));
            }
            Node::Arg(Arg::Expr(e)) => out.push(Node::Expr(e)),
            Node::Arg(Arg::Words { .. }) => {}
            Node::Expr(e) => match &e.kind {
                ExprKind::Or(a, b) | ExprKind::And(a, b) | ExprKind::Compare(a, _, b) => {
                    out.push(Node::Expr(a));
                    out.push(Node::Expr(b));
                }
                ExprKind::Not(a) => out.push(Node::Expr(a)),
                ExprKind::Attr(a) => out.push(Node::Attr(a)),
                ExprKind::Period(p) => out.push(Node::Leaf(p.span)),
                ExprKind::Str(_) | ExprKind::Number(_) | ExprKind::Bool(_) | ExprKind::Error => {}
            },
            Node::Attr(a) => out.extend(a.segments.iter().map(Node::Ident)),
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::Fixture;

    const MISSION: &str = r#"{
  Guards: Turtlebot3_Burger tb[3], Ev3_Robot ev
}
Guards.Listen.Hear {
  [[
    group(instance of Turtlebot3_Burger){
      if (Guards.LIGHTNESS < 200 and not Guards.Alarm == DARK)
        publish(Guards, Guards.Alarm = DARK)
    }
  ]]
  move("3,3"), timeout = 2 SEC
} repeat(500 MSEC)
Guards.M { set(Listen, Hear) }
Guards.main { default: mode = M }
"#;

    fn chain(f: &Fixture, marker: &str, shift: usize) -> Vec<String> {
        let offset = f.offset_of(marker) + shift;
        let ranges = selection_ranges(&f.analysis, &f.text, offset);
        for pair in ranges.windows(2) {
            assert!(
                pair[1].start <= pair[0].start && pair[0].end <= pair[1].end && pair[0] != pair[1],
                "{ranges:?}"
            );
        }
        ranges
            .iter()
            .map(|s| {
                let text = &f.text[s.range()];
                match text.lines().count() {
                    0 | 1 => text.to_string(),
                    n => format!("{}… ({n} lines)", text.lines().next().unwrap_or("")),
                }
            })
            .collect()
    }

    #[test]
    fn from_a_name_out_to_the_file() {
        let f = Fixture::new(MISSION);
        assert_eq!(
            chain(&f, "LIGHTNESS", 2),
            [
                "LIGHTNESS",
                "Guards.LIGHTNESS",
                "Guards.LIGHTNESS < 200",
                "Guards.LIGHTNESS < 200 and not Guards.Alarm == DARK",
                "if (Guards.LIGHTNESS < 200 and not Guards.Alarm == DARK)… (2 lines)",
                "{… (4 lines)",
                "group(instance of Turtlebot3_Burger){… (4 lines)",
                "[[… (6 lines)",
                "{… (9 lines)",
                "Guards.Listen.Hear {… (9 lines)",
                "{… (14 lines)",
            ]
        );
        assert_eq!(
            chain(&f, "Hear {", 0),
            [
                "Hear",
                "Guards.Listen.Hear",
                "Guards.Listen.Hear {… (9 lines)",
                "{… (14 lines)"
            ]
        );
        assert_eq!(
            chain(&f, "tb[3]", 0),
            [
                "tb",
                "Turtlebot3_Burger tb[3]",
                "Guards: Turtlebot3_Burger tb[3], Ev3_Robot ev",
                "{… (3 lines)",
                "{… (14 lines)"
            ]
        );
        assert_eq!(
            chain(&f, "SEC\n}", 0),
            [
                "2 SEC",
                "move(\"3,3\"), timeout = 2 SEC",
                "{… (9 lines)",
                "Guards.Listen.Hear {… (9 lines)",
                "{… (14 lines)"
            ]
        );
    }

    #[test]
    fn anywhere_and_in_broken_files() {
        let f = Fixture::new(MISSION);
        for offset in 0..=f.text.len() + 2 {
            assert!(!selection_ranges(&f.analysis, &f.text, offset).is_empty());
        }
        let broken = Fixture::new("T.P.S {\n  if (a == ) move(\n}\n{ T: x");
        for offset in 0..=broken.text.len() {
            selection_ranges(&broken.analysis, &broken.text, offset);
        }
    }
}
