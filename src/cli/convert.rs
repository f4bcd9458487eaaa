//! `btfsm convert FILE --to T`: a policy in another representation — the
//! TOML format, BehaviorTree.CPP XML or SCXML (`format::*_write`), a Mermaid
//! diagram, the HFSM of a BT (Fig. 5 → Fig. 6) or the fault-tolerant FSM of
//! a sequential one (Fig. 2 → Fig. 4) — written to `-o` or stdout.

use super::EXIT_BAD_INPUT;
use super::args::{ConvertTarget, LimitArgs};
use super::io::{emit_text, error_with_hint, fail, load_one};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use btfsm_format::Loaded;
use btfsm_model::Policy;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub(crate) struct ConvertArgs {
    /// Policy file (any format), or `-` for stdin
    pub(super) file: PathBuf,
    /// Target representation
    #[arg(long, value_enum)]
    pub(super) to: ConvertTarget,
    /// Output file (default: stdout)
    #[arg(short, long)]
    pub(super) output: Option<PathBuf>,
    /// With --to fault-tolerant: the action domain giving the skills'
    /// preconditions and effects (default: the built-in
    /// policies/domains/moma.toml)
    #[arg(long, value_name = "DOMAIN.toml")]
    pub(super) domain: Option<PathBuf>,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

/// Why the HFSM construction refused a BT.
const HFSM_HINT: &str = "the construction covers sequence, fallback (with or without memory), inverter, force_success, force_failure and leaves";
/// Why the fault-tolerant construction refused an FSM.
const FAULT_TOLERANT_HINT: &str = "the construction needs a flat FSM whose action states run skills the domain has actions for (--domain; built in: policies/domains/moma.toml)";

pub(super) fn run(a: ConvertArgs) -> u8 {
    if a.domain.is_some() && a.to != ConvertTarget::FaultTolerant {
        return fail(Diagnostic::error(
            "--domain applies to --to fault-tolerant only",
        ));
    }
    let limits = a.limits.limits();
    let domain = match &a.domain {
        None => None,
        Some(path) => match super::plan::read_domain(path, &limits) {
            Some(d) => Some(d),
            None => return EXIT_BAD_INPUT,
        },
    };
    let Some(l) = load_one(&a.file, &limits) else {
        return EXIT_BAD_INPUT;
    };
    let policy = match a.to {
        ConvertTarget::Toml => l.policy,
        ConvertTarget::BtcppXml | ConvertTarget::Scxml => {
            return to_xml(&l.policy, a.to, a.output.as_deref());
        }
        ConvertTarget::Mermaid => {
            return emit_text(
                a.output.as_deref(),
                btfsm_render::mermaid::policy_mermaid(&l.policy),
            );
        }
        ConvertTarget::FaultTolerant => {
            let d = domain
                .as_ref()
                .unwrap_or_else(|| btfsm_plan::domain::builtin());
            match btfsm_transform::fault_tolerant::fault_tolerant_policy_with(&l.policy, d) {
                Ok(p) => p,
                Err(errs) => {
                    for e in errs {
                        fail(error_with_hint(
                            format!("{}: {e}", shown(&l.path)),
                            FAULT_TOLERANT_HINT,
                        ));
                    }
                    return EXIT_BAD_INPUT;
                }
            }
        }
        ConvertTarget::Hfsm => match to_hfsm(&l) {
            Some(p) => p,
            None => return EXIT_BAD_INPUT,
        },
    };
    // Only what reads back: a machine the TOML format can nest, within the
    // file size limit.
    match btfsm_format::toml_write::write_policy_within(&policy, a.limits.max_file_bytes) {
        Ok(text) => emit_text(a.output.as_deref(), text),
        Err(e) => fail(error_with_hint(
            format!("{}: {e}", shown(&l.path)),
            "SCXML has no nesting limit: convert a machine with --to scxml (a BT more than 39 levels deep has no HFSM in TOML)",
        )),
    }
}

/// The HFSM of a BT (Fig. 5 → Fig. 6), warning about every node whose
/// memory the construction does not keep; `None` after its errors.
fn to_hfsm(l: &Loaded) -> Option<Policy> {
    if let btfsm_model::PolicyBody::Bt(bt) = &l.policy.body {
        for n in btfsm_transform::bt_to_hfsm::memory_nodes(bt) {
            let node = &bt.nodes[n];
            eprint!(
                "{}",
                Diagnostic::warning(format!(
                    "{}: `{}` node `{}` becomes a container re-entered at its first state every tick: the HFSM counts as the paper's construction but does not keep the node's memory",
                    shown(&l.path),
                    node.kind.keyword(),
                    shown(&node.id)
                ))
            );
        }
    }
    match btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&l.policy) {
        Ok(p) => Some(p),
        Err(errs) => {
            for e in errs {
                fail(error_with_hint(e, HFSM_HINT));
            }
            None
        }
    }
}

/// Writes `p` as BehaviorTree.CPP XML or SCXML to `output` (or stdout).
pub(super) fn to_xml(p: &Policy, to: ConvertTarget, output: Option<&Path>) -> u8 {
    let text = match to {
        ConvertTarget::BtcppXml => btfsm_format::btcpp_xml_write::write_policy(p).map_err(|e| {
            (
                e.to_string(),
                "convert a machine with --to scxml (or --to toml)",
            )
        }),
        _ => btfsm_format::scxml_write::write_policy(p)
            .map_err(|e| (e.to_string(), "convert a behavior tree with --to btcpp-xml")),
    };
    match text {
        Ok(t) => emit_text(output, t),
        Err((msg, hint)) => fail(error_with_hint(msg, hint)),
    }
}
