//! Expansion of a tree into the BT model: an explicit pre-order walk that
//! expands `<SubTree>`s in place (recursion rejected) and resolves their
//! port remappings through the chain of enclosing expansions
//! (BehaviorTree.CPP 4 "Remapping ports between Trees and SubTrees").

use super::super::xml::{XElem, shown};
use super::derive_ids;
use super::loader::Loader;
use super::ports::{Key, KeyUse, SCRIPT_ATTRS, SubTreeFlow};
use btfsm_core::diagnostic::suggest;
use btfsm_model::{Bt, BtNode};
use std::collections::{BTreeMap, HashMap};

/// An element waiting in the expansion's walk.
struct Item {
    d: usize,
    e: usize,
    parent: Option<usize>,
    /// Levels below the root (a SubTree's root takes its place).
    depth: usize,
    /// Index into `frames`: the SubTree expansion this element is in.
    frame: usize,
    /// `name` of the SubTree element this root replaces.
    name_override: Option<String>,
    /// ID of the (outermost) SubTree this root replaces.
    subtree: Option<String>,
}

/// An expansion under way: the SubTree expansions made, the elements still
/// to read, the nodes made so far with their names, and what the limits
/// still allow.
struct Walk {
    frames: Vec<Frame>,
    /// SubTree elements whose root node is the next node made.
    pending: Vec<usize>,
    /// The expansions enclosing the element being read: recursion and
    /// port remapping are looked up in O(1) per SubTree and port.
    chain: Chain,
    stack: Vec<Item>,
    nodes: Vec<BtNode>,
    names: Vec<Option<String>>,
    explicit: Vec<Option<String>>,
    failed: bool,
    budget: usize,
    /// SubTree elements are no nodes, but expanding one is work: at most
    /// as many expansions as nodes.
    expansions: usize,
}

