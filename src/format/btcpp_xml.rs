//! BehaviorTree.CPP XML (formats 3 and 4, as documented at behaviortree.dev and
//! used by Nav2 and Groot2) read into the BT model.
//!
//! - `<root>` holds `<BehaviorTree ID>` definitions, `<include path>` (relative to
//!   the including file; cycles rejected) and `<TreeNodesModel>`; the tree run is
//!   `--tree ID`, else `main_tree_to_execute`, else the only tree of the main file.
//! - Nodes in compact (`<Sequence>`) or explicit (`<Action ID="...">`) syntax.
//!   `<SubTree ID>` (and format 3's `<SubTreePlus>`) is expanded in place: the
//!   subtree's root takes the SubTree element's place, as TOML subtree includes
//!   do, so counts are those of the expanded tree; recursion is rejected. Its
//!   ports remap the subtree's blackboard entries, so inside the expansion a
//!   port `{key}` becomes the value or outer entry the SubTree maps `key` to
//!   (BehaviorTree.CPP 4 "Remapping ports between Trees and SubTrees").
//! - Built-in types map onto the model (see [`BUILTINS`] and the README table);
//!   other types are resolved through a `<TreeNodesModel>` (in the files read or
//!   given with `--nodes-model`), or `--assume-leaf` decides for leaves.
//! - Node identity (for `named` GED): a `btfsm:id` attribute when present (written
//!   by `btfsm convert`), else the `name` attribute when no other node of the
//!   expanded tree has that name, else the parent's identity and the child's
//!   position (`Parent/2`); the root without a name takes the tree's ID.
//!
//! The expansion walks an explicit stack (no recursion on input depth).

use super::xml::{self, XDoc, XElem, shown};
use super::{AssumeLeaf, Limits, Loaded};
use crate::diagnostic::{Diagnostic, SourceFile, suggest};
use crate::model::skill::{self, ArgValue, SkillCall, SkillKind};
use crate::model::{Bt, BtNode, BtNodeKind, Policy, PolicyBody};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a node type is, as a `<TreeNodesModel>` says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Category {
    Action,
    Condition,
    Control,
    Decorator,
}

impl Category {
    pub fn tag(self) -> &'static str {
        match self {
            Category::Action => "Action",
            Category::Condition => "Condition",
            Category::Control => "Control",
            Category::Decorator => "Decorator",
        }
    }
}

/// BehaviorTree.CPP's built-in node types (formats 3 and 4) and their category.
/// How each maps onto the model is [`builtin_kind`].
pub const BUILTINS: &[(&str, Category)] = &[
    ("Sequence", Category::Control),
    ("ReactiveSequence", Category::Control),
    ("SequenceWithMemory", Category::Control),
    ("SequenceStar", Category::Control),
    ("AsyncSequence", Category::Control),
    ("Fallback", Category::Control),
    ("ReactiveFallback", Category::Control),
    ("AsyncFallback", Category::Control),
    ("Parallel", Category::Control),
    ("ParallelAll", Category::Control),
    ("IfThenElse", Category::Control),
    ("WhileDoElse", Category::Control),
    ("Switch2", Category::Control),
    ("Switch3", Category::Control),
    ("Switch4", Category::Control),
    ("Switch5", Category::Control),
    ("Switch6", Category::Control),
    ("ManualSelector", Category::Control),
    ("TryCatch", Category::Control),
    ("Inverter", Category::Decorator),
    ("ForceSuccess", Category::Decorator),
    ("ForceFailure", Category::Decorator),
    ("RetryUntilSuccessful", Category::Decorator),
    ("RetryUntilSuccesful", Category::Decorator),
    ("Repeat", Category::Decorator),
    ("Timeout", Category::Decorator),
    ("Delay", Category::Decorator),
    ("KeepRunningUntilFailure", Category::Decorator),
    ("RunOnce", Category::Decorator),
    ("Precondition", Category::Decorator),
    ("LoopInt", Category::Decorator),
    ("LoopDouble", Category::Decorator),
    ("LoopString", Category::Decorator),
    ("LoopBool", Category::Decorator),
    ("EntryUpdated", Category::Decorator),
    ("SkipUnlessUpdated", Category::Decorator),
    ("WaitValueUpdate", Category::Decorator),
    ("BlackboardCheckInt", Category::Decorator),
    ("BlackboardCheckDouble", Category::Decorator),
    ("BlackboardCheckString", Category::Decorator),
    ("BlackboardCheckBool", Category::Decorator),
    ("AlwaysSuccess", Category::Action),
    ("AlwaysFailure", Category::Action),
    ("Script", Category::Action),
    ("SetBlackboard", Category::Action),
    ("UnsetBlackboard", Category::Action),
    ("Sleep", Category::Action),
    ("ScriptCondition", Category::Condition),
    ("WasEntryUpdated", Category::Action),
];

/// The category of a built-in type.
pub fn builtin(name: &str) -> Option<Category> {
    BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, c)| *c)
}

/// The model kind of a built-in type with `n` children, the attributes that the
/// kind carries (not kept as ports), and whether the type name must be kept
/// (it is not the one [`canonical_type`] gives the kind).
pub fn builtin_kind(
    name: &str,
    e: &XElem,
    n: usize,
) -> (BtNodeKind, &'static [&'static str], bool) {
    let int = |a: &str| e.attr(a).and_then(|v| v.trim().parse::<i64>().ok());
    match name {
        "Sequence" => (BtNodeKind::SequenceMemory, &[], false),
        "ReactiveSequence" => (BtNodeKind::Sequence, &[], false),
        "SequenceWithMemory" | "SequenceStar" | "AsyncSequence" => {
            (BtNodeKind::SequenceMemory, &[], true)
        }
        "Fallback" => (BtNodeKind::FallbackMemory, &[], false),
        "ReactiveFallback" => (BtNodeKind::Fallback, &[], false),
        "AsyncFallback" => (BtNodeKind::FallbackMemory, &[], true),
        "Parallel" => {
            // Format 4: success_count (negative: counted from the number of
            // children, -1 = all); format 3: success_threshold / threshold.
            let (attr, v) = ["success_count", "success_threshold", "threshold"]
                .iter()
                .find_map(|a| e.attr(a).map(|_| (*a, int(a))))
                .unwrap_or(("", Some(-1)));
            match v {
                Some(c) => {
                    let nn = n as i64;
                    let s = if c < 0 { nn + c + 1 } else { c };
                    let success = s.clamp(1, nn.max(1)) as usize;
                    let keep = attr != "success_count";
                    let consumed: &'static [&'static str] = match attr {
                        "success_count" => &["success_count"],
                        "success_threshold" => &["success_threshold"],
                        "threshold" => &["threshold"],
                        _ => &[],
                    };
                    (BtNodeKind::Parallel { success }, consumed, keep)
                }
                None => (BtNodeKind::Control, &[], true),
            }
        }
        "ParallelAll" => (BtNodeKind::Parallel { success: n.max(1) }, &[], true),
        "Inverter" => (BtNodeKind::Inverter, &[], false),
        "ForceSuccess" => (BtNodeKind::ForceSuccess, &[], false),
        "ForceFailure" => (BtNodeKind::ForceFailure, &[], false),
        "RetryUntilSuccessful" | "RetryUntilSuccesful" => match int("num_attempts") {
            Some(t) if t >= 0 => (
                BtNodeKind::Retry {
                    times: t.min(u32::MAX as i64) as u32,
                },
                &["num_attempts"],
                name != "RetryUntilSuccessful",
            ),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        "Repeat" => match int("num_cycles") {
            Some(t) if t >= 0 => (
                BtNodeKind::Repeat {
                    times: Some(t.min(u32::MAX as i64) as u32),
                },
                &["num_cycles"],
                false,
            ),
            Some(-1) => (BtNodeKind::Repeat { times: None }, &["num_cycles"], false),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        "Timeout" => match int("msec") {
            Some(ms) if ms >= 0 => (BtNodeKind::Timeout { ms: ms as u64 }, &["msec"], false),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        _ => match builtin(name) {
            Some(Category::Control) => (BtNodeKind::Control, &[], true),
            Some(Category::Decorator) => (BtNodeKind::Decorator, &[], true),
            Some(Category::Condition) => (BtNodeKind::Condition, &[], true),
            _ => (BtNodeKind::Action, &[], true),
        },
    }
}

/// The BehaviorTree.CPP type written for a model kind that carries no type name.
pub fn canonical_type(kind: BtNodeKind) -> Option<&'static str> {
    Some(match kind {
        BtNodeKind::Sequence => "ReactiveSequence",
        BtNodeKind::Fallback => "ReactiveFallback",
        BtNodeKind::SequenceMemory => "Sequence",
        BtNodeKind::FallbackMemory => "Fallback",
        BtNodeKind::Parallel { .. } => "Parallel",
        BtNodeKind::Inverter => "Inverter",
        BtNodeKind::ForceSuccess => "ForceSuccess",
        BtNodeKind::ForceFailure => "ForceFailure",
        BtNodeKind::Repeat { .. } => "Repeat",
        BtNodeKind::Retry { .. } => "RetryUntilSuccessful",
        BtNodeKind::Timeout { .. } => "Timeout",
        _ => return None,
    })
}

/// Reads a BehaviorTree.CPP XML file (with its includes).
pub fn load_file(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = super::toml::read_source(path, &shown, limits)?;
    load_read(file, path, limits)
}

/// Reads BehaviorTree.CPP XML already read from `path` (includes resolve
/// beside it).
pub fn load_read(
    file: Arc<SourceFile>,
    path: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    load(file, super::toml::canonical(path), base, limits)
}

/// Reads BehaviorTree.CPP XML from text; includes resolve against `base`.
pub fn parse_str(
    name: &str,
    text: &str,
    base: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let file = SourceFile::new(name, text);
    load(file, PathBuf::from(name), base.to_path_buf(), limits)
}

/// A type declared in a `<TreeNodesModel>`.
#[derive(Debug, Clone)]
struct ModelEntry {
    cat: Category,
}

struct Loader<'l> {
    limits: &'l Limits,
    diags: xml::Sink,
    docs: Vec<XDoc>,
    dirs: Vec<PathBuf>,
    /// Tree ID -> (document, `<BehaviorTree>` element).
    trees: BTreeMap<String, (usize, usize)>,
    models: BTreeMap<String, ModelEntry>,
    /// The directory every included file must be in (`None`: anywhere).
    root: Option<PathBuf>,
    /// What remains of `--max-nodes` for the elements of the files still to
    /// read: every element of every file counts, used or not.
    elems_left: usize,
    /// Unknown node types already reported: each is an error once, at its
    /// first use, however often it is used.
    unknown: std::collections::HashSet<String>,
}

