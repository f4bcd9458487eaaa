//! The tree a `.btlog` embeds: every node with its `_uid`, its type (the
//! element's tag), its name, its category (a built-in's, or the
//! `<TreeNodesModel>`'s), its parent and its children in order. A SubTree
//! node's child is the root of the `<BehaviorTree>` whose `_fullpath` is
//! the SubTree's (BehaviorTree.CPP's `WriteTreeToXML` with metadata).
//! Each node keeps its ports (the attributes the XML gives it).

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
    // Subtree roots by `_fullpath`, and SubTree nodes to link to them.
    let mut by_path: BTreeMap<String, u16> = BTreeMap::new();
    let mut subtrees: Vec<(u16, String)> = Vec::new();
    for bt in root.children().filter(|c| c.has_tag_name("BehaviorTree")) {
        let path = bt.attribute("_fullpath").unwrap_or("").to_string();
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
                subtrees.push((uid, p));
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
    for (uid, path) in subtrees {
        if let Some(&r) = by_path.get(&path)
            && r != uid
        {
            t.nodes.get_mut(&r).expect("root").parent = Some(uid);
            t.nodes.get_mut(&uid).expect("subtree").children.push(r);
        }
    }
    t.root = by_path.get("").copied();
    Ok(t)
}
