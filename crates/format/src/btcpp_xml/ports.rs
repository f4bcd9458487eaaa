//! Ports of BehaviorTree.CPP node types: what a `<TreeNodesModel>` entry
//! declares (`<input_port>`, `<output_port>`, `<inout_port>` with `name`,
//! `type`, `default`), what BehaviorTree.CPP 4's built-in nodes provide
//! (their `providedPorts()`, read in BehaviorTree.CPP's source:
//! `include/behaviortree_cpp/{actions,controls,decorators}/*.h`; the names
//! checked against the engine in tests/differential/dataflow_btcpp.py), and
//! the blackboard keys a script reads and writes (BehaviorTree.CPP 4's
//! script language: `key := expr`, `key = expr`, `key += expr`, ...;
//! `Script`, `ScriptCondition`, `Precondition`'s `if` and the `_skipIf`,
//! `_onSuccess`, ... attributes every node takes).
//!
//! What the lint rules of `src/lint/dataflow.rs` read: [`Dataflow`], built
//! by the loader as it expands the tree.

use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::Arc;

/// Which way a port carries data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum PortDir {
    Input,
    Output,
    InOut,
}

impl PortDir {
    pub fn tag(self) -> &'static str {
        match self {
            PortDir::Input => "input_port",
            PortDir::Output => "output_port",
            PortDir::InOut => "inout_port",
        }
    }
    pub fn reads(self) -> bool {
        self != PortDir::Output
    }
    pub fn writes(self) -> bool {
        self != PortDir::Input
    }
}

/// One declared port of a node type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PortDecl {
    pub dir: PortDir,
    pub name: String,
    /// The declared type as written (`type="double"`); `None` when untyped.
    pub ty: Option<String>,
    /// The default value; an input without one must be given.
    pub default: Option<String>,
    /// Where it is declared: document index and span (`None`: built-in).
    pub at: Option<(usize, Range<usize>)>,
    /// Built-ins whose absence the node tolerates although BehaviorTree.CPP
    /// declares no default (Switch's `variable` and cases).
    pub optional: bool,
    /// A port whose value is a script (`Script`'s `code`, `Precondition`'s `if`).
    pub script: bool,
    /// SetBlackboard's `output_key`: the bare name of the key written.
    pub key_name: bool,
}

/// A blackboard entry: the expansion whose blackboard holds it (0: the
/// tree's own) and its name there.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Key {
    pub scope: usize,
    pub name: String,
}

/// How a node uses a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    Read,
    Write,
    /// Read then written (an `inout_port`, `x += 1`).
    ReadWrite,
    /// A `{key}` on a port whose direction is not known (no model, or a port
    /// the model does not declare): may read or write it.
    Unknown,
    /// Read by a script: an identifier may also be an enum name, so it does
    /// not count as a read that must come after a write.
    ScriptRead,
}

/// One attribute of a node that refers to a key, or one key of a script.
#[derive(Debug, Clone)]
pub struct KeyUse {
    pub key: Key,
    pub access: Access,
    /// The port (attribute) it is written on.
    pub port: String,
    /// The port's declared type, when the model gives one.
    pub ty: Option<String>,
    /// Span of the attribute in its document.
    pub span: Range<usize>,
}

/// One attribute of a node as written.
#[derive(Debug, Clone)]
pub struct PortUse {
    pub name: String,
    pub value: String,
    pub span: Range<usize>,
}

/// What the dataflow rules know of one node of the expanded tree.
#[derive(Debug, Clone)]
pub struct NodeFlow {
    /// Index in [`btfsm_model::Bt::nodes`].
    pub node: usize,
    /// The BehaviorTree.CPP type (`ID`).
    pub ty: String,
    /// The document it was read from (0: the file linted).
    pub doc: usize,
    pub span: Range<usize>,
    /// Index into [`Dataflow::decls`]: the ports its type declares, when
    /// known (a `<TreeNodesModel>` entry, or a built-in in a format-4 file).
    pub decl: Option<usize>,
    /// Whether `decl` is a built-in's.
    pub builtin: bool,
    /// Its attributes but `name`, `ID`, namespaced and `_`-prefixed ones.
    pub ports: Vec<PortUse>,
    pub keys: Vec<KeyUse>,
}

