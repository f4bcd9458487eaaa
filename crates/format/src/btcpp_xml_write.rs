//! Writes a BT as BehaviorTree.CPP XML, format 4 (used by `btfsm convert --to
//! btcpp-xml`): one `<BehaviorTree>` in compact syntax, and a `<TreeNodesModel>`
//! declaring every type that is not built in, so that reading the output (with
//! `format::btcpp_xml`) gives back the same tree.
//!
//! Model kinds are written as BehaviorTree.CPP types by
//! [`btcpp_xml::canonical_type`] (reactive `sequence` -> `ReactiveSequence`,
//! `sequence_memory` -> `Sequence`, ...) unless the node keeps its original type
//! name. What BehaviorTree.CPP 4 loads (`make differential` loads every
//! export in it, `tests/differential/accept_btcpp.py`):
//!
//! - a node's identity is written only where the reader would not derive it
//!   from the written names and positions ([`btcpp_xml::derive_ids`]), and
//!   then as a comment before the element (`<!-- btfsm:id deliver -->`,
//!   [`xml::ID_COMMENT`]): BehaviorTree.CPP 4 refuses an attribute
//!   `btfsm:id` as a port its node does not declare. Trees imported from
//!   XML export without any;
//! - a `Parallel` always says its thresholds in format 4's ports
//!   (`success_count`, `failure_count`), also when it was read from format
//!   3 (`success_threshold`, `failure_threshold`, `threshold`);
//! - format 3's built-ins that format 4 renamed or dropped are written as
//!   format 4 names them ([`btcpp_xml::v4_name`]; `BlackboardCheckInt`,
//!   `...Double`, `...String`, `...Bool` as a `Precondition` whose `if`
//!   script compares the two values, its `else` the status on a mismatch).

use super::btcpp_xml::{self, BUILTINS, Category};
use super::xml::{self, escape_attr, escape_comment};
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
    let v4_ports = || {
        n.ports
            .iter()
            .map(|(k, v)| (k.clone(), v4_port(v)))
            .collect()
    };
    let ty = if let Some(check) = n.type_name.as_deref().and_then(blackboard_check)
        && check_script(check, &v4_ports()).is_some()
    {
        "Precondition".to_string()
    } else if let Some(t) = &n.type_name {
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

    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    if let Some(d) = description {
        let _ = writeln!(out, "<!-- {} -->", escape_comment(d));
    }
    let _ = writeln!(
        out,
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"{}\">",
        escape_attr(name)
    );
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
        // The id, when written, on the element's line, just before it.
        let id = if explicit[i] {
            format!("<!-- {}{} -->", xml::ID_COMMENT, xml::id_to_comment(&n.id))
        } else {
            String::new()
        };
        let attr_text: String = node_attrs(n, ty, names[i].as_ref())
            .iter()
            .map(|(k, v)| format!(" {k}=\"{}\"", escape_attr(v)))
            .collect();
        if n.children.is_empty() {
            let _ = writeln!(out, "{pad}{id}<{open}{attr_text}/>");
        } else {
            let _ = writeln!(out, "{pad}{id}<{open}{attr_text}>");
            stack.push((i, depth, true));
            for &c in n.children.iter().rev() {
                stack.push((c, depth + 1, false));
            }
        }
    }
}

