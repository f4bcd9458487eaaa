//! `btfsm compare A B`: loads both policies, runs the selected GED modes
//! (SPEC §3, §7) under the time budget, prints the report, and optionally
//! draws B with the edits highlighted. While a long search runs, a progress
//! line on stderr (only when stderr is a terminal) tells which mode is being
//! computed and how much of its budget is spent. `--mode tree` (and the
//! default, for two BTs) adds the ordered tree edit distance
//! (`metrics::ted`), bounded by a count of table cells.

use super::args::{CompareMode, LimitArgs};
use super::dot::draw;
use super::io::{emit_report, fail, load_all, outputs_distinct};
use super::{EXIT_BAD_INPUT, EXIT_NOT_REPRODUCIBLE, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_core::sanitize::shown;
use btfsm_metrics::ged::{GedMode, GedOptions, StopReason};
use btfsm_metrics::ted::TedOptions;
use btfsm_model::{PolicyBody, PolicyKind};
use btfsm_report::compare::{self, Pair, Side};
use clap::Args;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    /// The old policy
    pub(super) a: PathBuf,
    /// The new policy
    pub(super) b: PathBuf,
    /// Which distance: a GED — structural (any vertex to any vertex),
    /// labeled (same vertex type only), named (by node id / state name) —
    /// or tree, the ordered tree edit distance of two BTs (children
    /// order and node labels count); all: the three GEDs, and tree when
    /// both policies are BTs
    #[arg(long, value_enum, default_value_t = CompareMode::All)]
    pub(super) mode: CompareMode,
    /// Safety cap per mode in CPU time of the search (not wall-clock time,
    /// so a loaded machine does not make it fire sooner), its whole
    /// computation (graphs, search, edit script; docs/robustness.md gives
    /// the floor on large graphs). Default: 400 ns per --work unit, at
    /// least 30 s (120 s at the default --work), far past what the work
    /// takes. The work budget decides the result; when this cap ends a
    /// search first the report says `stopped_by: time` and the exit code
    /// is 3 (the interval may differ on another machine)
    #[arg(long, value_name = "MS")]
    pub(super) timeout_ms: Option<u64>,
    /// Work budget of the exact search per mode, in work units (one per
    /// assignment-matrix entry the search builds; 15-80 ns each: the
    /// default is about 4-5 s on the hardest pairs measured, idle).
    /// The same pair gives the same result (GED, exact, interval) on any
    /// machine under any load; when the budget runs out the result is a
    /// certified interval with `exact: false` and `stopped_by: work`
    #[arg(long, default_value_t = btfsm_metrics::ged::DEFAULT_WORK, value_name = "UNITS")]
    pub(super) work: u64,
    /// Work budget of --mode tree, in table cells (about 3 ns each; the
    /// default, 10^10, computes two unrelated 10,000-node trees exactly in
    /// seconds): past it the result is an interval with `exact: false` and
    /// `stopped_by: work`, the same on any machine. Counted before the
    /// exact computation starts, so a pair beyond it does not spend it
    #[arg(long, default_value_t = btfsm_metrics::ted::DEFAULT_MAX_WORK, value_name = "CELLS")]
    pub(super) tree_max_work: u64,
    /// Memory budget of --mode tree, in MiB of tables held at once (the
    /// exact computation needs about 4·n1·n2 bytes and some rows: 400-650
    /// MB for two unrelated 10,000-node trees): past it the result is an interval with
    /// `stopped_by: memory`, whatever --tree-max-work says
    #[arg(long, default_value_t = btfsm_metrics::ted::DEFAULT_MAX_BYTES >> 20, value_name = "MIB")]
    pub(super) tree_max_memory: u64,
    /// Output format
    #[arg(long, value_parser = super::format::parser(Comparison::FORMATS, super::format::COMPARISON_HELP), default_value = "table")]
    pub(super) format: Format,
    /// Also draw B with added elements magenta, A's removed ones dashed
    /// grey and changed ones (relabels, reorders) orange with their old
    /// value, a title and a legend (the edit script of --mode; named when
    /// all modes run)
    #[arg(long, value_name = "OUT")]
    pub(super) dot: Option<PathBuf>,
    /// With --dot: render through Graphviz instead of writing DOT (under
    /// the --timeout-ms cap of one mode, in wall-clock time: past it `dot`
    /// is killed);
    /// default: the extension of --dot when it is .svg, .png or .pdf
    #[arg(long, value_enum, requires = "dot")]
    pub(super) render: Option<btfsm_render::dot::RenderFormat>,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(args: CompareArgs) -> u8 {
    if !outputs_distinct(&[("--dot", args.dot.as_deref())], true) {
        return EXIT_BAD_INPUT;
    }
    if args.mode == CompareMode::Tree && args.dot.is_some() {
        return fail(
            Diagnostic::error("--dot draws a GED edit script, and --mode tree computes none")
                .hint("use --dot with --mode named (or structural, labeled, all)"),
        );
    }
    let Some(loaded) = load_all(&[args.a.clone(), args.b.clone()], &args.limits.limits()) else {
        return EXIT_BAD_INPUT;
    };
    let [la, lb] = loaded.as_slice() else {
        return EXIT_BAD_INPUT;
    };
    let bts = matches!(
        (&la.policy.body, &lb.policy.body),
        (PolicyBody::Bt(_), PolicyBody::Bt(_))
    );
    if args.mode == CompareMode::Tree && !bts {
        let other = if la.policy.kind() == PolicyKind::Bt {
            lb
        } else {
            la
        };
        return fail(
            Diagnostic::error(format!(
                "--mode tree compares two Behavior Trees, and {} is an {}",
                shown(&other.path),
                other.policy.kind().as_str().to_uppercase(),
            ))
            .hint("FSMs and HFSMs are graphs, not ordered trees: use --mode structural, labeled or named (or leave --mode out)"),
        );
    }
    let mut opts = GedOptions::with_work(args.work);
    if let Some(ms) = args.timeout_ms {
        opts.timeout = Duration::from_millis(ms);
    }
    let topts = TedOptions {
        max_work: args.tree_max_work,
        max_bytes: args.tree_max_memory.saturating_mul(1 << 20),
    };
    let pair = Pair::with_tree_options(
        Side {
            file: &la.path,
            policy: &la.policy,
        },
        Side {
            file: &lb.path,
            policy: &lb.policy,
        },
        &topts,
        matches!(args.mode, CompareMode::Tree | CompareMode::All),
    );
    let mut results = Vec::new();
    for mode in args.mode.ged_modes() {
        let progress = Progress::start(mode, opts.timeout);
        results.push(pair.run(mode, &opts));
        drop(progress);
    }
    let mut report = pair.report(results);
    if matches!(args.mode, CompareMode::Tree | CompareMode::All) {
        report.tree = pair.tree_report();
    }
    // The drawing first (its file is written or its error said), then the
    // comparison, which is printed whatever became of the drawing: a
    // missing Graphviz costs the picture, not the report (exit 2 still says
    // that an output asked for was not made).
    let mut drawn = EXIT_OK;
    if let (Some(path), Some(primary)) = (&args.dot, report.primary()) {
        let cap = Duration::from_millis(
            args.timeout_ms
                .unwrap_or(btfsm_metrics::ged::DEFAULT_TIMEOUT_MS),
        );
        let opts = pair.dot_options(&primary.edit_script);
        // Graphviz gets the cap of one mode (--timeout-ms, by default 30 s),
        // in wall-clock time.
        drawn = draw(&lb.policy, &opts, Some(path), args.render, cap);
    }
    let printed = emit_report(None, &Comparison(&report), args.format);
    let timed = report
        .modes
        .iter()
        .any(|m| m.stopped_by == Some(StopReason::Time));
    if drawn != EXIT_OK {
        drawn
    } else if printed == EXIT_OK && timed {
        EXIT_NOT_REPRODUCIBLE
    } else {
        printed
    }
}

/// A progress line on stderr, shown after a short delay while a search runs
/// and erased when it ends (dropping the guard).
struct Progress {
    done: Option<mpsc::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Progress {
    const DELAY: Duration = Duration::from_millis(300);
    const TICK: Duration = Duration::from_millis(100);

    fn start(mode: GedMode, budget: Duration) -> Progress {
        if mode == GedMode::Named || !std::io::stderr().is_terminal() {
            return Progress {
                done: None,
                thread: None,
            };
        }
        let (tx, rx) = mpsc::channel::<()>();
        let thread = std::thread::spawn(move || {
            let start = Instant::now();
            if rx.recv_timeout(Self::DELAY).is_ok() {
                return;
            }
            loop {
                let line = format!(
                    "\r{} GED: searching, {:.1} s (CPU-time cap {:.1} s)",
                    mode.as_str(),
                    start.elapsed().as_secs_f64(),
                    budget.as_secs_f64()
                );
                let _ = std::io::stderr().write_all(line.as_bytes());
                match rx.recv_timeout(Self::TICK) {
                    Err(mpsc::RecvTimeoutError::Timeout) => continue,
                    _ => break,
                }
            }
            // Erase the line.
            let _ = std::io::stderr().write_all(b"\r\x1b[2K");
        });
        Progress {
            done: Some(tx),
            thread: Some(thread),
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(tx) = self.done.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// `compare`'s report in its formats.
struct Comparison<'a>(&'a compare::CompareReport);

impl Report for Comparison<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json, Format::Markdown];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Json => compare::render_json(self.0),
            Format::Markdown => compare::render_markdown(self.0),
            _ => compare::render_table(self.0),
        }
    }
}
