//! Writes a policy back as TOML in the format `format::toml` reads (used by
//! `btfsm convert`). Reading the output gives back the same policy.
//!
//! An HFSM is written with `[states.a.states.b...]` headers and a state of
//! another region is named by its path, so the text grows with depth times
//! names; the TOML reader reads at most [`MAX_TOML_STATE_DEPTH`] nested
//! containers. [`write_policy_within`] refuses what could not be read back
//! (deeper machines, text beyond a byte budget) before writing it, so the
//! output stays within a constant factor of the input.

use btfsm_model::{
    ArgValue, Bt, BtNodeKind, Guard, Policy, PolicyBody, Pseudo, SkillCall, StateBody,
    StateMachine, Target, Trigger,
};
use std::collections::BTreeMap;
use std::fmt::Write;

/// Most containers around a state that the TOML reader reads back (the
/// `toml` crate's nesting limit, 80 levels, over `[states.a.states.b...]`
/// headers): checked by `tests::deepest_readable_hfsm_reads_back`.
pub const MAX_TOML_STATE_DEPTH: usize = 39;

/// Why a policy is not written as TOML.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Unwritable {
    #[error(
        "`{name}` nests a state {depth} containers deep; the TOML format reads back at most {MAX_TOML_STATE_DEPTH}"
    )]
    TooDeep { name: String, depth: usize },
    #[error(
        "the TOML text of `{name}` would be longer than {max} bytes (--max-file-bytes), too big to read back"
    )]
    TooBig { name: String, max: u64 },
}

/// TOML text of a policy, or why it would not read back: an HFSM nested
/// deeper than [`MAX_TOML_STATE_DEPTH`], or text longer than `max_bytes`
/// (stopped as soon as it is: memory stays within the budget).
pub fn write_policy_within(p: &Policy, max_bytes: u64) -> Result<String, Unwritable> {
    let name = super::xml::shown(&p.name).into_owned();
    if let PolicyBody::Machine(m) = &p.body {
        let mut depth = vec![0usize; m.states.len()];
        for s in m.parents_first() {
            depth[s] = m.states[s].parent.map_or(0, |q| depth[q] + 1);
            if depth[s] > MAX_TOML_STATE_DEPTH {
                return Err(Unwritable::TooDeep {
                    name,
                    depth: depth[s],
                });
            }
        }
    }
    let max = usize::try_from(max_bytes).unwrap_or(usize::MAX);
    write_bounded(p, max).ok_or(Unwritable::TooBig {
        name,
        max: max_bytes,
    })
}

/// TOML text of a policy (however long).
pub fn write_policy(p: &Policy) -> String {
    write_bounded(p, usize::MAX).expect("no budget")
}

/// TOML text of a policy, or `None` once it is longer than `max` bytes.
fn write_bounded(p: &Policy, max: usize) -> Option<String> {
    let mut out = String::new();
    let kind = p.kind();
    let _ = writeln!(out, "kind = {}", quote(kind.as_str()));
    let _ = writeln!(out, "name = {}", quote(&p.name));
    if let Some(d) = &p.description {
        let _ = writeln!(out, "description = {}", quote(d));
    }
    match &p.body {
        PolicyBody::Bt(bt) => write_bt(&mut out, bt, max)?,
        PolicyBody::Machine(m) => write_machine(&mut out, m, max)?,
    }
    (out.len() <= max).then_some(out)
}

/// A TOML basic string.
pub fn quote(s: &str) -> String {
    let mut q = String::with_capacity(s.len() + 2);
    q.push('"');
    for c in s.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            '\n' => q.push_str("\\n"),
            '\t' => q.push_str("\\t"),
            '\r' => q.push_str("\\r"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                let _ = write!(q, "\\u{:04X}", c as u32);
            }
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

/// A TOML key: bare when possible, else quoted.
pub fn key(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        s.to_string()
    } else {
        quote(s)
    }
}

fn arg(v: &ArgValue) -> String {
    match v {
        ArgValue::Str(s) => quote(s),
        ArgValue::Int(i) => i.to_string(),
        ArgValue::Float(x) if x.is_finite() && x.fract() == 0.0 => format!("{x:.1}"),
        ArgValue::Float(x) => x.to_string(),
        ArgValue::Bool(b) => b.to_string(),
    }
}