/// One `<SubTree>` element: the remapping of its ports.
#[derive(Debug, Clone)]
pub struct SubTreeFlow {
    pub id: String,
    pub doc: usize,
    pub span: Range<usize>,
    /// The node that takes its place (the subtree's root).
    pub node: usize,
    /// Port name, value as written, the outer key it maps to (`None`: a
    /// literal), attribute span.
    pub remap: Vec<(String, String, Option<Key>, Range<usize>)>,
    /// The entries its pre- and post-condition scripts (`_skipIf`,
    /// `_onSuccess`, ...) use, in the enclosing tree's blackboard.
    pub keys: Vec<KeyUse>,
}

/// Blackboard dataflow of an expanded BehaviorTree.CPP tree.
#[derive(Debug, Clone, Default)]
pub struct Dataflow {
    /// Every document read (0: the main file), for positions.
    pub files: Vec<Arc<btfsm_core::diagnostic::SourceFile>>,
    pub decls: Vec<Vec<PortDecl>>,
    /// Node type -> its index in `decls` (`None`: ports not known).
    pub types: BTreeMap<String, Option<usize>>,
    pub nodes: Vec<NodeFlow>,
    pub subtrees: Vec<SubTreeFlow>,
    /// Keys a `<SubTree>` sets to a literal (initialised in the subtree's
    /// blackboard).
    pub given: Vec<Key>,
    /// The ports of the tree run, when a `<TreeNodesModel>` declares them
    /// (`<SubTree ID="Main"><input_port .../></SubTree>`): its interface
    /// with the application. `None`: the application may set any key.
    pub tree_ports: Option<Vec<PortDecl>>,
    /// Expansions (blackboards) in the tree: scope -> SubTree ID.
    pub scopes: Vec<String>,
    /// The node types the tree uses that no model declares, and what the
    /// models say of the others (read with [`crate::Limits::for_lint`]).
    pub node_types: NodeTypes,
}

/// What the models say of the node types a tree uses (`unknown-node-type`).
#[derive(Debug, Clone, Default)]
pub struct NodeTypes {
    /// A model was given (`--nodes-model`, `[lint] models`, a model file
    /// given as an input): it is taken to declare every type the program
    /// registers.
    pub given_model: bool,
    /// The model files found rather than given (as shown).
    pub found_models: Vec<String>,
    /// Types the tree uses, not built in, that a model declares.
    pub declared: std::collections::BTreeSet<String>,
    /// Types no model declares and BehaviorTree.CPP does not build in, and
    /// SubTrees no file read defines, each at its first use, in tick order.
    pub unknown: Vec<UnknownType>,
}

/// A node type no model declares, at its first use.
#[derive(Debug, Clone)]
pub struct UnknownType {
    pub ty: String,
    /// The document it is used in (index into [`Dataflow::files`]) and the
    /// element's span there.
    pub doc: usize,
    pub span: Range<usize>,
    /// Its number of children there.
    pub children: usize,
    /// Written in the explicit syntax (`<Action ID="...">`).
    pub explicit: bool,
    /// A `<SubTree ID>` no file read defines (read as one opaque node).
    pub subtree: bool,
    /// The closest known type (built-in or declared) or tree ID, when one
    /// is close.
    pub closest: Option<String>,
}

/// Reads the port declarations under a `<TreeNodesModel>` entry.
pub(super) fn model_ports(doc: &super::super::xml::XDoc, d: usize, e: usize) -> Vec<PortDecl> {
    doc.children(e)
        .filter_map(|(_, p)| {
            let dir = match p.name.as_str() {
                "input_port" => PortDir::Input,
                "output_port" => PortDir::Output,
                "inout_port" => PortDir::InOut,
                _ => return None,
            };
            Some(PortDecl {
                dir,
                name: p.attr("name")?.to_string(),
                ty: p.attr("type").map(str::to_string),
                default: p.attr("default").map(str::to_string),
                at: Some((d, p.span.clone())),
                optional: false,
                script: false,
                key_name: false,
            })
        })
        .collect()
}

