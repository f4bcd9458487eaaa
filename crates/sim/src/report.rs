//! The report of `btfsm sim` (SPEC §7): per policy the outcome, executed skills,
//! final world and duration, and the behavior-match verdicts between policies;
//! as a table or as JSON (a stable contract documented in docs/guide/sim.md). Also the
//! `--runs` summary and the `--trace` file.

use super::monte_carlo::{McStats, PairStats};
use super::scenario::expect::{ExpectResult, Status};
use super::sensitivity::Sensitivity;
use super::trace::{FRECHET_POINTS, Run, Verdict, verdicts_within};
use btfsm_core::output::{Format, Report};
use btfsm_core::table::Table;
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
    /// Pairs whose verdict was not computed: the wall-clock budget
    /// (`--timeout-ms`) ran out first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped_verdicts: Vec<[String; 2]>,
    /// The scenario's `[expect]`, checked (empty when it has none).
    pub expectations: Vec<ExpectResult>,
    /// How many expectations failed or could not be decided (`sim` exits 1
    /// when this is not 0).
    pub expectations_failed: usize,
    /// With `--sensitivity` (or an expectation that failed): which
    /// policy-independent settings reverse which verdict.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensitivity: Option<Sensitivity>,
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
        Self::within(scenario, file, seed, dt, runs, points, None)
    }

    /// The report, its verdicts computed until `deadline` (the others are
    /// listed in `skipped_verdicts`).
    pub fn within(
        scenario: &str,
        file: &str,
        seed: u64,
        dt: f64,
        runs: Vec<Run>,
        points: usize,
        deadline: Option<std::time::Instant>,
    ) -> Self {
        let (verdicts, skipped_verdicts) = verdicts_within(&runs, points, deadline);
        SimReport {
            scenario: scenario.into(),
            file: file.into(),
            seed,
            dt,
            policies: runs,
            verdicts,
            skipped_verdicts,
            expectations: Vec::new(),
            expectations_failed: 0,
            sensitivity: None,
        }
    }

    /// Checks the scenario's expectations against the runs and verdicts;
    /// `cut[i]`: the wall-clock budget cut run `i` short.
    pub fn check(&mut self, expect: &[super::scenario::expect::Expectation], cut: &[bool]) {
        self.expectations =
            super::scenario::expect::check(expect, &self.policies, &self.verdicts, cut);
        self.expectations_failed = (self.expectations.iter())
            .filter(|e| e.status != Status::Pass)
            .count();
    }

    pub fn json(&self) -> String {
        let mut s =
            btfsm_core::sanitize::json(serde_json::to_string_pretty(self).expect("serializable"));
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
            #[serde(skip_serializing_if = "<[_]>::is_empty")]
            skipped_verdicts: &'a [[String; 2]],
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
            skipped_verdicts: &self.skipped_verdicts,
        };
        let mut s = btfsm_core::sanitize::json(serde_json::to_string(&t).expect("serializable"));
        s.push('\n');
        s
    }

    /// The report as text: a table of the runs, each run's skills and
    /// final world, the verdicts, and the expectations.
    pub fn table(&self) -> String {
        let mut out = format!(
            "scenario `{}` (seed {}, step {} s)\n\n",
            self.scenario, self.seed, self.dt
        );
        out.push_str(&self.runs_table());
        for r in &self.policies {
            run_details(&mut out, r);
        }
        self.verdicts_text(&mut out);
        self.skipped_text(&mut out);
        expectations_text(
            &mut out,
            &self.expectations,
            self.expectations_failed,
            false,
        );
        if let Some(x) = &self.sensitivity {
            x.text(&mut out, false);
        }
        out
    }

    /// The verdicts as [`crate::sensitivity`] compares them.
    pub fn verdict_values(&self) -> Vec<(String, String)> {
        crate::sensitivity::run_verdicts(&self.policies, &self.verdicts, &self.expectations)
    }

    /// Adds the sensitivity report, and names beside each expectation that
    /// does not hold the flips under which it would.
    pub fn set_sensitivity(&mut self, x: Sensitivity) {
        attach_reversals(&mut self.expectations, &x);
        self.sensitivity = Some(x);
    }

    /// One row per run: kind, outcome, goal, times, distance, skills.
    fn runs_table(&self) -> String {
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
        t.render()
    }

    /// The behavior-match verdicts, with why a pair differs and where it
    /// first diverged.
    fn verdicts_text(&self, out: &mut String) {
        if self.verdicts.is_empty() {
            return;
        }
        let (tol_s, tol_m, shift_s) =
            (self.verdicts.iter()).fold((0.0f64, 0.0f64, 0.0f64), |(s, m, h), v| {
                (
                    s.max(v.tolerance_s),
                    m.max(v.pose_tolerance_m),
                    h.max(v.max_time_shift_s),
                )
            });
        out.push_str(&format!("\nbehavior match (same executed skills with arguments and results, started within {tol_s} s; robots within {tol_m} m at equal times, shifted by up to {shift_s} s; same goal outcome; same final world):\n"));
        for v in &self.verdicts {
            let what = if v.matches {
                "MATCH".to_string()
            } else {
                let mut why = Vec::new();
                if !v.same_skills {
                    why.push("skills differ");
                }
                if !v.same_outcome {
                    why.push("outcomes differ");
                }
                if !v.same_final_world {
                    why.push("final worlds differ");
                }
                if !v.same_motion {
                    why.push("motion differs");
                }
                format!("DIFFER ({})", why.join(", "))
            };
            let shift = if v.time_shift_s == 0.0 {
                String::new()
            } else {
                format!(" shifted by {} s", v.time_shift_s)
            };
            out.push_str(&format!(
                "  {} vs {}: {what}, trajectory distance {:.3} m at equal times{shift} ({:.3} m between the paths)\n",
                v.a, v.b, v.trajectory_distance_m, v.path_distance_m
            ));
            if let Some(d) = &v.first_divergence {
                out.push_str(&format!("    first divergence {}\n", d.summary()));
            }
            if let Some(t) = v.worlds_diverge_s {
                out.push_str(&format!("    worlds diverge at {t} s\n"));
            }
        }
    }

    /// The verdicts the wall-clock budget left out (the first ten named).
    fn skipped_text(&self, out: &mut String) {
        if self.skipped_verdicts.is_empty() {
            return;
        }
        let n = self.skipped_verdicts.len();
        let shown: Vec<String> = (self.skipped_verdicts.iter().take(10))
            .map(|[a, b]| format!("{a} vs {b}"))
            .collect();
        out.push_str(&format!(
            "\n{n} verdict{} skipped, the wall-clock budget ran out first: {}{}\n",
            if n == 1 { "" } else { "s" },
            shown.join("; "),
            if n > 10 {
                format!("; and {} more", n - 10)
            } else {
                String::new()
            }
        ));
    }
}

