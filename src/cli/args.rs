//! Raw command-line flags (clap derive).

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "btfsm",
    version,
    about = "Metrics for robot policy structures: Behavior Trees, FSMs and HFSMs",
    long_about = "Metrics for robot policy structures: Behavior Trees, FSMs and HFSMs.\n\nComputes the metrics of Iovino et al., \"Comparison between Behavior Trees and Finite State Machines\": element counts, cyclomatic and essential complexity, graph edit distance and effort.\n\nExit codes: 0 success, 1 a check failed, 2 bad usage or bad input."
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Counts, complexity and Table I estimates of each policy
    Analyze(super::analyze::AnalyzeArgs),
    /// Checks policy files and reports every problem with its position
    Validate(super::validate::ValidateArgs),
    /// Draws a policy as Graphviz DOT (or SVG/PNG with --render)
    Dot(super::dot::DotArgs),
    /// Graph edit distance between two policies (and, for two BTs, the
    /// ordered tree edit distance), with the edit script
    Compare(super::compare::CompareArgs),
    /// Converts a policy into another representation
    Convert(super::convert::ConvertArgs),
    /// Effort (Eq. 4/5) to make an FSM reactive: formula and measured named GED
    Effort(super::effort::EffortArgs),
    /// Reproduces the paper's Tables I-III and effort examples from policies/paper
    Paper(PaperArgs),
    /// The paper's edit operations: insert a BT subtree, add an (H)FSM state
    Edit(Box<EditArgs>),
    /// Runs policies in the planar robot simulator, compares their behavior
    /// and checks the scenario's [expect] (exit 1 when one fails)
    Sim(super::sim::SimArgs),
    /// Ticks a BT against scripted leaf outcomes (BehaviorTree.CPP 4 semantics)
    Tick(super::tick::TickArgs),
    /// Backchains an action domain's goal into a BT, and derives the
    /// fault-tolerant FSM and the HFSM of the same plan (exit 1 when a
    /// precondition conflict no order resolves is left)
    Plan(super::plan::PlanArgs),
    /// Checks policies against coded rules (structure, the paper's
    /// smells, BehaviorTree.CPP ports and blackboard keys); text, JSON,
    /// SARIF or JUnit XML; exit 1 when an error-level finding remains
    Lint(super::lint::LintArgs),
    /// Reviews the policy changes between two git revisions: metrics
    /// before and after, GED, tree distance, changes, new lint findings
    /// and diff drawings, as text, JSON or one pull-request comment; exit
    /// 1 when a gate of the base revision's btfsm.toml fails
    Review(super::review::ReviewArgs),
    /// Reads BehaviorTree.CPP execution logs (.btlog, .db3): `log report`,
    /// `log dot`, `log compare`, `log timeline`
    Log(super::log::LogArgs),
    /// Writes one self-contained HTML page replaying runs: each policy's
    /// diagram coloured by status at a step (RUNNING yellow, SUCCESS green,
    /// FAILURE red), a timeline of the actions, a slider and step buttons;
    /// from a scenario (run here), a `sim --trace` file, a .btlog or a .db3
    View(super::view::ViewArgs),
    /// Tree edit distances of trees in bracket notation, one pair per line
    /// (`{a{b}}<TAB>{a{c}}`): what tests/differential/ted.py and
    /// bench/ted_vs_apted.py drive
    #[command(hide = true)]
    TedPairs(super::ted_pairs::TedPairsArgs),
    /// Prints a shell completion script (e.g. `btfsm completions bash >
    /// ~/.local/share/bash-completion/completions/btfsm`)
    Completions(super::completions::CompletionsArgs),
    /// Prints the man page (roff; `make man` writes target/man/btfsm*.1)
    #[command(hide = true)]
    Man(super::man::ManArgs),
}

