//! The sections of a PDDL domain (`:requirements`, `:types`, `:constants`,
//! `:predicates`, `:action`, `:durative-action`) and problem (`:domain`,
//! `:objects`, `:init`, `:goal`) read from S-expressions into a checked
//! [`Model`] and [`Task`], every problem reported with its position. The
//! grammar is PDDL 1.2's (McDermott et al. 1998, BNF of sec. 2-4) and PDDL
//! 2.1's durative actions (Fox & Long 2003, sec. 5); the subset kept is in
//! `super`'s doc.

use super::sexpr::{self, Sexp};
use super::{MAX_TYPE_DEPTH, Model, RawAction, Task};
use crate::domain::{MAX_DECLARATIONS, MAX_SIBLINGS, Param};
use crate::fact::{self, Pattern};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_core::sanitize::shown;
use std::ops::Range;
use std::sync::Arc;

/// Every requirement flag of PDDL 3.1.
const REQUIREMENTS: &[&str] = &[
    ":strips",
    ":typing",
    ":negative-preconditions",
    ":disjunctive-preconditions",
    ":equality",
    ":existential-preconditions",
    ":universal-preconditions",
    ":quantified-preconditions",
    ":conditional-effects",
    ":fluents",
    ":numeric-fluents",
    ":object-fluents",
    ":adl",
    ":durative-actions",
    ":duration-inequalities",
    ":continuous-effects",
    ":derived-predicates",
    ":timed-initial-literals",
    ":preferences",
    ":constraints",
    ":action-costs",
];

const SUPPORTED: &str = "btfsm plan reads STRIPS and durative actions: conditions are conjunctions of atoms, effects atoms and `(not atom)` (docs/guide/plan.md, \"PDDL domains\")";

/// Most errors reported per file (each a suggestion's work).
const MAX_ERRORS: usize = 100;

/// When a condition must hold or an effect happens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum When {
    Start,
    All,
    End,
}

/// A typed name: name (without `?`), its span, its type and the type's span.
type Typed = (String, Range<usize>, String, Range<usize>);

pub(super) struct Reader {
    file: Arc<SourceFile>,
    pub(super) diags: Vec<Diagnostic>,
}

impl Reader {
    pub(super) fn new(file: &Arc<SourceFile>) -> Self {
        Reader {
            file: file.clone(),
            diags: Vec::new(),
        }
    }

    fn err(&mut self, span: Range<usize>, msg: impl Into<String>, hint: impl Into<String>) {
        if self.diags.len() > MAX_ERRORS {
            return;
        }
        let d = if self.diags.len() == MAX_ERRORS {
            Diagnostic::error(format!(
                "more than {MAX_ERRORS} errors; the rest are not shown"
            ))
            .in_file(&self.file)
            .hint("fix these first")
        } else {
            Diagnostic::error(msg).at(&self.file, span).hint(hint)
        };
        self.diags.push(d);
    }

    /// Has the error cap been reached (no more checking worth its work)?
    fn full(&self) -> bool {
        self.diags.len() > MAX_ERRORS
    }

    /// A feature `btfsm plan` does not read, named with its requirement.
    fn refuse(&mut self, span: Range<usize>, what: &str, req: &str) {
        self.err(
            span,
            format!("{what} needs `{req}`, which `btfsm plan` does not support"),
            SUPPORTED,
        );
    }

