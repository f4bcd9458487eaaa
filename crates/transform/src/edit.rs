//! The paper's edit operations (sec. IV-A 1, Algorithm 1; SPEC §4's last
//! paragraph), as library functions that change a policy in place and say
//! what they touched:
//!
//! - BT ([`insert_subtree`], [`wrap_root`]): a subtree is inserted among a
//!   control node's children (Figs. 7a, 7b); a new root is put above the tree
//!   so that a subtree can be prepended or appended to the task (Figs. 7c,
//!   7d). Each inserted node costs one vertex and one edge (the paper's
//!   2n*).
//! - FSM ([`add_state`]): a *sequential* state takes its predecessor's
//!   `SUCCESS` arc and goes on to the predecessor's old successor (Figs. 8a,
//!   8c); an *alternative* state takes its predecessor's `FAILURE` arc and
//!   goes on where the predecessor would on success (Fig. 8b); a *connected*
//!   state (Algorithm 1, Fig. 8d) gets a guarded arc from every other action
//!   state and from the SELECTOR, `RUNNING` -> itself and `SUCCESS` ->
//!   SELECTOR (SPEC §4 and the authors' code; Algorithm 1 as printed writes
//!   `FAILURE`). A new sequential or alternative state copies its
//!   predecessor's `RUNNING` and `FAILURE` pattern and its guards to the
//!   connected states, so it joins their pattern (Fig. 8e). In an HFSM the
//!   same happens inside the region of the predecessor (or of a named
//!   container), whose decision state plays the SELECTOR; a new state never
//!   shifts another state's identity (SPEC §3: names unique in the machine,
//!   else positions).
//!
//! [`Touched::edits`] is the number of unit edits, which equals the named GED
//! between the policy before and after (tested on the paper's figures).

use btfsm_model::bt::{Arity, BtNode};
use btfsm_model::skill::{SkillKind, skill_kind, skill_names, skill_params};
use btfsm_model::{
    ArgValue, Bt, BtNodeKind, Guard, GuardTerm, SkillCall, State, StateBody, StateMachine, Target,
    Transition, Trigger,
};
use std::collections::{BTreeMap, HashSet};

/// What an edit touched.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Touched {
    /// BT nodes or FSM states created.
    pub added: usize,
    /// Existing nodes or states whose children or transitions changed.
    pub modified: usize,
    /// BT edges or FSM transitions created (a re-targeted transition counts
    /// as one removed and one added, as GED counts it).
    pub transitions_added: usize,
    /// BT edges or FSM transitions removed.
    pub transitions_removed: usize,
}

impl Touched {
    /// Unit edit operations: vertices and arcs added or removed.
    pub fn edits(&self) -> usize {
        self.added + self.transitions_added + self.transitions_removed
    }
}

/// Why an edit cannot be made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EditError {
    pub message: String,
    pub hint: Option<String>,
}

impl std::fmt::Display for EditError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)?;
        if let Some(h) = &self.hint {
            write!(f, "\n  = hint: {h}")?;
        }
        Ok(())
    }
}

impl std::error::Error for EditError {}

fn err(message: impl Into<String>, hint: Option<String>) -> EditError {
    EditError {
        message: message.into(),
        hint,
    }
}

fn one_of<'a>(what: &str, names: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let v: Vec<String> = names.into_iter().map(|n| format!("`{n}`")).collect();
    (!v.is_empty()).then(|| format!("{what}: {}", v.join(", ")))
}

// --- BT ---------------------------------------------------------------------------

/// Inserts the tree `sub` as child number `index` (default: last) of the
/// control node `parent`. Node ids of `sub` are kept, or prefixed with
/// `prefix/`; they must not collide with the tree's.
pub fn insert_subtree(
    bt: &mut Bt,
    parent: &str,
    index: Option<usize>,
    sub: &Bt,
    prefix: Option<&str>,
) -> Result<Touched, EditError> {
    let Some(p) = bt.nodes.iter().position(|n| n.id == parent) else {
        let controls = bt
            .nodes
            .iter()
            .filter(|n| n.kind.is_control())
            .map(|n| n.id.as_str());
        return Err(err(
            format!("unknown node `{parent}`"),
            one_of("control nodes of the tree", controls),
        ));
    };
    if bt.nodes[p].kind.arity() != Arity::AtLeastOne {
        return Err(err(
            format!(
                "node `{parent}` is a {} and cannot take another child",
                bt.nodes[p].kind.keyword()
            ),
            Some("insert under a sequence, fallback or parallel node".into()),
        ));
    }
    let len = bt.nodes[p].children.len();
    let index = index.unwrap_or(len);
    if index > len {
        return Err(err(
            format!("index {index} is past the end of `{parent}`'s {len} children"),
            Some(format!("use 0..={len} ({len} appends)")),
        ));
    }
    let new_id = |id: &str| match prefix {
        Some(pre) => format!("{pre}/{id}"),
        None => id.to_string(),
    };
    let existing: HashSet<&str> = bt.nodes.iter().map(|n| n.id.as_str()).collect();
    let clashes: Vec<String> = sub
        .preorder()
        .into_iter()
        .map(|i| new_id(&sub.nodes[i].id))
        .filter(|id| existing.contains(id.as_str()))
        .collect();
    if !clashes.is_empty() {
        return Err(err(
            format!(
                "the subtree's node ids already exist in the tree: {}",
                clashes.join(", ")
            ),
            Some("give --prefix to prefix the inserted ids, or rename them".into()),
        ));
    }
    // Copy the nodes reachable from the subtree's root.
    let order = sub.preorder();
    let offset = bt.nodes.len();
    let mut slot = vec![usize::MAX; sub.nodes.len()];
    for (k, &i) in order.iter().enumerate() {
        slot[i] = offset + k;
    }
    for &i in &order {
        let n = &sub.nodes[i];
        bt.nodes.push(BtNode {
            id: new_id(&n.id),
            label: n.label.clone(),
            kind: n.kind,
            children: n.children.iter().map(|&c| slot[c]).collect(),
            skill: n.skill.clone(),
            type_name: n.type_name.clone(),
            ports: n.ports.clone(),
            subtree: n.subtree.clone(),
            id_source: btfsm_model::IdSource::Given,
            span: None,
        });
    }
    bt.nodes[p].children.insert(index, slot[sub.root]);
    Ok(Touched {
        added: order.len(),
        modified: 1,
        transitions_added: order.len(),
        transitions_removed: 0,
    })
}