impl Loader<'_> {
    /// Expands the tree from its root element into the arena (pre-order, explicit
    /// stack), resolving every node's type and expanding SubTrees. Depth and
    /// name lengths are checked here, at the element, as it is read.
    pub(super) fn expand(&mut self, tree_id: &str, d0: usize, e0: usize) -> Option<Bt> {
        let mut w = Walk {
            frames: vec![Frame {
                id: tree_id.to_string(),
                parent: None,
                remap: BTreeMap::new(),
                keys: BTreeMap::new(),
                autoremap: false,
            }],
            pending: Vec::new(),
            chain: Chain::default(),
            stack: vec![Item {
                d: d0,
                e: self.docs[d0].elems[e0].children[0],
                parent: None,
                depth: 0,
                frame: 0,
                name_override: None,
                subtree: None,
            }],
            nodes: Vec::new(),
            names: Vec::new(),
            explicit: Vec::new(),
            failed: false,
            budget: self.limits.max_nodes,
            expansions: self.limits.max_nodes,
        };
        w.chain.push(&w.frames, 0);
        while let Some(it) = w.stack.pop() {
            w.chain.enter(&w.frames, it.frame);
            let el = self.docs[it.d].elems[it.e].clone();
            if self.names_too_long(it.d, &el) {
                return None;
            }
            if it.depth > self.limits.max_depth {
                self.err(
                    it.d,
                    el.span.clone(),
                    format!(
                        "`<{}>` is {} levels below the root, deeper than the limit of {} levels",
                        shown(&el.name),
                        it.depth,
                        self.limits.max_depth
                    ),
                )
                .hint = Some("raise the limit with --max-depth".into());
                return None;
            }
            let tag = el.name.as_str();
            // SubTree: the referenced tree's root takes this element's place.
            if tag == "SubTree" || tag == "SubTreePlus" {
                self.expand_subtree(&mut w, it, &el)?;
            } else {
                self.expand_node(&mut w, it, &el)?;
            }
        }
        let Walk {
            frames,
            mut nodes,
            names,
            explicit,
            failed,
            ..
        } = w;
        if failed || nodes.is_empty() {
            return None;
        }
        let children: Vec<Vec<usize>> = nodes.iter().map(|n| n.children.clone()).collect();
        let (ids, sources) = derive_ids(&children, 0, tree_id, &names, |i, _| explicit[i].clone());
        for ((n, id), source) in nodes.iter_mut().zip(ids).zip(sources) {
            n.id = id;
            n.id_source = source;
        }
        self.flow.scopes = frames.iter().map(|f| f.id.clone()).collect();
        Some(Bt { nodes, root: 0 })
    }

    /// Expands a `<SubTree>` element: the tree it names is entered as a new
    /// expansion whose root takes the element's place. `None` when the
    /// expansion limit is hit.
    fn expand_subtree(&mut self, w: &mut Walk, it: Item, el: &XElem) -> Option<()> {
        // Among several files given together (a folder), a tree none of
        // them defines may come from a file the program registers and lint
        // was not given (MoveIt Pro's objectives library), and a tree
        // several of them define alike (robot configurations of one
        // workspace) from the one the program registers: `lint` reads it
        // as one opaque node. A single file given is refused as every
        // command refuses it.
        if self.limits.for_lint
            && self.limits.companions.as_ref().is_some_and(|c| c.len() > 1)
            && let Some(id) = el.attr("ID")
            && !self.trees.contains_key(id)
        {
            return self.opaque_subtree(w, it, el);
        }
        let Some((id, sd, se)) = self.subtree_target(w, it.d, el) else {
            w.failed = true;
            return Some(());
        };
        if w.expansions == 0 {
            self.err(
                it.d,
                el.span.clone(),
                format!("more than {} SubTree expansions", self.limits.max_nodes),
            )
            .hint = Some("raise the limit with --max-nodes".into());
            return None;
        }
        w.expansions -= 1;
        let frame = self.subtree_frame(w, &it, el, id);
        w.frames.push(frame);
        let child = self.docs[sd].elems[se].children[0];
        w.stack.push(Item {
            d: sd,
            e: child,
            parent: it.parent,
            depth: it.depth,
            frame: w.frames.len() - 1,
            name_override: el.attr("name").map(str::to_string).or(it.name_override),
            subtree: it.subtree.or(Some(w.frames[w.frames.len() - 1].id.clone())),
        });
        Some(())
    }

    /// The tree a `<SubTree>` element of document `d` names: its ID,
    /// document and `<BehaviorTree>` element. `None` after an error when it
    /// names none, a tree several companions define, an unknown tree, or a
    /// tree it is inside of (recursion).
    fn subtree_target(&mut self, w: &Walk, d: usize, el: &XElem) -> Option<(String, usize, usize)> {
        let Some(id) = el.attr("ID").map(str::to_string) else {
            self.err(d, el.span.clone(), "`<SubTree>` needs an `ID`");
            return None;
        };
        let Some(&(sd, se)) = self.trees.get(&id) else {
            if let Some(files) = self.ambiguous.get(&id) {
                let files = files.join(", ");
                self.err(
                    d,
                    el.span.clone(),
                    format!(
                        "tree `{}` in `<SubTree>` is defined by several files given together: {files}",
                        shown(&id)
                    ),
                )
                .hint = Some(
                    "`<include path>` the one you mean, or give only that file with this one"
                        .into(),
                );
                return None;
            }
            let h = if self.hinting() {
                suggest(&id, self.trees.keys().map(String::as_str))
            } else {
                String::new()
            };
            self.err(
                d,
                el.span.clone(),
                format!("unknown tree `{}` in `<SubTree>`", shown(&id)),
            )
            .hint = Some(match self.limits.companions.as_deref() {
                // Already given together: the file that defines it is not
                // among them (suggesting the command just run would not help).
                Some(c) if c.len() > 1 => format!(
                    "{h}; none of the {} BehaviorTree.CPP files given together defines it: `<include>` the file that does, or give it too",
                    c.len()
                ),
                _ => format!(
                    "{h}; a tree of another file is found when that file is `<include>`d, or given together with this one (both files, or their folder)"
                ),
            });
            return None;
        };
        if w.chain.trees.get(&id).is_some_and(|&c| c > 0) {
            let cycle = recursion(w, &id);
            self.err(d, el.span.clone(), format!("recursive subtree: {cycle}"))
                .set_code("subtree-recursion")
                .hint = Some(
                "a tree must not contain itself as a `<SubTree>`, directly or through others"
                    .into(),
            );
            return None;
        }
        Some((id, sd, se))
    }

    /// The expansion a `<SubTree>` element of tree `id` starts, its port
    /// remappings resolved in the enclosing expansions; the SubTree's
    /// dataflow is recorded.
    fn subtree_frame(&mut self, w: &mut Walk, it: &Item, el: &XElem, id: String) -> Frame {
        // Its ports remap the subtree's blackboard entries: a
        // reference is resolved in the enclosing expansion now, so
        // that the subtree's nodes get the value or the outer entry.
        // Format 3's `<SubTree>` (not `<SubTreePlus>`) maps an
        // entry to an outer entry by its bare name: `target="goal"`
        // is format 4's `target="{goal}"`.
        let keys_by_name = el.name == "SubTree" && self.format_3(it.d);
        let mut remap = BTreeMap::new();
        let mut keys = BTreeMap::new();
        let mut flow_remap = Vec::new();
        let me = w.frames.len();
        for a in el
            .attrs
            .iter()
            .filter(|a| a.ns.is_none() && !SUBTREE_ATTRS.contains(&a.name.as_str()))
        {
            let v = if a.value == "{=}" {
                format!("{{{}}}", a.name)
            } else if keys_by_name && port_key(&a.value).is_none() {
                format!("{{{}}}", a.value)
            } else {
                a.value.clone()
            };
            // The entry the port designates: an outer one, or its
            // own, set to the literal.
            let key = port_key(&v).map(|k| w.chain.resolve_key(&w.frames, k));
            let inner = key.clone().unwrap_or_else(|| Key {
                scope: me,
                name: a.name.clone(),
            });
            if !a.name.starts_with('_') {
                if key.is_none() {
                    self.flow.given.push(inner.clone());
                }
                flow_remap.push((a.name.clone(), a.value.clone(), key, a.span.clone()));
            }
            keys.insert(a.name.clone(), inner);
            remap.insert(a.name.clone(), w.chain.resolve(&w.frames, &v));
        }
        let autoremap = ["_autoremap", "__autoremap", "__shared_blackboard"]
            .iter()
            .any(|k| el.attr(k) == Some("true") || el.attr(k) == Some("1"));
        w.pending.push(self.flow.subtrees.len());
        self.flow.subtrees.push(SubTreeFlow {
            id: id.clone(),
            doc: it.d,
            span: el.span.clone(),
            node: usize::MAX,
            remap: flow_remap,
            keys: script_key_uses(w, el),
        });
        Frame {
            id,
            parent: Some(it.frame),
            remap,
            keys,
            autoremap,
        }
    }

    /// For `lint`, a `<SubTree>` whose tree no file given defines (the
    /// program may register a file that does: MoveIt Pro's objectives
    /// library, a package not given): one opaque action node in its place,
    /// its ports of unknown direction, recorded for the `unknown-subtree`
    /// rule with the closest tree ID.
    fn opaque_subtree(&mut self, w: &mut Walk, it: Item, el: &XElem) -> Option<()> {
        let id = el.attr("ID").unwrap_or_default().to_string();
        if w.budget == 0 {
            self.err(
                it.d,
                el.span.clone(),
                format!("more than {} nodes", self.limits.max_nodes),
            )
            .hint = Some("raise the limit with --max-nodes".into());
            return None;
        }
        w.budget -= 1;
        if self.unknown_subtrees.insert(id.clone()) {
            // Among the trees read and those the files given define.
            let closest = (self.unknown_subtrees.len() <= 256)
                .then(|| {
                    let given = self.limits.companions.clone();
                    let given = given.as_deref().map(|c| c.tree_ids(self.limits));
                    let cands = self
                        .trees
                        .keys()
                        .map(String::as_str)
                        .chain(given.into_iter().flatten());
                    btfsm_core::diagnostic::closest(&id, cands)
                        .filter(|c| *c != id)
                        .map(str::to_string)
                })
                .flatten();
            self.flow
                .node_types
                .unknown
                .push(super::ports::UnknownType {
                    ty: id.clone(),
                    doc: it.d,
                    span: el.span.clone(),
                    children: 0,
                    explicit: false,
                    subtree: true,
                    closest,
                });
        }
        let idx = w.nodes.len();
        for p in w.pending.drain(..) {
            self.flow.subtrees[p].node = idx;
        }
        let flow = self.node_flow(it.d, el, idx, |k| w.chain.resolve_key(&w.frames, k));
        self.flow.nodes.push(flow);
        if let Some(p) = it.parent {
            w.nodes[p].children.push(idx);
        }
        let name = it
            .name_override
            .or_else(|| el.attr("name").map(str::to_string));
        w.names.push(name.clone());
        w.explicit.push(el.btfsm_attr("id").map(str::to_string));
        w.nodes.push(BtNode {
            id: String::new(),
            label: name.unwrap_or_else(|| id.clone()),
            kind: btfsm_model::BtNodeKind::Action,
            children: Vec::new(),
            skill: None,
            type_name: Some(id),
            ports: Default::default(),
            subtree: it.subtree,
            id_source: Default::default(),
            span: Some(el.span.clone()),
        });
        Some(())
    }

    /// Reads a node element into the arena and queues its children. `None`
    /// when the node limit is hit.
    fn expand_node(&mut self, w: &mut Walk, it: Item, el: &XElem) -> Option<()> {
        if w.budget == 0 {
            self.err(
                it.d,
                el.span.clone(),
                format!("more than {} nodes", self.limits.max_nodes),
            )
            .hint = Some("raise the limit with --max-nodes".into());
            return None;
        }
        w.budget -= 1;
        let Some(mut node) = self.node(it.d, el, |v| w.chain.resolve(&w.frames, v)) else {
            w.failed = true;
            return Some(());
        };
        node.subtree = it.subtree;
        let idx = w.nodes.len();
        for p in w.pending.drain(..) {
            self.flow.subtrees[p].node = idx;
        }
        let flow = self.node_flow(it.d, el, idx, |k| w.chain.resolve_key(&w.frames, k));
        self.flow.nodes.push(flow);
        if let Some(p) = it.parent {
            w.nodes[p].children.push(idx);
        }
        w.names.push(
            it.name_override
                .or_else(|| el.attr("name").map(str::to_string)),
        );
        w.explicit.push(
            el.btfsm_attr("id")
                .map(str::to_string)
                .or_else(|| el.id_comment.clone()),
        );
        w.nodes.push(node);
        for &c in el.children.iter().rev() {
            w.stack.push(Item {
                d: it.d,
                e: c,
                parent: Some(idx),
                depth: it.depth + 1,
                frame: it.frame,
                name_override: None,
                subtree: None,
            });
        }
        Some(())
    }
}

