//! `btfsm review` (docs/guide/review.md; issue 30): the policy files a
//! change between two git revisions touches, each read at both revisions
//! with its includes and node models from the same revision, and for each
//! the metrics before and after, the paper's named GED and the ordered tree
//! distance, the change list, the lint findings new in head and a Mermaid
//! diff drawing; the gates of the base revision's `btfsm.toml`; and the
//! report as one pull-request comment (markdown), JSON or text.
//!
//! Everything a pull request holds is untrusted: git runs without a shell
//! and with a repository's programs disabled ([`git`]), a revision's files
//! are materialised only as regular files inside a private directory
//! ([`snapshot`]), and every string that reaches an output is escaped by
//! `btfsm_core::sanitize` or the Mermaid label escaping.

pub mod findings;
pub mod gate;
pub mod git;
mod markdown;
mod pair;
mod select;
pub mod side;
pub mod snapshot;
mod text;

use btfsm_core::diagnostic::Diagnostic;
use btfsm_format::Limits;
use std::path::PathBuf;
use std::time::Duration;

pub use findings::NewFinding;
pub use git::Status;
pub use markdown::{MARKER, MAX_COMMENT_CHARS, render_markdown};
pub use side::Holds;
pub use text::{render_json, render_text};

/// What to review.
#[derive(Debug, Clone)]
pub struct Options {
    /// Where the command runs (inside the repository).
    pub cwd: PathBuf,
    /// `--base`; `None`: the merge base of HEAD with the default branch.
    pub base: Option<String>,
    /// `--head`; `None`: the work tree.
    pub head: Option<String>,
    /// Paths (files or folders, relative to `cwd`) the review is limited to.
    pub paths: Vec<PathBuf>,
    pub limits: Limits,
    /// CPU-time safety cap of one GED computation (`None`: the one derived
    /// from the work budget, so that the work budget decides).
    pub timeout: Option<Duration>,
    /// Work budget of one tree edit distance, in table cells.
    pub tree_max_work: u64,
    /// Also make each diff's DOT text (for `--svg-dir`).
    pub dot: bool,
    /// `--config FILE`: read instead of the base revision's `btfsm.toml`
    /// (a file outside the pull request, never head's).
    pub config: Option<PathBuf>,
}

/// The metrics of one side (SPEC §7's `analyze` numbers).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Metrics {
    pub vertices: i64,
    pub edges: i64,
    pub graphical_elements: i64,
    pub active_elements: i64,
    pub cc: i64,
    pub essential_cc: i64,
}

/// The ordered tree edit distance of two BTs.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Ted {
    pub distance: u64,
    pub exact: bool,
}

/// One revision.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Revision {
    /// The commit id, `null` for the work tree.
    pub commit: Option<String>,
    /// As shown: a short commit id, or `work tree`.
    pub label: String,
}

/// One file's review.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FileReview {
    pub path: String,
    /// A renamed file's path in base.
    pub from: Option<String>,
    pub status: Status,
    pub holds: Holds,
    /// `bt`, `fsm` or `hfsm` when it loaded.
    pub kind: Option<String>,
    /// For a file that did not change itself: the changed files it reads.
    pub via: Vec<String>,
    pub before: Option<Metrics>,
    pub after: Option<Metrics>,
    /// `after` minus `before`.
    pub delta: Option<Metrics>,
    /// The named GED (paper Eq. 2, nodes matched by id), base to head.
    pub ged: Option<u64>,
    pub ted: Option<Ted>,
    /// The change list (at most 200 lines; `changes_total` counts all).
    pub changes: Vec<String>,
    pub changes_total: usize,
    pub new_findings: Vec<NewFinding>,
    /// Base's findings gone in head.
    pub fixed_findings: usize,
    /// Why the file does not load in head.
    pub load_error: Option<String>,
    pub gate_failures: Vec<gate::Failure>,
    /// Both revisions load into the same policy.
    #[serde(skip)]
    pub unchanged: bool,
    /// The Mermaid diff drawing, or the nodes and links that were too many.
    #[serde(skip)]
    pub diagram: Option<Result<String, (usize, usize)>>,
    /// The diff drawing as DOT (with [`Options::dot`]).
    #[serde(skip)]
    pub dot: Option<String>,
}

impl FileReview {
    fn new(path: &str, from: Option<String>, status: Status) -> FileReview {
        FileReview {
            path: path.to_string(),
            from,
            status,
            holds: Holds::Other,
            kind: None,
            via: Vec::new(),
            before: None,
            after: None,
            delta: None,
            ged: None,
            ted: None,
            changes: Vec::new(),
            changes_total: 0,
            new_findings: Vec::new(),
            fixed_findings: 0,
            load_error: None,
            gate_failures: Vec::new(),
            unchanged: false,
            diagram: None,
            dot: None,
        }
    }
}

/// The whole review.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Review {
    pub base: Revision,
    pub head: Revision,
    pub gates: gate::Gates,
    pub files: Vec<FileReview>,
    /// Changed files that are no policy and that no policy reads.
    pub other_changes: usize,
    /// Head's lint findings of every file reviewed (for SARIF).
    #[serde(skip)]
    pub head_findings: Vec<btfsm_lint::Finding>,
}

impl Review {
    /// Every gate failure.
    pub fn failures(&self) -> impl Iterator<Item = &gate::Failure> {
        self.files.iter().flat_map(|f| &f.gate_failures)
    }

    /// Files that do not load in head.
    pub fn not_loaded(&self) -> Vec<(String, String)> {
        self.files
            .iter()
            .filter_map(|f| Some((f.path.clone(), f.load_error.clone()?)))
            .collect()
    }
}

/// Reviews the change `opts` names.
pub fn review(opts: &Options) -> Result<Review, Diagnostic> {
    select::run(opts)
}
