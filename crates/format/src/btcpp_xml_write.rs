//! Writes a BT as BehaviorTree.CPP XML, format 4 (used by `btfsm convert --to
//! btcpp-xml`): one `<BehaviorTree>` in compact syntax, and a `<TreeNodesModel>`
//! declaring every type that is not built in, so that reading the output (with
//! `format::btcpp_xml`) gives back the same tree.
//!
//! Model kinds are written as BehaviorTree.CPP types by
//! [`btcpp_xml::canonical_type`] (reactive `sequence` -> `ReactiveSequence`,
//! `sequence_memory` -> `Sequence`, ...) unless the node keeps its original type
//! name. A node's identity is written as `btfsm:id` only where the reader would
//! not derive it from the written names and positions
//! ([`btcpp_xml::derive_ids`]), so trees imported from XML export without it.

use super::btcpp_xml::{self, BUILTINS, Category};
use super::xml::{BTFSM_NS, escape_attr, escape_comment};
use btfsm_model::{Bt, BtNode, BtNodeKind, Policy, PolicyBody};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// Why a policy cannot be written as BehaviorTree.CPP XML.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{name}` is {kind}, and BehaviorTree.CPP XML holds behavior trees only")]
pub struct NotABt {
    pub name: String,
    pub kind: &'static str,
}

/// XML text of a BT policy.
pub fn write_policy(p: &Policy) -> Result<String, NotABt> {
    let PolicyBody::Bt(bt) = &p.body else {
        return Err(NotABt {
            name: p.name.clone(),
            kind: if p.kind() == btfsm_model::PolicyKind::Hfsm {
                "an HFSM"
            } else {
                "an FSM"
            },
        });
    };
    Ok(write_bt(&p.name, p.description.as_deref(), bt))
}

/// Is `s` usable as an XML element name (ASCII subset)?
fn is_xml_name(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(f) if f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || matches!(ch, '_' | '-' | '.'))
}

/// A format-3 blackboard reference `${key}` as format 4 writes it, `{key}`.
fn v4_port(v: &str) -> String {
    match v.strip_prefix("${").and_then(|r| r.strip_suffix('}')) {
        Some(key) if !key.is_empty() && !key.contains(['{', '}']) => format!("{{{key}}}"),
        _ => v.to_string(),
    }
}

/// The type a node is written as, and its category when it is not built in.
fn node_type(n: &BtNode) -> (String, Category) {
    let cat = match n.kind {
        BtNodeKind::Action => Category::Action,
        BtNodeKind::Condition => Category::Condition,
        k if k.is_decorator() => Category::Decorator,
        _ => Category::Control,
    };
    let ty = if let Some(t) = &n.type_name {
        btcpp_xml::v4_name(t).to_string()
    } else if let Some(call) = &n.skill {
        call.skill.clone()
    } else if let Some(t) = btcpp_xml::canonical_type(n.kind) {
        t.to_string()
    } else {
        // A leaf with neither skill nor type: a type from its label.
        let t: String = n
            .label
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        if t.starts_with(|c: char| c.is_ascii_alphabetic()) {
            t
        } else {
            format!("N{t}")
        }
    };
    (ty, cat)
}

/// XML text of BT `bt` named `name`.
fn write_bt(name: &str, description: Option<&str>, bt: &Bt) -> String {
    let types: Vec<(String, Category)> = bt.nodes.iter().map(node_type).collect();
    // The `name` attribute: written when the label is not the type.
    let names: Vec<Option<String>> = bt
        .nodes
        .iter()
        .zip(&types)
        .map(|(n, (t, _))| (n.label != *t).then(|| n.label.clone()))
        .collect();
    let children: Vec<Vec<usize>> = bt.nodes.iter().map(|n| n.children.clone()).collect();
    let (_, explicit) = btcpp_xml::derive_ids(&children, bt.root, name, &names, |i, derived| {
        (bt.nodes[i].id != derived).then(|| bt.nodes[i].id.clone())
    });
    let explicit: Vec<bool> = explicit.iter().map(|s| !s.is_derived()).collect();
    let need_ns = explicit.iter().any(|&e| e);

    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    if let Some(d) = description {
        let _ = writeln!(out, "<!-- {} -->", escape_comment(d));
    }
    let _ = write!(
        out,
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"{}\"",
        escape_attr(name)
    );
    if need_ns {
        let _ = write!(out, " xmlns:btfsm=\"{BTFSM_NS}\"");
    }
    out.push_str(">\n");
    let _ = writeln!(out, "  <BehaviorTree ID=\"{}\">", escape_attr(name));
    write_nodes(&mut out, bt, &types, &names, &explicit);
    out.push_str("  </BehaviorTree>\n");
    write_nodes_model(&mut out, bt, &types);
    out.push_str("</root>\n");
    out
}

