//! Dataflow rules: what a BehaviorTree.CPP tree's ports and blackboard
//! entries say before it runs (docs/lint.md). The facts are the loader's
//! [`Dataflow`]: each node's declared ports (its `<TreeNodesModel>` entry,
//! or a BehaviorTree.CPP 4 built-in's `providedPorts()`), the entries its
//! ports and scripts read and write, resolved through SubTree remappings
//! (BehaviorTree.CPP 4 "Remapping ports between Trees and SubTrees"). A
//! node whose type has no known ports is never judged; a `{key}` on it may
//! read or write, so the rules about that key stay silent. Tick order is
//! the tree's preorder (docs/bt-semantics.md).
//!
//! Work: one pass over the nodes' attributes and keys with hash maps, one
//! map per declared type; nothing is compared pairwise.

use super::{Level, Rule, Sink, Subject};
use btfsm_format::btcpp_xml::Dataflow;
use btfsm_format::btcpp_xml::ports::{Access, Key, KeyUse, PortDecl, PortDir, is_pointer};
use btfsm_model::{BtNodeKind, PolicyBody};
use std::collections::{HashMap, HashSet};
use std::ops::Range;

/// The dataflow of a BT, when it has one that matches its nodes.
fn flow<'a>(s: &'a Subject) -> Option<&'a Dataflow> {
    let PolicyBody::Bt(bt) = &s.policy.body else {
        return None;
    };
    s.dataflow.filter(|d| d.nodes.len() == bt.nodes.len())
}

/// A finding's span (in the file linted), or where it is in another one.
pub(crate) fn place(
    df: &Dataflow,
    doc: usize,
    span: &Range<usize>,
) -> (Option<Range<usize>>, String) {
    if doc == 0 {
        return (Some(span.clone()), String::new());
    }
    match df.files.get(doc) {
        Some(f) => {
            let (l, c) = f.line_col(span.start.min(f.text.len()));
            (None, format!(" (at {}:{l}:{c})", f.path))
        }
        None => (None, String::new()),
    }
}

/// Node id of flow `i`.
fn id_of<'a>(s: &'a Subject, i: usize) -> &'a str {
    match &s.policy.body {
        PolicyBody::Bt(bt) => bt.nodes.get(i).map_or("", |n| n.id.as_str()),
        PolicyBody::Machine(_) => "",
    }
}

/// Node `i` as a reader sees it: `label` (`id`), or `id` when they agree.
fn who(s: &Subject, i: usize) -> String {
    let PolicyBody::Bt(bt) = &s.policy.body else {
        return String::new();
    };
    match bt.nodes.get(i) {
        Some(n) if n.label != n.id => format!("`{}` (`{}`)", n.label, n.id),
        Some(n) => format!("`{}`", n.id),
        None => String::new(),
    }
}

/// Per declared type, its ports by name (built once per type).
fn port_maps(df: &Dataflow) -> Vec<HashMap<&str, &PortDecl>> {
    df.decls
        .iter()
        .map(|ps| ps.iter().map(|p| (p.name.as_str(), p)).collect())
        .collect()
}

/// Suggestions (did-you-mean over the declared ports) for this many
/// findings at most: each scans the type's ports.
const HINTED: usize = 64;

pub const OUTPUT_PORT_LITERAL: Rule = Rule {
    code: "output-port-literal",
    level: Level::Error,
    summary: "an output port given a literal instead of a `{key}`: BehaviorTree.CPP cannot write it anywhere",
    check: output_port_literal,
};

fn output_port_literal(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let maps = port_maps(df);
    for nf in &df.nodes {
        let Some(m) = nf.decl.map(|x| &maps[x]) else {
            continue;
        };
        for u in &nf.ports {
            let Some(p) = m.get(u.name.as_str()) else {
                continue;
            };
            if p.dir != PortDir::Output || p.key_name || u.value.is_empty() || is_pointer(&u.value)
            {
                continue;
            }
            let (span, at) = place(df, nf.doc, &u.span);
            out.push(
                id_of(s, nf.node),
                span,
                format!(
                    "`{}` is an output port of `{}`, given the literal \"{}\"{at}: BehaviorTree.CPP writes an output only into a blackboard entry (setOutput fails)",
                    u.name, nf.ty, u.value
                ),
                format!(
                    "name the entry it writes: {}=\"{{{}}}\"",
                    u.name,
                    if u.value.chars().all(|c| c.is_alphanumeric() || c == '_') {
                        u.value.as_str()
                    } else {
                        "key"
                    }
                ),
            );
        }
    }
}

