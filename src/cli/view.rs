//! `btfsm view INPUT... -o page.html`: one self-contained HTML page replaying
//! runs (src/view/): a simulator scenario (run here as `btfsm sim` runs it),
//! a trace written by `btfsm sim --trace`, or a BehaviorTree.CPP `.btlog` (or `.db3`: its last session);
//! several inputs share one slider.

use super::io::{emit_text, fail, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_view::{Replay, ViewError};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub(crate) struct ViewArgs {
    /// Scenario (.toml, run with its seed), trace of `btfsm sim --trace`
    /// (.json; the policy files it names are read, relative to the current
    /// directory and inside the root) or BehaviorTree.CPP log (.btlog, or .db3: its last session)
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// The HTML file to write (default: stdout)
    #[arg(short, long, value_name = "OUT.html")]
    pub output: Option<PathBuf>,
    /// Run the scenarios' episode with seed S, as `sim --seed S` does
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Graphviz's time budget per diagram, ms; past it `dot` is killed and
    /// the run exits 2
    #[arg(long, default_value_t = btfsm_render::dot::DEFAULT_RENDER_TIMEOUT_MS, value_name = "MS")]
    pub timeout_ms: u64,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

/// Which kind of input a file is: by extension, else by its first bytes.
enum Kind {
    Scenario,
    Trace,
    Log,
    /// A SqliteLogger `.db3`: its last session, as the `log` commands read it.
    Db3,
}

fn kind_of(path: &Path, head: &[u8]) -> Kind {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("btlog") => Kind::Log,
        Some("db3") => Kind::Db3,
        _ if head.starts_with(b"SQLite format 3\0") => Kind::Db3,
        Some("json") => Kind::Trace,
        Some("toml") => Kind::Scenario,
        _ if head.starts_with(btfsm_log::btlog::MAGIC) => Kind::Log,
        _ if head.trim_ascii_start().starts_with(b"{") => Kind::Trace,
        _ => Kind::Scenario,
    }
}

fn view_failed(e: ViewError) -> Option<Replay> {
    match e {
        ViewError::Diagnostics(d) => print_diagnostics(&mut std::io::stderr().lock(), &d),
        e => eprint!("{}", Diagnostic::error(e.to_string())),
    }
    None
}

/// A log input, kept to compare its run with the other logs' as `btfsm log
/// compare` does.
enum LogSource {
    /// A `.btlog`'s bytes.
    Btlog(std::sync::Arc<[u8]>),
    /// A `.db3`, opened again (its last session).
    Db3(PathBuf),
}

/// One input's replay; `None` after printing why not. Every input is read
/// once through `format::source` (bounded, never blocking on a FIFO).
fn replay_of(
    path: &Path,
    a: &ViewArgs,
    limits: &btfsm_format::Limits,
    deadline: std::time::Instant,
) -> Option<(Replay, Option<LogSource>)> {
    let shown = path.display().to_string();
    let diags = |d: Vec<btfsm_core::diagnostic::Diagnostic>| {
        print_diagnostics(&mut std::io::stderr().lock(), &d);
        None
    };
    let bytes = match btfsm_format::source::read_bytes(path, &shown, limits, false) {
        Ok(b) => b,
        Err(d) => return diags(d),
    };
    let text = |bytes: Vec<u8>| match String::from_utf8(bytes) {
        Ok(t) => Some(t),
        Err(e) => {
            eprint!(
                "{}",
                Diagnostic::error(format!(
                    "{}: byte {}: not UTF-8 text",
                    btfsm_core::sanitize::shown(&shown),
                    e.utf8_error().valid_up_to()
                ))
                .hint("a scenario (.toml) or a trace (.json) is UTF-8 text")
            );
            None
        }
    };
    match kind_of(path, &bytes[..bytes.len().min(32)]) {
        Kind::Log => {
            let r = btfsm_view::log::from_log(&bytes[..], &shown, limits)
                .map_or_else(view_failed, Some)?;
            Some((r, Some(LogSource::Btlog(bytes.into()))))
        }
        Kind::Db3 => match btfsm_log::open(path, None, limits, deadline) {
            Ok(o) => {
                let r = btfsm_view::log::from_log(o.reader, &shown, limits)
                    .map_or_else(view_failed, Some)?;
                Some((r, Some(LogSource::Db3(path.to_path_buf()))))
            }
            Err(e) => {
                eprint!(
                    "{}",
                    Diagnostic::error(format!(
                        "{}: {}",
                        btfsm_core::sanitize::shown(&shown),
                        btfsm_core::sanitize::shown(&e)
                    ))
                );
                None
            }
        },
        Kind::Trace => {
            let text = text(bytes)?;
            let dir = path.parent().unwrap_or(Path::new(""));
            let root = btfsm_format::source::root_for(limits, dir);
            btfsm_view::sim::from_trace(&text, &shown, root.as_deref(), limits)
                .map_or_else(view_failed, Some)
                .map(|r| (r, None))
        }
        Kind::Scenario => {
            let file = btfsm_core::diagnostic::SourceFile::new(&shown, text(bytes)?);
            if btfsm_sim::symbolic::looks_symbolic(&file.text) {
                eprint!("{}", Diagnostic::error(format!("{}: a symbolic scenario (with `domain`) has no trace to replay", btfsm_core::sanitize::shown(&shown))).hint("`btfsm view` replays the planar simulator's scenarios, `sim --trace` files and .btlog logs"));
                return None;
            }
            let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
            let mut s = match btfsm_sim::scenario::parse(&file, &base, limits) {
                Ok(s) => s,
                Err(d) => return diags(d),
            };
            if !s.warnings.is_empty() {
                print_diagnostics(&mut std::io::stderr().lock(), &s.warnings);
            }
            if let Some(seed) = a.seed {
                let (ds, rates) = btfsm_sim::monte_carlo::episode(&s, seed);
                s.seed = seed;
                s.disturbances = ds;
                s.rates = rates;
            }
            btfsm_view::sim::from_scenario(&s, &shown)
                .map_or_else(view_failed, Some)
                .map(|r| (r, None))
        }
    }
}

pub(super) fn execute(a: ViewArgs) -> u8 {
    let limits = a.limits.limits();
    // One deadline for every `.db3` query of the command (issue 33).
    let deadline = std::time::Instant::now() + btfsm_log::DEADLINE;
    let mut all: Option<Replay> = None;
    // Per input: its first panel, and its log to compare.
    let mut logs: Vec<(usize, Option<LogSource>, String)> = Vec::new();
    for path in &a.inputs {
        let Some((r, log)) = replay_of(path, &a, &limits, deadline) else {
            return EXIT_BAD_INPUT;
        };
        let first = all.as_ref().map_or(0, |acc| acc.panels.len());
        logs.push((first, log, path.display().to_string()));
        all = Some(match all {
            None => r,
            Some(mut acc) => {
                acc.compared_all &= r.compared_all;
                let off = acc.panels.len();
                acc.title = format!("{} + {}", acc.title, r.title);
                acc.subtitle = format!("{}; {}", acc.subtitle, r.subtitle);
                if acc.step_name != r.step_name {
                    acc.step_name = format!("{}; {}", acc.step_name, r.step_name);
                }
                acc.panels.extend(r.panels);
                acc.divergences
                    .extend(r.divergences.into_iter().map(|mut d| {
                        d.a += off;
                        d.b += off;
                        d
                    }));
                acc
            }
        });
    }
    let Some(mut replay) = all else {
        return EXIT_BAD_INPUT;
    };
    if let Err(code) = compare_inputs(&mut replay, &logs, &limits, deadline) {
        return code;
    }
    let timeout = std::time::Duration::from_millis(a.timeout_ms);
    let page = match btfsm_view::html::page(&replay, timeout) {
        Ok(p) => p,
        Err(e @ ViewError::Render(btfsm_render::dot::RenderError::NotInstalled { .. })) => {
            return fail(Diagnostic::error(format!("no page made: {e}")).hint(
                "`btfsm view` draws each policy with Graphviz: install it; `btfsm sim --plot` and `btfsm dot` (DOT text) work without it",
            ));
        }
        Err(e) => return fail(Diagnostic::error(e.to_string())),
    };
    let code = emit_text(a.output.as_deref(), page);
    if code == EXIT_OK
        && let Some(out) = &a.output
    {
        let steps = (replay.panels.iter())
            .map(|p| p.rec.times.len())
            .max()
            .unwrap_or(0);
        eprintln!(
            "wrote {} ({} panel{}, {steps} steps)",
            btfsm_core::sanitize::shown(&out.display().to_string()),
            replay.panels.len(),
            if replay.panels.len() == 1 { "" } else { "s" }
        );
    }
    code
}

/// Compares the runs of every two inputs, as `btfsm log compare` does
/// when both are logs (its first divergence goes in the page's header);
/// any other two inputs leave the replay not compared throughout.
fn compare_inputs(
    replay: &mut Replay,
    logs: &[(usize, Option<LogSource>, String)],
    limits: &btfsm_format::Limits,
    deadline: std::time::Instant,
) -> Result<(), u8> {
    for (i, (pa, la, sa)) in logs.iter().enumerate() {
        for (pb, lb, sb) in &logs[i + 1..] {
            let (Some(la), Some(lb)) = (la, lb) else {
                replay.compared_all = false;
                continue;
            };
            let side = |l: &LogSource, shown: &str| -> Result<btfsm_log::compare::Side, String> {
                let r: Box<dyn std::io::Read> = match l {
                    LogSource::Btlog(b) => Box::new(std::io::Cursor::new(b.clone())),
                    LogSource::Db3(p) => {
                        btfsm_log::open(p, None, limits, deadline)
                            .map_err(|e| e.to_string())?
                            .reader
                    }
                };
                btfsm_log::compare::open(shown, r, None, limits.max_file_bytes)
                    .map_err(|e| e.to_string())
            };
            let cmp = side(la, sa).and_then(|a| {
                let b = side(lb, sb)?;
                btfsm_log::compare::compare(a, b, None, false).map_err(|e| e.to_string())
            });
            match cmp {
                Ok(rep) => {
                    if let Some(d) = rep.first_divergence {
                        replay.divergences.push(btfsm_view::Divergence {
                            a: *pa,
                            b: *pb,
                            t: d.t,
                            text: d.summary(),
                        });
                    }
                }
                Err(e) => {
                    return Err(fail(Diagnostic::error(
                        btfsm_core::sanitize::shown(&e).into_owned(),
                    )));
                }
            }
        }
    }
    Ok(())
}
