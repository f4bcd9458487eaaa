//! SCXML reader, initial states: a region's `initial` attribute, its
//! `<initial><transition target>`, or its first child state in document
//! order (W3C SCXML 3.3); an `initial` naming a state deeper inside enters
//! each container on the way at the next one. See the module doc of [`super`].

use super::{Ctx, Kind, is_scxml, long_attr};
use crate::diagnostic::{Diagnostic, suggest};
use crate::format::xml::{self, XElem, shown};
use crate::model::{StateBody, StateMachine};

/// Sets the initial state of every region of `m`; `None` after an error
/// that stops the reading.
pub(super) fn initials(cx: &Ctx<'_>, m: &mut StateMachine, diags: &mut xml::Sink) -> Option<()> {
    let Ctx {
        doc,
        limits,
        found,
        ids,
        by_id,
        state_of,
        entry_of,
        ..
    } = *cx;
    let root = &doc.elems[doc.root];
    let f = &doc.file;
    let err = |diags: &mut xml::Sink, e: &XElem, msg: String, hint: &str| {
        diags.push(Diagnostic::error(msg).at(f, e.span.clone()).hint(hint));
    };
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
        if let Some(slot) = region_initial(m, container) {
            *slot = top_child;
        }
        // Each container on the way is entered at the next state of the
        // chain, unless its own `initial` says otherwise: then the model
        // (one initial state per container) cannot say both.
        for w in chain.windows(2) {
            let (inner, outer) = (w[0], w[1]);
            let Some(slot) = region_initial(m, Some(outer)) else {
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
        match first(m, None) {
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
            let fs = first(m, Some(c));
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
    Some(())
}