    /// The file's one `(define (KIND NAME) SECTION...)`: NAME and the sections.
    fn define<'s>(&mut self, top: &'s [Sexp], kind: &str) -> Option<(String, &'s [Sexp])> {
        let want = format!("a PDDL {kind} is `(define ({kind} NAME) ...)`");
        let Some(first) = top.first() else {
            self.err(
                0..0,
                format!("no `(define ({kind} ...))` in the file"),
                want,
            );
            return None;
        };
        if let Some(extra) = top.get(1) {
            self.err(extra.span(), "text after the `(define ...)`", want.clone());
            return None;
        }
        let items = first.list().unwrap_or_default();
        let head = items.get(1).and_then(Sexp::list).unwrap_or_default();
        let name = match (first.head(), head) {
            (Some("define"), [k, n]) if k.atom() == Some(kind) => n,
            _ => {
                self.err(first.span(), format!("not a PDDL {kind}"), want);
                return None;
            }
        };
        let text = name.atom().unwrap_or_default();
        if !fact::is_name(text) {
            self.err(
                name.span(),
                format!("{kind} name `{}` is not a name", shown(text)),
                "letters, digits, `-` and `_`",
            );
            return None;
        }
        Some((text.to_string(), &items[2..]))
    }

    /// Reads the domain file.
    pub(super) fn domain(&mut self) -> Model {
        let top = match sexpr::read(&self.file) {
            Ok(t) => t,
            Err(d) => {
                self.diags.push(d);
                return Model::default();
            }
        };
        let Some((name, sections)) = self.define(&top, "domain") else {
            return Model::default();
        };
        let mut m = Model {
            name,
            requirements: vec![":strips".into()],
            ..Model::default()
        };
        let mut by_key: Vec<(&str, &Sexp)> = Vec::new();
        let mut actions = Vec::new();
        for s in sections {
            match s.head() {
                Some(k @ (":requirements" | ":types" | ":constants" | ":predicates")) => {
                    if by_key.iter().any(|(seen, _)| *seen == k) {
                        self.err(s.span(), format!("a second `{k}` section"), "merge them");
                    }
                    by_key.push((k, s));
                }
                Some(":functions") => {}
                Some(":action" | ":durative-action") => actions.push(s),
                Some(":derived") => self.refuse(s.span(), "`:derived`", ":derived-predicates"),
                Some(":constraints") => self.refuse(s.span(), "`:constraints`", ":constraints"),
                other => {
                    let keys = [
                        ":requirements",
                        ":types",
                        ":constants",
                        ":predicates",
                        ":functions",
                        ":action",
                        ":durative-action",
                    ];
                    self.err(
                        s.span(),
                        format!("unknown domain section `{}`", shown(other.unwrap_or("("))),
                        suggest(other.unwrap_or(""), keys),
                    );
                }
            }
        }
        for key in [":requirements", ":types", ":constants", ":predicates"] {
            if let Some((_, s)) = by_key.iter().find(|(k, _)| *k == key) {
                let items = &s.list().unwrap_or_default()[1..];
                match key {
                    ":requirements" => self.requirements(items, &mut m),
                    ":types" => self.types(items, &mut m),
                    ":constants" => self.objects(items, &mut m, "constant"),
                    _ => self.predicates(items, &mut m),
                }
            }
        }
        if actions.len() > MAX_DECLARATIONS {
            self.err(
                actions[MAX_DECLARATIONS].span(),
                format!("more than {MAX_DECLARATIONS} actions"),
                "split the domain",
            );
            return m;
        }
        for a in actions {
            if let Some(a) = self.action(a, &m) {
                if m.actions.iter().any(|b| b.name == a.name) {
                    self.err(
                        a.span.clone(),
                        format!("a second action `{}`", a.name),
                        "each action has its own name",
                    );
                }
                m.actions.push(a);
            }
        }
        m
    }

    fn requirements(&mut self, items: &[Sexp], m: &mut Model) {
        m.requirements.clear();
        for r in items {
            let Some(name) = r.atom().filter(|a| REQUIREMENTS.contains(a)) else {
                let text = r.atom().unwrap_or("(");
                self.err(
                    r.span(),
                    format!("unknown requirement `{}`", shown(text)),
                    suggest(text, REQUIREMENTS.iter().copied()),
                );
                continue;
            };
            let implied: &[&str] = match name {
                ":adl" => &[
                    ":strips",
                    ":typing",
                    ":negative-preconditions",
                    ":disjunctive-preconditions",
                    ":equality",
                    ":existential-preconditions",
                    ":universal-preconditions",
                    ":conditional-effects",
                ],
                ":quantified-preconditions" => {
                    &[":existential-preconditions", ":universal-preconditions"]
                }
                ":fluents" => &[":numeric-fluents", ":object-fluents"],
                _ => &[],
            };
            for r in std::iter::once(&name).chain(implied) {
                if !m.requirements.iter().any(|x| x == r) {
                    m.requirements.push((*r).to_string());
                }
            }
        }
    }

    /// `names - type names - type names`: each name with its type (`object`
    /// when none is given), variables (`?x`) without their `?`.
    fn typed_list(&mut self, items: &[Sexp], vars: bool, m: &Model) -> Vec<Typed> {
        let mut pending: Vec<(String, Range<usize>)> = Vec::new();
        let mut out = Vec::new();
        let mut i = 0;
        while i < items.len() {
            let it = &items[i];
            i += 1;
            match it.atom() {
                Some("-") => {
                    if !m.requirements.iter().any(|r| r == ":typing") {
                        self.err(
                            it.span(),
                            "`- type` needs `:typing` in `:requirements`",
                            "add `:typing` to `(:requirements ...)`",
                        );
                    }
                    match items.get(i) {
                        Some(Sexp::Atom(t, span)) => {
                            for (n, s) in pending.drain(..) {
                                out.push((n, s, t.clone(), span.clone()));
                            }
                        }
                        Some(l @ Sexp::List(..)) => {
                            self.err(
                                l.span(),
                                "`(either ...)` types are not supported",
                                "give each name one type (declare a common supertype)",
                            );
                            pending.clear();
                        }
                        None => self.err(it.span(), "`-` is followed by no type", "write `- TYPE`"),
                    }
                    i += 1;
                }
                Some(a) => {
                    let name = if vars {
                        match a.strip_prefix('?') {
                            Some(n) => n,
                            None => {
                                self.err(
                                    it.span(),
                                    format!("`{}` is not a variable", shown(a)),
                                    "a parameter is `?name`",
                                );
                                continue;
                            }
                        }
                    } else {
                        a
                    };
                    if fact::is_name(name) {
                        pending.push((name.to_string(), it.span()));
                    } else {
                        self.err(
                            it.span(),
                            format!("`{}` is not a name", shown(a)),
                            "letters, digits, `-` and `_`",
                        );
                    }
                }
                None => self.err(it.span(), "expected a name, found a list", "write names"),
            }
        }
        for (n, s) in pending {
            out.push((n, s.clone(), "object".into(), s));
        }
        out
    }

    /// Is `ty` a declared type (or `object`)? Reports it when not.
    fn known_type(&mut self, ty: &str, span: &Range<usize>, m: &Model) -> bool {
        if ty == "object" || m.types.contains_key(ty) {
            return true;
        }
        let names = m.types.keys().map(String::as_str).chain(["object"]);
        self.err(
            span.clone(),
            format!("undeclared type `{}`", shown(ty)),
            suggest(ty, names),
        );
        false
    }

    fn types(&mut self, items: &[Sexp], m: &mut Model) {
        let typed = self.typed_list(items, false, m);
        if typed.len() > MAX_DECLARATIONS {
            self.err(
                items[0].span(),
                format!("more than {MAX_DECLARATIONS} types"),
                "split the domain",
            );
            return;
        }
        for (t, span, up, _) in &typed {
            if t == "object" {
                continue;
            }
            if m.types.insert(t.clone(), up.clone()).is_some() {
                self.err(
                    span.clone(),
                    format!("a second type `{t}`"),
                    "declare it once",
                );
            }
        }
        // A supertype only named after `-` is a type too (below `object`).
        for (_, _, up, _) in &typed {
            if up != "object" && !m.types.contains_key(up) {
                m.types.insert(up.clone(), "object".into());
            }
        }
        for (t, span, up, _) in &typed {
            // Acyclic and at most MAX_TYPE_DEPTH deep.
            let mut at = up.as_str();
            let mut depth = 1;
            while let Some(next) = m.types.get(at) {
                depth += 1;
                if at == t || depth > MAX_TYPE_DEPTH {
                    self.err(
                        span.clone(),
                        format!(
                            "type `{t}` is its own supertype or has more than {MAX_TYPE_DEPTH} above it"
                        ),
                        "types form a tree below `object`",
                    );
                    break;
                }
                at = next;
            }
        }
    }

    /// `:constants` or a problem's `:objects` (`what` names them).
    fn objects(&mut self, items: &[Sexp], m: &mut Model, what: &str) {
        for (name, span, ty, ty_span) in self.typed_list(items, false, m) {
            if !self.known_type(&ty, &ty_span, m) {
                continue;
            }
            if m.objects.len() >= MAX_DECLARATIONS {
                self.err(
                    span,
                    format!("more than {MAX_DECLARATIONS} objects"),
                    "fewer objects",
                );
                return;
            }
            match m.objects.get(&name) {
                Some(t) if *t != ty => self.err(
                    span,
                    format!("{what} `{name}` is declared again with type `{ty}`, was `{t}`"),
                    "give it one type",
                ),
                Some(_) => {}
                None => {
                    m.objects.insert(name, ty);
                }
            }
        }
    }

    /// Typed parameters, each type declared and each name new.
    fn params(&mut self, items: &[Sexp], m: &Model) -> Vec<Param> {
        let mut out: Vec<Param> = Vec::new();
        for (name, span, ty, ty_span) in self.typed_list(items, true, m) {
            // Kept with an unknown type (reported): its uses are checked.
            self.known_type(&ty, &ty_span, m);
            if out.iter().any(|p| p.name == name) {
                self.err(span, format!("a second parameter `?{name}`"), "rename one");
                continue;
            }
            out.push(Param { name, ty });
        }
        out
    }

    fn predicates(&mut self, items: &[Sexp], m: &mut Model) {
        for p in items {
            let list = p.list().unwrap_or_default();
            let Some(name) = list
                .first()
                .and_then(Sexp::atom)
                .filter(|n| fact::is_name(n))
            else {
                self.err(
                    p.span(),
                    "expected `(name ?param - type ...)`",
                    "declare a predicate",
                );
                continue;
            };
            if m.predicate(name).is_some() {
                self.err(
                    p.span(),
                    format!("a second predicate `{name}`"),
                    "declare it once",
                );
                continue;
            }
            if m.predicates.len() >= MAX_DECLARATIONS {
                self.err(
                    p.span(),
                    format!("more than {MAX_DECLARATIONS} predicates"),
                    "split the domain",
                );
                return;
            }
            let params = self.params(&list[1..], m);
            m.predicates.push((name.to_string(), params));
        }
    }
}

