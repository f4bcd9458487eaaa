//! SCXML reader, the elements: pass 1 collects the state-like elements
//! (`<state>`, `<final>`, `<history>`) in document order under the limits,
//! gives each an id, and makes the model's states and regions of them
//! (W3C SCXML 3.3, 3.7, 3.10). See the module doc of [`super`].

use super::transitions::call_problem;
use super::{Entry, Kind, is_scxml, long_attr};
use crate::Limits;
use crate::btcpp_xml::arg_value;
use crate::xml::{self, BTFSM_NS, XDoc, XElem, shown};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_model::skill::SkillCall;
use btfsm_model::{Pseudo, Region, State, StateBody, StateMachine};
use std::borrow::Cow;
use std::collections::BTreeMap;

/// The state-like elements in document order with their parent entry.
/// `None` after an error that stops the reading.
pub(super) fn collect(doc: &XDoc, limits: &Limits, diags: &mut xml::Sink) -> Option<Vec<Entry>> {
    let f = &doc.file;
    let err = |diags: &mut xml::Sink, e: &XElem, msg: String, hint: &str| {
        diags.push(Diagnostic::error(msg).at(f, e.span.clone()).hint(hint));
    };
    let root = &doc.elems[doc.root];
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
            "parallel" => Kind::Parallel,
            _ => continue, // transitions, initial, executable content: read later
        };
        if let Some(d) = long_attr(el, f, limits) {
            diags.push(d);
            return None;
        }
        // Apache Commons SCXML 0.x wrote a final state as `<state
        // final="true">`; W3C SCXML has no such attribute and reads an
        // ordinary state (which, without transitions, the machine never
        // leaves), as btfsm does.
        if matches!(kind, Kind::State) && el.attr("final") == Some("true") {
            diags.push(
                Diagnostic::warning(format!(
                    "`final=\"true\"` on `<state id=\"{}\">` is Apache Commons SCXML 0.x syntax; W3C SCXML reads an ordinary state",
                    shown(el.attr("id").unwrap_or(""))
                ))
                .at(f, el.span.clone())
                .hint("write a final state as `<final id=\"...\"/>`"),
            );
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
        if matches!(found[idx].1, Kind::State | Kind::Parallel) {
            for &c in el.children.iter().rev() {
                stack.push((c, Some(idx)));
            }
        }
    }
    Some(found)
}

/// Each entry's id: its `id`, else a generated `_state1`, `_final2`, ...
/// (borrowed from the document where written).
pub(super) fn ids<'d>(doc: &'d XDoc, found: &[Entry]) -> Vec<Cow<'d, str>> {
    let mut generated = 0usize;
    found
        .iter()
        .map(|(e, _, _)| {
            let el = &doc.elems[*e];
            match el.attr("id") {
                Some(id) => Cow::Borrowed(id),
                None => {
                    generated += 1;
                    Cow::Owned(format!("_{}{generated}", el.name))
                }
            }
        })
        .collect()
}

/// The model's states (not finals) in document order, their regions and
/// outcomes; `(machine, state of each entry, entry of each state)`.
pub(super) fn states(
    doc: &XDoc,
    found: &[Entry],
    ids: &[Cow<'_, str>],
    diags: &mut xml::Sink,
) -> (StateMachine, Vec<Option<usize>>, Vec<usize>) {
    let f = &doc.file;
    // Model states (not finals), in document order.
    let mut m = StateMachine::unset();
    let mut state_of: Vec<Option<usize>> = vec![None; found.len()];
    for (k, (e, kind, parent)) in found.iter().enumerate() {
        let el = &doc.elems[*e];
        let name = el.btfsm_attr("name").unwrap_or(&ids[k]).to_string();
        let pstate = parent.and_then(|p| state_of[p]);
        if let Kind::Final = kind {
            if !add_final(&mut m, pstate, name) {
                // SCXML 3.4: a `<parallel>` holds no `<final>`.
                diags.push(
                    Diagnostic::error(format!(
                        "final state `{}` directly inside `<parallel>`",
                        shown(&ids[k])
                    ))
                    .at(f, el.span.clone())
                    .hint("a parallel state completes when each of its regions reaches a final state: put the `<final>` inside a region's `<state>`"),
                );
            }
            continue;
        }
        let si = m.states.len();
        state_of[k] = Some(si);
        let body = state_body(el, kind);
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
        add_to_region(&mut m, pstate, si);
    }
    // A `<parallel>` with no states inside is entered and stays, as a
    // plain state.
    for s in &mut m.states {
        if matches!(&s.body, StateBody::Container(r) if r.parallel && r.states.is_empty()) {
            s.body = StateBody::Task(None);
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
    (m, state_of, entry_of)
}

/// Adds a final state as an outcome of its region: the machine's, or that
/// of its parent state (which becomes a container). `false` when the parent
/// is a `<parallel>`, which holds no final.
fn add_final(m: &mut StateMachine, parent: Option<usize>, name: String) -> bool {
    match parent {
        None => m.top.outcomes.push(name),
        Some(p) => {
            if let StateBody::Container(r) = &mut m.states[p].body {
                if r.parallel {
                    return false;
                }
                r.outcomes.push(name);
            } else {
                m.states[p].body = StateBody::Container(Region::unset(vec![name]));
            }
        }
    }
    true
}

/// What a state-like element (not a final) is: a history's decision, a
/// parallel container (its regions added as they are read), a decision
/// state, or a task with its skill binding.
fn state_body(el: &XElem, kind: &Kind) -> StateBody {
    match kind {
        Kind::History(_) => StateBody::Decision,
        // Its regions are added as they are read.
        // Outcomes only in `btfsm:outcomes` (a yasmin OrthogonalState's).
        Kind::Parallel => StateBody::Container(Region {
            parallel: true,
            ..Region::unset(
                el.btfsm_attr("outcomes")
                    .unwrap_or_default()
                    .split_whitespace()
                    .map(str::to_string)
                    .collect(),
            )
        }),
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
    }
}

/// Adds state `si` to its region: the machine's, or that of its parent
/// state (which becomes a container).
fn add_to_region(m: &mut StateMachine, parent: Option<usize>, si: usize) {
    match parent {
        None => m.top.states.push(si),
        Some(p) => match &mut m.states[p].body {
            StateBody::Container(r) => r.states.push(si),
            _ => {
                m.states[p].body = StateBody::Container(Region {
                    states: vec![si],
                    ..Region::unset(vec![])
                })
            }
        },
    }
}
