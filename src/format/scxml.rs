//! SCXML (W3C State Chart XML, 2015 Recommendation) read into the FSM/HFSM model.
//!
//! - `<scxml initial>` and nested `<state>`: a state holding states is a container,
//!   so a machine with any is an HFSM, else an FSM. A region's initial state is
//!   its `initial` attribute, its `<initial><transition target>`, or its first
//!   child state in document order (SCXML 3.3); an `initial` naming a state
//!   deeper inside enters each container on the way at the next one.
//! - `<final>` states are the outcomes of their region (top level: the machine's
//!   outcomes, vertices of the graph; inside a container: the container's).
//! - `<transition event cond target>`: an event that is an outcome the source
//!   state can return (`SUCCESS`, `FAILURE`, `RUNNING` of a task state, a
//!   container's final states) with no `cond` becomes an outcome transition;
//!   every other transition becomes a guard labelled `event`, `event [cond]` or
//!   `[cond]`. Targets may be in other regions (SCXML allows it). Transitions
//!   without a target change no state and are not counted (a warning says so).
//! - `<history>` is modelled as a decision pseudo-state of its region (its
//!   default transition, if any, is its guard); `<parallel>`, transitions with
//!   several targets, and transitions into a final state of another region are
//!   reported as unsupported with their position.
//! - Executable content (`<onentry>`, `<send>`, `<script>`, ...) and elements
//!   and attributes of other namespaces (Qt Creator's `qt:editorinfo`) are
//!   ignored; btfsm's own namespace carries what SCXML has no place for
//!   (`btfsm:name`, `btfsm:label`, `btfsm:skill`, `btfsm:arg.NAME`,
//!   `btfsm:decision` on states; `btfsm:label`, `btfsm:terms`, `btfsm:guard`
//!   on transitions), written by `btfsm convert --to scxml`.
//!
//! The document is walked with explicit stacks (no recursion on nesting depth).

use super::btcpp_xml::arg_value;
use super::xml::{self, BTFSM_NS, XDoc, XElem, shown};
use super::{Limits, Loaded};
use crate::diagnostic::{Diagnostic, SourceFile, suggest};
use crate::model::skill::{self, Guard, GuardTerm, SkillCall, SkillKind};
use crate::model::{
    Policy, PolicyBody, Pseudo, Region, State, StateBody, StateMachine, Target, Transition, Trigger,
};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

/// The SCXML namespace.
pub const SCXML_NS: &str = "http://www.w3.org/2005/07/scxml";

/// Outcomes a task state returns (as in the TOML format).
const TASK_OUTCOMES: &[&str] = &["SUCCESS", "FAILURE", "RUNNING"];

/// Reads an SCXML file.
pub fn load_file(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = super::toml::read_source(path, &shown, limits)?;
    load(file, limits)
}

/// Reads SCXML already read from a file.
pub fn load_read(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load(file, limits)
}

/// Reads SCXML from text.
pub fn parse_str(name: &str, text: &str, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load(SourceFile::new(name, text), limits)
}

/// A state-like element found in the document.
enum Kind {
    State,
    History(Pseudo),
    Final,
}

fn load(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    // Every element counts (states, transitions, executable content), as in
    // BehaviorTree.CPP files: memory is bounded before the states are read.
    let doc = xml::parse(&file, limits.max_nodes, limits.max_nodes).map_err(|d| vec![d])?;
    let mut diags = xml::Sink::default();
    let policy = read(&doc, limits, &mut diags);
    super::finish(&file, policy, diags.into_vec(&file), "state machine")
}

/// The first attribute of `e` (name or value) longer than
/// `--max-name-bytes`, as an error at the element: ids, names, labels, skill
/// arguments, events, conditions, targets.
fn long_attr(e: &XElem, f: &Arc<SourceFile>, limits: &Limits) -> Option<Diagnostic> {
    let max = limits.max_name_bytes;
    let (what, text) = std::iter::once(("element name".to_string(), e.name.as_str()))
        .chain(e.attrs.iter().flat_map(|a| {
            [
                ("attribute name".to_string(), a.name.as_str()),
                (format!("value of `{}`", shown(&a.name)), a.value.as_str()),
            ]
        }))
        .find(|(_, t)| t.len() > max)?;
    Some(
        Diagnostic::error(format!(
            "{what} `{}` of `<{}>` is {} bytes long, more than the limit of {max} bytes",
            shown(text),
            shown(&e.name),
            text.len()
        ))
        .at(f, e.span.clone())
        .hint("shorten it, or raise the limit with --max-name-bytes"),
    )
}

/// Is the element SCXML's (in its namespace, or in none)?
fn is_scxml(e: &XElem) -> bool {
    e.ns.is_none() || e.ns.as_deref() == Some(SCXML_NS)
}

