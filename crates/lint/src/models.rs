//! Node-type rules: what BehaviorTree.CPP refuses because its factory does
//! not know a node type ("Node not recognized", `XMLParser` in
//! BehaviorTree.CPP 4's `xml_parsing.cpp`), and node models that disagree
//! (docs/lint.md, `unknown-node-type` and `model-conflict`).
//!
//! Whether a type is known comes from the node models (a
//! `<TreeNodesModel>`: given, found beside the trees, or in the file): a
//! model given is taken to list every type the program registers; one
//! found or in the file is taken as the tree's when it declares at least
//! as many of the types the tree uses as it leaves out. Without such a
//! model only a type close to a known one (a misspelt built-in) is
//! reported, as a note: the others may be registered in C++, and lint
//! says how many files it could not check this way instead
//! ([`unchecked`]).

use super::{Level, Rule, Sink, Subject};
use btfsm_core::diagnostic::edit_distance;
use btfsm_format::btcpp_xml::Dataflow;
use btfsm_format::btcpp_xml::ports::UnknownType;

/// Is the closest known name a typo's distance away (at most 2 edits, 1 in
/// a name of 6 characters or fewer, case aside)? Without a model, only such a near miss is reported: a custom
/// type merely resembling a built-in (or a library's objective resembling
/// a local one, "Move to Pose" and "Move to Folded") is not a typo.
fn near_miss(u: &UnknownType) -> bool {
    // Two edits in a long name, one in a short one (`Report` is not a
    // misspelt `Repeat`).
    let edits = if u.ty.chars().count() > 6 { 2 } else { 1 };
    u.closest
        .as_deref()
        .is_some_and(|c| edit_distance(&u.ty.to_lowercase(), &c.to_lowercase()) <= edits)
}

pub const UNKNOWN_NODE_TYPE: Rule = Rule {
    code: "unknown-node-type",
    level: Level::Error,
    summary: "a node type no model declares and BehaviorTree.CPP does not build in: the factory refuses the tree",
    check: unknown_node_type,
};

/// Does a model describe the tree's node types: one given, or one found
/// (or in the file) that declares at least as many of them as it misses?
pub fn modelled(df: &Dataflow) -> bool {
    let t = &df.node_types;
    let unknown = t.unknown.iter().filter(|u| !u.subtree).count();
    t.given_model || (!t.declared.is_empty() && t.declared.len() >= unknown)
}

/// What lint could not check in a tree: the unknown node types no model
/// describes and close to no known type, and the SubTrees no file given
/// defines and close to no tree ID (each read as one opaque node).
pub fn unchecked<'a>(s: &Subject<'a>) -> (Vec<&'a str>, Vec<&'a str>) {
    let Some(df) = s.dataflow else {
        return (Vec::new(), Vec::new());
    };
    let modelled = modelled(df);
    let quiet = df
        .node_types
        .unknown
        .iter()
        .filter(|u| !near_miss(u) && (u.subtree || !modelled));
    let (trees, types): (Vec<&UnknownType>, Vec<&UnknownType>) = quiet.partition(|u| u.subtree);
    (
        types.iter().map(|u| u.ty.as_str()).collect(),
        trees.iter().map(|u| u.ty.as_str()).collect(),
    )
}