/// Names, beside each expectation of `x`'s verdicts that does not hold,
/// the flips under which it would.
fn attach_reversals(expectations: &mut [ExpectResult], x: &Sensitivity) {
    for e in expectations.iter_mut() {
        if e.status != Status::Pass {
            e.reversed_by = x.reversing(&format!("expect {}", e.name));
        }
    }
}

/// The expectations checked (planar or symbolic): how many hold, and each
/// one's status, with the settings under which one that fails would hold;
/// as text, or as a markdown list (names escaped).
pub(crate) fn expectations_text(
    out: &mut String,
    expectations: &[ExpectResult],
    failed: usize,
    md: bool,
) {
    if expectations.is_empty() {
        return;
    }
    out.push_str(&format!(
        "\nexpectations: {} of {} hold\n{}",
        expectations.len() - failed,
        expectations.len(),
        if md { "\n" } else { "" }
    ));
    let cell = |t: &str| {
        if md {
            btfsm_core::sanitize::markdown_cell(t)
        } else {
            t.to_string()
        }
    };
    for e in expectations {
        let st = match (e.status, md) {
            (Status::Pass, true) => "- ok",
            (Status::Fail, true) => "- **FAIL**",
            (Status::Undecided, true) => "- **UNDECIDED**",
            (Status::Pass, false) => "  ok  ",
            (Status::Fail, false) => "  FAIL",
            (Status::Undecided, false) => "  UNDECIDED",
        };
        out.push_str(&format!("{st} {} ({})", cell(&e.name), cell(&e.found)));
        if !e.reversed_by.is_empty() {
            out.push_str(&format!(
                "; would hold with {}",
                cell(&e.reversed_by.join(" or "))
            ));
        }
        out.push('\n');
    }
}