pub const UNDECLARED_PORT: Rule = Rule {
    code: "undeclared-port",
    level: Level::Error,
    summary: "a port the node's type does not declare: BehaviorTree.CPP refuses to load the tree",
    check: undeclared_port,
};

fn undeclared_port(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let maps = port_maps(df);
    let mut hinted = 0;
    for nf in &df.nodes {
        let Some(x) = nf.decl else { continue };
        for u in nf
            .ports
            .iter()
            .filter(|u| !maps[x].contains_key(u.name.as_str()))
        {
            let (span, at) = place(df, nf.doc, &u.span);
            let whose = if nf.builtin {
                "the built-in"
            } else {
                "the model of"
            };
            let help = if df.decls[x].is_empty() {
                format!("`{}` takes no ports; remove `{}`", nf.ty, u.name)
            } else if hinted < HINTED {
                hinted += 1;
                btfsm_core::diagnostic::suggest(
                    &u.name,
                    df.decls[x].iter().map(|p| p.name.as_str()),
                )
            } else {
                "remove it, or declare it in the `<TreeNodesModel>`".into()
            };
            // A model given lists the ports the program's nodes provide; one
            // found beside the trees (or in the file) may be out of date.
            let why = if nf.builtin || df.node_types.given_model {
                "BehaviorTree.CPP refuses a port its node type does not provide"
            } else {
                "BehaviorTree.CPP refuses it unless the model is out of date (the node's providedPorts() decide)"
            };
            out.push(
                id_of(s, nf.node),
                span,
                format!(
                    "{whose} `{}` declares no port `{}`{at}; {why}",
                    nf.ty, u.name
                ),
                help,
            );
        }
    }
}

pub const MISSING_REQUIRED_PORT: Rule = Rule {
    code: "missing-required-port",
    level: Level::Warning,
    summary: "a built-in node without an input port it needs (Sleep's msec, Repeat's num_cycles...): it fails when ticked",
    check: missing_required_port,
};

pub const MISSING_MODEL_PORT: Rule = Rule {
    code: "missing-model-port",
    level: Level::Allow,
    summary: "an input port a node model declares without a default is not given (off: a model does not say what is optional)",
    check: missing_model_port,
};

fn missing_required_port(s: &Subject, out: &mut Sink) {
    missing_inputs(s, out, true);
}

fn missing_model_port(s: &Subject, out: &mut Sink) {
    missing_inputs(s, out, false);
}

/// Inputs declared without a default and not given: of built-ins (whose
/// source says which they need) or of types a model declares.
fn missing_inputs(s: &Subject, out: &mut Sink, builtins: bool) {
    let Some(df) = flow(s) else { return };
    // Per type, its required inputs (by name).
    let required: Vec<HashSet<&str>> = df
        .decls
        .iter()
        .map(|ps| {
            ps.iter()
                .filter(|p| p.dir == PortDir::Input && p.default.is_none() && !p.optional)
                .map(|p| p.name.as_str())
                .collect()
        })
        .collect();
    for nf in df.nodes.iter().filter(|nf| nf.builtin == builtins) {
        let Some(x) = nf.decl else { continue };
        let req = &required[x];
        if req.is_empty() {
            continue;
        }
        // Linear in the node's attributes: count the required ones given,
        // then name the first few missing, scanning at most that far.
        let given: HashSet<&str> = nf.ports.iter().map(|u| u.name.as_str()).collect();
        let present = given.iter().filter(|g| req.contains(*g)).count();
        if present == req.len() {
            continue;
        }
        let missing: Vec<&str> = df.decls[x]
            .iter()
            .filter(|p| req.contains(p.name.as_str()) && !given.contains(p.name.as_str()))
            .take(3)
            .map(|p| p.name.as_str())
            .collect();
        let n = req.len() - present;
        let more = if n > missing.len() {
            format!(" and {} more", n - missing.len())
        } else {
            String::new()
        };
        let (span, at) = place(df, nf.doc, &nf.span);
        out.push(
            id_of(s, nf.node),
            span,
            format!(
                "`{}` needs the input port{} `{}`{more} (declared without a default), not given here{at}",
                nf.ty,
                if n == 1 { "" } else { "s" },
                missing.join("`, `")
            ),
            if builtins {
                format!(
                    "give it, e.g. {}=\"...\" (BehaviorTree.CPP fails the node when it reads it)",
                    missing[0]
                )
            } else {
                format!(
                    "give it, e.g. {}=\"{{{}}}\", or declare a `default` in the model",
                    missing[0], missing[0]
                )
            },
        );
    }
}

