//! Writes an FSM or HFSM as SCXML (used by `btfsm convert --to scxml`), so that
//! `format::scxml` reads back the same machine: states become `<state>` (containers
//! nested), outcomes `<final>` states of their region, outcome transitions
//! `<transition event="SUCCESS">`, guards `<transition event cond>` split back
//! from their label (`event`, `event [cond]`, `[cond]`; a label with spaces is a
//! `cond`), history pseudo-states `<history>`, parallel regions `<parallel>`
//! (no `initial`), an initial or a target that is an outcome (of the region's
//! own or of an enclosing one) the id of that region's `<final>`.
//!
//! SCXML ids are unique XML names in a document while model names are unique per
//! region and may hold spaces: a state's id is its name (or, when another state
//! or final has the same name, its path while that is at most
//! [`MAX_PATH_ID_BYTES`] long, else a generated `s<index>` / `f<index>_<k>`),
//! with characters outside XML names replaced by `_`; where the id differs
//! from the name, the name is kept in `btfsm:name`. So every name is written
//! once and every reference is short or the name itself: the output is
//! linear in the machine whatever its depth (indentation stops growing after
//! [`MAX_INDENT`] levels). Skill bindings, display labels, decision states, a guard's
//! library conditions (`btfsm:terms`) and a label the event/cond split would not
//! give back go in btfsm's namespace.

use super::scxml::guard_label;
use super::xml::{BTFSM_NS, escape_attr, escape_comment};
use btfsm_model::{
    Policy, PolicyBody, Pseudo, StateBody, StateMachine, Target, Transition, Trigger,
};
use std::collections::{HashMap, HashSet};
use std::fmt::Write;

/// Why a policy cannot be written as SCXML.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "`{name}` is a behavior tree; SCXML holds state machines (convert it with --to hfsm first, then to scxml)"
)]
pub struct NotAMachine {
    pub name: String,
}

/// SCXML text of an FSM or HFSM policy.
pub fn write_policy(p: &Policy) -> Result<String, NotAMachine> {
    let PolicyBody::Machine(m) = &p.body else {
        return Err(NotAMachine {
            name: p.name.clone(),
        });
    };
    Ok(write_machine(&p.name, p.description.as_deref(), m))
}

/// Longest path of names used as an id (longer: a generated id).
pub const MAX_PATH_ID_BYTES: usize = 64;

/// Nesting levels indented; deeper elements get no more indentation, so
/// that a deep machine's text is not quadratic in its depth.
pub const MAX_INDENT: usize = 32;

/// Indentation of an element `depth` levels deep.
pub(crate) fn indent(depth: usize) -> String {
    "  ".repeat(depth.min(MAX_INDENT))
}

/// An SCXML id (an XML NCName: no spaces, no `/`) made from a name.
fn xml_id(s: &str) -> String {
    let mut id: String = s
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !id.starts_with(|c: char| c.is_alphabetic() || c == '_') {
        id.insert(0, '_');
    }
    id
}

/// Splits a guard label into SCXML `event` and `cond`.
pub fn split_label(label: &str) -> (Option<&str>, Option<&str>) {
    let l = label.trim();
    if l.is_empty() {
        return (None, None);
    }
    if let Some(inner) = l.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        return (None, Some(inner));
    }
    if let Some(open) = l.find(" [")
        && l.ends_with(']')
        && !l[..open].contains(char::is_whitespace)
    {
        return (Some(&l[..open]), Some(&l[open + 2..l.len() - 1]));
    }
    if l.contains(char::is_whitespace) {
        (None, Some(l))
    } else {
        (Some(l), None)
    }
}

/// Where each outcome of a region is (the first of a name).
fn outcome_index(outcomes: &[String]) -> HashMap<&str, usize> {
    let mut at: HashMap<&str, usize> = HashMap::with_capacity(outcomes.len());
    for (k, o) in outcomes.iter().enumerate() {
        at.entry(o.as_str()).or_insert(k);
    }
    at
}

/// Unique SCXML ids handed out in turn: a clashing candidate gets the next
/// free `~k` suffix.
#[derive(Default)]
struct UniqueIds {
    used: HashSet<String>,
    /// Per clashing candidate, the next suffix to try (no rescans from 2).
    next_suffix: HashMap<String, usize>,
}

