//! The containers and `add` calls of a FlexBE behavior's `create` method,
//! read from its Python syntax tree (flexbe_core's `Behavior.create`,
//! `OperatableStateMachine.add`, `ConcurrencyContainer(conditions=...)`;
//! the generated layout is the FlexBE App's `code_generator.js`). Only the
//! literal shapes the generator writes are accepted; anything else inside a
//! `with` block is an error naming what is valid.

use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_core::sanitize::shown;
use rustpython_parser::ast::{self, Constant, Expr, Ranged, Stmt};
use std::ops::Range;
use std::sync::Arc;

/// The container classes a `create` method builds.
pub(super) const CONTAINER_CLASSES: [&str; 5] = [
    "OperatableStateMachine",
    "ConcurrencyContainer",
    "PriorityContainer",
    "LockableStateMachine",
    "PreemptableStateMachine",
];

/// How a container runs its states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// One state at a time (`OperatableStateMachine`, `PriorityContainer`).
    Sequential,
    /// All at once (`ConcurrencyContainer`).
    Concurrent,
}

/// A container variable defined in `create`.
#[derive(Debug)]
pub(super) struct Container {
    pub(super) var: String,
    pub(super) kind: Kind,
    pub(super) outcomes: Vec<String>,
    /// A `ConcurrencyContainer`'s `(outcome, [(state, state outcome)])`,
    /// each with its span.
    pub(super) conditions: Conditions,
    pub(super) span: Range<usize>,
    pub(super) adds: Vec<Add>,
}

/// One `add('Label', STATE, transitions, autonomy, ...)` call.
#[derive(Debug)]
pub(super) struct Add {
    pub(super) name: String,
    pub(super) name_span: Range<usize>,
    pub(super) state: StateRef,
    /// `(outcome, target, span of the target)`, in file order.
    pub(super) transitions: Vec<(String, String, Range<usize>)>,
    /// `(outcome, level)`, in file order.
    pub(super) autonomy: Vec<(String, String)>,
}

/// What an `add` adds.
#[derive(Debug)]
pub(super) enum StateRef {
    /// A container variable, with the span of its name.
    Container(String, Range<usize>),
    /// Any other state (a state class instance, an embedded behavior).
    Task,
}

/// The variable `create` returns, with the span of the `return`.
type Returned = (String, Range<usize>);

/// What `create` builds.
#[derive(Debug)]
pub(super) struct Behavior {
    /// `self.name = '...'` in `__init__`, else the class name.
    pub(super) name: String,
    pub(super) description: Option<String>,
    /// In definition order.
    pub(super) containers: Vec<Container>,
    /// The variable `create` returns, with the span of the `return`.
    pub(super) top: Returned,
}

pub(super) fn span(r: &impl Ranged) -> Range<usize> {
    r.start().to_usize()..r.end().to_usize()
}

struct Cx<'a> {
    file: &'a Arc<SourceFile>,
    diags: &'a mut Vec<Diagnostic>,
}

impl Cx<'_> {
    fn err(&mut self, at: Range<usize>, msg: String, hint: &str) {
        self.diags
            .push(Diagnostic::error(msg).at(self.file, at).hint(hint));
    }

    fn unsupported(&mut self, at: Range<usize>, what: &str, valid: &str) {
        self.err(
            at,
            format!("unsupported construct {what}"),
            &format!("valid: {valid}"),
        );
    }
}

/// Reads the behavior class of a module: `None` (with errors) when it has
/// none or its `create` is not of the generated shape.
pub(super) fn collect(
    module: &[Stmt],
    file: &Arc<SourceFile>,
    diags: &mut Vec<Diagnostic>,
) -> Option<Behavior> {
    let mut cx = Cx { file, diags };
    let class = module.iter().find_map(|s| match s {
        Stmt::ClassDef(c) if c.bases.iter().any(|b| last_name(b) == Some("Behavior")) => Some(c),
        _ => None,
    });
    let Some(class) = class else {
        cx.diags.push(
            Diagnostic::error("no FlexBE behavior here: no class derives `Behavior`")
                .in_file(file)
                .hint("a FlexBE behavior is `class NameSM(Behavior):` with a `create(self)` method that returns its state machine"),
        );
        return None;
    };
    let method = |n: &str| {
        class.body.iter().find_map(|s| match s {
            Stmt::FunctionDef(f) if f.name.as_str() == n => Some(f),
            _ => None,
        })
    };
    let Some(create) = method("create") else {
        cx.err(
            span(class),
            format!(
                "behavior class `{}` has no `create` method",
                shown(&class.name)
            ),
            "FlexBE's `Behavior.create(self)` builds and returns the state machine",
        );
        return None;
    };
    let name = method("__init__")
        .and_then(|f| behavior_name(&f.body))
        .unwrap_or_else(|| class.name.to_string());
    let description = docstring(&class.body);
    let (containers, top) = read_create(&mut cx, &create.body, span(create))?;
    Some(Behavior {
        name,
        description,
        containers,
        top,
    })
}

