//! Folding ranges: every construct spanning several lines (the formation, a
//! composite service, function, mode or main block, a `case` of a main block,
//! `if`/`else`/`loop` bodies, a `[[ ]]` group statement and its arms) and
//! every comment banner (two or more consecutive comment lines).
//!
//! A fold covers the lines from its span's start to its span's end. A closing
//! `}` or `]]` that starts its line is left out (the fold ends on the line
//! before), so that `} repeat(1 SEC)` stays visible, as indentation folding
//! would have it.

use crate::CheckedMission;
use crate::span::Span;
use crate::syntax::ast::{Block, Else, Item, Stmt, StmtKind};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FoldKind {
    Block,
    Comment,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fold {
    pub span: Span,
    pub kind: FoldKind,
}

/// The folds of the file, sorted by start (outer before inner).
pub fn folding_ranges(analysis: &CheckedMission, text: &str) -> Vec<Fold> {
    let mut folds = Folds {
        text,
        folds: Vec::new(),
    };
    for item in &analysis.syntax.items {
        match item {
            Item::Formation(f) => {
                folds.add(f.span.start, f.span.end);
                for team in &f.teams {
                    folds.add(team.span.start, team.span.end);
                }
            }
            Item::Service(s) => {
                folds.add(s.span.start, s.body.span.end);
                folds.block(&s.body);
            }
            Item::Function(f) => {
                folds.add(f.span.start, f.body.span.end);
                folds.block(&f.body);
            }
            Item::Mode(m) => folds.add(m.span.start, m.span.end),
            Item::Main(m) => {
                folds.add(m.span.start, m.span.end);
                for case in &m.cases {
                    folds.add(case.span.start, case.span.end);
                }
            }
            Item::Error(_) => {}
        }
    }
    folds.comments();
    let mut folds = folds.folds;
    folds.sort_by_key(|f| (f.span.start, std::cmp::Reverse(f.span.end)));
    folds.dedup();
    folds
}

struct Folds<'a> {
    text: &'a str,
    folds: Vec<Fold>,
}

impl Folds<'_> {
    /// A block fold from `start` to `end`, if it spans lines.
    fn add(&mut self, start: usize, end: usize) {
        let Some(written) = self.text.get(..end) else {
            return;
        };
        let closing = if written.ends_with("]]") {
            2
        } else if written.ends_with('}') {
            1
        } else {
            0
        };
        let mut end = end;
        if closing > 0 {
            let close = end - closing;
            let line_start = written[..close].rfind('\n').map_or(0, |i| i + 1);
            if written[line_start..close].trim().is_empty() && line_start > 0 {
                end = line_start - 1;
            }
        }
        if self
            .text
            .get(start..end)
            .is_some_and(|folded| folded.contains('\n'))
        {
            self.folds.push(Fold {
                span: Span::new(start, end),
                kind: FoldKind::Block,
            });
        }
    }

    fn block(&mut self, block: &Block) {
        for stmt in &block.stmts {
            self.stmt(stmt);
        }
    }

    fn stmt(&mut self, stmt: &Stmt) {
        match &stmt.kind {
            StmtKind::If(i) => {
                self.add(stmt.span.start, i.then_block.span.end);
                self.block(&i.then_block);
                match i.else_branch.as_deref() {
                    Some(Else::If(s)) => self.stmt(s),
                    Some(Else::Block(b)) => {
                        self.add(b.span.start, b.span.end);
                        self.block(b);
                    }
                    None => {}
                }
            }
            StmtKind::Loop(l) => {
                self.add(stmt.span.start, l.body.span.end);
                self.block(&l.body);
            }
            StmtKind::Group(g) => {
                self.add(stmt.span.start, stmt.span.end);
                for arm in &g.arms {
                    self.add(arm.span.start, arm.body.span.end);
                    self.block(&arm.body);
                }
                if let Some(o) = &g.others {
                    self.add(o.keyword_span.start, o.body.span.end);
                    self.block(&o.body);
                }
            }
            StmtKind::Comm(_) | StmtKind::Throw(_) | StmtKind::Call(_) | StmtKind::Error => {}
        }
    }

    /// Runs of two or more lines holding only a comment.
    fn comments(&mut self) {
        let mut run: Option<(usize, usize, usize)> = None; // (start, end, lines)
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            let content = line.trim_end_matches(['\n', '\r']);
            let indent = content.len() - content.trim_start().len();
            if content.trim_start().starts_with('#') {
                let end = offset + content.len();
                run = Some(match run {
                    Some((start, _, lines)) => (start, end, lines + 1),
                    None => (offset + indent, end, 1),
                });
            } else if let Some(done) = run.take() {
                self.comment_run(done);
            }
            offset += line.len();
        }
        if let Some(done) = run {
            self.comment_run(done);
        }
    }

    fn comment_run(&mut self, (start, end, lines): (usize, usize, usize)) {
        if lines >= 2 {
            self.folds.push(Fold {
                span: Span::new(start, end),
                kind: FoldKind::Comment,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ide::mission::testing::Fixture;

    const MISSION: &str = r#"##########
# Guards
##########
{
  Base: iRobotCreate base
  Guards: Turtlebot3_Burger tb[3],
          Ev3_Robot ev
}
Base.Listen.Collect {
  subscribe(Guards, Guards.Alarm)
  if (Guards.Alarm == DARK) {
    throw alarm
  } else {
    standby()
  }
  if (Guards.Alarm == BRIGHT)
    throw calm
} repeat(1 SEC)
# one comment line
Guards.Action.Patrol {
  [[
    group(instance of Turtlebot3_Burger){
      loop(2 SEC){
        publish(Guards, Guards.Alarm = DARK)
      }
    }
    others { move("3,3") }
  ]]
} repeat()
Base.M { set(Listen, Collect) }
Guards.M {
  set(Action, Patrol)
}
Base.main {
  case (M):
    catch (alarm): mode = M
    catch (calm): mode = M
  default: mode = M
}
Guards.main { default: mode = M }
  # indented
  # banner"#;

    #[test]
    fn blocks_groups_and_banners() {
        let f = Fixture::new(MISSION);
        let shown: Vec<String> = folding_ranges(&f.analysis, &f.text)
            .iter()
            .map(|fold| {
                let (start, _) = f.line_col(fold.span.start);
                let (end, _) = f.line_col(fold.span.end);
                let first = f.text[fold.span.start..].lines().next().unwrap_or("");
                format!("{start}-{end} {:?} {first}", fold.kind)
            })
            .collect();
        assert_eq!(
            shown,
            [
                "1-3 Comment ##########",
                "4-7 Block {",
                "6-7 Block Guards: Turtlebot3_Burger tb[3],",
                "9-17 Block Base.Listen.Collect {",
                "11-12 Block if (Guards.Alarm == DARK) {",
                "13-14 Block {",
                "16-17 Block if (Guards.Alarm == BRIGHT)",
                "20-28 Block Guards.Action.Patrol {",
                "21-27 Block [[",
                "22-25 Block group(instance of Turtlebot3_Burger){",
                "23-24 Block loop(2 SEC){",
                "31-32 Block Guards.M {",
                "34-38 Block Base.main {",
                "35-37 Block case (M):",
                "41-42 Comment # indented",
            ]
        );
    }

    #[test]
    fn broken_files_still_fold() {
        let f = Fixture::new("T.P.S {\n  move(\n}\n{ T: x\n");
        folding_ranges(&f.analysis, &f.text);
        assert!(folding_ranges(&Fixture::new("").analysis, "").is_empty());
    }
}
