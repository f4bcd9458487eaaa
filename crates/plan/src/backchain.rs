//! Static backchaining: a goal becomes a reactive Behavior Tree (the
//! Postcondition-Precondition-Action pattern of Colledanchise & Ögren,
//! "Behavior Trees in Robotics and AI", ch. 7, and the planner of the
//! paper's Fig. 1). Each condition c becomes `Fallback(c, Sequence(pre(a)…,
//! a), …)` over its achievers a (the actions adding c), cheapest first,
//! recursively; the expansion stops at a condition no action adds, at one
//! already expanded on the branch, or at the depth limit, where the
//! condition stays a leaf. An achiever without preconditions stands in the
//! Fallback directly.
//!
//! Then the preconditions of every Sequence are ordered so that no subtree
//! undoes the condition an earlier sibling ensured
//! ([`super::conflicts`], after HandlePriority of Colledanchise, Almeida &
//! Ögren 2019, "Towards Blended Reactive Planning and Acting using Behavior
//! Trees").

use super::conflicts::{self, Conflict};
use super::domain::{Action, Domain};
use super::fact::Fact;
use btfsm_model::skill::SkillCall;
use btfsm_model::{Bt, BtNode, BtNodeKind};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Planner settings.
#[derive(Debug, Clone)]
pub struct Options {
    /// Order the preconditions of each Sequence to resolve conflicts
    /// (`false`: the domain's order, conflicts only reported).
    pub reorder: bool,
    /// Deepest nesting of achievers below a goal condition.
    pub max_depth: usize,
    /// Most nodes of the tree.
    pub max_nodes: usize,
    /// Most achievers (groundings) tried per condition.
    pub max_achievers: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            reorder: true,
            max_depth: 16,
            max_nodes: 100_000,
            max_achievers: 64,
        }
    }
}

/// A planned tree, with the conflicts among Sequence siblings: resolved
/// (reordered), or left (a cycle, or `reorder` off).
#[derive(Debug, Clone)]
pub struct Planned {
    pub bt: Bt,
    pub conflicts: Vec<Conflict>,
    /// Per node of `bt`: the domain action (index) and its parameters'
    /// objects, for action nodes.
    pub steps: Vec<Option<(usize, BTreeMap<String, String>)>>,
    /// Per node of `bt`: the fact a condition node checks.
    pub ensured: Vec<Option<Fact>>,
}

/// Why planning failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    #[error("the tree would have more than {0} nodes")]
    TooLarge(usize),
}

/// A ground action: the action and its parameters' objects.
#[derive(Debug, Clone)]
pub struct Step<'d> {
    pub action: &'d Action,
    pub bind: BTreeMap<String, String>,
}

impl Step<'_> {
    pub fn adds(&self) -> Vec<Fact> {
        self.action
            .add
            .iter()
            .map(|p| p.ground(&|a| self.bind.get(a).cloned()))
            .collect()
    }
    pub fn deletes(&self) -> Vec<Fact> {
        self.action
            .del
            .iter()
            .map(|p| p.ground(&|a| self.bind.get(a).cloned()))
            .collect()
    }
    pub fn pre(&self) -> Vec<Fact> {
        self.action
            .pre
            .iter()
            .map(|p| p.ground(&|a| self.bind.get(a).cloned()))
            .collect()
    }
}

