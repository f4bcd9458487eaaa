//! `btfsm review [--base REV] [--head REV] [PATH...]`: the policy changes
//! between two git revisions (`btfsm_review`; docs/guide/review.md) as a
//! pull-request comment (markdown), JSON or text; head's findings as SARIF
//! (`--sarif`); the diff drawings as SVG through Graphviz (`--svg-dir`).
//! Exit 1 when a gate of the base revision's `btfsm.toml` fails, 2 when a
//! revision, the repository or a file cannot be read, or a file does not
//! load in head.

use super::args::LimitArgs;
use super::io::{create_output_dir, emit, emit_report, emit_text, fail, outputs_distinct};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_review::Review;
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The help of `review`'s formats.
const REVIEW_HELP: super::format::Help = &[
    (Format::Text, "The review for a terminal"),
    (
        Format::Markdown,
        "One pull-request comment (hidden marker line first, at most 65,536 characters)",
    ),
    (Format::Json, "The contract of docs/guide/review.md"),
];

#[derive(Debug, Args)]
pub(crate) struct ReviewArgs {
    /// Files or folders the review is limited to (default: the whole
    /// repository)
    pub(super) paths: Vec<PathBuf>,
    /// The revision the change starts from [default: the merge base of HEAD
    /// with the default branch (origin/HEAD, else main or master)]
    #[arg(long, value_name = "REV")]
    pub(super) base: Option<String>,
    /// The revision the change ends at [default: the work tree]
    #[arg(long, value_name = "REV")]
    pub(super) head: Option<String>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(Printed::FORMATS, REVIEW_HELP), default_value = "text")]
    pub(super) format: Format,
    /// Also write head's lint findings of the files reviewed (load failures
    /// included) as SARIF 2.1.0 to FILE
    #[arg(long, value_name = "FILE")]
    pub(super) sarif: Option<PathBuf>,
    /// Also render each diff drawing as SVG into DIR through Graphviz's
    /// `dot` (a note when it is not installed)
    #[arg(long, value_name = "DIR")]
    pub(super) svg_dir: Option<PathBuf>,
    /// Read the gates and lint levels from FILE instead of the base
    /// revision's `btfsm.toml` (one the pull request cannot change)
    #[arg(long, value_name = "FILE")]
    pub(super) config: Option<PathBuf>,
    /// CPU-time safety cap of one file's GED, in milliseconds [default:
    /// derived from the work budget, far past what it takes, so that the
    /// work budget decides and the review is the same on any machine]; it
    /// also bounds each Graphviz rendering of `--svg-dir` (default 10 s)
    #[arg(long, value_name = "MS")]
    pub(super) timeout_ms: Option<u64>,
    /// Work budget of one file's tree edit distance, in table cells
    #[arg(long, default_value_t = btfsm_metrics::ted::DEFAULT_MAX_WORK, value_name = "CELLS")]
    pub(super) tree_max_work: u64,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(a: ReviewArgs) -> u8 {
    if !outputs_distinct(&[("--sarif", a.sarif.as_deref())], true) {
        return EXIT_BAD_INPUT;
    }
    let cwd = match std::env::current_dir() {
        Ok(c) => c,
        Err(e) => return fail(Diagnostic::error(format!("no current directory: {e}"))),
    };
    let opts = btfsm_review::Options {
        cwd,
        base: a.base.clone(),
        head: a.head.clone(),
        paths: a.paths.clone(),
        limits: a.limits.limits(),
        timeout: a.timeout_ms.map(Duration::from_millis),
        tree_max_work: a.tree_max_work,
        dot: a.svg_dir.is_some(),
        config: a.config.clone(),
    };
    let review = match btfsm_review::review(&opts) {
        Ok(r) => r,
        Err(d) => return fail(d),
    };
    let mut code = emit_report(None, &Printed(&review), a.format);
    if let Some(path) = &a.sarif {
        code = code.max(sarif(&review, path));
    }
    if let Some(dir) = &a.svg_dir {
        code = code.max(svgs(
            &review,
            dir,
            Duration::from_millis(a.timeout_ms.unwrap_or(10_000)),
        ));
    }
    let not_loaded = review.not_loaded();
    for (file, why) in &not_loaded {
        eprint!(
            "{}",
            Diagnostic::error(format!("`{file}` does not load in head: {why}"))
                .hint("`btfsm validate FILE` shows every problem")
        );
    }
    if code != EXIT_OK || !not_loaded.is_empty() {
        return EXIT_BAD_INPUT;
    }
    let failures = review.failures().count();
    if failures > 0 {
        eprint!(
            "{}",
            Diagnostic::error(format!(
                "review: {failures} gate failure{} (the base revision's btfsm.toml [review])",
                if failures == 1 { "" } else { "s" }
            ))
        );
        return EXIT_CHECK_FAILED;
    }
    EXIT_OK
}

/// Head's findings as SARIF, the files that do not load as notifications.
fn sarif(r: &Review, path: &Path) -> u8 {
    let inv = btfsm_lint::sarif::Invocation {
        not_linted: r.not_loaded(),
        notes: Vec::new(),
    };
    emit_text(
        Some(path),
        btfsm_lint::sarif::render(&r.head_findings, &inv),
    )
}

/// Each diff drawing as `DIR/<n>-<file name>.svg`, through Graphviz.
fn svgs(r: &Review, dir: &Path, timeout: Duration) -> u8 {
    use btfsm_render::dot::{self, RenderFormat};
    let drawn: Vec<_> = r.files.iter().filter(|f| f.dot.is_some()).collect();
    if drawn.is_empty() {
        return EXIT_OK;
    }
    if !dot::installed() {
        eprintln!(
            "note: --svg-dir: Graphviz's `dot` is not installed, so no SVG was made ({} diff{}); install Graphviz to draw them",
            drawn.len(),
            if drawn.len() == 1 { "" } else { "s" }
        );
        return EXIT_OK;
    }
    if let Err(code) = create_output_dir(dir) {
        return code;
    }
    let mut code = EXIT_OK;
    for (i, f) in drawn.iter().enumerate() {
        let name = svg_name(i, &f.path);
        let text = f.dot.as_deref().unwrap_or_default();
        match dot::render(text, RenderFormat::Svg, timeout) {
            Ok(bytes) => code = code.max(emit(Some(&dir.join(name)), &bytes)),
            Err(e) => code = code.max(fail(Diagnostic::error(e.to_string()))),
        }
    }
    code
}

/// `3-navigate.svg`: the index and the file's name, letters, digits, `-`,
/// `_` and `.` only (a name from a pull request cannot leave DIR).
fn svg_name(i: usize, path: &str) -> String {
    let base = path.rsplit('/').next().unwrap_or(path);
    let stem = base.rsplit_once('.').map_or(base, |(s, _)| s);
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_') {
                c
            } else {
                '_'
            }
        })
        .take(80)
        .collect();
    format!("{}-{safe}.svg", i + 1)
}

/// `review`'s report in its formats.
struct Printed<'a>(&'a Review);

impl Report for Printed<'_> {
    const FORMATS: &'static [Format] = &[Format::Text, Format::Markdown, Format::Json];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Markdown => btfsm_review::render_markdown(self.0),
            Format::Json => btfsm_review::render_json(self.0),
            _ => btfsm_review::render_text(self.0),
        }
    }
}
