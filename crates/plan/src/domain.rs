//! Action domains (TOML): objects with types, predicates with typed
//! parameters, STRIPS actions (Fikes & Nilsson 1971) with an ordered
//! precondition list, add and delete effects, a cost and the skill each
//! runs, predicates whose facts exclude each other, and a goal. Read into
//! a validated [`Domain`]; every problem is reported at once with its
//! position. The format is documented in docs/guide/plan.md.
//!
//! Node names of a generated policy come from templates in the domain
//! (`id = "at-{target:short}"`): `{param}` is the object, `{param:short}`
//! its `short` name, `{param:title}` the object with a capital first letter.

use super::fact::{Fact, Pattern};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Most objects, predicates and actions a domain may declare (each; the
/// planner's work is bounded by them).
pub const MAX_DECLARATIONS: usize = 10_000;
/// Most facts in an action's precondition list or in the goal: the
/// conflict order compares every pair of siblings.
pub const MAX_SIBLINGS: usize = 256;

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

#[derive(Debug, Clone, Default)]
pub struct Goal {
    pub id: String,
    /// The actions the planner may use for this goal (`use`; `None`: all).
    pub actions: Option<Vec<String>>,
    pub facts: Vec<Fact>,
    /// The facts that hold when the task starts (`init`; every other fact
    /// is false): the planned FSM starts at the step they let it resume
    /// at. Empty: unknown, the FSM starts at the plan's first step.
    pub init: Vec<Fact>,
    /// Node id of a goal fact's condition, by its text (`Object-At(cube2, delivery)`).
    pub ids: BTreeMap<String, String>,
    pub labels: BTreeMap<String, String>,
}

/// A validated action domain.
#[derive(Debug, Clone, Default)]
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

/// Reads and validates a domain from its text (`super::validate`).
pub fn load(file: &Arc<SourceFile>) -> Result<Domain, Vec<Diagnostic>> {
    super::validate::load(file)
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
                btfsm_core::sanitize::shown(name),
                btfsm_core::sanitize::shown(name),
                btfsm_core::sanitize::shown(&self.name),
                suggest(name, self.tasks.iter().map(|(n, _)| n.as_str()))
            )),
        }
    }

    /// A ground fact of the domain from its text (`Object-At(cube2,
    /// delivery)`, or a PDDL atom `(robot_at leia kitchen)`), checked as a goal fact is (predicate, arity, objects of
    /// the parameters' types); the error: what is wrong and a hint.
    pub fn ground_fact(&self, text: &str) -> Result<Fact, (String, String)> {
        let file = SourceFile::new("fact", String::new());
        let text = &super::pddl::fact_text(text);
        let (found, diags) = super::validate::goal_fact(&file, text, self);
        match (found.into_iter().next(), diags.into_iter().next()) {
            (Some(p), None) => Ok(p.ground(&|_| None)),
            (_, Some(d)) => Err((d.message, d.hint.unwrap_or_default())),
            (None, None) => Err((
                "not a fact".into(),
                "a fact is `Predicate(object, ...)`".into(),
            )),
        }
    }

    /// Replaces the goal by `facts` (`--goal`), each checked as a goal fact
    /// of the domain is; the errors say what is wrong with each.
    pub fn set_goal(&mut self, facts: &[String]) -> Result<(), Vec<String>> {
        self.goal.facts = self.ground_facts(facts, "--goal", "goal")?;
        Ok(())
    }

    /// Replaces the facts that hold at the start by `facts` (`--init`),
    /// each checked as a goal fact is.
    pub fn set_init(&mut self, facts: &[String]) -> Result<(), Vec<String>> {
        self.goal.init = self.ground_facts(facts, "--init", "initial")?;
        Ok(())
    }

    /// `facts` checked and grounded, at most [`MAX_SIBLINGS`]; the errors
    /// name the option `flag` they were given with.
    fn ground_facts(
        &self,
        facts: &[String],
        flag: &str,
        what: &str,
    ) -> Result<Vec<Fact>, Vec<String>> {
        let mut errors = Vec::new();
        let mut out = Vec::new();
        for text in facts {
            match self.ground_fact(text) {
                Ok(f) => out.push(f),
                Err((msg, hint)) => errors.push(format!(
                    "{flag} `{}`: {msg} ({hint})",
                    btfsm_core::sanitize::shown(text)
                )),
            }
        }
        if out.len() > MAX_SIBLINGS {
            errors.push(format!(
                "{} {what} facts, more than {MAX_SIBLINGS}",
                out.len()
            ));
        }
        if errors.is_empty() {
            Ok(out)
        } else {
            Err(errors)
        }
    }
}

