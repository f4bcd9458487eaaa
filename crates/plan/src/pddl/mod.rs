//! PDDL domains and problems (McDermott et al. 1998, PDDL 1.2; Fox & Long
//! 2003, PDDL 2.1 for `:durative-action`) read into the same [`Domain`]
//! the TOML domains give, so that `btfsm plan DOMAIN.pddl --problem
//! PROBLEM.pddl` backchains a PDDL task. The subset and its mapping are
//! documented in docs/guide/plan.md ("PDDL domains"):
//!
//! - `:strips` actions: a precondition that is a conjunction of atoms, an
//!   effect of atoms (added) and `(not atom)` (deleted);
//! - `:typing`: `:types` with supertypes, typed `:constants`, typed
//!   parameters `?x - type`; an object has its type, the type's ancestors
//!   and `object`;
//! - `:durative-actions`: `(at start c)` and `(over all c)` conditions are
//!   preconditions, so is `(at end c)` unless the action's own at-start
//!   effects add `c`; effects are the net change over the action's
//!   duration (at-start effects applied, then at-end ones: an at-start add
//!   an at-end effect deletes is not an effect); the duration is ignored
//!   (every action costs 1);
//! - a problem's `:objects` (with the domain's `:constants`) are the
//!   objects, its `:init` the facts that hold at the start (every other is
//!   false), its `:goal` (a conjunction of atoms) the goal.
//!
//! Any other feature (negative or disjunctive conditions, equality,
//! quantifiers, conditional effects, numeric fluents, ...) is refused
//! where it is used, naming the requirement; declaring a requirement is
//! allowed. Every used predicate is checked against `:predicates` (with a
//! "did you mean" for a near name), every term against the parameters and
//! objects, and its type against the predicate's. The planner grounds the
//! actions on demand; the number of groundings (the product over each
//! action's parameters of the objects of their type) is capped at
//! [`MAX_GROUNDINGS`] up front.

mod read;
pub mod sexpr;

use super::domain::{Action, Domain, Goal, Object, Param, Predicate};
use super::fact::{Fact, Pattern};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::Arc;

/// Most ground actions a domain and problem may give (each action's
/// parameters' object counts multiplied, summed over the actions).
pub const MAX_GROUNDINGS: u64 = 1_000_000;

/// Deepest chain of supertypes in `:types`.
pub const MAX_TYPE_DEPTH: usize = 32;

/// Is this text (of file `path`) PDDL rather than a TOML domain: a `.pddl`
/// file, or text whose first word (after `;` comments) is a `(`?
pub fn looks_like_pddl(path: &str, text: &str) -> bool {
    if path.to_ascii_lowercase().ends_with(".pddl") {
        return true;
    }
    let mut rest = text;
    loop {
        rest = rest.trim_start();
        match rest.strip_prefix(';') {
            Some(r) => rest = r.split_once('\n').map_or("", |(_, after)| after),
            None => return rest.starts_with('('),
        }
    }
}

/// A PDDL domain read and checked, before the objects are known.
#[derive(Debug, Default)]
struct Model {
    name: String,
    /// Declared requirements, implications expanded (`:adl` gives `:typing`).
    requirements: Vec<String>,
    /// Type -> supertype (`object` for a type declared without one).
    types: BTreeMap<String, String>,
    /// Objects (constants, then the problem's objects) -> type.
    objects: BTreeMap<String, String>,
    predicates: Vec<(String, Vec<Param>)>,
    actions: Vec<RawAction>,
}

#[derive(Debug)]
struct RawAction {
    name: String,
    span: Range<usize>,
    params: Vec<Param>,
    pre: Vec<Pattern>,
    add: Vec<Pattern>,
    del: Vec<Pattern>,
}

/// What a problem file gives: its name, objects are added to the model.
#[derive(Debug, Default)]
struct Task {
    name: String,
    init: Vec<Fact>,
    goal: Vec<Fact>,
}

impl Model {
    /// `ty` and its ancestors, ending with `object` (at most
    /// [`MAX_TYPE_DEPTH`] + 2: `:types` is checked acyclic and shallow).
    fn lineage(&self, ty: &str) -> Vec<String> {
        let mut out = vec![ty.to_string()];
        let mut at = ty;
        while let Some(up) = self.types.get(at) {
            if out.len() > MAX_TYPE_DEPTH || out.iter().any(|t| t == up) {
                break;
            }
            out.push(up.clone());
            at = up;
        }
        if !out.iter().any(|t| t == "object") {
            out.push("object".into());
        }
        out
    }

    fn is_subtype(&self, ty: &str, of: &str) -> bool {
        of == "object" || self.lineage(ty).iter().any(|t| t == of)
    }

