//! `btfsm sim`: runs the policies of a scenario in the planar simulator and
//! prints outcomes, executed skills, final worlds and behavior-match verdicts
//! (SPEC §6, §7); `--runs N` runs seeded Monte Carlo episodes instead.

use super::io::{emit_text, fail, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_sim::report::{McReport, SimReport, TraceWriter};
use btfsm_sim::{monte_carlo, plot, run, scenario};
use clap::Args;
use std::path::PathBuf;

/// What `sim` prints.
const SIM_FORMATS: &[Format] = &[Format::Table, Format::Json, Format::Markdown, Format::Csv];

/// The help of `sim`'s formats.
const SIM_HELP: super::format::Help = &[
    (
        Format::Markdown,
        "GitHub-flavoured markdown tables (with --runs)",
    ),
    (
        Format::Csv,
        "One row per policy (figures only: the verdicts are in table and json)",
    ),
];

/// `--threads` above this many per core are lowered to it.
pub(crate) const MAX_THREADS_PER_CORE: usize = 4;

/// Most `--runs` (issue 33: `--runs 4294967295` allocated 4 GiB of
/// per-episode flags before its figures).
pub(crate) const MAX_RUNS: u32 = 10_000_000;

#[derive(Debug, Args)]
pub(crate) struct SimArgs {
    /// Scenario file (TOML)
    pub scenario: PathBuf,
    /// Output format (table, json or csv; markdown with --runs)
    #[arg(long, value_parser = super::format::parser(SIM_FORMATS, SIM_HELP), default_value = "table")]
    pub format: Format,
    /// Write the full trace (every step of every run) as JSON
    #[arg(long, value_name = "OUT.json")]
    pub trace: Option<PathBuf>,
    /// Draw the room and each policy's trajectory as SVG
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
    /// Run N seeded episodes with randomized disturbances and failure rates
    /// (at most 10,000,000: more would take days, and the figures keep a
    /// flag per episode asked for)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=i64::from(MAX_RUNS)))]
    pub runs: Option<u32>,
    /// With --runs, the seed of the episodes (default: the scenario's
    /// seed); without, run the one episode with seed S (the scenario's
    /// disturbances jittered and the [monte_carlo] ones drawn as episode
    /// S of --runs was: the seed a --runs report names replays it)
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Worker threads for --runs (default: the number of cores; at least 1,
    /// and more than 4 x the cores are lowered to 4 x the cores)
    #[arg(long)]
    pub threads: Option<usize>,
    /// Wall-clock budget for all the simulation work, in ms: when it runs
    /// out, runs stop cleanly (outcome `timeout` at the step reached; with
    /// --runs, the figures cover the episodes completed) and the report
    /// says so; the exit code stays 0, unless an expectation of the
    /// scenario cannot be decided (exit 1). A budget too large for the clock
    /// (past the year 2^64 ns) is no budget
    #[arg(long, value_name = "MS")]
    pub timeout_ms: Option<u64>,
    /// Run the scenario again with each policy-independent modelling
    /// setting flipped (what the robot knows of a dropped object, after
    /// SUCCESS/FAILURE for every policy, tolerances, budgets) and name,
    /// beside each verdict, the flips that reverse it (an expectation that
    /// fails gets them without this flag)
    #[arg(long)]
    pub sensitivity: bool,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(crate) fn execute(a: SimArgs) -> u8 {
    let outputs = [
        ("--trace", a.trace.as_deref()),
        ("--plot", a.plot.as_deref()),
    ];
    if !super::io::outputs_distinct(&outputs, true) {
        return EXIT_BAD_INPUT;
    }
    let limits = a.limits.limits();
    let shown = a.scenario.display().to_string();
    let file = match btfsm_format::toml::read_source(&a.scenario, &shown, &limits) {
        Ok(f) => f,
        Err(d) => {
            print_diagnostics(&mut std::io::stderr().lock(), &d);
            return EXIT_BAD_INPUT;
        }
    };
    let base = a
        .scenario
        .parent()
        .unwrap_or(std::path::Path::new(""))
        .to_path_buf();
    if btfsm_sim::symbolic::looks_symbolic(&file.text) {
        return symbolic(&a, &file, &base, &limits);
    }
    let s = match scenario::parse(&file, &base, &limits) {
        Ok(s) => s,
        Err(d) => {
            print_diagnostics(&mut std::io::stderr().lock(), &d);
            return EXIT_BAD_INPUT;
        }
    };
    if !s.warnings.is_empty() {
        print_diagnostics(&mut std::io::stderr().lock(), &s.warnings);
    }
    // The budget's clock starts once the scenario is read.
    let t0 = std::time::Instant::now();
    // Checked: a budget past what the clock can hold is no deadline.
    let deadline = a
        .timeout_ms
        .and_then(|ms| t0.checked_add(std::time::Duration::from_millis(ms)));
    match a.runs {
        Some(n) => monte_carlo_runs(&a, &s, n, t0, deadline),
        None => one_run(&a, s, t0, deadline),
    }
}

/// `sim --runs N`: seeded episodes over the cores, within the deadline.
fn monte_carlo_runs(
    a: &SimArgs,
    s: &scenario::Scenario,
    n: u32,
    t0: std::time::Instant,
    deadline: Option<std::time::Instant>,
) -> u8 {
    if a.trace.is_some() || a.plot.is_some() {
        return fail(Diagnostic::error(
            "--trace and --plot record one run; leave them out with --runs",
        ));
    }
    let seed = a.seed.unwrap_or(s.seed);
    let Some(threads) = threads(a, n) else {
        return EXIT_BAD_INPUT;
    };
    let mc = monte_carlo::monte_carlo_within(s, n, seed, threads, deadline);
    let done = mc.runs;
    let expectations = btfsm_sim::scenario::expect::check_monte_carlo(&s.expect, &mc);
    note_single_run_expectations(s.expect.len() - expectations.len());
    // Every flip runs the same episodes, when all of them completed.
    let sensitivity = (a.sensitivity && done == n).then(|| {
        let base = btfsm_sim::sensitivity::monte_carlo_verdicts(&mc, &expectations);
        let budget = btfsm_sim::episodes::Budget {
            runs: n,
            seed,
            threads,
            deadline,
        };
        btfsm_sim::sensitivity::of_monte_carlo(s, &base, &budget)
    });
    let mut rep = McReport {
        scenario: s.name.clone(),
        seed,
        // What the figures cover.
        runs: done,
        threads,
        millis: t0.elapsed().as_millis(),
        policies: mc.policies,
        pairs: mc.pairs,
        expectations_failed: (expectations.iter())
            .filter(|e| e.status != btfsm_sim::scenario::expect::Status::Pass)
            .count(),
        expectations,
        sensitivity: None,
    };
    if let Some(x) = sensitivity {
        rep.set_sensitivity(x);
    }
    let budget = a.timeout_ms.map(|ms| Budget {
        timeout_ms: ms,
        exhausted: done < n,
        requested_runs: Some(n),
        millis: None,
    });
    let note =
        format!("{done} of {n} episodes completed; the figures cover those (the first {done})");
    finish(render(&rep, a.format, &budget, &note), &rep.expectations)
}

/// The workers of `--runs n`: `--threads` (default the cores; more than
/// [`MAX_THREADS_PER_CORE`] per core only wait and are lowered), at most
/// one per episode; `None` after an error.
fn threads(a: &SimArgs, n: u32) -> Option<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let t = match a.threads {
        Some(0) => {
            fail(Diagnostic::error("--threads must be at least 1"));
            return None;
        }
        Some(t) => t.min(MAX_THREADS_PER_CORE * cores),
        None => cores,
    };
    Some(t.clamp(1, n.max(1) as usize))
}

/// The `--trace` file within `--max-file-bytes`, the most btfsm reads back
/// (`view`, `log compare`, `dot --trace`): past it writing fails, the
/// temporary is removed and the run exits 2 (issue 33: a 1 KB scenario
/// wrote a 4.2 GB trace).
struct Capped<W> {
    w: W,
    left: u64,
    cap: u64,
}

impl<W: std::io::Write> std::io::Write for Capped<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if buf.len() as u64 > self.left {
            return Err(std::io::Error::other(format!(
                "the trace would be larger than {} bytes, the most btfsm reads back (--max-file-bytes); lower the scenario's max_steps, or raise --max-file-bytes",
                self.cap
            )));
        }
        let n = self.w.write(buf)?;
        self.left -= n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.w.flush()
    }
}