impl UniqueIds {
    /// The id for a name: the name as an XML id, made unique.
    fn unique(&mut self, cand: String) -> String {
        let cand = xml_id(&cand);
        let mut id = cand.clone();
        if self.used.contains(&id) {
            let k = self.next_suffix.entry(cand.clone()).or_insert(2);
            loop {
                id = format!("{cand}~{k}");
                *k += 1;
                if !self.used.contains(&id) {
                    break;
                }
            }
        }
        self.used.insert(id.clone());
        id
    }
}

/// The ids of a machine's elements: every state's, the finals of every
/// container and of the top region, and where each outcome's final is.
struct Ids<'m> {
    state: Vec<String>,
    /// Per state, the ids of its finals (a container's outcomes).
    finals: Vec<Vec<String>>,
    top_final: Vec<String>,
    top_at: HashMap<&'m str, usize>,
    /// Per state, where each outcome of its region is (containers only).
    region_at: Vec<Option<HashMap<&'m str, usize>>>,
}

impl<'m> Ids<'m> {
    /// Gives every state and final an id: its name when no other has it,
    /// else its path while short enough, else a generated one.
    fn of(m: &'m StateMachine) -> Ids<'m> {
        // Names of every state and every final; ids must be unique.
        let mut count: HashMap<&str, usize> = HashMap::new();
        for s in &m.states {
            *count.entry(s.name.as_str()).or_default() += 1;
            if let StateBody::Container(r) = &s.body {
                for o in &r.outcomes {
                    *count.entry(o.as_str()).or_default() += 1;
                }
            }
        }
        for o in &m.top.outcomes {
            *count.entry(o.as_str()).or_default() += 1;
        }
        let mut ids = UniqueIds::default();
        // Length of each state's path, without building it.
        let mut path_len: Vec<usize> = vec![0; m.states.len()];
        for c in m.parents_first() {
            let own = m.states[c].name.len();
            path_len[c] = m.states[c].parent.map_or(own, |p| path_len[p] + 1 + own);
        }
        // Top-level finals keep their names (they are vertices, keyed by name).
        let top_final: Vec<String> = m
            .top
            .outcomes
            .iter()
            .map(|o| ids.unique(o.clone()))
            .collect();
        let state: Vec<String> = (0..m.states.len())
            .map(|i| {
                let n = &m.states[i].name;
                ids.unique(if count[n.as_str()] == 1 {
                    n.clone()
                } else if path_len[i] <= MAX_PATH_ID_BYTES {
                    m.path(i)
                } else {
                    format!("s{i}")
                })
            })
            .collect();
        let finals: Vec<Vec<String>> = (0..m.states.len())
            .map(|i| match &m.states[i].body {
                StateBody::Container(r) => r
                    .outcomes
                    .iter()
                    .enumerate()
                    .map(|(k, o)| {
                        ids.unique(if count[o.as_str()] == 1 {
                            o.clone()
                        } else if path_len[i] + 1 + o.len() <= MAX_PATH_ID_BYTES {
                            format!("{}/{o}", m.path(i))
                        } else {
                            format!("f{i}_{k}")
                        })
                    })
                    .collect(),
                _ => vec![],
            })
            .collect();
        Ids {
            state,
            finals,
            top_final,
            top_at: outcome_index(&m.top.outcomes),
            region_at: m
                .states
                .iter()
                .map(|s| match &s.body {
                    StateBody::Container(r) => Some(outcome_index(&r.outcomes)),
                    _ => None,
                })
                .collect(),
        }
    }

    /// The final id of outcome `o` in the region of container `owner`
    /// (`None`: the top region).
    fn outcome(&self, owner: Option<usize>, o: &str) -> String {
        match owner {
            None => self
                .top_at
                .get(o)
                .map_or(o.to_string(), |&k| self.top_final[k].clone()),
            Some(p) => match &self.region_at[p] {
                Some(at) => at
                    .get(o)
                    .map_or(o.to_string(), |&k| self.finals[p][k].clone()),
                None => o.to_string(),
            },
        }
    }
}

/// SCXML text of machine `m` named `name`.
fn write_machine(name: &str, description: Option<&str>, m: &StateMachine) -> String {
    let ids = Ids::of(m);
    let mut out = String::new();
    // Pre-order with close events.
    let mut stack: Vec<(usize, usize, bool)> =
        m.top.states.iter().rev().map(|&s| (s, 1, false)).collect();
    while let Some((i, depth, close)) = stack.pop() {
        let s = &m.states[i];
        let pad = indent(depth);
        let tag = if s.pseudo.is_some() {
            "history"
        } else if matches!(&s.body, StateBody::Container(r) if r.parallel) {
            "parallel"
        } else {
            "state"
        };
        if close {
            if let StateBody::Container(r) = &s.body
                && !r.parallel
            {
                for (k, fid) in ids.finals[i].iter().enumerate() {
                    let _ = write!(out, "{pad}  <final id=\"{}\"", escape_attr(fid));
                    if *fid != r.outcomes[k] {
                        let _ = write!(out, " btfsm:name=\"{}\"", escape_attr(&r.outcomes[k]));
                    }
                    out.push_str("/>\n");
                }
            }
            let _ = writeln!(out, "{pad}</{tag}>");
            continue;
        }
        let _ = writeln!(out, "{pad}<{tag}{}>", state_attrs(&ids, m, i));
        // Outcomes the reader takes an `event` for (see `format::scxml`).
        let outcomes: Vec<&str> = match &s.body {
            StateBody::Container(r) => r.outcomes.iter().map(String::as_str).collect(),
            StateBody::Decision => vec!["RUNNING"],
            StateBody::Task(_) => vec!["SUCCESS", "FAILURE", "RUNNING"],
        };
        for t in &s.transitions {
            write_transition(&mut out, &ids, s.parent, t, &outcomes, &pad);
        }
        stack.push((i, depth, true));
        if let StateBody::Container(r) = &s.body {
            for &c in r.states.iter().rev() {
                stack.push((c, depth + 1, false));
            }
        }
    }
    for (fid, o) in ids.top_final.iter().zip(&m.top.outcomes) {
        let _ = write!(out, "  <final id=\"{}\"", escape_attr(fid));
        if fid != o {
            let _ = write!(out, " btfsm:name=\"{}\"", escape_attr(o));
        }
        out.push_str("/>\n");
    }
    out.push_str("</scxml>\n");
    let mut head = String::new();
    head.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    if let Some(d) = description {
        let _ = writeln!(head, "<!-- {} -->", escape_comment(d));
    }
    let _ = write!(
        head,
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" name=\"{}\" initial=\"{}\"",
        escape_attr(name),
        escape_attr(&match &m.top.initial {
            Target::State(j) => ids.state[*j].clone(),
            Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => ids.outcome(None, o),
        })
    );
    if out.contains(" btfsm:") {
        let _ = write!(head, " xmlns:btfsm=\"{BTFSM_NS}\"");
    }
    head.push_str(">\n");
    head + &out
}

/// The attributes of state `i`'s start tag: id, history type, initial,
/// and in btfsm's namespace a parallel state's outcomes, name, label,
/// skill binding and decision flag.
fn state_attrs(ids: &Ids<'_>, m: &StateMachine, i: usize) -> String {
    let s = &m.states[i];
    let mut attrs = format!(" id=\"{}\"", escape_attr(&ids.state[i]));
    match s.pseudo {
        Some(Pseudo::ShallowHistory) => attrs.push_str(" type=\"shallow\""),
        Some(Pseudo::DeepHistory) => attrs.push_str(" type=\"deep\""),
        None => {}
    }
    if let StateBody::Container(r) = &s.body
        && !r.parallel
    {
        let init = match &r.initial {
            Target::State(j) => ids.state[*j].clone(),
            Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => ids.outcome(Some(i), o),
        };
        let _ = write!(attrs, " initial=\"{}\"", escape_attr(&init));
    }
    // A parallel state's outcomes (yasmin's OrthogonalState; SCXML's
    // `<parallel>` holds no `<final>`).
    if let StateBody::Container(r) = &s.body
        && r.parallel
        && !r.outcomes.is_empty()
    {
        let _ = write!(
            attrs,
            " btfsm:outcomes=\"{}\"",
            escape_attr(&r.outcomes.join(" "))
        );
    }
    if ids.state[i] != s.name {
        let _ = write!(attrs, " btfsm:name=\"{}\"", escape_attr(&s.name));
    }
    if s.label != s.name {
        let _ = write!(attrs, " btfsm:label=\"{}\"", escape_attr(&s.label));
    }
    match &s.body {
        StateBody::Task(Some(call)) => {
            let _ = write!(attrs, " btfsm:skill=\"{}\"", escape_attr(&call.skill));
            for (k, v) in &call.args {
                let _ = write!(attrs, " btfsm:arg.{k}=\"{}\"", escape_attr(&v.to_string()));
            }
        }
        StateBody::Decision if s.pseudo.is_none() => attrs.push_str(" btfsm:decision=\"true\""),
        _ => {}
    }
    attrs
}

/// Writes one `<transition>` of a state whose parent is `parent` and which
/// returns `outcomes`.
fn write_transition(
    out: &mut String,
    ids: &Ids<'_>,
    parent: Option<usize>,
    t: &Transition,
    outcomes: &[&str],
    pad: &str,
) {
    let (event, cond) = match &t.trigger {
        Trigger::Outcome(o) => (Some(o.as_str()), None),
        Trigger::Guard(g) => split_label(&g.label),
    };
    // What SCXML cannot say, in btfsm's namespace: the exact label,
    // the library conditions, and a guard that looks like an outcome.
    let mut extra = String::new();
    if let Trigger::Guard(g) = &t.trigger {
        if guard_label(event, cond) != g.label {
            let _ = write!(extra, " btfsm:label=\"{}\"", escape_attr(&g.label));
        }
        if !g.all.is_empty() {
            let terms: Vec<String> = g.all.iter().map(ToString::to_string).collect();
            let _ = write!(extra, " btfsm:terms=\"{}\"", escape_attr(&terms.join("; ")));
        }
        if cond.is_none() && event.is_some_and(|e| outcomes.contains(&e)) {
            extra.push_str(" btfsm:guard=\"true\"");
        }
    }
    // An outcome the reader would take for an event (a state without
    // a skill returns any outcome, as yasmin states do).
    if let Trigger::Outcome(o) = &t.trigger
        && !outcomes.contains(&o.as_str())
    {
        extra.push_str(" btfsm:outcome=\"true\"");
    }
    let target = match &t.target {
        Target::State(j) => ids.state[*j].clone(),
        Target::Outcome(o) => ids.outcome(parent, o),
        Target::OuterOutcome { owner, outcome } => ids.outcome(*owner, outcome),
    };
    let mut ta = String::new();
    if let Some(e) = event {
        let _ = write!(ta, " event=\"{}\"", escape_attr(e));
    }
    if let Some(c) = cond {
        let _ = write!(ta, " cond=\"{}\"", escape_attr(c));
    }
    let _ = writeln!(
        out,
        "{pad}  <transition{ta} target=\"{}\"{extra}/>",
        escape_attr(&target)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Golden file: the paper's Fig. 6 HFSM as SCXML.
    #[test]
    fn fig06_as_scxml() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("policies/paper/fig06-hfsm.toml");
        let p = crate::load(&path, &Default::default()).unwrap().policy;
        insta::assert_snapshot!(write_policy(&p).unwrap());
    }

    /// A machine `n` containers deep whose every state is named `s`.
    fn deep_same_names(n: usize) -> String {
        format!(
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" xmlns:btfsm=\"urn:btfsm\" initial=\"s0\">{}<state id=\"leaf\" btfsm:name=\"s\"/>{}</scxml>",
            (0..n)
                .map(|i| format!("<state id=\"s{i}\" btfsm:name=\"s\">"))
                .collect::<String>(),
            "</state>".repeat(n)
        )
    }

    /// Ids of repeated names deep in the hierarchy are generated, not paths,
    /// and indentation stops growing: the text is linear in the depth; it
    /// reads back to the same machine.
    #[test]
    fn deep_machine_text_is_linear_in_depth() {
        let lim = crate::Limits {
            max_depth: 5000,
            ..Default::default()
        };
        let mut sizes = vec![];
        for n in [500, 2000] {
            let input = deep_same_names(n);
            let p = crate::scxml::parse_str("t.scxml", &input, &lim)
                .unwrap()
                .policy;
            let out = write_policy(&p).unwrap();
            assert!(
                out.len() < 8 * input.len(),
                "{n}: {} bytes from {}",
                out.len(),
                input.len()
            );
            sizes.push(out.len());
            let back = crate::scxml::parse_str("b.scxml", &out, &lim)
                .unwrap()
                .policy;
            let (PolicyBody::Machine(a), PolicyBody::Machine(b)) = (&p.body, &back.body) else {
                panic!()
            };
            assert_eq!(a.keys(), b.keys());
            assert_eq!(a.states.len(), b.states.len());
        }
        assert!(sizes[1] < 5 * sizes[0], "{sizes:?}");
    }

    #[test]
    fn labels_split_into_event_and_cond() {
        assert_eq!(split_label("go"), (Some("go"), None));
        assert_eq!(split_label("go [x > 1]"), (Some("go"), Some("x > 1")));
        assert_eq!(split_label("[x]"), (None, Some("x")));
        assert_eq!(split_label("battery < 20%"), (None, Some("battery < 20%")));
        assert_eq!(split_label(""), (None, None));
    }
}
