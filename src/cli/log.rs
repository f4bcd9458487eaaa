//! `btfsm log report LOG`: per-node figures and coverage of a
//! BehaviorTree.CPP `FileLogger2` log (src/log/); `--min-coverage` makes it
//! a CI gate (exit 1 below it).

use super::io::{emit_text, fail};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::Format;
use btfsm_log::report;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(crate) struct LogArgs {
    #[command(subcommand)]
    pub command: LogCommand,
}

#[derive(Debug, Subcommand)]
pub(crate) enum LogCommand {
    /// Per node: activations, status changes, time RUNNING; node and branch
    /// coverage (exit 1 below --min-coverage)
    Report(ReportArgs),
    /// Draws the log's tree with each node coloured by its status at a
    /// moment (RUNNING yellow, SUCCESS green, FAILURE red), as `dot --trace`
    Dot(DotArgs),
    /// The first divergence between two runs' sequences of executed actions
    /// (a .btlog or a `btfsm sim --format json`/`--trace` file each); exit 0
    /// the same, 1 diverged
    Compare(CompareArgs),
    /// Draws the log as an SVG timeline: a row per leaf ticked, bars where
    /// it was RUNNING, its status changes marked, a time axis in seconds
    Timeline(TimelineArgs),
}

#[derive(Debug, Args)]
pub(crate) struct TimelineArgs {
    /// A BehaviorTree.CPP 4 FileLogger2 log (.btlog; a file: it is read twice)
    pub log: PathBuf,
    /// For a .db3 (SqliteLogger) log: the session to read (default: the last)
    #[arg(long, value_name = "N")]
    pub session: Option<i64>,
    /// Output SVG file (default: stdout)
    #[arg(short, long, value_name = "OUT.svg")]
    pub output: Option<PathBuf>,
    /// Width of the time axis, in pixels (100 to 20000)
    #[arg(long, value_name = "PX", default_value_t = 1000)]
    pub width: u32,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    /// The first run: a BehaviorTree.CPP log (.btlog) or a simulator JSON
    pub a: PathBuf,
    /// The second run, as the first
    pub b: PathBuf,
    /// The session of A when it is a .db3 (default: its last)
    #[arg(long, value_name = "N")]
    pub session_a: Option<i64>,
    /// The session of B when it is a .db3 (default: its last)
    #[arg(long, value_name = "N")]
    pub session_b: Option<i64>,
    /// The simulator's policy, for a simulator JSON with several
    #[arg(long, value_name = "NAME")]
    pub policy: Option<String>,
    /// Also require the same action to start at most this many seconds
    /// apart (default: compare the order only)
    #[arg(long, value_name = "SECONDS")]
    pub tolerance: Option<f64>,
    /// Compare skills and outcomes, not arguments (ports)
    #[arg(long)]
    pub ignore_args: bool,
    /// Output format
    #[arg(long, value_parser = super::format::parser(super::format::COMPARISON, super::format::COMPARISON_HELP), default_value = "table")]
    pub format: Format,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

#[derive(Debug, Args)]
pub(crate) struct DotArgs {
    /// A BehaviorTree.CPP 4 FileLogger2 log (.btlog)
    pub log: PathBuf,
    /// For a .db3 (SqliteLogger) log: the session to read (default: the last)
    #[arg(long, value_name = "N")]
    pub session: Option<i64>,
    /// The moment: this many seconds after the log's first timestamp
    #[arg(
        long,
        value_name = "SECONDS",
        conflicts_with = "step",
        required_unless_present = "step"
    )]
    pub at: Option<f64>,
    /// The moment: after this many records (status changes)
    #[arg(long, value_name = "K")]
    pub step: Option<u64>,
    /// Output file (default: stdout); the render format follows its extension
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Render through Graphviz (svg, png, pdf) instead of writing DOT
    #[arg(long, value_enum)]
    pub render: Option<btfsm_render::dot::RenderFormat>,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

/// `log report`'s formats.
const LOG_REPORT_FORMATS: &[Format] = &[Format::Table, Format::Json, Format::Csv, Format::Markdown];

/// The help of `log report`'s formats.
const LOG_REPORT_HELP: super::format::Help = &[
    (
        Format::Csv,
        "One row per node: uid, node, type, activations, status changes by status, seconds RUNNING",
    ),
    (
        Format::Markdown,
        "GitHub-flavoured markdown: coverage, branches not covered, the nodes",
    ),
];