/// Writes the tree's elements in pre-order, with explicit close events (no
/// recursion).
fn write_nodes(
    out: &mut String,
    bt: &Bt,
    types: &[(String, Category)],
    names: &[Option<String>],
    explicit: &[bool],
) {
    let mut stack: Vec<(usize, usize, bool)> = vec![(bt.root, 2, false)];
    while let Some((i, depth, close)) = stack.pop() {
        let n = &bt.nodes[i];
        let (ty, cat) = &types[i];
        let pad = super::scxml_write::indent(depth);
        let (open, end) = if is_xml_name(ty) {
            (ty.clone(), ty.clone())
        } else {
            (
                format!("{} ID=\"{}\"", cat.tag(), escape_attr(ty)),
                cat.tag().to_string(),
            )
        };
        if close {
            let _ = writeln!(out, "{pad}</{end}>");
            continue;
        }
        let attr_text: String = node_attrs(n, names[i].as_ref(), explicit[i])
            .iter()
            .map(|(k, v)| format!(" {k}=\"{}\"", escape_attr(v)))
            .collect();
        if n.children.is_empty() {
            let _ = writeln!(out, "{pad}<{open}{attr_text}/>");
        } else {
            let _ = writeln!(out, "{pad}<{open}{attr_text}>");
            stack.push((i, depth, true));
            for &c in n.children.iter().rev() {
                stack.push((c, depth + 1, false));
            }
        }
    }
}

/// A node's attributes, unescaped: its `name`, its id when not derived
/// (`btfsm:id`), its kind's parameters, skill arguments and ports.
fn node_attrs(n: &BtNode, name: Option<&String>, explicit: bool) -> Vec<(String, String)> {
    let mut attrs: Vec<(String, String)> = Vec::new();
    if let Some(nm) = name {
        attrs.push(("name".into(), nm.clone()));
    }
    if explicit {
        attrs.push(("btfsm:id".into(), n.id.clone()));
    }
    match n.kind {
        BtNodeKind::Parallel { success } if n.type_name.is_none() => {
            attrs.push(("success_count".into(), success.to_string()));
            // The paper's Parallel fails when it can no longer succeed.
            if !n.ports.contains_key("failure_count") {
                let fail = n.children.len().saturating_sub(success) + 1;
                attrs.push(("failure_count".into(), fail.to_string()));
            }
        }
        BtNodeKind::Repeat { times } => attrs.push((
            "num_cycles".into(),
            times.map_or("-1".to_string(), |t| t.to_string()),
        )),
        BtNodeKind::Retry { times } => attrs.push(("num_attempts".into(), times.to_string())),
        BtNodeKind::Timeout { ms } => attrs.push(("msec".into(), ms.to_string())),
        _ => {}
    }
    if let Some(call) = &n.skill {
        for (k, v) in &call.args {
            attrs.push((k.clone(), v.to_string()));
        }
    }
    for (k, v) in &n.ports {
        attrs.push((k.clone(), v4_port(v)));
    }
    attrs
}

