//! The table and JSON of a symbolic `sim` (one run per policy, or Monte
//! Carlo), with the pairwise verdicts.

use super::run::{McPair, McPolicy, SymRun, first_difference};
use super::scenario::SymScenario;
use btfsm_core::sanitize::shown;
use btfsm_core::table::Table;

/// One run per policy: outcomes, steps, actions, and per pair whether the
/// runs match (else the first differing action).
pub fn render_runs(s: &SymScenario, runs: &[SymRun], json: bool) -> String {
    let pairs: Vec<(usize, usize, Option<usize>)> = (0..runs.len())
        .flat_map(|a| (a + 1..runs.len()).map(move |b| (a, b)))
        .map(|(a, b)| (a, b, first_difference(&runs[a], &runs[b])))
        .collect();
    if json {
        #[derive(serde::Serialize)]
        struct Pair<'a> {
            a: &'a str,
            b: &'a str,
            matches: bool,
            first_difference: Option<usize>,
        }
        #[derive(serde::Serialize)]
        struct Out<'a> {
            scenario: &'a str,
            domain: &'a str,
            goal: Vec<String>,
            runs: &'a [SymRun],
            pairs: Vec<Pair<'a>>,
        }
        let out = Out {
            scenario: &s.name,
            domain: &s.domain.name,
            goal: s.goal.iter().map(ToString::to_string).collect(),
            runs,
            pairs: pairs
                .iter()
                .map(|&(a, b, d)| Pair {
                    a: &runs[a].policy,
                    b: &runs[b].policy,
                    matches: d.is_none(),
                    first_difference: d,
                })
                .collect(),
        };
        let mut t =
            btfsm_core::sanitize::json(serde_json::to_string_pretty(&out).expect("serializable"));
        t.push('\n');
        return t;
    }
    let mut out = format!(
        "scenario `{}` (symbolic, domain `{}`): goal {}\n\n",
        shown(&s.name),
        shown(&s.domain.name),
        shown(
            &s.goal
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        )
    );
    let mut t = Table::new(&["policy", "outcome", "steps", "actions (succeeded / failed)"]);
    for r in runs {
        let ok = r.actions.iter().filter(|a| a.2).count();
        t.row(vec![
            shown(&r.policy).into_owned(),
            r.outcome.as_str().to_string(),
            r.steps.to_string(),
            format!("{ok} / {}", r.actions.len() - ok),
        ]);
    }
    out.push_str(&t.render());
    for r in runs {
        out.push_str(&format!(
            "\n{}: {}\n",
            shown(&r.policy),
            shown(&r.effective().join(", "))
        ));
    }
    if !pairs.is_empty() {
        out.push('\n');
        let mut t = Table::new(&["pair", "verdict"]);
        for (a, b, d) in pairs {
            let v = match d {
                None => "match".to_string(),
                Some(i) => format!("differ from action {}", i + 1),
            };
            t.row(vec![
                format!("{} vs {}", shown(&runs[a].policy), shown(&runs[b].policy)),
                v,
            ]);
        }
        out.push_str(&t.render());
    }
    out
}

/// Monte Carlo figures per policy and pair.
pub fn render_mc(
    s: &SymScenario,
    runs: u32,
    seed: u64,
    policies: &[McPolicy],
    pairs: &[McPair],
    json: bool,
) -> String {
    if json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            scenario: &'a str,
            domain: &'a str,
            seed: u64,
            runs: u32,
            policies: &'a [McPolicy],
            pairs: &'a [McPair],
        }
        let out = Out {
            scenario: &s.name,
            domain: &s.domain.name,
            seed,
            runs,
            policies,
            pairs,
        };
        let mut t =
            btfsm_core::sanitize::json(serde_json::to_string_pretty(&out).expect("serializable"));
        t.push('\n');
        return t;
    }
    let mut out = format!(
        "scenario `{}` (symbolic, domain `{}`): {runs} episodes (seed {seed})\n\n",
        shown(&s.name),
        shown(&s.domain.name)
    );
    let mut t = Table::new(&[
        "policy",
        "success rate",
        "95% CI",
        "failures",
        "chattering",
        "timeouts",
    ]);
    for p in policies {
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
    if !pairs.is_empty() {
        out.push('\n');
        let mut t = Table::new(&[
            "pair",
            "behavior match rate",
            "95% CI",
            "first diverging episode (seed)",
        ]);
        for p in pairs {
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
