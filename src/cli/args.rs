//! Raw command-line flags (clap derive).

use crate::report::OutputFormat;
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "btfsm",
    version,
    about = "Metrics for robot policy structures: Behavior Trees, FSMs and HFSMs",
    long_about = "Metrics for robot policy structures: Behavior Trees, FSMs and HFSMs.\n\nComputes the metrics of Iovino et al., \"Comparison between Behavior Trees and Finite State Machines\": element counts, cyclomatic and essential complexity, graph edit distance and effort.\n\nExit codes: 0 success, 1 a check failed, 2 bad usage or bad input."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Counts, complexity and Table I estimates of each policy
    Analyze {
        /// Policy files (TOML)
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = OutputFormat::Table)]
        format: OutputFormat,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Checks policy files and reports every problem with its position
    Validate {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Draws a policy as Graphviz DOT (or SVG/PNG with --render)
    Dot {
        file: PathBuf,
        /// Output file (default: stdout)
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Render with Graphviz's `dot` instead of printing DOT
        #[arg(long, value_enum)]
        render: Option<crate::render::dot::RenderFormat>,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Converts a policy into another representation
    Convert {
        file: PathBuf,
        /// Target representation
        #[arg(long, value_enum)]
        to: ConvertTarget,
        /// Output file (default: stdout)
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[command(flatten)]
        limits: LimitArgs,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ConvertTarget {
    /// The paper's BT -> HFSM construction (Fig. 5 -> Fig. 6)
    Hfsm,
    /// TOML (normalised)
    Toml,
    /// BehaviorTree.CPP XML, format 4 (behavior trees)
    BtcppXml,
    /// SCXML (FSMs and HFSMs)
    Scxml,
}

/// `--assume-leaf`: how to read BehaviorTree.CPP leaves of unknown type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AssumeLeafArg {
    Action,
    Condition,
}

/// Input limits (documented defaults; see `format::Limits`).
#[derive(Debug, Clone, Args)]
pub struct LimitArgs {
    /// Largest input file, in bytes
    #[arg(long, default_value_t = 64 * 1024 * 1024, hide_short_help = true)]
    pub max_file_bytes: u64,
    /// Most BT nodes or FSM states per policy, subtrees expanded
    #[arg(long, default_value_t = 2_000_000, hide_short_help = true)]
    pub max_nodes: usize,
    /// BehaviorTree.CPP TreeNodesModel file declaring node types (repeatable),
    /// e.g. Nav2's nav2_tree_nodes.xml
    #[arg(long = "nodes-model", value_name = "FILE")]
    pub nodes_model: Vec<PathBuf>,
    /// Read BehaviorTree.CPP leaves of unknown type as actions or conditions
    /// (default: an error listing the known types)
    #[arg(long, value_enum, value_name = "KIND")]
    pub assume_leaf: Option<AssumeLeafArg>,
}

impl LimitArgs {
    pub fn limits(&self) -> crate::format::Limits {
        crate::format::Limits {
            max_file_bytes: self.max_file_bytes,
            max_nodes: self.max_nodes,
            nodes_models: self.nodes_model.clone(),
            assume_leaf: self.assume_leaf.map(|a| match a {
                AssumeLeafArg::Action => crate::format::AssumeLeaf::Action,
                AssumeLeafArg::Condition => crate::format::AssumeLeaf::Condition,
            }),
            ..Default::default()
        }
    }
}