fn load(
    file: Arc<SourceFile>,
    identity: PathBuf,
    base: PathBuf,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    // BehaviorTree.CPP reads with tinyxml2, which is lenient: so is this
    // reader, with a warning at each place (`xml_lenient`).
    let (main, repaired) =
        xml::parse_lenient(&file, limits.max_nodes, limits.max_nodes).map_err(|d| vec![d])?;
    let elems_left = limits.max_nodes - main.elems.len();
    let root = super::source::root_for(limits, &base);
    let mut l = Loader {
        root,
        elems_left,
        limits,
        diags: xml::Sink::default(),
        docs: vec![main],
        dirs: vec![base],
        trees: BTreeMap::new(),
        models: BTreeMap::new(),
        unknown: Default::default(),
    };
    l.diags.extend(repaired);
    let policy = l.run(identity);
    super::finish(&file, policy, l.diags.into_vec(&file), "behavior tree")
}

impl Loader<'_> {
    fn err(&mut self, d: usize, span: Range<usize>, msg: impl Into<String>) -> &mut Diagnostic {
        let f = self.docs[d].file.clone();
        self.diags.push(Diagnostic::error(msg).at(&f, span))
    }

    /// Parses a file read for this policy, charging its elements to the
    /// shared element budget.
    fn parse_charged(&mut self, file: &Arc<SourceFile>) -> Result<XDoc, Diagnostic> {
        let (doc, repaired) = xml::parse_lenient(file, self.elems_left, self.limits.max_nodes)?;
        self.diags.extend(repaired);
        self.elems_left -= doc.elems.len();
        Ok(doc)
    }

    /// Are hints still worth computing? Past the messages shown
    /// (`finish` keeps the first ones), no did-you-mean search is done.
    fn hinting(&self) -> bool {
        self.diags.room_for_errors()
    }

    fn warn(&mut self, d: usize, span: Range<usize>, msg: impl Into<String>) -> &mut Diagnostic {
        let f = self.docs[d].file.clone();
        self.diags.push(Diagnostic::warning(msg).at(&f, span))
    }

    fn run(&mut self, identity: PathBuf) -> Option<Policy> {
        let root = self.docs[0].root;
        if self.docs[0].elems[root].name != "root" {
            let span = self.docs[0].elems[root].span.clone();
            let found = self.docs[0].elems[root].name.clone();
            self.err(
                0,
                span,
                format!(
                    "expected `<root>` as the document element, found `<{}>`",
                    shown(&found)
                ),
            )
            .hint = Some(
                "a BehaviorTree.CPP file is `<root BTCPP_format=\"4\"><BehaviorTree ID=\"...\">...</BehaviorTree></root>`"
                    .into(),
            );
            return None;
        }
        self.includes(identity);
        let extra = self.limits.nodes_models.clone();
        for m in &extra {
            self.nodes_model_file(m);
        }
        for d in 0..self.docs.len() {
            self.definitions(d);
        }
        if self.diags.has_errors() {
            return None;
        }
        let (tree_id, (d, e)) = self.main_tree()?;
        let bt = self.expand(&tree_id, d, e)?;
        Some(Policy {
            name: tree_id,
            description: None,
            body: PolicyBody::Bt(bt),
        })
    }

    /// Loads `<include path>` files depth-first with an explicit stack; a file
    /// including one of its includers is a cycle.
    fn includes(&mut self, identity: PathBuf) {
        let mut chain: Vec<PathBuf> = vec![identity];
        // The same chain as the user sees the paths (canonical ones differ by machine).
        let mut shown_chain: Vec<String> = vec![self.docs[0].file.path.clone()];
        let mut loaded: HashSet<PathBuf> = chain.iter().cloned().collect();
        let mut work: Vec<(usize, usize)> = vec![(0, 0)];
        while let Some(&mut (d, ref mut pos)) = work.last_mut() {
            let root = self.docs[d].root;
            let kids = &self.docs[d].elems[root].children;
            if *pos >= kids.len() {
                work.pop();
                chain.pop();
                shown_chain.pop();
                continue;
            }
            let e = kids[*pos];
            *pos += 1;
            let el = self.docs[d].elems[e].clone();
            if el.name != "include" {
                continue;
            }
            if el.attr("ros_pkg").is_some() {
                self.err(
                    d,
                    el.span.clone(),
                    "includes from ROS packages (`ros_pkg`) are not supported",
                )
                .hint = Some("give `path` relative to this file".into());
                continue;
            }
            let Some(p) = el.attr_full("path") else {
                self.err(d, el.span.clone(), "`<include>` needs a `path`")
                    .hint = Some("write `<include path=\"subtrees/other.xml\"/>`".into());
                continue;
            };
            let (pval, pspan) = (p.value.clone(), p.span.clone());
            let full = match super::source::resolve(self.root.as_deref(), &self.dirs[d], &pval) {
                Ok(p) => p,
                Err(r) => {
                    self.err(d, pspan, format!("cannot include this file: {}", r.message))
                        .hint = Some(r.hint);
                    continue;
                }
            };
            let canon = super::toml::canonical(&full);
            if let Some(at) = chain.iter().position(|c| *c == canon) {
                let mut names: Vec<String> = shown_chain[at..]
                    .iter()
                    .map(|n| shown(n).into_owned())
                    .collect();
                names.push(shown(&full.display().to_string()).into_owned());
                self.err(d, pspan, format!("cyclic include: {}", names.join(" -> ")))
                    .hint =
                    Some("a file must not include itself, directly or through others".into());
                continue;
            }
            if loaded.contains(&canon) {
                continue; // already read through another include
            }
            if chain.len() > self.limits.max_include_depth {
                self.err(
                    d,
                    pspan,
                    format!(
                        "includes nested deeper than {}",
                        self.limits.max_include_depth
                    ),
                );
                continue;
            }
            let shown = full.display().to_string();
            let file = match super::toml::read_included(&full, &shown, self.limits) {
                Ok(f) => f,
                Err(mut ds) => {
                    let msg = ds.remove(0).message;
                    self.err(d, pspan, msg).hint =
                        Some("`path` is relative to the including file".into());
                    continue;
                }
            };
            let doc = match self.parse_charged(&file) {
                Ok(doc) => doc,
                Err(diag) => {
                    self.diags.push(diag);
                    continue;
                }
            };
            if doc.elems[doc.root].name != "root" {
                let span = doc.elems[doc.root].span.clone();
                self.docs.push(doc);
                let nd = self.docs.len() - 1;
                self.err(
                    nd,
                    span,
                    "expected `<root>` as the document element of an included file",
                );
                self.docs.pop();
                continue;
            }
            loaded.insert(canon.clone());
            self.docs.push(doc);
            self.dirs
                .push(full.parent().unwrap_or(Path::new("")).to_path_buf());
            chain.push(canon);
            shown_chain.push(shown);
            work.push((self.docs.len() - 1, 0));
        }
    }

    /// Reads a `--nodes-model` file: a `<root>` holding a `<TreeNodesModel>`, or a
    /// bare `<TreeNodesModel>`.
    fn nodes_model_file(&mut self, path: &Path) {
        let shown = path.display().to_string();
        let file = match super::toml::read_source(path, &shown, self.limits) {
            Ok(f) => f,
            Err(ds) => {
                self.diags.extend(ds);
                return;
            }
        };
        let doc = match self.parse_charged(&file) {
            Ok(doc) => doc,
            Err(d) => {
                self.diags.push(d);
                return;
            }
        };
        let root = doc.root;
        let models: Vec<usize> = if doc.elems[root].name == "TreeNodesModel" {
            vec![root]
        } else {
            doc.children(root)
                .filter(|(_, e)| e.name == "TreeNodesModel")
                .map(|(i, _)| i)
                .collect()
        };
        self.docs.push(doc);
        let d = self.docs.len() - 1;
        self.dirs.push(PathBuf::new());
        if models.is_empty() {
            self.err(d, self.docs[d].elems[root].span.clone(), "no `<TreeNodesModel>` in this file")
                .hint = Some("a nodes model is `<root><TreeNodesModel><Action ID=\"...\"/>...</TreeNodesModel></root>`".into());
        }
        for m in models {
            self.read_model(d, m);
        }
    }

    fn read_model(&mut self, d: usize, m: usize) {
        let kids = self.docs[d].elems[m].children.clone();
        for k in kids {
            let el = self.docs[d].elems[k].clone();
            let cat = match el.name.as_str() {
                "Action" => Category::Action,
                "Condition" => Category::Condition,
                "Control" => Category::Control,
                "Decorator" => Category::Decorator,
                "SubTree" => continue,
                other => {
                    let h = suggest(
                        other,
                        ["Action", "Condition", "Control", "Decorator", "SubTree"],
                    );
                    self.err(
                        d,
                        el.span.clone(),
                        format!("unknown entry `<{}>` in `<TreeNodesModel>`", shown(other)),
                    )
                    .hint = Some(h);
                    continue;
                }
            };
            let Some(id) = el.attr("ID") else {
                self.err(
                    d,
                    el.span.clone(),
                    format!(
                        "`<{}>` in `<TreeNodesModel>` needs an `ID`",
                        shown(&el.name)
                    ),
                );
                continue;
            };
            if self.too_long(d, &el, "node type", id) {
                continue;
            }
            if let Some(b) = builtin(id)
                && b != cat
            {
                self.warn(
                    d,
                    el.span.clone(),
                    format!(
                        "`{}` is a built-in {} type; the model's `{}` is ignored",
                        shown(id),
                        b.tag().to_lowercase(),
                        cat.tag()
                    ),
                );
                continue;
            }
            if let Some(prev) = self.models.get(id)
                && prev.cat != cat
            {
                let was = prev.cat.tag();
                self.err(
                    d,
                    el.span.clone(),
                    format!(
                        "`{}` is declared both as `{was}` and as `{}`",
                        shown(id),
                        cat.tag()
                    ),
                )
                .hint = Some("keep one declaration per node type across the model files".into());
                continue;
            }
            self.models.insert(id.to_string(), ModelEntry { cat });
        }
    }

    /// Collects `<BehaviorTree>` definitions and `<TreeNodesModel>` entries.
    fn definitions(&mut self, d: usize) {
        let root = self.docs[d].root;
        if self.docs[d].elems[root].name != "root" {
            return; // a bare nodes-model file
        }
        if let Some(v) = self.docs[d].elems[root].attr_full("BTCPP_format")
            && v.value != "3"
            && v.value != "4"
        {
            let span = v.span.clone();
            let val = v.value.clone();
            self.warn(
                d,
                span,
                format!(
                    "unknown `BTCPP_format` \"{}\"; read as format 4",
                    shown(&val)
                ),
            )
            .hint = Some("BehaviorTree.CPP writes `BTCPP_format=\"4\"` (or \"3\")".into());
        }
        let kids = self.docs[d].elems[root].children.clone();
        for k in kids {
            let el = self.docs[d].elems[k].clone();
            match el.name.as_str() {
                "BehaviorTree" => {
                    let id = el.attr("ID").unwrap_or("MainTree").to_string();
                    if self.too_long(d, &el, "tree ID", &id) {
                        continue;
                    }
                    if let Some(&(pd, pe)) = self.trees.get(&id) {
                        let (l, c) = {
                            let f = &self.docs[pd].file;
                            f.line_col(self.docs[pd].elems[pe].span.start)
                        };
                        let first = format!("{}:{l}:{c}", self.docs[pd].file.path);
                        self.err(
                            d,
                            el.span.clone(),
                            format!("tree `{}` is defined twice", shown(&id)),
                        )
                        .hint = Some(format!(
                            "the first definition is at {first}; give each `<BehaviorTree>` its own `ID`"
                        ));
                        continue;
                    }
                    let n = el.children.len();
                    if n != 1 {
                        self.err(
                            d,
                            el.span.clone(),
                            format!(
                                "tree `{}` must hold exactly one root node, found {n}",
                                shown(&id)
                            ),
                        )
                        .hint = Some("wrap several nodes in a `<Sequence>` or `<Fallback>`".into());
                        continue;
                    }
                    self.trees.insert(id, (d, k));
                }
                "TreeNodesModel" => self.read_model(d, k),
                "include" => {}
                other => {
                    let h = suggest(other, ["BehaviorTree", "TreeNodesModel", "include"]);
                    self.warn(
                        d,
                        el.span.clone(),
                        format!("`<{}>` under `<root>` is ignored", shown(other)),
                    )
                    .hint = Some(h);
                }
            }
        }
    }

    /// The tree to run: `--tree ID`, else `main_tree_to_execute`, else the
    /// only tree of the main file.
    fn main_tree(&mut self) -> Option<(String, (usize, usize))> {
        let root = self.docs[0].root;
        let all: Vec<String> = self.trees.keys().cloned().collect();
        if let Some(id) = self.limits.tree.clone() {
            return match self.trees.get(&id) {
                Some(&t) => Some((id, t)),
                None => {
                    let span = self.docs[0].elems[root].span.clone();
                    let h = suggest(&id, all.iter().map(String::as_str));
                    self.err(
                        0,
                        span,
                        format!(
                            "--tree `{}`: no `<BehaviorTree ID>` of that name",
                            shown(&id)
                        ),
                    )
                    .hint = Some(h);
                    None
                }
            };
        }
        if let Some(a) = self.docs[0].elems[root].attr_full("main_tree_to_execute") {
            let (v, span) = (a.value.clone(), a.span.clone());
            return match self.trees.get(&v) {
                Some(&t) => Some((v, t)),
                None => {
                    let h = suggest(&v, all.iter().map(String::as_str));
                    self.err(
                        0,
                        span,
                        format!("`main_tree_to_execute` names unknown tree `{}`", shown(&v)),
                    )
                    .hint = Some(h);
                    None
                }
            };
        }
        let local: Vec<(&String, &(usize, usize))> =
            self.trees.iter().filter(|(_, (d, _))| *d == 0).collect();
        match local.as_slice() {
            [(id, t)] => Some(((*id).clone(), **t)),
            [] if self.trees.len() == 1 => {
                let (id, t) = self.trees.iter().next().expect("one tree");
                Some((id.clone(), *t))
            }
            [] => {
                let span = self.docs[0].elems[root].span.clone();
                self.err(0, span, "no `<BehaviorTree>` in this file").hint = Some(
                    "add `<BehaviorTree ID=\"Main\">...</BehaviorTree>` under `<root>`".into(),
                );
                None
            }
            many => {
                let mut ids: Vec<String> = many
                    .iter()
                    .take(10)
                    .map(|(id, _)| format!("`{}`", shown(id)))
                    .collect();
                if many.len() > 10 {
                    ids.push(format!("... ({} more)", many.len() - 10));
                }
                let span = self.docs[0].elems[root].span.clone();
                self.err(
                    0,
                    span,
                    format!("{} trees and no `main_tree_to_execute`", many.len()),
                )
                .hint = Some(format!(
                    "choose one with --tree ID, or add `main_tree_to_execute`: {}",
                    ids.join(", ")
                ));
                None
            }
        }
    }

    /// Is `value` (a name, type, ID or attribute of element `el` of document
    /// `d`) longer than `--max-name-bytes`? Then an error at the element.
    fn too_long(&mut self, d: usize, el: &XElem, what: &str, value: &str) -> bool {
        if value.len() <= self.limits.max_name_bytes {
            return false;
        }
        let max = self.limits.max_name_bytes;
        self.err(
            d,
            el.span.clone(),
            format!(
                "{what} `{}` of `<{}>` is {} bytes long, more than the limit of {max} bytes",
                shown(value),
                shown(&el.name),
                value.len()
            ),
        )
        .hint = Some("shorten it, or raise the limit with --max-name-bytes".into());
        true
    }

    /// Checks every name an element carries against `--max-name-bytes`: its
    /// tag, and the name and value of each attribute (ports, IDs, names).
    fn names_too_long(&mut self, d: usize, el: &XElem) -> bool {
        if self.too_long(d, el, "element name", &el.name) {
            return true;
        }
        for a in &el.attrs {
            if self.too_long(d, el, "attribute name", &a.name)
                || self.too_long(d, el, &format!("value of `{}`", shown(&a.name)), &a.value)
            {
                return true;
            }
        }
        false
    }

    /// Expands the tree from its root element into the arena (pre-order, explicit
    /// stack), resolving every node's type and expanding SubTrees. Depth and
    /// name lengths are checked here, at the element, as it is read.
    fn expand(&mut self, tree_id: &str, d0: usize, e0: usize) -> Option<Bt> {
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
        }
        let mut frames: Vec<Frame> = vec![Frame {
            id: tree_id.to_string(),
            parent: None,
            remap: BTreeMap::new(),
            autoremap: false,
        }];
        // The expansions enclosing the element being read: recursion and
        // port remapping are looked up in O(1) per SubTree and port.
        let mut chain = Chain::default();
        chain.push(&frames, 0);
        let root_el = self.docs[d0].elems[e0].children[0];
        let mut stack = vec![Item {
            d: d0,
            e: root_el,
            parent: None,
            depth: 0,
            frame: 0,
            name_override: None,
        }];
        let mut nodes: Vec<BtNode> = Vec::new();
        let mut names: Vec<Option<String>> = Vec::new();
        let mut explicit: Vec<Option<String>> = Vec::new();
        let mut failed = false;
        let mut budget = self.limits.max_nodes;
        // SubTree elements are no nodes, but expanding one is work: at most
        // as many expansions as nodes.
        let mut expansions = self.limits.max_nodes;
        while let Some(it) = stack.pop() {
            chain.enter(&frames, it.frame);
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
                let Some(id) = el.attr("ID").map(str::to_string) else {
                    self.err(it.d, el.span.clone(), "`<SubTree>` needs an `ID`");
                    failed = true;
                    continue;
                };
                let Some(&(sd, se)) = self.trees.get(&id) else {
                    let h = if self.hinting() {
                        suggest(&id, self.trees.keys().map(String::as_str))
                    } else {
                        String::new()
                    };
                    self.err(
                        it.d,
                        el.span.clone(),
                        format!("unknown tree `{}` in `<SubTree>`", shown(&id)),
                    )
                    .hint = Some(h);
                    failed = true;
                    continue;
                };
                if chain.trees.get(&id).is_some_and(|&c| c > 0) {
                    let chain: Vec<String> =
                        chain.frames.iter().map(|&f| frames[f].id.clone()).collect();
                    let at = chain.iter().position(|c| *c == id).unwrap_or(0);
                    let mut shown_chain: Vec<String> =
                        chain.iter().map(|c| shown(c).into_owned()).collect();
                    shown_chain.push(shown(&id).into_owned());
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
                    self.err(it.d, el.span.clone(), format!("recursive subtree: {}", cycle.join(" -> ")))
                        .hint = Some("a tree must not contain itself as a `<SubTree>`, directly or through others".into());
                    failed = true;
                    continue;
                }
                if expansions == 0 {
                    self.err(
                        it.d,
                        el.span.clone(),
                        format!("more than {} SubTree expansions", self.limits.max_nodes),
                    )
                    .hint = Some("raise the limit with --max-nodes".into());
                    return None;
                }
                expansions -= 1;
                // Its ports remap the subtree's blackboard entries: a
                // reference is resolved in the enclosing expansion now, so
                // that the subtree's nodes get the value or the outer entry.
                let remap = el
                    .attrs
                    .iter()
                    .filter(|a| a.ns.is_none() && !SUBTREE_ATTRS.contains(&a.name.as_str()))
                    .map(|a| {
                        let v = if a.value == "{=}" {
                            format!("{{{}}}", a.name)
                        } else {
                            a.value.clone()
                        };
                        (a.name.clone(), chain.resolve(&frames, &v))
                    })
                    .collect();
                let autoremap = ["_autoremap", "__autoremap", "__shared_blackboard"]
                    .iter()
                    .any(|k| el.attr(k) == Some("true") || el.attr(k) == Some("1"));
                frames.push(Frame {
                    id,
                    parent: Some(it.frame),
                    remap,
                    autoremap,
                });
                let child = self.docs[sd].elems[se].children[0];
                stack.push(Item {
                    d: sd,
                    e: child,
                    parent: it.parent,
                    depth: it.depth,
                    frame: frames.len() - 1,
                    name_override: el.attr("name").map(str::to_string).or(it.name_override),
                });
                continue;
            }
            if budget == 0 {
                self.err(
                    it.d,
                    el.span.clone(),
                    format!("more than {} nodes", self.limits.max_nodes),
                )
                .hint = Some("raise the limit with --max-nodes".into());
                return None;
            }
            budget -= 1;
            let Some(node) = self.node(it.d, &el, |v| chain.resolve(&frames, v)) else {
                failed = true;
                continue;
            };
            let idx = nodes.len();
            if let Some(p) = it.parent {
                nodes[p].children.push(idx);
            }
            names.push(
                it.name_override
                    .or_else(|| el.attr("name").map(str::to_string)),
            );
            explicit.push(el.btfsm_attr("id").map(str::to_string));
            nodes.push(node);
            for &c in el.children.iter().rev() {
                stack.push(Item {
                    d: it.d,
                    e: c,
                    parent: Some(idx),
                    depth: it.depth + 1,
                    frame: it.frame,
                    name_override: None,
                });
            }
        }
        if failed || nodes.is_empty() {
            return None;
        }
        let children: Vec<Vec<usize>> = nodes.iter().map(|n| n.children.clone()).collect();
        let (ids, _) = derive_ids(&children, 0, tree_id, &names, |i, _| explicit[i].clone());
        for (n, id) in nodes.iter_mut().zip(ids) {
            n.id = id;
        }
        Some(Bt { nodes, root: 0 })
    }

    /// One node: its kind, label, type name and ports; arity is checked here
    /// on the element (a SubTree child counts as one).
    fn node(&mut self, d: usize, el: &XElem, resolve: impl Fn(&str) -> String) -> Option<BtNode> {
        let tag = el.name.as_str();
        let n = el.children.len();
        let (mut ty, explicit_cat): (String, Option<Category>) = match tag {
            "Action" | "Condition" | "Control" | "Decorator" => {
                let cat = match tag {
                    "Action" => Category::Action,
                    "Condition" => Category::Condition,
                    "Control" => Category::Control,
                    _ => Category::Decorator,
                };
                match el.attr("ID") {
                    Some(id) => (id.to_string(), Some(cat)),
                    None => {
                        self.err(
                            d,
                            el.span.clone(),
                            format!("`<{tag}>` needs an `ID` naming its type"),
                        )
                        .hint = Some(format!(
                            "write `<{tag} ID=\"MyNode\"/>`, or the compact `<MyNode/>`"
                        ));
                        return None;
                    }
                }
            }
            _ => (tag.to_string(), None),
        };
        let mut type_kept = true;
        let mut consumed: &[&str] = &[];
        let (kind, cat) = if let Some(cat) = builtin(&ty) {
            let (k, c, keep) = builtin_kind(&ty, el, n);
            consumed = c;
            type_kept = keep;
            (k, cat)
        } else if let Some(cat) = explicit_cat {
            (generic(cat), cat)
        } else if let Some(m) = self.models.get(&ty) {
            (generic(m.cat), m.cat)
        } else if let Some((real, cat)) = BUILTINS.iter().find(|(b, _)| b.eq_ignore_ascii_case(&ty))
        {
            self.warn(
                d,
                el.span.clone(),
                format!(
                    "`{}` is not a BehaviorTree.CPP node type; read as the built-in `{real}`",
                    shown(&ty)
                ),
            )
            .hint = Some(format!(
                "node types are case-sensitive: write `<{real}>` (BehaviorTree.CPP itself rejects `<{}>`)",
                shown(&ty)
            ));
            let (k, c, keep) = builtin_kind(real, el, n);
            consumed = c;
            type_kept = keep;
            ty = real.to_string();
            (k, *cat)
        } else if let (Some(a), 0) = (self.limits.assume_leaf, n) {
            match a {
                AssumeLeaf::Action => (BtNodeKind::Action, Category::Action),
                AssumeLeaf::Condition => (BtNodeKind::Condition, Category::Condition),
            }
        } else if !self.unknown.insert(ty.clone()) {
            // Reported at its first use already.
            match n {
                0 => return None,
                1 => (BtNodeKind::Decorator, Category::Decorator),
                _ => (BtNodeKind::Control, Category::Control),
            }
        } else {
            // Hints only for messages that will be shown (the rest are
            // counted): bounded work under a million unknown types.
            let did = if self.hinting() {
                let cands = BUILTINS
                    .iter()
                    .map(|(b, _)| *b)
                    .chain(self.models.keys().map(String::as_str));
                suggest(&ty, cands)
            } else {
                String::new()
            };
            let ty = shown(&ty);
            let remedy = if n == 0 {
                format!(
                    "declare it as `<Action ID=\"{ty}\"/>` or `<Condition ID=\"{ty}\"/>` in a `<TreeNodesModel>` (in this file or with --nodes-model FILE), or read unknown leaves with --assume-leaf action|condition"
                )
            } else {
                format!(
                    "declare it as `<Control ID=\"{ty}\"/>` or `<Decorator ID=\"{ty}\"/>` in a `<TreeNodesModel>` (in this file or with --nodes-model FILE)"
                )
            };
            let hint = if did.starts_with("did you mean") {
                format!("{did} or {remedy}")
            } else {
                remedy
            };
            self.err(
                d,
                el.span.clone(),
                format!(
                    "unknown node type `{ty}` ({n} child{})",
                    if n == 1 { "" } else { "ren" }
                ),
            )
            .hint = Some(hint);
            // A node with children is read on as a placeholder of its
            // shape, so that the unknown types below it are reported in the
            // same run (the file fails with these errors anyway); a leaf has
            // nothing below it and costs nothing more.
            match n {
                0 => return None,
                1 => (BtNodeKind::Decorator, Category::Decorator),
                _ => (BtNodeKind::Control, Category::Control),
            }
        };
        // Arity of the element (a SubTree child is one node).
        let bad = match cat {
            Category::Action | Category::Condition => n != 0,
            Category::Decorator => n != 1,
            Category::Control => n == 0,
        };
        if bad {
            let want = match cat {
                Category::Action | Category::Condition => "no children",
                Category::Decorator => "exactly one child",
                Category::Control => "at least one child",
            };
            self.err(
                d,
                el.span.clone(),
                format!(
                    "`{}` is a {} and takes {want}, found {n}",
                    shown(&ty),
                    cat.tag().to_lowercase()
                ),
            )
            .hint = Some(match cat {
                Category::Decorator => "wrap several children in a `<Sequence>`".into(),
                Category::Control => "give it children, or use a leaf".into(),
                _ => "a leaf has no children; is the type right in the `<TreeNodesModel>`?".into(),
            });
            return None;
        }
        let mut ports: BTreeMap<String, String> = el
            .attrs
            .iter()
            .filter(|a| {
                a.ns.is_none()
                    && a.name != "name"
                    && a.name != "ID"
                    && !consumed.contains(&a.name.as_str())
            })
            .map(|a| (a.name.clone(), resolve(&a.value)))
            .collect();
        // BehaviorTree.CPP 4's Parallel fails at its first failure unless
        // told otherwise; the model's Parallel without `failure_count` is the
        // paper's, which fails when it can no longer succeed
        // (docs/bt-semantics.md).
        if matches!(kind, BtNodeKind::Parallel { .. })
            && ty == "Parallel"
            && el.attr("success_threshold").is_none()
            && el.attr("threshold").is_none()
        {
            ports
                .entry("failure_count".into())
                .or_insert_with(|| "1".into());
        }
        // A leaf whose type is a skill of the shared library, with arguments
        // that fit the skill, is bound to it.
        let mut skill_call = None;
        if let (BtNodeKind::Action | BtNodeKind::Condition, Some(sk), Some(params)) =
            (kind, skill::skill_kind(&ty), skill::skill_params(&ty))
        {
            let want = if kind == BtNodeKind::Action {
                SkillKind::Action
            } else {
                SkillKind::Condition
            };
            let fits = sk == want
                && ports.keys().all(|k| params.iter().any(|(p, _)| p == k))
                && params.iter().all(|(p, req)| !req || ports.contains_key(*p));
            if fits {
                skill_call = Some(SkillCall {
                    skill: ty.clone(),
                    args: std::mem::take(&mut ports)
                        .into_iter()
                        .map(|(k, v)| (k, arg_value(&v)))
                        .collect(),
                });
                type_kept = false;
            }
        }
        let label = el
            .attr("name")
            .map(str::to_string)
            .unwrap_or_else(|| ty.clone());
        Some(BtNode {
            id: String::new(),
            label,
            kind,
            children: Vec::new(),
            skill: skill_call,
            type_name: type_kept.then(|| ty.clone()),
            ports,
            span: Some(el.span.clone()),
        })
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
struct Frame {
    id: String,
    parent: Option<usize>,
    remap: BTreeMap<String, String>,
    /// Entries not remapped are shared with the enclosing tree by name
    /// (`_autoremap="true"`, format 3's `__shared_blackboard`).
    autoremap: bool,
}

/// The entry a port value refers to: `key` of a whole `{key}`.
fn port_key(value: &str) -> Option<&str> {
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
struct Chain {
    frames: Vec<usize>,
    trees: HashMap<String, usize>,
    barriers: Vec<usize>,
    by_key: HashMap<String, Vec<usize>>,
}

impl Chain {
    fn push(&mut self, frames: &[Frame], f: usize) {
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

    fn pop(&mut self, frames: &[Frame]) {
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
    fn enter(&mut self, frames: &[Frame], f: usize) {
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

    /// [`resolve_port`] in the innermost expansion, in O(1): the innermost
    /// expansion remapping the entry, if no expansion in between (the
    /// outer one included) keeps its blackboard to itself.
    fn resolve(&self, frames: &[Frame], value: &str) -> String {
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
fn resolve_port(frames: &[Frame], frame: usize, value: &str) -> String {
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

fn generic(cat: Category) -> BtNodeKind {
    match cat {
        Category::Action => BtNodeKind::Action,
        Category::Condition => BtNodeKind::Condition,
        Category::Control => BtNodeKind::Control,
        Category::Decorator => BtNodeKind::Decorator,
    }
}

/// A skill argument from attribute text: integer, float, boolean or string.
pub fn arg_value(v: &str) -> ArgValue {
    if let Ok(i) = v.parse::<i64>() {
        ArgValue::Int(i)
    } else if let Ok(x) = v.parse::<f64>()
        && x.is_finite()
        && v.chars().any(|c| c.is_ascii_digit())
    {
        ArgValue::Float(x)
    } else if v == "true" || v == "false" {
        ArgValue::Bool(v == "true")
    } else {
        ArgValue::Str(v.to_string())
    }
}

/// Longest identity made from positions before falling back to the pre-order
/// index (keeps identities short on degenerate deep trees).
const MAX_POSITIONAL_ID: usize = 200;

/// `s` when at most 64 bytes long, else its first 32 bytes (on a character
/// boundary): the prefix of generated identities.
fn short_prefix(s: &str) -> &str {
    if s.len() <= 64 {
        return s;
    }
    let mut end = 32;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

/// Node identities of an XML tree (see the module documentation), in pre-order
/// from `root`. `explicit(i, derived)` may give node `i` an identity of its own
/// instead of the derived one (the reader passes `btfsm:id`; the writer passes
/// the model's id where it differs, and learns from the returned flags which
/// nodes need a `btfsm:id`). Returns the identities and, per node, whether it
/// was explicit.
pub fn derive_ids(
    children: &[Vec<usize>],
    root: usize,
    tree_id: &str,
    names: &[Option<String>],
    mut explicit: impl FnMut(usize, &str) -> Option<String>,
) -> (Vec<String>, Vec<bool>) {
    let mut count: HashMap<&str, usize> = HashMap::new();
    for n in names.iter().flatten() {
        *count.entry(n.as_str()).or_default() += 1;
    }
    let mut ids = vec![String::new(); children.len()];
    let mut flags = vec![false; children.len()];
    let mut used: HashSet<String> = HashSet::new();
    // Per clashing candidate, the next suffix to try: a thousand nodes
    // clashing on one candidate cost a thousand probes, not a million.
    let mut next_suffix: HashMap<String, usize> = HashMap::new();
    // (node, parent, position among its siblings)
    let mut stack: Vec<(usize, Option<usize>, usize)> = vec![(root, None, 0)];
    let mut order = 0usize;
    while let Some((i, parent, pos)) = stack.pop() {
        let mut cand = match (&names[i], parent) {
            (Some(n), _) if count.get(n.as_str()) == Some(&1) => n.clone(),
            (_, None) => tree_id.to_string(),
            // Built only when short enough (the length checked first).
            (_, Some(p))
                if ids[p].len() + 2 + pos.checked_ilog10().unwrap_or(0) as usize
                    <= MAX_POSITIONAL_ID =>
            {
                format!("{}/{pos}", ids[p])
            }
            (_, Some(_)) => String::new(),
        };
        if cand.is_empty() || cand.len() > MAX_POSITIONAL_ID {
            // Short whatever the tree's ID: a long ID is not repeated in
            // every identity.
            cand = format!("{}#{order}", short_prefix(tree_id));
        }
        if used.contains(&cand) {
            let k = next_suffix.entry(cand.clone()).or_insert(2);
            while used.contains(&format!("{cand}~{k}")) {
                *k += 1;
            }
            cand = format!("{cand}~{k}");
            *k += 1;
        }
        let id = match explicit(i, &cand) {
            Some(x) => {
                flags[i] = true;
                x
            }
            None => cand,
        };
        used.insert(id.clone());
        ids[i] = id;
        order += 1;
        for (k, &c) in children[i].iter().enumerate().rev() {
            stack.push((c, Some(i), k));
        }
    }
    (ids, flags)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Loaded, Vec<Diagnostic>> {
        parse_str("t.xml", text, Path::new("."), &Limits::default())
    }

    #[test]
    fn every_unknown_type_is_reported_once_in_one_run() {
        // An unknown control hides nothing below it; a type used twice is
        // one error.
        let text = r#"<root BTCPP_format="4" main_tree_to_execute="T">
  <BehaviorTree ID="T">
    <RecoveryNode>
      <Sequence><Spin/><Wait/></Sequence>
      <RateController><Spin/></RateController>
    </RecoveryNode>
  </BehaviorTree>
</root>"#;
        let e = parse(text).unwrap_err();
        let msgs: Vec<&str> = e.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(
            msgs,
            [
                "unknown node type `RecoveryNode` (2 children)",
                "unknown node type `Spin` (0 children)",
                "unknown node type `Wait` (0 children)",
                "unknown node type `RateController` (1 child)",
                "t.xml: 4 problems",
            ][..msgs.len().min(5)],
            "{msgs:#?}"
        );
        assert_eq!(
            e.iter()
                .filter(|d| d.message.starts_with("unknown"))
                .count(),
            4
        );
    }

    #[test]
    fn tree_chooses_among_several_trees_without_a_main_tree() {
        let text = r#"<root BTCPP_format="4">
  <BehaviorTree ID="Alpha"><AlwaysSuccess/></BehaviorTree>
  <BehaviorTree ID="Beta"><Sequence><AlwaysSuccess/><SubTree ID="Alpha"/></Sequence></BehaviorTree>
</root>"#;
        let e = parse(text).unwrap_err();
        assert!(
            e[0].message
                .contains("2 trees and no `main_tree_to_execute`")
        );
        let hint = e[0].hint.as_deref().unwrap();
        assert!(hint.contains("--tree ID") && hint.contains("`Alpha`") && hint.contains("`Beta`"));
        let with = |id: &str| Limits {
            tree: Some(id.into()),
            ..Limits::default()
        };
        let l = parse_str("t.xml", text, Path::new("."), &with("Beta")).unwrap();
        assert_eq!(bt(&l).nodes.len(), 3, "Beta with Alpha expanded");
        let e = parse_str("t.xml", text, Path::new("."), &with("Bta")).unwrap_err();
        assert!(e[0].message.contains("--tree `Bta`"), "{}", e[0]);
        assert!(
            e[0].hint
                .as_deref()
                .unwrap()
                .contains("did you mean `Beta`")
        );
        // --tree wins over main_tree_to_execute.
        let named = text.replace(
            "<root BTCPP_format=\"4\">",
            "<root BTCPP_format=\"4\" main_tree_to_execute=\"Beta\">",
        );
        let l = parse_str("t.xml", &named, Path::new("."), &with("Alpha")).unwrap();
        assert_eq!(bt(&l).nodes.len(), 1);
    }

    fn bt(l: &Loaded) -> &Bt {
        match &l.policy.body {
            PolicyBody::Bt(b) => b,
            _ => panic!("not a BT"),
        }
    }

    #[test]
    fn compact_and_explicit_syntax_with_subtrees() {
        let l = parse(
            r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <ReactiveSequence name="top">
      <SubTree ID="Sub"/>
      <Action ID="Move-To" target="cube2"/>
      <Repeat num_cycles="3"><AlwaysSuccess/></Repeat>
    </ReactiveSequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub">
    <Fallback><Condition ID="Found"/><Search/></Fallback>
  </BehaviorTree>
  <TreeNodesModel><Action ID="Search"/></TreeNodesModel>
</root>"#,
        )
        .unwrap();
        let b = bt(&l);
        assert_eq!(b.nodes.len(), 7);
        assert_eq!(b.nodes[0].kind, BtNodeKind::Sequence);
        assert_eq!(b.nodes[0].id, "top");
        assert_eq!(b.nodes[1].kind, BtNodeKind::FallbackMemory);
        assert_eq!(b.nodes[1].id, "top/0");
        assert_eq!(b.nodes[3].kind, BtNodeKind::Action);
        assert_eq!(b.nodes[3].skill.as_ref().unwrap().skill, "Search");
        let mt = &b.nodes[4];
        assert_eq!(
            mt.skill.as_ref().unwrap().args["target"],
            ArgValue::Str("cube2".into())
        );
        assert_eq!(b.nodes[5].kind, BtNodeKind::Repeat { times: Some(3) });
        assert!(b.nodes[5].ports.is_empty());
        assert_eq!(l.policy.name, "Main");
    }

    #[test]
    fn recursion_is_rejected_with_position() {
        let e = parse(
            r#"<root main_tree_to_execute="A">
  <BehaviorTree ID="A"><Sequence><SubTree ID="B"/></Sequence></BehaviorTree>
  <BehaviorTree ID="B"><SubTree ID="A"/></BehaviorTree>
</root>"#,
        )
        .unwrap_err();
        assert!(
            e[0].message.contains("recursive subtree: A -> B -> A"),
            "{}",
            e[0].message
        );
        assert_eq!(e[0].location().unwrap().1, 3);
    }

    #[test]
    fn unknown_type_lists_choices_or_is_assumed() {
        let text = r#"<root><BehaviorTree ID="T"><Sequence><Sequenc/><Foo/></Sequence></BehaviorTree></root>"#;
        let e = parse(text).unwrap_err();
        assert!(e[0].message.contains("unknown node type `Sequenc`"));
        assert!(e[0].hint.as_ref().unwrap().contains("Sequence"));
        let lim = Limits {
            assume_leaf: Some(AssumeLeaf::Condition),
            ..Default::default()
        };
        let l = parse_str("t.xml", text, Path::new("."), &lim).unwrap();
        assert_eq!(bt(&l).nodes[1].kind, BtNodeKind::Condition);
        assert_eq!(bt(&l).nodes[1].type_name.as_deref(), Some("Sequenc"));
    }

    #[test]
    fn generic_controls_keep_their_type_and_ports() {
        let l = parse(
            r#"<root><BehaviorTree ID="T"><IfThenElse name="ite"><AlwaysSuccess/><Script code="x:=1"/><Delay delay_msec="5"><AlwaysFailure/></Delay></IfThenElse></BehaviorTree></root>"#,
        )
        .unwrap();
        let b = bt(&l);
        assert_eq!(b.nodes[0].kind, BtNodeKind::Control);
        assert_eq!(b.nodes[0].type_name.as_deref(), Some("IfThenElse"));
        assert_eq!(b.nodes[2].ports["code"], "x:=1");
        assert_eq!(b.nodes[3].kind, BtNodeKind::Decorator);
        assert_eq!(b.nodes[3].ports["delay_msec"], "5");
    }

    #[test]
    fn conflicting_model_declarations_are_errors() {
        let e = parse(
            r#"<root><BehaviorTree ID="T"><Foo/></BehaviorTree>
<TreeNodesModel><Action ID="Foo"/><Condition ID="Foo"/></TreeNodesModel></root>"#,
        )
        .unwrap_err();
        assert!(
            e[0].message
                .contains("declared both as `Action` and as `Condition`"),
            "{}",
            e[0].message
        );
    }

    #[test]
    fn decorator_arity_is_checked() {
        let e = parse(r#"<root><BehaviorTree ID="T"><Inverter><AlwaysSuccess/><AlwaysSuccess/></Inverter></BehaviorTree></root>"#).unwrap_err();
        assert!(
            e[0].message.contains("takes exactly one child, found 2"),
            "{}",
            e[0].message
        );
    }

    const SEED: &str = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <ReactiveSequence name="top">
      <SubTree ID="Sub"/>
      <Parallel success_count="-1"><AlwaysSuccess/><Script code="a:=1"/></Parallel>
      <Repeat num_cycles="3"><Move-To target="cube2"/></Repeat>
      <IfThenElse><Found/><Search/><AlwaysFailure/></IfThenElse>
    </ReactiveSequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub"><Fallback><Condition ID="Robot-At" target="x"/><Dock/></Fallback></BehaviorTree>
  <TreeNodesModel><Action ID="Search"/><Action ID="Dock"/><Condition ID="Found"/></TreeNodesModel>
</root>"#;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

        /// Mutated trees never panic: they read (and write and read back at the
        /// same size) or give positioned errors.
        #[test]
        fn mutated_trees_never_panic(
            cuts in proptest::collection::vec((0usize..2000, 0usize..8, "[<>/=\" a-zA-Z]{0,3}"), 1..4)
        ) {
            let text = crate::format::xml::mutate(SEED, &cuts);
            match parse(&text) {
                Ok(l) => {
                    let xml = crate::format::btcpp_xml_write::write_policy(&l.policy).expect("a BT");
                    let back = parse(&xml).expect("written XML reads back");
                    proptest::prop_assert_eq!(bt(&back).nodes.len(), bt(&l).nodes.len());
                }
                Err(ds) => proptest::prop_assert!(ds.iter().any(|d| d.is_error() && d.location().is_some())),
            }
        }

        #[test]
        fn random_text_never_panics(text in "\\PC{0,200}") {
            let _ = parse(&text);
            let _ = crate::format::scxml::parse_str("t.scxml", &text, &Limits::default());
        }
    }

    #[test]
    fn repeated_names_fall_back_to_positions() {
        let children = vec![vec![1, 2], vec![], vec![]];
        let names = vec![None, Some("x".to_string()), Some("x".to_string())];
        let (ids, _) = derive_ids(&children, 0, "T", &names, |_, _| None);
        assert_eq!(ids, ["T", "T/0", "T/1"]);
    }

    #[test]
    fn subtree_ports_remap_the_subtree_blackboard() {
        // Fetch is used twice with different cubes, Place through a nested
        // subtree that remaps an outer entry, and Dock's target comes from
        // an entry shared by _autoremap.
        let l = parse(
            r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Fetch" cube="cube1" where="{drop}"/>
      <SubTree ID="Fetch" cube="cube2" where="delivery"/>
      <SubTree ID="Park" _autoremap="true"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Fetch">
    <Sequence>
      <Action ID="Pick" object="{cube}"/>
      <SubTree ID="Put" thing="{cube}" at="{where}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Put">
    <Action ID="Place" object="{thing}" at="{at}"/>
  </BehaviorTree>
  <BehaviorTree ID="Park">
    <Sequence><Action ID="Move-To" target="{spot}"/><Wait secs="{private}"/></Sequence>
  </BehaviorTree>
  <TreeNodesModel><Action ID="Wait"/></TreeNodesModel>
</root>"#,
        )
        .unwrap();
        let b = bt(&l);
        let calls: Vec<String> = b
            .nodes
            .iter()
            .map(|n| match &n.skill {
                Some(c) => format!("{}{:?}", c.skill, c.args),
                None => format!("{}{:?}", n.label, n.ports),
            })
            .collect();
        assert_eq!(
            calls,
            vec![
                "Sequence{}",
                "Sequence{}",
                r#"Pick{"object": Str("cube1")}"#,
                r#"Place{"at": Str("{drop}"), "object": Str("cube1")}"#,
                "Sequence{}",
                r#"Pick{"object": Str("cube2")}"#,
                r#"Place{"at": Str("delivery"), "object": Str("cube2")}"#,
                "Sequence{}",
                r#"Move-To{"target": Str("{spot}")}"#,
                r#"Wait{"secs": "{private}"}"#,
            ]
        );
    }

    #[test]
    fn a_problem_in_a_subtree_used_twice_is_reported_once() {
        let e = parse(
            r#"<root main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence><SubTree ID="Sub"/><SubTree ID="Sub"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub"><Mystery/></BehaviorTree>
</root>"#,
        )
        .unwrap_err();
        let msgs: Vec<&str> = e.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(msgs, vec!["unknown node type `Mystery` (0 children)"]);
    }

    fn limited(text: &str, f: impl FnOnce(&mut Limits)) -> Result<Loaded, Vec<Diagnostic>> {
        let mut lim = Limits::default();
        f(&mut lim);
        parse_str("t.xml", text, Path::new("."), &lim)
    }

    #[test]
    fn elements_of_unused_trees_count_against_max_nodes() {
        let text = format!(
            "<root main_tree_to_execute=\"M\">\n<BehaviorTree ID=\"M\"><AlwaysSuccess/></BehaviorTree>\n<BehaviorTree ID=\"Unused\"><Sequence>\n{}</Sequence></BehaviorTree>\n</root>",
            "<AlwaysSuccess/>\n".repeat(50)
        );
        assert!(limited(&text, |l| l.max_nodes = 60).is_ok());
        let e = limited(&text, |l| l.max_nodes = 20).unwrap_err();
        assert!(
            e[0].message.starts_with("more than 20 elements"),
            "{}",
            e[0].message
        );
        // The 21st element: root, 2 trees, a leaf, a Sequence, then leaf 16.
        let (_, line, col) = e[0].location().unwrap();
        assert_eq!((line, col), (19, 1), "{}", e[0]);
    }

    #[test]
    fn depth_and_long_names_are_errors_at_the_element() {
        let deep = format!(
            "<root>\n<BehaviorTree ID=\"T\">\n{}<AlwaysSuccess/>\n{}</BehaviorTree></root>",
            "<Inverter>\n".repeat(8),
            "</Inverter>".repeat(8)
        );
        assert!(limited(&deep, |l| l.max_depth = 8).is_ok());
        let e = limited(&deep, |l| l.max_depth = 5).unwrap_err();
        assert!(
            e[0].message
                .contains("is 6 levels below the root, deeper than the limit of 5 levels"),
            "{}",
            e[0].message
        );
        assert_eq!(e[0].location().unwrap().1, 9);
        // Port names and values, types and names: --max-name-bytes.
        let long = "v".repeat(5000);
        for (text, what) in [
            (
                format!("<Action ID=\"Go\" goal=\"{long}\"/>"),
                "value of `goal`",
            ),
            (
                format!("<Action ID=\"Go\" {long}=\"1\"/>"),
                "attribute name",
            ),
            (format!("<{long}/>"), "element name"),
            (
                format!("<Sequence name=\"{long}\"><Go/></Sequence>"),
                "value of `name`",
            ),
        ] {
            let doc = format!(
                "<root>\n<BehaviorTree ID=\"T\">\n<Sequence>\n{text}</Sequence></BehaviorTree>\n<TreeNodesModel><Action ID=\"Go\"/></TreeNodesModel></root>"
            );
            let e = parse(&doc).unwrap_err();
            assert!(
                e[0].message.starts_with(what)
                    && e[0]
                        .message
                        .contains("is 5000 bytes long, more than the limit of 4096 bytes"),
                "{}",
                e[0].message
            );
            assert!(e[0].message.len() < 300, "{}", e[0].message);
            assert!(e[0].location().unwrap().1 >= 3, "{}", e[0]);
        }
    }

    #[test]
    fn messages_quote_long_names_truncated() {
        let ty = "Q".repeat(3000);
        let e = parse(&format!(
            "<root main_tree_to_execute=\"{ty}x\"><BehaviorTree ID=\"T\"><{ty}/></BehaviorTree></root>"
        ))
        .unwrap_err();
        assert!(!e.is_empty());
        for d in &e {
            let all = format!("{}{}", d.message, d.hint.as_deref().unwrap_or(""));
            assert!(all.len() < 1000, "{} bytes: {}", all.len(), &all[..200]);
            assert!(all.contains("…(300"), "{}", &all[..200.min(all.len())]);
        }
    }

    #[test]
    fn a_long_subtree_chain_and_its_recursion_stay_bounded() {
        // T0 -> T1 -> ... -> T2999 -> T0: the message shows the cycle cut.
        let n = 3000;
        let mut text = String::from("<root main_tree_to_execute=\"T0\">");
        for i in 0..n {
            let next = (i + 1) % n;
            text.push_str(&format!(
                "<BehaviorTree ID=\"T{i}\"><Sequence><AlwaysSuccess/><SubTree ID=\"T{next}\"/></Sequence></BehaviorTree>"
            ));
        }
        text.push_str("</root>");
        let e = limited(&text, |l| l.max_depth = 10 * n).unwrap_err();
        assert!(
            e[0].message
                .starts_with("recursive subtree: T0 -> T1 -> T2"),
            "{}",
            e[0].message
        );
        assert!(
            e[0].message
                .ends_with("trees) ... -> T2995 -> T2996 -> T2997 -> T2998 -> T2999 -> T0"),
            "{}",
            e[0].message
        );
        assert!(e[0].message.len() < 300, "{}", e[0].message);
        // Without the cycle, the chain expands.
        let ok = text.replace("<SubTree ID=\"T0\"/>", "<AlwaysFailure/>");
        let l = limited(&ok, |l| l.max_depth = 10 * n).unwrap();
        assert_eq!(bt(&l).nodes.len(), 2 * n + 1);
    }

    #[test]
    fn generated_identities_stay_short_under_a_long_tree_id() {
        let tree_id = "T".repeat(1000);
        let children = vec![(1..=100).collect::<Vec<usize>>()]
            .into_iter()
            .chain((0..100).map(|_| vec![]))
            .collect::<Vec<_>>();
        let names = vec![None; 101];
        let (ids, _) = derive_ids(&children, 0, &tree_id, &names, |_, _| None);
        assert!(ids.iter().all(|i| i.len() < 64), "{}", ids[1]);
        let distinct: HashSet<&String> = ids.iter().collect();
        assert_eq!(distinct.len(), 101);
        // Many clashes on one candidate get distinct suffixes.
        let names: Vec<Option<String>> = (0..101).map(|i| Some(format!("T~{}", i + 1))).collect();
        let (ids, _) = derive_ids(&children, 0, "T", &names, |_, _| None);
        let distinct: HashSet<&String> = ids.iter().collect();
        assert_eq!(distinct.len(), 101);
    }

    #[test]
    fn port_resolution_through_nested_expansions() {
        let frame = |parent, remap: &[(&str, &str)], autoremap| Frame {
            id: String::new(),
            parent,
            remap: remap
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            autoremap,
        };
        // Main <- Outer (goal={target}, autoremap) <- Inner (x={goal})
        let frames = vec![
            frame(None, &[], false),
            frame(Some(0), &[("goal", "{target}")], true),
            frame(Some(1), &[("x", "{goal}")], false),
        ];
        // Remap values are stored resolved, as `expand` does.
        assert_eq!(resolve_port(&frames, 1, "{goal}"), "{target}");
        // Not remapped in Inner and no autoremap: private, kept as written.
        assert_eq!(resolve_port(&frames, 2, "{goal}"), "{goal}");
        assert_eq!(resolve_port(&frames, 2, "{x}"), "{goal}");
        // Outer shares unmapped entries with Main by name.
        assert_eq!(resolve_port(&frames, 1, "{other}"), "{other}");
        // Not a whole reference: kept.
        for v in ["{}", "{a}{b}", "x{goal}", "{goal", "goal}", "literal"] {
            assert_eq!(resolve_port(&frames, 1, v), v);
        }
        // The chain the reader keeps gives the same answers in O(1).
        let mut chain = Chain::default();
        for f in 0..3 {
            chain.enter(&frames, f);
            for v in ["{goal}", "{x}", "{other}", "{target}", "{}", "x"] {
                assert_eq!(
                    chain.resolve(&frames, v),
                    resolve_port(&frames, f, v),
                    "{f} {v}"
                );
            }
        }
        // Back in Outer after Inner: Inner's remapping is gone.
        chain.enter(&frames, 1);
        assert_eq!(chain.frames, [0, 1]);
        assert_eq!(chain.resolve(&frames, "{x}"), "{x}");
    }
}