/// The chain of trees a recursive `<SubTree>` of tree `id` closes, as
/// shown: the cycle itself and at most a few trees before it, a long cycle
/// cut in the middle.
fn recursion(w: &Walk, id: &str) -> String {
    let chain: Vec<String> = w
        .chain
        .frames
        .iter()
        .map(|&f| w.frames[f].id.clone())
        .collect();
    let at = chain.iter().position(|c| *c == id).unwrap_or(0);
    let mut shown_chain: Vec<String> = chain.iter().map(|c| shown(c).into_owned()).collect();
    shown_chain.push(shown(id).into_owned());
    // The cycle itself, and at most a few trees before it.
    let from = at.saturating_sub(3);
    let mut cycle = shown_chain[from..].to_vec();
    if cycle.len() > 12 {
        let n = cycle.len();
        cycle.splice(6..n - 6, [format!("... ({} trees) ...", n - 12)]);
    }
    if from > 0 {
        cycle.insert(0, "...".into());
    }
    cycle.join(" -> ")
}

/// The blackboard entries the script attributes of a `<SubTree>` element
/// use, resolved in the enclosing expansions.
fn script_key_uses(w: &Walk, el: &XElem) -> Vec<KeyUse> {
    let mut script_keys = Vec::new();
    for a in el
        .attrs
        .iter()
        .filter(|a| a.ns.is_none() && SCRIPT_ATTRS.contains(&a.name.as_str()))
    {
        for (name, access) in super::ports::script_keys(&a.value) {
            script_keys.push(KeyUse {
                key: w.chain.resolve_key(&w.frames, &name),
                access,
                port: a.name.clone(),
                ty: None,
                span: a.span.clone(),
            });
        }
    }
    script_keys
}

