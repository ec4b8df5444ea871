//! The canonical layout of mission scripts: `semo fmt`, and later the language
//! server's "format document". [`format_source`] is the one entry point.
//!
//! # What it guarantees
//!
//! - **Nothing the user wrote is lost or changed.** Only whitespace changes:
//!   every token stays as written (`or` stays `or`, `||` stays `||`, `sec`
//!   stays `sec`, strings and numbers keep their spelling, `;` are kept), and
//!   every `#` comment stays between the same two tokens, at the end of a line
//!   of code or on a line of its own as it was (trailing whitespace in a
//!   comment is removed). The output is checked against the input before it is
//!   returned (`verify.rs`); if it differs, the text is refused, not returned.
//! - **Broken text is refused.** A file with any syntax error is not touched:
//!   what the parser did not understand cannot be laid out safely.
//! - **Idempotent**: formatting formatted text changes nothing.
//! - Never panics; linear time (a 10k-line mission in a few milliseconds).
//!
//! # The style
//!
//! Close to how the reference examples are written:
//!
//! - Two spaces per indentation level; no tabs, no trailing spaces; the file
//!   ends with one line break. Line breaks are `\n`, or `\r\n` if the file's
//!   first line ends so.
//! - Top-level items (formation, services, functions, modes, mains) start at
//!   the left margin, separated by exactly one empty line. Consecutive bare
//!   team declarations (`T: A a` without braces) stay on consecutive lines
//!   (with one empty line between them if the user left one).
//! - Headers end with ` {`: `T.Plan.Service {`, `T.MODE {`, `T.main {`,
//!   `def name {`. The body is indented one level; `}` starts its own line,
//!   followed on that line by ` repeat(...)` for a service. A body with
//!   nothing inside, not even a comment, is `{}`.
//! - The formation: `{`, one team per line (`Team: Type name, Type name[2]`),
//!   `}`.
//! - One statement (or `set`) per line. A braced block opens at the end of its
//!   header line (`if(c) {`, `loop(2 SEC) {`, `group(instance of X) {`,
//!   `others {`) and chains go `} else {`, `} else if(c) {`. A block without
//!   braces (one statement) goes on the next line, one level in; its `else`
//!   then starts a line of its own, as in the examples:
//!   `if(c)` / `  throw A` / `else if(d)` / `  throw B`.
//! - Group statements: `[[` and `]]` on lines of their own, the `group`,
//!   `leader` and `others` arms one level in.
//! - `main`: each `case (M):` and the `default: mode = M` one level in, each
//!   `catch (e): mode = M` one level deeper.
//! - Spaces: none between a name or keyword and its `(` (`move(`, `if(`,
//!   `repeat(`, `send(`), except `case (` and `catch (`; none inside brackets,
//!   around `.`, or before `,` `;` `:`; one after `,` and `:`; one on each side
//!   of `=`, comparisons, `and`, `or`, `&&`, `||`; `!x` and `not x`;
//!   `name[2]`; `{}` when empty.
//! - `;` are kept, glued to what precedes them; what follows still starts its
//!   own line.
//! - Empty lines: between statements, `set`s, arms and comments inside a
//!   block, one empty line is kept where the user left one or more; none
//!   after an opening `{` or before a closing `}`. Line breaks the user wrote
//!   elsewhere (inside a statement) are not kept.
//! - Width: lines aim at [`MAX_WIDTH`] columns (counted in characters). A
//!   statement that would be longer breaks its outermost parentheses: each
//!   comma-separated part on its own line one level in, `)` back at the
//!   statement's level; a part still too long breaks before each `and`/`or`
//!   outside nested parentheses. Parentheses holding a single part without
//!   `and`/`or` (`say("...")`) are not broken, and names and strings are
//!   never split, so a line can still be longer.
//! - Comments: a comment that ends a line of code stays there, after one
//!   space (it does not count against the width). A comment on its own line
//!   stays on its own line, indented like the code after it (before a
//!   closing `}`, like the statements of the block). Comments before the
//!   first token of an item belong to that item: the empty line between items
//!   goes before them. An empty line before or after a comment between
//!   statements is kept as above.
//! - A comment where the layout has no line break ends its line all the
//!   same. Inside parentheses, they break as if too long. Before `else` or
//!   `repeat`, an own-line comment puts them on a line of their own; after a
//!   comment, a block's `{` starts a line at its header's level. Elsewhere
//!   (`T.Plan # why` / `.Service {`) the statement goes on in the next line,
//!   one level deeper.