/// Puts a new control node `id` of `kind` above the root; the old root
/// becomes its only child (insert siblings with [`insert_subtree`]).
pub fn wrap_root(
    bt: &mut Bt,
    kind: BtNodeKind,
    id: &str,
    label: Option<&str>,
) -> Result<Touched, EditError> {
    if !kind.is_control() {
        return Err(err(
            format!("a {} cannot be a new root", kind.keyword()),
            Some("use sequence or fallback".into()),
        ));
    }
    if bt.nodes.iter().any(|n| n.id == id) {
        return Err(err(
            format!("node id `{id}` already exists"),
            Some("choose an unused id for the new root".into()),
        ));
    }
    bt.nodes.push(BtNode::bare(
        id.to_string(),
        label.unwrap_or(kind.default_label()).to_string(),
        kind,
        vec![bt.root],
    ));
    bt.root = bt.nodes.len() - 1;
    Ok(Touched {
        added: 1,
        modified: 0,
        transitions_added: 1,
        transitions_removed: 0,
    })
}

// --- FSM --------------------------------------------------------------------------

/// The three ways of adding a state (sec. IV-A 1b).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AddKind {
    Sequential,
    Alternative,
    Connected,
}

/// What [`add_state`] adds.
#[derive(Debug, Clone, PartialEq)]
pub struct AddState {
    pub kind: AddKind,
    pub name: String,
    /// The preceding state (sequential, alternative); for a connected state
    /// only its place in the file (default: before the SELECTOR). A name
    /// unique in the machine or a path (`Container/State`).
    pub after: Option<String>,
    /// HFSM: the container whose region gets the state when there is no
    /// `after` (default: the top level).
    pub within: Option<String>,
    pub skill: SkillCall,
    /// Connected: the guard every other action state gets to the new state
    /// (Algorithm 1's `condition`).
    pub guard: Option<Guard>,
    /// The SELECTOR's guard to the new state (Algorithm 1's
    /// `selector_condition`; connected: defaults to `guard`). Alternative
    /// states get none.
    pub selector_guard: Option<Guard>,
    /// Position of the SELECTOR's new guard among its guards (default:
    /// sequential, right before the guard to the predecessor; connected,
    /// first).
    pub selector_guard_index: Option<usize>,
}

fn outcome_target<'a>(s: &'a State, o: &str) -> Option<&'a Target> {
    s.transitions.iter().find_map(|t| match &t.trigger {
        Trigger::Outcome(x) if x == o => Some(&t.target),
        _ => None,
    })
}

fn set_outcome_target(s: &mut State, o: &str, target: Target) {
    for t in &mut s.transitions {
        if matches!(&t.trigger, Trigger::Outcome(x) if x == o) {
            t.target = target;
            return;
        }
    }
}

fn guard_transition(g: &Guard, target: usize) -> Transition {
    Transition {
        trigger: Trigger::Guard(g.clone()),
        target: Target::State(target),
        span: None,
    }
}

/// Inserts a guard transition at guard position `k` (clamped), keeping
/// guards before outcome transitions.
fn insert_guard(s: &mut State, k: usize, t: Transition) {
    let n_guards = s
        .transitions
        .iter()
        .filter(|t| matches!(t.trigger, Trigger::Guard(_)))
        .count();
    s.transitions.insert(k.min(n_guards), t);
}

/// Checks a skill binding against the shared library.
pub fn check_call(call: &SkillCall, kind: SkillKind) -> Result<(), EditError> {
    let what = match kind {
        SkillKind::Action => "action",
        SkillKind::Condition => "condition",
    };
    match skill_kind(&call.skill) {
        Some(k) if k == kind => {}
        Some(_) => {
            return Err(err(
                format!("`{}` is not an {what} skill", call.skill),
                one_of(&format!("{what} skills"), skill_names(kind)),
            ));
        }
        None => {
            return Err(err(
                format!("unknown skill `{}`", call.skill),
                one_of(&format!("{what} skills"), skill_names(kind)),
            ));
        }
    }
    let params = skill_params(&call.skill).unwrap_or(&[]);
    for (p, required) in params {
        if *required && !call.args.contains_key(*p) {
            return Err(err(
                format!("skill `{}` needs the argument `{p}`", call.skill),
                Some(format!("add `{p}=...`")),
            ));
        }
    }
    for k in call.args.keys() {
        if !params.iter().any(|(p, _)| p == k) {
            return Err(err(
                format!("skill `{}` takes no argument `{k}`", call.skill),
                one_of("its arguments", params.iter().map(|(p, _)| *p)),
            ));
        }
    }
    Ok(())
}