/// A run's outcome and reason, its executed skills, and its final world.
fn run_details(out: &mut String, r: &Run) {
    out.push_str(&format!(
        "\n{} — {}: {}\n  (after SUCCESS: {}; after FAILURE: {})\n",
        r.policy,
        r.outcome.as_str(),
        r.reason,
        r.after_success,
        r.after_failure
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

/// What `sim SCENARIO --runs N --format json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct McReport {
    pub scenario: String,
    pub seed: u64,
    pub runs: u32,
    pub threads: usize,
    pub millis: u128,
    pub policies: Vec<McStats>,
    /// Per pair of policies, the rate of episodes whose behavior matched.
    pub pairs: Vec<PairStats>,
    /// The scenario's `[expect]` on rates (`success_rate`, `match_rate`),
    /// checked on these figures (absent when it has none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub expectations: Vec<ExpectResult>,
    /// How many of them failed or are undecided (`sim` exits 1 when not 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub expectations_failed: usize,
    /// With `--sensitivity`: which policy-independent settings reverse
    /// which verdict.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensitivity: Option<Sensitivity>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl McReport {
    pub fn json(&self) -> String {
        let mut s =
            btfsm_core::sanitize::json(serde_json::to_string_pretty(self).expect("serializable"));
        s.push('\n');
        s
    }

    pub fn table(&self) -> String {
        self.render(false)
    }

    /// The same tables in GitHub-flavoured markdown (a paper's or a pull
    /// request's table).
    pub fn markdown(&self) -> String {
        self.render(true)
    }

    fn render(&self, md: bool) -> String {
        // The scenario's name is the input's: a code span (inert on
        // GitHub: issue 33) in markdown, one escaped line in the table.
        let name = if md {
            btfsm_core::sanitize::markdown_code(&self.scenario)
        } else {
            format!("`{}`", btfsm_core::sanitize::shown(&self.scenario))
        };
        let mut out = format!(
            "scenario {name}: {} episodes (seed {}) on {} threads in {} ms\n\n",
            self.runs, self.seed, self.threads, self.millis
        );
        let head = [
            "policy",
            "success rate",
            "95% CI",
            "failures",
            "chattering",
            "timeouts",
            "completion s (p10 / p50 / p90)",
            "recharges",
            "mean low-battery latency s",
        ];
        let f = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:.2}"));
        let rows: Vec<Vec<String>> = (self.policies.iter())
            .map(|p| {
                vec![
                    p.policy.clone(),
                    format!("{:.3}", p.success_rate),
                    format!("[{:.4}, {:.4}]", p.success_ci95[0], p.success_ci95[1]),
                    p.failures.to_string(),
                    p.chattering.to_string(),
                    p.timeouts.to_string(),
                    p.completion_quantiles_s.map_or("-".into(), |q| {
                        format!("{:.1} / {:.1} / {:.1}", q[0], q[1], q[2])
                    }),
                    p.recharges.to_string(),
                    f(p.mean_recharge_latency_s),
                ]
            })
            .collect();
        out.push_str(&table(md, &head, rows));
        if !self.pairs.is_empty() {
            out.push('\n');
            let head = [
                "pair",
                "behavior match rate",
                "95% CI",
                "moved alike",
                "first diverging episode (seed)",
            ];
            let rows = (self.pairs.iter())
                .map(|p| {
                    vec![
                        format!("{} vs {}", p.a, p.b),
                        format!("{:.3}", p.match_rate),
                        format!("[{:.4}, {:.4}]", p.match_ci95[0], p.match_ci95[1]),
                        format!("{:.3}", p.moved_alike_rate),
                        p.first_divergence
                            .as_ref()
                            .map_or("-".into(), |d| format!("{} (--seed {})", d.episode, d.seed)),
                    ]
                })
                .collect();
            out.push_str(&table(md, &head, rows));
        }
        expectations_text(&mut out, &self.expectations, self.expectations_failed, md);
        if let Some(x) = &self.sensitivity {
            x.text(&mut out, md);
        }
        out
    }

    /// Adds the sensitivity report, and names beside each expectation that
    /// does not hold the flips under which it would.
    pub fn set_sensitivity(&mut self, x: Sensitivity) {
        attach_reversals(&mut self.expectations, &x);
        self.sensitivity = Some(x);
    }
}

impl Report for SimReport {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json, Format::Csv];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Json => self.json(),
            Format::Csv => self.csv(),
            _ => self.table(),
        }
    }
}

