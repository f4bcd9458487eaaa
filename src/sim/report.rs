//! The report of `btfsm sim` (SPEC §7): per policy the outcome, executed skills,
//! final world and duration, and the behavior-match verdicts between policies;
//! as a table or as JSON (a stable contract documented in the README). Also the
//! `--runs` summary and the `--trace` file.

use super::run::McStats;
use super::trace::{FRECHET_POINTS, Run, Verdict, verdicts};
use crate::report::table::Table;
use serde::Serialize;

/// What `sim SCENARIO --format json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct SimReport {
    pub scenario: String,
    pub file: String,
    pub seed: u64,
    pub dt: f64,
    pub policies: Vec<Run>,
    pub verdicts: Vec<Verdict>,
}

impl SimReport {
    pub fn new(scenario: &str, file: &str, seed: u64, dt: f64, runs: Vec<Run>) -> Self {
        Self::with_points(scenario, file, seed, dt, runs, FRECHET_POINTS)
    }

    /// The report, with trajectory distances on at most `points` points per
    /// trajectory (fewer under a wall-clock budget).
    pub fn with_points(
        scenario: &str,
        file: &str,
        seed: u64,
        dt: f64,
        runs: Vec<Run>,
        points: usize,
    ) -> Self {
        let verdicts = verdicts(&runs, points);
        SimReport {
            scenario: scenario.into(),
            file: file.into(),
            seed,
            dt,
            policies: runs,
            verdicts,
        }
    }

    pub fn json(&self) -> String {
        let mut s =
            crate::sanitize::json(serde_json::to_string_pretty(self).expect("serializable"));
        s.push('\n');
        s
    }

    /// The trace file: the report plus every step of every run.
    pub fn trace_json(&self) -> String {
        #[derive(Serialize)]
        struct TracedRun<'a> {
            #[serde(flatten)]
            run: &'a Run,
            trajectory: Vec<[f64; 2]>,
            trace: &'a [super::trace::Step],
        }
        #[derive(Serialize)]
        struct TraceFile<'a> {
            scenario: &'a str,
            file: &'a str,
            seed: u64,
            dt: f64,
            policies: Vec<TracedRun<'a>>,
            verdicts: &'a [Verdict],
        }
        let t = TraceFile {
            scenario: &self.scenario,
            file: &self.file,
            seed: self.seed,
            dt: self.dt,
            policies: self
                .policies
                .iter()
                .map(|r| TracedRun {
                    run: r,
                    trajectory: r.trajectory.iter().map(|p| [p.0, p.1]).collect(),
                    trace: &r.trace,
                })
                .collect(),
            verdicts: &self.verdicts,
        };
        let mut s = crate::sanitize::json(serde_json::to_string(&t).expect("serializable"));
        s.push('\n');
        s
    }

    pub fn table(&self) -> String {
        let mut out = format!(
            "scenario `{}` (seed {}, step {} s)\n\n",
            self.scenario, self.seed, self.dt
        );
        let mut t = Table::new(&[
            "policy",
            "kind",
            "outcome",
            "goal",
            "completion s",
            "duration s",
            "distance m",
            "skills",
        ]);
        for r in &self.policies {
            t.row(vec![
                r.policy.clone(),
                match &r.convert {
                    Some(c) => format!("{c} (from bt)"),
                    None => r.kind.clone(),
                },
                r.outcome.as_str().into(),
                match r.goal_met {
                    Some(true) => "met".into(),
                    Some(false) => "not met".into(),
                    None => "-".into(),
                },
                r.completion_s.map_or("-".into(), |c| format!("{c:.1}")),
                format!("{:.1}", r.duration_s),
                format!("{:.2}", r.distance_m),
                r.skills.len().to_string(),
            ]);
        }
        out.push_str(&t.render());
        for r in &self.policies {
            out.push_str(&format!(
                "\n{} — {}: {}\n",
                r.policy,
                r.outcome.as_str(),
                r.reason
            ));
            for (i, s) in r.skills.iter().enumerate() {
                out.push_str(&format!(
                    "  {:>3}. {:>7.1} s  {}\n",
                    i + 1,
                    s.start,
                    s.text()
                ));
            }
            let w = &r.final_world;
            let objs: Vec<String> = w
                .objects
                .iter()
                .map(|(n, o)| {
                    let place = if o.held {
                        "held".to_string()
                    } else {
                        o.at.clone()
                            .unwrap_or_else(|| format!("({:.2}, {:.2})", o.x, o.y))
                    };
                    format!("{n} {place}")
                })
                .collect();
            out.push_str(&format!(
                "  final: robot {}, battery {:.1}%, holding {}, arm {}, {}\n",
                w.robot_at
                    .clone()
                    .unwrap_or_else(|| format!("({:.2}, {:.2})", w.robot[0], w.robot[1])),
                w.battery,
                w.holding.as_deref().unwrap_or("nothing"),
                if w.arm_tucked { "tucked" } else { "out" },
                objs.join(", ")
            ));
        }
        if !self.verdicts.is_empty() {
            out.push_str("\nbehavior match (same executed skills with arguments and outcomes, same final world):\n");
            for v in &self.verdicts {
                let what = if v.matches {
                    "MATCH".to_string()
                } else {
                    let mut why = Vec::new();
                    if !v.same_skills {
                        why.push("skills differ");
                    }
                    if !v.same_final_world {
                        why.push("final worlds differ");
                    }
                    format!("DIFFER ({})", why.join(", "))
                };
                out.push_str(&format!(
                    "  {} vs {}: {what}, trajectory distance {:.3} m\n",
                    v.a, v.b, v.trajectory_distance_m
                ));
                if let Some(d) = &v.first_divergence {
                    out.push_str(&format!(
                        "    first divergence at skill {}: {} | {}\n",
                        d.index + 1,
                        d.a.as_deref().unwrap_or("(none)"),
                        d.b.as_deref().unwrap_or("(none)")
                    ));
                }
            }
        }
        out
    }
}