/// `sim` without `--runs`: each policy once (or the episode of `--seed`),
/// the verdicts, the expectations, the trace and the plot.
fn one_run(
    a: &SimArgs,
    mut s: scenario::Scenario,
    t0: std::time::Instant,
    deadline: Option<std::time::Instant>,
) -> u8 {
    let file = a.scenario.display().to_string();
    if a.format == Format::Markdown {
        return fail(Diagnostic::error(
            "`sim` prints markdown with --runs; use `table` or `json` for one run",
        ));
    }
    if let Some(seed) = a.seed {
        // The episode with this seed, as `--runs` draws it.
        let (ds, rates) = monte_carlo::episode(&s, seed);
        s.seed = seed;
        s.disturbances = ds;
        s.rates = rates;
    }
    // The runs stop 5% early, leaving the verdicts time to compare them.
    let runs_deadline = a
        .timeout_ms
        .and_then(|ms| t0.checked_add(std::time::Duration::from_micros(ms.saturating_mul(950))));
    // The trace goes to its (temporary) file as the runs make it.
    let (runs, cut, trace_out) = match &a.trace {
        Some(p) => {
            let f = match super::io::create_output_file(p) {
                Ok(f) => f,
                Err(code) => return code,
            };
            let f = Capped {
                w: f,
                left: a.limits.max_file_bytes,
                cap: a.limits.max_file_bytes,
            };
            let mut w = TraceWriter::new(f, &s.name, &file, s.seed, s.dt);
            let (runs, cut) = run::run_scenario_traced(&s, runs_deadline, &mut w);
            (runs, cut, Some((p, w)))
        }
        None => {
            let (runs, cut) = run::run_scenario_within(&s, false, runs_deadline);
            (runs, cut, None)
        }
    };
    // The verdicts' trajectory distances get what is left of the budget:
    // fewer points per trajectory when little is (300 at the least).
    let pairs = runs.len() * runs.len().saturating_sub(1) / 2;
    let points = deadline.map_or(btfsm_sim::trace::FRECHET_POINTS, |d| {
        btfsm_sim::trace::frechet_points(
            pairs,
            d.saturating_duration_since(std::time::Instant::now()),
        )
    });
    // The verdicts stop at the deadline too; the pairs left are reported.
    let cut_runs: Vec<bool> = runs.iter().map(|r| run::cut_short(&s, r)).collect();
    let mut rep = SimReport::within(&s.name, &file, s.seed, s.dt, runs, points, deadline);
    rep.check(&s.expect, &cut_runs);
    // The flips: asked for, or to name what would make a failed
    // expectation hold.
    if a.sensitivity || rep.expectations_failed > 0 {
        let x = btfsm_sim::sensitivity::of_single_run(&s, &rep.verdict_values(), runs_deadline);
        rep.set_sensitivity(x);
        if !a.sensitivity {
            rep.sensitivity = None;
        }
    }
    let millis = t0.elapsed().as_millis();
    let budget = a.timeout_ms.map(|ms| Budget {
        timeout_ms: ms,
        exhausted: cut || !rep.skipped_verdicts.is_empty(),
        requested_runs: None,
        millis: Some(millis),
    });
    if let Some((p, w)) = trace_out
        && let Err(e) = w.finish(&rep).and_then(|f| f.w.commit())
    {
        return super::io::cannot_write(Some(p), e);
    }
    if let Some(p) = &a.plot
        && emit_text(Some(p), plot::svg(&s, &rep.policies)) != EXIT_OK
    {
        return EXIT_BAD_INPUT;
    }
    let note = "the runs with outcome `timeout` stopped at the step shown in their reason, and the verdicts not computed are listed";
    finish(render(&rep, a.format, &budget, note), &rep.expectations)
}

