//! The table and JSON of a symbolic `sim` (one run per policy, or Monte
//! Carlo), with the pairwise verdicts.

use super::run::{McPair, McPolicy, McResult, SymRun, first_difference};
use super::scenario::SymScenario;
use crate::scenario::expect::{ExpectResult, Status};
use btfsm_core::output::{Format, Report};
use btfsm_core::sanitize::shown;
use btfsm_core::table::Table;

/// A pair's verdict of one run per policy, under the planar verdict's
/// keys (`a`, `b`, `match`, `first_divergence`).
#[derive(Debug, serde::Serialize)]
pub struct PairVerdict<'a> {
    pub a: &'a str,
    pub b: &'a str,
    #[serde(rename = "match")]
    pub matches: bool,
    pub first_divergence: Option<SymDivergence>,
}

/// Where two symbolic runs first differ: the index in their lists of
/// successful actions, the two actions there (`None` past a list's end:
/// `missing`; both present: `action`; both ended: `outcome`).
#[derive(Debug, serde::Serialize)]
pub struct SymDivergence {
    pub index: usize,
    pub a: Option<String>,
    pub b: Option<String>,
    /// `action`, `missing` or `outcome`.
    pub kind: &'static str,
}

impl SymDivergence {
    fn of(a: &SymRun, b: &SymRun, index: usize) -> Self {
        let (x, y) = (a.effective(), b.effective());
        let (x, y) = (
            x.get(index).map(|s| s.to_string()),
            y.get(index).map(|s| s.to_string()),
        );
        let kind = match (&x, &y) {
            (Some(_), Some(_)) => "action",
            (None, None) => "outcome",
            _ => "missing",
        };
        SymDivergence {
            index,
            a: x,
            b: y,
            kind,
        }
    }
}

/// What a symbolic `sim` prints for one run per policy: outcomes, steps,
/// actions, and per pair whether the runs match (else the first differing
/// action).
#[derive(Debug, serde::Serialize)]
pub struct RunsReport<'a> {
    pub scenario: &'a str,
    pub domain: &'a str,
    pub goal: Vec<String>,
    pub runs: &'a [SymRun],
    pub verdicts: Vec<PairVerdict<'a>>,
    /// The scenario's `[expect]`, checked (empty when it has none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub expectations: Vec<ExpectResult>,
    /// How many expectations failed or could not be decided (`sim` exits 1
    /// when this is not 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub expectations_failed: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl<'a> RunsReport<'a> {
    pub fn new(s: &'a SymScenario, runs: &'a [SymRun]) -> Self {
        let verdicts = (0..runs.len())
            .flat_map(|a| (a + 1..runs.len()).map(move |b| (a, b)))
            .map(|(a, b)| {
                let d = first_difference(&runs[a], &runs[b]);
                PairVerdict {
                    a: &runs[a].policy,
                    b: &runs[b].policy,
                    matches: d.is_none(),
                    first_divergence: d.map(|i| SymDivergence::of(&runs[a], &runs[b], i)),
                }
            })
            .collect();
        let expectations = super::expect::check(&s.expect, runs);
        let expectations_failed = (expectations.iter())
            .filter(|e| e.status != Status::Pass)
            .count();
        RunsReport {
            scenario: &s.name,
            domain: &s.domain.name,
            goal: s.goal.iter().map(ToString::to_string).collect(),
            runs,
            verdicts,
            expectations,
            expectations_failed,
        }
    }

    fn table(&self) -> String {
        let mut out = format!(
            "scenario `{}` (symbolic, domain `{}`): goal {}\n\n",
            shown(self.scenario),
            shown(self.domain),
            shown(&self.goal.join(", "))
        );
        let mut t = Table::new(&["policy", "outcome", "steps", "actions (succeeded / failed)"]);
        for r in self.runs {
            let ok = r.actions.iter().filter(|a| a.2).count();
            t.row(vec![
                shown(&r.policy).into_owned(),
                r.outcome.as_str().to_string(),
                r.steps.to_string(),
                format!("{ok} / {}", r.actions.len() - ok),
            ]);
        }
        out.push_str(&t.render());
        for r in self.runs {
            out.push_str(&format!(
                "\n{}: {}\n",
                shown(&r.policy),
                shown(&r.effective().join(", "))
            ));
        }
        if !self.verdicts.is_empty() {
            out.push('\n');
            let mut t = Table::new(&["pair", "verdict"]);
            for p in &self.verdicts {
                let v = match &p.first_divergence {
                    None => "match".to_string(),
                    Some(d) => format!("differ from action {}", d.index + 1),
                };
                t.row(vec![format!("{} vs {}", shown(p.a), shown(p.b)), v]);
            }
            out.push_str(&t.render());
        }
        crate::report::expectations_text(
            &mut out,
            &self.expectations,
            self.expectations_failed,
            false,
        );
        out
    }
}

impl Report for RunsReport<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Json => json(self),
            _ => self.table(),
        }
    }
}

/// What a symbolic `sim --runs N` prints: Monte Carlo figures per policy
/// and pair.
#[derive(Debug, serde::Serialize)]
pub struct McReport<'a> {
    pub scenario: &'a str,
    pub domain: &'a str,
    pub seed: u64,
    /// Episodes the figures cover.
    pub runs: u32,
    pub policies: &'a [McPolicy],
    pub pairs: &'a [McPair],
}

impl<'a> McReport<'a> {
    pub fn new(s: &'a SymScenario, seed: u64, mc: &'a McResult) -> Self {
        McReport {
            scenario: &s.name,
            domain: &s.domain.name,
            seed,
            runs: mc.runs,
            policies: &mc.policies,
            pairs: &mc.pairs,
        }
    }

    fn table(&self) -> String {
        let mut out = format!(
            "scenario `{}` (symbolic, domain `{}`): {} episodes (seed {})\n\n",
            shown(self.scenario),
            shown(self.domain),
            self.runs,
            self.seed
        );
        let mut t = Table::new(&[
            "policy",
            "success rate",
            "95% CI",
            "failures",
            "chattering",
            "timeouts",
        ]);
        for p in self.policies {
            t.row(vec![
                shown(&p.policy).into_owned(),
                format!("{:.3}", p.success_rate),
                format!("[{:.4}, {:.4}]", p.success_ci95[0], p.success_ci95[1]),
                p.failures.to_string(),
                p.chattering.to_string(),
                p.timeouts.to_string(),
            ]);
        }
        out.push_str(&t.render());
        if !self.pairs.is_empty() {
            out.push('\n');
            let mut t = Table::new(&[
                "pair",
                "behavior match rate",
                "95% CI",
                "first diverging episode (seed)",
            ]);
            for p in self.pairs {
                t.row(vec![
                    format!("{} vs {}", shown(&p.a), shown(&p.b)),
                    format!("{:.3}", p.match_rate),
                    format!("[{:.4}, {:.4}]", p.match_ci95[0], p.match_ci95[1]),
                    match p.first_diverging {
                        Some((e, sd)) => format!("{e} (--seed {sd})"),
                        None => "-".into(),
                    },
                ]);
            }
            out.push_str(&t.render());
        }
        out
    }
}

impl Report for McReport<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Json => json(self),
            _ => self.table(),
        }
    }
}

/// Pretty JSON, sanitised, with a final newline.
fn json<T: serde::Serialize>(v: &T) -> String {
    let mut t = btfsm_core::sanitize::json(serde_json::to_string_pretty(v).expect("serializable"));
    t.push('\n');
    t
}
