//! Validation of action domains: the TOML read with serde into raw tables
//! (in file order, with spans), then checked into a [`Domain`] — names,
//! types, facts against predicates, skills against the shared library,
//! limits — every problem reported at once with its position.

use super::domain::*;
use super::fact::{self, Pattern};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_model::skill::{self, SkillKind};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

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
    init: Vec<Spanned<String>>,
    #[serde(default)]
    ids: BTreeMap<String, String>,
    #[serde(default)]
    labels: BTreeMap<String, String>,
}

/// Reads and validates a domain from its text.
pub(super) fn load(file: &Arc<SourceFile>) -> Result<Domain, Vec<Diagnostic>> {
    btfsm_core::toml_budget::check(
        file,
        btfsm_core::toml_budget::DEFAULT_MAX_TOKENS,
        "a domain's counts are capped (docs/guide/plan.md)",
    )
    .map_err(|d| vec![d])?;
    let raw: RawDomain = toml::from_str(&file.text).map_err(|e| {
        let d = Diagnostic::error(format!("invalid domain: {}", e.message().trim()))
            .hint("see docs/guide/plan.md (\"The domain file\") for the format");
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

    /// The whole domain: objects, limits, name, predicates, actions, the
    /// goal and the tasks, in that order (so are the diagnostics).
    fn domain(&mut self, raw: RawDomain) -> Domain {
        let objects = self.objects(&raw.objects);
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
                return Domain {
                    name: raw.name.into_inner(),
                    ..Domain::default()
                };
            }
        }
        if !fact::is_name(raw.name.get_ref()) {
            self.err(
                raw.name.span(),
                format!("domain name `{}` is not a name", btfsm_core::sanitize::shown(raw.name.get_ref())),
                "letters, digits, `-` and `_`: it prefixes the domain's own skills (`moma:Open-Door`)",
            );
        }
        let mut d = Domain {
            name: raw.name.get_ref().clone(),
            description: raw.description.clone(),
            objects,
            ..Domain::default()
        };
        for (name, p) in raw.predicates.0 {
            let p = self.predicate(name, p.into_inner(), &d);
            d.predicates.push(p);
        }
        for (name, a) in raw.actions.0 {
            if let Some(a) = self.action(name, a, &d) {
                d.actions.push(a);
            }
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

    /// The `[objects]` table, each name checked.
    fn objects(&mut self, raw: &BTreeMap<Spanned<String>, RawObject>) -> BTreeMap<String, Object> {
        let mut objects = BTreeMap::new();
        for (name, o) in raw {
            if !fact::is_name(name.get_ref()) {
                self.err(
                    name.span(),
                    format!(
                        "object `{}` is not a name",
                        btfsm_core::sanitize::shown(name.get_ref())
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
        objects
    }

    /// Predicate `name` (`[predicates.NAME]`): parameters, `exclusive`,
    /// skill, and the defaults of its ids and label.
    fn predicate(&mut self, name: String, p: RawPredicate, d: &Domain) -> Predicate {
        let params = self.params(&p.params, d);
        let exclusive = p.exclusive.as_ref().and_then(|x| {
            let at = params.iter().position(|q| &q.name == x.get_ref());
            if at.is_none() {
                self.err(
                    x.span(),
                    format!(
                        "`exclusive` names `{}`, not a parameter of `{}`",
                        btfsm_core::sanitize::shown(x.get_ref()),
                        btfsm_core::sanitize::shown(&name)
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
        Predicate {
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
        }
    }

    /// Action `name` (`[actions.NAME]`): parameters, facts, skill, and the
    /// defaults of its ids and label; `None` when it has too many
    /// preconditions to be checked.
    fn action(&mut self, name: String, a: Spanned<RawAction>, d: &Domain) -> Option<Action> {
        let span = a.span();
        let a = a.into_inner();
        let params = self.params(&a.params, d);
        if a.pre.len() > MAX_SIBLINGS {
            self.err(
                span.clone(),
                format!(
                    "action `{}` has {} preconditions, more than {MAX_SIBLINGS}",
                    btfsm_core::sanitize::shown(&name),
                    a.pre.len()
                ),
                "split the action",
            );
            return None;
        }
        let pre = self.patterns(&a.pre, &params, d);
        let add = self.patterns(&a.add, &params, d);
        let del = self.patterns(&a.del, &params, d);
        if a.add.is_empty() {
            self.err(
                span.clone(),
                format!(
                    "action `{}` adds no fact",
                    btfsm_core::sanitize::shown(&name)
                ),
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
        Some(Action {
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
        })
    }

    /// A goal (`[goal]` or `[tasks.NAME]`): facts, `use`, names.
    fn goal(&mut self, raw: &Spanned<RawGoal>, d: &Domain) -> Goal {
        let g = raw.get_ref();
        let mut out = Goal {
            id: g.id.clone().unwrap_or_else(|| d.name.clone()),
            actions: None,
            facts: Vec::new(),
            init: Vec::new(),
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
        if g.init.len() > MAX_SIBLINGS {
            self.err(
                raw.span(),
                format!(
                    "`init` has {} facts, more than {MAX_SIBLINGS}",
                    g.init.len()
                ),
                "name only the facts the task depends on",
            );
        } else {
            for f in self.patterns(&g.init, &empty_params, d) {
                out.init.push(f.ground(&|_| None));
            }
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
                            btfsm_core::sanitize::shown(n.get_ref())
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
                        btfsm_core::sanitize::shown(name)
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
                        btfsm_core::sanitize::shown(&p.name)
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
                        btfsm_core::sanitize::shown(p.get_ref())
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
                        btfsm_core::sanitize::shown(name)
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
                    format!("no object has type `{}`", btfsm_core::sanitize::shown(ty)),
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
                    format!(
                        "unknown predicate `{}`",
                        btfsm_core::sanitize::shown(&p.pred)
                    ),
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
                                btfsm_core::sanitize::shown(arg)
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
                                btfsm_core::sanitize::shown(arg),
                                want.ty,
                                want.name,
                                pred.name
                            ),
                            format!(
                                "give `{}` the type `{}`",
                                btfsm_core::sanitize::shown(arg),
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

pub(crate) fn default_id(name: &str, params: &[Param]) -> String {
    let mut id = name.to_lowercase();
    for p in params {
        id.push_str(&format!("-{{{}:short}}", p.name));
    }
    id
}

/// One `--goal` fact checked as a goal fact of `d` is: the pattern and the
/// problems found.
pub(super) fn goal_fact(
    file: &Arc<SourceFile>,
    text: &str,
    d: &Domain,
) -> (Vec<Pattern>, Vec<Diagnostic>) {
    let mut v = Validator {
        file: file.clone(),
        diags: Vec::new(),
    };
    let raw = [Spanned::new(0..0, text.to_string())];
    let found = v.patterns(&raw, &[], d);
    (found, v.diags)
}