/// With `--runs`, says how many expectations about single runs are not
/// checked (never skipped silently).
fn note_single_run_expectations(n: usize) {
    if n > 0 {
        eprintln!(
            "note: the scenario's {n} expectation{} about single runs {} checked without --runs",
            if n == 1 { "" } else { "s" },
            if n == 1 { "is" } else { "are" }
        );
    }
}

/// Prints the report; then exit 1 naming the expectations that failed
/// (the first 10), if any.
fn finish(text: String, expectations: &[btfsm_sim::scenario::expect::ExpectResult]) -> u8 {
    let code = emit_text(None, text);
    if code != EXIT_OK {
        return code;
    }
    let failed: Vec<String> = (expectations.iter())
        .filter(|e| e.status != btfsm_sim::scenario::expect::Status::Pass)
        .map(|e| btfsm_core::sanitize::shown(&e.name).into_owned())
        .collect();
    if failed.is_empty() {
        return EXIT_OK;
    }
    eprint!(
        "{}",
        Diagnostic::error(format!(
            "{} of {} expectations of the scenario failed: {}",
            failed.len(),
            expectations.len(),
            failed[..failed.len().min(10)].join("; ")
        ))
    );
    EXIT_CHECK_FAILED
}

/// What `--timeout-ms` adds to a JSON report.
#[derive(Debug, serde::Serialize)]
struct Budget {
    timeout_ms: u64,
    /// Whether the budget ran out (some run or episode was cut short).
    exhausted: bool,
    /// With `--runs`: the episodes asked for (`runs` is how many completed).
    #[serde(skip_serializing_if = "Option::is_none")]
    requested_runs: Option<u32>,
    /// Without `--runs` (whose report has its own `millis`): the wall time
    /// of the runs and their verdicts, ms.
    #[serde(skip_serializing_if = "Option::is_none")]
    millis: Option<u128>,
}

