//! Policy file formats. Each format reads a file into a [`btfsm_model::Policy`],
//! collecting every problem it finds as a positioned [`Diagnostic`].

pub mod btcpp_xml;
pub mod btcpp_xml_write;
pub mod discover;
pub mod flexbe;
pub mod py_trees_dot;
pub mod ros_pkg;
pub mod scxml;
pub mod scxml_write;
pub mod source;
pub mod toml;
pub mod toml_write;
pub mod xml;
pub mod xml_lenient;
pub mod yasmin;

use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_model::Policy;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A policy read from a file, with the warnings its validation produced.
#[derive(Debug)]
pub struct Loaded {
    pub path: String,
    pub policy: Policy,
    pub warnings: Vec<Diagnostic>,
    /// A BehaviorTree.CPP tree's blackboard dataflow (ports, keys,
    /// SubTree remappings), for `lint`; `None` for other formats.
    pub dataflow: Option<Arc<btcpp_xml::Dataflow>>,
}

/// Resource limits on input (hostile or accidental). Each is an error with
/// exit code 2 naming the flag that raises it (docs/guide/limits.md).
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
    /// BehaviorTree.CPP `<TreeNodesModel>` files (`--nodes-model`) that say
    /// which node types are actions, conditions, controls and decorators.
    pub nodes_models: Vec<PathBuf>,
    /// How to read a BehaviorTree.CPP leaf of unknown type (`--assume-leaf`);
    /// `None`: such a leaf is an error.
    pub assume_leaf: Option<AssumeLeaf>,
    /// Where files named by other files may be (`--root`,
    /// `--allow-outside-root`; [`source::resolve`]).
    pub confinement: source::Confinement,
    /// The bytes the whole command may read (`--max-total-bytes`), shared
    /// by every clone of these limits.
    pub read_budget: Arc<source::Budget>,
    /// The nodes the whole command may create by copying a subtree already
    /// read (TOML subtrees used again, BehaviorTree.CPP `<SubTree>`s):
    /// `max_nodes` in all, so that a few kilobytes of files including each
    /// other twice per level cannot build millions of nodes per policy.
    pub expansion_budget: Arc<source::Budget>,
    /// The nodes and states of all the policies the command reads
    /// (`--max-total-nodes`, issue 33: `validate DIR` of many large files
    /// took 101 s of CPU within the byte budget): once spent, no other
    /// policy is parsed.
    pub total_nodes: Arc<source::Budget>,
    /// The BehaviorTree.CPP tree to read (`--tree ID`), as a program names
    /// it to the factory; over `main_tree_to_execute`. Other formats
    /// ignore it.
    pub tree: Option<String>,
    /// The BehaviorTree.CPP files given together with the one being read:
    /// a `<SubTree>` that no file it reads defines is looked up in them
    /// ([`btcpp_xml::Companions`]).
    pub companions: Option<Arc<btcpp_xml::Companions>>,
    /// Where ROS packages are (`--ros-pkg`, `AMENT_PREFIX_PATH`, the
    /// repository), for BehaviorTree.CPP's `<include ros_pkg>` and yasmin's
    /// `package` includes ([`ros_pkg`]).
    pub ros: Arc<ros_pkg::RosPackages>,
    /// `<TreeNodesModel>` files found beside the trees rather than given
    /// (`lint`'s search of the repository, docs/lint.md "Node models"):
    /// read after [`Limits::nodes_models`], whose declarations win, and
    /// their problems are warnings (nobody asked for them).
    pub found_models: Vec<PathBuf>,
    /// Read as `lint` reads (docs/lint.md): a node type no model declares
    /// is kept (as `--assume-leaf` or its shape says) and recorded in the
    /// dataflow for the `unknown-node-type` rule rather than refused, and
    /// what BehaviorTree.CPP 4 refuses only when it ticks the node is read
    /// on: a Parallel threshold or an IfThenElse or SwitchN child count is
    /// a warning carrying its rule's code, and a built-in without a port it
    /// reads when ticked (`num_attempts`, `msec`, ...) is left to the
    /// `missing-required-port` rule, so that the other rules still run. A
    /// `<SubTree>` no file given defines, among several files given, is one
    /// opaque node.
    pub for_lint: bool,
}