/// What a condition or effect is read in: the action's parameters (none in
/// a problem), whether it is durative, and what a term not a variable is.
struct Ctx<'a> {
    params: &'a [Param],
    durative: bool,
    objects_are: &'static str,
}

impl Reader {
    /// One action: its parameters, its conditions and effects mapped to
    /// STRIPS (see `super`'s doc).
    fn action(&mut self, s: &Sexp, m: &Model) -> Option<RawAction> {
        let items = s.list().unwrap_or_default();
        let durative = s.head() == Some(":durative-action");
        if durative && !m.requirements.iter().any(|r| r == ":durative-actions") {
            self.err(
                items[0].span(),
                "`:durative-action` needs `:durative-actions` in `:requirements`",
                "add `:durative-actions` to `(:requirements ...)`",
            );
        }
        let Some(name) = items
            .get(1)
            .and_then(Sexp::atom)
            .filter(|n| fact::is_name(n))
        else {
            self.err(
                s.span(),
                "an action has no name",
                "write `(:action NAME :parameters (...) ...)`",
            );
            return None;
        };
        let keys: &[&str] = if durative {
            &[":parameters", ":duration", ":condition", ":effect"]
        } else {
            &[":parameters", ":precondition", ":effect"]
        };
        let (mut params, mut cond, mut eff) = (Vec::new(), None, None);
        let mut i = 2;
        while i < items.len() {
            let key = items[i].atom().unwrap_or("(");
            let Some(value) = items.get(i + 1).filter(|_| keys.contains(&key)) else {
                self.err(
                    items[i].span(),
                    format!("`{}` is not a key of `{}` here", shown(key), shown(name)),
                    format!("the keys, each with a value: {}", keys.join(", ")),
                );
                return None;
            };
            match key {
                ":parameters" => params = self.params(value.list().unwrap_or_default(), m),
                ":precondition" | ":condition" => cond = Some(value),
                ":effect" => eff = Some(value),
                _ => {}
            }
            i += 2;
        }
        for p in &params {
            if m.objects.contains_key(&p.name) {
                self.err(
                    items[1].span(),
                    format!(
                        "parameter `?{}` of `{name}` has the name of a constant",
                        p.name
                    ),
                    "rename the parameter",
                );
            }
        }
        let ctx = Ctx {
            params: &params,
            durative,
            objects_are: "a constant of the domain",
        };
        let mut conds = Vec::new();
        let mut effs = Vec::new();
        let plain = (!durative).then_some(When::Start);
        if let Some(c) = cond {
            self.condition(c, &ctx, m, plain, &mut conds);
        }
        if let Some(e) = eff {
            self.effect(e, &ctx, m, (!durative).then_some(When::End), &mut effs);
        }
        let (pre, add, del) = strips(conds, effs);
        if pre.len() > MAX_SIBLINGS || add.len() + del.len() > MAX_SIBLINGS {
            self.err(
                s.span(),
                format!("action `{name}` has more than {MAX_SIBLINGS} preconditions or effects"),
                "split the action",
            );
            return None;
        }
        Some(RawAction {
            name: name.to_string(),
            span: items[1].span(),
            params,
            pre,
            add,
            del,
        })
    }
}