fn args_inline(args: &BTreeMap<String, ArgValue>) -> String {
    let parts: Vec<String> = args
        .iter()
        .map(|(k, v)| format!("{} = {}", key(k), arg(v)))
        .collect();
    format!("{{ {} }}", parts.join(", "))
}

fn skill_fields(call: &SkillCall) -> String {
    let mut s = format!("skill = {}", quote(&call.skill));
    if !call.args.is_empty() {
        let _ = write!(s, ", args = {}", args_inline(&call.args));
    }
    s
}

fn write_bt(out: &mut String, bt: &Bt, max: usize) -> Option<()> {
    let _ = writeln!(out, "root = {}", quote(&bt.nodes[bt.root].id));
    let _ = writeln!(out, "\n[nodes]");
    for i in bt.preorder() {
        let n = &bt.nodes[i];
        let mut fields: Vec<String> = Vec::new();
        let kw = n.kind.keyword();
        match n.kind {
            BtNodeKind::Action | BtNodeKind::Condition => {
                fields.push(format!("{kw} = {}", quote(&n.label)));
                if let Some(call) = &n.skill {
                    fields.push(skill_fields(call));
                }
            }
            k if k.is_decorator() => {
                fields.push(format!("{kw} = {}", quote(&bt.nodes[n.children[0]].id)));
            }
            _ => {
                let kids: Vec<String> =
                    n.children.iter().map(|&c| quote(&bt.nodes[c].id)).collect();
                fields.push(format!("{kw} = [{}]", kids.join(", ")));
            }
        }
        match n.kind {
            BtNodeKind::Parallel { success } => fields.push(format!("success = {success}")),
            BtNodeKind::Repeat { times: Some(t) } | BtNodeKind::Retry { times: t } => {
                fields.push(format!("times = {t}"))
            }
            BtNodeKind::Timeout { ms } => fields.push(format!("ms = {ms}")),
            _ => {}
        }
        if !matches!(n.kind, BtNodeKind::Action | BtNodeKind::Condition)
            && n.label != n.kind.default_label()
        {
            fields.push(format!("name = {}", quote(&n.label)));
        }
        if let Some(t) = &n.type_name {
            fields.push(format!("type = {}", quote(t)));
        }
        if !n.ports.is_empty() {
            let ports: Vec<String> = n
                .ports
                .iter()
                .map(|(k, v)| format!("{} = {}", key(k), quote(v)))
                .collect();
            fields.push(format!("ports = {{ {} }}", ports.join(", ")));
        }
        let _ = writeln!(out, "{} = {{ {} }}", key(&n.id), fields.join(", "));
        if out.len() > max {
            return None;
        }
    }
    Some(())
}

fn guard_inline(g: &Guard, to: &str) -> String {
    let term = |t: &btfsm_model::GuardTerm| {
        let mut s = format!(
            "{} = {}",
            if t.negate { "unless" } else { "if" },
            quote(&t.condition.skill)
        );
        if !t.condition.args.is_empty() {
            let _ = write!(s, ", args = {}", args_inline(&t.condition.args));
        }
        s
    };
    if g.all.is_empty() {
        // A guard known only by its label (an SCXML event or condition).
        return format!("{{ to = {}, label = {} }}", quote(to), quote(&g.label));
    }
    let cond = if g.all.len() == 1 {
        term(&g.all[0])
    } else {
        let terms: Vec<String> = g.all.iter().map(|t| format!("{{ {} }}", term(t))).collect();
        format!("all = [{}]", terms.join(", "))
    };
    format!(
        "{{ {cond}, to = {}, label = {} }}",
        quote(to),
        quote(&g.label)
    )
}

/// A region's initial state or outcome, by name.
fn initial_name(m: &StateMachine, t: &Target) -> String {
    match t {
        Target::State(j) => m.states[*j].name.clone(),
        Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => o.clone(),
    }
}

