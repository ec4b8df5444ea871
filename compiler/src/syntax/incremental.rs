//! Incremental parsing: a new version of a file parsed with what is still
//! valid from the previous one, so that a keystroke re-lexes a line or two and
//! re-parses one chunk. The result is always exactly [`super::parse`]'s.
//!
//! How it stays exact:
//! - No token spans a newline, so the lines that did not change lex to the same
//!   tokens. The texts are compared (common prefix and suffix); only the lines
//!   from the first difference to the end of the last one are lexed again, and
//!   the old tokens after them are moved by the change in length. Lexical
//!   diagnostics are kept and moved the same way.
//! - Chunks are cut again only around the edit: from the last chunk start at
//!   least six tokens before the first re-lexed token (cutting reads at most
//!   six tokens ahead, and the state after a cut is always the same), until a
//!   chunk starts, past the re-lexed tokens, where an old chunk started. The
//!   chunks before and after are the old ones (see [`chunks::split_from`]).
//! - A chunk's items and syntax diagnostics depend only on the chunk's own text
//!   (from its first token to its last; bracket balancing and the parser look
//!   at nothing else, and only at relative positions). So a chunk whose text is
//!   unchanged takes the items and diagnostics parsed before, with every
//!   position moved by the distance the chunk moved. Around the edit a chunk is
//!   found at its old place (before or after the edit, where the texts are
//!   equal by construction), else by the hash of its text, confirmed by
//!   comparing the texts; the rest is parsed.
//! - Diagnostics are assembled as `parse` does: lexical ones first, then each
//!   chunk's in chunk order, sorted stably by position.

use super::shift::Shift;
use super::token::{self, Token};
use super::{
    ChunkParse, LexError, Parse, assemble_diagnostics, ast, chunks, lex, lexical_errors, parallel,
    parse_ranges,
};
use crate::diag::FileId;
use crate::fasthash::{FastHasher, FastMap};
use crate::span::Span;
use chumsky::span::SimpleSpan;
use std::hash::Hasher;
use std::ops::Range;
use std::sync::Arc;

/// What parsing one version of a file leaves for parsing the next: its text,
/// its tokens, and each chunk's items and diagnostics, shared (not copied)
/// between successive caches.
pub struct ParseCache {
    file: FileId,
    text: Box<str>,
    /// The tokens the parser reads (lexical errors repaired: unknown characters
    /// dropped, unterminated strings taken as strings), with the text of
    /// names, numbers and strings left out: it is `text[span]`.
    tokens: Vec<RawToken>,
    /// The lexical diagnostics (unknown characters, unterminated strings), in
    /// order.
    lexical: Vec<LexError>,
    /// The chunks, in order.
    chunks: Vec<CachedChunk>,
    /// Chunks parsed anew (not reused) when this cache was made.
    reparsed: usize,
    /// The bytes of `text` lexed anew when this cache was made.
    relexed: Range<usize>,
}

type RawToken = (Token<'static>, SimpleSpan);

#[derive(Clone)]
struct CachedChunk {
    /// The chunk's tokens.
    tokens: Range<usize>,
    /// The chunk's text: its first token's start to its last token's end.
    span: Span,
    /// The hash of that text.
    hash: u64,
    parsed: Arc<ParsedChunk>,
}

/// A chunk of the previous version with the same text: its parse and hash.
type Found = (Arc<ParsedChunk>, u64);

struct ParsedChunk {
    /// Where the chunk's text started when it was parsed: its items and
    /// diagnostics are positioned for a text starting there.
    at: usize,
    result: ChunkParse,
}

impl ParseCache {
    /// The number of chunks of the file.
    pub fn chunks(&self) -> usize {
        self.chunks.len()
    }

    /// How many chunks were parsed anew (rather than reused) for this version.
    pub fn reparsed(&self) -> usize {
        self.reparsed
    }

    /// The byte range of this version's text that was lexed anew.
    pub fn relexed(&self) -> Range<usize> {
        self.relexed.clone()
    }
}

impl std::fmt::Debug for ParseCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParseCache")
            .field("file", &self.file)
            .field("bytes", &self.text.len())
            .field("tokens", &self.tokens.len())
            .field("chunks", &self.chunks.len())
            .field("reparsed", &self.reparsed)
            .field("relexed", &self.relexed)
            .finish()
    }
}

