//! Parameters of functions (`def go_to(PLACE) { move(PLACE) }`), of
//! composite services (`T.Action.Go(PLACE) { move(PLACE) }`) and of modes
//! (`T.MOVE(TARGET) { set(Action, Go(TARGET)) }`): their names (E044 twice
//! in one list, E045 a name that would hide a value or a team variable),
//! what each body asks of them, and every argument (of a call, of a `set`,
//! of a mode entered) checked against that once every body is walked
//! (E023), W015 for one that is never used. The literals the arguments
//! are, and the parameters passed on, go to the value flow
//! (`values::Given`: W020, W021 for a parameter compared with what no
//! argument gives).
//!
//! A service's parameter is a function's for its body; a mode's parameter
//! has no body: used as the argument of a service in the mode's `set`s, it
//! is passed on to that service's parameter and asks what that one asks.
//!
//! A parameter stands in its body for the argument of the call being run, so
//! a function is the program its calls would be with the argument written in
//! place of the parameter (`docs/language/services.md`). Its type is what its
//! uses ask: passed to a built-in service's parameter, the type that
//! parameter takes; compared with a number or ordered, a number. The body is
//! walked once per set of robots running it (as before parameters), with each
//! parameter typed [`Type::Param`]: the uses are recorded here, the arguments
//! of each call too, and a parameter passed on to another function's
//! parameter asks what that one asks. Checking after the walk keeps the
//! cost linear: each body is walked as often as without parameters, and a
//! parameter's needs are at most one per type a service takes, plus one.

use super::Checker;
use super::body::{ParamRef, Type};
use super::ir::*;
use super::values::{Arguments, Given, Literal};
use crate::diag::Code;
use crate::fasthash::{FastMap, FastSet};
use crate::span::Span;
use crate::syntax::ast::{self, Name};

/// What the walk of the bodies found about parameters.
#[derive(Default)]
pub(super) struct ParamUses {
    /// Each parameter's needs from its own function's body, each kind once.
    own: FastMap<ParamRef, Vec<ParamNeed>>,
    /// A parameter given as the argument of another function's parameter:
    /// (the one given, the one it is given to).
    passed_on: Vec<(ParamRef, ParamRef)>,
    /// The argument of every call walked that is not itself a parameter.
    arguments: Vec<CallArgument>,
    /// The arguments not known when the mission is written that are not
    /// in `arguments` (E047): (the parameter, where).
    unfixed: Vec<(ParamRef, Span)>,
    /// The parameters some body uses.
    used: FastSet<ParamRef>,
}

/// An argument of a function call, a `set` or a mode entered, as the
/// caller's scope typed it.
pub(super) struct CallArgument {
    pub callee: ParamRef,
    pub ty: Type,
    pub span: Span,
    /// The literal it is, as a comparison reads it (`None`: not one), for
    /// the value flow.
    pub literal: Option<Literal>,
}

impl ParamUses {
    /// Records a use of `param` that asks `need` of its argument.
    pub(super) fn need(&mut self, param: ParamRef, need: ParamNeed) {
        let needs = self.own.entry(param).or_default();
        if !needs.iter().any(|n| n.kind == need.kind) {
            needs.push(need);
        }
    }

    pub(super) fn used(&mut self, param: ParamRef) {
        self.used.insert(param);
    }

    /// Records the argument `ty` at `span` of the call of `callee`'s
    /// function (`literal`: the literal it is, if one).
    pub(super) fn argument(
        &mut self,
        callee: ParamRef,
        ty: Type,
        span: Span,
        literal: Option<Literal>,
    ) {
        match ty {
            Type::Param { param, .. } => {
                self.passed_on.push((param, callee));
            }
            ty => self.arguments.push(CallArgument {
                callee,
                ty,
                span,
                literal,
            }),
        }
    }

    /// Records an argument of `callee` not known when the mission is
    /// written (reported E047): nothing is known of what it gives.
    pub(super) fn unfixed(&mut self, callee: ParamRef, span: Span) {
        self.unfixed.push((callee, span));
    }
}

