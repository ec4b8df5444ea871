//! Action results (`FOUND, WHERE = search(red)`): the names a function's or
//! a composite service's body binds to what a built-in service's call gives
//! back (`<Result>` in the catalog, `docs/language/services.md`).
//!
//! A body's result names are found from its syntax when it is declared,
//! each at its first binding (its definition), so that a read anywhere in
//! the body resolves to the result whatever the order of the walk; a read
//! written before that binding is W016. Walking a call that binds names
//! checks them against the service (E049: more names than it gives back, a
//! function's call, a name twice, robots giving different results, one name
//! bound to two types) and gives each name its type, the catalog's. A
//! result's name is its own (E045: not a value robots read, a team variable
//! or a parameter of the same body).

use super::Checker;
use super::ir::*;
use crate::catalog::{ResultDef, ServiceDef};
use crate::diag::Code;
use crate::fasthash::FastMap;
use crate::span::Span;
use crate::syntax::ast::{self, Name, StmtKind};

impl<'a> Checker<'a> {
    /// The result names `body` binds, each at its first binding in the
    /// text, recorded there as its definition.
    pub(super) fn declare_results(
        &mut self,
        owner: ParamOwner,
        body: &ast::Block,
    ) -> Vec<ResultInfo> {
        let mut results: Vec<ResultInfo> = Vec::new();
        let mut calls = Vec::new();
        body.walk(&mut |stmt| {
            if let StmtKind::Call(call) = &stmt.kind
                && !call.results.is_empty()
            {
                calls.push(call);
            }
        });
        for call in calls {
            for name in &call.results {
                let key = (owner, name.name.clone());
                if self.result_index.contains_key(&key) {
                    continue;
                }
                self.result_index.insert(key, results.len() as u32);
                let symbol = Symbol::Result {
                    owner,
                    index: results.len() as u32,
                };
                self.occurrence(name.span, symbol, true);
                results.push(ResultInfo {
                    name: name.name.clone(),
                    span: name.span,
                    service: call.name.name.clone(),
                    catalog_name: None,
                    ty: None,
                });
            }
        }
        results
    }

    /// E045: a result named like a value some robot type reads, a team
    /// variable, or a parameter of the body that binds it (one meaning per
    /// name, as for parameters).
    pub(super) fn check_result_names(&mut self) {
        let mut owners: Vec<ParamOwner> = (0..self.mission.functions.len())
            .map(|f| ParamOwner::Function(FunctionId(f as u32)))
            .collect();
        for (t, team) in self.mission.teams.iter().enumerate() {
            let id = TeamId(t as u32);
            owners.extend(team.service_ids().map(|s| ParamOwner::Service(id, s)));
        }
        let mut found = Vec::new();
        for owner in owners {
            for result in self.mission.results(owner) {
                let name = &result.name;
                let hidden = self.hidden_by(name).or_else(|| {
                    let param = self.mission.params(owner).iter().any(|p| &p.name == name);
                    param.then(|| format!("the parameter `{name}`"))
                });
                if let Some(hidden) = hidden {
                    found.push((owner, result.span, name.clone(), hidden));
                }
            }
        }
        for (owner, span, name, hidden) in found {
            let body = self.mission.owner_name(owner);
            let message = format!(
                "the result `{name}` bound in `{body}` would hide {hidden} there: name the result otherwise"
            );
            self.diagnostics
                .report(Code::ParameterHidesName, span, message);
        }
    }

    /// The index of `name` among the results `owner`'s body binds.
    pub(super) fn result_of(&self, owner: ParamOwner, name: &Name) -> Option<u32> {
        self.result_index.get(&(owner, name.clone())).copied()
    }

    /// A function's call that binds names: E049 (functions give nothing back).
    pub(super) fn function_results(&mut self, call: &ast::Call) {
        if let Some(first) = call.results.first() {
            let span = first.span.cover(call.results[call.results.len() - 1].span);
            self.diagnostics.report(
                Code::ResultsNotGiven,
                span,
                format!(
                    "`{}` is a function, which gives nothing back: only a robot's service has results",
                    call.name.name
                ),
            );
        }
    }