fn read(doc: &XDoc, limits: &Limits, diags: &mut xml::Sink) -> Option<Policy> {
    let f = &doc.file;
    let err = |diags: &mut xml::Sink, e: &XElem, msg: String, hint: &str| {
        diags.push(Diagnostic::error(msg).at(f, e.span.clone()).hint(hint));
    };
    let root = &doc.elems[doc.root];
    if root.name != "scxml" || !is_scxml(root) {
        err(
            diags,
            root,
            format!(
                "expected `<scxml>` as the document element, found `<{}>`",
                shown(&root.name)
            ),
            "an SCXML file is `<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" initial=\"...\">`",
        );
        return None;
    }
    // Pass 1: state-like elements in document order, with their parent state.
    // (element, kind, parent entry index)
    let mut found: Vec<(usize, Kind, Option<usize>)> = Vec::new();
    if let Some(d) = long_attr(root, f, limits) {
        diags.push(d);
        return None;
    }
    // Containers around each entry of `found` (checked against --max-depth
    // as the document is read).
    let mut depth_of: Vec<usize> = Vec::new();
    // Ids inside unsupported `<parallel>` elements: transitions to them are
    // not reported again.
    let mut skipped: std::collections::HashSet<String> = std::collections::HashSet::new();
    let mut stack: Vec<(usize, Option<usize>)> = doc.elems[doc.root]
        .children
        .iter()
        .rev()
        .map(|&c| (c, None))
        .collect();
    while let Some((e, parent)) = stack.pop() {
        let el = &doc.elems[e];
        if !is_scxml(el) {
            continue; // foreign namespace (editor data)
        }
        let kind = match el.name.as_str() {
            "state" => Kind::State,
            "final" => Kind::Final,
            "history" => Kind::History(match el.attr("type") {
                Some("deep") => Pseudo::DeepHistory,
                _ => Pseudo::ShallowHistory,
            }),
            "parallel" => {
                err(
                    diags,
                    el,
                    "`<parallel>` states are not supported".into(),
                    "the paper's FSMs and HFSMs run one state per region; model each parallel region as its own machine",
                );
                let mut inner = vec![e];
                while let Some(x) = inner.pop() {
                    if let Some(id) = doc.elems[x].attr("id") {
                        skipped.insert(id.to_string());
                    }
                    inner.extend(doc.elems[x].children.iter().copied());
                }
                continue;
            }
            _ => continue, // transitions, initial, executable content: read later
        };
        if let Some(d) = long_attr(el, f, limits) {
            diags.push(d);
            return None;
        }
        let depth = parent.map_or(0, |p| depth_of[p] + 1);
        if depth > limits.max_depth && !matches!(kind, Kind::Final) {
            err(
                diags,
                el,
                format!(
                    "state `{}` is nested {depth} containers deep, deeper than the limit of {} levels",
                    shown(el.attr("id").unwrap_or(&el.name)),
                    limits.max_depth
                ),
                "raise the limit with --max-depth",
            );
            return None;
        }
        if found.len() >= limits.max_nodes {
            err(
                diags,
                el,
                format!("more than {} states", limits.max_nodes),
                "raise the limit with --max-nodes",
            );
            return None;
        }
        let idx = found.len();
        found.push((e, kind, parent));
        depth_of.push(depth);
        if matches!(found[idx].1, Kind::State) {
            for &c in el.children.iter().rev() {
                stack.push((c, Some(idx)));
            }
        }
    }
    // Ids: unique in the document (borrowed from the document where written).
    let mut generated = 0usize;
    let ids: Vec<std::borrow::Cow<'_, str>> = found
        .iter()
        .map(|(e, _, _)| {
            let el = &doc.elems[*e];
            match el.attr("id") {
                Some(id) => std::borrow::Cow::Borrowed(id),
                None => {
                    generated += 1;
                    std::borrow::Cow::Owned(format!("_{}{generated}", el.name))
                }
            }
        })
        .collect();
    let mut by_id: HashMap<&str, usize> = HashMap::with_capacity(ids.len());
    for (k, id) in ids.iter().enumerate() {
        if by_id.insert(id, k).is_some() {
            err(
                diags,
                &doc.elems[found[k].0],
                format!("duplicate id `{}`", shown(id)),
                "every state id in an SCXML document is unique",
            );
        }
    }
    // Model states (not finals), in document order.
    let mut m = StateMachine::unset();
    let mut state_of: Vec<Option<usize>> = vec![None; found.len()];
    for (k, (e, kind, parent)) in found.iter().enumerate() {
        let el = &doc.elems[*e];
        let name = el.btfsm_attr("name").unwrap_or(&ids[k]).to_string();
        let pstate = parent.and_then(|p| state_of[p]);
        if let Kind::Final = kind {
            match pstate {
                None => m.top.outcomes.push(name),
                Some(p) => {
                    if let StateBody::Container(r) = &mut m.states[p].body {
                        r.outcomes.push(name);
                    } else {
                        m.states[p].body = StateBody::Container(Region::unset(vec![name]));
                    }
                }
            }
            continue;
        }
        let si = m.states.len();
        state_of[k] = Some(si);
        let body = match kind {
            Kind::History(_) => StateBody::Decision,
            _ if el.btfsm_attr("decision") == Some("true") => StateBody::Decision,
            _ => StateBody::Task(el.btfsm_attr("skill").map(|s| {
                SkillCall {
                    skill: s.to_string(),
                    args: el
                        .attrs
                        .iter()
                        .filter(|a| a.ns.as_deref() == Some(BTFSM_NS))
                        .filter_map(|a| {
                            a.name
                                .strip_prefix("arg.")
                                .map(|k| (k.to_string(), arg_value(&a.value)))
                        })
                        .collect::<BTreeMap<_, _>>(),
                }
            })),
        };
        // A skill binding is checked as the TOML reader checks it (so that
        // the machine converts to TOML that reads back).
        if let StateBody::Task(Some(call)) = &body
            && let Some((msg, hint)) = call_problem(call, None)
        {
            diags.push(Diagnostic::error(msg).at(f, el.span.clone()).hint(hint));
        }
        m.states.push(State {
            label: el.btfsm_attr("label").unwrap_or(&name).to_string(),
            name,
            parent: pstate,
            body,
            transitions: Vec::new(),
            pseudo: match kind {
                Kind::History(p) => Some(*p),
                _ => None,
            },
            span: Some(el.span.clone()),
        });
        match pstate {
            None => m.top.states.push(si),
            Some(p) => match &mut m.states[p].body {
                StateBody::Container(r) => r.states.push(si),
                _ => {
                    m.states[p].body = StateBody::Container(Region {
                        initial: usize::MAX,
                        outcomes: vec![],
                        states: vec![si],
                    })
                }
            },
        }
    }
    m.hierarchical = m
        .states
        .iter()
        .any(|s| matches!(s.body, StateBody::Container(_)));
    // The entry of `found` (and id) of each model state.
    let mut entry_of: Vec<usize> = vec![0; m.states.len()];
    for (k, s) in state_of.iter().enumerate() {
        if let Some(s) = s {
            entry_of[*s] = k;
        }
    }
    // Initial states: (container, target id, position of the target).
    let region_owner = |k: Option<usize>| k.and_then(|p| state_of[p]);
    let mut initial_of: Vec<(Option<usize>, String, std::ops::Range<usize>)> = Vec::new();
    {
        let top_init = root
            .attr_full("initial")
            .map(|a| (a.value.clone(), a.span.clone()));
        if let Some((v, s)) = top_init {
            initial_of.push((None, v, s));
        }
        for (k, (e, kind, _)) in found.iter().enumerate() {
            if !matches!(kind, Kind::State) {
                continue;
            }
            let Some(si) = state_of[k] else { continue };
            if !matches!(m.states[si].body, StateBody::Container(_)) {
                continue;
            }
            let el = &doc.elems[*e];
            if let Some(a) = el.attr_full("initial") {
                initial_of.push((Some(si), a.value.clone(), a.span.clone()));
            } else if let Some((_, ini)) = doc
                .children(*e)
                .find(|(_, c)| is_scxml(c) && c.name == "initial")
            {
                let it = doc.children_of_name(ini, "transition");
                if let Some(d) = it.and_then(|t| long_attr(t, f, limits)) {
                    diags.push(d);
                    return None;
                }
                match it.and_then(|t| t.attr_full("target")) {
                    Some(a) => initial_of.push((Some(si), a.value.clone(), a.span.clone())),
                    None => err(
                        diags,
                        ini,
                        "`<initial>` needs a `<transition target>`".into(),
                        "write `<initial><transition target=\"FIRST\"/></initial>`",
                    ),
                }
            }
        }
    }
    // `initial` naming a state deeper inside the region (SCXML 3.3 allows
    // any descendant): (container, chain from the named state up to the
    // region's child, span), applied once every explicit initial is set.
    let mut deep: Vec<(Option<usize>, Vec<usize>, std::ops::Range<usize>)> = Vec::new();
    for (container, target, span) in initial_of {
        let tid = target.trim();
        if let Some(s) = by_id.get(tid).and_then(|&k| state_of[k])
            && m.states[s].parent != container
        {
            // Walk up (at most --max-depth levels) to the region's child.
            let mut chain = vec![s];
            let mut cur = m.states[s].parent;
            while let Some(p) = cur {
                if Some(p) == container {
                    break;
                }
                chain.push(p);
                cur = m.states[p].parent;
            }
            if cur == container && container.is_none_or(|c| chain.last() != Some(&c)) {
                deep.push((container, chain, span));
                continue;
            }
        }
        if tid.split_whitespace().count() > 1 {
            diags.push(
                Diagnostic::error(format!("initial `{}` names several states", shown(tid)))
                    .at(f, span)
                    .hint("only one initial state per region is supported (several are for `<parallel>`)"),
            );
            continue;
        }
        let ok = by_id
            .get(tid)
            .and_then(|&k| state_of[k])
            .filter(|&s| m.states[s].parent == container);
        match ok {
            Some(s) => match container {
                None => m.top.initial = s,
                Some(c) => {
                    if let StateBody::Container(r) = &mut m.states[c].body {
                        r.initial = s;
                    }
                }
            },
            None => {
                // Hints only for messages that will be shown: bounded work
                // under a million bad `initial`s.
                let h = if diags.room_for_errors() {
                    let region = m
                        .states
                        .iter()
                        .enumerate()
                        .filter(|(_, st)| st.parent == container && st.pseudo.is_none())
                        .map(|(i, _)| &*ids[entry_of[i]]);
                    suggest(tid, region)
                } else {
                    String::new()
                };
                diags.push(
                    Diagnostic::error(format!(
                        "initial `{}` is not a state directly inside its region",
                        shown(tid)
                    ))
                    .at(f, span)
                    .hint(if h.is_empty() {
                        "name a child state of this region".to_string()
                    } else {
                        h
                    }),
                );
            }
        }
    }
    for (container, chain, span) in deep {
        let top_child = *chain.last().expect("a chain has a state");
        fn region_initial(m: &mut StateMachine, c: Option<usize>) -> Option<&mut usize> {
            match c {
                None => Some(&mut m.top.initial),
                Some(c) => match &mut m.states[c].body {
                    StateBody::Container(r) => Some(&mut r.initial),
                    _ => None,
                },
            }
        }
        if let Some(slot) = region_initial(&mut m, container) {
            *slot = top_child;
        }
        // Each container on the way is entered at the next state of the
        // chain, unless its own `initial` says otherwise: then the model
        // (one initial state per container) cannot say both.
        for w in chain.windows(2) {
            let (inner, outer) = (w[0], w[1]);
            let Some(slot) = region_initial(&mut m, Some(outer)) else {
                continue;
            };
            if *slot == usize::MAX {
                *slot = inner;
            } else if *slot != inner {
                diags.push(
                    Diagnostic::error(format!(
                        "initial `{}` is inside `{}`, whose own initial state is another one",
                        shown(&ids[entry_of[chain[0]]]),
                        shown(&ids[entry_of[outer]])
                    ))
                    .at(f, span.clone())
                    .hint("the model enters a container at one state: name a state directly inside this region, or drop the inner `initial`"),
                );
                break;
            }
        }
    }
    // Default: the first child state in document order (one pass: states are
    // in document order).
    let mut first_child: Vec<Option<usize>> = vec![None; m.states.len()];
    let mut first_top: Option<usize> = None;
    for (i, st) in m.states.iter().enumerate() {
        if st.pseudo.is_some() {
            continue;
        }
        let slot = match st.parent {
            None => &mut first_top,
            Some(p) => &mut first_child[p],
        };
        if slot.is_none() {
            *slot = Some(i);
        }
    }
    let first = |_: &StateMachine, c: Option<usize>| match c {
        None => first_top,
        Some(c) => first_child[c],
    };
    if m.top.initial == usize::MAX {
        match first(&m, None) {
            Some(s) => m.top.initial = s,
            None => {
                err(
                    diags,
                    root,
                    "the machine has no states".into(),
                    "add `<state id=\"...\"/>` under `<scxml>`",
                );
                return None;
            }
        }
    }
    for c in 0..m.states.len() {
        let needs = matches!(&m.states[c].body, StateBody::Container(r) if r.initial == usize::MAX);
        if needs {
            let fs = first(&m, Some(c));
            match fs {
                Some(s) => {
                    if let StateBody::Container(r) = &mut m.states[c].body {
                        r.initial = s;
                    }
                }
                None => {
                    let span = m.states[c].span.clone().unwrap_or(0..0);
                    diags.push(
                        Diagnostic::error(format!(
                            "state `{}` holds only final states",
                            shown(&m.states[c].name)
                        ))
                        .at(f, span)
                        .hint("a compound state needs a state to start in; make it a plain state"),
                    );
                }
            }
        }
    }
    // Transitions.
    for (k, (e, kind, _)) in found.iter().enumerate() {
        let Some(si) = state_of[k] else { continue };
        if matches!(kind, Kind::Final) {
            continue;
        }
        let mut used_outcomes: HashSet<&str> = HashSet::new();
        let mut guards: Vec<Transition> = Vec::new();
        let mut outs: Vec<Transition> = Vec::new();
        // Outcomes the source can return, once per state (a container may
        // have many finals, and many transitions).
        let valid: HashSet<&str> = match &m.states[si].body {
            StateBody::Container(r) => r.outcomes.iter().map(String::as_str).collect(),
            StateBody::Decision => HashSet::from(["RUNNING"]),
            StateBody::Task(_) => TASK_OUTCOMES.iter().copied().collect(),
        };
        let src = shown(&ids[k]);
        for (_, t) in doc
            .children(*e)
            .filter(|(_, c)| is_scxml(c) && c.name == "transition")
        {
            if let Some(d) = long_attr(t, f, limits) {
                diags.push(d);
                return None;
            }
            let event = t.attr("event").map(str::trim).filter(|s| !s.is_empty());
            let cond = t.attr("cond").map(str::trim).filter(|s| !s.is_empty());
            let Some(ta) = t.attr_full("target") else {
                diags.push(
                    Diagnostic::warning(format!(
                        "transition of `{src}` has no target; it changes no state and is not counted"
                    ))
                    .at(f, t.span.clone())
                    .hint("give it a `target` to make it an arc of the machine's graph"),
                );
                continue;
            };
            let targets: Vec<&str> = ta.value.split_whitespace().collect();
            if targets.len() != 1 {
                diags.push(
                    Diagnostic::error(format!(
                        "transition of `{src}` has {} targets",
                        targets.len()
                    ))
                    .at(f, ta.span.clone())
                    .hint("give exactly one target (several are for `<parallel>` regions)"),
                );
                continue;
            }
            let tid = targets[0];
            let Some(&tk) = by_id.get(tid) else {
                if skipped.contains(tid) {
                    continue;
                }
                let h = if diags.room_for_errors() {
                    suggest(tid, ids.iter().map(|i| &**i))
                } else {
                    String::new()
                };
                diags.push(
                    Diagnostic::error(format!(
                        "unknown state `{}` in transition of `{src}`",
                        shown(tid)
                    ))
                    .at(f, ta.span.clone())
                    .hint(h),
                );
                continue;
            };
            let target = match state_of[tk] {
                Some(ts) => Target::State(ts),
                None => {
                    // A final state: an outcome of the source's own region.
                    let fparent = region_owner(found[tk].2);
                    if fparent == m.states[si].parent {
                        Target::Outcome(m_final_name(doc, &found, &ids, tk))
                    } else {
                        diags.push(
                            Diagnostic::error(format!(
                                "transition from `{src}` to final state `{}` of another region",
                                shown(tid)
                            ))
                            .at(f, ta.span.clone())
                            .hint("only a final state of the source's own region (its parent's outcome) is supported"),
                        );
                        continue;
                    }
                }
            };
            let span = Some(t.span.clone());
            match (event, cond) {
                (Some(ev), None)
                    if t.btfsm_attr("guard") != Some("true")
                        && (valid.contains(ev)
                            || (t.btfsm_attr("outcome") == Some("true")
                                && matches!(m.states[si].body, StateBody::Task(None))))
                        && !used_outcomes.contains(ev) =>
                {
                    used_outcomes.insert(ev);
                    outs.push(Transition {
                        trigger: Trigger::Outcome(ev.to_string()),
                        target,
                        span,
                    });
                }
                _ => {
                    let label = t
                        .btfsm_attr("label")
                        .map_or_else(|| guard_label(event, cond), str::to_string);
                    let all = match t.btfsm_attr("terms") {
                        None => vec![],
                        Some(text) => match parse_terms(text) {
                            Some(all) => {
                                let bad = all.iter().find_map(|term| {
                                    call_problem(&term.condition, Some(SkillKind::Condition))
                                });
                                if let Some((msg, hint)) = bad {
                                    diags.push(
                                        Diagnostic::error(format!("`btfsm:terms`: {msg}"))
                                            .at(f, t.span.clone())
                                            .hint(hint),
                                    );
                                    continue;
                                }
                                all
                            }
                            None => {
                                diags.push(
                                    Diagnostic::error(format!("unreadable `btfsm:terms` \"{}\"", shown(text)))
                                        .at(f, t.span.clone())
                                        .hint("write conditions as `Skill(arg=value, ...)`, `not ` to negate, separated by `; `"),
                                );
                                continue;
                            }
                        },
                    };
                    guards.push(Transition {
                        trigger: Trigger::Guard(Guard { all, label }),
                        target,
                        span,
                    });
                }
            }
        }
        guards.extend(outs);
        m.states[si].transitions = guards;
    }
    if diags.has_errors() {
        return None;
    }
    for (i, seen) in m.reachable().into_iter().enumerate() {
        if !seen {
            diags.push(
                Diagnostic::warning(format!(
                    "state `{}` is unreachable from the initial state",
                    shown(&ids[entry_of[i]])
                ))
                .at(f, m.states[i].span.clone().unwrap_or(0..0))
                .hint("add a transition to it, or remove it"),
            );
        }
    }
    let name = root
        .attr("name")
        .map(str::to_string)
        .unwrap_or_else(|| file_stem(&f.path));
    Some(Policy {
        name,
        description: None,
        body: PolicyBody::Machine(m),
    })
}

