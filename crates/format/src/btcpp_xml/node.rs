//! One BehaviorTree.CPP element as a BT node: its type (built-in, from a
//! `<TreeNodesModel>`, or `--assume-leaf`), label, ports, and the
//! child-count rules BehaviorTree.CPP 4 enforces.

use super::super::xml::{XElem, shown};
use super::loader::Loader;
use super::*;

/// How an element's type reads: the node kind and category, the attributes
/// the kind carries (not kept as ports), and whether the type name is kept.
struct Typed {
    kind: BtNodeKind,
    cat: Category,
    consumed: &'static [&'static str],
    type_kept: bool,
}

impl Typed {
    /// A type read as its category's generic kind.
    fn generic(cat: Category) -> Typed {
        Typed {
            kind: generic(cat),
            cat,
            consumed: &[],
            type_kept: true,
        }
    }

    /// The built-in type `ty` on element `el` with `n` children.
    fn builtin(ty: &str, cat: Category, el: &XElem, n: usize) -> Typed {
        let (kind, consumed, type_kept) = builtin_kind(ty, el, n);
        Typed {
            kind,
            cat,
            consumed,
            type_kept,
        }
    }
}

impl Loader<'_> {
    /// One node: its kind, label, type name and ports; arity is checked here
    /// on the element (a SubTree child counts as one).
    pub(super) fn node(
        &mut self,
        d: usize,
        el: &XElem,
        resolve: impl Fn(&str) -> String,
    ) -> Option<BtNode> {
        let n = el.children.len();
        let (mut ty, explicit_cat) = self.element_type(d, el)?;
        let Typed {
            kind,
            cat,
            consumed,
            mut type_kept,
        } = self.node_kind(d, el, &mut ty, explicit_cat)?;
        if !self.arity_fits(d, el, &ty, cat) {
            return None;
        }
        // BehaviorTree.CPP's own rules for built-ins it checks when the
        // tree is built or first ticked (a program that loads the file fails
        // there): child counts, thresholds, required ports.
        if builtin(&ty).is_some()
            && !self.models.contains_key(&ty)
            && let Some((msg, hint, code)) = builtin_rule(&ty, el, n)
        {
            // For `lint`, what BehaviorTree.CPP refuses only when it ticks
            // the node is a finding beside the others (the tree is built).
            match tick_time(&ty, code) {
                Some(code) if self.limits.for_lint => {
                    if let Some(code) = code {
                        let w = self.warn(d, el.span.clone(), msg);
                        w.hint = Some(hint.into());
                        w.code = Some(code);
                    }
                }
                _ => {
                    let e = self.err(d, el.span.clone(), msg);
                    e.hint = Some(hint.into());
                    e.code = code;
                    return None;
                }
            }
        }
        if ty == "ReactiveSequence"
            && !self.models.contains_key(&ty)
            && self.says_format_4(d)
            && !self.reactive_children_fit(d, el)
        {
            return None;
        }
        let mut ports = node_ports(el, consumed, kind, &ty, resolve);
        let skill_call = bind_skill(kind, &ty, &mut ports);
        if skill_call.is_some() {
            type_kept = false;
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
            // Format 3's names of built-ins are kept as format 4 names them
            // (the same node; an export says BTCPP_format="4").
            type_name: type_kept.then(|| v4_name(&ty).to_string()),
            ports,
            subtree: None,
            // Set with the id, once the whole tree is read (`expand.rs`).
            id_source: btfsm_model::IdSource::Position,
            span: Some(el.span.clone()),
        })
    }

    /// An element's node type, and its category when the explicit syntax
    /// (`<Action ID="...">`) gives it.
    fn element_type(&mut self, d: usize, el: &XElem) -> Option<(String, Option<Category>)> {
        let tag = el.name.as_str();
        let cat = match tag {
            "Action" => Category::Action,
            "Condition" => Category::Condition,
            "Control" => Category::Control,
            "Decorator" => Category::Decorator,
            _ => {
                // The compact syntax names the type by the tag: BehaviorTree.CPP
                // 4 refuses an `ID` there ("Attribute [ID] is not allowed in
                // <Fallback>", `XMLParser`'s createNodeFromXML).
                if el.attr("ID").is_some() {
                    self.err(
                        d,
                        el.span.clone(),
                        format!("`ID` is not allowed on `<{}>`", shown(tag)),
                    )
                    .hint = Some(
                        "the tag names the type: remove `ID` (a display name is `name=\"...\"`), or write `<Action ID=\"...\">` to name the type by `ID`".into(),
                    );
                    return None;
                }
                return Some((tag.to_string(), None));
            }
        };
        match el.attr("ID") {
            Some(id) => Some((id.to_string(), Some(cat))),
            None => {
                self.err(
                    d,
                    el.span.clone(),
                    format!("`<{tag}>` needs an `ID` naming its type"),
                )
                .hint = Some(format!(
                    "write `<{tag} ID=\"MyNode\"/>`, or the compact `<MyNode/>`"
                ));
                None
            }
        }
    }

    /// How type `ty` reads: built in, of the explicit category, from a
    /// `<TreeNodesModel>`, a built-in miswritten in case (`ty` becomes the
    /// built-in), `--assume-leaf`, or an unknown type (an error at its first
    /// use; `None` for a leaf, else a placeholder of its shape).
    fn node_kind(
        &mut self,
        d: usize,
        el: &XElem,
        ty: &mut String,
        explicit_cat: Option<Category>,
    ) -> Option<Typed> {
        let n = el.children.len();
        Some(if let Some(cat) = builtin(ty) {
            if self.limits.for_lint && !self.format_3(d) && v4_name(ty) != ty.as_str() {
                self.v3_name(d, el, ty);
            }
            Typed::builtin(ty, cat, el, n)
        } else if let Some(cat) = explicit_cat {
            if self.models.contains_key(ty.as_str()) {
                self.declared(ty);
            } else if self.limits.for_lint {
                self.record_unknown(d, el, ty, true);
            }
            Typed::generic(cat)
        } else if let Some(m) = self.models.get(ty.as_str()) {
            let cat = m.cat;
            self.declared(ty);
            Typed::generic(cat)
        } else if let Some((real, cat)) = BUILTINS.iter().find(|(b, _)| b.eq_ignore_ascii_case(ty))
        {
            self.warn(
                d,
                el.span.clone(),
                format!(
                    "`{}` is not a BehaviorTree.CPP node type; read as the built-in `{real}`",
                    shown(ty)
                ),
            )
            .set_code("unknown-node-type")
            .hint = Some(format!(
                "node types are case-sensitive: write `<{real}>` (BehaviorTree.CPP itself rejects `<{}>`)",
                shown(ty)
            ));
            *ty = real.to_string();
            Typed::builtin(real, *cat, el, n)
        } else if explicit_cat.is_none() && self.trees.contains_key(ty.as_str()) {
            // A tree's ID used as a tag: BehaviorTree.CPP 4 does not take
            // it for the SubTree it names ("Node not recognized",
            // xml_parsing.cpp), so neither does btfsm, even with
            // --assume-leaf.
            if self.unknown.insert(ty.clone()) {
                self.err(
                    d,
                    el.span.clone(),
                    format!(
                        "`<{}>` names a tree, not a node type: BehaviorTree.CPP 4 refuses it (Node not recognized)",
                        shown(ty)
                    ),
                )
                .hint = Some(format!(
                    "write `<SubTree ID=\"{}\"/>` to run that tree here",
                    shown(ty)
                ));
            }
            return None;
        } else if self.limits.for_lint {
            // Kept as its shape says, for the `unknown-node-type` rule.
            self.record_unknown(d, el, ty, false);
            match (n, self.limits.assume_leaf) {
                (0, Some(AssumeLeaf::Condition)) => Typed::generic(Category::Condition),
                (0, _) => Typed::generic(Category::Action),
                (1, _) => Typed::generic(Category::Decorator),
                _ => Typed::generic(Category::Control),
            }
        } else if let (Some(a), 0) = (self.limits.assume_leaf, n) {
            match a {
                AssumeLeaf::Action => Typed::generic(Category::Action),
                AssumeLeaf::Condition => Typed::generic(Category::Condition),
            }
        } else {
            // Reported at its first use only.
            if self.unknown.insert(ty.clone()) {
                self.unknown_type(d, el, ty);
            }
            // A node with children is read on as a placeholder of its
            // shape, so that the unknown types below it are reported in the
            // same run (the file fails with these errors anyway); a leaf has
            // nothing below it and costs nothing more.
            match n {
                0 => return None,
                1 => Typed::generic(Category::Decorator),
                _ => Typed::generic(Category::Control),
            }
        })
    }

    /// A format-3 name of a built-in in a file BehaviorTree.CPP 4 reads as
    /// format 4 (`BTCPP_format="4"`): its factory does not know it ("Node
    /// not recognized: SequenceStar"). A file without the attribute may be
    /// written for BehaviorTree.CPP 3 (Nav2 Humble's): not reported.
    fn v3_name(&mut self, d: usize, el: &XElem, ty: &str) {
        let root = self.docs[d].root;
        if self.docs[d].elems[root].attr("BTCPP_format") != Some("4") {
            return;
        }
        let real = v4_name(ty);
        self.warn(
            d,
            el.span.clone(),
            format!(
                "`{}` is BehaviorTree.CPP 3's name: BehaviorTree.CPP 4 does not know it, and this file says BTCPP_format=\"4\"",
                shown(ty)
            ),
        )
        .set_code("unknown-node-type")
        .hint = Some(format!("write `<{real}>`"));
    }

    /// A type the tree uses that a model declares.
    fn declared(&mut self, ty: &str) {
        let types = &mut self.flow.node_types;
        if !types.declared.contains(ty) {
            types.declared.insert(ty.to_string());
        }
    }

    /// A type no model declares, at its first use (`lint`): with the
    /// closest known type for the first [`HINTED_TYPES`] of them.
    fn record_unknown(&mut self, d: usize, el: &XElem, ty: &str, explicit: bool) {
        if !self.unknown.insert(ty.to_string()) {
            return;
        }
        // A tree's ID written as a node type is its own closest (the
        // `unknown-node-type` rule says to write a `<SubTree>`).
        let closest = if self.trees.contains_key(ty) {
            Some(ty.to_string())
        } else {
            (self.unknown.len() <= HINTED_TYPES)
                .then(|| {
                    let cands = BUILTINS
                        .iter()
                        .map(|(b, _)| *b)
                        .chain(self.models.keys().map(String::as_str));
                    btfsm_core::diagnostic::closest(ty, cands).map(str::to_string)
                })
                .flatten()
        };
        self.flow
            .node_types
            .unknown
            .push(super::ports::UnknownType {
                ty: ty.to_string(),
                doc: d,
                span: el.span.clone(),
                children: el.children.len(),
                explicit,
                subtree: false,
                closest,
            });
    }

    /// The error of an unknown node type, with how to declare it.
    fn unknown_type(&mut self, d: usize, el: &XElem, ty: &str) {
        let n = el.children.len();
        // Hints only for messages that will be shown (the rest are
        // counted): bounded work under a million unknown types.
        let did = if self.hinting() {
            let cands = BUILTINS
                .iter()
                .map(|(b, _)| *b)
                .chain(self.models.keys().map(String::as_str));
            suggest(ty, cands)
        } else {
            String::new()
        };
        let ty = shown(ty);
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
    }

    /// BehaviorTree.CPP 4 (4.10, not 3) checks a ReactiveSequence's children
    /// when it loads the file (xml_parsing.cpp, `VerifyXML`): it looks each child up
    /// by its tag name, so the explicit form `<Action ID="X"/>` is refused
    /// ("Unknown node type: Action"), and two asynchronous children
    /// (`AsyncSequence`) are refused ("A ReactiveSequence cannot have more
    /// than one async child"). An error when not.
    fn reactive_children_fit(&mut self, d: usize, el: &XElem) -> bool {
        let mut asyncs = 0;
        for &c in &el.children {
            let child = self.docs[d].elems[c].clone();
            let name = child.name.as_str();
            if matches!(name, "Action" | "Condition" | "Control" | "Decorator") {
                let id = child.attr("ID").unwrap_or("TYPE");
                let hint = format!(
                    "write it in the compact form `<{}/>`: BehaviorTree.CPP looks a ReactiveSequence's children up by tag name",
                    shown(id)
                );
                self.err(
                    d,
                    child.span.clone(),
                    format!(
                        "BehaviorTree.CPP 4 refuses `<{name}>` as a child of `ReactiveSequence` (Unknown node type: {name})"
                    ),
                )
                .hint = Some(hint);
                return false;
            }
            if name == "AsyncSequence" {
                asyncs += 1;
                if asyncs > 1 {
                    self.err(
                        d,
                        el.span.clone(),
                        "a `ReactiveSequence` with more than one `AsyncSequence` child: BehaviorTree.CPP 4 refuses it".to_string(),
                    )
                    .hint = Some(
                        "keep one asynchronous child (BehaviorTree.CPP: \"A ReactiveSequence cannot have more than one async child\"); use a `Sequence` for the others".into(),
                    );
                    return false;
                }
            }
        }
        true
    }

    /// Whether the element's number of children fits its category (a
    /// SubTree child is one node); an error when not.
    fn arity_fits(&mut self, d: usize, el: &XElem, ty: &str, cat: Category) -> bool {
        let n = el.children.len();
        let bad = match cat {
            Category::Action | Category::Condition => n != 0,
            Category::Decorator => n != 1,
            Category::Control => n == 0,
        };
        if !bad {
            return true;
        }
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
                shown(ty),
                cat.tag().to_lowercase()
            ),
        )
        .set_code(if cat == Category::Control {
            "empty-composite"
        } else {
            "wrong-child-count"
        })
        .hint = Some(match cat {
            Category::Decorator => "wrap several children in a `<Sequence>`".into(),
            Category::Control => "give it children, or use a leaf".into(),
            _ => "a leaf has no children; is the type right in the `<TreeNodesModel>`?".into(),
        });
        false
    }
}