/// Where a key is read, written and mentioned, in tick order.
#[derive(Default)]
struct KeyFacts {
    /// Preorder position of the first node writing it.
    first_write: Option<(usize, usize)>,
    /// The first node reading it through a port or a compound assignment
    /// (position, flow index, key-use index).
    first_read: Option<(usize, usize, usize)>,
    /// Read anyhow (ports, scripts, ports of unknown direction).
    read: bool,
    /// Used by a port whose direction is not known.
    unknown: bool,
    /// The first writer's declared type (a type BehaviorTree.CPP checks).
    typed_write: Option<(usize, usize, usize)>,
}

/// Every key's facts, the keys SubTrees remap to, and the keys provided
/// from outside the nodes (literals given by SubTrees, the tree's declared
/// inputs).
struct Facts<'a> {
    keys: HashMap<&'a Key, KeyFacts>,
    remapped: HashSet<&'a Key>,
    provided: HashSet<Key>,
    /// Keys of the tree's own blackboard the application reads (its
    /// declared outputs).
    exported: HashSet<Key>,
}

fn facts(df: &Dataflow) -> Facts<'_> {
    let mut keys: HashMap<&Key, KeyFacts> = HashMap::new();
    // The scripts of SubTree elements run at their subtree's root.
    let mut at_root: HashMap<usize, Vec<&KeyUse>> = HashMap::new();
    for st in &df.subtrees {
        at_root.entry(st.node).or_default().extend(&st.keys);
    }
    // Flows are in expansion order, which is the tree's preorder.
    for (pos, nf) in df.nodes.iter().enumerate() {
        for k in at_root.get(&pos).into_iter().flatten() {
            let f = keys.entry(&k.key).or_default();
            f.read |= matches!(k.access, Access::ScriptRead | Access::ReadWrite);
            if matches!(k.access, Access::Write | Access::ReadWrite) && f.first_write.is_none() {
                f.first_write = Some((pos, pos));
            }
        }
        for (u, k) in nf.keys.iter().enumerate() {
            let f = keys.entry(&k.key).or_default();
            let reads = matches!(k.access, Access::Read | Access::ReadWrite);
            let writes = matches!(k.access, Access::Write | Access::ReadWrite);
            f.read |= reads || matches!(k.access, Access::ScriptRead | Access::Unknown);
            f.unknown |= k.access == Access::Unknown;
            if reads && f.first_read.is_none() {
                f.first_read = Some((pos, pos, u));
            }
            if writes {
                if f.first_write.is_none() {
                    f.first_write = Some((pos, pos));
                }
                if f.typed_write.is_none() && k.ty.as_deref().is_some_and(|t| strong(t).is_some()) {
                    f.typed_write = Some((pos, pos, u));
                }
            }
        }
    }
    let remapped = df
        .subtrees
        .iter()
        .flat_map(|st| st.remap.iter().filter_map(|r| r.2.as_ref()))
        .collect();
    let mut provided: HashSet<Key> = df.given.iter().cloned().collect();
    let mut exported = HashSet::new();
    for p in df.tree_ports.iter().flatten() {
        let k = Key {
            scope: 0,
            name: p.name.clone(),
        };
        if p.dir.reads() {
            provided.insert(k.clone());
        }
        if p.dir.writes() {
            exported.insert(k);
        }
    }
    Facts {
        keys,
        remapped,
        provided,
        exported,
    }
}

/// The keys of `df` in a deterministic order (scope, name).
fn sorted<'a>(f: &'a Facts) -> Vec<(&'a Key, &'a KeyFacts)> {
    let mut v: Vec<_> = f.keys.iter().map(|(k, kf)| (*k, kf)).collect();
    v.sort_by(|a, b| a.0.cmp(b.0));
    v
}