/// The kind given to BehaviorTree.CPP leaves of unknown type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssumeLeaf {
    Action,
    Condition,
}

/// Default of [`Limits::max_file_bytes`].
pub const DEFAULT_MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;
/// Default of [`Limits::max_nodes`].
pub const DEFAULT_MAX_NODES: usize = 150_000;
/// Default of `--max-total-nodes` ([`Limits::total_nodes`]): ten policies
/// at `--max-nodes`.
pub const DEFAULT_MAX_TOTAL_NODES: u64 = 10 * DEFAULT_MAX_NODES as u64;
/// Default of [`Limits::max_depth`].
pub const DEFAULT_MAX_DEPTH: usize = 1_000;
/// Default of [`Limits::max_name_bytes`].
pub const DEFAULT_MAX_NAME_BYTES: usize = 4096;

impl Limits {
    /// The TOML tokens a policy may hold before it is parsed
    /// (`core::toml_budget`): 50 per node of `--max-nodes`, at least a
    /// million.
    pub fn max_toml_tokens(&self) -> u64 {
        (self.max_nodes as u64)
            .saturating_mul(btfsm_core::toml_budget::TOKENS_PER_NODE)
            .max(1 << 20)
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_nodes: DEFAULT_MAX_NODES,
            max_include_depth: 64,
            max_depth: DEFAULT_MAX_DEPTH,
            max_name_bytes: DEFAULT_MAX_NAME_BYTES,
            nodes_models: Vec::new(),
            assume_leaf: None,
            confinement: source::Confinement::Auto,
            read_budget: source::Budget::new(source::DEFAULT_MAX_TOTAL_BYTES),
            expansion_budget: source::Budget::new(DEFAULT_MAX_NODES as u64),
            total_nodes: source::Budget::new(DEFAULT_MAX_TOTAL_NODES),
            tree: None,
            companions: None,
            ros: Arc::default(),
            found_models: Vec::new(),
            for_lint: false,
        }
    }
}

/// The limits every format shares, checked on the model a reader built:
/// nodes or states, nesting depth (BT levels below the root, HFSM
/// containers) and name length (ids, names, labels). An error carries the
/// span of the offending element when it has one (the caller attaches its
/// file); walks use explicit stacks.
pub fn check_shape(policy: &Policy, limits: &Limits) -> Option<Diagnostic> {
    use btfsm_model::PolicyBody;
    let too_long = |what: &str, name: &str, span: Option<std::ops::Range<usize>>| {
        let shown: String = name.chars().take(24).collect();
        let mut d = Diagnostic::error(format!(
            "{what} `{shown}…` is {} bytes long, more than the limit of {} bytes",
            name.len(),
            limits.max_name_bytes
        ))
        .hint("shorten it, or raise the limit with --max-name-bytes");
        d.span = span;
        d
    };
    let long = |s: &str| s.len() > limits.max_name_bytes;
    type Named<'p> = (&'p str, &'p str, &'p Option<std::ops::Range<usize>>);
    let mut named: Box<dyn Iterator<Item = Named<'_>>> = match &policy.body {
        PolicyBody::Bt(bt) => Box::new(bt.nodes.iter().map(|n| (&*n.id, &*n.label, &n.span))),
        PolicyBody::Machine(m) => Box::new(m.states.iter().map(|s| (&*s.name, &*s.label, &s.span))),
    };
    let words = match &policy.body {
        PolicyBody::Bt(_) => ["node id", "name of a node"],
        PolicyBody::Machine(_) => ["state name", "label of a state"],
    };
    if let Some((id, label, span)) = named.find(|(id, label, _)| long(id) || long(label)) {
        return Some(if long(id) {
            too_long(words[0], id, span.clone())
        } else {
            too_long(words[1], label, span.clone())
        });
    }
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

/// The file formats a policy is read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    Toml,
    BtcppXml,
    Scxml,
    /// yasmin (ROS 2) state machine XML.
    Yasmin,
    /// A FlexBE behavior's generated Python (`*_sm.py`; [`flexbe`]).
    Flexbe,
    /// A py_trees DOT render (`.dot`, `.gv`; [`py_trees_dot`]).
    PyTreesDot,
}

