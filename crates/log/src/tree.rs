//! The tree a `.btlog` embeds: every node with its `_uid`, its type (the
//! element's tag), its name, its category (a built-in's, or the
//! `<TreeNodesModel>`'s), its parent and its children in order. A SubTree
//! node's child is the root of the `<BehaviorTree>` whose `_fullpath` is
//! the SubTree's (BehaviorTree.CPP's `WriteTreeToXML` with metadata).
//! Each node keeps its ports (the attributes the XML gives it).
//!
//! BehaviorTree.CPP writes one `<BehaviorTree>` per SubTree instance, each
//! with its own `_fullpath`, so a tree is the child of one SubTree node at
//! most: a `_fullpath` given to two trees, a tree two SubTrees name, and
//! SubTree links that form a cycle are errors naming the trees (issue 33: a
//! 442-byte log whose links looped, or formed a 40-level DAG, hung every
//! walk of the tree). What is returned is a forest, walked in time linear
//! in its nodes.

use btfsm_format::btcpp_xml::{Category, builtin};
use std::collections::BTreeMap;

/// One node of the logged tree.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Node {
    pub uid: u16,
    pub tag: String,
    pub name: String,
    pub category: Option<Category>,
    pub parent: Option<u16>,
    pub children: Vec<u16>,
    /// The node's ports as the XML gives them (its attributes but `name`,
    /// `ID` and the logger's `_uid` and `_fullpath`).
    pub ports: BTreeMap<String, String>,
}

/// The logged tree, by UID.
#[derive(Debug, Clone, Default)]
pub struct Tree {
    pub nodes: BTreeMap<u16, Node>,
    pub root: Option<u16>,
}

/// Reads the tree XML of a log; an error says what is wrong.
pub fn parse(xml: &str) -> Result<Tree, String> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: 4_000_000,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(xml, opts)
        .map_err(|e| format!("the tree XML of the log is not well-formed: {e}"))?;
    let root = doc.root_element();
    let mut model: BTreeMap<String, Category> = BTreeMap::new();
    for m in root.children().filter(|c| c.has_tag_name("TreeNodesModel")) {
        for e in m.children().filter(|c| c.is_element()) {
            let cat = match e.tag_name().name() {
                "Action" => Category::Action,
                "Condition" => Category::Condition,
                "Control" => Category::Control,
                "Decorator" => Category::Decorator,
                _ => continue,
            };
            if let Some(id) = e.attribute("ID") {
                model.insert(id.to_string(), cat);
            }
        }
    }
    let mut t = Tree::default();
    // Subtree roots by `_fullpath`, and SubTree nodes to link to them
    // (with the `_fullpath` of the tree holding each).
    let mut by_path: BTreeMap<String, u16> = BTreeMap::new();
    let mut subtrees: Vec<(u16, String, String)> = Vec::new();
    for bt in root.children().filter(|c| c.has_tag_name("BehaviorTree")) {
        let path = bt.attribute("_fullpath").unwrap_or("").to_string();
        if by_path.contains_key(&path) {
            return Err(format!(
                "two trees of the log have `_fullpath` {}",
                tree_name(&path)
            ));
        }
        let mut stack: Vec<(roxmltree::Node, Option<u16>)> = bt
            .children()
            .filter(|c| c.is_element())
            .map(|c| (c, None))
            .collect();
        let mut first = true;
        while let Some((e, parent)) = stack.pop() {
            let Some(uid) = e.attribute("_uid").and_then(|u| u.parse::<u16>().ok()) else {
                return Err(format!(
                    "node `{}` of the log's tree has no `_uid`",
                    btfsm_core::sanitize::shown(e.tag_name().name())
                ));
            };
            let tag = e.tag_name().name().to_string();
            if first {
                by_path.insert(path.clone(), uid);
                first = false;
            }
            if tag == "SubTree" {
                let p = e.attribute("_fullpath").unwrap_or("").to_string();
                subtrees.push((uid, p, path.clone()));
            }
            let category = builtin(&tag).or_else(|| model.get(&tag).copied());
            if t.nodes.contains_key(&uid) {
                return Err(format!("UID {uid} appears twice in the log's tree"));
            }
            t.nodes.insert(
                uid,
                Node {
                    uid,
                    name: e.attribute("name").unwrap_or(&tag).to_string(),
                    tag,
                    category,
                    parent,
                    children: Vec::new(),
                    ports: e
                        .attributes()
                        .filter(|a| !matches!(a.name(), "name" | "ID" | "_uid" | "_fullpath"))
                        .map(|a| (a.name().to_string(), a.value().to_string()))
                        .collect(),
                },
            );
            if let Some(p) = parent {
                t.nodes
                    .get_mut(&p)
                    .expect("parent first")
                    .children
                    .push(uid);
            }
            let kids: Vec<_> = e.children().filter(|c| c.is_element()).collect();
            for k in kids.into_iter().rev() {
                stack.push((k, Some(uid)));
            }
        }
    }
    link_subtrees(&mut t, &by_path, subtrees)?;
    t.root = by_path.get("").copied();
    Ok(t)
}

