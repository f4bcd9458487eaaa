//! Helpers of the crate's unit tests: scenarios read from text, their
//! policy paths resolved against the bundled `policies/scenarios` folder.

use crate::scenario::Scenario;
use btfsm_core::diagnostic::SourceFile;
use btfsm_format::Limits;
use std::path::Path;

/// The goal of Experiment 1 (cube2 from the east table to the delivery
/// station) and its world, with `rest` (policies, disturbances) after them.
pub(crate) fn deliver(rest: &str) -> String {
    format!(
        "{}{rest}",
        r#"goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
objects = { cube2 = { at = "east-table" } }
"#
    )
}

/// A valid scenario from `text` (panics on an invalid one).
pub(crate) fn scenario(text: &str) -> Scenario {
    let f = SourceFile::new("t.toml", text);
    crate::scenario::parse(
        &f,
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        )),
        &Limits::default(),
    )
    .expect("valid scenario")
}