/// The built-in domain (`policies/domains/moma.toml`): the shared skill
/// library's preconditions and effects, for `convert --to fault-tolerant`
/// and `lint`.
pub fn builtin() -> &'static Domain {
    static D: std::sync::OnceLock<Domain> = std::sync::OnceLock::new();
    D.get_or_init(|| {
        let file = SourceFile::new(
            "policies/domains/moma.toml",
            include_str!("../../../policies/domains/moma.toml"),
        );
        load(&file).expect("the built-in domain is valid (plan tests)")
    })
}

/// An argument of a skill call as an object name.
fn object(v: &btfsm_model::skill::ArgValue) -> String {
    match v {
        btfsm_model::skill::ArgValue::Str(s) => s.clone(),
        other => other.to_string(),
    }
}

impl Domain {
    /// The fact a condition call checks: of the first predicate whose skill
    /// the call runs, its parameters taken from the call's arguments by
    /// name; `None` when no predicate has the skill or an argument is
    /// missing.
    pub fn fact_of(&self, c: &btfsm_model::skill::SkillCall) -> Option<Fact> {
        let p = self
            .predicates
            .iter()
            .find(|p| p.skill.as_deref() == Some(&c.skill))?;
        let args = p
            .params
            .iter()
            .map(|q| c.args.get(&q.name).map(object))
            .collect::<Option<Vec<_>>>()?;
        Some(Fact {
            pred: p.name.clone(),
            args,
        })
    }

    /// The action (its index) that runs a call's skill, its parameters
    /// bound to the call's arguments by name: the first action with the
    /// skill and every argument; `None` when there is none.
    pub fn action_of(
        &self,
        c: &btfsm_model::skill::SkillCall,
    ) -> Option<(usize, BTreeMap<String, String>)> {
        self.actions.iter().enumerate().find_map(|(i, a)| {
            if a.skill.as_deref() != Some(c.skill.as_str()) {
                return None;
            }
            let bind = a
                .params
                .iter()
                .map(|q| c.args.get(&q.name).map(|v| (q.name.clone(), object(v))))
                .collect::<Option<BTreeMap<_, _>>>()?;
            Some((i, bind))
        })
    }

    /// [`Domain::action_of`] as a ground step.
    pub fn step_of(&self, c: &btfsm_model::skill::SkillCall) -> Option<super::backchain::Step<'_>> {
        let (i, bind) = self.action_of(c)?;
        Some(super::backchain::Step {
            action: &self.actions[i],
            bind,
        })
    }

    /// The condition a fact stands for: its predicate's skill with the
    /// fact's objects as arguments.
    /// A fact as a guard term: its predicate's condition skill, negated or
    /// not.
    pub fn fact_term(&self, f: &Fact, negate: bool) -> btfsm_model::GuardTerm {
        btfsm_model::GuardTerm {
            condition: self.fact_condition(f),
            negate,
        }
    }

    pub fn fact_condition(&self, f: &Fact) -> btfsm_model::skill::SkillCall {
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
    ) -> btfsm_model::skill::SkillCall {
        btfsm_model::skill::SkillCall {
            skill: skill.to_string(),
            args: params
                .iter()
                .zip(objects)
                .map(|(p, o)| (p.name.clone(), btfsm_format::btcpp_xml::arg_value(o)))
                .collect(),
        }
    }
}
