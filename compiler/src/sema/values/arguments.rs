//! What each parameter is given. The arguments of functions, of composite
//! services and of modes are written in the mission: a call's, a `set`'s
//! or a mode's entry's argument is a literal (a word, a string, a number),
//! something read at run time, or a parameter of the caller passed on (a
//! function's to another function, a mode's to the services it sets). A
//! parameter's possible values are the literals every argument reaching
//! it gives, following the parameters passed on; one argument that is not
//! a literal, or a parameter passed on in a cycle (recursion, an error),
//! makes them unknown.
//!
//! Linear: each parameter is resolved once, from the parameters passed on
//! to it, and holds at most [`MAX_VALUES`] distinct values (past them, its
//! values are unknown: no comparison with it is reported) and its first
//! [`RELATED`] arguments by position, what a finding points at.

use super::RELATED;
use super::literal::Literal;
use crate::fasthash::{FastMap, FastSet};
use crate::sema::ir::ParamOwner;
use crate::span::Span;

/// A parameter: whose, and its place in the list.
type Param = (ParamOwner, u32);

/// Distinct values a parameter is followed with, at most.
const MAX_VALUES: usize = 64;

/// The arguments the walk of the bodies found, as [`Given::new`] reads them.
#[derive(Default)]
pub(in crate::sema) struct Arguments {
    /// (the parameter given it, the literal it is, where): `None` when it
    /// is not a literal (read at run time, an expression, `true`, a period).
    pub literals: Vec<(Param, Option<Literal>, Span)>,
    /// (the parameter passed on, the parameter it is given to).
    pub passed_on: Vec<(Param, Param)>,
}

/// What a parameter is given, as far as the mission says.
#[derive(Clone, Debug)]
pub(in crate::sema) enum Values {
    /// Some argument is not known when the mission is written.
    Unknown,
    /// Every argument is one of `values` (none: nothing gives it one);
    /// `given` the first arguments by position, each with its literal.
    Known {
        values: Vec<Literal>,
        given: Vec<(Span, Literal)>,
    },
}

impl Values {
    fn none() -> Values {
        Values::Known {
            values: Vec::new(),
            given: Vec::new(),
        }
    }

    fn add(&mut self, literal: Option<&Literal>, span: Span) {
        let Some(literal) = literal else {
            *self = Values::Unknown;
            return;
        };
        let Values::Known { values, given } = self else {
            return;
        };
        if !values.contains(literal) {
            if values.len() == MAX_VALUES {
                *self = Values::Unknown;
                return;
            }
            values.push(literal.clone());
        }
        if let Err(at) =
            given.binary_search_by_key(&(span.start, span.end), |(s, _)| (s.start, s.end))
        {
            given.insert(at, (span, literal.clone()));
            given.truncate(RELATED);
        }
    }

    fn merge(&mut self, other: &Values) {
        match other {
            Values::Unknown => *self = Values::Unknown,
            Values::Known { values, given } => {
                for literal in values {
                    // The spans come below; a value past the first
                    // arguments still counts.
                    if let Values::Known { values: mine, .. } = self
                        && !mine.contains(literal)
                    {
                        if mine.len() == MAX_VALUES {
                            *self = Values::Unknown;
                            return;
                        }
                        mine.push(literal.clone());
                    }
                }
                for (span, literal) in given {
                    self.add(Some(literal), *span);
                }
            }
        }
    }
}

/// Each parameter's values, resolved on demand ([`Given::values`]).
pub(in crate::sema) struct Given {
    direct: FastMap<Param, Values>,
    /// The parameters passed on to each parameter.
    sources: FastMap<Param, Vec<Param>>,
    resolved: FastMap<Param, Values>,
}

impl Given {
    pub(in crate::sema) fn new(arguments: Arguments) -> Given {
        let mut direct: FastMap<Param, Values> = FastMap::default();
        for (param, literal, span) in &arguments.literals {
            direct
                .entry(*param)
                .or_insert_with(Values::none)
                .add(literal.as_ref(), *span);
        }
        let mut sources: FastMap<Param, Vec<Param>> = FastMap::default();
        for &(from, to) in &arguments.passed_on {
            sources.entry(to).or_default().push(from);
        }
        Given {
            direct,
            sources,
            resolved: FastMap::default(),
        }
    }

    /// What `param` is given: its own arguments' literals and those of
    /// every parameter passed on to it, transitively. A depth-first walk
    /// with an explicit stack (a chain of functions passing a parameter on
    /// may be as long as the file); a parameter met again on the path is a
    /// cycle, whose values are unknown.
    pub(in crate::sema) fn values(&mut self, param: Param) -> &Values {
        let mut on_path: FastSet<Param> = FastSet::default();
        let mut stack = vec![(param, false)];
        while let Some((p, expanded)) = stack.pop() {
            if expanded {
                let mut values = self.direct.get(&p).cloned().unwrap_or_else(Values::none);
                for from in self.sources.get(&p).into_iter().flatten() {
                    match self.resolved.get(from) {
                        Some(given) => values.merge(given),
                        None => values = Values::Unknown, // on the path: a cycle
                    }
                }
                on_path.remove(&p);
                self.resolved.insert(p, values);
                continue;
            }
            if self.resolved.contains_key(&p) || !on_path.insert(p) {
                continue;
            }
            stack.push((p, true));
            for from in self.sources.get(&p).into_iter().flatten() {
                if !self.resolved.contains_key(from) && !on_path.contains(from) {
                    stack.push((*from, false));
                }
            }
        }
        &self.resolved[&param]
    }
}