    /// The names a built-in service's call binds: checked against the
    /// results of `def` and of every other robot type running the call
    /// (`providers`), each typed as its result.
    pub(super) fn service_results(
        &mut self,
        call: &ast::Call,
        def: &ServiceDef,
        providers: &[(Name, &ServiceDef)],
        owner: Option<ParamOwner>,
    ) {
        if call.results.is_empty() {
            return;
        }
        let mut seen: FastMap<&Name, Span> = FastMap::default();
        let mut again = vec![false; call.results.len()];
        for (k, name) in call.results.iter().enumerate() {
            if let Some(&first) = seen.get(&name.name) {
                again[k] = true;
                self.diagnostics
                    .report(
                        Code::ResultsNotGiven,
                        name.span,
                        format!("`{}` is bound twice by this call", name.name),
                    )
                    .relate(first, "first bound here");
            } else {
                seen.insert(&name.name, name.span);
            }
        }
        if let Some((other, differs)) = providers
            .iter()
            .find(|(_, d)| !same_results(&d.results, &def.results))
        {
            let (first, _) = &providers[0];
            self.diagnostics.report(
                Code::ResultsNotGiven,
                call.name.span,
                format!(
                    "`{}` gives back {} on {first} but {} on {other}: put the call inside `group(instance of {first})`",
                    call.name.name,
                    described(def),
                    described(differs),
                ),
            );
        }
        if call.results.len() > def.results.len() {
            let extra = &call.results[def.results.len()..];
            let span = extra[0].span.cover(extra[extra.len() - 1].span);
            self.diagnostics.report(
                Code::ResultsNotGiven,
                span,
                format!(
                    "`{}` gives back {}, but {} bound",
                    call.name.name,
                    described(def),
                    match call.results.len() {
                        1 => "1 name is".to_string(),
                        n => format!("{n} names are"),
                    }
                ),
            );
        }
        let Some(owner) = owner else { return };
        // A name bound twice in the list is reported once, above: it takes
        // its first result.
        for ((name, result), again) in call.results.iter().zip(&def.results).zip(again) {
            if !again {
                self.bind_result(owner, name, &call.name.name, result);
            }
        }
    }

    /// `name` bound to `result` of `service`: its occurrence, and its type
    /// (E049 when the body binds it to a result of another type too).
    fn bind_result(
        &mut self,
        owner: ParamOwner,
        name: &ast::Ident,
        service: &Name,
        result: &ResultDef,
    ) {
        let Some(&index) = self.result_index.get(&(owner, name.name.clone())) else {
            return;
        };
        let index = index as usize;
        let symbol = Symbol::Result {
            owner,
            index: index as u32,
        };
        let info = &self.mission.results(owner)[index];
        let (first, ty) = (info.span, info.ty.clone());
        if first != name.span {
            self.occurrence(name.span, symbol, false);
        }
        match ty {
            Some(ty) if ty != result.ty => {
                self.diagnostics
                    .report(
                        Code::ResultsNotGiven,
                        name.span,
                        format!(
                            "`{}` is bound to `{}` of `{service}`, a {}, but elsewhere to a {ty}: a result holds one type",
                            name.name, result.name, result.ty
                        ),
                    )
                    .relate(first, "first bound here");
            }
            Some(_) => {}
            None => {
                if let Some(results) = self.mission.results_mut(owner) {
                    let info = &mut results[index];
                    info.ty = Some(result.ty.clone());
                    info.service = service.clone();
                    info.catalog_name = Some(Name::new(&result.name));
                }
            }
        }
    }
}

/// Every call that binds results in `block`, in the order written.
/// Whether two robot types' service gives back the same results (names and
/// types, in order).
fn same_results(a: &[ResultDef], b: &[ResultDef]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.name == y.name && x.ty == y.ty)
}

/// `2 results (FOUND: bool, WHERE: location)` or `nothing`.
fn described(def: &ServiceDef) -> String {
    match def.results.len() {
        0 => "nothing".to_string(),
        1 => format!("1 result ({})", def.results_signature()),
        n => format!("{n} results ({})", def.results_signature()),
    }
}
