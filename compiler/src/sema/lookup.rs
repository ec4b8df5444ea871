//! Lookups shared by the features: in [`Mission::occurrences`], which sema
//! keeps sorted by span, and in the file's items, which are in file order.
//!
//! Every occurrence is the range of one identifier token, so two occurrences
//! either share their span (one name meaning several symbols: the robots of
//! `tb[3]`, or a function body inlined for several teams) or do not overlap.

use super::CheckedMission;
use super::{Mission, Occurrence, Symbol, TeamId};
use crate::span::Span;
use crate::syntax::ast::{Item, SourceFile};

/// The occurrences of the name at `offset` (containing it, or ending right
/// there: a cursor just after a name), all with the same span.
pub(crate) fn at(mission: &Mission, offset: usize) -> &[Occurrence] {
    let occurrences = &mission.occurrences;
    let after = occurrences.partition_point(|o| o.span.start <= offset);
    let Some(last) = after.checked_sub(1) else {
        return &[];
    };
    let span = occurrences[last].span;
    if !span.touches(offset) {
        return &[];
    }
    with_span(mission, span)
}

/// The occurrences whose span is exactly `span`.
pub(crate) fn with_span(mission: &Mission, span: Span) -> &[Occurrence] {
    let occurrences = &mission.occurrences;
    let key = |o: &Occurrence| (o.span.start, o.span.end);
    let start = occurrences.partition_point(|o| key(o) < (span.start, span.end));
    let len = occurrences[start..]
        .iter()
        .take_while(|o| o.span == span)
        .count();
    &occurrences[start..start + len]
}

/// The distinct symbols of `occurrences`, in order.
pub(crate) fn symbols(occurrences: &[Occurrence]) -> Vec<Symbol> {
    let mut symbols: Vec<Symbol> = Vec::new();
    for o in occurrences {
        if !symbols.contains(&o.symbol) {
            symbols.push(o.symbol.clone());
        }
    }
    symbols
}

/// The occurrences that overlap `range` (a run of the sorted list).
pub(crate) fn in_range(mission: &Mission, range: Span) -> &[Occurrence] {
    let occurrences = &mission.occurrences;
    let start = occurrences.partition_point(|o| o.span.end <= range.start);
    let end = occurrences.partition_point(|o| o.span.start < range.end);
    occurrences.get(start..end.max(start)).unwrap_or(&[])
}

/// The item at `offset` (containing it, or ending right there), with its index.
pub(crate) fn item_at(file: &SourceFile, offset: usize) -> Option<(usize, &Item)> {
    let after = file.items.partition_point(|i| i.span().start <= offset);
    let index = after.checked_sub(1)?;
    let item = &file.items[index];
    item.span().touches(offset).then_some((index, item))
}

/// The team whose service, mode or main block holds `offset`.
pub(crate) fn enclosing_team(analysis: &CheckedMission, offset: usize) -> Option<TeamId> {
    let team = match item_at(&analysis.syntax, offset)?.1 {
        Item::Service(s) => &s.team,
        Item::Mode(m) => &m.team,
        Item::Main(m) => &m.team,
        Item::Formation(_) | Item::Function(_) | Item::Error(_) => return None,
    };
    analysis.mission.team_by_name(&team.name)
}