impl Command {
    /// The command's input limits, whose `--root` and
    /// `--allow-outside-root` also say where its outputs may go.
    pub(crate) fn limit_args(&self) -> Option<&LimitArgs> {
        use super::log::LogCommand;
        Some(match self {
            Command::Analyze(a) => &a.limits,
            Command::Validate(a) => &a.limits,
            Command::Dot(a) => &a.limits,
            Command::Compare(a) => &a.limits,
            Command::Convert(a) => &a.limits,
            Command::Effort(a) => &a.limits,
            Command::Paper(a) => &a.limits,
            Command::Edit(a) => &a.limits,
            Command::Sim(a) => &a.limits,
            Command::Tick(a) => &a.limits,
            Command::Plan(a) => &a.limits,
            Command::Lint(a) => &a.limits,
            Command::Review(a) => &a.limits,
            Command::Log(a) => match &a.command {
                LogCommand::Report(a) => &a.limits,
                LogCommand::Dot(a) => &a.limits,
                LogCommand::Compare(a) => &a.limits,
                LogCommand::Timeline(a) => &a.limits,
            },
            Command::View(a) => &a.limits,
            Command::TedPairs(a) => &a.limits,
            Command::Completions(_) | Command::Man(_) => return None,
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum CompareMode {
    Structural,
    Labeled,
    Named,
    /// Ordered tree edit distance between two BTs (child order and node
    /// labels count; BT pairs only)
    Tree,
    /// The three GED modes, and `tree` when both policies are BTs
    All,
}

impl CompareMode {
    /// The GED modes selected, in report order (none for `tree`).
    pub(crate) fn ged_modes(self) -> Vec<btfsm_metrics::ged::GedMode> {
        use btfsm_metrics::ged::GedMode;
        match self {
            CompareMode::Structural => vec![GedMode::Structural],
            CompareMode::Labeled => vec![GedMode::Labeled],
            CompareMode::Named => vec![GedMode::Named],
            CompareMode::Tree => Vec::new(),
            CompareMode::All => btfsm_report::compare::modes_of(None),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ConvertTarget {
    /// The paper's BT -> HFSM construction (Fig. 5 -> Fig. 6)
    Hfsm,
    /// The paper's sequential FSM -> fault-tolerant FSM construction (Fig. 2 -> Fig. 4)
    FaultTolerant,
    /// TOML (normalised)
    Toml,
    /// BehaviorTree.CPP XML, format 4 (behavior trees)
    BtcppXml,
    /// SCXML (FSMs and HFSMs)
    Scxml,
    /// Mermaid (flowchart for BTs, stateDiagram-v2 for FSMs and HFSMs), as GitHub renders in markdown
    Mermaid,
}

/// `--assume-leaf`: how to read BehaviorTree.CPP leaves of unknown type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum AssumeLeafArg {
    Action,
    Condition,
}

/// Input limits (documented defaults; see `format::Limits`).
#[derive(Debug, Clone, Args)]
pub(crate) struct LimitArgs {
    /// Largest input file, in bytes (also the total read through subtree includes)
    #[arg(long, default_value_t = btfsm_format::DEFAULT_MAX_FILE_BYTES, hide_short_help = true)]
    pub max_file_bytes: u64,
    /// Most BT nodes or FSM states per policy, subtrees expanded (and most
    /// nodes all policies of the command create by copying subtrees)
    #[arg(long, default_value_t = btfsm_format::DEFAULT_MAX_NODES, hide_short_help = true)]
    pub max_nodes: usize,
    /// Deepest BT or HFSM nesting (the root is at depth 0)
    #[arg(long, default_value_t = btfsm_format::DEFAULT_MAX_DEPTH, hide_short_help = true)]
    pub max_depth: usize,
    /// Longest node id, state name, display name or label, in bytes
    #[arg(long, default_value_t = btfsm_format::DEFAULT_MAX_NAME_BYTES, hide_short_help = true)]
    pub max_name_bytes: usize,
    /// BehaviorTree.CPP TreeNodesModel file declaring node types (repeatable),
    /// e.g. Nav2's nav2_tree_nodes.xml
    #[arg(long = "nodes-model", value_name = "FILE")]
    pub nodes_model: Vec<PathBuf>,
    /// The BehaviorTree.CPP tree to read, by its `<BehaviorTree ID>` (over
    /// `main_tree_to_execute`; needed when a file holds several trees and
    /// names none, as a program names it to BT.CPP's factory); among
    /// several BehaviorTree.CPP files given together, the files that define it
    #[arg(long, value_name = "ID")]
    pub tree: Option<String>,
    /// Read BehaviorTree.CPP leaves of unknown type as actions or conditions
    /// (default: an error listing the known types)
    #[arg(long, value_enum, value_name = "KIND")]
    pub assume_leaf: Option<AssumeLeafArg>,
    /// Most bytes the command reads in all its files (includes, node models,
    /// baselines, traces and repeated arguments each count)
    #[arg(long, default_value_t = btfsm_format::source::DEFAULT_MAX_TOTAL_BYTES, hide_short_help = true)]
    pub max_total_bytes: u64,
    /// Most BT nodes and FSM states the command reads in all its policies
    /// (a directory's files, a scenario's policies); past it no other
    /// policy is parsed
    #[arg(long, default_value_t = btfsm_format::DEFAULT_MAX_TOTAL_NODES, hide_short_help = true)]
    pub max_total_nodes: u64,
    /// Directory that files named by a policy or scenario (subtrees,
    /// includes, scenario policies) must stay inside, and that outputs
    /// typed inside it may not leave through a symbolic link [default: the
    /// git work tree of the file given (for outputs: of the current
    /// directory), else its directory]
    #[arg(long, value_name = "DIR", conflicts_with = "allow_outside_root")]
    pub root: Option<PathBuf>,
    /// Let policies and scenarios name files anywhere (absolute paths, `..`
    /// out of the root), and outputs be written through symbolic links out
    /// of the root or into `.git`: for trusted local use only
    #[arg(long)]
    pub allow_outside_root: bool,
    /// Where ROS package NAME is, for BehaviorTree.CPP's `<include
    /// ros_pkg="NAME">` and yasmin's `package="NAME"` (repeatable; else
    /// AMENT_PREFIX_PATH's share/NAME/, else the package.xml named NAME in
    /// the repository; files stay inside the root)
    #[arg(long = "ros-pkg", value_name = "NAME=DIR", value_parser = parse_ros_pkg)]
    pub ros_pkg: Vec<(String, PathBuf)>,
}

/// `NAME=DIR` of `--ros-pkg`.
fn parse_ros_pkg(s: &str) -> Result<(String, PathBuf), String> {
    match s.split_once('=') {
        Some((n, d)) if !n.is_empty() && !d.is_empty() => Ok((n.to_string(), PathBuf::from(d))),
        _ => Err(
            "expected NAME=DIR, e.g. --ros-pkg nav2_bt_navigator=src/navigation2/nav2_bt_navigator"
                .into(),
        ),
    }
}

/// The prefixes of `AMENT_PREFIX_PATH` (what a sourced ROS 2 workspace
/// sets), in order.
fn ament_prefixes() -> Vec<PathBuf> {
    std::env::var_os("AMENT_PREFIX_PATH")
        .map(|v| {
            std::env::split_paths(&v)
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        })
        .unwrap_or_default()
}

/// How `dot` draws a Behavior Tree: ports, folded subtrees, direction.
#[derive(clap::Args, Debug, Clone)]
pub(crate) struct DotLookArgs {
    /// Draw each BT node's ports under its label (by default they are in
    /// its tooltip only)
    #[arg(long)]
    pub ports: bool,
    /// Draw the subtree of the BT node with this id as one node labelled
    /// with its size (repeatable; ids as `analyze --format json` and
    /// `compare` print them)
    #[arg(long, value_name = "ID", num_args = 1..)]
    pub collapse: Vec<String>,
    /// Fold every BT node at this depth (the root is at depth 0)
    #[arg(long, value_name = "N")]
    pub depth: Option<usize>,
    /// BT SubTrees (BehaviorTree.CPP `<SubTree>`, TOML `subtree`
    /// includes): drawn expanded, or folded into one node each
    #[arg(long, value_enum, default_value_t = SubtreesArg::Expanded)]
    pub subtrees: SubtreesArg,
    /// Layout direction of a BT: auto is top-down unless that is wider than
    /// 2.5:1 and left-to-right is closer to square
    #[arg(long, value_enum, default_value_t = btfsm_render::dot::RankDir::Auto)]
    pub rankdir: btfsm_render::dot::RankDir,
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SubtreesArg {
    Expanded,
    Folded,
}

impl DotLookArgs {
    /// Sets the look on drawing options.
    pub(crate) fn apply(&self, opts: &mut btfsm_render::dot::DotOptions) {
        opts.ports = self.ports;
        opts.collapse = self.collapse.iter().cloned().collect();
        opts.depth = self.depth;
        opts.fold_subtrees = self.subtrees == SubtreesArg::Folded;
        opts.rankdir = self.rankdir;
    }
}

impl LimitArgs {
    pub(crate) fn limits(&self) -> btfsm_format::Limits {
        let read_budget = btfsm_format::source::Budget::new(self.max_total_bytes);
        btfsm_format::Limits {
            max_file_bytes: self.max_file_bytes,
            max_nodes: self.max_nodes,
            max_depth: self.max_depth,
            max_name_bytes: self.max_name_bytes,
            nodes_models: self.nodes_model.clone(),
            assume_leaf: self.assume_leaf.map(|a| match a {
                AssumeLeafArg::Action => btfsm_format::AssumeLeaf::Action,
                AssumeLeafArg::Condition => btfsm_format::AssumeLeaf::Condition,
            }),
            confinement: match (&self.root, self.allow_outside_root) {
                (_, true) => btfsm_format::source::Confinement::Off,
                (Some(r), false) => btfsm_format::source::Confinement::Root(r.clone()),
                (None, false) => btfsm_format::source::Confinement::Auto,
            },
            read_budget: read_budget.clone(),
            expansion_budget: btfsm_format::source::Budget::new(self.max_nodes as u64),
            total_nodes: btfsm_format::source::Budget::new(self.max_total_nodes),
            tree: self.tree.clone(),
            ros: btfsm_format::ros_pkg::RosPackages::new(
                self.ros_pkg.clone(),
                ament_prefixes(),
                Some(read_budget),
            ),
            ..Default::default()
        }
    }
}

/// Flags of `btfsm paper`.
#[derive(Debug, Clone, Args)]
pub(crate) struct PaperArgs {
    /// Output format
    #[arg(long, value_parser = super::format::parser(<btfsm_report::paper::PaperReport as btfsm_core::output::Report>::FORMATS, &[]), default_value = "table")]
    pub format: btfsm_core::output::Format,
    /// CPU-time safety cap of each exact GED (default: derived from the
    /// default work budget, which decides every cell); when it runs out
    /// first the cell shows the certified interval
    #[arg(long, value_name = "MS")]
    pub timeout_ms: Option<u64>,
    /// Exit 1 naming every cell whose computed value departs from DIR/tables/expected.toml
    #[arg(long, conflicts_with = "record")]
    pub check: bool,
    /// Rewrite DIR/tables/expected.toml with the computed values (review the diff)
    #[arg(long)]
    pub record: bool,
    /// Directory of the paper's policies (with tables/published.toml)
    #[arg(long, value_name = "DIR", default_value = "policies/paper")]
    pub policies: PathBuf,
    /// Output file (default: stdout)
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// Flags of `btfsm edit`.
#[derive(Debug, Clone, Args)]
pub(crate) struct EditArgs {
    /// Policy to edit (TOML)
    pub file: PathBuf,
    /// Output file (default: stdout); the summary goes to stderr
    #[arg(short, long, global = true)]
    pub output: Option<PathBuf>,
    #[command(subcommand)]
    pub op: EditOp,
    #[command(flatten)]
    pub limits: LimitArgs,
}

#[derive(Debug, Clone, Subcommand)]
pub(crate) enum EditOp {
    /// Inserts a BT subtree (the root of another BT file) as a child of a node
    InsertSubtree {
        /// Id of the control node that receives the subtree
        #[arg(long, value_name = "ID")]
        parent: String,
        /// Position among the parent's children (0 = first; default: last)
        #[arg(long, value_name = "K")]
        index: Option<usize>,
        /// BT file whose tree is inserted (its node ids are kept)
        #[arg(long, value_name = "SUB.toml")]
        subtree: PathBuf,
        /// Prefix for the inserted node ids (`P/id`), when they would collide
        #[arg(long, value_name = "P")]
        prefix: Option<String>,
    },
    /// Puts a new control node above the root (the paper's Figs. 7c, 7d)
    WrapRoot {
        /// Control node to put above the root
        #[arg(long, value_enum)]
        kind: WrapKind,
        /// Id of the new root
        #[arg(long, value_name = "ID")]
        id: String,
        /// Display name (default: the kind's)
        #[arg(long)]
        name: Option<String>,
    },
    /// Adds an FSM state as the paper's sec. IV-A 1b does (Algorithm 1 for connected states)
    AddState(AddStateArgs),
}

#[derive(Debug, Clone, Args)]
pub(crate) struct AddStateArgs {
    /// How the new state is connected
    #[arg(long, value_enum)]
    pub kind: AddKind,
    /// Name of the new state
    #[arg(long, value_name = "N")]
    pub name: String,
    /// Preceding state (sequential, alternative); connected: file position only.
    /// A name unique in the machine, or a path `Container/State` (HFSM)
    #[arg(long, value_name = "P")]
    pub after: Option<String>,
    /// HFSM: the container to add the state to when there is no --after
    /// (default: the top level)
    #[arg(long = "in", value_name = "CONTAINER")]
    pub within: Option<String>,
    /// Skill the state runs, e.g. Tuck-Arm
    #[arg(long)]
    pub skill: String,
    /// Skill argument, `key=value` (repeatable)
    #[arg(long = "arg", value_name = "KEY=VALUE")]
    pub args: Vec<String>,
    /// Connected: the guard every other state gets to the new one,
    /// e.g. `not Battery-Level(min=20)`
    #[arg(long, value_name = "COND")]
    pub guard: Option<String>,
    /// Label of --guard (default: the condition)
    #[arg(long, value_name = "TEXT")]
    pub guard_label: Option<String>,
    /// The SELECTOR's guard to the new state (sequential; connected: default --guard),
    /// e.g. `In-Hand(object=cube2) & not Arm-Tucked`
    #[arg(long, value_name = "COND")]
    pub selector_guard: Option<String>,
    /// Label of --selector-guard (default: the condition)
    #[arg(long, value_name = "TEXT")]
    pub selector_guard_label: Option<String>,
    /// Position of the SELECTOR's new guard among its guards (default:
    /// sequential: right before the predecessor's; connected: first)
    #[arg(long, value_name = "K")]
    pub selector_guard_index: Option<usize>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum WrapKind {
    Sequence,
    Fallback,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum AddKind {
    /// Between the predecessor and its SUCCESS successor (Figs. 8a, 8c)
    Sequential,
    /// Takes the predecessor's FAILURE arc (Fig. 8b)
    Alternative,
    /// Reached from every other state (Algorithm 1, Fig. 8d)
    Connected,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every subcommand and every argument of every subcommand says what it
    /// is for in `--help` (clap's own `--help`/`--version` aside).
    #[test]
    fn every_subcommand_and_argument_has_help() {
        let mut missing = Vec::new();
        let mut stack = vec![(String::from("btfsm"), Cli::command())];
        while let Some((path, cmd)) = stack.pop() {
            for a in cmd.get_arguments() {
                let id = a.get_id().as_str();
                if id == "help" || id == "version" || a.is_hide_set() {
                    continue;
                }
                if a.get_help().is_none() && a.get_long_help().is_none() {
                    missing.push(format!("{path} {id}"));
                }
            }
            for sub in cmd.get_subcommands() {
                if sub.get_about().is_none() && !sub.is_hide_set() {
                    missing.push(format!("{path} {} (about)", sub.get_name()));
                }
                stack.push((format!("{path} {}", sub.get_name()), sub.clone()));
            }
        }
        assert!(missing.is_empty(), "arguments without help: {missing:#?}");
    }

    /// Clap's own consistency checks (conflicting names, bad defaults).
    #[test]
    fn the_command_line_is_well_formed() {
        Cli::command().debug_assert();
    }
}