impl Report for McReport {
    const FORMATS: &'static [Format] =
        &[Format::Table, Format::Json, Format::Markdown, Format::Csv];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Json => self.json(),
            Format::Csv => self.csv(),
            Format::Markdown => self.markdown(),
            _ => self.table(),
        }
    }
}

/// A table as text, or as markdown with every cell escaped.
fn table(md: bool, head: &[&str], rows: Vec<Vec<String>>) -> String {
    if md {
        let cell = |c: &str| btfsm_core::sanitize::markdown_cell(c);
        let mut out = format!("| {} |\n", head.join(" | "));
        out.push_str(&format!("|{}\n", "---|".repeat(head.len())));
        for r in rows {
            let cells: Vec<String> = r.iter().map(|c| cell(c)).collect();
            out.push_str(&format!("| {} |\n", cells.join(" | ")));
        }
        out
    } else {
        let mut t = Table::new(head);
        for r in rows {
            t.row(r);
        }
        t.render()
    }
}

/// Writes the `--trace` file as the runs go (see [`SimReport::trace_json`]
/// for the same content in memory): the scenario's fields, then per policy
/// its steps as they are made, its whole trajectory and the run's fields,
/// then the verdicts. Memory holds one step at a time; the first write
/// error is kept and returned by [`TraceWriter::finish`].
pub struct TraceWriter<W: std::io::Write> {
    w: W,
    runs: usize,
    steps: usize,
    err: Option<std::io::Error>,
}

impl<W: std::io::Write> TraceWriter<W> {
    pub fn new(w: W, scenario: &str, file: &str, seed: u64, dt: f64) -> Self {
        let mut t = TraceWriter {
            w,
            runs: 0,
            steps: 0,
            err: None,
        };
        #[derive(Serialize)]
        struct Head<'a> {
            scenario: &'a str,
            file: &'a str,
            seed: u64,
            dt: f64,
        }
        let head = serde_json::to_string(&Head {
            scenario,
            file,
            seed,
            dt,
        })
        .expect("serializable");
        let head = btfsm_core::sanitize::json(head);
        // The object without its closing brace.
        t.put(&head.as_bytes()[..head.len() - 1]);
        t.put(b",\"policies\":[");
        t
    }

    fn put(&mut self, b: &[u8]) {
        if self.err.is_none()
            && let Err(e) = self.w.write_all(b)
        {
            self.err = Some(e);
        }
    }

    /// A value as JSON with no raw control character
    /// ([`btfsm_core::sanitize::json`]: names come from the scenario).
    fn put_json<T: Serialize + ?Sized>(&mut self, v: &T) {
        match serde_json::to_string(v) {
            Ok(s) => self.put(btfsm_core::sanitize::json(s).as_bytes()),
            Err(e) => {
                self.err.get_or_insert(e.into());
            }
        }
    }

    /// Ends the file with the verdicts; the writer back, or the first error.
    pub fn finish(mut self, rep: &SimReport) -> std::io::Result<W> {
        self.put(b"],\"verdicts\":");
        self.put_json(&rep.verdicts);
        if !rep.skipped_verdicts.is_empty() {
            self.put(b",\"skipped_verdicts\":");
            self.put_json(&rep.skipped_verdicts);
        }
        self.put(b"}\n");
        match self.err.take() {
            Some(e) => Err(e),
            None => {
                self.w.flush()?;
                Ok(self.w)
            }
        }
    }
}

impl<W: std::io::Write> super::run::TraceOut for TraceWriter<W> {
    fn begin(&mut self) {
        if self.runs > 0 {
            self.put(b",");
        }
        self.put(b"{\"trace\":[");
        self.runs += 1;
        self.steps = 0;
    }

    fn step(&mut self, step: &super::trace::Step) {
        if self.steps > 0 {
            self.put(b",");
        }
        self.steps += 1;
        self.put_json(step);
    }