/// Parses `text`, reusing what `previous` (the cache of an earlier version of
/// the same file) still holds, and returns the parse with the cache for the
/// next version. The parse is the same as [`super::parse`]`(file, text)`, items,
/// positions, diagnostics and their order. A cache of another file, or none,
/// means parsing everything.
pub fn parse_incremental(
    file: FileId,
    text: &str,
    previous: Option<&ParseCache>,
) -> (Parse, ParseCache) {
    let empty = ParseCache {
        file,
        text: Box::default(),
        tokens: Vec::new(),
        lexical: Vec::new(),
        chunks: Vec::new(),
        reparsed: 0,
        relexed: 0..0,
    };
    let old = previous.filter(|p| p.file == file).unwrap_or(&empty);
    let edit = Edit::between(&old.text, text);
    let lexed = relex(old, text, &edit);
    let tokens = &lexed.tokens;

    // Cut chunks again from a chunk start far enough before the edit...
    let resume = old
        .chunks
        .partition_point(|c| c.tokens.start + chunks::MAX_HEADER_TOKENS <= lexed.kept_before)
        .saturating_sub(1);
    let from = old.chunks.get(resume).map_or(0, |c| c.tokens.start);
    // ...until a chunk starts after the new tokens where an old one did.
    let in_old = |i: usize| i - lexed.kept_after + lexed.kept_after_old;
    let old_chunk_at = |i: usize| old.chunks.binary_search_by_key(&i, |c| c.tokens.start).ok();
    let (middle, stop) = chunks::split_from(tokens, from, |at| {
        at >= lexed.kept_after && old_chunk_at(in_old(at)).is_some()
    });
    let after = match stop < tokens.len() {
        true => old_chunk_at(in_old(stop)).unwrap_or(old.chunks.len()),
        false => old.chunks.len(),
    };
    let token_delta = lexed.kept_after as isize - lexed.kept_after_old as isize;
    let byte_delta = edit.delta();

    // Each chunk around the edit: found in the previous version, or parsed.
    let mut finder = Finder {
        old_text: &old.text,
        old_chunks: &old.chunks,
        by_hash: None,
    };
    let mut around: Vec<(Range<usize>, Span, Option<Found>)> = Vec::with_capacity(middle.len());
    let mut to_parse: Vec<Range<usize>> = Vec::new();
    // Only the chunks to parse get the text of their tokens back.
    let mut readable: Vec<token::Spanned<'_>> = Vec::new();
    let mut parse_bytes = 0;
    for range in middle {
        let span = Span::new(tokens[range.start].1.start, tokens[range.end - 1].1.end);
        let found = finder.find(text, span, &edit);
        if found.is_none() {
            let start = readable.len();
            readable.extend(
                tokens[range.clone()]
                    .iter()
                    .map(|&(t, s)| (with_text(t, text, s), s)),
            );
            to_parse.push(start..readable.len());
            parse_bytes += span.len();
        }
        around.push((range, span, found));
    }
    let mut parsed =
        parse_ranges(file, text, &readable, &to_parse, parallel(parse_bytes)).into_iter();

    let mut chunks: Vec<CachedChunk> = Vec::with_capacity(old.chunks.len() + around.len());
    chunks.extend_from_slice(&old.chunks[..resume]);
    for (range, span, found) in around {
        let (parsed, hash) = found.unwrap_or_else(|| {
            // `parse_ranges` gives one result per range, in order.
            let result = parsed.next().unwrap_or_default();
            let hash = hash_text(&text[span.range()]);
            (
                Arc::new(ParsedChunk {
                    at: span.start,
                    result,
                }),
                hash,
            )
        });
        chunks.push(CachedChunk {
            tokens: range,
            span,
            hash,
            parsed,
        });
    }
    chunks.extend(old.chunks[after..].iter().map(|c| CachedChunk {
        tokens: c.tokens.start.wrapping_add_signed(token_delta)
            ..c.tokens.end.wrapping_add_signed(token_delta),
        span: c.span.shifted(byte_delta),
        hash: c.hash,
        parsed: c.parsed.clone(),
    }));

    // The parse: every chunk's items and diagnostics where the chunk is now.
    let (item_count, diagnostic_count) = chunks.iter().fold((0, 0), |(i, d), c| {
        (
            i + c.parsed.result.items.len(),
            d + c.parsed.result.diagnostics.len(),
        )
    });
    let mut items = Vec::with_capacity(item_count);
    let mut others = Vec::with_capacity(diagnostic_count);
    for chunk in &chunks {
        let parsed = &chunk.parsed;
        let delta = chunk.span.start as isize - parsed.at as isize;
        let start = items.len();
        items.extend_from_slice(&parsed.result.items);
        let first = others.len();
        others.extend_from_slice(&parsed.result.diagnostics);
        if delta != 0 {
            items[start..].shift_all(delta);
            others[first..].shift_all(delta);
        }
    }
    let diagnostics = assemble_diagnostics(file, &lexed.lexical, others);

    let cache = ParseCache {
        file,
        text: text.into(),
        tokens: lexed.tokens,
        lexical: lexed.lexical,
        chunks,
        reparsed: to_parse.len(),
        relexed: edit.lines_start..edit.new_lines_end,
    };
    let parse = Parse {
        file: ast::SourceFile { items },
        diagnostics,
    };
    (parse, cache)
}

