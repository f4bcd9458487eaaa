//! Reading a TOML Behavior Tree: the flat node table, node kinds and their
//! parameters, ports, the tree's shape (one root, no cycles, no sharing).

use super::*;

/// A node table's ids in file order, with their key spans.
type Ids<'a> = [(&'a str, Range<usize>)];

/// One node as its table says (first pass): its kind, label, children
/// ids, skill, included subtree, type and ports. A node that could not be
/// read has neither kind nor subtree.
struct RawNode {
    kind: Option<BtNodeKind>,
    label: String,
    children: Vec<(String, Range<usize>)>,
    skill: Option<SkillCall>,
    include: Option<Bt>,
    type_name: Option<String>,
    ports: BTreeMap<String, String>,
}

impl RawNode {
    /// A node that could not be read, labelled with its id.
    fn unread(id: &str) -> RawNode {
        RawNode {
            kind: None,
            label: id.to_string(),
            children: vec![],
            skill: None,
            include: None,
            type_name: None,
            ports: BTreeMap::new(),
        }
    }

    /// A node that includes a subtree file (read as `sub`).
    fn included(sub: Bt) -> RawNode {
        RawNode {
            kind: None,
            label: String::new(),
            children: vec![],
            skill: None,
            include: Some(sub),
            type_name: None,
            ports: BTreeMap::new(),
        }
    }
}

/// A node table being read: its id, the table, and its one type key
/// (`action`, `sequence`, ...) with that key's value and span.
struct NodeAt<'a, 'i> {
    id: &'a str,
    t: &'a DeTable<'i>,
    tkey: &'a str,
    tval: &'a Val<'i>,
    tspan: Range<usize>,
}

/// The tree's links once children ids are resolved: each node's parent
/// and children, by index in the node table.
struct Links {
    parent: Vec<Option<usize>>,
    children: Vec<Vec<usize>>,
}

impl Loader {
    /// Reads a BT document. `prefix` is set for included subtrees: node ids become
    /// `prefix/id` and the root takes the id `prefix`.
    pub(super) fn bt(
        &mut self,
        cx: &Ctx<'_>,
        doc: &DeTable<'_>,
        whole: Range<usize>,
        prefix: Option<&str>,
    ) -> Option<Bt> {
        let nodes = self.nodes_table(cx, doc, whole)?;
        let ids: Vec<(&str, Range<usize>)> = nodes
            .iter()
            .map(|(k, _)| (k.get_ref().as_ref(), k.span()))
            .collect();
        let index: HashMap<&str, usize> =
            ids.iter().enumerate().map(|(i, (k, _))| (*k, i)).collect();

        let root = self.bt_root(cx, doc, &ids, &index)?;

        // First pass: each node's type, label, children ids, skill.
        let mut raws: Vec<RawNode> = Vec::with_capacity(ids.len());
        for (key, v) in nodes.iter() {
            let id = key.get_ref().as_ref();
            if self.node_budget == 0 {
                self.err(
                    cx,
                    key.span(),
                    format!("more than {} nodes", self.limits.max_nodes),
                )
                .hint = Some("raise the limit with --max-nodes".into());
                return None;
            }
            self.node_budget -= 1;
            raws.push(
                self.bt_node(cx, id, key.span(), v)
                    .unwrap_or_else(|| RawNode::unread(id)),
            );
        }

        // Second pass: resolve children, check arity and tree shape.
        let links = self.link_children(cx, &ids, &index, &raws, root);
        self.check_cycles(cx, &ids, &links, root);
        // Unreachable nodes (no parent and not the root), when the tree is
        // otherwise sound (a broken node makes its children look unreachable).
        let sound =
            !self.any_error() && raws.iter().all(|r| r.kind.is_some() || r.include.is_some());
        if sound {
            self.unreachable_nodes(cx, &ids, &links, root);
        }
        self.check_arity(cx, &ids, &raws);
        if self.any_error() || raws.iter().any(|r| r.kind.is_none() && r.include.is_none()) {
            return None;
        }
        self.build_arena(cx, &ids, raws, &links, root, prefix)
    }