/// The format of a file: by its extension (`.toml`, `.scxml`, `.py` for a
/// FlexBE behavior, `.dot`/`.gv` for a py_trees render), else by its
/// first bytes (`<scxml`, `<StateMachine` for yasmin, `<root`, ...); TOML otherwise.
pub fn detect(path: &Path, text: &str) -> FileFormat {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("toml") => return FileFormat::Toml,
        Some(e) if e.eq_ignore_ascii_case("scxml") => return FileFormat::Scxml,
        Some(e) if e.eq_ignore_ascii_case("py") => return FileFormat::Flexbe,
        Some(e) if e.eq_ignore_ascii_case("dot") || e.eq_ignore_ascii_case("gv") => {
            return FileFormat::PyTreesDot;
        }
        _ => {}
    }
    let head = head(text);
    let is_xml_ext = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    if head.contains("<scxml") {
        FileFormat::Scxml
    } else if yasmin::looks_like_yasmin(head) {
        FileFormat::Yasmin
    } else if is_xml_ext || head.trim_start().starts_with('<') {
        FileFormat::BtcppXml
    } else {
        FileFormat::Toml
    }
}

/// What a command-line file holds, read once (so that a pipe or
/// `/dev/stdin` works, and nothing is opened twice).
pub enum Input {
    Policy(FileFormat),
    /// A simulator scenario (`sim`, `validate`).
    Scenario,
    /// An action domain (`plan`, `validate`; docs/guide/plan.md).
    Domain,
}

/// Reads a command-line file once ([`source::read`]: bounded, charged,
/// never blocking on a FIFO) and tells what it holds.
pub fn read_input(
    path: &Path,
    limits: &Limits,
) -> Result<(Arc<SourceFile>, Input), Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = source::read(path, &shown, limits, false)?;
    let input = match detect(path, &file.text) {
        FileFormat::Toml if crate::discover::looks_like_scenario(head(&file.text)) => {
            Input::Scenario
        }
        FileFormat::Toml if crate::discover::looks_like_domain(&file.text) => Input::Domain,
        f => Input::Policy(f),
    };
    Ok((file, input))
}

/// The first 4 KiB of a text (at a character boundary), for sniffing.
pub(crate) fn head(text: &str) -> &str {
    let mut end = text.len().min(4096);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    &text[..end]
}

/// Reads a policy that another file names (a scenario's `file`, a trace's
/// policy), once [`source::resolve`] has placed it inside the root: a
/// regular file that is a policy by its name and first bytes
/// ([`source::check_named`]), else refused quoting none of it.
pub fn load_named(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = source::read(path, &shown, limits, true)?;
    source::check_named(path, &file.text, source::Named::AnyPolicy).map_err(|r| {
        vec![
            Diagnostic::error(format!(
                "`{}`: {}",
                btfsm_core::sanitize::shown(&shown),
                r.message
            ))
            .hint(r.hint),
        ]
    })?;
    let format = detect(path, &file.text);
    load_read(file, path, format, limits)
}

/// Reads a policy from any supported format (see [`detect`]).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = source::read(path, &shown, limits, false)?;
    let format = detect(path, &file.text);
    load_read(file, path, format, limits)
}

/// A policy from a file already read from `path` (see [`read_input`]).
pub fn load_read(
    file: Arc<SourceFile>,
    path: &Path,
    format: FileFormat,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let total = &limits.total_nodes;
    let spent = || {
        vec![
            Diagnostic::error(format!(
                "{}: not read: this command has read more than {} nodes and states in all its policies",
                btfsm_core::sanitize::shown(&path.display().to_string()),
                total.limit()
            ))
            .hint("raise the limit with --max-total-nodes, or name fewer files"),
        ]
    };
    if total.remaining() == 0 {
        return Err(spent());
    }
    let loaded = match format {
        FileFormat::Toml => toml::load_read(&file, path, limits),
        FileFormat::BtcppXml => btcpp_xml::load_read(file, path, limits),
        FileFormat::Scxml => scxml::load_read(file, limits),
        FileFormat::Yasmin => yasmin::load_read(file, path, limits),
        FileFormat::Flexbe => flexbe::load_read(file, limits),
        FileFormat::PyTreesDot => py_trees_dot::load_read(file, limits),
    }?;
    // Every format: node count and nesting depth (the TOML reader has
    // already said where).
    if let Some(mut d) = check_shape(&loaded.policy, limits) {
        d.message = format!("{}: {}", loaded.path, d.message);
        d.span = None;
        return Err(vec![d]);
    }
    let size = match &loaded.policy.body {
        btfsm_model::PolicyBody::Bt(bt) => bt.nodes.len(),
        btfsm_model::PolicyBody::Machine(m) => m.states.len(),
    };
    if !total.charge(size as u64) {
        total.exhaust();
        return Err(spent());
    }
    Ok(loaded)
}