fn unknown_node_type(s: &Subject, out: &mut Sink) {
    let Some(df) = s.dataflow else { return };
    let modelled = modelled(df);
    for u in df.node_types.unknown.iter().filter(|u| !u.subtree) {
        if !modelled && !near_miss(u) {
            continue;
        }
        let (span, at) = super::dataflow::place(df, u.doc, &u.span);
        let t = &df.node_types;
        let tree = u.closest.as_deref() == Some(u.ty.as_str());
        let (message, help) = if tree {
            (
                format!(
                    "`{}`{at} is a tree, written as a node type: BehaviorTree.CPP's factory does not know it as one",
                    u.ty
                ),
                format!("write `<SubTree ID=\"{}\"/>`", u.ty),
            )
        } else if t.given_model {
            (
                format!(
                    "unknown node type `{}`{at}: the node models given do not declare it, and BehaviorTree.CPP refuses a tree with a type its factory does not know",
                    u.ty
                ),
                declare(u),
            )
        } else if modelled {
            let whose = match t.found_models.as_slice() {
                [] => "the file's `<TreeNodesModel>`".to_string(),
                [one] => format!("the node model found, {one},"),
                many => format!("the node models found ({}...)", many[0]),
            };
            (
                format!(
                    "unknown node type `{}`{at}: {whose} does not declare it; BehaviorTree.CPP refuses the tree unless the program registers the type",
                    u.ty
                ),
                outdated(u),
            )
        } else {
            (
                format!(
                    "unknown node type `{}`{at}, close to `{}`: BehaviorTree.CPP refuses it unless the program registers it",
                    u.ty,
                    u.closest.as_deref().unwrap_or("")
                ),
                declare(u),
            )
        };
        let level = if modelled || tree {
            None
        } else {
            Some(Level::Note)
        };
        out.push_capped(&u.ty, span, message, help, level);
    }
}

/// How to fix an unknown type a model found (or the file's) does not
/// declare: the close one, or the model is out of date.
fn outdated(u: &UnknownType) -> String {
    let fix = format!(
        "the program registers `{}`, the model is out of date: declare it there as {}",
        u.ty,
        kind_of(u)
    );
    match &u.closest {
        Some(c) => format!("did you mean `{c}`? If {fix}"),
        None => format!("if {fix}"),
    }
}

/// The kinds a type of this shape may be declared as.
fn kind_of(u: &UnknownType) -> &'static str {
    match u.children {
        0 => "an Action or a Condition",
        1 => "a Decorator",
        _ => "a Control",
    }
}

/// How to fix an unknown type: the close one, or declaring it.
fn declare(u: &UnknownType) -> String {
    let decl = format!(
        "declare it as {} in the `<TreeNodesModel>` of the program's nodes",
        kind_of(u)
    );
    match &u.closest {
        Some(c) => format!("did you mean `{c}`? else {decl}"),
        None => decl,
    }
}

pub const UNKNOWN_SUBTREE: Rule = Rule {
    code: "unknown-subtree",
    level: Level::Warning,
    summary: "a SubTree no file given defines, close to a tree ID that is defined (a misspelt tree ID?)",
    check: unknown_subtree,
};

/// SubTrees no file read defines but close to a tree that is: a misspelt
/// ID, which BehaviorTree.CPP refuses. The others may come from files the
/// program registers and lint was not given ([`unchecked`]).
fn unknown_subtree(s: &Subject, out: &mut Sink) {
    let Some(df) = s.dataflow else { return };
    for u in df
        .node_types
        .unknown
        .iter()
        .filter(|u| u.subtree && near_miss(u))
    {
        let Some(c) = &u.closest else { continue };
        let (span, at) = super::dataflow::place(df, u.doc, &u.span);
        out.push(
            &u.ty,
            span,
            format!(
                "no file given defines tree `{}`{at}, close to tree `{c}`: BehaviorTree.CPP refuses the SubTree unless the program registers a file that defines it",
                u.ty
            ),
            format!("did you mean `{c}`? else give the file that defines it with this one"),
        );
    }
}

pub const MODEL_CONFLICT: Rule = Rule {
    code: "model-conflict",
    level: Level::Warning,
    summary: "two node models declare one type as different kinds (Action here, Condition there)",
    check: super::load::found_by_the_reader,
};

/// Does a file carry its own node model (Groot2 saves one in the file): a
/// `<TreeNodesModel>` declaring node types, not only SubTree ports? Then
/// no model is searched for it (`lint`, `review`).
pub fn has_leaf_model(text: &str) -> bool {
    let Some(start) = text.find("<TreeNodesModel") else {
        return false;
    };
    let model = &text[start..];
    let model = &model[..model.find("</TreeNodesModel").unwrap_or(model.len())];
    ["<Action", "<Condition", "<Control", "<Decorator"]
        .iter()
        .any(|t| model.contains(t))
}