/// The report in `format`; with `--timeout-ms`, JSON gets the `budget`
/// object, and the table `note` when the budget ran out (on stderr for
/// CSV, which stays one table).
fn render<R: Report + serde::Serialize>(
    rep: &R,
    format: Format,
    budget: &Option<Budget>,
    note: &str,
) -> String {
    let format = R::supported(format);
    let Some(b) = budget else {
        return rep.write(format);
    };
    if format == Format::Json {
        return with_budget(rep, b);
    }
    let mut t = rep.write(format);
    if b.exhausted {
        let note = format!(
            "note: the wall-clock budget of {} ms ran out: {note}\n",
            b.timeout_ms
        );
        if format == Format::Csv {
            eprint!("{note}");
        } else {
            t.push_str(&note);
        }
    }
    t
}

/// The JSON report with a `budget` object after its own fields.
fn with_budget<T: serde::Serialize>(report: &T, budget: &Budget) -> String {
    #[derive(serde::Serialize)]
    struct Out<'a, T> {
        #[serde(flatten)]
        report: &'a T,
        budget: &'a Budget,
    }
    let mut s = btfsm_core::sanitize::json(
        serde_json::to_string_pretty(&Out { report, budget }).expect("serializable"),
    );
    s.push('\n');
    s
}

/// `btfsm dot FILE --trace TRACE.json --step K [--policy NAME]`.
#[derive(Debug, Clone, Args)]
pub(crate) struct DotTraceArgs {
    /// A trace written by `btfsm sim --trace`
    #[arg(long, value_name = "TRACE.json", requires = "step")]
    pub trace: Option<PathBuf>,
    /// Step of the trace to show (0 is the first step)
    #[arg(long, value_name = "K", requires = "trace")]
    pub step: Option<usize>,
    /// Which policy of the trace (default: the one run from FILE, unconverted)
    #[arg(long, value_name = "NAME", requires = "trace")]
    pub policy: Option<String>,
}

/// The policy to draw and its highlights: with `--trace`, every node or state
/// ticked at step K coloured by its status (RUNNING yellow, SUCCESS green,
/// FAILURE red); a trace of a converted HFSM converts FILE the same way.
/// `None` after printing an error.
pub(crate) fn dot_trace(
    a: &DotTraceArgs,
    file: &std::path::Path,
    policy: btfsm_model::Policy,
    limits: &btfsm_format::Limits,
) -> Option<(btfsm_model::Policy, btfsm_render::dot::DotOptions)> {
    use btfsm_render::dot::{Highlight, Status};
    let (Some(trace), Some(step)) = (&a.trace, a.step) else {
        return Some((policy, Default::default()));
    };
    let fail = |d: Diagnostic| {
        eprint!("{d}");
        None
    };
    let text = match read_trace(trace, limits) {
        Ok(t) => t,
        Err(diags) => {
            super::io::print_diagnostics(&mut std::io::stderr().lock(), &diags);
            return None;
        }
    };
    let v: serde_json::Value = match serde_json::from_str(&text.text) {
        Ok(v) => v,
        Err(e) => {
            return fail(Diagnostic::error(format!(
                "`{}` is not a trace written by `btfsm sim --trace`: {e}",
                trace.display()
            )));
        }
    };
    let empty = Vec::new();
    let runs = v["policies"].as_array().unwrap_or(&empty);
    let canon = |p: &str| std::fs::canonicalize(p).ok();
    let me = std::fs::canonicalize(file).ok();
    let run = match &a.policy {
        Some(name) => runs.iter().find(|r| r["policy"] == name.as_str()),
        None => runs
            .iter()
            .find(|r| r["convert"].is_null() && canon(r["file"].as_str().unwrap_or("")) == me)
            .or_else(|| {
                runs.iter()
                    .find(|r| canon(r["file"].as_str().unwrap_or("")) == me)
            }),
    };
    let Some(run) = run else {
        let names: Vec<&str> = runs.iter().filter_map(|r| r["policy"].as_str()).collect();
        return fail(
            Diagnostic::error(format!(
                "no policy of `{}` in the trace `{}`",
                file.display(),
                trace.display(),
            ))
            .hint(format!("choose one with --policy: {}", names.join(", "))),
        );
    };
    let steps = run["trace"].as_array().unwrap_or(&empty);
    let Some(st) = steps.get(step) else {
        return fail(Diagnostic::error(format!(
            "step {step} is past the end of the trace of `{}` ({} steps, 0 to {})",
            run["policy"].as_str().unwrap_or(""),
            steps.len(),
            steps.len().saturating_sub(1)
        )));
    };
    let policy = if run["convert"] == "hfsm" {
        match btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&policy) {
            Ok(p) => p,
            Err(e) => return fail(Diagnostic::error(e[0].to_string())),
        }
    } else {
        policy
    };
    let mut opts = btfsm_render::dot::DotOptions::default();
    // A trace names an (H)FSM's states by their full path; the drawing by
    // their vertex key (the name, unless it repeats).
    let (keys, paths) = btfsm_view::drawn_keys(&policy);
    let key_of: std::collections::HashMap<&str, &str> = paths
        .iter()
        .map(|(p, i)| (p.as_str(), keys[*i].as_str()))
        .collect();
    for pair in st["statuses"].as_array().unwrap_or(&empty) {
        if let (Some(k), Some(s)) = (pair[0].as_str(), pair[1].as_str())
            && let Some(s) = Status::from_outcome(s)
        {
            let k = key_of.get(k).copied().unwrap_or(k);
            opts.highlight.insert(k.to_string(), Highlight::Status(s));
        }
    }
    Some((policy, opts))
}