/// The STRIPS action of timed conditions and effects: conditions at start,
/// over all, and at end unless an at-start effect adds them; the net
/// effects (at start, then at end).
fn strips(
    conds: Vec<(When, Pattern)>,
    effs: Vec<(When, bool, Pattern)>,
) -> (Vec<Pattern>, Vec<Pattern>, Vec<Pattern>) {
    let of = |w: When, adds: bool| -> Vec<&Pattern> {
        (effs.iter())
            .filter(|(x, a, _)| *x == w && *a == adds)
            .map(|(_, _, p)| p)
            .collect()
    };
    let (add_start, del_start) = (of(When::Start, true), of(When::Start, false));
    let (add_end, del_end) = (of(When::End, true), of(When::End, false));
    let mut pre: Vec<Pattern> = Vec::new();
    for (w, p) in &conds {
        if (*w != When::End || !add_start.contains(&p)) && !pre.contains(p) {
            pre.push(p.clone());
        }
    }
    let mut add: Vec<Pattern> = Vec::new();
    for p in add_start
        .iter()
        .filter(|p| !del_end.contains(p))
        .chain(&add_end)
    {
        if !add.contains(p) {
            add.push((*p).clone());
        }
    }
    let mut del: Vec<Pattern> = Vec::new();
    for p in del_start.iter().chain(&del_end) {
        if !add.contains(p) && !del.contains(p) {
            del.push((*p).clone());
        }
    }
    (pre, add, del)
}

