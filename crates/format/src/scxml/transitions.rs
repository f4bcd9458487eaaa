//! SCXML reader, transitions: `<transition event cond target>` as outcome
//! transitions or guards (W3C SCXML 3.5), and the `btfsm:` skill bindings
//! and guard terms checked as the TOML reader checks them. See the module
//! doc of [`super`].

use super::{Ctx, Entry, Kind, TASK_OUTCOMES, is_scxml, long_attr};
use crate::btcpp_xml::arg_value;
use crate::xml::{self, XDoc, XElem, shown};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_model::skill::{self, Guard, GuardTerm, SkillCall, SkillKind};
use btfsm_model::{StateBody, StateMachine, Target, Transition, Trigger};
use std::borrow::Cow;
use std::collections::{BTreeMap, HashSet};
use std::sync::Arc;

/// Where the states inside each state end. States are in document order
/// (pre-order): the states inside state `c` are those from `c + 1` up to
/// `inside_end[c]` (excluded), so whether a region encloses another is one
/// comparison.
struct Nesting {
    inside_end: Vec<usize>,
}

impl Nesting {
    /// The nesting of the states of `m`.
    fn of(m: &StateMachine) -> Nesting {
        let mut inside_end: Vec<usize> = (1..=m.states.len()).collect();
        for i in (0..m.states.len()).rev() {
            if let Some(p) = m.states[i].parent {
                inside_end[p] = inside_end[p].max(inside_end[i]);
            }
        }
        Nesting { inside_end }
    }

    /// Is the region of container `owner` (`None`: the top region) around
    /// the region of container `inner`, further out?
    fn encloses(&self, owner: Option<usize>, inner: Option<usize>) -> bool {
        match (owner, inner) {
            (_, None) => false,
            (None, Some(_)) => true,
            (Some(c), Some(p)) => c < p && p < self.inside_end[c],
        }
    }
}

/// Reads every state's transitions into `m`; `None` after an error that
/// stops the reading.
pub(super) fn transitions(cx: &Ctx<'_>, m: &mut StateMachine, diags: &mut xml::Sink) -> Option<()> {
    let nesting = Nesting::of(m);
    for (k, (_, kind, _)) in cx.found.iter().enumerate() {
        let Some(si) = cx.state_of[k] else { continue };
        if matches!(kind, Kind::Final) {
            continue;
        }
        m.states[si].transitions = state_transitions(cx, m, diags, &nesting, k, si)?;
    }
    Some(())
}

/// The transitions of entry `k` (model state `si`): its guards in document
/// order, then its outcome transitions. `None` after an error that stops
/// the reading.
fn state_transitions(
    cx: &Ctx<'_>,
    m: &StateMachine,
    diags: &mut xml::Sink,
    nesting: &Nesting,
    k: usize,
    si: usize,
) -> Option<Vec<Transition>> {
    let (doc, f) = (cx.doc, &cx.doc.file);
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
    let src = shown(&cx.ids[k]);
    for (_, t) in doc
        .children(cx.found[k].0)
        .filter(|(_, c)| is_scxml(c) && c.name == "transition")
    {
        if let Some(d) = long_attr(t, f, cx.limits) {
            diags.push(d);
            return None;
        }
        let event = t.attr("event").map(str::trim).filter(|s| !s.is_empty());
        let cond = t.attr("cond").map(str::trim).filter(|s| !s.is_empty());
        let Some(target) = transition_target(cx, m, diags, nesting, si, &src, t) else {
            continue;
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
                let Some(all) = guard_terms(diags, f, t) else {
                    continue;
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
    Some(guards)
}

/// Where transition `t` of state `si` (shown as `src`) goes: a state, an
/// outcome of the source's region, or of a region around it. `None` after
/// a warning (no target) or an error (several targets, an unknown one, a
/// final of a region not around the source).
fn transition_target(
    cx: &Ctx<'_>,
    m: &StateMachine,
    diags: &mut xml::Sink,
    nesting: &Nesting,
    si: usize,
    src: &str,
    t: &XElem,
) -> Option<Target> {
    let f = &cx.doc.file;
    let Some(ta) = t.attr_full("target") else {
        diags.push(
            Diagnostic::warning(format!(
                "transition of `{src}` has no target; it changes no state and is not counted"
            ))
            .at(f, t.span.clone())
            .hint("give it a `target` to make it an arc of the machine's graph"),
        );
        return None;
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
        return None;
    }
    let tid = targets[0];
    let Some(&tk) = cx.by_id.get(tid) else {
        let h = if diags.room_for_errors() {
            suggest(tid, cx.ids.iter().map(|i| &**i))
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
        return None;
    };
    if let Some(ts) = cx.state_of[tk] {
        return Some(Target::State(ts));
    }
    // A final state: an outcome of the source's own region,
    // or of a region enclosing it.
    let fparent = cx.found[tk].2.and_then(|p| cx.state_of[p]);
    let own = m.states[si].parent;
    if fparent == own {
        Some(Target::Outcome(m_final_name(cx.doc, cx.found, cx.ids, tk)))
    } else if nesting.encloses(fparent, own) {
        Some(Target::OuterOutcome {
            owner: fparent,
            outcome: m_final_name(cx.doc, cx.found, cx.ids, tk),
        })
    } else {
        diags.push(
            Diagnostic::error(format!(
                "transition from `{src}` to final state `{}` of a region that does not enclose it",
                shown(tid)
            ))
            .at(f, ta.span.clone())
            .hint("target a final state of the source's own region or of one around it"),
        );
        None
    }
}

/// The library conditions of a guard transition (its `btfsm:terms`, none
/// when absent); `None` after an error (unreadable, or a bad skill call).
fn guard_terms(diags: &mut xml::Sink, f: &Arc<SourceFile>, t: &XElem) -> Option<Vec<GuardTerm>> {
    let Some(text) = t.btfsm_attr("terms") else {
        return Some(vec![]);
    };
    match parse_terms(text) {
        Some(all) => {
            let bad = all
                .iter()
                .find_map(|term| call_problem(&term.condition, Some(SkillKind::Condition)));
            if let Some((msg, hint)) = bad {
                diags.push(
                    Diagnostic::error(format!("`btfsm:terms`: {msg}"))
                        .at(f, t.span.clone())
                        .hint(hint),
                );
                return None;
            }
            Some(all)
        }
        None => {
            diags.push(
                Diagnostic::error(format!("unreadable `btfsm:terms` \"{}\"", shown(text)))
                    .at(f, t.span.clone())
                    .hint("write conditions as `Skill(arg=value, ...)`, `not ` to negate, separated by `; `"),
            );
            None
        }
    }
}

/// What is wrong with a skill call written in `btfsm:` attributes, as the
/// TOML reader would say it (`skill` and `args` of a state, `if` of a
/// guard): an unknown skill, one of the other kind, a missing or unknown
/// argument. `(message, hint)`.
pub(super) fn call_problem(call: &SkillCall, want: Option<SkillKind>) -> Option<(String, String)> {
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
fn m_final_name(doc: &XDoc, found: &[Entry], ids: &[Cow<'_, str>], k: usize) -> String {
    doc.elems[found[k].0]
        .btfsm_attr("name")
        .unwrap_or(&ids[k])
        .to_string()
}
