//! `btfsm lint FILE|DIR...`: runs the lint rules (src/lint/) on every policy
//! given or found below a directory; prints findings as positioned text,
//! JSON or SARIF 2.1.0; exit 1 when an error-level finding remains, 2 when
//! an input does not load (its errors printed, the others still linted).

use super::io::{emit_report, emit_text, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_format as format;
use btfsm_lint::{self as lint, Level, config};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The help of `lint`'s formats.
const LINT_HELP: super::format::Help = &[
    (
        Format::Text,
        "Positioned messages with snippet and help, as `validate` prints",
    ),
    (Format::Sarif, "SARIF 2.1.0, for GitHub code scanning"),
];

#[derive(Debug, Args)]
pub(crate) struct LintArgs {
    /// Policy files (any format), `-` for stdin, or directories
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(Findings::FORMATS, LINT_HELP), default_value = "text")]
    pub format: Format,
    /// Report rule CODE as an error (repeatable)
    #[arg(long, value_name = "CODE")]
    pub deny: Vec<String>,
    /// Report rule CODE as a warning (repeatable)
    #[arg(long, value_name = "CODE")]
    pub warn: Vec<String>,
    /// Do not report rule CODE (repeatable)
    #[arg(long, value_name = "CODE")]
    pub allow: Vec<String>,
    /// Do not read btfsm.toml (by default: the one in the current folder or
    /// above it, up to the repository root): for a pull request, whose
    /// btfsm.toml could allow every rule
    #[arg(long)]
    pub no_config: bool,
    /// Read the rule levels from this btfsm.toml instead of looking for one
    /// (for a pull request: the base branch's, which the pull request
    /// cannot change)
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<PathBuf>,
    /// List the rules with their default level and summary, and exit
    #[arg(long, exclusive = true)]
    pub list: bool,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(super) fn execute(a: LintArgs) -> u8 {
    if a.list {
        return emit_text(None, rule_table());
    }
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    let Some(cfg) = levels(&a, &mut err) else {
        return EXIT_BAD_INPUT;
    };
    let limits = a.limits.limits();
    let inputs = match format::discover::expand(&a.files) {
        Ok(i) => i,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    // BehaviorTree.CPP files given together resolve each other's SubTrees
    // (and models), as `analyze` reads them.
    let (limits, only) = match super::io::with_companions(&inputs, &limits) {
        Ok(x) => x,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    let (findings, failed) = lint_inputs(&inputs, only.as_deref(), &limits, &cfg, &mut err);
    let report = Findings {
        findings: &findings,
        files: inputs.len(),
    };
    let code = emit_report(None, &report, a.format);
    if code != EXIT_OK || failed {
        return EXIT_BAD_INPUT;
    }
    if findings.iter().any(|f| f.level == Level::Error) {
        EXIT_CHECK_FAILED
    } else {
        EXIT_OK
    }
}

/// `lint --list`: every rule's code, default level and summary.
fn rule_table() -> String {
    let mut t = btfsm_core::table::Table::new(&["code", "level", "what it finds"]);
    for r in lint::RULES {
        t.row(vec![
            r.code.to_string(),
            r.level.as_str().to_string(),
            r.summary.to_string(),
        ]);
    }
    t.render()
}

/// The rules' levels: `btfsm.toml`'s `[lint]` table (unless `--no-config`),
/// then the flags; `None` after printing why they are invalid.
fn levels(a: &LintArgs, err: &mut impl Write) -> Option<config::Config> {
    let mut cfg = config::Config::default();
    // `--config FILE` is read as a command-line file; one found is named.
    let found = || {
        let cwd = std::env::current_dir().ok()?;
        config::find(&cwd)
    };
    let path = match &a.config {
        Some(p) => Some((p.clone(), false)),
        None if a.no_config => None,
        None => found().map(|p| (p, true)),
    };
    if let Some((path, named)) = path {
        let limits = a.limits.limits();
        let shown = path.display().to_string();
        match format::source::read(&path, &shown, &limits, named).map(|f| config::read(&f)) {
            Ok(Ok(c)) => cfg = c,
            Ok(Err(d)) | Err(d) => {
                print_diagnostics(err, &d);
                return None;
            }
        }
    }
    for (codes, level) in [
        (&a.allow, Level::Allow),
        (&a.warn, Level::Warning),
        (&a.deny, Level::Error),
    ] {
        for c in codes {
            if let Err(e) = cfg.set(c, level) {
                let _ = write!(err, "{}", Diagnostic::error(e.to_string()));
                return None;
            }
        }
    }
    Some(cfg)
}

/// Lints every input (only those of `only` among BehaviorTree.CPP files,
/// when `--tree` chose some): the findings, and whether an input did not
/// load.
fn lint_inputs(
    inputs: &[format::discover::Input],
    only: Option<&[PathBuf]>,
    limits: &btfsm_format::Limits,
    cfg: &config::Config,
    err: &mut impl Write,
) -> (Vec<lint::Finding>, bool) {
    let mut findings = Vec::new();
    let mut failed = false;
    let mut models = SiblingModels::default();
    for input in inputs {
        if let Some(only) = only
            && super::io::is_btcpp_candidate(&input.path)
            && !only.contains(&input.path)
        {
            continue;
        }
        let (file, fmt) = match format::discover::read(input, limits) {
            Ok((file, Some(format::Input::Policy(fmt)))) => (file, fmt),
            Ok(_) => continue,
            Err(d) => {
                failed = true;
                print_diagnostics(err, &d);
                continue;
            }
        };
        let limits = models.limits_for(&input.path, fmt, limits);
        match format::load_read(file.clone(), &input.path, fmt, &limits) {
            Ok(l) => {
                let subject = lint::Subject {
                    policy: &l.policy,
                    dataflow: l.dataflow.as_deref(),
                };
                findings.extend(lint::lint_subject(&subject, Some(&file), &l.path, cfg))
            }
            Err(d) => {
                // Coded load errors are findings (lint::load); the others
                // mean the input does not load.
                let (coded, rest) = lint::load::findings(&d, &file.path, cfg);
                findings.extend(coded);
                if rest.iter().any(|d| d.is_error()) {
                    failed = true;
                    print_diagnostics(err, &rest);
                }
            }
        }
    }
    (findings, failed)
}

/// `lint`'s report: the findings of every file linted.
struct Findings<'a> {
    findings: &'a [lint::Finding],
    files: usize,
}

impl Report for Findings<'_> {
    const FORMATS: &'static [Format] = &[Format::Text, Format::Json, Format::Sarif];

    /// The findings in `format`; the text ends with the counts.
    fn write(&self, format: Format) -> String {
        let (findings, files) = (self.findings, self.files);
        match Self::supported(format) {
            Format::Sarif => lint::sarif::render(findings),
            Format::Json => {
                let mut s = btfsm_core::sanitize::json(
                    serde_json::to_string_pretty(findings).expect("serializable"),
                );
                s.push('\n');
                s
            }
            _ => {
                let mut s: String = findings.iter().map(lint::render_text).collect();
                let count = |l: Level| findings.iter().filter(|f| f.level == l).count();
                s.push_str(&format!(
                    "{} error{}, {} warning{}, {} note{} in {} file{}\n",
                    count(Level::Error),
                    if count(Level::Error) == 1 { "" } else { "s" },
                    count(Level::Warning),
                    if count(Level::Warning) == 1 { "" } else { "s" },
                    count(Level::Note),
                    if count(Level::Note) == 1 { "" } else { "s" },
                    files,
                    if files == 1 { "" } else { "s" },
                ));
                s
            }
        }
    }
}