impl<'a> Checker<'a> {
    /// The parameters `list` of `owner` (named `what` in messages), each
    /// name recorded where it is written; a name written twice is E044 (the
    /// first one is the one the body's uses mean).
    pub(super) fn declare_params(
        &mut self,
        owner: ParamOwner,
        what: &str,
        list: &[ast::Ident],
    ) -> Vec<ParamInfo> {
        let mut seen: FastMap<&Name, Span> = FastMap::default();
        let mut params = Vec::with_capacity(list.len());
        for (index, param) in list.iter().enumerate() {
            if let Some(&first) = seen.get(&param.name) {
                self.diagnostics
                    .report(
                        Code::DuplicateParameter,
                        param.span,
                        format!("`{}` is already a parameter of `{what}`", param.name),
                    )
                    .relate(first, "first written here");
            } else {
                seen.insert(&param.name, param.span);
            }
            let symbol = Symbol::Parameter {
                owner,
                index: index as u32,
            };
            self.occurrence(param.span, symbol, true);
            params.push(ParamInfo {
                name: param.name.clone(),
                span: param.span,
                needs: Vec::new(),
            });
        }
        params
    }

    /// Every owner of parameters, in the order declared per kind.
    fn param_owners(&self) -> Vec<ParamOwner> {
        let mut owners: Vec<ParamOwner> = (0..self.mission.functions.len())
            .map(|f| ParamOwner::Function(FunctionId(f as u32)))
            .collect();
        for (t, team) in self.mission.teams.iter().enumerate() {
            let id = TeamId(t as u32);
            owners.extend(
                team.service_ids()
                    .filter(|s| !team.service(*s).params.is_empty())
                    .map(|s| ParamOwner::Service(id, s)),
            );
            owners.extend(TemplateId::all(team.templates.len()).map(|m| ParamOwner::Mode(id, m)));
        }
        owners
    }

    /// What a name declared in a body (a parameter, a result) would hide
    /// there: a value some robot type of the catalog reads, or a team
    /// variable of the mission (E045: one meaning per name).
    pub(super) fn hidden_by(&self, name: &str) -> Option<String> {
        let value_of = self
            .catalog
            .types()
            .find(|(_, r)| r.value(name).is_some())
            .map(|(_, r)| r.name.clone());
        match value_of {
            Some(ty) => Some(format!("the value `{name}` of robot type {ty}")),
            None if self.variables.contains_key(name) => {
                Some(format!("the team variable `{name}`"))
            }
            None => None,
        }
    }

    /// E045: a parameter named like a value some robot type of the catalog
    /// reads, or a team variable of the mission. In the body the bare name
    /// would mean the parameter, so the value could not be read there by
    /// that name, and a reader could not tell which is meant: one meaning
    /// per name.
    pub(super) fn check_parameter_names(&mut self) {
        let mut found = Vec::new();
        for owner in self.param_owners() {
            for param in self.mission.params(owner) {
                if let Some(hidden) = self.hidden_by(&param.name) {
                    found.push((owner, param.span, param.name.clone(), hidden));
                }
            }
        }
        for (owner, span, name, hidden) in found {
            let function = self.mission.owner_name(owner);
            let message = format!(
                "the parameter `{name}` of `{function}` would hide {hidden} in its body: name the parameter otherwise"
            );
            self.diagnostics
                .report(Code::ParameterHidesName, span, message);
        }
    }

