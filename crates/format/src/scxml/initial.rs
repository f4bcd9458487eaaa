//! SCXML reader, initial states: a region's `initial` attribute, its
//! `<initial><transition target>`, or its first child state in document
//! order (W3C SCXML 3.3); an `initial` naming a state deeper inside enters
//! each container on the way at the next one. See the module doc of [`super`].

use super::{Ctx, Kind, is_scxml, long_attr};
use crate::xml::{self, shown};
use btfsm_core::diagnostic::{Diagnostic, suggest};
use btfsm_model::{StateBody, StateMachine, Target, UNSET};
use std::ops::Range;

/// An `initial` as written: the container of its region (`None`: the
/// machine), its value and its span.
type Written = (Option<usize>, String, Range<usize>);

/// Per state an `initial` names, the chain from it up to the region's child.
type Chains = Vec<Vec<usize>>;

/// An `initial` naming states deeper than the region's children, applied
/// once every explicit initial is set.
type Deep = (Option<usize>, Chains, Range<usize>);

/// Sets the initial state of every region of `m`; `None` after an error
/// that stops the reading.
pub(super) fn initials(cx: &Ctx<'_>, m: &mut StateMachine, diags: &mut xml::Sink) -> Option<()> {
    let written = written_initials(cx, m, diags)?;
    let deep = explicit_initials(cx, m, diags, written);
    deep_initials(cx, m, diags, deep);
    default_initials(cx, m, diags)?;
    // A container holding only history states has none to start in.
    let f = &cx.doc.file;
    for c in 0..m.states.len() {
        if matches!(&m.states[c].body, StateBody::Container(r) if r.is_unset()) {
            let span = m.states[c].span.clone().unwrap_or(0..0);
            diags.push(
                Diagnostic::error(format!(
                    "state `{}` holds only history states",
                    shown(&m.states[c].name)
                ))
                .at(f, span)
                .hint("a compound state needs a state or a final state to start in"),
            );
        }
    }
    Some(())
}

/// The `initial`s written: the machine's attribute, then per container in
/// document order its attribute or its `<initial><transition target>`.
/// `None` after an error that stops the reading.
fn written_initials(cx: &Ctx<'_>, m: &StateMachine, diags: &mut xml::Sink) -> Option<Vec<Written>> {
    let doc = cx.doc;
    let f = &doc.file;
    let mut initial_of: Vec<Written> = Vec::new();
    let top_init = doc.elems[doc.root]
        .attr_full("initial")
        .map(|a| (a.value.clone(), a.span.clone()));
    if let Some((v, s)) = top_init {
        initial_of.push((None, v, s));
    }
    for (k, (e, kind, _)) in cx.found.iter().enumerate() {
        if !matches!(kind, Kind::State) {
            continue;
        }
        let Some(si) = cx.state_of[k] else { continue };
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
            if let Some(d) = it.and_then(|t| long_attr(t, f, cx.limits)) {
                diags.push(d);
                return None;
            }
            match it.and_then(|t| t.attr_full("target")) {
                Some(a) => initial_of.push((Some(si), a.value.clone(), a.span.clone())),
                None => {
                    diags.push(
                        Diagnostic::error("`<initial>` needs a `<transition target>`")
                            .at(f, ini.span.clone())
                            .hint("write `<initial><transition target=\"FIRST\"/></initial>`"),
                    );
                }
            }
        }
    }
    Some(initial_of)
}