/// Writes `<TreeNodesModel>`: the types that are not built in, with the
/// ports they are given.
fn write_nodes_model(out: &mut String, bt: &Bt, types: &[(String, Category)]) {
    let mut model: BTreeMap<String, (Category, BTreeSet<String>)> = BTreeMap::new();
    for (n, (ty, cat)) in bt.nodes.iter().zip(types) {
        if BUILTINS.iter().any(|(b, _)| b == ty) {
            continue;
        }
        let e = model.entry(ty.clone()).or_insert((*cat, BTreeSet::new()));
        let keys = n
            .skill
            .iter()
            .flat_map(|c| c.args.keys())
            .chain(n.ports.keys());
        for k in keys {
            if !e.1.contains(k) {
                e.1.insert(k.clone());
            }
        }
    }
    if !model.is_empty() {
        out.push_str("  <TreeNodesModel>\n");
        for (ty, (cat, ports)) in model {
            let tag = cat.tag();
            if ports.is_empty() {
                let _ = writeln!(out, "    <{tag} ID=\"{}\"/>", escape_attr(&ty));
            } else {
                let _ = writeln!(out, "    <{tag} ID=\"{}\">", escape_attr(&ty));
                for p in ports {
                    let _ = writeln!(out, "      <input_port name=\"{}\"/>", escape_attr(&p));
                }
                let _ = writeln!(out, "    </{tag}>");
            }
        }
        out.push_str("  </TreeNodesModel>\n");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Limits;
    use crate::btcpp_xml::parse_str;
    use std::path::Path;

    /// Golden file: the paper's Fig. 5 BT as BehaviorTree.CPP XML.
    #[test]
    fn fig05_as_btcpp_xml() {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("policies/paper/fig05-bt.toml");
        let p = crate::load(&path, &Limits::default()).unwrap().policy;
        insta::assert_snapshot!(write_policy(&p).unwrap());
    }

    /// Indentation stops growing with depth: the text of a deep tree is
    /// linear in its depth, and reads back.
    #[test]
    fn deep_tree_text_is_linear_in_depth() {
        let lim = Limits {
            max_depth: 5000,
            ..Default::default()
        };
        let mut sizes = vec![];
        for n in [500, 2000] {
            let input = format!(
                "<root><BehaviorTree ID=\"T\">{}<AlwaysSuccess/>{}</BehaviorTree></root>",
                "<Inverter>".repeat(n),
                "</Inverter>".repeat(n)
            );
            let p = parse_str("t.xml", &input, Path::new("."), &lim)
                .unwrap()
                .policy;
            let out = write_policy(&p).unwrap();
            assert!(
                out.len() < 10 * input.len(),
                "{n}: {} bytes from {}",
                out.len(),
                input.len()
            );
            sizes.push(out.len());
            let back = parse_str("b.xml", &out, Path::new("."), &lim)
                .unwrap()
                .policy;
            let (PolicyBody::Bt(a), PolicyBody::Bt(b)) = (&p.body, &back.body) else {
                panic!()
            };
            let ids = |t: &Bt| t.nodes.iter().map(|n| n.id.clone()).collect::<Vec<_>>();
            assert_eq!(ids(a), ids(b));
        }
        assert!(sizes[1] < 5 * sizes[0], "{sizes:?}");
    }

    #[test]
    fn toml_tree_round_trips_through_xml() {
        let text = r#"kind = "bt"
name = "t"
root = "top"
[nodes]
top = { sequence = ["f", "p"] }
f = { fallback = ["c", "m"] }
c = { condition = "Robot-At cube2?", skill = "Robot-At", args = { target = "cube2" } }
m = { action = "Move-To cube2!", skill = "Move-To", args = { target = "cube2" } }
p = { repeat = "k", times = 2 }
k = { action = "Pick cube2!", skill = "Pick", args = { object = "cube2" } }
"#;
        let a = crate::toml::parse_str("t.toml", text, Path::new("."), &Limits::default())
            .unwrap()
            .policy;
        let xml = write_policy(&a).unwrap();
        let b = parse_str("t.xml", &xml, Path::new("."), &Limits::default())
            .unwrap_or_else(|e| panic!("{xml}\n{e:?}"))
            .policy;
        let (PolicyBody::Bt(x), PolicyBody::Bt(y)) = (&a.body, &b.body) else {
            panic!()
        };
        for n in &x.nodes {
            let m = y.nodes.iter().find(|m| m.id == n.id).expect("same ids");
            assert_eq!((&n.label, n.kind, &n.skill), (&m.label, m.kind, &m.skill));
            let kids = |b: &Bt, v: &BtNode| {
                v.children
                    .iter()
                    .map(|&c| b.nodes[c].id.clone())
                    .collect::<Vec<_>>()
            };
            assert_eq!(kids(x, n), kids(y, m));
        }
        assert_eq!(x.nodes.len(), y.nodes.len());
        assert!(xml.contains("<TreeNodesModel>"), "{xml}");
    }
}
