//! `btfsm validate FILE|DIR...`: reads every policy, scenario and action
//! domain given (directories walked) and reports every problem with its
//! position, or `ok` with what the file holds; nothing is computed.
//! BehaviorTree.CPP files given together resolve each other's SubTrees, as
//! `analyze` reads them.

use super::args::LimitArgs;
use super::io::{note_skipped, print_diagnostics, reported};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_core::sanitize::shown;
use btfsm_format::{self as format, Limits};
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, Args)]
pub(crate) struct ValidateArgs {
    /// Policy or scenario files, `-` for stdin, or directories (every
    /// policy and scenario file below, sorted)
    #[arg(required = true)]
    pub(super) files: Vec<PathBuf>,
    /// Skip the files named that hold no policy, scenario or domain, as
    /// those found below a directory are (a pre-commit hook is given every
    /// changed .xml and .toml file: a ROS package.xml, a Cargo.toml)
    #[arg(long)]
    pub(super) only_policies: bool,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(a: ValidateArgs) -> u8 {
    let limits = a.limits.limits();
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    let inputs = match format::discover::expand(&a.files) {
        Ok(i) => super::io::only_policies(i, a.only_policies),
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    // BehaviorTree.CPP files given together (a folder) resolve each other's
    // SubTrees, as `analyze` reads them and BehaviorTree.CPP's factory
    // registers every file it loads.
    let (limits, only) = match super::io::with_companions(&inputs, &limits) {
        Ok(x) => x,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    let (mut failed, mut skipped) = (false, 0usize);
    for (i, input) in inputs.iter().enumerate() {
        // Past the command's node budget, one message for the rest.
        if limits.total_nodes.remaining() == 0 {
            let _ = write!(
                err,
                "{}",
                Diagnostic::error(format!(
                    "{} files not validated: this command has read more than {} nodes and states in all",
                    inputs.len() - i,
                    limits.total_nodes.limit()
                ))
                .hint("raise the limit with --max-total-nodes, or name fewer files")
            );
            failed = true;
            break;
        }
        if let Some(only) = &only
            && super::io::is_btcpp_candidate(&input.path)
            && !only.contains(&input.path)
        {
            continue; // a companion of the files that define `--tree`
        }
        // Read once; a scenario is validated as `sim` reads it (its
        // policies included), without running it.
        match format::discover::read(input, &limits) {
            Ok((file, Some(what))) => {
                failed |= !validate_one(&mut err, &input.path, file, what, &limits);
            }
            Ok((_, None)) => skipped += 1,
            Err(diags) => {
                failed = true;
                print_diagnostics(&mut err, &diags);
            }
        }
    }
    note_skipped(&mut err, skipped);
    let none = inputs.len() == skipped && !a.only_policies;
    if none {
        let _ = write!(
            err,
            "{}",
            Diagnostic::error("no policy or scenario file below the directories given")
        );
    }
    if failed || none {
        EXIT_BAD_INPUT
    } else {
        EXIT_OK
    }
}

/// Validates one file read as `what`, printing `ok (...)` or its problems;
/// whether it is valid.
fn validate_one(
    err: &mut impl Write,
    f: &Path,
    file: Arc<SourceFile>,
    what: format::Input,
    limits: &Limits,
) -> bool {
    let base = f.parent().unwrap_or(Path::new(""));
    let shown_path = || shown(&f.display().to_string()).into_owned();
    let said = match what {
        format::Input::Policy(fmt) => {
            return match reported(format::load_read(file, f, fmt, limits), err) {
                Some(l) => {
                    let _ = writeln!(
                        err,
                        "{}: ok ({} `{}`, {} warning{})",
                        shown(&l.path),
                        l.policy.kind(),
                        shown(&l.policy.name),
                        l.warnings.len(),
                        if l.warnings.len() == 1 { "" } else { "s" },
                    );
                    true
                }
                None => false,
            };
        }
        format::Input::Domain => btfsm_plan::load(&file).map(|d| {
            format!(
                "{}: ok (action domain `{}`, {} predicates, {} actions, {} task{})",
                shown_path(),
                shown(&d.name),
                d.predicates.len(),
                d.actions.len(),
                d.tasks.len() + 1,
                if d.tasks.is_empty() { "" } else { "s" }
            )
        }),
        format::Input::Scenario if btfsm_sim::symbolic::looks_symbolic(&file.text) => {
            btfsm_sim::symbolic::scenario::parse(&file, base, limits).map(|s| {
                format!(
                    "{}: ok (symbolic scenario `{}`, domain `{}`, {} polic{})",
                    shown_path(),
                    shown(&s.name),
                    shown(&s.domain.name),
                    s.policies.len(),
                    if s.policies.len() == 1 { "y" } else { "ies" }
                )
            })
        }
        format::Input::Scenario => btfsm_sim::scenario::parse(&file, base, limits).map(|s| {
            print_diagnostics(err, &s.warnings);
            format!(
                "{}: ok (scenario `{}`, {} polic{})",
                shown_path(),
                shown(&s.name),
                s.policies.len(),
                if s.policies.len() == 1 { "y" } else { "ies" }
            )
        }),
    };
    match said {
        Ok(line) => {
            let _ = writeln!(err, "{line}");
            true
        }
        Err(diags) => {
            print_diagnostics(err, &diags);
            false
        }
    }
}