mod doc;
mod emit;
mod layout;
mod spacing;
mod trivia;
mod verify;

#[cfg(test)]
mod tests;

use crate::diag::{Diagnostic, FileId};
use crate::span::Span;
use crate::syntax;
use std::fmt;

pub use layout::MAX_NESTING;

/// The width lines are kept within where the layout allows a break.
pub const MAX_WIDTH: usize = 100;

/// Why a text was not formatted. The text is then to be left as it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FormatRefusal {
    /// The text has syntax errors (at least one; the parser's diagnostics, for
    /// [`FileId`]`(0)`, sorted by position).
    SyntaxErrors(Vec<Diagnostic>),
    /// Statements nested more deeply than [`MAX_NESTING`]
    /// levels, at this statement.
    TooDeep(Span),
    /// The formatter's own check of its output failed (a formatter bug): the
    /// output would have lost or changed a token or comment.
    Unfaithful(String),
}

impl FormatRefusal {
    /// Where the problem is, when it has a place.
    pub fn span(&self) -> Option<Span> {
        match self {
            FormatRefusal::SyntaxErrors(diags) => diags.first().map(|d| d.span),
            FormatRefusal::TooDeep(span) => Some(*span),
            FormatRefusal::Unfaithful(_) => None,
        }
    }
}

impl fmt::Display for FormatRefusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FormatRefusal::SyntaxErrors(diags) => {
                let first = diags.first().map_or("", |d| d.message.as_str());
                match diags.len() {
                    1 => write!(f, "syntax error: {first}"),
                    n => write!(f, "{n} syntax errors, the first: {first}"),
                }
            }
            FormatRefusal::TooDeep(_) => write!(
                f,
                "statements are nested more than {MAX_NESTING} levels deep"
            ),
            FormatRefusal::Unfaithful(what) => write!(
                f,
                "the formatter would have changed what you wrote ({what}); this is a bug in semo"
            ),
        }
    }
}

impl std::error::Error for FormatRefusal {}

/// Formats a mission script in the canonical layout (see the module
/// documentation). Returns the whole new text, or why the text must be left
/// as it is.
pub fn format_source(text: &str) -> Result<String, FormatRefusal> {
    let (parsed, tokens) = syntax::parse_with_tokens(FileId(0), text);
    if !parsed.diagnostics.is_empty() {
        return Err(FormatRefusal::SyntaxErrors(parsed.diagnostics));
    }
    let trivia = trivia::scan(text, &tokens)
        .map_err(|at| FormatRefusal::Unfaithful(format!("unexpected text at byte {}", at.0)))?;
    let mut emitter = emit::Emitter::new(text, &tokens, &trivia);
    layout::file(&mut emitter, &parsed.file).map_err(|e| match e {
        layout::LayoutError::TooDeep(span) => FormatRefusal::TooDeep(span),
        layout::LayoutError::Unparsed(span) => FormatRefusal::Unfaithful(format!(
            "a part at bytes {}..{} did not parse",
            span.start, span.end
        )),
    })?;
    let items = emitter.finish().map_err(|at| {
        FormatRefusal::Unfaithful(format!("the token at byte {at} was not placed"))
    })?;
    let mut out = doc::print(&items, MAX_WIDTH, text.len() + text.len() / 4);
    if uses_crlf(text) {
        out = out.replace('\n', "\r\n");
    }
    verify::faithful(&tokens, &trivia, &out).map_err(FormatRefusal::Unfaithful)?;
    Ok(out)
}

/// Whether the first line of `text` ends with `\r\n`.
fn uses_crlf(text: &str) -> bool {
    text.find('\n').is_some_and(|i| text[..i].ends_with('\r'))
}