impl Loader<'_> {
    /// Does document `d` say `BTCPP_format="3"`? (Without the attribute,
    /// BehaviorTree.CPP 4 reads a file as format 4, with a warning.)
    pub(super) fn format_3(&self, d: usize) -> bool {
        let doc = &self.docs[d];
        doc.elems[doc.root].attr("BTCPP_format") == Some("3")
    }

    /// Whether document `d` says `BTCPP_format="4"`: BehaviorTree.CPP 4's
    /// own load checks that BehaviorTree.CPP 3 does not make apply (a file
    /// without the attribute may be written for BehaviorTree.CPP 3, as
    /// format 3's names are reported only under this attribute).
    pub(super) fn says_format_4(&self, d: usize) -> bool {
        let doc = &self.docs[d];
        doc.elems[doc.root].attr("BTCPP_format") == Some("4")
    }
}

/// Attributes of a `<SubTree>` element that are not port remappings.
const SUBTREE_ATTRS: [&str; 5] = [
    "ID",
    "name",
    "_autoremap",
    "__autoremap",
    "__shared_blackboard",
];

/// A SubTree expansion: the tree, the expansion it is in, and its port
/// remapping (subtree entry -> value or outer `{entry}`, already resolved).
pub(super) struct Frame {
    pub(super) id: String,
    pub(super) parent: Option<usize>,
    pub(super) remap: BTreeMap<String, String>,
    /// The blackboard entry each remapped port designates.
    pub(super) keys: BTreeMap<String, Key>,
    /// Entries not remapped are shared with the enclosing tree by name
    /// (`_autoremap="true"`, format 3's `__shared_blackboard`).
    pub(super) autoremap: bool,
}

