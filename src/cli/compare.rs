//! `btfsm compare A B`: loads both policies, runs the selected GED modes
//! (SPEC §3, §7) under the time budget, prints the report, and optionally
//! draws B with the edits highlighted. While a long search runs, a progress
//! line on stderr (only when stderr is a terminal) tells which mode is being
//! computed and how much of its budget is spent. `--mode tree` (and the
//! default, for two BTs) adds the ordered tree edit distance
//! (`metrics::ted`), bounded by a count of table cells.

use super::args::{CompareFormat, CompareMode};
use super::commands::{draw, emit_text, load_all};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::sanitize::shown;
use btfsm_format::Limits;
use btfsm_metrics::ged::{GedMode, GedOptions};
use btfsm_metrics::ted::TedOptions;
use btfsm_model::{PolicyBody, PolicyKind};
use btfsm_render::dot::RenderFormat;
use btfsm_report::compare::{self, Pair, Side};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Validated arguments of `compare`.
pub(super) struct CompareArgs {
    pub a: PathBuf,
    pub b: PathBuf,
    pub mode: CompareMode,
    pub timeout_ms: u64,
    /// Work budget (`GedOptions::work`).
    pub work: u64,
    pub tree_max_work: u64,
    pub format: CompareFormat,
    pub dot: Option<PathBuf>,
    pub render: Option<RenderFormat>,
    pub limits: Limits,
}

pub(super) fn execute(args: CompareArgs) -> u8 {
    if !super::commands::outputs_distinct(&[("--dot", args.dot.as_deref())], true) {
        return EXIT_BAD_INPUT;
    }
    if args.mode == CompareMode::Tree && args.dot.is_some() {
        eprintln!(
            "error: --dot draws a GED edit script, and --mode tree computes none\n  = hint: use --dot with --mode named (or structural, labeled, all)"
        );
        return EXIT_BAD_INPUT;
    }
    let Some(loaded) = load_all(&[args.a.clone(), args.b.clone()], &args.limits) else {
        return EXIT_BAD_INPUT;
    };
    let [la, lb] = loaded.as_slice() else {
        return EXIT_BAD_INPUT;
    };
    let bts = match (&la.policy.body, &lb.policy.body) {
        (PolicyBody::Bt(a), PolicyBody::Bt(b)) => Some((a, b)),
        _ => None,
    };
    if args.mode == CompareMode::Tree && bts.is_none() {
        let other = if la.policy.kind() == PolicyKind::Bt {
            lb
        } else {
            la
        };
        eprintln!(
            "error: --mode tree compares two Behavior Trees, and {} is an {}\n  = hint: FSMs and HFSMs are graphs, not ordered trees: use --mode structural, labeled or named (or leave --mode out)",
            shown(&other.path),
            other.policy.kind().as_str().to_uppercase(),
        );
        return EXIT_BAD_INPUT;
    }
    let opts = GedOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        work: args.work,
    };
    let pair = Pair::new(
        Side {
            file: &la.path,
            policy: &la.policy,
        },
        Side {
            file: &lb.path,
            policy: &lb.policy,
        },
    );
    let mut results = Vec::new();
    for mode in args.mode.ged_modes() {
        let progress = Progress::start(mode, opts.timeout);
        results.push(pair.run(mode, &opts));
        drop(progress);
    }
    let mut report = pair.report(results);
    if matches!(args.mode, CompareMode::Tree | CompareMode::All)
        && let Some((a, b)) = bts
    {
        let topts = TedOptions {
            max_work: args.tree_max_work,
            ..TedOptions::default()
        };
        report.tree = Some(compare::tree::tree_report(a, b, &topts));
    }
    if let (Some(path), Some(primary)) = (&args.dot, report.primary()) {
        let opts = pair.dot_options(&primary.edit_script);
        // Graphviz gets the budget of one mode (--timeout-ms).
        let timeout = Duration::from_millis(args.timeout_ms);
        let code = draw(&lb.policy, &opts, Some(path), args.render, timeout);
        if code != EXIT_OK {
            return code;
        }
    }
    let text = match args.format {
        CompareFormat::Json => compare::render_json(&report),
        CompareFormat::Table => compare::render_table(&report),
        CompareFormat::Markdown => compare::render_markdown(&report),
    };
    emit_text(None, text)
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
                    "\r{} GED: searching, {:.1} s of the {:.1} s budget",
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