/// A tree named in a message: its `_fullpath`, or "the main tree".
fn tree_name(path: &str) -> String {
    if path.is_empty() {
        "the main tree (`_fullpath=\"\"`)".to_string()
    } else {
        format!("`{}`", btfsm_core::sanitize::shown(path))
    }
}

/// Makes each tree's root the child of the SubTree node naming its
/// `_fullpath`: a tree named by two SubTrees, or links forming a cycle, are
/// errors naming two trees.
fn link_subtrees(
    t: &mut Tree,
    by_path: &BTreeMap<String, u16>,
    subtrees: Vec<(u16, String, String)>,
) -> Result<(), String> {
    // The tree holding each linked tree: at most one.
    let mut parent_tree: BTreeMap<&str, &str> = BTreeMap::new();
    let mut links = Vec::new();
    for (uid, path, holder) in &subtrees {
        let Some(&r) = by_path.get(path) else {
            continue;
        };
        if r == *uid {
            continue;
        }
        if let Some(first) = parent_tree.insert(path, holder) {
            return Err(format!(
                "the tree {} is the SubTree of two nodes (in {} and in {}): a log has one tree per SubTree instance",
                tree_name(path),
                tree_name(first),
                tree_name(holder)
            ));
        }
        links.push((*uid, r));
    }
    // Each tree has one holder at most: a cycle is a loop of holders.
    let mut state: BTreeMap<&str, u8> = BTreeMap::new();
    for &start in parent_tree.keys() {
        let mut walk = Vec::new();
        let mut at = start;
        loop {
            match state.get(at) {
                Some(2) => break,
                Some(_) => {
                    let by = parent_tree.get(at).copied().unwrap_or_default();
                    return Err(format!(
                        "SubTree links form a cycle: the tree {} includes {}, which includes it back",
                        tree_name(by),
                        tree_name(at)
                    ));
                }
                None => {}
            }
            state.insert(at, 1);
            walk.push(at);
            match parent_tree.get(at) {
                Some(&up) => at = up,
                None => break,
            }
        }
        for w in walk {
            state.insert(w, 2);
        }
    }
    for (uid, r) in links {
        t.nodes.get_mut(&r).expect("root").parent = Some(uid);
        t.nodes.get_mut(&uid).expect("subtree").children.push(r);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log's tree XML: `levels` trees, tree `l` holding one SubTree
    /// (`twice`: two) naming tree `l + 1`; the last holds a leaf, or
    /// (`back`) a SubTree naming the main tree.
    fn tree(levels: usize, twice: bool, back: bool) -> String {
        let path = |l: usize| {
            if l == 0 {
                String::new()
            } else {
                format!("t{l}")
            }
        };
        let mut x = String::from(r#"<root BTCPP_format="4">"#);
        let mut uid = 0;
        for l in 0..levels {
            uid += 1;
            x.push_str(&format!(
                r#"<BehaviorTree ID="T{l}" _fullpath="{}"><Sequence _uid="{uid}">"#,
                path(l)
            ));
            let last = l + 1 == levels;
            for _ in 0..if twice { 2 } else { 1 } {
                uid += 1;
                if last && !back {
                    x.push_str(&format!(r#"<Go _uid="{uid}"/>"#));
                } else {
                    let next = if last { String::new() } else { path(l + 1) };
                    x.push_str(&format!(
                        r#"<SubTree ID="T" _uid="{uid}" _fullpath="{next}"/>"#
                    ));
                }
            }
            x.push_str("</Sequence></BehaviorTree>");
        }
        x.push_str("</root>");
        x
    }

    #[test]
    fn a_chain_of_subtrees_is_linked_once_each() {
        let t = parse(&tree(40, false, false)).unwrap();
        assert_eq!(t.nodes.len(), 80);
        // A pre-order walk sees every node once.
        let mut seen = 0;
        let mut stack: Vec<u16> = t.root.into_iter().collect();
        while let Some(u) = stack.pop() {
            seen += 1;
            stack.extend(&t.nodes[&u].children);
        }
        assert_eq!(seen, 80);
    }

    #[test]
    fn a_subtree_dag_or_cycle_is_an_error_naming_two_trees() {
        let t0 = std::time::Instant::now();
        let e = parse(&tree(40, true, false)).unwrap_err();
        assert!(
            e.contains("SubTree of two nodes") && e.contains("`t1`"),
            "{e}"
        );
        let e = parse(&tree(3, false, true)).unwrap_err();
        assert!(
            e.contains("cycle") && e.contains("`t2`") && e.contains("main tree"),
            "{e}"
        );
        let two = r#"<root><BehaviorTree ID="A" _fullpath="x"><Go _uid="1"/></BehaviorTree><BehaviorTree ID="B" _fullpath="x"><Go _uid="2"/></BehaviorTree></root>"#;
        assert!(parse(two).unwrap_err().contains("two trees"));
        assert!(t0.elapsed().as_secs() < 5);
    }
}
