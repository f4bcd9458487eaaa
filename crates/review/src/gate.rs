//! The review's gates, from the `[review]` table of the BASE revision's
//! `btfsm.toml` (a pull request cannot loosen the gates it is judged by):
//!
//! ```toml
//! [review]
//! max = { cc = 30, essential_cc = 10 }           # head's value at most
//! max-increase = { cc = 5, nodes = 20 }          # head minus base at most
//! fail-on = ["unknown-node-type", "load-error"]  # new findings that fail
//! ```
//!
//! Metrics are those of `analyze` (SPEC §7; `nodes` is `vertices`) and,
//! for `max`, the change's `ged` (the paper's named GED, Eq. 2) and `ted`
//! (the ordered tree edit distance). A file added by the change is held to
//! `max` only; `fail-on` takes lint rule codes. Any gate failed: exit 1.

use super::{FileReview, Metrics};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Metric names a gate takes.
const METRICS: &[&str] = &[
    "vertices",
    "nodes",
    "edges",
    "graphical_elements",
    "active_elements",
    "cc",
    "essential_cc",
    "ged",
    "ted",
];

/// The gates in force.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Gates {
    /// The `btfsm.toml` they were read from (in base), if any.
    pub config: Option<String>,
    pub max: BTreeMap<String, i64>,
    pub max_increase: BTreeMap<String, i64>,
    pub fail_on: Vec<String>,
}

/// One gate a file did not pass.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Failure {
    pub file: String,
    /// `max.cc`, `max-increase.nodes`, `fail-on.unknown-node-type`.
    pub gate: String,
    pub message: String,
}

#[derive(serde::Deserialize)]
struct RawFile {
    #[serde(default)]
    review: Option<RawReview>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawReview {
    #[serde(default)]
    max: BTreeMap<toml::Spanned<String>, i64>,
    #[serde(default, rename = "max-increase")]
    max_increase: BTreeMap<toml::Spanned<String>, i64>,
    #[serde(default, rename = "fail-on")]
    fail_on: Vec<toml::Spanned<String>>,
}

/// Reads the `[review]` table of `file` (a `btfsm.toml`).
pub fn read(file: &Arc<SourceFile>) -> Result<Gates, Diagnostic> {
    btfsm_core::toml_budget::check(
        file,
        btfsm_core::toml_budget::DEFAULT_MAX_TOKENS,
        "btfsm.toml holds a few gates: a few hundred tokens",
    )?;
    let hint = "[review] holds `max` and `max-increase` (tables of METRIC = N) and `fail-on` (a list of lint rule codes)";
    let raw: RawFile = toml::from_str(&file.text).map_err(|e| {
        let d = Diagnostic::error(format!("invalid btfsm.toml: {}", e.message().trim())).hint(hint);
        match e.span() {
            Some(s) => d.at(file, s),
            None => d,
        }
    })?;
    let mut gates = Gates {
        config: Some(file.path.clone()),
        ..Gates::default()
    };
    let Some(r) = raw.review else {
        return Ok(gates);
    };
    for (table, out, name) in [
        (&r.max, &mut gates.max, "max"),
        (&r.max_increase, &mut gates.max_increase, "max-increase"),
    ] {
        for (k, &v) in table {
            let key = k.get_ref().as_str();
            let allowed = name == "max" || !matches!(key, "ged" | "ted");
            if !METRICS.contains(&key) || !allowed {
                return Err(Diagnostic::error(format!(
                    "[review] {name}: unknown metric `{}`",
                    btfsm_core::sanitize::shown(key)
                ))
                .at(file, k.span())
                .hint(suggest(
                    key,
                    METRICS
                        .iter()
                        .copied()
                        .filter(|m| name == "max" || !["ged", "ted"].contains(m)),
                )));
            }
            out.insert(key.to_string(), v);
        }
    }
    for c in &r.fail_on {
        if btfsm_lint::rule(c.get_ref()).is_none() {
            return Err(Diagnostic::error(format!(
                "[review] fail-on: unknown lint rule `{}`",
                btfsm_core::sanitize::shown(c.get_ref())
            ))
            .at(file, c.span())
            .hint(suggest(
                c.get_ref(),
                btfsm_lint::RULES.iter().map(|r| r.code),
            )));
        }
        gates.fail_on.push(c.get_ref().clone());
    }
    Ok(gates)
}

/// A metric's value in `m`.
fn value(m: &Metrics, key: &str) -> Option<i64> {
    Some(match key {
        "vertices" | "nodes" => m.vertices,
        "edges" => m.edges,
        "graphical_elements" => m.graphical_elements,
        "active_elements" => m.active_elements,
        "cc" => m.cc,
        "essential_cc" => m.essential_cc,
        _ => return None,
    })
}

impl Gates {
    /// Whether any gate is set.
    pub fn is_empty(&self) -> bool {
        self.max.is_empty() && self.max_increase.is_empty() && self.fail_on.is_empty()
    }

    /// The gates `f` does not pass.
    pub fn check(&self, f: &FileReview) -> Vec<Failure> {
        let mut out = Vec::new();
        let fail = |gate: String, message: String| Failure {
            file: f.path.clone(),
            gate,
            message,
        };
        for (key, &limit) in &self.max {
            let v = match key.as_str() {
                "ged" => f.ged.map(|g| i64::try_from(g).unwrap_or(i64::MAX)),
                "ted" => f
                    .ted
                    .as_ref()
                    .map(|t| i64::try_from(t.distance).unwrap_or(i64::MAX)),
                k => f.after.as_ref().and_then(|m| value(m, k)),
            };
            if let Some(v) = v.filter(|&v| v > limit) {
                out.push(fail(
                    format!("max.{key}"),
                    format!("{key} is {v}, above the maximum {limit}"),
                ));
            }
        }
        if let (Some(a), Some(b)) = (&f.before, &f.after) {
            for (key, &limit) in &self.max_increase {
                let (Some(x), Some(y)) = (value(a, key), value(b, key)) else {
                    continue;
                };
                let grew = y.saturating_sub(x);
                if grew > limit {
                    out.push(fail(
                        format!("max-increase.{key}"),
                        format!("{key} grew by {grew} ({x} → {y}), more than the {limit} allowed"),
                    ));
                }
            }
        }
        for n in &f.new_findings {
            if self.fail_on.iter().any(|c| c == n.code) {
                out.push(fail(
                    format!("fail-on.{}", n.code),
                    format!("new `{}` finding: {}", n.code, n.message),
                ));
            }
        }
        out
    }
}