/// Sets the initial of each region an `initial` names a child state or a
/// final of; returns those naming deeper states.
///
/// Each `initial` names states or a final (SCXML 3.3: any descendants
/// of the region; several for the regions of a `<parallel>` inside it).
/// A state directly inside is the region's initial state, a final of the
/// region its initial outcome; a deeper state gives a chain from it up to
/// the region's child, and each container on the way is entered at the
/// next state of the chain (applied once every explicit initial is set).
fn explicit_initials(
    cx: &Ctx<'_>,
    m: &mut StateMachine,
    diags: &mut xml::Sink,
    written: Vec<Written>,
) -> Vec<Deep> {
    let mut deep: Vec<Deep> = Vec::new();
    for (container, target, span) in written {
        let (chains, outcome) = match initial_targets(cx, m, diags, container, &target) {
            Ok(t) => t,
            Err((msg, hint)) => {
                diags.push(Diagnostic::error(msg).at(&cx.doc.file, span).hint(hint));
                continue;
            }
        };
        let start = match (outcome, chains.as_slice()) {
            (Some(o), _) => Target::Outcome(o),
            (None, [one]) if one.len() == 1 => Target::State(one[0]),
            (None, _) => {
                deep.push((container, chains, span));
                continue;
            }
        };
        if let Some(slot) = region_initial(m, container) {
            *slot = start;
        }
    }
    deep
}

/// What an `initial` of the region of `container` names: a chain per
/// state, or the region's final it starts in; else the problem (message
/// and hint).
fn initial_targets(
    cx: &Ctx<'_>,
    m: &StateMachine,
    diags: &xml::Sink,
    container: Option<usize>,
    target: &str,
) -> Result<(Chains, Option<String>), (String, String)> {
    let tids: Vec<&str> = target.split_whitespace().collect();
    let mut chains: Chains = Vec::with_capacity(tids.len());
    let mut outcome: Option<String> = None;
    for &tid in &tids {
        let Some(&k) = cx.by_id.get(tid) else {
            // Hints only for messages that will be shown: bounded work
            // under a million bad `initial`s.
            let h = if diags.room_for_errors() {
                let region = m
                    .states
                    .iter()
                    .enumerate()
                    .filter(|(_, st)| st.parent == container && st.pseudo.is_none())
                    .map(|(i, _)| &*cx.ids[cx.entry_of[i]]);
                suggest(tid, region)
            } else {
                String::new()
            };
            return Err((format!("initial `{}` is not a state", shown(tid)), h));
        };
        match cx.state_of[k] {
            Some(s) => {
                let Some(chain) = chain_up(m, s, container) else {
                    return Err((
                        format!("initial `{}` is not a state inside its region", shown(tid)),
                        "name a state inside this region".into(),
                    ));
                };
                chains.push(chain);
            }
            None if tids.len() == 1 && region_owner(cx, cx.found[k].2) == container => {
                outcome = Some(cx.final_name(k));
            }
            None => {
                return Err((
                    format!(
                        "initial `{}` is a final state that is not directly inside this region",
                        shown(tid)
                    ),
                    "a region may start in one of its own final states only".into(),
                ));
            }
        }
    }
    if tids.is_empty() {
        return Err((
            "empty `initial`".into(),
            "name the state to start in".into(),
        ));
    }
    // Several states: each in its own region of a parallel state, all
    // below one child of this region.
    if chains.iter().any(|c| c.last() != chains[0].last()) {
        return Err((
            format!(
                "initial `{}` names several states of this region",
                shown(target.trim())
            ),
            "a region starts in one state; several initial states must be in different regions of one `<parallel>`".into(),
        ));
    }
    Ok((chains, outcome))
}

/// The chain from state `s` up to the child of the region of `container`
/// (walking at most --max-depth levels); `None` when `s` is not inside
/// that region.
fn chain_up(m: &StateMachine, s: usize, container: Option<usize>) -> Option<Vec<usize>> {
    let mut chain = vec![s];
    let mut cur = m.states[s].parent;
    while let Some(p) = cur {
        if Some(p) == container {
            break;
        }
        chain.push(p);
        cur = m.states[p].parent;
    }
    (cur == container).then_some(chain)
}