/// A built-in's port: direction, name, type, default.
type B = (PortDir, &'static str, &'static str, Option<&'static str>);

const I: PortDir = PortDir::Input;
const O: PortDir = PortDir::Output;
const IO: PortDir = PortDir::InOut;

/// The ports of a BehaviorTree.CPP 4 built-in (by its v4 name), `None` for
/// a type that is not one. Format-3 only types (`BlackboardCheck*`) have
/// BehaviorTree.CPP 3's.
pub fn builtin_ports(ty: &str) -> Option<Vec<PortDecl>> {
    let loop_value = |t: &'static str| -> Vec<B> {
        vec![
            (IO, "queue", "", None),
            (I, "if_empty", "NodeStatus", Some("SUCCESS")),
            (O, "value", t, None),
        ]
    };
    let check = |t: &'static str| -> Vec<B> {
        vec![
            (I, "value_A", t, None),
            (I, "value_B", t, None),
            (I, "return_on_mismatch", "NodeStatus", Some("FAILURE")),
        ]
    };
    let ports: Vec<B> = match ty {
        "Sequence"
        | "ReactiveSequence"
        | "SequenceWithMemory"
        | "AsyncSequence"
        | "Fallback"
        | "ReactiveFallback"
        | "AsyncFallback"
        | "IfThenElse"
        | "WhileDoElse"
        | "Inverter"
        | "ForceSuccess"
        | "ForceFailure"
        | "KeepRunningUntilFailure"
        | "AlwaysSuccess"
        | "AlwaysFailure" => vec![],
        "Parallel" => vec![
            (I, "success_count", "int", Some("-1")),
            (I, "failure_count", "int", Some("1")),
        ],
        "ParallelAll" => vec![(I, "max_failures", "int", Some("1"))],
        "ManualSelector" => vec![(I, "repeat_last_selection", "bool", Some("false"))],
        "TryCatch" => vec![(I, "catch_on_halt", "bool", Some("false"))],
        "RetryUntilSuccessful" => vec![(I, "num_attempts", "int", None)],
        "Repeat" => vec![(I, "num_cycles", "int", None)],
        "Timeout" => vec![(I, "msec", "unsigned int", None)],
        "Delay" => vec![(I, "delay_msec", "unsigned int", None)],
        "Sleep" => vec![(I, "msec", "unsigned int", None)],
        "RunOnce" => vec![(I, "then_skip", "bool", Some("true"))],
        "Precondition" => vec![
            (I, "if", "std::string", None),
            (I, "else", "NodeStatus", Some("FAILURE")),
        ],
        "Script" | "ScriptCondition" => vec![(I, "code", "std::string", None)],
        "SetBlackboard" => vec![(I, "value", "", None), (IO, "output_key", "", None)],
        "UnsetBlackboard" => vec![(I, "key", "std::string", None)],
        "WasEntryUpdated" | "EntryUpdated" | "SkipUnlessUpdated" | "WaitValueUpdate" => {
            vec![(I, "entry", "BT::Any", None)]
        }
        "LoopInt" => loop_value("int"),
        "LoopDouble" => loop_value("double"),
        "LoopString" => loop_value("std::string"),
        "LoopBool" => loop_value("bool"),
        "BlackboardCheckInt" => check("int"),
        "BlackboardCheckDouble" => check("double"),
        "BlackboardCheckString" => check("std::string"),
        "BlackboardCheckBool" => check("bool"),
        t if t.starts_with("Switch") => {
            let n: usize = t[6..].parse().ok().filter(|n| (2..=6).contains(n))?;
            let mut v = vec![PortDecl::builtin(I, "variable", "std::string", None)];
            for i in 1..=n {
                v.push(PortDecl::builtin(
                    I,
                    &format!("case_{i}"),
                    "std::string",
                    None,
                ));
            }
            for p in &mut v {
                p.optional = true;
            }
            return Some(v);
        }
        _ => return None,
    };
    Some(
        ports
            .into_iter()
            .map(|(dir, name, t, def)| {
                let mut p = PortDecl::builtin(dir, name, t, def);
                p.script = matches!(
                    (ty, name),
                    ("Script" | "ScriptCondition", "code") | ("Precondition", "if")
                );
                p.key_name = (ty, name) == ("SetBlackboard", "output_key");
                p
            })
            .collect(),
    )
}

