//! `btfsm effort FILE|DIR...`: Eq. 4/5 at the M_s and M_fc detected in each
//! FSM beside the measured effort, the named GED to the fault-tolerant FSM
//! generated from it (paper sec. IV-B).

use super::EXIT_BAD_INPUT;
use super::args::LimitArgs;
use super::io::{emit_report, load_inputs};
use btfsm_core::output::{Format, Report};
use btfsm_metrics::ged::GedOptions;
use btfsm_report::effort::{EffortRow, EffortTable, effort};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(crate) struct EffortArgs {
    /// FSM files (any policy format), `-` for stdin, or directories
    #[arg(required = true)]
    pub(super) files: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(EffortTable::FORMATS, &[]), default_value = "table")]
    pub(super) format: Format,
    /// CPU-time safety cap of the structural GED per policy (default:
    /// derived from the default work budget, which decides the result);
    /// when it runs out first the result is a certified interval (the named
    /// GED has no budget)
    #[arg(long, value_name = "MS")]
    pub(super) timeout_ms: Option<u64>,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(a: EffortArgs) -> u8 {
    let Some((loaded, failed)) = load_inputs(&a.files, &a.limits.limits()) else {
        return EXIT_BAD_INPUT;
    };
    let mut opts = GedOptions::default();
    if let Some(ms) = a.timeout_ms {
        opts.timeout = std::time::Duration::from_millis(ms);
    }
    let rows: Vec<EffortRow> = loaded
        .iter()
        .map(|l| EffortRow::new(&l.path, &l.policy.name, &effort(&l.policy, &opts).0))
        .collect();
    let code = emit_report(None, &EffortTable(&rows), a.format);
    if failed { EXIT_BAD_INPUT } else { code }
}