/// What `sim SCENARIO --runs N --format json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct McReport {
    pub scenario: String,
    pub seed: u64,
    pub runs: u32,
    pub threads: usize,
    pub millis: u128,
    pub policies: Vec<McStats>,
}

impl McReport {
    pub fn json(&self) -> String {
        let mut s =
            crate::sanitize::json(serde_json::to_string_pretty(self).expect("serializable"));
        s.push('\n');
        s
    }

    pub fn table(&self) -> String {
        let mut out = format!(
            "scenario `{}`: {} episodes (seed {}) on {} threads in {} ms\n\n",
            self.scenario, self.runs, self.seed, self.threads, self.millis
        );
        let mut t = Table::new(&[
            "policy",
            "success rate",
            "failures",
            "chattering",
            "timeouts",
            "mean completion s",
            "recharges",
            "mean low-battery latency s",
        ]);
        let f = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:.2}"));
        for p in &self.policies {
            t.row(vec![
                p.policy.clone(),
                format!("{:.3}", p.success_rate),
                p.failures.to_string(),
                p.chattering.to_string(),
                p.timeouts.to_string(),
                f(p.mean_completion_s),
                p.recharges.to_string(),
                f(p.mean_recharge_latency_s),
            ]);
        }
        out.push_str(&t.render());
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Limits;
    use std::path::Path;

    fn report(scenario: &str) -> SimReport {
        let s = super::super::scenario::load(Path::new(scenario), &Limits::default()).unwrap();
        let runs = super::super::run::run_scenario(&s, false);
        SimReport::new(&s.name, scenario, s.seed, s.dt, runs)
    }

    #[test]
    fn table_of_exp1_pick_fails() {
        insta::assert_snapshot!(report("policies/scenarios/exp1-pick-fails.toml").table());
    }

    #[test]
    fn json_has_the_contract_fields() {
        let r = report("policies/scenarios/exp2-recharge.toml");
        let v: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
        for k in ["scenario", "file", "seed", "dt", "policies", "verdicts"] {
            assert!(v.get(k).is_some(), "{k}");
        }
        let p = &v["policies"][0];
        for k in [
            "policy",
            "file",
            "kind",
            "convert",
            "outcome",
            "reason",
            "goal_met",
            "steps",
            "completion_s",
            "duration_s",
            "distance_m",
            "skills",
            "events",
            "final_world",
            "recharge_latency_s",
        ] {
            assert!(p.get(k).is_some(), "{k}");
        }
        assert!(p.get("trace").is_none() && p.get("trajectory").is_none());
        let t: serde_json::Value = serde_json::from_str(&r.trace_json()).unwrap();
        assert!(t["policies"][0]["trace"].as_array().unwrap().is_empty());
        assert!(
            !t["policies"][0]["trajectory"]
                .as_array()
                .unwrap()
                .is_empty()
        );
        assert_eq!(v["verdicts"][0]["match"], true);
    }
}