    fn predicate(&self, name: &str) -> Option<&[Param]> {
        (self.predicates.iter())
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.as_slice())
    }

    /// The number of objects of each type (its subtypes' included).
    fn counts(&self) -> BTreeMap<String, u64> {
        let mut out = BTreeMap::new();
        for ty in self.objects.values() {
            for t in self.lineage(ty) {
                *out.entry(t).or_insert(0) += 1;
            }
        }
        out
    }
}

/// Reads a PDDL domain and, when given, its problem. Without a problem
/// the objects are the domain's constants and the goal is empty (`plan`
/// then needs `--goal`).
pub fn load(
    domain: &Arc<SourceFile>,
    problem: Option<&Arc<SourceFile>>,
) -> Result<Domain, Vec<Diagnostic>> {
    let mut r = read::Reader::new(domain);
    let mut m = r.domain();
    if !r.diags.is_empty() {
        return Err(r.diags);
    }
    let task = match problem {
        Some(p) => {
            let mut r = read::Reader::new(p);
            let t = r.problem(&mut m);
            if !r.diags.is_empty() {
                return Err(r.diags);
            }
            Some(t)
        }
        None => None,
    };
    groundings(&m, domain)?;
    Ok(build(&m, task))
}

/// The ground actions counted against [`MAX_GROUNDINGS`].
fn groundings(m: &Model, file: &Arc<SourceFile>) -> Result<(), Vec<Diagnostic>> {
    let counts = m.counts();
    let mut total: u64 = 0;
    for a in &m.actions {
        let n = (a.params.iter()).fold(1u64, |n, p| {
            n.saturating_mul(counts.get(&p.ty).copied().unwrap_or(0))
        });
        total = total.saturating_add(n);
        if total > MAX_GROUNDINGS {
            return Err(vec![
                Diagnostic::error(format!(
                    "grounding the actions over the objects gives more than {MAX_GROUNDINGS} actions (`{}` alone {n})",
                    a.name
                ))
                .at(file, a.span.clone())
                .hint("fewer objects, or parameters of narrower types: the count is the product of each parameter's objects"),
            ]);
        }
    }
    Ok(())
}

/// The [`Domain`] of a checked model and task, with the names a TOML
/// domain without templates would get.
fn build(m: &Model, task: Option<Task>) -> Domain {
    let objects = (m.objects.iter())
        .map(|(name, ty)| {
            let o = Object {
                types: m.lineage(ty),
                short: name.clone(),
            };
            (name.clone(), o)
        })
        .collect();
    let predicates = (m.predicates.iter())
        .map(|(name, params)| {
            let id = super::validate::default_id(name, params);
            Predicate {
                name: name.clone(),
                skill: Some(format!("{}:{name}", m.name)),
                exclusive: None,
                label: format!("{}?", shown_call(name, params)),
                achieved_id: format!("ensure-{id}"),
                id,
                volatile: false,
                params: params.clone(),
            }
        })
        .collect();
    let actions = (m.actions.iter())
        .map(|a| {
            let id = super::validate::default_id(&a.name, &a.params);
            Action {
                name: a.name.clone(),
                pre: a.pre.clone(),
                add: a.add.clone(),
                del: a.del.clone(),
                cost: 1,
                skill: Some(format!("{}:{}", m.name, a.name)),
                label: format!("{}!", shown_call(&a.name, &a.params)),
                sequence_id: format!("do-{id}"),
                id,
                params: a.params.clone(),
            }
        })
        .collect();
    let task = task.unwrap_or_default();
    Domain {
        name: m.name.clone(),
        description: None,
        objects,
        predicates,
        actions,
        goal: Goal {
            id: if task.name.is_empty() {
                m.name.clone()
            } else {
                task.name
            },
            actions: None,
            facts: task.goal,
            init: task.init,
            ids: BTreeMap::new(),
            labels: BTreeMap::new(),
        },
        tasks: Vec::new(),
    }
}

/// `name {p} {q}`: a label template over the parameters.
fn shown_call(name: &str, params: &[Param]) -> String {
    let mut s = name.to_string();
    for p in params {
        s.push_str(&format!(" {{{}}}", p.name));
    }
    s
}

/// A PDDL atom `(pred a b)` as the fact text `pred(a, b)` (for `--goal`
/// and `--init`); other text is returned as it is.
pub fn fact_text(text: &str) -> String {
    let t = text.trim();
    match t.strip_prefix('(').and_then(|r| r.strip_suffix(')')) {
        Some(inner) if !inner.contains(['(', ')']) => {
            let mut words = inner.split_whitespace();
            let pred = words.next().unwrap_or_default().to_ascii_lowercase();
            let args: Vec<String> = words.map(str::to_ascii_lowercase).collect();
            if args.is_empty() {
                pred
            } else {
                format!("{pred}({})", args.join(", "))
            }
        }
        _ => t.to_string(),
    }
}

#[cfg(test)]
mod tests;