/// The containers defined and filled in `create`, and the one returned.
fn read_create(
    cx: &mut Cx<'_>,
    body: &[Stmt],
    create: Range<usize>,
) -> Option<(Vec<Container>, Returned)> {
    let mut containers: Vec<Container> = Vec::new();
    let mut top = None;
    for s in body {
        match s {
            Stmt::Assign(a) => {
                let [Expr::Name(target)] = a.targets.as_slice() else {
                    continue;
                };
                let Expr::Call(call) = &*a.value else {
                    continue;
                };
                let Some(class) = last_name(&call.func).filter(|c| CONTAINER_CLASSES.contains(c))
                else {
                    continue;
                };
                if let Some(c) = container(cx, target.id.as_str(), class, call, span(a)) {
                    // A variable bound again names the new container.
                    containers.retain(|old| old.var != c.var);
                    containers.push(c);
                }
            }
            Stmt::With(w) => with_block(cx, w, &mut containers),
            Stmt::Return(r) => match r.value.as_deref() {
                Some(Expr::Name(n)) => top = Some((n.id.to_string(), span(r))),
                _ => cx.unsupported(
                    span(r),
                    "`return` of something other than a container variable",
                    "`return _state_machine`",
                ),
            },
            Stmt::Expr(e) if is_add(&e.value) => cx.err(
                span(s),
                "`add` outside a `with` block".into(),
                "states are added inside `with CONTAINER:`, which opens the container",
            ),
            _ => {}
        }
    }
    if top.is_none() && !cx.diags.iter().any(Diagnostic::is_error) {
        cx.err(
            create,
            "`create` returns no state machine".into(),
            "end `create` with `return _state_machine`",
        );
    }
    top.map(|t| (containers, t))
}

/// Is this expression an `X.add(...)` call?
fn is_add(e: &Expr) -> bool {
    matches!(e, Expr::Call(c) if matches!(&*c.func, Expr::Attribute(a) if a.attr.as_str() == "add"))
}

/// A container constructor call.
fn container(
    cx: &mut Cx<'_>,
    var: &str,
    class: &str,
    call: &ast::ExprCall,
    at: Range<usize>,
) -> Option<Container> {
    let kind = if class == "ConcurrencyContainer" {
        Kind::Concurrent
    } else {
        Kind::Sequential
    };
    // `OperatableStateMachine(outcomes, ...)`; a ConcurrencyContainer's
    // first positional parameter is `conditions`.
    let outcomes_expr = keyword(call, "outcomes").or_else(|| {
        (kind == Kind::Sequential)
            .then(|| call.args.first())
            .flatten()
    });
    let Some(outcomes_expr) = outcomes_expr else {
        cx.unsupported(
            span(call),
            &format!("`{class}` without `outcomes`"),
            &format!("`{class}(outcomes=['finished', 'failed'])`"),
        );
        return None;
    };
    let outcomes = string_list(cx, outcomes_expr, "outcomes")?;
    let mut conditions = Vec::new();
    if kind == Kind::Concurrent
        && let Some(c) = keyword(call, "conditions")
    {
        conditions = read_conditions(cx, c)?;
    }
    Some(Container {
        var: var.to_string(),
        kind,
        outcomes,
        conditions,
        span: at,
        adds: Vec::new(),
    })
}

/// A ConcurrencyContainer's `conditions=[('outcome', [('State',
/// 'state outcome'), ...]), ...]`.
pub(super) type Conditions = Vec<(String, Vec<(String, String)>, Range<usize>)>;

