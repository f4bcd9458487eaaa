//! A log's tree as a policy, and its nodes' statuses at a moment: what
//! `btfsm log dot` draws (the status overlay of `dot --trace`).
//!
//! The policy is read from the XML the log embeds, as any BehaviorTree.CPP
//! file; its nodes in pre-order are the log's UIDs in pre-order with the
//! SubTree nodes left out (btfsm expands a SubTree in place, its root takes
//! the SubTree's place). The two orders are checked node by node.

use super::btlog::{LogError, Record, Records, Status, read_header};
use super::tree::{Tree, parse};
use btfsm_format::Limits;
use btfsm_model::Policy;
use std::collections::BTreeMap;
use std::io::Read;

/// When to stop replaying.
#[derive(Debug, Clone, Copy)]
pub enum At {
    /// After this many records.
    Step(u64),
    /// At this many µs after the first timestamp (records up to it).
    Time(u64),
}

/// The policy of the log's tree and each node's status (by btfsm node id)
/// at `at`; with the number of records applied and the time reached.
pub struct Replayed {
    pub policy: Policy,
    pub statuses: BTreeMap<String, Status>,
    pub applied: u64,
    pub t_usec: u64,
}

/// Why a log cannot be drawn.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    #[error("{0}")]
    Log(#[from] LogError),
    #[error("the log's tree does not load: {0}")]
    Tree(String),
}

fn preorder_without_subtrees(t: &Tree) -> Vec<u16> {
    let mut out = Vec::new();
    let mut stack: Vec<u16> = t.root.into_iter().collect();
    while let Some(u) = stack.pop() {
        let n = &t.nodes[&u];
        if n.tag != "SubTree" {
            out.push(u);
        }
        stack.extend(n.children.iter().rev());
    }
    out
}

/// A log opened for replay: its tree as a policy, the btfsm node id of each
/// UID, and its records still to read (`btfsm view` streams them).
pub struct Opened<R> {
    pub policy: Policy,
    pub id_of: BTreeMap<u16, String>,
    pub records: Records<std::io::BufReader<R>>,
}

/// Reads a log's header and tree, leaving its records to read.
pub fn open<R: Read>(r: R, limits: &Limits) -> Result<Opened<R>, ReplayError> {
    let mut r = std::io::BufReader::new(r);
    let h = read_header(&mut r, limits.max_file_bytes)?;
    let tree = parse(&h.xml).map_err(ReplayError::Tree)?;
    let main = tree
        .root
        .and_then(|_| main_tree_id(&h.xml))
        .ok_or_else(|| {
            ReplayError::Tree("no main tree (`_fullpath=\"\"`) in the log's XML".into())
        })?;
    // The log's bookkeeping attributes are not the nodes' ports.
    let xml = strip_attr(&strip_attr(&h.xml, "_uid"), "_fullpath");
    let mut lim = limits.clone();
    lim.tree = Some(main);
    lim.assume_leaf = lim.assume_leaf.or(Some(btfsm_format::AssumeLeaf::Action));
    let loaded =
        btfsm_format::btcpp_xml::parse_str("log tree", &xml, std::path::Path::new("."), &lim)
            .map_err(|d| {
                ReplayError::Tree(d.first().map(|x| x.message.clone()).unwrap_or_default())
            })?;
    let btfsm_model::PolicyBody::Bt(bt) = &loaded.policy.body else {
        return Err(ReplayError::Tree("not a behavior tree".into()));
    };
    let uids = preorder_without_subtrees(&tree);
    let order = bt.preorder();
    if uids.len() != order.len() {
        return Err(ReplayError::Tree(format!(
            "the log's tree has {} nodes and reads as {} (SubTrees expanded)",
            uids.len(),
            order.len()
        )));
    }
    let id_of: BTreeMap<u16, String> = uids
        .iter()
        .zip(&order)
        .map(|(&u, &n)| (u, bt.nodes[n].id.clone()))
        .collect();
    Ok(Opened {
        policy: loaded.policy,
        id_of,
        records: Records::new(r, &h),
    })
}

/// Replays a log up to `at`.
pub fn replay(r: impl Read, at: At, limits: &Limits) -> Result<Replayed, ReplayError> {
    let Opened {
        policy,
        id_of,
        records,
    } = open(r, limits)?;
    let mut status: BTreeMap<u16, Status> = BTreeMap::new();
    let mut applied = 0u64;
    let mut t_usec = 0u64;
    for rec in records {
        let Record {
            t_usec: t,
            uid,
            status: s,
        } = rec?;
        let stop = match at {
            At::Step(k) => applied >= k,
            At::Time(limit) => t > limit,
        };
        if stop {
            break;
        }
        status.insert(uid, s);
        applied += 1;
        t_usec = t;
    }
    let statuses = status
        .into_iter()
        .filter_map(|(u, s)| id_of.get(&u).map(|id| (id.clone(), s)))
        .collect();
    Ok(Replayed {
        policy,
        statuses,
        applied,
        t_usec,
    })
}

/// The ID of the `<BehaviorTree>` whose `_fullpath` is empty.
fn main_tree_id(xml: &str) -> Option<String> {
    let doc = roxmltree::Document::parse(xml).ok()?;
    doc.root_element()
        .children()
        .filter(|c| c.has_tag_name("BehaviorTree"))
        .find(|c| c.attribute("_fullpath").unwrap_or("").is_empty())
        .and_then(|c| c.attribute("ID").map(str::to_string))
}

/// `text` without the attributes ` NAME="..."`.
fn strip_attr(text: &str, name: &str) -> String {
    let pat = format!(" {name}=\"");
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(&pat) {
        out.push_str(&rest[..i]);
        let after = &rest[i + pat.len()..];
        match after.find('"') {
            Some(j) => rest = &after[j + 1..],
            None => {
                rest = after;
                break;
            }
        }
    }
    out.push_str(rest);
    out
}