trait ShiftAll {
    fn shift_all(&mut self, delta: isize);
}

impl<T: Shift> ShiftAll for [T] {
    fn shift_all(&mut self, delta: isize) {
        for x in self {
            x.shift(delta);
        }
    }
}

/// Where two versions of a text differ, widened to whole lines.
#[derive(Debug)]
struct Edit {
    /// Bytes that begin both texts alike.
    prefix: usize,
    /// Bytes that end both texts alike, not overlapping `prefix` in either.
    suffix: usize,
    old_len: usize,
    new_len: usize,
    /// The start of the line where the texts first differ (the same offset in
    /// both texts).
    lines_start: usize,
    /// The end (a newline, or the end of the text) of the line where the new
    /// text's differing part ends; after it the texts are alike.
    new_lines_end: usize,
    /// The same place in the old text.
    old_lines_end: usize,
}

impl Edit {
    fn between(old: &str, new: &str) -> Edit {
        let (a, b) = (old.as_bytes(), new.as_bytes());
        let prefix = common_prefix(a, b);
        let room = a.len().min(b.len()) - prefix;
        let suffix = common_suffix(&a[a.len() - room..], &b[b.len() - room..]);
        let lines_start = b[..prefix]
            .iter()
            .rposition(|&c| c == b'\n')
            .map_or(0, |i| i + 1);
        let changed_end = b.len() - suffix;
        let new_lines_end = b[changed_end..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(b.len(), |i| changed_end + i);
        Edit {
            prefix,
            suffix,
            old_len: a.len(),
            new_len: b.len(),
            lines_start,
            new_lines_end,
            old_lines_end: a.len() - (b.len() - new_lines_end),
        }
    }

    /// How far text after the edit moved.
    fn delta(&self) -> isize {
        self.new_len as isize - self.old_len as isize
    }
}

/// The length of the longest common prefix, compared a block at a time.
fn common_prefix(a: &[u8], b: &[u8]) -> usize {
    const BLOCK: usize = 64;
    let n = a.len().min(b.len());
    let mut i = 0;
    while i + BLOCK <= n && a[i..i + BLOCK] == b[i..i + BLOCK] {
        i += BLOCK;
    }
    while i < n && a[i] == b[i] {
        i += 1;
    }
    i
}

/// The length of the longest common suffix, compared a block at a time.
fn common_suffix(a: &[u8], b: &[u8]) -> usize {
    const BLOCK: usize = 64;
    let n = a.len().min(b.len());
    let (a, b) = (&a[a.len() - n..], &b[b.len() - n..]);
    let mut i = 0;
    while i + BLOCK <= n && a[n - i - BLOCK..n - i] == b[n - i - BLOCK..n - i] {
        i += BLOCK;
    }
    while i < n && a[n - i - 1] == b[n - i - 1] {
        i += 1;
    }
    i
}

/// The tokens and lexical diagnostics of a new version.
struct Lexed {
    tokens: Vec<RawToken>,
    lexical: Vec<LexError>,
    /// Tokens kept from before the edited lines (the same in both versions).
    kept_before: usize,
    /// Where the tokens kept from after the edited lines start, in the new
    /// tokens and in the old.
    kept_after: usize,
    kept_after_old: usize,
}

/// The tokens of the new text: the old ones before the edited lines, those
/// lines lexed again, and the old ones after them, moved; the same for the
/// lexical errors.
fn relex(old: &ParseCache, text: &str, edit: &Edit) -> Lexed {
    let kept_before = old.tokens.partition_point(|t| t.1.start < edit.lines_start);
    let kept_after_old = old
        .tokens
        .partition_point(|t| t.1.start < edit.old_lines_end);
    let lines = &text[edit.lines_start..edit.new_lines_end];
    let mut fresh = lex(lines, parallel(lines.len()));
    let fresh_lexical = lexical_errors(&mut fresh);

    let (base, delta) = (edit.lines_start as isize, edit.delta());
    let moved = |s: SimpleSpan, by: isize| {
        SimpleSpan::from(s.start.wrapping_add_signed(by)..s.end.wrapping_add_signed(by))
    };
    let after = &old.tokens[kept_after_old..];
    let mut tokens = Vec::with_capacity(kept_before + fresh.len() + after.len());
    tokens.extend_from_slice(&old.tokens[..kept_before]);
    tokens.extend(
        fresh
            .into_iter()
            .map(|(t, s)| (without_text(t), moved(s, base))),
    );
    let kept_after = tokens.len();
    tokens.extend(after.iter().map(|&(t, s)| (t, moved(s, delta))));

    let lexical_before = old
        .lexical
        .partition_point(|d| d.span.start < edit.lines_start);
    let lexical_after = old
        .lexical
        .partition_point(|d| d.span.start < edit.old_lines_end);
    let mut lexical = old.lexical[..lexical_before].to_vec();
    lexical.extend(fresh_lexical.into_iter().map(|e| e.shifted(base)));
    lexical.extend(
        old.lexical[lexical_after..]
            .iter()
            .map(|e| e.shifted(delta)),
    );
    Lexed {
        tokens,
        lexical,
        kept_before,
        kept_after,
        kept_after_old,
    }
}

/// Finds the parse of a chunk of the previous version with the same text.
struct Finder<'a> {
    old_text: &'a str,
    old_chunks: &'a [CachedChunk],
    /// Old chunks by the hash of their text, built when first needed.
    by_hash: Option<FastMap<u64, usize>>,
}