impl Reader {
    /// `(at start c)`, `(at end c)`, `(over all c)` of a durative action
    /// (`None`: not yet inside one).
    fn timed<'s>(&mut self, s: &'s Sexp, effect: bool) -> Option<(When, &'s Sexp)> {
        let items = s.list().unwrap_or_default();
        let when = match (s.head(), items.get(1).and_then(Sexp::atom), items.len()) {
            (Some("at"), Some("start"), 3) => When::Start,
            (Some("at"), Some("end"), 3) => When::End,
            (Some("over"), Some("all"), 3) if !effect => When::All,
            (Some("over"), Some("all"), 3) => {
                self.refuse(s.span(), "an `over all` effect", ":continuous-effects");
                return None;
            }
            _ => {
                let what = if effect {
                    "a durative action's effect is `(at start e)` or `(at end e)`"
                } else {
                    "a durative action's condition is `(at start c)`, `(at end c)` or `(over all c)`"
                };
                self.err(
                    s.span(),
                    what,
                    "wrap it in `(at start ...)` or `(at end ...)`",
                );
                return None;
            }
        };
        Some((when, &items[2]))
    }

    fn condition(
        &mut self,
        s: &Sexp,
        ctx: &Ctx<'_>,
        m: &Model,
        when: Option<When>,
        out: &mut Vec<(When, Pattern)>,
    ) {
        if s.list().is_some_and(<[Sexp]>::is_empty) {
            return;
        }
        let refused = match s.head() {
            Some("and") => {
                for c in &s.list().unwrap_or_default()[1..] {
                    self.condition(c, ctx, m, when, out);
                }
                return;
            }
            _ if ctx.durative && when.is_none() => {
                if let Some((w, inner)) = self.timed(s, false) {
                    self.condition(inner, ctx, m, Some(w), out);
                }
                return;
            }
            Some("not") => Some(":negative-preconditions"),
            Some("or" | "imply") => Some(":disjunctive-preconditions"),
            Some("exists") => Some(":existential-preconditions"),
            Some("forall") => Some(":universal-preconditions"),
            Some("=") => Some(":equality"),
            Some("<" | ">" | "<=" | ">=") => Some(":numeric-fluents"),
            Some("preference") => Some(":preferences"),
            _ => None,
        };
        if let Some(req) = refused {
            let head = s.head().unwrap_or_default();
            self.refuse(s.span(), &format!("`{head}` in a condition"), req);
        } else if let Some(p) = self.atom(s, ctx, m) {
            out.push((when.unwrap_or(When::Start), p));
        }
    }

    fn effect(
        &mut self,
        s: &Sexp,
        ctx: &Ctx<'_>,
        m: &Model,
        when: Option<When>,
        out: &mut Vec<(When, bool, Pattern)>,
    ) {
        if s.list().is_some_and(<[Sexp]>::is_empty) {
            return;
        }
        let refused = match s.head() {
            Some("and") => {
                for c in &s.list().unwrap_or_default()[1..] {
                    self.effect(c, ctx, m, when, out);
                }
                return;
            }
            _ if ctx.durative && when.is_none() => {
                if let Some((w, inner)) = self.timed(s, true) {
                    self.effect(inner, ctx, m, Some(w), out);
                }
                return;
            }
            Some("not") => {
                match s.list().unwrap_or_default() {
                    [_, atom] => {
                        if let Some(p) = self.atom(atom, ctx, m) {
                            out.push((when.unwrap_or(When::End), false, p));
                        }
                    }
                    _ => self.err(s.span(), "`not` takes one atom", "write `(not (pred ...))`"),
                }
                return;
            }
            Some("when" | "forall") => Some(":conditional-effects"),
            Some("increase" | "decrease" | "assign" | "scale-up" | "scale-down") => {
                Some(":numeric-fluents")
            }
            _ => None,
        };
        if let Some(req) = refused {
            let head = s.head().unwrap_or_default();
            self.refuse(s.span(), &format!("`{head}` in an effect"), req);
        } else if let Some(p) = self.atom(s, ctx, m) {
            out.push((when.unwrap_or(When::End), true, p));
        }
    }

    /// `(pred term...)` checked: a declared predicate, its arity, each term
    /// a parameter or object of the predicate's argument type.
    fn atom(&mut self, s: &Sexp, ctx: &Ctx<'_>, m: &Model) -> Option<Pattern> {
        if self.full() {
            return None;
        }
        let items = s.list().unwrap_or_default();
        let Some(name) = items.first().and_then(Sexp::atom) else {
            self.err(
                s.span(),
                "expected an atom `(predicate term...)`",
                "write `(pred ?x ...)`",
            );
            return None;
        };
        let Some(decl) = m.predicate(name) else {
            let names: Vec<&str> = m.predicates.iter().map(|(n, _)| n.as_str()).collect();
            let hint = match abbreviated(name, &names) {
                Some(full) => format!("did you mean `{full}`?"),
                None => suggest(name, names),
            };
            self.err(
                items[0].span(),
                format!("undeclared predicate `{}`", shown(name)),
                hint,
            );
            return None;
        };
        if items.len() - 1 != decl.len() {
            self.err(
                s.span(),
                format!(
                    "`{name}` takes {} argument(s), found {}",
                    decl.len(),
                    items.len() - 1
                ),
                format!("declared as `({name}{})`", typed_params(decl)),
            );
            return None;
        }
        let mut args = Vec::new();
        for (term, want) in items[1..].iter().zip(decl) {
            let text = term.atom().unwrap_or("(");
            let found = match text.strip_prefix('?') {
                Some(v) => ctx.params.iter().find(|p| p.name == v).map(|p| (v, &p.ty)),
                None => m.objects.get_key_value(text).map(|(k, t)| (k.as_str(), t)),
            };
            let Some((arg, ty)) = found else {
                let (what, names): (String, Vec<String>) = if text.starts_with('?') {
                    let n = ctx.params.iter().map(|p| format!("?{}", p.name)).collect();
                    ("a parameter here".into(), n)
                } else {
                    (ctx.objects_are.into(), m.objects.keys().cloned().collect())
                };
                self.err(
                    term.span(),
                    format!("`{}` is not {what}", shown(text)),
                    suggest(text, names.iter().map(String::as_str)),
                );
                return None;
            };
            if !m.is_subtype(ty, &want.ty) {
                self.err(
                    term.span(),
                    format!(
                        "`{}` is a `{ty}`; `{name}` takes a `{}` here (`?{}`)",
                        shown(text),
                        want.ty,
                        want.name
                    ),
                    format!("give a `{}`", want.ty),
                );
                return None;
            }
            args.push(arg.to_string());
        }
        Some(Pattern {
            pred: name.to_string(),
            args,
        })
    }
}