/// The entry a port value refers to: `key` of a whole `{key}`.
pub(super) fn port_key(value: &str) -> Option<&str> {
    value
        .strip_prefix('{')
        .and_then(|v| v.strip_suffix('}'))
        .filter(|k| !k.is_empty() && !k.contains(['{', '}']))
}

/// The expansions enclosing the element being expanded (outermost first),
/// kept as the expansion walks the tree depth-first, with what makes
/// lookups O(1): how often each tree ID is on the chain (recursion), the
/// positions of the expansions that do not share their blackboard by name,
/// and per blackboard entry the positions of the expansions remapping it.
/// Each expansion is entered and left once, so the whole expansion is
/// linear in the remappings (a walk up the chain per port was quadratic on
/// a long chain of `_autoremap` SubTrees).
#[derive(Default)]
pub(super) struct Chain {
    pub(super) frames: Vec<usize>,
    pub(super) trees: HashMap<String, usize>,
    pub(super) barriers: Vec<usize>,
    pub(super) by_key: HashMap<String, Vec<usize>>,
}

impl Chain {
    pub(super) fn push(&mut self, frames: &[Frame], f: usize) {
        let at = self.frames.len();
        self.frames.push(f);
        *self.trees.entry(frames[f].id.clone()).or_default() += 1;
        if !frames[f].autoremap {
            self.barriers.push(at);
        }
        for k in frames[f].remap.keys() {
            self.by_key.entry(k.clone()).or_default().push(at);
        }
    }