fn read_conditions(cx: &mut Cx<'_>, e: &Expr) -> Option<Conditions> {
    let valid = "`conditions=[('finished', [('State', 'done')]), ...]`";
    let Expr::List(list) = e else {
        cx.unsupported(span(e), "in `conditions` (not a list literal)", valid);
        return None;
    };
    let mut out = Vec::new();
    for item in &list.elts {
        let parsed = match item {
            Expr::Tuple(t) if t.elts.len() == 2 => match (string(&t.elts[0]), &t.elts[1]) {
                (Some(o), Expr::List(reqs)) => reqs
                    .elts
                    .iter()
                    .map(|r| match r {
                        Expr::Tuple(p) if p.elts.len() == 2 => {
                            Some((string(&p.elts[0])?, string(&p.elts[1])?))
                        }
                        _ => None,
                    })
                    .collect::<Option<Vec<_>>>()
                    .map(|r| (o, r)),
                _ => None,
            },
            _ => None,
        };
        match parsed {
            Some((o, r)) => out.push((o, r, span(item))),
            None => {
                cx.unsupported(span(item), "in `conditions`", valid);
                return None;
            }
        }
    }
    Some(out)
}

/// The `add` calls of a `with CONTAINER:` block, onto that container.
fn with_block(cx: &mut Cx<'_>, w: &ast::StmtWith, containers: &mut [Container]) {
    let var = match w.items.as_slice() {
        [item] if item.optional_vars.is_none() => match &item.context_expr {
            Expr::Name(n) => Some((n.id.as_str(), span(&item.context_expr))),
            _ => None,
        },
        _ => None,
    };
    let Some((var, var_span)) = var else {
        cx.unsupported(
            span(w),
            "`with` of something other than one container variable",
            "`with _state_machine:` around the `OperatableStateMachine.add(...)` calls",
        );
        return;
    };
    let Some(ci) = containers.iter().position(|c| c.var == var) else {
        cx.err(
            var_span,
            format!("`{}` is not a container defined before", shown(var)),
            "define it first: `VAR = OperatableStateMachine(outcomes=[...])`",
        );
        return;
    };
    let names: Vec<String> = containers.iter().map(|c| c.var.clone()).collect();
    for s in &w.body {
        match s {
            Stmt::Expr(e) if is_add(&e.value) => {
                let Expr::Call(call) = &*e.value else {
                    continue;
                };
                if let Some(add) = read_add(cx, call, &names) {
                    containers[ci].adds.push(add);
                }
            }
            Stmt::Pass(_) => {}
            _ => cx.unsupported(
                span(s),
                "inside a `with` block",
                "`OperatableStateMachine.add('Name', State(...), transitions={...}, autonomy={...})` statements",
            ),
        }
    }
}

/// One `add(label, state, transitions, autonomy, remapping)` call.
fn read_add(cx: &mut Cx<'_>, call: &ast::ExprCall, containers: &[String]) -> Option<Add> {
    let arg = |i: usize, k: &str| keyword(call, k).or_else(|| call.args.get(i));
    let valid = "`OperatableStateMachine.add('Name', State(...), transitions={'done': 'Next'}, autonomy={'done': Autonomy.Off})`";
    let (Some(label), Some(state)) = (arg(0, "label"), arg(1, "state")) else {
        cx.unsupported(span(call), "`add` without a label and a state", valid);
        return None;
    };
    let Some(name) = string(label) else {
        cx.unsupported(
            span(label),
            "as a state label (not a string literal)",
            valid,
        );
        return None;
    };
    let state = match state {
        Expr::Name(n) if containers.iter().any(|c| c == n.id.as_str()) => {
            StateRef::Container(n.id.to_string(), span(state))
        }
        _ => StateRef::Task,
    };
    let transitions = match arg(2, "transitions") {
        // A state whose transitions are not literals is still a state
        // (its error is said once, not again at each transition to it).
        Some(t) => string_dict(cx, t, "transitions").unwrap_or_default(),
        None => {
            cx.unsupported(span(call), "`add` without `transitions`", valid);
            return None;
        }
    };
    let autonomy = match arg(3, "autonomy") {
        Some(Expr::Dict(d)) => d
            .keys
            .iter()
            .zip(&d.values)
            .filter_map(|(k, v)| Some((string(k.as_ref()?)?, level(cx, v))))
            .collect(),
        _ => Vec::new(),
    };
    Some(Add {
        name,
        name_span: span(label),
        state,
        transitions,
        autonomy,
    })
}