impl Finder<'_> {
    fn find(&mut self, text: &str, span: Span, edit: &Edit) -> Option<Found> {
        // Wholly before or wholly after the edit: the old chunk at the same
        // place (moved by the edit) has the same text if it has the same length.
        let old_span = if span.end <= edit.prefix {
            Some(span)
        } else if span.start >= edit.new_len - edit.suffix {
            Some(span.shifted(-edit.delta()))
        } else {
            None
        };
        if let Some(old_span) = old_span {
            let at = self
                .old_chunks
                .binary_search_by_key(&old_span.start, |c| c.span.start);
            if let Ok(i) = at
                && self.old_chunks[i].span == old_span
            {
                let c = &self.old_chunks[i];
                return Some((c.parsed.clone(), c.hash));
            }
        }
        let chunk_text = &text[span.range()];
        let hash = hash_text(chunk_text);
        let old_chunks = self.old_chunks;
        let by_hash = self.by_hash.get_or_insert_with(|| {
            let mut map = FastMap::default();
            map.reserve(old_chunks.len());
            for (i, c) in old_chunks.iter().enumerate() {
                map.entry(c.hash).or_insert(i);
            }
            map
        });
        let c = &self.old_chunks[*by_hash.get(&hash)?];
        (self.old_text.get(c.span.range()) == Some(chunk_text)).then(|| (c.parsed.clone(), hash))
    }
}

fn hash_text(text: &str) -> u64 {
    // Deterministic and fast; a collision costs only a comparison of texts.
    let mut hasher = FastHasher::default();
    hasher.write(text.as_bytes());
    hasher.finish()
}