/// Unknown types whose closest known type is looked for (each search scans
/// the built-ins and the models once): bounded work under a million types.
const HINTED_TYPES: usize = 256;

/// Whether a problem `builtin_rule` finds is one BehaviorTree.CPP 4 meets
/// only when it ticks the node (it creates the tree): `Some` with the
/// rule's code (`None`: the rule that reports it runs on the loaded tree,
/// `missing-required-port` for `num_attempts`, `msec`, ...). Checked against
/// behaviortreepy by tests/differential/btcpp_when.py.
fn tick_time(ty: &str, code: Option<&'static str>) -> Option<Option<&'static str>> {
    match ty {
        "Parallel" | "IfThenElse" | "WhileDoElse" | "Switch2" | "Switch3" | "Switch4"
        | "Switch5" | "Switch6" => Some(code),
        "RetryUntilSuccessful" | "Sleep" | "Timeout" | "Delay" | "Repeat" => Some(None),
        _ => None,
    }
}

/// A node's ports: its attributes but `name`, `ID`, namespaced ones and
/// those its kind carries, values resolved.
fn node_ports(
    el: &XElem,
    consumed: &[&str],
    kind: BtNodeKind,
    ty: &str,
    resolve: impl Fn(&str) -> String,
) -> BTreeMap<String, String> {
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
    ports
}

/// A leaf whose type is a skill of the shared library, with arguments that
/// fit the skill, is bound to it: its ports become the skill's arguments.
fn bind_skill(
    kind: BtNodeKind,
    ty: &str,
    ports: &mut BTreeMap<String, String>,
) -> Option<SkillCall> {
    let (BtNodeKind::Action | BtNodeKind::Condition, Some(sk), Some(params)) =
        (kind, skill::skill_kind(ty), skill::skill_params(ty))
    else {
        return None;
    };
    let want = if kind == BtNodeKind::Action {
        SkillKind::Action
    } else {
        SkillKind::Condition
    };
    let fits = sk == want
        && ports.keys().all(|k| params.iter().any(|(p, _)| p == k))
        && params.iter().all(|(p, req)| !req || ports.contains_key(*p));
    fits.then(|| SkillCall {
        skill: ty.to_string(),
        args: std::mem::take(ports)
            .into_iter()
            .map(|(k, v)| (k, arg_value(&v)))
            .collect(),
    })
}

/// The model kind of a category's generic node.
fn generic(cat: Category) -> BtNodeKind {
    match cat {
        Category::Action => BtNodeKind::Action,
        Category::Condition => BtNodeKind::Condition,
        Category::Control => BtNodeKind::Control,
        Category::Decorator => BtNodeKind::Decorator,
    }
}