/// Is `s` the path of state `i` (`m.path(i) == s`, without building the
/// path: at most `s.len()` bytes compared, so trying every state of a deep
/// machine stays linear in the machine times the length of `s`)?
fn path_is(m: &StateMachine, i: usize, s: &str) -> bool {
    let mut rest = s;
    let mut cur = Some(i);
    while let Some(c) = cur {
        let name = m.states[c].name.as_str();
        let Some(before) = rest.strip_suffix(name) else {
            return false;
        };
        cur = m.states[c].parent;
        match cur {
            None => return before.is_empty(),
            Some(_) => match before.strip_suffix('/') {
                Some(b) => rest = b,
                None => return false,
            },
        }
    }
    false
}

/// A state by path (`Container/State`) or by a name unique in the machine.
fn find_state(m: &StateMachine, s: &str) -> Result<usize, EditError> {
    let n = m.states.len();
    if let Some(i) = (0..n).find(|&i| path_is(m, i, s)) {
        return Ok(i);
    }
    let named: Vec<usize> = (0..n).filter(|&i| m.states[i].name == s).collect();
    match named.as_slice() {
        [i] => Ok(*i),
        [] => Err(err(
            format!("unknown state `{s}`"),
            one_of(
                "states",
                (0..n)
                    .filter(|&i| m.states[i].parent.is_none())
                    .map(|i| m.states[i].name.as_str()),
            ),
        )),
        many => Err(err(
            format!("{} states are named `{s}`", many.len()),
            Some(format!(
                "give its path: {}",
                many.iter()
                    .map(|&i| format!("`{}`", m.path(i)))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        )),
    }
}

/// Adds a state to an FSM, or to a region of an HFSM (see the module
/// documentation).
pub fn add_state(m: &mut StateMachine, spec: &AddState) -> Result<Touched, EditError> {
    check_calls(spec)?;
    let after = spec
        .after
        .as_deref()
        .map(|a| find_state(m, a))
        .transpose()?;
    // The container whose region gets the state (`None`: the top level).
    let container = container_of_new(m, spec, after)?;
    let (top, outcomes) = region_of_new(m, container)?;
    check_name_free(m, spec, &top, &outcomes)?;
    let at = Placement {
        after,
        selector: top
            .iter()
            .copied()
            .find(|&i| matches!(m.states[i].body, StateBody::Decision)),
        n: m.states.len(),
    };
    let keys_before = m.hierarchical.then(|| m.keys());
    let mut new = State {
        name: spec.name.clone(),
        label: spec.name.clone(),
        parent: container,
        body: StateBody::Task(Some(spec.skill.clone())),
        transitions: Vec::new(),
        pseudo: None,
        span: None,
    };
    let mut touched = Touched {
        added: 1,
        ..Touched::default()
    };
    // The place of the new state in the file.
    let pos = match (after, at.selector) {
        (Some(p), _) => top
            .iter()
            .position(|&i| i == p)
            .map_or(top.len(), |k| k + 1),
        (None, Some(s)) => top.iter().position(|&i| i == s).unwrap_or(top.len()),
        (None, None) => top.len(),
    };
    match spec.kind {
        AddKind::Sequential | AddKind::Alternative => {
            link_after(m, spec, &at, &mut new, &mut touched)?;
        }
        AddKind::Connected => link_connected(m, spec, &at, &top, &mut new, &mut touched)?,
    }
    m.states.push(new);
    region_mut(m, container).states.insert(pos, at.n);
    // A state named by its position among siblings keeps its identity only
    // if the new state does not come before it: else it goes last.
    if let Some(before) = keys_before
        && m.keys()[..at.n] != before[..]
    {
        let r = region_mut(m, container);
        r.states.retain(|&i| i != at.n);
        r.states.push(at.n);
    }
    Ok(touched)
}

/// Where [`add_state`] puts the new state.
struct Placement {
    /// Its predecessor (`--after`).
    after: Option<usize>,
    /// The decision state of its region (the SELECTOR).
    selector: Option<usize>,
    /// Its index in the machine's states.
    n: usize,
}

/// Checks the new state's skill, and the conditions of its guards, against
/// the shared library.
fn check_calls(spec: &AddState) -> Result<(), EditError> {
    check_call(&spec.skill, SkillKind::Action)?;
    for g in spec.guard.iter().chain(&spec.selector_guard) {
        for t in &g.all {
            check_call(&t.condition, SkillKind::Condition)?;
        }
    }
    Ok(())
}

/// The container whose region gets the new state (`None`: the top level):
/// `--in`'s, which must hold the predecessor `after` if there is one, else
/// the predecessor's.
fn container_of_new(
    m: &StateMachine,
    spec: &AddState,
    after: Option<usize>,
) -> Result<Option<usize>, EditError> {
    match (&spec.within, after) {
        (None, a) => Ok(a.and_then(|a| m.states[a].parent)),
        (Some(c), a) => {
            let c = find_state(m, c)?;
            if !matches!(m.states[c].body, StateBody::Container(_)) {
                return Err(err(
                    format!("`{}` is not a container", m.path(c)),
                    Some("--in names a state that holds states".into()),
                ));
            }
            if let Some(a) = a
                && m.states[a].parent != Some(c)
            {
                return Err(err(
                    format!("state `{}` is not in `{}`", m.path(a), m.path(c)),
                    Some("drop --in: the new state goes beside its predecessor".into()),
                ));
            }
            Ok(Some(c))
        }
    }
}

/// The states and outcomes of the region of `container` (the top level for
/// `None`), which must not be parallel.
fn region_of_new(
    m: &StateMachine,
    container: Option<usize>,
) -> Result<(Vec<usize>, Vec<String>), EditError> {
    let r = match container {
        None => &m.top,
        Some(c) => match &m.states[c].body {
            StateBody::Container(r) => r,
            _ => unreachable!("checked above"),
        },
    };
    if r.parallel {
        // A state here would be a new region, run beside the others:
        // none of the paper's edit operations.
        return Err(err(
            format!(
                "`{}` is a parallel state: a state added to it would be a region of its own",
                container.map_or_else(String::new, |c| m.path(c))
            ),
            Some("add the state inside one of its regions (--in REGION)".into()),
        ));
    }
    Ok((r.states.clone(), r.outcomes.clone()))
}

/// Checks that the new state's name is not taken by a state (of its region
/// `top`, or of the machine in an HFSM) or an outcome.
fn check_name_free(
    m: &StateMachine,
    spec: &AddState,
    top: &[usize],
    outcomes: &[String],
) -> Result<(), EditError> {
    // HFSM vertex identity is the name where it is unique in the machine, so
    // a new name must be unique there (else other states' identities move).
    let taken = if m.hierarchical {
        m.states.iter().any(|s| s.name == spec.name)
    } else {
        top.iter().any(|&i| m.states[i].name == spec.name)
    };
    if taken || outcomes.contains(&spec.name) || m.top.outcomes.contains(&spec.name) {
        return Err(err(
            format!("a state or outcome `{}` already exists", spec.name),
            Some("choose an unused name".into()),
        ));
    }
    Ok(())
}

/// A transition on outcome `o`.
fn outcome(o: &str, target: Target) -> Transition {
    Transition {
        trigger: Trigger::Outcome(o.to_string()),
        target,
        span: None,
    }
}

/// Links a sequential or alternative state `new` after its predecessor:
/// it takes the predecessor's `SUCCESS` (or `FAILURE`) arc, copies its
/// `FAILURE` and `RUNNING` pattern and its guards to connected states, and
/// a sequential state gets the SELECTOR's guard.
fn link_after(
    m: &mut StateMachine,
    spec: &AddState,
    at: &Placement,
    new: &mut State,
    touched: &mut Touched,
) -> Result<(), EditError> {
    let (selector, n) = (at.selector, at.n);
    let Some(p) = at.after else {
        return Err(err(
            "a sequential or alternative state needs its predecessor",
            Some("give --after STATE".into()),
        ));
    };
    let connected = btfsm_metrics::counts::fully_connected_states(m);
    let pred = m.states[p].clone();
    let next = outcome_target(&pred, "SUCCESS").cloned().ok_or_else(|| {
        err(
            format!("state `{}` has no SUCCESS transition to follow", pred.name),
            None,
        )
    })?;
    // Guards of the predecessor to connected states come along.
    for t in &pred.transitions {
        if let (Trigger::Guard(_), Target::State(j)) = (&t.trigger, &t.target)
            && connected.contains(j)
        {
            new.transitions.push(t.clone());
        }
    }
    if spec.kind == AddKind::Sequential
        && let Some(s) = selector
        && spec.selector_guard.is_none()
    {
        return Err(err(
            format!(
                "the SELECTOR `{}` needs a guard to resume the task at `{}`",
                m.states[s].name, spec.name
            ),
            Some("give --selector-guard, e.g. 'In-Hand(object=cube2) & not Arm-Tucked'".into()),
        ));
    }
    let fail = outcome_target(&pred, "FAILURE").cloned();
    let running = outcome_target(&pred, "RUNNING").cloned();
    if spec.kind == AddKind::Sequential {
        set_outcome_target(&mut m.states[p], "SUCCESS", Target::State(n));
        new.transitions.push(outcome("SUCCESS", next));
        if let Some(f) = fail {
            new.transitions.push(outcome("FAILURE", f));
        }
    } else {
        let Some(f) = fail else {
            return Err(err(
                format!(
                    "state `{}` has no FAILURE transition to take over",
                    pred.name
                ),
                Some("an alternative state runs when its predecessor fails".into()),
            ));
        };
        set_outcome_target(&mut m.states[p], "FAILURE", Target::State(n));
        new.transitions.push(outcome("SUCCESS", next));
        new.transitions.push(outcome("FAILURE", f));
    }
    match running {
        Some(Target::State(r)) if r == p => {
            new.transitions.push(outcome("RUNNING", Target::State(n)))
        }
        Some(t) => new.transitions.push(outcome("RUNNING", t)),
        None => {}
    }
    touched.modified += 1;
    touched.transitions_added += 1 + new.transitions.len();
    touched.transitions_removed += 1;
    if spec.kind == AddKind::Sequential
        && let (Some(s), Some(g)) = (selector, &spec.selector_guard)
    {
        add_resume_guard(&mut m.states[s], spec.selector_guard_index, g, p, n);
        touched.modified += 1;
        touched.transitions_added += 1;
    }
    Ok(())
}

/// Gives the SELECTOR `sel` the guard `g` resuming the task at the new
/// state `n`, at guard position `index` (default: right before its guard
/// to the predecessor `p`).
fn add_resume_guard(sel: &mut State, index: Option<usize>, g: &Guard, p: usize, n: usize) {
    let k = index.unwrap_or_else(|| {
        sel.transitions
            .iter()
            .position(|t| matches!(t.trigger, Trigger::Guard(_)) && t.target == Target::State(p))
            .unwrap_or(usize::MAX)
    });
    insert_guard(sel, k, guard_transition(g, n));
}

/// Links a connected state `new` (Algorithm 1): a guarded arc from every
/// action state of its region `top` and from the SELECTOR, `SUCCESS` ->
/// SELECTOR and `RUNNING` -> itself.
fn link_connected(
    m: &mut StateMachine,
    spec: &AddState,
    at: &Placement,
    top: &[usize],
    new: &mut State,
    touched: &mut Touched,
) -> Result<(), EditError> {
    let n = at.n;
    let Some(s) = at.selector else {
        return Err(err(
            "a connected state returns to the SELECTOR, and this FSM has no decision state",
            Some("make the FSM fault tolerant first (btfsm convert --to fault-tolerant)".into()),
        ));
    };
    let Some(g) = &spec.guard else {
        return Err(err(
            "a connected state needs the guard every other state takes to it",
            Some("give --guard, e.g. 'not Battery-Level(min=20)'".into()),
        ));
    };
    let is_action = |m: &StateMachine, i: usize| {
        matches!(
            btfsm_model::graph::build::state_vertex_type(&m.states[i].body),
            btfsm_model::graph::VertexType::State
        )
    };
    for &i in top {
        if is_action(m, i) {
            insert_guard(&mut m.states[i], 0, guard_transition(g, n));
            touched.modified += 1;
            touched.transitions_added += 1;
        }
    }
    let sg = spec.selector_guard.as_ref().unwrap_or(g);
    insert_guard(
        &mut m.states[s],
        spec.selector_guard_index.unwrap_or(0),
        guard_transition(sg, n),
    );
    touched.modified += 1;
    touched.transitions_added += 1;
    new.transitions.push(outcome("SUCCESS", Target::State(s)));
    new.transitions.push(outcome("RUNNING", Target::State(n)));
    touched.transitions_added += 2;
    Ok(())
}

fn region_mut(m: &mut StateMachine, container: Option<usize>) -> &mut btfsm_model::Region {
    match container {
        None => &mut m.top,
        Some(c) => match &mut m.states[c].body {
            StateBody::Container(r) => r,
            _ => unreachable!("a container holds a region"),
        },
    }
}

/// Parses a guard written `Skill(key=value, ...) & not Skill ...`: terms
/// joined by `&`, each optionally negated with `not` or `!`. Values are
/// integers, floats, booleans or text. The label defaults to the text.
pub fn parse_guard(text: &str, label: Option<&str>) -> Result<Guard, EditError> {
    let bad = |why: String| {
        err(
            format!("invalid guard `{text}`: {why}"),
            Some("write terms like `In-Hand(object=cube2) & not Arm-Tucked`".into()),
        )
    };
    let mut all = Vec::new();
    for raw in text.split('&') {
        let mut t = raw.trim();
        let mut negate = false;
        if let Some(rest) = t.strip_prefix('!') {
            negate = true;
            t = rest.trim_start();
        } else if let Some(rest) = t.strip_prefix("not ") {
            negate = true;
            t = rest.trim_start();
        }
        let (name, args_text) = match t.find('(') {
            Some(k) => {
                let Some(inner) = t[k + 1..].strip_suffix(')') else {
                    return Err(bad(format!("`{t}` lacks its closing parenthesis")));
                };
                (t[..k].trim(), inner)
            }
            None => (t, ""),
        };
        if name.is_empty() {
            return Err(bad("a term has no condition".into()));
        }
        let mut args = BTreeMap::new();
        for kv in args_text
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
        {
            let Some((k, v)) = kv.split_once('=') else {
                return Err(bad(format!("argument `{kv}` is not key=value")));
            };
            args.insert(k.trim().to_string(), parse_value(v.trim()));
        }
        all.push(GuardTerm {
            condition: SkillCall {
                skill: name.to_string(),
                args,
            },
            negate,
        });
    }
    let label = label.map_or_else(|| text.trim().to_string(), str::to_string);
    Ok(Guard { all, label })
}

/// `key=value` argument text -> value (integer, float, boolean, else text).
pub fn parse_value(v: &str) -> ArgValue {
    let unq = v
        .strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(v);
    if unq.len() != v.len() {
        return ArgValue::Str(unq.to_string());
    }
    if let Ok(i) = v.parse::<i64>() {
        ArgValue::Int(i)
    } else if let Ok(x) = v.parse::<f64>()
        && v.contains('.')
    {
        ArgValue::Float(x)
    } else if v == "true" || v == "false" {
        ArgValue::Bool(v == "true")
    } else {
        ArgValue::Str(v.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::Limits;
    use btfsm_model::{Policy, PolicyBody};
    use std::path::Path;

    use crate::paper_policy as paper;

    use crate::named_ged as named;

    /// `path_is` agrees with `path` on every state and a few near misses,
    /// names with `/` included.
    #[test]
    fn paths_are_matched_without_building_them() {
        let p = btfsm_format::load(
            &Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
                .join("policies/paper/fig06-hfsm.toml"),
            &Limits::default(),
        )
        .unwrap()
        .policy;
        let PolicyBody::Machine(m) = &p.body else {
            panic!()
        };
        for i in 0..m.states.len() {
            let path = m.path(i);
            for j in 0..m.states.len() {
                assert_eq!(path_is(m, j, &path), i == j, "{path} vs {}", m.path(j));
            }
            assert!(!path_is(m, i, &format!("/{path}")));
            assert!(!path_is(m, i, &format!("x{path}")));
            assert!(!path_is(m, i, &path[1..]));
        }
    }

    fn bt(p: &mut Policy) -> &mut Bt {
        match &mut p.body {
            PolicyBody::Bt(b) => b,
            PolicyBody::Machine(_) => panic!("not a BT"),
        }
    }

    fn fsm(p: &mut Policy) -> &mut StateMachine {
        match &mut p.body {
            PolicyBody::Machine(m) => m,
            PolicyBody::Bt(_) => panic!("not an FSM"),
        }
    }

    fn sub(name: &str) -> Bt {
        match paper(&format!("lib/{name}")).body {
            PolicyBody::Bt(b) => b,
            PolicyBody::Machine(_) => panic!("not a BT"),
        }
    }

    /// Applies `edit` to a copy of `base` and checks that it reproduces
    /// `target` (named GED 0) and that its count of edits is the named GED.
    fn reproduces(base: &str, target: &str, edit: impl Fn(&mut Policy) -> Vec<Touched>) {
        let orig = paper(base);
        let mut p = orig.clone();
        let touched = edit(&mut p);
        assert_eq!(named(&p, &paper(target)), 0, "{base} -> {target}");
        let edits: usize = touched.iter().map(Touched::edits).sum();
        assert_eq!(edits as u64, named(&orig, &p), "{base} -> {target}: edits");
        // The result is a valid policy file.
        let text = btfsm_format::toml_write::write_policy(&p);
        let back = btfsm_format::toml::parse_str(
            "edited.toml",
            &text,
            Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper")),
            &Limits::default(),
        )
        .unwrap_or_else(|d| panic!("{text}\n{d:?}"));
        assert_eq!(named(&back.policy, &p), 0);
    }

    #[test]
    fn bt_edits_reproduce_fig07a_to_d() {
        reproduces("fig01-bt", "fig07a-bt", |p| {
            vec![insert_subtree(bt(p), "deliver", Some(1), &sub("tuck-arm"), None).unwrap()]
        });
        reproduces("fig01-bt", "fig07b-bt", |p| {
            vec![insert_subtree(bt(p), "reached-cube", None, &sub("safe-move-to"), None).unwrap()]
        });
        reproduces("fig01-bt", "fig07c-bt", |p| {
            vec![
                wrap_root(bt(p), BtNodeKind::Sequence, "root", None).unwrap(),
                insert_subtree(bt(p), "root", None, &sub("dock"), None).unwrap(),
            ]
        });
        reproduces("fig01-bt", "fig07d-bt", |p| {
            vec![
                wrap_root(bt(p), BtNodeKind::Sequence, "root", None).unwrap(),
                insert_subtree(bt(p), "root", Some(0), &sub("recharge"), None).unwrap(),
            ]
        });
    }

    fn spec(kind: AddKind, name: &str, after: Option<&str>, skill: &str) -> AddState {
        AddState {
            kind,
            name: name.into(),
            after: after.map(str::to_string),
            within: None,
            skill: SkillCall {
                skill: skill.into(),
                args: BTreeMap::new(),
            },
            guard: None,
            selector_guard: None,
            selector_guard_index: None,
        }
    }

    #[test]
    fn fsm_edits_reproduce_fig08a_to_d() {
        reproduces("fig04-fsm", "fig08a-fsm", |p| {
            let mut s = spec(
                AddKind::Sequential,
                "Tuck arm",
                Some("Pick cube2"),
                "Tuck-Arm",
            );
            s.selector_guard =
                Some(parse_guard("In-Hand(object=cube2) & not Arm-Tucked", None).unwrap());
            s.selector_guard_index = Some(1);
            vec![add_state(fsm(p), &s).unwrap()]
        });
        reproduces("fig04-fsm", "fig08b-fsm", |p| {
            let mut s = spec(
                AddKind::Alternative,
                "Safe-Move-To cube2",
                Some("Move-To cube2"),
                "Safe-Move-To",
            );
            s.skill
                .args
                .insert("target".into(), ArgValue::Str("cube2".into()));
            vec![add_state(fsm(p), &s).unwrap()]
        });
        reproduces("fig04-fsm", "fig08c-fsm", |p| {
            let mut s = spec(AddKind::Sequential, "Dock", Some("Place cube2"), "Dock");
            s.selector_guard =
                Some(parse_guard("Object-At(object=cube2, at=delivery)", None).unwrap());
            vec![add_state(fsm(p), &s).unwrap()]
        });
        reproduces("fig04-fsm", "fig08d-fsm", |p| {
            let mut s = spec(AddKind::Connected, "Recharge", None, "Recharge");
            s.guard =
                Some(parse_guard("not Battery-Level(min=20)", Some("battery < 20%")).unwrap());
            vec![add_state(fsm(p), &s).unwrap()]
        });
    }

    #[test]
    fn hfsm_states_are_added_inside_containers() {
        let orig = paper("fig06-hfsm");
        let mut p = orig.clone();
        let s = spec(AddKind::Sequential, "tuck", Some("pick"), "Tuck-Arm");
        let t = add_state(fsm(&mut p), &s).unwrap();
        assert_eq!(t.edits() as u64, named(&orig, &p));
        let m = fsm(&mut p);
        let tuck = m.states.iter().position(|s| s.name == "tuck").unwrap();
        assert_eq!(m.path(tuck), "fetch/tuck");
        // Pick's SUCCESS now goes to tuck, which ends the container.
        let pick = m.states.iter().position(|s| s.name == "pick").unwrap();
        assert_eq!(
            outcome_target(&m.states[pick], "SUCCESS"),
            Some(&Target::State(tuck))
        );
        assert_eq!(
            outcome_target(&m.states[tuck], "SUCCESS"),
            Some(&Target::Outcome("SUCCESS".into()))
        );
        // By path, and into a named container; clashes and wrong places are
        // explained.
        let mut q = orig.clone();
        let mut s = spec(
            AddKind::Alternative,
            "retry-move",
            Some("fetch/reached-cube/move-to-cube"),
            "Move-To",
        );
        s.skill
            .args
            .insert("target".into(), ArgValue::Str("cube2".into()));
        assert!(add_state(fsm(&mut q), &s).is_ok());
        let e = add_state(
            fsm(&mut q),
            &spec(AddKind::Sequential, "pick", Some("at-cube"), "Dock"),
        )
        .unwrap_err();
        assert!(e.message.contains("already exists"), "{}", e.message);
        let mut s = spec(AddKind::Sequential, "x", Some("pick"), "Dock");
        s.within = Some("reached-cube".into());
        let e = add_state(fsm(&mut q), &s).unwrap_err();
        assert!(
            e.message.contains("is not in `fetch/reached-cube`"),
            "{}",
            e.message
        );
        let mut s = spec(AddKind::Sequential, "x", None, "Dock");
        s.within = Some("pick".into());
        let e = add_state(fsm(&mut q), &s).unwrap_err();
        assert!(e.message.contains("not a container"), "{}", e.message);
    }

    /// A parallel state's states are its regions: adding one is refused;
    /// adding inside a region works.
    #[test]
    fn states_are_not_added_beside_parallel_regions() {
        let l = btfsm_format::scxml::parse_str(
            "p.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml">
  <parallel id="p"><state id="r1"><state id="a"><transition event="SUCCESS" target="r1done"/></state><final id="r1done"/></state><state id="r2"><state id="b"/></state></parallel>
</scxml>"#,
            &btfsm_format::Limits::default(),
        )
        .unwrap();
        let mut p = l.policy;
        let mut s = spec(AddKind::Sequential, "x", None, "Dock");
        s.within = Some("p".into());
        let e = add_state(fsm(&mut p), &s).unwrap_err();
        assert!(e.message.contains("is a parallel state"), "{}", e.message);
        let s = spec(AddKind::Sequential, "x", Some("a"), "Dock");
        add_state(fsm(&mut p), &s).unwrap();
        let m = fsm(&mut p);
        let x = m.states.iter().position(|s| s.name == "x").unwrap();
        assert_eq!(m.path(x), "p/r1/x");
    }

    #[test]
    fn touched_counts_follow_the_paper() {
        // Sec. IV-A 2b: a new state brings one vertex and at least 5 arcs (4
        // for an alternative); a connected one 4 + n.
        let mut p = paper("fig04-fsm");
        let mut s = spec(
            AddKind::Sequential,
            "Tuck arm",
            Some("Pick cube2"),
            "Tuck-Arm",
        );
        s.selector_guard = Some(parse_guard("Arm-Tucked", None).unwrap());
        let t = add_state(fsm(&mut p), &s).unwrap();
        assert_eq!(
            (
                t.added,
                t.modified,
                t.transitions_added,
                t.transitions_removed
            ),
            (1, 2, 5, 1)
        );
        let mut p = paper("fig04-fsm");
        let mut s = spec(AddKind::Connected, "Recharge", None, "Recharge");
        s.guard = Some(parse_guard("!Battery-Level(min=20)", None).unwrap());
        let t = add_state(fsm(&mut p), &s).unwrap();
        assert_eq!((t.added, t.modified, t.transitions_added), (1, 5, 7));
    }

    #[test]
    fn bad_edits_are_explained() {
        let mut p = paper("fig01-bt");
        let e = insert_subtree(bt(&mut p), "pick", None, &sub("dock"), None).unwrap_err();
        assert!(e.message.contains("cannot take another child"), "{e}");
        let e = insert_subtree(bt(&mut p), "nope", None, &sub("dock"), None).unwrap_err();
        assert!(e.message.contains("unknown node `nope`"), "{e}");
        let e = insert_subtree(bt(&mut p), "deliver", Some(9), &sub("dock"), None).unwrap_err();
        assert!(e.message.contains("past the end"), "{e}");
        insert_subtree(bt(&mut p), "deliver", None, &sub("dock"), None).unwrap();
        let e = insert_subtree(bt(&mut p), "deliver", None, &sub("dock"), None).unwrap_err();
        assert!(e.message.contains("already exist"), "{e}");
        insert_subtree(bt(&mut p), "deliver", None, &sub("dock"), Some("again")).unwrap();
        let mut f = paper("fig04-fsm");
        let s = spec(
            AddKind::Sequential,
            "Tuck arm",
            Some("Pick cube2"),
            "Tuck-Arm",
        );
        let e = add_state(fsm(&mut f), &s).unwrap_err();
        assert!(e.message.contains("needs a guard"), "{e}");
        assert_eq!(f, paper("fig04-fsm"), "a refused edit changes nothing");
        let s = spec(AddKind::Sequential, "X", Some("Pick cube2"), "Fly");
        assert!(
            add_state(fsm(&mut f), &s)
                .unwrap_err()
                .message
                .contains("unknown skill")
        );
        let s = spec(
            AddKind::Alternative,
            "Pick cube2",
            Some("Pick cube2"),
            "Dock",
        );
        assert!(
            add_state(fsm(&mut f), &s)
                .unwrap_err()
                .message
                .contains("already exists")
        );
        assert!(parse_guard("In-Hand(object=cube2", None).is_err());
    }

    #[test]
    fn guard_values() {
        let g = parse_guard(
            "Battery-Level(min=20) & not Robot-At(target=\"dock 1\")",
            None,
        )
        .unwrap();
        assert_eq!(g.all.len(), 2);
        assert_eq!(g.all[0].condition.args["min"], ArgValue::Int(20));
        assert!(g.all[1].negate);
        assert_eq!(
            g.all[1].condition.args["target"],
            ArgValue::Str("dock 1".into())
        );
        assert_eq!(parse_value("0.5"), ArgValue::Float(0.5));
        assert_eq!(parse_value("true"), ArgValue::Bool(true));
    }

    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// Law: the unit edits an edit sequence reports are the named GED
        /// it causes, and the result is a valid policy file.
        #[test]
        fn bt_edit_counts_are_the_named_ged(ops in proptest::collection::vec((0usize..64, 0usize..8, 0usize..4), 1..5)) {
            let subs = ["tuck-arm", "safe-move-to", "dock", "recharge"].map(sub);
            let orig = paper("fig01-bt");
            let mut p = orig.clone();
            let mut edits = 0;
            for (k, (parent, index, which)) in ops.into_iter().enumerate() {
                let b = bt(&mut p);
                let controls: Vec<usize> = (0..b.nodes.len()).filter(|&i| b.nodes[i].kind.is_control()).collect();
                let parent = controls[parent % controls.len()];
                let id = b.nodes[parent].id.clone();
                let index = index % (b.nodes[parent].children.len() + 1);
                let before = p.clone();
                let t = insert_subtree(bt(&mut p), &id, Some(index), &subs[which], Some(&format!("e{k}"))).unwrap();
                prop_assert_eq!(t.edits() as u64, named(&before, &p));
                edits += t.edits();
            }
            // Insertions never cancel out.
            prop_assert_eq!(edits as u64, named(&orig, &p));
            let text = btfsm_format::toml_write::write_policy(&p);
            prop_assert!(btfsm_format::toml::parse_str("e.toml", &text, Path::new("."), &Limits::default()).is_ok());
        }

        #[test]
        fn fsm_edit_counts_are_the_named_ged(ops in proptest::collection::vec((0usize..64, 0usize..3), 1..5)) {
            let orig = paper("fig04-fsm");
            let mut p = orig.clone();
            let mut edits = 0;
            for (k, (after, kind)) in ops.into_iter().enumerate() {
                let m = fsm(&mut p);
                let actions: Vec<String> = m.top.states.iter()
                    .filter(|&&i| matches!(m.states[i].body, StateBody::Task(_)))
                    .map(|&i| m.states[i].name.clone())
                    .collect();
                let kind = [AddKind::Sequential, AddKind::Alternative, AddKind::Connected][kind];
                let mut s = spec(kind, &format!("S{k}"), Some(&actions[after % actions.len()]), "Dock");
                s.guard = Some(parse_guard("not Battery-Level(min=20)", None).unwrap());
                s.selector_guard = Some(parse_guard("Robot-At(target=inspection)", None).unwrap());
                let before = p.clone();
                match add_state(fsm(&mut p), &s) {
                    // Each edit's count is the named GED of that step.
                    Ok(t) => {
                        prop_assert_eq!(t.edits() as u64, named(&before, &p));
                        edits += t.edits();
                    }
                    // A refused edit changes nothing.
                    Err(_) => prop_assert_eq!(&before, &p),
                }
            }
            // Edits of a sequence may cancel out (an arc re-routed twice).
            prop_assert!(edits as u64 >= named(&orig, &p));
            let text = btfsm_format::toml_write::write_policy(&p);
            prop_assert!(btfsm_format::toml::parse_str("e.toml", &text, Path::new("."), &Limits::default()).is_ok());
        }
        #[test]
        fn hfsm_edit_counts_are_the_named_ged(ops in proptest::collection::vec((0usize..64, 0usize..2), 1..5)) {
            let orig = crate::bt_to_hfsm::bt_policy_to_hfsm(&paper("fig01-bt")).unwrap();
            let mut p = orig.clone();
            for (k, (after, kind)) in ops.into_iter().enumerate() {
                let m = fsm(&mut p);
                let tasks: Vec<String> = (0..m.states.len())
                    .filter(|&i| matches!(m.states[i].body, StateBody::Task(_)))
                    .map(|i| m.path(i))
                    .collect();
                let kind = [AddKind::Sequential, AddKind::Alternative][kind];
                let s = spec(kind, &format!("S{k}"), Some(&tasks[after % tasks.len()]), "Dock");
                let before = p.clone();
                match add_state(fsm(&mut p), &s) {
                    Ok(t) => prop_assert_eq!(t.edits() as u64, named(&before, &p)),
                    Err(_) => prop_assert_eq!(&before, &p),
                }
            }
            let text = btfsm_format::toml_write::write_policy(&p);
            let back = btfsm_format::toml::parse_str("e.toml", &text, Path::new("."), &Limits::default());
            prop_assert!(back.is_ok(), "{}", text);
            prop_assert_eq!(named(&back.unwrap().policy, &p), 0);
        }
    }
}