#[derive(Debug, Args)]
pub(crate) struct ReportArgs {
    /// A BehaviorTree.CPP 4 FileLogger2 log (.btlog), or `-` for stdin
    pub log: PathBuf,
    /// For a .db3 (SqliteLogger) log: the session to read (default: the last)
    #[arg(long, value_name = "N")]
    pub session: Option<i64>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(LOG_REPORT_FORMATS, LOG_REPORT_HELP), default_value = "table")]
    pub format: Format,
    /// Exit 1 when node or branch coverage is below this ratio (0 to 1)
    #[arg(long, value_name = "X")]
    pub min_coverage: Option<f64>,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(super) fn execute(a: LogArgs) -> u8 {
    let a = match a.command {
        LogCommand::Report(a) => a,
        LogCommand::Dot(d) => return dot(d),
        LogCommand::Compare(c) => return compare(c),
        LogCommand::Timeline(t) => return timeline(t),
    };
    if let Some(x) = a.min_coverage
        && !(0.0..=1.0).contains(&x)
    {
        return fail(Diagnostic::error(format!(
            "--min-coverage must be a ratio from 0 to 1, found {x}"
        )));
    }
    let shown = a.log.display().to_string();
    let limits = a.limits.limits();
    // One deadline for every query of the command (issue 33).
    let deadline = std::time::Instant::now() + btfsm_log::DEADLINE;
    let opened = match btfsm_log::open(&a.log, a.session, &limits, deadline) {
        Ok(o) => o,
        Err(e) => return bad_log(&shown, &e),
    };
    let mut r = match report::report(&shown, opened.reader, limits.max_file_bytes) {
        Ok(r) => r,
        Err(e) => {
            return fail(Diagnostic::error(format!("{}: {}", btfsm_core::sanitize::shown(&shown), btfsm_core::sanitize::shown(&e.to_string()))).hint("a BehaviorTree.CPP 4 FileLogger2 log (.btlog) is the header `BTCPP4-FileLogger2`, the tree XML, a timestamp and 9-byte records; a SqliteLogger log (.db3) an SQLite database"));
        }
    };
    r.session = opened.session;
    r.sessions = opened.sessions;
    r.more_sessions = opened.more_sessions;
    let text = match a.format {
        Format::Json => {
            let mut s =
                btfsm_core::sanitize::json(serde_json::to_string_pretty(&r).expect("serializable"));
            s.push('\n');
            s
        }
        Format::Csv => report::render_csv(&r),
        Format::Markdown => report::render_markdown(&r),
        _ => report::render_table(&r),
    };
    let code = emit_text(None, text);
    if code != EXIT_OK {
        return code;
    }
    match a.min_coverage {
        Some(x) if r.node_coverage.ratio < x || r.branch_coverage.ratio < x => {
            eprint!(
                "{}",
                Diagnostic::error(format!(
                    "coverage below {x}: node {:.3}, branch {:.3}",
                    r.node_coverage.ratio, r.branch_coverage.ratio
                ))
            );
            EXIT_CHECK_FAILED
        }
        _ => EXIT_OK,
    }
}

fn dot(a: DotArgs) -> u8 {
    use btfsm_log::replay::{At, replay};
    use btfsm_render::dot::{DotOptions, Highlight, Status as Drawn};
    let at = match (a.at, a.step) {
        (Some(t), _) if t.is_finite() && t >= 0.0 => At::Time((t * 1e6) as u64),
        (Some(t), _) => {
            return fail(Diagnostic::error(format!(
                "--at must be a time in seconds from 0, found {t}"
            )));
        }
        (None, Some(k)) => At::Step(k),
        (None, None) => unreachable!("clap requires one"),
    };
    let shown = a.log.display().to_string();
    let limits = a.limits.limits();
    // One deadline for every query of the command (issue 33).
    let deadline = std::time::Instant::now() + btfsm_log::DEADLINE;
    let file = match btfsm_log::open(&a.log, a.session, &limits, deadline) {
        Ok(o) => o.reader,
        Err(e) => return bad_log(&shown, &e),
    };
    let r = match replay(file, at, &limits) {
        Ok(r) => r,
        Err(e) => {
            return fail(Diagnostic::error(format!(
                "{}: {}",
                btfsm_core::sanitize::shown(&shown),
                btfsm_core::sanitize::shown(&e.to_string())
            )));
        }
    };
    let mut opts = DotOptions::default();
    for (id, s) in &r.statuses {
        let st = match s {
            btfsm_log::btlog::Status::Running => Drawn::Running,
            btfsm_log::btlog::Status::Success => Drawn::Success,
            btfsm_log::btlog::Status::Failure => Drawn::Failure,
            _ => continue,
        };
        opts.highlight.insert(id.clone(), Highlight::Status(st));
    }
    opts.title = Some(format!(
        "{} at {:.3} s ({} status changes)",
        shown,
        r.t_usec as f64 / 1e6,
        r.applied
    ));
    super::dot::draw(
        &r.policy,
        &opts,
        a.output.as_deref(),
        a.render,
        std::time::Duration::from_secs(60),
    )
}