/// An autonomy level: `Autonomy.Low` is `Low`; other expressions their
/// source text (cut).
fn level(cx: &Cx<'_>, e: &Expr) -> String {
    match e {
        Expr::Attribute(a) => a.attr.to_string(),
        _ => {
            let text = cx.file.text.get(span(e)).unwrap_or("?");
            shown(text).chars().take(24).collect()
        }
    }
}

/// A keyword argument of a call.
fn keyword<'a>(call: &'a ast::ExprCall, name: &str) -> Option<&'a Expr> {
    call.keywords
        .iter()
        .find(|k| k.arg.as_ref().is_some_and(|a| a.as_str() == name))
        .map(|k| &k.value)
}

/// A string literal's value.
fn string(e: &Expr) -> Option<String> {
    match e {
        Expr::Constant(ast::ExprConstant {
            value: Constant::Str(s),
            ..
        }) => Some(s.clone()),
        _ => None,
    }
}

/// A list (or tuple) of string literals.
fn string_list(cx: &mut Cx<'_>, e: &Expr, what: &str) -> Option<Vec<String>> {
    let elts = match e {
        Expr::List(l) => &l.elts,
        Expr::Tuple(t) => &t.elts,
        _ => {
            cx.unsupported(
                span(e),
                &format!("as `{what}` (not a list literal)"),
                "a list of strings: `['finished', 'failed']`",
            );
            return None;
        }
    };
    let mut out = Vec::with_capacity(elts.len());
    for x in elts {
        match string(x) {
            Some(s) => out.push(s),
            None => {
                cx.unsupported(
                    span(x),
                    &format!("in `{what}` (not a string literal)"),
                    "a list of strings: `['finished', 'failed']`",
                );
                return None;
            }
        }
    }
    Some(out)
}

/// A dict literal from strings to strings, with the span of each value.
fn string_dict(
    cx: &mut Cx<'_>,
    e: &Expr,
    what: &str,
) -> Option<Vec<(String, String, Range<usize>)>> {
    let valid = "a dict of strings: `{'done': 'Next_State', 'failed': 'failed'}`";
    let Expr::Dict(d) = e else {
        cx.unsupported(span(e), &format!("as `{what}` (not a dict literal)"), valid);
        return None;
    };
    let mut out = Vec::with_capacity(d.values.len());
    for (k, v) in d.keys.iter().zip(&d.values) {
        match (k.as_ref().and_then(string), string(v)) {
            (Some(k), Some(t)) => out.push((k, t, span(v))),
            _ => {
                let at = k
                    .as_ref()
                    .map_or_else(|| span(v), |k| span(k).start..span(v).end);
                cx.unsupported(at, &format!("in `{what}` (not a string literal)"), valid);
                return None;
            }
        }
    }
    Some(out)
}

/// The name an expression ends in: `Behavior`, `flexbe_core.Behavior`.
fn last_name(e: &Expr) -> Option<&str> {
    match e {
        Expr::Name(n) => Some(n.id.as_str()),
        Expr::Attribute(a) => Some(a.attr.as_str()),
        _ => None,
    }
}

/// `self.name = '...'` in `__init__`.
fn behavior_name(body: &[Stmt]) -> Option<String> {
    body.iter().find_map(|s| match s {
        Stmt::Assign(a) => match a.targets.as_slice() {
            [Expr::Attribute(t)]
                if t.attr.as_str() == "name"
                    && matches!(&*t.value, Expr::Name(n) if n.id.as_str() == "self") =>
            {
                string(&a.value)
            }
            _ => None,
        },
        _ => None,
    })
}

/// A class's docstring, trimmed.
fn docstring(body: &[Stmt]) -> Option<String> {
    match body.first()? {
        Stmt::Expr(e) => string(&e.value)
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty()),
        _ => None,
    }
}