fn write_machine(out: &mut String, m: &StateMachine, max: usize) -> Option<()> {
    let outcomes = |o: &[String]| o.iter().map(|s| quote(s)).collect::<Vec<_>>().join(", ");
    let _ = writeln!(out, "initial = {}", quote(&initial_name(m, &m.top.initial)));
    let _ = writeln!(out, "outcomes = [{}]", outcomes(&m.top.outcomes));
    if m.top.states.is_empty() {
        // Only outcomes (an SCXML machine that is one `<final>`).
        let _ = writeln!(out, "\n[states]");
    }
    // Pre-order over the state hierarchy, without recursion.
    let mut stack: Vec<usize> = m.top.states.iter().rev().copied().collect();
    while let Some(i) = stack.pop() {
        let s = &m.states[i];
        let mut path = vec![key(&s.name)];
        let mut cur = s.parent;
        while let Some(p) = cur {
            path.push(key(&m.states[p].name));
            cur = m.states[p].parent;
        }
        path.reverse();
        let _ = writeln!(out, "\n[states.{}]", path.join(".states."));
        if s.label != s.name {
            let _ = writeln!(out, "label = {}", quote(&s.label));
        }
        match &s.body {
            StateBody::Task(Some(call)) => {
                let _ = writeln!(out, "skill = {}", quote(&call.skill));
                if !call.args.is_empty() {
                    let _ = writeln!(out, "args = {}", args_inline(&call.args));
                }
            }
            StateBody::Task(None) => {}
            StateBody::Decision => {
                let _ = writeln!(out, "decision = true");
                match s.pseudo {
                    Some(Pseudo::ShallowHistory) => {
                        let _ = writeln!(out, "history = \"shallow\"");
                    }
                    Some(Pseudo::DeepHistory) => {
                        let _ = writeln!(out, "history = \"deep\"");
                    }
                    None => {}
                }
            }
            StateBody::Container(r) => {
                if r.parallel {
                    let _ = writeln!(out, "parallel = true");
                } else {
                    let _ = writeln!(out, "initial = {}", quote(&initial_name(m, &r.initial)));
                }
                if r.states.is_empty() {
                    // Only outcomes (an SCXML state holding only finals).
                    let _ = writeln!(out, "states = {{}}");
                }
                let _ = writeln!(out, "outcomes = [{}]", outcomes(&r.outcomes));
                stack.extend(r.states.iter().rev().copied());
            }
        }
        let target = |t: &Target| match t {
            // A state of another region (SCXML imports) by its path.
            Target::State(j) if m.states[*j].parent != s.parent => m.path(*j),
            Target::State(j) => m.states[*j].name.clone(),
            Target::Outcome(o) => o.clone(),
            // An outcome of an enclosing region: `/OUTCOME` (the machine's),
            // `PATH/OUTCOME` (the container's at PATH).
            Target::OuterOutcome { owner, outcome } => match owner {
                None => format!("/{outcome}"),
                Some(c) => format!("{}/{outcome}", m.path(*c)),
            },
        };
        // The text of one state is bounded too (a state may have many
        // transitions to a deep state named by its path).
        let mut pending = out.len();
        let mut within = |t: String| {
            pending += t.len() + 4;
            (pending <= max).then_some(t)
        };
        let mut guards: Vec<String> = Vec::new();
        for t in &s.transitions {
            if let Trigger::Guard(g) = &t.trigger {
                guards.push(within(guard_inline(g, &target(&t.target)))?);
            }
        }
        if !guards.is_empty() {
            let _ = writeln!(out, "guards = [\n  {},\n]", guards.join(",\n  "));
        }
        let mut on: Vec<String> = Vec::new();
        for t in &s.transitions {
            if let Trigger::Outcome(o) = &t.trigger {
                on.push(within(format!(
                    "{} = {}",
                    key(o),
                    quote(&target(&t.target))
                ))?);
            }
        }
        if !on.is_empty() {
            let _ = writeln!(out, "on = {{ {} }}", on.join(", "));
        }
        if out.len() > max {
            return None;
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Limits;
    use std::path::Path;

    fn deep_bt(levels: usize) -> Policy {
        let mut s = String::from("kind = \"bt\"\nname = \"d\"\nroot = \"n0\"\n[nodes]\n");
        for i in 0..levels {
            s.push_str(&format!("n{i} = {{ sequence = [\"n{}\"] }}\n", i + 1));
        }
        s.push_str(&format!(
            "n{levels} = {{ action = \"Dock!\", skill = \"Dock\" }}\n"
        ));
        crate::toml::parse_str("d.toml", &s, Path::new("."), &Limits::default())
            .unwrap()
            .policy
    }

    #[test]
    fn text_beyond_the_budget_is_refused() {
        let p = deep_bt(30);
        let full = write_policy(&p);
        assert_eq!(write_policy_within(&p, full.len() as u64).unwrap(), full);
        assert!(matches!(
            write_policy_within(&p, full.len() as u64 - 1),
            Err(Unwritable::TooBig { .. })
        ));
    }
}