    /// The `[nodes]` table of a BT document, which must hold a node.
    fn nodes_table<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        doc: &'t DeTable<'i>,
        whole: Range<usize>,
    ) -> Option<&'t DeTable<'i>> {
        let Some(nodes_v) = doc.get("nodes") else {
            self.err(cx, whole.start..whole.start, "a BT needs a `[nodes]` table")
                .hint = Some(
                "add `[nodes]` with one line per node, e.g. `root = { sequence = [\"a\", \"b\"] }`"
                    .into(),
            );
            return None;
        };
        let DeValue::Table(nodes) = nodes_v.get_ref() else {
            self.err(
                cx,
                nodes_v.span(),
                format!(
                    "`nodes` must be a table, found {}",
                    type_name(nodes_v.get_ref())
                ),
            );
            return None;
        };
        if nodes.is_empty() {
            self.err(cx, nodes_v.span(), "`[nodes]` is empty").hint =
                Some("a BT needs at least one node".into());
            return None;
        }
        Some(nodes)
    }

    /// The root node: explicit `root = "id"` or the first node.
    fn bt_root(
        &mut self,
        cx: &Ctx<'_>,
        doc: &DeTable<'_>,
        ids: &Ids<'_>,
        index: &HashMap<&str, usize>,
    ) -> Option<usize> {
        match doc.get("root") {
            Some(r) => match r.get_ref().as_str() {
                Some(s) => match index.get(s) {
                    Some(&i) => Some(i),
                    None => {
                        let h = self.suggest(s, ids.iter().map(|(k, _)| *k));
                        self.err(cx, r.span(), format!("unknown node `{s}` given as `root`"))
                            .hint = Some(h);
                        None
                    }
                },
                None => {
                    self.err(cx, r.span(), "`root` must be a string naming a node");
                    None
                }
            },
            None => Some(0),
        }
    }

    /// Resolves every node's children ids, reporting unknown ids, the root
    /// as a child and nodes with two parents.
    fn link_children(
        &mut self,
        cx: &Ctx<'_>,
        ids: &Ids<'_>,
        index: &HashMap<&str, usize>,
        raws: &[RawNode],
        root: usize,
    ) -> Links {
        let mut parent: Vec<Option<usize>> = vec![None; ids.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); ids.len()];
        for (i, raw) in raws.iter().enumerate() {
            for (c, span) in &raw.children {
                match index.get(c.as_str()) {
                    None => {
                        let h = self.suggest(c, ids.iter().map(|(k, _)| *k));
                        self.err(
                            cx,
                            span.clone(),
                            format!("unknown node `{c}` in children of `{}`", ids[i].0),
                        )
                        .hint = Some(h);
                    }
                    Some(&ci) if ci == root => {
                        self.err(
                            cx,
                            span.clone(),
                            format!(
                                "the root `{}` cannot be a child of `{}`",
                                ids[ci].0, ids[i].0
                            ),
                        )
                        .hint = Some("a BT is a tree: the root has no parent".into());
                    }
                    Some(&ci) => match parent[ci] {
                        Some(p) => {
                            self.err(
                                cx,
                                span.clone(),
                                format!(
                                    "node `{c}` is a child of both `{}` and `{}`",
                                    ids[p].0, ids[i].0
                                ),
                            )
                            .hint = Some(
                                "a BT is a tree: give the second use its own node (or include a subtree file twice)"
                                    .into(),
                            );
                        }
                        None => {
                            parent[ci] = Some(i);
                            children[i].push(ci);
                        }
                    },
                }
            }
        }
        Links { parent, children }
    }

    /// Reports cycles among non-root nodes, walking up from every node
    /// (iteratively).
    fn check_cycles(&mut self, cx: &Ctx<'_>, ids: &Ids<'_>, links: &Links, root: usize) {
        let mut state = vec![0u8; ids.len()]; // 0 unknown, 1 on path, 2 reaches root
        state[root] = 2;
        for start in 0..ids.len() {
            let mut path = Vec::new();
            let mut cur = start;
            loop {
                match state[cur] {
                    2 => break,
                    1 => {
                        self.err(
                            cx,
                            ids[cur].1.clone(),
                            format!("node `{}` is its own ancestor", ids[cur].0),
                        )
                        .hint = Some("a BT is a tree: children lists must not form a cycle".into());
                        break;
                    }
                    _ => {}
                }
                state[cur] = 1;
                path.push(cur);
                match links.parent[cur] {
                    Some(p) => cur = p,
                    None => break,
                }
            }
            for p in path {
                state[p] = 2;
            }
        }
    }

    /// Warns about nodes that have no parent and are not the root.
    fn unreachable_nodes(&mut self, cx: &Ctx<'_>, ids: &Ids<'_>, links: &Links, root: usize) {
        for (i, (id, span)) in ids.iter().enumerate() {
            if i != root && links.parent[i].is_none() {
                self.warn(
                    cx,
                    span.clone(),
                    format!(
                        "node `{id}` is not reachable from the root `{}`",
                        ids[root].0
                    ),
                );
                self.hint_last("list it in the children of a control node, or remove it");
            }
        }
    }

    /// Checks each node's number of children against its kind, and a
    /// parallel node's `success` against its children.
    fn check_arity(&mut self, cx: &Ctx<'_>, ids: &Ids<'_>, raws: &[RawNode]) {
        for (i, raw) in raws.iter().enumerate() {
            let Some(kind) = raw.kind else { continue };
            let n = raw.children.len();
            let span = ids[i].1.clone();
            match kind.arity() {
                Arity::One if n != 1 => {
                    self.err(
                        cx,
                        span,
                        format!(
                            "decorator `{}` (`{}`) takes exactly one child, found {n}",
                            ids[i].0,
                            kind.keyword()
                        ),
                    )
                    .set_code("wrong-child-count")
                    .hint = Some(format!(
                        "write `{} = \"child\"`; wrap several children in a sequence or fallback",
                        kind.keyword()
                    ));
                }
                Arity::AtLeastOne if n == 0 => {
                    self.err(
                        cx,
                        span,
                        format!(
                            "control node `{}` (`{}`) has no children",
                            ids[i].0,
                            kind.keyword()
                        ),
                    )
                    .set_code("empty-composite")
                    .hint = Some(format!(
                        "write `{} = [\"child1\", \"child2\"]`",
                        kind.keyword()
                    ));
                }
                _ => {}
            }
            if let BtNodeKind::Parallel { success } = kind
                && n > 0
                && (success == 0 || success > n)
            {
                self.err(
                    cx,
                    ids[i].1.clone(),
                    format!(
                        "parallel node `{}` needs `success` between 1 and its {n} children, found {success}",
                        ids[i].0
                    ),
                );
            }
        }
    }

    /// Builds the arena in pre-order from the root, splicing included subtrees.
    /// An included tree's ids are its own (`x`); the including node's
    /// id is put before them when it is spliced (`moma1/x`).
    fn build_arena(
        &mut self,
        cx: &Ctx<'_>,
        ids: &Ids<'_>,
        mut raws: Vec<RawNode>,
        links: &Links,
        root: usize,
        prefix: Option<&str>,
    ) -> Option<Bt> {
        let full_id = |id: &str| match prefix {
            Some(p) if id.is_empty() => p.to_string(),
            Some(p) if !p.is_empty() => format!("{p}/{id}"),
            _ => id.to_string(),
        };
        let mut out: Vec<BtNode> = Vec::new();
        let mut new_index = vec![usize::MAX; ids.len()];
        let mut order = vec![root];
        let mut k = 0;
        while k < order.len() {
            let i = order[k];
            k += 1;
            order.extend(links.children[i].iter().copied());
        }
        for &i in &order {
            new_index[i] = out.len();
            let raw = &mut raws[i];
            let id = if i == root && prefix.is_some() {
                full_id("")
            } else {
                full_id(ids[i].0)
            };
            match raw.include.take() {
                Some(sub) => new_index[i] = self.splice_subtree(cx, &ids[i], id, sub, &mut out)?,
                None => out.push(BtNode {
                    id,
                    label: std::mem::take(&mut raw.label),
                    kind: raw.kind.expect("checked above"),
                    children: Vec::new(),
                    skill: raw.skill.take(),
                    type_name: raw.type_name.take(),
                    ports: std::mem::take(&mut raw.ports),
                    subtree: None,
                    id_source: btfsm_model::IdSource::Given,
                    span: Some(ids[i].1.clone()),
                }),
            }
        }
        for &i in &order {
            let ni = new_index[i];
            if !links.children[i].is_empty() {
                out[ni].children = links.children[i].iter().map(|&c| new_index[c]).collect();
            }
        }
        Some(Bt {
            nodes: out,
            root: new_index[root],
        })
    }

    /// Appends an included tree in place of the node `(name, span)` whose
    /// id is `id`: its root takes that id, its other nodes are put under
    /// it. Returns the index of the spliced root.
    fn splice_subtree(
        &mut self,
        cx: &Ctx<'_>,
        (name, span): &(&str, Range<usize>),
        id: String,
        sub: Bt,
        out: &mut Vec<BtNode>,
    ) -> Option<usize> {
        // The included tree's root takes this node's place and id.
        // Ids grow by a prefix at each level: bounded here, before
        // millions of them are built.
        let longest = sub.nodes.iter().map(|n| n.id.len()).max().unwrap_or(0);
        if id.len() + 1 + longest > self.limits.max_name_bytes {
            self.err(
                cx,
                span.clone(),
                format!(
                    "the ids of subtree node `{}` would be longer than the limit of {} bytes",
                    btfsm_core::sanitize::shown(name),
                    self.limits.max_name_bytes
                ),
            )
            .hint = Some("nest fewer subtrees, or raise the limit with --max-name-bytes".into());
            return None;
        }
        let offset = out.len();
        for (j, mut n) in sub.nodes.into_iter().enumerate() {
            n.id = if j == sub.root {
                // The boundary of the inclusion, for drawing it folded.
                n.subtree = n.subtree.or(Some(name.to_string()));
                id.clone()
            } else {
                format!("{id}/{}", n.id)
            };
            for c in &mut n.children {
                *c += offset;
            }
            // Spans are positions in this file.
            n.span = None;
            out.push(n);
        }
        Some(offset + sub.root)
    }

    /// Reads one node table.
    fn bt_node(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        key_span: Range<usize>,
        v: &Val<'_>,
    ) -> Option<RawNode> {
        let DeValue::Table(t) = v.get_ref() else {
            self.err(
                cx,
                v.span(),
                format!(
                    "node `{id}` must be a table, found {}",
                    type_name(v.get_ref())
                ),
            )
            .hint = Some(format!(
                "write `{id} = {{ action = \"Move-To cube2!\", skill = \"Move-To\", args = {{ target = \"cube2\" }} }}`"
            ));
            return None;
        };
        let n = self.node_type(cx, id, key_span, t)?;
        let name = self.opt_str(cx, t, "name");
        if n.tkey == "subtree" {
            let sub = self.include(cx, id, t, n.tval)?;
            return Some(RawNode::included(sub));
        }
        let kind = self.node_kind(cx, &n)?;
        self.misplaced_fields(cx, &n, kind);
        let (label, skill, children) = match kind.arity() {
            Arity::Leaf => {
                let (label, skill) = self.leaf(cx, &n, kind)?;
                (label, skill, Vec::new())
            }
            _ => (
                name.unwrap_or_else(|| kind.default_label().to_string()),
                None,
                self.child_ids(cx, &n)?,
            ),
        };
        let type_name = self.opt_str(cx, t, "type");
        if matches!(kind, BtNodeKind::Control | BtNodeKind::Decorator) && type_name.is_none() {
            self.err(cx, n.tspan, format!("{} node `{id}` needs `type`", n.tkey))
                .hint = Some(
                "write `type = \"IfThenElse\"`: the node's kind in the file it came from".into(),
            );
            return None;
        }
        let ports = self.ports(cx, t, id)?;
        Some(RawNode {
            kind: Some(kind),
            label,
            children,
            skill,
            include: None,
            type_name,
            ports,
        })
    }

    /// Finds a node table's one type key, reporting unknown keys and a
    /// missing or second type.
    fn node_type<'a, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        id: &'a str,
        key_span: Range<usize>,
        t: &'a DeTable<'i>,
    ) -> Option<NodeAt<'a, 'i>> {
        const FIELDS: &[&str] = &[
            "name", "skill", "args", "success", "times", "ms", "with", "type", "ports",
        ];
        let type_keys: Vec<(&str, &Val<'_>, Range<usize>)> = t
            .iter()
            .filter(|(k, _)| NODE_KEYWORDS.contains(&k.get_ref().as_ref()))
            .map(|(k, v)| (k.get_ref().as_ref(), v, k.span()))
            .collect();
        let mut unknown_keys = false;
        for (k, _) in t.iter() {
            let k_str: &str = k.get_ref();
            if !NODE_KEYWORDS.contains(&k_str) && !FIELDS.contains(&k_str) {
                unknown_keys = true;
                let h = self.suggest(k_str, NODE_KEYWORDS.iter().chain(FIELDS).copied());
                self.err(
                    cx,
                    k.span(),
                    format!("unknown node type or field `{k_str}` in node `{id}`"),
                )
                .hint = Some(h);
            }
        }
        let (tkey, tval, tspan) = match type_keys.as_slice() {
            [one] => one.clone(),
            [] if unknown_keys => return None,
            [] => {
                self.err(cx, key_span, format!("node `{id}` has no type"))
                    .hint = Some(format!(
                    "add one of {}",
                    NODE_KEYWORDS
                        .iter()
                        .map(|k| format!("`{k}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                return None;
            }
            [_, second, ..] => {
                self.err(
                    cx,
                    second.2.clone(),
                    format!(
                        "node `{id}` has two types, `{}` and `{}`",
                        type_keys[0].0, second.0
                    ),
                )
                .hint = Some("a node has exactly one type key".into());
                return None;
            }
        };
        Some(NodeAt {
            id,
            t,
            tkey,
            tval,
            tspan,
        })
    }

    /// The kind a node's type key gives, with its parameters (`success`,
    /// `times`, `ms`); not for subtrees.
    fn node_kind(&mut self, cx: &Ctx<'_>, n: &NodeAt<'_, '_>) -> Option<BtNodeKind> {
        let uint = |s: &mut Self, key: &str| s.opt_uint(cx, n.t, key, n.id);
        Some(match n.tkey {
            "sequence" => BtNodeKind::Sequence,
            "fallback" => BtNodeKind::Fallback,
            "sequence_memory" => BtNodeKind::SequenceMemory,
            "fallback_memory" => BtNodeKind::FallbackMemory,
            "parallel" => BtNodeKind::Parallel {
                success: uint(self, "success")
                    .map(|s| s as usize)
                    .unwrap_or_else(|| match n.tval.get_ref() {
                        DeValue::Array(a) => a.len(),
                        _ => 1,
                    }),
            },
            "inverter" => BtNodeKind::Inverter,
            "force_success" => BtNodeKind::ForceSuccess,
            "force_failure" => BtNodeKind::ForceFailure,
            "repeat" => BtNodeKind::Repeat {
                times: uint(self, "times").map(|t| t.min(u32::MAX as u64) as u32),
            },
            "retry" => BtNodeKind::Retry {
                times: uint(self, "times").map_or(1, |t| t.min(u32::MAX as u64) as u32),
            },
            "timeout" => match uint(self, "ms") {
                Some(ms) => BtNodeKind::Timeout { ms },
                None => {
                    self.err(
                        cx,
                        n.tspan.clone(),
                        format!("timeout `{}` needs `ms`", n.id),
                    )
                    .hint = Some("write `ms = 5000`".into());
                    return None;
                }
            },
            "action" => BtNodeKind::Action,
            "condition" => BtNodeKind::Condition,
            "control" => BtNodeKind::Control,
            "decorator" => BtNodeKind::Decorator,
            _ => unreachable!("filtered by NODE_KEYWORDS, subtrees read before"),
        })
    }

    /// Reports fields that do not belong to the node's kind.
    fn misplaced_fields(&mut self, cx: &Ctx<'_>, n: &NodeAt<'_, '_>, kind: BtNodeKind) {
        for (k, _) in n.t.iter() {
            let k_str: &str = k.get_ref();
            let fits = match k_str {
                "name" => true,
                "skill" | "args" => matches!(kind, BtNodeKind::Action | BtNodeKind::Condition),
                "success" => matches!(kind, BtNodeKind::Parallel { .. }),
                "times" => matches!(kind, BtNodeKind::Repeat { .. } | BtNodeKind::Retry { .. }),
                "ms" => matches!(kind, BtNodeKind::Timeout { .. }),
                "with" => false,
                "type" | "ports" => true,
                _ => true,
            };
            if !fits {
                self.err(
                    cx,
                    k.span(),
                    format!("`{k_str}` does not apply to {} node `{}`", n.tkey, n.id),
                );
            }
        }
    }

    /// A leaf's label (the type key's value) and skill call.
    fn leaf(
        &mut self,
        cx: &Ctx<'_>,
        n: &NodeAt<'_, '_>,
        kind: BtNodeKind,
    ) -> Option<(String, Option<SkillCall>)> {
        let (id, tkey) = (n.id, n.tkey);
        match n.tval.get_ref().as_str() {
            Some(s) => {
                let label = cx.subst(s);
                let want = if kind == BtNodeKind::Action {
                    SkillKind::Action
                } else {
                    SkillKind::Condition
                };
                let skill = self.skill_call(cx, n.t, &format!("node `{id}`"), Some(want));
                if n.t.contains_key("skill") && skill.is_none() {
                    return None;
                }
                Some((label, skill))
            }
            None => {
                self.err(
                    cx,
                    n.tval.span(),
                    format!(
                        "`{tkey}` of node `{id}` must be its display name (a string), found {}",
                        type_name(n.tval.get_ref())
                    ),
                )
                .hint = Some(format!("write `{tkey} = \"Robot-At cube2?\"`"));
                None
            }
        }
    }

    /// The children ids a control node or decorator lists (the type key's
    /// value: one id or an array of them).
    fn child_ids(
        &mut self,
        cx: &Ctx<'_>,
        n: &NodeAt<'_, '_>,
    ) -> Option<Vec<(String, Range<usize>)>> {
        let (id, tkey, tval) = (n.id, n.tkey, n.tval);
        let mut children = Vec::new();
        match tval.get_ref() {
            DeValue::String(s) => children.push((s.to_string(), tval.span())),
            DeValue::Array(a) => {
                for c in a.iter() {
                    match c.get_ref().as_str() {
                        Some(s) => children.push((s.to_string(), c.span())),
                        None => {
                            self.err(
                                cx,
                                c.span(),
                                format!(
                                    "children of `{id}` must be node ids (strings), found {}",
                                    type_name(c.get_ref())
                                ),
                            );
                        }
                    }
                }
            }
            other => {
                self.err(
                    cx,
                    tval.span(),
                    format!(
                        "`{tkey}` of node `{id}` must list children ids, found {}",
                        type_name(other)
                    ),
                )
                .hint = Some(format!("write `{tkey} = [\"child1\", \"child2\"]`"));
                return None;
            }
        }
        Some(children)
    }

    /// Reads `ports = { name = "value", ... }` (values kept as text).
    pub(super) fn ports(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        id: &str,
    ) -> Option<BTreeMap<String, String>> {
        let mut out = BTreeMap::new();
        let Some(pv) = t.get("ports") else {
            return Some(out);
        };
        let DeValue::Table(pt) = pv.get_ref() else {
            self.err(
                cx,
                pv.span(),
                format!(
                    "`ports` of node `{id}` must be a table, found {}",
                    type_name(pv.get_ref())
                ),
            )
            .hint = Some("write `ports = { num_cycles = \"3\" }`".into());
            return None;
        };
        for (k, v) in pt.iter() {
            match v.get_ref() {
                DeValue::String(_)
                | DeValue::Integer(_)
                | DeValue::Float(_)
                | DeValue::Boolean(_) => {
                    out.insert(k.get_ref().to_string(), scalar_text(v.get_ref()));
                }
                other => {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "port `{}` of node `{id}` must be a string, found {}",
                            k.get_ref(),
                            type_name(other)
                        ),
                    );
                    return None;
                }
            }
        }
        Some(out)
    }
}
