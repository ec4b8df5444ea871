//! Phase 5: value flow. What each team variable and received value can
//! hold, and when it can have been sent, from the mission alone:
//!
//! - [`comparisons`]: a comparison of a team variable with a constant none
//!   of its writers sets, or of a parameter with a constant none of its
//!   arguments gives ([`arguments`]), decides the same way at every run
//!   (W020, W021);
//! - [`early_reads`]: a value read once, when the mission starts, before
//!   any robot can have sent it (W022);
//! - [`forwarded_once`]: a received value sent on once when its mode starts,
//!   while another plan of the mode keeps receiving it (W023);
//! - [`unfed`]: a receive or subscribe that no robot can ever feed (W024).
//!
//! Every fact is an under-approximation: reported only when it holds at
//! every run the language's meaning allows (`docs/language/`, the
//! simulator's), whatever the scenario does (latencies of zero included),
//! apart from robots killed and restarted. The last three read when
//! services can run ([`timeline`]), so they are left out when the mission
//! has an error: a broken line may be a missing send or catch.

mod arguments;
mod comparisons;
mod early_reads;
mod forwarded_once;
mod literal;
mod timeline;
mod unfed;

pub(super) use arguments::{Arguments, Given};
pub(super) use comparisons::{ParameterTest, VariableTest};
pub(super) use literal::Literal;

use super::Checker;
use super::ir::{AttrKey, TeamId};
use crate::diag::Code;
use crate::span::Span;
use timeline::Timeline;

/// A write of a team variable: `T.X = value` (`value`: `None` when it is
/// not a literal), or `T.X` received from the operator.
#[derive(Clone, Debug)]
pub(super) struct VariableWrite {
    pub key: AttrKey,
    pub value: Option<Literal>,
    pub span: Span,
    /// The team whose robots write it, or take it from the operator (who
    /// may send anything at any time); `None`: a function nobody calls.
    pub team: Option<TeamId>,
}

/// Places named in a finding's related information, at most.
const RELATED: usize = 8;

/// A warning found by a pass, reported once every pass has read the
/// checker's state.
struct Finding {
    code: Code,
    span: Span,
    message: String,
    related: Vec<(Span, String)>,
}

impl Checker<'_> {
    /// `parsed_whole`: the parse reported no error (no line was dropped).
    pub(super) fn check_values(&mut self, parsed_whole: bool) {
        self.check_comparisons();
        if !parsed_whole || self.diagnostics.iter().any(|d| d.is_error()) {
            return;
        }
        let timeline = Timeline::new(&self.mission);
        let mut findings = self.early_reads(&timeline);
        findings.extend(self.forwarded_once(&timeline));
        findings.extend(self.unfed(&timeline));
        for finding in findings {
            let diagnostic = self
                .diagnostics
                .report(finding.code, finding.span, finding.message);
            let mut related = finding.related;
            related.sort_by_key(|(span, _)| (span.start, span.end));
            related.dedup_by_key(|(span, _)| *span);
            for (span, message) in related.into_iter().take(RELATED) {
                diagnostic.relate(span, message);
            }
        }
    }
}

/// `a`, `a or b`, `a, b or c`, each quoted.
fn list(values: &[String]) -> String {
    let quoted: Vec<String> = values.iter().map(|v| format!("`{v}`")).collect();
    match quoted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// The first few names of `names`, then how many more: a message stays
/// short whatever the mission's size.
fn some(names: &[&str]) -> String {
    const SHOWN: usize = 3;
    let shown = names[..names.len().min(SHOWN)].join(", ");
    match names.len().saturating_sub(SHOWN) {
        0 => shown,
        more => format!("{shown} and {more} more"),
    }
}

#[cfg(test)]
mod tests;