/// `{key}` as shown, with the SubTree whose blackboard holds it.
fn key_shown(df: &Dataflow, k: &Key) -> String {
    match k.scope {
        0 => format!("{{{}}}", k.name),
        s => format!(
            "{{{}}} (of SubTree `{}`)",
            k.name,
            df.scopes.get(s).map_or("?", String::as_str)
        ),
    }
}

pub const READ_BEFORE_WRITE: Rule = Rule {
    code: "read-before-write",
    level: Level::Warning,
    summary: "a blackboard entry read before any node writes it, in tick order",
    check: read_before_write,
};

fn read_before_write(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let PolicyBody::Bt(bt) = &s.policy.body else {
        return;
    };
    let f = facts(df);
    let mut found: Vec<(usize, usize, String, String)> = Vec::new();
    let mut lca: Option<Ancestry> = None;
    for (k, kf) in sorted(&f) {
        let Some((r, fi, u)) = kf.first_read else {
            continue;
        };
        // A condition checks the entry: it fails while the entry is not
        // set, BehaviorTree.CPP's idiom for "not yet" (Nav2's
        // IsGoalNearby on {path}).
        if kf.unknown || f.provided.contains(k) || bt.nodes[fi].kind == BtNodeKind::Condition {
            continue;
        }
        // A node that reads and writes the entry (Nav2's RemovePassedGoals
        // on {goals}) needs it from an earlier writer like any reader.
        let (msg, help) = match kf.first_write {
            Some((w, _)) if w < r => continue,
            // Read in an earlier branch of a Fallback (or of a control whose
            // order is not known) than the writer: the reader failing while
            // the entry is unset leads to the writer, the "check, else
            // compute" idiom (Nav2's ValidatePath on {path} before
            // ComputePathToPose). Only a Sequence runs the reader first for
            // sure.
            Some((w, _)) if w > r && !lca.get_or_insert_with(|| Ancestry::new(bt)).in_sequence(r, w) => continue,
            Some((w, wi)) if w > r => (
                format!(
                    "{} reads {} before any node writes it: the first writer, {}, comes later in tick order",
                    who(s, fi),
                    key_shown(df, k),
                    who(s, wi)
                ),
                "move the writer before the reader, or give the entry a value first (SetBlackboard, Script `key := ...`)".to_string(),
            ),
            _ => {
                // The tree's own entries may be the application's, unless
                // the tree declares its ports; an entry a SubTree remaps is
                // `subtree-remap-unprovided`'s.
                if (k.scope == 0 && df.tree_ports.is_none()) || f.remapped.contains(k) {
                    continue;
                }
                (
                    format!(
                        "{} reads {}, which no node writes before it and nothing gives",
                        who(s, fi),
                        key_shown(df, k)
                    ),
                    if k.scope == 0 {
                        "declare it as an input port of the tree in its `<TreeNodesModel>` entry, or write it first".to_string()
                    } else {
                        "a SubTree has its own blackboard: remap the port on the `<SubTree>` element (port=\"{key}\"), or use _autoremap=\"true\"".to_string()
                    },
                )
            }
        };
        found.push((fi, u, msg, help));
    }
    found.sort_by_key(|x| (x.0, x.1));
    for (fi, u, msg, help) in found {
        let nf = &df.nodes[fi];
        let (span, at) = place(df, nf.doc, &nf.keys[u].span);
        out.push(id_of(s, fi), span, format!("{msg}{at}"), help);
    }
}

/// Ancestors of a BT's nodes (numbered in preorder, as the loader makes
/// them) by binary lifting: the lowest common ancestor of two nodes in
/// O(log n) after O(n log n) work, whatever the depth.
struct Ancestry<'a> {
    bt: &'a btfsm_model::Bt,
    /// `up[j][i]`: the 2^j-th ancestor of node `i` (the root its own).
    up: Vec<Vec<usize>>,
    /// One past the last node of each node's subtree, in preorder.
    end: Vec<usize>,
}

