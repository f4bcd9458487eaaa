//! `btfsm convert --to btcpp-xml | scxml`: writes a policy in an ecosystem
//! format (`format::btcpp_xml_write`, `format::scxml_write`).

use super::EXIT_BAD_INPUT;
use super::args::ConvertTarget;
use btfsm_model::Policy;
use std::path::Path;

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
        Ok(t) => super::commands::emit_text(output, t),
        Err((msg, hint)) => {
            eprintln!(
                "error: {}\n  = hint: {hint}",
                btfsm_core::sanitize::shown_max(&msg.to_string(), 1000)
            );
            EXIT_BAD_INPUT
        }
    }
}
