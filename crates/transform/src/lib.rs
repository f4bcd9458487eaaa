//! Transformations between representations (the paper's constructions).

pub mod bt_to_hfsm;
pub mod edit;
pub mod fault_tolerant;
#[cfg(test)]
mod fault_tolerant_tests;

/// Test helper shared by the transforms' and metrics' unit tests.
#[cfg(test)]
pub(crate) fn paper_policy(name: &str) -> btfsm_model::Policy {
    let p = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("policies/paper")
        .join(format!("{name}.toml"));
    btfsm_format::load(&p, &btfsm_format::Limits::default())
        .unwrap_or_else(|d| panic!("{name}: {d:?}"))
        .policy
}

/// Named GED between two policies' graphs (unit tests).
#[cfg(test)]
pub(crate) fn named_ged(a: &btfsm_model::Policy, b: &btfsm_model::Policy) -> u64 {
    use btfsm_metrics::ged::{GedMode, GedOptions, ged};
    let (ga, gb) = (
        btfsm_model::graph::policy_graph(a),
        btfsm_model::graph::policy_graph(b),
    );
    ged(&ga, &gb, GedMode::Named, &GedOptions::default()).ged
}