fn bad_log(shown: &str, e: &str) -> u8 {
    eprint!(
        "{}",
        Diagnostic::error(format!(
            "{}: {}",
            btfsm_core::sanitize::shown(shown),
            btfsm_core::sanitize::shown_max(e, 1000)
        ))
    );
    EXIT_BAD_INPUT
}

fn compare(a: CompareArgs) -> u8 {
    use btfsm_log::compare as c;
    if let Some(t) = a.tolerance
        && !(t.is_finite() && t >= 0.0)
    {
        return fail(Diagnostic::error(format!(
            "--tolerance must be a number of seconds from 0, found {t}"
        )));
    }
    if a.a.as_os_str() == "-" && a.b.as_os_str() == "-" {
        return fail(Diagnostic::error(
            "only one of the two runs can be `-` (stdin)",
        ));
    }
    let limits = a.limits.limits();
    // One deadline for every query of the command (issue 33).
    let deadline = std::time::Instant::now() + btfsm_log::DEADLINE;
    let mut sides = Vec::new();
    for (p, session) in [(&a.a, a.session_a), (&a.b, a.session_b)] {
        let shown = p.display().to_string();
        let r = match btfsm_log::open(p, session, &limits, deadline) {
            Ok(o) => o.reader,
            Err(e) => return bad_log(&shown, &e),
        };
        match c::open(&shown, r, a.policy.as_deref(), limits.max_file_bytes) {
            Ok(s) => sides.push(s),
            Err(e) => return bad_run(&e),
        }
    }
    let b = sides.pop().expect("two");
    let first = sides.pop().expect("two");
    let r = match c::compare(first, b, a.tolerance, a.ignore_args) {
        Ok(r) => r,
        Err(e) => return bad_run(&e),
    };
    let text = match a.format {
        Format::Json => {
            let mut s =
                btfsm_core::sanitize::json(serde_json::to_string_pretty(&r).expect("serializable"));
            s.push('\n');
            s
        }
        Format::Markdown => c::render_markdown(&r),
        _ => c::render_table(&r),
    };
    let code = emit_text(None, text);
    if code != EXIT_OK {
        return code;
    }
    if r.same { EXIT_OK } else { EXIT_CHECK_FAILED }
}

fn bad_run(e: &btfsm_log::compare::CompareError) -> u8 {
    eprint!("{}", Diagnostic::error(format!("{}", btfsm_core::sanitize::shown_max(&e.to_string(), 4000))).hint("each run is a BehaviorTree.CPP 4 FileLogger2 log (.btlog) or what `btfsm sim --format json` or `--trace` writes"));
    EXIT_BAD_INPUT
}

fn timeline(a: TimelineArgs) -> u8 {
    use btfsm_log::timeline::MAX_WIDTH;
    if !(100..=MAX_WIDTH).contains(&a.width) {
        return fail(Diagnostic::error(format!(
            "--width must be from 100 to {MAX_WIDTH} pixels, found {}",
            a.width
        )));
    }
    if a.log.as_os_str() == "-" {
        return fail(Diagnostic::error(
            "log timeline reads its log twice: give a file, not `-`",
        ));
    }
    let shown = a.log.display().to_string();
    let limits = a.limits.limits();
    // One deadline for every query of the command (issue 33).
    let deadline = std::time::Instant::now() + btfsm_log::DEADLINE;
    let open = || {
        btfsm_log::open(&a.log, a.session, &limits, deadline)
            .map(|o| o.reader)
            .map_err(std::io::Error::other)
    };
    if let Err(e) = open() {
        return bad_log(&shown, &e.to_string());
    }
    let t = btfsm_log::timeline::timeline(&shown, open, limits.max_file_bytes, a.width);
    match t {
        Ok(t) => emit_text(a.output.as_deref(), t.svg),
        Err(e) => {
            eprint!(
                "{}",
                Diagnostic::error(format!(
                    "{}: {}",
                    btfsm_core::sanitize::shown(&shown),
                    btfsm_core::sanitize::shown(&e.to_string())
                ))
            );
            EXIT_BAD_INPUT
        }
    }
}
