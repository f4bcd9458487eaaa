//! Action domains (TOML): objects with types, predicates with typed
//! parameters, STRIPS actions (Fikes & Nilsson 1971) with an ordered
//! precondition list, add and delete effects, a cost and the skill each
//! runs, predicates whose facts exclude each other, and a goal. Read into
//! a validated [`Domain`]; every problem is reported at once with its
//! position. The format is documented in the README ("Action domains").
//!
//! Node names of a generated policy come from templates in the domain
//! (`id = "at-{target:short}"`): `{param}` is the object, `{param:short}`
//! its `short` name, `{param:title}` the object with a capital first letter.

use super::fact::{self, Fact, Pattern};
use crate::diagnostic::{Diagnostic, SourceFile, suggest};
use crate::model::skill::{self, SkillKind};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

/// Most objects, predicates and actions a domain may declare (each; the
/// planner's work is bounded by them).
pub const MAX_DECLARATIONS: usize = 10_000;
/// Most facts in an action's precondition list or in the goal: the
/// conflict order compares every pair of siblings.
pub const MAX_SIBLINGS: usize = 256;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDomain {
    name: Spanned<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    objects: BTreeMap<Spanned<String>, RawObject>,
    #[serde(default)]
    predicates: Ordered<Spanned<RawPredicate>>,
    #[serde(default)]
    actions: Ordered<Spanned<RawAction>>,
    goal: Spanned<RawGoal>,
    #[serde(default)]
    tasks: Ordered<Spanned<RawGoal>>,
}

/// A table read in file order (the domain's order breaks cost ties).
struct Ordered<T>(Vec<(String, T)>);

