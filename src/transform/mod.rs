//! Transformations between representations (the paper's constructions).

pub mod bt_to_hfsm;
pub mod edit;
pub mod fault_tolerant;

/// Test helper shared by the transforms' and metrics' unit tests.
#[cfg(test)]
pub(crate) fn paper_policy(name: &str) -> crate::model::Policy {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/paper")
        .join(format!("{name}.toml"));
    crate::format::load(&p, &crate::format::Limits::default())
        .unwrap_or_else(|d| panic!("{name}: {d:?}"))
        .policy
}

/// Named GED between two policies' graphs (unit tests).
#[cfg(test)]
pub(crate) fn named_ged(a: &crate::model::Policy, b: &crate::model::Policy) -> u64 {
    use crate::metrics::ged::{GedMode, GedOptions, ged};
    let (ga, gb) = (crate::graph::policy_graph(a), crate::graph::policy_graph(b));
    ged(&ga, &gb, GedMode::Named, &GedOptions::default()).ged
}
