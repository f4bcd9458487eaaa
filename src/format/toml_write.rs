//! Writes a policy back as TOML in the format `format::toml` reads (used by
//! `btfsm convert`). Reading the output gives back the same policy.

use crate::model::{
    ArgValue, Bt, BtNodeKind, Guard, Policy, PolicyBody, Pseudo, SkillCall, StateBody,
    StateMachine, Target, Trigger,
};
use std::collections::BTreeMap;
use std::fmt::Write;

/// TOML text of a policy.
pub fn write_policy(p: &Policy) -> String {
    let mut out = String::new();
    let kind = p.kind();
    let _ = writeln!(out, "kind = {}", quote(kind.as_str()));
    let _ = writeln!(out, "name = {}", quote(&p.name));
    if let Some(d) = &p.description {
        let _ = writeln!(out, "description = {}", quote(d));
    }
    match &p.body {
        PolicyBody::Bt(bt) => write_bt(&mut out, bt),
        PolicyBody::Machine(m) => write_machine(&mut out, m),
    }
    out
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

fn write_bt(out: &mut String, bt: &Bt) {
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
    }
}

fn guard_inline(g: &Guard, to: &str) -> String {
    let term = |t: &crate::model::GuardTerm| {
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

fn write_machine(out: &mut String, m: &StateMachine) {
    let outcomes = |o: &[String]| o.iter().map(|s| quote(s)).collect::<Vec<_>>().join(", ");
    let _ = writeln!(out, "initial = {}", quote(&m.states[m.top.initial].name));
    let _ = writeln!(out, "outcomes = [{}]", outcomes(&m.top.outcomes));
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
                let _ = writeln!(out, "initial = {}", quote(&m.states[r.initial].name));
                let _ = writeln!(out, "outcomes = [{}]", outcomes(&r.outcomes));
                stack.extend(r.states.iter().rev().copied());
            }
        }
        let target = |t: &Target| match t {
            // A state of another region (SCXML imports) by its path.
            Target::State(j) if m.states[*j].parent != s.parent => m.path(*j),
            Target::State(j) => m.states[*j].name.clone(),
            Target::Outcome(o) => o.clone(),
        };
        let guards: Vec<String> = s
            .transitions
            .iter()
            .filter_map(|t| match &t.trigger {
                Trigger::Guard(g) => Some(guard_inline(g, &target(&t.target))),
                Trigger::Outcome(_) => None,
            })
            .collect();
        if !guards.is_empty() {
            let _ = writeln!(out, "guards = [\n  {},\n]", guards.join(",\n  "));
        }
        let on: Vec<String> = s
            .transitions
            .iter()
            .filter_map(|t| match &t.trigger {
                Trigger::Outcome(o) => Some(format!("{} = {}", key(o), quote(&target(&t.target)))),
                Trigger::Guard(_) => None,
            })
            .collect();
        if !on.is_empty() {
            let _ = writeln!(out, "on = {{ {} }}", on.join(", "));
        }
    }
}