impl<'a> Ancestry<'a> {
    fn new(bt: &'a btfsm_model::Bt) -> Ancestry<'a> {
        let n = bt.nodes.len();
        let mut parent: Vec<usize> = (0..n).collect();
        for (i, node) in bt.nodes.iter().enumerate() {
            for &c in &node.children {
                parent[c] = i;
            }
        }
        // Preorder numbering: a subtree ends where the next node after
        // its last descendant starts; computed children before parents.
        let mut end: Vec<usize> = (1..=n).collect();
        for i in (0..n).rev() {
            if let Some(&last) = bt.nodes[i].children.last() {
                end[i] = end[i].max(end[last]);
            }
        }
        let mut up = vec![parent];
        while (1usize << up.len()) < n.max(2) {
            let prev = up.last().expect("one level");
            let next: Vec<usize> = (0..n).map(|i| prev[prev[i]]).collect();
            up.push(next);
        }
        Ancestry { bt, up, end }
    }

    /// One past the last node of `a`'s subtree (`a` itself past the end:
    /// nothing).
    fn end_of(&self, a: usize) -> usize {
        self.end.get(a).copied().unwrap_or(a)
    }

    /// Does `a`'s subtree hold `b`?
    fn holds(&self, a: usize, b: usize) -> bool {
        a <= b && b < self.end[a]
    }

    /// Is the lowest common ancestor of `r` and `w` (`r` before `w`) a
    /// Sequence, which runs `r`'s branch before `w`'s whatever they return?
    fn in_sequence(&self, r: usize, w: usize) -> bool {
        let mut a = r;
        if !self.holds(a, w) {
            for level in self.up.iter().rev() {
                if !self.holds(level[a], w) {
                    a = level[a];
                }
            }
            a = self.up[0][a];
        }
        matches!(
            self.bt.nodes.get(a).map(|n| n.kind),
            Some(BtNodeKind::Sequence | BtNodeKind::SequenceMemory)
        )
    }
}

pub const KEY_NEVER_READ: Rule = Rule {
    code: "key-never-read",
    level: Level::Allow,
    summary: "a blackboard entry written and never read by the tree",
    check: key_never_read,
};

fn key_never_read(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let f = facts(df);
    // The entries read somewhere, by blackboard: a close one is what a
    // misspelt entry of the tree's own blackboard was meant to be.
    let read_root: Vec<&str> = sorted(&f)
        .into_iter()
        .filter(|(k, kf)| k.scope == 0 && kf.read)
        .map(|(k, _)| k.name.as_str())
        .collect();
    let mut found = Vec::new();
    let mut checked = 0;
    for (k, kf) in sorted(&f) {
        let Some((_, wi)) = kf.first_write else {
            continue;
        };
        if kf.read || kf.unknown || f.exported.contains(k) {
            continue;
        }
        // The tree's own blackboard is the application's too, which may
        // read what the tree writes (Nav2's navigators read the error
        // codes): reported when the tree declares its ports, or when a
        // close entry is read (a misspelling).
        let misspelt = || {
            btfsm_core::diagnostic::closest(&k.name, read_root.iter().copied()).is_some_and(|c| {
                c != k.name && btfsm_core::diagnostic::edit_distance(c, &k.name) <= 2
            })
        };
        if k.scope == 0 && df.tree_ports.is_none() {
            // Each look-up scans the entries read: bounded work.
            checked += 1;
            if checked > HINTED || !misspelt() {
                continue;
            }
        }
        found.push((wi, k));
    }
    found.sort_by_key(|x| x.0);
    for (wi, k) in found {
        let nf = &df.nodes[wi];
        let span = nf
            .keys
            .iter()
            .find(|u| u.key == *k)
            .map_or(&nf.span, |u| &u.span);
        let (span, at) = place(df, nf.doc, span);
        out.push(
            id_of(s, wi),
            span,
            format!(
                "{} writes {}, which no node of the tree reads{at}",
                who(s, wi),
                key_shown(df, k)
            ),
            if k.scope == 0 {
                "if the application reads it, declare it as an output port of the tree in its `<TreeNodesModel>` entry; else check the key's spelling".into()
            } else {
                "a SubTree has its own blackboard: remap the port on the `<SubTree>` element to pass the value out".into()
            },
        );
    }
}

/// A type BehaviorTree.CPP checks between ports, normalised; `None` for
/// the untyped, `Any` and strings (which BehaviorTree.CPP converts from).
fn strong(t: &str) -> Option<String> {
    let n: String = t.chars().filter(|c| !c.is_whitespace()).collect();
    let n = n.trim_start_matches("std::").to_string();
    let n = n.strip_prefix("BT::").unwrap_or(&n).to_string();
    if n.is_empty()
        || n == "AnyTypeAllowed"
        || n == "Any"
        || n == "string"
        || n.starts_with("__cxx11::basic_string")
        || n.starts_with("basic_string")
        || n == "string_view"
    {
        return None;
    }
    Some(match n.as_str() {
        "unsigned" => "unsignedint".into(),
        _ => n,
    })
}

pub const PORT_TYPE_MISMATCH: Rule = Rule {
    code: "port-type-mismatch",
    level: Level::Warning,
    summary: "a port reads a blackboard entry as another type than the port that writes it",
    check: port_type_mismatch,
};

fn port_type_mismatch(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let f = facts(df);
    let mut found = Vec::new();
    for nf in &df.nodes {
        for u in &nf.keys {
            if !matches!(u.access, Access::Read | Access::ReadWrite) {
                continue;
            }
            let Some(rt) = u.ty.as_deref().and_then(strong) else {
                continue;
            };
            let Some((_, wi, wu)) = f.keys.get(&u.key).and_then(|kf| kf.typed_write) else {
                continue;
            };
            let w = &df.nodes[wi].keys[wu];
            let wt = w.ty.as_deref().unwrap_or("");
            if strong(wt).is_some_and(|x| x != rt) && wi != nf.node {
                found.push((nf, u, wi, w));
            }
        }
    }
    for (nf, u, wi, w) in found {
        let (span, at) = place(df, nf.doc, &u.span);
        out.push(
            id_of(s, nf.node),
            span,
            format!(
                "`{}` of `{}` reads {} as `{}`, but {} writes it as `{}` (port `{}`){at}",
                u.port,
                nf.ty,
                key_shown(df, &u.key),
                u.ty.as_deref().unwrap_or(""),
                who(s, wi),
                w.ty.as_deref().unwrap_or(""),
                w.port
            ),
            "use one type for the entry in both models, or convert between them in a node".into(),
        );
    }
}

pub const SUBTREE_REMAP_UNPROVIDED: Rule = Rule {
    code: "subtree-remap-unprovided",
    level: Level::Warning,
    summary: "a SubTree port remapped to a blackboard entry that no node writes and nothing gives",
    check: subtree_remap_unprovided,
};

fn subtree_remap_unprovided(s: &Subject, out: &mut Sink) {
    let Some(df) = flow(s) else { return };
    let PolicyBody::Bt(bt) = &s.policy.body else {
        return;
    };
    let f = facts(df);
    // Where each entry is read (node positions, in preorder), for the
    // entries SubTrees remap: a remapping is reported only when a node of
    // that SubTree reads the entry.
    let mut readers: HashMap<&Key, Vec<usize>> = HashMap::new();
    for (pos, nf) in df.nodes.iter().enumerate() {
        for k in nf.keys.iter().filter(|k| {
            f.remapped.contains(&k.key)
                && matches!(
                    k.access,
                    Access::Read | Access::ReadWrite | Access::ScriptRead
                )
        }) {
            readers.entry(&k.key).or_default().push(pos);
        }
    }
    let mut lca: Option<Ancestry> = None;
    for st in &df.subtrees {
        for (port, value, key, aspan) in &st.remap {
            let Some(k) = key else { continue };
            let kf = f.keys.get(k);
            if kf.is_some_and(|kf| kf.first_write.is_some() || kf.unknown)
                || f.provided.contains(k)
                || (k.scope == 0 && df.tree_ports.is_none())
            {
                continue;
            }
            // A remapped entry no node of the SubTree reads is a dead
            // remapping, harmless (MoveIt Studio objectives pass
            // `{parameters}` down chains of SubTrees that do not use it).
            let end = lca.get_or_insert_with(|| Ancestry::new(bt)).end_of(st.node);
            // Readers are in preorder: the first at or after the SubTree's
            // root, by binary search.
            let read_inside = readers.get(k).is_some_and(|r| {
                let i = r.partition_point(|&p| p < st.node);
                r.get(i).is_some_and(|&p| p < end)
            });
            if !read_inside {
                continue;
            }
            let (span, at) = place(df, st.doc, aspan);
            out.push(
                id_of(s, st.node),
                span,
                format!(
                    "SubTree `{}` maps its port `{port}` to \"{value}\", but no node writes {} and nothing gives it{at}",
                    st.id,
                    key_shown(df, k)
                ),
                "write the entry before the SubTree runs, pass it down from the enclosing SubTree, or declare it as an input port of the tree".into(),
            );
        }
    }
}