    fn end(&mut self, run: &Run) {
        self.put(b"],\"trajectory\":[");
        for (i, p) in run.trajectory.iter().enumerate() {
            if i > 0 {
                self.put(b",");
            }
            self.put_json(&[p.0, p.1]);
        }
        self.put(b"],");
        // The run's own fields: its JSON object without the opening brace.
        match serde_json::to_string(run) {
            Ok(v) => self.put(&btfsm_core::sanitize::json(v).as_bytes()[1..]),
            Err(e) => {
                self.err.get_or_insert(e.into());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::Limits;
    use std::path::Path;

    fn report(scenario: &str) -> SimReport {
        let s = super::super::scenario::load(Path::new(scenario), &Limits::default()).unwrap();
        let runs = super::super::run::run_scenario(&s, false);
        SimReport::new(&s.name, scenario, s.seed, s.dt, runs)
    }

    #[test]
    fn table_of_exp1_pick_fails() {
        insta::assert_snapshot!(
            report(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../policies/scenarios/exp1-pick-fails.toml"
            ))
            .table()
        );
    }

    #[test]
    fn json_has_the_contract_fields() {
        let r = report(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios/exp2-recharge.toml"
        ));
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
        assert!(p.get("after_success").is_some());
        assert!(p.get("trace").is_none() && p.get("trajectory").is_none());
        for k in [
            "a",
            "b",
            "match",
            "same_skills",
            "same_outcome",
            "same_final_world",
            "tolerance_s",
            "first_divergence",
            "trajectory_distance_m",
            "path_distance_m",
            "time_shift_s",
            "max_time_shift_s",
            "worlds_diverge_s",
        ] {
            assert!(v["verdicts"][0].get(k).is_some(), "{k}");
        }
        assert!(v["expectations"].as_array().unwrap().is_empty());
        assert_eq!(v["expectations_failed"], 0);
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

    /// `sim --trace` writes the trace as the runs go, one step at a time:
    /// the same document as the trace built whole in memory.
    #[test]
    fn a_streamed_trace_is_the_trace_built_in_memory() {
        use super::super::run;
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios/exp1-pick-fails.toml"
        );
        let s = super::super::scenario::load(Path::new(file), &Limits::default()).unwrap();
        let mut w = TraceWriter::new(Vec::new(), &s.name, file, s.seed, s.dt);
        let (runs, cut) = run::run_scenario_traced(&s, None, &mut w);
        assert!(!cut);
        assert!(
            runs.iter().all(|r| r.trace.is_empty()),
            "not kept in memory"
        );
        let streamed = SimReport::new(&s.name, file, s.seed, s.dt, runs);
        let bytes = w.finish(&streamed).expect("written");
        let streamed: serde_json::Value = serde_json::from_slice(&bytes).expect("whole JSON");
        // In memory: every step and the whole trajectory kept.
        let whole: Vec<_> = run::prepare(&s)
            .iter()
            .map(|p| {
                let opts = run::RunOptions {
                    log: true,
                    trace: true,
                    deadline: None,
                };
                run::run_policy(
                    &s,
                    p,
                    s.world.clone(),
                    &s.disturbances,
                    s.rates.clone(),
                    s.seed,
                    opts,
                )
            })
            .collect();
        let steps: usize = whole.iter().map(|r| r.trace.len()).sum();
        assert!(steps > 500, "{steps}");
        let mem = SimReport::new(&s.name, file, s.seed, s.dt, whole).trace_json();
        let mem: serde_json::Value = serde_json::from_str(&mem).unwrap();
        assert_eq!(streamed, mem);
    }

    /// The verdicts stop at the deadline; the pairs left are listed.
    #[test]
    fn skipped_verdicts_are_reported() {
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios/exp1-nominal.toml"
        );
        let s = super::super::scenario::load(Path::new(file), &Limits::default()).unwrap();
        let runs = super::super::run::run_scenario(&s, false);
        let past = Some(std::time::Instant::now());
        let r = SimReport::within(&s.name, file, s.seed, s.dt, runs, 300, past);
        assert!(r.verdicts.is_empty());
        assert_eq!(r.skipped_verdicts.len(), 6);
        let v: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
        assert_eq!(v["skipped_verdicts"][0][0], "Fig. 1 BT baseline");
        assert!(r.table().contains("6 verdicts skipped, the wall-clock budget ran out first: Fig. 1 BT baseline vs Fig. 1 BT baseline (HFSM);"), "{}", r.table());
        let r = report(file);
        assert!(r.skipped_verdicts.is_empty());
        assert!(!r.json().contains("skipped_verdicts"));
    }
}