/// `t` with the text it borrows left out (`text[span]` gives it back).
fn without_text(t: Token<'_>) -> Token<'static> {
    match t {
        Token::Ident(_) => Token::Ident(""),
        Token::Number(_) => Token::Number(""),
        Token::Str(_) => Token::Str(""),
        Token::Unterminated(_) => Token::Unterminated(""),
        Token::Kw(k) => Token::Kw(k),
        Token::LBrace => Token::LBrace,
        Token::RBrace => Token::RBrace,
        Token::LParen => Token::LParen,
        Token::RParen => Token::RParen,
        Token::LBracket => Token::LBracket,
        Token::RBracket => Token::RBracket,
        Token::GroupOpen => Token::GroupOpen,
        Token::GroupClose => Token::GroupClose,
        Token::Colon => Token::Colon,
        Token::Semi => Token::Semi,
        Token::Comma => Token::Comma,
        Token::Dot => Token::Dot,
        Token::Assign => Token::Assign,
        Token::EqEq => Token::EqEq,
        Token::NotEq => Token::NotEq,
        Token::Lt => Token::Lt,
        Token::Le => Token::Le,
        Token::Gt => Token::Gt,
        Token::Ge => Token::Ge,
        Token::AndAnd => Token::AndAnd,
        Token::OrOr => Token::OrOr,
        Token::Bang => Token::Bang,
        Token::Error(c) => Token::Error(c),
    }
}

/// `t` (from [`without_text`]) with its text, `text[span]`, back.
fn with_text<'s>(t: Token<'static>, text: &'s str, span: SimpleSpan) -> Token<'s> {
    let written = || text.get(span.start..span.end).unwrap_or_default();
    match t {
        Token::Ident(_) => Token::Ident(written()),
        Token::Number(_) => Token::Number(written()),
        Token::Str(_) => Token::Str(written()),
        Token::Unterminated(_) => Token::Unterminated(written()),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::parse;

    /// Parses `versions` in turn, each with the cache of the one before, and
    /// checks each against a parse from scratch. Returns the last cache.
    fn chain(versions: &[&str]) -> ParseCache {
        let mut cache: Option<ParseCache> = None;
        for text in versions {
            let (incremental, next) = parse_incremental(FileId(3), text, cache.as_ref());
            let scratch = parse(FileId(3), text);
            assert_eq!(incremental.file, scratch.file, "items of {text:?}");
            assert_eq!(
                incremental.diagnostics, scratch.diagnostics,
                "diagnostics of {text:?}"
            );
            cache = Some(next);
        }
        cache.expect("at least one version")
    }

    const MISSION: &str = "{ A: Turtlebot3_Burger tb[2] }\n\
        A.P.S {\n  move(\"1,1\")\n  if (LOCATION == \"1,1\") throw done\n} repeat(1 SEC)\n\
        A.M { set(P, S) }\n\
        A.main {\n  case (M):\n    catch (done): mode = M\n  default: mode = M\n}\n\
        def f {\n  stop()\n}\n";

    #[test]
    fn junk_past_the_diagnostic_limit_parses_incrementally_as_from_scratch() {
        // 150 lexical errors and some grammar errors among them: past the
        // limit either way, and edits move the cut and the E004 count.
        let junk: String = (0..50)
            .map(|i| {
                format!(
                    "@ $$ {} \u{0}\u{0}\n",
                    if i % 7 == 0 { "A.P.S { move( }" } else { "&|" }
                )
            })
            .collect();
        let fewer = junk.replacen("@ $$", "", 30);
        let more = format!("%%\n{junk}\n\"open");
        let versions = [junk.as_str(), &fewer, &more, MISSION, &junk];
        chain(&versions);
        let last = parse(FileId(3), &junk);
        assert_eq!(
            last.diagnostics.len(),
            crate::syntax::MAX_SYNTAX_DIAGNOSTICS + 1
        );
        assert_eq!(
            last.diagnostics.last().map(|d| d.code),
            Some(crate::diag::Code::TooManyProblems)
        );
    }

    #[test]
    fn an_edit_in_one_item_reparses_only_that_chunk() {
        let edited = MISSION.replace("move(\"1,1\")", "move(\"2,2\")");
        let cache = chain(&[MISSION, &edited]);
        assert_eq!(cache.chunks(), 5);
        assert_eq!(cache.reparsed(), 1);
        let line = edited.find("  move").unwrap();
        assert_eq!(cache.relexed(), line..line + "  move(\"2,2\")".len());
    }

    #[test]
    fn a_comment_typed_before_everything_moves_every_chunk() {
        let cache = chain(&[MISSION, &format!("# 한국어 😀\n{MISSION}")]);
        assert_eq!(cache.reparsed(), 0);
        let cache = chain(&[MISSION, &format!("#\n{MISSION}"), MISSION]);
        assert_eq!(cache.reparsed(), 0);
    }

    #[test]
    fn an_edit_inside_a_string() {
        let broken = MISSION.replace("move(\"1,1\")", "move(\"1,1)");
        let cache = chain(&[MISSION, &broken, MISSION]);
        assert_eq!(cache.reparsed(), 1);
        let cache = chain(&[MISSION, &MISSION.replace("\"1,1\"", "\"1,{ 1\"")]);
        assert_eq!(cache.reparsed(), 1);
        // A brace that leaves the string closes the service's body early: the
        // rest of it becomes chunks of its own, `}` and `repeat(1 SEC)`.
        let cache = chain(&[MISSION, &MISSION.replacen("\"1,1\")", "\"1,1\" }\")", 1)]);
        assert_eq!((cache.chunks(), cache.reparsed()), (7, 3));
    }

    #[test]
    fn an_edit_that_merges_two_chunks_and_splits_them_again() {
        // Without its braces the mode is no item: its text joins the service's chunk.
        let merged = MISSION.replace("A.M { set(P, S) }", "A.M ( set(P, S) )");
        let cache = chain(&[MISSION, &merged]);
        assert_eq!(cache.chunks(), 4);
        let cache = chain(&[MISSION, &merged, MISSION]);
        assert_eq!(cache.chunks(), 5);
        assert_eq!(cache.reparsed(), 2);
    }

    #[test]
    fn an_edit_that_splits_a_chunk() {
        let split = MISSION.replace("  stop()\n}", "  stop()\n} def g {\n stop() }");
        let cache = chain(&[MISSION, &split]);
        assert_eq!(cache.chunks(), 6);
        // Unbalancing a brace: the header after it still starts a chunk.
        chain(&[MISSION, &MISSION.replacen('}', "", 1), MISSION]);
        chain(&[MISSION, &MISSION.replacen('{', "", 2), MISSION]);
    }

    #[test]
    fn an_edit_to_a_header_written_over_lines() {
        // Only the brace's line is lexed again, but the chunk start two lines
        // up depends on it: the mode's header stops being one, and its text
        // joins the service's chunk.
        let text = "A.P.S {\n stop() }\nA.M\n{ set(P, S) }\n";
        let cache = chain(&[text, &text.replace("\n{", "\n("), text]);
        assert_eq!(cache.chunks(), 2);
        let text = "A.P.S { stop() }\ndef\nf\n{ stop() }\n";
        chain(&[text, &text.replace("\n{", "\n("), text]);
    }

    #[test]
    fn edits_at_the_very_start_and_end() {
        chain(&[MISSION, &format!("x{MISSION}"), &MISSION[1..], MISSION]);
        chain(&[
            MISSION,
            &format!("{MISSION}x"),
            &MISSION[..MISSION.len() - 2],
        ]);
        let cache = chain(&[MISSION, MISSION.trim_end(), MISSION]);
        assert_eq!(cache.reparsed(), 0);
        chain(&[MISSION, &format!("{MISSION}A.P.T {{"), MISSION]);
    }

    #[test]
    fn deleting_everything_and_typing_it_again() {
        let cache = chain(&[MISSION, "", MISSION]);
        assert_eq!(cache.reparsed(), 5);
        chain(&["", " ", "\n", "{", "{}", "", "😀", "\"", ""]);
    }

    #[test]
    fn a_moved_item_is_found_by_its_text() {
        let (first, rest) = MISSION.split_at(MISSION.find("A.P.S").unwrap());
        let moved = format!("{rest}\n{first}");
        let cache = chain(&[MISSION, &moved]);
        assert_eq!(cache.reparsed(), 0);
    }

    #[test]
    fn a_cache_of_another_file_is_not_used() {
        let (_, cache) = parse_incremental(FileId(1), MISSION, None);
        let (parse_two, cache) = parse_incremental(FileId(2), MISSION, Some(&cache));
        assert_eq!(cache.reparsed(), 5);
        assert_eq!(parse_two.file, parse(FileId(2), MISSION).file);
    }

    #[test]
    fn diagnostics_of_reused_chunks_are_moved_too() {
        let bad = MISSION.replace("stop()", "stop( @ 😀");
        let edited = format!("# x\n{bad}");
        let cache = chain(&[&bad, &edited]);
        assert_eq!(cache.reparsed(), 0);
        let (parse, _) = parse_incremental(FileId(3), &edited, None);
        assert!(parse.diagnostics.len() >= 3, "{:?}", parse.diagnostics);
    }

    #[test]
    fn the_prefix_and_suffix_never_overlap() {
        // "aa" → "aaa": the prefix takes both, nothing is left for the suffix.
        let edit = Edit::between("aa", "aaa");
        assert_eq!((edit.prefix, edit.suffix), (2, 0));
        assert_eq!(edit.delta(), 1);
        let edit = Edit::between("x\nab\ny", "x\nb\ny");
        assert_eq!((edit.prefix, edit.suffix), (2, 3));
        assert_eq!(
            (edit.lines_start, edit.new_lines_end, edit.old_lines_end),
            (2, 3, 4)
        );
        let long = "ab".repeat(100);
        assert_eq!(common_prefix(long.as_bytes(), long.as_bytes()), 200);
        assert_eq!(common_suffix(long.as_bytes(), &long.as_bytes()[1..]), 199);
    }
}