/// What is wrong with a skill call written in `btfsm:` attributes, as the
/// TOML reader would say it (`skill` and `args` of a state, `if` of a
/// guard): an unknown skill, one of the other kind, a missing or unknown
/// argument. `(message, hint)`.
fn call_problem(call: &SkillCall, want: Option<SkillKind>) -> Option<(String, String)> {
    let name = shown(&call.skill);
    let Some(kind) = skill::skill_kind(&call.skill) else {
        let cands: Vec<&str> = match want {
            Some(k) => skill::skill_names(k),
            None => skill::SKILLS.iter().map(|s| s.0).collect(),
        };
        return Some((
            format!("unknown skill `{name}`"),
            suggest(&call.skill, cands),
        ));
    };
    if let Some(w) = want
        && w != kind
    {
        return Some((
            format!("`{name}` is not a condition skill"),
            format!("condition skills are {}", skill::skill_names(w).join(", ")),
        ));
    }
    let params = skill::skill_params(&call.skill).unwrap_or(&[]);
    let all = || {
        params
            .iter()
            .map(|(p, _)| *p)
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some((p, _)) = params
        .iter()
        .find(|(p, required)| *required && !call.args.contains_key(*p))
    {
        return Some((
            format!("skill `{name}` needs argument `{p}`"),
            format!("its arguments are {}", all()),
        ));
    }
    if let Some(k) = call
        .args
        .keys()
        .find(|k| !params.iter().any(|(p, _)| p == k))
    {
        return Some((
            format!("skill `{name}` has no argument `{}`", shown(k)),
            if params.is_empty() {
                format!("`{name}` takes no arguments")
            } else {
                format!("its arguments are {}", all())
            },
        ));
    }
    None
}

/// The label of a guard read from SCXML: `event`, `event [cond]` or `[cond]`.
pub fn guard_label(event: Option<&str>, cond: Option<&str>) -> String {
    match (event, cond) {
        (Some(ev), Some(c)) => format!("{ev} [{c}]"),
        (Some(ev), None) => ev.to_string(),
        (None, Some(c)) => format!("[{c}]"),
        (None, None) => String::new(),
    }
}

/// Guard conditions as written in `btfsm:terms`:
/// `not In-Hand(object=cube2); Battery-Level(min=20)`.
pub fn parse_terms(text: &str) -> Option<Vec<GuardTerm>> {
    let mut out = Vec::new();
    for part in text.split("; ") {
        let (negate, rest) = match part.strip_prefix("not ") {
            Some(r) => (true, r),
            None => (false, part),
        };
        let open = rest.find('(')?;
        let inner = rest[open + 1..].strip_suffix(')')?;
        let skill = rest[..open].trim();
        if skill.is_empty() {
            return None;
        }
        let mut args = BTreeMap::new();
        for kv in inner.split(", ").filter(|kv| !kv.is_empty()) {
            let (k, v) = kv.split_once('=')?;
            args.insert(k.to_string(), arg_value(v));
        }
        out.push(GuardTerm {
            condition: SkillCall {
                skill: skill.to_string(),
                args,
            },
            negate,
        });
    }
    Some(out)
}

/// The outcome name of a final state.
fn m_final_name(
    doc: &XDoc,
    found: &[(usize, Kind, Option<usize>)],
    ids: &[std::borrow::Cow<'_, str>],
    k: usize,
) -> String {
    doc.elems[found[k].0]
        .btfsm_attr("name")
        .unwrap_or(&ids[k])
        .to_string()
}

fn file_stem(path: &str) -> String {
    Path::new(path)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("machine")
        .to_string()
}

impl XDoc {
    /// The first SCXML child element of `e` with a given name.
    pub fn children_of_name(&self, e: &XElem, name: &str) -> Option<&XElem> {
        e.children
            .iter()
            .map(|&c| &self.elems[c])
            .find(|c| is_scxml(c) && c.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine(l: &Loaded) -> &StateMachine {
        match &l.policy.body {
            PolicyBody::Machine(m) => m,
            _ => panic!("not a machine"),
        }
    }

    #[test]
    fn flat_machine_with_final_and_events() {
        let l = parse_str(
            "t.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a">
  <state id="a"><transition event="go" target="b"/><transition event="SUCCESS" target="done"/></state>
  <state id="b"><transition cond="x &gt; 1" target="a"/><transition event="e" cond="y" target="b"/></state>
  <final id="done"/>
</scxml>"#,
            &Limits::default(),
        )
        .unwrap();
        let m = machine(&l);
        assert!(!m.hierarchical);
        assert_eq!(m.top.outcomes, ["done"]);
        assert_eq!(m.states.len(), 2);
        let labels: Vec<String> = m.states[1]
            .transitions
            .iter()
            .map(|t| t.trigger.label())
            .collect();
        assert_eq!(labels, ["[x > 1]", "e [y]"]);
        assert_eq!(
            m.states[0].transitions[1].trigger,
            Trigger::Outcome("SUCCESS".into())
        );
        assert_eq!(
            m.states[0].transitions[1].target,
            Target::Outcome("done".into())
        );
    }

    #[test]
    fn nested_states_history_and_foreign_namespaces() {
        let l = parse_str(
            "t.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:qt="http://www.qt.io/2015/02/scxml-ext" version="1.0">
  <qt:editorinfo initialGeometry="1"/>
  <state id="p"><qt:editorinfo geometry="2"/>
    <state id="c1"><transition event="t" target="c2"/></state>
    <state id="c2"/>
    <history id="h"/>
  </state>
  <state id="q"><transition event="back" target="h"/></state>
</scxml>"#,
            &Limits::default(),
        )
        .unwrap();
        let m = machine(&l);
        assert!(m.hierarchical);
        assert_eq!(m.states.len(), 5);
        assert_eq!(m.states[3].pseudo, Some(Pseudo::ShallowHistory));
        let StateBody::Container(r) = &m.states[0].body else {
            panic!()
        };
        assert_eq!(m.states[r.initial].name, "c1");
        assert_eq!(m.states[4].transitions[0].target, Target::State(3));
    }

    const SEED: &str = r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:qt="http://www.qt.io/2015/02/scxml-ext" version="1.0" initial="a">
  <state id="a" initial="a1"><qt:editorinfo g="1"/>
    <state id="a1"><transition event="SUCCESS" target="a2"/></state>
    <state id="a2"><transition event="x" cond="In(a1)" target="done_a"/></state>
    <history id="h" type="deep"><transition target="a1"/></history>
    <final id="done_a"/>
    <transition event="done_a" target="b"/>
  </state>
  <state id="b"><transition event="back" target="h"/><transition event="end" target="end"/></state>
  <final id="end"/>
</scxml>"#;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

        /// Mutated machines never panic: they read (and write and read back
        /// at the same size) or give positioned errors.
        #[test]
        fn mutated_machines_never_panic(
            cuts in proptest::collection::vec((0usize..2000, 0usize..8, "[<>/=\" a-z0-9]{0,3}"), 1..4)
        ) {
            let text = crate::format::xml::mutate(SEED, &cuts);
            match parse_str("t.scxml", &text, &Limits::default()) {
                Ok(l) => {
                    let out = crate::format::scxml_write::write_policy(&l.policy).expect("a machine");
                    let back = parse_str("back.scxml", &out, &Limits::default())
                        .unwrap_or_else(|e| panic!("{out}\n{e:?}"));
                    proptest::prop_assert_eq!(machine(&back).states.len(), machine(&l).states.len());
                }
                Err(ds) => proptest::prop_assert!(ds.iter().any(|d| d.is_error() && d.location().is_some())),
            }
        }
    }

    #[test]
    fn seed_reads_and_round_trips() {
        let l = parse_str("t.scxml", SEED, &Limits::default()).unwrap();
        let m = machine(&l);
        assert_eq!(m.top.outcomes, ["end"]);
        assert_eq!(m.states.len(), 5);
        let StateBody::Container(r) = &m.states[0].body else {
            panic!()
        };
        assert_eq!(r.outcomes, ["done_a"]);
        let out = crate::format::scxml_write::write_policy(&l.policy).unwrap();
        let back = parse_str("b.scxml", &out, &Limits::default()).unwrap();
        // Equal but for source positions.
        let strip = |m: &StateMachine| {
            let mut m = m.clone();
            for st in &mut m.states {
                st.span = None;
                for t in &mut st.transitions {
                    t.span = None;
                }
            }
            m
        };
        assert_eq!(strip(machine(&back)), strip(m), "{out}");
    }

    #[test]
    fn unreachable_state_is_a_warning() {
        let l = parse_str(
            "t.scxml",
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n  <state id=\"a\"/>\n  <state id=\"z\"/>\n</scxml>",
            &Limits::default(),
        )
        .unwrap();
        assert_eq!(l.warnings.len(), 1);
        assert!(l.warnings[0].message.contains("`z` is unreachable"));
        assert_eq!(l.warnings[0].location().unwrap().1, 3);
    }

    #[test]
    fn a_transition_into_a_nested_state_reaches_its_containers() {
        // `a` jumps straight into `c1` inside `outer/inner`: both containers
        // are entered with it, so neither is unreachable; `lone` is.
        let l = parse_str(
            "t.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="a">
  <state id="a"><transition event="go" target="c1"/></state>
  <state id="outer"><state id="inner"><state id="c0"/><state id="c1"/></state></state>
  <state id="lone"/>
</scxml>"#,
            &Limits::default(),
        )
        .unwrap();
        let w: Vec<_> = l.warnings.iter().map(|d| d.message.clone()).collect();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w.iter().any(|m| m.contains("`c0` is unreachable")), "{w:?}");
        assert!(
            w.iter().any(|m| m.contains("`lone` is unreachable")),
            "{w:?}"
        );
    }

    #[test]
    fn an_initial_state_deeper_in_the_region_enters_the_containers_on_the_way() {
        // SCXML 3.3: `initial` may name any descendant. The machine starts in
        // `outer`, entered at `inner`, entered at `deep`.
        let l = parse_str(
            "t.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="deep">
  <state id="x"/>
  <state id="outer"><state id="o1"/><state id="inner"><state id="i1"/><state id="deep"/></state></state>
</scxml>"#,
            &Limits::default(),
        )
        .unwrap();
        let m = machine(&l);
        let name = |i: usize| m.states[i].name.as_str();
        assert_eq!(name(m.top.initial), "outer");
        let init = |i: usize| match &m.states[i].body {
            StateBody::Container(r) => r.initial,
            _ => panic!(),
        };
        assert_eq!(name(init(m.top.initial)), "inner");
        assert_eq!(name(init(init(m.top.initial))), "deep");
        // A container whose own initial says otherwise: the model cannot say both.
        let e = parse_str(
            "t.scxml",
            r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="deep">
  <state id="outer" initial="o1"><state id="o1"/><state id="deep"/></state>
</scxml>"#,
            &Limits::default(),
        )
        .unwrap_err();
        assert!(
            e[0].message
                .contains("whose own initial state is another one"),
            "{}",
            e[0]
        );
    }

    const HEAD: &str = "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" xmlns:btfsm=\"urn:btfsm\" version=\"1.0\">\n";

    #[test]
    fn long_events_conditions_and_names_are_errors_at_the_element() {
        let long = "e".repeat(5000);
        for (text, what) in [
            (
                format!("<state id=\"a\">\n<transition event=\"{long}\" target=\"a\"/></state>"),
                "value of `event`",
            ),
            (
                format!("<state id=\"a\">\n<transition cond=\"{long}\" target=\"a\"/></state>"),
                "value of `cond`",
            ),
            (
                format!("<state id=\"a\">\n<transition event=\"go\" target=\"{long}\"/></state>"),
                "value of `target`",
            ),
            (
                format!("<state id=\"a\">\n<state id=\"b\" btfsm:label=\"{long}\"/></state>"),
                "value of `label`",
            ),
        ] {
            let e = parse_str(
                "t.scxml",
                &format!("{HEAD}{text}\n</scxml>"),
                &Limits::default(),
            )
            .unwrap_err();
            assert!(
                e[0].message.starts_with(what)
                    && e[0]
                        .message
                        .contains("is 5000 bytes long, more than the limit of 4096 bytes"),
                "{}",
                e[0].message
            );
            assert!(e[0].message.len() < 300, "{}", e[0].message);
            assert_eq!(e[0].location().unwrap().1, 3, "{}", e[0]);
        }
    }

    #[test]
    fn depth_is_an_error_at_the_state() {
        let text = format!(
            "{HEAD}{}{}\n</scxml>",
            (0..8)
                .map(|i| format!("<state id=\"s{i}\">\n"))
                .collect::<String>(),
            "</state>".repeat(8)
        );
        let lim = |d| Limits {
            max_depth: d,
            ..Default::default()
        };
        assert!(parse_str("t.scxml", &text, &lim(7)).is_ok());
        let e = parse_str("t.scxml", &text, &lim(5)).unwrap_err();
        assert!(
            e[0].message
                == "state `s6` is nested 6 containers deep, deeper than the limit of 5 levels",
            "{}",
            e[0].message
        );
        assert_eq!(e[0].location().unwrap().1, 8);
    }

    /// A deep machine where no state is reachable: each warning names the
    /// state by its id, not by the path of ids above it (which made the
    /// messages quadratic in depth).
    #[test]
    fn unreachable_states_of_a_deep_machine_are_named_by_id() {
        let n = 50;
        let id = |i: usize| format!("{i:0>100}");
        let text = format!(
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" initial=\"z\"><state id=\"z\"/>{}{}</scxml>",
            (0..n)
                .map(|i| format!("<state id=\"{}\">", id(i)))
                .collect::<String>(),
            "</state>".repeat(n)
        );
        let l = parse_str("t.scxml", &text, &Limits::default()).unwrap();
        assert_eq!(l.warnings.len(), n);
        assert!(
            l.warnings.iter().all(|w| w.message.len() < 250),
            "{}",
            l.warnings[n - 1].message
        );
    }

    /// Skill bindings are checked as in TOML (found by fuzzing: an unknown
    /// skill was read, and its TOML conversion did not read back).
    #[test]
    fn skill_bindings_are_checked_as_in_toml() {
        for (attrs, want) in [
            (r#"btfsm:skill="Tu%k-Arm""#, "unknown skill `Tu%k-Arm`"),
            (
                r#"btfsm:skill="Pick""#,
                "skill `Pick` needs argument `object`",
            ),
            (
                r#"btfsm:skill="Dock" btfsm:arg.x="1""#,
                "skill `Dock` has no argument `x`",
            ),
        ] {
            let text = format!("{HEAD}<state id=\"a\" {attrs}/>\n</scxml>");
            let e = parse_str("t.scxml", &text, &Limits::default()).unwrap_err();
            assert_eq!(e[0].message, want);
            assert_eq!(e[0].location().unwrap().1, 2);
        }
        let text = format!(
            "{HEAD}<state id=\"a\"><transition event=\"go\" target=\"a\" btfsm:terms=\"Dock()\"/></state>\n</scxml>"
        );
        let e = parse_str("t.scxml", &text, &Limits::default()).unwrap_err();
        assert_eq!(
            e[0].message,
            "`btfsm:terms`: `Dock` is not a condition skill"
        );
        let ok = format!(
            "{HEAD}<state id=\"a\" btfsm:skill=\"Pick\" btfsm:arg.object=\"cube1\"><transition event=\"go\" target=\"a\" btfsm:terms=\"not Found()\"/></state>\n</scxml>"
        );
        assert!(parse_str("t.scxml", &ok, &Limits::default()).is_ok());
    }

    #[test]
    fn parallel_is_reported_with_its_position() {
        let e = parse_str(
            "t.scxml",
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n  <parallel id=\"p\"/>\n</scxml>",
            &Limits::default(),
        )
        .unwrap_err();
        let p = e
            .iter()
            .find(|d| d.message.contains("`<parallel>`"))
            .expect("parallel reported");
        assert_eq!(p.location().unwrap().1, 2);
    }
}
