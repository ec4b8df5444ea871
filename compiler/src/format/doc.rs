//! The layout document and its printer.
//!
//! A document is a flat list of [`Item`]s: texts, spaces, line breaks, and
//! markers that open and close groups and indentation. A group is printed on
//! one line ("flat") when it fits in the width and holds no forced break; else
//! its [`Item::Line`]s become line breaks. Deciding a group looks ahead only as
//! far as the width allows, so printing is linear in the size of the document.
//!
//! Line breaks are printed lazily: a break only records that the next text
//! starts a new line, so consecutive breaks merge, no line ends in spaces, and
//! the indentation is the one in force when the text arrives.

/// Spaces per indentation level.
pub const INDENT: usize = 2;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item<'s> {
    /// Text without line breaks.
    Text(&'s str),
    /// One space (unless at the start of a line), then the text.
    SpacedText(&'s str),
    /// A possible line break: prints `flat` (`""` or `" "`) when its group is
    /// flat, else breaks the line.
    Line(&'static str),
    /// A line break.
    Hard,
    /// A line break with one empty line before the next text.
    Blank,
    /// A comment ending the current line (after one space); what follows
    /// starts a new line.
    TrailingComment(&'s str),
    /// A comment on a line of its own. Written where no break is planned, it
    /// gets one, and the code after it continues one level deeper.
    OwnLineComment(&'s str),
    GroupStart,
    GroupEnd,
    IndentStart,
    IndentEnd,
}

impl Item<'_> {
    /// Items that always end the line, so that a group holding one is never flat.
    fn forces_break(self) -> bool {
        matches!(
            self,
            Item::Hard | Item::Blank | Item::TrailingComment(_) | Item::OwnLineComment(_)
        )
    }
}

fn width(s: &str) -> usize {
    if s.is_ascii() {
        s.len()
    } else {
        s.chars().count()
    }
}

/// The line break that the next text will start with.
#[derive(Clone, Copy, Debug)]
struct Pending {
    /// An empty line first.
    blank: bool,
    /// A break the layout did not plan (after a comment inside a construct):
    /// the line is indented one level more.
    continuation: bool,
}

fn merge(a: Option<Pending>, b: Pending) -> Option<Pending> {
    Some(match a {
        None => b,
        Some(a) => Pending {
            blank: a.blank || b.blank,
            continuation: a.continuation && b.continuation,
        },
    })
}

/// If the group opening at `start` fits flat in `room` columns, together with
/// what follows it up to the next possible line break, the index of its end.
fn fits(items: &[Item<'_>], start: usize, room: usize) -> Option<usize> {
    let mut room = room as isize;
    let mut depth = 0usize;
    let mut end = None;
    for (i, item) in items.iter().enumerate().skip(start) {
        match *item {
            Item::GroupStart => depth += 1,
            Item::GroupEnd => {
                depth = depth.saturating_sub(1);
                if depth == 0 && end.is_none() {
                    end = Some(i);
                }
            }
            Item::Text(s) => room -= width(s) as isize,
            Item::SpacedText(s) => room -= 1 + width(s) as isize,
            Item::Line(flat) if end.is_none() => room -= flat.len() as isize,
            // After the group: the rest of the line ends at the next break.
            Item::Line(_) => return end,
            item if item.forces_break() => return end,
            _ => {}
        }
        if room < 0 {
            return None;
        }
    }
    end
}

/// Prints `items` in `max_width` columns, in a text of about `size_hint`
/// bytes. The text ends with one line break unless it is empty.
pub fn print(items: &[Item<'_>], max_width: usize, size_hint: usize) -> String {
    let mut out = String::with_capacity(size_hint);
    let mut level = 0usize;
    let mut col = 0usize;
    let mut pending: Option<Pending> = None;
    // Whether the current line is a continuation line.
    let mut continued = false;
    // Items before this index belong to a group printed flat.
    let mut flat_until = 0usize;

    let indentation =
        |level: usize, continuation: bool| (level + usize::from(continuation)) * INDENT;
    // Starts the pending line, if any, before a text.
    let flush = |out: &mut String,
                 pending: &mut Option<Pending>,
                 col: &mut usize,
                 continued: &mut bool,
                 level: usize| {
        if let Some(p) = pending.take() {
            // Nothing precedes the first text: no break at the start of the file.
            if !out.is_empty() {
                out.push('\n');
                if p.blank {
                    out.push('\n');
                }
                let indent = indentation(level, p.continuation);
                out.extend(std::iter::repeat_n(' ', indent));
                *col = indent;
                *continued = p.continuation;
            }
        }
    };

    for (i, item) in items.iter().enumerate() {
        let flat = i < flat_until;
        match *item {
            Item::SpacedText(s) | Item::Text(s) => {
                if matches!(item, Item::SpacedText(_)) && pending.is_none() && !out.is_empty() {
                    out.push(' ');
                    col += 1;
                }
                flush(&mut out, &mut pending, &mut col, &mut continued, level);
                out.push_str(s);
                col += width(s);
            }
            Item::Line(flat_text) if flat => {
                if pending.is_none() && !out.is_empty() {
                    out.push_str(flat_text);
                    col += flat_text.len();
                }
            }
            Item::Line(_) | Item::Hard => {
                pending = merge(
                    pending,
                    Pending {
                        blank: false,
                        continuation: false,
                    },
                );
            }
            Item::Blank => {
                pending = merge(
                    pending,
                    Pending {
                        blank: true,
                        continuation: false,
                    },
                );
            }
            Item::TrailingComment(s) => {
                flush(&mut out, &mut pending, &mut col, &mut continued, level);
                if !out.is_empty() {
                    out.push(' ');
                }
                out.push_str(s);
                pending = merge(
                    pending,
                    Pending {
                        blank: false,
                        continuation: true,
                    },
                );
            }
            Item::OwnLineComment(s) => {
                if pending.is_none() && !out.is_empty() {
                    pending = Some(Pending {
                        blank: false,
                        continuation: true,
                    });
                }
                flush(&mut out, &mut pending, &mut col, &mut continued, level);
                out.push_str(s);
                // The code after it goes on as the comment's own line went.
                pending = Some(Pending {
                    blank: false,
                    continuation: continued,
                });
            }
            Item::GroupStart if !flat => {
                let start_col = match pending {
                    Some(p) => indentation(level, p.continuation),
                    None => col,
                };
                if let Some(end) = fits(items, i, max_width.saturating_sub(start_col)) {
                    flat_until = end;
                }
            }
            Item::GroupStart | Item::GroupEnd => {}
            Item::IndentStart => level += 1,
            Item::IndentEnd => level = level.saturating_sub(1),
        }
    }
    if !out.is_empty() {
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use Item::*;

    fn call<'s>(args: &[&'s str]) -> Vec<Item<'s>> {
        let mut items = vec![Text("move"), GroupStart, Text("("), IndentStart, Line("")];
        for (i, a) in args.iter().enumerate() {
            if i > 0 {
                items.extend([Text(","), Line(" ")]);
            }
            items.push(Text(a));
        }
        items.extend([IndentEnd, Line(""), Text(")"), GroupEnd]);
        items
    }

    #[test]
    fn a_group_that_fits_stays_on_one_line() {
        assert_eq!(print(&call(&["a", "b"]), 20, 0), "move(a, b)\n");
    }

    #[test]
    fn a_group_too_wide_breaks_every_line_of_it() {
        assert_eq!(
            print(&call(&["alpha", "beta", "gamma"]), 15, 0),
            "move(\n  alpha,\n  beta,\n  gamma\n)\n"
        );
    }

    #[test]
    fn what_follows_a_group_on_its_line_counts() {
        let mut items = call(&["a", "b"]);
        items.extend([Text(","), SpacedText("timeout")]);
        assert_eq!(print(&items, 18, 0), "move(\n  a,\n  b\n), timeout\n");
        assert_eq!(print(&items, 19, 0), "move(a, b), timeout\n");
    }

    #[test]
    fn a_trailing_comment_breaks_its_group_and_the_line() {
        let mut items = vec![Text("move"), GroupStart, Text("("), IndentStart, Line("")];
        items.extend([Text("a"), Text(","), TrailingComment("# first"), Line(" ")]);
        items.extend([Text("b"), IndentEnd, Line(""), Text(")"), GroupEnd]);
        assert_eq!(print(&items, 80, 0), "move(\n  a, # first\n  b\n)\n");
    }

    #[test]
    fn a_comment_where_no_break_is_planned_continues_one_level_deeper() {
        let items = [
            Text("a"),
            TrailingComment("# one"),
            Text("b"),
            OwnLineComment("# two"),
            Text("c"),
            Hard,
            Text("d"),
        ];
        assert_eq!(print(&items, 80, 0), "a # one\n  b\n  # two\n  c\nd\n");
    }

    #[test]
    fn breaks_merge_blank_lines_collapse_and_nothing_leads_the_file() {
        let items = [
            Blank,
            Text("a"),
            Blank,
            Hard,
            Blank,
            IndentStart,
            Text("b"),
            Hard,
        ];
        assert_eq!(print(&items, 80, 0), "a\n\n  b\n");
        assert_eq!(print(&[], 80, 0), "");
    }
}