/// A node's attributes, unescaped: its `name`, its kind's parameters,
/// skill arguments and ports, format 3's as format 4 names them. `ty` is
/// the type written.
fn node_attrs(n: &BtNode, ty: &str, name: Option<&String>) -> Vec<(String, String)> {
    let mut attrs: Vec<(String, String)> = Vec::new();
    if let Some(nm) = name {
        attrs.push(("name".into(), nm.clone()));
    }
    let mut ports: BTreeMap<String, String> = n
        .ports
        .iter()
        .map(|(k, v)| (k.clone(), v4_port(v)))
        .collect();
    match n.kind {
        BtNodeKind::Parallel { success } if ty == "Parallel" => {
            attrs.push(("success_count".into(), success.to_string()));
            // Format 3's names of the thresholds (the success one is the
            // kind's parameter).
            for old in ["success_threshold", "threshold"] {
                ports.remove(old);
            }
            if let Some(f) = ports.remove("failure_threshold") {
                ports.entry("failure_count".into()).or_insert(f);
            }
            // The paper's Parallel fails when it can no longer succeed.
            if !ports.contains_key("failure_count") {
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
    if ty == "Precondition"
        && let Some(check) = n.type_name.as_deref().and_then(blackboard_check)
        && let Some(script) = check_script(check, &ports)
    {
        attrs.push(("if".into(), script));
        if let Some(st) = ports.get("return_on_mismatch").filter(|s| !s.is_empty()) {
            attrs.push(("else".into(), st.clone()));
        }
        return attrs;
    }
    attrs.extend(ports);
    attrs
}

/// The value type a format-3 `BlackboardCheck*` compares, if `t` is one.
fn blackboard_check(t: &str) -> Option<&'static str> {
    Some(match t {
        "BlackboardCheckInt" => "int",
        "BlackboardCheckDouble" => "double",
        "BlackboardCheckString" => "string",
        "BlackboardCheckBool" => "bool",
        _ => return None,
    })
}

/// The `if` script of the `Precondition` that stands for a format-3
/// `BlackboardCheck*` of value type `ty` with ports `value_A`, `value_B`:
/// each value a blackboard entry (`{key}`: the script's variable `key`) or
/// a literal (a number, `true`/`false`, or a quoted string); `None` when a
/// value cannot be written so.
fn check_script(ty: &str, ports: &BTreeMap<String, String>) -> Option<String> {
    let operand = |v: &str| -> Option<String> {
        if let Some(key) = v.strip_prefix('{').and_then(|r| r.strip_suffix('}')) {
            let ident = key.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            return ident.then(|| key.to_string());
        }
        let v = v.trim();
        match ty {
            "int" => v.parse::<i64>().ok().map(|x| x.to_string()),
            "double" => v
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .map(|_| v.to_string()),
            "bool" => match v {
                "true" | "1" => Some("true".into()),
                "false" | "0" => Some("false".into()),
                _ => None,
            },
            _ => (!v.contains(['\'', '\\'])).then(|| format!("'{v}'")),
        }
    };
    let a = operand(ports.get("value_A")?)?;
    let b = operand(ports.get("value_B")?)?;
    Some(format!("{a} == {b}"))
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

    /// BehaviorTree.CPP 4 refuses a `btfsm:id` attribute (an undeclared
    /// port): ids travel in comments, and come back, `--` and `%` too.
    #[test]
    fn ids_travel_in_comments_not_attributes() {
        let text = r#"kind = "bt"
name = "t"
root = "top"
[nodes]
top = { sequence = ["a--b", "c-"] }
"a--b" = { action = "A" }
"c-" = { fallback = ["100%"] }
"100%" = { condition = "C" }
"#;
        let a = crate::toml::parse_str("t.toml", text, Path::new("."), &Limits::default())
            .unwrap()
            .policy;
        let xml = write_policy(&a).unwrap();
        assert!(
            !xml.contains("btfsm:id=") && !xml.contains("xmlns:btfsm"),
            "{xml}"
        );
        assert!(xml.contains("<!-- btfsm:id a%2D%2Db --><A"), "{xml}");
        let b = parse_str("t.xml", &xml, Path::new("."), &Limits::default())
            .unwrap()
            .policy;
        let ids = |p: &Policy| match &p.body {
            PolicyBody::Bt(t) => t.nodes.iter().map(|n| n.id.clone()).collect::<Vec<_>>(),
            PolicyBody::Machine(_) => panic!("a BT"),
        };
        assert_eq!(ids(&a), ids(&b));
    }

    /// Format 3's Parallel thresholds and BlackboardCheck* as format 4
    /// writes them.
    #[test]
    fn format3_nodes_are_written_as_format4_names_them() {
        let input = r#"<root main_tree_to_execute="M">
  <BehaviorTree ID="M">
    <Sequence>
      <Parallel success_threshold="1" failure_threshold="2">
        <AlwaysSuccess/>
        <AlwaysFailure/>
        <AlwaysFailure/>
      </Parallel>
      <BlackboardCheckInt value_A="${count}" value_B="42" return_on_mismatch="SUCCESS">
        <AlwaysSuccess/>
      </BlackboardCheckInt>
      <BlackboardCheckString value_A="{mode}" value_B="auto">
        <AlwaysSuccess/>
      </BlackboardCheckString>
      <SequenceStar><AlwaysSuccess/></SequenceStar>
    </Sequence>
  </BehaviorTree>
</root>"#;
        let p = parse_str("v3.xml", input, Path::new("."), &Limits::default())
            .unwrap()
            .policy;
        let out = write_policy(&p).unwrap();
        for want in [
            r#"<Parallel success_count="1" failure_count="2">"#,
            r#"<Precondition name="BlackboardCheckInt" if="count == 42" else="SUCCESS">"#,
            r#"<Precondition name="BlackboardCheckString" if="mode == 'auto'">"#,
            "<SequenceWithMemory name=\"SequenceStar\">",
        ] {
            assert!(out.contains(want), "{want}\n{out}");
        }
        for gone in [
            "threshold",
            "BlackboardCheckInt ",
            "value_A",
            "SequenceStar>",
        ] {
            assert!(!out.contains(gone), "{gone}\n{out}");
        }
    }
}