/// Most `*tree_nodes*.xml` files taken from one folder.
const MAX_SIBLING_MODELS: usize = 8;

/// The node models `lint` reads beside a BehaviorTree.CPP file when the
/// command names none (`--nodes-model`): the `*tree_nodes*.xml` files of its
/// folder (Nav2 keeps `nav2_tree_nodes.xml` beside its trees, as Groot
/// projects do), at most [`MAX_SIBLING_MODELS`], sorted; each folder listed
/// once. Unknown leaves are read as actions unless `--assume-leaf` says
/// otherwise: their C++ registers them, and lint checks what it can.
#[derive(Default)]
struct SiblingModels {
    by_dir: std::collections::HashMap<PathBuf, Vec<PathBuf>>,
}

impl SiblingModels {
    fn limits_for(
        &mut self,
        path: &std::path::Path,
        fmt: format::FileFormat,
        limits: &format::Limits,
    ) -> format::Limits {
        let mut l = limits.clone();
        if fmt != format::FileFormat::BtcppXml {
            return l;
        }
        l.assume_leaf = l.assume_leaf.or(Some(format::AssumeLeaf::Action));
        if !l.nodes_models.is_empty() {
            return l;
        }
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."))
            .to_path_buf();
        let found = self.by_dir.entry(dir.clone()).or_insert_with(|| {
            let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
                .into_iter()
                .flatten()
                .flatten()
                .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
                .map(|e| e.path())
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.contains("tree_nodes") && n.ends_with(".xml"))
                })
                .collect();
            v.sort();
            v.truncate(MAX_SIBLING_MODELS);
            v
        });
        l.nodes_models = found
            .iter()
            .filter(|m| m.as_path() != path)
            .cloned()
            .collect();
        l
    }
}