/// The result of reading `file`: the policy with its warnings, or every error
/// followed by the warnings (each in file and source order). `what` names the
/// policy in the fallback message when reading failed without an error.
pub(crate) fn finish(
    file: &Arc<SourceFile>,
    policy: Option<Policy>,
    mut diags: Vec<Diagnostic>,
    what: &str,
) -> Result<Loaded, Vec<Diagnostic>> {
    diags.sort_by_key(|d| {
        (
            d.file.as_ref().map(|f| f.path.clone()),
            d.span.as_ref().map_or(0, |s| s.start),
        )
    });
    // A problem inside a subtree used twice is found twice: say it once.
    let mut seen = std::collections::BTreeSet::new();
    diags.retain(|d| {
        seen.insert((
            d.file.as_ref().map(|f| f.path.clone()),
            d.span.as_ref().map(|s| (s.start, s.end)),
            d.is_error(),
            d.message.clone(),
        ))
    });
    let (mut errors, mut warnings): (Vec<_>, Vec<_>) =
        diags.into_iter().partition(Diagnostic::is_error);
    // At most `MAX_DIAGNOSTICS` of each, the rest counted in one message (the
    // TOML reader already stops keeping them there; the XML readers rely on
    // this), so that a file with a million bad elements prints a bounded
    // report.
    let cap = self::toml::MAX_DIAGNOSTICS;
    let end = file.text.len()..file.text.len();
    if errors.len() > cap + 1 {
        let more = errors.len() - cap;
        errors.truncate(cap);
        errors.push(
            Diagnostic::error(format!(
                "{more} more errors not shown (the first {cap} messages are)"
            ))
            .at(file, end.clone()),
        );
    }
    if warnings.len() > cap + 1 {
        let more = warnings.len() - cap;
        warnings.truncate(cap);
        warnings.push(Diagnostic::warning(format!("{more} more warnings not shown")).at(file, end));
    }
    match policy {
        Some(policy) if errors.is_empty() => Ok(Loaded {
            path: file.path.clone(),
            policy,
            warnings,
            dataflow: None,
        }),
        _ => {
            let mut all = errors;
            if all.is_empty() {
                all.push(Diagnostic::error(format!("invalid {what}")).in_file(file));
            }
            all.extend(warnings);
            Err(all)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_core::diagnostic::SourceFile;

    #[test]
    fn finish_keeps_a_bounded_number_of_messages() {
        let file = SourceFile::new("many.xml", "<root/>");
        let cap = toml::MAX_DIAGNOSTICS;
        let diags: Vec<Diagnostic> = (0..cap * 3)
            .map(|i| Diagnostic::error(format!("problem {i}")).at(&file, 0..1))
            .chain((0..cap * 2).map(|i| Diagnostic::warning(format!("odd {i}")).at(&file, 0..1)))
            .collect();
        let Err(all) = finish(&file, None, diags, "behavior tree") else {
            panic!("errors make it fail");
        };
        let errors: Vec<_> = all.iter().filter(|d| d.is_error()).collect();
        assert_eq!(errors.len(), cap + 1);
        assert_eq!(
            errors[cap].message,
            format!(
                "{} more errors not shown (the first {cap} messages are)",
                cap * 2
            )
        );
        let warnings = all.len() - errors.len();
        assert_eq!(warnings, cap + 1);
        // At the cap exactly, nothing is dropped.
        let diags: Vec<Diagnostic> = (0..=cap)
            .map(|i| Diagnostic::error(format!("problem {i}")).at(&file, 0..1))
            .collect();
        let Err(all) = finish(&file, None, diags, "behavior tree") else {
            panic!("errors make it fail");
        };
        assert_eq!(all.len(), cap + 1);
    }
}
