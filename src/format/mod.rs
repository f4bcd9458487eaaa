//! Policy file formats. Each format reads a file into a [`crate::model::Policy`],
//! collecting every problem it finds as a positioned [`Diagnostic`].

pub mod toml;
pub mod toml_write;

use crate::diagnostic::Diagnostic;
use crate::model::Policy;
use std::path::Path;

/// A policy read from a file, with the warnings its validation produced.
#[derive(Debug)]
pub struct Loaded {
    pub path: String,
    pub policy: Policy,
    pub warnings: Vec<Diagnostic>,
}

/// Resource limits on input (hostile or accidental). Each is an error with
/// exit code 2 naming the flag that raises it (README, "Limits and
/// robustness").
#[derive(Debug, Clone)]
pub struct Limits {
    /// Largest file read, in bytes (each file; subtree includes also count
    /// towards a total of this many bytes read per policy).
    pub max_file_bytes: u64,
    /// Most BT nodes or FSM states after expanding subtree includes.
    pub max_nodes: usize,
    /// Deepest subtree include chain.
    pub max_include_depth: usize,
    /// Deepest BT (root at depth 0) or HFSM container nesting.
    pub max_depth: usize,
    /// Longest node id, state or outcome name, display name or label, in bytes.
    pub max_name_bytes: usize,
}

/// Default of [`Limits::max_file_bytes`].
pub const DEFAULT_MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;
/// Default of [`Limits::max_nodes`].
pub const DEFAULT_MAX_NODES: usize = 2_000_000;
/// Default of [`Limits::max_depth`].
pub const DEFAULT_MAX_DEPTH: usize = 1_000;
/// Default of [`Limits::max_name_bytes`].
pub const DEFAULT_MAX_NAME_BYTES: usize = 4096;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_nodes: DEFAULT_MAX_NODES,
            max_include_depth: 64,
            max_depth: DEFAULT_MAX_DEPTH,
            max_name_bytes: DEFAULT_MAX_NAME_BYTES,
        }
    }
}

/// The limits every format shares, checked on the model a reader built:
/// nodes or states, and nesting depth (BT levels below the root, HFSM
/// containers). An error carries the span of the offending element when it
/// has one (the caller attaches its file); walks use explicit stacks.
pub fn check_shape(policy: &Policy, limits: &Limits) -> Option<Diagnostic> {
    use crate::model::PolicyBody;
    let too_many = |n: usize, what: &str| {
        Diagnostic::error(format!(
            "{n} {what}, more than the limit of {}",
            limits.max_nodes
        ))
        .hint("raise the limit with --max-nodes")
    };
    let too_deep = |what: String, span: Option<std::ops::Range<usize>>| {
        let mut d = Diagnostic::error(format!(
            "{what}, deeper than the limit of {} levels",
            limits.max_depth
        ))
        .hint("raise the limit with --max-depth");
        d.span = span;
        d
    };
    match &policy.body {
        PolicyBody::Bt(bt) => {
            if bt.nodes.len() > limits.max_nodes {
                return Some(too_many(bt.nodes.len(), "nodes"));
            }
            let mut stack = vec![(bt.root, 0usize)];
            while let Some((i, depth)) = stack.pop() {
                let node = bt.nodes.get(i)?;
                if depth > limits.max_depth {
                    return Some(too_deep(
                        format!("node `{}` is {depth} levels below the root", node.id),
                        node.span.clone(),
                    ));
                }
                stack.extend(node.children.iter().map(|&c| (c, depth + 1)));
            }
            None
        }
        PolicyBody::Machine(m) => {
            if m.states.len() > limits.max_nodes {
                return Some(too_many(m.states.len(), "states"));
            }
            let mut depth = vec![0usize; m.states.len()];
            for s in m.parents_first() {
                let st = &m.states[s];
                depth[s] = st.parent.map_or(0, |p| depth[p] + 1);
                if depth[s] > limits.max_depth {
                    return Some(too_deep(
                        format!("state `{}` is nested {} containers deep", st.name, depth[s]),
                        st.span.clone(),
                    ));
                }
            }
            None
        }
    }
}

/// Reads a policy from any supported format (chosen by extension).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    toml::load_file(path, limits)
}