/// Backchains the domain's goal into a BT.
pub fn plan_bt(d: &Domain, opts: &Options) -> Result<Planned, PlanError> {
    let mut p = Planner {
        d,
        opts,
        nodes: Vec::new(),
        ids: HashMap::new(),
        conflicts: Vec::new(),
        ensured: Vec::new(),
        steps: Vec::new(),
        statics: statics(d),
        init: d.goal.init.iter().cloned().collect(),
    };
    let root = if let [only] = d.goal.facts.as_slice() {
        p.ensure(only, &mut Vec::new(), 0, Some(d.goal.id.clone()))?
    } else {
        let mut kids = Vec::new();
        for f in &d.goal.facts {
            kids.push(p.ensure(f, &mut Vec::new(), 0, None)?);
        }
        p.order(&mut kids);
        let id = d.goal.id.clone();
        p.push(
            id,
            BtNodeKind::Sequence.default_label().into(),
            BtNodeKind::Sequence,
            kids,
            None,
        )?
    };
    let mut bt = Bt {
        nodes: p.nodes,
        root,
    };
    // Pre-order, root first (what the writers and the named ids expect).
    let order = bt.preorder();
    let mut at = vec![0usize; bt.nodes.len()];
    for (i, &n) in order.iter().enumerate() {
        at[n] = i;
    }
    let steps = order
        .iter()
        .map(|&n| match bt.nodes[n].kind {
            BtNodeKind::Action => p.steps[n].first().cloned(),
            _ => None,
        })
        .collect();
    let ensured = (order.iter())
        .map(|&n| match bt.nodes[n].kind {
            BtNodeKind::Condition => p.ensured[n].clone(),
            _ => None,
        })
        .collect();
    let mut nodes: Vec<BtNode> = order.iter().map(|&n| bt.nodes[n].clone()).collect();
    for n in &mut nodes {
        for c in &mut n.children {
            *c = at[*c];
        }
    }
    bt = Bt { nodes, root: 0 };
    Ok(Planned {
        bt,
        conflicts: p.conflicts,
        steps,
        ensured,
    })
}

struct Planner<'d, 'o> {
    d: &'d Domain,
    opts: &'o Options,
    nodes: Vec<BtNode>,
    /// Ids given so far, with the next suffix to try.
    ids: HashMap<String, usize>,
    conflicts: Vec<Conflict>,
    /// Per node: the fact it ensures (a condition, or a Fallback over one).
    ensured: Vec<Option<Fact>>,
    /// Per node: the ground actions below it (for the conflict check).
    steps: Vec<Vec<(usize, BTreeMap<String, String>)>>,
    /// The static predicates (no action adds or deletes one of their
    /// facts) when the goal's `init` is known; empty otherwise.
    statics: BTreeSet<String>,
    init: BTreeSet<Fact>,
}

/// With the facts at the start known (`init`, every other false), the
/// predicates no action adds or deletes: their facts never change, so an
/// action needing one `init` does not list can never run.
fn statics(d: &Domain) -> BTreeSet<String> {
    if d.goal.init.is_empty() {
        return BTreeSet::new();
    }
    let changed: BTreeSet<&str> = (d.actions.iter())
        .flat_map(|a| a.add.iter().chain(&a.del))
        .map(|p| p.pred.as_str())
        .collect();
    (d.predicates.iter())
        .filter(|p| !changed.contains(p.name.as_str()))
        .map(|p| p.name.clone())
        .collect()
}