    /// Once every body is walked: each parameter's needs (its own and those
    /// of the parameters it is passed on to), recorded in the IR; every
    /// call's argument checked against its parameter's needs (E023 at the
    /// argument, the use as related information); W015 for a parameter no
    /// body uses.
    pub(super) fn check_parameters(&mut self) {
        let uses = std::mem::take(&mut self.param_uses);
        let needs = closed_needs(&uses);
        let owners = self.param_owners();
        for &owner in &owners {
            for (i, param) in self.mission.params_mut(owner).iter_mut().enumerate() {
                param.needs = needs.get(&(owner, i as u32)).cloned().unwrap_or_default();
            }
        }
        let mut reported: FastSet<(Span, Span)> = FastSet::default();
        for argument in &uses.arguments {
            let (owner, index) = argument.callee;
            let Some(param) = self.mission.params(owner).get(index as usize) else {
                continue;
            };
            for need in &param.needs {
                let (fits, asks) = match &need.kind {
                    NeedKind::Argument { service, param, ty } => (
                        argument.ty.fits(ty),
                        format!(
                            "is passed to `{service}`, which expects {} for `{param}`",
                            super::body::describe_param(ty)
                        ),
                    ),
                    NeedKind::Number => (
                        argument.ty.is_numeric(),
                        "is compared as a number".to_string(),
                    ),
                };
                if fits || !reported.insert((argument.span, need.span)) {
                    continue;
                }
                let message = format!(
                    "the parameter `{}` of `{}` {asks}, but this is {}",
                    param.name,
                    self.mission.owner_name(owner),
                    argument.ty.describe()
                );
                self.diagnostics
                    .report(Code::WrongArgumentType, argument.span, message)
                    .relate(need.span, format!("`{}` used here", param.name));
            }
        }
        let mut unused = Vec::new();
        for &owner in &owners {
            let params = self.mission.params(owner);
            for (i, param) in params.iter().enumerate() {
                // A name written twice is E044 already; its uses mean the first.
                let again = params[..i].iter().any(|p| p.name == param.name);
                if !again && !uses.used.contains(&(owner, i as u32)) {
                    unused.push((param.span, param.name.clone(), owner));
                }
            }
        }
        self.given = Some(Given::new(Arguments {
            literals: uses
                .arguments
                .into_iter()
                .map(|a| (a.callee, a.literal, a.span))
                .chain(uses.unfixed.into_iter().map(|(p, span)| (p, None, span)))
                .collect(),
            passed_on: uses.passed_on,
        }));
        for (span, name, owner) in unused {
            let (whose, body) = match owner {
                ParamOwner::Mode(..) => ("mode", "its `set`s"),
                _ => ("", "its body"),
            };
            let owner = self.mission.owner_name(owner);
            self.diagnostics.report(
                Code::ParameterNeverUsed,
                span,
                format!(
                    "the parameter `{name}` of {whose}{}`{owner}` is never used in {body}",
                    if whose.is_empty() { "" } else { " " }
                ),
            );
        }
    }
}

/// Each parameter's needs: its own, then those of every parameter it is
/// passed on to, transitively, each kind once. Walked with an explicit
/// stack (a chain of functions passing one parameter on may be as long as
/// the file), each parameter finished once.
fn closed_needs(uses: &ParamUses) -> FastMap<ParamRef, Vec<ParamNeed>> {
    let mut next: FastMap<ParamRef, Vec<ParamRef>> = FastMap::default();
    for &(from, to) in &uses.passed_on {
        next.entry(from).or_default().push(to);
    }
    let mut done: FastMap<ParamRef, Vec<ParamNeed>> = FastMap::default();
    let mut started: FastSet<ParamRef> = FastSet::default();
    let roots: Vec<ParamRef> = uses.own.keys().chain(next.keys()).copied().collect();
    for root in roots {
        if !started.insert(root) {
            continue;
        }
        // (parameter, whether its successors are finished)
        let mut stack = vec![(root, false)];
        while let Some((param, expanded)) = stack.pop() {
            if expanded {
                let mut needs = uses.own.get(&param).cloned().unwrap_or_default();
                for to in next.get(&param).into_iter().flatten() {
                    // A successor still open is a cycle: recursion, which
                    // the walk reports (E029); it adds nothing here.
                    for need in done.get(to).into_iter().flatten() {
                        if !needs.iter().any(|n| n.kind == need.kind) {
                            needs.push(need.clone());
                        }
                    }
                }
                done.insert(param, needs);
                continue;
            }
            stack.push((param, true));
            for &to in next.get(&param).into_iter().flatten() {
                if started.insert(to) {
                    stack.push((to, false));
                }
            }
        }
    }
    done
}