    pub(super) fn pop(&mut self, frames: &[Frame]) {
        let Some(f) = self.frames.pop() else { return };
        let at = self.frames.len();
        if let Some(c) = self.trees.get_mut(&frames[f].id) {
            *c -= 1;
        }
        if self.barriers.last() == Some(&at) {
            self.barriers.pop();
        }
        for k in frames[f].remap.keys() {
            if let Some(v) = self.by_key.get_mut(k) {
                v.pop();
            }
        }
    }

    /// Makes `f` the innermost expansion: leaves those the walk is done
    /// with, enters `f` if it is new (a child of the innermost one).
    pub(super) fn enter(&mut self, frames: &[Frame], f: usize) {
        while let Some(&top) = self.frames.last() {
            if top == f || Some(top) == frames[f].parent {
                break;
            }
            self.pop(frames);
        }
        if self.frames.last() != Some(&f) {
            self.push(frames, f);
        }
    }

    /// The blackboard entry `key` (of a `{key}` in the innermost expansion)
    /// is: the one the innermost expansion remapping it designates, else
    /// the innermost expansion's own that does not share its blackboard by
    /// name; `@key` is the tree's own (BehaviorTree.CPP 4's global entries).
    pub(super) fn resolve_key(&self, frames: &[Frame], key: &str) -> Key {
        if let Some(g) = key.strip_prefix('@') {
            return Key {
                scope: 0,
                name: g.to_string(),
            };
        }
        let barrier = self.barriers.last().copied().unwrap_or(0);
        match self.by_key.get(key).and_then(|v| v.last()) {
            Some(&at) if at >= barrier => frames[self.frames[at]].keys[key].clone(),
            _ => Key {
                scope: self.frames.get(barrier).copied().unwrap_or(0),
                name: key.to_string(),
            },
        }
    }

    /// [`resolve_port`] in the innermost expansion, in O(1): the innermost
    /// expansion remapping the entry, if no expansion in between (the
    /// outer one included) keeps its blackboard to itself.
    pub(super) fn resolve(&self, frames: &[Frame], value: &str) -> String {
        let Some(key) = port_key(value) else {
            return value.to_string();
        };
        let barrier = self.barriers.last().copied().unwrap_or(0);
        match self.by_key.get(key).and_then(|v| v.last()) {
            Some(&at) if at >= barrier => frames[self.frames[at]].remap[key].clone(),
            _ => value.to_string(),
        }
    }
}

/// The value a port written as `value` inside expansion `frame` has in the
/// expanded tree: a blackboard reference `{key}` remapped by the enclosing
/// SubTree elements is replaced by what they map it to (a literal or an outer
/// `{key}`); anything else is kept as written. BehaviorTree.CPP gives a
/// subtree its own blackboard, so inlining it means renaming its entries.
/// (The reference definition; the reader uses [`Chain::resolve`].)
#[cfg(test)]
pub(super) fn resolve_port(frames: &[Frame], frame: usize, value: &str) -> String {
    let Some(key) = port_key(value) else {
        return value.to_string();
    };
    let mut f = frame;
    loop {
        let fr = &frames[f];
        if let Some(v) = fr.remap.get(key) {
            return v.clone();
        }
        match fr.parent {
            Some(p) if fr.autoremap => f = p,
            _ => return value.to_string(),
        }
    }
}