impl<T> Default for Ordered<T> {
    fn default() -> Self {
        Ordered(Vec::new())
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Ordered<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for V<T> {
            type Value = Ordered<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Ordered<T>, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = m.next_entry::<String, T>()? {
                    if out.len() >= MAX_DECLARATIONS {
                        return Err(serde::de::Error::custom(format!(
                            "more than {MAX_DECLARATIONS} entries"
                        )));
                    }
                    out.push((k, v));
                }
                Ok(Ordered(out))
            }
        }
        d.deserialize_map(V(std::marker::PhantomData))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    types: Vec<String>,
    #[serde(default)]
    short: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPredicate {
    #[serde(default)]
    params: Vec<Spanned<String>>,
    #[serde(default)]
    skill: Option<Spanned<String>>,
    #[serde(default)]
    exclusive: Option<Spanned<String>>,
    #[serde(default)]
    id: Option<String>,
    #[serde(default)]
    label: Option<String>,
    #[serde(default)]
    achieved_id: Option<String>,
    #[serde(default)]
    volatile: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAction {
    #[serde(default)]
    params: Vec<Spanned<String>>,
    #[serde(default)]
    pre: Vec<Spanned<String>>,
    #[serde(default)]
    add: Vec<Spanned<String>>,
    #[serde(default)]
    del: Vec<Spanned<String>>,
    #[serde(default = "one")]
    cost: u32,
    #[serde(default)]
    skill: Option<Spanned<String>>,
    #[serde(default)]
    id: Option<String>,
    #[serde(default)]
    label: Option<String>,
    #[serde(default)]
    sequence_id: Option<String>,
}

fn one() -> u32 {
    1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGoal {
    #[serde(default)]
    id: Option<String>,
    #[serde(default, rename = "use")]
    use_actions: Option<Vec<Spanned<String>>>,
    facts: Vec<Spanned<String>>,
    #[serde(default)]
    ids: BTreeMap<String, String>,
    #[serde(default)]
    labels: BTreeMap<String, String>,
}

/// A typed parameter.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Param {
    pub name: String,
    pub ty: String,
}

#[derive(Debug, Clone)]
pub struct Object {
    pub types: Vec<String>,
    pub short: String,
}

#[derive(Debug, Clone)]
pub struct Predicate {
    pub name: String,
    pub params: Vec<Param>,
    /// The condition skill that checks it (its arguments are the
    /// parameters, by name): a library skill, or the domain's own
    /// `domain:Name`; `None` only while a domain with errors is read.
    pub skill: Option<String>,
    /// The parameter whose different values make facts exclude each other
    /// (`Robot-At(a)` and `Robot-At(b)`): an action adding one deletes the
    /// others.
    pub exclusive: Option<usize>,
    pub id: String,
    pub label: String,
    pub achieved_id: String,
    /// The world makes its facts false at any time (a battery drains): in
    /// an FSM, the action restoring one is a connected state.
    pub volatile: bool,
}

#[derive(Debug, Clone)]
pub struct Action {
    pub name: String,
    pub params: Vec<Param>,
    pub pre: Vec<Pattern>,
    pub add: Vec<Pattern>,
    pub del: Vec<Pattern>,
    pub cost: u32,
    pub skill: Option<String>,
    pub id: String,
    pub label: String,
    pub sequence_id: String,
}

#[derive(Debug, Clone)]
pub struct Goal {
    pub id: String,
    /// The actions the planner may use for this goal (`use`; `None`: all).
    pub actions: Option<Vec<String>>,
    pub facts: Vec<Fact>,
    /// Node id of a goal fact's condition, by its text (`Object-At(cube2, delivery)`).
    pub ids: BTreeMap<String, String>,
    pub labels: BTreeMap<String, String>,
}

/// A validated action domain.
#[derive(Debug, Clone)]
pub struct Domain {
    pub name: String,
    pub description: Option<String>,
    pub objects: BTreeMap<String, Object>,
    pub predicates: Vec<Predicate>,
    pub actions: Vec<Action>,
    pub goal: Goal,
    /// Other goals by name (`[tasks.NAME]`), for `plan --task NAME`.
    pub tasks: Vec<(String, Goal)>,
}

impl Domain {
    pub fn predicate(&self, name: &str) -> Option<&Predicate> {
        self.predicates.iter().find(|p| p.name == name)
    }

    /// The objects of type `ty`, sorted.
    pub fn objects_of(&self, ty: &str) -> impl Iterator<Item = &str> {
        self.objects
            .iter()
            .filter(move |(_, o)| o.types.iter().any(|t| t == ty))
            .map(|(n, _)| n.as_str())
    }

    /// Fills a name template: `{param}` is the object bound to `param`,
    /// `{param:short}` its short name, `{param:title}` the object with a
    /// capital first letter; other text is kept.
    pub fn fill(&self, template: &str, bind: &BTreeMap<String, String>) -> String {
        let mut out = String::with_capacity(template.len());
        let mut rest = template;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let Some(close) = rest[open..].find('}') else {
                out.push_str(&rest[open..]);
                return out;
            };
            let key = &rest[open + 1..open + close];
            let (param, modifier) = key.split_once(':').unwrap_or((key, ""));
            match bind.get(param) {
                Some(obj) => {
                    let short = self.objects.get(obj).map_or(obj.as_str(), |o| &o.short);
                    match modifier {
                        "short" => out.push_str(short),
                        "title" => {
                            let mut c = obj.chars();
                            if let Some(first) = c.next() {
                                out.extend(first.to_uppercase());
                                out.push_str(c.as_str());
                            }
                        }
                        _ => out.push_str(obj),
                    }
                }
                None => out.push_str(&rest[open..open + close + 1]),
            }
            rest = &rest[open + close + 1..];
        }
        out.push_str(rest);
        out
    }
}

/// Does a TOML text look like an action domain: no top-level `kind`, and
/// a `[actions...]` or `[predicates...]` table?
pub fn looks_like_domain(text: &str) -> bool {
    let mut tables = false;
    for line in text.lines() {
        let l = line.trim();
        if let Some(h) = l.strip_prefix('[') {
            let h = h.trim_start();
            if h.starts_with("actions") || h.starts_with("predicates") {
                tables = true;
            }
            continue;
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if key == "kind" && l.contains('=') && !tables {
            return false;
        }
    }
    tables
}

/// Reads and validates a domain from its text.
pub fn load(file: &Arc<SourceFile>) -> Result<Domain, Vec<Diagnostic>> {
    let raw: RawDomain = toml::from_str(&file.text).map_err(|e| {
        let d = Diagnostic::error(format!("invalid domain: {}", e.message().trim()))
            .hint("see README \"Action domains\" for the format");
        vec![match e.span() {
            Some(s) => d.at(file, s),
            None => d,
        }]
    })?;
    let mut v = Validator {
        file: file.clone(),
        diags: Vec::new(),
    };
    let domain = v.domain(raw);
    if v.diags.is_empty() {
        Ok(domain)
    } else {
        Err(v.diags)
    }
}

struct Validator {
    file: Arc<SourceFile>,
    diags: Vec<Diagnostic>,
}

impl Validator {
    fn err(&mut self, span: Range<usize>, msg: impl Into<String>, hint: impl Into<String>) {
        let d = Diagnostic::error(msg).at(&self.file, span).hint(hint);
        self.diags.push(d);
    }

    fn domain(&mut self, raw: RawDomain) -> Domain {
        let mut objects = BTreeMap::new();
        for (name, o) in &raw.objects {
            if !fact::is_name(name.get_ref()) {
                self.err(
                    name.span(),
                    format!(
                        "object `{}` is not a name",
                        crate::sanitize::shown(name.get_ref())
                    ),
                    "letters, digits, `-` and `_`",
                );
            }
            objects.insert(
                name.get_ref().clone(),
                Object {
                    types: o.types.clone(),
                    short: o.short.clone().unwrap_or_else(|| name.get_ref().clone()),
                },
            );
        }
        let too_many = [
            ("objects", objects.len()),
            ("predicates", raw.predicates.0.len()),
            ("actions", raw.actions.0.len()),
        ];
        for (what, n) in too_many {
            if n > MAX_DECLARATIONS {
                self.err(
                    0..0,
                    format!("{n} {what}, more than {MAX_DECLARATIONS}"),
                    "split the domain",
                );
                return empty(raw.name.into_inner());
            }
        }
        if !fact::is_name(raw.name.get_ref()) {
            self.err(
                raw.name.span(),
                format!("domain name `{}` is not a name", crate::sanitize::shown(raw.name.get_ref())),
                "letters, digits, `-` and `_`: it prefixes the domain's own skills (`moma:Open-Door`)",
            );
        }
        let mut d = Domain {
            name: raw.name.get_ref().clone(),
            description: raw.description.clone(),
            objects,
            predicates: Vec::new(),
            actions: Vec::new(),
            goal: Goal {
                id: String::new(),
                actions: None,
                facts: Vec::new(),
                ids: BTreeMap::new(),
                labels: BTreeMap::new(),
            },
            tasks: Vec::new(),
        };
        for (name, p) in raw.predicates.0 {
            let p = p.into_inner();
            let params = self.params(&p.params, &d);
            let exclusive = p.exclusive.as_ref().and_then(|x| {
                let at = params.iter().position(|q| &q.name == x.get_ref());
                if at.is_none() {
                    self.err(
                        x.span(),
                        format!(
                            "`exclusive` names `{}`, not a parameter of `{}`",
                            crate::sanitize::shown(x.get_ref()),
                            crate::sanitize::shown(&name)
                        ),
                        "name the parameter whose different values exclude each other",
                    );
                }
                at
            });
            let args: Vec<String> = params.iter().map(|q| format!("{{{}}}", q.name)).collect();
            let shown_fact = if args.is_empty() {
                name.clone()
            } else {
                format!("{name} {}", args.join(" "))
            };
            let custom = format!("{}:{name}", d.name);
            let skill = self.skill(p.skill.as_ref(), SkillKind::Condition, &params, custom);
            d.predicates.push(Predicate {
                name: name.clone(),
                skill,
                exclusive,
                id: p.id.unwrap_or_else(|| default_id(&name, &params)),
                label: p.label.unwrap_or_else(|| format!("{shown_fact}?")),
                volatile: p.volatile,
                achieved_id: p
                    .achieved_id
                    .unwrap_or_else(|| format!("ensure-{}", default_id(&name, &params))),
                params,
            });
        }
        for (name, a) in raw.actions.0 {
            let span = a.span();
            let a = a.into_inner();
            let params = self.params(&a.params, &d);
            if a.pre.len() > MAX_SIBLINGS {
                self.err(
                    span.clone(),
                    format!(
                        "action `{}` has {} preconditions, more than {MAX_SIBLINGS}",
                        crate::sanitize::shown(&name),
                        a.pre.len()
                    ),
                    "split the action",
                );
                continue;
            }
            let pre = self.patterns(&a.pre, &params, &d);
            let add = self.patterns(&a.add, &params, &d);
            let del = self.patterns(&a.del, &params, &d);
            if a.add.is_empty() {
                self.err(
                    span.clone(),
                    format!("action `{}` adds no fact", crate::sanitize::shown(&name)),
                    "write `add = [\"Fact(param)\"]`: a planner uses an action for what it adds",
                );
            }
            let args: Vec<String> = params.iter().map(|q| format!("{{{}}}", q.name)).collect();
            let shown_call = if args.is_empty() {
                name.clone()
            } else {
                format!("{name} {}", args.join(" "))
            };
            let id = a.id.unwrap_or_else(|| default_id(&name, &params));
            d.actions.push(Action {
                name: name.clone(),
                pre,
                add,
                del,
                cost: a.cost,
                skill: self.skill(
                    a.skill.as_ref(),
                    SkillKind::Action,
                    &params,
                    format!("{}:{name}", d.name),
                ),
                label: a.label.unwrap_or_else(|| format!("{shown_call}!")),
                sequence_id: a.sequence_id.unwrap_or_else(|| format!("do-{id}")),
                id,
                params,
            });
        }
        d.goal = self.goal(&raw.goal, &d);
        for (name, t) in &raw.tasks.0 {
            let mut g = self.goal(t, &d);
            if t.get_ref().id.is_none() {
                g.id = name.clone();
            }
            d.tasks.push((name.clone(), g));
        }
        d
    }

    /// A goal (`[goal]` or `[tasks.NAME]`): facts, `use`, names.
    fn goal(&mut self, raw: &Spanned<RawGoal>, d: &Domain) -> Goal {
        let g = raw.get_ref();
        let mut out = Goal {
            id: g.id.clone().unwrap_or_else(|| d.name.clone()),
            actions: None,
            facts: Vec::new(),
            ids: g.ids.clone(),
            labels: g.labels.clone(),
        };
        if g.facts.len() > MAX_SIBLINGS {
            self.err(
                raw.span(),
                format!(
                    "the goal has {} facts, more than {MAX_SIBLINGS}",
                    g.facts.len()
                ),
                "split the goal",
            );
            return out;
        }
        if g.facts.is_empty() {
            self.err(
                raw.span(),
                "the goal has no facts",
                "write `facts = [\"Object-At(cube2, delivery)\"]`",
            );
        }
        let empty_params: Vec<Param> = Vec::new();
        for f in self.patterns(&g.facts, &empty_params, d) {
            out.facts.push(f.ground(&|_| None));
        }
        if let Some(names) = &g.use_actions {
            let mut ok = Vec::new();
            for n in names {
                if d.actions.iter().any(|a| &a.name == n.get_ref()) {
                    ok.push(n.get_ref().clone());
                } else {
                    let h = suggest(n.get_ref(), d.actions.iter().map(|a| a.name.as_str()));
                    self.err(
                        n.span(),
                        format!(
                            "`use` names `{}`, not an action",
                            crate::sanitize::shown(n.get_ref())
                        ),
                        h,
                    );
                }
            }
            out.actions = Some(ok);
        }
        out
    }

    /// A `skill` of the shared library of `kind` whose arguments are the
    /// parameters (every required one given, none it does not take); without
    /// one, `custom` (the domain's own skill `domain:Name`).
    fn skill(
        &mut self,
        raw: Option<&Spanned<String>>,
        kind: SkillKind,
        params: &[Param],
        custom: String,
    ) -> Option<String> {
        // Without `skill`: a skill of the domain's own, `domain:Name`, which
        // runs in symbolic simulation.
        let Some(raw) = raw else {
            return Some(custom);
        };
        let name = raw.get_ref();
        let word = match kind {
            SkillKind::Action => "an action",
            SkillKind::Condition => "a condition",
        };
        match skill::skill_kind(name) {
            Some(k) if k == kind => {}
            _ => {
                let h = suggest(name, skill::skill_names(kind));
                self.err(
                    raw.span(),
                    format!(
                        "`{}` is not {word} skill of the shared library",
                        crate::sanitize::shown(name)
                    ),
                    h,
                );
                return None;
            }
        }
        let takes = skill::skill_params(name).unwrap_or(&[]);
        let mut ok = true;
        for (arg, required) in takes {
            if *required && !params.iter().any(|p| p.name == *arg) {
                self.err(
                    raw.span(),
                    format!("skill `{name}` needs argument `{arg}`, which is not a parameter here"),
                    format!("name a parameter `{arg}`: its object is the argument"),
                );
                ok = false;
            }
        }
        for p in params {
            if !takes.iter().any(|(arg, _)| *arg == p.name) {
                self.err(
                    raw.span(),
                    format!(
                        "skill `{name}` has no argument `{}`",
                        crate::sanitize::shown(&p.name)
                    ),
                    format!(
                        "the parameters are the skill's arguments: {}",
                        if takes.is_empty() {
                            "none".to_string()
                        } else {
                            takes
                                .iter()
                                .map(|(a, _)| format!("`{a}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        }
                    ),
                );
                ok = false;
            }
        }
        ok.then(|| name.clone())
    }

    /// `["name:type", ...]`, types checked against the objects.
    fn params(&mut self, raw: &[Spanned<String>], d: &Domain) -> Vec<Param> {
        let mut out: Vec<Param> = Vec::new();
        for p in raw {
            let Some((name, ty)) = p.get_ref().split_once(':') else {
                self.err(
                    p.span(),
                    format!(
                        "parameter `{}` has no type",
                        crate::sanitize::shown(p.get_ref())
                    ),
                    "write `\"name:type\"`, e.g. `\"target:location\"`",
                );
                continue;
            };
            let (name, ty) = (name.trim(), ty.trim());
            if !fact::is_name(name) || out.iter().any(|q| q.name == name) {
                self.err(
                    p.span(),
                    format!(
                        "parameter `{}` is not a new name",
                        crate::sanitize::shown(name)
                    ),
                    "each parameter has its own name: letters, digits, `-`, `_`",
                );
                continue;
            }
            if d.objects_of(ty).next().is_none() {
                let types: Vec<&str> = d
                    .objects
                    .values()
                    .flat_map(|o| o.types.iter().map(String::as_str))
                    .collect();
                self.err(
                    p.span(),
                    format!("no object has type `{}`", crate::sanitize::shown(ty)),
                    suggest(ty, types),
                );
                continue;
            }
            out.push(Param {
                name: name.into(),
                ty: ty.into(),
            });
        }
        out
    }

    /// Facts over `params` and objects, checked against the predicates.
    fn patterns(&mut self, raw: &[Spanned<String>], params: &[Param], d: &Domain) -> Vec<Pattern> {
        let mut out = Vec::new();
        for r in raw {
            let p = match fact::parse(r.get_ref()) {
                Ok(p) => p,
                Err(e) => {
                    self.err(r.span(), e, "a fact is `Predicate(arg, ...)`");
                    continue;
                }
            };
            let Some(pred) = d.predicate(&p.pred) else {
                let h = suggest(&p.pred, d.predicates.iter().map(|q| q.name.as_str()));
                self.err(
                    r.span(),
                    format!("unknown predicate `{}`", crate::sanitize::shown(&p.pred)),
                    h,
                );
                continue;
            };
            if pred.params.len() != p.args.len() {
                self.err(
                    r.span(),
                    format!(
                        "`{}` takes {} argument(s), found {}",
                        pred.name,
                        pred.params.len(),
                        p.args.len()
                    ),
                    format!(
                        "write `{}({})`",
                        pred.name,
                        pred.params
                            .iter()
                            .map(|q| q.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                );
                continue;
            }
            let mut ok = true;
            for (arg, want) in p.args.iter().zip(&pred.params) {
                // A parameter fits when every object of its type has the
                // type wanted; a constant when it has the type.
                let ty = params
                    .iter()
                    .find(|q| &q.name == arg)
                    .map(|q| {
                        if d.objects_of(&q.ty)
                            .all(|o| d.objects[o].types.contains(&want.ty))
                        {
                            vec![want.ty.clone()]
                        } else {
                            vec![q.ty.clone()]
                        }
                    })
                    .or_else(|| d.objects.get(arg).map(|o| o.types.clone()));
                match ty {
                    None => {
                        let names = params
                            .iter()
                            .map(|q| q.name.as_str())
                            .chain(d.objects.keys().map(String::as_str));
                        self.err(
                            r.span(),
                            format!(
                                "`{}` is neither a parameter nor an object",
                                crate::sanitize::shown(arg)
                            ),
                            suggest(arg, names),
                        );
                        ok = false;
                    }
                    Some(tys) if !tys.contains(&want.ty) => {
                        self.err(
                            r.span(),
                            format!(
                                "`{}` is not a `{}` (argument `{}` of `{}`)",
                                crate::sanitize::shown(arg),
                                want.ty,
                                want.name,
                                pred.name
                            ),
                            format!(
                                "give `{}` the type `{}`",
                                crate::sanitize::shown(arg),
                                want.ty
                            ),
                        );
                        ok = false;
                    }
                    Some(_) => {}
                }
            }
            if ok {
                out.push(p);
            }
        }
        out
    }
}

fn default_id(name: &str, params: &[Param]) -> String {
    let mut id = name.to_lowercase();
    for p in params {
        id.push_str(&format!("-{{{}:short}}", p.name));
    }
    id
}

fn empty(name: String) -> Domain {
    Domain {
        name,
        description: None,
        objects: BTreeMap::new(),
        predicates: Vec::new(),
        actions: Vec::new(),
        goal: Goal {
            id: String::new(),
            actions: None,
            facts: Vec::new(),
            ids: BTreeMap::new(),
            labels: BTreeMap::new(),
        },
        tasks: Vec::new(),
    }
}

impl Domain {
    /// Makes task `name` the goal (`plan --task`); the error lists the tasks.
    pub fn select_task(&mut self, name: &str) -> Result<(), String> {
        match self.tasks.iter().find(|(n, _)| n == name) {
            Some((_, g)) => {
                self.goal = g.clone();
                Ok(())
            }
            None => Err(format!(
                "--task `{}`: no `[tasks.{}]` in domain `{}`; {}",
                crate::sanitize::shown(name),
                crate::sanitize::shown(name),
                crate::sanitize::shown(&self.name),
                suggest(name, self.tasks.iter().map(|(n, _)| n.as_str()))
            )),
        }
    }

    /// Replaces the goal by `facts` (`--goal`), each checked as a goal fact
    /// of the domain is; the errors say what is wrong with each.
    pub fn set_goal(&mut self, facts: &[String]) -> Result<(), Vec<String>> {
        let mut errors = Vec::new();
        let mut goal = Vec::new();
        let file = SourceFile::new("--goal", String::new());
        for text in facts {
            let mut v = Validator {
                file: file.clone(),
                diags: Vec::new(),
            };
            let raw = [Spanned::new(0..0, text.clone())];
            let found = v.patterns(&raw, &[], self);
            errors.extend(v.diags.into_iter().map(|d| match d.hint {
                Some(h) => format!(
                    "--goal `{}`: {} ({h})",
                    crate::sanitize::shown(text),
                    d.message
                ),
                None => format!("--goal `{}`: {}", crate::sanitize::shown(text), d.message),
            }));
            goal.extend(found.into_iter().map(|p| p.ground(&|_| None)));
        }
        if goal.len() > MAX_SIBLINGS {
            errors.push(format!(
                "{} goal facts, more than {MAX_SIBLINGS}",
                goal.len()
            ));
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        self.goal.facts = goal;
        Ok(())
    }
}

impl Domain {
    /// The condition a fact stands for: its predicate's skill with the
    /// fact's objects as arguments.
    pub fn fact_condition(&self, f: &Fact) -> crate::model::skill::SkillCall {
        let pred = self.predicate(&f.pred).expect("a fact of the domain");
        let skill = pred
            .skill
            .as_deref()
            .expect("a valid domain's predicates have skills");
        Domain::skill_call(skill, &pred.params, &f.args)
    }

    /// The skill call of `skill` with `params` bound to `objects` (numbers
    /// and booleans as such: `Battery-Level(20)` is `min = 20`).
    pub fn skill_call(
        skill: &str,
        params: &[Param],
        objects: &[String],
    ) -> crate::model::skill::SkillCall {
        crate::model::skill::SkillCall {
            skill: skill.to_string(),
            args: params
                .iter()
                .zip(objects)
                .map(|(p, o)| (p.name.clone(), crate::format::btcpp_xml::arg_value(o)))
                .collect(),
        }
    }
}