/// Reads a trace file as every input is read (`format::source::read`):
/// within `--max-file-bytes` (`/dev/zero` stops there), charged to the
/// command's `--max-total-bytes`, never blocking on a FIFO.
fn read_trace(
    path: &std::path::Path,
    limits: &btfsm_format::Limits,
) -> Result<
    std::sync::Arc<btfsm_core::diagnostic::SourceFile>,
    Vec<btfsm_core::diagnostic::Diagnostic>,
> {
    let shown = path.display().to_string();
    btfsm_format::source::read(path, &shown, limits, false)
}

/// A symbolic scenario (a top-level `domain`): one run per policy, or
/// `--runs` Monte Carlo episodes, in the domain's world of facts.
fn symbolic(
    a: &SimArgs,
    file: &std::sync::Arc<btfsm_core::diagnostic::SourceFile>,
    base: &std::path::Path,
    limits: &btfsm_format::Limits,
) -> u8 {
    use btfsm_sim::symbolic::{report, run};
    if a.trace.is_some() || a.plot.is_some() || matches!(a.format, Format::Markdown | Format::Csv) {
        return fail(
            Diagnostic::error("a symbolic scenario has no trace, plot, markdown or csv report")
                .hint("print `table` or `json`"),
        );
    }
    if a.sensitivity {
        return fail(
            Diagnostic::error("--sensitivity flips the planar world's modelling settings; a symbolic scenario has none")
                .hint("leave out --sensitivity"),
        );
    }
    let s = match btfsm_sim::symbolic::scenario::parse(file, base, limits) {
        Ok(s) => s,
        Err(d) => {
            print_diagnostics(&mut std::io::stderr().lock(), &d);
            return EXIT_BAD_INPUT;
        }
    };
    let t0 = std::time::Instant::now();
    let deadline = a
        .timeout_ms
        .and_then(|ms| t0.checked_add(std::time::Duration::from_millis(ms)));
    let Some(n) = a.runs else {
        let runs = run::run_all(&s, a.seed, deadline);
        let budget = a.timeout_ms.map(|ms| Budget {
            timeout_ms: ms,
            exhausted: runs.iter().any(|r| r.cut_short),
            requested_runs: None,
            millis: Some(t0.elapsed().as_millis()),
        });
        let note = "the runs with outcome `timeout` stopped at the step shown";
        let rep = report::RunsReport::new(&s, &runs);
        return finish(render(&rep, a.format, &budget, note), &rep.expectations);
    };
    let Some(threads) = threads(a, n) else {
        return EXIT_BAD_INPUT;
    };
    let budget = btfsm_sim::episodes::Budget {
        runs: n,
        seed: a.seed.unwrap_or(s.seed),
        threads,
        deadline,
    };
    note_single_run_expectations(s.expect.len());
    let mc = run::monte_carlo(&s, &budget);
    let done = mc.runs;
    let b = a.timeout_ms.map(|ms| Budget {
        timeout_ms: ms,
        exhausted: done < n,
        requested_runs: Some(n),
        millis: Some(t0.elapsed().as_millis()),
    });
    let note =
        format!("{done} of {n} episodes completed; the figures cover those (the first {done})");
    let rep = report::McReport::new(&s, budget.seed, &mc);
    emit_text(None, render(&rep, a.format, &b, &note))
}