impl<'d> Planner<'d, '_> {
    fn push(
        &mut self,
        id: String,
        label: String,
        kind: BtNodeKind,
        children: Vec<usize>,
        skill: Option<SkillCall>,
    ) -> Result<usize, PlanError> {
        if self.nodes.len() >= self.opts.max_nodes {
            return Err(PlanError::TooLarge(self.opts.max_nodes));
        }
        let id = self.unique(id);
        let mut steps = Vec::new();
        for &c in &children {
            steps.extend(self.steps[c].iter().cloned());
        }
        self.nodes.push(BtNode {
            skill,
            ..BtNode::bare(id, label, kind, children)
        });
        self.ensured.push(None);
        self.steps.push(steps);
        Ok(self.nodes.len() - 1)
    }

    /// `id`, or `id~2`, `id~3`... when taken.
    fn unique(&mut self, id: String) -> String {
        match self.ids.get_mut(&id) {
            None => {
                self.ids.insert(id.clone(), 2);
                id
            }
            Some(k) => {
                let mut n = *k;
                let mut cand = format!("{id}~{n}");
                while self.ids.contains_key(&cand) {
                    n += 1;
                    cand = format!("{id}~{n}");
                }
                *self.ids.get_mut(&id).expect("present") = n + 1;
                self.ids.insert(cand.clone(), 2);
                cand
            }
        }
    }

    fn bind_of(&self, f: &Fact) -> BTreeMap<String, String> {
        let pred = self.d.predicate(&f.pred).expect("validated");
        pred.params
            .iter()
            .zip(&f.args)
            .map(|(p, a)| (p.name.clone(), a.clone()))
            .collect()
    }

    fn call(skill: &Option<String>, bind: &BTreeMap<String, String>) -> Option<SkillCall> {
        skill.as_ref().map(|s| SkillCall {
            skill: s.clone(),
            args: bind
                .iter()
                .map(|(k, v)| (k.clone(), btfsm_format::btcpp_xml::arg_value(v)))
                .collect(),
        })
    }

    /// The subtree that ensures `f`; `top_id` names its root (a goal).
    fn ensure(
        &mut self,
        f: &Fact,
        branch: &mut Vec<Fact>,
        depth: usize,
        top_id: Option<String>,
    ) -> Result<usize, PlanError> {
        let pred = self.d.predicate(&f.pred).expect("validated");
        let bind = self.bind_of(f);
        let text = f.to_string();
        let cond_id = self
            .d
            .goal
            .ids
            .get(&text)
            .cloned()
            .unwrap_or_else(|| self.d.fill(&pred.id, &bind));
        let label = self
            .d
            .goal
            .labels
            .get(&text)
            .cloned()
            .unwrap_or_else(|| self.d.fill(&pred.label, &bind));
        let cond = self.push(
            cond_id,
            label,
            BtNodeKind::Condition,
            vec![],
            Self::call(&pred.skill, &bind),
        )?;
        self.ensured[cond] = Some(f.clone());
        let achievers = if branch.contains(f) || depth >= self.opts.max_depth {
            Vec::new()
        } else {
            self.achievers(f)
        };
        if achievers.is_empty() {
            return Ok(cond);
        }
        branch.push(f.clone());
        let mut kids = vec![cond];
        for step in achievers {
            let a = step.action;
            let act = self.push(
                self.d.fill(&a.id, &step.bind),
                self.d.fill(&a.label, &step.bind),
                BtNodeKind::Action,
                vec![],
                Self::call(&a.skill, &step.bind),
            )?;
            let ai = self
                .d
                .actions
                .iter()
                .position(|x| std::ptr::eq(x, a))
                .expect("ours");
            self.steps[act].push((ai, step.bind.clone()));
            let pre = step.pre();
            if pre.is_empty() {
                kids.push(act);
                continue;
            }
            let mut seq = Vec::new();
            for p in &pre {
                seq.push(self.ensure(p, branch, depth + 1, None)?);
            }
            self.order(&mut seq);
            seq.push(act);
            let s = self.push(
                self.d.fill(&a.sequence_id, &step.bind),
                BtNodeKind::Sequence.default_label().into(),
                BtNodeKind::Sequence,
                seq,
                None,
            )?;
            kids.push(s);
        }
        branch.pop();
        let id = top_id.unwrap_or_else(|| self.d.fill(&pred.achieved_id, &bind));
        let fb = self.push(
            id,
            BtNodeKind::Fallback.default_label().into(),
            BtNodeKind::Fallback,
            kids,
            None,
        )?;
        self.ensured[fb] = Some(f.clone());
        Ok(fb)
    }

    /// The ground actions that add `f`, cheapest first, then in domain
    /// order, then by their objects; parameters `f` does not bind range
    /// over the objects of their type.
    fn achievers(&self, f: &Fact) -> Vec<Step<'d>> {
        let mut out: Vec<Step<'d>> = Vec::new();
        let mut order: Vec<usize> = (0..self.d.actions.len()).collect();
        order.sort_by_key(|&i| self.d.actions[i].cost);
        for i in order {
            let a = &self.d.actions[i];
            if let Some(allowed) = &self.d.goal.actions
                && !allowed.contains(&a.name)
            {
                continue;
            }
            for add in &a.add {
                if add.pred != f.pred {
                    continue;
                }
                // Unify the added pattern with f.
                let mut bind: BTreeMap<String, String> = BTreeMap::new();
                let mut ok = true;
                for (term, obj) in add.args.iter().zip(&f.args) {
                    if a.params.iter().any(|p| &p.name == term) {
                        match bind.get(term) {
                            Some(b) if b != obj => ok = false,
                            _ => {
                                bind.insert(term.clone(), obj.clone());
                            }
                        }
                    } else if term != obj {
                        ok = false;
                    }
                }
                if !ok || !self.possible(a, &bind) {
                    continue;
                }
                // Type check and ground the parameters left (a binding
                // whose static preconditions fail is dropped at once).
                let mut partial = vec![bind];
                for p in &a.params {
                    let mut next = Vec::new();
                    for b in partial {
                        match b.get(&p.name) {
                            Some(obj) => {
                                let typed = self
                                    .d
                                    .objects
                                    .get(obj)
                                    .is_some_and(|o| o.types.contains(&p.ty));
                                if typed && self.possible(a, &b) {
                                    next.push(b);
                                }
                            }
                            None => {
                                for obj in self.d.objects_of(&p.ty) {
                                    let mut b2 = b.clone();
                                    b2.insert(p.name.clone(), obj.to_string());
                                    if !self.possible(a, &b2) {
                                        continue;
                                    }
                                    next.push(b2);
                                    if next.len() > self.opts.max_achievers {
                                        break;
                                    }
                                }
                            }
                        }
                    }
                    partial = next;
                }
                for bind in partial {
                    if out.len() >= self.opts.max_achievers {
                        return out;
                    }
                    out.push(Step { action: a, bind });
                }
            }
        }
        out
    }

    /// Can `a` under the (partial) binding `bind` run as far as the static
    /// facts tell: each precondition on a static predicate whose terms are
    /// all bound is in `init`.
    fn possible(&self, a: &Action, bind: &BTreeMap<String, String>) -> bool {
        if self.statics.is_empty() {
            return true;
        }
        a.pre
            .iter()
            .filter(|p| self.statics.contains(&p.pred))
            .all(|p| {
                let is_param = |t: &String| a.params.iter().any(|q| &q.name == t);
                if p.args.iter().any(|t| is_param(t) && !bind.contains_key(t)) {
                    return true;
                }
                self.init.contains(&p.ground(&|t| bind.get(t).cloned()))
            })
    }

    /// Orders the precondition subtrees `kids` (see [`conflicts::order`]).
    fn order(&mut self, kids: &mut [usize]) {
        let ensured: Vec<Option<Fact>> = kids.iter().map(|&k| self.ensured[k].clone()).collect();
        let undoes: Vec<BTreeSet<Fact>> = kids
            .iter()
            .map(|&k| {
                let mut del = BTreeSet::new();
                for (ai, bind) in &self.steps[k] {
                    let step = Step {
                        action: &self.d.actions[*ai],
                        bind: bind.clone(),
                    };
                    del.extend(conflicts::undone_by(self.d, &step, &ensured));
                }
                del
            })
            .collect();
        let names: Vec<String> = kids.iter().map(|&k| self.nodes[k].id.clone()).collect();
        let (order, found) = conflicts::order(&ensured, &undoes, &names, self.opts.reorder);
        self.conflicts.extend(found);
        let old = kids.to_vec();
        for (slot, i) in kids.iter_mut().zip(order) {
            *slot = old[i];
        }
    }
}