/// The candidate `wrong` abbreviates — every character of `wrong` in it,
/// in order, and at most twice as long (`piece_is_sterwheel` for
/// `piece_is_steering_wheel`) — closest by edit distance: letters left out
/// are the likelier typo than a different word (plain edit distance
/// prefers `piece_is_wheel`). `None` when no candidate is one.
fn abbreviated<'a>(wrong: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let within = |c: &str| c.len() > wrong.len() && c.len() <= 2 * wrong.len();
    let subsequence = |c: &str| {
        let mut it = c.chars();
        wrong.chars().all(|w| it.any(|x| x == w))
    };
    (candidates.iter())
        .take(btfsm_core::diagnostic::SUGGEST_SCAN)
        .filter(|c| wrong.len() >= 4 && within(c) && subsequence(c))
        // For a subsequence, the edit distance is the length difference.
        .min_by_key(|c| c.len())
        .copied()
}

/// ` ?a - t ?b - u`: a predicate's parameters as declared.
fn typed_params(params: &[Param]) -> String {
    params
        .iter()
        .map(|p| format!(" ?{} - {}", p.name, p.ty))
        .collect()
}

impl Reader {
    /// Reads the problem file: its objects are added to `m`.
    pub(super) fn problem(&mut self, m: &mut Model) -> Task {
        let top = match sexpr::read(&self.file) {
            Ok(t) => t,
            Err(d) => {
                self.diags.push(d);
                return Task::default();
            }
        };
        let Some((name, sections)) = self.define(&top, "problem") else {
            return Task::default();
        };
        let mut task = Task {
            name,
            ..Task::default()
        };
        let section = |key: &str| sections.iter().find(|s| s.head() == Some(key));
        let body = |s: &Sexp| {
            s.list()
                .unwrap_or_default()
                .get(1..)
                .unwrap_or_default()
                .to_vec()
        };
        for s in sections {
            let keys = [
                ":domain",
                ":requirements",
                ":objects",
                ":init",
                ":goal",
                ":metric",
            ];
            if !s.head().is_some_and(|h| keys.contains(&h)) {
                let h = s.head().unwrap_or("(");
                self.err(
                    s.span(),
                    format!("unknown problem section `{}`", shown(h)),
                    suggest(h, keys),
                );
            }
        }
        match section(":domain").map(body).as_deref() {
            Some([d]) if d.atom() == Some(&m.name) => {}
            Some([d]) => self.err(
                d.span(),
                format!(
                    "the problem is for domain `{}`, not `{}`",
                    shown(d.atom().unwrap_or("(")),
                    m.name
                ),
                "give the domain file the problem names",
            ),
            _ => self.err(
                0..0,
                "the problem has no `(:domain NAME)`",
                "name its domain",
            ),
        }
        if let Some(s) = section(":objects") {
            self.objects(&body(s), m, "object");
        }
        let ctx = Ctx {
            params: &[],
            durative: false,
            objects_are: "an object of the problem or a constant",
        };
        if let Some(s) = section(":init") {
            task.init = self.init(&body(s), &ctx, m);
        }
        let mut goal = Vec::new();
        match section(":goal").map(body).as_deref() {
            Some([g]) => self.condition(g, &ctx, m, Some(When::Start), &mut goal),
            _ => self.err(
                0..0,
                "the problem has no `(:goal ...)`",
                "write `(:goal (and (pred obj ...)))`",
            ),
        }
        if goal.len() > MAX_SIBLINGS {
            self.err(
                0..0,
                format!("the goal has more than {MAX_SIBLINGS} facts"),
                "split the goal",
            );
        }
        task.goal = goal.into_iter().map(|(_, p)| p.ground(&|_| None)).collect();
        if task.goal.is_empty() && self.diags.is_empty() {
            self.err(
                0..0,
                "the problem's goal has no facts",
                "write `(:goal (and (pred obj ...)))`",
            );
        }
        task
    }

    fn init(&mut self, items: &[Sexp], ctx: &Ctx<'_>, m: &Model) -> Vec<crate::fact::Fact> {
        let mut out = Vec::new();
        for f in items {
            match f.head() {
                Some("=") => self.refuse(
                    f.span(),
                    "a function value `(= ...)` in `:init`",
                    ":numeric-fluents",
                ),
                Some("at")
                    if f.list()
                        .and_then(|l| l.get(1))
                        .and_then(Sexp::atom)
                        .is_some_and(|a| a.parse::<f64>().is_ok()) =>
                {
                    self.refuse(
                        f.span(),
                        "`(at TIME ...)` in `:init`",
                        ":timed-initial-literals",
                    );
                }
                Some("not") => self.err(
                    f.span(),
                    "`not` in `:init`",
                    "list only the facts that hold: every other is false",
                ),
                _ => {
                    if let Some(p) = self.atom(f, ctx, m) {
                        out.push(p.ground(&|_| None));
                    }
                }
            }
            if out.len() > MAX_DECLARATIONS {
                self.err(
                    f.span(),
                    format!("more than {MAX_DECLARATIONS} initial facts"),
                    "fewer facts",
                );
                break;
            }
        }
        out
    }
}
