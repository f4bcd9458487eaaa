//! `btfsm analyze FILE|DIR...`: counts, complexity and Table I estimates of
//! each policy (SPEC §2, §7), and the complexity gate (`--max`,
//! `--baseline`, `--max-increase`) that exits 1 naming every limit passed.

use super::args::LimitArgs;
use super::io::{each_input, emit_report};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_core::sanitize::shown;
use btfsm_format::Limits;
use btfsm_report::gate::{Baseline, Gate, Limit};
use btfsm_report::{Analysis, analyze};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub(crate) struct AnalyzeArgs {
    /// Policy files (TOML, BehaviorTree.CPP XML, SCXML, yasmin XML, FlexBE
    /// `*_sm.py`, py_trees DOT renders), `-`
    /// for stdin, or directories (every policy file below, sorted)
    #[arg(required = true)]
    pub(super) files: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(Analysis::FORMATS, &[]), default_value = "table")]
    pub(super) format: Format,
    /// Exit 1 when a policy's METRIC is above N, e.g. `--max cc=30`
    /// (repeatable; metrics: vertices, edges, graphical_elements,
    /// active_elements, cc, essential_cc)
    #[arg(long = "max", value_name = "METRIC=N")]
    pub(super) max: Vec<Limit>,
    /// A previous `analyze --format json` output: exit 1 when a policy's
    /// metric grew over it by more than --max-increase allows
    #[arg(long, value_name = "OLD.json")]
    pub(super) baseline: Option<PathBuf>,
    /// How much METRIC may grow over the baseline (repeatable; default
    /// `cc=0` and `essential_cc=0`)
    #[arg(long = "max-increase", value_name = "METRIC=N", requires = "baseline")]
    pub(super) max_increase: Vec<Limit>,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(a: AnalyzeArgs) -> u8 {
    let limits = a.limits.limits();
    let Some(gate) = gate(a.max, a.baseline.as_deref(), a.max_increase, &limits) else {
        return EXIT_BAD_INPUT;
    };
    // A report for the files that load, an error for each that does not,
    // and exit 2 at the end when any failed.
    // Each policy is dropped once measured: memory is bounded by the
    // largest file and the rows, not by the files' sizes in all.
    let mut reports = Vec::new();
    let Some(failed) = each_input(&a.files, &limits, &mut |l| reports.push(analyze(&l))) else {
        return EXIT_BAD_INPUT;
    };
    let code = emit_report(None, &Analysis(&reports), a.format);
    if failed {
        return EXIT_BAD_INPUT;
    }
    if code != EXIT_OK || gate.is_empty() {
        return code;
    }
    check_gate(&gate, &reports)
}

/// The complexity gate of `analyze`, with its baseline read (`None`: the
/// baseline is unreadable, said on stderr).
fn gate(
    max: Vec<Limit>,
    baseline: Option<&Path>,
    max_increase: Vec<Limit>,
    limits: &Limits,
) -> Option<Gate> {
    let baseline = match baseline {
        None => None,
        Some(p) => {
            let shown = p.display().to_string();
            let file = match btfsm_format::toml::read_source(p, &shown, limits) {
                Ok(f) => f,
                Err(diags) => {
                    for d in diags {
                        eprint!("{d}");
                    }
                    return None;
                }
            };
            match Baseline::parse(&shown, &file.text) {
                Ok(b) => Some(b),
                Err(d) => {
                    eprint!("{d}");
                    return None;
                }
            }
        }
    };
    Some(Gate {
        max,
        baseline,
        max_increase,
    })
}

/// Prints the gate's verdict on stderr: exit 1 naming every metric over its
/// limit.
fn check_gate(gate: &Gate, reports: &[btfsm_report::PolicyReport]) -> u8 {
    let r = gate.check(reports);
    let mut rules: Vec<String> = gate.max.iter().map(|l| format!("--max {l}")).collect();
    if let Some(b) = &gate.baseline {
        let grow: Vec<String> = gate
            .increase_limits()
            .iter()
            .map(|l| format!("{} +{}", l.metric.key(), l.value))
            .collect();
        rules.push(format!("growth over `{}`: {}", b.path, grow.join(", ")));
        for f in &r.new_policies {
            eprintln!(
                "note: `{}` is not in the baseline; only its ceilings are checked",
                shown(f)
            );
        }
    }
    let n = reports.len();
    let policies = if n == 1 { "policy" } else { "policies" };
    if r.violations.is_empty() {
        eprintln!(
            "complexity gate: {n} {policies} within limits ({})",
            rules.join("; ")
        );
        return EXIT_OK;
    }
    for v in &r.violations {
        eprint!("{}", Diagnostic::error(format!("complexity gate: {v}")));
    }
    eprint!(
        "{}",
        Diagnostic::error(format!(
            "complexity gate: {} limit{} exceeded in {n} {policies} ({})",
            r.violations.len(),
            if r.violations.len() == 1 { "" } else { "s" },
            rules.join("; ")
        ))
    );
    EXIT_CHECK_FAILED
}
