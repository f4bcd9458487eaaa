//! `btfsm sim --format csv` (SPEC §7: `--format csv` wherever figures are
//! printed): one row per policy with the figures of the table (outcome,
//! goal, completion and duration, distance, skills, steps), and with
//! `--runs N` one row per policy with the Monte Carlo figures. The
//! verdicts between policies (and `--runs`' match rates per pair) are not
//! rows of this table: they are in `table`, `json` and `markdown`.
//! Fields from input are quoted and neutralised by
//! [`btfsm_core::sanitize::csv_cell`].

use super::report::{McReport, SimReport};
use btfsm_core::sanitize::csv_cell as csv_field;
use std::fmt::Write;

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v}"))
}

impl SimReport {
    /// One row per policy run.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "scenario,seed,policy,file,kind,convert,outcome,goal_met,completion_s,duration_s,distance_m,skills,steps\n",
        );
        for r in &self.policies {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&self.scenario),
                self.seed,
                csv_field(&r.policy),
                csv_field(&r.file),
                csv_field(&r.kind),
                csv_field(r.convert.as_deref().unwrap_or("")),
                r.outcome.as_str(),
                r.goal_met.map_or(String::new(), |g| g.to_string()),
                opt(r.completion_s),
                r.duration_s,
                r.distance_m,
                r.skills.len(),
                r.steps
            );
        }
        s
    }
}

impl McReport {
    /// One row per policy over the episodes.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "scenario,seed,episodes,policy,successes,success_rate,success_ci95_low,success_ci95_high,failures,chattering,timeouts,mean_completion_s,completion_p10_s,completion_p50_s,completion_p90_s,recharges,mean_recharge_latency_s\n",
        );
        for p in &self.policies {
            let q = p.completion_quantiles_s;
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&self.scenario),
                self.seed,
                self.runs,
                csv_field(&p.policy),
                p.successes,
                p.success_rate,
                p.success_ci95[0],
                p.success_ci95[1],
                p.failures,
                p.chattering,
                p.timeouts,
                opt(p.mean_completion_s),
                opt(q.map(|q| q[0])),
                opt(q.map(|q| q[1])),
                opt(q.map(|q| q[2])),
                p.recharges,
                opt(p.mean_recharge_latency_s)
            );
        }
        s
    }
}
