//! `btfsm log report LOG`: per-node figures and coverage of a
//! BehaviorTree.CPP `FileLogger2` log (src/log/); `--min-coverage` makes it
//! a CI gate (exit 1 below it).

use super::commands::emit_text;
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use crate::log::report;
use clap::{Args, Subcommand, ValueEnum};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct LogArgs {
    #[command(subcommand)]
    pub command: LogCommand,
}

#[derive(Debug, Subcommand)]
pub enum LogCommand {
    /// Per node: activations, status changes, time RUNNING; node and branch
    /// coverage (exit 1 below --min-coverage)
    Report(ReportArgs),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LogFormat {
    Table,
    Json,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// A BehaviorTree.CPP 4 FileLogger2 log (.btlog), or `-` for stdin
    pub log: PathBuf,
    /// Output format
    #[arg(long, value_enum, default_value_t = LogFormat::Table)]
    pub format: LogFormat,
    /// Exit 1 when node or branch coverage is below this ratio (0 to 1)
    #[arg(long, value_name = "X")]
    pub min_coverage: Option<f64>,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub fn execute(a: LogArgs) -> u8 {
    let LogCommand::Report(a) = a.command;
    if let Some(x) = a.min_coverage
        && !(0.0..=1.0).contains(&x)
    {
        eprintln!("error: --min-coverage must be a ratio from 0 to 1, found {x}");
        return EXIT_BAD_INPUT;
    }
    let shown = a.log.display().to_string();
    let reader: Box<dyn std::io::Read> = if a.log.as_os_str() == "-" {
        Box::new(std::io::stdin())
    } else {
        match std::fs::File::open(&a.log) {
            Ok(f) => Box::new(f),
            Err(e) => {
                eprintln!(
                    "error: {}: cannot read this file: {e}",
                    crate::sanitize::shown(&shown)
                );
                return EXIT_BAD_INPUT;
            }
        }
    };
    let limits = a.limits.limits();
    let r = match report::report(&shown, reader, limits.max_file_bytes) {
        Ok(r) => r,
        Err(e) => {
            eprintln!(
                "error: {}: {}\n  = hint: a BehaviorTree.CPP 4 FileLogger2 log (.btlog) is the header `BTCPP4-FileLogger2`, the tree XML, a timestamp and 9-byte records",
                crate::sanitize::shown(&shown),
                crate::sanitize::shown(&e.to_string())
            );
            return EXIT_BAD_INPUT;
        }
    };
    let text = match a.format {
        LogFormat::Json => {
            let mut s =
                crate::sanitize::json(serde_json::to_string_pretty(&r).expect("serializable"));
            s.push('\n');
            s
        }
        LogFormat::Table => report::render_table(&r),
    };
    let code = emit_text(None, text);
    if code != EXIT_OK {
        return code;
    }
    match a.min_coverage {
        Some(x) if r.node_coverage.ratio < x || r.branch_coverage.ratio < x => {
            eprintln!(
                "error: coverage below {x}: node {:.3}, branch {:.3}",
                r.node_coverage.ratio, r.branch_coverage.ratio
            );
            EXIT_CHECK_FAILED
        }
        _ => EXIT_OK,
    }
}
