//! The loader of a BehaviorTree.CPP file: the main document, its
//! `<include>`s (depth-first, cycles rejected), `--nodes-model` files,
//! `<BehaviorTree>` and `<TreeNodesModel>` definitions, and the choice of
//! the tree to read (`--tree`, `main_tree_to_execute`, the only tree).

use super::super::xml::{self, XDoc, XElem, shown};
use super::super::{Limits, Loaded};
use super::{Category, builtin};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_model::{Policy, PolicyBody};
use std::collections::{BTreeMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A type declared in a `<TreeNodesModel>`.
#[derive(Debug, Clone)]
pub(super) struct ModelEntry {
    pub(super) cat: Category,
    /// Its `<input_port>`, `<output_port>` and `<inout_port>`s.
    pub(super) ports: Vec<super::ports::PortDecl>,
    /// Where it is declared: document and span.
    pub(super) at: (usize, Range<usize>),
}

/// The files being included, outermost first: their canonical paths (for
/// cycles) and their paths as the user sees them (canonical ones differ by
/// machine).
struct IncludeChain {
    canon: Vec<PathBuf>,
    shown: Vec<String>,
}

pub(super) struct Loader<'l> {
    pub(super) limits: &'l Limits,
    pub(super) diags: xml::Sink,
    pub(super) docs: Vec<XDoc>,
    pub(super) dirs: Vec<PathBuf>,
    /// Tree ID -> (document, `<BehaviorTree>` element).
    pub(super) trees: BTreeMap<String, (usize, usize)>,
    pub(super) models: BTreeMap<String, ModelEntry>,
    /// The directory every included file must be in (`None`: anywhere).
    pub(super) root: Option<PathBuf>,
    /// What remains of `--max-nodes` for the elements of the files still to
    /// read: every element of every file counts, used or not.
    pub(super) elems_left: usize,
    /// Unknown node types already reported: each is an error once, at its
    /// first use, however often it is used.
    pub(super) unknown: std::collections::HashSet<String>,
    /// Types two models declare in different categories, with the warning
    /// said when the tree uses the type.
    pub(super) conflicts: Vec<(String, Diagnostic)>,
    /// SubTree IDs no file read defines, read as opaque nodes (`lint`).
    pub(super) unknown_subtrees: std::collections::HashSet<String>,
    /// Files read so far (canonical paths): each is read once.
    pub(super) seen: HashSet<PathBuf>,
    /// The first document read as a companion (a file given together with
    /// this one that defines a missing SubTree); `usize::MAX` before any.
    pub(super) first_companion: usize,
    /// Tree IDs no file read defines and several companions do: the files.
    pub(super) ambiguous: BTreeMap<String, Vec<String>>,
    /// `<SubTree ID>` entries of the models: the ports of each tree.
    pub(super) tree_ports: super::ports::TreePorts,
    /// The dataflow of the expanded tree (filled by `expand`).
    pub(super) flow: super::ports::Dataflow,
}

pub(super) fn load(
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
    let root = crate::source::root_for(limits, &base);
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
        unknown_subtrees: Default::default(),
        conflicts: Vec::new(),
        seen: HashSet::new(),
        first_companion: usize::MAX,
        ambiguous: BTreeMap::new(),
        tree_ports: BTreeMap::new(),
        flow: Default::default(),
    };
    l.diags.extend(repaired);
    let policy = l.run(identity);
    let mut flow = std::mem::take(&mut l.flow);
    flow.files = l.docs.iter().map(|d| d.file.clone()).collect();
    let mut loaded = crate::finish(&file, policy, l.diags.into_vec(&file), "behavior tree")?;
    if let btfsm_model::PolicyBody::Bt(_) = &loaded.policy.body {
        flow.tree_ports = l.tree_ports.get(&loaded.policy.name).cloned();
        loaded.dataflow = Some(Arc::new(flow));
    }
    Ok(loaded)
}