/// Enters each region a deep `initial` names states below at the child on
/// the way, and each container on the way at the next state of the chain.
fn deep_initials(cx: &Ctx<'_>, m: &mut StateMachine, diags: &mut xml::Sink, deep: Vec<Deep>) {
    let (ids, entry_of) = (cx.ids, cx.entry_of);
    for (container, chains, span) in deep {
        let top_child = *chains[0].last().expect("a chain has a state");
        if let Some(slot) = region_initial(m, container) {
            *slot = Target::State(top_child);
        }
        // Each container on the way is entered at the next state of the
        // chain, unless its own `initial` says otherwise: then the model
        // (one initial state per region) cannot say both. A parallel state
        // enters all of its regions anyway.
        'chains: for chain in &chains {
            for w in chain.windows(2) {
                let (inner, outer) = (w[0], w[1]);
                if matches!(&m.states[outer].body, StateBody::Container(r) if r.parallel) {
                    continue;
                }
                let Some(slot) = region_initial(m, Some(outer)) else {
                    continue;
                };
                if *slot == UNSET {
                    *slot = Target::State(inner);
                } else if *slot != Target::State(inner) {
                    diags.push(
                        Diagnostic::error(format!(
                            "initial `{}` is inside `{}`, whose own initial state is another one",
                            shown(&ids[entry_of[chain[0]]]),
                            shown(&ids[entry_of[outer]])
                        ))
                        .at(&cx.doc.file, span.clone())
                        .hint("the model enters a container at one state: name a state directly inside this region, or drop the inner `initial`"),
                    );
                    break 'chains;
                }
            }
        }
    }
}

/// Sets the initial of every region still without one. `None` after an
/// error that stops the reading (a machine without states).
///
/// Default: the first child in document order (SCXML 3.3: a state, a
/// parallel state or a final; not a history). A parallel state's initial
/// is its first state (all are entered).
fn default_initials(cx: &Ctx<'_>, m: &mut StateMachine, diags: &mut xml::Sink) -> Option<()> {
    let mut first: Vec<Option<usize>> = vec![None; m.states.len()];
    let mut first_top: Option<usize> = None;
    for (k, (_, kind, parent)) in cx.found.iter().enumerate() {
        if matches!(kind, Kind::History(_)) {
            continue;
        }
        let slot = match region_owner(cx, *parent) {
            None if parent.is_some() => continue, // inside a refused element
            None => &mut first_top,
            Some(p) => &mut first[p],
        };
        if slot.is_none() {
            *slot = Some(k);
        }
    }
    let start_of = |k: usize| match cx.state_of[k] {
        Some(s) => Target::State(s),
        None => Target::Outcome(cx.final_name(k)),
    };
    if m.top.is_unset() {
        match first_top {
            Some(k) => m.top.initial = start_of(k),
            None => {
                let root = &cx.doc.elems[cx.doc.root];
                diags.push(
                    Diagnostic::error("the machine has no states")
                        .at(&cx.doc.file, root.span.clone())
                        .hint("add `<state id=\"...\"/>` under `<scxml>`"),
                );
                return None;
            }
        }
    }
    for (st, first) in m.states.iter_mut().zip(first) {
        if let StateBody::Container(r) = &mut st.body
            && r.is_unset()
        {
            if r.parallel {
                if let Some(&s) = r.states.first() {
                    r.initial = Target::State(s);
                }
            } else if let Some(k) = first {
                r.initial = start_of(k);
            }
        }
    }
    Some(())
}

/// The model state whose region the entry with parent entry `k` is in
/// (`None`: the machine's, or `k` is no model state).
fn region_owner(cx: &Ctx<'_>, k: Option<usize>) -> Option<usize> {
    k.and_then(|p| cx.state_of[p])
}

/// The slot of the initial of the region of container `c` (`None`: the top).
fn region_initial(m: &mut StateMachine, c: Option<usize>) -> Option<&mut Target> {
    match c {
        None => Some(&mut m.top.initial),
        Some(c) => match &mut m.states[c].body {
            StateBody::Container(r) => Some(&mut r.initial),
            _ => None,
        },
    }
}