impl PortDecl {
    fn builtin(dir: PortDir, name: &str, ty: &str, default: Option<&str>) -> PortDecl {
        PortDecl {
            dir,
            name: name.to_string(),
            ty: (!ty.is_empty()).then(|| ty.to_string()),
            default: default.map(str::to_string),
            at: None,
            optional: false,
            script: false,
            key_name: false,
        }
    }
}

/// The attributes every BehaviorTree.CPP 4 node takes whose value is a
/// script (pre- and post-conditions).
pub const SCRIPT_ATTRS: &[&str] = &[
    "_skipIf",
    "_failureIf",
    "_successIf",
    "_while",
    "_onSuccess",
    "_onFailure",
    "_onHalted",
    "_post",
];

/// The keys a BehaviorTree.CPP script reads and writes, in order:
/// identifiers (`[A-Za-z_@][A-Za-z0-9_]*`, outside single-quoted strings,
/// not `true`/`false`), written when followed by `:=` or `=`, read and
/// written when followed by `+=`, `-=`, `*=`, `/=`, else read. One pass,
/// linear in the script.
pub fn script_keys(script: &str) -> Vec<(String, Access)> {
    let b = script.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'\'' || c == b'"' {
            i += 1;
            while i < b.len() && b[i] != c {
                i += 1;
            }
            i += 1;
        } else if c.is_ascii_digit() {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'_') {
                i += 1;
            }
        } else if c.is_ascii_alphabetic() || c == b'_' || c == b'@' {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let word = &script[start..i];
            if word == "true" || word == "false" {
                continue;
            }
            let mut j = i;
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            let next = |k: usize| b.get(j + k).copied();
            let access = match (next(0), next(1)) {
                (Some(b':'), Some(b'=')) => Access::Write,
                (Some(b'='), n) if n != Some(b'=') => Access::Write,
                (Some(b'+' | b'-' | b'*' | b'/'), Some(b'=')) => Access::ReadWrite,
                _ => Access::ScriptRead,
            };
            out.push((word.to_string(), access));
        } else {
            i += 1;
        }
    }
    out
}

/// Does a port value name a blackboard entry (`{key}`, `{=}`, or `=`),
/// as BehaviorTree.CPP's `setOutput` requires?
pub fn is_pointer(value: &str) -> bool {
    value == "="
        || value
            .strip_prefix('{')
            .and_then(|v| v.strip_suffix('}'))
            .is_some_and(|k| !k.is_empty() && !k.contains(['{', '}']))
}

/// The declared ports of `tree`'s `<SubTree ID>` model entries, by ID.
pub(super) type TreePorts = BTreeMap<String, Vec<PortDecl>>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_read_and_write_keys() {
        let k = script_keys("a := b + 1; c = 'x:=y' ; d += 2; e == f; @g := true");
        let got: Vec<(&str, Access)> = k.iter().map(|(s, a)| (s.as_str(), *a)).collect();
        assert_eq!(
            got,
            [
                ("a", Access::Write),
                ("b", Access::ScriptRead),
                ("c", Access::Write),
                ("d", Access::ReadWrite),
                ("e", Access::ScriptRead),
                ("f", Access::ScriptRead),
                ("@g", Access::Write),
            ]
        );
        assert!(script_keys("1.5e3 > 0x1F").is_empty());
    }

    #[test]
    fn builtins_have_their_ports() {
        let s = builtin_ports("SetBlackboard").unwrap();
        assert!(s.iter().any(|p| p.key_name && p.dir == PortDir::InOut));
        assert_eq!(builtin_ports("Switch3").unwrap().len(), 4);
        assert!(builtin_ports("Switch9").is_none());
        assert!(builtin_ports("MoveBase").is_none());
        let l = builtin_ports("LoopInt").unwrap();
        assert_eq!(l[2].ty.as_deref(), Some("int"));
    }
}