impl Loader<'_> {
    pub(super) fn err(
        &mut self,
        d: usize,
        span: Range<usize>,
        msg: impl Into<String>,
    ) -> &mut Diagnostic {
        let f = self.docs[d].file.clone();
        self.diags.push(Diagnostic::error(msg).at(&f, span))
    }

    /// Parses a file read for this policy, charging its elements to the
    /// shared element budget.
    pub(super) fn parse_charged(&mut self, file: &Arc<SourceFile>) -> Result<XDoc, Diagnostic> {
        let (doc, repaired) = xml::parse_lenient(file, self.elems_left, self.limits.max_nodes)?;
        self.diags.extend(repaired);
        self.elems_left -= doc.elems.len();
        Ok(doc)
    }

    /// Are hints still worth computing? Past the messages shown
    /// (`finish` keeps the first ones), no did-you-mean search is done.
    pub(super) fn hinting(&self) -> bool {
        self.diags.room_for_errors()
    }

    pub(super) fn warn(
        &mut self,
        d: usize,
        span: Range<usize>,
        msg: impl Into<String>,
    ) -> &mut Diagnostic {
        let f = self.docs[d].file.clone();
        self.diags.push(Diagnostic::warning(msg).at(&f, span))
    }

    pub(super) fn run(&mut self, identity: PathBuf) -> Option<Policy> {
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
        self.includes(0, identity.clone());
        let extra = self.limits.nodes_models.clone();
        for m in &extra {
            self.nodes_model_file(m);
        }
        // The node models of the Groot2 projects given together (a project
        // folder walked as a directory), for the trees in the project's
        // folder or below it, unless this file is one. `lint` finds them in
        // its own search of the repository (`found_models`).
        let projects: Vec<PathBuf> = match &self.limits.companions {
            Some(c) if !self.limits.for_lint => c.projects().map(Path::to_path_buf).collect(),
            _ => Vec::new(),
        };
        for p in projects {
            let p = crate::toml::canonical(&p);
            let governs = p.parent().is_some_and(|dir| identity.starts_with(dir));
            if p != identity && governs {
                self.project_models(&p);
            }
        }
        self.flow.node_types.given_model = !extra.is_empty();
        // Models found rather than given: their problems are warnings.
        let found = self.limits.found_models.clone();
        self.flow.node_types.found_models = found
            .iter()
            .map(|m| btfsm_core::sanitize::shown_max(&m.display().to_string(), 240).into_owned())
            .collect();
        for m in &found {
            let mark = self.diags.mark();
            self.nodes_model_file(m);
            self.diags.demote_since(mark);
        }
        for d in 0..self.docs.len() {
            self.definitions(d);
        }
        if self.diags.has_errors() {
            return None;
        }
        let (tree_id, (d, e)) = self.main_tree()?;
        self.companion_trees();
        if self.diags.has_errors() {
            return None;
        }
        let bt = self.expand(&tree_id, d, e)?;
        // Model conflicts about types the tree uses (another tree's types
        // are its own business).
        for (id, w) in std::mem::take(&mut self.conflicts) {
            if self.flow.node_types.declared.contains(&id) {
                self.diags.push(w);
            }
        }
        Some(Policy {
            name: tree_id,
            description: None,
            body: PolicyBody::Bt(bt),
        })
    }

    /// Loads `<include path>` files depth-first with an explicit stack; a file
    /// including one of its includers is a cycle.
    pub(super) fn includes(&mut self, start: usize, identity: PathBuf) {
        self.seen.insert(identity.clone());
        let mut chain = IncludeChain {
            canon: vec![identity],
            shown: vec![self.docs[start].file.path.clone()],
        };
        let mut work: Vec<(usize, usize)> = vec![(start, 0)];
        while let Some(&mut (d, ref mut pos)) = work.last_mut() {
            let root = self.docs[d].root;
            let kids = &self.docs[d].elems[root].children;
            if *pos >= kids.len() {
                work.pop();
                chain.canon.pop();
                chain.shown.pop();
                continue;
            }
            let e = kids[*pos];
            *pos += 1;
            let el = self.docs[d].elems[e].clone();
            if el.name != "include" {
                continue;
            }
            let Some((full, canon, pspan)) = self.include_path(d, &el, &chain) else {
                continue;
            };
            if self.seen.contains(&canon) {
                continue; // already read through another include
            }
            if chain.canon.len() > self.limits.max_include_depth {
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
            let Some(doc) = self.included_doc(d, &full, &shown, pspan) else {
                continue;
            };
            self.seen.insert(canon.clone());
            self.docs.push(doc);
            self.dirs
                .push(full.parent().unwrap_or(Path::new("")).to_path_buf());
            chain.canon.push(canon);
            chain.shown.push(shown);
            work.push((self.docs.len() - 1, 0));
        }
    }

    /// The file an `<include>` element of document `d` names (as resolved,
    /// canonical) and the span of its `path`; `None` when it names none, is
    /// outside the root or includes one of its includers.
    fn include_path(
        &mut self,
        d: usize,
        el: &XElem,
        chain: &IncludeChain,
    ) -> Option<(PathBuf, PathBuf, Range<usize>)> {
        let Some(p) = el.attr_full("path") else {
            self.err(d, el.span.clone(), "`<include>` needs a `path`")
                .hint = Some("write `<include path=\"subtrees/other.xml\"/>`".into());
            return None;
        };
        let (pval, pspan) = (p.value.clone(), p.span.clone());
        // `ros_pkg`: `path` is in that package's share directory
        // (BehaviorTree.CPP's xml_parsing.cpp; `ros_pkg.rs`).
        let found = match el.attr_full("ros_pkg") {
            Some(pkg) => {
                let (name, span) = (pkg.value.clone(), pkg.span.clone());
                crate::ros_pkg::resolve_in_package(
                    &self.limits.ros,
                    self.root.as_deref(),
                    &self.dirs[d],
                    &name,
                    &pval,
                )
                .map_err(|r| (r, span))
            }
            None => crate::source::resolve(self.root.as_deref(), &self.dirs[d], &pval)
                .map_err(|r| (r, pspan.clone())),
        };
        let full = match found {
            Ok(p) => p,
            Err((r, span)) => {
                self.err(d, span, format!("cannot include this file: {}", r.message))
                    .hint = Some(r.hint);
                return None;
            }
        };
        let canon = crate::toml::canonical(&full);
        if let Some(at) = chain.canon.iter().position(|c| *c == canon) {
            let mut names: Vec<String> = chain.shown[at..]
                .iter()
                .map(|n| shown(n).into_owned())
                .collect();
            names.push(shown(&full.display().to_string()).into_owned());
            self.err(d, pspan, format!("cyclic include: {}", names.join(" -> ")))
                .set_code("include-cycle")
                .hint = Some("a file must not include itself, directly or through others".into());
            return None;
        }
        Some((full, canon, pspan))
    }

    /// Reads and parses an included file (`shown` as the user sees its
    /// path), which must be a `<root>`; errors at the `path` of the
    /// `<include>` in document `d`.
    fn included_doc(
        &mut self,
        d: usize,
        full: &Path,
        shown: &str,
        pspan: Range<usize>,
    ) -> Option<XDoc> {
        let named = crate::source::Named::Xml("root");
        let file = match crate::toml::read_included(full, shown, self.limits, named) {
            Ok(f) => f,
            Err(mut ds) => {
                let x = ds.remove(0);
                self.err(d, pspan, x.message).hint = Some(
                    x.hint
                        .unwrap_or_else(|| "`path` is relative to the including file".into()),
                );
                return None;
            }
        };
        let doc = match self.parse_charged(&file) {
            Ok(doc) => doc,
            Err(diag) => {
                self.diags.push(diag);
                return None;
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
            return None;
        }
        Some(doc)
    }

    /// Reads and parses a file named on the command line (a `--nodes-model`
    /// file, a companion), its elements charged to the element budget; its
    /// problems go to the diagnostics.
    pub(super) fn read_named(&mut self, path: &Path) -> Option<XDoc> {
        let shown = path.display().to_string();
        let file = match crate::source::read(path, &shown, self.limits, false) {
            Ok(f) => f,
            Err(ds) => {
                self.diags.extend(ds);
                return None;
            }
        };
        match self.parse_charged(&file) {
            Ok(doc) => Some(doc),
            Err(d) => {
                self.diags.push(d);
                None
            }
        }
    }

    /// Reads a `--nodes-model` file: a `<root>` holding a `<TreeNodesModel>`, or a
    /// bare `<TreeNodesModel>`.
    pub(super) fn nodes_model_file(&mut self, path: &Path) {
        let Some(doc) = self.read_named(path) else {
            return;
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

    /// The `<TreeNodesModel>`s of a Groot2 project file (`.btproj`) given
    /// together with this one, if any (a project may declare none).
    fn project_models(&mut self, path: &Path) {
        let Some(doc) = self.read_named(path) else {
            return;
        };
        let root = doc.root;
        let models: Vec<usize> = doc
            .children(root)
            .filter(|(_, e)| e.name == "TreeNodesModel")
            .map(|(i, _)| i)
            .collect();
        self.docs.push(doc);
        let d = self.docs.len() - 1;
        self.dirs.push(PathBuf::new());
        for m in models {
            self.read_model(d, m);
        }
    }

    pub(super) fn read_model(&mut self, d: usize, m: usize) {
        let kids = self.docs[d].elems[m].children.clone();
        for k in kids {
            let el = self.docs[d].elems[k].clone();
            let cat = match el.name.as_str() {
                "Action" => Category::Action,
                "Condition" => Category::Condition,
                "Control" => Category::Control,
                "Decorator" => Category::Decorator,
                "SubTree" => {
                    // BehaviorTree.CPP 4 (xml_parsing.cpp, loadSubtreeModel)
                    // refuses a model's `<SubTree>` without `ID`.
                    if let Some(id) = el.attr("ID") {
                        let ports = super::ports::model_ports(&self.docs[d], d, k);
                        self.tree_ports.insert(id.to_string(), ports);
                    } else if self.says_format_4(d) {
                        self.err(
                            d,
                            el.span.clone(),
                            "`<SubTree>` in `<TreeNodesModel>` needs an `ID`".to_string(),
                        )
                        .hint = Some(
                            "name the tree whose ports it declares: `<SubTree ID=\"Name\">` (BehaviorTree.CPP refuses it too)".into(),
                        );
                    }
                    continue;
                }
                // Metadata MoveIt Studio (and BehaviorTree.CPP's own
                // writeTreeNodesModelXML) keeps in a model; BehaviorTree.CPP
                // reads only what it registers, and ignores the rest.
                "MetadataFields" | "Metadata" | "description" => continue,
                other => {
                    let h = suggest(
                        other,
                        ["Action", "Condition", "Control", "Decorator", "SubTree"],
                    );
                    self.warn(
                        d,
                        el.span.clone(),
                        format!(
                            "unknown entry `<{}>` in `<TreeNodesModel>` is ignored",
                            shown(other)
                        ),
                    )
                    .hint = Some(format!("{h} (BehaviorTree.CPP ignores it too)"));
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
            if let Some(prev) = self.models.get(id) {
                if prev.cat != cat {
                    self.model_conflict(d, &el, id, prev.clone(), cat);
                }
                continue; // the first declaration read wins
            }
            let ports = super::ports::model_ports(&self.docs[d], d, k);
            let at = (d, el.span.clone());
            self.models
                .insert(id.to_string(), ModelEntry { cat, ports, at });
        }
    }

    /// A type two models declare in different categories: a warning naming
    /// both places; the first read (a model given, before one found; the
    /// file's own, before its includes') is kept.
    fn model_conflict(&mut self, d: usize, el: &XElem, id: &str, prev: ModelEntry, cat: Category) {
        let (pd, pspan) = prev.at;
        let first = {
            let f = &self.docs[pd].file;
            let (l, c) = f.line_col(pspan.start.min(f.text.len()));
            format!("{}:{l}:{c}", shown(&f.path))
        };
        let f = self.docs[d].file.clone();
        let w = Diagnostic::warning(format!(
            "`{}` is declared as `{}` here and as `{}` at {first}; read as `{}`",
            shown(id),
            cat.tag(),
            prev.cat.tag(),
            prev.cat.tag()
        ))
        .at(&f, el.span.clone())
        .with_code("model-conflict")
        .hint(
            "keep one declaration per node type across the model files (the C++ class the program registers decides)",
        );
        self.conflicts.push((id.to_string(), w));
    }

    /// Collects `<BehaviorTree>` definitions and `<TreeNodesModel>` entries.
    pub(super) fn definitions(&mut self, d: usize) {
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
        let mut models_seen = 0;
        for &k in &kids {
            let el = self.docs[d].elems[k].clone();
            match el.name.as_str() {
                "BehaviorTree" => {
                    if el.attr("ID").is_none_or(str::is_empty)
                        && kids.len() > 1
                        && self.says_format_4(d)
                    {
                        self.untitled_tree(d, &el);
                        continue;
                    }
                    let id = el.attr("ID").unwrap_or("MainTree").to_string();
                    if self.too_long(d, &el, "tree ID", &id) {
                        continue;
                    }
                    if d >= self.first_companion && self.trees.contains_key(&id) {
                        continue; // the files read first define it (docs: companions)
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
                "TreeNodesModel" => {
                    models_seen += 1;
                    if models_seen > 1 {
                        self.second_model(d, &el);
                        continue;
                    }
                    self.read_model(d, k);
                }
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

    /// A `<BehaviorTree>` without `ID` (or with an empty one) beside other
    /// elements under `<root>` of a `BTCPP_format="4"` file: BehaviorTree.CPP 4 refuses it ("The tag
    /// <BehaviorTree> must have the attribute [ID]", xml_parsing.cpp,
    /// `VerifyXML`, which counts every element under `<root>`).
    fn untitled_tree(&mut self, d: usize, el: &XElem) {
        self.err(
            d,
            el.span.clone(),
            "`<BehaviorTree>` needs an `ID` when `<root>` holds other elements".to_string(),
        )
        .hint = Some(
            "give it one: `<BehaviorTree ID=\"MainTree\">` (BehaviorTree.CPP refuses it too)"
                .into(),
        );
    }

    /// A second `<TreeNodesModel>` in one file: BehaviorTree.CPP refuses it
    /// ("Only a single node <TreeNodesModel> is supported", xml_parsing.cpp,
    /// `VerifyXML`).
    fn second_model(&mut self, d: usize, el: &XElem) {
        self.err(
            d,
            el.span.clone(),
            "a second `<TreeNodesModel>` in one file".to_string(),
        )
        .hint = Some("merge its entries into the first (BehaviorTree.CPP reads one per file and refuses the file)".into());
    }

    /// The tree to run: `--tree ID`, else `main_tree_to_execute`, else the
    /// only tree of the main file.
    pub(super) fn main_tree(&mut self) -> Option<(String, (usize, usize))> {
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
    pub(super) fn too_long(&mut self, d: usize, el: &XElem, what: &str, value: &str) -> bool {
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
    pub(super) fn names_too_long(&mut self, d: usize, el: &XElem) -> bool {
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
}
